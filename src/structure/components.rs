//! The components of the deployed spacecraft: hub, beams, plates, lumped masses.
//!
//! Model limits, stated once: small deflections about the deployed configuration;
//! Euler–Bernoulli beams without shear deformation or bending rotary inertia (a beam's mass is
//! a line mass plus the polar inertia ρI_p about its axis); Kirchhoff plates, rigid in their
//! own plane, thin (the plate's mass is a sheet in its mid-plane); lumped masses rigid.
//!
//! Every component is validated by its constructor (the only place each rule is checked;
//! ranges in [`crate::limits`]) and is read-only afterwards: fields are readable inside the
//! crate and through accessors outside it.

use super::{in_range, name, point, rigid::RigidBody, unit, Field, Material, StructureError};
use crate::limits as L;
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
    pub(crate) motion: HubMotion,
    pub(crate) mass: f64,
    pub(crate) center_of_mass: Vec3,
    pub(crate) inertia: Mat3,
    /// The cylinder it was built from ([`Hub::cylinder`]), for drawing.
    pub(crate) shape: Option<Cylinder>,
}

/// The paper's hub: a circular cylinder of one material, for [`Hub::cylinder`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    /// Outer diameter, m.
    pub diameter: f64,
    /// Wall thickness, m.
    pub wall: f64,
    /// Length, m.
    pub length: f64,
    /// Axis direction (any scale).
    pub axis: Vec3,
    /// Centre, m.
    pub center: Vec3,
    /// Closed by two end discs of the wall's thickness.
    pub closed_ends: bool,
}

impl Hub {
    /// A hub with the given mass properties (inertia from [`super::inertia_tensor`]).
    pub fn new(
        motion: HubMotion,
        mass: f64,
        center_of_mass: Vec3,
        inertia: Mat3,
    ) -> Result<Self, StructureError> {
        Ok(Self {
            motion,
            mass: in_range(Field::Mass, mass, L::MASS)?,
            center_of_mass: point(Field::CenterOfMass, center_of_mass)?,
            inertia,
            shape: None,
        })
    }

    /// A thin-walled circular cylinder of `material`, optionally closed by two end discs of
    /// the wall's thickness inside the tube. Exact hollow-cylinder formulas:
    /// m = ρπ(R² − r²)L, J_axial = m(R² + r²)/2, J_transverse = m(3(R² + r²) + L²)/12.
    pub fn cylinder(
        motion: HubMotion,
        c: Cylinder,
        material: &Material,
    ) -> Result<Self, StructureError> {
        let diameter = in_range(Field::Diameter, c.diameter, L::LENGTH)?;
        let wall = in_range(Field::Wall, c.wall, L::SECTION)?;
        let length = in_range(Field::Length, c.length, L::LENGTH)?;
        let a = unit(Field::Axis, c.axis)?;
        let center = point(Field::Center, c.center)?;
        let big_r = diameter / 2.0;
        if wall >= big_r {
            return Err(StructureError::WallTooThick {
                wall,
                radius: big_r,
            });
        }
        if c.closed_ends && 2.0 * wall >= length {
            return Err(StructureError::WallTooThick {
                wall,
                radius: length / 2.0,
            });
        }
        let density = material.density;
        let r = big_r - wall;
        let along = a.outer(a);
        let across = Mat3::IDENTITY - along;
        let m = density * std::f64::consts::PI * (big_r * big_r - r * r) * length;
        let mut body = RigidBody::from_cm(
            m,
            Vec3::ZERO,
            along * (m * (big_r * big_r + r * r) / 2.0)
                + across * (m * (3.0 * (big_r * big_r + r * r) + length * length) / 12.0),
        );
        if c.closed_ends {
            let md = density * std::f64::consts::PI * r * r * wall;
            let j = along * (md * r * r / 2.0) + across * (md * (3.0 * r * r + wall * wall) / 12.0);
            for s in [-1.0, 1.0] {
                body = body.plus(&RigidBody::from_cm(md, a * (s * (length - wall) / 2.0), j));
            }
        }
        // The derived body obeys the same ranges as a hub given by its mass properties.
        let inertia = body.inertia_at_cm();
        let j = inertia.0;
        super::inertia_tensor(&[j[0][0], j[1][1], j[2][2], j[0][1], j[0][2], j[1][2]])?;
        Ok(Self {
            motion,
            mass: in_range(Field::Mass, body.mass, L::MASS)?,
            center_of_mass: center,
            inertia,
            shape: Some(Cylinder {
                axis: a,
                center,
                ..c
            }),
        })
    }

