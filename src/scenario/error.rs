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
    /// Location of a byte offset in `src` (one scan of the text before it; for many lookups
    /// in one text, the parser's line index).
    pub fn of_offset(src: &str, offset: usize) -> Self {
        LineIndex::new(src).locate(src, offset)
    }
}

/// The byte offsets where the lines of a text start: a location in O(log lines) (the
/// scenario's parsing locates every component; a scan per lookup made 10 000 beams take
/// seconds).
#[derive(Debug, Clone)]
pub struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    /// The index of `src`.
    pub fn new(src: &str) -> Self {
        let starts = std::iter::once(0)
            .chain(src.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Self { starts }
    }

    /// Location of a byte offset in `src` (the text this index was made of).
    pub fn locate(&self, src: &str, offset: usize) -> Location {
        let mut o = offset.min(src.len());
        while !src.is_char_boundary(o) {
            o -= 1;
        }
        // The last line start at or before o.
        let line = self.starts.partition_point(|s| *s <= o);
        let line_start = self.starts[line - 1];
        Location {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The index's lookup against a scan of the text before each offset (the definition:
    /// line = newlines before it + 1, column = characters since the last newline + 1), on a
    /// text with multi-byte characters, empty lines and offsets inside a character or past
    /// the end.
    #[test]
    fn the_line_index_locates_like_a_scan() {
        let src = "a = 1\n\nname = \"κ → ω\"\r\n  x = [1, 2]\nlast";
        let index = LineIndex::new(src);
        for offset in 0..=src.len() + 3 {
            let mut o = offset.min(src.len());
            while !src.is_char_boundary(o) {
                o -= 1;
            }
            let before = &src[..o];
            let line = before.matches('\n').count() + 1;
            let start = before.rfind('\n').map_or(0, |i| i + 1);
            let column = src[start..o].chars().count() + 1;
            assert_eq!(
                index.locate(src, offset),
                Location { line, column },
                "offset {offset}"
            );
        }
    }
}
