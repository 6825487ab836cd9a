//! Rodas5P, an L-stable, stiffly accurate Rosenbrock method of order 5 (8 stages, embedded
//! order 4), for the coupled deployment: the base's Ritz modes reach kilohertz (the seed's
//! mast: 11.8 Hz … 8.7 kHz) while the panels open over tens of seconds, so an explicit
//! method's step is bound by stability, not accuracy (DOPRI5 needs h < 3.3/ω_max).
//!
//! Coefficients: G. Steinebach, "Construction of Rosenbrock–Wanner method Rodas5P and
//! numerical benchmarks within the Julia Differential Equations package", BIT Numer. Math.
//! 63:27 (2023), in the form W = I/(γh) − J, k_i = W⁻¹ [f(y + Σ_j a_ij k_j) + Σ_j c_ij k_j / h]
//! (autonomous systems), y₁ = y₀ + Σ b_i k_i, error estimate k₈. The unit tests check the
//! tableau: 5th order on the harmonic oscillator with fixed steps, and a stiff linear system
//! (ω h = 10⁴) integrated with steps set by its slow part alone.
//!
//! The Jacobian J = ∂f/∂y is the system's own ([`OdeSystem::jacobian`]; the coupled model
//! gives its stiff part analytically, [`super::coupled::Coupled::stiff_jacobian`]) or, when it
//! has none, forward differences (n + 1 evaluations), at every step's start. Rosenbrock
//! methods keep their order with the exact Jacobian; the stiff part alone leaves out terms of
//! the slow motion's size (J − J_stiff = O(1/T_slow)), whose effect on a step h is O(h²)
//! relative to it and is seen by the error estimate: measured, the seed's latch time and
//! rates agree with the explicit reference to 1e-9 (tests/suite/implicit.rs) at a sixth of
//! the finite-difference version's evaluations, as long as the ringing base modes bound the
//! step anyway. Once the state is on the slow manifold (no ringing) the stiff part is not
//! enough: Rodas5P is not a W-method, and the left-out terms cost it its stability on the
//! fast modes, so its step shrinks with the panels' speed (seed, 20 modes: 38 707 steps
//! against 195 with the full Jacobian; `studies/slow_manifold_study.rs`). Modes far above
//! 1/h are damped by the method (R(∞) = 0): that is the price of a step set by the slow
//! motion, and it is why `integrator = "explicit"` (DOPRI5) stays available for
//! conservation checks on few modes.
//!
//! The continuous extension is the cubic Hermite interpolant of y and f at both ends of the
//! step (3rd order), written in [`DenseStep`]'s form. Hand-written for the same reasons as
//! [`super::integrator`]: the run needs every accepted step's continuous extension as a
//! value, restarts at every latch, and byte-identical results.

use super::integrator::{difference_columns, differenced_columns, Change, DenseStep, OdeSystem};
use faer::Mat;

const STAGES: usize = 8;
const GAMMA: f64 = 0.21193756319429014;

/// a_ij (row i, columns j < i).
const A: [[f64; 7]; STAGES] = [
    [0.0; 7],
    [3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        2.849394379747939,
        0.45842242204463923,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        -6.954028509809101,
        2.489845061869568,
        -10.358996098473584,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.8029986275628964,
        0.5072464736228206,
        -0.3988312541770524,
        -0.04721187230404641,
        0.0,
        0.0,
        0.0,
    ],
    [
        -7.502846399306121,
        2.561846144803919,
        -11.627539656261098,
        -0.18268767659942256,
        0.030198172008377946,
        0.0,
        0.0,
    ],
    [
        -7.502846399306121,
        2.561846144803919,
        -11.627539656261098,
        -0.18268767659942256,
        0.030198172008377946,
        1.0,
        0.0,
    ],
    [
        -7.502846399306121,
        2.561846144803919,
        -11.627539656261098,
        -0.18268767659942256,
        0.030198172008377946,
        1.0,
        1.0,
    ],
];

/// c_ij (row i, columns j < i).
const C: [[f64; 7]; STAGES] = [
    [0.0; 7],
    [-14.155112264123755, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        -17.97296035885952,
        -2.859693295451294,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        147.12150275711716,
        -1.41221402718213,
        71.68940251302358,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        165.43517024871676,
        -0.4592823456491126,
        42.90938336958603,
        -5.961986721573306,
        0.0,
        0.0,
        0.0,
    ],
    [
        24.854864614690072,
        -3.0009227002832186,
        47.4931110020768,
        5.5814197821558125,
        -0.6610691825249471,
        0.0,
        0.0,
    ],
    [
        30.91273214028599,
        -3.1208243349937974,
        77.79954646070892,
        34.28646028294783,
        -19.097331116725623,
        -28.087943162872662,
        0.0,
    ],
    [
        37.80277123390563,
        -3.2571969029072276,
        112.26918849496327,
        66.9347231244047,
        -40.06618937091002,
        -54.66780262877968,
        -9.48861652309627,
    ],
];

