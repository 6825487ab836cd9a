//! The deploying array on the flexible, free-floating base as one system (docs/theory.md §2).
//!
//! Coordinates: the hub's position R and attitude quaternion (free hub only), the base's
//! modal coordinates η (hub-fixed modes, [`super::base`]), the opening angles α. Speeds
//! u = [v, ω, η̇, α̇]: v and ω are the hub's velocity and angular velocity in hub components.
//!
//! The root hinge frame H sits at p(η) = p₀ + P η on the base and turns with it by the small
//! rotation θ = Θ η, its axes E(η) = exp(θ̃) E₀ (E₀ = [e_a, n, ẑ] of the deploying plate):
//!   V_H = v + ω × p + P η̇,   Ω_H = ω + J(θ) Θ η̇,
//! J the exponential map's left Jacobian ([`super::attitude`]). In H the chain is the planar
//! chain of [`super::chain`] (hub held, root at H's origin); its panels move in 3-D with H.
//!
//! Kane's equations: the chain's inertia forces reduce to the wrench W = [F; M_H] the base
//! exerts on panel 1 at H and to the hinge equations. In H's components, with A and Ω̇ the
//! inertial accelerations of H,
//!   a_i = A + Ω̇ × c_i + Ω × (Ω × c_i) + 2 Ω × ċ_i + c̈_i,   ε_i = Ω̇ + φ̈_i ẑ + Ω × φ̇_i ẑ,
//!   F = Σ m_i a_i,   M_H = Σ c_i × m_i a_i + I_i ε_i + ω_i × I_i ω_i,
//!   d_l ẑ·Σ_{i≥l} [(c_i − h_l) × m_i a_i + I_i ε_i + ω_i × I_i ω_i] = Q_l,
//! which are linear in (A, Ω̇, α̈): [W; Q*] = M_c [A; Ω̇; α̈] + b_c. With [V_H; Ω_H] = B u_base
//! and [A; Ω̇] = B u̇_base + a_b, the base receives Bᵀ W; the base itself contributes
//! M_base u̇ + c_base ([`super::inertia`]), its elastic forces −ω_j² η_j. The system
//!   M u̇ = Q − c,   M = M_base ⊕ 0 + [B 0; 0 I]ᵀ M_c [B 0; 0 I]
//! is solved on the admissible speeds u = Z w (locked hinges, an ideal cable):
//!   (ZᵀMZ) ẇ = Zᵀ(Q − c).
//!
//! A latch is a plastic impact of the whole system: u⁺ = Z (ZᵀMZ)⁻¹ Zᵀ M u⁻, the velocity
//! nearest to u⁻ in the mass metric among those the locked hinges admit; the energy lost is
//! ½ (u⁻ − u⁺)ᵀ M (u⁻ − u⁺).
//!
//! Cable synchronisation (closed loops between neighbouring hinges): the hinge angles keep
//! α_2 − α_2(0) = 2 (α_1 − α_1(0)) and α_{i+1} − α_{i+1}(0) = α_i − α_i(0) (i ≥ 2), i.e. C α̇ = 0
//! with rows (−2, 1, 0, …), (0, −1, 1, 0, …), …; ideal (a holonomic constraint, its torques
//! the multipliers λ = (CCᵀ)⁻¹ C (M u̇ + c − Q)) or a torsional spring k_c per loop
//! (V = ½ k_c |C (α − α(0))|²).

use super::articulated;
use super::attitude::{self, Quaternion};
use super::base::BaseModel;
use super::chain::{Chain, P2};
use super::inertia::{combine, AtShape};
use crate::math::{dot4, Mat3, Vec3};
use crate::ode::integrator::{Change, Tie};
use crate::structure::HubMotion;
use faer::{Mat, Side};
use std::cell::RefCell;
use std::f64::consts::PI;

/// How the hinges are tied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Synchronisation {
    /// Independent hinges.
    None,
    /// Closed cable loops, ideal (a holonomic constraint).
    IdealCable,
    /// Closed cable loops with a torsional stiffness per loop, N·m/rad.
    ElasticCable(f64),
}

/// A compliant latch per hinge (docs/theory.md §2.3a): once hinge j has been
/// captured (the first time it reaches its latch angle α_j^L while opening) its moment gains
/// −k_j (α_j − α_j^L) − c_j α̇_j for good; the hinge spring keeps acting.
#[derive(Debug, Clone, PartialEq)]
pub struct CompliantLatch {
    /// k_j, N·m/rad.
    pub stiffness: Vec<f64>,
    /// c_j, N·m·s/rad.
    pub damping: Vec<f64>,
}

/// The coupled system.
#[derive(Debug)]
pub struct Coupled {
    /// The base.
    pub base: BaseModel,
    /// The planar chain in the hinge frame (hub held, root at the origin).
    pub chain: Chain,
    /// Panel inertias about their centres in their own axes (length, normal, hinge axis).
    pub panel_inertia: Vec<[f64; 3]>,
    /// Cable synchronisation.
    pub sync: Synchronisation,
    /// Compliant latches (`None`: rigid latches, plastic impacts).
    pub latch: Option<CompliantLatch>,
    /// ζ of the base's modal damping (`[deployment] base_damping_ratio`, 0 by default): the
    /// force −2 ζ ω_j η̇_j on each kept hub-fixed mode.
    pub base_damping_ratio: f64,
}

/// A state split into its parts (slices of y = [positions, speeds]).
#[derive(Debug, Clone, Copy)]
pub struct View<'a> {
    /// Hub position R (inertial), m; zero for a held hub.
    pub r: Vec3,
    /// Hub attitude.
    pub quat: Quaternion,
    /// Base modal coordinates.
    pub eta: &'a [f64],
    /// Opening angles, rad.
    pub alpha: &'a [f64],
    /// Hub velocity (hub components), m/s.
    pub v: Vec3,
    /// Hub angular velocity (hub components), rad/s.
    pub w: Vec3,
    /// Modal rates.
    pub eta_dot: &'a [f64],
    /// Opening rates, rad/s.
    pub alpha_dot: &'a [f64],
}

/// Everything computed at one state.
#[derive(Debug, Clone)]
pub struct Eval {
    /// System mass matrix over the speeds (0 × 0 from the per-step load path, which does
    /// without it).
    pub mass: Mat<f64>,
    /// Velocity terms c.
    pub bias: Vec<f64>,
    /// Applied generalized forces Q (elastic, hinge springs, dampers, friction, cable).
    pub force: Vec<f64>,
    /// Base invariants at η.
    pub at: AtShape,
    /// Hinge frame axes in hub components (columns e_a, n, ẑ).
    pub frame: Mat3,
    /// Hinge point from the hub's centre of mass (hub components), m.
    pub hinge: Vec3,
    /// Map from base speeds to [V_H; Ω_H] in hinge components (6 × base speeds).
    pub b: Mat<f64>,
    /// [A; Ω̇] of H for zero accelerations (hinge components).
    pub a_bias: [f64; 6],
    /// The chain's block matrix M_c ((6 + N)²; 0 × 0 from the per-step load path) and bias b_c.
    pub mc: Mat<f64>,
    /// The chain's bias b_c.
    pub bc: Vec<f64>,
    /// Panel centres in the hinge frame (components e_a, n, ẑ), m.
    pub centres: Vec<Vec3>,
    /// Hinge points in the hinge frame, m (N + 1, the tip last).
    pub hinge_points: Vec<Vec3>,
    /// Panel angles in the hinge plane, rad.
    pub phi: Vec<f64>,
}

/// Accelerations and the loads that follow from them.
#[derive(Debug, Clone)]
pub struct Solution {
    /// u̇.
    pub udot: Vec<f64>,
    /// Wrench the base exerts on panel 1 at the root hinge, hub components: force (N) and
    /// moment about the hinge point (N·m).
    pub root_wrench: (Vec3, Vec3),
    /// Cable torque per loop, N·m (empty without a cable).
    pub cable_torque: Vec<f64>,
    /// The root hinge frame's acceleration and angular acceleration and the hinges' α̈:
    /// [A; Ω̇; α̈], hinge components.
    pub hinge_acc: Vec<f64>,
}

fn cross_mat(a: Vec3) -> Mat3 {
    a.skew()
}

fn from_cols(c: [Vec3; 3]) -> Mat3 {
    Mat3(std::array::from_fn(|i| {
        std::array::from_fn(|j| c[j].get(i))
    }))
}

impl Coupled {
    /// Hub speeds: 6 for a free hub, 0 for a held one.
    pub fn hub_dof(&self) -> usize {
        match self.base.hub_motion {
            HubMotion::Free => 6,
            HubMotion::Fixed => 0,
        }
    }

    /// Number of base modes.
    pub fn modes(&self) -> usize {
        self.base.modes()
    }

    /// Number of panels.
    pub fn panels(&self) -> usize {
        self.chain.len()
    }

    /// Number of speeds.
    pub fn speeds(&self) -> usize {
        self.hub_dof() + self.modes() + self.panels()
    }

    /// Number of position coordinates (the quaternion has four).
    pub fn positions(&self) -> usize {
        self.speeds() + usize::from(self.hub_dof() == 6)
    }

    /// Index of α_1 among the positions.
    pub fn alpha_offset(&self) -> usize {
        self.positions() - self.panels()
    }

    /// Index of α̇_1 among the speeds.
    pub fn rate_offset(&self) -> usize {
        self.speeds() - self.panels()
    }

    /// The state at release: at rest, undeformed, hub at the origin, α(0) and α̇(0) of the
    /// hinges. With an ideal cable the rates are the root hinge's along the cable's speed
    /// vector r = (1, 2, 2, …) exactly (the scenario accepts them to 1e-9 of the law): the
    /// state starts on the cable's manifold, whose tangent space the Jacobian's ties
    /// ([`Coupled::cable_ties`]) assume.
    pub fn initial_state(&self) -> Vec<f64> {
        let (np, ns) = (self.positions(), self.speeds());
        let mut y = vec![0.0; np + ns];
        if self.hub_dof() == 6 {
            y[3] = 1.0;
        }
        let (a, r) = (self.alpha_offset(), np + self.rate_offset());
        let cable = self.sync == Synchronisation::IdealCable;
        let root_rate = self.chain.hinges.first().map_or(0.0, |h| h.initial_rate);
        for (i, h) in self.chain.hinges.iter().enumerate() {
            y[a + i] = h.initial_angle;
            y[r + i] = match (cable, i) {
                (true, 0) => root_rate,
                (true, _) => 2.0 * root_rate,
                (false, _) => h.initial_rate,
            };
        }
        y
    }

