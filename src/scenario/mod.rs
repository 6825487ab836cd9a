//! Scenario files (TOML, format version 1; keys documented in docs/scenario.md): parsing,
//! validation with the location of every refused value, and construction of the
//! [`Structure`].

mod attach;
mod beams;
mod budget;
mod context;
mod deployment;
mod error;
mod export;
mod hub;
mod masses;
mod materials;
mod montecarlo;
mod overrides;
mod plates;
mod raw;
mod response;
mod ritz;
mod stress;

pub use budget::{default_memory_budget, format_bytes, Estimate, RunParts};
pub use deployment::{DEFAULT_END_TIME, DEFAULT_OUTPUT_RATE, DEFAULT_TOLERANCE};
pub use error::{ErrorKind, Location, ScenarioError};
pub use montecarlo::MAX_RUNS;
pub use overrides::{apply_overrides, DeploymentOverrides, OverrideValue};

use crate::deploy::Deployment;
use crate::response::ResponseSettings;
use crate::structure::{ComponentId, Parts, Structure, StructureError};
use context::Ctx;
use raw::*;
use std::collections::BTreeMap;

/// A validated scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The scenario's name.
    pub name: String,
    /// The deployed structure.
    pub structure: Structure,
    /// The deployment problem, when the file has a `[deployment]` section.
    pub deployment: Option<Deployment>,
    /// The `[response]` settings (defaults when the section is absent).
    pub response: ResponseSettings,
    /// The `[export]` settings (defaults when the section is absent).
    pub export: crate::export::ExportSettings,
    /// The automatic term selection and its frequency-error estimate: present when a
    /// component gives no `terms` or `[ritz] tolerance` is set (then `structure` has the
    /// chosen counts).
    pub term_selection: Option<crate::ritz::refine::TermSelection>,
    /// The `[montecarlo]` section (docs/montecarlo.md), when present.
    pub montecarlo: Option<crate::montecarlo::MonteCarlo>,
    /// Allowables, section fibres and the latch's allowable moment (stresses and margins).
    pub stress: crate::response::stress::StressSpec,
    /// Where each component was written, to locate a failure found after parsing.
    sources: Sources,
}

/// The file and the place each component was written (its `name` key; the `[hub]` table).
#[derive(Debug, Clone, Default)]
struct Sources {
    file: String,
    /// The text that was parsed.
    text: String,
    at: BTreeMap<ComponentId, (String, Location)>,
    /// Keys located after parsing (`response.output_rate`, …): the value, or its section.
    keys: BTreeMap<&'static str, Location>,
    /// Where each `[montecarlo.dispersions]` entry was written.
    dispersions: Vec<(String, Location)>,
}

impl Scenario {
    /// A failure found after parsing (a numerical one, e.g. a mass matrix that is not
    /// positive definite) located at the component it was traced to: `file:line:column:
    /// key: reason`, with the component's key (`beams[0]`, `hub`, …).
    pub fn locate(&self, component: ComponentId, reason: impl Into<String>) -> ScenarioError {
        let (key, location) = self
            .sources
            .at
            .get(&component)
            .cloned()
            .unwrap_or_else(|| ("(structure)".into(), Location { line: 1, column: 1 }));
        ScenarioError {
            kind: ErrorKind::Invalid,
            file: self.sources.file.clone(),
            location,
            key,
            reason: reason.into(),
        }
    }

    /// The scenario's text exactly as it was parsed (e.g. to fingerprint the run's input
    /// without reading the file a second time).
    pub fn source_text(&self) -> &str {
        &self.sources.text
    }

    /// The elastic modes the export keeps: `[export] modes` (or the damping list's length);
    /// with automatic terms and neither given, the modes the selection aimed at (the higher
    /// ones of such a model are not converged); otherwise every mode of the model (`None`).
    pub fn export_modes(&self) -> Option<usize> {
        self.export
            .modes
            .or(self.term_selection.as_ref().map(|s| s.accuracy.modes))
    }

    /// A refusal of `[export] damping_ratio` found once the model's mode count is known (a
    /// list longer than the modes the model has), located where it was written.
    pub fn refuse_export_damping(&self, reason: impl Into<String>) -> ScenarioError {
        self.locate_key("export.damping_ratio", reason)
    }

