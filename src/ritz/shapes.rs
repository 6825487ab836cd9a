//! Displacement fields of the assembled model: the structure-frame displacement of any point
//! of a component for a vector of generalized coordinates q (a mode shape or a response).

use super::assembly::{Element, ElementKind, FieldKind, RitzModel};
use crate::math::Vec3;
use crate::structure::ComponentId;

/// One sampled point of a component.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PointSample {
    /// Local coordinates: (x, 0) along a beam, (x, y) on a plate, m.
    pub local: [f64; 2],
    /// Undeformed position, structure frame, m.
    pub position: Vec3,
    /// Displacement, structure frame (units of q times metres per unit of q).
    pub displacement: Vec3,
    /// Small rotation of the section (beams: includes the twist θ about the axis), rad per unit q.
    pub rotation: Vec3,
}

fn attachment_motion(e: &Element, q: &[f64]) -> (Vec3, Vec3) {
    let t = &e.attachment;
    let mut v = [0.0; 6];
    for (r, vr) in v.iter_mut().enumerate() {
        *vr = (0..q.len()).map(|c| t[(r, c)] * q[c]).sum();
    }
    (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
}

/// Samples a beam at `n` equally spaced stations (root and tip included).
pub fn sample_beam(model: &RitzModel, beam: usize, q: &[f64], n: usize) -> Vec<PointSample> {
    (0..n)
        .filter_map(|i| beam_point(model, beam, i as f64 / (n.max(2) - 1) as f64, q))
        .collect()
}

/// The basis values of a beam's three fields at one station, computed once and reused for
/// many coordinate vectors ([`BeamStation::sample`]).
#[derive(Debug, Clone)]
pub struct BeamStation {
    beam: usize,
    xi: f64,
    axial: Vec<crate::basis::Derivs>,
    bending: Vec<crate::basis::Derivs>,
    torsion: Vec<crate::basis::Derivs>,
}

impl BeamStation {
    /// Beam `beam` at ξ = x/L ∈ [0, 1]; `None` for a beam the model does not have.
    pub fn new(model: &RitzModel, beam: usize, xi: f64) -> Option<Self> {
        let e = model.element(ComponentId::Beam(beam))?;
        let ElementKind::Beam {
            axial,
            bending,
            torsion,
            ..
        } = &e.kind
        else {
            return None;
        };
        Some(Self {
            beam,
            xi,
            axial: axial.eval_vec(xi),
            bending: bending.eval_vec(xi),
            torsion: torsion.eval_vec(xi),
        })
    }

    /// The section's displacement and small rotation (twist included) for coordinates q,
    /// given the motion (u₀, θ₀) of the beam's attachment section for the same q
    /// ([`attachment_of`]).
    pub fn sample(&self, model: &RitzModel, q: &[f64], attachment: (Vec3, Vec3)) -> PointSample {
        let e = model
            .element(ComponentId::Beam(self.beam))
            .expect("a BeamStation is made for a beam of this model");
        let b = &model.structure.beams[self.beam];
        let f = b.frame;
        let (u0, th0) = attachment;
        let coeff = |kind: FieldKind| &q[e.field(kind)];
        let x = self.xi * b.length;
        let sum = |vals: &[crate::basis::Derivs], c: &[f64], d: usize| -> f64 {
            vals.iter().zip(c).map(|(v, ci)| v[d] * ci).sum()
        };
        let u = sum(&self.axial, coeff(FieldKind::U), 0);
        let v = sum(&self.bending, coeff(FieldKind::V), 0);
        let w = sum(&self.bending, coeff(FieldKind::W), 0);
        let dv = sum(&self.bending, coeff(FieldKind::V), 1) / b.length;
        let dw = sum(&self.bending, coeff(FieldKind::W), 1) / b.length;
        let th = sum(&self.torsion, coeff(FieldKind::Theta), 0);
        let r = f.ex * x;
        PointSample {
            local: [x, 0.0],
            position: e.origin + r,
            displacement: u0 + th0.cross(r) + f.ex * u + f.ey * v + f.ez * w,
            rotation: th0 + f.ex * th - f.ey * dw + f.ez * dv,
        }
    }
}

/// The section of beam `beam` at ξ = x/L ∈ [0, 1]: its displacement and small rotation
/// (twist included) for coordinates q. `None` for a beam the model does not have.
pub fn beam_point(model: &RitzModel, beam: usize, xi: f64, q: &[f64]) -> Option<PointSample> {
    let station = BeamStation::new(model, beam, xi)?;
    let att = attachment_of(model, ComponentId::Beam(beam), q)?;
    Some(station.sample(model, q, att))
}

/// The displacement and rotation of the attachment section of a component (the hub's or a
/// beam section's motion where the component is fixed) for coordinates q.
pub fn attachment_of(model: &RitzModel, id: ComponentId, q: &[f64]) -> Option<(Vec3, Vec3)> {
    model.element(id).map(|e| attachment_motion(e, q))
}

/// Samples a plate on an `nx` × `ny` grid (edges included), row-major in x.
pub fn sample_plate(
    model: &RitzModel,
    plate: usize,
    q: &[f64],
    nx: usize,
    ny: usize,
) -> Vec<PointSample> {
    let grid = |i: usize, n: usize| i as f64 / (n.max(2) - 1) as f64;
    (0..nx)
        .flat_map(|i| (0..ny).map(move |j| (grid(i, nx), grid(j, ny))))
        .filter_map(|(xi, eta)| plate_point(model, plate, xi, eta, q))
        .collect()
}

/// The basis values of a plate's deflection at one point (ξ, η), computed once and reused for
/// many coordinate vectors ([`PlatePoint::sample`]).
#[derive(Debug, Clone)]
pub struct PlatePoint {
    plate: usize,
    xi: f64,
    eta: f64,
    x: Vec<crate::basis::Derivs>,
    y: Vec<crate::basis::Derivs>,
}

impl PlatePoint {
    /// Plate `plate` at (ξ, η) ∈ [0, 1]² (ξ along the length from the root edge, η across the
    /// width); `None` for a plate the model does not have.
    pub fn new(model: &RitzModel, plate: usize, xi: f64, eta: f64) -> Option<Self> {
        let e = model.element(ComponentId::Plate(plate))?;
        let ElementKind::Plate { length, width, .. } = &e.kind else {
            return None;
        };
        Some(Self {
            plate,
            xi,
            eta,
            x: length.eval_vec(xi),
            y: width.eval_vec(eta),
        })
    }

    /// The point's displacement and the small rotation of its normal for coordinates q,
    /// given the motion (u₀, θ₀) of the plate's attachment for the same q.
    pub fn sample(&self, model: &RitzModel, q: &[f64], attachment: (Vec3, Vec3)) -> PointSample {
        let e = model
            .element(ComponentId::Plate(self.plate))
            .expect("a PlatePoint is made for a plate of this model");
        let p = &model.structure.plates[self.plate];
        let (ea, eb, nn) = (p.length_axis, p.width_axis(), p.normal);
        let (u0, th0) = attachment;
        let g = &q[e.field(FieldKind::G)];
        let nyb = self.y.len();
        let (mut w, mut wx, mut wy) = (0.0, 0.0, 0.0);
        for (m, xm) in self.x.iter().enumerate() {
            for (nidx, yn) in self.y.iter().enumerate() {
                let c = g[m * nyb + nidx];
                w += c * xm[0] * yn[0];
                wx += c * xm[1] * yn[0];
                wy += c * xm[0] * yn[1];
            }
        }
        let (x, y) = (self.xi * p.length, (self.eta - 0.5) * p.width);
        let r = ea * x + eb * y;
        // Small rotation of the normal: ∂W/∂x about −e_b, ∂W/∂y about e_a.
        let rot = th0 + eb * (-wx / p.length) + ea * (wy / p.width);
        PointSample {
            local: [x, y],
            position: e.origin + r,
            displacement: u0 + th0.cross(r) + nn * w,
            rotation: rot,
        }
    }
}

/// The point (ξ, η) ∈ [0, 1]² of plate `plate` (ξ along the length from the root edge, η
/// across the width): its displacement and the small rotation of its normal for
/// coordinates q. `None` for a plate the model does not have.
pub fn plate_point(
    model: &RitzModel,
    plate: usize,
    xi: f64,
    eta: f64,
    q: &[f64],
) -> Option<PointSample> {
    let point = PlatePoint::new(model, plate, xi, eta)?;
    let att = attachment_of(model, ComponentId::Plate(plate), q)?;
    Some(point.sample(model, q, att))
}

/// Translation of the hub's centre of mass and its small rotation, for q over all
/// coordinates (hub first).
pub fn hub_motion(q: &[f64]) -> (Vec3, Vec3) {
    (Vec3::new(q[0], q[1], q[2]), Vec3::new(q[3], q[4], q[5]))
}
