//! The symmetric-definite generalized eigenproblem K φ = λ M φ.

use super::RitzError;
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
