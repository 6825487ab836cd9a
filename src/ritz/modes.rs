//! Natural modes of the assembled model (docs/theory.md §1.2).
//!
//! Because the stiffness acts on the components' own coordinates only (K = diag(0₆, K_ee)
//! with K_ee positive definite for root-clamped bases), the modes are found by partition
//! rather than by letting the eigensolver find six numerically-zero roots:
//! * hub fixed: K_ee φ = ω² M_ee φ;
//! * hub free: the hub's momentum equation gives φ_r = −M_rr⁻¹ M_re φ_e, leaving
//!   K_ee φ_e = ω² (M_ee − M_er M_rr⁻¹ M_re) φ_e for the elastic modes; the six rigid
//!   modes are exact (ω = 0): translations of the whole structure and rotations about its
//!   centre of mass along the principal axes, mass-normalised.
//!
//! Modal effective masses are those of the hub-fixed modes, with respect to the hub's six
//! coordinates (translation of, and rotation about, the hub's centre of mass):
//! m_eff,i,d = (φ_iᵀ M_e,d)², whose sum over a complete basis is the appendages' rigid mass.

use super::assembly::{ElementKind, RitzModel, HUB_DOF};
use super::eigen::{lowest_of, Lowest, Operator};
use super::parallel;
use super::RitzError;
use crate::math::Vec3;
use crate::structure::{Attachment, ComponentId, HubMotion, RigidBody};
use faer::Mat;

/// One natural mode.
#[derive(Debug, Clone)]
pub struct Mode {
    /// 1-based number: rigid modes first, then elastic ones by ascending frequency.
    pub number: usize,
    /// Rigid-body (zero-frequency) mode.
    pub rigid: bool,
    /// Circular frequency ω, rad/s.
    pub omega_rad_s: f64,
    /// Generalized coordinates of the mass-normalised shape (φᵀMφ = 1).
    pub shape: Vec<f64>,
    /// Strain-energy share of each elastic component (sums to 1; empty for rigid modes).
    pub strain_energy_share: Vec<(String, f64)>,
    /// Modal effective mass in the hub's six directions [kg, kg, kg, kg·m², kg·m², kg·m²]
    /// (elastic modes of a fixed hub).
    pub effective_mass: Option<[f64; 6]>,
    /// Estimated relative error of the frequency, (f − f_exact)/f ≥ 0 (the Ritz frequency is
    /// an upper bound), for the modes an automatic term selection aimed at
    /// ([`super::refine`]); `None` otherwise.
    pub frequency_error_estimate: Option<f64>,
}

impl Mode {
    /// Frequency f = ω/2π, Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.omega_rad_s / (2.0 * std::f64::consts::PI)
    }

    /// A zero-frequency rigid-body mode with the given shape.
    fn rigid_body(shape: Vec<f64>) -> Self {
        Self {
            number: 0,
            rigid: true,
            omega_rad_s: 0.0,
            shape,
            strain_energy_share: Vec::new(),
            effective_mass: None,
            frequency_error_estimate: None,
        }
    }

    /// The strain-energy share of the named component (None for rigid modes).
    pub fn share(&self, component: &str) -> Option<f64> {
        self.strain_energy_share
            .iter()
            .find(|(k, _)| k == component)
            .map(|x| x.1)
    }

    /// The component with the largest strain-energy share ("rigid" for rigid modes).
    pub fn dominant(&self) -> &str {
        self.strain_energy_share
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or("rigid", |(n, _)| n.as_str())
    }
}

