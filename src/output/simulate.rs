//! `flexcraft simulate` outputs: the terminal summary, summary.json, response.csv and the
//! response plots (the paper's figures 2.4–2.7 and the modal amplitudes).

use super::deploy::Peak;
use super::names::csv_writer;
use super::{deploy_table, modes_json, num, write_deploy, OutputDir, OutputError};
use crate::math::Vec3;
use crate::response::ChannelKind;
use crate::scenario::Scenario;
use crate::simulation::{Response, Simulation};
use serde_json::{json, Value};
use std::fmt::Write;

fn v3(v: Vec3) -> [f64; 3] {
    v.0
}

fn response_json(sim: &Simulation, s: &Scenario, r: &Response) -> Value {
    let h = &r.handover;
    let st = &s.response;
    let channels: Vec<Value> = r
        .channels
        .iter()
        .enumerate()
        .map(|(c, ch)| {
            let (peak, at) = r.history.peak(c);
            json!({"name": ch.name, "label": ch.label, "unit": ch.unit, "peak": peak, "peak_time": at, "final": r.history.last(c)})
        })
        .collect();
    let (rv, rw) = r.hub_rigid_rates(&sim.modes);
    let last = |kind: ChannelKind| -> Vec<f64> {
        r.channels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.kind == kind)
            .map(|(i, _)| r.history.last(i))
            .collect()
    };
    json!({
        "handover": {
            "method": h.method.name(),
            "latch_time": h.latch_time,
            "latch_hinge": h.latch_hinge,
            "energy_before": h.energy_before,
            "energy_before_plate_field": h.energy_before_field,
            "energy_after": h.energy_after,
            "energy_lost": h.energy_before - h.energy_after,
            "captured_energy_fraction": r.modal.captured_energy_fraction,
            "momentum_before": {"linear": v3(h.momentum_before.linear), "angular": v3(h.momentum_before.angular)},
            "momentum_after": {"linear": v3(h.momentum_after.linear), "angular": v3(h.momentum_after.angular)},
            "angle_mismatch": h.angle_mismatch,
            "elastic_energy_before": h.elastic_energy_before,
            "elastic_energy_after": h.elastic_energy_after,
            "projection_residual": (h.energy_before + h.elastic_energy_before + h.lines_energy) - (h.energy_after + h.elastic_energy_after),
            "latch_energy": h.latch_energy,
            "latch_energy_carried": h.latch_carried,
            "latch_lines_energy": h.lines_energy,
        },
        "response": {
            "duration": st.duration,
            "output_rate": st.output_rate,
            "rows": r.history.times.len(),
            "damping_ratio": st.damping_ratio,
            "elastic_modes_available": r.modal.available_elastic,
            "elastic_modes_requested": r.modal.requested_elastic,
            "elastic_modes_kept": r.modal.kept_elastic(),
            "elastic_energy_drift": r.history.energy_drift(),
            "kept_modes": r.modal.modes.iter().map(|m| json!({
                "number": m.number, "rigid": m.rigid,
                "frequency_hz": m.omega_rad_s / (2.0 * std::f64::consts::PI),
                "initial_modal_velocity": m.eta_dot0,
            })).collect::<Vec<_>>(),
            "channels": channels,
            "hub": {
                "translation_final": last(ChannelKind::HubTranslation),
                "rotation_final": last(ChannelKind::HubRotation),
                "rigid_velocity": rv,
                "rigid_rate": rw,
            },
        },
    })
}

/// The largest magnitude over the response of the vector made of channels `cs` (a beam
/// root's force or moment; one channel: its absolute value), from the closed form, with its
/// time from release.
fn response_peak(r: &Response, cs: &[usize]) -> Option<Peak> {
    let (v, t) = r.history.vector_peak(cs)?;
    Some((v, r.handover.latch_time + t))
}

fn peak_json(p: Option<Peak>) -> Value {
    p.map_or(Value::Null, |(v, t)| json!({"value": v, "time": t}))
}