    /// Splits y.
    pub fn view<'a>(&self, y: &'a [f64]) -> View<'a> {
        let (np, m, n) = (self.positions(), self.modes(), self.panels());
        let (pos, spd) = y.split_at(np);
        let free = self.hub_dof() == 6;
        let h = if free { 7 } else { 0 };
        let hs = if free { 6 } else { 0 };
        View {
            r: if free {
                Vec3::new(pos[0], pos[1], pos[2])
            } else {
                Vec3::ZERO
            },
            quat: if free {
                [pos[3], pos[4], pos[5], pos[6]]
            } else {
                [1.0, 0.0, 0.0, 0.0]
            },
            eta: &pos[h..h + m],
            alpha: &pos[h + m..h + m + n],
            v: if free {
                Vec3::new(spd[0], spd[1], spd[2])
            } else {
                Vec3::ZERO
            },
            w: if free {
                Vec3::new(spd[3], spd[4], spd[5])
            } else {
                Vec3::ZERO
            },
            eta_dot: &spd[hs..hs + m],
            alpha_dot: &spd[hs + m..hs + m + n],
        }
    }

    /// With an ideal cable and some hinge free ([`OdeSystem`](crate::ode::integrator::OdeSystem)
    /// ties): the opening angles and their rates, each along the cable's speed vector
    /// r = (1, 2, 2, …) (α − α(0) = r (α₁ − α₁(0)), α̇ = r α̇₁); none otherwise.
    pub fn cable_ties(&self, free: &[bool]) -> Vec<Tie> {
        let n = self.panels();
        if !self.cable_speed(free) || n < 2 {
            return Vec::new();
        }
        let r: Vec<f64> = (0..n).map(|i| if i == 0 { 1.0 } else { 2.0 }).collect();
        let (a, s) = (self.alpha_offset(), self.positions() + self.rate_offset());
        [a, s]
            .into_iter()
            .map(|first| Tie {
                components: (first..first + n).collect(),
                direction: r.clone(),
            })
            .collect()
    }

    /// The cable's loop matrix C ((N − 1) × N).
    fn cable_rows(&self) -> Vec<Vec<f64>> {
        Self::cable_law(self.panels())
    }

    /// The cable law's rows for `n` hinges, C α̇ = 0: α̇₂ = 2 α̇₁, α̇_{k+1} = α̇_k (k ≥ 2).
    pub(crate) fn cable_law(n: usize) -> Vec<Vec<f64>> {
        (1..n)
            .map(|k| {
                let mut r = vec![0.0; n];
                r[k] = 1.0;
                r[k - 1] = if k == 1 { -2.0 } else { -1.0 };
                r
            })
            .collect()
    }

    /// Basis Z of the admissible speeds for the hinges flagged free.
    pub fn admissible(&self, free: &[bool]) -> Mat<f64> {
        let mut z = SparseColumns::default();
        self.admissible_into(free, &mut z);
        let mut out = Mat::zeros(self.speeds(), z.len());
        for j in 0..z.len() {
            for &(i, v) in z.column(j) {
                out[(i, j)] = v;
            }
        }
        out
    }

    /// Z as sparse columns: a unit column per base speed, then one per free hinge
    /// (independent or elastically tied hinges) or, with an ideal cable and any hinge free,
    /// the cable's column (1, 2, 2, …) over the opening rates.
    fn admissible_into(&self, free: &[bool], z: &mut SparseColumns) {
        let (nb, n) = (self.rate_offset(), self.panels());
        z.clear();
        for i in 0..nb {
            z.push_column([(i, 1.0)]);
        }
        if self.sync == Synchronisation::IdealCable {
            if free.iter().any(|f| *f) {
                z.push_column((0..n).map(|i| (nb + i, if i == 0 { 1.0 } else { 2.0 })));
            }
        } else {
            for i in (0..n).filter(|&i| free[i]) {
                z.push_column([(nb + i, 1.0)]);
            }
        }
    }

    /// Kinematics, mass matrix, velocity terms and applied forces at a state.
    pub fn evaluate(&self, y: &[f64]) -> Eval {
        let mut ws = Workspace::default();
        self.assemble(y, &mut ws);
        ws.to_eval(self)
    }

    /// [`Coupled::evaluate`] into the buffers of `ws` (no allocation once they are sized).
    fn assemble(&self, y: &[f64], ws: &mut Workspace) {
        self.assemble_parts(y, ws, true);
    }

    /// The evaluation's parts into `ws`: the base block M_bb = M_base + Bᵀ M₁₁ B of the mass
    /// matrix, c and Q always; the whole mass matrix (with the chain's Bᵀ M₁₂ and M₂₂, O(N²))
    /// when `dense`. In two phases: the configuration's ([`Coupled::assemble_configuration`],
    /// the positions alone) and the motion's ([`Coupled::assemble_motion`]).
    fn assemble_parts(&self, y: &[f64], ws: &mut Workspace, dense: bool) {
        self.assemble_configuration(y, ws, dense);
        self.assemble_motion(y, ws);
    }

    /// What depends on the positions alone (η and α): the invariants at η, the hinge frame,
    /// B, the chain's mass blocks M₁₁ and M₁₂ and outboard sums, M_bb (and the dense M when
    /// `dense`). The speeds' columns of a Jacobian by differences share it
    /// ([`Coupled::rhs_captured_speeds`]).
    fn assemble_configuration(&self, y: &[f64], ws: &mut Workspace, dense: bool) {
        let s = self.view(y);
        let base = &self.base;
        let inv = &base.invariants;
        let (h, m) = (self.hub_dof(), self.modes());
        let nb = h + m;
        inv.at_into(s.eta, &mut ws.at);
        // Hinge frame.
        let theta = combine(&base.hinge_rotations, s.eta);
        let e0 = from_cols(base.frame);
        let frame = attitude::exp(theta).matmul(e0);
        let jl = attitude::left_jacobian(theta);
        let hinge = base.hinge + combine(&base.hinge_shapes, s.eta);
        let et = frame.transpose();
        // B: base speeds → [V_H; Ω_H], hinge components (6 × nb, row-major).
        let b = &mut ws.b;
        refill(b, 6 * nb, 0.0);
        if h == 6 {
            let ph = cross_mat(hinge);
            for i in 0..3 {
                for j in 0..3 {
                    b[i * nb + j] = et.get(i, j);
                    // −E ᵀ p̃ (ω ↦ ω × p = −p̃ ω).
                    b[i * nb + 3 + j] = -(0..3).map(|k| et.get(i, k) * ph.get(k, j)).sum::<f64>();
                    b[(3 + i) * nb + 3 + j] = et.get(i, j);
                }
            }
        }
        for k in 0..m {
            let pv = et.apply(base.hinge_shapes[k]);
            let rv = et.apply(jl.apply(base.hinge_rotations[k]));
            for i in 0..3 {
                b[i * nb + h + k] = pv.get(i);
                b[(3 + i) * nb + h + k] = rv.get(i);
            }
        }
        ws.frame = frame;
        ws.hinge = hinge;
        ws.theta = theta;
        ws.jl = jl;
        self.chain_mass_blocks(s.alpha, &mut ws.chain, dense);
        refill(&mut ws.mbb, nb * nb, 0.0);
        self.base_mass(ws);
        let (b, mbb) = (&ws.b, &mut ws.mbb);
        let m11 = &ws.chain.m11;
        // [B 0; 0 I]ᵀ M_c [B 0; 0 I] by blocks: Bᵀ M₁₁ B here, Bᵀ M₁₂, M₂₁ B and M₂₂ below
        // when dense (loops: the blocks are small, and a general product's set-up costs more
        // than the arithmetic).
        // The columns of B and of M₁₁ B as 6-arrays: each entry below is the same sum, in the
        // same order, as over the row-major blocks, without their strided reads.
        let (bt, mbt) = (&mut ws.bt, &mut ws.mbt);
        bt.clear();
        bt.extend((0..nb).map(|j| std::array::from_fn(|k| b[k * nb + j])));
        mbt.clear();
        mbt.extend(
            bt.iter()
                .map(|bj| std::array::from_fn(|i| (0..6).map(|k| m11[i][k] * bj[k]).sum::<f64>())),
        );
        // (No base speeds, nb = 0: a held hub on a rigid base.)
        for (row, bi) in mbb.chunks_exact_mut(nb.max(1)).zip(bt.iter()) {
            for (x, mj) in row.iter_mut().zip(mbt.iter()) {
                *x += (0..6).map(|k| bi[k] * mj[k]).sum::<f64>();
            }
        }
        if dense {
            self.dense_mass(ws);
        } else {
            // Nothing of an earlier dense evaluation (perhaps of another model) stays readable.
            ws.mass.clear();
            ws.chain.mc.clear();
        }
    }

    /// What the speeds enter, at the configuration [`Coupled::assemble_configuration`] left
    /// in `ws` (the same positions): H's bias acceleration, the chain's bias b_c, c and Q.
    fn assemble_motion(&self, y: &[f64], ws: &mut Workspace) {
        let s = self.view(y);
        let base = &self.base;
        let (h, m, n) = (self.hub_dof(), self.modes(), self.panels());
        let nb = h + m;
        let (theta, jl, hinge, et) = (ws.theta, ws.jl, ws.hinge, ws.frame.transpose());
        let theta_dot = combine(&base.hinge_rotations, s.eta_dot);
        let p_dot = combine(&base.hinge_shapes, s.eta_dot);
        let omega_rel = jl.apply(theta_dot);
        let v_h = s.v + s.w.cross(hinge) + p_dot;
        let a_h = s.w.cross(p_dot) + s.w.cross(v_h);
        let wd_h = attitude::left_jacobian_rate(theta, theta_dot) + s.w.cross(omega_rel);
        let omega_h = et.apply(s.w + omega_rel);
        let a_bias = {
            let a = et.apply(a_h);
            let wd = et.apply(wd_h);
            [
                a.get(0),
                a.get(1),
                a.get(2),
                wd.get(0),
                wd.get(1),
                wd.get(2),
            ]
        };
        ws.a_bias = a_bias;
        self.chain_bias(s.alpha_dot, omega_h, &mut ws.chain);
        let ns = nb + n;
        refill(&mut ws.bias, ns, 0.0);
        self.base_bias(&s, ws);
        let (m11, m12) = (&ws.chain.m11, &ws.chain.m12);
        // Chain bias with H's bias acceleration: b_c + M_c [a_b; 0], mapped by [B 0; 0 I]ᵀ
        // (M₂₁ has the planar columns 0, 1 and 5 only).
        let cb = &mut ws.cb;
        cb.clear();
        cb.extend_from_slice(&ws.chain.bc);
        for i in 0..6 {
            cb[i] += (0..6).map(|k| m11[i][k] * a_bias[k]).sum::<f64>();
        }
        for (c, col) in m12.iter().enumerate() {
            cb[6 + c] += col[0] * a_bias[0] + col[1] * a_bias[1] + col[2] * a_bias[5];
        }
        let bias = &mut ws.bias;
        for (x, bj) in bias.iter_mut().zip(ws.bt.iter()) {
            *x += (0..6).map(|i| bj[i] * cb[i]).sum::<f64>();
        }
        for c in 0..n {
            bias[nb + c] += cb[6 + c];
        }
        // Applied forces.
        let force = &mut ws.force;
        refill(force, ns, 0.0);
        for k in 0..m {
            force[h + k] = -base.omega[k].powi(2) * s.eta[k];
        }
        if self.base_damping_ratio > 0.0 {
            // Modal damping of the base (an option; zero by default): −2 ζ ω_j η̇_j.
            for k in 0..m {
                force[h + k] -= self.modal_damping(k) * s.eta_dot[k];
            }
        }
        for (i, hg) in self.chain.hinges.iter().enumerate() {
            force[nb + i] = hg.moment(s.alpha[i], s.alpha_dot[i]);
        }
        if let Synchronisation::ElasticCable(kc) = self.sync {
            // Row k of C has −2 (k = 1) or −1 at hinge k − 1 and 1 at hinge k.
            for k in 1..n {
                let mis = self.cable_loop_mismatch(s.alpha, k);
                let (below, at) = (if k == 1 { -2.0 } else { -1.0 }, 1.0);
                force[nb + k - 1] -= kc * mis * below;
                force[nb + k] -= kc * mis * at;
            }
        }
    }

    /// The whole mass matrix into `ws.mass` (ns × ns): M_bb, Bᵀ M₁₂ and its transpose, M₂₂.
    fn dense_mass(&self, ws: &mut Workspace) {
        let (nb, n) = (self.rate_offset(), self.panels());
        let (ns, nc) = (nb + n, 6 + n);
        let (b, mc, mass) = (&ws.b, &ws.chain.mc, &mut ws.mass);
        refill(mass, ns * ns, 0.0);
        for i in 0..nb {
            mass[i * ns..i * ns + nb].copy_from_slice(&ws.mbb[i * nb..(i + 1) * nb]);
        }
        for c in 0..n {
            for i in 0..nb {
                // Bᵀ M₁₂ = (M₂₁ B)ᵀ.
                let v = (0..6)
                    .map(|k| mc[(6 + c) * nc + k] * b[k * nb + i])
                    .sum::<f64>();
                mass[i * ns + nb + c] += v;
                mass[(nb + c) * ns + i] += v;
            }
        }
        for r in 0..n {
            for c in 0..n {
                mass[(nb + r) * ns + nb + c] += mc[(6 + r) * nc + 6 + c];
            }
        }
    }

    /// C (α − α(0)) per cable loop, rad.
    pub fn cable_mismatch(&self, alpha: &[f64]) -> Vec<f64> {
        (1..self.panels())
            .map(|k| self.cable_loop_mismatch(alpha, k))
            .collect()
    }

    /// Loop k's (k = 1 … N − 1) mismatch: (α_k − α_k(0)) − c (α_{k−1} − α_{k−1}(0)), c = 2
    /// for the first loop, 1 for the others (hinges 0-based).
    fn cable_loop_mismatch(&self, alpha: &[f64], k: usize) -> f64 {
        let d = |i: usize| alpha[i] - self.chain.hinges[i].initial_angle;
        let below = if k == 1 { -2.0 } else { -1.0 };
        below * d(k - 1) + d(k)
    }

    /// The base's own mass matrix over [v, ω, η̇] (see [`super::inertia`]), added to
    /// `ws.mbb` (`ws.at` holds the invariants at η).
    fn base_mass(&self, ws: &mut Workspace) {
        let inv = &self.base.invariants;
        let (h, m) = (self.hub_dof(), self.modes());
        let ns = h + m; // the stride of M_bb
        let (at, mass) = (&ws.at, &mut ws.mbb);
        for a in 0..m {
            for c in 0..m {
                mass[(h + a) * ns + h + c] += inv.mee[(a, c)];
            }
        }
        if h == 0 {
            return;
        }
        let st = at.s.skew();
        for i in 0..3 {
            mass[i * ns + i] += inv.mass;
            for j in 0..3 {
                mass[i * ns + 3 + j] -= st.get(i, j);
                mass[(3 + i) * ns + j] += st.get(i, j);
                mass[(3 + i) * ns + 3 + j] += at.j.get(i, j);
            }
        }
        for k in 0..m {
            for i in 0..3 {
                mass[i * ns + 6 + k] += inv.s[k].get(i);
                mass[(6 + k) * ns + i] += inv.s[k].get(i);
                mass[(3 + i) * ns + 6 + k] += at.l[k].get(i);
                mass[(6 + k) * ns + 3 + i] += at.l[k].get(i);
            }
        }
    }

    /// The base's own velocity terms over [v, ω, η̇] (see [`super::inertia`]), added to
    /// `ws.bias` (`ws.at` holds the invariants at η).
    fn base_bias(&self, s: &View<'_>, ws: &mut Workspace) {
        let inv = &self.base.invariants;
        let (h, m) = (self.hub_dof(), self.modes());
        if h == 0 {
            return;
        }
        let (at, bias) = (&ws.at, &mut ws.bias);
        let (v, w) = (s.v, s.w);
        let (p, hh) = inv.momenta(at, v, w, s.eta_dot);
        let s_dot = inv.s_rate(s.eta_dot);
        // J̇ ω = Σ_k η̇_k (∂J/∂η_k) ω.
        let mut j_dot = [[0.0; 3]; 3];
        for (d, e) in at.dj.iter().zip(s.eta_dot) {
            for r in 0..3 {
                for c in 0..3 {
                    j_dot[r][c] += d.0[r][c] * *e;
                }
            }
        }
        let j_dot = Mat3(j_dot);
        inv.l_rate_into(s.eta_dot, &mut ws.l_dot);
        let l_dot = &ws.l_dot;
        let cv = w.cross(s_dot) + w.cross(p);
        let cw =
            s_dot.cross(v) + j_dot.apply(w) + combine(l_dot, s.eta_dot) + w.cross(hh) + v.cross(p);
        for i in 0..3 {
            bias[i] += cv.get(i);
            bias[3 + i] += cw.get(i);
        }
        // ġ_k − ∂T/∂η_k: L̇_kᵀ ω from ġ, and ∂T/∂η_k = v·(ω × S_k) + ½ ωᵀ J_{,k} ω + ωᵀ L1_k η̇,
        // whose last term is −ω·L̇_k (L1 antisymmetric: Σ_c L1_kc η̇_c = −Σ_c L1_ck η̇_c).
        for k in 0..m {
            let dt_deta = v.dot(w.cross(inv.s[k])) + 0.5 * w.dot(at.dj[k].apply(w));
            bias[6 + k] += 2.0 * l_dot[k].dot(w) - dt_deta;
        }
    }

    /// The chain's mass blocks over [A; Ω̇; α̈] (hinge components) into `cw`: M₁₁ and the
    /// coupling columns M₁₂ always, the dense M_c when `dense` (the O(N) elimination of
    /// [`super::articulated`] does without M₂₂), with the configuration they need (angles,
    /// centres, hinge points, inertia tensors, outboard sums).
    fn chain_mass_blocks(&self, alpha: &[f64], cw: &mut ChainWork, dense: bool) {
        let ch = &self.chain;
        let n = ch.len();
        cw.configure(ch, alpha);
        let z = Vec3::new(0.0, 0.0, 1.0);
        let d = |k: usize| if k % 2 == 0 { -1.0 } else { 1.0 };
        let (centres, hinges) = (&cw.centres, &cw.hinges);
        // Panel inertia tensors in hinge components.
        cw.inertia.clear();
        for i in 0..n {
            cw.inertia.push(self.panel_tensor(i, cw.phi[i]));
        }
        refill(&mut cw.m12, n, [0.0; 3]);
        // Outboard sums, tip to root: mass, first moment, rotational inertia about ẑ.
        let (mut mt, mut s1) = (0.0, Vec3::ZERO);
        let mut jc = Mat3::ZERO;
        let mut iz = 0.0;
        let mut mzz = 0.0; // Σ m_i |c_i|² about H (in-plane)
        for i in (0..n).rev() {
            let p = &ch.panels[i];
            let c = centres[i];
            let ii = cw.inertia[i];
            mt += p.mass;
            s1 = s1 + c * p.mass;
            jc = jc + (Mat3::IDENTITY * c.dot(c) - c.outer(c)) * p.mass + ii;
            iz += self.panel_inertia[i][2];
            mzz += p.mass * c.dot(c);
            // Hinge l = i: outboard sums about h_i.
            let hl = hinges[i];
            let bl = s1 - hl * mt; // Σ m_j (c_j − h_l)
            let al = mzz - 2.0 * hl.dot(s1) + mt * hl.dot(hl) + iz; // Σ m_j|c_j − h_l|² + I_z
            let dl = d(i);
            // Column 6 + l of M_c: a force in the hinge plane and a moment about ẑ.
            let fcol = z.cross(bl) * dl;
            let mcol = dl * (al + hl.dot(bl));
            cw.m12[i] = [fcol.get(0), fcol.get(1), mcol];
        }
        let st = s1.skew();
        let m11 = &mut cw.m11;
        *m11 = [[0.0; 6]; 6];
        for r in 0..3 {
            m11[r][r] = mt;
            for c in 0..3 {
                m11[r][3 + c] = -st.get(r, c);
                m11[3 + r][c] = st.get(r, c);
                m11[3 + r][3 + c] = jc.get(r, c);
            }
        }
        cw.outboard_sums(ch);
        if dense {
            cw.dense_blocks();
        }
    }

    /// The chain's bias b_c (the forces and moments of zero accelerations) for the opening
    /// rates α̇ and H's angular velocity `omega` (hinge components), at the configuration
    /// [`Coupled::chain_mass_blocks`] left in `cw`.
    fn chain_bias(&self, alpha_dot: &[f64], omega: Vec3, cw: &mut ChainWork) {
        let ch = &self.chain;
        let n = ch.len();
        cw.rates_of(alpha_dot);
        let z = Vec3::new(0.0, 0.0, 1.0);
        let d = |k: usize| if k % 2 == 0 { -1.0 } else { 1.0 };
        let (centres, hinges, rates) = (&cw.centres, &cw.hinges, &cw.rates);
        // Centre velocities and accelerations relative to H.
        cw.cdot.clear();
        cw.cdd.clear();
        let (mut vh, mut ah) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            let r = centres[i] - hinges[i];
            let l = hinges[i + 1] - hinges[i];
            let wi = rates[i];
            cw.cdot.push(vh + z.cross(r) * wi);
            cw.cdd.push(ah - r * (wi * wi));
            vh = vh + z.cross(l) * wi;
            ah = ah - l * (wi * wi);
        }
        let bc = &mut cw.bc;
        refill(bc, 6 + n, 0.0);
        // Outboard sums, tip to root: the bias forces' resultant and moment about H.
        let (mut fb, mut mb) = (Vec3::ZERO, Vec3::ZERO);
        for i in (0..n).rev() {
            let p = &ch.panels[i];
            let c = centres[i];
            let wv = omega + z * rates[i];
            let ab = omega.cross(omega.cross(c)) + omega.cross(cw.cdot[i]) * 2.0 + cw.cdd[i];
            let eb = omega.cross(z * rates[i]);
            let ii = cw.inertia[i];
            let rot = ii.apply(eb) + wv.cross(ii.apply(wv));
            fb = fb + ab * p.mass;
            mb = mb + c.cross(ab * p.mass) + rot;
            // d_l ẑ·[Σ (c_j − h_l) × m_j a_j^b + rot_j] = d_l ẑ·(mb − h_l × fb).
            let hl = hinges[i];
            bc[6 + i] = d(i) * z.dot(mb - hl.cross(fb));
        }
        for r in 0..3 {
            bc[r] = fb.get(r);
            bc[3 + r] = mb.get(r);
        }
    }

    /// Panel i's inertia tensor about its centre in hinge components, at absolute angle φ_i.
    pub(crate) fn panel_tensor(&self, i: usize, phi: f64) -> Mat3 {
        let z = Vec3::new(0.0, 0.0, 1.0);
        let (sn, cs) = phi.sin_cos();
        let a1 = Vec3::new(cs, sn, 0.0);
        let a2 = Vec3::new(-sn, cs, 0.0);
        let [i1, i2, i3] = self.panel_inertia[i];
        a1.outer(a1) * i1 + a2.outer(a2) * i2 + z.outer(z) * i3
    }

    /// Accelerations for the hinges flagged free, and the loads.
    pub fn solve(&self, y: &[f64], free: &[bool]) -> (Eval, Solution) {
        self.solve_captured(y, free, &vec![false; self.panels()])
    }

    /// [`Coupled::solve`] with the compliant latches of the hinges flagged `captured` acting.
    /// The accelerations come from the dense system over every speed (the reference the
    /// O(N) elimination of [`Coupled::solve_captured_fast`] is tested against).
    pub fn solve_captured(&self, y: &[f64], free: &[bool], captured: &[bool]) -> (Eval, Solution) {
        let mut ws = Workspace::default();
        self.assemble_captured(y, captured, &mut ws, true);
        let ev = ws.to_eval(self);
        let udot = self.accelerations(&ev, free);
        let qc: Vec<f64> = ev.force.iter().zip(&ev.bias).map(|(f, c)| f - c).collect();
        let sol = self.loads_from_blocks(y, &ws, &qc, udot, free);
        (ev, sol)
    }

    /// [`Coupled::assemble`] with the latch moments of the captured hinges in the forces.
    fn assemble_captured(&self, y: &[f64], captured: &[bool], ws: &mut Workspace, dense: bool) {
        self.assemble_parts(y, ws, dense);
        self.add_latch_moments(y, captured, ws);
    }

    /// The captured hinges' latch moments added to the forces in `ws`.
    fn add_latch_moments(&self, y: &[f64], captured: &[bool], ws: &mut Workspace) {
        let nb = self.rate_offset();
        let s = self.view(y);
        for j in 0..self.panels() {
            ws.force[nb + j] += self.latch_moment(&s, captured, j);
        }
    }

    /// The compliant latches' moments on the hinges, −k_j (α_j − α_j^L) − c_j α̇_j for the
    /// captured ones, zero otherwise, N·m.
    pub fn latch_moments(&self, y: &[f64], captured: &[bool]) -> Vec<f64> {
        let s = self.view(y);
        (0..self.panels())
            .map(|j| self.latch_moment(&s, captured, j))
            .collect()
    }

    /// Hinge j's term of [`Coupled::latch_moments`].
    fn latch_moment(&self, s: &View<'_>, captured: &[bool], j: usize) -> f64 {
        match &self.latch {
            Some(l) if captured.get(j).copied().unwrap_or(false) => {
                let a = s.alpha[j] - self.chain.hinges[j].latch_angle;
                -l.stiffness[j] * a - l.damping[j] * s.alpha_dot[j]
            }
            _ => 0.0,
        }
    }

    /// Elastic energy of the captured latches' springs, ½ Σ k_j (α_j − α_j^L)², J.
    pub fn latch_energy(&self, y: &[f64], captured: &[bool]) -> f64 {
        let s = self.view(y);
        let Some(l) = &self.latch else { return 0.0 };
        (0..self.panels())
            .filter(|&j| captured.get(j).copied().unwrap_or(false))
            .map(|j| {
                let a = s.alpha[j] - self.chain.hinges[j].latch_angle;
                0.5 * l.stiffness[j] * a * a
            })
            .sum()
    }

    /// u̇ on the admissible speeds of the hinges flagged free: (ZᵀMZ) ẇ = Zᵀ(Q − c), u̇ = Z ẇ.
    fn accelerations(&self, ev: &Eval, free: &[bool]) -> Vec<f64> {
        let mut sw = SolveWork::default();
        self.admissible_into(free, &mut sw.z);
        let rhs: Vec<f64> = ev.force.iter().zip(&ev.bias).map(|(f, c)| f - c).collect();
        let mut udot = vec![0.0; rhs.len()];
        solve_admissible(|i, j| ev.mass[(i, j)], &rhs, &mut sw, &mut udot);
        udot
    }

    /// u̇ = Z (ZᵀMZ)⁻¹ Zᵀ (Q − c) for the hinges flagged free, in O(N + m²) per call beyond the
    /// base block's factorisation (docs/theory.md §2.7), from the parts of
    /// [`Coupled::assemble_parts`] without the dense mass matrix; `r` is Q − c.
    /// With M₁₂ (M_c's coupling columns, planar: rows A_x, A_y, Ω̇_z) and B_p the same rows
    /// of B, the opening rates' block is eliminated:
    ///   independent (or elastically tied) hinges, free set F: Y = M₂₂,FF⁻¹ M₂₁,F and
    ///   y = M₂₂,FF⁻¹ (Q − c)_F by the articulated-body recursion ([`super::articulated`]),
    ///   (M_bb − B_pᵀ M₁₂,F Y B_p) u̇_b = (Q − c)_b − B_pᵀ M₁₂,F y,   α̈_F = y − Y B_p u̇_b;
    ///   an ideal cable (α̇ = r ẇ, r = (1, 2, 2, …)): the one speed ẇ joins the base's with
    ///   rᵀ M₂₂ r (M₂₂ r by prefix and suffix sums, [`super::articulated::mass_times`]) and
    ///   the coupling B_pᵀ M₁₂ r; α̈ = r ẇ.
    /// A failed factorisation (a non-finite state) gives NaN, which stops the run.
    fn eliminate_chain(
        &self,
        ws: &Workspace,
        r: &[f64],
        sw: &mut SolveWork,
        free: &[bool],
        udot: &mut [f64],
    ) {
        if self.factor_chain(ws, sw, free) {
            self.solve_chain(ws, r, sw, free, udot);
        } else {
            udot.fill(f64::NAN);
        }
    }

    /// An ideal cable ties the hinges and some are free: the chain moves on its one speed.
    fn cable_speed(&self, free: &[bool]) -> bool {
        self.sync == Synchronisation::IdealCable && free.iter().any(|f| *f)
    }

    /// [`Coupled::eliminate_chain`]'s part that depends on the configuration alone: the
    /// reduced base block (M_bb − B_pᵀ M₁₂,F Y B_p, or M_bb bordered by the cable's speed)
    /// factored into `sw.zmz`, Y into `sw.fast.y[1..=3]` (the cable's r into `sw.fast.y[1]`);
    /// false when the factorisation fails.
    fn factor_chain(&self, ws: &Workspace, sw: &mut SolveWork, free: &[bool]) -> bool {
        let (nb, n) = (self.rate_offset(), self.panels());
        let cw = &ws.chain;
        // Rows A_x, A_y, Ω̇_z of B (6 × nb).
        let bp = |k: usize, j: usize| ws.b[[0, 1, 5][k] * nb + j];
        let fw = &mut sw.fast;
        let cable = self.cable_speed(free);
        let k = nb + usize::from(cable);
        let a = &mut sw.zmz;
        refill(a, k * k, 0.0);
        for i in 0..nb {
            a[i * k..i * k + nb].copy_from_slice(&ws.mbb[i * nb..(i + 1) * nb]);
        }
        refill(&mut fw.y[0], n, 0.0);
        if cable {
            let rc = &mut fw.y[1];
            refill(rc, n, 2.0);
            rc[0] = 1.0;
            let (mr, rest) = fw.y.split_at_mut(1);
            articulated::mass_times(&cw.plane_hinges, &cw.bsum, &cw.asum, &rest[0], &mut mr[0]);
            let rc = &fw.y[1];
            let srr = dot(rc, &fw.y[0]);
            let mut g = [0.0; 3];
            for (col, x) in cw.m12.iter().zip(rc) {
                for q in 0..3 {
                    g[q] += col[q] * x;
                }
            }
            for j in 0..nb {
                let v = (0..3).map(|q| bp(q, j) * g[q]).sum::<f64>();
                a[nb * k + j] = v;
                a[j * k + nb] = v;
            }
            a[nb * k + nb] = srr;
        } else {
            fw.panels.clear();
            fw.panels.extend((0..n).map(|i| articulated::PlanarPanel {
                mass: self.chain.panels[i].mass,
                inertia: self.chain.panels[i].inertia,
                centre: [cw.centres[i].get(0), cw.centres[i].get(1)],
                hinge: [cw.hinges[i].get(0), cw.hinges[i].get(1)],
            }));
            if !fw.art.factor(&fw.panels, free) {
                return false;
            }
            // y[1 + q] = M₂₂⁻¹ M₂₁[:, q].
            for q in 0..3 {
                fw.tau.clear();
                fw.tau.extend(cw.m12.iter().map(|col| col[q]));
                refill(&mut fw.y[1 + q], n, 0.0);
                fw.art.solve(&fw.tau, &mut fw.y[1 + q]);
            }
            // Δ = M₁₂ Y (3 × 3).
            let mut delta = [[0.0; 3]; 3];
            for (c, col) in cw.m12.iter().enumerate() {
                for q in 0..3 {
                    for p in 0..3 {
                        delta[q][p] += col[q] * fw.y[1 + p][c];
                    }
                }
            }
            for i in 0..nb {
                let di: [f64; 3] =
                    std::array::from_fn(|p| (0..3).map(|q| bp(q, i) * delta[q][p]).sum::<f64>());
                for j in 0..nb {
                    a[i * k + j] -= (0..3).map(|p| di[p] * bp(p, j)).sum::<f64>();
                }
            }
        }
        cholesky_in_place(a, k)
    }

    /// [`Coupled::eliminate_chain`]'s part that depends on `r` = Q − c, with the factor of
    /// [`Coupled::factor_chain`] in `sw`.
    fn solve_chain(
        &self,
        ws: &Workspace,
        r: &[f64],
        sw: &mut SolveWork,
        free: &[bool],
        udot: &mut [f64],
    ) {
        let (nb, n) = (self.rate_offset(), self.panels());
        let cw = &ws.chain;
        let (rb, ra) = r.split_at(nb);
        let bp = |k: usize, j: usize| ws.b[[0, 1, 5][k] * nb + j];
        let fw = &mut sw.fast;
        let cable = self.cable_speed(free);
        let k = nb + usize::from(cable);
        refill(&mut sw.w, k, 0.0);
        sw.w[..nb].copy_from_slice(rb);
        if cable {
            sw.w[nb] = dot(&fw.y[1], ra);
        } else {
            // y[0] = M₂₂⁻¹ (Q − c)_α and M₁₂ y.
            refill(&mut fw.y[0], n, 0.0);
            fw.art.solve(ra, &mut fw.y[0]);
            let mut my = [0.0; 3];
            for (c, col) in cw.m12.iter().enumerate() {
                for q in 0..3 {
                    my[q] += col[q] * fw.y[0][c];
                }
            }
            for i in 0..nb {
                sw.w[i] -= (0..3).map(|q| bp(q, i) * my[q]).sum::<f64>();
            }
        }
        cholesky_solve(&sw.zmz, k, &mut sw.w);
        udot[..nb].copy_from_slice(&sw.w[..nb]);
        if cable {
            let wd = sw.w[nb];
            for (u, rc) in udot[nb..].iter_mut().zip(&fw.y[1]) {
                *u = rc * wd;
            }
        } else {
            let ap: [f64; 3] =
                std::array::from_fn(|q| (0..nb).map(|j| bp(q, j) * sw.w[j]).sum::<f64>());
            for c in 0..n {
                udot[nb + c] = fw.y[0][c] - (0..3).map(|q| fw.y[1 + q][c] * ap[q]).sum::<f64>();
            }
        }
    }

    /// [`Coupled::solve_captured`] through the O(N) elimination (docs/theory.md §2.7), for
    /// the loads a run tracks at every step: the same accelerations, root wrench and cable
    /// torques, to rounding. The [`Eval`] returned has no dense `mass` and `mc` (0 × 0).
    pub fn solve_captured_fast(
        &self,
        y: &[f64],
        free: &[bool],
        captured: &[bool],
    ) -> (Eval, Solution) {
        WORKSPACE.with_borrow_mut(|(ws, sw)| {
            self.assemble_captured(y, captured, ws, false);
            let mut qc = std::mem::take(&mut sw.fast.qc);
            qc.clear();
            qc.extend(ws.force.iter().zip(&ws.bias).map(|(f, c)| f - c));
            let mut udot = vec![0.0; self.speeds()];
            self.eliminate_chain(ws, &qc, sw, free, &mut udot);
            let sol = self.loads_from_blocks(y, ws, &qc, udot, free);
            sw.fast.qc = qc;
            (ws.to_eval(self), sol)
        })
    }

    /// The root wrench and cable torques for accelerations u̇, from the blocks M₁₁ and M₁₂ of
    /// `ws` (no dense matrix): with
    /// acc = [A; Ω̇; α̈] of H, W = M₁₁ [A; Ω̇] + M₁₂ α̈ + b₁; an ideal cable's torques from the
    /// hinge rows of M u̇ − (Q − c) = M₂₁ B u̇_b + M₂₂ α̈ − (Q − c)_α (M₂₂ α̈ in O(N),
    /// [`articulated::mass_times`]).
    fn loads_from_blocks(
        &self,
        y: &[f64],
        ws: &Workspace,
        qc: &[f64],
        udot: Vec<f64>,
        free: &[bool],
    ) -> Solution {
        let (nb, n) = (self.rate_offset(), self.panels());
        let (cw, b) = (&ws.chain, &ws.b);
        let mut acc = vec![0.0; 6 + n];
        for i in 0..6 {
            acc[i] = ws.a_bias[i] + (0..nb).map(|j| b[i * nb + j] * udot[j]).sum::<f64>();
        }
        acc[6..].copy_from_slice(&udot[nb..]);
        let mut w: [f64; 6] =
            std::array::from_fn(|i| cw.bc[i] + (0..6).map(|k| cw.m11[i][k] * acc[k]).sum::<f64>());
        for (col, a) in cw.m12.iter().zip(&acc[6..]) {
            w[0] += col[0] * a;
            w[1] += col[1] * a;
            w[5] += col[2] * a;
        }
        let f = ws.frame.apply(Vec3::new(w[0], w[1], w[2]));
        let mo = ws.frame.apply(Vec3::new(w[3], w[4], w[5]));
        let cable_torque = match self.sync {
            Synchronisation::None => Vec::new(),
            Synchronisation::ElasticCable(kc) => self
                .cable_mismatch(self.view(y).alpha)
                .iter()
                .map(|x| kc * x)
                .collect(),
            Synchronisation::IdealCable => {
                if free.iter().any(|f| *f) {
                    // B_p u̇_b: H's in-plane acceleration less its bias.
                    let bu = [0, 1, 5].map(|i| acc[i] - ws.a_bias[i]);
                    let mut r = vec![0.0; n];
                    let (h, b, a) = (&cw.plane_hinges, &cw.bsum, &cw.asum);
                    articulated::mass_times(h, b, a, &acc[6..], &mut r);
                    for (i, ri) in r.iter_mut().enumerate() {
                        let col = cw.m12[i];
                        *ri += col[0] * bu[0] + col[1] * bu[1] + col[2] * bu[2] - qc[nb + i];
                    }
                    least_squares_multipliers(&self.cable_rows(), &r)
                } else {
                    vec![0.0; n.saturating_sub(1)]
                }
            }
        };
        Solution {
            udot,
            root_wrench: (f, mo),
            cable_torque,
            hinge_acc: acc,
        }
    }

    /// Plastic impact onto the admissible speeds of `free_after`: u⁺ = Z (ZᵀMZ)⁻¹ Zᵀ M u⁻.
    pub fn impact(&self, y: &[f64], free_after: &[bool]) -> Vec<f64> {
        let ev = self.evaluate(y);
        let np = self.positions();
        let u = &y[np..];
        let mu = mat_vec(&ev.mass, u);
        let mut sw = SolveWork::default();
        self.admissible_into(free_after, &mut sw.z);
        let mut out = vec![0.0; mu.len()];
        solve_admissible(|i, j| ev.mass[(i, j)], &mu, &mut sw, &mut out);
        out
    }

    /// Kinetic energy ½ uᵀ M u, J.
    pub fn kinetic_energy(&self, y: &[f64]) -> f64 {
        let ev = self.evaluate(y);
        let u = &y[self.positions()..];
        0.5 * dot(u, &mat_vec(&ev.mass, u))
    }

    /// Hinge spring energy, J.
    pub fn spring_energy(&self, y: &[f64]) -> f64 {
        let s = self.view(y);
        let hinge: f64 = self
            .chain
            .hinges
            .iter()
            .zip(s.alpha)
            .map(|(h, a)| h.energy(*a))
            .sum();
        let cable = match self.sync {
            Synchronisation::ElasticCable(kc) => self
                .cable_mismatch(s.alpha)
                .iter()
                .map(|x| 0.5 * kc * x * x)
                .sum(),
            _ => 0.0,
        };
        hinge + cable
    }

    /// Elastic energy of the base, ½ Σ ω_j² η_j², J.
    pub fn elastic_energy(&self, y: &[f64]) -> f64 {
        let s = self.view(y);
        self.base
            .omega
            .iter()
            .zip(s.eta)
            .map(|(w, e)| 0.5 * w * w * e * e)
            .sum()
    }

    /// Positions (hub components, from the hub's centre of mass) and inertial velocities (hub
    /// components) of the panel centres, and the panels' angular velocities.
    pub fn panel_motion(&self, y: &[f64], ev: &Eval) -> Vec<(Vec3, Vec3, Vec3)> {
        let s = self.view(y);
        let u = &y[self.positions()..];
        let nb = self.rate_offset();
        let vh: Vec<f64> = (0..6)
            .map(|i| (0..nb).map(|j| ev.b[(i, j)] * u[j]).sum())
            .collect();
        let (vhh, wh) = (
            Vec3::new(vh[0], vh[1], vh[2]),
            Vec3::new(vh[3], vh[4], vh[5]),
        );
        let rates = self.chain.phi_rates(s.alpha_dot);
        let z = Vec3::new(0.0, 0.0, 1.0);
        let mut vhinge = Vec3::ZERO;
        (0..self.panels())
            .map(|i| {
                let c = ev.centres[i];
                let r = c - ev.hinge_points[i];
                let vrel = vhinge + z.cross(r) * rates[i];
                vhinge = vhinge + z.cross(ev.hinge_points[i + 1] - ev.hinge_points[i]) * rates[i];
                let vel = vhh + wh.cross(c) + vrel;
                (
                    ev.hinge + ev.frame.apply(c),
                    ev.frame.apply(vel),
                    ev.frame.apply(wh + z * rates[i]),
                )
            })
            .collect()
    }

    /// Linear momentum (N·s) and angular momentum about the system's centre of mass (N·m·s),
    /// inertial components, and the centre of mass (inertial, m).
    pub fn momentum(&self, y: &[f64]) -> (Vec3, Vec3, Vec3) {
        // Kinematics only: the per-thread workspace, without the dense mass matrix.
        let ev = WORKSPACE.with_borrow_mut(|(ws, _)| {
            self.assemble_parts(y, ws, false);
            ws.to_eval(self)
        });
        let s = self.view(y);
        let inv = &self.base.invariants;
        let (pb, hb) = inv.momenta(&ev.at, s.v, s.w, s.eta_dot);
        let panels = self.panel_momenta(y, &ev, Vec3::ZERO);
        let (p, h) = (pb + panels.linear, hb + panels.angular);
        let first = ev.at.s + panels.first_moment;
        let mass = inv.mass + panels.mass;
        let a = attitude::matrix(s.quat);
        let pi = a.apply(p);
        let cm = s.r + a.apply(first * (1.0 / mass));
        // About the inertial origin: R × P + A h; about the centre of mass: minus c × P.
        let l = s.r.cross(pi) + a.apply(h) - cm.cross(pi);
        (pi, l, cm)
    }

    /// Linear momentum (N·s) and angular momentum about the hub's centre of mass (N·m·s),
    /// hub components.
    pub fn momentum_hub(&self, y: &[f64]) -> (Vec3, Vec3) {
        let ev = self.evaluate(y);
        let s = self.view(y);
        let (pb, hb) = self.base.invariants.momenta(&ev.at, s.v, s.w, s.eta_dot);
        let panels = self.panel_momenta(y, &ev, Vec3::ZERO);
        (pb + panels.linear, hb + panels.angular)
    }

    /// dy/dt for the hinges flagged free.
    pub fn rhs(&self, y: &[f64], free: &[bool], dy: &mut [f64]) {
        self.rhs_captured(y, free, &vec![false; self.panels()], dy);
    }

    /// The free hub's position and attitude quaternion, the first 7 positions (none with a
    /// held hub): nothing else in dy/dt depends on them (the dynamics are written in the hub
    /// frame, and nothing acts on the spacecraft from outside).
    pub fn kinematic_positions(&self) -> usize {
        if self.hub_dof() == 6 {
            7
        } else {
            0
        }
    }

    /// Their rates, ṙ = A(q) v and q̇ = ½ q ⊗ (0, ω), into `dy` (of length
    /// [`Coupled::kinematic_positions`]).
    pub fn hub_kinematics(&self, y: &[f64], dy: &mut [f64]) {
        if self.hub_dof() == 6 {
            let s = self.view(y);
            let rd = attitude::matrix(s.quat).apply(s.v);
            let qd = attitude::rate(s.quat, s.w);
            dy[..3].copy_from_slice(&rd.0);
            dy[3..7].copy_from_slice(&qd);
        }
    }

    /// dy/dt for the hinges flagged free, the compliant latches of those flagged `captured`
    /// acting.
    /// Evaluates into a workspace kept per thread: no allocation once it is sized.
    pub fn rhs_captured(&self, y: &[f64], free: &[bool], captured: &[bool], dy: &mut [f64]) {
        WORKSPACE.with_borrow_mut(|(ws, sw)| {
            self.assemble_configuration(y, ws, false);
            let factored = self.factor_chain(ws, sw, free);
            self.rhs_at_configuration(y, free, captured, factored, ws, sw, dy);
        });
    }

    /// [`Coupled::rhs_captured`] at y with some speeds changed, for each change of `changes`
    /// in turn ((component, value) pairs), into the rows of `out`: the configuration's work
    /// (the invariants at η, B, M_bb, the chain's mass blocks and the reduced matrix's
    /// factorisation, most of an evaluation's time) is done once for all of them. Each
    /// row equals [`Coupled::rhs_captured`] at its state, bit for bit. A change that moves a
    /// position (not only speeds) is evaluated on its own.
    pub fn rhs_captured_speeds(
        &self,
        y: &[f64],
        free: &[bool],
        captured: &[bool],
        changes: &[Change],
        out: &mut [Vec<f64>],
    ) {
        let np = self.positions();
        let mut yp = y.to_vec();
        WORKSPACE.with_borrow_mut(|(ws, sw)| {
            self.assemble_configuration(y, ws, false);
            let mut factored = self.factor_chain(ws, sw, free);
            for (change, dy) in changes.iter().zip(out.iter_mut()) {
                for &(c, v) in change {
                    yp[c] = v;
                }
                if change.iter().any(|&(c, _)| c < np) {
                    self.assemble_configuration(&yp, ws, false);
                    let f = self.factor_chain(ws, sw, free);
                    self.rhs_at_configuration(&yp, free, captured, f, ws, sw, dy);
                    // Back to y's configuration for the changes that follow.
                    self.assemble_configuration(y, ws, false);
                    factored = self.factor_chain(ws, sw, free);
                } else {
                    self.rhs_at_configuration(&yp, free, captured, factored, ws, sw, dy);
                }
                for &(c, _) in change {
                    yp[c] = y[c];
                }
            }
        });
    }

    /// dy/dt at y, whose configuration [`Coupled::assemble_configuration`] and
    /// [`Coupled::factor_chain`] left in `ws` and `sw` (`factored`: the factorisation
    /// succeeded; else the accelerations are NaN, which stops the run).
    #[allow(clippy::too_many_arguments)]
    fn rhs_at_configuration(
        &self,
        y: &[f64],
        free: &[bool],
        captured: &[bool],
        factored: bool,
        ws: &mut Workspace,
        sw: &mut SolveWork,
        dy: &mut [f64],
    ) {
        let np = self.positions();
        self.assemble_motion(y, ws);
        self.add_latch_moments(y, captured, ws);
        // Q − c, in place of Q.
        for (f, c) in ws.force.iter_mut().zip(&ws.bias) {
            *f -= c;
        }
        if factored {
            self.solve_chain(ws, &ws.force, sw, free, &mut dy[np..]);
        } else {
            dy[np..].fill(f64::NAN);
        }
        let s = self.view(y);
        let m = self.modes();
        let pe = self.kinematic_positions();
        self.hub_kinematics(y, &mut dy[..pe]);
        dy[pe..pe + m].copy_from_slice(s.eta_dot);
        for (i, r) in s.alpha_dot.iter().enumerate() {
            dy[pe + m + i] = *r;
        }
    }
}

