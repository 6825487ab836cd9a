//! Hand-over from the deploying chain to the flexible model at the final latch
//! (docs/theory.md §3).
//!
//! *Projection* (default). Just before the final latch the velocity field v⁻ is the chain's:
//! the hub and every component other than the deploying plate move rigidly with the hub
//! (V at its centre of mass, Ω), and each point of panel i at distance s from its hinge moves
//! with V_{H_i} + φ̇_i ẑ × s e(φ_i). The latch is a plastic impact after which the motion lies
//! in the Ritz space of the deployed structure; conservation of generalized momentum gives
//!
//!   M q̇⁺ = b = ∫ Φᵀ ρ v⁻ dV,    η̇_j = φ_jᵀ b  (mass-normalised modes, η₀ = 0),
//!
//! the M-orthogonal projection of v⁻: the kinetic energy can only drop, by
//! ½∫ρ|v⁻ − Φq̇⁺|² dV, and for a free hub the linear and angular momentum are kept exactly
//! (rigid translations and rotations are in the Ritz space). Split v⁻ = Φ q̇_h + δv with q̇_h
//! the hub's rigid velocity in Ritz coordinates and δv non-zero on the plate only:
//!
//!   b = M q̇_h + Bᵀ b_z(δv),  b_z = [∫μ δv dA; ∫μ r × δv dA; ∫μ X_m Y_n (n·δv) dA],
//!
//! with B = [T; P] the plate's attachment map and own-coordinate selector
//! ([`crate::ritz::assembly`]). δv does not vary across the width, so the width integral is
//! b·∫Y_n dη and the length integral is a Gauss rule on every panel (δv has a kink at each
//! hinge).
//!
//! *Impulse* (the paper's route, (2.7)): the structure at rest receives the final latch's
//! hinge impulses, S_i applied at the centre of panel i (the paper's Π = Σ S_i f(x_i)):
//! b = Σ_i Φ(x_i)ᵀ S_i.
//!
//! Frames: the chain's deployment plane (u along the wing's length axis e_a, v along its
//! normal n, ẑ = e_a × n) is turned by the hub's rotation θ at the latch; everything is
//! expressed in the hub's body axes, i.e. the structure frame of the deployed model.

use super::ResponseError;
use crate::basis::{Basis1d, Quadrature};
use crate::deploy::chain::{Chain, PlanarHub, P2};
use crate::deploy::coupled::Coupled;
use crate::deploy::{Deployment, DeploymentResult, LatchEvent};
use crate::math::Vec3;
use crate::ritz::assembly::{Element, ElementKind, FieldKind, HUB_DOF};
use crate::ritz::{ModalAnalysis, RitzModel};
use crate::structure::{ComponentId, HubMotion, Plate, RigidBody, Structure};
use faer::linalg::solvers::Solve;

/// How the deployment's motion becomes the structure's initial velocity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HandoverMethod {
    /// Mass-weighted projection of the pre-latch velocity field (default).
    Projection,
    /// The paper's route: the latch impulses applied to the structure at rest.
    Impulse,
}

impl HandoverMethod {
    /// The scenario keyword.
    pub fn name(self) -> &'static str {
        match self {
            HandoverMethod::Projection => "projection",
            HandoverMethod::Impulse => "impulse",
        }
    }
}

/// Linear momentum (N·s) and angular momentum about the hub's centre of mass (N·m·s), in
/// the structure frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Momentum {
    /// N·s.
    pub linear: Vec3,
    /// N·m·s, about the hub's centre of mass.
    pub angular: Vec3,
}

