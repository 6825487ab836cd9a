//! Coupled-deployment benchmarks (issue 11): the accordion array on the flexible,
//! free-floating base of `deploy::coupled`, integrated by the explicit DOPRI5.
//!
//! 1. The seed example (free hub, 20 base modes at the seed's mast terms): time and steps of
//!    a window from release, extrapolated to the whole deployment, and the rigid base
//!    (0 modes) until all latched for comparison. A whole flexible run takes minutes (it
//!    ends at the 1e6-step limit), too long for criterion's samples.
//! 2. A 50-panel wing on the seed's mast (30 base modes, mast terms raised), ideal cable:
//!    the same figures.
//! 3. The cost of one right-hand side at the initial state for N = 2…100 panels and
//!    m = 0…30 base modes (`Coupled::rhs` and its `Coupled::evaluate` part), the fitted
//!    growth exponents, and the dense kernels at the same sizes.
//! 4. The seed's window at tolerances 1e-4…1e-10, and its steps against m.
//! 5. Whole deployments with the adiabatic integrator (docs/theory.md §2.8), tolerance 1e-8,
//!    until all latched (or, with compliant latches, settled): the seed with 20 base modes,
//!    seed_compliant (6 modes, k_L = 1e5 and 1e7) and the 50-panel wing with 30 modes — the
//!    issue's targets 0.2 s, 0.5 s (1e7 within 3× of 1e4) and 1 s. The whole-process times
//!    of the same runs come from `scripts/bench_coupled.sh`.
//!
//! Times are the on-CPU time of the benchmark thread (the wall time is also kept): the
//! machine may be shared. Run `scripts/bench_coupled.sh` (prints the table of
//! docs/bench-coupled.md) or `cargo bench --bench coupled`; the table follows criterion's
//! output. `COUPLED_FULL=1` also runs each whole deployment once (about 15 minutes);
//! `COUPLED_RHS_LOOP=N,m` only times `rhs` in a loop (for a profiler, or to compare heap
//! settings in a fresh process).

use criterion::{Bencher, Criterion, SamplingMode};
use flexcraft::deploy::base::BaseKind;
use flexcraft::deploy::coupled::{Coupled, CoupledRun, Synchronisation};
use flexcraft::deploy::{simulate_coupled, Deployment, Integrator};
use flexcraft::faer::{Mat, Side};
use flexcraft::Scenario;
use std::collections::BTreeMap;
use std::hint::black_box;
use std::sync::Mutex;
use std::time::{Duration, Instant};

const SEED: &str = include_str!("../examples/seed.toml");
const SEED_COMPLIANT: &str = include_str!("../examples/seed_compliant.toml");
/// The seed's mast terms (26 elastic coordinates: 20 modes exist).
const SEED_TERMS: (usize, usize, usize) = (8, 6, 4);
/// Raised mast terms (50 elastic coordinates) for 30 modes: the terms at which the seed's
/// first 10 frequencies converge to 1e-6 (docs/convergence.md, benches/modes.rs).
const RICH_TERMS: (usize, usize, usize) = (16, 10, 8);
/// The seed's per-hinge tables, removed for other panel counts.
const SEED_HINGES: &str = "[[deployment.hinges]]          # hinge 1, at the wing root\nstiffness = 12.0\n[[deployment.hinges]]          # hinge 2: the common values above\n[[deployment.hinges]]          # hinge 3\n";
/// Simulated windows from release, s.
const SEED_WINDOW: f64 = 0.5;
const WIDE_WINDOW: f64 = 0.02;
/// The 50-panel wing: common hinge stiffness, N·m/rad (0.25 rad preload as in the seed).
const WIDE_STIFFNESS: f64 = 1.0;
const PANELS: [usize; 6] = [2, 5, 10, 20, 50, 100];
const MODES: [usize; 5] = [0, 5, 10, 20, 30];
const TOLS: [f64; 4] = [1e-4, 1e-6, 1e-8, 1e-10];

fn edit(src: String, from: &str, to: &str) -> String {
    assert!(
        src.contains(from),
        "examples/seed.toml no longer contains {from:?}"
    );
    src.replace(from, to)
}

