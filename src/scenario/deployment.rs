//! `[deployment]`: the accordion-folded array of one plate, its hinges and the run settings.
//! The chain itself (panel masses, the hub's planar mass properties, the root arm) is derived
//! from the structure by [`crate::deploy::planar`].

use super::context::Ctx;
use super::raw::{
    RawBase, RawDeployment, RawIntegrator, RawLatchModel, RawLatching, RawPerHinge,
    RawSynchronisation, S,
};
use super::ScenarioError;
use crate::deploy::base::BaseKind;
use crate::deploy::chain::Hinge;
use crate::deploy::coupled::Synchronisation;
use crate::deploy::{Deployment, Integrator, LatchModel, Latching};
use crate::limits as L;
use crate::structure::HubMotion;
use crate::structure::Structure;

/// Default deployment settings (docs/scenario.md).
pub const DEFAULT_END_TIME: f64 = 300.0;
/// Default sample rate, Hz.
pub const DEFAULT_OUTPUT_RATE: f64 = 10.0;
/// Default relative integration tolerance of the named integrators.
pub const DEFAULT_TOLERANCE: f64 = 1e-10;
/// Default results accuracy of the automatic integrator (relative).
pub const DEFAULT_ACCURACY: f64 = 1e-3;

/// Builds the deployment from `[deployment]` and the structure: the deploying plate, its
/// panels and hinges, the run settings; the chain itself comes from
/// [`crate::deploy::planar::chain_of_plate`].
pub(super) fn lower(
    cx: &Ctx,
    raw: &S<RawDeployment>,
    st: &Structure,
) -> Result<Deployment, ScenarioError> {
    let d = raw.get_ref();
    if let Some(h) = &d.hub {
        return Err(cx.invalid(
            h.span(),
            "deployment.hub",
            "this key is gone: the hub moves the same way during deployment and response, \
             as [hub] motion says (\"free\" or \"fixed\"); remove deployment.hub",
        ));
    }
    let plate_index = st
        .plates
        .iter()
        .position(|p| p.name == *d.plate.get_ref())
        .ok_or_else(|| {
            let names: Vec<&str> = st.plates.iter().map(|p| p.name.as_str()).collect();
            cx.invalid(
                d.plate.span(),
                "deployment.plate",
                format!(
                    "no plate named \"{}\" (plates: {})",
                    d.plate.get_ref(),
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            )
        })?;
    let plate = &st.plates[plate_index];
    let lengths = panel_lengths(cx, raw, plate)?;
    let panel_mass = match &d.panel_mass {
        Some(m) => Some(cx.bounded(m, "deployment.panel_mass", L::MASS)?),
        None => None,
    };
    let panel_inertia = match &d.panel_inertia {
        Some(m) => Some(cx.bounded(m, "deployment.panel_inertia", L::PANEL_INERTIA)?),
        None => None,
    };
    let hinges = hinges(cx, raw, lengths.len())?;
    let chain = crate::deploy::planar::chain_of_plate(
        st,
        plate_index,
        &lengths,
        crate::deploy::planar::PanelOverrides {
            mass: panel_mass,
            inertia: panel_inertia,
        },
        hinges,
        st.hub.motion == HubMotion::Free,
    );
    // Panel masses and inertias derived from the plate obey the ranges of given ones.
    if let Some(p) = chain
        .panels
        .iter()
        .find(|p| !(L::MASS.contains(p.mass) && L::PANEL_INERTIA.contains(p.inertia)))
    {
        return Err(cx.invalid(
            d.plate.span(),
            "deployment.plate",
            format!(
                "a panel of this plate has mass {:e} kg and inertia {:e} kg·m²; they must lie in {} \
                 and {} (give panel_mass / panel_inertia, or fewer panels)",
                p.mass,
                p.inertia,
                L::MASS.describe(),
                L::PANEL_INERTIA.describe()
            ),
        ));
    }
    let (end_time, output_rate, tolerance) = run_settings(cx, raw)?;
    let synchronisation = synchronisation(cx, raw, &chain.hinges)?;
    let latch = latch(cx, raw, chain.len())?;
    let integrator = match d.integrator.as_ref().map(|i| *i.get_ref()) {
        Some(RawIntegrator::Implicit) => Integrator::Implicit,
        Some(RawIntegrator::Adiabatic) => Integrator::Adiabatic,
        Some(RawIntegrator::Explicit) => Integrator::Explicit,
        Some(RawIntegrator::Auto) | None => Integrator::Auto,
    };
    let accuracy = accuracy(cx, raw, integrator)?;
    Ok(Deployment {
        latch,
        integrator,
        accuracy,
        base: base(cx, raw)?,
        base_damping_ratio: base_damping_ratio(cx, raw)?,
        settling: None,
        synchronisation,
        plate: plate.name.clone(),
        chain,
        latching: match d.latching.as_ref().map(|l| *l.get_ref()) {
            Some(RawLatching::Simultaneous) => Latching::Simultaneous,
            _ => Latching::Sequential,
        },
        end_time,
        output_rate,
        tolerance,
    })
}

/// `[deployment.latch]`: the rigid latch (default) or the compliant one with its stiffness
/// and damping (one value or one per hinge) and settle time.
fn latch(cx: &Ctx, raw: &S<RawDeployment>, n: usize) -> Result<LatchModel, ScenarioError> {
    let Some(l) = &raw.get_ref().latch else {
        return Ok(LatchModel::Rigid);
    };
    let lr = l.get_ref();
    let compliant = matches!(
        lr.model.as_ref().map(|m| *m.get_ref()),
        Some(RawLatchModel::Compliant)
    );
    if !compliant {
        for (key, span) in [
            ("stiffness", lr.stiffness.as_ref().map(|v| v.span())),
            ("damping", lr.damping.as_ref().map(|v| v.span())),
            ("settle_time", lr.settle_time.as_ref().map(|v| v.span())),
        ] {
            if let Some(span) = span {
                return Err(cx.invalid(
                    span,
                    format!("deployment.latch.{key}"),
                    "a rigid latch (model = \"rigid\", the default) has no stiffness, damping or \
                     settle time: set model = \"compliant\" or remove the key",
                ));
            }
        }
        return Ok(LatchModel::Rigid);
    }
    let per_hinge = |v: &Option<S<RawPerHinge>>,
                     key: &str,
                     limit: L::Limit|
     -> Result<Vec<f64>, ScenarioError> {
        let key = format!("deployment.latch.{key}");
        let Some(v) = v else {
            return Err(cx.missing(
                l.span(),
                key,
                "missing: a compliant latch needs stiffness and damping",
            ));
        };
        let values = match v.get_ref() {
            RawPerHinge::One(x) => vec![*x; n],
            RawPerHinge::Each(list) if list.len() == n => list.clone(),
            RawPerHinge::Each(list) => {
                return Err(cx.invalid(
                    v.span(),
                    key,
                    format!(
                        "{} values for {n} hinges: give one value, or one per hinge",
                        list.len()
                    ),
                ))
            }
        };
        if let Some(bad) = values.iter().find(|x| !limit.contains(**x)) {
            return Err(cx.invalid(v.span(), key, limit.refusal(*bad)));
        }
        Ok(values)
    };
    let stiffness = per_hinge(&lr.stiffness, "stiffness", L::LATCH_STIFFNESS)?;
    let damping = per_hinge(&lr.damping, "damping", L::LATCH_DAMPING)?;
    let settle_time = match &lr.settle_time {
        Some(v) => Some(cx.bounded(v, "deployment.latch.settle_time", L::DURATION)?),
        None => None,
    };
    Ok(LatchModel::Compliant {
        stiffness,
        damping,
        settle_time,
    })
}

/// `base` and `base_modes`.
fn base(cx: &Ctx, raw: &S<RawDeployment>) -> Result<BaseKind, ScenarioError> {
    let d = raw.get_ref();
    let rigid = matches!(d.base.as_ref().map(|b| *b.get_ref()), Some(RawBase::Rigid));
    match &d.base_modes {
        None if rigid => Ok(BaseKind::Rigid),
        None => Ok(BaseKind::Flexible { modes: None }),
        Some(m) if rigid => Err(cx.invalid(
            m.span(),
            "deployment.base_modes",
            "a rigid base (base = \"rigid\") has no modes to keep: remove base_modes or set \
             base = \"flexible\"",
        )),
        Some(m) => {
            let k = *m.get_ref();
            if k < 0 {
                return Err(cx.invalid(
                    m.span(),
                    "deployment.base_modes",
                    format!("must be a number of modes (0 or more), got {k}"),
                ));
            }
            Ok(BaseKind::Flexible {
                modes: Some(usize::try_from(k).unwrap_or(usize::MAX)),
            })
        }
    }
}

/// `base_damping_ratio`: ζ in [0, 1) of the flexible base's modal damping, refused with a
/// rigid base (it has no modes to damp). Absent: 0 (undamped; `[response] damping_ratio` is
/// not inherited, so that no deployment result changes without the key).
fn base_damping_ratio(cx: &Ctx, raw: &S<RawDeployment>) -> Result<f64, ScenarioError> {
    let d = raw.get_ref();
    let rigid = matches!(d.base.as_ref().map(|b| *b.get_ref()), Some(RawBase::Rigid));
    match &d.base_damping_ratio {
        None => Ok(0.0),
        Some(z) if rigid => Err(cx.invalid(
            z.span(),
            "deployment.base_damping_ratio",
            "a rigid base (base = \"rigid\") has no modes to damp: remove base_damping_ratio \
             or set base = \"flexible\"",
        )),
        Some(z) if L::DAMPING_RATIO.contains(*z.get_ref()) => Ok(*z.get_ref()),
        Some(z) => Err(cx.invalid(
            z.span(),
            "deployment.base_damping_ratio",
            format!(
                "must lie in [0, 1): below 1 (an underdamped structure), got {}",
                z.get_ref()
            ),
        )),
    }
}

/// Relative tolerance of the cable law's check on the hinges' angles and rates.
const CABLE_LAW_TOL: f64 = 1e-9;

/// `synchronisation` and `cable_stiffness`. The cable law ties the hinges' openings,
/// α_2 − α_2(0) = 2 (α_1 − α_1(0)) and α_{i+1} − α_{i+1}(0) = α_i − α_i(0), whatever the
/// panel lengths; it is refused when the latch angles (or the initial rates) do not follow
/// it, since then the hinges could not all reach their latch angles together.
fn synchronisation(
    cx: &Ctx,
    raw: &S<RawDeployment>,
    hinges: &[Hinge],
) -> Result<Synchronisation, ScenarioError> {
    let d = raw.get_ref();
    let cable = matches!(
        d.synchronisation.as_ref().map(|s| *s.get_ref()),
        Some(RawSynchronisation::Cable)
    );
    let stiffness = match &d.cable_stiffness {
        Some(k) if !cable => {
            return Err(cx.invalid(
                k.span(),
                "deployment.cable_stiffness",
                "only a cable has a stiffness: set synchronisation = \"cable\" or remove \
                 cable_stiffness",
            ))
        }
        Some(k) => Some(cx.bounded(k, "deployment.cable_stiffness", L::CABLE_STIFFNESS)?),
        None => None,
    };
    if !cable {
        return Ok(Synchronisation::None);
    }
    let span = d.synchronisation.as_ref().map_or(raw.span(), |s| s.span());
    if hinges.len() < 2 {
        return Err(cx.invalid(
            span,
            "deployment.synchronisation",
            "a cable ties neighbouring hinges: it needs at least 2 panels",
        ));
    }
    let opening = |h: &Hinge| h.latch_angle - h.initial_angle;
    let root = opening(&hinges[0]);
    for (i, h) in hinges.iter().enumerate().skip(1) {
        let want = 2.0 * root;
        if (opening(h) - want).abs() > CABLE_LAW_TOL * want.abs().max(1.0) {
            return Err(cx.invalid(
                span,
                "deployment.synchronisation",
                format!(
                    "the cable opens every interior hinge twice as far as the root hinge \
                     (α_i − α_i(0) = 2 (α_1 − α_1(0))), so all reach their latch angles \
                     together only if latch_angle − initial_angle is {want} rad for hinge {} \
                     (root hinge: {root} rad); it is {} rad. Adjust latch_angle / \
                     initial_angle or remove synchronisation",
                    i + 1,
                    opening(h)
                ),
            ));
        }
        let rate = 2.0 * hinges[0].initial_rate;
        if (h.initial_rate - rate).abs() > CABLE_LAW_TOL * rate.abs().max(1.0) {
            return Err(cx.invalid(
                span,
                "deployment.synchronisation",
                format!(
                    "the cable makes every interior hinge's rate twice the root hinge's: \
                     hinge {} needs initial_rate {rate} rad/s, it has {} rad/s",
                    i + 1,
                    h.initial_rate
                ),
            ));
        }
    }
    Ok(stiffness.map_or(Synchronisation::IdealCable, Synchronisation::ElasticCable))
}

/// `panels` (equal lengths) or `panel_lengths` (summing to the plate's length).
fn panel_lengths(
    cx: &Ctx,
    raw: &S<RawDeployment>,
    plate: &crate::structure::Plate,
) -> Result<Vec<f64>, ScenarioError> {
    let d = raw.get_ref();
    Ok(match (&d.panels, &d.panel_lengths) {
        (Some(_), Some(l)) => {
            return Err(cx.invalid(
                l.span(),
                "deployment.panel_lengths",
                "give either panels or panel_lengths, not both",
            ))
        }
        (Some(n), None) => {
            let v = *n.get_ref();
            if !(1..=L::MAX_PANELS as i64).contains(&v) {
                return Err(cx.invalid(
                    n.span(),
                    "deployment.panels",
                    format!("must be between 1 and {}, got {v}", L::MAX_PANELS),
                ));
            }
            let l = plate.length / v as f64;
            if !L::PANEL_LENGTH.contains(l) {
                return Err(cx.invalid(
                    n.span(),
                    "deployment.panels",
                    format!(
                        "{v} panels of the {} m plate are {l:e} m long; a panel's length must lie in {}",
                        plate.length,
                        L::PANEL_LENGTH.describe()
                    ),
                ));
            }
            vec![l; v as usize]
        }
        (None, Some(l)) => {
            let v = l.get_ref();
            if v.is_empty() || v.len() > L::MAX_PANELS {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!("needs 1 to {} lengths, got {}", L::MAX_PANELS, v.len()),
                ));
            }
            if let Some(bad) = v.iter().find(|x| !L::PANEL_LENGTH.contains(**x)) {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!(
                        "every length must lie in {}, got {bad:e}",
                        L::PANEL_LENGTH.describe()
                    ),
                ));
            }
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |(a, b), x| (a.min(*x), b.max(*x)));
            if hi > L::MAX_PANEL_LENGTH_RATIO * lo {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!(
                        "the longest panel ({hi} m) is more than {} times the shortest ({lo} m)",
                        L::MAX_PANEL_LENGTH_RATIO
                    ),
                ));
            }
            let sum: f64 = v.iter().sum();
            if (sum - plate.length).abs() > 1e-9 * plate.length {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!(
                        "the lengths sum to {sum} m, but the plate \"{}\" is {} m long",
                        plate.name, plate.length
                    ),
                ));
            }
            v.clone()
        }
        (None, None) => {
            return Err(cx.missing(
                raw.span(),
                "deployment.panels",
                "missing: give panels or panel_lengths",
            ))
        }
    })
}

