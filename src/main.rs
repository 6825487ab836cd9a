//! `flexcraft`: the command-line layer over the library. It reads files, prints, picks exit
//! codes; the physics lives in the library.

// No function over 120 lines (clippy.toml), as in the library.
#![warn(clippy::too_many_lines)]

mod mc_cli;

use clap::{Parser, Subcommand};
use flexcraft::deploy::Deployment;
use flexcraft::output::{self, OutputDir};
use flexcraft::scenario::{default_memory_budget, RunParts};
use flexcraft::{ModalAnalysis, RitzModel, Scenario};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// mimalloc instead of the system allocator: the deployment's many short-lived small
/// matrices made glibc's malloc and free about a fifth of a run (docs/montecarlo.md,
/// "Speed"); the numbers do not change.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

const UNITS: &str = "Units: SI throughout — lengths m, masses kg, inertias kg·m², moduli Pa, \
frequencies Hz (and rad/s), angles rad.";

#[derive(Parser)]
#[command(name = "flexcraft", version, about = "Dynamics of flexible spacecraft with deployable solar arrays.", after_help = UNITS)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// What every command takes: the scenario, the output choices and the memory budget.
#[derive(clap::Args)]
struct Common {
    /// Scenario file (TOML, format version 1; see docs/scenario.md; at most 16 MiB).
    scenario: PathBuf,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    json: bool,
    /// Also write the command's files here (listed above). The folder appears whole when the
    /// run is complete, or not at all.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Replace DIR even if it exists and was not written by flexcraft (no .flexcraft-output
    /// marker). DIR is always replaced as a whole, never merged into.
    #[arg(long, requires = "out")]
    force: bool,
    /// Refuse a run whose estimated peak memory exceeds this many bytes (suffixes K, M, G,
    /// T: powers of 1024). Default: half of the memory the process may use (the machine's,
    /// or its control group's limit when lower).
    #[arg(long, value_name = "BYTES", value_parser = parse_bytes)]
    max_memory: Option<u64>,
}

