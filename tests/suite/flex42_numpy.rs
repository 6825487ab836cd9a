//! NASA 42's flexible-body and node files (`flexcraft export`) read by an independent reader:
//! `scripts/check_flex42_numpy.py`, written from 42's own C source (42init.c `InitFlexModes`
//! and `InitNodes`, upstream commit 11e3cc39), replays 42's `fscanf` sequence with NumPy —
//! which lines it skips, which fields it reads, in what order and shape — and refuses any file
//! 42 would read differently from its layout (a failed conversion, a value line without its
//! comment, whose next line 42 would swallow, a call spanning lines, an overflowing buffer,
//! an index 42 exits on). On the parsed arrays alone it checks the identities of any flex
//! body: Mf = I; Kf diagonal, non-negative; Cf symmetric positive semi-definite; N the Gram
//! matrix of the mode-shape components (symmetric, positive semi-definite, Σ_a N_aapq =
//! Mf_pq); Hf the antisymmetric part of L; and, against the rigid mass of the spacecraft
//! computed here in closed form from the scenario's own numbers (not by flexcraft), the
//! effective-mass bounds Σ Pf Pfᵀ ≤ m I, Σ Hf Hfᵀ ≤ J_O, [Pf; Hf][Pf; Hf]ᵀ ≤ M_O and the
//! positive semi-definite Gram matrix of {1, r, Ψ}.
//!
//! This test then holds the NumPy-parsed values against a second formulation, the library's
//! own modal solve of the same scenario (the Ritz eigenproblem, which shares no code with the
//! writer's mass-element integrals): Kf = ω² and Cf = 2ζω of the hub-fixed modes, Pf = the
//! translational participation φᵀM_{e,d} and Hf = the rotational one shifted to the reference
//! point, to 1e-9 of the largest; the nodes where the scenario puts them; the hub's nodes
//! motionless in every hub-fixed mode; the other nodes' shapes equal to the library's point
//! kinematics applied to its hub-fixed shapes (this last one shares the point kinematics
//! with the writer: it checks the file's mode, node and axis order).
//!
//! Ignored by default (it needs Python with numpy): `scripts/check_array_files.sh` runs it
//! with `FLEXCRAFT_PYTHON` set; under `--ignored` an unset `FLEXCRAFT_PYTHON` is a failure.

use super::common::{bin, example, scenario, scratch};
use flexcraft::export::points::HUB_REFERENCE;
use flexcraft::export::{point_jacobian, ExportModel, PointLocation};
use flexcraft::{ModalAnalysis, RitzModel};

const EXAMPLE: &str = include_str!("../../examples/export.toml");

fn num(v: &toml::Value) -> f64 {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .unwrap_or_else(|| panic!("not a number: {v}"))
}

fn vec3(v: &toml::Value) -> [f64; 3] {
    let a = v.as_array().expect("an array of three numbers");
    assert_eq!(a.len(), 3);
    [num(&a[0]), num(&a[1]), num(&a[2])]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn axpy(s: f64, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2]]
}

/// Mass, first moment and second moment ∫ r rᵀ dm about the reference point, accumulated.
#[derive(Default)]
struct Moments {
    m: f64,
    s: [f64; 3],
    e: [[f64; 3]; 3],
}

impl Moments {
    /// A mass m whose own centroid is p and whose second moment about p is e0.
    fn add(&mut self, m: f64, p: [f64; 3], e0: [[f64; 3]; 3]) {
        self.m += m;
        for i in 0..3 {
            self.s[i] += m * p[i];
            for j in 0..3 {
                self.e[i][j] += e0[i][j] + m * p[i] * p[j];
            }
        }
    }

    /// The matrix c a bᵀ.
    fn outer(c: f64, a: [f64; 3], b: [f64; 3]) -> [[f64; 3]; 3] {
        let mut o = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                o[i][j] = c * a[i] * b[j];
            }
        }
        o
    }

    /// Inertia about the reference point, J_O = tr(E) I − E.
    fn inertia(&self) -> [[f64; 3]; 3] {
        let tr = self.e[0][0] + self.e[1][1] + self.e[2][2];
        let mut j = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                j[a][b] = if a == b { tr } else { 0.0 } - self.e[a][b];
            }
        }
        j
    }
}