/// The result of the hand-over.
#[derive(Debug, Clone, PartialEq)]
pub struct Handover {
    /// The method used.
    pub method: HandoverMethod,
    /// Time of the hand-over (the final latch, or the compliant latches' settled state), s.
    pub latch_time: f64,
    /// Hinge whose latch ended the deployment (1-based); with compliant latches, the last
    /// captured one.
    pub latch_hinge: usize,
    /// Compliant latches: how the settling after the last capture, which the hand-over
    /// follows, ended (None after a rigid latch).
    pub settled: Option<crate::deploy::Settled>,
    /// Generalized impulse b = ∫Φᵀρv⁻dV (projection) or Σ Φᵀ S (impulse), per coordinate.
    pub generalized_impulse: Vec<f64>,
    /// Initial modal velocities η̇_j(0) = φ_jᵀ b, one per mode of the analysis.
    pub modal_velocity: Vec<f64>,
    /// Generalized velocities after the hand-over, q̇⁺ = Σ_j φ_j η̇_j.
    pub qdot: Vec<f64>,
    /// Kinetic energy just before the final latch, from the chain's bodies and the
    /// structure's rigid parts moving with the hub, J.
    pub energy_before: f64,
    /// The same from the plate's own density field (the quantity the projection conserves or
    /// lowers; equal to `energy_before` when the panels' masses are the plate's), J. The
    /// impulse route does not use the field and repeats `energy_before` here.
    pub energy_before_field: f64,
    /// Kinetic energy after the hand-over, ½Σ η̇_j², J.
    pub energy_after: f64,
    /// Momentum before (chain bodies + rigid parts), structure frame.
    pub momentum_before: Momentum,
    /// Momentum after, rows of M q̇⁺ (a free hub's; for a fixed hub the supports take it).
    pub momentum_after: Momentum,
    /// Largest |α_i − latch angle_i| at the final latch, rad (non-zero only with
    /// simultaneous latching: the hand-over still uses the straight wing); with the latch
    /// lines in the deployed model ([`Handover::latch_carried`]) only the part they cannot
    /// take (off the ideal cable's manifold).
    pub angle_mismatch: f64,
    /// Hub position u, v (m) and rotation θ (rad) in the deployment plane at the latch
    /// (planar chain; zero for the coupled model, whose hub pose is in the deployment's
    /// samples).
    pub hub_state: [f64; 3],
    /// Initial modal displacements η_j(0) = φ_jᵀ M q(0), one per mode (the base's elastic
    /// displacement at the final latch; zero for the planar chain).
    pub modal_displacement: Vec<f64>,
    /// Elastic energy of the base just after the final latch (coupled model), J.
    pub elastic_energy_before: f64,
    /// Elastic energy of the initial displacement in the deployed model, ½Σ ω_j² η_j(0)², J.
    pub elastic_energy_after: f64,
    /// Compliant latches: their springs' energy at the hand-over, ½ Σ k_L,j (α_j − α_j^L)², J.
    /// With [`Handover::latch_carried`] the deployed wing's hinge lines take the hinges'
    /// angles off their equilibrium as its initial displacement, so the response carries it
    /// (in `elastic_energy_after`).
    pub latch_energy: f64,
    /// The deployed model carries the latch springs (its wing is cut along hinge lines,
    /// docs/theory.md §1.6): the latched array's motion goes on in the response.
    pub latch_carried: bool,
    /// With [`Handover::latch_carried`]: the latch lines' energy about their rest at the
    /// hand-over, ½ Δθᵀ K Δθ (latch, hinge and cable springs together, about the latched
    /// equilibrium), J — what the deployed model's elastic energy holds of them.
    pub lines_energy: f64,
    /// Notes on choices the data forced (printed as warnings).
    pub notes: Vec<String>,
}

/// The deploying plate's place in the model.
struct PlateView<'a> {
    index: usize,
    plate: &'a Plate,
    element: &'a Element,
    xb: &'a dyn Basis1d,
    yb: &'a dyn Basis1d,
}

impl<'a> PlateView<'a> {
    fn find(model: &'a RitzModel, name: &str) -> Result<Self, ResponseError> {
        let idx = model
            .structure
            .plates
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| ResponseError::UnknownPlate(name.to_string()))?;
        let element = model
            .element(ComponentId::Plate(idx))
            .ok_or_else(|| ResponseError::UnknownPlate(name.to_string()))?;
        let ElementKind::Plate { length, width, .. } = &element.kind else {
            return Err(ResponseError::UnknownPlate(name.to_string()));
        };
        Ok(Self {
            index: idx,
            plate: &model.structure.plates[idx],
            element,
            xb: length.as_ref(),
            yb: width.as_ref(),
        })
    }

    /// Bᵀ [f_U; f_Θ; f_g] added into b (length n).
    fn scatter(&self, b: &mut [f64], fu: Vec3, fth: Vec3, fg: &[f64]) {
        let t = &self.element.attachment;
        for (c, bc) in b.iter_mut().enumerate() {
            let mut s = 0.0;
            for i in 0..3 {
                s += t[(i, c)] * fu.get(i) + t[(3 + i, c)] * fth.get(i);
            }
            *bc += s;
        }
        let start = self.element.own_range().start;
        for (k, v) in fg.iter().enumerate() {
            b[start + k] += v;
        }
    }
}

/// The state just before the final latch, in the structure frame.
struct PreLatch {
    /// Hub's centre-of-mass velocity and angular velocity.
    v_hub: Vec3,
    w_hub: Vec3,
    /// The base's elastic velocity in the deployed model's coordinates (hub's six zero;
    /// empty for the planar chain's rigid base).
    base_velocity: Vec<f64>,
    /// Per panel: place on the straight wing, mass properties and rigid motion (structure
    /// frame).
    panels: Vec<PanelMotion>,
    theta: f64,
    hub_state: [f64; 3],
}

struct PanelMotion {
    start: f64,
    length: f64,
    mass: f64,
    inertia: f64,
    /// Velocity of the panel's centre.
    v_centre: Vec3,
    /// φ̇_i ẑ × e_a: the velocity per metre along the (straight) panel.
    v_per_metre: Vec3,
    /// φ̇_i ẑ.
    omega: Vec3,
}

impl PanelMotion {
    /// Velocity of the point at distance s from the panel's hinge on the straight wing: the
    /// panel's rigid motion (centre velocity, rate) carried over to its straight position,
    /// which keeps each panel's momentum, angular momentum about its centre and kinetic
    /// energy when simultaneous latching locks the array bent (docs/theory.md §3). For the
    /// straight wing it is the chain's own velocity field.
    fn velocity(&self, s: f64) -> Vec3 {
        self.v_centre + self.v_per_metre * (s - 0.5 * self.length)
    }
}

