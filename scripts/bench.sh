#!/bin/sh
# Prints the performance figures quoted in the README: criterion benchmarks of the library and
# the wall time of whole `flexcraft` processes on the bundled example.
set -eu
cd "$(dirname "$0")/.."
cargo build --release --quiet
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"

# best_of N CMD...: the smallest wall time of N runs, µs.
best_of() {
    n=$1
    shift
    best=999999999
    i=0
    while [ $i -lt "$n" ]; do
        t0=$(date +%s%N)
        "$@" > /dev/null 2>&1
        t1=$(date +%s%N)
        dt=$(( (t1 - t0) / 1000 ))
        [ $dt -lt $best ] && best=$dt
        i=$((i + 1))
    done
    echo "  $best µs"
}

echo "whole process, flexcraft modes examples/seed.toml (best of 20):"
best_of 20 ./target/release/flexcraft modes examples/seed.toml
echo "the same with --out (CSV + 24 plots), one run:"
best_of 1 ./target/release/flexcraft modes examples/seed.toml --out target/bench-out
rm -rf target/bench-out
echo "whole process, flexcraft modes examples/composite.toml (automatic terms, first 10 to 1e-5; best of 5):"
best_of 5 ./target/release/flexcraft modes examples/composite.toml
sed 's/^tolerance = 1e-5/tolerance = 1e-6\nmax_dof = 3000/' examples/composite.toml > target/composite-1e-6.toml
echo "the same to 1e-6 (best of 3):"
best_of 3 ./target/release/flexcraft modes target/composite-1e-6.toml
echo "whole process, flexcraft simulate examples/seed.toml (best of 20):"
best_of 20 ./target/release/flexcraft simulate examples/seed.toml
echo "the same with --out (CSV, JSON, 11 PNG+SVG plots), best of 5:"
i=0
while [ $i -lt 5 ]; do rm -rf target/bench-sim; best_of 1 ./target/release/flexcraft simulate examples/seed.toml --out target/bench-sim; i=$((i + 1)); done
rm -rf target/bench-sim
python3 - > target/seed-export.toml <<'PY'
src = open("examples/seed.toml").read() + "\n[export]\nmodes = 50\n"
for i in range(10):
    src += f'[[export.points]]\nname = "p{i}"\ncomponent = "mast"\nstation = {i * 1.3}\n'
print(src)
PY
echo "whole process, flexcraft export of the seed with 50 modes and 10 points, --out (best of 5):"
i=0
best=999999999
while [ $i -lt 5 ]; do rm -rf target/bench-export; best_of 1 ./target/release/flexcraft export target/seed-export.toml --out target/bench-export; i=$((i + 1)); done
rm -rf target/bench-export
cargo bench --bench export 2>/dev/null | grep -E "^export/|time:"
cargo bench --bench modes 2>/dev/null | grep -E "^(modes|deploy|response)/|time:"
