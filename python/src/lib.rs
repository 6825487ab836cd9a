//! `flexcraft._flexcraft`: the native half of the Python package. Each entry point does what
//! the matching command of the `flexcraft` tool does (src/main.rs: `run_modes`, `run_deploy`,
//! `run_simulate`, `run_export`) with the same library calls, and hands Python plain data:
//! the command's `--json` text, NumPy arrays, and a handle on the Rust result for what needs
//! it later (mode shapes at points, writing the output folder). The pure-Python package
//! (`flexcraft/__init__.py`) wraps these in the documented classes.
//!
//! Every computation runs without the GIL and inside `catch_unwind`: a panic becomes
//! `flexcraft.InternalError`, never an abort or a `PanicException`.

use flexcraft::deploy::Deployment;
use flexcraft::export::ExportModel;
use flexcraft::faer::Mat;
use flexcraft::output::{self, OutputDir};
use flexcraft::ritz::shapes::{attachment_of, BeamStation, PlatePoint};
use flexcraft::scenario::default_memory_budget;
use flexcraft::scenario::{ErrorKind, OverrideValue, ScenarioError as RustScenarioError};
use flexcraft::simulation::Simulation;
use flexcraft::structure::ComponentId;
use flexcraft::{ModalAnalysis, RitzModel, Scenario};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};
use pyo3::IntoPyObjectExt;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pyo3::create_exception!(
    flexcraft,
    ScenarioError,
    PyValueError,
    "A scenario refused: `.file`, `.line`, `.column` (1-based; 0 when the file could not be \
     read or an override path did not resolve), `.key` (dotted path), `.reason`, `.kind` \
     ('io', 'syntax', 'schema', 'invalid'); str() is the command line's message \
     `file:line:column: key: reason`."
);
pyo3::create_exception!(
    flexcraft,
    ComputationError,
    PyRuntimeError,
    "A numerical failure (a modal solve, the deployment's integration, a non-finite result), \
     with the command line's message."
);
pyo3::create_exception!(
    flexcraft,
    InternalError,
    PyRuntimeError,
    "A bug in flexcraft (a Rust panic caught at the boundary); please report it with the \
     scenario."
);

/// The Python exception for a refused scenario, its fields as attributes. They live in the
/// instance's `__dict__`, which `BaseException.__reduce__` pickles with the message: the
/// exception round-trips through pickle (and so through process pools) whole.
fn scenario_error(py: Python<'_>, e: &RustScenarioError) -> PyErr {
    let err = ScenarioError::new_err(e.to_string());
    let kind = match e.kind {
        ErrorKind::Io => "io",
        ErrorKind::Syntax => "syntax",
        ErrorKind::Schema => "schema",
        _ => "invalid",
    };
    let v = err.value(py);
    let set = |k: &str, o: PyResult<Bound<'_, PyAny>>| o.and_then(|o| v.setattr(k, o));
    let ok = set("file", e.file.as_str().into_bound_py_any(py))
        .and(set("line", e.location.line.into_bound_py_any(py)))
        .and(set("column", e.location.column.into_bound_py_any(py)))
        .and(set("key", e.key.as_str().into_bound_py_any(py)))
        .and(set("reason", e.reason.as_str().into_bound_py_any(py)))
        .and(set("kind", kind.into_bound_py_any(py)));
    match ok {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// Why a computation did not give a result.
enum Failure {
    Scenario(RustScenarioError),
    Computation(String),
    Panic(String),
}

impl Failure {
    fn into_py(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Scenario(e) => scenario_error(py, &e),
            Failure::Computation(m) => ComputationError::new_err(m),
            Failure::Panic(m) => internal_error(&m),
        }
    }
}

/// Runs `f` without the GIL, a panic turned into [`Failure::Panic`].
fn compute<T: Send>(py: Python<'_>, f: impl FnOnce() -> Result<T, Failure> + Send) -> PyResult<T> {
    let r = py.allow_threads(|| {
        catch_unwind(AssertUnwindSafe(f))
            .unwrap_or_else(|p| Err(Failure::Panic(panic_message(&*p))))
    });
    r.map_err(|e| e.into_py(py))
}

/// Runs `f` with the GIL (a result's conversion to Python objects), a panic turned into
/// `InternalError` as in [`compute`], not into pyo3's `PanicException`.
fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| Err(internal_error(&panic_message(&*p))))
}

