#!/usr/bin/env python3
"""Independent rigid-body mass properties of the bundled examples (tests/suite/independent_truths.rs).

Run from the repository root:   python3 tests/data/gen_mass_properties.py
It writes tests/data/mass_properties.json (deterministic: run it twice, same bytes).
Python 3.11 standard library only (tomllib, json, decimal).

What it computes, for examples/seed.toml, composite.toml and full.toml, from the scenario's
own numbers (the TOML file, read with tomllib, nothing of flexcraft's code):

  * the total mass M,
  * the centre of mass c (structure axes, m),
  * the inertia tensor J_cm about c (structure axes, kg m^2),
  * the hub's centre of mass h, and the 6 x 6 rigid mass block about h that the Ritz model's
    hub coordinates (translation of h, small rotation) must carry:
        B = [[M I, -S(s)], [S(s), J_h]],  s = M (c - h),  S(a) b = a x b,
    because the kinetic energy of the rigid motion v = U' + Theta' x r (r from h) is
    1/2 [U'; Theta']^T B [U'; Theta'] (docs/theory.md 1.2, the hub coordinates).

Formulation (deliberately not the code's: flexcraft sums each component's inertia about its
attachment point and moves it with the parallel-axis theorem; here every component is
integrated into three moments about the structure origin O)

    mass         M     = sum  integral dm
    first moment F     = sum  integral r dm
    second moment Sigma = sum  integral r r^T dm           (a symmetric 3 x 3 tensor)

and then  J_O = tr(Sigma) I - Sigma,  c = F / M,  J_cm = J_O - M (|c|^2 I - c c^T).
A body given by its own inertia J about its own centre c_b (the hub, a lumped mass) enters
Sigma through the inverse of that map: its second moment about its centre is
Sigma_b = tr(J)/2 I - J (since tr J = 2 tr Sigma_b), plus m c_b c_b^T.  The map is linear, so
the same holds for an inertia that is not the inertia of any mass distribution (a beam's
polar line inertia below, which alone breaks the triangle inequality): it is added as an
inertia, k e e^T  <=>  Sigma += k/2 I - k e e^T.

Arithmetic: Python's decimal module at 60 significant digits (pi from the decimal
documentation's series; square roots by Decimal.sqrt). The TOML numbers are converted
exactly from the binary doubles tomllib returns (the same doubles the Rust parser reads), so
the results are the exact mass properties of the file's doubles to ~55 digits, rounded once
to the nearest double when written (17 significant digits).

The components and their formulas (docs/scenario.md, docs/theory.md 1.1):

Hub, given: mass m, centre of mass c_h, inertia about c_h: 3 principal values (diagonal) or 6
  values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] entering the tensor as given (J_xy = Ixy, ...).
  docs/scenario.md names the six values but not the products' sign convention; the tensor-
  entry convention is the one src/structure/rigid.rs (inertia_tensor) documents.

Hub, shape = cylinder {diameter D, wall t, length L, axis a, center c0, material rho,
  closed_ends}: a circular tube of outer radius R = D/2, inner radius r = R - t, length L,
  centred on c0 along the unit axis a (centre of mass c0 by symmetry). Its second moment
  about c0, with dA the annulus element and z along a:
      integral x^2 dA = integral_0^2pi integral_r^R (rho' cos phi)^2 rho' drho' dphi
                      = pi (R^4 - r^4)/4      (the same for y; x y integrates to 0)
      integral_{-L/2}^{L/2} z^2 dz = L^3/12
      Sigma_tube = rho [ L pi (R^4 - r^4)/4 (I - a a^T) + pi (R^2 - r^2) L^3/12 a a^T ],
      m_tube = rho pi (R^2 - r^2) L.
  closed_ends = true adds two solid end discs "of the same wall thickness" (docs/scenario.md).
  Where the discs sit is not written in the docs; docs/seed-comparison.md puts the seed's
  tube (L = 15, centre z = -7.5) with its top end at the origin, which holds if the discs
  close the tube inside its length. Each disc: radius r (the inner radius, fitting inside the
  wall), thickness t, its centre on the axis at +-(L - t)/2 from c0 (flush with the ends):
      m_d = rho pi r^2 t,
      Sigma_disc = rho [ t pi r^4/4 (I - a a^T) + pi r^2 t^3/12 a a^T ] + m_d d^2 a a^T,
      d = (L - t)/2.
  (Checked against src/structure/components.rs, Hub::cylinder, for the placement only.)

Beam {root p (hub parent) or station s on a parent beam, axis e (unit), length L, material
  rho, section}: a line mass lambda = rho A from p to p + L e (Euler-Bernoulli: no rotary
  inertia of the section in bending, docs/scenario.md "Rotary inertia of the section in
  bending is neglected"), plus the torsional line inertia rho I_p per length about e
  ("in torsion the line inertia is rho polar_inertia"):
      m = lambda L
      F = lambda integral_0^L (p + x e) dx = lambda (L p + L^2/2 e)
      Sigma = lambda integral_0^L (p + x e)(p + x e)^T dx
            = lambda (L p p^T + L^2/2 (p e^T + e p^T) + L^3/3 e e^T)
      J += k e e^T with k = rho I_p L  (Sigma += k/2 I - k e e^T).
  Sections: tube {outer_diameter D, wall t}: R = D/2, r = R - t, A = pi (R^2 - r^2),
  I_p = integral rho'^2 dA = 2 pi integral_r^R rho'^3 drho' = pi (R^4 - r^4)/2;
  general {area, polar_inertia, ...}: A and I_p as given.
  A beam on a beam: its root is the parent's root + station * (parent's unit axis).

Plate {root p (hub) or station on a beam, length_axis e_a, normal n, length a, width b,
  areal density mu (given, or rho h for thickness h and a material)}: a uniform sheet
  (thin, in its mid-plane, docs/theory.md 1.1) over x in [0, a] along e_a and y in
  [-b/2, b/2] along e_b = n x e_a ("the root edge (width b) is centred on the attachment
  point"):
      m = mu a b
      F = m (p + a/2 e_a)
      Sigma = mu integral integral (p + x e_a + y e_b)(...)^T dy dx
            = m (p p^T + a/2 (p e_a^T + e_a p^T) + a^2/3 e_a e_a^T + b^2/12 e_b e_b^T)
      (the terms odd in y integrate to zero).

Lumped mass {point on the hub, or station on a beam; offset o (default 0); mass m; inertia
  J about its own centre (3 or 6 values as for the hub, default 0)}: centre q = attachment
  point + o;  F = m q,  Sigma = m q q^T + tr(J)/2 I - J.
"""
import json
import os
import tomllib
from decimal import Decimal, getcontext

