//! `[export]`: what the linear model for control design keeps (modes, damping), the named
//! points that carry inputs and outputs, and the transfer functions of the frequency
//! response.

use super::context::Ctx;
use super::raw::{RawDamping, RawExport, RawPoint, S};
use super::ScenarioError;
use crate::export::{
    default_transfers, input_names, output_names, Damping, ExportSettings, NamedPoint,
    PointLocation, Transfer, DEFAULT_FREQUENCY_POINTS,
};
use crate::limits as L;
use crate::math::Vec3;
use crate::structure::Structure;

/// A point's name: an identifier (it prefixes channel names such as `tip.fx`).
fn point_name(cx: &Ctx, v: &S<String>, key: &str) -> Result<String, ScenarioError> {
    let n = v.get_ref();
    let ok = n.len() <= L::MAX_NAME
        && n.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok {
        return Err(cx.invalid(
            v.span(),
            key,
            format!(
                "{n:?} is not a point name: 1 to {} letters, digits and `_`, starting with a \
                 letter (it prefixes the point's input and output names)",
                L::MAX_NAME
            ),
        ));
    }
    if n == "hub" {
        return Err(cx.invalid(
            v.span(),
            key,
            "\"hub\" is reserved for the hub's own inputs and outputs",
        ));
    }
    Ok(n.clone())
}

/// A unit-interval coordinate of a plate point.
fn unit_interval(
    cx: &Ctx,
    v: &Option<S<f64>>,
    span: std::ops::Range<usize>,
    key: &str,
) -> Result<f64, ScenarioError> {
    let Some(v) = v else {
        return Err(cx.missing(span, key, "a point on a plate needs xi and eta in [0, 1]"));
    };
    let x = *v.get_ref();
    if (0.0..=1.0).contains(&x) {
        Ok(x)
    } else {
        Err(cx.invalid(
            v.span(),
            key,
            format!("must lie in [0, 1] (a fraction of the plate's length or width), got {x}"),
        ))
    }
}

/// Refuses a key that does not belong to this kind of point.
fn refuse_extra<T>(cx: &Ctx, v: &Option<S<T>>, key: &str, kind: &str) -> Result<(), ScenarioError> {
    match v {
        Some(v) => Err(cx.invalid(
            v.span(),
            key,
            format!("a point on {kind} does not take this key"),
        )),
        None => Ok(()),
    }
}

/// One `[[export.points]]` entry.
fn lower_point(
    cx: &Ctx,
    i: usize,
    p: &S<RawPoint>,
    st: &Structure,
) -> Result<NamedPoint, ScenarioError> {
    let r = p.get_ref();
    let key = |k: &str| format!("export.points[{i}].{k}");
    let name = point_name(cx, &r.name, &key("name"))?;
    let comp = r.component.get_ref().as_str();
    let location = if comp == "hub" {
        refuse_extra(cx, &r.station, &key("station"), "the hub")?;
        refuse_extra(cx, &r.xi, &key("xi"), "the hub")?;
        refuse_extra(cx, &r.eta, &key("eta"), "the hub")?;
        let position = match &r.position {
            Some(v) => {
                let x = *v.get_ref();
                if !x.iter().all(|c| L::COORDINATE.contains(*c)) {
                    return Err(cx.invalid(
                        v.span(),
                        key("position"),
                        L::COORDINATE.refusal(
                            x.iter()
                                .copied()
                                .find(|c| !L::COORDINATE.contains(*c))
                                .unwrap_or(0.0),
                        ),
                    ));
                }
                Vec3::new(x[0], x[1], x[2])
            }
            None => Vec3::ZERO,
        };
        PointLocation::Hub { position }
    } else if let Some(beam) = st.beam_index(comp) {
        refuse_extra(cx, &r.xi, &key("xi"), "a beam")?;
        refuse_extra(cx, &r.eta, &key("eta"), "a beam")?;
        refuse_extra(cx, &r.position, &key("position"), "a beam")?;
        let length = st.beams()[beam].length();
        let station = match &r.station {
            None => {
                return Err(cx.missing(
                    p.span(),
                    key("station"),
                    format!(
                        "a point on beam \"{comp}\" needs station (m from its root, 0 to {length})"
                    ),
                ))
            }
            Some(v) => {
                let x = *v.get_ref();
                if !(0.0..=length).contains(&x) {
                    return Err(cx.invalid(
                        v.span(),
                        key("station"),
                        format!(
                            "must lie on beam \"{comp}\": 0 to {length} m from its root, got {x}"
                        ),
                    ));
                }
                x
            }
        };
        PointLocation::Beam { beam, station }
    } else if let Some(plate) = st.plates().iter().position(|pl| pl.name() == comp) {
        refuse_extra(cx, &r.station, &key("station"), "a plate")?;
        refuse_extra(cx, &r.position, &key("position"), "a plate")?;
        PointLocation::Plate {
            plate,
            xi: unit_interval(cx, &r.xi, p.span(), &key("xi"))?,
            eta: unit_interval(cx, &r.eta, p.span(), &key("eta"))?,
        }
    } else if let Some(mass) = st.masses().iter().position(|m| m.name() == comp) {
        refuse_extra(cx, &r.station, &key("station"), "a lumped mass")?;
        refuse_extra(cx, &r.xi, &key("xi"), "a lumped mass")?;
        refuse_extra(cx, &r.eta, &key("eta"), "a lumped mass")?;
        refuse_extra(cx, &r.position, &key("position"), "a lumped mass")?;
        PointLocation::Mass { mass }
    } else {
        return Err(cx.invalid(
            r.component.span(),
            key("component"),
            format!("no component is named {comp:?} (\"hub\", a beam, a plate or a lumped mass)"),
        ));
    };
    Ok(NamedPoint { name, location })
}

