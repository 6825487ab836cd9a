//! Pictures (PNG and SVG) drawn with plotters and a bundled font (DejaVu Sans), so that the
//! output does not depend on the machine's fonts.

use super::{OutputDir, OutputError};
use crate::ritz::{Mode, RitzModel};
use crate::structure::ComponentId;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

/// Draws one picture as SVG into `<stem>.svg` of the output directory and rasterises it
/// into `<stem>.png` ([`super::raster`]): the body runs once with `$root` bound to the SVG
/// drawing area.
macro_rules! png_and_svg {
    ($dir:expr, $stem:expr, $size:expr, |$root:ident| $body:expr) => {{
        let stem = $stem;
        let mut svg = String::new();
        {
            let $root = SVGBackend::with_string(&mut svg, $size).into_drawing_area();
            let r: Result<(), String> = $body;
            r.map_err(|reason| OutputError::Plot {
                file: format!("{stem}.svg"),
                reason,
            })?;
        }
        let png = super::raster::svg_to_png(&svg).map_err(|reason| OutputError::Plot {
            file: format!("{stem}.png"),
            reason,
        })?;
        $dir.write(&format!("{stem}.svg"), svg.as_bytes())?;
        $dir.write(&format!("{stem}.png"), png)?;
    }};
}

static FONT: Once = Once::new();

/// Registers the bundled font as "sans-serif" (once per process).
pub fn register_font() {
    FONT.call_once(|| {
        let _ =
            plotters::style::register_font("sans-serif", FontStyle::Normal, super::raster::FONT);
    });
}

type Lines = Vec<Vec<(f64, f64, f64)>>;

