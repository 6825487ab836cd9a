//! Deployment of an accordion-folded N-panel array (docs/theory.md §2): the chain's dynamics
//! ([`chain`]), an adaptive integrator with dense output (`integrator`), the latch-event
//! finder (`events`), the swing-back tracker ([`swing`]), the chain of a plate of the 3-D
//! structure ([`planar`]), and the run with latch events,
//! samples, its status and warnings ([`simulate`]).

pub(crate) mod articulated;
pub mod attitude;
pub mod auto;
pub mod base;
pub mod chain;
pub mod coupled;
pub mod envelope;
pub(crate) mod events;
pub mod inertia;
pub mod loads;
pub mod peaks;
pub mod planar;
pub(crate) mod run;
pub mod static_correction;
pub mod sweep;
pub mod swing;
pub mod timescales;

pub use crate::ode::{Change, DenseStep, OdeSystem, Rodas5P, Tie};
use crate::ritz::RitzError;
use crate::structure::Structure;
use crate::warning::Warning;
use base::{BaseKind, BaseModel};
use chain::{Chain, PlanarHub, P2};
use coupled::{Coupled, Synchronisation};
pub use run::Schedule;
pub use swing::SwingBack;

/// Why a coupled deployment could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DeployError {
    /// The deploying plate is not in the structure.
    #[error("the structure has no plate named \"{0}\"")]
    UnknownPlate(String),
    /// The base's modal analysis failed.
    #[error(transparent)]
    Ritz(#[from] RitzError),
}

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
    /// Relative integration tolerance (the named integrators').
    pub tolerance: f64,
    /// The results' accuracy asked of the automatic integrator (relative; [`auto`]).
    pub accuracy: f64,
    /// The base during deployment: flexible (its hub-fixed modes) or frozen rigid.
    pub base: BaseKind,
    /// How the hinges are tied.
    pub synchronisation: Synchronisation,
    /// The time integrator.
    pub integrator: Integrator,
    /// How hinges latch.
    pub latch: LatchModel,
    /// ζ of a modal damping of the flexible base's kept modes during deployment
    /// (`[deployment] base_damping_ratio`; 0, undamped, by default). A physical option, not
    /// a numerical one: it changes the results.
    pub base_damping_ratio: f64,
    /// With compliant latches, how the run goes on after the last capture, overriding the
    /// latch model's (`settle_time`, else one latch period and the hand-over): e.g.
    /// [`Settle::decayed`], to run until the latches' motion has decayed. `None` from a
    /// scenario file.
    pub settling: Option<Settle>,
}

/// The time integrator of a deployment run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// The default: the method chosen for the spacecraft (docs/theory.md §2.9) — Rodas5P at
    /// steps set by what each phase of the deployment must resolve, the base's modes above
    /// that followed quasi-statically.
    #[default]
    Auto,
    /// DOPRI5, explicit Runge–Kutta 5(4): cheap steps that conserve energy to the tolerance,
    /// bound by the highest kept base mode (h < 3.3/ω_max) when that mode is stiff.
    Explicit,
    /// Rodas5P, L-stable Rosenbrock of order 5: steps set by the resolved motion whatever the
    /// highest mode (unresolved modes are damped numerically); a Jacobian per step.
    Implicit,
    /// The slow motion by Rodas5P on its slow manifold, the base's ringing carried along it
    /// mode by mode ([`crate::ode::adiabatic`]): steps set by the deployment, not by the base modes,
    /// which are kept (not damped).
    Adiabatic,
}

/// How a hinge latches.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum LatchModel {
    /// A perfectly plastic impact of the whole system (the paper's; default).
    #[default]
    Rigid,
    /// A spring–damper that captures the hinge at its latch angle for good.
    Compliant {
        /// Per hinge, N·m/rad.
        stiffness: Vec<f64>,
        /// Per hinge, N·m·s/rad.
        damping: Vec<f64>,
        /// How long the run continues after the last capture, s (`None`: one latch period,
        /// then the hand-over to the deployed model, which carries the latch springs,
        /// [`Settle::hand_over`]).
        settle_time: Option<f64>,
    },
}

