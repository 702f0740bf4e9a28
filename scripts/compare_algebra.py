#!/usr/bin/env python3
"""Time the `mms algebra` pipeline against python-flint and SymPy, and check
that the factor lists agree.

For every model class of N masses the pipeline is: Num, Den (taken from
`mms derive --format json`), Res_Omega(Num, Den), Disc_Omega(Num),
Disc_Omega(Den), and the factorization of each of the five into irreducibles
over Q. `mms algebra --format json` reports its own in-process time for the
same work; python-flint (fmpz_mpoly) and SymPy are timed here in-process, so
process start-up is excluded on both sides.

Usage: scripts/compare_algebra.py [--masses 3 4 5] [--mms target/release/mms]
       [--no-sympy] [--sympy-max-masses 4] [--json OUT]
Set up once with scripts/setup-venv.sh (python-flint, sympy).
"""

import argparse
import json
import re
import subprocess
import sys
import time

import flint
import sympy


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def as_flint(ctx, names, text):
    gens = dict(zip(names, ctx.gens()))
    env = {"__builtins__": {}}
    if "(" in text:
        return eval(text.replace("^", "**"), env, gens)
    # An expanded sum (the form mms prints): term by term, since one eval of
    # tens of thousands of terms exceeds Python's recursion limit.
    parts = re.split(r" ([+-]) ", text.replace("^", "**"))
    terms = [eval(parts[0], env, gens)]
    for sign, term in zip(parts[1::2], parts[2::2]):
        t = eval(term, env, gens)
        terms.append(t if sign == "+" else -t)
    while len(terms) > 1:  # pairwise sums: linear merges of balanced sizes
        terms = [sum(terms[i:i + 2][1:], terms[i]) for i in range(0, len(terms), 2)]
    return terms[0]


def flint_pipeline(num, den, var, idx):
    res = num.resultant(den, var)
    dn = num.discriminant(var) if num.degrees()[idx] >= 1 else None
    dd = den.discriminant(var) if den.degrees()[idx] >= 1 else None
    polys = {"num": num, "den": den, "res": res, "disc_num": dn, "disc_den": dd}
    facs = {}
    for k, p in polys.items():
        if p is None or p == 0:
            facs[k] = None
            continue
        facs[k] = p.factor()
    return facs


def sympy_pipeline(num, den, var):
    res = sympy.resultant(num, den, var)
    dn = sympy.discriminant(num, var) if sympy.degree(num, var) >= 1 else None
    dd = sympy.discriminant(den, var) if sympy.degree(den, var) >= 1 else None
    out = {}
    for k, p in {"num": num, "den": den, "res": res, "disc_num": dn, "disc_den": dd}.items():
        out[k] = None if p is None or p == 0 else sympy.factor_list(p)
    return out


def nonconstant(factors):
    """Set of non-constant factors, each normalised up to sign, with multiplicities."""
    out = set()
    for f, m in factors:
        if f.total_degree() == 0:
            continue
        g = -f if str(f).startswith("-") else f
        out.add((str(g), m))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--masses", type=int, nargs="+", default=[3, 4, 5])
    ap.add_argument("--mms", default="target/release/mms")
    ap.add_argument("--no-sympy", action="store_true")
    ap.add_argument("--sympy-max-masses", type=int, default=4)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json")
    args = ap.parse_args()

    report = []
    print(f"{'N':>2} {'models':>6} {'mms [s]':>10} {'flint [s]':>10} {'sympy [s]':>10} "
          f"{'mms/flint':>9} factors")
    for n in args.masses:
        derived = run_json([args.mms, "derive", "--masses", str(n), "--format", "json"])
        ours_runs = [run_json([args.mms, "algebra", "--masses", str(n), "--format", "json"])
                     for _ in range(args.repeat)]
        ours = min(ours_runs, key=lambda r: r["total_seconds"])
        t_ours = ours["total_seconds"]

        names = set()
        for m in derived["models"]:
            for key in ("numerator", "denominator"):
                for tok in m[key].replace("(", " ").replace(")", " ").replace("*", " ") \
                        .replace("^", " ").replace("+", " ").replace("-", " ").split():
                    if tok[0].isalpha():
                        names.add(tok)
        names = sorted(names)
        ctx = flint.fmpz_mpoly_ctx.get(tuple(names), "lex")
        omega = names.index("Omega")

        # python-flint, best of --repeat
        t_flint = float("inf")
        flint_facs = None
        # parsing the text is not part of the timed pipeline (as for mms)
        pairs = [(as_flint(ctx, names, m["numerator"]), as_flint(ctx, names, m["denominator"]))
                 for m in derived["models"]]
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            facs = []
            for num, den in pairs:
                facs.append(flint_pipeline(num, den, "Omega", omega))
            t_flint = min(t_flint, time.perf_counter() - t0)
            flint_facs = facs

        # agreement of factor lists (up to sign and constants)
        mismatches = []
        for m, ff, mine in zip(derived["models"], flint_facs, ours["models"]):
            for entry in mine["polys"]:
                k = entry["name"]
                theirs = ff.get(k)
                if theirs is None:
                    if entry["factors"]:
                        mismatches.append((m["id"], k, "flint has none"))
                    continue
                a = nonconstant([(as_flint(ctx, names, f["factor"]), f["multiplicity"])
                                 for f in entry["factors"]])
                b = nonconstant(theirs[1])
                if a != b:
                    mismatches.append((m["id"], k, f"mms {sorted(a)} flint {sorted(b)}"))

        t_sympy = None
        if not args.no_sympy and n <= args.sympy_max_masses:
            syms = sympy.symbols(names)
            env = dict(zip(names, syms))
            pairs = [(sympy.sympify(m["numerator"].replace("^", "**"), locals=env),
                      sympy.sympify(m["denominator"].replace("^", "**"), locals=env))
                     for m in derived["models"]]
            t0 = time.perf_counter()
            for num, den in pairs:
                sympy_pipeline(num, den, env["Omega"])
            t_sympy = time.perf_counter() - t0

        ratio = t_ours / t_flint if t_flint > 0 else float("nan")
        status = "agree" if not mismatches else f"{len(mismatches)} DIFFER"
        sp = f"{t_sympy:10.4f}" if t_sympy is not None else f"{'-':>10}"
        print(f"{n:>2} {len(derived['models']):>6} {t_ours:10.4f} {t_flint:10.4f} {sp} "
              f"{ratio:9.2f} {status}")
        for mm in mismatches[:10]:
            print("   ", mm, file=sys.stderr)
        report.append({"masses": n, "models": len(derived["models"]), "mms_seconds": t_ours,
                       "flint_seconds": t_flint, "sympy_seconds": t_sympy,
                       "mms_over_flint": ratio, "mismatches": len(mismatches)})

    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=2)
    if any(r["mismatches"] for r in report):
        sys.exit(1)


if __name__ == "__main__":
    main()
