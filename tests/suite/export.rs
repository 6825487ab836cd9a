//! The exported linear model (`flexcraft export`): its frequency response against a direct
//! solve of the full Ritz model, its rigid-body asymptotes against the structure's own mass
//! properties, the eigenvalues of A, and the participation's completeness against the
//! published effective masses of a cantilever.

use super::common::scenario;
use faer::linalg::solvers::Solve;
use faer::Mat;
use flexcraft::export::{point_jacobian, ExportModel, ExportSettings, PointLocation};
use flexcraft::{ModalAnalysis, RitzModel};

/// A free hub (CM off the reference point), a tube boom, a plate at the boom's tip and a
/// lumped mass on the boom; points on every kind of component.
fn spacecraft(motion: &str, extra: &str) -> String {
    format!(
        r#"
name = "export test"
[hub]
motion = "{motion}"
mass = 300.0
inertia = [120.0, 150.0, 90.0, 4.0, -3.0, 2.0]
center_of_mass = [0.1, -0.2, -0.4]
[materials.al]
youngs_modulus = 70e9
poisson_ratio = 0.3
density = 2700.0
[[beams]]
name = "boom"
parent = "hub"
root = [0.3, 0.0, 0.5]
axis = [0.0, 0.2, 1.0]
length = 4.0
material = "al"
section = {{ tube = {{ outer_diameter = 0.08, wall = 0.003 }} }}
terms = {{ bending = 6, torsion = 4, axial = 3 }}
[[plates]]
name = "wing"
parent = "boom"
station = 4.0
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 3.0
width = 1.2
areal_density = 4.0
bending_stiffness = 2.0e3
poisson_ratio = 0.3
terms = {{ length = 5, width = 3 }}
[[masses]]
name = "box"
parent = "boom"
station = 2.5
offset = [0.1, 0.05, 0.0]
mass = 12.0
inertia = [0.3, 0.2, 0.25]
[export]
{extra}
[[export.points]]
name = "tip"
component = "boom"
station = 4.0
[[export.points]]
name = "corner"
component = "wing"
xi = 1.0
eta = 0.0
[[export.points]]
name = "payload"
component = "box"
[[export.points]]
name = "sensor"
component = "hub"
position = [0.5, 0.5, -0.3]
"#
    )
}

/// Runs `flexcraft export examples/export.toml --out OUT` and checks it succeeded.
fn export_example(out: &std::path::Path) {
    use super::common::{bin, example};
    let o = bin()
        .arg("export")
        .arg(example("export.toml"))
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn build(toml: &str) -> (RitzModel, ModalAnalysis, ExportModel, ExportSettings) {
    let s = scenario(toml);
    let model = RitzModel::assemble(&s.structure);
    let modes = ModalAnalysis::compute_lowest(&model, s.export_modes()).expect("modes");
    let ex = ExportModel::build(&model, &modes, &s.export).expect("export");
    (model, modes, ex, s.export)
}

/// H(iω) of every input/output pair by a direct solve of (K − ω²M + iωC_q) q = B_q u on the
/// full Ritz model, with C_q = M Φ diag(2ζω) Φᵀ M (modal damping in physical coordinates),
/// in real block form [[K − ω²M, −ωC], [ωC, K − ω²M]] [qr; qi] = [b; 0].
fn direct_response(
    model: &RitzModel,
    modes: &ModalAnalysis,
    zeta: f64,
    sites: &[PointLocation],
    omega: f64,
) -> Vec<Vec<(f64, f64)>> {
    // A fixed hub holds its six coordinates: the direct solve keeps the elastic ones only.
    let h = match modes.hub_motion {
        flexcraft::structure::HubMotion::Free => 0,
        flexcraft::structure::HubMotion::Fixed => 6,
    };
    let n = model.dof() - h;
    let m = model.mass.submatrix(h, h, n, n).to_owned();
    let k = model.stiffness.submatrix(h, h, n, n).to_owned();
    let phi = Mat::from_fn(n, modes.modes.len(), |i, j| modes.modes[j].shape[h + i]);
    let z = Mat::from_fn(modes.modes.len(), modes.modes.len(), |i, j| {
        let md = &modes.modes[i];
        if i == j && !md.rigid {
            2.0 * zeta * md.omega_rad_s
        } else {
            0.0
        }
    });
    let mp = &m * &phi;
    let c = &mp * &z * mp.transpose();
    let dyn_k = Mat::from_fn(n, n, |i, j| k[(i, j)] - omega * omega * m[(i, j)]);
    let big = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => dyn_k[(i, j)],
        (true, false) => -omega * c[(i, j - n)],
        (false, true) => omega * c[(i - n, j)],
        (false, false) => dyn_k[(i - n, j - n)],
    });
    let lu = big.partial_piv_lu();
    let jac: Vec<Vec<[f64; 6]>> = sites.iter().map(|s| point_jacobian(model, s)).collect();
    let ni = 6 * sites.len();
    let rhs = Mat::from_fn(2 * n, ni, |r, col| {
        if r < n {
            jac[col / 6][h + r][col % 6]
        } else {
            0.0
        }
    });
    let q = lu.solve(&rhs);
    // Outputs: every site's six displacement components (the velocity ones are iω times).
    (0..ni)
        .map(|o| {
            (0..ni)
                .map(|i| {
                    let (mut re, mut im) = (0.0, 0.0);
                    for r in 0..n {
                        let jr = jac[o / 6][h + r][o % 6];
                        re += jr * q[(r, i)];
                        im += jr * q[(n + r, i)];
                    }
                    (re, im)
                })
                .collect()
        })
        .collect()
}

