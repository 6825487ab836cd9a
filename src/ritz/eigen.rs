//! The symmetric-definite generalized eigenproblem K φ = λ M φ.

use super::RitzError;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt as SparseLlt;
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use faer::{Mat, Side};

/// Solves K φ = λ M φ for symmetric K and symmetric positive definite M.
///
/// Method: Jacobi scaling D = diag(M)^{-1/2}; Cholesky of DKD = LLᵀ when it exists, the
/// standard symmetric problem L⁻¹(DMD)L⁻ᵀ y = μ y (faer), μ = 1/λ, φ = D L⁻ᵀ y; otherwise
/// the same with the roles of K and M exchanged. The eigenvalues are then recomputed
/// as Rayleigh quotients λ = φᵀKφ / φᵀMφ: the symmetric solver's absolute error ε‖A‖
/// would otherwise cost the low modes digits when the spectrum spans many decades, while
/// the Rayleigh quotient's error is quadratic in the eigenvector's.
///
/// Returns λ ascending and Φ with ΦᵀMΦ = I.
pub fn generalized_symmetric(
    k: &Mat<f64>,
    m: &Mat<f64>,
) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
    let n = m.nrows();
    if n == 0 {
        return Ok((Vec::new(), Mat::zeros(0, 0)));
    }
    let mut d = vec![0.0; n];
    for (i, di) in d.iter_mut().enumerate() {
        let mii = m[(i, i)];
        if !(mii.is_finite() && mii > 0.0) {
            return Err(RitzError::MassNotPositiveDefinite { pivot: i });
        }
        *di = 1.0 / mii.sqrt();
    }
    let ms = Mat::from_fn(n, n, |i, j| d[i] * m[(i, j)] * d[j]);
    let ks = Mat::from_fn(n, n, |i, j| d[i] * k[(i, j)] * d[j]);
    // Preferred route when K is positive definite (every root-clamped component): the
    // inverse problem M φ = μ K φ, μ = 1/λ. The symmetric solver's absolute error ε·μ_max
    // then falls on the *high* modes, and the low modes — the ones that matter — keep full
    // relative accuracy however ill-conditioned M is (high-order polynomial bases make M's
    // condition number grow like n⁴ per direction). Otherwise (K singular, e.g. a structure
    // with no elastic component) the direct route through M's Cholesky factor.
    let mut phi = match ks.llt(Side::Lower) {
        Ok(llt) => symmetric_reduced(llt.L(), &ms)?,
        Err(_) => {
            let llt = ms
                .llt(Side::Lower)
                .map_err(|_| RitzError::MassNotPositiveDefinite {
                    pivot: first_bad_pivot(&ms),
                })?;
            symmetric_reduced(llt.L(), &ks)?
        }
    };
    for i in 0..n {
        for j in 0..n {
            phi[(i, j)] *= d[i];
        }
    }
    // Rayleigh quotients with the unscaled matrices.
    let kp = k * &phi;
    let mp = m * &phi;
    let mut pairs: Vec<(f64, f64, usize)> = (0..n)
        .map(|j| {
            let num: f64 = (0..n).map(|i| phi[(i, j)] * kp[(i, j)]).sum();
            let den: f64 = (0..n).map(|i| phi[(i, j)] * mp[(i, j)]).sum();
            (num / den, den, j)
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
    let lambda = pairs.iter().map(|p| p.0).collect();
    // Mass-normalise (φᵀMφ = 1), then steps of symmetric (Löwdin) re-orthonormalisation,
    // Φ ← Φ (I − ½E) with E = ΦᵀMΦ − I, each leaving O(E²) without favouring any mode. The
    // K-Cholesky route leaves the high modes M-orthogonal to ≈ 1e-10 on small models, where
    // one step makes them orthonormal to rounding; on large ones far less (a 932-coordinate
    // plate model of 932 coordinates: |E| = 3e-3 on its top modes, 1.1e-5 left after one step, and NASA 42's
    // export refused the modes as not mass-normalised), so the steps go on while the last
    // one started from |E| above 1e-7 (at most LOWDIN_STEPS).
    const LOWDIN_STEPS: usize = 4;
    let mut phi = Mat::from_fn(n, n, |i, j| phi[(i, pairs[j].2)] / pairs[j].1.sqrt());
    for _ in 0..LOWDIN_STEPS {
        let e = phi.transpose() * (m * &phi);
        let mut worst = 0.0_f64;
        let half = Mat::from_fn(n, n, |i, j| {
            let delta = if i == j { 1.0 } else { 0.0 };
            worst = worst.max((e[(i, j)] - delta).abs());
            delta - 0.25 * (e[(i, j)] + e[(j, i)] - 2.0 * delta)
        });
        phi = &phi * &half;
        if worst <= 1e-7 {
            break;
        }
    }
    Ok((lambda, phi))
}

/// With B = LLᵀ, the eigenvectors of L⁻¹ A L⁻ᵀ mapped back by L⁻ᵀ: the B-orthonormal
/// eigenvectors of the pencil (A, B), in any order (the caller sorts by Rayleigh quotient).
fn symmetric_reduced(l: faer::MatRef<'_, f64>, a: &Mat<f64>) -> Result<Mat<f64>, RitzError> {
    let mut x = a.clone();
    l.solve_lower_triangular_in_place(x.as_mut());
    let mut c = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(c.as_mut());
    let n = c.nrows();
    let c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| RitzError::EigenNoConvergence)?;
    let mut phi = evd.U().to_owned();
    l.transpose().solve_upper_triangular_in_place(phi.as_mut());
    Ok(phi)
}

