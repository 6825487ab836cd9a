//! The deployment's own time scales (docs/theory.md §2.9): the frequencies of the folded
//! array's free vibration on its hinge springs, its cable and its captured latches, with the
//! base held. They set what a run must resolve — the base modes it keeps and, with the
//! automatic integrator, its steps — so that nothing of the base's own spectrum does.
//!
//! Model: the planar chain of [`super::chain`] on a held root, linearised about a
//! configuration α: M(α) ẍ + K x = 0 with K = diag(k_j + k_L,j) (the hinge springs, and the
//! latch springs of the hinges a compliant latch holds) plus k_c CᵀC for an elastic cable
//! (C the cable law's rows); with an ideal cable the array has one speed, α̇ = r ṡ with
//! r = (1, 2, 2, …), and one frequency, ω² = rᵀKr / rᵀM r (Rayleigh's quotient on it).
//! Hinge damping and friction add no frequency (they make the motion decay or stick, which
//! an L-stable step follows without resolving it).

use super::chain::{Chain, PlanarHub};
use super::coupled::{Coupled, Synchronisation};

/// The array's free vibration frequencies about `alpha` (rad/s, ascending) with the base
/// held, on its hinge springs plus the latch springs `latch` (N·m/rad per hinge: 0 for a
/// hinge no latch holds), tied by `sync`, its hinges flagged in `moving` free and the
/// others locked (M and K restricted to the moving hinges' angles). Empty when the problem
/// is degenerate or nothing moves.
pub fn array_frequencies(
    chain: &Chain,
    alpha: &[f64],
    latch: &[f64],
    sync: Synchronisation,
    moving: &[bool],
) -> Vec<f64> {
    let n = chain.len();
    let idx: Vec<usize> = (0..n)
        .filter(|&i| moving.get(i).copied().unwrap_or(true))
        .collect();
    if idx.is_empty() {
        return Vec::new();
    }
    let held = Chain {
        hub: PlanarHub::Fixed,
        ..chain.clone()
    };
    let whole = held.mass_matrix(alpha);
    let mut kw = faer::Mat::<f64>::from_fn(n, n, |i, j| {
        if i == j {
            held.hinges[i].stiffness + latch.get(i).copied().unwrap_or(0.0)
        } else {
            0.0
        }
    });
    if let Synchronisation::ElasticCable(kc) = sync {
        for row in Coupled::cable_law(n) {
            for i in 0..n {
                for j in 0..n {
                    kw[(i, j)] += kc * row[i] * row[j];
                }
            }
        }
    }
    let nf = idx.len();
    let m = faer::Mat::<f64>::from_fn(nf, nf, |a, b| whole[(idx[a], idx[b])]);
    let k = faer::Mat::<f64>::from_fn(nf, nf, |a, b| kw[(idx[a], idx[b])]);
    let n = nf;
    let omega = |lam: f64| lam.max(0.0).sqrt();
    if sync == Synchronisation::IdealCable && nf == chain.len() {
        let r: Vec<f64> = (0..n).map(|i| if i == 0 { 1.0 } else { 2.0 }).collect();
        let quad = |a: &faer::Mat<f64>| -> f64 {
            (0..n)
                .map(|i| (0..n).map(|j| r[i] * a[(i, j)] * r[j]).sum::<f64>())
                .sum()
        };
        let w = omega(quad(&k) / quad(&m));
        return if w.is_finite() { vec![w] } else { Vec::new() };
    }
    crate::ritz::eigen::generalized_symmetric(&k, &m)
        .map(|(lam, _)| {
            lam.into_iter()
                .map(omega)
                .filter(|w| w.is_finite())
                .collect()
        })
        .unwrap_or_default()
}

/// The latch mode's period, s: the slowest free vibration of the captured array about its
/// latch angles with the base held ([`array_frequencies`] with every latch spring acting).
/// On seed_compliant (ideal cable) 0.406 s (15.49 rad/s), against 0.403 s (15.6 rad/s) for
/// the coupled mode on the free, flexible spacecraft. Zero when the problem is degenerate
/// (no panels).
pub fn latch_period(chain: &Chain, stiffness: &[f64], sync: Synchronisation) -> f64 {
    let q: Vec<f64> = chain.hinges.iter().map(|h| h.latch_angle).collect();
    match array_frequencies(chain, &q, stiffness, sync, &[]).first() {
        Some(&w) if w > 0.0 => 2.0 * std::f64::consts::PI / w,
        _ => 0.0,
    }
}

