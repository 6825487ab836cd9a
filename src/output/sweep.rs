//! `flexcraft modes --deployment-sweep K`: the frequencies of the partly deployed spacecraft
//! along the deployment (deployment_modes.csv, plots/deployment_modes.{png,svg}, a terminal
//! table and a JSON array).

use super::names::csv_bytes;
use super::{num, OutputDir, OutputError};
use crate::deploy::sweep::SweepState;
use serde_json::{json, Value};

/// The largest number of frequencies any state has.
fn width(states: &[SweepState]) -> usize {
    states
        .iter()
        .map(|s| s.frequencies_hz.len())
        .max()
        .unwrap_or(0)
}

/// The sweep as a JSON array (one object per state).
pub fn sweep_json(states: &[SweepState]) -> Value {
    Value::Array(
        states
            .iter()
            .map(|s| {
                json!({
                    "t_s": s.time,
                    "progress": s.progress,
                    "alpha_rad": s.alpha,
                    "latched": s.latched,
                    "frequency_hz": s.frequencies_hz,
                })
            })
            .collect(),
    )
}

/// The terminal table: time, progress, latched hinges, the lowest frequencies.
pub fn sweep_table(states: &[SweepState]) -> String {
    let nf = width(states).min(6);
    let mut o = String::from(
        "\nModes along the deployment (frozen configuration: panels rigid at their angles, \
         free hinges as their springs, latched hinges rigid; elastic modes, Hz):\n",
    );
    o += "         t [s]  progress  latched";
    for j in 0..nf {
        o += &format!("   f{:<8}", j + 1);
    }
    o += "\n";
    for s in states {
        let latched: String = s
            .latched
            .iter()
            .map(|l| if *l { 'L' } else { '-' })
            .collect();
        o += &format!("  {:>12.4}  {:>8.4}  {:>7}", s.time, s.progress, latched);
        for f in s.frequencies_hz.iter().take(nf) {
            o += &format!("  {f:>9.5}");
        }
        o += "\n";
    }
    o
}

/// deployment_modes.csv and plots/deployment_modes.{png,svg}.
pub fn write_sweep(dir: &mut OutputDir, states: &[SweepState]) -> Result<(), OutputError> {
    let n = states.first().map_or(0, |s| s.alpha.len());
    let nf = width(states);
    let csv = csv_bytes(|w| {
        let mut header = vec!["t [s]".to_string(), "progress [-]".to_string()];
        header.extend((1..=n).map(|i| format!("alpha_{i} [rad]")));
        header.extend((1..=n).map(|i| format!("latched_{i} [-]")));
        header.extend((1..=nf).map(|j| format!("f_{j} [Hz]")));
        w.write_record(&header)?;
        for s in states {
            w.write_field(num(s.time))?;
            w.write_field(num(s.progress))?;
            for a in &s.alpha {
                w.write_field(num(*a))?;
            }
            for l in &s.latched {
                w.write_field(if *l { "1" } else { "0" })?;
            }
            for j in 0..nf {
                w.write_field(s.frequencies_hz.get(j).map_or(String::new(), |f| num(*f)))?;
            }
            w.write_record(None::<&[u8]>)?;
        }
        Ok(())
    })?;
    dir.write("deployment_modes.csv", csv)?;
    let series: Vec<super::plot::Series> = (0..nf.min(8))
        .map(|j| {
            (
                format!("mode {}", j + 1),
                states
                    .iter()
                    .filter_map(|s| s.frequencies_hz.get(j).map(|f| (s.progress, *f)))
                    .collect(),
            )
        })
        .collect();
    super::plot::line_chart(
        dir,
        "deployment_modes",
        "Natural frequencies along the deployment",
        (
            "deployment progress (root hinge opening / travel) [-]",
            "frequency [Hz]",
        ),
        &series,
        false,
    )
}
