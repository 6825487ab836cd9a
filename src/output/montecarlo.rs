//! The files of a Monte Carlo run, a shard and a merge (docs/montecarlo.md): scenario.toml,
//! shard.json (the fingerprint of scenario, seed and runs), runs.csv, torque_margin.csv and,
//! once every run is there, summary.json and the plots; the terminal table; reading shards
//! back and merging them.
//!
//! A merge recomputes everything from the rows it reads: every number is written in its
//! shortest round-trip form, so the rows read back are the f64 the runs produced, and the
//! merged folder is byte-identical to the unsharded run's.

use super::plot::{line_chart, Series};
use super::{num, OutputDir, OutputError};
use crate::montecarlo::{
    analyse, output_names, worst_margins, Analysis, MonteCarlo, RunRecord, RunStatus, Sensitivity,
    Summary, MARGIN_POINTS,
};
use crate::Scenario;
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What a shard folder holds besides its rows.
#[derive(Debug, Clone, PartialEq)]
pub struct ShardInfo {
    /// SHA-256 of the scenario text, the seed and the run count.
    pub hash: String,
    /// Seed.
    pub seed: u64,
    /// Runs of the whole analysis.
    pub runs: u64,
    /// This shard (0-based).
    pub shard: u64,
    /// Shards of the analysis.
    pub shards: u64,
}

/// The fingerprint written with every shard: SHA-256 of the scenario text, the seed and the
/// number of runs (shards of different analyses are never merged).
pub fn fingerprint(text: &str, mc: &MonteCarlo) -> String {
    fingerprint_of(text, mc.seed, mc.runs)
}

fn fingerprint_of(text: &str, seed: u64, runs: u64) -> String {
    sha256(format!("{text}\nseed={seed}\nruns={runs}\n").as_bytes())
}

/// SHA-256 in hexadecimal.
fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// shard.json's format line; merge refuses any other.
const SHARD_FORMAT: &str = "flexcraft Monte Carlo shard, version 2";

/// The files of a shard whose SHA-256 shard.json records at write time, checked by merge.
const SEALED: [&str; 3] = ["scenario.toml", "runs.csv", "torque_margin.csv"];

/// The seal of shard.json: SHA-256 over its fields and its files' hashes, so that an edit of
/// any of them (a run count, a shard number, a value in runs.csv) is found by merge.
fn seal(info: &ShardInfo, files: &[String]) -> String {
    sha256(
        format!(
            "{SHARD_FORMAT}\nhash={}\nseed={}\nruns={}\nshard={}\nshards={}\nfiles={}\n",
            info.hash,
            info.seed,
            info.runs,
            info.shard,
            info.shards,
            files.join(",")
        )
        .as_bytes(),
    )
}

/// runs.csv: run, status, every applied value, every output.
fn runs_csv(
    mc: &MonteCarlo,
    names: &[String],
    records: &[RunRecord],
) -> Result<Vec<u8>, OutputError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| OutputError::Io(std::io::Error::other(e.to_string()));
    let mut header = vec!["run".to_string(), "status".to_string()];
    header.extend(mc.dispersions.iter().map(|d| d.path.clone()));
    // The applied values are in their keys' own (SI) units, as written in the scenario; the
    // outputs carry theirs.
    header.extend(
        names
            .iter()
            .map(|n| format!("{n} [{}]", crate::montecarlo::output_unit(n))),
    );
    w.write_record(&header).map_err(csv_err)?;
    for r in records {
        let mut row = vec![r.index.to_string(), r.status.name().to_string()];
        row.extend(r.applied.iter().map(|v| num(*v)));
        row.extend(r.outputs.iter().map(|v| num(*v)));
        w.write_record(&row).map_err(csv_err)?;
    }
    w.into_inner()
        .map_err(|e| OutputError::Io(std::io::Error::other(e.to_string())))
}

/// torque_margin.csv: per fraction of the travel, every hinge's worst margin.
fn margin_csv(margins: &[Vec<f64>]) -> String {
    let mut s = String::from("travel fraction [-]");
    for h in 1..=margins.len() {
        s += &format!(",hinge {h} torque margin [-] (1 = 100 %)");
    }
    s.push('\n');
    for j in 0..MARGIN_POINTS {
        s += &num(j as f64 / (MARGIN_POINTS - 1) as f64);
        for m in margins {
            s += &format!(",{}", num(m[j]));
        }
        s.push('\n');
    }
    s
}

