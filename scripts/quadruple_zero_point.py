"""An exact quadruple zero of N5-g1-a2.1-s4.1 by a second route (sympy).

The numerator is linear in (c1, m1, m2) jointly but in no four parameters,
so num(z) = num'(z) = num''(z) = num'''(z) = 0 is solved for (c1, m1, m2)
from the first three, and the fourth, cleared of denominators, for c23
(the search one parameter short of a linear set, crates/mms/src/analysis/
targeted.rs, does it through the determinant of the linear system
instead). The other parameters are short rationals near a witness of
AAAARRRR. Prints the point and the numerator factored; the unit test
`a_quadruple_zero_one_parameter_short_of_a_linear_set` compares with it.

Usage: scripts/.venv/bin/python scripts/quadruple_zero_point.py
"""
import sympy as sp

c1, c23, c34, c45, m1, m2, m3, m4, m5, W = sp.symbols("c1 c23 c34 c45 m1 m2 m3 m4 m5 Omega")
# The numerator of `mms derive N5-g1-a2.1-s4.1`.
N = (
    m2 * m3 * m4 * m5 * W**4
    - (c23 * m2 * m4 * m5 + c23 * m3 * m4 * m5 + c34 * m2 * m3 * m5 + c34 * m2 * m4 * m5
       + c45 * m2 * m3 * m4 + c45 * m2 * m3 * m5) * W**3
    + (c23 * c34 * m1 * m5 + c23 * c34 * m2 * m5 + c23 * c34 * m3 * m5 + c23 * c34 * m4 * m5
       + c23 * c45 * m2 * m4 + c23 * c45 * m2 * m5 + c23 * c45 * m3 * m4 + c23 * c45 * m3 * m5
       + c34 * c45 * m2 * m3 + c34 * c45 * m2 * m4 + c34 * c45 * m2 * m5) * W**2
    - (c1 * c23 * c34 * m5 + c23 * c34 * c45 * (m1 + m2 + m3 + m4 + m5)) * W
    + c1 * c23 * c34 * c45
)
R = sp.Rational
fixed = {c34: R(247281, 25000), c45: R(29163, 200000), m3: R(169783, 10000),
         m4: R(470593, 5000), m5: R(128607, 500000)}
z = R(1, 2)
E = [sp.diff(N, W, j).subs(W, z).subs(fixed) for j in range(4)]
sol = sp.solve(E[:3], (c1, m1, m2), dict=True)[0]
last = sp.numer(sp.together(E[3].subs(sol)))
# Cleared, the fourth condition is c23 times a factor of degree one in c23.
roots = [r for r in sp.solve(last, c23) if r > 0]
for r in roots:
    point = dict(fixed)
    point[c23] = r
    point.update({k: v.subs(c23, r) for k, v in sol.items()})
    print({str(k): str(v) for k, v in sorted(point.items(), key=lambda kv: str(kv[0]))})
    print("positive:", all(v > 0 for v in point.values()))
    print(sp.factor(N.subs(point)))
