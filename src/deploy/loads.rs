//! Loads and impulses of the coupled model ([`super::coupled`]): the hinge reactions, every
//! base beam's root loads and tip deflection, the impulses of a latch, and the coupled
//! model as an `Engine` of a deployment run.
//!
//! Hinge reactions (Newton–Euler on the outboard sub-chain, hinge components): with the
//! panels' inertial accelerations a_i, angular velocities ω_i and accelerations ε_i,
//!   F_l = Σ_{i≥l} m_i a_i,   M_l = Σ_{i≥l} (c_i − h_l) × m_i a_i + I_i ε_i + ω_i × I_i ω_i,
//! the force the inboard body applies to panel l and the moment its hinge transmits (the
//! planar chain's F_i and M_i when the root hinge is held).
//!
//! Root loads of a base beam: the beam and everything outboard of it (its subtree, and the
//! array when it hangs there) is a free body on which only its parent acts, so the parent's
//! force and moment about the hub's centre of mass O are the rates of its momenta
//! ([`super::inertia::Invariants::wrench`]) plus, for a subtree that carries the array, the
//! wrench it applies to panel 1 at the root hinge H:
//!   F = ṗ_s + ω × p_s + W_F,   M_O = ḣ_s + ω × h_s + v × p_s + M_H + r_H × W_F,
//! moved to the root point r_b: M_b = M_O − r_b × F. Momentum rates give the loads without
//! differentiating the truncated elastic field twice, as a stress recovery from curvatures
//! would.

use super::attitude;
use super::chain::{Hinge, P2};
use super::coupled::{Coupled, Eval, Solution, Synchronisation};
use super::inertia::combine;
use super::run::{Engine, Impulses};
use super::{BodySample, Sample};
use crate::math::Vec3;
use crate::ode::integrator::{Change, Tie};

/// ẑ, the hinge axis in hinge components.
const Z: Vec3 = Vec3::new(0.0, 0.0, 1.0);

impl Coupled {
    /// The panels' inertial accelerations, angular velocities and angular accelerations
    /// (hinge components) for the solution `sol` at state `y`.
    fn panel_accelerations(&self, y: &[f64], ev: &Eval, sol: &Solution) -> Vec<[Vec3; 3]> {
        let s = self.view(y);
        let u = &y[self.positions()..];
        let nb = self.rate_offset();
        let omega = Vec3::new(
            (0..nb).map(|j| ev.b[(3, j)] * u[j]).sum(),
            (0..nb).map(|j| ev.b[(4, j)] * u[j]).sum(),
            (0..nb).map(|j| ev.b[(5, j)] * u[j]).sum(),
        );
        let acc = &sol.hinge_acc;
        let a_h = Vec3::new(acc[0], acc[1], acc[2]);
        let wd_h = Vec3::new(acc[3], acc[4], acc[5]);
        let rates = self.chain.phi_rates(s.alpha_dot);
        let rates_dd = self.chain.phi_rates(&acc[6..]);
        let (mut vh, mut ah) = (Vec3::ZERO, Vec3::ZERO);
        (0..self.panels())
            .map(|i| {
                let c = ev.centres[i];
                let r = c - ev.hinge_points[i];
                let l = ev.hinge_points[i + 1] - ev.hinge_points[i];
                let (w, wd) = (rates[i], rates_dd[i]);
                let vrel = vh + Z.cross(r) * w;
                let arel = ah + Z.cross(r) * wd - r * (w * w);
                vh = vh + Z.cross(l) * w;
                ah = ah + Z.cross(l) * wd - l * (w * w);
                let a = a_h
                    + wd_h.cross(c)
                    + omega.cross(omega.cross(c))
                    + omega.cross(vrel) * 2.0
                    + arel;
                let wi = omega + Z * w;
                let ei = wd_h + Z * wd + omega.cross(Z * w);
                [a, wi, ei]
            })
            .collect()
    }

