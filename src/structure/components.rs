//! The components of the deployed spacecraft (MODEL.md §3.1): hub, beams, plates, lumped masses.
//!
//! Model limits, stated once: small deflections about the deployed configuration;
//! Euler–Bernoulli beams without shear deformation or bending rotary inertia (a beam's mass is
//! a line mass plus the polar inertia ρI_p about its axis); Kirchhoff plates, rigid in their
//! own plane, thin (the plate's mass is a sheet in its mid-plane); lumped masses rigid.

use super::{finite_vec, positive, rigid::RigidBody, unit, StructureError};
use crate::math::{Mat3, Vec3};

/// Whether the hub floats or is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HubMotion {
    /// Six rigid-body degrees of freedom (a spacecraft in orbit).
    Free,
    /// Held in inertial space (a test stand).
    Fixed,
}

/// The rigid hub. Its generalized coordinates are the translation of its centre of mass and
/// its small rotation vector (structure frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Hub {
    /// Free or fixed.
    pub motion: HubMotion,
    /// Mass, kg.
    pub mass: f64,
    /// Centre of mass, m.
    pub center_of_mass: Vec3,
    /// Inertia about the centre of mass, kg·m².
    pub inertia: Mat3,
}

impl Hub {
    /// A hub with the given mass properties (inertia already validated by
    /// [`super::inertia_tensor`]).
    pub fn new(
        motion: HubMotion,
        mass: f64,
        center_of_mass: Vec3,
        inertia: Mat3,
    ) -> Result<Self, StructureError> {
        positive("mass", mass)?;
        finite_vec("center_of_mass", center_of_mass)?;
        Ok(Self {
            motion,
            mass,
            center_of_mass,
            inertia,
        })
    }

    /// The paper's hub: a thin-walled circular cylinder (outer diameter, wall) of the given
    /// length along `axis`, centred at `center`, optionally closed by two end discs of the
    /// wall's thickness inside the tube. Exact hollow-cylinder formulas:
    /// m = ρπ(R² − r²)L, J_axial = m(R² + r²)/2, J_transverse = m(3(R² + r²) + L²)/12.
    #[allow(clippy::too_many_arguments)]
    pub fn cylinder(
        motion: HubMotion,
        diameter: f64,
        wall: f64,
        length: f64,
        axis: Vec3,
        center: Vec3,
        density: f64,
        closed_ends: bool,
    ) -> Result<Self, StructureError> {
        positive("diameter", diameter)?;
        positive("wall", wall)?;
        positive("length", length)?;
        finite_vec("center", center)?;
        let a = unit("axis", axis)?;
        let big_r = diameter / 2.0;
        if wall >= big_r {
            return Err(StructureError::WallTooThick {
                wall,
                radius: big_r,
            });
        }
        if closed_ends && 2.0 * wall >= length {
            return Err(StructureError::WallTooThick {
                wall,
                radius: length / 2.0,
            });
        }
        let r = big_r - wall;
        let along = a.outer(a);
        let across = Mat3::IDENTITY - along;
        let m = density * std::f64::consts::PI * (big_r * big_r - r * r) * length;
        let tube = RigidBody::from_cm(
            m,
            Vec3::ZERO,
            along * (m * (big_r * big_r + r * r) / 2.0)
                + across * (m * (3.0 * (big_r * big_r + r * r) + length * length) / 12.0),
        );
        let mut body = tube;
        if closed_ends {
            let md = density * std::f64::consts::PI * r * r * wall;
            let j = along * (md * r * r / 2.0) + across * (md * (3.0 * r * r + wall * wall) / 12.0);
            for s in [-1.0, 1.0] {
                body = body.plus(&RigidBody::from_cm(md, a * (s * (length - wall) / 2.0), j));
            }
        }
        Ok(Self {
            motion,
            mass: body.mass,
            center_of_mass: center,
            inertia: body.inertia_at_cm(),
        })
    }

