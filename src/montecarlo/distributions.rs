//! The distributions of dispersed parameters, sampled with `rand_distr` (docs/montecarlo.md).

use rand::Rng;
use rand_distr::weighted::WeightedIndex;
use rand_distr::{Distribution as _, LogNormal, Normal, Uniform};
use thiserror::Error;

/// Smallest probability a truncation interval must hold: the truncated normal is sampled by
/// rejection (expected draws 1/P), so an interval far in a tail is refused, not looped on.
pub const MIN_TRUNCATED_MASS: f64 = 1e-3;

/// A distribution of one dispersed value.
#[derive(Debug, Clone, PartialEq)]
pub enum Distribution {
    /// Normal N(mean, sd²).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (≥ 0; 0 is the constant `mean`).
        sd: f64,
    },
    /// Normal N(mean, sd²) conditioned on low ≤ x ≤ high.
    TruncatedNormal {
        /// Mean of the parent normal.
        mean: f64,
        /// Standard deviation of the parent normal (> 0).
        sd: f64,
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
    /// Uniform on [low, high).
    Uniform {
        /// Lower bound.
        low: f64,
        /// Upper bound (> low).
        high: f64,
    },
    /// Log-normal: ln x ~ N(mu, sigma²) (the parameters of the logarithm).
    LogNormal {
        /// Mean of ln x.
        mu: f64,
        /// Standard deviation of ln x (≥ 0).
        sigma: f64,
    },
    /// One of the values, with probabilities proportional to the weights.
    Choice {
        /// The values.
        values: Vec<f64>,
        /// Their weights (equal when not given).
        weights: Vec<f64>,
    },
}

/// A distribution refused, with the numbers.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DistributionError {
    /// A parameter is NaN or infinite.
    #[error("the parameters must be finite numbers")]
    NotFinite,
    /// σ < 0.
    #[error("the standard deviation must be ≥ 0, got {0}")]
    NegativeSd(f64),
    /// lower ≥ upper.
    #[error("the lower bound {low} must be below the upper bound {high}")]
    Bounds {
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
    /// The truncation interval holds almost none of the normal's probability.
    #[error(
        "the truncation [{low}, {high}] holds a probability of {mass:.3e} of the normal \
         (at least {MIN_TRUNCATED_MASS} is needed): it lies outside the distribution's support"
    )]
    TruncationOutside {
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
        /// Φ(high) − Φ(low).
        mass: f64,
    },
    /// An empty choice, or weights that do not match.
    #[error("a choice needs at least one value and, if weights are given, one positive weight per value")]
    Choice,
}

/// The standard normal CDF Φ(z) = ½ erfc(−z/√2).
pub fn normal_cdf(z: f64) -> f64 {
    0.5 * libm::erfc(-z / std::f64::consts::SQRT_2)
}

