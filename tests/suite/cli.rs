//! The `flexcraft` binary end to end: bad input is refused with file, line:column, key and
//! reason, exit status 2, and no output left behind; good input writes complete, reproducible
//! outputs.

use super::common::{assert_same_tree, bin, entries, scratch};
use std::path::Path;

const SEED: &str = include_str!("../../examples/seed.toml");
const FULL: &str = include_str!("../../examples/full.toml");

/// Runs `flexcraft SUB SCENARIO --out DIR/a` and `… DIR/b`; returns both stdouts.
fn run_twice(sub: &str, scenario: &Path, dir: &Path) -> Vec<String> {
    ["a", "b"]
        .iter()
        .map(|run| {
            let r = bin()
                .arg(sub)
                .arg(scenario)
                .arg("--out")
                .arg(dir.join(run))
                .output()
                .unwrap();
            assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
            String::from_utf8_lossy(&r.stdout).into_owned()
        })
        .collect()
}

/// (name, source, mutation: (from, to), expected location "line:", key fragment, reason fragment)
fn bad_cases() -> Vec<(
    &'static str,
    &'static str,
    &'static str,
    &'static str,
    &'static str,
    &'static str,
)> {
    vec![
        ("syntax", SEED, "[hub]", "[hub", "hub", "header"),
        (
            "unknown key",
            SEED,
            "length = 13.0",
            "lenght = 13.0",
            "lenght",
            "unknown field",
        ),
        (
            "missing key",
            SEED,
            "length = 13.0\n",
            "\n",
            "length",
            "missing field",
        ),
        (
            "wrong type",
            SEED,
            "length = 13.0",
            "length = \"13\"",
            "length",
            "invalid type",
        ),
        (
            "negative size",
            SEED,
            "length = 13.0",
            "length = -13.0",
            "length",
            "positive",
        ),
        (
            "non-finite",
            SEED,
            "length = 13.0",
            "length = nan",
            "length",
            "positive finite",
        ),
        (
            "negative mass",
            FULL,
            "mass = 15.0",
            "mass = -15.0",
            "mass",
            "positive",
        ),
        (
            "poisson",
            SEED,
            "poisson_ratio = 0.3\ndensity",
            "poisson_ratio = 0.5\ndensity",
            "poisson_ratio",
            "(-1, 0.5)",
        ),
        (
            "poisson low",
            SEED,
            "poisson_ratio = 0.3\nterms",
            "poisson_ratio = -1.0\nterms",
            "poisson_ratio",
            "(-1, 0.5)",
        ),
        (
            "tube wall",
            SEED,
            "wall = 0.02 }",
            "wall = 1.2 }",
            "wall",
            "radius",
        ),
        (
            "station",
            SEED,
            "station = 13.0 ",
            "station = 13.5 ",
            "station",
            "beyond",
        ),
        (
            "unknown parent",
            SEED,
            "parent = \"mast\"",
            "parent = \"mats\"",
            "parent",
            "unknown parent",
        ),
        (
            "cycle",
            FULL,
            "parent = \"hub\"\nroot = [0.0, 0.0, 0.0]",
            "parent = \"boom\"\nstation = 1.0",
            "parent",
            "cycle",
        ),
        (
            "zero axis",
            SEED,
            "axis = [0.0, 0.0, 1.0]\nlength",
            "axis = [0.0, 0.0, 0.0]\nlength",
            "axis",
            "zero length",
        ),
        (
            "normal",
            SEED,
            "normal = [0.0, 0.0, 1.0]",
            "normal = [1.0, 0.0, 0.5]",
            "normal",
            "perpendicular",
        ),
        (
            "inertia pd",
            FULL,
            "1100.0, 15.0",
            "1100.0, 1500.0",
            "inertia",
            "positive definite",
        ),
        (
            "inertia triangle",
            FULL,
            "[900.0, 1200.0, 1100.0, 15.0, -8.0, 4.0]",
            "[100.0, 1200.0, 100.0]",
            "inertia",
            "triangle",
        ),
        (
            "terms zero",
            SEED,
            "bending = 8,",
            "bending = 0,",
            "bending",
            "between 1 and 100",
        ),
        (
            "terms large",
            SEED,
            "width = 6 }",
            "width = 101 }",
            "width",
            "between 1 and 100",
        ),
        (
            "response duration",
            SEED,
            "duration = 60.0",
            "duration = 0.0",
            "response.duration",
            "positive",
        ),
        (
            "response rows",
            SEED,
            "duration = 60.0\noutput_rate = 50.0",
            "duration = 6e5\noutput_rate = 50.0",
            "response.output_rate",
            "30000001 rows; the limit is 1000000",
        ),
        (
            "response damping",
            SEED,
            "damping_ratio = 0.0",
            "damping_ratio = 1.5",
            "response.damping_ratio",
            "below 1",
        ),
        (
            "response modes",
            SEED,
            "modes = 20",
            "modes = 0",
            "response.modes",
            "at least 1",
        ),
        (
            "response handover",
            SEED,
            "handover = \"projection\"",
            "handover = \"magic\"",
            "handover",
            "unknown variant",
        ),
        (
            "response key",
            SEED,
            "damping_ratio = 0.0",
            "damping = 0.0",
            "damping",
            "unknown field",
        ),
        (
            "basis",
            SEED,
            "basis = \"legendre\"",
            "basis = \"chebyshev\"",
            "basis",
            "unknown variant",
        ),
    ]
}