/// Undeformed and deformed polylines of every elastic component, and the exaggeration factor
/// (the largest displacement drawn as 12 % of the structure's extent).
fn polylines(model: &RitzModel, q: &[f64]) -> (Lines, Lines, f64) {
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
    (undeformed, deformed, scale)
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
        .caption(title, ("sans-serif", 17))
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
        .x_label_formatter(&|v| tick_label(*v, span))
        .y_label_formatter(&|v| tick_label(*v, span))
        .label_style(("sans-serif", 14))
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
    let (und, def, scale) = polylines(model, &mode.shape);
    let title = format!("{title}; deflection ×{scale:.3e} (mass-normalised shape)");
    let root = root
        .titled(&title, ("sans-serif", 22))
        .map_err(|e| e.to_string())?;
    // The two views that show the most of the deflection: drop the axis it moves least
    // along, then the next one.
    let mut motion = [0.0_f64; 3];
    for (u, d) in und.iter().zip(&def) {
        for (a, b) in u.iter().zip(d) {
            motion[0] += (b.0 - a.0).abs();
            motion[1] += (b.1 - a.1).abs();
            motion[2] += (b.2 - a.2).abs();
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| motion[i].total_cmp(&motion[j]));
    let names = ["x", "y", "z"];
    let plane = |dropped: usize| -> (usize, usize) {
        match dropped {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        }
    };
    let (a, b) = root.split_horizontally(root.dim_in_pixel().0 / 2);
    for (area, dropped, what) in [
        (&a, order[0], "grey: undeformed"),
        (&b, order[1], "blue: deformed"),
    ] {
        let (h, v) = plane(dropped);
        let labels = (format!("{} [m]", names[h]), format!("{} [m]", names[v]));
        draw_view(
            area,
            &format!(
                "view along {} ({}–{}), {what}",
                names[dropped], names[h], names[v]
            ),
            (h, v),
            (&labels.0, &labels.1),
            &und,
            &def,
        )?;
    }
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

const PALETTE: [RGBColor; 10] = [
    RGBColor(20, 90, 200),
    RGBColor(220, 60, 40),
    RGBColor(30, 150, 70),
    RGBColor(150, 60, 180),
    RGBColor(230, 140, 20),
    RGBColor(20, 160, 170),
    RGBColor(120, 120, 120),
    RGBColor(180, 40, 120),
    RGBColor(120, 80, 30),
    RGBColor(0, 0, 0),
];

/// SI prefixes for the y axis: (factor, prefix).
const PREFIXES: [(f64, &str); 8] = [
    (1e-12, "p"),
    (1e-9, "n"),
    (1e-6, "µ"),
    (1e-3, "m"),
    (1.0, ""),
    (1e3, "k"),
    (1e6, "M"),
    (1e9, "G"),
];

/// Units a prefix may go in front of.
const PREFIXABLE: [&str; 8] = ["m", "rad", "N", "N·m", "J", "N·s", "m/s", "rad/s"];

/// The factor the y values are divided by and the axis label that says so: an SI prefix on
/// the label's unit ("deflection [µm]") when it takes one, else a shared power of ten
/// ("η [×1e-6 √kg·m]"); the scaled values' largest magnitude lies in [1, 1000).
pub fn axis_scale(largest: f64, label: &str) -> (f64, String) {
    if !(largest.is_finite() && largest > 0.0) || (1e-2..1e4).contains(&largest) {
        return (1.0, label.to_string());
    }
    let exp3 = (largest.log10() / 3.0).floor() as i32 * 3;
    let factor = 10f64.powi(exp3);
    let Some(open) = label.rfind('[') else {
        return (factor, format!("{label} [×1e{exp3}]"));
    };
    let unit = label[open + 1..].trim_end_matches(']');
    let prefix = PREFIXES
        .iter()
        .find(|(f, _)| (*f / factor - 1.0).abs() < 1e-9);
    match prefix {
        Some((_, p)) if PREFIXABLE.contains(&unit) => {
            (factor, format!("{}[{p}{unit}]", &label[..open]))
        }
        _ => (factor, format!("{}[×1e{exp3} {unit}]", &label[..open])),
    }
}

/// Tick label of v on an axis spanning `range`: as many decimals as the tick spacing (about
/// a tenth of the range) needs, and never "-0".
pub fn tick_label(v: f64, range: f64) -> String {
    let step = (range / 12.0).abs().max(1e-300);
    let decimals = (-step.log10()).ceil().clamp(0.0, 9.0) as usize;
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        "0".to_string()
    } else {
        s
    }
}

/// The data's x and y ranges (finite points; a unit range when there are none, a padded one
/// when flat).
fn bounds(series: &[Series]) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in series.iter().flat_map(|s| s.1.iter()) {
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
        // A flat trace (identically zero, or constant): a unit span around it.
        let c = 0.5 * (y0 + y1);
        let d = if c == 0.0 { 1.0 } else { c.abs() * 0.1 };
        (y0, y1) = (c - d, c + d);
    }
    (x0, x1, y0, y1)
}

