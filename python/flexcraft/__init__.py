"""flexcraft: dynamics of flexible spacecraft with deployable solar arrays, from Python.

The Rust library behind the ``flexcraft`` command line, with NumPy results::

    import flexcraft as fc
    sc = fc.Scenario.from_file("examples/seed.toml")
    m = fc.modes(sc)             # natural modes (Rayleigh-Ritz)
    d = fc.deploy(sc)            # deployment of the folded array, latch events
    s = fc.simulate(sc)          # modes, deployment, hand-over, response
    x = fc.export(sc)            # linear model for control design

Units are SI throughout: m, kg, s, N, Pa, rad; frequencies in Hz (``frequency_hz``) and
rad/s (``omega``). Each function does what the command of the same name does, with the same
library calls: ``to_dict()`` / ``summary`` equal the command's ``--json`` output, ``columns``
and ``response`` its CSV files, and ``write(dir)`` writes the files of ``--out dir``.

Computations release the GIL (threads run in parallel); every object pickles (a scenario as
its TOML text, a result as its arrays), so process pools can ship them.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Dict, List, Optional

import numpy as np

from . import _flexcraft as _native
from ._flexcraft import ComputationError, InternalError, ScenarioError

__version__ = _native.__version__

__all__ = [
    "Scenario",
    "ScenarioError",
    "ComputationError",
    "InternalError",
    "Modes",
    "Deployment",
    "Latch",
    "Simulation",
    "LinearModel",
    "SecondOrder",
    "modes",
    "deploy",
    "simulate",
    "export",
]


class Scenario:
    """A validated scenario (a TOML text, format version 1; keys in docs/scenario.md).

    Build one with :meth:`from_file` or :meth:`from_toml`; a refused text raises
    :class:`ScenarioError` with the file, line, column, key and reason. A scenario is
    immutable: :meth:`with_values` returns a new one. It pickles as its TOML text.
    """

    __slots__ = ("_s",)

    def __init__(self, native: "_native._Scenario") -> None:
        self._s = native

    @staticmethod
    def from_file(path) -> "Scenario":
        """Reads and validates a scenario file (at most 16 MiB of UTF-8 TOML)."""
        import os

        return Scenario(_native._Scenario.from_file(os.fspath(path)))

    @staticmethod
    def from_toml(text: str, file: str = "<string>") -> "Scenario":
        """Parses and validates scenario text; ``file`` names it in error messages."""
        return Scenario(_native._Scenario.from_toml(text, file))

    def with_values(self, values: Dict[str, object]) -> "Scenario":
        """This scenario with values replaced at dotted paths, validated like a file.

        Keys are table keys joined by ``.``; a number segment is a 1-based position in an
        array (``deployment.hinges.2.latch_angle``, ``hub.inertia.1``), and an array of
        named components can be entered by name (``beams.mast.length``). Values are numbers
        (SI units), strings or bools. An unknown path or an invalid value raises
        :class:`ScenarioError` whose ``key`` is the path.
        """
        return Scenario(self._s.with_values(dict(values)))

    @property
    def toml(self) -> str:
        """The scenario's text exactly as parsed (overrides applied)."""
        return self._s.toml

    @property
    def name(self) -> str:
        """The scenario's ``name``."""
        return self._s.name

    @property
    def file(self) -> str:
        """The file it was read from (or the name given to :meth:`from_toml`)."""
        return self._s.file

    @property
    def has_deployment(self) -> bool:
        """True when the scenario has a ``[deployment]`` section."""
        return self._s.has_deployment

    @property
    def beams(self) -> List[str]:
        """Beam names, in file order."""
        return self._s.components()[0]

    @property
    def plates(self) -> List[str]:
        """Plate names, in file order."""
        return self._s.components()[1]

    @property
    def masses(self) -> List[str]:
        """Lumped-mass names, in file order."""
        return self._s.components()[2]

    def __reduce__(self):
        return (Scenario.from_toml, (self.toml, self.file))

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Scenario)
            and self.toml == other.toml
            and self.file == other.file
        )

    def __hash__(self) -> int:
        return hash((self.toml, self.file))

    def __repr__(self) -> str:
        return f"Scenario({self.name!r}, file={self.file!r})"


class _Result:
    """What every result shares: the scenario, the arrays, and the native handle (kept in
    memory, not pickled: after unpickling, what needs it — ``write``, mode shapes — runs the
    computation again, which gives the same numbers bit for bit)."""

    _native_fields: tuple = ()

    def __getstate__(self):
        state = dict(self.__dict__)
        state.pop("_h", None)
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._h = None

    def _handle(self):
        if self._h is None:
            self._h = self._recompute()
        return self._h


