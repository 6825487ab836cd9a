//! The planar accordion chain: kinematics, mass matrix, equations of motion, hinge reactions,
//! latching impact (docs/theory.md §2; the paper's (2.1)–(2.6), rederived in minimal coordinates).
//!
//! Coordinates q = [u, v, θ] of a free hub (its centre of mass in the deployment plane, and
//! its rotation about the hinge-parallel axis) followed by the opening angles α₁…α_N (a fixed
//! hub has only the α). The plane is spanned by the wing's length axis (u) and normal (v).
//!
//! Absolute panel directions (panel i runs from hinge i to hinge i+1):
//!   φ₁ = θ + π/2 − α₁,   φ_i = φ_{i−1} + s_i (π − α_i),  s_i = (−1)^{i−1}   (accordion fold),
//! so stowed (α = 0) panel 1 points along the normal and each next panel folds back on the
//! previous one; at α₁ = π/2, α_i = π all lie along the length axis. ∂φ_j/∂α_k = d_k = (−1)^k
//! for j ≥ k. Hinge points H₁ = P + R(θ) r₀, H_{i+1} = H_i + l_i e(φ_i); centres
//! C_i = H_i + (l_i/2) e(φ_i), e(φ) = (cos φ, sin φ).
//!
//! Lagrange's equations (with T = ½ Σ m_i|Ċ_i|² + I_i φ̇_i² + hub, V = Σ ½ k_i(α_ref,i − α_i)²):
//!   M(q) q̈ = Q(q, q̇) − Σ_i m_i J_iᵀ γ_i,   M = Σ_i m_i J_iᵀJ_i + I_i a_i a_iᵀ (+ hub),
//! with J_i = ∂C_i/∂q (columns: u → (1,0), v → (0,1), θ → ẑ×(C_i − P), α_k → d_k ẑ×(C_i − H_k)
//! for k ≤ i), a_i = ∂φ_i/∂q, and the velocity terms
//!   γ_i = −θ̇² (H₁ − P) − Σ_{j<i} l_j e(φ_j) φ̇_j² − (l_i/2) e(φ_i) φ̇_i².
//! The hinge moment on α_k is Q_k = k_k(α_ref,k − α_k) − c_k α̇_k − f_k sgn(α̇_k).
//! Hinge reactions follow from Newton–Euler on the outboard sub-chain: the force that the
//! inboard body applies to panel i is F_i = Σ_{j≥i} m_j C̈_j and the moment it transmits is
//! M_i = Σ_{j≥i} [(C_j − H_i) × m_j C̈_j + I_j φ̈_j].

use faer::{Mat, Side};
use std::f64::consts::PI;

/// A 2-vector in the deployment plane (u along the length axis, v along the normal).
pub type P2 = [f64; 2];

fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn perp(a: P2) -> P2 {
    [-a[1], a[0]]
}
fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}
fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn e(phi: f64) -> P2 {
    [phi.cos(), phi.sin()]
}

/// A rigid panel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel {
    /// Length along the deployment direction, m.
    pub length: f64,
    /// Mass, kg.
    pub mass: f64,
    /// Moment of inertia about its centre, about the hinge-parallel axis, kg·m².
    pub inertia: f64,
}

/// A hinge: spring, damper, Coulomb friction and latch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hinge {
    /// k, N·m/rad.
    pub stiffness: f64,
    /// α_ref, rad: the spring's neutral angle.
    pub reference_angle: f64,
    /// c, N·m·s/rad.
    pub damping: f64,
    /// Coulomb friction moment, N·m.
    pub friction: f64,
    /// The angle at which the hinge locks, rad.
    pub latch_angle: f64,
    /// α at t = 0, rad.
    pub initial_angle: f64,
    /// α̇ at t = 0, rad/s.
    pub initial_rate: f64,
}

/// Rates below which Coulomb friction is regularised linearly (rad/s): sgn(α̇) is replaced
/// by clamp(α̇/ε, −1, 1) so that the integrator never meets a discontinuous right-hand side.
pub const FRICTION_RATE: f64 = 1e-6;

