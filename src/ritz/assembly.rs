//! Assembly of the Ritz mass and stiffness matrices (docs/theory.md §1; the paper's (1.2)–(1.5)).
//!
//! Generalized coordinates q: the hub's six (translation of its centre of mass, small
//! rotation vector), then each beam's own coefficients [u, v, w, θ] (parents before children),
//! then each plate's g_mn (index m·N_width + n). A component's points move with its parent's
//! attachment section — translation U and small rotation Θ, both linear in q through the
//! 6×n *attachment map* T — plus its own deformation:
//!
//! u(r) = U + Θ × r + Σ q_k F_k(r),  so with z = [U; Θ; q_own] = B q, B = [T; P],
//! T = ½ żᵀ M_e ż ⇒ M = Σ Bᵀ M_e B,  Π = ½ q_ownᵀ K_e q_own ⇒ K = Σ Pᵀ K_e P.
//!
//! Compatibility holds by construction; nothing is penalised. The element matrices M_e are
//! written blockwise from the one-dimensional integrals of [`crate::basis::Integrals`]
//! (plates by Kronecker products), so no two-dimensional quadrature is needed.

use crate::basis::{Basis1d, Integrals};
use crate::math::Vec3;
use crate::structure::{Attachment, Beam, ComponentId, Plate, RigidBody, Structure};
use faer::sparse::Triplet;
use faer::Mat;

/// Which field of a component's own coordinates a [`FieldRange`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FieldKind {
    /// A beam's axial displacement u.
    U,
    /// A beam's bending displacement v (along its e_y).
    V,
    /// A beam's bending displacement w (along its e_z).
    W,
    /// A beam's torsion angle θ.
    Theta,
    /// A plate's deflection coefficients g_mn.
    G,
}

impl FieldKind {
    /// The field's name in outputs: "u", "v", "w", "theta" or "g".
    pub fn name(self) -> &'static str {
        match self {
            Self::U => "u",
            Self::V => "v",
            Self::W => "w",
            Self::Theta => "theta",
            Self::G => "g",
        }
    }
}

/// A field of a component's own coordinates (e.g. the mast's `w`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldRange {
    /// Which field.
    pub kind: FieldKind,
    /// First global index.
    pub start: usize,
    /// Number of coordinates.
    pub len: usize,
}

impl FieldRange {
    /// The range of `len` coordinates of field `kind` from global index `start`.
    pub fn new(kind: FieldKind, start: usize, len: usize) -> Self {
        Self { kind, start, len }
    }

    /// Global index range.
    pub fn range(&self) -> std::ops::Range<usize> {
        self.start..self.start + self.len
    }
}

/// The kind of one component together with its Ritz functions: one variant per element kind,
/// so that the component and its basis cannot disagree.
#[derive(Debug)]
pub enum ElementKind {
    /// A beam: axial, bending (v and w), torsion.
    Beam {
        /// Index into `Structure::beams`.
        index: usize,
        /// Axial functions.
        axial: Box<dyn Basis1d>,
        /// Bending functions (shared by v and w).
        bending: Box<dyn Basis1d>,
        /// Torsion functions.
        torsion: Box<dyn Basis1d>,
    },
    /// A plate: X_m along the length, Y_n across the width.
    Plate {
        /// Index into `Structure::plates`.
        index: usize,
        /// Clamped–free functions along the length.
        length: Box<dyn Basis1d>,
        /// Free–free functions across the width.
        width: Box<dyn Basis1d>,
    },
    /// A rigid body (hub, lumped mass): no own coordinates.
    Rigid,
}

/// One component's place in the assembled model.
#[derive(Debug)]
pub struct Element {
    /// Which component (agrees with `kind`: both come from one layout entry).
    pub id: ComponentId,
    /// Its own coordinates, field by field.
    pub fields: Vec<FieldRange>,
    /// The attachment map T (6 × n): [U; Θ] of the attachment section = T q.
    pub attachment: Mat<f64>,
    /// Structure-frame position of the attachment point.
    pub origin: Vec3,
    /// The component's kind and its Ritz functions.
    pub kind: ElementKind,
}

impl Element {
    /// Global index range of the component's own coordinates.
    pub fn own_range(&self) -> std::ops::Range<usize> {
        let start = self.fields.first().map_or(0, |f| f.start);
        let len: usize = self.fields.iter().map(|f| f.len).sum();
        start..start + len
    }

