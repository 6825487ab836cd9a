//! The compliant latch (docs/theory.md §2.3a; issue 19) against closed forms.

use flexcraft::deploy::simulate_coupled;
use flexcraft::Scenario;

/// One 2 m, 10 kg panel on a held hub (no beams: a rigid base), hinge spring k = 3 N·m/rad
/// preloaded 0.4 rad, compliant latch k_L, c_L.
fn one_panel(latch: &str) -> String {
    super::common::one_panel("one panel, compliant latch", 50.0, 1e-13, latch)
}

/// Before capture: J α̈ = k (α_ref − α) from rest, so the capture rate is
/// ω₀ = √(2 (V(0) − V(α_L)) / J), J = I + m l²/4. After: J ẍ + c_L ẋ + (k + k_L) x = 0 with
/// x = α − α_eq, α_eq = (k α_ref + k_L α_L)/(k + k_L), x(0) = α_L − α_eq, ẋ(0) = ω₀ — the
/// closed-form damped oscillator; the latch moment is −k_L (α − α_L) − c_L α̇. Every sample
/// after the capture matches to 1e-8 (of the latch moment's peak, and in rad).
#[test]
fn one_panel_capture_matches_the_damped_oscillator() {
    let (kl, cl) = (400.0, 6.0);
    let src = one_panel(&format!(
        "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = {cl:?}\nsettle_time = 5.0\n"
    ));
    let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let (c, r) = simulate_coupled(&sc.structure, d).unwrap();
    let p = &c.chain.panels[0];
    let h = &c.chain.hinges[0];
    let (k, a_ref, a_l) = (h.stiffness, h.reference_angle, h.latch_angle);
    let j = c.panel_inertia[0][2] + 0.25 * p.mass * p.length * p.length;
    assert_eq!(r.captures.len(), 1);
    assert!(r.latches.is_empty(), "a compliant latch is no impact");
    let cap = &r.captures[0];
    let v = |a: f64| 0.5 * k * (a_ref - a).powi(2);
    let w0 = (2.0 * (v(0.0) - v(a_l)) / j).sqrt();
    assert!(
        (cap.rates[0] - w0).abs() < 1e-9 * w0,
        "{} vs {w0}",
        cap.rates[0]
    );
    let a_eq = (k * a_ref + kl * a_l) / (k + kl);
    let wn = ((k + kl) / j).sqrt();
    let zeta = cl / (2.0 * (j * (k + kl)).sqrt());
    assert!(zeta < 1.0);
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let (x0, v0) = (a_l - a_eq, w0);
    let exact = |t: f64| {
        let e = (-zeta * wn * t).exp();
        let (s, co) = (wd * t).sin_cos();
        let b = (v0 + zeta * wn * x0) / wd;
        let x = e * (x0 * co + b * s);
        let xd = -zeta * wn * x + e * wd * (b * co - x0 * s);
        (a_eq + x, xd)
    };
    let peak = r
        .samples
        .iter()
        .map(|s| s.latch_moment[0].abs())
        .fold(0.0, f64::max);
    assert!(peak > 1.0);
    let mut checked = 0;
    for s in r.samples.iter().filter(|s| s.t > cap.time) {
        let (a, ad) = exact(s.t - cap.time);
        let m = -kl * (a - a_l) - cl * ad;
        assert!(
            (s.alpha[0] - a).abs() < 1e-8,
            "t = {}: α {} vs {a}",
            s.t,
            s.alpha[0]
        );
        assert!(
            (s.latch_moment[0] - m).abs() < 1e-8 * peak,
            "t = {}: latch moment {} vs {m}",
            s.t,
            s.latch_moment[0]
        );
        checked += 1;
    }
    assert!(checked > 100, "{checked} samples after the capture");
    // The run settles for settle_time after the capture.
    assert!((r.final_time - (cap.time + 5.0)).abs() < 1e-9);
    assert_eq!(r.settled, Some(flexcraft::deploy::Settled::AfterTime));
    assert!(r.all_latched);
}