/// What a panic said.
fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

fn internal_error(msg: &str) -> PyErr {
    InternalError::new_err(format!(
        "flexcraft panicked (a bug; please report it with the scenario): {msg}"
    ))
}

/// A validated scenario (the library's `Scenario`) and the name it was read under.
#[pyclass(module = "flexcraft._flexcraft", frozen, name = "_Scenario")]
struct PyScenario {
    inner: Arc<Scenario>,
    /// The file as named by the caller (errors and the report's footer), or the name given
    /// to `from_toml`.
    file: String,
}

impl PyScenario {
    /// `file`'s last component, as the command line names the scenario in the report.
    fn file_name(&self) -> String {
        Path::new(&self.file)
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    }

    /// The command line's memory check (default budget), then the scenario.
    fn checked(&self, max_memory: Option<u64>) -> Result<Arc<Scenario>, Failure> {
        self.inner
            .check_budget(max_memory.unwrap_or_else(default_memory_budget))
            .map_err(Failure::Scenario)?;
        Ok(self.inner.clone())
    }

    fn deployment(&self) -> Result<&Deployment, Failure> {
        self.inner.deployment.as_ref().ok_or_else(|| {
            Failure::Scenario(RustScenarioError {
                kind: ErrorKind::Invalid,
                file: self.file.clone(),
                location: Default::default(),
                key: "deployment".into(),
                reason: "the scenario has no [deployment] section (see docs/scenario.md)".into(),
            })
        })
    }
}

#[pymethods]
impl PyScenario {
    #[staticmethod]
    fn from_file(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let file = path.display().to_string();
        let inner = compute(py, || Scenario::from_file(&path).map_err(Failure::Scenario))?;
        Ok(Self {
            inner: Arc::new(inner),
            file,
        })
    }

    #[staticmethod]
    #[pyo3(signature = (text, file = "<string>".to_string()))]
    fn from_toml(py: Python<'_>, text: String, file: String) -> PyResult<Self> {
        let inner = compute(py, || {
            Scenario::from_toml_str(&text, &file).map_err(Failure::Scenario)
        })?;
        Ok(Self {
            inner: Arc::new(inner),
            file,
        })
    }

    /// Values replaced at dotted paths, validated like a file.
    fn with_values(&self, py: Python<'_>, values: &Bound<'_, PyDict>) -> PyResult<Self> {
        let mut owned: Vec<(String, OverrideValue)> = Vec::new();
        for (k, v) in values.iter() {
            let key: String = k
                .extract()
                .map_err(|_| PyTypeError::new_err("with_values: keys are dotted paths (str)"))?;
            let value = if v.is_instance_of::<PyBool>() {
                OverrideValue::Bool(v.extract()?)
            } else if v.is_instance_of::<PyInt>() || v.is_instance_of::<PyFloat>() {
                OverrideValue::Number(v.extract()?)
            } else if v.is_instance_of::<PyString>() {
                OverrideValue::Text(v.extract()?)
            } else if let Ok(x) = v.extract::<f64>() {
                // NumPy scalars and anything else with __float__.
                OverrideValue::Number(x)
            } else {
                return Err(PyTypeError::new_err(format!(
                    "with_values: {key}: a value is a number, a string or a bool, not {}",
                    v.get_type().name()?
                )));
            };
            owned.push((key, value));
        }
        let inner = self.inner.clone();
        let s = compute(py, move || {
            let pairs: Vec<(&str, OverrideValue)> =
                owned.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
            inner.with_values(&pairs).map_err(Failure::Scenario)
        })?;
        Ok(Self {
            inner: Arc::new(s),
            file: self.file.clone(),
        })
    }

    #[getter]
    fn toml(&self) -> &str {
        self.inner.source_text()
    }

    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }

    #[getter]
    fn file(&self) -> &str {
        &self.file
    }

    #[getter]
    fn has_deployment(&self) -> bool {
        self.inner.deployment.is_some()
    }

    /// Component names: (beams, plates, masses).
    fn components(&self) -> (Vec<String>, Vec<String>, Vec<String>) {
        let st = &self.inner.structure;
        (
            st.beams().iter().map(|b| b.name().to_string()).collect(),
            st.plates().iter().map(|p| p.name().to_string()).collect(),
            st.masses().iter().map(|m| m.name().to_string()).collect(),
        )
    }
}

