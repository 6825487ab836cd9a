//! What a run will cost before it starts: memory and output size estimated from the
//! scenario alone, so that a run that would exhaust the machine is refused with a location
//! instead of dying in an allocation half-way (docs/scenario.md, "Limits").
//!
//! The model (measured 2026-11-28 on the seed structure with plate terms 20×20, 30×30 and
//! 40×40, n = 432, 932 and 1632 generalized coordinates: peak resident memory of
//! `flexcraft modes` 98, 256 and 677 MiB, i.e. 51 MiB + 31 · 8n² bytes; `simulate` 2–5 %
//! more): the assembly and the generalized eigen-solve hold about [`MATRICES_PER_SOLVE`]
//! dense n × n matrices at once, and the program itself [`BASELINE_BYTES`]. The estimate is
//! about 1.15 times the measured peak there (`tests/suite/memory_estimate.rs` measures
//! it). Time series cost 8 bytes per number in memory, plus about
//! [`CSV_BYTES_PER_NUMBER`] bytes of CSV text for the deployment's (the response's CSV is
//! streamed to its file).

use super::{Scenario, ScenarioError};
use crate::deploy::base::BaseKind;
use crate::structure::ComponentId;

/// Dense n × n matrices alive at the peak of a modal solve (assembly, scaling, the Cholesky
/// factor, the reduced problem, its eigenvectors, the back-transformed modes and the
/// Rayleigh-quotient products): 31 measured, with a margin.
pub const MATRICES_PER_SOLVE: u64 = 36;
/// Bytes of CSV text per number written (`1.2345678901234567e-5,`), rounded up.
pub const CSV_BYTES_PER_NUMBER: u64 = 24;
/// The base modes the automatic deployment is guessed to keep (its cutoff is found at run
/// time): the estimate's column count of deployment.csv (generated spacecraft keep 2 to 9).
pub const DEPLOY_MODES_GUESS: u64 = 12;
/// Bytes of NASA 42's flex file per pair of modes (the nine numbers of N_pq on commented
/// lines: measured 640–650 per pair, 74 per number, on 100- to 926-mode exports), rounded up.
pub const FLEX_BYTES_PER_PAIR: u64 = 9 * 80;

/// The default memory budget of a run: half of the memory this process may use — the
/// machine's (Linux: MemTotal of /proc/meminfo) or, when lower, its control group's limit
/// (cgroup v2 `memory.max`, v1 `memory.limit_in_bytes`: a container's or a Slurm job's) — or
/// 8 GiB when neither is known.
pub fn default_memory_budget() -> u64 {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        m.lines()
            .find(|l| l.starts_with("MemTotal:"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|kb| kb.parse::<u64>().ok())
            .map(|kb| kb.saturating_mul(1024))
    });
    let group = [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .iter()
    .filter_map(|p| std::fs::read_to_string(p).ok())
    .find_map(|t| cgroup_limit(&t));
    match (total, group) {
        (Some(t), Some(g)) => t.min(g) / 2,
        (Some(b), None) | (None, Some(b)) => b / 2,
        (None, None) => 8 << 30,
    }
}

/// A control group's memory limit from its file's text: bytes, or None for "max" (v2) or a
/// v1 "unlimited" (a number near 2⁶³).
fn cgroup_limit(text: &str) -> Option<u64> {
    text.trim()
        .parse::<u64>()
        .ok()
        .filter(|&b| b > 0 && b < 1 << 62)
}

/// Memory of the program itself (code, the scenario, the reports and figures of a small
/// model), bytes: 51 MiB measured, with a margin.
pub const BASELINE_BYTES: u64 = 64 << 20;

/// The estimated cost of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Estimate {
    /// Generalized coordinates of the Ritz model.
    pub dof: u64,
    /// Peak memory of the modal solve, bytes.
    pub modes_bytes: u64,
    /// Deployment samples × numbers per sample.
    pub deployment_cells: u64,
    /// Response samples × numbers per sample.
    pub response_cells: u64,
    /// The export's model and files in memory (`flexcraft export`), bytes.
    pub export_bytes: u64,
}

impl Estimate {
    /// Peak memory of the whole run, bytes: the modal solve, then the time series.
    pub fn peak_bytes(&self) -> u64 {
        // The deployment's samples (of two runs at once while the automatic run compares a
        // refinement with the run before it, and copied once for the outputs) and its CSV
        // text are held in memory together; the response's history is held as numbers and
        // its CSV streamed to the file.
        let series = self
            .deployment_cells
            .saturating_mul(3 * 8 + CSV_BYTES_PER_NUMBER)
            .saturating_add(self.response_cells.saturating_mul(8));
        BASELINE_BYTES
            .saturating_add(self.modes_bytes)
            .saturating_add(series)
            .saturating_add(self.export_bytes)
    }
}

