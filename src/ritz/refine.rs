//! Automatic choice of the Ritz term counts for a requested accuracy, with a per-mode error
//! estimate (docs/theory.md §1.4).
//!
//! Every elastic component's functions fall into *families* that can be refined on their own:
//! a beam's bending (v and w together), torsion and axial functions, a plate's functions
//! along its length and across its width. All bases are hierarchical (the first n functions
//! of a family are the same whatever the count), so
//!
//! * the spaces are nested and every Ritz frequency falls monotonically as any family is
//!   refined (Cauchy interlacing / the min–max principle): ω_k is an upper bound, and the
//!   change Δω_k when one family goes from n to n′ is the part of ω_k's error that family
//!   removed;
//! * the mass and stiffness matrices of a smaller set of functions are a sub-block of those of
//!   a larger set: the model is assembled once at a *ceiling* and each refinement level is an
//!   index selection ([`Ceiling`]), re-assembled only when a family outgrows the ceiling.
//!
//! **Error model.** The error of ω_k is the sum of the families' truncation errors,
//! e_k = Σ_F e_F,k(n_F), each algebraic in the count, e_F,k(n) ≈ C n^(−p) (the corner
//! singularities of plates and the joints bound the rate; smooth components converge faster,
//! and an algebraic model then over-estimates: the estimate stays on the safe side). From a
//! family's last two refinements n₀ → n₁ → n₂ with changes d₁, d₂ the rate p solves
//! d₁/d₂ = (a^p − 1) b^p / (b^p − 1), a = n₁/n₀, b = n₂/n₁ (a Richardson step with the rate
//! fitted, clamped to [`RATE_MIN`, `RATE_MAX`]), and the remaining error is
//! e = d₂ / (b^p − 1), times a safety factor [`SAFETY`]. With one refinement the slowest rate
//! [`RATE_MIN`] is assumed. Because
//! the frequencies converge from above, the estimate is one-sided: the true ω_k lies in
//! [ω_k − e_k, ω_k].
//!
//! **Selection.** Start every automatic family small (enough functions for twice the wanted
//! modes), then repeatedly refine (n → max(n + 1, ⌈1.5 n⌉)) the automatic family whose
//! estimated error is the largest relative to its mode's frequency, until the sum of the
//! estimates is below the tolerance for every wanted mode, or no family can grow without
//! passing `max_dof`. Families with explicit terms are never changed; their error is
//! estimated by two coarser sub-blocks of the same model.

use super::assembly::{ElementKind, FieldKind, RitzModel, HUB_DOF};
use super::modes::elastic_frequencies;
use super::RitzError;
use crate::structure::{ComponentId, Structure, MAX_TERMS};
use faer::Mat;

/// Slowest convergence rate assumed, in ω_k − ω_k,exact ≈ C n^(−p).
pub const RATE_MIN: f64 = 1.0;
/// Fastest rate believed. Measured: a cantilever plate's frequencies converge like n^(−5)
/// in the count along its length (the clamped–free corners' singularities), a beam's faster
/// than any power; early levels often *look* faster than the asymptotic rate, and believing
/// them under-estimates the error. Capping the rate keeps the estimate on the safe side
/// (it over-estimates a faster-converging family, which then costs one refinement more).
pub const RATE_MAX: f64 = 3.0;
/// Factor on every family's estimate: on the composite spacecraft of the tests the
/// coarsest levels (tolerance 1e-3, ~200 coordinates) still under-estimated some modes by up
/// to 2×, before the rates settle; 1.25 keeps those within a factor 1.6.
pub const SAFETY: f64 = 1.25;
/// Growth factor of a refinement.
pub const GROWTH: f64 = 1.5;

/// One refinable family of Ritz functions of one component.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Family {
    /// A beam's bending functions (v and w together).
    Bending(usize),
    /// A beam's torsion functions.
    Torsion(usize),
    /// A beam's axial functions.
    Axial(usize),
    /// A plate's functions along its length.
    Length(usize),
    /// A plate's functions across its width.
    Width(usize),
}