/// An elastic mode of the hub-fixed system (the hub held: the structure's fixed-interface
/// modes) with its participation in the hub's six rigid motions.
#[derive(Debug, Clone)]
pub struct HubFixedMode {
    /// ω, rad/s.
    pub omega_rad_s: f64,
    /// Effective masses, hub directions [x, y, z, rx, ry, rz]: L_d² (rounding below
    /// [`EFFECTIVE_MASS_FLOOR`] of the appendage's mass in that direction reads 0).
    pub effective_mass: [f64; 6],
    /// Signed modal participation L_d = φᵀ M_{e,d} (kg^½ for the translations, kg^½·m for
    /// the rotations): the coupling of the mass-normalised mode φ with the hub's rigid motion
    /// d (translation of the hub's centre of mass, rotation about it, structure frame).
    pub participation: [f64; 6],
    /// The mode shape over all coordinates (the hub's six are zero), mass-normalised
    /// (φᵀ M φ = 1), signed so that its largest coordinate is positive.
    pub shape: Vec<f64>,
}

/// The result of a modal analysis.
#[derive(Debug, Clone)]
pub struct ModalAnalysis {
    /// Number of generalized coordinates of the solved system (hub's six included if free).
    pub dof: usize,
    /// Hub motion.
    pub hub_motion: HubMotion,
    /// Every mode, rigid first.
    pub modes: Vec<Mode>,
    /// Elastic modes of the hub-fixed system (the same as `modes` for a fixed hub).
    pub hub_fixed: Vec<HubFixedMode>,
    /// Rigid mass of the appendages (everything not rigidly part of the hub) in the hub's six
    /// directions, about the hub's centre of mass: the limit of the effective-mass sums.
    pub appendage_mass: [f64; 6],
    /// The automatic term selection the model was built with, if any.
    pub selection: Option<super::refine::TermSelection>,
}

/// Effective masses below this fraction of the appendage's mass (or inertia) in their
/// direction are rounding noise and reported as exact zero.
pub const EFFECTIVE_MASS_FLOOR: f64 = 1e-12;

impl ModalAnalysis {
    /// Solves for every mode of the model.
    pub fn compute(model: &RitzModel) -> Result<Self, RitzError> {
        Self::compute_lowest(model, None)
    }

    /// Solves for the `count` lowest elastic modes only (all of them for `None`, or when
    /// `count` is not well below the number of coordinates), by
    /// [`super::eigen::lowest_of`]: the fast route when a run needs ten modes of a model with a
    /// thousand coordinates. The hub-fixed list (effective masses) is cut to the same count.
    pub fn compute_lowest(model: &RitzModel, count: Option<usize>) -> Result<Self, RitzError> {
        Self::compute_started(model, count, None)
    }

    /// [`Self::compute_lowest`] for a model built with an automatic term selection, the
    /// selection attached ([`Self::with_selection`]): the selection has already solved this
    /// model's pencil for the modes it aimed at, and its eigenvectors start the iteration
    /// here (two steps instead of five).
    pub fn compute_selected(
        model: &RitzModel,
        count: Option<usize>,
        selection: Option<&super::refine::TermSelection>,
    ) -> Result<Self, RitzError> {
        let start = selection
            .filter(|s| s.structure == model.structure)
            .map(|s| &s.vectors);
        Ok(Self::compute_started(model, count, start)?.with_selection(selection))
    }

