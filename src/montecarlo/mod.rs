//! Monte Carlo dispersions of a deployment (docs/montecarlo.md): the `[montecarlo]`
//! settings, the draws of run i from a generator seeded by (seed, i) alone, one run's
//! applied scenario and outputs, and the analysis of many runs (statistics, requirement
//! verdicts by order statistics, sensitivity ranking, static torque margins).
//!
//! Reproducible by construction: run i draws from ChaCha20 seeded with `seed` on stream i, so
//! its values, and so its outputs, do not depend on the thread count, the shard split or the
//! order of the runs.

pub mod copula;
pub mod distributions;
pub mod order;
pub mod stats;

use crate::deploy::coupled::Coupled;
use crate::deploy::{simulate_coupled_with, Deployment, DeploymentResult, LatchModel};
use crate::response::channels::standard_channels;
use crate::response::handover::hand_over_coupled;
use crate::response::{Channel, ModalResponse, ResponseError};
use crate::ritz::{ModalAnalysis, RitzError, RitzModel};
use crate::scenario::{DeploymentOverrides, OverrideValue, Scenario};
use crate::structure::Structure;
pub use copula::{Copula, CopulaError, Correlation};
pub use distributions::{Distribution, DistributionError};
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rayon::prelude::*;
pub use stats::Summary;

/// One dispersed value.
#[derive(Debug, Clone, PartialEq)]
pub struct Dispersion {
    /// The dotted path of the scenario key (`deployment.hinges.2.latch_angle`).
    pub path: String,
    /// Its distribution.
    pub distribution: Distribution,
}

/// A requirement on one per-run output: min ≤ output ≤ max with probability ≥ p at
/// confidence c.
#[derive(Debug, Clone, PartialEq)]
pub struct Requirement {
    /// Its name.
    pub name: String,
    /// The output (one of [`output_names`]).
    pub output: String,
    /// Lower bound, if any.
    pub min: Option<f64>,
    /// Upper bound, if any.
    pub max: Option<f64>,
    /// p, in (0, 1).
    pub probability: f64,
    /// c, in (0, 1).
    pub confidence: f64,
    /// A factor of safety (≥ 1) the output is multiplied by before it is compared with
    /// `max` (a load × factor ≤ its allowable); `None`: the output as it is.
    pub factor_of_safety: Option<f64>,
}

impl Requirement {
    /// The value compared with the bounds: the output times the factor of safety.
    pub fn checked(&self, v: f64) -> f64 {
        self.factor_of_safety.map_or(v, |f| v * f)
    }

    /// Whether a run's output meets the bounds once factored (NaN never does).
    pub fn met(&self, v: f64) -> bool {
        let v = self.checked(v);
        !v.is_nan() && self.min.is_none_or(|m| v >= m) && self.max.is_none_or(|m| v <= m)
    }
}

/// The `[montecarlo]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarlo {
    /// Number of runs.
    pub runs: u64,
    /// The seed.
    pub seed: u64,
    /// The dispersed values, drawn in this order (the paths sorted alphabetically).
    pub dispersions: Vec<Dispersion>,
    /// The requirements.
    pub requirements: Vec<Requirement>,
    /// The correlated pairs (`[[montecarlo.correlations]]`), as given.
    pub correlations: Vec<Correlation>,
    /// Their Gaussian copula (`None` without pairs).
    pub copula: Option<Copula>,
    /// Per-run response outputs (`response = true`; the scenario has `[response]`).
    pub response: bool,
}

/// Points of the torque-margin curve over the hinge travel (fractions 0, 1/20, …, 1).
pub const MARGIN_POINTS: usize = 21;

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunStatus {
    /// It ran to its end.
    Ok,
    /// Its applied scenario was refused (a drawn value outside the key's range): no outputs.
    Refused,
    /// The deployment could not be built (e.g. the base's modal solve failed): no outputs.
    Failed,
    /// It ran, but stopped early (divergence or the step limit): outputs up to there.
    Incomplete,
}

impl RunStatus {
    /// The word written in runs.csv.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::Refused => "refused",
            Self::Failed => "failed",
            Self::Incomplete => "incomplete",
        }
    }

    /// The status written as `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::Ok, Self::Refused, Self::Failed, Self::Incomplete]
            .into_iter()
            .find(|s| s.name() == name)
    }
}