/// A column-major faer matrix as a NumPy array.
fn mat<'py>(py: Python<'py>, m: &Mat<f64>) -> Bound<'py, PyAny> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)])
        .into_pyarray(py)
        .into_any()
}

/// Rows of N numbers as an n × N array.
fn rows<'py, const N: usize>(
    py: Python<'py>,
    r: impl IntoIterator<Item = [f64; N]>,
) -> Bound<'py, PyAny> {
    let flat: Vec<f64> = r.into_iter().flatten().collect();
    let n = flat.len() / N;
    Array2::from_shape_fn((n, N), |(i, j)| flat[i * N + j])
        .into_pyarray(py)
        .into_any()
}

fn vec1<'py>(py: Python<'py>, v: impl IntoIterator<Item = f64>) -> Bound<'py, PyAny> {
    v.into_iter()
        .collect::<Vec<f64>>()
        .into_pyarray(py)
        .into_any()
}

/// A field name the package does not know: a bug in flexcraft/__init__.py.
fn no_field(what: &str, name: &str) -> PyErr {
    InternalError::new_err(format!("flexcraft: a {what} result has no field {name:?}"))
}

/// The model and modes of `fc.modes`, kept for mode shapes at points and for writing.
#[pyclass(module = "flexcraft._flexcraft", frozen, name = "_Modes")]
struct PyModes {
    src: ModesSource,
}

/// A modal analysis of its own (`fc.modes`) or the one of a simulation.
enum ModesSource {
    Own(Box<(RitzModel, ModalAnalysis)>),
    Simulation(Arc<Simulation>),
}

/// Where `Modes.shape` samples: a station of a beam or a point of a plate.
enum ShapePoint {
    Beam(BeamStation),
    Plate(PlatePoint),
}

impl PyModes {
    fn model(&self) -> &RitzModel {
        match &self.src {
            ModesSource::Own(own) => &own.0,
            ModesSource::Simulation(s) => &s.model,
        }
    }

    fn modes(&self) -> &ModalAnalysis {
        match &self.src {
            ModesSource::Own(own) => &own.1,
            ModesSource::Simulation(s) => &s.modes,
        }
    }
}

/// The command line's `numerical_failure` message.
fn ritz_failure(s: &Scenario, model: &RitzModel, e: &flexcraft::ritz::RitzError) -> Failure {
    let id = model.culprit(e);
    let name = s.structure.component_name(id);
    Failure::Scenario(s.locate(
        id,
        format!(
            "{e}; traced to component \"{name}\": check its values against the others \
             (masses, stiffnesses and sizes that differ by many orders of magnitude)"
        ),
    ))
}

fn non_finite(file: &str, r: Result<(), flexcraft::finite::NonFinite>) -> Result<(), Failure> {
    r.map_err(|e| Failure::Computation(format!("{file}: {e}")))
}

#[pymethods]
impl PyModes {
    /// The `modes --json` text (= modes.json).
    fn json(&self) -> PyResult<String> {
        guard(|| Ok(output::modes_json(self.model(), self.modes())))
    }