    /// Like [`Scenario::locate`], for one of the keys the run checks after parsing.
    fn locate_key(&self, key: &'static str, reason: impl Into<String>) -> ScenarioError {
        ScenarioError {
            kind: ErrorKind::Invalid,
            file: self.sources.file.clone(),
            location: self
                .sources
                .keys
                .get(key)
                .copied()
                .unwrap_or(Location { line: 1, column: 1 }),
            key: key.to_string(),
            reason: reason.into(),
        }
    }
}

/// Largest scenario file read, bytes (16 MiB).
pub const MAX_SCENARIO_BYTES: u64 = 16 << 20;

/// Default number of Ritz functions (bending, torsion, axial) of a beam.
pub const DEFAULT_BEAM_TERMS: (usize, usize, usize) = (8, 6, 4);
/// Default number of Ritz functions (length, width) of a plate.
pub const DEFAULT_PLATE_TERMS: (usize, usize) = (8, 6);

/// The key on the line of `offset`, prefixed by the enclosing table header: a readable name
/// for the place toml's own errors point at.
/// The key path of a table header line: `[hub]` → `hub`; an element of an array of tables,
/// `[[beams]]`, gets its 0-based index as in the value errors (`beams[1]`): the count of
/// the same header up to `end`, the end of the header's line.
fn table_path(src: &str, end: usize, header: &str) -> String {
    let name = header.trim_matches(|c| c == '[' || c == ']').trim();
    if !header.starts_with("[[") {
        return name.to_string();
    }
    let same = |l: &str| {
        let l = l.trim();
        l.starts_with("[[") && l.trim_matches(|c| c == '[' || c == ']').trim() == name
    };
    let index = src[..end].lines().filter(|l| same(l)).count();
    format!("{name}[{}]", index.saturating_sub(1))
}

/// The keys open at the end of `prefix` (a line's text up to an offset): the line's key, those
/// of the inline tables entered since and the key whose value is being read, skipping quoted
/// strings and array elements. Empty when no `key =` precedes the offset.
fn inline_path(prefix: &str) -> Vec<String> {
    // The keys of the inline tables open around the offset; for each, what to restore when it
    // closes: the array depth and the key pending outside it (an array's key stays pending
    // across its elements: `t = [{ n = 1 }, { n = "x" }]` → t.n for both).
    let mut stack: Vec<String> = Vec::new();
    let mut saved: Vec<(usize, Option<String>, bool)> = Vec::new();
    let mut pending: Option<String> = None;
    let mut word = String::new();
    let mut depth = 0usize; // arrays open in the current inline table
    let mut chars = prefix.chars();
    while let Some(c) = chars.next() {
        match c {
            '"' | '\'' => {
                // A quoted string (a basic string's escapes included): a quoted key if '='
                // follows, a value otherwise (cleared by the ',' or '}' after it).
                let mut escaped = false;
                word.clear();
                for d in chars.by_ref() {
                    if c == '"' && !escaped && d == '\\' {
                        escaped = true;
                        continue;
                    }
                    if d == c && !escaped {
                        break;
                    }
                    escaped = false;
                    word.push(d);
                }
            }
            '#' => break,
            '=' if depth == 0 => {
                pending = Some(word.trim().to_string()).filter(|w| !w.is_empty());
                word.clear();
            }
            '{' => {
                let key = pending.clone();
                saved.push((depth, pending.take(), key.is_some()));
                stack.extend(key);
                depth = 0;
                word.clear();
            }
            '}' => {
                if let Some((d, p, pushed)) = saved.pop() {
                    if pushed {
                        stack.pop();
                    }
                    depth = d;
                    // Inside an array its key stays pending; otherwise the value has ended.
                    pending = if depth > 0 { p } else { None };
                }
                word.clear();
            }
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            ',' if depth == 0 => {
                pending = None;
                word.clear();
            }
            _ => word.push(c),
        }
    }
    stack.extend(pending);
    stack
}

