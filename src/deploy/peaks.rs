//! Peaks of load magnitudes between the output samples.
//!
//! A latch-up load peaks within a fraction of the latch's period, which the output rate
//! need not resolve, so the run observes every tracked magnitude at every accepted step's
//! end (the explicit and implicit integrators resolve the motion there; the adiabatic one,
//! whose steps do not resolve the ringing, adds points inside its steps during a latch-up,
//! `super::run`) and at every sample and event. Where the
//! three latest observations of a magnitude rise and fall, the peak between them is the
//! vertex of the parabola through them (error O(h³) for a smooth magnitude against O(h²)
//! for the largest observation alone). A latch or a capture changes the loads abruptly; the
//! run breaks the history there so that no parabola spans the jump.

/// A peak magnitude and its time (s from release).
pub type Peak = (f64, f64);

/// Running peaks of a fixed number of magnitudes.
#[derive(Debug, Clone, Default)]
pub struct PeakTracker {
    /// The latest two observations of each magnitude since the last break.
    recent: Vec<Vec<(f64, f64)>>,
    best: Vec<Peak>,
}

impl PeakTracker {
    /// Observes the magnitudes `values` at time t (later than every earlier observation, or
    /// equal to the last one across a break).
    pub fn observe(&mut self, t: f64, values: &[f64]) {
        if self.best.len() != values.len() {
            self.best = vec![(0.0, 0.0); values.len()];
            self.recent = vec![Vec::new(); values.len()];
        }
        for ((&v, best), recent) in values.iter().zip(&mut self.best).zip(&mut self.recent) {
            if recent.last().is_some_and(|p| p.0 >= t) {
                continue;
            }
            let mut candidate = (v, t);
            if let [p0, p1] = recent.as_slice() {
                if p1.1 >= p0.1 && p1.1 >= v {
                    if let Some(vertex) = parabola_peak(*p0, *p1, (t, v)) {
                        candidate = (vertex.1, vertex.0);
                    }
                }
            }
            if candidate.0 > best.0 {
                *best = candidate;
            }
            if recent.len() == 2 {
                recent.remove(0);
            }
            recent.push((t, v));
        }
    }

    /// Forgets the history (a jump follows); the peaks found so far stay.
    pub fn break_history(&mut self) {
        self.recent.iter_mut().for_each(Vec::clear);
    }

    /// The peak of every magnitude, (value, time).
    pub fn peaks(&self) -> &[Peak] {
        &self.best
    }
}

/// The vertex (t, v) of the parabola through three points (t increasing) when it is a
/// maximum inside [t₀, t₂]; None otherwise. Newton's divided differences:
/// p(t) = v₀ + d₁(t − t₀) + d₂(t − t₀)(t − t₁), p'(t*) = 0.
pub fn parabola_peak(p0: (f64, f64), p1: (f64, f64), p2: (f64, f64)) -> Option<(f64, f64)> {
    let (t0, v0) = p0;
    let (t1, v1) = p1;
    let (t2, v2) = p2;
    if !(t0 < t1 && t1 < t2) {
        return None;
    }
    let d01 = (v1 - v0) / (t1 - t0);
    let d12 = (v2 - v1) / (t2 - t1);
    let d2 = (d12 - d01) / (t2 - t0);
    if d2 >= 0.0 {
        return None;
    }
    // p'(t) = d01 + d2 (2t − t0 − t1) = 0.
    let ts = 0.5 * (t0 + t1) - d01 / (2.0 * d2);
    if !(t0..=t2).contains(&ts) {
        return None;
    }
    let v = v0 + d01 * (ts - t0) + d2 * (ts - t0) * (ts - t1);
    Some((ts, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_of_an_exact_parabola() {
        // v = 3 − 2 (t − 0.7)², peak 3 at 0.7.
        let f = |t: f64| 3.0 - 2.0 * (t - 0.7) * (t - 0.7);
        let (t, v) = parabola_peak((0.1, f(0.1)), (0.5, f(0.5)), (1.3, f(1.3))).unwrap();
        assert!((t - 0.7).abs() < 1e-14 && (v - 3.0).abs() < 1e-14);
        assert!(parabola_peak((0.0, 0.0), (1.0, 1.0), (2.0, 2.0)).is_none());
    }

    #[test]
    fn sine_peak_between_coarse_observations_is_found_to_third_order() {
        // |sin t| observed every h: the tracked peak's error falls as h³ (about 8× per halving).
        let err = |h: f64| {
            (0..10)
                .map(|k| {
                    let mut tr = PeakTracker::default();
                    let mut t = 0.3 + 0.01 * k as f64;
                    while t < 3.0 {
                        tr.observe(t, &[t.sin()]);
                        t += h;
                    }
                    (1.0 - tr.peaks()[0].0).abs()
                })
                .fold(0.0, f64::max)
        };
        let (e1, e2) = (err(0.2), err(0.1));
        assert!(e1 > 0.0 && e2 > 0.0 && e1 < 2e-3);
        assert!(e1 / e2 > 6.0, "{e1:.3e} / {e2:.3e}");
    }
}
