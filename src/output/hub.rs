//! The hub on one timeline (hub.csv and two figures): its position, attitude, velocity and
//! angular rate from release through every latch to the end of the response, in one frame —
//! inertial, the hub's body axes at release — with t from release.
//!
//! The deployment gives them directly (the coupled model's hub state, inertial components).
//! After the hand-over at t_h the response gives the hub's translation u and small rotation
//! θ in the hub's axes at the hand-over (the linear model's frame), so with the hand-over's
//! position P_h and attitude q_h: position P_h + R_h u, attitude q_h ⊗ q(θ), velocity R_h u̇
//! and rate R_h θ̇ (the small-rotation rate: the linear model's).

use super::figures::{Curve, Figure};
use crate::deploy::attitude;
use crate::math::Vec3;
use crate::response::extrema::WaveSum;
use crate::response::ChannelKind;
use crate::simulation::Simulation;
use crate::structure::HubMotion;

/// One row of the hub's timeline (inertial components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HubRow {
    /// s from release.
    pub t: f64,
    /// From the response (after the hand-over), not the deployment.
    pub response: bool,
    /// Centre of mass, m.
    pub position: Vec3,
    /// Attitude as a rotation vector, rad.
    pub rotation: Vec3,
    /// Centre-of-mass velocity, m/s.
    pub velocity: Vec3,
    /// Angular velocity, rad/s.
    pub rate: Vec3,
}

/// The timeline: the deployment's samples up to the hand-over, then the response's
/// (None for a fixed hub, or without the coupled model's 3-D samples).
pub fn timeline(sim: &Simulation) -> Option<Vec<HubRow>> {
    if sim.model.structure.hub().motion() != HubMotion::Free {
        return None;
    }
    let mut rows = Vec::new();
    let t_h = sim.response.as_ref().map(|r| r.handover.latch_time);
    let mut at_handover = None;
    for s in &sim.deployment.samples {
        let b = s.body.as_ref()?;
        if t_h.is_some_and(|th| s.t > th) {
            break;
        }
        let row = HubRow {
            t: s.t,
            response: false,
            position: Vec3(b.hub_position),
            rotation: Vec3(b.hub_rotation),
            velocity: Vec3(b.hub_velocity),
            rate: Vec3(b.hub_rate),
        };
        at_handover = Some(row);
        rows.push(row);
    }
    let (Some(r), Some(h)) = (&sim.response, at_handover) else {
        return Some(rows);
    };
    let th = r.handover.latch_time;
    let pick = |kind: ChannelKind| -> Vec<usize> {
        r.channels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.kind == kind)
            .map(|(i, _)| i)
            .collect()
    };
    let (tr, rot) = (
        pick(ChannelKind::HubTranslation),
        pick(ChannelKind::HubRotation),
    );
    if tr.len() != 3 || rot.len() != 3 {
        return Some(rows);
    }
    let channels: Vec<_> = tr
        .iter()
        .chain(&rot)
        .map(|&i| r.channels[i].clone())
        .collect();
    let rates: Vec<WaveSum> = r
        .modal
        .signals(&sim.modes, &channels)
        .iter()
        .map(WaveSum::derivative)
        .collect();
    // With rigid latches the hand-over is the last latch, whose sample is the last row; with
    // compliant ones it is the settling's end, after the last sample by up to one output
    // period Δ: the hub's state there to first order in Δ (its velocity and rate carried).
    let gap = (th - h.t).max(0.0);
    let q_h = attitude::product(
        attitude::from_rotation_vector(h.rate * gap),
        attitude::from_rotation_vector(h.rotation),
    );
    let r_h = attitude::matrix(q_h);
    let h = HubRow {
        position: h.position + h.velocity * gap,
        ..h
    };
    for (k, &t) in r.history.times.iter().enumerate() {
        if k == 0 && gap == 0.0 {
            // The hand-over instant is the deployment's last row.
            continue;
        }
        let v = |c: &[usize]| {
            Vec3::new(
                r.history.values[(k, c[0])],
                r.history.values[(k, c[1])],
                r.history.values[(k, c[2])],
            )
        };
        let d = |o: usize| Vec3::new(rates[o].at(t), rates[o + 1].at(t), rates[o + 2].at(t));
        let (u, theta) = (v(&tr), v(&rot));
        rows.push(HubRow {
            t: th + t,
            response: true,
            position: h.position + r_h.apply(u),
            rotation: attitude::rotation_vector(attitude::product(
                q_h,
                attitude::from_rotation_vector(theta),
            )),
            velocity: r_h.apply(d(0)),
            rate: r_h.apply(d(3)),
        });
    }
    Some(rows)
}

