//! `[montecarlo]` (docs/montecarlo.md): runs, seed, the dispersions keyed by dotted path and
//! the requirements on per-run outputs.

use super::context::Ctx;
use super::raw::{RawCorrelation, RawDispersion, RawMonteCarlo, RawRequirement, S};
use super::{ErrorKind, Location, Scenario, ScenarioError};
use crate::deploy::Deployment;
use crate::montecarlo::{
    output_names, Copula, CopulaError, Correlation, Dispersion, Distribution, MonteCarlo,
    Requirement,
};
use crate::structure::Structure;

/// Most runs one scenario may ask for.
pub const MAX_RUNS: u64 = 100_000_000;
/// Runs when `runs` is not given.
pub const DEFAULT_RUNS: u64 = 100;

/// Exactly two numbers.
fn pair(cx: &Ctx, v: &S<Vec<f64>>, key: &str, what: &str) -> Result<(f64, f64), ScenarioError> {
    match v.get_ref().as_slice() {
        [a, b] => Ok((*a, *b)),
        _ => Err(cx.invalid(v.span(), key, format!("must be two numbers: {what}"))),
    }
}

/// One `[montecarlo.dispersions]` entry.
fn lower_dispersion(
    cx: &Ctx,
    path: &str,
    d: &S<RawDispersion>,
) -> Result<Distribution, ScenarioError> {
    let r = d.get_ref();
    let key = format!("montecarlo.dispersions.\"{path}\"");
    let given = [&r.normal, &r.uniform, &r.lognormal, &r.choice]
        .iter()
        .filter(|v| v.is_some())
        .count();
    if given != 1 {
        return Err(cx.invalid(
            d.span(),
            &key,
            "give exactly one distribution: normal = [mean, sd], uniform = [low, high], \
             lognormal = [mu, sigma] (of ln x) or choice = [values] (with optional weights); \
             a normal may add truncate = [low, high]",
        ));
    }
    let refuse_extra = |v: &Option<S<Vec<f64>>>, name: &str, with: &str| match v {
        Some(v) => Err(cx.invalid(
            v.span(),
            format!("{key}.{name}"),
            format!("applies to {with} only"),
        )),
        None => Ok(()),
    };
    if r.normal.is_none() {
        refuse_extra(&r.truncate, "truncate", "a normal distribution")?;
    }
    if r.choice.is_none() {
        refuse_extra(&r.weights, "weights", "a choice")?;
    }
    let (dist, span) = if let Some(v) = &r.normal {
        let (mean, sd) = pair(cx, v, &key, "[mean, standard deviation]")?;
        match &r.truncate {
            Some(t) => {
                let (low, high) = pair(cx, t, &format!("{key}.truncate"), "[low, high]")?;
                (
                    Distribution::TruncatedNormal {
                        mean,
                        sd,
                        low,
                        high,
                    },
                    t.span(),
                )
            }
            None => (Distribution::Normal { mean, sd }, v.span()),
        }
    } else if let Some(v) = &r.uniform {
        let (low, high) = pair(cx, v, &key, "[low, high]")?;
        (Distribution::Uniform { low, high }, v.span())
    } else if let Some(v) = &r.lognormal {
        let (mu, sigma) = pair(cx, v, &key, "[mu, sigma] of ln x")?;
        (Distribution::LogNormal { mu, sigma }, v.span())
    } else {
        let v = r.choice.as_ref().expect("one is given");
        let values = v.get_ref().clone();
        let weights = match &r.weights {
            Some(w) => relative_weights(w.get_ref()),
            None => vec![1.0; values.len()],
        };
        (Distribution::Choice { values, weights }, v.span())
    };
    dist.validate()
        .map_err(|e| cx.invalid(span, &key, e.to_string()))?;
    Ok(dist)
}

/// A choice's weights as given, or, when their sum would overflow (each finite, e.g. two of
/// 1e308), divided by the largest: only their ratios matter.
fn relative_weights(w: &[f64]) -> Vec<f64> {
    if w.iter().sum::<f64>().is_finite() {
        return w.to_vec();
    }
    let top = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if top.is_finite() && top > 0.0 {
        w.iter().map(|x| x / top).collect()
    } else {
        w.to_vec()
    }
}

