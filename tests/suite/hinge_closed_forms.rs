//! Hinge viscous damping and Coulomb friction (docs/theory.md §2.1; issue 43) against the
//! closed forms of a single hinged panel.
//!
//! One rigid panel on a held hub (`[hub] motion = "fixed"`, `[deployment] base = "rigid"`)
//! turns about its hinge line, so its opening angle obeys exactly
//! J α̈ = k (α_ref − α) − c α̇ − f sgn(α̇), with J the panel's moment of inertia about the
//! hinge line. Every test computes J from the scenario's own numbers — a uniform plate of
//! areal density ρ_A, width w and length L rotating about its edge, m = ρ_A L w,
//! J = m L²/12 + m (L/2)² = m L²/3 — never from the library, and places the latch angle
//! beyond every angle the motion reaches, so the panel swings freely until `end_time`.

use flexcraft::deploy::{simulate_coupled, DeploymentResult, RunStatus, Sample};
use flexcraft::Scenario;

/// The documented friction regularisation (docs/scenario.md `[deployment.hinge]`): below this
/// rate (rad/s) sgn(α̇) is replaced by α̇/ε.
const FRICTION_RATE: f64 = 1e-6;

/// The panel: a plate of length L, width w, areal density ρ_A, cut into one panel.
#[derive(Debug, Clone, Copy)]
struct Plate {
    length: f64,
    width: f64,
    areal_density: f64,
}

impl Plate {
    /// J = m L²/3 about the hinge line (edge), m = ρ_A L w.
    fn inertia_about_hinge(&self) -> f64 {
        let m = self.areal_density * self.length * self.width;
        m * self.length * self.length / 3.0
    }
}

/// The hinge: spring k about α_ref, damper c, Coulomb friction f, released from rest at α₀.
#[derive(Debug, Clone, Copy)]
struct Hinge {
    stiffness: f64,
    damping: f64,
    friction: f64,
    reference: f64,
    initial: f64,
    latch: f64,
}

/// The scenario text: one panel on a held hub, a rigid base, the hinge of `h`, `run` the
/// lines choosing the integrator (empty: the default automatic one).
fn scenario(p: Plate, h: Hinge, end_time: f64, output_rate: f64, run: &str) -> String {
    format!(
        r#"
name = "one hinged panel"
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
length = {length:?}
width = {width:?}
areal_density = {rho:?}
bending_stiffness = 1.0e4
poisson_ratio = 0.3
terms = {{ length = 3, width = 2 }}
[deployment]
plate = "wing"
panels = 1
base = "rigid"
end_time = {end_time:?}
output_rate = {output_rate:?}
{run}
[[deployment.hinges]]
stiffness = {k:?}
reference_angle = {reference:?}
damping = {c:?}
friction = {f:?}
latch_angle = {latch:?}
initial_angle = {initial:?}
"#,
        length = p.length,
        width = p.width,
        rho = p.areal_density,
        k = h.stiffness,
        c = h.damping,
        f = h.friction,
        reference = h.reference,
        latch = h.latch,
        initial = h.initial,
    )
}

/// Parses and runs the scenario (the library's route of `flexcraft deploy`).
fn run(src: &str) -> DeploymentResult {
    let sc = Scenario::from_toml_str(src, "hinge.toml").unwrap_or_else(|e| panic!("{e}"));
    let d = sc.deployment.as_ref().expect("a [deployment] section");
    simulate_coupled(&sc.structure, d).expect("deployment").1
}

/// The underdamped oscillator J ẍ + c ẋ + k x = 0, x = α − α_ref, released from rest at x₀:
/// x(t) = x₀ e^{−ζωt} (cos ω_d t + ζ/√(1−ζ²) sin ω_d t),
/// ẋ(t) = −x₀ ω/√(1−ζ²) e^{−ζωt} sin ω_d t,
/// ω = √(k/J), ζ = c/(2√(kJ)), ω_d = ω√(1−ζ²).
#[derive(Debug, Clone, Copy)]
struct Damped {
    x0: f64,
    omega: f64,
    zeta: f64,
}

impl Damped {
    fn new(k: f64, c: f64, j: f64, x0: f64) -> Self {
        let zeta = c / (2.0 * (k * j).sqrt());
        assert!(zeta < 1.0, "underdamped: ζ = {zeta}");
        Self {
            x0,
            omega: (k / j).sqrt(),
            zeta,
        }
    }

    /// (x, ẋ) at t.
    fn at(&self, t: f64) -> (f64, f64) {
        let s = (1.0 - self.zeta * self.zeta).sqrt();
        let wd = self.omega * s;
        let e = (-self.zeta * self.omega * t).exp();
        let (sn, cs) = (wd * t).sin_cos();
        (
            self.x0 * e * (cs + self.zeta / s * sn),
            -self.x0 * self.omega / s * e * sn,
        )
    }
}

