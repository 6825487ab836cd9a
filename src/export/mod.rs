//! The linear model of the deployed spacecraft for a control engineer's tools: modal data,
//! the rigid-body mass matrix, modal participation, second-order (`mechss`) and first-order
//! (A, B, C, D) state-space forms with named inputs and outputs, and frequency responses.
//!
//! Conventions (docs/export.md):
//! - Frame: the structure (hub) frame; the hub's force and torque act at, and its position
//!   and attitude are read at, the hub's reference point (the frame's origin).
//! - Modal coordinates η: the modes of [`ModalAnalysis`] (rigid first when the hub is free),
//!   mass-normalised, φᵀ M φ = 1; the physical coordinates are q = Φ η.
//! - Second order: M η̈ + C η̇ + K η = B u, y = F η + G η̇ + D u with M = I,
//!   K = diag(ω_j²), C = diag(2 ζ_j ω_j), B = Φᵀ Bq (Bq: the generalized forces of unit
//!   inputs, Bq = Jᵀ for a force or torque at a point whose motion is J q), F and G the
//!   displacement and velocity output maps J Φ, D = 0.
//! - First order: x = [η; η̇], A = [[0, I], [−K, −C]], B₁ = [0; B], C₁ = [F, G], D₁ = 0.
//!   Rigid modes (ω = 0, ζ = 0) are double integrators.
//! - Damping: modal (proportional) damping ζ_j on the elastic modes, none on rigid ones; in
//!   physical coordinates C_q = M Φ diag(2ζω) Φᵀ M when every mode is kept.

pub mod mass;
pub mod points;

pub use mass::{element_count, mass_elements, MassElement};
pub use points::{point_jacobian, point_motion, point_position, NamedPoint, PointLocation};

use crate::math::Vec3;
use crate::ritz::{ModalAnalysis, RitzModel};
use crate::structure::HubMotion;
use faer::{c64, Mat};
use points::HUB_REFERENCE;

/// Default modal damping ratio of the exported elastic modes.
pub const DEFAULT_DAMPING_RATIO: f64 = 0.005;
/// Default number of frequencies of the frequency response (before the resonances are
/// added).
pub const DEFAULT_FREQUENCY_POINTS: usize = 200;

/// Modal damping of the kept elastic modes.
#[derive(Debug, Clone, PartialEq)]
pub enum Damping {
    /// One ratio for every elastic mode.
    Uniform(f64),
    /// One ratio per kept elastic mode, in order.
    PerMode(Vec<f64>),
}

/// One transfer function: an input's name and an output's name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Transfer {
    /// Input name (see [`input_names`]).
    pub input: String,
    /// Output name (see [`output_names`]).
    pub output: String,
}

/// What to export (`[export]` of a scenario).
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSettings {
    /// Elastic modes kept (None: every mode the model has).
    pub modes: Option<usize>,
    /// Modal damping of the elastic modes.
    pub damping: Damping,
    /// Named points: inputs (force, torque) and outputs (displacement, rotation, velocity).
    pub points: Vec<NamedPoint>,
    /// Transfer functions of the frequency response (empty: the defaults of
    /// [`default_transfers`]).
    pub transfers: Vec<Transfer>,
    /// Frequency range of the response, Hz (None: from the kept modes).
    pub frequency_range_hz: Option<(f64, f64)>,
    /// Log-spaced frequencies of the response (the resonances are added to them).
    pub frequency_points: usize,
}

impl Default for ExportSettings {
    fn default() -> Self {
        Self {
            modes: None,
            damping: Damping::Uniform(DEFAULT_DAMPING_RATIO),
            points: Vec::new(),
            transfers: Vec::new(),
            frequency_range_hz: None,
            frequency_points: DEFAULT_FREQUENCY_POINTS,
        }
    }
}

/// Failures of the export that the scenario layer cannot see in advance.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The per-mode damping list does not match the kept modes.
    #[error("damping_ratio lists {given} values but {kept} elastic modes are kept")]
    DampingLength {
        /// Values given.
        given: usize,
        /// Modes kept.
        kept: usize,
    },
    /// A transfer names a channel that does not exist.
    #[error("unknown {what} \"{name}\"")]
    UnknownChannel {
        /// "input" or "output".
        what: &'static str,
        /// The name.
        name: String,
    },
}

