//! The deployed spacecraft as a tree of components rooted at the hub (docs/theory.md §1).

pub mod components;
mod error;
pub mod material;
pub mod rigid;

pub use components::{
    Attachment, Beam, BeamSection, BeamSpec, BeamTerms, Cylinder, Frame, Hub, HubMotion, LineHinge,
    LumpedMass, Plate, PlateSpec, PlateStiffness, PlateTerms, MAX_TERMS,
};
pub(crate) use error::{in_range, name, point, unit};
pub use error::{Field, StructureError};
pub use material::Material;
pub use rigid::{inertia_tensor, RigidBody};

use crate::basis::BasisKind;
use crate::math::Vec3;

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
/// attachment tree checked (parents exist, no cycle, stations on their parents). Built once
/// by [`Structure::new`] and read through accessors: nothing can break the tree afterwards.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    pub(crate) name: String,
    pub(crate) hub: Hub,
    pub(crate) beams: Vec<Beam>,
    pub(crate) plates: Vec<Plate>,
    pub(crate) masses: Vec<LumpedMass>,
    pub(crate) basis: BasisKind,
    beam_order: Vec<usize>,
}

/// Everything a structure is made of, for [`Structure::new`].
#[derive(Debug, Clone)]
pub struct Parts {
    /// Name (free text).
    pub name: String,
    /// The hub.
    pub hub: Hub,
    /// Beams; attachments refer to beams by their index in this list.
    pub beams: Vec<Beam>,
    /// Plates.
    pub plates: Vec<Plate>,
    /// Lumped masses.
    pub masses: Vec<LumpedMass>,
    /// Ritz basis.
    pub basis: BasisKind,
}

impl Structure {
    /// Checks the attachment tree (unique names, parents that exist, no cycle, stations on
    /// their parents) and builds the structure.
    ///
    /// ```
    /// use flexcraft::math::Vec3;
    /// use flexcraft::structure::*;
    /// let aluminium = Material::new(70e9, 0.3, 2700.0, None)?;
    /// let hub = Hub::new(HubMotion::Fixed, 100.0, Vec3::ZERO, inertia_tensor(&[10.0, 10.0, 10.0])?)?;
    /// let mast = Beam::new(BeamSpec {
    ///     name: "mast".into(),
    ///     attachment: Attachment::Hub { point: Vec3::ZERO },
    ///     frame: Frame::new(Vec3([1.0, 0.0, 0.0]), None)?,
    ///     length: 2.0,
    ///     material: aluminium,
    ///     section: BeamSection::tube(0.05, 0.002)?,
    ///     terms: BeamTerms::new(8, 6, 4)?,
    /// })?;
    /// let s = Structure::new(Parts {
    ///     name: "cantilever".into(),
    ///     hub,
    ///     beams: vec![mast],
    ///     plates: vec![],
    ///     masses: vec![],
    ///     basis: flexcraft::basis::BasisKind::Legendre,
    /// })?;
    /// assert!((s.total_mass() - 100.0 - s.beams()[0].mass()).abs() < 1e-9);
    /// # Ok::<(), flexcraft::structure::StructureError>(())
    /// ```
    pub fn new(parts: Parts) -> Result<Self, StructureError> {
        let Parts {
            name,
            hub,
            beams,
            plates,
            masses,
            basis,
        } = parts;
        // Every attached component once: its id, name and attachment. ("hub" cannot be a
        // component's name: the constructors refuse it.)
        let components = (beams.iter().enumerate())
            .map(|(i, b)| (ComponentId::Beam(i), &b.name, &b.attachment))
            .chain(
                (plates.iter().enumerate())
                    .map(|(i, p)| (ComponentId::Plate(i), &p.name, &p.attachment)),
            )
            .chain(
                (masses.iter().enumerate())
                    .map(|(i, m)| (ComponentId::Mass(i), &m.name, &m.attachment)),
            );
        let mut seen = std::collections::BTreeSet::new();
        for (component, n, att) in components {
            if !seen.insert(n) {
                return Err(StructureError::DuplicateName {
                    component,
                    name: n.clone(),
                });
            }
            if let Attachment::Beam { beam, station } = att {
                let parent = beams.get(*beam).ok_or(StructureError::UnknownParent {
                    component,
                    parent: *beam,
                    count: beams.len(),
                })?;
                if *station > parent.length * (1.0 + 1e-12) {
                    return Err(StructureError::StationBeyondParent {
                        component,
                        parent: parent.name.clone(),
                        station_m: *station,
                        length_m: parent.length,
                    });
                }
            }
        }
        let beam_order = topological_order(&beams)?;
        Ok(Self {
            name,
            hub,
            beams,
            plates,
            masses,
            basis,
            beam_order,
        })
    }

