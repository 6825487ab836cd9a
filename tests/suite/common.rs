//! Helpers shared by the test modules: build scenarios from TOML text and solve them.

use flexcraft::{ModalAnalysis, RitzModel, Scenario};

/// Parses a scenario given as TOML text (panics with the error report on failure).
pub fn scenario(toml: &str) -> Scenario {
    Scenario::from_toml_str(toml, "test.toml").unwrap_or_else(|e| panic!("{e}"))
}

/// Parses the bundled example `examples/<name>` after `edit` has changed its text.
pub fn edited_example(name: &str, edit: impl Fn(String) -> String) -> Scenario {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    let src = edit(std::fs::read_to_string(&path).unwrap());
    Scenario::from_toml_str(&src, &path).unwrap()
}

/// Assembles and solves a scenario.
pub fn solve(toml: &str) -> (RitzModel, ModalAnalysis) {
    let s = scenario(toml);
    let model = RitzModel::assemble(&s.structure);
    let modes = ModalAnalysis::compute(&model).expect("modal analysis");
    (model, modes)
}

/// Elastic circular frequencies ω [rad/s], ascending.
pub fn elastic_omegas(modes: &ModalAnalysis) -> Vec<f64> {
    modes.elastic().map(|m| m.omega_rad_s).collect()
}

/// A fixed-hub cantilever plate of length 1, width 1/aspect, D = ρh = 1 (so λ = ω).
pub fn cfff_plate(aspect: f64, basis: &str, nl: usize, nw: usize) -> String {
    clamped_plate(1.0, 1.0 / aspect, 1.0, 1.0, 0.3, basis, nl, nw)
}

/// A plate named "plate" of length a and width b, bending stiffness D, areal density μ and
/// Poisson ratio ν, clamped along its root edge to a fixed hub; nl × nw terms of `basis`.
#[allow(clippy::too_many_arguments)]
pub fn clamped_plate(
    a: f64,
    b: f64,
    d: f64,
    mu: f64,
    nu: f64,
    basis: &str,
    nl: usize,
    nw: usize,
) -> String {
    format!(
        r#"
name = "clamped plate"
[hub]
motion = "fixed"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
center_of_mass = [0.0, 0.0, 0.0]
[[plates]]
name = "plate"
parent = "hub"
root = [0.0, 0.0, 0.0]
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = {a}
width = {b}
areal_density = {mu}
bending_stiffness = {d}
poisson_ratio = {nu}
terms = {{ length = {nl}, width = {nw} }}
[ritz]
basis = "{basis}"
"#
    )
}

/// Bisection for a sign change of f on [a, b] to machine precision.
pub fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let mut fa = f(a);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let fm = f(m);
        if (fm > 0.0) == (fa > 0.0) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Every sign change of f on a fine grid over [a, b], refined by bisection.
pub fn roots(f: impl Fn(f64) -> f64, a: f64, b: f64, steps: usize) -> Vec<f64> {
    let h = (b - a) / steps as f64;
    let mut out = Vec::new();
    let mut x0 = a;
    let mut f0 = f(a);
    for i in 1..=steps {
        let x1 = a + h * i as f64;
        let f1 = f(x1);
        if f0.is_finite() && f1.is_finite() && (f0 > 0.0) != (f1 > 0.0) {
            out.push(bisect(&f, x0, x1));
        }
        x0 = x1;
        f0 = f1;
    }
    out
}

/// Determinant of a 4×4 matrix (Laplace expansion).
pub fn det4(m: [[f64; 4]; 4]) -> f64 {
    let minor = |r: usize, c: usize| -> f64 {
        let mut s = [[0.0; 3]; 3];
        let mut ri = 0;
        for (i, row) in m.iter().enumerate() {
            if i == r {
                continue;
            }
            let mut ci = 0;
            for (j, v) in row.iter().enumerate() {
                if j == c {
                    continue;
                }
                s[ri][ci] = *v;
                ci += 1;
            }
            ri += 1;
        }
        s[0][0] * (s[1][1] * s[2][2] - s[1][2] * s[2][1])
            - s[0][1] * (s[1][0] * s[2][2] - s[1][2] * s[2][0])
            + s[0][2] * (s[1][0] * s[2][1] - s[1][1] * s[2][0])
    };
    (0..4)
        .map(|c| if c % 2 == 0 { 1.0 } else { -1.0 } * m[0][c] * minor(0, c))
        .sum()
}

