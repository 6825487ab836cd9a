//! The restoration of a system's conserved quantities after every step: a projection method
//! (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, 2nd ed., Springer 2006,
//! §IV.4) through the coordinates the system names ([`OdeSystem::invariant_coordinates`]),
//! on which the invariants depend linearly (a free spacecraft's momentum on its hub's
//! velocity and rate).

use super::integrator::OdeSystem;
use faer::linalg::solvers::Solve;
use faer::Mat;

/// Steps over which the invariants' Jacobian is kept ([`Restorer::restore`]).
const RESTORE_REFRESH: usize = 16;

/// Newton iterations restoring the invariants at most at an event ([`Restorer::restore`] with
/// `tight`).
const RESTORE_ITERATIONS: usize = 4;

fn max_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, x| m.max(x.abs()))
}

/// The conserved quantities at a run's start and what restores them.
#[derive(Debug, Clone)]
pub struct Restorer {
    /// The conserved quantities at the first step ([`OdeSystem::invariants`]); empty when the
    /// system has none.
    target: Vec<f64>,
    /// ∂(invariants)/∂(their coordinates), kept while it serves.
    jacobian: Option<Mat<f64>>,
    /// Restorations since the invariants' Jacobian was differenced.
    age: usize,
    /// The invariants' residual (max norm) found by the last restoration.
    residual: f64,
    /// Right-hand-side-sized evaluations spent (invariants evaluated), for the run's count.
    pub evaluations: usize,
}

impl Default for Restorer {
    fn default() -> Self {
        Self {
            target: Vec::new(),
            jacobian: None,
            age: 0,
            residual: f64::INFINITY,
            evaluations: 0,
        }
    }
}

impl Restorer {
    /// Takes the invariants at `y` as the target, the first time only: impacts and captures
    /// conserve them (internal impulses), and a state located on a step's dense output carries
    /// that step's own error.
    pub fn start(&mut self, sys: &dyn OdeSystem, y: &[f64]) {
        if self.target.is_empty() {
            self.target = sys.invariants(y);
        }
    }

    /// Differences the invariants' Jacobian afresh at the next restoration.
    pub fn forget_jacobian(&mut self) {
        self.jacobian = None;
    }

    /// Restores the conserved quantities ([`OdeSystem::invariants`]) in `y` through their
    /// coordinates, by Newton's method on their exact linear dependence (the correction is
    /// returned, to be applied to the slow state too). The slow run and the ringing each
    /// conserve the free spacecraft's momentum only to their truncation: measured on the
    /// seed with compliant latches, the ringing's first-order approximation lets P drift to
    /// 4.6e-3 N·s in the second after the capture, while the latch mode (15.6 rad/s) is not
    /// slow against the mast's (109 rad/s). Restoring it after every step is a projection
    /// method (Hairer, Lubich & Wanner, Geometric Numerical Integration, IV.4): it keeps the
    /// order and holds the invariants at every step's end, up to what the Jacobian's age
    /// leaves.
    ///
    /// After a step (`tight` false) one iteration with the kept Jacobian (differenced afresh
    /// after [`RESTORE_REFRESH`] restorations, or when the residual has grown fourfold since
    /// the last) removes most of the step's error, and what is left is removed with the next
    /// step's: nothing accumulates while the Jacobian contracts. At an event (`tight`) the
    /// iterations go on to rounding. The step's dense output takes the correction spread
    /// linearly over the step (the stepper adds it to its dense output, [`crate::ode::DenseStep::add_linear`]), so that it stays continuous.
    pub fn restore(
        &mut self,
        sys: &dyn OdeSystem,
        y: &mut [f64],
        tight: bool,
    ) -> Vec<(usize, f64)> {
        if self.target.is_empty() {
            return Vec::new();
        }
        self.age += 1;
        if self.age > RESTORE_REFRESH {
            self.jacobian = None;
        }
        let coords = sys.invariant_coordinates();
        let residual = |y: &[f64]| -> Vec<f64> {
            self.target
                .iter()
                .zip(sys.invariants(y))
                .map(|(t, v)| t - v)
                .collect()
        };
        let mut r = residual(y);
        self.evaluations += 1;
        // A residual growing from step to step means the kept Jacobian no longer contracts
        // it (the inertia has changed): difference it afresh.
        let growing = max_norm(&r) > 4.0 * self.residual;
        self.residual = max_norm(&r);
        if growing && self.age > 0 {
            self.jacobian = None;
        }
        let before: Vec<f64> = coords.iter().map(|&k| y[k]).collect();
        // Newton on an exactly linear dependence: one iteration with a fresh Jacobian
        // leaves rounding; a kept one (from an earlier configuration) contracts by its
        // change, so iterate while that pays, and refresh it when it no longer contracts
        // by 1e-3.
        for _ in 0..if tight { RESTORE_ITERATIONS } else { 1 } {
            if max_norm(&r) == 0.0 {
                break;
            }
            let g = match self.jacobian.take() {
                Some(g) => g,
                None => {
                    // Linear in the coordinates: a unit difference is exact.
                    let base: Vec<f64> = sys.invariants(y);
                    let mut g = Mat::<f64>::zeros(base.len(), coords.len());
                    let mut yp = y.to_vec();
                    for (c, &k) in coords.iter().enumerate() {
                        yp[k] += 1.0;
                        for (row, (a, b)) in sys.invariants(&yp).iter().zip(&base).enumerate() {
                            g[(row, c)] = a - b;
                        }
                        yp[k] = y[k];
                    }
                    self.evaluations += coords.len() + 1;
                    self.age = 0;
                    g
                }
            };
            let rhs = Mat::<f64>::from_fn(r.len(), 1, |i, _| r[i]);
            let step = g.partial_piv_lu().solve(&rhs);
            if !(0..coords.len()).all(|c| step[(c, 0)].is_finite()) {
                break;
            }
            let kept: Vec<f64> = coords.iter().map(|&k| y[k]).collect();
            for (c, &k) in coords.iter().enumerate() {
                y[k] += step[(c, 0)];
            }
            if !tight {
                self.jacobian = Some(g);
                break;
            }
            let next = residual(y);
            self.evaluations += 1;
            if max_norm(&next) >= max_norm(&r) {
                // Rounding reached (or a useless Jacobian): undo this iteration.
                for (&k, v) in coords.iter().zip(kept) {
                    y[k] = v;
                }
                break;
            }
            if max_norm(&next) <= 1e-3 * max_norm(&r) {
                self.jacobian = Some(g);
            }
            r = next;
        }
        coords
            .iter()
            .zip(before)
            .map(|(&k, b)| (k, y[k] - b))
            .collect()
    }
}