/// The legend in its own area beside the plot: a line of each trace's colour and its name,
/// and how many more traces there are when not all are listed.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    named: &[(usize, &String)],
    more: usize,
) -> Result<(), String> {
    let top = 40;
    let font = || ("sans-serif", 13).into_font().color(&BLACK);
    for (row, (i, name)) in named.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let y = top + 22 * row as i32;
        area.draw(&PathElement::new(
            vec![(4, y), (28, y)],
            color.stroke_width(3),
        ))
        .map_err(|e| e.to_string())?;
        area.draw(&Text::new(name.to_string(), (34, y - 8), font()))
            .map_err(|e| e.to_string())?;
    }
    if more > 0 {
        area.draw(&Text::new(
            format!("(+{more} more)"),
            (34, top + 22 * named.len() as i32 - 8),
            font(),
        ))
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// The caption's font size (px) that fits `title` in `width` px: 20 px, smaller for a long
/// title (a sans-serif glyph is ~0.55 of the size wide on average), never below 10 px.
fn caption_size(title: &str, width: u32) -> u32 {
    let chars = title.chars().count().max(1) as f64;
    let fit = (width.saturating_sub(24) as f64 / (0.55 * chars)).floor();
    (fit as u32).clamp(10, 20)
}

fn draw_chart<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    labels: (&str, &str),
    series: &[Series],
    equal_aspect: bool,
    markers: &[f64],
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let largest = series
        .iter()
        .flat_map(|s| s.1.iter())
        .filter(|p| p.1.is_finite())
        .fold(0.0_f64, |a, p| a.max(p.1.abs()));
    let (factor, ylabel) = if equal_aspect {
        (1.0, labels.1.to_string())
    } else {
        axis_scale(largest, labels.1)
    };
    let series: Vec<Series> = series
        .iter()
        .map(|(n, p)| (n.clone(), p.iter().map(|&(x, y)| (x, y / factor)).collect()))
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = bounds(&series);
    // The legend sits beside the plot, never on the data.
    let named: Vec<(usize, &String)> = series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.0.is_empty())
        .map(|(i, s)| (i, &s.0))
        .take(12)
        .collect();
    let (w, h) = root.dim_in_pixel();
    let legend_w = if named.is_empty() {
        0
    } else {
        let longest = named
            .iter()
            .map(|(_, n)| n.chars().count())
            .max()
            .unwrap_or(0);
        ((longest as u32) * 7 + 44).clamp(120, w / 3)
    };
    let (plot_area, legend_area) = root.split_horizontally(w - legend_w);
    if equal_aspect {
        let pw = w - legend_w;
        let span = ((x1 - x0) / pw as f64).max((y1 - y0) / h as f64);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        (x0, x1) = (cx - 0.5 * span * pw as f64, cx + 0.5 * span * pw as f64);
        (y0, y1) = (cy - 0.5 * span * h as f64, cy + 0.5 * span * h as f64);
    }
    let pad = 0.04 * (y1 - y0);
    let (ya, yb) = (y0 - pad, y1 + pad);
    let (xr, yr) = (x1 - x0, yb - ya);
    let mut chart = ChartBuilder::on(&plot_area)
        .caption(title, ("sans-serif", caption_size(title, w - legend_w)))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(76)
        .build_cartesian_2d(x0..x1, ya..yb)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(labels.0)
        .y_desc(ylabel.as_str())
        .x_label_formatter(&|v| tick_label(*v, xr))
        .y_label_formatter(&|v| tick_label(*v, yr))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(|e| e.to_string())?;
    // Event markers (latches, captures): thin grey vertical lines across the plot.
    for &m in markers.iter().filter(|m| (x0..=x1).contains(*m)) {
        chart
            .draw_series(LineSeries::new(
                [(m, ya), (m, yb)],
                BLACK.mix(0.35).stroke_width(1),
            ))
            .map_err(|e| e.to_string())?;
    }
    for (i, (_, pts)) in series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))
            .map_err(|e| e.to_string())?;
    }
    let more = series.iter().filter(|s| !s.0.is_empty()).count() - named.len();
    draw_legend(&legend_area, &named, more)?;
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

/// A tick label of a logarithmic axis: a plain decimal between 10⁻³ and 10⁴, else
/// scientific.
fn log_tick_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".to_string()
    } else if (1e-3..1e4).contains(&a) {
        let s = format!("{v:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    } else {
        format!("{v:.0e}")
    }
}

/// One Bode curve: its label and H(f) at frequencies f [Hz].
pub type BodeCurve = (String, Vec<(f64, faer::c64)>);

/// plots/STEM.png and .svg: a Bode plot, magnitude (log–log) above phase (degrees, log
/// frequency), one colour per transfer function.
pub fn bode_chart(
    dir: &mut OutputDir,
    stem: &str,
    title: &str,
    curves: &[BodeCurve],
) -> Result<(), OutputError> {
    register_font();
    png_and_svg!(dir, format!("plots/{stem}"), (1000, 800), |root| draw_bode(
        root, title, curves
    ));
    Ok(())
}

