//! `report.html`: one self-contained page (inline style, script, data and pictures; no
//! network) with the scenario, the modes, the deployment and the response. Plots are drawn
//! in the browser by a small inline script (`assets/report.js`: hover to read a value, drag
//! to zoom a time window, double-click to reset) from data embedded as JSON; the mode shapes
//! are the same SVG pictures as `plots/mode_NNN.svg`. Nothing time-dependent is written, so
//! the page is byte-identical across runs.
//!
//! Every table number that is also in summary.json carries `data-key` (a JSON pointer into
//! summary.json) and `data-value` (the full-precision value), which the tests compare.

use super::figures::Figure;
use super::names::{html as esc, script_json as embed};
use super::plot::mode_shape_svg;
use super::OutputError;
use crate::deploy::chain::PlanarHub;
use crate::math::Vec3;
use crate::scenario::Scenario;
use crate::simulation::Simulation;
use crate::structure::{HubMotion, Structure};
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::fmt::Write;

const SCRIPT: &str = include_str!("../../assets/report.js");
const STYLE: &str = include_str!("../../assets/report.css");
/// The frames-and-signs figure (also docs/frames.svg).
const FRAMES: &str = include_str!("../../docs/frames.svg");
/// Most frames in the deployment animation (every example has fewer samples than this).
const ANIMATION_FRAMES: usize = 4000;

/// A table cell with a value that summary.json also holds.
fn keyed(key: &str, v: f64, shown: String) -> String {
    format!("<td data-key=\"{key}\" data-value=\"{v:e}\">{shown}</td>")
}

/// Seven significant digits keep the embedded plot data compact.
fn round7(v: f64) -> f64 {
    if v.is_finite() {
        format!("{v:.6e}").parse().unwrap_or(v)
    } else {
        0.0
    }
}

/// An interactive chart of a figure (data rounded to 7 significant digits).
fn plot(f: &Figure) -> String {
    let s: Vec<Value> = f
        .curves
        .iter()
        .map(|(name, x, y)| {
            json!({"name": name, "x": x.iter().copied().map(round7).collect::<Vec<_>>(),
                   "y": y.iter().copied().map(round7).collect::<Vec<_>>()})
        })
        .collect();
    let spec = json!({"title": f.title, "xlabel": f.xlabel, "ylabel": f.ylabel, "series": s,
                      "markers": f.markers.iter().copied().map(round7).collect::<Vec<_>>()});
    format!(
        "<figure class=\"plot\" data-title=\"{}\"><script type=\"application/json\">{}</script></figure>\n",
        esc(&f.title),
        embed(&spec)
    )
}

/// Two orthogonal views (x–z and x–y) of the deployed structure, labelled.
/// Points on the hub's surface: its cylinder's two end circles, or its equivalent box's
/// corners (uniform box with the hub's principal moments, as in the 3-D view).
fn hub_outline(st: &Structure) -> Vec<Vec3> {
    let hub = st.hub();
    if let Some(c) = hub.shape() {
        let a = c.axis * (1.0 / c.axis.norm());
        let helper = if a.get(0).abs() < 0.9 {
            Vec3::new(1.0, 0.0, 0.0)
        } else {
            Vec3::new(0.0, 1.0, 0.0)
        };
        let u = a.cross(helper).normalized();
        let v = a.cross(u);
        let r = c.diameter / 2.0;
        let mut out = Vec::new();
        for end in [-0.5, 0.5] {
            for k in 0..32 {
                let t = std::f64::consts::TAU * k as f64 / 32.0;
                out.push(c.center + a * (end * c.length) + u * (r * t.cos()) + v * (r * t.sin()));
            }
        }
        return out;
    }
    let h = super::view3d::box_half_sides(st);
    let mut out = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                out.push(hub.center_of_mass() + Vec3::new(sx * h[0], sy * h[1], sz * h[2]));
            }
        }
    }
    out
}

