#!/usr/bin/env python3
"""flexcraft against CalculiX on examples/composite.toml: error against whole-process time.

Run from anywhere (needs cargo, and `ccx` on PATH: Debian's `apt-get install calculix-ccx`):

    python3 scripts/compare_calculix.py            # the README's table
    python3 scripts/compare_calculix.py --quick    # coarser sequences, a smoke test
    python3 scripts/compare_calculix.py --keep DIR # keep the decks and outputs in DIR

Python 3.11 standard library only. Everything is measured in one run on one machine, so the
time ratios hold on another machine; the absolute times do not (nor on a loaded machine).

What is compared: the first 10 elastic frequencies of the free spacecraft of
examples/composite.toml (the six rigid-body modes come first in both tools and are skipped).
Both tools run as whole processes (start, read, assemble, solve, print), best of 3, on one
thread: flexcraft gets RAYON_NUM_THREADS=1 (it otherwise runs independent work side by
side: a term selection level's solves, the final hub-fixed and free pencils, a large
model's two symmetrisations; every factorisation is sequential anyway, faer without its
"rayon" feature), and ccx gets OMP_NUM_THREADS=1 (its default; with 2 threads on
a busy 2-core machine it spun 20× slower).

flexcraft: `flexcraft modes --json` on copies of the example with `[ritz] tolerance` 1e-2 …
1e-6 (automatic terms) and with explicit `terms` sequences (no `[ritz]` table).

CalculiX: one deck per mesh, *FREQUENCY for 20 modes above 0.2 Hz printed (the 6 rigid ones,
at ~0, drop out; 14 elastic remain), eigenvalues read from the .dat file. The model, and where
it differs from flexcraft's continuum:

* Mast: B32R elements (three-node, reduced integration) with *BEAM SECTION, SECTION=PIPE,
  outer radius 0.15 m, wall 5 mm. CalculiX 2.20 accepts SECTION=PIPE only on B32R ("*BEAM
  SECTION of type PIPE can only be used for B32R elements"), so B32R stands in for the B32 the
  issue names; CalculiX expands either into C3D20R bricks. The expanded tube is a 3-D solid:
  it has transverse shear flexibility and rotary inertia, which flexcraft's Euler–Bernoulli
  beam has not (docs/theory.md §1.1); on the mast alone (free–free) that lowers the first
  bending frequency by 0.27 %.
* Wing: S8R shells (eight-node, reduced integration) in the plane z = 13 m, length along +x
  from the mast tip, the root edge (x = 0, width 3.75 m) centred on the mast axis, as
  docs/scenario.md places it. flexcraft's plate is a Kirchhoff plate given by D and ρh only,
  rigid in its own plane. The shell gets a thickness h = 20 mm and the E and ρ that give the
  same D = E h³/12(1 − ν²) = 6.2e5 N·m and ρh = 8 kg/m² (E = 8.46e11 Pa, ρ = 400 kg/m³,
  ν = 0.3): its span/thickness ratio 190 keeps its transverse shear (Mindlin) small, and its
  membrane stiffness E h = 1.7e10 N/m puts its first in-plane mode near 120 Hz, far above the
  16 Hz of the 10th elastic mode. Thinner shells (h = 5 mm, E = 5.4e13 Pa) made CalculiX's
  expanded shells erratic: the clamped wing's fundamental jumped by 4 % between meshes.
* Tie: CalculiX 2.20's *RIGID BODY carries only the translation of a beam node (tried: a
  cantilever clamped through a rigid body on its root node swings like a pin), so the rigid
  connections are stiff massless beams instead, whose shared nodes CalculiX turns into rigid
  "knots": the yoke is a B32R beam along the wing's root edge through its nodes, whose
  middle node is the mast's tip node (flexcraft: "clamped along the root edge to a rigid
  massless yoke at the attachment"). Their E is 1e4 times the mast's, a solid circle of
  radius 0.1 m, density 1e-3 kg/m³: 10 times stiffer changes no frequency by more than 1e-5,
  100 times stiffer makes the solution noisy (conditioning).
* Hub: CalculiX 2.20 has no *ROTARY INERTIA (added in a later version), so the hub's 800 kg
  and inertia [600, 600, 400] kg·m² about its centre of mass (0, 0, −1) are seven *MASS
  points: 64 kg at ±1.25 m along x and along y, 128 kg at ±1.25 m along z, 288 kg at the
  centre, which is exactly that mass, centre and inertia tensor; a spider of the same stiff
  beams joins them to the mast's root node. It is the same rigid body with the same mass.

Error: each run's largest relative error over the first 10 elastic frequencies,
max_k |f_k − f_k,ref| / f_k,ref, against each tool's own converged limit:
  flexcraft: the reference of tests/suite/term_selection.rs, mast terms 36/20/20, wing width
            28, wing length 48, 64 and 80 extrapolated (rate fitted per mode);
  CalculiX: a Richardson extrapolation, per mode, of its three finest meshes (each halves
            the element size), with the rate fitted per mode and bounded to [1, 4].
So each error column says how far a run is from what its own model converges to; the last
column gives every run's error against flexcraft's reference, and the table above it the
CalculiX limits' difference from that reference per mode: what the different physics (shear
and rotary inertia of the 3-D tube, the shell's transverse shear and membrane flexibility)
amounts to.
"""

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "composite.toml"
FLEXCRAFT = ROOT / "target" / "release" / "flexcraft"