    /// Global index range of one field (empty if the component has no such field).
    pub fn field(&self, kind: FieldKind) -> std::ops::Range<usize> {
        self.fields
            .iter()
            .find(|f| f.kind == kind)
            .map_or(0..0, FieldRange::range)
    }
}

/// A component's own-coordinate layout before its attachment map is known.
struct Part<'a> {
    id: ComponentId,
    attachment: &'a Attachment,
    kind: ElementKind,
    fields: Vec<FieldRange>,
    /// A lumped mass's inertia (beams and plates take theirs from their element matrices).
    lumped: Option<RigidBody>,
}

impl Element {
    fn new(part: Part<'_>, attachment: Mat<f64>, origin: Vec3) -> Self {
        Self {
            id: part.id,
            fields: part.fields,
            attachment,
            origin,
            kind: part.kind,
        }
    }
}

/// The own-coordinate layout of every component but the hub (beams parents first, then
/// plates, then lumped masses) and the total number of coordinates.
fn layout(structure: &Structure) -> (Vec<Part<'_>>, usize) {
    let kind = structure.basis;
    let mut n = HUB_DOF;
    let mut parts = Vec::new();
    for &i in structure.beam_order() {
        let beam = &structure.beams[i];
        let t = beam.terms;
        let mut fields = Vec::new();
        for (field, len) in [
            (FieldKind::U, t.axial),
            (FieldKind::V, t.bending),
            (FieldKind::W, t.bending),
            (FieldKind::Theta, t.torsion),
        ] {
            fields.push(FieldRange::new(field, n, len));
            n += len;
        }
        parts.push(Part {
            id: ComponentId::Beam(i),
            attachment: &beam.attachment,
            kind: ElementKind::Beam {
                index: i,
                axial: kind.rod(t.axial),
                bending: kind.bending(t.bending),
                torsion: kind.rod(t.torsion),
            },
            fields,
            lumped: None,
        });
    }
    for (i, p) in structure.plates.iter().enumerate() {
        let len = p.dof();
        parts.push(Part {
            id: ComponentId::Plate(i),
            attachment: &p.attachment,
            kind: ElementKind::Plate {
                index: i,
                length: plate_length_basis(kind, p),
                width: kind.free_free(p.terms.width),
            },
            fields: vec![FieldRange::new(FieldKind::G, n, len)],
            lumped: None,
        });
        n += len;
    }
    for (i, m) in structure.masses.iter().enumerate() {
        parts.push(Part {
            id: ComponentId::Mass(i),
            attachment: &m.attachment,
            kind: ElementKind::Rigid,
            fields: Vec::new(),
            lumped: Some(m.rigid_body()),
        });
    }
    (parts, n)
}

/// Where an assembly adds its entries: a dense matrix, or a list of triplets (for the
/// eigen-solver's sparse matrices, without ever forming the dense ones).
pub(crate) trait Sink {
    /// a_ij += v.
    fn add(&mut self, i: usize, j: usize, v: f64);
}

impl Sink for Mat<f64> {
    fn add(&mut self, i: usize, j: usize, v: f64) {
        self[(i, j)] += v;
    }
}

/// Entries with their (row, column); zeros are skipped, and entries at the same place are
/// summed when the matrix is built from them.
impl Sink for Vec<Triplet<usize, usize, f64>> {
    fn add(&mut self, i: usize, j: usize, v: f64) {
        if v != 0.0 {
            self.push(Triplet::new(i, j, v));
        }
    }
}

/// A sink shifted by (r0, c0).
struct Offset<'a, S: Sink> {
    sink: &'a mut S,
    r0: usize,
    c0: usize,
}

impl<S: Sink> Sink for Offset<'_, S> {
    fn add(&mut self, i: usize, j: usize, v: f64) {
        self.sink.add(self.r0 + i, self.c0 + j, v);
    }
}