    /// `start`: approximate eigenvectors of the pencil the modes come from (the free one for
    /// a free hub, n rows; the hub-fixed one for a fixed hub, n − 6 rows); ignored when the
    /// rows do not match.
    fn compute_started(
        model: &RitzModel,
        count: Option<usize>,
        start: Option<&Mat<f64>>,
    ) -> Result<Self, RitzError> {
        let n = model.dof();
        let ne = n - HUB_DOF;
        let m = &model.mass;
        let k = &model.stiffness;
        let mer = m.submatrix(HUB_DOF, 0, ne, HUB_DOF).to_owned();
        let mrr = m.submatrix(0, 0, HUB_DOF, HUB_DOF).to_owned();
        let wanted = count.map_or(ne, |c| c.min(ne));
        // The matrices as the eigen-solver holds them (sparse when they are), once; the
        // hub-fixed pencil (K_ee, M_ee) is their elastic sub-block.
        let large = n >= super::assembly::PARALLEL_FROM;
        let (ko, mo) = parallel::join(
            large,
            || Operator::from_dense(k),
            || Operator::from_dense(m),
        );
        let elastic: Vec<usize> = (HUB_DOF..n).collect();
        let motion = model.structure.hub.motion;
        // The start's elastic rows: the hub-fixed pencil's own vectors for a fixed hub, and a
        // fair approximation of them (the free modes' elastic parts) for a free one.
        let start_fixed = start.and_then(|v| match motion {
            HubMotion::Fixed => (v.nrows() == ne).then(|| v.clone()),
            HubMotion::Free => (v.nrows() == n).then(|| v.subrows(HUB_DOF, ne).to_owned()),
        });
        // The hub-fixed pencil and, for a free hub, the free one: independent solves, side
        // by side (each sequential inside: the numbers do not depend on the cores).
        let fixed_pencil = || {
            lowest_of(
                &ko.select(&elastic),
                &mo.select(&elastic),
                wanted,
                &Lowest {
                    null_space: 0,
                    start: start_fixed.as_ref(),
                },
            )
        };
        // The eigenpairs of (K, M) M-orthogonal to the six rigid-body ones (K is zero on the
        // hub's coordinates): their hub coordinates follow from the elastic ones by the hub's
        // momentum equation, q_r = −M_rr⁻¹ M_re q_e.
        let free_pencil = || match motion {
            HubMotion::Fixed => Ok(None),
            HubMotion::Free => lowest_of(
                &ko,
                &mo,
                wanted,
                &Lowest {
                    null_space: HUB_DOF,
                    start: start.filter(|v| v.nrows() == n),
                },
            )
            .map(Some),
        };
        let (fixed, free) = parallel::join(large, fixed_pencil, free_pencil);
        let ((lam_f, phi_f), free) = (fixed?, free?);
        let appendage_mass = appendage_mass(model, &mrr);
        let hub_fixed: Vec<HubFixedMode> = (0..wanted)
            .map(|j| {
                let mut shape = vec![0.0; n];
                for i in 0..ne {
                    shape[HUB_DOF + i] = phi_f[(i, j)];
                }
                fix_sign(&mut shape);
                let mut eff = [0.0; 6];
                let mut participation = [0.0; 6];
                for (d, e) in eff.iter_mut().enumerate() {
                    let l: f64 = (0..ne).map(|i| shape[HUB_DOF + i] * mer[(i, d)]).sum();
                    participation[d] = l;
                    // Below EFFECTIVE_MASS_FLOOR of the appendage's mass in that direction
                    // the value is rounding (a mode that cannot move that way): exact zero.
                    *e = if l * l <= EFFECTIVE_MASS_FLOOR * appendage_mass[d] {
                        0.0
                    } else {
                        l * l
                    };
                }
                HubFixedMode {
                    omega_rad_s: lam_f[j].max(0.0).sqrt(),
                    effective_mass: eff,
                    participation,
                    shape,
                }
            })
            .collect();

        let mut modes = Vec::new();
        // The free pencil was solved exactly when the hub is free.
        match free {
            None => {
                for (j, h) in hub_fixed.iter().enumerate() {
                    modes.push(elastic_mode(
                        lam_f[j],
                        h.shape.clone(),
                        Some(h.effective_mass),
                    ));
                }
            }
            Some((lam, phi)) => {
                modes.extend(rigid_modes(model, &mrr));
                for (j, &lambda) in lam.iter().enumerate() {
                    if !lambda.is_finite() {
                        return Err(model.not_finite());
                    }
                    let shape = (0..n).map(|i| phi[(i, j)]).collect();
                    modes.push(elastic_mode(lambda, shape, None));
                }
            }
        }
        // Rounding past recovery (masses over too many decades) shows as a NaN or an
        // infinity somewhere in a mode: an error, not a result.
        let finite = lam_f.iter().all(|l| l.is_finite())
            && modes
                .iter()
                .all(|m| m.omega_rad_s.is_finite() && m.shape.iter().all(|v| v.is_finite()))
            && hub_fixed
                .iter()
                .all(|h| h.omega_rad_s.is_finite() && h.shape.iter().all(|v| v.is_finite()));
        if !finite {
            return Err(model.not_finite());
        }
        strain_energy_shares(model, &mut modes);
        for (i, md) in modes.iter_mut().enumerate() {
            md.number = i + 1;
        }
        let dof = match motion {
            HubMotion::Free => n,
            HubMotion::Fixed => ne,
        };
        Ok(Self {
            dof,
            hub_motion: motion,
            modes,
            hub_fixed,
            appendage_mass,
            selection: None,
        })
    }