/// One `[[montecarlo.requirements]]` entry.
fn lower_requirement(
    cx: &Ctx,
    i: usize,
    q: &S<RawRequirement>,
    outputs: &[String],
) -> Result<Requirement, ScenarioError> {
    let r = q.get_ref();
    let key = |k: &str| format!("montecarlo.requirements[{i}].{k}");
    if let Err(why) = crate::limits::valid_text("a requirement's name", r.name.get_ref()) {
        return Err(cx.invalid(r.name.span(), key("name"), why));
    }
    if !outputs.contains(r.output.get_ref()) {
        return Err(cx.invalid(
            r.output.span(),
            key("output"),
            format!(
                "no per-run output is named {:?}; the outputs are {}",
                r.output.get_ref(),
                outputs.join(", ")
            ),
        ));
    }
    let unit = |v: &S<f64>, k: &str| {
        let x = *v.get_ref();
        if x > 0.0 && x < 1.0 {
            Ok(x)
        } else {
            Err(cx.invalid(
                v.span(),
                key(k),
                format!("must lie strictly between 0 and 1, got {x}"),
            ))
        }
    };
    let probability = unit(&r.probability, "probability")?;
    let confidence = unit(&r.confidence, "confidence")?;
    let (min, max) = (r.min.as_ref(), r.max.as_ref());
    if min.is_none() && max.is_none() {
        return Err(cx.missing(q.span(), key("max"), "give max, min or both"));
    }
    for (v, k) in [(min, "min"), (max, "max")] {
        if let Some(v) = v.filter(|v| !v.get_ref().is_finite()) {
            return Err(cx.invalid(v.span(), key(k), "must be a finite number"));
        }
    }
    if let (Some(a), Some(b)) = (min, max) {
        if a.get_ref() >= b.get_ref() {
            return Err(cx.invalid(
                b.span(),
                key("max"),
                format!("min {} must be below max {}", a.get_ref(), b.get_ref()),
            ));
        }
    }
    let factor_of_safety = match &r.factor_of_safety {
        None => None,
        Some(f) => {
            let x = *f.get_ref();
            if !(x.is_finite() && x >= 1.0) {
                return Err(cx.invalid(
                    f.span(),
                    key("factor_of_safety"),
                    format!("must be a finite number ≥ 1 (it multiplies the output), got {x}"),
                ));
            }
            if min.is_some() || max.is_none() {
                return Err(cx.invalid(
                    f.span(),
                    key("factor_of_safety"),
                    "applies to a max bound only (output × factor ≤ max, a load against its \
                     allowable); give max without min",
                ));
            }
            Some(x)
        }
    };
    Ok(Requirement {
        name: r.name.get_ref().clone(),
        output: r.output.get_ref().clone(),
        min: min.map(|v| *v.get_ref()),
        max: max.map(|v| *v.get_ref()),
        probability,
        confidence,
        factor_of_safety,
    })
}

/// `[[montecarlo.correlations]]`: the pairs (keys resolved to dispersion indices) and their
/// copula; each refusal is located at the entry's `keys` or `coefficient`.
fn lower_correlations(
    cx: &Ctx,
    raw: &[S<RawCorrelation>],
    dispersions: &[Dispersion],
) -> Result<(Vec<Correlation>, Option<Copula>), ScenarioError> {
    if raw.is_empty() {
        return Ok((Vec::new(), None));
    }
    let key = |i: usize, k: &str| format!("montecarlo.correlations[{i}].{k}");
    let mut pairs = Vec::new();
    for (i, c) in raw.iter().enumerate() {
        let c = c.get_ref();
        let names = c.keys.get_ref();
        let [a, b] = names.as_slice() else {
            return Err(cx.invalid(
                c.keys.span(),
                key(i, "keys"),
                format!("must name exactly two dispersed keys, got {}", names.len()),
            ));
        };
        let index = |n: &String| {
            dispersions
                .iter()
                .position(|d| d.path == *n)
                .ok_or_else(|| {
                    let known: Vec<&str> = dispersions.iter().map(|d| d.path.as_str()).collect();
                    cx.invalid(
                        c.keys.span(),
                        key(i, "keys"),
                        format!(
                            "\"{n}\" is not dispersed: a correlation pairs two keys of \
                         [montecarlo.dispersions] ({})",
                            if known.is_empty() {
                                "none".to_string()
                            } else {
                                known.join(", ")
                            }
                        ),
                    )
                })
        };
        let (ia, ib) = (index(a)?, index(b)?);
        let pair = Correlation::new(ia, ib, *c.coefficient.get_ref()).map_err(|e| {
            let (span, k) = match e {
                CopulaError::Coefficient(_) => (c.coefficient.span(), "coefficient"),
                _ => (c.keys.span(), "keys"),
            };
            cx.invalid(span, key(i, k), e.to_string())
        })?;
        pairs.push(pair);
    }
    let marginals: Vec<Distribution> = dispersions.iter().map(|d| d.distribution.clone()).collect();
    let copula = Copula::new(&marginals, &pairs).map_err(|e| {
        let c = raw[e.pair].get_ref();
        let (span, k) = match e.error {
            CopulaError::NotPositiveDefinite { .. } => (c.coefficient.span(), "coefficient"),
            _ => (c.keys.span(), "keys"),
        };
        cx.invalid(span, key(e.pair, k), e.error.to_string())
    })?;
    Ok((pairs, Some(copula)))
}