/// `[deployment.hinge]` for every hinge, `[[deployment.hinges]]` per hinge overriding it.
fn hinges(cx: &Ctx, raw: &S<RawDeployment>, n: usize) -> Result<Vec<Hinge>, ScenarioError> {
    use std::f64::consts::PI;
    let d = raw.get_ref();
    let (k_all, preload, damping_all, friction_all) = common_hinge(cx, raw)?;
    if let Some(list) = &d.hinges {
        if list.len() != n {
            let span = list.first().map_or(raw.span(), |h| h.span());
            return Err(cx.invalid(
                span,
                "deployment.hinges",
                format!("{} entries for {n} panels: give one per hinge", list.len()),
            ));
        }
    }
    let mut hinges = Vec::with_capacity(n);
    for i in 0..n {
        let one = d.hinges.as_ref().map(|l| &l[i]);
        let r = one.map(|h| h.get_ref());
        let key = |f: &str| {
            if r.is_some() {
                format!("deployment.hinges[{i}].{f}")
            } else {
                format!("deployment.hinge.{f}")
            }
        };
        let default_latch = if i == 0 { PI / 2.0 } else { PI };
        let latch = cx.bounded_or(
            &r.and_then(|h| h.latch_angle.clone()),
            default_latch,
            key("latch_angle"),
            L::LATCH_ANGLE,
        )?;
        let stiffness = match r.and_then(|h| h.stiffness.clone()) {
            Some(k) => cx.bounded(&k, key("stiffness"), L::HINGE_STIFFNESS)?,
            None => k_all.ok_or_else(|| {
                cx.missing(
                    one.map_or(raw.span(), |h| h.span()),
                    key("stiffness"),
                    format!("missing: hinge {} has no stiffness (set [deployment.hinge] stiffness or one per hinge)", i + 1),
                )
            })?,
        };
        let reference = cx.bounded_or(
            &r.and_then(|h| h.reference_angle.clone()),
            latch + preload,
            key("reference_angle"),
            L::ANGLE,
        )?;
        let initial = cx.bounded_or(
            &r.and_then(|h| h.initial_angle.clone()),
            0.0,
            key("initial_angle"),
            L::ANGLE,
        )?;
        if initial >= latch {
            let span = r
                .and_then(|h| h.initial_angle.as_ref())
                .map_or(raw.span(), |x| x.span());
            return Err(cx.invalid(
                span,
                key("initial_angle"),
                format!("{initial} rad is not below the latch angle {latch} rad"),
            ));
        }
        hinges.push(Hinge {
            stiffness,
            reference_angle: reference,
            damping: cx.bounded_or(
                &r.and_then(|h| h.damping.clone()),
                damping_all,
                key("damping"),
                L::HINGE_DAMPING,
            )?,
            friction: cx.bounded_or(
                &r.and_then(|h| h.friction.clone()),
                friction_all,
                key("friction"),
                L::HINGE_FRICTION,
            )?,
            latch_angle: latch,
            initial_angle: initial,
            initial_rate: cx.bounded_or(
                &r.and_then(|h| h.initial_rate.clone()),
                0.0,
                key("initial_rate"),
                L::RATE,
            )?,
        });
    }
    Ok(hinges)
}

