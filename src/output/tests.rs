//! The output layer tested from inside the crate. Defence in depth: component names that the scenario
//! parser would refuse (it validates them) are forced into a parsed scenario here, and every
//! output destination must still escape or sanitise them. (Outside the crate a structure is
//! read-only, so this test can only live here.) And long series: decimated for the plots,
//! complete in the CSV.

use std::path::{Path, PathBuf};

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
fn scenario_with_components(response: &str) -> crate::Scenario {
    let base = include_str!("../../examples/free_hub.toml").to_string();
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
    // Two base modes keep the run short (the stubby booms' higher modes reach kilohertz).
    let tail = tail.replace("[deployment]\n", "[deployment]\nbase_modes = 2\n");
    let mut src = format!("{head}{extra}\n{tail}");
    if !response.is_empty() {
        let at = src.find("[response]").unwrap();
        src.truncate(at);
        src.push_str(response);
    }
    crate::Scenario::from_toml_str(&src, "hardening.toml").unwrap()
}

/// Runs `simulate` through the library and writes its outputs into `out`.
fn write_simulate(s: &crate::Scenario, out: &Path) -> crate::simulation::Simulation {
    let sim = crate::simulation::Simulation::run(s).unwrap();
    let mut dir = crate::output::OutputDir::create(out, false).unwrap();
    crate::output::write_simulate(&mut dir, s, &sim, b"hostile", "<!--x.toml").unwrap();
    crate::output::write_modes(&mut dir, &sim.model, &sim.modes).unwrap();
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

/// Items 8 and 1: hostile component names (renamed after parsing, since the parser refuses
/// them) reach CSV, HTML, embedded JSON and file names intact where they are data and
/// harmless where they are syntax.
#[test]
fn hostile_names_are_escaped_for_every_destination() {
    const NAMES: [&str; 4] = ["a,b\"q", "x/../../y", "<!--<script>", ".."];
    let mut s = scenario_with_components("");
    s.name = "</script><!--<script>alert(1)".into();
    s.structure.beams[0].name = NAMES[0].into();
    s.structure.beams[1].name = NAMES[1].into();
    s.structure.plates[0].name = NAMES[2].into();
    s.structure.masses[0].name = NAMES[3].into();
    s.deployment.as_mut().unwrap().plate = NAMES[2].into();

    let root = scratch("hostile");
    let out = root.join("out");
    let sim = write_simulate(&s, &out);
    let r = sim.response.as_ref().expect("a response");

    // Nothing was written beside the output folder, and every file name is sane.
    let beside: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(beside, ["out"]);
    let files = tree(&out);
    for f in &files {
        assert!(
            f.components()
                .all(|c| matches!(c, std::path::Component::Normal(_))),
            "{f:?}"
        );
        let name = f.file_name().unwrap().to_str().unwrap();
        if name == ".flexcraft-output" {
            continue; // flexcraft's own marker of an output folder
        }
        assert!(!name.starts_with('.'), "{f:?}");
        assert!(
            name.chars()
                .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c)),
            "{f:?}"
        );
    }
    let stems = crate::output::file_stems(&NAMES);
    for stem in &stems[..2] {
        for kind in ["tip", "twist"] {
            assert!(files.contains(&PathBuf::from(format!("plots/response_{stem}_{kind}.png"))));
        }
    }
    assert!(files.contains(&PathBuf::from(format!(
        "plots/response_{}_tip.svg",
        stems[2]
    ))));

    // response.csv: the header reads back as exactly the column names, every row as wide.
    let rows = csv_rows(&out.join("response.csv"));
    let mut want = vec!["t [s]".to_string(), "t_after_latch [s]".to_string()];
    want.extend(
        r.channels
            .iter()
            .map(|c| format!("{} [{}]", c.name, c.unit)),
    );
    want.extend(
        r.modal
            .modes
            .iter()
            .map(|m| format!("eta_{} [√kg·m]", m.number)),
    );
    assert_eq!(rows[0], want);
    assert!(rows[0].iter().any(|c| c.starts_with("a,b\"q_tip")));
    assert_eq!(rows.len(), r.history.times.len() + 1);
    assert!(rows.iter().all(|row| row.len() == want.len()));

    // frequencies.csv names every component's strain-energy share; the coefficient and
    // shape tables carry the names as one field.
    let freq = csv_rows(&out.join("frequencies.csv"));
    for n in &NAMES[..3] {
        assert!(
            freq[0].contains(&format!("strain energy share {n} [-]")),
            "{n}"
        );
    }
    assert!(freq.iter().all(|row| row.len() == freq[0].len()));
    let first_elastic = sim.modes.modes.iter().find(|m| !m.rigid).unwrap().number;
    for table in ["coefficients", "shapes"] {
        let rows = csv_rows(&out.join(format!("{table}/mode_{first_elastic:03}.csv")));
        let comps: std::collections::BTreeSet<&str> =
            rows[1..].iter().map(|r| r[0].as_str()).collect();
        for n in &NAMES[..3] {
            assert!(comps.contains(n), "{table}: {n} in {comps:?}");
        }
        assert!(rows.iter().all(|row| row.len() == rows[0].len()));
    }

    // report.html: the embedded JSON cannot change the parser's state, parses, and carries
    // the names; every <script> element is closed where it should be.
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let blocks = json_blocks(&html);
    assert!(blocks.len() >= 9, "{} JSON blocks", blocks.len());
    let mut labels = String::new();
    for b in &blocks {
        for bad in ["<!--", "</", "<script", "<"] {
            assert!(!b.contains(bad), "{bad} in an embedded JSON block");
        }
        let v: serde_json::Value = serde_json::from_str(b).unwrap();
        labels.push_str(&v.to_string());
    }
    assert!(
        labels.contains("<!--<script> tip corner"),
        "the plate's label survives as data"
    );
    assert_eq!(
        html.matches("<script").count(),
        html.matches("</script>").count(),
        "unbalanced <script> elements"
    );
    assert_eq!(html.matches("<script>").count(), 1, "one executable script");
    assert!(!html.contains("<!--"));
    assert!(html.contains("&lt;!--&lt;script&gt;"));
    let _ = std::fs::remove_dir_all(&root);
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
    assert!(n > 5 * crate::output::figures::PLOT_POINTS, "{n} rows");
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
            assert!(x.len() <= crate::output::figures::PLOT_POINTS && x.len() == y.len());
            let xs: Vec<f64> = x.iter().map(|v| v.as_f64().unwrap()).collect();
            assert!(xs.windows(2).all(|w| w[0] <= w[1]), "x not monotone");
            // A response channel's largest sampled |value| is in the plotted data (the
            // closed-form peak of summary.json may lie between samples).
            let name = sr["name"].as_str().unwrap();
            if let Some(c) = r.channels.iter().position(|c| c.label == name) {
                let peak = r.history.sampled_peak(c).0;
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

#[test]
fn engineering_notation_uses_si_prefixes_and_four_digits() {
    use super::engineering;
    assert_eq!(engineering(8.6954e4, "Pa"), "86.95 kPa");
    assert_eq!(engineering(1049.3, "N·m"), "1.049 kN·m");
    assert_eq!(engineering(2.5e-5, "m"), "25.00 µm");
    assert_eq!(engineering(-3.3e8, "Pa"), "-330.0 MPa");
    assert_eq!(engineering(999.96, "Pa"), "1.000 kPa");
    assert_eq!(engineering(0.0, "Pa"), "0 Pa");
    assert_eq!(engineering(f64::NAN, "Pa"), "–");
    assert_eq!(engineering(7.0, "N"), "7.000 N");
    assert_eq!(engineering(2e15, "Pa"), "2000 TPa");
    assert_eq!(engineering(9.9996, "Pa"), "10.00 Pa");
    assert_eq!(engineering(99.996, "Pa"), "100.0 Pa");
    assert_eq!(engineering(1e-7, "Pa"), "100.0 nPa");
}
