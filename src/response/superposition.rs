//! Response by modal superposition, exact in time (docs/theory.md §3).
//!
//! With q = Σ_j φ_j η_j (mass-normalised modes), every mode obeys
//! η̈_j + 2ζω_j η̇_j + ω_j² η_j = 0 after the hand-over, solved in closed form:
//!
//! * rigid (ω = 0): η = η₀ + η̇₀ t — the momentum the latch left in the spacecraft;
//! * elastic, 0 ≤ ζ < 1, ω_d = ω√(1 − ζ²):
//!   η = e^{−ζωt} [η₀ cos ω_d t + (η̇₀ + ζωη₀)/ω_d · sin ω_d t].
//!
//! No time stepping: an undamped mode keeps its energy ½(η̇² + ω²η²) to rounding for any
//! duration, and the samples t_k = k/rate are exact.

use super::channels::{Channel, Order};
use super::ResponseSettings;
use crate::ritz::ModalAnalysis;
use faer::Mat;

/// One mode kept in the response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeptMode {
    /// Mode number in the modal analysis (1-based).
    pub number: usize,
    /// Rigid-body mode.
    pub rigid: bool,
    /// ω, rad/s.
    pub omega_rad_s: f64,
    /// η(0).
    pub eta0: f64,
    /// η̇(0).
    pub eta_dot0: f64,
}

/// The modal model of the response.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalResponse {
    /// Kept modes: every rigid mode, then the first elastic ones.
    pub modes: Vec<KeptMode>,
    /// ζ of every elastic mode.
    pub damping_ratio: f64,
    /// Elastic modes the model has.
    pub available_elastic: usize,
    /// Elastic modes requested (before clamping to the model).
    pub requested_elastic: Option<usize>,
    /// Fraction of the hand-over kinetic energy carried by the kept modes.
    pub captured_energy_fraction: f64,
}

/// Sampled response.
#[derive(Debug, Clone)]
pub struct ResponseHistory {
    /// Sample times after the final latch, s (t_k = k / rate).
    pub times: Vec<f64>,
    /// Channel values, samples × channels.
    pub values: Mat<f64>,
    /// Modal amplitudes η_j, samples × kept modes.
    pub modal: Mat<f64>,
    /// Elastic energy Σ_elastic ½(η̇² + ω²η²) at every sample, J.
    pub elastic_energy: Vec<f64>,
}

impl ModalResponse {
    /// Keeps every rigid mode and the first `settings.modes` elastic ones (all when `None`,
    /// clamped to the model's number), starting from η₀ = 0 and η̇₀ = `modal_velocity`.
    pub fn new(modal: &ModalAnalysis, modal_velocity: &[f64], settings: &ResponseSettings) -> Self {
        let zero = vec![0.0; modal_velocity.len()];
        Self::with_initial(modal, &zero, modal_velocity, settings)
    }

    /// As [`ModalResponse::new`], starting from η₀ = `modal_displacement`; the captured energy
    /// counts kinetic and elastic energy, ½(η̇² + ω²η²) per mode.
    pub fn with_initial(
        modal: &ModalAnalysis,
        modal_displacement: &[f64],
        modal_velocity: &[f64],
        settings: &ResponseSettings,
    ) -> Self {
        let available = modal.modes.iter().filter(|m| !m.rigid).count();
        let keep = settings.modes.unwrap_or(available).min(available);
        let mut elastic_seen = 0;
        let mut modes = Vec::new();
        let (mut kept_e, mut total_e) = (0.0, 0.0);
        for ((m, &v), &e) in modal
            .modes
            .iter()
            .zip(modal_velocity)
            .zip(modal_displacement)
        {
            let energy = 0.5 * (v * v + (m.omega_rad_s * e).powi(2));
            total_e += energy;
            let take = m.rigid || {
                elastic_seen += 1;
                elastic_seen <= keep
            };
            if take {
                kept_e += energy;
                modes.push(KeptMode {
                    number: m.number,
                    rigid: m.rigid,
                    omega_rad_s: m.omega_rad_s,
                    eta0: e,
                    eta_dot0: v,
                });
            }
        }
        Self {
            modes,
            damping_ratio: settings.damping_ratio,
            available_elastic: available,
            requested_elastic: settings.modes,
            captured_energy_fraction: if total_e > 0.0 { kept_e / total_e } else { 1.0 },
        }
    }

    /// Number of elastic modes kept.
    pub fn kept_elastic(&self) -> usize {
        self.modes.iter().filter(|m| !m.rigid).count()
    }

    /// (η, η̇) of kept mode j at time t.
    pub fn state(&self, j: usize, t: f64) -> (f64, f64) {
        state(&self.modes[j], self.damping_ratio, t)
    }