impl Hinge {
    /// The moment on α (spring + damper + friction), N·m.
    pub fn moment(&self, alpha: f64, rate: f64) -> f64 {
        self.stiffness * (self.reference_angle - alpha)
            - self.damping * rate
            - self.friction * (rate / FRICTION_RATE).clamp(-1.0, 1.0)
    }

    /// The slopes of [`Hinge::moment`]: (∂/∂α, ∂/∂α̇) = (−k, −c − μ/ε inside the friction's
    /// linear band |α̇| < ε, −c outside).
    pub fn moment_slopes(&self, rate: f64) -> (f64, f64) {
        let friction = if rate.abs() < FRICTION_RATE {
            self.friction / FRICTION_RATE
        } else {
            0.0
        };
        (-self.stiffness, -self.damping - friction)
    }

    /// Spring energy ½ k (α_ref − α)², J.
    pub fn energy(&self, alpha: f64) -> f64 {
        0.5 * self.stiffness * (self.reference_angle - alpha).powi(2)
    }
}

/// The hub during deployment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlanarHub {
    /// Held in inertial space (the paper's assumption).
    Fixed,
    /// Free in the deployment plane.
    Free {
        /// kg.
        mass: f64,
        /// About its centre of mass, about the hinge-parallel axis, kg·m².
        inertia: f64,
    },
}

/// The deploying chain.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// Panels, root first.
    pub panels: Vec<Panel>,
    /// Hinges, hinge 1 at the root.
    pub hinges: Vec<Hinge>,
    /// The hub.
    pub hub: PlanarHub,
    /// Hinge 1 relative to the hub's centre of mass, in the plane at θ = 0, m.
    pub root: P2,
}

/// Positions of every body for one q.
#[derive(Debug, Clone)]
pub struct Configuration {
    /// Hub centre of mass.
    pub hub: P2,
    /// Hub rotation θ.
    pub theta: f64,
    /// Panel directions φ_i.
    pub phi: Vec<f64>,
    /// Hinge points H_1..H_{N+1} (H_{N+1} is the tip).
    pub hinges: Vec<P2>,
    /// Panel centres.
    pub centres: Vec<P2>,
}

/// Accelerations and hinge loads at one state.
#[derive(Debug, Clone)]
pub struct Dynamics {
    /// q̈ (zero for locked coordinates).
    pub qdd: Vec<f64>,
    /// Force from the inboard body on panel i through hinge i, N (plane axes).
    pub force: Vec<P2>,
    /// Moment transmitted through hinge i, N·m.
    pub moment: Vec<f64>,
}

/// Solves M_FF x_F = b_F for the coordinates flagged free (x = 0 elsewhere). M is positive
/// definite for positive masses; a non-finite state (a diverged integration) makes the
/// factorisation fail and gives NaN, which stops the run.
fn solve_free(m: Mat<f64>, b: &[f64], free: &[bool]) -> Vec<f64> {
    let n = b.len();
    let idx: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
    let mut x = vec![0.0; n];
    if idx.is_empty() {
        return x;
    }
    let mf = if idx.len() == n {
        m
    } else {
        Mat::from_fn(idx.len(), idx.len(), |a, c| m[(idx[a], idx[c])])
    };
    let mut rhs = Mat::from_fn(idx.len(), 1, |a, _| b[idx[a]]);
    match mf.llt(Side::Lower) {
        Ok(llt) => {
            faer::linalg::solvers::Solve::solve_in_place(&llt, rhs.as_mut());
            for (a, &i) in idx.iter().enumerate() {
                x[i] = rhs[(a, 0)];
            }
        }
        Err(_) => x.iter_mut().for_each(|v| *v = f64::NAN),
    }
    x
}

