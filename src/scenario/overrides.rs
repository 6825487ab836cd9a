//! Dotted-key overrides: a scenario with some values replaced ("deployment.hinge.stiffness" =
//! 3.0), as a dispersion run or a parameter sweep needs. The override edits the TOML document
//! (comments and layout kept), then the edited text is parsed and validated like any file, so
//! an overridden value meets every check a written one does, and the text can be saved as the
//! run's own scenario.
//!
//! Paths: table keys joined by `.`; a numeric segment is a 1-based position in an array of
//! tables or of values (`deployment.hinges.2.latch_angle` is hinge 2's latch angle,
//! `hub.inertia.1` the first inertia value); an array of named tables (`beams`, `plates`,
//! `masses`) can also be entered by the component's name (`beams.mast.length`). The last
//! segment may name a key the file does not write (a default) inside a table it writes; the
//! schema then decides whether such a key exists. Anything else that does not resolve is
//! refused.

use super::{ErrorKind, Location, Scenario, ScenarioError};
use toml_edit::{Array, ArrayOfTables, DocumentMut, InlineTable, Item, Table, Value};

/// A value to put at a dotted path.
#[derive(Debug, Clone, PartialEq)]
pub enum OverrideValue {
    /// A number: written as an integer where the file has an integer (it must then be
    /// integral), else as a float.
    Number(f64),
    /// A string (e.g. `hub.motion` = "fixed").
    Text(String),
    /// A boolean.
    Bool(bool),
}

impl From<f64> for OverrideValue {
    fn from(v: f64) -> Self {
        Self::Number(v)
    }
}

impl From<&str> for OverrideValue {
    fn from(v: &str) -> Self {
        Self::Text(v.to_string())
    }
}

/// Where the walk down a path stands.
enum Cursor<'a> {
    Table(&'a mut Table),
    Inline(&'a mut InlineTable),
    Tables(&'a mut ArrayOfTables),
    Values(&'a mut Array),
}

/// A 1-based position in 1…len.
fn position(seg: &str, len: usize) -> Result<usize, String> {
    match seg.parse::<usize>() {
        Ok(k) if (1..=len).contains(&k) => Ok(k - 1),
        Ok(k) => Err(format!(
            "position {k} is outside 1…{len} (positions count from 1)"
        )),
        Err(_) => Err(format!("`{seg}` is not a position (1…{len})")),
    }
}

fn enter_value<'a>(v: &'a mut Value, seg: &str) -> Result<Cursor<'a>, String> {
    match v {
        Value::InlineTable(t) => Ok(Cursor::Inline(t)),
        Value::Array(a) => Ok(Cursor::Values(a)),
        _ => Err(format!("`{seg}` is a value, not a table or an array")),
    }
}

impl<'a> Cursor<'a> {
    /// One segment down.
    fn step(self, seg: &str) -> Result<Cursor<'a>, String> {
        let missing = || format!("the file has no `{seg}` here");
        match self {
            Cursor::Table(t) => match t.get_mut(seg).ok_or_else(missing)? {
                Item::Table(t) => Ok(Cursor::Table(t)),
                Item::ArrayOfTables(a) => Ok(Cursor::Tables(a)),
                Item::Value(v) => enter_value(v, seg),
                Item::None => Err(missing()),
            },
            Cursor::Inline(t) => enter_value(t.get_mut(seg).ok_or_else(missing)?, seg),
            Cursor::Tables(a) => {
                let len = a.len();
                let idx = match seg.parse::<usize>() {
                    Ok(_) => position(seg, len)?,
                    Err(_) => a
                        .iter()
                        .position(|t| t.get("name").and_then(Item::as_str) == Some(seg))
                        .ok_or_else(|| format!("no table of this array has name = {seg:?}"))?,
                };
                Ok(Cursor::Table(a.get_mut(idx).expect("index checked")))
            }
            Cursor::Values(a) => {
                let idx = position(seg, a.len())?;
                enter_value(a.get_mut(idx).expect("index checked"), seg)
            }
        }
    }

    /// Puts `value` at the last segment.
    fn set(self, seg: &str, value: &OverrideValue) -> Result<(), String> {
        match self {
            Cursor::Table(t) => {
                let old = t.get(seg).and_then(Item::as_value).cloned();
                let new = convert(old.as_ref(), value)?;
                match t.get_mut(seg) {
                    Some(Item::Value(v)) => replace_keeping_decor(v, new),
                    Some(_) => return Err(format!("`{seg}` is a table, not a value")),
                    None => {
                        t.insert(seg, Item::Value(new));
                    }
                }
                Ok(())
            }
            Cursor::Inline(t) => {
                let new = convert(t.get(seg), value)?;
                match t.get_mut(seg) {
                    Some(v) => replace_keeping_decor(v, new),
                    None => {
                        t.insert(seg, new);
                    }
                }
                Ok(())
            }
            Cursor::Tables(_) => Err(format!("`{seg}` names a whole table, not a value")),
            Cursor::Values(a) => {
                let idx = position(seg, a.len())?;
                let slot = a.get_mut(idx).expect("index checked");
                let new = convert(Some(slot), value)?;
                replace_keeping_decor(slot, new);
                Ok(())
            }
        }
    }
}