/// The decayed settling (`Settle::decayed`, a library option) ends once the hinge rate has stayed below 1 % of
/// the capture rate for one latch period W = 2π √(J / (k + k_L)), J = I + m l²/4 =
/// 40/3 kg·m², k = 3 N·m/rad the hinge spring: the end time against the closed-form damped
/// oscillator's (the first t with max_{[t − W, t]} |ẋ| ≤ 0.01 ω₀), to 2 % of W (the run
/// checks at its steps' quarter points). With light damping the cap, 100 periods after the
/// capture, ends it, with a warning that gives the rate left; an end_time before either ends
/// it with a warning that says so.
#[test]
fn the_decayed_settling_ends_when_the_latch_has_decayed_or_at_its_cap() {
    use flexcraft::deploy::Settled;
    let (kl, j) = (4000.0_f64, 40.0 / 3.0);
    let w = 2.0 * std::f64::consts::PI * (j / (kl + 3.0)).sqrt();
    let cap_time = 100.0 * w;
    for (cl, decays) in [(60.0, true), (0.6, false)] {
        let src = one_panel(&format!(
            "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = {cl:?}\n"
        ))
        .replace("end_time = 20.0", "end_time = 60.0");
        let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
        let (c, r) = simulate_coupled(&sc.structure, &decayed(&sc)).unwrap();
        let h = &c.chain.hinges[0];
        let (k, a_ref, a_l) = (h.stiffness, h.reference_angle, h.latch_angle);
        let cap = &r.captures[0];
        let w0 = cap.rates[0];
        // ẋ(t) of J ẍ + c_L ẋ + (k + k_L) x = 0, x(0) = α_L − α_eq, ẋ(0) = ω₀.
        let a_eq = (k * a_ref + kl * a_l) / (k + kl);
        let wn = ((k + kl) / j).sqrt();
        let zeta = cl / (2.0 * (j * (k + kl)).sqrt());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let (x0, v0) = (a_l - a_eq, w0);
        let b = (v0 + zeta * wn * x0) / wd;
        let rate = |t: f64| {
            let e = (-zeta * wn * t).exp();
            let (s, co) = (wd * t).sin_cos();
            -zeta * wn * e * (x0 * co + b * s) + e * wd * (b * co - x0 * s)
        };
        // The last time |ẋ| exceeds 1 %, on a grid of W/2000 over the cap.
        let dt = w / 2000.0;
        let last_loud = (0..200_000)
            .map(|i| f64::from(i) * dt)
            .filter(|&t| rate(t).abs() > 0.01 * w0)
            .fold(0.0, f64::max);
        let settle = r.final_time - cap.time;
        if decays {
            let expected = last_loud + w;
            assert!(expected < cap_time, "{expected} s: not within the cap");
            assert!(
                (settle - expected).abs() < 0.02 * w,
                "settled {settle} s after the capture, closed form {expected} s"
            );
            assert_eq!(r.settled, Some(Settled::Decayed));
            assert!(r.warnings.is_empty(), "{:?}", r.warnings);
        } else {
            assert!(last_loud + w > cap_time);
            assert!((settle - cap_time).abs() < 1e-9, "{settle} vs {cap_time}");
            let Some(Settled::Capped { ratio }) = r.settled else {
                panic!("{:?}", r.settled);
            };
            // The largest |ẋ| over the last period, from the closed form.
            let loudest = (0..=2000)
                .map(|i| rate(cap_time - f64::from(i) * dt).abs())
                .fold(0.0, f64::max);
            assert!(
                (ratio - loudest / w0).abs() < 2e-3 * ratio,
                "{ratio} vs {}",
                loudest / w0
            );
            assert!(r
                .warnings
                .iter()
                .any(|x| x.to_string().contains("had not settled")));
        }
    }
    // end_time 1 s after the capture: neither decayed nor capped.
    let src = one_panel(
        "[deployment.latch]\nmodel = \"compliant\"\nstiffness = 4000.0\ndamping = 60.0\n",
    );
    let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
    let (_, r) = simulate_coupled(&sc.structure, &decayed(&sc)).unwrap();
    let t_cut = r.captures[0].time + 1.0;
    let src = src.replace("end_time = 20.0", &format!("end_time = {t_cut:?}"));
    let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
    let (_, r) = simulate_coupled(&sc.structure, &decayed(&sc)).unwrap();
    assert!(r.all_latched && (r.final_time - t_cut).abs() < 1e-9);
    assert!(matches!(r.settled, Some(Settled::EndTime { ratio: Some(x) }) if x > 0.01));
    assert!(r
        .warnings
        .iter()
        .any(|x| x.to_string().contains("end_time")));
}

/// `sc`'s deployment run until the compliant latches' motion has decayed
/// ([`flexcraft::deploy::Settle::decayed`]) instead of the default hand-over one latch period
/// after the last capture.
fn decayed(sc: &Scenario) -> flexcraft::deploy::Deployment {
    let d = sc.deployment.clone().unwrap();
    let flexcraft::deploy::LatchModel::Compliant { stiffness, .. } = &d.latch else {
        panic!("compliant latches");
    };
    let settling = Some(flexcraft::deploy::Settle::decayed(
        &d.chain,
        stiffness,
        d.synchronisation,
    ));
    flexcraft::deploy::Deployment { settling, ..d }
}

