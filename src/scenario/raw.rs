//! The TOML schema, format version 1 (docs/scenario.md). Every value keeps its span so that
//! validation can point at it. Unknown keys are errors.

use crate::basis::BasisKind;
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

pub type S<T> = Spanned<T>;

/// A vector of exactly three numbers. serde reads `[f64; 3]` from the first three elements
/// of a longer array and ignores the rest (`[0, 0, 0, "junk", nan]` was accepted): read the
/// whole array and refuse any other length.
fn three<'de, D: serde::Deserializer<'de>>(d: D) -> Result<S<[f64; 3]>, D::Error> {
    let v: S<Vec<f64>> = S::deserialize(d)?;
    let span = v.span();
    let x = v.into_inner();
    let a: [f64; 3] = x.as_slice().try_into().map_err(|_| {
        serde::de::Error::invalid_length(x.len(), &"exactly three numbers [x, y, z]")
    })?;
    Ok(S::new(span, a))
}

/// [`three`] for an optional key.
fn maybe_three<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<S<[f64; 3]>>, D::Error> {
    three(d).map(Some)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    pub format_version: Option<S<i64>>,
    pub name: Option<S<String>>,
    pub hub: S<RawHub>,
    #[serde(default)]
    pub materials: BTreeMap<String, S<RawMaterial>>,
    #[serde(default)]
    pub beams: Vec<S<RawBeam>>,
    #[serde(default)]
    pub plates: Vec<S<RawPlate>>,
    #[serde(default)]
    pub masses: Vec<S<RawMass>>,
    pub ritz: Option<S<RawRitz>>,
    pub deployment: Option<S<RawDeployment>>,
    pub response: Option<S<RawResponse>>,
    pub export: Option<S<RawExport>>,
    pub montecarlo: Option<S<RawMonteCarlo>>,
}

