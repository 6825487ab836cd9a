//! Export benchmarks (issue 13 targets): the seed spacecraft with 50 elastic modes and 10
//! named points — modal solve and the linear model (`ExportModel::build`), the first-order
//! form, the NumPy/MATLAB arrays — and a 200-point frequency response of three transfer
//! functions. The whole process (`flexcraft export … --out`) is timed by `scripts/bench.sh`.
//! Run: `cargo bench --bench export`.

use criterion::{criterion_group, criterion_main, Criterion};
use flexcraft::export::ExportModel;
use flexcraft::{ModalAnalysis, RitzModel, Scenario};
use std::hint::black_box;

/// The seed with `[export] modes = 50` and ten points along the mast.
fn seed_export() -> Scenario {
    let mut src = include_str!("../examples/seed.toml").to_string();
    src += "\n[export]\nmodes = 50\n";
    for i in 0..10 {
        src += &format!(
            "[[export.points]]\nname = \"p{i}\"\ncomponent = \"mast\"\nstation = {}\n",
            i as f64 * 1.3
        );
    }
    Scenario::from_toml_str(&src, "seed_export.toml").expect("scenario")
}

fn bench(c: &mut Criterion) {
    let s = seed_export();
    let mut g = c.benchmark_group("export");
    g.sample_size(20);
    g.bench_function(
        "seed, 50 modes, 10 points: assemble + modes + linear model",
        |b| {
            b.iter(|| {
                let model = RitzModel::assemble(&s.structure);
                let modes = ModalAnalysis::compute_lowest(&model, s.export_modes()).expect("modes");
                let ex = ExportModel::build(&model, &modes, &s.export).expect("export");
                black_box(ex.first_order());
            })
        },
    );
    let model = RitzModel::assemble(&s.structure);
    let modes = ModalAnalysis::compute_lowest(&model, s.export_modes()).expect("modes");
    let ex = ExportModel::build(&model, &modes, &s.export).expect("export");
    g.bench_function("frequency response, 200 frequencies, 3 transfers", |b| {
        let pairs: Vec<(usize, usize)> = s
            .export
            .transfers
            .iter()
            .map(|t| {
                (
                    ex.output_index(&t.output).unwrap(),
                    ex.input_index(&t.input).unwrap(),
                )
            })
            .collect();
        b.iter(|| {
            let f = ex.frequency_grid(None, 200);
            let mut acc = 0.0;
            for (o, i) in &pairs {
                for fk in &f {
                    acc += ex.transfer(*o, *i, 2.0 * std::f64::consts::PI * fk).norm();
                }
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
