//! Automatic term selection (`[ritz] tolerance`): the achieved error against independent
//! truths, and the honesty of the reported estimate.

use super::common::{elastic_omegas, scenario};
use flexcraft::{ModalAnalysis, RitzModel};

/// The composite spacecraft of issue 17: a free (or fixed) 800 kg hub, a 13 m aluminium tube
/// mast and a 15 m × 3.75 m plate wing at its tip. `terms`: the mast's and the plate's terms
/// tables, or empty for automatic.
pub fn composite(motion: &str, mast_terms: &str, plate_terms: &str, ritz: &str) -> String {
    format!(
        r#"
name = "composite"
[hub]
motion = "{motion}"
mass = 800.0
inertia = [600.0, 600.0, 400.0]
center_of_mass = [0.0, 0.0, -1.0]
[materials.aluminium]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = 2700.0
[[beams]]
name = "mast"
parent = "hub"
root = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
length = 13.0
material = "aluminium"
section = {{ tube = {{ outer_diameter = 0.3, wall = 0.005 }} }}
{mast_terms}
[[plates]]
name = "wing"
parent = "mast"
station = 13.0
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 15.0
width = 3.75
areal_density = 8.0
bending_stiffness = 6.2e5
poisson_ratio = 0.3
{plate_terms}
[ritz]
{ritz}
"#
    )
}

/// The lowest `count` elastic ω of a scenario, by the partial solver.
fn lowest_omegas(toml: &str, count: usize) -> Vec<f64> {
    let s = scenario(toml);
    let model = RitzModel::assemble(&s.structure);
    let modes = ModalAnalysis::compute_lowest(&model, Some(count)).expect("modes");
    elastic_omegas(&modes)
}

/// A converged reference for a structure whose plate limits the convergence: Ritz values at
/// plate length counts 48, 64 and 80 (everything else generous and fixed) and their
/// Richardson extrapolation with the rate p fitted per mode from the three levels,
/// ω_∞ = ω₈₀ − d₂/((80/64)^p − 1) — written here independently of the library's estimator.
/// Also returns the extrapolation's size, (ω₈₀ − ω_∞)/ω_∞: the reference's own uncertainty
/// is a fraction of it.
fn extrapolated(toml_at: impl Fn(usize) -> String, count: usize) -> (Vec<f64>, f64) {
    let counts = [48, 64, 80];
    let w: Vec<Vec<f64>> = counts
        .iter()
        .map(|&n| lowest_omegas(&toml_at(n), count))
        .collect();
    richardson(counts, &w)
}

