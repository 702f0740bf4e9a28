#!/usr/bin/env python3
"""Evidence for the non-generic types `mms analyze` leaves unknown: random
points on each type's own region, not in the open orthant.

A type with cancelled poles or a multiple antiresonance lives on a
variety: a cancelled pole at rho needs N(rho) = D(rho) = 0, an A^mu at
sigma needs N and its first mu - 1 derivatives to vanish at sigma.
Log-uniform sampling of the parameters never lands there (the sampling
of scripts/sample_unknown_types.py sees only generic types). So this
script samples the variety itself. The unknowns are the log parameters,
the log of every cancelled pole and of every multiple zero; the
equations are those root conditions, each divided by the sum of the
absolute values of its terms (so 1e-13 means "zero in f64"). From a
log-uniform start (the poles and zeros started at roots of the start's
denominator and numerator) a min-norm Gauss-Newton step
dx = -J^T (J J^T)^-1 F (forward-difference Jacobian) projects onto the
variety; a point counts when it converges and stays within the box
widened by 2 in every log coordinate.

At a converged point the type is read without the ill-conditioned
multiple roots: the known cancelled poles and multiple zeros are divided
out of numerator and denominator (synthetic division), the rest's roots
are companion eigenvalues, and the point is skipped when any two of all
the positive roots (rest, cancelled, multiple) lie within a relative
1e-6 (a point of a still thinner stratum, or one f64 cannot order). The
type is then the ordered tokens (the multiple zero as A^mu, the rest's
positive zeros as A, its positive poles as R) and "(nm)" when a zero is
left off the positive axis (a zero at Omega = 0 included), as
`mms check` defines it.

Per model and per structure (number of cancelled poles, multiplicities
of the multiple zeros) it reports the points, how many were skipped, the
count of each unknown type of that structure seen (with the first point)
and any type the table certifies impossible (which would be a bug in the
prover and the checker: exit status 1).

The counts are evidence, not proof. A type seen is possible (the point is
not rational, so it is not a witness); a type never seen in many
converged points is either impossible or thin within its variety.

Usage: scripts/sample_unknown_cells.py FILE.json [--models ID,ID]
       [--samples 100000] [--log-range 6] [--seed 11] [--batch 20000]
Set up with scripts/setup-venv.sh.
"""

import argparse
import json
import re
import sys
from collections import Counter, defaultdict

import mpmath as mp
import numpy as np
import sympy as sp

TOKEN = re.compile(r"([AR])(?:\^(\d+))?")


def parse_type(t):
    """(tokens [(kind, mult)], nm) of a type string."""
    nm = t.endswith(" (nm)")
    body = t[: -len(" (nm)")] if nm else t
    if body == "C":
        return [], nm
    toks = [(k, int(m or 1)) for k, m in TOKEN.findall(body)]
    assert "".join(k + (f"^{m}" if m > 1 else "") for k, m in toks) == body, t
    return toks, nm


def type_string(toks, nm):
    body = "".join(k + (f"^{m}" if m > 1 else "") for k, m in toks) or "C"
    return body + (" (nm)" if nm else "")


def horner(c, x):
    """Values of the polynomials with coefficient columns `c` (list, highest
    first, each an array over the batch) at `x` (array over the batch)."""
    v = np.zeros_like(x)
    for a in c:
        v = v * x + a
    return v


def derivative(c):
    d = len(c) - 1
    return [a * (d - i) for i, a in enumerate(c[:-1])]


def deflate(c, r):
    """Quotient of the coefficient columns `c` (highest first) by (x - r),
    remainder dropped. Composite deflation: the quotient's high part by
    forward recurrence, its low part by backward, split at the dominant
    term |c_i r^i|, so a large root does not swamp the small ones."""
    b = np.array(c[::-1])  # lowest first, (d + 1, n)
    d = b.shape[0] - 1
    fwd = np.zeros((d, b.shape[1]))
    bwd = np.zeros((d, b.shape[1]))
    fwd[d - 1] = b[d]
    for i in range(d - 1, 0, -1):
        fwd[i - 1] = b[i] + r * fwd[i]
    bwd[0] = -b[0] / r
    for i in range(1, d):
        bwd[i] = (bwd[i - 1] - b[i]) / r
    with np.errstate(divide="ignore", over="ignore"):
        size = np.abs(b) * np.abs(r)[None, :] ** np.arange(d + 1)[:, None]
    k = np.argmax(size, axis=0)
    q = np.where(np.arange(d)[:, None] >= k[None, :], fwd, bwd)
    return list(q[::-1])


