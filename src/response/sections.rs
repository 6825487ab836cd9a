//! Section loads along a beam by force summation (docs/theory.md §3.3): the part of the
//! structure outboard of a section — the beam beyond it and everything that hangs on the
//! beam there or beyond — is touched only through that section, so the force and moment the
//! inboard part exerts on it are the rates of its linear momentum and of its angular
//! momentum about the section's centre, both linear in q̈ (as the root loads,
//! [`super::loads`], which are the section loads at the root).
//!
//! With r(x) the undeformed position of the station x, J_u(x) and J_θ(x) the Jacobians of
//! its displacement and small rotation ([`crate::ritz::shapes::BeamStation`]), ρA the line
//! mass and ρI_p the polar inertia per length, and M_D the mass matrix of the components
//! hanging on the beam at or beyond x ([`RitzModel::partial_mass`],
//! [`Structure::hanging_station`]):
//!
//!   p = ∫_x^L ρA J_u dx q̇ + M_D[0..3,:] q̇,
//!   H_c = ∫_x^L [ρA (r − c) × J_u + ρI_p eₓ (eₓ·J_θ)] dx q̇ + M_D[3..6,:] q̇,
//!
//! (c the hub's centre of mass, about which the hub's rotation coordinates turn everything;
//! the beam's mass matrix has the same terms: line mass and polar inertia, Euler–Bernoulli),
//! and the inboard part's force and moment about the section's centre r(x) on it are
//! F = ṗ and M = Ḣ_c − (r(x) − c) × F. The stress resultants on the section's positive face
//! (normal eₓ, the inboard part's end) are their opposites, in the beam's axes:
//! N = −F·eₓ, V_y = −F·e_y, V_z = −F·e_z, T = −M·eₓ, M_y = −M·e_y, M_z = −M·e_z
//! (N > 0 in tension; σ = N/A + M_y z/I_y − M_z y/I_z).

use super::channels::{Channel, ChannelKind, Order};
use crate::basis::Quadrature;
use crate::math::Vec3;
use crate::ritz::shapes::{attachment_of, BeamStation};
use crate::ritz::RitzModel;
use crate::structure::{ComponentId, Structure};

/// The six stress resultants' names, units and labels, in the order of [`section_channels`].
pub const RESULTANTS: [(&str, &str); 6] = [
    ("N", "N"),
    ("Vy", "N"),
    ("Vz", "N"),
    ("T", "N·m"),
    ("My", "N·m"),
    ("Mz", "N·m"),
];

/// The stations of beam `beam` where its section loads are recovered: tenths of its length,
/// root and tip included, and every station where something hangs on it (the inboard side,
/// which carries it). Increasing, m from the root.
pub fn stations(st: &Structure, beam: usize) -> Vec<f64> {
    let l = st.beams[beam].length;
    let mut out: Vec<f64> = (0..=10).map(|k| l * k as f64 / 10.0).collect();
    let ids = (0..st.beams.len())
        .map(ComponentId::Beam)
        .chain((0..st.plates.len()).map(ComponentId::Plate))
        .chain((0..st.masses.len()).map(ComponentId::Mass));
    for id in ids {
        if let Some(x) = st.hanging_station(id, beam) {
            out.push(x.clamp(0.0, l));
        }
    }
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * l);
    out
}

/// The six stress resultants (N, V_y, V_z, T, M_y, M_z: [`RESULTANTS`]) at station `x` of
/// beam `beam` as acceleration channels (module doc), named `<beam>@<x>_<resultant>`.
pub fn section_channels(model: &RitzModel, beam: usize, x: f64) -> Vec<Channel> {
    beam_section_channels(model, beam, &[x])
}