/// The larger of two peaks and the phase it falls in.
fn overall(dep: Option<Peak>, resp: Option<Peak>) -> Value {
    let (p, phase) = match (dep, resp) {
        (Some(d), Some(r)) if r.0 > d.0 => (r, "response"),
        (Some(d), _) => (d, "deployment"),
        (None, Some(r)) => (r, "response"),
        (None, None) => return Value::Null,
    };
    json!({"value": p.0, "time": p.1, "phase": phase})
}

/// Peak root loads of every beam and peak latch moments, over the deployment and the
/// response (times from release).
pub(super) fn peak_loads(sim: &Simulation) -> Value {
    let dep = &sim.deployment;
    let r = sim.response.as_ref();
    let find = |pred: &dyn Fn(&ChannelKind) -> bool| -> Vec<usize> {
        r.map_or(Vec::new(), |r| {
            r.channels
                .iter()
                .enumerate()
                .filter(|(_, c)| pred(&c.kind))
                .map(|(i, _)| i)
                .collect()
        })
    };
    let roots: Vec<Value> = super::deploy::root_load_peaks(&sim.coupled, dep)
        .into_iter()
        .map(|(beam, f, m)| {
            let cs = find(&|k| matches!(k, ChannelKind::BeamRoot { beam: b } if *b == beam));
            let (rf, rm) = match (r, cs.len()) {
                (Some(r), 6) => (response_peak(r, &cs[..3]), response_peak(r, &cs[3..])),
                _ => (None, None),
            };
            json!({
                "beam": beam,
                "force": {"deployment": peak_json(Some(f)), "response": peak_json(rf), "overall": overall(Some(f), rf)},
                "moment": {"deployment": peak_json(Some(m)), "response": peak_json(rm), "overall": overall(Some(m), rm)},
            })
        })
        .collect();
    let dep_latch = super::deploy::latch_moment_peaks(dep);
    let n = sim.coupled.panels();
    let latches: Vec<Value> = (0..n)
        .map(|i| {
            let d = dep_latch.get(i).copied();
            let cs = find(&|k| matches!(k, ChannelKind::LatchMoment { hinge } if *hinge == i + 1));
            let rp = match (r, cs.as_slice()) {
                (Some(r), [c]) => response_peak(r, &[*c]),
                _ => None,
            };
            json!({"hinge": i + 1, "deployment": peak_json(d), "response": peak_json(rp), "overall": overall(d, rp)})
        })
        .collect();
    json!({"root_loads": roots, "latch_moments": latches})
}

/// The columns of response.csv, in order: t from release (one timeline with deployment.csv)
/// and from the final latch, every channel with its unit, the modal amplitudes.
pub fn response_header(r: &Response) -> Vec<String> {
    let mut header = vec!["t [s]".to_string(), "t_after_latch [s]".to_string()];
    header.extend(
        r.channels
            .iter()
            .map(|ch| format!("{} [{}]", ch.name, ch.unit)),
    );
    header.extend(
        r.modal
            .modes
            .iter()
            .map(|m| format!("eta_{} [√kg·m]", m.number)),
    );
    header
}

