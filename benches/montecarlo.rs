//! The per-run overhead of a Monte Carlo run (docs/montecarlo.md, "Speed"): applying the
//! drawn values to the scenario text and validating it again (what every run does before its
//! deployment when a structure key is dispersed, as the wing's areal density is here), the
//! same with the deployment keys alone (only `[deployment]` lowered again, the structure
//! kept), against the deployment run itself, for the seed deployment of
//! examples/montecarlo.toml (rigid base). `cargo bench --bench montecarlo`.

use criterion::{criterion_group, criterion_main, Criterion};
use flexcraft::montecarlo::Runner;
use flexcraft::Scenario;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/montecarlo.toml");
    let s = Scenario::from_file(std::path::Path::new(path)).expect("example parses");
    let mc = s.montecarlo.clone().expect("[montecarlo]");
    let mut g = c.benchmark_group("montecarlo");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    let runner = Runner::new(&s, &mc);
    let mut i = 0;
    g.bench_function("overhead: draw, apply and validate", |b| {
        b.iter(|| {
            i += 1;
            s.with_values(&mc.overrides(i)).expect("valid")
        })
    });
    let mut dep = mc.clone();
    dep.dispersions
        .retain(|d| d.path.starts_with("deployment."));
    let only = s.deployment_overrides().expect("[deployment]");
    g.bench_function(
        "overhead, deployment keys only: draw, lower [deployment] again",
        |b| {
            b.iter(|| {
                i += 1;
                only.deployment(&s, &dep.overrides(i)).expect("valid")
            })
        },
    );
    g.bench_function("whole run (draw, apply, deploy, outputs)", |b| {
        b.iter(|| {
            i += 1;
            runner.run(i)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
