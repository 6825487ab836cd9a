//! Rayleigh–Ritz synthesis of the deployed structure: assembly of M and K, the generalized
//! eigenproblem, and the modes with their energy shares and effective masses.

pub mod assembly;
pub mod eigen;
pub mod modes;
pub mod shapes;

pub use assembly::{Element, ElementBasis, FieldRange, RitzModel, HUB_DOF};
pub use modes::{HubFixedMode, ModalAnalysis, Mode};

use thiserror::Error;

/// Failures of the linear algebra.
#[derive(Debug, Clone, PartialEq, Error)]
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
}
