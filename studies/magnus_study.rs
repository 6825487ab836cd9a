//! A measurement, not a feature: can an exponential integrator step over the seed's ringing
//! base modes and still be accurate? (docs/bench-coupled.md, "Exponential integrators,
//! measured".)
//!
//! The coupled seed deployment (`examples/seed.toml` with `base_modes` replaced) is
//! integrated from release to `t_end` with fixed steps h by one of these one-step methods,
//! all built on the local linearisation of y' = f(y) (f = `Coupled::rhs`, ideal cable, no
//! hinge locked):
//!
//! * `cf4`: the commutator-free Magnus method of Blanes & Moan (2006), fourth order for
//!   linear problems (at most third here: the node states are second-order predictions),
//!   y₁ = exp(h(α₂B₁ + α₁B₂)) exp(h(α₁B₁ + α₂B₂)) y₀, α₁,₂ = ¼ ± √3/6, with B_i the affine
//!   linearisation [J(ȳ_i), f(ȳ_i) − J(ȳ_i)ȳ_i; 0, 0] at the Gauss nodes t₀ + (½ ∓ √3/6)h;
//!   the node states ȳ_i come from the linearisation frozen at y₀.
//! * `mm`: the modified Magnus method (Iserles, BIT 42 (2002) 561–599) about the step's
//!   midpoint generator B̄ = (B₁ + B₂)/2 with B(t) ≈ B̄ + (t − t½)B′, B′ = √3 (B₂ − B₁)/h:
//!   y₁ = e^{hB̄} exp(Ω₁) y₀, Ω₁ = ∫₀ʰ (s − h/2) e^{−sB̄} B′ e^{sB̄} ds, the oscillatory
//!   integral taken exactly from one block-triangular exponential (Van Loan, IEEE TAC 23
//!   (1978) 395–404). Second order, uniformly in hω.
//! * `mm-smooth`, `cf4-smooth`: the same, but linearised about the node state with the
//!   base's elastic coordinates and rates set to zero, so that B(t) carries no ringing.
//! * `mm-smooth-rich`: `mm-smooth` with one Richardson extrapolation (h and two h/2 steps).
//! * `mm4`, `mm4-smooth`: the modified Magnus step with its second term
//!   Ω₂ = ½∬[C(s₁), C(s₂)], C(s) = (s − h/2) e^{−sB̄}B′e^{sB̄}, also from block exponentials
//!   ([`van_loan`]); fourth order. Under `--tol` the step without Ω₂ is its embedded estimate.
//!
//! The error is measured against classical RK4 with a fixed step far below the highest
//! period (cached in `target/magnus_study/`), and DOPRI5 (the library's explicit
//! integrator, through `simulate_coupled`) at the given tolerances is measured the same way.
//! Run: `cargo run --release --example magnus_study -- 20 20 mm-smooth 1 0.5 0.25` (without
//! arguments: `4 2 mm-smooth 0.05 0.025`, a few seconds)
//! (base modes, t_end, method, fixed steps…); `--tol 1e-8` adds a run whose step is
//! controlled on the Richardson pair (one step h against two of h/2), `--dopri 1e-8` DOPRI5 at
//! that tolerance. The first run for a (modes, t_end) pair computes the reference: about 4
//! minutes for 20 modes and 20 s. The cache is keyed by those two numbers only: delete
//! `target/magnus_study/` when the model changes.

use faer::{Mat, Scale};
use flexcraft::deploy::coupled::Coupled;
use flexcraft::deploy::{simulate_coupled, Deployment, Integrator};
use flexcraft::Scenario;
use std::cell::Cell;
use std::time::Instant;

/// The coupled model as y' = f(y), in scaled coordinates z = D y (η_j scaled by ω_j so that
/// each oscillator's position and rate have one size: the exponentials stay balanced).
struct Problem<'a> {
    c: &'a Coupled,
    free: Vec<bool>,
    dim: usize,
    scale: Vec<f64>,
    smooth: bool,
    /// Passes that recompute the node states from the step's own generator model.
    node_passes: usize,
    evaluations: Cell<usize>,
}

