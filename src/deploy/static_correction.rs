//! The static correction of the base's hub-fixed modes left out of a deployment run
//! (docs/theory.md §2.9): the residual flexibility of the modes above the cutoff under the
//! loads the deployment puts on the base, carried as a few extra Ritz vectors beside the kept
//! modes — MacNeal's residual flexibility (R. H. MacNeal, "A hybrid method of component mode
//! synthesis", Computers & Structures 1 (1971) 581–601) in the form of Dickens, Nakagawa and
//! Wittbrodt's modal truncation augmentation (J. M. Dickens, J. M. Nakagawa, M. J. Wittbrodt,
//! "A critique of mode acceleration and modal truncation augmentation methods for modal
//! response analysis", Computers & Structures 62 (1997) 985–998).
//!
//! Why: the deployment loads the base at one point (the root hinge) and, with a free hub,
//! through the hub's rigid-body acceleration. A mode far above the deployment's own time
//! scales answers those loads quasi-statically, so only its static flexibility matters; but
//! that flexibility does not vanish with the mode's frequency as fast as its dynamics do (at a
//! beam's tip the rotation per mass-normalised mode grows with the mode number and the
//! rotational compliance of the modes above the N-th falls only like 1/N). Truncating the
//! modes alone leaves the base too stiff at the hinge, and a compliant latch's loads converge
//! slowly with the count (5 % off with the twelve lowest of 54 modes on a boom-mounted wing);
//! with the correction the two lowest modes already give them to 0.1 %.

use crate::math::Vec3;
use crate::ritz::assembly::HUB_DOF;
use crate::ritz::shapes::beam_point;
use crate::ritz::RitzModel;
use crate::structure::{Attachment, HubMotion};

/// The loads the deployment puts on the base's elastic coordinates (columns over them): a
/// unit force along each hub axis and a unit moment about each at the root hinge (the chain's
/// wrench), and the inertial loads −M_er of a unit rigid-body acceleration of the hub frame
/// along and about each axis (a free hub accelerates under that wrench; a held hub's frame
/// does not, and its columns are left out).
pub(crate) fn deployment_loads(ritz: &RitzModel, hinge: &Attachment) -> Vec<Vec<f64>> {
    let n = ritz.dof();
    let ne = n - HUB_DOF;
    let mut loads = Vec::new();
    if let Attachment::Beam { beam, station } = hinge {
        let st = &ritz.structure;
        let xi = (station / st.beams[*beam].length).clamp(0.0, 1.0);
        // The hinge's displacement and rotation per elastic coordinate (linear in q).
        let motion: Vec<(Vec3, Vec3)> = (0..ne)
            .map(|i| {
                let mut q = vec![0.0; n];
                q[HUB_DOF + i] = 1.0;
                let s = beam_point(ritz, *beam, xi, &q).unwrap_or_default();
                (s.displacement, s.rotation)
            })
            .collect();
        for axis in 0..3 {
            loads.push(motion.iter().map(|(u, _)| u.0[axis]).collect());
            loads.push(motion.iter().map(|(_, r)| r.0[axis]).collect());
        }
    }
    if ritz.structure.hub.motion == HubMotion::Free {
        for k in 0..HUB_DOF {
            loads.push((0..ne).map(|i| ritz.mass[(HUB_DOF + i, k)]).collect());
        }
    }
    loads
}

