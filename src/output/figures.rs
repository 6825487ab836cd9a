//! The figures of the deployment and of the response, defined once: drawn as PNG+SVG files
//! ([`super::plot::line_chart`]) and as interactive charts in the HTML report.

use crate::deploy::{Deployment, DeploymentResult, Sample};
use crate::response::{Channel, ChannelKind};
use crate::scenario::Scenario;
use crate::simulation::Response;

/// One curve: name, x and y samples.
pub type Curve = (String, Vec<f64>, Vec<f64>);

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
}

impl Figure {
    /// plots/STEM.png and .svg.
    pub fn draw(&self, dir: &mut super::OutputDir) -> Result<(), super::OutputError> {
        super::plot::line_chart(
            dir,
            &self.stem,
            &self.title,
            (self.xlabel, self.ylabel),
            &self.series(),
            false,
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

/// Angles, rates, hinge reaction magnitudes (up to 8 hinges shown) and hub motion.
pub fn deployment_figures(d: &Deployment, r: &DeploymentResult) -> Vec<Figure> {
    let n = d.chain.len();
    let shown: Vec<usize> = (0..n).step_by(n.div_ceil(8).max(1)).collect();
    let t: Vec<f64> = r.samples.iter().map(|s| s.t).collect();
    let per_hinge = |f: &dyn Fn(&Sample, usize) -> f64| -> Vec<Curve> {
        shown
            .iter()
            .map(|&i| {
                (
                    format!("hinge {}", i + 1),
                    t.clone(),
                    r.samples.iter().map(|s| f(s, i)).collect(),
                )
            })
            .collect()
    };
    let fig = |stem: &str, title: &str, ylabel: &'static str, curves| Figure {
        stem: stem.into(),
        title: title.into(),
        xlabel: "t [s]",
        ylabel,
        curves,
    };
    let hub: Vec<Curve> = ["u [m]", "v [m]", "θ [rad]"]
        .iter()
        .enumerate()
        .map(|(k, l)| {
            (
                format!("hub {l}"),
                t.clone(),
                r.samples.iter().map(|s| s.hub[k]).collect(),
            )
        })
        .collect();
    vec![
        fig(
            "angles",
            "opening angles",
            "α [rad]",
            per_hinge(&|s, i| s.alpha[i]),
        ),
        fig(
            "rates",
            "opening rates",
            "α̇ [rad/s]",
            per_hinge(&|s, i| s.rate[i]),
        ),
        fig(
            "reactions",
            "hinge reaction force magnitude (inboard body on panel i)",
            "|F| [N]",
            per_hinge(&|s, i| s.force[i][0].hypot(s.force[i][1])),
        ),
        fig(
            "hub",
            "hub motion in the deployment plane",
            "u, v [m]; θ [rad]",
            hub,
        ),
    ]
}

/// The paper's figures 2.4–2.7 (every beam's tip deflection and twist, every plate's tip
/// corners, hub translation and rotation) and the first eight elastic modal amplitudes.
pub fn response_figures(s: &Scenario, r: &Response) -> Vec<Figure> {
    let hist = &r.history;
    let t = &hist.times;
    let pick = |f: &dyn Fn(&Channel) -> bool| -> Vec<Curve> {
        r.channels
            .iter()
            .enumerate()
            .filter(|(_, c)| f(c))
            .map(|(j, c)| {
                (
                    c.label.clone(),
                    t.clone(),
                    (0..t.len()).map(|k| hist.values[(k, j)]).collect(),
                )
            })
            .collect()
    };
    let fig = |stem: String, title: String, ylabel: &'static str, curves| Figure {
        stem,
        title,
        xlabel: "t after the latch [s]",
        ylabel,
        curves,
    };
    let mut out = Vec::new();
    for b in &s.structure.beams {
        let kind = ChannelKind::BeamTip {
            beam: b.name.clone(),
        };
        out.push(fig(
            format!("response_{}_tip", b.name),
            format!(
                "{} tip: elastic deflection in both bending planes (fig. 2.4)",
                b.name
            ),
            "deflection [m]",
            pick(&|c| c.kind == kind && c.unit == "m"),
        ));
        out.push(fig(
            format!("response_{}_twist", b.name),
            format!("{} tip: elastic twist (fig. 2.4)", b.name),
            "twist [rad]",
            pick(&|c| c.kind == kind && c.unit == "rad"),
        ));
    }
    for p in &s.structure.plates {
        let kind = ChannelKind::PlateTip {
            plate: p.name.clone(),
        };
        out.push(fig(
            format!("response_{}_tip", p.name),
            format!("{} tip corners: elastic deflection (fig. 2.5)", p.name),
            "deflection [m]",
            pick(&|c| c.kind == kind),
        ));
    }
    out.push(fig(
        "response_hub_translation".into(),
        "hub translation along the structure axes (fig. 2.6)".into(),
        "translation [m]",
        pick(&|c| c.kind == ChannelKind::HubTranslation),
    ));
    out.push(fig(
        "response_hub_rotation".into(),
        "hub rotation about the structure axes (fig. 2.7)".into(),
        "rotation [rad]",
        pick(&|c| c.kind == ChannelKind::HubRotation),
    ));
    let modal: Vec<Curve> = r
        .modal
        .modes
        .iter()
        .enumerate()
        .filter(|(_, m)| !m.rigid)
        .take(8)
        .map(|(j, m)| {
            (
                format!(
                    "mode {} ({:.3} Hz)",
                    m.number,
                    m.omega / (2.0 * std::f64::consts::PI)
                ),
                t.clone(),
                (0..t.len()).map(|k| hist.modal[(k, j)]).collect(),
            )
        })
        .collect();
    out.push(fig(
        "response_modal_amplitudes".into(),
        "modal amplitudes of the first elastic modes".into(),
        "η [√kg·m]",
        modal,
    ));
    out
}