/// The seed scenario with mast terms `terms`, `panels` equal panels (the seed's own hinge
/// tables for 3, the common hinge values otherwise) and an optional common hinge stiffness.
/// The `[deployment] hub` line (being removed from the format) is dropped where present: the
/// hub's motion is `[hub] motion = "free"`.
fn scenario(terms: (usize, usize, usize), panels: usize, stiffness: Option<f64>) -> Scenario {
    let mut src = SEED.replace("hub = \"fixed\"\n", "");
    assert!(src.contains("[hub]\nmotion = \"free\""));
    src = edit(
        src,
        "bending = 8, torsion = 6, axial = 4",
        &format!(
            "bending = {}, torsion = {}, axial = {}",
            terms.0, terms.1, terms.2
        ),
    );
    if panels != 3 {
        src = edit(src, "panels = 3", &format!("panels = {panels}"));
        // Older seeds list per-hinge tables for their three hinges.
        src = src.replace(SEED_HINGES, "");
    }
    if let Some(k) = stiffness {
        let key = "[deployment.hinge]\nstiffness = ";
        let at = src
            .find(key)
            .expect("examples/seed.toml has [deployment.hinge] stiffness")
            + key.len();
        let end = at + src[at..].find('\n').expect("a line");
        src.replace_range(at..end, &format!("{k:?}"));
    }
    Scenario::from_toml_str(&src, "seed.toml").expect("scenario")
}

/// The coupled model of a scenario's deployment with `modes` base modes.
fn coupled(sc: &Scenario, modes: usize, sync: Synchronisation) -> Coupled {
    let d = Deployment {
        // No modes: the base frozen rigid (`base_modes = 0` is clamped to one mode).
        base: if modes == 0 {
            BaseKind::Rigid
        } else {
            BaseKind::Flexible { modes: Some(modes) }
        },
        synchronisation: sync,
        ..sc.deployment.clone().expect("[deployment]")
    };
    let c = d.coupled(&sc.structure).expect("coupled model");
    assert_eq!(c.modes(), modes, "the base has fewer modes than asked");
    c
}

fn seed(modes: usize) -> Coupled {
    coupled(&scenario(SEED_TERMS, 3, None), modes, Synchronisation::None)
}

fn wide(modes: usize) -> Coupled {
    coupled(
        &scenario(RICH_TERMS, 50, Some(WIDE_STIFFNESS)),
        modes,
        Synchronisation::IdealCable,
    )
}

/// Highest kept base frequency, Hz.
fn f_max(c: &Coupled) -> f64 {
    c.base.omega.last().copied().unwrap_or(0.0) / (2.0 * std::f64::consts::PI)
}

/// Per-iteration on-CPU and wall times (s) of every call criterion made, by key.
static TIMES: Mutex<BTreeMap<String, Vec<(f64, f64)>>> = Mutex::new(BTreeMap::new());
/// The last run of each run benchmark: steps, final time, all latched, latches.
static RUNS: Mutex<BTreeMap<String, (usize, f64, bool, usize)>> = Mutex::new(BTreeMap::new());
/// Criterion's samples per benchmark (the last calls of each benchmark's routine).
const SAMPLES: usize = 10;

/// On-CPU time of the calling thread, s (`CLOCK_THREAD_CPUTIME_ID`): unlike the wall time
/// it does not count the time this thread waits while other processes have the core.
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
fn cpu_time() -> Option<f64> {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut t = Timespec { sec: 0, nsec: 0 };
    // SAFETY: glibc's clock_gettime writes one timespec (two 64-bit fields on 64-bit Linux)
    // through the valid pointer it is given.
    let r = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) };
    (r == 0).then_some(t.sec as f64 + t.nsec as f64 * 1e-9)
}

#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
fn cpu_time() -> Option<f64> {
    None
}