    /// The cylinder the hub was built from, if it was (None: given by its mass properties).
    pub fn shape(&self) -> Option<Cylinder> {
        self.shape
    }

    /// Free or fixed.
    pub fn motion(&self) -> HubMotion {
        self.motion
    }

    /// Mass, kg.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Centre of mass, m.
    pub fn center_of_mass(&self) -> Vec3 {
        self.center_of_mass
    }

    /// Inertia about the centre of mass, kg·m².
    pub fn inertia(&self) -> Mat3 {
        self.inertia
    }

    /// Mass properties about the hub's centre of mass.
    pub fn rigid_body(&self) -> RigidBody {
        RigidBody::from_cm(self.mass, Vec3::ZERO, self.inertia)
    }
}

/// Where a component is fixed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Attachment {
    /// To the hub, at a point of the structure frame.
    Hub {
        /// The attachment point, m.
        point: Vec3,
    },
    /// To a section of a beam, `station` metres from the beam's root.
    Beam {
        /// The parent beam's index in the structure's beam list.
        beam: usize,
        /// Distance from the parent's root, m, in [0, parent length].
        station: f64,
    },
}

impl Attachment {
    /// Checks the point's or station's range ([`L::COORDINATE`], [`L::STATION`]); the
    /// parent's existence and length are checked by [`super::Structure::new`].
    fn validated(self) -> Result<Self, StructureError> {
        match self {
            Attachment::Hub { point: p } => Ok(Attachment::Hub {
                point: point(Field::Root, p)?,
            }),
            Attachment::Beam { beam, station } => Ok(Attachment::Beam {
                beam,
                station: in_range(Field::Station, station, L::STATION)?,
            }),
        }
    }

