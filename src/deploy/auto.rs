//! The automatic choice of model and method for a coupled deployment, and the check of its
//! accuracy (docs/theory.md §2.9, `[deployment] integrator = "auto"`, the default).
//!
//! The model: the base keeps its hub-fixed modes up to a cutoff ω_c = μ ω_a, ω_a the
//! array's fastest motion ([`super::timescales::fastest`]: its hinge springs and cable, base
//! held), plus the static correction of the modes above ([`super::static_correction`]). The
//! method: Rodas5P at steps set by the phase ([`super::Schedule`]): κ/ω of the fastest motion
//! the phase must resolve, and at most a turn δ of any opening hinge; the base's vibration
//! above 1/h follows its quasi-static solution.
//!
//! The accuracy: the run is repeated with everything refined (μ doubled with at least two
//! more modes, κ divided by √2, δ halved) and the two compared on what is well posed: every
//! capture's time and the capturing hinge's rate and, with compliant latches, the peak latch
//! moments from the first capture on (the base beams' root loads are estimated beside them);
//! with rigid latches the first impact's time and rate (after an impact on an elastic base the
//! outcome depends on the modes kept: no continuum limit); with no latch or capture before the
//! end time, the angles and rates reached there. The finer run is reported, with the largest
//! relative difference as its error estimate, and the refinement goes on while the estimate
//! exceeds the accuracy asked for (at most [`LEVELS`] runs; then the run says which estimate
//! it reached). With `base_modes` given, the count stays the user's and only the steps are
//! refined.

use super::base::BaseKind;
use super::coupled::Coupled;
use super::run::Schedule;
use super::{DeployError, Deployment, DeploymentResult, LatchModel, RunSettings};
use crate::structure::Structure;

/// The cutoff's margin over the array's fastest motion at the first level.
pub const MARGIN: f64 = 2.0;

/// The most runs the refinement makes.
pub const LEVELS: usize = 3;

/// The level-`k` settings: μ = 2·2^k, δ = 0.02/2^k, κ = 1/√2^k (the steps resolve the
/// kept modes, so that doubling the cutoff also shortens them where the base sets them).
pub fn level(k: usize) -> (f64, Schedule) {
    let f = (1u64 << k.min(30)) as f64;
    let base = Schedule::default();
    (
        MARGIN * f,
        Schedule {
            kappa: base.kappa / f.sqrt(),
            delta: base.delta / f,
        },
    )
}

/// What the automatic run found about its own accuracy.
#[derive(Debug, Clone, PartialEq)]
pub struct Accuracy {
    /// The accuracy asked for (relative).
    pub asked: f64,
    /// The estimate: the largest relative difference between the reported run and the one
    /// before it in the events' times and rates and the peak latch moments.
    pub estimate: f64,
    /// Its parts: capture (or first impact) times, relative to the time since release (with
    /// no latch or capture before the end time: the angles reached there, against the latch
    /// angles).
    pub times: f64,
    /// The latching (captured) hinge's rate at each of those events, relative to the largest
    /// such rate (a hinge creeping into its latch has a small rate, of no design consequence,
    /// that a relative measure of its own would blow up).
    pub rates: f64,
    /// Peak latch moments (compliant latches), each against the largest of them (as the
    /// rates).
    pub latch_moments: f64,
    /// Peak root forces and moments of the base's beams after the first capture, relative
    /// (estimated, not held to the accuracy: [`Accuracy::reached`]).
    pub root_loads: f64,
    /// The runs made (levels 0, 1, …).
    pub runs: usize,
    /// The right-hand-side evaluations of every run together.
    pub evaluations: usize,
    /// The base's cutoff of the reported run, rad/s (None with `base_modes` given, or a
    /// rigid base).
    pub cutoff: Option<f64>,
    /// The step rule of the reported run.
    pub schedule: Schedule,
    /// Rigid latches: only the first impact is compared (what follows it depends on the
    /// base's truncation).
    pub first_impact_only: bool,
    /// The two runs differ in their events (count or hinges): no estimate.
    pub events_differ: bool,
}

impl Accuracy {
    /// The estimate meets the accuracy asked for: the events' times and rates and the peak
    /// latch moments. The base's root loads are estimated beside them but not held to it:
    /// their peaks right after a capture carry the base's response to the latch damper's
    /// moment, which starts as a step (c_L α̇ at the capture) and so excites every mode, the
    /// more of them the higher the cutoff — a shear force converges with the modes kept as
    /// the effective masses above the cutoff vanish, slowly (docs/theory.md §2.9).
    pub fn reached(&self) -> bool {
        !self.events_differ && self.estimate <= self.asked
    }
}