fn summary_json(s: &Summary) -> Value {
    let pct: serde_json::Map<String, Value> = (crate::montecarlo::stats::PERCENTILES.iter())
        .zip(&s.percentiles)
        .map(|(p, v)| (format!("p{p}"), json!(v)))
        .collect();
    json!({
        "count": s.count, "non_finite": s.non_finite, "mean": s.mean, "sd": s.sd,
        "min": s.min, "max": s.max, "percentiles": pct,
    })
}

fn ranked(r: &Sensitivity) -> Value {
    let params: Vec<Value> = (r.ranking.iter())
        .map(|p| json!({"parameter": p.parameter, "spearman": p.spearman, "srrc": p.srrc}))
        .collect();
    json!({"rank_regression_r2": r.r2, "runs": r.runs, "parameters": params})
}

/// summary.json.
pub fn summary(info: &ShardInfo, mc: &MonteCarlo, a: &Analysis, margins: &[Vec<f64>]) -> String {
    let correlations: Vec<Value> = (mc.correlations.iter().zip(&a.correlations))
        .map(|(c, sampled)| {
            let (i, j) = c.keys();
            let rho = c.coefficient();
            json!({
                "keys": [mc.dispersions[i].path, mc.dispersions[j].path],
                "coefficient": rho,
                "spearman_expected": 6.0 / std::f64::consts::PI * (rho / 2.0).asin(),
                "spearman_sampled": sampled,
            })
        })
        .collect();
    let verdicts: Vec<Value> = (a.verdicts.iter())
        .map(|v| {
            let q = &v.requirement;
            json!({
                "name": q.name, "output": q.output, "min": q.min, "max": q.max,
                "factor_of_safety": q.factor_of_safety,
                "probability": q.probability, "confidence": q.confidence,
                "runs": v.runs, "failures": v.failures, "failures_allowed": v.allowed,
                "runs_needed": v.runs_needed, "met": v.met,
                "tolerance_bound": v.tolerance_bound,
                "failure_drivers": ranked(&v.drivers),
            })
        })
        .collect();
    let named = |xs: &[(String, Summary)]| -> serde_json::Map<String, Value> {
        xs.iter()
            .map(|(n, s)| (n.clone(), summary_json(s)))
            .collect()
    };
    let worst: Vec<Value> = (margins.iter().enumerate())
        .map(|(h, m)| {
            let least = m.iter().copied().fold(f64::INFINITY, f64::min);
            json!({"hinge": h + 1, "least_margin": least, "meets_100_percent": least >= 1.0})
        })
        .collect();
    let v = json!({
        "hash": info.hash, "seed": info.seed, "runs": info.runs,
        "status": a.status_counts.iter().map(|(s, n)| (s.to_string(), json!(n))).collect::<serde_json::Map<_, _>>(),
        "requirements": verdicts,
        "applied": named(&a.applied),
        "outputs": named(&a.outputs),
        "sensitivity": a.sensitivity.iter().map(|(n, r)| (n.clone(), ranked(r))).collect::<serde_json::Map<_, _>>(),
        "correlations": correlations,
        "torque_margin": worst,
        "notes": {
            "percentiles": "linear interpolation between order statistics (Hyndman & Fan type 7), over the finite values",
            "verdict": "order statistics (Wilks): met when failures ≤ failures_allowed at probability and confidence; a refused or failed run is a failure; with a factor_of_safety the output × factor is compared with max, and tolerance_bound is on that product",
            "sensitivity": "per output: Spearman rank correlation (spearman) of each dispersed parameter with the output, largest |ρ| first, and the standardised rank regression coefficients (srrc) of the fit of the output's ranks on all parameters' ranks, with its R² (rank_regression_r2) over the runs with a value",
            "torque_margin": "static margin k(α_ref − α)/μ − 1 over the travel, worst case over the runs (null: no friction, unbounded)",
        },
    });
    serde_json::to_string_pretty(&v).expect("JSON of plain values") + "\n"
}

