//! Gauss–Legendre quadrature on [0, 1].
//!
//! Hand-written (≈40 lines): the nodes come from Newton's method on the
//! three-term Legendre recurrence, which is accurate to a few ulp for the
//! rule sizes used here (≤ 400 points). A crate would add a dependency for
//! one function.

/// A quadrature rule on the unit interval: ∫₀¹ f(ξ) dξ ≈ Σ wᵢ f(ξᵢ).
#[derive(Debug, Clone, PartialEq)]
pub struct Quadrature {
    /// Nodes ξᵢ in (0, 1), ascending.
    pub points: Vec<f64>,
    /// Weights wᵢ > 0, summing to 1.
    pub weights: Vec<f64>,
}

impl Quadrature {
    /// The n-point Gauss–Legendre rule on [0, 1]: exact for polynomials of degree ≤ 2n − 1.
    pub fn gauss(n: usize) -> Self {
        let n = n.max(1);
        let mut points = vec![0.0; n];
        let mut weights = vec![0.0; n];
        let m = n.div_ceil(2);
        for i in 0..m {
            // Tricomi's initial guess for the i-th root of P_n on [−1, 1] (descending).
            let mut t = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre_and_derivative(n, t);
                dp = d;
                let dt = p / d;
                t -= dt;
                if dt.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre_and_derivative(n, t);
            if d.is_finite() {
                dp = d;
            }
            let w = 2.0 / ((1.0 - t * t) * dp * dp);
            // Map t ∈ [−1, 1] to ξ = (1 + t)/2, weights halve.
            points[n - 1 - i] = 0.5 * (1.0 + t);
            points[i] = 0.5 * (1.0 - t);
            weights[i] = 0.5 * w;
            weights[n - 1 - i] = 0.5 * w;
        }
        Self { points, weights }
    }

    /// A composite rule: `panels` equal sub-intervals, each with an `n`-point Gauss rule.
    /// Used for the oscillatory characteristic functions (β up to ≈ 315 for n = 100).
    pub fn composite(panels: usize, n: usize) -> Self {
        let panels = panels.max(1);
        let base = Self::gauss(n);
        let h = 1.0 / panels as f64;
        let mut points = Vec::with_capacity(panels * base.points.len());
        let mut weights = Vec::with_capacity(panels * base.points.len());
        for k in 0..panels {
            let a = k as f64 * h;
            for (p, w) in base.points.iter().zip(&base.weights) {
                points.push(a + h * p);
                weights.push(h * w);
            }
        }
        Self { points, weights }
    }

    /// This rule on every piece of [0, 1] between the `breaks` (ascending, in [0, 1); a break
    /// at 0 adds nothing): exact piecewise where the rule is exact, for integrands with a kink
    /// or a jump at the breaks.
    pub fn split(&self, breaks: &[f64]) -> Self {
        let mut ends: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|&b| b > 0.0 && b < 1.0)
            .collect();
        ends.push(1.0);
        let mut points = Vec::with_capacity(ends.len() * self.points.len());
        let mut weights = Vec::with_capacity(ends.len() * self.points.len());
        let mut a = 0.0;
        for &b in &ends {
            let h = b - a;
            if h > 0.0 {
                for (p, w) in self.points.iter().zip(&self.weights) {
                    points.push(a + h * p);
                    weights.push(h * w);
                }
            }
            a = b;
        }
        Self { points, weights }
    }

    /// ∫₀¹ f(ξ) dξ by this rule.
    pub fn integrate(&self, f: impl Fn(f64) -> f64) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(&x, &w)| w * f(x))
            .sum()
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when the rule has no node (never, for rules built here).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// P_n(t) and P_n'(t) by the Bonnet recurrence (k+1)P_{k+1} = (2k+1) t P_k − k P_{k−1}.
fn legendre_and_derivative(n: usize, t: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, t);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 1..n {
        let kf = k as f64;
        let p2 = ((2.0 * kf + 1.0) * t * p1 - kf * p0) / (kf + 1.0);
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (t * p1 - p0) / (t * t - 1.0);
    (p1, d)
}