impl Distribution {
    /// Checks the parameters (what [`Distribution::sample`] needs to be valid).
    pub fn validate(&self) -> Result<(), DistributionError> {
        let finite = |xs: &[f64]| xs.iter().all(|x| x.is_finite());
        match self {
            Self::Normal { mean, sd }
            | Self::LogNormal {
                mu: mean,
                sigma: sd,
            } => {
                if !finite(&[*mean, *sd]) {
                    return Err(DistributionError::NotFinite);
                }
                if *sd < 0.0 {
                    return Err(DistributionError::NegativeSd(*sd));
                }
            }
            Self::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } => {
                if !finite(&[*mean, *sd, *low, *high]) {
                    return Err(DistributionError::NotFinite);
                }
                if *sd < 0.0 {
                    return Err(DistributionError::NegativeSd(*sd));
                }
                if low >= high {
                    return Err(DistributionError::Bounds {
                        low: *low,
                        high: *high,
                    });
                }
                let mass = self.truncated_mass();
                if mass < MIN_TRUNCATED_MASS {
                    return Err(DistributionError::TruncationOutside {
                        low: *low,
                        high: *high,
                        mass,
                    });
                }
            }
            Self::Uniform { low, high } => {
                if !finite(&[*low, *high]) {
                    return Err(DistributionError::NotFinite);
                }
                if low >= high {
                    return Err(DistributionError::Bounds {
                        low: *low,
                        high: *high,
                    });
                }
            }
            Self::Choice { values, weights } => {
                if !finite(values) || !finite(weights) {
                    return Err(DistributionError::NotFinite);
                }
                if values.is_empty()
                    || weights.len() != values.len()
                    || weights.iter().any(|w| *w <= 0.0)
                {
                    return Err(DistributionError::Choice);
                }
            }
        }
        Ok(())
    }

    /// Φ((high − μ)/σ) − Φ((low − μ)/σ) of a truncated normal (1 otherwise); with σ = 0,
    /// 1 if the mean lies inside the bounds, else 0.
    fn truncated_mass(&self) -> f64 {
        match *self {
            Self::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } => {
                if sd == 0.0 {
                    f64::from(u8::from((low..=high).contains(&mean)))
                } else {
                    normal_cdf((high - mean) / sd) - normal_cdf((low - mean) / sd)
                }
            }
            _ => 1.0,
        }
    }

    /// One draw. The parameters must have passed [`Distribution::validate`].
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        match self {
            Self::Normal { mean, sd } => Normal::new(*mean, *sd).expect("validated").sample(rng),
            Self::LogNormal { mu, sigma } => {
                LogNormal::new(*mu, *sigma).expect("validated").sample(rng)
            }
            Self::Uniform { low, high } => {
                Uniform::new(*low, *high).expect("validated").sample(rng)
            }
            Self::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } => {
                // Rejection from the parent normal: exact, expected 1/P draws (P ≥ 1e-3).
                let n = Normal::new(*mean, *sd).expect("validated");
                loop {
                    let x = n.sample(rng);
                    if (*low..=*high).contains(&x) {
                        return x;
                    }
                }
            }
            Self::Choice { values, weights } => {
                let w = WeightedIndex::new(weights).expect("validated");
                values[w.sample(rng)]
            }
        }
    }

    /// The exact CDF F(x) (for tests and the KS distance).
    pub fn cdf(&self, x: f64) -> f64 {
        match *self {
            Self::Normal { mean, sd } => normal_cdf((x - mean) / sd),
            Self::LogNormal { mu, sigma } => {
                if x <= 0.0 {
                    0.0
                } else {
                    normal_cdf((x.ln() - mu) / sigma)
                }
            }
            Self::Uniform { low, high } => ((x - low) / (high - low)).clamp(0.0, 1.0),
            Self::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } => {
                let a = normal_cdf((low - mean) / sd);
                ((normal_cdf((x.clamp(low, high) - mean) / sd) - a) / self.truncated_mass())
                    .clamp(0.0, 1.0)
            }
            Self::Choice {
                ref values,
                ref weights,
            } => {
                let total: f64 = weights.iter().sum();
                let below: f64 = (values.iter().zip(weights))
                    .filter(|(v, _)| **v <= x)
                    .map(|(_, w)| w)
                    .sum();
                below / total
            }
        }
    }

    /// Two values the distribution can take, distinct unless it has a single value (to
    /// check that the scenario uses a dispersed key: the lowered scenarios at the two must
    /// differ).
    pub fn probes(&self) -> (f64, f64) {
        let pair = match self {
            Self::Normal { mean, sd } => (mean - 0.5 * sd, mean + 0.5 * sd),
            Self::TruncatedNormal { low, high, .. } => {
                (low + (high - low) / 3.0, low + 2.0 * (high - low) / 3.0)
            }
            Self::Uniform { low, high } => {
                (low + (high - low) / 3.0, low + 2.0 * (high - low) / 3.0)
            }
            Self::LogNormal { mu, sigma } => ((mu - 0.5 * sigma).exp(), (mu + 0.5 * sigma).exp()),
            Self::Choice { values, .. } => {
                let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (lo, hi)
            }
        };
        pair
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_parameters_are_refused_with_their_numbers() {
        let e = Distribution::Normal {
            mean: 1.0,
            sd: -0.1,
        }
        .validate()
        .unwrap_err();
        assert_eq!(e, DistributionError::NegativeSd(-0.1));
        let e = Distribution::Uniform {
            low: 2.0,
            high: 1.0,
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("lower bound 2"));
        let far = Distribution::TruncatedNormal {
            mean: 0.0,
            sd: 1.0,
            low: 10.0,
            high: 11.0,
        };
        assert!(matches!(
            far.validate(),
            Err(DistributionError::TruncationOutside { .. })
        ));
    }

    #[test]
    fn normal_cdf_matches_tabulated_values() {
        // Abramowitz & Stegun table 26.1: Φ(1) = 0.841344746, Φ(1.96) = 0.975002105.
        assert!((normal_cdf(1.0) - 0.841_344_746).abs() < 1e-9);
        assert!((normal_cdf(1.96) - 0.975_002_105).abs() < 1e-9);
    }
}
