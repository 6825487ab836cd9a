//! The structure as mass elements: quadrature points of every beam and plate and the rigid
//! bodies (hub, lumped masses), each with its motion in given mode shapes. Sums over them are
//! the modal integrals of the continuum (∫ Ψ dm, ∫ r × Ψ dm, ∫ Ψ_p·Ψ_q dm, …) that NASA 42's
//! flexible-body model needs.
//!
//! Each element carries exactly the kinetic energy the Ritz mass matrix gives its part of the
//! structure (docs/theory.md §1): a beam point the line mass ρA and the section's polar
//! inertia ρI_p about the beam's axis (Euler–Bernoulli: no rotary inertia of bending), a plate
//! point the areal mass μ (Kirchhoff), a lumped mass or the hub its mass and inertia tensor.
//! The rules are Gauss–Legendre with `terms + EXTRA` points along each direction: for the
//! polynomial (Legendre) basis one rule over the component, exact (a bending function of the
//! n-term family has degree n + 1, so a product of two times a coordinate has degree
//! 2n + 3 ≤ 2(n + EXTRA) − 1); for the characteristic functions a composite rule of `PANELS` such
//! panels, accurate to rounding. One rule instead of four panels matters for a plate: 16 times
//! fewer points, each carrying every kept mode's motion (a 40 × 40 plate exporting all its
//! 1 618 modes held 2.4 GB of point motions with the composite rule).

use super::points::{point_motion, point_position, PointLocation};
use crate::basis::quadrature::Quadrature;
use crate::basis::BasisKind;
use crate::math::{Mat3, Vec3};
use crate::ritz::shapes::{attachment_of, BeamStation, PlatePoint};
use crate::ritz::RitzModel;
use crate::structure::ComponentId;

/// Panels of the composite rules (characteristic functions).
const PANELS: usize = 4;
/// Points per panel beyond the component's term count.
const EXTRA: usize = 4;

/// The number of mass elements [`mass_elements`] makes for `st` (the memory estimate's count):
/// the hub, the lumped masses, and each beam's and plate's quadrature points.
pub fn element_count(st: &crate::structure::Structure) -> u64 {
    let panels = if st.basis() == BasisKind::Legendre {
        1
    } else {
        PANELS as u64
    };
    let points = |terms: usize| panels * (terms + EXTRA) as u64;
    1 + st.masses.len() as u64
        + st.beams
            .iter()
            .map(|b| points(b.terms.bending.max(b.terms.torsion).max(b.terms.axial)))
            .sum::<u64>()
        + st.plates
            .iter()
            .map(|p| points(p.terms.length) * (p.hinges.len() as u64 + 1) * points(p.terms.width))
            .sum::<u64>()
}

/// One mass element of the discretised structure.
#[derive(Debug, Clone, PartialEq)]
pub struct MassElement {
    /// Position of its centre of mass, structure frame, m.
    pub position: Vec3,
    /// Mass, kg.
    pub mass: f64,
    /// Inertia about its own centre of mass, kg·m².
    pub inertia: Mat3,
    /// Per given shape: translation of the centre and small rotation (u, θ).
    pub motion: Vec<(Vec3, Vec3)>,
}

/// The mass elements of the whole structure (hub first, then beams, plates and lumped
/// masses), with their motion in each of `shapes` (vectors over all coordinates).
pub fn mass_elements(model: &RitzModel, shapes: &[&[f64]]) -> Vec<MassElement> {
    let st = &model.structure;
    let mut out = Vec::new();
    let hub = &st.hub;
    out.push(MassElement {
        position: hub.center_of_mass,
        mass: hub.mass,
        inertia: hub.inertia,
        motion: shapes
            .iter()
            .map(|q| {
                point_motion(
                    model,
                    &PointLocation::Hub {
                        position: hub.center_of_mass,
                    },
                    q,
                )
            })
            .collect(),
    });
    // Basis values at each point are computed once, each attachment's motion once per shape.
    let attachments = |id: ComponentId| -> Vec<(Vec3, Vec3)> {
        shapes
            .iter()
            .map(|q| attachment_of(model, id, q).unwrap_or((Vec3::ZERO, Vec3::ZERO)))
            .collect()
    };
    let polynomial = st.basis() == BasisKind::Legendre;
    let rule_for = |terms: usize| {
        if polynomial {
            Quadrature::gauss(terms + EXTRA)
        } else {
            Quadrature::composite(PANELS, terms + EXTRA)
        }
    };
    for (i, b) in st.beams.iter().enumerate() {
        let t = b.terms;
        let rule = rule_for(t.bending.max(t.torsion).max(t.axial));
        let mu = b.mass_per_length();
        let rho_ip = b.density * b.section.polar_inertia;
        let ex = b.frame.ex;
        let att = attachments(ComponentId::Beam(i));
        for (&xi, &w) in rule.points.iter().zip(&rule.weights) {
            let Some(station) = BeamStation::new(model, i, xi) else {
                continue;
            };
            let dl = w * b.length;
            out.push(MassElement {
                position: point_position(
                    st,
                    &PointLocation::Beam {
                        beam: i,
                        station: xi * b.length,
                    },
                ),
                mass: mu * dl,
                inertia: ex.outer(ex) * (rho_ip * dl),
                motion: shapes
                    .iter()
                    .zip(&att)
                    .map(|(q, a)| {
                        let p = station.sample(model, q, *a);
                        (p.displacement, p.rotation)
                    })
                    .collect(),
            });
        }
    }
    for (i, p) in st.plates.iter().enumerate() {
        let rx = rule_for(p.terms.length).split(&p.hinge_positions());
        let ry = rule_for(p.terms.width);
        let area = p.length * p.width;
        let att = attachments(ComponentId::Plate(i));
        for (&xi, &wx) in rx.points.iter().zip(&rx.weights) {
            for (&eta, &wy) in ry.points.iter().zip(&ry.weights) {
                let Some(point) = PlatePoint::new(model, i, xi, eta) else {
                    continue;
                };
                out.push(MassElement {
                    position: point_position(st, &PointLocation::Plate { plate: i, xi, eta }),
                    mass: p.areal_density * area * wx * wy,
                    inertia: Mat3::default(),
                    motion: shapes
                        .iter()
                        .zip(&att)
                        .map(|(q, a)| {
                            let s = point.sample(model, q, *a);
                            (s.displacement, s.rotation)
                        })
                        .collect(),
                });
            }
        }
    }
    for (i, m) in st.masses.iter().enumerate() {
        let loc = PointLocation::Mass { mass: i };
        out.push(MassElement {
            position: point_position(st, &loc),
            mass: m.mass(),
            inertia: m.inertia(),
            motion: shapes
                .iter()
                .map(|q| point_motion(model, &loc, q))
                .collect(),
        });
    }
    out
}