/// The Bode plot of [`bode_chart`] as SVG text (for the report).
pub fn bode_svg(title: &str, curves: &[BodeCurve]) -> Result<String, OutputError> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 800)).into_drawing_area();
        draw_bode(root, title, curves).map_err(|reason| OutputError::Plot {
            file: "report: Bode plot".to_string(),
            reason,
        })?;
    }
    Ok(svg)
}

fn draw_bode<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    curves: &[BodeCurve],
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (w, _) = root.dim_in_pixel();
    let legend_w = 300.min(w / 3);
    let (plots, legend) = root.split_horizontally(w - legend_w);
    let (top, bottom) = plots.split_vertically(400);
    let pts = || curves.iter().flat_map(|c| c.1.iter());
    let (mut f0, mut f1, mut m0, mut m1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (f, h) in pts() {
        let m = h.norm();
        if f.is_finite() && *f > 0.0 && m.is_finite() && m > 0.0 {
            (f0, f1) = (f0.min(*f), f1.max(*f));
            (m0, m1) = (m0.min(m), m1.max(m));
        }
    }
    if f0 >= f1 {
        (f0, f1) = (0.1, 10.0);
    }
    if m0 > m1 {
        // No finite, nonzero magnitude (an identically zero transfer: the log axis needs a
        // range of its own; f64::MAX · 2 would make it infinite and plotters' ticks endless).
        (m0, m1) = (0.5, 2.0);
    } else if m0 == m1 {
        (m0, m1) = (m0 * 0.5, m0 * 2.0);
    }
    // Magnitudes near the ends of the floating-point range keep the axis finite.
    m0 = m0.clamp(1e-290, 1e289);
    m1 = m1.clamp(2.0 * m0, 1e290);
    let mut mag = ChartBuilder::on(&top)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(76)
        .build_cartesian_2d((f0..f1).log_scale(), (m0 / 1.5..m1 * 1.5).log_scale())
        .map_err(|e| e.to_string())?;
    mag.configure_mesh()
        .y_desc("|H| (output unit / input unit)")
        .x_label_formatter(&|v| log_tick_label(*v))
        .y_label_formatter(&|v| log_tick_label(*v))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(|e| e.to_string())?;
    let mut phase = ChartBuilder::on(&bottom)
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(76)
        .build_cartesian_2d((f0..f1).log_scale(), -190.0..190.0)
        .map_err(|e| e.to_string())?;
    phase
        .configure_mesh()
        .x_desc("frequency [Hz]")
        .y_desc("phase [deg]")
        .x_label_formatter(&|v| log_tick_label(*v))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .y_labels(9)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(|e| e.to_string())?;
    for (i, (_, c)) in curves.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let good = c.iter().filter(|(f, h)| *f > 0.0 && h.norm() > 0.0);
        mag.draw_series(LineSeries::new(
            good.clone().map(|(f, h)| (*f, h.norm())),
            color.stroke_width(2),
        ))
        .map_err(|e| e.to_string())?;
        // Phase wrapped to (−180°, 180°]: a jump of the wrap starts a new segment.
        let mut seg: Vec<(f64, f64)> = Vec::new();
        for (f, h) in good {
            let p = h.arg().to_degrees();
            if seg.last().is_some_and(|l| (l.1 - p).abs() > 180.0) {
                phase
                    .draw_series(LineSeries::new(seg.drain(..), color.stroke_width(2)))
                    .map_err(|e| e.to_string())?;
            }
            seg.push((*f, p));
        }
        phase
            .draw_series(LineSeries::new(seg, color.stroke_width(2)))
            .map_err(|e| e.to_string())?;
    }
    let named: Vec<(usize, &String)> = curves.iter().map(|c| &c.0).enumerate().take(12).collect();
    draw_legend(&legend, &named, curves.len() - named.len())?;
    root.present().map_err(|e| e.to_string())
}
