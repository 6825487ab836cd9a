"""Speed of the Python package (benchmarks, not tests; figures in docs/python.md).

    python python/bench.py [examples/seed.toml]

1. `import flexcraft` plus `Scenario.from_file` and `fc.modes` on the seed, in a fresh
   interpreter (the median of several).
2. The overhead of a Python `fc.deploy` call over the library's `deploy::simulate_coupled`
   on the same scenario: the Python call's wall time (the computation, the NumPy arrays, the
   JSON text and the latches as Python objects) against the library alone, timed inside Rust
   (alternating runs, medians).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
seed = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "examples" / "seed.toml")

IMPORT_AND_MODES = f"""
import time
t0 = time.perf_counter()
import numpy
tn = time.perf_counter()
import flexcraft as fc
t1 = time.perf_counter()
m = fc.modes(fc.Scenario.from_file({seed!r}))
t2 = time.perf_counter()
print(tn - t0, t1 - tn, t2 - t1)
"""

runs = []
for _ in range(7):
    out = subprocess.run(
        [sys.executable, "-c", IMPORT_AND_MODES], capture_output=True, text=True, check=True,
        cwd=ROOT / "target" if (ROOT / "target").is_dir() else None,
    ).stdout.split()
    runs.append(tuple(float(v) for v in out))
npy, imp, mod = (statistics.median(r[k] for r in runs) for k in range(3))
print(
    f"import numpy: {npy * 1e3:.1f} ms; then import flexcraft: {imp * 1e3:.1f} ms; "
    f"from_file + fc.modes(seed): {mod * 1e3:.1f} ms; "
    f"total {1e3 * (npy + imp + mod):.1f} ms, without NumPy's own import {1e3 * (imp + mod):.1f} ms"
)

import flexcraft as fc  # noqa: E402

sc = fc.Scenario.from_file(seed)
fc.deploy(sc)  # warm-up
py_times, lib_times = [], []
for _ in range(5):
    t = time.perf_counter()
    d = fc.deploy(sc)
    py_times.append(time.perf_counter() - t)
    lib_times.append(fc._native._library_deploy_seconds(sc._s))
py_t, lib_t = statistics.median(py_times), statistics.median(lib_times)
print(
    f"deploy(seed): Python call {py_t:.3f} s, library alone {lib_t:.3f} s, "
    f"overhead {100 * (py_t - lib_t) / lib_t:+.2f} %"
)
t = time.perf_counter()
cols = d.columns
print(f"  (.columns, deployment.csv as arrays, on first access: {1e3 * (time.perf_counter() - t):.1f} ms)")
