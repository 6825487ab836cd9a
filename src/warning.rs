//! Typed warnings of a run. The physics modules ([`crate::deploy`],
//! [`crate::simulation`]) produce them; the output layer only renders them, through their
//! [`Display`](std::fmt::Display) text.

use std::fmt;

/// Something a run wants the user to know: a result outside the model's assumptions or a run
/// that stopped before its end.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// A panel swung back below its initial angle: the real array would collide there.
    SwingBack {
        /// Hinge (1-based).
        hinge: usize,
        /// First time below the initial angle, s.
        first_time: f64,
        /// Smallest angle reached, rad.
        min_angle: f64,
        /// The hinge's initial angle, rad.
        initial_angle: f64,
    },
    /// The deployment's integration produced a non-finite state at `t` (s) and stopped there.
    Diverged {
        /// Time of the last finite state, s.
        t: f64,
    },
    /// The deployment took its step limit and stopped at `t` (s).
    StepLimit {
        /// Time the run stopped, s.
        t: f64,
    },
    /// Hinges that had not latched when the deployment ended at `t` (s).
    NotLatched {
        /// Time the run ended, s.
        t: f64,
        /// Per unlatched hinge: (hinge, 1-based; final angle, rad; latch angle, rad).
        hinges: Vec<(usize, f64, f64)>,
    },
    /// No hand-over and no response, because the array did not latch completely.
    NoResponse,
    /// The response's output rate is below 2.5 times its highest kept frequency: its samples
    /// cannot show the ringing, so the figures draw the solution's min/max envelope (the peaks
    /// are the solution's in any case).
    Aliasing {
        /// `response.output_rate`, Hz.
        output_rate: f64,
        /// The highest kept elastic frequency, Hz.
        highest_hz: f64,
    },
    /// The deployment's output rate is below 2.5 times the fastest vibration its steps resolve
    /// (the base's highest kept mode or the captured array's fastest mode on its latch
    /// springs): deployment.csv's samples alias that ringing, so the deployment's figures draw
    /// the solution's min/max envelope.
    DeploymentAliasing {
        /// `deployment.output_rate`, Hz.
        output_rate: f64,
        /// The fastest resolved vibration, Hz.
        fastest_hz: f64,
    },
    /// The response keeps every elastic mode (no `[response] modes`) up to a frequency whose
    /// exact peaks need a long closed-form search: its grid resolves the highest kept mode
    /// over the whole duration.
    CostlyPeaks {
        /// Elastic modes kept.
        kept: usize,
        /// The highest kept elastic frequency, Hz.
        highest_hz: f64,
        /// The search's grid points per pass.
        knots: usize,
    },
    /// More elastic modes requested than the model has: all are kept.
    ModesClamped {
        /// `response.modes`.
        requested: usize,
        /// Elastic modes of the model.
        available: usize,
    },
    /// Simultaneous latching without a cable locked the array bent at `t`.
    LocksBent {
        /// Time of the lock, s.
        t: f64,
        /// The hinge farthest from its latch angle (1-based).
        hinge: usize,
        /// Its latch angle minus its angle, rad.
        rad: f64,
    },
    /// `[deployment] base_modes` was 0 or above the base's count: clamped.
    BaseModesClamped {
        /// `deployment.base_modes`.
        requested: usize,
        /// Modes kept.
        kept: usize,
        /// The base's hub-fixed modes.
        available: usize,
    },
    /// Rigid latches on an elastic base: the latch outcome with half of the kept base modes
    /// (the latch with the largest change of the base impulse).
    RigidLatchTruncation(crate::deploy::HalfModes),
    /// The automatic integrator's accuracy estimate stayed above the accuracy asked for
    /// after its last refinement.
    AccuracyNotReached(crate::deploy::auto::Accuracy),
    /// The automatic integrator accepted steps that gained mechanical energy even with the
    /// exact Jacobian and the step halved eight times.
    EnergyGained {
        /// How many.
        steps: usize,
    },
    /// Compliant latches still moving when the settling's cap, or the deployment's end time,
    /// ended the deployment.
    NotSettled {
        /// The end of the deployment, s.
        t: f64,
        /// The largest captured-hinge rate in the last window over the largest at a capture
        /// (None with a `settle_time`, which is not watched).
        ratio: Option<f64>,
        /// The settling's tolerance on that fraction.
        tolerance: f64,
        /// `end_time` ended it, not the settling's cap.
        by_end_time: bool,
    },
    /// The array locked away from the straight wing; the hand-over uses the straight wing.
    AngleMismatch {
        /// Largest hinge-angle mismatch, rad.
        rad: f64,
    },
    /// A tip's peak elastic deflection is beyond the small-deformation assumption.
    LargeDeflection {
        /// The channel's label.
        label: String,
        /// Peak elastic deflection, m.
        peak_m: f64,
        /// The component's length, m.
        length_m: f64,
        /// The threshold, as a fraction of the length.
        fraction: f64,
    },
    /// A note of the hand-over, in plain language.
    HandoverNote(String),
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::SwingBack {
                hinge,
                first_time,
                min_angle,
                initial_angle,
            } => swing_back(f, *hinge, *first_time, *min_angle, *initial_angle),
            Self::Diverged { t } => write!(
                f,
                "the integration diverged (non-finite state) at t = {t} s and was stopped there"
            ),
            Self::StepLimit { t } => write!(
                f,
                "step limit reached at t = {t} s: the integration was stopped there after its \
                 step limit (a stiff or badly scaled deployment; the results up to t are valid)"
            ),
            Self::NotLatched { t, hinges } => {
                let list: Vec<String> = hinges
                    .iter()
                    .map(|(h, a, latch)| format!("hinge {h} at {a:.6} rad (latch {latch:.6} rad)"))
                    .collect();
                write!(
                    f,
                    "not all hinges latched by t = {t} s: {}",
                    list.join(", ")
                )
            }
            Self::NoResponse => f.write_str(NO_RESPONSE),
            Self::Aliasing {
                output_rate,
                highest_hz,
            } => aliasing(f, *output_rate, *highest_hz),
            Self::DeploymentAliasing {
                output_rate,
                fastest_hz,
            } => deployment_aliasing(f, *output_rate, *fastest_hz),
            Self::CostlyPeaks {
                kept,
                highest_hz,
                knots,
            } => costly_peaks(f, *kept, *highest_hz, *knots),
            Self::ModesClamped {
                requested,
                available,
            } => modes_clamped(f, *requested, *available),
            Self::NotSettled {
                t,
                ratio,
                tolerance,
                by_end_time,
            } => f.write_str(&not_settled(*t, *ratio, *tolerance, *by_end_time)),
            Self::LocksBent { t, hinge, rad } => write!(
                f,
                "LATCHING = \"simultaneous\" WITHOUT A CABLE LOCKS THE ARRAY BENT: at t = {t} s \
                 every hinge locked where it stood; hinge {hinge} is {rad:.6} rad ({:.1}°) short \
                 of its latch angle. Hinges tied by cables reach their latch angles together: \
                 use [deployment] synchronisation = \"cable\"",
                rad.to_degrees()
            ),
            Self::BaseModesClamped {
                requested,
                kept,
                available,
            } => write!(
                f,
                "deployment.base_modes = {requested} is outside 1…{available} (the base's \
                 hub-fixed modes): {kept} kept{}",
                if *requested == 0 {
                    " (a rigid base is base = \"rigid\")"
                } else {
                    ""
                }
            ),
            Self::RigidLatchTruncation(h) => write!(
                f,
                "rigid latch on an elastic base: the base impulse changes {:.1} % (force) and \
                 {:.1} % (moment), the rates after the latch {:.1} %, between {} and {} base \
                 modes: its loads depend on the truncation (a rigid latch on an elastic base has \
                 no continuum limit); use [deployment.latch] model = \"compliant\" for \
                 latch-up loads",
                100.0 * h.force_change,
                100.0 * h.moment_change,
                100.0 * h.rates_change,
                h.modes,
                h.kept
            ),
            Self::AccuracyNotReached(a) => accuracy_not_reached(f, a),
            Self::EnergyGained { steps } => write!(
                f,
                "{steps} step(s) of the automatic integrator gained mechanical energy even with \
                 the exact Jacobian and the step halved eight times (nothing in the model \
                 supplies energy): the results there are doubtful; compare with integrator = \
                 \"explicit\""
            ),
            Self::AngleMismatch { rad } => write!(
                f,
                "the array locked away from the straight wing (largest hinge-angle mismatch \
                 {rad:.3e} rad): the hand-over uses the straight wing"
            ),
            Self::LargeDeflection {
                label,
                peak_m,
                length_m,
                fraction,
            } => write!(
                f,
                "{label}: peak elastic deflection {peak_m:.6e} m is {:.1} % of the component's \
                 length {length_m} m: the linear (small-deformation) model is outside its \
                 assumption there (more than {} %)",
                100.0 * peak_m / length_m,
                100.0 * fraction
            ),
            Self::HandoverNote(note) => f.write_str(note),
        }
    }
}

