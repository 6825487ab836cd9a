//! The largest |v(t)| over an interval of a sum of damped sinusoids, exactly (to a relative
//! 1e-10 of the signal's scale), not read from samples (docs/theory.md §3.2).
//!
//! A channel of the modal superposition is
//!
//!   v(t) = c₀ + c₁ t + Σ_k e^{−σ_k t} (p_k cos ω_k t + q_k sin ω_k t),
//!
//! the rigid modes giving the polynomial part and every elastic mode one wave. Its peak is
//! found by branch and bound on a grid of spacing h₀ = π / (4 ω_max):
//!
//! * on every interval [t₀, t₁] the cubic Hermite interpolant H of v and v′ at the ends
//!   differs from v by at most M₄ h⁴ / 384 (M₄ ≥ |v⁗| on the interval: the interpolation
//!   error (t − t₀)²(t − t₁)² v⁗(ξ)/4!), and its own largest |H| is found from the roots of
//!   the quadratic H′;
//! * an interval whose largest |H| plus that bound cannot beat the best value found is
//!   dropped; the others are halved (v and v′ evaluated in closed form at the midpoint),
//!   which divides the bound by 16, until it is below the tolerance, and v is then evaluated
//!   at the interpolant's maximiser.
//!
//! The result is a value v attains (never an overestimate) within the tolerance of the true
//! maximum, at any sampling of the output. Each wave's derivatives are waves again: with
//! λ = −σ + iω, v = Re(C e^{λt}), C = p − iq, so v⁽ⁿ⁾ = Re(C λⁿ e^{λt}) and
//! |v⁽ⁿ⁾(t)| ≤ |C| |λ|ⁿ e^{−σt}.
//!
//! Hand-written: no crate finds the global extremum of an exponential-trigonometric sum.

/// One damped sinusoid e^{−σt}(p cos ωt + q sin ωt).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wave {
    /// Decay rate σ ≥ 0, 1/s.
    pub sigma: f64,
    /// Angular frequency ω > 0, rad/s.
    pub omega: f64,
    /// Cosine amplitude at t = 0.
    pub p: f64,
    /// Sine amplitude at t = 0.
    pub q: f64,
}

impl Wave {
    /// Its time derivative: e^{−σt}((ωq − σp) cos ωt − (σq + ωp) sin ωt).
    pub fn derivative(&self) -> Self {
        Self {
            p: self.omega * self.q - self.sigma * self.p,
            q: -(self.sigma * self.q + self.omega * self.p),
            ..*self
        }
    }

    /// Value at t.
    pub fn at(&self, t: f64) -> f64 {
        let (s, c) = (self.omega * t).sin_cos();
        (-self.sigma * t).exp() * (self.p * c + self.q * s)
    }

    /// |C| = √(p² + q²): |v(t)| ≤ |C| e^{−σt}.
    pub fn modulus(&self) -> f64 {
        self.p.hypot(self.q)
    }

    /// |λ| = √(σ² + ω²): each derivative multiplies the modulus by it.
    pub fn rate(&self) -> f64 {
        self.sigma.hypot(self.omega)
    }
}

/// v(t) = c₀ + c₁ t + Σ waves.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WaveSum {
    /// c₀.
    pub constant: f64,
    /// c₁, per second.
    pub slope: f64,
    /// The waves.
    pub waves: Vec<Wave>,
}

impl WaveSum {
    /// v(t).
    pub fn at(&self, t: f64) -> f64 {
        self.constant + self.slope * t + self.waves.iter().map(|w| w.at(t)).sum::<f64>()
    }

    /// v′ as a sum of the same kind.
    pub fn derivative(&self) -> Self {
        Self {
            constant: self.slope,
            slope: 0.0,
            waves: self.waves.iter().map(Wave::derivative).collect(),
        }
    }

