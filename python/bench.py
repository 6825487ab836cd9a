"""Speed of the Python package (benchmarks, not tests; figures in docs/python.md).

    python python/bench.py [examples/seed.toml]

1. `import flexcraft` plus `Scenario.from_file` and `fc.modes` on the seed, in a fresh
   interpreter (the median of several): NumPy is not imported by either (a result makes its
   arrays on first read); then the first array read, which imports NumPy.
2. The overhead of a Python `fc.deploy` call over the library's `deploy::simulate_coupled`
   on the same scenario: the Python call's wall time against the library alone, timed
   inside Rust (alternating runs, the fastest of each); then the time to read its results (t, alpha,
   rate, the latches and to_dict(): the arrays and objects made from the Rust result).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
seed = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "examples" / "seed.toml")

IMPORT_AND_MODES = f"""
import sys, time
t0 = time.perf_counter()
import flexcraft as fc
t1 = time.perf_counter()
m = fc.modes(fc.Scenario.from_file({seed!r}))
t2 = time.perf_counter()
numpy_before = "numpy" in sys.modules
m.frequency_hz
t3 = time.perf_counter()
assert not numpy_before, "NumPy was imported before the first array read"
print(t1 - t0, t2 - t1, t3 - t2)
"""

runs, walls = [], []
for _ in range(9):
    t = time.perf_counter()
    out = subprocess.run(
        [sys.executable, "-c", IMPORT_AND_MODES], capture_output=True, text=True, check=True,
        cwd=ROOT / "target" if (ROOT / "target").is_dir() else None,
    ).stdout.split()
    walls.append(time.perf_counter() - t)
    runs.append(tuple(float(v) for v in out))
imp, mod, arr = (statistics.median(r[k] for r in runs) for k in range(3))
print(
    f"import flexcraft: {imp * 1e3:.1f} ms; from_file + fc.modes(seed): {mod * 1e3:.1f} ms; "
    f"together {1e3 * (imp + mod):.1f} ms (NumPy not imported)"
)
print(
    f"  then the first array read (imports NumPy): {arr * 1e3:.1f} ms; the whole process "
    f"(interpreter start and exit included): {1e3 * statistics.median(walls):.0f} ms"
)

import flexcraft as fc  # noqa: E402

sc = fc.Scenario.from_file(seed)
fc.deploy(sc)  # warm-up
py_times, read_times, lib_times = [], [], []
for _ in range(7):
    t = time.perf_counter()
    d = fc.deploy(sc)
    py_times.append(time.perf_counter() - t)
    t = time.perf_counter()
    d.t, d.alpha, d.rate, d.latches, d.to_dict()
    read_times.append(time.perf_counter() - t)
    lib_times.append(fc._native._library_deploy_seconds(sc._s))
# The fastest of the alternating runs: the least disturbed by other work on the machine.
py_t, read_t, lib_t = (min(x) for x in (py_times, read_times, lib_times))
print(
    f"deploy(seed), fastest of 7 each: library alone {lib_t:.3f} s; Python call {py_t:.3f} s, "
    f"overhead {100 * (py_t - lib_t) / lib_t:+.2f} % (medians {statistics.median(lib_times):.3f} s "
    f"and {statistics.median(py_times):.3f} s); then reading t, alpha, rate, latches and "
    f"to_dict(): {1e3 * read_t:.1f} ms, {100 * read_t / lib_t:.3f} % of the library's time"
)
t = time.perf_counter()
cols = d.columns
print(f"  (.columns, deployment.csv as arrays, on first access: {1e3 * (time.perf_counter() - t):.1f} ms)")
print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} (1 min)")