#[derive(Subcommand)]
enum Command {
    /// Natural frequencies and mode shapes of the deployed spacecraft (Rayleigh–Ritz).
    /// --out writes modes.json, frequencies.csv, coefficient and shape CSVs and plots.
    /// With --deployment-sweep K, also the modes of the partly deployed spacecraft at K
    /// states along the simulated deployment (and the stowed and final states):
    /// deployment_modes.csv and plots/deployment_modes.{png,svg}.
    #[command(after_help = UNITS)]
    Modes {
        #[command(flatten)]
        common: Common,
        /// Frequencies at K states evenly spaced in time along the deployment of [deployment]
        /// (1 to 1000), plus the stowed and final states.
        #[arg(long, value_name = "K", value_parser = clap::value_parser!(u16).range(1..=1000))]
        deployment_sweep: Option<u16>,
    },
    /// Deployment of the accordion-folded array in [deployment]: hinge springs, loads,
    /// latching with impact, hub disturbance. --out writes deployment.csv, events.json and
    /// plots.
    #[command(after_help = UNITS)]
    Deploy(#[command(flatten)] Common),
    /// The linear model for control design: modal data, rigid-body mass, participation,
    /// second-order (mechss) and first-order (A, B, C, D) forms with named inputs and
    /// outputs ([export] in the scenario; docs/export.md), and the frequency response.
    /// --out writes model.json, model.npz, model.mat, NASA 42's flex_NAME.txt and
    /// nodes_NAME.txt, frequency_response.csv and plots/bode.{png,svg}.
    #[command(after_help = UNITS)]
    Export(#[command(flatten)] Common),
    /// The whole story: modes of the deployed spacecraft, deployment of the array, hand-over
    /// at the final latch (or once compliant latches have settled) and the latch-excited
    /// vibration, hub drift and attitude motion.
    /// --out writes report.html (one self-contained page), summary.json, modes.json,
    /// deployment.csv, events.json, response.csv, hub.csv (a free hub from release to the end
    /// of the response, inertial axes) and plots.
    #[command(after_help = UNITS)]
    Simulate {
        #[command(flatten)]
        common: Common,
        /// Open DIR/report.html in the default browser when done (needs --out).
        #[arg(long, requires = "out")]
        open: bool,
        /// No progress bar (it is shown only on a terminal, for runs longer than a second).
        #[arg(long, short)]
        quiet: bool,
        /// Exit with status 3, naming the component and the time, when a margin of safety is
        /// negative (beams against `[materials.X] allowable_stress`, latches against
        /// `[deployment.latch] moment_allowable`); the outputs are written first.
        #[arg(long)]
        fail_on_negative_margin: bool,
    },
    /// Monte Carlo dispersions of the deployment ([montecarlo]; docs/montecarlo.md): runs
    /// with dispersed values, requirement verdicts by order statistics, sharding for
    /// clusters (`--shard I/N | auto`, then `montecarlo merge DIR… --out DIR`).
    #[command(after_help = UNITS)]
    Montecarlo(mc_cli::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let done = match cli.command {
        Command::Modes {
            common,
            deployment_sweep,
        } => run_modes(&common, deployment_sweep.map(usize::from)),
        Command::Deploy(c) => run_deploy(&c),
        Command::Export(c) => run_export(&c),
        Command::Simulate {
            common,
            open,
            quiet,
            fail_on_negative_margin,
        } => run_simulate(&common, open, quiet, fail_on_negative_margin),
        Command::Montecarlo(a) => mc_cli::run(&a),
    };
    done.err().unwrap_or(ExitCode::SUCCESS)
}

/// "4G", "512M", "1000000" → bytes (K, M, G, T are powers of 1024).
fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, shift) = match t.chars().last().map(|c| c.to_ascii_uppercase()) {
        Some('K') => (&t[..t.len() - 1], 10),
        Some('M') => (&t[..t.len() - 1], 20),
        Some('G') => (&t[..t.len() - 1], 30),
        Some('T') => (&t[..t.len() - 1], 40),
        _ => (t, 0),
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("not a size: {s:?} (e.g. 4G, 512M, 1000000)"))?;
    let bytes = v * (1u64 << shift) as f64;
    if bytes.is_finite() && bytes >= 1.0 {
        // A limit above what a u64 holds is no limit: saturate (`as` does).
        Ok(bytes as u64)
    } else {
        Err(format!("not a size: {s:?} (e.g. 4G, 512M, 1000000)"))
    }
}

/// Exit statuses: 2 the input was refused (the scenario, a missing section the command
/// needs, or an --out folder that must not be replaced); 1 a numerical failure or an output
/// that could not be written (stdout included); 0 otherwise — an array that does not latch is
/// a result, not an error.
const REFUSED: u8 = 2;
const FAILED: u8 = 1;
/// `simulate --fail-on-negative-margin` found a negative margin of safety.
const NEGATIVE_MARGIN: u8 = 3;

/// Reads and validates the scenario and checks that the run fits the memory budget,
/// reporting a refusal with its location.
fn load(c: &Common, parts: RunParts) -> Result<Scenario, ExitCode> {
    let refuse = |e: flexcraft::scenario::ScenarioError| {
        eprintln!("error: {e}");
        ExitCode::from(REFUSED)
    };
    let s = Scenario::from_file(&c.scenario).map_err(refuse)?;
    s.check_budget_for(c.max_memory.unwrap_or_else(default_memory_budget), parts)
        .map_err(refuse)?;
    Ok(s)
}

/// The `[deployment]` section a command needs.
fn need_deployment<'a>(path: &Path, s: &'a Scenario) -> Result<&'a Deployment, ExitCode> {
    s.deployment.as_ref().ok_or_else(|| {
        eprintln!(
            "error: {}: deployment: the scenario has no [deployment] section (see docs/scenario.md)",
            path.display()
        );
        ExitCode::from(REFUSED)
    })
}

/// A result with a NaN or an infinity is an error naming the quantity, never printed.
fn not_finite(path: &Path, r: Result<(), flexcraft::finite::NonFinite>) -> Result<(), ExitCode> {
    r.map_err(|e| {
        eprintln!("error: {}: {e}", path.display());
        ExitCode::from(FAILED)
    })
}

/// A failed modal solve, reported at the component it is traced to (exit status 2: the
/// scenario's values, not the machine, are the cause).
fn numerical_failure(
    scenario: &Scenario,
    model: &RitzModel,
    e: &flexcraft::ritz::RitzError,
) -> ExitCode {
    let id = model.culprit(e);
    let name = scenario.structure.component_name(id);
    eprintln!(
        "error: {}",
        scenario.locate(
            id,
            format!(
                "{e}; traced to component \"{name}\": check its values against the others \
                 (masses, stiffnesses and sizes that differ by many orders of magnitude)"
            )
        )
    );
    ExitCode::from(REFUSED)
}