/// The convex hull of points in the plane (Andrew's monotone chain), counter-clockwise.
fn convex_hull(mut p: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

fn sketch(st: &Structure) -> String {
    // Segments and labelled points in the structure frame.
    let mut segs: Vec<(Vec3, Vec3, &'static str)> = Vec::new();
    let mut labels: Vec<(Vec3, String)> = Vec::new();
    let hub = st.hub.center_of_mass;
    labels.push((hub, "hub".into()));
    for (i, b) in st.beams.iter().enumerate() {
        let r = st.beam_root(i);
        let t = r + b.frame.ex * b.length;
        segs.push((r, t, "beam"));
        labels.push((r + b.frame.ex * (0.5 * b.length), b.name.clone()));
    }
    for p in &st.plates {
        let o = st.attachment_point(&p.attachment);
        let (ea, eb) = (p.length_axis, p.width_axis());
        let c = [
            o + eb * (-0.5 * p.width),
            o + eb * (0.5 * p.width),
            o + eb * (0.5 * p.width) + ea * p.length,
            o + eb * (-0.5 * p.width) + ea * p.length,
        ];
        for k in 0..4 {
            segs.push((c[k], c[(k + 1) % 4], "plate"));
        }
        labels.push((o + ea * (0.5 * p.length), p.name.clone()));
    }
    for m in &st.masses {
        labels.push((
            st.attachment_point(&m.attachment) + m.offset,
            m.name.clone(),
        ));
    }
    let mut out = String::from("<div class=\"sketch\">");
    for (axes, title) in [((0, 2), "side view (x–z)"), ((0, 1), "top view (x–y)")] {
        let pts: Vec<(f64, f64)> = segs
            .iter()
            .flat_map(|(a, b, _)| [*a, *b])
            .chain(labels.iter().map(|l| l.0))
            .chain(hub_outline(st))
            .map(|p| (p.get(axes.0), p.get(axes.1)))
            .collect();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for (x, y) in &pts {
            x0 = x0.min(*x);
            x1 = x1.max(*x);
            y0 = y0.min(*y);
            y1 = y1.max(*y);
        }
        let span = (x1 - x0).max(y1 - y0).max(1e-6);
        let (w, h, m) = (560.0, 380.0, 40.0);
        let s = ((w - 2.0 * m) / span).min((h - 2.0 * m) / span);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let px = |x: f64| w / 2.0 + (x - cx) * s;
        let py = |y: f64| h / 2.0 - (y - cy) * s;
        let _ = write!(
            out,
            "<svg viewBox=\"0 0 {w} {h}\" width=\"49%\" role=\"img\"><rect width=\"{w}\" height=\"{h}\" fill=\"#fbfbfd\" stroke=\"#ccd\"/><text x=\"10\" y=\"18\" font-size=\"13\" font-weight=\"bold\">{title}, m</text>"
        );
        // The hub as its body: the outline (convex hull) of its cylinder or box, projected.
        let outline = convex_hull(
            hub_outline(st)
                .iter()
                .map(|p| (px(p.get(axes.0)), py(p.get(axes.1))))
                .collect(),
        );
        let _ = write!(
            out,
            "<polygon points=\"{}\" fill=\"#cfd5df\" stroke=\"#556\"/><circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"#333\"/>",
            outline
                .iter()
                .map(|(x, y)| format!("{x:.1},{y:.1}"))
                .collect::<Vec<_>>()
                .join(" "),
            px(hub.get(axes.0)),
            py(hub.get(axes.1))
        );
        for (a, b, kind) in &segs {
            let (color, width) = if *kind == "beam" {
                ("#1e9646", 4)
            } else {
                ("#1f5ac8", 2)
            };
            let _ = write!(
                out,
                "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{color}\" stroke-width=\"{width}\"/>",
                px(a.get(axes.0)),
                py(a.get(axes.1)),
                px(b.get(axes.0)),
                py(b.get(axes.1))
            );
        }
        // Labels never overprint: one that would land on an earlier one moves down a line.
        let mut placed: Vec<(f64, f64)> = Vec::new();
        for (p, name) in &labels {
            let x = px(p.get(axes.0)) + 6.0;
            let mut y = py(p.get(axes.1)) - 6.0;
            while placed
                .iter()
                .any(|(a, b)| (a - x).abs() < 60.0 && (b - y).abs() < 14.0)
            {
                y += 15.0;
            }
            placed.push((x, y));
            let _ = write!(
                out,
                "<text x=\"{x:.1}\" y=\"{y:.1}\" font-size=\"13\" fill=\"#222\">{}</text>",
                esc(name)
            );
        }
        let _ = write!(
            out,
            "<text x=\"10\" y=\"{}\" font-size=\"11\" fill=\"#555\">{}: {:.3} … {:.3}; {}: {:.3} … {:.3}</text></svg>",
            h - 8.0,
            ["x", "y", "z"][axes.0],
            x0,
            x1,
            ["x", "y", "z"][axes.1],
            y0,
            y1
        );
    }
    out.push_str("</div>\n");
    out
}

fn scenario_section(s: &Scenario) -> String {
    let st = &s.structure;
    let mut o = String::from("<section id=\"scenario\"><h2>Scenario</h2>\n");
    let h = &st.hub;
    let j = h.inertia;
    let _ = writeln!(
        o,
        "<table><tr><th class=\"l\">hub</th><th>motion</th><th>mass [kg]</th><th>centre of mass [m]</th><th>J_xx, J_yy, J_zz [kg·m²]</th><th>total mass [kg]</th></tr>\
         <tr><td class=\"l\">hub</td><td>{}</td><td>{:.6}</td><td>[{:.4}, {:.4}, {:.4}]</td><td>{:.6e}, {:.6e}, {:.6e}</td><td>{:.6}</td></tr></table>",
        if h.motion == HubMotion::Free { "free" } else { "fixed" },
        h.mass,
        h.center_of_mass.0[0],
        h.center_of_mass.0[1],
        h.center_of_mass.0[2],
        j.get(0, 0),
        j.get(1, 1),
        j.get(2, 2),
        st.total_mass()
    );
    if !st.beams.is_empty() {
        o.push_str("<table><tr><th class=\"l\">beam</th><th class=\"l\">parent</th><th>length [m]</th><th>mass [kg]</th><th>EA [N]</th><th>EI_y [N·m²]</th><th>EI_z [N·m²]</th><th>GJ [N·m²]</th><th>terms (bending, torsion, axial)</th></tr>\n");
        for b in &st.beams {
            let e = b.youngs_modulus;
            let _ = writeln!(
                o,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4e}</td><td>{:.4e}</td><td>{:.4e}</td><td>{:.4e}</td><td>{}, {}, {}</td></tr>",
                esc(&b.name),
                esc(st.parent_name(&b.attachment)),
                b.length,
                b.mass(),
                e * b.section.area,
                e * b.section.iy,
                e * b.section.iz,
                b.shear_modulus * b.section.torsion_constant,
                b.terms.bending,
                b.terms.torsion,
                b.terms.axial
            );
        }
        o.push_str("</table>\n");
    }
    if !st.plates.is_empty() {
        o.push_str("<table><tr><th class=\"l\">plate</th><th class=\"l\">parent</th><th>length a [m]</th><th>width b [m]</th><th>mass [kg]</th><th>ρh [kg/m²]</th><th>D [N·m]</th><th>ν</th><th>terms (length × width)</th></tr>\n");
        for p in &st.plates {
            let _ = writeln!(
                o,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4e}</td><td>{:.3}</td><td>{} × {}</td></tr>",
                esc(&p.name),
                esc(st.parent_name(&p.attachment)),
                p.length,
                p.width,
                p.mass(),
                p.areal_density,
                p.bending_stiffness,
                p.poisson_ratio,
                p.terms.length,
                p.terms.width
            );
        }
        o.push_str("</table>\n");
    }
    if !st.masses.is_empty() {
        o.push_str("<table><tr><th class=\"l\">lumped mass</th><th class=\"l\">parent</th><th>mass [kg]</th><th>offset [m]</th></tr>\n");
        for m in &st.masses {
            let _ = writeln!(
                o,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.4}</td><td>[{:.3}, {:.3}, {:.3}]</td></tr>",
                esc(&m.name),
                esc(st.parent_name(&m.attachment)),
                m.mass,
                m.offset.0[0],
                m.offset.0[1],
                m.offset.0[2]
            );
        }
        o.push_str("</table>\n");
    }
    o.push_str(&sketch(st));
    let _ = write!(
        o,
        "<h3>Frames and signs</h3><figure class=\"frames\">{}</figure>",
        FRAMES
    );
    o.push_str("</section>\n");
    o
}

