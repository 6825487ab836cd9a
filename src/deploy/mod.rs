//! Deployment of an accordion-folded N-panel array (MODEL.md §3.2): the chain's dynamics
//! ([`chain`]), an adaptive integrator with dense output ([`integrator`]), the latch-event
//! finder ([`events`]), the swing-back tracker ([`swing`]), the chain of a plate of the 3-D
//! structure ([`planar`]), and the run with latch events,
//! samples, its status and warnings ([`simulate`]).

pub mod attitude;
pub mod base;
pub mod chain;
pub mod coupled;
pub(crate) mod events;
pub mod inertia;
pub(crate) mod integrator;
pub mod planar;
pub mod swing;

use crate::warning::Warning;
use chain::{Chain, P2};
use events::Crossing;
use integrator::{DenseStep, Dopri5, OdeSystem};
pub use swing::SwingBack;
use swing::SwingTracker;

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

/// How a deployment run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum RunStatus {
    /// Every hinge locked.
    AllLatched,
    /// The run reached its end time with some hinge still free.
    EndTime,
    /// The run took its step limit and was stopped at `t` (s) before its end (a stiff or
    /// badly scaled problem; the result up to there is valid).
    StepLimit {
        /// Time the run stopped, s.
        t: f64,
    },
    /// The integration produced a non-finite state and was stopped at `t` (s), the last
    /// finite state.
    Diverged {
        /// Time of the last finite state, s.
        t: f64,
    },
}

/// The result of a deployment run.
#[derive(Debug, Clone, PartialEq)]
pub struct DeploymentResult {
    /// Samples at k/output_rate and at every event.
    pub samples: Vec<Sample>,
    /// Latch events in time order.
    pub latches: Vec<LatchEvent>,
    /// How the run ended.
    pub status: RunStatus,
    /// Every hinge locked (the same as `status == RunStatus::AllLatched`).
    pub all_latched: bool,
    /// Time the run ended, s.
    pub final_time: f64,
    /// Final coordinates and rates.
    pub final_q: Vec<f64>,
    /// Final rates.
    pub final_qd: Vec<f64>,
    /// Hinges that never latched: (hinge, final angle).
    pub unlatched: Vec<(usize, f64)>,
    /// Swing-backs below the initial angle.
    pub swing_back: Vec<SwingBack>,
    /// The run's warnings: swing-backs, divergence, step limit, unlatched hinges.
    pub warnings: Vec<Warning>,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
}

impl DeploymentResult {
    /// The integration produced a non-finite state and was stopped at `final_time`.
    pub fn diverged(&self) -> bool {
        matches!(self.status, RunStatus::Diverged { .. })
    }

    /// The run took its step limit and was stopped at `final_time` before its end.
    pub fn step_limit_reached(&self) -> bool {
        matches!(self.status, RunStatus::StepLimit { .. })
    }
}

/// Most integration steps one deployment run may take. A deterministic guard (a wall-time
/// limit would make the result depend on the machine): a run of accepted values that would
/// take longer stops with [`RunStatus::StepLimit`] and a warning, never hangs. The seed
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

/// The impact at latch crossing `e`: `y` holds the state at the crossing; the hinges that
/// lock (per `latching`) are fixed in `free`, the rates in `y` replaced by those after the
/// impact. Returns the event.
fn impact(
    chain: &Chain,
    latching: Latching,
    e: Crossing,
    y: &mut [f64],
    free: &mut Vec<bool>,
) -> LatchEvent {
    let n = chain.dof();
    let h = chain.hub_dof();
    let mut free_after = free.clone();
    match latching {
        Latching::Sequential => free_after[h + e.hinge] = false,
        Latching::Simultaneous => free_after[h..].iter_mut().for_each(|f| *f = false),
    }
    let (q, qd) = y.split_at(n);
    let (qd_new, impulses) = chain.impact(q, qd, &free_after);
    let locked = (0..chain.len())
        .filter(|&i| free[h + i] && !free_after[h + i])
        .map(|i| i + 1)
        .collect();
    let event = LatchEvent {
        hinge: e.hinge + 1,
        locked,
        time: e.t,
        angles: q[h..].to_vec(),
        rates_before: qd[h..].to_vec(),
        rates_after: qd_new[h..].to_vec(),
        energy_before: chain.kinetic_energy(q, qd),
        energy_after: chain.kinetic_energy(q, &qd_new),
        impulses,
        hub_rate_after: if h == 3 {
            [qd_new[0], qd_new[1], qd_new[2]]
        } else {
            [0.0; 3]
        },
        q: q.to_vec(),
        qd_before: qd.to_vec(),
    };
    y[n..].copy_from_slice(&qd_new);
    *free = free_after;
    event
}

/// The state of a run between steps.
struct Run<'a> {
    d: &'a Deployment,
    sys: System<'a>,
    latch_angles: Vec<f64>,
    solver: Dopri5,
    t: f64,
    y: Vec<f64>,
    samples: Vec<Sample>,
    next_k: u64,
    latches: Vec<LatchEvent>,
    swing: SwingTracker,
    buf: Vec<f64>,
}

