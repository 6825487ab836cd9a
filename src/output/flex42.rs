//! NASA 42's flexible-body input files, `flex_<name>.txt` and `nodes_<name>.txt`, with the
//! modal integrals computed.
//!
//! # What 42 reads (42 source, `ericstoneking/42`, read at commit 11e3cc3)
//! 42 models each flexible body by assumed modes: the displacement of a mass element at r is
//! d = Ψ(r) η and its small rotation Θ(r) η, with η the Nf modal coordinates ("x" in the
//! file) and ξ = η̇ ("u"). Everything is in the body frame B, about the body's reference
//! point. With hub-fixed (cantilever) modes the reference point is the clamp and the
//! spacecraft file must say `REFPT_JOINT`: with `REFPT_CM` 42 sets Pf and Hf to zero after
//! reading them (`InitFlexModes`, "Don't trust input file…"), which is right only for
//! free-free modes about the mass centre.
//!
//! ## `flex_<name>.txt` (`Source/42init.c`, `InitFlexModes`; sample `InOut/Flex_Simple.txt`)
//! 42 reads it with `fscanf`: a "comment line" is `%[^\n] %[\n]` (the rest of the line, then
//! all white space, blank lines included, is skipped); a data line is its numbers followed
//! by `%[^\n] %[\n]`, so **every data line must end with a comment**: without one the next
//! line is swallowed. The line and comment buffers are `char junk[80]`, so every comment
//! line and trailing comment must be shorter than 80 bytes. The file, in reading order:
//! 1. a title line; a description line; `Nf` (number of modes);
//! 2. a header line, then Nf lines `x u` (initial η and ξ of each mode);
//! 3. a header ("Joint Node Mode Shapes"), then for PSI and then THETA: a header line, the
//!    number of non-zero elements, and that many lines `mode joint axis value`: the
//!    translation Ψ [m/√kg] / rotation Θ [rad/√kg] of each mode at a joint, joints numbered
//!    as in the spacecraft file (the body must be that joint's inner or outer body);
//! 4. the same for the analysis nodes ("Analysis Node Mode Shapes"): `mode node axis value`,
//!    nodes numbered as in this body's nodes file;
//! 5. the modal mass, stiffness and damping matrices Mf, Kf, Cf, each as a header line, the
//!    number of non-zero elements and `row col value` lines (42 then checks π/√(Kf_ii/Mf_ii)
//!    against its time step);
//! 6. Pf and Hf: a header line, then Nf lines `x y z`, one per mode;
//! 7. L: a header line, the number of non-zero elements, lines `i j mode value`;
//! 8. N: a header line, the number of non-zero elements, lines `i j p q value`.
//!
//! 42 reads nothing after N: this writer ends with `[EOF]`, as 42's samples do, followed by
//! notes on units and conventions. Indices are 0-based throughout. The joint mode shapes
//! feed the multibody kinematics, the analysis-node ones the node motions and the modal
//! forces of loads applied at nodes.
//!
//! ## `nodes_<name>.txt` (`Source/42init.c`, `InitNodes`; sample `InOut/Nodes_Simple.txt`)
//! A title line, a description line, the number of nodes, a header line, then per node
//! `x y z "comment"` (position in B \[m\], read as `%lf %lf %lf "%[^"]"`; the comment is the
//! node's name, 1 to 79 bytes, no double quote).
//!
//! ## The modal integrals (`Docs/Kane_NBody_Flex.pdf`, slides 13 and 15–17; their use in
//! `Source/42dynamics.c`, `FindFlexTerms`, `FindInertiaFrc`, `FindFlexInertiaFrc`)
//! With Ψ_p(r) the translation of mode p at r, Θ_p its rotation and dm the mass element,
//! 42 defines, about the reference point:
//! - c = ∫ r dm (first mass moment; from the spacecraft file, c = m·cm with `REFPT_JOINT`)
//! - J = −∫ r̃ r̃ dm (inertia about the reference point; spacecraft file)
//! - Pf (3 × Nf): Pf_p = ∫ Ψ_p dm ("linear momentum modal integral")
//! - Hf (3 × Nf): Hf_p = ∫ r × Ψ_p dm ("angular momentum modal integral")
//! - Mf (Nf × Nf): Mf_pq = ∫ Ψ_p · Ψ_q dm
//! - L (3 × 3 × Nf): L_ijp = ∫ Ψ_ip r_j dm
//! - N (3 × 3 × Nf × Nf): N_ijpq = ∫ Ψ_ip Ψ_jq dm
//!
//! 42 forms from them Q_pq = ∫ Ψ_q × Ψ_p dm (from N_32 − N_23, …), R (from L) and S (from N)
//! for the second-order terms ω·R·ω and ω·S·ω η. The index order matters for Q only: 42's
//! Hf + Q η must equal ∫ (r + Ψη) × Ψ_p dm, which fixes N's first axis index to the first
//! mode index, as in the slides.
//!
//! ## Mass elements with rotary inertia
//! The slides integrate over point masses. flexcraft's discretisation ([`MassPoint`]) also
//! has rigid elements with a rotary inertia J_k about their own centre (a lumped mass, a tip
//! body): a point at ρ from the element's centre moves by Ψ_p + Θ_p × ρ. Integrated exactly
//! over the element, with E_k = ∫ ρ ρᵀ dm = ½ tr(J_k) 𝟙 − J_k:
//! - Pf_p = Σ m Ψ_p
//! - Hf_p = Σ (m r × Ψ_p + J_k Θ_p)
//! - Mf_pq = Σ (m Ψ_p · Ψ_q + Θ_pᵀ J_k Θ_q)
//! - L_p = Σ (m Ψ_p rᵀ + Θ̃_p E_k)            (L_p the 3 × 3 matrix L_ijp)
//! - N_pq = Σ (m Ψ_p Ψ_qᵀ + Θ̃_p E_k Θ̃_qᵀ)     (N_pq the 3 × 3 matrix N_ijpq)
//!
//! They keep the slides' identities: Hf = (L_32 − L_23, L_13 − L_31, L_21 − L_12) and
//! Mf = N_11 + N_22 + N_33. The sums are exact for the structure when the mass points are the
//! nodes and weights of a quadrature that integrates the mass matrix exactly.
//!
//! Limits: first-order modal deflections (42's assumed modes), modes mass-normalised
//! (Mf = 𝟙 is written and checked against the integrals), modal damping Cf = diag(2ζω),
//! Kf = diag(ω²).

use std::fmt::Write as _;
use thiserror::Error;

/// A vector in the body frame B.
pub type Vec3 = [f64; 3];
/// A 3 × 3 matrix in B, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// Longest file name 42 stores (`char FlexFileName[40]`, with its terminating NUL).
const MAX_FILE_NAME: usize = 39;
/// The longest body name whose file names (`nodes_<name>.txt`, the longer) fit
/// 42's 39-byte file names.
pub const MAX_BODY_NAME: usize = MAX_FILE_NAME - "nodes_.txt".len();
/// 42's line buffer (`char junk[80]`), with its terminating NUL.
const MAX_LINE: usize = 79;
/// Largest departure of the integrated modal mass matrix from 𝟙 that is accepted.
pub const MODAL_MASS_TOLERANCE: f64 = 1e-6;

/// One kept mode.
#[derive(Debug, Clone, PartialEq)]
pub struct FlexMode {
    /// Natural frequency ω [rad/s] (of the hub-fixed structure).
    pub frequency_rad_s: f64,
    /// Modal damping ratio ζ, in [0, 1).
    pub damping_ratio: f64,
    /// Initial modal displacement η₀ (42's "x") [√kg m].
    pub initial_displacement: f64,
    /// Initial modal rate ξ₀ = η̇₀ (42's "u") [√kg m/s].
    pub initial_rate: f64,
}

/// A rigid mass element of the discretised structure.
#[derive(Debug, Clone, PartialEq)]
pub struct MassPoint {
    /// Position r of its centre of mass in B \[m\].
    pub position_m: Vec3,
    /// Mass m \[kg\] (≥ 0).
    pub mass_kg: f64,
    /// Inertia about its own centre of mass, in B [kg m²] (zero for a quadrature point).
    pub inertia_kg_m2: Mat3,
    /// Per mode, the mass-normalised translation Ψ_p at the centre [m/√kg].
    pub psi: Vec<Vec3>,
    /// Per mode, the mass-normalised small rotation Θ_p [rad/√kg].
    pub theta: Vec<Vec3>,
}

/// A joint of the spacecraft file on this body, with its mode shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct FlexJoint {
    /// The joint's index in 42's spacecraft file (this body must be its inner or outer body).
    pub joint: usize,
    /// Per mode, the translation Ψ_p at the joint [m/√kg].
    pub psi: Vec<Vec3>,
    /// Per mode, the rotation Θ_p at the joint [rad/√kg].
    pub theta: Vec<Vec3>,
}

/// A named analysis node (sensor, actuator, load point), in the order of the nodes file.
#[derive(Debug, Clone, PartialEq)]
pub struct FlexNode {
    /// Name, written as the node's comment (1 to 79 bytes, no double quote or line break).
    pub name: String,
    /// Position in B \[m\].
    pub position_m: Vec3,
    /// Per mode, the translation Ψ_p at the node [m/√kg].
    pub psi: Vec<Vec3>,
    /// Per mode, the rotation Θ_p at the node [rad/√kg].
    pub theta: Vec<Vec3>,
}

