//! Automatic term selection (`[ritz] tolerance`): the achieved error against independent
//! truths, and the honesty of the reported estimate.

use super::common::{elastic_omegas, scenario, solve};
use flexcraft::ritz::refine::TermSelection;

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

fn selection(toml: &str) -> (TermSelection, Vec<f64>) {
    let s = scenario(toml);
    let sel = s.term_selection.clone().expect("a selection");
    let (_, modes) = solve(toml);
    (sel, elastic_omegas(&modes))
}

#[test]
fn explore_composite() {
    for motion in ["fixed", "free"] {
        let reference = elastic_omegas(
            &solve(&composite(
                motion,
                "terms = { bending = 40, torsion = 24, axial = 24 }",
                "terms = { length = 40, width = 24 }",
                "",
            ))
            .1,
        );
        let coarser = elastic_omegas(
            &solve(&composite(
                motion,
                "terms = { bending = 32, torsion = 18, axial = 18 }",
                "terms = { length = 32, width = 18 }",
                "",
            ))
            .1,
        );
        for k in 0..10 {
            println!("{motion} ref {k}: {} rel diff {:e}", reference[k], coarser[k] / reference[k] - 1.0);
        }
        for tol in [1e-3, 1e-4, 1e-5, 1e-6] {
            let t = std::time::Instant::now();
            let (sel, _) = selection(&composite(motion, "", "", &format!("tolerance = {tol}\nmodes = 10")));
            let el = t.elapsed().as_secs_f64();
            let worst = (0..10)
                .map(|k| {
                    let truth = sel.omega[k] / reference[k] - 1.0;
                    (truth, sel.frequency_error[k])
                })
                .collect::<Vec<_>>();
            println!(
                "{motion} tol {tol:e}: dof {} solves {} asm {} reached {} {:.3}s",
                sel.dof, sel.solves, sel.assemblies, sel.reached, el
            );
            for f in &sel.families {
                println!("   {:?} {}", f.family, f.terms);
            }
            for (k, (t, e)) in worst.iter().enumerate() {
                println!("   mode {k}: true {t:.3e} est {e:.3e} ratio {:.2}", e / t);
            }
        }
    }
}

#[test]
fn explore_plate_rates() {
    use super::common::clamped_plate;
    let w = |nl: usize, nw: usize| elastic_omegas(&solve(&clamped_plate(15.0, 3.75, 6.2e5, 8.0, 0.3, "legendre", nl, nw)).1);
    let base = w(48, 40);
    for nw in [4, 6, 9, 12, 16, 20, 24, 28, 32] {
        let x = w(48, nw);
        println!("width {nw}: {:?}", (0..8).map(|k| format!("{:.2e}", x[k] / base[k] - 1.0)).collect::<Vec<_>>());
    }
    for nl in [6, 9, 12, 16, 20, 24, 28, 32, 40] {
        let x = w(nl, 40);
        println!("length {nl}: {:?}", (0..8).map(|k| format!("{:.2e}", x[k] / base[k] - 1.0)).collect::<Vec<_>>());
    }
}

#[test]
fn explore_reference() {
    use flexcraft::{ModalAnalysis, RitzModel};
    for (b, t, l, w) in [(30, 16, 48, 24), (36, 20, 64, 28), (40, 20, 80, 28)] {
        let t0 = std::time::Instant::now();
        let s = scenario(&composite("free", &format!("terms = {{ bending = {b}, torsion = {t}, axial = {t} }}"), &format!("terms = {{ length = {l}, width = {w} }}"), ""));
        let model = RitzModel::assemble(&s.structure);
        let t1 = t0.elapsed().as_secs_f64();
        let m = ModalAnalysis::compute_lowest(&model, Some(10)).unwrap();
        let om = elastic_omegas(&m);
        println!("{} dof asm {t1:.2}s total {:.2}s {:?}", model.dof(), t0.elapsed().as_secs_f64(), om.iter().map(|x| format!("{x:.12}")).collect::<Vec<_>>());
    }
}