/// The default: one latch period W after the last capture the run ends and hands over
/// (`Settled::HandedOver`, no warning), W the captured array's slowest mode with the base
/// held (here one panel: 2π √(J/(k + k_L))).
#[test]
fn by_default_the_run_hands_over_one_latch_period_after_the_last_capture() {
    let (kl, j) = (4000.0_f64, 40.0 / 3.0);
    let w = 2.0 * std::f64::consts::PI * (j / (kl + 3.0)).sqrt();
    let src = one_panel(&format!(
        "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = 0.6\n"
    ));
    let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
    let (_, r) = simulate_coupled(&sc.structure, sc.deployment.as_ref().unwrap()).unwrap();
    let settle = r.final_time - r.captures[0].time;
    assert!((settle - w).abs() < 1e-9 * w, "{settle} s vs W = {w} s");
    assert_eq!(r.settled, Some(flexcraft::deploy::Settled::HandedOver));
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

/// As the latch stiffness grows at a fixed damping ratio (c_L ∝ √k_L), the rate some latch
/// periods after capture tends to the plastic impact's post-impact rate (zero for one panel
/// on a held hub) and the energy the latch takes to the impact's loss; the hinge angle tends
/// to the latch angle. Here, eight seconds after the capture, the hinge rests at its static
/// equilibrium, whose offset from the latch angle is the closed form k (α_ref − α_L)/(k + k_L)
/// (hinge spring against latch spring), within what the damped oscillator's envelope leaves
/// of the capture's vibration, and so falls towards zero as k_L grows.
#[test]
fn stiffer_latches_tend_to_the_plastic_impact() {
    let mut last = f64::INFINITY;
    let mut last_excess = f64::INFINITY;
    for kl in [1e2_f64, 1e3, 1e4] {
        // ζ = c_L / (2 √(J k_L)) = 0.5 with J = I + m l²/4 = 40/3 kg·m².
        let cl = (40.0 / 3.0 * kl).sqrt();
        let src = one_panel(&format!(
            "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = {cl:?}\nsettle_time = 8.0\n"
        ));
        let sc = Scenario::from_toml_str(&src, "one.toml").unwrap();
        let (c, r) = simulate_coupled(&sc.structure, sc.deployment.as_ref().unwrap()).unwrap();
        let end = r.samples.last().unwrap();
        let h = &c.chain.hinges[0];
        let off = (end.alpha[0] - h.latch_angle).abs();
        let static_offset =
            (h.stiffness * (h.reference_angle - h.latch_angle) / (h.stiffness + kl)).abs();
        // What is left of the capture's vibration: the damped oscillator's envelope
        // (|x₀| + |ẋ₀|/ω_d) e^{−ζω_n t} (x₀ = the static offset, ẋ₀ the capture rate).
        let p = &c.chain.panels[0];
        let j = c.panel_inertia[0][2] + 0.25 * p.mass * p.length * p.length;
        let wn = ((h.stiffness + kl) / j).sqrt();
        let zeta = cl / (2.0 * (j * (h.stiffness + kl)).sqrt());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let after = end.t - r.captures[0].time;
        let left = (static_offset + r.captures[0].rates[0].abs() / wd) * (-zeta * wn * after).exp();
        assert!(
            (off - static_offset).abs() <= left + 1e-9,
            "k_L = {kl}: |α − α_L| = {off}, static {static_offset}, vibration left ≤ {left:e}"
        );
        assert!(
            off < last,
            "k_L = {kl}: |α − α_L| = {off} (previous {last})"
        );
        assert!(
            end.rate[0].abs() <= wn * left / (1.0 - zeta * zeta).sqrt() + 1e-9,
            "k_L = {kl}: rate {}",
            end.rate[0]
        );
        // The energy the latch took (the run's kinetic + hinge spring + latch spring energy
        // at the capture less at the end): the damped oscillator dissipates all of its
        // vibration about α_eq, ½ J ω₀² + ½ (k + k_L) (α_L − α_eq)², i.e. the plastic impact's
        // loss ½ J ω₀² plus M² / (2 (k + k_L)), M = k (α_ref − α_L) the hinge spring's moment
        // at the latch — an excess that vanishes as k_L grows. What is left of the vibration
        // after eight seconds is below 1e-8 of it here (e^{−2ζω_n t}).
        let energy = |s: &flexcraft::deploy::Sample| s.kinetic + s.spring + s.latch_energy;
        let at_capture = r
            .samples
            .iter()
            .find(|s| s.t >= r.captures[0].time)
            .expect("a sample at the capture");
        assert!((at_capture.t - r.captures[0].time).abs() < 1e-12);
        let taken = energy(at_capture) - energy(end);
        let w0 = r.captures[0].rates[0];
        let plastic = 0.5 * j * w0 * w0;
        let moment = h.stiffness * (h.reference_angle - h.latch_angle);
        let excess = moment * moment / (2.0 * (h.stiffness + kl));
        assert!(
            (taken - (plastic + excess)).abs() <= 1e-8 * plastic,
            "k_L = {kl}: the latch took {taken} J, closed form {} J (plastic {plastic}, excess {excess})",
            plastic + excess
        );
        assert!(
            taken / plastic - 1.0 < last_excess,
            "k_L = {kl}: the excess over the plastic loss does not fall"
        );
        last_excess = taken / plastic - 1.0;
        last = off;
    }
}

/// `super::coupled::PLANAR_CASE` (free 1500 kg hub, 8 m elastic aluminium mast, three 2 m
/// panels) with its mast function space reduced to bending 4, axial 2 (short runs), the run
/// settings replaced and compliant latches k_L, c_L added; `extra` goes into `[deployment]`.
fn planar_compliant(extra: &str, end: f64, rate: f64, kl: f64, cl: f64) -> String {
    let mut src = super::coupled::PLANAR_CASE.to_string();
    for (from, to) in [
        (
            "terms = { bending = 6, torsion = 2, axial = 4 }",
            "terms = { bending = 4, torsion = 2, axial = 2 }".to_string(),
        ),
        (
            "end_time = 6.0\noutput_rate = 10.0",
            format!("{extra}end_time = {end:?}\noutput_rate = {rate:?}"),
        ),
    ] {
        assert!(src.contains(from), "PLANAR_CASE has no {from:?}");
        src = src.replace(from, &to);
    }
    src + &format!(
        "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = {cl:?}\nsettle_time = 1.0\n"
    )
}

/// The mast case with three base modes and latches k_L = 2e3 N·m/rad, c_L = 20 N·m·s/rad,
/// sampled at 8 kHz for 12 s.
fn mast_case() -> String {
    planar_compliant("base_modes = 3\n", 12.0, 8000.0, 2.0e3, 20.0)
}

/// Free hub, elastic mast, compliant latches, no hinge damping: kinetic + hinge springs +
/// elastic + latch springs + dissipated (∫ Σ c_L α̇_j² dt over the captured hinges, Simpson
/// on 0.125 ms samples, piecewise between captures) equals the initial energy to 1e-9 of it; the linear momentum and the
/// angular momentum about the system's centre of mass stay zero (the system starts at rest)
/// to 1e-9 of the largest panel momentum, from release through every capture.
#[test]
fn compliant_latches_conserve_energy_with_dissipation_and_momentum() {
    let sc = Scenario::from_toml_str(&mast_case(), "mast.toml").unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let (c, r) = simulate_coupled(&sc.structure, d).unwrap();
    assert!(!r.captures.is_empty(), "no capture by t = {}", r.final_time);
    let damping = &c.latch.as_ref().unwrap().damping;
    let capture_time = |j: usize| {
        r.captures
            .iter()
            .find(|k| k.hinge == j + 1)
            .map_or(f64::INFINITY, |k| k.time)
    };
    let h = 1.0 / d.output_rate;
    let energy = |s: &flexcraft::deploy::Sample| {
        s.kinetic + s.spring + s.latch_energy + s.body.as_ref().unwrap().elastic
    };
    let e0 = energy(&r.samples[0]);
    // ∫ power dt, piece by piece between captures (the damper's power jumps at a capture):
    // each piece starts at the capture's own sample, then runs on the uniform grid; the
    // first, uneven interval and a last odd one by the quadratic through three samples
    // (3-point Gauss on it), the rest by Simpson.
    let mut bounds: Vec<f64> = r.captures.iter().map(|k| k.time).collect();
    bounds.dedup();
    bounds.push(r.final_time);
    let mut dissipated = 0.0;
    let mut t0 = bounds[0];
    for w in bounds.windows(2) {
        // Within the piece the captured set is that of its start.
        let pw = |s: &flexcraft::deploy::Sample| -> f64 {
            (0..c.panels())
                .filter(|&j| capture_time(j) <= w[0])
                .map(|j| damping[j] * s.rate[j] * s.rate[j])
                .sum()
        };
        let on_grid = |t: f64| ((t / h).round() * h - t).abs() < 1e-9;
        let mut pts: Vec<_> = r
            .samples
            .iter()
            .filter(|s| s.t >= w[0] && s.t <= w[1])
            .filter(|s| s.t == w[0] || s.t == w[1] || on_grid(s.t))
            .collect();
        pts.dedup_by(|a, b| a.t == b.t);
        let n = pts.len();
        assert!(n > 6 && pts[0].t == w[0], "piece from {}", w[0]);
        let quad = |k: usize, a: f64, b: f64| {
            let (x, f): (Vec<f64>, Vec<f64>) = (k..k + 3).map(|i| (pts[i].t, pw(pts[i]))).unzip();
            let lagrange = |t: f64| {
                (0..3)
                    .map(|i| {
                        f[i] * (0..3)
                            .filter(|&j| j != i)
                            .map(|j| (t - x[j]) / (x[i] - x[j]))
                            .product::<f64>()
                    })
                    .sum::<f64>()
            };
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            let g = (0.6_f64).sqrt();
            half * (5.0 * lagrange(mid - g * half)
                + 8.0 * lagrange(mid)
                + 5.0 * lagrange(mid + g * half))
                / 9.0
        };
        // The uneven first interval, Simpson pairs on the grid, then what is left (the
        // uneven last interval to the next capture among it) interval by interval.
        dissipated += quad(0, pts[0].t, pts[1].t);
        let last_grid = if on_grid(pts[n - 1].t) { n - 1 } else { n - 2 };
        let mut k = 1;
        while k + 2 <= last_grid {
            let (a, b, c2) = (pts[k], pts[k + 1], pts[k + 2]);
            dissipated += (c2.t - a.t) / 6.0 * (pw(a) + 4.0 * pw(b) + pw(c2));
            k += 2;
        }
        while k + 1 < n {
            dissipated += quad(n - 3, pts[k].t, pts[k + 1].t);
            k += 1;
        }
        let e = energy(pts[n - 1]);
        assert!(
            (e0 - e - dissipated).abs() < 1e-9 * e0,
            "t = {} (piece from {}): E0 − E = {} vs dissipated {dissipated}",
            pts[n - 1].t,
            w[0],
            e0 - e
        );
        t0 = pts[n - 1].t;
    }
    assert!(t0 > r.captures.last().unwrap().time);
    assert!(
        dissipated > 1e-3 * e0,
        "the latches dissipate: {dissipated} of {e0}"
    );
    let scale = c
        .chain
        .panels
        .iter()
        .map(|p| p.mass * p.length)
        .fold(0.0, f64::max)
        * r.captures[0]
            .rates
            .iter()
            .fold(0.0_f64, |a, x| a.max(x.abs()));
    for s in &r.samples {
        let b = s.body.as_ref().unwrap();
        let p = b.momentum.iter().map(|x| x * x).sum::<f64>().sqrt();
        let l = b.angular_momentum.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(p < 1e-9 * scale, "t = {}: linear momentum {p}", s.t);
        assert!(l < 1e-8 * scale * 10.0, "t = {}: angular momentum {l}", s.t);
    }
}

/// Rigid base (held hub, no beams), two panels: as the latch stiffness k_L grows at a fixed
/// damping ratio (c_L ∝ √k_L), the motion some time after the first capture tends to the one
/// after the rigid latch's plastic impact (the same crossing: the runs agree exactly before
/// it), and the energy the latch has taken to the impact's loss. Observed (2026-11-23): the
/// rate error 5.5e-4, 1.7e-5, 1.7e-6, 1.7e-7 rad/s and the energy error 1.3e-3, 1.3e-4,
/// 1.3e-5, 1.3e-6 (relative) for k_L = 1e3…1e6: order 1 in k_L (the latch spring's
/// residual compliance, (hinge moment)/k_L, after the transient has decayed).
#[test]
fn stiff_compliant_latches_tend_to_the_plastic_impact_on_a_rigid_base() {
    let two = |latch: &str| {
        one_panel(latch)
            .replace("length = 2.0", "length = 4.0")
            .replace("panels = 1", "panels = 2")
            .replace("end_time = 20.0", "end_time = 30.0")
            .replace("output_rate = 50.0", "output_rate = 20.0")
            .replace("tolerance = 1e-13", "tolerance = 1e-11")
    };
    let run = |src: String| {
        let sc = Scenario::from_toml_str(&src, "two.toml").unwrap();
        simulate_coupled(&sc.structure, sc.deployment.as_ref().unwrap())
            .unwrap()
            .1
    };
    let rigid = run(two(""));
    let first = &rigid.latches[0];
    let t_star = first.time + 1.0;
    let at = |r: &flexcraft::deploy::DeploymentResult| {
        r.samples
            .iter()
            .find(|s| s.t >= t_star)
            .map(|s| (s.rate.clone(), s.kinetic + s.spring + s.latch_energy))
            .unwrap()
    };
    let (rates_r, e_r) = at(&rigid);
    let mut errors = Vec::new();
    for kl in [1e3_f64, 1e4, 1e5, 1e6] {
        // ζ ≈ 0.7 on one panel about its hinge (J = 40/3 kg·m²).
        let cl = 1.4 * (40.0 / 3.0 * kl).sqrt();
        let r = run(two(&format!(
            "[deployment.latch]\nmodel = \"compliant\"\nstiffness = {kl:?}\ndamping = {cl:?}\nsettle_time = 30.0\n"
        )));
        assert_eq!(r.captures[0].hinge, first.hinge);
        assert!((r.captures[0].time - first.time).abs() < 1e-9 * first.time);
        let (rates, e) = at(&r);
        let err = rates
            .iter()
            .zip(&rates_r)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        errors.push((kl, err, (e - e_r).abs() / e_r));
    }
    for w in errors.windows(2) {
        assert!(w[1].1 < w[0].1, "rates do not converge: {errors:?}");
        assert!(w[1].2 < w[0].2, "energy does not converge: {errors:?}");
    }
    let order = (errors[2].1 / errors[3].1).log10();
    assert!(order > 0.9, "observed order {order} in k_L: {errors:?}");
    assert!(errors[3].1 < 0.02 * rates_r.iter().fold(0.0_f64, |a, x| a.max(x.abs())));
}

/// The mast case with latches k_L = 1e4 N·m/rad, c_L = 200 N·m·s/rad, sampled at 1 kHz for
/// 6 s.
fn planar_compliant_case() -> String {
    planar_compliant("", 6.0, 1000.0, 1.0e4, 200.0)
}

/// Compliant latches on the free hub with the elastic mast: the coupled model
/// (`simulate_coupled`: minimal coordinates, the base by its floating-frame Ritz model,
/// adaptive integration with event location) and the independent maximal-coordinate
/// formulation of `coupled_maximal` (panels as free rigid bodies held by hinge constraints
/// with Lagrange multipliers, the mast's kinetic energy over Gauss particles, fixed-step
/// Gauss–Legendre collocation, the capture located by bisection of the step, its own
/// latch-moment law) agree on the capture order, the capture times and the rates at each
/// capture, and on the latch moment −k_L (α − α^L) − c_L α̇ of every hinge at every common
/// 1 kHz output time (each formulation evaluates it at that exact instant, so the peak is
/// compared where it is, not as sampled by one side), hence on its peak (and on the hinge
/// angles there); and on the mast root moment at those times and its peak, which the coupled
/// model takes from the momentum rates of everything outboard of the root and the second
/// formulation from the hub's own equations (−I_h θ̈ + (R − O) × m_h a_O). Both use the same
/// mast function space (Legendre rod/bending Ritz functions, axial 2, bending 4).
#[test]
fn compliant_latches_agree_with_the_maximal_coordinate_formulation() {
    let sc = Scenario::from_toml_str(&planar_compliant_case(), "planar.toml").unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let (_, r) = simulate_coupled(&sc.structure, d).unwrap();
    let mut case = super::coupled_maximal::reference_case();
    case.axial_terms = 2;
    case.bending_terms = 4;
    case.end_time = d.end_time;
    case.compliant = Some(super::coupled_maximal::CompliantLatch {
        stiffness: vec![1.0e4; 3],
        damping: vec![200.0; 3],
        settle_time: 1.0,
    });
    let h = super::coupled_maximal::default_step(&case);
    let times: Vec<f64> = r
        .samples
        .iter()
        .map(|s| s.t)
        .filter(|t| ((t * d.output_rate).round() / d.output_rate - t).abs() < 1e-12)
        .collect();
    let m = super::coupled_maximal::solve_planar_sampled(&case, h, &times);
    let order = |c: &[(usize, f64)]| c.iter().map(|x| x.0).collect::<Vec<_>>();
    let theirs: Vec<(usize, f64)> = r.captures.iter().map(|c| (c.hinge, c.time)).collect();
    let mine: Vec<(usize, f64)> = m.captures.iter().map(|c| (c.hinge, c.time)).collect();
    assert!(theirs.len() >= 2, "captures {theirs:?}");
    assert_eq!(order(&theirs), order(&mine), "{theirs:?} vs {mine:?}");
    let mut worst_time = 0.0f64;
    let mut worst_rate = 0.0f64;
    for (a, b) in r.captures.iter().zip(&m.captures) {
        let rel = (a.time - b.time).abs() / b.time;
        worst_time = worst_time.max(rel);
        let scale = b.rates.iter().fold(0.0f64, |x, y| x.max(y.abs()));
        for (x, y) in a.rates.iter().zip(&b.rates) {
            worst_rate = worst_rate.max((x - y).abs() / scale);
        }
    }
    assert_eq!(r.final_time, m.final_time.min(r.final_time));
    assert_eq!(times.len(), m.samples.len());
    let peak = |f: &dyn Fn(usize) -> Vec<f64>| {
        (0..3)
            .map(|j| f(j).iter().fold(0.0f64, |a, x| a.max(x.abs())))
            .collect::<Vec<_>>()
    };
    let theirs_on_grid: Vec<_> = r.samples.iter().filter(|s| times.contains(&s.t)).collect();
    let peak_theirs = peak(&|j| theirs_on_grid.iter().map(|s| s.latch_moment[j]).collect());
    let peak_mine = peak(&|j| m.samples.iter().map(|s| s.latch_moment[j]).collect());
    let top = peak_mine.iter().fold(0.0f64, |a, x| a.max(*x));
    assert!(top > 1.0, "latch moments {peak_mine:?}");
    let mut worst_moment = 0.0f64;
    let mut worst_alpha = 0.0f64;
    for (a, b) in theirs_on_grid.iter().zip(&m.samples) {
        assert_eq!(a.t, b.t);
        for j in 0..3 {
            worst_moment = worst_moment.max((a.latch_moment[j] - b.latch_moment[j]).abs() / top);
            worst_alpha = worst_alpha.max((a.alpha[j] - b.alpha[j]).abs());
        }
    }
    let worst_peak = peak_theirs
        .iter()
        .zip(&peak_mine)
        .filter(|(_, b)| **b > 0.0)
        .map(|(a, b)| (a - b).abs() / b)
        .fold(0.0f64, f64::max);
    // The mast root moment about the deployment plane's normal (hub z): theirs from the
    // momentum rates of everything outboard of the root, mine from the hub's equations.
    let root_theirs: Vec<f64> = theirs_on_grid
        .iter()
        .map(|s| {
            s.body
                .as_ref()
                .expect("coupled samples carry the body")
                .root_loads[0][5]
        })
        .collect();
    let root_mine: Vec<f64> = m.samples.iter().map(|s| s.root_moment).collect();
    let root_peak = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let (rp_theirs, rp_mine) = (root_peak(&root_theirs), root_peak(&root_mine));
    assert!(rp_mine > 1.0, "root moment peak {rp_mine}");
    let worst_root = root_theirs
        .iter()
        .zip(&root_mine)
        .map(|(a, b)| (a - b).abs() / rp_mine)
        .fold(0.0f64, f64::max);
    let worst_root_peak = (rp_theirs - rp_mine).abs() / rp_mine;
    println!(
        "h = {h:.3e}; captures {theirs:?} vs {mine:?}: time rel {worst_time:.1e}, rates \
         {worst_rate:.1e}; peaks {peak_theirs:?} vs {peak_mine:?}: rel {worst_peak:.1e}; \
         moment at {} samples {worst_moment:.1e} of the peak, α {worst_alpha:.1e} rad; \
         root moment peak {rp_theirs:.6e} vs {rp_mine:.6e} (rel {worst_root_peak:.1e}), \
         at the samples {worst_root:.1e} of the peak",
        times.len()
    );
    assert!(
        worst_root_peak <= 1e-6 && worst_root <= 1e-6,
        "mast root moment: peak rel {worst_root_peak:.1e}, samples {worst_root:.1e}"
    );
    assert!(worst_time <= 1e-8, "capture times: rel {worst_time:.1e}");
    assert!(worst_rate <= 1e-6, "capture rates: rel {worst_rate:.1e}");
    assert!(
        worst_peak <= 1e-6,
        "peak latch moments: rel {worst_peak:.1e}"
    );
    assert!(
        worst_moment <= 1e-6,
        "latch moments: {worst_moment:.1e} of the peak"
    );
    assert!(worst_alpha <= 1e-8, "hinge angles: {worst_alpha:.1e} rad");
}

/// The latch period that paces the settling, against closed forms at the straight latch
/// configuration, base held. seed_compliant's three equal panels (m = 150 kg, l = 5 m) tied
/// by the ideal cable (α̇ = (1, 2, 2) ṡ): the panels turn by ∓ṡ in turn and their centres
/// move at 2.5 ṡ each, so T = ½ (3 m (l/2)² + 3 m l²/12) ṡ² = ½ m l² ṡ² against
/// V = ½ (1 + 4 + 4)(k + k_L) s²: ω² = 9 (k + k_L) / (m l²). One panel alone:
/// ω² = (k + k_L) / (m l²/3).
#[test]
fn the_latch_period_is_the_captured_arrays_slowest_mode() {
    use flexcraft::deploy::coupled::Synchronisation;
    use flexcraft::deploy::latch_period;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/seed_compliant.toml");
    let sc = Scenario::from_toml_str(&std::fs::read_to_string(path).unwrap(), path).unwrap();
    let d = sc.deployment.as_ref().unwrap();
    let c = d.coupled(&sc.structure).unwrap();
    let kl = &c.latch.as_ref().unwrap().stiffness;
    let (m, l) = (c.chain.panels[0].mass, c.chain.panels[0].length);
    let k = c.chain.hinges[0].stiffness;
    assert!((m - 150.0).abs() < 1e-9 && (l - 5.0).abs() < 1e-12);
    let two_pi = 2.0 * std::f64::consts::PI;
    let cable = two_pi * (m * l * l / (9.0 * (k + kl[0]))).sqrt();
    let w = latch_period(&c.chain, kl, Synchronisation::IdealCable);
    assert!((w - cable).abs() < 1e-12 * cable, "{w} vs {cable}");
    // Without the cable the slowest mode is that of the whole array on its three latches: the
    // straight chain of rigid panels (hub held) linearised here in absolute angles θ_j — the
    // centre of panel j moves across by Σ_{i<j} l_i θ̇_i + (l_j/2) θ̇_j, so
    // M_ik = Σ_j m_j c_ji c_jk + δ_ik I_j (c_ji = l_i for i < j, l_j/2 for i = j), and the
    // hinge and latch springs act on the relative angles, V = ½ Σ_i (k_i + k_L,i)(θ_i − θ_{i−1})²
    // — its lowest root of det(K − ω²M) = 0 found by scanning and bisection.
    let n = c.chain.panels.len();
    let coef = |j: usize, i: usize| -> f64 {
        let l = c.chain.panels[i].length;
        if i < j {
            l
        } else if i == j {
            l / 2.0
        } else {
            0.0
        }
    };
    let mm: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|k| {
                    let own = if i == k {
                        c.chain.panels[i].inertia
                    } else {
                        0.0
                    };
                    own + (0..n)
                        .map(|j| c.chain.panels[j].mass * coef(j, i) * coef(j, k))
                        .sum::<f64>()
                })
                .collect()
        })
        .collect();
    let spring = |i: usize| c.chain.hinges[i].stiffness + kl[i];
    let kk: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|k| {
                    let mut v = 0.0;
                    if i == k {
                        v += spring(i) + if i + 1 < n { spring(i + 1) } else { 0.0 };
                    }
                    if k == i + 1 {
                        v -= spring(k);
                    }
                    if i == k + 1 {
                        v -= spring(i);
                    }
                    v
                })
                .collect()
        })
        .collect();
    assert_eq!(n, 3);
    let det = |w2: f64| {
        let a = |i: usize, k: usize| kk[i][k] - w2 * mm[i][k];
        a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1))
            - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
            + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0))
    };
    let (mut lo, mut step) = (0.0, 1e-6 * spring(0) / mm[0][0]);
    while det(lo + step).signum() == det(lo).signum() {
        lo += step;
        step *= 1.01;
    }
    let mut hi = lo + step;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if det(mid).signum() == det(lo).signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let chain = two_pi / (0.5 * (lo + hi)).sqrt();
    let free = latch_period(&c.chain, kl, Synchronisation::None);
    assert!((free - chain).abs() < 1e-9 * chain, "{free} vs {chain}");
    // Slower than one panel alone on its latch.
    let alone = two_pi * (m * l * l / 3.0 / (k + kl[0])).sqrt();
    assert!(free > alone, "{free} vs one panel's {alone}");
}