    /// Per hinge, hinge components: the force the inboard body applies to panel l (N) and the
    /// moment the hinge transmits about h_l (N·m).
    pub fn hinge_loads(&self, y: &[f64], ev: &Eval, sol: &Solution) -> Vec<(Vec3, Vec3)> {
        let kin = self.panel_accelerations(y, ev, sol);
        let n = self.panels();
        let mut out = vec![(Vec3::ZERO, Vec3::ZERO); n];
        // Tip to root: M_l = M_{l+1} + (h_{l+1} − h_l) × F_{l+1} + panel l's own terms.
        let (mut f, mut m) = (Vec3::ZERO, Vec3::ZERO);
        for l in (0..n).rev() {
            let h = ev.hinge_points[l];
            m = m + (ev.hinge_points[l + 1] - h).cross(f);
            let [a, w, e] = kin[l];
            let fl = a * self.chain.panels[l].mass;
            let il = self.panel_tensor(l, ev.phi[l]);
            f = f + fl;
            m = m + (ev.centres[l] - h).cross(fl) + il.apply(e) + w.cross(il.apply(w));
            out[l] = (f, m);
        }
        out
    }

    /// Per hinge: the linear impulse (N·s, deployment-plane axes) from the inboard body on
    /// panel l and the angular impulse (N·m·s) its hinge carries, for a jump of the speeds
    /// from those of `y` to `u_after`.
    pub fn hinge_impulses(&self, y: &[f64], u_after: &[f64]) -> Vec<(P2, f64)> {
        let np = self.positions();
        let ev = self.evaluate(y);
        let mut y_after = y.to_vec();
        y_after[np..].copy_from_slice(u_after);
        let et = ev.frame.transpose();
        let before = self.panel_motion(y, &ev);
        let after = self.panel_motion(&y_after, &ev);
        let dv: Vec<(Vec3, Vec3)> = before
            .iter()
            .zip(&after)
            .map(|(b, a)| (et.apply(a.1 - b.1), et.apply(a.2 - b.2)))
            .collect();
        let n = self.panels();
        (0..n)
            .map(|l| {
                let h = ev.hinge_points[l];
                let (mut s, mut a) = (Vec3::ZERO, Vec3::ZERO);
                for i in l..n {
                    let si = dv[i].0 * self.chain.panels[i].mass;
                    s = s + si;
                    a = a
                        + (ev.centres[i] - h).cross(si)
                        + self.panel_tensor(i, ev.phi[i]).apply(dv[i].1);
                }
                ([s.get(0), s.get(1)], a.get(2))
            })
            .collect()
    }

    /// Per base beam: elastic tip deflection along its axes (u, v, w, m) and twist (rad).
    pub fn beam_tips(&self, y: &[f64]) -> Vec<[f64; 4]> {
        let eta = self.view(y).eta;
        self.base
            .beams
            .iter()
            .map(|b| {
                let d = combine(&b.tip_shapes, eta);
                let r = combine(&b.tip_rotations, eta);
                [
                    d.dot(b.axes[0]),
                    d.dot(b.axes[1]),
                    d.dot(b.axes[2]),
                    r.dot(b.axes[0]),
                ]
            })
            .collect()
    }

