//! Natural modes of a small spacecraft built in code: a cantilevered aluminium beam with a
//! tip mass on a fixed hub, written as a TOML string, parsed, assembled and solved.
//!
//! Run with `cargo run --release --example modes_from_toml`.

use flexcraft::{ModalAnalysis, RitzModel, Scenario};

/// The scenario, exactly as it could be written in a file (SI units: m, kg, Pa).
const SCENARIO: &str = r#"
name = "beam with tip mass"
format_version = 1

[hub]
motion = "fixed"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
center_of_mass = [0.0, 0.0, 0.0]

[materials.aluminium]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = 2700.0

[[beams]]
name = "beam"
parent = "hub"
root = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 2.0
material = "aluminium"
section = { area = 1e-3, iy = 1e-6, iz = 1e-6, torsion_constant = 2e-6, polar_inertia = 2e-6 }
terms = { bending = 12, torsion = 8, axial = 8 }

[[masses]]
name = "tip"
parent = "beam"
station = 2.0
mass = 3.0
inertia = [0.05, 0.2, 0.2]
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The second argument names the text in error messages (`file:line:column: key: …`).
    let scenario = Scenario::from_toml_str(SCENARIO, "beam_with_tip_mass.toml")?;
    let model = RitzModel::assemble(&scenario.structure);
    let modes = ModalAnalysis::compute(&model)?;

    println!(
        "{}: {} generalized coordinates ({} solved for, hub {:?})",
        scenario.name,
        model.dof(),
        modes.dof,
        modes.hub_motion
    );
    println!(
        "{:>4}  {:>8}  {:>12}  {:>12}  {:>9}",
        "mode", "kind", "f [Hz]", "ω [rad/s]", "dominant"
    );
    for m in modes.modes.iter().take(10) {
        println!(
            "{:>4}  {:>8}  {:>12.6}  {:>12.6}  {:>9}",
            m.number,
            if m.rigid { "rigid" } else { "elastic" },
            m.frequency_hz(),
            m.omega_rad_s,
            m.dominant()
        );
    }

    // A mode shape is a plain Vec<f64> over all generalized coordinates (the hub's six
    // first), mass-normalised (φᵀMφ = 1).
    let first = modes.elastic().next().ok_or("no elastic mode")?;
    let largest = first.shape.iter().fold(0.0_f64, |a, &c| a.max(c.abs()));
    println!(
        "first elastic mode: {:.6} Hz, {} coefficients, largest |coefficient| {:.6e}",
        first.frequency_hz(),
        first.shape.len(),
        largest
    );
    Ok(())
}