/// The per-mode Richardson limit of three levels at counts n₀ < n₁ < n₂ (error ≈ C n^(−p),
/// p fitted per mode) and the largest relative correction.
fn richardson(n: [usize; 3], w: &[Vec<f64>]) -> (Vec<f64>, f64) {
    let (a, b) = (n[1] as f64 / n[0] as f64, n[2] as f64 / n[1] as f64);
    let mut worst = 0.0_f64;
    let reference = (0..w[0].len())
        .map(|k| {
            let (d1, d2) = (w[0][k] - w[1][k], w[1][k] - w[2][k]);
            assert!(
                d1 >= -1e-12 * w[0][k] && d2 >= -1e-12 * w[0][k],
                "monotone from above"
            );
            let g = |p: f64| (a.powf(p) - 1.0) * b.powf(p) / (b.powf(p) - 1.0);
            let target = d1 / d2.max(1e-300);
            let (mut lo, mut hi) = (0.5, 30.0);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if g(mid) < target {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            let p = 0.5 * (lo + hi);
            let inf = w[2][k] - d2.max(0.0) / (b.powf(p) - 1.0);
            worst = worst.max((w[2][k] - inf) / inf);
            inf
        })
        .collect();
    (reference, worst)
}

/// Asserts, for every tolerance, that the automatic selection's true error (against
/// `truth`) is below the tolerance and its estimate at least half the true error.
fn check_selection(
    case: &str,
    tolerances: &[f64],
    toml_with: impl Fn(f64) -> String,
    truth: &[f64],
    count: usize,
) {
    for &tol in tolerances {
        let s = scenario(&toml_with(tol));
        let sel = s.term_selection.expect("a selection");
        assert!(
            sel.reached,
            "{case}, tol {tol:e}: not reached: {:?}",
            sel.frequency_error
        );
        assert_eq!(sel.omega.len(), count);
        if std::env::var("FC_SHOW").is_ok() {
            let ratios: Vec<String> = (0..count)
                .map(|k| {
                    let t = sel.omega[k] / truth[k] - 1.0;
                    format!("{:.1e}/{:.2}", t, sel.frequency_error[k] / t)
                })
                .collect();
            eprintln!(
                "{case} tol {tol:e} dof {} solves {}: {}",
                sel.dof,
                sel.solves,
                ratios.join(" ")
            );
            let kw = (0..count)
                .max_by(|&a, &b| (sel.omega[a] / truth[a]).total_cmp(&(sel.omega[b] / truth[b])))
                .unwrap();
            eprintln!(
                "   worst mode {kw}: true {:.2e} fams {:?}",
                sel.omega[kw] / truth[kw] - 1.0,
                sel.families
                    .iter()
                    .map(|f| (f.family, f.terms, format!("{:.2e}", f.error[kw])))
                    .collect::<Vec<_>>()
            );
            continue;
        }
        for k in 0..count {
            let true_err = sel.omega[k] / truth[k] - 1.0;
            let est = sel.frequency_error[k];
            assert!(
                true_err <= tol,
                "{case}, tol {tol:e}, mode {k}: true error {true_err:e} (dof {})",
                sel.dof
            );
            // (Below 1e-12 the "true error" is the rounding of the two computations.)
            assert!(
                est >= 0.5 * true_err || true_err < 1e-12,
                "{case}, tol {tol:e}, mode {k}: estimate {est:e} < half the true error {true_err:e}; {:?}",
                sel.families.iter().map(|f| (f.family, f.terms, f.error[k])).collect::<Vec<_>>()
            );
        }
    }
}

#[test]
fn composite_reaches_every_tolerance_with_an_honest_estimate() {
    for motion in ["fixed", "free"] {
        let (reference, spread) = extrapolated(
            |n| {
                composite(
                    motion,
                    "terms = { bending = 36, torsion = 20, axial = 20 }",
                    &format!("terms = {{ length = {n}, width = 28 }}"),
                    "",
                )
            },
            10,
        );
        // The reference's correction is small against the finest tolerance checked.
        assert!(spread < 3e-7, "{motion}: extrapolation {spread:e}");
        check_selection(
            &format!("composite, {motion} hub"),
            &[1e-3, 1e-4, 1e-5, 1e-6],
            |tol| {
                composite(
                    motion,
                    "",
                    "",
                    &format!("tolerance = {tol}\nmodes = 10\nmax_dof = 3000"),
                )
            },
            &reference,
            10,
        );
    }
}

/// A 2 m cantilever (E = 70 GPa, ρ = 2700 kg/m³, A = 1e-3 m², I = 1e-6 m⁴, J = I_p = 2e-6 m⁴)
/// with a 3 kg tip mass (inertia 0.05 kg·m² about the axis, 0.2 across it), the terms left
/// to the selection.
fn tip_mass_cantilever(ritz: &str) -> String {
    format!(
        r#"
name = "tip mass"
[hub]
motion = "fixed"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
center_of_mass = [0.0, 0.0, 0.0]
[materials.al]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = 2700.0
[[beams]]
name = "beam"
parent = "hub"
root = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 2.0
material = "al"
section = {{ area = 1e-3, iy = 1e-6, iz = 1e-6, torsion_constant = 2e-6, polar_inertia = 2e-6 }}
[[masses]]
name = "tip"
parent = "beam"
station = 2.0
mass = 3.0
inertia = [0.05, 0.2, 0.2]
[ritz]
{ritz}
"#
    )
}

/// The exact lowest frequencies of [`tip_mass_cantilever`], merged in ascending order:
/// bending in both planes (the transcendental equation of `exact_beams.rs`:
/// EI W″(L) = J ω² W′(L), EI W‴(L) = −m ω² W(L)), axial (βL tan βL = ρAL/m, ω = β√(E/ρ))
/// and torsion (βL tan βL = ρI_pL/J_x, ω = β√(GJ/(ρI_p))).
fn tip_mass_exact(count: usize) -> Vec<f64> {
    use super::common::roots;
    let (e, rho, a, i, l, m, j, jx) = (70e9, 2700.0, 1e-3, 1e-6, 2.0, 3.0, 0.2, 0.05);
    let (jt, ip, g) = (2e-6, 2e-6, 70e9 / 2.6);
    let ra = rho * a;
    let det = |b: f64| {
        let x = b * l;
        let (ch, sh, c, s) = (x.cosh(), x.sinh(), x.cos(), x.sin());
        let w = [ch - c, sh - s];
        let w1 = [sh + s, ch - c];
        let w2 = [ch + c, sh + s];
        let w3 = [sh - s, ch + c];
        let k1 = j * b * b * b / ra;
        let k2 = m * b / ra;
        let r1 = [w2[0] - k1 * w1[0], w2[1] - k1 * w1[1]];
        let r2 = [w3[0] + k2 * w[0], w3[1] + k2 * w[1]];
        (r1[0] * r2[1] - r1[1] * r2[0]) / (ch * ch)
    };
    let mut all: Vec<f64> = Vec::new();
    for b in roots(det, 0.05, 14.0, 20000) {
        let w = b * b * (e * i / ra).sqrt();
        all.extend([w, w]);
    }
    let rod = |c: f64| roots(move |x: f64| x * x.sin() - c * x.cos(), 1e-6, 60.0, 20000);
    all.extend(rod(ra * l / m).iter().map(|x| x / l * (e / rho).sqrt()));
    all.extend(
        rod(rho * ip * l / jx)
            .iter()
            .map(|x| x / l * (g * jt / (rho * ip)).sqrt()),
    );
    all.sort_by(f64::total_cmp);
    assert!(all.len() >= count);
    all.truncate(count);
    all
}

#[test]
fn tip_mass_cantilever_reaches_every_tolerance_with_an_honest_estimate() {
    let exact = tip_mass_exact(10);
    check_selection(
        "tip-mass cantilever",
        &[1e-3, 1e-4, 1e-5, 1e-6],
        |tol| tip_mass_cantilever(&format!("tolerance = {tol}\nmodes = 10")),
        &exact,
        10,
    );
}

#[test]
fn cfff_plate_reaches_every_tolerance_with_an_honest_estimate() {
    use super::common::cfff_plate;
    // Extrapolated in both directions: in the length at widths 24, 32 and 48, then in the
    // width (at 1e-6 the selection's width 55 resolves more than a width of 28 does).
    let widths = [24, 32, 48];
    let at: Vec<Vec<f64>> = widths
        .iter()
        .map(|&nw| {
            let (r, spread) = extrapolated(|n| cfff_plate(1.0, "legendre", n, nw), 10);
            assert!(spread < 3e-7, "width {nw}: length extrapolation {spread:e}");
            r
        })
        .collect();
    let (reference, spread) = richardson(widths, &at);
    assert!(spread < 3e-7, "width extrapolation {spread:e}");
    let auto = |tol: f64| {
        cfff_plate(1.0, "legendre", 1, 1)
            .replace("terms = { length = 1, width = 1 }", "")
            .replace(
                "[ritz]\n",
                &format!("[ritz]\ntolerance = {tol}\nmodes = 10\nmax_dof = 4000\n"),
            )
    };
    // 1e-6 needs the last step shortened to fit max_dof (width 41 → 55 at length 72, 3966
    // coordinates), measured backward there.
    check_selection(
        "CFFF plate",
        &[1e-3, 1e-4, 1e-5, 1e-6],
        auto,
        &reference,
        10,
    );
}

/// The final solve started from the selection's own eigenvectors
/// (`ModalAnalysis::compute_selected`) gives the modes of the cold solve
/// (`compute_lowest`): frequencies to 1e-10 relative, M-orthonormal shapes to 1e-10, and
/// the hub-fixed frequencies (whose pencil the selection never solved for a free hub) too.
#[test]
fn the_warm_started_final_solve_equals_the_cold_one() {
    for motion in ["fixed", "free"] {
        let s = scenario(&composite(
            motion,
            "",
            "",
            "tolerance = 1e-5\nmodes = 10\nmax_dof = 3000",
        ));
        let sel = s.term_selection.as_ref().expect("a selection");
        let model = RitzModel::assemble(&s.structure);
        let cold = ModalAnalysis::compute_lowest(&model, Some(10)).expect("cold");
        let warm = ModalAnalysis::compute_selected(&model, Some(10), Some(sel)).expect("warm");
        assert!(warm.selection.is_some());
        let (wc, ww) = (elastic_omegas(&cold), elastic_omegas(&warm));
        assert_eq!(wc.len(), ww.len());
        for (a, b) in wc.iter().zip(&ww) {
            assert!((a / b - 1.0).abs() < 1e-10, "{motion}: {a} vs {b}");
        }
        for (a, b) in cold.hub_fixed.iter().zip(&warm.hub_fixed) {
            let (a, b) = (a.omega_rad_s, b.omega_rad_s);
            assert!(
                (a / b - 1.0).abs() < 1e-10,
                "{motion}, hub fixed: {a} vs {b}"
            );
        }
        let m = &model.mass;
        let shapes: Vec<&Vec<f64>> = warm.elastic().map(|md| &md.shape).collect();
        for (i, x) in shapes.iter().enumerate() {
            for (j, y) in shapes.iter().enumerate() {
                let mut xy = 0.0;
                for r in 0..m.nrows() {
                    for c in 0..m.ncols() {
                        xy += x[r] * m[(r, c)] * y[c];
                    }
                }
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((xy - want).abs() < 1e-10, "{motion}: φ{i}ᵀMφ{j} = {xy}");
            }
        }
    }
}

/// A level's independent solves run side by side, each sequential inside: the whole `modes
/// --json` output (counts, frequencies, estimates, shapes) is byte-for-byte the same on one
/// thread and on four (`RAYON_NUM_THREADS`, read when a process makes its pool, so each
/// count is its own process).
#[test]
fn the_selection_does_not_depend_on_the_number_of_threads() {
    let dir = std::env::temp_dir().join(format!("fc-threads-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("composite.toml");
    std::fs::write(
        &path,
        composite("free", "", "", "tolerance = 1e-5\nmodes = 10"),
    )
    .expect("write");
    let on = |threads: &str| {
        let out = super::common::bin()
            .args(["modes", "--json"])
            .arg(&path)
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .expect("run flexcraft");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    let (a, b) = (on("1"), on("4"));
    assert!(!a.is_empty());
    assert!(a == b, "modes --json differs between 1 and 4 threads");
    std::fs::remove_dir_all(&dir).ok();
}
