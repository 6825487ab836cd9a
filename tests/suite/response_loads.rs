//! Loads in the response by force summation (`flexcraft::response::loads`): a beam's root
//! moment and shear and a plate's bending moment across a hinge line against the
//! Euler–Bernoulli closed forms, and the hub's momentum balance on a free spacecraft.

use super::common::{bisect, clamped_plate, scenario};
use super::response::{cantilever_tip_impulse, AREA, E, IY, L, RHO};
use flexcraft::deploy::chain::Hinge;
use flexcraft::math::Vec3;
use flexcraft::response::channels::standard_channels;
use flexcraft::response::handover::{modal_velocities, point_impulse};
use flexcraft::response::loads::{beam_root_channels, latch_channels};
use flexcraft::response::{Channel, ChannelKind, ModalResponse, Order, ResponseSettings};
use flexcraft::structure::ComponentId;
use flexcraft::{ModalAnalysis, RitzModel};

/// The n-th clamped–free beam function on ξ ∈ [0, 1] and its β, σ:
/// X = cosh βξ − cos βξ − σ(sinh βξ − sin βξ), σ = (cosh β + cos β)/(sinh β + sin β),
/// cos β cosh β = −1; ∫₀¹ X² dξ = 1. Returns (β, X(1), X''(0)/β², X'''(0)/β³, X''(ξ)/β²).
fn clamped_free(n: usize) -> (f64, f64, f64, f64, impl Fn(f64) -> f64) {
    let guess = (2.0 * n as f64 - 1.0) * std::f64::consts::PI / 2.0;
    let beta = bisect(|b| b.cos() * b.cosh() + 1.0, guess - 0.5, guess + 0.5);
    let sigma = (beta.cosh() + beta.cos()) / (beta.sinh() + beta.sin());
    let x1 = beta.cosh() - beta.cos() - sigma * (beta.sinh() - beta.sin());
    let d2 = move |xi: f64| {
        let b = beta * xi;
        b.cosh() + b.cos() - sigma * (b.sinh() + b.sin())
    };
    (beta, x1, 2.0, -2.0 * sigma, d2)
}

fn channel(channels: &[Channel], name: &str) -> usize {
    channels
        .iter()
        .position(|c| c.name == name)
        .unwrap_or_else(|| panic!("no channel {name}"))
}

/// A cantilever hit at its tip by an impulse P along z: with modes X_n normalised to
/// ∫₀ᴸ X_n² dx = L, w(x, t) = Σ_n P X_n(x) X_n(L) / (ρAL ω_n) · sin ω_n t (Meirovitch,
/// *Fundamentals of Vibrations*, §8), so the moment the hub exerts on the beam about y is
/// EI w''(0, t) and the force along z is EI w'''(0, t) (a static tip load F gives FL and −F).
/// The force-summation channels (momentum rates of the beam) must give the same series.
#[test]
fn cantilever_root_moment_and_shear_match_the_series() {
    let p = 0.01;
    let (model, modal, resp, settings) = cantilever_tip_impulse(p);
    let channels = beam_root_channels(&model);
    let hist = resp.sample(&modal, &channels, &settings);
    let (my, fz) = (
        channel(&channels, "beam_root_my"),
        channel(&channels, "beam_root_fz"),
    );
    let ei = E * IY;
    let scale = (ei / (RHO * AREA * L.powi(4))).sqrt();
    let terms: Vec<(f64, f64, f64)> = (1..=5)
        .map(|n| {
            let (beta, x1, d2, d3, _) = clamped_free(n);
            let w = beta * beta * scale;
            let amp = p * x1 / (RHO * AREA * L * w);
            (
                w,
                amp * ei * d2 * beta.powi(2) / L.powi(2),
                amp * ei * d3 * beta.powi(3) / L.powi(3),
            )
        })
        .collect();
    let series = |t: f64, which: usize| -> f64 {
        terms
            .iter()
            .map(|&(w, m, f)| if which == 0 { m } else { f } * (w * t).sin())
            .sum()
    };
    for (which, c) in [(0, my), (1, fz)] {
        let peak = hist
            .times
            .iter()
            .map(|&t| series(t, which).abs())
            .fold(0.0, f64::max);
        assert!(peak > 1e-3, "peak {peak}");
        for (k, &t) in hist.times.iter().enumerate() {
            let err = (hist.values[(k, c)] - series(t, which)).abs();
            assert!(
                err < 1e-9 * peak,
                "{}: t = {t}: Ritz {} series {} (err/peak {:.2e})",
                channels[c].name,
                hist.values[(k, c)],
                series(t, which),
                err / peak
            );
        }
    }
}

