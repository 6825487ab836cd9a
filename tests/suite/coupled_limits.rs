//! Limits of the coupled deployment model (`deploy::coupled`, the folded array on the flexible
//! free-floating base) against independent truths:
//!
//! 1. every hinge locked from the start: the small oscillations are the natural modes of the
//!    mast with a rigid wing (the Ritz model of the structure, its plate made rigid);
//! 2. an elastic cable tends to the ideal cable as its stiffness grows (first order in 1/k);
//! 3. a stiffer and stiffer mast tends to the rigid base (first latch, error ∝ 1/factor), and
//!    what does not converge after a latch (the plastic impact on an elastic base);
//! 4. the rigid base with a free 3-D hub agrees with a second formulation written here: rigid
//!    bodies in maximal coordinates, revolute hinges as constraints, RK4 with projection.

use super::coupled::coupled;
use faer::{Mat, Side};
use flexcraft::deploy::base::BaseKind;
use flexcraft::deploy::coupled::{Coupled, CoupledRun, Synchronisation};
use flexcraft::ritz::assembly::HUB_DOF;
use flexcraft::scenario::Scenario;
use flexcraft::structure::ComponentId;
use flexcraft::{ModalAnalysis, RitzModel};
use std::time::Instant;

fn parse(src: &str, name: &str) -> Scenario {
    Scenario::from_toml_str(src, name).unwrap_or_else(|e| panic!("{e}"))
}

/// ω (rad/s, ascending) of the pencil K φ = ω² M φ, K and M symmetric positive definite:
/// M = LLᵀ, then the eigenvalues of the symmetric L⁻¹KL⁻ᵀ (faer's dense solver; the library's
/// own eigen-solver is not used).
fn pencil_frequencies(k: &Mat<f64>, m: &Mat<f64>) -> Vec<f64> {
    let llt = m.llt(Side::Lower).expect("M positive definite");
    let l = llt.L();
    let mut x = k.clone();
    l.solve_lower_triangular_in_place(x.as_mut());
    let mut c = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(c.as_mut());
    let n = c.nrows();
    let c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let mut w: Vec<f64> = c
        .self_adjoint_eigenvalues(Side::Lower)
        .expect("symmetric eigenvalues")
        .iter()
        .map(|l| l.sqrt())
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn sci(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.2e}")).collect();
    format!("[{}]", items.join(", "))
}

fn fixed(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.3}")).collect();
    format!("[{}]", items.join(", "))
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------------------
// 1. Locked from the start → modes
// ---------------------------------------------------------------------------------------

