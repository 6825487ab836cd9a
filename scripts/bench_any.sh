#!/bin/sh
# Issue 36's speed figures (README, "Performance: any spacecraft"): `flexcraft deploy` with
# defaults on the examples and the benchmark set (benches/spacecraft), and the README's main
# command. Whole processes, CPU time, best of three (or of the first argument);
# --simulate adds `simulate` on the benchmark set.
set -eu
cd "$(dirname "$0")/.."
cargo build --release --quiet
python3 scripts/bench_any.py "$@"