/// One run: what was applied and what came out.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Run index, 0-based.
    pub index: u64,
    /// How it ended.
    pub status: RunStatus,
    /// The applied value of every dispersion, in [`MonteCarlo::dispersions`] order.
    pub applied: Vec<f64>,
    /// Every output, in [`output_names`] order (NaN where there is none).
    pub outputs: Vec<f64>,
    /// Per hinge, the static torque margin at the [`MARGIN_POINTS`] fractions of its travel
    /// (empty when the scenario was refused).
    pub margins: Vec<Vec<f64>>,
}

impl MonteCarlo {
    /// The values of run i: ChaCha20 seeded with `seed`, stream i, one draw per dispersion in
    /// order — its value, or for a correlated dispersion a standard normal score, which the
    /// copula then correlates and maps through the dispersion's inverse CDF
    /// ([`copula`]). Without correlations every value is its distribution's own draw.
    pub fn draw(&self, i: u64) -> Vec<f64> {
        let mut rng = ChaCha20Rng::seed_from_u64(self.seed);
        rng.set_stream(i);
        let members = self.copula.as_ref().map_or(&[][..], |c| c.members());
        let mut v: Vec<f64> = (self.dispersions.iter().enumerate())
            .map(|(k, d)| {
                if members.binary_search(&k).is_ok() {
                    rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng)
                } else {
                    d.distribution.sample(&mut rng)
                }
            })
            .collect();
        if let Some(c) = &self.copula {
            let mut z: Vec<f64> = members.iter().map(|&k| v[k]).collect();
            c.correlate(&mut z);
            for (&k, z) in members.iter().zip(z) {
                v[k] = self.dispersions[k].distribution.from_normal_score(z);
            }
        }
        v
    }

    /// The (path, value) overrides of run i.
    pub fn overrides(&self, i: u64) -> Vec<(&str, OverrideValue)> {
        (self.dispersions.iter().zip(self.draw(i)))
            .map(|(d, v)| (d.path.as_str(), OverrideValue::Number(v)))
            .collect()
    }

    /// The full scenario text of run i (the base text with the applied values).
    pub fn run_text(&self, base: &Scenario, i: u64) -> Result<String, (String, String)> {
        crate::scenario::apply_overrides(base.source_text(), &self.overrides(i))
    }

    /// The runs of shard `shard` of `shards` (0-based): i ≡ shard (mod shards).
    pub fn shard_runs(&self, shard: u64, shards: u64) -> Vec<u64> {
        (shard..self.runs).step_by(shards as usize).collect()
    }
}

/// The per-run outputs, in the order of runs.csv's columns (docs/montecarlo.md):
/// `latch_time.H` (s; NaN when hinge H never latched), `all_latched` (1/0),
/// `final_latch_time` (s; +∞ when not all latched), `swing_back` (1/0), `min_swing_angle`
/// (rad; NaN without swing-back), `energy_lost.H` (J, kinetic energy lost at the latch
/// event of hinge H), `peak_hinge_force.H` (N) and `peak_hinge_moment.H` (N·m), with rigid
/// latches `latch_impulse.H` (N·m·s) and with compliant ones `peak_latch_moment.H` (N·m),
/// `peak_root_force.BEAM` (N) and `peak_root_moment.BEAM` (N·m), `hub_attitude_excursion`
/// (rad) and `hub_position_excursion` (m); with `response`, the peak elastic tip deflections
/// over the response, `peak_tip_deflection.BEAM.v`, `….BEAM.w` and
/// `peak_tip_deflection.PLATE.minus`, `….PLATE.plus` (m).
pub fn output_names(st: &Structure, d: &Deployment, response: bool) -> Vec<String> {
    let n = d.chain.hinges.len();
    let hinge = |stem: &'static str| (1..=n).map(move |h| format!("{stem}.{h}"));
    let mut v: Vec<String> = hinge("latch_time").collect();
    v.extend(
        [
            "all_latched",
            "final_latch_time",
            "swing_back",
            "min_swing_angle",
        ]
        .map(String::from),
    );
    v.extend(hinge("energy_lost"));
    v.extend(hinge("peak_hinge_force"));
    v.extend(hinge("peak_hinge_moment"));
    v.extend(hinge(match d.latch {
        LatchModel::Rigid => "latch_impulse",
        LatchModel::Compliant { .. } => "peak_latch_moment",
    }));
    for b in st.beams() {
        v.push(format!("peak_root_force.{}", b.name()));
        v.push(format!("peak_root_moment.{}", b.name()));
    }
    v.extend(["hub_attitude_excursion", "hub_position_excursion"].map(String::from));
    if response {
        v.extend(deflection_channels(st).into_iter().map(|(name, _)| name));
    }
    v
}

