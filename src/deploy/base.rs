//! The base that carries the deploying array (docs/theory.md §2): the hub with every beam, lumped
//! mass and plate other than the deploying one, elastic by its hub-fixed Ritz modes in the
//! hub's floating frame.
//!
//! The base's Ritz model is the structure's without the deploying plate; its hub-fixed modes
//! (K_ee φ = ω² M_ee φ on the elastic coordinates, mass-normalised) are truncated to the
//! `base_modes` lowest. The base's kinetic energy is written through the inertia invariants
//! of [`super::inertia`], summed over a cloud of mass points: Gauss points along every beam
//! (ρA w L each, with the torsional inertia ρI_p w L about the axis as a rotary point) and
//! over every plate (μ w dA), the hub and every lumped mass as a point at its centre of mass
//! with its inertia. The rules are exact for the polynomial bases (degree ≤ 2n−1 with n
//! points) and converge exponentially for the characteristic functions.
//!
//! The frame's origin O is the hub's centre of mass; its axes are the structure axes.

use super::inertia::{Invariants, MassPoint, RotaryPoint};
use super::static_correction;
use crate::basis::Quadrature;
use crate::math::Vec3;
use crate::ritz::assembly::HUB_DOF;
use crate::ritz::eigen::generalized_symmetric;
use crate::ritz::shapes::{attachment_of, beam_point, plate_point};
use crate::ritz::{RitzError, RitzModel};
use crate::structure::{Attachment, ComponentId, HubMotion, Structure};

/// How the base is modelled during deployment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BaseKind {
    /// Elastic, by its hub-fixed Ritz modes (the default).
    Flexible {
        /// Number of kept modes (`None`: all of the base's Ritz model).
        modes: Option<usize>,
    },
    /// Elastic by its `modes` lowest hub-fixed modes, plus the static correction of the
    /// others ([`static_correction`]): their residual flexibility under the loads the
    /// deployment puts on the base (the root hinge's wrench and the hub's rigid-body
    /// acceleration), as at most twelve M-orthonormal vectors. With every mode kept it is
    /// [`BaseKind::Flexible`] with all modes.
    Corrected {
        /// Number of kept modes (clamped to the base's count).
        modes: usize,
    },
    /// Elastic by its hub-fixed modes up to `cutoff` (rad/s), and at least `at_least` of
    /// them, plus the static correction of the others, as [`BaseKind::Corrected`].
    Reduced {
        /// The highest kept mode's ω at most, rad/s (unless `at_least` asks for more).
        cutoff: f64,
        /// The fewest modes kept (clamped to the base's count).
        at_least: usize,
    },
    /// Frozen rigid, with its full 3-D mass properties (the paper's staged route).
    Rigid,
}

/// A beam of the base, for its tip deflection and root loads.
#[derive(Debug, Clone)]
pub struct BaseBeam {
    /// Name.
    pub name: String,
    /// Beam axes (e_x along the beam) in the hub frame.
    pub axes: [Vec3; 3],
    /// Root point from the hub's centre of mass, m.
    pub root: Vec3,
    /// Root displacement per mode, m.
    pub root_shapes: Vec<Vec3>,
    /// Tip displacement per mode, m.
    pub tip_shapes: Vec<Vec3>,
    /// Tip rotation per mode, rad.
    pub tip_rotations: Vec<Vec3>,
    /// Invariants of everything outboard of the root (the beam and its descendants).
    pub subtree: Invariants,
    /// The deploying array hangs on this subtree.
    pub carries_array: bool,
}