/// A flexible body as 42 sees it: the hub-fixed (constrained) modes of the structure, in
/// the body frame B, origin at the body's reference point (the clamp).
#[derive(Debug, Clone, PartialEq)]
pub struct FlexBody {
    /// File-name stem: `flex_<name>.txt`, `nodes_<name>.txt` (1 to [`MAX_BODY_NAME`] = 29 bytes, no white space
    /// or quote: 42 reads file names with `%s` into 40 bytes).
    pub name: String,
    /// The kept modes.
    pub modes: Vec<FlexMode>,
    /// Mass elements that integrate the whole elastic structure exactly enough.
    pub mass_points: Vec<MassPoint>,
    /// Joints of the spacecraft file on this body (may be empty: a single-body spacecraft).
    pub joints: Vec<FlexJoint>,
    /// Analysis nodes.
    pub nodes: Vec<FlexNode>,
}

/// The modal integrals of a [`FlexBody`] about its reference point, with 42's definitions
/// (module documentation), and its rigid mass properties.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalIntegrals {
    /// Total mass m \[kg\] of the mass points.
    pub mass_kg: f64,
    /// First mass moment c = ∫ r dm [kg m].
    pub first_moment_kg_m: Vec3,
    /// Inertia about the reference point J = −∫ r̃ r̃ dm + Σ J_k [kg m²].
    pub inertia_kg_m2: Mat3,
    /// Mf_pq = ∫ Ψ_p · Ψ_q dm (+ rotary terms) [dimensionless for mass-normalised modes].
    pub modal_mass: Vec<Vec<f64>>,
    /// Pf_p = ∫ Ψ_p dm, per mode [√kg].
    pub pf: Vec<Vec3>,
    /// Hf_p = ∫ r × Ψ_p dm (+ rotary terms), per mode [√kg m].
    pub hf: Vec<Vec3>,
    /// `L_p[i][j]` = L_ijp = ∫ Ψ_ip r_j dm (+ rotary terms), per mode p [√kg m].
    pub l: Vec<Mat3>,
    /// `N_pq[i][j]` = N_ijpq = ∫ Ψ_ip Ψ_jq dm (+ rotary terms), `n[p][q]` \[dimensionless\].
    pub n: Vec<Vec<Mat3>>,
}

impl ModalIntegrals {
    /// 42's `L[i][j][p]`.
    pub fn l_ijp(&self, i: usize, j: usize, p: usize) -> f64 {
        self.l[p][i][j]
    }

    /// 42's `N[i][j][p][q]`.
    pub fn n_ijpq(&self, i: usize, j: usize, p: usize, q: usize) -> f64 {
        self.n[p][q][i][j]
    }

    /// The mass centre c/m \[m\] (the origin for a massless body).
    pub fn mass_centre_m(&self) -> Vec3 {
        if self.mass_kg > 0.0 {
            self.first_moment_kg_m.map(|c| c / self.mass_kg)
        } else {
            [0.0; 3]
        }
    }

    /// The mass-property lines of this body's block in 42's spacecraft file, for
    /// `REFPT_JOINT` (inertia about the reference point). 42 reads the products of inertia
    /// as (xy, xz, yz) and negates them into the tensor (`InitSpacecraft`), so the file holds
    /// −J_xy = ∫ x y dm, etc.
    pub fn sc_mass_lines(&self) -> String {
        let j = &self.inertia_kg_m2;
        let cm = self.mass_centre_m();
        format!(
            "{}  ! Mass\n{} {} {}  ! Moments of Inertia (kg-m^2)\n{} {} {}  ! Products of Inertia (xy,xz,yz)\n{} {} {}  ! Location of mass center, m\n",
            num(self.mass_kg),
            num(j[0][0]),
            num(j[1][1]),
            num(j[2][2]),
            num(-j[0][1]),
            num(-j[0][2]),
            num(-j[1][2]),
            num(cm[0]),
            num(cm[1]),
            num(cm[2]),
        )
    }
}

/// A non-zero mode-shape element `mode index axis value` (index: joint or node).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeEntry {
    /// Mode p.
    pub mode: usize,
    /// Joint (spacecraft-file numbering) or node (nodes-file numbering).
    pub index: usize,
    /// Axis 0, 1, 2 = x, y, z of B.
    pub axis: usize,
    /// The value.
    pub value: f64,
}

/// A non-zero matrix element `row col value`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MatrixEntry {
    /// Row.
    pub row: usize,
    /// Column.
    pub col: usize,
    /// The value.
    pub value: f64,
}

/// A non-zero element of L: `i j p value`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LEntry {
    /// Axis index i (of Ψ).
    pub i: usize,
    /// Axis index j (of r).
    pub j: usize,
    /// Mode p.
    pub mode: usize,
    /// L_ijp.
    pub value: f64,
}

/// A non-zero element of N: `i j p q value`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NEntry {
    /// Axis index i (of Ψ_p).
    pub i: usize,
    /// Axis index j (of Ψ_q).
    pub j: usize,
    /// Mode p.
    pub p: usize,
    /// Mode q.
    pub q: usize,
    /// N_ijpq.
    pub value: f64,
}

/// A flex file as 42's `InitFlexModes` reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedFlex {
    /// The description line (with its trailing comment).
    pub description: String,
    /// Per mode, the initial (x, u) = (η₀, ξ₀).
    pub initial: Vec<(f64, f64)>,
    /// Joint translation mode shapes.
    pub joint_psi: Vec<ShapeEntry>,
    /// Joint rotation mode shapes.
    pub joint_theta: Vec<ShapeEntry>,
    /// Analysis-node translation mode shapes.
    pub node_psi: Vec<ShapeEntry>,
    /// Analysis-node rotation mode shapes.
    pub node_theta: Vec<ShapeEntry>,
    /// Mf.
    pub mass: Vec<MatrixEntry>,
    /// Kf.
    pub stiffness: Vec<MatrixEntry>,
    /// Cf.
    pub damping: Vec<MatrixEntry>,
    /// Pf, one vector per mode.
    pub pf: Vec<Vec3>,
    /// Hf, one vector per mode.
    pub hf: Vec<Vec3>,
    /// L.
    pub l: Vec<LEntry>,
    /// N.
    pub n: Vec<NEntry>,
}

/// A node as 42's `InitNodes` reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedNode {
    /// Position in B \[m\].
    pub position_m: Vec3,
    /// The quoted comment (the node's name).
    pub comment: String,
}

/// Invalid flex-body data, or a file 42 would misread.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Flex42Error {
    /// A body name that cannot make 42's file names.
    #[error("flex body name {name:?}: must be 1 to 29 bytes without white space or quotes (42 reads file names, nodes_<name>.txt the longer, with %s into 40 bytes)")]
    BadName {
        /// The name.
        name: String,
    },
    /// No mode to write.
    #[error("flex body {name:?}: no mode")]
    NoModes {
        /// The body.
        name: String,
    },
    /// A per-mode list of the wrong length.
    #[error("{what}: {found} mode shapes for {expected} modes")]
    ModeCount {
        /// Which list.
        what: String,
        /// Number of modes.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A NaN or infinite number.
    #[error("{what}: {value} is not finite")]
    NotFinite {
        /// Which number.
        what: String,
        /// The value.
        value: f64,
    },
    /// A negative frequency or mass, or a damping ratio outside [0, 1).
    #[error("{what}: {value} is out of range ({range})")]
    OutOfRange {
        /// Which number.
        what: String,
        /// The value.
        value: f64,
        /// The accepted range.
        range: &'static str,
    },
    /// The mass points do not give Mf = 𝟙: the modes are not mass-normalised over them.
    #[error("modal mass Mf[{p}][{q}] = {value} integrated over the mass points, expected {expected} (tolerance {MODAL_MASS_TOLERANCE}): the modes are not mass-normalised over the mass points")]
    NotMassNormalised {
        /// Row.
        p: usize,
        /// Column.
        q: usize,
        /// Integrated value.
        value: f64,
        /// 1 on the diagonal, 0 off it.
        expected: f64,
    },
    /// A node name 42 cannot read back.
    #[error("node name {name:?}: must be 1 to 79 bytes without double quote or line break")]
    BadNodeName {
        /// The name.
        name: String,
    },
    /// Two joints with the same index.
    #[error("joint {joint} listed twice")]
    DuplicateJoint {
        /// The joint index.
        joint: usize,
    },
    /// A number or line 42's reader expects is missing or malformed.
    #[error("line {line}: expected {expected}, found {found:?}")]
    Parse {
        /// 1-based line.
        line: usize,
        /// What 42 reads there.
        expected: &'static str,
        /// What is there.
        found: String,
    },
    /// A line longer than 42's 80-byte buffer.
    #[error("line {line}: {length} bytes overflow 42's 80-byte line buffer")]
    LineTooLong {
        /// 1-based line.
        line: usize,
        /// Its length.
        length: usize,
    },
    /// A data line without a trailing comment: 42 would swallow the next line as its comment.
    #[error(
        "line {line}: data without a trailing comment (42 would read the next line as the comment)"
    )]
    MissingComment {
        /// 1-based line of the data.
        line: usize,
    },
    /// An index out of the range 42 checks.
    #[error("line {line}: {what} index {index} out of range 0..{limit}")]
    IndexOutOfRange {
        /// 1-based line.
        line: usize,
        /// Which index.
        what: &'static str,
        /// The index.
        index: i64,
        /// Its bound.
        limit: usize,
    },
}

/// `flex_<name>.txt`.
pub fn flex_file_name(name: &str) -> String {
    format!("flex_{name}.txt")
}

/// `nodes_<name>.txt`.
pub fn nodes_file_name(name: &str) -> String {
    format!("nodes_{name}.txt")
}

/// The shortest text that reads back (by Rust and by C's `strtod`) to the same f64.
/// −0 is written as 0.
fn num(v: f64) -> String {
    let v = if v == 0.0 { 0.0 } else { v };
    format!("{v:e}")
}

