"""Checks a `flexcraft export` folder with the tools its files are for.

Usage: python check_export_files.py DIR

- model.npz (numpy.load) and model.mat (scipy.io.loadmat) hold the same arrays as model.json,
  with the documented names, shapes and values;
- the first-order model (A, B, C, D) evaluated independently here as C (iωI − A)⁻¹ B + D by
  a dense complex solve reproduces frequency_response.csv (flexcraft's modal sum) to 1e-9;
- the eigenvalues of A are −ζω ± iω√(1−ζ²) of the listed modes.
Exits non-zero with a message on the first mismatch.
"""

import csv
import json
import math
import sys

import numpy as np
import scipy.io


def fail(msg):
    print("check_export_files: FAILED:", msg)
    sys.exit(1)


def close(a, b, tol, what):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        fail(f"{what}: shape {a.shape} vs {b.shape}")
    scale = max(1.0, float(np.nanmax(np.abs(b))) if b.size else 1.0)
    both_nan = np.isnan(a) & np.isnan(b)
    d = np.where(both_nan, 0.0, np.abs(a - b))
    if d.size and float(np.nanmax(d)) > tol * scale:
        fail(f"{what}: differs by {float(np.nanmax(d))}")


def main(folder):
    js = json.load(open(f"{folder}/model.json"))
    npz = np.load(f"{folder}/model.npz")
    mat = scipy.io.loadmat(f"{folder}/model.mat")
    first, second = js["first_order"], js["second_order"]
    for name in "ABCD":
        ref = np.array(first[name], dtype=float).reshape(np.asarray(npz[name]).shape)
        close(npz[name], ref, 0.0, f"npz {name}")
        close(mat[name], ref, 0.0, f"mat {name}")
    for name in "MCKBFGD":
        ref = np.array(second[name], dtype=float).reshape(np.asarray(npz["mechss_" + name]).shape)
        close(npz["mechss_" + name], ref, 0.0, f"npz mechss_{name}")
        close(mat["mechss_" + name], ref, 0.0, f"mat mechss_{name}")
    for key in ["state_names", "input_names", "output_names"]:
        want = js[key]
        if list(npz[key]) != want:
            fail(f"npz {key}")
        got = [str(c[0]) for c in mat[key][0]]
        if got != want:
            fail(f"mat {key}: {got[:3]} vs {want[:3]}")
    freq = [m["frequency_hz"] for m in js["modes"]]
    close(npz["frequency_hz"], freq, 0.0, "npz frequency_hz")
    close(mat["frequency_hz"].ravel(), freq, 0.0, "mat frequency_hz")
    close(npz["participation"], js["hub_fixed_modes"]["participation"], 0.0, "participation")
    close(mat["rigid_mass_reference"], js["rigid_body"]["mass_matrix_about_reference_point"], 0.0, "rigid mass")
    if str(npz["name"]) != js["name"] or str(mat["name"][0]) != js["name"]:
        fail("name")

    # Eigenvalues of A.
    A = np.asarray(npz["A"])
    ev = np.linalg.eigvals(A)
    wmax = max(m["omega_rad_s"] for m in js["modes"])
    for m in js["modes"]:
        w, z = m["omega_rad_s"], m["damping_ratio"]
        for s in (1, -1):
            want = complex(-z * w, s * w * math.sqrt(1 - z * z))
            tol = 1e-6 * wmax if w == 0 else 1e-9 * wmax
            if np.min(np.abs(ev - want)) > tol:
                fail(f"pole {want} not among the eigenvalues of A")

    # Frequency response by a dense complex solve of the state-space model.
    B, C, D = (np.asarray(npz[k]) for k in "BCD")
    ins, outs = js["input_names"], js["output_names"]
    rows = list(csv.reader(open(f"{folder}/frequency_response.csv")))
    header, data = rows[0], rows[1:]
    n = A.shape[0]
    for t in js["transfers"]:
        i, o = ins.index(t["input"]), outs.index(t["output"])
        tag = f'{t["input"]}->{t["output"]}'
        cre = header.index(next(h for h in header if h.startswith(tag + " re ")))
        for r in data[:: max(1, len(data) // 40)]:
            w = float(r[1])
            x = np.linalg.solve(1j * w * np.eye(n) - A, B[:, i])
            h = C[o, :] @ x + D[o, i]
            got = complex(float(r[cre]), float(r[cre + 1]))
            if abs(got - h) > 1e-9 * max(abs(h), 1e-300) + 1e-14 * abs(h):
                fail(f"{tag} at {w} rad/s: csv {got} vs C(iwI-A)^-1 B {h}")
    print(f"check_export_files: {folder}: npz, mat, json agree; poles and "
          f"{len(js['transfers'])} transfer functions verified")


if __name__ == "__main__":
    main(sys.argv[1])