/// Times `f` through criterion and keeps the per-iteration times under `key`. Criterion
/// is given the on-CPU time where there is one (the machine may be shared), else the wall
/// time.
fn timed<T>(b: &mut Bencher<'_>, key: &str, mut f: impl FnMut() -> T) {
    b.iter_custom(|iters| {
        let c0 = cpu_time();
        let t0 = Instant::now();
        for _ in 0..iters {
            black_box(f());
        }
        let wall = t0.elapsed();
        let cpu = c0.zip(cpu_time()).map(|(a, b)| b - a);
        let per = |t: f64| t / iters as f64;
        TIMES
            .lock()
            .unwrap()
            .entry(key.to_string())
            .or_default()
            .push((
                per(cpu.unwrap_or(wall.as_secs_f64())),
                per(wall.as_secs_f64()),
            ));
        cpu.map_or(wall, Duration::from_secs_f64)
    });
}

fn run_and_keep(key: &str, c: &Coupled, end: f64, tol: f64) -> CoupledRun {
    let run = c.simulate(false, end, tol);
    let info = (
        run.steps,
        run.final_time,
        run.all_latched,
        run.latches.len(),
    );
    RUNS.lock().unwrap().insert(key.to_string(), info);
    run
}

/// Median per-iteration time of `key` over criterion's samples (the warm-up calls come
/// first and are left out): on-CPU, s.
fn median(key: &str) -> Option<f64> {
    medians(key).map(|m| m.0)
}

/// Median per-iteration on-CPU and wall times of `key`, s.
fn medians(key: &str) -> Option<(f64, f64)> {
    let times = TIMES.lock().unwrap();
    let all = times.get(key)?;
    let last = &all[all.len().saturating_sub(SAMPLES)..];
    let mid = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    Some((
        mid(last.iter().map(|t| t.0).collect()),
        mid(last.iter().map(|t| t.1).collect()),
    ))
}

fn run_info(key: &str) -> Option<(usize, f64, bool, usize)> {
    RUNS.lock().unwrap().get(key).copied()
}

/// Targets 1, 2 and 4: deployment runs (windows from release, and the rigid base until all
/// latched).
fn bench_runs(cr: &mut Criterion) {
    let mut g = cr.benchmark_group("coupled_run");
    g.sample_size(SAMPLES)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(10))
        .measurement_time(Duration::from_secs(1));
    let seed20 = seed(20);
    let sc = scenario(SEED_TERMS, 3, None);
    let d = sc.deployment.as_ref().unwrap();
    g.bench_function("seed build (20 modes)", |b| {
        timed(b, "seed build", || seed(20))
    });
    let rigid = seed(0);
    g.bench_function("seed rigid base until all latched", |b| {
        timed(b, "seed rigid", || {
            run_and_keep("seed rigid", &rigid, d.end_time, d.tolerance)
        })
    });
    for tol in TOLS {
        let key = format!("seed20 {tol:e}");
        g.bench_function(
            format!("seed 20 modes, first {SEED_WINDOW} s, tol {tol:e}"),
            |b| timed(b, &key, || run_and_keep(&key, &seed20, SEED_WINDOW, tol)),
        );
    }
    let wide30 = wide(30);
    g.bench_function("50 panels build (30 modes)", |b| {
        timed(b, "wide build", || wide(30))
    });
    let wide0 = wide(0);
    g.bench_function("50 panels rigid base until all latched", |b| {
        timed(b, "wide rigid", || {
            run_and_keep("wide rigid", &wide0, d.end_time, d.tolerance)
        })
    });
    g.bench_function(
        format!("50 panels 30 modes, first {WIDE_WINDOW} s, tol 1e-10"),
        |b| {
            timed(b, "wide30", || {
                run_and_keep("wide30", &wide30, WIDE_WINDOW, 1e-10)
            })
        },
    );
    g.finish();
}

