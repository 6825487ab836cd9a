//! Inertia invariants of an elastic body in a floating frame (docs/theory.md §2.1–2.2: small
//! elastic deformation in the hub frame, exact rigid motion, all inertia coupling and all
//! quadratic-velocity terms).
//!
//! The body is represented by mass points p (mass m_p, position r_p from the frame's origin O,
//! displacement Φ_p η, Φ_p a 3×m matrix of the kept modes) and rotary inertias s (tensor I_s,
//! small rotation Ψ_s η). With v the velocity of O and ω the frame's angular velocity (both
//! in frame components) every point moves with v + ω × ρ_p + Φ_p η̇, ρ_p = r_p + Φ_p η, so
//!
//!   T = ½ m|v|² + v·(ω × s) + v·S η̇ + ½ ωᵀ J ω + ωᵀ L η̇ + ½ η̇ᵀ M_ee η̇,
//!
//! with the invariants s(η) = s₀ + S η, J(η) = J₀ + Σ_j η_j J1_j + Σ_jk η_j η_k J2_jk,
//! L(η) = L₀ + Σ_j η_j L1_j (sums over the points of m_p ρ̃_pᵀρ̃_p, m_p ρ̃_p Φ_p, plus the
//! rotary inertias' I_s and I_s Ψ_s). The momenta are p = ∂T/∂v = m v + ω × s + S η̇,
//! h = ∂T/∂ω = s × v + J ω + L η̇, g = ∂T/∂η̇ = Sᵀv + Lᵀω + M_ee η̇, and the equations of
//! motion (Kirchhoff's for the frame, Lagrange's for η) read
//!
//!   ṗ + ω × p = F,   ḣ + ω × h + v × p = M_O,   ġ − ∂T/∂η + K η = Q_η,
//!
//! with ∂T/∂η_j = v·(ω × S_j) + ½ ωᵀ J_{,j} ω + ωᵀ L1_j η̇. The rotary inertias keep their
//! undeformed orientation (their rotation changes I_s at second order in η, neglected: the
//! torsional and lumped inertias are small). The same invariants of a beam's outboard
//! subtree give its root loads: F = ṗ + ω × p and M_O = ḣ + ω × h + v × p.

use crate::math::{dot4, Mat3, Vec3};
use faer::Mat;

/// A point mass of the cloud.
#[derive(Debug, Clone)]
pub struct MassPoint {
    /// kg.
    pub mass: f64,
    /// Position from the frame's origin, m.
    pub position: Vec3,
    /// Displacement per unit modal coordinate, one per mode, m.
    pub shapes: Vec<Vec3>,
}

/// A rotary inertia of the cloud (a lumped body's or a beam section's torsional inertia).
#[derive(Debug, Clone)]
pub struct RotaryPoint {
    /// kg·m².
    pub inertia: Mat3,
    /// Small rotation per unit modal coordinate, one per mode, rad.
    pub rotations: Vec<Vec3>,
}

/// The invariants of a body of `m` modes (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Invariants {
    /// Number of modes.
    pub modes: usize,
    /// kg.
    pub mass: f64,
    /// s₀, kg·m.
    pub s0: Vec3,
    /// Columns S_j, kg.
    pub s: Vec<Vec3>,
    /// J₀, kg·m².
    pub j0: Mat3,
    /// J1_j, kg·m.
    pub j1: Vec<Mat3>,
    /// J2_jk (index j·m + k), kg (private: `j2_sym` is derived from it).
    j2: Vec<Mat3>,
    /// Columns of L₀, kg·m.
    pub l0: Vec<Vec3>,
    /// L1_j's columns (index j·m + k), kg (private: `l1_parts` is derived from it).
    l1: Vec<Vec3>,
    /// M_ee (m × m), kg.
    pub mee: Mat<f64>,
    /// J2's symmetric parts ½ (J2_ab + J2_abᵀ) by component (xx, yy, zz, xy, xz, yz), each an
    /// m × m array (row a, column b; symmetric in a and b, since J2_ba = J2_abᵀ): the
    /// quadratic terms of [`Invariants::at_into`] as six matrix–vector products over
    /// contiguous rows.
    j2_sym: [Vec<f64>; 6],
    /// L1_ab's components x, y, z, each an m × m array (row a, column b; antisymmetric in a
    /// and b, L1_ba = −L1_ab, exactly as summed: m f_b × f_a = −m f_a × f_b in floating point).
    l1_parts: [Vec<f64>; 3],
}