/// The fastest motion of the array, rad/s: the highest frequency of [`array_frequencies`]
/// (the hinges flagged in `moving`) at the stowed (initial) angles, halfway and at the latch
/// angles, with the latch springs `latch` acting, and the moving hinges' initial rates
/// |α̇_j(0)| (a hinge released spinning turns by a radian in 1/|α̇| s). Zero when nothing
/// moves the array (no spring, no rate).
pub fn fastest(chain: &Chain, latch: &[f64], sync: Synchronisation, moving: &[bool]) -> f64 {
    let at = |s: f64| -> Vec<f64> {
        chain
            .hinges
            .iter()
            .map(|h| h.initial_angle + s * (h.latch_angle - h.initial_angle))
            .collect()
    };
    let springs = [0.0, 0.5, 1.0]
        .iter()
        .filter_map(|&s| {
            array_frequencies(chain, &at(s), latch, sync, moving)
                .last()
                .copied()
        })
        .fold(0.0, f64::max);
    chain
        .hinges
        .iter()
        .enumerate()
        .filter(|(i, _)| moving.get(*i).copied().unwrap_or(true))
        .map(|(_, h)| h.initial_rate.abs())
        .fold(springs, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deploy::chain::{Hinge, Panel};

    fn one_panel(k: f64, mass: f64, length: f64) -> Chain {
        Chain {
            hub: PlanarHub::Fixed,
            root: [0.0, 0.0],
            panels: vec![Panel {
                length,
                mass,
                inertia: mass * length * length / 12.0,
            }],
            hinges: vec![Hinge {
                stiffness: k,
                reference_angle: 2.0,
                damping: 0.0,
                friction: 0.0,
                latch_angle: std::f64::consts::FRAC_PI_2,
                initial_angle: 0.0,
                initial_rate: 0.0,
            }],
        }
    }

    /// A single panel on its hinge spring: ω² = k / I_hinge, I_hinge = m l² / 3 (a uniform
    /// bar about its end), whatever the angle; with a latch spring, ω² = (k + k_L) / I_hinge.
    #[test]
    fn one_panel_vibrates_at_the_closed_form() {
        let (k, m, l) = (3.0, 2.0, 1.5);
        let c = one_panel(k, m, l);
        let i = m * l * l / 3.0;
        let w = array_frequencies(&c, &[0.7], &[0.0], Synchronisation::None, &[]);
        assert_eq!(w.len(), 1);
        assert!((w[0] - (k / i).sqrt()).abs() < 1e-12 * w[0], "{w:?}");
        let kl = 50.0;
        let w = array_frequencies(&c, &[0.7], &[kl], Synchronisation::None, &[]);
        assert!((w[0] - ((k + kl) / i).sqrt()).abs() < 1e-12 * w[0], "{w:?}");
        let period = latch_period(&c, &[kl], Synchronisation::None);
        assert!((period - 2.0 * std::f64::consts::PI / ((k + kl) / i).sqrt()).abs() < 1e-12);
        assert!((fastest(&c, &[0.0], Synchronisation::None, &[]) - (k / i).sqrt()).abs() < 1e-12);
        assert!(fastest(&c, &[0.0], Synchronisation::None, &[false]) == 0.0);
    }

    /// Two equal panels folded flat (α₂ = π: the second lies back on the first) on equal
    /// springs, held root: the chain's mass matrix there is, with I = m l²/12 and the second
    /// panel's centre back at l/2 from the root, M = [[I₁ + I₂ + m l²/4·2 − …]]; rather than
    /// expanding it, check the two frequencies against the eigenvalues of the 2 × 2 problem
    /// assembled independently from the bars' kinetic energy (points along each bar).
    #[test]
    fn two_panels_match_the_kinetic_energy_of_their_points() {
        let (k1, k2, m, l) = (5.0, 2.0, 1.3, 0.8);
        let mut c = one_panel(k1, m, l);
        c.panels.push(c.panels[0]);
        c.hinges.push(Hinge {
            stiffness: k2,
            latch_angle: std::f64::consts::PI,
            ..c.hinges[0]
        });
        let alpha = [0.4, 1.9];
        // Angles: panel 1 at φ₁ = α₁, panel 2 at φ₂ = α₁ + α₂ − π (the accordion's fold);
        // only the Jacobian ∂φ/∂α and the points' positions matter for M.
        let points = 400;
        let mut mm = [[0.0; 2]; 2];
        let phi1 = alpha[0];
        let phi2 = alpha[0] + alpha[1] - std::f64::consts::PI;
        let (e1, e2) = ([phi1.cos(), phi1.sin()], [phi2.cos(), phi2.sin()]);
        let tip1 = [l * e1[0], l * e1[1]];
        for p in 0..points {
            let s = (p as f64 + 0.5) / points as f64 * l;
            let dm = m / points as f64;
            // Panel 1's point: r = s e1, ∂r/∂α₁ = s e1⊥, ∂r/∂α₂ = 0.
            let d1 = [[-s * e1[1], s * e1[0]], [0.0, 0.0]];
            // Panel 2's point: r = tip1 + s e2, ∂r/∂α₁ = tip1⊥ + s e2⊥, ∂r/∂α₂ = s e2⊥.
            let d2 = [
                [-tip1[1] - s * e2[1], tip1[0] + s * e2[0]],
                [-s * e2[1], s * e2[0]],
            ];
            for d in [d1, d2] {
                for a in 0..2 {
                    for b in 0..2 {
                        mm[a][b] += dm * (d[a][0] * d[b][0] + d[a][1] * d[b][1]);
                    }
                }
            }
        }
        // det(K − λ M) = 0 for the 2 × 2 pencil.
        let (a, b, cc) = (
            mm[0][0] * mm[1][1] - mm[0][1] * mm[1][0],
            -(k1 * mm[1][1] + k2 * mm[0][0]),
            k1 * k2,
        );
        let disc = (b * b - 4.0 * a * cc).sqrt();
        let mut want = [
            ((-b - disc) / (2.0 * a)).sqrt(),
            ((-b + disc) / (2.0 * a)).sqrt(),
        ];
        want.sort_by(f64::total_cmp);
        let got = array_frequencies(&c, &alpha, &[0.0, 0.0], Synchronisation::None, &[]);
        // Hinge 1 locked: panel 2 alone on its hinge, about its end: ω² = k₂ / (m l²/3).
        let alone = array_frequencies(
            &c,
            &alpha,
            &[0.0, 0.0],
            Synchronisation::None,
            &[false, true],
        );
        assert!((alone[0] - (k2 / (m * l * l / 3.0)).sqrt()).abs() < 1e-12 * alone[0]);
        assert_eq!(got.len(), 2, "{got:?}");
        for (g, w) in got.iter().zip(want) {
            // The midpoint rule's error on the bars' l²/12 terms: 1/(4 points²) relative.
            assert!((g - w).abs() < 1e-5 * w, "{got:?} vs {want:?}");
        }
    }
}
