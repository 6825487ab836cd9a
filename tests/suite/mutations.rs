//! Property test: random mutations of the bundled examples are either refused with a
//! located error or give a valid modal solution — never a panic.

use flexcraft::{ModalAnalysis, RitzModel, Scenario};
use proptest::prelude::*;

const EXAMPLES: [&str; 2] = [
    include_str!("../../examples/seed.toml"),
    include_str!("../../examples/full.toml"),
];

/// Values a mutated number may take: signs, zero, extremes, non-finite, typos.
const VALUES: [&str; 14] = [
    "0", "-1.0", "0.0", "1e308", "-1e-300", "nan", "inf", "0.5", "0.4999", "100", "101", "\"x\"",
    "[]", "1e3",
];

fn mutate(src: &str, kind: u8, line: usize, pick: usize, ch: char) -> String {
    let mut lines: Vec<String> = src.lines().map(str::to_string).collect();
    let i = line % lines.len();
    match kind % 5 {
        0 => {
            lines.remove(i);
        }
        1 => {
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        2 => {
            // Replace the value after '=' (or the first number) with a hostile value.
            if let Some(eq) = lines[i].find('=') {
                let key = lines[i][..eq].to_string();
                lines[i] = format!("{key}= {}", VALUES[pick % VALUES.len()]);
            }
        }
        3 => {
            let l: Vec<char> = lines[i].chars().collect();
            if !l.is_empty() {
                let mut l = l;
                let p = pick % l.len();
                l[p] = ch;
                lines[i] = l.into_iter().collect();
            }
        }
        _ => {
            let j = pick % lines.len();
            lines.swap(i, j);
        }
    }
    lines.join("\n")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]
    #[test]
    fn mutated_examples_never_panic(
        which in 0usize..2,
        muts in proptest::collection::vec((any::<u8>(), any::<usize>(), any::<usize>(), any::<char>()), 1..4),
    ) {
        let mut src = EXAMPLES[which].to_string();
        for (k, l, p, c) in muts {
            src = mutate(&src, k, l, p, c);
        }
        match Scenario::from_toml_str(&src, "mutated.toml") {
            Err(e) => {
                prop_assert!(e.location.line >= 1, "no location: {e}");
                prop_assert!(!e.reason.is_empty());
            }
            Ok(s) => {
                let model = RitzModel::assemble(&s.structure);
                // Bound the work: a mutation may ask for 100×100 plate terms.
                if model.dof() <= 600 {
                    if let Ok(m) = ModalAnalysis::compute(&model) {
                        prop_assert!(m.modes.iter().all(|x| x.omega_rad_s.is_finite()));
                    }
                }
            }
        }
    }
}
