//! Deployment outputs: event table, JSON, deployment.csv, events.json and plots.

use super::plot::{line_chart, Series};
use super::{num, OutputDir, OutputError};
use crate::deploy::base::BaseKind;
use crate::deploy::coupled::{Coupled, Synchronisation};
use crate::deploy::{
    BodySample, Deployment, DeploymentResult, Latching, Settled, SETTLE_TOLERANCE,
};
use crate::structure::HubMotion;
use serde_json::{json, Value};
use std::fmt::Write;

fn latching_name(l: Latching) -> &'static str {
    match l {
        Latching::Sequential => "sequential",
        Latching::Simultaneous => "simultaneous",
    }
}

/// The last sample's 3-D state (the state when the run ended).
fn final_body(r: &DeploymentResult) -> BodySample {
    r.samples
        .last()
        .and_then(|s| s.body.as_deref())
        .cloned()
        .unwrap_or_default()
}

fn hub_json(c: &Coupled, r: &DeploymentResult) -> Value {
    match c.base.hub_motion {
        HubMotion::Fixed => json!({"motion": "fixed"}),
        HubMotion::Free => {
            let b = final_body(r);
            json!({
                "motion": "free",
                "position_m": b.hub_position,
                "rotation_vector_rad": b.hub_rotation,
                "velocity_m_s": b.hub_velocity,
                "rate_rad_s": b.hub_rate,
            })
        }
    }
}

pub use crate::deploy::peaks::Peak;

/// Per base beam: its name and the largest magnitude of its root force (N) and root moment
/// (N·m) over the deployment, with their times: tracked at every integration step
/// (`DeploymentResult::load_peaks`, laid out as `TrackedLoads` says).
pub fn root_load_peaks(c: &Coupled, r: &DeploymentResult) -> Vec<(String, Peak, Peak)> {
    let t = c.tracked_loads();
    let at = |i: usize| r.load_peaks.get(i).copied().unwrap_or((0.0, 0.0));
    c.base
        .beams
        .iter()
        .enumerate()
        .map(|(b, beam)| (beam.name.clone(), at(t.root_force(b)), at(t.root_moment(b))))
        .collect()
}

/// [`root_load_peaks`] as JSON.
pub fn peak_root_loads(c: &Coupled, r: &DeploymentResult) -> Value {
    Value::Array(
        root_load_peaks(c, r)
            .into_iter()
            .map(|(beam, (f, tf), (m, tm))| {
                json!({"beam": beam, "force": f, "force_time": tf, "moment": m, "moment_time": tm})
            })
            .collect(),
    )
}

/// Per hinge, the largest in-plane reaction force (N) and transmitted moment (N·m) over the
/// deployment, with their times: tracked at every integration step
/// (`DeploymentResult::load_peaks`, laid out as `TrackedLoads` says), as
/// the Monte Carlo outputs `peak_hinge_force.H` and `peak_hinge_moment.H` are.
pub fn peak_hinge_reactions(c: &Coupled, r: &DeploymentResult) -> Value {
    let t = c.tracked_loads();
    let at = |i: usize| r.load_peaks.get(i).copied().unwrap_or((0.0, 0.0));
    Value::Array(
        (0..c.panels())
            .map(|i| {
                let ((f, tf), (m, tm)) = (at(t.hinge_force(i)), at(t.hinge_moment(i)));
                json!({"hinge": i + 1, "force": f, "force_time": tf, "moment": m, "moment_time": tm})
            })
            .collect(),
    )
}

/// Per hinge, the largest compliant-latch moment magnitude (N·m) over the deployment and
/// its time, tracked at every integration step (empty with rigid latches).
pub fn latch_moment_peaks(r: &DeploymentResult) -> Vec<Peak> {
    if r.captures.is_empty() {
        return Vec::new();
    }
    let n = r.samples.first().map_or(0, |s| s.latch_moment.len());
    r.load_peaks.iter().take(n).copied().collect()
}

/// [`latch_moment_peaks`] as JSON.
pub fn peak_latch_moments(r: &DeploymentResult) -> Value {
    Value::Array(
        latch_moment_peaks(r)
            .into_iter()
            .enumerate()
            .map(|(i, (m, t))| json!({"hinge": i + 1, "moment": m, "time": t}))
            .collect(),
    )
}