/// The `flexcraft` binary under test.
pub fn bin() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_flexcraft"))
}

/// A bundled example scenario's path.
pub fn example(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

/// A fresh, empty scratch directory for one test (names are unique across the suite).
pub fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("flexcraft-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Starts `flexcraft simulate` on the seed with ten minutes of response (about a second of
/// writing) into `out` (a folder named `out` in `parent`) and waits until its staging folder
/// `parent/.out.partial-HOST-PID` exists: (the child, that folder).
pub fn simulate_until_staging(
    dir: &std::path::Path,
    parent: &std::path::Path,
) -> (std::process::Child, std::path::PathBuf) {
    use std::time::{Duration, Instant};
    let seed = std::fs::read_to_string(example("seed.toml")).unwrap();
    assert!(seed.contains("duration = 60.0"));
    let file = dir.join("long.toml");
    std::fs::write(&file, seed.replace("duration = 60.0", "duration = 600.0")).unwrap();
    let mut child = bin()
        .arg("simulate")
        .arg(&file)
        .arg("--out")
        .arg(parent.join("out"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap();
    let staging = parent.join(format!(".out.partial-{}-{}", host.trim(), child.id()));
    let start = Instant::now();
    while !staging.exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before staging"
        );
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no staging folder"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    (child, staging)
}

/// The sorted names in a directory.
pub fn entries(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Every file below `root` with its bytes, by path relative to `root`.
pub fn tree(root: &std::path::Path) -> std::collections::BTreeMap<std::path::PathBuf, Vec<u8>> {
    use std::path::{Path, PathBuf};
    fn walk(root: &Path, rel: &Path, out: &mut std::collections::BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(root.join(rel)).unwrap() {
            let e = e.unwrap();
            let r = rel.join(e.file_name());
            if e.file_type().unwrap().is_dir() {
                walk(root, &r, out);
            } else {
                out.insert(r.clone(), std::fs::read(root.join(&r)).unwrap());
            }
        }
    }
    let mut m = std::collections::BTreeMap::new();
    walk(root, Path::new(""), &mut m);
    m
}

/// The same files with the same bytes under `a` and `b`, both ways (the difference named if
/// not); returns the number of files.
pub fn assert_same_tree(a: &std::path::Path, b: &std::path::Path) -> usize {
    let (x, y) = (tree(a), tree(b));
    let only_a: Vec<_> = x.keys().filter(|k| !y.contains_key(*k)).collect();
    let only_b: Vec<_> = y.keys().filter(|k| !x.contains_key(*k)).collect();
    assert!(
        only_a.is_empty() && only_b.is_empty(),
        "only in {}: {only_a:?}; only in {}: {only_b:?}",
        a.display(),
        b.display()
    );
    for (k, v) in &x {
        assert!(
            y[k] == *v,
            "{} differs between {} and {}",
            k.display(),
            a.display(),
            b.display()
        );
    }
    x.len()
}

/// One 2 m, 10 kg panel (5 kg/m², 2 m × 1 m) on a held 100 kg hub without beams (a rigid
/// base), hinge spring k = 3 N·m/rad preloaded 0.4 rad beyond the latch at π/2, no friction
/// or damping, deploying over 20 s at `output_rate` and `tolerance`; `extra` is appended
/// (a latch or a [montecarlo] section). The closed-form deployment of the Monte Carlo and
/// compliant-latch tests.
pub fn one_panel(name: &str, output_rate: f64, tolerance: f64, extra: &str) -> String {
    format!(
        r#"
name = "{name}"
[hub]
motion = "fixed"
mass = 100.0
inertia = [10.0, 10.0, 10.0]
center_of_mass = [0.0, 0.0, 0.0]
[[plates]]
name = "wing"
parent = "hub"
root = [0.5, 0.0, 0.0]
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 2.0
width = 1.0
areal_density = 5.0
bending_stiffness = 1.0e4
poisson_ratio = 0.3
terms = {{ length = 3, width = 2 }}
[deployment]
plate = "wing"
panels = 1
end_time = 20.0
output_rate = {output_rate:?}
integrator = "explicit"
tolerance = {tolerance:e}
[deployment.hinge]
stiffness = 3.0
preload_angle = 0.4
{extra}
"#
    )
}