/// Replaces a value, keeping the spaces and comment around it.
fn replace_keeping_decor(slot: &mut Value, mut new: Value) {
    *new.decor_mut() = slot.decor().clone();
    *slot = new;
}

/// The TOML value for an override, typed after the value it replaces.
fn convert(old: Option<&Value>, v: &OverrideValue) -> Result<Value, String> {
    match (old, v) {
        (Some(Value::Integer(_)), OverrideValue::Number(x)) => {
            if x.fract() == 0.0 && x.abs() < 9.0e15 {
                Ok(Value::from(*x as i64))
            } else {
                Err(format!("the key holds an integer; {x} is not one"))
            }
        }
        (Some(Value::Array(_) | Value::InlineTable(_)), _) => {
            Err("the key holds an array or a table: override its elements".to_string())
        }
        (_, OverrideValue::Number(x)) if !x.is_finite() => {
            Err(format!("{x} is not a finite number"))
        }
        (_, OverrideValue::Number(x)) => Ok(Value::from(*x)),
        (_, OverrideValue::Text(s)) => Ok(Value::from(s.as_str())),
        (_, OverrideValue::Bool(b)) => Ok(Value::from(*b)),
    }
}

/// Applies overrides to scenario text: the edited text, or the path that could not be set and
/// why.
pub fn apply_overrides(
    text: &str,
    values: &[(&str, OverrideValue)],
) -> Result<String, (String, String)> {
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| ("(file)".to_string(), e.to_string()))?;
    for (path, value) in values {
        let segs: Vec<&str> = path.split('.').collect();
        if segs.iter().any(|s| s.is_empty()) {
            return Err((
                path.to_string(),
                "an empty segment in the dotted path".into(),
            ));
        }
        let (last, walk) = segs
            .split_last()
            .expect("split yields one segment at least");
        let mut cur = Cursor::Table(doc.as_table_mut());
        for seg in walk {
            cur = cur.step(seg).map_err(|why| (path.to_string(), why))?;
        }
        cur.set(last, value)
            .map_err(|why| (path.to_string(), why))?;
    }
    Ok(doc.to_string())
}

impl Scenario {
    /// This scenario with values replaced at dotted paths (module doc), validated like a file:
    /// an unknown path, a value of the wrong type or outside its range is refused with the
    /// path as the key. The result's [`Scenario::source_text`] is the edited text.
    pub fn with_values(&self, values: &[(&str, OverrideValue)]) -> Result<Scenario, ScenarioError> {
        let file = format!("{} (with overrides)", self.sources.file);
        let text =
            apply_overrides(self.source_text(), values).map_err(|(path, why)| ScenarioError {
                kind: ErrorKind::Invalid,
                file: file.clone(),
                location: Location { line: 0, column: 0 },
                key: path,
                reason: why,
            })?;
        Scenario::from_toml_str(&text, &file)
    }
}