    /// Mass properties about the hub's centre of mass.
    pub fn rigid_body(&self) -> RigidBody {
        RigidBody::from_cm(self.mass, Vec3::ZERO, self.inertia)
    }
}

/// Where a component is fixed.
#[derive(Debug, Clone, PartialEq)]
pub enum Attachment {
    /// To the hub, at a point of the structure frame.
    Hub {
        /// The attachment point, m.
        point: Vec3,
    },
    /// To a section of a beam, `station` metres from the beam's root.
    Beam {
        /// The parent beam's name.
        beam: String,
        /// Distance from the parent's root, m, in [0, parent length].
        station: f64,
    },
}

impl Attachment {
    /// The parent's name ("hub" or a beam).
    pub fn parent_name(&self) -> &str {
        match self {
            Attachment::Hub { .. } => "hub",
            Attachment::Beam { beam, .. } => beam,
        }
    }
}

/// Cross-section properties of a beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamSection {
    /// Area A, m².
    pub area: f64,
    /// Second moment about the section's y axis (bending w, in the x–z plane), m⁴.
    pub iy: f64,
    /// Second moment about the section's z axis (bending v, in the x–y plane), m⁴.
    pub iz: f64,
    /// Saint-Venant torsion constant J, m⁴.
    pub torsion_constant: f64,
    /// Polar second moment I_p (torsional rotary inertia ρI_p per length), m⁴.
    pub polar_inertia: f64,
}

impl BeamSection {
    /// A thin- or thick-walled circular tube: A = π(R² − r²), I = π(R⁴ − r⁴)/4, J = I_p = 2I.
    pub fn tube(outer_diameter: f64, wall: f64) -> Result<Self, StructureError> {
        positive("outer_diameter", outer_diameter)?;
        positive("wall", wall)?;
        let big_r = outer_diameter / 2.0;
        if wall >= big_r {
            return Err(StructureError::WallTooThick {
                wall,
                radius: big_r,
            });
        }
        let r = big_r - wall;
        let pi = std::f64::consts::PI;
        let i = pi * (big_r.powi(4) - r.powi(4)) / 4.0;
        Ok(Self {
            area: pi * (big_r * big_r - r * r),
            iy: i,
            iz: i,
            torsion_constant: 2.0 * i,
            polar_inertia: 2.0 * i,
        })
    }

    /// A general section given by its constants (all > 0).
    pub fn general(
        area: f64,
        iy: f64,
        iz: f64,
        torsion_constant: f64,
        polar_inertia: f64,
    ) -> Result<Self, StructureError> {
        positive("area", area)?;
        positive("iy", iy)?;
        positive("iz", iz)?;
        positive("torsion_constant", torsion_constant)?;
        positive("polar_inertia", polar_inertia)?;
        Ok(Self {
            area,
            iy,
            iz,
            torsion_constant,
            polar_inertia,
        })
    }
}

/// Number of Ritz functions per field of a beam.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BeamTerms {
    /// Bending functions per plane (v and w each).
    pub bending: usize,
    /// Torsion functions.
    pub torsion: usize,
    /// Axial functions.
    pub axial: usize,
}

/// Largest number of functions per field.
pub const MAX_TERMS: usize = 100;

pub(super) fn check_terms(field: &'static str, n: usize) -> Result<usize, StructureError> {
    if n == 0 || n > MAX_TERMS {
        Err(StructureError::Terms { field, value: n })
    } else {
        Ok(n)
    }
}

impl BeamTerms {
    /// Validates 1 ≤ terms ≤ 100 for each field.
    pub fn new(bending: usize, torsion: usize, axial: usize) -> Result<Self, StructureError> {
        Ok(Self {
            bending: check_terms("bending", bending)?,
            torsion: check_terms("torsion", torsion)?,
            axial: check_terms("axial", axial)?,
        })
    }

    /// Generalized coordinates of the beam: axial + 2 × bending + torsion.
    pub fn dof(&self) -> usize {
        self.axial + 2 * self.bending + self.torsion
    }
}

