//! Modal-analysis benchmarks (issue 2 targets): assembly + eigen-solve of the seed structure
//! at the default terms and at the term counts where its first 10 elastic frequencies are
//! converged to 1e-5 and 1e-6 relative (see docs/convergence.md), and a 1000-DOF model.
//! Run: `scripts/bench.sh` (prints the figures) or `cargo bench --bench modes`.

use criterion::{criterion_group, criterion_main, Criterion};
use flexcraft::{ModalAnalysis, RitzModel, Scenario};
use std::hint::black_box;

const SEED: &str = include_str!("../examples/seed.toml");

/// The command line's allocator (src/main.rs), so that the figures are the tool's: the
/// system allocator maps and faults a large model's matrices afresh on every iteration.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The seed scenario with other term counts: beam (bending, torsion, axial), plate (length, width).
fn seed_with(beam: (usize, usize, usize), plate: (usize, usize)) -> Scenario {
    let src = SEED
        .replace(
            "bending = 8, torsion = 6, axial = 4",
            &format!(
                "bending = {}, torsion = {}, axial = {}",
                beam.0, beam.1, beam.2
            ),
        )
        .replace(
            "length = 8, width = 6",
            &format!("length = {}, width = {}", plate.0, plate.1),
        );
    Scenario::from_toml_str(&src, "seed.toml").expect("seed scenario")
}

fn solve(s: &Scenario) -> ModalAnalysis {
    let model = RitzModel::assemble(&s.structure);
    ModalAnalysis::compute(&model).expect("modes")
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("modes");
    g.sample_size(10);
    let cases = [
        ("seed default terms (80 DOF)", (8, 6, 4), (8, 6)),
        ("seed first 10 to 1e-5 (716 DOF)", (12, 8, 6), (48, 14)),
        ("seed first 10 to 1e-6 (1256 DOF)", (16, 10, 8), (60, 20)),
        ("seed 1000 DOF", (14, 8, 6), (56, 17)),
    ];
    for (name, beam, plate) in cases {
        let s = seed_with(beam, plate);
        g.bench_function(name, |b| b.iter(|| black_box(solve(black_box(&s)))));
    }
    // Issue 17's composite: automatic terms (selection + the wanted modes), from the text.
    let composite = include_str!("../examples/composite.toml");
    for tol in ["1e-5", "1e-6"] {
        let text = composite.replace(
            "tolerance = 1e-5",
            &format!("tolerance = {tol}\nmax_dof = 3000"),
        );
        g.bench_function(
            format!("composite first 10 to {tol}, automatic terms"),
            |b| {
                b.iter(|| {
                    let s = Scenario::from_toml_str(black_box(&text), "composite.toml")
                        .expect("composite");
                    let model = RitzModel::assemble(&s.structure);
                    let sel = s.term_selection.as_ref().map(|t| t.accuracy.modes);
                    black_box(
                        ModalAnalysis::compute_selected(&model, sel, s.term_selection.as_ref())
                            .expect("modes"),
                    )
                })
            },
        );
    }
    let s = Scenario::from_toml_str(SEED, "seed.toml").expect("seed");
    g.bench_function("seed default: assembly only", |b| {
        b.iter(|| black_box(RitzModel::assemble(black_box(&s.structure))))
    });
    g.finish();
}

/// Deployment of the seed example until all latched, and N-panel chains (fixed hub, equal
/// springs) for the cost-versus-N figure.
fn bench_deploy(c: &mut Criterion) {
    let mut g = c.benchmark_group("deploy");
    g.sample_size(10);
    let s = Scenario::from_toml_str(SEED, "seed.toml").expect("seed");
    let d = s.deployment.clone().expect("seed has [deployment]");
    g.bench_function("seed (3 panels) until all latched", |b| {
        b.iter(|| black_box(flexcraft::deploy::simulate(black_box(&d))))
    });
    for n in [5usize, 10, 20, 50] {
        let src = SEED.replace("panels = 3", &format!("panels = {n}")).replace(
            "[[deployment.hinges]]          # hinge 1, at the wing root\nstiffness = 12.0\n[[deployment.hinges]]          # hinge 2: the common values above\n[[deployment.hinges]]          # hinge 3\n",
            "",
        );
        let s = Scenario::from_toml_str(&src, "seed.toml").expect("seed N");
        let mut d = s.deployment.clone().expect("deployment");
        d.end_time = 20.0;
        g.bench_function(format!("{n} panels until all latched"), |b| {
            b.iter(|| black_box(flexcraft::deploy::simulate(black_box(&d))))
        });
    }
    g.finish();
}

/// The whole simulation of the seed example (library: modes, deployment, hand-over,
/// response), and the response alone for 100 elastic modes × 10⁵ samples.
fn bench_response(c: &mut Criterion) {
    use flexcraft::response::channels::standard_channels;
    use flexcraft::response::{ModalResponse, ResponseSettings};
    use flexcraft::simulation::Simulation;
    let mut g = c.benchmark_group("response");
    g.sample_size(10);
    let s = Scenario::from_toml_str(SEED, "seed.toml").expect("seed");
    g.bench_function("seed simulate (default settings)", |b| {
        b.iter(|| black_box(Simulation::run(black_box(&s)).expect("simulate")))
    });
    // 100 of 122 elastic modes (plate 12 × 8), 10⁵ samples (2000 s at 50 Hz).
    let big = seed_with((8, 6, 4), (12, 8));
    let sim = Simulation::run(&big).expect("simulate");
    let eta_dot = sim
        .response
        .as_ref()
        .expect("latched")
        .handover
        .modal_velocity
        .clone();
    let settings = ResponseSettings {
        duration: 1999.99,
        output_rate: 50.0,
        modes: Some(100),
        ..ResponseSettings::default()
    };
    assert_eq!(settings.rows(), 100_000);
    let channels = standard_channels(&sim.model);
    let resp = ModalResponse::new(&sim.modes, &eta_dot, &settings);
    assert_eq!(resp.kept_elastic(), 100);
    g.bench_function("100 modes x 1e5 samples", |b| {
        b.iter(|| black_box(resp.sample(&sim.modes, &channels, &settings)))
    });
    g.finish();
}

criterion_group!(benches, bench, bench_deploy, bench_response);
criterion_main!(benches);
