#!/usr/bin/env python3
"""SciPy reference values for the Monte Carlo statistics (tests/suite/independent_truths.rs).

Setup (once) and run from the repository root:
    python3 -m venv /tmp/v && /tmp/v/bin/pip install numpy scipy
    /tmp/v/bin/python tests/data/gen_stats_reference.py
It writes tests/data/stats_reference.json (deterministic for a given SciPy; the file records
the SciPy and NumPy versions it was made with). Values are written with 17 significant digits
(the double SciPy returned, exactly).

Contents:

1. "ks_critical": the exact critical value of the two-sided one-sample Kolmogorov-Smirnov
   statistic D_n = sup |F_n - F|, the (1 - alpha) quantile of its distribution for a sample
   of n from a continuous F: scipy.stats.kstwo.ppf(1 - alpha, n) (SciPy's exact distribution
   of D_n: Simard & L'Ecuyer, J. Stat. Softw. 39 (2011), and the algorithms cited there), for
   alpha in {0.001, 0.01, 0.05} and n in {1, 5, 10, 50, 100, 1000, 10000}. The script checks
   each by the round trip kstwo.sf(ppf) = alpha to 1e-6 relative (SciPy's largest deviation,
   at n = 1000, is 4e-7 of alpha, i.e. some 3e-8 of the critical value itself) and records
   the deviation.

2. "cdf": the CDF of every distribution flexcraft's Monte Carlo module offers
   (src/montecarlo/distributions.rs, docs/montecarlo.md, "Distributions"), with flexcraft's
   parameterisation mapped onto SciPy's:
     normal    [mean, sd]                 -> scipy.stats.norm(loc=mean, scale=sd)
     uniform   [low, high]                -> scipy.stats.uniform(loc=low, scale=high - low)
     lognormal [mu, sigma] (ln x ~ N)     -> scipy.stats.lognorm(s=sigma, scale=exp(mu))
     normal + truncate [low, high]        -> scipy.stats.truncnorm(a=(low - mean)/sd,
                                              b=(high - mean)/sd, loc=mean, scale=sd)
     choice [values], weights             -> the exact step CDF sum_{v_i <= x} w_i / sum w_i,
                                              in rational arithmetic (fractions.Fraction of
                                              the doubles), rounded once (SciPy's rv_discrete
                                              wants integer support points)
   at a grid of points (tails included: the normal down to Phi(-37.5) ~ 5e-308, and points
   outside each support).

3. "normal_quantile": scipy.stats.norm.ppf(p) (the standard normal quantile, for
   flexcraft's normal_quantile, Wichura's AS 241) from p = 1e-300 to 1 - 1e-12.

4. "quantile": each continuous distribution's quantile of a normal score z, F^-1(Phi(z)):
   SciPy's ppf(norm.cdf(z)) for z <= 0 and isf(norm.sf(z)) for z > 0 (the upper side from its
   own tail probability, which keeps its digits), for flexcraft's
   Distribution::from_normal_score (the Gaussian copula's marginal transform,
   docs/montecarlo.md).

Every truncated-normal case also records its probability P = Phi(beta) - Phi(alpha) (from the
tail on the interval's side): the accuracy an evaluation of its CDF can have scales with 1/P.

The reference's own accuracy. If mpmath is installed (/tmp/v/bin/pip install mpmath), every
value is also evaluated at 50 digits (mpmath.ncdf, bisection for the quantiles) and the
script stops if SciPy is off by more than: CDFs 2e-15 absolute (and 2e-13 relative, except
the truncated normal, whose SciPy CDF is accurate in absolute terms only: 2e-10 relative just
inside its lower bound); normal quantile 1e-15 relative; quantiles of a score 5e-14 relative
(SciPy's truncnorm.isf is 1e-14 off at the upper end of [3, 5]). SciPy 1.17.1's largest
deviations: 1.2e-15 absolute (lognormal, sigma = 0.02), 5.7e-14 relative (Phi(-37.5)),
1.4e-16, 1.8e-14. Without mpmath the check is skipped (the file is the same either way).
"""
import json
import math
import os
from fractions import Fraction

import numpy
import scipy
from scipy import stats

try:
    import mpmath
except ImportError:  # the check against 50 digits is optional
    mpmath = None

HERE = os.path.dirname(os.path.abspath(__file__))

ALPHAS = [0.001, 0.01, 0.05]
NS = [1, 5, 10, 50, 100, 1000, 10000]

# Standard normal scores used for the grids.
Z = [-37.5, -30.0, -20.0, -10.0, -8.0, -5.0, -3.0, -1.959963984540054, -1.0, -0.5, -1e-3,
     0.0, 1e-3, 0.5, 1.0, 1.959963984540054, 3.0, 5.0, 8.0, 9.0]
Z_SHORT = [-6.0, -3.0, -1.0, -0.25, 0.0, 0.25, 1.0, 3.0, 6.0]