/// The base of `d` at a refinement level of cutoff margin `margin`, keeping at least
/// `at_least` modes: the user's count (with the correction) when `base_modes` is given, the
/// cutoff otherwise; rigid stays rigid.
fn base_at(d: &Deployment, margin: f64, at_least: usize) -> (BaseKind, Option<f64>) {
    match d.base {
        BaseKind::Rigid => (BaseKind::Rigid, None),
        BaseKind::Flexible { modes: Some(m) } | BaseKind::Corrected { modes: m } => {
            (BaseKind::Corrected { modes: m.max(1) }, None)
        }
        BaseKind::Flexible { modes: None } | BaseKind::Reduced { .. } => {
            // The array on its hinge springs and cable: a latch-up's faster vibration is
            // resolved by the steps while it lasts, and with it the correction's vectors
            // below 1/h (the base's quasi-static and first dynamic response to the latch).
            let fastest = super::timescales::fastest(&d.chain, &[], d.synchronisation, &[]);
            let cutoff = margin * fastest;
            (BaseKind::Reduced { cutoff, at_least }, Some(cutoff))
        }
    }
}

/// What the automatic run tells an observer while it works (the command line's progress and
/// cost estimate; the library never prints).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Progress {
    /// Run `run` (1-based) of at most [`LEVELS`] starts; from the second on, the right-hand-
    /// side evaluations it is expected to take (the previous run's times 2.5: twice the
    /// steps where the kept modes set them, and more modes) and those made so far.
    Starting {
        /// The run's number, from 1.
        run: usize,
        /// The expected evaluations of this run (None for the first).
        expected: Option<usize>,
        /// Evaluations made by the runs before it.
        done: usize,
    },
    /// Run `run` has reached time `t` (s) of at most `end` (s).
    At {
        /// The run's number, from 1.
        run: usize,
        /// Time reached, s.
        t: f64,
        /// The deployment's end time, s.
        end: f64,
    },
}

/// One run at level `k`.
fn run_level(
    st: &Structure,
    d: &Deployment,
    k: usize,
    at_least: usize,
    record_samples: bool,
    observe: &mut dyn FnMut(Progress),
) -> Result<(Coupled, DeploymentResult, Option<f64>, Schedule), DeployError> {
    let (margin, schedule) = level(k);
    let (base, cutoff) = base_at(d, margin, at_least);
    let dk = Deployment { base, ..d.clone() };
    let c = dk.coupled(st)?;
    let settings = RunSettings {
        record_samples,
        schedule,
        ..dk.settings()
    };
    let end = settings.end_time;
    let r = super::run::run_observed(&c, &settings, super::MAX_STEPS, &mut |t| {
        observe(Progress::At { run: k + 1, t, end })
    });
    Ok((c, r, cutoff, schedule))
}

/// The relative difference of two values against a scale.
fn rel(a: f64, b: f64, scale: f64) -> f64 {
    if scale > 0.0 {
        (a - b).abs() / scale
    } else if a == b {
        0.0
    } else {
        f64::INFINITY
    }
}

/// The parts of the estimate between a coarse and a fine run of `d`: (times, rates,
/// latch moments, root loads, events differ).
fn compare(
    d: &Deployment,
    coarse: &DeploymentResult,
    fine: &DeploymentResult,
    beams: usize,
) -> (f64, f64, f64, f64, bool) {
    let compliant = matches!(d.latch, LatchModel::Compliant { .. });
    // (time, hinge, rates) of each event compared.
    let events = |r: &DeploymentResult| -> Vec<(f64, usize, Vec<f64>)> {
        if compliant {
            r.captures
                .iter()
                .map(|c| (c.time, c.hinge, c.rates.clone()))
                .collect()
        } else {
            r.latches
                .iter()
                .take(1)
                .map(|l| (l.time, l.hinge, l.rates_before.clone()))
                .collect()
        }
    };
    let (a, b) = (events(coarse), events(fine));
    if a.len() != b.len() || a.iter().zip(&b).any(|(x, y)| x.1 != y.1) {
        return (f64::INFINITY, f64::INFINITY, 0.0, 0.0, true);
    }
    if b.is_empty() {
        // No latch and no capture before the end time: the state reached instead, every
        // hinge's angle against its latch angle and its rate against the largest rate.
        let (Some(x), Some(y)) = (coarse.samples.last(), fine.samples.last()) else {
            return (f64::INFINITY, f64::INFINITY, 0.0, 0.0, true);
        };
        let angles = x
            .alpha
            .iter()
            .zip(&y.alpha)
            .zip(&d.chain.hinges)
            .map(|((p, q), h)| rel(*p, *q, h.latch_angle.abs()))
            .fold(0.0, f64::max);
        let largest = y.rate.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let rates = x
            .rate
            .iter()
            .zip(&y.rate)
            .map(|(p, q)| rel(*p, *q, largest))
            .fold(0.0, f64::max);
        return (angles, rates, 0.0, 0.0, false);
    }
    // Each event's time, against the time since release, and the latching (or captured)
    // hinge's rate there, against itself: the other hinges' rates at that instant include
    // the captured ones' ringing on their latches, a small oscillation of no design use.
    let (mut times, mut rates) = (0.0_f64, 0.0_f64);
    let largest = b
        .iter()
        .filter_map(|e| e.2.get(e.1 - 1))
        .fold(0.0_f64, |m, r| m.max(r.abs()));
    for (x, y) in a.iter().zip(&b) {
        times = times.max(rel(x.0, y.0, y.0.abs()));
        let j = y.1 - 1;
        if let (Some(p), Some(q)) = (x.2.get(j), y.2.get(j)) {
            rates = rates.max(rel(*p, *q, largest));
        }
    }
    let (mut moments, mut roots) = (0.0_f64, 0.0_f64);
    if compliant && !b.is_empty() {
        let n = d.chain.len();
        let (pa, pb) = (&coarse.latch_up_peaks, &fine.latch_up_peaks);
        // Each latch's peak moment against the largest of them, as the capture rates are
        // against the largest rate: a hinge creeping into its latch takes a small moment, of
        // no design consequence, whose own relative change a long undamped ringing of the
        // base before it sets (docs/theory.md §2.9).
        moments = group_stride(pa, pb, 0, n, 1, 0, 1.0);
        // Root force and moment of each beam, alternating; peaks below 1e-3 of the largest
        // of their kind are not design loads: their difference is measured against that floor.
        let forces = group_stride(pa, pb, n, beams, 2, 0, 1e-3);
        let torques = group_stride(pa, pb, n, beams, 2, 1, 1e-3);
        roots = forces.max(torques);
    }
    (times, rates, moments, roots, false)
}