/// `[deployment]` alone, ready to take values at `deployment.…` paths and be lowered again
/// against the structure of the scenario it came from: what a dispersion run needs when
/// every dispersed key is a deployment key (the structure, and so its modes, cannot change
/// then: the structure is built from the other sections only). The text is the section as
/// the file writes it (comments kept), so a value meets exactly the checks
/// [`Scenario::with_values`] applies; only the location of a refusal differs (it points into
/// this text).
#[derive(Debug, Clone)]
pub struct DeploymentOverrides {
    text: String,
    file: String,
}

/// The first segment of the paths [`DeploymentOverrides`] takes.
const DEPLOYMENT: &str = "deployment";

impl Scenario {
    /// `[deployment]` alone for [`DeploymentOverrides::deployment`]; `None` without the
    /// section.
    pub fn deployment_overrides(&self) -> Option<DeploymentOverrides> {
        let doc: DocumentMut = self.source_text().parse().ok()?;
        let item = doc.get(DEPLOYMENT)?.clone();
        let mut only = DocumentMut::new();
        only.insert(DEPLOYMENT, item);
        Some(DeploymentOverrides {
            text: only.to_string(),
            file: format!("{} ([deployment] with overrides)", self.sources.file),
        })
    }

    /// Whether every path is a `deployment.…` path (then [`DeploymentOverrides`] applies).
    pub fn deployment_paths_only<'a>(paths: impl IntoIterator<Item = &'a str>) -> bool {
        paths
            .into_iter()
            .all(|p| p.split('.').next() == Some(DEPLOYMENT) && p.len() > DEPLOYMENT.len())
    }
}