impl<'a> Run<'a> {
    fn new(d: &'a Deployment) -> Self {
        let chain = &d.chain;
        let n = chain.dof();
        let (q0, qd0) = chain.initial_state();
        let y: Vec<f64> = q0.iter().chain(&qd0).copied().collect();
        let sys = System {
            chain,
            free: vec![true; n],
        };
        let samples = vec![sample(chain, 0.0, &y, &sys.free)];
        Self {
            d,
            sys,
            latch_angles: chain.hinges.iter().map(|j| j.latch_angle).collect(),
            solver: Dopri5::new(d.tolerance, d.tolerance * 1e-2, f64::INFINITY),
            t: 0.0,
            y,
            samples,
            next_k: 1,
            latches: Vec::new(),
            swing: SwingTracker::new(chain.hinges.iter().map(|j| j.initial_angle).collect()),
            buf: vec![0.0; 2 * n],
        }
    }

    /// Some hinge is still free.
    fn moving(&self) -> bool {
        self.sys.free[self.sys.chain.hub_dof()..].iter().any(|f| *f)
    }

    /// One accepted step: its samples, the swing-back scan and the earliest latch in it.
    /// False (and the state left at the step's start) when the step's state is not finite.
    fn advance(&mut self) -> bool {
        let h = self.sys.chain.hub_dof();
        let n = self.sys.chain.dof();
        let y_start = self.y.clone();
        let step = self
            .solver
            .step(&self.sys, &mut self.t, &mut self.y, self.d.end_time);
        if !self.y.iter().all(|v| v.is_finite()) {
            self.y.copy_from_slice(&y_start);
            self.t = step.t0;
            return false;
        }
        let event = events::earliest_latch(&step, h, &self.latch_angles, &self.sys.free[h..]);
        let t_limit = event.map_or(self.t, |e| e.t);
        self.sample_until(&step, t_limit);
        self.swing.scan(&step, h, t_limit);
        match event {
            None => self.swing.observe(self.t, &self.y[h..n]),
            Some(e) => self.latch(&step, e),
        }
        true
    }

    /// Samples at k / rate within (step.t0, t_limit].
    fn sample_until(&mut self, step: &DenseStep, t_limit: f64) {
        let chain = self.sys.chain;
        let (h, n) = (chain.hub_dof(), chain.dof());
        loop {
            let tk = self.next_k as f64 / self.d.output_rate;
            if tk > t_limit || tk > self.d.end_time {
                break;
            }
            step.eval(tk, &mut self.buf);
            self.swing.observe(tk, &self.buf[h..n]);
            self.samples
                .push(sample(chain, tk, &self.buf, &self.sys.free));
            self.next_k += 1;
        }
    }

    /// The latch at crossing `e` of `step`: the state moves to the crossing, the impact
    /// applies, and samples just before and after are recorded.
    fn latch(&mut self, step: &DenseStep, e: Crossing) {
        let chain = self.sys.chain;
        let h = chain.hub_dof();
        step.eval(e.t, &mut self.y);
        self.y[h + e.hinge] = self.latch_angles[e.hinge];
        self.t = e.t;
        let before = sample(chain, e.t, &self.y, &self.sys.free);
        let event = impact(chain, self.d.latching, e, &mut self.y, &mut self.sys.free);
        self.latches.push(event);
        if self.samples.last().is_none_or(|s| s.t < e.t) {
            self.samples.push(before);
        }
        self.samples
            .push(sample(chain, e.t, &self.y, &self.sys.free));
        self.solver.restart();
    }

    fn finish(self, out_of_steps: bool, diverged: bool) -> DeploymentResult {
        let chain = self.sys.chain;
        let (h, n) = (chain.hub_dof(), chain.dof());
        let all_latched = !self.moving();
        let t = self.t;
        let status = if diverged {
            RunStatus::Diverged { t }
        } else if all_latched {
            RunStatus::AllLatched
        } else if out_of_steps && t < self.d.end_time {
            RunStatus::StepLimit { t }
        } else {
            RunStatus::EndTime
        };
        let unlatched: Vec<(usize, f64)> = (0..chain.len())
            .filter(|&i| self.sys.free[h + i])
            .map(|i| (i + 1, self.y[h + i]))
            .collect();
        let (swing_back, mut warnings) = self.swing.finish();
        match status {
            RunStatus::Diverged { t } => warnings.push(Warning::Diverged { t }),
            RunStatus::StepLimit { t } => warnings.push(Warning::StepLimit { t }),
            RunStatus::AllLatched | RunStatus::EndTime => {}
        }
        if !all_latched {
            warnings.push(Warning::NotLatched {
                t,
                hinges: unlatched
                    .iter()
                    .map(|&(i, a)| (i, a, self.latch_angles[i - 1]))
                    .collect(),
            });
        }
        DeploymentResult {
            samples: self.samples,
            latches: self.latches,
            status,
            all_latched,
            final_time: t,
            final_q: self.y[..n].to_vec(),
            final_qd: self.y[n..].to_vec(),
            unlatched,
            swing_back,
            warnings,
            evaluations: self.solver.evaluations,
        }
    }
}

/// Runs the deployment until every hinge has latched or `end_time` (at most [`MAX_STEPS`]
/// steps).
pub fn simulate(d: &Deployment) -> DeploymentResult {
    simulate_limited(d, MAX_STEPS)
}

/// [`simulate`] with a step limit of the caller's choosing: the run stops after `max_steps`
/// steps with [`RunStatus::StepLimit`] (and its warning).
pub fn simulate_limited(d: &Deployment, max_steps: usize) -> DeploymentResult {
    let mut run = Run::new(d);
    let mut steps = 0usize;
    let mut diverged = false;
    while run.t < d.end_time && run.moving() && steps < max_steps {
        steps += 1;
        if !run.advance() {
            diverged = true;
            break;
        }
    }
    run.finish(steps >= max_steps, diverged)
}
