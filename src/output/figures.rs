//! The figures of the deployment and of the response, defined once: drawn as PNG+SVG files
//! ([`super::plot::line_chart`]) and as interactive charts in the HTML report.

use crate::deploy::envelope::{Envelope, Trace};
use crate::deploy::{Deployment, DeploymentResult, Sample};
use crate::response::{Channel, ChannelKind};
use crate::ritz::ModalAnalysis;
use crate::scenario::Scenario;
use crate::simulation::Response;

/// One curve: name, x and y samples.
pub type Curve = (String, Vec<f64>, Vec<f64>);

/// Most points drawn per curve (PNG, SVG and the report); longer series are decimated by
/// [`decimate`]. Above every example's series length (≤ 3 001 samples), so their pictures
/// and reports are drawn from every sample. The CSV files always keep every row.
pub const PLOT_POINTS: usize = 4000;

/// Indices of the samples `0..n` to draw when at most `max_points` (≥ 4) may be: all of them
/// when `n ≤ max_points`; otherwise the first and the last, and of each of
/// `(max_points − 2) / 2` equal runs of the samples in between, those of its minimum and its
/// maximum of `y` (the first of equal ones; NaN is never picked unless a run holds nothing
/// else), in increasing order. Every extremum of the series survives exactly, the order of
/// the samples (monotone x) is kept, and the result has at most `max_points` indices.
pub fn decimate(n: usize, y: impl Fn(usize) -> f64, max_points: usize) -> Vec<usize> {
    let max_points = max_points.max(4);
    if n <= max_points {
        return (0..n).collect();
    }
    let inner = n - 2; // samples 1..=n-2
    let buckets = (max_points - 2) / 2;
    let mut out = Vec::with_capacity(2 * buckets + 2);
    out.push(0);
    for b in 0..buckets {
        // Run b: samples 1 + [b·inner/buckets, (b+1)·inner/buckets), never empty.
        let lo = 1 + b * inner / buckets;
        let hi = 1 + (b + 1) * inner / buckets;
        let (mut imin, mut imax) = (lo, lo);
        let (mut vmin, mut vmax) = (y(lo), y(lo));
        for k in lo + 1..hi {
            let v = y(k);
            if v < vmin || (vmin.is_nan() && !v.is_nan()) {
                (imin, vmin) = (k, v);
            }
            if v > vmax || (vmax.is_nan() && !v.is_nan()) {
                (imax, vmax) = (k, v);
            }
        }
        let (a, c) = (imin.min(imax), imin.max(imax));
        out.push(a);
        if c != a {
            out.push(c);
        }
    }
    out.push(n - 1);
    out
}

/// A curve of the samples `0..n` (x(k), y(k)), decimated to [`PLOT_POINTS`].
pub(super) fn curve(
    name: String,
    n: usize,
    x: impl Fn(usize) -> f64,
    y: impl Fn(usize) -> f64,
) -> Curve {
    let idx = decimate(n, &y, PLOT_POINTS);
    let xs = idx.iter().map(|&k| x(k)).collect();
    let ys = idx.iter().map(|&k| y(k)).collect();
    (name, xs, ys)
}

/// Curves whose largest magnitude is below this fraction of the largest of the same
/// quantity in the run are rounding noise: drawn as exact zero and labelled so.
pub const NOISE_FLOOR: f64 = 1e-9;

/// The unit of a curve: the last "[…]" of its name, else of the figure's y label.
fn unit_of<'a>(name: &'a str, ylabel: &'a str) -> Option<&'a str> {
    let last = |s: &'a str| {
        let a = s.rfind('[')?;
        let b = s[a..].find(']')? + a;
        Some(&s[a + 1..b])
    };
    last(name).or_else(|| last(ylabel))
}