/// A local orthonormal frame (e_x along the element).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Element axis.
    pub ex: Vec3,
    /// Second axis.
    pub ey: Vec3,
    /// ex × ey.
    pub ez: Vec3,
}

impl Frame {
    /// The frame with e_x = axis and e_y = `y_axis` (if given, must be perpendicular to the
    /// axis) or, by default, e_y = normalize(Z × e_x) (or X × e_x when the axis is within
    /// ~25° of Z): a deterministic choice, documented in docs/scenario.md.
    pub fn new(axis: Vec3, y_axis: Option<Vec3>) -> Result<Self, StructureError> {
        let ex = unit("axis", axis)?;
        let ey = match y_axis {
            Some(y) => {
                let y = unit("y_axis", y)?;
                perpendicular("y_axis", ex, y)?;
                y
            }
            None => {
                let helper = if ex.get(2).abs() < 0.9 {
                    Vec3::unit(2)
                } else {
                    Vec3::unit(0)
                };
                helper.cross(ex).normalized()
            }
        };
        let ey = (ey - ex * ey.dot(ex)).normalized();
        Ok(Self {
            ex,
            ey,
            ez: ex.cross(ey),
        })
    }
}

/// Checks that `b` is perpendicular to `a` (both unit) to 1e-6 rad.
pub(super) fn perpendicular(field: &'static str, a: Vec3, b: Vec3) -> Result<(), StructureError> {
    let c = a.dot(b);
    if c.abs() > 1e-6 {
        return Err(StructureError::NotPerpendicular {
            field,
            angle_deg: c.clamp(-1.0, 1.0).acos().to_degrees(),
        });
    }
    Ok(())
}

/// A straight Euler–Bernoulli beam clamped at its root to its parent (MODEL.md §3.1).
/// Fields: axial u (along e_x), bending v (along e_y, stiffness EI_z), w (along e_z, EI_y),
/// torsion θ (about e_x).
#[derive(Debug, Clone, PartialEq)]
pub struct Beam {
    /// Unique name.
    pub name: String,
    /// Where the root is clamped.
    pub attachment: Attachment,
    /// Local frame.
    pub frame: Frame,
    /// Length L, m.
    pub length: f64,
    /// Young's modulus E, Pa.
    pub youngs_modulus: f64,
    /// Shear modulus G, Pa.
    pub shear_modulus: f64,
    /// Density ρ, kg/m³.
    pub density: f64,
    /// Section constants.
    pub section: BeamSection,
    /// Ritz functions per field.
    pub terms: BeamTerms,
}

impl Beam {
    /// Mass per length ρA, kg/m.
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.section.area
    }

    /// Total mass ρAL, kg.
    pub fn mass(&self) -> f64 {
        self.mass_per_length() * self.length
    }

    /// Mass properties about the root: line mass plus ρI_p about the axis (no rotary inertia
    /// of the section about transverse axes, consistent with the kinetic energy of §3.1).
    pub fn rigid_body(&self) -> RigidBody {
        let m = self.mass();
        let l = self.length;
        let ex = self.frame.ex;
        let along = ex.outer(ex);
        RigidBody {
            mass: m,
            first_moment: ex * (m * l / 2.0),
            inertia: (Mat3::IDENTITY - along) * (m * l * l / 3.0)
                + along * (self.density * self.section.polar_inertia * l),
        }
    }
}

/// Number of Ritz functions of a plate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlateTerms {
    /// Functions along the length (clamped–free).
    pub length: usize,
    /// Functions across the width (free–free, rigid pair included).
    pub width: usize,
}

impl PlateTerms {
    /// Validates 1 ≤ terms ≤ 100 in each direction.
    pub fn new(length: usize, width: usize) -> Result<Self, StructureError> {
        Ok(Self {
            length: check_terms("length", length)?,
            width: check_terms("width", width)?,
        })
    }

    /// Generalized coordinates: length × width.
    pub fn dof(&self) -> usize {
        self.length * self.width
    }
}