/// First non-positive pivot of an unpivoted LDLᵀ, for the error message.
fn first_bad_pivot(m: &Mat<f64>) -> usize {
    let n = m.nrows();
    let mut a = m.clone();
    for k in 0..n {
        let p = a[(k, k)];
        if p.is_nan() || p <= 0.0 {
            return k;
        }
        for i in k + 1..n {
            let f = a[(i, k)] / p;
            for j in k + 1..n {
                a[(i, j)] -= f * a[(k, j)];
            }
        }
    }
    n
}

/// Up to this many coordinates the dense solver of every mode is faster than an iteration
/// from no start (measured: 2 ms against 8 ms at 106 coordinates). An iteration started from
/// good vectors (a nested level's, [`Lowest::start`]) converges in two or three steps and is
/// the faster one down to the block size (composite spacecraft, 109–146 coordinates:
/// 0.6–1 ms against 1–1.5 ms).
pub const DENSE_BELOW: usize = 160;

/// Above this fraction of non-zero entries a dense factorisation is cheaper than a sparse one.
const DENSE_ABOVE: f64 = 0.25;

/// A symmetric matrix as the lowest-mode solver holds it: sparse (its exact non-zero
/// entries) when they are few, dense otherwise. The polynomial bases' matrices are sparse:
/// the Legendre polynomials' orthogonality makes most integrals vanish exactly (and
/// [`crate::basis::Integrals`] sets their quadrature rounding to exact zeros), a plate's
/// matrices are block-banded, and the components couple only through the few functions with
/// a non-zero mean or moment.
pub enum Operator {
    /// Compressed sparse columns.
    Sparse(SparseColMat<usize, f64>),
    /// Dense.
    Dense(Mat<f64>),
}

impl Operator {
    /// The non-zero entries of a dense matrix.
    pub fn from_dense(a: &Mat<f64>) -> Self {
        let n = a.nrows();
        let nnz = (0..n)
            .map(|j| (0..n).filter(|&i| a[(i, j)] != 0.0).count())
            .sum::<usize>();
        if nnz as f64 >= DENSE_ABOVE * (n * n) as f64 {
            return Self::Dense(a.clone());
        }
        let mut triplets = Vec::with_capacity(nnz);
        for j in 0..n {
            for i in 0..n {
                if a[(i, j)] != 0.0 {
                    triplets.push(Triplet::new(i, j, a[(i, j)]));
                }
            }
        }
        Self::from_triplets(n, &triplets)
    }

    /// An n × n matrix from its entries, those at the same (i, j) summed (an assembly adds
    /// several components' contributions to one entry: a child beam's to its parent's
    /// coordinates and the hub's). Both routes sum: faer's triplet constructor does, and so
    /// must the dense one (it overwrote, and a beam-on-beam model's mass matrix came out
    /// indefinite: issue 37).
    pub fn from_triplets(n: usize, triplets: &[Triplet<usize, usize, f64>]) -> Self {
        let dense = || {
            let mut a = Mat::zeros(n, n);
            for t in triplets {
                a[(t.row, t.col)] += t.val;
            }
            Self::Dense(a)
        };
        if triplets.len() as f64 >= DENSE_ABOVE * (n * n) as f64 {
            return dense();
        }
        match SparseColMat::try_new_from_triplets(n, n, triplets) {
            Ok(s) => Self::Sparse(s),
            Err(_) => dense(),
        }
    }

