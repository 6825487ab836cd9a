//! Beams with lumped and hub inertia against their exact transcendental frequency equations
//! (Euler–Bernoulli, no rotary inertia of the section, as docs/theory.md §1).
//!
//! With EI W'''' = ρA ω² W, β⁴ = ρA ω²/EI and W = A cosh βs + B sinh βs + C cos βs + D sin βs
//! (or the root-clamped combination), the natural boundary conditions follow from the
//! variation of ½∫ρA Ẇ² + ½ m Ẇ(L)² + ½ J Ẇ'(L)² − ½∫EI W''²:
//!   tip mass m with rotary inertia J at s = L:  EI W''(L) = J ω² W'(L),  EI W'''(L) = −m ω² W(L).
//! For a beam clamped at distance r from the centre of mass of a free rigid hub (mass M_h,
//! inertia J_h about the hub's CM), total linear and angular momentum vanish in a mode:
//!   M_h z_h + ∫ρA W = 0,  J_h φ + ∫ρA (r + s) W = 0,
//! with z_h = W(0) − r W'(0), φ = W'(0). Using ρA W = EI W''''/ω² and integrating by parts
//! with the free-tip conditions W''(L) = W'''(L) = 0:
//!   M_h ω² (W(0) − r W'(0)) − EI W'''(0) = 0,
//!   J_h ω² W'(0) + EI (W''(0) − r W'''(0)) = 0.
//! Each set is a 2×2 or 4×4 determinant in β whose roots give ω exactly.

use super::common::{det4, elastic_omegas, roots, solve};

const E: f64 = 70e9;
const RHO: f64 = 2700.0;
const AREA: f64 = 1e-3;
const I: f64 = 1e-6;
const L: f64 = 2.0;

fn omega(beta: f64) -> f64 {
    beta * beta * (E * I / (RHO * AREA)).sqrt()
}

/// Relative distance from ω to the nearest computed frequency.
fn nearest(computed: &[f64], w: f64) -> f64 {
    computed
        .iter()
        .map(|c| ((c - w) / w).abs())
        .fold(f64::INFINITY, f64::min)
}

fn beam_block(parent: &str, root: &str, bending: usize) -> String {
    format!(
        r#"
[materials.al]
youngs_modulus = {E}
poisson_ratio = 0.3
density = {RHO}
[[beams]]
name = "beam"
parent = "{parent}"
root = {root}
axis = [1.0, 0.0, 0.0]
length = {L}
material = "al"
section = {{ area = {AREA}, iy = {I}, iz = {I}, torsion_constant = 2e-6, polar_inertia = 2e-6 }}
terms = {{ bending = {bending}, torsion = 12, axial = 12 }}
"#
    )
}

#[test]
fn cantilever_with_tip_mass_and_rotary_inertia_matches_exact_frequencies() {
    let (m, j) = (3.0, 0.2);
    let toml = format!(
        r#"
name = "tip mass"
[hub]
motion = "fixed"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
center_of_mass = [0.0, 0.0, 0.0]
{}
[[masses]]
name = "tip"
parent = "beam"
station = {L}
mass = {m}
inertia = [0.05, {j}, {j}]
"#,
        beam_block("hub", "[0.0, 0.0, 0.0]", 30)
    );
    let computed = elastic_omegas(&solve(&toml).1);
    let ra = RHO * AREA;
    let det = |b: f64| {
        let x = b * L;
        let (ch, sh, c, s) = (x.cosh(), x.sinh(), x.cos(), x.sin());
        // Columns A, B of W = A(cosh − cos) + B(sinh − sin); rows scaled by cosh.
        let w = [ch - c, sh - s];
        let w1 = [sh + s, ch - c];
        let w2 = [ch + c, sh + s];
        let w3 = [sh - s, ch + c];
        let k1 = j * b * b * b / ra;
        let k2 = m * b / ra;
        let r1 = [w2[0] - k1 * w1[0], w2[1] - k1 * w1[1]];
        let r2 = [w3[0] + k2 * w[0], w3[1] + k2 * w[1]];
        (r1[0] * r2[1] - r1[1] * r2[0]) / (ch * ch)
    };
    let betas = roots(det, 0.05, 14.0, 20000);
    assert!(betas.len() >= 5, "found {betas:?}");
    for b in &betas[..5] {
        let e = nearest(&computed, omega(*b));
        assert!(e < 1e-8, "β = {b}: ω = {}, error {e:e}", omega(*b));
    }
}

#[test]
fn beam_clamped_to_rim_of_free_hub_matches_exact_frequencies() {
    let (mh, jh, r) = (50.0, 20.0, 0.8);
    let toml = format!(
        r#"
name = "hub and beam"
[hub]
motion = "free"
mass = {mh}
inertia = [10.0, {jh}, {jh}]
center_of_mass = [0.0, 0.0, 0.0]
{}
"#,
        beam_block("hub", &format!("[{r}, 0.0, 0.0]"), 30)
    );
    let (_, modes) = solve(&toml);
    assert_eq!(modes.modes.iter().filter(|m| m.rigid).count(), 6);
    let computed = elastic_omegas(&modes);
    let ra = RHO * AREA;
    let det = |b: f64| {
        let x = b * L;
        let (ch, sh, c, s) = (x.cosh(), x.sinh(), x.cos(), x.sin());
        let km = mh * b / ra;
        let kj = jh * b * b * b / ra;
        let rb = r * b;
        det4([
            [km, -km * rb - 1.0, km, -km * rb + 1.0],
            [1.0, kj - rb, -1.0, kj + rb],
            [1.0, sh / ch, -c / ch, -s / ch],
            [sh / ch, 1.0, s / ch, -c / ch],
        ])
    };
    let betas = roots(det, 0.05, 14.0, 20000);
    assert!(betas.len() >= 4, "found {betas:?}");
    for b in &betas[..4] {
        let e = nearest(&computed, omega(*b));
        assert!(e < 1e-8, "β = {b}: ω = {}, error {e:e}", omega(*b));
    }
}