/// The scales of a latch's impulses (the largest hinge or base force, N·s, and moment,
/// N·m·s), against which rounding noise reads as zero.
pub(crate) fn impulse_scales(e: &crate::deploy::LatchEvent) -> (f64, f64) {
    let mut f = e
        .impulses
        .iter()
        .fold(0.0_f64, |a, (v, _)| a.max(v[0].hypot(v[1])));
    let mut m = e.impulses.iter().fold(0.0_f64, |a, (_, v)| a.max(v.abs()));
    if let Some((bf, bm)) = e.base_impulse {
        f = bf.iter().fold(f, |a, v| a.max(v.abs()));
        m = bm.iter().fold(m, |a, v| a.max(v.abs()));
    }
    (f, m.max(f))
}

/// "flexible, 12 of 40 modes" / "rigid", and the synchronisation's name.
fn model_names(d: &Deployment, c: &Coupled) -> (String, String) {
    let base = match d.base {
        BaseKind::Rigid => "rigid".to_string(),
        BaseKind::Flexible { .. } | BaseKind::Corrected { .. } | BaseKind::Reduced { .. }
            if c.base.ritz.dof() <= 6 =>
        {
            "rigid (flexible asked, but it has no elastic component)".to_string()
        }
        BaseKind::Flexible { .. } | BaseKind::Corrected { .. } | BaseKind::Reduced { .. } => {
            format!(
                "flexible, {} of {} hub-fixed modes{}",
                c.modes() - c.base.correction,
                c.base.ritz.dof().saturating_sub(6),
                if c.base.correction > 0 {
                    format!(" + {} static-correction vectors", c.base.correction)
                } else {
                    String::new()
                }
            )
        }
    };
    let sync = match c.sync {
        Synchronisation::None => "none".to_string(),
        Synchronisation::IdealCable => "cable (ideal)".to_string(),
        Synchronisation::ElasticCable(k) => format!("cable ({k} N·m/rad per loop)"),
    };
    (base, sync)
}

/// The model and method the run used, and the automatic integrator's accuracy estimate.
pub fn model_json(d: &Deployment, c: &Coupled, r: &DeploymentResult) -> Value {
    let kept = c.modes() - c.base.correction;
    let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
    let mut v = json!({
        "integrator": integrator_name(d.integrator),
        "base_modes_kept": kept,
        "base_modes_available": c.base.ritz.dof().saturating_sub(6),
        "kept_frequencies_hz": c.base.omega[..kept].iter().map(|w| hz(*w)).collect::<Vec<_>>(),
        "static_correction_vectors": c.base.correction,
        "static_correction_frequencies_hz": c.base.omega[kept..].iter().map(|w| hz(*w)).collect::<Vec<_>>(),
    });
    if let Some(a) = &r.accuracy {
        v["cutoff_hz"] = json!(a.cutoff.map(hz));
        v["step_rule"] = json!({"kappa": a.schedule.kappa, "delta_rad": a.schedule.delta});
        v["accuracy"] = json!({
            "asked": a.asked,
            "estimate": if a.events_differ { Value::Null } else { json!(a.estimate) },
            "reached": a.reached(),
            "times": a.times,
            "rates": a.rates,
            "latch_moments": a.latch_moments,
            "root_loads": a.root_loads,
            "runs": a.runs,
            "events_differ": a.events_differ,
            "scope": if a.first_impact_only {
                "the first impact's time and rate (after a rigid impact on an elastic base the outcome depends on the base modes kept)"
            } else {
                "every capture's time and rate, and the peak latch moments; root loads estimated"
            },
        });
    }
    v
}

