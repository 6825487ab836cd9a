//! A second, independent formulation of the coupled deployment in the plane: a free rigid hub
//! carrying an elastic mast, with the accordion-folded array hinged at the mast tip. It is a
//! test oracle for the minimal-coordinate 3-D model (`src/deploy/`, not used here): the same
//! physics written in maximal coordinates with hinge reactions as Lagrange multipliers.
//!
//! # Model (everything in the inertial x–y plane, rotations about +z)
//!
//! * Hub: mass m_h, inertia I_h about its centre of mass O; coordinates X, Y (position of O)
//!   and θ (attitude). A(θ) is the planar rotation, ẑ×(x, y) = (−y, x).
//! * Mast: Euler–Bernoulli beam clamped at r_m (hub frame), along +x_h, length L, ρA, EA, EI,
//!   no rotary inertia. u(s) = Σ a_k U_k(s/L) (axial), v(s) = Σ b_k V_k(s/L) (along y_h), with
//!   the test's own functions U_k(ξ) = ξ P*_{k−1}(ξ), V_k(ξ) = ξ² P*_{k−1}(ξ) (P*_n the shifted
//!   Legendre polynomial P_n(2ξ − 1), by its recurrence: [`clamped_family`]). They span what
//!   the library's clamped–free bases span (ξ … ξ^na and ξ² … ξ^(nb+1)), so the Ritz
//!   solution is the same, but share no code with them. A mast point is at
//!   r(s) = R + A(θ) ρ(s),   ρ(s) = r_m + (s + u(s)) e_x + v(s) e_y.
//!   Its velocity is exact: ṙ = Ṙ + θ̇ A ẑ×ρ + A ρ̇, so T_mast = ½∫ρA|ṙ|² ds keeps every
//!   centrifugal and Coriolis coupling between θ̇ and the deformation. The integral is a sum
//!   over Gauss points, each a particle of mass m_p = ρA L w_p; the rule is exact for the
//!   polynomial integrands, so the particle model *is* the continuum kinetic energy.
//!   Strain energy V_e = ½ aᵀK_a a + ½ bᵀK_b b, K_a = (EA/L)∫U_i'U_j' dξ,
//!   K_b = (EI/L³)∫V_i''V_j'' dξ (primes: ξ-derivatives). EA or EI = ∞ holds the a or b
//!   coefficients at zero by constraints (the rigid limit).
//! * Base coordinates q_b = (X, Y, θ, a_1..a_na, b_1..b_nb). Each particle has
//!   r_p = R + Aρ_p, Jacobian columns J_p = [(1,0), (0,1), A ẑ×ρ_p, A(U_k,0), A(0,V_k)] and
//!   r̈_p = J_p q̈_b + γ_p, γ_p = A(−θ̇² ρ_p + 2θ̇ ẑ×ρ̇_p). d'Alembert gives
//!   M_b q̈_b = −Σ m_p J_pᵀγ_p − K q_b + Q + (reactions),  M_b = diag(m_h, m_h, I_h, 0…) + Σ m_p J_pᵀJ_p.
//! * Root hinge at the mast tip: H₁ = R + A ρ(L). The hinge frame turns with the tip section:
//!   its inertial angle is ψ = θ + ψ0 + v'(L), v'(L) = (1/L) Σ b_k V_k'(1) (exact planar
//!   rotation of the frame, no linearisation of the angle itself).
//! * Panels i = 1..N: rigid, (x_i, y_i) centroid, φ_i absolute direction angle, mass m_i,
//!   centroidal inertia J_i; panel i runs from H_i to H_{i+1} = (x_i, y_i) + (l_i/2) e(φ_i),
//!   e(φ) = (cos φ, sin φ). Opening angles (linear in q):
//!   α₁ = π/2 − (φ₁ − ψ) = π/2 − φ₁ + θ + ψ0 + v'(L),
//!   α_i = π − s_i (φ_i − φ_{i−1}),  s_i = (−1)^{i−1}   (accordion fold).
//! * Hinge constraints (2 per hinge): c_i = (x_i, y_i) − (l_i/2) e(φ_i) − H_i = 0, with
//!   H_i = (x_{i−1}, y_{i−1}) + (l_{i−1}/2) e(φ_{i−1}) for i ≥ 2. Springs: V_s = Σ ½k_i(α_ref,i − α_i)²,
//!   generalised force k_i(α_ref,i − α_i) ∇α_i (acting between the tip section and panel 1 for
//!   i = 1, between panels i−1 and i otherwise).
//! * Equations of motion, index 1: with M = blockdiag(M_b, m_i, m_i, J_i), constraint rows G
//!   (c̈ = G q̈ + γ_c),
//!   [M Gᵀ; G 0][q̈; −λ] = [F; −γ_c],
//!   solved by the Schur complement S = G M⁻¹ Gᵀ. Integrated by the 3-stage Gauss–Legendre
//!   collocation method (order 6, symmetric: it does not damp the fast mast modes that every
//!   latch excites, which classical RK4 does visibly) with a fixed step, the stage equations
//!   solved by fixed-point iteration; after every step the positions (Gauss–Newton, to
//!   1e-15) and the velocities are projected M-orthogonally onto the constraints (an impulse
//!   of internal reactions: momentum is unchanged).
//! * Latch: when an unlatched α_j reaches α_j^L (located by bisection of the sub-step),
//!   the lock α_j = α_j^L joins the constraints and the velocities jump by the plastic-impact
//!   solution [M Gᵀ; G 0][v⁺; −Λ] = [M v⁻; 0], i.e. v⁺ = v⁻ − M⁻¹Gᵀ S⁻¹ G v⁻, which is the
//!   kinetic-energy minimiser and loses exactly ½ Δvᵀ M Δv.

use flexcraft::deploy::chain::{Chain, Hinge, Panel, PlanarHub};
use flexcraft::deploy::{simulate, Deployment, Latching};
use std::f64::consts::PI;

/// The n-point Gauss–Legendre rule mapped to [0, 1] (weights summing to 1): the roots of
/// P_n by Newton's method from the Chebyshev-like guesses cos(π(i + 3/4)/(n + 1/2)), the
/// weights 2/((1 − x²) P_n'(x)²) (Abramowitz & Stegun 25.4.29), halved.
fn gauss01(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut points, mut weights) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            let pm1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * p - pm1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        points.push(0.5 * (1.0 - x));
        weights.push(1.0 / ((1.0 - x * x) * dp * dp));
    }
    (points, weights)
}

/// The n functions ξ^power P*_k(ξ), k = 0 … n − 1, at ξ: for each its value and first and
/// second ξ-derivatives. P*_k(ξ) = P_k(2ξ − 1) by the three-term recurrence
/// (k + 1) P_{k+1} = (2k + 1) x P_k − k P_{k−1}, with P'_{k+1} = P'_{k−1} + (2k + 1) P_k and
/// P''_{k+1} = P''_{k−1} + (2k + 1) P'_k (x-derivatives; d/dξ = 2 d/dx), then the product
/// rule with ξ^power.
fn clamped_family(n: usize, power: i32, xi: f64) -> Vec<[f64; 3]> {
    let x = 2.0 * xi - 1.0;
    // (P, P', P'') in x for k = 0 … n − 1.
    let mut p: Vec<[f64; 3]> = Vec::with_capacity(n);
    for k in 0..n {
        let next = match k {
            0 => [1.0, 0.0, 0.0],
            1 => [x, 1.0, 0.0],
            _ => {
                let m = (k - 1) as f64;
                let (a, b) = (p[k - 1], p[k - 2]);
                [
                    ((2.0 * m + 1.0) * x * a[0] - m * b[0]) / (m + 1.0),
                    b[1] + (2.0 * m + 1.0) * a[0],
                    b[2] + (2.0 * m + 1.0) * a[1],
                ]
            }
        };
        p.push(next);
    }
    let m = power as f64;
    let (w, dw, ddw) = (
        xi.powi(power),
        m * xi.powi(power - 1),
        m * (m - 1.0) * xi.powi((power - 2).max(0)),
    );
    p.iter()
        .map(|&[v, d, dd]| {
            let (d, dd) = (2.0 * d, 4.0 * dd);
            [w * v, dw * v + w * d, ddw * v + 2.0 * dw * d + w * dd]
        })
        .collect()
}

