//! The compliant latch (MODEL.md §3.2, "Compliant latch"; issue 19) against closed forms.

use flexcraft::deploy::simulate_coupled;
use flexcraft::Scenario;

/// One 2 m, 10 kg panel on a held hub (no beams: a rigid base), hinge spring k = 3 N·m/rad
/// preloaded 0.4 rad, compliant latch k_L, c_L.
fn one_panel(latch: &str) -> String {
    format!(
        r#"
name = "one panel, compliant latch"
[hub]
motion = "fixed"
mass = 100.0
inertia = [10.0, 10.0, 10.0]
center_of_mass = [0.0, 0.0, 0.0]
[[plates]]
name = "wing"
parent = "hub"
root = [0.5, 0.0, 0.0]
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 2.0
width = 1.0
areal_density = 5.0
bending_stiffness = 1.0e4
poisson_ratio = 0.3
[deployment]
plate = "wing"
panels = 1
end_time = 20.0
output_rate = 50.0
tolerance = 1e-13
[deployment.hinge]
stiffness = 3.0
preload_angle = 0.4
{latch}
"#
    )
}

/// Before capture: J α̈ = k (α_ref − α) from rest, so the capture rate is
/// ω₀ = √(2 (V(0) − V(α_L)) / J), J = I + m l²/4. After: J ẍ + c_L ẋ + (k + k_L) x = 0 with
/// x = α − α_eq, α_eq = (k α_ref + k_L α_L)/(k + k_L), x(0) = α_L − α_eq, ẋ(0) = ω₀ — the
/// closed-form damped oscillator; the latch moment is −k_L (α − α_L) − c_L α̇. Every sample
/// after the capture matches to 1e-8 (of the latch moment's peak, and in rad).
#[test]
fn one_panel_capture_matches_the_damped_oscillator() {
    let (kl, cl) = (400.0, 6.0);
    let src = one_panel(&format!(
        "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = {cl:?}\nsettle_time = 5.0\n"
    ));
    let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let (c, r) = simulate_coupled(&sc.structure, d).unwrap();
    let p = &c.chain.panels[0];
    let h = &c.chain.hinges[0];
    let (k, a_ref, a_l) = (h.stiffness, h.reference_angle, h.latch_angle);
    let j = c.panel_inertia[0][2] + 0.25 * p.mass * p.length * p.length;
    assert_eq!(r.captures.len(), 1);
    assert!(r.latches.is_empty(), "a compliant latch is no impact");
    let cap = &r.captures[0];
    let v = |a: f64| 0.5 * k * (a_ref - a).powi(2);
    let w0 = (2.0 * (v(0.0) - v(a_l)) / j).sqrt();
    assert!(
        (cap.rates[0] - w0).abs() < 1e-9 * w0,
        "{} vs {w0}",
        cap.rates[0]
    );
    let a_eq = (k * a_ref + kl * a_l) / (k + kl);
    let wn = ((k + kl) / j).sqrt();
    let zeta = cl / (2.0 * (j * (k + kl)).sqrt());
    assert!(zeta < 1.0);
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let (x0, v0) = (a_l - a_eq, w0);
    let exact = |t: f64| {
        let e = (-zeta * wn * t).exp();
        let (s, co) = (wd * t).sin_cos();
        let b = (v0 + zeta * wn * x0) / wd;
        let x = e * (x0 * co + b * s);
        let xd = -zeta * wn * x + e * wd * (b * co - x0 * s);
        (a_eq + x, xd)
    };
    let peak = r
        .samples
        .iter()
        .map(|s| s.latch_moment[0].abs())
        .fold(0.0, f64::max);
    assert!(peak > 1.0);
    let mut checked = 0;
    for s in r.samples.iter().filter(|s| s.t > cap.time) {
        let (a, ad) = exact(s.t - cap.time);
        let m = -kl * (a - a_l) - cl * ad;
        assert!(
            (s.alpha[0] - a).abs() < 1e-8,
            "t = {}: α {} vs {a}",
            s.t,
            s.alpha[0]
        );
        assert!(
            (s.latch_moment[0] - m).abs() < 1e-8 * peak,
            "t = {}: latch moment {} vs {m}",
            s.t,
            s.latch_moment[0]
        );
        checked += 1;
    }
    assert!(checked > 100, "{checked} samples after the capture");
    // The run settles for settle_time after the capture.
    assert!((r.final_time - (cap.time + 5.0)).abs() < 1e-9);
    assert!(r.all_latched);
}

/// As the latch stiffness grows at a fixed damping ratio (c_L ∝ √k_L), the rate some latch
/// periods after capture tends to the plastic impact's post-impact rate (zero for one panel
/// on a held hub) and the energy the latch takes to the impact's loss; the hinge angle tends
/// to the latch angle. Here: the panel's residual energy of motion relative to its static
/// equilibrium (which tends to the latch angle) falls monotonically.
#[test]
fn stiffer_latches_tend_to_the_plastic_impact() {
    let mut last = f64::INFINITY;
    for kl in [1e2_f64, 1e3, 1e4] {
        // ζ = c_L / (2 √(J k_L)) = 0.5 with J = I + m l²/4 = 40/3 kg·m².
        let cl = (40.0 / 3.0 * kl).sqrt();
        let src = one_panel(&format!(
            "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = {cl:?}\nsettle_time = 8.0\n"
        ));
        let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
        let (c, r) = simulate_coupled(&sc.structure, sc.deployment.as_ref().unwrap()).unwrap();
        let end = r.samples.last().unwrap();
        let h = &c.chain.hinges[0];
        let off = (end.alpha[0] - h.latch_angle).abs();
        assert!(
            off < last,
            "k_L = {kl}: |α − α_L| = {off} (previous {last})"
        );
        assert!(end.rate[0].abs() < 1e-3, "k_L = {kl}: rate {}", end.rate[0]);
        last = off;
    }
}