    /// The order n.
    pub fn order(&self) -> usize {
        match self {
            Self::Sparse(s) => s.nrows(),
            Self::Dense(d) => d.nrows(),
        }
    }

    /// The entry (i, j) (zero when not stored).
    fn get(&self, i: usize, j: usize) -> f64 {
        match self {
            Self::Sparse(s) => {
                let rows = s.row_idx_of_col_raw(j);
                rows.binary_search(&i).map_or(0.0, |p| s.val_of_col(j)[p])
            }
            Self::Dense(d) => d[(i, j)],
        }
    }

    /// Every non-zero entry (i, j, a_ij), column by column.
    pub fn entries(&self) -> Vec<(usize, usize, f64)> {
        match self {
            Self::Sparse(s) => (0..s.ncols())
                .flat_map(|j| {
                    let (rows, vals) = (s.row_idx_of_col_raw(j), s.val_of_col(j));
                    rows.iter().zip(vals).map(move |(&i, &v)| (i, j, v))
                })
                .collect(),
            Self::Dense(d) => (0..d.ncols())
                .flat_map(|j| (0..d.nrows()).map(move |i| (i, j, d[(i, j)])))
                .filter(|e| e.2 != 0.0)
                .collect(),
        }
    }

    /// The sub-matrix of rows and columns `idx` (strictly increasing), in that order.
    pub fn select(&self, idx: &[usize]) -> Self {
        debug_assert!(idx.windows(2).all(|w| w[0] < w[1]));
        match self {
            Self::Dense(d) => Self::Dense(Mat::from_fn(idx.len(), idx.len(), |i, j| {
                d[(idx[i], idx[j])]
            })),
            Self::Sparse(a) => {
                let mut pos = vec![usize::MAX; a.nrows()];
                for (new, &old) in idx.iter().enumerate() {
                    pos[old] = new;
                }
                let (mut col_ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
                for &j in idx {
                    let (r, v) = (a.row_idx_of_col_raw(j), a.val_of_col(j));
                    for (&i, &x) in r.iter().zip(v) {
                        if pos[i] != usize::MAX {
                            rows.push(pos[i]);
                            vals.push(x);
                        }
                    }
                    col_ptr.push(rows.len());
                }
                // Increasing idx keeps every column's rows sorted.
                let n = idx.len();
                let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
                Self::Sparse(SparseColMat::new(symbolic, vals))
            }
        }
    }

    /// The whole matrix, dense.
    fn to_dense(&self) -> Mat<f64> {
        match self {
            Self::Sparse(s) => s.to_dense(),
            Self::Dense(d) => d.clone(),
        }
    }

    /// A X.
    fn apply(&self, x: &Mat<f64>) -> Mat<f64> {
        match self {
            Self::Sparse(s) => {
                // Hand-written rather than faer's sparse × dense product, which walks each
                // of the block's columns separately: here the block is transposed once so
                // that every stored entry a_ji scales a contiguous row of X (p values) into
                // row i of Y, for the symmetric A (A X)_i = Σ_j a_ji X_j — 2–3× faster for
                // the 20–50 columns of the subspace iteration.
                let (n, p) = (x.nrows(), x.ncols());
                let mut xt = vec![0.0; n * p];
                for c in 0..p {
                    for j in 0..n {
                        xt[j * p + c] = x[(j, c)];
                    }
                }
                let mut yt = vec![0.0; n * p];
                for (i, yi) in yt.chunks_exact_mut(p).enumerate() {
                    let (rows, vals) = (s.row_idx_of_col_raw(i), s.val_of_col(i));
                    for (&j, &v) in rows.iter().zip(vals) {
                        let xj = &xt[j * p..(j + 1) * p];
                        for (y, x) in yi.iter_mut().zip(xj) {
                            *y += v * x;
                        }
                    }
                }
                Mat::from_fn(n, p, |i, c| yt[i * p + c])
            }
            Self::Dense(d) => d * x,
        }
    }
}

/// A Cholesky factor of A = K + s M for the shift-invert iteration: sparse with a
/// fill-reducing ordering when both matrices are sparse, dense otherwise.
enum ShiftInvert {
    Sparse(SparseLlt<usize, f64>),
    Dense(faer::linalg::solvers::Llt<f64>),
}

impl ShiftInvert {
    /// None when A is not positive definite in rounding.
    fn new(k: &Operator, m: &Operator, s: f64) -> Option<Self> {
        let n = k.order();
        match (k, m) {
            (Operator::Sparse(ks), Operator::Sparse(ms)) => {
                // The lower triangle of K + sM, column by column (both columns' rows are
                // sorted: a merge).
                let (mut col_ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
                for j in 0..n {
                    let (kr, kv) = (ks.row_idx_of_col_raw(j), ks.val_of_col(j));
                    let (mr, mv) = (ms.row_idx_of_col_raw(j), ms.val_of_col(j));
                    let (mut a, mut b) = (
                        kr.partition_point(|&i| i < j),
                        mr.partition_point(|&i| i < j),
                    );
                    while a < kr.len() || b < mr.len() {
                        let (ia, ib) = (
                            kr.get(a).copied().unwrap_or(usize::MAX),
                            mr.get(b).copied().unwrap_or(usize::MAX),
                        );
                        let i = ia.min(ib);
                        let mut v = 0.0;
                        if ia == i {
                            v += kv[a];
                            a += 1;
                        }
                        if ib == i {
                            v += s * mv[b];
                            b += 1;
                        }
                        rows.push(i);
                        vals.push(v);
                    }
                    col_ptr.push(rows.len());
                }
                let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
                let a = SparseColMat::new(symbolic, vals);
                Some(Self::Sparse(a.sp_cholesky(Side::Lower).ok()?))
            }
            _ => {
                let (kd, md) = (k.to_dense(), m.to_dense());
                let a = Mat::from_fn(n, n, |i, j| kd[(i, j)] + s * md[(i, j)]);
                Some(Self::Dense(a.llt(Side::Lower).ok()?))
            }
        }
    }

    fn solve_in_place(&self, x: &mut Mat<f64>) {
        match self {
            Self::Sparse(f) => f.solve_in_place(x.as_mut()),
            Self::Dense(f) => f.solve_in_place(x.as_mut()),
        }
    }
}

/// M-orthonormalises the columns of `y` by Cholesky QR, twice ("CholQR2": G = YᵀMY = LLᵀ,
/// Y ← Y L⁻ᵀ; the second pass removes the first one's loss of orthogonality), all in
/// matrix products. When G is singular in rounding (a column dependent on the others) it
/// falls back on modified Gram–Schmidt, which leaves such a column at rounding length (the
/// Rayleigh–Ritz step then leaves it out). Returns M·Y, updated alongside Y.
fn m_orthonormalize(m: &Operator, y: &mut Mat<f64>) -> Mat<f64> {
    let mut my = m.apply(y);
    for _ in 0..2 {
        let g = y.transpose() * &my;
        let p = g.nrows();
        let g = Mat::from_fn(p, p, |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
        match g.llt(Side::Lower) {
            Ok(llt) => {
                // Y L⁻ᵀ = (L⁻¹ Yᵀ)ᵀ.
                let apply = |a: &Mat<f64>| {
                    let mut t = a.transpose().to_owned();
                    llt.L().solve_lower_triangular_in_place(t.as_mut());
                    t.transpose().to_owned()
                };
                let (ny, nmy) = (apply(y), apply(&my));
                // A factor whose pivots underflowed (G singular but for rounding) leaves
                // non-finite columns: Gram–Schmidt on the block as it was instead.
                if !all_finite(&ny) || !all_finite(&nmy) {
                    gram_schmidt(y, &mut my);
                    break;
                }
                (*y, my) = (ny, nmy);
            }
            Err(_) => {
                gram_schmidt(y, &mut my);
                break;
            }
        }
    }
    my
}

/// Every entry of `a` is finite.
fn all_finite(a: &Mat<f64>) -> bool {
    a.col_iter().all(|c| c.iter().all(|v| v.is_finite()))
}

/// Modified Gram–Schmidt in the M inner product, twice ("twice is enough"), on Y and M·Y.
fn gram_schmidt(y: &mut Mat<f64>, my: &mut Mat<f64>) {
    let (n, p) = (y.nrows(), y.ncols());
    let length = |y: &Mat<f64>, my: &Mat<f64>, j: usize| -> f64 {
        (0..n).map(|r| y[(r, j)] * my[(r, j)]).sum::<f64>().sqrt()
    };
    for _ in 0..2 {
        for j in 0..p {
            let before = length(y, my, j);
            for i in 0..j {
                let c: f64 = (0..n).map(|r| y[(r, i)] * my[(r, j)]).sum();
                for r in 0..n {
                    y[(r, j)] -= c * y[(r, i)];
                    my[(r, j)] -= c * my[(r, i)];
                }
            }
            let norm = length(y, my, j);
            if norm > DEPENDENT_LENGTH * before && norm.is_finite() {
                for r in 0..n {
                    y[(r, j)] /= norm;
                    my[(r, j)] /= norm;
                }
            } else {
                // Dependent on the columns before it but for rounding (normalised, that
                // rounding would be a vector neither M-orthogonal to them nor meaningful), or
                // not finite: zero, so that the Rayleigh–Ritz step leaves it out
                // ([`shifted_ritz`]).
                for r in 0..n {
                    y[(r, j)] = 0.0;
                    my[(r, j)] = 0.0;
                }
            }
        }
    }
}

/// The fraction of its length a column must keep through [`gram_schmidt`]'s projections not
/// to count as dependent on the columns before it.
const DEPENDENT_LENGTH: f64 = 1e-10;

/// Subspace iterations at most in [`lowest`].
pub const LOWEST_MAX_ITERATIONS: usize = 400;

/// Iterations with every wanted eigenvalue settled after which [`lowest_of`] accepts a
/// residual up to [`FLOOR_RESIDUAL`].
const STALLED_ITERATIONS: usize = 3;

/// The relative residual accepted at the rounding floor (see [`STALLED_ITERATIONS`]).
const FLOOR_RESIDUAL: f64 = 1e-6;

/// An eigenvalue's change between iterations, relative to the largest wanted, that counts
/// as settled at the rounding floor (where λ jitters by a few 1e-13).
const STALLED_CHANGE: f64 = 1e-11;

/// The `count` lowest eigenpairs of K φ = λ M φ (K symmetric positive semi-definite, M
/// symmetric positive definite) without solving for the others: shift-invert subspace
/// iteration with Rayleigh–Ritz (Bathe's subspace iteration; e.g. K.-J. Bathe, *Finite
/// Element Procedures*, §11.6), for the "fast lowest-mode solves" a large model needs.
///
/// * Shift σ = −s, s = 0.01 · min(K_ii/M_ii) over the coordinates with K_ii > 0 (or 1), so
///   that A = K + sM is positive definite even with rigid-body modes (λ = 0); A = LLᵀ once,
///   by faer's sparse Cholesky (fill-reducing ordering) when the matrices are sparse
///   ([`Operator`]), by the dense one otherwise.
/// * A block X of p = min(n, 2·count + 8) vectors: Y = A⁻¹ M X, then the p × p problem
///   (YᵀKY) z = λ (YᵀMY) z by [`generalized_symmetric`] and X = Y Z, M-orthonormal. The
///   error of λ_j falls by ((λ_j + s)/(λ_{p+1} + s))² per iteration.
/// * Stops when each wanted λ has settled to 1e-13 and its residual ‖K x − λ M x‖ is below
///   1e-8 of ‖K x‖ + |λ| ‖M x‖ (the eigenvalue's error is quadratic in it; the high-order
///   polynomial bases' conditioning leaves a rounding floor near 1e-11 on small models, up
///   to 1e-7 at hundreds of modes: once every λ has stayed settled for
///   three iterations, a residual up to 1e-6 is accepted).
///
/// Falls back on the dense [`generalized_symmetric`] when p would not be smaller than n or n
/// is at most [`DENSE_BELOW`].
/// Returns λ ascending and Φ (n × count) with ΦᵀMΦ = I.
pub fn lowest(k: &Mat<f64>, m: &Mat<f64>, count: usize) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
    let n = m.nrows();
    if dense_route(n, 0, count, false) {
        return dense_lowest(k, m, 0, count.min(n));
    }
    lowest_of(
        &Operator::from_dense(k),
        &Operator::from_dense(m),
        count,
        &Lowest::default(),
    )
}

/// What [`lowest_of`] knows beyond the pencil.
#[derive(Debug, Clone, Copy, Default)]
pub struct Lowest<'a> {
    /// The first `null_space` coordinates span K's null space exactly (K's rows and
    /// columns there are zero: a free hub's six rigid-body coordinates). The eigenpairs
    /// returned are then the lowest of the rest — those M-orthogonal to that space — whose
    /// leading coordinates follow from the others, q_r = −M_rr⁻¹ M_re q_e.
    pub null_space: usize,
    /// Vectors to start the iteration from (n × c, c ≤ the block size): approximations of
    /// the wanted eigenvectors, e.g. those of a nested smaller model padded with zeros.
    pub start: Option<&'a Mat<f64>>,
}

/// True when [`lowest_of`] solves densely: the block would hold half the modes or more, or
/// the model is small and there is no start. A block near the whole space gains nothing over
/// the dense solve, and shift-invert crushes its columns' stiff components by (λ + s)⁻¹ —
/// over a spectrum of many decades they become dependent in rounding (500 modes of the
/// composite spacecraft's 1 014 coordinates: a 1 008-vector block whose reduced mass matrix
/// had zero pivots).
fn dense_route(n: usize, r: usize, count: usize, started: bool) -> bool {
    let count = count.min(n - r);
    let p = (2 * count + 8).min(n - r);
    2 * p >= n - r || (n <= DENSE_BELOW && !started)
}

/// The dense route: every mode, then the `count` lowest.
fn dense_lowest(
    k: &Mat<f64>,
    m: &Mat<f64>,
    r: usize,
    count: usize,
) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
    if r == 0 {
        let (lambda, phi) = generalized_symmetric(k, m)?;
        Ok((lambda[..count].to_vec(), phi.subcols(0, count).to_owned()))
    } else {
        condensed(k, m, r, count)
    }
}

