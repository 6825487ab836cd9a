//! One deployment run, whatever the model: the adaptive integration with dense output, the
//! samples at k / output_rate, the latch events located on the dense output and applied as
//! impacts, the swing-back scan, and how the run ended. The model is an [`Engine`]: the
//! planar chain ([`PlanarEngine`], the rigid reference) or the coupled model
//! ([`super::coupled::Coupled`]).

use super::chain::{Chain, Hinge, PlanarHub, FRICTION_RATE, P2};
use super::envelope::{Envelope, Trace};
use super::events::{self, Crossing};
use super::peaks::PeakTracker;
use super::swing::SwingTracker;
use super::Integrator;
use super::{Capture, DeploymentResult, LatchEvent, Latching, RunSettings, RunStatus, Sample};
use super::{Settle, Settled, SETTLE_TOLERANCE};
use crate::ode::adiabatic::Adiabatic;
use crate::ode::integrator::{each_change, Change, DenseStep, Dopri5, OdeSystem, Tie};
use crate::ode::restore::Restorer;
use crate::ode::rosenbrock::Rodas5P;
use crate::warning::Warning;

/// The impulses of one impact.
pub(crate) struct Impulses {
    /// Per hinge: linear impulse from the inboard body on panel i (deployment-plane axes) and
    /// the angular impulse the hinge carries.
    pub hinges: Vec<(P2, f64)>,
    /// The impulse the base receives at the root hinge (coupled model).
    pub base: Option<([f64; 3], [f64; 3])>,
    /// The planar free hub's (u̇, v̇, θ̇) after the impact; zero otherwise.
    pub hub_rate: [f64; 3],
}

/// A model a deployment run integrates. The state is y = [positions, speeds]; the opening
/// angles are positions `alpha_offset()..+N`, their rates speeds `rate_offset()..+N`. `free`
/// flags the hinges (one per panel) that still move.
pub(crate) trait Engine {
    /// The hinges, root first.
    fn hinges(&self) -> &[Hinge];
    /// Number of position coordinates.
    fn positions(&self) -> usize;
    /// Index of α_1 among the positions.
    fn alpha_offset(&self) -> usize;
    /// Index of α̇_1 among the speeds.
    fn rate_offset(&self) -> usize;
    /// The state at release.
    fn initial_state(&self) -> Vec<f64>;
    /// An ideal cable ties every hinge: all lock at the first latch, at their latch angles.
    fn ideal_cable(&self) -> bool {
        false
    }
    /// The hinges latch compliantly (captured, no impact).
    fn compliant(&self) -> bool {
        false
    }
    /// With compliant latches, the latch mode's period ([`super::latch_period`]), s; 0
    /// otherwise.
    fn latch_period(&self) -> f64 {
        0.0
    }
    /// The fastest motion of the array the automatic integrator's steps resolve
    /// ([`super::timescales::fastest`]), rad/s: the hinges flagged in `moving` on their
    /// springs, with the latch springs of those flagged in `latched` acting; 0 by default.
    fn array_fastest(&self, _moving: &[bool], _latched: &[bool]) -> f64 {
        0.0
    }
    /// The highest frequency of the base's kept modes (not its static correction), rad/s: the
    /// scheduled steps resolve it, so that the base's vibration below the cutoff is carried,
    /// not damped; 0 by default.
    fn base_resolved(&self) -> f64 {
        0.0
    }
    /// The captured hinges' slowest latch period, s ([`super::timescales::latch_period`] on
    /// the hinges flagged in `captured`, the others locked); 0 without compliant latches.
    fn latch_window(&self, _captured: &[bool]) -> f64 {
        0.0
    }
    /// For the adiabatic integrator: |Im λ| of ∂f/∂y above which an eigenvalue is the
    /// base's vibration, rad/s ([`crate::ode::adiabatic::fast_threshold`]); infinite (no ringing)
    /// by default.
    fn fast_threshold(&self) -> f64 {
        f64::INFINITY
    }
    /// dy/dt; `captured` flags the hinges whose compliant latch acts.
    fn rhs(&self, y: &[f64], free: &[bool], captured: &[bool], dy: &mut [f64]);
    /// The plastic impact onto the speeds `free_after` admits: the speeds after, the impulses.
    fn impact(&self, y: &[f64], free_after: &[bool]) -> (Vec<f64>, Impulses);
    /// Kinetic energy, J.
    fn kinetic_energy(&self, y: &[f64]) -> f64;
    /// The mechanical energy (kinetic, hinge and cable springs, the base's elastic energy and
    /// the captured latches' springs), J: conserved but for dampers, friction and impacts.
    fn energy(&self, y: &[f64], _captured: &[bool]) -> f64 {
        self.kinetic_energy(y)
    }
    /// The sample at time t.
    fn sample(&self, t: f64, y: &[f64], free: &[bool], captured: &[bool]) -> Sample;
    /// ∂(dy/dt)/∂y, or its stiff part, into `jac` (zeroed); false when the model has none
    /// (see [`OdeSystem::jacobian`]).
    fn jacobian(
        &self,
        _y: &[f64],
        _free: &[bool],
        _captured: &[bool],
        _jac: &mut faer::Mat<f64>,
    ) -> bool {
        false
    }
    /// The leading kinematic components of y ([`OdeSystem::kinematic`]); none by default.
    fn kinematic(&self) -> usize {
        0
    }
    /// Their rows of dy/dt.
    fn rhs_kinematic(&self, _y: &[f64], _dy: &mut [f64]) {}
    /// The first speed, when [`Engine::rhs_speeds`] shares the configuration's work
    /// ([`OdeSystem::speed_offset`]); None by default.
    fn speed_offset(&self) -> Option<usize> {
        None
    }
    /// dy/dt at y with one speed changed, per change ([`OdeSystem::rhs_speeds`]); one
    /// [`Engine::rhs`] each by default.
    fn rhs_speeds(
        &self,
        y: &[f64],
        free: &[bool],
        captured: &[bool],
        changes: &[Change],
        out: &mut [Vec<f64>],
    ) {
        each_change(y, changes, out, |yp, dy| self.rhs(yp, free, captured, dy));
    }
    /// The components the motion ties for the hinges flagged free ([`OdeSystem::ties`]);
    /// none by default.
    fn ties(&self, _free: &[bool]) -> Vec<Tie> {
        Vec::new()
    }
    /// Conserved quantities ([`OdeSystem::invariants`]); none by default.
    fn invariants(&self, _y: &[f64]) -> Vec<f64> {
        Vec::new()
    }
    /// The components of y they are restored through.
    fn invariant_coordinates(&self) -> Vec<usize> {
        Vec::new()
    }
    /// The tolerance's factors per component for the slow run
    /// ([`OdeSystem::slow_tolerance_scales`]); none by default.
    fn slow_tolerance_scales(&self) -> Option<Vec<f64>> {
        None
    }
    /// Load magnitudes whose peaks the run tracks at every step ([`super::peaks`]); none by
    /// default.
    fn load_magnitudes(&self, _y: &[f64], _free: &[bool], _captured: &[bool]) -> Vec<f64> {
        Vec::new()
    }
}

