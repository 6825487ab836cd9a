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