/// [`lowest`] for a pencil held as [`Operator`]s, with a known null space deflated and an
/// optional start.
///
/// The null space: every iterate is projected onto the M-orthogonal complement of the
/// first r coordinates, X ← X − E M_rr⁻¹ (E ᵀ M X) (only X's first r rows change), after
/// each shift-invert step (which would otherwise amplify the rigid-body directions by
/// 1/s). The iteration then needs no room for the r zero eigenvalues. The dense route
/// condenses them out instead: (K_ee, M_ee − M_er M_rr⁻¹ M_re) — never the whole singular
/// pencil, whose M-Cholesky route loses the low modes' digits (1 % on the composite
/// spacecraft's 434 coordinates).
pub fn lowest_of(
    ko: &Operator,
    mo: &Operator,
    count: usize,
    with: &Lowest,
) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
    let n = mo.order();
    let r = with.null_space.min(n);
    let count = count.min(n - r);
    let p = (2 * count + 8).min(n - r);
    if count == 0 {
        return Ok((Vec::new(), Mat::zeros(n, 0)));
    }
    if dense_route(n, r, count, with.start.is_some()) {
        return dense_lowest(&ko.to_dense(), &mo.to_dense(), r, count);
    }
    let kdiag: Vec<f64> = (0..n).map(|i| ko.get(i, i)).collect();
    let mdiag: Vec<f64> = (0..n).map(|i| mo.get(i, i)).collect();
    let deflation = if r > 0 {
        let mrr = Mat::from_fn(r, r, |i, j| mo.get(i, j));
        let llt = mrr
            .llt(Side::Lower)
            .map_err(|_| RitzError::MassNotPositiveDefinite { pivot: 0 })?;
        let e = Mat::from_fn(n, r, |i, j| if i == j { 1.0 } else { 0.0 });
        Some((llt, mo.apply(&e)))
    } else {
        None
    };
    // X ← X − E M_rr⁻¹ (M X)[0..r], M X alongside.
    let deflate = |x: &mut Mat<f64>, mx: &mut Mat<f64>| {
        if let Some((llt, mcols)) = &deflation {
            let mut c = mx.subrows(0, r).to_owned();
            llt.solve_in_place(c.as_mut());
            for j in 0..x.ncols() {
                for i in 0..r {
                    x[(i, j)] -= c[(i, j)];
                }
            }
            *mx -= mcols * &c;
        }
    };
    // The shift: 1 % of the smallest diagonal Rayleigh quotient K_ii/M_ii (an upper bound of
    // λ₁), so that σ sits below the wanted eigenvalues without drowning them: the
    // convergence factor (λ_j + s)/(λ_{p+1} + s) is then ≈ λ_j/λ_{p+1}. (A shift scaled by the
    // mean quotient — dominated by the stiff high-order functions — stalls the iteration.)
    // Raised while K + sM fails to factorise in rounding (rigid-body modes), up to the
    // safe 1e-3 · mean quotient.
    let ratios: Vec<f64> = (0..n)
        .filter(|&i| kdiag[i] > 0.0 && mdiag[i] > 0.0)
        .map(|i| kdiag[i] / mdiag[i])
        .collect();
    let smallest = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let mean = ratios.iter().sum::<f64>() / ratios.len().max(1) as f64;
    let shifts = if ratios.is_empty() {
        vec![1.0]
    } else {
        vec![1e-2 * smallest, smallest, 1e2 * smallest, 1e-3 * mean]
    };
    let Some((s, factor)) = shifts
        .iter()
        .find_map(|&s| ShiftInvert::new(ko, mo, s).map(|f| (s, f)))
    else {
        let (kd, md) = (ko.to_dense(), mo.to_dense());
        let a = Mat::from_fn(n, n, |i, j| {
            kd[(i, j)] + shifts[shifts.len() - 1] * md[(i, j)]
        });
        return Err(RitzError::MassNotPositiveDefinite {
            pivot: first_bad_pivot(&a),
        });
    };
    // A deterministic start block: the given vectors, then the unit vectors of the
    // coordinates with the smallest K_ii/M_ii (those the low modes live on), plus a smooth
    // spread over all coordinates so that no wanted mode is orthogonal to the start.
    let mut order: Vec<usize> = (r..n).collect();
    order.sort_by(|&i, &j| (kdiag[i] / mdiag[i]).total_cmp(&(kdiag[j] / mdiag[j])));
    let given = with.start.map_or(0, |v| v.ncols().min(p));
    let mut x = Mat::from_fn(n, p, |i, j| match with.start {
        Some(v) if j < given => v[(i, j)],
        _ => 1e-3 * ((i + 1) as f64 * (j + 1) as f64 * 0.618).sin(),
    });
    for (j, &i) in order.iter().take(p - given).enumerate() {
        x[(i, given + j)] += 1.0;
    }
    let mut previous = vec![f64::INFINITY; count];
    let mut stalled = 0;
    let mut mx = mo.apply(&x);
    for _ in 0..LOWEST_MAX_ITERATIONS {
        let mut y = mx;
        factor.solve_in_place(&mut y);
        // With a small shift the rigid-body directions dominate every column of A⁻¹MX;
        // M-orthonormalising the block keeps the reduced problem well conditioned. The
        // products M·Y and K·Y are formed once per iteration and carried through Z.
        if deflation.is_some() {
            let mut my = mo.apply(&y);
            deflate(&mut y, &mut my);
        }
        let my = m_orthonormalize(mo, &mut y);
        let ky = ko.apply(&y);
        let kr = y.transpose() * &ky;
        let mr = y.transpose() * &my;
        let (lambda, z) = shifted_ritz(&kr, &mr, s)?;
        if lambda.len() < count {
            // The block lost so many dependent columns that it no longer holds the modes.
            return Err(RitzError::EigenNoConvergence);
        }
        x = &y * &z;
        let zc = z.subcols(0, count);
        let kx = &ky * zc;
        mx = &my * &z;
        let scale = lambda[count - 1].abs().max(s);
        let all_settled =
            (0..count).all(|j| (lambda[j] - previous[j]).abs() <= STALLED_CHANGE * scale);
        stalled = if all_settled { stalled + 1 } else { 0 };
        // The residual's floor is the bases' conditioning times rounding (1e-7 for the
        // composite spacecraft's hundredth mode at 450 coordinates): once every eigenvalue
        // has stayed settled (to STALLED_CHANGE) for STALLED_ITERATIONS iterations, a residual
        // up to FLOOR_RESIDUAL is that floor, not a lack of convergence (the eigenvalue's error is
        // its square over the gap to the next one).
        let bound = if stalled >= STALLED_ITERATIONS {
            FLOOR_RESIDUAL
        } else {
            1e-8
        };
        let settle = if stalled >= STALLED_ITERATIONS {
            STALLED_CHANGE
        } else {
            1e-13
        };
        let converged = (0..count).all(|j| {
            let (mut rr, mut kn, mut mn) = (0.0_f64, 0.0_f64, 0.0_f64);
            for i in 0..n {
                rr += (kx[(i, j)] - lambda[j] * mx[(i, j)]).powi(2);
                kn += kx[(i, j)].powi(2);
                mn += mx[(i, j)].powi(2);
            }
            let settled = (lambda[j] - previous[j]).abs() <= settle * scale;
            settled
                && rr.sqrt() <= bound * (kn.sqrt() + lambda[j].abs() * mn.sqrt()).max(s * mn.sqrt())
        });
        previous.copy_from_slice(&lambda[..count]);
        if converged {
            return Ok((lambda[..count].to_vec(), x.subcols(0, count).to_owned()));
        }
    }
    Err(RitzError::EigenNoConvergence)
}

