//! The folded array's opening angles eliminated in O(N) (docs/theory.md §2.7): the
//! articulated-body recursion of the planar chain with its root held, which solves
//!   M_αα,FF x_F = τ_F   (x = 0 on the locked hinges)
//! for the chain's mass matrix over the opening rates without forming it.
//!
//! M_αα is the mass matrix of N rigid panels in the hinge plane, hinge l turning every panel
//! i ≥ l about the hinge point H_l at the rate d_l α̇_l (d_l = ∓1 by the fold's alternation):
//!   M_kl = d_k d_l Σ_{i ≥ max(k,l)} [m_i (C_i − H_k)·(C_i − H_l) + I_i].
//! Planar motion vectors (a_x, a_y, ε) and force vectors (f_x, f_y, n) are taken at each
//! panel's own hinge point. Moving the reference point by r, X(r) = [1 0 −r_y; 0 1 r_x; 0 0 1]
//! maps a motion vector and Xᵀ a force vector back; panel i's inertia about H_i is
//! X(C_i − H_i)ᵀ diag(m_i, m_i, I_i) X(C_i − H_i), hinge i's motion subspace s_i = (0, 0, d_i).
//! Tip to root (Featherstone, "Rigid Body Dynamics Algorithms", Springer 2008, §7.3, with no
//! velocity terms and a held root):
//!   I^A_i = I_i + X_{i+1}ᵀ (I^A_{i+1} − U_{i+1} U_{i+1}ᵀ / D_{i+1}) X_{i+1},
//!   U_i = I^A_i s_i,   D_i = s_iᵀ U_i,
//! with I^A_{i+1} passed whole through a locked hinge (it welds panel i + 1 to panel i);
//! per right-hand side τ the bias p^A runs the same way and the accelerations root to tip:
//!   α̈_i = (τ_i − s_iᵀ p^A_i − U_iᵀ a'_i) / D_i,   a_i = a'_i + s_i α̈_i,   a'_{i+1} = X_{i+1} a_i.
//! Hand-written: a recursion over the panels, not a linear-algebra kernel.

use super::chain::Chain;

type M3 = [[f64; 3]; 3];

/// X(r)ᵀ A X(r) for a symmetric planar inertia A: the same inertia about a point r nearer
/// the root (r from that point to A's reference point).
fn shift(a: &M3, r: [f64; 2]) -> M3 {
    // X = I + E with E having −r_y, r_x in its last column; XᵀAX = A + AE + EᵀA + EᵀAE.
    let (ry, rx) = (r[1], r[0]);
    // A X: column 2 gains −r_y A[:,0] + r_x A[:,1].
    let col2 = |m: &M3, i: usize| m[i][2] - ry * m[i][0] + rx * m[i][1];
    let ax: M3 = std::array::from_fn(|i| [a[i][0], a[i][1], col2(a, i)]);
    // Xᵀ (A X): row 2 gains −r_y (AX)[0,:] + r_x (AX)[1,:].
    std::array::from_fn(|i| {
        if i < 2 {
            ax[i]
        } else {
            std::array::from_fn(|j| ax[2][j] - ry * ax[0][j] + rx * ax[1][j])
        }
    })
}

/// The factored recursion for one configuration and one set of free hinges.
#[derive(Debug, Default)]
pub(crate) struct Articulated {
    /// U_i = I^A_i s_i.
    u: Vec<[f64; 3]>,
    /// D_i (zero for a locked hinge).
    d: Vec<f64>,
    /// d_i, the sign of hinge i's rotation.
    sign: Vec<f64>,
    /// H_{i+1} − H_i (i < N − 1).
    step: Vec<[f64; 2]>,
    free: Vec<bool>,
    /// p^A_i of the last solve.
    pa: Vec<[f64; 3]>,
}

/// One panel as the recursion needs it: mass, in-plane inertia about its centre, centre and
/// hinge point in the hinge plane.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PlanarPanel {
    pub mass: f64,
    pub inertia: f64,
    pub centre: [f64; 2],
    pub hinge: [f64; 2],
}

