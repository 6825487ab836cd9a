#!/bin/sh
# Loads the .npz and .mat files of output::arrays, and those `flexcraft export` writes, in NumPy
# and SciPy (their reference readers): makes a Python virtual environment under target/ with
# numpy and scipy (once; later runs reuse it), then runs the ignored tests
# suite::array_files::array_files_load_in_numpy_and_scipy and
# suite::export::export_files_load_in_numpy_and_scipy and
# suite::flex42_numpy::numpy_reads_the_42_files_as_42_does_and_they_match_the_modal_solve
# (NASA 42's flex and node files read by NumPy in 42's own fscanf order,
# scripts/check_flex42_numpy.py) with FLEXCRAFT_PYTHON set to its
# interpreter. Fails if Python, the install or any check fails.
set -eu
cd "$(dirname "$0")/.."
venv=target/array-check-venv
if ! "$venv/bin/python" -c "import numpy, scipy" 2>/dev/null; then
    rm -rf "$venv"
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check numpy scipy
fi
"$venv/bin/python" -c "import numpy, scipy; print('numpy', numpy.__version__, 'scipy', scipy.__version__)"
FLEXCRAFT_PYTHON="$PWD/$venv/bin/python" cargo test --release --test lib -- \
    --ignored --exact suite::array_files::array_files_load_in_numpy_and_scipy \
    suite::export::export_files_load_in_numpy_and_scipy \
    suite::flex42_numpy::numpy_reads_the_42_files_as_42_does_and_they_match_the_modal_solve \
    --nocapture