/// The dense route of [`lowest_of`] with a null space of the first r coordinates: the
/// pencil (K_ee, M̃), M̃ = M_ee − M_er X, X = M_rr⁻¹ M_re, and q_r = −X q_e.
fn condensed(
    k: &Mat<f64>,
    m: &Mat<f64>,
    r: usize,
    count: usize,
) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
    let n = m.nrows();
    let ne = n - r;
    let mee = m.submatrix(r, r, ne, ne);
    let kee = k.submatrix(r, r, ne, ne).to_owned();
    let mer = m.submatrix(r, 0, ne, r);
    let llt = m
        .submatrix(0, 0, r, r)
        .to_owned()
        .llt(Side::Lower)
        .map_err(|_| RitzError::MassNotPositiveDefinite { pivot: 0 })?;
    let mut x = mer.transpose().to_owned();
    llt.solve_in_place(x.as_mut());
    let corr = mer * &x;
    let mt = Mat::from_fn(ne, ne, |i, j| {
        mee[(i, j)] - 0.5 * (corr[(i, j)] + corr[(j, i)])
    });
    let (lambda, phi) = generalized_symmetric(&kee, &mt)?;
    let qr = -(&x * phi.subcols(0, count));
    let shapes = Mat::from_fn(
        n,
        count,
        |i, j| {
            if i < r {
                qr[(i, j)]
            } else {
                phi[(i - r, j)]
            }
        },
    );
    Ok((lambda[..count].to_vec(), shapes))
}

