//! A clamped family extended by kink functions at hinge lines (docs/theory.md §1.6).
//!
//! A plate cut across its length at ξ_1 < ξ_2 < … and joined there by hinge springs deforms
//! with a jump of slope at each cut. The smooth family cannot represent it; the kinks
//!
//!   K_k(ξ) = (ξ − ξ_k)₊ = max(ξ − ξ_k, 0),   K_k' = H(ξ − ξ_k),   K_k'' = 0 (off the line),
//!
//! can: the outboard side turns rigidly by h_k/a about the line. A kink's curvature is a
//! Dirac at its line, where the plate is cut: the plate's bending energy is the integral over
//! the pieces between lines (so K_k'' = 0 there), and the line's own energy is the hinge
//! spring's, added by the assembly. Products of kinks and smooth functions are smooth on each
//! piece only, so the quadrature is the inner family's rule on every piece.

use super::{Basis1d, Derivs, Quadrature};

/// `inner`'s functions followed by kink functions F_i = Σ_k W_ik K_k.
#[derive(Debug)]
pub struct Hinged {
    inner: Box<dyn Basis1d>,
    /// ξ_k, ascending in [0, 1).
    lines: Vec<f64>,
    /// W, one row per kink function.
    weights: Vec<Vec<f64>>,
}

impl Hinged {
    /// `inner` extended by one kink at each of `lines` (ascending fractions of the length in
    /// [0, 1)).
    pub fn new(inner: Box<dyn Basis1d>, lines: Vec<f64>) -> Self {
        let n = lines.len();
        let weights = (0..n)
            .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
            .collect();
        Self::combined(inner, lines, weights)
    }

    /// `inner` extended by the kink combinations F_i = Σ_k W_ik K_k, W = `weights` (lines tied,
    /// e.g. by an ideal cable).
    pub fn combined(inner: Box<dyn Basis1d>, lines: Vec<f64>, weights: Vec<Vec<f64>>) -> Self {
        Self {
            inner,
            lines,
            weights,
        }
    }

    /// Number of smooth (inner) functions; the kinks follow them.
    pub fn smooth(&self) -> usize {
        self.inner.len()
    }
}

impl Basis1d for Hinged {
    fn len(&self) -> usize {
        self.inner.len() + self.weights.len()
    }

    fn eval_all(&self, xi: f64, out: &mut [Derivs]) {
        let n = self.inner.len();
        self.inner.eval_all(xi, &mut out[..n]);
        for (i, w) in self.weights.iter().enumerate() {
            let (mut v, mut d) = (0.0, 0.0);
            for (&l, &wk) in self.lines.iter().zip(w) {
                if xi > l {
                    v += wk * (xi - l);
                    d += wk;
                }
            }
            out[n + i] = [v, d, 0.0, 0.0];
        }
    }

    fn polynomial_degree(&self) -> Option<usize> {
        self.inner.polynomial_degree()
    }

    fn max_wavenumber(&self) -> f64 {
        self.inner.max_wavenumber()
    }

    fn quadrature(&self) -> Quadrature {
        self.inner.quadrature().split(&self.lines)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::{Integrals, LegendreBending};

    /// ∫₀¹ K_j K_k dξ = (1 − m)²(1 − m)/3 + (m − l)(1 − m)²/2 with m = max(l_j, l_k),
    /// l = min: a closed form the piecewise rule must reach to rounding, and the smooth
    /// block must equal the inner family's.
    #[test]
    fn kink_integrals_are_exact_on_the_pieces() {
        let lines = vec![0.0, 0.3, 0.71];
        let h = Hinged::new(Box::new(LegendreBending::new(5)), lines.clone());
        let (hi, si) = (Integrals::new(&h), Integrals::new(&LegendreBending::new(5)));
        for j in 0..3 {
            for k in 0..3 {
                let (l, m) = (lines[j].min(lines[k]), lines[j].max(lines[k]));
                let r = 1.0 - m;
                let exact = r * r * r / 3.0 + (m - l) * r * r / 2.0;
                assert!((hi.i00[(5 + j, 5 + k)] - exact).abs() < 1e-15, "{j} {k}");
                assert!((hi.i11[(5 + j, 5 + k)] - r).abs() < 1e-15);
                assert_eq!(hi.i22[(5 + j, 5 + k)], 0.0);
            }
            // ∫ K dξ = (1 − l)²/2, ∫ ξ K dξ = (1 − l)²(2 + l)/6.
            let r = 1.0 - lines[j];
            assert!((hi.m0[5 + j] - r * r / 2.0).abs() < 1e-15);
            assert!((hi.m1[5 + j] - r * r * (2.0 + lines[j]) / 6.0).abs() < 1e-15);
        }
        for a in 0..5 {
            for b in 0..5 {
                assert!((hi.i00[(a, b)] - si.i00[(a, b)]).abs() < 1e-14);
                assert!((hi.i22[(a, b)] - si.i22[(a, b)]).abs() < 1e-12);
            }
        }
    }
}