/// The base model.
#[derive(Debug)]
pub struct BaseModel {
    /// Free or held hub.
    pub hub_motion: HubMotion,
    /// Invariants of the whole base.
    pub invariants: Invariants,
    /// ω of the kept modes, rad/s (with [`BaseKind::Corrected`], the static correction's
    /// vectors after the modes, their Rayleigh quotients ascending).
    pub omega: Vec<f64>,
    /// How many of `omega` (and `shapes`) are the static correction's vectors, the last ones.
    pub correction: usize,
    /// ω of every hub-fixed mode of the base's Ritz model, rad/s, ascending (kept or not).
    pub spectrum: Vec<f64>,
    /// The root hinge point (the deploying plate's attachment) from the hub's centre of mass.
    pub hinge: Vec3,
    /// Its displacement per mode, m.
    pub hinge_shapes: Vec<Vec3>,
    /// Its small rotation per mode, rad.
    pub hinge_rotations: Vec<Vec3>,
    /// The hinge frame's axes in the hub frame: the plate's length axis e_a, its normal n and
    /// ẑ = e_a × n (the hinge axes).
    pub frame: [Vec3; 3],
    /// The base's beams.
    pub beams: Vec<BaseBeam>,
    /// The base's Ritz model (the structure without the deploying plate; the hub's six first).
    pub ritz: RitzModel,
    /// The kept modes as vectors over the base's Ritz coordinates (hub's six zero).
    pub shapes: Vec<Vec<f64>>,
}

impl BaseModel {
    /// Number of kept modes.
    pub fn modes(&self) -> usize {
        self.omega.len()
    }

    /// The base of structure `st` that carries plate `plate`.
    pub fn new(st: &Structure, plate: usize, kind: BaseKind) -> Result<Self, RitzError> {
        let mut base_st = st.clone();
        let deploying = base_st.plates.remove(plate);
        let ritz = RitzModel::assemble(&base_st);
        let basis = hub_fixed_modes(&ritz, &deploying.attachment, kind)?;
        let (omega, shapes) = (basis.omega, basis.shapes);
        let m = omega.len();
        let c_hub = st.hub.center_of_mass;
        let (hinge, hinge_shapes, hinge_rotations) =
            section_motion(&ritz, &deploying.attachment, &shapes);
        let cloud = Cloud::new(&ritz, &shapes);
        let invariants = cloud.invariants(m, |_| true);
        let beams = (0..base_st.beams.len())
            .map(|i| {
                let b = &base_st.beams[i];
                let inside = |id: ComponentId| base_st.in_subtree(id, i);
                let tip = |k: usize| beam_point(&ritz, i, 1.0, &shapes[k]).unwrap_or_default();
                let root = |k: usize| beam_point(&ritz, i, 0.0, &shapes[k]).unwrap_or_default();
                let carries = match deploying.attachment {
                    Attachment::Hub { .. } => false,
                    Attachment::Beam { beam, .. } => {
                        beam == i || base_st.in_subtree(ComponentId::Beam(beam), i)
                    }
                };
                BaseBeam {
                    name: b.name.clone(),
                    axes: [b.frame.ex, b.frame.ey, b.frame.ez],
                    root: st.beam_root(i) - c_hub,
                    root_shapes: (0..m).map(|k| root(k).displacement).collect(),
                    tip_shapes: (0..m).map(|k| tip(k).displacement).collect(),
                    tip_rotations: (0..m).map(|k| tip(k).rotation).collect(),
                    subtree: cloud.invariants(m, inside),
                    carries_array: carries,
                }
            })
            .collect();
        let ea = deploying.length_axis;
        let n = deploying.normal;
        Ok(Self {
            hub_motion: st.hub.motion,
            invariants,
            omega,
            correction: basis.correction,
            spectrum: basis.spectrum,
            hinge: hinge - c_hub,
            hinge_shapes,
            hinge_rotations,
            frame: [ea, n, ea.cross(n)],
            beams,
            ritz,
            shapes,
        })
    }
}

/// The base's reduction basis: kept modes, then the static correction's vectors.
struct Basis {
    omega: Vec<f64>,
    shapes: Vec<Vec<f64>>,
    correction: usize,
    spectrum: Vec<f64>,
}