impl Family {
    /// The families of one elastic component (none for rigid ones).
    pub fn of(id: ComponentId) -> Vec<Family> {
        match id {
            ComponentId::Beam(i) => vec![Self::Bending(i), Self::Torsion(i), Self::Axial(i)],
            ComponentId::Plate(i) => vec![Self::Length(i), Self::Width(i)],
            _ => Vec::new(),
        }
    }

    /// The component the family belongs to.
    pub fn component(self) -> ComponentId {
        match self {
            Self::Bending(i) | Self::Torsion(i) | Self::Axial(i) => ComponentId::Beam(i),
            Self::Length(i) | Self::Width(i) => ComponentId::Plate(i),
        }
    }

    /// The field's key in a scenario's `terms` table.
    pub fn key(self) -> &'static str {
        match self {
            Self::Bending(_) => "bending",
            Self::Torsion(_) => "torsion",
            Self::Axial(_) => "axial",
            Self::Length(_) => "length",
            Self::Width(_) => "width",
        }
    }

    /// Number of functions the structure gives the family.
    pub fn count(self, st: &Structure) -> usize {
        match self {
            Self::Bending(i) => st.beams[i].terms.bending,
            Self::Torsion(i) => st.beams[i].terms.torsion,
            Self::Axial(i) => st.beams[i].terms.axial,
            Self::Length(i) => st.plates[i].terms.length,
            Self::Width(i) => st.plates[i].terms.width,
        }
    }

    fn set(self, st: &mut Structure, n: usize) {
        match self {
            Self::Bending(i) => st.beams[i].terms.bending = n,
            Self::Torsion(i) => st.beams[i].terms.torsion = n,
            Self::Axial(i) => st.beams[i].terms.axial = n,
            Self::Length(i) => st.plates[i].terms.length = n,
            Self::Width(i) => st.plates[i].terms.width = n,
        }
    }

    /// The count an automatic family starts from.
    fn start(self) -> usize {
        match self {
            Self::Bending(_) | Self::Length(_) => 4,
            Self::Width(_) => 3,
            Self::Torsion(_) | Self::Axial(_) => 2,
        }
    }
}

/// The next count of a refinement (None at [`MAX_TERMS`]).
fn finer(n: usize) -> Option<usize> {
    let m = ((n as f64 * GROWTH).ceil() as usize).max(n + 1);
    (n < MAX_TERMS).then_some(m.min(MAX_TERMS))
}

/// The previous count of a refinement (None below 2).
fn coarser(n: usize) -> Option<usize> {
    let m = ((n as f64 / GROWTH).floor() as usize).min(n - 1);
    (n >= 2 && m >= 1).then_some(m)
}

/// Generalized coordinates of a structure's model, hub included.
fn dof(st: &Structure) -> usize {
    HUB_DOF
        + st.beams.iter().map(|b| b.terms.dof()).sum::<usize>()
        + st.plates.iter().map(|p| p.terms.dof()).sum::<usize>()
}

/// What accuracy to reach and within what size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    /// Relative tolerance on the frequencies of the wanted modes.
    pub tolerance: f64,
    /// Number of lowest elastic modes wanted.
    pub modes: usize,
    /// Largest model, generalized coordinates (hub included).
    pub max_dof: usize,
}

/// Default tolerance of a scenario whose components give no terms.
pub const DEFAULT_TOLERANCE: f64 = 1e-4;
/// Default number of wanted elastic modes.
pub const DEFAULT_MODES: usize = 20;
/// Default size limit.
pub const DEFAULT_MAX_DOF: usize = 1500;

impl Default for Accuracy {
    fn default() -> Self {
        Self {
            tolerance: DEFAULT_TOLERANCE,
            modes: DEFAULT_MODES,
            max_dof: DEFAULT_MAX_DOF,
        }
    }
}

/// One family's chosen count and its share of the error estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct FamilyError {
    /// The family.
    pub family: Family,
    /// Its count in the chosen model.
    pub terms: usize,
    /// Chosen by the selection (false: given in the scenario).
    pub automatic: bool,
    /// Estimated error of each wanted mode's ω left by this family's truncation, relative
    /// to ω (infinite when it could not be estimated: a single function).
    pub error: Vec<f64>,
}

