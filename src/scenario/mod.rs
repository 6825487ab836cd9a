//! Scenario files (TOML, format version 1; keys documented in docs/scenario.md): parsing,
//! validation with the location of every refused value, and construction of the
//! [`Structure`].

mod budget;
mod error;
pub mod limits;
mod raw;

pub use budget::{format_bytes, Estimate};
pub use error::{ErrorKind, Location, ScenarioError};

use crate::deploy::{Deployment, Latching};
use crate::math::Vec3;
use crate::response::{HandoverMethod, ResponseSettings};
use crate::structure::{
    inertia_tensor, Attachment, Beam, BeamSection, BeamTerms, ComponentId, Frame, Hub, HubMotion,
    LumpedMass, Material, Plate, PlateTerms, Structure, StructureError,
};
use limits as L;
use limits::Limit;
use raw::*;
use std::collections::BTreeMap;
use std::ops::Range;

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
    /// Where each component was written, to locate a failure found after parsing.
    sources: Sources,
}

/// The file and the place each component was written (its `name` key; the `[hub]` table).
#[derive(Debug, Clone, Default)]
struct Sources {
    file: String,
    at: BTreeMap<ComponentId, (String, Location)>,
    /// Keys located after parsing (`response.output_rate`, …): the value, or its section.
    keys: BTreeMap<&'static str, Location>,
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

struct Ctx<'a> {
    src: &'a str,
    file: &'a str,
}

impl Ctx<'_> {
    fn err(
        &self,
        kind: ErrorKind,
        span: Range<usize>,
        key: impl Into<String>,
        reason: impl Into<String>,
    ) -> ScenarioError {
        ScenarioError {
            kind,
            file: self.file.to_string(),
            location: Location::of_offset(self.src, span.start),
            key: key.into(),
            reason: reason.into(),
        }
    }

    fn invalid(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        reason: impl Into<String>,
    ) -> ScenarioError {
        self.err(ErrorKind::Invalid, span, key, reason)
    }

    fn structural<T>(
        &self,
        r: Result<T, StructureError>,
        span: Range<usize>,
        key: impl Into<String>,
    ) -> Result<T, ScenarioError> {
        r.map_err(|e| self.invalid(span, key, e.to_string()))
    }

    /// A scalar inside its accepted range ([`limits`]).
    fn bounded(
        &self,
        v: &S<f64>,
        key: impl Into<String>,
        lim: Limit,
    ) -> Result<f64, ScenarioError> {
        let x = *v.get_ref();
        if lim.contains(x) {
            Ok(x)
        } else {
            Err(self.invalid(
                v.span(),
                key,
                format!(
                    "must be a {}finite number in {}, got {x:e}",
                    if lim.lo > 0.0 || (lim.open_lo && lim.lo == 0.0) {
                        "positive "
                    } else {
                        ""
                    },
                    lim.describe()
                ),
            ))
        }
    }

    /// An optional scalar inside its range, or `default` when absent.
    fn bounded_or(
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

    /// A component or material name: [`limits::valid_name`]'s rule, checked once here.
    fn name(&self, v: &S<String>, key: impl Into<String>) -> Result<String, ScenarioError> {
        let n = v.get_ref();
        match L::valid_name(n) {
            Ok(()) => Ok(n.clone()),
            Err(why) => Err(self.invalid(v.span(), key, why)),
        }
    }

    /// An inertia given as 3 principal or 6 values: each entry in range, then a physical
    /// tensor ([`inertia_tensor`]).
    fn inertia(
        &self,
        v: &S<Vec<f64>>,
        key: impl Into<String>,
    ) -> Result<crate::math::Mat3, ScenarioError> {
        let key = key.into();
        let vals = v.get_ref();
        for (i, x) in vals.iter().enumerate() {
            let diagonal = i < 3;
            let ok = L::INERTIA.contains(*x) && (!diagonal || x.abs() >= L::MIN_PRINCIPAL_INERTIA);
            if !ok {
                return Err(self.invalid(
                    v.span(),
                    key,
                    format!(
                        "entry {} is {x:e}: moments must lie in [{:e}, {:e}] kg·m², products in {}",
                        i + 1,
                        L::MIN_PRINCIPAL_INERTIA,
                        L::INERTIA.hi,
                        L::INERTIA.describe()
                    ),
                ));
            }
        }
        self.structural(inertia_tensor(vals), v.span(), key)
    }

    /// Poisson's ratio in (−1, 0.5).
    fn poisson(&self, v: &S<f64>, key: impl Into<String>) -> Result<f64, ScenarioError> {
        let nu = *v.get_ref();
        if L::POISSON.contains(nu) && nu < 0.5 {
            Ok(nu)
        } else {
            Err(self.invalid(v.span(), key, format!("must lie in (-1, 0.5), got {nu}")))
        }
    }

    /// A point or offset: every coordinate inside [`limits::COORDINATE`].
    fn point(&self, v: &S<[f64; 3]>, key: impl Into<String>) -> Result<Vec3, ScenarioError> {
        let a = *v.get_ref();
        if a.iter().all(|x| limits::COORDINATE.contains(*x)) {
            Ok(Vec3(a))
        } else {
            Err(self.invalid(
                v.span(),
                key,
                format!(
                    "every coordinate must lie in {}, got [{:e}, {:e}, {:e}]",
                    limits::COORDINATE.describe(),
                    a[0],
                    a[1],
                    a[2]
                ),
            ))
        }
    }

    /// A direction: finite components, not all zero (any scale: it is normalised
    /// scale-safely by the structure).
    fn direction(&self, v: &S<[f64; 3]>, key: impl Into<String>) -> Result<Vec3, ScenarioError> {
        let a = *v.get_ref();
        if a.iter().all(|x| x.is_finite()) && a.iter().any(|x| *x != 0.0) {
            Ok(Vec3(a))
        } else {
            Err(self.invalid(
                v.span(),
                key,
                "has zero length or a non-finite component (a direction needs finite \
                 components, not all zero)",
            ))
        }
    }

    fn terms(
        &self,
        v: &Option<S<i64>>,
        default: usize,
        key: impl Into<String>,
    ) -> Result<usize, ScenarioError> {
        match v {
            None => Ok(default),
            Some(t) => {
                let n = *t.get_ref();
                if (1..=crate::structure::MAX_TERMS as i64).contains(&n) {
                    Ok(n as usize)
                } else {
                    Err(self.invalid(
                        t.span(),
                        key,
                        format!(
                            "must be between 1 and {}, got {n}",
                            crate::structure::MAX_TERMS
                        ),
                    ))
                }
            }
        }
    }
}

