//! Mass properties and Monte Carlo statistics against truths computed outside flexcraft
//! (issue 43).
//!
//! * **Rigid-body mass properties** of examples/seed.toml, composite.toml and full.toml:
//!   tests/data/mass_properties.json, written by tests/data/gen_mass_properties.py (Python
//!   standard library only). That script reads each scenario file with `tomllib` and integrates
//!   every component (the hub tube and its end discs, the beams' line masses and polar line
//!   inertia, the plates' sheets, the lumped bodies) into its mass, first and second moments
//!   about the structure origin, in 60-digit decimal arithmetic, with its own formulas (in its
//!   header); flexcraft instead sums closed-form inertias about each attachment point and
//!   shifts them by the parallel-axis theorem. Both of flexcraft's routes are compared with it:
//!   `Structure::rigid_body` (mass, centre of mass, inertia about the centre of mass) and the
//!   hub's 6 × 6 block of the Ritz mass matrix (`RitzModel::assemble`, built from the
//!   attachment maps T: Σ Tᵀ B T), which must be the whole spacecraft's rigid mass block about
//!   the hub's centre of mass. Regenerate after changing an example:
//!   `python3 tests/data/gen_mass_properties.py`.
//! * **Statistics**: tests/data/stats_reference.json, written by
//!   tests/data/gen_stats_reference.py with SciPy (`python3 -m venv /tmp/v &&
//!   /tmp/v/bin/pip install numpy scipy`, then `/tmp/v/bin/python
//!   tests/data/gen_stats_reference.py`; with mpmath installed too it also checks SciPy's
//!   values against 50 digits): the exact Kolmogorov–Smirnov critical values
//!   `kstwo.ppf(1 − α, n)`, the CDFs of the Monte Carlo distributions (normal, uniform,
//!   lognormal, truncated normal; the discrete choice in exact rational arithmetic), the normal
//!   quantile and each marginal's quantile of a normal score.
//!
//! The fixtures are read by the small JSON reader at the end, whose numbers go through Rust's
//! correctly rounded `str::parse::<f64>`: serde_json as this crate builds it (without its
//! `float_roundtrip` feature) may read a 17-digit number one ulp off, which moved an input
//! point of the narrow uniform case by 1e-10 of the interval and its CDF by as much.

use super::common::example;
use flexcraft::montecarlo::distributions::normal_quantile;
use flexcraft::montecarlo::stats::ks_critical;
use flexcraft::montecarlo::Distribution;
use flexcraft::{RitzModel, Scenario};

/// Relative tolerance of every mass property, against its own scale (below).
///
/// Why 1e-12: each property is a sum of a few dozen floating-point products, and the largest
/// cancellation in flexcraft's route (the parallel-axis shifts of the hub and of the total,
/// J_cm = J_O − M(|c|²I − ccᵀ)) loses less than one digit on these examples (the seed's hub,
/// 7.1 t at 7.5 m from the origin: 4e5 kg·m² against tr J = 1.8e6); the measured differences
/// are below 2e-15 of the scales. 1e-12 leaves three decades of margin for rounding, and is
/// still five decades below the smallest physical term of the examples: the full example's
/// boom polar line inertia ρI_pL = 0.0192 kg·m² and the star tracker's product of inertia
/// 0.01 kg·m², against tr J_cm = 7.6e4 kg·m² (2.5e-7 and 1.3e-7), so any term left out, any
/// sign or axis convention changed, is caught.
const MASS_TOL: f64 = 1e-12;

fn check(what: &str, got: f64, want: f64, scale: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol * scale,
        "{what}: flexcraft {got:e}, truth {want:e} (difference {:.2e} of the scale {scale:e}, \
         tolerance {tol:e})",
        (got - want).abs() / scale
    );
}

/// The examples of the mass-properties fixture, each with its parsed scenario.
fn mass_property_examples() -> Vec<(String, Json, Scenario)> {
    let fixture = Json::read("mass_properties.json");
    let Json::Obj(entries) = fixture else {
        panic!("the fixture is not an object")
    };
    let examples: Vec<(String, Json, Scenario)> = entries
        .into_iter()
        .filter(|(k, _)| k.ends_with(".toml"))
        .map(|(name, truth)| {
            let s = Scenario::from_file(&example(&name)).unwrap_or_else(|e| panic!("{e}"));
            (name, truth, s)
        })
        .collect();
    assert_eq!(examples.len(), 3, "seed, composite and full");
    examples
}

