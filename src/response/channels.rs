//! The physical quantities recorded during the response, each linear in the generalized
//! coordinates (a row c with value c·q): the paper's figures 2.4–2.7.
//!
//! * every beam's tip: elastic deflection in its two bending planes (v along the section's
//!   y axis, w along z) and twist θ, relative to its root section (fig. 2.4 for the mast);
//! * every plate's two tip corners (x = a, y = ∓b/2): elastic deflection W along the normal,
//!   relative to its root yoke (fig. 2.5);
//! * the hub: translation of its centre of mass along the structure axes (fig. 2.6) and its
//!   small rotation about them (fig. 2.7).

use crate::ritz::assembly::{ElementKind, FieldKind};
use crate::ritz::RitzModel;

/// What a channel measures.
#[derive(Debug, Clone, PartialEq)]
pub enum ChannelKind {
    /// A beam tip's elastic deflection (m) or twist (rad).
    BeamTip {
        /// Beam name.
        beam: String,
    },
    /// A plate tip corner's elastic deflection (m).
    PlateTip {
        /// Plate name.
        plate: String,
    },
    /// Hub translation, m.
    HubTranslation,
    /// Hub rotation, rad.
    HubRotation,
    /// The force (N) or moment (N·m) a beam's parent exerts on it at its root
    /// ([`super::loads`]).
    BeamRoot {
        /// Beam name.
        beam: String,
    },
    /// A stress resultant of a beam's section along its length (N or N·m: N, V_y, V_z, T,
    /// M_y, M_z on the positive face, beam axes; [`super::sections`]).
    BeamSection {
        /// Beam name.
        beam: String,
        /// Station, m from the root.
        station: f64,
    },
    /// A latch's moment on its hinge (N·m) in the deployed wing ([`super::loads`]).
    LatchMoment {
        /// Hinge number, 1 at the root.
        hinge: usize,
    },
}

/// Which time derivative of q a channel's row multiplies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// value = c · q + offset (deflections, rotations).
    Displacement,
    /// value = c · q̈ + offset (loads by force summation: momentum rates).
    Acceleration,
}

/// One recorded quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Column name (CSV header), e.g. `mast_tip_v`.
    pub name: String,
    /// Human label, e.g. "mast tip deflection v".
    pub label: String,
    /// SI unit.
    pub unit: &'static str,
    /// Group.
    pub kind: ChannelKind,
    /// The row c: value = c · q (or c · q̈, see `order`) + `offset`.
    pub row: Vec<f64>,
    /// The derivative of q the row multiplies.
    pub order: Order,
    /// A constant added to c · q (or c · q̈): a static part the linear model does not carry.
    pub offset: f64,
    /// A second row c_v whose product with q̇ is added too (a dashpot's share: a compliant
    /// latch's moment −k_L θ − c_L θ̇); `None` for most channels.
    pub rate_row: Option<Vec<f64>>,
}

/// The standard channels of a model: beams' tips, plates' tip corners, the hub.
pub fn standard_channels(model: &RitzModel) -> Vec<Channel> {
    let n = model.dof();
    let st = &model.structure;
    let mut out = Vec::new();
    for e in &model.elements {
        match &e.kind {
            ElementKind::Beam {
                index,
                bending,
                torsion,
                ..
            } => {
                let name = &st.beams[*index].name;
                let xb = bending.eval_vec(1.0);
                let xt = torsion.eval_vec(1.0);
                for (field, label, unit, values) in [
                    (FieldKind::V, "v", "m", &xb),
                    (FieldKind::W, "w", "m", &xb),
                    (FieldKind::Theta, "twist", "rad", &xt),
                ] {
                    let mut row = vec![0.0; n];
                    for (k, c) in e.field(field).enumerate() {
                        row[c] = values[k][0];
                    }
                    out.push(Channel {
                        name: format!("{name}_tip_{label}"),
                        label: if unit == "m" {
                            format!("{name} tip deflection {label}")
                        } else {
                            format!("{name} tip twist")
                        },
                        unit,
                        kind: ChannelKind::BeamTip { beam: name.clone() },
                        row,
                        order: Order::Displacement,
                        offset: 0.0,
                        rate_row: None,
                    });
                }
            }
            ElementKind::Plate {
                index,
                length,
                width,
            } => {
                let name = &st.plates[*index].name;
                let xv = length.eval_vec(1.0);
                let ny = width.len();
                let start = e.own_range().start;
                for (eta, side, sign) in [(0.0, "minus", "−"), (1.0, "plus", "+")] {
                    let yv = width.eval_vec(eta);
                    let mut row = vec![0.0; n];
                    for (m, x) in xv.iter().enumerate() {
                        for (k, y) in yv.iter().enumerate() {
                            row[start + m * ny + k] = x[0] * y[0];
                        }
                    }
                    out.push(Channel {
                        name: format!("{name}_tip_{side}"),
                        label: format!("{name} tip corner y = {sign}b/2"),
                        unit: "m",
                        kind: ChannelKind::PlateTip {
                            plate: name.clone(),
                        },
                        row,
                        order: Order::Displacement,
                        offset: 0.0,
                        rate_row: None,
                    });
                }
            }
            ElementKind::Rigid => {}
        }
    }
    // Hub coordinates 0–2 (translation of its centre of mass) and 3–5 (small rotation).
    for (first, name, label, unit, kind) in [
        (
            0,
            "hub_",
            "hub translation ",
            "m",
            ChannelKind::HubTranslation,
        ),
        (
            3,
            "hub_r",
            "hub rotation about ",
            "rad",
            ChannelKind::HubRotation,
        ),
    ] {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let mut row = vec![0.0; n];
            row[first + k] = 1.0;
            out.push(Channel {
                name: format!("{name}{axis}"),
                label: format!("{label}{axis}"),
                unit,
                kind: kind.clone(),
                row,
                order: Order::Displacement,
                offset: 0.0,
                rate_row: None,
            });
        }
    }
    out
}
