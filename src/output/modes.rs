//! Modal-analysis outputs: table, JSON, CSV, mode-shape samples and pictures.

use super::names::csv_bytes;
use super::{plot, OutputDir, OutputError};
use crate::ritz::shapes::{sample_beam, sample_plate, PointSample};
use crate::ritz::{ElementKind, ModalAnalysis, Mode, RitzModel};
use crate::scenario::Scenario;
use crate::structure::{ComponentId, HubMotion};
use serde_json::{json, Map, Value};
use std::fmt::Write;

const DIRECTIONS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

fn shares_json(m: &Mode) -> Value {
    let mut map = Map::new();
    for (n, s) in &m.strain_energy_share {
        map.insert(n.clone(), json!(s));
    }
    Value::Object(map)
}

/// The automatic term selection (null without one): what was asked, whether it was
/// reached, the chosen terms per component and each family's share of the estimate.
pub(crate) fn selection_json(modes: &ModalAnalysis) -> Value {
    let Some(sel) = &modes.selection else {
        return Value::Null;
    };
    let st = &sel.structure;
    let mut terms = Map::new();
    for f in &sel.families {
        let name = st.component_name(f.family.component()).to_string();
        let entry = terms.entry(name).or_insert_with(|| json!({}));
        entry[f.family.key()] = json!(f.terms);
        entry["automatic"] = json!(f.automatic);
    }
    let families: Vec<Value> = sel
        .families
        .iter()
        .map(|f| {
            json!({
                "component": st.component_name(f.family.component()),
                "family": f.family.key(),
                "terms": f.terms,
                "automatic": f.automatic,
                "frequency_error_estimate": f.error.iter().map(|e| e.is_finite().then_some(*e)).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({
        "tolerance": sel.accuracy.tolerance,
        "modes": sel.accuracy.modes,
        "max_dof": sel.accuracy.max_dof,
        "dof": sel.dof,
        "reached": sel.reached,
        "breakdown": sel.breakdown.as_ref().map(ToString::to_string),
        "max_frequency_error_estimate": sel.frequency_error.iter().copied().fold(0.0_f64, f64::max),
        "eigen_solves": sel.solves,
        "assemblies": sel.assemblies,
        "terms": terms,
        "families": families,
    })
}

/// The modes as one JSON object (the `--json` interface and `modes.json`).
pub fn modes_json(model: &RitzModel, modes: &ModalAnalysis) -> String {
    let st = &model.structure;
    let list: Vec<Value> = modes
        .modes
        .iter()
        .map(|m| {
            json!({
                "number": m.number,
                "rigid": m.rigid,
                "frequency_hz": m.frequency_hz(),
                "omega_rad_s": m.omega_rad_s,
                "dominant": m.dominant(),
                "strain_energy_share": shares_json(m),
                "effective_mass_kg": m.effective_mass,
                "frequency_error_estimate": m.frequency_error_estimate,
            })
        })
        .collect();
    let fractions = modes.effective_mass_fractions();
    let fixed: Vec<Value> = modes
        .hub_fixed
        .iter()
        .zip(&fractions)
        .enumerate()
        .map(|(i, (m, f))| {
            json!({
                "number": i + 1,
                "frequency_hz": m.omega_rad_s / (2.0 * std::f64::consts::PI),
                "omega_rad_s": m.omega_rad_s,
                "effective_mass_kg": m.effective_mass,
                "cumulative_fraction": f,
            })
        })
        .collect();
    let v = json!({
        "units": {
            "frequency_hz": "Hz", "omega_rad_s": "rad/s",
            "effective_mass_kg": "kg for x, y, z; kg·m² for rx, ry, rz (about the hub's centre of mass, structure axes)",
            "shapes": "mass-normalised: modal coordinate × shape = displacement in m",
        },
        "name": st.name,
        "basis": st.basis.name(),
        "hub_motion": match st.hub.motion { HubMotion::Free => "free", HubMotion::Fixed => "fixed" },
        "dof": modes.dof,
        "total_mass_kg": st.total_mass(),
        "ritz": selection_json(modes),
        "modes": list,
        "hub_fixed": {
            "directions": DIRECTIONS,
            "appendage_mass_kg": modes.appendage_mass,
            "effective_mass_fraction": fractions.last().copied().unwrap_or([0.0; 6]),
            "modes": fixed,
        },
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// One line on the automatic term selection: tolerance, modes, outcome, chosen terms.
pub fn selection_line(sel: &crate::ritz::refine::TermSelection) -> String {
    let st = &sel.structure;
    let mut parts: Vec<String> = Vec::new();
    for f in &sel.families {
        let name = st.component_name(f.family.component());
        let tag = if f.automatic { "" } else { " (given)" };
        parts.push(format!("{name} {} {}{tag}", f.family.key(), f.terms));
    }
    let worst = sel.frequency_error.iter().copied().fold(0.0_f64, f64::max);
    format!(
        "Ritz terms for a relative frequency error ≤ {:.0e} on the first {} elastic modes: {} \
         (estimated error ≤ {:.1e}, {} coordinates, {} eigen-solves): {}",
        sel.accuracy.tolerance,
        sel.accuracy.modes,
        match (&sel.breakdown, sel.reached) {
            (Some(e), _) => format!(
                "NOT reached: the refinement stopped where a finer level's solve broke down in \
                 rounding ({e}; the polynomial terms' mass matrix grows ill-conditioned with \
                 their count)"
            ),
            (None, true) => "reached".to_string(),
            (None, false) => "NOT reached within max_dof".to_string(),
        },
        worst,
        sel.dof,
        sel.solves,
        parts.join(", ")
    )
}

/// The terminal table.
pub fn modes_table(scenario: &Scenario, model: &RitzModel, modes: &ModalAnalysis) -> String {
    let st = &scenario.structure;
    let mut s = String::new();
    let motion = match st.hub.motion {
        HubMotion::Free => "free",
        HubMotion::Fixed => "fixed",
    };
    let _ = writeln!(s, "flexcraft modes: {}", scenario.name);
    let _ = writeln!(
        s,
        "basis {}, hub {motion}, {} generalized coordinates, total mass {:.6} kg (SI units: Hz, rad/s, kg, kg·m²)",
        st.basis.name(),
        modes.dof,
        st.total_mass()
    );
    if let Some(sel) = &modes.selection {
        let _ = writeln!(s, "{}", selection_line(sel));
    }
    let estimated = modes
        .modes
        .iter()
        .any(|m| m.frequency_error_estimate.is_some());
    let names: Vec<String> = model
        .elements
        .iter()
        .filter(|e| !matches!(e.kind, ElementKind::Rigid))
        .map(|e| st.component_name(e.id).to_string())
        .collect();
    let _ = write!(
        s,
        "\n{:>4}  {:<7} {:>12} {:>12}  {:<10}",
        "mode", "kind", "f [Hz]", "ω [rad/s]", "dominant"
    );
    if estimated {
        let _ = write!(s, " {:>9}", "est. err");
    }
    for n in &names {
        let _ = write!(s, " {:>8}", format!("SE {n}"));
    }
    s.push('\n');
    for m in &modes.modes {
        let _ = write!(
            s,
            "{:>4}  {:<7} {:>12.6} {:>12.6}  {:<10}",
            m.number,
            if m.rigid { "rigid" } else { "elastic" },
            m.frequency_hz(),
            m.omega_rad_s,
            m.dominant()
        );
        if estimated {
            let _ = match m.frequency_error_estimate {
                Some(e) => write!(s, " {:>9.1e}", e),
                None => write!(s, " {:>9}", "-"),
            };
        }
        for n in &names {
            let v = m.share(n);
            match v {
                Some(v) => {
                    let _ = write!(s, " {:>8.4}", v);
                }
                None => {
                    let _ = write!(s, " {:>8}", "-");
                }
            }
        }
        s.push('\n');
    }
    let fr = modes.effective_mass_fractions();
    let _ = writeln!(
        s,
        "\nHub-fixed elastic modes: modal effective mass in the hub's six directions (kg; kg·m² about the hub CM)\n\
         and the running sum as a fraction of the appendage mass [{}]:",
        modes.appendage_mass.iter().map(|v| format!("{v:.6e}")).collect::<Vec<_>>().join(", ")
    );
    let _ = write!(s, "{:>4} {:>12}", "mode", "f [Hz]");
    for d in DIRECTIONS {
        let _ = write!(s, " {:>10}", format!("meff {d}"));
    }
    for d in DIRECTIONS {
        let _ = write!(s, " {:>8}", format!("Σ {d}"));
    }
    s.push('\n');
    for (i, (m, f)) in modes.hub_fixed.iter().zip(&fr).enumerate() {
        let _ = write!(
            s,
            "{:>4} {:>12.6}",
            i + 1,
            m.omega_rad_s / (2.0 * std::f64::consts::PI)
        );
        for v in m.effective_mass {
            let _ = write!(s, " {:>10.4e}", v);
        }
        for v in f {
            let _ = write!(s, " {:>8.5}", v);
        }
        s.push('\n');
    }
    s
}

fn csv_num(v: f64) -> String {
    format!("{v:e}")
}

/// Samples of every elastic component for generalized coordinates q.
pub(crate) fn sample_all(
    model: &RitzModel,
    q: &[f64],
) -> Vec<(String, ComponentId, Vec<PointSample>)> {
    let st = &model.structure;
    let mut out = Vec::new();
    for e in &model.elements {
        let samples = match e.id {
            ComponentId::Beam(i) => sample_beam(model, i, q, 41),
            ComponentId::Plate(i) => sample_plate(model, i, q, 31, 9),
            _ => continue,
        };
        out.push((st.component_name(e.id).to_string(), e.id, samples));
    }
    out
}

/// frequencies.csv: one row per mode with its frequency, dominant component, strain-energy
/// shares, effective masses and (automatic terms) the frequency-error estimate.
fn frequencies_csv(model: &RitzModel, modes: &ModalAnalysis) -> std::io::Result<Vec<u8>> {
    let st = &model.structure;
    let names: Vec<String> = model
        .elements
        .iter()
        .filter(|e| !matches!(e.kind, ElementKind::Rigid))
        .map(|e| st.component_name(e.id).to_string())
        .collect();
    csv_bytes(|w| {
        let mut header: Vec<String> = [
            "mode",
            "rigid",
            "frequency [Hz]",
            "omega [rad/s]",
            "dominant",
        ]
        .map(String::from)
        .to_vec();
        let estimated = modes
            .modes
            .iter()
            .any(|m| m.frequency_error_estimate.is_some());
        if estimated {
            header.push("estimated frequency error [-]".to_string());
        }
        header.extend(names.iter().map(|n| format!("strain energy share {n} [-]")));
        for d in DIRECTIONS {
            let unit = if d.starts_with('r') { "kg·m²" } else { "kg" };
            header.push(format!("effective mass {d} [{unit}]"));
        }
        w.write_record(&header)?;
        for m in &modes.modes {
            w.write_field(m.number.to_string())?;
            w.write_field(m.rigid.to_string())?;
            w.write_field(csv_num(m.frequency_hz()))?;
            w.write_field(csv_num(m.omega_rad_s))?;
            w.write_field(m.dominant())?;
            if estimated {
                w.write_field(m.frequency_error_estimate.map_or(String::new(), csv_num))?;
            }
            for n in &names {
                w.write_field(csv_num(m.share(n).unwrap_or(0.0)))?;
            }
            for d in 0..6 {
                w.write_field(m.effective_mass.map_or(String::new(), |e| csv_num(e[d])))?;
            }
            w.write_record(None::<&[u8]>)?;
        }
        Ok(())
    })
}

/// Writes modes.json, frequencies.csv, coefficients/mode_NNN.csv, shapes/mode_NNN.csv and
/// plots/mode_NNN.{png,svg} (first 12 modes).
pub fn write_modes(
    dir: &mut OutputDir,
    model: &RitzModel,
    modes: &ModalAnalysis,
) -> Result<(), OutputError> {
    let st = &model.structure;
    dir.write("modes.json", modes_json(model, modes) + "\n")?;

    dir.write("frequencies.csv", frequencies_csv(model, modes)?)?;

    for m in &modes.modes {
        // Coefficients grouped by component and field: the paper's tables 2.2–2.3.
        let c = csv_bytes(|w| {
            w.write_record([
                "component",
                "field",
                "i",
                "j",
                "coefficient [mass-normalised]",
            ])?;
            if st.hub.motion == HubMotion::Free {
                for (k, d) in ["ux", "uy", "uz", "rx", "ry", "rz"].iter().enumerate() {
                    w.write_record([
                        "hub",
                        d,
                        (k + 1).to_string().as_str(),
                        "",
                        csv_num(m.shape[k]).as_str(),
                    ])?;
                }
            }
            for e in &model.elements {
                let name = st.component_name(e.id);
                let ny = match (&e.kind, e.id) {
                    (ElementKind::Plate { width, .. }, _) => width.len(),
                    _ => 0,
                };
                for fr in &e.fields {
                    for k in 0..fr.len {
                        let v = csv_num(m.shape[fr.start + k]);
                        let (i, j) = match (k.checked_div(ny), k.checked_rem(ny)) {
                            (Some(i), Some(j)) => ((i + 1).to_string(), (j + 1).to_string()),
                            _ => ((k + 1).to_string(), String::new()),
                        };
                        w.write_record([name, fr.kind.name(), i.as_str(), j.as_str(), v.as_str()])?;
                    }
                }
            }
            Ok(())
        })?;
        dir.write(&format!("coefficients/mode_{:03}.csv", m.number), c)?;

        let sh = csv_bytes(|w| {
            w.write_record([
                "component",
                "s [m]",
                "t [m]",
                "x [m]",
                "y [m]",
                "z [m]",
                "ux [m/√kg, mass-normalised]",
                "uy [m/√kg, mass-normalised]",
                "uz [m/√kg, mass-normalised]",
                "rx [rad/√kg, mass-normalised]",
                "ry [rad/√kg, mass-normalised]",
                "rz [rad/√kg, mass-normalised]",
            ])?;
            for (name, _, samples) in sample_all(model, &m.shape) {
                for p in samples {
                    w.write_field(&name)?;
                    for v in p
                        .local
                        .iter()
                        .chain(&p.position.0)
                        .chain(&p.displacement.0)
                        .chain(&p.rotation.0)
                    {
                        w.write_field(csv_num(*v))?;
                    }
                    w.write_record(None::<&[u8]>)?;
                }
            }
            Ok(())
        })?;
        dir.write(&format!("shapes/mode_{:03}.csv", m.number), sh)?;
    }
    let first_elastic = modes.modes.iter().position(|m| !m.rigid).unwrap_or(0);
    for m in modes.modes.iter().skip(first_elastic).take(12) {
        plot::mode_shape(dir, model, m)?;
    }
    Ok(())
}