/// The six input components of a point: force [N] and torque [N·m].
const INPUT_SUFFIXES: [&str; 6] = ["fx", "fy", "fz", "tx", "ty", "tz"];
/// The hub's twelve outputs: position [m], attitude [rad], velocity [m/s], rate [rad/s].
const HUB_OUTPUTS: [&str; 12] = [
    "x", "y", "z", "rx", "ry", "rz", "vx", "vy", "vz", "wx", "wy", "wz",
];
/// A point's nine outputs: displacement [m], rotation [rad], velocity [m/s].
const POINT_OUTPUTS: [&str; 9] = ["ux", "uy", "uz", "rx", "ry", "rz", "vx", "vy", "vz"];

/// The names of the sites: the hub, then each named point.
fn site_names(points: &[NamedPoint]) -> impl Iterator<Item = &str> {
    std::iter::once("hub").chain(points.iter().map(|p| p.name.as_str()))
}

/// Input names, in the order of B's columns: `hub.fx … hub.tz`, then `<point>.fx …` for
/// every named point.
pub fn input_names(points: &[NamedPoint]) -> Vec<String> {
    site_names(points)
        .flat_map(|s| INPUT_SUFFIXES.iter().map(move |c| format!("{s}.{c}")))
        .collect()
}

/// Output names, in the order of C's rows: `hub.x hub.y hub.z hub.rx … hub.wz`, then
/// `<point>.ux … <point>.vz` for every named point.
pub fn output_names(points: &[NamedPoint]) -> Vec<String> {
    let hub = HUB_OUTPUTS.iter().map(|c| format!("hub.{c}"));
    let pts = points
        .iter()
        .flat_map(|p| POINT_OUTPUTS.iter().map(move |c| format!("{}.{c}", p.name)));
    hub.chain(pts).collect()
}

/// The SI unit of an input or output, from its name's suffix.
pub fn channel_unit(name: &str) -> &'static str {
    match name.rsplit('.').next().unwrap_or("") {
        "fx" | "fy" | "fz" => "N",
        "tx" | "ty" | "tz" => "N·m",
        "x" | "y" | "z" | "ux" | "uy" | "uz" => "m",
        "rx" | "ry" | "rz" => "rad",
        "vx" | "vy" | "vz" => "m/s",
        "wx" | "wy" | "wz" => "rad/s",
        _ => "",
    }
}

/// The unit of a transfer function from `input` to `output`, e.g. `rad/(N·m)`.
pub fn transfer_unit(input: &str, output: &str) -> String {
    let i = channel_unit(input);
    if i.contains('·') {
        format!("{}/({i})", channel_unit(output))
    } else {
        format!("{}/{i}", channel_unit(output))
    }
}

/// The default transfer functions: hub torque → hub attitude about each axis (collocated).
/// With a fixed hub (the hub's inputs move nothing), each named point's force → its
/// displacement along the same axis instead.
pub fn default_transfers(motion: HubMotion, points: &[NamedPoint]) -> Vec<Transfer> {
    let t = |i: String, o: String| Transfer {
        input: i,
        output: o,
    };
    match motion {
        HubMotion::Free => ["x", "y", "z"]
            .iter()
            .map(|a| t(format!("hub.t{a}"), format!("hub.r{a}")))
            .collect(),
        HubMotion::Fixed => points
            .iter()
            .flat_map(|p| {
                ["x", "y", "z"]
                    .iter()
                    .map(move |a| t(format!("{}.f{a}", p.name), format!("{}.u{a}", p.name)))
            })
            .collect(),
    }
}

/// One exported mode.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportMode {
    /// ω, rad/s (0 for a rigid mode).
    pub omega_rad_s: f64,
    /// Modal damping ratio ζ.
    pub damping_ratio: f64,
    /// Rigid-body mode.
    pub rigid: bool,
}