impl Coupled {
    /// The stiff part of the Jacobian ∂f/∂y of [`Coupled::rhs_captured`] into `jac` (zeroed,
    /// positions + speeds square), for the implicit integrator (`super::rosenbrock`).
    ///
    /// f = [ẏ_pos; u̇] with u̇ = Z (ZᵀMZ)⁻¹ Zᵀ (Q − c). Kept exactly: the kinematic rows
    /// (η̇ and α̇ from the speeds, Ṙ = A(q) v, q̇ = ½ q ⊗ ω) and the applied forces' slopes
    /// through the admissible inverse at y,
    ///   ∂u̇/∂x ≈ Z (ZᵀMZ)⁻¹ Zᵀ ∂Q/∂x,
    /// with ∂Q/∂η = −diag(ω_j²) and ∂Q/∂η̇ = −diag(2 ζ ω_j) (the base's stiffness and modal
    /// damping, up to kHz: the stiff block), the hinge springs, dampers and regularised
    /// friction, the elastic cable and the captured latches' k_L and c_L. Left out: the
    /// configuration dependence of M and c, ∂(M⁻¹)/∂q (Q − c), and ∂c/∂u — terms of the
    /// order of the slow motion's rates (the panels' and the hub's), which a step set by that
    /// motion resolves; the stepper's error control sees what leaving them out costs.
    pub fn stiff_jacobian(
        &self,
        y: &[f64],
        free: &[bool],
        captured: &[bool],
        jac: &mut faer::Mat<f64>,
    ) {
        let (np, ns) = (self.positions(), self.speeds());
        let (h, m, n) = (self.hub_dof(), self.modes(), self.panels());
        let nb = h + m;
        let s = self.view(y);
        let pe = if h == 6 { 7 } else { 0 };
        // Kinematic rows.
        if h == 6 {
            let a = attitude::matrix(s.quat);
            for i in 0..3 {
                for j in 0..3 {
                    jac[(i, np + j)] = a.get(i, j);
                }
            }
            // Ṙ = A(q) v: ∂/∂q by differences of a 3 × 4 map (cheap, and not stiff).
            let rd = a.apply(s.v);
            for c in 0..4 {
                let mut q = s.quat;
                let d = 1e-7;
                q[c] += d;
                let r1 = attitude::matrix(q).apply(s.v);
                for i in 0..3 {
                    jac[(i, 3 + c)] = (r1.get(i) - rd.get(i)) / d;
                }
            }
            // q̇ = ½ q ⊗ (0, ω): linear in q and in ω.
            for c in 0..4 {
                let mut e = [0.0; 4];
                e[c] = 1.0;
                let col = attitude::rate(e, s.w);
                for i in 0..4 {
                    jac[(3 + i, 3 + c)] = col[i];
                }
            }
            for c in 0..3 {
                let mut e = Vec3::ZERO;
                e.0[c] = 1.0;
                let col = attitude::rate(s.quat, e);
                for i in 0..4 {
                    jac[(3 + i, np + 3 + c)] = col[i];
                }
            }
        }
        for k in 0..m + n {
            jac[(pe + k, np + h + k)] = 1.0;
        }
        // ∂Q/∂y as sparse columns: (column of y, [(row of Q, value)]).
        let mut cols: Vec<(usize, Vec<(usize, f64)>)> = Vec::with_capacity(2 * (m + n));
        for k in 0..m {
            let w = self.base.omega[k];
            cols.push((pe + k, vec![(h + k, -w * w)]));
            cols.push((np + h + k, vec![(h + k, -self.modal_damping(k))]));
        }
        for (i, hg) in self.chain.hinges.iter().enumerate() {
            let (mut ka, mut kr) = hg.moment_slopes(s.alpha_dot[i]);
            if let Some(l) = &self.latch {
                if captured.get(i).copied().unwrap_or(false) {
                    ka -= l.stiffness[i];
                    kr -= l.damping[i];
                }
            }
            let mut col = vec![(nb + i, ka)];
            if let Synchronisation::ElasticCable(kc) = self.sync {
                // Q_α = −k_c Cᵀ C (α − α(0)): column i of −k_c CᵀC.
                let rows = self.cable_rows();
                for r in 0..n {
                    let v: f64 = rows.iter().map(|c| c[r] * c[i]).sum();
                    if r == i {
                        col[0].1 -= kc * v;
                    } else if v != 0.0 {
                        col.push((nb + r, -kc * v));
                    }
                }
            }
            cols.push((pe + m + i, col));
            cols.push((np + nb + i, vec![(nb + i, kr)]));
        }
        WORKSPACE.with_borrow_mut(|(ws, sw)| {
            self.assemble(y, ws);
            self.admissible_into(free, &mut sw.z);
            let mass = &ws.mass;
            let ok = factor_admissible(|i, j| mass[i * ns + j], sw);
            let mut b = vec![0.0; ns];
            let mut u = vec![0.0; ns];
            for (c, entries) in &cols {
                if entries.iter().all(|&(_, v)| v == 0.0) {
                    continue;
                }
                b.fill(0.0);
                for &(r, v) in entries {
                    b[r] = v;
                }
                u.fill(if ok { 0.0 } else { f64::NAN });
                if ok {
                    solve_factored(&b, sw, &mut u);
                }
                for (r, ur) in u.iter().enumerate() {
                    jac[(np + r, *c)] = *ur;
                }
            }
        });
    }