    /// The parent beam's index (None: the hub).
    pub fn parent_beam(&self) -> Option<usize> {
        match self {
            Attachment::Hub { .. } => None,
            Attachment::Beam { beam, .. } => Some(*beam),
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
        in_range(Field::OuterDiameter, outer_diameter, L::SECTION)?;
        in_range(Field::Wall, wall, L::SECTION)?;
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

    /// A general section given by its constants ([`L::AREA`], [`L::SECOND_MOMENT`]).
    pub fn general(
        area: f64,
        iy: f64,
        iz: f64,
        torsion_constant: f64,
        polar_inertia: f64,
    ) -> Result<Self, StructureError> {
        Ok(Self {
            area: in_range(Field::Area, area, L::AREA)?,
            iy: in_range(Field::Iy, iy, L::SECOND_MOMENT)?,
            iz: in_range(Field::Iz, iz, L::SECOND_MOMENT)?,
            torsion_constant: in_range(Field::TorsionConstant, torsion_constant, L::SECOND_MOMENT)?,
            polar_inertia: in_range(Field::PolarInertia, polar_inertia, L::SECOND_MOMENT)?,
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

fn check_terms(field: Field, n: usize) -> Result<usize, StructureError> {
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
            bending: check_terms(Field::TermsBending, bending)?,
            torsion: check_terms(Field::TermsTorsion, torsion)?,
            axial: check_terms(Field::TermsAxial, axial)?,
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
        let ex = unit(Field::Axis, axis)?;
        let ey = match y_axis {
            Some(y) => {
                let y = unit(Field::YAxis, y)?;
                perpendicular(Field::YAxis, ex, y)?;
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
fn perpendicular(field: Field, a: Vec3, b: Vec3) -> Result<(), StructureError> {
    let c = a.dot(b);
    if c.abs() > 1e-6 {
        return Err(StructureError::NotPerpendicular {
            field,
            angle_deg: c.clamp(-1.0, 1.0).acos().to_degrees(),
        });
    }
    Ok(())
}

/// A straight Euler–Bernoulli beam clamped at its root to its parent.
/// Fields: axial u (along e_x), bending v (along e_y, stiffness EI_z), w (along e_z, EI_y),
/// torsion θ (about e_x).
#[derive(Debug, Clone, PartialEq)]
pub struct Beam {
    pub(crate) name: String,
    pub(crate) attachment: Attachment,
    pub(crate) frame: Frame,
    pub(crate) length: f64,
    pub(crate) youngs_modulus: f64,
    pub(crate) shear_modulus: f64,
    pub(crate) density: f64,
    pub(crate) section: BeamSection,
    pub(crate) terms: BeamTerms,
}

/// What a beam is made of, for [`Beam::new`].
#[derive(Debug, Clone)]
pub struct BeamSpec {
    /// Unique name ([`L::valid_name`]).
    pub name: String,
    /// Where the root is clamped.
    pub attachment: Attachment,
    /// Local frame.
    pub frame: Frame,
    /// Length L, m.
    pub length: f64,
    /// Material.
    pub material: Material,
    /// Section constants.
    pub section: BeamSection,
    /// Ritz functions per field.
    pub terms: BeamTerms,
}

impl Beam {
    /// Validates the name, length and attachment.
    pub fn new(s: BeamSpec) -> Result<Self, StructureError> {
        Ok(Self {
            name: name(&s.name)?,
            attachment: s.attachment.validated()?,
            frame: s.frame,
            length: in_range(Field::Length, s.length, L::LENGTH)?,
            youngs_modulus: s.material.youngs_modulus,
            shear_modulus: s.material.shear_modulus,
            density: s.material.density,
            section: s.section,
            terms: s.terms,
        })
    }

    /// Unique name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where the root is clamped.
    pub fn attachment(&self) -> Attachment {
        self.attachment
    }

    /// Local frame.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// Length L, m.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Young's modulus E, Pa.
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }

    /// Shear modulus G, Pa.
    pub fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }

    /// Density ρ, kg/m³.
    pub fn density(&self) -> f64 {
        self.density
    }

    /// Section constants.
    pub fn section(&self) -> BeamSection {
        self.section
    }

    /// Ritz functions per field.
    pub fn terms(&self) -> BeamTerms {
        self.terms
    }

    /// Mass per length ρA, kg/m.
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.section.area
    }

    /// Total mass ρAL, kg.
    pub fn mass(&self) -> f64 {
        self.mass_per_length() * self.length
    }

    /// Mass properties about the root: line mass plus ρI_p about the axis (no rotary inertia
    /// of the section about transverse axes, consistent with the beam's kinetic energy).
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
            length: check_terms(Field::TermsLength, length)?,
            width: check_terms(Field::TermsWidth, width)?,
        })
    }

    /// Generalized coordinates: length × width.
    pub fn dof(&self) -> usize {
        self.length * self.width
    }
}

/// How a plate's stiffness and mass are given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlateStiffness {
    /// A homogeneous plate: D = Eh³/12(1 − ν²), μ = ρh.
    Homogeneous {
        /// Thickness h, m.
        thickness: f64,
        /// Its material.
        material: Material,
    },
    /// Given constants (e.g. a sandwich panel).
    Given {
        /// Mass per area μ, kg/m².
        areal_density: f64,
        /// Bending stiffness D, N·m.
        bending_stiffness: f64,
        /// Poisson's ratio ν.
        poisson_ratio: f64,
    },
}

/// What a plate is made of, for [`Plate::new`].
#[derive(Debug, Clone)]
pub struct PlateSpec {
    /// Unique name ([`L::valid_name`]).
    pub name: String,
    /// Where the yoke is fixed.
    pub attachment: Attachment,
    /// Direction away from the clamped edge (any scale).
    pub length_axis: Vec3,
    /// Normal (any scale), perpendicular to the length axis.
    pub normal: Vec3,
    /// Length a, m.
    pub length: f64,
    /// Width b, m.
    pub width: f64,
    /// Stiffness and mass.
    pub stiffness: PlateStiffness,
    /// Ritz functions.
    pub terms: PlateTerms,
}

/// A rectangular Kirchhoff plate clamped along its root edge to a rigid massless yoke.
/// Local coordinates: x ∈ [0, a] along `length_axis`, y ∈ [−b/2, b/2] along
/// `width_axis` = normal × length_axis; the root edge's centre is the attachment point.
#[derive(Debug, Clone, PartialEq)]
pub struct Plate {
    pub(crate) name: String,
    pub(crate) attachment: Attachment,
    pub(crate) length_axis: Vec3,
    pub(crate) normal: Vec3,
    pub(crate) length: f64,
    pub(crate) width: f64,
    pub(crate) areal_density: f64,
    pub(crate) bending_stiffness: f64,
    pub(crate) poisson_ratio: f64,
    pub(crate) terms: PlateTerms,
    pub(crate) hinges: Vec<LineHinge>,
    /// W (functions × lines): the plate's kink function i is Σ_j W_ij K_j (the identity for
    /// independent hinges; one row for hinges an ideal cable ties).
    pub(crate) hinge_functions: Vec<Vec<f64>>,
    /// Stiffness coupling the lines' rotations besides each line's own spring (lines × lines,
    /// N·m/rad; an elastic cable's), empty for none.
    pub(crate) hinge_coupling: Vec<Vec<f64>>,
}

/// A latched hinge line across a plate's width: the compliant latch of a folded array, kept
/// in the deployed wing's model (docs/theory.md §1.6). The plate is cut along the line x = `at`
/// and the two sides are joined by a continuous line hinge of rotational stiffness
/// `stiffness`/b per unit length (and a dashpot `damping`/b): a uniform relative rotation θ
/// about the line stores ½ k_L θ², as the latch spring of the deployment does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineHinge {
    /// Distance of the line from the root edge, m (0 is the root hinge).
    pub at: f64,
    /// k_L, N·m/rad, for a uniform rotation about the line.
    pub stiffness: f64,
    /// c_L, N·m·s/rad, likewise.
    pub damping: f64,
    /// The line's rotation at the latched array's equilibrium, rad, about e_a × n: where the
    /// latch springs hold the hinge springs' preload (and a cable's); the straight plate is
    /// the model's equilibrium, so a hand-over and the latch moments measure from it.
    pub rest: f64,
}

impl Plate {
    /// Validates the name, geometry, stiffness and attachment of a plate.
    pub fn new(s: PlateSpec) -> Result<Self, StructureError> {
        let length_axis = unit(Field::LengthAxis, s.length_axis)?;
        let normal = unit(Field::Normal, s.normal)?;
        perpendicular(Field::Normal, length_axis, normal)?;
        let (areal_density, bending_stiffness, poisson_ratio) = match s.stiffness {
            PlateStiffness::Homogeneous {
                thickness,
                material,
            } => {
                let h = in_range(Field::Thickness, thickness, L::SECTION)?;
                let nu = material.poisson_ratio;
                // The derived constants obey the ranges of given ones (refused at the
                // thickness, the value that sets them).
                let mu = material.density * h;
                let d = material.youngs_modulus * h.powi(3) / (12.0 * (1.0 - nu * nu));
                if !(L::AREAL_DENSITY.contains(mu) && L::BENDING_STIFFNESS.contains(d)) {
                    return Err(StructureError::DerivedOutOfRange {
                        field: Field::Thickness,
                        areal_density: mu,
                        bending_stiffness: d,
                    });
                }
                (mu, d, nu)
            }
            PlateStiffness::Given {
                areal_density,
                bending_stiffness,
                poisson_ratio,
            } => (
                in_range(Field::ArealDensity, areal_density, L::AREAL_DENSITY)?,
                in_range(
                    Field::BendingStiffness,
                    bending_stiffness,
                    L::BENDING_STIFFNESS,
                )?,
                in_range(Field::PoissonRatio, poisson_ratio, L::POISSON)?,
            ),
        };
        Ok(Self {
            name: name(&s.name)?,
            attachment: s.attachment.validated()?,
            length_axis,
            normal,
            length: in_range(Field::Length, s.length, L::LENGTH)?,
            width: in_range(Field::Width, s.width, L::LENGTH)?,
            areal_density,
            bending_stiffness,
            poisson_ratio,
            terms: s.terms,
            hinges: Vec::new(),
            hinge_functions: Vec::new(),
            hinge_coupling: Vec::new(),
        })
    }