/// The planar chain of [`super::chain`] as an engine: y = [q, q̇].
pub(crate) struct PlanarEngine<'a>(pub &'a Chain);

impl PlanarEngine<'_> {
    /// The chain's own free flags: hub coordinates always free.
    fn full_free(&self, free: &[bool]) -> Vec<bool> {
        let mut f = vec![true; self.0.hub_dof()];
        f.extend_from_slice(free);
        f
    }
}

impl Engine for PlanarEngine<'_> {
    fn hinges(&self) -> &[Hinge] {
        &self.0.hinges
    }
    fn positions(&self) -> usize {
        self.0.dof()
    }
    fn alpha_offset(&self) -> usize {
        self.0.hub_dof()
    }
    fn rate_offset(&self) -> usize {
        self.0.hub_dof()
    }
    fn initial_state(&self) -> Vec<f64> {
        let (q0, qd0) = self.0.initial_state();
        q0.iter().chain(&qd0).copied().collect()
    }
    fn array_fastest(&self, moving: &[bool], _latched: &[bool]) -> f64 {
        super::timescales::fastest(self.0, &[], super::coupled::Synchronisation::None, moving)
    }
    fn rhs(&self, y: &[f64], free: &[bool], _captured: &[bool], dy: &mut [f64]) {
        let chain = self.0;
        let (n, h) = (chain.dof(), chain.hub_dof());
        let full = self.full_free(free);
        let d = chain.solve_dynamics(&y[..n], &y[n..], &full, false);
        for i in 0..n {
            dy[i] = if i < h || free[i - h] { y[n + i] } else { 0.0 };
            dy[n + i] = d.qdd[i];
        }
    }
    fn impact(&self, y: &[f64], free_after: &[bool]) -> (Vec<f64>, Impulses) {
        let n = self.0.dof();
        let (qd, hinges) = self.0.impact(&y[..n], &y[n..], &self.full_free(free_after));
        let hub_rate = match self.0.hub {
            PlanarHub::Free { .. } => [qd[0], qd[1], qd[2]],
            PlanarHub::Fixed => [0.0; 3],
        };
        (
            qd,
            Impulses {
                hinges,
                base: None,
                hub_rate,
            },
        )
    }
    fn kinetic_energy(&self, y: &[f64]) -> f64 {
        let n = self.0.dof();
        self.0.kinetic_energy(&y[..n], &y[n..])
    }
    fn energy(&self, y: &[f64], _captured: &[bool]) -> f64 {
        let n = self.0.dof();
        self.0.kinetic_energy(&y[..n], &y[n..]) + self.0.spring_energy(&y[..n])
    }
    fn sample(&self, t: f64, y: &[f64], free: &[bool], _captured: &[bool]) -> Sample {
        let chain = self.0;
        let (n, h) = (chain.dof(), chain.hub_dof());
        let (q, qd) = (&y[..n], &y[n..]);
        let d = chain.dynamics(q, qd, &self.full_free(free));
        let free_hub = matches!(chain.hub, PlanarHub::Free { .. });
        Sample {
            t,
            alpha: q[h..].to_vec(),
            rate: qd[h..].to_vec(),
            hub: if free_hub {
                [q[0], q[1], q[2]]
            } else {
                [0.0; 3]
            },
            hub_rate: if free_hub {
                [qd[0], qd[1], qd[2]]
            } else {
                [0.0; 3]
            },
            force: d.force,
            moment: d.moment,
            kinetic: chain.kinetic_energy(q, qd),
            spring: chain.spring_energy(q),
            hinges: chain.configuration(q).hinges,
            body: None,
            latch_moment: vec![0.0; chain.len()],
            latch_energy: 0.0,
        }
    }
}

/// The automatic integrator's step rule (docs/theory.md §2.9): Rodas5P at steps set by what
/// the deployment's current phase must resolve, h = min(κ / ω, δ / |α̇|, √(2δ / |α̈|)) —
/// ω the array's fastest motion in the phase ([`super::timescales::fastest`]: its hinge springs
/// in the free swing, with the latch springs during a latch-up), α̇ and α̈ the open hinges'
/// rates and accelerations (δ the largest turn of a hinge in one step). The base's modes
/// above 1/h are not resolved: the L-stable steps let them follow their quasi-static
/// solution ([`Rodas5P::step_scheduled`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    /// κ: the step's fraction of 1/ω.
    pub kappa: f64,
    /// δ, rad: the largest turn of a hinge in one step.
    pub delta: f64,
}

impl Default for Schedule {
    fn default() -> Self {
        Self {
            kappa: 1.0,
            delta: 0.02,
        }
    }
}

/// Rodas5P at scheduled steps, the conserved quantities restored after each.
struct Scheduled {
    rodas: Rodas5P,
    restorer: Restorer,
    rule: Schedule,
    /// The phase's ω (rad/s).
    omega: f64,
    /// The longest step at all, s.
    longest: f64,
    /// The hinges with Coulomb friction.
    rubbing: Vec<bool>,
    /// The largest mechanical energy seen at the end of a step that kept it, J (the scale
    /// of [`ENERGY_GROWTH`]).
    energy_scale: f64,
    /// Steps accepted though they gained energy after every halving.
    energy_gained: usize,
}

impl Scheduled {
    fn step(
        &mut self,
        sys: &dyn OdeSystem,
        t: &mut f64,
        y: &mut [f64],
        t_end: f64,
        (open_rates, open): (std::ops::Range<usize>, &[bool]),
        energy: &dyn Fn(&[f64]) -> f64,
    ) -> DenseStep {
        self.restorer.start(sys, y);
        let f = self.rodas.derivative(sys, *t, y);
        let mut h = self.longest;
        if self.omega > 0.0 {
            h = h.min(self.rule.kappa / self.omega);
        }
        for (j, k) in open_rates.enumerate() {
            if open.get(j).copied().unwrap_or(false) {
                h = h
                    .min(self.rule.delta / y[k].abs())
                    .min((2.0 * self.rule.delta / f[k].abs()).sqrt());
                // Coulomb friction is regularised linearly below FRICTION_RATE: a stiff
                // damping there, which a long step linearises across the whole step and
                // holds the hinge back (a panel released from rest latched 0.53 s late). A
                // hinge with friction leaving the band (its rate below 100 FRICTION_RATE and
                // growing) changes its rate by at most half of it per step, or of
                // 10 FRICTION_RATE, so that it is out within a few short steps; one held in
                // the band (sticking, its rate pulled back towards it) sets no bound.
                if self.rubbing.get(j).copied().unwrap_or(false)
                    && y[k].abs() < 100.0 * FRICTION_RATE
                    && y[k] * f[k] >= 0.0
                {
                    let scale = y[k].abs().max(10.0 * FRICTION_RATE);
                    h = h.min(0.5 * scale / f[k].abs());
                }
            }
        }
        let mut dense = self.guarded(sys, t, y, t_end, h, energy);
        if y.iter().all(|v| v.is_finite()) {
            // One Newton iteration with the kept Jacobian: what it leaves goes with the next
            // step's; events and the end are restored to rounding, the samples by one
            // iteration from the step end's Jacobian.
            let correction = self.restorer.restore(sys, y, false);
            if correction.iter().any(|(_, d)| *d != 0.0) {
                for &(k, d) in &correction {
                    dense.add_linear(k, d);
                }
                self.rodas.refresh_derivative(sys, *t, y);
            }
        }
        dense
    }
}

