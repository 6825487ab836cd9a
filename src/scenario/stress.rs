//! Stresses and margins: `[materials.X] allowable_stress` and `factor_of_safety`, a general
//! section's fibres (`y_extreme`, `z_extreme`, `torsion_radius`, `shear_factor_y`,
//! `shear_factor_z`; a tube's come from its geometry) and `[deployment.latch]
//! moment_allowable` (docs/theory.md §3.3).

use super::context::Ctx;
use super::raw::{RawScenario, S};
use super::ScenarioError;
use crate::limits as L;
use crate::response::stress::{Allowable, BeamStress, SectionFibres, StressSpec};

/// The stress settings of every beam and the latch's allowable moment.
pub(super) fn lower(cx: &Ctx, raw: &RawScenario) -> Result<StressSpec, ScenarioError> {
    let mut allowables = std::collections::BTreeMap::new();
    for (name, m) in &raw.materials {
        let r = m.get_ref();
        let k = format!("materials.{name}");
        let stress = match &r.allowable_stress {
            Some(v) => Some(cx.bounded(v, format!("{k}.allowable_stress"), L::ALLOWABLE_STRESS)?),
            None => None,
        };
        let factor = match &r.factor_of_safety {
            Some(v) => {
                let f = cx.bounded(v, format!("{k}.factor_of_safety"), L::FACTOR_OF_SAFETY)?;
                if stress.is_none() {
                    return Err(cx.invalid(
                        v.span(),
                        format!("{k}.factor_of_safety"),
                        "a factor of safety needs allowable_stress beside it",
                    ));
                }
                f
            }
            None => 1.0,
        };
        allowables.insert(
            name.as_str(),
            stress.map(|stress| Allowable {
                stress,
                factor_of_safety: factor,
            }),
        );
    }
    let mut beams = Vec::new();
    for (i, b) in raw.beams.iter().enumerate() {
        let b = b.get_ref();
        let sec = b.section.get_ref();
        let k = format!("beams[{i}].section");
        let allowable = allowables
            .get(b.material.get_ref().as_str())
            .copied()
            .flatten();
        let general = [
            (&sec.y_extreme, "y_extreme"),
            (&sec.z_extreme, "z_extreme"),
            (&sec.torsion_radius, "torsion_radius"),
            (&sec.shear_factor_y, "shear_factor_y"),
            (&sec.shear_factor_z, "shear_factor_z"),
        ];
        let fibres = match &sec.tube {
            Some(t) => {
                if let Some((v, key)) = general
                    .iter()
                    .find_map(|(v, key)| v.as_ref().map(|v| (v, key)))
                {
                    return Err(cx.invalid(
                        v.span(),
                        format!("{k}.{key}"),
                        "a tube's fibres come from its geometry: give them for a general section only",
                    ));
                }
                let t = t.get_ref();
                Some(SectionFibres::tube(
                    *t.outer_diameter.get_ref(),
                    *t.wall.get_ref(),
                ))
            }
            None => {
                let given: Vec<&S<f64>> = general.iter().filter_map(|(v, _)| v.as_ref()).collect();
                if given.is_empty() && allowable.is_none() {
                    None
                } else if let Some((_, key)) = general.iter().find(|(v, _)| v.is_none()) {
                    let why = if given.is_empty() {
                        format!(
                            "missing `{key}`: the material \"{}\" has an allowable_stress, and a \
                             general section's stresses need y_extreme, z_extreme, torsion_radius, \
                             shear_factor_y and shear_factor_z",
                            b.material.get_ref()
                        )
                    } else {
                        format!(
                            "missing `{key}`: a general section's stresses need all of y_extreme, \
                             z_extreme, torsion_radius, shear_factor_y and shear_factor_z"
                        )
                    };
                    return Err(cx.missing(b.section.span(), format!("{k}.{key}"), why));
                } else {
                    let get = |j: usize, lim| -> Result<f64, ScenarioError> {
                        let (v, key) = general[j];
                        let v = v.as_ref().expect("every key is given here");
                        cx.bounded(v, format!("{k}.{key}"), lim)
                    };
                    Some(SectionFibres {
                        round: false,
                        y: get(0, L::SECTION)?,
                        z: get(1, L::SECTION)?,
                        torsion_radius: get(2, L::SECTION)?,
                        shear_factor: (get(3, L::SHEAR_FACTOR)?, get(4, L::SHEAR_FACTOR)?),
                    })
                }
            }
        };
        beams.push(BeamStress { fibres, allowable });
    }
    let latch_moment_allowable = match raw
        .deployment
        .as_ref()
        .and_then(|d| d.get_ref().latch.as_ref())
        .and_then(|l| l.get_ref().moment_allowable.as_ref())
    {
        Some(v) => Some(cx.bounded(
            v,
            "deployment.latch.moment_allowable",
            L::LATCH_MOMENT_ALLOWABLE,
        )?),
        None => None,
    };
    Ok(StressSpec {
        beams,
        latch_moment_allowable,
    })
}