/// The adiabatic runs of target 5: label, scenario, base modes.
fn adiabatic_cases() -> Vec<(&'static str, Scenario, usize)> {
    let compliant = |k: &str, c: &str| {
        let src = edit(
            edit(
                SEED_COMPLIANT.to_string(),
                "stiffness = 1.0e5",
                &format!("stiffness = {k}"),
            ),
            "damping = 2236.0",
            &format!("damping = {c}"),
        );
        Scenario::from_toml_str(&src, "seed_compliant.toml").expect("scenario")
    };
    vec![
        ("seed, 20 modes", scenario(SEED_TERMS, 3, None), 20),
        ("seed_compliant, k_L = 1e4", compliant("1.0e4", "707.1"), 6),
        ("seed_compliant, k_L = 1e5", compliant("1.0e5", "2236.0"), 6),
        (
            "seed_compliant, k_L = 1e7",
            compliant("1.0e7", "22360.0"),
            6,
        ),
        (
            "50 panels, 30 modes",
            scenario(RICH_TERMS, 50, Some(WIDE_STIFFNESS)),
            30,
        ),
    ]
}

/// Target 5: whole deployments with the adiabatic integrator at tolerance 1e-8 (the model's
/// build included: `simulate_coupled` from the structure).
fn bench_adiabatic(cr: &mut Criterion) {
    let mut g = cr.benchmark_group("coupled_adiabatic");
    g.sample_size(SAMPLES)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(10))
        .measurement_time(Duration::from_secs(2));
    for (label, sc, modes) in adiabatic_cases() {
        let d = Deployment {
            base: BaseKind::Flexible { modes: Some(modes) },
            integrator: Integrator::Adiabatic,
            tolerance: 1e-8,
            ..sc.deployment.clone().expect("[deployment]")
        };
        let key = format!("adiabatic {label}");
        g.bench_function(label, |b| {
            timed(b, &key, || {
                let (_, r) = simulate_coupled(&sc.structure, &d).expect("run");
                let info = (r.evaluations, r.final_time, r.all_latched, r.latches.len());
                RUNS.lock().unwrap().insert(key.clone(), info);
                r
            })
        });
    }
    g.finish();
}

fn print_adiabatic() {
    println!("[5] adiabatic integrator, tol 1e-8, whole deployments (build included)");
    println!("    {:<44} {:>10} {:>10}  evaluations", "", "CPU", "wall");
    for (label, ..) in adiabatic_cases() {
        let key = format!("adiabatic {label}");
        if let Some((evaluations, tf, all, _)) = run_info(&key) {
            row(
                label,
                &key,
                &format!("{evaluations} (to t = {tf:.3} s, all latched: {all})"),
            );
        }
    }
}

/// Zeroes the upper halves of the vector registers (`vzeroupper`). The library is compiled
/// for baseline x86-64 while faer dispatches AVX-512 kernels at run time; after a faer
/// matrix product the scalar code of `Coupled::evaluate` (`Invariants::at` most of all) runs
/// up to 3× slower than after faer's Cholesky solve or a `vzeroupper`. Inside
/// `Coupled::rhs`, `evaluate` follows the previous call's Cholesky solve, so `evaluate`
/// alone is timed after this call to see it as `rhs` does.
fn clean_upper() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: `vzeroupper` (AVX, checked above) only zeroes the upper halves of
        // ymm/zmm0–15, which `clobber_abi("C")` declares clobbered; it touches no memory.
        unsafe { std::arch::asm!("vzeroupper", clobber_abi("C"), options(nomem, nostack)) }
    }
}

/// The model of cell (N, m) of the cost grid: free hub, mast terms `RICH_TERMS`.
fn grid_model(n: usize, m: usize, sync: Synchronisation) -> Coupled {
    coupled(&scenario(RICH_TERMS, n, None), m, sync)
}

