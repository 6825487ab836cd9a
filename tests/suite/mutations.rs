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
    #![proptest_config(ProptestConfig {
        cases: 512,
        rng_seed: proptest::test_runner::RngSeed::Fixed(43),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]
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
                    match ModalAnalysis::compute(&model) {
                        Ok(m) => {
                            prop_assert!(m.modes.iter().all(|x| x.omega_rad_s.is_finite()));
                        }
                        Err(e) => prop_assert!(false, "accepted but not solved: {e}\n{src}"),
                    }
                }
            }
        }
    }
}

/// Extreme magnitudes a number may be replaced by: huge, tiny, subnormal, signed zero.
const EXTREMES: [&str; 10] = [
    "1e300",
    "-1e300",
    "1e-300",
    "-1e-300",
    "5e-324",
    "-5e-324",
    "-0.0",
    "1.7976931348623157e308",
    "2.2250738585072014e-308",
    "1e-12",
];

/// Byte ranges of every number literal in `src` outside comments: the values of keys and
/// the entries of arrays (the integers of `terms`, `panels` and `format_version` included).
fn number_spans(src: &str) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut offset = 0;
    for line in src.split_inclusive('\n') {
        let code = line.split('#').next().unwrap_or("");
        if let Some(eq) = code.find('=') {
            let b = code.as_bytes();
            let mut i = eq + 1;
            while i < b.len() {
                let c = b[i] as char;
                let starts = c.is_ascii_digit()
                    || (matches!(c, '-' | '+') && b.get(i + 1).is_some_and(u8::is_ascii_digit));
                let inside_word =
                    i > 0 && ((b[i - 1] as char).is_ascii_alphanumeric() || b[i - 1] == b'_');
                if starts && !inside_word {
                    let mut j = i + 1;
                    while j < b.len()
                        && ((b[j] as char).is_ascii_alphanumeric()
                            || matches!(b[j], b'.' | b'-' | b'+' | b'_'))
                    {
                        j += 1;
                    }
                    out.push(offset + i..offset + j);
                    i = j;
                } else {
                    i += 1;
                }
            }
        }
        offset += line.len();
    }
    out
}

/// Runs everything the CLI would run on an accepted scenario; every reported number must be
/// finite (or the failure located), and the deployment's work is bounded by its step limit.
fn check_accepted(s: &Scenario) -> Result<(), TestCaseError> {
    let model = RitzModel::assemble(&s.structure);
    if model.dof() > 600 {
        return Ok(());
    }
    match ModalAnalysis::compute(&model) {
        Err(e) => {
            // A numerical failure is traced to a component with a location.
            let located = s.locate(model.culprit(&e), e.to_string());
            prop_assert!(located.location.line >= 1);
            return Ok(());
        }
        Ok(m) => prop_assert!(flexcraft::finite::check_modes(&m).is_ok()),
    }
    if s.deployment.is_some() {
        match flexcraft::simulation::Simulation::run(s) {
            Ok(sim) => {
                prop_assert!(
                    sim.deployment.evaluations <= 13 * flexcraft::deploy::MAX_STEPS,
                    "the step limit bounds the work"
                );
                prop_assert!(
                    flexcraft::finite::check_simulation(&sim).is_ok(),
                    "{:?}",
                    flexcraft::finite::check_simulation(&sim)
                );
            }
            Err(flexcraft::simulation::SimulationError::Ritz(_)) => {}
            Err(e) => prop_assert!(false, "unexpected failure {e}"),
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]
    /// Any number of the examples replaced by an extreme magnitude (1e±300, subnormals,
    /// -0.0, the largest and smallest normal doubles): a located refusal, or a run whose
    /// every reported number is finite — never a panic, an unbounded run or a NaN.
    #[test]
    fn extreme_magnitudes_are_refused_with_a_location_or_give_finite_results(
        which in 0usize..3,
        picks in proptest::collection::vec((any::<usize>(), 0usize..EXTREMES.len()), 1..3),
    ) {
        let examples = [
            include_str!("../../examples/seed.toml"),
            include_str!("../../examples/full.toml"),
            include_str!("../../examples/free_hub.toml"),
        ];
        let mut src = examples[which].to_string();
        for (at, v) in picks {
            let spans = number_spans(&src);
            let r = spans[at % spans.len()].clone();
            src.replace_range(r, EXTREMES[v]);
        }
        match Scenario::from_toml_str(&src, "extreme.toml") {
            Err(e) => {
                prop_assert!(e.location.line >= 1, "no location: {e}");
                prop_assert!(!e.key.is_empty() && !e.reason.is_empty(), "{e}");
            }
            Ok(s) => check_accepted(&s)?,
        }
    }
}

#[test]
fn every_number_of_the_examples_is_found_by_the_mutator() {
    // The extreme-value property test reaches every numeric key: count the literals of the
    // seed by hand-checked landmarks.
    let seed = include_str!("../../examples/seed.toml");
    let spans = number_spans(seed);
    let texts: Vec<&str> = spans.iter().map(|r| &seed[r.clone()]).collect();
    for must in [
        "70e9", "0.3", "2700.0", "13.0", "70.0", "1.283", "0.25", "60.0", "50.0",
    ] {
        assert!(texts.contains(&must), "{must} not found in {texts:?}");
    }
    assert!(!texts.iter().any(|t| t.contains('#')));
}