    /// Per base beam: the force (N) and the moment about its root point (N·m) its parent
    /// exerts on it, hub components (module doc).
    pub fn beam_root_loads(&self, y: &[f64], ev: &Eval, sol: &Solution) -> Vec<[f64; 6]> {
        let s = self.view(y);
        let (h, m) = (self.hub_dof(), self.modes());
        let ud = &sol.udot;
        let (vd, wd) = if h == 6 {
            (
                Vec3::new(ud[0], ud[1], ud[2]),
                Vec3::new(ud[3], ud[4], ud[5]),
            )
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        let eta_dd = &ud[h..h + m];
        let (wf, wm) = sol.root_wrench;
        self.base
            .beams
            .iter()
            .map(|b| {
                let at = b.subtree.at(s.eta);
                let (mut f, mut mo) = b.subtree.wrench(&at, s.v, s.w, s.eta_dot, vd, wd, eta_dd);
                if b.carries_array {
                    f = f + wf;
                    mo = mo + wm + ev.hinge.cross(wf);
                }
                let root = b.root + combine(&b.root_shapes, s.eta);
                let mb = mo - root.cross(f);
                [
                    f.get(0),
                    f.get(1),
                    f.get(2),
                    mb.get(0),
                    mb.get(1),
                    mb.get(2),
                ]
            })
            .collect()
    }

    /// The 3-D part of a sample.
    fn body_sample(&self, y: &[f64], ev: &Eval, sol: &Solution) -> BodySample {
        let s = self.view(y);
        let a = attitude::matrix(s.quat);
        let (p, l, _) = self.momentum(y);
        BodySample {
            hub_position: s.r.0,
            hub_rotation: attitude::rotation_vector(s.quat).0,
            hub_velocity: a.apply(s.v).0,
            hub_rate: a.apply(s.w).0,
            eta: s.eta.to_vec(),
            beam_tips: self.beam_tips(y),
            root_loads: self.beam_root_loads(y, ev, sol),
            cable_torque: sol.cable_torque.clone(),
            elastic: self.elastic_energy(y),
            momentum: p.0,
            angular_momentum: l.0,
        }
    }
}

/// Where each load the coupled model tracks at every step sits in its
/// `Engine::load_magnitudes` and so in [`super::DeploymentResult::load_peaks`]: every hinge's
/// latch moment, every base beam's root force and root moment, every hinge's reaction force,
/// every hinge's transmitted moment, the hub's |rotation vector| and |position|.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackedLoads {
    hinges: usize,
    beams: usize,
}

impl TrackedLoads {
    /// Hinge h's (0-based) latch moment magnitude, N·m.
    pub fn latch_moment(self, h: usize) -> usize {
        h
    }
    /// Base beam b's (0-based, [`super::base::BaseModel::beams`] order) root force, N.
    pub fn root_force(self, b: usize) -> usize {
        self.hinges + 2 * b
    }
    /// Base beam b's root moment, N·m.
    pub fn root_moment(self, b: usize) -> usize {
        self.hinges + 2 * b + 1
    }
    /// Hinge h's in-plane reaction force, N.
    pub fn hinge_force(self, h: usize) -> usize {
        self.hinges + 2 * self.beams + h
    }
    /// Hinge h's transmitted moment, N·m.
    pub fn hinge_moment(self, h: usize) -> usize {
        2 * self.hinges + 2 * self.beams + h
    }
    /// The hub's |rotation vector|, rad.
    pub fn hub_rotation(self) -> usize {
        3 * self.hinges + 2 * self.beams
    }
    /// The hub's |position|, m.
    pub fn hub_position(self) -> usize {
        3 * self.hinges + 2 * self.beams + 1
    }
}

impl Coupled {
    /// The layout of the loads tracked at every step.
    pub fn tracked_loads(&self) -> TrackedLoads {
        TrackedLoads {
            hinges: self.panels(),
            beams: self.base.beams.len(),
        }
    }
}