/// The outcome of [`select_terms`].
#[derive(Debug, Clone)]
pub struct TermSelection {
    /// The structure with the chosen counts.
    pub structure: Structure,
    /// What was asked.
    pub accuracy: Accuracy,
    /// Generalized coordinates of the chosen model (hub included).
    pub dof: usize,
    /// Frequencies ω [rad/s] of the wanted modes in the chosen model.
    pub omega: Vec<f64>,
    /// Estimated relative error of each wanted mode's frequency, (ω − ω_exact)/ω ≥ 0.
    pub frequency_error: Vec<f64>,
    /// Per family.
    pub families: Vec<FamilyError>,
    /// Every estimate below the tolerance.
    pub reached: bool,
    /// Eigen-solves made.
    pub solves: usize,
    /// Model assemblies made.
    pub assemblies: usize,
}

/// A model assembled at counts at least those of every level it serves: each level's
/// matrices are an index selection of its own (the bases are hierarchical).
struct Ceiling {
    model: RitzModel,
}

impl Ceiling {
    fn new(st: &Structure) -> Self {
        Self {
            model: RitzModel::assemble(st),
        }
    }

    fn covers(&self, st: &Structure, families: &[Family]) -> bool {
        families
            .iter()
            .all(|f| f.count(st) <= f.count(&self.model.structure))
    }

    /// The global indices of `st`'s coordinates in the ceiling model, in `st`'s own order.
    fn indices(&self, st: &Structure) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..HUB_DOF).collect();
        for e in &self.model.elements {
            match e.kind {
                ElementKind::Beam { index, .. } => {
                    let t = st.beams[index].terms;
                    for f in &e.fields {
                        let n = match f.kind {
                            FieldKind::U => t.axial,
                            FieldKind::V | FieldKind::W => t.bending,
                            _ => t.torsion,
                        };
                        idx.extend(f.start..f.start + n);
                    }
                }
                ElementKind::Plate { index, .. } => {
                    let t = st.plates[index].terms;
                    let full = self.model.structure.plates[index].terms.width;
                    let start = e.own_range().start;
                    for m in 0..t.length {
                        idx.extend((0..t.width).map(|w| start + m * full + w));
                    }
                }
                ElementKind::Rigid => {}
            }
        }
        idx
    }

    /// The `count` lowest elastic ω of `st`'s model.
    fn frequencies(&self, st: &Structure, count: usize) -> Result<Vec<f64>, RitzError> {
        let idx = self.indices(st);
        let pick = |a: &Mat<f64>| Mat::from_fn(idx.len(), idx.len(), |i, j| a[(idx[i], idx[j])]);
        elastic_frequencies(
            &pick(&self.model.mass),
            &pick(&self.model.stiffness),
            st.hub.motion,
            count,
        )
    }
}

/// One refinement of one family: counts and the change of every wanted ω (rad/s).
#[derive(Debug, Clone)]
struct Step {
    from: usize,
    to: usize,
    change: Vec<f64>,
}

/// The step from count `from` (frequencies `coarse`) to `to` (`fine`).
fn step(from: usize, to: usize, coarse: &[f64], fine: &[f64]) -> Step {
    let len = coarse.len().min(fine.len());
    Step {
        from,
        to,
        change: (0..len).map(|k| coarse[k] - fine[k]).collect(),
    }
}

/// The error left in one mode by a family after its last steps (absolute, rad/s).
fn remaining(steps: &[Step], k: usize) -> f64 {
    let d = |s: &Step| s.change.get(k).map_or(f64::INFINITY, |v| v.max(0.0));
    match steps {
        [] => f64::INFINITY,
        [s] => d(s) / ((s.to as f64 / s.from as f64).powf(RATE_MIN) - 1.0),
        [.., s1, s2] => {
            let (d1, d2) = (d(s1), d(s2));
            let a = s1.to as f64 / s1.from as f64;
            let b = s2.to as f64 / s2.from as f64;
            let p = fitted_rate(a, b, d1, d2);
            d2 / (b.powf(p) - 1.0)
        }
    }
}