/// A structure's size for comparing rotations with lengths: its longest beam or plate side, m.
pub fn structure_size(st: &crate::structure::Structure) -> f64 {
    st.beams
        .iter()
        .map(|b| b.length)
        .chain(st.plates.iter().map(|p| p.length.max(p.width)))
        .fold(1e-3, f64::max)
}

/// The label a curve of rounding noise gets.
pub const ZERO_LABEL: &str = "identically zero (rounding only)";

/// Rounding noise and coinciding traces, over one phase's figures (deployment or response):
/// * a curve whose peak magnitude is at most [`NOISE_FLOOR`] times the largest peak of the
///   same quantity among `figs` becomes exactly zero, its name ending in [`ZERO_LABEL`];
///   lengths (m) and angles (rad) are one quantity through `length` (a structure's size:
///   1 rad of rotation ~ `length` m), so that a twist of 1e-17 rad next to deflections of
///   1e-5 m reads as the rounding it is;
/// * a curve equal to an earlier one of the same figure (to 1e-12 of their peak) is noted
///   "(coincides with …)", since it is drawn under it.
pub fn clean(figs: &mut [Figure], length: f64) {
    let peak = |c: &Curve| c.2.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let mut reference = NoiseReference::new(length);
    for f in figs.iter() {
        for c in &f.curves {
            if let Some(u) = unit_of(&c.0, f.ylabel) {
                reference.observe(u, peak(c));
            }
        }
    }
    for f in figs.iter_mut() {
        let ylabel = f.ylabel;
        for c in f.curves.iter_mut() {
            let Some(u) = unit_of(&c.0, ylabel) else {
                continue;
            };
            let p = peak(c);
            if p > 0.0 && reference.is_noise(u, p) {
                c.2.iter_mut().for_each(|v| *v = 0.0);
                c.0 = format!("{}: {ZERO_LABEL}", c.0);
            } else if p == 0.0 && !c.0.ends_with(ZERO_LABEL) {
                c.0 = format!("{}: identically zero", c.0);
            }
        }
        for i in 1..f.curves.len() {
            let same = (0..i).find(|&j| {
                let (a, b) = (&f.curves[i], &f.curves[j]);
                let scale = peak(a).max(peak(b));
                a.1 == b.1
                    && scale > 0.0
                    && a.2
                        .iter()
                        .zip(&b.2)
                        .all(|(x, y)| (x - y).abs() <= 1e-12 * scale)
            });
            if let Some(j) = same {
                let other = short_name(&f.curves[i].0, &f.curves[j].0);
                f.curves[i].0 = format!("{} (coincides with {other})", f.curves[i].0);
            }
        }
    }
}

/// `other` from the word before the one where it departs from `name` ("latch moment,
/// hinge 2" beside "latch moment, hinge 3" is "hinge 2"), so that a legend entry stays short.
fn short_name(name: &str, other: &str) -> String {
    let common = name
        .char_indices()
        .zip(other.chars())
        .find(|((_, a), b)| a != b)
        .map_or(name.len().min(other.len()), |((i, _), _)| i);
    // The word where they differ, and the one before it.
    let word = other[..common].rfind([' ', ',']).map_or(0, |i| i + 1);
    let cut = other[..word]
        .trim_end_matches([' ', ','])
        .rfind([' ', ','])
        .map_or(0, |i| i + 1);
    let short = other[cut..].trim_start();
    if short.is_empty() {
        other.to_string()
    } else {
        short.to_string()
    }
}

/// The largest magnitude of every quantity (by unit) in one phase of a run, against which
/// rounding noise is judged ([`NOISE_FLOOR`]); lengths (m) and angles (rad) are one quantity
/// through a structure's size (1 rad of rotation ~ `size` m).
#[derive(Debug, Clone)]
pub struct NoiseReference {
    size: f64,
    largest: std::collections::BTreeMap<String, f64>,
}

impl NoiseReference {
    /// No quantity seen yet; `size` converts angles to lengths.
    pub fn new(size: f64) -> Self {
        Self {
            size,
            largest: Default::default(),
        }
    }

