//! `flexcraft`: the command-line layer over the library. It reads files, prints, picks exit
//! codes; the physics lives in the library.

use clap::{Parser, Subcommand};
use flexcraft::output::{self, OutputDir};
use flexcraft::{ModalAnalysis, RitzModel, Scenario};
use std::path::PathBuf;
use std::process::ExitCode;

const UNITS: &str = "Units: SI throughout — lengths m, masses kg, inertias kg·m², moduli Pa, \
frequencies Hz (and rad/s), angles rad.";

#[derive(Parser)]
#[command(name = "flexcraft", version, about = "Dynamics of flexible spacecraft with deployable solar arrays.", after_help = UNITS)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Natural frequencies and mode shapes of the deployed spacecraft (Rayleigh–Ritz).
    #[command(after_help = UNITS)]
    Modes {
        /// Scenario file (TOML, format version 1; see docs/scenario.md).
        scenario: PathBuf,
        /// Print one JSON object on stdout instead of the table.
        #[arg(long)]
        json: bool,
        /// Also write modes.json, frequencies.csv, coefficient and shape CSVs and plots here.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Deployment of the accordion-folded array in [deployment]: hinge springs, loads,
    /// latching with impact, hub disturbance.
    #[command(after_help = UNITS)]
    Deploy {
        /// Scenario file (TOML, format version 1, with a [deployment] section).
        scenario: PathBuf,
        /// Print one JSON object on stdout instead of the event table.
        #[arg(long)]
        json: bool,
        /// Also write deployment.csv, events.json and plots here.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// The whole story: modes of the deployed spacecraft, deployment of the array, hand-over
    /// at the final latch and the latch-excited vibration, hub drift and attitude motion.
    #[command(after_help = UNITS)]
    Simulate {
        /// Scenario file (TOML, format version 1, with [deployment] and optionally [response]).
        scenario: PathBuf,
        /// Print summary.json on stdout instead of the summary table.
        #[arg(long)]
        json: bool,
        /// Also write summary.json, modes.json, deployment.csv, events.json, response.csv and
        /// plots here.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Modes {
            scenario,
            json,
            out,
        } => run_modes(&scenario, json, out.as_deref()),
        Command::Deploy {
            scenario,
            json,
            out,
        } => run_deploy(&scenario, json, out.as_deref()),
        Command::Simulate {
            scenario,
            json,
            out,
        } => run_simulate(&scenario, json, out.as_deref()),
    }
}

/// Exit status 2: the input was refused. 1: an output could not be written or a numerical
/// failure.
fn run_modes(path: &std::path::Path, json: bool, out: Option<&std::path::Path>) -> ExitCode {
    let scenario = match Scenario::from_file(path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let model = RitzModel::assemble(&scenario.structure);
    let modes = match ModalAnalysis::compute(&model) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            return ExitCode::from(1);
        }
    };
    if json {
        emit(&(output::modes_json(&model, &modes) + "\n"));
    } else {
        emit(&output::modes_table(&scenario, &model, &modes));
    }
    if let Some(dir) = out {
        let written = OutputDir::create(dir).and_then(|mut d| {
            output::write_modes(&mut d, &model, &modes)?;
            d.commit()
        });
        match written {
            Ok(files) => {
                if !json {
                    println!("wrote {} files to {}", files, dir.display());
                }
            }
            Err(e) => {
                eprintln!("error: writing {}: {e}", dir.display());
                return ExitCode::from(1);
            }
        }
    }
    ExitCode::SUCCESS
}

/// `flexcraft deploy`: exit 2 on a refused scenario (or one without [deployment]), 1 when an
/// output cannot be written; an array that does not latch is a result, not an error (0).
fn run_deploy(path: &std::path::Path, json: bool, out: Option<&std::path::Path>) -> ExitCode {
    let scenario = match Scenario::from_file(path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let Some(d) = &scenario.deployment else {
        eprintln!(
            "error: {}: deployment: the scenario has no [deployment] section (see docs/scenario.md)",
            path.display()
        );
        return ExitCode::from(2);
    };
    let result = flexcraft::deploy::simulate(d);
    if json {
        emit(&(output::deploy_json(&scenario.name, d, &result) + "\n"));
    } else {
        emit(&output::deploy_table(&scenario.name, d, &result));
    }
    if let Some(dir) = out {
        let written = OutputDir::create(dir).and_then(|mut o| {
            output::write_deploy(&mut o, &scenario.name, d, &result)?;
            o.commit()
        });
        match written {
            Ok(files) => {
                if !json {
                    emit(&format!("wrote {} files to {}\n", files, dir.display()));
                }
            }
            Err(e) => {
                eprintln!("error: writing {}: {e}", dir.display());
                return ExitCode::from(1);
            }
        }
    }
    ExitCode::SUCCESS
}

/// `flexcraft simulate`: exit 2 on a refused scenario (or one without [deployment]), 1 on a
/// numerical failure or an unwritable output; an array that does not latch is reported
/// (no response) with exit status 0, as in `deploy`.
fn run_simulate(path: &std::path::Path, json: bool, out: Option<&std::path::Path>) -> ExitCode {
    use flexcraft::simulation::{Simulation, SimulationError};
    let started = std::time::Instant::now();
    let scenario = match Scenario::from_file(path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let sim = match Simulation::run(&scenario) {
        Ok(s) => s,
        Err(SimulationError::NoDeployment) => {
            eprintln!(
                "error: {}: deployment: the scenario has no [deployment] section (see docs/scenario.md)",
                path.display()
            );
            return ExitCode::from(2);
        }
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            return ExitCode::from(1);
        }
    };
    if json {
        emit(&(output::simulate_json(&scenario, &sim) + "\n"));
    } else {
        emit(&output::simulate_table(&scenario, &sim));
    }
    if let Some(dir) = out {
        let written = OutputDir::create(dir).and_then(|mut o| {
            output::write_simulate(&mut o, &scenario, &sim)?;
            o.commit()
        });
        match written {
            Ok(files) => {
                if !json {
                    emit(&format!("wrote {} files to {}\n", files, dir.display()));
                }
            }
            Err(e) => {
                eprintln!("error: writing {}: {e}", dir.display());
                return ExitCode::from(1);
            }
        }
    }
    if !json {
        // Wall time on the terminal only: no file carries it (outputs stay byte-identical).
        eprintln!("done in {:.3} s", started.elapsed().as_secs_f64());
    }
    ExitCode::SUCCESS
}

/// Prints to stdout; a closed pipe (`flexcraft modes … | head`) is not an error.
fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|()| out.flush());
}
