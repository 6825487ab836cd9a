//! Pictures (PNG and SVG) drawn with plotters and a bundled font (DejaVu Sans), so that the
//! output does not depend on the machine's fonts.

use super::{OutputDir, OutputError};
use crate::ritz::{Mode, RitzModel};
use crate::structure::ComponentId;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

/// Draws one picture into `<stem>.png` and `<stem>.svg` of the output directory: the body
/// runs once per back end with `$root` bound to its drawing area.
macro_rules! png_and_svg {
    ($dir:expr, $stem:expr, $size:expr, |$root:ident| $body:expr) => {{
        for ext in ["png", "svg"] {
            let rel = format!("{}.{ext}", $stem);
            let path = $dir.path(&rel)?;
            let r = if ext == "png" {
                let $root = BitMapBackend::new(&path, $size).into_drawing_area();
                $body
            } else {
                let $root = SVGBackend::new(&path, $size).into_drawing_area();
                $body
            };
            r.map_err(|reason| OutputError::Plot { file: rel, reason })?;
        }
    }};
}

static FONT: Once = Once::new();

/// Registers the bundled font as "sans-serif" (once per process).
pub fn register_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/DejaVuSans.ttf");
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, bytes);
    });
}

type Lines = Vec<Vec<(f64, f64, f64)>>;

/// Undeformed and deformed polylines of every elastic component.
fn polylines(model: &RitzModel, q: &[f64]) -> (Lines, Lines) {
    let mut undeformed = Vec::new();
    let mut deformed = Vec::new();
    let samples = super::modes::sample_all(model, q);
    let max_disp = samples
        .iter()
        .flat_map(|(_, _, s)| s.iter().map(|p| p.displacement.norm()))
        .fold(0.0, f64::max);
    let extent = samples
        .iter()
        .flat_map(|(_, _, s)| s.iter().map(|p| p.position.norm()))
        .fold(1.0, f64::max);
    let scale = if max_disp > 0.0 {
        0.12 * extent / max_disp
    } else {
        0.0
    };
    for (_, id, s) in &samples {
        let pos = |p: &crate::ritz::shapes::PointSample| {
            (p.position.0[0], p.position.0[1], p.position.0[2])
        };
        let def = |p: &crate::ritz::shapes::PointSample| {
            let r = p.position + p.displacement * scale;
            (r.0[0], r.0[1], r.0[2])
        };
        match id {
            ComponentId::Plate(_) => {
                // Grid 31 × 9, row-major in x: lines along x and along y.
                let (nx, ny) = (31, 9);
                for j in 0..ny {
                    undeformed.push((0..nx).map(|i| pos(&s[i * ny + j])).collect());
                    deformed.push((0..nx).map(|i| def(&s[i * ny + j])).collect());
                }
                for i in (0..nx).step_by(3) {
                    undeformed.push((0..ny).map(|j| pos(&s[i * ny + j])).collect());
                    deformed.push((0..ny).map(|j| def(&s[i * ny + j])).collect());
                }
            }
            _ => {
                undeformed.push(s.iter().map(pos).collect());
                deformed.push(s.iter().map(def).collect());
            }
        }
    }
    (undeformed, deformed)
}