/// The mass and stiffness matrices of a structure (unsymmetrised: M_ij and M_ji may differ
/// in the last bit) and its components' elements.
pub(crate) fn assemble_into<S: Sink>(
    structure: &Structure,
    mass: &mut S,
    stiffness: &mut S,
) -> Vec<Element> {
    // Own-coordinate layout first, so that every T has its final width.
    let (parts, n) = layout(structure);
    let hub = &structure.hub;
    let hub_t = hub_map(n, hub.center_of_mass, hub.center_of_mass);
    add_rigid(mass, &hub_t, &hub.rigid_body());
    let mut elements = vec![Element {
        id: ComponentId::Hub,
        fields: Vec::new(),
        attachment: hub_t,
        origin: hub.center_of_mass,
        kind: ElementKind::Rigid,
    }];
    // Root map of every beam, filled in topological order.
    let mut beam_elem: Vec<Option<usize>> = vec![None; structure.beams.len()];

    for part in parts {
        let att = part.attachment;
        let origin = structure.attachment_point(att);
        let t = match att {
            Attachment::Hub { point } => hub_map(n, *point, hub.center_of_mass),
            Attachment::Beam { beam, station } => {
                let bi = *beam;
                let pe = &elements[beam_elem[bi].expect("parents come first")];
                section_map(&structure.beams[bi], pe, *station, n)
            }
        };
        let own = part.fields.first().map_or(0, |f| f.start);
        match &part.kind {
            ElementKind::Beam {
                index,
                axial,
                bending,
                torsion,
            } => {
                let (me, ke) = beam_element(
                    &structure.beams[*index],
                    axial.as_ref(),
                    bending.as_ref(),
                    torsion.as_ref(),
                );
                add_element(mass, stiffness, &t, own, &me, &ke);
                beam_elem[*index] = Some(elements.len());
            }
            ElementKind::Plate {
                index,
                length,
                width,
            } => {
                let (rigid, coupling) = plate_element_into(
                    &structure.plates[*index],
                    length.as_ref(),
                    width.as_ref(),
                    &mut Offset {
                        sink: &mut *mass,
                        r0: own,
                        c0: own,
                    },
                    &mut Offset {
                        sink: &mut *stiffness,
                        r0: own,
                        c0: own,
                    },
                );
                add_coupling(mass, &t, own, &rigid, &coupling);
            }
            ElementKind::Rigid => {}
        }
        if let Some(rb) = &part.lumped {
            add_rigid(mass, &t, rb);
        }
        elements.push(Element::new(part, t, origin));
    }
    elements
}

/// The assembled Ritz model: K q = ω² M q.
#[derive(Debug)]
pub struct RitzModel {
    /// The structure.
    pub structure: Structure,
    /// Mass matrix (n × n), symmetric positive definite.
    pub mass: Mat<f64>,
    /// Stiffness matrix (n × n), symmetric, zero on the hub's six coordinates.
    pub stiffness: Mat<f64>,
    /// Components in assembly order (hub first).
    pub elements: Vec<Element>,
}

/// Number of hub coordinates (always the first six).
pub const HUB_DOF: usize = 6;

impl RitzModel {
    /// Total number of generalized coordinates (hub included).
    pub fn dof(&self) -> usize {
        self.mass.nrows()
    }

    /// Assembles M and K of a structure with its chosen basis.
    pub fn assemble(structure: &Structure) -> Self {
        let n = layout(structure).1;
        let mut mass = Mat::<f64>::zeros(n, n);
        let mut stiffness = Mat::<f64>::zeros(n, n);
        let elements = assemble_into(structure, &mut mass, &mut stiffness);
        // A pass over memory each (a large model's matrices pass the cache): side by side.
        super::parallel::join(
            n >= PARALLEL_FROM,
            || symmetrize(&mut mass),
            || symmetrize(&mut stiffness),
        );
        Self {
            structure: structure.clone(),
            mass,
            stiffness,
            elements,
        }
    }

    /// The mass matrix of the components `keep` selects only, M_S = Σ_{e∈S} Bᵀ M_e B (n × n,
    /// the same coordinates as [`RitzModel::mass`]). Its rows 0–2 and 3–5 are the linear
    /// momentum of S and its angular momentum about the hub's centre of mass per unit q̇
    /// (the hub's coordinates are a rigid translation and rotation of everything).
    pub fn partial_mass(&self, keep: impl Fn(ComponentId) -> bool) -> Mat<f64> {
        let n = self.dof();
        let st = &self.structure;
        let mut mass = Mat::<f64>::zeros(n, n);
        let mut unused = Mat::<f64>::zeros(n, n);
        for e in self.elements.iter().filter(|e| keep(e.id)) {
            let own = e.own_range().start;
            match (&e.kind, e.id) {
                (
                    ElementKind::Beam {
                        index,
                        axial,
                        bending,
                        torsion,
                    },
                    _,
                ) => {
                    let (me, ke) = beam_element(
                        &st.beams[*index],
                        axial.as_ref(),
                        bending.as_ref(),
                        torsion.as_ref(),
                    );
                    add_element(&mut mass, &mut unused, &e.attachment, own, &me, &ke);
                }
                (
                    ElementKind::Plate {
                        index,
                        length,
                        width,
                    },
                    _,
                ) => {
                    let (me, ke) =
                        plate_element(&st.plates[*index], length.as_ref(), width.as_ref());
                    add_element(&mut mass, &mut unused, &e.attachment, own, &me, &ke);
                }
                (ElementKind::Rigid, ComponentId::Hub) => {
                    add_rigid(&mut mass, &e.attachment, &st.hub.rigid_body());
                }
                (ElementKind::Rigid, ComponentId::Mass(i)) => {
                    add_rigid(&mut mass, &e.attachment, &st.masses[i].rigid_body());
                }
                (ElementKind::Rigid, _) => {}
            }
        }
        symmetrize(&mut mass);
        mass
    }

