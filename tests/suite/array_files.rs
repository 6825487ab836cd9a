//! The array files (`output::arrays`) read by the programs they are for: NumPy's `numpy.load`
//! and SciPy's `scipy.io.loadmat` (the reference readers of the two formats) load a sample
//! `.npz` and `.mat` and compare names, order, shapes, dtypes/classes and values with the
//! expectations written independently in `scripts/check_array_files.py`.
//!
//! Ignored by default (it needs Python with numpy and scipy): `scripts/check_array_files.sh`
//! makes a virtual environment and runs it with `FLEXCRAFT_PYTHON` set to its interpreter.

use super::common::scratch;
use flexcraft::output::{mat_bytes, npz_bytes, ArrayValue};
use std::path::Path;
use std::process::Command;

/// The sample `scripts/check_array_files.py` expects: every kind of value, shapes 0-d to 3-d,
/// empty arrays, IEEE special values, non-ASCII and beyond-BMP text.
fn sample() -> Vec<(&'static str, ArrayValue)> {
    let (a, b, c) = (2, 3, 4);
    let cube: Vec<f64> = (0..a * b * c)
        .map(|n| (100 * (n / (b * c)) + 10 * (n / c % b) + n % c) as f64)
        .collect();
    vec![
        (
            "A",
            ArrayValue::matrix(3, 2, vec![1.0, 2.0, 3.0, 0.1, -2.5e-7, 1e300]),
        ),
        (
            "T",
            ArrayValue::Real {
                shape: vec![a, b, c],
                data: cube,
            },
        ),
        ("freq_hz", ArrayValue::vector(vec![0.5, 1.25, 2.0])),
        ("mass_kg", ArrayValue::scalar(12.5)),
        (
            "special",
            ArrayValue::vector(vec![
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NAN,
                -0.0,
                5e-324,
            ]),
        ),
        ("E", ArrayValue::matrix(0, 3, vec![])),
        (
            "state_names",
            ArrayValue::Strings(vec!["eta_1".into(), "eta_dot_1".into(), "x".into()]),
        ),
        (
            "input_names",
            ArrayValue::Strings(vec!["F_x".into(), "θ_ü".into()]),
        ),
        ("no_names", ArrayValue::Strings(vec![])),
        ("units", ArrayValue::Text("rad/s".into())),
        ("title", ArrayValue::Text("Bode: θ → 𝜔".into())),
        ("empty_text", ArrayValue::Text(String::new())),
    ]
}

#[test]
#[ignore = "needs Python with numpy and scipy: scripts/check_array_files.sh"]
fn array_files_load_in_numpy_and_scipy() {
    // Run under --ignored, a missing Python is a failure, not a pass.
    let python = std::env::var_os("FLEXCRAFT_PYTHON")
        .expect("FLEXCRAFT_PYTHON not set: run scripts/check_array_files.sh");
    let dir = scratch("array-files");
    let arrays = sample();
    std::fs::write(dir.join("sample.npz"), npz_bytes(&arrays).unwrap()).unwrap();
    std::fs::write(
        dir.join("sample.mat"),
        mat_bytes(&arrays, "Platform: any, Created by: flexcraft test").unwrap(),
    )
    .unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_array_files.py");
    let out = Command::new(&python)
        .arg(&script)
        .arg(&dir)
        .output()
        .unwrap_or_else(|e| panic!("cannot run FLEXCRAFT_PYTHON={python:?}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    print!("{stdout}");
    assert!(
        out.status.success(),
        "{} failed ({}):\n{stdout}\n{stderr}",
        script.display(),
        out.status
    );
    assert!(stdout.contains("numpy.load: ok") && stdout.contains("scipy.io.loadmat: ok"));
    let _ = std::fs::remove_dir_all(&dir);
}
