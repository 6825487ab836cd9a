#!/bin/sh
# Issue 19's speed figures: `simulate` of the seed with compliant latches for k_L = 1e4, 1e5,
# 1e7 N·m/rad (criterion, benches/compliant.rs, 10 samples each: about 3 minutes), then the
# ratio 1e7 / 1e4. Criterion's log is kept in target/bench-compliant.log.
set -eu
cd "$(dirname "$0")/.."
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load average $(cut -d' ' -f1-3 /proc/loadavg)"
cargo bench --bench compliant > target/bench-compliant.log 2>&1
grep -E '^compliant_seed_simulate|time:' target/bench-compliant.log | paste - - |
    sed 's/ *time: *\[\([^ ]* [^ ]*\) \([^ ]* [^ ]*\) .*/\t\2 (median)/'
awk '/k_L = 1e4/{getline; split($0,a,"[][]"); split(a[2],b," "); t4=b[3]; u4=b[4]}
     /k_L = 1e7/{getline; split($0,a,"[][]"); split(a[2],b," "); t7=b[3]; u7=b[4]}
     END { f4 = (u4=="ms") ? t4/1000 : t4; f7 = (u7=="ms") ? t7/1000 : t7;
           if (f4 > 0) printf "ratio k_L 1e7 / 1e4: %.2f (target ≤ 3)\n", f7/f4 }' target/bench-compliant.log