def _modes_handle(scenario: Scenario, via: str):
    if via == "simulate":
        return _native.simulate(scenario._s).parts()[0]
    return _native.modes(scenario._s)


class Modes(_Result):
    """The natural modes of the deployed spacecraft (``flexcraft modes``).

    Attributes (NumPy arrays; one entry per mode, rigid modes first):

    - ``number``: 1-based mode numbers;
    - ``frequency_hz`` [Hz], ``omega`` [rad/s];
    - ``rigid``: bool, rigid-body (zero-frequency) modes;
    - ``coefficients``: modes × coordinates, the mass-normalised Ritz coefficients
      (φᵀMφ = 1; the hub's six coordinates first when it is free);
    - ``mass_matrix`` [kg, kg·m, kg·m²], ``stiffness_matrix`` [N/m, N, N·m]: the assembled
      Ritz M and K over the generalized coordinates;
    - ``effective_mass``: hub-fixed elastic modes × 6 [kg ×3, kg·m² ×3], directions x, y,
      z, rx, ry, rz about the hub's centre of mass (for a fixed hub, the elastic modes);
    - ``participation``: the signed L_d of the same modes [kg^½, kg^½·m];
    - ``hub_fixed_omega`` [rad/s]; ``appendage_mass``: the limit of the effective-mass
      sums, 6 directions.
    """

    def __init__(self, scenario: Scenario, handle, via: str = "modes") -> None:
        self.scenario = scenario
        self._via = via
        self._h = handle
        a = handle.arrays()
        self.number: np.ndarray = a["number"]
        self.frequency_hz: np.ndarray = a["frequency_hz"]
        self.omega: np.ndarray = a["omega"]
        self.rigid: np.ndarray = a["rigid"]
        self.coefficients: np.ndarray = a["coefficients"]
        self.mass_matrix: np.ndarray = a["mass_matrix"]
        self.stiffness_matrix: np.ndarray = a["stiffness_matrix"]
        self.effective_mass: np.ndarray = a["effective_mass"]
        self.participation: np.ndarray = a["participation"]
        self.hub_fixed_omega: np.ndarray = a["hub_fixed_omega"]
        self.appendage_mass: np.ndarray = a["appendage_mass"]
        self._json: str = handle.json()

    def _recompute(self):
        return _modes_handle(self.scenario, self._via)

    def __len__(self) -> int:
        return len(self.omega)

    def to_dict(self) -> dict:
        """The ``flexcraft modes --json`` object (= modes.json)."""
        return json.loads(self._json)

    def shape(self, component: str, points, mode: Optional[int] = None) -> np.ndarray:
        """Mode shapes of a beam or plate at points.

        ``points``: for a beam, a 1-D array of ξ = x/L in [0, 1] (root to tip); for a
        plate, an n × 2 array of (ξ, η) in [0, 1]² (ξ along the length from the root edge, η
        across the width). Returns modes × points × 6 — the displacement [m] and the small
        rotation [rad] of each point in the structure frame, [ux, uy, uz, rx, ry, rz], per
        unit mass-normalised modal coordinate — or points × 6 for one ``mode`` (its 1-based
        number).
        """
        pts = np.ascontiguousarray(points, dtype=np.float64)
        if pts.ndim == 0:
            pts = pts.reshape(1)
        s = self._handle().shape(component, pts)
        if mode is None:
            return s
        idx = np.nonzero(self.number == mode)[0]
        if len(idx) == 0:
            raise IndexError(f"no mode number {mode} (modes 1…{len(self)})")
        return s[idx[0]]

    def write(self, dir, force: bool = False) -> int:
        """Writes the files of ``flexcraft modes --out dir``; returns how many."""
        import os

        return self._handle().write(os.fspath(dir), force)

    def __repr__(self) -> str:
        return f"Modes({len(self)} modes of {self.scenario.name!r})"


@dataclass(frozen=True, eq=False)
class Latch:
    """One latching (plastic impact) of the deployment.

    ``time`` [s]; ``hinge``: the hinge that reached its latch angle (1-based); ``locked``:
    hinges locked by this event; ``angles`` [rad], ``rates_before``, ``rates_after``
    [rad/s] of every hinge; ``energy_before``, ``energy_after``, ``energy_lost`` [J]
    (kinetic energy); ``hinge_impulses``: hinges × 3, the linear impulse from the inboard
    body on each panel [N·s, deployment-plane u and v] and the angular impulse the hinge
    carries [N·m·s].
    """

    time: float
    hinge: int
    locked: List[int]
    angles: np.ndarray
    rates_before: np.ndarray
    rates_after: np.ndarray
    energy_before: float
    energy_after: float
    energy_lost: float
    hinge_impulses: np.ndarray

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Latch):
            return NotImplemented
        return all(
            np.array_equal(getattr(self, f), getattr(other, f))
            for f in self.__dataclass_fields__
        )

    __hash__ = None  # type: ignore[assignment]


