//! A second, independent formulation of the deployment (the paper's form, (2.1)–(2.3)):
//! every panel has its own coordinates (x_i, y_i, φ_i); the hinges are position constraints
//! whose reactions λ are solved together with the accelerations at every step,
//!   [M Gᵀ; G 0] [a; −λ] = [Q; −γ − 2βċ − β²c]   (Baumgarte drift control),
//! integrated by classical RK4 with a fixed step; a latch adds the lock constraint
//! φ_j − φ_{j−1} = const (φ_1 = const for the root hinge) and the velocities jump by the
//! impulse solution [M Gᵀ; G 0][v⁺; −Λ] = [M v⁻; 0]. Latch times and rates must agree with the
//! minimal-coordinate DOPRI5 solution to 1e-8.

use flexcraft::deploy::chain::{Chain, PlanarHub};
use flexcraft::deploy::{simulate, Latching};
use std::f64::consts::PI;

struct Maximal<'a> {
    chain: &'a Chain,
    locked: Vec<Option<f64>>,
}

fn e(p: f64) -> [f64; 2] {
    [p.cos(), p.sin()]
}

fn sign(i: usize) -> f64 {
    // s_i = (−1)^{i−1} for 1-based i; here i is 0-based.
    if i % 2 == 0 {
        1.0
    } else {
        -1.0
    }
}

/// Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap();
        a.swap(k, p);
        b.swap(k, p);
        for i in k + 1..n {
            let f = a[i][k] / a[k][k];
            for j in k..n {
                a[i][j] -= f * a[k][j];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k][j] * x[j]).sum();
        x[k] = (b[k] - s) / a[k][k];
    }
    x
}

impl Maximal<'_> {
    fn n(&self) -> usize {
        self.chain.len()
    }

    fn alpha(&self, x: &[f64], i: usize) -> f64 {
        if i == 0 {
            PI / 2.0 - x[2]
        } else {
            PI - sign(i) * (x[3 * i + 2] - x[3 * (i - 1) + 2])
        }
    }

    /// Constraint rows (G), their values c and velocity terms γ.
    fn constraints(&self, x: &[f64], v: &[f64]) -> (Vec<Vec<f64>>, Vec<f64>, Vec<f64>) {
        let n = self.n();
        let mut g = Vec::new();
        let mut c = Vec::new();
        let mut gam = Vec::new();
        for i in 0..n {
            let l = self.chain.panels[i].length;
            let (p, w) = (x[3 * i + 2], v[3 * i + 2]);
            let mut rows = [vec![0.0; 3 * n], vec![0.0; 3 * n]];
            let mut val = [
                x[3 * i] - 0.5 * l * e(p)[0],
                x[3 * i + 1] - 0.5 * l * e(p)[1],
            ];
            let mut gm = [0.5 * l * e(p)[0] * w * w, 0.5 * l * e(p)[1] * w * w];
            for d in 0..2 {
                rows[d][3 * i + d] = 1.0;
                // ∂/∂φ of −(l/2) e(φ) = −(l/2) perp(e) = (l/2)(sin, −cos).
                rows[d][3 * i + 2] = 0.5 * l * [p.sin(), -p.cos()][d];
            }
            if i == 0 {
                val[0] -= self.chain.root[0];
                val[1] -= self.chain.root[1];
            } else {
                let lp = self.chain.panels[i - 1].length;
                let (pp, wp) = (x[3 * (i - 1) + 2], v[3 * (i - 1) + 2]);
                for d in 0..2 {
                    rows[d][3 * (i - 1) + d] = -1.0;
                    rows[d][3 * (i - 1) + 2] = 0.5 * lp * [pp.sin(), -pp.cos()][d];
                    val[d] -= x[3 * (i - 1) + d] + 0.5 * lp * e(pp)[d];
                    gm[d] += 0.5 * lp * e(pp)[d] * wp * wp;
                }
            }
            for d in 0..2 {
                g.push(rows[d].clone());
                c.push(val[d]);
                gam.push(gm[d]);
            }
            if let Some(lock) = self.locked[i] {
                let mut row = vec![0.0; 3 * n];
                row[3 * i + 2] = 1.0;
                let mut value = x[3 * i + 2];
                if i > 0 {
                    row[3 * (i - 1) + 2] = -1.0;
                    value -= x[3 * (i - 1) + 2];
                }
                g.push(row);
                c.push(value - lock);
                gam.push(0.0);
            }
        }
        (g, c, gam)
    }

    fn kkt(&self, g: &[Vec<f64>], top: Vec<f64>, bottom: Vec<f64>) -> Vec<f64> {
        let n3 = 3 * self.n();
        let m = g.len();
        let mut a = vec![vec![0.0; n3 + m]; n3 + m];
        for i in 0..self.n() {
            let p = &self.chain.panels[i];
            a[3 * i][3 * i] = p.mass;
            a[3 * i + 1][3 * i + 1] = p.mass;
            a[3 * i + 2][3 * i + 2] = p.inertia;
        }
        for (r, row) in g.iter().enumerate() {
            for j in 0..n3 {
                a[n3 + r][j] = row[j];
                a[j][n3 + r] = row[j];
            }
        }
        let b: Vec<f64> = top.into_iter().chain(bottom).collect();
        solve(a, b)[..n3].to_vec()
    }

    fn accel(&self, x: &[f64], v: &[f64]) -> Vec<f64> {
        let n = self.n();
        let mut q = vec![0.0; 3 * n];
        for i in 0..n {
            let h = &self.chain.hinges[i];
            let tau = h.stiffness * (h.reference_angle - self.alpha(x, i));
            // δα_1 = −δφ_1; δα_i = −s_i (δφ_i − δφ_{i−1}).
            if i == 0 {
                q[2] -= tau;
            } else {
                q[3 * i + 2] -= sign(i) * tau;
                q[3 * (i - 1) + 2] += sign(i) * tau;
            }
        }
        let (g, c, gam) = self.constraints(x, v);
        let beta = 5.0;
        let cd: Vec<f64> = g
            .iter()
            .map(|row| row.iter().zip(v).map(|(a, b)| a * b).sum())
            .collect();
        let rhs: Vec<f64> = (0..g.len())
            .map(|r| -gam[r] - 2.0 * beta * cd[r] - beta * beta * c[r])
            .collect();
        self.kkt(&g, q, rhs)
    }

    fn rk4(&self, x: &[f64], v: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
        let add = |a: &[f64], b: &[f64], s: f64| -> Vec<f64> {
            a.iter().zip(b).map(|(p, q)| p + s * q).collect()
        };
        let a1 = self.accel(x, v);
        let (x2, v2) = (add(x, v, h / 2.0), add(v, &a1, h / 2.0));
        let a2 = self.accel(&x2, &v2);
        let (x3, v3) = (add(x, &v2, h / 2.0), add(v, &a2, h / 2.0));
        let a3 = self.accel(&x3, &v3);
        let (x4, v4) = (add(x, &v3, h), add(v, &a3, h));
        let a4 = self.accel(&x4, &v4);
        let xn = (0..x.len())
            .map(|i| x[i] + h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]))
            .collect();
        let vn = (0..x.len())
            .map(|i| v[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]))
            .collect();
        (xn, vn)
    }

    fn rate(&self, v: &[f64], i: usize) -> f64 {
        if i == 0 {
            -v[2]
        } else {
            -sign(i) * (v[3 * i + 2] - v[3 * (i - 1) + 2])
        }
    }
}