    /// The plate cut along `hinges` (ascending positions in [0, a), positive finite stiffness,
    /// finite damping ≥ 0), each line joined by its hinge spring ([`LineHinge`]).
    pub fn with_hinges(mut self, hinges: Vec<LineHinge>) -> Result<Self, StructureError> {
        let mut last = -1.0;
        for (i, h) in hinges.iter().enumerate() {
            let reason = if !(h.at >= 0.0 && h.at < self.length && h.at > last) {
                Some(format!(
                    "hinge line {} at {:e} m: positions must ascend within [0, {:e}) m",
                    i + 1,
                    h.at,
                    self.length
                ))
            } else if !(h.stiffness.is_finite() && h.stiffness > 0.0) {
                Some(format!(
                    "hinge line {}: stiffness {:e} N·m/rad must be positive and finite",
                    i + 1,
                    h.stiffness
                ))
            } else if !h.rest.is_finite() {
                Some(format!(
                    "hinge line {}: rest rotation {:e} rad is not finite",
                    i + 1,
                    h.rest
                ))
            } else if !(h.damping.is_finite() && h.damping >= 0.0) {
                Some(format!(
                    "hinge line {}: damping {:e} N·m·s/rad must be finite and not negative",
                    i + 1,
                    h.damping
                ))
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(StructureError::InvalidHinge { reason });
            }
            last = h.at;
        }
        let n = hinges.len();
        self.hinges = hinges;
        self.hinge_functions = (0..n)
            .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
            .collect();
        self.hinge_coupling = Vec::new();
        Ok(self)
    }