/// `Structure::rigid_body` (about the structure origin) against the Python integration:
/// total mass to 1e-12 of itself, the centre of mass to 1e-12 of the structure's radius of
/// gyration √(tr J_cm / M), and the inertia about the centre of mass to 1e-12 of tr J_cm.
#[test]
fn structure_mass_properties_match_the_independent_integration() {
    for (name, truth, s) in mass_property_examples() {
        let body = s.structure.rigid_body();
        let (c, j) = (body.center_of_mass(), body.inertia_at_cm());
        check_rigid(&name, &truth, body.mass, c, j);
    }
}

/// A mass, centre of mass and inertia about it against the fixture's entry `truth`: the mass
/// to MASS_TOL of itself, the centre to MASS_TOL of the radius of gyration √(tr J_cm / M),
/// the inertia to MASS_TOL of tr J_cm.
fn check_rigid(
    name: &str,
    truth: &Json,
    mass: f64,
    centre: flexcraft::math::Vec3,
    inertia: flexcraft::math::Mat3,
) {
    let m = truth.get("mass").num();
    let c = truth.get("center_of_mass").nums();
    let j = truth.get("inertia_cm").matrix();
    let trace = j[0][0] + j[1][1] + j[2][2];
    let gyration = (trace / m).sqrt();
    check(&format!("{name} mass"), mass, m, m, MASS_TOL);
    for i in 0..3 {
        let what = format!("{name} centre of mass [{i}]");
        check(&what, centre.get(i), c[i], gyration, MASS_TOL);
        for k in 0..3 {
            let what = format!("{name} inertia about the centre of mass [{i}][{k}]");
            check(&what, inertia.get(i, k), j[i][k], trace, MASS_TOL);
        }
    }
}

/// The hub's six coordinates of the assembled Ritz mass matrix (translation of the hub's
/// centre of mass h, small rotation) against the Python block [[M I, −S(s)], [S(s), J_h]],
/// s = M(c − h): the translational entries to 1e-12 of M, the couplings to 1e-12 of M·√(tr
/// J_h / M), the rotational ones to 1e-12 of tr J_h. The hub's centre of mass the scenario
/// gives (the point the block refers to) must be the fixture's.
#[test]
fn ritz_hub_mass_block_matches_the_independent_integration() {
    for (name, truth, s) in mass_property_examples() {
        let h = truth.get("hub_center_of_mass").nums();
        let gh = s.structure.hub().center_of_mass();
        for i in 0..3 {
            check(
                &format!("{name} hub centre [{i}]"),
                gh.get(i),
                h[i],
                1.0,
                1e-15,
            );
        }
        let model = RitzModel::assemble(&s.structure);
        let b = truth.get("hub_block").matrix();
        let m = truth.get("mass").num();
        let trace = b[3][3] + b[4][4] + b[5][5];
        for i in 0..6 {
            for k in 0..6 {
                let scale = match (i < 3, k < 3) {
                    (true, true) => m,
                    (false, false) => trace,
                    _ => m * (trace / m).sqrt(),
                };
                let what = format!("{name} Ritz mass matrix M[{i}][{k}]");
                check(&what, model.mass[(i, k)], b[i][k], scale, MASS_TOL);
            }
        }
    }
}

/// NASA 42's mass elements (`export::mass_elements`: quadrature points of every beam and plate,
/// the hub and the lumped bodies, each with its mass and own inertia) summed into the whole
/// spacecraft's mass, centre of mass and inertia about it, against the Python integration:
/// the same tolerances as [`structure_mass_properties_match_the_independent_integration`]
/// ([`check_rigid`]).
/// The examples hold every kind of element: beams on the hub and on a beam (full), plates on
/// a beam, lumped masses with products of inertia. A plate or a beam left out, a quadrature
/// weight off, a line inertia about the wrong axis is caught.
#[test]
fn export_mass_elements_match_the_independent_integration() {
    use flexcraft::math::{Mat3, Vec3};
    for (name, truth, s) in mass_property_examples() {
        let model = RitzModel::assemble(&s.structure);
        let elements = flexcraft::export::mass_elements(&model, &[]);
        let mass: f64 = elements.iter().map(|e| e.mass).sum();
        let first = elements
            .iter()
            .fold(Vec3::ZERO, |a, e| a + e.position * e.mass);
        // Inertia about the origin: each element's own plus m(|r|² I − r rᵀ).
        let steiner = |r: Vec3, m: f64| (Mat3::IDENTITY * r.dot(r) - r.outer(r)) * m;
        let j_o = elements.iter().fold(Mat3::default(), |a, e| {
            a + e.inertia + steiner(e.position, e.mass)
        });
        let c = first * (1.0 / mass);
        let j_cm = j_o - steiner(c, mass);
        check_rigid(&format!("{name} elements'"), &truth, mass, c, j_cm);
    }
}

