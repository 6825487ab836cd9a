//! # flexcraft
//!
//! Dynamics of flexible spacecraft with deployable solar arrays, after Borisov & Avramenko,
//! "Modeling of motion of the complex elastic system". From a [`Scenario`] (a TOML text:
//! a rigid hub, elastic beams and plates, lumped masses, an optional folded array to
//! deploy) the library computes
//!
//! - the natural modes of the deployed spacecraft by Rayleigh–Ritz synthesis ([`ritz`])
//!   over one of two bases ([`basis`]): [`RitzModel::assemble`] then
//!   [`ModalAnalysis::compute`];
//! - the deployment of the accordion-folded array, with latching by plastic impact
//!   ([`deploy::simulate`]);
//! - the latch-excited vibration by modal superposition ([`response`]), and all three
//!   chained end to end by [`simulation::Simulation::run`].
//!
//! The library never prints and never exits. The `flexcraft` command-line tool and the
//! output layer (tables, JSON, CSV, plots, the HTML report: the `output` module) are built
//! by the default cargo feature `cli`; with
//! `flexcraft = { version = "0.1", default-features = false }` only the computing library
//! is built, without plotters, sha2, indicatif, clap, csv or serde_json.
//!
//! **Units**: SI throughout — m, kg, s, N, Pa, rad; [`ritz::Mode::frequency_hz`] in Hz,
//! `omega_rad_s` in rad/s.
//!
//! ## Modes of a structure
//!
//! A scenario is parsed and validated from text with [`Scenario::from_toml_str`] (the
//! second argument names it in error messages, which carry `file:line:column: key`) or
//! from a file with [`Scenario::from_file`]. The format is described in `docs/scenario.md`.
//!
//! ```
//! use flexcraft::{ModalAnalysis, RitzModel, Scenario};
//!
//! let toml = r#"
//! name = "cantilever"
//! format_version = 1
//!
//! [hub]
//! motion = "fixed"
//! mass = 1.0
//! inertia = [1.0, 1.0, 1.0]
//! center_of_mass = [0.0, 0.0, 0.0]
//!
//! [materials.steel]
//! youngs_modulus = 210e9
//! poisson_ratio = 0.3
//! density = 7850.0
//!
//! [[beams]]
//! name = "boom"
//! parent = "hub"
//! root = [0.0, 0.0, 0.0]
//! axis = [1.0, 0.0, 0.0]
//! length = 3.0
//! material = "steel"
//! section = { tube = { outer_diameter = 0.05, wall = 0.002 } }
//! terms = { bending = 10, torsion = 4, axial = 4 }
//! "#;
//!
//! let scenario = Scenario::from_toml_str(toml, "cantilever.toml")?;
//! let model = RitzModel::assemble(&scenario.structure);
//! let modes = ModalAnalysis::compute(&model)?;
//!
//! // A fixed hub has no rigid-body modes: the first mode is the boom's first bending mode,
//! // 1.875104² √(EI / ρA) / (2π L²) for a clamped-free beam.
//! let f1 = modes.modes[0].frequency_hz();
//! println!("f1 = {f1:.6} Hz");
//! assert!(!modes.modes[0].rigid);
//! # let (d, t, l, e, rho) = (0.05_f64, 0.002_f64, 3.0_f64, 210e9_f64, 7850.0_f64);
//! # let di = d - 2.0 * t;
//! # let area = std::f64::consts::PI / 4.0 * (d * d - di * di);
//! # let i = std::f64::consts::PI / 64.0 * (d.powi(4) - di.powi(4));
//! # let exact = 1.875104068711961_f64.powi(2) * (e * i / (rho * area)).sqrt()
//! #     / (2.0 * std::f64::consts::PI * l * l);
//! # assert!((f1 - exact).abs() < 1e-6 * exact, "{f1} vs {exact}");
//!
//! // Mode shapes are plain vectors of Ritz coefficients over all the model's generalized
//! // coordinates (the hub's six first), mass-normalised (φᵀMφ = 1).
//! let shape: &Vec<f64> = &modes.modes[0].shape;
//! assert_eq!(shape.len(), model.dof());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Deployment and its latch events
//!
//! The `[deployment]` section of a scenario is [`Scenario::deployment`];
//! [`deploy::simulate_coupled`] integrates it on the flexible, free-floating spacecraft as
//! one system and returns the coupled model and a [`deploy::DeploymentResult`] with the
//! sampled motion and one [`deploy::LatchEvent`] per latching ([`deploy::simulate`] runs
//! the planar chain alone, the rigid reference).
//!
//! ```
//! use flexcraft::Scenario;
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/seed.toml");
//! let scenario = Scenario::from_file(path.as_ref())?;
//! let deployment = scenario.deployment.as_ref().expect("seed.toml has a [deployment]");
//! let (_model, result) = flexcraft::deploy::simulate_coupled(&scenario.structure, deployment)?;
//! for e in &result.latches {
//!     println!(
//!         "t = {:.3} s: hinge {} latched, kinetic energy {:.4e} J -> {:.4e} J",
//!         e.time, e.hinge, e.energy_before, e.energy_after
//!     );
//! }
//! assert!(result.all_latched);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The whole story — modes, deployment, hand-over at the final latch and the response — is
//! one call, `flexcraft::simulation::Simulation::run(&scenario)`.
//!
//! ## Matrices
//!
//! Matrices that cross the API (the Ritz model's `mass` and `stiffness`, the response
//! history's `values` and `modal`, the basis integrals) are `faer::Mat<f64>` of **faer
//! 0.24**, re-exported as [`flexcraft::faer`](faer) so that callers use the same version.
//! A `Mat` is column-major: `m[(i, j)]` reads an entry, `m.col_as_slice(j)` gives a
//! column as `&[f64]`. Mode shapes ([`ritz::Mode::shape`]) and time series are plain
//! `Vec<f64>`.
//!
//! Two programs in `examples/` show the same in full: `modes_from_toml.rs` and
//! `deployment_events.rs` (`cargo run --release --example modes_from_toml`).
#![warn(missing_docs)]
// No function over 120 lines (clippy.toml sets the threshold); CI denies warnings.
#![warn(clippy::too_many_lines)]
// Index loops over small fixed-size matrices read like the equations they implement.
#![allow(clippy::needless_range_loop)]

pub mod basis;
pub mod deploy;
pub mod export;
pub mod finite;
pub mod limits;
pub mod math;
pub mod montecarlo;
pub mod ode;
#[cfg(feature = "cli")]
pub mod output;
pub mod response;
pub mod ritz;
pub mod scenario;
pub mod simulation;
pub mod structure;
pub mod warning;

pub use faer;
pub use ritz::{ModalAnalysis, RitzModel};
pub use scenario::Scenario;
pub use structure::Structure;
