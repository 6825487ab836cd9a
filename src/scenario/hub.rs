//! `[hub]`: the rigid hub, by its mass properties or as a cylinder of a material.

use super::context::Ctx;
use super::raw::{RawHub, RawMotion, S};
use super::ScenarioError;
use crate::math::Vec3;
use crate::structure::{inertia_tensor, Cylinder, Field, Hub, HubMotion, Material};
use std::collections::BTreeMap;

/// The hub; validated by [`Hub::new`] / [`Hub::cylinder`] and [`inertia_tensor`].
pub(super) fn lower(
    cx: &Ctx,
    raw: &S<RawHub>,
    materials: &BTreeMap<String, Material>,
) -> Result<Hub, ScenarioError> {
    let rh = raw.get_ref();
    let motion = match *rh.motion.get_ref() {
        RawMotion::Free => HubMotion::Free,
        RawMotion::Fixed => HubMotion::Fixed,
    };
    match &rh.shape {
        Some(shape) => {
            for (present, k) in [
                (rh.mass.is_some(), "mass"),
                (rh.inertia.is_some(), "inertia"),
                (rh.center_of_mass.is_some(), "center_of_mass"),
            ] {
                if present {
                    return Err(cx.invalid(
                        shape.span(),
                        format!("hub.{k}"),
                        "give either shape or mass/inertia/center_of_mass, not both",
                    ));
                }
            }
            let c = shape.get_ref().cylinder.get_ref();
            let k = "hub.shape.cylinder";
            let mat = super::materials::find(cx, materials, &c.material, format!("{k}.material"))?;
            let cyl = Cylinder {
                diameter: *c.diameter.get_ref(),
                wall: *c.wall.get_ref(),
                length: *c.length.get_ref(),
                axis: Vec3(*c.axis.get_ref()),
                center: Vec3(*c.center.get_ref()),
                closed_ends: c.closed_ends,
            };
            cx.domain(Hub::cylinder(motion, cyl, &mat), |f| {
                let span = match f {
                    Field::Diameter => c.diameter.span(),
                    Field::Wall => c.wall.span(),
                    Field::Length => c.length.span(),
                    Field::Axis => c.axis.span(),
                    Field::Center => c.center.span(),
                    _ => shape.span(),
                };
                (span, format!("{k}.{}", f.key()))
            })
        }
        None => {
            let missing = |k: &str| {
                cx.missing(
                    raw.span(),
                    format!("hub.{k}"),
                    format!("missing field `{k}` (or give hub.shape)"),
                )
            };
            let mass = rh.mass.as_ref().ok_or_else(|| missing("mass"))?;
            let inertia = rh.inertia.as_ref().ok_or_else(|| missing("inertia"))?;
            let com = rh
                .center_of_mass
                .as_ref()
                .ok_or_else(|| missing("center_of_mass"))?;
            let at = |f: Field| {
                let span = match f {
                    Field::Mass => mass.span(),
                    Field::CenterOfMass => com.span(),
                    _ => inertia.span(),
                };
                (span, format!("hub.{}", f.key()))
            };
            let j = cx.domain(inertia_tensor(inertia.get_ref()), at)?;
            cx.domain(
                Hub::new(motion, *mass.get_ref(), Vec3(*com.get_ref()), j),
                at,
            )
        }
    }
}