fn pre_latch(chain: &Chain, plate: &Plate, ev: &LatchEvent) -> PreLatch {
    let cfg = chain.configuration(&ev.q);
    let qd = &ev.qd_before;
    let free = matches!(chain.hub, PlanarHub::Free { .. });
    let (theta, hub_state) = if free {
        (ev.q[2], [ev.q[0], ev.q[1], ev.q[2]])
    } else {
        (0.0, [0.0; 3])
    };
    let (ea, nn) = (plate.length_axis, plate.normal);
    let z = ea.cross(nn);
    let (s, c) = theta.sin_cos();
    // Plane (world) → structure frame: turn by −θ, then u → e_a, v → n.
    let to3 = |p: P2| -> Vec3 { ea * (c * p[0] + s * p[1]) + nn * (-s * p[0] + c * p[1]) };
    let (v_hub, w_hub) = if free {
        (to3([qd[0], qd[1]]), z * qd[2])
    } else {
        (Vec3::ZERO, Vec3::ZERO)
    };
    let hv = chain.hinge_velocities(&cfg, qd);
    let w = chain.phi_rates(qd);
    let mut start = 0.0;
    let panels = chain
        .panels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let e = [cfg.phi[i].cos(), cfg.phi[i].sin()];
            let half = 0.5 * p.length * w[i];
            let omega = z * w[i];
            let pm = PanelMotion {
                start,
                length: p.length,
                mass: p.mass,
                inertia: p.inertia,
                v_centre: to3([hv[i][0] - half * e[1], hv[i][1] + half * e[0]]),
                v_per_metre: omega.cross(ea),
                omega,
            };
            start += p.length;
            pm
        })
        .collect();
    PreLatch {
        v_hub,
        w_hub,
        base_velocity: Vec::new(),
        panels,
        theta,
        hub_state,
    }
}

/// The mass properties of everything but the deploying plate, about the hub's centre of mass.
fn rigid_rest(st: &Structure, plate: &str) -> RigidBody {
    let mut total = st.hub.rigid_body().about(-st.hub.center_of_mass);
    for b in &st.beams {
        total = total.plus(&b.rigid_body().about(-st.attachment_point(&b.attachment)));
    }
    for p in st.plates.iter().filter(|p| p.name != plate) {
        total = total.plus(&p.rigid_body().about(-st.attachment_point(&p.attachment)));
    }
    for m in &st.masses {
        total = total.plus(&m.rigid_body().about(-st.attachment_point(&m.attachment)));
    }
    total.about(st.hub.center_of_mass)
}

/// [p; L] = B [V; Ω] of a rigid body about the reference point.
fn rigid_momentum(rb: &RigidBody, v: Vec3, w: Vec3) -> Momentum {
    Momentum {
        linear: v * rb.mass + w.cross(rb.first_moment),
        angular: rb.first_moment.cross(v) + rb.inertia.apply(w),
    }
}

/// The generalized impulse Φ(p)ᵀ S of an impulse S (N·s, structure frame) applied at a point
/// of a beam (`local` = [station from the root, 0]) or a plate (`local` = [x from the root
/// edge, y across the width from its centre line]): b = Tᵀ[S; r × S] + own functions·S.
/// Other components (hub, lumped masses) take it at their attachment point (r = 0).
pub fn point_impulse(model: &RitzModel, id: ComponentId, local: [f64; 2], s: Vec3) -> Vec<f64> {
    let n = model.dof();
    let mut b = vec![0.0; n];
    let Some(e) = model.element(id) else {
        return b;
    };
    let st = &model.structure;
    let (r, own): (Vec3, Vec<(usize, f64)>) = match &e.kind {
        ElementKind::Beam {
            index,
            axial,
            bending,
            ..
        } => {
            let beam = &st.beams[*index];
            let f = beam.frame;
            let xi = (local[0] / beam.length).clamp(0.0, 1.0);
            let mut own = Vec::new();
            let xa = axial.eval_vec(xi);
            let xb = bending.eval_vec(xi);
            for (field, comp, vals) in [
                (FieldKind::U, f.ex, &xa),
                (FieldKind::V, f.ey, &xb),
                (FieldKind::W, f.ez, &xb),
            ] {
                for (k, c) in e.field(field).enumerate() {
                    own.push((c, vals[k][0] * comp.dot(s)));
                }
            }
            (f.ex * local[0], own)
        }
        ElementKind::Plate {
            index,
            length,
            width,
        } => {
            let p = &st.plates[*index];
            let xv = length.eval_vec((local[0] / p.length).clamp(0.0, 1.0));
            let yv = width.eval_vec((local[1] / p.width + 0.5).clamp(0.0, 1.0));
            let start = e.own_range().start;
            let sn = p.normal.dot(s);
            let mut own = Vec::new();
            for (m, x) in xv.iter().enumerate() {
                for (k, y) in yv.iter().enumerate() {
                    own.push((start + m * yv.len() + k, x[0] * y[0] * sn));
                }
            }
            (p.length_axis * local[0] + p.width_axis() * local[1], own)
        }
        ElementKind::Rigid => (Vec3::ZERO, Vec::new()),
    };
    let m = r.cross(s);
    let t = &e.attachment;
    for (c, bc) in b.iter_mut().enumerate() {
        for i in 0..3 {
            *bc += t[(i, c)] * s.get(i) + t[(3 + i, c)] * m.get(i);
        }
    }
    for (k, v) in own {
        b[k] += v;
    }
    b
}