    /// A bound on |v⁽ⁿ⁾(t)| for every t ≥ t₀ (n ≥ 2: the polynomial part has none).
    pub fn derivative_bound(&self, n: i32, t0: f64) -> f64 {
        self.waves
            .iter()
            .map(|w| w.modulus() * w.rate().powi(n) * (-w.sigma * t0).exp())
            .sum()
    }

    /// The scale of the signal: |c₀| + |c₁| t_end + Σ |C_k| (what "relative" refers to).
    pub fn scale(&self, t_end: f64) -> f64 {
        self.constant.abs()
            + self.slope.abs() * t_end
            + self.waves.iter().map(Wave::modulus).sum::<f64>()
    }

    /// The fastest wave's ω (0 without waves).
    pub fn fastest(&self) -> f64 {
        self.waves.iter().map(|w| w.rate()).fold(0.0, f64::max)
    }
}

/// Several signals whose waves share their (σ, ω), wave by wave (the channels of one modal
/// superposition: wave k is mode k's in each), evaluated together: the modes' e^{−σt}cos ωt
/// and e^{−σt}sin ωt once per time, then each signal as a dot product — one `sin_cos` per
/// mode instead of one per mode and signal.
#[derive(Debug, Clone)]
pub struct Bank<'a> {
    signals: Vec<&'a WaveSum>,
    /// (σ, ω) of wave k, shared by every signal.
    modes: Vec<(f64, f64)>,
}

impl<'a> Bank<'a> {
    /// The bank of `signals`, or None if their waves do not share (σ, ω) wave by wave.
    pub fn new(signals: Vec<&'a WaveSum>) -> Option<Self> {
        let modes: Vec<(f64, f64)> = signals
            .first()
            .map(|s| s.waves.iter().map(|w| (w.sigma, w.omega)).collect())
            .unwrap_or_default();
        let shared = signals.iter().all(|s| {
            s.waves.len() == modes.len()
                && s.waves
                    .iter()
                    .zip(&modes)
                    .all(|(w, m)| w.sigma == m.0 && w.omega == m.1)
        });
        shared.then_some(Self { signals, modes })
    }

    /// Every signal's (v(t), v′(t)) into `out` (one entry per signal).
    pub fn at(&self, t: f64, out: &mut [(f64, f64)]) {
        debug_assert_eq!(out.len(), self.signals.len());
        for (o, s) in out.iter_mut().zip(&self.signals) {
            *o = (s.constant + s.slope * t, s.slope);
        }
        for (k, &(sigma, omega)) in self.modes.iter().enumerate() {
            let (sn, cs) = (omega * t).sin_cos();
            let d = (-sigma * t).exp();
            let (c, s_) = (d * cs, d * sn);
            for (o, sig) in out.iter_mut().zip(&self.signals) {
                let w = &sig.waves[k];
                // v = p c + q s; v′ = (ωq − σp) c − (σq + ωp) s.
                o.0 += w.p * c + w.q * s_;
                o.1 += (omega * w.q - sigma * w.p) * c - (sigma * w.q + omega * w.p) * s_;
            }
        }
    }
}

/// The kept intervals' count at which a search first drops those the best has overtaken.
const PRUNE_AT: usize = 4096;

/// The relative tolerance of [`peak`], against [`WaveSum::scale`].
pub const TOLERANCE: f64 = 1e-10;

/// The grid spacing of the first pass, as a fraction of π / ω_max.
pub const GRID_FRACTION: f64 = 0.25;

/// The deepest halving of one grid interval (each divides the bound by 16).
const MAX_DEPTH: usize = 24;

/// A point of the signal: (t, v, v′).
pub type Knot = (f64, f64, f64);

/// The running maximum of |v| and where.
#[derive(Debug, Clone, Copy)]
struct Best {
    value: f64,
    time: f64,
}

impl Best {
    fn offer(&mut self, t: f64, v: f64) {
        if v.abs() > self.value {
            self.value = v.abs();
            self.time = t;
        }
    }
}

