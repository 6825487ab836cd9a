//! Rigid-body mass properties and inertia tensors.

use super::StructureError;
use crate::math::{Mat3, Vec3};

/// Mass properties of a body about a reference point O, in the structure frame:
/// mass m, first moment s = ∫ r dm, inertia J_O = ∫ (|r|² I − r rᵀ) dm (r from O).
///
/// For a displacement field u = U + Θ × r of the body (U, Θ: translation and small rotation
/// at O) the kinetic energy is ½ [U̇; Θ̇]ᵀ B [U̇; Θ̇] with
/// B = [[m I, −S(s)], [S(s), J_O]], S(a)b = a × b ([`RigidBody::block`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RigidBody {
    /// Mass, kg.
    pub mass: f64,
    /// First moment of mass about O, kg·m.
    pub first_moment: Vec3,
    /// Inertia tensor about O, kg·m².
    pub inertia: Mat3,
}

impl RigidBody {
    /// A body of mass m with centre of mass at `c` (relative to O) and inertia `j_cm` about its
    /// centre of mass (parallel-axis theorem).
    pub fn from_cm(mass: f64, c: Vec3, j_cm: Mat3) -> Self {
        Self {
            mass,
            first_moment: c * mass,
            inertia: j_cm + (Mat3::IDENTITY * c.dot(c) - c.outer(c)) * mass,
        }
    }

    /// Centre of mass relative to O (zero for a massless body).
    pub fn center_of_mass(&self) -> Vec3 {
        if self.mass > 0.0 {
            self.first_moment * (1.0 / self.mass)
        } else {
            Vec3::ZERO
        }
    }

    /// Inertia tensor about the centre of mass.
    pub fn inertia_at_cm(&self) -> Mat3 {
        let c = self.center_of_mass();
        self.inertia - (Mat3::IDENTITY * c.dot(c) - c.outer(c)) * self.mass
    }

    /// The same body referred to the point O' = O + d.
    pub fn about(&self, d: Vec3) -> Self {
        Self::from_cm(self.mass, self.center_of_mass() - d, self.inertia_at_cm())
    }

    /// Sum of two bodies about the same point.
    pub fn plus(&self, o: &RigidBody) -> Self {
        Self {
            mass: self.mass + o.mass,
            first_moment: self.first_moment + o.first_moment,
            inertia: self.inertia + o.inertia,
        }
    }

    /// The 6×6 mass block [[m I, −S(s)], [S(s), J_O]] (row-major).
    pub fn block(&self) -> [[f64; 6]; 6] {
        let mut b = [[0.0; 6]; 6];
        let s = self.first_moment.skew();
        for i in 0..3 {
            b[i][i] = self.mass;
            for j in 0..3 {
                b[i][3 + j] = -s.get(i, j);
                b[3 + i][j] = s.get(i, j);
                b[3 + i][3 + j] = self.inertia.get(i, j);
            }
        }
        b
    }
}

/// Builds an inertia tensor from 3 principal values or 6 values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]
/// (products of inertia enter the tensor as given: J = [[Ixx, Ixy, Ixz], …]) and checks
/// that it is a physical one: finite, positive definite, and its principal moments obey the
/// triangle inequality Iₐ + I_b ≥ I_c.
pub fn inertia_tensor(values: &[f64]) -> Result<Mat3, StructureError> {
    let j = match values.len() {
        3 => Mat3::diag([values[0], values[1], values[2]]),
        6 => Mat3::symmetric([
            values[0], values[1], values[2], values[3], values[4], values[5],
        ]),
        n => return Err(StructureError::InertiaLength { len: n }),
    };
    // Ranges (crate::limits): moments in [MIN_PRINCIPAL_INERTIA, INERTIA.hi], products in
    // INERTIA; non-finite values are outside both.
    for (i, v) in values.iter().enumerate() {
        let ok = crate::limits::INERTIA.contains(*v)
            && (i >= 3 || v.abs() >= crate::limits::MIN_PRINCIPAL_INERTIA);
        if !ok {
            return Err(StructureError::InertiaEntry {
                entry: i + 1,
                value: *v,
            });
        }
    }
    let (p, _) = j.symmetric_eigen();
    if p[0] <= 0.0 {
        return Err(StructureError::InertiaNotPositive { principal: p });
    }
    let tol = 1e-12 * p[2];
    if p[0] + p[1] < p[2] - tol {
        return Err(StructureError::InertiaTriangle { principal: p });
    }
    Ok(j)
}