impl DeploymentOverrides {
    /// The deployment of `base` (the scenario this came from) with values at `deployment.…`
    /// paths, validated like a file: the same as `base.with_values(values)?.deployment`.
    pub fn deployment(
        &self,
        base: &Scenario,
        values: &[(&str, OverrideValue)],
    ) -> Result<crate::deploy::Deployment, ScenarioError> {
        let refuse = |key: String, reason: String| ScenarioError {
            kind: ErrorKind::Invalid,
            file: self.file.clone(),
            location: Location { line: 0, column: 0 },
            key,
            reason,
        };
        if let Some((p, _)) = values
            .iter()
            .find(|(p, _)| !Scenario::deployment_paths_only([*p]))
        {
            return Err(refuse(
                p.to_string(),
                "not a deployment key: use Scenario::with_values".into(),
            ));
        }
        let text = apply_overrides(&self.text, values).map_err(|(p, why)| refuse(p, why))?;
        let cx = super::context::Ctx::new(&text, &self.file);
        let raw: super::raw::RawDeploymentOnly =
            toml::from_str(&text).map_err(|e| super::toml_error(&cx, ErrorKind::Schema, &e))?;
        super::deployment::lower(&cx, &raw.deployment, &base.structure)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SEED: &str = include_str!("../../examples/seed.toml");

    fn seed() -> Scenario {
        Scenario::from_toml_str(SEED, "seed.toml").expect("seed parses")
    }

    #[test]
    fn a_value_is_replaced_in_place_and_validated() {
        let s = seed()
            .with_values(&[
                ("beams.mast.length", 14.0.into()),
                ("hub.motion", "fixed".into()),
            ])
            .expect("valid overrides");
        assert_eq!(s.structure.beams()[0].length(), 14.0);
        assert_eq!(
            s.structure.hub().motion(),
            crate::structure::HubMotion::Fixed
        );
        // Comments and the other lines are kept.
        let lines_before = SEED.lines().count();
        assert_eq!(s.source_text().lines().count(), lines_before);
        assert!(s.source_text().contains("# the paper's \"vertical rod\""));
        // The same path by position.
        let by_position = seed()
            .with_values(&[("beams.1.length", 14.0.into())])
            .unwrap();
        let by_name = seed()
            .with_values(&[("beams.mast.length", 14.0.into())])
            .unwrap();
        assert_eq!(by_position.source_text(), by_name.source_text());
        // An integer key takes an integral number, as an integer.
        let p = seed()
            .with_values(&[("deployment.panels", 3.0.into())])
            .unwrap();
        assert!(p.source_text().contains("panels = 3\n"));
        let e = seed()
            .with_values(&[("deployment.panels", 2.5.into())])
            .unwrap_err();
        assert!(e.reason.contains("integer"), "{e}");
    }

    #[test]
    fn deployment_overrides_lower_as_the_whole_file_does() {
        let s = seed();
        let t = s.deployment_overrides().expect("the seed deploys");
        for values in [
            vec![("deployment.hinge.stiffness", OverrideValue::Number(1.5))],
            vec![
                ("deployment.hinge.friction", OverrideValue::Number(0.002)),
                ("deployment.hinge.preload_angle", OverrideValue::Number(0.3)),
                ("deployment.end_time", OverrideValue::Number(50.0)),
            ],
            vec![("deployment.panels", OverrideValue::Number(2.0))],
        ] {
            let whole = s.with_values(&values).unwrap().deployment.unwrap();
            assert_eq!(t.deployment(&s, &values).unwrap(), whole);
        }
        // Refusals are the same refusals (key and reason).
        for values in [
            vec![("deployment.hinge.stiffness", OverrideValue::Number(-1.0))],
            vec![("deployment.panels", OverrideValue::Number(2.5))],
            vec![("deployment.hinge.stifness", OverrideValue::Number(1.0))],
        ] {
            let a = s.with_values(&values).unwrap_err();
            let b = t.deployment(&s, &values).unwrap_err();
            assert_eq!((a.key, a.reason), (b.key, b.reason), "{values:?}");
        }
        assert!(t
            .deployment(&s, &[("hub.mass", OverrideValue::Number(1.0))])
            .is_err());
        assert!(Scenario::deployment_paths_only([
            "deployment.hinge.stiffness"
        ]));
        assert!(!Scenario::deployment_paths_only([
            "deployments.x",
            "deployment.a"
        ]));
        assert!(!Scenario::deployment_paths_only(["deployment"]));
    }

    #[test]
    fn bad_paths_and_values_are_refused_with_the_path() {
        for (path, v, why) in [
            (
                "beams.mats.length",
                OverrideValue::Number(1.0),
                "no table of this array has name =",
            ),
            ("beams.3.length", OverrideValue::Number(1.0), "outside 1…1"),
            ("hub.motion.x", OverrideValue::Number(1.0), "is a value"),
            ("nothing.here", OverrideValue::Number(1.0), "no `nothing`"),
            (
                "beams.mast.length",
                OverrideValue::Number(f64::NAN),
                "not a finite number",
            ),
            ("beams..length", OverrideValue::Number(1.0), "empty segment"),
        ] {
            let e = seed().with_values(&[(path, v)]).unwrap_err();
            assert_eq!(e.key, path, "{e}");
            assert!(e.reason.contains(why), "{path}: {e}");
        }
        // A key the schema does not know, inserted at the end of the path: refused by the
        // parse of the edited text.
        let e = seed().with_values(&[("hub.mas", 1.0.into())]).unwrap_err();
        assert!(e.to_string().contains("mas"), "{e}");
        // A value outside its range: the ordinary validation.
        let e = seed()
            .with_values(&[("beams.mast.length", (-1.0).into())])
            .unwrap_err();
        assert!(e.to_string().contains("length"), "{e}");
    }
}