/// A document holding `[deployment]` alone (the re-lowering of dispersed deployment keys:
/// [`super::DeploymentOverrides`]).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDeploymentOnly {
    pub deployment: S<RawDeployment>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RawMotion {
    Free,
    Fixed,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawHub {
    pub motion: S<RawMotion>,
    pub mass: Option<S<f64>>,
    pub inertia: Option<S<Vec<f64>>>,
    #[serde(default, deserialize_with = "maybe_three")]
    pub center_of_mass: Option<S<[f64; 3]>>,
    pub shape: Option<S<RawHubShape>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawHubShape {
    pub cylinder: S<RawCylinder>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCylinder {
    pub diameter: S<f64>,
    pub wall: S<f64>,
    pub length: S<f64>,
    #[serde(deserialize_with = "three")]
    pub axis: S<[f64; 3]>,
    #[serde(deserialize_with = "three")]
    pub center: S<[f64; 3]>,
    pub material: S<String>,
    #[serde(default)]
    pub closed_ends: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMaterial {
    pub youngs_modulus: S<f64>,
    pub poisson_ratio: S<f64>,
    pub shear_modulus: Option<S<f64>>,
    pub density: S<f64>,
    pub allowable_stress: Option<S<f64>>,
    pub factor_of_safety: Option<S<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTube {
    pub outer_diameter: S<f64>,
    pub wall: S<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSection {
    pub tube: Option<S<RawTube>>,
    pub area: Option<S<f64>>,
    pub iy: Option<S<f64>>,
    pub iz: Option<S<f64>>,
    pub torsion_constant: Option<S<f64>>,
    pub polar_inertia: Option<S<f64>>,
    #[serde(default, deserialize_with = "maybe_three")]
    pub y_axis: Option<S<[f64; 3]>>,
    pub y_extreme: Option<S<f64>>,
    pub z_extreme: Option<S<f64>>,
    pub torsion_radius: Option<S<f64>>,
    pub shear_factor_y: Option<S<f64>>,
    pub shear_factor_z: Option<S<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBeamTerms {
    pub bending: Option<S<i64>>,
    pub torsion: Option<S<i64>>,
    pub axial: Option<S<i64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBeam {
    pub name: S<String>,
    pub parent: S<String>,
    #[serde(default, deserialize_with = "maybe_three")]
    pub root: Option<S<[f64; 3]>>,
    pub station: Option<S<f64>>,
    #[serde(deserialize_with = "three")]
    pub axis: S<[f64; 3]>,
    pub length: S<f64>,
    pub material: S<String>,
    pub section: S<RawSection>,
    pub terms: Option<S<RawBeamTerms>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPlateTerms {
    pub length: Option<S<i64>>,
    pub width: Option<S<i64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPlate {
    pub name: S<String>,
    pub parent: S<String>,
    pub station: Option<S<f64>>,
    #[serde(default, deserialize_with = "maybe_three")]
    pub root: Option<S<[f64; 3]>>,
    #[serde(deserialize_with = "three")]
    pub length_axis: S<[f64; 3]>,
    #[serde(deserialize_with = "three")]
    pub normal: S<[f64; 3]>,
    pub length: S<f64>,
    pub width: S<f64>,
    pub thickness: Option<S<f64>>,
    pub material: Option<S<String>>,
    pub areal_density: Option<S<f64>>,
    pub bending_stiffness: Option<S<f64>>,
    pub poisson_ratio: Option<S<f64>>,
    pub terms: Option<S<RawPlateTerms>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMass {
    pub name: S<String>,
    pub parent: S<String>,
    pub station: Option<S<f64>>,
    #[serde(default, deserialize_with = "maybe_three")]
    pub point: Option<S<[f64; 3]>>,
    #[serde(default, deserialize_with = "maybe_three")]
    pub offset: Option<S<[f64; 3]>>,
    pub mass: S<f64>,
    pub inertia: Option<S<Vec<f64>>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRitz {
    #[serde(default)]
    pub basis: BasisKind,
    pub tolerance: Option<S<f64>>,
    pub modes: Option<S<i64>>,
    pub max_dof: Option<S<i64>>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RawLatching {
    Sequential,
    Simultaneous,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDeployment {
    pub plate: S<String>,
    pub panels: Option<S<i64>>,
    pub panel_lengths: Option<S<Vec<f64>>>,
    /// Gone: the hub's motion is `[hub] motion` (refused with that message).
    pub hub: Option<S<toml::Value>>,
    pub latching: Option<S<RawLatching>>,
    pub base: Option<S<RawBase>>,
    pub base_modes: Option<S<i64>>,
    pub base_damping_ratio: Option<S<f64>>,
    pub synchronisation: Option<S<RawSynchronisation>>,
    pub cable_stiffness: Option<S<f64>>,
    pub integrator: Option<S<RawIntegrator>>,
    pub latch: Option<S<RawLatch>>,
    pub end_time: Option<S<f64>>,
    pub output_rate: Option<S<f64>>,
    pub tolerance: Option<S<f64>>,
    pub accuracy: Option<S<f64>>,
    pub panel_mass: Option<S<f64>>,
    pub panel_inertia: Option<S<f64>>,
    pub hinge: Option<S<RawHingeAll>>,
    pub hinges: Option<Vec<S<RawHinge>>>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RawBase {
    Flexible,
    Rigid,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLatch {
    pub model: Option<S<RawLatchModel>>,
    pub stiffness: Option<S<RawPerHinge>>,
    pub damping: Option<S<RawPerHinge>>,
    pub settle_time: Option<S<f64>>,
    pub moment_allowable: Option<S<f64>>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RawLatchModel {
    Rigid,
    Compliant,
}

/// One value for every hinge, or one per hinge.
#[derive(Debug, Deserialize, Clone, PartialEq)]
#[serde(untagged)]
pub enum RawPerHinge {
    One(f64),
    Each(Vec<f64>),
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RawIntegrator {
    Auto,
    Implicit,
    Adiabatic,
    Explicit,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RawSynchronisation {
    None,
    Cable,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawHingeAll {
    pub stiffness: Option<S<f64>>,
    pub preload_angle: Option<S<f64>>,
    pub damping: Option<S<f64>>,
    pub friction: Option<S<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawHinge {
    pub stiffness: Option<S<f64>>,
    pub reference_angle: Option<S<f64>>,
    pub damping: Option<S<f64>>,
    pub friction: Option<S<f64>>,
    pub latch_angle: Option<S<f64>>,
    pub initial_angle: Option<S<f64>>,
    pub initial_rate: Option<S<f64>>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RawHandover {
    Projection,
    Impulse,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawResponse {
    pub duration: Option<S<f64>>,
    pub output_rate: Option<S<f64>>,
    pub modes: Option<S<i64>>,
    pub damping_ratio: Option<S<f64>>,
    pub handover: Option<S<RawHandover>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawExport {
    pub modes: Option<S<i64>>,
    pub damping_ratio: Option<S<RawDamping>>,
    #[serde(default)]
    pub points: Vec<S<RawPoint>>,
    #[serde(default)]
    pub transfer: Vec<S<RawTransfer>>,
    pub frequency_range: Option<S<Vec<f64>>>,
    pub frequency_points: Option<S<i64>>,
}

/// One ratio for every mode, or a list with one per kept mode.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum RawDamping {
    One(f64),
    List(Vec<f64>),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPoint {
    pub name: S<String>,
    pub component: S<String>,
    pub station: Option<S<f64>>,
    pub xi: Option<S<f64>>,
    pub eta: Option<S<f64>>,
    #[serde(default, deserialize_with = "maybe_three")]
    pub position: Option<S<[f64; 3]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTransfer {
    pub input: S<String>,
    pub output: S<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMonteCarlo {
    pub runs: Option<S<i64>>,
    pub seed: Option<S<i64>>,
    /// Keyed by dotted path (sorted: the order of the draws).
    #[serde(default)]
    pub dispersions: BTreeMap<String, S<RawDispersion>>,
    #[serde(default)]
    pub requirements: Vec<S<RawRequirement>>,
    #[serde(default)]
    pub correlations: Vec<S<RawCorrelation>>,
    /// Per-run response outputs (needs `[response]`).
    pub response: Option<S<bool>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCorrelation {
    pub keys: S<Vec<String>>,
    pub coefficient: S<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDispersion {
    pub normal: Option<S<Vec<f64>>>,
    pub uniform: Option<S<Vec<f64>>>,
    pub lognormal: Option<S<Vec<f64>>>,
    pub choice: Option<S<Vec<f64>>>,
    pub weights: Option<S<Vec<f64>>>,
    pub truncate: Option<S<Vec<f64>>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRequirement {
    pub name: S<String>,
    pub output: S<String>,
    pub min: Option<S<f64>>,
    pub max: Option<S<f64>>,
    pub probability: S<f64>,
    pub confidence: S<f64>,
    pub factor_of_safety: Option<S<f64>>,
}
