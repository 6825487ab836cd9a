//! The HTML report (issue 5): structure, self-containment, numbers equal to summary.json,
//! and (ignored by default, run by .ci/run) a real headless browser.

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexcraft"))
}

fn simulate(example: &str, tag: &str) -> (PathBuf, PathBuf) {
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(example);
    let out = std::env::temp_dir().join(format!("flexcraft-report-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let r = bin()
        .arg("simulate")
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    (scenario, out)
}

/// Every `<script type="application/json">…</script>` block after `marker`.
fn json_blocks<'a>(html: &'a str, marker: &str) -> Vec<&'a str> {
    let open = "<script type=\"application/json\">";
    html.match_indices(marker)
        .filter_map(|(i, _)| {
            let rest = &html[i..];
            let a = rest.find(open)? + open.len();
            let b = rest[a..].find("</script>")?;
            Some(&rest[a..a + b])
        })
        .collect()
}

#[test]
fn report_has_every_section_nonempty_plots_and_the_summary_numbers() {
    for (example, tag) in [("seed.toml", "seed"), ("free_hub.toml", "free")] {
        let (scenario, out) = simulate(example, tag);
        let html = std::fs::read_to_string(out.join("report.html")).unwrap();
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
        for id in ["scenario", "modes", "deployment", "response"] {
            assert!(
                html.contains(&format!("<section id=\"{id}\">")),
                "{example}: {id}"
            );
        }
        for table in ["frequencies", "latches", "handover"] {
            assert!(
                html.contains(&format!("<table id=\"{table}\">")),
                "{example}: {table}"
            );
        }
        // Self-contained: no external resource of any kind.
        for bad in ["src=\"", "<link", "@import", "url(", "https://", "fetch("] {
            assert!(!html.contains(bad), "{example}: {bad}");
        }
        // Footer: version and the scenario's SHA-256.
        let hash: String = Sha256::digest(std::fs::read(&scenario).unwrap())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        assert!(html.contains(&format!("<code id=\"scenario-hash\">{hash}</code>")));
        assert!(html.contains(&format!("flexcraft {}", env!("CARGO_PKG_VERSION"))));
        // Plots: 4 deployment + figures 2.4–2.7 + modal amplitudes, each with data.
        let plots = json_blocks(&html, "<figure class=\"plot\"");
        assert!(plots.len() >= 8, "{example}: {} plots", plots.len());
        for p in &plots {
            let v: serde_json::Value = serde_json::from_str(p).unwrap();
            let series = v["series"].as_array().unwrap();
            assert!(!series.is_empty(), "{example}: empty plot {}", v["title"]);
            for s in series {
                let (x, y) = (s["x"].as_array().unwrap(), s["y"].as_array().unwrap());
                assert!(
                    x.len() >= 2 && x.len() == y.len(),
                    "{example}: {}",
                    v["title"]
                );
                assert!(y.iter().all(|v| v.as_f64().is_some_and(f64::is_finite)));
            }
        }
        // The animation has frames; six mode-shape pictures are inline SVG.
        let anim: serde_json::Value =
            serde_json::from_str(json_blocks(&html, "<div class=\"animation\"")[0]).unwrap();
        assert!(anim["frames"].as_array().unwrap().len() > 10);
        assert_eq!(html.matches("<figure class=\"shape\"").count(), 6);
        // The Bode plot of the default transfer functions (hub torque → attitude about x, y,
        // z for a free hub): one inline SVG, a magnitude and a phase trace per transfer.
        if let Some(at) = html.find("<figure class=\"bode\">") {
            let fig = &html[at..at + html[at..].find("</figure>").unwrap()];
            assert!(fig.contains("hub.tz → hub.rz"), "{example}: Bode legend");
            assert!(
                fig.matches("<polyline").count() >= 6,
                "{example}: Bode traces"
            );
        } else {
            panic!("{example}: no Bode plot");
        }
        // Table numbers equal summary.json's (data-key is a JSON pointer into it).
        let mut checked = 0;
        for (i, _) in html.match_indices("data-key=\"") {
            let rest = &html[i + 10..];
            let key = &rest[..rest.find('"').unwrap()];
            let vpos = rest.find("data-value=\"").unwrap() + 12;
            let value: f64 = rest[vpos..vpos + rest[vpos..].find('"').unwrap()]
                .parse()
                .unwrap();
            let want = summary
                .pointer(key)
                .and_then(|v| v.as_f64())
                .unwrap_or_else(|| panic!("{example}: {key} not in summary.json"));
            assert!(
                (value - want).abs() <= 4.0 * f64::EPSILON * want.abs(),
                "{example}: {key}: report {value}, summary {want}"
            );
            checked += 1;
        }
        assert!(checked >= 20, "{example}: only {checked} numbers checked");
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// Decoded RGBA pixels of a PNG.
fn pixels(path: &Path) -> Vec<u8> {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
        .into_raw()
}

/// Chromium's profile folders of one test, in the temporary directory, removed when the
/// test ends (passed or failed).
#[derive(Default)]
struct Profiles(std::cell::RefCell<Vec<std::path::PathBuf>>);

impl Profiles {
    /// The `--user-data-dir` argument of a fresh profile folder named by `tag`.
    fn arg(&self, tag: &str) -> String {
        let d =
            std::env::temp_dir().join(format!("flexcraft-chromium-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        let arg = format!("--user-data-dir={}", d.display());
        self.0.borrow_mut().push(d);
        arg
    }
}

impl Drop for Profiles {
    fn drop(&mut self) {
        for d in self.0.borrow().iter() {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}

/// Headless Chromium: the page runs without a script error, hovering a chart shows a
/// readout and dragging zooms it, its screenshot is not blank, and the animation's first and
/// last frames differ. Needs `chromium` (.ci/run installs
/// Debian's package): `cargo test --release -- --ignored browser`.
#[test]
#[ignore]
fn browser_renders_the_report_without_errors_and_animates() {
    let chromium = ["chromium", "chromium-browser"]
        .into_iter()
        .find(|c| Command::new(c).arg("--version").output().is_ok())
        .expect("chromium not found: .ci/run installs Debian's chromium");
    let (_, out) = simulate("seed.toml", "browser");
    let page = format!("file://{}", out.join("report.html").display());
    let profiles = Profiles::default();
    let profile = |tag: &str| profiles.arg(tag);
    let base = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
    ];
    let dom = Command::new(chromium)
        .args(base)
        .arg(profile("dom"))
        .arg("--dump-dom")
        .arg(&page)
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&dom.stdout);
    assert!(
        dom.contains("data-status=\"ok\""),
        "script error or no run: {}",
        dom.find("data-status")
            .map_or("no status", |i| &dom[i..i + 80])
    );
    // The page's own #selftest, with synthetic mouse events: hover and drag-zoom a chart; no
    // axis of any chart repeats a tick label and no tick or table number is rounding noise
    // shown as non-zero; the 3-D view draws frame 0 and the last frame (non-blank, different),
    // rotating changes the picture, and a picked mode is drawn and moves. On the seed, the
    // staged route and the free-hub example.
    for example in ["seed.toml", "seed_staged.toml", "free_hub.toml"] {
        let (_, dir) = simulate(example, &format!("selftest-{example}"));
        let dom = Command::new(chromium)
            .args(base)
            .arg(profile(&format!("selftest-{example}")))
            .arg("--window-size=1280,1600")
            .arg("--dump-dom")
            .arg(format!(
                "file://{}#selftest",
                dir.join("report.html").display()
            ))
            .output()
            .unwrap();
        let dom = String::from_utf8_lossy(&dom.stdout);
        for key in ["data-status", "data-selftest", "data-view3d"] {
            assert!(
                dom.contains(&format!("{key}=\"ok\"")),
                "{example}: {key}: {}",
                dom.find(key)
                    .map_or("not run", |i| &dom[i..(i + 120).min(dom.len())])
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let mut shots = Vec::new();
    for frame in ["0", "last"] {
        let png = out.join(format!("shot-{frame}.png"));
        let r = Command::new(chromium)
            .args(base)
            .arg(profile(frame))
            .arg("--window-size=1280,12000")
            .arg(format!("--screenshot={}", png.display()))
            .arg(format!("{page}#frame={frame}"))
            .output()
            .unwrap();
        assert!(png.exists(), "{}", String::from_utf8_lossy(&r.stderr));
        let px = pixels(&png);
        // Not blank: a real page has many colours and plenty of non-white pixels.
        let non_white = px
            .chunks(4)
            .filter(|p| p[0] < 240 || p[1] < 240 || p[2] < 240)
            .count();
        assert!(
            non_white > px.len() / 4 / 100,
            "screenshot {frame} is blank"
        );
        shots.push(px);
    }
    assert!(
        shots[0] != shots[1],
        "the animation's first and last frames look the same"
    );
    let _ = std::fs::remove_dir_all(&out);
}
