"""Latch time of the seed's solar array against its hinge stiffness, in parallel.

Each stiffness is a scenario of its own (`Scenario.with_values`), shipped to a worker
process (a Scenario pickles as its TOML text); each worker runs `fc.deploy`. Plots the final
latch time against the stiffness with matplotlib if it is installed, else prints the table.

    python python/examples/sweep_hinge_stiffness.py [examples/seed.toml] [--plot out.png]
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import os
from pathlib import Path

import numpy as np

import flexcraft as fc

ROOT = Path(__file__).resolve().parents[2]


def latch_time(scenario: fc.Scenario) -> float:
    """The time of the last latch [s], NaN when the array does not latch in end_time."""
    d = fc.deploy(scenario)
    return d.latches[-1].time if d.all_latched else float("nan")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenario", nargs="?", default=str(ROOT / "examples" / "seed.toml"))
    p.add_argument("--plot", default="latch_time_vs_stiffness.png")
    p.add_argument("--points", type=int, default=8)
    a = p.parse_args()

    base = fc.Scenario.from_file(a.scenario)
    stiffness = np.linspace(1.1, 3.0, a.points)  # N·m/rad
    scenarios = [base.with_values({"deployment.hinge.stiffness": float(k)}) for k in stiffness]
    with cf.ProcessPoolExecutor(max_workers=os.cpu_count()) as pool:
        times = np.array(list(pool.map(latch_time, scenarios)))

    print(f"{'k [N·m/rad]':>12}  {'latch time [s]':>14}")
    for k, t in zip(stiffness, times):
        print(f"{k:12.4f}  {t:14.4f}")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(matplotlib is not installed: no plot)")
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(stiffness, times, "o-")
    ax.set_xlabel("hinge stiffness k [N·m/rad]")
    ax.set_ylabel("final latch time [s]")
    ax.set_title(base.name, fontsize=9)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(a.plot, dpi=120)
    print(f"wrote {a.plot}")


if __name__ == "__main__":
    main()
