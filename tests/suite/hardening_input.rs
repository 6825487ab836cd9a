//! Hardening of the input side: hostile names, oversized or non-UTF-8 files, values outside
//! their accepted ranges, memory budgets, step limits, located numerical failures, scale-safe
//! directions and the small-deformation warning. Each refusal is checked through the binary
//! (file:line:column, key, reason, exit 2, nothing written) or through the library.

use super::common::{bin, scratch};
use flexcraft::simulation::Simulation;
use flexcraft::structure::ComponentId;
use flexcraft::{ModalAnalysis, RitzModel, Scenario};
use std::path::Path;
use std::process::Output;

const SEED: &str = include_str!("../../examples/seed.toml");
const FREE_HUB: &str = include_str!("../../examples/free_hub.toml");

/// Writes `src` as `dir/scenario.toml` and runs `flexcraft SUB it --out dir/out ARGS`.
pub fn run(dir: &Path, sub: &str, src: impl AsRef<[u8]>, args: &[&str]) -> Output {
    let f = dir.join("scenario.toml");
    std::fs::write(&f, src).unwrap();
    bin()
        .arg(sub)
        .arg(&f)
        .arg("--out")
        .arg(dir.join("out"))
        .args(args)
        .output()
        .unwrap()
}

/// Exit 2, one line `file:LINE:col: KEY…: …REASON…`, and nothing but the scenario in `dir`.
pub fn assert_refused(dir: &Path, out: &Output, line: usize, key: &str, reason: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let loc = format!("scenario.toml:{line}:");
    assert!(err.contains(&loc), "no {loc} in: {err}");
    assert!(err.contains(&format!(" {key}")), "no key {key} in: {err}");
    assert!(err.contains(reason), "no reason {reason:?} in: {err}");
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["scenario.toml"], "{err}");
}

/// The 1-based line of the first occurrence of `needle` in `src`.
pub fn line_of(src: &str, needle: &str) -> usize {
    let at = src
        .find(needle)
        .unwrap_or_else(|| panic!("{needle} not in source"));
    src[..at].matches('\n').count() + 1
}

