//! `[ritz]`: the basis, and the accuracy the automatic term selection aims at
//! ([`crate::ritz::refine`]).

use super::context::Ctx;
use super::raw::{RawScenario, S};
use super::ScenarioError;
use crate::limits as L;
use crate::ritz::refine::{self, Accuracy, TermSelection};
use crate::structure::{ComponentId, Structure};

/// An integer key in `lo..=hi`.
fn int_in(cx: &Ctx, v: &S<i64>, key: &str, lo: usize, hi: usize) -> Result<usize, ScenarioError> {
    let x = *v.get_ref();
    match usize::try_from(x) {
        Ok(n) if (lo..=hi).contains(&n) => Ok(n),
        _ => Err(cx.invalid(
            v.span(),
            key,
            format!("must be an integer from {lo} to {hi}, got {x}"),
        )),
    }
}

/// Chooses the term counts of the components written without `terms` (and estimates the
/// frequency error of every component) when any component is automatic or
/// `[ritz] tolerance` is given; `None` otherwise (every count as written, no estimate).
///
/// The wanted modes: `[ritz] modes`, else the larger of `[response] modes` and `[export]
/// modes` (`used_modes`), else [`refine::DEFAULT_MODES`]. `max_dof` must leave room for the components with given terms.
pub(super) fn select(
    cx: &Ctx,
    raw: &RawScenario,
    structure: &Structure,
    used_modes: Option<usize>,
) -> Result<Option<TermSelection>, ScenarioError> {
    let automatic: Vec<ComponentId> = (raw.beams.iter().enumerate())
        .filter(|(_, b)| b.get_ref().terms.is_none())
        .map(|(i, _)| ComponentId::Beam(i))
        .chain(
            (raw.plates.iter().enumerate())
                .filter(|(_, p)| p.get_ref().terms.is_none())
                .map(|(i, _)| ComponentId::Plate(i)),
        )
        .collect();
    let r = raw.ritz.as_ref().map(|r| r.get_ref());
    let tolerance = r.and_then(|r| r.tolerance.as_ref());
    // The ranges hold whether or not a selection runs (every component with its own terms
    // and no tolerance: `modes` and `max_dof` then have nothing to steer, but a value out of
    // range is still a mistake in the file).
    let given_modes = match r.and_then(|r| r.modes.as_ref()) {
        Some(m) => Some(int_in(cx, m, "ritz.modes", 1, L::MAX_RITZ_MODES)?),
        None => None,
    };
    let given_max_dof = match r.and_then(|r| r.max_dof.as_ref()) {
        Some(m) => Some((int_in(cx, m, "ritz.max_dof", 7, L::MAX_RITZ_DOF)?, m)),
        None => None,
    };
    if automatic.is_empty() && tolerance.is_none() {
        return Ok(None);
    }
    let d = Accuracy::default();
    let tolerance = match tolerance {
        Some(t) => cx.bounded(t, "ritz.tolerance", L::RITZ_TOLERANCE)?,
        None => d.tolerance,
    };
    let modes = given_modes.unwrap_or_else(|| used_modes.unwrap_or(d.modes).min(L::MAX_RITZ_MODES));
    let given: usize = crate::ritz::HUB_DOF
        + (structure.beams().iter().enumerate())
            .filter(|(i, _)| !automatic.contains(&ComponentId::Beam(*i)))
            .map(|(_, b)| b.terms.dof())
            .sum::<usize>()
        + (structure.plates().iter().enumerate())
            .filter(|(i, _)| !automatic.contains(&ComponentId::Plate(*i)))
            .map(|(_, p)| p.dof())
            .sum::<usize>();
    let max_dof = match given_max_dof {
        Some((n, m)) => {
            if n < given {
                return Err(cx.invalid(
                    m.span(),
                    "ritz.max_dof",
                    format!(
                        "the components with given terms already have {given} coordinates \
                         (hub included), more than max_dof = {n}"
                    ),
                ));
            }
            n
        }
        None => d.max_dof.max(given),
    };
    let accuracy = Accuracy {
        tolerance,
        modes,
        max_dof,
    };
    refine::select_terms(structure, &automatic, &accuracy)
        .map(Some)
        .map_err(|e| {
            let span = raw.ritz.as_ref().map_or(0..0, |r| r.span());
            cx.invalid(
                span,
                "ritz",
                format!(
                    "the automatic term selection could not solve its first level for {modes} \
                     modes ({e}): a limit of the selection's solver at this size, not a fault \
                     of the structure; ask for fewer modes, or give every component its terms"
                ),
            )
        })
}
