//! How the coupled deployment's outputs change as base modes are added (the table in
//! docs/convergence.md): a free 1500 kg hub, an 8 m aluminium tube mast (D 0.12 m, wall
//! 3 mm) and three 5 m, 50 kg panels hinged at its tip (k = 2 N·m/rad, preload 0.25 rad),
//! rigid latches, sequential. For every `base_modes` it prints the latch times, the root
//! hinge's rate just after each latch, the base impulse of each latch and the peak mast root
//! moment over the deployment (tracked at every integration step); then the same with
//! compliant latches (k_L = 1e4 N·m/rad,
//! c_L = 200 N·m·s/rad): capture times, peak latch moments and the peak mast root moment.
//!
//! Run with `cargo run --release --example base_modes_convergence`.

use flexcraft::deploy::base::BaseKind;
use flexcraft::deploy::{simulate_coupled, Integrator, LatchModel};
use flexcraft::Scenario;

const CASE: &str = r#"
name = "mast and three panels (docs/convergence.md)"
[hub]
motion = "free"
mass = 1500.0
inertia = [1267.5, 1267.5, 1267.5]
center_of_mass = [0.0, 0.0, 0.0]
[materials.aluminium]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = 2700.0
[[beams]]
name = "mast"
parent = "hub"
root = [1.3, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 8.0
material = "aluminium"
section = { tube = { outer_diameter = 0.12, wall = 0.003 } }
terms = { bending = 10, torsion = 2, axial = 2 }
[[plates]]
name = "wing"
parent = "mast"
station = 8.0
length_axis = [0.0, -1.0, 0.0]
normal = [1.0, 0.0, 0.0]
length = 15.0
width = 1.0
areal_density = 10.0
bending_stiffness = 1.0e4
poisson_ratio = 0.3
terms = { length = 4, width = 2 }
[deployment]
plate = "wing"
panels = 3
end_time = 60.0
output_rate = 20.0
integrator = "explicit"
tolerance = 1e-10
[deployment.hinge]
stiffness = 2.0
preload_angle = 0.25
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sc = Scenario::from_toml_str(CASE, "convergence.toml")?;
    let mut d = sc.deployment.clone().ok_or("no deployment")?;
    d.integrator = Integrator::Explicit;
    println!("base_modes | latch times [s] | root-hinge rate after each latch [rad/s] | |base impulse| per latch [N·s] | peak mast root moment [N·m] at t [s]");
    for modes in [0usize, 1, 2, 4, 6, 8] {
        d.base = if modes == 0 {
            BaseKind::Rigid
        } else {
            BaseKind::Flexible { modes: Some(modes) }
        };
        let (c, r) = simulate_coupled(&sc.structure, &d)?;
        let times: Vec<String> = r.latches.iter().map(|e| format!("{:.9}", e.time)).collect();
        let rates: Vec<String> = r
            .latches
            .iter()
            .map(|e| format!("{:.5}", e.rates_after[0]))
            .collect();
        let impulses: Vec<String> = r
            .latches
            .iter()
            .map(|e| {
                let (f, _) = e.base_impulse.unwrap_or_default();
                format!("{:.4}", (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
            })
            .collect();
        let (peak, at) = mast_root_moment_peak(&r);
        println!(
            "{} ({}) | {} | {} | {} | {:.4} at {:.2}",
            modes,
            if modes == 0 {
                "rigid".to_string()
            } else {
                format!("{} kept", c.modes())
            },
            times.join(", "),
            rates.join(", "),
            impulses.join(", "),
            peak,
            at
        );
    }
    d.latch = LatchModel::Compliant {
        stiffness: vec![1e4; 3],
        damping: vec![200.0; 3],
        settle_time: Some(5.0),
    };
    println!("\ncompliant latches (k_L = 1e4 N·m/rad, c_L = 200 N·m·s/rad)");
    println!("base_modes | capture times [s] | peak latch moment per hinge [N·m] | peak mast root moment [N·m] at t [s]");
    for modes in [0usize, 2, 4, 6, 8] {
        d.base = if modes == 0 {
            BaseKind::Rigid
        } else {
            BaseKind::Flexible { modes: Some(modes) }
        };
        let (_, r) = simulate_coupled(&sc.structure, &d)?;
        let times: Vec<String> = r
            .captures
            .iter()
            .map(|k| format!("{:.9}", k.time))
            .collect();
        // Tracked at every integration step (`load_peaks`: the latch moments first).
        let peaks: Vec<String> = r.load_peaks[..3]
            .iter()
            .map(|(p, _)| format!("{p:.4}"))
            .collect();
        let (peak, at) = mast_root_moment_peak(&r);
        println!(
            "{} | {} | {} | {:.4} at {:.3}",
            if modes == 0 {
                "rigid".to_string()
            } else {
                modes.to_string()
            },
            times.join(", "),
            peaks.join(", "),
            peak,
            at
        );
    }
    Ok(())
}

/// The peak magnitude of the mast's root moment and its time, tracked at every integration
/// step (`DeploymentResult::load_peaks`: the 3 latch moments, then the mast's root force and
/// root moment).
fn mast_root_moment_peak(r: &flexcraft::deploy::DeploymentResult) -> (f64, f64) {
    r.load_peaks[3 + 1]
}
