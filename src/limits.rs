//! The accepted range of every physical quantity a model takes (docs/scenario.md lists
//! them per scenario key). The domain constructors (`structure`, `deploy`, `response`) are
//! the only places that check them.
//!
//! The ranges are physical (no spacecraft has a 1e308 kg hub) and keep the arithmetic of the
//! Ritz assembly, the eigen-solve and the deployment integration finite and well inside the
//! range of `f64`: products such as E·h³ or m·L² of any two accepted values stay far from
//! overflow and underflow. A value outside its range is refused with its location; the
//! bounds are inclusive unless `open` says otherwise.

/// An accepted interval of a scalar key, with its unit for messages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// Smallest accepted value.
    pub lo: f64,
    /// Largest accepted value.
    pub hi: f64,
    /// The lower bound itself is refused.
    pub open_lo: bool,
    /// The upper bound itself is refused.
    pub open_hi: bool,
    /// Unit for messages.
    pub unit: &'static str,
}

const fn closed(lo: f64, hi: f64, unit: &'static str) -> Limit {
    Limit {
        lo,
        hi,
        open_lo: false,
        open_hi: false,
        unit,
    }
}

const fn open(lo: f64, hi: f64, unit: &'static str) -> Limit {
    Limit {
        lo,
        hi,
        open_lo: true,
        open_hi: true,
        unit,
    }
}

const fn closed_open(lo: f64, hi: f64, unit: &'static str) -> Limit {
    Limit {
        lo,
        hi,
        open_lo: false,
        open_hi: true,
        unit,
    }
}

impl Limit {
    /// Whether `v` is finite and inside the interval.
    pub fn contains(&self, v: f64) -> bool {
        let below_hi = if self.open_hi {
            v < self.hi
        } else {
            v <= self.hi
        };
        let above_lo = if self.open_lo {
            v > self.lo
        } else {
            v >= self.lo
        };
        v.is_finite() && below_hi && above_lo
    }

    /// Whether every value inside is positive (for messages: "must be a positive …").
    pub fn positive(&self) -> bool {
        self.lo > 0.0 || (self.open_lo && self.lo == 0.0)
    }

    /// The message for a refused value: "must be a positive finite number in [1e-3, 1e4] m,
    /// got -1e0".
    pub fn refusal(&self, v: f64) -> String {
        format!(
            "must be a {}finite number in {}, got {v:e}",
            if self.positive() { "positive " } else { "" },
            self.describe()
        )
    }

    /// "[1e-3, 1e4] m", for messages and docs.
    pub fn describe(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!(
            "{}{}, {}{}{unit}",
            if self.open_lo { "(" } else { "[" },
            fmt_bound(self.lo),
            fmt_bound(self.hi),
            if self.open_hi { ")" } else { "]" }
        )
    }
}

