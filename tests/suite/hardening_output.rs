//! Hardening of the outputs (issue items 7, 8, 1, 3): byte-identical results whatever the
//! thread count, names escaped for every destination (CSV, HTML, JSON in `<script>`, file
//! names), and long series decimated for plotting.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexcraft"))
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexcraft-hardening-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every file below `root`, as paths relative to it, sorted.
fn tree(root: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, rel: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(root.join(rel)).unwrap() {
            let e = e.unwrap();
            let r = rel.join(e.file_name());
            if e.file_type().unwrap().is_dir() {
                walk(root, &r, out);
            } else {
                out.push(r);
            }
        }
    }
    let mut files = Vec::new();
    walk(root, Path::new(""), &mut files);
    files.sort();
    files
}

/// The two trees hold the same files with the same bytes; returns the number of files.
fn assert_identical_trees(a: &Path, b: &Path) -> usize {
    let (fa, fb) = (tree(a), tree(b));
    assert_eq!(
        fa,
        fb,
        "{} and {} list different files",
        a.display(),
        b.display()
    );
    for f in &fa {
        let x = std::fs::read(a.join(f)).unwrap();
        let y = std::fs::read(b.join(f)).unwrap();
        assert!(
            x == y,
            "{} differs between {} and {}",
            f.display(),
            a.display(),
            b.display()
        );
    }
    fa.len()
}

/// Item 7: `modes --out` and `simulate --out` give the same bytes with 1 and 2 threads.
#[test]
fn outputs_are_byte_identical_with_one_and_two_threads() {
    let dir = scratch("threads");
    for ex in ["seed.toml", "free_hub.toml"] {
        for sub in ["modes", "simulate"] {
            let runs: Vec<PathBuf> = ["1", "2"]
                .iter()
                .map(|threads| {
                    let out = dir.join(format!("{ex}-{sub}-{threads}"));
                    let r = bin()
                        .env("RAYON_NUM_THREADS", threads)
                        .arg(sub)
                        .arg(example(ex))
                        .arg("--out")
                        .arg(&out)
                        .output()
                        .unwrap();
                    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
                    out
                })
                .collect();
            let n = assert_identical_trees(&runs[0], &runs[1]);
            assert!(n > 5, "{ex} {sub}: only {n} files");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// free_hub.toml with two beams and a lumped mass on the hub, so that every kind of
/// component carries a name into the outputs.
fn scenario_with_components(response: &str) -> flexcraft::Scenario {
    let base = std::fs::read_to_string(example("free_hub.toml")).unwrap();
    let (head, tail) = base.split_at(base.find("[[plates]]").unwrap());
    let extra = r#"
[materials.aluminium]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = 2700.0

[[beams]]
name = "boom"
parent = "hub"
root = [-1.0, 0.0, 0.0]
axis = [-1.0, 0.0, 0.0]
length = 3.0
material = "aluminium"
section = { tube = { outer_diameter = 0.1, wall = 0.004 } }
terms = { bending = 4, torsion = 3, axial = 2 }

[[beams]]
name = "mast"
parent = "hub"
root = [0.0, 0.0, 1.0]
axis = [0.0, 0.0, 1.0]
length = 2.0
material = "aluminium"
section = { tube = { outer_diameter = 0.1, wall = 0.004 } }
terms = { bending = 4, torsion = 3, axial = 2 }

[[masses]]
name = "antenna"
parent = "hub"
point = [0.0, 1.0, 0.0]
mass = 5.0
"#;
    let mut src = format!("{head}{extra}\n{tail}");
    if !response.is_empty() {
        let at = src.find("[response]").unwrap();
        src.truncate(at);
        src.push_str(response);
    }
    flexcraft::Scenario::from_toml_str(&src, "hardening.toml").unwrap()
}

/// Runs `simulate` through the library and writes its outputs into `out`.
fn write_simulate(s: &flexcraft::Scenario, out: &Path) -> flexcraft::simulation::Simulation {
    let sim = flexcraft::simulation::Simulation::run(s).unwrap();
    let mut dir = flexcraft::output::OutputDir::create(out, false).unwrap();
    flexcraft::output::write_simulate(&mut dir, s, &sim, b"hostile", "<!--x.toml").unwrap();
    flexcraft::output::write_modes(&mut dir, &sim.model, &sim.modes).unwrap();
    dir.commit().unwrap();
    sim
}

/// Every `<script type="application/json">…</script>` block of the page.
fn json_blocks(html: &str) -> Vec<&str> {
    let open = "<script type=\"application/json\">";
    html.match_indices(open)
        .map(|(i, _)| {
            let a = i + open.len();
            let b = html[a..].find("</script>").unwrap();
            &html[a..a + b]
        })
        .collect()
}

fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let mut r = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_path(path)
        .unwrap();
    r.records()
        .map(|rec| rec.unwrap().iter().map(String::from).collect())
        .collect()
}

/// Item 3: a long response is drawn from a few thousand points per curve (its peaks kept),
/// while response.csv keeps every row.
#[test]
fn long_series_are_decimated_for_plots_but_not_for_csv() {
    let s = scenario_with_components(
        "[response]\nduration = 30.0\noutput_rate = 1000.0\nmodes = 12\ndamping_ratio = 0.01\n",
    );
    let root = scratch("long");
    let out = root.join("out");
    let sim = write_simulate(&s, &out);
    let r = sim.response.as_ref().unwrap();
    let n = r.history.times.len();
    assert!(n > 5 * flexcraft::output::figures::PLOT_POINTS, "{n} rows");
    assert_eq!(csv_rows(&out.join("response.csv")).len(), n + 1);

    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let mut checked = 0;
    for b in json_blocks(&html) {
        let v: serde_json::Value = serde_json::from_str(b).unwrap();
        let Some(series) = v["series"].as_array() else {
            continue;
        };
        for sr in series {
            let (x, y) = (sr["x"].as_array().unwrap(), sr["y"].as_array().unwrap());
            assert!(x.len() <= flexcraft::output::figures::PLOT_POINTS && x.len() == y.len());
            let xs: Vec<f64> = x.iter().map(|v| v.as_f64().unwrap()).collect();
            assert!(xs.windows(2).all(|w| w[0] <= w[1]), "x not monotone");
            // A response channel's peak |value| (summary.json) is in the plotted data.
            let name = sr["name"].as_str().unwrap();
            if let Some(c) = r.channels.iter().position(|c| c.label == name) {
                let peak = r.history.peak(c).0;
                let drawn = y
                    .iter()
                    .map(|v| v.as_f64().unwrap().abs())
                    .fold(0.0, f64::max);
                assert!(
                    (drawn - peak).abs() <= 1e-6 * peak,
                    "{name}: {drawn} vs {peak}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 10, "{checked} channels checked");
    // The SVG pictures are drawn from the decimated curves too.
    let svg = std::fs::read_to_string(out.join("plots/response_boom_tip.svg")).unwrap();
    assert!(svg.len() < 400_000, "{} bytes", svg.len());
    let _ = std::fs::remove_dir_all(&root);
}