/// The terminal table.
pub fn montecarlo_table(info: &ShardInfo, a: &Analysis) -> String {
    let mut s = format!("Monte Carlo: {} runs, seed {}\n", info.runs, info.seed);
    for (st, n) in a.status_counts.iter().filter(|(_, n)| *n > 0) {
        s += &format!("  {st}: {n}\n");
    }
    s += "\noutput                          mean          sd            min           p50           p99           max\n";
    for (n, o) in &a.outputs {
        s += &format!(
            "{n:<30} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13}\n",
            stat(o.mean),
            stat(o.sd),
            stat(o.min),
            stat(o.percentiles[3]),
            stat(o.percentiles[6]),
            stat(o.max)
        );
    }
    s += "\nsensitivity (strongest parameter by |Spearman ρ|; SRRC: standardised rank regression coefficient, R² of the rank model)\n";
    for (n, r) in &a.sensitivity {
        match r.ranking.first().filter(|p| p.spearman.is_finite()) {
            Some(p) => {
                s += &format!(
                    "{n:<30} {:<34} ρ = {:>7}  SRRC = {:>7}  R² = {}\n",
                    p.parameter,
                    three(p.spearman),
                    three(p.srrc),
                    three(r.r2)
                )
            }
            None => s += &format!("{n:<30} – (constant)\n"),
        }
    }
    for v in &a.verdicts {
        let q = &v.requirement;
        s += &format!(
            "\nrequirement \"{}\" ({}{} {}{}, p = {}, c = {}): {} — {} failures in {} runs, {} allowed; {} runs would allow the observed failures\n",
            q.name,
            q.factor_of_safety.map_or(String::new(), |f| format!("{f} × ")),
            q.output,
            q.min.map_or(String::new(), |m| format!("≥ {m} ")),
            q.max.map_or(String::new(), |m| format!("≤ {m}")),
            q.probability,
            q.confidence,
            if v.met { "MET" } else { "NOT MET" },
            v.failures,
            v.runs,
            v.allowed.map_or("none (too few runs)".to_string(), |f| f.to_string()),
            v.runs_needed,
        );
        if let Some(p) = v.drivers.ranking.first().filter(|d| d.spearman.is_finite()) {
            s += &format!(
                "  strongest driver of failures: {} (Spearman ρ = {}, SRRC = {})\n",
                p.parameter,
                three(p.spearman),
                three(p.srrc)
            );
        }
    }
    s
}

/// Text for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A number for the report (4 significant digits; "–" for a missing one).
fn sig(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4e}")
    } else if v.is_nan() {
        "–".into()
    } else {
        format!("{v}")
    }
}

