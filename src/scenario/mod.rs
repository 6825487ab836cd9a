//! Scenario files (TOML, format version 1; keys documented in docs/scenario.md): parsing,
//! validation with the location of every refused value, and construction of the
//! [`Structure`].

mod error;
mod raw;

pub use error::{ErrorKind, Location, ScenarioError};

use crate::deploy::{Deployment, Latching};
use crate::math::Vec3;
use crate::response::{HandoverMethod, ResponseSettings};
use crate::structure::{
    inertia_tensor, Attachment, Beam, BeamSection, BeamTerms, Frame, Hub, HubMotion, LumpedMass,
    Material, Plate, PlateTerms, Structure, StructureError,
};
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
}

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

    fn positive(&self, v: &S<f64>, key: impl Into<String>) -> Result<f64, ScenarioError> {
        let x = *v.get_ref();
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(
                v.span(),
                key,
                format!("must be a positive finite number, got {x}"),
            ))
        }
    }

    fn vec3(&self, v: &S<[f64; 3]>, key: impl Into<String>) -> Result<Vec3, ScenarioError> {
        let a = *v.get_ref();
        if a.iter().all(|x| x.is_finite()) {
            Ok(Vec3(a))
        } else {
            Err(self.invalid(v.span(), key, "every component must be finite"))
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
        let file = path.display().to_string();
        let src = std::fs::read_to_string(path).map_err(|e| ScenarioError {
            kind: ErrorKind::Io,
            file: file.clone(),
            location: Location { line: 0, column: 0 },
            key: "(file)".into(),
            reason: e.to_string(),
        })?;
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
    let name = raw
        .name
        .as_ref()
        .map_or_else(|| "unnamed".to_string(), |n| n.get_ref().clone());

    // Materials.
    let mut materials: BTreeMap<&str, Material> = BTreeMap::new();
    for (mname, m) in &raw.materials {
        let k = format!("materials.{mname}");
        let e = cx.positive(&m.get_ref().youngs_modulus, format!("{k}.youngs_modulus"))?;
        let rho = cx.positive(&m.get_ref().density, format!("{k}.density"))?;
        let nu_s = &m.get_ref().poisson_ratio;
        let nu = *nu_s.get_ref();
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(cx.invalid(
                nu_s.span(),
                format!("{k}.poisson_ratio"),
                format!("must lie in (-1, 0.5), got {nu}"),
            ));
        }
        let g = match &m.get_ref().shear_modulus {
            Some(g) => Some(cx.positive(g, format!("{k}.shear_modulus"))?),
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
            let d = cx.positive(&c.diameter, format!("{k}.diameter"))?;
            let w = cx.positive(&c.wall, format!("{k}.wall"))?;
            let l = cx.positive(&c.length, format!("{k}.length"))?;
            if w >= d / 2.0 {
                return Err(cx.invalid(
                    c.wall.span(),
                    format!("{k}.wall"),
                    format!("wall {w} m is not less than the radius {} m", d / 2.0),
                ));
            }
            let axis = cx.vec3(&c.axis, format!("{k}.axis"))?;
            let center = cx.vec3(&c.center, format!("{k}.center"))?;
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
            let mass = cx.positive(rh.mass.as_ref().ok_or_else(|| missing("mass"))?, "hub.mass")?;
            let inertia_s = rh.inertia.as_ref().ok_or_else(|| missing("inertia"))?;
            let inertia = cx.structural(
                inertia_tensor(inertia_s.get_ref()),
                inertia_s.span(),
                "hub.inertia",
            )?;
            let c = cx.vec3(
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
                point: cx.vec3(p, format!("{key}.{point_key}"))?,
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
            let st = *s.get_ref();
            if !(st.is_finite() && st >= 0.0) {
                return Err(cx.invalid(
                    s.span(),
                    format!("{key}.station"),
                    format!("must be a finite distance >= 0, got {st}"),
                ));
            }
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
        let attachment = attach(&k, &b.parent, &b.station, &b.root, "root")?;
        let length = cx.positive(&b.length, format!("{k}.length"))?;
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
                let d = cx.positive(&t.outer_diameter, format!("{sk}.tube.outer_diameter"))?;
                let w = cx.positive(&t.wall, format!("{sk}.tube.wall"))?;
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
                let need = |v: &Option<S<f64>>, f: &str| -> Result<f64, ScenarioError> {
                    match v {
                        Some(v) => cx.positive(v, format!("{sk}.{f}")),
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
                let area = need(&sec.area, "area")?;
                let iy = need(&sec.iy, "iy")?;
                let iz = need(&sec.iz, "iz")?;
                let j = need(&sec.torsion_constant, "torsion_constant")?;
                let ip = need(&sec.polar_inertia, "polar_inertia")?;
                cx.structural(
                    BeamSection::general(area, iy, iz, j, ip),
                    b.section.span(),
                    sk.clone(),
                )?
            }
        };
        let axis = cx.vec3(&b.axis, format!("{k}.axis"))?;
        let y_axis = match &sec.y_axis {
            Some(y) => Some(cx.vec3(y, format!("{sk}.y_axis"))?),
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
        let attachment = attach(&k, &p.parent, &p.station, &p.root, "root")?;
        let length = cx.positive(&p.length, format!("{k}.length"))?;
        let width = cx.positive(&p.width, format!("{k}.width"))?;
        let la = cx.vec3(&p.length_axis, format!("{k}.length_axis"))?;
        let nn = cx.vec3(&p.normal, format!("{k}.normal"))?;
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
                let h = cx.positive(h, format!("{k}.thickness"))?;
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
                let mu = cx.positive(
                    need(cx, &p.areal_density, p.name.span(), &k, "areal_density")?,
                    format!("{k}.areal_density"),
                )?;
                let d = cx.positive(
                    need(
                        cx,
                        &p.bending_stiffness,
                        p.name.span(),
                        &k,
                        "bending_stiffness",
                    )?,
                    format!("{k}.bending_stiffness"),
                )?;
                let nu_s = need(cx, &p.poisson_ratio, p.name.span(), &k, "poisson_ratio")?;
                let nu = *nu_s.get_ref();
                if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
                    return Err(cx.invalid(
                        nu_s.span(),
                        format!("{k}.poisson_ratio"),
                        format!("must lie in (-1, 0.5), got {nu}"),
                    ));
                }
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
            let (span, f) = match e {
                StructureError::ZeroAxis {
                    field: "length_axis",
                } => (p.length_axis.span(), "length_axis"),
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
        let attachment = attach(&k, &m.parent, &m.station, &m.point, "point")?;
        let mass = cx.positive(&m.mass, format!("{k}.mass"))?;
        let offset = match &m.offset {
            Some(o) => cx.vec3(o, format!("{k}.offset"))?,
            None => Vec3::ZERO,
        };
        let inertia = match &m.inertia {
            Some(j) => cx.structural(
                inertia_tensor(j.get_ref()),
                j.span(),
                format!("{k}.inertia"),
            )?,
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
    Ok(Scenario {
        name,
        structure,
        deployment,
        response,
    })
}

/// `[response]` (docs/scenario.md): duration > 0, output_rate > 0 with at most
/// [`crate::response::MAX_ROWS`] samples, modes ≥ 1 (clamped later to the model's count,
/// with a warning), 0 ≤ damping_ratio < 1.
fn response(cx: &Ctx, r: &S<RawResponse>) -> Result<ResponseSettings, ScenarioError> {
    let d = ResponseSettings::default();
    let rr = r.get_ref();
    let duration = match &rr.duration {
        Some(v) => cx.positive(v, "response.duration")?,
        None => d.duration,
    };
    let output_rate = match &rr.output_rate {
        Some(v) => cx.positive(v, "response.output_rate")?,
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
    let damping_ratio = non_negative(
        cx,
        &rr.damping_ratio,
        d.damping_ratio,
        "response.damping_ratio".into(),
    )?;
    if damping_ratio >= 1.0 {
        let span = rr.damping_ratio.as_ref().map_or(r.span(), |v| v.span());
        return Err(cx.invalid(
            span,
            "response.damping_ratio",
            format!("must be below 1 (an underdamped structure), got {damping_ratio}"),
        ));
    }
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

fn non_negative(
    cx: &Ctx,
    v: &Option<S<f64>>,
    default: f64,
    key: String,
) -> Result<f64, ScenarioError> {
    match v {
        None => Ok(default),
        Some(x) => {
            let val = *x.get_ref();
            if val.is_finite() && val >= 0.0 {
                Ok(val)
            } else {
                Err(cx.invalid(
                    x.span(),
                    key,
                    format!("must be a non-negative finite number, got {val}"),
                ))
            }
        }
    }
}

fn finite(cx: &Ctx, v: &Option<S<f64>>, default: f64, key: String) -> Result<f64, ScenarioError> {
    match v {
        None => Ok(default),
        Some(x) if x.get_ref().is_finite() => Ok(*x.get_ref()),
        Some(x) => Err(cx.invalid(
            x.span(),
            key,
            format!("must be finite, got {}", x.get_ref()),
        )),
    }
}

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
            if !(1..=1000).contains(&v) {
                return Err(cx.invalid(
                    n.span(),
                    "deployment.panels",
                    format!("must be between 1 and 1000, got {v}"),
                ));
            }
            vec![plate.length / v as f64; v as usize]
        }
        (None, Some(l)) => {
            let v = l.get_ref();
            if v.is_empty() || v.len() > 1000 {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!("needs 1 to 1000 lengths, got {}", v.len()),
                ));
            }
            if let Some(bad) = v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                return Err(cx.invalid(
                    l.span(),
                    "deployment.panel_lengths",
                    format!("every length must be positive and finite, got {bad}"),
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
        Some(m) => Some(cx.positive(m, "deployment.panel_mass")?),
        None => None,
    };
    let panel_inertia = match &d.panel_inertia {
        Some(m) => Some(cx.positive(m, "deployment.panel_inertia")?),
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
        Some(k) => Some(non_negative(
            cx,
            &Some(k.clone()),
            0.0,
            "deployment.hinge.stiffness".into(),
        )?),
        None => None,
    };
    let preload = finite(
        cx,
        &all.and_then(|h| h.preload_angle.clone()),
        0.0,
        "deployment.hinge.preload_angle".into(),
    )?;
    let damping_all = non_negative(
        cx,
        &all.and_then(|h| h.damping.clone()),
        0.0,
        "deployment.hinge.damping".into(),
    )?;
    let friction_all = non_negative(
        cx,
        &all.and_then(|h| h.friction.clone()),
        0.0,
        "deployment.hinge.friction".into(),
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
        let latch = finite(
            cx,
            &r.and_then(|h| h.latch_angle.clone()),
            default_latch,
            key("latch_angle"),
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
            Some(k) => non_negative(cx, &Some(k), 0.0, key("stiffness"))?,
            None => k_all.ok_or_else(|| {
                cx.invalid(
                    one.map_or(raw.span(), |h| h.span()),
                    "deployment.hinge.stiffness",
                    format!("missing: hinge {} has no stiffness (set [deployment.hinge] stiffness or one per hinge)", i + 1),
                )
            })?,
        };
        let reference = finite(
            cx,
            &r.and_then(|h| h.reference_angle.clone()),
            latch + preload,
            key("reference_angle"),
        )?;
        let initial = finite(
            cx,
            &r.and_then(|h| h.initial_angle.clone()),
            0.0,
            key("initial_angle"),
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
            damping: non_negative(
                cx,
                &r.and_then(|h| h.damping.clone()),
                damping_all,
                key("damping"),
            )?,
            friction: non_negative(
                cx,
                &r.and_then(|h| h.friction.clone()),
                friction_all,
                key("friction"),
            )?,
            latch_angle: latch,
            initial_angle: initial,
            initial_rate: finite(
                cx,
                &r.and_then(|h| h.initial_rate.clone()),
                0.0,
                key("initial_rate"),
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
    let pos = |v: &Option<S<f64>>, default: f64, key: &str| -> Result<f64, ScenarioError> {
        match v {
            Some(x) => cx.positive(x, key),
            None => Ok(default),
        }
    };
    let tolerance = pos(&d.tolerance, DEFAULT_TOLERANCE, "deployment.tolerance")?;
    if tolerance > 1e-3 {
        let span = d.tolerance.as_ref().map_or(raw.span(), |x| x.span());
        return Err(cx.invalid(
            span,
            "deployment.tolerance",
            format!("must be at most 1e-3, got {tolerance}"),
        ));
    }
    Ok(Deployment {
        plate: plate.name.clone(),
        chain,
        latching: match d.latching.as_ref().map(|l| *l.get_ref()) {
            Some(RawLatching::Simultaneous) => Latching::Simultaneous,
            _ => Latching::Sequential,
        },
        end_time: pos(&d.end_time, DEFAULT_END_TIME, "deployment.end_time")?,
        output_rate: pos(
            &d.output_rate,
            DEFAULT_OUTPUT_RATE,
            "deployment.output_rate",
        )?,
        tolerance,
    })
}
