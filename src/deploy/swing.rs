//! The swing-back tracker: panels that swing back below their initial angle (the real array
//! would collide there; the model has no contact).

use super::events::EVENT_TOL;
use super::integrator::{locate, DenseStep};
use crate::warning::Warning;

/// Margin below the initial angle that counts as a swing-back, rad.
const MARGIN: f64 = 1e-12;

/// Points per step at which the dense output is scanned.
const SUBDIVISIONS: u32 = 8;

/// A panel that swung back below its initial angle: the real array would collide there.
#[derive(Debug, Clone, PartialEq)]
pub struct SwingBack {
    /// Hinge (1-based).
    pub hinge: usize,
    /// First time below the initial angle, s.
    pub first_time: f64,
    /// Smallest angle reached, rad.
    pub min_angle: f64,
}

/// Tracks, per hinge, the first time below the initial angle and the smallest angle seen.
/// It is fed the run's samples ([`observe`](Self::observe)) and its dense steps
/// ([`scan`](Self::scan)); the smallest angle is the smallest at the points it was fed.
#[derive(Debug, Clone)]
pub struct SwingTracker {
    initial: Vec<f64>,
    found: Vec<Option<SwingBack>>,
}

impl SwingTracker {
    /// A tracker for hinges with these initial angles (rad).
    pub fn new(initial: Vec<f64>) -> Self {
        let found = vec![None; initial.len()];
        Self { initial, found }
    }

    fn record(&mut self, i: usize, first_time: f64, angle: f64) {
        match &mut self.found[i] {
            Some(s) => s.min_angle = s.min_angle.min(angle),
            None => {
                self.found[i] = Some(SwingBack {
                    hinge: i + 1,
                    first_time,
                    min_angle: angle,
                })
            }
        }
    }

    /// The angles `alpha` (rad) at time `t`: a hinge below its initial angle starts its
    /// swing-back at `t` if none was seen before.
    pub fn observe(&mut self, t: f64, alpha: &[f64]) {
        for (i, &a) in alpha.iter().enumerate() {
            if a < self.initial[i] - MARGIN {
                self.record(i, t, a);
            }
        }
    }

    /// The dense step on (step.t0, t_seen] (hinge i's angle is component `offset + i`),
    /// scanned at `SUBDIVISIONS` evenly spaced points; a swing-back starting in the step
    /// has its first time located on the dense output.
    pub fn scan(&mut self, step: &DenseStep, offset: usize, t_seen: f64) {
        let t_start = step.t0;
        for i in 0..self.initial.len() {
            let a0 = self.initial[i];
            let g = |tt: f64| a0 - MARGIN - step.component(offset + i, tt);
            let mut a = t_start;
            for s in 1..=SUBDIVISIONS {
                let b = t_start + (t_seen - t_start) * f64::from(s) / f64::from(SUBDIVISIONS);
                if g(b) > 0.0 {
                    let first = if self.found[i].is_none() && g(a) <= 0.0 {
                        locate(g, a, b, EVENT_TOL * b.abs().max(1.0))
                    } else {
                        b
                    };
                    self.record(i, first, step.component(offset + i, b));
                }
                a = b;
            }
        }
    }

    /// The swing-backs seen, in hinge order, with their warnings.
    pub fn finish(self) -> (Vec<SwingBack>, Vec<Warning>) {
        let found: Vec<SwingBack> = self.found.into_iter().flatten().collect();
        let warnings = found
            .iter()
            .map(|s| Warning::SwingBack {
                hinge: s.hinge,
                first_time: s.first_time,
                min_angle: s.min_angle,
                initial_angle: self.initial[s.hinge - 1],
            })
            .collect();
        (found, warnings)
    }
}
