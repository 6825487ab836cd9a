//! Internal loads of the vibrating spacecraft by force summation (the "mode-acceleration"
//! load recovery of structural dynamics): the load a part of the structure receives through
//! its one cut is the rate of change of that part's momentum, since nothing else acts on a
//! free-floating spacecraft. Both are linear in the accelerations q̈, so each load is a
//! channel row c with value c · q̈ (docs/theory.md, "Loads in the response").
//!
//! * **Beam root loads.** For beam i and the set S of components hanging on it (itself
//!   included), the momentum of S is p_S = M_S[0..3, :] q̇ and its angular momentum about the
//!   hub's centre of mass c is H_S = M_S[3..6, :] q̇, with M_S the mass matrix of S alone
//!   ([`RitzModel::partial_mass`]); the hub coordinates are a rigid translation and a rigid
//!   rotation about c of everything. The force the parent exerts on the beam is F = ṗ_S and
//!   the moment about the root point r is M = Ḣ_S − (r − c) × F (small motions: the root's
//!   own velocity times p_S is of second order). Structure axes (the hub's body axes).
//! * **Latch moments in the deployed wing.** The wing is one plate in the response; the
//!   hinge line k at x_k (the panel lengths inboard of it) carries the moment T_b = Ḣ_b
//!   the inboard part exerts on the outboard strip x ∈ [x_k, a] about the width axis e_b,
//!   with
//!   H_b = −μ ∫∫_{x ≥ x_k} (x − x_k) v_n dA and v_n = n·(U̇ + Θ̇ × r) + Ẇ the normal velocity
//!   (the attachment's translation U and rotation Θ, r from the root edge's centre). On the
//!   hinge coordinate α_k (whose opening turns the outboard panels by (−1)^k about
//!   e_a × n = −e_b) this is the generalized moment Q_k = (−1)^{k+1} T_b: the hinge spring and
//!   the latch together. The latch's share is Q_k minus the hinge spring's moment at the
//!   latch angle, the static preload the unstressed plate does not carry, so that a settled
//!   deployment and the response's start agree. A wing cut along compliant latch lines
//!   (docs/theory.md §1.6) reports the latch's own moment from the lines' rotation and rate
//!   instead (`latch_line_channels`). The lines are at the panels' true positions.

use super::channels::{Channel, ChannelKind, Order};
use crate::basis::{Basis1d, Quadrature};
use crate::deploy::chain::Hinge;
use crate::math::Vec3;
use crate::ritz::assembly::ElementKind;
use crate::ritz::RitzModel;
use crate::structure::ComponentId;

/// Every beam's root force (N) and moment (N·m) about its root point, structure axes: six
/// acceleration channels per beam, `<beam>_root_fx` … `<beam>_root_mz`.
pub fn beam_root_channels(model: &RitzModel) -> Vec<Channel> {
    let st = &model.structure;
    let c = st.hub.center_of_mass;
    let mut out = Vec::new();
    for (i, beam) in st.beams.iter().enumerate() {
        let ms = model.partial_mass(|id| st.in_subtree(id, i));
        let d = st.beam_root(i) - c;
        let n = model.dof();
        let col = |j: usize, first: usize| {
            Vec3::new(ms[(first, j)], ms[(first + 1, j)], ms[(first + 2, j)])
        };
        // Column j: F_j = p-rows, M_j = H-rows − d × F_j.
        let (mut f, mut m) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        for j in 0..n {
            let fj = col(j, 0);
            let mj = col(j, 3) - d.cross(fj);
            f[j] = fj.0;
            m[j] = mj.0;
        }
        for (rows, what, unit) in [(&f, "f", "N"), (&m, "m", "N·m")] {
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                out.push(Channel {
                    name: format!("{}_root_{what}{axis}", beam.name),
                    label: format!(
                        "{} root {} {axis}",
                        beam.name,
                        if what == "f" { "force" } else { "moment" }
                    ),
                    unit,
                    kind: ChannelKind::BeamRoot {
                        beam: beam.name.clone(),
                    },
                    row: rows.iter().map(|r| r[k]).collect(),
                    order: Order::Acceleration,
                    offset: 0.0,
                    rate_row: None,
                });
            }
        }
    }
    out
}