/// The settling criterion's tolerance: a latch has settled once its hinge rate has stayed
/// below this fraction of the largest hinge rate at a capture for one [`latch_period`]
/// (its energy then below about 1e-4 of the capture's).
pub const SETTLE_TOLERANCE: f64 = 1e-2;

/// The settling's cap, in [`latch_period`]s after the last capture.
pub const SETTLE_PERIODS: f64 = 100.0;

pub use timescales::latch_period;

/// How long a deployment with compliant latches goes on after the last capture, before the
/// hand-over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Settle {
    /// For this long, s (`[deployment.latch] settle_time`).
    For(f64),
    /// The default: for `window` s (one [`latch_period`]) after the last capture, which holds
    /// the last-captured hinge's first latch-moment peak, then the hand-over: the deployed
    /// model carries the latch springs (docs/theory.md §1.6), so the latched array's ringing
    /// goes on there, exactly, in the response.
    HandOver {
        /// The time after the last capture, s.
        window: f64,
    },
    /// Until the latches' motion has decayed (the default): the run ends once no captured
    /// hinge's rate has exceeded [`SETTLE_TOLERANCE`] times the largest hinge rate at a
    /// capture for one `window` (s), and at the latest `cap` s after the last capture (a
    /// [`Warning::NotSettled`] then).
    Decayed {
        /// The quiet time asked for, s.
        window: f64,
        /// The longest settling, s.
        cap: f64,
    },
}

impl Settle {
    /// The default for latches of stiffness `stiffness` on `chain` tied by `sync`: decayed
    /// over one [`latch_period`], capped at [`SETTLE_PERIODS`] of them.
    pub fn decayed(chain: &Chain, stiffness: &[f64], sync: Synchronisation) -> Self {
        let window = latch_period(chain, stiffness, sync);
        Self::Decayed {
            window,
            cap: SETTLE_PERIODS * window,
        }
    }

    /// The default: [`Settle::HandOver`] after one [`latch_period`] of the captured array.
    pub fn hand_over(chain: &Chain, stiffness: &[f64], sync: Synchronisation) -> Self {
        Self::HandOver {
            window: latch_period(chain, stiffness, sync),
        }
    }

    /// The longest the run goes on after the last capture, s.
    pub fn limit(&self) -> f64 {
        match *self {
            Self::For(d) => d,
            Self::Decayed { cap, .. } => cap,
            Self::HandOver { window } => window,
        }
    }
}

/// How the settling after the last capture ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Settled {
    /// After the `settle_time` asked for.
    AfterTime,
    /// One latch period after the last capture, handed over to the deployed model with its
    /// latch springs ([`Settle::HandOver`], the default).
    HandedOver,
    /// The latches' motion decayed below [`SETTLE_TOLERANCE`] (for one window).
    Decayed,
    /// At the cap, with the motion not decayed: the largest captured-hinge rate in the last
    /// window, as a fraction of the largest rate at a capture.
    Capped {
        /// That fraction.
        ratio: f64,
    },
    /// At the deployment's `end_time`, before the settling's end.
    EndTime {
        /// With the default settling, the fraction as in [`Settled::Capped`].
        ratio: Option<f64>,
    },
}

/// What a run needs besides the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSettings {
    /// Latching mode.
    pub latching: Latching,
    /// Stop time, s.
    pub end_time: f64,
    /// Sample rate, Hz: samples at t = k / output_rate.
    pub output_rate: f64,
    /// Relative integration tolerance.
    pub tolerance: f64,
    /// The time integrator.
    pub integrator: Integrator,
    /// With compliant latches: how long the run continues after the last capture.
    pub settle: Option<Settle>,
    /// The automatic integrator's step rule.
    pub schedule: run::Schedule,
    /// Record the samples at k / output_rate (false: only the first, those at the latch
    /// events and the load peaks tracked at every step — what a Monte Carlo run reads;
    /// building a sample evaluates the whole model and was 58 % of such a run).
    pub record_samples: bool,
}

