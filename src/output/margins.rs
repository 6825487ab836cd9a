//! Stresses and margins of safety in the outputs (docs/theory.md §3.3): summary.json's
//! `stresses` and `margins`, the terminal's lines, the report's table, and the components
//! whose margin is negative (`simulate --fail-on-negative-margin`).

use crate::scenario::Scenario;
use crate::simulation::Simulation;
use serde_json::{json, Value};
use std::fmt::Write as _;

/// One margin of safety: a beam's largest von Mises stress against its material's
/// allowable, or a latch's peak moment against `moment_allowable`.
#[derive(Debug, Clone, PartialEq)]
pub struct Margin {
    /// What: `beam "mast" at x = 1.2 m` or `latch, hinge 2`.
    pub component: String,
    /// The load: σ_vm (Pa) or the latch moment (N·m).
    pub value: f64,
    /// Its unit.
    pub unit: &'static str,
    /// The allowable, same unit.
    pub allowable: f64,
    /// The factor of safety applied (1 for latches).
    pub factor_of_safety: f64,
    /// MS = allowable / (FS · value) − 1.
    pub margin: f64,
    /// When, s from release.
    pub time: f64,
}

/// Every margin of a simulation: the beams with an allowable (at their worst station), and
/// the latches when `moment_allowable` is given.
pub fn margins(s: &Scenario, sim: &Simulation) -> Vec<Margin> {
    let mut out = Vec::new();
    if let Some(r) = &sim.response {
        let t0 = r.handover.latch_time;
        for b in &r.stresses {
            let (Some(a), Some((x, p))) = (b.allowable, b.worst()) else {
                continue;
            };
            out.push(Margin {
                component: format!("beam \"{}\" at x = {x:.4} m", b.name),
                value: p.stresses.von_mises,
                unit: "Pa",
                allowable: a.stress,
                factor_of_safety: a.factor_of_safety,
                margin: a.margin(p.stresses.von_mises),
                time: t0 + p.time,
            });
        }
    }
    if let Some(allow) = s.stress.latch_moment_allowable {
        let peaks = super::simulate::peak_loads(sim);
        for l in peaks["latch_moments"].as_array().into_iter().flatten() {
            let (Some(v), Some(t)) = (
                l["overall"]["value"].as_f64(),
                l["overall"]["time"].as_f64(),
            ) else {
                continue;
            };
            out.push(Margin {
                component: format!("latch, hinge {}", l["hinge"].as_u64().unwrap_or(0)),
                value: v,
                unit: "N·m",
                allowable: allow,
                factor_of_safety: 1.0,
                margin: if v > 0.0 {
                    allow / v - 1.0
                } else {
                    f64::INFINITY
                },
                time: t,
            });
        }
    }
    out
}

/// A margin for JSON: +∞ (an unloaded part) as null.
fn finite_or_null(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// summary.json's `stresses`: per beam, every station's peak (times from release).
pub fn stresses_json(sim: &Simulation) -> Value {
    let Some(r) = &sim.response else {
        return Value::Array(Vec::new());
    };
    let t0 = r.handover.latch_time;
    Value::Array(
        r.stresses
            .iter()
            .map(|b| {
                let stations: Vec<Value> = b
                    .stations
                    .iter()
                    .map(|(x, p)| {
                        json!({
                            "station_m": x,
                            "time_s": t0 + p.time,
                            "von_mises_pa": p.stresses.von_mises,
                            "normal_pa": p.stresses.normal,
                            "shear_pa": p.stresses.shear,
                            "resultants": {
                                "N": p.resultants[0], "Vy": p.resultants[1], "Vz": p.resultants[2],
                                "T": p.resultants[3], "My": p.resultants[4], "Mz": p.resultants[5],
                            },
                        })
                    })
                    .collect();
                let worst = b.worst();
                json!({
                    "beam": b.name,
                    "stations": stations,
                    "worst_station_m": worst.map(|w| w.0),
                    "von_mises_pa": worst.map(|w| w.1.stresses.von_mises),
                    "allowable_stress_pa": b.allowable.map(|a| a.stress),
                    "factor_of_safety": b.allowable.map(|a| a.factor_of_safety),
                    "margin_of_safety": b.margin().map(finite_or_null),
                })
            })
            .collect(),
    )
}

/// summary.json's `margins`.
pub fn margins_json(s: &Scenario, sim: &Simulation) -> Value {
    Value::Array(
        margins(s, sim)
            .into_iter()
            .map(|m| {
                json!({
                    "component": m.component, "value": m.value, "unit": m.unit,
                    "allowable": m.allowable, "factor_of_safety": m.factor_of_safety,
                    "margin_of_safety": finite_or_null(m.margin), "time_s": m.time,
                })
            })
            .collect(),
    )
}

/// The terminal's lines: each beam's largest von Mises stress, and every margin.
pub fn stress_lines(o: &mut String, s: &Scenario, sim: &Simulation) {
    let Some(r) = &sim.response else {
        return;
    };
    if r.stresses.is_empty() && s.stress.latch_moment_allowable.is_none() {
        return;
    }
    let _ = writeln!(
        o,
        "\nStresses over the response (von Mises of the largest normal and shear stress at the same instant; docs/theory.md §3.3):"
    );
    for b in &r.stresses {
        if let Some((x, p)) = b.worst() {
            let _ = writeln!(
                o,
                "  {:<28} σ_vm {:>11} at x = {x:.4} m, t = {:.3} s from release (σ {}, τ {})",
                b.name,
                super::engineering(p.stresses.von_mises, "Pa"),
                r.handover.latch_time + p.time,
                super::engineering(p.stresses.normal, "Pa"),
                super::engineering(p.stresses.shear, "Pa")
            );
        }
    }
    for m in margins(s, sim) {
        let ms = if m.margin.is_finite() {
            format!("{:+.3}", m.margin)
        } else {
            "∞ (unloaded)".into()
        };
        let _ = writeln!(
            o,
            "  margin of safety {:<34} MS = {ms}{} ({} against {} / FS {})",
            m.component,
            if m.margin < 0.0 { "  NEGATIVE" } else { "" },
            super::engineering(m.value, m.unit),
            super::engineering(m.allowable, m.unit),
            m.factor_of_safety
        );
    }
}

/// The report's margins table (negative margins in red), empty without margins.
pub fn margins_table(s: &Scenario, sim: &Simulation) -> String {
    let ms = margins(s, sim);
    if ms.is_empty() {
        return String::new();
    }
    let mut o = String::from(
        "<h3>Margins of safety</h3><p>MS = allowable / (FS · load) − 1: beams at their \
         largest von Mises stress over the response (the largest normal and shear stress at \
         the same instant, conservative), latches at their peak moment.</p>\
         <table id=\"margins\"><tr><th class=\"l\">component</th><th>load</th>\
         <th>allowable</th><th>FS</th><th>MS</th><th>t from release [s]</th></tr>\n",
    );
    for m in ms {
        let cls = if m.margin < 0.0 { " class=\"neg\"" } else { "" };
        let shown = if m.margin.is_finite() {
            format!("{:+.3}", m.margin)
        } else {
            "∞".into()
        };
        let _ = writeln!(
            o,
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td{cls}>{shown}</td><td>{:.3}</td></tr>",
            super::names::html(&m.component),
            super::engineering(m.value, m.unit),
            super::engineering(m.allowable, m.unit),
            m.factor_of_safety,
            m.time
        );
    }
    o.push_str("</table>\n");
    o
}