    /// One result as a NumPy array, made when Python first asks for it (the package caches
    /// it): omega, frequency_hz, rigid, number, mass_matrix, stiffness_matrix, coefficients
    /// (modes × coordinates), effective_mass and participation (hub-fixed modes × 6),
    /// hub_fixed_omega, appendage_mass.
    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let m = &self.modes().modes;
            let hf = &self.modes().hub_fixed;
            Ok(match name {
                "omega" => vec1(py, m.iter().map(|m| m.omega_rad_s)),
                "frequency_hz" => vec1(py, m.iter().map(|m| m.frequency_hz())),
                "rigid" => m
                    .iter()
                    .map(|m| m.rigid)
                    .collect::<Vec<bool>>()
                    .into_pyarray(py)
                    .into_any(),
                "number" => m
                    .iter()
                    .map(|m| m.number as i64)
                    .collect::<Vec<i64>>()
                    .into_pyarray(py)
                    .into_any(),
                "mass_matrix" => mat(py, &self.model().mass),
                "stiffness_matrix" => mat(py, &self.model().stiffness),
                "coefficients" => {
                    Array2::from_shape_fn((m.len(), self.model().dof()), |(i, j)| m[i].shape[j])
                        .into_pyarray(py)
                        .into_any()
                }
                "effective_mass" => rows(py, hf.iter().map(|h| h.effective_mass)),
                "participation" => rows(py, hf.iter().map(|h| h.participation)),
                "hub_fixed_omega" => vec1(py, hf.iter().map(|h| h.omega_rad_s)),
                "appendage_mass" => vec1(py, self.modes().appendage_mass),
                _ => return Err(no_field("modes", name)),
            })
        })
    }

    /// Displacement and small rotation [ux, uy, uz, rx, ry, rz] (structure frame, m and rad
    /// per unit modal coordinate) of `component` at `points` for every mode: a beam's points
    /// are ξ = x/L (1-D), a plate's (ξ, η) pairs (n × 2), both in [0, 1]. Returns
    /// modes × points × 6 as a flat vector and its shape.
    fn shape<'py>(
        &self,
        py: Python<'py>,
        component: &str,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let model = self.model();
            let st = &model.structure;
            let beam = st.beams().iter().position(|b| b.name() == component);
            let plate = st.plates().iter().position(|p| p.name() == component);
            let (id, at): (ComponentId, Vec<ShapePoint>) = if let Some(b) = beam {
                let xs: PyReadonlyArray1<f64> = points.extract().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "shape: \"{component}\" is a beam: points is a 1-D float array of ξ = x/L"
                    ))
                })?;
                let at = xs
                    .as_slice()?
                    .iter()
                    .map(|&xi| {
                        if !(0.0..=1.0).contains(&xi) {
                            return Err(PyValueError::new_err(format!(
                                "shape: ξ = {xi} is outside [0, 1]"
                            )));
                        }
                        BeamStation::new(model, b, xi)
                            .map(ShapePoint::Beam)
                            .ok_or_else(|| PyValueError::new_err("shape: no such beam"))
                    })
                    .collect::<PyResult<Vec<_>>>()?;
                (ComponentId::Beam(b), at)
            } else if let Some(p) = plate {
                let xy: PyReadonlyArray2<f64> = points.extract().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "shape: \"{component}\" is a plate: points is an n × 2 float array of (ξ, η)"
                    ))
                })?;
                let xy = xy.as_array();
                if xy.ncols() != 2 {
                    return Err(PyValueError::new_err(
                        "shape: a plate's points are n × 2 (ξ, η)",
                    ));
                }
                let at = xy
                    .rows()
                    .into_iter()
                    .map(|r| {
                        let (xi, eta) = (r[0], r[1]);
                        if !(0.0..=1.0).contains(&xi) || !(0.0..=1.0).contains(&eta) {
                            return Err(PyValueError::new_err(format!(
                                "shape: (ξ, η) = ({xi}, {eta}) is outside [0, 1]²"
                            )));
                        }
                        PlatePoint::new(model, p, xi, eta)
                            .map(ShapePoint::Plate)
                            .ok_or_else(|| PyValueError::new_err("shape: no such plate"))
                    })
                    .collect::<PyResult<Vec<_>>>()?;
                (ComponentId::Plate(p), at)
            } else {
                let names: Vec<&str> = st
                    .beams()
                    .iter()
                    .map(|b| b.name())
                    .chain(st.plates().iter().map(|p| p.name()))
                    .collect();
                return Err(PyValueError::new_err(format!(
                    "shape: no beam or plate is named {component:?} (the model has {names:?})"
                )));
            };
            let m = &self.modes().modes;
            let mut flat = Vec::with_capacity(m.len() * at.len() * 6);
            for mode in m {
                let q = &mode.shape;
                let att = attachment_of(model, id, q).unwrap_or_default();
                for point in &at {
                    let p = match point {
                        ShapePoint::Beam(s) => s.sample(model, q, att),
                        ShapePoint::Plate(s) => s.sample(model, q, att),
                    };
                    let (d, r) = (p.displacement.0, p.rotation.0);
                    flat.extend([d[0], d[1], d[2], r[0], r[1], r[2]]);
                }
            }
            let a = numpy::ndarray::Array3::from_shape_vec((m.len(), at.len(), 6), flat)
                .map_err(|e| InternalError::new_err(e.to_string()))?;
            Ok(a.into_pyarray(py).into_any())
        })
    }

    /// Writes what `flexcraft modes --out DIR` writes.
    #[pyo3(signature = (dir, force = false))]
    fn write(&self, py: Python<'_>, dir: PathBuf, force: bool) -> PyResult<usize> {
        write_dir(py, &dir, force, |o| {
            output::write_modes(o, self.model(), self.modes())
        })
    }
}