/// The three-dimensional state of the coupled model at a sample (hub and base quantities;
/// inertial components unless stated).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BodySample {
    /// Hub centre of mass position, m.
    pub hub_position: [f64; 3],
    /// Hub attitude as a rotation vector, rad.
    pub hub_rotation: [f64; 3],
    /// Hub centre of mass velocity, m/s.
    pub hub_velocity: [f64; 3],
    /// Hub angular velocity, rad/s.
    pub hub_rate: [f64; 3],
    /// Base modal coordinates (hub-fixed modes, mass-normalised), √kg·m.
    pub eta: Vec<f64>,
    /// Per base beam: elastic tip deflection along the beam's axes (u axial, v, w) in m and
    /// twist in rad, relative to the hub.
    pub beam_tips: Vec<[f64; 4]>,
    /// Per base beam: the force (N) and moment about the root point (N·m) that the parent
    /// exerts on the beam, hub components.
    pub root_loads: Vec<[f64; 6]>,
    /// Cable torque per loop (ideal cable: the constraint's multiplier), N·m.
    pub cable_torque: Vec<f64>,
    /// Elastic energy of the base, J.
    pub elastic: f64,
    /// Total linear momentum, N·s.
    pub momentum: [f64; 3],
    /// Total angular momentum about the system's centre of mass, N·m·s.
    pub angular_momentum: [f64; 3],
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
    /// The coupled model's 3-D state (`None` for the planar chain).
    pub body: Option<Box<BodySample>>,
    /// Compliant latches: the latch moment on each hinge, N·m (zero before capture).
    pub latch_moment: Vec<f64>,
    /// Compliant latches: the latch springs' energy, J.
    pub latch_energy: f64,
}

/// A compliant latch capturing its hinge.
#[derive(Debug, Clone, PartialEq)]
pub struct Capture {
    /// Time, s.
    pub time: f64,
    /// The hinge (1-based).
    pub hinge: usize,
    /// Every hinge's opening rate at the capture, rad/s.
    pub rates: Vec<f64>,
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
    /// Per hinge: linear impulse from the inboard body on panel i (N·s, deployment-plane
    /// axes) and angular impulse carried by the hinge (N·m·s).
    pub impulses: Vec<(P2, f64)>,
    /// Hub velocity after (u̇, v̇, θ̇) for a free hub.
    pub hub_rate_after: [f64; 3],
    /// Every coordinate at the event (the chain's q: hub's u, v, θ when free, then α; the
    /// coupled model's positions).
    pub q: Vec<f64>,
    /// Every rate just before the impact.
    pub qd_before: Vec<f64>,
    /// Every rate just after the impact.
    pub qd_after: Vec<f64>,
    /// The coupled model: the impulse the base receives at the root hinge, hub components:
    /// force (N·s) and moment about the hinge point (N·m·s).
    pub base_impulse: Option<([f64; 3], [f64; 3])>,
    /// A rigid latch on an elastic base: the same impact computed with half of the kept base
    /// modes, and how much its outcome changes.
    pub half_modes: Option<HalfModes>,
}

/// A rigid latch's sensitivity to the base's truncation (docs/theory.md §2: a rigid latch on an
/// elastic base has no continuum limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfModes {
    /// Base modes of the comparison (half of those kept).
    pub modes: usize,
    /// Base modes kept in the run.
    pub kept: usize,
    /// |ΔF| / |F| of the base impulse's force between the two.
    pub force_change: f64,
    /// |ΔM| / |M| of the base impulse's moment.
    pub moment_change: f64,
    /// |Δα̇⁺| / |α̇⁺| of the hinge rates after the impact (|Δα̇⁺| when α̇⁺ = 0).
    pub rates_change: f64,
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
    /// Latch events in time order (rigid latches).
    pub latches: Vec<LatchEvent>,
    /// Captures in time order (compliant latches).
    pub captures: Vec<Capture>,
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
    /// With compliant latches all captured: how the settling ended.
    pub settled: Option<Settled>,
    /// With the automatic integrator: its model and its accuracy estimate.
    pub accuracy: Option<auto::Accuracy>,
    /// The same peaks from the first impact or capture on: the latch-ups' loads, apart from
    /// the release's transient.
    pub latch_up_peaks: Vec<peaks::Peak>,
    /// Where the output rate aliases the ringing the run resolves: the plotted quantities'
    /// min/max per plot column over every state the run computed ([`envelope`]).
    pub envelope: Option<envelope::Envelope>,
    /// Peaks of the engine's tracked load magnitudes ([`peaks`]), observed at every step
    /// (coupled model: every hinge's latch moment, then every base beam's root force and
    /// root moment, then every hinge's reaction force, every hinge's transmitted moment, and
    /// the hub's |rotation vector| and |position|).
    pub load_peaks: Vec<peaks::Peak>,
}

