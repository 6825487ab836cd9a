//! Any spacecraft (issue 36): the default deployment (`integrator = "auto"`) on random valid
//! spacecraft nobody tuned for (`tests/support/spacecraft.rs`: free and held hubs, one to
//! three beams, tip masses, a second plate now and then, one to eight panels of unequal
//! lengths, with and without a cable, rigid and compliant latches, hinge damping and
//! friction or not). Truths: the run's own physics cannot be asserted case by case, so the
//! suite asserts what holds for every case — how the run ends (every hinge latched or
//! captured, or a physical reason reported; never the step limit, never a non-finite state),
//! the conservation of a free spacecraft's momentum (nothing acts from outside), and on a
//! subset the agreement of the latch or capture times with an explicit run of every base
//! mode at a tight tolerance (which shares neither the cutoff, the correction nor the
//! steps), within the accuracy the run reports.

use crate::support::spacecraft::{spacecraft, Drawn};
use flexcraft::deploy::{simulate_coupled, Deployment, DeploymentResult, Integrator, RunStatus};
use flexcraft::Scenario;
use proptest::prelude::*;

/// The panels' momentum scale of a run: the heaviest panel's mass × the wing's length × the
/// largest hinge rate sampled (N·s), and its moment (× the wing's length, N·m·s).
fn momentum_scale(sc: &Scenario, r: &DeploymentResult) -> (f64, f64) {
    let d = sc.deployment.as_ref().unwrap();
    let mass = d.chain.panels.iter().fold(0.0_f64, |m, p| m.max(p.mass));
    let length: f64 = d.chain.panels.iter().map(|p| p.length).sum();
    let rate = r
        .samples
        .iter()
        .flat_map(|s| s.rate.iter())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    (mass * length * rate, mass * length * length * rate)
}

/// One case: the default run ends properly and keeps a free hub's momentum.
fn check(seed: u64) -> Result<(), TestCaseError> {
    let drawn: Drawn = spacecraft(seed);
    let sc = Scenario::from_toml_str(&drawn.toml, &format!("random{seed}.toml"))
        .map_err(|e| TestCaseError::fail(format!("seed {seed}: refused: {e}")))?;
    let d = sc.deployment.as_ref().unwrap();
    prop_assert_eq!(d.integrator, Integrator::Auto);
    let (c, r) = simulate_coupled(&sc.structure, d)
        .map_err(|e| TestCaseError::fail(format!("seed {seed}: {e}")))?;
    prop_assert!(
        !matches!(
            r.status,
            RunStatus::StepLimit { .. } | RunStatus::Diverged { .. }
        ),
        "seed {seed}: {:?} ({:?})",
        r.status,
        r.warnings
    );
    // Every hinge latched or captured, or the end time came first and the run says which
    // hinges it left where (a hinge that swung back, or that never reached its latch).
    if !r.all_latched {
        prop_assert_eq!(r.status, RunStatus::EndTime, "seed {}", seed);
        prop_assert!(!r.unlatched.is_empty(), "seed {seed}");
        prop_assert!(
            r.warnings
                .iter()
                .any(|w| w.to_string().contains("not all hinges latched")),
            "seed {seed}: {:?}",
            r.warnings
        );
    }
    // An estimate above the accuracy asked for is said in the warnings.
    let a = r.accuracy.clone().unwrap();
    prop_assert_eq!(
        a.reached(),
        !r.warnings
            .iter()
            .any(|w| w.to_string().starts_with("accuracy not reached")),
        "seed {}",
        seed
    );
    if drawn.free_hub {
        let (p_scale, l_scale) = momentum_scale(&sc, &r);
        let (p0, l0, _) = c.momentum(&c.initial_state());
        let drift = |y: &[f64]| -> (f64, f64) {
            let (p, l, _) = c.momentum(y);
            ((p - p0).norm(), (l - l0).norm())
        };
        // Step ends and events: the restoration holds P and L to rounding.
        let mut states = vec![("end", r.final_state())];
        for e in &r.latches {
            let mut before = e.q.clone();
            before.extend_from_slice(&e.qd_before);
            let mut after = e.q.clone();
            after.extend_from_slice(&e.qd_after);
            states.push(("before a latch", before));
            states.push(("after a latch", after));
        }
        for (what, y) in &states {
            let (dp, dl) = drift(y);
            prop_assert!(
                dp <= 1e-9 * p_scale && dl <= 1e-9 * l_scale,
                "seed {seed} {what}: ΔP {dp:e} N·s (scale {p_scale:e}), ΔL {dl:e} N·m·s (scale {l_scale:e})"
            );
        }
        // Between step ends the samples come from the step's interpolant.
        for s in &r.samples {
            let b = s.body.as_ref().unwrap();
            let dp = (0..3)
                .map(|k| (b.momentum[k] - p0.0[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            let dl = (0..3)
                .map(|k| (b.angular_momentum[k] - l0.0[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            prop_assert!(
                dp <= SAMPLE_MOMENTUM * p_scale && dl <= SAMPLE_MOMENTUM * l_scale,
                "seed {seed} sample at {} s: ΔP {dp:e} (scale {p_scale:e}), ΔL {dl:e} (scale {l_scale:e})",
                s.t
            );
        }
    }
    Ok(())
}

/// The samples' momentum error against the panels' momentum scale: the steps' cubic
/// interpolant between two restored step ends.
const SAMPLE_MOMENTUM: f64 = 1e-3;

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 32,
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::SourceParallel("proptest-regressions")
        )),
        // Seeded: the same 32 spacecraft on every run, so that CI is repeatable; the
        // sweep below reaches others.
        rng_seed: proptest::test_runner::RngSeed::Fixed(36),
        ..ProptestConfig::default()
    })]
    /// A few random spacecraft on every run of the suite.
    #[test]
    fn prop_any_spacecraft_deploys_by_default(seed in any::<u64>()) {
        check(seed)?;
    }
}

