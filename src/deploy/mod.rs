//! Deployment of an accordion-folded N-panel array (MODEL.md §3.2): the chain's dynamics
//! ([`chain`]), an adaptive integrator with dense output ([`integrator`]), and the run with
//! latch events, samples and warnings ([`simulate`]).

pub mod chain;
pub mod integrator;
pub mod planar;

use chain::{Chain, P2};
use integrator::{locate, DenseStep, Dopri5, OdeSystem};

/// When hinges lock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Latching {
    /// Each hinge locks when it reaches its latch angle (default).
    Sequential,
    /// Every hinge locks at the first latch (the paper's assumption 1).
    Simultaneous,
}

/// A deployment problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Deployment {
    /// The name of the deploying plate.
    pub plate: String,
    /// The chain.
    pub chain: Chain,
    /// Latching mode.
    pub latching: Latching,
    /// Stop time, s.
    pub end_time: f64,
    /// Sample rate, Hz: samples at t = k / output_rate.
    pub output_rate: f64,
    /// Relative integration tolerance.
    pub tolerance: f64,
}

/// One output sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Opening angles, rad.
    pub alpha: Vec<f64>,
    /// Opening rates, rad/s.
    pub rate: Vec<f64>,
    /// Hub u, v (m) and θ (rad); zero for a fixed hub.
    pub hub: [f64; 3],
    /// Hub u̇, v̇ (m/s), θ̇ (rad/s).
    pub hub_rate: [f64; 3],
    /// Hinge reaction force on panel i from the inboard body, N.
    pub force: Vec<P2>,
    /// Moment transmitted by hinge i, N·m.
    pub moment: Vec<f64>,
    /// Kinetic energy, J.
    pub kinetic: f64,
    /// Spring energy, J.
    pub spring: f64,
    /// Hinge and panel points (for snapshots), m.
    pub hinges: Vec<P2>,
}

/// One latch event.
#[derive(Debug, Clone, PartialEq)]
pub struct LatchEvent {
    /// The hinge that reached its latch angle (1-based).
    pub hinge: usize,
    /// Hinges locked by this event (1-based; several with simultaneous latching).
    pub locked: Vec<usize>,
    /// Time, s.
    pub time: f64,
    /// Opening angles at the event, rad.
    pub angles: Vec<f64>,
    /// Rates before, rad/s.
    pub rates_before: Vec<f64>,
    /// Rates after, rad/s.
    pub rates_after: Vec<f64>,
    /// Kinetic energy before, J.
    pub energy_before: f64,
    /// Kinetic energy after, J.
    pub energy_after: f64,
    /// Per hinge: linear impulse from the inboard body on panel i (N·s) and angular impulse
    /// carried by the hinge (N·m·s).
    pub impulses: Vec<(P2, f64)>,
    /// Hub velocity after (u̇, v̇, θ̇) for a free hub.
    pub hub_rate_after: [f64; 3],
    /// Every coordinate at the event (the chain's q: hub's u, v, θ when free, then α).
    pub q: Vec<f64>,
    /// Every rate just before the impact.
    pub qd_before: Vec<f64>,
}

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

/// The result of a deployment run.
#[derive(Debug, Clone, PartialEq)]
pub struct DeploymentResult {
    /// Samples at k/output_rate and at every event.
    pub samples: Vec<Sample>,
    /// Latch events in time order.
    pub latches: Vec<LatchEvent>,
    /// Every hinge locked.
    pub all_latched: bool,
    /// Time the run ended, s.
    pub final_time: f64,
    /// Final coordinates and rates.
    pub final_q: Vec<f64>,
    /// Final rates.
    pub final_qd: Vec<f64>,
    /// Hinges that never latched: (hinge, final angle).
    pub unlatched: Vec<(usize, f64)>,
    /// Swing-back warnings.
    pub swing_back: Vec<SwingBack>,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
    /// The integration produced a non-finite state and was stopped there.
    pub diverged: bool,
    /// The run took [`MAX_STEPS`] steps and was stopped at `final_time` before its end
    /// (a stiff or badly scaled problem; the result up to there is valid).
    pub step_limit_reached: bool,
}

/// Most integration steps one deployment run may take. A deterministic guard (a wall-time
/// limit would make the result depend on the machine): a run of accepted values that would
/// take longer stops with [`DeploymentResult::step_limit_reached`], never hangs. The seed
/// example takes a few thousand steps.
pub const MAX_STEPS: usize = 1_000_000;

