//! Scenario errors: every refusal names the file, line:column, key and reason.

use thiserror::Error;

/// What kind of problem the scenario has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file could not be read.
    Io,
    /// Not valid TOML.
    Syntax,
    /// Valid TOML, but an unknown or missing key, or a value of the wrong type.
    Schema,
    /// A value that is not physical or not consistent with the rest.
    Invalid,
}

/// A 1-based line and column (columns count characters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Location {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1.
    pub column: usize,
}

impl Location {
    /// Location of a byte offset in `src`.
    pub fn of_offset(src: &str, offset: usize) -> Self {
        let offset = offset.min(src.len());
        let mut o = offset;
        while !src.is_char_boundary(o) {
            o -= 1;
        }
        let before = &src[..o];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Self {
            line,
            column: src[line_start..o].chars().count() + 1,
        }
    }
}

/// A scenario refused, with where and why.
#[derive(Debug, Clone, PartialEq, Error)]
pub struct ScenarioError {
    /// Kind of problem.
    pub kind: ErrorKind,
    /// The file (as given by the caller).
    pub file: String,
    /// Where in the file.
    pub location: Location,
    /// The key, as a dotted path (e.g. `beams[0].section.tube.wall`).
    pub key: String,
    /// Why it is refused.
    pub reason: String,
}

/// Longest key shown in a message, characters.
pub const MAX_KEY_CHARS: usize = 80;
/// Longest reason shown in a message, characters (about one screen line or three).
pub const MAX_REASON_CHARS: usize = 240;

/// `s` cut to at most `max` characters, with an ellipsis when cut; control characters shown
/// as escapes so a message stays on one line.
pub fn truncate(s: &str, max: usize) -> String {
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i == max {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

impl std::fmt::Display for ScenarioError {
    /// `file:line:column: key: reason`, or `file: reason` when the file could not be read;
    /// keys and reasons are cut to one screen (`MAX_KEY_CHARS`, `MAX_REASON_CHARS`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let reason = truncate(&self.reason, MAX_REASON_CHARS);
        if self.kind == ErrorKind::Io {
            write!(f, "{}: cannot read the scenario: {reason}", self.file)
        } else {
            write!(
                f,
                "{}:{}:{}: {}: {reason}",
                self.file,
                self.location.line,
                self.location.column,
                truncate(&self.key, MAX_KEY_CHARS)
            )
        }
    }
}