/// The component order of [`Mat3::symmetric`]: (row, column) of xx, yy, zz, xy, xz, yz.
const SYMMETRIC: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// The η-dependent invariants at one η.
#[derive(Debug, Clone, Default)]
pub struct AtShape {
    /// s(η).
    pub s: Vec3,
    /// J(η).
    pub j: Mat3,
    /// Columns of L(η).
    pub l: Vec<Vec3>,
    /// ∂J/∂η_j.
    pub dj: Vec<Mat3>,
}

fn skew_t_skew(a: Vec3, b: Vec3) -> Mat3 {
    // ãᵀ b̃ = (a·b) I − b aᵀ.
    Mat3::IDENTITY * a.dot(b) - b.outer(a)
}

impl Invariants {
    /// Sums the invariants of a cloud of `modes` modes.
    pub fn of_cloud(modes: usize, points: &[MassPoint], rotary: &[RotaryPoint]) -> Self {
        let m = modes;
        let mut inv = Self {
            modes: m,
            mass: 0.0,
            s0: Vec3::ZERO,
            s: vec![Vec3::ZERO; m],
            j0: Mat3::ZERO,
            j1: vec![Mat3::ZERO; m],
            j2: vec![Mat3::ZERO; m * m],
            l0: vec![Vec3::ZERO; m],
            l1: vec![Vec3::ZERO; m * m],
            mee: Mat::zeros(m, m),
            j2_sym: Default::default(),
            l1_parts: Default::default(),
        };
        for p in points {
            let (mp, r) = (p.mass, p.position);
            inv.mass += mp;
            inv.s0 = inv.s0 + r * mp;
            inv.j0 = inv.j0 + skew_t_skew(r, r) * mp;
            for j in 0..m {
                let fj = p.shapes[j];
                inv.s[j] = inv.s[j] + fj * mp;
                inv.j1[j] = inv.j1[j] + (skew_t_skew(r, fj) + skew_t_skew(fj, r)) * mp;
                inv.l0[j] = inv.l0[j] + r.cross(fj) * mp;
                for k in 0..m {
                    let fk = p.shapes[k];
                    inv.j2[j * m + k] = inv.j2[j * m + k] + skew_t_skew(fj, fk) * mp;
                    inv.l1[j * m + k] = inv.l1[j * m + k] + fj.cross(fk) * mp;
                    inv.mee[(j, k)] += mp * fj.dot(fk);
                }
            }
        }
        for s in rotary {
            inv.j0 = inv.j0 + s.inertia;
            for j in 0..m {
                inv.l0[j] = inv.l0[j] + s.inertia.apply(s.rotations[j]);
                for k in 0..m {
                    inv.mee[(j, k)] += s.rotations[j].dot(s.inertia.apply(s.rotations[k]));
                }
            }
        }
        inv.j2_sym = SYMMETRIC.map(|(r, c)| {
            inv.j2
                .iter()
                .map(|x| 0.5 * (x.get(r, c) + x.get(c, r)))
                .collect()
        });
        inv.l1_parts = [0, 1, 2].map(|i| inv.l1.iter().map(|x| x.get(i)).collect());
        inv
    }

    /// Σ_b L1_ab x_b for row a, = −Σ_b L1_ba x_b (antisymmetry): one contiguous row.
    fn l1_row(&self, a: usize, x: &[f64]) -> Vec3 {
        let m = self.modes;
        Vec3(
            self.l1_parts
                .each_ref()
                .map(|p| dot4(&p[a * m..(a + 1) * m], x)),
        )
    }

    /// s(η), J(η), L(η) and ∂J/∂η.
    pub fn at(&self, eta: &[f64]) -> AtShape {
        let mut out = AtShape::default();
        self.at_into(eta, &mut out);
        out
    }