fn key_at(src: &str, offset: usize) -> String {
    let offset = offset.min(src.len());
    let line_start = src[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = src[offset..].find('\n').map_or(src.len(), |i| offset + i);
    let line = &src[line_start..line_end];
    let trimmed = line.trim();
    if trimmed.starts_with('[') {
        return table_path(src, line_end, trimmed);
    }
    let header = src[..line_start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| table_path(src, line_start, l));
    // Inside an inline table the key is the innermost one at the offset
    // (`section = { tube = { outer_diameter = "x" } }` → section.tube.outer_diameter).
    let path = inline_path(&line[..offset - line_start]);
    let key = if path.is_empty() {
        line.split('=').next().unwrap_or("").trim().to_string()
    } else {
        path.join(".")
    };
    match (header, key.is_empty() || !line.contains('=')) {
        (Some(h), false) => format!("{h}.{key}"),
        (Some(h), true) => h,
        (None, false) => key,
        (None, true) => "(top level)".to_string(),
    }
}

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, ScenarioError> {
        use std::io::Read;
        let file = path.display().to_string();
        let io = |reason: String| ScenarioError {
            kind: ErrorKind::Io,
            file: file.clone(),
            location: Location { line: 0, column: 0 },
            key: "(file)".into(),
            reason,
        };
        // A FIFO or a device would block the open or the read with no end: only a regular
        // file (or a symbolic link to one) is read.
        let meta = std::fs::metadata(path).map_err(|e| io(e.to_string()))?;
        if !meta.is_file() {
            return Err(io(if meta.is_dir() {
                "is a folder, not a scenario file".into()
            } else {
                "is not a regular file (a FIFO, socket or device): give the scenario as a file"
                    .into()
            }));
        }
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_SCENARIO_BYTES + 1).read_to_end(&mut bytes))
            .map_err(|e| io(e.to_string()))?;
        if bytes.len() as u64 > MAX_SCENARIO_BYTES {
            return Err(io(format!(
                "the file is larger than {} MiB; a scenario is a small text file",
                MAX_SCENARIO_BYTES >> 20
            )));
        }
        let src = match String::from_utf8(bytes) {
            Ok(s) => s,
            Err(e) => {
                let good = e.utf8_error().valid_up_to();
                let text = String::from_utf8_lossy(&e.as_bytes()[..good]).into_owned();
                return Err(ScenarioError {
                    kind: ErrorKind::Syntax,
                    file: file.clone(),
                    location: Location::of_offset(&text, good),
                    key: key_at(&text, good),
                    reason: "the file is not valid UTF-8 here (TOML is UTF-8 text)".into(),
                });
            }
        };
        Self::from_toml_str(&src, &file)
    }

    /// Parses and validates scenario text; `file` names it in errors.
    pub fn from_toml_str(src: &str, file: &str) -> Result<Self, ScenarioError> {
        let cx = Ctx::new(src, file);
        // Two stages, so that the kind of a refusal never depends on toml's wording: text
        // that is not TOML at all is a syntax error; TOML that does not fit the schema (an
        // unknown, missing or mistyped key) is a schema error.
        // (The second parse runs only for a refused text.)
        let kind = || match src.parse::<toml::Table>() {
            Err(_) => ErrorKind::Syntax,
            Ok(_) => ErrorKind::Schema,
        };
        let raw: RawScenario = toml::from_str(src).map_err(|e| toml_error(&cx, kind(), &e))?;
        build(&cx, raw)
    }
}

/// A refusal of toml's deserializer, located, with the key it points at.
/// serde writes an unexpected float in full decimal (5e-324 with 324 digits): the shortest
/// scientific form instead, in "floating point `…`".
fn short_floats(msg: &str) -> String {
    const TAG: &str = "floating point `";
    let Some(at) = msg.find(TAG) else {
        return msg.to_string();
    };
    let start = at + TAG.len();
    let Some(len) = msg[start..].find('`') else {
        return msg.to_string();
    };
    match msg[start..start + len].parse::<f64>() {
        Ok(v) if len > 16 => format!("{}{v:e}{}", &msg[..start], &msg[start + len..]),
        _ => msg.to_string(),
    }
}

fn toml_error(cx: &Ctx, kind: ErrorKind, e: &toml::de::Error) -> ScenarioError {
    let span = e.span().unwrap_or(0..0);
    let mut msg = e.message().trim().to_string();
    if msg.is_empty() {
        msg = "malformed TOML here (a control character or an unexpected character)".to_string();
    }
    msg = short_floats(&msg);
    // A dotted key (`motion.x = "free"`) makes a table where a text value belongs; serde's
    // words for it ("expected a borrowed string") say nothing to a user.
    if msg.ends_with("expected a borrowed string") {
        msg = "a table (a dotted key) where a text value belongs: write `key = \"…\"`".into();
    }
    // serde names a missing field only in its message; put it into the key when it is there
    // (the location is the enclosing table either way).
    let mut key = key_at(cx.src, span.start);
    // `[deployment] hub` is in the schema only to be refused with its own message: not a
    // field to suggest.
    if key.starts_with("deployment.") && msg.starts_with("unknown field") {
        msg = msg.replace(", `hub`", "");
    }
    if let Some(field) = msg
        .strip_prefix("missing field `")
        .and_then(|r| r.split('`').next())
    {
        key = if key == "(top level)" {
            field.to_string()
        } else {
            format!("{key}.{field}")
        };
    }
    cx.err(kind, span, key, msg)
}

