//! Deployment outputs: event table, JSON, deployment.csv, events.json and plots.

use super::plot::{line_chart, Series};
use super::{num, OutputDir, OutputError};
use crate::deploy::chain::PlanarHub;
use crate::deploy::{Deployment, DeploymentResult, Latching};
use serde_json::{json, Value};
use std::fmt::Write;

fn latching_name(l: Latching) -> &'static str {
    match l {
        Latching::Sequential => "sequential",
        Latching::Simultaneous => "simultaneous",
    }
}

fn hub_json(d: &Deployment, r: &DeploymentResult) -> Value {
    match d.chain.hub {
        PlanarHub::Fixed => json!({"motion": "fixed"}),
        PlanarHub::Free { mass, inertia } => json!({
            "motion": "free",
            "mass_kg": mass,
            "inertia_kg_m2": inertia,
            "position_m": [r.final_q[0], r.final_q[1]],
            "angle_rad": r.final_q[2],
            "velocity_m_s": [r.final_qd[0], r.final_qd[1]],
            "rate_rad_s": r.final_qd[2],
        }),
    }
}

/// The deployment result as one JSON object (`--json` and events.json).
pub fn deploy_json(name: &str, d: &Deployment, r: &DeploymentResult) -> String {
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
            })
        })
        .collect();
    let v = json!({
        "units": {
            "time": "s", "angles": "rad", "rates": "rad/s", "energy": "J (kinetic)",
            "force": "N·s, linear impulse from the inboard body (hub or panel i−1) on panel i, deployment-plane axes [u along the wing's length axis, v along its normal]",
            "moment": "N·m·s, angular impulse carried by the hinge",
        },
        "name": name,
        "plate": d.plate,
        "panels": d.chain.len(),
        "latching": latching_name(d.latching),
        "latches": latches,
        "all_latched": r.all_latched,
        "final_time": r.final_time,
        "unlatched": r.unlatched.iter().map(|(h, a)| json!({"hinge": h, "angle": a})).collect::<Vec<_>>(),
        "swing_back": r.swing_back.iter().map(|s| json!({"hinge": s.hinge, "first_time": s.first_time, "min_angle": s.min_angle})).collect::<Vec<_>>(),
        "warnings": r.warnings.iter().map(ToString::to_string).collect::<Vec<_>>(),
        "hub": hub_json(d, r),
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// The terminal event table.
pub fn deploy_table(name: &str, d: &Deployment, r: &DeploymentResult) -> String {
    let mut s = String::new();
    let hub = match d.chain.hub {
        PlanarHub::Fixed => "fixed",
        PlanarHub::Free { .. } => "free",
    };
    let _ = writeln!(s, "flexcraft deploy: {name}");
    let _ = writeln!(
        s,
        "plate {}, {} panels, hub {hub}, latching {} (SI units: s, rad, rad/s, J, N·s, N·m·s)",
        d.plate,
        d.chain.len(),
        latching_name(d.latching)
    );
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
                "{:>6} {:>12.6} {:>13.6} {:>13.6} {:>13.6} {:>13.6} {:>13.6}",
                i + 1,
                e.angles[i],
                e.rates_before[i],
                e.rates_after[i],
                f[0],
                f[1],
                m
            );
        }
        if show < d.chain.len() {
            let _ = writeln!(s, "   … {} more hinges in --json", d.chain.len() - show);
        }
    }
    let _ = writeln!(
        s,
        "\n{} at t = {:.9} s",
        if r.all_latched {
            "all hinges latched"
        } else {
            "NOT all hinges latched"
        },
        r.final_time
    );
    if let PlanarHub::Free { .. } = d.chain.hub {
        let _ = writeln!(
            s,
            "hub (centre of mass, deployment plane u, v; rotation θ): position [{:.6e}, {:.6e}] m, θ = {:.6e} rad; velocity [{:.6e}, {:.6e}] m/s, θ̇ = {:.6e} rad/s",
            r.final_q[0], r.final_q[1], r.final_q[2], r.final_qd[0], r.final_qd[1], r.final_qd[2]
        );
    }
    for w in &r.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}

/// Writes deployment.csv, events.json and plots/*.{png,svg}.
pub fn write_deploy(
    dir: &mut OutputDir,
    name: &str,
    d: &Deployment,
    r: &DeploymentResult,
) -> Result<(), OutputError> {
    let n = d.chain.len();
    dir.write("events.json", deploy_json(name, d, r) + "\n")?;
    let mut c = String::from("t [s]");
    for i in 1..=n {
        let _ = write!(c, ",alpha_{i} [rad]");
    }
    for i in 1..=n {
        let _ = write!(c, ",rate_{i} [rad/s]");
    }
    c.push_str(",hub_u [m],hub_v [m],hub_theta [rad]");
    for i in 1..=n {
        let _ = write!(c, ",reaction_u_{i} [N]");
    }
    for i in 1..=n {
        let _ = write!(c, ",reaction_v_{i} [N]");
    }
    for i in 1..=n {
        let _ = write!(c, ",moment_{i} [N·m]");
    }
    c.push_str(",kinetic_energy [J],spring_energy [J]\n");
    for s in &r.samples {
        c.push_str(&num(s.t));
        for v in s.alpha.iter().chain(&s.rate).chain(&s.hub) {
            c.push(',');
            c.push_str(&num(*v));
        }
        for f in &s.force {
            c.push(',');
            c.push_str(&num(f[0]));
        }
        for f in &s.force {
            c.push(',');
            c.push_str(&num(f[1]));
        }
        for m in &s.moment {
            c.push(',');
            c.push_str(&num(*m));
        }
        let _ = writeln!(c, ",{},{}", num(s.kinetic), num(s.spring));
    }
    dir.write("deployment.csv", c)?;

    for f in super::figures::deployment_figures(d, r) {
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