def ks_table():
    rows = []
    for alpha in ALPHAS:
        for n in NS:
            d = float(stats.kstwo.ppf(1.0 - alpha, n))
            back = float(stats.kstwo.sf(d, n))
            dev = abs(back - alpha) / alpha
            assert dev < 1e-6, (alpha, n, d, back)
            rows.append({"alpha": alpha, "n": n, "critical": d, "sf_roundtrip_rel": dev})
    return rows


def normal_cases():
    cases = []
    for mean, sd in [(0.0, 1.0), (3.0, 0.2), (-1000.0, 50.0), (1e-3, 1e-6)]:
        xs = [mean + sd * z for z in (Z if (mean, sd) == (0.0, 1.0) else Z_SHORT)]
        d = stats.norm(loc=mean, scale=sd)
        cases.append({"kind": "normal", "params": [mean, sd], "x": xs,
                      "cdf": [float(d.cdf(x)) for x in xs]})
    return cases


def uniform_cases():
    cases = []
    for low, high in [(0.0, 0.1), (-2.0, 3.0), (1000.0, 1000.001)]:
        w = high - low
        xs = [low - w, low, low + 1e-9 * w, low + 0.25 * w, low + w / 3.0, low + 0.5 * w,
              low + 0.9 * w, high, high + w]
        d = stats.uniform(loc=low, scale=w)
        cases.append({"kind": "uniform", "params": [low, high], "x": xs,
                      "cdf": [float(d.cdf(x)) for x in xs]})
    return cases


def lognormal_cases():
    cases = []
    for mu, sigma in [(0.0, 1.0), (1.6, 0.1), (2.0794, 0.02), (-3.0, 2.0)]:
        xs = [-1.0, 0.0] + [math.exp(mu + sigma * z) for z in Z_SHORT]
        d = stats.lognorm(s=sigma, scale=math.exp(mu))
        cases.append({"kind": "lognormal", "params": [mu, sigma], "x": xs,
                      "cdf": [float(d.cdf(x)) for x in xs]})
    return cases


TRUNCATED = [
    (0.4, 0.05, 0.35, 0.48),      # tests/suite/montecarlo.rs
    (800.0, 8.0, 780.0, 820.0),   # docs/montecarlo.md
    (0.0, 1.0, -1.0, 2.0),
    (0.0, 1.0, 3.0, 5.0),         # upper tail, probability 1.35e-3
    (0.0, 1.0, -5.0, -3.0),       # lower tail
    (0.0, 1.0, -10.0, 0.1),
]


def truncnorm(mean, sd, low, high):
    return stats.truncnorm(a=(low - mean) / sd, b=(high - mean) / sd, loc=mean, scale=sd)


def truncated_cases():
    cases = []
    for mean, sd, low, high in TRUNCATED:
        w = high - low
        xs = [low - 1.0, low, low + 1e-6 * w, low + 0.1 * w, low + 0.5 * w, low + 0.9 * w,
              high - 1e-6 * w, high, high + 1.0]
        d = truncnorm(mean, sd, low, high)
        a, b = (low - mean) / sd, (high - mean) / sd
        p = stats.norm.sf(a) - stats.norm.sf(b) if a > 0 else stats.norm.cdf(b) - stats.norm.cdf(a)
        cases.append({"kind": "truncated_normal", "params": [mean, sd, low, high],
                      "probability": float(p), "x": xs, "cdf": [float(d.cdf(x)) for x in xs]})
    return cases


def choice_cases():
    cases = []
    for values, weights in [([0.0, 0.001, 0.002], [1.0, 2.0, 1.0]),
                            ([0.2, 0.25, 0.3], [1.0, 1.0, 1.0]),
                            ([5.0, -1.0, 2.5], [0.3, 0.1, 0.6])]:
        xs = sorted({v + dv for v in values for dv in (-1e-9, 0.0, 1e-9)} | {-10.0, 10.0})
        total = sum(Fraction(w) for w in weights)
        cdf = [float(sum((Fraction(w) for v, w in zip(values, weights) if v <= x), Fraction(0))
                     / total) for x in xs]
        cases.append({"kind": "choice", "params": values, "weights": weights, "x": xs,
                      "cdf": cdf})
    return cases


def normal_quantiles():
    ps = [1e-300, 1e-100, 1e-20, 1e-12, 1e-5, 0.001, 0.01, 0.02425, 0.07, 0.3, 0.5, 0.6,
          0.92, 0.975, 0.999, 1.0 - 1e-9, 1.0 - 1e-12]
    return {"p": ps, "x": [float(stats.norm.ppf(p)) for p in ps]}


