//! Hinge viscous damping and Coulomb friction (docs/theory.md §2.1; issue 43) against the
//! closed forms of a single hinged panel.
//!
//! One rigid panel on a held hub (`[hub] motion = "fixed"`; the structure is the hub and the
//! deploying plate alone, and `[deployment] base = "rigid"`: the base neither moves nor
//! deforms) turns about its hinge line, so its opening angle obeys exactly
//!
//!   J α̈ = k (α_ref − α) − c α̇ − f sgn(α̇),
//!
//! J the panel's moment of inertia about the hinge line. Every test computes J from the
//! scenario's own numbers — a uniform plate of areal density ρ_A, width w and length L
//! turning about its edge: m = ρ_A L w, J = m L²/12 + m (L/2)² = m L²/3 — never from the
//! library, and sets the latch angle beyond every angle the motion reaches and the initial
//! angle below every later one (no latch, no swing-back), so the panel swings freely until
//! `end_time`. The runs go through the scenario parser and [`simulate_coupled`], the route of
//! `flexcraft deploy`.

use flexcraft::deploy::{simulate_coupled, DeploymentResult, RunStatus, Sample};
use flexcraft::warning::Warning;
use flexcraft::Scenario;
use std::f64::consts::PI;

/// The documented friction regularisation ε (docs/scenario.md `[deployment.hinge]`,
/// docs/theory.md §2.1): below |α̇| = ε, sgn(α̇) is replaced by α̇/ε.
const FRICTION_RATE: f64 = 1e-6;

/// What the explicit integrator's global error may add at tolerance 1e-12 (relative; its
/// absolute tolerance is 1e-14): a thousand steps' local errors at the tolerance, on angles
/// and rates of order one (measured: 1e-12 on the viscous panel).
const EXPLICIT_ALLOWANCE: f64 = 1e-9;

/// The deploying plate, cut into one panel: length L, width w, areal density ρ_A.
#[derive(Debug, Clone, Copy)]
struct Plate {
    length: f64,
    width: f64,
    areal_density: f64,
}

impl Plate {
    /// J = m L²/3 about the hinge line (the panel's edge), m = ρ_A L w.
    fn inertia_about_hinge(&self) -> f64 {
        let m = self.areal_density * self.length * self.width;
        m * self.length * self.length / 3.0
    }
}

/// The hinge: spring k about α_ref, damper c, Coulomb friction f, latch angle, released from
/// rest at α₀.
#[derive(Debug, Clone, Copy)]
struct Hinge {
    stiffness: f64,
    damping: f64,
    friction: f64,
    reference: f64,
    initial: f64,
    latch: f64,
}