/// The 3-D view of the spacecraft, its deployment and its first elastic modes
/// ([`super::view3d`], drawn by the page's script on a canvas).
fn view_section(s: &Scenario, sim: &Simulation) -> String {
    let spec = super::view3d::view_spec(sim, s.deployment.as_ref().map(|d| d.plate.as_str()));
    format!(
        "<section id=\"view3d\"><h2>3-D view</h2><div class=\"view3d\"><script type=\"application/json\">{}</script>\
         <div class=\"controls\"><select aria-label=\"what to show\"></select> <button type=\"button\">play</button> \
         <input type=\"range\" min=\"0\" value=\"0\" aria-label=\"time or phase\"></div>\
         <canvas width=\"960\" height=\"560\"></canvas><p class=\"time\"></p>\
         <p class=\"note\">Drag to rotate, wheel to zoom. Structure axes: x red, y green, z blue (bottom left); \
         scale bar bottom right. The hub is drawn as its cylinder, or as the uniform box with its principal \
         moments of inertia; beams as tubes of their outer diameter; plates as panels; lumped masses as spheres. \
         Deployment: the hub moves and turns as computed, the panels unfold in the deployment plane, and the \
         beams bend by their computed tip deflection (exaggerated by the stated factor, drawn with a \
         cantilever's static shape). Modes: mass-normalised shapes, exaggerated by the stated factor.</p></div></section>\n",
        embed(&spec)
    )
}