/// Modal velocities η̇_j = φ_jᵀ b of a generalized impulse b, for every mode of the
/// analysis (mass-normalised shapes; a fixed hub's entries are zero).
pub fn modal_velocities(modal: &ModalAnalysis, b: &[f64]) -> Vec<f64> {
    modal
        .modes
        .iter()
        .map(|m| m.shape.iter().zip(b).map(|(p, v)| p * v).sum())
        .collect()
}

/// The final latch of a run in which every hinge latched.
fn final_latch(result: &DeploymentResult) -> Result<&LatchEvent, ResponseError> {
    match result.latches.last() {
        Some(ev) if result.all_latched => Ok(ev),
        _ => Err(ResponseError::NotLatched {
            hinges: result.unlatched.iter().map(|u| u.0).collect(),
            time: result.final_time,
        }),
    }
}

/// Hands the motion over at the final latch (see the module documentation).
pub fn hand_over(
    model: &RitzModel,
    modal: &ModalAnalysis,
    deployment: &Deployment,
    result: &DeploymentResult,
    method: HandoverMethod,
) -> Result<Handover, ResponseError> {
    let last = final_latch(result)?;
    let view = PlateView::find(model, &deployment.plate)?;
    let st = &model.structure;
    let chain = &deployment.chain;
    let pl = pre_latch(chain, view.plate, last);
    let mut notes = Vec::new();

    // Before: the chain's bodies and the rigid rest of the structure.
    let rest = rigid_rest(st, &deployment.plate);
    let (before, energy_before) = momentum_before(&rest, &view, &pl, st.hub.center_of_mass);
    let (b, energy_before_field) = match method {
        HandoverMethod::Projection => projected_impulse(model, &view, &pl, &mut notes),
        HandoverMethod::Impulse => (latch_impulse(model, &view, &pl, last), energy_before),
    };
    let (eta_dot, qdot, energy_after, momentum_after) = after_latch(model, modal, &b);
    let angle_mismatch = chain
        .hinges
        .iter()
        .enumerate()
        .map(|(i, h)| (last.q[chain.hub_dof() + i] - h.latch_angle).abs())
        .fold(0.0, f64::max);
    if (energy_before_field - energy_before).abs() > 1e-9 * energy_before.abs().max(1e-300) {
        notes.push(format!(
            "the panels' masses or inertias differ from the plate's density field: kinetic \
             energy before the latch {energy_before:.6e} J from the panels, \
             {energy_before_field:.6e} J from the plate (the hand-over projects the plate's)"
        ));
    }
    Ok(Handover {
        method,
        latch_time: last.time,
        latch_hinge: last.hinge,
        settled: None,
        generalized_impulse: b,
        modal_velocity: eta_dot,
        qdot,
        energy_before,
        energy_before_field,
        energy_after,
        momentum_before: before,
        momentum_after,
        angle_mismatch,
        hub_state: pl.hub_state,
        modal_displacement: vec![0.0; modal.modes.len()],
        elastic_energy_before: 0.0,
        elastic_energy_after: 0.0,
        latch_energy: 0.0,
        latch_carried: false,
        lines_energy: 0.0,
        notes,
    })
}

/// For every coordinate of the base's Ritz model, its index in the deployed model's (the
/// same components with the same functions, the deploying plate added; matched by name).
fn base_coordinates(base: &RitzModel, model: &RitzModel) -> Vec<usize> {
    let mut map = vec![0; base.dof()];
    for (i, m) in map.iter_mut().enumerate().take(HUB_DOF) {
        *m = i;
    }
    for e in &base.elements {
        let name = base.structure.component_name(e.id);
        let Some(f) = model
            .elements
            .iter()
            .find(|f| model.structure.component_name(f.id) == name)
        else {
            continue;
        };
        for (a, b) in e.own_range().zip(f.own_range()) {
            map[a] = b;
        }
    }
    map
}

/// The base's elastic velocity and displacement in the deployed model's coordinates.
fn base_state(coupled: &Coupled, model: &RitzModel, y: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = model.dof();
    let sv = coupled.view(y);
    let map = base_coordinates(&coupled.base.ritz, model);
    let (mut velocity, mut q0) = (vec![0.0; n], vec![0.0; n]);
    for (k, shape) in coupled.base.shapes.iter().enumerate() {
        for (i, v) in shape.iter().enumerate() {
            velocity[map[i]] += v * sv.eta_dot[k];
            q0[map[i]] += v * sv.eta[k];
        }
    }
    (velocity, q0)
}

