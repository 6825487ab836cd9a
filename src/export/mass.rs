//! The structure as mass elements: quadrature points of every beam and plate and the rigid
//! bodies (hub, lumped masses), each with its motion in given mode shapes. Sums over them are
//! the modal integrals of the continuum (∫ Ψ dm, ∫ r × Ψ dm, ∫ Ψ_p·Ψ_q dm, …) that NASA 42's
//! flexible-body model needs.
//!
//! Each element carries exactly the kinetic energy the Ritz mass matrix gives its part of the
//! structure (docs/theory.md §1): a beam point the line mass ρA and the section's polar
//! inertia ρI_p about the beam's axis (Euler–Bernoulli: no rotary inertia of bending), a plate
//! point the areal mass μ (Kirchhoff), a lumped mass or the hub its mass and inertia tensor.
//! The rules are Gauss–Legendre, composite with `PANELS` panels of `terms + EXTRA` points
//! along each direction: exact for the polynomial basis (the integrands are polynomials of
//! degree below 2·(terms + EXTRA)) and accurate to rounding for the characteristic functions.

use super::points::{point_motion, point_position, PointLocation};
use crate::basis::quadrature::Quadrature;
use crate::math::{Mat3, Vec3};
use crate::ritz::shapes::{attachment_of, BeamStation, PlatePoint};
use crate::ritz::RitzModel;
use crate::structure::ComponentId;

/// Panels of the composite rules.
const PANELS: usize = 4;
/// Points per panel beyond the component's term count.
const EXTRA: usize = 4;

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
    for (i, b) in st.beams.iter().enumerate() {
        let t = b.terms;
        let rule = Quadrature::composite(PANELS, t.bending.max(t.torsion).max(t.axial) + EXTRA);
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
        let rx = Quadrature::composite(PANELS, p.terms.length + EXTRA);
        let ry = Quadrature::composite(PANELS, p.terms.width + EXTRA);
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
