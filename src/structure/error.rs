//! Why a structure or one of its parts is refused: every error names the offending field
//! ([`Field`]) and, for errors of the attachment tree, the component ([`ComponentId`]), so a
//! front end can point at the place it was written without reading the message.

use super::ComponentId;
use crate::limits::Limit;
use thiserror::Error;

/// A field of a component (or material) that a constructor validates.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// The component's name.
    Name,
    /// Young's modulus E.
    YoungsModulus,
    /// Poisson's ratio ν.
    PoissonRatio,
    /// Shear modulus G.
    ShearModulus,
    /// Density ρ.
    Density,
    /// A body's mass.
    Mass,
    /// A body's inertia tensor.
    Inertia,
    /// The hub's centre of mass.
    CenterOfMass,
    /// The hub cylinder's diameter.
    Diameter,
    /// A wall thickness (hub cylinder or tube).
    Wall,
    /// A member's length (beam, plate, hub cylinder).
    Length,
    /// A member's axis direction.
    Axis,
    /// The hub cylinder's centre.
    Center,
    /// A tube's outer diameter.
    OuterDiameter,
    /// Section area.
    Area,
    /// Second moment about the section's y axis.
    Iy,
    /// Second moment about the section's z axis.
    Iz,
    /// Torsion constant.
    TorsionConstant,
    /// Polar second moment.
    PolarInertia,
    /// A beam section's y axis.
    YAxis,
    /// An attachment point on the hub.
    Root,
    /// An attachment station on a beam.
    Station,
    /// The parent named by an attachment.
    Parent,
    /// A plate's length axis.
    LengthAxis,
    /// A plate's normal.
    Normal,
    /// A plate's width.
    Width,
    /// A plate's thickness.
    Thickness,
    /// A plate's areal density ρh.
    ArealDensity,
    /// A plate's bending stiffness D.
    BendingStiffness,
    /// A lumped mass's offset.
    Offset,
    /// Beam bending terms.
    TermsBending,
    /// Beam torsion terms.
    TermsTorsion,
    /// Beam axial terms.
    TermsAxial,
    /// Plate terms along the length.
    TermsLength,
    /// Plate terms across the width.
    TermsWidth,
}

impl Field {
    /// The field's name as written in a scenario file (`terms.bending`, `youngs_modulus`, …).
    pub fn key(self) -> &'static str {
        match self {
            Field::Name => "name",
            Field::YoungsModulus => "youngs_modulus",
            Field::PoissonRatio => "poisson_ratio",
            Field::ShearModulus => "shear_modulus",
            Field::Density => "density",
            Field::Mass => "mass",
            Field::Inertia => "inertia",
            Field::CenterOfMass => "center_of_mass",
            Field::Diameter => "diameter",
            Field::Wall => "wall",
            Field::Length => "length",
            Field::Axis => "axis",
            Field::Center => "center",
            Field::OuterDiameter => "outer_diameter",
            Field::Area => "area",
            Field::Iy => "iy",
            Field::Iz => "iz",
            Field::TorsionConstant => "torsion_constant",
            Field::PolarInertia => "polar_inertia",
            Field::YAxis => "y_axis",
            Field::Root => "root",
            Field::Station => "station",
            Field::Parent => "parent",
            Field::LengthAxis => "length_axis",
            Field::Normal => "normal",
            Field::Width => "width",
            Field::Thickness => "thickness",
            Field::ArealDensity => "areal_density",
            Field::BendingStiffness => "bending_stiffness",
            Field::Offset => "offset",
            Field::TermsBending => "terms.bending",
            Field::TermsTorsion => "terms.torsion",
            Field::TermsAxial => "terms.axial",
            Field::TermsLength => "terms.length",
            Field::TermsWidth => "terms.width",
        }
    }
}