/// The key on the line of `offset`, prefixed by the enclosing table header: a readable name
/// for the place toml's own errors point at.
fn key_at(src: &str, offset: usize) -> String {
    let offset = offset.min(src.len());
    let line_start = src[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = src[offset..].find('\n').map_or(src.len(), |i| offset + i);
    let line = &src[line_start..line_end];
    let header = src[..line_start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    let trimmed = line.trim();
    if trimmed.starts_with('[') {
        return trimmed
            .trim_matches(|c| c == '[' || c == ']')
            .trim()
            .to_string();
    }
    let key = line.split('=').next().unwrap_or("").trim().to_string();
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
        let cx = Ctx { src, file };
        let raw: RawScenario = toml::from_str(src).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            let mut msg = e.message().trim().to_string();
            if msg.is_empty() {
                msg = "malformed TOML here (a control character or an unexpected character)"
                    .to_string();
            }
            let kind = if msg.starts_with("invalid type")
                || msg.starts_with("unknown field")
                || msg.starts_with("missing field")
                || msg.starts_with("unknown variant")
                || msg.starts_with("invalid length")
                || msg.starts_with("invalid value")
            {
                ErrorKind::Schema
            } else {
                ErrorKind::Syntax
            };
            let mut key = key_at(src, span.start);
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
        })?;
        build(&cx, raw)
    }
}

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
        Some(n) => match L::valid_title(n.get_ref()) {
            Ok(()) => n.get_ref().clone(),
            Err(why) => return Err(cx.invalid(n.span(), "name", why)),
        },
    };

    // Materials.
    let mut materials: BTreeMap<&str, Material> = BTreeMap::new();
    for (mname, m) in &raw.materials {
        if let Err(why) = L::valid_name(mname) {
            return Err(cx.invalid(m.span(), "materials", format!("material name: {why}")));
        }
        let k = format!("materials.{mname}");
        let e = cx.bounded(
            &m.get_ref().youngs_modulus,
            format!("{k}.youngs_modulus"),
            L::MODULUS,
        )?;
        let rho = cx.bounded(&m.get_ref().density, format!("{k}.density"), L::DENSITY)?;
        let nu = cx.poisson(&m.get_ref().poisson_ratio, format!("{k}.poisson_ratio"))?;
        let g = match &m.get_ref().shear_modulus {
            Some(g) => Some(cx.bounded(g, format!("{k}.shear_modulus"), L::MODULUS)?),
            None => None,
        };
        let mat = cx.structural(Material::new(e, nu, rho, g), m.span(), k)?;
        materials.insert(mname.as_str(), mat);
    }
    let material = |s: &S<String>, key: String| -> Result<Material, ScenarioError> {
        materials.get(s.get_ref().as_str()).copied().ok_or_else(|| {
            let known: Vec<&str> = materials.keys().copied().collect();
            cx.invalid(
                s.span(),
                key,
                format!(
                    "unknown material \"{}\" (defined: {})",
                    s.get_ref(),
                    if known.is_empty() {
                        "none".into()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        })
    };

    // Hub.
    let rh = raw.hub.get_ref();
    let motion = match *rh.motion.get_ref() {
        RawMotion::Free => HubMotion::Free,
        RawMotion::Fixed => HubMotion::Fixed,
    };
    let hub = match &rh.shape {
        Some(shape) => {
            for (present, k) in [
                (rh.mass.is_some(), "mass"),
                (rh.inertia.is_some(), "inertia"),
                (rh.center_of_mass.is_some(), "center_of_mass"),
            ] {
                if present {
                    return Err(cx.invalid(
                        shape.span(),
                        format!("hub.{k}"),
                        "give either shape or mass/inertia/center_of_mass, not both",
                    ));
                }
            }
            let c = shape.get_ref().cylinder.get_ref();
            let k = "hub.shape.cylinder";
            let d = cx.bounded(&c.diameter, format!("{k}.diameter"), L::LENGTH)?;
            let w = cx.bounded(&c.wall, format!("{k}.wall"), L::SECTION)?;
            let l = cx.bounded(&c.length, format!("{k}.length"), L::LENGTH)?;
            if w >= d / 2.0 {
                return Err(cx.invalid(
                    c.wall.span(),
                    format!("{k}.wall"),
                    format!("wall {w} m is not less than the radius {} m", d / 2.0),
                ));
            }
            let axis = cx.direction(&c.axis, format!("{k}.axis"))?;
            let center = cx.point(&c.center, format!("{k}.center"))?;
            let mat = material(&c.material, format!("{k}.material"))?;
            cx.structural(
                Hub::cylinder(motion, d, w, l, axis, center, mat.density, c.closed_ends),
                shape.span(),
                k,
            )?
        }
        None => {
            let missing = |k: &str| {
                cx.err(
                    ErrorKind::Schema,
                    raw.hub.span(),
                    format!("hub.{k}"),
                    format!("missing field `{k}` (or give hub.shape)"),
                )
            };
            let mass = cx.bounded(
                rh.mass.as_ref().ok_or_else(|| missing("mass"))?,
                "hub.mass",
                L::MASS,
            )?;
            let inertia_s = rh.inertia.as_ref().ok_or_else(|| missing("inertia"))?;
            let inertia = cx.inertia(inertia_s, "hub.inertia")?;
            let c = cx.point(
                rh.center_of_mass
                    .as_ref()
                    .ok_or_else(|| missing("center_of_mass"))?,
                "hub.center_of_mass",
            )?;
            cx.structural(Hub::new(motion, mass, c, inertia), raw.hub.span(), "hub")?
        }
    };

    // Attachment of a component, with the spans used for tree errors.
    struct Spans {
        name: Range<usize>,
        parent: Range<usize>,
        station: Range<usize>,
    }
    impl Spans {
        /// Where a component's name, parent and attachment station were written.
        fn of(name: &S<String>, parent: &S<String>, station: &Option<S<f64>>) -> Self {
            Self {
                name: name.span(),
                parent: parent.span(),
                station: station.as_ref().map_or(parent.span(), |s| s.span()),
            }
        }
    }
    let mut spans: BTreeMap<String, Spans> = BTreeMap::new();
    let attach = |key: &str,
                  parent: &S<String>,
                  station: &Option<S<f64>>,
                  point: &Option<S<[f64; 3]>>,
                  point_key: &str|
     -> Result<Attachment, ScenarioError> {
        if parent.get_ref() == "hub" {
            if let Some(s) = station {
                return Err(cx.invalid(
                    s.span(),
                    format!("{key}.station"),
                    format!(
                        "station applies to a beam parent; on the hub give {point_key} = [x, y, z]"
                    ),
                ));
            }
            let p = point.as_ref().ok_or_else(|| {
                cx.err(
                    ErrorKind::Schema,
                    parent.span(),
                    format!("{key}.{point_key}"),
                    format!("missing field `{point_key}`: the attachment point on the hub"),
                )
            })?;
            Ok(Attachment::Hub {
                point: cx.point(p, format!("{key}.{point_key}"))?,
            })
        } else {
            if let Some(p) = point {
                return Err(cx.invalid(
                    p.span(),
                    format!("{key}.{point_key}"),
                    format!("{point_key} applies to the hub; on a beam parent give station"),
                ));
            }
            let s = station.as_ref().ok_or_else(|| {
                cx.err(
                    ErrorKind::Schema,
                    parent.span(),
                    format!("{key}.station"),
                    "missing field `station`: distance from the parent beam's root",
                )
            })?;
            let st = cx.bounded(s, format!("{key}.station"), L::STATION)?;
            Ok(Attachment::Beam {
                beam: parent.get_ref().clone(),
                station: st,
            })
        }
    };

    let mut beams = Vec::new();
    for (i, b) in raw.beams.iter().enumerate() {
        let b = b.get_ref();
        let k = format!("beams[{i}]");
        cx.name(&b.name, format!("{k}.name"))?;
        let attachment = attach(&k, &b.parent, &b.station, &b.root, "root")?;
        let length = cx.bounded(&b.length, format!("{k}.length"), L::LENGTH)?;
        let mat = material(&b.material, format!("{k}.material"))?;
        let sec = b.section.get_ref();
        let sk = format!("{k}.section");
        let section = match &sec.tube {
            Some(t) => {
                if let Some(s) = [
                    &sec.area,
                    &sec.iy,
                    &sec.iz,
                    &sec.torsion_constant,
                    &sec.polar_inertia,
                ]
                .into_iter()
                .flatten()
                .next()
                {
                    return Err(cx.invalid(
                        s.span(),
                        sk,
                        "give either tube or the section constants, not both",
                    ));
                }
                let t = t.get_ref();
                let d = cx.bounded(
                    &t.outer_diameter,
                    format!("{sk}.tube.outer_diameter"),
                    L::SECTION,
                )?;
                let w = cx.bounded(&t.wall, format!("{sk}.tube.wall"), L::SECTION)?;
                if w >= d / 2.0 {
                    return Err(cx.invalid(
                        t.wall.span(),
                        format!("{sk}.tube.wall"),
                        format!("wall {w} m is not less than the radius {} m", d / 2.0),
                    ));
                }
                cx.structural(BeamSection::tube(d, w), b.section.span(), sk.clone())?
            }
            None => {
                let need =
                    |v: &Option<S<f64>>, f: &str, lim: Limit| -> Result<f64, ScenarioError> {
                        match v {
                            Some(v) => cx.bounded(v, format!("{sk}.{f}"), lim),
                            None => Err(cx.err(
                                ErrorKind::Schema,
                                b.section.span(),
                                format!("{sk}.{f}"),
                                format!(
                                "missing field `{f}` (or give tube = {{ outer_diameter, wall }})"
                            ),
                            )),
                        }
                    };
                let area = need(&sec.area, "area", L::AREA)?;
                let iy = need(&sec.iy, "iy", L::SECOND_MOMENT)?;
                let iz = need(&sec.iz, "iz", L::SECOND_MOMENT)?;
                let j = need(&sec.torsion_constant, "torsion_constant", L::SECOND_MOMENT)?;
                let ip = need(&sec.polar_inertia, "polar_inertia", L::SECOND_MOMENT)?;
                cx.structural(
                    BeamSection::general(area, iy, iz, j, ip),
                    b.section.span(),
                    sk.clone(),
                )?
            }
        };
        let axis = cx.direction(&b.axis, format!("{k}.axis"))?;
        let y_axis = match &sec.y_axis {
            Some(y) => Some(cx.direction(y, format!("{sk}.y_axis"))?),
            None => None,
        };
        let frame = match Frame::new(axis, y_axis) {
            Ok(f) => f,
            Err(e @ StructureError::ZeroAxis { field: "axis" }) => {
                return Err(cx.invalid(b.axis.span(), format!("{k}.axis"), e.to_string()))
            }
            Err(e) => {
                return Err(cx.invalid(
                    sec.y_axis.as_ref().map_or(b.axis.span(), |y| y.span()),
                    format!("{sk}.y_axis"),
                    e.to_string(),
                ))
            }
        };
        let (tb, tt, ta) = DEFAULT_BEAM_TERMS;
        let terms = match &b.terms {
            Some(t) => {
                let t = t.get_ref();
                BeamTerms::new(
                    cx.terms(&t.bending, tb, format!("{k}.terms.bending"))?,
                    cx.terms(&t.torsion, tt, format!("{k}.terms.torsion"))?,
                    cx.terms(&t.axial, ta, format!("{k}.terms.axial"))?,
                )
            }
            None => BeamTerms::new(tb, tt, ta),
        };
        let terms = cx.structural(terms, b.name.span(), format!("{k}.terms"))?;
        spans.insert(
            b.name.get_ref().clone(),
            Spans::of(&b.name, &b.parent, &b.station),
        );
        beams.push(Beam {
            name: b.name.get_ref().clone(),
            attachment,
            frame,
            length,
            youngs_modulus: mat.youngs_modulus,
            shear_modulus: mat.shear_modulus,
            density: mat.density,
            section,
            terms,
        });
    }

    let mut plates = Vec::new();
    for (i, p) in raw.plates.iter().enumerate() {
        let p = p.get_ref();
        let k = format!("plates[{i}]");
        cx.name(&p.name, format!("{k}.name"))?;
        let attachment = attach(&k, &p.parent, &p.station, &p.root, "root")?;
        let length = cx.bounded(&p.length, format!("{k}.length"), L::LENGTH)?;
        let width = cx.bounded(&p.width, format!("{k}.width"), L::LENGTH)?;
        let la = cx.direction(&p.length_axis, format!("{k}.length_axis"))?;
        let nn = cx.direction(&p.normal, format!("{k}.normal"))?;
        let (d, mu, nu) = match (&p.material, &p.thickness) {
            (Some(m), Some(h)) => {
                for (v, f) in [
                    (&p.areal_density, "areal_density"),
                    (&p.bending_stiffness, "bending_stiffness"),
                    (&p.poisson_ratio, "poisson_ratio"),
                ] {
                    if let Some(v) = v {
                        return Err(cx.invalid(v.span(), format!("{k}.{f}"), "give either thickness + material or areal_density + bending_stiffness + poisson_ratio"));
                    }
                }
                let h = cx.bounded(h, format!("{k}.thickness"), L::SECTION)?;
                let mat = material(m, format!("{k}.material"))?;
                let (d, mu) = Plate::homogeneous_properties(
                    h,
                    mat.youngs_modulus,
                    mat.poisson_ratio,
                    mat.density,
                );
                (d, mu, mat.poisson_ratio)
            }
            (None, None) => {
                fn need<'v>(
                    cx: &Ctx,
                    v: &'v Option<S<f64>>,
                    span: Range<usize>,
                    k: &str,
                    f: &str,
                ) -> Result<&'v S<f64>, ScenarioError> {
                    v.as_ref().ok_or_else(|| {
                        cx.err(
                            ErrorKind::Schema,
                            span,
                            format!("{k}.{f}"),
                            format!("missing field `{f}` (or give thickness + material)"),
                        )
                    })
                }
                let mu = cx.bounded(
                    need(cx, &p.areal_density, p.name.span(), &k, "areal_density")?,
                    format!("{k}.areal_density"),
                    L::AREAL_DENSITY,
                )?;
                let d = cx.bounded(
                    need(
                        cx,
                        &p.bending_stiffness,
                        p.name.span(),
                        &k,
                        "bending_stiffness",
                    )?,
                    format!("{k}.bending_stiffness"),
                    L::BENDING_STIFFNESS,
                )?;
                let nu_s = need(cx, &p.poisson_ratio, p.name.span(), &k, "poisson_ratio")?;
                let nu = cx.poisson(nu_s, format!("{k}.poisson_ratio"))?;
                (d, mu, nu)
            }
            (Some(m), None) => {
                return Err(cx.err(
                    ErrorKind::Schema,
                    m.span(),
                    format!("{k}.thickness"),
                    "missing field `thickness` (a plate of a material needs its thickness)",
                ))
            }
            (None, Some(h)) => {
                return Err(cx.err(
                    ErrorKind::Schema,
                    h.span(),
                    format!("{k}.material"),
                    "missing field `material` (a plate of a given thickness needs its material)",
                ))
            }
        };
        let (tl, tw) = DEFAULT_PLATE_TERMS;
        let terms = match &p.terms {
            Some(t) => {
                let t = t.get_ref();
                PlateTerms::new(
                    cx.terms(&t.length, tl, format!("{k}.terms.length"))?,
                    cx.terms(&t.width, tw, format!("{k}.terms.width"))?,
                )
            }
            None => PlateTerms::new(tl, tw),
        };
        let terms = cx.structural(terms, p.name.span(), format!("{k}.terms"))?;
        let plate = Plate::new(
            p.name.get_ref().clone(),
            attachment,
            la,
            nn,
            length,
            width,
            mu,
            d,
            nu,
            terms,
        )
        .map_err(|e| {
            // The key the failing field was written as: D and ρh come from the thickness
            // (and the material) when those are given.
            let homogeneous = p.thickness.as_ref();
            let given = |v: &Option<S<f64>>, f: &'static str| {
                homogeneous
                    .map(|h| (h.span(), "thickness"))
                    .or_else(|| v.as_ref().map(|v| (v.span(), f)))
                    .unwrap_or((p.name.span(), f))
            };
            let (span, f) = match &e {
                StructureError::ZeroAxis {
                    field: "length_axis",
                } => (p.length_axis.span(), "length_axis"),
                StructureError::NotPositive {
                    field: "length", ..
                } => (p.length.span(), "length"),
                StructureError::NotPositive { field: "width", .. } => (p.width.span(), "width"),
                StructureError::NotPositive {
                    field: "areal_density",
                    ..
                } => given(&p.areal_density, "areal_density"),
                StructureError::NotPositive {
                    field: "bending_stiffness",
                    ..
                } => given(&p.bending_stiffness, "bending_stiffness"),
                StructureError::PoissonRatio { .. } => match (&p.material, &p.poisson_ratio) {
                    (Some(m), _) => (m.span(), "material"),
                    (None, Some(v)) => (v.span(), "poisson_ratio"),
                    (None, None) => (p.name.span(), "poisson_ratio"),
                },
                _ => (p.normal.span(), "normal"),
            };
            cx.invalid(span, format!("{k}.{f}"), e.to_string())
        })?;
        spans.insert(
            p.name.get_ref().clone(),
            Spans::of(&p.name, &p.parent, &p.station),
        );
        plates.push(plate);
    }

    let mut masses = Vec::new();
    for (i, m) in raw.masses.iter().enumerate() {
        let m = m.get_ref();
        let k = format!("masses[{i}]");
        cx.name(&m.name, format!("{k}.name"))?;
        let attachment = attach(&k, &m.parent, &m.station, &m.point, "point")?;
        let mass = cx.bounded(&m.mass, format!("{k}.mass"), L::MASS)?;
        let offset = match &m.offset {
            Some(o) => cx.point(o, format!("{k}.offset"))?,
            None => Vec3::ZERO,
        };
        let inertia = match &m.inertia {
            Some(j) => cx.inertia(j, format!("{k}.inertia"))?,
            None => crate::math::Mat3::ZERO,
        };
        spans.insert(
            m.name.get_ref().clone(),
            Spans::of(&m.name, &m.parent, &m.station),
        );
        masses.push(LumpedMass {
            name: m.name.get_ref().clone(),
            attachment,
            offset,
            mass,
            inertia,
        });
    }

    let basis = raw
        .ritz
        .as_ref()
        .map(|r| r.get_ref().basis)
        .unwrap_or_default();
    let structure =
        Structure::new(name.clone(), hub, beams, plates, masses, basis).map_err(|e| {
            let (span, key) = match &e {
                StructureError::DuplicateName { name } => {
                    (spans.get(name).map(|s| s.name.clone()), "name".to_string())
                }
                StructureError::UnknownParent { component, .. } => (
                    spans.get(component).map(|s| s.parent.clone()),
                    format!("{component}.parent"),
                ),
                StructureError::Cycle { path } => (
                    path.first()
                        .and_then(|n| spans.get(n))
                        .map(|s| s.parent.clone()),
                    format!("{}.parent", path.first().cloned().unwrap_or_default()),
                ),
                StructureError::StationBeyondParent { component, .. } => (
                    spans.get(component).map(|s| s.station.clone()),
                    format!("{component}.station"),
                ),
                _ => (None, "structure".to_string()),
            };
            cx.invalid(span.unwrap_or(0..0), key, e.to_string())
        })?;
    let deployment = match &raw.deployment {
        Some(d) => Some(deployment(cx, d, &structure)?),
        None => None,
    };
    let response = match &raw.response {
        Some(r) => response(cx, r)?,
        None => ResponseSettings::default(),
    };
    let mut at = BTreeMap::new();
    let loc = |span: Range<usize>| Location::of_offset(cx.src, span.start);
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
    if let Some(r) = &raw.response {
        let span = r
            .get_ref()
            .output_rate
            .as_ref()
            .map_or(r.span(), |v| v.span());
        keys.insert("response.output_rate", loc(span));
    }
    if let Some(d) = &raw.deployment {
        let span = d
            .get_ref()
            .output_rate
            .as_ref()
            .map_or(d.span(), |v| v.span());
        keys.insert("deployment.output_rate", loc(span));
    }
    Ok(Scenario {
        name,
        structure,
        deployment,
        response,
        sources: Sources {
            file: cx.file.to_string(),
            at,
            keys,
        },
    })
}