/// [`clamped_family`] against closed forms: P*_0 … P*_3 are 1, 2ξ − 1, 6ξ² − 6ξ + 1,
/// 20ξ³ − 30ξ² + 12ξ − 1 (Abramowitz & Stegun 22.2.11), times ξ (the axial family) and ξ²
/// (bending), and their derivatives written out.
#[test]
fn the_oracles_own_functions_are_the_shifted_legendre_polynomials_times_the_clamp() {
    // (P*, P*', P*'') of each degree.
    type Poly = (fn(f64) -> f64, fn(f64) -> f64, fn(f64) -> f64);
    let polys: [Poly; 4] = [
        (|_| 1.0, |_| 0.0, |_| 0.0),
        (|x| 2.0 * x - 1.0, |_| 2.0, |_| 0.0),
        (
            |x| 6.0 * x * x - 6.0 * x + 1.0,
            |x| 12.0 * x - 6.0,
            |_| 12.0,
        ),
        (
            |x| 20.0 * x.powi(3) - 30.0 * x * x + 12.0 * x - 1.0,
            |x| 60.0 * x * x - 60.0 * x + 12.0,
            |x| 120.0 * x - 60.0,
        ),
    ];
    for (power, xi) in [1, 2]
        .into_iter()
        .flat_map(|w| [0.0, 0.13, 0.5, 0.77, 1.0].map(|x| (w, x)))
    {
        let got = clamped_family(4, power, xi);
        for (k, (p, dp, ddp)) in polys.iter().enumerate() {
            // (ξ^w P)′ = w ξ^(w−1) P + ξ^w P′, (ξ^w P)″ = w(w−1) ξ^(w−2) P + 2w ξ^(w−1) P′ + ξ^w P″.
            let want = if power == 1 {
                [xi * p(xi), p(xi) + xi * dp(xi), 2.0 * dp(xi) + xi * ddp(xi)]
            } else {
                [
                    xi * xi * p(xi),
                    2.0 * xi * p(xi) + xi * xi * dp(xi),
                    2.0 * p(xi) + 4.0 * xi * dp(xi) + xi * xi * ddp(xi),
                ]
            };
            for d in 0..3 {
                assert!(
                    (got[k][d] - want[d]).abs() <= 1e-13 * (1.0 + want[d].abs()),
                    "power {power}, k = {k}, ξ = {xi}, derivative {d}: {} vs {}",
                    got[k][d],
                    want[d]
                );
            }
        }
    }
}

/// The planar case.
#[derive(Debug, Clone)]
pub struct PlanarCase {
    /// m_h, kg.
    pub hub_mass: f64,
    /// I_h about the hub's centre of mass, kg·m².
    pub hub_inertia: f64,
    /// r_m, the mast root in the hub frame relative to the hub's centre of mass, m.
    pub mast_root: [f64; 2],
    /// L, m.
    pub mast_length: f64,
    /// ρA, kg/m.
    pub rho_a: f64,
    /// EA, N (∞: axially rigid).
    pub ea: f64,
    /// EI, N·m² (∞: rigid in bending).
    pub ei: f64,
    /// Number of axial Ritz functions.
    pub axial_terms: usize,
    /// Number of bending Ritz functions.
    pub bending_terms: usize,
    /// ψ0: the hinge frame's angle relative to the hub frame when the mast is undeformed.
    pub psi0: f64,
    /// (length, mass, centroidal inertia) per panel, root first.
    pub panels: Vec<(f64, f64, f64)>,
    /// k_i, N·m/rad.
    pub stiffness: Vec<f64>,
    /// α_ref,i, rad.
    pub reference_angle: Vec<f64>,
    /// α_i^L, rad.
    pub latch_angle: Vec<f64>,
    /// α_i(0), rad.
    pub initial_angle: Vec<f64>,
    /// s.
    pub end_time: f64,
    /// A compliant latch instead of the rigid one (`None`: the plastic impact).
    pub compliant: Option<CompliantLatch>,
}

/// The compliant latch: once α_j first reaches α_j^L while opening, the hinge moment gains
/// −k_L,j (α_j − α_j^L) − c_L,j α̇_j for good (the hinge spring keeps acting); no velocity jump.
#[derive(Debug, Clone)]
pub struct CompliantLatch {
    /// k_L per hinge, N·m/rad.
    pub stiffness: Vec<f64>,
    /// c_L per hinge, N·m·s/rad.
    pub damping: Vec<f64>,
    /// How long the run continues after the last capture, s.
    pub settle_time: f64,
}

/// One capture by a compliant latch.
#[derive(Debug, Clone)]
pub struct PlanarCapture {
    /// 1-based hinge number.
    pub hinge: usize,
    /// s.
    pub time: f64,
    /// dα_i/dt at the capture.
    pub rates: Vec<f64>,
}

/// The state at a requested output time.
#[derive(Debug, Clone)]
pub struct PlanarSample {
    /// s.
    pub t: f64,
    /// α_i, rad.
    pub alpha: Vec<f64>,
    /// The compliant latches' moments, N·m (zero before capture).
    pub latch_moment: Vec<f64>,
    /// The moment about +z the hub exerts on the mast about its root point R, N·m, from the
    /// hub's own equations (the mast is the only thing touching it):
    /// M_R = −I_h θ̈ + (R − O) × m_h (Ẍ, Ÿ).
    pub root_moment: f64,
}

/// One latch.
#[derive(Debug, Clone)]
pub struct PlanarLatch {
    /// 1-based hinge number.
    pub hinge: usize,
    /// s.
    pub time: f64,
    /// dα_i/dt just before the impact.
    pub rates_before: Vec<f64>,
    /// dα_i/dt just after the impact.
    pub rates_after: Vec<f64>,
    /// (u(L), v(L)) in the hub frame at the latch, m.
    pub tip_before: [f64; 2],
}

/// The run's outcome.
#[derive(Debug, Clone)]
pub struct PlanarResult {
    /// Latches in time order.
    pub latches: Vec<PlanarLatch>,
    /// end_time, or the instant the last hinge latched.
    pub final_time: f64,
    /// (u(L), v(L)) at final_time, m.
    pub tip_at_end: [f64; 2],
    /// X, Y, θ at final_time.
    pub hub_at_end: [f64; 3],
    /// Compliant latches: captures in time order.
    pub captures: Vec<PlanarCapture>,
    /// The states at the requested output times (see [`solve_planar_sampled`]).
    pub samples: Vec<PlanarSample>,
}

/// Diagnostics of one run (for the conservation tests).
#[derive(Debug, Clone)]
pub struct Diagnostics {
    /// (t, total energy, linear momentum, angular momentum about the origin, number of
    /// latches so far) after each step.
    pub history: Vec<(f64, f64, [f64; 2], f64, usize)>,
    /// Per latch: (energy before, energy after, ½ΔvᵀMΔv).
    pub impacts: Vec<(f64, f64, f64)>,
    /// Largest panel momentum |m_i ẋ_i| seen.
    pub max_panel_momentum: f64,
    /// Largest constraint violation after projection.
    pub max_violation: f64,
}