/// Human-readable bytes ("1.5 GiB").
pub fn format_bytes(b: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

/// The parts of a run a command makes: every command solves the modal model; `deploy` (and
/// `modes --deployment-sweep`) also keeps the deployment's time series, `simulate` both time
/// series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunParts {
    /// The deployment's time series.
    pub deployment: bool,
    /// The response's time series.
    pub response: bool,
    /// The export's model and files.
    pub export: bool,
}

impl RunParts {
    /// `simulate`: the modal solve and both time series.
    pub const SIMULATE: Self = Self {
        deployment: true,
        response: true,
        export: false,
    };
    /// `modes`: the modal solve alone.
    pub const MODES: Self = Self {
        deployment: false,
        response: false,
        export: false,
    };
    /// `export`: the modal solve and the exported model and files.
    pub const EXPORT: Self = Self {
        deployment: false,
        response: false,
        export: true,
    };
    /// `deploy`, `modes --deployment-sweep`: the modal solve and the deployment.
    pub const DEPLOY: Self = Self {
        deployment: true,
        response: false,
        export: false,
    };
}

impl Scenario {
    /// The cost of `simulate` on this scenario (an upper bound for `modes` and `deploy`).
    pub fn estimate(&self) -> Estimate {
        self.estimate_for(RunParts::SIMULATE)
    }

    /// The cost of the parts of a run a command makes.
    pub fn estimate_for(&self, parts: RunParts) -> Estimate {
        let st = &self.structure;
        let dof = 6
            + st.beams.iter().map(|b| b.terms.dof() as u64).sum::<u64>()
            + st.plates.iter().map(|p| p.dof() as u64).sum::<u64>();
        let modes_bytes = MATRICES_PER_SOLVE.saturating_mul(8 * dof * dof);
        let deployment_cells =
            (self.deployment.as_ref().filter(|_| parts.deployment)).map_or(0, |d| {
                let n = d.chain.len() as u64;
                // The base's coordinates (every component but the deploying plate).
                let base_dof = st.beams.iter().map(|b| b.terms.dof() as u64).sum::<u64>()
                    + st.plates
                        .iter()
                        .filter(|p| p.name != d.plate)
                        .map(|p| p.dof() as u64)
                        .sum::<u64>();
                // The base's columns: every mode when no count is given, else the count asked
                // for (or, chosen automatically, about DEPLOY_MODES_GUESS) plus at most twelve
                // correction vectors.
                // (The automatic run turns a given count into `Corrected`.)
                let base = match d.base {
                    BaseKind::Rigid => 0,
                    BaseKind::Flexible { modes: None } => base_dof,
                    BaseKind::Flexible { modes: Some(m) } | BaseKind::Corrected { modes: m } => {
                        m as u64 + 12
                    }
                    BaseKind::Reduced { at_least, .. } => {
                        DEPLOY_MODES_GUESS.max(at_least as u64) + 12
                    }
                }
                .min(base_dof);
                // deployment.csv's columns: t, α, α̇ (2N), the hub (12), the base's columns,
                // each beam's tip (4) and root loads (6), each hinge's reactions and latch
                // moment (3N), the cable (N − 1), energies (3), momentum (6); one sample per
                // row, plus a copy at every latch.
                let per_sample = 21 + 6 * n + base + 10 * st.beams.len() as u64;
                crate::response::rows(d.end_time, d.output_rate)
                    .saturating_add(2 * n)
                    .saturating_mul(per_sample)
            });
        let response_cells = if self.deployment.is_some() && parts.response {
            // Hub (6), every beam's tip (3) and root loads (6), plate corners (2), latch
            // moments (one per panel); η and η̈ of every kept mode.
            let panels = self.deployment.as_ref().map_or(0, |d| d.chain.len() as u64);
            let channels = 6 + 9 * st.beams.len() as u64 + 2 * st.plates.len() as u64 + panels;
            let modes = self.response.modes.map_or(dof, |m| (m as u64).min(dof));
            // hub.csv (output/hub.rs): t, position, rotation, velocity and rate (13) per
            // row, as numbers and as text held whole (CSV_BYTES_PER_NUMBER each): 13 · 4 in
            // 8-byte cells.
            let hub = 13 * (1 + CSV_BYTES_PER_NUMBER / 8);
            // The history's numbers are counted one and a half times: its vectors grow by
            // doubling (measured: the response part alone was within 3 % of one times).
            self.response
                .rows()
                .saturating_mul(3 * (1 + channels + 2 * modes) / 2 + hub)
        } else {
            0
        };
        let export_bytes = if parts.export {
            self.export_bytes(dof)
        } else {
            0
        };
        Estimate {
            dof,
            modes_bytes,
            deployment_cells,
            response_cells,
            export_bytes,
        }
    }

