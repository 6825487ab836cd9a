//! Deployment of the seed spacecraft's solar array (examples/seed.toml): runs the
//! deployment and prints every latch event — time, hinge, rates before and after the
//! impact and the kinetic energy it dissipates.
//!
//! Run with `cargo run --release --example deployment_events`.

use flexcraft::Scenario;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/seed.toml"));
    let scenario = Scenario::from_file(path)?;
    let deployment = scenario
        .deployment
        .as_ref()
        .ok_or("the scenario has no [deployment] section")?;

    let (_model, result) = flexcraft::deploy::simulate_coupled(&scenario.structure, deployment)?;

    println!("{}: {} latch events", scenario.name, result.latches.len());
    for e in &result.latches {
        let lost = e.energy_before - e.energy_after;
        println!(
            "t = {:.6} s  hinge {} latched  kinetic energy {:.6e} J -> {:.6e} J (lost {:.3} %)",
            e.time,
            e.hinge,
            e.energy_before,
            e.energy_after,
            100.0 * lost / e.energy_before
        );
        println!("    rates before [rad/s]: {}", list(&e.rates_before));
        println!("    rates after  [rad/s]: {}", list(&e.rates_after));
    }
    println!(
        "all hinges latched: {}; run ended at t = {:.6} s",
        result.all_latched, result.final_time
    );
    Ok(())
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:+.6e}"))
        .collect::<Vec<_>>()
        .join(", ")
}