/// The reduced problem (K_r, M_r), shifted like A: with rigid-body modes K_r is singular to
/// rounding, and its inverse route would spread that rounding over every mode. λ ascending
/// and Z with Zᵀ M_r Z = I.
fn shifted_ritz(kr: &Mat<f64>, mr: &Mat<f64>, s: f64) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
    let p = kr.nrows();
    let sym = |a: &Mat<f64>, b: &Mat<f64>, c: f64| {
        Mat::from_fn(p, p, |i, j| {
            0.5 * (a[(i, j)] + a[(j, i)]) + c * 0.5 * (b[(i, j)] + b[(j, i)])
        })
    };
    // The block is M-orthonormal, so YᵀMY ≈ I but for columns the orthonormalisation left at
    // rounding length (dependent on the others): those are left out of the reduced problem
    // and of the block (Z has a row of zeros for each, and one column fewer).
    let keep: Vec<usize> = (0..p).filter(|&j| mr[(j, j)] > DEPENDENT_COLUMN).collect();
    if keep.len() < p {
        let q = keep.len();
        let pick = |a: &Mat<f64>| Mat::from_fn(q, q, |i, j| a[(keep[i], keep[j])]);
        let (lambda, zk) = shifted_ritz(&pick(kr), &pick(mr), s)?;
        let mut z = Mat::zeros(p, q);
        for (i, &r) in keep.iter().enumerate() {
            for j in 0..q {
                z[(r, j)] = zk[(i, j)];
            }
        }
        return Ok((lambda, z));
    }
    let (shifted, z) = generalized_symmetric(&sym(kr, mr, s), &sym(mr, mr, 0.0))?;
    Ok((shifted.iter().map(|l| l - s).collect(), z))
}

