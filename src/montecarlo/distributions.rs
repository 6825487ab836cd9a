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
    #[error("a choice needs at least one value and, if weights are given, one positive weight per value (with a finite sum)")]
    Choice,
}

/// The standard normal CDF Φ(z) = ½ erfc(−z/√2).
pub fn normal_cdf(z: f64) -> f64 {
    0.5 * libm::erfc(-z / std::f64::consts::SQRT_2)
}

/// The standard normal quantile Φ⁻¹(p), 0 < p < 1 (±∞ at 1 and 0, NaN outside): Wichura's
/// algorithm AS 241 (PPND16), "The percentage points of the normal distribution", Applied
/// Statistics 37 (1988) 477–484, relative accuracy about 1e-16.
pub fn normal_quantile(p: f64) -> f64 {
    if !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    if p == 0.0 {
        return f64::NEG_INFINITY;
    }
    if p == 1.0 {
        return f64::INFINITY;
    }
    let poly = |c: &[f64], x: f64| c.iter().rev().fold(0.0, |acc, k| acc * x + k);
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        const A: [f64; 8] = [
            3.387_132_872_796_366_5,
            133.141_667_891_784_38,
            1_971.590_950_306_551_3,
            13_731.693_765_509_46,
            45_921.953_931_549_87,
            67_265.770_927_008_7,
            33_430.575_583_588_13,
            2_509.080_928_730_122_7,
        ];
        const B: [f64; 8] = [
            1.0,
            42.313_330_701_600_91,
            687.187_007_492_057_9,
            5_394.196_021_424_751,
            21_213.794_301_586_597,
            39_307.895_800_092_71,
            28_729.085_735_721_943,
            5_226.495_278_852_546,
        ];
        let r = 0.180_625 - q * q;
        return q * poly(&A, r) / poly(&B, r);
    }
    let mut r = (-(if q < 0.0 { p } else { 1.0 - p }).ln()).sqrt();
    let x = if r <= 5.0 {
        const C: [f64; 8] = [
            1.423_437_110_749_683_5,
            4.630_337_846_156_545,
            5.769_497_221_460_691,
            3.647_848_324_763_204_6,
            1.270_458_252_452_368_4,
            0.241_780_725_177_450_6,
            0.022_723_844_989_269_184,
            7.745_450_142_783_414e-4,
        ];
        const D: [f64; 8] = [
            1.0,
            2.053_191_626_637_759,
            1.676_384_830_183_803_8,
            0.689_767_334_985_1,
            0.148_103_976_427_480_08,
            0.015_198_666_563_616_457,
            5.475_938_084_995_345e-4,
            1.050_750_071_644_416_8e-9,
        ];
        r -= 1.6;
        poly(&C, r) / poly(&D, r)
    } else {
        const E: [f64; 8] = [
            6.657_904_643_501_103,
            5.463_784_911_164_114,
            1.784_826_539_917_291_3,
            0.296_560_571_828_504_9,
            0.026_532_189_526_576_124,
            0.001_242_660_947_388_078_4,
            2.711_555_568_743_487_6e-5,
            2.010_334_399_292_288_1e-7,
        ];
        const F: [f64; 8] = [
            1.0,
            0.599_832_206_555_887_9,
            0.136_929_880_922_735_8,
            0.014_875_361_290_850_615,
            7.868_691_311_456_133e-4,
            1.846_318_317_510_054_8e-5,
            1.421_511_758_316_446e-7,
            2.044_263_103_389_939_7e-15,
        ];
        r -= 5.0;
        poly(&E, r) / poly(&F, r)
    };
    if q < 0.0 {
        -x
    } else {
        x
    }
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
                    || !weights.iter().sum::<f64>().is_finite()
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
    fn normal_quantile_inverts_the_cdf_and_matches_tabulated_values() {
        // Abramowitz & Stegun table 26.5 (9 decimals): the upper 2.5 %, 0.5 % and 0.005 %
        // points.
        for (p, x) in [
            (0.975, 1.959_963_985),
            (0.995, 2.575_829_304),
            (0.999_95, 3.890_591_886),
        ] {
            assert!((normal_quantile(p) - x).abs() < 6e-10, "{p}");
            assert!((normal_quantile(1.0 - p) + x).abs() < 6e-10, "{p}");
        }
        // Φ(Φ⁻¹(p)) = p over the three branches of AS 241 (central, r ≤ 5, r > 5).
        for p in [
            1e-300, 1e-20, 1e-12, 1e-5, 0.01, 0.07, 0.3, 0.5, 0.6, 0.92, 0.999,
        ] {
            let z = normal_quantile(p);
            assert!(
                ((normal_cdf(z) - p) / p).abs() < 1e-13,
                "{p}: {}",
                normal_cdf(z)
            );
        }
        assert_eq!(normal_quantile(0.0), f64::NEG_INFINITY);
        assert!(normal_quantile(1.5).is_nan());
    }

    #[test]
    fn normal_cdf_matches_tabulated_values() {
        // Abramowitz & Stegun table 26.1: Φ(1) = 0.841344746, Φ(1.96) = 0.975002105.
        assert!((normal_cdf(1.0) - 0.841_344_746).abs() < 1e-9);
        assert!((normal_cdf(1.96) - 0.975_002_105).abs() < 1e-9);
    }
}