struct System<'a> {
    chain: &'a Chain,
    free: Vec<bool>,
}

impl OdeSystem for System<'_> {
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.chain.dof();
        let d = self
            .chain
            .solve_dynamics(&y[..n], &y[n..], &self.free, false);
        for i in 0..n {
            dy[i] = if self.free[i] { y[n + i] } else { 0.0 };
            dy[n + i] = d.qdd[i];
        }
    }
}

fn sample(chain: &Chain, t: f64, y: &[f64], free: &[bool]) -> Sample {
    let n = chain.dof();
    let h = chain.hub_dof();
    let (q, qd) = (&y[..n], &y[n..]);
    let d = chain.dynamics(q, qd, free);
    let hub = if h == 3 { [q[0], q[1], q[2]] } else { [0.0; 3] };
    let hub_rate = if h == 3 {
        [qd[0], qd[1], qd[2]]
    } else {
        [0.0; 3]
    };
    Sample {
        t,
        alpha: q[h..].to_vec(),
        rate: qd[h..].to_vec(),
        hub,
        hub_rate,
        force: d.force,
        moment: d.moment,
        kinetic: chain.kinetic_energy(q, qd),
        spring: chain.spring_energy(q),
        hinges: chain.configuration(q).hinges,
    }
}

/// Runs the deployment until every hinge has latched or `end_time` (at most [`MAX_STEPS`]
/// steps).
pub fn simulate(d: &Deployment) -> DeploymentResult {
    simulate_limited(d, MAX_STEPS)
}

