//! `flexcraft export`: model.json (and the same arrays in model.npz and model.mat), the
//! frequency response (frequency_response.csv, plots/bode.{png,svg}) and the terminal
//! summary. Conventions: docs/export.md.

use super::flex42::{
    flex_file, flex_file_name, nodes_file, nodes_file_name, Flex42Error, FlexBody, FlexMode,
    FlexNode, MassPoint,
};
use super::names::csv_bytes;
use super::{num, ArrayValue, OutputDir, OutputError};
use crate::export::{
    mass_elements, point_motion, point_position, transfer_unit, ExportModel, PointLocation,
    Transfer,
};
use crate::ritz::ModalAnalysis;
use crate::ritz::RitzModel;
use crate::structure::{HubMotion, Structure};
use faer::Mat;
use serde_json::{json, Value};

const DIRECTIONS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];
const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// A matrix as a JSON array of rows.
fn rows(m: &Mat<f64>) -> Value {
    Value::Array(
        (0..m.nrows())
            .map(|i| Value::Array((0..m.ncols()).map(|j| json!(m[(i, j)])).collect()))
            .collect(),
    )
}

fn rows6(m: &[[f64; 6]; 6]) -> Value {
    json!(m.iter().map(|r| r.to_vec()).collect::<Vec<_>>())
}

/// Where a named point sits, for model.json and the 42 node file.
pub(crate) fn describe_location(st: &Structure, loc: &PointLocation) -> Value {
    match *loc {
        PointLocation::Hub { position } => json!({"component": "hub", "position_m": position.0}),
        PointLocation::Beam { beam, station } => {
            json!({"component": st.beams()[beam].name(), "station_m": station})
        }
        PointLocation::Plate { plate, xi, eta } => {
            json!({"component": st.plates()[plate].name(), "xi": xi, "eta": eta})
        }
        PointLocation::Mass { mass } => json!({"component": st.masses()[mass].name()}),
    }
}

/// Names of the rows of the mode shapes at the sites: `hub.ux … hub.rz`, `<point>.ux …`.
pub(crate) fn site_row_names(ex: &ExportModel) -> Vec<String> {
    std::iter::once("hub")
        .chain(ex.points.iter().map(|p| p.name.as_str()))
        .flat_map(|s| {
            ["ux", "uy", "uz", "rx", "ry", "rz"]
                .iter()
                .map(move |c| format!("{s}.{c}"))
        })
        .collect()
}

/// The frequency response of one transfer at frequencies `f_hz`.
fn response_of(ex: &ExportModel, t: &Transfer, f_hz: &[f64]) -> Vec<faer::c64> {
    let (o, i) = (
        ex.output_index(&t.output).unwrap_or(0),
        ex.input_index(&t.input).unwrap_or(0),
    );
    f_hz.iter().map(|f| ex.transfer(o, i, TWO_PI * f)).collect()
}

