#!/usr/bin/env python3
"""Fit benchmark against scipy.optimize.least_squares (issue 5, item 8).

Reads the problems written by

    cargo run --release -p ident --example fit_benchmark -- --export FILE

(random damped 3-mass structures, noise-free 2000-line FRFs, one start per
problem, and the time mms's Levenberg-Marquardt took from that start), fits
each with scipy.optimize.least_squares on the same residual from the same
start, and prints both medians, their ratio, and how often each reached the
data (RMS below 0.05 dB).

The residual is the one mms uses: real and imaginary part of
ln(G(p, f) / H(f)) over the lines, in log-parameters. The model is the
chain's dynamic stiffness Z = C + j w D - w^2 M (tridiagonal), solved for
all lines at once with numpy; scipy gets its default 2-point finite
difference Jacobian (method 'trf'), as a user would call it.

Usage:  scripts/.venv/bin/python scripts/compare_fit.py FILE [--limit N]
"""

import json
import math
import sys
import time

import numpy as np
from scipy.optimize import least_squares


def response(prob, p, w):
    """G(jw) of the chain for parameters p (masses, springs, dampers)."""
    n, gap = prob["n"], prob["gap"]
    links = [i for i in range(n) if i != gap]  # link i joins node i, i+1
    m = p[:n]
    c = p[n:n + len(links)]
    d = p[n + len(links):]
    z = np.zeros((len(w), n, n), dtype=complex)
    for i in range(n):
        z[:, i, i] -= w * w * m[i]
    for k, i in enumerate(links):
        y = c[k] + 1j * w * d[k]
        a, b = i, i + 1  # nodes, 0 = ground
        z[:, b - 1, b - 1] += y
        if a > 0:
            z[:, a - 1, a - 1] += y
            z[:, a - 1, b - 1] -= y
            z[:, b - 1, a - 1] -= y

    def port(pp):
        v = np.zeros(n)
        v[pp[0] - 1] += 1.0
        if pp[1] > 0:
            v[pp[1] - 1] -= 1.0
        return v

    bvec = port(prob["actuator"])
    cvec = port(prob["sensor"])
    x = np.linalg.solve(z, np.broadcast_to(bvec, (len(w), n))[..., None])[..., 0]
    y = x @ cvec
    k = {"position": 0, "velocity": 1, "acceleration": 2}[prob["output"]]
    return y * (1j * w) ** k


def main():
    path = sys.argv[1]
    limit = None
    if "--limit" in sys.argv:
        limit = int(sys.argv[sys.argv.index("--limit") + 1])
    probs = json.load(open(path))
    if limit:
        probs = probs[:limit]
    ours, theirs, ok_ours, ok_theirs = [], [], 0, 0
    for prob in probs:
        f = np.array(prob["freq_hz"])
        w = 2 * math.pi * f
        h = np.array(prob["re"]) + 1j * np.array(prob["im"])
        x0 = np.log(np.array(prob["start"]))

        def res(x):
            e = np.log(response(prob, np.exp(x), w) / h)
            return np.concatenate([e.real, e.imag])

        t = time.perf_counter()
        sol = least_squares(res, x0, method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12)
        theirs.append(time.perf_counter() - t)
        e = res(sol.x)
        rms_db = math.sqrt(np.mean(e[: len(f)] ** 2)) * 20 / math.log(10)
        ok_theirs += rms_db < 0.05
        ours.append(prob["mms_seconds"])
        ok_ours += prob["mms_rms_db"] < 0.05
    mo, mt = np.median(ours), np.median(theirs)
    print(f"problems: {len(probs)}")
    print(f"mms  Levenberg-Marquardt: median {mo * 1e3:.1f} ms, reached the data in {ok_ours}/{len(probs)}")
    print(f"scipy least_squares (trf, 2-point Jacobian): median {mt * 1e3:.1f} ms, "
          f"reached the data in {ok_theirs}/{len(probs)}")
    print(f"ratio of medians scipy/mms: {mt / mo:.1f}")


if __name__ == "__main__":
    main()