def roots_rows(c):
    """Roots (n, degree) of the coefficient columns `c`."""
    d = len(c) - 1
    n = c[0].shape[0]
    if d <= 0:
        return np.zeros((n, 0), complex)
    comp = np.zeros((n, d, d))
    for j in range(d):
        comp[:, 0, j] = -c[j + 1] / c[0]
    comp[:, np.arange(1, d), np.arange(0, d - 1)] = 1.0
    return np.linalg.eigvals(comp)


def positive(z):
    return (np.abs(z.imag) <= 1e-9 * (1 + np.abs(z))) & (z.real > 0)


class Model:
    def __init__(self, m):
        omega = sp.Symbol("Omega")
        num = sp.Poly(sp.sympify(m["numerator"]), omega)
        den = sp.Poly(sp.sympify(m["denominator"]), omega)
        self.params = sorted(
            (num.free_symbols | den.free_symbols) - {omega}, key=str
        )

        def valuation(p):
            cs = p.all_coeffs()[::-1]
            return next(i for i, c in enumerate(cs) if c != 0)

        common = min(valuation(num), valuation(den))
        # Zeros at Omega = 0 left after the common factor are off the
        # positive axis; poles there are not resonances.
        self.zero_at_0 = valuation(num) - common
        nc = num.all_coeffs()[: len(num.all_coeffs()) - valuation(num)]
        dc = den.all_coeffs()[: len(den.all_coeffs()) - valuation(den)]
        self.fn = [sp.lambdify(self.params, c, "numpy") for c in nc]
        self.fd = [sp.lambdify(self.params, c, "numpy") for c in dc]
        self.num_coeffs, self.den_coeffs = nc, dc
        self.deg_n = len(nc) - 1
        self.poles = len(dc) - 1

    def coeffs(self, theta):
        x = np.exp(theta)
        cols = [x[:, i] for i in range(x.shape[1])]
        n = theta.shape[0]
        cn = [np.broadcast_to(f(*cols), (n,)).astype(float) for f in self.fn]
        cd = [np.broadcast_to(f(*cols), (n,)).astype(float) for f in self.fd]
        return cn, cd


def residual(model, c, mults, x):
    """Normalised root conditions at the batch of unknown vectors x."""
    k = len(model.params)
    cn, cd = model.coeffs(x[:, :k])
    an = [np.abs(a) for a in cn]
    ad = [np.abs(a) for a in cd]
    out = []
    for i in range(c):
        r = np.exp(x[:, k + i])
        out.append(horner(cn, r) / horner(an, r))
        out.append(horner(cd, r) / horner(ad, r))
    for j, mu in enumerate(mults):
        s = np.exp(x[:, k + c + j])
        p, a = cn, an
        for _ in range(mu):
            out.append(horner(p, s) / horner(a, s))
            p, a = derivative(p), derivative(a)
    return np.stack(out, axis=1)


def project(model, c, mults, x, iters=40, tol=1e-13):
    """Min-norm Gauss-Newton onto the variety; returns (x, converged)."""
    h = 1e-7
    for _ in range(iters):
        f = residual(model, c, mults, x)
        done = np.max(np.abs(f), axis=1) < tol
        if done.all():
            break
        jac = np.empty((x.shape[0], f.shape[1], x.shape[1]))
        for i in range(x.shape[1]):
            xp = x.copy()
            xp[:, i] += h
            jac[:, :, i] = (residual(model, c, mults, xp) - f) / h
        jjt = jac @ np.transpose(jac, (0, 2, 1))
        jjt += 1e-14 * np.eye(f.shape[1])[None] * np.trace(jjt, axis1=1, axis2=2)[:, None, None]
        try:
            y = np.linalg.solve(jjt, f[:, :, None])
        except np.linalg.LinAlgError:
            y = np.linalg.lstsq(jjt[0], f[0], rcond=None)[0][None, :, None]
        step = (np.transpose(jac, (0, 2, 1)) @ y)[:, :, 0]
        # A long step leaves the basin; cap it at 1 in log units.
        norm = np.maximum(1.0, np.max(np.abs(step), axis=1))[:, None]
        step = np.where(np.isfinite(step), step / norm, 0.0)
        x = np.where(done[:, None], x, x - step)
    f = residual(model, c, mults, x)
    ok = np.all(np.isfinite(f), axis=1) & (np.max(np.abs(f), axis=1) < tol * 10)
    return x, ok


