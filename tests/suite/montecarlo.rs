//! Monte Carlo dispersions (issue 15, docs/montecarlo.md) against independent truths: the
//! closed-form latch time of one spring-driven panel, the exact distributions of the
//! applied values, the published order-statistics sample sizes, and the identity of sharded,
//! merged, multi-threaded and re-run results with the one-machine run.

use super::common::{bin, scratch};
use flexcraft::deploy::simulate_coupled;
use flexcraft::montecarlo::stats::{ks_critical, ks_distance, pearson, rank_regression, spearman};
use flexcraft::montecarlo::{
    analyse, order, output_names, outputs, run_many, Distribution, RunRecord, RunStatus,
};
use flexcraft::Scenario;
use std::path::Path;

/// One 2 m, 10 kg panel on a held hub without beams (a rigid base), hinge spring k preloaded
/// 0.4 rad beyond the latch at π/2, no friction or damping, rigid latch; `extra` is appended
/// (the [montecarlo] section).
fn one_panel(extra: &str) -> String {
    super::common::one_panel("one panel", 10.0, 1e-10, extra)
}

fn parse(src: &str) -> Scenario {
    Scenario::from_toml_str(src, "one.toml").unwrap_or_else(|e| panic!("{e}"))
}

/// t = arccos(1 − α_L/α_ref) / √(k/J) for J α̈ = k (α_ref − α) from rest; with k ~ N(μ, σ²)
/// (t decreasing in k): F_t(x) = P(k ≥ J a²/x²) = 1 − Φ((J a²/x² − μ)/σ), a = arccos(…).
fn latch_time_cdf_matches(runs: u64) {
    let (mu, sigma) = (3.0, 0.3);
    let src = one_panel(&format!(
        "[montecarlo]\nruns = {runs}\nseed = 7\n[montecarlo.dispersions]\n\
         \"deployment.hinge.stiffness\" = {{ normal = [{mu:?}, {sigma:?}] }}\n"
    ));
    let s = parse(&src);
    s.check_dispersions().unwrap();
    let mc = s.montecarlo.clone().unwrap();
    let d = s.deployment.as_ref().unwrap();
    let (c, _) = simulate_coupled(&s.structure, d).unwrap();
    let (p, h) = (&c.chain.panels[0], &c.chain.hinges[0]);
    let j = c.panel_inertia[0][2] + 0.25 * p.mass * p.length * p.length;
    let a = (1.0 - h.latch_angle / h.reference_angle).acos();
    let exact = Distribution::Normal {
        mean: mu,
        sd: sigma,
    };
    let cdf = |x: f64| 1.0 - exact.cdf(j * a * a / (x * x));
    let indices: Vec<u64> = (0..runs).collect();
    let records = run_many(&s, &mc, &indices, &|| ());
    let names = output_names(&s.structure, d, false);
    let k = names.iter().position(|n| n == "latch_time.1").unwrap();
    let t: Vec<f64> = records.iter().map(|r| r.outputs[k]).collect();
    assert!(t.iter().all(|x| x.is_finite()));
    // Each run against its own closed form (the integration is exact to its tolerance) …
    for r in records.iter().take(50) {
        let exact_t = a / (r.applied[0] / j).sqrt();
        assert!(
            (r.outputs[k] - exact_t).abs() < 1e-6 * exact_t,
            "run {}",
            r.index
        );
    }
    // … and the sample's distribution against the exact one.
    let dks = ks_distance(&t, cdf);
    let crit = ks_critical(t.len(), 0.001);
    assert!(
        dks < crit,
        "KS distance {dks} ≥ the 99.9 % critical value {crit}"
    );
}

/// 20 000 runs (about 18 s of CPU: 9 s on 2 cores).
#[test]
fn val_latch_time_distribution_matches_closed_form_20000_runs() {
    latch_time_cdf_matches(20_000);
}

