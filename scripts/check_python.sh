#!/bin/sh
# The Python package (python/, issue 14) as CI checks it: a FRESH virtual environment under
# target/ with maturin, pytest, hypothesis and numpy from PyPI, `pip install ./python`
# (maturin builds the extension: the library is compiled again, into python/target, a few
# minutes on 2 cores the first time), then the pytest suite in python/tests, which compares
# the results with the command line's output (target/release/flexcraft, built here if
# missing); its property tests (hypothesis) are derandomized with a fixed number of cases.
# Needs only Rust, Python >= 3.9 with pip and venv, and a C linker. Fails if any step fails.
set -eu
cd "$(dirname "$0")/.."
root=$PWD
venv=target/python-check-venv
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check maturin pytest hypothesis numpy
"$venv/bin/python" -c "import numpy, pytest, hypothesis; print('numpy', numpy.__version__, 'pytest', pytest.__version__, 'hypothesis', hypothesis.__version__)"
# The command line the tests compare with (a no-op after `cargo test --release`).
cargo build --release --bin flexcraft
# The package exactly as a user installs it: pip alone (maturin is its build backend).
CARGO_TARGET_DIR="$root/python/target" "$venv/bin/python" -m pip install \
    --disable-pip-version-check ./python
# From the repository root, so that `import flexcraft` is the installed package and not the
# source folder python/flexcraft.
"$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests
