//! Beam characteristic functions against high-precision reference values
//! (tests/data/beam_functions.csv, made by tests/data/gen_beam_functions.py with mpmath at 300
//! digits from the textbook cosh/sinh/cos/sin form, where its cancellation is harmless).

use flexcraft::basis::characteristic::{root, BeamFunctions, End, RodFunctions};
use flexcraft::basis::Basis1d;
use std::collections::BTreeMap;

struct Row {
    k: usize,
    beta: f64,
    xi: f64,
    d: [f64; 4],
}

fn reference() -> BTreeMap<String, Vec<Row>> {
    let text = include_str!("../data/beam_functions.csv");
    let mut map: BTreeMap<String, Vec<Row>> = BTreeMap::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        map.entry(f[0].to_string()).or_default().push(Row {
            k: f[1].parse().unwrap(),
            beta: num(2),
            xi: num(3),
            d: [num(4), num(5), num(6), num(7)],
        });
    }
    map
}

fn end(c: char) -> End {
    match c {
        'C' => End::Clamped,
        'P' => End::Pinned,
        _ => End::Free,
    }
}

/// Largest error of function k's values and derivatives, relative to β^d·max|X| (the scale of
/// the d-th derivative), over the reference points.
fn worst(rows: &[&Row], eval: impl Fn(f64) -> [f64; 4]) -> f64 {
    let xmax = rows.iter().map(|r| r.d[0].abs()).fold(1.0_f64, f64::max);
    let beta = rows[0].beta.max(1.0);
    let mut e = 0.0_f64;
    for r in rows {
        let got = eval(r.xi);
        for d in 0..4 {
            e = e.max((got[d] - r.d[d]).abs() / (xmax * beta.powi(d as i32)));
        }
    }
    e
}

#[test]
fn roots_values_and_derivatives_match_high_precision_reference_up_to_n_100() {
    let reference = reference();
    for pair in ["CF", "FF", "CC", "PP", "CP", "PF"] {
        let ch: Vec<char> = pair.chars().collect();
        let (l, r) = (end(ch[0]), end(ch[1]));
        let probe = BeamFunctions::new(l, r, 4);
        let rigid = probe.rigid_count();
        let funcs = BeamFunctions::new(l, r, rigid + 100);
        let rows = &reference[pair];
        for k in 1..=100 {
            let rk: Vec<&Row> = rows.iter().filter(|row| row.k == k).collect();
            let beta = root(l, r, k);
            assert!(
                (beta - rk[0].beta).abs() < 1e-12,
                "{pair} root {k}: {beta} vs {}",
                rk[0].beta
            );
            assert!((funcs.beta(rigid + k - 1) - rk[0].beta).abs() < 1e-12);
            let e = worst(&rk, |xi| funcs.eval(rigid + k - 1, xi));
            assert!(e < 1e-10, "{pair} function {k}: relative error {e:e}");
        }
    }
}

#[test]
fn rod_functions_match_reference() {
    let reference = reference();
    let rod = RodFunctions::clamped_free(100);
    for k in 1..=100 {
        let rk: Vec<&Row> = reference["rod"].iter().filter(|row| row.k == k).collect();
        assert!((RodFunctions::wavenumber(k - 1) - rk[0].beta).abs() < 1e-12);
        let e = worst(&rk, |xi| rod.eval_vec(xi)[k - 1]);
        assert!(e < 1e-10, "rod function {k}: {e:e}");
    }
}

/// The closed characteristic equations themselves: cos β cosh β = ∓1, tan β = tanh β.
#[test]
fn roots_satisfy_their_characteristic_equations() {
    for k in 1..=30 {
        let b = root(End::Clamped, End::Free, k);
        assert!((b.cos() + 1.0 / b.cosh()).abs() < 1e-13);
        let b = root(End::Free, End::Free, k);
        assert!((b.cos() - 1.0 / b.cosh()).abs() < 1e-13);
        let b = root(End::Clamped, End::Pinned, k);
        assert!((b.tan() - b.tanh()).abs() < 1e-11 * (1.0 + b.tan().abs()));
    }
    // Classical first roots (Blevins, Formulas for natural frequency and mode shape, table 8-1).
    assert!((root(End::Clamped, End::Free, 1) - 1.875_104_068_711_96).abs() < 1e-13);
    assert!((root(End::Free, End::Free, 1) - 4.730_040_744_862_70).abs() < 1e-13);
    assert!((root(End::Clamped, End::Pinned, 1) - 3.926_602_312_047_92).abs() < 1e-13);
}

/// Orthonormality of each family (∫ X_i X_j = δ_ij), the rigid pair included.
#[test]
fn families_are_orthonormal() {
    for (l, r) in [
        (End::Clamped, End::Free),
        (End::Free, End::Free),
        (End::Clamped, End::Clamped),
        (End::Pinned, End::Free),
    ] {
        let f = BeamFunctions::new(l, r, 40);
        let q = f.quadrature();
        let vals: Vec<Vec<[f64; 4]>> = q.points.iter().map(|&x| f.eval_vec(x)).collect();
        for i in 0..40 {
            for j in 0..40 {
                let s: f64 = q
                    .weights
                    .iter()
                    .zip(&vals)
                    .map(|(w, v)| w * v[i][0] * v[j][0])
                    .sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((s - want).abs() < 1e-10, "{l:?}-{r:?} ({i},{j}): {s}");
            }
        }
    }
}
