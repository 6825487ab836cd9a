//! The coupled deployment (docs/theory.md §2: the array on the flexible, free-floating base as one
//! system) against independent truths: the planar chain of `deploy::chain` in the rigid
//! limit, and conservation laws on an elastic base.

use flexcraft::deploy::base::BaseKind;
use flexcraft::deploy::coupled::{Coupled, Synchronisation};
use flexcraft::deploy::{simulate, Deployment};
use flexcraft::scenario::Scenario;

use super::common::edited_example as scenario;

/// The coupled model of a scenario's deployment (hub motion from `[hub] motion`, no cable,
/// the given base).
pub fn coupled(sc: &Scenario, kind: BaseKind) -> Coupled {
    let d = Deployment {
        base: kind,
        synchronisation: Synchronisation::None,
        ..sc.deployment.clone().unwrap()
    };
    d.coupled(&sc.structure).unwrap()
}

/// A hub-only base (no beams) is the rigid planar problem: the coupled model's latch times
/// and rates equal the planar chain's (held and free hub; the wing's root lies in the hub's
/// principal plane, so the free hub's motion stays planar).
#[test]
fn hub_only_base_reproduces_the_planar_chain() {
    for motion in ["free", "fixed"] {
        let sc = scenario("free_hub.toml", |s| {
            s.replace("motion = \"free\"", &format!("motion = \"{motion}\""))
                .replace("hub = \"free\"", &format!("hub = \"{motion}\""))
        });
        // Both formulations by the explicit integrator at the scenario's tolerance.
        let d = &Deployment {
            integrator: flexcraft::deploy::Integrator::Explicit,
            ..sc.deployment.clone().unwrap()
        };
        let planar = simulate(d);
        let c = coupled(&sc, BaseKind::Flexible { modes: None });
        assert_eq!(c.modes(), 0);
        let run = c.simulate(false, d.end_time, d.tolerance);
        assert_eq!(run.latches.len(), planar.latches.len(), "{motion}");
        for (a, b) in run.latches.iter().zip(&planar.latches) {
            assert_eq!(a.hinge, b.hinge);
            assert!(
                (a.time - b.time).abs() <= 1e-9 * b.time,
                "{motion}: latch {} at {} vs planar {}",
                a.hinge,
                a.time,
                b.time
            );
            for (x, y) in a.rates_after.iter().zip(&b.rates_after) {
                assert!((x - y).abs() <= 1e-8, "{motion}: rate {x} vs {y}");
            }
        }
    }
}