getcontext().prec = 60

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXAMPLES = ["seed.toml", "composite.toml", "full.toml"]


def pi():
    """pi to the current precision (the recipe of the decimal module's documentation)."""
    getcontext().prec += 2
    three = Decimal(3)
    lasts, t, s, n, na, d, da = 0, three, 3, 1, 0, 0, 24
    while s != lasts:
        lasts = s
        n, na = n + na, na + 8
        d, da = d + da, da + 32
        t = (t * n) / d
        s += t
    getcontext().prec -= 2
    return +s


PI = pi()
ZERO = Decimal(0)
HALF = Decimal(1) / 2


def D(x):
    """The exact value of a TOML number (an int, or the binary double tomllib read)."""
    return Decimal(x)


def vec(v):
    assert len(v) == 3
    return [D(x) for x in v]


def add(u, v):
    return [a + b for a, b in zip(u, v)]


def sub(u, v):
    return [a - b for a, b in zip(u, v)]


def scale(u, k):
    return [a * k for a in u]


def dot(u, v):
    return sum((a * b for a, b in zip(u, v)), ZERO)


def cross(u, v):
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def unit(v):
    v = vec(v)
    return scale(v, 1 / dot(v, v).sqrt())


def outer(u, v):
    return [[a * b for b in v] for a in u]


def madd(a, b):
    return [[x + y for x, y in zip(ra, rb)] for ra, rb in zip(a, b)]


def mscale(a, k):
    return [[x * k for x in r] for r in a]