/// The automatic integrator's model and accuracy in two lines (None for a named integrator).
fn accuracy_line(c: &Coupled, r: &DeploymentResult) -> Option<String> {
    let a = r.accuracy.as_ref()?;
    let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
    let kept = c.modes() - c.base.correction;
    let top = c.base.omega[..kept].iter().copied().fold(0.0, f64::max);
    let modes = match (kept, a.cutoff) {
        (0, _) => "no base mode kept".to_string(),
        (k, Some(w)) => format!(
            "the base's {k} lowest modes (to {:.4} Hz; the array's time scales set the \
             cutoff at {:.4} Hz, each refinement keeps two more)",
            hz(top),
            hz(w)
        ),
        (k, None) => format!("the base's {k} lowest modes (to {:.4} Hz)", hz(top)),
    };
    let resolved = if a.first_impact_only {
        "followed quasi-statically between the array's steps"
    } else {
        "resolved from the first capture on"
    };
    let model = format!(
        "integrator auto: Rodas5P at steps set by each phase (κ = {:.3}, δ = {:.4} rad); {modes}, \
         {resolved}; {} static-correction vectors, quasi-static; {} runs, {} evaluations",
        a.schedule.kappa, a.schedule.delta, c.base.correction, a.runs, a.evaluations
    );
    let flag = if a.reached() { "" } else { ", NOT reached" };
    let estimate = if a.events_differ {
        "the last two runs differ in their events: no estimate".to_string()
    } else if a.first_impact_only {
        format!(
            "estimate {:.1e} (asked {:.0e}{flag}): time {:.1e}, rate {:.1e}; what follows the \
             impact depends on the base modes kept (a rigid latch on an elastic base has no \
             continuum limit) and is reported with the model above",
            a.estimate, a.asked, a.times, a.rates
        )
    } else {
        format!(
            "estimate {:.1e} (asked {:.0e}{flag}): times {:.1e}, rates {:.1e}, latch moments \
             {:.1e}; root loads {:.1e} (estimated, not bounded)",
            a.estimate, a.asked, a.times, a.rates, a.latch_moments, a.root_loads
        )
    };
    let scope = if a.first_impact_only {
        "the first impact"
    } else {
        "the captures and latch loads"
    };
    Some(format!("{model}\naccuracy of {scope}: {estimate}"))
}

/// The integrator's name as the scenario spells it.
fn integrator_name(i: crate::deploy::Integrator) -> &'static str {
    match i {
        crate::deploy::Integrator::Auto => "auto",
        crate::deploy::Integrator::Explicit => "explicit",
        crate::deploy::Integrator::Implicit => "implicit",
        crate::deploy::Integrator::Adiabatic => "adiabatic",
    }
}