/// The lowest hub-fixed modes of the base, mass-normalised, as vectors over all of its
/// coordinates; with [`BaseKind::Corrected`], the static correction of the others after
/// them.
fn hub_fixed_modes(
    ritz: &RitzModel,
    hinge: &Attachment,
    kind: BaseKind,
) -> Result<Basis, RitzError> {
    let n = ritz.dof();
    let ne = n - HUB_DOF;
    let (keep, corrected) = match kind {
        BaseKind::Rigid => (0, false),
        BaseKind::Flexible { modes } => (modes.unwrap_or(ne).min(ne), false),
        BaseKind::Corrected { modes } => (modes.min(ne), true),
        BaseKind::Reduced { .. } => (0, true),
    };
    if (keep == 0 && !corrected) || ne == 0 {
        return Ok(Basis {
            omega: Vec::new(),
            shapes: Vec::new(),
            correction: 0,
            spectrum: Vec::new(),
        });
    }
    let mee = ritz.mass.submatrix(HUB_DOF, HUB_DOF, ne, ne).to_owned();
    let kee = ritz
        .stiffness
        .submatrix(HUB_DOF, HUB_DOF, ne, ne)
        .to_owned();
    let (lam, phi) = generalized_symmetric(&kee, &mee)?;
    let spectrum: Vec<f64> = lam.iter().map(|l| l.max(0.0).sqrt()).collect();
    let keep = match kind {
        BaseKind::Reduced { cutoff, at_least } => spectrum
            .iter()
            .take_while(|w| **w <= cutoff)
            .count()
            .max(at_least)
            .min(ne),
        _ => keep,
    };
    let mut omega: Vec<f64> = spectrum[..keep].to_vec();
    let widen = |v: &[f64]| {
        let mut w = vec![0.0; n];
        w[HUB_DOF..].copy_from_slice(v);
        w
    };
    let mut shapes: Vec<Vec<f64>> = (0..keep)
        .map(|j| widen(&(0..ne).map(|i| phi[(i, j)]).collect::<Vec<_>>()))
        .collect();
    let mut correction = 0;
    if corrected && keep < ne {
        let loads = static_correction::deployment_loads(ritz, hinge);
        let (w, v) = static_correction::vectors(&lam, &phi, keep, &loads);
        correction = w.len();
        omega.extend(w);
        shapes.extend(v.iter().map(|x| widen(x)));
    }
    Ok(Basis {
        omega,
        shapes,
        correction,
        spectrum,
    })
}

/// The point where an attachment sits, with its displacement and rotation per mode.
fn section_motion(
    ritz: &RitzModel,
    att: &Attachment,
    shapes: &[Vec<f64>],
) -> (Vec3, Vec<Vec3>, Vec<Vec3>) {
    let st = &ritz.structure;
    let point = st.attachment_point(att);
    let (mut disp, mut rot) = (Vec::new(), Vec::new());
    for q in shapes {
        let (u, th) = match att {
            Attachment::Hub { .. } => (Vec3::ZERO, Vec3::ZERO),
            Attachment::Beam { beam, station } => {
                let xi = (station / st.beams[*beam].length).clamp(0.0, 1.0);
                let s = beam_point(ritz, *beam, xi, q).unwrap_or_default();
                (s.displacement, s.rotation)
            }
        };
        disp.push(u);
        rot.push(th);
    }
    (point, disp, rot)
}

/// The base's mass points, each tagged with its component.
struct Cloud {
    points: Vec<(ComponentId, MassPoint)>,
    rotary: Vec<(ComponentId, RotaryPoint)>,
}

/// Gauss points for a family of `terms` functions: exact for the polynomial bases' products
/// (degree ≤ 2·terms + 4 with the position factor), ample for the characteristic ones.
fn rule(terms: usize) -> Quadrature {
    Quadrature::gauss(2 * terms + 12)
}