impl DeploymentResult {
    /// The whole state at `final_time`, y = [q, q̇].
    pub fn final_state(&self) -> Vec<f64> {
        self.final_q.iter().chain(&self.final_qd).copied().collect()
    }

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

/// Runs the planar chain of `d` (hub held, or free with the hub body alone; the rigid
/// reference of the coupled model) until every hinge has latched or `end_time` (at most
/// [`MAX_STEPS`] steps).
pub fn simulate(d: &Deployment) -> DeploymentResult {
    simulate_limited(d, MAX_STEPS)
}

/// [`simulate`] with a step limit of the caller's choosing: the run stops after `max_steps`
/// steps with [`RunStatus::StepLimit`] (and its warning).
pub fn simulate_limited(d: &Deployment, max_steps: usize) -> DeploymentResult {
    // The rigid reference is integrated explicitly at the deployment's tolerance whatever the
    // integrator asked for the coupled run (the automatic one chooses for an elastic base).
    let mut s = d.settings();
    if s.integrator == Integrator::Auto {
        s.integrator = Integrator::Explicit;
    }
    run::run(&run::PlanarEngine(&d.chain), &s, max_steps)
}

/// The deployment of `d` on the structure `st` as one system ([`coupled`]): the array on the
/// flexible (or frozen rigid, per `d.base`), free or held base. Returns the coupled model
/// (for the hand-over) and the run.
pub fn simulate_coupled(
    st: &Structure,
    d: &Deployment,
) -> Result<(Coupled, DeploymentResult), DeployError> {
    simulate_coupled_with(st, d, true)
}

/// [`simulate_coupled`] without the periodic samples when `record_samples` is false: the
/// latch events, the first sample and the load peaks ([`DeploymentResult::load_peaks`],
/// tracked at every step) are the same, the run costs less than half (a Monte Carlo run).
pub fn simulate_coupled_with(
    st: &Structure,
    d: &Deployment,
    record_samples: bool,
) -> Result<(Coupled, DeploymentResult), DeployError> {
    simulate_coupled_observed(st, d, record_samples, &mut |_| {})
}

/// [`simulate_coupled_with`], telling `observe` how the automatic integrator's runs progress
/// ([`auto::Progress`]; a named integrator reports nothing).
pub fn simulate_coupled_observed(
    st: &Structure,
    d: &Deployment,
    record_samples: bool,
    observe: &mut dyn FnMut(auto::Progress),
) -> Result<(Coupled, DeploymentResult), DeployError> {
    let (c, mut r) = if d.integrator == Integrator::Auto {
        let (c, mut r, acc) = auto::simulate_observed(st, d, record_samples, observe)?;
        if !acc.reached() {
            r.warnings.push(Warning::AccuracyNotReached(acc.clone()));
        }
        r.accuracy = Some(acc);
        (c, r)
    } else {
        let c = d.coupled(st)?;
        let settings = RunSettings {
            record_samples,
            ..d.settings()
        };
        let mut r = run::run(&c, &settings, MAX_STEPS);
        truncation_check(st, d, &c, &mut r)?;
        (c, r)
    };
    large_base_deflections(st, &c, &mut r);
    if let BaseKind::Flexible {
        modes: Some(requested),
    } = d.base
    {
        let available = c.base.ritz.dof().saturating_sub(6);
        if requested == 0 || requested > available {
            r.warnings.insert(
                0,
                Warning::BaseModesClamped {
                    requested,
                    kept: c.modes() - c.base.correction,
                    available,
                },
            );
        }
    }
    Ok((c, r))
}

/// [`Warning::LargeDeflection`] for every base beam whose tip deflects (in the samples) by
/// more than [`crate::limits::SMALL_DEFLECTION_FRACTION`] of its length: the base's modes
/// and the hand-over's momentum in the undeformed geometry assume small deflections.
fn large_base_deflections(st: &Structure, c: &Coupled, r: &mut DeploymentResult) {
    let fraction = crate::limits::SMALL_DEFLECTION_FRACTION;
    for (i, b) in c.base.beams.iter().enumerate() {
        let Some(length) = st.beams.iter().find(|x| x.name == b.name).map(|x| x.length) else {
            continue;
        };
        let peak = (r.samples.iter())
            .filter_map(|s| s.body.as_ref()?.beam_tips.get(i).copied())
            .map(|t| t[1].hypot(t[2]))
            .fold(0.0_f64, f64::max);
        if peak > fraction * length {
            r.warnings.push(Warning::LargeDeflection {
                label: format!("{} tip during the deployment", b.name),
                peak_m: peak,
                length_m: length,
                fraction,
            });
        }
    }
}

/// Rigid latches on an elastic base: every latch's impact again with half of the kept base
/// modes (the first half of the same modes), its relative change recorded in the event and
/// the largest stated in a warning.
fn truncation_check(
    st: &Structure,
    d: &Deployment,
    c: &Coupled,
    r: &mut DeploymentResult,
) -> Result<(), DeployError> {
    let m = c.modes();
    if d.latch != LatchModel::Rigid || m < 2 || r.latches.is_empty() {
        return Ok(());
    }
    let half = Deployment {
        base: BaseKind::Flexible { modes: Some(m / 2) },
        ..d.clone()
    }
    .coupled(st)?;
    let nh = half.positions();
    let (e0, h0) = (c.alpha_offset() - m, m / 2); // η's start and the half count
    let n = c.panels();
    let mut free = vec![true; n];
    let mut worst: Option<HalfModes> = None;
    for e in &mut r.latches {
        let mut free_after = free.clone();
        for &j in &e.locked {
            free_after[j - 1] = false;
        }
        // The state with the upper half of η and η̇ dropped.
        let mut y = Vec::with_capacity(nh + half.speeds());
        y.extend_from_slice(&e.q[..e0 + h0]);
        y.extend_from_slice(&e.q[e0 + m..]);
        let s0 = c.hub_dof();
        y.extend_from_slice(&e.qd_before[..s0 + h0]);
        y.extend_from_slice(&e.qd_before[s0 + m..]);
        let (u, imp) = run::Engine::impact(&half, &y, &free_after);
        let rel = |a: &[f64], b: &[f64]| {
            let d: f64 = a
                .iter()
                .zip(b)
                .map(|(x, y)| (x - y).powi(2))
                .sum::<f64>()
                .sqrt();
            let s: f64 = b.iter().map(|x| x * x).sum::<f64>().sqrt();
            if s > 0.0 {
                d / s
            } else {
                d
            }
        };
        let ((f, mo), (fh, mh)) = (
            e.base_impulse.unwrap_or_default(),
            imp.base.unwrap_or_default(),
        );
        let ro = half.rate_offset();
        let check = HalfModes {
            modes: m / 2,
            kept: m,
            force_change: rel(&fh, &f),
            moment_change: rel(&mh, &mo),
            rates_change: rel(&u[ro..ro + n], &e.rates_after),
        };
        e.half_modes = Some(check);
        if worst.is_none_or(|w| check.force_change > w.force_change) {
            worst = Some(check);
        }
        free = free_after;
    }
    if let Some(w) = worst {
        r.warnings.push(Warning::RigidLatchTruncation(w));
    }
    Ok(())
}

impl Deployment {
    /// The compliant latches as hinge lines of the deployed wing (docs/theory.md §1.6): hinge
    /// i's line at the sum of the panel lengths inboard of it (hinge 1 at the root edge),
    /// with its latch spring and dashpot in parallel with the hinge's own spring and damper
    /// (which keep acting once latched, as in the run; its friction is left out). Empty
    /// with rigid latches (the latched wing is one plate). The lines' rest rotations are
    /// zero here; [`Deployment::latched_structure`] sets them.
    pub fn latch_lines(&self) -> Vec<crate::structure::LineHinge> {
        let LatchModel::Compliant {
            stiffness, damping, ..
        } = &self.latch
        else {
            return Vec::new();
        };
        let mut at = 0.0;
        self.chain
            .panels
            .iter()
            .zip(&self.chain.hinges)
            .zip(stiffness.iter().zip(damping))
            .map(|((p, h), (&k, &c))| {
                let line = crate::structure::LineHinge {
                    at,
                    stiffness: k + h.stiffness,
                    damping: c + h.damping,
                    rest: 0.0,
                };
                at += p.length;
                line
            })
            .collect()
    }