fn modes_section(s: &Scenario, sim: &Simulation) -> Result<String, OutputError> {
    let st = &sim.model.structure;
    let mut o = String::from("<section id=\"modes\"><h2>Modes</h2>\n");
    let _ = writeln!(
        o,
        "<p class=\"note\">{} generalized coordinates, basis {}, hub {}. SE: strain-energy share of each component. Effective masses (kg; base-excitation measure) are those of the hub-fixed elastic modes: in the table for a fixed hub, below it for a free one.</p>",
        sim.modes.dof,
        st.basis.name(),
        if st.hub.motion == HubMotion::Free { "free" } else { "fixed" }
    );
    if let Some(sel) = &sim.modes.selection {
        let _ = writeln!(
            o,
            "<p class=\"note\">{}</p>",
            esc(&super::modes::selection_line(sel))
        );
    }
    frequency_table(sim, &mut o);
    if st.hub.motion == HubMotion::Free {
        hub_fixed_table(sim, &mut o);
    }
    mode_shapes(sim, &mut o)?;
    bode_section(s, sim, &mut o)?;
    coefficient_tables(sim, &mut o);
    o.push_str("</section>\n");
    Ok(o)
}

/// The frequency table (first 30 modes): kind, frequency, dominant component, strain-energy
/// shares and effective masses.
fn frequency_table(sim: &Simulation, o: &mut String) {
    let comps: Vec<String> = sim
        .modes
        .elastic()
        .next()
        .map(|m| {
            m.strain_energy_share
                .iter()
                .map(|(n, _)| n.clone())
                .collect()
        })
        .unwrap_or_default();
    let estimated = sim
        .modes
        .modes
        .iter()
        .any(|m| m.frequency_error_estimate.is_some());
    o.push_str("<table id=\"frequencies\"><tr><th>mode</th><th class=\"l\">kind</th><th>f [Hz]</th><th>ω [rad/s]</th><th class=\"l\">dominant</th>");
    if estimated {
        o.push_str("<th>est. error [-]</th>");
    }
    for c in &comps {
        let _ = write!(o, "<th>SE {}</th>", esc(c));
    }
    o.push_str("<th>m_eff x [kg]</th><th>m_eff y [kg]</th><th>m_eff z [kg]</th></tr>\n");
    let mut elastic_index = 0;
    for m in sim.modes.modes.iter().take(30) {
        let f = m.frequency_hz();
        let cell = if !m.rigid && elastic_index < 10 {
            let c = keyed(
                &format!("/modes/first_frequencies_hz/{elastic_index}"),
                f,
                format!("{f:.6}"),
            );
            elastic_index += 1;
            c
        } else {
            format!("<td>{f:.6}</td>")
        };
        let _ = write!(
            o,
            "<tr><td>{}</td><td class=\"l\">{}</td>{cell}<td>{:.6}</td><td class=\"l\">{}</td>",
            m.number,
            if m.rigid { "rigid" } else { "elastic" },
            m.omega_rad_s,
            esc(m.dominant())
        );
        if estimated {
            match m.frequency_error_estimate {
                Some(e) => {
                    let _ = write!(o, "<td>{e:.1e}</td>");
                }
                None => o.push_str("<td>–</td>"),
            }
        }
        for c in &comps {
            match m.share(c) {
                Some(v) => {
                    let _ = write!(o, "<td>{v:.4}</td>");
                }
                None => o.push_str("<td>–</td>"),
            }
        }
        match m.effective_mass {
            Some(e) => {
                let _ = write!(
                    o,
                    "<td>{:.4e}</td><td>{:.4e}</td><td>{:.4e}</td>",
                    e[0], e[1], e[2]
                );
            }
            None => o.push_str("<td>–</td><td>–</td><td>–</td>"),
        }
        o.push_str("</tr>\n");
    }
    o.push_str("</table>\n");
    if sim.modes.modes.len() > 30 {
        let _ = writeln!(
            o,
            "<p class=\"note\">… {} more modes in modes.json.</p>",
            sim.modes.modes.len() - 30
        );
    }
}

