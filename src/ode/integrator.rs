//! Dormand–Prince 5(4) with dense output and event location.
//!
//! The coefficients are those of E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary
//! Differential Equations I*, 2nd ed., Springer 1993, §II.5–6 (DOPRI5, with the 4th-order
//! dense output of its code `dopri5`); the unit tests below check the method against the
//! harmonic oscillator's closed form: 5th order with fixed steps, global error ∝ tolerance,
//! the dense output between steps, event location to 1e-12 s and a restart after an impulse.
//!
//! Why hand-written (≈ 300 lines) although crates exist: diffsol (0.x) offers explicit
//! Runge–Kutta (Tsit45) and implicit solvers with step-by-step control, interpolation within
//! the last step, root (event) functions and a mutable solver state, so the deployment could
//! be built on it. It is kept because (1) every deployment number is pinned by the
//! byte-identical example outputs, and another method or error norm changes all of them;
//! (2) the deployment uses each accepted step's continuous extension as a value
//! ([`DenseStep`]): samples exactly at k/output_rate, a per-hinge latch search that
//! subdivides the step so that a crossing and return within one step is not missed, and the
//! swing-back scan, all on the same polynomial; (3) the right-hand side changes at every
//! latch (the locked hinges), which here is a restart with the new state and a new free set
//! ([`Dopri5::restart`]) rather than a new problem; (4) a non-stiff explicit method needs no
//! linear algebra back end, which diffsol would bring (nalgebra or faer). Revisit if the
//! hinge dampers make the chain stiff: an implicit method (diffsol's BDF or SDIRK) is then
//! the better choice.

use super::adiabatic::RingingStep;
use std::sync::Arc;

/// A change of some components of y: (component, new value) pairs.
pub type Change = Vec<(usize, f64)>;

/// Components that move together ([`OdeSystem::ties`]): y_k − y_k(0) = d_k s along the
/// direction d, whose first entry, the representative's, is 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    /// The components, the representative first.
    pub components: Vec<usize>,
    /// d, one entry per component, d₀ = 1.
    pub direction: Vec<f64>,
}

/// The columns a Jacobian of `sys` by differences at y takes ([`OdeSystem::ties`]): each
/// untied component c with the change y_c + step(c), and each tie's representative c with
/// the change of all its components y_k + d_k step(c) (first in the change: c's own). The
/// other tied components' columns are zero.
pub(crate) fn difference_columns(
    sys: &dyn OdeSystem,
    y: &[f64],
    step: impl Fn(usize) -> f64,
) -> Vec<(usize, Change)> {
    let ties = sys.ties();
    let mut tie_of = vec![None; y.len()];
    for (i, tie) in ties.iter().enumerate() {
        for (p, &k) in tie.components.iter().enumerate() {
            tie_of[k] = Some((i, p));
        }
    }
    (0..y.len())
        .filter_map(|c| match tie_of[c] {
            None => Some((c, vec![(c, y[c] + step(c))])),
            Some((i, 0)) => {
                let (h, tie) = (step(c), &ties[i]);
                let change = tie
                    .components
                    .iter()
                    .zip(&tie.direction)
                    .map(|(&k, &d)| (k, y[k] + d * h))
                    .collect();
                Some((c, change))
            }
            Some(_) => None,
        })
        .collect()
}

/// `eval` at y with each change of `changes` applied in turn, into the rows of `out`.
pub(crate) fn each_change(
    y: &[f64],
    changes: &[Change],
    out: &mut [Vec<f64>],
    mut eval: impl FnMut(&[f64], &mut [f64]),
) {
    let mut yp = y.to_vec();
    for (change, dy) in changes.iter().zip(out.iter_mut()) {
        for &(c, v) in change {
            yp[c] = v;
        }
        eval(&yp, dy);
        for &(c, _) in change {
            yp[c] = y[c];
        }
    }
}

/// The evaluations of f a Jacobian of `sys` by differences at y takes, one a side: its
/// [`difference_columns`] that are not kinematic.
pub(crate) fn differenced_columns(sys: &dyn OdeSystem, y: &[f64]) -> usize {
    let k = sys.kinematic();
    difference_columns(sys, y, |_| 0.0)
        .iter()
        .filter(|(c, _)| *c >= k)
        .count()
}