impl Problem<'_> {
    fn f(&self, y: &[f64]) -> Vec<f64> {
        let mut dy = vec![0.0; self.dim];
        self.c.rhs(y, &self.free, &mut dy);
        self.evaluations.set(self.evaluations.get() + 1);
        dy
    }

    fn elastic(&self) -> impl Iterator<Item = usize> + '_ {
        let (m, np, h) = (self.c.modes(), self.c.positions(), self.c.hub_dof());
        let e0 = self.c.alpha_offset() - m;
        (0..m).flat_map(move |k| [e0 + k, np + h + k])
    }

    /// The affine linearisation at `y` as a (dim + 1)-square generator in z.
    fn generator(&self, y: &[f64]) -> Mat<f64> {
        let n = self.dim;
        let mut ybar = y.to_vec();
        if self.smooth {
            for i in self.elastic() {
                ybar[i] = 0.0;
            }
        }
        let f0 = self.f(&ybar);
        // Forward differences, one column per coordinate, the step 1e-4 of the scaled size.
        let mut j = Mat::<f64>::zeros(n, n);
        for k in 0..n {
            let d = 1e-4 * (ybar[k] * self.scale[k]).abs().max(1.0) / self.scale[k];
            let mut yp = ybar.clone();
            yp[k] += d;
            let fp = self.f(&yp);
            for i in 0..n {
                j[(i, k)] = (fp[i] - f0[i]) / d;
            }
        }
        let mut b = Mat::<f64>::zeros(n + 1, n + 1);
        for i in 0..n {
            let mut jy = 0.0;
            for k in 0..n {
                b[(i, k)] = self.scale[i] * j[(i, k)] / self.scale[k];
                jy += j[(i, k)] * ybar[k];
            }
            b[(i, n)] = self.scale[i] * (f0[i] - jy);
        }
        b
    }

    fn to_z(&self, y: &[f64]) -> Vec<f64> {
        let mut z: Vec<f64> = y.iter().zip(&self.scale).map(|(a, s)| a * s).collect();
        z.push(1.0);
        z
    }

    fn to_y(&self, z: &[f64]) -> Vec<f64> {
        (0..self.dim).map(|i| z[i] / self.scale[i]).collect()
    }
}