impl Scheduled {
    /// One scheduled step that does not create energy: a step whose mechanical energy grows
    /// by more than [`ENERGY_GROWTH`] of the largest energy seen is taken again with the
    /// Jacobian differenced (Rodas5P keeps its L-stability on the base's stiff modes only with
    /// the exact one; the model's analytic stiff part leaves out the configuration's slopes,
    /// which at steps far beyond a mode's period let it grow: a six-panel wing's hub reached
    /// 1e15 rad/s), then at half the step, down to [`GUARD_HALVINGS`] times. Nothing in the
    /// model supplies energy (a held hub does no work), so growth is the method's.
    fn guarded(
        &mut self,
        sys: &dyn OdeSystem,
        t: &mut f64,
        y: &mut [f64],
        t_end: f64,
        h: f64,
        energy: &dyn Fn(&[f64]) -> f64,
    ) -> DenseStep {
        let (t0, y0) = (*t, y.to_vec());
        let e0 = energy(&y0);
        self.energy_scale = self.energy_scale.max(e0.abs());
        let mut h = h;
        let mut attempt = 0;
        loop {
            let dense = self.rodas.step_scheduled(sys, t, y, t_end, h);
            let e1 = energy(y);
            // A non-finite energy grew too.
            let grew = e1.is_nan() || e1 > e0 + ENERGY_GROWTH * self.energy_scale;
            self.rodas.differenced = false;
            if !grew {
                self.energy_scale = self.energy_scale.max(e1.abs());
                return dense;
            }
            if attempt > GUARD_HALVINGS {
                // Accepted as it is, said in the run's warnings; the scale stays that of the
                // steps that kept the energy.
                self.energy_gained += 1;
                return dense;
            }
            // Back to the step's start, with the exact Jacobian (and, from the second retry
            // on, half the step).
            attempt += 1;
            *t = t0;
            y.copy_from_slice(&y0);
            self.rodas.refresh_derivative(sys, t0, &y0);
            self.rodas.differenced = true;
            if attempt > 1 {
                h *= 0.5;
            }
        }
    }
}

/// The mechanical energy a scheduled step may gain, as a fraction of the largest seen.
const ENERGY_GROWTH: f64 = 1e-4;

/// The halvings of a scheduled step that gains energy with the exact Jacobian.
const GUARD_HALVINGS: usize = 8;

/// The stepper a run uses.
enum Stepper {
    Explicit(Dopri5),
    Implicit(Rodas5P),
    Adiabatic(Box<Adiabatic>),
    Scheduled(Box<Scheduled>),
}

impl Stepper {
    fn new(s: &RunSettings, fast_threshold: f64) -> Self {
        let (rtol, atol) = (s.tolerance, s.tolerance * 1e-2);
        match s.integrator {
            Integrator::Auto => Self::Scheduled(Box::new(Scheduled {
                rodas: Rodas5P::new(rtol, atol, f64::INFINITY),
                restorer: Restorer::default(),
                rule: s.schedule,
                omega: 0.0,
                // The cap is refined with the steps (κ shrinks at each refinement level):
                // a cap fixed across levels would set the quiet phases' steps alike in every
                // run, and the accuracy estimate would not see their error.
                longest: LONGEST_STEP * s.end_time * s.schedule.kappa / Schedule::default().kappa,
                rubbing: Vec::new(),
                energy_scale: 0.0,
                energy_gained: 0,
            })),
            Integrator::Explicit => Self::Explicit(Dopri5::new(rtol, atol, f64::INFINITY)),
            Integrator::Implicit => Self::Implicit(Rodas5P::new(rtol, atol, f64::INFINITY)),
            Integrator::Adiabatic => {
                Self::Adiabatic(Box::new(Adiabatic::new(rtol, atol, fast_threshold)))
            }
        }
    }
    fn step(&mut self, sys: &dyn OdeSystem, t: &mut f64, y: &mut [f64], t_end: f64) -> DenseStep {
        match self {
            Self::Explicit(s) => s.step(sys, t, y, t_end),
            Self::Implicit(s) => s.step(sys, t, y, t_end),
            Self::Adiabatic(s) => s.step(sys, t, y, t_end),
            // The run calls Scheduled::step itself (it needs the open hinges).
            Self::Scheduled(_) => unreachable!("the run steps the scheduled stepper itself"),
        }
    }
    /// A state taken from the dense output (an event's) with its conserved quantities
    /// restored, for the stepper that restores them after every step.
    fn conserve(&mut self, sys: &dyn OdeSystem, y: &mut [f64]) {
        match self {
            Self::Adiabatic(s) => s.conserve(sys, y),
            Self::Scheduled(s) => {
                s.restorer.restore(sys, y, true);
            }
            _ => {}
        }
    }
    fn restart(&mut self) {
        match self {
            Self::Explicit(s) => s.restart(),
            Self::Implicit(s) => s.restart(),
            Self::Adiabatic(s) => s.restart(),
            Self::Scheduled(s) => s.rodas.restart(),
        }
    }
    fn evaluations(&self) -> usize {
        match self {
            Self::Explicit(s) => s.evaluations,
            Self::Implicit(s) => s.evaluations,
            Self::Adiabatic(s) => s.evaluations(),
            Self::Scheduled(s) => s.rodas.evaluations + s.restorer.evaluations,
        }
    }
}

struct System<'a, E: Engine> {
    engine: &'a E,
    free: Vec<bool>,
    captured: Vec<bool>,
}

impl<E: Engine> System<'_, E> {
    /// Hinges that may still reach their latch angle: free and not captured.
    fn open(&self) -> Vec<bool> {
        self.free
            .iter()
            .zip(&self.captured)
            .map(|(f, c)| *f && !*c)
            .collect()
    }
}