/// Why a structure (or one of its parts) is refused.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StructureError {
    /// A value outside its accepted range ([`crate::limits`]).
    #[error("{}", range.refusal(*value))]
    OutOfRange {
        /// The field.
        field: Field,
        /// Its value.
        value: f64,
        /// The accepted range.
        range: Limit,
    },
    /// A point with a coordinate outside its accepted range.
    #[error("every coordinate must lie in {}, got [{:e}, {:e}, {:e}]", range.describe(), value[0], value[1], value[2])]
    PointOutOfRange {
        /// The field.
        field: Field,
        /// The point.
        value: [f64; 3],
        /// The accepted range per coordinate.
        range: Limit,
    },
    /// A plate whose thickness and material give a stiffness or areal density outside the
    /// ranges accepted for given ones.
    #[error(
        "gives ρh = {areal_density:e} kg/m² and D = {bending_stiffness:e} N·m; they must lie in {} and {}",
        crate::limits::AREAL_DENSITY.describe(),
        crate::limits::BENDING_STIFFNESS.describe()
    )]
    DerivedOutOfRange {
        /// The field that sets them.
        field: Field,
        /// ρh, kg/m².
        areal_density: f64,
        /// D, N·m.
        bending_stiffness: f64,
    },
    /// A name that breaks the naming rule ([`crate::limits::valid_name`]).
    #[error("{reason}")]
    InvalidName {
        /// Why.
        reason: String,
    },
    /// A tube wall at least as thick as the tube's radius.
    #[error("wall {wall} m is not less than the radius {radius} m")]
    WallTooThick {
        /// Wall, m.
        wall: f64,
        /// Outer radius (or half length for end caps), m.
        radius: f64,
    },
    /// A plate's hinge lines out of order or with a bad spring ([`super::Plate::with_hinges`]).
    #[error("{reason}")]
    InvalidHinge {
        /// Why.
        reason: String,
    },
    /// An inertia given with neither 3 nor 6 values.
    #[error("inertia needs 3 principal values or 6 [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], got {len}")]
    InertiaLength {
        /// Number given.
        len: usize,
    },
    /// An inertia entry outside its range.
    #[error(
        "entry {entry} is {value:e}: moments must lie in [{:e}, {:e}] kg·m², products in {}",
        crate::limits::MIN_PRINCIPAL_INERTIA,
        crate::limits::INERTIA.hi,
        crate::limits::INERTIA.describe()
    )]
    InertiaEntry {
        /// 1-based entry.
        entry: usize,
        /// Its value.
        value: f64,
    },
    /// An inertia tensor that is not positive definite.
    #[error("inertia tensor is not positive definite: principal moments {principal:?} kg·m²")]
    InertiaNotPositive {
        /// Principal moments, ascending.
        principal: [f64; 3],
    },
    /// Principal moments violating I_a + I_b ≥ I_c.
    #[error("principal moments {principal:?} kg·m² violate the triangle inequality I1 + I2 >= I3")]
    InertiaTriangle {
        /// Principal moments, ascending.
        principal: [f64; 3],
    },
    /// A direction vector of zero length or with a non-finite component.
    #[error("has zero length or a non-finite component (a direction needs finite components, not all zero)")]
    ZeroAxis {
        /// The vector.
        field: Field,
    },
    /// Two directions that must be perpendicular are not.
    #[error("must be perpendicular to the axis; the angle between them is {angle_deg:.6}°")]
    NotPerpendicular {
        /// The vector.
        field: Field,
        /// Angle, degrees.
        angle_deg: f64,
    },
    /// terms = 0 or > 100.
    #[error("must be between 1 and {}, got {value}", super::MAX_TERMS)]
    Terms {
        /// The field.
        field: Field,
        /// Value given.
        value: usize,
    },
    /// Two components with one name.
    #[error("the name \"{name}\" is used twice")]
    DuplicateName {
        /// The second component of that name.
        component: ComponentId,
        /// The name.
        name: String,
    },
    /// An attachment to a beam index that does not exist.
    #[error("parent beam {parent} does not exist ({count} beams)")]
    UnknownParent {
        /// The child.
        component: ComponentId,
        /// The parent index given.
        parent: usize,
        /// Number of beams.
        count: usize,
    },
    /// Beams whose parents form a loop.
    #[error("beams form a cycle: {}", path.join(" -> "))]
    Cycle {
        /// The first beam of the loop.
        component: ComponentId,
        /// The loop, first name repeated at the end.
        path: Vec<String>,
    },
    /// A station outside [0, L] of its parent beam.
    #[error("station {station_m} m is beyond the parent \"{parent}\" of length {length_m} m")]
    StationBeyondParent {
        /// The child.
        component: ComponentId,
        /// The parent's name.
        parent: String,
        /// The station, m.
        station_m: f64,
        /// The parent's length, m.
        length_m: f64,
    },
}

impl StructureError {
    /// The field the error is about.
    pub fn field(&self) -> Field {
        match self {
            StructureError::OutOfRange { field, .. }
            | StructureError::PointOutOfRange { field, .. }
            | StructureError::ZeroAxis { field }
            | StructureError::NotPerpendicular { field, .. }
            | StructureError::Terms { field, .. }
            | StructureError::DerivedOutOfRange { field, .. } => *field,
            StructureError::InvalidName { .. } | StructureError::DuplicateName { .. } => {
                Field::Name
            }
            StructureError::WallTooThick { .. } => Field::Wall,
            StructureError::InvalidHinge { .. } => Field::Length,
            StructureError::InertiaLength { .. }
            | StructureError::InertiaEntry { .. }
            | StructureError::InertiaNotPositive { .. }
            | StructureError::InertiaTriangle { .. } => Field::Inertia,
            StructureError::UnknownParent { .. } | StructureError::Cycle { .. } => Field::Parent,
            StructureError::StationBeyondParent { .. } => Field::Station,
        }
    }

    /// The component an error of the attachment tree is about.
    pub fn component(&self) -> Option<ComponentId> {
        match self {
            StructureError::DuplicateName { component, .. }
            | StructureError::UnknownParent { component, .. }
            | StructureError::Cycle { component, .. }
            | StructureError::StationBeyondParent { component, .. } => Some(*component),
            _ => None,
        }
    }
}

/// `value` inside `range`, or [`StructureError::OutOfRange`] naming `field`.
pub(crate) fn in_range(field: Field, value: f64, range: Limit) -> Result<f64, StructureError> {
    if range.contains(value) {
        Ok(value)
    } else {
        Err(StructureError::OutOfRange {
            field,
            value,
            range,
        })
    }
}

/// A point whose every coordinate lies in [`crate::limits::COORDINATE`].
pub(crate) fn point(
    field: Field,
    v: crate::math::Vec3,
) -> Result<crate::math::Vec3, StructureError> {
    let range = crate::limits::COORDINATE;
    if v.0.iter().all(|x| range.contains(*x)) {
        Ok(v)
    } else {
        Err(StructureError::PointOutOfRange {
            field,
            value: v.0,
            range,
        })
    }
}

/// A direction of any scale, normalised scale-safely; only a zero or non-finite vector is
/// refused.
pub(crate) fn unit(
    field: Field,
    v: crate::math::Vec3,
) -> Result<crate::math::Vec3, StructureError> {
    if !v.is_finite() || v.0.iter().all(|x| *x == 0.0) {
        return Err(StructureError::ZeroAxis { field });
    }
    Ok(v.normalized())
}

/// A component or material name following [`crate::limits::valid_name`].
pub(crate) fn name(n: &str) -> Result<String, StructureError> {
    crate::limits::valid_name(n).map_err(|reason| StructureError::InvalidName { reason })?;
    Ok(n.to_string())
}