/// Checks, locks and stages the output directory before the computation: a target that must
/// not be replaced is refused (exit status 2) before any work is done.
fn prepare(
    out: Option<&Path>,
    force: bool,
    inputs: &[&Path],
) -> Result<Option<OutputDir>, ExitCode> {
    let Some(dir) = out else { return Ok(None) };
    output::refuse_inputs_inside(dir, inputs)
        .and_then(|()| OutputDir::create(dir, force))
        .map(Some)
        .map_err(|e| {
            if e.is_refusal() {
                eprintln!("error: {e}");
                ExitCode::from(REFUSED)
            } else {
                eprintln!("error: writing {}: {e}", dir.display());
                ExitCode::from(FAILED)
            }
        })
}

/// Prints the JSON object or the table, then writes the prepared output directory with
/// `write` and swaps it in whole.
fn finish(
    json: bool,
    json_text: impl FnOnce() -> String,
    table: impl FnOnce() -> String,
    out: Option<(OutputDir, &Path)>,
    write: impl FnOnce(&mut OutputDir) -> Result<(), output::OutputError>,
) -> Result<(), ExitCode> {
    if json {
        emit(&(json_text() + "\n"))?;
    } else {
        emit(&table())?;
    }
    if let Some((mut o, dir)) = out {
        let written = write(&mut o).and_then(|()| o.commit());
        match written {
            Ok(files) if !json => emit(&format!("wrote {} files to {}\n", files, dir.display()))?,
            Ok(_) => {}
            Err(e) => {
                eprintln!("error: writing {}: {e}", dir.display());
                return Err(ExitCode::from(FAILED));
            }
        }
    }
    Ok(())
}

/// The modes along the deployment (`modes --deployment-sweep K`): the coupled deployment
/// of [deployment], then the frozen-configuration modes at K + 2 states.
fn run_sweep(
    c: &Common,
    scenario: &Scenario,
    k: usize,
    count: usize,
) -> Result<Vec<flexcraft::deploy::sweep::SweepState>, ExitCode> {
    let path = c.scenario.as_path();
    let d = need_deployment(path, scenario)?;
    let fail = |e: &dyn std::fmt::Display| {
        eprintln!("error: {}: {e}", path.display());
        ExitCode::from(FAILED)
    };
    let (coupled, run) =
        flexcraft::deploy::simulate_coupled(&scenario.structure, d).map_err(|e| fail(&e))?;
    flexcraft::deploy::sweep::deployment_sweep(&coupled, &run, &coupled.initial_state(), k, count)
        .map_err(|e| fail(&e))
}

fn run_modes(c: &Common, sweep: Option<usize>) -> Result<(), ExitCode> {
    let (path, json, out) = (c.scenario.as_path(), c.json, c.out.as_deref());
    let parts = if sweep.is_some() {
        RunParts::DEPLOY
    } else {
        RunParts::MODES
    };
    let scenario = load(c, parts)?;
    let staged = prepare(out, c.force, &[c.scenario.as_path()])?;
    let model = RitzModel::assemble(&scenario.structure);
    // With an automatic term selection only the modes it aimed at are solved for (the higher
    // ones of such a model are not converged to anything).
    let selection = scenario.term_selection.as_ref();
    let modes =
        ModalAnalysis::compute_selected(&model, selection.map(|s| s.accuracy.modes), selection)
            .map_err(|e| numerical_failure(&scenario, &model, &e))?;
    not_finite(path, flexcraft::finite::check_modes(&modes))?;
    let count = modes.elastic().count().clamp(1, 10);
    let states = match sweep {
        Some(k) => Some(run_sweep(c, &scenario, k, count)?),
        None => None,
    };
    finish(
        json,
        || match &states {
            None => output::modes_json(&model, &modes),
            Some(s) => {
                let mut v: serde_json::Value =
                    serde_json::from_str(&output::modes_json(&model, &modes)).unwrap_or_default();
                v["deployment_sweep"] = output::sweep_json(s);
                serde_json::to_string_pretty(&v).unwrap_or_default()
            }
        },
        || {
            let mut t = output::modes_table(&scenario, &model, &modes);
            if let Some(s) = &states {
                t += &output::sweep_table(s);
            }
            t
        },
        staged.zip(out),
        |d| {
            output::write_modes(d, &model, &modes)?;
            match &states {
                Some(s) => output::write_sweep(d, s),
                None => Ok(()),
            }
        },
    )
}

