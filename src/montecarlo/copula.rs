//! Correlated dispersions by a Gaussian copula (docs/montecarlo.md, "Correlated pairs").
//!
//! Each correlated parameter k draws a standard normal z_k from its run's own stream (at its
//! place in the alphabetical order, where an independent parameter draws its value); the
//! vector z of the correlated parameters becomes z' = L z, with L L^T = C the correlation
//! matrix the pairs give (1 on the diagonal, the given coefficient for each pair, 0 for pairs
//! not given), and each z'_k maps to its marginal through the marginal's inverse CDF:
//! x_k = F_k⁻¹(Φ(z'_k)) (Nelsen, *An Introduction to Copulas*, 2nd ed., 2006, §5.1; the
//! NORTA method, Cario & Nelson 1997). Every marginal keeps its own distribution exactly.
//!
//! The coefficient ρ is the correlation of the normal scores z' (the copula's parameter):
//! the Pearson correlation of the values for two normal marginals; for any two continuous
//! marginals Spearman's rank correlation is ρ_S = (6/π) asin(ρ/2) and Kendall's
//! τ = (2/π) asin ρ (Kruskal 1958, "Ordinal measures of association", JASA 53, 814–861),
//! since increasing maps keep ranks.
//!
//! *Requirements*: |ρ| < 1; continuous marginals (a discrete choice has no inverse CDF that
//! keeps its ranks, so it is refused); the matrix C of all pairs positive definite (pairs
//! that chain — a with b, b with c, a with c — must be consistent).

use super::distributions::{normal_cdf, normal_quantile, Distribution};
use thiserror::Error;

/// The smallest pivot of the Cholesky factorisation of C accepted as positive definite.
pub const MIN_PIVOT: f64 = 1e-10;

/// A correlation refused, with the numbers.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CopulaError {
    /// |ρ| ≥ 1 or not a number.
    #[error("the coefficient must lie strictly between −1 and 1, got {0}")]
    Coefficient(f64),
    /// A pair of one parameter with itself.
    #[error("the same key twice: name two different dispersed keys")]
    SameKey,
    /// A discrete marginal.
    #[error(
        "a discrete choice cannot be correlated: the Gaussian copula maps a normal score \
         through the marginal's inverse CDF, which a discrete choice does not have in a \
         rank-preserving form; use a continuous distribution"
    )]
    Discrete,
    /// The same pair twice.
    #[error("this pair is already correlated by correlations[{first}]")]
    Duplicate {
        /// The entry that gave the pair first (0-based).
        first: usize,
    },
    /// The pairs up to and including this one make C not positive definite.
    #[error(
        "with this pair the correlation matrix is not positive definite (Cholesky pivot \
         {pivot:.3e} ≤ {MIN_PIVOT:e}): the coefficients of the pairs that chain through these \
         keys are inconsistent"
    )]
    NotPositiveDefinite {
        /// The pivot where the factorisation failed.
        pivot: f64,
    },
}

/// One correlated pair: two dispersions (indices in the draw order) and ρ.
#[derive(Debug, Clone, PartialEq)]
pub struct Correlation {
    a: usize,
    b: usize,
    coefficient: f64,
}

impl Correlation {
    /// A pair of dispersions `a` ≠ `b` with −1 < ρ < 1.
    pub fn new(a: usize, b: usize, coefficient: f64) -> Result<Self, CopulaError> {
        if a == b {
            return Err(CopulaError::SameKey);
        }
        if coefficient.is_nan() || coefficient.abs() >= 1.0 {
            return Err(CopulaError::Coefficient(coefficient));
        }
        Ok(Self { a, b, coefficient })
    }

    /// The two dispersions (indices in the draw order).
    pub fn keys(&self) -> (usize, usize) {
        (self.a, self.b)
    }

    /// The normal-space correlation ρ.
    pub fn coefficient(&self) -> f64 {
        self.coefficient
    }
}

/// Why a set of pairs was refused: the pair (0-based entry) and the reason.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("correlations[{pair}]: {error}")]
pub struct PairError {
    /// The entry.
    pub pair: usize,
    /// Why.
    pub error: CopulaError,
}

/// The Gaussian copula of the correlated dispersions.
#[derive(Debug, Clone, PartialEq)]
pub struct Copula {
    /// The correlated dispersions (indices in the draw order, ascending).
    members: Vec<usize>,
    /// L, lower triangular, row-major k × k, L Lᵀ = C.
    lower: Vec<f64>,
}