#[test]
fn val_applied_values_follow_their_distributions() {
    let src = one_panel(
        r#"[montecarlo]
runs = 20000
seed = 99
[montecarlo.dispersions]
"deployment.hinge.stiffness" = { normal = [3.0, 0.2] }
"deployment.hinge.damping" = { uniform = [0.0, 0.1] }
"plates.wing.areal_density" = { lognormal = [1.6, 0.1] }
"deployment.hinge.preload_angle" = { normal = [0.4, 0.05], truncate = [0.35, 0.48] }
"deployment.hinge.friction" = { choice = [0.0, 0.001, 0.002], weights = [1.0, 2.0, 1.0] }
"#,
    );
    let s = parse(&src);
    s.check_dispersions().unwrap();
    let mc = s.montecarlo.clone().unwrap();
    let n = 20_000u64;
    let draws: Vec<Vec<f64>> = (0..n).map(|i| mc.draw(i)).collect();
    let crit = ks_critical(n as usize, 0.001);
    for (k, d) in mc.dispersions.iter().enumerate() {
        let x: Vec<f64> = draws.iter().map(|v| v[k]).collect();
        let mean = x.iter().sum::<f64>() / n as f64;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        match &d.distribution {
            Distribution::Choice { values, weights } => {
                let total: f64 = weights.iter().sum();
                for (v, w) in values.iter().zip(weights) {
                    let p = w / total;
                    let f = x.iter().filter(|y| *y == v).count() as f64 / n as f64;
                    let se = (p * (1.0 - p) / n as f64).sqrt();
                    assert!(
                        (f - p).abs() < 4.0 * se,
                        "{}: {v} drawn {f}, p = {p}",
                        d.path
                    );
                }
                assert!(x.iter().all(|y| values.contains(y)));
            }
            dist => {
                let dks = ks_distance(&x, |y| dist.cdf(y));
                assert!(dks < crit, "{}: KS {dks} ≥ {crit}", d.path);
                // Moments against the exact ones (4 standard errors).
                let (m, v) = match *dist {
                    Distribution::Normal { mean, sd } => (mean, sd * sd),
                    Distribution::Uniform { low, high } => {
                        ((low + high) / 2.0, (high - low).powi(2) / 12.0)
                    }
                    Distribution::LogNormal { mu, sigma } => {
                        let s2 = sigma * sigma;
                        (
                            (mu + s2 / 2.0).exp(),
                            (s2.exp() - 1.0) * (2.0 * mu + s2).exp(),
                        )
                    }
                    Distribution::TruncatedNormal {
                        mean,
                        sd,
                        low,
                        high,
                    } => {
                        assert!(x.iter().all(|y| (low..=high).contains(y)), "truncation");
                        // Moments of the truncated normal (Johnson, Kotz & Balakrishnan,
                        // vol. 1, §13.10.1): α, β the standardised bounds, Z = Φ(β) − Φ(α).
                        let phi =
                            |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
                        let (al, be) = ((low - mean) / sd, (high - mean) / sd);
                        let z = flexcraft::montecarlo::distributions::normal_cdf(be)
                            - flexcraft::montecarlo::distributions::normal_cdf(al);
                        let m = mean + sd * (phi(al) - phi(be)) / z;
                        let v = sd
                            * sd
                            * (1.0 + (al * phi(al) - be * phi(be)) / z
                                - ((phi(al) - phi(be)) / z).powi(2));
                        (m, v)
                    }
                    Distribution::Choice { .. } => unreachable!(),
                };
                let se = (v / n as f64).sqrt();
                assert!(
                    (mean - m).abs() < 4.0 * se,
                    "{}: mean {mean} vs {m}",
                    d.path
                );
                assert!(
                    (var / v - 1.0).abs() < 0.05,
                    "{}: variance {var} vs {v}",
                    d.path
                );
            }
        }
    }
    // What is written as applied is what the run's model has (the values reach the model).
    for i in [0, 1, 17] {
        let run = s.with_values(&mc.overrides(i)).unwrap();
        let h = run.deployment.as_ref().unwrap().chain.hinges[0];
        let v = mc.draw(i);
        let at = |p: &str| v[mc.dispersions.iter().position(|d| d.path == p).unwrap()];
        assert_eq!(h.stiffness, at("deployment.hinge.stiffness"));
        assert_eq!(h.damping, at("deployment.hinge.damping"));
        assert_eq!(h.friction, at("deployment.hinge.friction"));
        assert_eq!(
            h.reference_angle,
            h.latch_angle + at("deployment.hinge.preload_angle")
        );
    }
}

/// Wilks's sample sizes, one-sided, as tabulated by Guba, Makai & Pál, "Statistical aspects
/// of best estimate method — I", Reliability Engineering and System Safety 80 (2003)
/// 217–232, table 1 (orders 1–5 at 95 %/95 %: 59, 93, 124, 153, 181; 90 %/90 %: 22, 38,
/// 52), and the first-order 99 %/99 %: 459. 97.5 %/90 % first order is 91
/// (⌈ln 0.1 / ln 0.975⌉ = ⌈90.9⌉); 93 is 95 %/95 % with one failure allowed (equivalently the
/// two-sided first-order 95 %/95 % size).
#[test]
fn val_wilks_sample_sizes_match_the_published_table() {
    for (failures, p, c, n) in [
        (0, 0.95, 0.95, 59),
        (1, 0.95, 0.95, 93),
        (2, 0.95, 0.95, 124),
        (3, 0.95, 0.95, 153),
        (4, 0.95, 0.95, 181),
        (0, 0.90, 0.90, 22),
        (1, 0.90, 0.90, 38),
        (2, 0.90, 0.90, 52),
        (0, 0.99, 0.99, 459),
        (0, 0.975, 0.90, 91),
    ] {
        assert_eq!(order::runs_needed(failures, p, c), n, "{failures} {p} {c}");
        assert_eq!(order::allowed_failures(n, p, c), Some(failures));
        assert_eq!(
            order::allowed_failures(n - 1, p, c),
            failures.checked_sub(1),
            "{n} − 1 runs"
        );
    }
}

/// A small fast Monte Carlo for the CLI tests.
pub fn small(runs: u64, seed: u64) -> String {
    one_panel(&format!(
        r#"[montecarlo]
runs = {runs}
seed = {seed}
[montecarlo.dispersions]
"deployment.hinge.stiffness" = {{ normal = [3.0, 0.3] }}
"deployment.hinge.friction" = {{ uniform = [0.0, 0.02] }}
"plates.wing.areal_density" = {{ normal = [5.0, 0.2], truncate = [4.6, 5.4] }}
[[montecarlo.correlations]]
keys = ["deployment.hinge.stiffness", "plates.wing.areal_density"]
coefficient = 0.5
[[montecarlo.requirements]]
name = "latched within 1.3 s"
output = "final_latch_time"
max = 1.3
probability = 0.9
confidence = 0.9
"#
    ))
}

pub fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

pub fn mc(args: &[&std::ffi::OsStr]) -> std::process::Output {
    let o = bin().arg("montecarlo").args(args).output().unwrap();
    o
}

/// Every file of a folder (relative path → bytes).
pub fn files(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut m = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                m.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    m
}