/// `[deployment.hinge]`: stiffness (if given), preload, damping and friction for every hinge.
fn common_hinge(
    cx: &Ctx,
    raw: &S<RawDeployment>,
) -> Result<(Option<f64>, f64, f64, f64), ScenarioError> {
    let all = raw.get_ref().hinge.as_ref().map(|h| h.get_ref());
    let k_all = match all.and_then(|h| h.stiffness.as_ref()) {
        Some(k) => Some(cx.bounded(k, "deployment.hinge.stiffness", L::HINGE_STIFFNESS)?),
        None => None,
    };
    let preload = cx.bounded_or(
        &all.and_then(|h| h.preload_angle.clone()),
        0.0,
        "deployment.hinge.preload_angle",
        L::ANGLE,
    )?;
    let damping_all = cx.bounded_or(
        &all.and_then(|h| h.damping.clone()),
        0.0,
        "deployment.hinge.damping",
        L::HINGE_DAMPING,
    )?;
    let friction_all = cx.bounded_or(
        &all.and_then(|h| h.friction.clone()),
        0.0,
        "deployment.hinge.friction",
        L::HINGE_FRICTION,
    )?;
    Ok((k_all, preload, damping_all, friction_all))
}

/// `accuracy` (the automatic integrator's) and the refusal of `tolerance` with it: each key
/// belongs to its integrators.
fn accuracy(
    cx: &Ctx,
    raw: &S<RawDeployment>,
    integrator: Integrator,
) -> Result<f64, ScenarioError> {
    let d = raw.get_ref();
    if integrator == Integrator::Auto {
        if let Some(t) = &d.tolerance {
            return Err(cx.invalid(
                t.span(),
                "deployment.tolerance",
                "the automatic integrator (integrator = \"auto\", the default) sets its steps \
                 itself and bounds the results' error by [deployment] accuracy: give accuracy \
                 instead, or name an integrator (\"explicit\", \"implicit\", \"adiabatic\") \
                 to set its tolerance",
            ));
        }
        return cx.bounded_or(
            &d.accuracy,
            DEFAULT_ACCURACY,
            "deployment.accuracy",
            L::ACCURACY,
        );
    }
    if let Some(a) = &d.accuracy {
        return Err(cx.invalid(
            a.span(),
            "deployment.accuracy",
            "accuracy is the automatic integrator's (integrator = \"auto\", the default); a \
             named integrator takes tolerance: remove accuracy or the integrator key",
        ));
    }
    Ok(DEFAULT_ACCURACY)
}