    /// Attaches a term selection's per-mode error estimates to the elastic modes it aimed at
    /// (the first `accuracy.modes` elastic modes, in order).
    pub fn with_selection(mut self, selection: Option<&super::refine::TermSelection>) -> Self {
        if let Some(sel) = selection {
            for (m, e) in self
                .modes
                .iter_mut()
                .filter(|m| !m.rigid)
                .zip(&sel.frequency_error)
            {
                m.frequency_error_estimate = Some(*e);
            }
            self.selection = Some(sel.clone());
        }
        self
    }

    /// Elastic modes only.
    pub fn elastic(&self) -> impl Iterator<Item = &Mode> {
        self.modes.iter().filter(|m| !m.rigid)
    }

    /// Running sum of the hub-fixed effective masses as fractions of the appendage mass, per
    /// direction, after each mode.
    pub fn effective_mass_fractions(&self) -> Vec<[f64; 6]> {
        let mut run = [0.0; 6];
        self.hub_fixed
            .iter()
            .map(|m| {
                for d in 0..6 {
                    run[d] += m.effective_mass[d];
                }
                std::array::from_fn(|d| {
                    if self.appendage_mass[d] > 0.0 {
                        run[d] / self.appendage_mass[d]
                    } else {
                        0.0
                    }
                })
            })
            .collect()
    }
}

/// Sign convention: the largest-magnitude coordinate is positive (deterministic output).
fn fix_sign(shape: &mut [f64]) {
    let big = shape.iter().copied().fold(0.0f64, |acc, v| {
        if v.abs() > acc.abs() * (1.0 + 1e-9) {
            v
        } else {
            acc
        }
    });
    if big < 0.0 {
        for v in shape.iter_mut() {
            *v = -*v;
        }
    }
}

fn elastic_mode(lambda: f64, mut shape: Vec<f64>, eff: Option<[f64; 6]>) -> Mode {
    fix_sign(&mut shape);
    Mode {
        number: 0,
        rigid: false,
        omega_rad_s: lambda.max(0.0).sqrt(),
        shape,
        strain_energy_share: Vec::new(),
        effective_mass: eff,
        frequency_error_estimate: None,
    }
}

/// Strain-energy share of each elastic component in every elastic mode:
/// U_c = ½ φ_cᵀ K_cc φ_c (K is block-diagonal over the components' own coordinates), as
/// fractions of Σ_c U_c. One matrix product per component for all modes at once.
fn strain_energy_shares(model: &RitzModel, modes: &mut [Mode]) {
    let elastic: Vec<usize> = (0..modes.len()).filter(|&j| !modes[j].rigid).collect();
    if elastic.is_empty() {
        return;
    }
    let nm = elastic.len();
    let mut energies: Vec<(String, Vec<f64>)> = Vec::new();
    for e in &model.elements {
        if matches!(e.kind, ElementKind::Rigid) {
            continue;
        }
        let r = e.own_range();
        let len = r.len();
        let kb = model.stiffness.submatrix(r.start, r.start, len, len);
        let pb = Mat::from_fn(len, nm, |i, j| modes[elastic[j]].shape[r.start + i]);
        let kp = kb * &pb;
        let en = (0..nm)
            .map(|j| 0.5 * (0..len).map(|i| pb[(i, j)] * kp[(i, j)]).sum::<f64>())
            .collect();
        energies.push((model.structure.component_name(e.id).to_string(), en));
    }
    for (col, &j) in elastic.iter().enumerate() {
        let total: f64 = energies.iter().map(|(_, en)| en[col]).sum();
        modes[j].strain_energy_share = energies
            .iter()
            .map(|(name, en)| {
                (
                    name.clone(),
                    if total > 0.0 { en[col] / total } else { 0.0 },
                )
            })
            .collect();
    }
}

