//! `[[beams]]`: Euler–Bernoulli beams.

use super::attach::Written;
use super::context::{count, span_or, Ctx};
use super::raw::{RawBeam, S};
use super::{ScenarioError, DEFAULT_BEAM_TERMS};
use crate::math::Vec3;
use crate::structure::{Beam, BeamSection, BeamSpec, BeamTerms, Field, Frame, Material};
use std::collections::BTreeMap;
use std::ops::Range;

/// Beam `i`; every value validated by the structure's constructors.
pub(super) fn lower(
    cx: &Ctx,
    i: usize,
    raw: &S<RawBeam>,
    materials: &BTreeMap<String, Material>,
    beams: &BTreeMap<&str, usize>,
) -> Result<Beam, ScenarioError> {
    let b = raw.get_ref();
    let k = format!("beams[{i}]");
    let written = Written {
        key: &k,
        parent: &b.parent,
        station: &b.station,
        point: &b.root,
        point_key: "root",
    };
    let attachment = written.lower(cx, beams)?;
    let material = super::materials::find(cx, materials, &b.material, format!("{k}.material"))?;
    let sec = b.section.get_ref();
    let sk = format!("{k}.section");
    let at = |f: Field| -> (Range<usize>, String) {
        if let Some(w) = written.at(f) {
            return w;
        }
        let tube = sec.tube.as_ref().map(|t| t.get_ref());
        let (span, key) = match (f, tube) {
            (Field::Name, _) => (b.name.span(), format!("{k}.name")),
            (Field::Length, _) => (b.length.span(), format!("{k}.length")),
            (Field::Axis, _) => (b.axis.span(), format!("{k}.axis")),
            (Field::YAxis, _) => (span_or(&sec.y_axis, b.axis.span()), format!("{sk}.y_axis")),
            (Field::OuterDiameter, Some(t)) => {
                (t.outer_diameter.span(), format!("{sk}.tube.outer_diameter"))
            }
            (Field::Wall, Some(t)) => (t.wall.span(), format!("{sk}.tube.wall")),
            (Field::Area, _) => (span_or(&sec.area, b.section.span()), format!("{sk}.area")),
            (Field::Iy, _) => (span_or(&sec.iy, b.section.span()), format!("{sk}.iy")),
            (Field::Iz, _) => (span_or(&sec.iz, b.section.span()), format!("{sk}.iz")),
            (Field::TorsionConstant, _) => (
                span_or(&sec.torsion_constant, b.section.span()),
                format!("{sk}.torsion_constant"),
            ),
            (Field::PolarInertia, _) => (
                span_or(&sec.polar_inertia, b.section.span()),
                format!("{sk}.polar_inertia"),
            ),
            (f, _) => {
                let span = b.terms.as_ref().map_or(b.name.span(), |t| {
                    let t = t.get_ref();
                    match f {
                        Field::TermsBending => span_or(&t.bending, b.name.span()),
                        Field::TermsTorsion => span_or(&t.torsion, b.name.span()),
                        Field::TermsAxial => span_or(&t.axial, b.name.span()),
                        _ => b.name.span(),
                    }
                });
                (span, format!("{k}.{}", f.key()))
            }
        };
        (span, key)
    };
    let section = cx.domain(section(cx, raw, &sk)?, at)?;
    let frame = cx.domain(
        Frame::new(
            Vec3(*b.axis.get_ref()),
            sec.y_axis.as_ref().map(|y| Vec3(*y.get_ref())),
        ),
        at,
    )?;
    let (tb, tt, ta) = DEFAULT_BEAM_TERMS;
    let t = b.terms.as_ref().map(|t| t.get_ref());
    let terms = BeamTerms::new(
        t.map_or(tb, |t| count(&t.bending, tb)),
        t.map_or(tt, |t| count(&t.torsion, tt)),
        t.map_or(ta, |t| count(&t.axial, ta)),
    );
    let terms = cx.domain(terms, at)?;
    let spec = BeamSpec {
        name: b.name.get_ref().clone(),
        attachment,
        frame,
        length: *b.length.get_ref(),
        material,
        section,
        terms,
    };
    cx.domain(Beam::new(spec), at)
}

/// The section as written: a tube, or all five constants (not both).
fn section(
    cx: &Ctx,
    raw: &S<RawBeam>,
    sk: &str,
) -> Result<Result<BeamSection, crate::structure::StructureError>, ScenarioError> {
    let b = raw.get_ref();
    let sec = b.section.get_ref();
    let constants = [
        &sec.area,
        &sec.iy,
        &sec.iz,
        &sec.torsion_constant,
        &sec.polar_inertia,
    ];
    match &sec.tube {
        Some(t) => {
            if let Some(s) = constants.into_iter().flatten().next() {
                return Err(cx.invalid(
                    s.span(),
                    sk.to_string(),
                    "give either tube or the section constants, not both",
                ));
            }
            let t = t.get_ref();
            Ok(BeamSection::tube(
                *t.outer_diameter.get_ref(),
                *t.wall.get_ref(),
            ))
        }
        None => {
            let need = |v: &Option<S<f64>>, f: &str| -> Result<f64, ScenarioError> {
                v.as_ref().map(|v| *v.get_ref()).ok_or_else(|| {
                    cx.missing(
                        b.section.span(),
                        format!("{sk}.{f}"),
                        format!("missing field `{f}` (or give tube = {{ outer_diameter, wall }})"),
                    )
                })
            };
            Ok(BeamSection::general(
                need(&sec.area, "area")?,
                need(&sec.iy, "iy")?,
                need(&sec.iz, "iz")?,
                need(&sec.torsion_constant, "torsion_constant")?,
                need(&sec.polar_inertia, "polar_inertia")?,
            ))
        }
    }
}