/// summary.json (and `simulate --json`).
pub fn simulate_json(s: &Scenario, sim: &Simulation) -> String {
    let d = s.deployment.as_ref();
    let dep = &sim.deployment;
    let mut v = json!({
        "units": {
            "time": "s", "length": "m", "angle": "rad", "energy": "J (kinetic unless stated)",
            "linear_momentum": "N·s", "angular_momentum": "N·m·s, about the hub's centre of mass",
            "frequency": "Hz", "modal_velocity": "√kg·m/s (mass-normalised modes)",
            "force": "N, except deployment.latches[].hinge_impulses and base_impulse: N·s", "moment": "N·m, except deployment.latches[].hinge_impulses and base_impulse: N·m·s",
            "root_loads": "the force a beam's parent exerts on it and the moment about its root point, hub axes",
            "latch_moment": "the latch's moment on its hinge angle (opening positive); in the response, the wing's moment across the hinge line less the hinge spring's at the latch angle",
            "axes": "structure frame (the hub's body axes at the final latch)",
        },
        "name": s.name,
        "deployment": {
            "plate": d.map(|d| d.plate.clone()),
            "panels": d.map(|d| d.chain.len()),
            "all_latched": dep.all_latched,
            "final_time": dep.final_time,
            "latches": dep.latches.iter().map(|e| json!({
                "hinge": e.hinge, "time": e.time, "energy_before": e.energy_before,
                "energy_after": e.energy_after,
                "hinge_impulses": e.impulses.iter().enumerate().map(|(i, (f, m))| json!({
                    "hinge": i + 1, "force": f, "moment": m})).collect::<Vec<_>>(),
                "base_impulse": e.base_impulse.map(|(f, m)| json!({"force": f, "moment": m})),
            })).collect::<Vec<_>>(),
            "peak_root_loads": super::deploy::peak_root_loads(&sim.coupled, dep),
            "peak_hinge_reactions": super::deploy::peak_hinge_reactions(&sim.coupled, dep),
            "captures": dep.captures.iter().map(|k| json!({"time": k.time, "hinge": k.hinge, "rates": k.rates})).collect::<Vec<_>>(),
            "peak_latch_moments": super::deploy::peak_latch_moments(dep),
            "model": d.map_or(Value::Null, |d| super::deploy::model_json(d, &sim.coupled, dep)),
        },
        "modes": {
            "dof": sim.modes.dof,
            "rigid": sim.modes.modes.iter().filter(|m| m.rigid).count(),
            "elastic": sim.modes.modes.iter().filter(|m| !m.rigid).count(),
            "first_frequencies_hz": sim.modes.elastic().take(10).map(|m| m.frequency_hz()).collect::<Vec<_>>(),
        },
        "peak_loads": peak_loads(sim),
        "stresses": super::margins::stresses_json(sim),
        "margins": super::margins::margins_json(s, sim),
        "handover": Value::Null,
        "response": Value::Null,
        "warnings": sim.all_warnings().map(ToString::to_string).collect::<Vec<_>>(),
    });
    if let Some(r) = &sim.response {
        let extra = response_json(sim, s, r);
        v["handover"] = extra["handover"].clone();
        v["response"] = extra["response"].clone();
    }
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// The terminal summary.
pub fn simulate_table(s: &Scenario, sim: &Simulation) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "flexcraft simulate: {}", s.name);
    let _ = writeln!(
        o,
        "SI units: s, m, rad, J, N·s, N·m·s, Hz; structure axes = the hub's body axes\n"
    );
    let _ = writeln!(
        o,
        "Modes: {} coordinates, {} rigid + {} elastic",
        sim.modes.dof,
        sim.modes.modes.iter().filter(|m| m.rigid).count(),
        sim.modes.elastic().count()
    );
    if let Some(d) = &s.deployment {
        o.push('\n');
        o.push_str(&deploy_table(&s.name, d, &sim.coupled, &sim.deployment));
    }
    let Some(r) = &sim.response else {
        let _ = writeln!(o, "\nno response: the array did not latch completely");
        return o;
    };
    let _ = writeln!(
        o,
        "\nResponse modes: {} rigid + {} of {} elastic kept",
        r.modal.modes.iter().filter(|m| m.rigid).count(),
        r.modal.kept_elastic(),
        r.modal.available_elastic
    );
    let _ = writeln!(
        o,
        "{:>6} {:>12} {:>7} {:>16}",
        "mode", "f [Hz]", "rigid", "η̇(0) [√kg·m/s]"
    );
    let shown = r.modal.modes.len().min(16);
    for m in &r.modal.modes[..shown] {
        let _ = writeln!(
            o,
            "{:>6} {:>12.6} {:>7} {:>16.6e}",
            m.number,
            m.omega_rad_s / (2.0 * std::f64::consts::PI),
            if m.rigid { "yes" } else { "" },
            m.eta_dot0
        );
    }
    if shown < r.modal.modes.len() {
        let _ = writeln!(
            o,
            "   … {} more in summary.json",
            r.modal.modes.len() - shown
        );
    }
    handover_lines(&mut o, r, handover_scales(s, sim, r));
    response_lines(&mut o, s, sim, r);
    for w in &sim.warnings {
        let _ = writeln!(o, "warning: {w}");
    }
    o
}

