//! Rotations: the hub's attitude quaternion and the exponential map of the small rotation
//! vector that turns the root hinge's frame with the deformed base.

use crate::math::{Mat3, Vec3};

/// A unit quaternion [w, x, y, z] taking body components to inertial ones.
pub type Quaternion = [f64; 4];

/// The rotation matrix of a quaternion (normalised first: the integrator lets its norm drift
/// at the tolerance's level).
pub fn matrix(q: Quaternion) -> Mat3 {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    Mat3([
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ])
}

/// q̇ = ½ q ⊗ (0, ω) for the body-frame angular velocity ω.
pub fn rate(q: Quaternion, w: Vec3) -> Quaternion {
    let [a, b, c, d] = q;
    let [x, y, z] = w.0;
    [
        0.5 * (-b * x - c * y - d * z),
        0.5 * (a * x + c * z - d * y),
        0.5 * (a * y - b * z + d * x),
        0.5 * (a * z + b * y - c * x),
    ]
}

/// The unit quaternion of a rotation vector θ (axis × angle): [cos(|θ|/2), sin(|θ|/2) θ/|θ|].
pub fn from_rotation_vector(theta: Vec3) -> Quaternion {
    let angle = theta.norm();
    if angle < 1e-300 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let (s, c) = (0.5 * angle).sin_cos();
    let v = theta * (s / angle);
    [c, v.0[0], v.0[1], v.0[2]]
}

/// The Hamilton product a ⊗ b: the rotation b, then a (body-to-inertial quaternions: a
/// body's attitude a, and b a further rotation in its body axes).
pub fn product(a: Quaternion, b: Quaternion) -> Quaternion {
    let [a0, a1, a2, a3] = a;
    let [b0, b1, b2, b3] = b;
    [
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    ]
}

/// The rotation vector (axis × angle, |angle| ≤ π) of a quaternion.
pub fn rotation_vector(q: Quaternion) -> Vec3 {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    let (w, v) = if w < 0.0 {
        (-w, Vec3::new(-x, -y, -z))
    } else {
        (w, Vec3::new(x, y, z))
    };
    let s = v.norm();
    if s < 1e-300 {
        return Vec3::ZERO;
    }
    let angle = 2.0 * s.atan2(w);
    v * (angle / s)
}

/// The coefficient functions of the exponential map in s = |θ|²:
/// a = sin x / x, b = (1 − cos x)/x², c = (x − sin x)/x³ and b' = db/ds, c' = dc/ds.
struct Coefficients {
    a: f64,
    b: f64,
    c: f64,
    db: f64,
    dc: f64,
}