def classify(model, c, mults, x):
    """The type at each converged row, or None (skipped)."""
    k = len(model.params)
    cn, cd = model.coeffs(x[:, :k])
    rho = [np.exp(x[:, k + i]) for i in range(c)]
    sig = [np.exp(x[:, k + c + j]) for j in range(len(mults))]
    for r in rho:
        cn, cd = deflate(cn, r), deflate(cd, r)
    for s, mu in zip(sig, mults):
        for _ in range(mu):
            cn = deflate(cn, s)
    zn, zd = roots_rows(cn), roots_rows(cd)
    out = []
    for i in range(x.shape[0]):
        pz, pd = positive(zn[i]), positive(zd[i])
        marks = [(z.real, "A", 1) for z in zn[i][pz]]
        marks += [(z.real, "R", 1) for z in zd[i][pd]]
        marks += [(s[i], "A", mu) for s, mu in zip(sig, mults)]
        every = sorted(marks + [(r[i], "C", 1) for r in rho])
        vals = [v for v, _, _ in every]
        if any(b - a <= 1e-6 * (abs(a) + abs(b)) for a, b in zip(vals, vals[1:])):
            out.append(None)
            continue
        toks = [(kind, mu) for _, kind, mu in sorted(marks)]
        nm = model.zero_at_0 > 0 or not pz.all()
        out.append(type_string(toks, nm))
    return out


def verify(model, c, mults, x):
    """The type at the unknown vector `x` read again at 50 digits: roots of
    the numerator and denominator by mpmath, a cancelled pole's pair of
    roots removed, the mu numerator roots nearest each multiple zero taken
    as it; None when the 50-digit roots do not bear the reading out."""
    mp.mp.dps = 50
    k = len(model.params)
    point = {p: sp.Float(mp.e ** mp.mpf(float(v)), 50) for p, v in zip(model.params, x[:k])}

    def roots(cs):
        vals = [mp.mpf(str(sp.Float(sp.sympify(a).subs(point), 50))) for a in cs]
        return list(mp.polyroots(vals, maxsteps=400, extraprec=400))

    zn, zd = roots(model.num_coeffs), roots(model.den_coeffs)
    for i in range(c):
        r = mp.e ** mp.mpf(float(x[k + i]))
        a = min(range(len(zn)), key=lambda j: abs(zn[j] - r))
        b = min(range(len(zd)), key=lambda j: abs(zd[j] - r))
        if abs(zn[a] - r) > 1e-8 * r or abs(zd[b] - r) > 1e-8 * r:
            return None
        zn.pop(a)
        zd.pop(b)
    marks = []
    for j, mu in enumerate(mults):
        s = mp.e ** mp.mpf(float(x[k + c + j]))
        for _ in range(mu):
            a = min(range(len(zn)), key=lambda i: abs(zn[i] - s))
            if abs(zn[a] - s) > 1e-2 * s:
                return None
            zn.pop(a)
        marks.append((s, "A", mu))
    real = lambda z: abs(mp.im(z)) <= 1e-20 * (1 + abs(z)) and mp.re(z) > 0
    marks += [(mp.re(z), "A", 1) for z in zn if real(z)]
    marks += [(mp.re(z), "R", 1) for z in zd if real(z)]
    vals = sorted(v for v, _, _ in marks)
    if any(b - a <= 1e-6 * (a + b) for a, b in zip(vals, vals[1:])):
        return None
    nm = model.zero_at_0 > 0 or any(not real(z) for z in zn)
    return type_string([(kind, mu) for _, kind, mu in sorted(marks)], nm)