    /// The quantity a unit belongs to and the magnitude in that quantity's terms.
    fn key(&self, unit: &str, magnitude: f64) -> (String, f64) {
        match unit {
            "rad" => ("m".to_string(), magnitude.abs() * self.size),
            _ => (unit.to_string(), magnitude.abs()),
        }
    }

    /// Records a magnitude of a quantity in `unit`.
    pub fn observe(&mut self, unit: &str, magnitude: f64) {
        let (quantity, m) = self.key(unit, magnitude);
        let e = self.largest.entry(quantity).or_insert(0.0);
        *e = e.max(m);
    }

    /// `magnitude` (in `unit`) is at most [`NOISE_FLOOR`] times the largest of its quantity.
    pub fn is_noise(&self, unit: &str, magnitude: f64) -> bool {
        let (quantity, m) = self.key(unit, magnitude);
        m <= NOISE_FLOOR * self.largest.get(&quantity).copied().unwrap_or(0.0)
    }
}

/// A line chart.
#[derive(Debug, Clone)]
pub struct Figure {
    /// File stem under plots/.
    pub stem: String,
    /// Title.
    pub title: String,
    /// Axis labels with units.
    pub xlabel: &'static str,
    /// Axis labels with units.
    pub ylabel: &'static str,
    /// Curves.
    pub curves: Vec<Curve>,
    /// Event times marked by vertical lines (the latches), in x units.
    pub markers: Vec<f64>,
}

impl Figure {
    /// plots/STEM.png and .svg.
    pub fn draw(&self, dir: &mut super::OutputDir) -> Result<(), super::OutputError> {
        super::plot::line_chart_marked(
            dir,
            &self.stem,
            &self.title,
            (self.xlabel, self.ylabel),
            &self.series(),
            false,
            &self.markers,
        )
    }

    /// (x, y) pairs of every curve, for plotters.
    pub fn series(&self) -> Vec<super::plot::Series> {
        self.curves
            .iter()
            .map(|(n, x, y)| {
                (
                    n.clone(),
                    x.iter().copied().zip(y.iter().copied()).collect(),
                )
            })
            .collect()
    }
}