/// A narrow plate with ν = 0 clamped to a fixed hub: its first mode is exactly the
/// clamped–free beam's (w independent of y satisfies the free edges' conditions when ν = 0),
/// with EI = D b. The moment across the line x_k on the outboard strip is then D b w''(x_k),
/// and the latch channel of hinge k reads (−1)^{k+1} of it (hinges with no spring, so no
/// static part).
#[test]
fn plate_hinge_line_moments_match_the_beam_mode() {
    let (a, b, d, mu): (f64, f64, f64, f64) = (4.0, 0.5, 3.0, 2.0);
    let toml = clamped_plate(a, b, d, mu, 0.0, "legendre", 14, 4);
    let s = scenario(&toml);
    let model = RitzModel::assemble(&s.structure);
    let modal = ModalAnalysis::compute(&model).expect("modes");
    let (beta, x1, _, _, d2) = clamped_free(1);
    // The first elastic mode is the beam mode: ω₁ = β² √(D b / (μ b a⁴)).
    let first = modal.elastic().next().expect("an elastic mode");
    let omega = beta * beta * (d / (mu * a.powi(4))).sqrt();
    assert!((first.omega_rad_s - omega).abs() < 1e-9 * omega);
    let hinge = Hinge {
        stiffness: 0.0,
        reference_angle: 0.0,
        damping: 0.0,
        friction: 0.0,
        latch_angle: 1.0,
        initial_angle: 0.0,
        initial_rate: 0.0,
    };
    let mut channels = standard_channels(&model);
    channels.extend(latch_channels(&model, "plate", &[hinge; 3], &[a / 3.0; 3]));
    let settings = ResponseSettings {
        duration: 0.0,
        output_rate: 1.0,
        ..ResponseSettings::default()
    };
    let mut eta0 = vec![0.0; modal.modes.len()];
    eta0[first.number - 1] = 1.0;
    let zero = vec![0.0; eta0.len()];
    let resp = ModalResponse::with_initial(&modal, &eta0, &zero, &settings);
    let hist = resp.sample(&modal, &channels, &settings);
    let tip = hist.values[(0, channel(&channels, "plate_tip_plus"))];
    for k in 1..=3 {
        let xi = (k - 1) as f64 / 3.0;
        let exact = d * b * (beta / a).powi(2) * d2(xi) / x1 * tip;
        let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
        let got = hist.values[(0, channel(&channels, &format!("latch_moment_{k}")))];
        assert!(
            (got - sign * exact).abs() < 1e-9 * exact.abs(),
            "hinge {k}: {got} against {}",
            sign * exact
        );
    }
}

/// Free spacecraft: nothing acts on it from outside, so the hub's momentum rate balances the
/// forces it exerts on the beams rooted on it, m_hub a_hub + Σ F_root = 0, and likewise the
/// moments about the hub's centre of mass (the seed: one mast on the hub).
#[test]
fn free_hub_balances_the_root_loads() {
    let s = scenario(include_str!("../../examples/seed.toml"));
    let model = RitzModel::assemble(&s.structure);
    let modal = ModalAnalysis::compute(&model).expect("modes");
    // Partial mass of everything equals the assembled mass matrix.
    let all = model.partial_mass(|_| true);
    let n = model.dof();
    let scale = (0..n).map(|i| model.mass[(i, i)].abs()).fold(0.0, f64::max);
    for i in 0..n {
        for j in 0..n {
            assert!((all[(i, j)] - model.mass[(i, j)]).abs() <= 1e-12 * scale);
        }
    }
    let b = point_impulse(
        &model,
        ComponentId::Plate(0),
        [15.0, 1.875],
        Vec3::new(0.3, -0.2, 1.0),
    );
    let eta_dot = modal_velocities(&modal, &b);
    let settings = ResponseSettings {
        duration: 2.0,
        output_rate: 100.0,
        ..ResponseSettings::default()
    };
    let resp = ModalResponse::new(&modal, &eta_dot, &settings);
    let mut channels = beam_root_channels(&model);
    // The hub's own momentum rates: rows 0–5 of its mass matrix (about its centre of mass).
    let hub = model.partial_mass(|id| id == ComponentId::Hub);
    for k in 0..6 {
        channels.push(Channel {
            name: format!("hub_{k}"),
            label: String::new(),
            unit: "",
            kind: ChannelKind::HubTranslation,
            row: (0..n).map(|j| hub[(k, j)]).collect(),
            order: Order::Acceleration,
            offset: 0.0,
            rate_row: None,
        });
    }
    let hist = resp.sample(&modal, &channels, &settings);
    let c = s.structure.hub().center_of_mass();
    let root = s.structure.beam_root(0);
    let mut peak = 0.0_f64;
    let mut worst = 0.0_f64;
    for k in 0..hist.times.len() {
        let v = |name: &str| hist.values[(k, channel(&channels, name))];
        let f = Vec3::new(v("mast_root_fx"), v("mast_root_fy"), v("mast_root_fz"));
        let m = Vec3::new(v("mast_root_mx"), v("mast_root_my"), v("mast_root_mz"));
        let hub_f = Vec3::new(v("hub_0"), v("hub_1"), v("hub_2"));
        let hub_m = Vec3::new(v("hub_3"), v("hub_4"), v("hub_5"));
        // The beam exerts −F at its root and −M about it on the hub.
        let about_c = m + (root - c).cross(f);
        peak = peak.max(f.norm()).max(about_c.norm() / 10.0);
        worst = worst
            .max((hub_f + f).norm())
            .max((hub_m + about_c).norm() / 10.0);
    }
    assert!(peak > 1.0, "peak root force {peak}");
    assert!(worst < 1e-11 * peak, "imbalance {worst:.3e} of {peak:.3e}");
}