/// The SI unit of a per-run output of [`output_names`] ("-" for the 0/1 flags).
pub fn output_unit(name: &str) -> &'static str {
    match name.split('.').next().unwrap_or(name) {
        "latch_time" | "final_latch_time" => "s",
        "all_latched" | "swing_back" => "-",
        "min_swing_angle" | "hub_attitude_excursion" => "rad",
        "energy_lost" => "J",
        "peak_hinge_force" | "peak_root_force" => "N",
        "peak_hinge_moment" | "peak_latch_moment" | "peak_root_moment" => "N·m",
        "latch_impulse" => "N·m·s",
        _ => "m",
    }
}

/// The response outputs: per beam its tip's v and w, per plate its two tip corners, as
/// (output name, the name of `flexcraft simulate`'s response channel).
fn deflection_channels(st: &Structure) -> Vec<(String, String)> {
    let mut v = Vec::new();
    for b in st.beams() {
        for side in ["v", "w"] {
            v.push((
                format!("peak_tip_deflection.{}.{side}", b.name()),
                format!("{}_tip_{side}", b.name()),
            ));
        }
    }
    for p in st.plates() {
        for side in ["minus", "plus"] {
            v.push((
                format!("peak_tip_deflection.{}.{side}", p.name()),
                format!("{}_tip_{side}", p.name()),
            ));
        }
    }
    v
}

/// The latch time of every hinge (rigid latch events and compliant captures; NaN if never).
fn latch_times(n: usize, r: &DeploymentResult) -> Vec<f64> {
    let mut t = vec![f64::NAN; n];
    for e in &r.latches {
        for &h in &e.locked {
            if t[h - 1].is_nan() {
                t[h - 1] = e.time;
            }
        }
    }
    for k in &r.captures {
        if t[k.hinge - 1].is_nan() {
            t[k.hinge - 1] = k.time;
        }
    }
    t
}

/// The deployment outputs of one run ([`output_names`] order, without the response ones).
///
/// Latch loads: with rigid latches `latch_impulse.H` is the largest |angular impulse| hinge
/// H carries at any latch event (N·m·s; the impact is instantaneous, so the impulse, not a
/// moment, is its load); with compliant latches `peak_latch_moment.H` is the peak |moment|
/// of the latch spring–damper on hinge H, tracked at every integration step (not only at the
/// samples) with the run's peak tracker (NaN if never captured).
pub fn outputs(st: &Structure, d: &Deployment, c: &Coupled, r: &DeploymentResult) -> Vec<f64> {
    let n = d.chain.hinges.len();
    let times = latch_times(n, r);
    let mut v = times.clone();
    v.push(f64::from(u8::from(r.all_latched)));
    v.push(if r.all_latched {
        times.iter().copied().fold(0.0, f64::max)
    } else {
        f64::INFINITY
    });
    v.push(f64::from(u8::from(!r.swing_back.is_empty())));
    v.push((r.swing_back.iter().map(|s| s.min_angle)).fold(f64::NAN, |a: f64, b| a.min(b)));
    let mut lost = vec![0.0; n];
    for e in &r.latches {
        lost[e.hinge - 1] += e.energy_before - e.energy_after;
    }
    v.extend(lost);
    // The coupled model's peaks tracked at every step, not only at the samples.
    let t = c.tracked_loads();
    let peak = |i: usize| r.load_peaks.get(i).map_or(f64::NAN, |p| p.0);
    v.extend((0..n).map(|h| peak(t.hinge_force(h))));
    v.extend((0..n).map(|h| peak(t.hinge_moment(h))));
    let (att, pos) = (peak(t.hub_rotation()), peak(t.hub_position()));
    match d.latch {
        LatchModel::Rigid => {
            let mut impulse = vec![0.0_f64; n];
            for e in &r.latches {
                for (h, (_, m)) in e.impulses.iter().enumerate().take(n) {
                    impulse[h] = impulse[h].max(m.abs());
                }
            }
            v.extend(impulse);
        }
        LatchModel::Compliant { .. } => {
            v.extend((0..n).map(|h| {
                let captured = r.captures.iter().any(|k| k.hinge == h + 1);
                if captured {
                    peak(t.latch_moment(h))
                } else {
                    f64::NAN
                }
            }));
        }
    }
    for b in st.beams() {
        match c.base.beams.iter().position(|x| x.name == b.name()) {
            Some(j) => v.extend([peak(t.root_force(j)), peak(t.root_moment(j))]),
            None => v.extend([f64::NAN; 2]),
        }
    }
    v.push(att);
    v.push(pos);
    v
}

