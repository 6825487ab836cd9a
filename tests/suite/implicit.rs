//! The implicit integrator of the coupled deployment (Rodas5P with the model's analytic stiff
//! Jacobian, docs/theory.md §2.6) against independent truths: the explicit DOPRI5 at a tight
//! tolerance as the reference run, finite differences of the right-hand side for the
//! Jacobian, and the closed-form damped oscillator for `base_damping_ratio`.

use flexcraft::deploy::base::BaseKind;
use flexcraft::deploy::{simulate_coupled, Deployment, Integrator};
use flexcraft::faer::Mat;
use flexcraft::ode::{OdeSystem, Rodas5P};
use flexcraft::scenario::Scenario;

use super::common::edited_example as scenario;

/// The seed's deployment (free hub, ideal cable, all three hinges latch at once) with
/// `modes` base modes, the integrator and tolerance given.
fn seed(modes: usize, integrator: Integrator, tol: f64) -> (Scenario, Deployment) {
    let sc = scenario("seed.toml", |s| s);
    let d = Deployment {
        base: BaseKind::Flexible { modes: Some(modes) },
        integrator,
        tolerance: tol,
        ..sc.deployment.clone().unwrap()
    };
    (sc, d)
}

/// Seed with 4 base modes: Rodas5P with the analytic stiff Jacobian at tolerance 1e-8 gives
/// the latch time, the rates before and after and the base impulse of DOPRI5 at 1e-11 (the
/// reference, converged to ~1e-12) to 1e-9 relative (rates 1e-7, impulse 1e-6), and the
/// peak mast root moment to 1e-4.
#[test]
fn implicit_with_the_analytic_jacobian_matches_the_explicit_reference() {
    let (sc, d_ref) = seed(4, Integrator::Explicit, 1e-11);
    let (_, reference) = simulate_coupled(&sc.structure, &d_ref).unwrap();
    let (_, d) = seed(4, Integrator::Implicit, 1e-8);
    let (_, fast) = simulate_coupled(&sc.structure, &d).unwrap();
    assert!(reference.all_latched && fast.all_latched);
    assert_eq!(reference.latches.len(), 1);
    assert_eq!(fast.latches.len(), 1);
    let (a, b) = (&fast.latches[0], &reference.latches[0]);
    let rel = (a.time - b.time).abs() / b.time;
    assert!(rel <= 1e-9, "latch {} s vs {} s ({rel:e})", a.time, b.time);
    let rate_scale = b.rates_before.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    for (x, y) in a
        .rates_before
        .iter()
        .zip(&b.rates_before)
        .chain(a.rates_after.iter().zip(&b.rates_after))
    {
        assert!((x - y).abs() <= 1e-7 * rate_scale, "rate {x} vs {y}");
    }
    let (fa, ma) = a.base_impulse.unwrap();
    let (fb, mb) = b.base_impulse.unwrap();
    let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let diff = |u: [f64; 3], v: [f64; 3]| norm([u[0] - v[0], u[1] - v[1], u[2] - v[2]]);
    assert!(diff(fa, fb) <= 1e-6 * norm(fb), "impulse {fa:?} vs {fb:?}");
    assert!(
        diff(ma, mb) <= 1e-6 * norm(mb),
        "moment impulse {ma:?} vs {mb:?}"
    );
    // The peak mast root moment (tracked at every step end): the implicit steps are longer,
    // so the parabola through three observations carries its O(h³) error.
    let scale = reference.load_peaks.iter().fold(0.0f64, |m, p| m.max(p.0));
    assert_eq!(fast.load_peaks.len(), reference.load_peaks.len());
    for (pa, pb) in fast.load_peaks.iter().zip(&reference.load_peaks) {
        assert!(
            (pa.0 - pb.0).abs() <= 1e-4 * scale,
            "peak load {} vs {} (largest {scale})",
            pa.0,
            pb.0
        );
    }
}

