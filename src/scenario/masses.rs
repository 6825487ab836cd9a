//! `[[masses]]`: rigid lumped masses.

use super::attach::Written;
use super::context::{span_or, Ctx};
use super::raw::{RawMass, S};
use super::ScenarioError;
use crate::math::{Mat3, Vec3};
use crate::structure::{inertia_tensor, Field, LumpedMass};
use std::collections::BTreeMap;
use std::ops::Range;

/// Lumped mass `i`; validated by [`LumpedMass::new`] and [`inertia_tensor`].
pub(super) fn lower(
    cx: &Ctx,
    i: usize,
    raw: &S<RawMass>,
    beams: &BTreeMap<&str, usize>,
) -> Result<LumpedMass, ScenarioError> {
    let m = raw.get_ref();
    let k = format!("masses[{i}]");
    let written = Written {
        key: &k,
        parent: &m.parent,
        station: &m.station,
        point: &m.point,
        point_key: "point",
    };
    let attachment = written.lower(cx, beams)?;
    let at = |f: Field| -> (Range<usize>, String) {
        if let Some(w) = written.at(f) {
            return w;
        }
        let span = match f {
            Field::Name => m.name.span(),
            Field::Mass => m.mass.span(),
            Field::Offset => span_or(&m.offset, m.name.span()),
            Field::Inertia => span_or(&m.inertia, m.name.span()),
            _ => m.name.span(),
        };
        (span, format!("{k}.{}", f.key()))
    };
    let inertia = match &m.inertia {
        Some(j) => cx.domain(inertia_tensor(j.get_ref()), at)?,
        None => Mat3::ZERO,
    };
    let offset = m.offset.as_ref().map_or(Vec3::ZERO, |o| Vec3(*o.get_ref()));
    cx.domain(
        LumpedMass::new(
            m.name.get_ref(),
            attachment,
            offset,
            *m.mass.get_ref(),
            inertia,
        ),
        at,
    )
}