fn fmt_bound(v: f64) -> String {
    if v == 0.0 || (1e-2..1e4).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Allowable stresses (`[materials.X] allowable_stress`).
pub const ALLOWABLE_STRESS: Limit = closed(1e3, 1e13, "Pa");
/// Factors of safety (`[materials.X] factor_of_safety`): below 1 is no safety.
pub const FACTOR_OF_SAFETY: Limit = closed(1.0, 100.0, "");
/// Transverse-shear factors of a general section (τ_max = k V/A; 1 for a uniform shear, 1.5
/// for a rectangle, 2 for a thin tube).
pub const SHEAR_FACTOR: Limit = closed(1.0, 10.0, "");
/// A latch's allowable moment (`[deployment.latch] moment_allowable`).
pub const LATCH_MOMENT_ALLOWABLE: Limit = closed(1e-6, 1e12, "N·m");

/// Lengths of members: beam length, plate length and width, hub cylinder diameter and length.
pub const LENGTH: Limit = closed(1e-3, 1e4, "m");
/// Cross-section sizes: tube diameter and wall, plate thickness, hub wall.
pub const SECTION: Limit = closed(1e-6, 1e2, "m");
/// A coordinate (root and attachment points, centres of mass, offsets), per component.
pub const COORDINATE: Limit = closed(-1e4, 1e4, "m");
/// Distance of an attachment from its parent beam's root.
pub const STATION: Limit = closed(0.0, 1e4, "m");
/// Young's and shear moduli.
pub const MODULUS: Limit = closed(1e3, 1e13, "Pa");
/// Material density.
pub const DENSITY: Limit = closed(1e-3, 1e5, "kg/m³");
/// Poisson's ratio: (−1, 0.5), both ends excluded.
pub const POISSON: Limit = open(-1.0, 0.5, "");
/// Masses: hub, lumped masses, panels.
pub const MASS: Limit = closed(1e-6, 1e9, "kg");
/// Any entry of an inertia tensor, in magnitude (kg·m²); principal moments are also checked
/// to be positive and to satisfy the triangle inequality.
pub const INERTIA: Limit = closed(-1e12, 1e12, "kg·m²");
/// Smallest accepted principal moment of a body's inertia tensor, kg·m².
pub const MIN_PRINCIPAL_INERTIA: f64 = 1e-12;
/// Cross-section area.
pub const AREA: Limit = closed(1e-12, 1e2, "m²");
/// Second moments of area, torsion constant, polar moment.
pub const SECOND_MOMENT: Limit = closed(1e-24, 1e2, "m⁴");
/// Plate areal density ρh.
pub const AREAL_DENSITY: Limit = closed(1e-6, 1e5, "kg/m²");
/// Plate bending stiffness D.
pub const BENDING_STIFFNESS: Limit = closed(1e-6, 1e12, "N·m");
/// Hinge spring stiffness.
pub const HINGE_STIFFNESS: Limit = closed(0.0, 1e6, "N·m/rad");
/// Hinge viscous damping.
pub const HINGE_DAMPING: Limit = closed(0.0, 1e6, "N·m·s/rad");
/// Hinge Coulomb friction moment.
pub const HINGE_FRICTION: Limit = closed(0.0, 1e5, "N·m");
/// Hinge angles given by the user (preload, reference, initial), rad.
pub const ANGLE: Limit = closed(
    -4.0 * std::f64::consts::PI,
    4.0 * std::f64::consts::PI,
    "rad",
);
/// Latch angle of a hinge: (0, π].
pub const LATCH_ANGLE: Limit = Limit {
    lo: 0.0,
    hi: std::f64::consts::PI,
    open_lo: true,
    open_hi: false,
    unit: "rad",
};
/// Torsional stiffness of a cable loop between neighbouring hinges.
pub const CABLE_STIFFNESS: Limit = Limit {
    lo: 0.0,
    hi: 1e9,
    open_lo: true,
    open_hi: false,
    unit: "N·m/rad",
};
/// Compliant latch stiffness.
pub const LATCH_STIFFNESS: Limit = Limit {
    lo: 0.0,
    hi: 1e12,
    open_lo: true,
    open_hi: false,
    unit: "N·m/rad",
};
/// Compliant latch damping.
pub const LATCH_DAMPING: Limit = closed(0.0, 1e9, "N·m·s/rad");
/// Initial hinge rate.
pub const RATE: Limit = closed(-100.0, 100.0, "rad/s");
/// Panel moment of inertia about its hinge-parallel centroidal axis.
pub const PANEL_INERTIA: Limit = closed(1e-9, 1e9, "kg·m²");
/// Length of one panel.
pub const PANEL_LENGTH: Limit = closed(1e-3, 1e4, "m");
/// Longest over shortest panel length.
pub const MAX_PANEL_LENGTH_RATIO: f64 = 100.0;
/// Most panels a deployment may have (a 100-panel chain runs in about a second).
pub const MAX_PANELS: usize = 100;
/// `[ritz] tolerance`: relative, on frequencies (rounding sets the floor).
pub const RITZ_TOLERANCE: Limit = closed(1e-10, 0.1, "");
/// `[ritz] max_dof`: the dense matrices of the largest model stay within memory.
pub const MAX_RITZ_DOF: usize = 4000;
/// `[ritz] modes`: most wanted elastic modes.
pub const MAX_RITZ_MODES: usize = 500;
/// Relative integration tolerance.
pub const TOLERANCE: Limit = closed(1e-14, 1e-3, "");
/// `[deployment] accuracy`: the automatic integrator's results accuracy (relative).
pub const ACCURACY: Limit = closed(1e-8, 0.1, "");
/// Deployment end time and response duration.
pub const DURATION: Limit = closed(1e-6, 1e6, "s");
/// Modal damping ratio of the response, [0, 1): an underdamped structure.
pub const DAMPING_RATIO: Limit = closed_open(0.0, 1.0, "");
/// `[export] frequency_range` of the frequency response.
pub const EXPORT_FREQUENCY: Limit = closed(1e-6, 1e7, "Hz");
/// `[export] frequency_points`: most log-spaced frequencies of the response.
pub const MAX_FREQUENCY_POINTS: usize = 100_000;
/// `[export] modes`: most kept elastic modes (the model's own count bounds it too).
pub const MAX_EXPORT_MODES: usize = MAX_RITZ_DOF;
/// `[[export.points]]`: most named points.
pub const MAX_EXPORT_POINTS: usize = 1000;
/// Output sample rates.
pub const OUTPUT_RATE: Limit = closed(1e-3, 1e5, "Hz");

/// Longest component or material name, characters.
pub const MAX_NAME: usize = 64;
/// Longest scenario title (`name` at the top level), characters.
pub const MAX_TITLE: usize = 200;

/// The rule for a component or material name: 1 to [`MAX_NAME`] characters from ASCII
/// letters, digits, space, `_`, `-` and `.`, starting with a letter or digit; `hub` is
/// reserved (it names the hub as a parent). Names become parts of file names and CSV
/// headers, so the rule keeps them inert there.
pub fn valid_name(name: &str) -> Result<(), String> {
    let n = name.chars().count();
    if n == 0 {
        return Err("a name must not be empty".into());
    }
    if n > MAX_NAME {
        return Err(format!("a name has at most {MAX_NAME} characters, got {n}"));
    }
    if let Some(c) = name
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, ' ' | '_' | '-' | '.')))
    {
        return Err(format!(
            "{c:?} is not allowed in a name (use ASCII letters, digits, space, '_', '-', '.')"
        ));
    }
    if !name.starts_with(|c: char| c.is_ascii_alphanumeric()) {
        return Err("a name must start with a letter or a digit".into());
    }
    if name == "hub" {
        return Err("\"hub\" is reserved (it names the hub as a parent)".into());
    }
    Ok(())
}