/// The exported linear model.
#[derive(Debug, Clone)]
pub struct ExportModel {
    /// Hub motion of the model.
    pub hub_motion: HubMotion,
    /// Kept modes (rigid first).
    pub modes: Vec<ExportMode>,
    /// Named points (the hub's reference point is implicit, first).
    pub points: Vec<NamedPoint>,
    /// Undeformed positions of the sites (hub reference point, then the points), m.
    pub site_positions: Vec<Vec3>,
    /// Mode shapes at the sites: row 6s + c is site s's [ux uy uz rx ry rz], column j mode j
    /// (mass-normalised: m / √kg, rad / √kg).
    pub site_shapes: Mat<f64>,
    /// Input map B (modes × inputs).
    pub b: Mat<f64>,
    /// Displacement output map F (outputs × modes).
    pub f: Mat<f64>,
    /// Velocity output map G (outputs × modes).
    pub g: Mat<f64>,
    /// Input names (B's columns).
    pub input_names: Vec<String>,
    /// Output names (F's and G's rows).
    pub output_names: Vec<String>,
    /// Total mass, kg.
    pub total_mass: f64,
    /// The system's centre of mass, structure frame, m.
    pub center_of_mass: Vec3,
    /// Rigid-body mass matrix of the whole structure about the hub's reference point,
    /// coordinates [u_O; θ] (row-major 6 × 6).
    pub rigid_mass_reference: [[f64; 6]; 6],
    /// The same about the system's centre of mass.
    pub rigid_mass_cm: [[f64; 6]; 6],
    /// Hub-fixed modes: ω [rad/s].
    pub hub_fixed_omega: Vec<f64>,
    /// Signed modal participation of the hub-fixed modes (6 × n_f): L_dj = φ_jᵀ M_{e,d},
    /// the hub's rigid motions d about its centre of mass.
    pub participation: Mat<f64>,
    /// Effective masses L_dj² (6 × n_f).
    pub effective_mass: Mat<f64>,
    /// Cumulative effective-mass fractions of the appendages' rigid mass (6 × n_f).
    pub effective_mass_fraction: Mat<f64>,
    /// Rigid mass of the appendages in the hub's six directions (the fractions' limit).
    pub appendage_mass: [f64; 6],
}

/// The kept elastic modes' damping ratios.
fn damping_ratios(d: &Damping, kept: usize) -> Result<Vec<f64>, ExportError> {
    match d {
        Damping::Uniform(z) => Ok(vec![*z; kept]),
        Damping::PerMode(v) if v.len() == kept => Ok(v.clone()),
        Damping::PerMode(v) => Err(ExportError::DampingLength {
            given: v.len(),
            kept,
        }),
    }
}

/// The rigid-body mass of the whole structure from the Ritz model's hub block (about the
/// hub's centre of mass c): M_O = Tᵀ M_c T for u_c = u_O − S(c) θ.
fn rigid_body_of(model: &RitzModel) -> crate::structure::RigidBody {
    let m = &model.mass;
    let mass = m[(0, 0)];
    let s = Vec3::new(m[(5, 1)], m[(3, 2)], m[(4, 0)]);
    let j = crate::math::Mat3(std::array::from_fn(|a| {
        std::array::from_fn(|b| m[(3 + a, 3 + b)])
    }));
    crate::structure::RigidBody {
        mass,
        first_moment: s,
        inertia: j,
    }
}