/// A cheap bound on the largest |H| of the cubic Hermite interpolant through two knots:
/// with H = v₀h₀₀ + v₁h₀₁ + h(v₀′h₁₀ + v₁′h₁₁), h₀₀ + h₀₁ = 1, both ≥ 0, and |h₁₀|, |h₁₁| ≤ 4/27,
/// |H| ≤ max(|v₀|, |v₁|) + (4/27) h (|v₀′| + |v₁′|).
pub fn hermite_bound(a: Knot, b: Knot) -> f64 {
    a.1.abs().max(b.1.abs()) + 4.0 / 27.0 * (b.0 - a.0) * (a.2.abs() + b.2.abs())
}

/// The largest |H| of the cubic Hermite interpolant through two knots, and where.
pub fn hermite_max(a: Knot, b: Knot) -> (f64, f64) {
    let h = b.0 - a.0;
    let mut best = if a.1.abs() >= b.1.abs() {
        (a.1.abs(), a.0)
    } else {
        (b.1.abs(), b.0)
    };
    if h <= 0.0 {
        return best;
    }
    // H(s) = v₀ h₀₀ + h v₀′ h₁₀ + v₁ h₀₁ + h v₁′ h₁₁ on s ∈ [0, 1]; as c₀ + c₁s + c₂s² + c₃s³.
    let (v0, d0, v1, d1) = (a.1, a.2 * h, b.1, b.2 * h);
    let c1 = d0;
    let c2 = 3.0 * (v1 - v0) - 2.0 * d0 - d1;
    let c3 = 2.0 * (v0 - v1) + d0 + d1;
    let value = |s: f64| v0 + s * (c1 + s * (c2 + s * c3));
    // H′(s) = c₁ + 2c₂ s + 3c₃ s².
    let (roots, count) = quadratic_roots(3.0 * c3, 2.0 * c2, c1);
    for &s in &roots[..count] {
        if s > 0.0 && s < 1.0 {
            let v = value(s).abs();
            if v > best.0 {
                best = (v, a.0 + s * h);
            }
        }
    }
    best
}

/// The interior critical points (t, H(t)) of the cubic Hermite interpolant through two
/// knots (its local minima and maxima strictly inside the interval), and how many.
pub fn hermite_critical(a: Knot, b: Knot) -> ([(f64, f64); 2], usize) {
    let h = b.0 - a.0;
    let mut out = [(0.0, 0.0); 2];
    if h <= 0.0 {
        return (out, 0);
    }
    let (v0, d0, v1, d1) = (a.1, a.2 * h, b.1, b.2 * h);
    let c2 = 3.0 * (v1 - v0) - 2.0 * d0 - d1;
    let c3 = 2.0 * (v0 - v1) + d0 + d1;
    let (roots, count) = quadratic_roots(3.0 * c3, 2.0 * c2, d0);
    let mut n = 0;
    for &s in &roots[..count] {
        if s > 0.0 && s < 1.0 {
            out[n] = (a.0 + s * h, v0 + s * (d0 + s * (c2 + s * c3)));
            n += 1;
        }
    }
    (out, n)
}

/// The real roots of a x² + b x + c (of the linear equation when a = 0; none when both
/// vanish), computed without cancellation: the roots and how many there are.
fn quadratic_roots(a: f64, b: f64, c: f64) -> ([f64; 2], usize) {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if scale == 0.0 {
        return ([0.0; 2], 0);
    }
    if a.abs() <= 1e-14 * scale {
        return if b != 0.0 {
            ([-c / b, 0.0], 1)
        } else {
            ([0.0; 2], 0)
        };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return ([0.0; 2], 0);
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q == 0.0 {
        return ([0.0; 2], 1);
    }
    ([q / a, c / q], 2)
}

/// What a [`PeakSearch`] maximises the absolute value of: a signal in closed form, its
/// value and slope at any time, and a bound on its fourth derivative.
pub trait Objective {
    /// (g(t), g′(t)).
    fn at(&self, t: f64) -> (f64, f64);
    /// A bound on |g⁗(t)| for every t in [t₀, t_end].
    fn fourth_bound(&self, t0: f64) -> f64;
    /// The scale the tolerance is relative to.
    fn scale(&self) -> f64;
}

/// One channel: g = v, |g| its magnitude.
#[derive(Debug, Clone)]
pub struct Scalar<'a> {
    v: &'a WaveSum,
    dv: WaveSum,
    t_end: f64,
}

