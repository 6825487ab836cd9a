//! The deployment's plotted quantities as min/max envelopes per plot column, from every
//! point the run computes, not from the output samples (docs/theory.md §3.2).
//!
//! From the first latch-up on, the base's kept modes and the compliant latches ring at up to
//! tens of hertz; a deployment sampled at a few hertz aliases that ringing into a slow beat
//! (a mast ringing at ~20 Hz read at 10 Hz shows a 0.17 Hz oscillation that is not there).
//! Where the output rate is below 2.5 times the fastest vibration the run resolves, the run
//! therefore keeps, per plot column of the time it reaches, the smallest and largest value of
//! each plotted quantity over every state it computes — each step's end, the points inside
//! the steps where it observes the loads, every event and every sample — and the figures
//! draw that envelope instead of the samples. The steps resolve the ringing they carry
//! (several points per period of the fastest resolved mode), so the envelope follows the
//! solution to the resolution of its own steps; deployment.csv keeps the samples.

use super::Sample;

/// A plotted quantity of a deployment sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Trace {
    /// Hinge i's opening rate α̇_i, rad/s.
    Rate(usize),
    /// Hinge i's reaction force magnitude (inboard body on panel i), N.
    Reaction(usize),
    /// Hinge i's compliant latch moment, N·m.
    LatchMoment(usize),
    /// Base beam b's root force magnitude, N.
    RootForce(usize),
    /// Base beam b's root moment magnitude, N·m.
    RootMoment(usize),
    /// The base's hub-fixed modal coordinate j, √kg·m.
    Eta(usize),
}

impl Trace {
    /// Its value in `s` (0 where the sample has no such quantity).
    pub fn value(&self, s: &Sample) -> f64 {
        let norm = |l: &[f64]| l.iter().map(|x| x * x).sum::<f64>().sqrt();
        let body = s.body.as_deref();
        match *self {
            Self::Rate(i) => s.rate.get(i).copied().unwrap_or(0.0),
            Self::Reaction(i) => s.force.get(i).map_or(0.0, |f| f[0].hypot(f[1])),
            Self::LatchMoment(i) => s.latch_moment.get(i).copied().unwrap_or(0.0),
            Self::RootForce(b) => body
                .and_then(|b_| b_.root_loads.get(b))
                .map_or(0.0, |l| norm(&l[0..3])),
            Self::RootMoment(b) => body
                .and_then(|b_| b_.root_loads.get(b))
                .map_or(0.0, |l| norm(&l[3..6])),
            Self::Eta(j) => body.and_then(|b_| b_.eta.get(j)).copied().unwrap_or(0.0),
        }
    }
}

/// One column's extremes of one trace: (t, smallest), (t, largest).
type Extremes = ((f64, f64), (f64, f64));

/// The envelope of a run's plotted quantities.
///
/// Its columns are [k w, (k + 1) w) for k < [`COLUMNS`]; the width w starts at
/// end_time / (COLUMNS · 2^[`FINE`]) and doubles (neighbouring columns merged) whenever an
/// observation falls beyond the last column, so that a run that ends long before its
/// `end_time` (a final latch at 30 s of 300 s) still spreads over half the columns at least.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    /// The fastest vibration the run resolves, Hz (what the samples alias).
    pub fastest_hz: f64,
    /// The output rate the samples have, Hz.
    pub output_rate: f64,
    /// The quantities kept.
    pub traces: Vec<Trace>,
    /// The columns' width w, s.
    width: f64,
    /// Per trace, per column.
    columns: Vec<Vec<Extremes>>,
}

/// Plot columns of the envelope (the figures are 1 600 px wide at most).
pub const COLUMNS: usize = 2000;

/// The first columns are 2^FINE times narrower than `end_time / COLUMNS`.
pub const FINE: i32 = 12;

/// An empty column.
const EMPTY: Extremes = ((f64::NAN, f64::INFINITY), (f64::NAN, f64::NEG_INFINITY));

/// The extremes of two columns together (the earlier one's on a tie).
fn merged(a: Extremes, b: Extremes) -> Extremes {
    (
        if b.0 .1 < a.0 .1 { b.0 } else { a.0 },
        if b.1 .1 > a.1 .1 { b.1 } else { a.1 },
    )
}

/// The samples alias a vibration when the output rate is below this many times its
/// frequency.
pub const ALIAS_FACTOR: f64 = 2.5;

impl Envelope {
    /// An empty envelope of `traces` over [0, end_time], or None where the output rate
    /// resolves `fastest_hz` (at least [`ALIAS_FACTOR`] times it) or nothing rings.
    pub fn new(
        traces: Vec<Trace>,
        end_time: f64,
        output_rate: f64,
        fastest_hz: f64,
    ) -> Option<Self> {
        let needed = fastest_hz > 0.0 && output_rate < ALIAS_FACTOR * fastest_hz;
        (needed && !traces.is_empty() && end_time > 0.0).then(|| Self {
            fastest_hz,
            output_rate,
            columns: vec![vec![EMPTY; COLUMNS]; traces.len()],
            traces,
            width: end_time / COLUMNS as f64 / 2f64.powi(FINE),
        })
    }

    /// The columns' current width, s.
    pub fn width(&self) -> f64 {
        self.width
    }

    /// The column of time t (≥ 0) at the current width.
    pub fn column(&self, t: f64) -> usize {
        ((t / self.width).max(0.0) as usize).min(COLUMNS - 1)
    }