/// [`simulate`] with a step limit of the caller's choosing: the run stops after `max_steps`
/// steps with [`DeploymentResult::step_limit_reached`] set.
pub fn simulate_limited(d: &Deployment, max_steps: usize) -> DeploymentResult {
    let chain = &d.chain;
    let n = chain.dof();
    let h = chain.hub_dof();
    let nh = chain.len();
    let (q0, qd0) = chain.initial_state();
    let mut y: Vec<f64> = q0.iter().chain(&qd0).copied().collect();
    let mut sys = System {
        chain,
        free: vec![true; n],
    };
    let mut solver = Dopri5::new(d.tolerance, d.tolerance * 1e-2, f64::INFINITY);
    let mut t = 0.0;
    let mut samples = vec![sample(chain, 0.0, &y, &sys.free)];
    let mut next_k: u64 = 1;
    let mut latches = Vec::new();
    let mut swing: Vec<Option<SwingBack>> = vec![None; nh];
    let event_tol = 1e-12;
    let mut buf = vec![0.0; 2 * n];
    let mut steps = 0usize;
    let mut diverged = false;

    let check_swing = |swing: &mut Vec<Option<SwingBack>>, t: f64, alpha: &[f64]| {
        for (i, a) in alpha.iter().enumerate() {
            let a0 = chain.hinges[i].initial_angle;
            if *a < a0 - 1e-12 {
                match &mut swing[i] {
                    Some(s) => s.min_angle = s.min_angle.min(*a),
                    None => {
                        swing[i] = Some(SwingBack {
                            hinge: i + 1,
                            first_time: t,
                            min_angle: *a,
                        })
                    }
                }
            }
        }
    };

    while t < d.end_time && sys.free[h..].iter().any(|f| *f) && steps < max_steps {
        steps += 1;
        let t_start = t;
        let y_start = y.clone();
        let step: DenseStep = solver.step(&sys, &mut t, &mut y, d.end_time);
        if !y.iter().all(|v| v.is_finite()) {
            y.copy_from_slice(&y_start);
            t = t_start;
            diverged = true;
            break;
        }
        // The earliest latch crossing in this step.
        let mut event: Option<(f64, usize)> = None;
        for j in 0..nh {
            if !sys.free[h + j] {
                continue;
            }
            let latch = chain.hinges[j].latch_angle;
            let g = |tt: f64| step.component(h + j, tt) - latch;
            let g0 = y_start[h + j] - latch;
            if g0 >= 0.0 {
                // Already at the latch angle at the step's start (cannot happen for a
                // validated scenario except after rounding): latch now.
                event = Some((t_start, j));
                break;
            }
            // Sample the step's interior so that a crossing and return within one step
            // is not missed.
            let mut a = t_start;
            for s in 1..=8 {
                let b = t_start + step.h * s as f64 / 8.0;
                if g(b) >= 0.0 {
                    let te = locate(g, a, b, event_tol * b.abs().max(1.0));
                    if event.is_none_or(|(t_ev, _)| te < t_ev) {
                        event = Some((te, j));
                    }
                    break;
                }
                a = b;
            }
        }
        let t_limit = event.map_or(t, |e| e.0);
        // Samples at k / rate within (t_start, t_limit].
        loop {
            let tk = next_k as f64 / d.output_rate;
            if tk > t_limit || tk > d.end_time {
                break;
            }
            step.eval(tk, &mut buf);
            check_swing(&mut swing, tk, &buf[h..n]);
            samples.push(sample(chain, tk, &buf, &sys.free));
            next_k += 1;
        }
        // Swing-back below the initial angle: locate its first time on the dense output.
        let t_seen = event.map_or(t, |e| e.0);
        for i in 0..nh {
            let a0 = chain.hinges[i].initial_angle;
            let g = |tt: f64| a0 - 1e-12 - step.component(h + i, tt);
            let mut a = t_start;
            for s in 1..=8 {
                let b = t_start + (t_seen - t_start) * s as f64 / 8.0;
                let gb = g(b);
                if gb > 0.0 {
                    let first = if swing[i].is_none() && g(a) <= 0.0 {
                        locate(g, a, b, event_tol * b.abs().max(1.0))
                    } else {
                        b
                    };
                    let angle = step.component(h + i, b);
                    match &mut swing[i] {
                        Some(sb) => sb.min_angle = sb.min_angle.min(angle),
                        None => {
                            swing[i] = Some(SwingBack {
                                hinge: i + 1,
                                first_time: first,
                                min_angle: angle,
                            })
                        }
                    }
                }
                a = b;
            }
        }
        match event {
            None => check_swing(&mut swing, t, &y[h..n]),
            Some((te, j)) => {
                step.eval(te, &mut y);
                y[h + j] = chain.hinges[j].latch_angle;
                t = te;
                let (q, qd) = y.split_at(n);
                let before = sample(chain, te, &y, &sys.free);
                let mut free_after = sys.free.clone();
                match d.latching {
                    Latching::Sequential => free_after[h + j] = false,
                    Latching::Simultaneous => free_after[h..].iter_mut().for_each(|f| *f = false),
                }
                let (qd_new, impulses) = chain.impact(q, qd, &free_after);
                let locked: Vec<usize> = (0..nh)
                    .filter(|&i| sys.free[h + i] && !free_after[h + i])
                    .map(|i| i + 1)
                    .collect();
                let rates_before = qd[h..].to_vec();
                let qd_before = qd.to_vec();
                let energy_before = chain.kinetic_energy(q, qd);
                let q = q.to_vec();
                y[n..].copy_from_slice(&qd_new);
                sys.free = free_after;
                let energy_after = chain.kinetic_energy(&q, &qd_new);
                latches.push(LatchEvent {
                    hinge: j + 1,
                    locked,
                    time: te,
                    angles: q[h..].to_vec(),
                    rates_before,
                    rates_after: qd_new[h..].to_vec(),
                    energy_before,
                    energy_after,
                    impulses,
                    hub_rate_after: if h == 3 {
                        [qd_new[0], qd_new[1], qd_new[2]]
                    } else {
                        [0.0; 3]
                    },
                    q: q.clone(),
                    qd_before,
                });
                if samples.last().is_none_or(|s| s.t < te) {
                    samples.push(before);
                }
                samples.push(sample(chain, te, &y, &sys.free));
                solver.restart();
            }
        }
    }
    let all_latched = sys.free[h..].iter().all(|f| !f);
    let unlatched = (0..nh)
        .filter(|&i| sys.free[h + i])
        .map(|i| (i + 1, y[h + i]))
        .collect();
    DeploymentResult {
        samples,
        latches,
        all_latched,
        final_time: t,
        final_q: y[..n].to_vec(),
        final_qd: y[n..].to_vec(),
        unlatched,
        swing_back: swing.into_iter().flatten().collect(),
        evaluations: solver.evaluations,
        step_limit_reached: steps >= max_steps && !diverged && t < d.end_time && !all_latched,
        diverged,
    }
}