/// Runs the case with the default step (see [`default_step`]).
pub fn solve_planar(case: &PlanarCase) -> PlanarResult {
    let model = Model::new(case);
    let h = model.default_step();
    model.run(h, None, &[])
}

/// Runs the case with the step `h` and returns the state at each of `times` (ascending),
/// each taken by a Gauss step of its own from the last step point before it (the main
/// trajectory is not changed by the sampling).
#[allow(dead_code)]
pub fn solve_planar_sampled(case: &PlanarCase, h: f64, times: &[f64]) -> PlanarResult {
    Model::new(case).run(h, None, times)
}

/// Runs the case with the step `h` (for convergence checks of a comparison).
#[allow(dead_code)]
pub fn solve_planar_with_step(case: &PlanarCase, h: f64) -> PlanarResult {
    Model::new(case).run(h, None, &[])
}

/// Runs the case with the step `h`, recording energy and momenta.
pub fn solve_planar_diagnostics(case: &PlanarCase, h: f64) -> (PlanarResult, Diagnostics) {
    let mut d = Diagnostics {
        history: Vec::new(),
        impacts: Vec::new(),
        max_panel_momentum: 0.0,
        max_violation: 0.0,
    };
    let r = Model::new(case).run(h, Some(&mut d), &[]);
    (r, d)
}

/// The default step: 0.25/ω_max (ω_max the highest clamped-mast Ritz frequency), at most
/// 2 ms. Latch times then converge to ≈ 1e-11 s; the rates at a latch carry the phase of
/// the fast mast modes and converge more slowly (check with [`solve_planar_with_step`]).
#[allow(dead_code)]
pub fn default_step(case: &PlanarCase) -> f64 {
    Model::new(case).default_step()
}

/// ω_max, rad/s: the highest Ritz frequency of the mast clamped to a fixed hub (0 if rigid).
pub fn fastest_mast_frequency(case: &PlanarCase) -> f64 {
    Model::new(case).fastest_frequency()
}

fn e(p: f64) -> [f64; 2] {
    [p.cos(), p.sin()]
}

/// ẑ × a.
fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

/// s_i = (−1)^{i−1} for the 0-based index i0 = i − 1.
fn fold_sign(i0: usize) -> f64 {
    if i0 % 2 == 0 {
        1.0
    } else {
        -1.0
    }
}

/// In-place Cholesky factor (lower, row-major n×n) of an SPD matrix.
fn cholesky(a: &mut [f64], n: usize) {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        assert!(d > 0.0, "matrix not positive definite ({d})");
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
        for k in j + 1..n {
            a[j * n + k] = 0.0;
        }
    }
}

/// Solves L Lᵀ x = b in place.
fn chol_solve(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
}

/// A mast point: particle mass, arc length s and the Ritz function values there.
struct MastPoint {
    mass: f64,
    s: f64,
    u: Vec<f64>,
    v: Vec<f64>,
}

/// Kinematics of one mast point: inertial position, velocity, base Jacobian columns, γ.
struct PointKin {
    pos: [f64; 2],
    vel: [f64; 2],
    jac: Vec<[f64; 2]>,
    gamma: [f64; 2],
}

/// Constraint rows G (dense, length ndof), values c and velocity terms γ_c.
struct Constraints {
    g: Vec<Vec<f64>>,
    c: Vec<f64>,
    gamma: Vec<f64>,
}

struct Model<'a> {
    case: &'a PlanarCase,
    na: usize,
    nb: usize,
    nbase: usize,
    n: usize,
    ndof: usize,
    points: Vec<MastPoint>,
    tip: MastPoint,
    /// ∂v'(L)/∂b_k = V_k'(1)/L.
    slope: Vec<f64>,
    /// Stiffness of the base coordinates (nbase × nbase, zero on X, Y, θ).
    k: Vec<f64>,
    rigid_axial: bool,
    rigid_bending: bool,
    /// The hinges a compliant latch has captured.
    captured: std::cell::RefCell<Vec<bool>>,
    /// The last Gauss step: end state, step and stage accelerations (the next predictor).
    #[allow(clippy::type_complexity)]
    last: std::cell::RefCell<Option<(Vec<f64>, Vec<f64>, f64, [Vec<f64>; 3])>>,
}

impl<'a> Model<'a> {
    fn new(case: &'a PlanarCase) -> Self {
        let (na, nb) = (case.axial_terms, case.bending_terms);
        let nbase = 3 + na + nb;
        let n = case.panels.len();
        // The test's own clamped families (the span is what matters: the monomials give the
        // same Ritz solution, but their conditioning slowed this formulation's projections
        // tenfold), with the test's own Gauss rule.
        let ub = |xi: f64| clamped_family(na, 1, xi);
        let vb = |xi: f64| clamped_family(nb, 2, xi);
        let l = case.mast_length;
        // Integrands: |ρ|² has degree 2·max(na, nb + 1), stiffness products less: exact with
        // max(na, nb + 1) + 2 points; two more for margin.
        let (q_points, q_weights) = gauss01(na.max(nb + 1) + 4);
        let mut k = vec![0.0; nbase * nbase];
        let mut points = Vec::new();
        for (&xi, &w) in q_points.iter().zip(&q_weights) {
            let uv = ub(xi);
            let vv = vb(xi);
            for i in 0..na {
                for j in 0..na {
                    k[(3 + i) * nbase + 3 + j] += w * case.ea / l * uv[i][1] * uv[j][1];
                }
            }
            for i in 0..nb {
                for j in 0..nb {
                    k[(3 + na + i) * nbase + 3 + na + j] +=
                        w * case.ei / (l * l * l) * vv[i][2] * vv[j][2];
                }
            }
            points.push(MastPoint {
                mass: case.rho_a * l * w,
                s: l * xi,
                u: uv.iter().map(|d| d[0]).collect(),
                v: vv.iter().map(|d| d[0]).collect(),
            });
        }
        let rigid_axial = case.ea.is_infinite();
        let rigid_bending = case.ei.is_infinite();
        if rigid_axial || rigid_bending {
            for x in k.iter_mut() {
                if !x.is_finite() {
                    *x = 0.0;
                }
            }
        }
        let ut = ub(1.0);
        let vt = vb(1.0);
        Self {
            case,
            na,
            nb,
            nbase,
            n,
            ndof: nbase + 3 * n,
            points,
            tip: MastPoint {
                mass: 0.0,
                s: l,
                u: ut.iter().map(|d| d[0]).collect(),
                v: vt.iter().map(|d| d[0]).collect(),
            },
            slope: vt.iter().map(|d| d[1] / l).collect(),
            k,
            rigid_axial,
            rigid_bending,
            captured: std::cell::RefCell::new(vec![false; n]),
            last: std::cell::RefCell::new(None),
        }
    }

    fn pi(&self, i0: usize) -> usize {
        self.nbase + 3 * i0
    }