    /// The export's memory beyond the modal solve for a model of `dof` coordinates, bytes:
    /// the mass elements of 42's modal integrals (`export::mass_elements`: per point and kept
    /// mode a translation and a rotation, 48 bytes, held three times — the elements, the
    /// flex body's points and the growth of their vectors — and 24 bytes more as the
    /// products' matrices), the integrals' N (nine numbers per pair of modes) and
    /// the texts held whole until they are written (outputs appear whole or not at all), each
    /// up to three times its length while it grows: the flex file (about
    /// [`FLEX_BYTES_PER_PAIR`] per pair of modes) and the state-space model's JSON
    /// ([`CSV_BYTES_PER_NUMBER`] per entry of its (2n)² A matrix, with the .mat and .npz
    /// beside it).
    fn export_bytes(&self, dof: u64) -> u64 {
        let st = &self.structure;
        let elastic = dof.saturating_sub(6);
        let modes = self
            .export_modes()
            .map_or(elastic, |m| (m as u64).min(elastic));
        let points = crate::export::element_count(st);
        let elements = points.saturating_mul(modes).saturating_mul(3 * 48 + 24);
        let pairs = modes.saturating_mul(modes);
        let integrals = pairs.saturating_mul(9 * 8);
        let flex = pairs.saturating_mul(3 * FLEX_BYTES_PER_PAIR);
        let states = 2 * (modes + 6);
        let model = states
            .saturating_mul(states)
            .saturating_mul(3 * CSV_BYTES_PER_NUMBER + 2 * 8);
        elements
            .saturating_add(integrals)
            .saturating_add(flex)
            .saturating_add(model)
    }

    /// Refuses a run whose estimated peak memory exceeds `max_bytes`, located at the key
    /// that drives it: the component with the most Ritz terms, or the output rate of the
    /// longest time series.
    pub fn check_budget(&self, max_bytes: u64) -> Result<Estimate, ScenarioError> {
        self.check_budget_for(max_bytes, RunParts::SIMULATE)
    }

    /// [`Scenario::check_budget`] for the parts of a run a command makes: `modes` is not
    /// refused for a response it does not compute.
    pub fn check_budget_for(
        &self,
        max_bytes: u64,
        parts: RunParts,
    ) -> Result<Estimate, ScenarioError> {
        let e = self.estimate_for(parts);
        let peak = e.peak_bytes();
        if peak <= max_bytes {
            return Ok(e);
        }
        let why = format!(
            "the run would need about {} of memory (limit {}; raise it with --max-memory)",
            format_bytes(peak),
            format_bytes(max_bytes)
        );
        let st = &self.structure;
        if e.export_bytes >= e.peak_bytes() / 2 {
            return Err(self.locate_key(
                "export.modes",
                format!(
                    "the export of this many modes (42's N integrals and flex file grow with \
                     their square): {why}"
                ),
            ));
        }
        // Without time series (modes, export) only the terms can be blamed.
        let series = e.deployment_cells.max(e.response_cells) > 0;
        if e.modes_bytes >= e.peak_bytes() / 2 || !series {
            let biggest = st
                .beams
                .iter()
                .enumerate()
                .map(|(i, b)| (b.terms.dof(), ComponentId::Beam(i)))
                .chain(
                    st.plates
                        .iter()
                        .enumerate()
                        .map(|(i, p)| (p.dof(), ComponentId::Plate(i))),
                )
                .max_by_key(|(n, _)| *n);
            let (n, id) = biggest.unwrap_or((0, ComponentId::Hub));
            let mut err = self.locate(
                id,
                format!(
                    "{n} of the model's {} generalized coordinates are this component's terms: {why}",
                    e.dof
                ),
            );
            err.key.push_str(".terms");
            return Err(err);
        }
        let key = if e.response_cells >= e.deployment_cells {
            "response.output_rate"
        } else {
            "deployment.output_rate"
        };
        Err(self.locate_key(key, format!("the time series are too long: {why}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_read_well() {
        assert_eq!(format_bytes(512), "512 B");
        assert_eq!(format_bytes(3 << 29), "1.5 GiB");
    }
}

#[cfg(test)]
mod cgroup_tests {
    use super::cgroup_limit;

    /// The limit files' forms: v2 "max" and v1's page-rounded 2⁶³ mean no limit; a number is
    /// one.
    #[test]
    fn cgroup_limits_are_read_or_taken_as_none() {
        assert_eq!(cgroup_limit("max\n"), None);
        assert_eq!(cgroup_limit("9223372036854771712\n"), None);
        assert_eq!(cgroup_limit("2147483648\n"), Some(2 << 30));
        assert_eq!(cgroup_limit("0"), None);
        assert_eq!(cgroup_limit("junk"), None);
    }
}