/// The analytic Jacobian's stiff columns (base modal coordinates, the captured latch's
/// angle; not the rates' columns, where the omitted ∂c/∂u is of the dampers' size) against forward differences of the right-hand side at a deformed, moving
/// state, the latch 1 mrad past its angle: the base's columns (ω_j² up to 3.8e5 s⁻²) equal to
/// 1e-5 of the column's size, the latch's (k_L/J ≈ 1e3 s⁻²) to 5e-3 (2e-3 measured; what is left out — the
/// configuration dependence of M and c, ∂M/∂α u̇ with the latch's 100 N·m acting — is of
/// the slow motion's size), and the kinematic rows exact.
#[test]
fn stiff_jacobian_matches_finite_differences_on_its_stiff_columns() {
    let sc = scenario("seed_compliant.toml", |s| s);
    let d = Deployment {
        base: BaseKind::Flexible { modes: Some(6) },
        ..sc.deployment.clone().unwrap()
    };
    let c = d.coupled(&sc.structure).unwrap();
    let (np, ns) = (c.positions(), c.speeds());
    let n = np + ns;
    let mut y = c.initial_state();
    let (pe, m, nh) = (7, c.modes(), c.panels());
    for k in 0..m {
        y[pe + k] = 1e-4 / (k + 1) as f64;
        y[np + 6 + k] = 1e-3 / (k + 1) as f64;
    }
    y[np + 4] = 2e-4; // hub rate ω_y
    for i in 0..nh {
        y[pe + m + i] = c.chain.hinges[i].latch_angle - 1e-3;
        y[np + 6 + m + i] = if i == 0 { 0.05 } else { 0.1 };
    }
    let free = vec![true; nh];
    let captured = vec![true, false, false];
    let mut jac = Mat::zeros(n, n);
    c.stiff_jacobian(&y, &free, &captured, &mut jac);
    let f = |y: &[f64]| {
        let mut dy = vec![0.0; n];
        c.rhs_captured(y, &free, &captured, &mut dy);
        dy
    };
    let f0 = f(&y);
    let stiff: Vec<usize> = (0..m).map(|k| pe + k).chain([pe + m]).collect();
    for &col in &stiff {
        let tol = if col < pe + m { 1e-5 } else { 5e-3 };
        let dlt = 1e-7 * y[col].abs().max(1e-3);
        let mut yp = y.clone();
        yp[col] += dlt;
        let fp = f(&yp);
        let fd: Vec<f64> = (0..n).map(|r| (fp[r] - f0[r]) / dlt).collect();
        let size = fd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for r in 0..n {
            assert!(
                (jac[(r, col)] - fd[r]).abs() <= tol * size,
                "column {col}, row {r}: analytic {} vs differences {} (column size {size})",
                jac[(r, col)],
                fd[r]
            );
        }
    }
    // Kinematic rows: η̇ and α̇ positions from the speeds (identity).
    for k in 0..m + nh {
        assert_eq!(jac[(pe + k, np + 6 + k)], 1.0);
    }
}

/// The coupled model with the panels locked, as an [`OdeSystem`] with its analytic stiff
/// Jacobian: what the implicit integrator steps.
struct Locked<'a> {
    c: &'a flexcraft::deploy::coupled::Coupled,
    free: Vec<bool>,
}

impl OdeSystem for Locked<'_> {
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        self.c.rhs(y, &self.free, dy);
    }
    fn jacobian(&self, _t: f64, y: &[f64], jac: &mut Mat<f64>) -> bool {
        let captured = vec![false; self.free.len()];
        self.c.stiff_jacobian(y, &self.free, &captured, jac);
        true
    }
}