fn run_export(c: &Common) -> Result<(), ExitCode> {
    use flexcraft::export::ExportModel;
    let (path, json, out) = (c.scenario.as_path(), c.json, c.out.as_deref());
    let scenario = load(c, RunParts::EXPORT)?;
    let staged = prepare(out, c.force, &[c.scenario.as_path()])?;
    let model = RitzModel::assemble(&scenario.structure);
    let wanted = scenario.export_modes();
    let selection = scenario.term_selection.as_ref();
    let modes = ModalAnalysis::compute_selected(&model, wanted, selection)
        .map_err(|e| numerical_failure(&scenario, &model, &e))?;
    not_finite(path, flexcraft::finite::check_modes(&modes))?;
    let available = modes.elastic().count();
    if let Some(w) = wanted.filter(|w| *w > available) {
        eprintln!(
            "warning: {}: export.modes: {w} elastic modes asked for, the model has {available}; \
             all {available} are kept",
            path.display()
        );
    }
    let settings = &scenario.export;
    let ex = ExportModel::build(&model, &modes, settings).map_err(|e| {
        eprintln!("error: {}", scenario.refuse_export_damping(e.to_string()));
        ExitCode::from(REFUSED)
    })?;
    let st = &scenario.structure;
    let body = output::flex_body_name(
        &path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
    );
    finish(
        json,
        || output::export_json(st, &modes, &ex, &settings.transfers),
        || output::export_table(st, &ex, &settings.transfers),
        staged.zip(out),
        |d| {
            output::write_export(
                d,
                &model,
                &body,
                &modes,
                &ex,
                &settings.transfers,
                settings.frequency_range_hz,
                settings.frequency_points,
            )
        },
    )
}

fn run_deploy(c: &Common) -> Result<(), ExitCode> {
    let (path, json, out) = (c.scenario.as_path(), c.json, c.out.as_deref());
    let scenario = load(c, RunParts::DEPLOY)?;
    let d = need_deployment(path, &scenario)?;
    let staged = prepare(out, c.force, &[c.scenario.as_path()])?;
    let progress = Progress::new(false);
    let started = std::time::Instant::now();
    let (coupled, result) =
        flexcraft::deploy::simulate_coupled_observed(&scenario.structure, d, true, &mut |p| {
            deploy_progress(&progress, started, p)
        })
        .map_err(|e| {
            eprintln!("error: {}: {e}", path.display());
            ExitCode::from(FAILED)
        })?;
    progress.done();
    not_finite(path, flexcraft::finite::check_deployment(&result))?;
    finish(
        json,
        || output::deploy_json(&scenario.name, d, &coupled, &result),
        || output::deploy_table(&scenario.name, d, &coupled, &result),
        staged.zip(out),
        |o| output::write_deploy(o, &scenario.name, d, &coupled, &result),
    )
}

fn run_simulate(
    c: &Common,
    open: bool,
    quiet: bool,
    fail_on_negative_margin: bool,
) -> Result<(), ExitCode> {
    use flexcraft::simulation::Simulation;
    let (path, json, out) = (c.scenario.as_path(), c.json, c.out.as_deref());
    let started = std::time::Instant::now();
    let progress = Progress::new(quiet);
    let scenario = load(c, RunParts::SIMULATE)?;
    need_deployment(path, &scenario)?;
    // The report's footer carries the SHA-256 of the text that was parsed (read once).
    let source = scenario.source_text().as_bytes().to_vec();
    let staged = prepare(out, c.force, &[c.scenario.as_path()])?;
    progress.stage(1, "modes, deployment, hand-over, response");
    let sim = Simulation::run(&scenario).map_err(|e| match &e {
        flexcraft::simulation::SimulationError::Ritz(r) => {
            numerical_failure(&scenario, &RitzModel::assemble(&scenario.structure), r)
        }
        _ => {
            eprintln!("error: {}: {e}", path.display());
            ExitCode::from(FAILED)
        }
    })?;
    not_finite(path, flexcraft::finite::check_simulation(&sim))?;
    progress.stage(2, "writing outputs");
    let file_name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    finish(
        json,
        || output::simulate_json(&scenario, &sim),
        || output::simulate_table(&scenario, &sim),
        staged.zip(out),
        |o| output::write_simulate(o, &scenario, &sim, &source, &file_name),
    )?;
    progress.done();
    if !json {
        // Wall time on the terminal only: no file carries it (outputs stay byte-identical).
        eprintln!("done in {:.3} s", started.elapsed().as_secs_f64());
    }
    if let (true, Some(dir)) = (open, out) {
        open_in_browser(&dir.join("report.html"));
    }
    if fail_on_negative_margin {
        let negative: Vec<_> = output::margins::margins(&scenario, &sim)
            .into_iter()
            // A margin that is not a number fails too.
            .filter(|m| m.margin < 0.0 || m.margin.is_nan())
            .collect();
        for m in &negative {
            eprintln!(
                "error: {}: negative margin of safety {:+.3}: {} at t = {:.3} s from release \
                 ({:.4e} {} against {:.4e} {} / FS {})",
                path.display(),
                m.margin,
                m.component,
                m.time,
                m.value,
                m.unit,
                m.allowable,
                m.unit,
                m.factor_of_safety
            );
        }
        if !negative.is_empty() {
            return Err(ExitCode::from(NEGATIVE_MARGIN));
        }
    }
    Ok(())
}