    /// [`Invariants::at`] into `out` (its vectors reused: no allocation once sized). With
    /// K_a = Σ_b J2_ab η_b and its symmetric part K̂_a = Σ_b ½ (J2_ab + J2_abᵀ) η_b
    /// (J2_ba = J2_abᵀ, so Σ_ab η_a η_b J2_ab is symmetric and equals Σ_a η_a K̂_a):
    ///   s = s₀ + Σ_a S_a η_a,   J = J₀ + Σ_a η_a (J1_a + K̂_a),
    ///   L_b = L₀_b + Σ_a L1_ab η_a = L₀_b − Σ_a L1_ba η_a,   ∂J/∂η_a = J1_a + 2 K̂_a,
    /// 6 m² + 3 m² multiply-adds for the quadratic terms, as dot products over contiguous rows
    /// (`j2_sym`, `l1_parts`).
    pub fn at_into(&self, eta: &[f64], out: &mut AtShape) {
        let m = self.modes;
        let mut s = self.s0;
        let mut j = self.j0.0;
        out.dj.clear();
        for a in 0..m {
            let ea = eta[a];
            s = s + self.s[a] * ea;
            let row = a * m..(a + 1) * m;
            let k = Mat3::symmetric(self.j2_sym.each_ref().map(|p| dot4(&p[row.clone()], eta))).0;
            let j1 = &self.j1[a].0;
            let mut dj = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    j[r][c] += (j1[r][c] + k[r][c]) * ea;
                    dj[r][c] = j1[r][c] + 2.0 * k[r][c];
                }
            }
            out.dj.push(Mat3(dj));
        }
        out.l.clear();
        out.l
            .extend((0..m).map(|b| self.l0[b] - self.l1_row(b, eta)));
        out.s = s;
        out.j = Mat3(j);
    }

    /// L̇ = Σ_j η̇_j L1_j, as columns.
    pub fn l_rate(&self, eta_dot: &[f64]) -> Vec<Vec3> {
        let mut out = Vec::new();
        self.l_rate_into(eta_dot, &mut out);
        out
    }

    /// [`Invariants::l_rate`] into `out` (resized to m): L̇_b = −Σ_a L1_ba η̇_a.
    pub fn l_rate_into(&self, eta_dot: &[f64], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend((0..self.modes).map(|b| -self.l1_row(b, eta_dot)));
    }

    /// S η̇.
    pub fn s_rate(&self, eta_dot: &[f64]) -> Vec3 {
        combine(&self.s, eta_dot)
    }

    /// The momenta p = m v + ω × s + S η̇ and h = s × v + J ω + L η̇ (frame components).
    pub fn momenta(&self, at: &AtShape, v: Vec3, w: Vec3, eta_dot: &[f64]) -> (Vec3, Vec3) {
        let p = v * self.mass + w.cross(at.s) + self.s_rate(eta_dot);
        let h = at.s.cross(v) + at.j.apply(w) + combine(&at.l, eta_dot);
        (p, h)
    }

    /// The rates ṗ + ω × p and ḣ + ω × h + v × p: the force and the moment about O that
    /// act on the body (frame components), for accelerations (v̇, ω̇, η̈).
    #[allow(clippy::too_many_arguments)]
    pub fn wrench(
        &self,
        at: &AtShape,
        v: Vec3,
        w: Vec3,
        eta_dot: &[f64],
        v_dot: Vec3,
        w_dot: Vec3,
        eta_ddot: &[f64],
    ) -> (Vec3, Vec3) {
        let (p, h) = self.momenta(at, v, w, eta_dot);
        let s_dot = self.s_rate(eta_dot);
        let j_dot = at
            .dj
            .iter()
            .zip(eta_dot)
            .fold(Mat3::ZERO, |acc, (d, e)| acc + *d * *e);
        let l_dot = self.l_rate(eta_dot);
        let p_dot = v_dot * self.mass + w_dot.cross(at.s) + w.cross(s_dot) + self.s_rate(eta_ddot);
        let h_dot = s_dot.cross(v)
            + at.s.cross(v_dot)
            + j_dot.apply(w)
            + at.j.apply(w_dot)
            + combine(&l_dot, eta_dot)
            + combine(&at.l, eta_ddot);
        (p_dot + w.cross(p), h_dot + w.cross(h) + v.cross(p))
    }
}

