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

/// The fast eigen-triples of J(y) (|Im λ| > `fast_above`): λ_j, v_j and w_j with w_jᵀ v_j = 1.
struct Fast {
    lam: Vec<c64>,
    v: Vec<Vec<c64>>,
    w: Vec<Vec<c64>>,
}

fn fast_part(s: &Sys, y: &[f64], fast_above: f64) -> Result<Fast, Box<dyn std::error::Error>> {
    let n = y.len();
    let j = jacobian(s, y);
    let right = j.eigen().map_err(|e| format!("{e:?}"))?;
    let left = j
        .transpose()
        .to_owned()
        .eigen()
        .map_err(|e| format!("{e:?}"))?;
    let (lam, laml) = (right.S().column_vector(), left.S().column_vector());
    let mut fast = Fast {
        lam: Vec::new(),
        v: Vec::new(),
        w: Vec::new(),
    };
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
        let wv = dotc(&w, &v);
        fast.lam.push(l);
        fast.v.push(v);
        fast.w.push(w.iter().map(|x| x / wv).collect());
    }
    Ok(fast)
}

/// Σ a_i b_i without conjugation.
fn dotc(a: &[c64], b: &[c64]) -> c64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// y moved onto the slow manifold along the fast eigen-directions of J(y) (module docs).
fn project(s: &Sys, y: &[f64], fast: &Fast) -> Vec<f64> {
    let n = y.len();
    let (mut ys, mut f) = (y.to_vec(), vec![0.0; n]);
    for it in 0..4 {
        s.rhs(0.0, &ys, &mut f);
        let mut largest = 0.0f64;
        for ((v, w), l) in fast.v.iter().zip(&fast.w).zip(&fast.lam) {
            let wf: c64 = w.iter().zip(&f).map(|(a, b)| a * b).sum();
            largest = largest.max(wf.norm());
            let c = wf / l;
            for i in 0..n {
                ys[i] -= (v[i] * c).re;
            }
        }
        println!("Newton {it}: largest |w_jᵀ f| before the update {largest:.3e}");
    }
    ys
}

/// The ringing carried adiabatically along the slow run: δ = Re Σ_j c_j e^{θ_j} v_j(t), the
/// eigenvectors parallel-transported (w_j(t_k)ᵀ v_j(t_{k+1}) = 1), θ_j = ∫ λ_j dt by the
/// trapezoidal rule over the slow steps.
struct Ringing {
    fast: Fast,
    c: Vec<c64>,
    theta: Vec<c64>,
}

impl Ringing {
    fn new(fast: Fast, delta: &[f64]) -> Self {
        let c: Vec<c64> = fast
            .w
            .iter()
            .map(|w| w.iter().zip(delta).map(|(a, b)| a * b).sum())
            .collect();
        let theta = vec![c64::new(0.0, 0.0); c.len()];
        Self { fast, c, theta }
    }

    /// Moves on through `mid` (at h/2) to `next` (at h): the eigenvectors transported through
    /// both, the phases by Simpson's rule.
    fn advance_simpson(&mut self, mid: Fast, next: Fast, h: f64) {
        let (l0, t0) = (self.fast.lam.clone(), self.theta.clone());
        self.advance(mid, 0.5 * h);
        let lm = self.fast.lam.clone();
        self.advance(next, 0.5 * h);
        for j in 0..self.theta.len() {
            self.theta[j] = t0[j] + (l0[j] + lm[j] * 4.0 + self.fast.lam[j]) * (h / 6.0);
        }
    }

    /// Moves on to the decomposition `next`, a step h later.
    fn advance(&mut self, next: Fast, h: f64) {
        let mut taken = vec![false; next.lam.len()];
        let mut lam = Vec::new();
        let (mut v, mut w) = (Vec::new(), Vec::new());
        for j in 0..self.fast.lam.len() {
            let l = self.fast.lam[j];
            // The new pair with the largest overlap w_j(t_k)ᵀ v_k(t_{k+1}): eigenvalues of
            // modes that do not couple (in-plane and out-of-plane bending) cross as the
            // configuration changes, so the nearest eigenvalue is not the same mode.
            let overlap = |k: usize| dotc(&self.fast.w[j], &next.v[k]).norm();
            let k = (0..next.lam.len())
                .filter(|&k| !taken[k])
                .max_by(|&p, &q| overlap(p).total_cmp(&overlap(q)))
                .expect("as many fast pairs");
            taken[k] = true;
            let g = dotc(&self.fast.w[j], &next.v[k]);
            self.theta[j] += (l + next.lam[k]) * (0.5 * h);
            lam.push(next.lam[k]);
            v.push(next.v[k].iter().map(|x| x / g).collect::<Vec<_>>());
            w.push(next.w[k].iter().map(|x| x * g).collect::<Vec<_>>());
        }
        self.fast = Fast { lam, v, w };
    }

    fn delta(&self) -> Vec<f64> {
        let n = self.fast.v[0].len();
        let mut d = vec![0.0; n];
        for j in 0..self.c.len() {
            let a = self.c[j] * self.theta[j].exp();
            for (di, vi) in d.iter_mut().zip(&self.fast.v[j]) {
                *di += (a * vi).re;
            }
        }
        d
    }
}