#[test]
fn maximal_coordinates_with_reactions_agree_with_minimal_coordinates() {
    let mut c = super::deploy::chain(3, PlanarHub::Fixed, 4.0, 0.25);
    c.hinges[0].stiffness = 12.0;
    let minimal = simulate(&super::deploy::deployment(
        c.clone(),
        Latching::Sequential,
        1e-13,
    ));
    assert_eq!(minimal.latches.len(), 3);

    let n = c.len();
    let cfg = c.configuration(&[0.0; 3]);
    let mut x: Vec<f64> = (0..n)
        .flat_map(|i| [cfg.centres[i][0], cfg.centres[i][1], cfg.phi[i]])
        .collect();
    let mut v = vec![0.0; 3 * n];
    let mut sys = Maximal {
        chain: &c,
        locked: vec![None; n],
    };
    let (mut t, h) = (0.0, 2e-3);
    let mut events = Vec::new();
    while events.len() < n && t < 200.0 {
        let (xn, vn) = sys.rk4(&x, &v, h);
        let crossed = (0..n)
            .find(|&i| sys.locked[i].is_none() && sys.alpha(&xn, i) >= c.hinges[i].latch_angle);
        match crossed {
            None => {
                x = xn;
                v = vn;
                t += h;
            }
            Some(j) => {
                // Bisect the sub-step length τ at which α_j reaches the latch angle.
                let (mut lo, mut hi) = (0.0, h);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    let (xm, _) = sys.rk4(&x, &v, mid);
                    if sys.alpha(&xm, j) >= c.hinges[j].latch_angle {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let (xe, ve) = sys.rk4(&x, &v, hi);
                let rates: Vec<f64> = (0..n).map(|i| sys.rate(&ve, i)).collect();
                t += hi;
                events.push((t, j, rates));
                let lock = if j == 0 {
                    xe[2]
                } else {
                    xe[3 * j + 2] - xe[3 * (j - 1) + 2]
                };
                sys.locked[j] = Some(lock);
                // Plastic impact: [M Gᵀ; G 0][v⁺; ·] = [M v⁻; 0].
                let (g, _, _) = sys.constraints(&xe, &ve);
                let mv: Vec<f64> = (0..3 * n)
                    .map(|k| {
                        ve[k]
                            * if k % 3 == 2 {
                                c.panels[k / 3].inertia
                            } else {
                                c.panels[k / 3].mass
                            }
                    })
                    .collect();
                v = sys.kkt(&g, mv, vec![0.0; g.len()]);
                x = xe;
            }
        }
    }
    assert_eq!(events.len(), n);
    for ((t, j, rates), ev) in events.iter().zip(&minimal.latches) {
        assert_eq!(j + 1, ev.hinge);
        assert!(
            (t - ev.time).abs() < 1e-8,
            "hinge {}: {t} vs {}",
            ev.hinge,
            ev.time
        );
        for (a, b) in rates.iter().zip(&ev.rates_before) {
            assert!((a - b).abs() < 1e-8, "hinge {}: rate {a} vs {b}", ev.hinge);
        }
    }
}