impl Articulated {
    /// The tip-to-root pass for `panels` (root first) with the hinges flagged `free`.
    /// False when a free hinge's D_i is not positive (a degenerate or non-finite state).
    pub fn factor(&mut self, panels: &[PlanarPanel], free: &[bool]) -> bool {
        let n = panels.len();
        self.u.clear();
        self.u.resize(n, [0.0; 3]);
        self.d.clear();
        self.d.resize(n, 0.0);
        self.sign.clear();
        self.sign.extend((0..n).map(Chain::d));
        self.step.clear();
        self.step.extend(
            panels
                .windows(2)
                .map(|w| [w[1].hinge[0] - w[0].hinge[0], w[1].hinge[1] - w[0].hinge[1]]),
        );
        self.free.clear();
        self.free.extend_from_slice(&free[..n]);
        let mut ok = true;
        // What panel i + 1's subtree passes to panel i, about H_{i+1}.
        let mut passed: M3 = [[0.0; 3]; 3];
        for i in (0..n).rev() {
            let p = &panels[i];
            let r = [p.centre[0] - p.hinge[0], p.centre[1] - p.hinge[1]];
            let own: M3 = [
                [p.mass, 0.0, -p.mass * r[1]],
                [0.0, p.mass, p.mass * r[0]],
                [
                    -p.mass * r[1],
                    p.mass * r[0],
                    p.inertia + p.mass * (r[0] * r[0] + r[1] * r[1]),
                ],
            ];
            let child = if i + 1 < n {
                shift(&passed, self.step[i])
            } else {
                [[0.0; 3]; 3]
            };
            let ia: M3 = std::array::from_fn(|a| std::array::from_fn(|b| own[a][b] + child[a][b]));
            passed = ia;
            if self.free[i] {
                let s = self.sign[i];
                let u = [s * ia[0][2], s * ia[1][2], s * ia[2][2]];
                let d = ia[2][2];
                ok &= d > 0.0 && d.is_finite();
                self.u[i] = u;
                self.d[i] = d;
                for a in 0..3 {
                    for b in 0..3 {
                        passed[a][b] -= u[a] * u[b] / d;
                    }
                }
            }
        }
        ok
    }

    /// x with M_αα,FF x_F = τ_F and x = 0 on the locked hinges (the root held), for the
    /// factor of the last [`Articulated::factor`].
    pub fn solve(&mut self, tau: &[f64], x: &mut [f64]) {
        let n = self.d.len();
        self.pa.clear();
        self.pa.resize(n, [0.0; 3]);
        let mut passed = [0.0; 3];
        for i in (0..n).rev() {
            let pa = if i + 1 < n {
                // Xᵀ f about H_i from f about H_{i+1}: the moment gains r × f.
                let r = self.step[i];
                [
                    passed[0],
                    passed[1],
                    passed[2] + r[0] * passed[1] - r[1] * passed[0],
                ]
            } else {
                [0.0; 3]
            };
            self.pa[i] = pa;
            passed = pa;
            if self.free[i] {
                let ui = tau[i] - self.sign[i] * pa[2];
                let k = ui / self.d[i];
                for (p, u) in passed.iter_mut().zip(&self.u[i]) {
                    *p += u * k;
                }
            }
        }
        let mut a = [0.0; 3]; // a'_i: panel i's hinge point held by its parent's motion
        for i in 0..n {
            if i > 0 {
                let r = self.step[i - 1];
                a = [a[0] - a[2] * r[1], a[1] + a[2] * r[0], a[2]];
            }
            x[i] = if self.free[i] {
                let ui = tau[i] - self.sign[i] * self.pa[i][2];
                let ua: f64 = self.u[i].iter().zip(&a).map(|(u, v)| u * v).sum();
                (ui - ua) / self.d[i]
            } else {
                0.0
            };
            a[2] += self.sign[i] * x[i];
        }
    }
}