/// The deployed wing's hinge lines (docs/theory.md §1.6) take the captured hinges' angles
/// off their rest as kinks: hinge j at α_j turns its outboard side by
/// θ_j = d_j (α_j − α_j^L) about ẑ = e_a × n (d_j = ∓1 the chain's sign of α_j in the panel
/// angles), less the line's rest rotation ([`crate::structure::LineHinge::rest`]: where the
/// latches hold the hinge springs' and the cable's preload; the straight deployed wing is
/// the model's equilibrium). The kink functions F_i = Σ_j W_ij K_j take the rotations that fit them in
/// least squares weighted by the lines' stiffness (exact for independent lines, W = I, and
/// for a state on an ideal cable's manifold), less the fit of the equilibrium's offsets, and
/// their coordinates h_in (W = Σ F_i(x/a) h_in Y_n) the uniform
/// rotation: h_in = a s_i c_n with Σ c_n Y_n = 1 (the width family holds the constant: its
/// rigid pair). Nothing without hinge lines (rigid latches).
///
/// Returns the largest |θ_j − Σ_i W_ij s_i| of the angles off the latch angles (rad): what
/// the lines cannot take (a state off an ideal cable's manifold; zero for independent
/// lines), or `None` without lines.
fn latch_displacement(
    coupled: &Coupled,
    y: &[f64],
    view: &PlateView<'_>,
    q0: &mut [f64],
) -> Option<(f64, f64)> {
    let lines = view.plate.hinges();
    let w = view.plate.hinge_functions();
    coupled.latch.as_ref()?;
    if lines.is_empty() || w.is_empty() {
        return None;
    }
    let iy = crate::basis::Integrals::new(view.yb);
    let ny = view.yb.len();
    let c = constant_coefficients(&iy);
    let smooth = view.xb.len() - w.len();
    let start = view.element.own_range().start;
    let sv = coupled.view(y);
    let ev = coupled.evaluate(y);
    let z_plate = view.plate.length_axis.cross(view.plate.normal);
    let sense = ev.frame.apply(Vec3::new(0.0, 0.0, 1.0)).dot(z_plate);
    // θ_j off the latch angle; the lines' rest rotations (the latched equilibrium).
    let theta: Vec<f64> = (coupled.chain.hinges.iter().enumerate())
        .take(lines.len())
        .map(|(j, h)| Chain::d(j) * (sv.alpha[j] - h.latch_angle) * sense)
        .collect();
    let rest: Vec<f64> = lines.iter().map(|l| l.rest).collect();
    // The lines' stiffness-weighted fit (W K Wᵀ) s = W K θ, exact for independent lines and
    // on an ideal cable's manifold (where the rest rotations lie too).
    let nf = w.len();
    let kw: Vec<f64> = lines.iter().map(|l| l.stiffness).collect();
    let wdot = |a: &[f64], b: &[f64]| (0..a.len()).map(|j| a[j] * kw[j] * b[j]).sum::<f64>();
    let gram = faer::Mat::<f64>::from_fn(nf, nf, |i, k| wdot(&w[i], &w[k]));
    let lu = gram.as_ref().partial_piv_lu();
    let fit = |v: &[f64]| {
        let rhs = faer::Mat::<f64>::from_fn(nf, 1, |i, _| wdot(&w[i], v));
        let s = lu.solve(&rhs);
        (0..nf).map(|i| s[(i, 0)]).collect::<Vec<f64>>()
    };
    let (s_state, s_rest) = (fit(&theta), fit(&rest));
    let ds: Vec<f64> = s_state.iter().zip(&s_rest).map(|(a, b)| a - b).collect();
    for (i, dsi) in ds.iter().enumerate() {
        for (n, cn) in c.iter().enumerate() {
            q0[start + (smooth + i) * ny + n] += view.plate.length * dsi * cn;
        }
    }
    // The lines' energy about their rest, ½ Δsᵀ S Δs (S per radian², uniform rotations).
    let stiff = view.plate.hinge_function_matrix(false);
    let energy = 0.5
        * (0..nf)
            .flat_map(|i| (0..nf).map(move |k| (i, k)))
            .map(|(i, k)| ds[i] * stiff[i][k] * ds[k])
            .sum::<f64>();
    let residual = (0..lines.len())
        .map(|j| (theta[j] - (0..nf).map(|i| w[i][j] * s_state[i]).sum::<f64>()).abs())
        .fold(0.0, f64::max);
    Some((residual, energy))
}

/// The coefficients c of the constant function in a family: ∫Y_m Y_n c_n = ∫Y_m (the
/// least-squares fit, exact when the family holds the constant).
fn constant_coefficients(iy: &crate::basis::Integrals) -> Vec<f64> {
    let n = iy.m0.len();
    let rhs = faer::Mat::<f64>::from_fn(n, 1, |i, _| iy.m0[i]);
    let sol = iy.i00.as_ref().partial_piv_lu().solve(&rhs);
    (0..n).map(|i| sol[(i, 0)]).collect()
}