/// [`Warning::SwingBack`]'s text.
fn swing_back(
    f: &mut fmt::Formatter<'_>,
    hinge: usize,
    first_time: f64,
    min_angle: f64,
    initial_angle: f64,
) -> fmt::Result {
    let into = if hinge == 1 {
        "the hub".to_string()
    } else {
        format!("panel {}", hinge - 1)
    };
    write!(
        f,
        "panel {hinge} swings back below its initial angle from t = {first_time:.6} s (minimum α_{hinge} = {min_angle:.6} rad, initial {initial_angle:.6} rad): the real array would collide with {into} there (no contact model)"
    )
}

/// [`Warning::NoResponse`]'s text.
const NO_RESPONSE: &str = "the array did not latch completely: no hand-over, no response";

/// [`Warning::ModesClamped`]'s text.
fn modes_clamped(f: &mut fmt::Formatter<'_>, requested: usize, available: usize) -> fmt::Result {
    write!(
        f,
        "response.modes = {requested} but the model has {available} elastic modes: all of them \
         are kept"
    )
}

/// [`Warning::CostlyPeaks`]'s text.
fn costly_peaks(
    f: &mut fmt::Formatter<'_>,
    kept: usize,
    highest_hz: f64,
    knots: usize,
) -> fmt::Result {
    write!(
        f,
        "the response keeps all {kept} elastic modes, the highest at {highest_hz:.1} Hz: its \
         exact peaks and stresses resolve them over the whole response ({:.1} million grid \
         points per pass, most of this run's time); `[response] modes` keeps only the lowest \
         ones where the others do not matter",
        knots as f64 / 1e6
    )
}