/// The hand-over's lines of the terminal summary.
fn handover_lines(o: &mut String, r: &Response, (_, p_scale, l_scale): (f64, f64, f64)) {
    let h = &r.handover;
    let lost = h.energy_before - h.energy_after;
    let _ = writeln!(
        o,
        "\nHand-over at t = {:.6} s ({}), method {}:",
        h.latch_time,
        handover_instant(h),
        h.method.name()
    );
    let _ = writeln!(
        o,
        "  kinetic energy before {:.6e} J, after {:.6e} J, difference {:.6e} J ({:.4} %)",
        h.energy_before,
        h.energy_after,
        lost,
        100.0 * lost / h.energy_before.max(1e-300)
    );
    // With the latch lines in the deployed model its elastic energy holds the lines' (latch,
    // hinge and cable springs about the latched equilibrium).
    let carried = if h.latch_carried { h.lines_energy } else { 0.0 };
    let (before, after) = (
        h.energy_before + h.elastic_energy_before + carried,
        h.energy_after + h.elastic_energy_after,
    );
    let springs = if h.latch_carried {
        format!(" (base) + {:.6e} J (latch lines)", h.lines_energy)
    } else {
        String::new()
    };
    let _ = writeln!(
        o,
        "  elastic energy before {:.6e} J{springs}, after {:.6e} J; total {:.6e} J → {:.6e} J: projection residual {:.6e} J ({:.4} %)",
        h.elastic_energy_before,
        h.elastic_energy_after,
        before,
        after,
        before - after,
        100.0 * (before - after) / before.max(1e-300)
    );
    if h.latch_energy > 0.0 && !h.latch_carried {
        let _ = writeln!(
            o,
            "  latch springs' energy {:.6e} J ({:.2e} of the kinetic + elastic energy handed over): not carried, the deployed wing has no latch spring",
            h.latch_energy,
            h.latch_energy / before.max(1e-300)
        );
    }
    let _ = writeln!(
        o,
        "  kept modes carry {:.6} % of the hand-over energy",
        100.0 * r.modal.captured_energy_fraction
    );
    // Rounding noise (within 1e-9 of the run's momentum scale) reads 0.
    let f = |v: Vec3, scale: f64| {
        let v = v.0.map(|x| super::snap(x, scale));
        format!("[{:.6e}, {:.6e}, {:.6e}]", v[0], v[1], v[2])
    };
    let _ = writeln!(
        o,
        "  momentum before: linear {} N·s, angular {} N·m·s",
        f(h.momentum_before.linear, p_scale),
        f(h.momentum_before.angular, l_scale)
    );
    let _ = writeln!(
        o,
        "  momentum after:  linear {} N·s, angular {} N·m·s",
        f(h.momentum_after.linear, p_scale),
        f(h.momentum_after.angular, l_scale)
    );
}

/// The hand-over's scales (energy J, linear momentum N·s, angular momentum N·m·s) against
/// which rounding noise reads 0: the largest kinetic energy of the run (the hand-over's
/// totals included), √(2 E m) of the spacecraft, and that times its size.
pub(crate) fn handover_scales(s: &Scenario, sim: &Simulation, r: &Response) -> (f64, f64, f64) {
    let h = &r.handover;
    let energy = sim
        .deployment
        .samples
        .iter()
        .map(|x| x.kinetic)
        .fold(h.energy_before + h.elastic_energy_before, f64::max)
        .max(h.energy_after + h.elastic_energy_after)
        .max(f64::MIN_POSITIVE);
    let p = (2.0 * energy * s.structure.total_mass()).sqrt();
    (energy, p, p * super::figures::structure_size(&s.structure))
}

