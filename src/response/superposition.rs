//! Response by modal superposition, exact in time (docs/theory.md §3).
//!
//! With q = Σ_j φ_j η_j (mass-normalised modes), every mode obeys
//! η̈_j + 2ζω_j η̇_j + ω_j² η_j = 0 after the hand-over, solved in closed form:
//!
//! * rigid (ω = 0): η = η₀ + η̇₀ t — the momentum the latch left in the spacecraft;
//! * elastic, 0 ≤ ζ < 1, ω_d = ω√(1 − ζ²):
//!   η = e^{−ζωt} [η₀ cos ω_d t + (η̇₀ + ζωη₀)/ω_d · sin ω_d t].
//!
//! No time stepping: an undamped mode keeps its energy ½(η̇² + ω²η²) to rounding for any
//! duration, and the samples t_k = k/rate are exact.

use super::channels::{Channel, ChannelKind, Order};
use super::extrema::{self, PeakSearch, Scalar, SquaredNorm, Wave, WaveSum};
use super::ResponseSettings;
use crate::ritz::ModalAnalysis;
use faer::{Mat, MatRef};

/// One mode kept in the response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeptMode {
    /// Mode number in the modal analysis (1-based).
    pub number: usize,
    /// Rigid-body mode.
    pub rigid: bool,
    /// ω, rad/s.
    pub omega_rad_s: f64,
    /// η(0).
    pub eta0: f64,
    /// η̇(0).
    pub eta_dot0: f64,
    /// ζ: `[response] damping_ratio` plus the hinge lines' dashpots
    /// ([`ModalResponse::with_line_damping`]); unused for rigid modes.
    pub zeta: f64,
}

/// The modal model of the response.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalResponse {
    /// Kept modes: every rigid mode, then the first elastic ones.
    pub modes: Vec<KeptMode>,
    /// ζ of every elastic mode.
    pub damping_ratio: f64,
    /// Elastic modes the model has.
    pub available_elastic: usize,
    /// Elastic modes requested (before clamping to the model).
    pub requested_elastic: Option<usize>,
    /// Fraction of the hand-over kinetic energy carried by the kept modes.
    pub captured_energy_fraction: f64,
}

pub use crate::ritz::modes::MAX_ZETA;

/// Sampled response.
#[derive(Debug, Clone)]
pub struct ResponseHistory {
    /// Sample times after the final latch, s (t_k = k / rate).
    pub times: Vec<f64>,
    /// Channel values, samples × channels.
    pub values: Mat<f64>,
    /// Modal amplitudes η_j, samples × kept modes.
    pub modal: Mat<f64>,
    /// Elastic energy Σ_elastic ½(η̇² + ω²η²) at every sample, J.
    pub elastic_energy: Vec<f64>,
    /// Every channel's largest |value| on [0, duration] and its time, from the closed form
    /// ([`ModalResponse::peaks`]), not from the samples.
    pub peaks: Vec<(f64, f64)>,
    /// Every beam root's force and moment (its three channels) with the largest magnitude of
    /// the vector and its time, likewise.
    pub vector_peaks: Vec<(Vec<usize>, (f64, f64))>,
}

impl ModalResponse {
    /// Keeps every rigid mode and the first `settings.modes` elastic ones (all when `None`,
    /// clamped to the model's number), starting from η₀ = 0 and η̇₀ = `modal_velocity`.
    pub fn new(modal: &ModalAnalysis, modal_velocity: &[f64], settings: &ResponseSettings) -> Self {
        let zero = vec![0.0; modal_velocity.len()];
        Self::with_initial(modal, &zero, modal_velocity, settings)
    }