impl<E: Engine> OdeSystem for System<'_, E> {
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        self.engine.rhs(y, &self.free, &self.captured, dy);
    }
    fn jacobian(&self, _t: f64, y: &[f64], jac: &mut faer::Mat<f64>) -> bool {
        self.engine.jacobian(y, &self.free, &self.captured, jac)
    }
    fn kinematic(&self) -> usize {
        self.engine.kinematic()
    }
    fn rhs_kinematic(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        self.engine.rhs_kinematic(y, dy);
    }
    fn speed_offset(&self) -> Option<usize> {
        self.engine.speed_offset()
    }
    fn rhs_speeds(&self, _t: f64, y: &[f64], changes: &[Change], out: &mut [Vec<f64>]) {
        self.engine
            .rhs_speeds(y, &self.free, &self.captured, changes, out);
    }
    fn ties(&self) -> Vec<Tie> {
        self.engine.ties(&self.free)
    }
    fn invariants(&self, y: &[f64]) -> Vec<f64> {
        self.engine.invariants(y)
    }
    fn invariant_coordinates(&self) -> Vec<usize> {
        self.engine.invariant_coordinates()
    }
    fn slow_tolerance_scales(&self) -> Option<Vec<f64>> {
        self.engine.slow_tolerance_scales()
    }
}

/// A latch-up under way (the scheduled stepper's): since when (s), its window (s), and the
/// captured hinges' largest |α̇| in the window, decreasing.
type LatchUp = (f64, f64, std::collections::VecDeque<(f64, f64)>);

/// The state of a run between steps.
struct Run<'a, E: Engine> {
    s: &'a RunSettings,
    sys: System<'a, E>,
    latch_angles: Vec<f64>,
    solver: Stepper,
    t: f64,
    y: Vec<f64>,
    samples: Vec<Sample>,
    next_k: u64,
    latches: Vec<LatchEvent>,
    captures: Vec<Capture>,
    swing: SwingTracker,
    peaks: PeakTracker,
    buf: Vec<f64>,
    warnings: Vec<Warning>,
    /// With every hinge captured: the largest captured-hinge rate |α̇| (rad/s) at the points
    /// [`Self::rates_left`] reads in the last settling window, (t, rate), decreasing.
    recent: std::collections::VecDeque<(f64, f64)>,
    /// How the settling ended, once it has.
    settled: Option<Settled>,
    /// The time of the last impact or capture (none yet: −∞), s.
    last_event: f64,
    /// The engine's latch period ([`Engine::latch_period`]: a small eigenproblem, so
    /// computed once), s.
    latch_period: f64,
    /// The load peaks from the first impact or capture on (the latch-ups'), as `peaks`.
    latch_up_peaks: PeakTracker,
    /// With the scheduled stepper, the latch-up under way: since when (s), its window (the
    /// captured hinges' slowest latch period, s), and the captured hinges' largest |α̇| in it,
    /// as [`Self::recent`].
    latch_up: Option<LatchUp>,
    /// The current step's observations resolve the motion, so that the peak tracker may
    /// interpolate between them; false where the adiabatic stepper's ringing turns by more
    /// than [`LOAD_PHASE`] between them (a parabola through such points is no peak).
    resolved: bool,
    /// The latest two steps' dense outputs (the older first), from which the peak trackers'
    /// candidates are evaluated ([`PeakTracker::resolve`]).
    dense: [Option<DenseStep>; 2],
    /// The plotted quantities' envelope, where the output rate aliases the ringing.
    envelope: Option<Envelope>,
}

impl<'a, E: Engine> Run<'a, E> {
    fn new(engine: &'a E, s: &'a RunSettings) -> Self {
        let hinges = engine.hinges();
        let y = engine.initial_state();
        let sys = System {
            engine,
            free: vec![true; hinges.len()],
            captured: vec![false; hinges.len()],
        };
        let samples = vec![engine.sample(0.0, &y, &sys.free, &sys.captured)];
        let envelope = s
            .record_samples
            .then(|| envelope_of(engine, &samples[0], s))
            .flatten();
        let mut peaks = PeakTracker::default();
        peaks.observe(0.0, &engine.load_magnitudes(&y, &sys.free, &sys.captured));
        let len = y.len();
        Self {
            s,
            sys,
            latch_angles: hinges.iter().map(|j| j.latch_angle).collect(),
            solver: Stepper::new(s, engine.fast_threshold()),
            t: 0.0,
            y,
            samples,
            next_k: 1,
            latches: Vec::new(),
            captures: Vec::new(),
            swing: SwingTracker::new(hinges.iter().map(|j| j.initial_angle).collect()),
            peaks,
            buf: vec![0.0; len],
            warnings: Vec::new(),
            recent: std::collections::VecDeque::new(),
            settled: None,
            last_event: f64::NEG_INFINITY,
            latch_period: engine.latch_period(),
            latch_up_peaks: PeakTracker::default(),
            latch_up: None,
            resolved: true,
            dense: [None, None],
            envelope,
        }
        .with_phase()
    }

    /// Hinges that still open (free, not captured).
    fn open_mask(&self) -> Vec<bool> {
        self.sys.open()
    }

    /// The scheduled stepper's ω for the current phase: during a latch-up, the open and the
    /// captured hinges with the captured ones' latch springs; otherwise the open hinges alone
    /// (captured hinges then sit quasi-statically on their latches, locked ones do not move).
    fn with_phase(mut self) -> Self {
        if let Stepper::Scheduled(s) = &mut self.solver {
            s.rubbing = self
                .sys
                .engine
                .hinges()
                .iter()
                .map(|h| h.friction > 0.0)
                .collect();
        }
        self.set_phase();
        self
    }

    fn set_phase(&mut self) {
        let open = self.open_mask();
        let omega = match &self.latch_up {
            Some(_) => {
                let moving: Vec<bool> = open
                    .iter()
                    .zip(&self.sys.captured)
                    .map(|(o, c)| *o || *c)
                    .collect();
                self.sys.engine.array_fastest(&moving, &self.sys.captured)
            }
            None => self.sys.engine.array_fastest(&open, &[]),
        };
        // The base's kept modes are resolved from the first capture on: a latch-up excites
        // them, and in an undamped base their vibration lasts and reaches the later events (a
        // hinge creeping into its latch meets the base still ringing from the earlier
        // latch-ups). Before it only the release has (a step of the hinge springs' moments,
        // small against a latch-up's), and after a rigid impact the base's motion depends on
        // the modes kept anyway (no continuum limit, docs/theory.md §2.3): steps set by the
        // array let that vibration settle quasi-statically.
        let base = if self.captures.is_empty() {
            0.0
        } else {
            self.sys.engine.base_resolved()
        };
        if let Stepper::Scheduled(s) = &mut self.solver {
            s.omega = omega.max(base);
        }
    }

