//! One-dimensional Ritz functions on ξ ∈ [0, 1] and their integrals (docs/theory.md §1.3).
//!
//! A component of length L uses x = Lξ; derivatives here are with respect to ξ and the
//! assembly divides by the powers of L.

pub mod characteristic;
pub mod hinged;
pub mod legendre;
pub mod quadrature;

pub use characteristic::{BeamFunctions, End, RodFunctions};
pub use hinged::Hinged;
pub use legendre::{LegendreBending, LegendreFree, LegendreRod};
pub use quadrature::Quadrature;

use faer::Mat;
use serde::{Deserialize, Serialize};

/// X(ξ) and its first three ξ-derivatives.
pub type Derivs = [f64; 4];

/// Which family of Ritz functions to expand the deformations in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BasisKind {
    /// Integrated Legendre polynomials satisfying the clamped root conditions (default).
    #[default]
    Legendre,
    /// The paper's beam characteristic functions (1.6)–(1.7).
    Characteristic,
}

impl BasisKind {
    /// Lower-case name as in the scenario file.
    pub fn name(self) -> &'static str {
        match self {
            BasisKind::Legendre => "legendre",
            BasisKind::Characteristic => "characteristic",
        }
    }

    /// Bending functions of a beam clamped at ξ = 0 and free at ξ = 1.
    pub fn bending(self, n: usize) -> Box<dyn Basis1d> {
        match self {
            BasisKind::Legendre => Box::new(LegendreBending::new(n)),
            BasisKind::Characteristic => Box::new(BeamFunctions::new(End::Clamped, End::Free, n)),
        }
    }

    /// Axial or torsion functions of a rod clamped at ξ = 0.
    pub fn rod(self, n: usize) -> Box<dyn Basis1d> {
        match self {
            BasisKind::Legendre => Box::new(LegendreRod::new(n)),
            BasisKind::Characteristic => Box::new(RodFunctions::clamped_free(n)),
        }
    }

    /// Free–free functions (across a plate's width), rigid pair included.
    pub fn free_free(self, n: usize) -> Box<dyn Basis1d> {
        match self {
            BasisKind::Legendre => Box::new(LegendreFree::new(n)),
            BasisKind::Characteristic => Box::new(BeamFunctions::new(End::Free, End::Free, n)),
        }
    }
}

/// A finite family of functions on [0, 1].
pub trait Basis1d: std::fmt::Debug + Send + Sync {
    /// Number of functions.
    fn len(&self) -> usize;

    /// True for an empty family.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every function's value and first three ξ-derivatives at ξ, into `out[..len]`.
    fn eval_all(&self, xi: f64, out: &mut [Derivs]);

    /// Highest polynomial degree, for polynomial families (selects an exact Gauss rule).
    fn polynomial_degree(&self) -> Option<usize> {
        None
    }

    /// Largest wavenumber (β or (2n−1)π/2) of a trigonometric family.
    fn max_wavenumber(&self) -> f64 {
        1.0
    }

    /// Every function at ξ, as a vector.
    fn eval_vec(&self, xi: f64) -> Vec<Derivs> {
        let mut out = vec![[0.0; 4]; self.len()];
        self.eval_all(xi, &mut out);
        out
    }

    /// A quadrature rule that integrates products of two functions (and their derivatives)
    /// to rounding: exact Gauss for polynomials; for trigonometric–hyperbolic families, a
    /// composite rule with ≥ 2 twelve-point panels per period of the fastest product.
    fn quadrature(&self) -> Quadrature {
        match self.polynomial_degree() {
            Some(d) => Quadrature::gauss(d + 2),
            None => {
                Quadrature::composite(((self.max_wavenumber() / 3.0).ceil() as usize).max(4), 12)
            }
        }
    }
}

/// The integrals over ξ ∈ [0, 1] that the Ritz assembly needs, for one family φ_i.
#[derive(Debug, Clone)]
pub struct Integrals {
    /// ∫ φ_i φ_j dξ.
    pub i00: Mat<f64>,
    /// ∫ φ_i' φ_j' dξ.
    pub i11: Mat<f64>,
    /// ∫ φ_i'' φ_j'' dξ.
    pub i22: Mat<f64>,
    /// ∫ φ_i'' φ_j dξ.
    pub i20: Mat<f64>,
    /// ∫ φ_i dξ.
    pub m0: Vec<f64>,
    /// ∫ ξ φ_i dξ.
    pub m1: Vec<f64>,
}

impl Integrals {
    /// Computes every integral with the family's own quadrature rule.
    pub fn new(basis: &dyn Basis1d) -> Self {
        let n = basis.len();
        let q = basis.quadrature();
        let mut i00 = Mat::zeros(n, n);
        let mut i11 = Mat::zeros(n, n);
        let mut i22 = Mat::zeros(n, n);
        let mut i20 = Mat::zeros(n, n);
        let mut m0 = vec![0.0; n];
        let mut m1 = vec![0.0; n];
        let mut vals = vec![[0.0; 4]; n];
        for (&x, &w) in q.points.iter().zip(&q.weights) {
            basis.eval_all(x, &mut vals);
            for i in 0..n {
                let vi = vals[i];
                m0[i] += w * vi[0];
                m1[i] += w * x * vi[0];
                for j in 0..n {
                    let vj = vals[j];
                    i00[(i, j)] += w * vi[0] * vj[0];
                    i11[(i, j)] += w * vi[1] * vj[1];
                    i22[(i, j)] += w * vi[2] * vj[2];
                    i20[(i, j)] += w * vi[2] * vj[0];
                }
            }
        }
        let mut this = Self {
            i00,
            i11,
            i22,
            i20,
            m0,
            m1,
        };
        this.clean();
        this
    }

    /// Sets to exactly zero every integral below [`ROUNDING`] of its Cauchy–Schwarz bound
    /// (|∫ f g| ≤ ‖f‖ ‖g‖ on [0, 1], e.g. |∫ φ_i'' φ_j| ≤ √(∫φ_i''² ∫φ_j²)): quadrature
    /// leaves the integrals that vanish exactly — most of them for the Legendre bases, whose
    /// orthogonality makes the matrices banded — at 1e-16 … 1e-14 of the bound. Exact zeros
    /// let the plate's assembly skip them and the eigen-solver keep the matrices sparse.
    fn clean(&mut self) {
        let n = self.i00.nrows();
        let norm = |a: &Mat<f64>, i: usize| a[(i, i)].max(0.0).sqrt();
        let zero = |v: &mut f64, bound: f64| {
            if v.abs() <= ROUNDING * bound {
                *v = 0.0;
            }
        };
        for i in 0..n {
            for j in 0..n {
                let b00 = norm(&self.i00, i) * norm(&self.i00, j);
                let b11 = norm(&self.i11, i) * norm(&self.i11, j);
                let b22 = norm(&self.i22, i) * norm(&self.i22, j);
                let b20 = norm(&self.i22, i) * norm(&self.i00, j);
                zero(&mut self.i00[(i, j)], b00);
                zero(&mut self.i11[(i, j)], b11);
                zero(&mut self.i22[(i, j)], b22);
                zero(&mut self.i20[(i, j)], b20);
            }
            let b = norm(&self.i00, i);
            zero(&mut self.m0[i], b);
            zero(&mut self.m1[i], b);
        }
    }
}

/// Relative size below which an integral is quadrature rounding of an exact zero
/// (`Integrals::clean`).
pub const ROUNDING: f64 = 1e-13;
