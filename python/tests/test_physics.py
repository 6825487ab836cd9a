"""Spot checks against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

import flexcraft as fc
from conftest import EXAMPLES


def bisect(f, a, b, tol=1e-14):
    fa = f(a)
    for _ in range(200):
        m = 0.5 * (a + b)
        fm = f(m)
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
        if b - a < tol * b:
            break
    return 0.5 * (a + b)


def test_tip_mass_cantilever_first_bending_frequency():
    """examples/tip_mass.toml: a clamped-free beam (EI, ρA, L) with a tip mass m. The
    frequency equation with the tip's rotary inertia J about a transverse axis (Blevins,
    Formulas for Natural Frequency and Mode Shape, table 8-1 case 3, J included; the same
    boundary conditions as tests/suite/exact_beams.rs):
        EI W''(L) = J ω² W'(L),  EI W'''(L) = −m ω² W(L),  W(0) = W'(0) = 0,
    with W = A(cosh βx − cos βx) + B(sinh βx − sin βx), β⁴ = ρA ω² / EI."""
    e, rho, area, i, length, m_tip, j_tip = 70e9, 2700.0, 1e-3, 1e-6, 2.0, 3.0, 0.2
    ei, mu = e * i, rho * area

    def det(beta):
        w2 = beta**4 * ei / mu
        bl = beta * length
        ch, sh, c, s = math.cosh(bl), math.sinh(bl), math.cos(bl), math.sin(bl)
        # Columns: the A and B functions; rows: the two tip conditions.
        def row_moment(f2, f1):
            return ei * f2 - j_tip * w2 * f1

        def row_shear(f3, f0):
            return ei * f3 + m_tip * w2 * f0

        # A: φ = ch − c; φ' = β(sh + s); φ'' = β²(ch + c); φ''' = β³(sh − s)
        # B: ψ = sh − s; ψ' = β(ch − c); ψ'' = β²(sh + s); ψ''' = β³(ch + c)
        a11 = row_moment(beta**2 * (ch + c), beta * (sh + s))
        a12 = row_moment(beta**2 * (sh + s), beta * (ch - c))
        a21 = row_shear(beta**3 * (sh - s), ch - c)
        a22 = row_shear(beta**3 * (ch + c), sh - s)
        return (a11 * a22 - a12 * a21) / (ch * ch)

    # First root: scan for a sign change, then bisect.
    betas = np.linspace(0.05, 3.0, 3000) / length
    vals = [det(b) for b in betas]
    k = next(k for k in range(len(vals) - 1) if (vals[k] > 0) != (vals[k + 1] > 0))
    beta1 = bisect(det, betas[k], betas[k + 1])
    f_exact = beta1**2 * math.sqrt(ei / mu) / (2 * math.pi)

    m = fc.modes(fc.Scenario.from_file(EXAMPLES / "tip_mass.toml"))
    assert not m.rigid.any()  # fixed hub
    # The beam bends alike in its two planes (iy = iz): the first two modes are the pair.
    f1 = m.frequency_hz[0]
    assert abs(f1 - f_exact) < 1e-6 * f_exact, (f1, f_exact)
    assert abs(m.frequency_hz[1] - f_exact) < 1e-6 * f_exact
    # Its shape: zero at the root, largest at the tip.
    s = m.shape("beam", np.linspace(0.0, 1.0, 11), mode=1)
    assert s.shape == (11, 6)
    lateral = np.hypot(s[:, 1], s[:, 2])
    assert lateral[0] < 1e-12 and np.all(np.diff(lateral) > 0)


ONE_PANEL = """
name = "one panel on a fixed hub"
format_version = 1

[hub]
motion = "fixed"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
center_of_mass = [0.0, 0.0, 0.0]

[[plates]]
name = "wing"
parent = "hub"
root = [0.0, 0.0, 0.0]
length_axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
length = {length}
width = 2.0
areal_density = {rho_a}
bending_stiffness = 1e5
poisson_ratio = 0.3
terms = {{ length = 4, width = 3 }}

[deployment]
plate = "wing"
panels = 1
base = "rigid"
end_time = 100.0
output_rate = 10.0
integrator = "explicit"
tolerance = 1e-12

[deployment.hinge]
stiffness = {k}
preload_angle = {preload}
damping = 0.0
friction = 0.0
"""


@pytest.mark.parametrize("k", [0.5, 3.0, 20.0])
def test_one_panel_latch_time_closed_form(k):
    """One rigid panel on a fixed hub, a linear hinge spring, no damping or friction:
    J α̈ = k (α_ref − α) from rest, so α = α_ref (1 − cos ωt), ω = √(k/J), and the latch at
    α_L = π/2 comes at t = arccos(1 − α_L/α_ref)/ω; J = m l²/3 about the hinge (a thin
    panel, I = m l²/12 about its centre)."""
    length, rho_a, width, preload = 4.0, 7.5, 2.0, 0.6
    sc = fc.Scenario.from_toml(
        ONE_PANEL.format(length=length, rho_a=rho_a, k=k, preload=preload), "one_panel.toml"
    )
    d = fc.deploy(sc)
    mass = rho_a * length * width
    j = mass * length**2 / 3.0
    a_ref = math.pi / 2 + preload
    w = math.sqrt(k / j)
    t_latch = math.acos(1.0 - (math.pi / 2) / a_ref) / w
    assert d.all_latched
    ev = d.latches[0]
    assert ev.hinge == 1
    assert abs(ev.time - t_latch) < 1e-8 * t_latch, (ev.time, t_latch)
    rate = a_ref * w * math.sin(w * t_latch)
    assert abs(ev.rates_before[0] - rate) < 1e-8 * rate
    assert ev.rates_after[0] == 0.0
    assert abs(ev.energy_lost - 0.5 * j * rate**2) < 1e-8 * ev.energy_lost
    # α(t) before the latch on the samples.
    before = d.t < t_latch
    want = a_ref * (1 - np.cos(w * d.t[before]))
    assert np.allclose(d.alpha[before, 0], want, rtol=0, atol=1e-8)
    # The sweep parameter by override gives the same run.
    base = fc.Scenario.from_toml(
        ONE_PANEL.format(length=length, rho_a=rho_a, k=1.0, preload=preload), "one_panel.toml"
    )
    d2 = fc.deploy(base.with_values({"deployment.hinge.stiffness": k}))
    assert d2.latches[0].time == ev.time
