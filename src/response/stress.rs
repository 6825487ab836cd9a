//! Stresses in a beam's section from its six resultants (docs/theory.md §3.3), and their
//! peak over the response, found on the closed-form solution at any output rate.
//!
//! At one instant, with the resultants N, V_y, V_z, T, M_y, M_z of the section
//! ([`super::sections`]), area A, second moments I_y, I_z and torsion constant J:
//!
//! * normal stress at the extreme fibre, σ = |N|/A + |M| R / I for a circular tube (the
//!   resultant moment |M| = √(M_y² + M_z²) peaks at the outer radius R, I_y = I_z = I), and
//!   σ = |N|/A + |M_y| z_e/I_y + |M_z| y_e/I_z for a general section (its extreme-fibre
//!   distances y_e, z_e: exact for a rectangle, conservative otherwise);
//! * shear, τ = |T| r_t/J + the transverse shear's largest, k √(V_y² + V_z²)/A for a tube
//!   (k = A Q/(I · 2w), Q = (2/3)(R³ − r³) the first moment of the half tube, w the wall:
//!   2 for a thin tube) and √((k_y V_y)² + (k_z V_z)²)/A for a general section;
//! * von Mises, σ_vm = √(σ² + 3τ²), the largest normal stress and the largest shear taken
//!   at the same instant (conservative: they sit at different fibres — the extreme fibre
//!   and the neutral axis — where a thin tube's own combination is within a few per cent);
//! * the margin of safety against an allowable, MS = σ_allow/(FS · σ_vm) − 1.
//!
//! The peak of σ_vm(t) over the response: every resultant is a sum of damped sinusoids in
//! closed form, so σ_vm and its slope are known on a grid of spacing π/(4ω_max); the cubic
//! Hermite interpolant between grid points estimates each interval's largest value, and
//! the intervals within [`REFINE_WINDOW`] of the best estimate are refined on the closed
//! form by successive parabolic interpolation: the result is a value the response attains.

use super::channels::Channel;
use super::extrema::{self, hermite_bound, hermite_max, WaveSum};
use super::superposition::ModalResponse;
use crate::ritz::ModalAnalysis;
use crate::structure::BeamSection;

/// Where a section's stresses are read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionFibres {
    /// A circular tube: the bending stress is that of the resultant moment at radius `y`.
    pub round: bool,
    /// Extreme-fibre distance along the section's y axis, m.
    pub y: f64,
    /// Extreme-fibre distance along the section's z axis, m.
    pub z: f64,
    /// Radius at which the torsional shear T r_t/J is read, m.
    pub torsion_radius: f64,
    /// Transverse-shear factors (k_y, k_z): τ_max = k V/A.
    pub shear_factor: (f64, f64),
}

impl SectionFibres {
    /// A circular tube of outer diameter D and wall w: extreme fibres and torsion at
    /// R = D/2, shear factor k = A Q/(I · 2w) with Q = (2/3)(R³ − r³).
    pub fn tube(outer_diameter: f64, wall: f64) -> Self {
        let big_r = outer_diameter / 2.0;
        let r = big_r - wall;
        let pi = std::f64::consts::PI;
        let area = pi * (big_r * big_r - r * r);
        let i = pi * (big_r.powi(4) - r.powi(4)) / 4.0;
        let q = 2.0 / 3.0 * (big_r.powi(3) - r.powi(3));
        let k = area * q / (i * 2.0 * wall);
        Self {
            round: true,
            y: big_r,
            z: big_r,
            torsion_radius: big_r,
            shear_factor: (k, k),
        }
    }
}

/// An allowable stress and its factor of safety (`[materials.X] allowable_stress`,
/// `factor_of_safety`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Allowable {
    /// σ_allow, Pa.
    pub stress: f64,
    /// FS ≥ 1.
    pub factor_of_safety: f64,
}

impl Allowable {
    /// MS = σ_allow/(FS · σ_vm) − 1 (+∞ for an unstressed section).
    pub fn margin(&self, von_mises: f64) -> f64 {
        if von_mises > 0.0 {
            self.stress / (self.factor_of_safety * von_mises) - 1.0
        } else {
            f64::INFINITY
        }
    }
}

/// One beam's stress settings.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BeamStress {
    /// Where its stresses are read (None: a general section without its fibres, whose
    /// material has no allowable: no stresses).
    pub fibres: Option<SectionFibres>,
    /// Its material's allowable, if given.
    pub allowable: Option<Allowable>,
}

/// The scenario's stress settings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StressSpec {
    /// One per beam, in the structure's order.
    pub beams: Vec<BeamStress>,
    /// `[deployment.latch] moment_allowable`, N·m.
    pub latch_moment_allowable: Option<f64>,
}