    /// With the scheduled stepper after a capture: the latch-up lasts until the captured
    /// hinges' rates have stayed below [`SETTLE_TOLERANCE`] of the largest rate at a capture
    /// for one window (the captured hinges' slowest latch period, [`Engine::latch_window`]),
    /// and at most [`super::SETTLE_PERIODS`] windows; then the steps no longer resolve the
    /// latches (they hold their hinges quasi-statically).
    fn start_latch_up(&mut self, t: f64) {
        if !matches!(self.solver, Stepper::Scheduled(_)) {
            return;
        }
        let window = self.sys.engine.latch_window(&self.sys.captured);
        self.latch_up = Some((t, window, std::collections::VecDeque::new()));
        self.set_phase();
    }

    /// After a step: whether the latch-up under way has ended.
    fn watch_latch_up(&mut self, step: &DenseStep) {
        let Some((since, window, mut recent)) = self.latch_up.take() else {
            return;
        };
        if window <= 0.0 {
            self.set_phase();
            return;
        }
        let ratio = self.rates_in(step, window, &mut recent);
        let elapsed = self.t - since;
        if (elapsed >= window && ratio <= SETTLE_TOLERANCE)
            || elapsed >= super::SETTLE_PERIODS * window
        {
            self.set_phase();
        } else {
            self.latch_up = Some((since, window, recent));
        }
    }

    fn alpha_range(&self) -> std::ops::Range<usize> {
        let a = self.sys.engine.alpha_offset();
        a..a + self.latch_angles.len()
    }

    /// Some hinge has not latched (or been captured) yet.
    fn moving(&self) -> bool {
        self.sys.open().iter().any(|f| *f)
    }

    /// The run goes on: a hinge has not latched, or the captured latches are settling.
    fn active(&self) -> bool {
        self.moving() || (self.settled.is_none() && self.t < self.settle_end())
    }

    /// With compliant latches, the latest time the run ends after the last capture.
    fn settle_end(&self) -> f64 {
        match (self.s.settle, self.captures.last()) {
            (Some(settle), Some(c)) => (c.time + settle.limit()).min(self.s.end_time),
            _ => f64::NEG_INFINITY,
        }
    }

    /// After a step once every hinge is captured. With [`Settle::Decayed`] the settling ends
    /// once the captured hinges' rates ([`Self::rates_left`]) have stayed below
    /// [`SETTLE_TOLERANCE`] times the largest rate at a capture for one window since the
    /// last capture, or at its cap; with [`Settle::For`] after its time; either way at
    /// `end_time` at the latest.
    fn watch_settling(&mut self, step: &DenseStep) {
        let (Some(settle), Some(last)) = (self.s.settle, self.captures.last()) else {
            return;
        };
        let last_time = last.time;
        let (ratio, decayed) = match settle {
            Settle::For(_) | Settle::HandOver { .. } => (None, false),
            Settle::Decayed { window, .. } => {
                let r = self.rates_left(step, window);
                (
                    Some(r),
                    self.t - last_time >= window && r <= SETTLE_TOLERANCE,
                )
            }
        };
        self.settled = if decayed {
            Some(Settled::Decayed)
        } else if self.t >= last_time + settle.limit() {
            Some(match (settle, ratio) {
                (Settle::HandOver { .. }, _) => Settled::HandedOver,
                (_, Some(ratio)) => Settled::Capped { ratio },
                (_, None) => Settled::AfterTime,
            })
        } else if self.t >= self.s.end_time {
            Some(Settled::EndTime { ratio })
        } else {
            None
        };
    }

    /// The captured hinges' largest |α̇| over the last `window` (s), read at the quarter
    /// points of every step since the last capture (16 per window at least), over the
    /// largest hinge rate at a capture.
    fn rates_left(&mut self, step: &DenseStep, window: f64) -> f64 {
        let mut recent = std::mem::take(&mut self.recent);
        let ratio = self.rates_in(step, window, &mut recent);
        self.recent = recent;
        ratio
    }

    /// [`Self::rates_left`] over the captured hinges, into the deque `recent`.
    fn rates_in(
        &self,
        step: &DenseStep,
        window: f64,
        recent: &mut std::collections::VecDeque<(f64, f64)>,
    ) -> f64 {
        let engine = self.sys.engine;
        let ro = engine.positions() + engine.rate_offset();
        let mut rates = vec![0.0; self.latch_angles.len()];
        // At least the step's quarter points, and 16 points per window: a step of the
        // adiabatic integrator can span many periods of a stiff latch, which it carries as
        // ringing (k_L = 1e7: W = 0.04 s), and a few samples of an oscillating rate would
        // read its envelope anywhere between zero and its top.
        let span = self.t - step.t0;
        let n = ((16.0 * span / window).ceil().clamp(4.0, 1e5)) as usize;
        for k in 1..=n {
            let t = if k == n {
                self.t
            } else {
                step.t0 + span * k as f64 / n as f64
            };
            step.components(ro, t, &mut rates);
            let loudest = rates
                .iter()
                .zip(&self.sys.captured)
                .filter(|(_, c)| **c)
                .fold(0.0, |m: f64, (r, _)| m.max(r.abs()));
            // A decreasing deque: its front is the window's largest.
            while recent.back().is_some_and(|&(_, v)| v <= loudest) {
                recent.pop_back();
            }
            recent.push_back((t, loudest));
        }
        while recent.front().is_some_and(|&(t, _)| t < self.t - window) {
            recent.pop_front();
        }
        let largest = recent.front().map_or(0.0, |r| r.1);
        let scale = self
            .captures
            .iter()
            .map(|c| c.rates[c.hinge - 1].abs())
            .fold(0.0, f64::max);
        if scale > 0.0 {
            largest / scale
        } else if largest > 0.0 {
            f64::INFINITY
        } else {
            0.0
        }
    }

    /// The end of the next step: once every hinge is captured, the settling's end, and with
    /// [`Settle::Decayed`] at most one window ahead, so that the settling ends within a
    /// window of the instant its criterion holds (the adiabatic integrator's steps can span
    /// many periods of a stiff latch it carries as ringing: with k_L = 1e7 one step ran from
    /// 2 s to the cap at 4.1 s after the capture).
    fn t_stop(&self) -> f64 {
        if self.moving() {
            return self.s.end_time;
        }
        match self.s.settle {
            Some(Settle::Decayed { window, .. }) => self.settle_end().min(self.t + window),
            _ => self.settle_end(),
        }
    }