/// The scenario, section by section; each section's own module lowers it and the domain
/// constructors validate every value.
fn build(cx: &Ctx, raw: RawScenario) -> Result<Scenario, ScenarioError> {
    if let Some(v) = &raw.format_version {
        if *v.get_ref() != 1 {
            return Err(cx.invalid(
                v.span(),
                "format_version",
                format!("this flexcraft reads format version 1, got {}", v.get_ref()),
            ));
        }
    }
    let name = match &raw.name {
        None => "unnamed".to_string(),
        Some(n) => match crate::limits::valid_title(n.get_ref()) {
            Ok(()) => n.get_ref().clone(),
            Err(why) => return Err(cx.invalid(n.span(), "name", why)),
        },
    };
    let materials = materials::lower(cx, &raw.materials)?;
    let hub = hub::lower(cx, &raw.hub, &materials)?;
    // Parent names resolve to beam indices once, here (the first beam of a name wins; a
    // second one is refused as a duplicate by the structure).
    let mut beam_index: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, b) in raw.beams.iter().enumerate() {
        beam_index
            .entry(b.get_ref().name.get_ref().as_str())
            .or_insert(i);
    }
    let beams = (raw.beams.iter().enumerate())
        .map(|(i, b)| beams::lower(cx, i, b, &materials, &beam_index))
        .collect::<Result<Vec<_>, _>>()?;
    let plates = (raw.plates.iter().enumerate())
        .map(|(i, p)| plates::lower(cx, i, p, &materials, &beam_index))
        .collect::<Result<Vec<_>, _>>()?;
    let masses = (raw.masses.iter().enumerate())
        .map(|(i, m)| masses::lower(cx, i, m, &beam_index))
        .collect::<Result<Vec<_>, _>>()?;
    let basis = raw
        .ritz
        .as_ref()
        .map(|r| r.get_ref().basis)
        .unwrap_or_default();
    let structure = Structure::new(Parts {
        name: name.clone(),
        hub,
        beams,
        plates,
        masses,
        basis,
    })
    .map_err(|e| tree_error(cx, &raw, &e))?;
    let response = match &raw.response {
        Some(r) => response::lower(cx, r)?,
        None => ResponseSettings::default(),
    };
    let export = match &raw.export {
        Some(e) => export::lower(cx, e, &structure)?,
        None => crate::export::ExportSettings {
            transfers: crate::export::default_transfers(structure.hub().motion(), &[]),
            ..Default::default()
        },
    };
    // The automatic terms aim at the modes the run uses: the response's or the export's.
    let used_modes = match (response.modes, export.modes) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    // The deployment is read on the structure as given (it uses the plate's geometry and
    // mass, not its terms). Compliant latches stay in the deployed wing: its plate is cut
    // along the hinge lines and joined by the latch springs (docs/theory.md §1.6) — before
    // the automatic terms are chosen, so that they aim at the cut wing's modes.
    let deployment = match &raw.deployment {
        Some(d) => Some(deployment::lower(cx, d, &structure)?),
        None => None,
    };
    let structure = match (&deployment, &raw.deployment) {
        (Some(d), Some(rd)) => d
            .latched_structure(&structure)
            .map_err(|e| cx.invalid(rd.span(), "deployment.latch", e.to_string()))?,
        _ => structure,
    };
    let term_selection = ritz::select(cx, &raw, &structure, used_modes)?;
    let structure = match &term_selection {
        Some(sel) => sel.structure.clone(),
        None => structure,
    };
    let montecarlo = match &raw.montecarlo {
        Some(m) => Some(montecarlo::lower(
            cx,
            m,
            &structure,
            deployment.as_ref(),
            raw.response.is_some(),
        )?),
        None => None,
    };
    let stress = stress::lower(cx, &raw)?;
    Ok(Scenario {
        name,
        structure,
        deployment,
        response,
        export,
        term_selection,
        montecarlo,
        stress,
        sources: sources(cx, &raw),
    })
}

