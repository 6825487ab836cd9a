//! `flexcraft montecarlo`: the command-line edge of the Monte Carlo analysis
//! (docs/montecarlo.md). Reads the scenario, picks the runs of the shard, runs them on a
//! rayon pool, writes the folder; `merge` combines shard folders.

use super::{emit, prepare, FAILED, REFUSED};
use flexcraft::montecarlo::{output_names, run_many, worst_margins, MonteCarlo};
use flexcraft::output::{self, ShardInfo};
use flexcraft::Scenario;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `flexcraft montecarlo …`.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    merge: Option<Sub>,
    /// Scenario file with [deployment] and [montecarlo].
    #[arg(required = true)]
    scenario: Option<PathBuf>,
    /// Output folder (runs.csv, summary.json, plots, …; docs/montecarlo.md).
    #[arg(long, value_name = "DIR", required = true)]
    out: Option<PathBuf>,
    /// Replace DIR even if flexcraft did not write it.
    #[arg(long)]
    force: bool,
    /// Number of runs (overrides [montecarlo] runs).
    #[arg(long, value_name = "N")]
    runs: Option<u64>,
    /// Threads (default: every core; at most 4 × the cores).
    #[arg(long, value_name = "J")]
    jobs: Option<usize>,
    /// Run only shard I of N (0-based; runs i ≡ I mod N), or `auto`: from Slurm's
    /// SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT, or AWS Batch's AWS_BATCH_JOB_ARRAY_INDEX
    /// with --shards N.
    #[arg(long, value_name = "I/N|auto", conflicts_with = "run")]
    shard: Option<String>,
    /// The shard count for `--shard auto` under AWS Batch.
    #[arg(long, value_name = "N")]
    shards: Option<u64>,
    /// Write run I alone: its full scenario (scenario.toml, with the applied values) and its
    /// complete `simulate` outputs.
    #[arg(long, value_name = "I")]
    run: Option<u64>,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(clap::Subcommand)]
enum Sub {
    /// Merge shard folders into the folder the unsharded run writes (byte-identical).
    Merge {
        /// The shard folders.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// The merged folder.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Replace DIR even if flexcraft did not write it.
        #[arg(long)]
        force: bool,
    },
}

fn refuse(msg: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::from(REFUSED)
}

/// `I/N` → (I, N), 0 ≤ I < N.
fn parse_shard(s: &str) -> Result<(u64, u64), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("--shard {s}: expected I/N (e.g. 0/4) or auto"))?;
    let (i, n): (u64, u64) = match (i.trim().parse(), n.trim().parse()) {
        (Ok(i), Ok(n)) => (i, n),
        _ => return Err(format!("--shard {s}: expected integers I/N (e.g. 0/4)")),
    };
    check_shard(i, n, &format!("--shard {s}"))
}

fn check_shard(i: u64, n: u64, what: &str) -> Result<(u64, u64), String> {
    if n == 0 || i >= n {
        Err(format!(
            "{what}: shard index {i} is out of range 0…{} (shards count from 0)",
            n.max(1) - 1
        ))
    } else if n > flexcraft::scenario::MAX_RUNS {
        Err(format!(
            "{what}: at most {} shards (the cap on runs)",
            flexcraft::scenario::MAX_RUNS
        ))
    } else {
        Ok((i, n))
    }
}

/// `--shard auto`: Slurm's array variables, or AWS Batch's index with --shards.
fn auto_shard(shards: Option<u64>) -> Result<(u64, u64), String> {
    let var = |k: &str| std::env::var(k).ok();
    let int = |k: &str, v: String| {
        v.trim()
            .parse::<u64>()
            .map_err(|_| format!("--shard auto: {k}={v:?} is not an integer"))
    };
    if let Some(id) = var("SLURM_ARRAY_TASK_ID") {
        let id = int("SLURM_ARRAY_TASK_ID", id)?;
        let count = var("SLURM_ARRAY_TASK_COUNT")
            .ok_or("--shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not")?;
        let count = int("SLURM_ARRAY_TASK_COUNT", count)?;
        let min = var("SLURM_ARRAY_TASK_MIN").map_or(Ok(0), |m| int("SLURM_ARRAY_TASK_MIN", m))?;
        if id < min {
            return Err(format!(
                "--shard auto (Slurm): SLURM_ARRAY_TASK_ID={id} is below SLURM_ARRAY_TASK_MIN={min}"
            ));
        }
        return check_shard(id - min, count, "--shard auto (Slurm)");
    }
    if let Some(idx) = var("AWS_BATCH_JOB_ARRAY_INDEX") {
        let idx = int("AWS_BATCH_JOB_ARRAY_INDEX", idx)?;
        let n = shards.ok_or("--shard auto under AWS Batch needs --shards N (the array size)")?;
        return check_shard(idx, n, "--shard auto (AWS Batch)");
    }
    Err("--shard auto: neither SLURM_ARRAY_TASK_ID nor AWS_BATCH_JOB_ARRAY_INDEX is set".into())
}