    /// As [`ModalResponse::new`], starting from η₀ = `modal_displacement`; the captured energy
    /// counts kinetic and elastic energy, ½(η̇² + ω²η²) per mode.
    pub fn with_initial(
        modal: &ModalAnalysis,
        modal_displacement: &[f64],
        modal_velocity: &[f64],
        settings: &ResponseSettings,
    ) -> Self {
        let available = modal.modes.iter().filter(|m| !m.rigid).count();
        let keep = settings.modes.unwrap_or(available).min(available);
        let mut elastic_seen = 0;
        let mut modes = Vec::new();
        let (mut kept_e, mut total_e) = (0.0, 0.0);
        for ((m, &v), &e) in modal
            .modes
            .iter()
            .zip(modal_velocity)
            .zip(modal_displacement)
        {
            let energy = 0.5 * (v * v + (m.omega_rad_s * e).powi(2));
            total_e += energy;
            let take = m.rigid || {
                elastic_seen += 1;
                elastic_seen <= keep
            };
            if take {
                kept_e += energy;
                modes.push(KeptMode {
                    number: m.number,
                    rigid: m.rigid,
                    omega_rad_s: m.omega_rad_s,
                    eta0: e,
                    eta_dot0: v,
                    zeta: settings.damping_ratio,
                });
            }
        }
        Self {
            modes,
            damping_ratio: settings.damping_ratio,
            available_elastic: available,
            requested_elastic: settings.modes,
            captured_energy_fraction: if total_e > 0.0 { kept_e / total_e } else { 1.0 },
        }
    }

    /// Adds to every kept elastic mode's ζ the hinge lines' dashpots (docs/theory.md §1.6):
    /// `extra[number − 1]` = φ_jᵀ C φ_j / (2ω_j), the diagonal of the damping in modal
    /// coordinates (the off-diagonal terms, second order for light damping, are left out). A
    /// sum with the dashpots stays below [`MAX_ZETA`] (or the ratio asked for, if larger).
    pub fn with_line_damping(mut self, extra: &[f64]) -> Self {
        for m in self.modes.iter_mut().filter(|m| !m.rigid) {
            let add = extra.get(m.number - 1).copied().unwrap_or(0.0);
            if add > 0.0 {
                m.zeta = (m.zeta + add).min(MAX_ZETA.max(m.zeta));
            }
        }
        self
    }

    /// Number of elastic modes kept.
    pub fn kept_elastic(&self) -> usize {
        self.modes.iter().filter(|m| !m.rigid).count()
    }

    /// (η, η̇) of kept mode j at time t.
    pub fn state(&self, j: usize, t: f64) -> (f64, f64) {
        state(&self.modes[j], t)
    }

    /// Samples the response at t_k = k/rate, k = 0…rows−1, into the given channels.
    pub fn sample(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
        settings: &ResponseSettings,
    ) -> ResponseHistory {
        let groups = vector_groups(channels);
        let (peaks, vector_peaks) = self.peaks(modal, channels, &groups, settings.duration);
        let rows = settings.rows() as usize;
        let nm = self.modes.len();
        let times: Vec<f64> = (0..rows).map(|k| k as f64 / settings.output_rate).collect();
        let mut eta = Mat::<f64>::zeros(rows, nm);
        let mut eta_dot = Mat::<f64>::zeros(rows, nm);
        let mut eta_dd = Mat::<f64>::zeros(rows, nm);
        let mut energy = vec![0.0; rows];
        let h = 1.0 / settings.output_rate;
        let (mut vel, mut acc) = (vec![0.0; rows], vec![0.0; rows]);
        for (j, m) in self.modes.iter().enumerate() {
            let col = eta
                .col_mut(j)
                .try_as_col_major_mut()
                .expect("a fresh Mat is column-major")
                .as_slice_mut();
            fill_mode(m, h, col, &mut vel, &mut acc, &mut energy);
            for k in 0..rows {
                eta_dot[(k, j)] = vel[k];
                eta_dd[(k, j)] = acc[k];
            }
        }
        let mut values = &eta * self.gains(modal, channels, Order::Displacement);
        if channels.iter().any(|c| c.order == Order::Acceleration) {
            values += &eta_dd * self.gains(modal, channels, Order::Acceleration);
        }
        if channels.iter().any(|c| c.rate_row.is_some()) {
            values += &eta_dot * self.rate_gains(modal, channels);
        }
        for (c, ch) in channels.iter().enumerate() {
            if ch.offset != 0.0 {
                for k in 0..rows {
                    values[(k, c)] += ch.offset;
                }
            }
        }
        ResponseHistory {
            times,
            values,
            modal: eta,
            elastic_energy: energy,
            peaks,
            vector_peaks: groups.into_iter().zip(vector_peaks).collect(),
        }
    }
}

