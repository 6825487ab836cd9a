#!/bin/sh
# Prints the performance figures quoted in the README: criterion benchmarks of the library and
# the wall time of the whole `flexcraft modes` process on the bundled example.
set -eu
cd "$(dirname "$0")/.."
cargo build --release --quiet
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "whole process, flexcraft modes examples/seed.toml (best of 20):"
best=999999
i=0
while [ $i -lt 20 ]; do
    t0=$(date +%s%N)
    ./target/release/flexcraft modes examples/seed.toml > /dev/null
    t1=$(date +%s%N)
    dt=$(( (t1 - t0) / 1000 ))
    [ $dt -lt $best ] && best=$dt
    i=$((i + 1))
done
echo "  $best µs"
echo "whole process, flexcraft simulate examples/seed.toml (best of 20):"
best=999999
i=0
while [ $i -lt 20 ]; do
    t0=$(date +%s%N)
    ./target/release/flexcraft simulate examples/seed.toml > /dev/null 2>&1
    t1=$(date +%s%N)
    dt=$(( (t1 - t0) / 1000 ))
    [ $dt -lt $best ] && best=$dt
    i=$((i + 1))
done
echo "  $best µs"
echo "flexcraft simulate --out (CSV, JSON, 11 PNG+SVG plots):"
t0=$(date +%s%N)
./target/release/flexcraft simulate examples/seed.toml --out target/bench-sim > /dev/null 2>&1
t1=$(date +%s%N)
echo "  $(( (t1 - t0) / 1000000 )) ms"
rm -rf target/bench-sim
echo "with --out (CSV + 24 plots):"
t0=$(date +%s%N)
./target/release/flexcraft modes examples/seed.toml --out target/bench-out > /dev/null
t1=$(date +%s%N)
echo "  $(( (t1 - t0) / 1000000 )) ms"
rm -rf target/bench-out
cargo bench --bench modes 2>/dev/null | grep -E "^(modes|deploy|response)/|time:"