    /// The base's modal damping coefficient of mode k, 2 ζ ω_k (1/s; zero when undamped).
    fn modal_damping(&self, k: usize) -> f64 {
        2.0 * self.base_damping_ratio * self.base.omega[k]
    }
}

thread_local! {
    /// [`Coupled::rhs_captured`]'s buffers (resized whenever the model changes).
    static WORKSPACE: RefCell<(Workspace, SolveWork)> = RefCell::new(Default::default());
}

#[derive(Default)]
struct PanelMomenta {
    linear: Vec3,
    angular: Vec3,
    first_moment: Vec3,
    mass: f64,
}

/// Clears `v` and fills it with `n` copies of `x` (keeps its allocation).
fn refill<T: Clone>(v: &mut Vec<T>, n: usize, x: T) {
    v.clear();
    v.resize(n, x);
}

/// The buffers of one evaluation ([`Coupled::evaluate`]'s quantities), reused from call to
/// call: once sized for a model, an evaluation allocates nothing. Matrices are flat and
/// row-major.
#[derive(Debug, Default)]
struct Workspace {
    /// Base invariants at η.
    at: AtShape,
    /// L̇ as columns.
    l_dot: Vec<Vec3>,
    /// Hinge frame axes (hub components) and hinge point.
    frame: Mat3,
    hinge: Vec3,
    /// The hinge frame's small rotation θ(η) and its left Jacobian.
    theta: Vec3,
    jl: Mat3,
    /// B (6 × nb).
    b: Vec<f64>,
    /// [A; Ω̇] of H for zero accelerations.
    a_bias: [f64; 6],
    /// The chain's blocks.
    chain: ChainWork,
    /// M (ns × ns, only when asked for), its base block M_bb (nb × nb), c and Q.
    mass: Vec<f64>,
    mbb: Vec<f64>,
    bias: Vec<f64>,
    force: Vec<f64>,
    /// The columns of B and of M₁₁ B (nb of each), and b_c + M_c [a_b; 0].
    bt: Vec<[f64; 6]>,
    mbt: Vec<[f64; 6]>,
    cb: Vec<f64>,
}