impl ModalResponse {
    /// The channel gains G_jc = c · φ_j of the channels reading `order` (0 for the others),
    /// kept modes × channels.
    fn gains(&self, modal: &ModalAnalysis, channels: &[Channel], order: Order) -> Mat<f64> {
        Mat::from_fn(self.modes.len(), channels.len(), |j, c| {
            if channels[c].order != order {
                return 0.0;
            }
            let shape = &modal.modes[self.modes[j].number - 1].shape;
            channels[c]
                .row
                .iter()
                .zip(shape)
                .map(|(a, b)| a * b)
                .sum::<f64>()
        })
    }

    /// The rate gains G_jc = c_v · φ_j of the channels with a rate row (0 for the others).
    fn rate_gains(&self, modal: &ModalAnalysis, channels: &[Channel]) -> Mat<f64> {
        Mat::from_fn(self.modes.len(), channels.len(), |j, c| {
            let Some(row) = &channels[c].rate_row else {
                return 0.0;
            };
            let shape = &modal.modes[self.modes[j].number - 1].shape;
            row.iter().zip(shape).map(|(a, b)| a * b).sum::<f64>()
        })
    }

    /// Kept mode j's η(t) as a wave sum: η₀ + η̇₀t for a rigid mode, otherwise
    /// e^{−ζωt}(η₀ cos ω_d t + (η̇₀ + ζωη₀)/ω_d · sin ω_d t).
    fn mode_signal(&self, j: usize) -> WaveSum {
        let m = &self.modes[j];
        if m.rigid || m.omega_rad_s == 0.0 {
            return WaveSum {
                constant: m.eta0,
                slope: m.eta_dot0,
                waves: Vec::new(),
            };
        }
        let (w, z) = (m.omega_rad_s, m.zeta);
        let wd = w * (1.0 - z * z).sqrt();
        WaveSum {
            constant: 0.0,
            slope: 0.0,
            waves: vec![Wave {
                sigma: z * w,
                omega: wd,
                p: m.eta0,
                q: (m.eta_dot0 + z * w * m.eta0) / wd,
            }],
        }
    }

    /// Every channel as a sum of damped sinusoids, its value in closed form at any time:
    /// offset + Σ_j (G_jc η_j or G_jc η̈_j).
    pub fn signals(&self, modal: &ModalAnalysis, channels: &[Channel]) -> Vec<WaveSum> {
        let (gd, ga, gv) = (
            self.gains(modal, channels, Order::Displacement),
            self.gains(modal, channels, Order::Acceleration),
            self.rate_gains(modal, channels),
        );
        let modes: Vec<WaveSum> = (0..self.modes.len()).map(|j| self.mode_signal(j)).collect();
        (0..channels.len())
            .map(|c| {
                let mut s = WaveSum {
                    constant: channels[c].offset,
                    ..WaveSum::default()
                };
                for (j, m) in modes.iter().enumerate() {
                    let (d, a, v) = (gd[(j, c)], ga[(j, c)], gv[(j, c)]);
                    s.constant += d * m.constant + v * m.slope;
                    s.slope += d * m.slope;
                    for w in &m.waves {
                        let vel = w.derivative();
                        let acc = vel.derivative();
                        s.waves.push(Wave {
                            p: d * w.p + v * vel.p + a * acc.p,
                            q: d * w.q + v * vel.q + a * acc.q,
                            ..*w
                        });
                    }
                }
                s
            })
            .collect()
    }

