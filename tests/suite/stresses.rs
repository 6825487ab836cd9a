//! Issue 38, item 4: section loads along a beam and its stresses (docs/theory.md §3.3).
//!
//! * Hand calculation: a tube cantilevered from a free hub with a tip mass, the whole
//!   spacecraft accelerated rigidly (a tip load m_t·a plus the tube's own inertia). At the
//!   station x: V = −(ρA(L − x) + m_t) a, M_y = (ρA(L − x)²/2 + m_t(L − x)) a, and at the
//!   root σ = M R/I, τ = k V/A, σ_vm = √(σ² + 3τ²).
//! * Second formulation: at the root the section loads are the opposite of the root-load
//!   channels, which integrate the beam's mass matrix in closed form (response/loads.rs)
//!   where the sections use quadrature and point Jacobians.

use flexcraft::response::loads::beam_root_channels;
use flexcraft::response::sections::{section_channels, stations};
use flexcraft::response::stress::{stresses, SectionFibres};
use flexcraft::RitzModel;

use super::common::scenario;

const RHO: f64 = 2700.0;
const D: f64 = 0.08;
const WALL: f64 = 0.002;
const L: f64 = 3.0;
const TIP: f64 = 4.0;

fn model() -> RitzModel {
    let s = scenario(&format!(
        r#"
name = "tube on a free hub"
[hub]
motion = "free"
mass = 50.0
inertia = [5.0, 5.0, 5.0]
center_of_mass = [0.0, 0.0, 0.0]
[materials.al]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = {RHO}
[[beams]]
name = "tube"
parent = "hub"
root = [0.5, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = {L}
material = "al"
section = {{ tube = {{ outer_diameter = {D}, wall = {WALL} }} }}
terms = {{ bending = 6, torsion = 3, axial = 3 }}
[[masses]]
name = "tip"
parent = "tube"
station = {L}
offset = [0.0, 0.0, 0.0]
mass = {TIP}
inertia = [0.01, 0.01, 0.01]
"#
    ));
    RitzModel::assemble(&s.structure)
}

fn dot(row: &[f64], q: &[f64]) -> f64 {
    row.iter().zip(q).map(|(a, b)| a * b).sum()
}

#[test]
fn rigid_acceleration_gives_the_cantilever_hand_calculation() {
    let m = model();
    let n = m.dof();
    let pi = std::f64::consts::PI;
    let (ro, ri) = (D / 2.0, D / 2.0 - WALL);
    let area = pi * (ro * ro - ri * ri);
    let inertia = pi * (ro.powi(4) - ri.powi(4)) / 4.0;
    let rho_a = RHO * area;
    let xs = stations(&m.structure, 0);
    assert_eq!(xs.len(), 11, "{xs:?}");
    for &x in &xs {
        let ch = section_channels(&m, 0, x);
        // q̈: the hub's translation along z (everything with it), a = 2 m/s²; then along x.
        let a = 2.0;
        let mut qdd = vec![0.0; n];
        qdd[2] = a;
        let r: Vec<f64> = ch.iter().map(|c| dot(&c.row, &qdd)).collect();
        let out = rho_a * (L - x) + TIP;
        let moment = (rho_a * (L - x).powi(2) / 2.0 + TIP * (L - x)) * a;
        let scale = out * a * L;
        assert!(
            (r[2] + out * a).abs() <= 1e-9 * out * a,
            "x = {x}: Vz {} vs {}",
            r[2],
            -out * a
        );
        assert!(
            (r[4] - moment).abs() <= 1e-9 * scale,
            "x = {x}: My {} vs {moment}",
            r[4]
        );
        for k in [0, 1, 3, 5] {
            assert!(
                r[k].abs() <= 1e-9 * scale,
                "x = {x}: resultant {k} = {}",
                r[k]
            );
        }
        qdd[2] = 0.0;
        qdd[0] = a;
        let n_force = dot(&ch[0].row, &qdd);
        assert!(
            (n_force + out * a).abs() <= 1e-9 * out * a,
            "x = {x}: N {n_force}"
        );
        if x == 0.0 {
            // At the root: σ = M R / I, τ = k V / A with k → 2 for this thin tube.
            let f = SectionFibres::tube(D, WALL);
            let s = stresses(
                [0.0, 0.0, -out * a, 0.0, moment, 0.0],
                &section(area, inertia),
                &f,
            );
            let sigma = moment * ro / inertia;
            let tau = f.shear_factor.1 * out * a / area;
            assert!((s.normal - sigma).abs() <= 1e-12 * sigma);
            assert!((s.shear - tau).abs() <= 1e-12 * tau);
            assert!((s.von_mises - (sigma * sigma + 3.0 * tau * tau).sqrt()).abs() <= 1e-9 * sigma);
            assert!(
                (f.shear_factor.1 - 2.0).abs() < 0.06,
                "{:?}",
                f.shear_factor
            );
        }
    }
}

fn section(area: f64, inertia: f64) -> flexcraft::structure::BeamSection {
    flexcraft::structure::BeamSection {
        area,
        iy: inertia,
        iz: inertia,
        torsion_constant: 2.0 * inertia,
        polar_inertia: 2.0 * inertia,
    }
}

#[test]
fn root_section_is_the_opposite_of_the_root_loads() {
    let m = model();
    let root = beam_root_channels(&m);
    let sec = section_channels(&m, 0, 0.0);
    let ex = [1.0, 0.0, 0.0];
    // The tube's axes are the structure's (axis x, section y along y): N = −F_x, V_y = −F_y,
    // V_z = −F_z, T = −M_x, M_y = −M_y, M_z = −M_z, column by column.
    let _ = ex;
    let scale = root
        .iter()
        .flat_map(|c| c.row.iter())
        .fold(0.0_f64, |a, v| a.max(v.abs()));
    for k in 0..6 {
        for (a, b) in sec[k].row.iter().zip(&root[k].row) {
            assert!((a + b).abs() <= 1e-10 * scale, "resultant {k}: {a} vs −{b}");
        }
    }
}

const SEED: &str = include_str!("../../examples/seed.toml");

/// The seed with `allowable` (and a factor of safety 1.25) on its aluminium.
fn seed_with_allowable(allowable: &str) -> String {
    let s = SEED.replacen(
        "density = 2700.0",
        &format!("density = 2700.0\nallowable_stress = {allowable}\nfactor_of_safety = 1.25"),
        1,
    );
    assert_ne!(s, SEED);
    s
}

#[test]
fn bad_allowables_and_missing_fibres_are_refused_with_their_key() {
    let refused = |text: &str, key: &str, why: &str| {
        let e = flexcraft::Scenario::from_toml_str(text, "s.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("s.toml:") && e.contains(key) && e.contains(why),
            "{e}"
        );
    };
    refused(
        &seed_with_allowable("-8e4"),
        "materials.aluminium.allowable_stress",
        "[1000, 1e13] Pa",
    );
    refused(
        &seed_with_allowable("8e4").replace("factor_of_safety = 1.25", "factor_of_safety = 0.9"),
        "materials.aluminium.factor_of_safety",
        "[1, 100]",
    );
    refused(
        &SEED.replacen(
            "density = 2700.0",
            "density = 2700.0\nfactor_of_safety = 2.0",
            1,
        ),
        "materials.aluminium.factor_of_safety",
        "needs allowable_stress",
    );
    // A general section whose material has an allowable: its fibres are needed.
    let general = seed_with_allowable("8e4").replace(
        "section = { tube = { outer_diameter = 2.0, wall = 0.02 } }",
        "section = { area = 0.124, iy = 0.0616, iz = 0.0616, torsion_constant = 0.123, polar_inertia = 0.123 }",
    );
    refused(&general, "beams[0].section.y_extreme", "allowable_stress");
    let tube_with_fibres = SEED.replace(
        "section = { tube = { outer_diameter = 2.0, wall = 0.02 } }",
        "section = { tube = { outer_diameter = 2.0, wall = 0.02 }, y_extreme = 1.0 }",
    );
    refused(
        &tube_with_fibres,
        "beams[0].section.y_extreme",
        "general section only",
    );
    let latch = SEED.replacen(
        "[deployment.hinge]",
        "[deployment.latch]\nmoment_allowable = -5.0\n\n[deployment.hinge]",
        1,
    );
    refused(&latch, "deployment.latch.moment_allowable", "N·m");
}

#[test]
fn a_negative_margin_fails_the_run_with_status_3_after_the_outputs() {
    // The seed's mast peaks at σ_vm ≈ 87 kPa in the response: against 80 kPa / 1.25 the
    // margin is −0.26, against 1 MPa it is positive.
    let dir = super::common::scratch("negative_margin");
    let file = dir.join("seed.toml");
    std::fs::write(&file, seed_with_allowable("8e4")).unwrap();
    let out = dir.join("out");
    let o = super::common::bin()
        .args(["simulate", "--quiet", "--fail-on-negative-margin", "--out"])
        .arg(&out)
        .arg(&file)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(
        err.contains("negative margin of safety") && err.contains("beam \"mast\""),
        "{err}"
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let m = &summary["margins"][0];
    let (vm, ms) = (
        m["value"].as_f64().unwrap(),
        m["margin_of_safety"].as_f64().unwrap(),
    );
    assert!((ms - (8e4 / (1.25 * vm) - 1.0)).abs() < 1e-12, "{m}");
    assert!(std::fs::read_to_string(out.join("report.html"))
        .unwrap()
        .contains("class=\"neg\""));
    std::fs::write(&file, seed_with_allowable("1e6")).unwrap();
    let o = super::common::bin()
        .args(["simulate", "--quiet", "--fail-on-negative-margin"])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn the_hub_timeline_is_continuous_and_its_rates_are_its_derivatives() {
    // The seed with 2 s of response at 2 kHz: hub.csv's positions and rotations, finite-
    // differenced, against its velocities and rates (the deployment's from the coupled
    // model's state, the response's from the closed form: a second formulation each), and
    // the rows continuous across the hand-over.
    let text = SEED
        .replace("output_rate = 50.0", "output_rate = 2000.0")
        .replace("duration = 60.0", "duration = 2.0");
    assert!(text.contains("output_rate = 2000.0") && text.contains("duration = 2.0"));
    let sim = flexcraft::simulation::Simulation::run(&scenario(&text)).unwrap();
    let rows = flexcraft::output::hub::timeline(&sim).expect("a free hub");
    let th = sim.response.as_ref().unwrap().handover.latch_time;
    assert_eq!(rows[0].t, 0.0);
    assert!((rows.last().unwrap().t - (th + 2.0)).abs() < 1e-9);
    assert!(rows.windows(2).all(|w| w[1].t >= w[0].t));
    let vmax = rows.iter().fold(0.0_f64, |m, r| m.max(r.velocity.norm()));
    let wmax = rows.iter().fold(0.0_f64, |m, r| m.max(r.rate.norm()));
    let mut checked = 0;
    for w in rows.windows(2) {
        let (a, b) = (w[0], w[1]);
        let dt = b.t - a.t;
        if dt <= 0.0 || a.response != b.response {
            continue;
        }
        // The trapezoidal rule: error dt²/12 · |ẍ|, small against the largest velocity at
        // 2 kHz; coarser at the deployment's 10 Hz samples, with its slow motion.
        let tol = if b.response { 2e-3 } else { 2e-2 };
        let dv = (b.position - a.position) * (1.0 / dt) - (a.velocity + b.velocity) * 0.5;
        assert!(dv.norm() <= tol * vmax, "t = {}: velocity {dv:?}", a.t);
        // The seed turns about y alone: the rotation vector's rate is the angular rate.
        let dw = (b.rotation - a.rotation) * (1.0 / dt) - (a.rate + b.rate) * 0.5;
        assert!(dw.norm() <= tol * wmax, "t = {}: rate {dw:?}", a.t);
        checked += 1;
    }
    assert!(checked > 4000, "{checked}");
    // Across the hand-over: the first response row follows the last deployment row within
    // the motion of one step (the velocity itself changes there: the response keeps 20 of
    // the 74 elastic modes, 96 % of the hand-over's energy, and its hub velocity is the
    // kept modes' share).
    let k = rows.iter().position(|r| r.response).unwrap();
    let (a, b) = (rows[k - 1], rows[k]);
    let dt = b.t - a.t;
    let jump = (b.position - a.position).norm();
    assert!(
        jump <= 1.5 * vmax * dt,
        "{a:?}\n{b:?}\n{jump:e} vs {vmax:e} dt {dt:e}"
    );
    assert!((b.rotation - a.rotation).norm() <= 1.5 * wmax * dt);
    assert!((b.velocity - a.velocity).norm() <= 0.2 * vmax);
}
