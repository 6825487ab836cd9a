//! The latch-event finder: the earliest crossing of a latch angle within one accepted step,
//! located on the step's dense output.

use super::integrator::{locate, DenseStep};

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
        if step.start()[offset + j] - latch >= 0.0 {
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