/// The deployment result as one JSON object (`--json` and events.json).
pub fn deploy_json(name: &str, d: &Deployment, c: &Coupled, r: &DeploymentResult) -> String {
    let latches: Vec<Value> = r
        .latches
        .iter()
        .map(|e| {
            json!({
                "hinge": e.hinge,
                "locked": e.locked,
                "time": e.time,
                "angles": e.angles,
                "rates_before": e.rates_before,
                "rates_after": e.rates_after,
                "energy_before": e.energy_before,
                "energy_after": e.energy_after,
                "energy_lost": e.energy_before - e.energy_after,
                "hinge_impulses": e.impulses.iter().enumerate().map(|(i, (f, m))| json!({
                    "hinge": i + 1, "force": f, "moment": m,
                })).collect::<Vec<_>>(),
                "base_impulse": e.base_impulse.map(|(f, m)| json!({"force": f, "moment": m})),
                "half_base_modes": e.half_modes.map(|h| json!({
                    "modes": h.modes, "kept": h.kept,
                    "base_impulse_force_change": h.force_change,
                    "base_impulse_moment_change": h.moment_change,
                    "rates_after_change": h.rates_change,
                })),
            })
        })
        .collect();
    let v = json!({
        "units": {
            "time": "s", "angles": "rad", "rates": "rad/s", "energy": "J (kinetic)",
            "hinge_impulses": "latches[].hinge_impulses: force N·s, the linear impulse from the inboard body (hub or panel i−1) on panel i, deployment-plane axes [u along the wing's length axis, v along its normal]; moment N·m·s, the angular impulse carried by the hinge",
            "base_impulse": "latches[].base_impulse: the impulse the base receives at the root hinge, hub axes: force N·s, moment about the hinge point N·m·s",
            "peak_hinge_reactions": "force N, moment N·m (magnitudes), with their times in s",
            "peak_root_loads": "force N, moment N·m: the force a beam's parent exerts on it and the moment about its root point, hub axes",
            "peak_latch_moments": "N·m",
        },
        "name": name,
        "plate": d.plate,
        "base": model_names(d, c).0,
        "synchronisation": model_names(d, c).1,
        "panels": d.chain.len(),
        "latching": latching_name(d.latching),
        "latch_model": if c.latch.is_some() { "compliant" } else { "rigid" },
        "latches": latches,
        "captures": r.captures.iter().map(|k| json!({"time": k.time, "hinge": k.hinge, "rates": k.rates})).collect::<Vec<_>>(),
        "all_latched": r.all_latched,
        "final_time": r.final_time,
        "settled": settled_json(r.settled),
        "rhs_evaluations": r.evaluations,
        "unlatched": r.unlatched.iter().map(|(h, a)| json!({"hinge": h, "angle": a})).collect::<Vec<_>>(),
        "swing_back": r.swing_back.iter().map(|s| json!({"hinge": s.hinge, "first_time": s.first_time, "min_angle": s.min_angle})).collect::<Vec<_>>(),
        "warnings": r.warnings.iter().map(ToString::to_string).collect::<Vec<_>>(),
        "hub": hub_json(c, r),
        "peak_root_loads": peak_root_loads(c, r),
        "peak_hinge_reactions": peak_hinge_reactions(c, r),
        "peak_latch_moments": peak_latch_moments(r),
        "model": model_json(d, c, r),
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// The terminal event table.
pub fn deploy_table(name: &str, d: &Deployment, c: &Coupled, r: &DeploymentResult) -> String {
    let mut s = String::new();
    let hub = match c.base.hub_motion {
        HubMotion::Fixed => "fixed",
        HubMotion::Free => "free",
    };
    let (base, sync) = model_names(d, c);
    let _ = writeln!(s, "flexcraft deploy: {name}");
    let _ = writeln!(
        s,
        "plate {}, {} panels, hub {hub}, base {base}, synchronisation {sync}, latching {} \
         (SI units: s, rad, rad/s, J, N·s, N·m·s)",
        d.plate,
        d.chain.len(),
        latching_name(d.latching)
    );
    if let Some(line) = accuracy_line(c, r) {
        let _ = writeln!(s, "{line}");
    }
    let show = d.chain.len().min(12);
    for e in &r.latches {
        let _ = writeln!(
            s,
            "\nlatch of hinge {} at t = {:.9} s (locks {:?}); kinetic energy {:.6} J → {:.6} J (lost {:.6} J)",
            e.hinge,
            e.time,
            e.locked,
            e.energy_before,
            e.energy_after,
            e.energy_before - e.energy_after
        );
        let _ = writeln!(
            s,
            "{:>6} {:>12} {:>13} {:>13} {:>13} {:>13} {:>13}",
            "hinge",
            "α [rad]",
            "rate before",
            "rate after",
            "S_u [N·s]",
            "S_v [N·s]",
            "M_S [N·m·s]"
        );
        for i in 0..show {
            let (f, m) = e.impulses[i];
            let _ = writeln!(
                s,
                "{:>6} {:>12} {:>13} {:>13} {:>13} {:>13} {:>13}",
                i + 1,
                super::fixed(e.angles[i], 6),
                super::fixed(e.rates_before[i], 6),
                super::fixed(e.rates_after[i], 6),
                super::fixed(f[0], 6),
                super::fixed(f[1], 6),
                super::fixed(m, 6)
            );
        }
        if show < d.chain.len() {
            let _ = writeln!(s, "   … {} more hinges in --json", d.chain.len() - show);
        }
        if let Some((f, m)) = e.base_impulse {
            let (fs, ms) = impulse_scales(e);
            let (f, m) = (f.map(|v| super::snap(v, fs)), m.map(|v| super::snap(v, ms)));
            let _ = writeln!(
                s,
                "impulse on the base at the root hinge (hub axes): force [{:.6e}, {:.6e}, {:.6e}] N·s, moment [{:.6e}, {:.6e}, {:.6e}] N·m·s",
                f[0], f[1], f[2], m[0], m[1], m[2]
            );
        }
    }
    for k in &r.captures {
        let rates: Vec<String> = k.rates.iter().map(|v| format!("{v:.6}")).collect();
        let _ = writeln!(
            s,
            "\ncapture of hinge {} by its compliant latch at t = {:.9} s (rates [{}] rad/s)",
            k.hinge,
            k.time,
            rates.join(", ")
        );
    }
    let _ = writeln!(s, "\n{}", ending(r));
    if c.base.hub_motion == HubMotion::Free {
        let b = final_body(r);
        // Each quantity's components within rounding of its largest over the run read 0.
        let largest = |f: &dyn Fn(&crate::deploy::BodySample) -> [f64; 3]| {
            r.samples
                .iter()
                .filter_map(|x| x.body.as_deref())
                .flat_map(f)
                .fold(0.0_f64, |m, v| m.max(v.abs()))
        };
        let clean = |v: [f64; 3], f: &dyn Fn(&crate::deploy::BodySample) -> [f64; 3]| {
            let scale = largest(f);
            v.map(|x| super::snap(x, scale))
        };
        let p = clean(b.hub_position, &|x| x.hub_position);
        let a = clean(b.hub_rotation, &|x| x.hub_rotation);
        let v = clean(b.hub_velocity, &|x| x.hub_velocity);
        let w = clean(b.hub_rate, &|x| x.hub_rate);
        let _ = writeln!(
            s,
            "hub (centre of mass, inertial axes): position [{:.6e}, {:.6e}, {:.6e}] m, rotation vector [{:.6e}, {:.6e}, {:.6e}] rad; velocity [{:.6e}, {:.6e}, {:.6e}] m/s, rate [{:.6e}, {:.6e}, {:.6e}] rad/s",
            p[0], p[1], p[2], a[0], a[1], a[2], v[0], v[1], v[2], w[0], w[1], w[2]
        );
    }
    for w in &r.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}

/// The header of deployment.csv (units in brackets).
fn csv_header(c: &Coupled) -> String {
    let n = c.panels();
    let mut h = String::from("t [s]");
    let mut cols = |name: String| {
        h.push(',');
        h.push_str(&name);
    };
    (1..=n).for_each(|i| cols(format!("alpha_{i} [rad]")));
    (1..=n).for_each(|i| cols(format!("rate_{i} [rad/s]")));
    for (q, unit) in [
        ("hub_", "m"),
        ("hub_r", "rad"),
        ("hub_v", "m/s"),
        ("hub_w", "rad/s"),
    ] {
        for a in ["x", "y", "z"] {
            cols(format!("{q}{a} [{unit}]"));
        }
    }
    (1..=c.modes()).for_each(|j| cols(format!("base_eta_{j} [√kg·m]")));
    for b in &c.base.beams {
        for a in ["u", "v", "w"] {
            cols(format!("{}_tip_{a} [m]", b.name));
        }
        cols(format!("{}_tip_twist [rad]", b.name));
    }
    for b in &c.base.beams {
        for a in ["fx", "fy", "fz"] {
            cols(format!("{}_root_{a} [N]", b.name));
        }
        for a in ["mx", "my", "mz"] {
            cols(format!("{}_root_{a} [N·m]", b.name));
        }
    }
    (1..=n).for_each(|i| cols(format!("reaction_u_{i} [N]")));
    (1..=n).for_each(|i| cols(format!("reaction_v_{i} [N]")));
    (1..=n).for_each(|i| cols(format!("moment_{i} [N·m]")));
    if c.sync != Synchronisation::None {
        (1..n).for_each(|k| cols(format!("cable_torque_{k} [N·m]")));
    }
    if c.latch.is_some() {
        (1..=n).for_each(|i| cols(format!("latch_moment_{i} [N·m]")));
        cols("latch_energy [J]".to_string());
    }
    for e in ["kinetic_energy", "spring_energy", "elastic_energy"] {
        cols(format!("{e} [J]"));
    }
    for a in ["x", "y", "z"] {
        cols(format!("p_{a} [N·s]"));
    }
    for a in ["x", "y", "z"] {
        cols(format!("l_{a} [N·m·s]"));
    }
    h.push('\n');
    h
}

/// deployment.csv: one row per sample, the columns of `csv_header` (the text `write_deploy`
/// writes; the Python binding reads its columns from it).
pub fn deployment_csv(c: &Coupled, r: &DeploymentResult) -> String {
    let mut out = csv_header(c);
    let blank = BodySample {
        eta: vec![0.0; c.modes()],
        beam_tips: vec![[0.0; 4]; c.base.beams.len()],
        root_loads: vec![[0.0; 6]; c.base.beams.len()],
        ..BodySample::default()
    };
    let cables = if c.sync == Synchronisation::None {
        0
    } else {
        c.panels().saturating_sub(1)
    };
    for s in &r.samples {
        let b = s.body.as_deref().unwrap_or(&blank);
        let mut row: Vec<f64> = Vec::new();
        row.extend(&s.alpha);
        row.extend(&s.rate);
        for v in [b.hub_position, b.hub_rotation, b.hub_velocity, b.hub_rate] {
            row.extend(v);
        }
        row.extend(&b.eta);
        b.beam_tips.iter().for_each(|t| row.extend(t));
        b.root_loads.iter().for_each(|l| row.extend(l));
        row.extend(s.force.iter().map(|f| f[0]));
        row.extend(s.force.iter().map(|f| f[1]));
        row.extend(&s.moment);
        row.extend((0..cables).map(|k| b.cable_torque.get(k).copied().unwrap_or(0.0)));
        if c.latch.is_some() {
            row.extend(&s.latch_moment);
            row.push(s.latch_energy);
        }
        row.extend([s.kinetic, s.spring, b.elastic]);
        row.extend(b.momentum);
        row.extend(b.angular_momentum);
        out.push_str(&num(s.t));
        for v in row {
            out.push(',');
            out.push_str(&num(v));
        }
        out.push('\n');
    }
    out
}

/// Writes deployment.csv, events.json and plots/*.{png,svg}.
pub fn write_deploy(
    dir: &mut OutputDir,
    name: &str,
    d: &Deployment,
    c: &Coupled,
    r: &DeploymentResult,
) -> Result<(), OutputError> {
    dir.write("events.json", deploy_json(name, d, c, r) + "\n")?;
    dir.write("deployment.csv", deployment_csv(c, r))?;

    let names: Vec<String> = c.base.beams.iter().map(|b| b.name.clone()).collect();
    for f in super::figures::deployment_figures(d, r, &names) {
        f.draw(dir)?;
    }
    // Snapshots: the chain at up to 9 evenly spaced sample times (and the final state).
    let m = r.samples.len();
    let picks: Vec<usize> = (0..9).map(|k| k * (m - 1) / 8).collect();
    let mut snaps: Vec<Series> = Vec::new();
    let mut last = usize::MAX;
    for &k in &picks {
        if k == last {
            continue;
        }
        last = k;
        let s = &r.samples[k];
        snaps.push((
            format!("t = {:.1} s", s.t),
            s.hinges.iter().map(|p| (p[0], p[1])).collect(),
        ));
    }
    line_chart(
        dir,
        "snapshots",
        "panel positions (hinge points joined)",
        ("u [m]", "v [m]"),
        &snaps,
        true,
    )?;
    Ok(())
}

/// How the compliant latches' settling ended, in words.
fn settled_text(s: Option<Settled>) -> String {
    let tol = 100.0 * SETTLE_TOLERANCE;
    match s {
        Some(Settled::AfterTime) => "the settle_time asked for".to_string(),
        Some(Settled::HandedOver) => {
            "one latch period after the last capture (the deployed model, \
             which carries the latch springs, takes the latched array's motion over)"
                .to_string()
        }
        Some(Settled::Decayed) => format!(
            "the latches settled (every captured hinge's rate below {tol} % of the largest at a \
             capture for one latch period)"
        ),
        Some(Settled::Capped { ratio }) => format!(
            "the settling's cap, the latches NOT settled (rates still {:.2} % of the largest at a \
             capture; settled means below {tol} %)",
            100.0 * ratio
        ),
        Some(Settled::EndTime { .. }) => {
            "the deployment's end_time, before the latches had settled".to_string()
        }
        None => "the run stopped (see the warnings)".to_string(),
    }
}

/// How the settling ended, for events.json.
fn settled_json(s: Option<Settled>) -> Value {
    match s {
        Some(Settled::AfterTime) => json!({"by": "settle_time"}),
        Some(Settled::HandedOver) => json!({"by": "hand_over"}),
        Some(Settled::Decayed) => json!({"by": "decayed", "tolerance": SETTLE_TOLERANCE}),
        Some(Settled::Capped { ratio }) => {
            json!({"by": "cap", "tolerance": SETTLE_TOLERANCE, "ratio": ratio})
        }
        Some(Settled::EndTime { ratio }) => {
            json!({"by": "end_time", "tolerance": SETTLE_TOLERANCE, "ratio": ratio})
        }
        None => Value::Null,
    }
}

/// How the run ended, in one line.
fn ending(r: &DeploymentResult) -> String {
    match r.captures.last() {
        // Compliant latches: the run goes on after the last capture while they settle.
        Some(last) if r.all_latched => format!(
            "all hinges captured (the last at t = {:.9} s); the deployment went on until t = {:.9} s: {}",
            last.time,
            r.final_time,
            settled_text(r.settled)
        ),
        _ if r.all_latched => format!("all hinges latched at t = {:.9} s", r.final_time),
        _ => format!("NOT all hinges latched at t = {:.9} s", r.final_time),
    }
}