impl<'a> Scalar<'a> {
    /// The signal `v` on [0, t_end].
    pub fn new(v: &'a WaveSum, t_end: f64) -> Self {
        Self {
            v,
            dv: v.derivative(),
            t_end,
        }
    }
}

impl Objective for Scalar<'_> {
    fn at(&self, t: f64) -> (f64, f64) {
        (self.v.at(t), self.dv.at(t))
    }
    fn fourth_bound(&self, t0: f64) -> f64 {
        self.v.derivative_bound(4, t0)
    }
    fn scale(&self) -> f64 {
        self.v.scale(self.t_end)
    }
}

/// A vector of channels (a force's or a moment's components): g = Σ v_c², whose peak is
/// the squared magnitude's. By Leibniz, g⁗ = Σ_c Σ_k C(4,k) v_c⁽ᵏ⁾ v_c⁽⁴⁻ᵏ⁾, bounded with
/// |v⁽ᵏ⁾| ≤ B_k: B₀ = |c₀| + |c₁| t_end + Σ|C|e^{−σt₀}, B₁ = |c₁| + Σ|C||λ|e^{−σt₀},
/// B_k = Σ|C||λ|ᵏe^{−σt₀}.
#[derive(Debug, Clone)]
pub struct SquaredNorm<'a> {
    parts: Vec<Scalar<'a>>,
    /// The components evaluated together when their waves share (σ, ω).
    bank: Option<Bank<'a>>,
}

impl<'a> SquaredNorm<'a> {
    /// The components `vs` on [0, t_end].
    pub fn new(vs: &[&'a WaveSum], t_end: f64) -> Self {
        Self {
            parts: vs.iter().map(|v| Scalar::new(v, t_end)).collect(),
            bank: Bank::new(vs.to_vec()),
        }
    }
}

impl Objective for SquaredNorm<'_> {
    fn at(&self, t: f64) -> (f64, f64) {
        // A force's or a moment's three components on the stack (no allocation per point).
        if let Some(bank) = self.bank.as_ref().filter(|_| self.parts.len() <= 3) {
            let mut buf = [(0.0, 0.0); 3];
            let out = &mut buf[..self.parts.len()];
            bank.at(t, out);
            return out.iter().fold((0.0, 0.0), |(g, dg), (v, dv)| {
                (g + v * v, dg + 2.0 * v * dv)
            });
        }
        self.parts.iter().fold((0.0, 0.0), |(g, dg), p| {
            let (v, dv) = p.at(t);
            (g + v * v, dg + 2.0 * v * dv)
        })
    }
    fn fourth_bound(&self, t0: f64) -> f64 {
        const BINOMIAL: [f64; 5] = [1.0, 4.0, 6.0, 4.0, 1.0];
        self.parts
            .iter()
            .map(|p| {
                let waves = |k: i32| p.v.derivative_bound(k, t0);
                let b = [
                    p.v.constant.abs() + p.v.slope.abs() * p.t_end + waves(0),
                    p.v.slope.abs() + waves(1),
                    waves(2),
                    waves(3),
                    waves(4),
                ];
                (0..5).map(|k| BINOMIAL[k] * b[k] * b[4 - k]).sum::<f64>()
            })
            .sum()
    }
    fn scale(&self) -> f64 {
        self.parts.iter().map(|p| p.scale().powi(2)).sum()
    }
}