/// Angles, rates, hinge reaction magnitudes (up to 8 hinges shown), the hub's motion, and
/// for the coupled model every base beam's root force and moment and the first base modal
/// coordinates; the latches marked on each.
pub fn deployment_figures(
    d: &Deployment,
    r: &DeploymentResult,
    beam_names: &[String],
) -> Vec<Figure> {
    let n = d.chain.len();
    let span: f64 = d.chain.panels.iter().map(|p| p.length).sum();
    let shown: Vec<usize> = (0..n).step_by(n.div_ceil(8).max(1)).collect();
    let m = r.samples.len();
    let t = |k: usize| r.samples[k].t;
    // Rigid latches and compliant captures (one marker per instant).
    let mut markers: Vec<f64> = r.latches.iter().map(|e| e.time).collect();
    markers.extend(r.captures.iter().map(|c| c.time));
    markers.sort_by(f64::total_cmp);
    markers.dedup();
    let env = r.envelope.as_ref();
    // Hinge i's samples, or its envelope from the solution where the samples alias.
    let per_hinge = |f: &dyn Fn(&Sample, usize) -> f64, trace: Option<fn(usize) -> Trace>| {
        shown
            .iter()
            .map(|&i| {
                let name = format!("hinge {}", i + 1);
                traced(env, trace.map(|tr| tr(i)), name, m, t, |k| {
                    f(&r.samples[k], i)
                })
            })
            .collect::<Vec<Curve>>()
    };
    let fig = |stem: &str, title: &str, ylabel: &'static str, curves| Figure {
        stem: stem.into(),
        title: title.into(),
        xlabel: "t [s]",
        ylabel,
        curves,
        markers: markers.clone(),
    };
    // The figures drawn from the envelope say so.
    let enveloped = |title: &str| deployment_title(title, env);
    let body = |k: usize| r.samples[k].body.as_deref();
    let mut figs = vec![
        fig(
            "angles",
            "opening angles",
            "α [rad]",
            per_hinge(&|s, i| s.alpha[i], None),
        ),
        fig(
            "rates",
            &enveloped("opening rates"),
            "α̇ [rad/s]",
            per_hinge(&|s, i| s.rate[i], Some(Trace::Rate)),
        ),
        fig(
            "reactions",
            &enveloped("hinge reaction force magnitude (inboard body on panel i)"),
            "|F| [N]",
            per_hinge(
                &|s, i| s.force[i][0].hypot(s.force[i][1]),
                Some(Trace::Reaction),
            ),
        ),
    ];
    if !r.captures.is_empty() {
        figs.push(fig(
            "latch_moments",
            &enveloped("compliant latch moments on the hinges (captures marked)"),
            "M_L [N·m]",
            per_hinge(&|s, i| s.latch_moment[i], Some(Trace::LatchMoment)),
        ));
    }
    if body(0).is_none() {
        let hub: Vec<Curve> = ["u [m]", "v [m]", "θ [rad]"]
            .iter()
            .enumerate()
            .map(|(j, l)| curve(format!("hub {l}"), m, t, |k| r.samples[k].hub[j]))
            .collect();
        figs.push(fig(
            "hub",
            "hub motion in the deployment plane",
            "u, v [m]; θ [rad]",
            hub,
        ));
        clean(&mut figs, span);
        return figs;
    }
    figs.extend(body_figures(r, beam_names, &markers));
    clean(&mut figs, span);
    figs
}

/// The coupled model's figures: the hub's position and attitude, every base beam's root
/// force and moment, the first base modal coordinates.
fn body_figures(r: &DeploymentResult, beam_names: &[String], markers: &[f64]) -> Vec<Figure> {
    let m = r.samples.len();
    let t = |k: usize| r.samples[k].t;
    let body = |k: usize| r.samples[k].body.as_deref();
    let fig = |stem: &str, title: &str, ylabel: &'static str, curves| Figure {
        stem: stem.into(),
        title: title.into(),
        xlabel: "t [s]",
        ylabel,
        curves,
        markers: markers.to_vec(),
    };
    let mut figs = Vec::new();
    let comp = |f: &dyn Fn(&crate::deploy::BodySample) -> f64, k: usize| body(k).map_or(0.0, f);
    // The x, y, z components of a vector of the body sample, one curve each.
    let components = |prefix: &str, get: fn(&crate::deploy::BodySample) -> [f64; 3]| {
        ["x", "y", "z"]
            .iter()
            .enumerate()
            .map(|(j, axis)| {
                curve(format!("{prefix} {axis}"), m, t, |k| {
                    comp(&|b| get(b)[j], k)
                })
            })
            .collect::<Vec<Curve>>()
    };
    figs.push(fig(
        "hub",
        "hub centre of mass (inertial)",
        "position [m]",
        components("hub", |b| b.hub_position),
    ));
    figs.push(fig(
        "hub_attitude",
        "hub attitude (rotation vector, inertial)",
        "rotation [rad]",
        components("rotation", |b| b.hub_rotation),
    ));
    let beams = body(0).map_or(0, |b| b.root_loads.len());
    let norm = |l: &[f64]| l.iter().map(|x| x * x).sum::<f64>().sqrt();
    let names = |b: usize| {
        beam_names
            .get(b)
            .cloned()
            .unwrap_or_else(|| format!("beam {}", b + 1))
    };
    let env = r.envelope.as_ref();
    if beams > 0 {
        let moments: Vec<Curve> = (0..beams)
            .map(|b| {
                traced(env, Some(Trace::RootMoment(b)), names(b), m, t, |k| {
                    comp(&|s| norm(&s.root_loads[b][3..6]), k)
                })
            })
            .collect();
        figs.push(fig(
            "root_moments",
            &deployment_title("beam root moment magnitude (parent on beam)", env),
            "|M| [N·m]",
            moments,
        ));
        let forces: Vec<Curve> = (0..beams)
            .map(|b| {
                traced(env, Some(Trace::RootForce(b)), names(b), m, t, |k| {
                    comp(&|s| norm(&s.root_loads[b][0..3]), k)
                })
            })
            .collect();
        figs.push(fig(
            "root_forces",
            &deployment_title("beam root force magnitude (parent on beam)", env),
            "|F| [N]",
            forces,
        ));
    }
    let modes = body(0).map_or(0, |b| b.eta.len()).min(6);
    if modes > 0 {
        let eta: Vec<Curve> = (0..modes)
            .map(|j| {
                let name = format!("base mode {}", j + 1);
                traced(env, Some(Trace::Eta(j)), name, m, t, |k| {
                    comp(&|s| s.eta[j], k)
                })
            })
            .collect();
        figs.push(fig(
            "base_modes",
            &deployment_title("base modal coordinates (hub-fixed modes)", env),
            "η [√kg·m]",
            eta,
        ));
    }
    figs
}