    /// Position, velocity, Jacobian and γ of a mast point (see the module doc).
    fn point(&self, q: &[f64], v: &[f64], p: &MastPoint) -> PointKin {
        let (na, nb) = (self.na, self.nb);
        let rm = self.case.mast_root;
        let mut rho = [rm[0] + p.s, rm[1]];
        let mut rhod = [0.0, 0.0];
        for k in 0..na {
            rho[0] += q[3 + k] * p.u[k];
            rhod[0] += v[3 + k] * p.u[k];
        }
        for k in 0..nb {
            rho[1] += q[3 + na + k] * p.v[k];
            rhod[1] += v[3 + na + k] * p.v[k];
        }
        let (s, c) = q[2].sin_cos();
        let rot = |x: [f64; 2]| [c * x[0] - s * x[1], s * x[0] + c * x[1]];
        let mut jac = Vec::with_capacity(self.nbase);
        jac.push([1.0, 0.0]);
        jac.push([0.0, 1.0]);
        jac.push(rot(perp(rho)));
        for k in 0..na {
            jac.push(rot([p.u[k], 0.0]));
        }
        for k in 0..nb {
            jac.push(rot([0.0, p.v[k]]));
        }
        let arho = rot(rho);
        let pos = [q[0] + arho[0], q[1] + arho[1]];
        let mut vel = [0.0; 2];
        for (col, vi) in jac.iter().zip(v) {
            vel[0] += col[0] * vi;
            vel[1] += col[1] * vi;
        }
        let w = v[2];
        let pr = perp(rhod);
        let gamma = rot([
            -w * w * rho[0] + 2.0 * w * pr[0],
            -w * w * rho[1] + 2.0 * w * pr[1],
        ]);
        PointKin {
            pos,
            vel,
            jac,
            gamma,
        }
    }

    /// ∇α_i as (index, coefficient) pairs (α is linear in q).
    fn alpha_grad(&self, i0: usize) -> Vec<(usize, f64)> {
        if i0 == 0 {
            let mut g = vec![(self.pi(0) + 2, -1.0), (2, 1.0)];
            for k in 0..self.nb {
                g.push((3 + self.na + k, self.slope[k]));
            }
            g
        } else {
            let s = fold_sign(i0);
            vec![(self.pi(i0) + 2, -s), (self.pi(i0 - 1) + 2, s)]
        }
    }

    fn alpha(&self, q: &[f64], i0: usize) -> f64 {
        let lin: f64 = self.alpha_grad(i0).iter().map(|&(j, c)| c * q[j]).sum();
        if i0 == 0 {
            PI / 2.0 + self.case.psi0 + lin
        } else {
            PI + lin
        }
    }

    /// −k_L (α − α^L) − c_L α̇ on a captured hinge, zero otherwise.
    fn latch_moment(&self, q: &[f64], v: &[f64], i0: usize) -> f64 {
        match &self.case.compliant {
            Some(l) if self.captured.borrow()[i0] => {
                -l.stiffness[i0] * (self.alpha(q, i0) - self.case.latch_angle[i0])
                    - l.damping[i0] * self.rate(v, i0)
            }
            _ => 0.0,
        }
    }

    fn rate(&self, v: &[f64], i0: usize) -> f64 {
        self.alpha_grad(i0).iter().map(|&(j, c)| c * v[j]).sum()
    }

    /// Base mass matrix M_b (nbase²) and full mass-matrix diagonal blocks of the panels are
    /// implicit; returns M_b and the base generalised force −Σ m_p J_pᵀγ_p − K q_b.
    fn base(&self, q: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let nb = self.nbase;
        let mut m = vec![0.0; nb * nb];
        let mut f = vec![0.0; nb];
        m[0] = self.case.hub_mass;
        m[nb + 1] = self.case.hub_mass;
        m[2 * nb + 2] = self.case.hub_inertia;
        for p in &self.points {
            let pk = self.point(q, v, p);
            for i in 0..nb {
                let ji = pk.jac[i];
                f[i] -= p.mass * (ji[0] * pk.gamma[0] + ji[1] * pk.gamma[1]);
                for j in i..nb {
                    let jj = pk.jac[j];
                    m[i * nb + j] += p.mass * (ji[0] * jj[0] + ji[1] * jj[1]);
                }
            }
        }
        for i in 0..nb {
            for j in 0..i {
                m[i * nb + j] = m[j * nb + i];
            }
            for j in 0..nb {
                f[i] -= self.k[i * nb + j] * q[j];
            }
        }
        (m, f)
    }

    /// Panel mass metric (m, m, J) at panel dof d (0..3).
    fn panel_mass(&self, i0: usize, d: usize) -> f64 {
        let (_, m, j) = self.case.panels[i0];
        if d == 2 {
            j
        } else {
            m
        }
    }

    /// The constraints: hinge coincidences, locks α_j = α_j^L, rigid-mast holds.
    fn constraints(&self, q: &[f64], v: &[f64], locked: &[bool]) -> Constraints {
        let nd = self.ndof;
        let mut out = Constraints {
            g: Vec::new(),
            c: Vec::new(),
            gamma: Vec::new(),
        };
        let tip = self.point(q, v, &self.tip);
        for i0 in 0..self.n {
            let l = self.case.panels[i0].0;
            let pi = self.pi(i0);
            let (p, w) = (q[pi + 2], v[pi + 2]);
            let ep = e(p);
            let mut rows = [vec![0.0; nd], vec![0.0; nd]];
            let mut val = [q[pi] - 0.5 * l * ep[0], q[pi + 1] - 0.5 * l * ep[1]];
            let mut gam = [0.5 * l * ep[0] * w * w, 0.5 * l * ep[1] * w * w];
            for d in 0..2 {
                rows[d][pi + d] = 1.0;
                rows[d][pi + 2] = 0.5 * l * [p.sin(), -p.cos()][d];
            }
            if i0 == 0 {
                for d in 0..2 {
                    for j in 0..self.nbase {
                        rows[d][j] = -tip.jac[j][d];
                    }
                    val[d] -= tip.pos[d];
                    gam[d] -= tip.gamma[d];
                }
            } else {
                let lp = self.case.panels[i0 - 1].0;
                let pp = self.pi(i0 - 1);
                let (f, wp) = (q[pp + 2], v[pp + 2]);
                let ef = e(f);
                for d in 0..2 {
                    rows[d][pp + d] = -1.0;
                    rows[d][pp + 2] = 0.5 * lp * [f.sin(), -f.cos()][d];
                    val[d] -= q[pp + d] + 0.5 * lp * ef[d];
                    gam[d] += 0.5 * lp * ef[d] * wp * wp;
                }
            }
            for d in 0..2 {
                out.g.push(rows[d].clone());
                out.c.push(val[d]);
                out.gamma.push(gam[d]);
            }
            if locked[i0] {
                let mut row = vec![0.0; nd];
                for (j, cf) in self.alpha_grad(i0) {
                    row[j] += cf;
                }
                out.g.push(row);
                out.c.push(self.alpha(q, i0) - self.case.latch_angle[i0]);
                out.gamma.push(0.0);
            }
        }
        let held = (0..self.na)
            .filter(|_| self.rigid_axial)
            .map(|k| 3 + k)
            .chain(
                (0..self.nb)
                    .filter(|_| self.rigid_bending)
                    .map(|k| 3 + self.na + k),
            );
        for j in held {
            let mut row = vec![0.0; nd];
            row[j] = 1.0;
            out.g.push(row);
            out.c.push(q[j]);
            out.gamma.push(0.0);
        }
        out
    }

    /// M⁻¹ x with the factored base block `lb`.
    fn minv(&self, lb: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = x.to_vec();
        chol_solve(lb, self.nbase, &mut y[..self.nbase]);
        for i0 in 0..self.n {
            for d in 0..3 {
                y[self.pi(i0) + d] /= self.panel_mass(i0, d);
            }
        }
        y
    }

