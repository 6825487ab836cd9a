//! Rayleigh–Ritz synthesis of the deployed structure: assembly of M and K, the generalized
//! eigenproblem, and the modes with their energy shares and effective masses.
//!
//! Determinism: faer is built without its "rayon" feature (Cargo.toml), so its global
//! parallelism is `Par::Seq` and every reduction runs in one fixed order: the modes, and
//! everything computed from them, are bit-for-bit the same whatever the core count or
//! `RAYON_NUM_THREADS`. (A dependent crate that turns faer's "rayon" feature back on would
//! re-enable parallel, thread-count-dependent rounding; the test below guards this crate.)

pub mod assembly;
pub mod eigen;
pub mod modes;
pub mod parallel;
pub mod refine;
pub mod shapes;

pub use assembly::{Element, ElementKind, FieldKind, FieldRange, RitzModel, HUB_DOF};
pub use modes::{HubFixedMode, ModalAnalysis, Mode};

use thiserror::Error;

/// Failures of the linear algebra.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RitzError {
    /// Cholesky of M failed (a massless coordinate or a dependent basis).
    #[error("the mass matrix is not positive definite (first bad pivot at coordinate {pivot})")]
    MassNotPositiveDefinite {
        /// Index of the first non-positive pivot.
        pivot: usize,
    },
    /// The symmetric eigensolver did not converge.
    #[error("the symmetric eigensolver did not converge")]
    EigenNoConvergence,
    /// A mode came out not finite: the structure's masses span more orders of magnitude
    /// than double precision resolves (a 10 km plate on a 4 m boom: 13 decades between the
    /// components' masses, 20 in the mass matrix).
    #[error(
        "a mode came out not finite: the mass matrix spans {decades:.0} orders of magnitude, \
         more than double precision resolves"
    )]
    NotFinite {
        /// log₁₀ of the ratio of the largest to the smallest diagonal mass of the components'
        /// coordinates.
        decades: f64,
    },
}

#[cfg(test)]
mod tests {
    /// faer must run sequentially: parallel reductions round differently on different core
    /// counts, which would break the byte-identical outputs.
    #[test]
    fn faer_runs_sequentially() {
        assert!(matches!(faer::get_global_parallelism(), faer::Par::Seq));
    }
}