/// `damping_ratio`: one number, or a list whose length is the kept modes (it sets `modes`
/// when that is absent and must equal it otherwise).
fn lower_damping(
    cx: &Ctx,
    damping_ratio: &Option<S<RawDamping>>,
    modes: &mut Option<usize>,
) -> Result<Damping, ScenarioError> {
    let ratio = |v: f64| L::DAMPING_RATIO.contains(v);
    Ok(match damping_ratio {
        None => ExportSettings::default().damping,
        Some(v) => match v.get_ref() {
            RawDamping::One(z) if ratio(*z) => Damping::Uniform(*z),
            RawDamping::List(l) if !l.is_empty() && l.iter().all(|z| ratio(*z)) => {
                match *modes {
                    Some(n) if n != l.len() => {
                        return Err(cx.invalid(
                            v.span(),
                            "export.damping_ratio",
                            format!(
                                "lists {} values but export.modes = {n}: give one ratio per \
                                 kept elastic mode (or one number for all)",
                                l.len()
                            ),
                        ))
                    }
                    _ => *modes = Some(l.len()),
                }
                Damping::PerMode(l.clone())
            }
            _ => {
                return Err(cx.invalid(
                    v.span(),
                    "export.damping_ratio",
                    "must be a number in [0, 1) or a non-empty list of such numbers, one per \
                     kept elastic mode (an underdamped structure)",
                ))
            }
        },
    })
}

/// `[export]` (docs/scenario.md). A damping list sets the kept modes when `modes` is absent
/// and must match it otherwise.
pub(super) fn lower(
    cx: &Ctx,
    e: &S<RawExport>,
    st: &Structure,
) -> Result<ExportSettings, ScenarioError> {
    let r = e.get_ref();
    let mut modes = match &r.modes {
        None => None,
        Some(m) => {
            let k = *m.get_ref();
            match usize::try_from(k) {
                Ok(n) if (1..=L::MAX_EXPORT_MODES).contains(&n) => Some(n),
                _ => {
                    return Err(cx.invalid(
                        m.span(),
                        "export.modes",
                        format!(
                            "must be an integer from 1 to {} (elastic modes kept), got {k}",
                            L::MAX_EXPORT_MODES
                        ),
                    ))
                }
            }
        }
    };
    let damping = lower_damping(cx, &r.damping_ratio, &mut modes)?;
    if r.points.len() > L::MAX_EXPORT_POINTS {
        return Err(cx.invalid(
            r.points[L::MAX_EXPORT_POINTS].span(),
            "export.points",
            format!("at most {} named points", L::MAX_EXPORT_POINTS),
        ));
    }
    let mut points: Vec<NamedPoint> = Vec::new();
    for (i, p) in r.points.iter().enumerate() {
        let np = lower_point(cx, i, p, st)?;
        if points.iter().any(|q| q.name == np.name) {
            return Err(cx.invalid(
                p.get_ref().name.span(),
                format!("export.points[{i}].name"),
                format!("a point named {:?} is already defined", np.name),
            ));
        }
        points.push(np);
    }
    let (ins, outs) = (input_names(&points), output_names(&points));
    let mut transfers = Vec::new();
    for (i, t) in r.transfer.iter().enumerate() {
        let t = t.get_ref();
        for (v, names, what) in [(&t.input, &ins, "input"), (&t.output, &outs, "output")] {
            if !names.contains(v.get_ref()) {
                return Err(cx.invalid(
                    v.span(),
                    format!("export.transfer[{i}].{what}"),
                    format!(
                        "no {what} is named {:?}; the {what}s are {} (hub, then each named \
                         point)",
                        v.get_ref(),
                        names.join(", ")
                    ),
                ));
            }
        }
        transfers.push(Transfer {
            input: t.input.get_ref().clone(),
            output: t.output.get_ref().clone(),
        });
    }
    if transfers.is_empty() {
        transfers = default_transfers(st.hub().motion(), &points);
    }
    let frequency_range_hz = match &r.frequency_range {
        None => None,
        Some(v) => match v.get_ref().as_slice() {
            [lo, hi]
                if L::EXPORT_FREQUENCY.contains(*lo)
                    && L::EXPORT_FREQUENCY.contains(*hi)
                    && lo < hi =>
            {
                Some((*lo, *hi))
            }
            _ => {
                return Err(cx.invalid(
                    v.span(),
                    "export.frequency_range",
                    format!(
                        "must be [lowest, highest] in Hz, lowest < highest, both within {}",
                        L::EXPORT_FREQUENCY.describe()
                    ),
                ))
            }
        },
    };
    let frequency_points = match &r.frequency_points {
        None => DEFAULT_FREQUENCY_POINTS,
        Some(v) => match usize::try_from(*v.get_ref()) {
            Ok(n) if (2..=L::MAX_FREQUENCY_POINTS).contains(&n) => n,
            _ => {
                return Err(cx.invalid(
                    v.span(),
                    "export.frequency_points",
                    format!(
                        "must be an integer from 2 to {}, got {}",
                        L::MAX_FREQUENCY_POINTS,
                        v.get_ref()
                    ),
                ))
            }
        },
    };
    Ok(ExportSettings {
        modes,
        damping,
        points,
        transfers,
        frequency_range_hz,
        frequency_points,
    })
}