/// A free hub's elastic modes carry no base-excitation effective mass; the standard measure
/// is that of the hub-fixed modes.
fn hub_fixed_table(sim: &Simulation, o: &mut String) {
    o.push_str("<h3>Effective masses of the hub-fixed elastic modes</h3><table id=\"effective-masses\"><tr><th>mode</th><th>f [Hz]</th><th>x [kg]</th><th>y [kg]</th><th>z [kg]</th><th>rx [kg·m²]</th><th>ry [kg·m²]</th><th>rz [kg·m²]</th><th>Σ x</th><th>Σ y</th><th>Σ z</th><th>Σ rx</th><th>Σ ry</th><th>Σ rz</th></tr>\n");
    let fractions = sim.modes.effective_mass_fractions();
    for (i, (m, fr)) in sim
        .modes
        .hub_fixed
        .iter()
        .zip(&fractions)
        .take(12)
        .enumerate()
    {
        let _ = write!(
            o,
            "<tr><td>{}</td><td>{:.6}</td>",
            i + 1,
            m.omega_rad_s / (2.0 * std::f64::consts::PI)
        );
        for v in m.effective_mass {
            let _ = write!(o, "<td>{v:.4e}</td>");
        }
        for v in fr {
            let _ = write!(o, "<td>{}</td>", super::fixed(*v, 5));
        }
        o.push_str("</tr>\n");
    }
    let _ = writeln!(
        o,
        "</table><p class=\"note\">Σ: the running sums as fractions of the appendage's rigid mass and inertia (the limit of the sums): {}.</p>",
        sim.modes
            .appendage_mass
            .iter()
            .map(|v| format!("{v:.4e}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
}

/// Mode shapes: the first six elastic modes.
/// The frequency response of `[export]`'s transfer functions (default: hub torque → attitude)
/// from the modes the run used, with the export's damping: a Bode plot (docs/export.md).
fn bode_section(s: &Scenario, sim: &Simulation, o: &mut String) -> Result<(), OutputError> {
    let e = &s.export;
    if e.transfers.is_empty() {
        return Ok(());
    }
    let Ok(ex) = crate::export::ExportModel::build(&sim.model, &sim.modes, e) else {
        return Ok(());
    };
    let curves =
        super::export::bode_curves(&ex, &e.transfers, e.frequency_range_hz, e.frequency_points);
    let svg = super::plot::bode_svg("Frequency response", &curves)?;
    let zetas: Vec<f64> = ex
        .modes
        .iter()
        .filter(|m| !m.rigid)
        .map(|m| m.damping_ratio)
        .collect();
    let zeta = match (
        zetas.first(),
        zetas.iter().all(|z| Some(z) == zetas.first()),
    ) {
        (Some(z), true) => format!("ζ = {z}"),
        _ => "ζ per mode as [export] lists".to_string(),
    };
    let _ = writeln!(
        o,
        "<h3>Frequency response</h3><p class=\"note\">Transfer functions of the linear model \
         (`flexcraft export`, docs/export.md) over the {} elastic modes above, modal damping {zeta}: \
         magnitude (output unit per input unit) and phase.</p><figure class=\"bode\">{svg}</figure>",
        zetas.len()
    );
    Ok(())
}

fn mode_shapes(sim: &Simulation, o: &mut String) -> Result<(), OutputError> {
    o.push_str("<h3>Mode shapes</h3><p class=\"note\">The first six elastic modes (rigid-body modes are not drawn): grey undeformed, blue deformed (exaggerated).</p><div class=\"modes\">\n");
    for m in sim.modes.elastic().take(6) {
        let svg = mode_shape_svg(&sim.model, m)?;
        let _ = writeln!(
            o,
            "<figure class=\"shape\" data-mode=\"{}\">{svg}</figure>",
            m.number
        );
    }
    o.push_str("</div>\n");
    Ok(())
}

/// The full Ritz coefficient tables of the first six elastic modes (the paper's tables
/// 2.2–2.3 show the first terms of two), each mode collapsible: per beam, one row per
/// function index and a column per field (u, v, w, θ); per plate, g_mn with m down and n
/// across. A coefficient within [`super::figures::NOISE_FLOOR`] of the mode's largest reads 0.
fn coefficient_tables(sim: &Simulation, o: &mut String) {
    let st = &sim.model.structure;
    o.push_str("<h3>Ritz coefficients (as the paper's tables 2.2–2.3, every term)</h3><p class=\"note\">Mass-normalised shapes (√kg⁻¹·m per unit modal amplitude). Beams: u axial, v and w bending in the section's two planes (the paper's d, f), θ torsion (c); plates: g_mn (m along the length, n across the width; the width functions include the two rigid ones). Click a mode to open its tables.</p>\n");
    for m in sim.modes.elastic().take(6) {
        let big = m.shape.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let cell = |v: f64| {
            if v.abs() <= super::figures::NOISE_FLOOR * big {
                "<td>0</td>".to_string()
            } else {
                format!("<td>{v:.6e}</td>")
            }
        };
        let _ = write!(
            o,
            "<details class=\"coefficients\" data-mode=\"{}\"><summary>mode {} (f = {:.6} Hz)</summary>",
            m.number,
            m.number,
            m.frequency_hz()
        );
        for e in &sim.model.elements {
            let name = esc(st.component_name(e.id));
            if e.fields.is_empty() {
                continue;
            }
            if let crate::structure::ComponentId::Plate(i) = e.id {
                let t = st.plates()[i].terms();
                let start = e.own_range().start;
                let _ = write!(
                    o,
                    "<table class=\"coefficients\"><tr><th class=\"l\">{name} g_mn</th>"
                );
                for n in 0..t.width {
                    let _ = write!(o, "<th>n = {}</th>", n + 1);
                }
                o.push_str("</tr>");
                // The smooth functions, then a cut wing's kink functions (latch lines).
                let kinks = st.plates()[i].hinge_functions().len();
                for mi in 0..t.length + kinks {
                    if mi < t.length {
                        let _ = write!(o, "<tr><th>m = {}</th>", mi + 1);
                    } else {
                        let _ = write!(o, "<tr><th>kink {}</th>", mi - t.length + 1);
                    }
                    for n in 0..t.width {
                        o.push_str(&cell(m.shape[start + mi * t.width + n]));
                    }
                    o.push_str("</tr>");
                }
                o.push_str("</table>\n");
                continue;
            }
            let rows = e.fields.iter().map(|f| f.len).max().unwrap_or(0);
            let _ = write!(
                o,
                "<table class=\"coefficients\"><tr><th class=\"l\">{name}</th>"
            );
            for f in &e.fields {
                let _ = write!(o, "<th>{}_k</th>", f.kind.name());
            }
            o.push_str("</tr>");
            for k in 0..rows {
                let _ = write!(o, "<tr><th>k = {}</th>", k + 1);
                for f in &e.fields {
                    if k < f.len {
                        o.push_str(&cell(m.shape[f.start + k]));
                    } else {
                        o.push_str("<td></td>");
                    }
                }
                o.push_str("</tr>");
            }
            o.push_str("</table>\n");
        }
        o.push_str("</details>\n");
    }
}

fn deployment_section(s: &Scenario, sim: &Simulation) -> String {
    let mut o = String::from("<section id=\"deployment\"><h2>Deployment</h2>\n");
    let Some(d) = &s.deployment else {
        o.push_str("<p>No [deployment] section.</p></section>\n");
        return o;
    };
    let r = &sim.deployment;
    let _ = writeln!(
        o,
        "<p>Plate {}, {} panels, hub {}; {} at t = {:.6} s.</p>",
        esc(&d.plate),
        d.chain.len(),
        match d.chain.hub {
            PlanarHub::Fixed => "fixed",
            PlanarHub::Free { .. } => "free",
        },
        if r.all_latched {
            "all hinges latched"
        } else {
            "NOT all hinges latched"
        },
        r.final_time
    );
    // Animation frames: the hinge points of every sample, in the deployment plane.
    // At most ANIMATION_FRAMES of them, evenly spaced, the first and the last included.
    let m = r.samples.len();
    let step = m.div_ceil(ANIMATION_FRAMES).max(1);
    let frames: Vec<Value> = (0..m)
        .filter(|k| k % step == 0 || k + 1 == m)
        .map(|k| &r.samples[k])
        .map(|smp| {
            json!({"t": round7(smp.t),
                   "p": smp.hinges.iter().map(|p| [round7(p[0]), round7(p[1])]).collect::<Vec<_>>(),
                   "h": [round7(smp.hub[0]), round7(smp.hub[1])]})
        })
        .collect();
    let (mut u0, mut u1, mut v0, mut v1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for smp in &r.samples {
        for p in smp
            .hinges
            .iter()
            .chain(std::iter::once(&[smp.hub[0], smp.hub[1]]))
        {
            u0 = u0.min(p[0]);
            u1 = u1.max(p[0]);
            v0 = v0.min(p[1]);
            v1 = v1.max(p[1]);
        }
    }
    let pad = 0.05 * (u1 - u0).max(v1 - v0).max(1e-6);
    let spec = json!({"frames": frames, "box": [u0 - pad, u1 + pad, v0 - pad, v1 + pad]});
    let _ = writeln!(
        o,
        "<h3>Animation</h3><div class=\"animation\" id=\"animation\"><script type=\"application/json\">{}</script>\
         <div class=\"controls\"><button type=\"button\">play</button> <input type=\"range\" min=\"0\" value=\"0\" aria-label=\"time\"> <span class=\"time\"></span></div>\
         <div class=\"stage\"></div><p class=\"note\">Deployment plane: u along the wing's length axis (right), v along its normal (up); the dark dot is the hub's centre of mass, red dots the hinges and the tip.</p></div>",
        embed(&spec)
    );
    o.push_str("<h3>Latch events</h3><table id=\"latches\"><tr><th>latch</th><th>hinge</th><th>t [s]</th><th>kinetic energy before [J]</th><th>after [J]</th><th>lost [J]</th><th>impulse on the base at the root hinge, hub axes: force [N·s], moment [N·m·s]</th></tr>\n");
    for (i, e) in r.latches.iter().enumerate() {
        let _ = writeln!(
            o,
            "<tr><td>{}</td><td>{}</td>{}{}{}<td>{:.6e}</td><td>{}</td></tr>",
            i + 1,
            e.hinge,
            keyed(
                &format!("/deployment/latches/{i}/time"),
                e.time,
                format!("{:.6}", e.time)
            ),
            keyed(
                &format!("/deployment/latches/{i}/energy_before"),
                e.energy_before,
                format!("{:.6e}", e.energy_before)
            ),
            keyed(
                &format!("/deployment/latches/{i}/energy_after"),
                e.energy_after,
                format!("{:.6e}", super::snap(e.energy_after, e.energy_before))
            ),
            super::snap(e.energy_before - e.energy_after, e.energy_before),
            e.base_impulse.map_or_else(String::new, |(f, m)| {
                let (fs, ms) = super::deploy::impulse_scales(e);
                let (f, m) = (f.map(|v| super::snap(v, fs)), m.map(|v| super::snap(v, ms)));
                format!(
                    "[{:.4e}, {:.4e}, {:.4e}], [{:.4e}, {:.4e}, {:.4e}]",
                    f[0], f[1], f[2], m[0], m[1], m[2]
                )
            })
        );
    }
    o.push_str("</table>\n");
    latch_details(r, &mut o);
    for w in &r.warnings {
        let _ = writeln!(o, "<p class=\"warn\">warning: {}</p>", esc(&w.to_string()));
    }
    let names: Vec<String> = sim
        .coupled
        .base
        .beams
        .iter()
        .map(|b| b.name.clone())
        .collect();
    for f in super::figures::deployment_figures(d, r, &names) {
        o.push_str(&plot(&f));
    }
    o.push_str("</section>\n");
    o
}

/// Per latch, what the terminal shows: every hinge's angle, rates before and after and the
/// impulse it carries (the first 12 hinges); rounding noise reads 0.
fn latch_details(r: &crate::deploy::DeploymentResult, o: &mut String) {
    for (i, e) in r.latches.iter().enumerate() {
        let (fs, ms) = super::deploy::impulse_scales(e);
        let _ = write!(
            o,
            "<details class=\"latch\"><summary>latch {}: hinge {} at t = {:.9} s, locks {:?}</summary>\
             <table class=\"latch-hinges\"><tr><th>hinge</th><th>α [rad]</th><th>rate before [rad/s]</th><th>rate after [rad/s]</th>\
             <th>S_u [N·s]</th><th>S_v [N·s]</th><th>M_S [N·m·s]</th></tr>",
            i + 1,
            e.hinge,
            e.time,
            e.locked
        );
        for k in 0..e.angles.len().min(12) {
            let (f, m) = e.impulses[k];
            let _ = write!(
                o,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                k + 1,
                super::fixed(e.angles[k], 6),
                super::fixed(e.rates_before[k], 6),
                super::fixed(e.rates_after[k], 6),
                super::fixed(super::snap(f[0], fs), 6),
                super::fixed(super::snap(f[1], fs), 6),
                super::fixed(super::snap(m, ms), 6)
            );
        }
        o.push_str("</table></details>\n");
    }
}

/// The hand-over balance: energies, the kept modes' share, the drift and the momenta.
fn handover_table(s: &Scenario, sim: &Simulation, r: &crate::simulation::Response, o: &mut String) {
    let h = &r.handover;
    o.push_str("<table id=\"handover\"><tr><th class=\"l\">quantity</th><th>value</th></tr>\n");
    let rows = [
        (
            "kinetic energy before [J]",
            "/handover/energy_before",
            h.energy_before,
        ),
        (
            "kinetic energy after [J]",
            "/handover/energy_after",
            h.energy_after,
        ),
        (
            "difference [J]",
            "/handover/energy_lost",
            h.energy_before - h.energy_after,
        ),
        (
            "elastic energy of the base before [J]",
            "/handover/elastic_energy_before",
            h.elastic_energy_before,
        ),
        (
            "elastic energy after [J]",
            "/handover/elastic_energy_after",
            h.elastic_energy_after,
        ),
        (
            "projection residual, kinetic + elastic [J]",
            "/handover/projection_residual",
            (h.energy_before + h.elastic_energy_before) - (h.energy_after + h.elastic_energy_after),
        ),
        (
            "latch springs' energy, not carried [J]",
            "/handover/latch_energy",
            h.latch_energy,
        ),
        (
            "share of the hand-over energy in the kept modes",
            "/handover/captured_energy_fraction",
            r.modal.captured_energy_fraction,
        ),
        (
            "elastic energy drift over the run (relative)",
            "/response/elastic_energy_drift",
            r.history.energy_drift(),
        ),
    ];
    // Rounding noise reads 0 (the exact values stay in data-value and summary.json), against
    // the scales of `handover_scales` (ratios against 1).
    let (energy, p_scale, l_scale) = super::simulate::handover_scales(s, sim, r);
    let shown = |v: f64, scale: f64| {
        if v.abs() <= super::figures::NOISE_FLOOR * scale {
            "0".to_string()
        } else {
            format!("{v:.6e}")
        }
    };
    for (i, (label, key, v)) in rows.into_iter().enumerate() {
        let scale = if i < 6 { energy } else { 1.0 };
        let _ = writeln!(
            o,
            "<tr><td class=\"l\">{label}</td>{}</tr>",
            keyed(key, v, shown(v, scale))
        );
    }
    for (label, key, v) in [
        (
            "linear momentum before [N·s]",
            "/handover/momentum_before/linear",
            h.momentum_before.linear,
        ),
        (
            "linear momentum after [N·s]",
            "/handover/momentum_after/linear",
            h.momentum_after.linear,
        ),
        (
            "angular momentum before [N·m·s]",
            "/handover/momentum_before/angular",
            h.momentum_before.angular,
        ),
        (
            "angular momentum after [N·m·s]",
            "/handover/momentum_after/angular",
            h.momentum_after.angular,
        ),
    ] {
        let _ = write!(o, "<tr><td class=\"l\">{label}</td><td><table>");
        let _ = write!(o, "<tr>");
        let scale = if label.starts_with("angular") {
            l_scale
        } else {
            p_scale
        };
        for k in 0..3 {
            o.push_str(&keyed(&format!("{key}/{k}"), v.0[k], shown(v.0[k], scale)));
        }
        o.push_str("</tr></table></td></tr>\n");
    }
    o.push_str("</table>\n");
}

fn response_section(s: &Scenario, sim: &Simulation) -> String {
    let mut o = String::from("<section id=\"response\"><h2>Response</h2>\n");
    let Some(r) = &sim.response else {
        o.push_str(
            "<p class=\"warn\">No response: the array did not latch completely.</p></section>\n",
        );
        return o;
    };
    let h = &r.handover;
    let _ = writeln!(
        o,
        "<h3>Hand-over</h3><p>t = {:.6} s ({}), method <b>{}</b>; {} s of response at {} Hz, ζ = {}, {} rigid + {} of {} elastic modes kept.</p>",
        h.latch_time,
        esc(&super::simulate::handover_instant(h)),
        h.method.name(),
        s.response.duration,
        s.response.output_rate,
        s.response.damping_ratio,
        r.modal.modes.iter().filter(|m| m.rigid).count(),
        r.modal.kept_elastic(),
        r.modal.available_elastic
    );
    handover_table(s, sim, r, &mut o);
    for w in &sim.warnings {
        let _ = writeln!(o, "<p class=\"warn\">warning: {}</p>", esc(&w.to_string()));
    }
    o.push_str(&super::margins::margins_table(s, sim));
    for f in super::hub::figures(sim) {
        o.push_str(&plot(&f));
    }
    for f in super::figures::response_figures(s, r, &sim.modes) {
        o.push_str(&plot(&f));
    }
    o.push_str("</section>\n");
    o
}

/// The whole page. `source` is the scenario file's bytes (its SHA-256 is in the footer).
pub fn report_html(
    s: &Scenario,
    sim: &Simulation,
    source: &[u8],
    file_name: &str,
) -> Result<String, OutputError> {
    let hash = Sha256::digest(source)
        .iter()
        .fold(String::new(), |mut h, b| {
            let _ = write!(h, "{b:02x}");
            h
        });
    let mut o = String::new();
    let _ = write!(
        o,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>flexcraft report: {}</title><style>{STYLE}</style></head>\n<body data-status=\"loading\">\n\
         <h1>flexcraft report: {}</h1><p class=\"note\">SI units: m, kg, s, rad, N, J, Hz. Plots: hover to read values, drag to zoom a time window, double-click to reset.</p>\
         <nav><a href=\"#scenario\">scenario</a><a href=\"#view3d\">3-D view</a><a href=\"#modes\">modes</a><a href=\"#deployment\">deployment</a><a href=\"#response\">response</a></nav>\n",
        esc(&s.name),
        esc(&s.name)
    );
    o.push_str(&scenario_section(s));
    o.push_str(&view_section(s, sim));
    o.push_str(&modes_section(s, sim)?);
    o.push_str(&deployment_section(s, sim));
    o.push_str(&response_section(s, sim));
    let _ = write!(
        o,
        "<footer>flexcraft {} · scenario {} · SHA-256 <code id=\"scenario-hash\">{hash}</code></footer>\n<script>{SCRIPT}</script>\n</body></html>\n",
        env!("CARGO_PKG_VERSION"),
        esc(file_name)
    );
    Ok(o)
}
