//! `[materials.NAME]`: isotropic materials by name.

use super::context::Ctx;
use super::raw::{RawMaterial, S};
use super::ScenarioError;
use crate::structure::{Field, Material};
use std::collections::BTreeMap;

/// The materials, by name; each validated by [`Material::new`].
pub(super) fn lower(
    cx: &Ctx,
    raw: &BTreeMap<String, S<RawMaterial>>,
) -> Result<BTreeMap<String, Material>, ScenarioError> {
    let mut out = BTreeMap::new();
    for (name, m) in raw {
        if let Err(why) = crate::limits::valid_name(name) {
            return Err(cx.invalid(
                m.span(),
                format!("materials.{name}"),
                format!("material name: {why}"),
            ));
        }
        let k = format!("materials.{name}");
        let r = m.get_ref();
        let mat = Material::new(
            *r.youngs_modulus.get_ref(),
            *r.poisson_ratio.get_ref(),
            *r.density.get_ref(),
            r.shear_modulus.as_ref().map(|g| *g.get_ref()),
        );
        let mat = cx.domain(mat, |f| {
            let span = match f {
                Field::YoungsModulus => r.youngs_modulus.span(),
                Field::PoissonRatio => r.poisson_ratio.span(),
                Field::Density => r.density.span(),
                Field::ShearModulus => super::context::span_or(&r.shear_modulus, m.span()),
                _ => m.span(),
            };
            (span, format!("{k}.{}", f.key()))
        })?;
        out.insert(name.clone(), mat);
    }
    Ok(out)
}

/// The material named by `s`, or a refusal listing the defined ones.
pub(super) fn find(
    cx: &Ctx,
    materials: &BTreeMap<String, Material>,
    s: &S<String>,
    key: String,
) -> Result<Material, ScenarioError> {
    materials.get(s.get_ref()).copied().ok_or_else(|| {
        let known: Vec<&str> = materials.keys().map(String::as_str).collect();
        cx.invalid(
            s.span(),
            key,
            format!(
                "unknown material \"{}\" (defined: {})",
                s.get_ref(),
                if known.is_empty() {
                    "none".into()
                } else {
                    known.join(", ")
                }
            ),
        )
    })
}