/// The scenario with its checked [montecarlo] section.
fn load(path: &Path, runs: Option<u64>) -> Result<(Scenario, MonteCarlo), ExitCode> {
    let s = Scenario::from_file(path).map_err(refuse)?;
    if s.deployment.is_none() {
        return Err(refuse(format!(
            "{}: deployment: the scenario has no [deployment] section (see docs/scenario.md)",
            path.display()
        )));
    }
    let Some(mut mc) = s.montecarlo.clone() else {
        return Err(refuse(format!(
            "{}: montecarlo: the scenario has no [montecarlo] section (see docs/montecarlo.md)",
            path.display()
        )));
    };
    s.check_dispersions().map_err(refuse)?;
    if let Some(n) = runs {
        if !(1..=flexcraft::scenario::MAX_RUNS).contains(&n) {
            return Err(refuse(format!(
                "--runs {n}: must be from 1 to {} (the scenario's cap)",
                flexcraft::scenario::MAX_RUNS
            )));
        }
        mc.runs = n;
    }
    Ok((s, mc))
}

/// A progress bar over the runs on stderr (a terminal only, not with --quiet).
fn bar(total: u64, quiet: bool) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let b = indicatif::ProgressBar::new(total);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{elapsed_precise} [{bar:30}] {pos}/{len} runs, eta {eta}",
    ) {
        b.set_style(style.progress_chars("=> "));
    }
    b
}

/// The most threads `--jobs` may ask for, per core this process may use: the runs are CPU
/// bound, more threads only cost memory (each holds a run's model).
const JOBS_PER_CORE: usize = 4;

pub fn run(a: &Args) -> Result<(), ExitCode> {
    if let Some(Sub::Merge { dirs, out, force }) = &a.merge {
        return merge(dirs, out, *force);
    }
    let (path, out) = (
        a.scenario.as_deref().expect("required"),
        a.out.as_deref().expect("required"),
    );
    let (s, mc) = load(path, a.runs)?;
    if let Some(i) = a.run {
        return one_run(path, &s, &mc, i, out, a.force);
    }
    if a.shards.is_some() && a.shard.as_deref() != Some("auto") {
        return Err(refuse(
            "--shards N goes with --shard auto (the array size under AWS Batch); with --shard I/N the count is N",
        ));
    }
    let (shard, shards) = match a.shard.as_deref() {
        None => (0, 1),
        Some("auto") => auto_shard(a.shards).map_err(refuse)?,
        Some(x) => parse_shard(x).map_err(refuse)?,
    };
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(j) = a.jobs {
        let cores = std::thread::available_parallelism().map_or(1, usize::from);
        if !(1..=JOBS_PER_CORE * cores).contains(&j) {
            return Err(refuse(format!(
                "--jobs {j}: from 1 to {} ({JOBS_PER_CORE} × the {cores} cores this process may use)",
                JOBS_PER_CORE * cores
            )));
        }
        pool = pool.num_threads(j);
    }
    // The records of every run of the shard are held until the analysis: refused before the
    // runs start when they would not fit.
    let d = s.deployment.as_ref().expect("checked");
    let runs_here = mc.runs / shards + u64::from(shard < mc.runs % shards);
    let names = output_names(&s.structure, d, mc.response);
    let held =
        flexcraft::montecarlo::records_bytes(&mc, names.len(), d.chain.hinges.len(), runs_here);
    let budget = flexcraft::scenario::default_memory_budget();
    if held > budget {
        return Err(refuse(format!(
            "{}: {runs_here} runs would hold about {} of records (limit {}, half the machine's \
             memory): split them into shards (--shard I/N, merged after) or run fewer",
            path.display(),
            flexcraft::scenario::format_bytes(held),
            flexcraft::scenario::format_bytes(budget)
        )));
    }
    let staged = prepare(Some(out), a.force, &[path])?.expect("an output folder");
    let pool = pool.build().map_err(|e| {
        eprintln!("error: starting the threads: {e}");
        ExitCode::from(FAILED)
    })?;
    let indices = mc.shard_runs(shard, shards);
    let progress = bar(indices.len() as u64, a.quiet);
    let records = pool.install(|| run_many(&s, &mc, &indices, &|| progress.inc(1)));
    progress.finish_and_clear();
    let margins = worst_margins(d.chain.hinges.len(), records.iter().map(|r| &r.margins));
    let info = ShardInfo {
        hash: output::fingerprint(s.source_text(), &mc),
        seed: mc.seed,
        runs: mc.runs,
        shard,
        shards,
    };
    write(
        staged,
        out,
        s.source_text(),
        &info,
        &mc,
        &names,
        &records,
        &margins,
    )
}