/// Σ_j c_j x_j.
pub fn combine(columns: &[Vec3], x: &[f64]) -> Vec3 {
    columns
        .iter()
        .zip(x)
        .fold(Vec3::ZERO, |acc, (c, xi)| acc + *c * *xi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small cloud: three points and a rotary inertia, three modes.
    fn cloud() -> (Vec<MassPoint>, Vec<RotaryPoint>) {
        let v = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
        let points = vec![
            MassPoint {
                mass: 2.0,
                position: v(1.0, 0.5, -0.3),
                shapes: vec![v(0.1, 0.2, 0.3), v(-0.2, 0.1, 0.05), v(0.0, 0.3, -0.1)],
            },
            MassPoint {
                mass: 3.5,
                position: v(-0.4, 2.0, 0.7),
                shapes: vec![v(0.3, -0.1, 0.2), v(0.05, 0.4, -0.2), v(0.1, 0.1, 0.1)],
            },
            MassPoint {
                mass: 1.2,
                position: v(0.2, -1.1, 1.5),
                shapes: vec![v(-0.1, 0.0, 0.4), v(0.2, -0.3, 0.1), v(0.3, 0.2, 0.0)],
            },
        ];
        let rotary = vec![RotaryPoint {
            inertia: Mat3::symmetric([0.5, 0.7, 0.9, 0.1, -0.05, 0.02]),
            rotations: vec![v(0.01, 0.02, 0.0), v(0.0, -0.03, 0.01), v(0.02, 0.0, 0.01)],
        }];
        (points, rotary)
    }

    /// s(η), J(η), L(η) and ∂J/∂η from the invariants against the cloud summed directly at
    /// the deformed positions ρ_p = r_p + Φ_p η (second formulation: J = Σ m ρ̃ᵀρ̃ + Σ I_s,
    /// L_j = Σ m ρ × Φ_pj + Σ I_s Ψ_sj, ∂J/∂η by central differences of that sum), and
    /// L̇ against L's own η-derivative along η̇.
    #[test]
    fn the_invariants_at_a_shape_equal_the_deformed_clouds_sums() {
        let (points, rotary) = cloud();
        let inv = Invariants::of_cloud(3, &points, &rotary);
        let direct = |eta: &[f64]| {
            let (mut s, mut j) = (Vec3::ZERO, Mat3::ZERO);
            let mut l = vec![Vec3::ZERO; 3];
            for p in &points {
                let rho = p.position + combine(&p.shapes, eta);
                s = s + rho * p.mass;
                j = j + skew_t_skew(rho, rho) * p.mass;
                for (lj, f) in l.iter_mut().zip(&p.shapes) {
                    *lj = *lj + rho.cross(*f) * p.mass;
                }
            }
            for r in &rotary {
                j = j + r.inertia;
                for (lj, psi) in l.iter_mut().zip(&r.rotations) {
                    *lj = *lj + r.inertia.apply(*psi);
                }
            }
            (s, j, l)
        };
        let eta = [0.3, -0.7, 0.45];
        let at = inv.at(&eta);
        let (s, j, l) = direct(&eta);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * (1.0 + b.abs());
        for i in 0..3 {
            assert!(close(at.s.get(i), s.get(i)));
            for c in 0..3 {
                assert!(close(at.j.get(i, c), j.get(i, c)), "J {i}{c}");
            }
            for (a, b) in at.l.iter().zip(&l) {
                assert!(close(a.get(i), b.get(i)), "L");
            }
        }
        for a in 0..3 {
            let h = 1e-5;
            let (mut up, mut down) = (eta, eta);
            up[a] += h;
            down[a] -= h;
            let dj = (direct(&up).1 - direct(&down).1) * (0.5 / h);
            for r in 0..3 {
                for c in 0..3 {
                    // J is quadratic in η: the central difference is exact up to rounding.
                    assert!((at.dj[a].get(r, c) - dj.get(r, c)).abs() < 1e-9, "dJ {a}");
                }
            }
        }
        let eta_dot = [0.2, 0.1, -0.4];
        let rate = inv.l_rate(&eta_dot);
        let h = 1e-6;
        let up: Vec<f64> = eta.iter().zip(&eta_dot).map(|(e, d)| e + h * d).collect();
        let down: Vec<f64> = eta.iter().zip(&eta_dot).map(|(e, d)| e - h * d).collect();
        let (lu, ld) = (direct(&up).2, direct(&down).2);
        for b in 0..3 {
            let d = (lu[b] - ld[b]) * (0.5 / h);
            for i in 0..3 {
                assert!((rate[b].get(i) - d.get(i)).abs() < 1e-9, "L̇ {b}");
            }
        }
    }
}