/// Seeds the proptest has found failing on earlier runs (kept also in
/// `proptest-regressions/suite/any_spacecraft.txt`): a six-panel wing whose hub reached
/// 1e15 rad/s before the energy guard (…364), momentum off by 4e-9 of its scale at the end
/// before the final state was restored (…366).
#[test]
fn found_spacecraft_deploy_by_default() {
    for seed in [11357577217028387364, 11357577217028387366] {
        check(seed).unwrap();
    }
}

/// Many more: `cargo test --release -- --ignored any_spacecraft_sweep` (seeds 0…199, some
/// minutes).
#[test]
#[ignore]
fn any_spacecraft_sweep() {
    let failures: Vec<String> = (0..200)
        .filter_map(|seed| check(seed).err().map(|e| e.to_string()))
        .collect();
    assert!(
        failures.is_empty(),
        "{} of 200 failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The explicit reference of `sc`: every base mode, DOPRI5 at 1e-9.
fn reference(sc: &Scenario) -> DeploymentResult {
    let d = sc.deployment.as_ref().unwrap();
    let explicit = Deployment {
        integrator: Integrator::Explicit,
        tolerance: 1e-9,
        ..d.clone()
    };
    simulate_coupled(&sc.structure, &explicit).unwrap().1
}

/// (time, hinge) of the events the accuracy covers: every capture, or the first impact.
fn events(r: &DeploymentResult) -> Vec<(f64, usize)> {
    if r.captures.is_empty() {
        r.latches
            .iter()
            .take(1)
            .map(|l| (l.time, l.hinge))
            .collect()
    } else {
        r.captures.iter().map(|c| (c.time, c.hinge)).collect()
    }
}

/// The default run's latch or capture times against the explicit run of every base mode
/// (no cutoff, no correction, no scheduled steps), within the larger of the accuracy asked
/// for and the estimate reported, on random spacecraft cheap enough for the reference.
fn agrees_with_the_reference(seed: u64) {
    let drawn = spacecraft(seed);
    let sc = Scenario::from_toml_str(&drawn.toml, "random.toml").unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let (_, auto) = simulate_coupled(&sc.structure, d).unwrap();
    let a = auto.accuracy.clone().unwrap();
    let reference = reference(&sc);
    let (mine, theirs) = (events(&auto), events(&reference));
    assert_eq!(
        mine.iter().map(|e| e.1).collect::<Vec<_>>(),
        theirs.iter().map(|e| e.1).collect::<Vec<_>>(),
        "seed {seed}: event order"
    );
    assert!(!theirs.is_empty(), "seed {seed}: nothing latched");
    // The accuracy asked for where the run says it reached it, its estimate otherwise.
    assert!(!a.events_differ, "seed {seed}: {a:?}");
    let bound = if a.reached() { a.asked } else { a.estimate };
    for (m, t) in mine.iter().zip(&theirs) {
        let rel = (m.0 - t.0).abs() / t.0;
        assert!(
            rel <= bound,
            "seed {seed}: hinge {} at {} vs {} (rel {rel:e}, bound {bound:e})",
            m.1,
            m.0,
            t.0
        );
    }
}

/// A cheap subset on every run: among seeds 0…22 the two whose all-mode explicit reference
/// takes seconds (a five-panel rigid-latch wing whose first impact comes at 0.39 s, a
/// two-panel compliant one capturing over 116 s).
#[test]
fn val_random_spacecraft_latch_like_the_all_mode_explicit_reference() {
    for seed in [4, 22] {
        agrees_with_the_reference(seed);
    }
}

/// One panel on a held hub, spring k preloaded beyond its latch, Coulomb friction μ: while it
/// opens, J α̈ = k (α_ref − α) − μ, so α = a (1 − cos ωt) with a = α_ref − μ/k, ω = √(k/J),
/// and it latches at α_L at t = arccos(1 − α_L/a)/ω (J = I + m l²/4 about the hinge). The
/// default run from rest (where the regularised friction band |α̇| < 1e-6 rad/s is a stiff
/// damping) latches there to its accuracy (seed 21 of the generator, a friction-held panel,
/// latched 0.53 s late before the band's step rule).
#[test]
fn val_one_panel_with_friction_latches_at_the_closed_form() {
    let (k, mu, preload) = (3.0, 0.4, 0.4);
    let src = super::common::one_panel("friction", 20.0, 1e-10, "")
        .replace("integrator = \"explicit\"\ntolerance = 1e-10\n", "")
        .replace(
            "preload_angle = 0.4\n",
            &format!("preload_angle = {preload:?}\nfriction = {mu:?}\n"),
        );
    let sc = Scenario::from_toml_str(&src, "friction.toml").unwrap();
    let d = sc.deployment.as_ref().unwrap();
    assert_eq!(d.integrator, Integrator::Auto);
    let p = d.chain.panels[0];
    let j = p.inertia + p.mass * p.length * p.length / 4.0;
    let a = std::f64::consts::FRAC_PI_2 + preload - mu / k;
    let t = (1.0 - std::f64::consts::FRAC_PI_2 / a).acos() / (k / j).sqrt();
    let (_, r) = simulate_coupled(&sc.structure, d).unwrap();
    let got = r.latches[0].time;
    let acc = r.accuracy.unwrap();
    assert!(acc.reached(), "{acc:?}");
    assert!(
        (got - t).abs() <= acc.asked * t,
        "latch at {got} s, closed form {t} s"
    );
}

/// More of the subset: `cargo test --release -- --ignored reference_sweep`.
#[test]
#[ignore]
fn reference_sweep() {
    for seed in 0..40 {
        agrees_with_the_reference(seed);
    }
}

/// The generated spacecraft of the benchmark set (`scripts/bench_any.sh`): the first eight
/// seeds with 3 to 8 panels, whatever their cost.
const BENCH_SEEDS: [u64; 8] = [1, 3, 4, 5, 6, 7, 8, 9];

fn bench_file(seed: u64) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("benches/spacecraft")
        .join(format!("random_{seed:03}.toml"))
}

/// The committed benchmark files are the generator's output (rewrite them with
/// `cargo test --release -- --ignored write_bench_spacecraft`).
#[test]
fn bench_spacecraft_files_are_the_generators() {
    for seed in BENCH_SEEDS {
        let want = spacecraft(seed).toml;
        let got = std::fs::read_to_string(bench_file(seed)).unwrap_or_default();
        assert!(
            got == want,
            "{} differs from spacecraft({seed})",
            bench_file(seed).display()
        );
    }
}

/// Writes the benchmark set's generated files.
#[test]
#[ignore]
fn write_bench_spacecraft() {
    for seed in BENCH_SEEDS {
        std::fs::write(bench_file(seed), spacecraft(seed).toml).unwrap();
    }
}

/// The bundled examples by default against their every-mode reference — the adiabatic
/// integrator with all 26 base modes at 1e-10, itself held to the explicit run by
/// `tests/suite/adiabatic.rs` — within the accuracy the default run reports: the seed's latch
/// time (rigid latch: the first impact), seed_compliant's capture time and peak latch moments.
#[test]
fn val_the_examples_deploy_by_default_as_their_all_mode_reference() {
    for (file, compliant) in [("seed.toml", false), ("seed_compliant.toml", true)] {
        let sc = super::common::edited_example(file, |s| s);
        let d = sc.deployment.as_ref().unwrap();
        let (_, auto) = simulate_coupled(&sc.structure, d).unwrap();
        let a = auto.accuracy.clone().unwrap();
        assert!(a.reached(), "{file}: {a:?}");
        let reference = Deployment {
            integrator: Integrator::Adiabatic,
            tolerance: 1e-10,
            ..d.clone()
        };
        let (c, r) = simulate_coupled(&sc.structure, &reference).unwrap();
        assert_eq!(c.modes(), c.base.spectrum.len(), "every mode");
        let bound = a.asked.max(a.estimate);
        let (mine, theirs) = (events(&auto), events(&r));
        assert_eq!(mine.len(), theirs.len(), "{file}");
        for (m, t) in mine.iter().zip(&theirs) {
            assert!((m.0 - t.0).abs() <= bound * t.0, "{file}: {m:?} vs {t:?}");
        }
        if compliant {
            let n = d.chain.len();
            for j in 0..n {
                let (p, q) = (auto.latch_up_peaks[j].0, r.load_peaks[j].0);
                assert!(
                    (p - q).abs() <= bound * q,
                    "{file}: latch moment {j}: {p} vs {q}"
                );
            }
        }
    }
}

/// The hand-over on a generated spacecraft whose base deflects far (benchmark set, generated
/// 009: a 4.8 m beam's tip 3 m off during the deployment). A free spacecraft released at
/// rest has no momentum; the hand-over keeps that exactly in the rigid modes and gives the
/// elastic modes the projection of the velocity field, so the kinetic energy after it cannot
/// exceed the field's (the projection only drops energy). Before 2026-11-28 the momentum
/// was written into the generalized impulse's hub rows, which moved every elastic mode too:
/// 1128 J handed over from a 382 J field. The run also says why its numbers are rough: the
/// base's deflection warning (deployment) and the hand-over's note on the rigid motion the
/// undeformed geometry carries.
#[test]
fn a_far_deflected_base_hands_over_no_more_energy_than_it_has() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/spacecraft/random_009.toml"
    );
    let src = std::fs::read_to_string(path).unwrap() + "\n[response]\nduration = 0.1\n";
    let sc = Scenario::from_toml_str(&src, path).unwrap();
    let sim = flexcraft::simulation::Simulation::run(&sc).unwrap();
    let h = &sim.response.as_ref().unwrap().handover;
    assert!(
        h.energy_after <= h.energy_before_field * (1.0 + 1e-9),
        "{} J after from a {} J field",
        h.energy_after,
        h.energy_before_field
    );
    let p = h.momentum_after.linear.norm() + h.momentum_after.angular.norm();
    assert!(p < 1e-6, "momentum after {p}");
    assert!(sim
        .all_warnings()
        .any(|w| w.to_string().contains("tip during the deployment")));
    assert!(sim.all_warnings().any(|w| w
        .to_string()
        .contains("beyond the small-deformation assumption")));
}
