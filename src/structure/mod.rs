//! The deployed spacecraft as a tree of components rooted at the hub (MODEL.md §3.1).

pub mod components;
pub mod material;
pub mod rigid;

pub use components::{
    Attachment, Beam, BeamSection, BeamTerms, Frame, Hub, HubMotion, LumpedMass, Plate, PlateTerms,
    MAX_TERMS,
};
pub use material::Material;
pub use rigid::{inertia_tensor, RigidBody};

use crate::basis::BasisKind;
use crate::math::Vec3;
use thiserror::Error;

/// Why a structure (or one of its parts) is refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StructureError {
    /// A size, mass or modulus that must be positive is not.
    #[error("{field} must be a positive finite number, got {value}")]
    NotPositive {
        /// The quantity.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A value is NaN or infinite.
    #[error("{field} must be finite")]
    NotFinite {
        /// The quantity.
        field: &'static str,
    },
    /// ν outside (−1, 0.5).
    #[error("Poisson's ratio must lie in (-1, 0.5), got {value}")]
    PoissonRatio {
        /// The value given.
        value: f64,
    },
    /// A tube wall at least as thick as the tube's radius.
    #[error("wall thickness {wall} m is not less than the radius {radius} m")]
    WallTooThick {
        /// Wall, m.
        wall: f64,
        /// Outer radius (or half length for end caps), m.
        radius: f64,
    },
    /// An inertia given with neither 3 nor 6 values.
    #[error("inertia needs 3 principal values or 6 [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], got {len}")]
    InertiaLength {
        /// Number given.
        len: usize,
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
    /// A direction vector of (near) zero length.
    #[error("{field} has zero length")]
    ZeroAxis {
        /// The vector.
        field: &'static str,
    },
    /// Two directions that must be perpendicular are not.
    #[error(
        "{field} must be perpendicular to the axis; the angle between them is {angle_deg:.6}°"
    )]
    NotPerpendicular {
        /// The vector.
        field: &'static str,
        /// Angle, degrees.
        angle_deg: f64,
    },
    /// terms = 0 or > 100.
    #[error("terms.{field} must be between 1 and 100, got {value}")]
    Terms {
        /// The field.
        field: &'static str,
        /// Value given.
        value: usize,
    },
    /// Two components with one name.
    #[error("the name \"{name}\" is used twice")]
    DuplicateName {
        /// The name.
        name: String,
    },
    /// A parent that is neither "hub" nor a beam.
    #[error("{component}: unknown parent \"{parent}\" (the hub is \"hub\"; beams: {known})")]
    UnknownParent {
        /// The child.
        component: String,
        /// The parent named.
        parent: String,
        /// The beams that exist.
        known: String,
    },
    /// Beams whose parents form a loop.
    #[error("beams form a cycle: {}", path.join(" -> "))]
    Cycle {
        /// The loop, first name repeated at the end.
        path: Vec<String>,
    },
    /// A station outside [0, L] of its parent beam.
    #[error("{component}: station {station_m} m is beyond the parent \"{parent}\" of length {length_m} m")]
    StationBeyondParent {
        /// The child.
        component: String,
        /// The parent.
        parent: String,
        /// The station, m.
        station_m: f64,
        /// The parent's length, m.
        length_m: f64,
    },
}

pub(crate) fn positive(field: &'static str, value: f64) -> Result<f64, StructureError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(StructureError::NotPositive { field, value })
    }
}

pub(crate) fn finite_vec(field: &'static str, v: Vec3) -> Result<Vec3, StructureError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(StructureError::NotFinite { field })
    }
}

pub(crate) fn unit(field: &'static str, v: Vec3) -> Result<Vec3, StructureError> {
    finite_vec(field, v)?;
    // A direction of any scale is accepted; only the zero vector has none.
    if v.0.iter().all(|x| *x == 0.0) {
        return Err(StructureError::ZeroAxis { field });
    }
    Ok(v.normalized())
}

/// Reference to a component of the structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ComponentId {
    /// The hub.
    Hub,
    /// `beams[i]`.
    Beam(usize),
    /// `plates[i]`.
    Plate(usize),
    /// `masses[i]`.
    Mass(usize),
}

/// A validated structure: the hub, the elastic components and lumped masses, with the
/// attachment tree checked (known parents, no cycle, stations on their parents).
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Name (free text).
    pub name: String,
    /// The hub.
    pub hub: Hub,
    /// Beams in the order given.
    pub beams: Vec<Beam>,
    /// Plates.
    pub plates: Vec<Plate>,
    /// Lumped masses.
    pub masses: Vec<LumpedMass>,
    /// Ritz basis.
    pub basis: BasisKind,
    beam_order: Vec<usize>,
    beam_parent: Vec<Option<usize>>,
}