impl Workspace {
    /// The evaluation as an [`Eval`].
    fn to_eval(&self, c: &Coupled) -> Eval {
        let (ns, nb, nc) = (c.speeds(), c.rate_offset(), 6 + c.panels());
        let cw = &self.chain;
        // Empty when the evaluation did without the dense blocks.
        let dense = |v: &[f64], n: usize| {
            if v.len() == n * n {
                Mat::from_fn(n, n, |i, j| v[i * n + j])
            } else {
                Mat::zeros(0, 0)
            }
        };
        Eval {
            mass: dense(&self.mass, ns),
            bias: self.bias.clone(),
            force: self.force.clone(),
            at: self.at.clone(),
            frame: self.frame,
            hinge: self.hinge,
            b: Mat::from_fn(6, nb, |i, j| self.b[i * nb + j]),
            a_bias: self.a_bias,
            mc: dense(&cw.mc, nc),
            bc: cw.bc.clone(),
            centres: cw.centres.clone(),
            hinge_points: cw.hinges.clone(),
            phi: cw.phi.clone(),
        }
    }
}

/// The chain's quantities at one state (hinge plane, hinge components).
#[derive(Debug, Default)]
struct ChainWork {
    /// Panel angles φ_i and rates φ̇_i.
    phi: Vec<f64>,
    rates: Vec<f64>,
    /// Panel centres and hinge points (N + 1, the tip last).
    centres: Vec<Vec3>,
    hinges: Vec<Vec3>,
    /// Panel inertia tensors, centre velocities and accelerations relative to H.
    inertia: Vec<Mat3>,
    cdot: Vec<Vec3>,
    cdd: Vec<Vec3>,
    /// M_c ((6 + N)², only when asked for) and b_c.
    mc: Vec<f64>,
    bc: Vec<f64>,
    /// M_c's upper left 6 × 6 block M₁₁ (the chain as one rigid body at H).
    m11: [[f64; 6]; 6],
    /// Column 6 + l of M_c (rows 0, 1 and 5; its other rows are zero): hinge l's coupling.
    m12: Vec<[f64; 3]>,
    /// Outboard sums of the hinges (see [`ChainWork::outboard_sums`]) and the hinge points
    /// H_l in the hinge plane, the form [`articulated::mass_times`] takes them in.
    bsum: Vec<P2>,
    asum: Vec<f64>,
    plane_hinges: Vec<P2>,
}