    /// Takes in the state `s` the run computed (at `s.t`).
    pub fn observe(&mut self, s: &Sample) {
        // Past the last column: neighbouring columns merged, the width doubled.
        while s.t >= self.width * COLUMNS as f64 && self.width.is_finite() {
            for cols in &mut self.columns {
                for k in 0..COLUMNS / 2 {
                    cols[k] = merged(cols[2 * k], cols[2 * k + 1]);
                }
                cols[COLUMNS / 2..].fill(EMPTY);
            }
            self.width *= 2.0;
        }
        let c = self.column(s.t);
        for (trace, cols) in self.traces.iter().zip(&mut self.columns) {
            let v = trace.value(s);
            if !v.is_finite() {
                continue;
            }
            let slot = &mut cols[c];
            if v < slot.0 .1 {
                slot.0 = (s.t, v);
            }
            if v > slot.1 .1 {
                slot.1 = (s.t, v);
            }
        }
    }

    /// The envelope of `trace` as (t, v) points in time order (each column's smaller and
    /// larger value, in the order they occurred), or None if it is not kept.
    pub fn points(&self, trace: Trace) -> Option<Vec<(f64, f64)>> {
        let k = self.traces.iter().position(|t| *t == trace)?;
        let mut pts = Vec::with_capacity(2 * COLUMNS);
        for &(lo, hi) in &self.columns[k] {
            if lo.1.is_finite() && hi.1.is_finite() {
                let (a, b) = if lo.0 <= hi.0 { (lo, hi) } else { (hi, lo) };
                pts.push(a);
                if b != a {
                    pts.push(b);
                }
            }
        }
        Some(pts)
    }

    /// The largest value of `trace` the envelope holds, and when.
    pub fn largest(&self, trace: Trace) -> Option<(f64, f64)> {
        self.points(trace)?.into_iter().map(|(t, v)| (v, t)).fold(
            None,
            |m: Option<(f64, f64)>, p| match m {
                Some(b) if b.0 >= p.0 => Some(b),
                _ => Some(p),
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, rate: f64) -> Sample {
        Sample {
            t,
            alpha: vec![0.0],
            rate: vec![rate],
            hub: [0.0; 3],
            hub_rate: [0.0; 3],
            force: vec![[0.0, 0.0]],
            moment: vec![0.0],
            kinetic: 0.0,
            spring: 0.0,
            hinges: Vec::new(),
            body: None,
            latch_moment: vec![0.0],
            latch_energy: 0.0,
        }
    }

    #[test]
    fn a_sine_above_the_output_rate_keeps_its_amplitude_in_every_column() {
        // 20 Hz observed at 4 000 points a second over 10 s of a run whose end time is 100 s:
        // the columns narrow to the 10 s reached (width doubled from 100 s / 2000 / 4096 up
        // to between 2.5 and 5 ms: more than 2 000 points). Every column's extremes lie on
        // the sine; a column that spans a crest (or a trough) reaches +1 (−1) to the
        // observations' resolution (200 points a period: 1 − cos(π/200) ≈ 1.2e-4), where
        // 10 Hz samples would read sin(2π·2k) = 0 throughout.
        let f = 20.0;
        let w = 2.0 * std::f64::consts::PI * f;
        let mut env = Envelope::new(vec![Trace::Rate(0)], 100.0, 10.0, f).expect("aliased");
        for k in 0..=40_000 {
            let t = k as f64 / 4000.0;
            env.observe(&sample(t, (w * t).sin()));
        }
        let pts = env.points(Trace::Rate(0)).expect("kept");
        assert!(pts.len() > 2 * COLUMNS / 2, "{} points", pts.len());
        for &(t, v) in &pts {
            assert!((v - (w * t).sin()).abs() < 1e-9);
        }
        // Per column, its extremes against the sine's over the column's span.
        let mut cols = std::collections::BTreeMap::new();
        for &(t, v) in &pts {
            let e = cols
                .entry(env.column(t))
                .or_insert((f64::INFINITY, f64::NEG_INFINITY));
            *e = (e.0.min(v), e.1.max(v));
        }
        let width = env.width();
        assert!(cols.len() >= COLUMNS / 2, "{} columns", cols.len());
        for (&c, &(lo, hi)) in &cols {
            let (a, b) = (c as f64 * width, (c + 1) as f64 * width);
            // A crest t = (1/4 + n)/f or a trough t = (3/4 + n)/f inside (a, b), clear of its
            // ends (a boundary's rounding may put the point at it in the other column).
            let inside = |phase: f64| {
                let n = (a * f - phase + 1e-6).ceil();
                (n + phase) / f < b - 1e-6
            };
            if inside(0.25) {
                assert!(hi > 1.0 - 2e-4, "column {c}: {hi}");
            }
            if inside(0.75) {
                assert!(lo < -1.0 + 2e-4, "column {c}: {lo}");
            }
        }
        assert!(pts.windows(2).all(|w| w[0].0 <= w[1].0));
        assert!(env.points(Trace::Eta(0)).is_none());
    }

    #[test]
    fn no_envelope_where_the_samples_resolve_the_ringing() {
        assert!(Envelope::new(vec![Trace::Rate(0)], 10.0, 50.0, 20.0).is_none());
        assert!(Envelope::new(vec![Trace::Rate(0)], 10.0, 49.0, 20.0).is_some());
        assert!(Envelope::new(vec![Trace::Rate(0)], 10.0, 1.0, 0.0).is_none());
    }
}