/// The hand-over after compliant latches reports the latch springs' energy,
/// ½ Σ k_L,j (α_j − α_j^L)² at the deployment's final state, and carries it: the deployed
/// wing stands on its latch lines (docs/theory.md §1.6), so the energy handed over — kinetic,
/// the base's elastic energy and the lines' (latch and hinge springs about the latched
/// rest, within 5 % of the latch springs' alone here) — is what the response starts with, to
/// the projection's residual (below 1e-3 of it; measured 3e-9 on seed_compliant). The run
/// ends one latch period after the last capture (`Settled::HandedOver`), however lightly the
/// latches are damped.
#[test]
fn the_hand_over_carries_the_latch_springs() {
    use flexcraft::deploy::Settled;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/seed_compliant.toml");
    let src = std::fs::read_to_string(path).unwrap();
    for damping in ["2236.0", "22.36"] {
        let text = src.replace("damping = 2236.0", &format!("damping = {damping}"));
        let sc = Scenario::from_toml_str(&text, path).unwrap();
        let sim = flexcraft::simulation::Simulation::run(&sc).unwrap();
        let h = &sim.response.as_ref().unwrap().handover;
        let l = sim.coupled.latch.as_ref().unwrap();
        let off = sim.coupled.alpha_offset();
        let expected: f64 = (0..sim.coupled.panels())
            .map(|j| {
                let d = sim.deployment.final_q[off + j] - sim.coupled.chain.hinges[j].latch_angle;
                0.5 * l.stiffness[j] * d * d
            })
            .sum();
        assert!(
            (h.latch_energy - expected).abs() <= 1e-12 * expected.max(1e-300),
            "{} vs {expected}",
            h.latch_energy
        );
        assert!(h.latch_carried && expected > 0.0);
        assert_eq!(h.settled, Some(Settled::HandedOver));
        let before = h.energy_before + h.elastic_energy_before + h.lines_energy;
        let after = h.energy_after + h.elastic_energy_after;
        assert!(
            (before - after).abs() < 1e-3 * before,
            "damping {damping}: {before} J before, {after} J after"
        );
        // Without the latch lines' share the books would not close by far more; the lines
        // hold the latch springs' energy and the hinge springs' about the latched rest.
        assert!(
            h.lines_energy > 10.0 * (before - after).abs(),
            "damping {damping}"
        );
        assert!(
            (h.lines_energy - h.latch_energy).abs() < 0.05 * h.latch_energy,
            "{} vs {}",
            h.lines_energy,
            h.latch_energy
        );
    }
}

