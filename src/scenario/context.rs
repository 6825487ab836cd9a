//! The parsing context: the source text and file name, and the one way every section maps a
//! refusal to `file:line:column: key: reason`.

use super::error::{ErrorKind, LineIndex, Location, ScenarioError};
use super::raw::S;
use crate::limits::Limit;
use crate::structure::{Field, StructureError};
use std::ops::Range;

/// Where the text came from.
pub(super) struct Ctx<'a> {
    pub(super) src: &'a str,
    pub(super) file: &'a str,
    lines: LineIndex,
}

impl<'a> Ctx<'a> {
    pub(super) fn new(src: &'a str, file: &'a str) -> Self {
        Self {
            src,
            file,
            lines: LineIndex::new(src),
        }
    }

    pub(super) fn location(&self, span: &Range<usize>) -> Location {
        self.lines.locate(self.src, span.start)
    }

    pub(super) fn err(
        &self,
        kind: ErrorKind,
        span: Range<usize>,
        key: impl Into<String>,
        reason: impl Into<String>,
    ) -> ScenarioError {
        ScenarioError {
            kind,
            file: self.file.to_string(),
            location: self.location(&span),
            key: key.into(),
            reason: reason.into(),
        }
    }

    pub(super) fn invalid(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        reason: impl Into<String>,
    ) -> ScenarioError {
        self.err(ErrorKind::Invalid, span, key, reason)
    }

    /// A missing key (a schema error) reported at `span`.
    pub(super) fn missing(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        reason: impl Into<String>,
    ) -> ScenarioError {
        self.err(ErrorKind::Schema, span, key, reason)
    }

    /// A domain constructor's refusal, located by the section's own map from the failing
    /// [`Field`] to where (span) and as what (key) it was written.
    pub(super) fn domain<T>(
        &self,
        r: Result<T, StructureError>,
        at: impl Fn(Field) -> (Range<usize>, String),
    ) -> Result<T, ScenarioError> {
        r.map_err(|e| {
            let (span, key) = at(e.field());
            self.invalid(span, key, e.to_string())
        })
    }

    /// A scalar inside its accepted range (for the settings the scenario layer owns:
    /// `[deployment]`, `[response]`).
    pub(super) fn bounded(
        &self,
        v: &S<f64>,
        key: impl Into<String>,
        lim: Limit,
    ) -> Result<f64, ScenarioError> {
        let x = *v.get_ref();
        if lim.contains(x) {
            Ok(x)
        } else {
            Err(self.invalid(v.span(), key, lim.refusal(x)))
        }
    }

    /// An optional scalar inside its range, or `default` when absent.
    pub(super) fn bounded_or(
        &self,
        v: &Option<S<f64>>,
        default: f64,
        key: impl Into<String>,
        lim: Limit,
    ) -> Result<f64, ScenarioError> {
        match v {
            Some(x) => self.bounded(x, key, lim),
            None => Ok(default),
        }
    }
}

/// A term count as written (an integer of any sign) for the domain constructor to check;
/// values that do not fit a `usize` become 0, which it refuses.
pub(super) fn count(v: &Option<S<i64>>, default: usize) -> usize {
    v.as_ref()
        .map_or(default, |t| usize::try_from(*t.get_ref()).unwrap_or(0))
}

/// The span of an optional value, or `fallback`.
pub(super) fn span_or<T>(v: &Option<S<T>>, fallback: Range<usize>) -> Range<usize> {
    v.as_ref().map_or(fallback, |x| x.span())
}