/// The coupled state as the hand-over's pre-latch motion: the hub's velocity, the base's
/// elastic velocity (deployed model's coordinates) and every panel's rigid motion.
fn coupled_pre_latch(coupled: &Coupled, y: &[f64], ea: Vec3, base_velocity: Vec<f64>) -> PreLatch {
    let sv = coupled.view(y);
    let ev = coupled.evaluate(y);
    let mut start = 0.0;
    let panels = coupled
        .panel_motion(y, &ev)
        .into_iter()
        .zip(&coupled.chain.panels)
        .map(|((_, v, w), p)| {
            let pm = PanelMotion {
                start,
                length: p.length,
                mass: p.mass,
                inertia: p.inertia,
                v_centre: v,
                v_per_metre: w.cross(ea),
                omega: w,
            };
            start += p.length;
            pm
        })
        .collect();
    PreLatch {
        v_hub: sv.v,
        w_hub: sv.w,
        base_velocity,
        panels,
        theta: 0.0,
        hub_state: [0.0; 3],
    }
}

/// Hands the coupled model's state after the final latch ([`crate::deploy::coupled`]) over
/// to the deployed structure's Ritz model: the base's rigid and elastic velocity and its
/// elastic displacement map one to one onto the deployed model's coordinates (the base's
/// functions are a subset of the deployed model's); the locked panels' rigid motion is
/// projected onto the plate's functions in the mass metric, as at the planar chain's latch
/// (module documentation). The kinetic energy can only drop by the projection residual
/// ½∫ρ|v − Φq̇⁺|² dV over the wing, which shrinks as the plate's terms grow (the locked rigid
/// wing is the stiff limit of the elastic plate); the elastic energy of the base carries over
/// unchanged.
pub fn hand_over_coupled(
    model: &RitzModel,
    modal: &ModalAnalysis,
    deployment: &Deployment,
    coupled: &Coupled,
    result: &DeploymentResult,
    method: HandoverMethod,
) -> Result<Handover, ResponseError> {
    // Rigid latches end the run at the final latch; compliant ones after the settling that
    // follows the last capture: the hand-over is at the run's end either way.
    if !result.all_latched {
        return Err(ResponseError::NotLatched {
            hinges: result.unlatched.iter().map(|u| u.0).collect(),
            time: result.final_time,
        });
    }
    let last = result.latches.last();
    let last_hinge = last
        .map(|e| e.hinge)
        .or_else(|| result.captures.last().map(|c| c.hinge))
        .unwrap_or(0);
    let view = PlateView::find(model, &deployment.plate)?;
    let n = model.dof();
    let y = result.final_state();
    let (base_velocity, mut q0) = base_state(coupled, model, &y);
    let carried_lines = latch_displacement(coupled, &y, &view, &mut q0);
    let carried = carried_lines.is_some();
    let residual = carried_lines.map(|(r, _)| r);
    let lines_energy = carried_lines.map_or(0.0, |(_, e)| e);
    let pl = coupled_pre_latch(coupled, &y, view.plate.length_axis, base_velocity);
    let mut notes = Vec::new();
    let energy_before = coupled.kinetic_energy(&y);
    let (b, energy_before_field) = match method {
        HandoverMethod::Projection => projected_impulse(model, &view, &pl, &mut notes),
        HandoverMethod::Impulse => match last {
            Some(last) => (latch_impulse(model, &view, &pl, last), energy_before),
            None => {
                notes.push(
                    "the impulse hand-over applies the final latch's impulses; compliant latches \
                     have none, so nothing is applied"
                        .to_string(),
                );
                (vec![0.0; n], energy_before)
            }
        },
    };
    let (linear, angular) = coupled.momentum_hub(&y);
    // Rows 0..6 of b = M q̇⁺ are the linear model's momentum. The projection gives the
    // momentum of the velocity field in the undeformed geometry; the coupled model's is that
    // of the deformed base (they differ by terms like (S η) × v, second order in the small
    // deformation). Setting those rows to the coupled model's momentum makes the response
    // carry it exactly; the kinetic energy changes by a second-order amount.
    let field = b.clone();
    let mut b = b;
    if method == HandoverMethod::Projection && model.structure.hub.motion == HubMotion::Free {
        for i in 0..3 {
            b[i] = linear.get(i);
            b[3 + i] = angular.get(i);
        }
    }
    // The rigid modes (hub coordinates only) take the coupled model's momentum; the elastic
    // ones, whose momentum is zero, the projection of the field (overriding b's momentum rows
    // would also change every elastic mode's η̇ = φᵀ b through its hub entries — by far more
    // than a second-order amount where the base is deflected).
    let (eta_dot, qdot, energy_after, momentum_after) = after_latch_split(model, modal, &field, &b);
    let rigid_drop = after_latch(model, modal, &field).2 - energy_after;
    if rigid_drop.abs() > 1e-2 * energy_before {
        notes.push(format!(
            "the panels' and base's velocities, taken in the undeformed geometry, carry a rigid \
             motion of {:.3e} J that the deformed spacecraft's momentum (kept exactly) does not \
             have: the base is deflected beyond the small-deformation assumption at the \
             hand-over, and the response drops that motion ({:.1} % of the kinetic energy)",
            rigid_drop,
            100.0 * rigid_drop / energy_before.max(1e-300)
        ));
    }
    // η(0) = Φᵀ M q(0).
    let m = &model.mass;
    let mq0: Vec<f64> = (0..n)
        .map(|r| (0..n).map(|c| m[(r, c)] * q0[c]).sum())
        .collect();
    let modal_displacement: Vec<f64> = match method {
        HandoverMethod::Projection => modal_velocities(modal, &mq0),
        HandoverMethod::Impulse => vec![0.0; modal.modes.len()],
    };
    let elastic_energy_after = modal
        .modes
        .iter()
        .zip(&modal_displacement)
        .map(|(md, e)| 0.5 * md.omega_rad_s.powi(2) * e * e)
        .sum();
    let off = coupled.alpha_offset();
    let angle_mismatch = residual.unwrap_or_else(|| {
        coupled
            .chain
            .hinges
            .iter()
            .enumerate()
            .map(|(i, h)| (result.final_q[off + i] - h.latch_angle).abs())
            .fold(0.0, f64::max)
    });
    if (energy_before_field - energy_before).abs() > 1e-6 * energy_before.abs().max(1e-300)
        && method == HandoverMethod::Projection
    {
        notes.push(format!(
            "the panels' masses or inertias differ from the plate's density field: kinetic \
             energy after the final latch {energy_before:.6e} J in the coupled model, \
             {energy_before_field:.6e} J from the plate's field (the hand-over projects the \
             plate's)"
        ));
    }
    Ok(Handover {
        method,
        latch_time: result.final_time,
        latch_hinge: last_hinge,
        settled: if last.is_none() { result.settled } else { None },
        generalized_impulse: b,
        modal_velocity: eta_dot,
        qdot,
        energy_before,
        energy_before_field,
        energy_after,
        momentum_before: Momentum { linear, angular },
        momentum_after,
        angle_mismatch,
        hub_state: [0.0; 3],
        modal_displacement,
        elastic_energy_before: coupled.elastic_energy(&y),
        elastic_energy_after,
        latch_energy: coupled.latch_energy(&y, &vec![true; coupled.panels()]),
        latch_carried: carried,
        lines_energy,
        notes,
    })
}