/// The stresses of one section at one instant, Pa.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stresses {
    /// σ, the largest normal stress.
    pub normal: f64,
    /// τ, the largest shear.
    pub shear: f64,
    /// √(σ² + 3τ²).
    pub von_mises: f64,
}

/// The stresses of a section with resultants [N, V_y, V_z, T, M_y, M_z] (module doc).
pub fn stresses(r: [f64; 6], section: &BeamSection, fibres: &SectionFibres) -> Stresses {
    let [n, vy, vz, t, my, mz] = r;
    let a = section.area;
    let bending = if fibres.round {
        (my * my + mz * mz).sqrt() * fibres.y / section.iy
    } else {
        my.abs() * fibres.z / section.iy + mz.abs() * fibres.y / section.iz
    };
    let normal = n.abs() / a + bending;
    let (ky, kz) = fibres.shear_factor;
    let transverse = if fibres.round {
        ky * (vy * vy + vz * vz).sqrt() / a
    } else {
        ((ky * vy).powi(2) + (kz * vz).powi(2)).sqrt() / a
    };
    let shear = t.abs() * fibres.torsion_radius / section.torsion_constant + transverse;
    Stresses {
        normal,
        shear,
        von_mises: (normal * normal + 3.0 * shear * shear).sqrt(),
    }
}

/// The stresses' slope dσ_vm/dt from the resultants `r`, their stresses `s` and their rates
/// (where σ_vm is smooth:
/// away from a resultant's zero, which is a minimum of its magnitude, never a maximum of
/// σ_vm's).
fn von_mises_rate(
    s: &Stresses,
    r: [f64; 6],
    dr: [f64; 6],
    section: &BeamSection,
    f: &SectionFibres,
) -> f64 {
    if s.von_mises == 0.0 {
        return 0.0;
    }
    let [n, vy, vz, t, my, mz] = r;
    let [dn, dvy, dvz, dt, dmy, dmz] = dr;
    let a = section.area;
    // d|x|/dt = sign(x) ẋ; d√(x² + y²)/dt = (x ẋ + y ẏ)/√(x² + y²).
    let dabs = |x: f64, dx: f64| if x == 0.0 { dx.abs() } else { x.signum() * dx };
    let dhyp = |x: f64, dx: f64, y: f64, dy: f64| {
        let h = (x * x + y * y).sqrt();
        if h == 0.0 {
            (dx * dx + dy * dy).sqrt()
        } else {
            (x * dx + y * dy) / h
        }
    };
    let dbending = if f.round {
        dhyp(my, dmy, mz, dmz) * f.y / section.iy
    } else {
        dabs(my, dmy) * f.z / section.iy + dabs(mz, dmz) * f.y / section.iz
    };
    let dnormal = dabs(n, dn) / a + dbending;
    let (ky, kz) = f.shear_factor;
    let dtransverse = if f.round {
        ky * dhyp(vy, dvy, vz, dvz) / a
    } else {
        dhyp(ky * vy, ky * dvy, kz * vz, kz * dvz) / a
    };
    let dshear = dabs(t, dt) * f.torsion_radius / section.torsion_constant + dtransverse;
    (s.normal * dnormal + 3.0 * s.shear * dshear) / s.von_mises
}

/// The intervals refined on the closed form: those whose interpolated largest value is
/// within this fraction of the best estimate (the interpolant's error on the grid is below
/// 1e-3 of a mode's amplitude).
pub const REFINE_WINDOW: f64 = 5e-3;

/// A section's peak stress at or below this fraction of the largest section's — over every
/// beam's stations searched together ([`beam_stresses`]) — is rounding noise, reported as
/// zero at t = 0 (the project's rule for every displayed quantity).
pub const NOISE: f64 = 1e-9;

/// The peak of σ_vm at one section over the response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StressPeak {
    /// s after the hand-over.
    pub time: f64,
    /// The stresses there.
    pub stresses: Stresses,
    /// The resultants there, [N, V_y, V_z, T, M_y, M_z].
    pub resultants: [f64; 6],
}