/// End time, output rate (with the row cap) and tolerance.
fn run_settings(cx: &Ctx, raw: &S<RawDeployment>) -> Result<(f64, f64, f64), ScenarioError> {
    let d = raw.get_ref();
    let tolerance = cx.bounded_or(
        &d.tolerance,
        DEFAULT_TOLERANCE,
        "deployment.tolerance",
        L::TOLERANCE,
    )?;
    let end_time = cx.bounded_or(
        &d.end_time,
        DEFAULT_END_TIME,
        "deployment.end_time",
        L::DURATION,
    )?;
    let output_rate = cx.bounded_or(
        &d.output_rate,
        DEFAULT_OUTPUT_RATE,
        "deployment.output_rate",
        L::OUTPUT_RATE,
    )?;
    let rows = crate::response::rows(end_time, output_rate);
    if rows > crate::response::MAX_ROWS {
        let span = d
            .output_rate
            .as_ref()
            .or(d.end_time.as_ref())
            .map_or(raw.span(), |v| v.span());
        return Err(cx.invalid(
            span,
            "deployment.output_rate",
            format!(
                "{end_time} s at {output_rate} Hz would write {rows} rows; the limit is {} \
                 (lower output_rate or end_time)",
                crate::response::MAX_ROWS
            ),
        ));
    }
    Ok((end_time, output_rate, tolerance))
}