    /// M x.
    fn mtimes(&self, mb: &[f64], x: &[f64]) -> Vec<f64> {
        let nb = self.nbase;
        let mut y = vec![0.0; self.ndof];
        for i in 0..nb {
            y[i] = (0..nb).map(|j| mb[i * nb + j] * x[j]).sum();
        }
        for i0 in 0..self.n {
            for d in 0..3 {
                let j = self.pi(i0) + d;
                y[j] = self.panel_mass(i0, d) * x[j];
            }
        }
        y
    }

    /// x + M⁻¹Gᵀ μ with S μ = r − G x, S = G M⁻¹ Gᵀ: the solution of
    /// [M Gᵀ; G 0][y; −μ] = [M x; r].
    fn constrained(&self, lb: &[f64], g: &[Vec<f64>], x: Vec<f64>, r: &[f64]) -> Vec<f64> {
        let m = g.len();
        let y: Vec<Vec<f64>> = g.iter().map(|row| self.minv(lb, row)).collect();
        let mut s = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                s[i * m + j] = g[i].iter().zip(&y[j]).map(|(a, b)| a * b).sum();
            }
        }
        let mut mu: Vec<f64> = (0..m)
            .map(|i| r[i] - g[i].iter().zip(&x).map(|(a, b)| a * b).sum::<f64>())
            .collect();
        cholesky(&mut s, m);
        chol_solve(&s, m, &mut mu);
        let mut out = x;
        for (yi, mi) in y.iter().zip(&mu) {
            for (o, a) in out.iter_mut().zip(yi) {
                *o += mi * a;
            }
        }
        out
    }

    fn factor(&self, mb: &[f64]) -> Vec<f64> {
        let mut lb = mb.to_vec();
        cholesky(&mut lb, self.nbase);
        lb
    }

    /// Accelerations q̈.
    fn accel(&self, q: &[f64], v: &[f64], locked: &[bool]) -> Vec<f64> {
        let (mb, fb) = self.base(q, v);
        let mut f = vec![0.0; self.ndof];
        f[..self.nbase].copy_from_slice(&fb);
        for i0 in 0..self.n {
            let tau = self.case.stiffness[i0] * (self.case.reference_angle[i0] - self.alpha(q, i0))
                + self.latch_moment(q, v, i0);
            for (j, cf) in self.alpha_grad(i0) {
                f[j] += tau * cf;
            }
        }
        let lb = self.factor(&mb);
        let con = self.constraints(q, v, locked);
        let z = self.minv(&lb, &f);
        let rhs: Vec<f64> = con.gamma.iter().map(|g| -g).collect();
        self.constrained(&lb, &con.g, z, &rhs)
    }

    /// One step of the 3-stage Gauss–Legendre collocation method (order 6, symmetric, no
    /// numerical dissipation of the fast mast modes) on q̇ = v, v̇ = accel(q, v):
    ///   V_i = v + h Σ_j a_ij K_j,  Q_i = q + h Σ_j a_ij V_j,  K_i = accel(Q_i, V_i),
    ///   q⁺ = q + h Σ b_i V_i,  v⁺ = v + h Σ b_i K_i,
    /// the stage equations solved by fixed-point iteration to rounding (the contraction
    /// factor is ≈ (h ω_max)² ρ(A)² ≪ 1), then the positions and velocities projected onto
    /// the constraints.
    fn step(&self, q: &[f64], v: &[f64], h: f64, locked: &[bool]) -> (Vec<f64>, Vec<f64>) {
        let r15 = 15f64.sqrt();
        let a = [
            [5.0 / 36.0, 2.0 / 9.0 - r15 / 15.0, 5.0 / 36.0 - r15 / 30.0],
            [5.0 / 36.0 + r15 / 24.0, 2.0 / 9.0, 5.0 / 36.0 - r15 / 24.0],
            [5.0 / 36.0 + r15 / 30.0, 2.0 / 9.0 + r15 / 15.0, 5.0 / 36.0],
        ];
        let b = [5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0];
        let nd = q.len();
        let c = [0.5 - r15 / 10.0, 0.5, 0.5 + r15 / 10.0];
        // Predictor: the previous step's stage accelerations, extrapolated by their quadratic
        // interpolant, when this step continues it; otherwise K_i = accel(q, v).
        let mut k = match &*self.last.borrow() {
            Some((q_end, v_end, hp, kp)) if q_end == q && v_end == v => {
                let mut k: [Vec<f64>; 3] = [vec![0.0; nd], vec![0.0; nd], vec![0.0; nd]];
                for i in 0..3 {
                    let t = hp + c[i] * h;
                    for j in 0..3 {
                        let mut w = 1.0;
                        for m in 0..3 {
                            if m != j {
                                w *= (t - c[m] * hp) / ((c[j] - c[m]) * hp);
                            }
                        }
                        for d in 0..nd {
                            k[i][d] += w * kp[j][d];
                        }
                    }
                }
                k
            }
            _ => {
                let k0 = self.accel(q, v, locked);
                [k0.clone(), k0.clone(), k0]
            }
        };
        let scale = 1.0 + v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let stage_v = |k: &[Vec<f64>; 3], i: usize| -> Vec<f64> {
            (0..nd)
                .map(|d| v[d] + h * (a[i][0] * k[0][d] + a[i][1] * k[1][d] + a[i][2] * k[2][d]))
                .collect()
        };
        let mut last = f64::INFINITY;
        for _ in 0..60 {
            let vs: Vec<Vec<f64>> = (0..3).map(|i| stage_v(&k, i)).collect();
            let mut change = 0.0f64;
            let mut knew: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
            for i in 0..3 {
                let qs: Vec<f64> = (0..nd)
                    .map(|d| {
                        q[d] + h * (a[i][0] * vs[0][d] + a[i][1] * vs[1][d] + a[i][2] * vs[2][d])
                    })
                    .collect();
                knew[i] = self.accel(&qs, &vs[i], locked);
                for d in 0..nd {
                    change = change.max(h * (knew[i][d] - k[i][d]).abs());
                }
            }
            k = knew;
            if change < 1e-15 * scale || (change < 1e-12 * scale && change >= last) {
                break;
            }
            last = change;
        }
        let vs: Vec<Vec<f64>> = (0..3).map(|i| stage_v(&k, i)).collect();
        let qn = (0..nd)
            .map(|d| q[d] + h * (b[0] * vs[0][d] + b[1] * vs[1][d] + b[2] * vs[2][d]))
            .collect();
        let vn = (0..nd)
            .map(|d| v[d] + h * (b[0] * k[0][d] + b[1] * k[1][d] + b[2] * k[2][d]))
            .collect();
        let (qn, vn) = self.project(qn, vn, locked);
        *self.last.borrow_mut() = Some((qn.clone(), vn.clone(), h, k));
        (qn, vn)
    }

    /// M-orthogonal projection of q onto c(q) = 0 (Gauss–Newton) and of v onto G v = 0.
    fn project(&self, mut q: Vec<f64>, v: Vec<f64>, locked: &[bool]) -> (Vec<f64>, Vec<f64>) {
        for _ in 0..10 {
            let con = self.constraints(&q, &v, locked);
            let size = con.c.iter().fold(0.0f64, |a, c| a.max(c.abs()));
            if size < 1e-15 {
                break;
            }
            let (mb, _) = self.base(&q, &v);
            let lb = self.factor(&mb);
            let rhs: Vec<f64> = con.c.iter().map(|c| -c).collect();
            let dq = self.constrained(&lb, &con.g, vec![0.0; self.ndof], &rhs);
            for (a, b) in q.iter_mut().zip(&dq) {
                *a += b;
            }
        }
        let v = self.impact(&q, v, locked);
        (q, v)
    }

    /// The plastic impact (and velocity projection): v⁺ minimising ½(v⁺−v)ᵀM(v⁺−v), G v⁺ = 0.
    fn impact(&self, q: &[f64], v: Vec<f64>, locked: &[bool]) -> Vec<f64> {
        let con = self.constraints(q, &v, locked);
        let (mb, _) = self.base(q, &v);
        let lb = self.factor(&mb);
        let zero = vec![0.0; con.g.len()];
        self.constrained(&lb, &con.g, v, &zero)
    }

    fn strain_energy(&self, q: &[f64]) -> f64 {
        let nb = self.nbase;
        let mut e = 0.0;
        for i in 0..nb {
            for j in 0..nb {
                e += 0.5 * q[i] * self.k[i * nb + j] * q[j];
            }
        }
        e
    }

    fn energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let (mb, _) = self.base(q, v);
        let mv = self.mtimes(&mb, v);
        let t: f64 = 0.5 * mv.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let springs: f64 = (0..self.n)
            .map(|i0| {
                0.5 * self.case.stiffness[i0]
                    * (self.case.reference_angle[i0] - self.alpha(q, i0)).powi(2)
            })
            .sum();
        t + springs + self.strain_energy(q)
    }

    /// Linear momentum and angular momentum about the inertial origin.
    fn momentum(&self, q: &[f64], v: &[f64]) -> ([f64; 2], f64) {
        let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
        let mh = self.case.hub_mass;
        let mut p = [mh * v[0], mh * v[1]];
        let mut h = self.case.hub_inertia * v[2] + mh * cross([q[0], q[1]], [v[0], v[1]]);
        for pt in &self.points {
            let k = self.point(q, v, pt);
            p[0] += pt.mass * k.vel[0];
            p[1] += pt.mass * k.vel[1];
            h += pt.mass * cross(k.pos, k.vel);
        }
        for i0 in 0..self.n {
            let j = self.pi(i0);
            let (_, m, inertia) = self.case.panels[i0];
            p[0] += m * v[j];
            p[1] += m * v[j + 1];
            h += m * cross([q[j], q[j + 1]], [v[j], v[j + 1]]) + inertia * v[j + 2];
        }
        (p, h)
    }

    fn tip(&self, q: &[f64]) -> [f64; 2] {
        let u: f64 = (0..self.na).map(|k| q[3 + k] * self.tip.u[k]).sum();
        let w: f64 = (0..self.nb)
            .map(|k| q[3 + self.na + k] * self.tip.v[k])
            .sum();
        [u, w]
    }

    /// 0.25/ω_max, at most 2 ms.
    fn default_step(&self) -> f64 {
        let w = self.fastest_frequency();
        if w > 0.0 {
            (0.25 / w).min(2e-3)
        } else {
            2e-3
        }
    }

    /// ω_max of the clamped mast (power iteration on M_ee⁻¹K_ee).
    fn fastest_frequency(&self) -> f64 {
        let ne = self.na + self.nb;
        let flexible = (0..ne).any(|k| {
            let j = 3 + k;
            self.k[j * self.nbase + j] > 0.0
        });
        if ne == 0 || !flexible {
            return 0.0;
        }
        let z = vec![0.0; self.ndof];
        let (mb, _) = self.base(&z, &z);
        let nb = self.nbase;
        let mut me = vec![0.0; ne * ne];
        let mut ke = vec![0.0; ne * ne];
        for i in 0..ne {
            for j in 0..ne {
                me[i * ne + j] = mb[(3 + i) * nb + 3 + j];
                ke[i * ne + j] = self.k[(3 + i) * nb + 3 + j];
            }
        }
        cholesky(&mut me, ne);
        let mut x = vec![1.0; ne];
        let mut lambda = 0.0;
        for it in 0..2000 {
            // y = M⁻¹ K x
            let mut y: Vec<f64> = (0..ne)
                .map(|i| (0..ne).map(|j| ke[i * ne + j] * x[j]).sum())
                .collect();
            chol_solve(&me, ne, &mut y);
            let norm = y.iter().map(|a| a * a).sum::<f64>().sqrt();
            let xn = x.iter().map(|a| a * a).sum::<f64>().sqrt();
            let new = norm / xn;
            x = y.iter().map(|a| a / norm).collect();
            if it > 50 && (new - lambda).abs() < 1e-10 * new {
                lambda = new;
                break;
            }
            lambda = new;
        }
        lambda.sqrt()
    }

    fn initial(&self) -> (Vec<f64>, Vec<f64>) {
        let c = self.case;
        let mut q = vec![0.0; self.ndof];
        let rm = c.mast_root;
        let mut hinge = [rm[0] + c.mast_length, rm[1]];
        let mut phi = c.psi0 + PI / 2.0 - c.initial_angle[0];
        for i0 in 0..self.n {
            if i0 > 0 {
                phi += fold_sign(i0) * (PI - c.initial_angle[i0]);
            }
            let l = c.panels[i0].0;
            let ep = e(phi);
            let j = self.pi(i0);
            q[j] = hinge[0] + 0.5 * l * ep[0];
            q[j + 1] = hinge[1] + 0.5 * l * ep[1];
            q[j + 2] = phi;
            hinge = [hinge[0] + l * ep[0], hinge[1] + l * ep[1]];
        }
        (q, vec![0.0; self.ndof])
    }

    fn run(&self, h: f64, mut diag: Option<&mut Diagnostics>, times: &[f64]) -> PlanarResult {
        let c = self.case;
        let n = self.n;
        let mut locked = vec![false; n];
        let (mut q, mut v) = self.initial();
        let (q0, v0) = self.project(q, v, &locked);
        q = q0;
        v = v0;
        let mut t = 0.0;
        let mut latches = Vec::new();
        let record = |d: &mut Option<&mut Diagnostics>, t: f64, q: &[f64], v: &[f64]| {
            if let Some(d) = d.as_deref_mut() {
                let (p, hm) = self.momentum(q, v);
                let segment = d.impacts.len();
                d.history.push((t, self.energy(q, v), p, hm, segment));
                for i0 in 0..n {
                    let j = self.pi(i0);
                    let pm = c.panels[i0].1 * v[j].hypot(v[j + 1]);
                    d.max_panel_momentum = d.max_panel_momentum.max(pm);
                }
                let con = self.constraints(q, v, &vec![false; n]);
                let viol = con.c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                d.max_violation = d.max_violation.max(viol);
            }
        };
        record(&mut diag, t, &q, &v);
        let compliant = c.compliant.is_some();
        self.captured
            .borrow_mut()
            .iter_mut()
            .for_each(|x| *x = false);
        let mut captures: Vec<PlanarCapture> = Vec::new();
        let mut samples: Vec<PlanarSample> = Vec::new();
        let mut next_sample = 0;
        // The states at the output times in (t, t_end], by Gauss steps of their own from (q, v).
        let mut sample_to = |t: f64, t_end: f64, q: &[f64], v: &[f64], locked: &[bool]| {
            while next_sample < times.len() && times[next_sample] <= t_end {
                let ts = times[next_sample];
                next_sample += 1;
                if ts < t {
                    continue;
                }
                let (qs, vs) = if ts > t {
                    self.step(q, v, ts - t, locked)
                } else {
                    (q.to_vec(), v.to_vec())
                };
                let acc = self.accel(&qs, &vs, locked);
                let (sn, cs) = qs[2].sin_cos();
                let rm = c.mast_root;
                let d = [cs * rm[0] - sn * rm[1], sn * rm[0] + cs * rm[1]];
                let root_moment =
                    -c.hub_inertia * acc[2] + c.hub_mass * (d[0] * acc[1] - d[1] * acc[0]);
                samples.push(PlanarSample {
                    t: ts,
                    alpha: (0..n).map(|i| self.alpha(&qs, i)).collect(),
                    latch_moment: (0..n).map(|i| self.latch_moment(&qs, &vs, i)).collect(),
                    root_moment,
                });
            }
        };
        let crossed = |q: &[f64], locked: &[bool]| -> Option<usize> {
            let captured = self.captured.borrow();
            (0..n)
                .filter(|&i| !locked[i] && !captured[i] && self.alpha(q, i) >= c.latch_angle[i])
                .max_by(|&i, &j| {
                    (self.alpha(q, i) - c.latch_angle[i])
                        .total_cmp(&(self.alpha(q, j) - c.latch_angle[j]))
                })
        };
        let open = |locked: &[bool]| {
            let captured = self.captured.borrow();
            (0..n).any(|i| !locked[i] && !captured[i])
        };
        // The run's end: end_time, or settle_time after the last capture once all are captured.
        let stop = |locked: &[bool], captures: &[PlanarCapture]| -> f64 {
            match (&c.compliant, captures.last()) {
                (Some(l), Some(k)) if !open(locked) => (k.time + l.settle_time).min(c.end_time),
                _ => c.end_time,
            }
        };
        while t < stop(&locked, &captures) && (open(&locked) || compliant) {
            let t_stop = stop(&locked, &captures);
            let step = h.min(t_stop - t);
            let (qn, vn) = self.step(&q, &v, step, &locked);
            if crossed(&qn, &locked).is_none() {
                let t_new = if step == t_stop - t { t_stop } else { t + step };
                sample_to(t, t_new, &q, &v, &locked);
                q = qn;
                v = vn;
                t = t_new;
                record(&mut diag, t, &q, &v);
                continue;
            }
            // Bisect the sub-step τ at which the first open α_j reaches α_j^L.
            let (mut lo, mut hi) = (0.0, step);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                let (qm, _) = self.step(&q, &v, mid, &locked);
                if crossed(&qm, &locked).is_some() {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let (qe, ve) = self.step(&q, &v, hi, &locked);
            let j = crossed(&qe, &locked).expect("the crossing persists at the bracket's end");
            sample_to(t, t + hi, &q, &v, &locked);
            t += hi;
            if compliant {
                // Capture: no jump; the integration restarts here with the latch acting.
                self.captured.borrow_mut()[j] = true;
                captures.push(PlanarCapture {
                    hinge: j + 1,
                    time: t,
                    rates: (0..n).map(|i| self.rate(&ve, i)).collect(),
                });
                q = qe;
                v = ve;
                record(&mut diag, t, &q, &v);
                continue;
            }
            let rates_before: Vec<f64> = (0..n).map(|i| self.rate(&ve, i)).collect();
            let tip_before = self.tip(&qe);
            let e_before = self.energy(&qe, &ve);
            locked[j] = true;
            // Impact (velocities), then put α_j exactly on its latch value (positions).
            let vp = self.impact(&qe, ve.clone(), &locked);
            let (mb, _) = self.base(&qe, &ve);
            let dv: Vec<f64> = vp.iter().zip(&ve).map(|(a, b)| a - b).collect();
            let loss = 0.5
                * self
                    .mtimes(&mb, &dv)
                    .iter()
                    .zip(&dv)
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            let e_after = self.energy(&qe, &vp);
            let (qp, vp) = self.project(qe, vp, &locked);
            if let Some(d) = diag.as_deref_mut() {
                d.impacts.push((e_before, e_after, loss));
            }
            q = qp;
            v = vp;
            record(&mut diag, t, &q, &v);
            latches.push(PlanarLatch {
                hinge: j + 1,
                time: t,
                rates_before,
                rates_after: (0..n).map(|i| self.rate(&v, i)).collect(),
                tip_before,
            });
        }
        PlanarResult {
            latches,
            final_time: t,
            tip_at_end: self.tip(&q),
            hub_at_end: [q[0], q[1], q[2]],
            captures,
            samples,
        }
    }
}