/// The search for the largest |g| of an [`Objective`] on [0, t_end], fed its grid's knots
/// (g and g′ at increasing times from 0 to t_end, in consecutive pieces that may share
/// their end knots: a grid the caller may compute faster in bulk, [`grid`]).
#[derive(Debug, Clone)]
pub struct PeakSearch<O> {
    g: O,
    floor: f64,
    best: Best,
    last: Option<Knot>,
    /// Intervals that might hold a larger value: (interpolated estimate, M₄ from their
    /// piece's start on, ends).
    open: Vec<(f64, f64, Knot, Knot)>,
    /// `open`'s length at which it is pruned next (twice what the last pruning left, so
    /// that pruning costs O(1) per interval even when most intervals stay: an undamped
    /// single mode's every crest).
    prune_at: usize,
}

impl<O: Objective> PeakSearch<O> {
    /// A search for the peak of `g`, to [`TOLERANCE`] of its scale.
    pub fn new(g: O) -> Self {
        Self {
            floor: TOLERANCE * g.scale(),
            g,
            best: Best {
                value: 0.0,
                time: 0.0,
            },
            last: None,
            open: Vec::new(),
            prune_at: PRUNE_AT,
        }
    }

    /// The objective, for computing knots.
    pub fn objective(&self) -> &O {
        &self.g
    }

    /// The next knots (the first may repeat the previous piece's last).
    pub fn feed(&mut self, knots: &[Knot]) {
        // |g⁗| is bounded from the piece's start on: the bound there holds for all of it.
        let start = self.last.or(knots.first().copied()).map_or(0.0, |k| k.0);
        let fourth = self.g.fourth_bound(start);
        for &k in knots {
            self.best.offer(k.0, k.1);
            if let Some(a) = self.last {
                if k.0 > a.0 {
                    self.first_pass(a, k, fourth);
                }
            }
            self.last = Some(k);
        }
    }

    /// One grid interval: kept when its interpolant plus the bound might beat the best.
    fn first_pass(&mut self, a: Knot, b: Knot, fourth: f64) {
        let bound = fourth * (b.0 - a.0).powi(4) / 384.0;
        if hermite_bound(a, b) + bound <= self.best.value + self.floor {
            return;
        }
        let (est, at) = hermite_max(a, b);
        if est > self.best.value {
            self.best.offer(at, self.g.at(at).0);
        }
        if est + bound > self.best.value + self.floor {
            self.open.push((est, fourth, a, b));
            if self.open.len() > self.prune_at {
                self.prune();
                self.prune_at = PRUNE_AT.max(2 * self.open.len());
            }
        }
    }

    /// Drops the kept intervals the best has overtaken.
    fn prune(&mut self) {
        let (best, floor) = (self.best.value, self.floor);
        self.open.retain(|(est, fourth, a, b)| {
            *est + fourth * (b.0 - a.0).powi(4) / 384.0 > best + floor
        });
    }

    /// The search over the knots fed to `self` and then those fed to `later` (a search of
    /// the same objective over the next segment of the grid, sharing its first knot with
    /// this one's last): the best of both (this one's on a tie) and both lists of intervals.
    pub fn merge(mut self, later: Self) -> Self {
        if later.best.value > self.best.value {
            self.best = later.best;
        }
        self.open.extend(later.open);
        self.last = later.last.or(self.last);
        self
    }

    /// The peak |g| and its time.
    pub fn finish(mut self) -> (f64, f64) {
        let mut open = std::mem::take(&mut self.open);
        open.sort_by(|x, y| y.0.total_cmp(&x.0));
        for (_, fourth, a, b) in open {
            refine(&self.g, (a, b), fourth, 0, self.floor, &mut self.best);
        }
        (self.best.value, self.best.time)
    }
}