/// report.html: the Monte Carlo section — verdicts, statistics, sensitivity, plots (linked
/// from plots/).
pub fn report(info: &ShardInfo, a: &Analysis, plots: &[String]) -> String {
    let mut h = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Monte Carlo</title>\n\
         <style>body{font-family:sans-serif;max-width:70em;margin:2em auto}td,th{padding:2px 8px;text-align:right}\
         td:first-child,th:first-child{text-align:left}.met{color:#070}.not{color:#b00}</style></head><body>\n",
    );
    h += &format!(
        "<h1>Monte Carlo dispersions</h1>\n<p>{} runs, seed {}; fingerprint <code>{}</code>.</p>\n",
        info.runs, info.seed, info.hash
    );
    h += "<h2>Requirements (order statistics)</h2>\n<table><tr><th>requirement</th><th>output</th><th>bound</th><th>p / c</th><th>failures</th><th>allowed</th><th>runs needed</th><th>tolerance bound</th><th>verdict</th><th>strongest driver</th></tr>\n";
    for v in &a.verdicts {
        let q = &v.requirement;
        let bound = match (q.min, q.max) {
            (Some(lo), Some(hi)) => format!("{lo} … {hi}"),
            (Some(lo), None) => format!("≥ {lo}"),
            (None, Some(hi)) => format!("≤ {hi}"),
            (None, None) => String::new(),
        };
        let bound = match q.factor_of_safety {
            Some(f) => format!("{f} × output {bound}"),
            None => bound,
        };
        let driver = (v.drivers.ranking.first())
            .filter(|d| d.spearman.is_finite())
            .map_or(String::new(), |p| {
                format!(
                    "{} (ρ = {}, SRRC = {})",
                    esc(&p.parameter),
                    three(p.spearman),
                    three(p.srrc)
                )
            });
        h += &format!(
            "<tr><td>{}</td><td>{}</td><td>{bound}</td><td>{} / {}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{}\">{}</td><td>{driver}</td></tr>\n",
            esc(&q.name), esc(&q.output), q.probability, q.confidence, v.failures,
            v.allowed.map_or("none".into(), |f| f.to_string()), v.runs_needed,
            v.tolerance_bound.map_or("–".into(), sig),
            if v.met { "met" } else { "not" }, if v.met { "met" } else { "not met" },
        );
    }
    h += "</table>\n<h2>Outputs</h2>\n<p>Strongest parameter: the largest |Spearman ρ|; SRRC: its standardised rank regression coefficient in the fit of the output's ranks on all parameters' ranks; R²: the share of the rank variance that fit explains (a small R² means the output is not monotone and additive in the parameters, and neither measure tells the whole story).</p>\n<table><tr><th>output</th><th>mean</th><th>sd</th><th>min</th><th>p50</th><th>p99</th><th>max</th><th>strongest parameter</th><th>ρ</th><th>SRRC</th><th>R²</th></tr>\n";
    for ((n, o), (_, rank)) in a.outputs.iter().zip(&a.sensitivity) {
        let (top, rho, srrc) = (rank.ranking.first())
            .filter(|d| d.spearman.is_finite())
            .map_or((String::new(), String::new(), String::new()), |p| {
                (esc(&p.parameter), three(p.spearman), three(p.srrc))
            });
        let r2 = three(rank.r2);
        h += &format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{top}</td><td>{rho}</td><td>{srrc}</td><td>{r2}</td></tr>\n",
            esc(n), sig(o.mean), sig(o.sd), sig(o.min), sig(o.percentiles[3]), sig(o.percentiles[6]), sig(o.max)
        );
    }
    h += "</table>\n<h2>Plots</h2>\n";
    for p in plots {
        h += &format!("<p><img src=\"plots/{p}.svg\" alt=\"{p}\" style=\"max-width:100%\"></p>\n");
    }
    h += "</body></html>\n";
    h
}

/// A file stem for an output name.
fn stem(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// Histogram (as a step line, 30 bins) and empirical CDF of one output's finite values.
fn distribution_plots(
    dir: &mut OutputDir,
    name: &str,
    values: &[f64],
) -> Result<bool, OutputError> {
    let s = crate::montecarlo::stats::sorted(
        &values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect::<Vec<_>>(),
    );
    let (Some(&lo), Some(&hi)) = (s.first(), s.last()) else {
        return Ok(false);
    };
    let n = s.len() as f64;
    let cdf: Vec<(f64, f64)> = (s.iter().enumerate())
        .flat_map(|(i, &x)| [(x, i as f64 / n), (x, (i + 1) as f64 / n)])
        .collect();
    line_chart(
        dir,
        &format!("cdf_{}", stem(name)),
        &format!("{name}: empirical CDF"),
        (name, "fraction of runs"),
        &[(name.to_string(), cdf)],
        false,
    )?;
    let bins = 30;
    let width = if hi > lo {
        (hi - lo) / bins as f64
    } else {
        1.0
    };
    let mut count = vec![0usize; bins];
    for x in &s {
        count[(((x - lo) / width) as usize).min(bins - 1)] += 1;
    }
    let mut hist: Vec<(f64, f64)> = vec![(lo, 0.0)];
    for (b, c) in count.iter().enumerate() {
        let (x0, x1) = (lo + b as f64 * width, lo + (b + 1) as f64 * width);
        hist.extend([(x0, *c as f64), (x1, *c as f64)]);
    }
    hist.push((lo + bins as f64 * width, 0.0));
    line_chart(
        dir,
        &format!("hist_{}", stem(name)),
        &format!("{name}: histogram ({bins} bins)"),
        (name, "runs"),
        &[(name.to_string(), hist)],
        false,
    )?;
    Ok(true)
}

/// plots/torque_margin: every hinge's worst margin over its travel, with the 100 % line.
fn margin_plot(dir: &mut OutputDir, margins: &[Vec<f64>]) -> Result<bool, OutputError> {
    let mut series: Vec<Series> = (margins.iter().enumerate())
        .map(|(h, m)| {
            let pts = (m.iter().enumerate())
                .filter(|(_, v)| v.is_finite())
                .map(|(j, v)| (j as f64 / (MARGIN_POINTS - 1) as f64, 100.0 * v))
                .collect();
            (format!("hinge {}", h + 1), pts)
        })
        .collect();
    if series.iter().all(|s| s.1.is_empty()) {
        return Ok(false); // no friction: unbounded margins
    }
    series.push(("100 %".to_string(), vec![(0.0, 100.0), (1.0, 100.0)]));
    line_chart(
        dir,
        "torque_margin",
        "static torque margin, worst case over the runs",
        ("fraction of the hinge travel", "margin [%]"),
        &series,
        false,
    )?;
    Ok(true)
}

/// A statistic in the terminal's table, "–" where the output has no finite value.
fn stat(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.6e}")
    } else {
        "–".into()
    }
}

