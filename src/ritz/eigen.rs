//! The symmetric-definite generalized eigenproblem K φ = λ M φ.

use super::RitzError;
use faer::linalg::solvers::Solve;
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
    // Mass-normalise (φᵀMφ = 1), then one step of symmetric (Löwdin) re-orthonormalisation,
    // Φ ← Φ (I − ½E) with E = ΦᵀMΦ − I: the K-Cholesky route leaves the high modes
    // M-orthogonal only to ≈ 1e-10; this makes them orthonormal to rounding (error O(E²))
    // without favouring any mode.
    let phi = Mat::from_fn(n, n, |i, j| phi[(i, pairs[j].2)] / pairs[j].1.sqrt());
    let e = phi.transpose() * (m * &phi);
    let half = Mat::from_fn(n, n, |i, j| {
        let delta = if i == j { 1.0 } else { 0.0 };
        delta - 0.25 * (e[(i, j)] + e[(j, i)] - 2.0 * delta)
    });
    let phi = &phi * &half;
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

/// Modified Gram–Schmidt in the M inner product, twice ("twice is enough"): the columns of
/// `y` become M-orthonormal. A column that vanishes against the others is left at zero
/// length's rounding (the Rayleigh–Ritz step then gives it an arbitrary direction).
/// Returns M·Y, updated alongside Y.
fn m_orthonormalize(m: &Mat<f64>, y: &mut Mat<f64>) -> Mat<f64> {
    let (n, p) = (y.nrows(), y.ncols());
    let mut my = m * &*y;
    for _ in 0..2 {
        for j in 0..p {
            for i in 0..j {
                let c: f64 = (0..n).map(|r| y[(r, i)] * my[(r, j)]).sum();
                for r in 0..n {
                    y[(r, j)] -= c * y[(r, i)];
                    my[(r, j)] -= c * my[(r, i)];
                }
            }
            let norm: f64 = (0..n).map(|r| y[(r, j)] * my[(r, j)]).sum::<f64>().sqrt();
            if norm > 0.0 && norm.is_finite() {
                for r in 0..n {
                    y[(r, j)] /= norm;
                    my[(r, j)] /= norm;
                }
            }
        }
    }
    my
}

/// Subspace iterations at most in [`lowest`].
pub const LOWEST_MAX_ITERATIONS: usize = 400;