/// Stages, writes and swaps in an output folder as the command line does.
fn write_dir(
    py: Python<'_>,
    dir: &Path,
    force: bool,
    write: impl FnOnce(&mut OutputDir) -> Result<(), output::OutputError> + Send,
) -> PyResult<usize> {
    compute(py, || {
        let mut o = OutputDir::create(dir, force).map_err(|e| {
            if e.is_refusal() {
                Failure::Computation(format!("{e}"))
            } else {
                Failure::Computation(format!("writing {}: {e}", dir.display()))
            }
        })?;
        write(&mut o)
            .and_then(|()| o.commit())
            .map_err(|e| Failure::Computation(format!("writing {}: {e}", dir.display())))
    })
    .map_err(|e| {
        Python::with_gil(|py| {
            if e.is_instance_of::<ComputationError>(py) {
                PyErr::new::<pyo3::exceptions::PyOSError, _>(e.value(py).to_string())
            } else {
                e
            }
        })
    })
}

/// `flexcraft modes`: the lowest modes an automatic term selection aims at, or all.
#[pyfunction]
#[pyo3(signature = (scenario, max_memory = None))]
fn modes(py: Python<'_>, scenario: &PyScenario, max_memory: Option<u64>) -> PyResult<PyModes> {
    let file = scenario.file.clone();
    compute(py, || {
        let s = scenario.checked(max_memory)?;
        let model = RitzModel::assemble(&s.structure);
        let selection = s.term_selection.as_ref();
        let modes = ModalAnalysis::compute_selected(&model, selection.map(|s| s.accuracy.modes), selection)
            .map_err(|e| ritz_failure(&s, &model, &e))?;
        non_finite(&file, flexcraft::finite::check_modes(&modes))?;
        Ok(PyModes {
            src: ModesSource::Own(Box::new((model, modes))),
        })
    })
}

/// The deployment of `fc.deploy` (and of `fc.simulate`).
#[pyclass(module = "flexcraft._flexcraft", frozen, name = "_Deployment")]
struct PyDeployment {
    scenario: Arc<Scenario>,
    src: DeploymentSource,
}

/// A deployment of its own (`fc.deploy`) or the one of a simulation.
enum DeploymentSource {
    Own(
        Box<(
            flexcraft::deploy::coupled::Coupled,
            flexcraft::deploy::DeploymentResult,
        )>,
    ),
    Simulation(Arc<Simulation>),
}

impl PyDeployment {
    fn coupled(&self) -> &flexcraft::deploy::coupled::Coupled {
        match &self.src {
            DeploymentSource::Own(own) => &own.0,
            DeploymentSource::Simulation(s) => &s.coupled,
        }
    }

    fn result(&self) -> &flexcraft::deploy::DeploymentResult {
        match &self.src {
            DeploymentSource::Own(own) => &own.1,
            DeploymentSource::Simulation(s) => &s.deployment,
        }
    }

    fn d(&self) -> &Deployment {
        self.scenario
            .deployment
            .as_ref()
            .expect("a deployment result is made for a scenario with [deployment]")
    }
}

#[pymethods]
impl PyDeployment {
    /// The `deploy --json` text (= events.json).
    fn json(&self) -> PyResult<String> {
        guard(|| {
            Ok(output::deploy_json(
                &self.scenario.name,
                self.d(),
                self.coupled(),
                self.result(),
            ))
        })
    }

    /// deployment.csv's text.
    fn csv(&self) -> PyResult<String> {
        guard(|| Ok(output::deployment_csv(self.coupled(), self.result())))
    }