impl ChainWork {
    /// Panel angles, centres and hinge points: [`Chain::configuration`] for the held hub of
    /// the coupled chain, in the same arithmetic, without allocating.
    fn configure(&mut self, ch: &Chain, alpha: &[f64]) {
        debug_assert_eq!(ch.hub_dof(), 0);
        let theta: f64 = 0.0;
        let (s, c) = theta.sin_cos();
        let r = [
            c * ch.root[0] - s * ch.root[1],
            s * ch.root[0] + c * ch.root[1],
        ];
        let mut hp = [0.0 + r[0], 0.0 + r[1]];
        self.phi.clear();
        self.centres.clear();
        self.hinges.clear();
        self.hinges.push(Vec3::new(hp[0], hp[1], 0.0));
        for (i, p) in ch.panels.iter().enumerate() {
            let a = alpha[i];
            let f = if i == 0 {
                theta + PI / 2.0 - a
            } else {
                let s_i = if i % 2 == 1 { -1.0 } else { 1.0 };
                self.phi[i - 1] + s_i * (PI - a)
            };
            self.phi.push(f);
            let ev = [f.cos(), f.sin()];
            self.centres.push(Vec3::new(
                hp[0] + 0.5 * p.length * ev[0],
                hp[1] + 0.5 * p.length * ev[1],
                0.0,
            ));
            hp = [hp[0] + p.length * ev[0], hp[1] + p.length * ev[1]];
            self.hinges.push(Vec3::new(hp[0], hp[1], 0.0));
        }
    }

