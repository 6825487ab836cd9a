//! User text (component and scenario names) on its way into an output, escaped once per
//! destination: CSV fields ([`csv_writer`]), HTML text and attributes ([`html`]), JSON inside
//! an HTML `<script>` element ([`script_json`]) and file names ([`file_stems`]). Names are
//! also validated when the scenario is parsed; these functions do not rely on it.

use serde_json::Value;
use std::collections::HashSet;

/// A CSV writer: comma-separated, `\n`-terminated, a field quoted only when it must be (a
/// comma, a quote or a line break in it), so ordinary names and numbers are written as they
/// are and any name reads back as exactly one field.
pub(crate) fn csv_writer<W: std::io::Write>(w: W) -> csv::Writer<W> {
    csv::WriterBuilder::new()
        .quote_style(csv::QuoteStyle::Necessary)
        .from_writer(w)
}

/// A CSV file built in memory by `rows` (for the small files).
pub(crate) fn csv_bytes(
    rows: impl FnOnce(&mut csv::Writer<Vec<u8>>) -> csv::Result<()>,
) -> std::io::Result<Vec<u8>> {
    let mut w = csv_writer(Vec::new());
    rows(&mut w).map_err(std::io::Error::other)?;
    w.into_inner()
        .map_err(|e| std::io::Error::other(e.to_string()))
}

/// HTML-escapes user text for element content and quoted attribute values.
pub(crate) fn html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&#39;")
}

/// JSON for the content of a `<script type="application/json">` element. Every `<` is written
/// as `\u003c` (valid JSON, the same string once parsed), so neither `</script>` nor `<!--`
/// nor `<script` can appear and the HTML parser's state cannot change inside the element;
/// U+2028 and U+2029 are escaped too (line terminators to a JavaScript parser).
pub(crate) fn script_json(v: &Value) -> String {
    serde_json::to_string(v)
        .unwrap_or_default()
        .replace('<', "\\u003c")
        .replace('\u{2028}', "\\u2028")
        .replace('\u{2029}', "\\u2029")
}

/// Longest stem kept from a name before it is considered changed.
const MAX_STEM: usize = 64;

/// A name reduced to the characters `A–Z a–z 0–9 _ - .`, everything else replaced by `_`, a
/// leading `.` replaced by `_` (no hidden files, never `.` or `..`) and at most
/// [`MAX_STEM`] characters; an empty name becomes `_`.
fn sanitise(name: &str) -> String {
    let mut s: String = name
        .chars()
        .take(MAX_STEM)
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.starts_with('.') {
        s.replace_range(0..1, "_");
    }
    if s.is_empty() {
        s.push('_');
    }
    s
}

/// File-name stems for the components `names` (in order), one each, distinct even on a
/// case-insensitive file system and safe as a path component. A name made only of the
/// characters above (not starting with `.`, at most 64 characters) is its own stem, so
/// ordinary names give the file names they always gave; any other name, or one that would
/// collide with an earlier stem, gets its sanitised form followed by `_` and its 1-based
/// index in `names` (and more `_` should even that be taken).
pub fn file_stems(names: &[&str]) -> Vec<String> {
    let key = |s: &str| s.to_ascii_lowercase();
    let sanitised: Vec<String> = names.iter().map(|n| sanitise(n)).collect();
    let mut taken: HashSet<String> = HashSet::new();
    let mut out: Vec<Option<String>> = vec![None; names.len()];
    // Unchanged names first: they keep their stem whatever comes before them.
    for (i, (n, s)) in names.iter().zip(&sanitised).enumerate() {
        if *n == s && taken.insert(key(s)) {
            out[i] = Some(s.clone());
        }
    }
    for (i, s) in sanitised.iter().enumerate() {
        if out[i].is_some() {
            continue;
        }
        let mut stem = format!("{s}_{}", i + 1);
        while !taken.insert(key(&stem)) {
            stem.push('_');
        }
        out[i] = Some(stem);
    }
    out.into_iter().map(Option::unwrap_or_default).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    const HOSTILE: [&str; 12] = [
        "a,b\"q",
        "<!--<script>",
        "x/../../y",
        "..",
        ".",
        "",
        "a\nb\r\nc",
        "C:\\evil",
        "wing",
        "WING",
        "wing_9",
        "ünïcode\u{2028}",
    ];

    #[test]
    fn csv_fields_read_back_exactly() {
        let bytes = csv_bytes(|w| {
            w.write_record(HOSTILE.iter().map(|n| format!("{n} [m]")))?;
            w.write_record((0..HOSTILE.len()).map(|k| format!("{k}e-3")))
        })
        .unwrap();
        let mut r = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(&bytes[..]);
        let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
        assert_eq!(rows.len(), 2);
        let header: Vec<&str> = rows[0].iter().collect();
        let want: Vec<String> = HOSTILE.iter().map(|n| format!("{n} [m]")).collect();
        assert_eq!(header, want);
        // Ordinary fields are not quoted: the same bytes as before the csv crate.
        let plain =
            csv_bytes(|w| w.write_record(["t [s]", "wing_tip_+ [m]", "1.5e0", ""])).unwrap();
        assert_eq!(plain, b"t [s],wing_tip_+ [m],1.5e0,\n");
    }

    #[test]
    fn script_json_cannot_change_the_html_parser_state() {
        let v = json!({"names": HOSTILE, "</script><script>alert(1)</script>": "<!-- </SCRIPT"});
        let s = script_json(&v);
        for bad in ["<", "\u{2028}", "\u{2029}"] {
            assert!(!s.contains(bad), "{bad:?} in {s}");
        }
        let back: Value = serde_json::from_str(&s).unwrap();
        assert_eq!(back, v);
    }

    #[test]
    fn html_escapes_markup() {
        let e = html("<!--<script>\"'&");
        assert_eq!(e, "&lt;!--&lt;script&gt;&quot;&#39;&amp;");
    }

    #[test]
    fn file_stems_are_safe_distinct_and_keep_ordinary_names() {
        let stems = file_stems(&HOSTILE);
        let mut seen = HashSet::new();
        for (n, s) in HOSTILE.iter().zip(&stems) {
            assert!(!s.is_empty() && s.len() <= MAX_STEM + 8, "{n:?} → {s:?}");
            assert!(
                s.chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.')),
                "{n:?} → {s:?}"
            );
            assert!(!s.starts_with('.'), "{n:?} → {s:?}");
            assert!(
                seen.insert(s.to_ascii_lowercase()),
                "collision at {n:?} → {s:?}"
            );
        }
        assert_eq!(stems[8], "wing");
        assert_eq!(stems[9], "WING_10"); // case-insensitive collision with "wing"
        assert_eq!(stems[10], "wing_9"); // an ordinary name keeps its stem...
        assert_eq!(stems[3], "_._4");
        // ...and a changed name never takes an ordinary one's: "a/b" (→ a_b_1) vs "a_b_1".
        assert_eq!(file_stems(&["a/b", "a_b_1"]), ["a_b_1_", "a_b_1"]);
        assert_eq!(file_stems(&["mast", "wing"]), ["mast", "wing"]);
        let long = "x".repeat(200);
        assert_eq!(file_stems(&[&long])[0], format!("{}_1", "x".repeat(64)));
    }
}