N_ELASTIC = 10  # compared elastic modes
N_RIGID = 6  # free hub
CCX_MODES = 20  # requested from ccx: 6 rigid + 14 elastic
CCX_LOWER_HZ = 0.2  # ccx prints only the modes above this: the rigid ones (~0) drop out
REPEATS = 3  # whole-process timings: best of
# flexcraft's reference (that of tests/suite/term_selection.rs): mast bending/torsion/axial
# terms, wing length counts (extrapolated) and width count.
REF_MAST = (36, 20, 20)
REF_LENGTHS = (48, 64, 80)
REF_WIDTH = 28

# Shell stand-in for the sandwich wing (see the docstring): thickness, and E, ρ from D and ρh.
SHELL_H_M = 0.02
# The hub as point masses this far from its centre of mass along ±x, ±y, ±z (see the docstring).
HUB_ARM_M = 1.25
# The stiff massless beams of the yoke and the hub's spider (see the docstring).
STIFF_E = 7e14  # 1e4 × the mast's E: 10× more changes no frequency by 1e-5; 100× more is noisy
STIFF_RHO = 1e-3
STIFF_R_M = 0.1


def best_time(cmd, repeats, cwd=None, env=None):
    """Runs cmd `repeats` times; returns (smallest wall time in s, stdout of the last run)."""
    best = math.inf
    out = ""
    for _ in range(repeats):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
        dt = time.perf_counter() - t0
        if p.returncode != 0:
            sys.exit(f"{' '.join(map(str, cmd))} failed ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
        best = min(best, dt)
        out = p.stdout
    return best, out


# ----------------------------------------------------------------------------- the structure

def load_structure():
    """The composite's data, with the layout this script's decks assume checked."""
    s = tomllib.loads(EXAMPLE.read_text())
    hub, (beam,), (plate,) = s["hub"], s["beams"], s["plates"]
    mat = s["materials"][beam["material"]]
    assert hub["motion"] == "free" and len(hub["inertia"]) == 3
    assert beam["parent"] == "hub" and beam["root"] == [0.0, 0.0, 0.0] and beam["axis"] == [0.0, 0.0, 1.0]
    assert plate["parent"] == beam["name"] and plate["station"] == beam["length"]
    assert plate["length_axis"] == [1.0, 0.0, 0.0] and plate["normal"] == [0.0, 0.0, 1.0]
    return s, hub, beam, plate, mat


def hub_point_masses(hub):
    """Six point masses (position, kg) with the hub's mass, centre of mass and principal inertia.

    At ±a along axis i the pair contributes 2 m_i a² to the two other moments, so
    I_x = 2a²(m_y + m_z), I_y = 2a²(m_x + m_z), I_z = 2a²(m_x + m_y); a central mass takes the rest.
    """
    a = HUB_ARM_M
    ix, iy, iz = (v / (2 * a * a) for v in hub["inertia"])
    total = (ix + iy + iz) / 2
    m = [total - ix, total - iy, total - iz]
    central = hub["mass"] - 2 * sum(m)
    assert min(m) >= 0 and central >= -1e-9, "HUB_ARM_M too small for this hub"
    c = hub["center_of_mass"]
    pts = []
    for axis in range(3):
        for sign in (1, -1):
            p = list(c)
            p[axis] += sign * a
            pts.append((p, m[axis]))
    if central > 1e-9:
        pts.append((list(c), central))
    return pts


# ----------------------------------------------------------------------------- CalculiX

def ccx_deck(n_mast, nx, ny, hub, beam, plate, mat):
    """The CalculiX deck for n_mast B32R mast elements and nx × ny S8R wing elements."""
    lines = ["*HEADING", f"flexcraft composite: mast {n_mast} B32R, wing {nx}x{ny} S8R"]
    length = beam["length"]
    tube = beam["section"]["tube"]
    nodes = []  # (id, x, y, z)
    # Mast nodes 1 … 2n+1 along z (B32R: end, middle, end).
    for i in range(2 * n_mast + 1):
        nodes.append((i + 1, 0.0, 0.0, length * i / (2 * n_mast)))
    root, tip = 1, 2 * n_mast + 1
    # Wing nodes on a (2nx+1) × (2ny+1) grid without the element centres; the root edge's
    # node on the mast axis is the mast's tip node itself.
    a, b = plate["length"], plate["width"]

    def wid(i, j):
        return tip if (i, j) == (0, ny) else 200001 + i * (2 * ny + 1) + j

    for i in range(2 * nx + 1):
        for j in range(2 * ny + 1):
            if (i % 2 and j % 2) or wid(i, j) == tip:
                continue
            nodes.append((wid(i, j), a * i / (2 * nx), -b / 2 + b * j / (2 * ny), length))
    # Hub: a massless stiff spider from the mast root to its centre of mass and on to the
    # point masses.
    spider = []  # (from, to) node pairs
    cm = 100001
    nodes.append((cm, *hub["center_of_mass"]))
    spider.append((root, cm))
    masses = []
    for k, (p, m) in enumerate(hub_point_masses(hub)):
        if p == list(hub["center_of_mass"]):
            masses.append((cm, m))
            continue
        nodes.append((100011 + k, *p))
        spider.append((cm, 100011 + k))
        masses.append((100011 + k, m))
    lines.append("*NODE")
    next_mid = 300001
    lines += [f"{n}, {x!r}, {y!r}, {z!r}" for n, x, y, z in nodes]
    where = {n: (x, y, z) for n, x, y, z in nodes}
    lines.append("*ELEMENT, TYPE=B32R, ELSET=MAST")
    for e in range(n_mast):
        lines.append(f"{e + 1}, {2 * e + 1}, {2 * e + 2}, {2 * e + 3}")
    lines.append("*ELEMENT, TYPE=S8R, ELSET=WING")
    eid = 10001
    for ei in range(nx):
        for ej in range(ny):
            i0, j0 = 2 * ei, 2 * ej
            # corners counter-clockwise seen from +z (normal +z), then the mid-side nodes
            c = [wid(i0, j0), wid(i0 + 2, j0), wid(i0 + 2, j0 + 2), wid(i0, j0 + 2)]
            m = [wid(i0 + 1, j0), wid(i0 + 2, j0 + 1), wid(i0 + 1, j0 + 2), wid(i0, j0 + 1)]
            lines.append(f"{eid}, " + ", ".join(map(str, c + m)))
            eid += 1
    # The yoke: a stiff massless beam along the root edge through its nodes (the shell nodes
    # it shares become rigid knots in CalculiX's expansion, so the edge is clamped to it).
    lines.append("*ELEMENT, TYPE=B32R, ELSET=YOKE")
    for k in range(ny):
        lines.append(f"{20001 + k}, {wid(0, 2 * k)}, {wid(0, 2 * k + 1)}, {wid(0, 2 * k + 2)}")
    # The hub's spider, each arm one B32R with a new middle node; ELSETs by arm direction for
    # the section orientation.
    mid_lines, arm_lines = ["*NODE"], []
    for k, (n0, n1) in enumerate(spider):
        p0, p1 = where[n0], where[n1]
        mid = next_mid + k
        mid_lines.append(f"{mid}, " + ", ".join(repr((u + v) / 2) for u, v in zip(p0, p1)))
        along_z = abs(p1[2] - p0[2]) > 1e-12
        arm_lines += [f"*ELEMENT, TYPE=B32R, ELSET={'ARMZ' if along_z else 'ARMXY'}",
                      f"{30001 + k}, {n0}, {mid}, {n1}"]
    lines += mid_lines + arm_lines
    for k, (n, m) in enumerate(masses):
        lines += [f"*ELEMENT, TYPE=MASS, ELSET=HUBM{k}", f"{900001 + k}, {n}",
                  f"*MASS, ELSET=HUBM{k}", f"{m!r}"]
    e, nu, rho = mat["youngs_modulus"], mat["poisson_ratio"], mat["density"]
    lines += ["*MATERIAL, NAME=AL", "*ELASTIC", f"{e!r}, {nu!r}", "*DENSITY", f"{rho!r}"]
    h = SHELL_H_M
    nu_p = plate["poisson_ratio"]
    e_p = plate["bending_stiffness"] * 12 * (1 - nu_p**2) / h**3
    rho_p = plate["areal_density"] / h
    lines += ["*MATERIAL, NAME=WINGMAT", "*ELASTIC", f"{e_p!r}, {nu_p!r}", "*DENSITY", f"{rho_p!r}"]
    lines += ["*MATERIAL, NAME=STIFF", "*ELASTIC", f"{STIFF_E!r}, 0.3", "*DENSITY", f"{STIFF_RHO!r}"]
    lines += ["*BEAM SECTION, ELSET=MAST, MATERIAL=AL, SECTION=PIPE",
              f"{tube['outer_diameter'] / 2!r}, {tube['wall']!r}", "1, 0, 0"]
    lines += ["*SHELL SECTION, ELSET=WING, MATERIAL=WINGMAT", f"{h!r}"]
    for elset, direction in (("YOKE", "1, 0, 0"), ("ARMZ", "1, 0, 0"), ("ARMXY", "0, 0, 1")):
        if any(l.endswith(f"ELSET={elset}") for l in lines):
            lines += [f"*BEAM SECTION, ELSET={elset}, MATERIAL=STIFF, SECTION=CIRC", f"{STIFF_R_M!r}", direction]
    lines += ["*STEP", "*FREQUENCY", f"{CCX_MODES}, {CCX_LOWER_HZ!r}", "*END STEP"]
    return "\n".join(lines) + "\n"


def ccx_frequencies(dat_text):
    """Frequencies [Hz] from the EIGENVALUE OUTPUT block of a .dat file, in mode order."""
    block = dat_text.split("E I G E N V A L U E   O U T P U T", 1)[1]
    block = block.split("P A R T I C I P A T I O N", 1)[0]
    freqs = []
    for line in block.splitlines():
        f = line.split()
        if len(f) == 5 and f[0].isdigit():
            freqs.append(float(f[3]))
    return freqs


def run_ccx(workdir, n_mast, nx, ny, structure, repeats):
    _, hub, beam, plate, mat = structure
    name = f"ccx_m{n_mast}_w{nx}x{ny}"
    (workdir / f"{name}.inp").write_text(ccx_deck(n_mast, nx, ny, hub, beam, plate, mat))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    t, out = best_time(["ccx", "-i", name], repeats, cwd=workdir, env=env)
    m = re.search(r"number of equations\s*\n\s*(\d+)", out)
    dof = int(m.group(1)) if m else -1
    freqs = ccx_frequencies((workdir / f"{name}.dat").read_text())
    if len(freqs) != CCX_MODES - N_RIGID:
        sys.exit(f"{name}: {len(freqs)} modes above {CCX_LOWER_HZ} Hz, expected {CCX_MODES - N_RIGID}")
    elastic = freqs[:N_ELASTIC]
    return {"tool": "CalculiX", "disc": f"mast {n_mast} B32R, wing {nx}×{ny} S8R", "dof": dof,
            "time_s": t, "freqs": elastic}


# ----------------------------------------------------------------------------- flexcraft

def scenario_variant(text, terms=None, tolerance=None, max_dof=None):
    """The example's text with its [ritz] table replaced, and explicit terms if given."""
    head = text.split("[ritz]", 1)[0].rstrip() + "\n"
    if terms is not None:
        bend, tors, axial, length, width = terms
        head = head.replace('section = { tube = { outer_diameter = 0.3, wall = 0.005 } }\n',
                            'section = { tube = { outer_diameter = 0.3, wall = 0.005 } }\n'
                            f"terms = {{ bending = {bend}, torsion = {tors}, axial = {axial} }}\n", 1)
        head = head.rstrip() + f"\nterms = {{ length = {length}, width = {width} }}\n"
        assert head.count("terms =") == 2
    if tolerance is not None:
        head += f"\n[ritz]\ntolerance = {tolerance:g}\nmodes = {N_ELASTIC}\n"
        if max_dof is not None:
            head += f"max_dof = {max_dof}\n"
    return head


def run_flexcraft(workdir, label, text, repeats):
    path = workdir / f"fc_{re.sub(r'[^A-Za-z0-9]+', '_', label)}.toml"
    path.write_text(text)
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    t, out = best_time([str(FLEXCRAFT), "modes", str(path), "--json"], repeats, env=env)
    d = json.loads(out)
    modes = d["modes"]
    assert all(m["rigid"] for m in modes[:N_RIGID]) and not modes[N_RIGID]["rigid"]
    freqs = [m["frequency_hz"] for m in modes[N_RIGID:N_RIGID + N_ELASTIC]]
    est = [m["frequency_error_estimate"] for m in modes[N_RIGID:N_RIGID + N_ELASTIC]]
    est = max(est) if all(e is not None for e in est) else None
    return {"tool": "flexcraft", "disc": label, "dof": d["dof"], "time_s": t, "freqs": freqs, "estimate": est}


# ----------------------------------------------------------------------------- comparison

def richardson(levels, ra, rb, bounds):
    """Per-mode limit of three levels refined by the factors ra, then rb (error ~ C n^-p).

    The rate p solves d1/d2 = (ra^p − 1) rb^p / (rb^p − 1) for the two differences, found by
    bisection in `bounds`; the limit is f3 − d2/(rb^p − 1).
    """
    out = []
    for f1, f2, f3 in zip(*levels):
        d1, d2 = f1 - f2, f2 - f3
        if d1 * d2 <= 0 or abs(d2) < 1e-15 * abs(f3):
            out.append(f3)  # not monotone: no extrapolation
            continue
        g = lambda p: (ra**p - 1) * rb**p / (rb**p - 1)
        lo, hi = bounds
        for _ in range(100):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if g(mid) < d1 / d2 else (lo, mid)
        p = (lo + hi) / 2
        out.append(f3 - d2 / (rb**p - 1))
    return out


def max_rel(freqs, ref):
    return max(abs(f - r) / r for f, r in zip(freqs, ref))


def time_to(rows, tol):
    """Smallest time among the runs whose error is at most tol (None if none)."""
    ok = [r["time_s"] for r in rows if r["err"] <= tol]
    return min(ok) if ok else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="coarse sequences only (smoke test)")
    ap.add_argument("--keep", metavar="DIR", help="write the decks and outputs here and keep them")
    args = ap.parse_args()
    if shutil.which("ccx") is None:
        sys.exit("ccx not found: apt-get install calculix-ccx")
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    structure = load_structure()
    text = EXAMPLE.read_text()
    ccx_v = subprocess.run(["ccx", "-v"], capture_output=True, text=True).stdout.strip().splitlines()
    print(f"machine: {os.cpu_count()} cores, {cpu_name()}; {ccx_v[-1] if ccx_v else 'ccx'}")

    if args.quick:
        meshes = [(8, 4, 2), (8, 8, 2), (16, 16, 4)]
        tolerances = [1e-2, 1e-3]
        term_seq = [(4, 2, 2, 4, 3), (8, 4, 4, 12, 6)]
    else:
        meshes = [(8, 4, 2), (8, 8, 2), (16, 16, 4), (32, 32, 8), (64, 64, 16), (128, 128, 32)]
        tolerances = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
        term_seq = [(4, 2, 2, 4, 3), (6, 3, 3, 8, 4), (8, 4, 4, 12, 6), (10, 6, 6, 16, 8),
                    (12, 6, 6, 24, 10), (14, 8, 8, 32, 14), (16, 8, 8, 48, 18)]

    with tempfile.TemporaryDirectory(prefix="flexcraft-ccx-") as tmp:
        workdir = Path(args.keep) if args.keep else Path(tmp)
        workdir.mkdir(parents=True, exist_ok=True)
        fc_rows = []
        for tol in tolerances:
            fc_rows.append(run_flexcraft(workdir, f"automatic, tolerance {tol:g}",
                                         scenario_variant(text, tolerance=tol, max_dof=4000), REPEATS))
            print(f"  flexcraft tolerance {tol:g}: {fc_rows[-1]['dof']} DOF, {fc_rows[-1]['time_s']:.3f} s", flush=True)
        for terms in term_seq:
            label = "terms mast {}/{}/{}, wing {}×{}".format(*terms)
            fc_rows.append(run_flexcraft(workdir, label, scenario_variant(text, terms=terms), REPEATS))
            print(f"  flexcraft {label}: {fc_rows[-1]['dof']} DOF, {fc_rows[-1]['time_s']:.3f} s", flush=True)
        # The reference of tests/suite/term_selection.rs: mast 36/20/20, wing length 48, 64, 80
        # by width 28, extrapolated in the length count.
        levels = (12, 16, 20) if args.quick else REF_LENGTHS
        fc_levels = [run_flexcraft(workdir, f"reference, wing length {n}",
                                   scenario_variant(text, terms=(*REF_MAST, n, REF_WIDTH)), 1)
                     for n in levels]
        fc_ref = {"disc": "mast {}/{}/{}, wing length ".format(*REF_MAST)
                  + ", ".join(map(str, levels)) + f" × width {REF_WIDTH}, extrapolated",
                  "dof": fc_levels[-1]["dof"],
                  "freqs": richardson([r["freqs"] for r in fc_levels], levels[1] / levels[0], levels[2] / levels[1],
                                      (0.5, 30.0))}
        fc_ref["spread"] = max_rel(fc_levels[-1]["freqs"], fc_ref["freqs"])
        print(f"  flexcraft reference: {fc_ref['disc']}, extrapolation {fc_ref['spread']:.1e}", flush=True)
        ccx_rows = []
        for mesh in meshes:
            ccx_rows.append(run_ccx(workdir, *mesh, structure, REPEATS))
            print(f"  {ccx_rows[-1]['disc']}: {ccx_rows[-1]['dof']} DOF, {ccx_rows[-1]['time_s']:.3f} s", flush=True)

    ccx_ref = richardson([r["freqs"] for r in ccx_rows[-3:]], 2.0, 2.0, (1.0, 4.0))
    for r in fc_rows:
        r["err"] = max_rel(r["freqs"], fc_ref["freqs"])
    for r in ccx_rows:
        r["err"] = max_rel(r["freqs"], ccx_ref)
        r["err_fc"] = max_rel(r["freqs"], fc_ref["freqs"])

    print()
    print(f"First {N_ELASTIC} elastic frequencies [Hz]")
    print(f"{'mode':>4} {'flexcraft ref':>14} {'CalculiX limit':>15} {'finest mesh':>12} {'limit/ref - 1':>14}")
    for k in range(N_ELASTIC):
        a, b, c = fc_ref["freqs"][k], ccx_ref[k], ccx_rows[-1]["freqs"][k]
        print(f"{k + 1:>4} {a:>14.6f} {b:>15.6f} {c:>12.6f} {b / a - 1:>+14.2e}")
    print(f"flexcraft reference: {fc_ref['disc']} ({fc_ref['dof']} DOF at the finest; extrapolation {fc_ref['spread']:.1e})")
    print(f"CalculiX limit: Richardson extrapolation of its three finest meshes")
    print()
    print("| tool | discretisation | DOF | whole process [s] | max rel. error (own limit) | vs flexcraft ref |")
    print("|---|---|---:|---:|---:|---:|")
    for r in fc_rows:
        print(f"| flexcraft | {r['disc']} | {r['dof']} | {r['time_s']:.3f} | {r['err']:.1e} | {r['err']:.1e} |")
    for r in ccx_rows:
        print(f"| CalculiX | {r['disc']} | {r['dof']} | {r['time_s']:.3f} | {r['err']:.1e} | {r['err_fc']:.1e} |")
    print()
    for tol in (1e-3, 1e-4):
        tf, tc = time_to(fc_rows, tol), time_to(ccx_rows, tol)
        fmt = lambda t: f"{t:.3f} s" if t is not None else "not reached"
        ratio = f"{tc / tf:.0f}×" if tf and tc else "-"
        print(f"to {tol:g} (own limit): flexcraft {fmt(tf)}, CalculiX {fmt(tc)}, ratio {ratio}")


def cpu_name():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


if __name__ == "__main__":
    main()