    /// Each channel's amplitude spectrum: for every kept elastic mode, in the modes' order,
    /// (its damped frequency in Hz, the amplitude √(p² + q²) of its contribution to the
    /// channel at the hand-over, the mode's number). The channel is its offset and rigid part
    /// plus the sum of these sinusoids, each decaying as e^{−ζωt}: the modes that carry it.
    pub fn spectrum(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
    ) -> Vec<Vec<(f64, f64, usize)>> {
        let elastic: Vec<usize> = self
            .modes
            .iter()
            .filter(|m| !(m.rigid || m.omega_rad_s == 0.0))
            .map(|m| m.number)
            .collect();
        self.signals(modal, channels)
            .iter()
            .map(|s| {
                s.waves
                    .iter()
                    .zip(&elastic)
                    .map(|(w, &n)| (w.omega / (2.0 * std::f64::consts::PI), w.modulus(), n))
                    .collect()
            })
            .collect()
    }

    /// Every channel's value (offset included) and slope on the uniform `grid` (t_i = i·h),
    /// in consecutive pieces that share their end rows: `f(times, values, slopes)` with
    /// rows × channels matrices. The modes are evaluated on the grid and the channels from
    /// them by one matrix product per piece.
    pub fn on_grid(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
        grid: &extrema::Grid,
        f: &mut GridPiece<'_>,
    ) {
        self.on_grid_within(modal, channels, grid, (0, grid.intervals), f);
    }

    /// [`Self::on_grid`] in [`extrema::Grid::segments`] walked side by side: `init()` makes
    /// each segment's state, `f` is handed it with every piece of its segment, and the states
    /// come back in time order (the segments depend on the grid only, so the results do not
    /// depend on the number of threads). Long grids only: a short one is one segment.
    pub fn on_grid_segments<S: Send>(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
        grid: &extrema::Grid,
        init: impl Fn() -> S + Sync + Send,
        f: impl Fn(&mut S, &[f64], MatRef<'_, f64>, MatRef<'_, f64>) + Sync + Send,
    ) -> Vec<S> {
        let count = if grid.len() > SEGMENT_KNOTS {
            SEGMENTS
        } else {
            1
        };
        crate::ritz::parallel::map(&grid.segments(count), |&range| {
            let mut state = init();
            self.on_grid_within(modal, channels, grid, range, &mut |t, v, dv| {
                f(&mut state, t, v, dv)
            });
            state
        })
    }