/// The paper's figures 2.4–2.7 (every beam's tip deflection and twist, every plate's tip
/// corners, hub translation and rotation) and the first eight elastic modal amplitudes.
pub fn response_figures(s: &Scenario, r: &Response, modes: &ModalAnalysis) -> Vec<Figure> {
    let hist = &r.history;
    let n = hist.times.len();
    let t = |k: usize| hist.times[k];
    // Where the samples would alias the kept modes, the channels are drawn as the solution's
    // min/max envelope, one pair per plot column (docs/theory.md §3.2).
    let envelope = crate::simulation::aliased(&r.modal, &s.response).map(|_| {
        r.modal.envelopes(
            modes,
            &r.channels,
            s.response.duration,
            (PLOT_POINTS - 2) / 2,
        )
    });
    let env = envelope.as_deref();
    let pick = |f: &dyn Fn(&Channel) -> bool| -> Vec<Curve> {
        r.channels
            .iter()
            .enumerate()
            .filter(|(_, c)| f(c))
            .map(|(j, c)| channel_curve(r, env, j, c))
            .collect()
    };
    let fig = |stem: String, title: String, ylabel: &'static str, curves| Figure {
        markers: Vec::new(),
        stem,
        title: envelope_title(title, env),
        xlabel: "t after the latch [s]",
        ylabel,
        curves,
    };
    // File stems of the components' figures: sanitised, distinct (names::file_stems).
    let st = &s.structure;
    let names: Vec<&str> = (st.beams.iter().map(|b| b.name.as_str()))
        .chain(st.plates.iter().map(|p| p.name.as_str()))
        .chain(st.masses.iter().map(|m| m.name.as_str()))
        .collect();
    let stems = super::file_stems(&names);
    let mut out = Vec::new();
    for (b, stem) in st.beams.iter().zip(&stems) {
        let kind = ChannelKind::BeamTip {
            beam: b.name.clone(),
        };
        out.push(fig(
            format!("response_{stem}_tip"),
            format!(
                "{} tip: elastic deflection in both bending planes (the paper's fig. 2.4)",
                b.name
            ),
            "deflection [m]",
            pick(&|c| c.kind == kind && c.unit == "m"),
        ));
        out.push(fig(
            format!("response_{stem}_twist"),
            format!("{} tip: elastic twist (the paper's fig. 2.4)", b.name),
            "twist [rad]",
            pick(&|c| c.kind == kind && c.unit == "rad"),
        ));
    }
    for (p, stem) in st.plates.iter().zip(&stems[st.beams.len()..]) {
        let kind = ChannelKind::PlateTip {
            plate: p.name.clone(),
        };
        out.push(fig(
            format!("response_{stem}_tip"),
            format!(
                "{} tip corners: elastic deflection (the paper's fig. 2.5)",
                p.name
            ),
            "deflection [m]",
            pick(&|c| c.kind == kind),
        ));
    }
    out.push(fig(
        "response_hub_translation".into(),
        "hub translation along the structure axes (the paper's fig. 2.6)".into(),
        "translation [m]",
        pick(&|c| c.kind == ChannelKind::HubTranslation),
    ));
    out.push(fig(
        "response_hub_rotation".into(),
        "hub rotation about the structure axes (the paper's fig. 2.7)".into(),
        "rotation [rad]",
        pick(&|c| c.kind == ChannelKind::HubRotation),
    ));
    out.extend(load_figures(s, r, &stems, env));
    let mut out = with_spectra(out, r, modes, structure_size(st));
    let modal: Vec<Curve> = r
        .modal
        .modes
        .iter()
        .enumerate()
        .filter(|(_, m)| !m.rigid)
        .take(8)
        .map(|(j, m)| {
            let name = format!(
                "mode {} ({:.3} Hz)",
                m.number,
                m.omega_rad_s / (2.0 * std::f64::consts::PI)
            );
            curve(name, n, t, |k| hist.modal[(k, j)])
        })
        .collect();
    out.push(fig(
        "response_modal_amplitudes".into(),
        "modal amplitudes of the first elastic modes".into(),
        "η [√kg·m]",
        modal,
    ));
    clean(&mut out, structure_size(st));
    out
}

