//! The paper's characteristic functions (1.6)–(1.7): eigenfunctions of a uniform
//! Euler–Bernoulli beam, X'''' = β⁴ X on ξ ∈ [0, 1], for any pair of end conditions,
//! and the clamped–free rod functions √2 sin((2n−1)πξ/2).
//!
//! **Cancellation-free form** (docs/theory.md §1). The textbook form
//! cosh βξ − cos βξ − σ(sinh βξ − sin βξ) subtracts numbers of size e^β/2 to obtain a
//! result of size 1, and has no correct digit left for β ≳ 36 (n ≈ 11). Here every function is
//! written in the basis
//!
//! X(ξ) = a₁ cos βξ + a₂ sin βξ + a₃ e^{−βξ} + a₄ e^{−β(1−ξ)},
//!
//! whose members are all bounded by 1 on [0, 1]. The coefficients are the null vector of the
//! 4×4 boundary-condition matrix (entries of size ≤ 1), taken as a row of cofactors, and
//! the roots β come from the characteristic equations divided through by cosh β:
//! * clamped–free: cos β cosh β = −1  ⇔  cos β + sech β = 0,
//! * free–free, clamped–clamped: cos β cosh β = 1  ⇔  cos β − sech β = 0,
//! * clamped–pinned, pinned–free: tan β = tanh β  ⇔  sin β − cos β tanh β = 0,
//! * pinned–pinned: sin β = 0.
//!
//! Functions are normalised to ∫₀¹ X² dξ = 1 (as the classical tables) with the sign of the
//! classical forms: the first non-zero of X(0), X'(0), X''(0) is positive. Rigid-body
//! functions come first where the end conditions allow them: free–free has the pair
//! 1 and √3(2ξ − 1) (docs/theory.md §1.3: the paper omits them, the plate needs them);
//! pinned–free has the rotation √3 ξ.

use super::quadrature::Quadrature;
use super::{Basis1d, Derivs};
use std::f64::consts::PI;

/// A boundary condition at one end of a beam.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum End {
    /// X = X' = 0.
    Clamped,
    /// X = X'' = 0 (simply supported).
    Pinned,
    /// X'' = X''' = 0.
    Free,
}

impl End {
    /// The derivative orders set to zero at this end.
    fn orders(self) -> [usize; 2] {
        match self {
            End::Clamped => [0, 1],
            End::Pinned => [0, 2],
            End::Free => [2, 3],
        }
    }
}

/// Which characteristic equation a pair of end conditions leads to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Family {
    /// cos β cosh β = −1.
    ClampedFree,
    /// cos β cosh β = 1.
    CoshCosOne,
    /// tan β = tanh β.
    TanTanh,
    /// sin β = 0.
    SinZero,
}

fn family(left: End, right: End) -> Family {
    use End::*;
    match (left, right) {
        (Clamped, Free) | (Free, Clamped) => Family::ClampedFree,
        (Clamped, Clamped) | (Free, Free) => Family::CoshCosOne,
        (Clamped, Pinned) | (Pinned, Clamped) | (Pinned, Free) | (Free, Pinned) => Family::TanTanh,
        (Pinned, Pinned) => Family::SinZero,
    }
}

/// Number of rigid-body (β = 0) functions admitted by the end conditions.
fn rigid_count(left: End, right: End) -> usize {
    use End::*;
    match (left, right) {
        (Free, Free) => 2,
        (Pinned, Free) | (Free, Pinned) => 1,
        _ => 0,
    }
}