/// `[montecarlo]`. It needs `[deployment]` (the runs are deployments), and `[response]`
/// (`response_written`) when it asks for the per-run response outputs.
pub(super) fn lower(
    cx: &Ctx,
    m: &S<RawMonteCarlo>,
    st: &Structure,
    d: Option<&Deployment>,
    response_written: bool,
) -> Result<MonteCarlo, ScenarioError> {
    let r = m.get_ref();
    let Some(d) = d else {
        return Err(cx.missing(
            m.span(),
            "montecarlo",
            "the runs are deployments: the scenario needs a [deployment] section",
        ));
    };
    let runs = match &r.runs {
        None => DEFAULT_RUNS,
        Some(v) => match u64::try_from(*v.get_ref()) {
            Ok(n) if (1..=MAX_RUNS).contains(&n) => n,
            _ => {
                return Err(cx.invalid(
                    v.span(),
                    "montecarlo.runs",
                    format!(
                        "must be an integer from 1 to {MAX_RUNS}, got {}",
                        v.get_ref()
                    ),
                ))
            }
        },
    };
    let seed = match &r.seed {
        None => 0,
        Some(v) => u64::try_from(*v.get_ref()).map_err(|_| {
            cx.invalid(
                v.span(),
                "montecarlo.seed",
                format!("must be an integer ≥ 0, got {}", v.get_ref()),
            )
        })?,
    };
    let dispersions = (r.dispersions.iter())
        .map(|(path, v)| {
            Ok(Dispersion {
                path: path.clone(),
                distribution: lower_dispersion(cx, path, v)?,
            })
        })
        .collect::<Result<Vec<_>, ScenarioError>>()?;
    let (correlations, copula) = lower_correlations(cx, &r.correlations, &dispersions)?;
    let response = match &r.response {
        Some(v) if *v.get_ref() && !response_written => {
            return Err(cx.missing(
                v.span(),
                "montecarlo.response",
                "the per-run response outputs need a [response] section (its duration, \
                 output_rate, modes and damping_ratio set the response of every run)",
            ))
        }
        Some(v) => *v.get_ref(),
        None => false,
    };
    let outputs = output_names(st, d, response);
    let requirements = (r.requirements.iter().enumerate())
        .map(|(i, q)| lower_requirement(cx, i, q, &outputs))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(MonteCarlo {
        runs,
        seed,
        dispersions,
        requirements,
        correlations,
        copula,
        response,
    })
}

impl Scenario {
    /// Checks every dispersion against the scenario it disperses: its path must resolve to a
    /// numeric key the schema accepts (applied at two values of its distribution, each must
    /// validate), and the key must be used: the scenarios lowered at the two values must
    /// differ. A key the file does not write, or one that another key overrides (e.g.
    /// `deployment.hinge.stiffness` when every `[[deployment.hinges]]` table sets its own
    /// stiffness), changes nothing and is refused rather than silently not applied.
    /// (A distribution with a single value cannot be checked for use; its path is still
    /// checked.) Errors are located at the dispersion's entry.
    pub fn check_dispersions(&self) -> Result<(), ScenarioError> {
        let Some(mc) = &self.montecarlo else {
            return Ok(());
        };
        let fingerprint = |s: &Scenario| {
            format!(
                "{:?}|{:?}|{:?}|{:?}",
                s.structure, s.deployment, s.response, s.export
            )
        };
        for d in &mc.dispersions {
            let location = (self.sources.dispersions.iter())
                .find(|(p, _)| *p == d.path)
                .map_or(Location { line: 1, column: 1 }, |(_, l)| *l);
            let err = |reason: String| ScenarioError {
                kind: ErrorKind::Invalid,
                file: self.sources.file.clone(),
                location,
                key: format!("montecarlo.dispersions.\"{}\"", d.path),
                reason,
            };
            let (a, b) = d.distribution.probes();
            let at = |v: f64| {
                self.with_values(&[(d.path.as_str(), v.into())])
                    .map_err(|e| {
                        err(format!(
                            "{}: {} (probed with the value {v})",
                            e.key, e.reason
                        ))
                    })
            };
            let (sa, sb) = (at(a)?, at(b)?);
            if a != b && fingerprint(&sa) == fingerprint(&sb) {
                return Err(err(format!(
                    "the scenario does not use this key: setting it to {a} or to {b} gives \
                     the same model (is it overridden elsewhere, e.g. by every \
                     [[deployment.hinges]] table?); disperse the key that is used"
                )));
            }
        }
        Ok(())
    }
}
