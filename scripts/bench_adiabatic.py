#!/usr/bin/env python3
"""Whole-process figures of the adiabatic integrator (tolerance 1e-8), the issue's speed
targets: CPU time (user + sys) of `flexcraft`, smallest and largest of five runs each.

The scenarios are the bundled examples edited as benches/coupled.rs edits them: the seed
with 20 base modes, seed_compliant with latch stiffness 1e4, 1e5 and 1e7 N·m/rad (damping
∝ √k_L), and a 50-panel wing (0.3 m panels, hinge stiffness 1 N·m/rad, mast terms raised to
16/10/8, 30 base modes, ideal cable). Run from the repository after `cargo build --release`
(scripts/bench_coupled.sh does both)."""
import os
import re
import resource
import subprocess
import sys

EXE = "./target/release/flexcraft"
RUNS = 5


def adiabatic(src: str, modes: int) -> str:
    """The example on the adiabatic integrator at tolerance 1e-8 with `modes` base modes (the
    examples run on the automatic integrator: the keys go after `synchronisation`)."""
    keys = f'\nbase_modes = {modes}\nintegrator = "adiabatic"\ntolerance = 1e-8'
    src, n = re.subn(r'\nsynchronisation = "cable"', '\nsynchronisation = "cable"' + keys, src)
    assert n == 1, "one synchronisation line"
    return src


def compliant(src: str, k: str, c: str) -> str:
    for old, new in (("stiffness = 1.0e5", f"stiffness = {k}"), ("damping = 2236.0", f"damping = {c}")):
        assert old in src, old
        src = src.replace(old, new)
    return src


def scenarios() -> list:
    seed = open("examples/seed.toml", encoding="utf-8").read()
    comp = open("examples/seed_compliant.toml", encoding="utf-8").read()
    wide = seed
    for old, new in (
        ("bending = 8, torsion = 6, axial = 4", "bending = 16, torsion = 10, axial = 8"),
        ("panels = 3", "panels = 50"),
    ):
        assert old in wide, old
        wide = wide.replace(old, new)
    wide, n = re.subn(r"\[deployment.hinge\]\nstiffness = [0-9.e]+", "[deployment.hinge]\nstiffness = 1.0", wide)
    assert n == 1, "examples/seed.toml has one [deployment.hinge] stiffness"
    return [
        ("seed, 20 base modes, simulate (target 0.2 s)", "simulate", "seed20", adiabatic(seed, 20)),
        ("examples/seed_compliant.toml, simulate (target 0.5 s)", "simulate", "compliant1e5", adiabatic(comp, 6)),
        ("seed_compliant, k_L = 1e4, simulate", "simulate", "compliant1e4", adiabatic(compliant(comp, "1.0e4", "707.1"), 6)),
        (
            "seed_compliant, k_L = 1e7, simulate (target: ≤ 3 × the 1e4 run)",
            "simulate",
            "compliant1e7",
            adiabatic(compliant(comp, "1.0e7", "22360.0"), 6),
        ),
        ("50 panels, 30 base modes, ideal cable, deploy (target 1 s)", "deploy", "wide50", adiabatic(wide, 30)),
    ]


def cpu_of(args: list) -> float:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> int:
    os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    if not os.path.exists(EXE):
        print(f"{EXE} is missing: run `cargo build --release` first", file=sys.stderr)
        return 1
    os.makedirs("target", exist_ok=True)
    print(f"whole process, adiabatic integrator, tol 1e-8, CPU (min–max of {RUNS} runs):")
    for label, command, name, src in scenarios():
        path = f"target/bench-{name}.toml"
        with open(path, "w", encoding="utf-8") as f:
            f.write(src)
        times = [cpu_of([EXE, command, path]) for _ in range(RUNS)]
        print(f"  {label}: {min(times):.3f}–{max(times):.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