/// The static torque margin of every hinge over its travel from the initial to the latch
/// angle, at the [`MARGIN_POINTS`] fractions s: with α(s) = α₀ + s (α_L − α₀),
///
///   TM(s) = k (α_ref − α(s)) / μ − 1,
///
/// the driving spring moment over the resisting Coulomb friction μ, less one (NASA-STD-5017
/// without its model-uncertainty factors; +∞ without friction). Requirement: ≥ 1 (100 %).
pub fn torque_margins(d: &Deployment) -> Vec<Vec<f64>> {
    (d.chain.hinges.iter())
        .map(|h| {
            (0..MARGIN_POINTS)
                .map(|j| {
                    let s = j as f64 / (MARGIN_POINTS - 1) as f64;
                    let a = h.initial_angle + s * (h.latch_angle - h.initial_angle);
                    let drive = h.stiffness * (h.reference_angle - a);
                    if h.friction == 0.0 {
                        f64::INFINITY
                    } else {
                        drive / h.friction - 1.0
                    }
                })
                .collect()
        })
        .collect()
}

/// The modes of the deployed structure and the channels of the tip deflections, for the
/// response outputs.
struct ResponseModel {
    model: RitzModel,
    modes: ModalAnalysis,
    channels: Vec<Channel>,
}

impl ResponseModel {
    /// The model, modes and deflection channels of a scenario's structure, as `simulate`
    /// computes them.
    fn new(s: &Scenario) -> Result<Self, RitzError> {
        Self::of(&s.structure, s)
    }

    /// As [`ResponseModel::new`] for the structure `st` (the scenario's, its wing on a
    /// sampled deployment's latch lines).
    fn of(st: &crate::structure::Structure, s: &Scenario) -> Result<Self, RitzError> {
        let model = RitzModel::assemble(st);
        let modes = ModalAnalysis::compute(&model)?.with_selection(s.term_selection.as_ref());
        let all = standard_channels(&model);
        let channels = deflection_channels(st)
            .into_iter()
            .map(|(_, c)| {
                (all.iter().find(|a| a.name == c).cloned())
                    .expect("a tip channel for every beam and plate")
            })
            .collect();
        Ok(Self {
            model,
            modes,
            channels,
        })
    }

    /// The peak |deflection| of every channel over the response after the deployment `r`
    /// (hand-over at the final latch, exact modal superposition, the `[response]` samples);
    /// NaN when not every hinge latched.
    fn peaks(
        &self,
        s: &Scenario,
        d: &Deployment,
        c: &Coupled,
        r: &DeploymentResult,
    ) -> Result<Vec<f64>, ResponseError> {
        let settings = &s.response;
        let h = match hand_over_coupled(&self.model, &self.modes, d, c, r, settings.handover) {
            Ok(h) => h,
            Err(ResponseError::NotLatched { .. }) => {
                return Ok(vec![f64::NAN; self.channels.len()])
            }
            Err(e) => return Err(e),
        };
        let modal = ModalResponse::with_initial(
            &self.modes,
            &h.modal_displacement,
            &h.modal_velocity,
            settings,
        )
        .with_line_damping(&self.modes.line_damping_ratios(&self.model));
        let history = modal.sample(&self.modes, &self.channels, settings);
        Ok((0..self.channels.len())
            .map(|k| history.peak(k).0)
            .collect())
    }
}

