//! The data of the report's 3-D view (drawn by assets/report.js on a canvas, by its own
//! projection: no library, no network): the spacecraft as described (the hub as its
//! cylinder, or as the uniform box with its principal inertias; beams as tubes of their
//! section's outer diameter; plates as panels; lumped masses as spheres), the first elastic
//! modes as displacement fields with their exaggeration factor, and the deployment as frames
//! of the hub's motion, the panels' hinge points and the beams' tip deflections.
//!
//! Coordinates are the structure frame (m); the deployment frames carry the hub's inertial
//! position change r and rotation vector ρ, and a body point p is drawn at
//! c + r + R(ρ)(p − c), c the hub's centre of mass.

use super::figures::decimate;
use super::modes::sample_all;
use crate::math::Vec3;
use crate::ritz::shapes::PointSample;
use crate::simulation::Simulation;
use crate::structure::{ComponentId, Structure};
use serde_json::{json, Value};

/// Elastic modes the view animates.
pub const VIEW_MODES: usize = 6;
/// Deployment frames at most.
pub const VIEW_FRAMES: usize = 600;

/// Rounds to 5 significant decimals of a metre-scale quantity (a smaller page).
fn r5(v: f64) -> f64 {
    (v * 1e5).round() / 1e5
}

fn p3(v: Vec3) -> [f64; 3] {
    [r5(v.0[0]), r5(v.0[1]), r5(v.0[2])]
}

/// The hub's drawable shape.
fn hub_json(st: &Structure) -> Value {
    let hub = st.hub();
    if let Some(c) = hub.shape() {
        return json!({"kind": "cylinder", "center": p3(c.center), "axis": p3(c.axis),
                      "radius": r5(c.diameter / 2.0), "length": r5(c.length)});
    }
    let h = box_half_sides(st);
    json!({"kind": "box", "center": p3(hub.center_of_mass()), "half": [r5(h[0]), r5(h[1]), r5(h[2])]})
}

/// The half-sides of the uniform box with the hub's principal moments along the structure
/// axes (products of inertia ignored): I_x = m (b² + c²)/3 for half-sides a, b, c, so
/// a² = 3 (I_y + I_z − I_x) / (2m).
pub(crate) fn box_half_sides(st: &Structure) -> [f64; 3] {
    let hub = st.hub();
    let j = hub.inertia().0;
    let m = hub.mass().max(1e-9);
    let half = |i: usize| {
        let (a, b, c) = (
            j[i][i],
            j[(i + 1) % 3][(i + 1) % 3],
            j[(i + 2) % 3][(i + 2) % 3],
        );
        (3.0 * (b + c - a) / (2.0 * m)).max(1e-6).sqrt()
    };
    [half(0), half(1), half(2)]
}

/// Outer diameter of a beam's section from its area A and polar moment J: for a tube
/// R² + r² = 2J/A and R² − r² = A/π (exact for tubes and solid circles).
fn beam_diameter(area: f64, polar: f64) -> f64 {
    let r2 = 0.5 * (2.0 * polar / area.max(1e-30) + area / std::f64::consts::PI);
    2.0 * r2.max(0.0).sqrt()
}