    /// [`Self::on_grid`] over the knots `first..=last` only.
    fn on_grid_within(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
        grid: &extrema::Grid,
        range: (usize, usize),
        f: &mut GridPiece<'_>,
    ) {
        // The channels reading η and those reading η̈, each with its own gains (the other
        // order's would be zeros: a product with them is wasted work).
        let order_of = |order: Order| -> (Vec<usize>, Mat<f64>) {
            let idx: Vec<usize> = (0..channels.len())
                .filter(|&c| channels[c].order == order)
                .collect();
            let g = self.gains(modal, channels, order);
            let compact = Mat::from_fn(g.nrows(), idx.len(), |j, k| g[(j, idx[k])]);
            (idx, compact)
        };
        let (id, gd) = order_of(Order::Displacement);
        let (ia, ga) = order_of(Order::Acceleration);
        // The channels with a rate row: their η̇ share is added after.
        let iv: Vec<usize> = (0..channels.len())
            .filter(|&c| channels[c].rate_row.is_some())
            .collect();
        let gv = {
            let g = self.rate_gains(modal, channels);
            Mat::from_fn(g.nrows(), iv.len(), |j, k| g[(j, iv[k])])
        };
        let nm = self.modes.len();
        let h = grid.spacing();
        let chunk = PEAK_CHUNK.min(range.1 - range.0 + 1);
        let (mut e, mut ed, mut edd, mut eddd) = (
            Mat::<f64>::zeros(chunk, nm),
            Mat::<f64>::zeros(chunk, nm),
            Mat::<f64>::zeros(chunk, nm),
            Mat::<f64>::zeros(chunk, nm),
        );
        let mut values = Mat::<f64>::zeros(chunk, channels.len());
        let mut slopes = Mat::<f64>::zeros(chunk, channels.len());
        let mut times = Vec::with_capacity(chunk);
        for (start, end) in grid.pieces_within(range, chunk) {
            let rows = end - start + 1;
            times.clear();
            times.extend((start..=end).map(|k| grid.at(k)));
            // η, η̇, η̈ = −2ζωη̇ − ω²η and η⃛ = −2ζωη̈ − ω²η̇ of every mode at the piece's times.
            for (j, m) in self.modes.iter().enumerate() {
                let (w, zeta) = if m.rigid {
                    (0.0, 0.0)
                } else {
                    (m.omega_rad_s, m.zeta)
                };
                let (x, xd) = (
                    e.col_mut(j)
                        .try_as_col_major_mut()
                        .expect("a fresh Mat is column-major")
                        .as_slice_mut(),
                    ed.col_mut(j)
                        .try_as_col_major_mut()
                        .expect("a fresh Mat is column-major")
                        .as_slice_mut(),
                );
                fill_state(m, grid.at(start), h, &mut x[..rows], &mut xd[..rows]);
                for i in 0..rows {
                    let (x, xd) = (e[(i, j)], ed[(i, j)]);
                    let xdd = -2.0 * zeta * w * xd - w * w * x;
                    edd[(i, j)] = xdd;
                    eddd[(i, j)] = -2.0 * zeta * w * xdd - w * w * xd;
                }
            }
            // Every channel has one order (its values copied), and some a rate share (added).
            for (idx, g, x, dx) in [(&id, &gd, &e, &ed), (&ia, &ga, &edd, &eddd)] {
                if idx.is_empty() {
                    continue;
                }
                let (v, dv) = (x.subrows(0, rows) * g, dx.subrows(0, rows) * g);
                for (k, &c) in idx.iter().enumerate() {
                    values.col_mut(c).subrows_mut(0, rows).copy_from(v.col(k));
                    slopes.col_mut(c).subrows_mut(0, rows).copy_from(dv.col(k));
                }
            }
            if !iv.is_empty() {
                let (v, dv) = (ed.subrows(0, rows) * &gv, edd.subrows(0, rows) * &gv);
                for (k, &c) in iv.iter().enumerate() {
                    for i in 0..rows {
                        values[(i, c)] += v[(i, k)];
                        slopes[(i, c)] += dv[(i, k)];
                    }
                }
            }
            for (c, ch) in channels.iter().enumerate() {
                if ch.offset != 0.0 {
                    for i in 0..rows {
                        values[(i, c)] += ch.offset;
                    }
                }
            }
            f(&times, values.subrows(0, rows), slopes.subrows(0, rows));
        }
    }