/// `[response]` (docs/scenario.md): duration > 0, output_rate > 0 with at most
/// [`crate::response::MAX_ROWS`] samples, modes ≥ 1 (clamped later to the model's count,
/// with a warning), 0 ≤ damping_ratio < 1.
fn response(cx: &Ctx, r: &S<RawResponse>) -> Result<ResponseSettings, ScenarioError> {
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
        Some(v) if L::DAMPING_RATIO.contains(*v.get_ref()) && *v.get_ref() < 1.0 => *v.get_ref(),
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

/// Default deployment settings (docs/scenario.md).
pub const DEFAULT_END_TIME: f64 = 300.0;
/// Default sample rate, Hz.
pub const DEFAULT_OUTPUT_RATE: f64 = 10.0;
/// Default relative integration tolerance.
pub const DEFAULT_TOLERANCE: f64 = 1e-10;

/// Builds the deployment chain from `[deployment]` and the structure (MODEL.md §3.2).
fn deployment(
    cx: &Ctx,
    raw: &S<RawDeployment>,
    st: &Structure,
) -> Result<Deployment, ScenarioError> {
    use crate::deploy::chain::{Chain, Hinge, Panel, PlanarHub};
    use std::f64::consts::PI;
    let d = raw.get_ref();
    let plate = st
        .plates
        .iter()
        .find(|p| p.name == *d.plate.get_ref())
        .ok_or_else(|| {
            let names: Vec<&str> = st.plates.iter().map(|p| p.name.as_str()).collect();
            cx.invalid(
                d.plate.span(),
                "deployment.plate",
                format!(
                    "no plate named \"{}\" (plates: {})",
                    d.plate.get_ref(),
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            )
        })?;
    let lengths: Vec<f64> = match (&d.panels, &d.panel_lengths) {
        (Some(_), Some(l)) => {
            return Err(cx.invalid(
                l.span(),
                "deployment.panel_lengths",
                "give either panels or panel_lengths, not both",
            ))
        }
        (Some(n), None) => {
            let v = *n.get_ref();
            if !(1..=L::MAX_PANELS as i64).contains(&v) {
                return Err(cx.invalid(
                    n.span(),
                    "deployment.panels",
                    format!("must be between 1 and {}, got {v}", L::MAX_PANELS),
                ));
            }
            vec![plate.length / v as f64; v as usize]
        }
        (None, Some(l)) => {
            let v = l.get_ref();
            if v.is_empty() || v.len() > L::MAX_PANELS {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!("needs 1 to {} lengths, got {}", L::MAX_PANELS, v.len()),
                ));
            }
            if let Some(bad) = v.iter().find(|x| !L::PANEL_LENGTH.contains(**x)) {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!(
                        "every length must lie in {}, got {bad:e}",
                        L::PANEL_LENGTH.describe()
                    ),
                ));
            }
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |(a, b), x| (a.min(*x), b.max(*x)));
            if hi > L::MAX_PANEL_LENGTH_RATIO * lo {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!(
                        "the longest panel ({hi} m) is more than {} times the shortest ({lo} m)",
                        L::MAX_PANEL_LENGTH_RATIO
                    ),
                ));
            }
            let sum: f64 = v.iter().sum();
            if (sum - plate.length).abs() > 1e-9 * plate.length {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!(
                        "the lengths sum to {sum} m, but the plate \"{}\" is {} m long",
                        plate.name, plate.length
                    ),
                ));
            }
            v.clone()
        }
        (None, None) => {
            return Err(cx.invalid(
                raw.span(),
                "deployment.panels",
                "missing: give panels or panel_lengths",
            ))
        }
    };
    let n = lengths.len();
    let panel_mass = match &d.panel_mass {
        Some(m) => Some(cx.bounded(m, "deployment.panel_mass", L::MASS)?),
        None => None,
    };
    let panel_inertia = match &d.panel_inertia {
        Some(m) => Some(cx.bounded(m, "deployment.panel_inertia", L::PANEL_INERTIA)?),
        None => None,
    };
    let panels: Vec<Panel> = lengths
        .iter()
        .map(|&l| {
            let mass = panel_mass.unwrap_or(plate.areal_density * l * plate.width);
            Panel {
                length: l,
                mass,
                inertia: panel_inertia.unwrap_or(mass * l * l / 12.0),
            }
        })
        .collect();
    // Hinges: [deployment.hinge] for all, [[deployment.hinges]] per hinge overriding it.
    let all = d.hinge.as_ref().map(|h| h.get_ref());
    let k_all = match all.and_then(|h| h.stiffness.as_ref()) {
        Some(k) => Some(cx.bounded(k, "deployment.hinge.stiffness", L::HINGE_STIFFNESS)?),
        None => None,
    };
    let preload = cx.bounded_or(
        &all.and_then(|h| h.preload_angle.clone()),
        0.0,
        "deployment.hinge.preload_angle",
        L::ANGLE,
    )?;
    let damping_all = cx.bounded_or(
        &all.and_then(|h| h.damping.clone()),
        0.0,
        "deployment.hinge.damping",
        L::HINGE_DAMPING,
    )?;
    let friction_all = cx.bounded_or(
        &all.and_then(|h| h.friction.clone()),
        0.0,
        "deployment.hinge.friction",
        L::HINGE_FRICTION,
    )?;
    if let Some(list) = &d.hinges {
        if list.len() != n {
            let span = list.first().map_or(raw.span(), |h| h.span());
            return Err(cx.invalid(
                span,
                "deployment.hinges",
                format!("{} entries for {n} panels: give one per hinge", list.len()),
            ));
        }
    }
    let mut hinges = Vec::with_capacity(n);
    for i in 0..n {
        let one = d.hinges.as_ref().map(|l| &l[i]);
        let r = one.map(|h| h.get_ref());
        let key = |f: &str| {
            if r.is_some() {
                format!("deployment.hinges[{i}].{f}")
            } else {
                format!("deployment.hinge.{f}")
            }
        };
        let default_latch = if i == 0 { PI / 2.0 } else { PI };
        let latch = cx.bounded_or(
            &r.and_then(|h| h.latch_angle.clone()),
            default_latch,
            key("latch_angle"),
            L::ANGLE,
        )?;
        if !(latch > 0.0 && latch <= PI) {
            let span = r
                .and_then(|h| h.latch_angle.as_ref())
                .map_or(raw.span(), |x| x.span());
            return Err(cx.invalid(
                span,
                key("latch_angle"),
                format!("must lie in (0, π], got {latch}"),
            ));
        }
        let stiffness = match r.and_then(|h| h.stiffness.clone()) {
            Some(k) => cx.bounded(&k, key("stiffness"), L::HINGE_STIFFNESS)?,
            None => k_all.ok_or_else(|| {
                cx.invalid(
                    one.map_or(raw.span(), |h| h.span()),
                    "deployment.hinge.stiffness",
                    format!("missing: hinge {} has no stiffness (set [deployment.hinge] stiffness or one per hinge)", i + 1),
                )
            })?,
        };
        let reference = cx.bounded_or(
            &r.and_then(|h| h.reference_angle.clone()),
            latch + preload,
            key("reference_angle"),
            L::ANGLE,
        )?;
        let initial = cx.bounded_or(
            &r.and_then(|h| h.initial_angle.clone()),
            0.0,
            key("initial_angle"),
            L::ANGLE,
        )?;
        if initial >= latch {
            let span = r
                .and_then(|h| h.initial_angle.as_ref())
                .map_or(raw.span(), |x| x.span());
            return Err(cx.invalid(
                span,
                key("initial_angle"),
                format!("{initial} rad is not below the latch angle {latch} rad"),
            ));
        }
        hinges.push(Hinge {
            stiffness,
            reference_angle: reference,
            damping: cx.bounded_or(
                &r.and_then(|h| h.damping.clone()),
                damping_all,
                key("damping"),
                L::HINGE_DAMPING,
            )?,
            friction: cx.bounded_or(
                &r.and_then(|h| h.friction.clone()),
                friction_all,
                key("friction"),
                L::HINGE_FRICTION,
            )?,
            latch_angle: latch,
            initial_angle: initial,
            initial_rate: cx.bounded_or(
                &r.and_then(|h| h.initial_rate.clone()),
                0.0,
                key("initial_rate"),
                L::RATE,
            )?,
        });
    }
    let hub = match d.hub.as_ref().map(|h| *h.get_ref()) {
        None | Some(RawMotion::Fixed) => PlanarHub::Fixed,
        Some(RawMotion::Free) => {
            let w = plate.width_axis();
            PlanarHub::Free {
                mass: st.hub.mass,
                inertia: st.hub.inertia.apply(w).dot(w),
            }
        }
    };
    let arm = st.attachment_point(&plate.attachment) - st.hub.center_of_mass;
    let chain = Chain {
        panels,
        hinges,
        hub,
        root: [arm.dot(plate.length_axis), arm.dot(plate.normal)],
    };
    let tolerance = cx.bounded_or(
        &d.tolerance,
        DEFAULT_TOLERANCE,
        "deployment.tolerance",
        L::TOLERANCE,
    )?;
    let end_time = cx.bounded_or(
        &d.end_time,
        DEFAULT_END_TIME,
        "deployment.end_time",
        L::DURATION,
    )?;
    let output_rate = cx.bounded_or(
        &d.output_rate,
        DEFAULT_OUTPUT_RATE,
        "deployment.output_rate",
        L::OUTPUT_RATE,
    )?;
    let rows = crate::response::rows(end_time, output_rate);
    if rows > crate::response::MAX_ROWS {
        let span = d
            .output_rate
            .as_ref()
            .or(d.end_time.as_ref())
            .map_or(raw.span(), |v| v.span());
        return Err(cx.invalid(
            span,
            "deployment.output_rate",
            format!(
                "{end_time} s at {output_rate} Hz would write {rows} rows; the limit is {} \
                 (lower output_rate or end_time)",
                crate::response::MAX_ROWS
            ),
        ));
    }
    Ok(Deployment {
        plate: plate.name.clone(),
        chain,
        latching: match d.latching.as_ref().map(|l| *l.get_ref()) {
            Some(RawLatching::Simultaneous) => Latching::Simultaneous,
            _ => Latching::Sequential,
        },
        end_time,
        output_rate,
        tolerance,
    })
}