impl FlexBody {
    /// Checks the name, the per-mode list lengths, finiteness and ranges, and node names.
    /// Does not check the mass normalisation (see [`flex_file`]).
    pub fn validate(&self) -> Result<(), Flex42Error> {
        let name_ok = !self.name.is_empty()
            && flex_file_name(&self.name)
                .len()
                .max(nodes_file_name(&self.name).len())
                <= MAX_FILE_NAME
            && !self
                .name
                .chars()
                .any(|c| c.is_whitespace() || c == '"' || c == '\'' || c.is_control());
        if !name_ok {
            return Err(Flex42Error::BadName {
                name: self.name.clone(),
            });
        }
        let nf = self.modes.len();
        if nf == 0 {
            return Err(Flex42Error::NoModes {
                name: self.name.clone(),
            });
        }
        for (p, mode) in self.modes.iter().enumerate() {
            check_range(
                &format!("mode {p} frequency [rad/s]"),
                mode.frequency_rad_s,
                |v| v >= 0.0,
                "≥ 0",
            )?;
            check_range(
                &format!("mode {p} damping ratio"),
                mode.damping_ratio,
                |v| (0.0..1.0).contains(&v),
                "[0, 1)",
            )?;
            check_finite(
                &format!("mode {p} initial displacement"),
                &[mode.initial_displacement],
            )?;
            check_finite(&format!("mode {p} initial rate"), &[mode.initial_rate])?;
        }
        for (k, point) in self.mass_points.iter().enumerate() {
            let what = format!("mass point {k}");
            check_range(&what, point.mass_kg, |v| v >= 0.0, "≥ 0")?;
            check_finite(&what, &point.position_m)?;
            check_finite(&what, point.inertia_kg_m2.as_flattened())?;
            check_shapes(&what, nf, &point.psi, &point.theta)?;
        }
        for (k, joint) in self.joints.iter().enumerate() {
            if self.joints[..k].iter().any(|g| g.joint == joint.joint) {
                return Err(Flex42Error::DuplicateJoint { joint: joint.joint });
            }
            check_shapes(
                &format!("joint {}", joint.joint),
                nf,
                &joint.psi,
                &joint.theta,
            )?;
        }
        for node in &self.nodes {
            if node.name.is_empty()
                || node.name.len() > MAX_LINE
                || node.name.contains(['"', '\n', '\r'])
            {
                return Err(Flex42Error::BadNodeName {
                    name: node.name.clone(),
                });
            }
            let what = format!("node {:?}", node.name);
            check_finite(&what, &node.position_m)?;
            check_shapes(&what, nf, &node.psi, &node.theta)?;
        }
        Ok(())
    }
}

fn check_finite(what: &str, values: &[f64]) -> Result<(), Flex42Error> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Flex42Error::NotFinite {
            what: what.to_string(),
            value,
        }),
        None => Ok(()),
    }
}

fn check_range(
    what: &str,
    value: f64,
    ok: impl Fn(f64) -> bool,
    range: &'static str,
) -> Result<(), Flex42Error> {
    check_finite(what, &[value])?;
    if ok(value) {
        Ok(())
    } else {
        Err(Flex42Error::OutOfRange {
            what: what.to_string(),
            value,
            range,
        })
    }
}

