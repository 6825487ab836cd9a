//! Peaks of load magnitudes between the output samples.
//!
//! A latch-up load peaks within a fraction of the latch's period, which the output rate
//! need not resolve, so the run observes every tracked magnitude at every accepted step's
//! end and at every event — never at the output samples, so that no peak depends on them —
//! and, with the named integrators, inside the steps too (each step's midpoint; the
//! adiabatic one, whose steps do not resolve the ringing, more points during a latch-up:
//! `super::run`). Where the three latest observations of a magnitude rise and fall and the
//! vertex of the parabola through them would beat the peak so far, the vertex is a
//! candidate ([`PeakTracker::resolve`]): the run evaluates the solution there from the
//! step's dense output and narrows the bracket by successive parabolic interpolation, so
//! that the peak is a value the solution attains, to the dense output's accuracy. Where the
//! run has no interpolant it trusts (the automatic integrator, whose interpolant overshoots
//! on the stiff parts it lets follow quasi-statically), the vertex stands, capped (error
//! O(h³) for a smooth magnitude against O(h²) for the largest observation alone). A latch
//! or a capture changes the loads abruptly; the run breaks the history there so that no
//! parabola spans the jump.

/// A peak magnitude and its time (s from release).
pub type Peak = (f64, f64);

/// Running peaks of a fixed number of magnitudes.
#[derive(Debug, Clone, Default)]
pub struct PeakTracker {
    /// The latest two observations of each magnitude since the last break.
    recent: Vec<Vec<(f64, f64)>>,
    best: Vec<Peak>,
    /// Brackets (magnitude, three observations rising and falling) whose parabola's vertex
    /// would beat the peak, waiting for [`Self::resolve`].
    pending: Vec<(usize, [(f64, f64); 3])>,
}

/// The most solution evaluations [`PeakTracker::resolve`] makes for one bracket.
pub const REFINEMENTS: usize = 6;

impl PeakTracker {
    /// Observes the magnitudes `values` at time t (later than every earlier observation, or
    /// equal to the last one across a break).
    pub fn observe(&mut self, t: f64, values: &[f64]) {
        if self.best.len() != values.len() {
            self.best = vec![(0.0, 0.0); values.len()];
            self.recent = vec![Vec::new(); values.len()];
        }
        for (i, ((&v, best), recent)) in values
            .iter()
            .zip(&mut self.best)
            .zip(&mut self.recent)
            .enumerate()
        {
            if recent.last().is_some_and(|p| p.0 >= t) {
                continue;
            }
            if v > best.0 {
                *best = (v, t);
            }
            if let [p0, p1] = recent.as_slice() {
                if p1.1 >= p0.1 && p1.1 >= v {
                    if let Some(vertex) = parabola_peak(*p0, *p1, (t, v)) {
                        if vertex.1 > best.0 {
                            self.pending.push((i, [*p0, *p1, (t, v)]));
                        }
                    }
                }
            }
            if recent.len() == 2 {
                recent.remove(0);
            }
            recent.push((t, v));
        }
    }

    /// Resolves the pending brackets: `eval(t)` gives every magnitude at t from the
    /// solution (None where it cannot: the vertex estimate then stands). Each bracket's
    /// vertex is evaluated and the bracket narrowed to the three best points, at most
    /// [`REFINEMENTS`] times, while the vertex could still beat the peak.
    pub fn resolve(&mut self, eval: &mut dyn FnMut(f64) -> Option<Vec<f64>>) {
        for (i, mut tri) in std::mem::take(&mut self.pending) {
            for _ in 0..REFINEMENTS {
                let Some((ts, vs)) = parabola_peak(tri[0], tri[1], tri[2]) else {
                    break;
                };
                let best = &mut self.best[i];
                if vs <= best.0 {
                    break;
                }
                let Some(v) = eval(ts).and_then(|m| m.get(i).copied()) else {
                    // The vertex stands, capped: for evenly spaced points it rises at most
                    // (v₁ − min(v₀, v₂))/8 above the middle one; unevenly spaced points can
                    // put it far above every observation (3.25 from 0, 1, 0.9 at 0, 1,
                    // 1.01), so it is held to twice that.
                    let low = tri[0].1.min(tri[2].1);
                    let vs = vs.min(tri[1].1 + 0.25 * (tri[1].1 - low));
                    if vs > best.0 {
                        *best = (vs, ts);
                    }
                    break;
                };
                if v > best.0 {
                    *best = (v, ts);
                }
                tri = narrow(tri, (ts, v));
            }
        }
    }

    /// Brackets wait for [`Self::resolve`].
    pub fn has_pending(&self) -> bool {
        !self.pending.is_empty()
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

/// The bracket (t₀ < t₁ < t₂, the middle highest) with a new point p inside it: the three
/// points that keep the highest in the middle (successive parabolic interpolation).
pub fn narrow(tri: [(f64, f64); 3], p: (f64, f64)) -> [(f64, f64); 3] {
    match (p.0 < tri[1].0, p.1 >= tri[1].1) {
        (true, true) => [tri[0], p, tri[1]],
        (true, false) => [p, tri[1], tri[2]],
        (false, true) => [tri[1], p, tri[2]],
        (false, false) => [tri[0], tri[1], p],
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
                        tr.resolve(&mut |_| None);
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

    #[test]
    fn resolved_peaks_are_attained_values_at_the_maximum() {
        // |sin t| and 2 + cos 3t observed every 0.5 (a sixth of a period and more), resolved
        // from the function itself: the peaks are 1 at π/2 and 3 at 2π/3, to rounding, and
        // never above them.
        for k in 0..10 {
            let f = |t: f64| vec![t.sin(), 2.0 + (3.0 * t).cos()];
            let mut tr = PeakTracker::default();
            let mut t = 0.3 + 0.037 * k as f64;
            while t < 2.9 {
                tr.observe(t, &f(t));
                tr.resolve(&mut |s| Some(f(s)));
                t += 0.5;
            }
            let (p, q) = (tr.peaks()[0], tr.peaks()[1]);
            assert!(p.0 <= 1.0 && 1.0 - p.0 < 1e-11, "{k}: {p:?}");
            assert!(
                (p.1 - std::f64::consts::FRAC_PI_2).abs() < 1e-5,
                "{k}: {p:?}"
            );
            assert!(q.0 <= 3.0 && 3.0 - q.0 < 1e-11, "{k}: {q:?}");
        }
    }
}