    /// One accepted step: its samples, the swing-back scan and the earliest latch in it.
    /// False (and the state left at the step's start) when the step's state is not finite.
    fn advance(&mut self) -> bool {
        let off = self.sys.engine.alpha_offset();
        let y_start = self.y.clone();
        let t_stop = self.t_stop();
        let step = match &mut self.solver {
            Stepper::Scheduled(s) => {
                let ro = self.sys.engine.positions() + self.sys.engine.rate_offset();
                let open = self.sys.open();
                let (engine, captured) = (self.sys.engine, &self.sys.captured);
                s.step(
                    &self.sys,
                    &mut self.t,
                    &mut self.y,
                    t_stop,
                    (ro..ro + open.len(), &open),
                    &|y| engine.energy(y, captured),
                )
            }
            solver => solver.step(&self.sys, &mut self.t, &mut self.y, t_stop),
        };
        if !self.y.iter().all(|v| v.is_finite()) {
            self.y.copy_from_slice(&y_start);
            self.t = step.t0;
            return false;
        }
        self.dense.swap(0, 1);
        self.dense[1] = Some(step.clone());
        let open = self.sys.open();
        let event = events::earliest_latch(&step, off, &self.latch_angles, &open).map(|e| {
            // An ideal cable brings every hinge to its latch angle at the same instant (up to
            // the event tolerance): the event is the root-most open hinge's, the one the
            // cable drives, whichever crossed first by rounding.
            match open.iter().position(|o| *o) {
                Some(first) if self.sys.engine.ideal_cable() => Crossing { hinge: first, ..e },
                _ => e,
            }
        });
        let t_limit = event.map_or(self.t, |e| e.t);
        self.sample_until(&step, t_limit);
        self.swing.scan(&step, off, t_limit);
        match event {
            None => {
                let r = self.alpha_range();
                self.swing.observe(self.t, &self.y[r]);
                self.observe_loads();
                self.watch_latch_up(&step);
                if !self.moving() {
                    self.watch_settling(&step);
                }
            }
            Some(e) if self.sys.engine.compliant() => self.capture(&step, e),
            Some(e) => self.latch(&step, e),
        }
        true
    }

    /// A compliant latch captures hinge `e.hinge` (every open hinge with an ideal cable) at
    /// the crossing: no velocity jump; the state moves to the crossing and the integration
    /// restarts with the latch's moment acting.
    fn capture(&mut self, step: &DenseStep, e: Crossing) {
        let engine = self.sys.engine;
        let off = engine.alpha_offset();
        let ro = engine.positions() + engine.rate_offset();
        step.eval(e.t, &mut self.y);
        self.t = e.t;
        self.last_event = e.t;
        self.observe_loads();
        self.peaks.break_history();
        self.latch_up_peaks.break_history();
        let open = self.sys.open();
        // A compliant latch captures its hinge when the hinge reaches it; "simultaneous"
        // latching does not apply (it would pull bent hinges onto their latch angles), and
        // an ideal cable brings every hinge to its latch at once.
        let all = engine.ideal_cable();
        for j in 0..self.latch_angles.len() {
            if open[j] && (all || j == e.hinge) {
                self.sys.captured[j] = true;
                self.captures.push(Capture {
                    time: e.t,
                    hinge: j + 1,
                    rates: self.y[ro..ro + self.latch_angles.len()].to_vec(),
                });
            }
        }
        // The hinge sits on its latch angle (to the event tolerance): put it there exactly;
        // with an ideal cable every hinge does.
        for j in 0..self.latch_angles.len() {
            if j == e.hinge || (all && open[j]) {
                self.y[off + j] = self.latch_angles[j];
            }
        }
        self.solver.conserve(&self.sys, &mut self.y);
        self.observe_loads();
        if self.samples.last().is_none_or(|s| s.t < e.t) {
            let sample = engine.sample(e.t, &self.y, &self.sys.free, &self.sys.captured);
            self.record(sample);
        }
        self.solver.restart();
        self.start_latch_up(e.t);
    }

    /// Observes the tracked load magnitudes at the current state (and the plotted
    /// quantities, where they are enveloped).
    fn observe_loads(&mut self) {
        let m = self
            .sys
            .engine
            .load_magnitudes(&self.y, &self.sys.free, &self.sys.captured);
        self.observe(self.t, &m);
        if let Some(env) = &mut self.envelope {
            let e = self.sys.engine;
            env.observe(&e.sample(self.t, &self.y, &self.sys.free, &self.sys.captured));
        }
    }

    /// Keeps an output sample (and takes it into the envelope).
    fn record(&mut self, sample: Sample) {
        if let Some(env) = &mut self.envelope {
            env.observe(&sample);
        }
        self.samples.push(sample);
    }

    /// Observes the load magnitudes `m` at t: with a parabola through the latest three
    /// observations where they resolve the motion, alone otherwise.
    fn observe(&mut self, t: f64, m: &[f64]) {
        if !self.resolved {
            self.peaks.break_history();
            self.latch_up_peaks.break_history();
        }
        self.peaks.observe(t, m);
        if self.last_event.is_finite() {
            self.latch_up_peaks.observe(t, m);
        }
        self.resolve_peaks();
    }

    /// Evaluates the peak trackers' candidates from the latest steps' dense outputs, with
    /// the hinges' current states (the trackers' brackets never span an event).
    fn resolve_peaks(&mut self) {
        if !self.peaks.has_pending() && !self.latch_up_peaks.has_pending() {
            return;
        }
        // The scheduled stepper's interpolant is no peak's value (see `sample_until`): its
        // vertices stand.
        let scheduled = matches!(self.solver, Stepper::Scheduled(_));
        let (steps, sys) = (&self.dense, &self.sys);
        let mut buf = vec![0.0; self.y.len()];
        let mut cache: Vec<(f64, Vec<f64>)> = Vec::new();
        let mut eval = |t: f64| -> Option<Vec<f64>> {
            if scheduled {
                return None;
            }
            if let Some((_, m)) = cache.iter().find(|(s, _)| *s == t) {
                return Some(m.clone());
            }
            let step = steps
                .iter()
                .rev()
                .flatten()
                .find(|d| t >= d.t0 && t <= d.t0 + d.h)?;
            step.eval(t, &mut buf);
            let m = sys.engine.load_magnitudes(&buf, &sys.free, &sys.captured);
            cache.push((t, m.clone()));
            Some(m)
        };
        self.peaks.resolve(&mut eval);
        self.latch_up_peaks.resolve(&mut eval);
    }

    /// How long after an impact or a capture the tracked loads are also observed inside the
    /// steps ([`load_times`]): the latch-up, [`LATCH_UP_PERIODS`] periods of the slowest mode
    /// the step's ringing carries, and at least one latch period. (Not after release: on the
    /// seed with 20 base modes that window cost a third of the run, and the latch-up loads
    /// are the ones sought; the explicit integrator resolves the release's.)
    fn latch_up_window(&self, step: &DenseStep) -> f64 {
        let slowest = step.slowest_ringing();
        let ringing = if slowest > 0.0 {
            LATCH_UP_PERIODS * 2.0 * std::f64::consts::PI / slowest
        } else {
            0.0
        };
        ringing.max(self.latch_period)
    }