/// The brief's case: 1500 kg hub, 8 m aluminium tube mast (Ø 0.2 m, wall 5 mm), three
/// 2 m, 20 kg panels, k = 2 N·m/rad, α_ref = α_latch + 0.5.
pub fn reference_case() -> PlanarCase {
    let (ro, ri) = (0.1f64, 0.095f64);
    let area = PI * (ro * ro - ri * ri);
    let second_moment = PI / 4.0 * (ro.powi(4) - ri.powi(4));
    let (rho, young) = (2700.0, 70e9);
    let latch = vec![PI / 2.0, PI, PI];
    PlanarCase {
        hub_mass: 1500.0,
        hub_inertia: 1500.0 * 1.3 * 1.3 / 2.0,
        mast_root: [1.3, 0.0],
        mast_length: 8.0,
        rho_a: rho * area,
        ea: young * area,
        ei: young * second_moment,
        axial_terms: 4,
        bending_terms: 6,
        psi0: -PI / 2.0,
        panels: vec![(2.0, 20.0, 20.0 * 4.0 / 12.0); 3],
        stiffness: vec![2.0; 3],
        reference_angle: latch.iter().map(|a| a + 0.5).collect(),
        latch_angle: latch,
        initial_angle: vec![0.0; 3],
        end_time: 60.0,
        compliant: None,
    }
}