/// b_i: the last row of a plus the last stage (stiffly accurate).
const B: [f64; STAGES] = [
    -7.502846399306121,
    2.561846144803919,
    -11.627539656261098,
    -0.18268767659942256,
    0.030198172008377946,
    1.0,
    1.0,
    1.0,
];

/// ∂f/∂y at (t, y) by forward differences, f0 = f(t, y): column c from the step
/// JAC_DELTA·max(|y_c|, 1), as represented. The columns of the kinematic components
/// ([`OdeSystem::kinematic`]) come from their rows alone (zero below); the others cost one
/// evaluation each, the speeds' ([`OdeSystem::speed_offset`]) through
/// [`OdeSystem::rhs_speeds`], which shares their configuration's work. A tie
/// ([`OdeSystem::ties`]) is differenced along its direction, in its first component's
/// column ([`difference_columns`]).
pub(crate) fn forward_jacobian(sys: &dyn OdeSystem, t: f64, y: &[f64], f0: &[f64]) -> Mat<f64> {
    let n = y.len();
    let k = sys.kinematic();
    let speeds = sys.speed_offset().unwrap_or(n).clamp(k, n);
    let mut j = Mat::zeros(n, n);
    let mut yp = y.to_vec();
    let mut fp = vec![0.0; n];
    let columns = difference_columns(sys, y, |c| JAC_DELTA * y[c].abs().max(1.0));
    // The representable step of column c: its component's change.
    let step = |c: usize, change: &Change| change[0].1 - y[c];
    let (moving, speed_columns): (Vec<_>, Vec<_>) =
        columns.into_iter().partition(|(c, _)| *c < speeds);
    for (c, change) in &moving {
        for &(i, v) in change {
            yp[i] = v;
        }
        let rows = if *c < k {
            sys.rhs_kinematic(t, &yp, &mut fp[..k]);
            k
        } else {
            sys.rhs(t, &yp, &mut fp);
            n
        };
        let d = step(*c, change);
        for r in 0..rows {
            j[(r, *c)] = (fp[r] - f0[r]) / d;
        }
        for &(i, _) in change {
            yp[i] = y[i];
        }
    }
    let changes: Vec<Change> = speed_columns.iter().map(|(_, ch)| ch.clone()).collect();
    let mut out = vec![vec![0.0; n]; changes.len()];
    sys.rhs_speeds(t, y, &changes, &mut out);
    for ((c, change), fp) in speed_columns.iter().zip(&out) {
        let d = step(*c, change);
        for r in 0..n {
            j[(r, *c)] = (fp[r] - f0[r]) / d;
        }
    }
    j
}

/// Adaptive Rodas5P stepper. Error control as `Dopri5`'s, with the system's tolerance
/// scales s_i on the absolute part ([`OdeSystem::tolerance_scales`]):
/// ‖err_i / (s_i atol + rtol·max(|y0_i|, |y1_i|))‖_rms ≤ 1.
#[derive(Debug, Clone)]
pub struct Rodas5P {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step allowed.
    pub h_max: f64,
    h: f64,
    f0: Vec<f64>,
    fresh: bool,
    /// Number of right-hand-side evaluations so far (Jacobians included).
    pub evaluations: usize,
    /// Difference the Jacobian (n + 1 evaluations) even when the system offers its own (a
    /// part of it): Rodas5P keeps its stability on stiff modes only with the exact one.
    pub differenced: bool,
}

/// Relative perturbation of the forward-difference Jacobian (≈ √ε).
const JAC_DELTA: f64 = 1.5e-8;

impl Rodas5P {
    /// A stepper with the given tolerances and largest step.
    pub fn new(rtol: f64, atol: f64, h_max: f64) -> Self {
        Self {
            rtol,
            atol,
            h_max,
            h: 0.0,
            f0: Vec::new(),
            fresh: true,
            evaluations: 0,
            differenced: false,
        }
    }

    /// Forget the derivative at the current point (after an impulsive change of state).
    pub fn restart(&mut self) {
        self.fresh = true;
    }

    /// The step size the controller proposes next, s.
    pub(crate) fn proposed_step(&self) -> f64 {
        self.h
    }

    /// Recompute the derivative at the current point, keeping the step size (after a change
    /// of the right-hand side that is not an impulse).
    pub(crate) fn refresh_derivative(&mut self, sys: &dyn OdeSystem, t: f64, y: &[f64]) {
        if !self.fresh && self.f0.len() == y.len() {
            sys.rhs(t, y, &mut self.f0);
            self.evaluations += 1;
        }
    }