/// Largest differences: α [rad], α̇ [rad/s], ω·η and η̇ [√kg·m/s].
fn errors(c: &Coupled, y: &[f64], r: &[f64]) -> [f64; 4] {
    let (m, n, np) = (c.modes(), c.panels(), c.positions());
    let (a0, e0, r0) = (c.alpha_offset(), c.alpha_offset() - m, np + c.rate_offset());
    let ed = np + c.hub_dof();
    let max = |it: &mut dyn Iterator<Item = f64>| it.fold(0.0, f64::max);
    [
        max(&mut (0..n).map(|k| (y[a0 + k] - r[a0 + k]).abs())),
        max(&mut (0..n).map(|k| (y[r0 + k] - r[r0 + k]).abs())),
        max(&mut (0..m).map(|k| ((y[e0 + k] - r[e0 + k]) * c.base.omega[k]).abs())),
        max(&mut (0..m).map(|k| (y[ed + k] - r[ed + k]).abs())),
    ]
}

/// Slow run plus adiabatic ringing to `t_end`, against the RK4 reference that
/// `examples/magnus_study.rs` cached for (modes, t_end).
fn ringing_run(
    s: &Sys,
    modes: usize,
    t_end: f64,
    tol: f64,
) -> Result<(), Box<dyn std::error::Error>> {
    let c = s.c;
    let cache = format!("target/magnus_study/rk4_{modes}_{t_end}.txt");
    let reference: Vec<f64> = std::fs::read_to_string(&cache)
        .map_err(|e| format!("{cache}: {e} (run magnus_study for ({modes}, {t_end}) first)"))?
        .lines()
        .map(|l| l.parse())
        .collect::<Result<_, _>>()?;
    let clock = Instant::now();
    let y0 = c.initial_state();
    let fast = fast_part(s, &y0, 20.0)?;
    let mut y = project(s, &y0, &fast);
    let delta0: Vec<f64> = y0.iter().zip(&y).map(|(a, b)| a - b).collect();
    let mut ringing = Ringing::new(fast_part(s, &y, 20.0)?, &delta0);
    let back = ringing.delta();
    let miss = back
        .iter()
        .zip(&delta0)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("ringing at t = 0 rebuilt from its modes to {miss:.2e}");
    let simpson = std::env::var("SIMPSON").is_ok();
    let h_max = std::env::var("H_MAX").map_or(Ok(f64::INFINITY), |v| v.parse())?;
    let mut stepper = Rodas5P::new(tol, tol * 1e-2, h_max);
    let (mut t, mut steps) = (0.0, 0usize);
    while t < t_end {
        let t_before = t;
        let dense = stepper.step(s, &mut t, &mut y, t_end);
        steps += 1;
        if simpson {
            let mut ym = vec![0.0; y.len()];
            dense.eval(0.5 * (t_before + t), &mut ym);
            let mid = fast_part(s, &ym, 20.0)?;
            ringing.advance_simpson(mid, fast_part(s, &y, 20.0)?, t - t_before);
        } else {
            ringing.advance(fast_part(s, &y, 20.0)?, t - t_before);
        }
    }
    let cpu = clock.elapsed().as_secs_f64();
    let total: Vec<f64> = y.iter().zip(ringing.delta()).map(|(a, b)| a + b).collect();
    let (es, et) = (errors(c, &y, &reference), errors(c, &total, &reference));
    println!("to {t_end} s: {steps} slow steps, CPU {cpu:.2} s (the decompositions included)");
    println!("errors against RK4 | α [rad] | α̇ [rad/s] | ω·η | η̇ [√kg·m/s]");
    println!(
        "slow run alone | {:.1e} | {:.1e} | {:.1e} | {:.1e}",
        es[0], es[1], es[2], es[3]
    );
    println!(
        "slow + ringing | {:.1e} | {:.1e} | {:.1e} | {:.1e}",
        et[0], et[1], et[2], et[3]
    );
    if std::env::var("PER_MODE").is_ok() {
        let (e0, ed) = (c.alpha_offset() - c.modes(), c.positions() + c.hub_dof());
        for k in 0..c.modes() {
            let w = c.base.omega[k];
            println!(
                "mode {k:2} {:8.1} Hz: ringing ω·η {:.2e} error {:.2e} | η̇ {:.2e} error {:.2e}",
                w / std::f64::consts::TAU,
                ((reference[e0 + k] - y[e0 + k]) * w).abs(),
                ((reference[e0 + k] - total[e0 + k]) * w).abs(),
                (reference[ed + k] - y[ed + k]).abs(),
                (reference[ed + k] - total[ed + k]).abs()
            );
        }
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: slow_manifold_study MODES TOL project|release fd|stiff [--ringing T_END]";
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
    if let Some(i) = args.iter().position(|a| a == "--ringing") {
        let t_end: f64 = args.get(i + 1).ok_or(usage)?.parse()?;
        return ringing_run(&s, modes, t_end, tol);
    }
    let mut y = if projected {
        project(&s, &y0, &fast_part(&s, &y0, 20.0)?)
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
