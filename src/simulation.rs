//! The end-to-end run behind `flexcraft simulate`: modes of the deployed structure, the
//! deployment, the hand-over at the final latch and the latch-excited response
//! (MODEL.md §3; the paper's section 2).

use crate::deploy::{self, DeploymentResult};
use crate::response::channels::standard_channels;
use crate::response::{
    hand_over, Channel, Handover, ModalResponse, ResponseError, ResponseHistory,
};
use crate::ritz::{ModalAnalysis, RitzError, RitzModel};
use crate::scenario::Scenario;

/// Why `simulate` could not run at all.
#[derive(Debug, thiserror::Error)]
pub enum SimulationError {
    /// `simulate` needs a `[deployment]` section.
    #[error("the scenario has no [deployment] section (see docs/scenario.md)")]
    NoDeployment,
    /// The modal analysis failed.
    #[error(transparent)]
    Ritz(#[from] RitzError),
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
}

/// Everything `simulate` computes.
#[derive(Debug)]
pub struct Simulation {
    /// The assembled Ritz model of the deployed structure.
    pub model: RitzModel,
    /// Its modes.
    pub modes: ModalAnalysis,
    /// The deployment.
    pub deployment: DeploymentResult,
    /// The response, when every hinge latched.
    pub response: Option<Response>,
    /// Plain-language warnings of the hand-over and response (clamped mode count, hand-over
    /// notes, …); the deployment's own are [`crate::output::deploy_warnings`].
    pub warnings: Vec<String>,
}

impl Simulation {
    /// Runs the whole chain for a scenario.
    pub fn run(scenario: &Scenario) -> Result<Self, SimulationError> {
        let d = scenario
            .deployment
            .as_ref()
            .ok_or(SimulationError::NoDeployment)?;
        let settings = &scenario.response;
        let model = RitzModel::assemble(&scenario.structure);
        let modes = ModalAnalysis::compute(&model)?;
        let deployment = deploy::simulate(d);
        let mut warnings = Vec::new();
        let response = match hand_over(&model, &modes, d, &deployment, settings.handover) {
            Ok(handover) => {
                warnings.extend(handover.notes.iter().cloned());
                if handover.angle_mismatch > 1e-9 {
                    warnings.push(format!(
                        "the array locked away from the straight wing (largest hinge-angle \
                         mismatch {:.6} rad): the hand-over uses the straight wing",
                        handover.angle_mismatch
                    ));
                }
                let modal = ModalResponse::new(&modes, &handover.modal_velocity, settings);
                if let Some(req) = settings.modes {
                    if req > modal.available_elastic {
                        warnings.push(format!(
                            "response.modes = {req} but the model has {} elastic modes: all of \
                             them are kept",
                            modal.available_elastic
                        ));
                    }
                }
                let channels = standard_channels(&model);
                let history = modal.sample(&modes, &channels, settings);
                warnings.extend(large_deflections(&model, &channels, &history));
                Some(Response {
                    handover,
                    modal,
                    channels,
                    history,
                })
            }
            Err(ResponseError::NotLatched { .. }) => {
                warnings.push(
                    "the array did not latch completely: no hand-over, no response".to_string(),
                );
                None
            }
            Err(e) => return Err(e.into()),
        };
        Ok(Self {
            model,
            modes,
            deployment,
            response,
            warnings,
        })
    }
}

/// Largest elastic deflection, as a fraction of the component's length, that the linear
/// (small-deformation) model is trusted with; above it a warning says so.
pub const SMALL_DEFLECTION_FRACTION: f64 = 0.1;

/// Warnings for beam and plate tips whose peak elastic deflection exceeds
/// [`SMALL_DEFLECTION_FRACTION`] of the component's length: the linear model's numbers are
/// then outside its assumption (small deflections about the deployed configuration).
fn large_deflections(
    model: &RitzModel,
    channels: &[Channel],
    history: &ResponseHistory,
) -> Vec<String> {
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
            out.push(format!(
                "{}: peak elastic deflection {peak:.6e} m is {:.1} % of the component's length \
                 {length} m: the linear (small-deformation) model is outside its assumption \
                 there (more than {} %)",
                c.label,
                100.0 * peak / length,
                100.0 * SMALL_DEFLECTION_FRACTION
            ));
        }
    }
    out
}
