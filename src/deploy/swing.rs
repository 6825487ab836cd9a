//! The swing-back tracker: panels that swing back below their initial angle (the real array
//! would collide there; the model has no contact).

use super::events::EVENT_TOL;
use crate::ode::integrator::{locate, DenseStep};
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
        let n = self.initial.len();
        // The angles at the subdivision points, all hinges at once.
        let (mut before, mut now) = (vec![0.0; n], vec![0.0; n]);
        step.components(offset, t_start, &mut before);
        let mut a = t_start;
        for s in 1..=SUBDIVISIONS {
            let b = t_start + (t_seen - t_start) * f64::from(s) / f64::from(SUBDIVISIONS);
            step.components(offset, b, &mut now);
            for i in 0..n {
                let a0 = self.initial[i];
                if a0 - MARGIN - now[i] > 0.0 {
                    let first = if self.found[i].is_none() && a0 - MARGIN - before[i] <= 0.0 {
                        let g = |tt: f64| a0 - MARGIN - step.component(offset + i, tt);
                        locate(g, a, b, EVENT_TOL * b.abs().max(1.0))
                    } else {
                        b
                    };
                    self.record(i, first, now[i]);
                }
            }
            std::mem::swap(&mut before, &mut now);
            a = b;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A step on [2, 6] whose three angles (components 1..4 of y) are linear: hinge 1 falls
    /// from 0.101 to 0.097 against its initial 0.1, so it swings back from t = 3 on (closed
    /// form: 0.101 − 0.001 (t − 2) = 0.1 − MARGIN); hinge 2 stays above its initial angle;
    /// hinge 3 starts below its own and falls further. The scan locates hinge 1's first time
    /// and records the least angle seen at the subdivision points.
    #[test]
    fn a_falling_angle_is_caught_where_it_crosses_its_initial_value() {
        let start = vec![9.0, 0.101, 0.5, 0.29];
        let end = vec![9.0, 0.097, 0.6, 0.25];
        let slope: Vec<f64> = start.iter().zip(&end).map(|(a, b)| b - a).collect();
        let zero = vec![0.0; 4];
        let step = DenseStep::from_coefficients(
            2.0,
            4.0,
            [start, slope, zero.clone(), zero.clone(), zero],
        );
        let mut tracker = SwingTracker::new(vec![0.1, 0.4, 0.3]);
        tracker.scan(&step, 1, 6.0);
        let (found, warnings) = tracker.finish();
        assert_eq!(found.len(), 2);
        assert_eq!(warnings.len(), 2);
        let first = 2.0 + (0.001 + MARGIN) / 0.001;
        assert_eq!(found[0].hinge, 1);
        assert!(
            (found[0].first_time - first).abs() <= 1e-9,
            "{}",
            found[0].first_time
        );
        assert!((found[0].min_angle - 0.097).abs() <= 1e-15);
        assert_eq!(found[1].hinge, 3);
        // Already below at the step's start: its first time is the first subdivision.
        assert!((found[1].first_time - 2.5).abs() <= 1e-15);
        assert!((found[1].min_angle - 0.25).abs() <= 1e-15);
    }
}