/// The six exact rigid-body modes of the free structure.
fn rigid_modes(model: &RitzModel, mrr: &Mat<f64>) -> Vec<Mode> {
    let n = model.dof();
    let mass = mrr[(0, 0)];
    // M_rr = [[mI, −S(s)], [S(s), J]] about the hub's CM; s = m d.
    let s = Vec3::new(mrr[(5, 1)], mrr[(3, 2)], mrr[(4, 0)]);
    let d = s * (1.0 / mass);
    let j = crate::math::Mat3(std::array::from_fn(|a| {
        std::array::from_fn(|b| mrr[(3 + a, 3 + b)])
    }));
    let rb = RigidBody {
        mass,
        first_moment: s,
        inertia: j,
    };
    let (principal, axes) = rb.inertia_at_cm().symmetric_eigen();
    let mut out = Vec::new();
    for a in 0..3 {
        let mut shape = vec![0.0; n];
        shape[a] = 1.0 / mass.sqrt();
        out.push(Mode::rigid_body(shape));
    }
    for (a, &ia) in principal.iter().enumerate() {
        let axis = Vec3::new(axes.get(0, a), axes.get(1, a), axes.get(2, a));
        let th = axis * (1.0 / ia.sqrt());
        // Rotation about the system CM: the hub CM (at −d from it) moves by Θ × (−d).
        let u = th.cross(-d);
        let mut shape = vec![0.0; n];
        for i in 0..3 {
            shape[i] = u.get(i);
            shape[3 + i] = th.get(i);
        }
        fix_sign(&mut shape);
        out.push(Mode::rigid_body(shape));
    }
    out
}

/// Diagonal of the appendages' rigid mass in the hub coordinates: M_rr minus the hub itself
/// and the lumped masses fixed directly to it.
fn appendage_mass(model: &RitzModel, mrr: &Mat<f64>) -> [f64; 6] {
    let st = &model.structure;
    let c = st.hub.center_of_mass;
    let mut own = st.hub.rigid_body();
    for lm in &st.masses {
        if let Attachment::Hub { point } = lm.attachment {
            own = own.plus(&lm.rigid_body().about(c - point));
        }
    }
    let b = own.block();
    std::array::from_fn(|d| mrr[(d, d)] - b[d][d])
}

/// Helper for callers: is this element an elastic component?
pub fn is_elastic(id: ComponentId) -> bool {
    matches!(id, ComponentId::Beam(_) | ComponentId::Plate(_))
}

/// The largest modal damping ratio the response's and the export's underdamped closed forms
/// take (the latch lines' dashpots are capped there).
pub const MAX_ZETA: f64 = 0.95;

impl ModalAnalysis {
    /// Every mode's damping ratio from `model`'s hinge-line dashpots (docs/theory.md §1.6),
    /// φ_jᵀ C φ_j / (2ω_j) with C = [`RitzModel::line_damping`] (the diagonal of the damping
    /// in modal coordinates; zero for rigid modes and without hinge lines).
    pub fn line_damping_ratios(&self, model: &super::RitzModel) -> Vec<f64> {
        let c = model.line_damping();
        self.modes
            .iter()
            .map(|m| {
                if m.rigid || m.omega_rad_s <= 0.0 || c.is_empty() {
                    return 0.0;
                }
                let q: f64 = c.iter().map(|&(i, j, v)| m.shape[i] * v * m.shape[j]).sum();
                q / (2.0 * m.omega_rad_s)
            })
            .collect()
    }
}
