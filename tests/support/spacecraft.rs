//! Random valid spacecraft for the robustness suite and the benchmark set (issue 36): a
//! scenario text drawn from a seed, across the documented ranges of what a user brings —
//! a free or held hub; one to three beams (tubes of random diameter, wall, length and term
//! counts, on the hub or on one another, along random directions) with tip masses; a second
//! plate in the base now and then; the deploying wing of 1 to 8 panels of unequal lengths on
//! a beam or on the hub; hinge springs set for a deployment of 5 to 200 s, hinge damping and
//! friction zero or not; with or without a cable; rigid or compliant latches.
//!
//! Deterministic: ChaCha8 from the seed, and every number written with Rust's shortest
//! round-trip formatting, so a seed names one scenario on every machine.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// What the generator drew, for the checks (a summary of the text).
#[derive(Debug, Clone)]
pub struct Drawn {
    /// The scenario text.
    pub toml: String,
    /// A free hub.
    pub free_hub: bool,
}

struct Draw(ChaCha8Rng);

impl Draw {
    fn u(&mut self) -> f64 {
        self.0.random::<f64>()
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.u()
    }
    fn log(&mut self, a: f64, b: f64) -> f64 {
        (a.ln() + (b.ln() - a.ln()) * self.u()).exp()
    }
    fn int(&mut self, a: usize, b: usize) -> usize {
        a + ((b - a + 1) as f64 * self.u()).floor().min((b - a) as f64) as usize
    }
    fn coin(&mut self, p: f64) -> bool {
        self.u() < p
    }
    /// A unit vector: an axis (±x, ±y, ±z) half the time, otherwise random.
    fn direction(&mut self) -> [f64; 3] {
        if self.coin(0.5) {
            let mut v = [0.0; 3];
            v[self.int(0, 2)] = if self.coin(0.5) { 1.0 } else { -1.0 };
            return v;
        }
        loop {
            let v = [
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            ];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.2 && n <= 1.0 {
                return [v[0] / n, v[1] / n, v[2] / n];
            }
        }
    }
    /// A unit vector perpendicular to `a`.
    fn perpendicular(&mut self, a: [f64; 3]) -> [f64; 3] {
        loop {
            let v = self.direction();
            let d = dot(v, a);
            let w = [v[0] - d * a[0], v[1] - d * a[1], v[2] - d * a[2]];
            let n = dot(w, w).sqrt();
            if n > 0.3 {
                return [w[0] / n, w[1] / n, w[2] / n];
            }
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn v3(v: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

/// A beam of the drawn base.
struct Beam {
    axis: [f64; 3],
    length: f64,
}

/// The spacecraft of `seed`.
pub fn spacecraft(seed: u64) -> Drawn {
    let mut d = Draw(ChaCha8Rng::seed_from_u64(seed));
    let mut t = String::new();
    let free_hub = d.coin(0.6);
    let _ = writeln!(
        t,
        "name = \"random spacecraft {seed}\"\nformat_version = 1\n"
    );
    // The hub: a box of 0.5 to 3 m sides and 50 kg to 5 t.
    let hub_mass = d.log(50.0, 5000.0);
    let sides = [d.range(0.5, 3.0), d.range(0.5, 3.0), d.range(0.5, 3.0)];
    let inertia = [
        hub_mass * (sides[1].powi(2) + sides[2].powi(2)) / 12.0,
        hub_mass * (sides[0].powi(2) + sides[2].powi(2)) / 12.0,
        hub_mass * (sides[0].powi(2) + sides[1].powi(2)) / 12.0,
    ];
    let _ = writeln!(
        t,
        "[hub]\nmotion = \"{}\"\nmass = {:?}\ninertia = {}\ncenter_of_mass = [0.0, 0.0, 0.0]\n",
        if free_hub { "free" } else { "fixed" },
        hub_mass,
        v3(inertia)
    );
    let materials = [
        ("aluminium", 70e9, 0.33, 2700.0),
        ("cfrp", 120e9, 0.3, 1600.0),
        ("steel", 200e9, 0.3, 7850.0),
    ];
    for (name, e, nu, rho) in materials {
        let _ = writeln!(
            t,
            "[materials.{name}]\nyoungs_modulus = {e:?}\npoisson_ratio = {nu:?}\ndensity = {rho:?}\n"
        );
    }
    // One to three beams: the first on the hub, each next on the hub or a previous beam.
    let nbeams = d.int(1, 3);
    let mut beams: Vec<Beam> = Vec::new();
    for i in 0..nbeams {
        let length = d.log(1.0, 15.0);
        let od = (length * d.log(0.005, 0.08)).clamp(0.02, 1.5);
        let wall = od * d.range(0.01, 0.1);
        let material = materials[d.int(0, 2)].0;
        let parent = if i == 0 || d.coin(0.3) {
            None
        } else {
            Some(d.int(0, i - 1))
        };
        let axis = match parent {
            Some(p) if d.coin(0.7) => d.perpendicular(beams[p].axis),
            _ => d.direction(),
        };
        let _ = writeln!(t, "[[beams]]\nname = \"beam{i}\"");
        match parent {
            None => {
                // On the hub's face the axis leaves from.
                let root = [
                    axis[0] * sides[0] / 2.0,
                    axis[1] * sides[1] / 2.0,
                    axis[2] * sides[2] / 2.0,
                ];
                let _ = writeln!(t, "parent = \"hub\"\nroot = {}", v3(root));
            }
            Some(p) => {
                let station = if d.coin(0.6) {
                    beams[p].length
                } else {
                    beams[p].length * d.range(0.3, 1.0)
                };
                let _ = writeln!(t, "parent = \"beam{p}\"\nstation = {station:?}");
            }
        }
        let _ = writeln!(
            t,
            "axis = {}\nlength = {length:?}\nmaterial = \"{material}\"\nsection = {{ tube = {{ outer_diameter = {od:?}, wall = {wall:?} }} }}\nterms = {{ bending = {}, torsion = {}, axial = {} }}\n",
            v3(axis),
            d.int(2, 12),
            d.int(1, 6),
            d.int(1, 8)
        );
        if d.coin(0.4) {
            let m = d.log(0.5, 50.0);
            let r = d.range(0.05, 0.3);
            let _ = writeln!(
                t,
                "[[masses]]\nname = \"tip{i}\"\nparent = \"beam{i}\"\nstation = {length:?}\nmass = {m:?}\ninertia = {}\n",
                v3([0.4 * m * r * r; 3])
            );
        }
        beams.push(Beam { axis, length });
    }
    // A second plate in the base now and then (an antenna, a radiator).
    if d.coin(0.25) {
        let b = d.int(0, nbeams - 1);
        let la = d.perpendicular(beams[b].axis);
        let normal = cross(la, beams[b].axis);
        let _ = writeln!(
            t,
            "[[plates]]\nname = \"panel\"\nparent = \"beam{b}\"\nstation = {:?}\nlength_axis = {}\nnormal = {}\nlength = {:?}\nwidth = {:?}\nareal_density = {:?}\nbending_stiffness = {:?}\npoisson_ratio = 0.3\nterms = {{ length = {}, width = {} }}\n",
            beams[b].length * d.range(0.5, 1.0),
            v3(la),
            v3(normal),
            d.range(0.5, 3.0),
            d.range(0.5, 2.0),
            d.log(1.0, 10.0),
            d.log(1e2, 1e5),
            d.int(3, 6),
            d.int(2, 4)
        );
    }
    // The wing: 1 to 8 panels, each 0.5 to 4 m, within a factor 3 of the first.
    let panels = d.int(1, 8);
    let first = d.range(0.5, 4.0);
    let lengths: Vec<f64> = (0..panels)
        .map(|i| {
            if i == 0 {
                first
            } else {
                (first * d.log(1.0 / 3.0, 3.0)).clamp(0.5, 4.0)
            }
        })
        .collect();
    let wing_length: f64 = lengths.iter().sum();
    let width = d.range(0.5, 4.0);
    let areal = d.log(0.5, 10.0);
    let wing_mass = areal * width * wing_length;
    let on_hub = d.coin(0.2);
    let _ = writeln!(t, "[[plates]]\nname = \"wing\"");
    let (la, normal) = if on_hub {
        let la = d.direction();
        let root = [
            la[0] * sides[0] / 2.0,
            la[1] * sides[1] / 2.0,
            la[2] * sides[2] / 2.0,
        ];
        let _ = writeln!(t, "parent = \"hub\"\nroot = {}", v3(root));
        (la, d.perpendicular(la))
    } else {
        let b = d.int(0, nbeams - 1);
        let station = if d.coin(0.7) {
            beams[b].length
        } else {
            beams[b].length * d.range(0.4, 1.0)
        };
        let _ = writeln!(t, "parent = \"beam{b}\"\nstation = {station:?}");
        let la = d.perpendicular(beams[b].axis);
        let normal = if d.coin(0.5) {
            beams[b].axis
        } else {
            d.perpendicular(la)
        };
        (la, normal)
    };
    let _ = writeln!(
        t,
        "length_axis = {}\nnormal = {}\nlength = {wing_length:?}\nwidth = {width:?}\nareal_density = {areal:?}\nbending_stiffness = {:?}\npoisson_ratio = 0.3\nterms = {{ length = 4, width = 3 }}\n",
        v3(la),
        v3(normal),
        d.log(1e2, 1e5)
    );
    // The deployment: hinge springs that open the wing in about t_dep.
    let t_dep = d.log(5.0, 200.0);
    let cable = panels >= 2 && d.coin(0.3);
    let compliant = d.coin(0.5);
    // The wing's inertia about the root hinge, as if straight: the springs' scale.
    let inertia_root = wing_mass * wing_length * wing_length / 3.0;
    let preload = d.range(0.05, 0.5);
    // A spring k opens a quarter turn in about t_dep when √(k / I) ≈ π / (2 t_dep).
    let k_root = inertia_root * (PI / (2.0 * t_dep)).powi(2);
    let _ = writeln!(
        t,
        "[deployment]\nplate = \"wing\"\npanel_lengths = [{}]\nend_time = {:?}",
        lengths
            .iter()
            .map(|l| format!("{l:?}"))
            .collect::<Vec<_>>()
            .join(", "),
        (4.0 * t_dep).clamp(20.0, 1000.0)
    );
    if cable {
        let _ = writeln!(t, "synchronisation = \"cable\"");
    }
    let damped = d.coin(0.5);
    let rubbing = d.coin(0.3);
    let _ = writeln!(t, "\n[deployment.hinge]\npreload_angle = {preload:?}");
    let _ = writeln!(t);
    // Equal springs on the interior hinges, as in most arrays, set against the outermost
    // panels' inertia; the root hinge's against the whole wing's.
    let k_inner = {
        let out: f64 = lengths[1.min(panels - 1)..].iter().sum();
        (areal * width * out * out * out / 3.0) * (PI / (2.0 * t_dep)).powi(2) * d.log(0.5, 2.0)
    };
    for i in 0..panels {
        let k = if i == 0 { k_root } else { k_inner };
        let out: f64 = lengths[i..].iter().sum();
        let m_out = areal * width * out;
        let _ = writeln!(t, "[[deployment.hinges]]\nstiffness = {k:?}");
        if damped {
            let c = 2.0 * d.range(0.01, 0.3) * (k * m_out * out * out / 3.0).sqrt();
            let _ = writeln!(t, "damping = {c:?}");
        }
        if rubbing {
            let _ = writeln!(t, "friction = {:?}", k * preload * d.range(0.01, 0.2));
        }
    }
    if compliant {
        // Latch modes of 0.5 to 30 Hz on the outermost panel, ζ 2 to 30 %.
        let lp = lengths[panels - 1];
        let ip = areal * width * lp * lp * lp / 3.0;
        let w = 2.0 * PI * d.log(0.5, 30.0);
        let k = ip * w * w;
        let c = 2.0 * d.range(0.02, 0.3) * (k * ip).sqrt();
        let _ = writeln!(
            t,
            "\n[deployment.latch]\nmodel = \"compliant\"\nstiffness = {k:?}\ndamping = {c:?}"
        );
    }
    Drawn { toml: t, free_hub }
}
