//! `[response]`: the latch-excited vibration after the final latch.

use super::context::Ctx;
use super::raw::{RawHandover, RawResponse, S};
use super::ScenarioError;
use crate::limits as L;
use crate::response::{HandoverMethod, ResponseSettings};

/// `[response]` (docs/scenario.md): duration > 0, output_rate > 0 with at most
/// [`crate::response::MAX_ROWS`] samples, modes ≥ 1 (clamped later to the model's count,
/// with a warning), 0 ≤ damping_ratio < 1.
pub(super) fn lower(cx: &Ctx, r: &S<RawResponse>) -> Result<ResponseSettings, ScenarioError> {
    let d = ResponseSettings::default();
    let rr = r.get_ref();
    let duration = match &rr.duration {
        Some(v) => cx.bounded(v, "response.duration", L::DURATION)?,
        None => d.duration,
    };
    let output_rate = match &rr.output_rate {
        Some(v) => cx.bounded(v, "response.output_rate", L::OUTPUT_RATE)?,
        None => d.output_rate,
    };
    let rows = crate::response::rows(duration, output_rate);
    if rows > crate::response::MAX_ROWS {
        let span = rr
            .output_rate
            .as_ref()
            .or(rr.duration.as_ref())
            .map_or(r.span(), |v| v.span());
        return Err(cx.invalid(
            span,
            "response.output_rate",
            format!(
                "{duration} s at {output_rate} Hz would write {rows} rows; the limit is {} \
                 (lower output_rate or duration)",
                crate::response::MAX_ROWS
            ),
        ));
    }
    let modes = match &rr.modes {
        None => None,
        Some(m) => {
            let k = *m.get_ref();
            if k < 1 {
                return Err(cx.invalid(
                    m.span(),
                    "response.modes",
                    format!("must be at least 1 (elastic modes kept), got {k}"),
                ));
            }
            Some(k as usize)
        }
    };
    let damping_ratio = match &rr.damping_ratio {
        None => d.damping_ratio,
        Some(v) if L::DAMPING_RATIO.contains(*v.get_ref()) => *v.get_ref(),
        Some(v) => {
            return Err(cx.invalid(
                v.span(),
                "response.damping_ratio",
                format!(
                    "must lie in [0, 1): below 1 (an underdamped structure), got {}",
                    v.get_ref()
                ),
            ))
        }
    };
    Ok(ResponseSettings {
        duration,
        output_rate,
        modes,
        damping_ratio,
        handover: match rr.handover.as_ref().map(|h| *h.get_ref()) {
            Some(RawHandover::Impulse) => HandoverMethod::Impulse,
            _ => HandoverMethod::Projection,
        },
    })
}