/// Row of output `o`'s displacement of site s, component c, in the export's output list.
fn displacement_row(site: usize, c: usize) -> usize {
    if site == 0 {
        c
    } else {
        12 + 9 * (site - 1) + c
    }
}

fn check_against_direct(motion: &str) {
    let zeta = 0.02;
    let (model, _, ex, settings) = build(&spacecraft(motion, &format!("damping_ratio = {zeta}")));
    // Every mode kept: the modal sum is exact.
    let all = ModalAnalysis::compute(&model).expect("modes");
    assert_eq!(ex.modes.len(), all.modes.len());
    let sites: Vec<PointLocation> = std::iter::once(PointLocation::Hub {
        position: flexcraft::math::Vec3::ZERO,
    })
    .chain(settings.points.iter().map(|p| p.location))
    .collect();
    let w1 = ex
        .modes
        .iter()
        .find(|m| !m.rigid)
        .expect("elastic")
        .omega_rad_s;
    for omega in [0.37 * w1, 1.3 * w1, 7.9 * w1, 55.0 * w1] {
        let direct = direct_response(&model, &all, zeta, &sites, omega);
        let mut scale: f64 = 0.0;
        for row in &direct {
            for (re, im) in row {
                scale = scale.max(re.hypot(*im));
            }
        }
        for o in 0..6 * sites.len() {
            for i in 0..6 * sites.len() {
                let h = ex.transfer(displacement_row(o / 6, o % 6), i, omega);
                let (re, im) = direct[o][i];
                let err = (h.re - re).hypot(h.im - im);
                assert!(
                    err <= 1e-9 * scale,
                    "{motion} ω = {omega}: {} → {}: modal {h} vs direct {re}+{im}i",
                    ex.input_names[i],
                    ex.output_names[displacement_row(o / 6, o % 6)]
                );
                // Velocity outputs are iω times the displacement ones.
                if o / 6 == 0 || o % 6 < 3 {
                    let vrow = if o / 6 == 0 {
                        6 + o
                    } else {
                        displacement_row(o / 6, o % 6) + 6
                    };
                    let hv = ex.transfer(vrow, i, omega);
                    let err = (hv.re + omega * im).hypot(hv.im - omega * re);
                    assert!(
                        err <= 1e-9 * scale * omega,
                        "velocity {}",
                        ex.output_names[vrow]
                    );
                }
            }
        }
    }
}

#[test]
fn frequency_response_equals_a_direct_solve_of_the_full_ritz_model() {
    check_against_direct("free");
    check_against_direct("fixed");
}