/// An 800 kg hub with a 5 m aluminium tube mast along x and, at its tip, a 4.5 m × 1.2 m wing
/// of three panels whose length axis (0, −0.6, 0.8) is oblique to both bending planes of the
/// mast: bending about y and z and torsion all couple through the wing.
fn mast_and_wing(motion: &str, bending_stiffness: f64, youngs_modulus: f64) -> String {
    format!(
        r#"
name = "mast with a three-panel wing at its tip"
format_version = 1
[hub]
motion = "{motion}"
mass = 800.0
inertia = [500.0, 600.0, 700.0]
center_of_mass = [0.0, 0.0, 0.0]
[materials.aluminium]
youngs_modulus = {youngs_modulus:e}
poisson_ratio = 0.3
density = 2700.0
[[beams]]
name = "mast"
parent = "hub"
root = [1.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 5.0
material = "aluminium"
section = {{ tube = {{ outer_diameter = 0.15, wall = 0.004 }} }}
terms = {{ bending = 6, torsion = 3, axial = 3 }}
[[plates]]
name = "wing"
parent = "mast"
station = 5.0
length_axis = [0.0, -0.6, 0.8]
normal = [1.0, 0.0, 0.0]
length = 4.5
width = 1.2
areal_density = 6.0
bending_stiffness = {bending_stiffness:e}
poisson_ratio = 0.3
terms = {{ length = 6, width = 3 }}
[deployment]
plate = "wing"
panels = 3
end_time = 10.0
[deployment.hinge]
stiffness = 2.0
preload_angle = 0.4
"#
    )
}

/// The state with every hinge at its latch angle (the straight, locked wing), at rest and
/// undeformed.
fn locked_straight(c: &Coupled) -> Vec<f64> {
    let mut y = c.initial_state();
    let off = c.alpha_offset();
    for (i, h) in c.chain.hinges.iter().enumerate() {
        y[off + i] = h.latch_angle;
    }
    y
}

/// Small-oscillation frequencies of the locked coupled model from its mass matrix on the
/// admissible speeds (Zᵀ M Z, here the η̇ block) and the stiffness diag(ω_j²).
fn locked_frequencies_from_mass(c: &Coupled) -> Vec<f64> {
    let y = locked_straight(c);
    let z = c.admissible(&vec![false; c.panels()]);
    let zmz = z.transpose() * (&c.evaluate(&y).mass * &z);
    let m = c.modes();
    assert_eq!(
        zmz.nrows(),
        m,
        "locked, held hub: the admissible speeds are η̇"
    );
    let k = Mat::from_fn(
        m,
        m,
        |i, j| {
            if i == j {
                c.base.omega[i].powi(2)
            } else {
                0.0
            }
        },
    );
    pencil_frequencies(&k, &zmz)
}

/// The same by central differences of `rhs` around the equilibrium: A = ∂η̈/∂η = −M⁻¹K,
/// whose spectrum is −ω²; with K = diag(ω_j²), K^½(−A)K^−½ = K^½M⁻¹K^½ is symmetric.
fn locked_frequencies_from_rhs(c: &Coupled, eps: f64) -> (Vec<f64>, f64) {
    let y = locked_straight(c);
    let (m, np) = (c.modes(), c.positions());
    let free = vec![false; c.panels()];
    let mut a = Mat::<f64>::zeros(m, m);
    for k in 0..m {
        let (mut yp, mut ym) = (y.clone(), y.clone());
        yp[k] += eps;
        ym[k] -= eps;
        let (mut dp, mut dm) = (vec![0.0; y.len()], vec![0.0; y.len()]);
        c.rhs(&yp, &free, &mut dp);
        c.rhs(&ym, &free, &mut dm);
        for i in 0..m {
            a[(i, k)] = -(dp[np + i] - dm[np + i]) / (2.0 * eps);
        }
    }
    let w = &c.base.omega;
    let s = Mat::from_fn(m, m, |i, j| w[i] * a[(i, j)] / w[j]);
    let scale = (0..m).map(|i| s[(i, i)].abs()).fold(0.0, f64::max);
    let asym = (0..m)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .map(|(i, j)| (s[(i, j)] - s[(j, i)]).abs())
        .fold(0.0, f64::max)
        / scale;
    let sym = Mat::from_fn(m, m, |i, j| 0.5 * (s[(i, j)] + s[(j, i)]));
    let id = Mat::from_fn(m, m, |i, j| if i == j { 1.0 } else { 0.0 });
    (pencil_frequencies(&sym, &id), asym)
}

/// The exact rigid-wing limit of the structure's Ritz model: the plate's own coordinates
/// (its deflection W = Σ g X Y) held at zero, so the plate moves rigidly with the mast-tip
/// section it is clamped to; held hub, so the hub's six go too.
fn rigid_wing_ritz_frequencies(sc: &Scenario) -> Vec<f64> {
    let model = RitzModel::assemble(&sc.structure);
    let plate = model
        .elements
        .iter()
        .find(|e| matches!(e.id, ComponentId::Plate(_)))
        .expect("the wing")
        .own_range();
    let keep: Vec<usize> = (HUB_DOF..model.dof())
        .filter(|i| !plate.contains(i))
        .collect();
    let n = keep.len();
    let m = Mat::from_fn(n, n, |i, j| model.mass[(keep[i], keep[j])]);
    let k = Mat::from_fn(n, n, |i, j| model.stiffness[(keep[i], keep[j])]);
    pencil_frequencies(&k, &m)
}

fn elastic_frequencies(sc: &Scenario) -> Vec<f64> {
    let modes = ModalAnalysis::compute(&RitzModel::assemble(&sc.structure)).expect("modes");
    modes.elastic().map(|m| m.omega_rad_s).collect()
}

/// Every hinge locked at t = 0 (α at the latch angles: the straight wing), held hub, all of
/// the base's hub-fixed modes kept: the coupled model's small oscillations about that
/// equilibrium are those of "mast + rigid wing". With the hinges locked the speeds are η̇
/// only; the frequencies come (a) from Zᵀ M Z of `evaluate` with K = diag(ω_j²) and (b) from
/// central differences of `rhs` (the integrator's right-hand side). The truths:
///
/// * the Ritz model of the same structure (`RitzModel::assemble`, element matrices from the
///   1-D integrals of the bases, `assembly.rs`) with the plate's deflection coordinates
///   removed — exactly the structure with a rigid wing clamped to the mast-tip section. The
///   coupled model instead builds its base from a mass-point cloud and inertia invariants and
///   its wing from rigid panels (mass μ l w, centroidal inertias of a thin plate), so the two
///   share only the mast's Ritz functions. The base modes span the whole mast space, so all
///   18 frequencies are comparable;
/// * `ModalAnalysis` of the structure with the plate's bending stiffness × 1e8 (1e12 N·m):
///   its frequencies tend to the rigid-wing ones as 1/D (checked: the error falls tenfold per
///   decade), the lowest nine to ≤ 1.3e-7 at 1e12; a Richardson step from 1e11 and 1e12
///   removes the 1/D term;
/// * with the base truncated to its 6 lowest modes the frequencies are Rayleigh–Ritz upper
///   bounds of the exact ones (min-max principle).
///
/// Achieved: (a) and (b) equal the rigid-wing Ritz frequencies to 5e-12 and 3e-12 (ε = 1e-7)
/// for all 18 modes; ModalAnalysis at D = 1e12: lowest nine to 1.3e-7, all 18 to 2.5e-5;
/// Richardson: lowest 15 to 2.3e-10, all to 5.4e-8.
#[test]
fn locked_wing_oscillates_at_the_modes_of_the_mast_with_a_rigid_wing() {
    let started = Instant::now();
    let d0 = 1.0e4;
    let sc = parse(&mast_and_wing("fixed", d0, 70e9), "locked.toml");
    let c = coupled(&sc, BaseKind::Flexible { modes: None });
    assert_eq!(c.hub_dof(), 0);
    let exact = rigid_wing_ritz_frequencies(&sc);
    assert_eq!(
        c.modes(),
        exact.len(),
        "every mast coordinate is a base mode"
    );
    assert_eq!(exact.len(), 18, "3 axial + 2 × 6 bending + 3 torsion");
    let by_mass = locked_frequencies_from_mass(&c);
    let (by_rhs, asym) = locked_frequencies_from_rhs(&c, 1e-7);
    assert!(asym < 1e-6, "K^½(−∂η̈/∂η)K^−½ symmetric: {asym:e}");
    let mut worst = (0.0f64, 0.0f64);
    for (i, ((a, b), e)) in by_mass.iter().zip(&by_rhs).zip(&exact).enumerate() {
        assert!(
            rel(*a, *e) <= 1e-9 && rel(*b, *e) <= 1e-9,
            "mode {}: coupled {a} (mass) / {b} (rhs) vs rigid-wing Ritz {e} rad/s",
            i + 1
        );
        worst = (worst.0.max(rel(*a, *e)), worst.1.max(rel(*b, *e)));
    }
    // The same limit through the public modal analysis with a very stiff plate.
    let stiff = elastic_frequencies(&parse(
        &mast_and_wing("fixed", d0 * 1e8, 70e9),
        "stiff.toml",
    ));
    let less = elastic_frequencies(&parse(&mast_and_wing("fixed", d0 * 1e7, 70e9), "less.toml"));
    let mut worst_stiff = 0.0f64;
    for i in 0..9 {
        let r = rel(by_mass[i], stiff[i]);
        assert!(
            r <= 1e-6,
            "mode {}: coupled {} vs ModalAnalysis (D × 1e8) {} rad/s",
            i + 1,
            by_mass[i],
            stiff[i]
        );
        worst_stiff = worst_stiff.max(r);
        // The plate's flexibility lowers every frequency (the rigid wing is a constraint; a
        // stiffer plate a larger K), by ∝ 1/D.
        assert!(
            stiff[i] <= exact[i] * (1.0 + 1e-11) && less[i] <= stiff[i] * (1.0 + 1e-11),
            "mode {}: D = 1e11 {}, 1e12 {}, rigid {} rad/s",
            i + 1,
            less[i],
            stiff[i],
            exact[i]
        );
    }
    let mut worst_rich = 0.0f64;
    for i in 0..18 {
        let extrapolated = (10.0 * stiff[i] - less[i]) / 9.0;
        let r = rel(by_mass[i], extrapolated);
        assert!(
            r <= if i < 15 { 1e-9 } else { 2e-7 },
            "mode {}: coupled {} vs Richardson-extrapolated D → ∞ {extrapolated} rad/s",
            i + 1,
            by_mass[i]
        );
        worst_rich = worst_rich.max(r);
    }
    // Truncated base: Rayleigh–Ritz upper bounds.
    let c6 = coupled(&sc, BaseKind::Flexible { modes: Some(6) });
    let trunc = locked_frequencies_from_mass(&c6);
    for (i, (t, e)) in trunc.iter().zip(&exact).enumerate() {
        assert!(
            *t >= e * (1.0 - 1e-12),
            "mode {}: 6 base modes give {t} < exact {e}",
            i + 1
        );
    }
    println!(
        "locked wing: ω₁…ω₃ = {:.6} {:.6} {:.6} rad/s; coupled vs rigid-wing Ritz: {:.1e} (mass), \
         {:.1e} (rhs); vs ModalAnalysis D × 1e8 (lowest 9): {worst_stiff:.1e}; vs Richardson: \
         {worst_rich:.1e}; 6-mode base ω₁ above by {:.1e}; {:.2?}",
        exact[0],
        exact[1],
        exact[2],
        worst.0,
        worst.1,
        rel(trunc[0], exact[0]),
        started.elapsed()
    );
}

// ---------------------------------------------------------------------------------------
// 2. Elastic cable → ideal cable
// ---------------------------------------------------------------------------------------

/// Three identical 2 m × 1.5 m, 15 kg panels (I = m l²/12 = 5 kg·m²) on a held hub-only
/// base, hinge springs k_i with α_ref = latch angle + 0.3, released from rest stowed.
fn three_panels(stiffness: [f64; 3]) -> String {
    format!(
        r#"
name = "three identical panels on a held hub"
format_version = 1
[hub]
motion = "fixed"
mass = 500.0
inertia = [300.0, 400.0, 350.0]
center_of_mass = [0.0, 0.0, 0.0]
[[plates]]
name = "wing"
parent = "hub"
root = [1.2, 0.0, 0.4]
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 6.0
width = 1.5
areal_density = 5.0
bending_stiffness = 2.0e4
poisson_ratio = 0.3
terms = {{ length = 4, width = 2 }}
[deployment]
plate = "wing"
panels = 3
end_time = 60.0
[deployment.hinge]
preload_angle = 0.3
[[deployment.hinges]]
stiffness = {:e}
[[deployment.hinges]]
stiffness = {:e}
[[deployment.hinges]]
stiffness = {:e}
"#,
        stiffness[0], stiffness[1], stiffness[2]
    )
}

/// (relative latch-time error, largest opening-rate error in rad/s) of an elastic cable's
/// first latch against the ideal cable's (single) latch.
fn cable_errors(c: &mut Coupled, ideal: &CoupledRun, k: f64) -> (f64, f64, usize) {
    let li = &ideal.latches[0];
    c.sync = Synchronisation::ElasticCable(k);
    let run = c.simulate(false, 1.2 * li.time, 1e-12);
    let l = &run.latches[0];
    (
        rel(l.time, li.time),
        max_abs_diff(&l.rates_before, &li.rates_before),
        run.steps,
    )
}

/// log10(e(k)/e(10k)): the observed order in k over one decade.
fn order(e: &[f64]) -> Vec<f64> {
    e.windows(2).map(|w| (w[0] / w[1]).log10()).collect()
}

/// An elastic cable (torsional stiffness k per loop) tends to the ideal cable (the holonomic
/// constraint α₂ = 2α₁, α₃ = α₂ from the stowed angles) as k → ∞. Singular-perturbation
/// theory of a stiff spring (the truth here, independent of the code): the slow motion
/// deviates from the constrained one by the quasi-static stretch λ(t)/k, λ the ideal cable's
/// multiplier, so the latch time and the rates converge as 1/k; a fast loop oscillation is
/// excited only if λ jumps at release — from rest λ̇(0) = 0, so with λ(0) = 0 its amplitude is
/// O(λ̈(0)/(k ω_c²)) = O(1/k²) (ω_c ∝ √k the loops' frequency).
///
/// The case is chosen so that λ(0) = 0: the unsynchronised initial accelerations M⁻¹Q already
/// satisfy the cable, i.e. the spring torques Q_i = k_i(α_ref,i − 0) are ∝ (M z)_i with
/// z = (1, 2, 2). Stowed, every panel lies on the normal through the root, every centre at
/// l/2 from its hinges (H₁ = H₃ = 0, H₂ = l n), so with A_l = Σ_{i≥l} m l²/4 + I = 20, 40, 60
/// and B_l = Σ_{i≥l} m (C_i − H_l) = 45 n, −30 n, 15 n (l = 3, 2, 1 from the tip),
/// M_kl = d_k d_l [A_l + (H_l − H_k)·B_l], d = (−1, 1, −1):
/// M = [60 20 20; 20 40 10; 20 10 20], M z = (140, 120, 80) kg·m². After release λ grows (to
/// ≈ 21 N·m near the latch, at 11.02 s) while the unsynchronised chain latches hinge 3 first,
/// ≈ 5 % earlier: the cable matters.
///
/// Below k ≈ 1e4 N·m/rad the loops' period is not short against the time in which λ changes
/// near the latch, and the errors are not yet monotone; from 1e4 to 1e8 they
/// fall by a factor 9.9–10 per decade (orders 1.00 ± 0.01 from 1e5 on, 1.09 for the rates from
/// 1e4). At k = 1e8: latch time to 2.0e-8 relative, rates to 2.5e-6 rad/s (of ≈ 1.1 rad/s).
///
/// The generic release (equal springs, λ(0) ≈ −3.3 N·m) excites the loops' fast oscillation:
/// the latch time still converges as 1/k (order ≈ 1 from 1e5 to 1e7), but the rates only
/// within an envelope ∝ k^−½ (that oscillation's velocity) whose phase at the latch makes the
/// error non-monotone beyond 1e7 (8.9e-5, 8.4e-5, 2.8e-5 rad/s at 1e8, 3.2e8, 1e9); asserted here from 1e5 to 1e7, where it falls from 2.3e-2 to 2.6e-4 rad/s.
#[test]
fn elastic_cable_converges_to_the_ideal_cable_as_one_over_k() {
    use std::f64::consts::PI;
    let started = Instant::now();
    // Spring torques at release ∝ M z = (140, 120, 80).
    let mz = [140.0, 120.0, 80.0];
    let reference = [PI / 2.0 + 0.3, PI + 0.3, PI + 0.3];
    let k: [f64; 3] = std::array::from_fn(|i| 0.02 * mz[i] / reference[i]);
    let sc = parse(&three_panels(k), "cable.toml");
    let mut c = coupled(&sc, BaseKind::Rigid);
    assert_eq!(c.modes(), 0);
    c.sync = Synchronisation::IdealCable;
    let lambda0 = c.solve(&c.initial_state(), &[true; 3]).1.cable_torque;
    assert!(
        lambda0.iter().all(|l| l.abs() < 1e-12),
        "consistent release: cable torques {lambda0:?}"
    );
    let ideal = c.simulate(false, 60.0, 1e-12);
    assert_eq!(ideal.latches.len(), 1);
    let li = &ideal.latches[0];
    assert!((li.rates_before[1] - 2.0 * li.rates_before[0]).abs() < 1e-9);
    c.sync = Synchronisation::None;
    let none = c.simulate(false, 60.0, 1e-12);
    assert!(
        rel(none.latches[0].time, li.time) > 0.03,
        "without the cable the first latch is {} s vs {} s",
        none.latches[0].time,
        li.time
    );
    let ks = [1e4, 1e5, 1e6, 1e7, 1e8];
    let (mut et, mut er) = (Vec::new(), Vec::new());
    for &kc in &ks {
        let (t, r, _) = cable_errors(&mut c, &ideal, kc);
        et.push(t);
        er.push(r);
    }
    let (ot, or) = (order(&et), order(&er));
    for (i, w) in et.windows(2).enumerate() {
        assert!(w[1] < w[0], "latch-time error not decreasing: {et:?}");
        assert!(er[i + 1] < er[i], "rate error not decreasing: {er:?}");
    }
    for o in ot.iter().chain(&or) {
        assert!(
            (0.9..=1.1).contains(o),
            "order {o} (time {ot:?}, rates {or:?})"
        );
    }
    assert!(et[4] <= 5e-8, "k = 1e8: latch time error {}", et[4]);
    assert!(er[4] <= 5e-6, "k = 1e8: rate error {} rad/s", er[4]);

    // Generic release: equal springs, λ(0) ≠ 0.
    let sc = parse(&three_panels([3.0; 3]), "cable_generic.toml");
    let mut g = coupled(&sc, BaseKind::Rigid);
    g.sync = Synchronisation::IdealCable;
    let lambda0 = g.solve(&g.initial_state(), &[true; 3]).1.cable_torque;
    assert!(lambda0.iter().all(|l| l.abs() > 1.0), "{lambda0:?}");
    let ideal_g = g.simulate(false, 60.0, 1e-12);
    let (mut gt, mut gr) = (Vec::new(), Vec::new());
    for kc in [1e5, 1e6, 1e7] {
        let (t, r, _) = cable_errors(&mut g, &ideal_g, kc);
        gt.push(t);
        gr.push(r);
    }
    let got = order(&gt);
    for o in &got {
        assert!(
            (0.9..=1.15).contains(o),
            "generic release, time order {got:?}"
        );
    }
    assert!(gr[1] < gr[0] && gr[2] < gr[1] && gr[2] < 1e-3, "{gr:?}");
    println!(
        "cable (consistent release): k = {}; latch-time errors {} (orders {}); rate errors {} \
         rad/s (orders {}); generic release k = 1e5…1e7: time {} (orders {}), rates {}; {:.2?}",
        sci(&ks),
        sci(&et),
        fixed(&ot),
        sci(&er),
        fixed(&or),
        sci(&gt),
        fixed(&got),
        sci(&gr),
        started.elapsed()
    );
}

// ---------------------------------------------------------------------------------------
// 3. Stiff mast → rigid base
// ---------------------------------------------------------------------------------------

/// The first latch of [`mast_and_wing`] (free hub) with the base's 2 lowest modes and its
/// stiffness × `factor` (ω × √factor), against the rigid base: (relative latch-time error,
/// largest rate error before, largest after, energy after, steps).
fn stiff_first_latch(
    sc: &Scenario,
    rigid: &CoupledRun,
    factor: f64,
    tol: f64,
) -> (f64, f64, f64, f64, usize) {
    let mut c = coupled(sc, BaseKind::Flexible { modes: Some(2) });
    for w in c.base.omega.iter_mut() {
        *w *= factor.sqrt();
    }
    let r0 = &rigid.latches[0];
    // Stop just after the first latch (the flexible one lies within 1e-5 relative).
    let run = c.simulate(false, r0.time * (1.0 + 1e-4), tol);
    assert!(
        !run.latches.is_empty(),
        "factor {factor:e}: no latch, {} steps",
        run.steps
    );
    let l = &run.latches[0];
    assert_eq!(l.hinge, r0.hinge);
    (
        rel(l.time, r0.time),
        max_abs_diff(&l.rates_before, &r0.rates_before),
        max_abs_diff(&l.rates_after, &r0.rates_after),
        l.energy_after,
        run.steps,
    )
}

/// A stiffer and stiffer mast tends to the rigid base (`BaseKind::Rigid` of the same
/// structure, free hub, 3-D: the wing is oblique to the mast). The mast's Young's (and shear)
/// modulus × f scales K and leaves M, so the mass-normalised base modes keep their shapes and
/// ω → √f ω: checked at f = 100 against the scenario with E × 100 (the scenario caps E at
/// 1e13 Pa, so aluminium × 1e6 cannot be written there), then used for every f.
///
/// Until the first latch the base only follows the chain's loads: its quasi-static deflection
/// and the vibration the release excites are both ∝ 1/f in displacement, so the first latch
/// time converges as 1/f (within a bounded factor set by that vibration's phase at the latch:
/// |error|·f stays in 1e-6…2.1e-5 from f = 1 to 1e4), and the rates, which carry the
/// vibration's velocity ∝ f^−½, within 2e-2/√f. Achieved: 1.0e-5 (f = 1), 1.0e-7 (10),
/// 3.2e-8 (100), 1.6e-8 (1e3), 1.6e-9 (1e4): below 1e-7 from f = 100. The cost of the explicit
/// integrator grows ≈ f^0.4 (3e3 steps at f = 1, 1.4e5 at 1e4, ≈ 5 s); f = 1e5 and 1e6 are in
/// [`stiff_mast_first_latch_at_1e5_and_1e6`] (ignored: ≈ 3 min; 8.6e-11 and 6.8e-12).
///
/// What does not converge: the latch itself. The plastic impact projects the velocities in the
/// mass metric onto what the locked hinges admit; the flexible base admits every η̇, a set
/// that contains the rigid base's and does not depend on the stiffness. So the flexible
/// latch keeps at least the rigid latch's kinetic energy (a minimisation over a larger set) —
/// here ≈ 1.4 % more for every f, the excess going into base vibration — and the post-latch
/// rates differ by ≈ 0.14 rad/s however stiff the mast: the later latches differ from the
/// rigid base's by 1e-4…1e-3 relative (f = 1, 10, 100), not decreasing with f. Asserted: the
/// energy inequality.
#[test]
fn stiff_mast_first_latch_converges_to_the_rigid_base() {
    let started = Instant::now();
    let sc = parse(&mast_and_wing("free", 1e4, 70e9), "stiff.toml");
    let rigid_model = coupled(&sc, BaseKind::Rigid);
    assert_eq!(rigid_model.hub_dof(), 6);
    let rigid = rigid_model.simulate(false, 30.0, 1e-12);
    assert_eq!(rigid.latches.len(), 3);
    // ω scaling = Young's modulus × f.
    let sc100 = parse(&mast_and_wing("free", 1e4, 70e9 * 100.0), "stiff100.toml");
    let c1 = coupled(&sc, BaseKind::Flexible { modes: Some(2) });
    let c100 = coupled(&sc100, BaseKind::Flexible { modes: Some(2) });
    for (a, b) in c100.base.omega.iter().zip(&c1.base.omega) {
        assert!(rel(*a, 10.0 * b) < 1e-12, "E × 100: ω {a} vs 10 × {b}");
    }
    let factors = [1.0, 1e1, 1e2, 1e3, 1e4];
    let mut rows = Vec::new();
    for &f in &factors {
        let (dt, db, da, ea, steps) = stiff_first_latch(&sc, &rigid, f, 1e-11);
        assert!(
            dt <= 3e-5 / f,
            "f = {f:e}: latch time error {dt:e} above 3e-5/f"
        );
        assert!(
            f < 100.0 || dt <= 1e-7,
            "f = {f:e}: latch time error {dt:e}"
        );
        assert!(db <= 2e-2 / f.sqrt(), "f = {f:e}: rates before {db:e}");
        let e_rigid = rigid.latches[0].energy_after;
        assert!(
            ea >= e_rigid * (1.0 - 1e-6),
            "f = {f:e}: the flexible latch keeps {ea} J < rigid {e_rigid} J"
        );
        rows.push((f, dt, db, da, (ea - e_rigid) / e_rigid, steps));
    }
    for r in &rows {
        println!(
            "stiff mast f = {:.0e}: first latch time error {:.2e} (× f = {:.1e}), rates before \
             {:.1e}, after {:.3} rad/s, energy kept above rigid {:.2e}, {} steps",
            r.0,
            r.1,
            r.1 * r.0,
            r.2,
            r.3,
            r.4,
            r.5
        );
    }
    println!("stiff mast: {:.2?}", started.elapsed());
}

/// [`stiff_mast_first_latch_converges_to_the_rigid_base`] at f = 1e5 and 1e6 (the factor the
/// issue asks for): 3.6e5 and 9.1e5 steps of the explicit integrator (its step limit is 1e6),
/// about three minutes in all. Achieved: latch time to 8.6e-11 and 6.8e-12 relative (|error|·f
/// = 8.6e-6, 6.8e-6: the 1/f law holds on), rates before the latch to 4.5e-5 and 1.4e-5 rad/s.
#[test]
#[ignore = "about three minutes: run with --ignored"]
fn stiff_mast_first_latch_at_1e5_and_1e6() {
    let sc = parse(&mast_and_wing("free", 1e4, 70e9), "stiff.toml");
    let rigid = coupled(&sc, BaseKind::Rigid).simulate(false, 30.0, 1e-12);
    for f in [1e5, 1e6] {
        let started = Instant::now();
        let (dt, db, _, _, steps) = stiff_first_latch(&sc, &rigid, f, 1e-11);
        println!(
            "f = {f:e}: latch time error {dt:.2e}, rates before {db:.1e}, {steps} steps, {:.2?}",
            started.elapsed()
        );
        assert!(dt <= 3e-5 / f && dt <= 1e-7, "f = {f:e}: {dt:e}");
        assert!(db <= 2e-2 / f.sqrt(), "f = {f:e}: rates before {db:e}");
    }
}

// ---------------------------------------------------------------------------------------
// 4. Rigid base, free 3-D hub: a second formulation in maximal coordinates
// ---------------------------------------------------------------------------------------
//
// Bodies: the base (hub + mast + lumped mass, one rigid body) and the panels, each with its
// centre of mass r, attitude quaternion q (body → inertial) and inertial velocities v, ω:
// 6 speeds per body, M = diag(m I, R I_body Rᵀ). Newton–Euler with the gyroscopic moment
// −ω × I_w ω, the hinge springs' moments k(α_ref − α) along the hinge axis (on the child
// −σ·moment·ẑ, on the parent +σ·moment·ẑ, from V = ½k(α_ref − α)² and α̇ = −σ(ω_c − ω_p)·ẑ).
// Each revolute hinge is five constraints (coincident hinge points; ẑ_parent ⟂ x_child,
// y_child), a latched hinge one more (α = α_latch). Index-1 form
// [M Gᵀ; G 0][u̇; λ] = [F; −γ] by the Schur complement G M⁻¹ Gᵀ, integrated by classical RK4
// with a fixed step; after every step the attitudes are normalised, the positions projected
// onto the constraints (Gauss–Newton in the mass metric, rotations applied exactly) and the
// velocities projected in the mass metric. A latch is located by bisection of the step length
// (one RK4 step from the step's start) and is a plastic impact: the velocity projection with
// the new lock, the kinetic-energy minimiser under every constraint. Nothing of
// `flexcraft::deploy` is used; the geometry and mass properties are computed from the
// scenario's numbers (constants below).
//
// The opening angles, on a branch continuous over (−π/2, 3π/2): hinge 1 from the base's
// (e_a, n): α₁ = π/2 − φ₁, cos α₁ = x₁·n, sin α₁ = x₁·e_a; hinge i ≥ 2 from panel i−1's
// (x, y): α_i = π − σ_i Δφ, cos α_i = −x_{i−1}·x_i, sin α_i = σ_i x_i·y_{i−1}, σ_i = (−1)^{i−1}
// (the accordion fold: stowed α = 0 folds each panel back on the previous one, deployed
// α₁ = π/2, α_i = π lays them along e_a).

type V3 = [f64; 3];
type M3 = [[f64; 3]; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: V3) -> V3 {
    scale(a, 1.0 / dot(a, a).sqrt())
}
fn mv(m: &M3, v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}
fn mt(m: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[j][i]))
}
fn mm(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}
fn madd(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + b[i][j]))
}
fn mscale(a: &M3, s: f64) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] * s))
}
fn outer(a: V3, b: V3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i] * b[j]))
}
fn ident() -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }))
}
/// Inverse of a 3×3 matrix by cofactors.
fn minv3(m: &M3) -> M3 {
    let c0 = cross(m[1], m[2]);
    let c1 = cross(m[2], m[0]);
    let c2 = cross(m[0], m[1]);
    let det = dot(m[0], c0);
    // Rows of the inverse's transpose are the cofactor rows.
    mt(&[
        scale(c0, 1.0 / det),
        scale(c1, 1.0 / det),
        scale(c2, 1.0 / det),
    ])
}
/// Parallel-axis shift: inertia about a point at `d` from the centre of mass.
fn steiner(mass: f64, d: V3) -> M3 {
    madd(
        &mscale(&ident(), mass * dot(d, d)),
        &mscale(&outer(d, d), -mass),
    )
}

