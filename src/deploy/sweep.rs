//! Modes along the deployment: the natural frequencies of the partially deployed spacecraft —
//! the base's Ritz model (its kept hub-fixed modes, the hub free or held) with the panels as
//! rigid bodies at their current angles, unlatched hinges as their torsional springs (and a
//! captured compliant latch as its spring), latched hinges rigid, an ideal cable as its
//! constraint — at states along a simulated deployment. What an operator needs to tell from a
//! measured frequency how far an array has deployed.
//!
//! The configuration is frozen (small oscillations about the state's angles, the springs'
//! preload not linearised: no geometric stiffness) and the motion is undamped:
//!   Zᵀ M(q) Z ü = −Zᵀ K Z u,   K = diag(0 (hub), ω_j² (base modes), k_i (free hinges)),
//! with M the coupled model's mass matrix over its speeds ([`Coupled::evaluate`]) and Z the
//! admissible speeds of the state ([`Coupled::admissible`]): the same system the deployment
//! integrates, linearised.

use super::coupled::{Coupled, Synchronisation};
use super::DeploymentResult;
use crate::ritz::eigen::generalized_symmetric;
use crate::ritz::RitzError;
use faer::Mat;

/// The frequencies of one state.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepState {
    /// Time from release, s.
    pub time: f64,
    /// Opening angles, rad.
    pub alpha: Vec<f64>,
    /// Latched (locked or captured) hinges.
    pub latched: Vec<bool>,
    /// Deployment progress: the root hinge's opening as a fraction of its travel, in [0, 1].
    pub progress: f64,
    /// The lowest elastic frequencies, Hz (the free hub's six rigid modes left out).
    pub frequencies_hz: Vec<f64>,
}

/// The elastic circular frequencies [rad/s], ascending, of the coupled model frozen at
/// positions `y` (the first [`Coupled::positions`] entries; any speeds after them are ignored), with the hinges flagged `free` acting as
/// springs and the others rigid, and `captured` hinges held by their compliant latch spring.
pub fn linear_frequencies(
    c: &Coupled,
    y: &[f64],
    free: &[bool],
    captured: &[bool],
) -> Result<Vec<f64>, RitzError> {
    let ns = c.speeds();
    let np = c.positions();
    // At rest: the positions of y, zero speeds (M does not depend on them).
    let mut at_rest = y[..np].to_vec();
    at_rest.resize(np + ns, 0.0);
    let ev = c.evaluate(&at_rest);
    let (h, m, n) = (c.hub_dof(), c.modes(), c.panels());
    let nb = h + m;
    let mut k = Mat::<f64>::zeros(ns, ns);
    for j in 0..m {
        k[(h + j, h + j)] = c.base.omega[j].powi(2);
    }
    for (i, hg) in c.chain.hinges.iter().enumerate() {
        let mut ki = -hg.moment_slopes(0.0).0;
        if let Some(l) = &c.latch {
            if captured.get(i).copied().unwrap_or(false) {
                ki += l.stiffness[i];
            }
        }
        k[(nb + i, nb + i)] += ki;
    }
    if let Synchronisation::ElasticCable(kc) = c.sync {
        // Loop k ties hinges k and k+1: mismatch a·α_k − α_{k+1} (a = 2 for the root loop).
        for l in 0..n.saturating_sub(1) {
            let a = if l == 0 { 2.0 } else { 1.0 };
            let (p, q) = (nb + l, nb + l + 1);
            k[(p, p)] += kc * a * a;
            k[(q, q)] += kc;
            k[(p, q)] -= kc * a;
            k[(q, p)] -= kc * a;
        }
    }
    let z = c.admissible(free);
    let mr = z.transpose() * &ev.mass * &z;
    let kr = z.transpose() * &k * &z;
    let sym =
        |a: &Mat<f64>| Mat::from_fn(a.nrows(), a.ncols(), |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let (lambda, _) = generalized_symmetric(&sym(&kr), &sym(&mr))?;
    Ok(lambda.iter().skip(h).map(|l| l.max(0.0).sqrt()).collect())
}

/// The frequencies (at most `count` per state) at `k` states evenly spaced in time from
/// release to the end of the deployment (the last latch or capture, or the run's end), plus
/// the stowed state at release and the final state — K + 2 states in time order. `y0` is the
/// initial state of the run ([`Coupled::initial_state`]).
pub fn deployment_sweep(
    c: &Coupled,
    run: &DeploymentResult,
    y0: &[f64],
    k: usize,
    count: usize,
) -> Result<Vec<SweepState>, RitzError> {
    let n = c.panels();
    let np = c.positions();
    let off = c.alpha_offset();
    let hinge = |i: usize| &c.chain.hinges[i];
    let end = run
        .latches
        .iter()
        .map(|l| l.time)
        .chain(run.captures.iter().map(|l| l.time))
        .fold(0.0, f64::max)
        .max(if run.latches.is_empty() && run.captures.is_empty() {
            run.final_time
        } else {
            0.0
        });
    // Which hinges are latched (rigid) and captured (compliant) at time t.
    let latched_at = |t: f64| -> (Vec<bool>, Vec<bool>) {
        let mut locked = vec![false; n];
        for e in run.latches.iter().filter(|e| e.time <= t) {
            for &j in &e.locked {
                locked[j - 1] = true;
            }
        }
        let mut captured = vec![false; n];
        for e in run.captures.iter().filter(|e| e.time <= t) {
            captured[e.hinge - 1] = true;
        }
        (locked, captured)
    };
    let progress = |alpha: &[f64]| {
        let h = hinge(0);
        let travel = h.latch_angle - alpha_initial(y0, off);
        if travel.abs() > 0.0 {
            ((alpha[0] - alpha_initial(y0, off)) / travel).clamp(0.0, 1.0)
        } else {
            1.0
        }
    };
    let mut states = Vec::with_capacity(k + 2);
    let mut push = |t: f64, y: &[f64], locked: Vec<bool>, captured: Vec<bool>| {
        let free: Vec<bool> = locked.iter().map(|l| !l).collect();
        let w = linear_frequencies(c, y, &free, &captured)?;
        let alpha = y[off..off + n].to_vec();
        states.push(SweepState {
            time: t,
            progress: progress(&alpha),
            latched: locked
                .iter()
                .zip(&captured)
                .map(|(a, b)| *a || *b)
                .collect(),
            alpha,
            frequencies_hz: w
                .iter()
                .take(count)
                .map(|w| w / (2.0 * std::f64::consts::PI))
                .collect(),
        });
        Ok::<(), RitzError>(())
    };
    push(0.0, y0, vec![false; n], vec![false; n])?;
    // Interior states from the samples (positions rebuilt: the hub's pose does not enter M in
    // hub components, so the identity attitude and the samples' η and α define the state).
    for s in 1..=k {
        let t = end * s as f64 / (k + 1) as f64;
        let Some(sample) = run.samples.iter().take_while(|p| p.t <= t).last() else {
            continue;
        };
        let mut y = y0[..np].to_vec();
        if let Some(b) = &sample.body {
            let e0 = off - c.modes();
            y[e0..off].copy_from_slice(&b.eta);
        }
        y[off..off + n].copy_from_slice(&sample.alpha);
        let (locked, captured) = latched_at(sample.t);
        push(sample.t, &y, locked, captured)?;
    }
    let (locked, captured) = latched_at(f64::INFINITY);
    let mut y = run.final_q.clone();
    y.truncate(np);
    push(run.final_time, &y, locked, captured)?;
    Ok(states)
}

fn alpha_initial(y0: &[f64], off: usize) -> f64 {
    y0[off]
}