def quantile_cases():
    """F^-1(Phi(z)), SciPy: ppf(Phi(z)) for z <= 0, isf(Phi(-z)) for z > 0 (no 1 - p loss)."""
    zs = [-6.0, -3.0, -1.0, -0.25, 0.0, 0.25, 1.0, 3.0, 6.0]
    dists = [("normal", [0.0, 1.0], stats.norm()),
             ("normal", [3.0, 0.2], stats.norm(loc=3.0, scale=0.2)),
             ("uniform", [-2.0, 3.0], stats.uniform(loc=-2.0, scale=5.0)),
             ("lognormal", [1.6, 0.1], stats.lognorm(s=0.1, scale=math.exp(1.6)))]
    dists += [("truncated_normal", list(t), truncnorm(*t)) for t in TRUNCATED]
    cases = []
    for kind, params, d in dists:
        x = [float(d.ppf(stats.norm.cdf(z))) if z <= 0 else float(d.isf(stats.norm.sf(z)))
             for z in zs]
        cases.append({"kind": kind, "params": params, "z": zs, "x": x})
    return cases


def check_against_mpmath(out):
    """SciPy's values against 50-digit evaluations (the bounds in the header)."""
    mp = mpmath
    mp.mp.dps = 50
    big = mp.mpf

    def ncdf(z):
        return mp.ncdf(z)

    def cdf(c, x):
        p, x = [big(v) for v in c["params"]], big(x)
        kind = c["kind"]
        if kind == "normal":
            return ncdf((x - p[0]) / p[1])
        if kind == "uniform":
            return min(max((x - p[0]) / (p[1] - p[0]), big(0)), big(1))
        if kind == "lognormal":
            return big(0) if x <= 0 else ncdf((mp.log(x) - p[0]) / p[1])
        if kind == "truncated_normal":
            m, s, lo, hi = p
            a = ncdf((lo - m) / s)
            return (ncdf((min(max(x, lo), hi) - m) / s) - a) / (ncdf((hi - m) / s) - a)
        w = [big(v) for v in c["weights"]]
        return sum((wi for v, wi in zip(p, w) if v <= x), big(0)) / sum(w)

    for c in out["cdf"]:
        for x, f in zip(c["x"], c["cdf"]):
            t = cdf(c, x)
            e = abs(big(f) - t)
            assert e <= 2e-15, (c["kind"], c["params"], x, f, t)
            if c["kind"] != "truncated_normal" and t > 0:
                assert e <= 2e-13 * t, (c["kind"], c["params"], x, f, t)

    q = out["normal_quantile"]
    for p, x in zip(q["p"], q["x"]):
        t = mp.findroot(lambda y: ncdf(y) - big(p), big(x))
        assert abs(big(x) - t) <= 1e-15 * abs(t), (p, x, t)

    def quantile(c, z):
        p, z = [big(v) for v in c["params"]], big(z)
        kind = c["kind"]
        if kind == "normal":
            return p[0] + p[1] * z
        if kind == "lognormal":
            return mp.exp(p[0] + p[1] * z)
        if kind == "uniform":
            return p[0] + (p[1] - p[0]) * ncdf(z)
        m, s, lo, hi = p
        a, b = (lo - m) / s, (hi - m) / s
        # P(X > x) = Phi(-z): bisection on the upper tail probability, 200 halvings.
        target = ncdf(-b) + ncdf(-z) * (ncdf(-a) - ncdf(-b))
        left, right = a, b
        for _ in range(200):
            mid = (left + right) / 2
            if ncdf(-mid) > target:
                left = mid
            else:
                right = mid
        return m + s * left

    for c in out["quantile"]:
        for z, x in zip(c["z"], c["x"]):
            t = quantile(c, z)
            assert abs(big(x) - t) <= 5e-14 * abs(t), (c["kind"], c["params"], z, x, t)


def fmt(v):
    if isinstance(v, float):
        return "0.0" if v == 0.0 else f"{v:.16e}"
    return json.dumps(v)


def to_json(v, indent=0):
    pad = " " * indent
    if isinstance(v, dict):
        items = [f'{pad}  {json.dumps(k)}: {to_json(x, indent + 2).lstrip()}' for k, x in v.items()]
        return pad + "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(v, list) and v and isinstance(v[0], dict):
        return pad + "[\n" + ",\n".join(to_json(x, indent + 2) for x in v) + "\n" + pad + "]"
    if isinstance(v, list):
        return pad + "[" + ", ".join(fmt(x) for x in v) + "]"
    return pad + fmt(v)


def main():
    out = {
        "generator": "tests/data/gen_stats_reference.py",
        "scipy": scipy.__version__,
        "numpy": numpy.__version__,
        "ks_critical": ks_table(),
        "cdf": normal_cases() + uniform_cases() + lognormal_cases() + truncated_cases()
        + choice_cases(),
        "normal_quantile": normal_quantiles(),
        "quantile": quantile_cases(),
    }
    if mpmath is not None:
        check_against_mpmath(out)
    else:
        print("mpmath not installed: the check of SciPy against 50 digits is skipped")
    text = to_json(out) + "\n"
    json.loads(text)
    with open(os.path.join(HERE, "stats_reference.json"), "w", encoding="utf-8") as fh:
        fh.write(text)


if __name__ == "__main__":
    main()