fn coefficients(s: f64) -> Coefficients {
    if s < 1.0 {
        // Alternating series Σ (−1)^k s^k/(2k + j)!: 14 terms are exact to rounding for s < 1.
        let (mut a, mut b, mut c, mut db, mut dc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let mut pow = 1.0; // s^k
        let mut prev = 1.0; // s^(k−1)
        let mut fact = 1.0; // (2k + 1)!
        for k in 0..14 {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            let f1 = fact;
            let f2 = f1 * (2 * k + 2) as f64;
            let f3 = f2 * (2 * k + 3) as f64;
            a += sign * pow / f1;
            b += sign * pow / f2;
            c += sign * pow / f3;
            if k > 0 {
                db += sign * k as f64 * prev / f2;
                dc += sign * k as f64 * prev / f3;
                prev *= s;
            }
            pow *= s;
            fact = f3;
        }
        Coefficients { a, b, c, db, dc }
    } else {
        let x = s.sqrt();
        let (sn, cs) = x.sin_cos();
        Coefficients {
            a: sn / x,
            b: (1.0 - cs) / s,
            c: (x - sn) / (x * s),
            db: (x * sn - 2.0 * (1.0 - cs)) / (2.0 * s * s),
            dc: ((1.0 - cs) * x - 3.0 * (x - sn)) / (2.0 * s * s * x),
        }
    }
}

/// exp(θ̃) = I + a θ̃ + b θ̃².
pub fn exp(theta: Vec3) -> Mat3 {
    let k = coefficients(theta.dot(theta));
    let t = theta.skew();
    Mat3::IDENTITY + t * k.a + t.matmul(t) * k.b
}

/// The left Jacobian J(θ) = I + b θ̃ + c θ̃²: the angular velocity of exp(θ̃) is J(θ) θ̇.
pub fn left_jacobian(theta: Vec3) -> Mat3 {
    let k = coefficients(theta.dot(theta));
    let t = theta.skew();
    Mat3::IDENTITY + t * k.b + t.matmul(t) * k.c
}

/// J̇(θ) θ̇ for θ̈ = 0, the part of the angular acceleration of exp(θ̃) that is quadratic in θ̇:
/// ḃ θ × θ̇ + ċ θ × (θ × θ̇) + c θ̇ × (θ × θ̇), ḃ = 2 b'(s) θ·θ̇, ċ = 2 c'(s) θ·θ̇.
pub fn left_jacobian_rate(theta: Vec3, theta_dot: Vec3) -> Vec3 {
    let k = coefficients(theta.dot(theta));
    let tt = theta.cross(theta_dot);
    let sd = 2.0 * theta.dot(theta_dot);
    tt * (k.db * sd) + theta.cross(tt) * (k.dc * sd) + theta_dot.cross(tt) * k.c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_product_is_the_matrix_product() {
        // matrix(a ⊗ b) = matrix(a) · matrix(b), and the rotation vector round-trips.
        let (ta, tb) = (Vec3::new(0.3, -1.2, 0.7), Vec3::new(-0.4, 0.2, 2.1));
        let (a, b) = (from_rotation_vector(ta), from_rotation_vector(tb));
        close(matrix(product(a, b)), matrix(a).matmul(matrix(b)), 1e-14);
        close(matrix(a), exp(ta), 1e-14);
        let back = rotation_vector(a);
        assert!((back - ta).norm() < 1e-14, "{back:?}");
    }

    fn close(a: Mat3, b: Mat3, tol: f64) {
        for i in 0..3 {
            for j in 0..3 {
                assert!((a.get(i, j) - b.get(i, j)).abs() < tol, "{a:?} vs {b:?}");
            }
        }
    }

    /// The series and the closed forms agree across their switch, and the exponential map is
    /// a rotation whose angular velocity is J(θ)θ̇ (central differences along a line θ + tθ̇).
    #[test]
    fn exponential_map_and_its_jacobians_agree_with_finite_differences() {
        for theta in [
            Vec3::new(0.3, -0.2, 0.5),
            Vec3::new(1e-4, 2e-5, -3e-5),
            Vec3::new(0.99, 0.1, 0.0),
            Vec3::new(1.2, -0.7, 0.4),
        ] {
            let td = Vec3::new(0.7, 0.4, -0.9);
            let r = exp(theta);
            close(r.matmul(r.transpose()), Mat3::IDENTITY, 1e-14);
            let h = 1e-5;
            let rp = exp(theta + td * h);
            let rm = exp(theta - td * h);
            let rdot = (rp - rm) * (0.5 / h);
            let w = rdot.matmul(r.transpose());
            let wv = Vec3::new(w.get(2, 1), w.get(0, 2), w.get(1, 0));
            let j = left_jacobian(theta).apply(td);
            assert!((wv - j).norm() < 1e-8, "{wv:?} vs {j:?}");
            let jp = left_jacobian(theta + td * h).apply(td);
            let jm = left_jacobian(theta - td * h).apply(td);
            let fd = (jp - jm) * (0.5 / h);
            let an = left_jacobian_rate(theta, td);
            assert!((fd - an).norm() < 1e-8, "{fd:?} vs {an:?}");
        }
    }

    #[test]
    fn quaternion_matrix_and_rotation_vector_agree_with_the_exponential_map() {
        let theta = Vec3::new(0.4, -1.1, 0.25);
        let angle = theta.norm();
        let axis = theta * (1.0 / angle);
        let (s, c) = (0.5 * angle).sin_cos();
        let q = [c, axis.get(0) * s, axis.get(1) * s, axis.get(2) * s];
        close(matrix(q), exp(theta), 1e-14);
        assert!((rotation_vector(q) - theta).norm() < 1e-14);
    }
}