    /// Samples at k / rate within (step.t0, t_limit], and the tracked loads observed between
    /// them at [`load_times`] during a latch-up ([`Self::latch_up_window`]).
    fn sample_until(&mut self, step: &DenseStep, t_limit: f64) {
        let r = self.alpha_range();
        let fastest = step.fastest_ringing();
        let mut inner = if fastest > 0.0 && step.t0 < self.last_event + self.latch_up_window(step) {
            load_times(fastest, step.t0, t_limit)
        } else {
            Vec::new()
        };
        let scheduled = matches!(self.solver, Stepper::Scheduled(_));
        if inner.is_empty() && t_limit > step.t0 && !scheduled {
            // The step's midpoint: with its ends, three points of every step, so that a
            // peak inside a step shows as a rise and fall and is resolved there. Not with
            // the scheduled stepper: its steps let the stiff parts (a captured latch's
            // spring, the base's fast modes) follow their quasi-static solution, and its
            // interpolant between the ends, built from their derivatives, overshoots there
            // (a latch moment of 12 kN·m between step ends of 2 kN·m).
            inner.push(0.5 * (step.t0 + t_limit));
        }
        if !self.resolved {
            // No parabola spans the unresolved step before this one.
            self.peaks.break_history();
            self.latch_up_peaks.break_history();
        }
        // Resolved: the observations (inner points and the end) no farther apart than
        // LOAD_PHASE / ω (the spacing's rounding aside).
        let gaps = inner.len() as f64 + 1.0;
        self.resolved = fastest * (t_limit - step.t0) <= LOAD_PHASE * gaps * (1.0 + 1e-9);
        let mut inner = inner.into_iter().peekable();
        loop {
            let tk = self.next_k as f64 / self.s.output_rate;
            let due = tk <= t_limit && tk <= self.s.end_time;
            while let Some(ti) = inner.next_if(|&ti| !due || ti < tk) {
                step.eval(ti, &mut self.buf);
                let m =
                    self.sys
                        .engine
                        .load_magnitudes(&self.buf, &self.sys.free, &self.sys.captured);
                self.observe(ti, &m);
                if let Some(env) = &mut self.envelope {
                    let e = self.sys.engine;
                    env.observe(&e.sample(ti, &self.buf, &self.sys.free, &self.sys.captured));
                }
            }
            if !due {
                break;
            }
            step.eval(tk, &mut self.buf);
            if let Stepper::Scheduled(s) = &self.solver {
                // A sample from the step's cubic interpolant carries its error in the
                // conserved quantities (up to 2e-3 of the panels' momentum across a long
                // step): one Newton iteration with the step end's Jacobian (a copy, so that
                // the steps' own restoration keeps its state) takes it to the Jacobian's
                // change across the step.
                s.restorer.clone().restore(&self.sys, &mut self.buf, false);
            }
            self.swing.observe(tk, &self.buf[r.clone()]);
            // The load peaks are not observed at the samples: they come from the steps
            // (and the points inside them), so that they do not move with the output rate.
            if self.s.record_samples {
                let e = self.sys.engine;
                self.record(e.sample(tk, &self.buf, &self.sys.free, &self.sys.captured));
            }
            self.next_k += 1;
        }
    }

    /// The latch at crossing `e` of `step`: the state moves to the crossing, the impact
    /// applies, and samples just before and after are recorded.
    fn latch(&mut self, step: &DenseStep, e: Crossing) {
        let engine = self.sys.engine;
        let off = engine.alpha_offset();
        let np = engine.positions();
        step.eval(e.t, &mut self.y);
        self.t = e.t;
        self.last_event = e.t;
        let cable = engine.ideal_cable();
        let all = cable || self.s.latching == Latching::Simultaneous;
        let mut free_after = self.sys.free.clone();
        if all {
            free_after.iter_mut().for_each(|f| *f = false);
        } else {
            free_after[e.hinge] = false;
        }
        // The hinge that reached its latch angle sits on it; with an ideal cable every hinge
        // does (the cable law puts them there together, up to the event tolerance).
        for j in 0..self.latch_angles.len() {
            if j == e.hinge || (cable && self.sys.free[j]) {
                self.y[off + j] = self.latch_angles[j];
            }
        }
        self.solver.conserve(&self.sys, &mut self.y);
        if all && !cable {
            self.bent_lock_warning(e);
        }
        self.observe_loads();
        self.peaks.break_history();
        self.latch_up_peaks.break_history();
        let before = engine.sample(e.t, &self.y, &self.sys.free, &self.sys.captured);
        let energy_before = engine.kinetic_energy(&self.y);
        let (u_new, impulses) = engine.impact(&self.y, &free_after);
        let qd_before = self.y[np..].to_vec();
        self.y[np..].copy_from_slice(&u_new);
        let ro = engine.rate_offset();
        let n = self.latch_angles.len();
        let event = LatchEvent {
            hinge: e.hinge + 1,
            locked: (0..n)
                .filter(|&i| self.sys.free[i] && !free_after[i])
                .map(|i| i + 1)
                .collect(),
            time: e.t,
            angles: self.y[off..off + n].to_vec(),
            rates_before: qd_before[ro..ro + n].to_vec(),
            rates_after: u_new[ro..ro + n].to_vec(),
            energy_before,
            energy_after: engine.kinetic_energy(&self.y),
            impulses: impulses.hinges,
            hub_rate_after: impulses.hub_rate,
            q: self.y[..np].to_vec(),
            qd_before,
            qd_after: u_new,
            base_impulse: impulses.base,
            half_modes: None,
        };
        self.latches.push(event);
        self.sys.free = free_after;
        self.observe_loads();
        if self.samples.last().is_none_or(|s| s.t < e.t) {
            self.record(before);
        }
        self.record(engine.sample(e.t, &self.y, &self.sys.free, &self.sys.captured));
        self.solver.restart();
        self.set_phase();
    }

    /// Simultaneous latching without a cable locks the array where it stands: the warning
    /// names the hinge farthest from its latch angle.
    fn bent_lock_warning(&mut self, e: Crossing) {
        let off = self.sys.engine.alpha_offset();
        let worst = (0..self.latch_angles.len())
            .filter(|&j| self.sys.free[j])
            .map(|j| (j, self.latch_angles[j] - self.y[off + j]))
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        if let Some((j, off_by)) = worst {
            if off_by.abs() > 1e-9 {
                self.warnings.push(Warning::LocksBent {
                    t: e.t,
                    hinge: j + 1,
                    rad: off_by,
                });
            }
        }
    }