/// M_αα x in O(N) from the outboard sums of [`super::coupled`]'s chain (S0, B_l, A_l about
/// hinge l): for k ≤ l, M_kl = d_k d_l (a_l − H_k·B_l) with a_l = A_l + H_l·B_l, so
///   (M x)_k = d_k [Σ_{l≥k} y_l a_l − H_k·Σ_{l≥k} y_l B_l + a_k Σ_{l<k} y_l − B_k·Σ_{l<k} y_l H_l],
/// y_l = d_l x_l (suffix and prefix sums). The hinge points enter absolutely (a_l and H_k·B_l)
/// where the dense M_kl takes the difference H_l − H_k: for a 100-panel wing some 2 of 16
/// digits go, which the test against the definition allows for.
pub(crate) fn mass_times(
    hinges: &[[f64; 2]],
    bsum: &[[f64; 2]],
    asum: &[f64],
    x: &[f64],
    out: &mut [f64],
) {
    let n = x.len();
    let sign = Chain::d;
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let a = |l: usize| asum[l] + dot(hinges[l], bsum[l]);
    // Suffix sums, stored in `out` as the first part of each row.
    let (mut sa, mut sb) = (0.0, [0.0; 2]);
    for k in (0..n).rev() {
        let y = sign(k) * x[k];
        sa += y * a(k);
        sb = [sb[0] + y * bsum[k][0], sb[1] + y * bsum[k][1]];
        out[k] = sa - dot(hinges[k], sb);
    }
    let (mut py, mut ph) = (0.0, [0.0; 2]);
    for k in 0..n {
        out[k] = sign(k) * (out[k] + a(k) * py - dot(bsum[k], ph));
        let y = sign(k) * x[k];
        py += y;
        ph = [ph[0] + y * hinges[k][0], ph[1] + y * hinges[k][1]];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mass matrix by its definition (a second formulation, O(N³)).
    fn dense(panels: &[PlanarPanel]) -> Vec<Vec<f64>> {
        let n = panels.len();
        let d = Chain::d;
        let mut m = vec![vec![0.0; n]; n];
        for k in 0..n {
            for l in 0..n {
                let (hk, hl) = (panels[k].hinge, panels[l].hinge);
                m[k][l] = d(k)
                    * d(l)
                    * panels[k.max(l)..]
                        .iter()
                        .map(|p| {
                            let (a, b) = (
                                [p.centre[0] - hk[0], p.centre[1] - hk[1]],
                                [p.centre[0] - hl[0], p.centre[1] - hl[1]],
                            );
                            p.mass * (a[0] * b[0] + a[1] * b[1]) + p.inertia
                        })
                        .sum::<f64>();
            }
        }
        m
    }

    /// A folded chain of `n` panels at an arbitrary configuration.
    fn chain(n: usize) -> Vec<PlanarPanel> {
        let mut h = [0.3, -0.2];
        let mut phi = 1.1_f64;
        (0..n)
            .map(|i| {
                let len = 1.0 + 0.3 * (i as f64 * 1.7).sin();
                phi += 2.0 + 0.4 * (i as f64).cos();
                let e = [phi.cos(), phi.sin()];
                let p = PlanarPanel {
                    mass: 10.0 + 3.0 * (i as f64 * 0.9).cos(),
                    inertia: 2.0 + (i as f64 * 0.5).sin(),
                    centre: [h[0] + 0.5 * len * e[0], h[1] + 0.5 * len * e[1]],
                    hinge: h,
                };
                h = [h[0] + len * e[0], h[1] + len * e[1]];
                p
            })
            .collect()
    }

    #[test]
    fn solves_the_mass_matrix_on_the_free_hinges() {
        for n in [1, 2, 3, 7, 20] {
            let panels = chain(n);
            let m = dense(&panels);
            for pattern in 0..4u32 {
                let free: Vec<bool> = (0..n)
                    .map(|i| pattern == 0 || (i as u32 + pattern) % 3 != 0)
                    .collect();
                let tau: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).cos() + 0.2).collect();
                let mut art = Articulated::default();
                assert!(art.factor(&panels, &free));
                let mut x = vec![f64::NAN; n];
                art.solve(&tau, &mut x);
                let scale = tau.iter().map(|t| t.abs()).fold(0.0, f64::max);
                for k in 0..n {
                    if free[k] {
                        let mx: f64 = (0..n).map(|l| m[k][l] * x[l]).sum();
                        assert!(
                            (mx - tau[k]).abs() < 1e-11 * scale,
                            "n {n} row {k}: {mx} vs {}",
                            tau[k]
                        );
                    } else {
                        assert_eq!(x[k], 0.0);
                    }
                }
            }
        }
    }

    #[test]
    fn the_product_in_linear_time_equals_the_definition() {
        for n in [1, 2, 5, 12] {
            let panels = chain(n);
            let m = dense(&panels);
            // Outboard sums about each hinge, by their definition.
            let hinges: Vec<[f64; 2]> = panels.iter().map(|p| p.hinge).collect();
            let bsum: Vec<[f64; 2]> = (0..n)
                .map(|l| {
                    panels[l..].iter().fold([0.0; 2], |s, p| {
                        [
                            s[0] + p.mass * (p.centre[0] - hinges[l][0]),
                            s[1] + p.mass * (p.centre[1] - hinges[l][1]),
                        ]
                    })
                })
                .collect();
            let asum: Vec<f64> = (0..n)
                .map(|l| {
                    panels[l..]
                        .iter()
                        .map(|p| {
                            let r = [p.centre[0] - hinges[l][0], p.centre[1] - hinges[l][1]];
                            p.mass * (r[0] * r[0] + r[1] * r[1]) + p.inertia
                        })
                        .sum()
                })
                .collect();
            let x: Vec<f64> = (0..n).map(|i| 1.0 + 0.5 * (i as f64).sin()).collect();
            let mut out = vec![0.0; n];
            mass_times(&hinges, &bsum, &asum, &x, &mut out);
            for k in 0..n {
                let want: f64 = (0..n).map(|l| m[k][l] * x[l]).sum();
                assert!(
                    (out[k] - want).abs() < 1e-11 * want.abs().max(1.0),
                    "n {n} row {k}"
                );
            }
        }
    }
}
