//! The latch-event finder: the earliest crossing of a latch angle within one accepted step,
//! located on the step's dense output.

use crate::ode::integrator::{locate, DenseStep};

/// Interior points at which each step is sampled so that a crossing and return within one
/// step is not missed.
const SUBDIVISIONS: u32 = 8;

/// Absolute time tolerance of a located event, relative to max(|t|, 1) s.
pub const EVENT_TOL: f64 = 1e-12;

/// A latch angle reached within a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// Time of the crossing, s.
    pub t: f64,
    /// The hinge (0-based).
    pub hinge: usize,
}

/// The earliest crossing of its latch angle by any free hinge in `step`. Hinge j's angle is
/// component `offset + j` of the state; `latch[j]` is its latch angle and `free[j]` says
/// whether it still moves. A hinge already at or beyond its latch angle at the step's start
/// (only possible after rounding) latches at the start.
pub fn earliest_latch(
    step: &DenseStep,
    offset: usize,
    latch: &[f64],
    free: &[bool],
) -> Option<Crossing> {
    let t_start = step.t0;
    let mut event: Option<Crossing> = None;
    for (j, (&latch, _)) in latch.iter().zip(free).enumerate().filter(|(_, (_, f))| **f) {
        let g = |tt: f64| step.component(offset + j, tt) - latch;
        if g(t_start) >= 0.0 {
            return Some(Crossing {
                t: t_start,
                hinge: j,
            });
        }
        let mut a = t_start;
        for s in 1..=SUBDIVISIONS {
            let b = t_start + step.h * f64::from(s) / f64::from(SUBDIVISIONS);
            if g(b) >= 0.0 {
                let te = locate(g, a, b, EVENT_TOL * b.abs().max(1.0));
                if event.is_none_or(|e| te < e.t) {
                    event = Some(Crossing { t: te, hinge: j });
                }
                break;
            }
            a = b;
        }
    }
    event
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::integrator::{Dopri5, OdeSystem};

    /// From y = (0, 1, 0): components sin t, cos t and 2 sin t.
    struct Waves;

    impl OdeSystem for Waves {
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -y[0];
            dy[2] = 2.0 * y[1];
        }
    }

    /// The first crossing over a tight adaptive run to t = 1 (hinge j on component j).
    fn first(latch: &[f64], free: &[bool]) -> Option<Crossing> {
        let mut s = Dopri5::new(1e-12, 1e-14, f64::INFINITY);
        let (mut t, mut y) = (0.0, vec![0.0, 1.0, 0.0]);
        while t < 1.0 {
            let step = s.step(&Waves, &mut t, &mut y, 1.0);
            if let Some(c) = earliest_latch(&step, 0, latch, free) {
                return Some(c);
            }
        }
        None
    }

    #[test]
    fn the_earliest_crossing_of_a_free_hinge_is_located_to_1e_12() {
        // cos t never rises to 1.5; sin t reaches 0.5 at π/6, 2 sin t at asin 0.25 (earlier).
        let c = first(&[0.5, 1.5, 0.5], &[true, true, true]).expect("a crossing");
        assert_eq!(c.hinge, 2);
        assert!((c.t - 0.25_f64.asin()).abs() <= 1e-12, "{c:?}");
        // With hinge 2 locked, hinge 0 at π/6.
        let c = first(&[0.5, 1.5, 0.5], &[true, true, false]).expect("a crossing");
        assert_eq!(c.hinge, 0);
        assert!((c.t - std::f64::consts::FRAC_PI_6).abs() <= 1e-12, "{c:?}");
        // Locked hinges are ignored; a free one that never reaches its latch gives none.
        assert_eq!(first(&[0.5, 1.5, 0.5], &[false, true, false]), None);
    }

    #[test]
    fn a_hinge_already_at_its_latch_angle_latches_at_the_step_start() {
        // cos 0 = 1 ≥ 0.9: hinge 1 latches at t = 0, before the others' crossings.
        let c = first(&[0.5, 0.9, 0.5], &[true, true, true]).expect("a crossing");
        assert_eq!(c, Crossing { t: 0.0, hinge: 1 });
    }
}