    /// One result, made when Python first asks for it (the package caches it): t
    /// (samples), alpha and rate (samples × hinges), latches (a list of dicts, the fields
    /// of `flexcraft.Latch`), all_latched, final_time.
    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let r = self.result();
            let s = &r.samples;
            let grid = |f: &dyn Fn(&flexcraft::deploy::Sample, usize) -> f64| {
                Array2::from_shape_fn((s.len(), self.coupled().panels()), |(k, i)| f(&s[k], i))
                    .into_pyarray(py)
                    .into_any()
            };
            Ok(match name {
                "t" => vec1(py, s.iter().map(|s| s.t)),
                "alpha" => grid(&|s, i| s.alpha[i]),
                "rate" => grid(&|s, i| s.rate[i]),
                "latches" => {
                    let latches = PyList::empty(py);
                    for e in &r.latches {
                        let l = PyDict::new(py);
                        l.set_item("time", e.time)?;
                        l.set_item("hinge", e.hinge)?;
                        l.set_item("locked", e.locked.clone())?;
                        l.set_item("angles", vec1(py, e.angles.iter().copied()))?;
                        l.set_item("rates_before", vec1(py, e.rates_before.iter().copied()))?;
                        l.set_item("rates_after", vec1(py, e.rates_after.iter().copied()))?;
                        l.set_item("energy_before", e.energy_before)?;
                        l.set_item("energy_after", e.energy_after)?;
                        l.set_item("energy_lost", e.energy_before - e.energy_after)?;
                        let imp = e.impulses.iter().map(|(p, m)| [p[0], p[1], *m]);
                        l.set_item("hinge_impulses", rows(py, imp))?;
                        latches.append(l)?;
                    }
                    latches.into_any()
                }
                "all_latched" => r.all_latched.into_bound_py_any(py)?,
                "final_time" => r.final_time.into_bound_py_any(py)?,
                _ => return Err(no_field("deploy", name)),
            })
        })
    }

    /// Writes what `flexcraft deploy --out DIR` writes.
    #[pyo3(signature = (dir, force = false))]
    fn write(&self, py: Python<'_>, dir: PathBuf, force: bool) -> PyResult<usize> {
        write_dir(py, &dir, force, |o| {
            output::write_deploy(
                o,
                &self.scenario.name,
                self.d(),
                self.coupled(),
                self.result(),
            )
        })
    }
}

/// `flexcraft deploy`: the coupled deployment of `[deployment]`.
#[pyfunction]
#[pyo3(signature = (scenario, max_memory = None))]
fn deploy(
    py: Python<'_>,
    scenario: &PyScenario,
    max_memory: Option<u64>,
) -> PyResult<PyDeployment> {
    let file = scenario.file.clone();
    compute(py, || {
        let s = scenario.checked(max_memory)?;
        let d = scenario.deployment()?;
        let (coupled, result) = flexcraft::deploy::simulate_coupled(&s.structure, d)
            .map_err(|e| Failure::Computation(format!("{file}: {e}")))?;
        non_finite(&file, flexcraft::finite::check_deployment(&result))?;
        Ok(PyDeployment {
            scenario: s,
            src: DeploymentSource::Own(Box::new((coupled, result))),
        })
    })
}

/// The whole story of `fc.simulate`.
#[pyclass(module = "flexcraft._flexcraft", frozen, name = "_Simulation")]
struct PySimulation {
    scenario: Arc<Scenario>,
    file_name: String,
    sim: Arc<Simulation>,
}

#[pymethods]
impl PySimulation {
    /// The `simulate --json` text (= summary.json).
    fn json(&self) -> PyResult<String> {
        guard(|| Ok(output::simulate_json(&self.scenario, &self.sim)))
    }