/// The largest σ_vm over [0, duration] of each section k whose six resultant channels are
/// `channels[6k..6k + 6]` and whose section and fibres are `sections[k]` (module doc): one
/// pass over the grid for all of them (every beam's stations together: the modes are
/// evaluated on the grid once).
pub fn peak_von_mises(
    response: &ModalResponse,
    modal: &ModalAnalysis,
    channels: &[Channel],
    sections: &[(&BeamSection, &SectionFibres)],
    duration: f64,
) -> Vec<StressPeak> {
    let signals = response.signals(modal, channels);
    let count = channels.len() / 6;
    debug_assert_eq!(count, sections.len());
    // Each section's six resultants evaluated together: one sin_cos per mode, not six.
    let banks: Vec<Option<extrema::Bank>> = (0..count)
        .map(|k| extrema::Bank::new(signals[6 * k..6 * k + 6].iter().collect()))
        .collect();
    let at = |k: usize, t: f64| -> [f64; 6] {
        match &banks[k] {
            Some(bank) => {
                let mut out = [(0.0, 0.0); 6];
                bank.at(t, &mut out);
                out.map(|o| o.0)
            }
            None => std::array::from_fn(|j| signals[6 * k + j].at(t)),
        }
    };
    let fastest = signals.iter().map(WaveSum::fastest).fold(0.0, f64::max);
    let grid = extrema::grid(fastest, duration.max(0.0));
    // First pass: every interval's interpolated largest value, per section.
    type Knot = (f64, f64, f64);
    // Per section: the kept intervals, the best estimate, the last knot and the length at
    // which the list is pruned next (when it doubles what the last pruning left: O(1) per
    // interval). Each segment of the grid is walked on its own, the lists then joined.
    type State = (Vec<(f64, f64, Knot, Knot)>, f64, Option<Knot>, usize);
    let init = || -> Vec<State> { vec![(Vec::new(), 0.0, None, 4096); count] };
    let segments = response.on_grid_segments(
        modal,
        channels,
        &grid,
        init,
        |state, times, values, slopes| {
            for (k, (list, best, prev, prune_at)) in state.iter_mut().enumerate() {
                let (section, fibres) = sections[k];
                for (i, &t) in times.iter().enumerate() {
                    let r: [f64; 6] = std::array::from_fn(|j| values[(i, 6 * k + j)]);
                    let dr: [f64; 6] = std::array::from_fn(|j| slopes[(i, 6 * k + j)]);
                    let s = stresses(r, section, fibres);
                    let knot = (t, s.von_mises, von_mises_rate(&s, r, dr, section, fibres));
                    if let Some(a) = *prev {
                        // A section with no stress at all (a beam's free tip) keeps no interval.
                        let bound = hermite_bound(a, knot);
                        if t > a.0 && bound > 0.0 && bound >= (1.0 - REFINE_WINDOW) * *best {
                            let (est, where_) = hermite_max(a, knot);
                            if est >= (1.0 - REFINE_WINDOW) * *best {
                                *best = best.max(est);
                                list.push((est, where_, a, knot));
                                if list.len() > *prune_at {
                                    let floor = (1.0 - REFINE_WINDOW) * *best;
                                    list.retain(|x| x.0 >= floor);
                                    *prune_at = 4096.max(2 * list.len());
                                }
                            }
                        }
                    }
                    *prev = Some(knot);
                }
            }
        },
    );
    let mut intervals: Vec<Vec<(f64, f64, Knot, Knot)>> = vec![Vec::new(); count];
    let mut best_estimate = vec![0.0_f64; count];
    for state in segments {
        for (k, (list, best, _, _)) in state.into_iter().enumerate() {
            intervals[k].extend(list);
            best_estimate[k] = best_estimate[k].max(best);
        }
    }
    // A section whose stress is rounding noise against the largest of all of them (within
    // NOISE of it: a free tip's resultants) has none: its every grid interval would qualify.
    let largest = best_estimate.iter().fold(0.0_f64, |m, &b| m.max(b));
    (0..count)
        .map(|k| {
            let (section, fibres) = sections[k];
            if best_estimate[k] <= NOISE * largest {
                return StressPeak {
                    time: 0.0,
                    stresses: stresses([0.0; 6], section, fibres),
                    resultants: [0.0; 6],
                };
            }
            let vm = |t: f64| stresses(at(k, t), section, fibres).von_mises;
            let floor = (1.0 - REFINE_WINDOW) * best_estimate[k];
            let mut list = std::mem::take(&mut intervals[k]);
            list.retain(|x| x.0 >= floor);
            list.sort_by(|x, y| y.0.total_cmp(&x.0));
            let mut best = (vm(0.0), 0.0);
            for (_, where_, a, b) in list {
                for (t, v) in [(a.0, a.1), (b.0, b.1)] {
                    if v > best.0 {
                        best = (v, t);
                    }
                }
                let (v, t) = refine_max(&vm, (a.0, a.1), (where_, vm(where_)), (b.0, b.1));
                if v > best.0 {
                    best = (v, t);
                }
            }
            let r = at(k, best.1);
            StressPeak {
                time: best.1,
                stresses: stresses(r, section, fibres),
                resultants: r,
            }
        })
        .collect()
}