    /// Each channel's smallest and largest value in each of `columns` equal spans of
    /// [0, duration], from the closed form — the grid's knots and their cubic Hermite
    /// interpolants' extrema (within ~1e-3 of a mode's amplitude: a plot's resolution) — as
    /// (t, v) points in time order: the min/max envelope a plot draws where the samples
    /// would alias.
    pub fn envelopes(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
        duration: f64,
        columns: usize,
    ) -> Vec<Vec<(f64, f64)>> {
        let columns = columns.max(1);
        let duration = duration.max(0.0);
        let signals = self.signals(modal, channels);
        let fastest = signals.iter().map(WaveSum::fastest).fold(0.0, f64::max);
        let grid = extrema::grid(fastest, duration);
        let empty = ((f64::NAN, f64::INFINITY), (f64::NAN, f64::NEG_INFINITY));
        let mut env = vec![vec![empty; columns]; channels.len()];
        let column = |t: f64| {
            if duration > 0.0 {
                ((t / duration * columns as f64) as usize).min(columns - 1)
            } else {
                0
            }
        };
        let mut last: Vec<Option<extrema::Knot>> = vec![None; channels.len()];
        self.on_grid(modal, channels, &grid, &mut |times, values, slopes| {
            for (c, (e, prev)) in env.iter_mut().zip(&mut last).enumerate() {
                for (i, &t) in times.iter().enumerate() {
                    let knot = (t, values[(i, c)], slopes[(i, c)]);
                    let mut offer = |(t, v): (f64, f64)| {
                        let slot = &mut e[column(t)];
                        if v < slot.0 .1 {
                            slot.0 = (t, v);
                        }
                        if v > slot.1 .1 {
                            slot.1 = (t, v);
                        }
                    };
                    offer((t, knot.1));
                    if let Some(a) = *prev {
                        if t > a.0 {
                            let (pts, n) = extrema::hermite_critical(a, knot);
                            pts[..n].iter().for_each(|p| offer(*p));
                        }
                    }
                    *prev = Some(knot);
                }
            }
        });
        env.into_iter()
            .map(|cols| {
                let mut pts = Vec::with_capacity(2 * columns);
                for (lo, hi) in cols {
                    if lo.1.is_finite() && hi.1.is_finite() {
                        let (a, b) = if lo.0 <= hi.0 { (lo, hi) } else { (hi, lo) };
                        pts.push(a);
                        if b != a {
                            pts.push(b);
                        }
                    }
                }
                pts
            })
            .collect()
    }

    /// The largest |value| of every channel on [0, duration] and its time, and the largest
    /// magnitude √(Σ v_c²) of every group of channels (a force's or a moment's components),
    /// exact to [`extrema::TOLERANCE`] of the channel's scale at any output rate
    /// ([`extrema`]): the first pass evaluates every mode on one grid of spacing
    /// π / (4 ω_max) and the channels from them in bulk, as the samples are.
    pub fn peaks(
        &self,
        modal: &ModalAnalysis,
        channels: &[Channel],
        groups: &[Vec<usize>],
        duration: f64,
    ) -> (Vec<Peak>, Vec<Peak>) {
        let signals = self.signals(modal, channels);
        let fastest = signals.iter().map(WaveSum::fastest).fold(0.0, f64::max);
        let grid = extrema::grid(fastest, duration.max(0.0));
        // Each segment of the grid searched on its own, the searches then merged in time order.
        let init = || {
            let norms: Vec<PeakSearch<SquaredNorm>> = groups
                .iter()
                .map(|g| {
                    let parts: Vec<&WaveSum> = g.iter().map(|&c| &signals[c]).collect();
                    PeakSearch::new(SquaredNorm::new(&parts, duration.max(0.0)))
                })
                .collect();
            let searches: Vec<PeakSearch<Scalar>> = signals
                .iter()
                .map(|s| PeakSearch::new(Scalar::new(s, duration.max(0.0))))
                .collect();
            (searches, norms, Vec::new())
        };
        let segments = self.on_grid_segments(
            modal,
            channels,
            &grid,
            init,
            |(searches, norms, knots), times, values, slopes| {
                let rows = times.len();
                for (c, search) in searches.iter_mut().enumerate() {
                    knots.clear();
                    knots.extend((0..rows).map(|i| (times[i], values[(i, c)], slopes[(i, c)])));
                    search.feed(knots);
                }
                for (group, search) in groups.iter().zip(norms.iter_mut()) {
                    knots.clear();
                    knots.extend((0..rows).map(|i| {
                        group.iter().fold((times[i], 0.0, 0.0), |(t, g, dg), &c| {
                            let v = values[(i, c)];
                            (t, g + v * v, dg + 2.0 * v * slopes[(i, c)])
                        })
                    }));
                    search.feed(knots);
                }
            },
        );
        let mut parts = segments.into_iter();
        let (mut searches, mut norms, _) = parts.next().unwrap_or_else(init);
        for (s, n, _) in parts {
            searches = searches
                .into_iter()
                .zip(s)
                .map(|(a, b)| a.merge(b))
                .collect();
            norms = norms.into_iter().zip(n).map(|(a, b)| a.merge(b)).collect();
        }
        (
            searches.into_iter().map(PeakSearch::finish).collect(),
            norms
                .into_iter()
                .map(|s| {
                    let (g, t) = s.finish();
                    (g.sqrt(), t)
                })
                .collect(),
        )
    }
}