/// An error of the attachment tree, located at the component's name, parent or station.
fn tree_error(cx: &Ctx, raw: &RawScenario, e: &StructureError) -> ScenarioError {
    let (key, spans) = match e.component() {
        Some(ComponentId::Beam(i)) => {
            let b = raw.beams[i].get_ref();
            (
                format!("beams[{i}]"),
                (
                    b.name.span(),
                    b.parent.span(),
                    context::span_or(&b.station, b.parent.span()),
                ),
            )
        }
        Some(ComponentId::Plate(i)) => {
            let p = raw.plates[i].get_ref();
            (
                format!("plates[{i}]"),
                (
                    p.name.span(),
                    p.parent.span(),
                    context::span_or(&p.station, p.parent.span()),
                ),
            )
        }
        Some(ComponentId::Mass(i)) => {
            let m = raw.masses[i].get_ref();
            (
                format!("masses[{i}]"),
                (
                    m.name.span(),
                    m.parent.span(),
                    context::span_or(&m.station, m.parent.span()),
                ),
            )
        }
        _ => ("structure".to_string(), (0..0, 0..0, 0..0)),
    };
    let field = e.field();
    let span = match field {
        crate::structure::Field::Parent => spans.1,
        crate::structure::Field::Station => spans.2,
        _ => spans.0,
    };
    cx.invalid(span, format!("{key}.{}", field.key()), e.to_string())
}

/// Where each component and each key checked after parsing was written.
fn sources(cx: &Ctx, raw: &RawScenario) -> Sources {
    let loc = |span: std::ops::Range<usize>| cx.location(&span);
    let mut at = BTreeMap::new();
    at.insert(ComponentId::Hub, ("hub".to_string(), loc(raw.hub.span())));
    for (i, b) in raw.beams.iter().enumerate() {
        at.insert(
            ComponentId::Beam(i),
            (format!("beams[{i}]"), loc(b.get_ref().name.span())),
        );
    }
    for (i, p) in raw.plates.iter().enumerate() {
        at.insert(
            ComponentId::Plate(i),
            (format!("plates[{i}]"), loc(p.get_ref().name.span())),
        );
    }
    for (i, m) in raw.masses.iter().enumerate() {
        at.insert(
            ComponentId::Mass(i),
            (format!("masses[{i}]"), loc(m.get_ref().name.span())),
        );
    }
    let mut keys = BTreeMap::new();
    let mut dispersions = Vec::new();
    if let Some(r) = &raw.response {
        let span = context::span_or(&r.get_ref().output_rate, r.span());
        keys.insert("response.output_rate", loc(span));
    }
    if let Some(d) = &raw.deployment {
        let span = context::span_or(&d.get_ref().output_rate, d.span());
        keys.insert("deployment.output_rate", loc(span));
    }
    if let Some(e) = &raw.export {
        let span = context::span_or(&e.get_ref().damping_ratio, e.span());
        keys.insert("export.damping_ratio", loc(span));
    }
    if let Some(m) = &raw.montecarlo {
        for (path, d) in &m.get_ref().dispersions {
            dispersions.push((path.clone(), loc(d.span())));
        }
    }
    Sources {
        dispersions,
        file: cx.file.to_string(),
        text: cx.src.to_string(),
        at,
        keys,
    }
}

#[cfg(test)]
mod key_tests {
    use super::inline_path;

    /// The key open at the end of a line's prefix, against paths read off by hand.
    #[test]
    fn inline_paths_name_the_innermost_key() {
        let cases: [(&str, &str); 9] = [
            ("length = ", "length"),
            (
                "section = { tube = { outer_diameter = ",
                "section.tube.outer_diameter",
            ),
            (
                "section = { tube = { outer_diameter = 1, wall = ",
                "section.tube.wall",
            ),
            ("a = { t = [ {n=1}, {n=", "a.t.n"),
            ("a = { t = [ {n=1}, {n=\"x\"} ], z = ", "a.z"),
            ("\"tube\" = { d = ", "tube.d"),
            ("root = [0.0, ", "root"),
            ("name = \"a = {b\", x = ", "x"),
            ("# x = 1", ""),
        ];
        for (prefix, want) in cases {
            assert_eq!(inline_path(prefix).join("."), want, "{prefix}");
        }
    }
}
