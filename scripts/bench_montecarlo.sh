#!/bin/bash
# Speed of `flexcraft montecarlo` (docs/montecarlo.md, "Speed"): 10 000 dispersed runs of the
# seed deployment (examples/montecarlo.toml, rigid base) as one whole process; the flexible
# base's cost per run; the merge of 100 shards of those 10 000 runs. Prints wall times.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
fc=$PWD/target/release/flexcraft
work=$(mktemp -d /tmp/flexcraft-bench.XXXXXX)
trap 'rm -rf "$work"' EXIT
t() { local s=$EPOCHREALTIME; "$@" >/dev/null; awk -v a="$s" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.2f", b - a }'; }
echo "cores: $(nproc)"
echo "10000 runs, rigid base, whole process: $(t "$fc" montecarlo examples/montecarlo.toml --runs 10000 --quiet --out "$work/whole") s"
for i in $(seq 0 99); do
    "$fc" montecarlo examples/montecarlo.toml --runs 10000 --shard "$i/100" --quiet --out "$work/s$i" >/dev/null
done
echo "merge of 100 shards (10000 runs): $(t "$fc" montecarlo merge "$work"/s* --out "$work/merged") s"
diff -r "$work/whole" "$work/merged" && echo "merged == whole (byte for byte)"
sed -e 's/^base = "rigid".*/base = "flexible"\nbase_modes = 6/' examples/montecarlo.toml > "$work/flexible.toml"
echo "4 runs, flexible base (6 modes), whole process: $(t "$fc" montecarlo "$work/flexible.toml" --runs 4 --quiet --out "$work/flex") s"
