#!/usr/bin/env python3
"""High-precision reference values of the beam characteristic functions (tests/beam_functions.rs).

Run once:  python3 tests/data/gen_beam_functions.py > tests/data/beam_functions.csv
Requires mpmath (pip install mpmath). Uses the textbook form
    X = A cosh(bx) + B sinh(bx) + C cos(bx) + D sin(bx)
at 300 significant digits, where its cancellation (cosh(b) ~ 1e136 at n = 100) is harmless.
Normalisation: int_0^1 X^2 = 1, evaluated exactly from the identity (X'''' = b^4 X)
    4 b^4 int_0^1 X^2 = [x (b^4 X^2 - 2 X' X''' + X''^2) + 3 X X''' - X' X'']_0^1.
Sign: at the left end, X''(0) > 0 if clamped, X'(0) > 0 if pinned, X(0) > 0 if free.
Rows: ends, k (elastic index, 1-based), beta, xi, X, X', X'', X''' (17 significant digits).
The clamped-free rod functions sqrt(2) sin((2k-1) pi x / 2) are rows with ends "rod".
"""
import mpmath as mp

mp.mp.dps = 300
ORDERS = {"C": (0, 1), "P": (0, 2), "F": (2, 3)}
PAIRS = ["CF", "FF", "CC", "PP", "CP", "PF"]
XIS = ["0", "0.13", "0.5", "0.77", "1"]
NMAX = 100


def char_eq(pair):
    if pair in ("CF",):
        return lambda b: mp.cos(b) * mp.cosh(b) + 1, lambda k: (2 * k - 1) * mp.pi / 2
    if pair in ("FF", "CC"):
        return lambda b: mp.cos(b) * mp.cosh(b) - 1, lambda k: (2 * k + 1) * mp.pi / 2
    if pair in ("CP", "PF"):
        return lambda b: mp.sin(b) * mp.cosh(b) - mp.cos(b) * mp.sinh(b), lambda k: (4 * k + 1) * mp.pi / 4
    return None, lambda k: k * mp.pi


def basis(b, x, d):
    """d-th derivative of [cosh, sinh, cos, sin](b x)."""
    ch, sh, c, s = mp.cosh(b * x), mp.sinh(b * x), mp.cos(b * x), mp.sin(b * x)
    hyp = [ch, sh] if d % 2 == 0 else [sh, ch]
    trig = [[c, s], [-s, c], [-c, -s], [s, -c]][d % 4]
    return [b**d * v for v in hyp + trig]


def function(pair, b):
    rows = [basis(b, 0, o) for o in ORDERS[pair[0]]] + [basis(b, 1, o) for o in ORDERS[pair[1]]]
    m = mp.matrix(rows)
    # Null vector: fix the coefficient with the largest cofactor to 1.
    best = None
    for j in range(4):
        sub = mp.matrix([[rows[i][c] for c in range(4) if c != j] for i in range(3)])
        try:
            sol = mp.lu_solve(sub, mp.matrix([-rows[i][j] for i in range(3)]))
        except ZeroDivisionError:
            continue
        coef = list(sol)
        coef.insert(j, mp.mpf(1))
        res = max(abs(sum(m[3, c] * coef[c] for c in range(4))), mp.mpf(0))
        scale = max(abs(v) for v in coef)
        if best is None or res / scale < best[0]:
            best = (res / scale, coef)
    coef = best[1]

    def ev(x, d):
        return sum(cc * v for cc, v in zip(coef, basis(b, x, d)))

    def bracket(x):
        X, X1, X2, X3 = (ev(x, d) for d in range(4))
        return x * (b**4 * X * X - 2 * X1 * X3 + X2 * X2) + 3 * X * X3 - X1 * X2

    norm = mp.sqrt((bracket(mp.mpf(1)) - bracket(mp.mpf(0))) / (4 * b**4))
    sign_order = {"C": 2, "P": 1, "F": 0}[pair[0]]
    sgn = 1 if ev(mp.mpf(0), sign_order) > 0 else -1
    return lambda x, d: sgn * ev(x, d) / norm


def main():
    print("ends,k,beta,xi,X,dX,d2X,d3X")
    for pair in PAIRS:
        f, guess = char_eq(pair)
        for k in range(1, NMAX + 1):
            b = guess(k) if f is None else mp.findroot(f, guess(k))
            fn = function(pair, b)
            for xs in XIS:
                x = mp.mpf(xs)
                vals = [fn(x, d) for d in range(4)]
                print(",".join([pair, str(k), mp.nstr(b, 17)] + [xs] + [mp.nstr(v, 17) for v in vals]))
    for k in range(1, NMAX + 1):
        w = (2 * k - 1) * mp.pi / 2
        for xs in XIS:
            x = mp.mpf(xs)
            vals = [mp.sqrt(2) * w**d * mp.sin(w * x + d * mp.pi / 2) for d in range(4)]
            print(",".join(["rod", str(k), mp.nstr(w, 17), xs] + [mp.nstr(v, 17) for v in vals]))


if __name__ == "__main__":
    main()