    /// The hinge lines' dashpots as a damping matrix C, its non-zero entries (row, column):
    /// (1/a²) S_ii' ∫Y_n Y_q dη between the kink functions as their stiffness, with the
    /// dashpots in S (docs/theory.md §1.6). Empty without hinge lines.
    pub fn line_damping(&self) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::new();
        for e in &self.elements {
            let ElementKind::Plate {
                index,
                length,
                width,
            } = &e.kind
            else {
                continue;
            };
            let p = &self.structure.plates[*index];
            if p.hinges.is_empty() {
                continue;
            }
            let iy = Integrals::new(width.as_ref());
            let start = e.own_range().start;
            let mut sink: Vec<Triplet<usize, usize, f64>> = Vec::new();
            add_hinge_lines(
                p,
                &iy,
                length.len(),
                &p.hinge_function_matrix(true),
                &mut sink,
            );
            out.extend(
                sink.into_iter()
                    .map(|t| (start + t.row, start + t.col, t.val)),
            );
        }
        out
    }

    /// The element of a component.
    pub fn element(&self, id: ComponentId) -> Option<&Element> {
        self.elements.iter().find(|e| e.id == id)
    }

    /// The component that owns generalized coordinate `dof` (the hub's six first).
    pub fn component_at(&self, dof: usize) -> ComponentId {
        self.elements
            .iter()
            .find(|e| e.own_range().contains(&dof))
            .map_or(ComponentId::Hub, |e| e.id)
    }

    /// The component a failed solve is traced to: the coordinate of the failing pivot, or,
    /// for an eigensolver that did not converge, the coordinate with the most extreme
    /// stiffness-to-mass ratio (the usual cause: values that spread over too many decades).
    pub fn culprit(&self, e: &super::RitzError) -> ComponentId {
        match e {
            super::RitzError::MassNotPositiveDefinite { pivot } => self.component_at(*pivot),
            super::RitzError::EigenNoConvergence => {
                let n = self.dof();
                let ratio = |i: usize| {
                    let r = self.stiffness[(i, i)] / self.mass[(i, i)];
                    if r.is_finite() {
                        r.abs()
                    } else {
                        f64::INFINITY
                    }
                };
                let worst = (0..n).fold(0, |w, i| if ratio(i) > ratio(w) { i } else { w });
                self.component_at(worst)
            }
            super::RitzError::NotFinite { .. } => {
                // The component out of scale with the rest: its mass farthest, in decades,
                // from the median of the components' masses (a 10 km plate on a 4 m boom,
                // or a micrometre tube on a spacecraft).
                let st = &self.structure;
                let parts: Vec<(f64, ComponentId)> =
                    std::iter::once((st.hub().mass(), ComponentId::Hub))
                        .chain(
                            st.beams()
                                .iter()
                                .enumerate()
                                .map(|(i, b)| (b.mass(), ComponentId::Beam(i))),
                        )
                        .chain(
                            st.plates()
                                .iter()
                                .enumerate()
                                .map(|(i, p)| (p.mass(), ComponentId::Plate(i))),
                        )
                        .chain(
                            st.masses()
                                .iter()
                                .enumerate()
                                .map(|(i, m)| (m.mass(), ComponentId::Mass(i))),
                        )
                        .filter(|(m, _)| *m > 0.0 && m.is_finite())
                        .collect();
                let mut logs: Vec<f64> = parts.iter().map(|(m, _)| m.log10()).collect();
                logs.sort_by(f64::total_cmp);
                let median = logs.get(logs.len() / 2).copied().unwrap_or(0.0);
                parts
                    .iter()
                    .fold((f64::NEG_INFINITY, ComponentId::Hub), |w, (m, id)| {
                        let d = (m.log10() - median).abs();
                        if d > w.0 {
                            (d, *id)
                        } else {
                            w
                        }
                    })
                    .1
            }
        }
    }

    /// The error of a solve whose modes came out not finite: the decades the diagonal mass
    /// of the components' coordinates spans.
    pub fn not_finite(&self) -> super::RitzError {
        let n = self.dof();
        let diag = |i: usize| self.mass[(i, i)].abs();
        // Over the components' own coordinates: the hub's six carry the whole structure's
        // rigid mass and would always be the largest.
        let first = if n > HUB_DOF { HUB_DOF } else { 0 };
        let (lo, hi) = (first..n)
            .map(diag)
            .filter(|v| *v > 0.0)
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        super::RitzError::NotFinite {
            decades: if hi > 0.0 && lo.is_finite() {
                (hi / lo).log10()
            } else {
                0.0
            },
        }
    }
}