/// Rounding noise in the terminal: a value at most [`super::figures::NOISE_FLOOR`] times the
/// largest peak of its quantity among the response's channels prints as 0 (lengths and
/// angles compared through the structure's size, as in the figures).
fn noise_floor<'a>(s: &Scenario, r: &'a Response) -> impl Fn(f64, &str) -> f64 + 'a {
    let mut reference =
        super::figures::NoiseReference::new(super::figures::structure_size(&s.structure));
    for (c, ch) in r.channels.iter().enumerate() {
        reference.observe(ch.unit, r.history.peak(c).0);
    }
    move |v: f64, unit: &str| {
        if reference.is_noise(unit, v) {
            0.0
        } else {
            v
        }
    }
}

/// The response's lines of the terminal summary.
fn response_lines(o: &mut String, s: &Scenario, sim: &Simulation, r: &Response) {
    let st = &s.response;
    // The latch lines' dashpots damp the modes that move them (docs/theory.md §1.6).
    let lines_damp = r
        .modal
        .modes
        .iter()
        .any(|m| !m.rigid && m.zeta > st.damping_ratio);
    let zeta_text = if lines_damp {
        format!("ζ = {} plus the latch dashpots' per mode", st.damping_ratio)
    } else {
        format!("ζ = {}", st.damping_ratio)
    };
    let _ = writeln!(
        o,
        "\nResponse over {} s after the hand-over ({} samples at {} Hz, {zeta_text}):",
        st.duration,
        r.history.times.len(),
        st.output_rate,
    );
    let snap = noise_floor(s, r);
    for (c, ch) in r.channels.iter().enumerate() {
        if matches!(
            ch.kind,
            ChannelKind::BeamTip { .. } | ChannelKind::PlateTip { .. }
        ) {
            let (p, t) = r.history.peak(c);
            if snap(p, ch.unit) == 0.0 {
                let _ = writeln!(
                    o,
                    "  peak {:<34} {:>13} {} (identically zero: rounding only)",
                    ch.label, "0", ch.unit
                );
            } else {
                let _ = writeln!(
                    o,
                    "  peak {:<34} {:>13.6e} {} at t = {:.3} s",
                    ch.label, p, ch.unit, t
                );
            }
        }
    }
    let peaks = peak_loads(sim);
    let line = |o: &mut String, what: String, unit: &str, p: &Value| {
        if let (Some(v), Some(t), Some(ph)) =
            (p["value"].as_f64(), p["time"].as_f64(), p["phase"].as_str())
        {
            let _ = writeln!(
                o,
                "  peak {what:<34} {v:>13.6e} {unit} at t = {t:.3} s from release ({ph})"
            );
        }
    };
    for b in peaks["root_loads"].as_array().into_iter().flatten() {
        let name = b["beam"].as_str().unwrap_or("");
        line(o, format!("{name} root force"), "N", &b["force"]["overall"]);
        line(
            o,
            format!("{name} root moment"),
            "N·m",
            &b["moment"]["overall"],
        );
    }
    for l in peaks["latch_moments"].as_array().into_iter().flatten() {
        let k = l["hinge"].as_u64().unwrap_or(0);
        line(o, format!("latch moment, hinge {k}"), "N·m", &l["overall"]);
    }
    super::margins::stress_lines(o, s, sim);
    let (rv, rw) = r.hub_rigid_rates(&sim.modes);
    let finals = |kind: ChannelKind| -> String {
        let v: Vec<String> = r
            .channels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.kind == kind)
            .map(|(i, c)| format!("{:.6e}", snap(r.history.last(i), c.unit)))
            .collect();
        format!("[{}]", v.join(", "))
    };
    // Rigid-body rates within rounding of the run's scales (√(2E/m), and over the size) read 0.
    let (_, p_scale, l_scale) = handover_scales(s, sim, r);
    let m = s.structure.total_mass();
    let rv = rv.map(|v| super::snap(v, p_scale / m));
    let rw = rw.map(|v| {
        super::snap(
            v,
            l_scale / m / super::figures::structure_size(&s.structure).powi(2),
        )
    });
    let _ = writeln!(
        o,
        "  hub drift: translation at the end {} m; rigid-body velocity [{:.6e}, {:.6e}, {:.6e}] m/s",
        finals(ChannelKind::HubTranslation),
        rv[0],
        rv[1],
        rv[2]
    );
    let _ = writeln!(
        o,
        "  attitude change: rotation at the end {} rad; rigid-body rate [{:.6e}, {:.6e}, {:.6e}] rad/s",
        finals(ChannelKind::HubRotation),
        rw[0],
        rw[1],
        rw[2]
    );
    if !lines_damp && st.damping_ratio == 0.0 {
        let _ = writeln!(
            o,
            "  elastic energy drift over the run: {:.2e} (relative; undamped, so rounding only)",
            r.history.energy_drift()
        );
    } else {
        let e = &r.history.elastic_energy;
        let _ = writeln!(
            o,
            "  elastic energy at the end: {:.4} % of the hand-over's (modal damping {zeta_text})",
            100.0 * e.last().copied().unwrap_or(0.0)
                / e.first().copied().unwrap_or(1.0).max(1e-300),
        );
    }
}