/// [`section_channels`] at every station of `xs`, six channels each in their order: the
/// attachment's motion per coordinate, which the stations share, computed once.
pub fn beam_section_channels(model: &RitzModel, beam: usize, xs: &[f64]) -> Vec<Channel> {
    let mut unit = vec![0.0; model.dof()];
    let attachments: Vec<(Vec3, Vec3)> = (0..unit.len())
        .map(|j| {
            unit[j] = 1.0;
            let a = attachment_of(model, ComponentId::Beam(beam), &unit)
                .unwrap_or((Vec3::ZERO, Vec3::ZERO));
            unit[j] = 0.0;
            a
        })
        .collect();
    xs.iter()
        .flat_map(|&x| station_channels(model, beam, x, &attachments))
        .collect()
}

/// The six channels at station x, given the attachment's motion for each unit coordinate.
fn station_channels(
    model: &RitzModel,
    beam: usize,
    x: f64,
    attachments: &[(Vec3, Vec3)],
) -> Vec<Channel> {
    let st = &model.structure;
    let b = &st.beams[beam];
    let n = model.dof();
    let c = st.hub.center_of_mass;
    let f = b.frame;
    let origin = st.beam_root(beam);
    let rs = origin + f.ex * x;
    let (rho_a, rho_ip) = (b.mass_per_length(), b.density * b.section.polar_inertia);
    // Columns of the momentum rows: p_j and H_j (about c) for q̇ = e_j.
    let mut p = vec![Vec3::ZERO; n];
    let mut h = vec![Vec3::ZERO; n];
    // The beam beyond x, by Gauss–Legendre quadrature on [x, L] (exact for the polynomial
    // fields, whose degree is below the points' 2·count).
    let terms = model
        .element(ComponentId::Beam(beam))
        .map_or(0, |e| e.own_range().len());
    let q = Quadrature::gauss(terms + 24);
    let span = b.length - x;
    let mut unit = vec![0.0; n];
    if span > 0.0 {
        for (&t, &w) in q.points.iter().zip(&q.weights) {
            let xg = x + span * t;
            let Some(station) = BeamStation::new(model, beam, xg / b.length) else {
                break;
            };
            let r = origin + f.ex * xg - c;
            let weight = w * span;
            for j in 0..n {
                unit[j] = 1.0;
                let s = station.sample(model, &unit, attachments[j]);
                unit[j] = 0.0;
                p[j] = p[j] + s.displacement * (rho_a * weight);
                h[j] = h[j]
                    + r.cross(s.displacement) * (rho_a * weight)
                    + f.ex * (rho_ip * weight * f.ex.dot(s.rotation));
            }
        }
    }
    // What hangs on the beam at or beyond x.
    let beyond = |id: ComponentId| {
        st.hanging_station(id, beam)
            .is_some_and(|s| s >= x - 1e-12 * b.length)
    };
    if (0..st.beams.len())
        .map(ComponentId::Beam)
        .chain((0..st.plates.len()).map(ComponentId::Plate))
        .chain((0..st.masses.len()).map(ComponentId::Mass))
        .any(beyond)
    {
        let md = model.partial_mass(beyond);
        for j in 0..n {
            p[j] = p[j] + Vec3::new(md[(0, j)], md[(1, j)], md[(2, j)]);
            h[j] = h[j] + Vec3::new(md[(3, j)], md[(4, j)], md[(5, j)]);
        }
    }
    let d = rs - c;
    let axes = [f.ex, f.ey, f.ez];
    let mut out = Vec::with_capacity(6);
    for (k, (what, unit)) in RESULTANTS.iter().enumerate() {
        let row: Vec<f64> = (0..n)
            .map(|j| {
                let force = p[j];
                let moment = h[j] - d.cross(force);
                // The positive face's resultant: the opposite of the load on the outboard part.
                if k < 3 {
                    -force.dot(axes[k])
                } else {
                    -moment.dot(axes[k - 3])
                }
            })
            .collect();
        out.push(Channel {
            name: format!("{}@{x:.4}_{what}", b.name),
            label: format!("{} section at x = {x:.4} m, {what}", b.name),
            unit,
            kind: ChannelKind::BeamSection {
                beam: b.name.clone(),
                station: x,
            },
            row,
            order: Order::Acceleration,
            offset: 0.0,
            rate_row: None,
        });
    }
    out
}