/// One beam's stresses over the response: the peak σ_vm at each station
/// ([`super::sections::stations`]), its allowable and the worst station.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamStresses {
    /// Beam index.
    pub beam: usize,
    /// Beam name.
    pub name: String,
    /// (station m from the root, its peak), root to tip.
    pub stations: Vec<(f64, StressPeak)>,
    /// The material's allowable, if given.
    pub allowable: Option<Allowable>,
}

impl BeamStresses {
    /// The station with the largest σ_vm and its peak.
    pub fn worst(&self) -> Option<(f64, StressPeak)> {
        self.stations
            .iter()
            .copied()
            .fold(None, |acc, s| match acc {
                Some(a) if a.1.stresses.von_mises >= s.1.stresses.von_mises => Some(a),
                _ => Some(s),
            })
    }

    /// The margin of safety at the worst station (None without an allowable).
    pub fn margin(&self) -> Option<f64> {
        let (_, p) = self.worst()?;
        Some(self.allowable?.margin(p.stresses.von_mises))
    }
}

/// The stresses of every beam whose fibres are known, over [0, duration] of the response.
pub fn beam_stresses(
    model: &crate::ritz::RitzModel,
    modes: &ModalAnalysis,
    response: &ModalResponse,
    spec: &StressSpec,
    duration: f64,
) -> Vec<BeamStresses> {
    let st = &model.structure;
    // Every beam with known fibres: its stations, and their channels and sections in one list.
    let mut beams = Vec::new();
    let mut channels = Vec::new();
    for (i, b) in st.beams.iter().enumerate() {
        let Some(bs) = spec.beams.get(i) else {
            continue;
        };
        let Some(fibres) = &bs.fibres else {
            continue;
        };
        let xs = super::sections::stations(st, i);
        channels.extend(super::sections::beam_section_channels(model, i, &xs));
        beams.push((i, b, bs, fibres, xs));
    }
    let sections: Vec<(&BeamSection, &SectionFibres)> = beams
        .iter()
        .flat_map(|(_, b, _, fibres, xs)| xs.iter().map(move |_| (&b.section, *fibres)))
        .collect();
    let mut peaks = peak_von_mises(response, modes, &channels, &sections, duration).into_iter();
    beams
        .into_iter()
        .map(|(i, b, bs, _, xs)| BeamStresses {
            beam: i,
            name: b.name.clone(),
            stations: xs.into_iter().zip(peaks.by_ref()).collect(),
            allowable: bs.allowable,
        })
        .collect()
}

/// The largest value of f near the middle point of a bracket (a, m, b), a < m < b, by
/// successive parabolic interpolation (at most 12 evaluations), keeping the best three
/// points; the best point evaluated.
fn refine_max(f: &dyn Fn(f64) -> f64, a: (f64, f64), m: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let mut tri = [a, m, b];
    let mut best = [a, m, b]
        .into_iter()
        .fold((f64::NEG_INFINITY, 0.0), |acc, p| {
            if p.1 > acc.0 {
                (p.1, p.0)
            } else {
                acc
            }
        });
    for _ in 0..12 {
        // The middle point must be the highest for a maximum between the ends.
        if !(tri[0].0 < tri[1].0 && tri[1].0 < tri[2].0) || tri[1].1 < tri[0].1.max(tri[2].1) {
            break;
        }
        let Some((ts, _)) = crate::deploy::peaks::parabola_peak(tri[0], tri[1], tri[2]) else {
            break;
        };
        if (ts - tri[1].0).abs() <= 1e-13 * (tri[2].0 - tri[0].0).max(f64::MIN_POSITIVE) {
            break;
        }
        let v = f(ts);
        if v > best.0 {
            best = (v, ts);
        }
        tri = crate::deploy::peaks::narrow(tri, (ts, v));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thin_tube_shear_factor_is_two() {
        // k → 2 as the wall thins (the thin tube's τ_max = 2V/A).
        let f = SectionFibres::tube(0.1, 1e-5);
        assert!(
            (f.shear_factor.0 - 2.0).abs() < 1e-3,
            "{:?}",
            f.shear_factor
        );
        // A solid-ish thick tube: k between 4/3 (solid circle) and 2.
        let g = SectionFibres::tube(0.1, 0.049);
        assert!(g.shear_factor.0 > 4.0 / 3.0 && g.shear_factor.0 < 2.0);
    }

    #[test]
    fn margin_of_safety() {
        let a = Allowable {
            stress: 300e6,
            factor_of_safety: 1.5,
        };
        assert!((a.margin(100e6) - 1.0).abs() < 1e-15);
        assert!(a.margin(0.0).is_infinite());
    }
}