/// The automatic deployment's progress on stderr: its cost before each refinement run that
/// is expected to take more than two seconds (from the evaluations so far and the time they
/// took), and the time reached on the progress bar.
fn deploy_progress(
    progress: &Progress,
    started: std::time::Instant,
    p: flexcraft::deploy::auto::Progress,
) {
    use flexcraft::deploy::auto::{Progress as P, LEVELS};
    match p {
        P::Starting {
            run,
            expected: Some(expected),
            done,
        } => {
            let rate = done as f64 / started.elapsed().as_secs_f64().max(1e-6);
            let seconds = expected as f64 / rate;
            if seconds > 2.0 {
                eprintln!(
                    "deployment: refining the model and the steps (run {run} of at most \
                     {LEVELS}): about {expected} evaluations, {seconds:.0} s"
                );
            }
        }
        P::At { run, t, end } => progress.message(format!(
            "deployment run {run} of at most {LEVELS}: t = {t:.1} of {end} s"
        )),
        _ => {}
    }
}

/// A progress bar on stderr, drawn only on a terminal, only once the run has taken more than
/// a second, and never with --quiet.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
}

impl Progress {
    const STAGES: u64 = 3;

    fn new(quiet: bool) -> Self {
        use std::io::IsTerminal;
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::with_draw_target(
                Some(Self::STAGES),
                indicatif::ProgressDrawTarget::hidden(),
            );
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{elapsed_precise} [{bar:30}] {pos}/{len} {msg}",
            ) {
                b.set_style(style.progress_chars("=> "));
            }
            // Shown only if the run is still going after a second.
            let shown = b.clone();
            std::thread::spawn(move || {
                std::thread::sleep(std::time::Duration::from_secs(1));
                if !shown.is_finished() {
                    shown.set_draw_target(indicatif::ProgressDrawTarget::stderr());
                    shown.enable_steady_tick(std::time::Duration::from_millis(200));
                }
            });
            b
        });
        Self { bar }
    }

    fn stage(&self, k: u64, msg: &'static str) {
        if let Some(b) = &self.bar {
            b.set_position(k);
            b.set_message(msg);
        }
    }

    fn message(&self, msg: String) {
        if let Some(b) = &self.bar {
            b.set_message(msg);
        }
    }

    fn done(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Opens a file with the desktop's default handler; a missing opener is a warning only.
fn open_in_browser(file: &Path) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(target_os = "windows") {
        "explorer"
    } else {
        "xdg-open"
    };
    match std::process::Command::new(opener).arg(file).spawn() {
        Ok(_) => {}
        Err(e) => eprintln!(
            "warning: could not open {} with {opener}: {e}; open it in a browser",
            file.display()
        ),
    }
}

/// Prints to stdout; a closed pipe (`flexcraft modes … | head`) is not an error, any other
/// write error is (exit status 1: `flexcraft simulate --json > /dev/full`).
fn emit(text: &str) -> Result<(), ExitCode> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            eprintln!("error: writing to stdout: {e}");
            Err(ExitCode::from(FAILED))
        }
        _ => Ok(()),
    }
}