def structure(model, t):
    """(cancelled poles, multiplicities of the multiple zeros), or None when
    the type cannot fit the degrees (certified structurally)."""
    toks, nm = parse_type(t)
    r = sum(m for kind, m in toks if kind == "R")
    zeros = sum(m for kind, m in toks if kind == "A")
    c = model.poles - r
    free = model.deg_n - c - zeros
    if c < 0 or free < 0 or (not nm and (free > 0 or model.zero_at_0 > 0)):
        return None
    mults = tuple(sorted(m for kind, m in toks if kind == "A" and m > 1))
    return c, mults


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--models", default="")
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--log-range", type=float, default=6.0)
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--batch", type=int, default=20_000)
    args = ap.parse_args()
    wanted = set(filter(None, args.models.split(",")))
    data = json.load(open(args.file))
    rng = np.random.default_rng(args.seed)
    certified_seen = 0
    for m in data["models"]:
        if wanted and m["id"] not in wanted:
            continue
        unknown = [t["type"] for t in m["types"] if t["status"] == "unknown"]
        if not unknown:
            continue
        model = Model(m)
        certified = {t["type"] for t in m["types"] if t["status"] == "impossible"}
        groups = defaultdict(list)
        for t in unknown:
            s = structure(model, t)
            if s is not None and (s[0] > 0 or s[1]):
                groups[s].append(t)
        for (c, mults), types in sorted(groups.items()):
            k = len(model.params)
            seen, first, bad, bad_at = Counter(), {}, Counter(), {}
            tried = converged = skipped = misread = 0
            while converged < args.samples and tried < 20 * args.samples:
                n = args.batch
                theta = rng.uniform(-args.log_range, args.log_range, size=(n, k))
                cn, cd = model.coeffs(theta)
                zd, zn = roots_rows(cd), roots_rows(cn)
                x = np.empty((n, k + c + len(mults)))
                x[:, :k] = theta
                for i in range(n):
                    poles = np.sort(np.abs(zd[i].real))
                    pick = rng.choice(len(poles), size=c, replace=False)
                    x[i, k : k + c] = np.log(poles[pick])
                    zs = np.abs(zn[i][positive(zn[i])].real) if positive(zn[i]).any() else poles
                    x[i, k + c :] = np.log(rng.choice(zs, size=len(mults)))
                tried += n
                x, ok = project(model, c, mults, x)
                box = np.all(np.abs(x[:, :k]) <= args.log_range + 2, axis=1)
                x = x[ok & box]
                converged += x.shape[0]
                for i, t in enumerate(classify(model, c, mults, x)):
                    if t is None:
                        skipped += 1
                    elif t in types:
                        # Counted only when the 50-digit reading bears it out.
                        if verify(model, c, mults, x[i]) != t:
                            misread += 1
                            continue
                        first.setdefault(t, {str(p): float(np.exp(v)) for p, v in zip(model.params, x[i, :k])})
                        seen[t] += 1
                    elif t in certified:
                        # A certified type seen would be a bug: only
                        # when the 50-digit reading bears it out.
                        if verify(model, c, mults, x[i]) == t:
                            bad[t] += 1
                            bad_at.setdefault(t, [float(v) for v in x[i]])
                        else:
                            misread += 1
            certified_seen += len(bad)
            label = f"{c} cancelled" + "".join(f", A^{mu}" for mu in mults)
            shown = ", ".join(f"{t}: {seen[t]}" for t in sorted(types))
            print(f"{m['id']} [{label}]: {tried} starts, {converged} on the variety, "
                  f"{skipped} skipped, {misread} f64 readings not borne out at 50 digits; unknown types: {shown}; "
                  f"certified types seen: {dict(bad) or 'none'}", flush=True)
            for t, point in sorted(first.items()):
                print(f"  {t} at {json.dumps(point)}", flush=True)
            for t, point in sorted(bad_at.items()):
                print(f"  CERTIFIED {t} at log point {json.dumps(point)}", flush=True)
    print(f"certified types seen: {certified_seen}")
    return 1 if certified_seen else 0


if __name__ == "__main__":
    sys.exit(main())