/// From this many coordinates up, the two matrices' passes run side by side (a thread's
/// start, some 50 µs, is then small against them).
pub const PARALLEL_FROM: usize = 400;

fn symmetrize(m: &mut Mat<f64>) {
    let n = m.nrows();
    for i in 0..n {
        for j in 0..i {
            let v = 0.5 * (m[(i, j)] + m[(j, i)]);
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
    }
}

/// T of a point p rigidly fixed to the hub: U = U_hub + Θ × (p − c_hub), rotation Θ.
fn hub_map(n: usize, p: Vec3, c_hub: Vec3) -> Mat<f64> {
    let mut t = Mat::zeros(6, n);
    let s = (p - c_hub).skew();
    for i in 0..3 {
        t[(i, i)] = 1.0;
        t[(3 + i, 3 + i)] = 1.0;
        for j in 0..3 {
            t[(i, 3 + j)] = -s.get(i, j);
        }
    }
    t
}

/// T of the section at `station` of a beam: translation
/// U + Θ × s e_x + u(s) e_x + v(s) e_y + w(s) e_z, rotation Θ + θ(s) e_x − w'(s) e_y + v'(s) e_z.
fn section_map(beam: &Beam, parent: &Element, station: f64, n: usize) -> Mat<f64> {
    let f = beam.frame;
    let tp = &parent.attachment;
    // Rigid part: [I, −S(s e_x); 0, I] T_parent.
    let s = (f.ex * station).skew();
    let mut t = Mat::zeros(6, n);
    for c in 0..n {
        let uu = Vec3::new(tp[(0, c)], tp[(1, c)], tp[(2, c)]);
        let th = Vec3::new(tp[(3, c)], tp[(4, c)], tp[(5, c)]);
        let tr = uu - s.apply(th);
        for i in 0..3 {
            t[(i, c)] = tr.get(i);
            t[(3 + i, c)] = th.get(i);
        }
    }
    // Own part (only a beam element has one; its basis comes with it).
    let ElementKind::Beam {
        axial,
        bending,
        torsion,
        ..
    } = &parent.kind
    else {
        return t;
    };
    let xi = (station / beam.length).clamp(0.0, 1.0);
    let l = beam.length;
    let mut put = |col: usize, tr: Vec3, rot: Vec3| {
        for i in 0..3 {
            t[(i, col)] += tr.get(i);
            t[(3 + i, col)] += rot.get(i);
        }
    };
    let field = |kind| parent.field(kind).start;
    for (k, d) in axial.eval_vec(xi).iter().enumerate() {
        put(field(FieldKind::U) + k, f.ex * d[0], Vec3::ZERO);
    }
    for (k, d) in bending.eval_vec(xi).iter().enumerate() {
        put(field(FieldKind::V) + k, f.ey * d[0], f.ez * (d[1] / l));
        put(field(FieldKind::W) + k, f.ez * d[0], f.ey * (-d[1] / l));
    }
    for (k, d) in torsion.eval_vec(xi).iter().enumerate() {
        put(field(FieldKind::Theta) + k, Vec3::ZERO, f.ex * d[0]);
    }
    t
}

fn rigid_block(rb: &RigidBody, ne: usize) -> Mat<f64> {
    let b = rb.block();
    let mut me = Mat::zeros(6 + ne, 6 + ne);
    for i in 0..6 {
        for j in 0..6 {
            me[(i, j)] = b[i][j];
        }
    }
    me
}

fn set_coupling(me: &mut Mat<f64>, col: usize, du: Vec3, dth: Vec3) {
    for i in 0..3 {
        me[(i, col)] = du.get(i);
        me[(col, i)] = du.get(i);
        me[(3 + i, col)] = dth.get(i);
        me[(col, 3 + i)] = dth.get(i);
    }
}

/// Element matrices over z = [U; Θ; own]: `me` is (6 + n_e)², `ke` is n_e².
///
/// Beam element (docs/theory.md §1):
/// T = ½∫ρA|U̇ + Θ̇ × x e_x + u̇ e_x + v̇ e_y + ẇ e_z|² + ρI_p(Θ̇·e_x + θ̇)² dx,
/// U = ½∫(EA u'² + EI_z v''² + EI_y w''² + GJ θ'²) dx.
pub(crate) fn beam_element(
    beam: &Beam,
    axial: &dyn Basis1d,
    bending: &dyn Basis1d,
    torsion: &dyn Basis1d,
) -> (Mat<f64>, Mat<f64>) {
    let (na, nb, nt) = (axial.len(), bending.len(), torsion.len());
    let ne = na + 2 * nb + nt;
    let l = beam.length;
    let rho_a = beam.mass_per_length();
    let rho_ip = beam.density * beam.section.polar_inertia;
    let f = beam.frame;
    let (ia, ib, it) = (
        Integrals::new(axial),
        Integrals::new(bending),
        Integrals::new(torsion),
    );
    let mut me = rigid_block(&beam.rigid_body(), ne);
    let mut ke = Mat::zeros(ne, ne);
    let (ou, ov, ow, ot) = (6, 6 + na, 6 + na + nb, 6 + na + 2 * nb);
    for i in 0..na {
        set_coupling(&mut me, ou + i, f.ex * (rho_a * l * ia.m0[i]), Vec3::ZERO);
    }
    for j in 0..nb {
        set_coupling(
            &mut me,
            ov + j,
            f.ey * (rho_a * l * ib.m0[j]),
            f.ez * (rho_a * l * l * ib.m1[j]),
        );
        set_coupling(
            &mut me,
            ow + j,
            f.ez * (rho_a * l * ib.m0[j]),
            f.ey * (-rho_a * l * l * ib.m1[j]),
        );
    }
    for k in 0..nt {
        set_coupling(&mut me, ot + k, Vec3::ZERO, f.ex * (rho_ip * l * it.m0[k]));
    }
    let e = beam.youngs_modulus;
    let s = beam.section;
    for i in 0..na {
        for j in 0..na {
            me[(ou + i, ou + j)] = rho_a * l * ia.i00[(i, j)];
            ke[(ou + i - 6, ou + j - 6)] = e * s.area / l * ia.i11[(i, j)];
        }
    }
    for i in 0..nb {
        for j in 0..nb {
            let m = rho_a * l * ib.i00[(i, j)];
            me[(ov + i, ov + j)] = m;
            me[(ow + i, ow + j)] = m;
            ke[(ov + i - 6, ov + j - 6)] = e * s.iz / l.powi(3) * ib.i22[(i, j)];
            ke[(ow + i - 6, ow + j - 6)] = e * s.iy / l.powi(3) * ib.i22[(i, j)];
        }
    }
    for i in 0..nt {
        for j in 0..nt {
            me[(ot + i, ot + j)] = rho_ip * l * it.i00[(i, j)];
            ke[(ot + i - 6, ot + j - 6)] =
                beam.shear_modulus * s.torsion_constant / l * it.i11[(i, j)];
        }
    }
    (me, ke)
}

/// The plate's functions along its length: the clamped family, followed by a kink per hinge
/// line when the plate is cut ([`crate::basis::Hinged`]).
pub(crate) fn plate_length_basis(kind: crate::basis::BasisKind, p: &Plate) -> Box<dyn Basis1d> {
    let smooth = kind.bending(p.terms.length);
    if p.hinges.is_empty() {
        smooth
    } else {
        Box::new(crate::basis::Hinged::combined(
            smooth,
            p.hinge_positions(),
            p.hinge_functions.clone(),
        ))
    }
}

/// Plate element (docs/theory.md §1): W = Σ g_mn X_m(x/a) Y_n(y/b + ½),
/// T = ½∫μ|U̇ + Θ̇ × r + Ẇ n|² dA,
/// U = (D/2)∫[W_xx² + W_yy² + 2ν W_xx W_yy + 2(1 − ν) W_xy²] dA
/// (= (D/2)∫[(ΔW)² − 2(1−ν)(W_xx W_yy − W_xy²)] dA).
pub(crate) fn plate_element(
    plate: &Plate,
    xb: &dyn Basis1d,
    yb: &dyn Basis1d,
) -> (Mat<f64>, Mat<f64>) {
    let ne = xb.len() * yb.len();
    let mut me = Mat::zeros(6 + ne, 6 + ne);
    let mut ke = Mat::zeros(ne, ne);
    let (rigid, coupling) = plate_element_into(
        plate,
        xb,
        yb,
        &mut Offset {
            sink: &mut me,
            r0: 6,
            c0: 6,
        },
        &mut ke,
    );
    for i in 0..6 {
        for j in 0..6 {
            me[(i, j)] = rigid[(i, j)];
        }
        for c in 0..ne {
            me[(i, 6 + c)] = coupling[(i, c)];
            me[(6 + c, i)] = coupling[(i, c)];
        }
    }
    (me, ke)
}

/// [`plate_element`] with the own blocks M_oo and K_oo added into sinks; returns the rigid
/// block M_rr (6 × 6) and the coupling M_ro (6 × n_e).
fn plate_element_into(
    plate: &Plate,
    xb: &dyn Basis1d,
    yb: &dyn Basis1d,
    own_mass: &mut impl Sink,
    own_stiffness: &mut impl Sink,
) -> (Mat<f64>, Mat<f64>) {
    let (nx, ny) = (xb.len(), yb.len());
    let ne = nx * ny;
    let (a, b) = (plate.length, plate.width);
    let mu = plate.areal_density;
    let (d, nu) = (plate.bending_stiffness, plate.poisson_ratio);
    let (ix, iy) = (Integrals::new(xb), Integrals::new(yb));
    let (ea, eb, nn) = (plate.length_axis, plate.width_axis(), plate.normal);
    let rigid = rigid_block(&plate.rigid_body(), 0);
    let mut coupling = Mat::zeros(6, ne);
    let area = a * b;
    for m in 0..nx {
        for n in 0..ny {
            let k = m * ny + n;
            let mean_x = a * ix.m1[m] * iy.m0[n];
            let mean_y = ix.m0[m] * b * (iy.m1[n] - 0.5 * iy.m0[n]);
            let du = nn * (mu * area * ix.m0[m] * iy.m0[n]);
            let dth = (eb * -mean_x + ea * mean_y) * (mu * area);
            for i in 0..3 {
                coupling[(i, k)] = du.get(i);
                coupling[(3 + i, k)] = dth.get(i);
            }
        }
    }
    let (a2b2, a4, b4) = (a * a * b * b, a.powi(4), b.powi(4));
    // Only the pairs of functions with some non-zero integral in each direction: the
    // tensor-product blocks of all others vanish (for the Legendre bases most do).
    let pairs = |i: &Integrals, n: usize| -> Vec<(usize, usize)> {
        (0..n)
            .flat_map(|m| (0..n).map(move |p| (m, p)))
            .filter(|&(m, p)| {
                [
                    i.i00[(m, p)],
                    i.i11[(m, p)],
                    i.i22[(m, p)],
                    i.i20[(m, p)],
                    i.i20[(p, m)],
                ]
                .iter()
                .any(|v| *v != 0.0)
            })
            .collect()
    };
    let (px, py) = (pairs(&ix, nx), pairs(&iy, ny));
    for &(m, p) in &px {
        for &(n, q) in &py {
            {
                {
                    let (k, l) = (m * ny + n, p * ny + q);
                    own_mass.add(k, l, mu * area * ix.i00[(m, p)] * iy.i00[(n, q)]);
                    let kxx = ix.i22[(m, p)] * iy.i00[(n, q)] / a4;
                    let kyy = ix.i00[(m, p)] * iy.i22[(n, q)] / b4;
                    let kxy = nu
                        * (ix.i20[(m, p)] * iy.i20[(q, n)] + ix.i20[(p, m)] * iy.i20[(n, q)])
                        / a2b2;
                    let ktw = 2.0 * (1.0 - nu) * ix.i11[(m, p)] * iy.i11[(n, q)] / a2b2;
                    own_stiffness.add(k, l, d * area * (kxx + kyy + kxy + ktw));
                }
            }
        }
    }
    // Hinge lines (docs/theory.md §1.6): the slope jump across line j is
    // (1/a) Σ_i W_ij Σ_n h_in Y_n for the kink functions' coordinates h_in; the line springs
    // (k/b per unit length) store ½ (1/a²) Σ S_ii' h_in h_i'q ∫Y_n Y_q dη.
    add_hinge_lines(
        plate,
        &iy,
        nx,
        &plate.hinge_function_matrix(false),
        own_stiffness,
    );
    (rigid, coupling)
}

/// Adds (1/a²) S_ii' ∫Y_n Y_q dη into the kink functions' block of a plate's own matrix
/// (`s` = [`Plate::hinge_function_matrix`]; the kinks follow the `nx` − len(S) smooth
/// length functions).
fn add_hinge_lines(plate: &Plate, iy: &Integrals, nx: usize, s: &[Vec<f64>], sink: &mut impl Sink) {
    let ny = iy.m0.len();
    let smooth = nx - s.len();
    let a2 = plate.length * plate.length;
    for (i, row) in s.iter().enumerate() {
        for (k, &sik) in row.iter().enumerate() {
            for n in 0..ny {
                for q in 0..ny {
                    let v = sik / a2 * iy.i00[(n, q)];
                    if v != 0.0 {
                        sink.add((smooth + i) * ny + n, (smooth + k) * ny + q, v);
                    }
                }
            }
        }
    }
}

/// The columns of a 6 × n map T that are not all zero: the hub's coordinates and the
/// parent's functions that move the attachment point. Only they take part in Tᵀ B T, so the
/// products stay small whatever n is.
fn support(t: &Mat<f64>) -> (Vec<usize>, Mat<f64>) {
    let cols: Vec<usize> = (0..t.ncols())
        .filter(|&c| (0..t.nrows()).any(|r| t[(r, c)] != 0.0))
        .collect();
    let ts = Mat::from_fn(t.nrows(), cols.len(), |r, c| t[(r, cols[c])]);
    (cols, ts)
}

/// M += Tᵀ B T for a rigid body's 6×6 block B.
fn add_rigid(mass: &mut impl Sink, t: &Mat<f64>, rb: &RigidBody) {
    let b = rigid_block(rb, 0);
    let (cols, ts) = support(t);
    let tbt = ts.transpose() * (&b * &ts);
    for (b, &j) in cols.iter().enumerate() {
        for (a, &i) in cols.iter().enumerate() {
            mass.add(i, j, tbt[(a, b)]);
        }
    }
}

/// M += Bᵀ M_e B and K[own, own] += K_e with B = [T; P_own], for dense element matrices.
fn add_element(
    mass: &mut impl Sink,
    stiffness: &mut impl Sink,
    t: &Mat<f64>,
    own: usize,
    me: &Mat<f64>,
    ke: &Mat<f64>,
) {
    let ne = ke.nrows();
    let rigid = me.submatrix(0, 0, 6, 6).to_owned();
    let coupling = me.submatrix(0, 6, 6, ne).to_owned();
    add_coupling(mass, t, own, &rigid, &coupling);
    for j in 0..ne {
        for i in 0..ne {
            mass.add(own + i, own + j, me[(6 + i, 6 + j)]);
            stiffness.add(own + i, own + j, ke[(i, j)]);
        }
    }
}

/// The parts of Bᵀ M_e B that involve the attachment's rigid motion: Tᵀ M_rr T and the
/// couplings Tᵀ M_ro, (Tᵀ M_ro)ᵀ, over the support of T only.
fn add_coupling(
    mass: &mut impl Sink,
    t: &Mat<f64>,
    own: usize,
    rigid: &Mat<f64>,
    coupling: &Mat<f64>,
) {
    let ne = coupling.ncols();
    let (cols, ts) = support(t);
    let tbt = ts.transpose() * (rigid * &ts);
    for (b, &j) in cols.iter().enumerate() {
        for (a, &i) in cols.iter().enumerate() {
            mass.add(i, j, tbt[(a, b)]);
        }
    }
    let tro = ts.transpose() * coupling; // |support| × ne
    for c in 0..ne {
        for (a, &i) in cols.iter().enumerate() {
            let v = tro[(a, c)];
            mass.add(i, own + c, v);
            mass.add(own + c, i, v);
        }
    }
}