/// What every run of an analysis shares, prepared once: the count of outputs, the
/// re-lowering of `[deployment]` alone when every dispersed key is a deployment key (the
/// structure then cannot change, and a run does not parse and build it again), and with
/// response outputs the modes of the deployed structure (computed once, used by every run
/// whose structure is the base's).
pub struct Runner<'a> {
    base: &'a Scenario,
    mc: &'a MonteCarlo,
    names: usize,
    deployment_only: Option<DeploymentOverrides>,
    response: Option<Result<ResponseModel, RitzError>>,
}

impl<'a> Runner<'a> {
    /// Prepares the runs of `mc` on `base` (a scenario with `[deployment]`).
    pub fn new(base: &'a Scenario, mc: &'a MonteCarlo) -> Self {
        let d = base
            .deployment
            .as_ref()
            .expect("a Monte Carlo scenario has [deployment]");
        let names = output_names(&base.structure, d, mc.response).len();
        let deployment_only =
            if Scenario::deployment_paths_only(mc.dispersions.iter().map(|d| d.path.as_str())) {
                base.deployment_overrides()
            } else {
                None
            };
        Self {
            base,
            mc,
            names,
            deployment_only,
            response: mc.response.then(|| ResponseModel::new(base)),
        }
    }

    /// Run i: applies its values, deploys, and collects the outputs.
    pub fn run(&self, i: u64) -> RunRecord {
        let applied = self.mc.draw(i);
        let values: Vec<(&str, OverrideValue)> = (self.mc.dispersions.iter().zip(&applied))
            .map(|(d, v)| (d.path.as_str(), OverrideValue::Number(*v)))
            .collect();
        let empty = |status| RunRecord {
            index: i,
            status,
            applied: applied.clone(),
            outputs: vec![f64::NAN; self.names],
            margins: Vec::new(),
        };
        // The run's scenario: the base with a new deployment, or the whole file again.
        let whole;
        let (s, d) = match &self.deployment_only {
            Some(t) => match t.deployment(self.base, &values) {
                Ok(d) => (self.base, d),
                Err(_) => return empty(RunStatus::Refused),
            },
            None => match self.base.with_values(&values) {
                Ok(s) => {
                    whole = s;
                    match whole.deployment.clone() {
                        Some(d) => (&whole, d),
                        None => return empty(RunStatus::Refused),
                    }
                }
                Err(_) => return empty(RunStatus::Refused),
            },
        };
        // Without the periodic samples: every output below is read from the latch events and
        // the load peaks tracked at every step.
        let Ok((c, r)) = simulate_coupled_with(&s.structure, &d, false) else {
            return empty(RunStatus::Failed);
        };
        let mut out = outputs(&s.structure, &d, &c, &r);
        if let Some(base_model) = &self.response {
            // The deployed wing stands on this run's latch lines (a sampled latch or hinge
            // spring changes the deployed modes).
            let Ok(deployed) = d.latched_structure(&s.structure) else {
                return empty(RunStatus::Refused);
            };
            let same = deployed == self.base.structure
                && (std::ptr::eq(s, self.base)
                    || (s.term_selection.is_none() && self.base.term_selection.is_none()));
            let own;
            let model = if same {
                base_model.as_ref().ok()
            } else {
                own = ResponseModel::of(&deployed, s);
                own.as_ref().ok()
            };
            let Some(peaks) = model.and_then(|m| m.peaks(s, &d, &c, &r).ok()) else {
                return empty(RunStatus::Failed);
            };
            out.extend(peaks);
        }
        if out.len() != self.names {
            // A dispersion changed the number of hinges or beams: not comparable.
            return empty(RunStatus::Refused);
        }
        let complete = !(r.diverged() || r.step_limit_reached());
        RunRecord {
            index: i,
            status: if complete {
                RunStatus::Ok
            } else {
                RunStatus::Incomplete
            },
            applied,
            outputs: out,
            margins: torque_margins(&d),
        }
    }
}

/// The memory the records of `runs` runs hold until the analysis (each run's applied values,
/// outputs and torque-margin curves, with their allocations' headers; the run indices), an
/// estimate checked before the runs start.
pub fn records_bytes(mc: &MonteCarlo, outputs: usize, hinges: usize, runs: u64) -> u64 {
    let vec = 24u64;
    let per_run = 8 // the index
        + 16 // status and padding
        + 8 // the shard's index list
        + 3 * vec
        + 8 * (mc.dispersions.len() + outputs) as u64
        + hinges as u64 * (vec + 8 * MARGIN_POINTS as u64);
    runs.saturating_mul(per_run)
}

