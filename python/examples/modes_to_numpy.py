"""The natural frequencies and mode shapes of a scenario as NumPy arrays.

    python python/examples/modes_to_numpy.py [examples/seed.toml]

Prints the elastic frequencies, samples the first elastic modes along every beam and over
every plate, checks the mass normalisation ΦᵀMΦ = I, and saves everything to modes.npz.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import flexcraft as fc

ROOT = Path(__file__).resolve().parents[2]

path = sys.argv[1] if len(sys.argv) > 1 else ROOT / "examples" / "seed.toml"
sc = fc.Scenario.from_file(path)
m = fc.modes(sc)

elastic = ~m.rigid
print(f"{sc.name}: {len(m)} modes, {m.rigid.sum()} rigid")
for n, f in zip(m.number[elastic][:10], m.frequency_hz[elastic][:10]):
    print(f"  mode {n:3d}: {f:10.4f} Hz")

# Mass normalisation of the Ritz coefficients: Φᵀ M Φ = I.
phi = m.coefficients.T
err = np.abs(phi.T @ m.mass_matrix @ phi - np.eye(len(m))).max()
print(f"max |ΦᵀMΦ − I| = {err:.2e}")

arrays = {"frequency_hz": m.frequency_hz, "omega": m.omega, "rigid": m.rigid}
xi = np.linspace(0.0, 1.0, 21)
for beam in sc.beams:
    # modes × points × [ux, uy, uz, rx, ry, rz] (m and rad per unit modal coordinate)
    arrays[f"beam_{beam}"] = m.shape(beam, xi)
gx, gy = np.meshgrid(np.linspace(0, 1, 11), np.linspace(0, 1, 5), indexing="ij")
grid = np.column_stack([gx.ravel(), gy.ravel()])
for plate in sc.plates:
    arrays[f"plate_{plate}"] = m.shape(plate, grid)
    first = int(m.number[elastic][0])
    w = m.shape(plate, grid, mode=first)[:, 2].reshape(gx.shape)
    print(f"plate {plate}, mode {first}: uz over the 11 × 5 grid, tip edge {w[-1].round(4)}")

np.savez("modes.npz", **arrays)
print("wrote modes.npz:", ", ".join(f"{k} {v.shape}" for k, v in arrays.items()))