/// The rate p with (a^p − 1) b^p / (b^p − 1) = d₁/d₂ (increasing in p), by bisection on
/// [`RATE_MIN`, `RATE_MAX`]; the bounds when the ratio lies outside.
pub fn fitted_rate(a: f64, b: f64, d1: f64, d2: f64) -> f64 {
    if d2 <= 0.0 || !d1.is_finite() || !d2.is_finite() {
        return RATE_MIN;
    }
    let target = d1 / d2;
    let g = |p: f64| (a.powf(p) - 1.0) * b.powf(p) / (b.powf(p) - 1.0);
    if target <= g(RATE_MIN) {
        return RATE_MIN;
    }
    if target >= g(RATE_MAX) {
        return RATE_MAX;
    }
    let (mut lo, mut hi) = (RATE_MIN, RATE_MAX);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if g(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The selection's state: counts, ceiling, steps per family.
struct Selector<'a> {
    accuracy: &'a Accuracy,
    structure: Structure,
    families: Vec<(Family, bool)>,
    steps: Vec<Vec<Step>>,
    exhausted: Vec<bool>,
    /// Per family: the round its steps were last measured, the round its count last changed.
    measured_at: Vec<usize>,
    refined_at: Vec<usize>,
    round: usize,
    ceiling: Ceiling,
    omega: Vec<f64>,
    solves: usize,
    assemblies: usize,
}

impl Selector<'_> {
    fn automatic(&self) -> Vec<Family> {
        self.families
            .iter()
            .filter(|(_, auto)| *auto)
            .map(|(f, _)| *f)
            .collect()
    }

    /// ω of the structure with one family's count changed (the ceiling grown if needed).
    fn solve_with(&mut self, family: Family, n: usize) -> Result<Vec<f64>, RitzError> {
        let mut st = self.structure.clone();
        family.set(&mut st, n);
        let auto = self.automatic();
        if !self.ceiling.covers(&st, &auto) {
            // Grow the outgrown families two refinements beyond the need (one, or none, where
            // that would pass max_dof), keep the rest.
            let mut top = self.ceiling.model.structure.clone();
            for f in &auto {
                let need = f.count(&st);
                if need > f.count(&top) {
                    let room = [finer(need).and_then(finer), finer(need)]
                        .into_iter()
                        .flatten()
                        .find(|&g| {
                            let mut t = top.clone();
                            f.set(&mut t, g);
                            dof(&t) <= self.accuracy.max_dof
                        });
                    f.set(&mut top, room.unwrap_or(need));
                }
            }
            self.ceiling = Ceiling::new(&top);
            self.assemblies += 1;
        }
        self.solves += 1;
        self.ceiling.frequencies(&st, self.accuracy.modes)
    }

    /// Estimated error of every wanted mode, per family (absolute, rad/s).
    fn errors(&self) -> Vec<Vec<f64>> {
        self.steps
            .iter()
            .map(|s| {
                (0..self.omega.len())
                    .map(|k| SAFETY * remaining(s, k))
                    .collect()
            })
            .collect()
    }

    /// Refines the automatic family that leaves the largest relative error; false when none
    /// can grow.
    fn refine_worst(&mut self) -> Result<bool, RitzError> {
        let errors = self.errors();
        let mut order: Vec<(f64, usize)> = (0..self.families.len())
            .filter(|&i| self.families[i].1 && !self.exhausted[i])
            .map(|i| {
                let worst = (errors[i].iter().zip(&self.omega))
                    .map(|(e, w)| e / w)
                    .fold(0.0_f64, |a, b| if b.is_nan() { a } else { a.max(b) });
                (worst, i)
            })
            .collect();
        // Largest error first; ties in family order (deterministic).
        order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        for (_, i) in order {
            let f = self.families[i].0;
            let n = f.count(&self.structure);
            let Some(m) = finer(n) else {
                self.exhausted[i] = true;
                continue;
            };
            let mut st = self.structure.clone();
            f.set(&mut st, m);
            if dof(&st) > self.accuracy.max_dof {
                self.exhausted[i] = true;
                continue;
            }
            let omega = self.solve_with(f, m)?;
            self.record(i, n, m, &omega);
            self.structure = st;
            self.omega = omega;
            self.round += 1;
            self.refined_at[i] = self.round;
            self.measured_at[i] = self.round;
            return Ok(true);
        }
        Ok(false)
    }

    /// A family's steps were measured before another family of its component changed
    /// count: the errors of a plate's two directions are not independent (the width's
    /// truncation shows only once the length resolves the mode), so they are measured again.
    fn stale(&self, i: usize) -> bool {
        let c = self.families[i].0.component();
        (0..self.families.len()).any(|j| {
            j != i
                && self.families[j].0.component() == c
                && self.refined_at[j] > self.measured_at[i]
        })
    }

    /// Measures family `i`'s last two steps afresh at the current counts, from two coarser
    /// sub-blocks (n₀ → n₁ → n, the others as they are).
    fn remeasure(&mut self, i: usize) -> Result<(), RitzError> {
        let f = self.families[i].0;
        let n2 = f.count(&self.structure);
        let mut steps = Vec::new();
        if let Some(n1) = coarser(n2) {
            let w1 = self.solve_with(f, n1)?;
            if let Some(n0) = coarser(n1) {
                let w0 = self.solve_with(f, n0)?;
                steps.push(step(n0, n1, &w0, &w1));
            }
            steps.push(step(n1, n2, &w1, &self.omega));
        }
        self.steps[i] = steps;
        self.measured_at[i] = self.round;
        Ok(())
    }

    /// Re-measures every stale family; true if any was.
    fn refresh(&mut self) -> Result<bool, RitzError> {
        let stale: Vec<usize> = (0..self.families.len())
            .filter(|&i| self.stale(i))
            .collect();
        for &i in &stale {
            self.remeasure(i)?;
        }
        Ok(!stale.is_empty())
    }

    fn record(&mut self, i: usize, from: usize, to: usize, finer_omega: &[f64]) {
        let s = step(from, to, &self.omega, finer_omega);
        self.steps[i].push(s);
    }

    /// Relative estimate of every wanted mode: Σ over families.
    fn total(&self) -> Vec<f64> {
        let errors = self.errors();
        (0..self.omega.len())
            .map(|k| errors.iter().map(|e| e[k]).sum::<f64>() / self.omega[k])
            .collect()
    }
}