/// The response's history figures `out`, each followed by its amplitude spectrum
/// ([`spectrum_figure`]); `size` is the structure's, for the noise rule.
fn with_spectra(out: Vec<Figure>, r: &Response, modes: &ModalAnalysis, size: f64) -> Vec<Figure> {
    let spectra = r.modal.spectrum(modes, &r.channels);
    // A channel whose every amplitude is rounding against its quantity's largest names no
    // mode (the rule of `clean`, which also draws its lines as zero).
    let largest = |j: usize| spectra[j].iter().fold(0.0_f64, |m, l| m.max(l.1));
    let mut noise = NoiseReference::new(size);
    for (j, c) in r.channels.iter().enumerate() {
        noise.observe(c.unit, largest(j));
    }
    let carries: Vec<bool> = (0..r.channels.len())
        .map(|j| largest(j) > 0.0 && !noise.is_noise(r.channels[j].unit, largest(j)))
        .collect();
    out.into_iter()
        .flat_map(|f| {
            let sp = spectrum_figure(&f, r, &spectra, &carries);
            std::iter::once(f).chain(sp)
        })
        .collect()
}

/// The amplitude spectrum of a response history figure `f` (its curves are channels, by
/// label): per channel, a line from zero up to each kept mode's amplitude at the mode's
/// frequency ([`crate::response::ModalResponse::spectrum`]), the title naming the modes that
/// carry the most among the channels flagged in `carries`. None for a figure whose curves
/// are not channels.
fn spectrum_figure(
    f: &Figure,
    r: &Response,
    spectra: &[Vec<(f64, f64, usize)>],
    carries: &[bool],
) -> Option<Figure> {
    let idx: Vec<usize> = f
        .curves
        .iter()
        .map(|c| r.channels.iter().position(|ch| ch.label == c.0))
        .collect::<Option<_>>()?;
    if idx.is_empty() {
        return None;
    }
    let curves: Vec<Curve> = idx
        .iter()
        .map(|&j| {
            let mut lines = spectra[j].clone();
            lines.sort_by(|a, b| a.0.total_cmp(&b.0));
            let xs = lines.iter().flat_map(|l| [l.0, l.0, l.0]).collect();
            let ys = lines.iter().flat_map(|l| [0.0, l.1, 0.0]).collect();
            (format!("{}: amplitude", r.channels[j].label), xs, ys)
        })
        .collect();
    // The three modes with the largest amplitude in any of the figure's channels.
    let mut top: Vec<(f64, f64, usize)> = Vec::new();
    for &j in idx.iter().filter(|&&j| carries[j]) {
        for &(hz, a, n) in &spectra[j] {
            match top.iter_mut().find(|t| t.2 == n) {
                Some(t) => t.1 = t.1.max(a),
                None => top.push((hz, a, n)),
            }
        }
    }
    top.sort_by(|a, b| b.1.total_cmp(&a.1));
    let carriers: Vec<String> = top
        .iter()
        .take(3)
        .filter(|t| t.1 > 0.0)
        .map(|t| {
            // Four significant digits.
            let decimals = (3 - t.0.abs().log10().floor() as i32).clamp(0, 6) as usize;
            format!("{:.*}", decimals, t.0)
        })
        .collect();
    // The history's title without its envelope note and its parenthesis.
    let base = f.title.split(" — ").next().unwrap_or(&f.title);
    let base = base.split(" (").next().unwrap_or(base);
    Some(Figure {
        stem: format!("{}_spectrum", f.stem),
        title: if carriers.is_empty() {
            format!("{base}: amplitude of each kept mode (none: rounding only)")
        } else {
            format!(
                "{base}: amplitude of each kept mode (largest at {} Hz)",
                carriers.join(", ")
            )
        },
        xlabel: "f [Hz]",
        ylabel: f.ylabel,
        curves,
        markers: Vec::new(),
    })
}