/// The rigid mass of `examples/export.toml` in closed form, from the scenario's numbers read
/// as plain TOML (not through flexcraft): the hub (mass, inertia about its centre of mass),
/// the tube mast (a uniform thin-walled tube: line mass ρ π (R² − r²), section second moment
/// (R² + r²)/4 per unit mass in each transverse direction) and the plate wing (a uniform
/// rectangle, its root edge centred on the mast's tip as docs/scenario.md says).
fn closed_form_mass() -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let doc: toml::Value = toml::from_str(EXAMPLE).unwrap();
    let mut mo = Moments::default();
    let hub = &doc["hub"];
    let hm = num(&hub["mass"]);
    let hc = vec3(&hub["center_of_mass"]);
    let hi = vec3(&hub["inertia"]); // principal values along the structure axes
                                    // second moment about the centroid from the inertia: E = tr(J)/2 I − J
    let htr = 0.5 * (hi[0] + hi[1] + hi[2]);
    let mut he = [[0.0; 3]; 3];
    for a in 0..3 {
        he[a][a] = htr - hi[a];
    }
    mo.add(hm, hc, he);

    let beams = doc["beams"].as_array().unwrap();
    assert_eq!(beams.len(), 1);
    let beam = &beams[0];
    let mat = beam["material"].as_str().unwrap();
    let rho = num(&doc["materials"][mat]["density"]);
    let tube = &beam["section"]["tube"];
    let ro = 0.5 * num(&tube["outer_diameter"]);
    let ri = ro - num(&tube["wall"]);
    let len = num(&beam["length"]);
    let root = vec3(&beam["root"]);
    let axis = unit(vec3(&beam["axis"]));
    let mb = rho * std::f64::consts::PI * (ro * ro - ri * ri) * len;
    // about the mast's centroid: m L²/12 along the axis, m (R² + r²)/4 across it
    let mut be = Moments::outer(mb * len * len / 12.0, axis, axis);
    let ring = mb * (ro * ro + ri * ri) / 4.0;
    for a in 0..3 {
        for b in 0..3 {
            be[a][b] += ring * (if a == b { 1.0 } else { 0.0 } - axis[a] * axis[b]);
        }
    }
    mo.add(mb, axpy(0.5 * len, axis, root), be);

    let plates = doc["plates"].as_array().unwrap();
    assert_eq!(plates.len(), 1);
    let plate = &plates[0];
    assert_eq!(plate["parent"].as_str(), Some("mast"));
    let proot = axpy(num(&plate["station"]), axis, root);
    let ex = unit(vec3(&plate["length_axis"]));
    let ey = unit(cross(vec3(&plate["normal"]), ex));
    let (a, b) = (num(&plate["length"]), num(&plate["width"]));
    let mp = num(&plate["areal_density"]) * a * b;
    let mut pe = Moments::outer(mp * a * a / 12.0, ex, ex);
    let w = Moments::outer(mp * b * b / 12.0, ey, ey);
    for i in 0..3 {
        for j in 0..3 {
            pe[i][j] += w[i][j];
        }
    }
    mo.add(mp, axpy(0.5 * a, ex, proot), pe);
    assert!(
        doc.get("masses").is_none(),
        "the closed form covers hub, mast and wing only"
    );
    let c = [mo.s[0] / mo.m, mo.s[1] / mo.m, mo.s[2] / mo.m];
    (mo.m, c, mo.inertia())
}

/// The largest deviation of one quantity from its truth, relative to a scale.
struct Worst {
    what: &'static str,
    scale: f64,
    tol: f64,
    err: f64,
    at: String,
}

impl Worst {
    fn new(what: &'static str, scale: f64, tol: f64) -> Self {
        assert!(scale > 0.0 && scale.is_finite(), "{what}: scale {scale}");
        Self {
            what,
            scale,
            tol,
            err: 0.0,
            at: String::new(),
        }
    }

    fn see(&mut self, got: f64, want: f64, at: impl FnOnce() -> String) {
        let e = (got - want).abs() / self.scale;
        // a NaN is a failure: it replaces any finite error and stays
        if e.is_nan() || e > self.err {
            self.err = e;
            self.at = format!("{}: {got} vs {want}", at());
        }
    }

    fn check(&self) {
        println!(
            "  {}: max |file - truth| = {:.2e} of {:.4e} (tolerance {:e}){}",
            self.what,
            self.err,
            self.scale,
            self.tol,
            if self.at.is_empty() {
                String::new()
            } else {
                format!(", at {}", self.at)
            }
        );
        assert!(
            self.err <= self.tol,
            "{}: {:.3e} of the largest > {:e}, at {}",
            self.what,
            self.err,
            self.tol,
            self.at
        );
    }
}

/// Numbers as a comma-separated list (full precision).
fn join<'a>(v: impl Iterator<Item = &'a f64>) -> String {
    v.map(|x| format!("{x:e}")).collect::<Vec<_>>().join(",")
}

fn arr(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap_or_else(|| panic!("not a number: {x}")))
        .collect()
}

fn mat(v: &serde_json::Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(arr).collect()
}