/// One right-hand side y' = f(t, y).
pub trait OdeSystem {
    /// Writes f(t, y) into `dy`.
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]);
    /// Writes an approximation of ∂f/∂y at (t, y) into `jac` (n × n, zeroed by the caller)
    /// and returns true, or returns false when the system has none (an implicit stepper then
    /// differences f). What "approximation" may leave out is the stepper's business: see
    /// [`Rodas5P`](super::Rodas5P).
    fn jacobian(&self, _t: f64, _y: &[f64], _jac: &mut faer::Mat<f64>) -> bool {
        false
    }
    /// The number k of leading components of y that are kinematic: they enter f only
    /// through its first k rows (a free hub's position and attitude, on which the dynamics in
    /// the hub frame do not depend). A Jacobian by differences takes their columns from
    /// [`OdeSystem::rhs_kinematic`] alone. Zero by default.
    fn kinematic(&self) -> usize {
        0
    }
    /// The first [`OdeSystem::kinematic`] components of f(t, y) into `dy` (of that length).
    fn rhs_kinematic(&self, _t: f64, _y: &[f64], _dy: &mut [f64]) {}
    /// The index of the first speed when [`OdeSystem::rhs_speeds`] evaluates changes of the
    /// speeds more cheaply than [`OdeSystem::rhs`] would (a mechanical system whose mass
    /// matrix depends on the positions alone factors it once for all of them); None (the
    /// default) otherwise. A Jacobian by differences takes the speeds' columns from there.
    fn speed_offset(&self) -> Option<usize> {
        None
    }
    /// f(t, y') for each (component, value) of `changes` in turn, y' being y with that
    /// component set to that value, into the rows of `out` (each of y's length). By default
    /// one [`OdeSystem::rhs`] each; a system with a [`OdeSystem::speed_offset`] shares the
    /// configuration's work between the changes of its speeds, and gives the same values.
    fn rhs_speeds(&self, t: f64, y: &[f64], changes: &[Change], out: &mut [Vec<f64>]) {
        each_change(y, changes, out, |yp, dy| self.rhs(t, yp, dy));
    }
    /// Components the flow moves together along a fixed direction: an ideal constraint
    /// linear in them (an ideal cable's opening angles, α − α(0) ∥ r, and their rates,
    /// α̇ ∥ r) keeps y − y(0) in the tangent space T they leave. None by default. A Jacobian
    /// by differences takes one column per tie, along its direction, and leaves the other
    /// tied columns zero: J P with P the projection onto T that reads each tie from its first
    /// component. J P equals J on T and maps into T, where every stage and step of the
    /// integrators stays, and its eigenproblem has T's dimension ([`Tie`]).
    fn ties(&self) -> Vec<Tie> {
        Vec::new()
    }
    /// Quantities the exact flow conserves, and on which components of y they depend
    /// linearly (none by default): a free-floating spacecraft's linear and angular momentum,
    /// linear in the hub's velocity and rate. A stepper that does not conserve them by
    /// itself restores them after every step by correcting those components (a projection
    /// method).
    fn invariants(&self, _y: &[f64]) -> Vec<f64> {
        Vec::new()
    }
    /// The components of y [`OdeSystem::invariants`] are corrected through.
    fn invariant_coordinates(&self) -> Vec<usize> {
        Vec::new()
    }
    /// Per-component factors s_i on the absolute error tolerance: a stepper that honours
    /// them ([`Rodas5P`](super::Rodas5P)) measures y_i's error against
    /// s_i atol + rtol |y_i|; the vector has one factor per component of y. None (the
    /// default) for all 1. A modal velocity's factor is its mode's ω, so that its tolerance
    /// carries the energy of its displacement's (½ δη̇² = ½ ω² δη²).
    fn tolerance_scales(&self) -> Option<Vec<f64>> {
        None
    }
    /// The tolerance factors for a run along the system's slow manifold, where its fast
    /// velocities are quasi-static (the adiabatic integrator's slow run, which passes them
    /// on as its [`tolerance_scales`](Self::tolerance_scales)); None (the default) for all 1.
    /// A run that resolves the fast modes keeps the common tolerance.
    fn slow_tolerance_scales(&self) -> Option<Vec<f64>> {
        None
    }
}

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// The continuous extension of one accepted step on [t0, t0 + h] (4th order).
#[derive(Debug, Clone)]
pub struct DenseStep {
    /// Start of the step.
    pub t0: f64,
    /// Step length.
    pub h: f64,
    r: [Vec<f64>; 5],
    /// The ringing the adiabatic stepper carries beside the polynomial.
    ringing: Option<Arc<RingingStep>>,
}

