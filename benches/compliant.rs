//! Issue 19's speed targets: `simulate` of the seed with compliant latches (library, whole
//! run: modes, the coupled deployment until the latches have settled, hand-over, response)
//! for latch stiffness 1e4, 1e5 and 1e7 N·m/rad at a fixed damping ratio (ζ = 0.1 for one
//! panel about its hinge, c_L = 2ζ√(k_L J), J = 1250 kg·m², as examples/seed_compliant.toml).
//! Targets: k_L = 1e5 under 0.5 s; 1e7 no more than 3× the time of 1e4.
//! `scripts/bench_compliant.sh` runs it and prints the table with the ratio.

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use flexcraft::scenario::Scenario;
use flexcraft::simulation::Simulation;
use std::time::Duration;

const SEED: &str = include_str!("../examples/seed_compliant.toml");

fn scenario(k: f64) -> Scenario {
    let c = 2.0 * 0.1 * (k * 1250.0_f64).sqrt();
    let src = SEED
        .replace("stiffness = 1.0e5", &format!("stiffness = {k:e}"))
        .replace("damping = 2236.0", &format!("damping = {c}"));
    assert_ne!(src, SEED, "the example's latch lines changed");
    Scenario::from_toml_str(&src, "seed_compliant.toml").expect("the edited example parses")
}

fn bench(cr: &mut Criterion) {
    let mut g = cr.benchmark_group("compliant_seed_simulate");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(10))
        .measurement_time(Duration::from_secs(5));
    for k in [1e4, 1e5, 1e7] {
        let sc = scenario(k);
        g.bench_function(format!("k_L = {k:e}"), |b| {
            b.iter(|| Simulation::run(&sc).expect("the seed simulates"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
