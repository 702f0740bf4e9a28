#!/usr/bin/env python3
"""Numeric cross-check of `mms analyze` certificates: no certified-impossible
FRF type may show up at random parameters.

A second route, independent of mms's exact arithmetic: for every model in a
file written by `mms analyze --format json`, draw log-uniform parameter points
(numpy), find the roots of the numerator and denominator in Omega with
numpy.roots, read the type (A for a positive real zero, R for a positive pole,
in increasing order; "(nm)" when some zero is not positive real) and report
every point whose type the file certifies impossible. Points with two roots
closer than a relative 1e-6 are skipped (f64 cannot tell their order), so
measure-zero types (cancellations, multiple zeros) are not probed; the
generic ones are.

Usage: scripts/cross_check_certificates.py FILE.json [--samples 3000]
       [--kind block_pole_signs] [--seed 7]
Exit status 1 if any certified type is seen. Set up with scripts/setup-venv.sh.
"""

import argparse
import json
import sys

import numpy as np
import sympy as sp


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--samples", type=int, default=3000)
    ap.add_argument("--kind", help="only certificates of this kind (e.g. block_pole_signs)")
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    data = json.load(open(args.file))
    rng = np.random.default_rng(args.seed)
    omega = sp.Symbol("Omega")
    hits = 0
    for m in data["models"]:
        certified = {
            t["type"]
            for t in m["types"]
            if t["status"] == "impossible"
            and (args.kind is None or t["certificate"]["open"].get("kind") == args.kind)
        }
        if not certified:
            continue
        num = sp.sympify(m["numerator"])
        den = sp.sympify(m["denominator"])
        params = sorted((num.free_symbols | den.free_symbols) - {omega}, key=str)
        coeffs = [
            [sp.lambdify(params, c, "numpy") for c in sp.Poly(p, omega).all_coeffs()]
            for p in (num, den)
        ]
        x = np.exp(rng.uniform(-3, 3, size=(args.samples, len(params))))
        cols = [x[:, i] for i in range(len(params))]
        cn, cd = (
            np.array([np.broadcast_to(f(*cols), (args.samples,)) for f in fs]).T for fs in coeffs
        )
        seen, skipped = {}, 0
        for k in range(args.samples):
            zn, zd = np.roots(cn[k]), np.roots(cd[k])
            real = sorted(z.real for z in list(zn) + list(zd) if abs(z.imag) <= 1e-7 * (1 + abs(z)))
            if any(b - a <= 1e-6 * (abs(a) + abs(b) + 1e-300) for a, b in zip(real, real[1:])):
                skipped += 1
                continue
            on_axis = [abs(z.imag) <= 1e-9 * (1 + abs(z)) and z.real > 0 for z in zn]
            tokens = [(z.real, "A") for z, ok in zip(zn, on_axis) if ok]
            tokens += [(z.real, "R") for z in zd if z.real > 0]
            t = "".join(c for _, c in sorted(tokens)) + ("" if all(on_axis) else " (nm)")
            seen[t] = seen.get(t, 0) + 1
        bad = {t: n for t, n in seen.items() if t in certified}
        hits += len(bad)
        print(f"{m['id']}: {len(certified)} certified, {len(seen)} types seen, "
              f"{skipped} points skipped, certified types seen: {bad or 'none'}", flush=True)
    print(f"certified types seen: {hits}")
    return 1 if hits else 0


if __name__ == "__main__":
    sys.exit(main())