impl Cloud {
    fn new(ritz: &RitzModel, shapes: &[Vec<f64>]) -> Self {
        let st = &ritz.structure;
        let c_hub = st.hub.center_of_mass;
        let mut points = Vec::new();
        let mut rotary = Vec::new();
        let m = shapes.len();
        points.push((
            ComponentId::Hub,
            MassPoint {
                mass: st.hub.mass,
                position: Vec3::ZERO,
                shapes: vec![Vec3::ZERO; m],
            },
        ));
        rotary.push((
            ComponentId::Hub,
            RotaryPoint {
                inertia: st.hub.inertia,
                rotations: vec![Vec3::ZERO; m],
            },
        ));
        for (i, b) in st.beams.iter().enumerate() {
            let id = ComponentId::Beam(i);
            let t = b.terms;
            let quad = rule(t.axial.max(t.bending).max(t.torsion));
            let rho_ip = b.density * b.section.polar_inertia;
            let ex = b.frame.ex;
            for (&xi, &w) in quad.points.iter().zip(&quad.weights) {
                let samples: Vec<_> = shapes
                    .iter()
                    .map(|q| beam_point(ritz, i, xi, q).unwrap_or_default())
                    .collect();
                let position = st.beam_root(i) + ex * (xi * b.length) - c_hub;
                points.push((
                    id,
                    MassPoint {
                        mass: b.mass_per_length() * b.length * w,
                        position,
                        shapes: samples.iter().map(|s| s.displacement).collect(),
                    },
                ));
                rotary.push((
                    id,
                    RotaryPoint {
                        inertia: ex.outer(ex) * (rho_ip * b.length * w),
                        rotations: samples.iter().map(|s| s.rotation).collect(),
                    },
                ));
            }
        }
        for (i, p) in st.plates.iter().enumerate() {
            let id = ComponentId::Plate(i);
            let (qx, qy) = (
                rule(p.terms.length).split(&p.hinge_positions()),
                rule(p.terms.width),
            );
            let origin = st.attachment_point(&p.attachment) - c_hub;
            for (&xi, &wx) in qx.points.iter().zip(&qx.weights) {
                for (&eta, &wy) in qy.points.iter().zip(&qy.weights) {
                    let r =
                        p.length_axis * (xi * p.length) + p.width_axis() * ((eta - 0.5) * p.width);
                    points.push((
                        id,
                        MassPoint {
                            mass: p.areal_density * p.length * p.width * wx * wy,
                            position: origin + r,
                            shapes: shapes
                                .iter()
                                .map(|q| {
                                    plate_point(ritz, i, xi, eta, q)
                                        .unwrap_or_default()
                                        .displacement
                                })
                                .collect(),
                        },
                    ));
                }
            }
        }
        for (i, lm) in st.masses.iter().enumerate() {
            let id = ComponentId::Mass(i);
            let motion: Vec<(Vec3, Vec3)> = shapes
                .iter()
                .map(|q| attachment_of(ritz, id, q).unwrap_or((Vec3::ZERO, Vec3::ZERO)))
                .collect();
            let origin = st.attachment_point(&lm.attachment) - c_hub;
            points.push((
                id,
                MassPoint {
                    mass: lm.mass,
                    position: origin + lm.offset,
                    shapes: motion
                        .iter()
                        .map(|(u, th)| *u + th.cross(lm.offset))
                        .collect(),
                },
            ));
            rotary.push((
                id,
                RotaryPoint {
                    inertia: lm.inertia,
                    rotations: motion.iter().map(|(_, th)| *th).collect(),
                },
            ));
        }
        Self { points, rotary }
    }

    fn invariants(&self, m: usize, keep: impl Fn(ComponentId) -> bool) -> Invariants {
        let pts: Vec<MassPoint> = self
            .points
            .iter()
            .filter(|(id, _)| keep(*id))
            .map(|(_, p)| p.clone())
            .collect();
        let rot: Vec<RotaryPoint> = self
            .rotary
            .iter()
            .filter(|(id, _)| keep(*id))
            .map(|(_, p)| p.clone())
            .collect();
        Invariants::of_cloud(m, &pts, &rot)
    }
}

/// Inertia tensor of a thin rectangular panel about its centre in its own axes (along its
/// length, along its normal, along the hinge axis), with a given inertia `about_hinge_axis`
/// about the hinge-parallel axis: the width contributes m w²/12 about the length axis, and
/// the perpendicular-axis theorem gives the normal axis.
pub fn panel_inertia(mass: f64, width: f64, about_hinge_axis: f64) -> [f64; 3] {
    let iw = mass * width * width / 12.0;
    [iw, iw + about_hinge_axis, about_hinge_axis]
}