/// hub.csv's header.
pub const HEADER: [&str; 14] = [
    "t [s]",
    "phase",
    "x [m]",
    "y [m]",
    "z [m]",
    "rx [rad]",
    "ry [rad]",
    "rz [rad]",
    "vx [m/s]",
    "vy [m/s]",
    "vz [m/s]",
    "wx [rad/s]",
    "wy [rad/s]",
    "wz [rad/s]",
];

/// hub.csv's text (None for a fixed hub). A value below 1e-9 (the figures' noise floor)
/// of the largest of its quantity (position, rotation, velocity, rate) over the timeline is
/// rounding noise and written as 0.
pub fn csv(sim: &Simulation) -> Option<String> {
    let rows = timeline(sim)?;
    let parts = |r: &HubRow| [r.position, r.rotation, r.velocity, r.rate];
    let mut largest = [0.0_f64; 4];
    for r in &rows {
        for (l, v) in largest.iter_mut().zip(parts(r)) {
            *l = v.0.iter().fold(*l, |m, x| m.max(x.abs()));
        }
    }
    let mut o = HEADER.join(",");
    o.push('\n');
    for r in &rows {
        let mut fields = vec![
            super::num(r.t),
            if r.response { "response" } else { "deployment" }.to_string(),
        ];
        for (v, l) in parts(r).into_iter().zip(largest) {
            fields.extend(v.0.iter().map(|x| {
                super::num(if x.abs() <= super::figures::NOISE_FLOOR * l {
                    0.0
                } else {
                    *x
                })
            }));
        }
        o.push_str(&fields.join(","));
        o.push('\n');
    }
    Some(o)
}

/// The hub's attitude and rate from release to the end of the response, the latches and
/// the hand-over marked by vertical lines (none for a fixed hub); rounding noise drawn as
/// zero and labelled so, as in the other figures.
pub fn figures(sim: &Simulation) -> Vec<Figure> {
    let Some(rows) = timeline(sim) else {
        return Vec::new();
    };
    let mut markers: Vec<f64> = sim.deployment.latches.iter().map(|l| l.time).collect();
    markers.extend(sim.deployment.captures.iter().map(|c| c.time));
    if let Some(r) = &sim.response {
        markers.push(r.handover.latch_time);
    }
    markers.sort_by(f64::total_cmp);
    markers.dedup();
    let curves = |name: &str, f: &dyn Fn(&HubRow) -> Vec3| -> Vec<Curve> {
        ["x", "y", "z"]
            .iter()
            .enumerate()
            .map(|(k, axis)| {
                super::figures::curve(
                    format!("{name} {axis}"),
                    rows.len(),
                    |i| rows[i].t,
                    |i| f(&rows[i]).0[k],
                )
            })
            .collect()
    };
    let mut figs = vec![
        Figure {
            stem: "hub_attitude".into(),
            title: "hub attitude from release (rotation vector, inertial axes)".into(),
            xlabel: "t from release [s]",
            ylabel: "rotation [rad]",
            curves: curves("rotation", &|r| r.rotation),
            markers: markers.clone(),
        },
        Figure {
            stem: "hub_rate".into(),
            title: "hub angular rate from release (inertial axes)".into(),
            xlabel: "t from release [s]",
            ylabel: "rate [rad/s]",
            curves: curves("rate", &|r| r.rate),
            markers,
        },
    ];
    super::figures::clean(
        &mut figs,
        super::figures::structure_size(&sim.model.structure),
    );
    figs
}
