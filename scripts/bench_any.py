#!/usr/bin/env python3
"""Issue 36's speed figures: `flexcraft deploy FILE` with defaults (the automatic model and
integrator) on the bundled examples and the benchmark set (benches/spacecraft: issue 36's
four cases and eight generated spacecraft), and `flexcraft simulate examples/seed.toml`
(the README's main command). Whole processes; CPU time (user + system) of the child, the
best of ROUNDS; the evaluation count, the base model and the accuracy estimate from
`deploy --json`.

Usage: scripts/bench_any.sh (builds the release binary first), or
    python3 scripts/bench_any.py [ROUNDS] [--simulate]
(--simulate adds one `simulate` of every benchmark spacecraft: minutes).
"""

import json
import os
import resource
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "flexcraft")


def cpu_of(args):
    """Runs args, returns (CPU seconds of the child, wall seconds, stdout)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(args, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed ({p.returncode}): {p.stderr[-500:]}")
    return cpu, wall, p.stdout


def deploy_row(path, rounds):
    best = None
    out = ""
    for _ in range(rounds):
        cpu, wall, out = cpu_of([BIN, "deploy", path, "--json"])
        best = cpu if best is None else min(best, cpu)
    d = json.loads(out)
    m = d["model"]
    a = m.get("accuracy") or {}
    events = len(d["latches"]) + len(d["captures"])
    est = a.get("estimate")
    return {
        "case": os.path.relpath(path, ROOT),
        "panels": d["panels"],
        "latch": d["latch_model"],
        "end_s": d["final_time"],
        "events": events,
        "all": d["all_latched"],
        "kept": m["base_modes_kept"],
        "corr": m["static_correction_vectors"],
        "runs": a.get("runs", 1),
        "evals": d["rhs_evaluations"],
        "estimate": "—" if est is None else f"{est:.1e}",
        "reached": a.get("reached", True),
        "cpu": best,
    }


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    rounds = int(args[0]) if args else 3
    files = [
        os.path.join(ROOT, "examples", f)
        for f in ["seed.toml", "seed_compliant.toml", "seed_staged.toml", "free_hub.toml", "montecarlo.toml"]
    ]
    bench = os.path.join(ROOT, "benches", "spacecraft")
    files += [os.path.join(bench, f) for f in sorted(os.listdir(bench)) if f.endswith(".toml")]
    print("| case | panels | latch | end [s] | events | all latched | kept modes + correction | runs | evaluations | estimate | CPU [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for f in files:
        r = deploy_row(f, rounds)
        flag = "" if r["reached"] else " (not reached)"
        print(
            f"| {r['case']} | {r['panels']} | {r['latch']} | {r['end_s']:.1f} | {r['events']} | "
            f"{'yes' if r['all'] else 'no'} | {r['kept']} + {r['corr']} | {r['runs']} | "
            f"{r['evals']} | {r['estimate']}{flag} | {r['cpu']:.3f} |"
        )
    best = None
    for _ in range(rounds):
        cpu, _, _ = cpu_of([BIN, "simulate", os.path.join(ROOT, "examples", "seed.toml")])
        best = cpu if best is None else min(best, cpu)
    print(f"\n`flexcraft simulate examples/seed.toml` (the README's main command): {best:.3f} s CPU")
    if "--simulate" in sys.argv:
        # The whole story on the benchmark set: the deployment above plus the modes and the
        # response's exact peaks and stresses, whose grid resolves the highest kept mode over
        # the whole duration (docs/theory.md §3.2; issue 38's cost of the exact peaks).
        print("\n| case | `simulate` wall [s] | CPU [s] |")
        print("|---|---|---|")
        for f in files[5:]:
            cpu, wall, _ = cpu_of([BIN, "simulate", f])
            print(f"| {os.path.relpath(f, ROOT)} | {wall:.2f} | {cpu:.2f} |")


if __name__ == "__main__":
    main()