#[test]
fn hostile_names_are_refused_at_parse_time_and_nothing_is_written_anywhere() {
    let dir = scratch("names");
    let escape = dir.join("SOMEWHERE");
    for (name, reason) in [
        (
            "x/../../../../../../../../SOMEWHERE/pwned",
            "'/' is not allowed",
        ),
        ("hub", "reserved"),
        ("", "must not be empty"),
        ("a,b\\n1,2,3\\\"q", "not allowed"),
        ("<!--<script>", "not allowed"),
        ("..", "start with a letter or a digit"),
    ] {
        let src = FREE_HUB.replace("name = \"wing\"", &format!("name = \"{name}\""));
        let out = run(&dir, "simulate", &src, &[]);
        assert_refused(
            &dir,
            &out,
            line_of(FREE_HUB, "name = \"wing\""),
            "plates[0].name",
            reason,
        );
    }
    assert!(!escape.exists());
    // A name of a megabyte is refused with a message of one screen.
    let src = FREE_HUB.replace(
        "name = \"wing\"",
        &format!("name = \"{}\"", "w".repeat(1 << 20)),
    );
    let out = run(&dir, "modes", &src, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(err.len() < 600, "{} bytes of message", err.len());
    assert!(err.contains("at most 64 characters"), "{err}");
}

#[test]
fn oversized_and_non_utf8_files_are_refused_with_a_location() {
    let dir = scratch("files");
    // A device (/dev/zero, endless) is not read at all; a 17 MiB file (sparse: zeros) is
    // cut at 16 MiB instead of read to the end.
    let out = bin().args(["modes", "/dev/zero"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a regular file"));
    let big = dir.join("big.toml");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(17 << 20)
        .unwrap();
    let out = bin().arg("modes").arg(&big).output().unwrap();
    std::fs::remove_file(&big).unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("larger than 16 MiB"));
    // An invalid UTF-8 byte on line 5, column 8.
    let mut bytes = SEED.as_bytes().to_vec();
    let line5: usize = SEED.match_indices('\n').nth(3).unwrap().0 + 1;
    bytes.insert(line5 + 7, 0xff);
    let out = run(&dir, "modes", &bytes, &[]);
    assert_refused(&dir, &out, 5, "", "not valid UTF-8");
    assert!(String::from_utf8_lossy(&out.stderr).contains("scenario.toml:5:8:"));
    // A file of one 5 MB line of comment, CR line ends only: the message stays short.
    let src = format!("#{}\r[hub]\rmotion = 1", "c".repeat(5 << 20));
    let out = run(&dir, "modes", src, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        out.stderr.len() < 600,
        "{} bytes of message",
        out.stderr.len()
    );
}

/// (what, from, to, key, reason): values that used to hang, overflow or print NaN.
const OUT_OF_RANGE: [(&str, &str, &str, &str, &str); 12] = [
    (
        "hub mass huge",
        "mass = 500.0",
        "mass = 1e308",
        "hub.mass",
        "[1e-6, 1e9] kg",
    ),
    (
        "hub mass subnormal",
        "mass = 500.0",
        "mass = 5e-324",
        "hub.mass",
        "[1e-6, 1e9] kg",
    ),
    (
        "stiffness",
        "stiffness = 3.0",
        "stiffness = 1e308",
        "deployment.hinge.stiffness",
        "[0, 1e6]",
    ),
    (
        "damping",
        "damping = 0.05",
        "damping = 1e308",
        "deployment.hinge.damping",
        "[0, 1e6]",
    ),
    (
        "preload",
        "preload_angle = 0.3",
        "preload_angle = 1e308",
        "deployment.hinge.preload_angle",
        "rad",
    ),
    (
        "tolerance",
        "output_rate = 20.0",
        "output_rate = 20.0\ntolerance = 1e-30",
        "deployment.tolerance",
        "[1e-14, 1e-3]",
    ),
    (
        "panels",
        "panels = 3",
        "panels = 400",
        "deployment.panels",
        "between 1 and 100",
    ),
    (
        "panel lengths",
        "panels = 3",
        "panel_lengths = [1e-6, 3.0, 2.999999]",
        "deployment.panel_lengths",
        "[1e-3, 1e4] m",
    ),
    (
        "panel ratio",
        "panels = 3",
        "panel_lengths = [0.02, 3.0, 2.98]",
        "deployment.panel_lengths",
        "more than 100 times",
    ),
    (
        "deployment rows",
        "end_time = 120.0\noutput_rate = 20.0",
        "end_time = 1e5\noutput_rate = 1e5",
        "deployment.output_rate",
        "the limit is 1000000",
    ),
    (
        "response rate",
        "output_rate = 100.0",
        "output_rate = 5e-324",
        "response.output_rate",
        "[1e-3, 1e5] Hz",
    ),
    (
        "direction",
        "normal = [0.0, 0.0, 1.0]",
        "normal = [0.0, 0.0, 0.0]",
        "plates[0].normal",
        "zero length",
    ),
];

#[test]
fn values_outside_their_range_are_refused_with_location_and_key() {
    let dir = scratch("ranges");
    for (what, from, to, key, reason) in OUT_OF_RANGE {
        assert!(FREE_HUB.contains(from), "{what}");
        let src = FREE_HUB.replacen(from, to, 1);
        let out = run(&dir, "simulate", &src, &[]);
        eprintln!("case: {what}");
        let line = line_of(&src, to.lines().last().unwrap());
        assert_refused(&dir, &out, line, key, reason);
    }
    // A plate's derived stiffness is reported at its thickness, not at its normal.
    let full = include_str!("../../examples/full.toml");
    let src = full.replacen("thickness = 0.01", "thickness = 1e110", 1);
    assert!(src != full);
    let out = run(&dir, "modes", &src, &[]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "thickness = 1e110"),
        "plates[0].thickness",
        "[1e-6, 100] m",
    );
    // A lumped mass of 1e-310 kg.
    let src = full.replacen("mass = 15.0", "mass = 1e-310", 1);
    assert!(src != full);
    let out = run(&dir, "modes", &src, &[]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "mass = 1e-310"),
        "masses[0].mass",
        "[1e-6, 1e9] kg",
    );
}