    /// response.csv as (header names, samples × columns array); None without a response.
    fn response<'py>(&self, py: Python<'py>) -> PyResult<Option<(Vec<String>, Bound<'py, PyAny>)>> {
        guard(|| {
            let Some(r) = self.sim.response.as_ref() else {
                return Ok(None);
            };
            let hist = &r.history;
            // The columns of write_simulate's response.csv, in its order.
            let header = output::response_header(r);
            let (nc, nm) = (r.channels.len(), r.modal.modes.len());
            let t_latch = r.handover.latch_time;
            let a = Array2::from_shape_fn((hist.times.len(), 2 + nc + nm), |(k, j)| match j {
                0 => t_latch + hist.times[k],
                1 => hist.times[k],
                j if j < 2 + nc => hist.values[(k, j - 2)],
                j => hist.modal[(k, j - 2 - nc)],
            });
            Ok(Some((header, a.into_pyarray(py).into_any())))
        })
    }

    /// The modes and the deployment of the run, as the handles of `fc.modes` and `fc.deploy`.
    fn parts(&self) -> (PyModes, PyDeployment) {
        (
            PyModes {
                src: ModesSource::Simulation(self.sim.clone()),
            },
            PyDeployment {
                scenario: self.scenario.clone(),
                src: DeploymentSource::Simulation(self.sim.clone()),
            },
        )
    }

    /// Writes what `flexcraft simulate --out DIR` writes.
    #[pyo3(signature = (dir, force = false))]
    fn write(&self, py: Python<'_>, dir: PathBuf, force: bool) -> PyResult<usize> {
        let source = self.scenario.source_text().as_bytes().to_vec();
        write_dir(py, &dir, force, |o| {
            output::write_simulate(o, &self.scenario, &self.sim, &source, &self.file_name)
        })
    }
}

/// `flexcraft simulate`: modes, deployment, hand-over and response.
#[pyfunction]
#[pyo3(signature = (scenario, max_memory = None))]
fn simulate(
    py: Python<'_>,
    scenario: &PyScenario,
    max_memory: Option<u64>,
) -> PyResult<PySimulation> {
    let file = scenario.file.clone();
    let file_name = scenario.file_name();
    compute(py, || {
        let s = scenario.checked(max_memory)?;
        scenario.deployment()?;
        let sim = Simulation::run(&s).map_err(|e| match &e {
            flexcraft::simulation::SimulationError::Ritz(r) => {
                ritz_failure(&s, &RitzModel::assemble(&s.structure), r)
            }
            _ => Failure::Computation(format!("{file}: {e}")),
        })?;
        non_finite(&file, flexcraft::finite::check_simulation(&sim))?;
        Ok(PySimulation {
            scenario: s,
            file_name,
            sim: Arc::new(sim),
        })
    })
}

/// The linear model of `fc.export`.
#[pyclass(module = "flexcraft._flexcraft", frozen, name = "_Export")]
struct PyExport {
    scenario: Arc<Scenario>,
    body: String,
    model: RitzModel,
    modes: ModalAnalysis,
    ex: ExportModel,
    warnings: Vec<String>,
}

#[pymethods]
impl PyExport {
    /// The `export --json` text (= model.json).
    fn json(&self) -> PyResult<String> {
        let st = &self.scenario.structure;
        guard(|| {
            Ok(output::export_json(
                st,
                &self.modes,
                &self.ex,
                &self.scenario.export.transfers,
            ))
        })
    }

    /// One result, made when Python first asks for it (the package caches it): the first
    /// order A, B, C, D and the names of x, u, y; the second order M2, C2, K2, B2, F, G; the
    /// kept modes' omega, damping_ratio, rigid; the hub-fixed and rigid-body data; warnings.
    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let ex = &self.ex;
            let n = ex.mode_count();
            Ok(match name {
                "A" => mat(py, &ex.first_order().a),
                "B" => mat(py, &ex.first_order().b),
                "C" => mat(py, &ex.first_order().c),
                "D" => mat(py, &ex.first_order().d),
                "state_names" => ex.first_order().state_names.into_bound_py_any(py)?,
                "input_names" => ex.input_names.as_slice().into_bound_py_any(py)?,
                "output_names" => ex.output_names.as_slice().into_bound_py_any(py)?,
                "M2" => mat(py, &Mat::<f64>::identity(n, n)),
                "C2" => mat(py, &ex.damping()),
                "K2" => mat(py, &ex.stiffness()),
                "B2" => mat(py, &ex.b),
                "F" => mat(py, &ex.f),
                "G" => mat(py, &ex.g),
                "omega" => vec1(py, ex.modes.iter().map(|m| m.omega_rad_s)),
                "damping_ratio" => vec1(py, ex.modes.iter().map(|m| m.damping_ratio)),
                "rigid" => ex
                    .modes
                    .iter()
                    .map(|m| m.rigid)
                    .collect::<Vec<bool>>()
                    .into_pyarray(py)
                    .into_any(),
                "site_shapes" => mat(py, &ex.site_shapes),
                "site_positions" => rows(py, ex.site_positions.iter().map(|p| p.0)),
                "total_mass" => ex.total_mass.into_bound_py_any(py)?,
                "center_of_mass" => vec1(py, ex.center_of_mass.0),
                "rigid_mass_reference" => rows(py, ex.rigid_mass_reference),
                "rigid_mass_cm" => rows(py, ex.rigid_mass_cm),
                "hub_fixed_omega" => vec1(py, ex.hub_fixed_omega.iter().copied()),
                "participation" => mat(py, &ex.participation),
                "effective_mass" => mat(py, &ex.effective_mass),
                "effective_mass_fraction" => mat(py, &ex.effective_mass_fraction),
                "appendage_mass" => vec1(py, ex.appendage_mass),
                "warnings" => self.warnings.as_slice().into_bound_py_any(py)?,
                _ => return Err(no_field("export", name)),
            })
        })
    }

    /// Writes what `flexcraft export --out DIR` writes.
    #[pyo3(signature = (dir, force = false))]
    fn write(&self, py: Python<'_>, dir: PathBuf, force: bool) -> PyResult<usize> {
        let settings = &self.scenario.export;
        write_dir(py, &dir, force, |d| {
            output::write_export(
                d,
                &self.model,
                &self.body,
                &self.modes,
                &self.ex,
                &settings.transfers,
                settings.frequency_range_hz,
                settings.frequency_points,
            )
        })
    }
}