def eye():
    return [[Decimal(int(i == j)) for j in range(3)] for i in range(3)]


def trace(a):
    return a[0][0] + a[1][1] + a[2][2]


def sym(a, b):
    """a b^T + b a^T."""
    return madd(outer(a, b), outer(b, a))


def inertia_tensor(values):
    """3 principal values (diagonal) or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] as tensor entries."""
    v = [D(x) for x in values]
    if len(v) == 3:
        return [[v[0], ZERO, ZERO], [ZERO, v[1], ZERO], [ZERO, ZERO, v[2]]]
    assert len(v) == 6
    return [[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]]


def sigma_of_inertia(j):
    """The second moment about the body's centre whose inertia is j: tr(j)/2 I - j."""
    return madd(mscale(eye(), trace(j) / 2), mscale(j, -1))


class Moments:
    """Mass, first moment and second moment about the structure origin."""

    def __init__(self):
        self.m = ZERO
        self.f = [ZERO] * 3
        self.s = [[ZERO] * 3 for _ in range(3)]

    def add(self, m, f, s):
        self.m += m
        self.f = add(self.f, f)
        self.s = madd(self.s, s)

    def add_body(self, m, c, j):
        """A rigid body of mass m, centre c, inertia j about c."""
        self.add(m, scale(c, m), madd(mscale(outer(c, c), m), sigma_of_inertia(j)))


def cylinder_hub(shape, materials, acc):
    c = shape["cylinder"]
    rho = D(materials[c["material"]]["density"])
    big_r = D(c["diameter"]) / 2
    t = D(c["wall"])
    length = D(c["length"])
    r = big_r - t
    a = unit(c["axis"])
    c0 = vec(c["center"])
    aa = outer(a, a)
    across = madd(eye(), mscale(aa, -1))
    # The tube about its centre.
    m_tube = rho * PI * (big_r**2 - r**2) * length
    s_tube = madd(
        mscale(across, rho * length * PI * (big_r**4 - r**4) / 4),
        mscale(aa, rho * PI * (big_r**2 - r**2) * length**3 / 12),
    )
    m, s = m_tube, s_tube
    if c.get("closed_ends", False):
        m_d = rho * PI * r**2 * t
        d = (length - t) / 2
        s_d = madd(
            madd(mscale(across, rho * t * PI * r**4 / 4), mscale(aa, rho * PI * r**2 * t**3 / 12)),
            mscale(aa, m_d * d * d),
        )
        m += 2 * m_d
        s = madd(s, mscale(s_d, 2))
    # Moved to c0: integral (c0 + x)(c0 + x)^T dm = m c0 c0^T + s (the first moment about c0
    # vanishes by symmetry).
    acc.add(m, scale(c0, m), madd(mscale(outer(c0, c0), m), s))
    return c0