/// `base_damping_ratio`: with massless panels locked from the start and a held hub, the base's
/// hub-fixed modes are uncoupled (mass-normalised: M_ee = I), so mode 1 released with a rate
/// is the damped oscillator η = (η̇₀/ω_d) e^{−ζωt} sin ω_d t, ω_d = ω √(1 − ζ²) (the truth).
/// The model's right-hand side, integrated by a classical RK4 written here with a step far
/// below the highest kept mode's period, agrees to 1e-6 of the amplitude; the implicit
/// integrator (Rodas5P with the model's stiff Jacobian, tolerance 1e-9) to 1e-5 at its step
/// ends; with ζ = 0 the same runs keep the amplitude (the undamped sine, same bounds).
#[test]
fn base_damping_ratio_damps_each_mode_at_its_modal_rate() {
    let sc = scenario("seed.toml", |s| {
        s.replace("motion = \"free\"", "motion = \"fixed\"")
            .replace("areal_density = 8.0", "areal_density = 1e-6")
    });
    for zeta in [0.02, 0.0] {
        let d = Deployment {
            base: BaseKind::Flexible { modes: Some(3) },
            base_damping_ratio: zeta,
            ..sc.deployment.clone().unwrap()
        };
        let c = d.coupled(&sc.structure).unwrap();
        assert_eq!(c.hub_dof(), 0);
        let (np, m) = (c.positions(), c.modes());
        let mut y0 = c.initial_state();
        let nh = c.panels();
        // Locked at the latch angles, at rest; mode 1 given a rate.
        for i in 0..nh {
            y0[m + i] = c.chain.hinges[i].latch_angle;
            y0[np + m + i] = 0.0;
        }
        let rate0 = 1e-3;
        y0[np] = rate0;
        let w = c.base.omega[0];
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let exact = |t: f64| rate0 / wd * (-zeta * w * t).exp() * (wd * t).sin();
        let amplitude = rate0 / wd;
        let t_end = 5.0 * 2.0 * std::f64::consts::PI / w;
        let sys = Locked {
            c: &c,
            free: vec![false; nh],
        };
        let n = y0.len();
        // Classical RK4: an integrator of the model's own right-hand side written here.
        let mut y = y0.clone();
        let h = 0.05 / c.base.omega[m - 1];
        let steps = (t_end / h).ceil() as usize;
        let h = t_end / steps as f64;
        let f = |y: &[f64]| {
            let mut dy = vec![0.0; n];
            sys.rhs(0.0, y, &mut dy);
            dy
        };
        let mut worst: f64 = 0.0;
        for s in 0..steps {
            let k1 = f(&y);
            let y2: Vec<f64> = (0..n).map(|i| y[i] + 0.5 * h * k1[i]).collect();
            let k2 = f(&y2);
            let y3: Vec<f64> = (0..n).map(|i| y[i] + 0.5 * h * k2[i]).collect();
            let k3 = f(&y3);
            let y4: Vec<f64> = (0..n).map(|i| y[i] + h * k3[i]).collect();
            let k4 = f(&y4);
            for i in 0..n {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            let t = (s + 1) as f64 * h;
            worst = worst.max((y[0] - exact(t)).abs());
        }
        assert!(
            worst <= 1e-6 * amplitude,
            "ζ = {zeta}, RK4: mode 1 against the damped oscillator: worst {worst:e} (amplitude \
             {amplitude:e})"
        );
        // The implicit integrator.
        let mut rodas = Rodas5P::new(1e-9, 1e-9 * amplitude, t_end);
        let (mut t, mut y) = (0.0, y0.clone());
        let (mut worst, mut steps) = (0.0_f64, 0);
        while t < t_end {
            rodas.step(&sys, &mut t, &mut y, t_end);
            steps += 1;
            assert!(steps < 100_000, "ζ = {zeta}: Rodas5P stalled at t = {t}");
            worst = worst.max((y[0] - exact(t)).abs());
        }
        assert!(
            worst <= 1e-5 * amplitude,
            "ζ = {zeta}, Rodas5P: mode 1 against the damped oscillator: worst {worst:e} \
             (amplitude {amplitude:e}, {steps} steps)"
        );
        // Over five periods the damped envelope has fallen by e^{−10πζ}; the undamped one not.
        let envelope = (-zeta * w * t_end).exp();
        let last = (y[0].powi(2) + (y[np] / wd).powi(2)).sqrt();
        assert!(
            (last - amplitude * envelope).abs() <= 1e-3 * amplitude,
            "ζ = {zeta}: amplitude after five periods {last:e}, expected {:e}",
            amplitude * envelope
        );
    }
}