    /// The panels' angle rates φ̇_i from the opening rates: [`Chain::phi_rates`] for the held
    /// hub, in the same arithmetic, without allocating.
    fn rates_of(&mut self, alpha_dot: &[f64]) {
        self.rates.clear();
        let mut w = 0.0;
        for (i, a) in alpha_dot.iter().enumerate() {
            let d = if i % 2 == 0 { -1.0 } else { 1.0 };
            w += d * a;
            self.rates.push(w);
        }
    }

    /// The outboard sums about hinge l that the chain's mass matrix over α̈ (M_c's lower
    /// right block, [`Chain::mass_matrix`] for the held hub, in the same arithmetic) is made
    /// of: B_l = Σ_{i≥l} m_i (C_i − H_l), A_l = Σ m_i |C_i − H_l|² + I_i (tip to root by the
    /// parallel-axis shift, with the outboard mass S0_l = Σ_{i≥l} m_i); for k ≤ l
    ///   M_{α_k α_l} = d_k d_l [A_l + (H_l − H_k)·B_l].
    fn outboard_sums(&mut self, ch: &Chain) {
        let nn = ch.len();
        let p2 = |v: Vec3| [v.get(0), v.get(1)];
        let sub = |a: P2, b: P2| [a[0] - b[0], a[1] - b[1]];
        let dot = |a: P2, b: P2| a[0] * b[0] + a[1] * b[1];
        self.plane_hinges.clear();
        self.plane_hinges
            .extend(self.hinges[..nn].iter().map(|h| p2(*h)));
        refill(&mut self.bsum, nn, [0.0; 2]);
        refill(&mut self.asum, nn, 0.0);
        let (mut s0n, mut bn, mut an) = (0.0, [0.0; 2], 0.0);
        for l in (0..nn).rev() {
            let p = &ch.panels[l];
            let dl = sub(p2(self.hinges[l + 1]), p2(self.hinges[l]));
            let c = sub(p2(self.centres[l]), p2(self.hinges[l]));
            an += 2.0 * dot(dl, bn) + s0n * dot(dl, dl) + p.mass * dot(c, c) + p.inertia;
            bn = [
                bn[0] + s0n * dl[0] + p.mass * c[0],
                bn[1] + s0n * dl[1] + p.mass * c[1],
            ];
            s0n += p.mass;
            self.bsum[l] = bn;
            self.asum[l] = an;
        }
    }

    /// The dense M_c ((6 + N)², row-major) from M₁₁, the coupling columns and the outboard
    /// sums (O(N²): [`Coupled::evaluate`]'s users; the right-hand side does without).
    fn dense_blocks(&mut self) {
        let nn = self.m12.len();
        let nc = 6 + nn;
        let p2 = |v: Vec3| [v.get(0), v.get(1)];
        let sub = |a: P2, b: P2| [a[0] - b[0], a[1] - b[1]];
        let dot = |a: P2, b: P2| a[0] * b[0] + a[1] * b[1];
        let d = |k: usize| if k % 2 == 0 { -1.0 } else { 1.0 };
        refill(&mut self.mc, nc * nc, 0.0);
        for r in 0..6 {
            self.mc[r * nc..r * nc + 6].copy_from_slice(&self.m11[r]);
        }
        for (i, [fx, fy, mz]) in self.m12.iter().copied().enumerate() {
            for (r, v) in [(0, fx), (1, fy), (5, mz)] {
                self.mc[r * nc + 6 + i] = v;
                self.mc[(6 + i) * nc + r] = v;
            }
        }
        for l in 0..nn {
            let hl = p2(self.hinges[l]);
            for k in 0..=l {
                let v =
                    d(k) * d(l) * (self.asum[l] + dot(sub(hl, p2(self.hinges[k])), self.bsum[l]));
                self.mc[(6 + k) * nc + 6 + l] = v;
                self.mc[(6 + l) * nc + 6 + k] = v;
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn mat_vec(m: &Mat<f64>, x: &[f64]) -> Vec<f64> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)] * x[j]).sum())
        .collect()
}

/// A matrix's columns as lists of (row, value), in one flat buffer.
#[derive(Debug, Default)]
struct SparseColumns {
    /// Start of column j in `entries` (and the end of the last column).
    start: Vec<usize>,
    entries: Vec<(usize, f64)>,
}

impl SparseColumns {
    fn clear(&mut self) {
        self.start.clear();
        self.start.push(0);
        self.entries.clear();
    }

