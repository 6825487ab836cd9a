//! The pictures (PNG rendered from SVG): on every figure of the seed's `simulate` and of the
//! free-hub example's `simulate` and `modes`, no axis repeats a tick label (read from the SVG source), every
//! trace is one unbroken polyline, and every PNG is the size of its SVG and not blank.

use super::common::{bin, example, scratch};
use std::collections::BTreeMap;
use std::path::Path;

/// (x, y, text-anchor, content) of every <text> element.
fn texts(svg: &str) -> Vec<(String, String, String, String)> {
    let attr = |tag: &str, name: &str| {
        let key = format!(" {name}=\"");
        tag.find(&key).map_or(String::new(), |i| {
            let rest = &tag[i + key.len()..];
            rest[..rest.find('"').unwrap_or(0)].to_string()
        })
    };
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find("<text") {
        rest = &rest[i..];
        let end_tag = rest.find('>').expect("a closed tag");
        let tag = &rest[..end_tag];
        let close = rest.find("</text>").expect("a closed text");
        let content = rest[end_tag + 1..close].trim().to_string();
        out.push((
            attr(tag, "x"),
            attr(tag, "y"),
            attr(tag, "text-anchor"),
            content,
        ));
        rest = &rest[close..];
    }
    out
}

/// Tick labels of one axis: right-aligned texts at one x (y axis); centred texts at one y
/// with at least three members (x axis), split where the value stops increasing from left
/// to right (side-by-side charts put their x axes at one height).
fn repeated_ticks(svg: &str) -> Vec<String> {
    let mut axes: BTreeMap<(String, String), Vec<(f64, String)>> = BTreeMap::new();
    for (x, y, anchor, content) in texts(svg) {
        let at = |v: &str| v.parse::<f64>().unwrap_or(0.0);
        match anchor.as_str() {
            "end" => axes
                .entry(("y at x".into(), x.clone()))
                .or_default()
                .push((at(&y), content)),
            "middle" => axes
                .entry(("x at y".into(), y))
                .or_default()
                .push((at(&x), content)),
            _ => {}
        }
    }
    let mut bad = Vec::new();
    for ((kind, at), mut labels) in axes.into_iter().filter(|(_, l)| l.len() >= 3) {
        labels.sort_by(|a, b| a.0.total_cmp(&b.0));
        let value = |l: &str| l.replace('−', "-").parse::<f64>().ok();
        let mut groups: Vec<Vec<String>> = vec![Vec::new()];
        for (i, (_, l)) in labels.iter().enumerate() {
            let restart = kind.starts_with('x')
                && i > 0
                && matches!(
                    (value(&labels[i - 1].1), value(l)),
                    (Some(a), Some(b)) if b < a
                );
            if restart {
                groups.push(Vec::new());
            }
            groups.last_mut().expect("one group").push(l.clone());
        }
        for g in groups {
            let mut seen = std::collections::BTreeSet::new();
            for l in &g {
                if !seen.insert(l) {
                    bad.push(format!("{kind} {at}: {l:?} repeated in {g:?}"));
                }
            }
        }
    }
    bad
}

fn check_dir(plots: &Path) -> usize {
    let mut checked = 0;
    let mut names: Vec<_> = std::fs::read_dir(plots)
        .expect("plots/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    names.sort();
    for svg_path in names {
        let svg = std::fs::read_to_string(&svg_path).expect("svg");
        let bad = repeated_ticks(&svg);
        assert!(bad.is_empty(), "{}: {bad:?}", svg_path.display());
        // One polyline per trace: the legend draws each trace's sample (3 px wide) once.
        let traces = svg.matches("stroke-width=\"2\" points=").count();
        let legend = svg.matches("stroke-width=\"3\" points=").count();
        if legend > 0 {
            assert_eq!(
                traces,
                legend,
                "{}: {traces} trace polylines for {legend} legend entries",
                svg_path.display()
            );
        }
        let png = svg_path.with_extension("png");
        let pixmap = resvg::tiny_skia::Pixmap::load_png(&png).expect("a PNG beside the SVG");
        let (w, h) = (pixmap.width(), pixmap.height());
        assert!(
            svg.contains(&format!("width=\"{w}\" height=\"{h}\"")),
            "{}: PNG {w}×{h} is not its SVG's size",
            png.display()
        );
        let ink = pixmap
            .pixels()
            .iter()
            .filter(|p| p.red() < 200 || p.green() < 200 || p.blue() < 200)
            .count();
        assert!(ink > 500, "{}: blank ({ink} dark pixels)", png.display());
        checked += 1;
    }
    checked
}

/// Runs `flexcraft <command> <example> --out <scratch>` and returns the output folder.
fn run(command: &str, example_name: &str, tag: &str) -> std::path::PathBuf {
    let dir = scratch(tag);
    let out = bin()
        .arg(command)
        .arg(example(example_name))
        .arg("--out")
        .arg(&dir)
        .output()
        .expect("run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

#[test]
fn plots_have_distinct_ticks_unbroken_traces_and_matching_pngs() {
    let n = check_dir(&run("simulate", "seed.toml", "plots_seed").join("plots"));
    assert!(n >= 15, "{n} figures");
    let n = check_dir(&run("simulate", "free_hub.toml", "plots_free_hub").join("plots"));
    assert!(n >= 10, "{n} figures");
    let n = check_dir(&run("modes", "free_hub.toml", "plots_free_hub_modes").join("plots"));
    assert!(n >= 6, "{n} figures");
}

#[test]
fn repeated_ticks_are_detected() {
    // The detector itself: three right-aligned labels at one x, two equal.
    let svg = r#"<text x="80" y="10" text-anchor="end">
0.0
</text><text x="80" y="20" text-anchor="end">
0.0
</text><text x="80" y="30" text-anchor="end">
0.1
</text>"#;
    assert_eq!(repeated_ticks(svg).len(), 1);
}