/// A correlation or R² to three decimals, "–" where it is undetermined (NaN: a constant
/// parameter, or fewer runs than parameters + 2 for the rank regression).
fn three(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3}")
    } else {
        "–".into()
    }
}

/// Writes a folder: the scenario text, shard.json, runs.csv and torque_margin.csv; when the
/// folder holds every run (one shard of one), also summary.json and the plots (the outputs
/// the requirements name, and final_latch_time). Returns the analysis of complete folders.
pub fn write_montecarlo(
    dir: &mut OutputDir,
    scenario_text: &str,
    info: &ShardInfo,
    mc: &MonteCarlo,
    names: &[String],
    records: &[RunRecord],
    margins: &[Vec<f64>],
) -> Result<Option<Analysis>, OutputError> {
    let runs = runs_csv(mc, names, records)?;
    let margin = margin_csv(margins);
    let bodies: [&[u8]; 3] = [scenario_text.as_bytes(), &runs, margin.as_bytes()];
    let files: Vec<String> = bodies.iter().map(|b| sha256(b)).collect();
    let shard = json!({
        "format": SHARD_FORMAT,
        "hash": info.hash, "seed": info.seed, "runs": info.runs,
        "shard": info.shard, "shards": info.shards,
        "split": "run i belongs to shard i mod shards",
        "files": SEALED.iter().zip(&files).map(|(n, h)| (n.to_string(), json!(h)))
            .collect::<serde_json::Map<String, Value>>(),
        "seal": seal(info, &files),
    });
    dir.write("scenario.toml", scenario_text)?;
    dir.write(
        "shard.json",
        serde_json::to_string_pretty(&shard).expect("plain JSON") + "\n",
    )?;
    dir.write("runs.csv", runs)?;
    dir.write("torque_margin.csv", margin)?;
    if info.shards != 1 {
        return Ok(None);
    }
    let a = analyse(mc, names, records);
    dir.write("summary.json", summary(info, mc, &a, margins))?;
    let mut plotted: Vec<&str> = mc.requirements.iter().map(|q| q.output.as_str()).collect();
    plotted.push("final_latch_time");
    plotted.sort_unstable();
    plotted.dedup();
    let mut stems = Vec::new();
    for name in plotted {
        if let Some(k) = names.iter().position(|n| n == name) {
            let v: Vec<f64> = records.iter().map(|r| r.outputs[k]).collect();
            if distribution_plots(dir, name, &v)? {
                stems.extend([
                    format!("hist_{}", stem(name)),
                    format!("cdf_{}", stem(name)),
                ]);
            }
        }
    }
    if margin_plot(dir, margins)? {
        stems.push("torque_margin".into());
    }
    dir.write("report.html", report(info, &a, &stems))?;
    Ok(Some(a))
}

/// `:LINE` for a line of a file, nothing for the whole file (line 0).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

