//! Small fixed-size vectors and matrices in the structure frame.
//!
//! Hand-written: the library needs a dozen 3-vector operations; faer (used for the large
//! matrices) has no fixed-size types, and nalgebra would double the build time for them.

use serde::Serialize;
use std::ops::{Add, Mul, Neg, Sub};

/// A 3-vector (structure-frame components unless stated otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Vec3(pub [f64; 3]);

impl Vec3 {
    /// The zero vector.
    pub const ZERO: Vec3 = Vec3([0.0; 3]);

    /// From components.
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3([x, y, z])
    }

    /// Unit vector along structure axis i.
    pub fn unit(i: usize) -> Self {
        let mut v = [0.0; 3];
        v[i] = 1.0;
        Vec3(v)
    }

    /// Dot product.
    pub fn dot(self, o: Vec3) -> f64 {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }

    /// Cross product self × o.
    pub fn cross(self, o: Vec3) -> Vec3 {
        let [a, b, c] = self.0;
        let [x, y, z] = o.0;
        Vec3([b * z - c * y, c * x - a * z, a * y - b * x])
    }

    /// Euclidean norm.
    pub fn norm(self) -> f64 {
        self.dot(self).sqrt()
    }

    /// This vector divided by its norm, computed scale-safely: the vector is first divided
    /// by its largest component's magnitude, so that no square overflows or underflows
    /// (`[0, 0, 1e200]` and `[0, 0, 1e-310]` both give `[0, 0, 1]`). The zero vector gives
    /// NaN components; callers check for it.
    pub fn normalized(self) -> Vec3 {
        let big = self.0.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        // Divide (not multiply by 1/big): the reciprocal of a subnormal overflows.
        let s = Vec3(self.0.map(|x| x / big));
        let n = s.norm();
        Vec3(s.0.map(|x| x / n))
    }

    /// Component i.
    pub fn get(self, i: usize) -> f64 {
        self.0[i]
    }

    /// Outer product self ⊗ o.
    pub fn outer(self, o: Vec3) -> Mat3 {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.0[i] * o.0[j];
            }
        }
        Mat3(m)
    }

    /// The skew matrix S(self) with S(a) b = a × b.
    pub fn skew(self) -> Mat3 {
        let [x, y, z] = self.0;
        Mat3([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    }

    /// True if every component is finite.
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    fn add(self, o: Vec3) -> Vec3 {
        Vec3([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
}

impl Sub for Vec3 {
    type Output = Vec3;
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
}

impl Neg for Vec3 {
    type Output = Vec3;
    fn neg(self) -> Vec3 {
        self * -1.0
    }
}

impl Mul<f64> for Vec3 {
    type Output = Vec3;
    fn mul(self, s: f64) -> Vec3 {
        Vec3([self.0[0] * s, self.0[1] * s, self.0[2] * s])
    }
}

/// A 3×3 matrix, row-major.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Mat3(pub [[f64; 3]; 3]);

impl Mat3 {
    /// The identity.
    pub const IDENTITY: Mat3 = Mat3([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    /// The zero matrix.
    pub const ZERO: Mat3 = Mat3([[0.0; 3]; 3]);

    /// Diagonal matrix.
    pub fn diag(d: [f64; 3]) -> Mat3 {
        Mat3([[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]])
    }

    /// Symmetric matrix from [xx, yy, zz, xy, xz, yz].
    pub fn symmetric(v: [f64; 6]) -> Mat3 {
        Mat3([[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]])
    }

    /// Transpose.
    pub fn transpose(self) -> Mat3 {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.0[j][i];
            }
        }
        Mat3(m)
    }

    /// Matrix product.
    pub fn matmul(self, o: Mat3) -> Mat3 {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| self.0[i][k] * o.0[k][j]).sum();
            }
        }
        Mat3(m)
    }

    /// Matrix–vector product.
    pub fn apply(self, v: Vec3) -> Vec3 {
        Vec3(std::array::from_fn(|i| {
            (0..3).map(|k| self.0[i][k] * v.0[k]).sum()
        }))
    }

    /// Trace.
    pub fn trace(self) -> f64 {
        self.0[0][0] + self.0[1][1] + self.0[2][2]
    }

    /// Entry (i, j).
    pub fn get(self, i: usize, j: usize) -> f64 {
        self.0[i][j]
    }

    /// Eigenvalues (ascending) and eigenvectors (columns) of a symmetric matrix
    /// (cyclic Jacobi: exact to rounding for 3×3, no allocation).
    pub fn symmetric_eigen(self) -> ([f64; 3], Mat3) {
        let mut a = self.0;
        let mut v = Mat3::IDENTITY.0;
        for _ in 0..50 {
            let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
            if off <= 1e-32 * (a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2)) {
                break;
            }
            for (p, q) in [(0, 1), (0, 2), (1, 2)] {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..3 {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..3 {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
        let mut idx = [0, 1, 2];
        idx.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
        let vals = [a[idx[0]][idx[0]], a[idx[1]][idx[1]], a[idx[2]][idx[2]]];
        let vecs = Mat3(std::array::from_fn(|r| {
            std::array::from_fn(|c| v[r][idx[c]])
        }));
        (vals, vecs)
    }
}

impl Add for Mat3 {
    type Output = Mat3;
    fn add(self, o: Mat3) -> Mat3 {
        Mat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| self.0[i][j] + o.0[i][j])
        }))
    }
}

impl Sub for Mat3 {
    type Output = Mat3;
    fn sub(self, o: Mat3) -> Mat3 {
        Mat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| self.0[i][j] - o.0[i][j])
        }))
    }
}

impl Mul<f64> for Mat3 {
    type Output = Mat3;
    fn mul(self, s: f64) -> Mat3 {
        Mat3(self.0.map(|r| r.map(|v| v * s)))
    }
}

/// Σ a_i b_i with four partial sums (lets the compiler use vector registers).
pub fn dot4(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for q in 0..4 {
            acc[q] += x[q] * y[q];
        }
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// The lower Cholesky factor L (row-major k × k, L Lᵀ = A) of the symmetric k × k matrix `a`
/// (row-major, lower triangle read), or the first pivot that is not above `min_pivot`.
/// Hand-written for the small dense matrices of the Monte Carlo statistics (a correlation
/// matrix, the rank regression's normal equations): a few dozen rows, where a call into a
/// linear-algebra crate costs more than the arithmetic.
pub fn cholesky_lower(a: &[f64], k: usize, min_pivot: f64) -> Result<Vec<f64>, f64> {
    let mut l = vec![0.0; k * k];
    for i in 0..k {
        for j in 0..=i {
            let s: f64 = (0..j).map(|m| l[i * k + m] * l[j * k + m]).sum();
            if i == j {
                let d = a[i * k + i] - s;
                if d <= min_pivot {
                    return Err(d);
                }
                l[i * k + i] = d.sqrt();
            } else {
                l[i * k + j] = (a[i * k + j] - s) / l[j * k + j];
            }
        }
    }
    Ok(l)
}