/// Free hub, elastic mast, no damping: linear and angular momentum stay zero (the system
/// starts at rest) from release through every latch, energy (kinetic + hinge springs +
/// elastic) is constant between latches, and each latch loses ½ Δuᵀ M Δu.
#[test]
fn elastic_base_conserves_momentum_and_energy_and_latches_lose_the_metric_energy() {
    // The seed (free hub) without its cable: independent hinges, some of which latch by its
    // end time; tolerance 1e-12 so that energy holds to 1e-9 between latches.
    let sc = scenario("seed.toml", |s| s);
    let d = sc.deployment.as_ref().unwrap();
    let c = coupled(&sc, BaseKind::Flexible { modes: Some(4) });
    assert_eq!(c.modes(), 4);
    let run = c.simulate(false, d.end_time, 1e-12);
    // The latches the run must cross: those of the planar chain on a rigid base (the
    // deployment's second formulation, deploy/chain.rs) by the end time, in the same order;
    // the elastic base shifts them by far less than their spacing.
    let planar = flexcraft::deploy::simulate(d);
    let order: Vec<usize> = planar.latches.iter().map(|e| e.hinge).collect();
    assert!(order.len() >= 2);
    assert!(
        run.latches.iter().map(|e| e.hinge).collect::<Vec<_>>() == order,
        "the planar chain latches {order:?}: stopped at {} after {} evaluations, latches {:?}",
        run.final_time,
        run.steps,
        run.latches
            .iter()
            .map(|l| (l.hinge, l.time))
            .collect::<Vec<_>>()
    );
    let energy = |y: &[f64]| c.kinetic_energy(y) + c.spring_energy(y) + c.elastic_energy(y);
    let e0 = energy(&c.initial_state());
    // Largest panel momentum as the scale.
    let scale = run
        .latches
        .iter()
        .map(|l| {
            l.rates_before
                .iter()
                .zip(&c.chain.panels)
                .map(|(r, p)| (r * p.length * p.mass).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let mut prev_after = e0;
    for l in &run.latches {
        let (p, ang, _) = c.momentum(&l.state_before);
        assert!(
            p.norm() <= 1e-9 * scale,
            "linear momentum {p:?} (scale {scale})"
        );
        assert!(
            ang.norm() <= 1e-9 * scale * 30.0,
            "angular momentum {ang:?}"
        );
        let e_before = energy(&l.state_before);
        assert!(
            (e_before - prev_after).abs() <= 1e-9 * e0,
            "energy between latches {prev_after} → {e_before}"
        );
        let loss = l.energy_before - l.energy_after;
        assert!(loss >= 0.0);
        assert!(
            (loss - l.loss_metric).abs() <= 1e-9 * e0,
            "latch {}: loss {loss} vs ½ΔuᵀMΔu {}",
            l.hinge,
            l.loss_metric
        );
        prev_after = e_before - loss;
    }
    let (p, ang, _) = c.momentum(&run.final_state);
    assert!(p.norm() <= 1e-9 * scale && ang.norm() <= 3e-8 * scale);
}

/// The planar case of the independent maximal-coordinate formulation
/// ([`super::coupled_maximal::reference_case`]) as a scenario: free 1500 kg hub, 8 m
/// aluminium tube mast along x from (1.3, 0, 0), three 2 m 20 kg panels at its tip folding in
/// the x–y plane (e_a = −y, n = x, hinge axes along z).
pub const PLANAR_CASE: &str = r#"
name = "planar case of the second formulation"
format_version = 1
[hub]
motion = "free"
mass = 1500.0
inertia = [1267.5, 1267.5, 1267.5]
center_of_mass = [0.0, 0.0, 0.0]
[materials.aluminium]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = 2700.0
[[beams]]
name = "mast"
parent = "hub"
root = [1.3, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 8.0
material = "aluminium"
section = { tube = { outer_diameter = 0.2, wall = 0.005 } }
terms = { bending = 6, torsion = 2, axial = 4 }
[[plates]]
name = "wing"
parent = "mast"
station = 8.0
length_axis = [0.0, -1.0, 0.0]
normal = [1.0, 0.0, 0.0]
length = 6.0
width = 1.0
areal_density = 10.0
bending_stiffness = 1.0e4
poisson_ratio = 0.3
terms = { length = 4, width = 2 }
[deployment]
plate = "wing"
panels = 3
end_time = 6.0
output_rate = 10.0
integrator = "explicit"
tolerance = 1e-12
[deployment.hinge]
stiffness = 2.0
preload_angle = 0.5
"#;

/// A second, independent formulation (maximal coordinates for the panels with hinge
/// constraint forces, the mast by its own floating-frame Lagrangian over Gauss particles,
/// Gauss–Legendre time stepping) agrees with the coupled model on the latch times and the
/// mast tip deflection at each latch, planar case, free hub, elastic mast, 3 panels.
#[test]
fn coupled_model_agrees_with_the_maximal_coordinate_formulation() {
    let sc = Scenario::from_toml_str(PLANAR_CASE, "planar.toml").unwrap();
    let c = coupled(&sc, BaseKind::Flexible { modes: None });
    let mut case = super::coupled_maximal::reference_case();
    case.end_time = 6.0;
    let reference = super::coupled_maximal::solve_planar(&case);
    let run = c.simulate(false, 6.0, 1e-10);
    assert_eq!(
        run.latches.len(),
        reference.latches.len(),
        "coupled: {:?} at {} after {} steps; reference {:?}",
        run.latches
            .iter()
            .map(|l| (l.hinge, l.time))
            .collect::<Vec<_>>(),
        run.final_time,
        run.steps,
        reference
            .latches
            .iter()
            .map(|l| (l.hinge, l.time))
            .collect::<Vec<_>>()
    );
    assert!(run.latches.len() >= 2);
    let tip = |y: &[f64]| {
        let s = c.view(y);
        flexcraft::deploy::inertia::combine(&c.base.beams[0].tip_shapes, s.eta)
    };
    for (a, b) in run.latches.iter().zip(&reference.latches) {
        assert_eq!(a.hinge, b.hinge);
        assert!(
            (a.time - b.time).abs() <= 1e-8 * b.time,
            "latch {}: {} vs {}",
            a.hinge,
            a.time,
            b.time
        );
        let t = tip(&a.state_before);
        let scale = b.tip_before[0].abs().max(b.tip_before[1].abs());
        for (x, y) in [(t.get(0), b.tip_before[0]), (t.get(1), b.tip_before[1])] {
            assert!(
                (x - y).abs() <= 1e-6 * scale,
                "tip at latch {}: {t:?} vs {:?}",
                a.hinge,
                b.tip_before
            );
        }
    }
}

/// Ideal cable synchronisation, held hub, N identical panels: one degree of freedom β = α₁
/// (α_i = 2β for i ≥ 2). Panel k (1-based) then points at ±(π/2 − β) and its centre sits at
/// ((k − ½) l sin β, ½ l cos β), so T = ½ J(β) β̇² with
///   J(β) = m l² Σ_k [(k − ½)² cos²β + ¼ sin²β] + N I,
/// V(β) = ½ k₁(α_ref,1 − β)² + Σ_{i≥2} ½ k_i(α_ref,i − 2β)², and from rest the latch (β = π/2)
/// comes at t = ∫₀^{π/2} dβ / √(2 (V(0) − V(β)) / J(β)) (with β = s² to remove the
/// endpoint singularity, Gauss–Legendre in s). Every hinge latches at that one instant.
#[test]
fn ideal_cable_latch_time_equals_the_energy_quadrature() {
    let sc = scenario("free_hub.toml", |s| {
        s.replace("motion = \"free\"", "motion = \"fixed\"")
            .replace("hub = \"free\"", "hub = \"fixed\"")
            .replace("damping = 0.05", "damping = 0.0")
    });
    let mut c = coupled(&sc, BaseKind::Rigid);
    c.sync = Synchronisation::IdealCable;
    let ch = &c.chain;
    let n = ch.len() as f64;
    let (l, m, i0) = (ch.panels[0].length, ch.panels[0].mass, ch.panels[0].inertia);
    let j = |b: f64| {
        let (sb, cb) = b.sin_cos();
        m * l
            * l
            * (1..=ch.len())
                .map(|k| (k as f64 - 0.5).powi(2) * cb * cb + 0.25 * sb * sb)
                .sum::<f64>()
            + n * i0
    };
    let v = |b: f64| {
        ch.hinges
            .iter()
            .enumerate()
            .map(|(i, h)| {
                let a = if i == 0 { b } else { 2.0 * b };
                0.5 * h.stiffness * (h.reference_angle - a).powi(2)
            })
            .sum::<f64>()
    };
    let smax = (std::f64::consts::FRAC_PI_2).sqrt();
    let quad = flexcraft::basis::Quadrature::gauss(200);
    let t_exact: f64 = quad
        .points
        .iter()
        .zip(&quad.weights)
        .map(|(x, w)| {
            let s = x * smax;
            let b = s * s;
            w * smax * 2.0 * s / (2.0 * (v(0.0) - v(b)) / j(b)).sqrt()
        })
        .sum();
    let run = c.simulate(false, 120.0, 1e-12);
    assert_eq!(run.latches.len(), 1, "one latch event locks every hinge");
    assert!(run.all_latched);
    let t = run.latches[0].time;
    assert!(
        (t - t_exact).abs() <= 1e-8 * t_exact,
        "cable latch at {t} s, quadrature {t_exact} s"
    );
    // Every hinge at its latch angle at that instant: straight.
    let s = c.view(&run.latches[0].state_before);
    for (a, h) in s.alpha.iter().zip(&ch.hinges) {
        assert!((a - h.latch_angle).abs() < 1e-9, "{a} vs {}", h.latch_angle);
    }
}

/// The right-hand side eliminates the opening angles in O(N) (the articulated-body recursion,
/// or the cable's one speed; docs/theory.md §2.7); `solve_captured` solves the dense
/// Kane system over every speed. The two formulations give the same accelerations at
/// arbitrary states, the base speeds' and the hinges' each to 1e-10 of their own block's
/// largest: free and held hub, a held hub on a rigid base (no base speeds at all),
/// independent hinges with any set locked or all, ideal and elastic cables, captured
/// compliant latches, 3 and 12 panels. (Both read the chain's blocks M₁₁, M₁₂ and b_c; those
/// are held to independent truths by the maximal-coordinate and conservation tests.)
#[test]
fn linear_time_elimination_equals_the_dense_solve() {
    use flexcraft::deploy::coupled::CompliantLatch;
    let mut seed = 0x9e3779b97f4a7c15_u64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut checked = 0;
    for (panels, motion, kind) in [
        (3, "free", BaseKind::Flexible { modes: Some(10) }),
        (3, "fixed", BaseKind::Flexible { modes: Some(10) }),
        (3, "fixed", BaseKind::Rigid),
        (12, "free", BaseKind::Flexible { modes: Some(10) }),
        (12, "fixed", BaseKind::Flexible { modes: Some(10) }),
    ] {
        let sc = scenario("seed.toml", |s| {
            s.replace("panels = 3", &format!("panels = {panels}"))
                .replace("motion = \"free\"", &format!("motion = \"{motion}\""))
        });
        let mut c = coupled(&sc, kind);
        let (np, n, nb) = (c.positions(), c.panels(), c.rate_offset());
        assert_eq!(n, panels);
        for sync in [
            Synchronisation::None,
            Synchronisation::IdealCable,
            Synchronisation::ElasticCable(50.0),
        ] {
            c.sync = sync;
            for pattern in 0..5usize {
                let free: Vec<bool> = (0..n)
                    .map(|i| pattern == 0 || (pattern < 4 && (i + pattern) % 3 != 0))
                    .collect();
                let captured: Vec<bool> = (0..n).map(|i| pattern == 3 && i % 2 == 0).collect();
                c.latch = (pattern == 3).then(|| CompliantLatch {
                    stiffness: vec![1e5; n],
                    damping: vec![300.0; n],
                });
                let mut y = c.initial_state();
                for (i, v) in y.iter_mut().enumerate() {
                    // Deformed, turning and moving: O(1) angles and rates, small η.
                    let scale = if i < np { 0.3 } else { 0.2 };
                    *v += scale * rand();
                }
                if motion == "free" {
                    let q = &mut y[3..7];
                    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
                    q.iter_mut().for_each(|x| *x /= norm);
                }
                let mut dy = vec![0.0; y.len()];
                c.rhs_captured(&y, &free, &captured, &mut dy);
                let (ev, sol) = c.solve_captured(&y, &free, &captured);
                // The per-step load path: the same solution and loads from the blocks.
                let (ev_fast, fast) = c.solve_captured_fast(&y, &free, &captured);
                let close = |a: &[f64], b: &[f64], what: &str| {
                    let scale = b.iter().map(|x| x.abs()).fold(1e-300, f64::max);
                    for (x, z) in a.iter().zip(b) {
                        assert!(
                            (x - z).abs() <= 1e-9 * scale,
                            "{panels} panels, {motion} hub, {sync:?}, pattern {pattern}: {what} {x} vs dense {z}"
                        );
                    }
                    assert_eq!(a.len(), b.len(), "{what}");
                };
                close(&fast.udot, &sol.udot, "u̇");
                close(&fast.hinge_acc, &sol.hinge_acc, "hinge frame acceleration");
                // The root wrench and the cable torques by their dense definitions:
                // W = rows 0..6 of M_c [A; Ω̇; α̈] + b_c (in hub components through the
                // hinge frame), and λ = (CCᵀ)⁻¹ C r with r = M u̇ + c − Q on the hinge rows.
                let acc = &sol.hinge_acc;
                let w: Vec<f64> = (0..6)
                    .map(|i| ev.bc[i] + (0..6 + n).map(|j| ev.mc[(i, j)] * acc[j]).sum::<f64>())
                    .collect();
                let hub = |v: &[f64]| {
                    ev.frame
                        .apply(flexcraft::math::Vec3::new(v[0], v[1], v[2]))
                        .0
                };
                let dense_wrench = [hub(&w[..3]), hub(&w[3..])].concat();
                let wrench = |s: &flexcraft::deploy::coupled::Solution| {
                    let (f, m) = s.root_wrench;
                    [f.0, m.0].concat()
                };
                close(&wrench(&fast), &dense_wrench, "root wrench");
                close(
                    &wrench(&sol),
                    &dense_wrench,
                    "root wrench (dense accelerations)",
                );
                if sync == Synchronisation::IdealCable && free.iter().any(|f| *f) {
                    let ns = sol.udot.len();
                    let r: Vec<f64> = (0..n)
                        .map(|i| {
                            let row = nb + i;
                            (0..ns)
                                .map(|j| ev.mass[(row, j)] * sol.udot[j])
                                .sum::<f64>()
                                + ev.bias[row]
                                - ev.force[row]
                        })
                        .collect();
                    // C: loop k ties hinge k to hinge k − 1 (−2 for the first loop, −1 after).
                    let row = |k: usize| {
                        let mut c = vec![0.0; n];
                        c[k] = 1.0;
                        c[k - 1] = if k == 1 { -2.0 } else { -1.0 };
                        c
                    };
                    let c: Vec<Vec<f64>> = (1..n).map(row).collect();
                    let dot =
                        |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
                    // (CCᵀ) λ = C r by Gaussian elimination (tridiagonal, well conditioned).
                    let k = c.len();
                    let mut a: Vec<Vec<f64>> = (0..k)
                        .map(|i| {
                            let mut row: Vec<f64> = (0..k).map(|j| dot(&c[i], &c[j])).collect();
                            row.push(dot(&c[i], &r));
                            row
                        })
                        .collect();
                    for p in 0..k {
                        for q in p + 1..k {
                            let f = a[q][p] / a[p][p];
                            for j in p..=k {
                                a[q][j] -= f * a[p][j];
                            }
                        }
                    }
                    let mut lambda = vec![0.0; k];
                    for p in (0..k).rev() {
                        let s: f64 = (p + 1..k).map(|j| a[p][j] * lambda[j]).sum();
                        lambda[p] = (a[p][k] - s) / a[p][p];
                    }
                    close(&fast.cable_torque, &lambda, "cable torque");
                    close(
                        &sol.cable_torque,
                        &lambda,
                        "cable torque (dense accelerations)",
                    );
                } else {
                    close(&fast.cable_torque, &sol.cable_torque, "cable torque");
                }
                let flat = |l: Vec<(flexcraft::math::Vec3, flexcraft::math::Vec3)>| {
                    l.iter()
                        .flat_map(|(f, m)| [f.0, m.0].concat())
                        .collect::<Vec<f64>>()
                };
                close(
                    &flat(c.hinge_loads(&y, &ev_fast, &fast)),
                    &flat(c.hinge_loads(&y, &ev, &sol)),
                    "hinge loads",
                );
                assert_eq!(ev_fast.mass.nrows(), 0);
                let block = |r: std::ops::Range<usize>| {
                    sol.udot[r].iter().map(|x| x.abs()).fold(1e-300, f64::max)
                };
                let (base, hinges) = (block(0..nb), block(nb..nb + n));
                for (k, (a, b)) in dy[np..].iter().zip(&sol.udot).enumerate() {
                    let scale = if k < nb { base } else { hinges };
                    assert!(
                        (a - b).abs() <= 1e-10 * scale,
                        "{panels} panels, {motion} hub, {sync:?}, pattern {pattern}: u̇[{k}] {a} vs dense {b}"
                    );
                }
                // The speeds' changes of a Jacobian by differences share the configuration's
                // work (`rhs_captured_speeds`): each row is `rhs_captured` at its own state,
                // bit for bit; a position among them (α_1, first) is evaluated on its own,
                // and one change moves every opening rate at once (a cable tie's column).
                let rates: Vec<(usize, f64)> = (np + nb..y.len())
                    .map(|c| (c, y[c] + 1e-3 * rand()))
                    .collect();
                let changes: Vec<Vec<(usize, f64)>> = std::iter::once(c.alpha_offset())
                    .chain(np..y.len())
                    .map(|c| vec![(c, y[c] + 1e-3 * rand())])
                    .chain([rates])
                    .collect();
                let mut rows = vec![vec![0.0; y.len()]; changes.len()];
                c.rhs_captured_speeds(&y, &free, &captured, &changes, &mut rows);
                for (k, (change, row)) in changes.iter().zip(&rows).enumerate() {
                    let mut yk = y.clone();
                    for &(i, v) in change {
                        yk[i] = v;
                    }
                    let mut alone = vec![0.0; y.len()];
                    c.rhs_captured(&yk, &free, &captured, &mut alone);
                    let same = row
                        .iter()
                        .zip(&alone)
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(
                        same,
                        "{panels} panels, {motion} hub, {sync:?}, pattern {pattern}: change {k}"
                    );
                }
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 75);
}

/// Nothing acts on the free-floating spacecraft from outside, and its dynamics are written in
/// the hub frame: moving and turning the whole spacecraft (the hub's position and attitude
/// quaternion, the first seven positions) changes only the rates of those seven, which
/// `hub_kinematics` gives alone (ṙ = A(q) v, q̇ = ½ q ⊗ (0, ω)). The integrators' Jacobians
/// by differences rely on it (`OdeSystem::kinematic`).
#[test]
fn the_dynamics_do_not_depend_on_where_the_hub_is_or_how_it_is_turned() {
    let sc = scenario("seed.toml", |s| s);
    let c = coupled(&sc, BaseKind::Flexible { modes: Some(10) });
    let k = c.kinematic_positions();
    assert_eq!(k, 7);
    let mut y = c.initial_state();
    for (i, v) in y.iter_mut().enumerate() {
        *v += 0.1 * ((i as f64 * 0.7).sin() + 0.3);
    }
    let norm = |q: &mut [f64]| {
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.iter_mut().for_each(|x| *x /= n);
    };
    norm(&mut y[3..7]);
    let (free, captured) = (vec![true; 3], vec![false; 3]);
    let mut dy = vec![0.0; y.len()];
    c.rhs_captured(&y, &free, &captured, &mut dy);
    let mut moved = y.clone();
    moved[..7].copy_from_slice(&[40.0, -3.0, 7.5, 0.2, -0.6, 0.5, 0.6]);
    norm(&mut moved[3..7]);
    let mut dy_moved = vec![0.0; y.len()];
    c.rhs_captured(&moved, &free, &captured, &mut dy_moved);
    assert_eq!(
        dy[k..],
        dy_moved[k..],
        "the dynamics changed with the hub's pose"
    );
    assert_ne!(dy[..k], dy_moved[..k]);
    let mut kin = vec![0.0; k];
    c.hub_kinematics(&moved, &mut kin);
    assert_eq!(kin, dy_moved[..k]);
}