/// Why shards could not be merged.
#[derive(Debug, Error)]
pub enum MergeError {
    /// A file could not be read.
    #[error("{}: {reason}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A file is not what a shard writes.
    #[error("{}{}: {reason}", path.display(), at_line(*line))]
    Malformed {
        /// The file.
        path: PathBuf,
        /// Its line (1-based; 0: the whole file).
        line: usize,
        /// Why.
        reason: String,
    },
    /// Shards of different analyses, or an incomplete or overlapping set.
    #[error("{}: {reason}", path.display())]
    Mismatch {
        /// The shard folder.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

/// One shard read back.
struct Shard {
    info: ShardInfo,
    text: String,
    records: Vec<RunRecord>,
    margins: Vec<Vec<f64>>,
}

/// A shard's file as bytes: a regular file (a FIFO would block, a device never end) of at
/// most `cap` bytes, checked before it is read.
fn read_capped(path: &Path, cap: u64) -> Result<Vec<u8>, MergeError> {
    use std::io::Read;
    let fail = |reason: String| MergeError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(e.to_string()))?;
    if !meta.is_file() {
        return Err(fail("not a regular file".into()));
    }
    if meta.len() > cap {
        return Err(fail(format!(
            "{} bytes, more than a shard writes (at most {cap})",
            meta.len()
        )));
    }
    let mut body = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(cap + 1).read_to_end(&mut body))
        .map_err(|e| fail(e.to_string()))?;
    if body.len() as u64 > cap {
        return Err(fail(format!("more than {cap} bytes")));
    }
    Ok(body)
}

/// The largest shard.json: a few hundred bytes are written.
const SHARD_JSON_CAP: u64 = 64 << 10;

/// The largest table file of a shard: a quarter of the memory budget (the records are held
/// until the analysis).
fn table_cap() -> u64 {
    crate::scenario::default_memory_budget() / 4
}

fn utf8(path: &Path, body: Vec<u8>) -> Result<String, MergeError> {
    String::from_utf8(body).map_err(|_| MergeError::Malformed {
        path: path.to_path_buf(),
        line: 0,
        reason: "not UTF-8".into(),
    })
}

fn parse_num(s: &str, path: &Path, line: usize) -> Result<f64, MergeError> {
    s.parse().map_err(|_| MergeError::Malformed {
        path: path.to_path_buf(),
        line,
        reason: format!("{s:?} is not a number"),
    })
}

fn read_info(dir: &Path) -> Result<(ShardInfo, Vec<String>), MergeError> {
    let path = dir.join("shard.json");
    let bad = |reason: &str| MergeError::Malformed {
        path: path.clone(),
        line: 0,
        reason: reason.to_string(),
    };
    let text = utf8(&path, read_capped(&path, SHARD_JSON_CAP)?)?;
    let v: Value = serde_json::from_str(&text).map_err(|e| bad(&e.to_string()))?;
    if v["format"].as_str() != Some(SHARD_FORMAT) {
        return Err(bad(&format!(
            "format {} is not {SHARD_FORMAT:?} (a shard of another flexcraft version, or not a shard)",
            v["format"]
        )));
    }
    let u = |k: &str| {
        v[k].as_u64()
            .ok_or_else(|| bad(&format!("no integer {k:?}")))
    };
    let text = |k: &str| {
        v[k].as_str()
            .map(str::to_string)
            .ok_or_else(|| bad(&format!("no {k:?}")))
    };
    let info = ShardInfo {
        hash: text("hash")?,
        seed: u("seed")?,
        runs: u("runs")?,
        shard: u("shard")?,
        shards: u("shards")?,
    };
    let files = SEALED
        .iter()
        .map(|n| {
            v["files"][n]
                .as_str()
                .map(str::to_string)
                .ok_or_else(|| bad(&format!("no hash of {n} under \"files\"")))
        })
        .collect::<Result<Vec<String>, _>>()?;
    if text("seal")? != seal(&info, &files) {
        return Err(bad(
            "its seal does not match its fields: shard.json was edited",
        ));
    }
    Ok((info, files))
}