/// The k-th (k ≥ 1) non-zero root β_k of the characteristic equation of (left, right).
pub fn root(left: End, right: End, k: usize) -> f64 {
    let kf = k.max(1) as f64;
    let fam = family(left, right);
    let (f, guess): (fn(f64) -> f64, f64) = match fam {
        Family::ClampedFree => (|b| b.cos() + 1.0 / b.cosh(), (2.0 * kf - 1.0) * PI / 2.0),
        Family::CoshCosOne => (|b| b.cos() - 1.0 / b.cosh(), (2.0 * kf + 1.0) * PI / 2.0),
        Family::TanTanh => (
            |b| b.sin() - b.cos() * b.tanh(),
            (4.0 * kf + 1.0) * PI / 4.0,
        ),
        Family::SinZero => return kf * PI,
    };
    // The root lies within 0.6 of the asymptotic guess for every k (closest at k = 1:
    // 1.8751 vs π/2); bisect to the last bit.
    let (mut a, mut b) = (guess - 0.6, guess + 0.6);
    let (mut fa, _) = (f(a), f(b));
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let fm = f(m);
        if fm == 0.0 {
            return m;
        }
        if (fm > 0.0) == (fa > 0.0) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// One elastic characteristic function in the bounded form.
#[derive(Debug, Clone, Copy)]
struct Elastic {
    beta: f64,
    a: [f64; 4],
}

impl Elastic {
    /// (X, X', X'', X''') / β^k at ξ, before normalisation.
    fn scaled(&self, xi: f64) -> Derivs {
        let (s, c) = (self.beta * xi).sin_cos();
        let e0 = (-self.beta * xi).exp();
        let e1 = (-self.beta * (1.0 - xi)).exp();
        let [a1, a2, a3, a4] = self.a;
        [
            a1 * c + a2 * s + a3 * e0 + a4 * e1,
            -a1 * s + a2 * c - a3 * e0 + a4 * e1,
            -a1 * c - a2 * s + a3 * e0 + a4 * e1,
            a1 * s - a2 * c - a3 * e0 + a4 * e1,
        ]
    }

    fn new(left: End, right: End, beta: f64) -> Self {
        let proto = Elastic { beta, a: [0.0; 4] };
        // Rows: the four basis functions' scaled derivatives at each end.
        let mut rows = [[0.0; 4]; 4];
        let mut r = 0;
        for (xi, end) in [(0.0, left), (1.0, right)] {
            for order in end.orders() {
                for (j, row_j) in rows[r].iter_mut().enumerate() {
                    let mut e = proto;
                    e.a = [0.0; 4];
                    e.a[j] = 1.0;
                    *row_j = e.scaled(xi)[order];
                }
                r += 1;
            }
        }
        // Null vector = cofactors of the row whose cofactor vector is largest.
        let mut best = [0.0; 4];
        let mut best_norm = -1.0;
        for i in 0..4 {
            let mut cof = [0.0; 4];
            for (j, cj) in cof.iter_mut().enumerate() {
                let sign = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
                *cj = sign * minor3(&rows, i, j);
            }
            let norm: f64 = cof.iter().map(|x| x * x).sum();
            if norm > best_norm {
                best_norm = norm;
                best = cof;
            }
        }
        let mut e = Elastic { beta, a: best };
        // Normalise ∫X² = 1 with a rule that resolves the boundary layers of width 1/β.
        let q = Quadrature::composite(((beta / 3.0).ceil() as usize).max(4), 12);
        let norm = q.integrate(|x| e.scaled(x)[0].powi(2)).sqrt();
        let x0 = e.scaled(0.0);
        let sign = x0
            .iter()
            .take(3)
            .find(|v| v.abs() > 1e-8 * norm)
            .map_or(1.0, |v| v.signum());
        for a in &mut e.a {
            *a *= sign / norm;
        }
        e
    }

    fn eval(&self, xi: f64) -> Derivs {
        let s = self.scaled(xi);
        let b = self.beta;
        [s[0], s[1] * b, s[2] * b * b, s[3] * b * b * b]
    }
}

/// Determinant of the 3×3 minor of `m` without row `i` and column `j`.
fn minor3(m: &[[f64; 4]; 4], i: usize, j: usize) -> f64 {
    let mut s = [[0.0; 3]; 3];
    let mut r = 0;
    for (ii, row) in m.iter().enumerate() {
        if ii == i {
            continue;
        }
        let mut c = 0;
        for (jj, v) in row.iter().enumerate() {
            if jj == j {
                continue;
            }
            s[r][c] = *v;
            c += 1;
        }
        r += 1;
    }
    s[0][0] * (s[1][1] * s[2][2] - s[1][2] * s[2][1])
        - s[0][1] * (s[1][0] * s[2][2] - s[1][2] * s[2][0])
        + s[0][2] * (s[1][0] * s[2][1] - s[1][1] * s[2][0])
}

/// The first n characteristic functions of a beam with the given end conditions, rigid-body
/// functions (if any) first.
#[derive(Debug, Clone)]
pub struct BeamFunctions {
    left: End,
    right: End,
    rigid: usize,
    elastic: Vec<Elastic>,
}

impl BeamFunctions {
    /// The first `n` functions (rigid ones included in the count).
    pub fn new(left: End, right: End, n: usize) -> Self {
        let rigid = rigid_count(left, right).min(n);
        let elastic = (1..=n - rigid)
            .map(|k| Elastic::new(left, right, root(left, right, k)))
            .collect();
        Self {
            left,
            right,
            rigid,
            elastic,
        }
    }

    /// The end conditions (left at ξ = 0, right at ξ = 1).
    pub fn ends(&self) -> (End, End) {
        (self.left, self.right)
    }

    /// β of function i (0 for the rigid-body functions).
    pub fn beta(&self, i: usize) -> f64 {
        if i < self.rigid {
            0.0
        } else {
            self.elastic[i - self.rigid].beta
        }
    }

    /// Number of leading rigid-body functions.
    pub fn rigid_count(&self) -> usize {
        self.rigid
    }

    fn rigid_eval(&self, i: usize, xi: f64) -> Derivs {
        let s3 = 3f64.sqrt();
        match (self.left, self.right, i) {
            (End::Free, End::Free, 0) => [1.0, 0.0, 0.0, 0.0],
            (End::Free, End::Free, _) => [s3 * (2.0 * xi - 1.0), 2.0 * s3, 0.0, 0.0],
            (End::Pinned, _, _) => [s3 * xi, s3, 0.0, 0.0],
            _ => [s3 * (1.0 - xi), -s3, 0.0, 0.0],
        }
    }

    /// Function i and its first three derivatives at ξ.
    pub fn eval(&self, i: usize, xi: f64) -> Derivs {
        if i < self.rigid {
            self.rigid_eval(i, xi)
        } else {
            self.elastic[i - self.rigid].eval(xi)
        }
    }
}

impl Basis1d for BeamFunctions {
    fn len(&self) -> usize {
        self.rigid + self.elastic.len()
    }

    fn eval_all(&self, xi: f64, out: &mut [Derivs]) {
        for (i, o) in out.iter_mut().enumerate().take(self.len()) {
            *o = self.eval(i, xi);
        }
    }

    fn max_wavenumber(&self) -> f64 {
        self.elastic.last().map_or(1.0, |e| e.beta)
    }
}

/// Clamped–free rod functions √2 sin((2n−1)πξ/2), n = 1..N: axial and torsion in the
/// `characteristic` basis (docs/theory.md §1).
#[derive(Debug, Clone)]
pub struct RodFunctions {
    n: usize,
}

impl RodFunctions {
    /// The first `n` functions.
    pub fn clamped_free(n: usize) -> Self {
        Self { n }
    }

    /// Wavenumber (2k−1)π/2 of function k (0-based index i = k − 1).
    pub fn wavenumber(i: usize) -> f64 {
        (2.0 * i as f64 + 1.0) * PI / 2.0
    }
}

impl Basis1d for RodFunctions {
    fn len(&self) -> usize {
        self.n
    }

    fn eval_all(&self, xi: f64, out: &mut [Derivs]) {
        let r2 = 2f64.sqrt();
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            let k = Self::wavenumber(i);
            let (s, c) = (k * xi).sin_cos();
            *o = [r2 * s, r2 * k * c, -r2 * k * k * s, -r2 * k * k * k * c];
        }
    }

    fn max_wavenumber(&self) -> f64 {
        Self::wavenumber(self.n.saturating_sub(1))
    }
}