    /// `st` with the deploying plate cut along [`Deployment::latch_lines`]: the deployed
    /// spacecraft whose wing stands on its compliant latches (`st` unchanged with rigid ones).
    ///
    /// The cable ties the latched hinges as it tied the opening ones, in the lines' rotations
    /// θ_j = d_j δα_j (δα_j = α_j − α_j^L, d_j = ∓1 the sign of α_j in the panel angles): an
    /// ideal cable leaves one motion, δα = r s with r = (1, 2, 2, …) (one kink function
    /// Σ_j d_j r_j K_j); an elastic one adds k_c (C D)ᵀ(C D) between the lines (C the cable
    /// law's rows, D = diag(d_j)). The lines rest where the potential
    /// V = Σ ½ k_j (δα_j − (α_j^ref − α_j^L))² + ½ k_L,j δα_j² + ½ k_c |C (δα + α^L − α(0))|²
    /// is least over the kink functions' motions: (W K Wᵀ) s = W f with
    /// f_j = d_j [k_j (α_j^ref − α_j^L) − k_c (Cᵀ C (α^L − α(0)))_j], rest = Wᵀ s.
    pub fn latched_structure(
        &self,
        st: &Structure,
    ) -> Result<Structure, crate::structure::StructureError> {
        let mut lines = self.latch_lines();
        let mut st = st.clone();
        if lines.is_empty() {
            return Ok(st);
        }
        let n = lines.len();
        let Some(p) = st.plates.iter_mut().find(|p| p.name == self.plate) else {
            return Ok(st);
        };
        let d: Vec<f64> = (0..n).map(Chain::d).collect();
        let identity = |n: usize| -> Vec<Vec<f64>> {
            (0..n)
                .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
                .collect()
        };
        let (functions, coupling, kc) = match self.synchronisation {
            Synchronisation::None => (identity(n), Vec::new(), 0.0),
            Synchronisation::IdealCable => (
                vec![(0..n)
                    .map(|j| d[j] * if j == 0 { 1.0 } else { 2.0 })
                    .collect()],
                Vec::new(),
                0.0,
            ),
            Synchronisation::ElasticCable(kc) => {
                let rows = Coupled::cable_law(n);
                let coupling = (0..n)
                    .map(|j| {
                        (0..n)
                            .map(|l| {
                                let c: f64 = rows.iter().map(|r| r[j] * r[l]).sum();
                                kc * c * d[j] * d[l]
                            })
                            .collect()
                    })
                    .collect();
                (identity(n), coupling, kc)
            }
        };
        // The rest rotations: the least potential over the kink functions' motions.
        let hinges = &self.chain.hinges;
        let mut f: Vec<f64> = (0..n)
            .map(|j| {
                d[j] * hinges[j].stiffness * (hinges[j].reference_angle - hinges[j].latch_angle)
            })
            .collect();
        if kc > 0.0 {
            let rows = Coupled::cable_law(n);
            let offset: Vec<f64> = (0..n)
                .map(|j| hinges[j].latch_angle - hinges[j].initial_angle)
                .collect();
            for r in &rows {
                let m: f64 = r.iter().zip(&offset).map(|(a, b)| a * b).sum();
                for j in 0..n {
                    f[j] -= d[j] * kc * r[j] * m;
                }
            }
        }
        let stiff = |j: usize, l: usize| -> f64 {
            let own = if j == l { lines[j].stiffness } else { 0.0 };
            own + coupling.get(j).map_or(0.0, |r: &Vec<f64>| r[l])
        };
        let nf = functions.len();
        let a = faer::Mat::<f64>::from_fn(nf, nf, |i, k| {
            (0..n)
                .flat_map(|j| (0..n).map(move |l| (j, l)))
                .map(|(j, l)| functions[i][j] * stiff(j, l) * functions[k][l])
                .sum()
        });
        let b =
            faer::Mat::<f64>::from_fn(nf, 1, |i, _| (0..n).map(|j| functions[i][j] * f[j]).sum());
        use faer::linalg::solvers::Solve;
        let s = a.as_ref().partial_piv_lu().solve(&b);
        for (j, line) in lines.iter_mut().enumerate() {
            line.rest = (0..nf).map(|i| functions[i][j] * s[(i, 0)]).sum();
        }
        let hinged = p.clone().with_hinges(lines)?;
        *p = match self.synchronisation {
            Synchronisation::None => hinged,
            _ => hinged.with_tied_hinges(functions, coupling)?,
        };
        Ok(st)
    }