/// The channel groups whose magnitude is a load: each beam root's force and moment, the
/// first and last three of its six channels ([`super::loads`]).
fn vector_groups(channels: &[Channel]) -> Vec<Vec<usize>> {
    let mut beams: Vec<&str> = Vec::new();
    for c in channels {
        if let ChannelKind::BeamRoot { beam } = &c.kind {
            if !beams.contains(&beam.as_str()) {
                beams.push(beam);
            }
        }
    }
    let mut out = Vec::new();
    for beam in beams {
        let cs: Vec<usize> = channels
            .iter()
            .enumerate()
            .filter(|(_, c)| matches!(&c.kind, ChannelKind::BeamRoot { beam: b } if b == beam))
            .map(|(i, _)| i)
            .collect();
        if cs.len() == 6 {
            out.push(cs[..3].to_vec());
            out.push(cs[3..].to_vec());
        }
    }
    out
}

/// What [`ModalResponse::on_grid`] hands each piece: (times, values, slopes).
pub type GridPiece<'a> = dyn FnMut(&[f64], MatRef<'_, f64>, MatRef<'_, f64>) + 'a;

/// A peak |value| and its time (s after the hand-over).
pub type Peak = (f64, f64);

/// Grids longer than this many knots are walked in [`SEGMENTS`] segments side by side.
const SEGMENT_KNOTS: usize = 100_000;

/// The segments of a long grid ([`ModalResponse::on_grid_segments`]): a fixed count, so that
/// the results are the same on any number of cores.
const SEGMENTS: usize = 8;

/// Grid intervals evaluated together in [`ModalResponse::peaks`].
const PEAK_CHUNK: usize = 2048;

/// Samples at t_k = k·h of one mode into `eta`, its rate into `eta_dot` and its acceleration
/// η̈ = −2ζωη̇ − ω²η into `eta_dd`, adding its energy to `energy` (elastic modes).
fn fill_mode(
    m: &KeptMode,
    h: f64,
    eta: &mut [f64],
    eta_dot: &mut [f64],
    eta_dd: &mut [f64],
    energy: &mut [f64],
) {
    fill_state(m, 0.0, h, eta, eta_dot);
    if m.rigid || m.omega_rad_s == 0.0 {
        eta_dd.fill(0.0);
        return;
    }
    let (w, zeta) = (m.omega_rad_s, m.zeta);
    for k in 0..eta.len() {
        let (e, ed) = (eta[k], eta_dot[k]);
        eta_dd[k] = -2.0 * zeta * w * ed - w * w * e;
        energy[k] += 0.5 * (ed * ed + w * w * e * e);
    }
}

