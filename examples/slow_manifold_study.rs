//! A measurement, not a feature: how fast is the coupled seed deployment once its state is
//! put on the slow manifold? (docs/bench-coupled.md, "The slow manifold, measured".)
//!
//! The seed (`examples/seed.toml`, `base_modes` replaced, ideal cable, free hub) is released
//! with its base at rest: the preloaded hinge springs load the mast tip as a step, and every
//! base mode rings from t = 0. Here that ringing is taken out of the initial state first:
//!
//! * J = ∂f/∂y at the release state by central differences; its eigenvalues with
//!   |Im λ| > 20 rad/s are the base's vibration (the fast subspace), with right and left
//!   eigenvectors v_j, w_j (w_jᵀ v_j = 1);
//! * the slow-manifold state y_s solves w_jᵀ f(y_s) = 0 for every fast j (the fast modal
//!   coordinates at rest, their acceleration zero: exact at release, where the slow motion
//!   starts from rest), by the Newton iteration y ← y − Re Σ_j v_j λ_j⁻¹ w_jᵀ f(y) with J
//!   frozen. What is taken out, y₀ − y_s, is the ringing's initial state; it is not
//!   propagated here, so the run below is the slow motion alone.
//!
//! Then Rodas5P (the library's implicit stepper) integrates from y_s to the latch
//! (α₁ reaching its latch angle; with the ideal cable every hinge latches then), with either
//! Jacobian: `fd` (forward differences of f, all n columns, every step) or `stiff` (the
//! model's analytic stiff part, `Coupled::stiff_jacobian`, which the library's runs use).
//!
//! Run: `cargo run --release --example slow_manifold_study -- 20 1e-8 project fd`
//! (base modes, tolerance, `project` | `release`, `fd` | `stiff`).

use faer::{c64, Mat};
use flexcraft::deploy::coupled::Coupled;
use flexcraft::deploy::{Deployment, OdeSystem, Rodas5P};
use flexcraft::Scenario;
use std::time::Instant;

/// The coupled model with every hinge free (ideal cable), as an ODE for Rodas5P.
struct Sys<'a> {
    c: &'a Coupled,
    free: Vec<bool>,
    captured: Vec<bool>,
    stiff_jacobian: bool,
}

impl OdeSystem for Sys<'_> {
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        self.c.rhs(y, &self.free, dy);
    }
    fn jacobian(&self, _t: f64, y: &[f64], jac: &mut Mat<f64>) -> bool {
        if self.stiff_jacobian {
            self.c.stiff_jacobian(y, &self.free, &self.captured, jac);
        }
        self.stiff_jacobian
    }
}

/// ∂f/∂y by central differences.
fn jacobian(s: &Sys, y: &[f64]) -> Mat<f64> {
    let n = y.len();
    let mut j = Mat::<f64>::zeros(n, n);
    let (mut fp, mut fm, mut yp) = (vec![0.0; n], vec![0.0; n], y.to_vec());
    for k in 0..n {
        let d = 1e-6 * y[k].abs().max(1e-3);
        yp[k] = y[k] + d;
        s.rhs(0.0, &yp, &mut fp);
        yp[k] = y[k] - d;
        s.rhs(0.0, &yp, &mut fm);
        yp[k] = y[k];
        for i in 0..n {
            j[(i, k)] = (fp[i] - fm[i]) / (2.0 * d);
        }
    }
    j
}