/// The deployed wing on its compliant latches (docs/theory.md §1.6) against a second
/// formulation: three unequal panels of a very stiff plate (D = 1e9 N·m, its own bending
/// above 1 kHz) on a held hub, latch springs 300 / 200 / 120 N·m/rad plus the hinge springs,
/// the hinges independent, tied by an ideal cable, or by an elastic one. The Ritz model's
/// lowest frequencies are the linearised planar chain's on the same springs and cable
/// (`timescales::array_frequencies`: rigid panels, the mass matrix from the panels' masses and
/// inertias; one frequency on the ideal cable's one motion) to 1e-6 — the rest is the
/// plate's compliance, (ω_latch/ω_plate)².
#[test]
fn the_deployed_wing_stands_on_its_latch_springs() {
    use flexcraft::deploy::coupled::Synchronisation;
    for (sync, key) in [
        (Synchronisation::None, "synchronisation = \"none\""),
        (Synchronisation::IdealCable, "synchronisation = \"cable\""),
        (
            Synchronisation::ElasticCable(150.0),
            "synchronisation = \"cable\"\ncable_stiffness = 150.0",
        ),
    ] {
        let src = held_wing(
            1e9,
            &format!("{key}\nend_time = 60.0"),
            "stiffness = [300.0, 200.0, 120.0]\ndamping = 1.0",
        );
        let sc = Scenario::from_toml_str(&src, "held.toml").unwrap();
        let d = sc.deployment.as_ref().unwrap();
        assert_eq!(d.synchronisation, sync);
        let lines = sc.structure.plates()[0].hinges();
        assert_eq!(
            lines.iter().map(|l| l.at).collect::<Vec<_>>(),
            vec![0.0, 1.5, 4.0]
        );
        let model = flexcraft::ritz::RitzModel::assemble(&sc.structure);
        let modal = flexcraft::ritz::ModalAnalysis::compute(&model).unwrap();
        let latched: Vec<f64> = d.chain.hinges.iter().map(|h| h.latch_angle).collect();
        let chain_w = flexcraft::deploy::timescales::array_frequencies(
            &d.chain,
            &latched,
            &[300.0, 200.0, 120.0],
            sync,
            &[],
        );
        let expect = if sync == Synchronisation::IdealCable {
            1
        } else {
            3
        };
        assert_eq!(chain_w.len(), expect, "{sync:?}");
        let ritz_w: Vec<f64> = modal
            .modes
            .iter()
            .filter(|m| m.omega_rad_s > 1e-6)
            .map(|m| m.omega_rad_s)
            .collect();
        for (a, b) in ritz_w.iter().zip(&chain_w) {
            assert!(
                (a - b).abs() < 1e-6 * b,
                "{sync:?}: Ritz {:?} vs chain {chain_w:?}",
                &ritz_w[..4]
            );
        }
        // Everything else is the plate's own bending, far above.
        assert!(ritz_w[expect] > 100.0 * chain_w[expect - 1], "{sync:?}");
    }
}

