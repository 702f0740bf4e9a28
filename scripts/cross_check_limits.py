#!/usr/bin/env python3
"""Cross-checks the rule "limits of generic types" on an analysis table.

A third route, apart from the prover's recursion and the checker's forward
enumeration (docs/analysis.md, "Limits of generic types"): a type T shows
only where a generic type (simple tokens, every pole) gathers into it, so

1. no type with a witness may have only impossible generic types gathering
   into it (the rule would contradict an exact witness);
2. every `limits` certificate must list exactly the generic types that
   gather into its type, all impossible;
3. the unknown types the rule would still settle are listed (none, once the
   table was made with the rule).

Usage: scripts/cross_check_limits.py TABLE.json   (exit 1 on a violation)
"""
import functools
import json
import re
import sys


def parse(s):
    nm = s.endswith(" (nm)")
    body = s[:-5] if nm else s
    toks = [] if body == "C" else [
        (m.group(1), int(m.group(2) or 1))
        for m in re.finditer(r"([AR])(?:\^(\d+))?", body)
    ]
    return toks, nm


def gathers(g, t, a, r):
    """Whether generic g gathers into t: g's tokens in consecutive runs,
    off-axis pairs landed on runs or alone, each run read A^(z-p), R^(p-z)
    or nothing; written as a recursion over both strings."""
    gt, _ = g
    tt, tnm = t
    r_t = sum(m for f, m in tt if f == "R")
    if r_t > r:
        return False
    c = r - r_t
    off_t = a - c - sum(m for f, m in tt if f == "A")
    if off_t < 0 or tnm != (off_t > 0):
        return False
    off_g = a - sum(1 for f, _ in gt if f == "A")
    if off_g < off_t or (off_g - off_t) % 2:
        return False
    pairs = (off_g - off_t) // 2

    @functools.lru_cache(None)
    def go(i, k, used):
        if i == len(gt) and k == len(tt):
            return used == pairs
        if k < len(tt) and tt[k][0] == "A" and tt[k][1] % 2 == 0:
            e = tt[k][1] // 2
            if used + e <= pairs and go(i, k + 1, used + e):
                return True
        z = p = 0
        for j in range(i, len(gt)):
            if gt[j][0] == "A":
                z += 1
            else:
                p += 1
            for e in range(pairs - used + 1):
                zz = z + 2 * e
                if zz == p:
                    if go(j + 1, k, used + e):
                        return True
                elif k < len(tt):
                    want = ("A", zz - p) if zz > p else ("R", p - zz)
                    if tt[k] == want and go(j + 1, k + 1, used + e):
                        return True
        return False

    return go(0, 0, 0)


def main(path):
    table = json.load(open(path))
    bad = 0
    would = []
    certified = 0
    for m in table["models"]:
        types = {v["type"]: v for v in m["types"]}
        parsed = {s: parse(s) for s in types}
        r = max(sum(k for f, k in parsed[s][0] if f == "R") for s in types)
        a = max(sum(k for f, k in parsed[s][0] if f == "A") for s in types)
        generic = [s for s in types
                   if all(k == 1 for _, k in parsed[s][0])
                   and sum(1 for f, _ in parsed[s][0] if f == "R") == r]
        for s, v in types.items():
            if s in generic:
                continue
            pre = sorted(g for g in generic
                         if gathers(parsed[g], parsed[s], a, r))
            all_impossible = all(types[g]["status"] == "impossible" for g in pre)
            cert = v.get("certificate") or {}
            if cert.get("open", {}).get("kind") == "limits":
                certified += 1
                listed = sorted(cert["open"]["generic"])
                if listed != pre or not all_impossible:
                    bad += 1
                    print(f"{m['id']} {s}: listed {listed}, gathering {pre}")
            elif v["status"] == "possible" and all_impossible:
                bad += 1
                print(f"{m['id']} {s}: a witness, but every generic type "
                      f"gathering into it is impossible: {pre}")
            elif v["status"] == "unknown" and all_impossible:
                would.append(f"{m['id']} {s}")
    print(f"{certified} limits certificates agree; "
          f"{len(would)} unknown types the rule would settle; {bad} violations")
    for w in would:
        print("  would settle", w)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