/// η and η̇ of one mode at t_k = t₀ + k·h. Within blocks of [`RESYNC`] samples the phase
/// advances by the rotation (cos, sin)(θ + ω_d h) = (c cos ω_d h − s sin ω_d h,
/// s cos ω_d h + c sin ω_d h) and the decay by the factor e^{−ζωh}; each block starts from the
/// closed form at its own time, so rounding cannot accumulate beyond RESYNC steps (≈ 1e-14
/// relative).
fn fill_state(m: &KeptMode, t0: f64, h: f64, eta: &mut [f64], eta_dot: &mut [f64]) {
    if m.rigid || m.omega_rad_s == 0.0 {
        for (k, (e, ed)) in eta.iter_mut().zip(eta_dot.iter_mut()).enumerate() {
            *e = m.eta0 + m.eta_dot0 * (t0 + k as f64 * h);
            *ed = m.eta_dot0;
        }
        return;
    }
    let (w, zeta) = (m.omega_rad_s, m.zeta);
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let (a, b) = (m.eta0, (m.eta_dot0 + zeta * w * m.eta0) / wd);
    let (sd, cd) = (wd * h).sin_cos();
    let step_decay = (-zeta * w * h).exp();
    for k0 in (0..eta.len()).step_by(RESYNC) {
        let tb = t0 + k0 as f64 * h;
        let (mut s, mut c) = (wd * tb).sin_cos();
        let mut decay = (-zeta * w * tb).exp();
        let end = (k0 + RESYNC).min(eta.len());
        for k in k0..end {
            let e = decay * (a * c + b * s);
            eta[k] = e;
            eta_dot[k] = -zeta * w * e + decay * wd * (b * c - a * s);
            (s, c) = (s * cd + c * sd, c * cd - s * sd);
            decay *= step_decay;
        }
    }
}

/// Samples between two closed-form evaluations in [`fill_state`].
const RESYNC: usize = 32;

fn state(m: &KeptMode, t: f64) -> (f64, f64) {
    if m.rigid || m.omega_rad_s == 0.0 {
        return (m.eta0 + m.eta_dot0 * t, m.eta_dot0);
    }
    let (w, zeta) = (m.omega_rad_s, m.zeta);
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let (s, c) = (wd * t).sin_cos();
    let decay = (-zeta * w * t).exp();
    let b = (m.eta_dot0 + zeta * w * m.eta0) / wd;
    let eta = decay * (m.eta0 * c + b * s);
    // d/dt: −ζω η + e^{−ζωt}[−η₀ ω_d sin + b ω_d cos].
    let eta_dot = -zeta * w * eta + decay * wd * (b * c - m.eta0 * s);
    (eta, eta_dot)
}

impl ResponseHistory {
    /// Largest |E(t) − E(0)| / E(0) of the elastic energy (0 when there is none).
    pub fn energy_drift(&self) -> f64 {
        let e0 = self.elastic_energy.first().copied().unwrap_or(0.0);
        if e0 <= 0.0 {
            return 0.0;
        }
        self.elastic_energy
            .iter()
            .map(|e| (e - e0).abs() / e0)
            .fold(0.0, f64::max)
    }

    /// Largest |value| of channel c on [0, duration] and the time it occurs, from the
    /// closed form (not from the samples: [`ModalResponse::peaks`]).
    pub fn peak(&self, c: usize) -> (f64, f64) {
        self.peaks[c]
    }

    /// Largest |value| of channel c among the samples, and its time (what a plot of the
    /// samples shows; never above [`Self::peak`] beyond its tolerance).
    pub fn sampled_peak(&self, c: usize) -> (f64, f64) {
        let mut best = (0.0, 0.0);
        for (k, &t) in self.times.iter().enumerate() {
            let v = self.values[(k, c)];
            if v.abs() > best.0 {
                best = (v.abs(), t);
            }
        }
        best
    }

    /// The largest magnitude of the vector of channels `cs` (a beam root's force or moment:
    /// [`Self::vector_peaks`]; one channel: [`Self::peak`]), None for another group.
    pub fn vector_peak(&self, cs: &[usize]) -> Option<(f64, f64)> {
        match cs {
            [c] => self.peaks.get(*c).copied(),
            _ => self
                .vector_peaks
                .iter()
                .find(|(g, _)| g.as_slice() == cs)
                .map(|(_, p)| *p),
        }
    }

    /// The value of channel c at the last sample.
    pub fn last(&self, c: usize) -> f64 {
        self.values[(self.times.len() - 1, c)]
    }
}
