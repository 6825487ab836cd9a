//! The end-to-end run behind `flexcraft simulate`: modes of the deployed structure, the
//! deployment, the hand-over at the final latch and the latch-excited response
//! (docs/theory.md; the paper's section 2).

use crate::deploy::coupled::Coupled;
use crate::deploy::{self, DeployError, DeploymentResult};
use crate::response::channels::standard_channels;
use crate::response::handover::hand_over_coupled;
use crate::response::loads::{beam_root_channels, latch_channels};
use crate::response::{Channel, Handover, ModalResponse, ResponseError, ResponseHistory};
use crate::ritz::{ModalAnalysis, RitzError, RitzModel};
use crate::scenario::Scenario;
use crate::warning::Warning;

/// Why `simulate` could not run at all.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimulationError {
    /// `simulate` needs a `[deployment]` section.
    #[error("the scenario has no [deployment] section (see docs/scenario.md)")]
    NoDeployment,
    /// The modal analysis failed.
    #[error(transparent)]
    Ritz(#[from] RitzError),
    /// The coupled deployment model could not be built.
    #[error(transparent)]
    Deploy(#[from] DeployError),
    /// The hand-over failed for a reason other than an incomplete deployment.
    #[error(transparent)]
    Response(#[from] ResponseError),
}

/// The response part of a simulation.
#[derive(Debug, Clone)]
pub struct Response {
    /// The hand-over at the final latch.
    pub handover: Handover,
    /// The modal model of the response.
    pub modal: ModalResponse,
    /// Recorded quantities.
    pub channels: Vec<Channel>,
    /// Sampled history.
    pub history: ResponseHistory,
    /// Every beam's stresses along its length (beams whose section's fibres are known:
    /// tubes, and general sections with their fibre keys; docs/theory.md §3.3).
    pub stresses: Vec<crate::response::stress::BeamStresses>,
}

/// Everything `simulate` computes.
#[derive(Debug)]
pub struct Simulation {
    /// The assembled Ritz model of the deployed structure.
    pub model: RitzModel,
    /// Its modes.
    pub modes: ModalAnalysis,
    /// The coupled deployment model (base modes, beams, chain).
    pub coupled: Coupled,
    /// The deployment.
    pub deployment: DeploymentResult,
    /// The response, when every hinge latched.
    pub response: Option<Response>,
    /// Warnings of the hand-over and response (clamped mode count, hand-over notes, …); the
    /// deployment's own are [`DeploymentResult::warnings`].
    pub warnings: Vec<Warning>,
}

impl Response {
    /// Rigid-body velocity of the hub after the hand-over (translation m/s, rotation rad/s):
    /// the part of the hub's motion that grows linearly in time. `modes` are those the
    /// response was built from.
    pub fn hub_rigid_rates(&self, modes: &ModalAnalysis) -> ([f64; 3], [f64; 3]) {
        let (mut v, mut w) = ([0.0; 3], [0.0; 3]);
        for m in self.modal.modes.iter().filter(|m| m.rigid) {
            let shape = &modes.modes[m.number - 1].shape;
            for i in 0..3 {
                v[i] += shape[i] * m.eta_dot0;
                w[i] += shape[3 + i] * m.eta_dot0;
            }
        }
        (v, w)
    }
}

impl Simulation {
    /// Every warning of the run: the deployment's, then those of the hand-over and response.
    pub fn all_warnings(&self) -> impl Iterator<Item = &Warning> {
        self.deployment.warnings.iter().chain(&self.warnings)
    }

    /// Rigid-body velocity of the hub after the hand-over (see [`Response::hub_rigid_rates`]);
    /// `None` without a response.
    pub fn hub_rigid_rates(&self) -> Option<([f64; 3], [f64; 3])> {
        self.response
            .as_ref()
            .map(|r| r.hub_rigid_rates(&self.modes))
    }

    /// Runs the whole chain for a scenario.
    pub fn run(scenario: &Scenario) -> Result<Self, SimulationError> {
        let d = scenario
            .deployment
            .as_ref()
            .ok_or(SimulationError::NoDeployment)?;
        let settings = &scenario.response;
        let model = RitzModel::assemble(&scenario.structure);
        let modes =
            ModalAnalysis::compute(&model)?.with_selection(scenario.term_selection.as_ref());
        let (coupled, deployment) = deploy::simulate_coupled(&scenario.structure, d)?;
        let mut warnings = Vec::new();
        let handed = hand_over_coupled(&model, &modes, d, &coupled, &deployment, settings.handover);
        let response = match handed {
            Ok(handover) => {
                warnings.extend(handover.notes.iter().cloned().map(Warning::HandoverNote));
                if handover.angle_mismatch > 1e-9 {
                    warnings.push(Warning::AngleMismatch {
                        rad: handover.angle_mismatch,
                    });
                }
                let modal = ModalResponse::with_initial(
                    &modes,
                    &handover.modal_displacement,
                    &handover.modal_velocity,
                    settings,
                )
                .with_line_damping(&modes.line_damping_ratios(&model));
                if let Some(req) = settings.modes {
                    if req > modal.available_elastic {
                        warnings.push(Warning::ModesClamped {
                            requested: req,
                            available: modal.available_elastic,
                        });
                    }
                }
                if let Some(w) = costly_peaks(&modal, settings) {
                    warnings.push(w);
                }
                if let Some(highest) = aliased(&modal, settings) {
                    warnings.push(Warning::Aliasing {
                        output_rate: settings.output_rate,
                        highest_hz: highest,
                    });
                }
                let mut channels = standard_channels(&model);
                channels.extend(beam_root_channels(&model));
                let lengths: Vec<f64> = d.chain.panels.iter().map(|p| p.length).collect();
                channels.extend(latch_channels(&model, &d.plate, &d.chain.hinges, &lengths));
                let history = modal.sample(&modes, &channels, settings);
                warnings.extend(large_deflections(&model, &channels, &history));
                let stresses = crate::response::stress::beam_stresses(
                    &model,
                    &modes,
                    &modal,
                    &scenario.stress,
                    settings.duration,
                );
                Some(Response {
                    handover,
                    modal,
                    channels,
                    history,
                    stresses,
                })
            }
            Err(ResponseError::NotLatched { .. }) => {
                warnings.push(Warning::NoResponse);
                None
            }
            Err(e) => return Err(e.into()),
        };
        Ok(Self {
            model,
            modes,
            coupled,
            deployment,
            response,
            warnings,
        })
    }
}

pub use crate::limits::SMALL_DEFLECTION_FRACTION;

/// Warnings for beam and plate tips whose peak elastic deflection exceeds
/// [`SMALL_DEFLECTION_FRACTION`] of the component's length: the linear model's numbers are
/// then outside its assumption (small deflections about the deployed configuration).
fn large_deflections(
    model: &RitzModel,
    channels: &[Channel],
    history: &ResponseHistory,
) -> Vec<Warning> {
    use crate::response::ChannelKind;
    let st = &model.structure;
    let mut out = Vec::new();
    for (j, c) in channels.iter().enumerate() {
        let length = match &c.kind {
            ChannelKind::BeamTip { beam } if c.unit == "m" => {
                st.beams.iter().find(|b| &b.name == beam).map(|b| b.length)
            }
            ChannelKind::PlateTip { plate } => st
                .plates
                .iter()
                .find(|p| &p.name == plate)
                .map(|p| p.length),
            _ => None,
        };
        let Some(length) = length else { continue };
        let peak = (0..history.times.len())
            .map(|k| history.values[(k, j)].abs())
            .fold(0.0_f64, f64::max);
        if peak > SMALL_DEFLECTION_FRACTION * length {
            out.push(Warning::LargeDeflection {
                label: c.label.clone(),
                peak_m: peak,
                length_m: length,
                fraction: SMALL_DEFLECTION_FRACTION,
            });
        }
    }
    out
}

/// [`Warning::CostlyPeaks`] when the response keeps every elastic mode (no `[response]
/// modes`) and the peaks' grid has more than [`COSTLY_KNOTS`] points (about a second per
/// pass on the 2-core benchmark machine): generated spacecraft with explicit terms keep modes
/// up to 11 kHz, 5.3 million points over 60 s.
pub fn costly_peaks(
    modal: &ModalResponse,
    settings: &crate::response::ResponseSettings,
) -> Option<Warning> {
    if settings.modes.is_some() {
        return None;
    }
    let (kept, fastest) = elastic_modes(modal);
    let knots = crate::response::extrema::grid(fastest, settings.duration).len();
    (knots > COSTLY_KNOTS).then_some(Warning::CostlyPeaks {
        kept,
        highest_hz: fastest / (2.0 * std::f64::consts::PI),
        knots,
    })
}

/// The response's kept elastic modes: their count and the highest ω (rad/s, 0 for none).
fn elastic_modes(modal: &ModalResponse) -> (usize, f64) {
    modal
        .modes
        .iter()
        .filter(|m| !m.rigid)
        .fold((0, 0.0), |(n, w), m| (n + 1, f64::max(w, m.omega_rad_s)))
}

/// The peak search's grid points per pass above which [`costly_peaks`] warns.
pub const COSTLY_KNOTS: usize = 1_000_000;

/// The highest kept elastic frequency (Hz) when the response's output rate is below 2.5
/// times it (the samples then alias the ringing), None otherwise.
pub fn aliased(modal: &ModalResponse, settings: &crate::response::ResponseSettings) -> Option<f64> {
    let highest = elastic_modes(modal).1 / (2.0 * std::f64::consts::PI);
    (highest > 0.0 && settings.output_rate < 2.5 * highest).then_some(highest)
}