/// Sums over the panels outboard of each hinge l (i ≥ l), about the hinge point H_l:
/// S0_l = Σ m_i, B_l = Σ m_i (C_i − H_l), A_l = Σ m_i |C_i − H_l|² + I_i, accumulated
/// tip-to-root by the parallel-axis shift (no cancellation between large absolute positions):
///   B_l = B_{l+1} + S0_{l+1}(H_{l+1} − H_l) + m_l (C_l − H_l),
///   A_l = A_{l+1} + 2(H_{l+1} − H_l)·B_{l+1} + S0_{l+1}|H_{l+1} − H_l|² + m_l|C_l − H_l|² + I_l.
struct OutboardSums {
    s0: Vec<f64>,
    b: Vec<P2>,
    a: Vec<f64>,
}

impl OutboardSums {
    fn new(chain: &Chain, cfg: &Configuration) -> Self {
        let nn = chain.len();
        let mut s0 = vec![0.0; nn];
        let mut b = vec![[0.0; 2]; nn];
        let mut a = vec![0.0; nn];
        let (mut s0n, mut bn, mut an) = (0.0, [0.0; 2], 0.0);
        for l in (0..nn).rev() {
            let p = &chain.panels[l];
            let d = sub(cfg.hinges[l + 1], cfg.hinges[l]);
            let c = sub(cfg.centres[l], cfg.hinges[l]);
            an += 2.0 * dot(d, bn) + s0n * dot(d, d) + p.mass * dot(c, c) + p.inertia;
            bn = [
                bn[0] + s0n * d[0] + p.mass * c[0],
                bn[1] + s0n * d[1] + p.mass * c[1],
            ];
            s0n += p.mass;
            s0[l] = s0n;
            b[l] = bn;
            a[l] = an;
        }
        Self { s0, b, a }
    }
}

impl Chain {
    /// Number of panels.
    pub fn len(&self) -> usize {
        self.panels.len()
    }

    /// True without panels (never for a validated scenario).
    pub fn is_empty(&self) -> bool {
        self.panels.is_empty()
    }

