//! The last check before anything is reported: every number a command prints or writes is
//! finite. A NaN or an infinity is never printed as a result; it is an error naming the
//! quantity (the scenario's ranges make this unreachable for accepted input, so reaching it
//! means a bug or an unforeseen combination, and the user is told which quantity failed).

use crate::deploy::DeploymentResult;
use crate::ritz::ModalAnalysis;
use crate::simulation::Simulation;

/// A reported quantity that is not finite.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the result is not finite: {quantity} = {value}")]
pub struct NonFinite {
    /// Which quantity (e.g. "mode 7 ω [rad/s]").
    pub quantity: String,
    /// Its value (NaN or ±∞).
    pub value: f64,
}

/// The first non-finite value of `values`, named by `name(index)`.
fn check(
    values: impl IntoIterator<Item = f64>,
    name: impl Fn(usize) -> String,
) -> Result<(), NonFinite> {
    match values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        None => Ok(()),
        Some((i, value)) => Err(NonFinite {
            quantity: name(i),
            value,
        }),
    }
}

/// Frequencies, shapes, energy shares and effective masses.
pub fn check_modes(m: &ModalAnalysis) -> Result<(), NonFinite> {
    for mode in &m.modes {
        let k = mode.number;
        check([mode.omega_rad_s], |_| format!("mode {k} ω [rad/s]"))?;
        check(mode.shape.iter().copied(), |i| {
            format!("mode {k} shape coefficient {}", i + 1)
        })?;
        check(mode.strain_energy_share.iter().map(|s| s.1), |i| {
            format!(
                "mode {k} strain-energy share of {}",
                mode.strain_energy_share[i].0
            )
        })?;
        check(mode.effective_mass.into_iter().flatten(), |i| {
            format!("mode {k} effective mass {}", i + 1)
        })?;
    }
    for (j, h) in m.hub_fixed.iter().enumerate() {
        check(
            std::iter::once(h.omega_rad_s).chain(h.effective_mass),
            |_| format!("hub-fixed mode {} ω or effective mass", j + 1),
        )?;
    }
    Ok(())
}

/// Every sample and latch event of a deployment.
pub fn check_deployment(r: &DeploymentResult) -> Result<(), NonFinite> {
    for s in &r.samples {
        let t = s.t;
        let values = std::iter::once(s.t)
            .chain(s.alpha.iter().copied())
            .chain(s.rate.iter().copied())
            .chain(s.hub)
            .chain(s.hub_rate)
            .chain(s.force.iter().flatten().copied())
            .chain(s.moment.iter().copied())
            .chain([s.kinetic, s.spring]);
        check(values, |_| format!("deployment sample at t = {t} s"))?;
    }
    for e in &r.latches {
        let values = std::iter::once(e.time)
            .chain(e.rates_after.iter().copied())
            .chain([e.energy_before, e.energy_after])
            .chain(e.impulses.iter().flat_map(|(p, m)| [p[0], p[1], *m]));
        check(values, |_| {
            format!("latch of hinge {} at t = {} s", e.hinge, e.time)
        })?;
    }
    Ok(())
}

/// Modes, deployment, hand-over and response history.
pub fn check_simulation(sim: &Simulation) -> Result<(), NonFinite> {
    check_modes(&sim.modes)?;
    check_deployment(&sim.deployment)?;
    if let Some(r) = &sim.response {
        let h = &r.handover;
        check(
            [h.energy_before, h.energy_after]
                .into_iter()
                .chain(h.momentum_after.linear.0)
                .chain(h.momentum_after.angular.0)
                .chain(h.modal_velocity.iter().copied()),
            |_| "hand-over energy, momentum or modal velocity".to_string(),
        )?;
        let hist = &r.history;
        for (k, t) in hist.times.iter().enumerate() {
            check(
                std::iter::once(*t)
                    .chain((0..hist.values.ncols()).map(|j| hist.values[(k, j)]))
                    .chain((0..hist.modal.ncols()).map(|j| hist.modal[(k, j)])),
                |_| format!("response sample at t = {t} s"),
            )?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_the_first_bad_value() {
        assert!(check([1.0, 2.0], |_| "x".into()).is_ok());
        let e = check([1.0, f64::NAN, f64::INFINITY], |i| format!("x{i}")).unwrap_err();
        assert_eq!(e.quantity, "x1");
        assert!(e.value.is_nan());
    }
}