/// The `count` lowest eigenpairs of K φ = λ M φ (K symmetric positive semi-definite, M
/// symmetric positive definite) without solving for the others: shift-invert subspace
/// iteration with Rayleigh–Ritz (Bathe's subspace iteration; e.g. K.-J. Bathe, *Finite
/// Element Procedures*, §11.6), for the "fast lowest-mode solves" a large model needs.
///
/// * Shift σ = −s, s = 0.01 · min(K_ii/M_ii) over the coordinates with K_ii > 0 (or 1), so
///   that A = K + sM is positive definite even with rigid-body modes (λ = 0); A = LLᵀ once.
/// * A block X of p = min(n, 2·count + 8) vectors: Y = A⁻¹ M X, then the p × p problem
///   (YᵀKY) z = λ (YᵀMY) z by [`generalized_symmetric`] and X = Y Z, M-orthonormal. The
///   error of λ_j falls by ((λ_j + s)/(λ_{p+1} + s))² per iteration.
/// * Stops when each wanted λ has settled to 1e-13 and its residual ‖K x − λ M x‖ is below
///   1e-8 of ‖K x‖ + |λ| ‖M x‖ (the eigenvalue's error is quadratic in it; the high-order
///   polynomial bases' conditioning leaves a rounding floor near 1e-11).
///
/// Falls back on the dense [`generalized_symmetric`] when p would not be smaller than n.
/// Returns λ ascending and Φ (n × count) with ΦᵀMΦ = I.
pub fn lowest(k: &Mat<f64>, m: &Mat<f64>, count: usize) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
    let n = m.nrows();
    let count = count.min(n);
    let p = (2 * count + 8).min(n);
    if p >= n {
        let (lambda, phi) = generalized_symmetric(k, m)?;
        let phi = phi.subcols(0, count).to_owned();
        return Ok((lambda[..count].to_vec(), phi));
    }
    // The shift: 1 % of the smallest diagonal Rayleigh quotient K_ii/M_ii (an upper bound of
    // λ₁), so that σ sits below the wanted eigenvalues without drowning them: the
    // convergence factor (λ_j + s)/(λ_{p+1} + s) is then ≈ λ_j/λ_{p+1}. (A shift scaled by the
    // mean quotient — dominated by the stiff high-order functions — stalls the iteration.)
    // Raised while K + sM fails to factorise in rounding (rigid-body modes), up to the
    // safe 1e-3 · mean quotient.
    let ratios: Vec<f64> = (0..n)
        .filter(|&i| k[(i, i)] > 0.0 && m[(i, i)] > 0.0)
        .map(|i| k[(i, i)] / m[(i, i)])
        .collect();
    let smallest = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let mean = ratios.iter().sum::<f64>() / ratios.len().max(1) as f64;
    let shifts = if ratios.is_empty() {
        vec![1.0]
    } else {
        vec![1e-2 * smallest, smallest, 1e2 * smallest, 1e-3 * mean]
    };
    let mut factored = None;
    for &s in &shifts {
        let a = Mat::from_fn(n, n, |i, j| k[(i, j)] + s * m[(i, j)]);
        if let Ok(llt) = a.llt(Side::Lower) {
            factored = Some((s, llt));
            break;
        }
    }
    let Some((s, llt)) = factored else {
        let a = Mat::from_fn(n, n, |i, j| {
            k[(i, j)] + shifts[shifts.len() - 1] * m[(i, j)]
        });
        return Err(RitzError::MassNotPositiveDefinite {
            pivot: first_bad_pivot(&a),
        });
    };
    // A deterministic start block: the unit vectors of the p coordinates with the smallest
    // K_ii/M_ii (those the low modes live on), plus a smooth spread over all coordinates so
    // that no wanted mode is orthogonal to the start.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| (k[(i, i)] / m[(i, i)]).total_cmp(&(k[(j, j)] / m[(j, j)])));
    let mut x = Mat::from_fn(n, p, |i, j| {
        1e-3 * ((i + 1) as f64 * (j + 1) as f64 * 0.618).sin()
    });
    for (j, &i) in order.iter().take(p).enumerate() {
        x[(i, j)] += 1.0;
    }
    let mut previous = vec![f64::INFINITY; count];
    let mut mx = m * &x;
    for _ in 0..LOWEST_MAX_ITERATIONS {
        let mut y = mx;
        llt.solve_in_place(y.as_mut());
        // With a small shift the rigid-body directions dominate every column of A⁻¹MX;
        // M-orthonormalising the block keeps the reduced problem well conditioned. The
        // products M·Y and K·Y are formed once per iteration and carried through Z.
        let my = m_orthonormalize(m, &mut y);
        let ky = k * &y;
        let kr = y.transpose() * &ky;
        let mr = y.transpose() * &my;
        // The reduced problem, shifted like A: with rigid-body modes YᵀKY is singular to
        // rounding, and its inverse route would spread that rounding over every mode.
        let sym = |a: &Mat<f64>, b: &Mat<f64>, c: f64| {
            Mat::from_fn(p, p, |i, j| {
                0.5 * (a[(i, j)] + a[(j, i)]) + c * 0.5 * (b[(i, j)] + b[(j, i)])
            })
        };
        let (shifted, z) = generalized_symmetric(&sym(&kr, &mr, s), &sym(&mr, &mr, 0.0))?;
        let lambda: Vec<f64> = shifted.iter().map(|l| l - s).collect();
        x = &y * &z;
        let kx = &ky * &z;
        mx = &my * &z;
        let scale = lambda[count - 1].abs().max(s);
        let converged = (0..count).all(|j| {
            let (mut r, mut kn, mut mn) = (0.0_f64, 0.0_f64, 0.0_f64);
            for i in 0..n {
                r += (kx[(i, j)] - lambda[j] * mx[(i, j)]).powi(2);
                kn += kx[(i, j)].powi(2);
                mn += mx[(i, j)].powi(2);
            }
            let settled = (lambda[j] - previous[j]).abs() <= 1e-13 * scale;
            settled
                && r.sqrt() <= 1e-8 * (kn.sqrt() + lambda[j].abs() * mn.sqrt()).max(s * mn.sqrt())
        });
        previous.copy_from_slice(&lambda[..count]);
        if converged {
            return Ok((lambda[..count].to_vec(), x.subcols(0, count).to_owned()));
        }
    }
    Err(RitzError::EigenNoConvergence)
}