    /// The hinge lines moving together: the plate's kink functions become the combinations
    /// `functions` (rows of weights on the lines' kinks; an ideal cable's one row), and
    /// `coupling` (lines × lines, N·m/rad, symmetric; empty for none) adds stiffness between
    /// the lines' rotations (an elastic cable's). Call after [`Plate::with_hinges`].
    pub fn with_tied_hinges(
        mut self,
        functions: Vec<Vec<f64>>,
        coupling: Vec<Vec<f64>>,
    ) -> Result<Self, StructureError> {
        let n = self.hinges.len();
        let bad = |v: &Vec<Vec<f64>>, rows: Option<usize>| {
            rows.is_some_and(|r| v.len() != r)
                || v.iter()
                    .any(|r| r.len() != n || r.iter().any(|x| !x.is_finite()))
        };
        if functions.is_empty() || bad(&functions, None) {
            return Err(StructureError::InvalidHinge {
                reason: format!("tied hinge functions need rows of {n} finite weights"),
            });
        }
        if !coupling.is_empty() && bad(&coupling, Some(n)) {
            return Err(StructureError::InvalidHinge {
                reason: format!("a hinge coupling is {n} × {n} finite values"),
            });
        }
        self.hinge_functions = functions;
        self.hinge_coupling = coupling;
        Ok(self)
    }