/// A rectangular Kirchhoff plate clamped along its root edge to a rigid massless yoke
/// (MODEL.md §3.1). Local coordinates: x ∈ [0, a] along `length_axis`, y ∈ [−b/2, b/2] along
/// `width_axis` = normal × length_axis; the root edge's centre is the attachment point.
#[derive(Debug, Clone, PartialEq)]
pub struct Plate {
    /// Unique name.
    pub name: String,
    /// Where the yoke is fixed.
    pub attachment: Attachment,
    /// Unit vector e_a, away from the clamped edge.
    pub length_axis: Vec3,
    /// Unit normal n.
    pub normal: Vec3,
    /// Length a, m.
    pub length: f64,
    /// Width b, m.
    pub width: f64,
    /// Mass per area μ = ρh, kg/m².
    pub areal_density: f64,
    /// Bending stiffness D = Eh³/12(1 − ν²), N·m.
    pub bending_stiffness: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Ritz functions.
    pub terms: PlateTerms,
}

impl Plate {
    /// Validates the geometry and stiffness of a plate.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: String,
        attachment: Attachment,
        length_axis: Vec3,
        normal: Vec3,
        length: f64,
        width: f64,
        areal_density: f64,
        bending_stiffness: f64,
        poisson_ratio: f64,
        terms: PlateTerms,
    ) -> Result<Self, StructureError> {
        let length_axis = unit("length_axis", length_axis)?;
        let normal = unit("normal", normal)?;
        perpendicular("normal", length_axis, normal)?;
        positive("length", length)?;
        positive("width", width)?;
        positive("areal_density", areal_density)?;
        positive("bending_stiffness", bending_stiffness)?;
        if !(poisson_ratio.is_finite() && poisson_ratio > -1.0 && poisson_ratio < 0.5) {
            return Err(StructureError::PoissonRatio {
                value: poisson_ratio,
            });
        }
        Ok(Self {
            name,
            attachment,
            length_axis,
            normal,
            length,
            width,
            areal_density,
            bending_stiffness,
            poisson_ratio,
            terms,
        })
    }

    /// D = Eh³/12(1 − ν²) and μ = ρh of a homogeneous plate of thickness h.
    pub fn homogeneous_properties(thickness: f64, e: f64, nu: f64, rho: f64) -> (f64, f64) {
        (
            e * thickness.powi(3) / (12.0 * (1.0 - nu * nu)),
            rho * thickness,
        )
    }

    /// Width direction e_b = n × e_a.
    pub fn width_axis(&self) -> Vec3 {
        self.normal.cross(self.length_axis)
    }

    /// Mass μab, kg.
    pub fn mass(&self) -> f64 {
        self.areal_density * self.length * self.width
    }

    /// Mass properties about the root-edge centre (a uniform sheet).
    pub fn rigid_body(&self) -> RigidBody {
        let (a, b) = (self.length, self.width);
        let m = self.mass();
        let (ea, eb) = (self.length_axis, self.width_axis());
        let sxx = m * a * a / 3.0;
        let syy = m * b * b / 12.0;
        RigidBody {
            mass: m,
            first_moment: ea * (m * a / 2.0),
            inertia: Mat3::IDENTITY * (sxx + syy) - ea.outer(ea) * sxx - eb.outer(eb) * syy,
        }
    }
}

/// A rigid lumped mass fixed to the hub or a beam section, its centre of mass `offset` from
/// the attachment point (rigid arm).
#[derive(Debug, Clone, PartialEq)]
pub struct LumpedMass {
    /// Unique name.
    pub name: String,
    /// Where it is fixed.
    pub attachment: Attachment,
    /// Centre of mass relative to the attachment point, m.
    pub offset: Vec3,
    /// Mass, kg.
    pub mass: f64,
    /// Inertia about its centre of mass, kg·m².
    pub inertia: Mat3,
}

impl LumpedMass {
    /// Mass properties about the attachment point.
    pub fn rigid_body(&self) -> RigidBody {
        RigidBody::from_cm(self.mass, self.offset, self.inertia)
    }
}