#[test]
fn a_run_over_the_memory_budget_is_refused_before_it_starts() {
    let dir = scratch("budget");
    // 100 × 100 plate terms: about 15 GiB; refused at the plate's terms under a 1 GiB budget.
    let src = SEED.replacen(
        "terms = { length = 8, width = 6 }",
        "terms = { length = 100, width = 100 }",
        1,
    );
    assert!(src != SEED);
    let out = run(&dir, "modes", &src, &["--max-memory", "1G"]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "name = \"wing\""),
        "plates[0].terms",
        "of memory (limit 1.0 GiB",
    );
    // The seed itself fits a generous budget and not a tiny one.
    let s = Scenario::from_toml_str(SEED, "seed.toml").unwrap();
    let e = s.check_budget(1 << 30).unwrap();
    assert_eq!(e.dof as usize, RitzModel::assemble(&s.structure).dof());
    assert!(s.check_budget(1 << 20).is_err());
    // The response's rows drive the estimate of a long run.
    let long = SEED.replacen("duration = 60.0", "duration = 1.9e4", 1);
    let s = Scenario::from_toml_str(&long, "long.toml").unwrap();
    let err = s.check_budget(128 << 20).unwrap_err();
    assert_eq!(err.key, "response.output_rate");
    assert_eq!(err.location.line, line_of(&long, "output_rate = 50.0"));
    // Commands that make no response are not refused for it: `modes` and `export` budget
    // the modal solve, `deploy` the deployment too.
    use flexcraft::scenario::RunParts;
    for parts in [RunParts::MODES, RunParts::DEPLOY] {
        let e = s.check_budget_for(128 << 20, parts).unwrap();
        assert_eq!(e.response_cells, 0);
    }
    assert!(s.check_budget_for(128 << 20, RunParts::SIMULATE).is_err());
    let out = run(&dir, "modes", &long, &["--max-memory", "128M"]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let out = run(&dir, "simulate", &long, &["--max-memory", "128M"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    // Without time series (modes, export) a budget below what the modal solve needs blames
    // the terms, never an output rate (issue 37); a limit past u64 is no limit.
    let out = run(&dir, "modes", SEED, &["--max-memory", "1K"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(".terms") && !err.contains("output_rate"),
        "{err}"
    );
    let out = run(
        &dir,
        "modes",
        SEED,
        &["--max-memory", "18446744073709551615"],
    );
    assert_eq!(out.status.code(), Some(0), "{out:?}");
}

#[test]
fn a_deployment_that_exceeds_its_step_limit_stops_with_a_status_not_a_hang() {
    let s = Scenario::from_toml_str(FREE_HUB, "free_hub.toml").unwrap();
    let d = s.deployment.as_ref().unwrap();
    let full = flexcraft::deploy::simulate(d);
    assert!(full.all_latched && !full.step_limit_reached());
    let cut = flexcraft::deploy::simulate_limited(d, 50);
    assert!(cut.step_limit_reached());
    assert_eq!(full.status, flexcraft::deploy::RunStatus::AllLatched);
    assert_eq!(
        cut.status,
        flexcraft::deploy::RunStatus::StepLimit { t: cut.final_time }
    );
    assert!(cut
        .warnings
        .contains(&flexcraft::warning::Warning::StepLimit { t: cut.final_time }));
    assert!(!cut.all_latched);
    assert!(cut.final_time > 0.0 && cut.final_time < full.final_time);
    // The samples written up to the stop are those of the full run (same steps).
    let k = cut.samples.len() - 1;
    assert_eq!(cut.samples[k].t, full.samples[k].t);
    assert_eq!(cut.samples[k].alpha, full.samples[k].alpha);
    let w: Vec<String> = cut.warnings.iter().map(ToString::to_string).collect();
    assert!(
        w.iter()
            .any(|w| w.starts_with("step limit reached at t = ")),
        "{w:?}"
    );
}

#[test]
fn a_direction_of_any_scale_gives_the_same_modes() {
    // Scale invariance: a direction is a direction. [0, 0, 1e200] used to overflow to zero
    // in the normalisation and change the first frequency from 1.584 to 0.954 Hz.
    let freqs = |src: &str| -> Vec<f64> {
        let s = Scenario::from_toml_str(src, "t.toml").unwrap();
        let m = ModalAnalysis::compute(&RitzModel::assemble(&s.structure)).unwrap();
        m.modes.iter().map(|m| m.omega_rad_s).collect()
    };
    let base = freqs(FREE_HUB);
    for scaled in [
        "[0.0, 0.0, 1e200]",
        "[0.0, 0.0, 1e-300]",
        "[0.0, -0.0, 5e-324]",
    ] {
        let f = freqs(&FREE_HUB.replace("normal = [0.0, 0.0, 1.0]", &format!("normal = {scaled}")));
        assert_eq!(f, base, "{scaled}");
    }
}

#[test]
fn a_numerical_failure_is_traced_to_its_component() {
    // The coordinate → component map behind located solver failures: the hub's six first,
    // then each element's own range.
    let s = Scenario::from_toml_str(SEED, "seed.toml").unwrap();
    let model = RitzModel::assemble(&s.structure);
    for k in 0..6 {
        assert_eq!(model.component_at(k), ComponentId::Hub);
    }
    for e in &model.elements {
        for k in e.own_range() {
            assert_eq!(model.component_at(k), e.id);
        }
    }
    let pivot = model
        .element(ComponentId::Plate(0))
        .unwrap()
        .own_range()
        .start
        + 3;
    let err = flexcraft::ritz::RitzError::MassNotPositiveDefinite { pivot };
    let id = model.culprit(&err);
    assert_eq!(id, ComponentId::Plate(0));
    let located = s.locate(id, err.to_string());
    assert_eq!(located.key, "plates[0]");
    assert_eq!(located.location.line, line_of(SEED, "name = \"wing\""));
    assert!(located
        .to_string()
        .starts_with(&format!("seed.toml:{}:", located.location.line)));
}

#[test]
fn deflections_beyond_the_linear_model_are_warned_about() {
    // Hinges of 1e5 N·m/rad slam the seed's panels: the linear wing "deflects" by more than
    // its own length, which the run must say is outside the model.
    let stiff = SEED.replacen("stiffness = 1.283", "stiffness = 1e5", 1);
    assert!(stiff != SEED);
    let s = Scenario::from_toml_str(&stiff, "stiff.toml").unwrap();
    let sim = Simulation::run(&s).unwrap();
    assert!(
        sim.warnings
            .iter()
            .any(|w| w.to_string().contains("small-deformation")),
        "{:?}",
        sim.warnings
    );
    let calm = Simulation::run(&Scenario::from_toml_str(SEED, "seed.toml").unwrap()).unwrap();
    assert!(!calm
        .warnings
        .iter()
        .any(|w| w.to_string().contains("small-deformation")));
}

#[test]
fn derived_values_obey_the_ranges_of_given_ones() {
    let dir = scratch("derived");
    // A 50 m thick aluminium plate: the thickness is a valid section size, but the stiffness
    // it implies (D ≈ 8e14 N·m) is outside the range accepted for a given D.
    let full = include_str!("../../examples/full.toml");
    let src = full.replacen("thickness = 0.01", "thickness = 50.0", 1);
    let out = run(&dir, "modes", &src, &[]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "thickness = 50.0"),
        "plates[0].thickness",
        "D = ",
    );
    // A latch angle is refused against its own range, (0, π].
    let src = FREE_HUB.replacen("stiffness = 9.0", "stiffness = 9.0\nlatch_angle = 5.0", 1);
    let out = run(&dir, "deploy", &src, &[]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "latch_angle = 5.0"),
        "deployment.hinges[0].latch_angle",
        "(0, 3.14",
    );
}

#[test]
fn derived_panels_obey_the_ranges_of_given_ones() {
    let dir = scratch("panels");
    // A 6 mm wing cut into 100 panels: 6e-5 m panels, shorter than any accepted panel length.
    let src = FREE_HUB
        .replacen("length = 6.0", "length = 0.006", 1)
        .replacen("panels = 3", "panels = 100", 1);
    let out = run(&dir, "deploy", &src, &[]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "panels = 100"),
        "deployment.panels",
        "a panel's length must lie in",
    );
    // A feather-light wing: the panel inertia m l²/12 falls below its range.
    let src = FREE_HUB
        .replacen("length = 6.0", "length = 0.03", 1)
        .replacen("areal_density = 5.0", "areal_density = 1e-6", 1);
    let out = run(&dir, "deploy", &src, &[]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "plate = \"wing\""),
        "deployment.plate",
        "give panel_mass",
    );
}

