//! Monte Carlo dispersions (issue 15, docs/montecarlo.md) against independent truths: the
//! closed-form latch time of one spring-driven panel, the exact distributions of the
//! applied values, the published order-statistics sample sizes, and the identity of sharded,
//! merged, multi-threaded and re-run results with the one-machine run.

use super::common::{bin, scratch};
use flexcraft::deploy::simulate_coupled;
use flexcraft::montecarlo::stats::{ks_critical, ks_distance};
use flexcraft::montecarlo::{order, output_names, outputs, run_many, Distribution};
use flexcraft::Scenario;
use std::path::Path;

/// One 2 m, 10 kg panel on a held hub without beams (a rigid base), hinge spring k preloaded
/// 0.4 rad beyond the latch at π/2, no friction or damping, rigid latch; `extra` is appended
/// (the [montecarlo] section).
fn one_panel(extra: &str) -> String {
    format!(
        r#"
name = "one panel"
[hub]
motion = "fixed"
mass = 100.0
inertia = [10.0, 10.0, 10.0]
center_of_mass = [0.0, 0.0, 0.0]
[[plates]]
name = "wing"
parent = "hub"
root = [0.5, 0.0, 0.0]
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 2.0
width = 1.0
areal_density = 5.0
bending_stiffness = 1.0e4
poisson_ratio = 0.3
terms = {{ length = 3, width = 2 }}
[deployment]
plate = "wing"
panels = 1
end_time = 20.0
output_rate = 10.0
tolerance = 1e-10
[deployment.hinge]
stiffness = 3.0
preload_angle = 0.4
{extra}
"#
    )
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
    let names = output_names(&s.structure, d);
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
fn small(runs: u64, seed: u64) -> String {
    one_panel(&format!(
        r#"[montecarlo]
runs = {runs}
seed = {seed}
[montecarlo.dispersions]
"deployment.hinge.stiffness" = {{ normal = [3.0, 0.3] }}
"deployment.hinge.friction" = {{ uniform = [0.0, 0.02] }}
"plates.wing.areal_density" = {{ normal = [5.0, 0.2], truncate = [4.6, 5.4] }}
[[montecarlo.requirements]]
name = "latched within 1.3 s"
output = "final_latch_time"
max = 1.3
probability = 0.9
confidence = 0.9
"#
    ))
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn mc(args: &[&std::ffi::OsStr]) -> std::process::Output {
    let o = bin().arg("montecarlo").args(args).output().unwrap();
    o
}

/// Every file of a folder (relative path → bytes).
fn files(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
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

fn ok(o: &std::process::Output) {
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
    let header = lines.next().unwrap().split(',').map(String::from).collect();
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
        let names = output_names(&s.structure, d);
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
            "unknown_component",
            swap(
                "\"plates.wing.areal_density\"",
                "\"plates.wong.areal_density\"",
            ),
            "\"plates.wong.areal_density\"",
            "plates.wong",
            "no element is named",
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