pub fn ok(o: &std::process::Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn prop_shards_merged_and_thread_counts_equal_the_unsharded_run_byte_for_byte() {
    let dir = scratch("mc_shards");
    let scen = write(&dir, "small.toml", &small(41, 5));
    let whole = dir.join("whole");
    ok(&mc(&[
        scen.as_os_str(),
        "--out".as_ref(),
        whole.as_os_str(),
        "-q".as_ref(),
    ]));
    let reference = files(&whole);
    assert!(reference.contains_key("summary.json") && reference.contains_key("runs.csv"));
    for jobs in ["1", "2", "3"] {
        let o = dir.join(format!("jobs{jobs}"));
        ok(&mc(&[
            scen.as_os_str(),
            "--out".as_ref(),
            o.as_os_str(),
            "--jobs".as_ref(),
            jobs.as_ref(),
        ]));
        assert!(files(&o) == reference, "--jobs {jobs} differs");
    }
    for n in [2u64, 3, 7, 50] {
        let mut shards = Vec::new();
        for i in (0..n).rev() {
            let o = dir.join(format!("n{n}_s{i}"));
            ok(&mc(&[
                scen.as_os_str(),
                "--out".as_ref(),
                o.as_os_str(),
                "--shard".as_ref(),
                format!("{i}/{n}").as_ref(),
            ]));
            shards.push(o);
        }
        let merged = dir.join(format!("merged{n}"));
        let mut args: Vec<&std::ffi::OsStr> = vec!["merge".as_ref()];
        args.extend(shards.iter().map(|s| s.as_os_str()));
        args.extend(["--out".as_ref(), merged.as_os_str()]);
        ok(&mc(&args));
        assert!(files(&merged) == reference, "{n} shards merged differ");
    }
    // Slurm's variables (an array 1…3 of 3) give the same shards as --shard I/N.
    let o = bin()
        .args(["montecarlo".as_ref(), scen.as_os_str(), "--out".as_ref()])
        .arg(dir.join("auto"))
        .args(["--shard", "auto"])
        .env("SLURM_ARRAY_TASK_ID", "3")
        .env("SLURM_ARRAY_TASK_MIN", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "3")
        .output()
        .unwrap();
    ok(&o);
    let manual = dir.join("manual");
    ok(&mc(&[
        scen.as_os_str(),
        "--out".as_ref(),
        manual.as_os_str(),
        "--shard".as_ref(),
        "2/3".as_ref(),
    ]));
    assert!(files(&dir.join("auto")) == files(&manual));
    // AWS Batch's index with --shards N, likewise.
    let o = bin()
        .args(["montecarlo".as_ref(), scen.as_os_str(), "--out".as_ref()])
        .arg(dir.join("aws"))
        .args(["--shard", "auto", "--shards", "3"])
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env("AWS_BATCH_JOB_ARRAY_INDEX", "2")
        .output()
        .unwrap();
    ok(&o);
    assert!(files(&dir.join("aws")) == files(&manual));
}

/// runs.csv rows as (run, values as bit patterns).
fn rows(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(dir.join("runs.csv")).unwrap();
    let mut lines = text.lines();
    // Output columns are "name [unit]": the name alone, as requirements use it.
    let header = (lines.next().unwrap().split(','))
        .map(|h| h.split(" [").next().unwrap().to_string())
        .collect();
    (
        header,
        lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect(),
    )
}

#[test]
fn prop_runs_rerun_from_their_written_scenarios_give_the_same_outputs_bit_for_bit() {
    let dir = scratch("mc_rerun");
    let scen = write(&dir, "small.toml", &small(12, 11));
    let whole = dir.join("whole");
    ok(&mc(&[
        scen.as_os_str(),
        "--out".as_ref(),
        whole.as_os_str(),
    ]));
    let (header, table) = rows(&whole);
    for i in [0usize, 5, 11] {
        let o = dir.join(format!("run{i}"));
        ok(&mc(&[
            scen.as_os_str(),
            "--run".as_ref(),
            i.to_string().as_ref(),
            "--out".as_ref(),
            o.as_os_str(),
        ]));
        for f in [
            "scenario.toml",
            "summary.json",
            "deployment.csv",
            "report.html",
        ] {
            assert!(o.join(f).exists(), "run {i}: {f}");
        }
        let s = Scenario::from_file(&o.join("scenario.toml")).unwrap();
        let d = s.deployment.as_ref().unwrap();
        let (c, r) = simulate_coupled(&s.structure, d).unwrap();
        let out = outputs(&s.structure, d, &c, &r);
        let names = output_names(&s.structure, d, false);
        let row = &table[i];
        assert_eq!(row[0], i.to_string());
        for (name, v) in names.iter().zip(&out) {
            let col = header.iter().position(|h| h == name).unwrap();
            let written: f64 = row[col].parse().unwrap();
            assert!(
                written.to_bits() == v.to_bits() || (written.is_nan() && v.is_nan()),
                "run {i} {name}: {written} written, {v} re-run"
            );
        }
        // The applied values are in the written scenario.
        let k = s.deployment.as_ref().unwrap().chain.hinges[0].stiffness;
        let col = header
            .iter()
            .position(|h| h == "deployment.hinge.stiffness")
            .unwrap();
        assert_eq!(k.to_bits(), row[col].parse::<f64>().unwrap().to_bits());
    }
}

/// A refusal: exit status 2, `file:line:column: key: reason` on stderr, no folder.
fn refused(
    dir: &Path,
    name: &str,
    text: &str,
    extra: &[&str],
    line: Option<usize>,
    key: &str,
    why: &str,
) {
    let scen = write(dir, &format!("{name}.toml"), text);
    let out = dir.join(format!("{name}_out"));
    let o = bin()
        .arg("montecarlo")
        .arg(&scen)
        .arg("--out")
        .arg(&out)
        .args(extra)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert!(err.contains(key), "{name}: no {key:?} in {err}");
    assert!(err.contains(why), "{name}: no {why:?} in {err}");
    if let Some(l) = line {
        let at = format!("{}:{l}:", scen.display());
        assert!(err.contains(&at), "{name}: not located at {at}: {err}");
    }
    assert!(!out.exists(), "{name}: wrote {}", out.display());
}

/// The line of the first occurrence of `needle` (1-based).
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn prop_bad_input_is_located_and_refused_with_nothing_written() {
    let dir = scratch("mc_bad");
    let base = small(10, 1);
    let swap = |from: &str, to: &str| {
        assert!(base.contains(from), "{from}");
        base.replacen(from, to, 1)
    };
    let cases: Vec<(&str, String, &str, &str, &str)> = vec![
        (
            "unknown_path",
            swap(
                "\"deployment.hinge.friction\"",
                "\"deployment.hinge.frction\"",
            ),
            "\"deployment.hinge.frction\"",
            "montecarlo.dispersions.\"deployment.hinge.frction\"",
            "frction",
        ),
        (
            // (in the correlation too, which must name a dispersed key)
            "unknown_component",
            base.replace(
                "\"plates.wing.areal_density\"",
                "\"plates.wong.areal_density\"",
            ),
            "\"plates.wong.areal_density\"",
            "plates.wong",
            "no table of this array has name =",
        ),
        (
            "non_numeric",
            swap("\"deployment.hinge.friction\"", "\"hub.motion\""),
            "\"hub.motion\"",
            "montecarlo.dispersions.\"hub.motion\"",
            "motion",
        ),
        (
            "negative_sd",
            swap("normal = [3.0, 0.3]", "normal = [3.0, -0.3]"),
            "normal = [3.0, -0.3]",
            "deployment.hinge.stiffness",
            "standard deviation must be ≥ 0",
        ),
        (
            "lower_above_upper",
            swap("uniform = [0.0, 0.02]", "uniform = [0.02, 0.0]"),
            "uniform = [0.02, 0.0]",
            "deployment.hinge.friction",
            "must be below the upper bound",
        ),
        (
            "truncation_outside",
            swap("truncate = [4.6, 5.4]", "truncate = [9.0, 10.0]"),
            "truncate = [9.0, 10.0]",
            "plates.wing.areal_density",
            "outside the distribution's support",
        ),
        (
            "unknown_output",
            swap("output = \"final_latch_time\"", "output = \"final_latch\""),
            "output = \"final_latch\"",
            "montecarlo.requirements[0].output",
            "no per-run output is named",
        ),
        (
            "probability",
            swap("probability = 0.9", "probability = 1.0"),
            "probability = 1.0",
            "montecarlo.requirements[0].probability",
            "strictly between 0 and 1",
        ),
        (
            "confidence",
            swap("confidence = 0.9", "confidence = 0.0"),
            "confidence = 0.0",
            "montecarlo.requirements[0].confidence",
            "strictly between 0 and 1",
        ),
        (
            "zero_runs",
            swap("runs = 10", "runs = 0"),
            "runs = 0",
            "montecarlo.runs",
            "from 1 to",
        ),
        (
            "correlation_coefficient",
            swap("coefficient = 0.5", "coefficient = 1.0"),
            "coefficient = 1.0",
            "montecarlo.correlations[0].coefficient",
            "strictly between −1 and 1",
        ),
        (
            "correlation_not_dispersed",
            swap(
                "\"plates.wing.areal_density\"]",
                "\"deployment.hinge.damping\"]",
            ),
            "keys = [",
            "montecarlo.correlations[0].keys",
            "is not dispersed",
        ),
        (
            "correlation_same_key",
            swap(
                "\"plates.wing.areal_density\"]",
                "\"deployment.hinge.stiffness\"]",
            ),
            "keys = [",
            "montecarlo.correlations[0].keys",
            "the same key twice",
        ),
        (
            "correlation_three_keys",
            swap(
                "\"plates.wing.areal_density\"]",
                "\"plates.wing.areal_density\", \"deployment.hinge.friction\"]",
            ),
            "keys = [",
            "montecarlo.correlations[0].keys",
            "exactly two",
        ),
        (
            "correlation_discrete",
            swap("uniform = [0.0, 0.02]", "choice = [0.0, 0.01]").replacen(
                "\"plates.wing.areal_density\"]",
                "\"deployment.hinge.friction\"]",
                1,
            ),
            "keys = [",
            "montecarlo.correlations[0].keys",
            "discrete choice cannot be correlated",
        ),
        (
            "correlation_twice",
            swap(
                "coefficient = 0.5\n",
                "coefficient = 0.5\n[[montecarlo.correlations]]\n\
                 keys = [\"plates.wing.areal_density\", \"deployment.hinge.stiffness\"]\n\
                 coefficient = 0.2\n",
            ),
            "keys = [\"plates.wing.areal_density\"",
            "montecarlo.correlations[1].keys",
            "already correlated by correlations[0]",
        ),
        (
            // ρ(k, ρA) = 0.5 and ρ(k, μ) = 0.8 are a correlation matrix (ρ(ρA, μ) = 0);
            // ρ(ρA, μ) = −0.8 makes it indefinite: refused at that pair.
            "correlation_not_positive_definite",
            swap(
                "coefficient = 0.5\n",
                "coefficient = 0.5\n[[montecarlo.correlations]]\n\
                 keys = [\"deployment.hinge.stiffness\", \"deployment.hinge.friction\"]\n\
                 coefficient = 0.8\n[[montecarlo.correlations]]\n\
                 keys = [\"plates.wing.areal_density\", \"deployment.hinge.friction\"]\n\
                 coefficient = -0.8\n",
            ),
            "coefficient = -0.8",
            "montecarlo.correlations[2].coefficient",
            "not positive definite",
        ),
        (
            "factor_of_safety_below_one",
            swap(
                "confidence = 0.9\n",
                "confidence = 0.9\nfactor_of_safety = 0.8\n",
            ),
            "factor_of_safety = 0.8",
            "montecarlo.requirements[0].factor_of_safety",
            "≥ 1",
        ),
        (
            "factor_of_safety_with_min",
            swap(
                "max = 1.3\n",
                "min = 0.1\nmax = 1.3\nfactor_of_safety = 2.0\n",
            ),
            "factor_of_safety = 2.0",
            "montecarlo.requirements[0].factor_of_safety",
            "applies to a max bound only",
        ),
        (
            "response_without_response_section",
            swap("seed = 1\n", "seed = 1\nresponse = true\n"),
            "response = true",
            "montecarlo.response",
            "need a [response] section",
        ),
        (
            // Every hinge sets its own stiffness: [deployment.hinge] stiffness is unused.
            "unused_key",
            swap(
                "preload_angle = 0.4\n",
                "preload_angle = 0.4\n[[deployment.hinges]]\nstiffness = 3.0\n",
            ),
            "\"deployment.hinge.stiffness\"",
            "montecarlo.dispersions.\"deployment.hinge.stiffness\"",
            "does not use this key",
        ),
    ];
    for (name, text, at, key, why) in cases {
        let line = line_of(&text, at);
        refused(&dir, name, &text, &[], Some(line), key, why);
    }
    refused(
        &dir,
        "shard",
        &base,
        &["--shard", "4/4"],
        None,
        "--shard 4/4",
        "out of range",
    );
    refused(
        &dir,
        "shards",
        &base,
        &["--shard", "1/4", "--shards", "4"],
        None,
        "--shards",
        "goes with --shard auto",
    );
    refused(
        &dir,
        "run",
        &base,
        &["--run", "10"],
        None,
        "--run 10",
        "out of range",
    );
    // Shards of different seeds (or scenarios) are not merged.
    let a = write(&dir, "a.toml", &small(10, 1));
    let b = write(&dir, "b.toml", &small(10, 2));
    let (sa, sb) = (dir.join("sa"), dir.join("sb"));
    ok(&mc(&[
        a.as_os_str(),
        "--out".as_ref(),
        sa.as_os_str(),
        "--shard".as_ref(),
        "0/2".as_ref(),
    ]));
    ok(&mc(&[
        b.as_os_str(),
        "--out".as_ref(),
        sb.as_os_str(),
        "--shard".as_ref(),
        "1/2".as_ref(),
    ]));
    let m = dir.join("m");
    let o = mc(&[
        "merge".as_ref(),
        sa.as_os_str(),
        sb.as_os_str(),
        "--out".as_ref(),
        m.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("another analysis"));
    assert!(!m.exists());
    // An incomplete set is refused too.
    let o = mc(&[
        "merge".as_ref(),
        sa.as_os_str(),
        "--out".as_ref(),
        m.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing"));
    assert!(!m.exists());
}

/// Spearman's ρ_S of a bivariate normal with correlation ρ: (6/π) asin(ρ/2) (Pearson 1907;
/// Kruskal 1958, JASA 53, 814–861, eq. 5.3).
fn spearman_of_normal(rho: f64) -> f64 {
    6.0 / std::f64::consts::PI * (rho / 2.0).asin()
}

/// The standard error of a sample Spearman correlation near ρ_S from n values (Fieller,
/// Hartley & Pearson 1957: var(artanh r_S) ≈ 1.06/(n − 3)).
fn spearman_se(rho_s: f64, n: usize) -> f64 {
    (1.0 - rho_s * rho_s) * (1.06 / (n as f64 - 3.0)).sqrt()
}

#[test]
fn val_correlated_pairs_follow_the_gaussian_copula() {
    let src = one_panel(
        r#"[montecarlo]
runs = 10
seed = 2026
[montecarlo.dispersions]
"deployment.hinge.stiffness" = { normal = [3.0, 0.2] }
"deployment.hinge.damping" = { normal = [0.05, 0.01] }
"deployment.hinge.friction" = { uniform = [0.0, 0.01] }
"plates.wing.areal_density" = { lognormal = [1.6, 0.1] }
"deployment.hinge.preload_angle" = { normal = [0.4, 0.05], truncate = [0.35, 0.48] }
[[montecarlo.correlations]]
keys = ["deployment.hinge.stiffness", "deployment.hinge.damping"]
coefficient = 0.6
[[montecarlo.correlations]]
keys = ["deployment.hinge.friction", "deployment.hinge.stiffness"]
coefficient = -0.5
[[montecarlo.correlations]]
keys = ["plates.wing.areal_density", "deployment.hinge.preload_angle"]
coefficient = 0.7
"#,
    );
    let s = parse(&src);
    s.check_dispersions().unwrap();
    let mc = s.montecarlo.clone().unwrap();
    let n = 200_000usize;
    let draws: Vec<Vec<f64>> = (0..n as u64).map(|i| mc.draw(i)).collect();
    let col = |p: &str| -> Vec<f64> {
        let k = mc.dispersions.iter().position(|d| d.path == p).unwrap();
        draws.iter().map(|v| v[k]).collect()
    };
    let (k, c, mu) = (
        col("deployment.hinge.stiffness"),
        col("deployment.hinge.damping"),
        col("deployment.hinge.friction"),
    );
    let (rho_a, pre) = (
        col("plates.wing.areal_density"),
        col("deployment.hinge.preload_angle"),
    );
    // Two normals: the coefficient is their Pearson correlation (sampling error
    // (1 − ρ²)/√n).
    let r = pearson(&k, &c);
    let se = (1.0 - 0.36) / (n as f64).sqrt();
    assert!((r - 0.6).abs() < 4.0 * se, "Pearson {r} vs 0.6 (se {se})");
    // A normal and a uniform; a lognormal and a truncated normal: Spearman's ρ_S =
    // (6/π) asin(ρ/2), distinguishable from ρ at this n.
    for (x, y, rho) in [(&mu, &k, -0.5), (&rho_a, &pre, 0.7)] {
        let rs = spearman(x, y);
        let expect = spearman_of_normal(rho);
        let se = spearman_se(expect, n);
        assert!(
            (rs - expect).abs() < 4.0 * se,
            "Spearman {rs} vs (6/π)asin(ρ/2) = {expect} (se {se})"
        );
        assert!((rs - rho).abs() > 4.0 * se, "not told apart from ρ = {rho}");
    }
    // Pairs not given stay independent in normal space: damping and friction, ρ_S =
    // (6/π) asin(0/2) = 0.
    let rs = spearman(&c, &mu);
    assert!(rs.abs() < 4.0 * spearman_se(0.0, n), "{rs}");
    // Every marginal keeps its own distribution (KS against the exact CDF) and truncation.
    let crit = ks_critical(n, 0.001);
    for (dk, d) in mc.dispersions.iter().enumerate() {
        let x: Vec<f64> = draws.iter().map(|v| v[dk]).collect();
        let dks = ks_distance(&x, |y| d.distribution.cdf(y));
        assert!(dks < crit, "{}: KS {dks} ≥ {crit}", d.path);
    }
    assert!(pre.iter().all(|p| (0.35..=0.48).contains(p)));
    // summary.json's sampled Spearman of each pair is that of the applied values.
    let records: Vec<RunRecord> = (0..2000)
        .map(|i| RunRecord {
            index: i as u64,
            status: RunStatus::Ok,
            applied: draws[i].clone(),
            outputs: Vec::new(),
            margins: Vec::new(),
        })
        .collect();
    let a = analyse(&mc, &[], &records);
    let pick = |p: &str| -> Vec<f64> {
        let k = mc.dispersions.iter().position(|d| d.path == p).unwrap();
        records.iter().map(|r| r.applied[k]).collect()
    };
    assert_eq!(
        a.correlations[1],
        spearman(
            &pick("deployment.hinge.stiffness"),
            &pick("deployment.hinge.friction")
        )
    );
}

/// y = 3 x₁ + x₂ with x₁, x₂ independent standard normals: y is normal, corr(y, x₁) =
/// 3/√10 and corr(y, x₂) = 1/√10, and ranks are increasing maps of normal values, so the
/// rank regression's population coefficients are Spearman's correlations of bivariate
/// normals (independent regressors: the multiple regression's coefficients are the simple
/// ones): SRRC_i = (6/π) asin(r_i/2), R² = Σ SRRC_i². Their ratio, 3.11, is not the 3 of the
/// regression on the values.
#[test]
fn val_srrc_of_a_linear_model_matches_the_closed_form() {
    let src = one_panel(
        r#"[montecarlo]
runs = 10
seed = 31
[montecarlo.dispersions]
"deployment.hinge.stiffness" = { normal = [0.0, 1.0] }
"deployment.hinge.damping" = { normal = [0.0, 1.0] }
"deployment.hinge.friction" = { uniform = [0.0, 1.0] }
"#,
    );
    let mc = parse(&src).montecarlo.unwrap();
    let n = 100_000u64;
    let at = |p: &str| mc.dispersions.iter().position(|d| d.path == p).unwrap();
    let (i1, i2) = (
        at("deployment.hinge.stiffness"),
        at("deployment.hinge.damping"),
    );
    let records: Vec<RunRecord> = (0..n)
        .map(|i| {
            let x = mc.draw(i);
            let y = 3.0 * x[i1] + x[i2];
            RunRecord {
                index: i,
                status: RunStatus::Ok,
                applied: x,
                // the linear output, and an increasing map of it (same ranks)
                outputs: vec![y, (0.5 * y).exp()],
                margins: Vec::new(),
            }
        })
        .collect();
    let names = vec!["y".to_string(), "exp_y".to_string()];
    let a = analyse(&mc, &names, &records);
    let (s1, s2) = (
        spearman_of_normal(3.0 / 10f64.sqrt()),
        spearman_of_normal(1.0 / 10f64.sqrt()),
    );
    let sens = &a.sensitivity[0].1;
    let get = |p: &str| sens.ranking.iter().find(|r| r.parameter == p).unwrap().srrc;
    let (b1, b2, b3) = (
        get("deployment.hinge.stiffness"),
        get("deployment.hinge.damping"),
        get("deployment.hinge.friction"),
    );
    // Standard error ≈ √((1 − R²)/n) ≈ 4e-4.
    assert!((b1 - s1).abs() < 2e-3, "SRRC x1 {b1} vs {s1}");
    assert!((b2 - s2).abs() < 2e-3, "SRRC x2 {b2} vs {s2}");
    assert!(b3.abs() < 2e-3, "SRRC of the unused parameter {b3}");
    assert!(
        (sens.r2 - (s1 * s1 + s2 * s2)).abs() < 2e-3,
        "R² {}",
        sens.r2
    );
    assert!(((b1 / b2) - s1 / s2).abs() < 0.03 && (b1 / b2 - 3.0).abs() > 0.08);
    assert_eq!(sens.ranking[0].parameter, "deployment.hinge.stiffness");
    assert_eq!(sens.runs, n as usize);
    // Ranks do not see an increasing map: the same coefficients for exp(y/2).
    assert_eq!(a.sensitivity[1].1, a.sensitivity[0].1);
    // The library function agrees with the analysis.
    let xs: Vec<Vec<f64>> = (0..3)
        .map(|k| records.iter().map(|r| r.applied[k]).collect())
        .collect();
    let y: Vec<f64> = records.iter().map(|r| r.outputs[0]).collect();
    assert_eq!(rank_regression(&xs, &y).r2, sens.r2);
}

/// One panel on a held hub, rigid latch: it reaches the latch at ω = √(k/J) √(α_ref² −
/// (α_ref − α_L)²) (energy, from rest at α = 0), and the latch stops it: the hinge carries
/// the angular impulse J ω (its angular momentum about the fixed hinge). Compliant latch
/// (k_L, no damping, the hinge spring acting on): after capture J θ̈ = k p − (k + k_L) θ
/// (θ = α − α_L, p = α_ref − α_L), so the latch moment k_L θ peaks at k_L (θ_e +
/// √(θ_e² + ω²/Ω²)), θ_e = k p/(k + k_L), Ω² = (k + k_L)/J.
#[test]
fn val_latch_loads_and_the_factor_of_safety_match_the_closed_form() {
    let req = |fos: f64, max: f64| {
        format!(
            "[[montecarlo.requirements]]\nname = \"latch load\"\noutput = \"latch_impulse.1\"\n\
             max = {max:?}\nfactor_of_safety = {fos:?}\nprobability = 0.9\nconfidence = 0.9\n"
        )
    };
    let mc_section = |extra: &str| {
        format!(
            "[montecarlo]\nruns = 60\nseed = 3\n[montecarlo.dispersions]\n\
             \"deployment.hinge.stiffness\" = {{ normal = [3.0, 0.3] }}\n{extra}"
        )
    };
    // The panel's J about its hinge, and ω at the latch, for stiffness k.
    let probe = parse(&one_panel(&mc_section("")));
    let d = probe.deployment.as_ref().unwrap();
    let (c, _) = simulate_coupled(&probe.structure, d).unwrap();
    let (p, h) = (&c.chain.panels[0], &c.chain.hinges[0]);
    let j = c.panel_inertia[0][2] + 0.25 * p.mass * p.length * p.length;
    let (a_ref, a_l) = (h.reference_angle, h.latch_angle);
    let omega = |k: f64| (k / j).sqrt() * (a_ref * a_ref - (a_ref - a_l).powi(2)).sqrt();
    // Rigid: the impulse, and a requirement 2 × impulse ≤ max.
    let impulses: Vec<f64> = {
        let s = parse(&one_panel(&mc_section("")));
        let mc = s.montecarlo.clone().unwrap();
        (0..60).map(|i| j * omega(mc.draw(i)[0])).collect()
    };
    let mut sorted = impulses.clone();
    sorted.sort_by(f64::total_cmp);
    // An allowable that twice the median impulse meets: about half the runs fail.
    let max = 2.0 * (sorted[29] + sorted[30]) / 2.0;
    let s = parse(&one_panel(&(mc_section("") + &req(2.0, max))));
    let mc = s.montecarlo.clone().unwrap();
    let d = s.deployment.as_ref().unwrap();
    let names = output_names(&s.structure, d, false);
    let col = names.iter().position(|n| n == "latch_impulse.1").unwrap();
    let records = run_many(&s, &mc, &(0..60).collect::<Vec<_>>(), &|| ());
    for (r, exact) in records.iter().zip(&impulses) {
        assert!(
            (r.outputs[col] - exact).abs() < 1e-6 * exact,
            "run {}: latch impulse {} vs J ω = {exact}",
            r.index,
            r.outputs[col]
        );
    }
    let a = analyse(&mc, &names, &records);
    let v = &a.verdicts[0];
    let expected_failures = impulses.iter().filter(|m| 2.0 * **m > max).count() as u64;
    assert_eq!(v.failures, expected_failures);
    assert_eq!(v.failures, 30);
    // The tolerance bound is on 2 × impulse: the (n − f_allowed)-th smallest of 2 J ω.
    let f = v.allowed.unwrap() as usize;
    let bound = v.tolerance_bound.unwrap();
    assert!((bound - 2.0 * sorted[59 - f]).abs() < 1e-6 * bound);
    // Compliant: the peak latch moment of every run against its closed form.
    let kl = 400.0;
    let s = parse(&one_panel(&mc_section("")).replace(
        "preload_angle = 0.4\n",
        &format!(
            "preload_angle = 0.4\n[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\n\
             damping = 0.0\nsettle_time = 1.0\n"
        ),
    ));
    let mc = s.montecarlo.clone().unwrap();
    let d = s.deployment.as_ref().unwrap();
    let names = output_names(&s.structure, d, false);
    let col = names
        .iter()
        .position(|n| n == "peak_latch_moment.1")
        .unwrap();
    assert!(!names.iter().any(|n| n.starts_with("latch_impulse")));
    for r in run_many(&s, &mc, &(0..12).collect::<Vec<_>>(), &|| ()) {
        let k = r.applied[0];
        let w = omega(k);
        let p = a_ref - a_l;
        let theta_e = k * p / (k + kl);
        let big_omega2 = (k + kl) / j;
        let exact = kl * (theta_e + (theta_e * theta_e + w * w / big_omega2).sqrt());
        assert!(
            (r.outputs[col] - exact).abs() < 1e-5 * exact,
            "run {}: peak latch moment {} vs {exact}",
            r.index,
            r.outputs[col]
        );
    }
}

/// `flexcraft montecarlo` on `text` (its runs.csv as header and rows), and `flexcraft
/// simulate` on the scenario `--run i` writes for run i (its summary.json).
fn mc_and_simulate(
    dir: &Path,
    name: &str,
    text: &str,
    run: usize,
) -> (Vec<String>, Vec<Vec<String>>, serde_json::Value) {
    let scen = write(dir, &format!("{name}.toml"), text);
    let out = dir.join(format!("{name}_mc"));
    ok(&mc(&[
        scen.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "-q".as_ref(),
    ]));
    let (header, table) = rows(&out);
    let one = dir.join(format!("{name}_run{run}"));
    ok(&mc(&[
        scen.as_os_str(),
        "--run".as_ref(),
        run.to_string().as_ref(),
        "--out".as_ref(),
        one.as_os_str(),
    ]));
    let sim = dir.join(format!("{name}_sim{run}"));
    ok(&bin()
        .arg("simulate")
        .arg(one.join("scenario.toml"))
        .arg("--out")
        .arg(&sim)
        .output()
        .unwrap());
    let summary =
        serde_json::from_str(&std::fs::read_to_string(sim.join("summary.json")).unwrap()).unwrap();
    (header, table, summary)
}

/// The per-run response outputs against `flexcraft simulate` (a second code path: the run's
/// written scenario parsed again, its own modal analysis, the full response with every
/// channel, summary.json), on the seed deployment of examples/montecarlo.toml (rigid base)
/// with compliant latches (a rigid latch stops the array on a rigid base: nothing would
/// vibrate; the latch springs' motion at the hand-over does): with deployment keys dispersed
/// only (the runs share the base's modes), and with the wing's areal density dispersed too
/// (each run has its own structure and modes).
#[test]
fn val_response_peak_deflections_equal_the_simulate_summary() {
    let dir = scratch("mc_response");
    let example = std::fs::read_to_string(super::common::example("montecarlo.toml")).unwrap();
    let with = |runs: u64, keep_density: bool, sd: &str| {
        let mut t = example
            .replace("runs = 250 ", &format!("runs = {runs} "))
            .replace("seed = 20261122\n", "seed = 20261122\nresponse = true\n")
            .replace("normal = [1.283, 0.04]", &format!("normal = [1.283, {sd}]"))
            .replace(
                "[montecarlo]\n",
                "[response]\nduration = 4.0\noutput_rate = 50.0\n\n[montecarlo]\n",
            )
            .replace(
                "[deployment.hinge]\n",
                "[deployment.latch]\nmodel = \"compliant\"\nstiffness = 1.0e4\ndamping = 10.0\n\
                 settle_time = 2.0\n\n[deployment.hinge]\n",
            );
        if !keep_density {
            t = t.replace(
                "\"plates.wing.areal_density\" = { lognormal = [2.0794, 0.02] }",
                "",
            );
        }
        assert!(t.contains("response = true") && t.contains(&format!("runs = {runs}")));
        t
    };
    for (name, text, run) in [
        ("deployment_keys", with(1, false, "0.04"), 0),
        ("structure_key", with(2, true, "0.04"), 1),
    ] {
        let (header, table, summary) = mc_and_simulate(&dir, name, &text, run);
        let channels = summary["response"]["channels"].as_array().unwrap();
        // Rounding noise (a deflection that is zero by symmetry) compares against the
        // largest peak.
        let scale = channels
            .iter()
            .filter(|c| c["unit"] == "m")
            .map(|c| c["peak"].as_f64().unwrap())
            .fold(0.0, f64::max);
        for (output, channel) in [
            ("peak_tip_deflection.mast.v", "mast_tip_v"),
            ("peak_tip_deflection.mast.w", "mast_tip_w"),
            ("peak_tip_deflection.wing.minus", "wing_tip_minus"),
            ("peak_tip_deflection.wing.plus", "wing_tip_plus"),
        ] {
            let col = header.iter().position(|h| h == output).unwrap();
            let got: f64 = table[run][col].parse().unwrap();
            let want = channels.iter().find(|c| c["name"] == channel).unwrap()["peak"]
                .as_f64()
                .unwrap();
            assert!(got.is_finite(), "{name}: {output}");
            assert!(
                (got - want).abs() <= 1e-12 * scale,
                "{name}: {output} {got} vs simulate {want}"
            );
        }
        let wing = header
            .iter()
            .position(|h| h == "peak_tip_deflection.wing.plus")
            .unwrap();
        assert!(
            table[run][wing].parse::<f64>().unwrap() > 1e-3,
            "{name}: the wing vibrates"
        );
    }
    // No dispersion (σ = 0, the other keys not dispersed): every run is the same run.
    let text = with(3, false, "0.0")
        .lines()
        .filter(|l| {
            !l.starts_with("\"deployment.hinge.preload_angle\"")
                && !l.starts_with("\"deployment.hinge.friction\"")
        })
        .collect::<Vec<_>>()
        .join("\n");
    let scen = write(&dir, "zero.toml", &text);
    let out = dir.join("zero_mc");
    ok(&mc(&[scen.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    let (header, table) = rows(&out);
    assert!(header.iter().any(|h| h.starts_with("peak_tip_deflection.")));
    assert_eq!(table.len(), 3);
    for row in &table[1..] {
        assert_eq!(row[1..], table[0][1..]);
    }
}

/// A Monte Carlo run skips the periodic samples (`simulate_coupled_with(.., false)`): its
/// outputs equal those of the same run with every sample recorded, except the hinge
/// reactions, which both take from the peaks tracked at every step — so they are at least
/// the largest sampled value, and the sampled maximum approaches them as the sample rate
/// rises (a second route to the same peak: the samples themselves).
#[test]
fn runs_without_samples_give_the_outputs_of_runs_with_them() {
    let text = include_str!("../../examples/seed_staged.toml").replacen(
        "output_rate = 10.0",
        "output_rate = 500.0",
        1,
    );
    assert!(text.contains("output_rate = 500.0"));
    let s = Scenario::from_toml_str(&text, "seed_staged.toml").unwrap();
    let d = s.deployment.as_ref().unwrap();
    let (c, full) = flexcraft::deploy::simulate_coupled_with(&s.structure, d, true).unwrap();
    let (_, lean) = flexcraft::deploy::simulate_coupled_with(&s.structure, d, false).unwrap();
    assert!(lean.samples.len() < 10 && full.samples.len() > 1000);
    let a = outputs(&s.structure, d, &c, &full);
    let b = outputs(&s.structure, d, &c, &lean);
    assert_eq!(
        a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        b.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    let names = output_names(&s.structure, d, false);
    let n = d.chain.hinges.len();
    for h in 0..n {
        let col = |name: String| names.iter().position(|x| *x == name).unwrap();
        let (f, m) = (
            a[col(format!("peak_hinge_force.{}", h + 1))],
            a[col(format!("peak_hinge_moment.{}", h + 1))],
        );
        let fs = (full.samples.iter())
            .map(|x| x.force[h][0].hypot(x.force[h][1]))
            .fold(0.0, f64::max);
        let ms = (full.samples.iter())
            .map(|x| x.moment[h].abs())
            .fold(0.0, f64::max);
        for (tracked, sampled, what) in [(f, fs, "force"), (m, ms, "moment")] {
            assert!(
                tracked >= sampled * (1.0 - 1e-12),
                "hinge {} {what}: {tracked} < {sampled}",
                h + 1
            );
            assert!(
                tracked <= sampled * (1.0 + 1e-4),
                "hinge {} {what}: {tracked} vs {sampled}",
                h + 1
            );
        }
    }
}
