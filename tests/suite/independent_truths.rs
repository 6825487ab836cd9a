//! Draft: measuring.

use super::common::example;
use flexcraft::montecarlo::distributions::{normal_cdf, normal_quantile};
use flexcraft::montecarlo::stats::ks_critical;
use flexcraft::montecarlo::Distribution;
use flexcraft::{RitzModel, Scenario};
use serde_json::Value;

fn fixture(name: &str) -> Value {
    let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(num).collect()
}

fn distribution(case: &Value) -> Distribution {
    let p = nums(&case["params"]);
    match case["kind"].as_str().unwrap() {
        "normal" => Distribution::Normal {
            mean: p[0],
            sd: p[1],
        },
        "uniform" => Distribution::Uniform {
            low: p[0],
            high: p[1],
        },
        "lognormal" => Distribution::LogNormal {
            mu: p[0],
            sigma: p[1],
        },
        "truncated_normal" => Distribution::TruncatedNormal {
            mean: p[0],
            sd: p[1],
            low: p[2],
            high: p[3],
        },
        "choice" => Distribution::Choice {
            values: p,
            weights: nums(&case["weights"]),
        },
        k => panic!("{k}"),
    }
}

#[test]
fn measure() {
    let t0 = std::time::Instant::now();
    let mp = fixture("mass_properties.json");
    for name in ["seed.toml", "composite.toml", "full.toml"] {
        let t = std::time::Instant::now();
        let s = Scenario::from_file(&example(name)).unwrap();
        let tl = t.elapsed();
        let f = &mp[name];
        let body = s.structure.rigid_body();
        let m = num(&f["mass"]);
        let c = nums(&f["center_of_mass"]);
        let j: Vec<Vec<f64>> = f["inertia_cm"]
            .as_array()
            .unwrap()
            .iter()
            .map(nums)
            .collect();
        let tr = j[0][0] + j[1][1] + j[2][2];
        let l = (tr / m).sqrt();
        let gc = body.center_of_mass();
        let gj = body.inertia_at_cm();
        let mut ec: f64 = 0.0;
        let mut ej: f64 = 0.0;
        for i in 0..3 {
            ec = ec.max((gc.get(i) - c[i]).abs() / l);
            for k in 0..3 {
                ej = ej.max((gj.get(i, k) - j[i][k]).abs() / tr);
            }
        }
        let t = std::time::Instant::now();
        let model = RitzModel::assemble(&s.structure);
        let ta = t.elapsed();
        let b: Vec<Vec<f64>> = f["hub_block"]
            .as_array()
            .unwrap()
            .iter()
            .map(nums)
            .collect();
        let mut eb = [0.0f64; 3];
        let trh = b[3][3] + b[4][4] + b[5][5];
        let lh = (trh / m).sqrt();
        for i in 0..6 {
            for k in 0..6 {
                let d = (model.mass[(i, k)] - b[i][k]).abs();
                let (slot, sc) = match (i < 3, k < 3) {
                    (true, true) => (0, m),
                    (false, false) => (2, trh),
                    _ => (1, m * lh),
                };
                eb[slot] = eb[slot].max(d / sc);
            }
        }
        println!(
            "{name}: load {tl:?} assemble {ta:?} dof {} mass {:e} cm {ec:e} J {ej:e} block {eb:?}",
            model.dof(),
            (body.mass - m).abs() / m
        );
    }
    let st = fixture("stats_reference.json");
    let mut worst_abs: f64 = 0.0;
    for case in st["cdf"].as_array().unwrap() {
        let d = distribution(case);
        d.validate().unwrap();
        let (xs, fs) = (nums(&case["x"]), nums(&case["cdf"]));
        let mut ea: f64 = 0.0;
        let mut er: f64 = 0.0;
        for (x, f) in xs.iter().zip(&fs) {
            let g = d.cdf(*x);
            ea = ea.max((g - f).abs());
            if *f > 0.0 && *f < 0.5 {
                er = er.max((g - f).abs() / f);
            }
            if (g - f).abs() > 1e-15 || (*f > 0.0 && (g - f).abs() / f > 1e-13) {
                println!("  {:?} x {x:e} got {g:e} want {f:e}", case["params"]);
            }
        }
        worst_abs = worst_abs.max(ea);
        println!(
            "{} {:?}: abs {ea:e} rel-lower {er:e}",
            case["kind"], case["params"]
        );
    }
    let q = &st["normal_quantile"];
    for (p, x) in nums(&q["p"]).iter().zip(nums(&q["x"])) {
        let g = normal_quantile(*p);
        println!("q p {p:e}: {g} {x} rel {:e}", ((g - x) / x).abs());
        let _ = normal_cdf(x);
    }
    for case in st["quantile"].as_array().unwrap() {
        let d = distribution(case);
        for (z, x) in nums(&case["z"]).iter().zip(nums(&case["x"])) {
            let g = d.from_normal_score(*z);
            println!(
                "{} {:?} z {z}: {g} {x} rel {:e}",
                case["kind"],
                case["params"],
                ((g - x) / x).abs()
            );
        }
    }
    for row in st["ks_critical"].as_array().unwrap() {
        let (a, n, c) = (
            num(&row["alpha"]),
            row["n"].as_u64().unwrap() as usize,
            num(&row["critical"]),
        );
        let k = ks_critical(n, a);
        let ca = (-(a / 2.0).ln() / 2.0).sqrt();
        println!(
            "ks {a} {n}: {k} {c} margin {:e} r {}",
            k / c - 1.0,
            (k / c - 1.0) * 6.0 * ca * (n as f64).sqrt()
        );
    }
    println!("total {:?}", t0.elapsed());
}
