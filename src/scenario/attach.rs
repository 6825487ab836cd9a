//! Where a beam, plate or lumped mass is fixed: `parent = "hub"` with a point, or a beam's
//! name with a `station`. Parent names are resolved to beam indices here, once.

use super::context::Ctx;
use super::raw::S;
use super::ScenarioError;
use crate::math::Vec3;
use crate::structure::{Attachment, Field};
use std::collections::BTreeMap;
use std::ops::Range;

/// How an attachment was written: the spans a refusal points at.
pub(super) struct Written<'a> {
    /// The component's key, e.g. `plates[0]`.
    pub key: &'a str,
    pub parent: &'a S<String>,
    pub station: &'a Option<S<f64>>,
    pub point: &'a Option<S<[f64; 3]>>,
    /// The point's key: `root` (beams, plates) or `point` (masses).
    pub point_key: &'static str,
}

impl Written<'_> {
    /// Where an attachment field was written, and its key.
    pub fn at(&self, f: Field) -> Option<(Range<usize>, String)> {
        match f {
            Field::Root => Some((
                super::context::span_or(self.point, self.parent.span()),
                format!("{}.{}", self.key, self.point_key),
            )),
            Field::Station => Some((
                super::context::span_or(self.station, self.parent.span()),
                format!("{}.station", self.key),
            )),
            Field::Parent => Some((self.parent.span(), format!("{}.parent", self.key))),
            _ => None,
        }
    }

    /// The attachment, with the parent resolved among `beams` (name → index).
    pub fn lower(
        &self,
        cx: &Ctx,
        beams: &BTreeMap<&str, usize>,
    ) -> Result<Attachment, ScenarioError> {
        let (key, pk) = (self.key, self.point_key);
        if self.parent.get_ref() == "hub" {
            if let Some(s) = self.station {
                return Err(cx.invalid(
                    s.span(),
                    format!("{key}.station"),
                    format!("station applies to a beam parent; on the hub give {pk} = [x, y, z]"),
                ));
            }
            let p = self.point.as_ref().ok_or_else(|| {
                cx.missing(
                    self.parent.span(),
                    format!("{key}.{pk}"),
                    format!("missing field `{pk}`: the attachment point on the hub"),
                )
            })?;
            return Ok(Attachment::Hub {
                point: Vec3(*p.get_ref()),
            });
        }
        if let Some(p) = self.point {
            return Err(cx.invalid(
                p.span(),
                format!("{key}.{pk}"),
                format!("{pk} applies to the hub; on a beam parent give station"),
            ));
        }
        let s = self.station.as_ref().ok_or_else(|| {
            cx.missing(
                self.parent.span(),
                format!("{key}.station"),
                "missing field `station`: distance from the parent beam's root",
            )
        })?;
        let beam = *beams.get(self.parent.get_ref().as_str()).ok_or_else(|| {
            let known: Vec<&str> = beams.keys().copied().collect();
            cx.invalid(
                self.parent.span(),
                format!("{key}.parent"),
                format!(
                    "unknown parent \"{}\" (the hub is \"hub\"; beams: {})",
                    self.parent.get_ref(),
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        })?;
        Ok(Attachment::Beam {
            beam,
            station: *s.get_ref(),
        })
    }
}
