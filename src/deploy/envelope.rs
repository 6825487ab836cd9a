//! The deployment's plotted quantities as min/max envelopes per plot column, from every
//! point the run computes, not from the output samples (docs/theory.md §3.2).
//!
//! From the first latch-up on, the base's kept modes and the compliant latches ring at up to
//! tens of hertz; a deployment sampled at a few hertz aliases that ringing into a slow beat
//! (a mast ringing at ~20 Hz read at 10 Hz shows a 0.17 Hz oscillation that is not there).
//! Where the output rate is below 2.5 times the fastest vibration the run resolves, the run
//! therefore keeps, per plot column of `[0, end_time]`, the smallest and largest value of
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
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    /// The fastest vibration the run resolves, Hz (what the samples alias).
    pub fastest_hz: f64,
    /// The output rate the samples have, Hz.
    pub output_rate: f64,
    /// The quantities kept.
    pub traces: Vec<Trace>,
    /// The columns span [0, end_time] (`deployment.end_time`: the run may end before it), s.
    pub end_time: f64,
    /// Per trace, per column.
    columns: Vec<Vec<Extremes>>,
}

/// Plot columns of the envelope (the figures are 1 600 px wide at most).
pub const COLUMNS: usize = 2000;

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
        let empty = ((f64::NAN, f64::INFINITY), (f64::NAN, f64::NEG_INFINITY));
        (needed && !traces.is_empty() && end_time > 0.0).then(|| Self {
            fastest_hz,
            output_rate,
            columns: vec![vec![empty; COLUMNS]; traces.len()],
            traces,
            end_time,
        })
    }

    /// Takes in the state `s` the run computed (at `s.t`).
    pub fn observe(&mut self, s: &Sample) {
        let c = ((s.t / self.end_time * COLUMNS as f64).max(0.0) as usize).min(COLUMNS - 1);
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
        // 20 Hz observed at 400 points a second over 10 s, 2 000 columns of 5 ms: every
        // column's extremes lie on the sine, and columns that span a crest reach ±1 to the
        // observation's resolution, where 10 Hz samples would read sin(2π·2k) = 0 throughout.
        let f = 20.0;
        let mut env = Envelope::new(vec![Trace::Rate(0)], 10.0, 10.0, f).expect("aliased");
        for k in 0..=4000 {
            let t = k as f64 / 400.0;
            env.observe(&sample(t, (2.0 * std::f64::consts::PI * f * t).sin()));
        }
        let pts = env.points(Trace::Rate(0)).expect("kept");
        for &(t, v) in &pts {
            assert!((v - (2.0 * std::f64::consts::PI * f * t).sin()).abs() < 1e-9);
        }
        let (hi, _) = env.largest(Trace::Rate(0)).expect("kept");
        let lo = pts.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        // 20 points a period: the best observation within (π/20)²/2 of the crest.
        assert!(hi > 1.0 - 0.013 && lo < -1.0 + 0.013, "{hi} {lo}");
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