/// y moved onto the slow manifold along the fast eigen-directions of J(y) (module docs).
fn project(s: &Sys, y: &[f64], fast_above: f64) -> Result<Vec<f64>, Box<dyn std::error::Error>> {
    let n = y.len();
    let j = jacobian(s, y);
    let right = j.eigen().map_err(|e| format!("{e:?}"))?;
    let left = j
        .transpose()
        .to_owned()
        .eigen()
        .map_err(|e| format!("{e:?}"))?;
    let (lam, laml) = (right.S().column_vector(), left.S().column_vector());
    // (v_j, w_j, λ_j) with w_jᵀ v_j = 1, for every fast eigenvalue.
    let mut fast: Vec<(Vec<c64>, Vec<c64>, c64)> = Vec::new();
    for a in 0..n {
        let l = lam[a];
        if l.im.abs() <= fast_above {
            continue;
        }
        let b = (0..n)
            .min_by(|&p, &q| (laml[p] - l).norm().total_cmp(&(laml[q] - l).norm()))
            .ok_or("no left eigenvector")?;
        let v: Vec<c64> = (0..n).map(|i| right.U()[(i, a)]).collect();
        let w: Vec<c64> = (0..n).map(|i| left.U()[(i, b)]).collect();
        let wv: c64 = w.iter().zip(&v).map(|(a, b)| a * b).sum();
        fast.push((v, w.iter().map(|x| x / wv).collect(), l));
    }
    println!("fast eigenvalues: {}", fast.len());
    let (mut ys, mut f) = (y.to_vec(), vec![0.0; n]);
    for it in 0..4 {
        s.rhs(0.0, &ys, &mut f);
        let mut largest = 0.0f64;
        for (v, w, l) in &fast {
            let wf: c64 = w.iter().zip(&f).map(|(a, b)| a * b).sum();
            largest = largest.max(wf.norm());
            let c = wf / l;
            for i in 0..n {
                ys[i] -= (v[i] * c).re;
            }
        }
        println!("Newton {it}: largest |w_jᵀ f| before the update {largest:.3e}");
    }
    Ok(ys)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: slow_manifold_study MODES TOL project|release fd|stiff";
    let modes: usize = args.first().ok_or(usage)?.parse()?;
    let tol: f64 = args.get(1).ok_or(usage)?.parse()?;
    let projected = args.get(2).ok_or(usage)? == "project";
    let stiff_jacobian = args.get(3).ok_or(usage)? == "stiff";
    let text = std::fs::read_to_string("examples/seed.toml")?
        .replace("base_modes = 6", &format!("base_modes = {modes}"));
    let sc = Scenario::from_toml_str(&text, "seed.toml")?;
    let d: Deployment = sc.deployment.clone().ok_or("no deployment")?;
    let c = d.coupled(&sc.structure)?;
    let s = Sys {
        c: &c,
        free: vec![true; c.panels()],
        captured: vec![false; c.panels()],
        stiff_jacobian,
    };
    let clock = Instant::now();
    let y0 = c.initial_state();
    let mut y = if projected {
        project(&s, &y0, 20.0)?
    } else {
        y0.clone()
    };
    let (a0, r0) = (c.alpha_offset(), c.positions() + c.rate_offset());
    let latch = c.chain.hinges[0].latch_angle;
    println!(
        "opening angles moved by the projection [rad]: {:?}",
        (0..c.panels())
            .map(|k| y[a0 + k] - y0[a0 + k])
            .collect::<Vec<_>>()
    );
    // The library's tolerances for a run at `tol` (rtol = tol, atol = tol/100).
    let mut stepper = Rodas5P::new(tol, tol * 1e-2, f64::INFINITY);
    let (mut t, mut steps) = (0.0, 0usize);
    while steps < 1_000_000 {
        let dense = stepper.step(&s, &mut t, &mut y, 1e3);
        steps += 1;
        if y[a0] < latch {
            continue;
        }
        // The crossing by bisection on the step's continuous extension.
        let (mut lo, mut hi) = (dense.t0, dense.t1());
        while hi - lo > 1e-13 {
            let mid = 0.5 * (lo + hi);
            if dense.component(a0, mid) < latch {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let mut yl = vec![0.0; y.len()];
        dense.eval(hi, &mut yl);
        println!(
            "latch at {hi:.11} s, rates {:?} rad/s, {steps} steps, {} evaluations, CPU {:.3} s",
            (0..c.panels()).map(|k| yl[r0 + k]).collect::<Vec<_>>(),
            stepper.evaluations,
            clock.elapsed().as_secs_f64()
        );
        return Ok(());
    }
    Err(format!("no latch in {steps} steps (t = {t} s)").into())
}