/// Halves [a, b] while it might hold a value above the best by more than `floor` (`fourth`
/// bounds |v⁗| on it).
fn refine(
    g: &dyn Objective,
    (a, b): (Knot, Knot),
    fourth: f64,
    depth: usize,
    floor: f64,
    best: &mut Best,
) {
    let h = b.0 - a.0;
    let (est, at) = hermite_max(a, b);
    let bound = fourth * h.powi(4) / 384.0;
    if est + bound <= best.value + floor {
        return;
    }
    // The leaf's value is within 2·bound of the interval's maximum.
    if 2.0 * bound <= floor || depth >= MAX_DEPTH {
        best.offer(at, g.at(at).0);
        return;
    }
    let tm = 0.5 * (a.0 + b.0);
    let (gm, dgm) = g.at(tm);
    let m = (tm, gm, dgm);
    best.offer(tm, m.1);
    // The half with the larger interpolated value first: it raises the best sooner.
    let (left, right) = (hermite_max(a, m).0, hermite_max(m, b).0);
    if left >= right {
        refine(g, (a, m), fourth, depth + 1, floor, best);
        refine(g, (m, b), fourth, depth + 1, floor, best);
    } else {
        refine(g, (m, b), fourth, depth + 1, floor, best);
        refine(g, (a, m), fourth, depth + 1, floor, best);
    }
}

/// The first pass's uniform grid on [0, t_end], t_k = t_end·k/n (k = 0 … n), never held
/// whole: a long response has t_end·ω_max·4/π knots (7e8 for 1e6 s at 93 Hz, 6 GB as a
/// vector), so its users walk it in pieces ([`Grid::pieces`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// n: the number of intervals (at least one).
    pub intervals: usize,
    /// The end, s.
    pub t_end: f64,
}

impl Grid {
    /// The knots' count, n + 1.
    pub fn len(&self) -> usize {
        self.intervals + 1
    }

    /// Never empty (one interval at least); for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Knot k's time.
    pub fn at(&self, k: usize) -> f64 {
        self.t_end * k as f64 / self.intervals as f64
    }

    /// The spacing, s.
    pub fn spacing(&self) -> f64 {
        self.t_end / self.intervals as f64
    }

    /// The knot ranges [start, end] of consecutive pieces of at most `size` knots (≥ 2) that
    /// share their end knots.
    pub fn pieces(&self, size: usize) -> impl Iterator<Item = (usize, usize)> {
        self.pieces_within((0, self.intervals), size)
    }

    /// [`Grid::pieces`] of the knots `first..=last` only.
    pub fn pieces_within(
        &self,
        (first, last): (usize, usize),
        size: usize,
    ) -> impl Iterator<Item = (usize, usize)> {
        let step = size.max(2) - 1;
        (0..)
            .map(move |i| first + i * step)
            .take_while(move |&start| start < last)
            .map(move |start| (start, (start + step).min(last)))
    }

    /// The knot ranges [start, end] of the grid cut into `count` (at least one) nearly equal
    /// segments that share their end knots: parts a search may walk side by side, fixed by
    /// the grid alone so that results do not depend on the number of threads.
    pub fn segments(&self, count: usize) -> Vec<(usize, usize)> {
        let count = count.clamp(1, self.intervals.max(1));
        (0..count)
            .map(|i| (self.intervals * i / count, self.intervals * (i + 1) / count))
            .collect()
    }
}

/// The first pass's grid on [0, t_end]: spacing at most [`GRID_FRACTION`]·π / ω_max (ω_max
/// the fastest wave's |λ|), at least one interval.
pub fn grid(fastest: f64, t_end: f64) -> Grid {
    let n = if fastest > 0.0 && t_end > 0.0 {
        (t_end * fastest / (GRID_FRACTION * std::f64::consts::PI))
            .ceil()
            .max(1.0)
    } else {
        1.0
    };
    Grid {
        intervals: n as usize,
        t_end,
    }
}

/// The largest |v| on [0, t_end] and its time, evaluating the grid in closed form (one
/// signal; [`PeakSearch`] fed in bulk when many signals share a grid).
pub fn peak(v: &WaveSum, t_end: f64) -> (f64, f64) {
    search_on_grid(Scalar::new(v, t_end), v.fastest(), t_end)
}