fn check_shapes(what: &str, nf: usize, psi: &[Vec3], theta: &[Vec3]) -> Result<(), Flex42Error> {
    for (kind, list) in [("psi", psi), ("theta", theta)] {
        if list.len() != nf {
            return Err(Flex42Error::ModeCount {
                what: format!("{what} {kind}"),
                expected: nf,
                found: list.len(),
            });
        }
        check_finite(&format!("{what} {kind}"), list.as_flattened())?;
    }
    Ok(())
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn mat_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// ã, the cross-product matrix: ã b = a × b.
fn skew(a: Vec3) -> Mat3 {
    [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]]
}

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn transpose(a: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

/// E = ∫ ρ ρᵀ dm = ½ tr(J) 𝟙 − J, the second moment of a rigid element about its centre
/// from its inertia J about that centre.
fn second_moment(j: &Mat3) -> Mat3 {
    let half_trace = 0.5 * (j[0][0] + j[1][1] + j[2][2]);
    std::array::from_fn(|a| {
        std::array::from_fn(|b| if a == b { half_trace } else { 0.0 } - j[a][b])
    })
}

/// Pf, Hf, Mf, L, N and the rigid mass properties as sums over the mass points (module
/// documentation, "Mass elements with rotary inertia").
pub fn modal_integrals(body: &FlexBody) -> Result<ModalIntegrals, Flex42Error> {
    body.validate()?;
    let nf = body.modes.len();
    let mut out = ModalIntegrals {
        mass_kg: 0.0,
        first_moment_kg_m: [0.0; 3],
        inertia_kg_m2: [[0.0; 3]; 3],
        modal_mass: vec![vec![0.0; nf]; nf],
        pf: vec![[0.0; 3]; nf],
        hf: vec![[0.0; 3]; nf],
        l: vec![[[0.0; 3]; 3]; nf],
        n: vec![vec![[[0.0; 3]; 3]; nf]; nf],
    };
    for point in &body.mass_points {
        add_point(&mut out, point);
    }
    add_translational_pairs(&mut out, &body.mass_points);
    Ok(out)
}

/// The mode pairs' translational sums over every point, Σ m Ψ_p[a] Ψ_q[b] into N_pq[a][b]
/// (and, a = b, into Mf), as the products A_aᵀ A_b of the points × modes matrices
/// A_a = √m Ψ[a]: the O(points · modes²) part of the integrals, a point-by-point loop of
/// which took a minute for a plate model exporting its 418 modes (faer's blocked product:
/// 0.1 s). Each N_qp is the mirror of N_pq, exactly.
fn add_translational_pairs(out: &mut ModalIntegrals, points: &[MassPoint]) {
    let nf = out.pf.len();
    if nf == 0 || points.is_empty() {
        return;
    }
    let a: [faer::Mat<f64>; 3] = std::array::from_fn(|ax| {
        faer::Mat::from_fn(points.len(), nf, |k, p| {
            points[k].mass_kg.sqrt() * points[k].psi[p][ax]
        })
    });
    for ax in 0..3 {
        for bx in ax..3 {
            let g = a[ax].transpose() * &a[bx];
            for p in 0..nf {
                for q in 0..nf {
                    // For a = b the upper triangle, mirrored.
                    if ax == bx && q < p {
                        continue;
                    }
                    let v = g[(p, q)];
                    out.n[p][q][ax][bx] += v;
                    if (p, ax) != (q, bx) {
                        out.n[q][p][bx][ax] += v;
                    }
                    if ax == bx {
                        out.modal_mass[p][q] += v;
                        if q != p {
                            out.modal_mass[q][p] += v;
                        }
                    }
                }
            }
        }
    }
}

/// Adds one rigid mass element's exact contribution to every integral but the translational
/// sums over mode pairs ([`add_translational_pairs`]).
fn add_point(out: &mut ModalIntegrals, point: &MassPoint) {
    let m = point.mass_kg;
    let r = point.position_m;
    let jk = &point.inertia_kg_m2;
    let e = second_moment(jk);
    let r2 = dot(r, r);
    out.mass_kg += m;
    for a in 0..3 {
        out.first_moment_kg_m[a] += m * r[a];
        for b in 0..3 {
            // J = Σ [J_k + m (|r|² 𝟙 − r rᵀ)]
            let delta = if a == b { r2 } else { 0.0 };
            out.inertia_kg_m2[a][b] += jk[a][b] + m * (delta - r[a] * r[b]);
        }
    }
    let theta_e: Vec<Mat3> = point.theta.iter().map(|&t| mat_mul(&skew(t), &e)).collect();
    for (p, (&psi_p, &theta_p)) in point.psi.iter().zip(&point.theta).enumerate() {
        let r_x_psi = cross(r, psi_p);
        let j_theta = mat_vec(jk, theta_p);
        for a in 0..3 {
            out.pf[p][a] += m * psi_p[a]; // Pf_p = Σ m Ψ_p
            out.hf[p][a] += m * r_x_psi[a] + j_theta[a]; // Hf_p = Σ (m r × Ψ_p + J_k Θ_p)
            for b in 0..3 {
                out.l[p][a][b] += m * psi_p[a] * r[b] + theta_e[p][a][b]; // L_p = Σ (m Ψ_p rᵀ + Θ̃_p E)
            }
        }
        // The rotary inertia's share of N and Mf (a quadrature point has none); N_qp = N_pqᵀ:
        // computed for q ≥ p, mirrored exactly for q ≠ p (N_pp's own share is symmetric to
        // rounding).
        if *jk == [[0.0; 3]; 3] {
            continue;
        }
        for (q, &theta_q) in point.theta.iter().enumerate().skip(p) {
            let mass_pq = dot(theta_p, mat_vec(jk, theta_q));
            out.modal_mass[p][q] += mass_pq;
            if q != p {
                out.modal_mass[q][p] += mass_pq;
            }
            let rot = mat_mul(&theta_e[p], &transpose(&skew(theta_q))); // Θ̃_p E Θ̃_qᵀ
            for a in 0..3 {
                for b in 0..3 {
                    let v = rot[a][b];
                    out.n[p][q][a][b] += v;
                    if q != p {
                        out.n[q][p][b][a] += v;
                    }
                }
            }
        }
    }
}

/// Checks Mf = 𝟙 within [`MODAL_MASS_TOLERANCE`].
fn check_mass_normalised(integrals: &ModalIntegrals) -> Result<(), Flex42Error> {
    for (p, row) in integrals.modal_mass.iter().enumerate() {
        for (q, &value) in row.iter().enumerate() {
            let expected = if p == q { 1.0 } else { 0.0 };
            if (value - expected).abs() > MODAL_MASS_TOLERANCE {
                return Err(Flex42Error::NotMassNormalised {
                    p,
                    q,
                    value,
                    expected,
                });
            }
        }
    }
    Ok(())
}

/// Appends `line`, padded so that comments line up, then `! comment`.
fn push_data(out: &mut String, data: &str, comment: &str) {
    let _ = writeln!(out, "{data:<36} ! {comment}");
}

/// Appends the sparse mode-shape section `count` + `mode index axis value` lines.
fn push_shapes<'a>(
    out: &mut String,
    header: &str,
    what: &str,
    entries: impl Iterator<Item = (usize, &'a [Vec3])>,
) {
    let mut nonzero: Vec<(usize, usize, usize, f64)> = Vec::new();
    for (index, shapes) in entries {
        for (mode, v) in shapes.iter().enumerate() {
            for (axis, &value) in v.iter().enumerate() {
                if value != 0.0 {
                    nonzero.push((mode, index, axis, value));
                }
            }
        }
    }
    // Mode first, as in 42's samples.
    nonzero.sort_by_key(|&(mode, index, axis, _)| (mode, index, axis));
    let lines: Vec<String> = nonzero
        .iter()
        .map(|&(mode, index, axis, value)| format!("{mode} {index} {axis} {}", num(value)))
        .collect();
    out.push_str(header);
    out.push('\n');
    push_data(out, &lines.len().to_string(), "Number of non-zero elements");
    let label = format!("[Mode] [{what}] [Axis] Value");
    for l in &lines {
        push_data(out, l, &label);
    }
}

/// Appends a sparse diagonal matrix section.
fn push_diagonal(out: &mut String, header: &str, diagonal: &[f64]) {
    out.push_str(header);
    out.push('\n');
    let nonzero: Vec<(usize, f64)> = diagonal
        .iter()
        .copied()
        .enumerate()
        .filter(|&(_, v)| v != 0.0)
        .collect();
    push_data(
        out,
        &nonzero.len().to_string(),
        "Number of non-zero elements",
    );
    for (i, v) in nonzero {
        push_data(out, &format!("{i} {i} {}", num(v)), "[Row] [Col] Value");
    }
}

/// The text of `flex_<name>.txt` in the layout 42's `InitFlexModes` reads (module
/// documentation), with Pf, Hf, L, N from [`modal_integrals`], Mf = 𝟙, Kf = diag(ω²) and
/// Cf = diag(2ζω). Refuses a body whose modes are not mass-normalised over its mass points.
pub fn flex_file(body: &FlexBody) -> Result<String, Flex42Error> {
    let integrals = modal_integrals(body)?;
    check_mass_normalised(&integrals)?;
    let nf = body.modes.len();
    let mut out = String::new();
    out.push_str("<<<<<<<<<<<<<<  Flexible Body Inputs for 42  >>>>>>>>>>>>>>>>>>>\n");
    push_data(&mut out, &format!("flexcraft {}", body.name), "Description");
    push_data(&mut out, &nf.to_string(), "Number of Flex Modes");
    out.push_str("****************** Initial Modal States x, u  ******************\n");
    for (p, mode) in body.modes.iter().enumerate() {
        let data = format!(
            "{} {}",
            num(mode.initial_displacement),
            num(mode.initial_rate)
        );
        push_data(&mut out, &data, &format!("Mode {p}  x, u"));
    }
    out.push_str("****************** Joint Node Mode Shapes *********************\n");
    let joints = || body.joints.iter();
    push_shapes(
        &mut out,
        "*******  Non-zero Translation Mode Shape (PSI) Elements ********",
        "Joint",
        joints().map(|g| (g.joint, g.psi.as_slice())),
    );
    push_shapes(
        &mut out,
        "*******  Non-zero Rotation Mode Shape (THETA) Elements ********",
        "Joint",
        joints().map(|g| (g.joint, g.theta.as_slice())),
    );
    out.push_str("**************** Analysis Node Mode Shapes *********************\n");
    let nodes = || body.nodes.iter().enumerate();
    push_shapes(
        &mut out,
        "*******  Non-zero Translation Mode Shape (PSI) Elements ********",
        "Node",
        nodes().map(|(k, n)| (k, n.psi.as_slice())),
    );
    push_shapes(
        &mut out,
        "*******  Non-zero Rotation Mode Shape (THETA) Elements ********",
        "Node",
        nodes().map(|(k, n)| (k, n.theta.as_slice())),
    );
    let omega: Vec<f64> = body.modes.iter().map(|m| m.frequency_rad_s).collect();
    push_diagonal(
        &mut out,
        "****************  Non-zero Mass Matrix Elements ******************",
        &vec![1.0; nf],
    );
    push_diagonal(
        &mut out,
        "*************  Non-zero Stiffness Matrix Elements ****************",
        &omega.iter().map(|w| w * w).collect::<Vec<_>>(),
    );
    push_diagonal(
        &mut out,
        "*************  Non-zero Damping Matrix Elements ****************",
        &body
            .modes
            .iter()
            .map(|m| 2.0 * m.damping_ratio * m.frequency_rad_s)
            .collect::<Vec<_>>(),
    );
    push_integrals(&mut out, &integrals);
    out.push_str("[EOF]\n");
    out.push_str(TRAILER);
    Ok(out)
}

/// Notes after `[EOF]`, which 42 never reads.
const TRAILER: &str = "\
Written by flexcraft. 42 reads nothing past [EOF]. SI units; body frame B, origin at the
reference point (the clamp of the hub-fixed modes): use REFPT_JOINT in the spacecraft file.
Modes mass-normalised: x = eta [sqrt(kg) m], PSI [m/sqrt(kg)], THETA [rad/sqrt(kg)].
Pf_p = int Psi_p dm; Hf_p = int r x Psi_p dm; L[i][j][p] = int Psi_ip r_j dm;
N[i][j][p][q] = int Psi_ip Psi_jq dm; rigid elements add their rotary terms.
";

/// Appends Pf, Hf, L and N.
fn push_integrals(out: &mut String, integrals: &ModalIntegrals) {
    let vector_rows = |out: &mut String, header: &str, rows: &[Vec3]| {
        out.push_str(header);
        out.push('\n');
        for (p, v) in rows.iter().enumerate() {
            let data = format!("{} {} {}", num(v[0]), num(v[1]), num(v[2]));
            push_data(out, &data, &format!("Mode {p}, [x y z]"));
        }
    };
    vector_rows(
        out,
        "*********  Linear Momentum Modal Integral, Pf, 3 x Nf  *********",
        &integrals.pf,
    );
    vector_rows(
        out,
        "********  Angular Momentum Modal Integral, Hf, 3 x Nf  *********",
        &integrals.hf,
    );
    let nf = integrals.pf.len();
    let mut lines = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            for p in 0..nf {
                let v = integrals.l_ijp(i, j, p);
                if v != 0.0 {
                    lines.push(format!("{i} {j} {p} {}", num(v)));
                }
            }
        }
    }
    out.push_str("**********  Linear Modal Integral, L, 3 x 3 x Nf  **************\n");
    push_data(out, &lines.len().to_string(), "Number of non-zero elements");
    for l in &lines {
        push_data(out, l, "[i] [j] [Mode] Value");
    }
    lines.clear();
    for i in 0..3 {
        for j in 0..3 {
            for p in 0..nf {
                for q in 0..nf {
                    let v = integrals.n_ijpq(i, j, p, q);
                    if v != 0.0 {
                        lines.push(format!("{i} {j} {p} {q} {}", num(v)));
                    }
                }
            }
        }
    }
    out.push_str("*********  Angular Modal Integral, N, 3 x 3 x Nf x Nf  *********\n");
    push_data(out, &lines.len().to_string(), "Number of non-zero elements");
    for l in &lines {
        push_data(out, l, "[i] [j] [Mode p] [Mode q] Value");
    }
}

/// The text of `nodes_<name>.txt` in the layout 42's `InitNodes` reads: the analysis
/// nodes, in the order the flex file's node indices refer to.
pub fn nodes_file(body: &FlexBody) -> Result<String, Flex42Error> {
    body.validate()?;
    let mut out = String::new();
    out.push_str("<<<<<<<<<<<<<<<<  Body Node Inputs for 42  >>>>>>>>>>>>>>>>>>>>>\n");
    push_data(&mut out, &format!("flexcraft {}", body.name), "Description");
    push_data(&mut out, &body.nodes.len().to_string(), "Number of Nodes");
    out.push_str("******************* Node Location, Comment *********************\n");
    for node in &body.nodes {
        let [x, y, z] = node.position_m;
        let _ = writeln!(out, "{} {} {}  \"{}\"", num(x), num(y), num(z), node.name);
    }
    Ok(out)
}

/// A cursor that reads text the way 42's `fscanf` calls do.
struct Scanner<'a> {
    text: &'a str,
    pos: usize,
}

impl<'a> Scanner<'a> {
    fn new(text: &'a str) -> Self {
        Self { text, pos: 0 }
    }

    /// 1-based line of the cursor.
    fn line(&self) -> usize {
        1 + self.text[..self.pos].matches('\n').count()
    }