type Quat = [f64; 4];

/// Rotation matrix (body → inertial) of the unit quaternion [w, x, y, z].
fn quat_matrix(q: Quat) -> M3 {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}
fn quat_mul(a: Quat, b: Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}
fn quat_of_rotation_vector(t: V3) -> Quat {
    let a = dot(t, t).sqrt();
    if a == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let s = (0.5 * a).sin() / a;
    [(0.5 * a).cos(), t[0] * s, t[1] * s, t[2] * s]
}
/// Quaternion of a rotation matrix (Shepperd's method).
fn quat_of_matrix(r: &M3) -> Quat {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let q = if tr > 0.0 {
        let s = 2.0 * (1.0 + tr).sqrt();
        [
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = 2.0 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
        [
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        ]
    } else if r[1][1] > r[2][2] {
        let s = 2.0 * (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt();
        [
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        ]
    } else {
        let s = 2.0 * (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt();
        [
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        ]
    };
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    q.map(|c| c / n)
}

/// A rigid body: mass and inertia tensor about its centre of mass in its own axes.
#[derive(Debug, Clone)]
struct Body {
    mass: f64,
    inertia: M3,
}

/// A revolute hinge between `parent` and `child` with a torsion spring and a latch.
#[derive(Debug, Clone)]
struct Joint {
    parent: usize,
    child: usize,
    /// Hinge point from each body's centre of mass, in the body's axes.
    on_parent: V3,
    on_child: V3,
    /// In the parent's axes: the hinge axis ẑ and the pair (x, y), x × y = ẑ, from which the
    /// child's direction angle is measured.
    axis: V3,
    ex: V3,
    ey: V3,
    /// σ = (−1)^(j) for hinge j (0-based): α̇ = −σ (ω_child − ω_parent)·ẑ.
    sign: f64,
    stiffness: f64,
    reference: f64,
    latch: f64,
}

#[derive(Debug, Clone)]
struct MaxSystem {
    bodies: Vec<Body>,
    joints: Vec<Joint>,
    inv_inertia: Vec<M3>,
}

/// Positions (centre of mass, attitude) and inertial velocities (v, ω) of every body.
#[derive(Debug, Clone)]
struct MaxState {
    r: Vec<V3>,
    q: Vec<Quat>,
    v: Vec<V3>,
    w: Vec<V3>,
}

/// Constraint rows over the speeds [v_0, ω_0, v_1, ω_1, …], residuals and velocity terms γ
/// (G u̇ + γ = 0 keeps c̈ = 0).
struct Rows {
    g: Vec<Vec<f64>>,
    c: Vec<f64>,
    gamma: Vec<f64>,
}

/// One latch of the maximal-coordinate run.
#[derive(Debug, Clone)]
struct MaxLatch {
    hinge: usize,
    time: f64,
    rates_before: Vec<f64>,
    rates_after: Vec<f64>,
}

impl MaxSystem {
    fn new(bodies: Vec<Body>, joints: Vec<Joint>) -> Self {
        let inv_inertia = bodies.iter().map(|b| minv3(&b.inertia)).collect();
        Self {
            bodies,
            joints,
            inv_inertia,
        }
    }

    fn nspeeds(&self) -> usize {
        6 * self.bodies.len()
    }

    /// The opening angle of hinge j, on a branch continuous over [−π/2, 3π/2).
    fn alpha(&self, s: &MaxState, j: usize) -> f64 {
        let jt = &self.joints[j];
        let ra = quat_matrix(s.q[jt.parent]);
        let rb = quat_matrix(s.q[jt.child]);
        let (xa, ya) = (mv(&ra, jt.ex), mv(&ra, jt.ey));
        let xb = mv(&rb, [1.0, 0.0, 0.0]);
        if j == 0 {
            // α₁ = π/2 − φ₁: cos α₁ = x_b·y_a, sin α₁ = x_b·x_a.
            std::f64::consts::FRAC_PI_2 + (-dot(xb, ya)).atan2(dot(xb, xa))
        } else {
            // α = π − σ Δφ: cos α = −x_a·x_b, sin α = σ x_b·y_a.
            std::f64::consts::FRAC_PI_2 + dot(xa, xb).atan2(jt.sign * dot(xb, ya))
        }
    }

    /// α̇_j = −σ (ω_child − ω_parent)·ẑ, as a row over the speeds.
    fn alpha_row(&self, s: &MaxState, j: usize) -> Vec<f64> {
        let jt = &self.joints[j];
        let z = mv(&quat_matrix(s.q[jt.parent]), jt.axis);
        let mut row = vec![0.0; self.nspeeds()];
        for k in 0..3 {
            row[6 * jt.parent + 3 + k] = jt.sign * z[k];
            row[6 * jt.child + 3 + k] = -jt.sign * z[k];
        }
        row
    }

    fn speeds(&self, s: &MaxState) -> Vec<f64> {
        let mut u = Vec::with_capacity(self.nspeeds());
        for b in 0..self.bodies.len() {
            u.extend_from_slice(&s.v[b]);
            u.extend_from_slice(&s.w[b]);
        }
        u
    }

    fn set_speeds(&self, s: &mut MaxState, u: &[f64]) {
        for b in 0..self.bodies.len() {
            s.v[b] = [u[6 * b], u[6 * b + 1], u[6 * b + 2]];
            s.w[b] = [u[6 * b + 3], u[6 * b + 4], u[6 * b + 5]];
        }
    }

    fn rates(&self, s: &MaxState) -> Vec<f64> {
        let u = self.speeds(s);
        (0..self.joints.len())
            .map(|j| {
                self.alpha_row(s, j)
                    .iter()
                    .zip(&u)
                    .map(|(a, b)| a * b)
                    .sum()
            })
            .collect()
    }

    fn rows(&self, s: &MaxState, locked: &[bool]) -> Rows {
        let n = self.nspeeds();
        let mut out = Rows {
            g: Vec::new(),
            c: Vec::new(),
            gamma: Vec::new(),
        };
        for (j, jt) in self.joints.iter().enumerate() {
            let (a, b) = (jt.parent, jt.child);
            let ra = quat_matrix(s.q[a]);
            let rb = quat_matrix(s.q[b]);
            let (pa, pb) = (mv(&ra, jt.on_parent), mv(&rb, jt.on_child));
            let (wa, wb) = (s.w[a], s.w[b]);
            // Coincident hinge points: r_a + ρ_a − r_b − ρ_b = 0.
            let gap = sub(add(s.r[a], pa), add(s.r[b], pb));
            let acc = sub(cross(wa, cross(wa, pa)), cross(wb, cross(wb, pb)));
            for k in 0..3 {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                let mut row = vec![0.0; n];
                let (ca, cb) = (cross(pa, e), cross(pb, e));
                for i in 0..3 {
                    row[6 * a + i] = e[i];
                    row[6 * a + 3 + i] = ca[i];
                    row[6 * b + i] = -e[i];
                    row[6 * b + 3 + i] = -cb[i];
                }
                out.g.push(row);
                out.c.push(gap[k]);
                out.gamma.push(acc[k]);
            }
            // Parallel axes: ẑ_a ⟂ x_b and ẑ_a ⟂ y_b.
            let za = mv(&ra, jt.axis);
            for wv in [mv(&rb, [1.0, 0.0, 0.0]), mv(&rb, [0.0, 1.0, 0.0])] {
                let d = cross(za, wv);
                let mut row = vec![0.0; n];
                for i in 0..3 {
                    row[6 * a + 3 + i] = d[i];
                    row[6 * b + 3 + i] = -d[i];
                }
                let dd = add(cross(cross(wa, za), wv), cross(za, cross(wb, wv)));
                out.g.push(row);
                out.c.push(dot(za, wv));
                out.gamma.push(dot(sub(wa, wb), dd));
            }
            if locked[j] {
                out.g.push(self.alpha_row(s, j));
                out.c.push(self.alpha(s, j) - jt.latch);
                out.gamma.push(-jt.sign * dot(sub(wb, wa), cross(wa, za)));
            }
        }
        out
    }

    /// M⁻¹ x (M = diag(m I, I_w) per body, I_w = R I Rᵀ).
    fn minv(&self, s: &MaxState, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        for (b, body) in self.bodies.iter().enumerate() {
            let r = quat_matrix(s.q[b]);
            for i in 0..3 {
                y[6 * b + i] = x[6 * b + i] / body.mass;
            }
            let t = [x[6 * b + 3], x[6 * b + 4], x[6 * b + 5]];
            let w = mv(&r, mv(&self.inv_inertia[b], mv(&mt(&r), t)));
            y[6 * b + 3..6 * b + 6].copy_from_slice(&w);
        }
        y
    }

    fn world_inertia(&self, s: &MaxState, b: usize) -> M3 {
        let r = quat_matrix(s.q[b]);
        mm(&r, &mm(&self.bodies[b].inertia, &mt(&r)))
    }

    /// y = M⁻¹ Gᵀ μ with (G M⁻¹ Gᵀ) μ = rhs.
    fn correction(&self, s: &MaxState, g: &[Vec<f64>], rhs: &[f64]) -> Vec<f64> {
        let m = g.len();
        let n = self.nspeeds();
        let mg: Vec<Vec<f64>> = g.iter().map(|row| self.minv(s, row)).collect();
        let mut a = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                a[i * m + j] = g[i].iter().zip(&mg[j]).map(|(p, q)| p * q).sum();
            }
        }
        let mut mu = rhs.to_vec();
        // Cholesky of the SPD Schur complement.
        for j in 0..m {
            let mut d = a[j * m + j];
            for k in 0..j {
                d -= a[j * m + k] * a[j * m + k];
            }
            assert!(d > 0.0, "constraint rows dependent");
            let d = d.sqrt();
            a[j * m + j] = d;
            for i in j + 1..m {
                let mut v = a[i * m + j];
                for k in 0..j {
                    v -= a[i * m + k] * a[j * m + k];
                }
                a[i * m + j] = v / d;
            }
        }
        for i in 0..m {
            let mut v = mu[i];
            for k in 0..i {
                v -= a[i * m + k] * mu[k];
            }
            mu[i] = v / a[i * m + i];
        }
        for i in (0..m).rev() {
            let mut v = mu[i];
            for k in i + 1..m {
                v -= a[k * m + i] * mu[k];
            }
            mu[i] = v / a[i * m + i];
        }
        let mut y = vec![0.0; n];
        for (row, mi) in mg.iter().zip(&mu) {
            for (yk, rk) in y.iter_mut().zip(row) {
                *yk += mi * rk;
            }
        }
        y
    }

    /// u̇ from [M Gᵀ; G 0][u̇; λ] = [F; −γ].
    fn accelerations(&self, s: &MaxState, locked: &[bool]) -> Vec<f64> {
        let n = self.nspeeds();
        let mut f = vec![0.0; n];
        for b in 0..self.bodies.len() {
            let iw = self.world_inertia(s, b);
            let gyro = cross(s.w[b], mv(&iw, s.w[b]));
            for i in 0..3 {
                f[6 * b + 3 + i] -= gyro[i];
            }
        }
        for (j, jt) in self.joints.iter().enumerate() {
            let moment = jt.stiffness * (jt.reference - self.alpha(s, j));
            for (fk, gk) in f.iter_mut().zip(self.alpha_row(s, j)) {
                *fk += moment * gk;
            }
        }
        let rows = self.rows(s, locked);
        let a0 = self.minv(s, &f);
        // G u̇ = −γ: u̇ = a0 − M⁻¹Gᵀ μ with S μ = G a0 + γ.
        let rhs: Vec<f64> = rows
            .g
            .iter()
            .zip(&rows.gamma)
            .map(|(row, gm)| row.iter().zip(&a0).map(|(p, q)| p * q).sum::<f64>() + gm)
            .collect();
        let corr = self.correction(s, &rows.g, &rhs);
        a0.iter().zip(&corr).map(|(a, c)| a - c).collect()
    }

    fn derivative(&self, s: &MaxState, locked: &[bool]) -> MaxState {
        let ud = self.accelerations(s, locked);
        let nb = self.bodies.len();
        MaxState {
            r: s.v.clone(),
            q: (0..nb)
                .map(|b| {
                    let w = s.w[b];
                    quat_mul([0.0, w[0], w[1], w[2]], s.q[b]).map(|c| 0.5 * c)
                })
                .collect(),
            v: (0..nb)
                .map(|b| [ud[6 * b], ud[6 * b + 1], ud[6 * b + 2]])
                .collect(),
            w: (0..nb)
                .map(|b| [ud[6 * b + 3], ud[6 * b + 4], ud[6 * b + 5]])
                .collect(),
        }
    }

    fn axpy(s: &MaxState, h: f64, d: &MaxState) -> MaxState {
        let f3 = |a: &[V3], b: &[V3]| -> Vec<V3> {
            a.iter()
                .zip(b)
                .map(|(x, y)| add(*x, scale(*y, h)))
                .collect()
        };
        MaxState {
            r: f3(&s.r, &d.r),
            q: s.q
                .iter()
                .zip(&d.q)
                .map(|(x, y)| std::array::from_fn(|i| x[i] + h * y[i]))
                .collect(),
            v: f3(&s.v, &d.v),
            w: f3(&s.w, &d.w),
        }
    }

    /// One classical RK4 step, then the attitudes normalised and the state projected onto
    /// the constraints.
    fn step(&self, s: &MaxState, h: f64, locked: &[bool]) -> MaxState {
        let k1 = self.derivative(s, locked);
        let k2 = self.derivative(&Self::axpy(s, 0.5 * h, &k1), locked);
        let k3 = self.derivative(&Self::axpy(s, 0.5 * h, &k2), locked);
        let k4 = self.derivative(&Self::axpy(s, h, &k3), locked);
        let mut out = s.clone();
        for (c, k) in [(1.0, &k1), (2.0, &k2), (2.0, &k3), (1.0, &k4)] {
            out = Self::axpy(&out, h * c / 6.0, k);
        }
        for q in out.q.iter_mut() {
            let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
            *q = q.map(|c| c / n);
        }
        self.project(out, locked)
    }

    /// Positions by Gauss–Newton in the mass metric (δr, δθ per body), then velocities by
    /// the mass-metric projection onto G u = 0 (also the plastic impact).
    fn project(&self, mut s: MaxState, locked: &[bool]) -> MaxState {
        for _ in 0..20 {
            let rows = self.rows(&s, locked);
            let size = rows.c.iter().fold(0.0f64, |a, c| a.max(c.abs()));
            if size < 1e-15 {
                break;
            }
            let d = self.correction(&s, &rows.g, &rows.c);
            for b in 0..self.bodies.len() {
                s.r[b] = sub(s.r[b], [d[6 * b], d[6 * b + 1], d[6 * b + 2]]);
                let th = [-d[6 * b + 3], -d[6 * b + 4], -d[6 * b + 5]];
                s.q[b] = quat_mul(quat_of_rotation_vector(th), s.q[b]);
            }
        }
        let rows = self.rows(&s, locked);
        let u = self.speeds(&s);
        let gu: Vec<f64> = rows
            .g
            .iter()
            .map(|row| row.iter().zip(&u).map(|(p, q)| p * q).sum())
            .collect();
        let d = self.correction(&s, &rows.g, &gu);
        let un: Vec<f64> = u.iter().zip(&d).map(|(a, b)| a - b).collect();
        self.set_speeds(&mut s, &un);
        s
    }

    /// Linear momentum and angular momentum about the origin.
    fn momentum(&self, s: &MaxState) -> (V3, V3) {
        let (mut p, mut l) = ([0.0; 3], [0.0; 3]);
        for (b, body) in self.bodies.iter().enumerate() {
            let pb = scale(s.v[b], body.mass);
            p = add(p, pb);
            l = add(
                l,
                add(cross(s.r[b], pb), mv(&self.world_inertia(s, b), s.w[b])),
            );
        }
        (p, l)
    }

    /// Runs with the fixed step h until every hinge has latched or `end`. Latches are
    /// located by bisection of the step length (one RK4 step from the step's start).
    fn run(&self, s0: MaxState, h: f64, end: f64) -> (Vec<MaxLatch>, MaxState, f64) {
        let n = self.joints.len();
        let mut locked = vec![false; n];
        let mut s = self.project(s0, &locked);
        let mut t = 0.0;
        let mut latches = Vec::new();
        let excess = |st: &MaxState, locked: &[bool]| -> Option<(usize, f64)> {
            (0..n)
                .filter(|&j| !locked[j])
                .map(|j| (j, self.alpha(st, j) - self.joints[j].latch))
                .max_by(|a, b| a.1.total_cmp(&b.1))
        };
        while t < end && locked.iter().any(|l| !l) {
            let hs = h.min(end - t);
            let next = self.step(&s, hs, &locked);
            if excess(&next, &locked).is_none_or(|e| e.1 < 0.0) {
                s = next;
                t += hs;
                continue;
            }
            let (mut lo, mut hi) = (0.0, hs);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                let x = self.step(&s, mid, &locked);
                if excess(&x, &locked).is_some_and(|e| e.1 >= 0.0) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let x = self.step(&s, hi, &locked);
            let (j, _) = excess(&x, &locked).unwrap();
            t += hi;
            let rates_before = self.rates(&x);
            locked[j] = true;
            s = self.project(x, &locked);
            latches.push(MaxLatch {
                hinge: j + 1,
                time: t,
                rates_before,
                rates_after: self.rates(&s),
            });
        }
        (latches, s, t)
    }
}

const HUB_MASS: f64 = 40.0;
const HUB_INERTIA: [f64; 3] = [6.0, 8.0, 9.0];
const HUB_CM: V3 = [0.05, -0.1, 0.08];
const DENSITY: f64 = 1600.0;
const MAST_ROOT: V3 = [0.5, 0.2, -0.1];
const MAST_AXIS: V3 = [1.0, 0.5, -0.4];
const MAST_LENGTH: f64 = 2.0;
const MAST_OD: f64 = 0.08;
const MAST_WALL: f64 = 0.003;
const BOX_POINT: V3 = [-0.3, 0.4, 0.35];
const BOX_OFFSET: V3 = [0.1, 0.2, -0.15];
const BOX_MASS: f64 = 12.0;
const BOX_INERTIA: [f64; 3] = [0.3, 0.4, 0.5];
const WING_AXIS: V3 = [2.0, 2.0, 1.0];
const WING_NORMAL: V3 = [1.0, -2.0, 2.0];
const WING_LENGTH: f64 = 2.4;
const WING_WIDTH: f64 = 0.6;
const WING_DENSITY: f64 = 4.0;
const PANELS: usize = 3;
const HINGE_K: [f64; 3] = [1.2, 0.6, 0.4];
const PRELOAD: f64 = 0.4;

fn v3(a: V3) -> String {
    format!("[{:?}, {:?}, {:?}]", a[0], a[1], a[2])
}

fn free_3d_case() -> String {
    format!(
        r#"
name = "free hub, offset mast, wing out of the principal planes"
format_version = 1
[hub]
motion = "free"
mass = {hm:?}
inertia = {hi}
center_of_mass = {hc}
[materials.cfrp]
youngs_modulus = 1.0e11
poisson_ratio = 0.3
density = {rho:?}
[[beams]]
name = "mast"
parent = "hub"
root = {mr}
axis = {ma}
length = {ml:?}
material = "cfrp"
section = {{ tube = {{ outer_diameter = {od:?}, wall = {wall:?} }} }}
terms = {{ bending = 3, torsion = 2, axial = 2 }}
[[masses]]
name = "box"
parent = "hub"
point = {bp}
offset = {bo}
mass = {bm:?}
inertia = {bi}
[[plates]]
name = "wing"
parent = "mast"
station = {ml:?}
length_axis = {wa}
normal = {wn}
length = {wl:?}
width = {ww:?}
areal_density = {wd:?}
bending_stiffness = 1.0e3
poisson_ratio = 0.3
terms = {{ length = 3, width = 2 }}
[deployment]
plate = "wing"
panels = {np}
end_time = 20.0
[deployment.hinge]
preload_angle = {pre:?}
[[deployment.hinges]]
stiffness = {k0:?}
[[deployment.hinges]]
stiffness = {k1:?}
[[deployment.hinges]]
stiffness = {k2:?}
"#,
        hm = HUB_MASS,
        hi = v3(HUB_INERTIA),
        hc = v3(HUB_CM),
        rho = DENSITY,
        mr = v3(MAST_ROOT),
        ma = v3(MAST_AXIS),
        ml = MAST_LENGTH,
        od = MAST_OD,
        wall = MAST_WALL,
        bp = v3(BOX_POINT),
        bo = v3(BOX_OFFSET),
        bm = BOX_MASS,
        bi = v3(BOX_INERTIA),
        wa = v3(WING_AXIS),
        wn = v3(WING_NORMAL),
        wl = WING_LENGTH,
        ww = WING_WIDTH,
        wd = WING_DENSITY,
        np = PANELS,
        pre = PRELOAD,
        k0 = HINGE_K[0],
        k1 = HINGE_K[1],
        k2 = HINGE_K[2],
    )
}

/// The maximal-coordinate model of [`free_3d_case`] built from its numbers alone, its state at
/// release, and the base's centre of mass (structure frame).
fn maximal_model() -> (MaxSystem, MaxState, V3) {
    use std::f64::consts::PI;
    let diag = |d: [f64; 3]| -> M3 { [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]] };
    // Mast: a line mass ρA L with ρ I_p per length about its axis (no rotary inertia of the
    // section about transverse axes: the beam model's kinetic energy).
    let (ro, ri) = (0.5 * MAST_OD, 0.5 * MAST_OD - MAST_WALL);
    let area = PI * (ro * ro - ri * ri);
    let ip = 0.5 * PI * (ro.powi(4) - ri.powi(4));
    let e = unit(MAST_AXIS);
    let m_mast = DENSITY * area * MAST_LENGTH;
    let c_mast = add(MAST_ROOT, scale(e, 0.5 * MAST_LENGTH));
    let i_mast = madd(
        &mscale(
            &madd(&ident(), &mscale(&outer(e, e), -1.0)),
            m_mast * MAST_LENGTH * MAST_LENGTH / 12.0,
        ),
        &mscale(&outer(e, e), DENSITY * ip * MAST_LENGTH),
    );
    let c_box = add(BOX_POINT, BOX_OFFSET);
    let parts = [
        (HUB_MASS, HUB_CM, diag(HUB_INERTIA)),
        (m_mast, c_mast, i_mast),
        (BOX_MASS, c_box, diag(BOX_INERTIA)),
    ];
    let mass: f64 = parts.iter().map(|p| p.0).sum();
    let cm = scale(
        parts.iter().fold([0.0; 3], |a, p| add(a, scale(p.1, p.0))),
        1.0 / mass,
    );
    let inertia = parts.iter().fold([[0.0; 3]; 3], |a, p| {
        madd(&a, &madd(&p.2, &steiner(p.0, sub(p.1, cm))))
    });
    // Hinge frame: e_a, n, ẑ = e_a × n; hinge 1 at the mast tip.
    let ea = unit(WING_AXIS);
    let nn = unit(WING_NORMAL);
    let z = cross(ea, nn);
    let h0 = add(MAST_ROOT, scale(e, MAST_LENGTH));
    let l = WING_LENGTH / PANELS as f64;
    let mp = WING_DENSITY * l * WING_WIDTH;
    let panel = Body {
        mass: mp,
        inertia: diag([
            mp * WING_WIDTH * WING_WIDTH / 12.0,
            mp * (l * l + WING_WIDTH * WING_WIDTH) / 12.0,
            mp * l * l / 12.0,
        ]),
    };
    let mut bodies = vec![Body { mass, inertia }];
    let mut joints = Vec::new();
    let latch = [PI / 2.0, PI, PI];
    for j in 0..PANELS {
        bodies.push(panel.clone());
        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
        let (on_parent, axis, ex, ey) = if j == 0 {
            (sub(h0, cm), z, ea, nn)
        } else {
            (
                [0.5 * l, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
            )
        };
        joints.push(Joint {
            parent: j,
            child: j + 1,
            on_parent,
            on_child: [-0.5 * l, 0.0, 0.0],
            axis,
            ex,
            ey,
            sign,
            stiffness: HINGE_K[j],
            reference: latch[j] + PRELOAD,
            latch: latch[j],
        });
    }
    // Release: at rest, α = 0 (stowed): φ₁ = π/2, φ_i = φ_{i−1} + s_i π.
    let mut s = MaxState {
        r: vec![cm],
        q: vec![[1.0, 0.0, 0.0, 0.0]],
        v: vec![[0.0; 3]; PANELS + 1],
        w: vec![[0.0; 3]; PANELS + 1],
    };
    let (mut hinge, mut phi) = (h0, PI / 2.0);
    for j in 0..PANELS {
        if j > 0 {
            phi += if j % 2 == 1 { -PI } else { PI };
        }
        let x = add(scale(ea, phi.cos()), scale(nn, phi.sin()));
        let y = cross(z, x);
        let rot = mt(&[x, y, z]);
        s.r.push(add(hinge, scale(x, 0.5 * l)));
        s.q.push(quat_of_matrix(&rot));
        hinge = add(hinge, scale(x, l));
    }
    (MaxSystem::new(bodies, joints), s, cm)
}

/// Rotation vector (axis × angle) of a rotation matrix's quaternion.
fn rotation_vector(r: &M3) -> V3 {
    let q = quat_of_matrix(r);
    let (w, v) = if q[0] < 0.0 {
        (-q[0], [-q[1], -q[2], -q[3]])
    } else {
        (q[0], [q[1], q[2], q[3]])
    };
    let s = dot(v, v).sqrt();
    if s == 0.0 {
        return [0.0; 3];
    }
    scale(v, 2.0 * s.atan2(w) / s)
}

/// `BaseKind::Rigid` with a free hub, the mast and a lumped mass on an offset arm in the base,
/// the wing's plane (e_a ∥ (2, 2, 1), n ∥ (1, −2, 2), hinge axes ∥ (2, −1, −2)) in no principal
/// plane of the base: the hub's motion is genuinely 3-D (it turns by ≈ 0.18 rad, ≈ 0.17 rad of
/// it about axes perpendicular to the hinges). Against the maximal-coordinate formulation
/// above, whose base is one rigid body with mass, centre of mass and inertia computed here
/// from the scenario's numbers (hub; mast as a line mass ρA L, inertia ρAL³/12 across and
/// ρI_p L about its axis — the beam model has no rotary inertia of the section in bending;
/// lumped mass at point + offset with its own inertia; parallel-axis sums) and whose panels
/// are thin plates (μ l w; m w²/12, m(l² + w²)/12, m l²/12).
///
/// The reference converges as h⁴ (latch times: 2.8e-9, 1.7e-10, 1.1e-11 relative to the
/// coupled model at h = 4, 2, 1 ms); at h = 1 ms it conserves linear momentum to rounding and
/// angular momentum to 1e-10. Achieved at h = 1 ms: the three latch times to 2e-11 relative,
/// the opening rates before and after each latch to 8e-9 rad/s (of up to 7.5 rad/s), the
/// hub's attitude after the last latch to 1e-12 and its position to 1e-12 m. Asserted:
/// latch times 1e-9, rates 1e-7 of the largest, attitude and position 1e-9.
#[test]
fn rigid_base_with_a_free_3d_hub_agrees_with_maximal_coordinates() {
    let started = Instant::now();
    let sc = parse(&free_3d_case(), "free3d.toml");
    let c = coupled(&sc, BaseKind::Rigid);
    assert_eq!((c.hub_dof(), c.modes()), (6, 0));
    let run = c.simulate(false, 20.0, 1e-12);
    assert!(run.all_latched && run.latches.len() == PANELS, "{run:?}");
    let (sys, s0, cm) = maximal_model();
    let (coarse, _, _) = sys.run(s0.clone(), 2e-3, 20.0);
    let (reference, end, t_end) = sys.run(s0, 1e-3, 20.0);
    assert_eq!(reference.len(), PANELS);
    // The reference converged (RK4: the error falls 16-fold when h halves).
    for (a, b) in reference.iter().zip(&coarse) {
        assert_eq!(a.hinge, b.hinge);
        assert!(
            rel(a.time, b.time) <= 2e-9,
            "reference h = 1 ms vs 2 ms: {} vs {}",
            a.time,
            b.time
        );
    }
    // Momentum: zero from rest.
    let rate_scale = reference
        .iter()
        .flat_map(|l| l.rates_before.iter())
        .fold(0.0f64, |a, r| a.max(r.abs()));
    let l = WING_LENGTH / PANELS as f64;
    let panel_momentum = WING_DENSITY * l * WING_WIDTH * l * rate_scale;
    let (p, h) = sys.momentum(&end);
    assert!(
        dot(p, p).sqrt() <= 1e-12 * panel_momentum && dot(h, h).sqrt() <= 1e-9 * panel_momentum,
        "reference momentum {p:?}, {h:?}"
    );
    let mut worst = (0.0f64, 0.0f64);
    for (a, b) in run.latches.iter().zip(&reference) {
        assert_eq!(a.hinge, b.hinge, "latch order");
        assert!(
            rel(a.time, b.time) <= 1e-9,
            "hinge {}: coupled {} s vs maximal {} s",
            a.hinge,
            a.time,
            b.time
        );
        let dr = max_abs_diff(&a.rates_before, &b.rates_before)
            .max(max_abs_diff(&a.rates_after, &b.rates_after));
        assert!(
            dr <= 1e-7 * rate_scale,
            "hinge {}: rates before {:?} / {:?}, after {:?} / {:?}",
            a.hinge,
            a.rates_before,
            b.rates_before,
            a.rates_after,
            b.rates_after
        );
        worst = (worst.0.max(rel(a.time, b.time)), worst.1.max(dr));
    }
    assert!(rel(run.final_time, t_end) <= 1e-9);
    // The hub after the last latch: attitude and centre of mass.
    let v = c.view(&run.final_state);
    let (a_coupled, a_max) = (quat_matrix(v.quat), quat_matrix(end.q[0]));
    let da = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| (a_coupled[i][j] - a_max[i][j]).abs())
        .fold(0.0, f64::max);
    assert!(da <= 1e-9, "hub attitude {a_coupled:?} vs {a_max:?}");
    let hub_max = add(end.r[0], mv(&a_max, sub(HUB_CM, cm)));
    let hub_coupled = add(HUB_CM, v.r.0);
    let dx = max_abs_diff(&hub_max, &hub_coupled);
    assert!(dx <= 1e-9, "hub centre {hub_coupled:?} vs {hub_max:?}");
    // Genuinely 3-D: the hub turns about axes off the hinge axis.
    let theta = rotation_vector(&a_max);
    let z = unit(cross(unit(WING_AXIS), unit(WING_NORMAL)));
    let off_axis = cross(theta, z);
    let off = dot(off_axis, off_axis).sqrt();
    assert!(
        off > 0.1,
        "hub rotation {theta:?} is nearly about the hinge axis {z:?}"
    );
    println!(
        "3-D rigid base vs maximal coordinates: latches {:?}; worst time {:.1e} relative, \
         rates {:.1e} rad/s; hub attitude {da:.1e}, centre {dx:.1e} m; hub rotation {theta:.4?} \
         ({off:.3} rad off the hinge axis); {:.2?}",
        run.latches
            .iter()
            .map(|l| (l.hinge, l.time))
            .collect::<Vec<_>>(),
        worst.0,
        worst.1,
        started.elapsed()
    );
}