/// The hand-over to the deployed wing on its latch lines (docs/theory.md §1.6) against the
/// deployment going on: three unequal panels (stiff plate, D = 1e7 N·m) on a held hub, latch
/// springs 3e4 / 2e4 / 1.2e4 N·m/rad, independent hinges. Run A hands over 0.5 s after the
/// last capture and follows 2 s of response (the linear modal model: elastic plate, latch
/// springs as hinge lines, their dashpots as modal damping); run B keeps integrating the
/// nonlinear chain of rigid panels 2.5 s after the last capture. Over those 2 s every latch
/// moment agrees to 5 % of its peak and each peak to 1 % — two formulations that share
/// nothing after the hand-over but the latch law. A wrong sign of a kink, a lost latch
/// spring's energy or hinge lines at the wrong place (the panels are unequal) fails it.
#[test]
fn the_response_goes_on_as_the_latched_deployment_does() {
    let base = held_wing(
        1e7,
        "synchronisation = \"none\"\nend_time = 200.0\noutput_rate = 400.0",
        "stiffness = [3.0e4, 2.0e4, 1.2e4]\ndamping = 3.0\nSETTLE",
    ) + "[response]\nduration = 2.0\noutput_rate = 400.0\n";
    let a =
        Scenario::from_toml_str(&base.replace("SETTLE", "settle_time = 0.5"), "a.toml").unwrap();
    let b =
        Scenario::from_toml_str(&base.replace("SETTLE", "settle_time = 2.5"), "b.toml").unwrap();
    let sim = flexcraft::simulation::Simulation::run(&a).unwrap();
    let resp = sim.response.as_ref().expect("every hinge captured");
    assert!(resp.handover.latch_carried);
    let (_, rb) = simulate_coupled(&b.structure, b.deployment.as_ref().unwrap()).unwrap();
    let t0 = resp.handover.latch_time;
    for k in 0..3 {
        let col = (resp.channels.iter())
            .position(|c| c.name == format!("latch_moment_{}", k + 1))
            .unwrap();
        // B's samples at A's times (both at 400 Hz from different origins): cubic Lagrange.
        let tb: Vec<f64> = rb.samples.iter().map(|s| s.t).collect();
        let at = |t: f64| -> f64 {
            let i = tb.partition_point(|&x| x < t).clamp(2, tb.len() - 2);
            let (xs, ys): (Vec<f64>, Vec<f64>) = (i - 2..i + 2)
                .map(|j| (tb[j], rb.samples[j].latch_moment[k]))
                .unzip();
            (0..4)
                .map(|p| {
                    ys[p]
                        * (0..4)
                            .filter(|&q| q != p)
                            .map(|q| (t - xs[q]) / (xs[p] - xs[q]))
                            .product::<f64>()
                })
                .sum()
        };
        let (mut peak_a, mut peak_b, mut worst) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (i, &t) in resp.history.times.iter().enumerate() {
            let t = t0 + t;
            if t > tb[tb.len() - 3] {
                break;
            }
            let (va, vb) = (resp.history.values[(i, col)], at(t));
            peak_a = peak_a.max(va.abs());
            peak_b = peak_b.max(vb.abs());
            worst = worst.max((va - vb).abs());
        }
        assert!(
            peak_b > 50.0,
            "hinge {}: the latch rings ({peak_b} N·m)",
            k + 1
        );
        assert!(
            worst < 0.05 * peak_b && (peak_a - peak_b).abs() < 0.01 * peak_b,
            "hinge {}: response vs deployment: largest difference {worst:.3e} N·m, peaks \
             {peak_a:.4e} vs {peak_b:.4e} N·m",
            k + 1
        );
    }
}