/// The largest magnitude √(Σ v_c²) of a vector of signals on [0, t_end] and its time.
pub fn norm_peak(vs: &[&WaveSum], t_end: f64) -> (f64, f64) {
    let fastest = vs.iter().map(|v| v.fastest()).fold(0.0, f64::max);
    let (g, t) = search_on_grid(SquaredNorm::new(vs, t_end), fastest, t_end);
    (g.sqrt(), t)
}

/// [`PeakSearch`] of `g` fed the [`grid`] for `fastest` on [0, t_end] in closed form.
fn search_on_grid<O: Objective>(g: O, fastest: f64, t_end: f64) -> (f64, f64) {
    let mut search = PeakSearch::new(g);
    let grid = grid(fastest, t_end);
    let mut knots: Vec<Knot> = Vec::new();
    for (start, end) in grid.pieces(PIECE) {
        knots.clear();
        knots.extend((start..=end).map(|k| {
            let t = grid.at(k);
            let (g, dg) = search.objective().at(t);
            (t, g, dg)
        }));
        search.feed(&knots);
    }
    search.finish()
}

/// Knots per piece of a grid walked in closed form.
const PIECE: usize = 4096;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_of_a_cubic_is_the_cubic() {
        // v = 1 + 3s − 4s³ on [0, 1]: v′ = 3 − 12s² = 0 at s = 1/2, v = 2.
        let f = |s: f64| 1.0 + 3.0 * s - 4.0 * s.powi(3);
        let d = |s: f64| 3.0 - 12.0 * s * s;
        let (v, t) = hermite_max((0.0, f(0.0), d(0.0)), (1.0, f(1.0), d(1.0)));
        assert!(
            (v - 2.0).abs() < 1e-14 && (t - 0.5).abs() < 1e-14,
            "{v} {t}"
        );
    }

    #[test]
    fn a_bank_evaluates_each_signal_and_its_slope_as_alone() {
        // Three channels of four shared modes: the bank's (v, v′) against each signal's own
        // closed form and a central difference of it; a signal whose waves differ is refused.
        let modes = [(0.0, 3.0), (0.2, 17.0), (0.01, 40.0), (1.5, 91.0)];
        let signal = |k: f64| WaveSum {
            constant: 0.3 * k,
            slope: -0.1 * k,
            waves: modes
                .iter()
                .enumerate()
                .map(|(j, &(sigma, omega))| Wave {
                    sigma,
                    omega,
                    p: (k + j as f64).sin(),
                    q: (2.0 * k - j as f64).cos(),
                })
                .collect(),
        };
        let sigs = [signal(1.0), signal(2.0), signal(3.0)];
        let bank = Bank::new(sigs.iter().collect()).expect("shared modes");
        let mut out = [(0.0, 0.0); 3];
        for t in [0.0, 0.013, 0.7, 2.5] {
            bank.at(t, &mut out);
            for (s, (v, dv)) in sigs.iter().zip(out) {
                let h = 1e-6;
                let fd = (s.at(t + h) - s.at(t - h)) / (2.0 * h);
                assert!((v - s.at(t)).abs() < 1e-13, "{v} {}", s.at(t));
                assert!((dv - s.derivative().at(t)).abs() < 1e-11);
                assert!((dv - fd).abs() < 1e-6 * s.scale(3.0) * 91.0, "{dv} {fd}");
            }
        }
        let mut other = signal(4.0);
        other.waves[2].omega = 41.0;
        assert!(Bank::new(vec![&sigs[0], &other]).is_none());
    }

    #[test]
    fn quadratic_roots_without_cancellation() {
        let (r, n) = quadratic_roots(1.0, -1e8, 1.0);
        let small = r[..n].iter().copied().fold(f64::INFINITY, f64::min);
        assert!(n == 2 && (small - 1e-8).abs() < 1e-22, "{small:e}");
        assert_eq!(quadratic_roots(0.0, 2.0, -1.0), ([0.5, 0.0], 1));
        assert_eq!(quadratic_roots(1.0, 0.0, 1.0).1, 0);
    }
}