/// Momentum (about the hub's centre of mass `c_hub`) and kinetic energy just before the latch:
/// the rigid rest of the structure moving with the hub, plus the deploying panels.
fn momentum_before(
    rest: &RigidBody,
    view: &PlateView<'_>,
    pl: &PreLatch,
    c_hub: Vec3,
) -> (Momentum, f64) {
    let mut before = rigid_momentum(rest, pl.v_hub, pl.w_hub);
    let mut energy_before = 0.5 * (pl.v_hub.dot(before.linear) + pl.w_hub.dot(before.angular));
    let origin = view.element.origin;
    let ea = view.plate.length_axis;
    for p in &pl.panels {
        let centre = origin + ea * (p.start + 0.5 * p.length) - c_hub;
        let v = p.velocity(0.5 * p.length);
        before.linear = before.linear + v * p.mass;
        before.angular = before.angular + centre.cross(v) * p.mass + p.omega * p.inertia;
        energy_before += 0.5 * (p.mass * v.dot(v) + p.inertia * p.omega.dot(p.omega));
    }
    (before, energy_before)
}

/// The generalized impulse of the projection method: the field's velocity relative to the
/// hub's rigid motion projected on the plate's functions, plus M q̇_h; with the kinetic energy
/// of that field before the latch.
fn projected_impulse(
    model: &RitzModel,
    view: &PlateView<'_>,
    pl: &PreLatch,
    notes: &mut Vec<String>,
) -> (Vec<f64>, f64) {
    let st = &model.structure;
    let n = model.dof();
    let (ea, nn) = (view.plate.length_axis, view.plate.normal);
    let (a, width, mu) = (
        view.plate.length,
        view.plate.width,
        view.plate.areal_density,
    );
    let (nx, ny) = (view.xb.len(), view.yb.len());
    let mut b = vec![0.0; n];
    let mut xv = vec![[0.0; 4]; nx];
    let mut yv = vec![[0.0; 4]; ny];
    // q̇_h: the hub's rigid velocity in Ritz coordinates.
    let mut qh = vec![0.0; n];
    for (q, v) in qh.iter_mut().zip(&pl.base_velocity) {
        *q += v;
    }
    if st.hub.motion == HubMotion::Free {
        for i in 0..3 {
            qh[i] = pl.v_hub.get(i);
            qh[3 + i] = pl.w_hub.get(i);
        }
    } else if pl.v_hub.norm() > 0.0 || pl.w_hub.norm() > 0.0 {
        notes.push(
            "the hub is free during deployment but fixed in the structure: its motion at \
             the latch is dropped from the hand-over"
                .to_string(),
        );
    }
    // ∫Y_n dη, with the width basis's own rule.
    let yq = view.yb.quadrature();
    let mut ybar = vec![0.0; ny];
    for (&eta, &w) in yq.points.iter().zip(&yq.weights) {
        view.yb.eval_all(eta, &mut yv);
        for (k, y) in ybar.iter_mut().enumerate() {
            *y += w * yv[k][0];
        }
    }
    let xq: Quadrature = view.xb.quadrature();
    let (mut fu, mut fth) = (Vec3::ZERO, Vec3::ZERO);
    let mut fg = vec![0.0; nx * ny];
    let mut ke_delta = 0.0;
    // The plate's velocity when it moves with its attachment section: [U̇; Θ̇] = T q̇_h.
    let t = &view.element.attachment;
    let row = |r: usize| (0..n).map(|c| t[(r, c)] * qh[c]).sum::<f64>();
    let (u_dot, th_dot) = (
        Vec3::new(row(0), row(1), row(2)),
        Vec3::new(row(3), row(4), row(5)),
    );
    let rigid = |x: f64| u_dot + th_dot.cross(ea * x);
    for p in &pl.panels {
        for (&xi, &w) in xq.points.iter().zip(&xq.weights) {
            let s = xi * p.length;
            let x = p.start + s;
            let wt = w * p.length * mu * width;
            let dv = p.velocity(s) - rigid(x);
            fu = fu + dv * wt;
            fth = fth + (ea * x).cross(dv) * wt;
            ke_delta += 0.5 * wt * dv.dot(dv);
            view.xb.eval_all((x / a).clamp(0.0, 1.0), &mut xv);
            let dn = nn.dot(dv) * wt;
            for m in 0..nx {
                for k in 0..ny {
                    fg[m * ny + k] += xv[m][0] * ybar[k] * dn;
                }
            }
        }
    }
    view.scatter(&mut b, fu, fth, &fg);
    let m = &model.mass;
    let mut kinetic_h = 0.0;
    let mut cross = 0.0;
    let nq = if pl.base_velocity.is_empty() {
        HUB_DOF
    } else {
        n
    };
    for r in 0..n {
        let mq: f64 = (0..nq).map(|c| m[(r, c)] * qh[c]).sum();
        kinetic_h += 0.5 * qh[r] * mq;
        cross += qh[r] * b[r];
        b[r] += mq;
    }
    (b, kinetic_h + cross + ke_delta)
}