    /// Samples the response at t_k = k/rate, k = 0…rows−1, into the given channels.
    pub fn sample(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
        settings: &ResponseSettings,
    ) -> ResponseHistory {
        let rows = settings.rows() as usize;
        let nm = self.modes.len();
        let times: Vec<f64> = (0..rows).map(|k| k as f64 / settings.output_rate).collect();
        // Channel gains G_jc = c · φ_j, split by the derivative each channel reads.
        let gain = |order: Order| {
            Mat::from_fn(nm, channels.len(), |j, c| {
                if channels[c].order != order {
                    return 0.0;
                }
                let shape = &modal.modes[self.modes[j].number - 1].shape;
                channels[c]
                    .row
                    .iter()
                    .zip(shape)
                    .map(|(a, b)| a * b)
                    .sum::<f64>()
            })
        };
        let mut eta = Mat::<f64>::zeros(rows, nm);
        let mut eta_dd = Mat::<f64>::zeros(rows, nm);
        let mut energy = vec![0.0; rows];
        let h = 1.0 / settings.output_rate;
        let mut acc = vec![0.0; rows];
        for (j, m) in self.modes.iter().enumerate() {
            let col = eta
                .col_mut(j)
                .try_as_col_major_mut()
                .expect("a fresh Mat is column-major")
                .as_slice_mut();
            fill_mode(m, self.damping_ratio, h, col, &mut acc, &mut energy);
            for (k, a) in acc.iter().enumerate() {
                eta_dd[(k, j)] = *a;
            }
        }
        let mut values = &eta * gain(Order::Displacement);
        if channels.iter().any(|c| c.order == Order::Acceleration) {
            values += &eta_dd * gain(Order::Acceleration);
        }
        for (c, ch) in channels.iter().enumerate() {
            if ch.offset != 0.0 {
                for k in 0..rows {
                    values[(k, c)] += ch.offset;
                }
            }
        }
        ResponseHistory {
            times,
            values,
            modal: eta,
            elastic_energy: energy,
        }
    }
}

/// Samples at t_k = k·h of one mode into `eta` and its acceleration
/// η̈ = −2ζωη̇ − ω²η into `eta_dd`, adding its energy to `energy` (elastic modes).
/// Within blocks of [`RESYNC`] samples the phase advances by the rotation
/// (cos, sin)(θ + ω_d h) = (c cos ω_d h − s sin ω_d h, s cos ω_d h + c sin ω_d h) and the decay
/// by the factor e^{−ζωh}; each block starts from the closed form at t = k·h, so rounding
/// cannot accumulate beyond RESYNC steps (≈ 1e-14 relative).
fn fill_mode(
    m: &KeptMode,
    zeta: f64,
    h: f64,
    eta: &mut [f64],
    eta_dd: &mut [f64],
    energy: &mut [f64],
) {
    if m.rigid || m.omega_rad_s == 0.0 {
        for (k, e) in eta.iter_mut().enumerate() {
            *e = m.eta0 + m.eta_dot0 * (k as f64 * h);
        }
        eta_dd.fill(0.0);
        return;
    }
    let w = m.omega_rad_s;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let (a, b) = (m.eta0, (m.eta_dot0 + zeta * w * m.eta0) / wd);
    let (sd, cd) = (wd * h).sin_cos();
    let step_decay = (-zeta * w * h).exp();
    for k0 in (0..eta.len()).step_by(RESYNC) {
        let t0 = k0 as f64 * h;
        let (mut s, mut c) = (wd * t0).sin_cos();
        let mut decay = (-zeta * w * t0).exp();
        let end = (k0 + RESYNC).min(eta.len());
        for k in k0..end {
            let e = decay * (a * c + b * s);
            let ed = -zeta * w * e + decay * wd * (b * c - a * s);
            eta[k] = e;
            eta_dd[k] = -2.0 * zeta * w * ed - w * w * e;
            energy[k] += 0.5 * (ed * ed + w * w * e * e);
            (s, c) = (s * cd + c * sd, c * cd - s * sd);
            decay *= step_decay;
        }
    }
}

/// Samples between two closed-form evaluations in [`fill_mode`].
const RESYNC: usize = 32;

fn state(m: &KeptMode, zeta: f64, t: f64) -> (f64, f64) {
    if m.rigid || m.omega_rad_s == 0.0 {
        return (m.eta0 + m.eta_dot0 * t, m.eta_dot0);
    }
    let w = m.omega_rad_s;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let (s, c) = (wd * t).sin_cos();
    let decay = (-zeta * w * t).exp();
    let b = (m.eta_dot0 + zeta * w * m.eta0) / wd;
    let eta = decay * (m.eta0 * c + b * s);
    // d/dt: −ζω η + e^{−ζωt}[−η₀ ω_d sin + b ω_d cos].
    let eta_dot = -zeta * w * eta + decay * wd * (b * c - m.eta0 * s);
    (eta, eta_dot)
}

impl ResponseHistory {
    /// Largest |E(t) − E(0)| / E(0) of the elastic energy (0 when there is none).
    pub fn energy_drift(&self) -> f64 {
        let e0 = self.elastic_energy.first().copied().unwrap_or(0.0);
        if e0 <= 0.0 {
            return 0.0;
        }
        self.elastic_energy
            .iter()
            .map(|e| (e - e0).abs() / e0)
            .fold(0.0, f64::max)
    }

    /// Largest |value| of channel c and the time it occurs.
    pub fn peak(&self, c: usize) -> (f64, f64) {
        let mut best = (0.0, 0.0);
        for (k, &t) in self.times.iter().enumerate() {
            let v = self.values[(k, c)];
            if v.abs() > best.0 {
                best = (v.abs(), t);
            }
        }
        best
    }

    /// The value of channel c at the last sample.
    pub fn last(&self, c: usize) -> f64 {
        self.values[(self.times.len() - 1, c)]
    }
}