impl Engine for Coupled {
    fn hinges(&self) -> &[Hinge] {
        &self.chain.hinges
    }
    fn positions(&self) -> usize {
        Coupled::positions(self)
    }
    fn alpha_offset(&self) -> usize {
        Coupled::alpha_offset(self)
    }
    fn rate_offset(&self) -> usize {
        Coupled::rate_offset(self)
    }
    fn initial_state(&self) -> Vec<f64> {
        Coupled::initial_state(self)
    }
    fn ideal_cable(&self) -> bool {
        self.sync == Synchronisation::IdealCable
    }
    fn compliant(&self) -> bool {
        self.latch.is_some()
    }
    fn latch_period(&self) -> f64 {
        self.latch.as_ref().map_or(0.0, |l| {
            super::latch_period(&self.chain, &l.stiffness, self.sync)
        })
    }
    fn array_fastest(&self, moving: &[bool], latched: &[bool]) -> f64 {
        let latch: Vec<f64> = match &self.latch {
            Some(l) => l
                .stiffness
                .iter()
                .zip(latched.iter().chain(std::iter::repeat(&false)))
                .map(|(k, on)| if *on { *k } else { 0.0 })
                .collect(),
            None => Vec::new(),
        };
        super::timescales::fastest(&self.chain, &latch, self.sync, moving)
    }
    fn base_resolved(&self) -> f64 {
        let kept = self.modes() - self.base.correction;
        self.base.omega[..kept].iter().copied().fold(0.0, f64::max)
    }
    fn latch_window(&self, captured: &[bool]) -> f64 {
        let Some(l) = &self.latch else {
            return 0.0;
        };
        let q: Vec<f64> = self.chain.hinges.iter().map(|h| h.latch_angle).collect();
        let slowest = super::timescales::array_frequencies(
            &self.chain,
            &q,
            &l.stiffness,
            self.sync,
            captured,
        )
        .first()
        .copied()
        .unwrap_or(0.0);
        if slowest > 0.0 {
            2.0 * std::f64::consts::PI / slowest
        } else {
            0.0
        }
    }
    fn fast_threshold(&self) -> f64 {
        let lowest = self.base.omega[..self.modes()]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        crate::ode::adiabatic::fast_threshold(lowest)
    }
    fn rhs(&self, y: &[f64], free: &[bool], captured: &[bool], dy: &mut [f64]) {
        self.rhs_captured(y, free, captured, dy);
    }
    fn kinematic(&self) -> usize {
        self.kinematic_positions()
    }
    fn rhs_kinematic(&self, y: &[f64], dy: &mut [f64]) {
        self.hub_kinematics(y, dy);
    }
    fn speed_offset(&self) -> Option<usize> {
        Some(Coupled::positions(self))
    }
    fn rhs_speeds(
        &self,
        y: &[f64],
        free: &[bool],
        captured: &[bool],
        changes: &[Change],
        out: &mut [Vec<f64>],
    ) {
        self.rhs_captured_speeds(y, free, captured, changes, out);
    }
    fn ties(&self, free: &[bool]) -> Vec<Tie> {
        self.cable_ties(free)
    }
    fn invariants(&self, y: &[f64]) -> Vec<f64> {
        if self.hub_dof() < 6 {
            return Vec::new();
        }
        // Nothing acts from outside a free hub: P and L about the centre of mass are
        // conserved (through impacts and captures too: their impulses are internal).
        let (p, l, _) = self.momentum(y);
        p.0.iter().chain(&l.0).copied().collect()
    }
    /// The base modes' velocities η̇_j at ω_j times the absolute tolerance of their
    /// displacements η_j (at least once: a mode below 1 rad/s keeps the common tolerance):
    /// an error in either then carries the same energy, ½ δη̇² = ½ ω_j² δη². With one
    /// tolerance for both, the slow run's quasi-static η̇ (the derivative of the base's
    /// deflection under the chain's loads) set its steps, held to 1e-10 of √kg·m/s, at
    /// thousands of rad/s. None without base modes.
    fn slow_tolerance_scales(&self) -> Option<Vec<f64>> {
        if self.modes() == 0 {
            return None;
        }
        let mut s = vec![1.0; Coupled::positions(self) + self.speeds()];
        let first = Coupled::positions(self) + self.hub_dof();
        for (si, w) in s[first..].iter_mut().zip(&self.base.omega[..self.modes()]) {
            *si = w.max(1.0);
        }
        Some(s)
    }
    fn invariant_coordinates(&self) -> Vec<usize> {
        if self.hub_dof() < 6 {
            return Vec::new();
        }
        // The hub's velocity and rate, the first six speeds.
        let np = self.positions();
        (np..np + 6).collect()
    }
    fn jacobian(
        &self,
        y: &[f64],
        free: &[bool],
        captured: &[bool],
        jac: &mut faer::Mat<f64>,
    ) -> bool {
        self.stiff_jacobian(y, free, captured, jac);
        true
    }
    fn impact(&self, y: &[f64], free_after: &[bool]) -> (Vec<f64>, Impulses) {
        let u = Coupled::impact(self, y, free_after);
        let hinges = self.hinge_impulses(y, &u);
        let (p0, h0) = self.chain_momentum(y);
        let mut y_after = y.to_vec();
        y_after[Coupled::positions(self)..].copy_from_slice(&u);
        let (p1, h1) = self.chain_momentum(&y_after);
        let base = Some(((p0 - p1).0, (h0 - h1).0));
        (
            u,
            Impulses {
                hinges,
                base,
                hub_rate: [0.0; 3],
            },
        )
    }
    fn energy(&self, y: &[f64], captured: &[bool]) -> f64 {
        Coupled::kinetic_energy(self, y)
            + self.spring_energy(y)
            + self.elastic_energy(y)
            + self.latch_energy(y, captured)
    }
    fn kinetic_energy(&self, y: &[f64]) -> f64 {
        Coupled::kinetic_energy(self, y)
    }
    fn load_magnitudes(&self, y: &[f64], free: &[bool], captured: &[bool]) -> Vec<f64> {
        let (ev, sol) = self.solve_captured_fast(y, free, captured);
        let mut out: Vec<f64> = self
            .latch_moments(y, captured)
            .iter()
            .map(|m| m.abs())
            .collect();
        for l in self.beam_root_loads(y, &ev, &sol) {
            out.push(l[..3].iter().map(|x| x * x).sum::<f64>().sqrt());
            out.push(l[3..].iter().map(|x| x * x).sum::<f64>().sqrt());
        }
        // Then every hinge's in-plane reaction force and transmitted moment (the samples'
        // `force` and `moment`), and the hub's excursion: |rotation vector| and |position|
        // (the layout of [`TrackedLoads`]).
        let hinges = self.hinge_loads(y, &ev, &sol);
        out.extend(hinges.iter().map(|(f, _)| f.get(0).hypot(f.get(1))));
        out.extend(hinges.iter().map(|(_, m)| m.get(2).abs()));
        let v = self.view(y);
        let norm = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        out.push(norm(attitude::rotation_vector(v.quat).0));
        out.push(norm(v.r.0));
        out
    }
    fn sample(&self, t: f64, y: &[f64], free: &[bool], captured: &[bool]) -> Sample {
        let (ev, sol) = self.solve_captured(y, free, captured);
        let loads = self.hinge_loads(y, &ev, &sol);
        let s = self.view(y);
        let cfg = self.chain.configuration(s.alpha);
        Sample {
            t,
            alpha: s.alpha.to_vec(),
            rate: s.alpha_dot.to_vec(),
            hub: [0.0; 3],
            hub_rate: [0.0; 3],
            force: loads.iter().map(|(f, _)| [f.get(0), f.get(1)]).collect(),
            moment: loads.iter().map(|(_, m)| m.get(2)).collect(),
            kinetic: Coupled::kinetic_energy(self, y),
            spring: self.spring_energy(y),
            hinges: cfg.hinges,
            body: Some(Box::new(self.body_sample(y, &ev, &sol))),
            latch_moment: self.latch_moments(y, captured),
            latch_energy: self.latch_energy(y, captured),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deploy::base::BaseKind;
    use crate::deploy::Deployment;
    use crate::scenario::Scenario;

    /// The seed's spacecraft with 12 panels and 8 base modes, free hub.
    fn twelve_panels(synchronisation: Synchronisation) -> Coupled {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/seed.toml");
        let src = std::fs::read_to_string(path)
            .unwrap()
            .replace("panels = 3", "panels = 12");
        let sc = Scenario::from_toml_str(&src, path).unwrap();
        let d = Deployment {
            base: BaseKind::Flexible { modes: Some(8) },
            synchronisation,
            ..sc.deployment.clone().unwrap()
        };
        d.coupled(&sc.structure).unwrap()
    }

    /// The tip-to-root recursion of [`Coupled::hinge_loads`] equals the definition
    ///   F_l = Σ_{i≥l} m_i a_i,   M_l = Σ_{i≥l} (c_i − h_l) × m_i a_i + I_i ε_i + ω_i × I_i ω_i
    /// summed directly, on 12 panels at an arbitrary turning, deforming state.
    #[test]
    fn hinge_loads_by_recursion_equal_the_outboard_sums() {
        let c = twelve_panels(Synchronisation::None);
        let mut y = c.initial_state();
        let np = c.positions();
        for (i, v) in y.iter_mut().enumerate() {
            *v += if i < np { 0.2 } else { 0.1 } * ((i as f64) * 2.3).sin();
        }
        let q = &mut y[3..7];
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.iter_mut().for_each(|x| *x /= norm);
        let free = vec![true; c.panels()];
        let (ev, sol) = c.solve(&y, &free);
        let kin = c.panel_accelerations(&y, &ev, &sol);
        let loads = c.hinge_loads(&y, &ev, &sol);
        let n = c.panels();
        let mut scale = 0.0_f64;
        let direct: Vec<(Vec3, Vec3)> = (0..n)
            .map(|l| {
                let h = ev.hinge_points[l];
                let (mut f, mut m) = (Vec3::ZERO, Vec3::ZERO);
                for (i, [a, w, e]) in kin.iter().enumerate().skip(l) {
                    let fi = *a * c.chain.panels[i].mass;
                    let ii = c.panel_tensor(i, ev.phi[i]);
                    f = f + fi;
                    m = m + (ev.centres[i] - h).cross(fi) + ii.apply(*e) + w.cross(ii.apply(*w));
                }
                scale = scale.max(f.dot(f).sqrt()).max(m.dot(m).sqrt());
                (f, m)
            })
            .collect();
        for (l, ((f, m), (fd, md))) in loads.iter().zip(&direct).enumerate() {
            let err = (*f - *fd).dot(*f - *fd).sqrt() + (*m - *md).dot(*m - *md).sqrt();
            assert!(err <= 1e-12 * scale, "hinge {l}: {err} against {scale}");
        }
    }

    /// The ideal cable's ties ([`Coupled::cable_ties`]): the Jacobian by differences takes
    /// one column per tie, J P. On the cable's tangent space T (α − α(0) and α̇ along
    /// r = (1, 2, 2, …)) it equals the Jacobian of one column per component, and both equal
    /// f's directional derivative by central differences (the independent truth) to 1e-6;
    /// every column of J P lies in T (its α and α̇ rows along r), and the other tied
    /// columns are zero. 12 panels, free hub, 8 base modes, at a deformed, moving state on
    /// the cable's manifold.
    #[test]
    fn the_cable_ties_jacobian_equals_the_full_one_on_the_cable_tangent_space() {
        use crate::ode::integrator::{OdeSystem, Tie};
        use crate::ode::rosenbrock::forward_jacobian;
        struct Sys<'a>(&'a Coupled, bool);
        impl OdeSystem for Sys<'_> {
            fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
                let n = self.0.panels();
                self.0.rhs_captured(y, &vec![true; n], &vec![false; n], dy);
            }
            fn kinematic(&self) -> usize {
                self.0.kinematic_positions()
            }
            fn rhs_kinematic(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
                self.0.hub_kinematics(y, dy);
            }
            fn speed_offset(&self) -> Option<usize> {
                Some(Coupled::positions(self.0))
            }
            fn rhs_speeds(&self, _t: f64, y: &[f64], changes: &[Change], out: &mut [Vec<f64>]) {
                let n = self.0.panels();
                self.0
                    .rhs_captured_speeds(y, &vec![true; n], &vec![false; n], changes, out);
            }
            fn ties(&self) -> Vec<Tie> {
                if self.1 {
                    self.0.cable_ties(&vec![true; self.0.panels()])
                } else {
                    Vec::new()
                }
            }
        }
        let c = twelve_panels(Synchronisation::IdealCable);
        let (np, n, nb) = (Coupled::positions(&c), c.panels(), c.rate_offset());
        let (a0, s0) = (c.alpha_offset(), np + nb);
        let r: Vec<f64> = (0..n).map(|i| if i == 0 { 1.0 } else { 2.0 }).collect();
        let wave = |i: usize, k: f64| (i as f64 * k).sin();
        // On the manifold: α = α(0) + 0.3 r, α̇ = 0.05 r; everything else deformed and moving.
        let mut y = c.initial_state();
        for i in 0..y.len() {
            if (a0..a0 + n).contains(&i) {
                y[i] += 0.3 * r[i - a0];
            } else if (s0..s0 + n).contains(&i) {
                y[i] = 0.05 * r[i - s0];
            } else {
                y[i] += 0.01 * wave(i, 2.3);
            }
        }
        let q = &mut y[3..7];
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.iter_mut().for_each(|x| *x /= norm);
        let mut f0 = vec![0.0; y.len()];
        Sys(&c, false).rhs(0.0, &y, &mut f0);
        let full = forward_jacobian(&Sys(&c, false), 0.0, &y, &f0);
        let tied = forward_jacobian(&Sys(&c, true), 0.0, &y, &f0);
        let len = y.len();
        for trial in 0..3 {
            // A tangent vector: any base and hub components, the chain's along r.
            let t: Vec<f64> = (0..len)
                .map(|i| {
                    let x = wave(i + 7 * trial, 1.7);
                    if (a0..a0 + n).contains(&i) {
                        r[i - a0] * wave(trial, 3.1)
                    } else if (s0..s0 + n).contains(&i) {
                        r[i - s0] * wave(trial + 5, 0.9)
                    } else {
                        x
                    }
                })
                .collect();
            let apply = |j: &faer::Mat<f64>| -> Vec<f64> {
                (0..len)
                    .map(|i| (0..len).map(|k| j[(i, k)] * t[k]).sum())
                    .collect()
            };
            let e = 1e-6;
            let (mut up, mut down) = (vec![0.0; len], vec![0.0; len]);
            let shifted =
                |s: f64| -> Vec<f64> { y.iter().zip(&t).map(|(a, b)| a + s * b).collect() };
            Sys(&c, false).rhs(0.0, &shifted(e), &mut up);
            Sys(&c, false).rhs(0.0, &shifted(-e), &mut down);
            let truth: Vec<f64> = up
                .iter()
                .zip(&down)
                .map(|(a, b)| (a - b) / (2.0 * e))
                .collect();
            // Each block of rows against its own largest entry (the base's kHz accelerations
            // would hide the chain's): the positions' rates, the base speeds' and the
            // opening rates'.
            let blocks = [0..np, np..s0, s0..len];
            for (what, j) in [("full", &full), ("tied", &tied)] {
                let jt = apply(j);
                for (i, (a, b)) in jt.iter().zip(&truth).enumerate() {
                    let rows = blocks
                        .iter()
                        .find(|b| b.contains(&i))
                        .map_or(0..len, Clone::clone);
                    let scale = truth[rows].iter().fold(0.0_f64, |m, x| m.max(x.abs()));
                    assert!(
                        (a - b).abs() <= 1e-6 * scale,
                        "{what}, trial {trial}, row {i}: {a} vs {b}"
                    );
                }
            }
        }
        for col in 0..len {
            for first in [a0, s0] {
                let rep = tied[(first, col)];
                let scale = (0..n).fold(0.0_f64, |m, i| m.max(tied[(first + i, col)].abs()));
                for i in 1..n {
                    let x = tied[(first + i, col)];
                    assert!(
                        (x - r[i] * rep).abs() <= 1e-9 * scale,
                        "column {col} leaves T"
                    );
                    if col == first + i {
                        assert!((0..len).all(|row| tied[(row, col)] == 0.0));
                    }
                }
            }
        }
    }
}