/// The coupled deployment's keys (issue 11): each bad value is refused with its line, key
/// and reason, exit 2, nothing written; `base_modes` out of range is clamped with a warning.
#[test]
fn coupled_deployment_keys_are_refused_or_clamped_with_location() {
    let dir = scratch("coupled-keys");
    let sync = "synchronisation = \"cable\"\n";
    let cases: [(String, &str, &str, &str); 13] = [
        (
            SEED.replace(sync, &format!("{sync}hub = \"free\"\n")),
            "hub = \"free\"",
            "deployment.hub",
            "[hub] motion",
        ),
        (
            SEED.replace(sync, &format!("{sync}base_modes = -1\n")),
            "base_modes = -1",
            "deployment.base_modes",
            "0 or more",
        ),
        (
            SEED.replace(sync, &format!("{sync}cable_stiffness = 0.0\n")),
            "cable_stiffness = 0.0",
            "deployment.cable_stiffness",
            "positive",
        ),
        (
            SEED.replace(sync, "cable_stiffness = 100.0\n"),
            "cable_stiffness = 100.0",
            "deployment.cable_stiffness",
            "only a cable",
        ),
        (
            SEED.replace("friction = 0.0\n", "friction = 0.0\n\n[[deployment.hinges]]\n[[deployment.hinges]]\nlatch_angle = 3.0\n[[deployment.hinges]]\n"),
            "synchronisation = \"cable\"",
            "deployment.synchronisation",
            "twice as far",
        ),
        (
            SEED.replace("base = \"flexible\"", "base = \"rigid\"\nbase_modes = 6"),
            "base_modes = 6",
            "deployment.base_modes",
            "rigid base",
        ),
        (
            SEED.replace(sync, &format!("{sync}base_damping_ratio = 1.0\n")),
            "base_damping_ratio = 1.0",
            "deployment.base_damping_ratio",
            "[0, 1)",
        ),
        (
            SEED.replace(sync, &format!("{sync}base_damping_ratio = -0.01\n")),
            "base_damping_ratio = -0.01",
            "deployment.base_damping_ratio",
            "[0, 1)",
        ),
        (
            SEED.replace("base = \"flexible\"", "base = \"rigid\"\nbase_damping_ratio = 0.01"),
            "base_damping_ratio = 0.01",
            "deployment.base_damping_ratio",
            "rigid base",
        ),
        // The automatic integrator (the default) takes accuracy, the named ones tolerance.
        (
            SEED.replace(sync, &format!("{sync}tolerance = 1e-8\n")),
            "tolerance = 1e-8",
            "deployment.tolerance",
            "give accuracy instead",
        ),
        (
            SEED.replace(sync, &format!("{sync}integrator = \"explicit\"\naccuracy = 1e-4\n")),
            "accuracy = 1e-4",
            "deployment.accuracy",
            "named integrator takes tolerance",
        ),
        (
            SEED.replace(sync, &format!("{sync}accuracy = 0.5\n")),
            "accuracy = 0.5",
            "deployment.accuracy",
            "[1e-8, 0.1]",
        ),
        (
            SEED.replace(sync, &format!("{sync}accuracy = 1e-9\n")),
            "accuracy = 1e-9",
            "deployment.accuracy",
            "[1e-8, 0.1]",
        ),
    ];
    for (k, (src, needle, key, reason)) in cases.iter().enumerate() {
        assert_ne!(src, SEED, "case {k}");
        let sub = dir.join(format!("case{k}"));
        std::fs::create_dir_all(&sub).unwrap();
        let out = run(&sub, "deploy", src, &[]);
        assert_refused(&sub, &out, line_of(src, needle), key, reason);
    }
    // A misspelt key is offered the keys that exist, not the gone `hub`.
    let src = SEED.replacen("panels = 3", "panls = 3", 1);
    let err = Scenario::from_toml_str(&src, "s.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("`panels`") && !err.contains("`hub`"), "{err}");
    // Above the base's count: clamped, with the warning.
    let sc = Scenario::from_toml_str(
        &SEED.replace(
            "synchronisation = \"cable\"\n",
            "synchronisation = \"cable\"\nbase_modes = 500\n",
        ),
        "s.toml",
    )
    .unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let mut short = d.clone();
    short.end_time = 0.5;
    let (c, r) = flexcraft::deploy::simulate_coupled(&sc.structure, &short).unwrap();
    assert_eq!(c.modes(), c.base.ritz.dof() - 6);
    assert!(r
        .warnings
        .iter()
        .any(|w| w.to_string().contains("base_modes = 500 is outside")));
}

/// `[deployment.latch]` (issue 19): each bad value is refused with its line, key and
/// reason, exit 2, nothing written.
#[test]
fn latch_keys_are_refused_with_location() {
    let dir = scratch("latch-keys");
    let with = |latch: &str| {
        SEED.replace(
            "[deployment.hinge]",
            &format!("{latch}\n[deployment.hinge]"),
        )
    };
    let cases = [
        (
            with("[deployment.latch]\nmodel = \"compliant\"\nstiffness = 0.0\ndamping = 10.0"),
            "stiffness = 0.0",
            "deployment.latch.stiffness",
            "positive",
        ),
        (
            with("[deployment.latch]\nmodel = \"compliant\"\nstiffness = 1e5\ndamping = -1.0"),
            "damping = -1.0",
            "deployment.latch.damping",
            "[0, 1e9]",
        ),
        (
            with(
                "[deployment.latch]\nmodel = \"compliant\"\nstiffness = [1e5, 1e5]\ndamping = 10.0",
            ),
            "stiffness = [1e5, 1e5]",
            "deployment.latch.stiffness",
            "2 values for 3 hinges",
        ),
        (
            with("[deployment.latch]\nmodel = \"rigid\"\ndamping = 10.0"),
            "damping = 10.0",
            "deployment.latch.damping",
            "rigid latch",
        ),
        (
            with("[deployment.latch]\nsettle_time = 2.0"),
            "settle_time = 2.0",
            "deployment.latch.settle_time",
            "rigid latch",
        ),
        (
            with("[deployment.latch]\nmodel = \"springy\""),
            "model = \"springy\"",
            "deployment.latch.model",
            "springy",
        ),
    ];
    for (k, (src, needle, key, reason)) in cases.iter().enumerate() {
        assert_ne!(src, SEED, "case {k}");
        let sub = dir.join(format!("case{k}"));
        std::fs::create_dir_all(&sub).unwrap();
        let out = run(&sub, "deploy", src, &[]);
        assert_refused(&sub, &out, line_of(src, needle), key, reason);
    }
}

/// `[ritz]` accuracy keys: out-of-range tolerance, mode count and size limit are refused at
/// their line with exit 2 and nothing written; a size limit too small for the components
/// with given terms says so.
#[test]
fn ritz_accuracy_keys_are_refused_with_location() {
    let dir = scratch("ritz_keys");
    let base = include_str!("../../examples/composite.toml");
    for (from, to, key, reason) in [
        (
            "tolerance = 1e-5",
            "tolerance = 0.5",
            "ritz.tolerance",
            "[1e-10, 0.1]",
        ),
        (
            "tolerance = 1e-5",
            "tolerance = 0.0",
            "ritz.tolerance",
            "[1e-10, 0.1]",
        ),
        ("modes = 10", "modes = 0", "ritz.modes", "from 1 to 500"),
        (
            "modes = 10",
            "modes = 10\nmax_dof = 5",
            "ritz.max_dof",
            "from 7 to 4000",
        ),
        (
            "modes = 10",
            "modes = 10\nmax_dof = 99999",
            "ritz.max_dof",
            "from 7 to 4000",
        ),
    ] {
        let src = base.replacen(from, to, 1);
        assert!(src != base, "{to}");
        let out = run(&dir, "modes", &src, &[]);
        let line = line_of(&src, to.lines().last().unwrap());
        assert_refused(&dir, &out, line, key, reason);
    }
    // With every component's terms given and no tolerance the selection does not run; the
    // ranges still hold (the seed gives every component its terms).
    let seed = include_str!("../../examples/seed.toml");
    for (to, key, reason) in [
        (
            "basis = \"legendre\"\nmodes = 0",
            "ritz.modes",
            "from 1 to 500",
        ),
        (
            "basis = \"legendre\"\nmax_dof = -5",
            "ritz.max_dof",
            "from 7 to 4000",
        ),
        (
            "basis = \"legendre\"\nmax_dof = 5000",
            "ritz.max_dof",
            "from 7 to 4000",
        ),
    ] {
        let src = seed.replacen("basis = \"legendre\"", to, 1);
        assert!(src != seed, "{to}");
        let out = run(&dir, "modes", &src, &[]);
        let line = line_of(&src, to.lines().last().unwrap());
        assert_refused(&dir, &out, line, key, reason);
    }
    // Given terms larger than the limit.
    let src = base
        .replacen(
            "bending_stiffness = 6.2e5",
            "bending_stiffness = 6.2e5\nterms = { length = 40, width = 20 }",
            1,
        )
        .replacen("modes = 10", "modes = 10\nmax_dof = 500", 1);
    let out = run(&dir, "modes", &src, &[]);
    assert_refused(
        &dir,
        &out,
        line_of(&src, "max_dof = 500"),
        "ritz.max_dof",
        "already have 806 coordinates",
    );
}

/// Schema errors inside an array of tables name the element as the value errors do
/// (0-based): a misspelt key in the second `[[beams]]` is `beams[1].…`.
#[test]
fn schema_errors_name_the_array_element_like_value_errors() {
    let full = include_str!("../../examples/full.toml");
    let second = full.match_indices("[[beams]]").nth(1).expect("two beams").0;
    let at = second + full[second..].find("\nlength =").expect("a length") + 1;
    let src = format!("{}lenth{}", &full[..at], &full[at + "length".len()..]);
    let err = Scenario::from_toml_str(&src, "full.toml").unwrap_err();
    assert_eq!(err.key, "beams[1].lenth", "{err}");
    assert_eq!(err.location.line, line_of(&src, "lenth ="));
    // And a value error in the same element uses the same form.
    let src = format!(
        "{}length = -1.0{}",
        &full[..at],
        &full[at + full[at..].find('\n').unwrap()..]
    );
    let err = Scenario::from_toml_str(&src, "full.toml").unwrap_err();
    assert!(err.key.starts_with("beams[1]"), "{err}");
}