/// A deployment quantity: its envelope from the solution where the run kept one for
/// `trace`, else its samples `0..n` (decimated).
fn traced(
    env: Option<&Envelope>,
    trace: Option<Trace>,
    name: String,
    n: usize,
    x: impl Fn(usize) -> f64,
    y: impl Fn(usize) -> f64,
) -> Curve {
    match env.zip(trace).and_then(|(e, tr)| e.points(tr)) {
        Some(points) => (
            name,
            points.iter().map(|p| p.0).collect(),
            points.iter().map(|p| p.1).collect(),
        ),
        None => curve(name, n, x, y),
    }
}

/// A deployment figure's title, saying when it draws the solution's envelope.
fn deployment_title(title: &str, env: Option<&Envelope>) -> String {
    match env {
        Some(e) => format!(
            "{title} — min/max envelope ({} Hz samples alias {:.3} Hz)",
            e.output_rate, e.fastest_hz
        ),
        None => title.to_string(),
    }
}

/// Response channel `j`: its samples (decimated), or its min/max envelope from the solution
/// where the samples would alias.
fn channel_curve(r: &Response, env: Option<&[Vec<(f64, f64)>]>, j: usize, c: &Channel) -> Curve {
    match env.and_then(|e| e.get(j)) {
        Some(points) => (
            c.label.clone(),
            points.iter().map(|p| p.0).collect(),
            points.iter().map(|p| p.1).collect(),
        ),
        None => {
            let hist = &r.history;
            curve(
                c.label.clone(),
                hist.times.len(),
                |k| hist.times[k],
                |k| hist.values[(k, j)],
            )
        }
    }
}

/// A response figure's title, saying when it draws the solution's envelope.
fn envelope_title(title: String, env: Option<&[Vec<(f64, f64)>]>) -> String {
    if env.is_some() {
        format!("{title} — min/max envelope of the solution (the samples alias)")
    } else {
        title
    }
}