/// Target 3: one right-hand side and its `evaluate` part at the initial state, N × m.
fn bench_rhs(cr: &mut Criterion) {
    let mut g = cr.benchmark_group("coupled_rhs");
    g.sample_size(SAMPLES)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_millis(500));
    let mut cells: Vec<(String, Coupled)> = Vec::new();
    for n in PANELS {
        for m in MODES {
            cells.push((format!("{n} {m}"), grid_model(n, m, Synchronisation::None)));
        }
    }
    cells.push((String::from("seed"), seed(20)));
    cells.push((
        String::from("cable 50 30"),
        grid_model(50, 30, Synchronisation::IdealCable),
    ));
    for (cell, c) in &cells {
        let y = c.initial_state();
        let free = vec![true; c.panels()];
        let mut dy = vec![0.0; y.len()];
        let key = format!("rhs {cell}");
        g.bench_function(&key, |b| {
            timed(b, &key, || c.rhs(black_box(&y), &free, &mut dy))
        });
        if cell.starts_with("cable") {
            continue;
        }
        let key = format!("evaluate {cell}");
        g.bench_function(&key, |b| {
            timed(b, &key, || {
                clean_upper();
                c.evaluate(black_box(&y))
            })
        });
        if cell == "50 30" || cell == "2 30" {
            let key = format!("evaluate after a product {cell}");
            g.bench_function(&key, |b| timed(b, &key, || c.evaluate(black_box(&y))));
            let key = format!("solve {cell}");
            g.bench_function(&key, |b| {
                timed(b, &key, || {
                    clean_upper();
                    c.solve(black_box(&y), &free)
                })
            });
        }
    }
    // Invariants::at alone (m = 30), after a 40×40 faer product, with and without
    // `vzeroupper` in between.
    let c = &cells.iter().find(|(k, _)| k == "2 30").unwrap().1;
    let eta = vec![0.0; c.modes()];
    let a = Mat::<f64>::from_fn(40, 40, |i, j| (i + j) as f64);
    for clean in [false, true] {
        let key = format!(
            "at m=30 after a product{}",
            if clean { ", vzeroupper" } else { "" }
        );
        g.bench_function(&key, |b| {
            timed(b, &key, || {
                black_box(&a * &a);
                if clean {
                    clean_upper();
                }
                c.base.invariants.at(black_box(&eta))
            })
        });
        let key = format!("40x40 product{}", if clean { ", vzeroupper" } else { "" });
        g.bench_function(&key, |b| {
            timed(b, &key, || {
                let p = black_box(&a * &a);
                if clean {
                    clean_upper();
                }
                p
            })
        });
    }
    // The dense kernels of one rhs at its sizes n = 6 + N + m: a product n×n · n×n (as
    // M·Z and Zᵀ(MZ) with Z = I when every hinge is free and there is no cable) and a
    // Cholesky factorisation.
    for n in [38, 86, 136] {
        let a = Mat::<f64>::from_fn(n, n, |i, j| {
            if i == j {
                n as f64
            } else {
                1.0 / (1 + i + j) as f64
            }
        });
        let key = format!("product {n}");
        g.bench_function(&key, |b| timed(b, &key, || &a * black_box(&a)));
        let key = format!("cholesky {n}");
        g.bench_function(&key, |b| {
            timed(b, &key, || black_box(&a).llt(Side::Lower).is_ok())
        });
    }
    g.finish();
}