impl ExportModel {
    /// Builds the export from a model and its modes (from
    /// [`ModalAnalysis::compute_lowest`]: rigid modes, then at least the kept elastic
    /// ones).
    pub fn build(
        model: &RitzModel,
        modes: &ModalAnalysis,
        settings: &ExportSettings,
    ) -> Result<Self, ExportError> {
        let elastic: Vec<_> = modes.elastic().collect();
        let kept = settings.modes.unwrap_or(elastic.len()).min(elastic.len());
        // The latch lines' dashpots (docs/theory.md §1.6) add to the damping asked for.
        let lines = modes.line_damping_ratios(model);
        let zeta: Vec<f64> = damping_ratios(&settings.damping, kept)?
            .into_iter()
            .zip(elastic.iter())
            .map(|(z, m)| match lines[m.number - 1] {
                add if add > 0.0 => (z + add).min(crate::ritz::modes::MAX_ZETA.max(z)),
                _ => z,
            })
            .collect();
        let rigid: Vec<_> = modes.modes.iter().filter(|m| m.rigid).collect();
        let chosen: Vec<(&crate::ritz::Mode, f64)> = rigid
            .iter()
            .map(|m| (*m, 0.0))
            .chain(elastic.iter().take(kept).copied().zip(zeta))
            .collect();
        let nm = chosen.len();

        let st = &model.structure;
        let locations: Vec<PointLocation> = std::iter::once(HUB_REFERENCE)
            .chain(settings.points.iter().map(|p| p.location))
            .collect();
        let ns = locations.len();
        let mut site_shapes = Mat::<f64>::zeros(6 * ns, nm);
        for (j, (m, _)) in chosen.iter().enumerate() {
            for (s, loc) in locations.iter().enumerate() {
                let (u, th) = point_motion(model, loc, &m.shape);
                for c in 0..3 {
                    site_shapes[(6 * s + c, j)] = u.0[c];
                    site_shapes[(6 * s + 3 + c, j)] = th.0[c];
                }
            }
        }
        let input_names = input_names(&settings.points);
        let output_names = output_names(&settings.points);
        // B: column 6s + c is site s's force/torque component c: B_j = (J_s φ_j)_c.
        let b = Mat::from_fn(nm, 6 * ns, |j, i| site_shapes[(i, j)]);
        let (nf, mut f, mut g) = (
            output_names.len(),
            Mat::<f64>::zeros(output_names.len(), nm),
            Mat::<f64>::zeros(output_names.len(), nm),
        );
        debug_assert_eq!(nf, 12 + 9 * (ns - 1));
        for j in 0..nm {
            for c in 0..6 {
                f[(c, j)] = site_shapes[(c, j)];
                g[(6 + c, j)] = site_shapes[(c, j)];
            }
            for s in 1..ns {
                let row = 12 + 9 * (s - 1);
                for c in 0..6 {
                    f[(row + c, j)] = site_shapes[(6 * s + c, j)];
                }
                for c in 0..3 {
                    g[(row + 6 + c, j)] = site_shapes[(6 * s + c, j)];
                }
            }
        }

        let body = rigid_body_of(model);
        let c_hub = st.hub.center_of_mass;
        let about_ref = body.about(-c_hub);
        let cm = about_ref.center_of_mass();
        let about_cm = about_ref.about(cm);

        let nh = modes.hub_fixed.len();
        let fr = modes.effective_mass_fractions();
        let participation = Mat::from_fn(6, nh, |d, j| modes.hub_fixed[j].participation[d]);
        let effective_mass = Mat::from_fn(6, nh, |d, j| modes.hub_fixed[j].effective_mass[d]);
        let effective_mass_fraction = Mat::from_fn(6, nh, |d, j| fr[j][d]);

        Ok(Self {
            hub_motion: modes.hub_motion,
            modes: chosen
                .iter()
                .map(|(m, z)| ExportMode {
                    omega_rad_s: m.omega_rad_s,
                    damping_ratio: *z,
                    rigid: m.rigid,
                })
                .collect(),
            points: settings.points.clone(),
            site_positions: locations.iter().map(|l| point_position(st, l)).collect(),
            site_shapes,
            b,
            f,
            g,
            input_names,
            output_names,
            total_mass: about_ref.mass,
            center_of_mass: cm,
            rigid_mass_reference: about_ref.block(),
            rigid_mass_cm: about_cm.block(),
            hub_fixed_omega: modes.hub_fixed.iter().map(|h| h.omega_rad_s).collect(),
            participation,
            effective_mass,
            effective_mass_fraction,
            appendage_mass: modes.appendage_mass,
        })
    }

    /// Number of modal coordinates.
    pub fn mode_count(&self) -> usize {
        self.modes.len()
    }

    /// Modal stiffness K = diag(ω²).
    pub fn stiffness(&self) -> Mat<f64> {
        let n = self.mode_count();
        Mat::from_fn(n, n, |i, j| {
            if i == j {
                self.modes[i].omega_rad_s.powi(2)
            } else {
                0.0
            }
        })
    }

    /// Modal damping C = diag(2 ζ ω).
    pub fn damping(&self) -> Mat<f64> {
        let n = self.mode_count();
        Mat::from_fn(n, n, |i, j| {
            if i == j {
                2.0 * self.modes[i].damping_ratio * self.modes[i].omega_rad_s
            } else {
                0.0
            }
        })
    }