/// The static correction of the hub-fixed modes left out (j ≥ `keep`) under `loads`: their
/// residual flexibility R = Σ_{j ≥ keep} φ_j φ_jᵀ / ω_j² applied to each load,
/// X = R F (MacNeal's residual flexibility; Dickens, Nakagawa & Wittbrodt's modal truncation
/// augmentation), then made M-orthonormal and K-diagonal within span X: the Ritz vectors
/// ψ_r with Kψ_r·ψ_s = ω_r² δ_rs, ascending. Each x = R f is M- and K-orthogonal to every kept
/// mode (φ_kᵀ M R = 0 since φ_kᵀ M φ_j = δ_kj), so the vectors simply join the kept modes: the
/// base's deflection under any combination of the loads, applied slowly, is then exact, the
/// modes left out answering quasi-statically, while their highest frequencies never enter
/// the model (the vectors' own ω_r lie above the cutoff, near the lowest mode left out of
/// each family the loads excite).
///
/// Returns (ω_r, ψ_r over the elastic coordinates). Directions below 1e-9 of a load's own
/// M-norm (a load the kept modes already carry, or a zero one) are dropped.
pub(crate) fn vectors(
    lam: &[f64],
    phi: &faer::Mat<f64>,
    keep: usize,
    loads: &[Vec<f64>],
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let ne = lam.len();
    // In the modal coordinates of the modes left out the M-inner product is the plain one and
    // K is diag(λ), and x = R f has coordinates c_j = φ_jᵀ f / λ_j there: work in them
    // (exact orthogonality to the kept modes by construction), each x scaled to unit M-norm
    // when it is not negligible against the whole static response K⁻¹ f = Φ Λ⁻¹ Φᵀ f.
    let mut xs: Vec<Vec<f64>> = Vec::new();
    for f in loads {
        let c: Vec<f64> = (0..ne)
            .map(|j| (0..ne).map(|i| phi[(i, j)] * f[i]).sum::<f64>() / lam[j])
            .collect();
        let whole = c.iter().map(|x| x * x).sum::<f64>().sqrt();
        let part = c[keep..].iter().map(|x| x * x).sum::<f64>().sqrt();
        if whole.is_finite() && part > 1e-9 * whole {
            xs.push(c[keep..].iter().map(|x| x / part).collect());
        }
    }
    if xs.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let r = xs.len();
    let gram = faer::Mat::<f64>::from_fn(r, r, |a, b| {
        xs[a].iter().zip(&xs[b]).map(|(x, y)| x * y).sum()
    });
    let stiff = faer::Mat::<f64>::from_fn(r, r, |a, b| {
        xs[a]
            .iter()
            .zip(&xs[b])
            .zip(&lam[keep..])
            .map(|((x, y), l)| x * y * l)
            .sum()
    });
    // An orthonormal basis of span X (the Gram matrix's eigenvectors above 1e-9 of the
    // largest: loads whose residual responses coincide give one vector), then the reduced
    // stiffness diagonalised in it.
    let Ok(eg) = gram.self_adjoint_eigen(faer::Side::Lower) else {
        return (Vec::new(), Vec::new());
    };
    let (gs, gv) = (eg.S(), eg.U());
    let gmax = (0..r).map(|i| gs[i]).fold(0.0, f64::max);
    let cols: Vec<usize> = (0..r).filter(|&i| gs[i] > 1e-9 * gmax).collect();
    let k = cols.len();
    let basis = faer::Mat::<f64>::from_fn(r, k, |a, c| gv[(a, cols[c])] / gs[cols[c]].sqrt());
    let kr = basis.transpose() * &stiff * &basis;
    let Ok(ek) = kr.self_adjoint_eigen(faer::Side::Lower) else {
        return (Vec::new(), Vec::new());
    };
    let (ks, kv) = (ek.S(), ek.U());
    let coef = &basis * kv; // r × k: ψ_c = Σ_a x_a coef[a, c] (modal coordinates)
    let mut out: Vec<(f64, Vec<f64>)> = (0..k)
        .map(|c| {
            // Back from the omitted modes' coordinates to the elastic coordinates.
            let modal: Vec<f64> = (0..ne - keep)
                .map(|j| (0..r).map(|a| xs[a][j] * coef[(a, c)]).sum())
                .collect();
            let psi = (0..ne)
                .map(|i| (keep..ne).map(|j| phi[(i, j)] * modal[j - keep]).sum())
                .collect();
            (ks[c].max(0.0).sqrt(), psi)
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out.into_iter().unzip()
}

#[cfg(test)]
mod tests {
    use crate::deploy::base::{BaseKind, BaseModel};
    use crate::ritz::assembly::HUB_DOF;
    use crate::scenario::Scenario;

    /// A steel tube cantilevered from a held hub along x, a wing on its tip: the base is the
    /// tube alone.
    fn cantilever(motion: &str) -> Scenario {
        let toml = format!(
            r#"
name = "cantilever"
format_version = 1
[hub]
motion = "{motion}"
mass = 200.0
inertia = [50.0, 60.0, 70.0]
center_of_mass = [0.0, 0.0, 0.0]
[materials.steel]
youngs_modulus = 210e9
poisson_ratio = 0.3
density = 7850.0
[[beams]]
name = "boom"
parent = "hub"
root = [0.5, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 3.0
material = "steel"
section = {{ tube = {{ outer_diameter = 0.08, wall = 0.003 }} }}
terms = {{ bending = 10, torsion = 4, axial = 6 }}
[[plates]]
name = "wing"
parent = "boom"
station = 3.0
length_axis = [0.0, 1.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 4.0
width = 1.0
areal_density = 2.0
bending_stiffness = 1e3
poisson_ratio = 0.3
terms = {{ length = 4, width = 3 }}
"#
        );
        Scenario::from_toml_str(&toml, "cantilever.toml").unwrap()
    }

    /// The tip deflection under a unit tip force across the tube, through the reduced basis
    /// (kept modes and correction vectors, each answering statically: η_j = φ_j·f / ω_j²),
    /// equals the cantilever's closed form L³/(3EI) with no mode kept or with two: the
    /// correction carries exactly the flexibility of the modes it stands for (the Legendre
    /// basis represents the cubic exactly). Without it, two modes give about 97 % of it.
    #[test]
    fn the_tip_force_deflection_is_the_closed_form_whatever_the_modes_kept() {
        let sc = cantilever("fixed");
        let st = &sc.structure;
        let (e, d, t, l) = (210e9_f64, 0.08_f64, 0.003_f64, 3.0_f64);
        let di = d - 2.0 * t;
        let i = std::f64::consts::PI / 64.0 * (d.powi(4) - di.powi(4));
        let exact = l.powi(3) / (3.0 * e * i);
        let static_tip = |b: &BaseModel| -> f64 {
            // Unit force along z at the hinge (the tube's tip): f·φ_j = u_z(φ_j).
            (0..b.modes())
                .map(|j| b.hinge_shapes[j].0[2].powi(2) / b.omega[j].powi(2))
                .sum()
        };
        for keep in [0, 2, 5] {
            let b = BaseModel::new(st, 0, BaseKind::Corrected { modes: keep }).unwrap();
            let got = static_tip(&b);
            assert!(
                (got - exact).abs() < 1e-9 * exact,
                "{keep} modes + {} vectors: {got:e} vs {exact:e}",
                b.correction
            );
        }
        let b = BaseModel::new(st, 0, BaseKind::Flexible { modes: Some(2) }).unwrap();
        let truncated = static_tip(&b);
        assert!(
            truncated < 0.999 * exact && truncated > 0.9 * exact,
            "{truncated:e}"
        );
    }

    /// The correction's vectors with the kept modes are M-orthonormal and K-diagonal over the
    /// base's Ritz coordinates (checked with the assembled M and K, not the modal algebra the
    /// construction uses), their ω above the kept modes', and with every mode kept there is
    /// no correction. On a free hub the twelve loads (hinge wrench and the hub's rigid-body
    /// accelerations) are all represented.
    #[test]
    fn the_vectors_are_orthonormal_and_above_the_kept_modes() {
        for motion in ["fixed", "free"] {
            let sc = cantilever(motion);
            let st = &sc.structure;
            let b = BaseModel::new(st, 0, BaseKind::Corrected { modes: 3 }).unwrap();
            // Six hinge-wrench loads on a fixed hub; six more from the free hub's rigid-body
            // accelerations. The beam has enough terms for all of them to be independent.
            let expected = if motion == "fixed" { 6 } else { 12 };
            assert_eq!(b.correction, expected, "{motion}");
            let (m, k) = (&b.ritz.mass, &b.ritz.stiffness);
            let n = b.ritz.dof();
            let form = |a: &faer::Mat<f64>, x: &[f64], y: &[f64]| -> f64 {
                (HUB_DOF..n)
                    .map(|i| (HUB_DOF..n).map(|j| x[i] * a[(i, j)] * y[j]).sum::<f64>())
                    .sum()
            };
            for p in 0..b.modes() {
                for q in 0..b.modes() {
                    let mass = form(m, &b.shapes[p], &b.shapes[q]);
                    let stiff = form(k, &b.shapes[p], &b.shapes[q]);
                    let (want_m, want_k) = if p == q {
                        (1.0, b.omega[p].powi(2))
                    } else {
                        (0.0, 0.0)
                    };
                    let scale = b.omega[p] * b.omega[q];
                    assert!((mass - want_m).abs() < 1e-8, "{motion} M[{p},{q}] = {mass}");
                    assert!(
                        (stiff - want_k).abs() < 1e-8 * scale,
                        "{motion} K[{p},{q}] = {stiff}"
                    );
                }
            }
            let kept_top = b.omega[2];
            assert!(b.omega[3..].iter().all(|w| *w > kept_top), "{:?}", b.omega);
            let all = b.spectrum.len();
            let whole = BaseModel::new(st, 0, BaseKind::Corrected { modes: all }).unwrap();
            assert_eq!(whole.correction, 0);
        }
    }
}