    /// The structure's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The hub.
    pub fn hub(&self) -> &Hub {
        &self.hub
    }

    /// The beams, in the order given.
    pub fn beams(&self) -> &[Beam] {
        &self.beams
    }

    /// The plates.
    pub fn plates(&self) -> &[Plate] {
        &self.plates
    }

    /// The lumped masses.
    pub fn masses(&self) -> &[LumpedMass] {
        &self.masses
    }

    /// The Ritz basis.
    pub fn basis(&self) -> BasisKind {
        self.basis
    }

    /// Beam indices with every parent before its children.
    pub fn beam_order(&self) -> &[usize] {
        &self.beam_order
    }

    /// The parent beam of beam i (None: the hub).
    pub fn beam_parent(&self, i: usize) -> Option<usize> {
        self.beams[i].attachment.parent_beam()
    }

    /// Index of the beam named `name`.
    pub fn beam_index(&self, name: &str) -> Option<usize> {
        self.beams.iter().position(|b| b.name == name)
    }

    /// The name of an attachment's parent ("hub" or the beam's).
    pub fn parent_name(&self, att: &Attachment) -> &str {
        match att.parent_beam() {
            None => "hub",
            Some(i) => &self.beams[i].name,
        }
    }

    /// Structure-frame position of an attachment.
    pub fn attachment_point(&self, att: &Attachment) -> Vec3 {
        match att {
            Attachment::Hub { point } => *point,
            Attachment::Beam { beam, station } => {
                self.beam_root(*beam) + self.beams[*beam].frame.ex * *station
            }
        }
    }

    /// Structure-frame position of beam i's root.
    pub fn beam_root(&self, i: usize) -> Vec3 {
        self.attachment_point(&self.beams[i].attachment)
    }

    /// Component `id` is beam `root`, or hangs on it through any chain of parents.
    pub fn in_subtree(&self, id: ComponentId, root: usize) -> bool {
        id == ComponentId::Beam(root) || self.hanging_station(id, root).is_some()
    }

    /// The station (m from its root) at which component `id` hangs on beam `beam` through
    /// its chain of parents; None if it does not hang on the beam (or is the beam).
    pub fn hanging_station(&self, id: ComponentId, beam: usize) -> Option<f64> {
        let mut att = match id {
            ComponentId::Hub => return None,
            ComponentId::Beam(i) if i == beam => return None,
            ComponentId::Beam(i) => &self.beams[i].attachment,
            ComponentId::Plate(i) => &self.plates[i].attachment,
            ComponentId::Mass(i) => &self.masses[i].attachment,
        };
        loop {
            match att {
                Attachment::Hub { .. } => return None,
                Attachment::Beam { beam: b, station } if *b == beam => return Some(*station),
                Attachment::Beam { beam: b, .. } => att = &self.beams[*b].attachment,
            }
        }
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

fn topological_order(beams: &[Beam]) -> Result<Vec<usize>, StructureError> {
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
                    return Err(StructureError::Cycle {
                        component: ComponentId::Beam(path[from]),
                        path: names,
                    });
                }
                _ => {
                    state[i] = 1;
                    path.push(i);
                    cur = beams[i].attachment.parent_beam();
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
