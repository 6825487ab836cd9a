//! # flexcraft
//!
//! Dynamics of flexible spacecraft with deployable solar arrays (see `MODEL.md` of the
//! project and the paper by Borisov & Avramenko). The library computes, from a
//! [`scenario::Scenario`], the natural modes of the deployed spacecraft by Rayleigh–Ritz
//! synthesis ([`ritz`]) over one of two bases ([`basis`]).
//!
//! Data flows one way: scenario file → [`structure::Structure`] → [`ritz::RitzModel`] →
//! [`ritz::ModalAnalysis`] → outputs; [`deploy`] simulates the array's deployment and
//! [`response`] the latch-excited vibration, chained end to end by
//! [`simulation::Simulation::run`]. The library never prints and never exits; the
//! `flexcraft` binary is a thin command-line layer over it.
//!
//! SI units throughout: m, kg, s, N, Pa, rad.
#![warn(missing_docs)]
// Index loops over small fixed-size matrices read like the equations they implement.
#![allow(clippy::needless_range_loop)]

pub mod basis;
pub mod deploy;
pub mod finite;
pub mod limits;
pub mod math;
pub mod output;
pub mod response;
pub mod ritz;
pub mod scenario;
pub mod simulation;
pub mod structure;
pub mod warning;

pub use ritz::{ModalAnalysis, RitzModel};
pub use scenario::Scenario;
pub use structure::Structure;
