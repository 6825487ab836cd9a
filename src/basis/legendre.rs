//! Polynomial Ritz bases built from Legendre polynomials (the default basis, docs/theory.md §1).
//!
//! With t = 2ξ − 1 ∈ [−1, 1]:
//! * bending, clamped at ξ = 0: ψ_k = c_k Q_k(t), Q_k'' = P_k, Q_k(−1) = Q_k'(−1) = 0
//!   (twice-integrated Legendre polynomials, the hierarchical p-FEM shape functions);
//!   c_k = √(2k+1)/4 makes ∫₀¹ ψ_i'' ψ_j'' dξ = δ_ij, so a uniform beam's stiffness is diagonal.
//! * rod (axial, torsion), clamped at ξ = 0: φ_k = c_k R_k(t), R_k' = P_k, R_k(−1) = 0,
//!   c_k = √(2k+1)/2 so that ∫₀¹ φ_i' φ_j' dξ = δ_ij.
//! * free–free (across a plate's width): √(2k+1) P_k(t), orthonormal on [0, 1].
//!
//! The first n functions of each family span every polynomial of the family's degree that
//! satisfies the root conditions, so the Ritz frequencies decrease monotonically with n.

use super::{Basis1d, Derivs};

/// Legendre polynomials and their first three derivatives at t, for k = 0..=n.
pub(crate) fn legendre_table(n: usize, t: f64) -> Vec<[f64; 4]> {
    let mut p = vec![[0.0; 4]; n + 1];
    p[0] = [1.0, 0.0, 0.0, 0.0];
    if n >= 1 {
        p[1] = [t, 1.0, 0.0, 0.0];
    }
    for k in 1..n {
        let kf = k as f64;
        let v = ((2.0 * kf + 1.0) * t * p[k][0] - kf * p[k - 1][0]) / (kf + 1.0);
        // P'_{k+1} = P'_{k−1} + (2k+1) P_k, and the same for higher derivatives.
        let d1 = p[k - 1][1] + (2.0 * kf + 1.0) * p[k][0];
        let d2 = p[k - 1][2] + (2.0 * kf + 1.0) * p[k][1];
        let d3 = p[k - 1][3] + (2.0 * kf + 1.0) * p[k][2];
        p[k + 1] = [v, d1, d2, d3];
    }
    p
}

/// ∫_{−1}^t P_j(s) ds.
fn int_p(p: &[[f64; 4]], j: usize, t: f64) -> f64 {
    if j == 0 {
        t + 1.0
    } else {
        (p[j + 1][0] - p[j - 1][0]) / (2.0 * j as f64 + 1.0)
    }
}

/// Clamped–free bending basis ψ_k = c_k Q_k(2ξ − 1), k = 0..n−1 (degrees 2..n+1).
#[derive(Debug, Clone)]
pub struct LegendreBending {
    n: usize,
}

impl LegendreBending {
    /// The first `n` functions.
    pub fn new(n: usize) -> Self {
        Self { n }
    }
}

impl Basis1d for LegendreBending {
    fn len(&self) -> usize {
        self.n
    }

    fn eval_all(&self, xi: f64, out: &mut [Derivs]) {
        let t = 2.0 * xi - 1.0;
        let p = legendre_table(self.n + 2, t);
        for (k, o) in out.iter_mut().enumerate().take(self.n) {
            let c = (2.0 * k as f64 + 1.0).sqrt() / 4.0;
            let (q, dq) = if k == 0 {
                (0.5 * (t + 1.0) * (t + 1.0), t + 1.0)
            } else {
                let kf = 2.0 * k as f64 + 1.0;
                (
                    (int_p(&p, k + 1, t) - int_p(&p, k - 1, t)) / kf,
                    (p[k + 1][0] - p[k - 1][0]) / kf,
                )
            };
            // d/dξ = 2 d/dt.
            *o = [c * q, 2.0 * c * dq, 4.0 * c * p[k][0], 8.0 * c * p[k][1]];
        }
    }

    fn polynomial_degree(&self) -> Option<usize> {
        Some(self.n + 1)
    }
}

/// Clamped–free rod basis (axial u, torsion θ): φ_k = c_k R_k(2ξ − 1), k = 0..n−1.
#[derive(Debug, Clone)]
pub struct LegendreRod {
    n: usize,
}

impl LegendreRod {
    /// The first `n` functions.
    pub fn new(n: usize) -> Self {
        Self { n }
    }
}

impl Basis1d for LegendreRod {
    fn len(&self) -> usize {
        self.n
    }

    fn eval_all(&self, xi: f64, out: &mut [Derivs]) {
        let t = 2.0 * xi - 1.0;
        let p = legendre_table(self.n + 1, t);
        for (k, o) in out.iter_mut().enumerate().take(self.n) {
            let c = (2.0 * k as f64 + 1.0).sqrt() / 2.0;
            let r = int_p(&p, k, t);
            *o = [
                c * r,
                2.0 * c * p[k][0],
                4.0 * c * p[k][1],
                8.0 * c * p[k][2],
            ];
        }
    }

    fn polynomial_degree(&self) -> Option<usize> {
        Some(self.n)
    }
}

/// Free–free basis √(2k+1) P_k(2ξ − 1), k = 0..n−1: includes the rigid pair (k = 0, 1).
#[derive(Debug, Clone)]
pub struct LegendreFree {
    n: usize,
}

impl LegendreFree {
    /// The first `n` functions.
    pub fn new(n: usize) -> Self {
        Self { n }
    }
}

impl Basis1d for LegendreFree {
    fn len(&self) -> usize {
        self.n
    }

    fn eval_all(&self, xi: f64, out: &mut [Derivs]) {
        let t = 2.0 * xi - 1.0;
        let p = legendre_table(self.n, t);
        for (k, o) in out.iter_mut().enumerate().take(self.n) {
            let c = (2.0 * k as f64 + 1.0).sqrt();
            *o = [
                c * p[k][0],
                2.0 * c * p[k][1],
                4.0 * c * p[k][2],
                8.0 * c * p[k][3],
            ];
        }
    }

    fn polynomial_degree(&self) -> Option<usize> {
        Some(self.n.saturating_sub(1))
    }
}