/// `COUPLED_RHS_LOOP="N,m"`: only times `Coupled::rhs` of that grid cell in a loop of
/// `COUPLED_RHS_REPS` calls (default 20 000) and prints µs per call, for a profiler or to
/// compare glibc malloc settings in a fresh process.
fn rhs_loop(spec: &str) {
    let v: Vec<usize> = spec
        .split(',')
        .map(|x| x.trim().parse().expect("COUPLED_RHS_LOOP=N,m"))
        .collect();
    let reps: usize = std::env::var("COUPLED_RHS_REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(20_000);
    let c = grid_model(v[0], v[1], Synchronisation::None);
    let y = c.initial_state();
    let free = vec![true; c.panels()];
    let mut dy = vec![0.0; y.len()];
    let c0 = cpu_time();
    let t0 = Instant::now();
    for _ in 0..reps {
        c.rhs(black_box(&y), &free, &mut dy);
        black_box(&dy);
    }
    let wall = t0.elapsed().as_secs_f64();
    let cpu = c0.zip(cpu_time()).map_or(wall, |(a, b)| b - a);
    println!(
        "rhs N={} m={}: {:.1} µs per call (CPU; wall {:.1} µs; {reps} calls in a fresh process)",
        v[0],
        v[1],
        cpu / reps as f64 * 1e6,
        wall / reps as f64 * 1e6
    );
}

/// Least-squares slope of ln y against ln x.
fn slope(pts: &[(f64, f64)]) -> f64 {
    let k = pts.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = pts.iter().map(|(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / k, ly.iter().sum::<f64>() / k);
    let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = lx.iter().map(|a| (a - mx).powi(2)).sum();
    sxy / sxx
}

fn fmt_time(s: f64) -> String {
    if s >= 1.0 {
        format!("{s:.2} s")
    } else if s >= 1e-3 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{:.2} µs", s * 1e6)
    }
}

/// One line of the run table: label, on-CPU and wall time of `key`, then `rest`.
fn row(label: &str, key: &str, rest: &str) {
    let (cpu, wall) = medians(key).map_or((String::from("—"), String::from("—")), |(c, w)| {
        (fmt_time(c), fmt_time(w))
    });
    println!("    {label:<44} {cpu:>10} {wall:>10}  {rest}");
}

fn print_runs() {
    let c20 = seed(20);
    println!(
        "[1] seed, free hub, 20 base modes (mast terms {SEED_TERMS:?}, f_max = {:.0} Hz)",
        f_max(&c20)
    );
    println!("    {:<44} {:>10} {:>10}  steps", "", "CPU", "wall");
    row("build (scenario, base modes, invariants)", "seed build", "");
    let rigid = run_info("seed rigid");
    if let Some((steps, tf, all, _)) = rigid {
        row(
            "rigid base (0 modes) until all latched",
            "seed rigid",
            &format!("{steps} (t = {tf:.2} s, all latched: {all})"),
        );
    }
    let key = "seed20 1e-10";
    if let (Some((t, _)), Some((steps, ..)), Some((_, tf, ..))) =
        (medians(key), run_info(key), rigid)
    {
        row(
            &format!("20 modes, first {SEED_WINDOW} s, tol 1e-10"),
            key,
            &format!(
                "{steps} ({:.0} per simulated s; {:.1} µs per step)",
                steps as f64 / SEED_WINDOW,
                t / steps as f64 * 1e6
            ),
        );
        println!(
            "    {:<44} {:>10} {:>10}  ≥ {:.2e} (the step limit is 1e6)",
            format!("→ whole deployment (≥ {tf:.1} s), extrapolated"),
            format!("≥ {}", fmt_time(t * tf / SEED_WINDOW)),
            "",
            steps as f64 * tf / SEED_WINDOW
        );
    }
    let w30 = wide(30);
    println!(
        "[2] 50 panels (0.3 m, ideal cable, k = {WIDE_STIFFNESS} N·m/rad), 30 base modes (mast terms {RICH_TERMS:?}, f_max = {:.0} Hz)",
        f_max(&w30)
    );
    row("build (scenario, base modes, invariants)", "wide build", "");
    let rigid = run_info("wide rigid");
    if let Some((steps, tf, all, _)) = rigid {
        row(
            "rigid base (0 modes) until all latched",
            "wide rigid",
            &format!("{steps} (t = {tf:.2} s, all latched: {all})"),
        );
    }
    if let (Some((t, _)), Some((steps, ..)), Some((_, tf, ..))) =
        (medians("wide30"), run_info("wide30"), rigid)
    {
        row(
            &format!("30 modes, first {WIDE_WINDOW} s, tol 1e-10"),
            "wide30",
            &format!(
                "{steps} ({:.0} per simulated s; {:.1} µs per step)",
                steps as f64 / WIDE_WINDOW,
                t / steps as f64 * 1e6
            ),
        );
        println!(
            "    {:<44} {:>10} {:>10}  ≥ {:.2e}",
            format!("→ whole deployment (≥ {tf:.1} s), extrapolated"),
            format!("≥ {}", fmt_time(t * tf / WIDE_WINDOW)),
            "",
            steps as f64 * tf / WIDE_WINDOW
        );
    }
}

/// Target 4: the seed's window against the tolerance, and its steps against m.
fn print_tol() {
    let w_max = 2.0 * std::f64::consts::PI * f_max(&seed(20));
    println!("[4] seed, 20 modes, first {SEED_WINDOW} s, against the tolerance (h: the mean step)");
    println!(
        "    {:<8} {:>10} {:>10} {:>8} {:>10}  {:>7}  steps ÷ steps at 100× looser tol",
        "tol", "CPU", "wall", "steps", "steps/s", "h·ω_max"
    );
    let mut prev: Option<usize> = None;
    for tol in TOLS {
        let key = format!("seed20 {tol:e}");
        if let (Some((c, w)), Some((steps, ..))) = (medians(&key), run_info(&key)) {
            let ratio = prev.map_or(String::from("—"), |p| {
                format!("{:.2}", steps as f64 / p as f64)
            });
            println!(
                "    {tol:<8.0e} {:>10} {:>10} {steps:>8} {:>10.0}  {:>7.2}  {ratio}",
                fmt_time(c),
                fmt_time(w),
                steps as f64 / SEED_WINDOW,
                SEED_WINDOW / steps as f64 * w_max
            );
            prev = Some(steps);
        }
    }
    println!(
        "    (accuracy-bound DOPRI5: steps ∝ tol^(-1/5), 2.51 per 100×; on the imaginary axis its \
         stability function stays within |R| ≤ 1 only up to h·ω ≈ 1)"
    );
    println!(
        "    steps in the first {SEED_WINDOW} s at tol 1e-10 against the number of base modes m (one run each):"
    );
    println!("      m   f_max (Hz)    steps   steps per period of f_max");
    for m in [0, 2, 5, 10, 15, 20, 24] {
        let c = seed(m);
        let run = c.simulate(false, SEED_WINDOW, 1e-10);
        let f = f_max(&c);
        let per_period = if f > 0.0 {
            format!("{:.0}", run.steps as f64 / (f * SEED_WINDOW))
        } else {
            String::from("—")
        };
        println!("      {m:<3} {f:>9.1}   {:>7}   {per_period}", run.steps);
    }
}

fn print_rhs() {
    println!(
        "[3] one rhs at the initial state, µs (in brackets: the dense `evaluate`, µs, which samples and loads use; the rhs does without it since the O(N) elimination); free hub, mast terms {RICH_TERMS:?}"
    );
    print!("    N \\ m ");
    for m in MODES {
        print!("{m:>14}");
    }
    println!();
    let mut rhs = BTreeMap::new();
    let mut ev = BTreeMap::new();
    for n in PANELS {
        print!("    {n:>5} ");
        for m in MODES {
            match (
                median(&format!("rhs {n} {m}")),
                median(&format!("evaluate {n} {m}")),
            ) {
                (Some(r), Some(e)) => {
                    print!("{:>8.1} ({:>5.1})", r * 1e6, e * 1e6);
                    rhs.insert((n, m), r);
                    ev.insert((n, m), e);
                }
                _ => print!("{:>14}", "—"),
            }
        }
        println!();
    }
    let us = |k: &str| median(k).map_or(String::from("—"), |t| format!("{:.1} µs", t * 1e6));
    println!(
        "    seed N=3 m=20 (mast terms {SEED_TERMS:?}): rhs {}, evaluate {}",
        us("rhs seed"),
        us("evaluate seed")
    );
    println!(
        "    N=50 m=30: solve {}, rhs with the ideal cable {}",
        us("solve 50 30"),
        us("rhs cable 50 30")
    );
    println!(
        "    evaluate timed alone after its own faer product (no vzeroupper): N=2 m=30 {} (vs {}), N=50 m=30 {} (vs {})",
        us("evaluate after a product 2 30"),
        us("evaluate 2 30"),
        us("evaluate after a product 50 30"),
        us("evaluate 50 30")
    );
    let diff = |a: &str, b: &str| match (median(a), median(b)) {
        (Some(x), Some(y)) => format!("{:.1} µs", (x - y) * 1e6),
        _ => String::from("—"),
    };
    println!(
        "    Invariants::at, m=30, after a 40×40 faer product: {}; with vzeroupper in between: {}",
        diff("at m=30 after a product", "40x40 product"),
        diff(
            "at m=30 after a product, vzeroupper",
            "40x40 product, vzeroupper"
        )
    );
    for n in [38, 86, 136] {
        println!(
            "    dense kernels at n = {n}: product n×n·n×n {}, Cholesky {}",
            us(&format!("product {n}")),
            us(&format!("cholesky {n}"))
        );
    }
    if rhs.len() < PANELS.len() * MODES.len() {
        return;
    }
    println!("    fitted exponents p of t ∝ x^p (least squares in log–log):");
    for (name, t) in [("rhs", &rhs), ("dense evaluate", &ev)] {
        let in_n = |m: usize, ns: &[usize]| {
            slope(
                &ns.iter()
                    .map(|&n| (n as f64, t[&(n, m)]))
                    .collect::<Vec<_>>(),
            )
        };
        let in_m = |n: usize, added: bool| {
            let base = if added { t[&(n, 0)] } else { 0.0 };
            slope(
                &[10, 20, 30]
                    .iter()
                    .map(|&m| (m as f64, (t[&(n, m)] - base).max(1e-12)))
                    .collect::<Vec<_>>(),
            )
        };
        let all: Vec<(f64, f64)> = t
            .iter()
            .map(|((n, m), v)| ((6 + n + m) as f64, *v))
            .collect();
        println!("    {name}:");
        for ns in [&[10, 20, 50][..], &[20, 50, 100][..]] {
            println!(
                "      in N (N = {ns:?}) at m = 0, 10, 30:        {:.2}, {:.2}, {:.2}",
                in_n(0, ns),
                in_n(10, ns),
                in_n(30, ns)
            );
        }
        println!(
            "      in m (m = 10, 20, 30) at N = 2, 10, 50, 100:        {:.2}, {:.2}, {:.2}, {:.2}",
            in_m(2, false),
            in_m(10, false),
            in_m(50, false),
            in_m(100, false)
        );
        println!(
            "      of t − t(m=0) in m (10, 20, 30) at N = 2, 10, 50, 100: {:.2}, {:.2}, {:.2}, {:.2}",
            in_m(2, true),
            in_m(10, true),
            in_m(50, true),
            in_m(100, true)
        );
        println!(
            "      in the speed count n = 6 + N + m (all {} cells):      {:.2}",
            all.len(),
            slope(&all)
        );
    }
}

/// The whole deployments, once each (COUPLED_FULL=1): they take minutes.
fn print_full() {
    println!("[full] whole deployments, one run each (until all latched or the 1e6-step limit)");
    let one = |name: &str, c: &Coupled, tol: f64| {
        let c0 = cpu_time();
        let t0 = Instant::now();
        let run = c.simulate(false, 300.0, tol);
        let wall = t0.elapsed().as_secs_f64();
        let cpu = c0.zip(cpu_time()).map_or(wall, |(a, b)| b - a);
        println!(
            "    {name:<30} tol {tol:<6.0e} CPU {:>9}, wall {:>9}: {:>7} steps, stopped at t = {:.2} s, all latched: {}, latches (hinge, t) {:?}",
            fmt_time(cpu),
            fmt_time(wall),
            run.steps,
            run.final_time,
            run.all_latched,
            run.latches
                .iter()
                .map(|l| (l.hinge, (l.time * 100.0).round() / 100.0))
                .collect::<Vec<_>>()
        );
    };
    one("seed, 4 modes (f_max 74 Hz)", &seed(4), 1e-10);
    let c = seed(20);
    for tol in [1e-4, 1e-6, 1e-8, 1e-10] {
        one("seed, 20 modes", &c, tol);
    }
    one("50 panels, cable, 30 modes", &wide(30), 1e-10);
}

fn main() {
    if let Ok(spec) = std::env::var("COUPLED_RHS_LOOP") {
        rhs_loop(&spec);
        return;
    }
    let mut cr = Criterion::default().configure_from_args();
    bench_runs(&mut cr);
    bench_rhs(&mut cr);
    bench_adiabatic(&mut cr);
    cr.final_summary();
    println!();
    println!("== coupled figures (median of criterion's samples) ==");
    print_runs();
    print_rhs();
    print_tol();
    print_adiabatic();
    if std::env::var_os("COUPLED_FULL").is_some() {
        print_full();
    }
}
