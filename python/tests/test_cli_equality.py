"""Results equal the command line's JSON and CSV for the same scenarios, to the last bit:
JSON objects compared after json.loads (the same floats: both sides parse the same text),
CSV columns compared as float64 arrays with exact equality."""

from __future__ import annotations

import csv
import filecmp
import io
import math

import numpy as np
import pytest

import flexcraft as fc
from conftest import EXAMPLES, cli_json

MODE_EXAMPLES = [
    "seed.toml",
    "tip_mass.toml",
    "cantilever_plate.toml",
    "composite.toml",
    "free_hub.toml",
    "seed_characteristic.toml",
]


def read_csv(path) -> dict:
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    data = np.array([[float(v) for v in r] for r in body], dtype=np.float64)
    return {h: data[:, j] for j, h in enumerate(header)}


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("name", MODE_EXAMPLES)
def test_modes_to_dict_equals_cli_json(name):
    path = EXAMPLES / name
    m = fc.modes(fc.Scenario.from_file(path))
    want = cli_json("modes", path)
    assert m.to_dict() == want
    # The arrays are the JSON's numbers.
    freqs = [mode["frequency_hz"] for mode in want["modes"]] if "modes" in want else None
    if freqs is not None and all(isinstance(f, float) for f in freqs):
        assert same_bits(m.frequency_hz, np.array(freqs))


def test_modes_arrays_are_consistent(seed):
    m = fc.modes(seed)
    assert same_bits(m.frequency_hz, m.omega / (2 * math.pi))
    assert m.rigid.dtype == np.bool_
    assert m.rigid.sum() == 6  # free hub: six rigid-body modes
    n = m.mass_matrix.shape[0]
    assert m.coefficients.shape == (len(m), n)
    # Mass-normalised: Φᵀ M Φ = I, Φᵀ K Φ = diag(ω²).
    phi = m.coefficients.T
    assert np.allclose(phi.T @ m.mass_matrix @ phi, np.eye(len(m)), atol=1e-8)
    k = phi.T @ m.stiffness_matrix @ phi
    assert np.allclose(np.diag(k), m.omega**2, rtol=1e-8, atol=1e-6)


def test_deploy_equals_cli_json_and_csv(seed, seed_path, tmp_path):
    d = fc.deploy(seed)
    assert d.to_dict() == cli_json("deploy", seed_path)
    # deployment.csv of `flexcraft simulate --out` (the same deployment) vs .columns.
    from conftest import run_cli

    out = tmp_path / "dep"
    p = run_cli("deploy", str(seed_path), "--out", str(out))
    assert p.returncode == 0, p.stderr
    want = read_csv(out / "deployment.csv")
    got = d.columns
    assert list(got) == list(want)
    for k in want:
        assert same_bits(got[k], want[k]), k
    # t, alpha, rate are the CSV's columns.
    assert same_bits(d.t, want["t [s]"])
    for i in range(d.alpha.shape[1]):
        assert same_bits(d.alpha[:, i], want[f"alpha_{i + 1} [rad]"])
        assert same_bits(d.rate[:, i], want[f"rate_{i + 1} [rad/s]"])
    # write() gives the command's folder.
    d.write(tmp_path / "py")
    assert_same_tree(out, tmp_path / "py")
    assert len(d.latches) >= 1
    assert d.latches[0].energy_lost == d.latches[0].energy_before - d.latches[0].energy_after


def test_simulate_equals_cli(seed_simulation, seed_path, seed_cli_out, tmp_path):
    s = seed_simulation
    assert s.summary == cli_json("simulate", seed_path)
    want = read_csv(seed_cli_out / "response.csv")
    assert list(s.response) == list(want)
    for k in want:
        assert same_bits(s.response[k], want[k]), k
    dep = read_csv(seed_cli_out / "deployment.csv")
    for k in dep:
        assert same_bits(s.deployment.columns[k], dep[k]), k
    import json

    assert s.modes.to_dict() == json.loads((seed_cli_out / "modes.json").read_text())


def assert_same_tree(a, b):
    """The same files in both folders, byte for byte."""

    def walk(c, rel=""):
        assert not c.left_only and not c.right_only, (rel, c.left_only, c.right_only)
        _, mismatch, errors = filecmp.cmpfiles(c.left, c.right, c.common_files, shallow=False)
        assert not mismatch and not errors, (rel, mismatch, errors)
        for name, sub in c.subdirs.items():
            walk(sub, f"{rel}/{name}")

    walk(filecmp.dircmp(a, b))


def test_simulate_write_equals_cli_out(seed_simulation, seed_cli_out, tmp_path):
    out = tmp_path / "py"
    assert seed_simulation.write(out) > 0
    assert_same_tree(seed_cli_out, out)


@pytest.mark.parametrize("command", ["modes", "export"])
def test_modes_and_export_write_equal_cli_out(command, tmp_path):
    from conftest import run_cli

    path = EXAMPLES / "export.toml"
    cli = tmp_path / "cli"
    p = run_cli(command, str(path), "--out", str(cli))
    assert p.returncode == 0, p.stderr
    result = getattr(fc, command)(fc.Scenario.from_file(path))
    assert result.write(tmp_path / "py") > 0
    assert_same_tree(cli, tmp_path / "py")


def test_export_equals_cli_json():
    path = EXAMPLES / "export.toml"
    x = fc.export(fc.Scenario.from_file(path))
    want = cli_json("export", path)
    assert x.to_dict() == want
    n = len(x.omega)
    assert x.A.shape == (2 * n, 2 * n)
    assert x.B.shape == (2 * n, len(x.input_names))
    assert x.C.shape == (len(x.output_names), 2 * n)
    assert x.D.shape == (len(x.output_names), len(x.input_names))
    assert len(x.state_names) == 2 * n
    # First order from second order: A = [[0, I], [−K, −C]], B = [0; B2], C = [F, G].
    so = x.second_order
    assert np.array_equal(x.A[n:, :n], -so.K)  # (−0.0 off the diagonal)
    assert same_bits(x.B[n:], so.B)
    assert same_bits(x.C, np.hstack([so.F, so.G]))