/// The response's load figures: every beam's root moment, and the latch moments.
fn load_figures(
    s: &Scenario,
    r: &Response,
    stems: &[String],
    env: Option<&[Vec<(f64, f64)>]>,
) -> Vec<Figure> {
    let pick = |f: &dyn Fn(&Channel) -> bool| -> Vec<Curve> {
        r.channels
            .iter()
            .enumerate()
            .filter(|(_, c)| f(c))
            .map(|(j, c)| channel_curve(r, env, j, c))
            .collect()
    };
    let fig = |stem: String, title: String, curves| Figure {
        markers: Vec::new(),
        stem,
        title: envelope_title(title, env),
        xlabel: "t after the latch [s]",
        ylabel: "moment [N·m]",
        curves,
    };
    let mut out = Vec::new();
    for (b, stem) in s.structure.beams.iter().zip(stems) {
        let kind = ChannelKind::BeamRoot {
            beam: b.name.clone(),
        };
        out.push(fig(
            format!("response_{stem}_root_moment"),
            format!(
                "{} root moment (parent on beam, about its root point)",
                b.name
            ),
            pick(&|c| c.kind == kind && c.unit == "N·m"),
        ));
    }
    let latches = pick(&|c| matches!(c.kind, ChannelKind::LatchMoment { .. }));
    if !latches.is_empty() {
        out.push(fig(
            "response_latch_moments".into(),
            "latch moments in the deployed wing".into(),
            latches,
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_coinciding_curve_names_the_other_by_what_differs() {
        use super::short_name;
        assert_eq!(
            short_name("latch moment, hinge 3", "latch moment, hinge 2"),
            "hinge 2"
        );
        assert_eq!(short_name("mast tip v", "wing tip w"), "wing tip w");
        assert_eq!(short_name("hinge 12", "hinge 1"), "hinge 1");
    }

    use super::*;

    fn signal(n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let t = k as f64 * 1e-3;
                (7.0 * t).sin() * (-0.1 * t).exp() + 0.3 * (313.0 * t).sin()
            })
            .collect()
    }

    #[test]
    fn short_series_are_unchanged() {
        for n in [0, 1, 2, 5, PLOT_POINTS] {
            assert_eq!(
                decimate(n, |k| k as f64, PLOT_POINTS),
                (0..n).collect::<Vec<_>>()
            );
        }
    }

    #[test]
    fn long_series_keep_ends_order_and_every_extremum() {
        for n in [PLOT_POINTS + 1, 10_007, 1_000_000] {
            let mut y = signal(n);
            // Isolated spikes, one sample wide, must survive.
            y[n / 3] = 50.0;
            y[2 * n / 3] = -60.0;
            let idx = decimate(n, |k| y[k], PLOT_POINTS);
            assert!(
                idx.len() <= PLOT_POINTS && idx.len() > PLOT_POINTS / 2,
                "{n}: {}",
                idx.len()
            );
            assert_eq!((idx[0], *idx.last().unwrap()), (0, n - 1));
            assert!(idx.windows(2).all(|w| w[0] < w[1]), "{n}: not increasing");
            let kept: Vec<f64> = idx.iter().map(|&k| y[k]).collect();
            let max = |v: &[f64]| v.iter().copied().fold(f64::MIN, f64::max);
            let min = |v: &[f64]| v.iter().copied().fold(f64::MAX, f64::min);
            assert_eq!(max(&kept), 50.0);
            assert_eq!(min(&kept), -60.0);
            // Every run's minimum and maximum are kept (the runs as documented).
            let (inner, runs) = (n - 2, (PLOT_POINTS - 2) / 2);
            for b in 0..runs {
                let run = &y[1 + b * inner / runs..1 + (b + 1) * inner / runs];
                assert!(
                    kept.contains(&max(run)) && kept.contains(&min(run)),
                    "{n}: run {b}"
                );
            }
        }
    }

    #[test]
    fn nan_is_not_picked_over_numbers() {
        let n = 20_000;
        let mut y = signal(n);
        y[1000] = f64::NAN;
        let idx = decimate(n, |k| y[k], 100);
        assert!(idx.iter().all(|&k| k != 1000));
        assert!(idx.len() <= 100);
    }
}