impl DenseStep {
    /// The extension y(s) = r0 + s (r1 + (1 − s)(r2 + s (r3 + (1 − s) r4))), s = (t − t0)/h.
    pub(crate) fn from_coefficients(t0: f64, h: f64, r: [Vec<f64>; 5]) -> Self {
        Self {
            t0,
            h,
            r,
            ringing: None,
        }
    }

    /// Adds δ (t − t0)/h to component k of the extension: a correction made at the step's
    /// end, spread over the step so that the extension stays continuous there.
    pub(crate) fn add_linear(&mut self, k: usize, delta: f64) {
        self.r[1][k] += delta;
    }

    /// Adds the adiabatic stepper's ringing over this step to the extension.
    pub(crate) fn add_ringing(&mut self, ringing: Arc<RingingStep>) {
        self.ringing = Some(ringing);
    }

    /// The fastest angular frequency the ringing carried beside the polynomial has, rad/s
    /// (0 without ringing): the polynomial follows the accepted steps, the ringing does not.
    pub fn fastest_ringing(&self) -> f64 {
        self.ringing.as_ref().map_or(0.0, |r| r.fastest())
    }

    /// The slowest angular frequency of the ringing, rad/s (0 without ringing).
    pub fn slowest_ringing(&self) -> f64 {
        self.ringing
            .as_ref()
            .map(|r| r.slowest())
            .filter(|w| w.is_finite())
            .unwrap_or(0.0)
    }

    /// End of the step.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
    }

    /// y(t) for t in the step (extrapolates slightly outside).
    pub fn eval(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.r[0][i]
                + s * (self.r[1][i] + s1 * (self.r[2][i] + s * (self.r[3][i] + s1 * self.r[4][i])));
        }
        if let Some(r) = &self.ringing {
            r.add_to(t, out);
        }
    }

    /// Components `first..first + out.len()` of y(t) (the ringing's phases computed once).
    pub fn components(&self, first: usize, t: f64, out: &mut [f64]) {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        for (k, o) in out.iter_mut().enumerate() {
            let i = first + k;
            *o = self.r[0][i]
                + s * (self.r[1][i] + s1 * (self.r[2][i] + s * (self.r[3][i] + s1 * self.r[4][i])));
        }
        if let Some(r) = &self.ringing {
            r.add_range_to(t, first, out);
        }
    }

    /// Component i of y(t).
    pub fn component(&self, i: usize, t: f64) -> f64 {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        let p = self.r[0][i]
            + s * (self.r[1][i] + s1 * (self.r[2][i] + s * (self.r[3][i] + s1 * self.r[4][i])));
        match &self.ringing {
            Some(r) => p + r.component(i, t),
            None => p,
        }
    }
}

/// Adaptive DOPRI5 stepper. Error control: ‖err_i / (atol + rtol·max(|y0_i|, |y1_i|))‖_rms ≤ 1.
#[derive(Debug, Clone)]
pub struct Dopri5 {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step allowed.
    pub h_max: f64,
    h: f64,
    k1: Vec<f64>,
    fresh: bool,
    /// Number of right-hand-side evaluations so far.
    pub evaluations: usize,
}

impl Dopri5 {
    /// A stepper with the given tolerances and largest step.
    pub fn new(rtol: f64, atol: f64, h_max: f64) -> Self {
        Self {
            rtol,
            atol,
            h_max,
            h: 0.0,
            k1: Vec::new(),
            fresh: true,
            evaluations: 0,
        }
    }

    /// Forget the derivative at the current point (after an impulsive change of state).
    pub fn restart(&mut self) {
        self.fresh = true;
    }

