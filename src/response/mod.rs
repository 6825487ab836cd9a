//! The latch-excited vibration of the deployed spacecraft (docs/theory.md §3; the paper's
//! section 2.2 end and figures 2.4–2.7): the hand-over from the deploying chain to the
//! flexible model ([`handover`]), the response by exact modal superposition
//! ([`superposition`]), and the physical quantities sampled from it ([`channels`]), loads
//! included ([`loads`]).

pub mod channels;
pub mod extrema;
pub mod handover;
pub mod loads;
pub mod sections;
pub mod stress;
pub mod superposition;

pub use channels::{Channel, ChannelKind, Order};
pub use handover::{hand_over, Handover, HandoverMethod, Momentum};
pub use superposition::{ModalResponse, ResponseHistory};

/// Largest number of output rows a response may have.
pub const MAX_ROWS: u64 = 1_000_000;

/// The `[response]` settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResponseSettings {
    /// Time after the last latch, s.
    pub duration: f64,
    /// Samples at t = k / output_rate, Hz.
    pub output_rate: f64,
    /// Elastic modes kept (every rigid-body mode is always kept); `None`: all of them.
    pub modes: Option<usize>,
    /// Modal damping ratio ζ of every elastic mode, 0 ≤ ζ < 1.
    pub damping_ratio: f64,
    /// How the deployment's motion becomes the structure's initial velocity.
    pub handover: HandoverMethod,
}

impl Default for ResponseSettings {
    fn default() -> Self {
        Self {
            duration: 60.0,
            output_rate: 50.0,
            modes: None,
            damping_ratio: 0.0,
            handover: HandoverMethod::Projection,
        }
    }
}

impl ResponseSettings {
    /// Number of samples t_k = k/rate, k = 0…⌊duration·rate⌋.
    pub fn rows(&self) -> u64 {
        rows(self.duration, self.output_rate)
    }
}

/// ⌊duration·rate⌋ + 1 (with a rounding allowance so that 60 s at 50 Hz gives 3001).
pub fn rows(duration: f64, rate: f64) -> u64 {
    let k = duration * rate;
    if !k.is_finite() || k >= 1e18 {
        return u64::MAX;
    }
    (k * (1.0 + 1e-12)).floor() as u64 + 1
}

/// Why a response could not be computed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ResponseError {
    /// The deployment ended before every hinge latched.
    #[error("the array did not latch completely (hinges {hinges:?} still free at t = {time} s): nothing to hand over")]
    NotLatched {
        /// Hinges still free (1-based).
        hinges: Vec<usize>,
        /// The time the deployment stopped, s.
        time: f64,
    },
    /// The deploying plate is not in the structure.
    #[error("the deploying plate `{0}` is not in the structure")]
    UnknownPlate(String),
}