/// The scenario: one panel on a held hub, a rigid base, the hinge `h` in a
/// `[[deployment.hinges]]` table; `integrator` holds the lines choosing the integrator (empty:
/// the default automatic one).
fn scenario(p: Plate, h: Hinge, end_time: f64, output_rate: f64, integrator: &str) -> String {
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
{integrator}
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

/// Parses and runs the scenario.
fn run(src: &str) -> DeploymentResult {
    let sc = Scenario::from_toml_str(src, "hinge.toml").unwrap_or_else(|e| panic!("{e}"));
    let d = sc.deployment.as_ref().expect("a [deployment] section");
    simulate_coupled(&sc.structure, d).expect("deployment").1
}

/// The run swung freely to its end time: no latch, no capture, and no warning but the hinge
/// left unlatched (no swing-back below the initial angle, no step limit, no divergence, no
/// accuracy missed). Returns the samples at t = i / output_rate, every one of them in order.
fn free_swing(r: &DeploymentResult, end_time: f64, output_rate: f64) -> Vec<&Sample> {
    assert_eq!(r.status, RunStatus::EndTime, "{:?}", r.warnings);
    assert!(r.latches.is_empty() && r.captures.is_empty());
    assert!(
        matches!(r.warnings[..], [Warning::NotLatched { .. }]),
        "{:?}",
        r.warnings
    );
    assert!((r.final_time - end_time).abs() <= 1e-9 * end_time);
    let s: Vec<&Sample> = r.samples.iter().collect();
    assert_eq!(s.len(), (end_time * output_rate).round() as usize + 1);
    for (i, x) in s.iter().enumerate() {
        assert!(
            (x.t - i as f64 / output_rate).abs() <= 1e-12 * (1.0 + x.t),
            "sample {i} at t = {}",
            x.t
        );
    }
    s
}

/// The underdamped oscillator J ẍ + c ẋ + k x = 0, x = α − α_ref, released from rest at x₀:
///   x(t) = x₀ e^{−ζωt} (cos ω_d t + ζ/√(1−ζ²) sin ω_d t),
///   ẋ(t) = −x₀ ω/√(1−ζ²) e^{−ζωt} sin ω_d t,
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

    /// √(1 − ζ²).
    fn s(&self) -> f64 {
        (1.0 - self.zeta * self.zeta).sqrt()
    }

    /// (x, ẋ) at t.
    fn at(&self, t: f64) -> (f64, f64) {
        let s = self.s();
        let e = (-self.zeta * self.omega * t).exp();
        let (sn, cs) = (self.omega * s * t).sin_cos();
        (
            self.x0 * e * (cs + self.zeta / s * sn),
            -self.x0 * self.omega / s * e * sn,
        )
    }

    /// The envelope of |ẋ|: x₀ ω/√(1−ζ²).
    fn rate_scale(&self) -> f64 {
        self.x0.abs() * self.omega / self.s()
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

/// The viscous panel of the first two tests: L = 2 m, w = 1 m, ρ_A = 5 kg/m², so
/// J = 10·2²/3 = 40/3 kg·m²; k = 30 N·m/rad (ω = 1.5 rad/s), c = 4 N·m·s/rad
/// (√(kJ) = 20, ζ = 0.1), α_ref = 1, released at α₀ = 0.4: the angle stays within
/// [0.4, 1.6] (first overshoot 1 + 0.6 e^{−ζπ/√(1−ζ²)} = 1.44), below the latch at 2.5 and
/// never below α₀.
fn viscous_panel() -> (Plate, Hinge) {
    (
        Plate {
            length: 2.0,
            width: 1.0,
            areal_density: 5.0,
        },
        Hinge {
            stiffness: 30.0,
            damping: 4.0,
            friction: 0.0,
            reference: 1.0,
            initial: 0.4,
            latch: 2.5,
        },
    )
}

/// Viscous damping, explicit integrator (DOPRI5 at tolerance 1e-12). Truth: the underdamped
/// oscillator J α̈ + c α̇ + k (α − α_ref) = 0 released from rest,
///   α(t) = α_ref + (α₀ − α_ref) e^{−ζωt} (cos ω_d t + ζ/√(1−ζ²) sin ω_d t),
/// ω = √(k/J), ζ = c/(2√(kJ)) = 0.1, ω_d = ω√(1−ζ²), J = ρ_A L w · L²/3. Every sample over
/// 20 s (4.8 periods, 50 Hz) matches in angle and rate to 1e-9 ([`EXPLICIT_ALLOWANCE`]), and
/// its kinetic + spring energy the closed form's ½ J ẋ² + ½ k x² to 1e-9 of E₀ = ½ k x₀².
/// The dissipated energy: E₀ − E(T) equals the damper's work ∫₀ᵀ c α̇² dt, integrated from
/// the samples' own rates by Simpson's rule, within Simpson's error bound
/// T h⁴ max|g⁗|/180 for g = c α̇², |g⁗| ≤ c V² (2ω)⁴ (α̇ = −V e^{−ζωt} sin ω_d t,
/// V = x₀ω/√(1−ζ²), and |−2ζω ± 2iω_d| = 2ω): 8.7e-7 of E₀ here.
#[test]
fn viscous_hinge_explicit_matches_the_damped_oscillator() {
    let (p, h) = viscous_panel();
    let (end, rate) = (20.0, 50.0);
    let r = run(&scenario(
        p,
        h,
        end,
        rate,
        "integrator = \"explicit\"\ntolerance = 1e-12",
    ));
    let s = free_swing(&r, end, rate);
    let j = p.inertia_about_hinge();
    let osc = Damped::new(h.stiffness, h.damping, j, h.initial - h.reference);
    assert!((osc.zeta - 0.1).abs() < 1e-12 && (osc.omega - 1.5).abs() < 1e-12);
    let e0 = 0.5 * h.stiffness * osc.x0 * osc.x0;
    for x in &s {
        let (xa, xd) = osc.at(x.t);
        let (ea, er) = (x.alpha[0] - h.reference - xa, x.rate[0] - xd);
        assert!(
            ea.abs() <= EXPLICIT_ALLOWANCE,
            "t = {}: angle off by {ea:e}",
            x.t
        );
        assert!(
            er.abs() <= EXPLICIT_ALLOWANCE,
            "t = {}: rate off by {er:e}",
            x.t
        );
        let e = 0.5 * j * xd * xd + 0.5 * h.stiffness * xa * xa;
        let ee = x.kinetic + x.spring - e;
        assert!(
            ee.abs() <= EXPLICIT_ALLOWANCE * e0,
            "t = {}: energy {} vs {e} J",
            x.t,
            x.kinetic + x.spring
        );
    }
    // The damper's work over the whole run against the energy lost.
    let g: Vec<f64> = s.iter().map(|x| h.damping * x.rate[0].powi(2)).collect();
    let step = 1.0 / rate;
    let work = simpson(&g, step);
    let last = s.last().unwrap();
    let lost = e0 - (last.kinetic + last.spring);
    let v = osc.rate_scale();
    let simpson_bound = end * step.powi(4) * h.damping * v * v * (2.0 * osc.omega).powi(4) / 180.0;
    assert!(simpson_bound < 1e-6 * e0, "{simpson_bound:e}");
    assert!(lost > 0.9 * e0, "{lost} of {e0} J dissipated");
    assert!(
        (lost - work).abs() <= simpson_bound + EXPLICIT_ALLOWANCE * e0,
        "energy lost {lost} J, damper's work {work} J (bound {simpson_bound:e})"
    );
}

/// Viscous damping, the default automatic integrator (Rodas5P at scheduled steps, refined
/// until its estimate meets `accuracy`, here 1e-6). Truth: the damped oscillator of
/// [`viscous_hinge_explicit_matches_the_damped_oscillator`]. The bound is the run's own
/// reported accuracy, as documented (docs/scenario.md `accuracy`, docs/theory.md §2.9: with
/// no latch before the end time, the angles reached there against the latch angle and the
/// rates against the largest rate): the run reports the accuracy reached
/// (`Accuracy::reached`: estimate ≤ asked), and the final angle is within asked × α_latch and
/// the final rate within asked × |α̇(T)| of the closed form. The samples before the end lie
/// between step ends, on the steps' cubic Hermite dense output (src/ode/rosenbrock.rs), which
/// the estimate does not compare: each is held to the same asked × α_latch (asked × V for the
/// rate) plus the Hermite interpolation error h⁴/384 · max|y⁗| with h the schedule's longest
/// step, 1 % of end_time = 0.2 s (below κ/ω = 1/1.5 s), and |x⁗| ≤ ω⁴|x₀|/√(1−ζ²),
/// |ẋ⁗| ≤ ω⁵|x₀|/√(1−ζ²): 1.3e-5 rad and 1.9e-5 rad/s.
#[test]
fn viscous_hinge_auto_matches_the_damped_oscillator_to_its_reported_accuracy() {
    let (p, h) = viscous_panel();
    let (end, rate) = (20.0, 50.0);
    let r = run(&scenario(p, h, end, rate, "accuracy = 1e-6"));
    let s = free_swing(&r, end, rate);
    let acc = r
        .accuracy
        .clone()
        .expect("the automatic integrator's accuracy");
    assert_eq!(acc.asked, 1e-6);
    assert!(acc.reached(), "{acc:?}");
    let j = p.inertia_about_hinge();
    let osc = Damped::new(h.stiffness, h.damping, j, h.initial - h.reference);
    // The final state, to the accuracy the run reports.
    let last = s.last().unwrap();
    let (xa, xd) = osc.at(last.t);
    let (ea, er) = (last.alpha[0] - h.reference - xa, last.rate[0] - xd);
    assert!(
        ea.abs() <= acc.asked * h.latch,
        "final angle off by {ea:e} ({acc:?})"
    );
    assert!(
        er.abs() <= acc.asked * xd.abs(),
        "final rate off by {er:e} of {xd} ({acc:?})"
    );
    // Every sample, with the dense output's interpolation error.
    let longest = (0.01 * end).min(1.0 / osc.omega);
    let hermite = longest.powi(4) / 384.0 * osc.omega.powi(4) * osc.x0.abs() / osc.s();
    let (angle_bound, rate_bound) = (
        acc.asked * h.latch + hermite,
        acc.asked * osc.rate_scale() + hermite * osc.omega,
    );
    for x in &s {
        let (xa, xd) = osc.at(x.t);
        let (ea, er) = (x.alpha[0] - h.reference - xa, x.rate[0] - xd);
        assert!(
            ea.abs() <= angle_bound,
            "t = {}: angle off by {ea:e} (bound {angle_bound:e})",
            x.t
        );
        assert!(
            er.abs() <= rate_bound,
            "t = {}: rate off by {er:e} (bound {rate_bound:e})",
            x.t
        );
    }
}

/// The automatic run's accuracy estimate sees every step it makes: a small swing (0.01 rad)
/// asked to 1e-8, where the steps of the quiet free swing are set by the longest-step cap
/// alone. Before the cap was refined with the steps, both runs made the same steps: the
/// estimate was exactly 0, "reached", and the final rate was off by 1.9e-7 of itself. Now
/// either the run says it did not reach 1e-8, or the closed form confirms it did (final angle
/// and rate to the accuracy asked); and the estimate is never the zero of two identical runs.
#[test]
fn the_automatic_estimate_sees_the_capped_steps() {
    let (p, mut h) = viscous_panel();
    h.initial = h.reference - 0.01;
    let end = 20.0;
    let r = run(&scenario(p, h, end, 50.0, "accuracy = 1e-8"));
    let acc = r
        .accuracy
        .clone()
        .expect("the automatic integrator's accuracy");
    assert!(acc.estimate > 0.0, "{acc:?}");
    let j = p.inertia_about_hinge();
    let osc = Damped::new(h.stiffness, h.damping, j, h.initial - h.reference);
    let last = r.samples.last().unwrap();
    let (xa, xd) = osc.at(last.t);
    let (ea, er) = (last.alpha[0] - h.reference - xa, last.rate[0] - xd);
    if acc.reached() {
        assert!(
            ea.abs() <= 1e-8 * h.latch,
            "final angle off by {ea:e} ({acc:?})"
        );
        assert!(
            er.abs() <= 1e-8 * xd.abs(),
            "final rate off by {er:e} of {xd} ({acc:?})"
        );
    }
}

/// The Coulomb-damped oscillator J ẍ + k x + f sgn(ẋ) = 0, x = α − α_ref, released from rest
/// at x₀ with |k x₀| > f. Between stops the motion is a half cycle of the undamped oscillator
/// about the shifted centre x_c = sgn(x_n) f/k (opposite to the motion's sign): from the stop
/// x_n at t_n = nπ/ω, x(t) = x_c + (x_n − x_c) cos ω(t − t_n), so the next stop is
/// x_{n+1} = 2x_c − x_n, |x_{n+1}| = |x_n| − 2f/k with the sign reversed, each half period
/// π/ω (ω = √(k/J), the period unchanged). At the first stop with |k x_n| ≤ f (the stick
/// condition) the panel stays for good.
#[derive(Debug, Clone)]
struct Coulomb {
    omega: f64,
    /// f/k, rad.
    shift: f64,
    /// The stops x_0, x_1, …, the last one the stick point.
    stops: Vec<f64>,
}

impl Coulomb {
    fn new(k: f64, f: f64, j: f64, x0: f64) -> Self {
        let shift = f / k;
        let mut stops = vec![x0];
        while stops.last().unwrap().abs() > shift {
            let x = *stops.last().unwrap();
            stops.push(2.0 * x.signum() * shift - x);
        }
        Self {
            omega: (k / j).sqrt(),
            shift,
            stops,
        }
    }

    /// The half cycles before the panel sticks.
    fn moving(&self) -> usize {
        self.stops.len() - 1
    }

    /// The time of stop n, nπ/ω.
    fn stop_time(&self, n: usize) -> f64 {
        n as f64 * PI / self.omega
    }

    /// (x, ẋ) at t.
    fn at(&self, t: f64) -> (f64, f64) {
        let n = ((t * self.omega / PI).floor().max(0.0)) as usize;
        if n >= self.moving() {
            return (*self.stops.last().unwrap(), 0.0);
        }
        let xn = self.stops[n];
        let xc = xn.signum() * self.shift;
        let tau = t - self.stop_time(n);
        let (sn, cs) = (self.omega * tau).sin_cos();
        (xc + (xn - xc) * cs, -(xn - xc) * self.omega * sn)
    }
}

/// Coulomb friction (c = 0), explicit integrator (DOPRI5 at tolerance 1e-12). Truth: the
/// Coulomb-damped oscillator ([`Coulomb`]): turning points at t_n = nπ/ω exactly, the
/// amplitude about α_ref falling by 2f/k each half period, and the panel stuck for good at the
/// first stop with |k (α − α_ref)| ≤ f.
///
/// The numbers: J = 40/3 kg·m² as above, k = J ω² with ω = π/4 rad/s (the stops fall on the
/// 10 Hz samples, at 4 s, 8 s, …), f = 0.04 k (f/k = 0.04 rad), α_ref = 0.6, released at
/// α₀ = α_ref − 8.5 f/k: the stops are α_ref − 0.34, + 0.26, − 0.18, + 0.10, − 0.02, the last
/// within f/k, so the panel turns at 4, 8 and 12 s and sticks at 16 s at α_ref − 0.02 (all
/// within [α₀, 0.86], below the latch at 2.5). The run goes on to 24 s.
///
/// The bounds are the regularisation's (chain.rs `FRICTION_RATE`, ε = 1e-6 rad/s, checked
/// against the documented value), derived: within the band |α̇| < ε the friction is the
/// damper f/ε, time constant τ = Jε/f (4.05e-5 s), the spring nearly constant while the rate
/// crosses the band. Crossing it at a stop x_n (r = k|x_n|/f > 1) it leaves at −ε after
/// τ ln((r+1)/(r−1)), against the Coulomb law's τ·2r/(r²−1): the regularised motion comes out
/// ahead by τ (2r/(r²−1) − ln((r+1)/(r−1))) (0.105 τ at r = 2.5), at the release from rest
/// by τ (1/(r−1) − ln(r/(r−1))), otherwise equal (the positions differ by the band's ε × its
/// crossing time). So after stop n the motion is the closed form shifted ahead by the sum
/// Δ_n of these leads (at most Δ = 5.4e-6 s):
/// - against the closed form itself, the angles agree within V Δ (V the largest rate,
///   1.3e-6 rad), the rates within A Δ + 2ε (A the largest acceleration, 2ε the band), the
///   stops' angles within ½ A Δ² plus the band's drift, and the rate at t_n is within
///   A Δ + 2ε of zero: the rate's zero, the turning time, is nπ/ω to within
///   (A Δ + 2ε)/a_n, a_n = (k|x_n| − f)/J the smallest acceleration there (8e-5 s), and the
///   rate has the closed form's sign one sample before and after;
/// - against the closed form shifted by Δ_n, the angles agree within the band's drift
///   ε τ Σ 2r/(r²−1) (8e-11 rad) and the rates off the stops within the allowance: the
///   regularisation's effect itself, predicted (measured: 7e-12 rad, against 2.6e-7 rad
///   unshifted).
///
/// Stuck, the rate stays inside the band (|α̇| < ε, so the angle within ε (t − t_s) of the
/// stick point), where the band's damper lets the spring creep on its slow manifold
/// α̇ = −(kε/f) x, x(t) = x_s e^{−(kε/f)(t − t_s)} (|α̇| = r_s ε, r_s = k|x_s|/f = 0.5:
/// 4e-6 rad in the last 8 s): the rate matches it to 1e-11 rad/s (2e-5 of it: the allowance
/// scaled by the integrator's absolute tolerance, 1e-2 of its relative one), the angle to
/// the entry's lead and the band's transient. [`EXPLICIT_ALLOWANCE`] is added to each bound
/// for the integration. The energy at each stop is ½ k x_n²: E₀ − E(t_n) is the friction's
/// work f Σ|x_{m+1} − x_m|.
#[test]
fn coulomb_hinge_matches_the_coulomb_damped_oscillator_and_sticks() {
    assert_eq!(
        flexcraft::deploy::chain::FRICTION_RATE,
        FRICTION_RATE,
        "the documented regularisation"
    );
    let eps = FRICTION_RATE;
    let p = Plate {
        length: 2.0,
        width: 1.0,
        areal_density: 5.0,
    };
    let j = p.inertia_about_hinge();
    let omega = PI / 4.0;
    let k = j * omega * omega;
    let f = 0.04 * k;
    let h = Hinge {
        stiffness: k,
        damping: 0.0,
        friction: f,
        reference: 0.6,
        initial: 0.6 - 8.5 * 0.04,
        latch: 2.5,
    };
    let (end, rate) = (24.0, 10.0);
    let r = run(&scenario(
        p,
        h,
        end,
        rate,
        "integrator = \"explicit\"\ntolerance = 1e-12",
    ));
    let s = free_swing(&r, end, rate);
    let cf = Coulomb::new(k, f, j, h.initial - h.reference);
    assert_eq!(cf.moving(), 4, "stops {:?}", cf.stops);
    assert!((cf.omega - omega).abs() < 1e-15);
    // The regularisation's lead: after the release and after each stop n, Δ_n (s).
    let tau = j * eps / f;
    let ratio = |x: f64| k * x.abs() / f;
    let r0 = ratio(cf.stops[0]);
    let mut leads = vec![tau * (1.0 / (r0 - 1.0) - (r0 / (r0 - 1.0)).ln())];
    let mut crossing = 1.0 / (r0 - 1.0);
    for &x in &cf.stops[1..cf.moving()] {
        let r = ratio(x);
        let d = 2.0 * r / (r * r - 1.0) - ((r + 1.0) / (r - 1.0)).ln();
        leads.push(leads.last().unwrap() + tau * d);
        crossing += 2.0 * r / (r * r - 1.0);
    }
    let lead = *leads.last().unwrap();
    let band_drift = eps * crossing * tau;
    assert!(
        leads[0] > 0.0 && lead < 0.2 * tau,
        "Δ = {leads:?} s, τ = {tau:e} s"
    );
    let v_max = cf.omega * (cf.stops[0].abs() - cf.shift);
    let a_max = (k * cf.stops[0].abs() + f) / j;
    let angle_bound = v_max * lead + band_drift + EXPLICIT_ALLOWANCE;
    let rate_bound = a_max * lead + 2.0 * eps + EXPLICIT_ALLOWANCE;
    let stop_bound = 0.5 * a_max * lead * lead + band_drift + EXPLICIT_ALLOWANCE;
    let t_stick = cf.stop_time(cf.moving());
    // Every sample while the panel moves, against the closed form shifted by the lead Δ_n the
    // regularisation predicts for its half cycle n: the regularised motion itself, to the
    // band's drift. The rates are compared off the stops (at a stop and at the release the
    // rate is inside the band, where the two laws differ by up to 2ε: checked below).
    for x in s.iter().filter(|x| x.t <= t_stick) {
        let half = ((x.t * cf.omega / PI).ceil() as usize).clamp(1, cf.moving()) - 1;
        let (xa, xd) = cf.at(x.t + leads[half]);
        let (ea, er) = (x.alpha[0] - h.reference - xa, x.rate[0] - xd);
        let shifted_bound = band_drift + EXPLICIT_ALLOWANCE;
        assert!(
            ea.abs() <= shifted_bound,
            "t = {}: angle off the shifted closed form by {ea:e} (bound {shifted_bound:e})",
            x.t
        );
        let at_stop = (0..=cf.moving()).any(|n| (x.t - cf.stop_time(n)).abs() < 1e-9);
        assert!(
            at_stop || er.abs() <= EXPLICIT_ALLOWANCE,
            "t = {}: rate off the shifted closed form by {er:e}",
            x.t
        );
    }
    // The same samples against the closed form itself, within the lead's effect.
    for x in s.iter().filter(|x| x.t <= t_stick) {
        let (xa, xd) = cf.at(x.t);
        let (ea, er) = (x.alpha[0] - h.reference - xa, x.rate[0] - xd);
        assert!(
            ea.abs() <= angle_bound,
            "t = {}: angle off by {ea:e} (bound {angle_bound:e})",
            x.t
        );
        assert!(
            er.abs() <= rate_bound,
            "t = {}: rate off by {er:e} (bound {rate_bound:e})",
            x.t
        );
    }
    // The turning points: angle, time, energy.
    let at = |t: f64| {
        let i = (t * rate).round() as usize;
        assert!((s[i].t - t).abs() < 1e-9, "no sample at {t} s");
        i
    };
    let e0 = 0.5 * k * cf.stops[0].powi(2);
    let mut travel = 0.0;
    for n in 1..=cf.moving() {
        let tn = cf.stop_time(n);
        let i = at(tn);
        let (xn, before) = (cf.stops[n], cf.stops[n - 1]);
        let x = s[i].alpha[0] - h.reference;
        assert!(
            (x - xn).abs() <= stop_bound,
            "stop {n} at {tn} s: x = {x}, closed form {xn} (bound {stop_bound:e})"
        );
        assert!(
            s[i].rate[0].abs() <= rate_bound,
            "stop {n} at {tn} s: rate {:e} (bound {rate_bound:e})",
            s[i].rate[0]
        );
        // Moving towards the stop before it, away from it (or stuck) after.
        let towards = (xn - before).signum();
        assert!(
            s[i - 1].rate[0] * towards > rate_bound,
            "stop {n}: approach"
        );
        if n < cf.moving() {
            assert!(s[i + 1].rate[0] * towards < -rate_bound, "stop {n}: leave");
        }
        let a_n = (k * xn.abs() - f).max(0.0) / j;
        if a_n > 0.0 {
            assert!(
                rate_bound / a_n < 1e-4,
                "turning time to {:e} s",
                rate_bound / a_n
            );
        }
        travel += (xn - before).abs();
        let energy = s[i].kinetic + s[i].spring;
        let energy_bound = k * xn.abs() * stop_bound + 0.5 * j * rate_bound * rate_bound;
        assert!(
            (e0 - energy - f * travel).abs() <= energy_bound + EXPLICIT_ALLOWANCE * e0,
            "stop {n}: energy lost {} J, friction's work {} J",
            e0 - energy,
            f * travel
        );
    }
    // Stuck for good: the rate inside the band for the rest of the run, and the angle on the
    // band's creep, x(t) = x_s e^{−(kε/f)(t − t_s)}, α̇ = −(kε/f) x.
    let xs = *cf.stops.last().unwrap();
    let rs = ratio(xs);
    assert!(rs <= 1.0 && rs > 0.1, "r_s = {rs}");
    let slow = k * eps / f;
    let stuck: Vec<&&Sample> = s.iter().filter(|x| x.t > t_stick).collect();
    assert!(stuck.len() > 70, "{} samples stuck", stuck.len());
    for x in stuck {
        let since = x.t - t_stick;
        let (xa, xd) = (x.alpha[0] - h.reference, x.rate[0]);
        assert!(xd.abs() < eps, "t = {}: rate {xd:e} outside the band", x.t);
        assert!(
            (xa - xs).abs() < eps * since,
            "t = {}: moved {:e} rad off the stick point",
            x.t,
            xa - xs
        );
        // The creep from the entry into the band (Δ early), plus the band's transient from
        // the entry rate to the creep's (time constant τ, |α̇| ≤ ε).
        let creep = xs * (-slow * since).exp();
        let creep_bound = rs * eps * lead + (1.0 + rs) * eps * tau + stop_bound;
        assert!(
            (xa - creep).abs() <= creep_bound,
            "t = {}: x = {xa:e}, the band's creep {creep:e} (bound {creep_bound:e})",
            x.t
        );
        assert!(
            (xd + slow * xa).abs() <= 1e-2 * EXPLICIT_ALLOWANCE,
            "t = {}: rate {xd:e}, the band's creep {:e}",
            x.t,
            -slow * xa
        );
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 10,
        rng_seed: proptest::test_runner::RngSeed::Fixed(43),
        failure_persistence: None,
        ..proptest::prelude::ProptestConfig::default()
    })]
    /// Viscous damping over panels and hinges (10 seeded cases): L ∈ [0.5, 4] m,
    /// w ∈ [0.3, 2] m, ρ_A ∈ [0.5, 10] kg/m² (J = ρ_A L w · L²/3 from 0.006 to 430 kg·m²),
    /// ω ∈ [0.5, 5] rad/s (k = J ω²), ζ ∈ [0.01, 0.5] (c = 2ζ√(kJ)), released from rest
    /// x₀ ∈ ±[0.05, 0.8] rad off α_ref = 1 (latch at 3, out of reach), over three damped
    /// periods at 40 samples a period, explicit at tolerance 1e-12. Truth: the underdamped
    /// oscillator of [`Damped`]; every sample's angle and rate to [`EXPLICIT_ALLOWANCE`] (the
    /// rate scaled by ω, the angle's rate), and its energy to that fraction of E₀.
    #[test]
    fn prop_viscous_hinge_matches_the_damped_oscillator(
        length in 0.5f64..4.0,
        width in 0.3f64..2.0,
        areal_density in 0.5f64..10.0,
        omega in 0.5f64..5.0,
        zeta in 0.01f64..0.5,
        offset in 0.05f64..0.8,
        above in proptest::prelude::any::<bool>(),
    ) {
        let p = Plate { length, width, areal_density };
        let j = p.inertia_about_hinge();
        let k = j * omega * omega;
        let c = 2.0 * zeta * (k * j).sqrt();
        let x0 = if above { offset } else { -offset };
        let h = Hinge {
            stiffness: k,
            damping: c,
            friction: 0.0,
            reference: 1.0,
            initial: 1.0 + x0,
            latch: 3.0,
        };
        let osc = Damped::new(k, c, j, x0);
        let period = 2.0 * PI / (omega * osc.s());
        let rate = 40.0 / period;
        let end = 3.0 * period;
        let r = run(&scenario(p, h, end, rate, "integrator = \"explicit\"\ntolerance = 1e-12"));
        proptest::prop_assert_eq!(r.status, RunStatus::EndTime);
        proptest::prop_assert!(r.latches.is_empty());
        // The hinge left unlatched, and released above α_ref the panel swings below its
        // initial angle at once: the only warnings.
        proptest::prop_assert!(
            r.warnings.iter().all(|w| matches!(w, Warning::NotLatched { .. })
                || above && matches!(w, Warning::SwingBack { .. })),
            "{:?}",
            r.warnings
        );
        let e0 = 0.5 * k * x0 * x0;
        proptest::prop_assert!(r.samples.len() >= 120);
        for x in &r.samples {
            let (xa, xd) = osc.at(x.t);
            let (ea, er) = (x.alpha[0] - h.reference - xa, x.rate[0] - xd);
            proptest::prop_assert!(ea.abs() <= EXPLICIT_ALLOWANCE, "t = {}: angle off by {:e}", x.t, ea);
            proptest::prop_assert!(er.abs() <= EXPLICIT_ALLOWANCE * omega, "t = {}: rate off by {:e}", x.t, er);
            let e = 0.5 * j * xd * xd + 0.5 * k * xa * xa;
            proptest::prop_assert!(
                (x.kinetic + x.spring - e).abs() <= EXPLICIT_ALLOWANCE * e0,
                "t = {}: energy {} vs {} J", x.t, x.kinetic + x.spring, e
            );
        }
    }
}