/// [`Warning::DeploymentAliasing`]'s text.
fn deployment_aliasing(
    f: &mut fmt::Formatter<'_>,
    output_rate: f64,
    fastest_hz: f64,
) -> fmt::Result {
    write!(
        f,
        "deployment.output_rate = {output_rate} Hz is below 2.5 times the fastest vibration the \
         run resolves ({fastest_hz:.4} Hz): deployment.csv's samples alias it; the deployment's \
         figures draw the solution's min/max envelope and every peak is the solution's"
    )
}

/// [`Warning::Aliasing`]'s text.
fn aliasing(f: &mut fmt::Formatter<'_>, output_rate: f64, highest_hz: f64) -> fmt::Result {
    write!(
        f,
        "response.output_rate = {output_rate} Hz is below 2.5 times the highest kept mode \
         ({highest_hz:.4} Hz): the samples (response.csv) alias its ringing; the figures draw \
         the solution's min/max envelope and every peak is the solution's"
    )
}

/// [`Warning::AccuracyNotReached`]'s text.
fn accuracy_not_reached(
    f: &mut fmt::Formatter<'_>,
    a: &crate::deploy::auto::Accuracy,
) -> fmt::Result {
    if a.events_differ {
        write!(
            f,
            "accuracy not reached: after {} runs, each refined twofold, the last two still \
             differ in their latch events (count or order); the results are the finest run's, \
             with no estimate (a deployment that is sensitive to its model there: compare runs \
             with [deployment] base_modes or integrator = \"explicit\")",
            a.runs
        )
    } else {
        write!(
            f,
            "accuracy not reached: [deployment] accuracy = {:e} asked, {:.2e} estimated after \
             {} runs, each refined twofold (the last two differ by that much: times {:.1e}, \
             rates {:.1e}, latch moments {:.1e})",
            a.asked, a.estimate, a.runs, a.times, a.rates, a.latch_moments
        )
    }
}

/// [`Warning::NotSettled`]'s text.
fn not_settled(t: f64, ratio: Option<f64>, tolerance: f64, by_end_time: bool) -> String {
    let left = ratio.map_or(String::new(), |r| {
        format!(
            ": the hinge rates were still {:.2} % of the largest rate at a capture (settled \
             means below {:.2} %)",
            100.0 * r,
            100.0 * tolerance
        )
    });
    if by_end_time {
        format!(
            "the deployment's end_time, t = {t} s, came before the latches had settled{left}; \
             the hand-over starts from there. Raise [deployment] end_time"
        )
    } else {
        format!(
            "the latches had not settled when the deployment handed over at t = {t} s{left}; \
             the latch springs' remaining motion is not in the response. Add latch damping or \
             set [deployment.latch] settle_time"
        )
    }
}