/// At low frequency the free structure responds as a rigid body: −ω² H(hub wrench → hub
/// motion) → M_O⁻¹, the inverse of the whole structure's rigid mass about the hub's
/// reference point, computed here from the components' own mass properties
/// ([`flexcraft::structure::Structure::rigid_body`]), not from the Ritz mass matrix. Its
/// force → position block along a principal direction is 1/m_total only at the CM; the
/// torque → attitude block is the inverse inertia about the system CM.
#[test]
fn low_frequency_asymptote_is_the_inverse_rigid_mass() {
    let (_, _, ex, _) = build(&spacecraft("free", "modes = 8"));
    let body = scenario(&spacecraft("free", "modes = 8"))
        .structure
        .rigid_body();
    // structure.rigid_body() is about the structure frame's origin: the hub's reference point.
    let m6 = body.block();
    let mref = Mat::from_fn(6, 6, |i, j| m6[i][j]);
    let inv = mref.partial_piv_lu().solve(Mat::<f64>::identity(6, 6));
    let w1 = ex
        .modes
        .iter()
        .find(|m| !m.rigid)
        .expect("elastic")
        .omega_rad_s;
    let omega = 1e-4 * w1;
    for o in 0..6 {
        for i in 0..6 {
            let h = ex.transfer(o, i, omega);
            let got = -omega * omega * h.re;
            let want = inv[(o, i)];
            assert!(
                (got - want).abs() <= 1e-6 * inv[(o, o)].abs().max(inv[(i, i)].abs()),
                "{} → {}: {got} vs {want}",
                ex.input_names[i],
                ex.output_names[o]
            );
        }
    }
    // Torque → attitude: the inverse inertia about the system CM.
    let jcm = body.inertia_at_cm();
    let j = Mat::from_fn(3, 3, |a, b| jcm.get(a, b));
    let jinv = j.partial_piv_lu().solve(Mat::<f64>::identity(3, 3));
    for a in 0..3 {
        for b in 0..3 {
            assert!((inv[(3 + a, 3 + b)] - jinv[(a, b)]).abs() <= 1e-12 * jinv[(a, a)]);
        }
    }
    assert!((ex.total_mass - body.mass).abs() <= 1e-12 * body.mass);
    assert!((ex.center_of_mass - body.center_of_mass()).norm() <= 1e-12);
}

/// The eigenvalues of A are −ζω ± iω√(1 − ζ²) for every kept elastic mode and pairs of
/// zeros for the rigid modes (faer's general eigen-solver, not the construction).
#[test]
fn eigenvalues_of_a_are_the_damped_modal_poles() {
    let zetas = "[0.01, 0.02, 0.03, 0.05, 0.1, 0.2]";
    let (_, _, ex, _) = build(&spacecraft("free", &format!("damping_ratio = {zetas}")));
    assert_eq!(ex.modes.iter().filter(|m| !m.rigid).count(), 6);
    let ss = ex.first_order();
    let ev = ss.a.eigenvalues().expect("eigenvalues");
    let mut want: Vec<(f64, f64)> = Vec::new();
    for m in &ex.modes {
        let (w, z) = (m.omega_rad_s, m.damping_ratio);
        let wd = w * (1.0 - z * z).sqrt();
        want.push((-z * w, wd));
        want.push((-z * w, -wd));
    }
    let wmax = ex.modes.iter().map(|m| m.omega_rad_s).fold(0.0, f64::max);
    for (re, im) in want {
        let best = ev
            .iter()
            .map(|e| (e.re - re).hypot(e.im - im))
            .fold(f64::INFINITY, f64::min);
        // Zero poles are a defective (Jordan) pair: their computed values scatter by √ε.
        let tol = if re == 0.0 && im == 0.0 {
            1e-6 * wmax
        } else {
            1e-9 * wmax
        };
        assert!(best <= tol, "pole {re}{im:+}i: nearest computed at {best}");
    }
}