/// Writes summary.json, report.html, modes.json, the deployment's files, response.csv and
/// plots. `source` and `file_name` are the scenario file's bytes and name (the report's
/// footer carries its SHA-256).
pub fn write_simulate(
    dir: &mut OutputDir,
    s: &Scenario,
    sim: &Simulation,
    source: &[u8],
    file_name: &str,
) -> Result<(), OutputError> {
    dir.write("summary.json", simulate_json(s, sim) + "\n")?;
    dir.write(
        "report.html",
        super::report_html(s, sim, source, file_name)?,
    )?;
    dir.write("modes.json", modes_json(&sim.model, &sim.modes) + "\n")?;
    if let Some(d) = &s.deployment {
        write_deploy(dir, &s.name, d, &sim.coupled, &sim.deployment)?;
    }
    let Some(r) = &sim.response else {
        return Ok(());
    };
    // response.csv, streamed to the file: it can hold millions of rows.
    let hist = &r.history;
    let file = std::fs::File::create(dir.path("response.csv")?)?;
    let mut w = csv_writer(std::io::BufWriter::with_capacity(1 << 16, file));
    let header = response_header(r);
    let csv_err = |e: csv::Error| OutputError::Io(std::io::Error::other(e));
    w.write_record(&header).map_err(csv_err)?;
    let t_latch = r.handover.latch_time;
    for (k, &t) in hist.times.iter().enumerate() {
        w.write_field(num(t_latch + t)).map_err(csv_err)?;
        w.write_field(num(t)).map_err(csv_err)?;
        for j in 0..r.channels.len() {
            w.write_field(num(hist.values[(k, j)])).map_err(csv_err)?;
        }
        for j in 0..r.modal.modes.len() {
            w.write_field(num(hist.modal[(k, j)])).map_err(csv_err)?;
        }
        w.write_record(None::<&[u8]>).map_err(csv_err)?;
    }
    // Flushes the csv buffer and the BufWriter, reporting any error.
    w.into_inner()
        .map_err(|e| OutputError::Io(std::io::Error::other(e.to_string())))?;

    for f in super::figures::response_figures(s, r, &sim.modes) {
        f.draw(dir)?;
    }
    if let Some(text) = super::hub::csv(sim) {
        dir.write("hub.csv", text)?;
    }
    for f in super::hub::figures(sim) {
        f.draw(dir)?;
    }
    Ok(())
}

/// What the hand-over follows: a latch, or the compliant latches' settling.
pub(crate) fn handover_instant(h: &crate::response::handover::Handover) -> String {
    use crate::deploy::Settled;
    let how = match h.settled {
        None => return format!("latch of hinge {}", h.latch_hinge),
        Some(Settled::Decayed) => "after the latches settled",
        Some(Settled::AfterTime) => "after the settle_time",
        Some(Settled::HandedOver) => "one latch period after the last capture",
        Some(Settled::Capped { .. }) => "at the settling's cap, the latches NOT settled",
        Some(Settled::EndTime { .. }) => "at end_time, the latches NOT settled",
    };
    format!("{how}; last capture: hinge {}", h.latch_hinge)
}