/// model.json: every array of the export with its names and units.
pub fn export_json(
    st: &Structure,
    modes: &ModalAnalysis,
    ex: &ExportModel,
    transfers: &[Transfer],
) -> String {
    let ss = ex.first_order();
    let n = ex.mode_count();
    let estimates: Vec<Option<f64>> = {
        let mut el = modes.elastic().map(|m| m.frequency_error_estimate);
        ex.modes
            .iter()
            .map(|m| if m.rigid { None } else { el.next().flatten() })
            .collect()
    };
    let mode_list: Vec<Value> = ex
        .modes
        .iter()
        .zip(&estimates)
        .enumerate()
        .map(|(j, (m, e))| {
            json!({
                "number": j + 1,
                "rigid": m.rigid,
                "frequency_hz": m.omega_rad_s / TWO_PI,
                "omega_rad_s": m.omega_rad_s,
                "damping_ratio": m.damping_ratio,
                "frequency_error_estimate": e,
            })
        })
        .collect();
    let points: Vec<Value> = ex
        .points
        .iter()
        .zip(ex.site_positions.iter().skip(1))
        .map(|(p, x)| {
            let mut v = describe_location(st, &p.location);
            v["name"] = json!(p.name);
            v["position_m"] = json!(x.0);
            v
        })
        .collect();
    let v = json!({
        "units": {
            "frequency_hz": "Hz", "omega_rad_s": "rad/s",
            "inputs": "N (f*), N·m (t*)",
            "outputs": "m (x, y, z, u*), rad (r*), m/s (v*), rad/s (w*)",
            "rigid_mass": "kg, kg·m (first moments), kg·m² (inertia)",
            "mode_shapes": "mass-normalised: m/√kg and rad/√kg per unit modal coordinate",
            "participation": "√kg (x, y, z), √kg·m (rx, ry, rz)",
            "effective_mass": "kg (x, y, z), kg·m² (rx, ry, rz)",
        },
        "conventions": "Structure (hub) frame; the hub's inputs act at and its outputs are read at \
            the hub's reference point (the frame's origin); modal coordinates eta of \
            mass-normalised modes, rigid first when the hub is free; second order: \
            M eta'' + C eta' + K eta = B u, y = F eta + G eta' + D u; first order: \
            x = [eta; eta'], x' = A x + B u, y = C x + D u. See docs/export.md.",
        "name": st.name(),
        "hub_motion": match ex.hub_motion { HubMotion::Free => "free", HubMotion::Fixed => "fixed" },
        "ritz": super::modes::selection_json(modes),
        "modes": mode_list,
        "points": points,
        "mode_shapes_at_points": {
            "rows": site_row_names(ex),
            "values": rows(&ex.site_shapes),
        },
        "rigid_body": {
            "total_mass_kg": ex.total_mass,
            "center_of_mass_m": ex.center_of_mass.0,
            "mass_matrix_about_reference_point": rows6(&ex.rigid_mass_reference),
            "mass_matrix_about_center_of_mass": rows6(&ex.rigid_mass_cm),
        },
        "hub_fixed_modes": {
            "directions": DIRECTIONS,
            "about": "the hub's centre of mass, structure axes",
            "frequency_hz": ex.hub_fixed_omega.iter().map(|w| w / TWO_PI).collect::<Vec<_>>(),
            "participation": rows(&ex.participation),
            "effective_mass": rows(&ex.effective_mass),
            "cumulative_effective_mass_fraction": rows(&ex.effective_mass_fraction),
            "appendage_mass": ex.appendage_mass,
        },
        "input_names": ex.input_names,
        "output_names": ex.output_names,
        "state_names": ss.state_names,
        "second_order": {
            "M": rows(&Mat::<f64>::identity(n, n)),
            "C": rows(&ex.damping()),
            "K": rows(&ex.stiffness()),
            "B": rows(&ex.b),
            "F": rows(&ex.f),
            "G": rows(&ex.g),
            "D": rows(&Mat::<f64>::zeros(ex.output_names.len(), ex.input_names.len())),
        },
        "first_order": {
            "A": rows(&ss.a), "B": rows(&ss.b), "C": rows(&ss.c), "D": rows(&ss.d),
        },
        "transfers": transfers.iter().map(|t| json!({
            "input": t.input, "output": t.output,
            "unit": transfer_unit(&t.input, &t.output),
        })).collect::<Vec<_>>(),
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// The terminal summary of an export.
pub fn export_table(st: &Structure, ex: &ExportModel, transfers: &[Transfer]) -> String {
    let mut o = String::new();
    let rigid = ex.modes.iter().filter(|m| m.rigid).count();
    o += &format!(
        "Linear model of \"{}\" (hub {}): {} modes ({} rigid, {} elastic), {} states, {} inputs, {} outputs. SI units.\n",
        st.name(),
        match ex.hub_motion {
            HubMotion::Free => "free",
            HubMotion::Fixed => "fixed",
        },
        ex.mode_count(),
        rigid,
        ex.mode_count() - rigid,
        2 * ex.mode_count(),
        ex.input_names.len(),
        ex.output_names.len()
    );
    o += &format!(
        "Total mass {:.6} kg, centre of mass ({:.4}, {:.4}, {:.4}) m.\n\n",
        ex.total_mass, ex.center_of_mass.0[0], ex.center_of_mass.0[1], ex.center_of_mass.0[2]
    );
    o += "  mode   frequency [Hz]   damping ratio\n";
    for (j, m) in ex.modes.iter().enumerate() {
        if m.rigid {
            o += &format!("  {:>4}   {:>14}   rigid\n", j + 1, "0");
        } else {
            o += &format!(
                "  {:>4}   {:>14.6}   {:.4}\n",
                j + 1,
                m.omega_rad_s / TWO_PI,
                m.damping_ratio
            );
        }
    }
    if let Some(last) = ex.effective_mass_fraction.ncols().checked_sub(1) {
        o += "\nHub-fixed modes' cumulative effective mass (fraction of the appendages' rigid mass):\n ";
        for (d, name) in DIRECTIONS.iter().enumerate() {
            o += &format!(" {name} {:.4}", ex.effective_mass_fraction[(d, last)]);
        }
        o += "\n";
    }
    o += "\nTransfer functions: ";
    o += &transfers
        .iter()
        .map(|t| format!("{} → {}", t.input, t.output))
        .collect::<Vec<_>>()
        .join(", ");
    o += "\n";
    o
}

fn matrix(m: &Mat<f64>) -> ArrayValue {
    ArrayValue::matrix(
        m.nrows(),
        m.ncols(),
        (0..m.nrows())
            .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
            .collect(),
    )
}

fn matrix6(m: &[[f64; 6]; 6]) -> ArrayValue {
    ArrayValue::matrix(6, 6, m.iter().flatten().copied().collect())
}

/// The arrays of model.npz and model.mat (names valid in both; docs/export.md lists them).
pub fn export_arrays(
    st: &Structure,
    modes: &ModalAnalysis,
    ex: &ExportModel,
) -> Vec<(&'static str, ArrayValue)> {
    let ss = ex.first_order();
    let n = ex.mode_count();
    let mut el = modes.elastic().map(|m| m.frequency_error_estimate);
    let estimates: Vec<f64> = ex
        .modes
        .iter()
        .map(|m| {
            if m.rigid {
                f64::NAN
            } else {
                el.next().flatten().unwrap_or(f64::NAN)
            }
        })
        .collect();
    let strings = |v: &[String]| ArrayValue::Strings(v.to_vec());
    let sites: Vec<String> = std::iter::once("hub".to_string())
        .chain(ex.points.iter().map(|p| p.name.clone()))
        .collect();
    vec![
        ("name", ArrayValue::Text(st.name().to_string())),
        (
            "hub_motion",
            ArrayValue::Text(
                match ex.hub_motion {
                    HubMotion::Free => "free",
                    HubMotion::Fixed => "fixed",
                }
                .into(),
            ),
        ),
        ("units", ArrayValue::Text(UNITS.to_string())),
        (
            "frequency_hz",
            ArrayValue::vector(ex.modes.iter().map(|m| m.omega_rad_s / TWO_PI).collect()),
        ),
        (
            "omega_rad_s",
            ArrayValue::vector(ex.modes.iter().map(|m| m.omega_rad_s).collect()),
        ),
        (
            "damping_ratio",
            ArrayValue::vector(ex.modes.iter().map(|m| m.damping_ratio).collect()),
        ),
        (
            "rigid",
            ArrayValue::vector(
                ex.modes
                    .iter()
                    .map(|m| f64::from(u8::from(m.rigid)))
                    .collect(),
            ),
        ),
        ("frequency_error_estimate", ArrayValue::vector(estimates)),
        ("site_names", strings(&sites)),
        (
            "site_positions",
            ArrayValue::matrix(
                sites.len(),
                3,
                ex.site_positions.iter().flat_map(|p| p.0).collect(),
            ),
        ),
        ("mode_shape_rows", strings(&site_row_names(ex))),
        ("mode_shapes_at_points", matrix(&ex.site_shapes)),
        ("total_mass", ArrayValue::scalar(ex.total_mass)),
        (
            "center_of_mass",
            ArrayValue::vector(ex.center_of_mass.0.to_vec()),
        ),
        ("rigid_mass_reference", matrix6(&ex.rigid_mass_reference)),
        ("rigid_mass_cm", matrix6(&ex.rigid_mass_cm)),
        (
            "directions",
            ArrayValue::Strings(DIRECTIONS.iter().map(|d| d.to_string()).collect()),
        ),
        (
            "hub_fixed_frequency_hz",
            ArrayValue::vector(ex.hub_fixed_omega.iter().map(|w| w / TWO_PI).collect()),
        ),
        ("participation", matrix(&ex.participation)),
        ("effective_mass", matrix(&ex.effective_mass)),
        (
            "effective_mass_fraction",
            matrix(&ex.effective_mass_fraction),
        ),
        (
            "appendage_mass",
            ArrayValue::vector(ex.appendage_mass.to_vec()),
        ),
        ("mechss_M", matrix(&Mat::<f64>::identity(n, n))),
        ("mechss_C", matrix(&ex.damping())),
        ("mechss_K", matrix(&ex.stiffness())),
        ("mechss_B", matrix(&ex.b)),
        ("mechss_F", matrix(&ex.f)),
        ("mechss_G", matrix(&ex.g)),
        (
            "mechss_D",
            matrix(&Mat::<f64>::zeros(
                ex.output_names.len(),
                ex.input_names.len(),
            )),
        ),
        ("A", matrix(&ss.a)),
        ("B", matrix(&ss.b)),
        ("C", matrix(&ss.c)),
        ("D", matrix(&ss.d)),
        ("state_names", strings(&ss.state_names)),
        ("input_names", strings(&ex.input_names)),
        ("output_names", strings(&ex.output_names)),
    ]
}

/// A name 42 accepts for the flexible body (its file names): the letters, digits, `_` and `-`
/// of `stem` (others become `_`), at most 29 bytes ([`super::flex42::MAX_BODY_NAME`]); "spacecraft" when nothing is left.
pub fn flex_body_name(stem: &str) -> String {
    let s: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .take(super::flex42::MAX_BODY_NAME)
        .collect();
    if s.trim_matches('_').is_empty() {
        "spacecraft".to_string()
    } else {
        s
    }
}

/// The structure as NASA 42 sees it: one flexible body whose modes are the hub-fixed modes
/// kept by the export (the hub is its rigid core, the reference point the hub's reference
/// point), discretised into mass elements for the modal integrals, with the hub's reference
/// point and the named points as analysis nodes. `None` when no elastic mode is kept.
fn flex_body(
    model: &RitzModel,
    modes: &ModalAnalysis,
    ex: &ExportModel,
    name: &str,
) -> Option<FlexBody> {
    let elastic: Vec<&crate::export::ExportMode> = ex.modes.iter().filter(|m| !m.rigid).collect();
    let kept = elastic.len().min(modes.hub_fixed.len());
    if kept == 0 {
        return None;
    }
    let shapes: Vec<&[f64]> = modes.hub_fixed[..kept]
        .iter()
        .map(|h| h.shape.as_slice())
        .collect();
    let arr = |v: crate::math::Vec3| v.0;
    let mat = |m: crate::math::Mat3| m.0;
    let mass_points = mass_elements(model, &shapes)
        .into_iter()
        .map(|e| MassPoint {
            position_m: arr(e.position),
            mass_kg: e.mass,
            inertia_kg_m2: mat(e.inertia),
            psi: e.motion.iter().map(|m| arr(m.0)).collect(),
            theta: e.motion.iter().map(|m| arr(m.1)).collect(),
        })
        .collect();
    let sites = std::iter::once(("hub".to_string(), crate::export::points::HUB_REFERENCE))
        .chain(ex.points.iter().map(|p| (p.name.clone(), p.location)));
    let nodes = sites
        .map(|(n, loc)| {
            let motion: Vec<_> = shapes
                .iter()
                .map(|q| point_motion(model, &loc, q))
                .collect();
            FlexNode {
                name: n,
                position_m: arr(point_position(&model.structure, &loc)),
                psi: motion.iter().map(|m| arr(m.0)).collect(),
                theta: motion.iter().map(|m| arr(m.1)).collect(),
            }
        })
        .collect();
    Some(FlexBody {
        name: name.to_string(),
        modes: modes.hub_fixed[..kept]
            .iter()
            .zip(&elastic)
            .map(|(h, e)| FlexMode {
                frequency_rad_s: h.omega_rad_s,
                damping_ratio: e.damping_ratio,
                initial_displacement: 0.0,
                initial_rate: 0.0,
            })
            .collect(),
        mass_points,
        joints: Vec::new(),
        nodes,
    })
}

/// Units and conventions, one line (the array files' `units` text).
const UNITS: &str = "SI: Hz, rad/s, kg, m, rad, N, N m; mode shapes mass-normalised (m/sqrt(kg), \
rad/sqrt(kg)); structure (hub) frame, hub inputs/outputs at its reference point; docs/export.md";

/// frequency_response.csv: per transfer, the real and imaginary parts, magnitude and phase.
/// With `left_out` > 0 the first column's header says that the grid's points where a
/// response is infinite (an undamped resonance) were left out.
fn frequency_csv(
    ex: &ExportModel,
    transfers: &[Transfer],
    f: &[f64],
    left_out: usize,
) -> std::io::Result<Vec<u8>> {
    let h: Vec<Vec<faer::c64>> = transfers.iter().map(|t| response_of(ex, t, f)).collect();
    csv_bytes(|w| {
        let first = if left_out > 0 {
            format!(
                "frequency [Hz] ({left_out} points at undamped resonances left out: the response is not finite there)"
            )
        } else {
            "frequency [Hz]".to_string()
        };
        let mut header = vec![first, "omega [rad/s]".to_string()];
        for t in transfers {
            let unit = transfer_unit(&t.input, &t.output);
            let tag = format!("{}->{}", t.input, t.output);
            header.push(format!("{tag} re [{unit}]"));
            header.push(format!("{tag} im [{unit}]"));
            header.push(format!("{tag} magnitude [{unit}]"));
            header.push(format!("{tag} phase [deg]"));
        }
        w.write_record(&header)?;
        for (k, fk) in f.iter().enumerate() {
            w.write_field(num(*fk))?;
            w.write_field(num(TWO_PI * fk))?;
            for ht in &h {
                let z = ht[k];
                w.write_field(num(z.re))?;
                w.write_field(num(z.im))?;
                w.write_field(num(z.norm()))?;
                w.write_field(num(z.arg().to_degrees()))?;
            }
            w.write_record(None::<&[u8]>)?;
        }
        Ok(())
    })
}

/// The export's frequency grid without the points where a transfer's response is not finite
/// (at an undamped mode's resonance, ζ = 0 or so small that 1/(2ζ) overflows), and how many
/// were left out.
fn finite_grid(
    ex: &ExportModel,
    transfers: &[Transfer],
    range_hz: Option<(f64, f64)>,
    points: usize,
) -> (Vec<f64>, usize) {
    let all = ex.frequency_grid(range_hz, points);
    let h: Vec<Vec<faer::c64>> = transfers.iter().map(|t| response_of(ex, t, &all)).collect();
    let kept: Vec<f64> = all
        .iter()
        .enumerate()
        .filter(|(k, _)| {
            h.iter()
                .all(|ht| ht[*k].re.is_finite() && ht[*k].im.is_finite())
        })
        .map(|(_, f)| *f)
        .collect();
    let left_out = all.len() - kept.len();
    (kept, left_out)
}

/// The Bode curves of `transfers` over the export's frequency grid.
pub(crate) fn bode_curves(
    ex: &ExportModel,
    transfers: &[Transfer],
    range_hz: Option<(f64, f64)>,
    points: usize,
) -> Vec<super::plot::BodeCurve> {
    let (f, _) = finite_grid(ex, transfers, range_hz, points);
    transfers
        .iter()
        .map(|t| {
            let h = response_of(ex, t, &f);
            (
                format!("{} → {}", t.input, t.output),
                f.iter().copied().zip(h).collect(),
            )
        })
        .collect()
}

/// Writes model.json, model.npz, model.mat, NASA 42's flex_BODY.txt and nodes_BODY.txt
/// ([`flex_body_name`]), frequency_response.csv and plots/bode.{png,svg}.
#[allow(clippy::too_many_arguments)]
pub fn write_export(
    dir: &mut OutputDir,
    model: &RitzModel,
    body: &str,
    modes: &ModalAnalysis,
    ex: &ExportModel,
    transfers: &[Transfer],
    range_hz: Option<(f64, f64)>,
    points: usize,
) -> Result<(), OutputError> {
    let st = &model.structure;
    dir.write("model.json", export_json(st, modes, ex, transfers) + "\n")?;
    if let Some(b) = flex_body(model, modes, ex, body) {
        let bad42 = |e: Flex42Error| OutputError::Io(std::io::Error::other(e.to_string()));
        dir.write(&flex_file_name(&b.name), flex_file(&b).map_err(bad42)?)?;
        dir.write(&nodes_file_name(&b.name), nodes_file(&b).map_err(bad42)?)?;
    }
    let arrays = export_arrays(st, modes, ex);
    let bad = |e: super::ArrayFileError| OutputError::Io(std::io::Error::other(e.to_string()));
    dir.write("model.npz", super::npz_bytes(&arrays).map_err(bad)?)?;
    dir.write(
        "model.mat",
        super::mat_bytes(&arrays, "flexcraft export, SI units").map_err(bad)?,
    )?;
    let (f, left_out) = finite_grid(ex, transfers, range_hz, points);
    dir.write(
        "frequency_response.csv",
        frequency_csv(ex, transfers, &f, left_out)?,
    )?;
    if !transfers.is_empty() {
        let curves: Vec<(String, Vec<(f64, faer::c64)>)> = transfers
            .iter()
            .map(|t| {
                let h = response_of(ex, t, &f);
                (
                    format!("{} → {}", t.input, t.output),
                    f.iter().copied().zip(h).collect(),
                )
            })
            .collect();
        super::plot::bode_chart(
            dir,
            "bode",
            &format!("Frequency response of {}", st.name()),
            &curves,
        )?;
    }
    Ok(())
}