    /// ∂f/∂y at (t, y) by forward differences, f0 = f(t, y).
    fn jacobian(&mut self, sys: &dyn OdeSystem, t: f64, y: &[f64]) -> Mat<f64> {
        self.evaluations += differenced_columns(sys, y);
        forward_jacobian(sys, t, y, &self.f0)
    }

    /// The starting step: as DOPRI5's (Hairer's HINIT) but without its trial evaluation:
    /// 1 % of y's scale over f's, capped.
    fn initial_step(&self, y: &[f64]) -> f64 {
        let n = y.len() as f64;
        let sk = |i: usize| self.atol + self.rtol * y[i].abs();
        let d0 = (y
            .iter()
            .enumerate()
            .map(|(i, v)| (v / sk(i)).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        let d1 = (self
            .f0
            .iter()
            .enumerate()
            .map(|(i, v)| (v / sk(i)).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        let h = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        h.min(self.h_max)
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
        self.advance(sys, t, y, t_end, None)
    }

    /// dy/dt at (t, y), the state the next step starts from (evaluated once per step: the
    /// step reuses it).
    pub fn derivative(&mut self, sys: &dyn OdeSystem, t: f64, y: &[f64]) -> &[f64] {
        let n = y.len();
        if self.fresh || self.f0.len() != n {
            self.f0 = vec![0.0; n];
            sys.rhs(t, y, &mut self.f0);
            self.evaluations += 1;
            self.h = self.initial_step(y);
            self.fresh = false;
        }
        &self.f0
    }

    /// One step of length `h` (or to `t_end` if that is nearer), accepted whatever its error
    /// estimate: the caller sets the steps from what the motion must resolve, and the method's
    /// L-stability (R(∞) = 0) damps what they do not resolve — modes with ω h ≫ 1 follow
    /// their quasi-static solution after a few steps, as in structural dynamics' implicit
    /// integrators with high-frequency dissipation (Hilber, Hughes & Taylor 1977; Chung &
    /// Hulbert 1993). A step that is not finite returns as such (the caller stops there).
    pub fn step_scheduled(
        &mut self,
        sys: &dyn OdeSystem,
        t: &mut f64,
        y: &mut [f64],
        t_end: f64,
        h: f64,
    ) -> DenseStep {
        self.advance(sys, t, y, t_end, Some(h))
    }

    fn advance(
        &mut self,
        sys: &dyn OdeSystem,
        t: &mut f64,
        y: &mut [f64],
        t_end: f64,
        scheduled: Option<f64>,
    ) -> DenseStep {
        let n = y.len();
        self.derivative(sys, *t, y);
        let jac = {
            let mut j = Mat::zeros(n, n);
            if !self.differenced && sys.jacobian(*t, y, &mut j) {
                j
            } else {
                self.jacobian(sys, *t, y)
            }
        };
        let scales = sys.tolerance_scales();
        if let Some(s) = &scales {
            assert_eq!(s.len(), n, "one tolerance scale per component");
        }
        let mut k = vec![vec![0.0; n]; STAGES];
        let mut yt = vec![0.0; n];
        let mut rhs = Mat::<f64>::zeros(n, 1);
        let mut f1 = vec![0.0; n];
        loop {
            let mut h = scheduled.unwrap_or_else(|| self.h.min(self.h_max));
            let last = *t + h >= t_end - 1e-12 * t_end.abs().max(1.0);
            if last {
                h = t_end - *t;
            }
            // W = I/(γh) − J, factored once per attempt.
            let w = Mat::from_fn(n, n, |r, c| {
                let d = if r == c { 1.0 / (GAMMA * h) } else { 0.0 };
                d - jac[(r, c)]
            });
            let lu = w.partial_piv_lu();
            let mut finite = true;
            for i in 0..STAGES {
                for r in 0..n {
                    yt[r] = y[r] + (0..i).map(|j| A[i][j] * k[j][r]).sum::<f64>();
                }
                if i == 0 {
                    yt.copy_from_slice(y);
                    for r in 0..n {
                        rhs[(r, 0)] = self.f0[r];
                    }
                } else {
                    sys.rhs(*t, &yt, &mut f1);
                    self.evaluations += 1;
                    for r in 0..n {
                        rhs[(r, 0)] = f1[r] + (0..i).map(|j| C[i][j] * k[j][r]).sum::<f64>() / h;
                    }
                }
                faer::linalg::solvers::Solve::solve_in_place(&lu, rhs.as_mut());
                for r in 0..n {
                    k[i][r] = rhs[(r, 0)];
                    finite &= k[i][r].is_finite();
                }
            }
            let y1: Vec<f64> = (0..n)
                .map(|r| y[r] + (0..STAGES).map(|i| B[i] * k[i][r]).sum::<f64>())
                .collect();
            let mut err = 0.0;
            for r in 0..n {
                let sc = self.atol * scales.as_ref().map_or(1.0, |s| s[r])
                    + self.rtol * y[r].abs().max(y1[r].abs());
                err += (k[STAGES - 1][r] / sc).powi(2);
            }
            let err = if finite {
                (err / n as f64).sqrt()
            } else {
                f64::INFINITY
            };
            let fac = if err == 0.0 {
                5.0
            } else if err.is_finite() {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            } else {
                0.2
            };
            if scheduled.is_some() || err <= 1.0 || h.abs() < 1e-14 * t.abs().max(1.0) {
                sys.rhs(*t + h, &y1, &mut f1);
                self.evaluations += 1;
                // Cubic Hermite in DenseStep's form: r1 = Δ, r2 = h f0 − Δ,
                // r3 = Δ − h f1 − r2, r4 = 0.
                let ydiff: Vec<f64> = (0..n).map(|r| y1[r] - y[r]).collect();
                let r2: Vec<f64> = (0..n).map(|r| h * self.f0[r] - ydiff[r]).collect();
                let r3: Vec<f64> = (0..n).map(|r| ydiff[r] - h * f1[r] - r2[r]).collect();
                let dense =
                    DenseStep::from_coefficients(*t, h, [y.to_vec(), ydiff, r2, r3, vec![0.0; n]]);
                *t = if last { t_end } else { *t + h };
                y.copy_from_slice(&y1);
                self.f0.copy_from_slice(&f1);
                if !last {
                    self.h = h * fac;
                }
                return dense;
            }
            self.h = h * fac.min(1.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y'' = −y as a first-order system.
    struct Oscillator;
    impl OdeSystem for Oscillator {
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    /// Fixed steps (tolerance huge): the global error at t = 2 falls as h⁵.
    #[test]
    fn fixed_steps_converge_at_fifth_order() {
        let err = |steps: usize| {
            let h = 2.0 / steps as f64;
            let mut s = Rodas5P::new(1e3, 1e3, h);
            let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
            while t < 2.0 - 1e-12 {
                s.step(&Oscillator, &mut t, &mut y, 2.0);
            }
            ((y[0] - 2f64.cos()).powi(2) + (y[1] + 2f64.sin()).powi(2)).sqrt()
        };
        let (e1, e2) = (err(10), err(20));
        let order = (e1 / e2).log2();
        // A linear problem may converge faster than the method's order (here ≈ 5.5–6).
        assert!(
            (4.7..6.3).contains(&order),
            "observed order {order} ({e1:e}, {e2:e})"
        );
    }

    /// y' = −λ (y − cos t) − sin t, λ = 1e6: y = cos t after the initial layer. The step is
    /// set by cos t (tolerance 1e-8), not by λ: far fewer steps than λ·T, and accurate.
    struct Stiff;
    impl OdeSystem for Stiff {
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            // Autonomous form: y[1] = t.
            dy[0] = -1e6 * (y[0] - y[1].cos()) - y[1].sin();
            dy[1] = 1.0;
        }
    }

    #[test]
    fn a_stiff_system_takes_steps_of_its_slow_part() {
        let mut s = Rodas5P::new(1e-8, 1e-10, f64::INFINITY);
        let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
        let mut steps = 0;
        while t < 10.0 {
            s.step(&Stiff, &mut t, &mut y, 10.0);
            steps += 1;
        }
        assert!(
            (y[0] - 10f64.cos()).abs() < 1e-7,
            "y = {} vs {}",
            y[0],
            10f64.cos()
        );
        assert!(steps < 2000, "{steps} steps");
    }

    /// The dense output between steps is the cubic Hermite interpolant: 4th-order local
    /// error, checked against the closed form at mid-step.
    #[test]
    fn dense_output_interpolates_between_steps() {
        let mut s = Rodas5P::new(1e-10, 1e-12, 0.05);
        let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
        let mut out = vec![0.0; 2];
        let mut worst: f64 = 0.0;
        while t < 3.0 {
            let d = s.step(&Oscillator, &mut t, &mut y, 3.0);
            let tm = d.t0 + 0.5 * d.h;
            d.eval(tm, &mut out);
            worst = worst.max((out[0] - tm.cos()).abs());
        }
        // h = 0.05: the Hermite error is h⁴/384·max|y''''| ≈ 1.6e-8.
        assert!(worst < 2e-8, "mid-step error {worst:e}");
    }
}
