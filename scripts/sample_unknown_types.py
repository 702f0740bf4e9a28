#!/usr/bin/env python3
"""Evidence for the generic types `mms analyze` leaves unknown: how often
each shows up at many random parameter points.

A generic type (simple antiresonances and resonances, every pole kept) is
possible exactly when it fills an open set of the orthant, so a witness
search that misses it either faces an impossible type or a thin region.
This script draws log-uniform points (numpy), finds the roots of the
numerator and denominator in Omega at all of them at once (eigenvalues of
companion matrices), reads each point's type (A for a positive real zero,
R for a positive pole, in increasing order, "(nm)" when a zero is off the
positive axis) and reports, per model, how many points showed each unknown
generic type. Points with two roots closer than a relative 1e-6 are
skipped (f64 cannot order them). It also reports any type the file
certifies impossible (which would be a bug in the prover and the checker).

The counts are evidence, not proof: a type seen here is possible (round
the point and classify it exactly with mms to get a witness); a type never
seen in 10^6 points fills less than about 1e-6 of the sampled box, if any.

Usage: scripts/sample_unknown_types.py FILE.json [--samples 1000000]
       [--log-range 6] [--seed 11] [--batch 200000]
Exit status 1 if any certified type is seen. Set up with scripts/setup-venv.sh.
"""

import argparse
import json
import sys

import numpy as np
import sympy as sp


def roots_batched(c):
    """Roots of the polynomials with coefficient rows `c` (highest first),
    as an (n, degree) complex array (companion matrices' eigenvalues)."""
    n, k = c.shape
    d = k - 1
    if d == 0:
        return np.zeros((n, 0), complex)
    comp = np.zeros((n, d, d))
    comp[:, 0, :] = -c[:, 1:] / c[:, :1]
    comp[:, np.arange(1, d), np.arange(0, d - 1)] = 1.0
    return np.linalg.eigvals(comp)


def types_at(zn, zd):
    """The type string at every row, or None where roots are too close."""
    out = []
    for a, b in zip(zn, zd):
        real = sorted(z.real for z in list(a) + list(b) if abs(z.imag) <= 1e-7 * (1 + abs(z)))
        if any(y - x <= 1e-6 * (abs(x) + abs(y) + 1e-300) for x, y in zip(real, real[1:])):
            out.append(None)
            continue
        on_axis = [abs(z.imag) <= 1e-9 * (1 + abs(z)) and z.real > 0 for z in a]
        tokens = [(z.real, "A") for z, ok in zip(a, on_axis) if ok]
        tokens += [(z.real, "R") for z in b if z.real > 0 and abs(z.imag) <= 1e-9 * (1 + abs(z))]
        out.append("".join(c for _, c in sorted(tokens)) + ("" if all(on_axis) else " (nm)"))
    return out


def generic(t, poles):
    return "^" not in t and "(nm)" not in t and t.count("R") == poles


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--log-range", type=float, default=6.0)
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--batch", type=int, default=200_000)
    args = ap.parse_args()
    data = json.load(open(args.file))
    rng = np.random.default_rng(args.seed)
    omega = sp.Symbol("Omega")
    certified_seen = 0
    for m in data["models"]:
        den = sp.sympify(m["denominator"])
        poles = sp.degree(den, omega)
        unknown = sorted(
            t["type"]
            for t in m["types"]
            if t["status"] == "unknown" and generic(t["type"], poles)
        )
        if not unknown:
            continue
        certified = {t["type"] for t in m["types"] if t["status"] == "impossible"}
        num = sp.sympify(m["numerator"])
        params = sorted((num.free_symbols | den.free_symbols) - {omega}, key=str)
        coeffs = [
            [sp.lambdify(params, c, "numpy") for c in sp.Poly(p, omega).all_coeffs()]
            for p in (num, den)
        ]
        counts = {t: 0 for t in unknown}
        first = {}
        bad, skipped, done = {}, 0, 0
        while done < args.samples:
            n = min(args.batch, args.samples - done)
            x = np.exp(rng.uniform(-args.log_range, args.log_range, size=(n, len(params))))
            cols = [x[:, i] for i in range(len(params))]
            cn, cd = (np.array([np.broadcast_to(f(*cols), (n,)) for f in fs]).T for fs in coeffs)
            for i, t in enumerate(types_at(roots_batched(cn), roots_batched(cd))):
                if t is None:
                    skipped += 1
                elif t in counts:
                    counts[t] += 1
                    first.setdefault(t, {str(p): float(v) for p, v in zip(params, x[i])})
                elif t in certified:
                    bad[t] = bad.get(t, 0) + 1
            done += n
        certified_seen += len(bad)
        seen = ", ".join(f"{t}: {k}" for t, k in counts.items())
        print(f"{m['id']}: {args.samples} points in [e^-{args.log_range:g}, e^{args.log_range:g}], "
              f"{skipped} skipped; unknown generic types seen: {seen}; "
              f"certified types seen: {bad or 'none'}", flush=True)
        for t, point in first.items():
            print(f"  {t} at {json.dumps(point)}", flush=True)
    print(f"certified types seen: {certified_seen}")
    return 1 if certified_seen else 0


if __name__ == "__main__":
    sys.exit(main())