/// The flex and node files of `examples/export.toml` parsed in NumPy in 42's reading order
/// and checked for the identities of a flex body, then compared with the library's hub-fixed
/// modal solve of the same scenario (module docs).
#[test]
#[ignore = "needs Python with numpy: scripts/check_array_files.sh"]
fn numpy_reads_the_42_files_as_42_does_and_they_match_the_modal_solve() {
    // Run under --ignored, a missing Python is a failure, not a pass.
    let python = std::env::var_os("FLEXCRAFT_PYTHON")
        .expect("FLEXCRAFT_PYTHON not set: run scripts/check_array_files.sh");
    let dir = scratch("flex42-numpy");
    let out = dir.join("out");
    let o = bin()
        .arg("export")
        .arg(example("export.toml"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let (mass, cm, jo) = closed_form_mass();
    let json_path = dir.join("flex42.json");
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_flex42_numpy.py");
    let mut cmd = std::process::Command::new(&python);
    cmd.arg(&script)
        .arg(out.join("flex_export.txt"))
        .arg(out.join("nodes_export.txt"))
        .arg("--json")
        .arg(&json_path)
        .arg(format!("--mass={mass:e}"))
        .arg(format!("--cm={}", join(cm.iter())))
        .arg(format!("--inertia-ref={}", join(jo.iter().flatten())));
    let run = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run FLEXCRAFT_PYTHON={python:?}: {e}"));
    print!("{}", String::from_utf8_lossy(&run.stdout));
    assert!(
        run.status.success(),
        "the independent reader refused the 42 files:\n{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    let parsed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();

    // The library's modal solve of the same scenario (the second formulation).
    let s = scenario(EXAMPLE);
    let model = RitzModel::assemble(&s.structure);
    let modes = ModalAnalysis::compute_lowest(&model, s.export_modes()).expect("modes");
    let ex = ExportModel::build(&model, &modes, &s.export).expect("export");
    let doc: toml::Value = toml::from_str(EXAMPLE).unwrap();
    let kept = doc["export"]["modes"].as_integer().unwrap() as usize;
    let zeta = num(&doc["export"]["damping_ratio"]);

    let nf = parsed["nf"].as_u64().unwrap() as usize;
    assert_eq!(nf, kept, "one flex mode per kept elastic mode");
    assert!(modes.hub_fixed.len() >= nf);
    let kf = mat(&parsed["kf"]);
    let cf = mat(&parsed["cf"]);
    let mf = mat(&parsed["mf"]);
    let pf = mat(&parsed["pf"]); // [axis][mode]
    let hf = mat(&parsed["hf"]); // [axis][mode]

    // Kf = ω², Cf = 2ζω, Mf = I
    let w2max = (0..nf)
        .map(|p| modes.hub_fixed[p].omega_rad_s.powi(2))
        .fold(0.0, f64::max);
    let mut wk = Worst::new("Kf vs ω² of the modal solve", w2max, 1e-9);
    let mut wc = Worst::new("Cf vs 2ζω", 2.0 * zeta * w2max.sqrt(), 1e-9);
    let mut wm = Worst::new("Mf vs I", 1.0, 1e-9);
    for p in 0..nf {
        let w = modes.hub_fixed[p].omega_rad_s;
        for q in 0..nf {
            let d = if p == q { 1.0 } else { 0.0 };
            wk.see(kf[p][q], d * w * w, || format!("Kf[{p}][{q}]"));
            wc.see(cf[p][q], d * 2.0 * zeta * w, || format!("Cf[{p}][{q}]"));
            wm.see(mf[p][q], d, || format!("Mf[{p}][{q}]"));
        }
    }

    // Pf = translational participation; Hf = rotational participation (about the hub's
    // centre of mass c) + c × Pf (about the reference point)
    let hc = vec3(&doc["hub"]["center_of_mass"]);
    let pscale = (0..nf)
        .flat_map(|p| (0..3).map(move |a| (p, a)))
        .map(|(p, a)| modes.hub_fixed[p].participation[a].abs())
        .fold(0.0, f64::max);
    let mut hwant = vec![[0.0; 3]; nf];
    for p in 0..nf {
        let l = &modes.hub_fixed[p].participation;
        let cx = cross(hc, [l[0], l[1], l[2]]);
        for a in 0..3 {
            hwant[p][a] = l[3 + a] + cx[a];
        }
    }
    let hscale = hwant.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut wp = Worst::new("Pf vs participation φᵀM_e,d", pscale, 1e-9);
    let mut wh = Worst::new("Hf vs rotational participation + c × Pf", hscale, 1e-9);
    for p in 0..nf {
        let l = &modes.hub_fixed[p].participation;
        for a in 0..3 {
            wp.see(pf[a][p], l[a], || format!("Pf[{a}][{p}]"));
            wh.see(hf[a][p], hwant[p][a], || format!("Hf[{a}][{p}]"));
        }
    }
    println!("the NumPy-parsed 42 file against the library's modal solve:");
    for w in [&wk, &wc, &wm, &wp, &wh] {
        w.check();
    }

    // The nodes: the hub's reference point, then the named points where the scenario puts them
    let names: Vec<&str> = parsed["node_comment"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(names, ["hub", "star_tracker", "mast_tip", "wing_tip"]);
    let beam = &doc["beams"][0];
    let plate = &doc["plates"][0];
    let mast_tip = axpy(
        num(&doc["export"]["points"][1]["station"]),
        unit(vec3(&beam["axis"])),
        vec3(&beam["root"]),
    );
    let proot = axpy(
        num(&plate["station"]),
        unit(vec3(&beam["axis"])),
        vec3(&beam["root"]),
    );
    let pt = &doc["export"]["points"][2];
    let ex_axis = unit(vec3(&plate["length_axis"]));
    let ey_axis = unit(cross(vec3(&plate["normal"]), ex_axis));
    let wing_tip = axpy(
        (num(&pt["eta"]) - 0.5) * num(&plate["width"]),
        ey_axis,
        axpy(num(&pt["xi"]) * num(&plate["length"]), ex_axis, proot),
    );
    let want_pos = [
        [0.0; 3],
        vec3(&doc["export"]["points"][0]["position"]),
        mast_tip,
        wing_tip,
    ];
    let pos = mat(&parsed["node_position"]);
    for (n, w) in want_pos.iter().enumerate() {
        for a in 0..3 {
            assert!(
                (pos[n][a] - w[a]).abs() <= 1e-12 * (1.0 + w[a].abs()),
                "node {n} ({}) at {:?}, the scenario puts it at {w:?}",
                names[n],
                pos[n]
            );
        }
    }

    // Node shapes [node][axis][mode]: the hub's nodes do not move in a hub-fixed mode; the
    // others equal the library's point kinematics on its hub-fixed shapes.
    let psi: Vec<Vec<Vec<f64>>> = parsed["psi"].as_array().unwrap().iter().map(mat).collect();
    let theta: Vec<Vec<Vec<f64>>> = parsed["theta"]
        .as_array()
        .unwrap()
        .iter()
        .map(mat)
        .collect();
    let sites: Vec<PointLocation> = std::iter::once(HUB_REFERENCE)
        .chain(ex.points.iter().map(|p| p.location))
        .collect();
    assert_eq!(sites.len(), 4);
    let mut shape_scale = 0.0f64;
    let mut expected = Vec::new();
    for loc in &sites {
        let jac = point_jacobian(&model, loc); // per coordinate: [ux uy uz rx ry rz]
        let mut e = vec![[0.0; 6]; nf];
        for (p, ep) in e.iter_mut().enumerate() {
            let phi = &modes.hub_fixed[p].shape;
            assert_eq!(phi.len(), jac.len());
            for (c, row) in jac.iter().enumerate() {
                for k in 0..6 {
                    ep[k] += row[k] * phi[c];
                }
            }
            for k in 0..6 {
                shape_scale = shape_scale.max(ep[k].abs());
            }
        }
        expected.push(e);
    }
    // The hub's nodes: exactly still (the reference point and the star tracker are on the hub).
    // The others: 1e-8 of the largest, the agreement of two eigen-solves of the same pencil
    // (the command line's starts from the term selection's eigenvectors, this one afresh).
    let mut ws = Worst::new("node PSI, THETA vs the library's points", shape_scale, 1e-8);
    for (n, e) in expected.iter().enumerate() {
        for p in 0..nf {
            for a in 0..3 {
                if n < 2 {
                    assert_eq!(psi[n][a][p], 0.0, "PSI of hub node {n} ({})", names[n]);
                    assert_eq!(theta[n][a][p], 0.0, "THETA of hub node {n} ({})", names[n]);
                }
                ws.see(psi[n][a][p], e[p][a], || format!("PSI[{n}][{a}][{p}]"));
                ws.see(theta[n][a][p], e[p][3 + a], || {
                    format!("THETA[{n}][{a}][{p}]")
                });
            }
        }
    }
    ws.check();
    // No joint-node shapes (one body, no joints) and zero initial modal states.
    assert_eq!(parsed["joint_psi"].as_array().unwrap().len(), 0);
    assert_eq!(parsed["joint_theta"].as_array().unwrap().len(), 0);
    assert!(arr(&parsed["x"])
        .iter()
        .chain(&arr(&parsed["u"]))
        .all(|v| *v == 0.0));
}
