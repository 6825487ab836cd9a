//! Deployment dynamics against closed-form solutions, conservation laws and a second,
//! independent formulation (maximal coordinates with hinge reactions, as the paper's
//! (2.1)–(2.3), integrated by classical RK4).

use flexcraft::deploy::chain::{Chain, Hinge, Panel, PlanarHub};
use flexcraft::deploy::{simulate, Deployment, Latching};
use std::f64::consts::PI;

fn hinge(k: f64, reference: f64, latch: f64) -> Hinge {
    Hinge {
        stiffness: k,
        reference_angle: reference,
        damping: 0.0,
        friction: 0.0,
        latch_angle: latch,
        initial_angle: 0.0,
        initial_rate: 0.0,
    }
}

/// N equal panels (length l, mass m, I = m l²/12), springs k with α_ref = latch + preload.
pub fn chain(n: usize, hub: PlanarHub, k: f64, preload: f64) -> Chain {
    let (l, m) = (5.0, 150.0);
    Chain {
        panels: vec![
            Panel {
                length: l,
                mass: m,
                inertia: m * l * l / 12.0
            };
            n
        ],
        hinges: (0..n)
            .map(|i| {
                let latch = if i == 0 { PI / 2.0 } else { PI };
                hinge(k, latch + preload, latch)
            })
            .collect(),
        hub,
        root: [0.3, 1.2],
    }
}

pub fn deployment(chain: Chain, latching: Latching, tol: f64) -> Deployment {
    Deployment {
        plate: "wing".into(),
        chain,
        latching,
        end_time: 400.0,
        output_rate: 10.0,
        base: flexcraft::deploy::base::BaseKind::Rigid,
        synchronisation: flexcraft::deploy::coupled::Synchronisation::None,
        integrator: flexcraft::deploy::Integrator::Explicit,
        latch: flexcraft::deploy::LatchModel::Rigid,
        base_damping_ratio: 0.0,
        settling: None,
        tolerance: tol,
        accuracy: 1e-3,
    }
}

#[test]
fn one_panel_on_fixed_hub_matches_closed_form() {
    // J α̈ = k (α_ref − α), α(0) = α̇(0) = 0  ⇒  α = α_ref (1 − cos ωt), ω² = k / (I + m l²/4).
    let (l, m, i_c, k, a_ref) = (4.0, 60.0, 95.0, 3.0, 2.1);
    let c = Chain {
        panels: vec![Panel {
            length: l,
            mass: m,
            inertia: i_c,
        }],
        hinges: vec![hinge(k, a_ref, PI / 2.0)],
        hub: PlanarHub::Fixed,
        root: [0.0, 0.0],
    };
    let r = simulate(&deployment(c, Latching::Sequential, 1e-12));
    let w = (k / (i_c + m * l * l / 4.0)).sqrt();
    let t_latch = (1.0 - (PI / 2.0) / a_ref).acos() / w;
    let rate = a_ref * w * (w * t_latch).sin();
    assert!(r.all_latched);
    let ev = &r.latches[0];
    assert!((ev.time - t_latch).abs() < 1e-9, "{} vs {t_latch}", ev.time);
    assert!((ev.rates_before[0] - rate).abs() < 1e-9 * rate.max(1.0));
    assert_eq!(ev.rates_after[0], 0.0);
    // Samples at exactly k / rate, and α(t) on them.
    for s in r.samples.iter().filter(|s| s.t < t_latch) {
        let k_index = (s.t * 10.0).round();
        assert!(s.t == k_index / 10.0 || s.t == ev.time);
        let want = a_ref * (1.0 - (w * s.t).cos());
        assert!(
            (s.alpha[0] - want).abs() < 1e-9,
            "t = {}: {} vs {want}",
            s.t,
            s.alpha[0]
        );
    }
    // The energy lost is the whole kinetic energy of the panel.
    assert!((ev.energy_before - 0.5 * (i_c + m * l * l / 4.0) * rate * rate).abs() < 1e-8);
    assert!(ev.energy_after.abs() < 1e-15);
}

/// A free hub's coordinates (or rates) followed by the opening angles (or rates): the
/// chain's q (or q̇).
fn coords(hub: [f64; 3], angles: &[f64]) -> Vec<f64> {
    hub.iter().chain(angles).copied().collect()
}

fn total_energy(s: &flexcraft::deploy::Sample) -> f64 {
    s.kinetic + s.spring
}

#[test]
fn energy_is_conserved_between_latches_and_lost_at_latches() {
    for hub in [
        PlanarHub::Fixed,
        PlanarHub::Free {
            mass: 800.0,
            inertia: 1200.0,
        },
    ] {
        let r = simulate(&deployment(
            chain(3, hub, 4.0, 0.3),
            Latching::Sequential,
            1e-12,
        ));
        assert!(r.all_latched, "{hub:?}");
        let mut seg_start = 0.0;
        for ev in r.latches.iter().map(Some).chain([None]) {
            let t_end = ev.map_or(f64::INFINITY, |e| e.time);
            let seg: Vec<_> = r
                .samples
                .iter()
                .filter(|s| s.t > seg_start && s.t < t_end)
                .collect();
            if let Some(first) = seg.first() {
                let e0 = total_energy(first);
                for s in &seg {
                    assert!(
                        (total_energy(s) - e0).abs() <= 1e-9 * e0,
                        "{hub:?} t = {}",
                        s.t
                    );
                }
            }
            if let Some(e) = ev {
                assert!(e.energy_after <= e.energy_before);
                seg_start = e.time;
            }
        }
    }
}

