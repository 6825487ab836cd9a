//! The deploying array on the flexible, free-floating base as one system (MODEL.md §3.2).
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

use super::attitude::{self, Quaternion};
use super::base::BaseModel;
use super::chain::Chain;
use super::inertia::{combine, AtShape};
use crate::math::{Mat3, Vec3};
use crate::structure::HubMotion;
use faer::{Mat, Side};

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

/// A compliant latch per hinge (MODEL.md §3.2, "Compliant latch"): once hinge j has been
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
    /// System mass matrix over the speeds.
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
    /// The chain's block matrix M_c ((6 + N)²) and bias b_c.
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
    /// hinges.
    pub fn initial_state(&self) -> Vec<f64> {
        let (np, ns) = (self.positions(), self.speeds());
        let mut y = vec![0.0; np + ns];
        if self.hub_dof() == 6 {
            y[3] = 1.0;
        }
        let (a, r) = (self.alpha_offset(), np + self.rate_offset());
        for (i, h) in self.chain.hinges.iter().enumerate() {
            y[a + i] = h.initial_angle;
            y[r + i] = h.initial_rate;
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

    /// The cable's loop matrix C ((N − 1) × N).
    fn cable_rows(&self) -> Vec<Vec<f64>> {
        let n = self.panels();
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
        let (nb, n) = (self.rate_offset(), self.panels());
        let cols: Vec<Vec<f64>> = if self.sync == Synchronisation::IdealCable {
            if free.iter().any(|f| *f) {
                let mut c = vec![2.0; n];
                c[0] = 1.0;
                vec![c]
            } else {
                Vec::new()
            }
        } else {
            (0..n)
                .filter(|&i| free[i])
                .map(|i| {
                    let mut c = vec![0.0; n];
                    c[i] = 1.0;
                    c
                })
                .collect()
        };
        let mut z = Mat::zeros(nb + n, nb + cols.len());
        for i in 0..nb {
            z[(i, i)] = 1.0;
        }
        for (j, c) in cols.iter().enumerate() {
            for i in 0..n {
                z[(nb + i, nb + j)] = c[i];
            }
        }
        z
    }

    /// Kinematics, mass matrix, velocity terms and applied forces at a state.
    pub fn evaluate(&self, y: &[f64]) -> Eval {
        let s = self.view(y);
        let base = &self.base;
        let inv = &base.invariants;
        let (h, m, n) = (self.hub_dof(), self.modes(), self.panels());
        let nb = h + m;
        let at = inv.at(s.eta);
        // Hinge frame.
        let theta = combine(&base.hinge_rotations, s.eta);
        let theta_dot = combine(&base.hinge_rotations, s.eta_dot);
        let e0 = from_cols(base.frame);
        let frame = attitude::exp(theta).matmul(e0);
        let jl = attitude::left_jacobian(theta);
        let hinge = base.hinge + combine(&base.hinge_shapes, s.eta);
        let p_dot = combine(&base.hinge_shapes, s.eta_dot);
        let omega_rel = jl.apply(theta_dot);
        let v_h = s.v + s.w.cross(hinge) + p_dot;
        let a_h = s.w.cross(p_dot) + s.w.cross(v_h);
        let wd_h = attitude::left_jacobian_rate(theta, theta_dot) + s.w.cross(omega_rel);
        let et = frame.transpose();
        // B: base speeds → [V_H; Ω_H], hinge components.
        let mut b = Mat::zeros(6, nb);
        if h == 6 {
            let ph = cross_mat(hinge);
            for i in 0..3 {
                for j in 0..3 {
                    b[(i, j)] = et.get(i, j);
                    // −E ᵀ p̃ (ω ↦ ω × p = −p̃ ω).
                    b[(i, 3 + j)] = -(0..3).map(|k| et.get(i, k) * ph.get(k, j)).sum::<f64>();
                    b[(3 + i, 3 + j)] = et.get(i, j);
                }
            }
        }
        for k in 0..m {
            let pv = et.apply(base.hinge_shapes[k]);
            let rv = et.apply(jl.apply(base.hinge_rotations[k]));
            for i in 0..3 {
                b[(i, h + k)] = pv.get(i);
                b[(3 + i, h + k)] = rv.get(i);
            }
        }
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
        let chain = self.chain_blocks(s.alpha, s.alpha_dot, omega_h);
        // Assemble.
        let ns = nb + n;
        let mut mass = Mat::zeros(ns, ns);
        let mut bias = vec![0.0; ns];
        self.base_terms(&s, &at, &mut mass, &mut bias);
        let mc = &chain.mc;
        // [B 0; 0 I]ᵀ M_c [B 0; 0 I] by blocks: Bᵀ M₁₁ B, Bᵀ M₁₂, M₂₁ B, M₂₂ (loops: the
        // blocks are small, and a general product's set-up costs more than the arithmetic).
        let mut mb = vec![0.0; (6 + n) * nb]; // M_c[:, 0..6] B, row-major (6 + n) × nb
        for i in 0..6 + n {
            for j in 0..nb {
                mb[i * nb + j] = (0..6).map(|k| mc[(i, k)] * b[(k, j)]).sum::<f64>();
            }
        }
        for i in 0..nb {
            for j in 0..nb {
                mass[(i, j)] += (0..6).map(|k| b[(k, i)] * mb[k * nb + j]).sum::<f64>();
            }
            for c in 0..n {
                // Bᵀ M₁₂ = (M₂₁ B)ᵀ.
                let v = mb[(6 + c) * nb + i];
                mass[(i, nb + c)] += v;
                mass[(nb + c, i)] += v;
            }
        }
        for r in 0..n {
            for c in 0..n {
                mass[(nb + r, nb + c)] += mc[(6 + r, 6 + c)];
            }
        }
        // Chain bias with H's bias acceleration: b_c + M_c [a_b; 0], mapped by [B 0; 0 I]ᵀ.
        let mut cb = chain.bc.clone();
        for i in 0..6 + n {
            cb[i] += (0..6).map(|k| mc[(i, k)] * a_bias[k]).sum::<f64>();
        }
        for j in 0..nb {
            bias[j] += (0..6).map(|i| b[(i, j)] * cb[i]).sum::<f64>();
        }
        for c in 0..n {
            bias[nb + c] += cb[6 + c];
        }
        // Applied forces.
        let mut force = vec![0.0; ns];
        for k in 0..m {
            force[h + k] = -base.omega[k].powi(2) * s.eta[k];
        }
        for (i, hg) in self.chain.hinges.iter().enumerate() {
            force[nb + i] = hg.moment(s.alpha[i], s.alpha_dot[i]);
        }
        if let Synchronisation::ElasticCable(kc) = self.sync {
            for (row, mis) in self.cable_rows().iter().zip(self.cable_mismatch(s.alpha)) {
                for i in 0..n {
                    force[nb + i] -= kc * mis * row[i];
                }
            }
        }
        Eval {
            mass,
            bias,
            force,
            at,
            frame,
            hinge,
            b,
            a_bias,
            mc: chain.mc,
            bc: chain.bc,
            centres: chain.centres,
            hinge_points: chain.hinges,
            phi: chain.phi,
        }
    }

    /// C (α − α(0)) per cable loop, rad.
    pub fn cable_mismatch(&self, alpha: &[f64]) -> Vec<f64> {
        let d: Vec<f64> = alpha
            .iter()
            .zip(&self.chain.hinges)
            .map(|(a, h)| a - h.initial_angle)
            .collect();
        self.cable_rows()
            .iter()
            .map(|r| r.iter().zip(&d).map(|(c, x)| c * x).sum())
            .collect()
    }

    /// The base's own mass matrix and velocity terms over [v, ω, η̇] (see [`super::inertia`]).
    fn base_terms(&self, s: &View<'_>, at: &AtShape, mass: &mut Mat<f64>, bias: &mut [f64]) {
        let inv = &self.base.invariants;
        let (h, m) = (self.hub_dof(), self.modes());
        for a in 0..m {
            for c in 0..m {
                mass[(h + a, h + c)] += inv.mee[(a, c)];
            }
        }
        if h == 0 {
            return;
        }
        let st = at.s.skew();
        for i in 0..3 {
            mass[(i, i)] += inv.mass;
            for j in 0..3 {
                mass[(i, 3 + j)] -= st.get(i, j);
                mass[(3 + i, j)] += st.get(i, j);
                mass[(3 + i, 3 + j)] += at.j.get(i, j);
            }
        }
        for k in 0..m {
            for i in 0..3 {
                mass[(i, 6 + k)] += inv.s[k].get(i);
                mass[(6 + k, i)] += inv.s[k].get(i);
                mass[(3 + i, 6 + k)] += at.l[k].get(i);
                mass[(6 + k, 3 + i)] += at.l[k].get(i);
            }
        }
        let (v, w) = (s.v, s.w);
        let (p, hh) = inv.momenta(at, v, w, s.eta_dot);
        let s_dot = inv.s_rate(s.eta_dot);
        let j_dot = at
            .dj
            .iter()
            .zip(s.eta_dot)
            .fold(Mat3::ZERO, |acc, (d, e)| acc + *d * *e);
        let l_dot = inv.l_rate(s.eta_dot);
        let cv = w.cross(s_dot) + w.cross(p);
        let cw =
            s_dot.cross(v) + j_dot.apply(w) + combine(&l_dot, s.eta_dot) + w.cross(hh) + v.cross(p);
        for i in 0..3 {
            bias[i] += cv.get(i);
            bias[3 + i] += cw.get(i);
        }
        for k in 0..m {
            let dt_deta = v.dot(w.cross(inv.s[k]))
                + 0.5 * w.dot(at.dj[k].apply(w))
                + (0..m)
                    .map(|c| w.dot(inv.l1[k * m + c]) * s.eta_dot[c])
                    .sum::<f64>();
            bias[6 + k] += l_dot[k].dot(w) - dt_deta;
        }
    }

    /// The chain's block matrix M_c over [A; Ω̇; α̈] and its bias b_c for H's angular
    /// velocity `omega` (hinge components), all in hinge components.
    fn chain_blocks(&self, alpha: &[f64], alpha_dot: &[f64], omega: Vec3) -> ChainBlocks {
        let ch = &self.chain;
        let n = ch.len();
        let cfg = ch.configuration(alpha);
        let rates = ch.phi_rates(alpha_dot);
        let z = Vec3::new(0.0, 0.0, 1.0);
        let p3 = |p: [f64; 2]| Vec3::new(p[0], p[1], 0.0);
        let centres: Vec<Vec3> = cfg.centres.iter().map(|c| p3(*c)).collect();
        let hinges: Vec<Vec3> = cfg.hinges.iter().map(|c| p3(*c)).collect();
        let d = |k: usize| if k % 2 == 0 { -1.0 } else { 1.0 };
        // Panel inertia tensors in hinge components, relative velocities and accelerations.
        let mut inertia = Vec::with_capacity(n);
        let mut cdot = Vec::with_capacity(n);
        let mut cdd = Vec::with_capacity(n);
        let (mut vh, mut ah) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            inertia.push(self.panel_tensor(i, cfg.phi[i]));
            let r = centres[i] - hinges[i];
            let l = hinges[i + 1] - hinges[i];
            let wi = rates[i];
            cdot.push(vh + z.cross(r) * wi);
            cdd.push(ah - r * (wi * wi));
            vh = vh + z.cross(l) * wi;
            ah = ah - l * (wi * wi);
        }
        let mut mc = Mat::zeros(6 + n, 6 + n);
        let mut bc = vec![0.0; 6 + n];
        // Outboard sums, tip to root: mass, first moment, rotational inertia about ẑ and the
        // bias forces' resultant and moment about H.
        let (mut mt, mut s1) = (0.0, Vec3::ZERO);
        let mut jc = Mat3::ZERO;
        let (mut fb, mut mb) = (Vec3::ZERO, Vec3::ZERO);
        let mut iz = 0.0;
        let mut mzz = 0.0; // Σ m_i |c_i|² about H (in-plane)
        for i in (0..n).rev() {
            let p = &ch.panels[i];
            let c = centres[i];
            let wv = omega + z * rates[i];
            let ab = omega.cross(omega.cross(c)) + omega.cross(cdot[i]) * 2.0 + cdd[i];
            let eb = omega.cross(z * rates[i]);
            let rot = inertia[i].apply(eb) + wv.cross(inertia[i].apply(wv));
            mt += p.mass;
            s1 = s1 + c * p.mass;
            jc = jc + (Mat3::IDENTITY * c.dot(c) - c.outer(c)) * p.mass + inertia[i];
            fb = fb + ab * p.mass;
            mb = mb + c.cross(ab * p.mass) + rot;
            iz += self.panel_inertia[i][2];
            mzz += p.mass * c.dot(c);
            // Hinge l = i: outboard sums about h_i.
            let hl = hinges[i];
            let bl = s1 - hl * mt; // Σ m_j (c_j − h_l)
            let al = mzz - 2.0 * hl.dot(s1) + mt * hl.dot(hl) + iz; // Σ m_j|c_j − h_l|² + I_z
            let dl = d(i);
            let fcol = z.cross(bl) * dl;
            let mcol = z * (dl * (al + hl.dot(bl)));
            for r in 0..3 {
                mc[(r, 6 + i)] = fcol.get(r);
                mc[(6 + i, r)] = fcol.get(r);
                mc[(3 + r, 6 + i)] = mcol.get(r);
                mc[(6 + i, 3 + r)] = mcol.get(r);
            }
            // d_l ẑ·[Σ (c_j − h_l) × m_j a_j^b + rot_j] = d_l ẑ·(mb − h_l × fb).
            bc[6 + i] = dl * z.dot(mb - hl.cross(fb));
        }
        let st = s1.skew();
        for r in 0..3 {
            mc[(r, r)] = mt;
            for c in 0..3 {
                mc[(r, 3 + c)] = -st.get(r, c);
                mc[(3 + r, c)] = st.get(r, c);
                mc[(3 + r, 3 + c)] = jc.get(r, c);
            }
            bc[r] = fb.get(r);
            bc[3 + r] = mb.get(r);
        }
        let maa = ch.mass_matrix(alpha);
        for i in 0..n {
            for j in 0..n {
                mc[(6 + i, 6 + j)] = maa[(i, j)];
            }
        }
        ChainBlocks {
            mc,
            bc,
            centres,
            hinges,
            phi: cfg.phi,
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
    pub fn solve_captured(&self, y: &[f64], free: &[bool], captured: &[bool]) -> (Eval, Solution) {
        let ev = self.evaluate_captured(y, captured);
        let udot = self.accelerations(&ev, free);
        let sol = self.loads(y, &ev, udot, free);
        (ev, sol)
    }

    /// [`Coupled::evaluate`] with the latch moments of the captured hinges in the forces.
    fn evaluate_captured(&self, y: &[f64], captured: &[bool]) -> Eval {
        let mut ev = self.evaluate(y);
        let nb = self.rate_offset();
        for (j, m) in self.latch_moments(y, captured).into_iter().enumerate() {
            ev.force[nb + j] += m;
        }
        ev
    }

    /// The compliant latches' moments on the hinges, −k_j (α_j − α_j^L) − c_j α̇_j for the
    /// captured ones, zero otherwise, N·m.
    pub fn latch_moments(&self, y: &[f64], captured: &[bool]) -> Vec<f64> {
        let s = self.view(y);
        (0..self.panels())
            .map(|j| match &self.latch {
                Some(l) if captured.get(j).copied().unwrap_or(false) => {
                    let a = s.alpha[j] - self.chain.hinges[j].latch_angle;
                    -l.stiffness[j] * a - l.damping[j] * s.alpha_dot[j]
                }
                _ => 0.0,
            })
            .collect()
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
        let z = self.admissible(free);
        let rhs: Vec<f64> = ev.force.iter().zip(&ev.bias).map(|(f, c)| f - c).collect();
        solve_admissible(&ev.mass, &z, &rhs)
    }

    /// The root wrench and cable torques for accelerations u̇.
    fn loads(&self, y: &[f64], ev: &Eval, udot: Vec<f64>, free: &[bool]) -> Solution {
        let (nb, n) = (self.rate_offset(), self.panels());
        // [A; Ω̇] of H, then W = rows 0..6 of M_c [A; Ω̇; α̈] + b_c.
        let mut acc = vec![0.0; 6 + n];
        for i in 0..6 {
            acc[i] = ev.a_bias[i] + (0..nb).map(|j| ev.b[(i, j)] * udot[j]).sum::<f64>();
        }
        acc[6..].copy_from_slice(&udot[nb..]);
        let w: Vec<f64> = (0..6)
            .map(|i| ev.bc[i] + (0..6 + n).map(|j| ev.mc[(i, j)] * acc[j]).sum::<f64>())
            .collect();
        let f = ev.frame.apply(Vec3::new(w[0], w[1], w[2]));
        let mo = ev.frame.apply(Vec3::new(w[3], w[4], w[5]));
        let cable_torque = match self.sync {
            Synchronisation::None => Vec::new(),
            Synchronisation::ElasticCable(kc) => self
                .cable_mismatch(self.view(y).alpha)
                .iter()
                .map(|x| kc * x)
                .collect(),
            Synchronisation::IdealCable => {
                if free.iter().any(|f| *f) {
                    // r = (M u̇ + c − Q) on the hinge rows = Cᵀ λ.
                    let r: Vec<f64> = (0..n)
                        .map(|i| {
                            let row = nb + i;
                            (0..udot.len())
                                .map(|j| ev.mass[(row, j)] * udot[j])
                                .sum::<f64>()
                                + ev.bias[row]
                                - ev.force[row]
                        })
                        .collect();
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
        let z = self.admissible(free_after);
        solve_admissible(&ev.mass, &z, &mu)
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
        let ev = self.evaluate(y);
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

    /// dy/dt for the hinges flagged free, the compliant latches of those flagged `captured`
    /// acting.
    pub fn rhs_captured(&self, y: &[f64], free: &[bool], captured: &[bool], dy: &mut [f64]) {
        let udot = self.accelerations(&self.evaluate_captured(y, captured), free);
        let s = self.view(y);
        let np = self.positions();
        let (h, m) = (self.hub_dof(), self.modes());
        if h == 6 {
            let a = attitude::matrix(s.quat);
            let rd = a.apply(s.v);
            let qd = attitude::rate(s.quat, s.w);
            dy[..3].copy_from_slice(&rd.0);
            dy[3..7].copy_from_slice(&qd);
        }
        let pe = if h == 6 { 7 } else { 0 };
        dy[pe..pe + m].copy_from_slice(s.eta_dot);
        for (i, r) in s.alpha_dot.iter().enumerate() {
            dy[pe + m + i] = *r;
        }
        dy[np..].copy_from_slice(&udot);
    }
}

#[derive(Default)]
struct PanelMomenta {
    linear: Vec3,
    angular: Vec3,
    first_moment: Vec3,
    mass: f64,
}

struct ChainBlocks {
    mc: Mat<f64>,
    bc: Vec<f64>,
    centres: Vec<Vec3>,
    hinges: Vec<Vec3>,
    phi: Vec<f64>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn mat_vec(m: &Mat<f64>, x: &[f64]) -> Vec<f64> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)] * x[j]).sum())
        .collect()
}

/// u = Z (ZᵀMZ)⁻¹ Zᵀ b. M is positive definite for positive masses; a failed factorisation
/// (a non-finite state) gives NaN, which stops the run.
fn solve_admissible(m: &Mat<f64>, z: &Mat<f64>, b: &[f64]) -> Vec<f64> {
    let n = m.nrows();
    let k = z.ncols();
    if k == 0 {
        return vec![0.0; n];
    }
    // Z is sparse (unit columns for the hub and base speeds and the free hinges, one cable
    // column): ZᵀMZ by loops over its non-zeros.
    let nz: Vec<Vec<(usize, f64)>> = (0..k)
        .map(|c| {
            (0..n)
                .filter(|&r| z[(r, c)] != 0.0)
                .map(|r| (r, z[(r, c)]))
                .collect()
        })
        .collect();
    let zmz = Mat::from_fn(k, k, |a, c| {
        nz[a]
            .iter()
            .map(|&(i, za)| za * nz[c].iter().map(|&(j, zc)| m[(i, j)] * zc).sum::<f64>())
            .sum::<f64>()
    });
    let mut rhs = Mat::from_fn(k, 1, |i, _| {
        nz[i].iter().map(|&(j, zj)| zj * b[j]).sum::<f64>()
    });
    match zmz.llt(Side::Lower) {
        Ok(llt) => {
            faer::linalg::solvers::Solve::solve_in_place(&llt, rhs.as_mut());
            (0..n)
                .map(|i| (0..k).map(|j| z[(i, j)] * rhs[(j, 0)]).sum())
                .collect()
        }
        Err(_) => vec![f64::NAN; n],
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
    /// about the hinge point (N·m·s). Truncation-dependent on an elastic base (MODEL.md §3.2).
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
            settle_time: self
                .latch
                .as_ref()
                .map(|l| super::settle_time_default(&self.chain, &l.stiffness)),
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