/// The lower Cholesky factor of the k × k matrix `c` (row-major), or the failing pivot.
fn cholesky(c: &[f64], k: usize) -> Result<Vec<f64>, f64> {
    crate::math::cholesky_lower(c, k, MIN_PIVOT)
}

impl Copula {
    /// The copula of `pairs` over dispersions with these `marginals` (all of them, in draw
    /// order). Refuses a discrete marginal, a pair given twice and a matrix that is not
    /// positive definite — at the first pair with which it fails.
    pub fn new(marginals: &[Distribution], pairs: &[Correlation]) -> Result<Self, PairError> {
        let mut members: Vec<usize> = Vec::new();
        for (p, c) in pairs.iter().enumerate() {
            let err = |error| PairError { pair: p, error };
            for k in [c.a, c.b] {
                if matches!(marginals.get(k), Some(Distribution::Choice { .. }) | None) {
                    return Err(err(CopulaError::Discrete));
                }
            }
            let same = |d: &Correlation| (d.a, d.b) == (c.a, c.b) || (d.a, d.b) == (c.b, c.a);
            if let Some(first) = pairs[..p].iter().position(same) {
                return Err(err(CopulaError::Duplicate { first }));
            }
            members.extend([c.a, c.b]);
        }
        members.sort_unstable();
        members.dedup();
        let k = members.len();
        let at = |d: usize| members.binary_search(&d).expect("a member");
        // Factor C with the pairs added one at a time, so that a failure is reported at the
        // first pair that makes the matrix indefinite.
        let mut c = vec![0.0; k * k];
        for i in 0..k {
            c[i * k + i] = 1.0;
        }
        let mut lower = cholesky(&c, k).expect("the identity");
        for (p, pair) in pairs.iter().enumerate() {
            let (i, j) = (at(pair.a), at(pair.b));
            c[i * k + j] = pair.coefficient;
            c[j * k + i] = pair.coefficient;
            lower = cholesky(&c, k).map_err(|pivot| PairError {
                pair: p,
                error: CopulaError::NotPositiveDefinite { pivot },
            })?;
        }
        Ok(Self { members, lower })
    }

    /// The correlated dispersions (indices in the draw order, ascending).
    pub fn members(&self) -> &[usize] {
        &self.members
    }

    /// z ← L z: independent standard normals (one per member, in member order) become
    /// standard normals with correlation matrix C.
    pub fn correlate(&self, z: &mut [f64]) {
        let k = self.members.len();
        // Row i uses z[0..=i]: go from the last row up so that each z[j], j ≤ i, is still
        // the independent draw when row i reads it.
        for i in (0..k).rev() {
            z[i] = (0..=i).map(|j| self.lower[i * k + j] * z[j]).sum();
        }
    }
}

