//! The planar deployment chain of a plate of the 3-D structure: panel masses and inertias
//! from the plate, the hub's planar mass properties, the root hinge's arm (the derivation
//! from the structure lives here, beside the chain it builds).
//!
//! The chain moves in the plane spanned by the plate's length axis (u) and normal (v); hinge
//! axes run along its width. A free hub is planar: its mass and its inertia about the width
//! axis, from the hub body alone.

use super::chain::{Chain, Hinge, Panel, PlanarHub};
use crate::structure::Structure;

/// Panel mass and inertia overrides; `None` derives them from the plate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PanelOverrides {
    /// Mass of every panel, kg (default: areal density × length × width).
    pub mass: Option<f64>,
    /// Inertia of every panel about its centroidal hinge-parallel axis, kg·m²
    /// (default: m l² / 12, a uniform bar).
    pub inertia: Option<f64>,
}

/// The chain of plate `plate` of `st` cut into panels of the given lengths (summing to the
/// plate's length), with `hinges` (one per panel, root first) and the hub free or held in
/// the deployment plane.
pub fn chain_of_plate(
    st: &Structure,
    plate: usize,
    lengths: &[f64],
    overrides: PanelOverrides,
    hinges: Vec<Hinge>,
    hub_free: bool,
) -> Chain {
    let p = &st.plates[plate];
    let panels = lengths
        .iter()
        .map(|&l| {
            let mass = overrides.mass.unwrap_or(p.areal_density * l * p.width);
            Panel {
                length: l,
                mass,
                inertia: overrides.inertia.unwrap_or(mass * l * l / 12.0),
            }
        })
        .collect();
    let hub = if hub_free {
        let w = p.width_axis();
        PlanarHub::Free {
            mass: st.hub.mass,
            inertia: st.hub.inertia.apply(w).dot(w),
        }
    } else {
        PlanarHub::Fixed
    };
    let arm = st.attachment_point(&p.attachment) - st.hub.center_of_mass;
    Chain {
        panels,
        hinges,
        hub,
        root: [arm.dot(p.length_axis), arm.dot(p.normal)],
    }
}
