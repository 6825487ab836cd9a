//! What a run will cost before it starts: memory and output size estimated from the
//! scenario alone, so that a run that would exhaust the machine is refused with a location
//! instead of dying in an allocation half-way (docs/scenario.md, "Limits").
//!
//! The model (measured on the seed structure with plate terms 20×20 … 40×40, peak resident
//! memory of `flexcraft modes` ≈ 18–20 · 8n² bytes for n generalized coordinates): the
//! assembly and the generalized eigen-solve hold about [`MATRICES_PER_SOLVE`] dense n × n
//! matrices at once. Time series cost 8 bytes per number in memory, plus about
//! [`CSV_BYTES_PER_NUMBER`] bytes of CSV text for the deployment's (the response's CSV is
//! streamed to its file).

use super::{Scenario, ScenarioError};
use crate::structure::ComponentId;

/// Dense n × n matrices alive at the peak of a modal solve (assembly, scaling, the Cholesky
/// factor, the reduced problem, its eigenvectors, the back-transformed modes and the
/// Rayleigh-quotient products), rounded up.
pub const MATRICES_PER_SOLVE: u64 = 20;
/// Bytes of CSV text per number written (`1.2345678901234567e-5,`), rounded up.
pub const CSV_BYTES_PER_NUMBER: u64 = 24;

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

/// Memory of the program itself, bytes.
pub const BASELINE_BYTES: u64 = 32 << 20;

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
}

impl Estimate {
    /// Peak memory of the whole run, bytes: the modal solve, then the time series.
    pub fn peak_bytes(&self) -> u64 {
        // The deployment's samples and its CSV text are held in memory together; the
        // response's history is held as numbers and its CSV streamed to the file.
        let series = self
            .deployment_cells
            .saturating_mul(8 + CSV_BYTES_PER_NUMBER)
            .saturating_add(self.response_cells.saturating_mul(8));
        BASELINE_BYTES
            .saturating_add(self.modes_bytes)
            .saturating_add(series)
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
}

impl RunParts {
    /// `simulate`: the modal solve and both time series.
    pub const SIMULATE: Self = Self {
        deployment: true,
        response: true,
    };
    /// `modes`, `export`: the modal solve alone.
    pub const MODES: Self = Self {
        deployment: false,
        response: false,
    };
    /// `deploy`, `modes --deployment-sweep`: the modal solve and the deployment.
    pub const DEPLOY: Self = Self {
        deployment: true,
        response: false,
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
            + st.plates.iter().map(|p| p.terms.dof() as u64).sum::<u64>();
        let modes_bytes = MATRICES_PER_SOLVE.saturating_mul(8 * dof * dof);
        let deployment_cells =
            (self.deployment.as_ref().filter(|_| parts.deployment)).map_or(0, |d| {
                let n = d.chain.len() as u64;
                // t, α, α̇, hub (3 + 3), reactions (2N), moments (N), energies, hinge points
                // (2(N + 1)): one sample, plus a copy at every latch.
                let per_sample = 10 + 8 * n;
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
            self.response
                .rows()
                .saturating_mul(1 + channels + 2 * modes)
        } else {
            0
        };
        Estimate {
            dof,
            modes_bytes,
            deployment_cells,
            response_cells,
        }
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
                        .map(|(i, p)| (p.terms.dof(), ComponentId::Plate(i))),
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
