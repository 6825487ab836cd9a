//! Monte Carlo dispersions of a deployment (docs/montecarlo.md): the `[montecarlo]`
//! settings, the draws of run i from a generator seeded by (seed, i) alone, one run's
//! applied scenario and outputs, and the analysis of many runs (statistics, requirement
//! verdicts by order statistics, sensitivity ranking, static torque margins).
//!
//! Reproducible by construction: run i draws from ChaCha20 seeded with `seed` on stream i, so
//! its values, and so its outputs, do not depend on the thread count, the shard split or the
//! order of the runs.

pub mod distributions;
pub mod order;
pub mod stats;

use crate::deploy::coupled::Coupled;
use crate::deploy::{simulate_coupled, Deployment, DeploymentResult};
use crate::scenario::{OverrideValue, Scenario};
use crate::structure::Structure;
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
}

impl Requirement {
    /// Whether a run's value meets the bounds (NaN never does).
    pub fn met(&self, v: f64) -> bool {
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
    /// order.
    pub fn draw(&self, i: u64) -> Vec<f64> {
        let mut rng = ChaCha20Rng::seed_from_u64(self.seed);
        rng.set_stream(i);
        (self.dispersions.iter())
            .map(|d| d.distribution.sample(&mut rng))
            .collect()
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
/// event of hinge H), `peak_hinge_force.H` (N) and `peak_hinge_moment.H` (N·m),
/// `peak_root_force.BEAM` (N) and `peak_root_moment.BEAM` (N·m), `hub_attitude_excursion`
/// (rad) and `hub_position_excursion` (m).
pub fn output_names(st: &Structure, d: &Deployment) -> Vec<String> {
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
    for b in st.beams() {
        v.push(format!("peak_root_force.{}", b.name()));
        v.push(format!("peak_root_moment.{}", b.name()));
    }
    v.extend(["hub_attitude_excursion", "hub_position_excursion"].map(String::from));
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

/// The outputs of one run ([`output_names`] order).
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
    let (mut force, mut moment) = (vec![0.0_f64; n], vec![0.0_f64; n]);
    let (mut att, mut pos) = (0.0_f64, 0.0_f64);
    for s in &r.samples {
        for i in 0..n.min(s.force.len()) {
            force[i] = force[i].max(s.force[i][0].hypot(s.force[i][1]));
            moment[i] = moment[i].max(s.moment[i].abs());
        }
        let (a, p) = match &s.body {
            Some(b) => (norm(b.hub_rotation), norm(b.hub_position)),
            None => (s.hub[2].abs(), s.hub[0].hypot(s.hub[1])),
        };
        (att, pos) = (att.max(a), pos.max(p));
    }
    v.extend(force);
    v.extend(moment);
    let panels = c.panels();
    for b in st.beams() {
        let at = c.base.beams.iter().position(|x| x.name == b.name());
        let peak = |k: usize| {
            at.and_then(|j| r.load_peaks.get(panels + 2 * j + k))
                .map_or(f64::NAN, |p| p.0)
        };
        v.push(peak(0));
        v.push(peak(1));
    }
    v.push(att);
    v.push(pos);
    v
}

fn norm(x: [f64; 3]) -> f64 {
    (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
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

/// Runs run i of `mc` on `base`: applies its values, deploys, and collects the outputs.
pub fn run_one(base: &Scenario, mc: &MonteCarlo, names: usize, i: u64) -> RunRecord {
    let applied = mc.draw(i);
    let values: Vec<(&str, OverrideValue)> = (mc.dispersions.iter().zip(&applied))
        .map(|(d, v)| (d.path.as_str(), OverrideValue::Number(*v)))
        .collect();
    let empty = |status| RunRecord {
        index: i,
        status,
        applied: applied.clone(),
        outputs: vec![f64::NAN; names],
        margins: Vec::new(),
    };
    let Ok(s) = base.with_values(&values) else {
        return empty(RunStatus::Refused);
    };
    let Some(d) = s.deployment.as_ref() else {
        return empty(RunStatus::Refused);
    };
    let Ok((c, r)) = simulate_coupled(&s.structure, d) else {
        return empty(RunStatus::Failed);
    };
    let out = outputs(&s.structure, d, &c, &r);
    if out.len() != names {
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
        margins: torque_margins(d),
    }
}

/// Runs `indices` on the current rayon pool (`on_done` after each run, from any thread);
/// the records come back in the order of `indices`, whatever the threads.
pub fn run_many(
    base: &Scenario,
    mc: &MonteCarlo,
    indices: &[u64],
    on_done: &(dyn Fn() + Sync),
) -> Vec<RunRecord> {
    let d = base
        .deployment
        .as_ref()
        .expect("a Monte Carlo scenario has [deployment]");
    let names = output_names(&base.structure, d).len();
    indices
        .par_iter()
        .map(|&i| {
            let r = run_one(base, mc, names, i);
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
    /// The one-sided p/c tolerance bound on the output from the runs, on the side of the
    /// bound (upper for `max`, lower for `min`; `None` when too few runs).
    pub tolerance_bound: Option<f64>,
    /// The dispersed parameters ranked by |Spearman ρ| with the failure indicator.
    pub drivers: Vec<(String, f64)>,
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
    /// Per output: the parameters ranked by |Spearman ρ| (NaN when either is constant,
    /// ranked last).
    pub sensitivity: Vec<(String, Vec<(String, f64)>)>,
}

/// Parameters ranked by |ρ| with `y`, largest first (NaN last; ties in path order).
fn ranking(mc: &MonteCarlo, columns: &[Vec<f64>], y: &[f64]) -> Vec<(String, f64)> {
    let mut r: Vec<(String, f64)> = (mc.dispersions.iter().zip(columns))
        .map(|(d, x)| (d.path.clone(), stats::spearman(x, y)))
        .collect();
    r.sort_by(|a, b| {
        let key = |v: f64| if v.is_nan() { -1.0 } else { v.abs() };
        key(b.1).total_cmp(&key(a.1))
    });
    r
}

/// The verdict of one requirement over the values of its output.
fn verdict(q: &Requirement, mc: &MonteCarlo, columns: &[Vec<f64>], values: &[f64]) -> Verdict {
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
            .map(|v| if v.is_nan() { worst } else { *v })
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
            verdict(q, mc, &applied, &outs[k])
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
            .map(|(n, y)| (n.clone(), ranking(mc, &applied, y)))
            .collect(),
    }
}