/// Runs `indices` on the current rayon pool (`on_done` after each run, from any thread);
/// the records come back in the order of `indices`, whatever the threads.
pub fn run_many(
    base: &Scenario,
    mc: &MonteCarlo,
    indices: &[u64],
    on_done: &(dyn Fn() + Sync),
) -> Vec<RunRecord> {
    let runner = Runner::new(base, mc);
    indices
        .par_iter()
        .map(|&i| {
            let r = runner.run(i);
            on_done();
            r
        })
        .collect()
}

/// The worst case (smallest) margin of every hinge at every point over the records, and
/// over curves already reduced (a shard's): the minimum is exact and associative, so any
/// split reduces to the same curve.
pub fn worst_margins<'a>(
    hinges: usize,
    curves: impl IntoIterator<Item = &'a Vec<Vec<f64>>>,
) -> Vec<Vec<f64>> {
    let mut w = vec![vec![f64::INFINITY; MARGIN_POINTS]; hinges];
    for c in curves {
        for (wh, ch) in w.iter_mut().zip(c) {
            for (a, b) in wh.iter_mut().zip(ch) {
                *a = a.min(*b);
            }
        }
    }
    w
}

/// A requirement's verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// The requirement.
    pub requirement: Requirement,
    /// Runs.
    pub runs: u64,
    /// Runs that did not meet it (refused and failed runs included).
    pub failures: u64,
    /// Failures allowed at p, c by order statistics (`None`: too few runs even for none).
    pub allowed: Option<u64>,
    /// Runs needed to allow the observed failures (order statistics).
    pub runs_needed: u64,
    /// Met: failures ≤ allowed.
    pub met: bool,
    /// The one-sided p/c tolerance bound on the compared value (the output times the factor
    /// of safety, if any) from the runs, on the side of the bound (upper for `max`, lower
    /// for `min`; `None` when too few runs).
    pub tolerance_bound: Option<f64>,
    /// The dispersed parameters ranked by |Spearman ρ| with the failure indicator, with
    /// their SRRCs.
    pub drivers: Sensitivity,
}

/// One parameter's sensitivity measures for one output.
#[derive(Debug, Clone, PartialEq)]
pub struct Ranked {
    /// The dispersed parameter's path.
    pub parameter: String,
    /// Spearman's rank correlation with the output (NaN when either is constant).
    pub spearman: f64,
    /// Its standardised rank regression coefficient ([`stats::rank_regression`]).
    pub srrc: f64,
}

/// The sensitivity of one output to the dispersed parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensitivity {
    /// The parameters, largest |Spearman ρ| first (NaN last; ties in path order).
    pub ranking: Vec<Ranked>,
    /// R² of the rank regression.
    pub r2: f64,
    /// Runs in the rank regression (those with a value).
    pub runs: usize,
}

/// Everything summary.json reports.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysis {
    /// Runs by status (ok, refused, failed, incomplete).
    pub status_counts: Vec<(&'static str, u64)>,
    /// Per dispersed parameter: its path and the summary of its applied values.
    pub applied: Vec<(String, Summary)>,
    /// Per output: its name and summary.
    pub outputs: Vec<(String, Summary)>,
    /// Per requirement.
    pub verdicts: Vec<Verdict>,
    /// Per output: its sensitivity to the parameters.
    pub sensitivity: Vec<(String, Sensitivity)>,
    /// Per correlated pair ([`MonteCarlo::correlations`]): the Spearman correlation of the
    /// applied values (against (6/π) asin(ρ/2) expected).
    pub correlations: Vec<f64>,
}

/// The applied values of the runs, by parameter, with their ranks (computed once for every
/// output's ranking).
struct Columns {
    values: Vec<Vec<f64>>,
    ranks: Vec<Vec<f64>>,
}