/// A shard's sealed files, each against the hash recorded when the shard was written, and
/// the fingerprint against the scenario, seed and run count (before any of it is parsed):
/// the files' texts in [`SEALED`] order, the very bytes that were hashed.
fn verify_files(dir: &Path, info: &ShardInfo, files: &[String]) -> Result<Vec<String>, MergeError> {
    let mut texts = Vec::new();
    for (name, want) in SEALED.iter().zip(files) {
        let path = dir.join(name);
        let cap = if *name == "scenario.toml" {
            crate::scenario::MAX_SCENARIO_BYTES
        } else {
            table_cap()
        };
        let body = read_capped(&path, cap)?;
        if sha256(&body) != *want {
            return Err(MergeError::Malformed {
                path,
                line: 0,
                reason: "differs from what the shard wrote (its SHA-256 is not the one in \
                         shard.json): the file was altered"
                    .into(),
            });
        }
        texts.push(utf8(&path, body)?);
    }
    let text = &texts[0];
    let bad = |reason: String| MergeError::Malformed {
        path: dir.join("shard.json"),
        line: 0,
        reason,
    };
    if fingerprint_of(text, info.seed, info.runs) != info.hash {
        return Err(bad(
            "its hash is not that of the scenario, seed and run count: shard.json was edited"
                .into(),
        ));
    }
    if info.runs == 0 || info.runs > crate::scenario::MAX_RUNS {
        return Err(bad(format!(
            "runs {} outside 1…{}",
            info.runs,
            crate::scenario::MAX_RUNS
        )));
    }
    if info.shards == 0 || info.shards > crate::scenario::MAX_RUNS || info.shard >= info.shards {
        return Err(bad(format!(
            "shard {} of {} is not a shard of a split into 1…{} shards",
            info.shard,
            info.shards,
            crate::scenario::MAX_RUNS
        )));
    }
    Ok(texts)
}

fn read_shard(dir: &Path, k_applied: usize, k_out: usize) -> Result<Shard, MergeError> {
    let (info, files) = read_info(dir)?;
    let mut texts = verify_files(dir, &info, &files)?.into_iter();
    let (text, body, mtext) = (
        texts.next().unwrap_or_default(),
        texts.next().unwrap_or_default(),
        texts.next().unwrap_or_default(),
    );
    let path = dir.join("runs.csv");
    let mut rd = csv::Reader::from_reader(body.as_bytes());
    let mut records = Vec::new();
    for (i, row) in rd.records().enumerate() {
        let line = i + 2;
        let bad = |reason: String| MergeError::Malformed {
            path: path.clone(),
            line,
            reason,
        };
        let row = row.map_err(|e| bad(e.to_string()))?;
        if row.len() != 2 + k_applied + k_out {
            return Err(bad(format!(
                "{} columns, the scenario gives {}",
                row.len(),
                2 + k_applied + k_out
            )));
        }
        let nums = (2..row.len())
            .map(|c| parse_num(&row[c], &path, line))
            .collect::<Result<Vec<f64>, _>>()?;
        records.push(RunRecord {
            index: row[0]
                .parse()
                .map_err(|_| bad(format!("run {:?}", &row[0])))?,
            status: RunStatus::from_name(&row[1])
                .ok_or_else(|| bad(format!("status {:?}", &row[1])))?,
            applied: nums[..k_applied].to_vec(),
            outputs: nums[k_applied..].to_vec(),
            margins: Vec::new(),
        });
    }
    let mpath = dir.join("torque_margin.csv");
    let mut margins: Vec<Vec<f64>> = Vec::new();
    for (j, l) in mtext.lines().skip(1).enumerate() {
        let cells: Vec<&str> = l.split(',').skip(1).collect();
        if margins.is_empty() {
            margins = vec![Vec::new(); cells.len()];
        }
        for (h, c) in cells.iter().enumerate() {
            let v = parse_num(c, &mpath, j + 2)?;
            margins
                .get_mut(h)
                .ok_or_else(|| MergeError::Malformed {
                    path: mpath.clone(),
                    line: j + 2,
                    reason: "a ragged row".into(),
                })?
                .push(v);
        }
    }
    Ok(Shard {
        info,
        text,
        records,
        margins,
    })
}

/// Everything a merge writes.
pub struct Merged {
    /// The scenario text.
    pub text: String,
    /// The shard info of the whole (shard 0 of 1).
    pub info: ShardInfo,
    /// The analysis settings (runs from the shards).
    pub mc: MonteCarlo,
    /// Output names.
    pub names: Vec<String>,
    /// Every run, by index.
    pub records: Vec<RunRecord>,
    /// The worst margins.
    pub margins: Vec<Vec<f64>>,
}