/// The same elements carry the Ritz model's kinetic energy in every hub-fixed mode (the
/// module's claim): Σ_e m_e ψ_p·ψ_q + θ_p·I_e θ_q, a quadrature of the continuum that samples
/// the shapes point by point (attachments' motion included), must be δ_pq for the mass-
/// normalised hub-fixed modes of the full example (beams on a beam, plate on a beam, lumped
/// bodies), which come from the assembled mass matrix (Gauss rules of the basis products). To
/// 1e-9: both are exact for the polynomial basis, the rest is the eigen-solver's orthonormality.
#[test]
fn export_mass_elements_carry_the_modes_kinetic_energy() {
    let (_, _, s) = mass_property_examples()
        .into_iter()
        .find(|(n, _, _)| n == "full.toml")
        .expect("full.toml in the fixture");
    let model = RitzModel::assemble(&s.structure);
    let modes = flexcraft::ModalAnalysis::compute_lowest(&model, Some(12)).expect("modes");
    let shapes: Vec<&[f64]> = modes.hub_fixed.iter().map(|h| h.shape.as_slice()).collect();
    assert!(shapes.len() >= 8, "{} hub-fixed modes", shapes.len());
    let elements = flexcraft::export::mass_elements(&model, &shapes);
    for p in 0..shapes.len() {
        for q in 0..shapes.len() {
            let sum: f64 = elements
                .iter()
                .map(|e| {
                    let ((up, tp), (uq, tq)) = (e.motion[p], e.motion[q]);
                    e.mass * up.dot(uq) + tp.dot(e.inertia.apply(tq))
                })
                .sum();
            let want = if p == q { 1.0 } else { 0.0 };
            assert!(
                (sum - want).abs() <= 1e-9,
                "modes {p}, {q}: Σ m ψ·ψ + θ·Iθ = {sum:e}, want {want}"
            );
        }
    }
}

fn distribution(case: &Json) -> Distribution {
    let p = case.get("params").nums();
    match case.get("kind").str() {
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
            weights: case.get("weights").nums(),
        },
        k => panic!("unknown distribution {k}"),
    }
}

/// `Distribution::cdf` against SciPy (the choice: against its exact rational step sum).
///
/// Tolerances. flexcraft evaluates Φ(z) = ½ erfc(−z/√2) with libm's erfc (under 1 ulp), and
/// SciPy's values are within 1.2e-15 absolute (and, but for the truncated normal, 6e-14
/// relative) of 50-digit values on this grid (checked by the generator): what differs is
/// mostly the rounding of the standardised argument.
/// * Normal, lognormal, uniform, choice: 1e-14 absolute (measured: 5.6e-16; a single-
///   precision or polynomial erf, 1e-7, fails by seven decades), and in the lower half
///   (F < ½) 1e-12 relative: there Φ keeps its own relative precision, and the argument's
///   rounding, relative ε/2, is amplified by z² (the exp(−z²/2) factor): 1.6e-13 at z = −37.5,
///   the deepest point (Φ = 5e-308; measured 1.7e-13).
/// * Truncated normal, (Φ(z) − Φ(α)) / P: the two Φ values are each accurate to about ε, so
///   their difference, divided by the interval's probability P, to 4ε/P (+1e-14): 7e-13 for
///   the tail intervals of probability 1.35e-3, and never above 9e-13 for an accepted one
///   (P ≥ 1e-3, `MIN_TRUNCATED_MASS`). Not relative: just inside a tail interval's lower
///   bound both flexcraft (1e-9) and SciPy (2e-10) lose relative digits to that difference.
#[test]
fn distribution_cdfs_match_scipy() {
    let fixture = Json::read("stats_reference.json");
    let cases = fixture.get("cdf").arr();
    for kind in [
        "normal",
        "uniform",
        "lognormal",
        "truncated_normal",
        "choice",
    ] {
        assert!(cases.iter().any(|c| c.get("kind").str() == kind), "{kind}");
    }
    for case in cases {
        let d = distribution(case);
        d.validate().unwrap();
        let kind = case.get("kind").str();
        let absolute = match kind {
            "truncated_normal" => 1e-14 + 4.0 * f64::EPSILON / case.get("probability").num(),
            _ => 1e-14,
        };
        for (x, want) in case.get("x").nums().into_iter().zip(case.get("cdf").nums()) {
            let got = d.cdf(x);
            let what = format!("{kind} {:?} CDF at {x:e}", case.get("params").nums());
            check(&what, got, want, 1.0, absolute);
            if kind != "truncated_normal" && want > 0.0 && want < 0.5 {
                check(&format!("{what} (relative)"), got, want, want, 1e-12);
            }
        }
    }
}