/// The generalized impulse of the impulse method: the latch impulses applied at the panels'
/// centres.
fn latch_impulse(
    model: &RitzModel,
    view: &PlateView<'_>,
    pl: &PreLatch,
    last: &LatchEvent,
) -> Vec<f64> {
    let (ea, nn) = (view.plate.length_axis, view.plate.normal);
    let mut b = vec![0.0; model.dof()];
    let (s, c) = pl.theta.sin_cos();
    for (i, p) in pl.panels.iter().enumerate() {
        let sp = last.impulses[i].0;
        let imp = ea * (c * sp[0] + s * sp[1]) + nn * (-s * sp[0] + c * sp[1]);
        let bi = point_impulse(
            model,
            ComponentId::Plate(view.index),
            [p.start + 0.5 * p.length, 0.0],
            imp,
        );
        b.iter_mut().zip(&bi).for_each(|(x, y)| *x += y);
    }
    b
}

/// The motion after the latch: modal velocities η̇, coordinate velocities q̇, kinetic energy
/// and momentum.
fn after_latch(
    model: &RitzModel,
    modal: &ModalAnalysis,
    b: &[f64],
) -> (Vec<f64>, Vec<f64>, f64, Momentum) {
    after_latch_split(model, modal, b, b)
}

/// As [`after_latch`], the elastic modes' η̇ from `b` and the rigid modes' from `rigid_b`.
fn after_latch_split(
    model: &RitzModel,
    modal: &ModalAnalysis,
    b: &[f64],
    rigid_b: &[f64],
) -> (Vec<f64>, Vec<f64>, f64, Momentum) {
    let n = model.dof();
    let eta_dot: Vec<f64> = modal_velocities(modal, b)
        .into_iter()
        .zip(modal_velocities(modal, rigid_b))
        .zip(&modal.modes)
        .map(|((e, r), m)| if m.rigid { r } else { e })
        .collect();
    let mut qdot = vec![0.0; n];
    for (m, &v) in modal.modes.iter().zip(&eta_dot) {
        for (q, p) in qdot.iter_mut().zip(&m.shape) {
            *q += p * v;
        }
    }
    let energy_after = 0.5 * eta_dot.iter().map(|v| v * v).sum::<f64>();
    let m = &model.mass;
    let row = |r: usize| (0..n).map(|c| m[(r, c)] * qdot[c]).sum::<f64>();
    let momentum_after = Momentum {
        linear: Vec3::new(row(0), row(1), row(2)),
        angular: Vec3::new(row(3), row(4), row(5)),
    };
    (eta_dot, qdot, energy_after, momentum_after)
}
