//! Outputs: the terminal table, JSON, CSV files and plots. Everything is deterministic (no
//! time stamps; shortest round-trip float formatting) and written through [`OutputDir`].

mod atomic;
mod deploy;
pub mod figures;
mod modes;
mod names;
pub mod plot;
mod report;
mod simulate;

pub use atomic::OutputDir;
pub use deploy::{deploy_json, deploy_table, deploy_warnings, write_deploy};
pub use modes::{modes_json, modes_table, write_modes};
pub use names::file_stems;
pub use report::report_html;
pub use simulate::{simulate_json, simulate_table, write_simulate};

use thiserror::Error;

/// A CSV number: the shortest representation that reads back to the same f64.
fn num(v: f64) -> String {
    format!("{v:e}")
}

/// Failure to write an output.
#[derive(Debug, Error)]
pub enum OutputError {
    /// File-system error.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The plotting back end failed.
    #[error("plot {file}: {reason}")]
    Plot {
        /// The plot file.
        file: String,
        /// What went wrong.
        reason: String,
    },
}

impl From<OutputError> for std::io::Error {
    fn from(e: OutputError) -> Self {
        match e {
            OutputError::Io(e) => e,
            other => std::io::Error::other(other.to_string()),
        }
    }
}