#[allow(clippy::too_many_arguments)]
fn write(
    mut staged: output::OutputDir,
    out: &Path,
    text: &str,
    info: &ShardInfo,
    mc: &MonteCarlo,
    names: &[String],
    records: &[flexcraft::montecarlo::RunRecord],
    margins: &[Vec<f64>],
) -> Result<(), ExitCode> {
    let written = output::write_montecarlo(&mut staged, text, info, mc, names, records, margins)
        .and_then(|a| staged.commit().map(|n| (a, n)));
    match written {
        Ok((a, n)) => {
            if let Some(a) = a {
                emit(&output::montecarlo_table(info, &a))?;
            } else {
                emit(&format!(
                    "shard {}/{}: {} runs\n",
                    info.shard,
                    info.shards,
                    records.len()
                ))?;
            }
            emit(&format!("wrote {n} files to {}\n", out.display()))
        }
        Err(e) => {
            eprintln!("error: writing {}: {e}", out.display());
            Err(ExitCode::from(FAILED))
        }
    }
}

/// `merge DIR… --out DIR`.
fn merge(dirs: &[PathBuf], out: &Path, force: bool) -> Result<(), ExitCode> {
    let m = output::merge_shards(dirs).map_err(refuse)?;
    let inputs: Vec<&Path> = dirs.iter().map(PathBuf::as_path).collect();
    let staged = prepare(Some(out), force, &inputs)?.expect("an output folder");
    write(
        staged, out, &m.text, &m.info, &m.mc, &m.names, &m.records, &m.margins,
    )
}

/// `--run I`: run I's scenario and its complete simulate outputs.
fn one_run(
    path: &Path,
    s: &Scenario,
    mc: &MonteCarlo,
    i: u64,
    out: &Path,
    force: bool,
) -> Result<(), ExitCode> {
    if i >= mc.runs {
        return Err(refuse(format!(
            "--run {i}: out of range 0…{} (runs count from 0)",
            mc.runs - 1
        )));
    }
    let text = mc
        .run_text(s, i)
        .map_err(|(p, why)| refuse(format!("{}: run {i}: {p}: {why}", path.display())))?;
    let file = format!("{} (run {i})", path.display());
    let run = Scenario::from_toml_str(&text, &file).map_err(|e| {
        refuse(format!(
            "run {i}: its applied values are refused: {}: {}",
            e.key, e.reason
        ))
    })?;
    let mut staged = prepare(Some(out), force, &[path])?.expect("an output folder");
    let sim = flexcraft::simulation::Simulation::run(&run).map_err(|e| {
        eprintln!("error: {file}: {e}");
        ExitCode::from(FAILED)
    })?;
    let name = format!("run{i}.toml");
    let written = staged
        .write("scenario.toml", &text)
        .and_then(|()| output::write_simulate(&mut staged, &run, &sim, text.as_bytes(), &name))
        .and_then(|()| staged.commit());
    match written {
        Ok(n) => {
            emit(&output::simulate_table(&run, &sim))?;
            emit(&format!("wrote {n} files to {}\n", out.display()))
        }
        Err(e) => {
            eprintln!("error: writing {}: {e}", out.display());
            Err(ExitCode::from(FAILED))
        }
    }
}