    /// Number of hub coordinates (3 free, 0 fixed).
    pub fn hub_dof(&self) -> usize {
        match self.hub {
            PlanarHub::Fixed => 0,
            PlanarHub::Free { .. } => 3,
        }
    }

    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.hub_dof() + self.len()
    }

    /// ∂φ_j/∂α_k for j ≥ k.
    pub(crate) fn d(k: usize) -> f64 {
        // k is 0-based here: hinge k+1, d = (−1)^(k+1).
        if k % 2 == 0 {
            -1.0
        } else {
            1.0
        }
    }

    /// The initial coordinates and rates.
    pub fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let h = self.hub_dof();
        let mut q = vec![0.0; self.dof()];
        let mut qd = vec![0.0; self.dof()];
        for (i, hg) in self.hinges.iter().enumerate() {
            q[h + i] = hg.initial_angle;
            qd[h + i] = hg.initial_rate;
        }
        (q, qd)
    }

    /// Positions for coordinates q.
    pub fn configuration(&self, q: &[f64]) -> Configuration {
        let h = self.hub_dof();
        let (hub, theta) = if h == 3 {
            ([q[0], q[1]], q[2])
        } else {
            ([0.0, 0.0], 0.0)
        };
        let (s, c) = theta.sin_cos();
        let r = [
            c * self.root[0] - s * self.root[1],
            s * self.root[0] + c * self.root[1],
        ];
        let mut hinges = vec![[hub[0] + r[0], hub[1] + r[1]]];
        let mut phi = Vec::with_capacity(self.len());
        let mut centres = Vec::with_capacity(self.len());
        for (i, p) in self.panels.iter().enumerate() {
            let a = q[h + i];
            let f = if i == 0 {
                theta + PI / 2.0 - a
            } else {
                let s_i = if i % 2 == 1 { -1.0 } else { 1.0 };
                phi[i - 1] + s_i * (PI - a)
            };
            phi.push(f);
            let hp = hinges[i];
            let ev = e(f);
            centres.push([
                hp[0] + 0.5 * p.length * ev[0],
                hp[1] + 0.5 * p.length * ev[1],
            ]);
            hinges.push([hp[0] + p.length * ev[0], hp[1] + p.length * ev[1]]);
        }
        Configuration {
            hub,
            theta,
            phi,
            hinges,
            centres,
        }
    }

    /// Absolute angular rates φ̇_i.
    pub fn phi_rates(&self, qd: &[f64]) -> Vec<f64> {
        let h = self.hub_dof();
        let mut w = if h == 3 { qd[2] } else { 0.0 };
        (0..self.len())
            .map(|i| {
                w += Self::d(i) * qd[h + i];
                w
            })
            .collect()
    }

    /// Jacobian of C_i: column j as a 2-vector (only columns 0..h+i+1 are non-zero).
    fn jacobian(&self, cfg: &Configuration, i: usize) -> Vec<P2> {
        let h = self.hub_dof();
        let mut jc = vec![[0.0; 2]; self.dof()];
        let ci = cfg.centres[i];
        if h == 3 {
            jc[0] = [1.0, 0.0];
            jc[1] = [0.0, 1.0];
            jc[2] = perp(sub(ci, cfg.hub));
        }
        for k in 0..=i {
            let p = perp(sub(ci, cfg.hinges[k]));
            jc[h + k] = [Self::d(k) * p[0], Self::d(k) * p[1]];
        }
        jc
    }

    /// Jacobian of φ_i.
    fn angle_jacobian(&self, i: usize) -> Vec<f64> {
        let h = self.hub_dof();
        let mut a = vec![0.0; self.dof()];
        if h == 3 {
            a[2] = 1.0;
        }
        for k in 0..=i {
            a[h + k] = Self::d(k);
        }
        a
    }

    /// The mass matrix M(q) (dof × dof).
    pub fn mass_matrix(&self, q: &[f64]) -> Mat<f64> {
        let cfg = self.configuration(q);
        self.mass_matrix_at(&cfg, &OutboardSums::new(self, &cfg))
    }

    /// M(q) from the outboard sums, O(N²) with O(1) per entry (the Jacobian form
    /// Σ m_i J_iᵀJ_i costs O(N³); both agree, see the unit test). Every column of a rotation
    /// (θ about P, α_k about H_k with sign d_k) moves panel i ≥ its start as
    /// J_i = s ẑ×(C_i − X), so for k ≤ l
    ///   M_{α_k α_l} = d_k d_l [A_l + (H_l − H_k)·B_l],
    ///   M_{θ α_l}   = d_l [A_l + (H_l − P)·B_l],
    ///   M_{u α_l}   = d_l (ẑ×B_l)_u,   M_{v α_l} = d_l (ẑ×B_l)_v,
    /// with A_l, B_l of [`OutboardSums`].
    fn mass_matrix_at(&self, cfg: &Configuration, sums: &OutboardSums) -> Mat<f64> {
        let n = self.dof();
        let h = self.hub_dof();
        let nn = self.len();
        let mut m = Mat::<f64>::zeros(n, n);
        for l in 0..nn {
            let hl = cfg.hinges[l];
            for k in 0..=l {
                let v =
                    Self::d(k) * Self::d(l) * (sums.a[l] + dot(sub(hl, cfg.hinges[k]), sums.b[l]));
                m[(h + k, h + l)] = v;
                m[(h + l, h + k)] = v;
            }
        }
        if let PlanarHub::Free { mass, inertia } = self.hub {
            let p = cfg.hub;
            let r = sub(cfg.hinges[0], p);
            let b_p = [
                sums.b[0][0] + sums.s0[0] * r[0],
                sums.b[0][1] + sums.s0[0] * r[1],
            ];
            m[(0, 0)] = mass + sums.s0[0];
            m[(1, 1)] = mass + sums.s0[0];
            m[(2, 2)] = inertia + sums.a[0] + 2.0 * dot(r, sums.b[0]) + sums.s0[0] * dot(r, r);
            let pb = perp(b_p);
            m[(0, 2)] = pb[0];
            m[(2, 0)] = pb[0];
            m[(1, 2)] = pb[1];
            m[(2, 1)] = pb[1];
            for l in 0..nn {
                let d = Self::d(l);
                let pb = perp(sums.b[l]);
                let t = d * (sums.a[l] + dot(sub(cfg.hinges[l], p), sums.b[l]));
                for (row, v) in [(0, d * pb[0]), (1, d * pb[1]), (2, t)] {
                    m[(row, h + l)] = v;
                    m[(h + l, row)] = v;
                }
            }
        }
        m
    }

    /// Velocity terms γ_i = C̈_i − J_i q̈.
    fn gamma(&self, cfg: &Configuration, qd: &[f64], w: &[f64]) -> Vec<P2> {
        let h = self.hub_dof();
        let th_d = if h == 3 { qd[2] } else { 0.0 };
        let r = sub(cfg.hinges[0], cfg.hub);
        let mut acc = [-th_d * th_d * r[0], -th_d * th_d * r[1]];
        let mut out = Vec::with_capacity(self.len());
        for (i, p) in self.panels.iter().enumerate() {
            let ev = e(cfg.phi[i]);
            let w2 = w[i] * w[i];
            out.push([
                acc[0] - 0.5 * p.length * ev[0] * w2,
                acc[1] - 0.5 * p.length * ev[1] * w2,
            ]);
            acc = [
                acc[0] - p.length * ev[0] * w2,
                acc[1] - p.length * ev[1] * w2,
            ];
        }
        out
    }

    /// Accelerations and hinge loads with the coordinates flagged in `free` free and the
    /// others locked (their rates must be zero).
    pub fn dynamics(&self, q: &[f64], qd: &[f64], free: &[bool]) -> Dynamics {
        self.solve_dynamics(q, qd, free, true)
    }

    /// As [`Chain::dynamics`], the hinge loads only when `loads` (the integrator needs q̈ only).
    pub fn solve_dynamics(&self, q: &[f64], qd: &[f64], free: &[bool], loads: bool) -> Dynamics {
        let n = self.dof();
        let h = self.hub_dof();
        let cfg = self.configuration(q);
        let w = self.phi_rates(qd);
        let sums = OutboardSums::new(self, &cfg);
        let m = self.mass_matrix_at(&cfg, &sums);
        let gam = self.gamma(&cfg, qd, &w);
        // Generalized forces Q − Σ_i m_i J_iᵀ γ_i through outboard sums of the panels'
        // velocity-term forces: G_k = Σ_{i≥k} m_i γ_i and X_k = Σ_{i≥k} m_i (C_i − H_k) × γ_i,
        // X_k = X_{k+1} + (H_{k+1} − H_k) × G_{k+1} + m_k (C_k − H_k) × γ_k.
        let mut rhs = vec![0.0; n];
        for (i, hg) in self.hinges.iter().enumerate() {
            rhs[h + i] = hg.moment(q[h + i], qd[h + i]);
        }
        let nn = self.len();
        let mut g = [0.0; 2];
        let mut x = 0.0;
        for k in (0..nn).rev() {
            let mk = self.panels[k].mass;
            x += cross(sub(cfg.hinges[k + 1], cfg.hinges[k]), g)
                + mk * cross(sub(cfg.centres[k], cfg.hinges[k]), gam[k]);
            g = [g[0] + mk * gam[k][0], g[1] + mk * gam[k][1]];
            rhs[h + k] -= Self::d(k) * x;
        }
        if h == 3 {
            rhs[0] -= g[0];
            rhs[1] -= g[1];
            rhs[2] -= x + cross(sub(cfg.hinges[0], cfg.hub), g);
        }
        let qdd = solve_free(m, &rhs, free);
        if !loads {
            return Dynamics {
                qdd,
                force: Vec::new(),
                moment: Vec::new(),
            };
        }
        // Body accelerations and Newton–Euler on the outboard sub-chains.
        let mut cdd = Vec::with_capacity(self.len());
        let mut wd = Vec::with_capacity(self.len());
        for i in 0..self.len() {
            let jc = self.jacobian(&cfg, i);
            let ja = self.angle_jacobian(i);
            let mut a = gam[i];
            let mut al = 0.0;
            for j in 0..h + i + 1 {
                a[0] += jc[j][0] * qdd[j];
                a[1] += jc[j][1] * qdd[j];
                al += ja[j] * qdd[j];
            }
            cdd.push(a);
            wd.push(al);
        }
        let mut force = vec![[0.0; 2]; nn];
        let mut moment = vec![0.0; nn];
        for i in 0..nn {
            let mut f = [0.0; 2];
            let mut mo = 0.0;
            for j in i..nn {
                let p = &self.panels[j];
                let fj = [p.mass * cdd[j][0], p.mass * cdd[j][1]];
                f[0] += fj[0];
                f[1] += fj[1];
                mo += cross(sub(cfg.centres[j], cfg.hinges[i]), fj) + p.inertia * wd[j];
            }
            force[i] = f;
            moment[i] = mo;
        }
        Dynamics { qdd, force, moment }
    }

    /// Kinetic energy ½ q̇ᵀ M q̇, J.
    pub fn kinetic_energy(&self, q: &[f64], qd: &[f64]) -> f64 {
        let m = self.mass_matrix(q);
        let n = self.dof();
        let mut t = 0.0;
        for a in 0..n {
            for b in 0..n {
                t += qd[a] * m[(a, b)] * qd[b];
            }
        }
        0.5 * t
    }

    /// Spring energy of every hinge, J.
    pub fn spring_energy(&self, q: &[f64]) -> f64 {
        let h = self.hub_dof();
        self.hinges
            .iter()
            .enumerate()
            .map(|(i, hg)| hg.energy(q[h + i]))
            .sum()
    }

    /// Linear momentum (N·s) and angular momentum about the plane's origin (N·m·s) of the
    /// whole system (hub included when free).
    pub fn momentum(&self, q: &[f64], qd: &[f64]) -> (P2, f64) {
        let cfg = self.configuration(q);
        let w = self.phi_rates(qd);
        let mut p = [0.0; 2];
        let mut l = 0.0;
        if let PlanarHub::Free { mass, inertia } = self.hub {
            let v = [qd[0], qd[1]];
            p = [mass * v[0], mass * v[1]];
            l = mass * cross(cfg.hub, v) + inertia * qd[2];
        }
        for (i, pn) in self.panels.iter().enumerate() {
            let v = self.centre_velocity(&cfg, i, qd);
            p[0] += pn.mass * v[0];
            p[1] += pn.mass * v[1];
            l += pn.mass * cross(cfg.centres[i], v) + pn.inertia * w[i];
        }
        (p, l)
    }

    /// Velocities of the hinge points H_1..H_N: V_{H₁} = V_P + θ̇ ẑ × (H₁ − P),
    /// V_{H_{i+1}} = V_{H_i} + φ̇_i ẑ × l_i e(φ_i). A point of panel i at distance s from its
    /// hinge moves with V_{H_i} + φ̇_i ẑ × s e(φ_i).
    pub fn hinge_velocities(&self, cfg: &Configuration, qd: &[f64]) -> Vec<P2> {
        let h = self.hub_dof();
        let w = self.phi_rates(qd);
        let mut v = if h == 3 {
            let r = perp(sub(cfg.hinges[0], cfg.hub));
            [qd[0] + qd[2] * r[0], qd[1] + qd[2] * r[1]]
        } else {
            [0.0; 2]
        };
        let mut out = Vec::with_capacity(self.len());
        for (i, p) in self.panels.iter().enumerate() {
            out.push(v);
            let d = perp(e(cfg.phi[i]));
            v = [v[0] + w[i] * p.length * d[0], v[1] + w[i] * p.length * d[1]];
        }
        out
    }

    fn centre_velocity(&self, cfg: &Configuration, i: usize, qd: &[f64]) -> P2 {
        let jc = self.jacobian(cfg, i);
        let mut v = [0.0; 2];
        for (j, c) in jc.iter().enumerate() {
            v[0] += c[0] * qd[j];
            v[1] += c[1] * qd[j];
        }
        v
    }

    /// Plastic impact: the coordinates flagged in `lock` lose their rate; the generalized
    /// momentum of the coordinates that stay free is conserved:
    /// M_FF q̇⁺_F = (M q̇⁻)_F, q̇⁺ = 0 elsewhere (docs/theory.md §2). Returns q̇⁺ and the impulse
    /// each hinge carries (linear, from the inboard body on panel i, and angular).
    pub fn impact(&self, q: &[f64], qd: &[f64], free_after: &[bool]) -> (Vec<f64>, Vec<(P2, f64)>) {
        let n = self.dof();
        let m = self.mass_matrix(q);
        let p: Vec<f64> = (0..n)
            .map(|a| (0..n).map(|j| m[(a, j)] * qd[j]).sum::<f64>())
            .collect();
        let qd_new = solve_free(m, &p, free_after);
        let cfg = self.configuration(q);
        let dq: Vec<f64> = (0..n).map(|i| qd_new[i] - qd[i]).collect();
        let dw = self.phi_rates(&dq);
        let dv: Vec<P2> = (0..self.len())
            .map(|i| self.centre_velocity(&cfg, i, &dq))
            .collect();
        let nn = self.len();
        let impulses = (0..nn)
            .map(|i| {
                let mut s = [0.0; 2];
                let mut a = 0.0;
                for j in i..nn {
                    let p = &self.panels[j];
                    let sj = [p.mass * dv[j][0], p.mass * dv[j][1]];
                    s[0] += sj[0];
                    s[1] += sj[1];
                    a += cross(sub(cfg.centres[j], cfg.hinges[i]), sj) + p.inertia * dw[j];
                }
                (s, a)
            })
            .collect();
        (qd_new, impulses)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook form M = Σ_i m_i J_iᵀJ_i + I_i a_i a_iᵀ (+ hub), O(N³).
    fn mass_matrix_by_jacobians(chain: &Chain, q: &[f64]) -> Mat<f64> {
        let n = chain.dof();
        let cfg = chain.configuration(q);
        let mut m = Mat::<f64>::zeros(n, n);
        if let PlanarHub::Free { mass, inertia } = chain.hub {
            m[(0, 0)] = mass;
            m[(1, 1)] = mass;
            m[(2, 2)] = inertia;
        }
        for (i, p) in chain.panels.iter().enumerate() {
            let jc = chain.jacobian(&cfg, i);
            let ja = chain.angle_jacobian(i);
            for a in 0..n {
                for b in 0..n {
                    m[(a, b)] += p.mass * dot(jc[a], jc[b]) + p.inertia * ja[a] * ja[b];
                }
            }
        }
        m
    }

    fn chain(n: usize, hub: PlanarHub) -> Chain {
        let panels = (0..n)
            .map(|i| {
                let l = 1.0 + 0.1 * i as f64;
                let m = 2.0 + 0.3 * i as f64;
                Panel {
                    length: l,
                    mass: m,
                    inertia: m * l * l / 12.0 + 0.01,
                }
            })
            .collect();
        let hinge = Hinge {
            stiffness: 1.0,
            reference_angle: 3.0,
            damping: 0.0,
            friction: 0.0,
            latch_angle: PI,
            initial_angle: 0.0,
            initial_rate: 0.0,
        };
        Chain {
            panels,
            hinges: vec![hinge; n],
            hub,
            root: [0.7, -0.4],
        }
    }

    #[test]
    fn outboard_sums_give_the_jacobian_mass_matrix() {
        for hub in [
            PlanarHub::Fixed,
            PlanarHub::Free {
                mass: 50.0,
                inertia: 20.0,
            },
        ] {
            let c = chain(7, hub);
            let q: Vec<f64> = (0..c.dof()).map(|i| 0.3 + 0.37 * i as f64).collect();
            let fast = c.mass_matrix(&q);
            let slow = mass_matrix_by_jacobians(&c, &q);
            for a in 0..c.dof() {
                for b in 0..c.dof() {
                    let scale = slow[(a, a)].abs().max(slow[(b, b)].abs());
                    assert!(
                        (fast[(a, b)] - slow[(a, b)]).abs() <= 1e-13 * scale,
                        "M[{a},{b}] {} vs {}",
                        fast[(a, b)],
                        slow[(a, b)]
                    );
                }
            }
        }
    }
}
