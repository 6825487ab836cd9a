//! The symmetric-definite generalized eigenproblem K φ = λ M φ.

use super::RitzError;
use faer::{Mat, Side};

/// Solves K φ = λ M φ for symmetric K and symmetric positive definite M.
///
/// Method: Jacobi scaling D = diag(M)^{-1/2}; Cholesky DMD = LLᵀ; the standard symmetric
/// problem L⁻¹(DKD)L⁻ᵀ y = λ y (faer); φ = D L⁻ᵀ y. The eigenvalues are then recomputed
/// as Rayleigh quotients λ = φᵀKφ / φᵀMφ: the symmetric solver's absolute error ε‖A‖
/// would otherwise cost the low modes digits when the spectrum spans many decades, while
/// the Rayleigh quotient's error is quadratic in the eigenvector's.
///
/// Returns λ ascending and Φ with ΦᵀMΦ = I.
pub fn generalized_symmetric(k: &Mat<f64>, m: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), RitzError> {
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
    let llt = ms.llt(Side::Lower).map_err(|_| RitzError::MassNotPositiveDefinite { pivot: first_bad_pivot(&ms) })?;
    let l = llt.L();
    // X = L⁻¹ K_s, then A = L⁻¹ Xᵀ = L⁻¹ K_s L⁻ᵀ.
    let mut x = ks;
    l.solve_lower_triangular_in_place(x.as_mut());
    let mut a = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(a.as_mut());
    let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let evd = a.self_adjoint_eigen(Side::Lower).map_err(|_| RitzError::EigenNoConvergence)?;
    let mut phi = evd.U().to_owned();
    l.transpose().solve_upper_triangular_in_place(phi.as_mut());
    for i in 0..n {
        for j in 0..n {
            phi[(i, j)] *= d[i];
        }
    }
    // Rayleigh quotients with the unscaled matrices.
    let kp = k * &phi;
    let mp = m * &phi;
    let mut pairs: Vec<(f64, usize)> = (0..n)
        .map(|j| {
            let num: f64 = (0..n).map(|i| phi[(i, j)] * kp[(i, j)]).sum();
            let den: f64 = (0..n).map(|i| phi[(i, j)] * mp[(i, j)]).sum();
            (num / den, j)
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let lambda = pairs.iter().map(|p| p.0).collect();
    let phi = Mat::from_fn(n, n, |i, j| phi[(i, pairs[j].1)]);
    Ok((lambda, phi))
}

/// First non-positive pivot of an unpivoted LDLᵀ, for the error message.
fn first_bad_pivot(m: &Mat<f64>) -> usize {
    let n = m.nrows();
    let mut a = m.clone();
    for k in 0..n {
        let p = a[(k, k)];
        if !(p > 0.0) {
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
