"""Errors with their location, a caught panic, pickling (errors and results, through process
pools too), threads. (Mutated files and hostile overrides: test_fuzz.py.)"""

from __future__ import annotations

import concurrent.futures as cf
import copy
import pickle
import time
from pathlib import Path

import numpy as np
import pytest

import flexcraft as fc
from conftest import EXAMPLES, cli_json, run_cli


def test_broken_file_error_carries_location(tmp_path):
    text = (EXAMPLES / "tip_mass.toml").read_text()
    broken = text.replace("length = 2.0", "length = -2.0")
    lines = broken.splitlines()
    line = next(i for i, l in enumerate(lines, 1) if "length = -2.0" in l)
    path = tmp_path / "broken.toml"
    path.write_text(broken)
    with pytest.raises(fc.ScenarioError) as info:
        fc.Scenario.from_file(path)
    e = info.value
    assert isinstance(e, ValueError)
    assert e.file == str(path)
    assert e.line == line
    assert e.column == lines[line - 1].index("-2.0") + 1
    assert e.key.endswith("length")
    assert e.kind == "invalid"
    assert e.reason
    # The same message as the command line's ("error: " + message on stderr, status 2).
    p = run_cli("modes", str(path))
    assert p.returncode == 2
    assert p.stderr.strip() == f"error: {e}"


def test_syntax_error_and_missing_file(tmp_path):
    with pytest.raises(fc.ScenarioError) as info:
        fc.Scenario.from_toml('name = "x"\nformat_version = 1\n[hub\n', "bad.toml")
    assert (info.value.file, info.value.line, info.value.kind) == ("bad.toml", 3, "syntax")
    with pytest.raises(fc.ScenarioError) as info:
        fc.Scenario.from_file(tmp_path / "nope.toml")
    assert info.value.kind == "io" and info.value.line == 0


def test_overrides_are_validated(seed):
    s2 = seed.with_values({"deployment.hinge.stiffness": 3.0, "beams.mast.length": 14.0})
    assert "stiffness = 3.0" in s2.toml
    assert s2 != seed
    with pytest.raises(fc.ScenarioError) as info:
        seed.with_values({"beams.nosuch.length": 1.0})
    assert info.value.key == "beams.nosuch.length"
    with pytest.raises(fc.ScenarioError):
        seed.with_values({"beams.mast.length": -1.0})
    with pytest.raises(TypeError):
        seed.with_values({"beams.mast.length": [1.0]})


def test_no_deployment_section_is_a_scenario_error():
    sc = fc.Scenario.from_file(EXAMPLES / "tip_mass.toml")
    with pytest.raises(fc.ScenarioError) as info:
        fc.deploy(sc)
    assert info.value.key == "deployment"


def test_a_panic_becomes_internal_error():
    with pytest.raises(fc.InternalError, match="test panic"):
        fc._native._panic_for_test()


ERROR_FIELDS = ("file", "line", "column", "key", "reason", "kind")


def broken_tip_mass(tmp_path):
    """tip_mass.toml with a negative beam length: the path, the line and the column of the
    bad value, found in the text (the error's independent truth)."""
    text = (EXAMPLES / "tip_mass.toml").read_text().replace("length = 2.0", "length = -2.0")
    lines = text.splitlines()
    line = next(i for i, l in enumerate(lines, 1) if "length = -2.0" in l)
    path = tmp_path / "broken.toml"
    path.write_text(text)
    return path, line, lines[line - 1].index("-2.0") + 1


def fields(e) -> dict:
    return {f: getattr(e, f) for f in ERROR_FIELDS}


@pytest.mark.parametrize("protocol", range(pickle.HIGHEST_PROTOCOL + 1))
def test_scenario_error_pickles_whole(protocol, tmp_path):
    """A ScenarioError unpickles as a ScenarioError (a ValueError) with the command line's
    message and every field."""
    path, line, column = broken_tip_mass(tmp_path)
    with pytest.raises(fc.ScenarioError) as info:
        fc.Scenario.from_file(path)
    e = info.value
    for e2 in (pickle.loads(pickle.dumps(e, protocol=protocol)), copy.deepcopy(e)):
        assert type(e2) is fc.ScenarioError and isinstance(e2, ValueError)
        assert fields(e2) == fields(e)
        assert (e2.file, e2.line, e2.column) == (str(path), line, column)
        assert str(e2) == str(e) == run_cli("modes", str(path)).stderr.strip()[len("error: ") :]


def _load(path: str):
    return fc.Scenario.from_file(path)


def _override(path: str, key: str, value):
    return fc.Scenario.from_file(path).with_values({key: value})


def _deploy(path: str):
    return fc.deploy(fc.Scenario.from_file(path))


def _modes(path: str):
    return fc.modes(fc.Scenario.from_file(path))