/// The rule for the scenario's title: free text of at most [`MAX_TITLE`] characters without
/// control characters.
pub fn valid_title(title: &str) -> Result<(), String> {
    valid_text("the title", title)
}

/// The title's rule for any free text a scenario gives that reaches a terminal or a report
/// (`what`: "the title", "a requirement's name"): at most [`MAX_TITLE`] characters, no
/// control characters (an escape sequence would reach stdout raw).
pub fn valid_text(what: &str, text: &str) -> Result<(), String> {
    let n = text.chars().count();
    if n > MAX_TITLE {
        return Err(format!(
            "{what} has at most {MAX_TITLE} characters, got {n}"
        ));
    }
    if text.chars().any(char::is_control) {
        return Err(format!("{what} must not contain control characters"));
    }
    Ok(())
}

/// Largest elastic deflection, as a fraction of the component's length, that the linear
/// (small-deformation) model is trusted with; above it a warning says so.
pub const SMALL_DEFLECTION_FRACTION: f64 = 0.1;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_and_specials() {
        assert!(LENGTH.contains(1.0));
        assert!(LENGTH.contains(1e-3));
        assert!(!LENGTH.contains(1e-4));
        assert!(!LENGTH.contains(f64::NAN));
        assert!(!LENGTH.contains(f64::INFINITY));
        assert!(!DURATION.contains(0.0));
        assert!(!DURATION.contains(-0.0));
        assert!(!OUTPUT_RATE.contains(5e-324));
        assert!(HINGE_DAMPING.contains(-0.0));
        assert!(!MASS.contains(5e-324));
        assert_eq!(LENGTH.describe(), "[1e-3, 1e4] m");
        assert_eq!(DURATION.describe(), "[1e-6, 1e6] s");
        assert_eq!(POISSON.describe(), "(-1, 0.5)");
        assert!(!POISSON.contains(0.5) && !POISSON.contains(-1.0));
        assert!(!DAMPING_RATIO.contains(1.0) && DAMPING_RATIO.contains(0.0));
    }

    #[test]
    fn hostile_names_are_refused() {
        for ok in ["mast", "tip mass", "star-tracker_2", "w.1", "A"] {
            assert!(valid_name(ok).is_ok(), "{ok}");
        }
        for bad in [
            "",
            "hub",
            "x/../../y",
            "..",
            ".hidden",
            "a,b",
            "<!--<script>",
            "a\0b",
            "a\nb",
            "wing\"",
            "ü",
            &"x".repeat(65),
        ] {
            assert!(valid_name(bad).is_err(), "{bad:?}");
        }
        assert!(valid_title("seed spacecraft (Borisov & Avramenko, table 2.1)").is_ok());
        assert!(valid_title("a\u{1b}[31m").is_err());
        assert!(valid_title(&"t".repeat(201)).is_err());
    }
}