/// The rigid-mast limit as the existing planar chain: one free rigid body (hub + mast) of
/// mass m_h + ρAL, inertia about the combined centre of mass c,
///   I = I_h + m_h|c|² + ρAL³/12 + ρAL|r_m + (L/2)e_x − c|²,
/// and root hinge r_m + L e_x − c, expressed in the hinge frame's axes (e_a, n) at θ = 0
/// (the chain's plane coordinates: its φ₁ = θ + π/2 − α₁ is measured from e_a).
fn rigid_chain(case: &PlanarCase) -> Chain {
    let m_mast = case.rho_a * case.mast_length;
    let mass = case.hub_mass + m_mast;
    let mid = [
        case.mast_root[0] + 0.5 * case.mast_length,
        case.mast_root[1],
    ];
    let c = [m_mast * mid[0] / mass, m_mast * mid[1] / mass];
    let d2 = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let inertia = case.hub_inertia
        + case.hub_mass * d2(c, [0.0, 0.0])
        + m_mast * case.mast_length.powi(2) / 12.0
        + m_mast * d2(mid, c);
    let d = [
        case.mast_root[0] + case.mast_length - c[0],
        case.mast_root[1] - c[1],
    ];
    let (s, co) = case.psi0.sin_cos();
    let root = [co * d[0] + s * d[1], -s * d[0] + co * d[1]];
    Chain {
        panels: case
            .panels
            .iter()
            .map(|&(length, mass, inertia)| Panel {
                length,
                mass,
                inertia,
            })
            .collect(),
        hinges: (0..case.panels.len())
            .map(|i| Hinge {
                stiffness: case.stiffness[i],
                reference_angle: case.reference_angle[i],
                damping: 0.0,
                friction: 0.0,
                latch_angle: case.latch_angle[i],
                initial_angle: case.initial_angle[i],
                initial_rate: 0.0,
            })
            .collect(),
        hub: PlanarHub::Free { mass, inertia },
        root,
    }
}

