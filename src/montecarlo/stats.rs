//! Sample statistics of the runs: moments, percentiles, the empirical CDF, Spearman's rank
//! correlation, standardised rank regression and the Kolmogorov–Smirnov distance.

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

/// A standardised rank regression (Iman & Conover 1979, "The use of the rank transform in
/// regression", Technometrics 21, 499–509; Saltelli et al., *Global Sensitivity Analysis:
/// The Primer*, 2008, §1.2.5): the least-squares fit of the standardised ranks of the output
/// on the standardised ranks of all parameters together.
#[derive(Debug, Clone, PartialEq)]
pub struct RankRegression {
    /// The standardised rank regression coefficient (SRRC) of each parameter, in the order
    /// given (NaN for a constant parameter, and all NaN when the fit is undetermined: a
    /// constant output, fewer runs than parameters + 2, or parameters whose ranks are
    /// collinear).
    pub coefficients: Vec<f64>,
    /// R² of the rank model: the share of the variance of the output's ranks it explains
    /// (near 1: the output is close to monotone and additive in the parameters, and the
    /// SRRCs rank them; small: they do not, and neither ranking tells the whole story).
    pub r2: f64,
    /// The runs the fit used (those with a value: NaN outputs are left out).
    pub runs: usize,
}

/// Standardised values (mean 0, population sd 1); `None` for a constant column.
fn standardised(v: &[f64]) -> Option<Vec<f64>> {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let ss = v.iter().map(|x| (x - m).powi(2)).sum::<f64>();
    if ss == 0.0 || !ss.is_finite() {
        return None;
    }
    let sd = (ss / n).sqrt();
    Some(v.iter().map(|x| (x - m) / sd).collect())
}

/// The SRRCs of the parameters `xs` (columns, one value per run) for the output `y`, and R².
/// With every column standardised, the coefficients solve R_xx b = r_xy (R_xx the rank
/// correlation matrix of the parameters, r_xy their rank correlations with the output), and
/// R² = bᵀ r_xy. Runs whose output is NaN are left out (±∞ rank as the largest/smallest
/// values). With independent parameters the SRRCs tend to the Spearman correlations.
pub fn rank_regression(xs: &[Vec<f64>], y: &[f64]) -> RankRegression {
    let keep: Vec<usize> = (0..y.len()).filter(|&r| !y[r].is_nan()).collect();
    let pick = |v: &[f64]| -> Vec<f64> { keep.iter().map(|&r| v[r]).collect() };
    let xr: Vec<Vec<f64>> = xs.iter().map(|x| ranks(&pick(x))).collect();
    regress_ranks(&xr, &ranks(&pick(y)))
}

/// [`rank_regression`] from the ranks (of the same runs, none NaN).
pub fn regress_ranks(xranks: &[Vec<f64>], yranks: &[f64]) -> RankRegression {
    let n = yranks.len();
    let k = xranks.len();
    let undetermined = RankRegression {
        coefficients: vec![f64::NAN; k],
        r2: f64::NAN,
        runs: n,
    };
    let Some(ry) = standardised(yranks) else {
        return undetermined;
    };
    // The non-constant parameters take part in the fit.
    let cols: Vec<(usize, Vec<f64>)> = (xranks.iter().enumerate())
        .filter_map(|(j, x)| standardised(x).map(|z| (j, z)))
        .collect();
    let m = cols.len();
    if m == 0 || n < m + 2 {
        return undetermined;
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>() / n as f64;
    let mut a = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..=i {
            let v = if i == j {
                1.0
            } else {
                dot(&cols[i].1, &cols[j].1)
            };
            a[i * m + j] = v;
            a[j * m + i] = v;
        }
    }
    let r: Vec<f64> = cols.iter().map(|(_, z)| dot(z, &ry)).collect();
    // Cholesky of R_xx (symmetric positive definite unless the ranks are collinear).
    let Ok(l) = crate::math::cholesky_lower(&a, m, 1e-12) else {
        return undetermined;
    };
    let mut b = r.clone();
    for i in 0..m {
        b[i] = (b[i] - (0..i).map(|q| l[i * m + q] * b[q]).sum::<f64>()) / l[i * m + i];
    }
    for i in (0..m).rev() {
        b[i] = (b[i] - ((i + 1)..m).map(|q| l[q * m + i] * b[q]).sum::<f64>()) / l[i * m + i];
    }
    let mut coefficients = vec![f64::NAN; k];
    for ((j, _), bj) in cols.iter().zip(&b) {
        coefficients[*j] = *bj;
    }
    RankRegression {
        coefficients,
        r2: b.iter().zip(&r).map(|(p, q)| p * q).sum(),
        runs: n,
    }
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

    #[test]
    fn rank_regression_of_an_exactly_monotone_additive_output() {
        // y = x1 + x2 on a grid where the ranks are the values: y's ranks are an exact
        // linear function of them only when one parameter alone drives it.
        let x1: Vec<f64> = (0..50).map(f64::from).collect();
        let x2: Vec<f64> = (0..50).map(|i| f64::from((i * 7) % 50)).collect();
        let r = rank_regression(
            &[x1.clone(), x2.clone()],
            &x1.iter().map(|v| v.exp()).collect::<Vec<_>>(),
        );
        assert!((r.coefficients[0] - 1.0).abs() < 1e-12, "{r:?}");
        assert!(r.coefficients[1].abs() < 1e-12, "{r:?}");
        assert!((r.r2 - 1.0).abs() < 1e-12);
        // A constant parameter has no coefficient; NaN outputs are left out.
        let mut y = x1.clone();
        y[3] = f64::NAN;
        let r = rank_regression(&[x1.clone(), vec![2.0; 50]], &y);
        assert!(r.coefficients[1].is_nan() && (r.coefficients[0] - 1.0).abs() < 1e-12);
        assert_eq!(r.runs, 49);
        // Too few runs: undetermined.
        let r = rank_regression(&[x1[..3].to_vec(), x2[..3].to_vec()], &x1[..3]);
        assert!(r.r2.is_nan());
    }
}
