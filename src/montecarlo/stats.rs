//! Sample statistics of the runs: moments, percentiles, the empirical CDF, Spearman's rank
//! correlation and the Kolmogorov–Smirnov distance.

/// The percentiles reported for every output, %.
pub const PERCENTILES: [f64; 7] = [1.0, 5.0, 10.0, 50.0, 90.0, 95.0, 99.0];

/// Summary of one column over the runs (over its finite values; `non_finite` counts the
/// others: a hinge that never latched has no latch time).
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Finite values.
    pub count: usize,
    /// NaN or infinite values.
    pub non_finite: usize,
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation (n − 1).
    pub sd: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// The [`PERCENTILES`], in order.
    pub percentiles: Vec<f64>,
}

/// The q-quantile (0 ≤ q ≤ 1) of sorted values by linear interpolation between order
/// statistics (Hyndman & Fan 1996, definition 7: h = (n − 1) q).
pub fn quantile_sorted(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        1 => sorted[0],
        n => {
            let h = (n - 1) as f64 * q;
            let (lo, frac) = (h.floor() as usize, h - h.floor());
            let hi = (lo + 1).min(n - 1);
            sorted[lo] + frac * (sorted[hi] - sorted[lo])
        }
    }
}

/// Values sorted ascending (total order; NaN last).
pub fn sorted(values: &[f64]) -> Vec<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v
}

/// Mean, sd, extremes and percentiles of the finite values.
pub fn summarize(values: &[f64]) -> Summary {
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let n = finite.len();
    let mean = if n == 0 {
        f64::NAN
    } else {
        finite.iter().sum::<f64>() / n as f64
    };
    let sd = if n < 2 {
        f64::NAN
    } else {
        (finite.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    };
    let s = sorted(&finite);
    Summary {
        count: n,
        non_finite: values.len() - n,
        mean,
        sd,
        min: s.first().copied().unwrap_or(f64::NAN),
        max: s.last().copied().unwrap_or(f64::NAN),
        percentiles: PERCENTILES
            .iter()
            .map(|p| quantile_sorted(&s, p / 100.0))
            .collect(),
    }
}

/// Ranks 1…n, ties sharing their average rank (NaN values ranked last).
pub fn ranks(values: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..values.len()).collect();
    idx.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut r = vec![0.0; values.len()];
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && values[idx[j + 1]].total_cmp(&values[idx[i]]).is_eq() {
            j += 1;
        }
        let avg = (i + j) as f64 / 2.0 + 1.0;
        for &k in &idx[i..=j] {
            r[k] = avg;
        }
        i = j + 1;
    }
    r
}

/// Pearson's correlation; NaN when either side is constant.
pub fn pearson(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx).powi(2);
        syy += (b - my).powi(2);
    }
    if sxx == 0.0 || syy == 0.0 {
        f64::NAN
    } else {
        sxy / (sxx * syy).sqrt()
    }
}

/// Spearman's rank correlation ρ_s = Pearson(rank x, rank y) (ties averaged).
pub fn spearman(x: &[f64], y: &[f64]) -> f64 {
    pearson(&ranks(x), &ranks(y))
}

/// The Kolmogorov–Smirnov distance D = sup |F_n(x) − F(x)| of a sample against an exact
/// CDF (evaluated on both sides of every step of F_n).
pub fn ks_distance(sample: &[f64], cdf: impl Fn(f64) -> f64) -> f64 {
    let s = sorted(sample);
    let n = s.len() as f64;
    s.iter()
        .enumerate()
        .map(|(i, &x)| {
            let f = cdf(x);
            (f - i as f64 / n).abs().max(((i + 1) as f64 / n - f).abs())
        })
        .fold(0.0, f64::max)
}

/// The asymptotic critical value of D at level α for n values: √(−ln(α/2)/2) / √n
/// (1.9495/√n at α = 0.001; Smirnov 1948).
pub fn ks_critical(n: usize, alpha: f64) -> f64 {
    (-(alpha / 2.0).ln() / 2.0).sqrt() / (n as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_and_ranks() {
        let s = summarize(&[4.0, 1.0, 3.0, 2.0, f64::NAN]);
        assert_eq!((s.count, s.non_finite), (4, 1));
        assert_eq!((s.min, s.max, s.mean), (1.0, 4.0, 2.5));
        assert_eq!(quantile_sorted(&[1.0, 2.0, 3.0, 4.0], 0.5), 2.5);
        assert_eq!(ranks(&[10.0, 20.0, 10.0]), vec![1.5, 3.0, 1.5]);
        assert!((spearman(&[1.0, 2.0, 3.0], &[1.0, 8.0, 27.0]) - 1.0).abs() < 1e-15);
        // 1.9495 at α = 0.001 (Smirnov's table).
        assert!((ks_critical(1, 0.001) - 1.9495).abs() < 1e-3);
    }
}
