//! Requirement verdicts by order statistics (Wilks 1941; the nonparametric one-sided
//! tolerance limit as in NASA's Monte Carlo practice).
//!
//! A requirement "the output meets its bound with probability ≥ p, at confidence c" holds
//! from n runs with f failures when, were the true probability of success only p, seeing f
//! or fewer failures would be unlikely:
//!
//!   P(F ≤ f | n, 1 − p) = Σ_{j=0}^{f} C(n, j) (1 − p)^j p^(n−j) ≤ 1 − c.        (W.1)
//!
//! The failures allowed at n are the largest f satisfying (W.1) (none when even f = 0 fails
//! it: too few runs); the runs needed for f failures are the smallest n satisfying it; with
//! f = 0 that is n ≥ ln(1 − c)/ln p (59 for 95 %/95 %). Equivalently, the (n − f)-th smallest
//! output of the runs (f the failures allowed) is a one-sided upper p/c tolerance bound
//! (the (f + 1)-th smallest a lower one).

/// ln C(n, j) by sums of logarithms (exact enough for n up to millions).
fn ln_choose(n: u64, j: u64) -> f64 {
    let j = j.min(n - j);
    (0..j)
        .map(|i| ((n - i) as f64).ln() - ((i + 1) as f64).ln())
        .sum()
}

/// P(F ≤ f) for F ~ Binomial(n, q), q the probability of a failure (W.1).
pub fn binomial_cdf(f: u64, n: u64, q: f64) -> f64 {
    if f >= n {
        return 1.0;
    }
    let (lq, lp) = (q.ln(), (1.0 - q).ln());
    (0..=f)
        .map(|j| (ln_choose(n, j) + j as f64 * lq + (n - j) as f64 * lp).exp())
        .sum::<f64>()
        .min(1.0)
}

/// The failures allowed among n runs for probability p at confidence c: the largest f < n
/// with (W.1), or `None` when n is too small even for f = 0. At least one run must succeed:
/// with c so small that 1 − c rounds to 1, (W.1) holds for every f, and n failures would
/// leave no run to read the tolerance bound from.
pub fn allowed_failures(n: u64, p: f64, c: f64) -> Option<u64> {
    let q = 1.0 - p;
    let ok = |f: u64| binomial_cdf(f, n, q) <= 1.0 - c;
    if n == 0 || !ok(0) {
        return None;
    }
    // P(F ≤ f) grows with f: find the last f that satisfies (W.1) by bisection.
    let (mut lo, mut hi) = (0, n - 1);
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        if ok(mid) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    Some(lo)
}

/// The fewest runs for which `failures` failures are still allowed at probability p and
/// confidence c (W.1); `failures` = 0 gives Wilks's first-order sample size.
pub fn runs_needed(failures: u64, p: f64, c: f64) -> u64 {
    let q = 1.0 - p;
    // P(F ≤ f | n) decreases with n (and is 1 for n ≤ f): double, then bisect with
    // (W.1) false at lo and true at hi.
    let ok = |n: u64| binomial_cdf(failures, n, q) <= 1.0 - c;
    let (mut lo, mut hi) = (failures, failures + 1);
    while !ok(hi) {
        lo = hi;
        // (W.1) holds for n large enough whenever p < 1; saturate rather than overflow.
        if hi == u64::MAX {
            return u64::MAX;
        }
        hi = hi.saturating_mul(2);
    }
    while lo + 1 < hi {
        let mid = lo + (hi - lo) / 2;
        if ok(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_order_closed_form() {
        for (p, c) in [(0.95_f64, 0.95), (0.99, 0.99), (0.997, 0.9), (0.9, 0.9)] {
            let exact = ((1.0_f64 - c).ln() / p.ln()).ceil() as u64;
            assert_eq!(runs_needed(0, p, c), exact, "{p} {c}");
        }
    }

    #[test]
    fn allowed_and_needed_agree() {
        for n in [59, 93, 124, 500] {
            let f = allowed_failures(n, 0.95, 0.95).unwrap();
            assert!(runs_needed(f, 0.95, 0.95) <= n);
            assert!(runs_needed(f + 1, 0.95, 0.95) > n);
        }
        assert_eq!(allowed_failures(58, 0.95, 0.95), None);
    }

    /// A confidence so small that 1 − c rounds to 1 (issue 37: an index out of bounds):
    /// every f satisfies (W.1), and the allowed failures stop at n − 1, one run left.
    #[test]
    fn a_vanishing_confidence_leaves_one_run() {
        for c in [1e-17, 1e-300, 5e-324] {
            assert_eq!(allowed_failures(10, 0.95, c), Some(9));
            assert_eq!(allowed_failures(1, 0.5, c), Some(0));
            assert_eq!(runs_needed(3, 0.95, c), 4);
        }
    }
}