/// The latch moments `latch_moment_<k>` (N·m, on the hinge coordinate α_k) of the deployed
/// wing `plate`, one per hinge of `hinges` (module doc). Empty if the plate is not in the
/// model.
pub fn latch_channels(
    model: &RitzModel,
    plate: &str,
    hinges: &[Hinge],
    panel_lengths: &[f64],
) -> Vec<Channel> {
    let st = &model.structure;
    let Some(pi) = st.plates.iter().position(|p| p.name == plate) else {
        return Vec::new();
    };
    let Some(e) = model.element(ComponentId::Plate(pi)) else {
        return Vec::new();
    };
    let ElementKind::Plate { length, width, .. } = &e.kind else {
        return Vec::new();
    };
    let p = &st.plates[pi];
    if !p.hinges.is_empty() && p.hinges.len() == hinges.len() {
        return latch_line_channels(model, e, p, hinges, length.len(), width.as_ref());
    }
    let (a, b, mu) = (p.length, p.width, p.areal_density);
    // Hinge k's line at the panels' lengths inboard of it (the deployment's panels, equal or
    // not); the length family's kinks (latch lines) break the quadrature there.
    let lines: Vec<f64> = panel_lengths
        .iter()
        .scan(0.0, |at, l| {
            let x = *at;
            *at += l;
            Some(x)
        })
        .collect();
    let breaks = p.hinge_positions();
    let y_means = means(width.as_ref(), 0.0, |_| 1.0, &[]);
    let own = e.own_range().start;
    let ny = width.len();
    hinges
        .iter()
        .enumerate()
        .map(|(i, h)| {
            let k = i + 1;
            let xk = lines.get(i).copied().unwrap_or(0.0);
            let a1 = 0.5 * (a - xk).powi(2);
            let a2 = a.powi(3) / 3.0 - xk * a * a / 2.0 + xk.powi(3) / 6.0;
            let coef_u = p.normal * (-mu * b * a1);
            let coef_th = p.width_axis() * (mu * b * a2);
            let x_moments = means(length.as_ref(), xk / a, |xi| a * xi - xk, &breaks);
            let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
            let t = &e.attachment;
            let mut row: Vec<f64> = (0..model.dof())
                .map(|j| {
                    let u = Vec3::new(t[(0, j)], t[(1, j)], t[(2, j)]);
                    let th = Vec3::new(t[(3, j)], t[(4, j)], t[(5, j)]);
                    sign * (coef_u.dot(u) + coef_th.dot(th))
                })
                .collect();
            for (m, xm) in x_moments.iter().enumerate() {
                for (n, yn) in y_means.iter().enumerate() {
                    row[own + m * ny + n] += sign * (-mu * b * a * xm * yn);
                }
            }
            Channel {
                name: format!("latch_moment_{k}"),
                label: format!("latch moment, hinge {k}"),
                unit: "N·m",
                kind: ChannelKind::LatchMoment { hinge: k },
                row,
                order: Order::Acceleration,
                offset: -h.moment(h.latch_angle, 0.0),
                rate_row: None,
            }
        })
        .collect()
}

/// The compliant latches' own moments on a wing cut along its latch lines (docs/theory.md
/// §1.6), as in the deployment: M_j = −k_L,j (α_j − α_j^L) − c_L,j α̇_j. Line j turns by
/// the mean θ̄_j = (1/a) Σ_i W_ij Σ_n h_in ∫Y_n dη of its kink functions' coordinates beyond
/// its rest rotation ρ_j (the latched equilibrium the straight model stands for), and
/// α_j − α_j^L = d_j (θ̄_j + ρ_j): a displacement row −k_L,j d_j ∂θ̄_j/∂q, a rate row
/// −c_L,j d_j ∂θ̄_j/∂q and the constant −k_L,j d_j ρ_j. The latch's share only: the
/// hinge spring's and, with a cable, the cable's moments through the line are not in it.
/// The lines hold k_L + k and c_L + c; the hinges give k and c.
fn latch_line_channels(
    model: &RitzModel,
    e: &crate::ritz::assembly::Element,
    p: &crate::structure::Plate,
    hinges: &[Hinge],
    nx: usize,
    width: &dyn Basis1d,
) -> Vec<Channel> {
    let w = p.hinge_functions();
    let ny = width.len();
    let smooth = nx - w.len();
    let own = e.own_range().start;
    let y_means = means(width, 0.0, |_| 1.0, &[]);
    hinges
        .iter()
        .zip(p.hinges())
        .enumerate()
        .map(|(j, (h, line))| {
            let (kl, cl) = (line.stiffness - h.stiffness, line.damping - h.damping);
            let d = crate::deploy::chain::Chain::d(j);
            let mut dtheta = vec![0.0; model.dof()];
            for (i, wi) in w.iter().enumerate() {
                for (n, yn) in y_means.iter().enumerate() {
                    dtheta[own + (smooth + i) * ny + n] += wi[j] * yn / p.length;
                }
            }
            let k = j + 1;
            Channel {
                name: format!("latch_moment_{k}"),
                label: format!("latch moment, hinge {k}"),
                unit: "N·m",
                kind: ChannelKind::LatchMoment { hinge: k },
                row: dtheta.iter().map(|v| -kl * d * v).collect(),
                order: Order::Displacement,
                offset: -kl * d * line.rest,
                rate_row: Some(dtheta.iter().map(|v| -cl * d * v).collect()),
            }
        })
        .collect()
}

/// ∫_{ξ₀}^1 w(ξ) F_m(ξ) dξ for every function F_m of a family, by Gauss–Legendre quadrature on
/// each piece of [ξ₀, 1] between the `breaks` (the kinks of a plate's latch lines; exact for
/// the polynomial families with w linear).
fn means(basis: &dyn Basis1d, xi0: f64, weight: impl Fn(f64) -> f64, breaks: &[f64]) -> Vec<f64> {
    let q = Quadrature::gauss(basis.len() + 24);
    let mut ends: Vec<f64> = breaks
        .iter()
        .copied()
        .filter(|&b| b > xi0 && b < 1.0)
        .collect();
    ends.push(1.0);
    let mut out = vec![0.0; basis.len()];
    let mut vals = vec![[0.0; 4]; basis.len()];
    let mut lo = xi0;
    for hi in ends {
        let span = hi - lo;
        for (&t, &w) in q.points.iter().zip(&q.weights) {
            let xi = lo + span * t;
            basis.eval_all(xi, &mut vals);
            let f = w * span * weight(xi);
            for (o, v) in out.iter_mut().zip(&vals) {
                *o += f * v[0];
            }
        }
        lo = hi;
    }
    out
}