/// `normal_quantile` (Wichura's AS 241, documented relative accuracy about 1e-16) against
/// SciPy's `norm.ppf` from p = 1e-300 to 1 − 1e-12, to 2e-15 relative (9ε: AS 241's own
/// error plus SciPy's, 1.4e-16; measured 4.2e-16); and `Distribution::from_normal_score`,
/// F⁻¹(Φ(z)) of each continuous marginal, against SciPy's ppf/isf to 1e-13 relative (SciPy's
/// truncnorm.isf is itself 1e-14 off at the upper end of [3, 5], checked by the generator;
/// measured difference 1.1e-14).
#[test]
fn normal_quantile_and_marginal_quantiles_match_scipy() {
    let fixture = Json::read("stats_reference.json");
    let q = fixture.get("normal_quantile");
    for (p, want) in q.get("p").nums().into_iter().zip(q.get("x").nums()) {
        let got = normal_quantile(p);
        let scale = want.abs().max(f64::MIN_POSITIVE);
        check(
            &format!("normal quantile at {p:e}"),
            got,
            want,
            scale,
            2e-15,
        );
    }
    for case in fixture.get("quantile").arr() {
        let d = distribution(case);
        for (z, want) in case.get("z").nums().into_iter().zip(case.get("x").nums()) {
            let got = d.from_normal_score(z);
            let what = format!(
                "{} {:?} quantile of the score {z}",
                case.get("kind").str(),
                case.get("params").nums()
            );
            check(&what, got, want, want.abs().max(1e-300), 1e-13);
        }
    }
}

/// `ks_critical(n, α) = √(−ln(α/2)/2)/√n` (the first term of Kolmogorov's limit series)
/// against the exact critical value d_n = `kstwo.ppf(1 − α, n)`.
///
/// * The reference itself, at n = 1: D₁ = max(F(x), 1 − F(x)) is uniform on [½, 1], so
///   d₁ = 1 − α/2 exactly (to 1e-12).
/// * Conservative for every n: ks_critical ≥ d_n. A theorem, not a fit: Massart's tight
///   Dvoretzky–Kiefer–Wolfowitz inequality, P(D_n > ε) ≤ 2 exp(−2nε²) for every n (Ann.
///   Probab. 18 (1990) 1269–1283), gives P(D_n > ks_critical) ≤ α. So a KS test at
///   ks_critical (tests/suite/montecarlo.rs) rejects a correct distribution with probability
///   at most α.
/// * How much above, for n ≥ 100: the exact quantile of √n D_n approaches Kolmogorov's c_K
///   from below as c_K − 1/(6√n) + O(1/n) (the first finite-sample correction: √n D_n +
///   1/(6√n) follows Kolmogorov's law to O(1/n); J. Vrbik, "Small-sample corrections to
///   Kolmogorov–Smirnov test statistic", 2018; at α = 0.05, 1/(6c) = 0.123 is Stephens' (1970)
///   familiar √n + 0.12), and c_K equals the first-term value c = √(−ln(α/2)/2) to 2e-6
///   relative at α ≤ 0.05. So the relative margin r = ks_critical/d_n − 1 is
///   1/(6c√n) + O(1/n); asserted as 0 ≤ r − 1/(6c√n) ≤ 0.5/n. The O(1/n) coefficient,
///   measured, is positive: 0.32 at α = 0.001, 0.19 at 0.01, 0.10 at 0.05, the same at
///   n = 100, 1000 and 10 000 (so truly 1/n); 0.5 bounds it with room for SciPy's 3e-8
///   relative error in d_n. In numbers: ks_critical is 1.2–1.3 % above d_n at n = 100,
///   0.3–0.4 % at 1000, 0.09–0.12 % at 10 000.
#[test]
fn ks_critical_is_conservative_by_the_first_finite_sample_correction() {
    let fixture = Json::read("stats_reference.json");
    let rows = fixture.get("ks_critical").arr();
    assert_eq!(rows.len(), 21, "3 levels × 7 sample sizes");
    for row in rows {
        let alpha = row.get("alpha").num();
        let n = row.get("n").num();
        let exact = row.get("critical").num();
        let got = ks_critical(n as usize, alpha);
        let what = format!("α = {alpha}, n = {n}");
        if n == 1.0 {
            assert!(
                (exact - (1.0 - alpha / 2.0)).abs() <= 1e-12,
                "{what}: SciPy's d₁ = {exact}, the closed form 1 − α/2 = {}",
                1.0 - alpha / 2.0
            );
        }
        assert!(
            got >= exact,
            "{what}: ks_critical {got} below the exact {exact}"
        );
        if n >= 100.0 {
            let c = (-(alpha / 2.0).ln() / 2.0).sqrt();
            let first_order = 1.0 / (6.0 * c * n.sqrt());
            let r = got / exact - 1.0;
            assert!(
                r >= first_order && r - first_order <= 0.5 / n,
                "{what}: ks_critical {got} is {r:.4e} above the exact {exact}; the first-order \
                 correction 1/(6c√n) = {first_order:.4e} plus at most 0.5/n = {:.1e}",
                0.5 / n
            );
        }
    }
}