    fn initial_step(&mut self, sys: &dyn OdeSystem, t: f64, y: &[f64]) -> f64 {
        // Hairer's starting-step heuristic (HINIT), order 5.
        let n = y.len();
        let sk: Vec<f64> = y.iter().map(|v| self.atol + self.rtol * v.abs()).collect();
        let rms = |v: &[f64]| {
            (v.iter().zip(&sk).map(|(a, s)| (a / s).powi(2)).sum::<f64>() / n as f64).sqrt()
        };
        let d0 = rms(y);
        let d1 = rms(&self.k1);
        let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        h0 = h0.min(self.h_max);
        let y1: Vec<f64> = y.iter().zip(&self.k1).map(|(a, k)| a + h0 * k).collect();
        let mut f1 = vec![0.0; n];
        sys.rhs(t + h0, &y1, &mut f1);
        self.evaluations += 1;
        let diff: Vec<f64> = f1.iter().zip(&self.k1).map(|(a, b)| a - b).collect();
        let d2 = rms(&diff) / h0;
        let dm = d1.max(d2);
        let h1 = if dm <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / dm).powf(1.0 / 5.0)
        };
        (100.0 * h0).min(h1).min(self.h_max)
    }

    /// Takes one accepted step from (t, y) towards at most `t_end`; updates t and y and returns
    /// the step's continuous extension.
    pub fn step(
        &mut self,
        sys: &dyn OdeSystem,
        t: &mut f64,
        y: &mut [f64],
        t_end: f64,
    ) -> DenseStep {
        let n = y.len();
        if self.fresh || self.k1.len() != n {
            self.k1 = vec![0.0; n];
            sys.rhs(*t, y, &mut self.k1);
            self.evaluations += 1;
            self.h = self.initial_step(sys, *t, y);
            self.fresh = false;
        }
        let mut k = vec![vec![0.0; n]; 6];
        let mut yt = vec![0.0; n];
        let mut y1 = vec![0.0; n];
        loop {
            let mut h = self.h.min(self.h_max);
            let last = *t + h >= t_end - 1e-12 * t_end.abs().max(1.0);
            if last {
                h = t_end - *t;
            }
            let k1 = &self.k1;
            for i in 0..n {
                yt[i] = y[i] + h * A21 * k1[i];
            }
            sys.rhs(*t + C2 * h, &yt, &mut k[0]);
            for i in 0..n {
                yt[i] = y[i] + h * (A31 * k1[i] + A32 * k[0][i]);
            }
            sys.rhs(*t + C3 * h, &yt, &mut k[1]);
            for i in 0..n {
                yt[i] = y[i] + h * (A41 * k1[i] + A42 * k[0][i] + A43 * k[1][i]);
            }
            sys.rhs(*t + C4 * h, &yt, &mut k[2]);
            for i in 0..n {
                yt[i] = y[i] + h * (A51 * k1[i] + A52 * k[0][i] + A53 * k[1][i] + A54 * k[2][i]);
            }
            sys.rhs(*t + C5 * h, &yt, &mut k[3]);
            for i in 0..n {
                yt[i] = y[i]
                    + h * (A61 * k1[i]
                        + A62 * k[0][i]
                        + A63 * k[1][i]
                        + A64 * k[2][i]
                        + A65 * k[3][i]);
            }
            sys.rhs(*t + h, &yt, &mut k[4]);
            for i in 0..n {
                y1[i] = y[i]
                    + h * (A71 * k1[i]
                        + A73 * k[1][i]
                        + A74 * k[2][i]
                        + A75 * k[3][i]
                        + A76 * k[4][i]);
            }
            sys.rhs(*t + h, &y1, &mut k[5]);
            self.evaluations += 6;
            // k[0..6] hold k2..k7.
            let mut err = 0.0;
            for i in 0..n {
                let e = h
                    * (E1 * k1[i]
                        + E3 * k[1][i]
                        + E4 * k[2][i]
                        + E5 * k[3][i]
                        + E6 * k[4][i]
                        + E7 * k[5][i]);
                let sc = self.atol + self.rtol * y[i].abs().max(y1[i].abs());
                err += (e / sc).powi(2);
            }
            let err = (err / n as f64).sqrt();
            let fac = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            };
            if err <= 1.0 || h.abs() < 1e-14 * t.abs().max(1.0) {
                let ydiff: Vec<f64> = (0..n).map(|i| y1[i] - y[i]).collect();
                let bspl: Vec<f64> = (0..n).map(|i| h * k1[i] - ydiff[i]).collect();
                let r4: Vec<f64> = (0..n).map(|i| ydiff[i] - h * k[5][i] - bspl[i]).collect();
                let r5: Vec<f64> = (0..n)
                    .map(|i| {
                        h * (D1 * k1[i]
                            + D3 * k[1][i]
                            + D4 * k[2][i]
                            + D5 * k[3][i]
                            + D6 * k[4][i]
                            + D7 * k[5][i])
                    })
                    .collect();
                let dense = DenseStep {
                    t0: *t,
                    h,
                    r: [y.to_vec(), ydiff, bspl, r4, r5],
                    ringing: None,
                };
                *t = if last { t_end } else { *t + h };
                y.copy_from_slice(&y1);
                self.k1.copy_from_slice(&k[5]);
                if !last {
                    self.h = h * fac;
                }
                return dense;
            }
            self.h = h * fac.min(1.0);
        }
    }
}