/// Composite Simpson's rule over equally spaced values (an even number of intervals).
fn simpson(values: &[f64], h: f64) -> f64 {
    let n = values.len() - 1;
    assert!(n >= 2 && n % 2 == 0, "{n} intervals");
    let inner: f64 = (1..n)
        .map(|i| if i % 2 == 1 { 4.0 } else { 2.0 } * values[i])
        .sum();
    h / 3.0 * (values[0] + inner + values[n])
}

/// The run ended at its end time with no latch and no divergence.
fn assert_free_swing(r: &DeploymentResult, end_time: f64) {
    assert_eq!(r.status, RunStatus::EndTime, "{:?}", r.warnings);
    assert!(r.latches.is_empty() && r.captures.is_empty());
    assert!((r.final_time - end_time).abs() < 1e-9 * end_time);
}

/// The samples at k / output_rate (every one of them, in order).
fn samples(r: &DeploymentResult, output_rate: f64) -> Vec<&Sample> {
    let s: Vec<&Sample> = r.samples.iter().collect();
    for (i, x) in s.iter().enumerate() {
        assert!(
            (x.t - i as f64 / output_rate).abs() < 1e-12 * (1.0 + x.t),
            "sample {i} at t = {}",
            x.t
        );
    }
    s
}

/// Viscous damping, explicit integrator (DOPRI5 at tolerance 1e-12). Truth: the underdamped
/// oscillator J α̈ + c α̇ + k (α − α_ref) = 0 from rest,
/// α(t) = α_ref + (α₀ − α_ref) e^{−ζωt}(cos ω_d t + ζ/√(1−ζ²) sin ω_d t),
/// ω = √(k/J), ζ = c/(2√(kJ)), ω_d = ω√(1−ζ²), J = ρ_A L w · L²/3.
#[test]
fn viscous_hinge_explicit_matches_the_damped_oscillator() {
    let p = Plate {
        length: 2.0,
        width: 1.0,
        areal_density: 5.0,
    };
    let h = Hinge {
        stiffness: 30.0,
        damping: 4.0,
        friction: 0.0,
        reference: 1.0,
        initial: 0.4,
        latch: 2.5,
    };
    let (end, rate) = (20.0, 50.0);
    let r = run(&scenario(
        p,
        h,
        end,
        rate,
        "integrator = \"explicit\"\ntolerance = 1e-12",
    ));
    assert_free_swing(&r, end);
    let j = p.inertia_about_hinge();
    let osc = Damped::new(h.stiffness, h.damping, j, h.initial - h.reference);
    let s = samples(&r, rate);
    let (mut ea, mut er, mut ee) = (0.0_f64, 0.0_f64, 0.0_f64);
    let e0 = 0.5 * h.stiffness * osc.x0 * osc.x0;
    for x in &s {
        let (xa, xd) = osc.at(x.t);
        ea = ea.max((x.alpha[0] - h.reference - xa).abs());
        er = er.max((x.rate[0] - xd).abs());
        let e = 0.5 * j * xd * xd + 0.5 * h.stiffness * xa * xa;
        ee = ee.max((x.kinetic + x.spring - e).abs() / e0);
    }
    eprintln!(
        "explicit: angle {ea:e} rate {er:e} energy {ee:e} zeta {}",
        osc.zeta
    );
    // energy balance
    let f: Vec<f64> = s.iter().map(|x| h.damping * x.rate[0].powi(2)).collect();
    let w = simpson(&f, 1.0 / rate);
    let last = s.last().unwrap();
    let lost = e0 - (last.kinetic + last.spring);
    eprintln!(
        "dissipated {lost} vs simpson {w}: {:e}",
        (lost - w).abs() / e0
    );
}

/// Viscous damping, the default automatic integrator.
#[test]
fn viscous_hinge_auto_matches_the_damped_oscillator() {
    let p = Plate {
        length: 2.0,
        width: 1.0,
        areal_density: 5.0,
    };
    let h = Hinge {
        stiffness: 30.0,
        damping: 4.0,
        friction: 0.0,
        reference: 1.0,
        initial: 0.4,
        latch: 2.5,
    };
    let (end, rate) = (20.0, 50.0);
    for acc in ["", "accuracy = 1e-5", "accuracy = 1e-8"] {
        let r = run(&scenario(p, h, end, rate, acc));
        assert_free_swing(&r, end);
        let acc = r.accuracy.clone().unwrap();
        eprintln!("{acc:?}");
        let j = p.inertia_about_hinge();
        let osc = Damped::new(h.stiffness, h.damping, j, h.initial - h.reference);
        let s = samples(&r, rate);
        let (mut ea, mut er) = (0.0_f64, 0.0_f64);
        for x in &s {
            let (xa, xd) = osc.at(x.t);
            ea = ea.max((x.alpha[0] - h.reference - xa).abs());
            er = er.max((x.rate[0] - xd).abs());
        }
        let last = s.last().unwrap();
        let (xa, xd) = osc.at(last.t);
        eprintln!(
            "auto: angle {ea:e} rate {er:e}; final angle {:e} rate {:e}",
            (last.alpha[0] - h.reference - xa).abs(),
            (last.rate[0] - xd).abs()
        );
    }
}