/// A JSON value (what the fixtures use: objects, arrays, strings without escapes, numbers).
#[derive(Debug)]
enum Json {
    Num(f64),
    Str(String),
    Arr(Vec<Json>),
    Obj(Vec<(String, Json)>),
}

impl Json {
    /// tests/data/`name`, parsed.
    fn read(name: &str) -> Json {
        let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let mut p = JsonParser {
            b: text.as_bytes(),
            i: 0,
        };
        let v = p.value();
        p.ws();
        assert_eq!(p.i, p.b.len(), "{path}: text after the value");
        v
    }

    fn get(&self, key: &str) -> &Json {
        match self {
            Json::Obj(m) => m
                .iter()
                .find(|(k, _)| k == key)
                .map(|(_, v)| v)
                .unwrap_or_else(|| panic!("no key {key:?}")),
            _ => panic!("{key:?} asked of a non-object"),
        }
    }

    fn num(&self) -> f64 {
        match self {
            Json::Num(v) => *v,
            _ => panic!("not a number: {self:?}"),
        }
    }

    fn str(&self) -> &str {
        match self {
            Json::Str(s) => s,
            _ => panic!("not a string: {self:?}"),
        }
    }

    fn arr(&self) -> &[Json] {
        match self {
            Json::Arr(v) => v,
            _ => panic!("not an array: {self:?}"),
        }
    }

    fn nums(&self) -> Vec<f64> {
        self.arr().iter().map(Json::num).collect()
    }

    fn matrix(&self) -> Vec<Vec<f64>> {
        self.arr().iter().map(Json::nums).collect()
    }
}

struct JsonParser<'a> {
    b: &'a [u8],
    i: usize,
}

impl JsonParser<'_> {
    fn ws(&mut self) {
        while self.b.get(self.i).is_some_and(u8::is_ascii_whitespace) {
            self.i += 1;
        }
    }

    fn eat(&mut self, c: u8) -> bool {
        self.ws();
        let hit = self.b.get(self.i) == Some(&c);
        if hit {
            self.i += 1;
        }
        hit
    }

    /// The items of an array or object up to `close`, each read by `item`.
    fn items<T>(&mut self, close: u8, mut item: impl FnMut(&mut Self) -> T) -> Vec<T> {
        let mut v = Vec::new();
        if self.eat(close) {
            return v;
        }
        loop {
            v.push(item(self));
            if self.eat(close) {
                return v;
            }
            assert!(self.eat(b','), "',' expected at byte {}", self.i);
        }
    }

    fn value(&mut self) -> Json {
        self.ws();
        match self.b[self.i] {
            b'{' => {
                self.i += 1;
                Json::Obj(self.items(b'}', |p| {
                    p.ws();
                    let key = p.string();
                    assert!(p.eat(b':'), "':' expected at byte {}", p.i);
                    (key, p.value())
                }))
            }
            b'[' => {
                self.i += 1;
                Json::Arr(self.items(b']', Self::value))
            }
            b'"' => Json::Str(self.string()),
            _ => {
                let start = self.i;
                while self
                    .b
                    .get(self.i)
                    .is_some_and(|c| matches!(c, b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E'))
                {
                    self.i += 1;
                }
                let s = std::str::from_utf8(&self.b[start..self.i]).unwrap();
                Json::Num(
                    s.parse()
                        .unwrap_or_else(|e| panic!("number {s:?} at byte {start}: {e}")),
                )
            }
        }
    }

    fn string(&mut self) -> String {
        assert_eq!(self.b[self.i], b'"', "string expected at byte {}", self.i);
        self.i += 1;
        let start = self.i;
        while self.b[self.i] != b'"' {
            assert_ne!(self.b[self.i], b'\\', "the fixtures write no escapes");
            self.i += 1;
        }
        self.i += 1;
        std::str::from_utf8(&self.b[start..self.i - 1])
            .unwrap()
            .to_string()
    }
}
