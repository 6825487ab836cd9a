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

A result holds the Rust result; each attribute is made (a NumPy array, a list, a dict) when
it is first read, then kept. Neither ``import flexcraft`` nor a computation imports NumPy:
the first array read does.

Computations release the GIL (threads run in parallel); every object pickles (a scenario as
its TOML text, a result as its arrays), so process pools can ship them.
"""

from __future__ import annotations

import math

from . import _flexcraft as _native
from ._flexcraft import ComputationError, InternalError, ScenarioError

# For type checkers only: NumPy (about 100 ms to import), typing and dataclasses are not
# imported with the package (the annotations are strings: `from __future__ import
# annotations`).
TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any, Callable, Dict, List, Optional

    import numpy as np

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


class _Lazy:
    """A result's attribute, made from the Rust result when first read, then kept in the
    instance (a non-data descriptor: the instance's value wins from then on).

    ``make(result)`` builds it; by default the native handle's ``field(name)``. A
    ``pickled`` attribute is made before pickling, so that the unpickled result has it
    without the native handle; the others are made again from what was pickled, or by
    computing again (``Deployment.columns``).
    """

    def __init__(self, doc: str, make: Optional[Callable[[Any], Any]], pickled: bool) -> None:
        self.__doc__ = doc
        self.make = make
        self.pickled = pickled
        self.name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, obj: Any, owner: Optional[type] = None) -> Any:
        if obj is None:
            return self
        value = obj._handle().field(self.name) if self.make is None else self.make(obj)
        obj.__dict__[self.name] = value
        return value


def _lazy(doc: str, make: Optional[Callable[[Any], Any]] = None, pickled: bool = True) -> Any:
    """An attribute made on first read (:class:`_Lazy`); typed ``Any`` so that the class
    body's annotation (``omega: np.ndarray = _lazy(...)``) is the attribute's type."""
    return _Lazy(doc, make, pickled)


class _Result:
    """What every result shares: its scenario, the native handle on the Rust result, the
    attributes made from it on first read, ``to_dict``, ``write`` and pickling.

    The handle is kept in memory, not pickled: a result pickles as its attributes (all made
    first), and after unpickling what needs the handle — ``write``, ``Modes.shape``,
    ``Deployment.columns`` — runs the computation again, which gives the same numbers bit
    for bit (the library is deterministic).
    """

    #: The command, and native function, that makes the result.
    _command = ""
    #: Its index in ``_native.simulate(...).parts()``, for the modes and deployment of a
    #: simulation.
    _part = -1
    #: The attributes made before pickling (every `_lazy` with pickled=True).
    _pickled: tuple = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls._pickled = tuple(
            name
            for klass in reversed(cls.__mro__)
            for name, v in vars(klass).items()
            if isinstance(v, _Lazy) and v.pickled
        )

    def __init__(self, scenario: Scenario, handle: Any, via: str = "") -> None:
        self.scenario = scenario
        self._h = handle
        self._via = via or self._command

    def _handle(self) -> Any:
        if self._h is None:
            made = getattr(_native, self._via)(self.scenario._s)
            self._h = made if self._via == self._command else made.parts()[self._part]
        return self._h

    _json: str = _lazy("The command's --json text.", lambda r: r._handle().json())

    def to_dict(self) -> dict:
        """The command's ``--json`` object, which is also the JSON file its ``--out``
        writes: ``modes`` → modes.json, ``deploy`` → events.json, ``simulate`` →
        summary.json, ``export`` → model.json. A new dict each call."""
        import json

        return json.loads(self._json)

    def write(self, dir: Any, force: bool = False) -> int:
        """Writes the files (and, for a simulation, the report) of ``flexcraft <command>
        --out dir`` and returns how many. The folder appears whole or not at all; an
        existing folder that flexcraft did not write is refused (``OSError``) unless
        ``force``."""
        import os

        return self._handle().write(os.fspath(dir), force)

    def __getstate__(self) -> dict:
        for name in self._pickled:
            getattr(self, name)
        state = dict(self.__dict__)
        state.pop("_h", None)
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._h = None


class _Record:
    """A small immutable record of named values (floats, lists, NumPy arrays), compared
    value by value (``np.array_equal``); pickles as its values. The subclasses list their
    fields in ``_fields`` (and ``__slots__``)."""

    __slots__ = ()
    _fields: tuple = ()

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        values = dict(zip(self._fields, args))
        values.update(kwargs)
        if len(args) > len(self._fields) or set(values) != set(self._fields):
            raise TypeError(f"{type(self).__name__} takes the fields {', '.join(self._fields)}")
        for name in self._fields:
            object.__setattr__(self, name, values[name])

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable")

    def __reduce__(self) -> tuple:
        return (type(self), tuple(getattr(self, f) for f in self._fields))

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        import numpy as np

        return all(np.array_equal(getattr(self, f), getattr(other, f)) for f in self._fields)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        fields = ", ".join(f"{f}={getattr(self, f)!r}" for f in self._fields)
        return f"{type(self).__name__}({fields})"


class Modes(_Result):
    """The natural modes of the deployed spacecraft (``flexcraft modes``).

    Attributes (NumPy arrays, made on first read; one entry per mode, rigid modes first):

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

    ``to_dict()`` is ``flexcraft modes --json`` (= modes.json).
    """

    _command = "modes"
    _part = 0

    number: np.ndarray = _lazy("1-based mode numbers (int64).")
    frequency_hz: np.ndarray = _lazy("Natural frequencies [Hz].")
    omega: np.ndarray = _lazy("Natural circular frequencies [rad/s].")
    rigid: np.ndarray = _lazy("True for a rigid-body (zero-frequency) mode.")
    coefficients: np.ndarray = _lazy(
        "Modes × coordinates: the mass-normalised Ritz coefficients (ΦᵀMΦ = I)."
    )
    mass_matrix: np.ndarray = _lazy("The assembled Ritz mass matrix M.")
    stiffness_matrix: np.ndarray = _lazy("The assembled Ritz stiffness matrix K.")
    effective_mass: np.ndarray = _lazy(
        "Hub-fixed elastic modes × 6: effective masses x, y, z [kg], rx, ry, rz [kg·m²]."
    )
    participation: np.ndarray = _lazy(
        "Hub-fixed elastic modes × 6: the signed participation L_d [kg^½, kg^½·m]."
    )
    hub_fixed_omega: np.ndarray = _lazy("The hub-fixed modes' ω [rad/s].")
    appendage_mass: np.ndarray = _lazy("The effective-mass sums' limit, 6 directions.")

    def __len__(self) -> int:
        return len(self.number)

    def shape(self, component: str, points: Any, mode: Optional[int] = None) -> np.ndarray:
        """Mode shapes of a beam or plate at points.

        ``points``: for a beam, a 1-D array of ξ = x/L in [0, 1] (root to tip); for a
        plate, an n × 2 array of (ξ, η) in [0, 1]² (ξ along the length from the root edge, η
        across the width). Returns modes × points × 6 — the displacement [m] and the small
        rotation [rad] of each point in the structure frame, [ux, uy, uz, rx, ry, rz], per
        unit mass-normalised modal coordinate — or points × 6 for one ``mode`` (its 1-based
        number).
        """
        import numpy as np

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

    def __repr__(self) -> str:
        return f"Modes({len(self)} modes of {self.scenario.name!r})"


class Latch(_Record):
    """One latching (plastic impact) of the deployment.

    ``time`` [s]; ``hinge``: the hinge that reached its latch angle (1-based); ``locked``:
    hinges locked by this event; ``angles`` [rad], ``rates_before``, ``rates_after``
    [rad/s] of every hinge; ``energy_before``, ``energy_after``, ``energy_lost`` [J]
    (kinetic energy); ``hinge_impulses``: hinges × 3, the linear impulse from the inboard
    body on each panel [N·s, deployment-plane u and v] and the angular impulse the hinge
    carries [N·m·s].
    """

    __slots__ = _fields = (
        "time",
        "hinge",
        "locked",
        "angles",
        "rates_before",
        "rates_after",
        "energy_before",
        "energy_after",
        "energy_lost",
        "hinge_impulses",
    )
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


def _read_csv(text: str) -> Dict[str, np.ndarray]:
    import numpy as np

    lines = text.splitlines()
    header = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]], dtype=np.float64)
    data = data.reshape(len(lines) - 1, len(header))
    return {h: data[:, j].copy() for j, h in enumerate(header)}


class Deployment(_Result):
    """The deployment of the folded array (``flexcraft deploy``).

    ``t`` [s] (samples), ``alpha`` [rad] and ``rate`` [rad/s] (samples × hinges, hinge 1
    at the root), ``latches`` (list of :class:`Latch`), ``all_latched``, ``final_time``
    [s]; ``columns``: every column of deployment.csv by its header name (units in
    brackets); ``to_dict()``: the ``--json`` object (= events.json). Each is made on first
    read.
    """

    _command = "deploy"
    _part = 1

    t: np.ndarray = _lazy("Sample times [s]: t = k/output_rate, plus two rows at every latch.")
    alpha: np.ndarray = _lazy("Hinge angles [rad], samples × hinges (hinge 1 at the root).")
    rate: np.ndarray = _lazy("Hinge rates [rad/s], samples × hinges.")
    latches: List[Latch] = _lazy(
        "The latch events, in time order (:class:`Latch`).",
        lambda r: [Latch(**latch) for latch in r._handle().field("latches")],
    )
    all_latched: bool = _lazy("True when every hinge latched.")
    final_time: float = _lazy("The time the deployment ended [s].")
    columns: Dict[str, np.ndarray] = _lazy(
        "deployment.csv as a dict of arrays (header name → column), read from the text the "
        "command writes, so the values are the file's to the last bit.",
        lambda r: _read_csv(r._handle().csv()),
        pickled=False,
    )

    def __repr__(self) -> str:
        return (
            f"Deployment({len(self.t)} samples, {len(self.latches)} latches, "
            f"all latched: {self.all_latched})"
        )


def _response_columns(sim: Simulation) -> Dict[str, np.ndarray]:
    r = sim._handle().response()
    return {} if r is None else {h: r[1][:, j].copy() for j, h in enumerate(r[0])}


class Simulation(_Result):
    """The whole story (``flexcraft simulate``): modes of the deployed spacecraft,
    deployment, hand-over at the final latch and the latch-excited response.

    ``summary``: the ``--json`` object (= summary.json, also ``to_dict()``); ``response``:
    response.csv as a dict of arrays by header name (empty when the run has no response,
    e.g. the array did not latch); ``deployment`` (:class:`Deployment`), ``modes``
    (:class:`Modes`). Each is made on first read.
    """

    _command = "simulate"

    summary: dict = _lazy(
        "The --json object (= summary.json).", lambda r: r.to_dict(), pickled=False
    )
    response: Dict[str, np.ndarray] = _lazy(
        "response.csv as a dict of arrays by header name (empty without a response).",
        _response_columns,
    )
    modes: Modes = _lazy(
        "The deployed spacecraft's modes (all of them).",
        lambda r: Modes(r.scenario, r._handle().parts()[0], via="simulate"),
    )
    deployment: Deployment = _lazy(
        "The run's deployment.",
        lambda r: Deployment(r.scenario, r._handle().parts()[1], via="simulate"),
    )

    def __repr__(self) -> str:
        return f"Simulation({self.scenario.name!r})"


class SecondOrder(_Record):
    """The second-order modal form M η̈ + C η̇ + K η = B u, y = F η + G η̇ (M = I, the
    modes mass-normalised; C = diag(2ζω) [1/s], K = diag(ω²) [1/s²])."""

    __slots__ = _fields = ("M", "C", "K", "B", "F", "G")
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
    the named points); ``warnings``; ``to_dict()`` (= model.json). Each is made on first
    read.
    """

    _command = "export"

    A: np.ndarray = _lazy("State matrix of x = [η; η̇].")
    B: np.ndarray = _lazy("Input matrix.")
    C: np.ndarray = _lazy("Output matrix.")
    D: np.ndarray = _lazy("Feed-through matrix.")
    state_names: List[str] = _lazy("Names of the states x.")
    input_names: List[str] = _lazy("Names of the inputs u.")
    output_names: List[str] = _lazy("Names of the outputs y.")
    second_order: SecondOrder = _lazy(
        "The second-order form (:class:`SecondOrder`).",
        lambda r: SecondOrder(*(r._handle().field(k) for k in ("M2", "C2", "K2", "B2", "F", "G"))),
    )
    omega: np.ndarray = _lazy("The kept modes' ω [rad/s].")
    frequency_hz: np.ndarray = _lazy(
        "The kept modes' frequencies [Hz].", lambda r: r.omega / (2.0 * math.pi), pickled=False
    )
    damping_ratio: np.ndarray = _lazy("The kept modes' damping ratios ζ.")
    rigid: np.ndarray = _lazy("True for a kept rigid-body mode.")
    hub_fixed_omega: np.ndarray = _lazy("The hub-fixed modes' ω [rad/s].")
    participation: np.ndarray = _lazy("Participation factors of the hub-fixed modes (6 × modes).")
    effective_mass: np.ndarray = _lazy("Effective masses of the hub-fixed modes (6 × modes).")
    effective_mass_fraction: np.ndarray = _lazy(
        "Effective masses as fractions of the appendage mass (6 × modes)."
    )
    total_mass: float = _lazy("Total mass [kg].")
    center_of_mass: np.ndarray = _lazy("Centre of mass [m] (structure frame).")
    rigid_mass_reference: np.ndarray = _lazy("6 × 6 rigid-body mass matrix about the reference point.")
    rigid_mass_cm: np.ndarray = _lazy("6 × 6 rigid-body mass matrix about the centre of mass.")
    appendage_mass: np.ndarray = _lazy("The effective-mass sums' limit, 6 directions.")
    site_positions: np.ndarray = _lazy("The hub reference point and the named points [m].")
    site_shapes: np.ndarray = _lazy("The mode shapes at the sites.")
    warnings: List[str] = _lazy("The command's warnings (e.g. fewer modes than asked for).")

    def __repr__(self) -> str:
        return (
            f"LinearModel({len(self.state_names)} states, {len(self.input_names)} inputs, "
            f"{len(self.output_names)} outputs)"
        )


def _need(scenario: Any) -> Scenario:
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