    fn rest(&self) -> &'a str {
        &self.text[self.pos..]
    }

    /// The space directive: skips all white space, line breaks included.
    fn skip_ws(&mut self) {
        let rest = self.rest();
        self.pos += rest.len() - rest.trim_start().len();
    }

    /// A snippet of what is at the cursor, for error messages.
    fn found(&self) -> String {
        self.rest()
            .lines()
            .next()
            .unwrap_or("")
            .chars()
            .take(40)
            .collect()
    }

    fn parse_error(&self, expected: &'static str) -> Flex42Error {
        Flex42Error::Parse {
            line: self.line(),
            expected,
            found: self.found(),
        }
    }

    /// `%[^\n]` into an 80-byte buffer: one or more bytes up to the line break.
    fn read_line_rest(&mut self, expected: &'static str) -> Result<&'a str, Flex42Error> {
        let rest = self.rest();
        let len = rest.find('\n').unwrap_or(rest.len());
        let s = rest[..len].trim_end_matches('\r');
        if s.is_empty() {
            return Err(self.parse_error(expected));
        }
        if s.len() > MAX_LINE {
            return Err(Flex42Error::LineTooLong {
                line: self.line(),
                length: s.len(),
            });
        }
        self.pos += len;
        Ok(s)
    }

    /// `fscanf("%[^\n] %[\n]")`: a whole comment line, then white space.
    fn comment_line(&mut self, expected: &'static str) -> Result<&'a str, Flex42Error> {
        let s = self.read_line_rest(expected)?;
        self.skip_ws();
        Ok(s)
    }

    /// The ` %[^\n] %[\n]` that ends a data line, which began on line `line`.
    fn end_record(&mut self, line: usize) -> Result<(), Flex42Error> {
        self.skip_ws();
        if self.line() != line {
            return Err(Flex42Error::MissingComment { line });
        }
        self.read_line_rest("a trailing comment")?;
        self.skip_ws();
        Ok(())
    }

    /// `%ld`.
    fn long(&mut self) -> Result<i64, Flex42Error> {
        self.skip_ws();
        let rest = self.rest();
        let sign = usize::from(rest.starts_with(['+', '-']));
        let digits = rest[sign..].bytes().take_while(u8::is_ascii_digit).count();
        let value = rest[..sign + digits]
            .parse::<i64>()
            .map_err(|_| self.parse_error("an integer"))?;
        self.pos += sign + digits;
        Ok(value)
    }

    /// `%ld` for an index or count in 0..limit.
    fn index(&mut self, what: &'static str, limit: usize) -> Result<usize, Flex42Error> {
        let line = self.line();
        let value = self.long()?;
        match usize::try_from(value) {
            Ok(v) if v < limit => Ok(v),
            _ => Err(Flex42Error::IndexOutOfRange {
                line,
                what,
                index: value,
                limit,
            }),
        }
    }

    /// `%lf`: a finite number up to the next white space.
    fn double(&mut self) -> Result<f64, Flex42Error> {
        self.skip_ws();
        let rest = self.rest();
        let len = rest.find(char::is_whitespace).unwrap_or(rest.len());
        match rest[..len].parse::<f64>() {
            Ok(v) if v.is_finite() => {
                self.pos += len;
                Ok(v)
            }
            _ => Err(self.parse_error("a finite number")),
        }
    }

    /// `fscanf("%ld %[^\n] %[\n]")`: a count line.
    fn count_line(&mut self) -> Result<usize, Flex42Error> {
        let line = self.line();
        let n = self.index("element count", usize::MAX)?;
        self.end_record(line)?;
        Ok(n)
    }

    /// A sparse mode-shape section (after its header): count, `mode index axis value` lines.
    fn shapes(&mut self, nf: usize, what: &'static str) -> Result<Vec<ShapeEntry>, Flex42Error> {
        self.comment_line("a section header")?;
        let count = self.count_line()?;
        (0..count)
            .map(|_| {
                let line = self.line();
                let mode = self.index("mode", nf)?;
                let index = self.index(what, usize::MAX)?;
                let axis = self.index("axis", 3)?;
                let value = self.double()?;
                self.end_record(line)?;
                Ok(ShapeEntry {
                    mode,
                    index,
                    axis,
                    value,
                })
            })
            .collect()
    }

    /// A sparse Nf × Nf matrix section: header, count, `row col value` lines.
    fn matrix(&mut self, nf: usize) -> Result<Vec<MatrixEntry>, Flex42Error> {
        self.comment_line("a section header")?;
        let count = self.count_line()?;
        (0..count)
            .map(|_| {
                let line = self.line();
                let row = self.index("row", nf)?;
                let col = self.index("column", nf)?;
                let value = self.double()?;
                self.end_record(line)?;
                Ok(MatrixEntry { row, col, value })
            })
            .collect()
    }

    /// A 3 × Nf section: header, Nf lines `x y z`.
    fn vectors(&mut self, nf: usize) -> Result<Vec<Vec3>, Flex42Error> {
        self.comment_line("a section header")?;
        (0..nf)
            .map(|_| {
                let line = self.line();
                let v = [self.double()?, self.double()?, self.double()?];
                self.end_record(line)?;
                Ok(v)
            })
            .collect()
    }
}

/// Reads a flex file in 42's reading order (`InitFlexModes`: the first pass for Nf, then the
/// second pass), with the same range checks (mode < Nf, axis < 3, matrix and tensor indices)
/// and, where 42 would silently misread, an error: a data line without a trailing comment,
/// a line longer than 42's 80-byte buffer. Joint and node indices are not checked (they
/// refer to the spacecraft and nodes files). Numbers are read as whole white-space-separated
/// tokens (C's `strtod` would stop at the first character that cannot continue a number).
pub fn read_flex_file(text: &str) -> Result<ParsedFlex, Flex42Error> {
    let mut s = Scanner::new(text);
    s.skip_ws();
    s.comment_line("the title line")?;
    let description = s.comment_line("the description line")?.to_string();
    let nf = s.count_line()?;
    s.comment_line("the initial modal states header")?;
    let initial = (0..nf)
        .map(|_| {
            let line = s.line();
            let xu = (s.double()?, s.double()?);
            s.end_record(line)?;
            Ok(xu)
        })
        .collect::<Result<Vec<_>, Flex42Error>>()?;
    s.comment_line("the joint node mode shapes header")?;
    let joint_psi = s.shapes(nf, "joint")?;
    let joint_theta = s.shapes(nf, "joint")?;
    s.comment_line("the analysis node mode shapes header")?;
    let node_psi = s.shapes(nf, "node")?;
    let node_theta = s.shapes(nf, "node")?;
    let mass = s.matrix(nf)?;
    let stiffness = s.matrix(nf)?;
    let damping = s.matrix(nf)?;
    let pf = s.vectors(nf)?;
    let hf = s.vectors(nf)?;
    s.comment_line("the L header")?;
    let count = s.count_line()?;
    let l = (0..count)
        .map(|_| {
            let line = s.line();
            let e = LEntry {
                i: s.index("L i", 3)?,
                j: s.index("L j", 3)?,
                mode: s.index("L mode", nf)?,
                value: s.double()?,
            };
            s.end_record(line)?;
            Ok(e)
        })
        .collect::<Result<Vec<_>, Flex42Error>>()?;
    s.comment_line("the N header")?;
    let count = s.count_line()?;
    let n = (0..count)
        .map(|_| {
            let line = s.line();
            let e = NEntry {
                i: s.index("N i", 3)?,
                j: s.index("N j", 3)?,
                p: s.index("N p", nf)?,
                q: s.index("N q", nf)?,
                value: s.double()?,
            };
            s.end_record(line)?;
            Ok(e)
        })
        .collect::<Result<Vec<_>, Flex42Error>>()?;
    Ok(ParsedFlex {
        description,
        initial,
        joint_psi,
        joint_theta,
        node_psi,
        node_theta,
        mass,
        stiffness,
        damping,
        pf,
        hf,
        l,
        n,
    })
}

/// Reads a nodes file in 42's reading order (`InitNodes`): title, description, count,
/// header, then `x y z "comment"` per node.
pub fn read_nodes_file(text: &str) -> Result<Vec<ParsedNode>, Flex42Error> {
    let mut s = Scanner::new(text);
    s.skip_ws();
    s.comment_line("the title line")?;
    s.comment_line("the description line")?;
    let count = s.count_line()?;
    s.comment_line("the node location header")?;
    (0..count)
        .map(|_| {
            let position_m = [s.double()?, s.double()?, s.double()?];
            s.skip_ws();
            let rest = s.rest();
            let comment = rest
                .strip_prefix('"')
                .and_then(|r| r.split_once('"'))
                .map(|(c, _)| c)
                .filter(|c| !c.is_empty() && c.len() <= MAX_LINE)
                .ok_or_else(|| s.parse_error("a quoted node comment"))?;
            s.pos += comment.len() + 2;
            s.skip_ws();
            Ok(ParsedNode {
                position_m,
                comment: comment.to_string(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    //! The reference: a uniform Euler–Bernoulli cantilever (length ℓ, mass per length μ,
    //! stiffness EI) along x from the body origin, bending in y and z, with a rigid box of
    //! mass M_t at its tip; its modes in closed form.
    use super::*;
    use crate::basis::Quadrature;

    const LEN: f64 = 2.0;
    const MU: f64 = 3.0;
    const EI: f64 = 5.0e3;
    const TIP_MASS: f64 = 1.5;
    /// The tip box's sides along x, y, z [m]; its centre is the beam's tip.
    const BOX: Vec3 = [0.2, 0.3, 0.1];

    /// The tip box's inertia about its centre: M/12 diag(b² + c², a² + c², a² + b²).
    fn tip_inertia() -> Mat3 {
        let [a, b, c] = BOX;
        let k = TIP_MASS / 12.0;
        [
            [k * (b * b + c * c), 0.0, 0.0],
            [0.0, k * (a * a + c * c), 0.0],
            [0.0, 0.0, k * (a * a + b * b)],
        ]
    }

    /// One bending mode φ = A (cosh βx − cos βx) + B (sinh βx − sin βx), clamped at x = 0,
    /// in the plane y (`axis` 1, rotation about z) or z (`axis` 2, rotation about y).
    #[derive(Clone, Copy)]
    struct BeamMode {
        beta: f64,
        a: f64,
        b: f64,
        axis: usize,
    }

    /// The k-th derivatives (k ≤ 3) of cosh βx − cos βx and sinh βx − sin βx.
    fn basis(beta: f64, k: usize, x: f64) -> (f64, f64) {
        let (ch, sh, co, si) = (
            (beta * x).cosh(),
            (beta * x).sinh(),
            (beta * x).cos(),
            (beta * x).sin(),
        );
        let s = beta.powi(k as i32);
        match k {
            0 => (ch - co, sh - si),
            1 => (s * (sh + si), s * (ch - co)),
            2 => (s * (ch + co), s * (sh + si)),
            _ => (s * (sh - si), s * (ch + co)),
        }
    }

    /// The tip conditions for rotary inertia `j` about the bending axis (energy variation):
    /// EI φ''(ℓ) = ω² j φ'(ℓ) and EI φ'''(ℓ) = −ω² M_t φ(ℓ), ω² = EI β⁴/μ, as rows in (A, B).
    fn tip_rows(beta: f64, j: f64) -> [[f64; 2]; 2] {
        let k4 = beta.powi(4) / MU;
        let d = |k| basis(beta, k, LEN);
        let (c1, s1) = d(1);
        let (c2, s2) = d(2);
        let (c0, s0) = d(0);
        let (c3, s3) = d(3);
        [
            [c2 - j * k4 * c1, s2 - j * k4 * s1],
            [c3 + TIP_MASS * k4 * c0, s3 + TIP_MASS * k4 * s0],
        ]
    }

    fn determinant(beta: f64, j: f64) -> f64 {
        let r = tip_rows(beta, j);
        (r[0][0] * r[1][1] - r[0][1] * r[1][0]) / (beta * LEN).cosh().powi(2)
    }

    /// The first `count` roots β of the frequency determinant: scan, then bisect.
    fn roots(count: usize, j: f64) -> Vec<f64> {
        let mut out = Vec::new();
        let step = 1e-3 / LEN;
        let mut lo = step;
        while out.len() < count {
            let hi = lo + step;
            if determinant(lo, j).signum() != determinant(hi, j).signum() {
                let (mut a, mut b) = (lo, hi);
                for _ in 0..200 {
                    let m = 0.5 * (a + b);
                    if determinant(a, j).signum() == determinant(m, j).signum() {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                out.push(0.5 * (a + b));
            }
            lo = hi;
        }
        out
    }

    impl BeamMode {
        /// Mode of root β, normalised analytically: ∫μφ² dx + M_t φ(ℓ)² + j φ'(ℓ)² = 1 with
        /// ∫₀^ℓ φ² dx = F(ℓ)/(4β⁴), F = x(β⁴φ² − 2φ'φ''' + φ''²) + 3φφ''' − φ'φ'' (dF/dx =
        /// 4β⁴φ² since φ'''' = β⁴φ; F(0) = 0 at the clamp).
        fn new(beta: f64, axis: usize) -> Self {
            let j = bending_inertia(axis);
            let r = tip_rows(beta, j);
            let (a, b) = if r[0][0].hypot(r[0][1]) > r[1][0].hypot(r[1][1]) {
                (r[0][1], -r[0][0])
            } else {
                (r[1][1], -r[1][0])
            };
            let raw = Self { beta, a, b, axis };
            let [p0, p1, p2, p3] = [0, 1, 2, 3].map(|k| raw.phi(k, LEN));
            let b4 = beta.powi(4);
            let f = LEN * (b4 * p0 * p0 - 2.0 * p1 * p3 + p2 * p2) + 3.0 * p0 * p3 - p1 * p2;
            let norm2 = MU * f / (4.0 * b4) + TIP_MASS * p0 * p0 + j * p1 * p1;
            let s = norm2.sqrt().recip();
            Self {
                beta,
                a: a * s,
                b: b * s,
                axis,
            }
        }

        /// φ^(k)(x).
        fn phi(&self, k: usize, x: f64) -> f64 {
            let (c, s) = basis(self.beta, k, x);
            self.a * c + self.b * s
        }

        fn omega(&self) -> f64 {
            self.beta * self.beta * (EI / MU).sqrt()
        }

        /// Ψ(x): φ along the bending axis.
        fn psi(&self, x: f64) -> Vec3 {
            let mut v = [0.0; 3];
            v[self.axis] = self.phi(0, x);
            v
        }

        /// Θ(x): rotation φ' about z for y-bending, −φ' about y for z-bending.
        fn theta(&self, x: f64) -> Vec3 {
            let slope = self.phi(1, x);
            if self.axis == 1 {
                [0.0, 0.0, slope]
            } else {
                [0.0, -slope, 0.0]
            }
        }
    }

    /// The tip's rotary inertia about the axis of the rotation that bending in `axis` makes.
    fn bending_inertia(axis: usize) -> f64 {
        let j = tip_inertia();
        if axis == 1 {
            j[2][2]
        } else {
            j[1][1]
        }
    }

    /// `per_plane` modes in each plane, interleaved y, z, y, z, …
    fn beam_modes(per_plane: usize) -> Vec<BeamMode> {
        let ry = roots(per_plane, bending_inertia(1));
        let rz = roots(per_plane, bending_inertia(2));
        ry.iter()
            .zip(&rz)
            .flat_map(|(&by, &bz)| [BeamMode::new(by, 1), BeamMode::new(bz, 2)])
            .collect()
    }

    /// The flex body: composite Gauss points of the beam plus the tip box; a joint at the
    /// clamp (joint 0, no motion) and one at the tip (joint 3); nodes "mid" and "tip".
    fn body(modes: &[BeamMode]) -> FlexBody {
        let rule = Quadrature::composite(16, 12);
        let shapes = |x: f64| {
            (
                modes.iter().map(|m| m.psi(x)).collect::<Vec<_>>(),
                modes.iter().map(|m| m.theta(x)).collect::<Vec<_>>(),
            )
        };
        let mut mass_points: Vec<MassPoint> = rule
            .points
            .iter()
            .zip(&rule.weights)
            .map(|(&xi, &w)| {
                let x = LEN * xi;
                let (psi, theta) = shapes(x);
                MassPoint {
                    position_m: [x, 0.0, 0.0],
                    mass_kg: MU * LEN * w,
                    inertia_kg_m2: [[0.0; 3]; 3],
                    psi,
                    theta,
                }
            })
            .collect();
        let (psi, theta) = shapes(LEN);
        mass_points.push(MassPoint {
            position_m: [LEN, 0.0, 0.0],
            mass_kg: TIP_MASS,
            inertia_kg_m2: tip_inertia(),
            psi: psi.clone(),
            theta: theta.clone(),
        });
        let node = |name: &str, x: f64| {
            let (psi, theta) = shapes(x);
            FlexNode {
                name: name.to_string(),
                position_m: [x, 0.0, 0.0],
                psi,
                theta,
            }
        };
        let (psi0, theta0) = shapes(0.0);
        FlexBody {
            name: "boom".to_string(),
            modes: modes
                .iter()
                .enumerate()
                .map(|(p, m)| FlexMode {
                    frequency_rad_s: m.omega(),
                    damping_ratio: 0.005 * (p + 1) as f64,
                    initial_displacement: if p == 0 { 1e-6 } else { 0.0 },
                    initial_rate: 0.0,
                })
                .collect(),
            mass_points,
            joints: vec![
                FlexJoint {
                    joint: 0,
                    psi: psi0,
                    theta: theta0,
                },
                FlexJoint {
                    joint: 3,
                    psi,
                    theta,
                },
            ],
            nodes: vec![node("mid", 0.5 * LEN), node("tip", LEN)],
        }
    }

    /// ∫₀^ℓ f dx by composite Simpson on `n` (even) intervals: a different rule from the
    /// Gauss points the body is built from.
    fn simpson(n: usize, f: impl Fn(f64) -> f64) -> f64 {
        let h = LEN / n as f64;
        let inner: f64 = (1..n)
            .map(|k| f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
            .sum();
        h / 3.0 * (f(0.0) + inner + f(LEN))
    }

    /// ∫ over the tip box of g(ρ) dm by the 2 × 2 × 2 Gauss product rule, exact for the
    /// quadratics in ρ integrated here (the box's own mass distribution, not its inertia).
    fn over_box(g: impl Fn(Vec3) -> f64) -> f64 {
        let t = 0.5 / 3f64.sqrt();
        let mut sum = 0.0;
        for sx in [-t, t] {
            for sy in [-t, t] {
                for sz in [-t, t] {
                    sum += g([sx * BOX[0], sy * BOX[1], sz * BOX[2]]);
                }
            }
        }
        TIP_MASS * sum / 8.0
    }

    /// The definitions evaluated independently: Simpson on the closed-form beam fields plus
    /// the tip box integrated as a body, each point of it moving by Ψ(ℓ) + Θ(ℓ) × ρ.
    fn reference(modes: &[BeamMode]) -> ModalIntegrals {
        let nf = modes.len();
        let n = 4000;
        let beam_r = |x: f64| [x, 0.0, 0.0];
        let tip_u = |p: usize, rho: Vec3| {
            let m = &modes[p];
            let (psi, rot) = (m.psi(LEN), cross(m.theta(LEN), rho));
            [psi[0] + rot[0], psi[1] + rot[1], psi[2] + rot[2]]
        };
        let tip_r = |rho: Vec3| [LEN + rho[0], rho[1], rho[2]];
        let both = |beam: &dyn Fn(f64) -> f64, tip: &dyn Fn(Vec3) -> f64| {
            simpson(n, |x| MU * beam(x)) + over_box(tip)
        };
        let pf = (0..nf)
            .map(|p| {
                std::array::from_fn(|a| both(&|x| modes[p].psi(x)[a], &|rho| tip_u(p, rho)[a]))
            })
            .collect();
        let hf = (0..nf)
            .map(|p| {
                std::array::from_fn(|a| {
                    both(&|x| cross(beam_r(x), modes[p].psi(x))[a], &|rho| {
                        cross(tip_r(rho), tip_u(p, rho))[a]
                    })
                })
            })
            .collect();
        let l = (0..nf)
            .map(|p| {
                std::array::from_fn(|i| {
                    std::array::from_fn(|j| {
                        both(&|x| modes[p].psi(x)[i] * beam_r(x)[j], &|rho| {
                            tip_u(p, rho)[i] * tip_r(rho)[j]
                        })
                    })
                })
            })
            .collect();
        let n_pq = |p: usize, q: usize| -> Mat3 {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    both(&|x| modes[p].psi(x)[i] * modes[q].psi(x)[j], &|rho| {
                        tip_u(p, rho)[i] * tip_u(q, rho)[j]
                    })
                })
            })
        };
        let n_all: Vec<Vec<Mat3>> = (0..nf)
            .map(|p| (0..nf).map(|q| n_pq(p, q)).collect())
            .collect();
        let modal_mass = n_all
            .iter()
            .map(|row| row.iter().map(|m| m[0][0] + m[1][1] + m[2][2]).collect())
            .collect();
        ModalIntegrals {
            mass_kg: MU * LEN + TIP_MASS,
            first_moment_kg_m: [0.0; 3],
            inertia_kg_m2: [[0.0; 3]; 3],
            modal_mass,
            pf,
            hf,
            l,
            n: n_all,
        }
    }

    /// max |a − b| ≤ tol · max |b| over a tensor.
    fn assert_close(what: &str, a: &[f64], b: &[f64], tol: f64) {
        assert_eq!(a.len(), b.len());
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(err <= tol * scale, "{what}: error {err:e}, scale {scale:e}");
    }

    fn flat_l(l: &[Mat3]) -> Vec<f64> {
        l.iter().flat_map(|m| m.as_flattened().to_vec()).collect()
    }

    fn flat_n(n: &[Vec<Mat3>]) -> Vec<f64> {
        n.iter().flat_map(|row| flat_l(row)).collect()
    }

    #[test]
    fn val_frequency_equation_roots() {
        // Without rotary inertia the roots satisfy the textbook tip-mass equation
        // 1 + cos βℓ cosh βℓ + (M_t β/μ)(cos βℓ sinh βℓ − sin βℓ cosh βℓ) = 0.
        for beta in roots(3, 0.0) {
            let bl = beta * LEN;
            let f = 1.0
                + bl.cos() * bl.cosh()
                + TIP_MASS * beta / MU * (bl.cos() * bl.sinh() - bl.sin() * bl.cosh());
            assert!(f.abs() < 1e-9 * bl.cosh(), "residual {f} at βℓ = {bl}");
        }
    }

    #[test]
    fn val_integrals_against_quadrature_of_closed_form_modes() {
        let modes = beam_modes(3);
        let got = modal_integrals(&body(&modes)).unwrap();
        let want = reference(&modes);
        let tol = 1e-9;
        for p in 0..modes.len() {
            assert_close(&format!("Pf mode {p}"), &got.pf[p], &want.pf[p], tol);
            assert_close(&format!("Hf mode {p}"), &got.hf[p], &want.hf[p], tol);
            assert_close(
                &format!("L mode {p}"),
                got.l[p].as_flattened(),
                want.l[p].as_flattened(),
                tol,
            );
        }
        assert_close("Pf", got.pf.as_flattened(), want.pf.as_flattened(), tol);
        assert_close("Hf", got.hf.as_flattened(), want.hf.as_flattened(), tol);
        assert_close("L", &flat_l(&got.l), &flat_l(&want.l), tol);
        assert_close("N", &flat_n(&got.n), &flat_n(&want.n), tol);
        let mm = |m: &[Vec<f64>]| m.concat();
        assert_close("Mf", &mm(&got.modal_mass), &mm(&want.modal_mass), tol);
        assert!((got.mass_kg - want.mass_kg).abs() < 1e-12 * want.mass_kg);
    }

    #[test]
    fn val_pf_hf_are_root_shear_and_moment_over_omega_squared() {
        // EI φ'''' = μω²φ integrated over the beam, with the tip conditions:
        // ∫μφ dx + M_t φ(ℓ) = −EI φ'''(0)/ω² and ∫μxφ dx + M_t ℓ φ(ℓ) + j φ'(ℓ) = EI φ''(0)/ω².
        let modes = beam_modes(3);
        let got = modal_integrals(&body(&modes)).unwrap();
        for (p, m) in modes.iter().enumerate() {
            let w2 = m.omega().powi(2);
            let shear = -EI * m.phi(3, 0.0) / w2;
            let moment = EI * m.phi(2, 0.0) / w2;
            let (pf, h) = if m.axis == 1 {
                (got.pf[p][1], got.hf[p][2])
            } else {
                (got.pf[p][2], -got.hf[p][1])
            };
            assert!(
                (pf - shear).abs() < 1e-10 * shear.abs(),
                "mode {p}: {pf} vs {shear}"
            );
            assert!(
                (h - moment).abs() < 1e-10 * moment.abs(),
                "mode {p}: {h} vs {moment}"
            );
        }
    }

    #[test]
    fn prop_modes_mass_normalised_and_orthogonal_over_the_mass_points() {
        // Σ m Ψ_p·Ψ_q + Θ_pᵀ J Θ_q = δ_pq (normalised in closed form, summed by Gauss).
        let modes = beam_modes(3);
        let got = modal_integrals(&body(&modes)).unwrap();
        for (p, row) in got.modal_mass.iter().enumerate() {
            for (q, &v) in row.iter().enumerate() {
                let want = if p == q { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-12, "Mf[{p}][{q}] = {v}");
            }
        }
    }

    #[test]
    fn prop_slide_identities_hold() {
        // 42's slides: Hf from L's antisymmetric part, Mf = trace of N, N_ijpq = N_jiqp.
        let modes = beam_modes(3);
        let got = modal_integrals(&body(&modes)).unwrap();
        let nf = modes.len();
        for p in 0..nf {
            let l = |i, j| got.l_ijp(i, j, p);
            let h = [l(2, 1) - l(1, 2), l(0, 2) - l(2, 0), l(1, 0) - l(0, 1)];
            assert_close("Hf from L", &h, &got.hf[p], 1e-13);
            for q in 0..nf {
                let tr: f64 = (0..3).map(|i| got.n_ijpq(i, i, p, q)).sum();
                assert!((tr - got.modal_mass[p][q]).abs() < 1e-13);
                for i in 0..3 {
                    for j in 0..3 {
                        assert_eq!(got.n_ijpq(i, j, p, q), got.n_ijpq(j, i, q, p));
                    }
                }
            }
        }
    }

    #[test]
    fn prop_effective_masses_grow_towards_the_flexible_mass_and_inertia() {
        // Bessel: Σ_p Pf_py² ≤ m (projection of the rigid translation along y), and
        // Σ_p Hf_pz² ≤ J_zz about the clamp, both growing with the number of modes.
        let modes = beam_modes(5);
        let got = modal_integrals(&body(&modes)).unwrap();
        let mass = MU * LEN + TIP_MASS;
        let j_zz = got.inertia_kg_m2[2][2];
        let want_j = MU * LEN.powi(3) / 3.0 + TIP_MASS * LEN * LEN + tip_inertia()[2][2];
        assert!((j_zz - want_j).abs() < 1e-12 * want_j);
        let (mut m_sum, mut j_sum) = (0.0, 0.0);
        for p in (0..modes.len()).filter(|&p| modes[p].axis == 1) {
            let (dm, dj) = (got.pf[p][1].powi(2), got.hf[p][2].powi(2));
            assert!(dm > 0.0 && dj > 0.0);
            m_sum += dm;
            j_sum += dj;
            assert!(m_sum <= mass && j_sum <= j_zz);
        }
        // Five modes: about 92 % of the mass (a cantilever's classic 61 %, 19 %, 6.5 %, …).
        assert!(m_sum > 0.9 * mass, "{m_sum} of {mass}");
        assert!(j_sum > 0.9 * j_zz, "{j_sum} of {j_zz}");
    }

    #[test]
    fn participations_equal_the_modes_root_loads() {
        // The truth, from the mode's own equation and tip conditions rather than quadrature:
        // integrating EI φ'''' = ω² μ φ over the beam, with EI φ'''(ℓ) = −ω² M_t φ(ℓ) and
        // EI φ''(ℓ) = ω² j φ'(ℓ) at the tip, gives the participations as the root's shear and
        // moment per ω²: ∫μφ dx + M_t φ(ℓ) = −(EI/ω²) φ'''(0) = −2Bμ/β, and
        // ∫μxφ dx + M_t ℓ φ(ℓ) + j φ'(ℓ) = (EI/ω²) φ''(0) = 2Aμ/β² (φ = A(cosh βx − cos βx)
        // + B(sinh βx − sin βx), EI/ω² = μ/β⁴). To 1e-9: the flex body's composite Gauss rule
        // integrates the fifth mode's x·φ to 2.5e-10.
        let modes = beam_modes(5);
        let got = modal_integrals(&body(&modes)).unwrap();
        for (p, m) in modes.iter().enumerate().filter(|(_, m)| m.axis == 1) {
            let pf = -2.0 * m.b * MU / m.beta;
            let hf = 2.0 * m.a * MU / (m.beta * m.beta);
            assert!(
                (got.pf[p][1] - pf).abs() <= 1e-9 * pf.abs(),
                "Pf {p}: {} vs {pf}",
                got.pf[p][1]
            );
            assert!(
                (got.hf[p][2] - hf).abs() <= 1e-9 * hf.abs(),
                "Hf {p}: {} vs {hf}",
                got.hf[p][2]
            );
        }
    }

    fn dense_shapes(entries: &[ShapeEntry], index: usize, nf: usize) -> Vec<Vec3> {
        let mut out = vec![[0.0; 3]; nf];
        for e in entries.iter().filter(|e| e.index == index) {
            out[e.mode][e.axis] = e.value;
        }
        out
    }

    #[test]
    fn prop_flex_file_reads_back_exactly_in_42s_order() {
        let modes = beam_modes(3);
        let b = body(&modes);
        let nf = modes.len();
        let text = flex_file(&b).unwrap();
        let parsed = read_flex_file(&text).unwrap();
        let integrals = modal_integrals(&b).unwrap();
        assert_eq!(
            parsed.description,
            "flexcraft boom                       ! Description"
        );
        let initial: Vec<(f64, f64)> = b
            .modes
            .iter()
            .map(|m| (m.initial_displacement, m.initial_rate))
            .collect();
        assert_eq!(parsed.initial, initial);
        assert!(parsed.joint_psi.iter().all(|e| e.index == 3));
        assert_eq!(dense_shapes(&parsed.joint_psi, 3, nf), b.joints[1].psi);
        assert_eq!(dense_shapes(&parsed.joint_theta, 3, nf), b.joints[1].theta);
        for (k, node) in b.nodes.iter().enumerate() {
            assert_eq!(dense_shapes(&parsed.node_psi, k, nf), node.psi);
            assert_eq!(dense_shapes(&parsed.node_theta, k, nf), node.theta);
        }
        let diag = |entries: &[MatrixEntry]| {
            assert!(entries.iter().all(|e| e.row == e.col));
            entries.iter().map(|e| e.value).collect::<Vec<_>>()
        };
        assert_eq!(diag(&parsed.mass), vec![1.0; nf]);
        let w: Vec<f64> = b.modes.iter().map(|m| m.frequency_rad_s).collect();
        assert_eq!(
            diag(&parsed.stiffness),
            w.iter().map(|w| w * w).collect::<Vec<_>>()
        );
        let c: Vec<f64> = b
            .modes
            .iter()
            .map(|m| 2.0 * m.damping_ratio * m.frequency_rad_s)
            .collect();
        assert_eq!(diag(&parsed.damping), c);
        assert_eq!(parsed.pf, integrals.pf);
        assert_eq!(parsed.hf, integrals.hf);
        let mut l = vec![[[0.0; 3]; 3]; nf];
        for e in &parsed.l {
            l[e.mode][e.i][e.j] = e.value;
        }
        assert_eq!(l, integrals.l);
        let mut n = vec![vec![[[0.0; 3]; 3]; nf]; nf];
        for e in &parsed.n {
            n[e.p][e.q][e.i][e.j] = e.value;
        }
        assert_eq!(n, integrals.n);
        // Deterministic text.
        assert_eq!(flex_file(&b).unwrap(), text);
        // 42's 80-byte buffer: every line it reads is shorter (the reader checks the
        // comments; the whole data lines are short too).
        let read_part = text.split("[EOF]").next().unwrap();
        assert!(read_part.lines().all(|l| l.len() < 80));
    }

    #[test]
    fn prop_nodes_file_reads_back_exactly() {
        let b = body(&beam_modes(1));
        let nodes = read_nodes_file(&nodes_file(&b).unwrap()).unwrap();
        let want: Vec<ParsedNode> = b
            .nodes
            .iter()
            .map(|n| ParsedNode {
                position_m: n.position_m,
                comment: n.name.clone(),
            })
            .collect();
        assert_eq!(nodes, want);
    }

    #[test]
    fn val_reader_follows_42s_scanf_on_a_hand_written_file() {
        // 42's own layout with its habits: padded columns, 1.0E-6 style numbers, a blank
        // line (skipped by the " " directive), zero-count sections.
        let text = "\
<<<<  Flexible Body Inputs for 42  >>>>
Hand Model                           ! Description
1                                    ! Number of Flex Modes
****** Initial Modal States x, u ******
1.0E-6  0.0                          ! Mode 0  x, u
****** Joint Node Mode Shapes ******
****** PSI ******
0                                    ! Number of non-zero elements
****** THETA ******
0                                    ! Number of non-zero elements
****** Analysis Node Mode Shapes ******
****** PSI ******
1                                    ! Number of non-zero elements
  0  1  2  -0.25                     ! [Mode] [Node] [Axis] Value

****** THETA ******
0                                    ! Number of non-zero elements
****** Mass ******
1                                    ! Number of non-zero elements
0 0    1.0                           ! [Row] [Col] Value
****** Stiffness ******
1                                    ! n
0 0    39.478                        ! (1 Hz)
****** Damping ******
0                                    ! n
****** Pf ******
0.5 0.0 -1.5                         ! Mode 0
****** Hf ******
0.0 2.0 0.0                          ! Mode 0
****** L ******
1                                    ! n
1 0 0 0.75                           ! [i] [j] [Mode]
****** N ******
1                                    ! n
2 2 0 0 1.0                          ! [i] [j] [p] [q]
";
        let f = read_flex_file(text).unwrap();
        assert_eq!(f.initial, vec![(1e-6, 0.0)]);
        assert_eq!(
            f.node_psi,
            vec![ShapeEntry {
                mode: 0,
                index: 1,
                axis: 2,
                value: -0.25
            }]
        );
        assert_eq!(f.stiffness[0].value, 39.478);
        assert!(f.damping.is_empty());
        assert_eq!(f.pf, vec![[0.5, 0.0, -1.5]]);
        assert_eq!(f.hf, vec![[0.0, 2.0, 0.0]]);
        assert_eq!(f.l[0].value, 0.75);
        assert_eq!((f.n[0].i, f.n[0].value), (2, 1.0));
    }

    #[test]
    fn bad_files_are_refused_where_42_would_misread() {
        let b = body(&beam_modes(1));
        let text = flex_file(&b).unwrap();
        // A data line without its comment: 42 would swallow the next line.
        let no_comment = text.replacen("! Number of Flex Modes", "", 1);
        assert!(matches!(
            read_flex_file(&no_comment),
            Err(Flex42Error::MissingComment { line: 3 })
        ));
        // A comment longer than 42's buffer.
        let long = text.replacen("! Description", &format!("! {}", "x".repeat(90)), 1);
        assert!(matches!(
            read_flex_file(&long),
            Err(Flex42Error::LineTooLong { line: 2, .. })
        ));
        // An axis out of range, as 42 checks.
        let pos = text.find("! [Mode] [Node] [Axis] Value").unwrap();
        let start = text[..pos].rfind('\n').unwrap() + 1;
        let mut bad = text.clone();
        bad.replace_range(start..start + 5, "0 0 3");
        assert!(matches!(
            read_flex_file(&bad),
            Err(Flex42Error::IndexOutOfRange {
                what: "axis",
                index: 3,
                ..
            })
        ));
        // A number that is not one.
        let nan = text.replacen("1e0 ", "nan ", 1);
        assert!(matches!(
            read_flex_file(&nan),
            Err(Flex42Error::Parse { .. })
        ));
    }

    #[test]
    fn bad_bodies_are_refused_with_the_value() {
        let good = body(&beam_modes(1));
        let with = |f: &dyn Fn(&mut FlexBody)| {
            let mut b = good.clone();
            f(&mut b);
            flex_file(&b).unwrap_err()
        };
        assert!(matches!(
            with(&|b| b.name = "a b".into()),
            Flex42Error::BadName { .. }
        ));
        assert!(matches!(
            with(&|b| b.name = "n".repeat(31)),
            Flex42Error::BadName { .. }
        ));
        assert!(matches!(
            with(&|b| b.modes.clear()),
            Flex42Error::NoModes { .. }
        ));
        assert!(matches!(
            with(&|b| b.modes[0].damping_ratio = 1.0),
            Flex42Error::OutOfRange { value, .. } if value == 1.0
        ));
        assert!(matches!(
            with(&|b| b.mass_points[0].psi.push([0.0; 3])),
            Flex42Error::ModeCount {
                expected: 2,
                found: 3,
                ..
            }
        ));
        assert!(matches!(
            with(&|b| b.nodes[0].position_m[1] = f64::NAN),
            Flex42Error::NotFinite { .. }
        ));
        assert!(matches!(
            with(&|b| b.nodes[0].name = "say \"hi\"".into()),
            Flex42Error::BadNodeName { .. }
        ));
        assert!(matches!(
            with(&|b| b.joints[1].joint = 0),
            Flex42Error::DuplicateJoint { joint: 0 }
        ));
        // Half the tip mass missing: the modes are no longer mass-normalised.
        assert!(matches!(
            with(&|b| b.mass_points.last_mut().unwrap().mass_kg *= 0.5),
            Flex42Error::NotMassNormalised { p: 0, q: 0, .. }
        ));
    }

    #[test]
    fn sc_mass_lines_use_42s_product_sign() {
        let mut b = body(&beam_modes(1));
        b.mass_points = vec![MassPoint {
            position_m: [1.0, 2.0, 0.0],
            mass_kg: 2.0,
            inertia_kg_m2: [[0.0; 3]; 3],
            psi: vec![[0.0; 3]; 2],
            theta: vec![[0.0; 3]; 2],
        }];
        let i = modal_integrals(&b).unwrap();
        // J_xy = −m x y = −4; 42's file holds ∫ x y dm = 4.
        assert_eq!(i.inertia_kg_m2[0][1], -4.0);
        let lines = i.sc_mass_lines();
        assert!(
            lines.contains("\n4e0 0e0 0e0  ! Products of Inertia"),
            "{lines}"
        );
        assert_eq!(i.mass_centre_m(), [1.0, 2.0, 0.0]);
    }
}