fn draw_view<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    axes: (usize, usize),
    labels: (&str, &str),
    und: &Lines,
    def: &Lines,
) -> Result<(), String> {
    let all = und.iter().chain(def.iter()).flatten();
    let pick = |p: &(f64, f64, f64), i: usize| [p.0, p.1, p.2][i];
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in all {
        x0 = x0.min(pick(p, axes.0));
        x1 = x1.max(pick(p, axes.0));
        y0 = y0.min(pick(p, axes.1));
        y1 = y1.max(pick(p, axes.1));
    }
    // Equal scales on both axes (the drawing areas are square).
    let span = (x1 - x0).max(y1 - y0).max(1e-9) * 1.1;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(48)
        .build_cartesian_2d(
            cx - span / 2.0..cx + span / 2.0,
            cy - span / 2.0..cy + span / 2.0,
        )
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(labels.0)
        .y_desc(labels.1)
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    for l in und {
        chart
            .draw_series(LineSeries::new(
                l.iter().map(|p| (pick(p, axes.0), pick(p, axes.1))),
                RGBColor(170, 170, 170),
            ))
            .map_err(|e| e.to_string())?;
    }
    for l in def {
        chart
            .draw_series(LineSeries::new(
                l.iter().map(|p| (pick(p, axes.0), pick(p, axes.1))),
                RGBColor(20, 90, 200).stroke_width(2),
            ))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

fn draw_mode<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    model: &RitzModel,
    mode: &Mode,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let kind = if mode.rigid { "rigid" } else { "elastic" };
    let title = format!(
        "mode {} ({kind}), f = {:.6} Hz, dominant: {}",
        mode.number,
        mode.frequency_hz(),
        mode.dominant()
    );
    let root = root
        .titled(&title, ("sans-serif", 22))
        .map_err(|e| e.to_string())?;
    let (und, def) = polylines(model, &mode.shape);
    let (a, b) = root.split_horizontally(root.dim_in_pixel().0 / 2);
    draw_view(
        &a,
        "side view (x–z), grey: undeformed",
        (0, 2),
        ("x [m]", "z [m]"),
        &und,
        &def,
    )?;
    draw_view(
        &b,
        "top view (x–y), blue: deformed (exaggerated)",
        (0, 1),
        ("x [m]", "y [m]"),
        &und,
        &def,
    )?;
    root.present().map_err(|e| e.to_string())
}

/// plots/mode_NNN.png and .svg: two orthogonal views of the undeformed (grey) and deformed
/// (blue, exaggerated) structure.
pub fn mode_shape(dir: &mut OutputDir, model: &RitzModel, mode: &Mode) -> Result<(), OutputError> {
    register_font();
    let stem = format!("plots/mode_{:03}", mode.number);
    png_and_svg!(dir, stem, (1200, 640), |root| draw_mode(root, model, mode));
    Ok(())
}

/// The same picture as [`mode_shape`], as an SVG document in a string (for the HTML report).
pub fn mode_shape_svg(model: &RitzModel, mode: &Mode) -> Result<String, OutputError> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1200, 640)).into_drawing_area();
        draw_mode(root, model, mode).map_err(|reason| OutputError::Plot {
            file: format!("report: mode {}", mode.number),
            reason,
        })?;
    }
    Ok(svg)
}

/// A named polyline for [`line_chart`].
pub type Series = (String, Vec<(f64, f64)>);

const PALETTE: [RGBColor; 8] = [
    RGBColor(20, 90, 200),
    RGBColor(220, 60, 40),
    RGBColor(30, 150, 70),
    RGBColor(150, 60, 180),
    RGBColor(230, 140, 20),
    RGBColor(20, 160, 170),
    RGBColor(120, 120, 120),
    RGBColor(180, 40, 120),
];

fn draw_chart<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    labels: (&str, &str),
    series: &[Series],
    equal_aspect: bool,
    markers: &[f64],
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let pts = series.iter().flat_map(|s| s.1.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in pts {
        if x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    if x1 - x0 < 1e-12 {
        x1 = x0 + 1.0;
    }
    if y1 - y0 < 1e-12 * (y0.abs() + y1.abs()).max(1e-30) {
        let c = 0.5 * (y0 + y1);
        let d = (c.abs() * 0.1).max(1e-9);
        (y0, y1) = (c - d, c + d);
    }
    if equal_aspect {
        let (w, h) = root.dim_in_pixel();
        let span = ((x1 - x0) / w as f64).max((y1 - y0) / h as f64);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        (x0, x1) = (cx - 0.5 * span * w as f64, cx + 0.5 * span * w as f64);
        (y0, y1) = (cy - 0.5 * span * h as f64, cy + 0.5 * span * h as f64);
    }
    let pad = 0.04 * (y1 - y0);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(labels.0)
        .y_desc(labels.1)
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    // Event markers (latches): thin grey vertical lines across the plot.
    for &m in markers.iter().filter(|m| (x0..=x1).contains(*m)) {
        chart
            .draw_series(LineSeries::new(
                [(m, y0 - pad), (m, y1 + pad)],
                BLACK.mix(0.35).stroke_width(1),
            ))
            .map_err(|e| e.to_string())?;
    }
    for (i, (name, pts)) in series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let drawn = chart
            .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))
            .map_err(|e| e.to_string())?;
        if !name.is_empty() {
            drawn.label(name.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
            });
        }
    }
    if series.iter().any(|s| !s.0.is_empty()) && series.len() <= 12 {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

/// plots/STEM.png and .svg: a line chart of the given series (equal axis scales on request).
pub fn line_chart(
    dir: &mut OutputDir,
    stem: &str,
    title: &str,
    labels: (&str, &str),
    series: &[Series],
    equal_aspect: bool,
) -> Result<(), OutputError> {
    line_chart_marked(dir, stem, title, labels, series, equal_aspect, &[])
}

/// [`line_chart`] with vertical event markers at the given x values.
pub fn line_chart_marked(
    dir: &mut OutputDir,
    stem: &str,
    title: &str,
    labels: (&str, &str),
    series: &[Series],
    equal_aspect: bool,
    markers: &[f64],
) -> Result<(), OutputError> {
    register_font();
    png_and_svg!(
        dir,
        format!("plots/{stem}"),
        (1000, 600),
        |root| draw_chart(root, title, labels, series, equal_aspect, markers)
    );
    Ok(())
}
