"""Results hold the Rust result and make each attribute on first read: `import flexcraft` and
a computation do not import NumPy; attributes are made once; a pickled result carries every
attribute, so the unpickled one needs no computation to read them."""

from __future__ import annotations

import json
import pickle
import subprocess
import sys

import numpy as np
import pytest

import flexcraft as fc
from conftest import EXAMPLES, cli_json

FRESH = """
import json, sys
import flexcraft as fc
seen = {"import": "numpy" in sys.modules}
sc = fc.Scenario.from_file(sys.argv[1])
m = fc.modes(sc)
d = fc.deploy(sc.with_values({"deployment.end_time": 1.0}))
x = fc.export(sc)
out = {"modes": m.to_dict(), "deploy": d.to_dict(), "export": x.to_dict()}
seen["computations and to_dict"] = "numpy" in sys.modules
f = m.frequency_hz
seen["an array read"] = "numpy" in sys.modules
print(json.dumps({"seen": seen, "frequency_hz": f.tolist(), "modes": out["modes"]}))
"""


def test_import_and_computations_do_not_import_numpy(tmp_path):
    """In a fresh interpreter: NumPy is imported by the first array read, not before."""
    seed = EXAMPLES / "seed.toml"
    p = subprocess.run(
        [sys.executable, "-c", FRESH, str(seed)],
        capture_output=True,
        text=True,
        cwd=tmp_path,  # `import flexcraft` is the installed package
    )
    assert p.returncode == 0, p.stderr
    got = json.loads(p.stdout)
    assert got["seen"] == {
        "import": False,
        "computations and to_dict": False,
        "an array read": True,
    }
    # The lazily made array is the command line's numbers.
    want = cli_json("modes", seed)
    assert got["modes"] == want
    assert got["frequency_hz"] == [mode["frequency_hz"] for mode in want["modes"]]


def test_attributes_are_made_once(seed):
    m = fc.modes(seed)
    assert m.omega is m.omega
    assert m.coefficients is m.coefficients
    x = fc.export(seed)
    assert x.second_order is x.second_order and x.A is x.A
    assert np.array_equal(x.frequency_hz, x.omega / (2 * np.pi))


MODES_ATTRIBUTES = [
    "number",
    "frequency_hz",
    "omega",
    "rigid",
    "coefficients",
    "mass_matrix",
    "stiffness_matrix",
    "effective_mass",
    "participation",
    "hub_fixed_omega",
    "appendage_mass",
]
EXPORT_ATTRIBUTES = [
    "A",
    "B",
    "C",
    "D",
    "state_names",
    "input_names",
    "output_names",
    "second_order",
    "omega",
    "frequency_hz",
    "damping_ratio",
    "rigid",
    "hub_fixed_omega",
    "participation",
    "effective_mass",
    "effective_mass_fraction",
    "total_mass",
    "center_of_mass",
    "rigid_mass_reference",
    "rigid_mass_cm",
    "appendage_mass",
    "site_positions",
    "site_shapes",
    "warnings",
]


def same(a, b) -> bool:
    if isinstance(a, fc.SecondOrder):
        return a == b
    return np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b


@pytest.mark.parametrize(
    "command, example, attributes",
    [
        ("modes", "seed.toml", MODES_ATTRIBUTES),
        ("export", "export.toml", EXPORT_ATTRIBUTES),
    ],
)
def test_unpickled_result_reads_without_computing(command, example, attributes, monkeypatch):
    """A result pickled before any attribute was read still carries them all: reading them
    after unpickling computes nothing (the native functions are replaced by a trap)."""
    path = EXAMPLES / example
    r = getattr(fc, command)(fc.Scenario.from_file(path))
    blob = pickle.dumps(r)

    def trap(*args, **kwargs):
        raise AssertionError("computed again")

    for name in ("modes", "deploy", "simulate", "export"):
        monkeypatch.setattr(fc._native, name, trap)
    r2 = pickle.loads(blob)
    assert r2.to_dict() == cli_json(command, path)
    for name in attributes:
        assert same(getattr(r2, name), getattr(r, name)), name


def test_unpickled_deployment_and_simulation_read_without_computing(seed_simulation, monkeypatch):
    blob = pickle.dumps(seed_simulation)
    monkeypatch.setattr(fc._native, "simulate", lambda *a, **k: pytest.fail("computed again"))
    s = pickle.loads(blob)
    assert s.summary == seed_simulation.summary
    assert list(s.response) == list(seed_simulation.response)
    d, d0 = s.deployment, seed_simulation.deployment
    for name in ("t", "alpha", "rate", "latches", "all_latched", "final_time"):
        assert same(getattr(d, name), getattr(d0, name)), name
    assert s.modes.to_dict() == seed_simulation.modes.to_dict()