impl Distribution {
    /// The value whose CDF is Φ(z): F⁻¹(Φ(z)), the marginal's own quantile of a standard
    /// normal score. Normal: μ + σz; lognormal: exp(μ + σz); uniform: a + (b − a)Φ(z);
    /// truncated normal: μ + σ Φ⁻¹(Φ(α) + Φ(z)(Φ(β) − Φ(α))) (α, β the standardised
    /// bounds), evaluated on the side of the smaller tail, so that an interval far in the
    /// upper tail loses no digits. A discrete choice is not a copula marginal (refused by
    /// [`Copula::new`]); it gets its value by inversion of its step CDF.
    pub fn from_normal_score(&self, z: f64) -> f64 {
        match self {
            Self::Normal { mean, sd } => mean + sd * z,
            Self::LogNormal { mu, sigma } => (mu + sigma * z).exp(),
            Self::Uniform { low, high } => (low + (high - low) * normal_cdf(z)).clamp(*low, *high),
            Self::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } => {
                if *sd == 0.0 {
                    return *mean;
                }
                let (al, be) = ((low - mean) / sd, (high - mean) / sd);
                let x = if al > 0.0 {
                    // Upper tail: P(X > x) = (Φ(−x') − Φ(−β)) / (Φ(−α) − Φ(−β)) = Φ(−z).
                    let (ua, ub) = (normal_cdf(-al), normal_cdf(-be));
                    -normal_quantile(ub + normal_cdf(-z) * (ua - ub))
                } else {
                    let (ua, ub) = (normal_cdf(al), normal_cdf(be));
                    normal_quantile(ua + normal_cdf(z) * (ub - ua))
                };
                (mean + sd * x).clamp(*low, *high)
            }
            Self::Choice { values, weights } => {
                let total: f64 = weights.iter().sum();
                let u = normal_cdf(z) * total;
                let mut acc = 0.0;
                for (v, w) in values.iter().zip(weights) {
                    acc += w;
                    if u < acc {
                        return *v;
                    }
                }
                *values.last().expect("validated: one value at least")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn normal() -> Distribution {
        Distribution::Normal { mean: 0.0, sd: 1.0 }
    }

    #[test]
    fn bad_pairs_are_refused_at_the_pair_that_fails() {
        assert_eq!(Correlation::new(0, 0, 0.5), Err(CopulaError::SameKey));
        assert_eq!(
            Correlation::new(0, 1, 1.0),
            Err(CopulaError::Coefficient(1.0))
        );
        assert!(Correlation::new(0, 1, f64::NAN).is_err());
        let m = vec![normal(); 3];
        let p = |a, b, r| Correlation::new(a, b, r).unwrap();
        // a–b 0.6, b–c 0.6 is one (det 0.28, a–c 0 in normal space); a–c −0.6 is not one.
        let e = Copula::new(&m, &[p(0, 1, 0.6), p(1, 2, 0.6), p(0, 2, -0.6)]).unwrap_err();
        assert_eq!(e.pair, 2);
        assert!(matches!(e.error, CopulaError::NotPositiveDefinite { .. }));
        // a–b 0.9, b–c 0.9 with a–c left at 0 is not one either (det −0.62): refused at the
        // second pair.
        let e = Copula::new(&m, &[p(0, 1, 0.9), p(1, 2, 0.9)]).unwrap_err();
        assert_eq!(e.pair, 1);
        assert!(matches!(e.error, CopulaError::NotPositiveDefinite { .. }));
        let e = Copula::new(&m, &[p(0, 1, 0.5), p(1, 0, 0.2)]).unwrap_err();
        assert_eq!(
            e,
            PairError {
                pair: 1,
                error: CopulaError::Duplicate { first: 0 }
            }
        );
        let with_choice = vec![
            normal(),
            Distribution::Choice {
                values: vec![1.0, 2.0],
                weights: vec![1.0, 1.0],
            },
        ];
        let e = Copula::new(&with_choice, &[p(0, 1, 0.5)]).unwrap_err();
        assert_eq!(e.error, CopulaError::Discrete);
    }

    #[test]
    fn the_factor_reproduces_the_matrix() {
        let m = vec![normal(); 4];
        let p = |a, b, r| Correlation::new(a, b, r).unwrap();
        let c = Copula::new(&m, &[p(0, 1, 0.6), p(1, 3, -0.3), p(0, 3, 0.2)]).unwrap();
        assert_eq!(c.members(), &[0, 1, 3]);
        // Columns of L are the images of the unit vectors: (L Lᵀ)_ij = C_ij.
        let k = 3;
        let col = |j: usize| {
            let mut z = vec![0.0; k];
            z[j] = 1.0;
            c.correlate(&mut z);
            z
        };
        let cols: Vec<Vec<f64>> = (0..k).map(col).collect();
        let cij = |i: usize, j: usize| (0..k).map(|m| cols[m][i] * cols[m][j]).sum::<f64>();
        let expect = [[1.0, 0.6, 0.2], [0.6, 1.0, -0.3], [0.2, -0.3, 1.0]];
        for i in 0..k {
            for j in 0..k {
                assert!((cij(i, j) - expect[i][j]).abs() < 1e-15, "{i} {j}");
            }
        }
    }

    #[test]
    fn normal_scores_map_to_the_marginal_quantiles() {
        // F(F⁻¹(Φ(z))) = Φ(z) for every continuous marginal, against its exact CDF.
        let t = Distribution::TruncatedNormal {
            mean: 0.25,
            sd: 0.01,
            low: 0.23,
            high: 0.27,
        };
        let upper = Distribution::TruncatedNormal {
            mean: 0.0,
            sd: 1.0,
            low: 2.5,
            high: 4.0,
        };
        for d in [
            Distribution::Uniform {
                low: 1.0,
                high: 3.0,
            },
            Distribution::LogNormal {
                mu: 1.6,
                sigma: 0.1,
            },
            Distribution::Normal { mean: 3.0, sd: 0.2 },
            t,
            upper,
        ] {
            for z in [-3.0, -1.0, -0.1, 0.0, 0.7, 2.0, 3.5] {
                let x = d.from_normal_score(z);
                assert!(
                    (d.cdf(x) - normal_cdf(z)).abs() < 1e-12,
                    "{d:?} at z = {z}: F(x) = {} vs Φ(z) = {}",
                    d.cdf(x),
                    normal_cdf(z)
                );
            }
        }
    }
}