def test_errors_and_results_cross_a_process_pool(tmp_path):
    """Raised in a worker process, a ScenarioError arrives whole in the parent (pickled by
    concurrent.futures); so does a result."""
    path, line, column = broken_tip_mass(tmp_path)
    tip = str(EXAMPLES / "tip_mass.toml")
    with cf.ProcessPoolExecutor(max_workers=2) as pool:
        jobs = {
            "file": pool.submit(_load, str(path)),
            "override": pool.submit(_override, tip, "beams.beam.length", -1.0),
            "unknown key": pool.submit(_override, tip, "beams.nosuch.length", 1.0),
            "no deployment": pool.submit(_deploy, tip),
            "modes": pool.submit(_modes, tip),
        }
        errors = {}
        for name, job in jobs.items():
            if name == "modes":
                continue
            with pytest.raises(fc.ScenarioError) as info:
                job.result()
            errors[name] = info.value
        m = jobs["modes"].result()
    # Each error is the one raised here, in this process, field for field.
    for name, local in [
        ("file", lambda: _load(str(path))),
        ("override", lambda: _override(tip, "beams.beam.length", -1.0)),
        ("unknown key", lambda: _override(tip, "beams.nosuch.length", 1.0)),
        ("no deployment", lambda: _deploy(tip)),
    ]:
        with pytest.raises(fc.ScenarioError) as info:
            local()
        assert type(errors[name]) is fc.ScenarioError, name
        assert fields(errors[name]) == fields(info.value), name
        assert str(errors[name]) == str(info.value), name
    e = errors["file"]
    assert (e.file, e.line, e.column, e.kind) == (str(path), line, column, "invalid")
    assert e.key.endswith("length")
    assert f"error: {e}" == run_cli("modes", str(path)).stderr.strip()
    assert errors["unknown key"].key == "beams.nosuch.length"
    assert errors["no deployment"].key == "deployment"
    assert m.to_dict() == cli_json("modes", Path(tip))
    assert np.array_equal(m.frequency_hz, [x["frequency_hz"] for x in cli_json("modes", Path(tip))["modes"]])


def test_pickling_round_trips(seed, seed_simulation):
    s = pickle.loads(pickle.dumps(seed))
    assert s == seed and s.toml == seed.toml and s.file == seed.file
    m = fc.modes(fc.Scenario.from_file(EXAMPLES / "tip_mass.toml"))
    m2 = pickle.loads(pickle.dumps(m))
    assert m2.to_dict() == m.to_dict()
    assert np.array_equal(m2.coefficients, m.coefficients)
    # What needs the native result is computed again, to the same bits.
    pts = np.linspace(0, 1, 5)
    assert np.array_equal(m2.shape("beam", pts), m.shape("beam", pts))
    sim = pickle.loads(pickle.dumps(seed_simulation))
    assert sim.summary == seed_simulation.summary
    for k, v in seed_simulation.response.items():
        assert np.array_equal(sim.response[k], v)
    assert np.array_equal(sim.deployment.alpha, seed_simulation.deployment.alpha)
    assert sim.deployment.latches == seed_simulation.deployment.latches
    # Columns pickled or not (computed on first access) read the same.
    d = pickle.loads(pickle.dumps(seed_simulation.deployment))
    cols = seed_simulation.deployment.columns
    for k, v in d.columns.items():
        assert np.array_equal(v, cols[k])
    x = fc.export(fc.Scenario.from_file(EXAMPLES / "export.toml"))
    x2 = pickle.loads(pickle.dumps(x))
    assert np.array_equal(x2.A, x.A) and x2.to_dict() == x.to_dict()


def test_thread_pool_vs_serial_benchmark(capsys):
    """A benchmark, not a timed assertion: eight modal analyses of a refined seed (the wing
    with 20 × 14 plate functions, 312 modes), serial and on a thread pool of two (the GIL is
    released during the computation)."""
    base = fc.Scenario.from_file(EXAMPLES / "seed.toml").with_values(
        {"plates.wing.terms.length": 20, "plates.wing.terms.width": 14}
    )
    scenarios = [base.with_values({"beams.mast.length": 13.0 + 0.25 * i}) for i in range(8)]
    t0 = time.perf_counter()
    serial = [fc.modes(s).frequency_hz for s in scenarios]
    t1 = time.perf_counter()
    with cf.ThreadPoolExecutor(max_workers=2) as pool:
        threaded = list(pool.map(lambda s: fc.modes(s).frequency_hz, scenarios))
    t2 = time.perf_counter()
    for a, b in zip(serial, threaded):
        assert np.array_equal(a, b)
    with capsys.disabled():
        print(
            f"\n[bench] 8 x fc.modes(seed): serial {t1 - t0:.3f} s, "
            f"2 threads {t2 - t1:.3f} s (speed-up {(t1 - t0) / (t2 - t1):.2f})"
        )