/// The squared M-length below which a column of an M-orthonormalised block is taken as
/// dependent on the others (the orthonormal ones have 1).
const DEPENDENT_COLUMN: f64 = 1e-8;

#[cfg(test)]
mod tests {
    use super::*;

    /// Entries at the same place are summed on both routes: the sparse one (few entries)
    /// and the dense one (many), against the sum done by hand.
    #[test]
    fn triplets_at_one_place_are_summed() {
        for n in [2, 40] {
            // Every entry twice (dense route for n = 2: 8 triplets ≥ 25 % of 4), or only the
            // diagonal twice (sparse route for n = 40: 80 triplets < 400).
            let mut t = Vec::new();
            for i in 0..n {
                for j in 0..n {
                    if n == 2 || i == j {
                        t.push(Triplet::new(i, j, (1 + i + j) as f64));
                        t.push(Triplet::new(i, j, 0.5));
                    }
                }
            }
            let op = Operator::from_triplets(n, &t);
            assert_eq!(matches!(op, Operator::Dense(_)), n == 2);
            for i in 0..n {
                for j in 0..n {
                    let want = if n == 2 || i == j {
                        (1 + i + j) as f64 + 0.5
                    } else {
                        0.0
                    };
                    assert_eq!(op.get(i, j), want, "n {n} ({i}, {j})");
                }
            }
        }
    }
}