/// Reads shard folders and merges them: the same analysis (hash), the same shard count,
/// every shard exactly once.
pub fn merge_shards(dirs: &[PathBuf]) -> Result<Merged, MergeError> {
    let first = dirs.first().ok_or_else(|| MergeError::Mismatch {
        path: PathBuf::from("."),
        reason: "no shard folders given".into(),
    })?;
    let (first_info, files) = read_info(first)?;
    let text = verify_files(first, &first_info, &files)?.swap_remove(0);
    let file = first.join("scenario.toml").display().to_string();
    let s = Scenario::from_toml_str(&text, &file).map_err(|e| MergeError::Malformed {
        path: first.join("scenario.toml"),
        line: e.location.line,
        reason: format!("{}: {}", e.key, e.reason),
    })?;
    let (Some(d), Some(mut mc)) = (s.deployment.as_ref(), s.montecarlo.clone()) else {
        return Err(MergeError::Mismatch {
            path: first.clone(),
            reason: "scenario.toml has no [deployment] and [montecarlo]".into(),
        });
    };
    let names = output_names(&s.structure, d, mc.response);
    mc.runs = first_info.runs;
    // The merge holds every run's record, as the unsharded run would: refused before any
    // other shard is read when they would not fit half the machine's memory.
    let held = crate::montecarlo::records_bytes(&mc, names.len(), d.chain.hinges.len(), mc.runs);
    let budget = crate::scenario::default_memory_budget();
    if held > budget {
        return Err(MergeError::Mismatch {
            path: first.clone(),
            reason: format!(
                "the merged {} runs would hold about {} of records (limit {}, half the \
                 machine's memory): merge on a machine with more memory",
                mc.runs,
                crate::scenario::format_bytes(held),
                crate::scenario::format_bytes(budget)
            ),
        });
    }
    let mut seen = std::collections::BTreeSet::new();
    let mut records = Vec::new();
    let mut curves = Vec::new();
    for dir in dirs {
        let sh = read_shard(dir, mc.dispersions.len(), names.len())?;
        let mismatch = |reason: String| MergeError::Mismatch {
            path: dir.clone(),
            reason,
        };
        if sh.info.hash != first_info.hash || sh.text != text {
            return Err(mismatch(format!(
                "a shard of another analysis (hash {} ≠ {}): the scenario, seed or run count differ",
                sh.info.hash, first_info.hash
            )));
        }
        if sh.info.shards != first_info.shards || sh.info.shard >= sh.info.shards {
            return Err(mismatch(format!(
                "shard {}/{} does not belong to a split into {} shards",
                sh.info.shard, sh.info.shards, first_info.shards
            )));
        }
        if !seen.insert(sh.info.shard) {
            return Err(mismatch(format!("shard {} is given twice", sh.info.shard)));
        }
        if sh.margins.len() != d.chain.hinges.len() {
            return Err(mismatch(
                "torque_margin.csv does not match the hinges".into(),
            ));
        }
        // The runs i ≡ shard (mod shards), counted without a list of them.
        let expected = (sh.info.shard..mc.runs).step_by(sh.info.shards.max(1) as usize);
        if sh.records.iter().map(|r| r.index).ne(expected) {
            return Err(mismatch(format!(
                "runs.csv does not hold exactly the runs of shard {}/{}",
                sh.info.shard, sh.info.shards
            )));
        }
        records.extend(sh.records);
        curves.push(sh.margins);
    }
    if let Some(missing) = (0..first_info.shards).find(|k| !seen.contains(k)) {
        return Err(MergeError::Mismatch {
            path: first.clone(),
            reason: format!("shard {missing} of {} is missing", first_info.shards),
        });
    }
    records.sort_by_key(|r| r.index);
    let margins = worst_margins(d.chain.hinges.len(), &curves);
    Ok(Merged {
        text,
        info: ShardInfo {
            shard: 0,
            shards: 1,
            ..first_info
        },
        mc,
        names,
        records,
        margins,
    })
}