def mass_properties(path):
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    materials = doc.get("materials", {})
    beams = {b["name"]: b for b in doc.get("beams", [])}
    acc = Moments()

    hub = doc["hub"]
    if "shape" in hub:
        hub_c = cylinder_hub(hub["shape"], materials, acc)
    else:
        hub_c = vec(hub["center_of_mass"])
        acc.add_body(D(hub["mass"]), hub_c, inertia_tensor(hub["inertia"]))

    def beam_root(name):
        b = beams[name]
        if b["parent"] == "hub":
            return vec(b["root"])
        parent = beams[b["parent"]]
        return add(beam_root(parent["name"]), scale(unit(parent["axis"]), D(b["station"])))

    def attachment(item, hub_key):
        if item["parent"] == "hub":
            return vec(item[hub_key])
        parent = beams[item["parent"]]
        return add(beam_root(parent["name"]), scale(unit(parent["axis"]), D(item["station"])))

    for b in doc.get("beams", []):
        rho = D(materials[b["material"]]["density"])
        sec = b["section"]
        if "tube" in sec:
            big_r = D(sec["tube"]["outer_diameter"]) / 2
            r = big_r - D(sec["tube"]["wall"])
            area = PI * (big_r**2 - r**2)
            polar = PI * (big_r**4 - r**4) / 2
        else:
            area = D(sec["area"])
            polar = D(sec["polar_inertia"])
        p = beam_root(b["name"])
        e = unit(b["axis"])
        length = D(b["length"])
        lam = rho * area
        m = lam * length
        f = scale(add(scale(p, length), scale(e, length**2 / 2)), lam)
        s = mscale(
            madd(madd(mscale(outer(p, p), length), mscale(sym(p, e), length**2 / 2)),
                 mscale(outer(e, e), length**3 / 3)),
            lam,
        )
        k = rho * polar * length
        s = madd(s, sigma_of_inertia(mscale(outer(e, e), k)))
        acc.add(m, f, s)

    for pl in doc.get("plates", []):
        if "areal_density" in pl:
            mu = D(pl["areal_density"])
        else:
            mu = D(materials[pl["material"]]["density"]) * D(pl["thickness"])
        p = attachment(pl, "root")
        ea = unit(pl["length_axis"])
        eb = cross(unit(pl["normal"]), ea)
        a, b = D(pl["length"]), D(pl["width"])
        m = mu * a * b
        f = scale(add(p, scale(ea, a / 2)), m)
        s = mscale(
            madd(
                madd(outer(p, p), mscale(sym(p, ea), a / 2)),
                madd(mscale(outer(ea, ea), a * a / 3), mscale(outer(eb, eb), b * b / 12)),
            ),
            m,
        )
        acc.add(m, f, s)

    for lm in doc.get("masses", []):
        q = add(attachment(lm, "point"), vec(lm.get("offset", [0.0, 0.0, 0.0])))
        j = inertia_tensor(lm["inertia"]) if "inertia" in lm else [[ZERO] * 3 for _ in range(3)]
        acc.add_body(D(lm["mass"]), q, j)

    big_m = acc.m
    c = scale(acc.f, 1 / big_m)
    j_o = madd(mscale(eye(), trace(acc.s)), mscale(acc.s, -1))

    def shift(d):
        """M (|d|^2 I - d d^T)."""
        return mscale(madd(mscale(eye(), dot(d, d)), mscale(outer(d, d), -1)), big_m)

    j_cm = madd(j_o, mscale(shift(c), -1))
    d = sub(c, hub_c)
    j_h = madd(j_cm, shift(d))
    s = scale(d, big_m)
    skew = [[ZERO, -s[2], s[1]], [s[2], ZERO, -s[0]], [-s[1], s[0], ZERO]]
    block = [[ZERO] * 6 for _ in range(6)]
    for i in range(3):
        block[i][i] = big_m
        for k in range(3):
            block[i][3 + k] = -skew[i][k]
            block[3 + i][k] = skew[i][k]
            block[3 + i][3 + k] = j_h[i][k]
    return {
        "mass": big_m,
        "center_of_mass": c,
        "inertia_cm": j_cm,
        "hub_center_of_mass": hub_c,
        "hub_block": block,
    }


def fmt(x):
    """A Decimal rounded once to the nearest double, written with 17 significant digits."""
    v = float(x)
    return "0.0" if v == 0.0 else f"{v:.16e}"


def to_json(v, indent):
    pad = " " * indent
    if isinstance(v, dict):
        items = [f'{pad}  "{k}": {to_json(x, indent + 2).lstrip()}' for k, x in v.items()]
        return pad + "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(v, list) and v and isinstance(v[0], list):
        rows = [to_json(r, indent + 2) for r in v]
        return pad + "[\n" + ",\n".join(rows) + "\n" + pad + "]"
    if isinstance(v, list):
        return pad + "[" + ", ".join(fmt(x) for x in v) + "]"
    if isinstance(v, str):
        return pad + json.dumps(v)
    return pad + fmt(v)


def main():
    out = {
        "generator": "tests/data/gen_mass_properties.py",
        "units": "kg, m, kg m^2; structure axes",
    }
    for name in EXAMPLES:
        out[name] = mass_properties(os.path.join(ROOT, "examples", name))
    text = to_json(out, 0) + "\n"
    json.loads(text)  # well-formed
    with open(os.path.join(HERE, "mass_properties.json"), "w", encoding="utf-8") as fh:
        fh.write(text)


if __name__ == "__main__":
    main()
