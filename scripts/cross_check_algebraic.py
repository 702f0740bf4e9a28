#!/usr/bin/env python3
"""High-precision cross-check of the algebraic witnesses of an analysis table.

A second route, independent of mms's exact arithmetic over number fields:
for every verdict of a file written by `mms analyze --format json` that
carries an `algebraic` witness, theta is found by bisection at 240 digits
(mpmath) inside the witness's interval, every parameter is evaluated there,
the numerator and denominator in Omega are formed from the table's own
polynomials (SymPy), their roots found by mpmath.polyroots at 240 digits,
roots of both within a relative 1e-35 cancelled, zeros within 1e-35 of
each other grouped into one multiple zero, and the type read (A^k for a
positive real zero of multiplicity k, R for a positive pole, in increasing
order, "(nm)" when a zero is not positive real). It must equal the
verdict's type.

Usage: scripts/cross_check_algebraic.py FILE.json
Exit status 1 on any disagreement. Set up with scripts/setup-venv.sh.
"""

import json
import sys

import mpmath as mp
import sympy as sp

# A zero of multiplicity k moves by about eps^(1/k) under rounding eps:
# at 240 digits a quadruple zero's copies stay within 1e-60.
mp.mp.dps = 240
TOL = mp.mpf(10) ** -35


def theta_of(w):
    t = sp.Symbol("theta")
    f = sp.Poly(sp.sympify(w["minimal"]), t)
    coeffs = [mp.mpf(sp.Rational(c).p) / sp.Rational(c).q for c in f.all_coeffs()]
    lo, hi = (mp.mpf(sp.Rational(x).p) / sp.Rational(x).q for x in w["interval"])
    if lo == hi:
        return lo
    flo = mp.polyval(coeffs, lo)
    for _ in range(900):
        m = (lo + hi) / 2
        fm = mp.polyval(coeffs, m)
        if fm == 0:
            return m
        if (fm > 0) == (flo > 0):
            lo, flo = m, fm
        else:
            hi = m
    return (lo + hi) / 2


def roots_of(poly, omega):
    c = [mp.mpf(sp.Rational(x).p) / sp.Rational(x).q if x.is_Rational else mp.mpf(sp.N(x, 250))
         for x in sp.Poly(poly, omega).all_coeffs()]
    while c and c[0] == 0:
        c.pop(0)
    if len(c) <= 1:
        return []
    return list(mp.polyroots(c, maxsteps=20000, extraprec=800))


def read_type(num_roots, den_roots):
    close = lambda a, b: abs(a - b) <= TOL * max(1, abs(a), abs(b))
    num, den = list(num_roots), list(den_roots)
    for r in list(den):
        for i, z in enumerate(num):
            if close(r, z):
                num.pop(i)
                den.remove(r)
                break
    positive = lambda r: abs(mp.im(r)) <= TOL * max(1, abs(r)) and mp.re(r) > 0
    zeros = sorted(mp.re(z) for z in num if positive(z))
    poles = sorted(mp.re(p) for p in den if positive(p))
    groups = []
    for z in zeros:
        if groups and close(groups[-1][0], z):
            groups[-1][1] += 1
        else:
            groups.append([z, 1])
    tokens = [(g[0], "A" if g[1] == 1 else f"A^{g[1]}") for g in groups]
    tokens += [(p, "R") for p in poles]
    tokens.sort(key=lambda x: x[0])
    text = "".join(t for _, t in tokens)
    if len(zeros) < len(num):
        text += " (nm)"
    return text or "C"


def main() -> int:
    data = json.load(open(sys.argv[1]))
    omega = sp.Symbol("Omega")
    t = sp.Symbol("theta")
    checked = bad = 0
    for m in data["models"]:
        num = sp.sympify(m["numerator"])
        den = sp.sympify(m["denominator"])
        for v in m["types"]:
            w = v.get("algebraic")
            if not w:
                continue
            th = theta_of(w)
            subs = {}
            for k, p in w["parameters"].items():
                poly = sp.Poly(sp.sympify(p), t)
                coeffs = [mp.mpf(sp.Rational(c).p) / sp.Rational(c).q for c in poly.all_coeffs()]
                subs[sp.Symbol(k)] = sp.Float(mp.nstr(mp.polyval(coeffs, th), 250), 250)
            n = sp.expand(num.subs(subs))
            d = sp.expand(den.subs(subs))
            got = read_type(roots_of(n, omega), roots_of(d, omega))
            checked += 1
            if got != v["type"]:
                bad += 1
                print(f"{m['id']}: {v['type']} read as {got} at 240 digits")
    print(f"{checked} algebraic witnesses checked at 240 digits, {bad} disagree")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