def _deploy_handle(scenario: Scenario, via: str):
    if via == "simulate":
        return _native.simulate(scenario._s).parts()[1]
    return _native.deploy(scenario._s)


class Deployment(_Result):
    """The deployment of the folded array (``flexcraft deploy``).

    ``t`` [s] (samples), ``alpha`` [rad] and ``rate`` [rad/s] (samples × hinges, hinge 1
    at the root), ``latches`` (list of :class:`Latch`), ``all_latched``, ``final_time``
    [s]; ``columns``: every column of deployment.csv by its header name (units in
    brackets); ``to_dict()``: the ``--json`` object (= events.json).
    """

    def __init__(self, scenario: Scenario, handle, via: str = "deploy") -> None:
        self.scenario = scenario
        self._via = via
        self._h = handle
        a = handle.arrays()
        self.t: np.ndarray = a["t"]
        self.alpha: np.ndarray = a["alpha"]
        self.rate: np.ndarray = a["rate"]
        self.latches: List[Latch] = [Latch(**latch) for latch in a["latches"]]
        self.all_latched: bool = a["all_latched"]
        self.final_time: float = a["final_time"]
        self._json: str = handle.json()
        self._columns: Optional[Dict[str, np.ndarray]] = None

    def _recompute(self):
        return _deploy_handle(self.scenario, self._via)

    @property
    def columns(self) -> Dict[str, np.ndarray]:
        """deployment.csv as a dict of arrays (header name → column), read from the text
        the command writes, so the values are the file's to the last bit."""
        if self._columns is None:
            self._columns = _read_csv(self._handle().csv())
        return self._columns

    def to_dict(self) -> dict:
        """The ``flexcraft deploy --json`` object (= events.json)."""
        return json.loads(self._json)

    def write(self, dir, force: bool = False) -> int:
        """Writes the files of ``flexcraft deploy --out dir``; returns how many."""
        import os

        return self._handle().write(os.fspath(dir), force)

    def __repr__(self) -> str:
        return (
            f"Deployment({len(self.t)} samples, {len(self.latches)} latches, "
            f"all latched: {self.all_latched})"
        )


def _read_csv(text: str) -> Dict[str, np.ndarray]:
    lines = text.splitlines()
    header = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]], dtype=np.float64)
    data = data.reshape(len(lines) - 1, len(header))
    return {h: data[:, j].copy() for j, h in enumerate(header)}


class Simulation(_Result):
    """The whole story (``flexcraft simulate``): modes of the deployed spacecraft,
    deployment, hand-over at the final latch and the latch-excited response.

    ``summary``: the ``--json`` object (= summary.json); ``response``: response.csv as a
    dict of arrays by header name (empty when the run has no response, e.g. the array did
    not latch); ``deployment`` (:class:`Deployment`), ``modes`` (:class:`Modes`).
    """

    def __init__(self, scenario: Scenario, handle) -> None:
        self.scenario = scenario
        self._h = handle
        self.summary: dict = json.loads(handle.json())
        r = handle.response()
        self.response: Dict[str, np.ndarray] = (
            {} if r is None else {h: r[1][:, j].copy() for j, h in enumerate(r[0])}
        )
        m, d = handle.parts()
        self.modes = Modes(scenario, m, via="simulate")
        self.deployment = Deployment(scenario, d, via="simulate")

    def _recompute(self):
        return _native.simulate(self.scenario._s)

    def write(self, dir, force: bool = False) -> int:
        """Writes the files and report of ``flexcraft simulate --out dir`` (the folder
        appears whole or not at all; an existing folder not written by flexcraft is refused
        unless ``force``); returns how many files."""
        import os

        return self._handle().write(os.fspath(dir), force)

    def __repr__(self) -> str:
        return f"Simulation({self.scenario.name!r})"


@dataclass(frozen=True, eq=False)
class SecondOrder:
    """The second-order modal form M η̈ + C η̇ + K η = B u, y = F η + G η̇ (M = I, the
    modes mass-normalised; C = diag(2ζω) [1/s], K = diag(ω²) [1/s²])."""

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    B: np.ndarray
    F: np.ndarray
    G: np.ndarray