    fn push_column(&mut self, col: impl IntoIterator<Item = (usize, f64)>) {
        self.entries.extend(col);
        self.start.push(self.entries.len());
    }

    fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    fn column(&self, j: usize) -> &[(usize, f64)] {
        &self.entries[self.start[j]..self.start[j + 1]]
    }
}

/// The admissible basis and the reduced system's buffers.
#[derive(Debug, Default)]
struct SolveWork {
    /// Z.
    z: SparseColumns,
    /// ZᵀMZ (k × k, row-major), overwritten by its Cholesky factor.
    zmz: Vec<f64>,
    /// Zᵀb, overwritten by ẇ.
    w: Vec<f64>,
    /// The O(N) elimination's buffers ([`Coupled::eliminate_chain`]).
    fast: FastWork,
}

/// [`Coupled::eliminate_chain`]'s buffers.
#[derive(Debug, Default)]
struct FastWork {
    art: articulated::Articulated,
    panels: Vec<articulated::PlanarPanel>,
    tau: Vec<f64>,
    /// M₂₂⁻¹ (Q − c)_α and M₂₂⁻¹ M₂₁'s three columns (or M₂₂ r and r with a cable).
    y: [Vec<f64>; 4],
    /// Q − c ([`Coupled::solve_captured_fast`]).
    qc: Vec<f64>,
}

/// u = Z (ZᵀMZ)⁻¹ Zᵀ b into `u`, with M given by its entries `m(i, j)` and Z in `work.z`.
/// M is positive definite for positive masses; a failed factorisation (a non-finite state)
/// gives NaN, which stops the run.
fn solve_admissible(
    m: impl Fn(usize, usize) -> f64,
    b: &[f64],
    work: &mut SolveWork,
    u: &mut [f64],
) {
    u.fill(0.0);
    if work.z.len() == 0 {
        return;
    }
    if !factor_admissible(m, work) {
        u.fill(f64::NAN);
        return;
    }
    solve_factored(b, work, u);
}

/// ZᵀMZ (M by its entries `m(i, j)`, Z in `work.z`) and its Cholesky factor into
/// `work.zmz`; false when it is not positive definite.
fn factor_admissible(m: impl Fn(usize, usize) -> f64, work: &mut SolveWork) -> bool {
    let z = &work.z;
    let k = z.len();
    // Z is sparse (unit columns for the hub and base speeds and the free hinges, one cable
    // column): ZᵀMZ and Zᵀb by loops over its non-zeros, the lower triangle of ZᵀMZ only
    // (the factorisation reads no more).
    refill(&mut work.zmz, k * k, 0.0);
    for a in 0..k {
        let col_a = z.column(a);
        for c in 0..=a {
            let col_c = z.column(c);
            let mut v = 0.0;
            for &(i, za) in col_a {
                let mut t = 0.0;
                for &(j, zc) in col_c {
                    t += m(i, j) * zc;
                }
                v += za * t;
            }
            work.zmz[a * k + c] = v;
        }
    }
    cholesky_in_place(&mut work.zmz, k)
}

/// u += Z (ZᵀMZ)⁻¹ Zᵀ b with the factor of [`factor_admissible`] in `work.zmz`.
fn solve_factored(b: &[f64], work: &mut SolveWork, u: &mut [f64]) {
    let z = &work.z;
    let k = z.len();
    refill(&mut work.w, k, 0.0);
    for (a, wa) in work.w.iter_mut().enumerate() {
        *wa = z.column(a).iter().map(|&(j, zj)| zj * b[j]).sum::<f64>();
    }
    cholesky_solve(&work.zmz, k, &mut work.w);
    for (j, wj) in work.w.iter().enumerate() {
        for &(i, zij) in z.column(j) {
            u[i] += zij * wj;
        }
    }
}

/// Cholesky factorisation A = L Lᵀ of the symmetric positive definite k × k matrix `a`
/// (row-major; the lower triangle is read), L written over the lower triangle:
///   L_jj = √(A_jj − Σ_{p<j} L_jp²),   L_ij = (A_ij − Σ_{p<j} L_ip L_jp) / L_jj  (i > j).
/// False if a pivot is not positive (or not finite). Hand-written: the systems are small
/// (tens of speeds), where a library's blocking and dispatch cost more than the arithmetic.
fn cholesky_in_place(a: &mut [f64], k: usize) -> bool {
    for j in 0..k {
        let row_j = &a[j * k..j * k + j];
        let d = a[j * k + j] - dot4(row_j, row_j);
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        let ljj = d.sqrt();
        a[j * k + j] = ljj;
        for i in j + 1..k {
            let (upper, lower) = a.split_at_mut(i * k);
            let s = dot4(&lower[..j], &upper[j * k..j * k + j]);
            lower[j] = (lower[j] - s) / ljj;
        }
    }
    true
}

/// Solves L Lᵀ x = b in place (L from [`cholesky_in_place`]).
fn cholesky_solve(l: &[f64], k: usize, x: &mut [f64]) {
    for i in 0..k {
        x[i] = (x[i] - dot4(&l[i * k..i * k + i], &x[..i])) / l[i * k + i];
    }
    for i in (0..k).rev() {
        let mut v = x[i];
        for p in i + 1..k {
            v -= l[p * k + i] * x[p];
        }
        x[i] = v / l[i * k + i];
    }
}

/// λ = (CCᵀ)⁻¹ C r.
fn least_squares_multipliers(c: &[Vec<f64>], r: &[f64]) -> Vec<f64> {
    let k = c.len();
    if k == 0 {
        return Vec::new();
    }
    let cct = Mat::from_fn(k, k, |i, j| dot(&c[i], &c[j]));
    let mut rhs = Mat::from_fn(k, 1, |i, _| dot(&c[i], r));
    match cct.llt(Side::Lower) {
        Ok(llt) => {
            faer::linalg::solvers::Solve::solve_in_place(&llt, rhs.as_mut());
            (0..k).map(|i| rhs[(i, 0)]).collect()
        }
        Err(_) => vec![f64::NAN; k],
    }
}

/// One latch of a coupled run.
#[derive(Debug, Clone, PartialEq)]
pub struct CoupledLatch {
    /// The hinge that reached its latch angle (1-based).
    pub hinge: usize,
    /// Time, s.
    pub time: f64,
    /// Opening rates before and after, rad/s.
    pub rates_before: Vec<f64>,
    /// Opening rates after, rad/s.
    pub rates_after: Vec<f64>,
    /// Kinetic energy before and after, J.
    pub energy_before: f64,
    /// Kinetic energy after, J.
    pub energy_after: f64,
    /// ½ Δuᵀ M Δu, J (equal to the loss for a plastic impact).
    pub loss_metric: f64,
    /// Impulse the base receives at the root hinge, hub components: force (N·s) and moment
    /// about the hinge point (N·m·s). Truncation-dependent on an elastic base (docs/theory.md §2).
    pub base_impulse: (Vec3, Vec3),
    /// The state just before the impact.
    pub state_before: Vec<f64>,
}

/// The result of a coupled run.
#[derive(Debug, Clone, PartialEq)]
pub struct CoupledRun {
    /// Latches in time order.
    pub latches: Vec<CoupledLatch>,
    /// Time the run ended, s.
    pub final_time: f64,
    /// The final state.
    pub final_state: Vec<f64>,
    /// Every hinge locked.
    pub all_latched: bool,
    /// Right-hand-side evaluations.
    pub steps: usize,
}

impl Coupled {
    /// The chain's linear and angular momentum about the root hinge point (hub components).
    pub(crate) fn chain_momentum(&self, y: &[f64]) -> (Vec3, Vec3) {
        let ev = self.evaluate(y);
        let m = self.panel_momenta(y, &ev, ev.hinge);
        (m.linear, m.angular)
    }

    /// The panels' momenta (hub components): linear, angular about `about` (from the hub's
    /// centre of mass), and their first moment about the hub's centre of mass and mass.
    fn panel_momenta(&self, y: &[f64], ev: &Eval, about: Vec3) -> PanelMomenta {
        let mut out = PanelMomenta::default();
        for (i, (r, v, w)) in self.panel_motion(y, ev).into_iter().enumerate() {
            let mi = self.chain.panels[i].mass;
            // E I_H Eᵀ: the tensor in hub components.
            let ii = ev
                .frame
                .matmul(self.panel_tensor(i, ev.phi[i]))
                .matmul(ev.frame.transpose());
            out.linear = out.linear + v * mi;
            out.angular = out.angular + (r - about).cross(v * mi) + ii.apply(w);
            out.first_moment = out.first_moment + r * mi;
            out.mass += mi;
        }
        out
    }

    /// Runs from release until every hinge has latched or `end_time`, with sequential or
    /// simultaneous latching, at relative tolerance `tol`, with the explicit integrator (it
    /// conserves energy to the tolerance; the latches only: the samples, loads and warnings
    /// are [`super::simulate_coupled`]'s).
    pub fn simulate(&self, simultaneous: bool, end_time: f64, tol: f64) -> CoupledRun {
        let settings = super::RunSettings {
            latching: if simultaneous {
                super::Latching::Simultaneous
            } else {
                super::Latching::Sequential
            },
            end_time,
            output_rate: 1.0 / end_time,
            tolerance: tol,
            integrator: super::Integrator::Explicit,
            record_samples: true,
            schedule: super::run::Schedule::default(),
            settle: self
                .latch
                .as_ref()
                .map(|l| super::Settle::decayed(&self.chain, &l.stiffness, self.sync)),
        };
        let r = super::run::run(self, &settings, super::MAX_STEPS);
        let latches = r
            .latches
            .into_iter()
            .map(|e| {
                let state_before: Vec<f64> = e.q.iter().chain(&e.qd_before).copied().collect();
                let du: Vec<f64> = e
                    .qd_before
                    .iter()
                    .zip(&e.qd_after)
                    .map(|(a, b)| a - b)
                    .collect();
                let mass = self.evaluate(&state_before).mass;
                let (f, m) = e.base_impulse.unwrap_or_default();
                CoupledLatch {
                    hinge: e.hinge,
                    time: e.time,
                    rates_before: e.rates_before,
                    rates_after: e.rates_after,
                    energy_before: e.energy_before,
                    energy_after: e.energy_after,
                    loss_metric: 0.5 * dot(&du, &mat_vec(&mass, &du)),
                    base_impulse: (Vec3(f), Vec3(m)),
                    state_before,
                }
            })
            .collect();
        CoupledRun {
            latches,
            final_time: r.final_time,
            final_state: r.final_q.iter().chain(&r.final_qd).copied().collect(),
            all_latched: r.all_latched,
            steps: r.evaluations,
        }
    }
}
