//! The memory estimate that refuses a run before it starts (`scenario/budget.rs`) against
//! the memory the run really takes (issue 43): the peak resident set of the `flexcraft`
//! process, read from the kernel when it ends (`ru_maxrss`), for every part the
//! estimate models — a modal solve whose dense matrices dominate (a 30 × 30 plate: 932
//! coordinates), the export's mass elements and 42 files, the deployment's time series and
//! the response's.
//!
//! Each case must be bounded by its estimate (a run the budget lets through fits in it) and
//! the estimate must stay within twice the measured peak (a budget that refuses runs that
//! would fit, or that no longer models what dominates, fails). Measured 2026-11-28: estimates
//! 1.1–1.6 times the peaks.

use super::common::{example, scratch};
use flexcraft::scenario::RunParts;
use flexcraft::Scenario;

/// Runs `flexcraft ARGS` to completion and returns its peak resident memory, bytes.
///
/// Read through a small Python parent (`resource.getrusage(RUSAGE_CHILDREN).ru_maxrss`): a
/// process started straight from this test binary would inherit its high-water mark, since
/// Linux carries the exec'ing process's old peak over into the new image's (`exec_mmap`),
/// and the test binary runs many other tests beside this one.
fn peak_resident(args: &[&str]) -> u64 {
    const PARENT: &str = "import resource, subprocess, sys\n\
r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n\
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n\
sys.exit(r.returncode)\n";
    let exe = env!("CARGO_BIN_EXE_flexcraft");
    let o = std::process::Command::new("python3")
        .arg("-c")
        .arg(PARENT)
        .arg(exe)
        .args(args)
        .output()
        .expect("python3 runs (a fresh machine has Python 3.11)");
    assert!(
        o.status.success(),
        "flexcraft {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Linux reports ru_maxrss in KiB.
    let kib: u64 = String::from_utf8_lossy(&o.stdout)
        .trim()
        .parse()
        .expect("a number of KiB");
    kib * 1024
}

fn check(name: &str, edit: impl Fn(String) -> String, command: &str, parts: RunParts) {
    let dir = scratch(&format!("memory-{name}"));
    let text = edit(std::fs::read_to_string(example("seed.toml")).unwrap());
    let file = dir.join("scenario.toml");
    std::fs::write(&file, &text).unwrap();
    let estimate = Scenario::from_file(&file)
        .unwrap()
        .estimate_for(parts)
        .peak_bytes();
    let out = dir.join("out");
    let measured = peak_resident(&[
        command,
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let ratio = estimate as f64 / measured as f64;
    eprintln!("{name}: {command} peak {measured} B, estimate {estimate} B ({ratio:.2})");
    assert!(
        (1.0..=2.0).contains(&ratio),
        "{name}: `flexcraft {command}` peaked at {:.1} MiB, estimated {:.1} MiB ({ratio:.2} times)",
        measured as f64 / 1048576.0,
        estimate as f64 / 1048576.0
    );
}

fn plate_terms(n: usize) -> impl Fn(String) -> String {
    move |t| {
        t.replace(
            "terms = { length = 8, width = 6 }",
            &format!("terms = {{ length = {n}, width = {n} }}"),
        )
    }
}

/// `modes` on the seed with a 30 × 30 plate (932 coordinates): the dense solve dominates.
#[test]
fn the_modal_solve_fits_its_estimate() {
    check("modes", plate_terms(30), "modes", RunParts::MODES);
}

/// `export` of 100 modes of the seed with a 20 × 20 plate: the mass elements, the 42 flex
/// file (9 · 100² numbers of N) and the state space, held whole until written.
#[test]
fn the_export_fits_its_estimate() {
    let edit = |t: String| plate_terms(20)(t) + "\n[export]\nmodes = 100\n";
    check("export", edit, "export", RunParts::EXPORT);
}

/// `deploy` of the seed sampled at 1 kHz (70 001 rows of 63 numbers): the samples of two
/// runs and deployment.csv's text.
#[test]
fn the_deployment_series_fit_their_estimate() {
    let edit = |t: String| t.replace("output_rate = 10.0", "output_rate = 1000.0");
    check("deploy", edit, "deploy", RunParts::DEPLOY);
}

/// `simulate` with the response sampled at 1 kHz for 200 s (200 001 rows of every channel
/// and every kept mode's η and η̈).
#[test]
fn the_response_series_fit_their_estimate() {
    let edit = |t: String| {
        t.replace("duration = 60.0", "duration = 200.0")
            .replace("output_rate = 50.0", "output_rate = 1000.0")
    };
    check("simulate", edit, "simulate", RunParts::SIMULATE);
}
