//! `[[plates]]`: Kirchhoff plates (the wings).

use super::attach::Written;
use super::context::{count, span_or, Ctx};
use super::raw::{RawPlate, S};
use super::{ScenarioError, DEFAULT_PLATE_TERMS};
use crate::math::Vec3;
use crate::structure::{Field, Material, Plate, PlateSpec, PlateStiffness, PlateTerms};
use std::collections::BTreeMap;
use std::ops::Range;

/// Plate `i`; every value validated by [`Plate::new`] and [`PlateTerms::new`].
pub(super) fn lower(
    cx: &Ctx,
    i: usize,
    raw: &S<RawPlate>,
    materials: &BTreeMap<String, Material>,
    beams: &BTreeMap<&str, usize>,
) -> Result<Plate, ScenarioError> {
    let p = raw.get_ref();
    let k = format!("plates[{i}]");
    let written = Written {
        key: &k,
        parent: &p.parent,
        station: &p.station,
        point: &p.root,
        point_key: "root",
    };
    let attachment = written.lower(cx, beams)?;
    let stiffness = stiffness(cx, p, &k, materials)?;
    // Where each field the constructors check was written. D and ρh come from the
    // thickness (and the material's ν) when those are given.
    let at = |f: Field| -> (Range<usize>, String) {
        if let Some(w) = written.at(f) {
            return w;
        }
        let span = match f {
            Field::Name => p.name.span(),
            Field::LengthAxis => p.length_axis.span(),
            Field::Normal => p.normal.span(),
            Field::Length => p.length.span(),
            Field::Width => p.width.span(),
            Field::Thickness => span_or(&p.thickness, p.name.span()),
            Field::ArealDensity => span_or(&p.areal_density, p.name.span()),
            Field::BendingStiffness => span_or(&p.bending_stiffness, p.name.span()),
            Field::PoissonRatio => span_or(&p.poisson_ratio, p.name.span()),
            Field::TermsLength | Field::TermsWidth => p.terms.as_ref().map_or(p.name.span(), |t| {
                let t = t.get_ref();
                let v = if f == Field::TermsLength {
                    &t.length
                } else {
                    &t.width
                };
                span_or(v, p.name.span())
            }),
            _ => p.name.span(),
        };
        (span, format!("{k}.{}", f.key()))
    };
    let (tl, tw) = DEFAULT_PLATE_TERMS;
    let t = p.terms.as_ref().map(|t| t.get_ref());
    let terms = cx.domain(
        PlateTerms::new(
            t.map_or(tl, |t| count(&t.length, tl)),
            t.map_or(tw, |t| count(&t.width, tw)),
        ),
        at,
    )?;
    let spec = PlateSpec {
        name: p.name.get_ref().clone(),
        attachment,
        length_axis: Vec3(*p.length_axis.get_ref()),
        normal: Vec3(*p.normal.get_ref()),
        length: *p.length.get_ref(),
        width: *p.width.get_ref(),
        stiffness,
        terms,
    };
    cx.domain(Plate::new(spec), at)
}

/// Thickness + material, or areal density + bending stiffness + Poisson's ratio.
fn stiffness(
    cx: &Ctx,
    p: &RawPlate,
    k: &str,
    materials: &BTreeMap<String, Material>,
) -> Result<PlateStiffness, ScenarioError> {
    match (&p.material, &p.thickness) {
        (Some(m), Some(h)) => {
            for (v, f) in [
                (&p.areal_density, "areal_density"),
                (&p.bending_stiffness, "bending_stiffness"),
                (&p.poisson_ratio, "poisson_ratio"),
            ] {
                if let Some(v) = v {
                    return Err(cx.invalid(
                        v.span(),
                        format!("{k}.{f}"),
                        "give either thickness + material or areal_density + \
                         bending_stiffness + poisson_ratio",
                    ));
                }
            }
            Ok(PlateStiffness::Homogeneous {
                thickness: *h.get_ref(),
                material: super::materials::find(cx, materials, m, format!("{k}.material"))?,
            })
        }
        (None, None) => {
            let need = |v: &Option<S<f64>>, f: &str| -> Result<f64, ScenarioError> {
                v.as_ref().map(|v| *v.get_ref()).ok_or_else(|| {
                    cx.missing(
                        p.name.span(),
                        format!("{k}.{f}"),
                        format!("missing field `{f}` (or give thickness + material)"),
                    )
                })
            };
            Ok(PlateStiffness::Given {
                areal_density: need(&p.areal_density, "areal_density")?,
                bending_stiffness: need(&p.bending_stiffness, "bending_stiffness")?,
                poisson_ratio: need(&p.poisson_ratio, "poisson_ratio")?,
            })
        }
        (Some(m), None) => Err(cx.missing(
            m.span(),
            format!("{k}.thickness"),
            "missing field `thickness` (a plate of a material needs its thickness)",
        )),
        (None, Some(h)) => Err(cx.missing(
            h.span(),
            format!("{k}.material"),
            "missing field `material` (a plate of a given thickness needs its material)",
        )),
    }
}
