//! Outputs: the terminal table, JSON, CSV files and plots. Everything is deterministic (no
//! time stamps; shortest round-trip float formatting) and written through [`OutputDir`].

mod arrays;
mod atomic;
mod deploy;
mod export;
pub(crate) mod figures;
pub mod flex42;
pub mod hub;
pub mod margins;
mod modes;
mod montecarlo;
mod names;
pub(crate) mod plot;
pub(crate) mod raster;
mod report;
mod simulate;
mod sweep;
#[cfg(test)]
mod tests;
pub(crate) mod view3d;

pub use arrays::{mat_bytes, npz_bytes, ArrayFileError, ArrayValue, NameProblem};
pub use atomic::{refuse_inputs_inside, OutputDir, MARKER};
pub use deploy::{deploy_json, deploy_table, deployment_csv, write_deploy};
pub use export::{export_json, export_table, flex_body_name, write_export};
pub use modes::{modes_json, modes_table, write_modes};
pub use montecarlo::{
    fingerprint, merge_shards, montecarlo_table, write_montecarlo, MergeError, Merged, ShardInfo,
};
pub use names::file_stems;
pub use report::report_html;
pub use simulate::{response_header, simulate_json, simulate_table, write_simulate};
pub use sweep::{sweep_json, sweep_table, write_sweep};

use thiserror::Error;

/// A CSV number: the shortest representation that reads back to the same f64.
fn num(v: f64) -> String {
    format!("{v:e}")
}

/// v for display: exact zero when |v| is at most [`figures::NOISE_FLOOR`] times `scale` (the
/// largest value of that quantity), so that rounding noise reads as the zero it is.
pub(crate) fn snap(v: f64, scale: f64) -> f64 {
    if v.abs() <= figures::NOISE_FLOOR * scale.abs() {
        0.0
    } else {
        v
    }
}

/// v in engineering notation with an SI prefix and four significant digits, for tables a
/// person reads: 8.6954e4 Pa → "86.95 kPa", 1049.3 N·m → "1.049 kN·m", 2.5e-5 m → "25.00 µm".
/// Zero is "0 unit"; a value that is not finite is "–"; beyond the prefixes (1e-12 … 1e12)
/// the mantissa grows or shrinks.
pub(crate) fn engineering(v: f64, unit: &str) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    if v == 0.0 {
        return format!("0 {unit}");
    }
    const PREFIXES: [&str; 9] = ["p", "n", "µ", "m", "", "k", "M", "G", "T"];
    // Four significant digits, decided on the rounded mantissa (9.99996 is "10.00").
    let significant = |x: f64| {
        let f = 10f64.powf(3.0 - x.abs().log10().floor());
        (x * f).round() / f
    };
    let mut g = ((v.abs().log10() / 3.0).floor() as i32).clamp(-4, 4);
    let mut m = significant(v / 10f64.powi(3 * g));
    // 999.96 rounds to 1000: one group up.
    if m.abs() >= 1000.0 && g < 4 {
        g += 1;
        m = significant(v / 10f64.powi(3 * g));
    }
    let decimals = (3 - m.abs().log10().floor() as i32).clamp(0, 3) as usize;
    let text = format!("{m:.decimals$}");
    format!("{text} {}{unit}", PREFIXES[(g + 4) as usize])
}

/// v with `decimals` fixed decimals, never "-0.000…".
pub(crate) fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// Failure to write an output.
#[derive(Debug, Error)]
#[non_exhaustive]
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
    /// An existing, non-empty output folder that flexcraft did not write (no marker file):
    /// replacing it needs `--force`.
    #[error(
        "{}: exists and was not written by flexcraft (no {MARKER} marker); choose another --out or pass --force to replace it",
        dir.display()
    )]
    NotOurs {
        /// The folder, as named by the user.
        dir: std::path::PathBuf,
    },
    /// A target that is never replaced: `/`, the home folder, the current folder, a mount
    /// point, a file.
    #[error("{}: {reason}; choose another --out", dir.display())]
    ForbiddenTarget {
        /// The folder, as named by the user.
        dir: std::path::PathBuf,
        /// Why it is refused.
        reason: String,
    },
    /// A file name that would leave the output folder (absolute, `..`, NUL, …).
    #[error("unsafe output file name \"{name}\": {reason}")]
    UnsafePath {
        /// The name, escaped.
        name: String,
        /// What is wrong with it.
        reason: &'static str,
    },
}

impl OutputError {
    /// True for a refusal of the target the user named (exit status 2), false for a failure
    /// while writing (exit status 1).
    pub fn is_refusal(&self) -> bool {
        matches!(self, Self::NotOurs { .. } | Self::ForbiddenTarget { .. })
    }
}

impl From<OutputError> for std::io::Error {
    fn from(e: OutputError) -> Self {
        match e {
            OutputError::Io(e) => e,
            other => std::io::Error::other(other.to_string()),
        }
    }
}