/// A wing of three unequal panels (1.5, 2.5, 2 m; plate stiffness `d` N·m) on a held hub,
/// hinge springs 1 N·m/rad preloaded 0.2 rad, compliant latches: `deployment` and `latch`
/// are the lines of those tables beyond the common ones.
fn held_wing(d: f64, deployment: &str, latch: &str) -> String {
    format!(
        r#"
name = "held wing on compliant latches"
[hub]
motion = "fixed"
mass = 1000.0
inertia = [1000.0, 1000.0, 1000.0]
center_of_mass = [0.0, 0.0, 0.0]
[[plates]]
name = "wing"
parent = "hub"
root = [0.0, 0.0, 0.0]
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = 6.0
width = 2.0
areal_density = 5.0
bending_stiffness = {d:e}
poisson_ratio = 0.3
terms = {{ length = 6, width = 4 }}
[deployment]
plate = "wing"
panel_lengths = [1.5, 2.5, 2.0]
{deployment}
[deployment.latch]
model = "compliant"
{latch}
[deployment.hinge]
stiffness = 1.0
preload_angle = 0.2
damping = 0.0
friction = 0.0
"#
    )
}

/// The latch lines' rest rotations (`LineHinge::rest`: where the latches hold the hinge
/// springs' preload, and the cable ties the hinges) against the deployment itself come to
/// rest: a held wing of three unequal panels, heavily damped latches of unequal stiffness
/// (ζ ≈ 0.6 on the slowest latch mode, the whole wing about its root at 0.5 rad/s), run
/// 120 s past the last capture. Its final angles off the latch angles, as line
/// rotations d_j (α_j − α_j^L), are the rest rotations — independent hinges, an ideal cable
/// (one tied motion: not each hinge's own equilibrium) and an elastic one — to 1e-6 of the
/// largest (the run's own decay and tolerance).
#[test]
fn the_latch_lines_rest_where_the_deployment_comes_to_rest() {
    for sync in [
        "synchronisation = \"none\"",
        "synchronisation = \"cable\"",
        "synchronisation = \"cable\"\ncable_stiffness = 150.0",
    ] {
        let src = held_wing(
            1e7,
            &format!("{sync}\nend_time = 400.0"),
            "stiffness = [300.0, 200.0, 120.0]\ndamping = 600.0\nsettle_time = 120.0",
        );
        let sc = Scenario::from_toml_str(&src, "held.toml").unwrap();
        let (c, r) = simulate_coupled(&sc.structure, sc.deployment.as_ref().unwrap()).unwrap();
        assert!(r.all_latched, "{sync}");
        let lines = sc.structure.plates()[0].hinges();
        let off = c.alpha_offset();
        let largest = lines.iter().fold(0.0_f64, |m, l| m.max(l.rest.abs()));
        assert!(largest > 1e-4, "{sync}: a preload to hold ({largest} rad)");
        for (j, (h, l)) in c.chain.hinges.iter().zip(lines).enumerate() {
            let d = if j % 2 == 0 { -1.0 } else { 1.0 };
            let theta = d * (r.final_q[off + j] - h.latch_angle);
            assert!(
                (theta - l.rest).abs() < 1e-6 * largest,
                "{sync}: hinge {}: at rest {theta:e} rad, line rest {:e} rad",
                j + 1,
                l.rest
            );
        }
    }
}
