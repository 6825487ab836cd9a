#!/bin/sh
# Prints the figures of docs/bench-coupled.md (issue 11): the coupled deployment (the array on
# the flexible free-floating base, explicit DOPRI5) of the seed example and of a 50-panel wing,
# the cost of one right-hand side against panels N and base modes m with the fitted growth
# exponents, the steps against the tolerance, and the whole runs with the adiabatic integrator
# against the issue's targets (scripts/bench_adiabatic.py for the whole processes, criterion's
# group coupled_adiabatic for the library call). Criterion runs with quick settings (10
# samples, short measurement); its own output is kept in target/bench-coupled.log.
#   COUPLED_FULL=1 scripts/bench_coupled.sh   also runs every whole deployment once (about
#                                             15 minutes: they end at the 1e6-step limit).
set -eu
cd "$(dirname "$0")/.."
mkdir -p target
cargo bench --bench coupled --no-run 2> target/bench-coupled.build || {
    cat target/bench-coupled.build
    exit 1
}
exe=$(sed -n 's/.*Executable .*(\(.*\))$/\1/p' target/bench-coupled.build)
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load average $(cut -d' ' -f1-3 /proc/loadavg)"

# The heap effect: one rhs in a fresh process with glibc's default heap trimming (the top of
# the heap is given back to the kernel when more than 128 KiB is free, and faulted in again on
# the next call) and with trimming off.
echo "one rhs in a fresh process (20 000 calls, CPU time), glibc malloc default / trim_threshold = 256 MiB:"
for cell in 3,20 50,30 100,0; do
    a=$(COUPLED_RHS_LOOP=$cell "$exe" | sed 's/.*: \([0-9.]* µs\).*/\1/')
    b=$(GLIBC_TUNABLES=glibc.malloc.trim_threshold=268435456 COUPLED_RHS_LOOP=$cell "$exe" | sed 's/.*: \([0-9.]* µs\).*/\1/')
    echo "  N,m = $cell: $a / $b"
done

cargo build --release --quiet
python3 scripts/bench_adiabatic.py

cargo bench --bench coupled > target/bench-coupled.log 2> /dev/null
# Criterion's own estimates (on-CPU time) are in the log; the table:
sed -n '/^== coupled figures/,$p' target/bench-coupled.log