// ---------------------------------------------------------------------------------------
// 5. Modes along the deployment (`deploy::sweep`)
// ---------------------------------------------------------------------------------------

/// The sweep's frozen-configuration modes at the latched, straight state are the modes of the
/// mast with a rigid wing (the Ritz model of the structure with the plate's coordinates
/// removed, as in test 1): every hinge rigid, the held hub.
#[test]
fn sweep_modes_at_the_latched_state_are_those_of_the_mast_with_a_rigid_wing() {
    use flexcraft::deploy::sweep::linear_frequencies;
    let sc = parse(&mast_and_wing("fixed", 1.0e4, 70e9), "sweep.toml");
    let c = coupled(&sc, BaseKind::Flexible { modes: None });
    let y = locked_straight(&c);
    let n = c.panels();
    let w = linear_frequencies(&c, &y, &vec![false; n], &vec![false; n]).expect("modes");
    let exact = rigid_wing_ritz_frequencies(&sc);
    assert_eq!(w.len(), exact.len());
    for (i, (a, e)) in w.iter().zip(&exact).enumerate() {
        assert!(
            rel(*a, *e) <= 1e-9,
            "mode {}: sweep {a} vs rigid-wing Ritz {e}",
            i + 1
        );
    }
}

/// At a partly deployed state (every hinge half-way), panels on stiffer and stiffer hinge
/// springs: the modes that stay finite converge to those of the array clamped at that
/// configuration (every hinge rigid), with an error falling as 1/k (the springs' compliance);
/// free hub, so the six rigid modes are left out of both.
#[test]
fn sweep_modes_on_stiff_hinges_converge_to_the_clamped_array() {
    use flexcraft::deploy::sweep::linear_frequencies;
    let sc = parse(&mast_and_wing("free", 1.0e4, 70e9), "sweep_free.toml");
    let mut c = coupled(&sc, BaseKind::Flexible { modes: Some(8) });
    assert_eq!(c.hub_dof(), 6);
    let n = c.panels();
    let mut y = c.initial_state();
    let off = c.alpha_offset();
    for (i, h) in c.chain.hinges.iter().enumerate() {
        y[off + i] = 0.5 * (h.initial_angle + h.latch_angle);
    }
    let clamped = linear_frequencies(&c, &y, &vec![false; n], &vec![false; n]).unwrap();
    assert_eq!(clamped.len(), 8);
    let mut errors = Vec::new();
    for k in [1e8, 1e10, 1e12] {
        for h in &mut c.chain.hinges {
            h.stiffness = k;
        }
        let w = linear_frequencies(&c, &y, &vec![true; n], &vec![false; n]).unwrap();
        assert_eq!(w.len(), 8 + n);
        // The clamped modes are the first 8 once the hinge modes (∝ √k) are above them.
        let err = clamped
            .iter()
            .zip(&w)
            .map(|(a, b)| rel(*b, *a))
            .fold(0.0, f64::max);
        // Springs add compliance: every frequency at or below the clamped one.
        for (a, b) in clamped.iter().zip(&w) {
            assert!(*b <= *a * (1.0 + 1e-10), "k = {k:e}: {b} above clamped {a}");
        }
        errors.push(err);
    }
    assert!(errors[2] < 1e-5, "k = 1e12: {}", sci(&errors));
    assert!(
        errors[1] < errors[0] / 50.0 && errors[2] < errors[1] / 50.0,
        "1/k convergence: {}",
        sci(&errors)
    );
}