#[test]
fn bad_input_is_refused_with_location_key_reason_and_exit_2_and_no_output() {
    let dir = scratch("bad");
    for (name, src, from, to, key, reason) in bad_cases() {
        assert!(src.contains(from), "{name}: mutation source not found");
        let file = dir.join("scenario.toml");
        std::fs::write(&file, src.replacen(from, to, 1)).unwrap();
        let out = dir.join("out");
        let sub = if name.starts_with("response") {
            "simulate"
        } else if name.contains("panel")
            || name.contains("stiffness")
            || name.contains("damping")
            || name.contains("latch")
            || name.contains("initial")
            || name.contains("deploy")
        {
            "deploy"
        } else {
            "modes"
        };
        let r = bin()
            .arg(sub)
            .arg(&file)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{name}: {err}");
        assert!(r.stdout.is_empty(), "{name}: printed on stdout");
        let first = err.lines().next().unwrap_or("");
        assert!(
            first.starts_with(&format!("error: {}:", file.display())),
            "{name}: {err}"
        );
        let loc = first[format!("error: {}:", file.display()).len()..]
            .split(':')
            .take(2)
            .collect::<Vec<_>>();
        assert!(
            loc.len() == 2 && loc.iter().all(|p| p.parse::<usize>().is_ok_and(|v| v > 0)),
            "{name}: {first}"
        );
        assert!(err.contains(key), "{name}: key {key} not named: {err}");
        assert!(
            err.contains(reason),
            "{name}: reason {reason} not given: {err}"
        );
        assert!(!err.contains("panicked"), "{name}");
        assert!(err.lines().count() <= 24, "{name}: more than a screen");
        assert_eq!(
            entries(&dir),
            vec!["scenario.toml".to_string()],
            "{name}: output left behind"
        );
    }
    let r = bin()
        .args(["modes", "/nonexistent/flexcraft.toml"])
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn outputs_are_complete_and_byte_identical_across_runs() {
    let dir = scratch("good");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/seed.toml");
    run_twice("modes", &scenario, &dir);
    let a = entries(&dir.join("a"));
    for f in [
        "modes.json",
        "frequencies.csv",
        "coefficients",
        "shapes",
        "plots",
    ] {
        assert!(a.contains(&f.to_string()), "{f} missing: {a:?}");
    }
    let plots = entries(&dir.join("a/plots"));
    assert!(plots.iter().filter(|p| p.ends_with(".png")).count() >= 6);
    assert!(plots.iter().filter(|p| p.ends_with(".svg")).count() >= 6);
    // Every file identical between the two runs.
    assert!(assert_same_tree(&dir.join("a"), &dir.join("b")) > 20);
    // The JSON on stdout is the same object as modes.json, and carries the interface keys.
    let r = bin()
        .arg("modes")
        .arg(&scenario)
        .arg("--json")
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    let file: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("a/modes.json")).unwrap()).unwrap();
    assert_eq!(v, file);
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(v["dof"].as_u64().unwrap() as usize, modes.len());
    for (i, m) in modes.iter().enumerate() {
        assert_eq!(m["number"].as_u64().unwrap() as usize, i + 1);
        assert_eq!(m["rigid"].as_bool().unwrap(), i < 6);
        let f = m["frequency_hz"].as_f64().unwrap();
        let w = m["omega_rad_s"].as_f64().unwrap();
        assert!((w - 2.0 * std::f64::consts::PI * f).abs() <= 1e-12 * w.max(1.0));
        assert!(m["dominant"].is_string() && m["strain_energy_share"].is_object());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn help_states_si_units() {
    for args in [
        vec!["--help"],
        vec!["modes", "--help"],
        vec!["deploy", "--help"],
        vec!["simulate", "--help"],
    ] {
        let r = bin().args(&args).output().unwrap();
        let s = String::from_utf8_lossy(&r.stdout);
        assert!(s.contains("SI"), "{args:?}: {s}");
    }
}

#[test]
fn deploy_writes_complete_reproducible_outputs_and_json_interface() {
    let dir = scratch("deploy");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/seed.toml");
    run_twice("deploy", &scenario, &dir);
    for f in [
        "deployment.csv",
        "events.json",
        "plots/angles.png",
        "plots/rates.svg",
        "plots/reactions.png",
        "plots/hub.png",
        "plots/snapshots.svg",
    ] {
        let a = std::fs::read(dir.join("a").join(f)).unwrap_or_else(|_| panic!("{f} missing"));
        assert_eq!(
            a,
            std::fs::read(dir.join("b").join(f)).unwrap(),
            "{f} differs"
        );
    }
    let csv = std::fs::read_to_string(dir.join("a/deployment.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    for col in [
        "t [s]",
        "alpha_3 [rad]",
        "rate_1 [rad/s]",
        "hub_x [m]",
        "hub_ry [rad]",
        "hub_wz [rad/s]",
        "base_eta_1 [√kg·m]",
        "mast_tip_w [m]",
        "mast_root_my [N·m]",
        "cable_torque_2 [N·m]",
        "elastic_energy [J]",
        "l_z [N·m·s]",
        "reaction_u_1 [N]",
        "reaction_v_3 [N]",
    ] {
        assert!(header.contains(col), "{col}");
    }
    let r = bin()
        .arg("deploy")
        .arg(&scenario)
        .arg("--json")
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(v["all_latched"], serde_json::Value::Bool(true));
    // The ideal cable: every hinge latches at once, straight.
    let latches = v["latches"].as_array().unwrap();
    assert_eq!(latches.len(), 1);
    assert_eq!(latches[0]["locked"].as_array().unwrap().len(), 3);
    assert!(latches[0]["base_impulse"]["force"].is_array());
    for l in latches {
        assert_eq!(l["hinge_impulses"].as_array().unwrap().len(), 3);
        assert!(l["energy_before"].as_f64().unwrap() >= l["energy_after"].as_f64().unwrap());
        assert_eq!(l["angles"].as_array().unwrap().len(), 3);
    }
    // A scenario without [deployment] is refused with exit status 2.
    let plate = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/cantilever_plate.toml");
    let r = bin().arg("deploy").arg(&plate).output().unwrap();
    assert_eq!(r.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_array_that_cannot_latch_is_reported_not_hung() {
    let dir = scratch("nolatch");
    let file = dir.join("weak.toml");
    // Springs whose neutral angle is short of the latch angle: the panels stop short.
    let src = SEED
        .replace("preload_angle = 0.25", "preload_angle = -1.0")
        .replace("stiffness = 12.0", "stiffness = 4.0");
    std::fs::write(&file, src.replace("end_time = 70.0", "end_time = 60.0")).unwrap();
    let r = bin()
        .arg("deploy")
        .arg(&file)
        .arg("--json")
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(v["all_latched"], serde_json::Value::Bool(false));
    assert!(!v["unlatched"].as_array().unwrap().is_empty());
    assert!((v["final_time"].as_f64().unwrap() - 60.0).abs() < 1e-9);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_writes_complete_reproducible_outputs() {
    let dir = scratch("simulate");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/seed.toml");
    let printed = run_twice("simulate", &scenario, &dir);
    let text = &printed[0];
    for needle in [
        "Hand-over at t =",
        "kinetic energy before",
        "peak mast tip deflection w",
        "peak wing tip corner",
        "hub drift",
        "attitude change",
        "latch of hinge",
    ] {
        assert!(text.contains(needle), "summary lacks {needle}: {text}");
    }
    let a = entries(&dir.join("a"));
    for f in [
        "summary.json",
        "modes.json",
        "deployment.csv",
        "response.csv",
        "events.json",
        "plots",
    ] {
        assert!(a.contains(&f.to_string()), "{f} missing: {a:?}");
    }
    let plots = entries(&dir.join("a/plots"));
    for p in [
        "response_mast_tip",
        "response_mast_twist",
        "response_wing_tip",
        "response_hub_translation",
        "response_hub_rotation",
        "response_modal_amplitudes",
    ] {
        for ext in ["png", "svg"] {
            let f = format!("{p}.{ext}");
            assert!(plots.contains(&f), "{f} missing");
            assert!(
                std::fs::metadata(dir.join("a/plots").join(&f))
                    .unwrap()
                    .len()
                    > 1000
            );
        }
    }
    assert_same_tree(&dir.join("a"), &dir.join("b"));
    // summary.json: the interface numbers, consistent with response.csv.
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("a/summary.json")).unwrap()).unwrap();
    let h = &v["handover"];
    let (eb, ea) = (
        h["energy_before"].as_f64().unwrap(),
        h["energy_after"].as_f64().unwrap(),
    );
    // The linear model's energy after vs the coupled model's (deformed base) before: equal
    // to second order in the deformation (docs/theory.md §3).
    assert!(ea <= eb * (1.0 + 1e-8) && ea > 0.0);
    let frac = h["captured_energy_fraction"].as_f64().unwrap();
    assert!(frac > 0.9 && frac < 1.0, "20 of 74 modes: {frac}");
    let resp = &v["response"];
    assert_eq!(resp["elastic_modes_kept"].as_u64(), Some(20));
    assert_eq!(resp["rows"].as_u64(), Some(3001));
    let csv = std::fs::read_to_string(dir.join("a/response.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert!(header[0] == "t [s]" && header[1] == "t_after_latch [s]");
    assert!(header.contains(&"wing_tip_plus [m]"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3001);
    assert_eq!(rows[3000][1], 60.0);
    let t_latch = v["handover"]["latch_time"].as_f64().unwrap();
    assert!((rows[3000][0] - (t_latch + 60.0)).abs() < 1e-9);
    let col = header
        .iter()
        .position(|h| *h == "wing_tip_plus [m]")
        .unwrap();
    let peak = rows.iter().map(|r| r[col].abs()).fold(0.0, f64::max);
    let ch = resp["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "wing_tip_plus")
        .unwrap();
    // The summary's peak is the closed form's (docs/theory.md §3.2): no sample is above it
    // (serde_json's default float parser may be 1 ulp off), and the 50 Hz samples of the
    // wing's ~1 Hz bending come within 1e-3 of it.
    let want = ch["peak"].as_f64().unwrap();
    assert!(
        peak <= want * (1.0 + 4.0 * f64::EPSILON) && peak >= want * (1.0 - 1e-3),
        "{peak} vs {want}"
    );
    // --json prints the same object as summary.json.
    let r = bin()
        .arg("simulate")
        .arg(&scenario)
        .arg("--json")
        .output()
        .unwrap();
    let j: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(j, v);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_clamps_too_many_modes_and_refuses_a_scenario_without_deployment() {
    let dir = scratch("simulate-bad");
    let file = dir.join("s.toml");
    std::fs::write(&file, SEED.replace("modes = 20", "modes = 5000")).unwrap();
    let r = bin()
        .arg("simulate")
        .arg(&file)
        .arg("--json")
        .output()
        .unwrap();
    assert!(r.status.success());
    let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(
        v["response"]["elastic_modes_kept"],
        v["response"]["elastic_modes_available"]
    );
    assert!(v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("response.modes = 5000")));
    let cut = SEED.find("[deployment]").unwrap();
    let resp = SEED.find("[response]").unwrap();
    std::fs::write(&file, format!("{}{}", &SEED[..cut], &SEED[resp..])).unwrap();
    let out = dir.join("out");
    let r = bin()
        .arg("simulate")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("[deployment]"));
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}