/// A slender cantilever on a fixed hub: the effective-mass fractions of its first bending
/// modes are the Euler–Bernoulli cantilever's 0.6131, 0.1883, 0.0647 (closed form below),
/// and the participation's Σ L Lᵀ is the projection the Müntz distance formula gives.
#[test]
fn participation_reproduces_the_cantilever_effective_masses() {
    let toml = r#"
name = "cantilever"
[hub]
motion = "fixed"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
center_of_mass = [0.0, 0.0, 0.0]
[materials.steel]
youngs_modulus = 210e9
poisson_ratio = 0.3
density = 7850.0
[[beams]]
name = "boom"
parent = "hub"
root = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 3.0
material = "steel"
section = { tube = { outer_diameter = 0.05, wall = 0.002 } }
terms = { bending = 16, torsion = 4, axial = 4 }
"#;
    let (_, modes, ex, _) = build(toml);
    let beam_mass =
        7850.0 * std::f64::consts::PI / 4.0 * (0.05f64.powi(2) - 0.046f64.powi(2)) * 3.0;
    // Closed form: β_j L are the roots of 1 + cos βL cosh βL = 0 and the effective-mass
    // fraction of mode j is 4 σ_j² / (β_j L)², σ_j = (sinh − sin)/(cosh + cos) at β_j L.
    let beta_l = [1.875104068711961, 4.694091132974175, 7.854757438237613];
    let frac: Vec<f64> = beta_l
        .iter()
        .map(|&b: &f64| {
            let sigma = (b.sinh() - b.sin()) / (b.cosh() + b.cos());
            4.0 * sigma * sigma / (b * b)
        })
        .collect();
    assert!((frac[0] - 0.6131).abs() < 1e-4 && (frac[1] - 0.1883).abs() < 1e-4);
    // Bending in y (direction 1) and z (direction 2): hub-fixed modes come in pairs.
    let mut got_y: Vec<f64> = (0..ex.hub_fixed_omega.len())
        .map(|j| ex.effective_mass[(1, j)] / beam_mass)
        .filter(|f| *f > 1e-3)
        .collect();
    got_y.truncate(3);
    for (g, w) in got_y.iter().zip(&frac) {
        assert!((g - w).abs() <= 1e-6, "effective mass fraction {g} vs {w}");
    }
    // Completeness: Σ_j L_j L_jᵀ over all N bending modes is the mass-weighted projection of
    // the rigid translation onto the clamped bending basis, whose span is {x², …, x^(N+1)}
    // (polynomial basis). By the Müntz/Cauchy-determinant distance formula, the L²(0, 1)
    // distance of 1 from span{x^λ_k} is Π λ_k/(λ_k + 1) (Borwein & Erdélyi, "Polynomials and
    // Polynomial Inequalities", Springer 1995, §4.2), which telescopes here to 2/(N + 2): the
    // reported fraction is exactly 1 − (2/(N + 2))².
    let nf = ex.hub_fixed_omega.len();
    let sum_yy: f64 = (0..nf).map(|j| ex.participation[(1, j)].powi(2)).sum();
    let want = 1.0 - (2.0f64 / 18.0).powi(2);
    assert!(
        (sum_yy / modes.appendage_mass[1] - want).abs() <= 1e-10,
        "completeness {} vs {want}",
        sum_yy / modes.appendage_mass[1]
    );
    let last = ex.effective_mass_fraction[(1, nf - 1)];
    assert!((last - want).abs() <= 1e-10, "reported fraction {last}");
    // The signed participation squares to the effective mass.
    for j in 0..nf {
        for d in 0..6 {
            let l = ex.participation[(d, j)];
            let e = ex.effective_mass[(d, j)];
            assert!(e == 0.0 || (l * l - e).abs() <= 1e-12 * e);
        }
    }
}