/// e^A by scaling and squaring with a degree-12 Taylor polynomial (‖A/2^s‖ ≤ 1/4).
fn expm(a: &Mat<f64>) -> Mat<f64> {
    let n = a.nrows();
    let norm = (0..n)
        .map(|i| (0..n).map(|k| a[(i, k)].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let s = if norm > 0.25 {
        (norm / 0.25).log2().ceil() as i32
    } else {
        0
    };
    let x = a * Scale(0.5f64.powi(s));
    let id = Mat::<f64>::identity(n, n);
    let mut e = id.clone();
    for k in (1..=12).rev() {
        e = &id + (&x * &e) * Scale(1.0 / k as f64);
    }
    for _ in 0..s {
        e = &e * &e;
    }
    e
}

fn apply(e: &Mat<f64>, z: &[f64]) -> Vec<f64> {
    (0..z.len())
        .map(|i| (0..z.len()).map(|k| e[(i, k)] * z[k]).sum())
        .collect()
}

#[derive(Clone, Copy, PartialEq)]
enum Method {
    Cf4,
    Mm,
    /// The modified Magnus step with its second term Ω₂ (fourth order).
    Mm4,
}

/// exp(h M) for the block-bidiagonal M with B̄ on the diagonal and `links` on the
/// superdiagonal (None: the identity), as its first block row: block (1, k + 1) is the nested
/// integral ∫ e^{(h−s₁)B̄} L₁ e^{(s₁−s₂)B̄} L₂ … e^{s_k B̄} over h > s₁ > … > s_k > 0
/// (Van Loan 1978). An identity link after a B′ weights by the time of that B′.
fn van_loan(bbar: &Mat<f64>, links: &[Option<&Mat<f64>>], h: f64) -> Vec<Mat<f64>> {
    let (n, k) = (bbar.nrows(), links.len() + 1);
    let mut big = Mat::<f64>::zeros(k * n, k * n);
    for blk in 0..k {
        for i in 0..n {
            for c in 0..n {
                big[(blk * n + i, blk * n + c)] = h * bbar[(i, c)];
            }
        }
    }
    for (l, link) in links.iter().enumerate() {
        for i in 0..n {
            match link {
                Some(m) => {
                    for c in 0..n {
                        big[(l * n + i, (l + 1) * n + c)] = h * m[(i, c)];
                    }
                }
                None => big[(l * n + i, (l + 1) * n + i)] = h,
            }
        }
    }
    let e = expm(&big);
    (0..k)
        .map(|b| Mat::<f64>::from_fn(n, n, |i, c| e[(i, b * n + c)]))
        .collect()
}

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// One step of `method` from y, and for `Mm4` the second-order step without Ω₂ beside it
/// (the embedded pair of the step control).
fn step(p: &Problem, method: Method, y: &[f64], h: f64) -> (Vec<f64>, Option<Vec<f64>>) {
    let z = p.to_z(y);
    let b0 = p.generator(y);
    let node = |c: f64| p.to_y(&apply(&expm(&(&b0 * Scale(c * h))), &z));
    let (c1, c2) = (0.5 - SQRT3 / 6.0, 0.5 + SQRT3 / 6.0);
    let (b1, b2) = (p.generator(&node(c1)), p.generator(&node(c2)));
    match method {
        Method::Cf4 => {
            let (a1, a2) = (0.25 + SQRT3 / 6.0, 0.25 - SQRT3 / 6.0);
            let first = expm(&(&b1 * Scale(a1 * h) + &b2 * Scale(a2 * h)));
            let second = expm(&(&b1 * Scale(a2 * h) + &b2 * Scale(a1 * h)));
            (p.to_y(&apply(&second, &apply(&first, &z))), None)
        }
        Method::Mm | Method::Mm4 => {
            let (mut b1, mut b2) = (b1, b2);
            // Node states again, from this step's own generator model over [0, c h] (each
            // pass gains an order in the nodes, which the fourth-order step needs when the
            // slow motion is fast).
            for _ in 0..p.node_passes {
                let bbar = (&b1 + &b2) * Scale(0.5);
                let bp = (&b2 - &b1) * Scale(SQRT3 / h);
                let at = |t: f64| &bbar + &bp * Scale(t - 0.5 * h);
                let node = |c: f64| {
                    let (zc, _) =
                        modified_magnus(&at(c * c1 * h), &at(c * c2 * h), c * h, &z, true);
                    p.to_y(&zc)
                };
                let (n1, n2) = (node(c1), node(c2));
                b1 = p.generator(&n1);
                b2 = p.generator(&n2);
            }
            let (high, low) = modified_magnus(&b1, &b2, h, &z, method == Method::Mm4);
            (p.to_y(&high), low.map(|l| p.to_y(&l)))
        }
    }
}

/// The modified Magnus step over h from z with the generator model through the Gauss-node
/// generators b1, b2: e^{hB̄} exp(Ω₁) z, and with `fourth` e^{hB̄} exp(Ω₁ + Ω₂) z beside it
/// (returned first, the second-order value second).
fn modified_magnus(
    b1: &Mat<f64>,
    b2: &Mat<f64>,
    h: f64,
    z: &[f64],
    fourth: bool,
) -> (Vec<f64>, Option<Vec<f64>>) {
    let bbar = (b1 + b2) * Scale(0.5);
    let bp = (b2 - b1) * Scale(SQRT3 / h);
    // Chain [B′, I]: blocks e^{hB̄}, ∫ e^{(h−s)B̄} B′ e^{sB̄} ds, the same weighted by s.
    let e = van_loan(&bbar, &[Some(&bp), None], h);
    // G = e^{hB̄} Ω₁ = (1,3) − h/2 (1,2); e^{hB̄} exp(Ω₁) = exp(G e^{−hB̄}) e^{hB̄}.
    let g = &e[2] - &e[1] * Scale(0.5 * h);
    let inverse = expm(&(&bbar * Scale(-h)));
    let second = apply(&expm(&(&g * &inverse)), &apply(&e[0], z));
    if !fourth {
        return (second, None);
    }
    // Ω₂ = P − ½ Ω₁², P = ∫∫_{s₂<s₁} C(s₁) C(s₂), C(s) = (s − h/2) e^{−sB̄} B′ e^{sB̄}.
    // e^{hB̄} P from two chains: w(s₁)w(s₂) = (s₁ − s₂)s₂ + s₂² − (h/2)((s₁ − s₂) + 2s₂)
    // + h²/4, an identity between the B′ giving s₁ − s₂, one or two after them s₂ or s₂²/2.
    let x = van_loan(&bbar, &[Some(&bp), None, Some(&bp), None], h);
    let y2 = van_loan(&bbar, &[Some(&bp), Some(&bp), None, None], h);
    let (t_d, t_ds) = (&x[3], &x[4]); // s₁ − s₂, (s₁ − s₂)s₂
    let (t_1, t_s, t_ss) = (&y2[2], &y2[3], &y2[4]); // 1, s₂, s₂²/2
    let ep = t_ds + t_ss * Scale(2.0) - (t_d + t_s * Scale(2.0)) * Scale(0.5 * h)
        + t_1 * Scale(0.25 * h * h);
    let omega1 = &inverse * &g;
    let omega = &omega1 + &inverse * &ep - (&omega1 * &omega1) * Scale(0.5);
    (apply(&e[0], &apply(&expm(&omega), z)), Some(second))
}

/// One Richardson step: from a step h and two steps h/2, the extrapolation
/// (4 y_{h/2,h/2} − y_h)/3, the estimate (y_{h/2,h/2} − y_h)/3 of the halves' error, and the
/// halves' value.
fn richardson(p: &Problem, kind: Method, y: &[f64], h: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let whole = step(p, kind, y, h).0;
    let half = step(p, kind, &step(p, kind, y, h / 2.0).0, h / 2.0).0;
    let estimate = half
        .iter()
        .zip(&whole)
        .map(|(a, b)| (a - b) / 3.0)
        .collect();
    let extrapolated = half
        .iter()
        .zip(&whole)
        .map(|(a, b)| (4.0 * a - b) / 3.0)
        .collect();
    (extrapolated, estimate, half)
}

fn rk4(p: &Problem, y: &mut [f64], h: f64, steps: usize) {
    let n = y.len();
    for _ in 0..steps {
        let k1 = p.f(y);
        let k2 = p.f(&(0..n).map(|i| y[i] + 0.5 * h * k1[i]).collect::<Vec<_>>());
        let k3 = p.f(&(0..n).map(|i| y[i] + 0.5 * h * k2[i]).collect::<Vec<_>>());
        let k4 = p.f(&(0..n).map(|i| y[i] + h * k3[i]).collect::<Vec<_>>());
        for i in 0..n {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
}

/// Largest errors: α [rad], α̇ [rad/s], ω·η and η̇ [√kg·m/s].
fn errors(p: &Problem, y: &[f64], r: &[f64]) -> [f64; 4] {
    let c = p.c;
    let (m, n, np) = (c.modes(), c.panels(), c.positions());
    let (a0, e0, r0) = (c.alpha_offset(), c.alpha_offset() - m, np + c.rate_offset());
    let max = |it: &mut dyn Iterator<Item = f64>| it.fold(0.0, f64::max);
    [
        max(&mut (0..n).map(|k| (y[a0 + k] - r[a0 + k]).abs())),
        max(&mut (0..n).map(|k| (y[r0 + k] - r[r0 + k]).abs())),
        max(&mut (0..m).map(|k| ((y[e0 + k] - r[e0 + k]) * p.scale[e0 + k]).abs())),
        max(&mut (0..m).map(|k| (y[np + c.hub_dof() + k] - r[np + c.hub_dof() + k]).abs())),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        // Without arguments, a short demonstration: 4 base modes for 2 s, the modified
        // Magnus method at two steps against the RK4 reference.
        args = ["4", "2", "mm-smooth", "0.05", "0.025"]
            .iter()
            .map(ToString::to_string)
            .collect();
        println!("(no arguments: magnus_study {})", args.join(" "));
    }
    let modes: usize = args.first().ok_or("base modes")?.parse()?;
    let t_end: f64 = args.get(1).ok_or("t_end")?.parse()?;
    let method = args.get(2).ok_or("method")?.as_str();
    let mut dopri = Vec::new();
    let mut adaptive = Vec::new();
    let mut node_passes = 0usize;
    let mut hs = Vec::new();
    let mut it = args[3..].iter();
    while let Some(a) = it.next() {
        if a == "--dopri" {
            dopri.push(it.next().ok_or("--dopri tol")?.parse::<f64>()?);
        } else if a == "--node-passes" {
            node_passes = it.next().ok_or("--node-passes k")?.parse()?;
        } else if a == "--tol" {
            adaptive.push(it.next().ok_or("--tol tol")?.parse::<f64>()?);
        } else {
            hs.push(a.parse::<f64>()?);
        }
    }
    let text = std::fs::read_to_string("examples/seed.toml")?.replace(
        "synchronisation = \"cable\"\n",
        &format!("synchronisation = \"cable\"\nbase_modes = {modes}\n"),
    );
    let sc = Scenario::from_toml_str(&text, "seed.toml")?;
    let d: Deployment = sc.deployment.clone().ok_or("no deployment")?;
    let c = d.coupled(&sc.structure)?;
    let dim = c.positions() + c.speeds();
    let mut scale = vec![1.0; dim];
    let e0 = c.alpha_offset() - c.modes();
    scale[e0..e0 + c.modes()].copy_from_slice(&c.base.omega[..c.modes()]);
    let (kind, smooth, extrapolate) = match method {
        "cf4" => (Method::Cf4, false, false),
        "cf4-smooth" => (Method::Cf4, true, false),
        "mm" => (Method::Mm, false, false),
        "mm-smooth" => (Method::Mm, true, false),
        "mm-smooth-rich" => (Method::Mm, true, true),
        "mm4" => (Method::Mm4, false, false),
        "mm4-smooth" => (Method::Mm4, true, false),
        other => return Err(format!("unknown method {other}").into()),
    };
    let p = Problem {
        c: &c,
        free: vec![true; c.panels()],
        dim,
        scale,
        smooth,
        node_passes,
        evaluations: Cell::new(0),
    };

    // The reference: RK4 with h = 5e-6 s (h ω_max ≤ 0.03 up to 20 modes), cached.
    let cache = format!("target/magnus_study/rk4_{modes}_{t_end}.txt");
    let reference: Vec<f64> = match std::fs::read_to_string(&cache) {
        Ok(t) => t.lines().map(|l| l.parse()).collect::<Result<_, _>>()?,
        Err(_) => {
            let mut y = c.initial_state();
            let steps = (t_end / 5e-6).round() as usize;
            rk4(&p, &mut y, t_end / steps as f64, steps);
            std::fs::create_dir_all("target/magnus_study")?;
            let lines: Vec<String> = y.iter().map(|v| format!("{v:e}")).collect();
            std::fs::write(&cache, lines.join("\n"))?;
            y
        }
    };
    println!("seed, {modes} base modes, t = 0 … {t_end} s; errors against RK4 (h = 5e-6 s)");
    println!("method | h [s] | steps | f evaluations | CPU [s] | α [rad] | α̇ [rad/s] | ω·η | η̇");
    for tol in dopri {
        let run = Deployment {
            tolerance: tol,
            end_time: t_end,
            integrator: Integrator::Explicit,
            ..d.clone()
        };
        let t0 = Instant::now();
        let (_, r) = simulate_coupled(&sc.structure, &run)?;
        let secs = t0.elapsed().as_secs_f64();
        let s = r
            .samples
            .iter()
            .rev()
            .find(|s| (s.t - t_end).abs() < 1e-9)
            .ok_or("no sample at t_end")?;
        let b = s.body.as_ref().ok_or("no body sample")?;
        let mut y = reference.clone();
        let a0 = c.alpha_offset();
        let r0 = c.positions() + c.rate_offset();
        y[a0..a0 + c.panels()].copy_from_slice(&s.alpha);
        y[r0..r0 + c.panels()].copy_from_slice(&s.rate);
        y[e0..e0 + c.modes()].copy_from_slice(&b.eta);
        let e = errors(&p, &y, &reference);
        println!(
            "DOPRI5 tol {tol:e} | adaptive | – | {} | {secs:.2} | {:.1e} | {:.1e} | {:.1e} | (not sampled)",
            r.evaluations, e[0], e[1], e[2]
        );
    }
    for tol in adaptive {
        // Step control on an error estimate of third order locally: mm4's embedded
        // second-order step, or else the Richardson pair (one step h against two of h/2, the
        // difference over 3). The RMS of its scaled components (atol = rtol = tol, z
        // coordinates) is held at 1; the higher-order value goes on.
        p.evaluations.set(0);
        let t0 = Instant::now();
        let (mut y, mut t, mut h) = (c.initial_state(), 0.0f64, 0.1f64);
        let (mut accepted, mut rejected) = (0usize, 0usize);
        while t < t_end - 1e-12 {
            let hh = h.min(t_end - t);
            // (the new state, its error estimate, the estimated state, whose size scales it)
            let (next, estimate, sized) = match kind {
                // Mm4: the embedded second-order step; the fourth-order one goes on.
                Method::Mm4 => {
                    let (high, low) = step(&p, kind, &y, hh);
                    let low = low.expect("mm4 returns its embedded step");
                    let d = high.iter().zip(&low).map(|(a, b)| a - b).collect();
                    (high.clone(), d, high)
                }
                // The Richardson pair; the extrapolation goes on.
                _ => richardson(&p, kind, &y, hh),
            };
            let err = ((0..dim)
                .map(|i| {
                    let sc =
                        tol * (1.0 + (y[i] * p.scale[i]).abs().max((sized[i] * p.scale[i]).abs()));
                    (estimate[i] * p.scale[i] / sc).powi(2)
                })
                .sum::<f64>()
                / dim as f64)
                .sqrt();
            let fac = (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 4.0);
            if err <= 1.0 {
                y = next;
                t += hh;
                accepted += 1;
            } else {
                rejected += 1;
            }
            h = hh * fac;
        }
        let secs = t0.elapsed().as_secs_f64();
        let e = errors(&p, &y, &reference);
        println!(
            "{method} adaptive tol {tol:e} | {accepted} accepted, {rejected} rejected | | {} | {secs:.2} | {:.1e} | {:.1e} | {:.1e} | {:.1e}",
            p.evaluations.get(),
            e[0],
            e[1],
            e[2],
            e[3]
        );
    }
    for h0 in hs {
        let steps = (t_end / h0).round() as usize;
        let h = t_end / steps as f64;
        p.evaluations.set(0);
        let t0 = Instant::now();
        let mut y = c.initial_state();
        for _ in 0..steps {
            y = if extrapolate {
                richardson(&p, kind, &y, h).0
            } else {
                step(&p, kind, &y, h).0
            };
        }
        let secs = t0.elapsed().as_secs_f64();
        let e = errors(&p, &y, &reference);
        println!(
            "{method} | {h} | {steps} | {} | {secs:.2} | {:.1e} | {:.1e} | {:.1e} | {:.1e}",
            p.evaluations.get(),
            e[0],
            e[1],
            e[2],
            e[3]
        );
    }
    Ok(())
}