    /// The run settings.
    pub fn settings(&self) -> RunSettings {
        RunSettings {
            latching: self.latching,
            end_time: self.end_time,
            output_rate: self.output_rate,
            tolerance: self.tolerance,
            integrator: self.integrator,
            settle: match &self.latch {
                LatchModel::Rigid => None,
                LatchModel::Compliant {
                    stiffness,
                    settle_time,
                    ..
                } => Some(self.settling.unwrap_or_else(|| {
                    settle_time.map_or_else(
                        || Settle::hand_over(&self.chain, stiffness, self.synchronisation),
                        Settle::For,
                    )
                })),
            },
            record_samples: true,
            schedule: run::Schedule::default(),
        }
    }

    /// The coupled model of this deployment on structure `st` (the structure the scenario
    /// describes, the deploying plate included): the base without the plate, the chain in
    /// the root hinge's frame, the panels' 3-D inertias (thin plates), the synchronisation.
    /// `base_modes = 0` keeps one mode (see [`Warning::BaseModesClamped`]).
    pub fn coupled(&self, st: &Structure) -> Result<Coupled, DeployError> {
        let plate = st
            .plates
            .iter()
            .position(|p| p.name == self.plate)
            .ok_or_else(|| DeployError::UnknownPlate(self.plate.clone()))?;
        let base = match self.base {
            BaseKind::Flexible { modes: Some(0) } => BaseKind::Flexible { modes: Some(1) },
            other => other,
        };
        let width = st.plates[plate].width;
        let chain = Chain {
            hub: PlanarHub::Fixed,
            root: [0.0, 0.0],
            ..self.chain.clone()
        };
        let panel_inertia = chain
            .panels
            .iter()
            .map(|p| base::panel_inertia(p.mass, width, p.inertia))
            .collect();
        Ok(Coupled {
            base: BaseModel::new(st, plate, base)?,
            chain,
            panel_inertia,
            sync: self.synchronisation,
            latch: match &self.latch {
                LatchModel::Rigid => None,
                LatchModel::Compliant {
                    stiffness, damping, ..
                } => Some(coupled::CompliantLatch {
                    stiffness: stiffness.clone(),
                    damping: damping.clone(),
                }),
            },
            base_damping_ratio: self.base_damping_ratio,
        })
    }
}