/// The structure, the first elastic modes and the deployment frames.
pub fn view_spec(sim: &Simulation, deploying_plate: Option<&str>) -> Value {
    let model = &sim.model;
    let st = &model.structure;
    let zero = vec![0.0; model.dof()];
    let base = sample_all(model, &zero);
    let positions = |s: &[PointSample]| s.iter().map(|p| p3(p.position)).collect::<Vec<_>>();
    let mut beams = Vec::new();
    let mut plates = Vec::new();
    for (name, id, s) in &base {
        match id {
            ComponentId::Beam(i) => {
                let b = &st.beams()[*i];
                let sec = b.section();
                beams.push(
                    json!({"name": name, "d": r5(beam_diameter(sec.area, sec.polar_inertia)),
                                  "pts": positions(s)}),
                );
            }
            ComponentId::Plate(_) => {
                plates.push(json!({"name": name, "nx": 31, "ny": 9, "pts": positions(s)}));
            }
            _ => {}
        }
    }
    let masses: Vec<Value> = st
        .masses()
        .iter()
        .map(|m| {
            let p = st.attachment_point(&m.attachment()) + m.offset();
            // A sphere of aluminium's density: a visible size that grows with the mass.
            let r = (3.0 * m.mass() / (4.0 * std::f64::consts::PI * 2700.0)).cbrt();
            json!({"name": m.name(), "p": p3(p), "r": r5(r)})
        })
        .collect();
    let extent = base
        .iter()
        .flat_map(|(_, _, s)| {
            s.iter()
                .map(|p| (p.position - st.hub().center_of_mass()).norm())
        })
        .fold(1.0, f64::max);
    let modes: Vec<Value> = sim
        .modes
        .elastic()
        .take(VIEW_MODES)
        .map(|m| {
            let samples = sample_all(model, &m.shape);
            let peak = samples
                .iter()
                .flat_map(|(_, _, s)| s.iter().map(|p| p.displacement.norm()))
                .fold(0.0, f64::max);
            // The largest displacement drawn as 10 % of the structure's extent.
            let k = if peak > 0.0 { 0.1 * extent / peak } else { 0.0 };
            let field = |want: fn(&ComponentId) -> bool| -> Vec<Vec<[f64; 3]>> {
                samples
                    .iter()
                    .filter(|(_, id, _)| want(id))
                    .map(|(_, _, s)| s.iter().map(|p| p3(p.displacement * k)).collect())
                    .collect()
            };
            json!({"n": m.number, "f": m.frequency_hz(), "k": k,
                   "beams": field(|id| matches!(id, ComponentId::Beam(_))),
                   "plates": field(|id| matches!(id, ComponentId::Plate(_)))})
        })
        .collect();
    json!({"extent": r5(extent), "hub": hub_json(st), "beams": beams, "plates": plates,
           "masses": masses, "modes": modes, "deploy": deploying_plate.map_or(Value::Null, |p| deploy_json(sim, p, extent))})
}

/// The deployment frames: time, the hub's r and ρ, the hinge points in the deployment plane
/// (u along the plate's length axis, v along its normal, from the root hinge at the plate's
/// attachment point `origin`),
/// and every beam's tip deflection (structure axes) with the factor that makes the largest
/// visible (10 % of the extent).
fn deploy_json(sim: &Simulation, plate_name: &str, extent: f64) -> Value {
    let st = &sim.model.structure;
    let r = &sim.deployment;
    let c = &sim.coupled;
    let Some(pi) = st.plates().iter().position(|p| p.name() == plate_name) else {
        return Value::Null;
    };
    let plate = &st.plates()[pi];
    let hub_c = st.hub().center_of_mass();
    let att = st.attachment_point(&plate.attachment());
    let (ea, n, eb) = (plate.length_axis(), plate.normal(), plate.width_axis());
    let m = r.samples.len();
    let idx = decimate(m, |k| r.samples[k].t, VIEW_FRAMES.min(m.max(4)));
    let tip_vector = |k: usize, b: usize| -> Vec3 {
        r.samples[k].body.as_deref().map_or(Vec3::ZERO, |body| {
            let t = body.beam_tips[b];
            let ax = c.base.beams[b].axes;
            ax[0] * t[0] + ax[1] * t[1] + ax[2] * t[2]
        })
    };
    let nb = c.base.beams.len();
    let peak = (0..m)
        .flat_map(|k| (0..nb).map(move |b| (k, b)))
        .map(|(k, b)| tip_vector(k, b).norm())
        .fold(0.0, f64::max);
    let k_tip = if peak > 0.0 { 0.1 * extent / peak } else { 0.0 };
    let beam_index: Vec<Option<usize>> = c
        .base
        .beams
        .iter()
        .map(|b| st.beams().iter().position(|sb| sb.name() == b.name))
        .collect();
    let frames: Vec<Value> = idx
        .iter()
        .map(|&k| {
            let s = &r.samples[k];
            let (hx, hr) = s
                .body
                .as_deref()
                .map_or(([0.0; 3], [0.0; 3]), |b| (b.hub_position, b.hub_rotation));
            json!({"t": r5(s.t), "hx": hx.map(r5), "hr": hr.map(|v| (v * 1e9).round() / 1e9),
                   "p": s.hinges.iter().map(|p| [r5(p[0]), r5(p[1])]).collect::<Vec<_>>(),
                   "tips": (0..nb).map(|b| p3(tip_vector(k, b) * k_tip)).collect::<Vec<_>>()})
        })
        .collect();
    json!({"plate": pi, "ea": p3(ea), "n": p3(n), "eb": p3(eb), "c": p3(hub_c),
           "origin": p3(att), "width": r5(plate.width()),
           "k_tip": k_tip, "tip_beams": beam_index, "frames": frames,
           "carrier": c.base.beams.iter().position(|b| b.carries_array)})
}