    /// The stiffness (`damping` = false) or damping between the plate's kink functions for a
    /// uniform rotation of each line: S_ii' = Σ_jl W_ij (diag(k or c) + coupling)_jl W_i'l
    /// (the coupling is stiffness only), per radian², N·m/rad or N·m·s/rad.
    pub fn hinge_function_matrix(&self, damping: bool) -> Vec<Vec<f64>> {
        let w = &self.hinge_functions;
        let n = self.hinges.len();
        let line = |j: usize, l: usize| -> f64 {
            let own = if j == l {
                if damping {
                    self.hinges[j].damping
                } else {
                    self.hinges[j].stiffness
                }
            } else {
                0.0
            };
            let c = if damping {
                0.0
            } else {
                self.hinge_coupling.get(j).map_or(0.0, |r| r[l])
            };
            own + c
        };
        w.iter()
            .map(|wi| {
                w.iter()
                    .map(|wk| {
                        (0..n)
                            .flat_map(|j| (0..n).map(move |l| (j, l)))
                            .map(|(j, l)| wi[j] * line(j, l) * wk[l])
                            .sum()
                    })
                    .collect()
            })
            .collect()
    }

    /// The weights W of the kink functions on the lines ([`Plate::with_tied_hinges`]).
    pub fn hinge_functions(&self) -> &[Vec<f64>] {
        &self.hinge_functions
    }

    /// The latched hinge lines ([`Plate::with_hinges`]; none for an uncut plate).
    pub fn hinges(&self) -> &[LineHinge] {
        &self.hinges
    }

    /// The hinge lines' positions as fractions ξ = x/a of the length.
    pub fn hinge_positions(&self) -> Vec<f64> {
        self.hinges.iter().map(|h| h.at / self.length).collect()
    }

    /// Number of Ritz coordinates: (length terms + kink functions) × width terms.
    pub fn dof(&self) -> usize {
        (self.terms.length + self.hinge_functions.len()) * self.terms.width
    }

    /// Unique name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where the yoke is fixed.
    pub fn attachment(&self) -> Attachment {
        self.attachment
    }

    /// Unit vector e_a, away from the clamped edge.
    pub fn length_axis(&self) -> Vec3 {
        self.length_axis
    }

    /// Unit normal n.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// Length a, m.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Width b, m.
    pub fn width(&self) -> f64 {
        self.width
    }

    /// Mass per area μ = ρh, kg/m².
    pub fn areal_density(&self) -> f64 {
        self.areal_density
    }

    /// Bending stiffness D, N·m.
    pub fn bending_stiffness(&self) -> f64 {
        self.bending_stiffness
    }

    /// Poisson's ratio ν.
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }

    /// Ritz functions.
    pub fn terms(&self) -> PlateTerms {
        self.terms
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
    pub(crate) name: String,
    pub(crate) attachment: Attachment,
    pub(crate) offset: Vec3,
    pub(crate) mass: f64,
    pub(crate) inertia: Mat3,
}

impl LumpedMass {
    /// Validates the name, attachment, offset and mass; `inertia` about the centre of mass
    /// (from [`super::inertia_tensor`]; zero for a point mass).
    pub fn new(
        name_: &str,
        attachment: Attachment,
        offset: Vec3,
        mass: f64,
        inertia: Mat3,
    ) -> Result<Self, StructureError> {
        Ok(Self {
            name: name(name_)?,
            attachment: attachment.validated()?,
            offset: point(Field::Offset, offset)?,
            mass: in_range(Field::Mass, mass, L::MASS)?,
            inertia,
        })
    }

    /// Unique name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where it is fixed.
    pub fn attachment(&self) -> Attachment {
        self.attachment
    }

    /// Centre of mass relative to the attachment point, m.
    pub fn offset(&self) -> Vec3 {
        self.offset
    }

    /// Mass, kg.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Inertia about its centre of mass, kg·m².
    pub fn inertia(&self) -> Mat3 {
        self.inertia
    }

    /// Mass properties about the attachment point.
    pub fn rigid_body(&self) -> RigidBody {
        RigidBody::from_cm(self.mass, self.offset, self.inertia)
    }
}