#[test]
fn energy_lost_at_a_latch_is_the_kinetic_energy_of_the_velocity_jump() {
    // Carnot's theorem for a perfectly plastic impact: ΔT = ½ Δq̇ᵀ M Δq̇.
    let hub = PlanarHub::Free {
        mass: 800.0,
        inertia: 1200.0,
    };
    let c = chain(3, hub, 4.0, 0.3);
    let r = simulate(&deployment(c.clone(), Latching::Sequential, 1e-12));
    for ev in &r.latches {
        let s = r.samples.iter().find(|s| s.t == ev.time).unwrap();
        let q: Vec<f64> = coords(s.hub, &ev.angles);
        let before: Vec<f64> = coords(s.hub_rate, &ev.rates_before);
        let after: Vec<f64> = coords(ev.hub_rate_after, &ev.rates_after);
        let jump: Vec<f64> = before.iter().zip(&after).map(|(a, b)| a - b).collect();
        let lost = c.kinetic_energy(&q, &jump);
        assert!(lost > 0.0);
        assert!(((ev.energy_before - ev.energy_after) - lost).abs() < 1e-9 * ev.energy_before);
    }
}

#[test]
fn free_hub_conserves_linear_and_angular_momentum_across_latches() {
    let hub = PlanarHub::Free {
        mass: 800.0,
        inertia: 1200.0,
    };
    let c = chain(4, hub, 4.0, 0.3);
    let r = simulate(&deployment(c.clone(), Latching::Sequential, 1e-12));
    assert!(r.all_latched);
    let (p0, l0) = c.momentum(&r.final_q, &r.final_qd);
    // Initially at rest: every momentum is zero; scale by a typical momentum.
    let scale = r.latches[0]
        .rates_before
        .iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()))
        * 150.0
        * 5.0
        * 20.0;
    for s in &r.samples {
        let q: Vec<f64> = coords(s.hub, &s.alpha);
        let qd: Vec<f64> = coords(s.hub_rate, &s.rate);
        let (p, l) = c.momentum(&q, &qd);
        assert!(
            p[0].abs() < 1e-9 * scale && p[1].abs() < 1e-9 * scale,
            "t = {}: p = {p:?}",
            s.t
        );
        assert!(l.abs() < 1e-9 * scale, "t = {}: L = {l}", s.t);
    }
    assert!(p0[0].abs() < 1e-9 * scale && l0.abs() < 1e-9 * scale);
}

#[test]
fn simultaneous_latching_stops_a_fixed_hub_array_and_turns_a_free_one_rigidly() {
    let r = simulate(&deployment(
        chain(3, PlanarHub::Fixed, 4.0, 0.3),
        Latching::Simultaneous,
        1e-12,
    ));
    assert!(r.all_latched);
    assert_eq!(r.latches.len(), 1);
    assert!(r.latches[0].rates_after.iter().all(|v| *v == 0.0));
    assert_eq!(r.latches[0].locked, vec![1, 2, 3]);

    let hub = PlanarHub::Free {
        mass: 800.0,
        inertia: 1200.0,
    };
    let c = chain(3, hub, 4.0, 0.3);
    let r = simulate(&deployment(c.clone(), Latching::Simultaneous, 1e-12));
    let ev = &r.latches[0];
    assert!(ev.rates_after.iter().all(|v| *v == 0.0));
    // After: a rigid body (hub + locked array) whose momenta equal those before (zero here),
    // i.e. the hub velocity is the one that conserves linear and angular momentum.
    let s = r.samples.iter().rev().find(|s| s.t == ev.time).unwrap();
    let q: Vec<f64> = coords(s.hub, &ev.angles);
    let first = r.samples.iter().find(|x| x.t == ev.time).unwrap();
    let before: Vec<f64> = coords(first.hub_rate, &ev.rates_before);
    let after: Vec<f64> = coords(ev.hub_rate_after, &ev.rates_after);
    let (p_b, l_b) = c.momentum(&q, &before);
    let (p_a, l_a) = c.momentum(&q, &after);
    assert!((p_b[0] - p_a[0]).abs() < 1e-10 && (p_b[1] - p_a[1]).abs() < 1e-10);
    assert!((l_b - l_a).abs() < 1e-9);
}

#[test]
fn fifty_panels_deploy_without_failure_and_conserve_energy_between_latches() {
    let r = simulate(&deployment(
        chain(50, PlanarHub::Fixed, 4.0, 0.3),
        Latching::Sequential,
        1e-10,
    ));
    let first = r.latches.first().map_or(f64::INFINITY, |e| e.time);
    let seg: Vec<_> = r.samples.iter().filter(|s| s.t < first).collect();
    let e0 = total_energy(seg[0]);
    for s in &seg {
        assert!((total_energy(s) - e0).abs() <= 1e-8 * e0, "t = {}", s.t);
    }
    // Without failure: to the end time (or every latch), neither diverged nor stopped at
    // the step limit.
    assert!(
        matches!(
            r.status,
            flexcraft::deploy::RunStatus::EndTime | flexcraft::deploy::RunStatus::AllLatched
        ) && !r.diverged(),
        "{:?}",
        r.status
    );
}