    fn finish(mut self, out_of_steps: bool, diverged: bool) -> DeploymentResult {
        if !diverged {
            // The end is a state the run reports: its conserved quantities to rounding.
            self.solver.conserve(&self.sys, &mut self.y);
        }
        let engine = self.sys.engine;
        let np = engine.positions();
        let all_latched = !self.moving();
        let t = self.t;
        let status = if diverged {
            RunStatus::Diverged { t }
        } else if all_latched {
            RunStatus::AllLatched
        } else if out_of_steps && t < self.s.end_time {
            RunStatus::StepLimit { t }
        } else {
            RunStatus::EndTime
        };
        let off = engine.alpha_offset();
        let open = self.sys.open();
        let unlatched: Vec<(usize, f64)> = (0..self.latch_angles.len())
            .filter(|&i| open[i])
            .map(|i| (i + 1, self.y[off + i]))
            .collect();
        let (swing_back, swing_warnings) = self.swing.finish();
        let mut warnings = self.warnings;
        if let Stepper::Scheduled(s) = &self.solver {
            if s.energy_gained > 0 {
                warnings.push(Warning::EnergyGained {
                    steps: s.energy_gained,
                });
            }
        }
        warnings.extend(swing_warnings);
        if let Some(e) = &self.envelope {
            warnings.push(Warning::DeploymentAliasing {
                output_rate: e.output_rate,
                fastest_hz: e.fastest_hz,
            });
        }
        match status {
            RunStatus::Diverged { t } => warnings.push(Warning::Diverged { t }),
            RunStatus::StepLimit { t } => warnings.push(Warning::StepLimit { t }),
            RunStatus::AllLatched | RunStatus::EndTime => {}
        }
        // All captured, but no step after the last capture (it fell on end_time).
        let settled = self.settled.or_else(|| {
            (all_latched && self.s.settle.is_some() && status == RunStatus::EndTime)
                .then_some(Settled::EndTime { ratio: None })
        });
        match settled {
            Some(Settled::Capped { ratio }) => warnings.push(Warning::NotSettled {
                t,
                ratio: Some(ratio),
                tolerance: SETTLE_TOLERANCE,
                by_end_time: false,
            }),
            Some(Settled::EndTime { ratio }) => warnings.push(Warning::NotSettled {
                t,
                ratio,
                tolerance: SETTLE_TOLERANCE,
                by_end_time: true,
            }),
            _ => {}
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
            captures: self.captures,
            status,
            all_latched,
            final_time: t,
            final_q: self.y[..np].to_vec(),
            final_qd: self.y[np..].to_vec(),
            unlatched,
            swing_back,
            warnings,
            evaluations: self.solver.evaluations(),
            settled,
            accuracy: None,
            load_peaks: self.peaks.peaks().to_vec(),
            latch_up_peaks: self.latch_up_peaks.peaks().to_vec(),
            envelope: self.envelope,
        }
    }
}

/// The envelope of a run of `engine` whose first sample is `first`: every hinge's rate and
/// reaction (and latch moment, compliant latches), every base beam's root force and moment,
/// the first six base modal coordinates — where the output rate is below
/// [`super::envelope::ALIAS_FACTOR`] times the fastest vibration the run resolves: the
/// base's highest kept mode, or the captured array's fastest mode on its latch springs. Only
/// with the steppers that resolve that vibration at several points a period (the automatic
/// one's scheduled steps, the explicit one's error-controlled steps): the adiabatic stepper
/// carries its ringing inside long steps and the implicit one damps it, so neither has the
/// points an envelope needs.
fn envelope_of<E: Engine>(engine: &E, first: &Sample, s: &RunSettings) -> Option<Envelope> {
    if !matches!(s.integrator, Integrator::Auto | Integrator::Explicit) {
        return None;
    }
    let n = engine.hinges().len();
    let latch_omega = if engine.compliant() {
        engine.array_fastest(&vec![true; n], &vec![true; n])
    } else {
        0.0
    };
    let fastest = engine.base_resolved().max(latch_omega) / (2.0 * std::f64::consts::PI);
    let mut traces: Vec<Trace> = (0..n).map(Trace::Rate).collect();
    traces.extend((0..n).map(Trace::Reaction));
    if engine.compliant() {
        traces.extend((0..n).map(Trace::LatchMoment));
    }
    if let Some(b) = first.body.as_deref() {
        traces.extend((0..b.root_loads.len()).map(Trace::RootForce));
        traces.extend((0..b.root_loads.len()).map(Trace::RootMoment));
        traces.extend((0..b.eta.len().min(6)).map(Trace::Eta));
    }
    let mut env = Envelope::new(traces, s.end_time, s.output_rate, fastest)?;
    env.observe(first);
    Some(env)
}

/// The scheduled stepper's longest step, as a fraction of the end time, at the first
/// refinement level (κ = 1; it shrinks with κ).
const LONGEST_STEP: f64 = 0.01;

/// The most points [`load_times`] gives one step (past it the step is not resolved).
const MAX_LOAD_TIMES: f64 = 1e4;

/// The latch-up's length in periods of the slowest carried ringing mode.
const LATCH_UP_PERIODS: f64 = 4.0;

/// Where the adiabatic stepper's fastest carried ringing mode turns by more than this phase
/// (rad) within a step, the loads are observed inside the step too.
const LOAD_PHASE: f64 = 0.125;

/// The times inside (t0, t_limit) at which the tracked loads are observed besides the step's
/// end, for the adiabatic stepper's ringing, which its steps do not resolve (the explicit
/// and implicit steps do: no ringing, ω = 0, no points): a spacing of [`LOAD_PHASE`] / ω,
/// ω the fastest carried mode's ([`DenseStep::fastest_ringing`]), so that the peak
/// tracker's parabola finds a peak of that mode to ~0.25 (ωδ)³ ≈ 5e-4 relative.
fn load_times(fastest: f64, t0: f64, t_limit: f64) -> Vec<f64> {
    let span = t_limit - t0;
    let turns = fastest * span / LOAD_PHASE;
    if turns.is_nan() || turns <= 1.0 {
        return Vec::new();
    }
    let n = turns.ceil().min(MAX_LOAD_TIMES) as usize;
    (1..n).map(|k| t0 + span * k as f64 / n as f64).collect()
}

/// Runs `engine` from release until every hinge has latched or the end time (at most
/// `max_steps` steps).
pub(crate) fn run<E: Engine>(engine: &E, s: &RunSettings, max_steps: usize) -> DeploymentResult {
    run_observed(engine, s, max_steps, &mut |_| {})
}

/// [`run`], telling `progress` the time reached (s) every [`PROGRESS_STEPS`] steps.
pub(crate) fn run_observed<E: Engine>(
    engine: &E,
    s: &RunSettings,
    max_steps: usize,
    progress: &mut dyn FnMut(f64),
) -> DeploymentResult {
    let mut run = Run::new(engine, s);
    let mut steps = 0usize;
    let mut diverged = false;
    while run.t < s.end_time && run.active() && steps < max_steps {
        steps += 1;
        if !run.advance() {
            diverged = true;
            break;
        }
        if steps % PROGRESS_STEPS == 0 {
            progress(run.t);
        }
    }
    run.finish(steps >= max_steps, diverged)
}

/// Steps between two progress reports ([`run_observed`]).
const PROGRESS_STEPS: usize = 256;