/// `flexcraft export`: the linear model for control design.
#[pyfunction]
#[pyo3(signature = (scenario, max_memory = None))]
fn export(py: Python<'_>, scenario: &PyScenario, max_memory: Option<u64>) -> PyResult<PyExport> {
    let file = scenario.file.clone();
    let body = output::flex_body_name(
        &Path::new(&file)
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
    );
    compute(py, || {
        let s = scenario.checked(max_memory)?;
        let model = RitzModel::assemble(&s.structure);
        let wanted = s.export_modes();
        let selection = s.term_selection.as_ref();
        let modes = ModalAnalysis::compute_selected(&model, wanted, selection)
            .map_err(|e| ritz_failure(&s, &model, &e))?;
        non_finite(&file, flexcraft::finite::check_modes(&modes))?;
        let available = modes.elastic().count();
        let mut warnings = Vec::new();
        if let Some(w) = wanted.filter(|w| *w > available) {
            warnings.push(format!(
                "{file}: export.modes: {w} elastic modes asked for, the model has {available}; \
                 all {available} are kept"
            ));
        }
        let ex = ExportModel::build(&model, &modes, &s.export)
            .map_err(|e| Failure::Scenario(s.refuse_export_damping(e.to_string())))?;
        Ok(PyExport {
            scenario: s,
            body,
            model,
            modes,
            ex,
            warnings,
        })
    })
}

/// The library alone: seconds spent in `deploy::simulate_coupled` for the scenario (the
/// reference of python/bench.py's overhead figure; no conversion to Python objects).
#[pyfunction]
fn _library_deploy_seconds(py: Python<'_>, scenario: &PyScenario) -> PyResult<f64> {
    let file = scenario.file.clone();
    compute(py, || {
        let d = scenario.deployment()?;
        let t = std::time::Instant::now();
        let r = flexcraft::deploy::simulate_coupled(&scenario.inner.structure, d)
            .map_err(|e| Failure::Computation(format!("{file}: {e}")))?;
        let s = t.elapsed().as_secs_f64();
        drop(r);
        Ok(s)
    })
}

/// A panic raised on purpose, to test that it reaches Python as `InternalError`.
#[pyfunction]
fn _panic_for_test(py: Python<'_>) -> PyResult<()> {
    compute(py, || -> Result<(), Failure> { panic!("test panic") })
}

#[pymodule]
fn _flexcraft(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ScenarioError", py.get_type::<ScenarioError>())?;
    m.add("ComputationError", py.get_type::<ComputationError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add_class::<PyScenario>()?;
    m.add_class::<PyModes>()?;
    m.add_class::<PyDeployment>()?;
    m.add_class::<PySimulation>()?;
    m.add_class::<PyExport>()?;
    m.add_function(wrap_pyfunction!(modes, m)?)?;
    m.add_function(wrap_pyfunction!(deploy, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(export, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    m.add_function(wrap_pyfunction!(_library_deploy_seconds, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