/// The library's planar chain (deploy/chain.rs) on `case`'s rigid limit, DOPRI5 at 1e-12.
fn rigid_run(case: &PlanarCase) -> flexcraft::deploy::DeploymentResult {
    simulate(&Deployment {
        plate: "wing".into(),
        chain: rigid_chain(case),
        latching: Latching::Sequential,
        end_time: case.end_time,
        output_rate: 10.0,
        base: flexcraft::deploy::base::BaseKind::Rigid,
        synchronisation: flexcraft::deploy::coupled::Synchronisation::None,
        integrator: flexcraft::deploy::Integrator::Explicit,
        latch: flexcraft::deploy::LatchModel::Rigid,
        base_damping_ratio: 0.0,
        settling: None,
        tolerance: 1e-12,
        accuracy: 1e-3,
    })
}

#[test]
fn rigid_mast_limit_agrees_with_the_rigid_chain() {
    // EA = EI = ∞: the Ritz coefficients are held at zero by constraints (the limit of a
    // stiffer and stiffer mast; a finite ×1e8 mast would have ω_max ≈ 1e8 rad/s, beyond any
    // fixed-step integration of a 60 s run).
    let mut case = reference_case();
    case.ea = f64::INFINITY;
    case.ei = f64::INFINITY;
    let mine = solve_planar(&case);
    let theirs = rigid_run(&case);
    assert_eq!(
        mine.latches.len(),
        3,
        "every hinge latches within {} s",
        case.end_time
    );
    assert_eq!(
        theirs.latches.len(),
        3,
        "the rigid chain latches every hinge"
    );
    for (a, b) in mine.latches.iter().zip(&theirs.latches) {
        assert_eq!(a.hinge, b.hinge, "latch order");
        assert!(
            (a.time - b.time).abs() <= 1e-8 * b.time,
            "hinge {}: latch time {} (maximal, rigid mast) vs {} (rigid chain)",
            a.hinge,
            a.time,
            b.time
        );
        for (label, x, y) in [
            ("before", &a.rates_before, &b.rates_before),
            ("after", &a.rates_after, &b.rates_after),
        ] {
            for (i, (p, r)) in x.iter().zip(y).enumerate() {
                assert!(
                    (p - r).abs() <= 1e-7 * r.abs().max(1.0),
                    "latch of hinge {}: dα_{}/dt {label} {p} (maximal) vs {r} (rigid chain)",
                    a.hinge,
                    i + 1
                );
            }
        }
        assert!(
            a.tip_before[0].abs().max(a.tip_before[1].abs()) < 1e-15,
            "a rigid mast does not deflect: tip {:?}",
            a.tip_before
        );
        println!(
            "hinge {}: t = {:.12} (maximal) vs {:.12} (chain), rel {:.1e}; max rate diff {:.1e}",
            a.hinge,
            a.time,
            b.time,
            (a.time - b.time).abs() / b.time,
            a.rates_before
                .iter()
                .zip(&b.rates_before)
                .chain(a.rates_after.iter().zip(&b.rates_after))
                .map(|(p, r)| (p - r).abs())
                .fold(0.0, f64::max)
        );
    }
    assert!((mine.final_time - theirs.final_time).abs() <= 1e-8 * theirs.final_time);
    // The hub's attitude when the last hinge latches (θ is the same angle in both).
    assert!(
        (mine.hub_at_end[2] - theirs.final_q[2]).abs() <= 1e-8 * theirs.final_q[2].abs().max(1e-3),
        "hub attitude at the end: {} (maximal) vs {} (rigid chain)",
        mine.hub_at_end[2],
        theirs.final_q[2]
    );
    assert!(mine.tip_at_end[0].abs().max(mine.tip_at_end[1].abs()) < 1e-15);
}

#[test]
fn elastic_mast_conserves_momentum_and_energy() {
    // The first two latches (hinges 3 and 2, t ≈ 4.30 s and 5.76 s) with the elastic mast.
    let mut case = reference_case();
    case.end_time = 6.0;
    let h = 0.7 / fastest_mast_frequency(&case);
    let (r, d) = solve_planar_diagnostics(&case, h);
    assert_eq!(r.final_time, case.end_time);
    assert!(r.tip_at_end[1].abs() > 1e-5 && r.hub_at_end[2].abs() > 1e-3);
    // The latches to cross: those of the library's rigid chain in the first 6 s (the stiff
    // mast moves them by far less than their spacing), in its order.
    let rigid: Vec<usize> = rigid_run(&reference_case())
        .latches
        .iter()
        .filter(|l| l.time < case.end_time)
        .map(|l| l.hinge)
        .collect();
    assert!(rigid.len() >= 2);
    assert_eq!(
        r.latches.iter().map(|l| l.hinge).collect::<Vec<_>>(),
        rigid,
        "latch order in the first 6 s"
    );
    // The mast really flexes: the tip moves by ~mm at the second latch.
    let tip = r.latches[1].tip_before;
    assert!(tip[1].abs() > 1e-4, "tip deflection {tip:?}");

    // Momenta: zero from rest, measured against the largest panel momentum.
    let pmax = d.max_panel_momentum;
    let size: f64 = case.mast_root[0].hypot(case.mast_root[1])
        + case.mast_length
        + case.panels.iter().map(|p| p.0).sum::<f64>();
    assert!(pmax > 1.0, "panels move: max |m v| = {pmax}");
    for &(t, _, p, hm, _) in &d.history {
        assert!(
            p[0].hypot(p[1]) <= 1e-9 * pmax,
            "t = {t}: linear momentum {p:?} vs panel momentum {pmax}"
        );
        assert!(
            hm.abs() <= 1e-9 * pmax * size,
            "t = {t}: angular momentum {hm} vs panel momentum × size {}",
            pmax * size
        );
    }

    // Energy: constant between latches; at a latch the loss is ½ΔvᵀMΔv.
    let e0 = d.history[0].1;
    for seg in 0..=d.impacts.len() {
        let rows: Vec<_> = d.history.iter().filter(|x| x.4 == seg).collect();
        let start = rows[0].1;
        let mut end_values: Vec<f64> = rows.iter().map(|x| x.1).collect();
        if seg < d.impacts.len() {
            end_values.push(d.impacts[seg].0);
        }
        for (k, e) in end_values.iter().enumerate() {
            assert!(
                (e - start).abs() <= 1e-9 * e0,
                "between latches {seg} and {}: energy {e} vs {start} (sample {k}), E0 = {e0}",
                seg + 1
            );
        }
    }
    for (k, &(before, after, loss)) in d.impacts.iter().enumerate() {
        assert!(loss > 0.1, "latch {} dissipates", k + 1);
        assert!(
            ((before - after) - loss).abs() <= 1e-9 * e0,
            "latch {}: energy loss {} vs ½ΔvᵀMΔv = {loss}",
            k + 1,
            before - after
        );
    }
    let de = d
        .history
        .windows(2)
        .filter(|w| w[0].4 == w[1].4)
        .map(|w| (w[1].1 - w[0].1).abs())
        .fold(0.0, f64::max);
    let pm = d
        .history
        .iter()
        .map(|x| x.2[0].hypot(x.2[1]))
        .fold(0.0, f64::max);
    let hm = d.history.iter().map(|x| x.3.abs()).fold(0.0, f64::max);
    println!(
        "h = {h:.3e}; latches {:?}; |P|max/pmax = {:.1e}; |H|max/(pmax·size) = {:.1e}; \
         max step energy change / E0 = {:.1e}; impacts {:?}",
        r.latches
            .iter()
            .map(|l| (l.hinge, l.time, l.tip_before))
            .collect::<Vec<_>>(),
        pm / pmax,
        hm / (pmax * size),
        de / e0,
        d.impacts
    );
    assert!(
        d.max_violation < 1e-12,
        "constraint violation {}",
        d.max_violation
    );
}