    /// The first-order form (A, B, C, D) with x = [η; η̇].
    pub fn first_order(&self) -> StateSpace {
        let n = self.mode_count();
        let (ni, no) = (self.input_names.len(), self.output_names.len());
        let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
        for j in 0..n {
            let (w, z) = (self.modes[j].omega_rad_s, self.modes[j].damping_ratio);
            a[(j, n + j)] = 1.0;
            a[(n + j, j)] = -w * w;
            a[(n + j, n + j)] = -2.0 * z * w;
        }
        let b = Mat::from_fn(
            2 * n,
            ni,
            |r, i| if r < n { 0.0 } else { self.b[(r - n, i)] },
        );
        let c = Mat::from_fn(no, 2 * n, |o, r| {
            if r < n {
                self.f[(o, r)]
            } else {
                self.g[(o, r - n)]
            }
        });
        StateSpace {
            a,
            b,
            c,
            d: Mat::zeros(no, ni),
            state_names: (1..=n)
                .map(|j| format!("eta_{j}"))
                .chain((1..=n).map(|j| format!("eta_dot_{j}")))
                .collect(),
        }
    }

    /// Index of an input by name.
    pub fn input_index(&self, name: &str) -> Result<usize, ExportError> {
        self.input_names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| ExportError::UnknownChannel {
                what: "input",
                name: name.to_string(),
            })
    }

    /// Index of an output by name.
    pub fn output_index(&self, name: &str) -> Result<usize, ExportError> {
        self.output_names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| ExportError::UnknownChannel {
                what: "output",
                name: name.to_string(),
            })
    }

    /// The transfer function from input `i` to output `o` at ω [rad/s], by modal
    /// superposition: H(iω) = Σ_j (F_oj + iω G_oj) B_ji / (ω_j² − ω² + 2iζ_jω_jω).
    pub fn transfer(&self, o: usize, i: usize, omega: f64) -> c64 {
        let mut h = c64::new(0.0, 0.0);
        for (j, m) in self.modes.iter().enumerate() {
            let bji = self.b[(j, i)];
            if bji == 0.0 {
                continue;
            }
            let num = c64::new(self.f[(o, j)] * bji, omega * self.g[(o, j)] * bji);
            let den = c64::new(
                m.omega_rad_s * m.omega_rad_s - omega * omega,
                2.0 * m.damping_ratio * m.omega_rad_s * omega,
            );
            h += num / den;
        }
        h
    }

    /// The response's frequencies \[Hz\]: `points` log-spaced over the range (default: a
    /// decade below the lowest elastic mode to 1.5 times the highest kept), with every kept
    /// resonance f_j and its half-power points f_j (1 ± ζ_j) added (damped modes only),
    /// sorted.
    pub fn frequency_grid(&self, range_hz: Option<(f64, f64)>, points: usize) -> Vec<f64> {
        let two_pi = 2.0 * std::f64::consts::PI;
        let elastic: Vec<&ExportMode> = self.modes.iter().filter(|m| !m.rigid).collect();
        let (lo, hi) = range_hz.unwrap_or_else(|| match (elastic.first(), elastic.last()) {
            (Some(a), Some(b)) => (0.1 * a.omega_rad_s / two_pi, 1.5 * b.omega_rad_s / two_pi),
            _ => (0.01, 100.0),
        });
        let n = points.max(2);
        let mut f: Vec<f64> = (0..n)
            .map(|k| lo * (hi / lo).powf(k as f64 / (n - 1) as f64))
            .collect();
        // An undamped mode's resonance is infinite: its point is not added (a log-spaced
        // point that meets it is left out by the writers).
        for m in elastic.iter().filter(|m| m.damping_ratio > 0.0) {
            let fj = m.omega_rad_s / two_pi;
            for x in [
                fj * (1.0 - m.damping_ratio),
                fj,
                fj * (1.0 + m.damping_ratio),
            ] {
                if x >= lo && x <= hi {
                    f.push(x);
                }
            }
        }
        f.sort_by(f64::total_cmp);
        f.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
        f
    }
}

/// A first-order state-space model ẋ = A x + B u, y = C x + D u.
#[derive(Debug, Clone)]
pub struct StateSpace {
    /// A (2n × 2n).
    pub a: Mat<f64>,
    /// B (2n × inputs).
    pub b: Mat<f64>,
    /// C (outputs × 2n).
    pub c: Mat<f64>,
    /// D (outputs × inputs), zero.
    pub d: Mat<f64>,
    /// `eta_j` then `eta_dot_j`.
    pub state_names: Vec<String>,
}