/// Parameters ranked by |Spearman ρ| with `y`, largest first (NaN last; ties in path
/// order), with their SRRCs and the R² of the rank regression.
fn ranking(mc: &MonteCarlo, columns: &Columns, y: &[f64]) -> Sensitivity {
    let yr = stats::ranks(y);
    let rr = if y.iter().any(|v| v.is_nan()) {
        stats::rank_regression(&columns.values, y)
    } else {
        stats::regress_ranks(&columns.ranks, &yr)
    };
    let mut ranking: Vec<Ranked> = (mc.dispersions.iter().zip(&columns.ranks))
        .zip(&rr.coefficients)
        .map(|((d, xr), srrc)| Ranked {
            parameter: d.path.clone(),
            // Spearman's ρ = Pearson of the ranks (NaN ranked last).
            spearman: stats::pearson(xr, &yr),
            srrc: *srrc,
        })
        .collect();
    ranking.sort_by(|a, b| {
        let key = |v: f64| if v.is_nan() { -1.0 } else { v.abs() };
        key(b.spearman).total_cmp(&key(a.spearman))
    });
    Sensitivity {
        ranking,
        r2: rr.r2,
        runs: rr.runs,
    }
}

/// The verdict of one requirement over the values of its output.
fn verdict(q: &Requirement, mc: &MonteCarlo, columns: &Columns, values: &[f64]) -> Verdict {
    let n = values.len() as u64;
    let fail: Vec<f64> = values
        .iter()
        .map(|v| f64::from(u8::from(!q.met(*v))))
        .collect();
    let failures = fail.iter().filter(|f| **f > 0.0).count() as u64;
    let allowed = order::allowed_failures(n, q.probability, q.confidence);
    // NaN counts as the worst value on the bound's side.
    let upper = q.max.is_some();
    let worst = if upper {
        f64::INFINITY
    } else {
        f64::NEG_INFINITY
    };
    let s = stats::sorted(
        &values
            .iter()
            .map(|v| if v.is_nan() { worst } else { q.checked(*v) })
            .collect::<Vec<_>>(),
    );
    let tolerance_bound = allowed.map(|f| {
        if upper {
            s[(n - 1 - f) as usize]
        } else {
            s[f as usize]
        }
    });
    Verdict {
        requirement: q.clone(),
        runs: n,
        failures,
        allowed,
        runs_needed: order::runs_needed(failures, q.probability, q.confidence),
        met: allowed.is_some_and(|a| failures <= a),
        tolerance_bound,
        drivers: ranking(mc, columns, &fail),
    }
}

/// Statistics, verdicts and sensitivities of complete records (sorted by index).
pub fn analyse(mc: &MonteCarlo, names: &[String], records: &[RunRecord]) -> Analysis {
    let column = |f: &dyn Fn(&RunRecord) -> f64| records.iter().map(f).collect::<Vec<f64>>();
    let applied: Vec<Vec<f64>> = (0..mc.dispersions.len())
        .map(|k| column(&|r| r.applied[k]))
        .collect();
    let columns = Columns {
        ranks: applied.iter().map(|x| stats::ranks(x)).collect(),
        values: applied.clone(),
    };
    let outs: Vec<Vec<f64>> = (0..names.len())
        .map(|k| column(&|r| r.outputs[k]))
        .collect();
    let status_counts = [
        RunStatus::Ok,
        RunStatus::Refused,
        RunStatus::Failed,
        RunStatus::Incomplete,
    ]
    .map(|s| {
        (
            s.name(),
            records.iter().filter(|r| r.status == s).count() as u64,
        )
    })
    .to_vec();
    let verdicts = (mc.requirements.iter())
        .map(|q| {
            let k = names
                .iter()
                .position(|n| *n == q.output)
                .expect("validated");
            verdict(q, mc, &columns, &outs[k])
        })
        .collect();
    Analysis {
        status_counts,
        applied: (mc.dispersions.iter().zip(&applied))
            .map(|(d, v)| (d.path.clone(), stats::summarize(v)))
            .collect(),
        outputs: (names.iter().zip(&outs))
            .map(|(n, v)| (n.clone(), stats::summarize(v)))
            .collect(),
        verdicts,
        sensitivity: (names.iter().zip(&outs))
            .map(|(n, y)| (n.clone(), ranking(mc, &columns, y)))
            .collect(),
        correlations: (mc.correlations.iter())
            .map(|c| {
                let (i, j) = c.keys();
                stats::pearson(&columns.ranks[i], &columns.ranks[j])
            })
            .collect(),
    }
}