/// Coulomb friction.
#[test]
fn coulomb_hinge_explicit() {
    let p = Plate {
        length: 2.0,
        width: 1.0,
        areal_density: 5.0,
    };
    let j = p.inertia_about_hinge();
    let omega = std::f64::consts::PI / 4.0;
    let k = j * omega * omega;
    let h = Hinge {
        stiffness: k,
        damping: 0.0,
        friction: 0.04 * k,
        reference: 0.6,
        initial: 0.6 - 8.5 * 0.04,
        latch: 2.5,
    };
    let (end, rate) = (24.0, 10.0);
    let t0 = std::time::Instant::now();
    let r = run(&scenario(
        p,
        h,
        end,
        rate,
        "integrator = \"explicit\"\ntolerance = 1e-10",
    ));
    eprintln!(
        "coulomb explicit {:?} evals {}",
        t0.elapsed(),
        r.evaluations
    );
    assert_free_swing(&r, end);
    for x in r
        .samples
        .iter()
        .filter(|x| (x.t * 10.0).round() as i64 % 10 == 0)
    {
        eprintln!("{} {} {:e}", x.t, x.alpha[0], x.rate[0]);
    }
}

#[test]
fn scratch_rodas_order() {
    use flexcraft::deploy::{OdeSystem, Rodas5P};
    struct Sys<'a>(&'a flexcraft::deploy::coupled::Coupled, bool);
    impl OdeSystem for Sys<'_> {
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            self.0.rhs(y, &[true], dy);
        }
        fn jacobian(&self, _t: f64, y: &[f64], jac: &mut flexcraft::faer::Mat<f64>) -> bool {
            if self.1 {
                self.0.stiff_jacobian(y, &[true], &[false], jac);
            }
            self.1
        }
    }
    let p = Plate {
        length: 2.0,
        width: 1.0,
        areal_density: 5.0,
    };
    let h = Hinge {
        stiffness: 30.0,
        damping: 4.0,
        friction: 0.0,
        reference: 1.0,
        initial: 0.4,
        latch: 2.5,
    };
    let src = scenario(p, h, 20.0, 50.0, "");
    let sc = Scenario::from_toml_str(&src, "x.toml").unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let c = d.coupled(&sc.structure).unwrap();
    let y0 = c.initial_state();
    eprintln!("state len {} {:?}", y0.len(), y0);
    let mut jac = flexcraft::faer::Mat::zeros(y0.len(), y0.len());
    c.stiff_jacobian(&y0, &[true], &[false], &mut jac);
    eprintln!("jac {:?}", jac);
    let j = p.inertia_about_hinge();
    let osc = Damped::new(30.0, 4.0, j, -0.6);
    for hh in [0.2, 0.1, 0.05, 0.027] {
        let t_end = 20.0;
        let mut s = Rodas5P::new(1e3, 1e3, f64::INFINITY);
        let (mut t, mut y) = (0.0, y0.clone());
        let sys = Sys(&c, true);
        while t < t_end - 1e-12 {
            s.step_scheduled(&sys, &mut t, &mut y, t_end, hh);
        }
        let (xa, _) = osc.at(t_end);
        eprintln!("fixed h {hh} err {:e}", (y[0] - 1.0 - xa).abs());
    }
    for lev in 0..3 {
        let f = (1u64 << lev) as f64;
        let (kappa, delta) = (1.0 / f.sqrt(), 0.02 / f);
        let t_end = 20.0;
        let mut s = Rodas5P::new(1e3, 1e3, f64::INFINITY);
        let (mut t, mut y) = (0.0, y0.clone());
        let sys = Sys(&c, true);
        let mut steps = 0;
        while t < t_end - 1e-12 {
            let fy = s.derivative(&sys, t, &y).to_vec();
            let hh = (kappa / 1.5)
                .min(delta / y[1].abs())
                .min((2.0 * delta / fy[1].abs()).sqrt())
                .min(0.2);
            s.step_scheduled(&sys, &mut t, &mut y, t_end, hh);
            steps += 1;
        }
        let (xa, _) = osc.at(t_end);
        let e = (y[0] - 1.0 - xa).abs();
        eprintln!("level {lev} steps {steps} err {e:e}");
    }
}
