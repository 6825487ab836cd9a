//! Named points of the structure: where the export's forces and torques act and where its
//! displacements, rotations and velocities are read.
//!
//! Every point's motion is linear in the generalized coordinates q: a displacement u and a
//! small rotation θ, structure (hub) frame. For a point rigidly attached at a section that
//! moves by (u₀, θ₀), at offset r from it, u = u₀ + θ₀ × r and θ = θ₀.

use crate::math::Vec3;
use crate::ritz::shapes::{attachment_of, beam_point, hub_motion, plate_point};
use crate::ritz::RitzModel;
use crate::structure::{ComponentId, Structure};

/// Where a named point sits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PointLocation {
    /// A point of the rigid hub, structure frame \[m\] (the origin is the hub's reference
    /// point).
    Hub {
        /// Position, m.
        position: Vec3,
    },
    /// A section of beam `beam`, `station` metres from its root.
    Beam {
        /// Beam index.
        beam: usize,
        /// Distance from the root, m, in [0, length].
        station: f64,
    },
    /// A point of plate `plate` at (ξ, η) ∈ [0, 1]² (ξ along the length from the root edge,
    /// η across the width).
    Plate {
        /// Plate index.
        plate: usize,
        /// ξ = x / length.
        xi: f64,
        /// η = y / width + ½.
        eta: f64,
    },
    /// The centre of mass of lumped mass `mass`.
    Mass {
        /// Lumped-mass index.
        mass: usize,
    },
}

/// A point with the name its inputs and outputs carry.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedPoint {
    /// Name (letters, digits, `_`; not `hub`).
    pub name: String,
    /// Where it is.
    pub location: PointLocation,
}

/// The hub's reference point (the structure frame's origin), where the hub's force and
/// torque act and its position and attitude are read.
pub const HUB_REFERENCE: PointLocation = PointLocation::Hub {
    position: Vec3::ZERO,
};

/// Undeformed position of a point, structure frame \[m\].
pub fn point_position(structure: &Structure, loc: &PointLocation) -> Vec3 {
    match *loc {
        PointLocation::Hub { position } => position,
        PointLocation::Beam { beam, station } => {
            let b = &structure.beams[beam];
            structure.beam_root(beam) + b.frame.ex * station
        }
        PointLocation::Plate { plate, xi, eta } => {
            let p = &structure.plates[plate];
            structure.attachment_point(&p.attachment)
                + p.length_axis * (xi * p.length)
                + p.width_axis() * ((eta - 0.5) * p.width)
        }
        PointLocation::Mass { mass } => {
            let m = &structure.masses[mass];
            structure.attachment_point(&m.attachment()) + m.offset()
        }
    }
}

/// The motion (u, θ) of the section a point is rigidly fixed to, at `at`: hub points move
/// with the hub's centre of mass (u_c, θ) as u = u_c + θ × (p − c).
fn hub_point_motion(model: &RitzModel, at: Vec3, q: &[f64]) -> (Vec3, Vec3) {
    let (uc, th) = hub_motion(q);
    let c = model.structure.hub.center_of_mass;
    (uc + th.cross(at - c), th)
}

/// Displacement u [m per unit q] and small rotation θ [rad per unit q] of a point for
/// coordinates q (linear in q), structure frame.
pub fn point_motion(model: &RitzModel, loc: &PointLocation, q: &[f64]) -> (Vec3, Vec3) {
    let st = &model.structure;
    match *loc {
        PointLocation::Hub { position } => hub_point_motion(model, position, q),
        PointLocation::Beam { beam, station } => {
            let xi = station / st.beams[beam].length;
            beam_point(model, beam, xi, q)
                .map_or((Vec3::ZERO, Vec3::ZERO), |p| (p.displacement, p.rotation))
        }
        PointLocation::Plate { plate, xi, eta } => plate_point(model, plate, xi, eta, q)
            .map_or((Vec3::ZERO, Vec3::ZERO), |p| (p.displacement, p.rotation)),
        PointLocation::Mass { mass } => {
            let m = &st.masses[mass];
            let (u0, th0) = attachment_of(model, ComponentId::Mass(mass), q)
                .unwrap_or((Vec3::ZERO, Vec3::ZERO));
            (u0 + th0.cross(m.offset()), th0)
        }
    }
}

/// The 6 × n Jacobian of a point's motion [u; θ] with respect to q (row-major rows of
/// length n): column c is the motion for the unit vector e_c.
pub fn point_jacobian(model: &RitzModel, loc: &PointLocation) -> Vec<[f64; 6]> {
    let n = model.dof();
    let mut q = vec![0.0; n];
    (0..n)
        .map(|c| {
            q[c] = 1.0;
            let (u, th) = point_motion(model, loc, &q);
            q[c] = 0.0;
            [u.0[0], u.0[1], u.0[2], th.0[0], th.0[1], th.0[2]]
        })
        .collect()
}