/// The first root in (a, b] of g along a dense step, located by bisection refined with the
/// secant (Illinois) method to |Δt| ≤ tol. `g(a)` and `g(b)` must have opposite signs.
pub fn locate(g: impl Fn(f64) -> f64, mut a: f64, mut b: f64, tol: f64) -> f64 {
    let mut fa = g(a);
    let mut fb = g(b);
    let mut side = 0;
    for _ in 0..200 {
        if (b - a).abs() <= tol {
            break;
        }
        let mut m = (a * fb - b * fa) / (fb - fa);
        if !(m > a && m < b) {
            m = 0.5 * (a + b);
        }
        let fm = g(m);
        if fm == 0.0 {
            return m;
        }
        if (fm > 0.0) == (fa > 0.0) {
            a = m;
            fa = fm;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = m;
            fb = fm;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    //! The integrator against the closed form of the harmonic oscillator y'' = −y,
    //! y(0) = 1, y'(0) = 0: y = cos t, y' = −sin t.
    use super::*;

    struct Oscillator;

    impl OdeSystem for Oscillator {
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    fn exact(t: f64) -> [f64; 2] {
        [t.cos(), -t.sin()]
    }

    /// Least-squares slope of log(e) against log(x).
    fn slope(x: &[f64], e: &[f64]) -> f64 {
        let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
        let le: Vec<f64> = e.iter().map(|v| v.ln()).collect();
        let n = lx.len() as f64;
        let (mx, me) = (lx.iter().sum::<f64>() / n, le.iter().sum::<f64>() / n);
        let sxy: f64 = lx.iter().zip(&le).map(|(a, b)| (a - mx) * (b - me)).sum();
        let sxx: f64 = lx.iter().map(|a| (a - mx) * (a - mx)).sum();
        sxy / sxx
    }

    /// Adaptive run to `t_end`; every accepted step's dense output is handed to `each`.
    fn run(rtol: f64, t_end: f64, mut each: impl FnMut(&DenseStep)) -> (Vec<f64>, usize) {
        let mut s = Dopri5::new(rtol, rtol * 1e-2, f64::INFINITY);
        let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
        let mut steps = 0;
        while t < t_end {
            each(&s.step(&Oscillator, &mut t, &mut y, t_end));
            steps += 1;
        }
        (y, steps)
    }

    /// Fixed steps of length h to t_end: tolerances so loose that every step is accepted and
    /// a largest step of h (the first step too).
    fn run_fixed(h: f64, steps: usize, mut each: impl FnMut(&DenseStep)) -> Vec<f64> {
        let mut s = Dopri5::new(1e30, 1e30, h);
        let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
        s.k1 = vec![0.0; 2];
        Oscillator.rhs(t, &y, &mut s.k1);
        s.h = h;
        s.fresh = false;
        let t_end = h * steps as f64;
        for _ in 0..steps {
            let d = s.step(&Oscillator, &mut t, &mut y, t_end);
            assert!((d.h - h).abs() <= 1e-12 * h, "step {} instead of {h}", d.h);
            each(&d);
        }
        assert_eq!(t, t_end);
        y
    }

    fn error(y: &[f64], t: f64) -> f64 {
        let e = exact(t);
        (y[0] - e[0]).abs().max((y[1] - e[1]).abs())
    }

    #[test]
    fn fixed_steps_converge_at_fifth_order() {
        let t_end = 10.0;
        let ns = [20usize, 40, 80, 160];
        let hs: Vec<f64> = ns.iter().map(|&n| t_end / n as f64).collect();
        let errs: Vec<f64> = ns
            .iter()
            .zip(&hs)
            .map(|(&n, &h)| error(&run_fixed(h, n, |_| {}), t_end))
            .collect();
        let p = slope(&hs, &errs);
        assert!((p - 5.0).abs() <= 0.3, "order {p}, errors {errs:?}");
    }

    #[test]
    fn global_error_is_proportional_to_the_tolerance() {
        let t_end = 6.0 * std::f64::consts::PI; // three periods
        let tols = [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];
        let errs: Vec<f64> = tols
            .iter()
            .map(|&tol| error(&run(tol, t_end, |_| {}).0, t_end))
            .collect();
        let p = slope(&tols, &errs);
        assert!((0.7..=1.3).contains(&p), "slope {p}, errors {errs:?}");
        for (tol, e) in tols.iter().zip(&errs) {
            assert!(*e < 100.0 * tol, "error {e} at tolerance {tol}");
        }
    }

    /// A correction added at a step's end by `add_linear` leaves the extension's start as it
    /// was, moves its end by the correction and every interior point by the correction
    /// times (t − t0)/h: the remaining terms of the extension vanish at both ends.
    #[test]
    fn a_linear_correction_moves_the_step_end_only() {
        let r = [
            vec![1.0, -2.0],
            vec![0.5, 0.25],
            vec![0.3, -0.7],
            vec![-0.2, 0.9],
            vec![0.05, 0.4],
        ];
        let plain = DenseStep::from_coefficients(2.0, 0.5, r.clone());
        let mut corrected = DenseStep::from_coefficients(2.0, 0.5, r);
        corrected.add_linear(1, 1e-3);
        for k in 0..=8 {
            let t = 2.0 + 0.5 * f64::from(k) / 8.0;
            let (a, b) = (plain.component(1, t), corrected.component(1, t));
            let expected = 1e-3 * f64::from(k) / 8.0;
            assert!((b - a - expected).abs() <= 1e-15, "at {t}: {a} → {b}");
            assert_eq!(plain.component(0, t), corrected.component(0, t));
        }
    }

    #[test]
    fn dense_output_is_fourth_order_between_steps() {
        // Largest error against the closed form of the continuous extension at interior
        // points of every step (the global error the step inherits included).
        let t_end = 10.0;
        let ns = [20usize, 40, 80, 160];
        let hs: Vec<f64> = ns.iter().map(|&n| t_end / n as f64).collect();
        let mut worst = Vec::new();
        for (&n, &h) in ns.iter().zip(&hs) {
            let mut w: f64 = 0.0;
            let mut out = [0.0; 2];
            run_fixed(h, n, |d| {
                for k in 1..10 {
                    let t = d.t0 + d.h * f64::from(k) / 10.0;
                    d.eval(t, &mut out);
                    w = w.max(error(&out, t));
                    assert_eq!(d.component(0, t), out[0]);
                }
            });
            // A 4th-order interpolant errs by O(h⁵) per step: C·h⁵ with a small C.
            assert!(w <= 0.01 * h.powi(5), "dense error {w} at h = {h}");
            worst.push(w);
        }
        let p = slope(&hs, &worst);
        assert!(p >= 4.5, "dense-output order {p}: {worst:?}");
        // Adaptive run: between steps the dense output is as good as the steps themselves.
        let tol = 1e-9;
        let mut w: f64 = 0.0;
        let mut out = [0.0; 2];
        run(tol, t_end, |d| {
            for k in 1..10 {
                let t = d.t0 + d.h * f64::from(k) / 10.0;
                d.eval(t, &mut out);
                w = w.max(error(&out, t));
            }
        });
        assert!(w < 100.0 * tol, "dense error {w} at tolerance {tol}");
    }

    #[test]
    fn an_event_is_located_on_the_dense_output() {
        // cos t = 0.3 first at t = acos 0.3, located on the step that crosses it.
        let level: f64 = 0.3;
        let target = level.acos();
        let mut found = None;
        run(1e-12, 2.0, |d| {
            let g = |t: f64| d.component(0, t) - level;
            if found.is_none() && g(d.t0) > 0.0 && g(d.t1()) <= 0.0 {
                found = Some(locate(g, d.t0, d.t1(), 1e-14));
            }
        });
        let t = found.expect("a crossing");
        assert!((t - target).abs() <= 1e-12, "t = {t}, exact {target}");
        // locate itself, on the closed form, to its tolerance.
        let t = locate(|t: f64| t.cos() - level, 0.0, 2.0, 1e-15);
        assert!((t - target).abs() <= 1e-15, "t = {t}, exact {target}");
    }

    #[test]
    fn a_restart_after_an_impulse_follows_the_new_state() {
        // At t = 1 the velocity is reversed (an impulse) and the stepper restarted: from
        // y(1) = cos 1, y'(1) = +sin 1 the solution is y = cos(2 − t), y' = sin(2 − t).
        let mut s = Dopri5::new(1e-10, 1e-12, f64::INFINITY);
        let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
        while t < 1.0 {
            s.step(&Oscillator, &mut t, &mut y, 1.0);
        }
        y[1] = -y[1];
        s.restart();
        while t < 3.0 {
            s.step(&Oscillator, &mut t, &mut y, 3.0);
        }
        assert!((y[0] - (2.0_f64 - 3.0).cos()).abs() < 1e-8, "{y:?}");
        assert!((y[1] - (2.0_f64 - 3.0).sin()).abs() < 1e-8, "{y:?}");
    }
}
