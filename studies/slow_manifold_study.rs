//! A measurement, not a feature: how fast is the coupled seed deployment once its state is
//! put on the slow manifold? (docs/bench-coupled.md, "The slow manifold, measured".)
//!
//! The seed (`examples/seed.toml`, `base_modes` replaced, ideal cable, free hub) is released
//! with its base at rest: the preloaded hinge springs load the mast tip as a step, and every
//! base mode rings from t = 0. Two measurements:
//!
//! * **The slow run alone** (the default): the release state is put on the slow manifold by
//!   the library's `deploy::adiabatic::slow_manifold` (a Newton iteration along the fast
//!   eigen-directions of J = ∂f/∂y, |Im λ| above a quarter of the lowest base mode), or left
//!   as it is (`release`); then Rodas5P integrates to the latch (α₁ reaching its latch angle;
//!   with the ideal cable every hinge latches then) with either Jacobian: `fd` (forward
//!   differences of f, every step) or `stiff` (the model's analytic stiff part,
//!   `Coupled::stiff_jacobian`, which `integrator = "implicit"` uses). What the projection
//!   takes out, the ringing, is not propagated.
//! * **`--ringing T_END`**: the library's adiabatic stepper (`integrator = "adiabatic"`: the
//!   slow run plus the ringing carried mode by mode) and the slow run alone, to T_END, against
//!   the RK4 reference that `studies/magnus_study.rs` caches for (modes, T_END).
//!
//! Run: `cargo run --release --example slow_manifold_study -- 20 1e-8 project fd`
//! (base modes, tolerance, `project` | `release`, `fd` | `stiff` [, `--ringing 55`]).

use faer::Mat;
use flexcraft::deploy::coupled::Coupled;
use flexcraft::deploy::{Deployment, OdeSystem, Rodas5P};
use flexcraft::ode::adiabatic::{fast_threshold, slow_manifold, Adiabatic};
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

/// The library's adiabatic stepper (`integrator = "adiabatic"`) to `t_end`, against the RK4
/// reference that `studies/magnus_study.rs` cached for (modes, t_end); beside it the slow
/// run alone (the state projected, no ringing).
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
    let threshold = fast_threshold(c.base.omega[0]);
    let run = |y: &mut Vec<f64>, adiabatic: bool| {
        let clock = Instant::now();
        let (mut t, mut steps) = (0.0, 0usize);
        let mut ad = Adiabatic::new(
            tol,
            tol * 1e-2,
            if adiabatic { threshold } else { f64::INFINITY },
        );
        while t < t_end {
            ad.step(s, &mut t, y, t_end);
            steps += 1;
        }
        (steps, ad.evaluations(), clock.elapsed().as_secs_f64())
    };
    let y0 = c.initial_state();
    let mut slow = slow_manifold(s, &y0, threshold).ok_or("eigensolver")?.0;
    let (steps_s, ev_s, cpu_s) = run(&mut slow, false);
    let mut total = y0.clone();
    let (steps, ev, cpu) = run(&mut total, true);
    let (es, et) = (errors(c, &slow, &reference), errors(c, &total, &reference));
    println!("errors against RK4 to {t_end} s | steps | evaluations | CPU [s] | α [rad] | α̇ [rad/s] | ω·η | η̇ [√kg·m/s]");
    println!(
        "slow run alone | {steps_s} | {ev_s} | {cpu_s:.3} | {:.1e} | {:.1e} | {:.1e} | {:.1e}",
        es[0], es[1], es[2], es[3]
    );
    println!(
        "adiabatic | {steps} | {ev} | {cpu:.3} | {:.1e} | {:.1e} | {:.1e} | {:.1e}",
        et[0], et[1], et[2], et[3]
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: slow_manifold_study MODES TOL project|release fd|stiff [--ringing T_END]";
    if args.is_empty() {
        // Without arguments, a short demonstration (4 base modes, the projected start, the
        // stiff Jacobian).
        args = ["4", "1e-8", "project", "stiff"]
            .iter()
            .map(ToString::to_string)
            .collect();
        println!("(no arguments: slow_manifold_study {})", args.join(" "));
    }
    let modes: usize = args.first().ok_or(usage)?.parse()?;
    let tol: f64 = args.get(1).ok_or(usage)?.parse()?;
    let projected = args.get(2).ok_or(usage)? == "project";
    let stiff_jacobian = args.get(3).ok_or(usage)? == "stiff";
    let text = std::fs::read_to_string("examples/seed.toml")?.replace(
        "synchronisation = \"cable\"\n",
        &format!("synchronisation = \"cable\"\nbase_modes = {modes}\n"),
    );
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
        slow_manifold(&s, &y0, fast_threshold(c.base.omega[0]))
            .ok_or("eigensolver")?
            .0
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