class LinearModel(_Result):
    """The linear model for control design (``flexcraft export``; docs/export.md).

    First order, x = [η; η̇]: ``A``, ``B``, ``C``, ``D`` with ``state_names``,
    ``input_names``, ``output_names``; ``second_order`` (:class:`SecondOrder`); modal data
    ``omega`` [rad/s], ``frequency_hz`` [Hz], ``damping_ratio``, ``rigid``; the hub-fixed
    modes' ``hub_fixed_omega`` [rad/s], ``participation``, ``effective_mass``,
    ``effective_mass_fraction`` (6 × modes); ``total_mass`` [kg], ``center_of_mass`` [m],
    ``rigid_mass_reference``, ``rigid_mass_cm`` (6 × 6), ``appendage_mass``;
    ``site_positions`` [m] and ``site_shapes`` (mode shapes at the hub reference point and
    the named points); ``warnings``; ``to_dict()`` (= model.json).
    """

    def __init__(self, scenario: Scenario, handle) -> None:
        self.scenario = scenario
        self._h = handle
        a = handle.arrays()
        self.A: np.ndarray = a["A"]
        self.B: np.ndarray = a["B"]
        self.C: np.ndarray = a["C"]
        self.D: np.ndarray = a["D"]
        self.state_names: List[str] = a["state_names"]
        self.input_names: List[str] = a["input_names"]
        self.output_names: List[str] = a["output_names"]
        self.second_order = SecondOrder(a["M2"], a["C2"], a["K2"], a["B2"], a["F"], a["G"])
        self.omega: np.ndarray = a["omega"]
        self.frequency_hz: np.ndarray = a["omega"] / (2.0 * np.pi)
        self.damping_ratio: np.ndarray = a["damping_ratio"]
        self.rigid: np.ndarray = a["rigid"]
        self.hub_fixed_omega: np.ndarray = a["hub_fixed_omega"]
        self.participation: np.ndarray = a["participation"]
        self.effective_mass: np.ndarray = a["effective_mass"]
        self.effective_mass_fraction: np.ndarray = a["effective_mass_fraction"]
        self.total_mass: float = a["total_mass"]
        self.center_of_mass: np.ndarray = a["center_of_mass"]
        self.rigid_mass_reference: np.ndarray = a["rigid_mass_reference"]
        self.rigid_mass_cm: np.ndarray = a["rigid_mass_cm"]
        self.appendage_mass: np.ndarray = a["appendage_mass"]
        self.site_positions: np.ndarray = a["site_positions"]
        self.site_shapes: np.ndarray = a["site_shapes"]
        self.warnings: List[str] = handle.warnings()
        self._json: str = handle.json()

    def _recompute(self):
        return _native.export(self.scenario._s)

    def to_dict(self) -> dict:
        """The ``flexcraft export --json`` object (= model.json)."""
        return json.loads(self._json)

    def write(self, dir, force: bool = False) -> int:
        """Writes the files of ``flexcraft export --out dir``; returns how many."""
        import os

        return self._handle().write(os.fspath(dir), force)

    def __repr__(self) -> str:
        return (
            f"LinearModel({len(self.state_names)} states, {len(self.input_names)} inputs, "
            f"{len(self.output_names)} outputs)"
        )


def _need(scenario) -> Scenario:
    if not isinstance(scenario, Scenario):
        raise TypeError(f"expected a flexcraft.Scenario, not {type(scenario).__name__}")
    return scenario


def modes(scenario: Scenario, max_memory: Optional[int] = None) -> Modes:
    """Natural modes of the deployed spacecraft by Rayleigh–Ritz (``flexcraft modes``).

    ``max_memory``: refuse a run whose estimated peak memory exceeds this many bytes
    (default: half of the machine's memory), as the command line does.
    """
    sc = _need(scenario)
    return Modes(sc, _native.modes(sc._s, max_memory))


def deploy(scenario: Scenario, max_memory: Optional[int] = None) -> Deployment:
    """Deployment of the folded array in ``[deployment]`` (``flexcraft deploy``); a
    scenario without that section raises :class:`ScenarioError` (key ``deployment``)."""
    sc = _need(scenario)
    return Deployment(sc, _native.deploy(sc._s, max_memory))


def simulate(scenario: Scenario, max_memory: Optional[int] = None) -> Simulation:
    """Modes, deployment, hand-over at the final latch and response (``flexcraft
    simulate``)."""
    sc = _need(scenario)
    return Simulation(sc, _native.simulate(sc._s, max_memory))


def export(scenario: Scenario, max_memory: Optional[int] = None) -> LinearModel:
    """The linear model for control design (``flexcraft export``)."""
    sc = _need(scenario)
    return LinearModel(sc, _native.export(sc._s, max_memory))