/// Every bad `[export]` value is refused through the binary with its file:line, key and
/// reason, exit status 2, and nothing written.
#[test]
fn export_keys_are_refused_with_location() {
    use super::hardening_input::{assert_refused, run};
    let dir = super::common::scratch("export_keys");
    let base = include_str!("../../examples/export.toml");
    for (from, to, key, reason) in [
        (
            "component = \"mast\"",
            "component = \"mats\"",
            "export.points[1].component",
            "no component is named \"mats\"",
        ),
        (
            "station = 13.0\n\n[[export.points]]\nname = \"wing_tip\"",
            "station = 13.5\n\n[[export.points]]\nname = \"wing_tip\"",
            "export.points[1].station",
            "0 to 13 m",
        ),
        (
            "xi = 1.0",
            "xi = 1.2",
            "export.points[2].xi",
            "must lie in [0, 1]",
        ),
        (
            "name = \"mast_tip\"",
            "name = \"star_tracker\"",
            "export.points[1].name",
            "already defined",
        ),
        (
            "name = \"mast_tip\"",
            "name = \"hub\"",
            "export.points[1].name",
            "reserved",
        ),
        (
            "name = \"mast_tip\"",
            "name = \"mast tip\"",
            "export.points[1].name",
            "not a point name",
        ),
        (
            "output = \"hub.rz\"",
            "output = \"hub.rq\"",
            "export.transfer[0].output",
            "no output is named \"hub.rq\"",
        ),
        (
            "input = \"hub.tx\"\noutput = \"wing_tip.uz\"",
            "input = \"wing.tx\"\noutput = \"wing_tip.uz\"",
            "export.transfer[2].input",
            "no input is named \"wing.tx\"",
        ),
        (
            "damping_ratio = 0.005",
            "damping_ratio = 1.0",
            "export.damping_ratio",
            "[0, 1)",
        ),
        (
            "damping_ratio = 0.005",
            "damping_ratio = [0.01, 0.02]",
            "export.damping_ratio",
            "lists 2 values but export.modes = 12",
        ),
        (
            "damping_ratio = 0.005",
            "damping_ratio = [0.01, -0.02]",
            "export.damping_ratio",
            "[0, 1)",
        ),
        ("modes = 12", "modes = 0", "export.modes", "from 1 to"),
        (
            "position = [0.5, 0.0, 0.8]",
            "position = [0.5, 0.0, 0.8]\nstation = 1.0",
            "export.points[0].station",
            "does not take this key",
        ),
    ] {
        let src = base.replacen(from, to, 1);
        assert!(src != base, "{to}");
        let out = run(&dir, "export", &src, &[]);
        // The refused value's line: where `to` went in, at its line naming the key.
        let field = key.rsplit('.').next().unwrap();
        let within = to
            .lines()
            .position(|l| l.trim_start().starts_with(field))
            .unwrap_or(0);
        let line = base[..base.find(from).unwrap()].matches('\n').count() + 1 + within;
        assert_refused(&dir, &out, line, key, reason);
    }
    // A damping list longer than the modes the model has: found after the solve, located.
    let src = base
        .replacen("modes = 12\n", "", 1)
        .replacen("tolerance = 1e-5\n", "tolerance = 1e-5\nmodes = 3\n", 1)
        .replacen(
            "damping_ratio = 0.005",
            "damping_ratio = [0.01, 0.02, 0.03, 0.04]",
            1,
        );
    let out = run(&dir, "export", &src, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    // The list sets the kept modes (4) and the automatic terms aim at them: accepted.
    assert_eq!(out.status.code(), Some(0), "{err}");
}

/// The same input gives byte-identical files.
#[test]
fn export_is_byte_identical_between_runs() {
    use super::common::{assert_same_tree, scratch};
    let dir = scratch("export_twice");
    for k in ["a", "b"] {
        export_example(&dir.join(k));
    }
    assert!(assert_same_tree(&dir.join("a"), &dir.join("b")) >= 4);
}

/// The exported files read by the programs they are for: `scripts/check_export_files.py`
/// loads model.npz with NumPy and model.mat with SciPy, compares them with model.json, checks
/// A's poles, and evaluates C (iωI − A)⁻¹ B + D by a dense complex solve against
/// frequency_response.csv (a second formulation of the modal sum). Ignored by default (it
/// needs Python with numpy and scipy): `scripts/check_array_files.sh` runs it.
#[test]
#[ignore = "needs Python with numpy and scipy: scripts/check_array_files.sh"]
fn export_files_load_in_numpy_and_scipy() {
    use super::common::scratch;
    // Run under --ignored, a missing Python is a failure, not a pass.
    let python = std::env::var_os("FLEXCRAFT_PYTHON")
        .expect("FLEXCRAFT_PYTHON not set: run scripts/check_array_files.sh");
    let dir = scratch("export-python");
    export_example(&dir.join("out"));
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_export_files.py");
    let out = std::process::Command::new(&python)
        .arg(&script)
        .arg(dir.join("out"))
        .output()
        .unwrap_or_else(|e| panic!("cannot run FLEXCRAFT_PYTHON={python:?}: {e}"));
    print!("{}", String::from_utf8_lossy(&out.stdout));
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// NASA 42's flex file, read back in 42's reading order, against a second formulation: its
/// modal integrals are sums over quadrature points of the continuum (and the rigid bodies),
/// while the participation matrix comes from the Ritz mass matrix, φᵀ M_{e,d}. The two must
/// agree: Pf_p = ∫Ψ_p dm is the translational participation, and Hf_p = ∫ r × Ψ_p dm about the
/// reference point is the rotational participation (about the hub's centre of mass c) plus
/// c × Pf_p. Mf is the identity, Kf = diag(ω²) of the hub-fixed modes, and the node file lists
/// the hub and the named points where they are.
#[test]
fn flex_file_integrals_agree_with_the_ritz_participation() {
    use super::common::scratch;
    use flexcraft::output::flex42::{read_flex_file, read_nodes_file};
    let dir = scratch("export-42");
    export_example(&dir.join("out"));
    let text = std::fs::read_to_string(dir.join("out/flex_export.txt")).unwrap();
    let flex = read_flex_file(&text).expect("42 reads the flex file");
    let nodes =
        read_nodes_file(&std::fs::read_to_string(dir.join("out/nodes_export.txt")).unwrap())
            .expect("42 reads the node file");
    let (_, modes, ex, _) = build(include_str!("../../examples/export.toml"));
    let nf = flex.pf.len();
    assert_eq!(nf, 12);
    let c = scenario(include_str!("../../examples/export.toml"))
        .structure
        .hub()
        .center_of_mass();
    let scale = (0..nf)
        .flat_map(|p| (0..6).map(move |d| (p, d)))
        .map(|(p, d)| ex.participation[(d, p)].abs())
        .fold(0.0, f64::max);
    for p in 0..nf {
        let l = &modes.hub_fixed[p].participation;
        let pf = flex.pf[p];
        for a in 0..3 {
            assert!(
                (pf[a] - l[a]).abs() <= 1e-9 * scale,
                "Pf[{p}][{a}] {} vs L {}",
                pf[a],
                l[a]
            );
        }
        // c × Pf
        let cx = [
            c.get(1) * pf[2] - c.get(2) * pf[1],
            c.get(2) * pf[0] - c.get(0) * pf[2],
            c.get(0) * pf[1] - c.get(1) * pf[0],
        ];
        for a in 0..3 {
            let want = l[3 + a] + cx[a];
            assert!(
                (flex.hf[p][a] - want).abs() <= 1e-9 * scale.max(1.0) * 10.0,
                "Hf[{p}][{a}] {} vs {want}",
                flex.hf[p][a]
            );
        }
    }
    for e in &flex.mass {
        let want = if e.row == e.col { 1.0 } else { 0.0 };
        assert!(
            (e.value - want).abs() <= 1e-9,
            "Mf[{}][{}] = {}",
            e.row,
            e.col,
            e.value
        );
    }
    for e in &flex.stiffness {
        if e.row == e.col {
            let w = modes.hub_fixed[e.row].omega_rad_s;
            assert!((e.value - w * w).abs() <= 1e-12 * w * w);
        }
    }
    let names: Vec<&str> = nodes.iter().map(|n| n.comment.as_str()).collect();
    assert_eq!(names, ["hub", "star_tracker", "mast_tip", "wing_tip"]);
    assert_eq!(nodes[3].position_m, [15.0, 0.0, 13.0]);
}

/// `modes --deployment-sweep K`: K + 2 states in time order from release (progress 0, no
/// hinge latched) to the fully latched array, whose frequencies are those of the frozen
/// model with every hinge rigid — the same numbers the library gives for the run's final
/// state; K = 0 and a scenario without [deployment] are refused with exit status 2.
#[test]
fn deployment_sweep_writes_k_plus_two_states() {
    use super::common::{bin, example, scratch};
    let dir = scratch("sweep");
    let out = bin()
        .args(["modes", "--deployment-sweep", "3", "--out"])
        .arg(dir.join("out"))
        .arg(example("seed.toml"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("out/deployment_modes.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 1 + 5, "{csv}");
    assert_eq!(rows[0][0], "t [s]");
    let n = 3;
    let latched = |r: &Vec<&str>| r[2 + n..2 + 2 * n].iter().all(|v| *v == "1");
    assert_eq!(rows[1][1].parse::<f64>().unwrap(), 0.0);
    assert!(!latched(&rows[1]) && latched(&rows[5]));
    let times: Vec<f64> = rows[1..].iter().map(|r| r[0].parse().unwrap()).collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
    // The final state by the library: the run's last state, every hinge rigid.
    let s = scenario(include_str!("../../examples/seed.toml"));
    let d = s.deployment.as_ref().unwrap();
    let (c, run) = flexcraft::deploy::simulate_coupled(&s.structure, d).unwrap();
    let w =
        flexcraft::deploy::sweep::linear_frequencies(&c, &run.final_q, &[false; 3], &[false; 3])
            .unwrap();
    let f1: f64 = rows[5][2 + 2 * n].parse().unwrap();
    assert!(
        (f1 - w[0] / (2.0 * std::f64::consts::PI)).abs() <= 1e-12 * f1,
        "{f1} vs {}",
        w[0]
    );
    assert!(dir.join("out/plots/deployment_modes.svg").exists());
    let out = bin()
        .args(["modes", "--deployment-sweep", "0"])
        .arg(example("seed.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "K = 0");
    let out = bin()
        .args(["modes", "--deployment-sweep", "2"])
        .arg(example("composite.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no [deployment] section"));
}

/// Base excitation of the held structure: the hub driven with acceleration a e^{iωt} needs
/// the wrench F = [M_rr + ω² M_re (K_ee − ω² M_ee)⁻¹ M_er] a (direct, from the Ritz
/// matrices), which in the exported hub-fixed modal data is the apparent mass
/// M_rr − Σ_j L_j L_jᵀ + Σ_j L_j L_jᵀ ω_j² / (ω_j² − ω²) (every mode kept): the participation
/// matrix reproduces the hub reaction to 1e-9 at frequencies below, between and above the
/// modes.
#[test]
fn fixed_hub_reaction_from_the_participation_equals_the_direct_one() {
    let (model, _, ex, _) = build(&spacecraft("fixed", ""));
    let nf = ex.hub_fixed_omega.len();
    assert_eq!(nf, model.dof() - 6, "every hub-fixed mode kept");
    let n = model.dof() - 6;
    let mee = model.mass.submatrix(6, 6, n, n).to_owned();
    let kee = model.stiffness.submatrix(6, 6, n, n).to_owned();
    let mer = model.mass.submatrix(6, 0, n, 6).to_owned();
    let mrr = model.mass.submatrix(0, 0, 6, 6).to_owned();
    let w1 = ex.hub_fixed_omega[0];
    for omega in [0.3 * w1, 1.7 * w1, 12.5 * w1] {
        let dynk = Mat::from_fn(n, n, |i, j| kee[(i, j)] - omega * omega * mee[(i, j)]);
        let x = dynk.partial_piv_lu().solve(&mer);
        let direct = Mat::from_fn(6, 6, |i, j| {
            mrr[(i, j)] + omega * omega * (0..n).map(|k| mer[(k, i)] * x[(k, j)]).sum::<f64>()
        });
        let scale = (0..6).map(|d| mrr[(d, d)]).fold(0.0, f64::max);
        for i in 0..6 {
            for j in 0..6 {
                let modal: f64 = mrr[(i, j)]
                    + (0..nf)
                        .map(|k| {
                            let w = ex.hub_fixed_omega[k];
                            let ll = ex.participation[(i, k)] * ex.participation[(j, k)];
                            ll * (w * w / (w * w - omega * omega) - 1.0)
                        })
                        .sum::<f64>();
                assert!(
                    (modal - direct[(i, j)]).abs() <= 1e-9 * scale,
                    "ω = {omega}: F[{i}][{j}] modal {modal} vs direct {}",
                    direct[(i, j)]
                );
            }
        }
    }
}