impl Structure {
    /// Checks the attachment tree and builds the structure.
    pub fn new(
        name: String,
        hub: Hub,
        beams: Vec<Beam>,
        plates: Vec<Plate>,
        masses: Vec<LumpedMass>,
        basis: BasisKind,
    ) -> Result<Self, StructureError> {
        let mut seen = std::collections::BTreeSet::new();
        seen.insert("hub".to_string());
        let names = beams
            .iter()
            .map(|b| &b.name)
            .chain(plates.iter().map(|p| &p.name))
            .chain(masses.iter().map(|m| &m.name));
        for n in names {
            if !seen.insert(n.clone()) {
                return Err(StructureError::DuplicateName { name: n.clone() });
            }
        }
        let known = beams
            .iter()
            .map(|b| b.name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        let resolve = |component: &str,
                       att: &Attachment|
         -> Result<Option<usize>, StructureError> {
            match att {
                Attachment::Hub { point } => {
                    finite_vec("root", *point)?;
                    Ok(None)
                }
                Attachment::Beam { beam, station } => {
                    let idx = beams.iter().position(|b| &b.name == beam).ok_or_else(|| {
                        StructureError::UnknownParent {
                            component: component.to_string(),
                            parent: beam.clone(),
                            known: if known.is_empty() {
                                "none".into()
                            } else {
                                known.clone()
                            },
                        }
                    })?;
                    let len = beams[idx].length;
                    if !(station.is_finite() && *station >= 0.0 && *station <= len * (1.0 + 1e-12))
                    {
                        return Err(StructureError::StationBeyondParent {
                            component: component.to_string(),
                            parent: beam.clone(),
                            station_m: *station,
                            length_m: len,
                        });
                    }
                    Ok(Some(idx))
                }
            }
        };
        let beam_parent = beams
            .iter()
            .map(|b| resolve(&b.name, &b.attachment))
            .collect::<Result<Vec<_>, _>>()?;
        for p in &plates {
            resolve(&p.name, &p.attachment)?;
        }
        for m in &masses {
            resolve(&m.name, &m.attachment)?;
        }
        let beam_order = topological_order(&beams, &beam_parent)?;
        Ok(Self {
            name,
            hub,
            beams,
            plates,
            masses,
            basis,
            beam_order,
            beam_parent,
        })
    }

    /// Beam indices with every parent before its children.
    pub fn beam_order(&self) -> &[usize] {
        &self.beam_order
    }

    /// The parent beam of beam i (None: the hub).
    pub fn beam_parent(&self, i: usize) -> Option<usize> {
        self.beam_parent[i]
    }

    /// Index of the beam named `name`.
    pub fn beam_index(&self, name: &str) -> Option<usize> {
        self.beams.iter().position(|b| b.name == name)
    }

    /// Structure-frame position of an attachment.
    pub fn attachment_point(&self, att: &Attachment) -> Vec3 {
        match att {
            Attachment::Hub { point } => *point,
            Attachment::Beam { beam, station } => {
                let i = self.beam_index(beam).unwrap_or(0);
                self.beam_root(i) + self.beams[i].frame.ex * *station
            }
        }
    }

    /// Structure-frame position of beam i's root.
    pub fn beam_root(&self, i: usize) -> Vec3 {
        self.attachment_point(&self.beams[i].attachment)
    }

    /// Every component's name, in the order hub, beams, plates, masses.
    pub fn component_name(&self, id: ComponentId) -> &str {
        match id {
            ComponentId::Hub => "hub",
            ComponentId::Beam(i) => &self.beams[i].name,
            ComponentId::Plate(i) => &self.plates[i].name,
            ComponentId::Mass(i) => &self.masses[i].name,
        }
    }

    /// Mass properties of the whole structure about the structure-frame origin, from each
    /// component's closed-form mass properties.
    pub fn rigid_body(&self) -> RigidBody {
        let mut total = self.hub.rigid_body().about(-self.hub.center_of_mass);
        for b in &self.beams {
            total = total.plus(&b.rigid_body().about(-self.attachment_point(&b.attachment)));
        }
        for p in &self.plates {
            total = total.plus(&p.rigid_body().about(-self.attachment_point(&p.attachment)));
        }
        for m in &self.masses {
            total = total.plus(&m.rigid_body().about(-self.attachment_point(&m.attachment)));
        }
        total
    }

    /// Total mass, kg.
    pub fn total_mass(&self) -> f64 {
        self.rigid_body().mass
    }
}

fn topological_order(
    beams: &[Beam],
    parent: &[Option<usize>],
) -> Result<Vec<usize>, StructureError> {
    // 0 = unvisited, 1 = on the current path, 2 = done.
    let mut state = vec![0u8; beams.len()];
    let mut order = Vec::with_capacity(beams.len());
    for start in 0..beams.len() {
        let mut path = Vec::new();
        let mut cur = Some(start);
        while let Some(i) = cur {
            match state[i] {
                2 => break,
                1 => {
                    let from = path.iter().position(|&p| p == i).unwrap_or(0);
                    let mut names: Vec<String> = path[from..]
                        .iter()
                        .map(|&p: &usize| beams[p].name.clone())
                        .collect();
                    names.push(beams[i].name.clone());
                    return Err(StructureError::Cycle { path: names });
                }
                _ => {
                    state[i] = 1;
                    path.push(i);
                    cur = parent[i];
                }
            }
        }
        for &i in path.iter().rev() {
            state[i] = 2;
            order.push(i);
        }
    }
    Ok(order)
}