/// The largest relative difference of the peaks `offset + stride·i + start` (i < count) of
/// two runs, each against the finer run's peak or, if larger, `floor` times the group's
/// largest: the latch moments (stride 1), the root forces or moments (stride 2, start 0 or
/// 1).
fn group_stride(
    pa: &[super::peaks::Peak],
    pb: &[super::peaks::Peak],
    offset: usize,
    count: usize,
    stride: usize,
    start: usize,
    floor: f64,
) -> f64 {
    let idx: Vec<usize> = (0..count).map(|b| offset + stride * b + start).collect();
    let top = idx
        .iter()
        .filter_map(|&i| pb.get(i))
        .fold(0.0_f64, |m, p| m.max(p.0));
    idx.iter()
        .filter_map(|&i| Some((pa.get(i)?.0, pb.get(i)?.0)))
        .map(|(x, y)| rel(x, y, y.abs().max(floor * top)))
        .fold(0.0, f64::max)
}

/// The deployment of `d` on `st` with the automatic model and method, refined until its
/// estimate meets `d.accuracy` (at most [`LEVELS`] runs): the finest run, its model and its
/// accuracy.
pub fn simulate(
    st: &Structure,
    d: &Deployment,
    record_samples: bool,
) -> Result<(Coupled, DeploymentResult, Accuracy), DeployError> {
    simulate_observed(st, d, record_samples, &mut |_| {})
}

/// [`simulate`], telling `observe` where it is ([`Progress`]).
pub fn simulate_observed(
    st: &Structure,
    d: &Deployment,
    record_samples: bool,
    observe: &mut dyn FnMut(Progress),
) -> Result<(Coupled, DeploymentResult, Accuracy), DeployError> {
    observe(Progress::Starting {
        run: 1,
        expected: None,
        done: 0,
    });
    let (mut c, mut r, _, _) = run_level(st, d, 0, 0, record_samples, observe)?;
    let mut evaluations = r.evaluations;
    let mut k = 1;
    loop {
        // Each refinement keeps at least two more modes (one more pair of a beam's bending
        // modes): a doubled cutoff below the next mode would compare a model with itself and
        // see nothing of its truncation.
        let kept = c.modes() - c.base.correction;
        observe(Progress::Starting {
            run: k + 1,
            expected: Some(r.evaluations * 5 / 2),
            done: evaluations,
        });
        let (c1, r1, cutoff, schedule) = run_level(st, d, k, kept + 2, record_samples, observe)?;
        evaluations += r1.evaluations;
        let (times, rates, latch_moments, root_loads, events_differ) =
            compare(d, &r, &r1, c1.base.beams.len());
        let a = Accuracy {
            asked: d.accuracy,
            estimate: times.max(rates).max(latch_moments),
            times,
            rates,
            latch_moments,
            root_loads,
            runs: k + 1,
            evaluations,
            cutoff,
            schedule,
            first_impact_only: !matches!(d.latch, LatchModel::Compliant { .. }),
            events_differ,
        };
        (c, r) = (c1, r1);
        k += 1;
        if a.reached() || r.diverged() || r.step_limit_reached() || k >= LEVELS {
            r.evaluations = evaluations;
            return Ok((c, r, a));
        }
    }
}