/// Chooses the counts of the `automatic` components' families (the others keep theirs) so
/// that the estimated relative error of the `accuracy.modes` lowest elastic frequencies is
/// below `accuracy.tolerance`, within `accuracy.max_dof`; estimates every family's error.
/// The result's `structure` is the one to assemble.
pub fn select_terms(
    structure: &Structure,
    automatic: &[ComponentId],
    accuracy: &Accuracy,
) -> Result<TermSelection, RitzError> {
    let mut st = structure.clone();
    let mut families: Vec<(Family, bool)> = Vec::new();
    let ids = (0..st.beams.len())
        .map(ComponentId::Beam)
        .chain((0..st.plates.len()).map(ComponentId::Plate));
    for id in ids {
        let auto = automatic.contains(&id);
        for f in Family::of(id) {
            if auto {
                f.set(&mut st, f.start());
            }
            families.push((f, auto));
        }
    }
    // Enough functions for the wanted modes: grow every automatic family together until the
    // elastic coordinates number four times the wanted modes (the first levels are then
    // closer to the asymptotic rate the estimate assumes), or the size limit stops it.
    let wanted_dof = HUB_DOF + 4 * accuracy.modes + 20;
    while dof(&st) < wanted_dof {
        let mut next = st.clone();
        for (f, _) in families.iter().filter(|(_, a)| *a) {
            if let Some(m) = finer(f.count(&next)) {
                f.set(&mut next, m);
            }
        }
        if dof(&next) == dof(&st) || dof(&next) > accuracy.max_dof {
            break;
        }
        st = next;
    }
    // The first ceiling: every automatic family two refinements up (one, or none, where the
    // size limit says so).
    let mut top = st.clone();
    for steps in [2, 1] {
        top = st.clone();
        for (f, auto) in &families {
            if *auto {
                let n = (0..steps).try_fold(f.count(&st), |n, _| finer(n));
                f.set(&mut top, n.unwrap_or(MAX_TERMS));
            }
        }
        if dof(&top) <= accuracy.max_dof {
            break;
        }
        top = st.clone();
    }
    let ceiling = Ceiling::new(&top);
    let omega = ceiling.frequencies(&st, accuracy.modes)?;
    let n = families.len();
    let mut sel = Selector {
        accuracy,
        structure: st,
        families,
        steps: vec![Vec::new(); n],
        exhausted: vec![false; n],
        measured_at: vec![0; n],
        refined_at: vec![0; n],
        round: 0,
        ceiling,
        omega,
        solves: 1,
        assemblies: 1,
    };
    // Given families: two coarser levels of the same model (sub-blocks, no re-assembly).
    for i in 0..n {
        if !sel.families[i].1 {
            sel.remeasure(i)?;
        }
    }
    // Refine until the estimate is below the tolerance with every family measured at the
    // final counts of its component.
    const MAX_ROUNDS: usize = 500;
    for _ in 0..MAX_ROUNDS {
        let worst = |sel: &Selector| sel.total().iter().fold(0.0_f64, |a, &b| a.max(b));
        if worst(&sel) <= accuracy.tolerance
            && !(sel.refresh()? && worst(&sel) > accuracy.tolerance)
        {
            break;
        }
        if !sel.refine_worst()? {
            sel.refresh()?;
            break;
        }
    }
    let total = sel.total();
    let errors = sel.errors();
    let reached = !total.is_empty() && total.iter().all(|e| *e <= accuracy.tolerance);
    let families = (sel.families.iter().zip(&errors))
        .map(|(&(family, automatic), e)| FamilyError {
            family,
            terms: family.count(&sel.structure),
            automatic,
            error: e.iter().zip(&sel.omega).map(|(e, w)| e / w).collect(),
        })
        .collect();
    Ok(TermSelection {
        dof: dof(&sel.structure),
        structure: sel.structure,
        accuracy: *accuracy,
        omega: sel.omega,
        frequency_error: total,
        families,
        reached,
        solves: sel.solves,
        assemblies: sel.assemblies,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fitted rate recovers an exactly algebraic sequence, and the remaining error is
    /// then exact: e(n) = n^(−p) sampled at 4, 6, 9.
    #[test]
    fn algebraic_sequences_are_extrapolated_exactly() {
        for p in [1.5, 2.0, 3.0] {
            let e = |n: f64| n.powf(-p);
            let steps = [
                Step {
                    from: 4,
                    to: 6,
                    change: vec![e(4.0) - e(6.0)],
                },
                Step {
                    from: 6,
                    to: 9,
                    change: vec![e(6.0) - e(9.0)],
                },
            ];
            let r = remaining(&steps, 0);
            assert!(
                (r / e(9.0) - 1.0).abs() < 1e-9,
                "p = {p}: {r} vs {}",
                e(9.0)
            );
        }
    }

    /// Exponential convergence (faster than any power): the algebraic model over-estimates.
    #[test]
    fn exponential_sequences_are_over_estimated() {
        let e = |n: f64| (-1.3 * n).exp();
        let steps = [
            Step {
                from: 4,
                to: 6,
                change: vec![e(4.0) - e(6.0)],
            },
            Step {
                from: 6,
                to: 9,
                change: vec![e(6.0) - e(9.0)],
            },
        ];
        assert!(remaining(&steps, 0) >= e(9.0));
    }

    #[test]
    fn counts_grow_and_shrink_by_the_growth_factor() {
        assert_eq!(finer(1), Some(2));
        assert_eq!(finer(4), Some(6));
        assert_eq!(finer(6), Some(9));
        assert_eq!(finer(MAX_TERMS), None);
        assert_eq!(coarser(9), Some(6));
        assert_eq!(coarser(2), Some(1));
        assert_eq!(coarser(1), None);
    }
}
