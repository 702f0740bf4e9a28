//! A small exact linear-programming solver (dictionary simplex over Q with
//! Bland's rule) and its one use: finding a positive combination of sign
//! conditions that contradicts positivity (a Positivstellensatz-style
//! certificate with nonnegative multipliers).

use poly::{Int, Poly, Rat};
use std::collections::HashMap;

/// Maximizes `c.x` subject to `rows.x <= rhs`, `x >= 0`, with `rhs >= 0`
/// (so the origin is feasible). Returns the optimal `x`, or `None` when the
/// problem is unbounded. Exact: every pivot is rational arithmetic.
pub(crate) fn maximize(c: &[Rat], rows: &[Vec<Rat>], rhs: &[Rat]) -> Option<Vec<Rat>> {
    let n = c.len();
    let m = rows.len();
    // Dictionary: basic_i = t[i][0] + sum_j t[i][1 + j] * nonbasic_j.
    // Variables 0..n are the unknowns, n..n+m the slacks.
    let mut t: Vec<Vec<Rat>> = (0..m)
        .map(|i| {
            let mut row = Vec::with_capacity(n + 1);
            row.push(rhs[i].clone());
            row.extend(rows[i].iter().map(|a| -a.clone()));
            row
        })
        .collect();
    let mut z: Vec<Rat> = std::iter::once(Rat::ZERO)
        .chain(c.iter().cloned())
        .collect();
    let mut basic: Vec<usize> = (n..n + m).collect();
    let mut nonbasic: Vec<usize> = (0..n).collect();
    // Bland: entering = smallest variable index with positive reduced cost.
    while let Some(e) = (0..n)
        .filter(|&j| z[1 + j].signum() > 0)
        .min_by_key(|&j| nonbasic[j])
    {
        let mut leave: Option<(usize, Rat)> = None;
        for i in 0..m {
            let a = &t[i][1 + e];
            if a.signum() < 0 {
                let ratio = &t[i][0] / &(-a.clone());
                let better = match &leave {
                    None => true,
                    Some((li, lr)) => ratio < *lr || (ratio == *lr && basic[i] < basic[*li]),
                };
                if better {
                    leave = Some((i, ratio));
                }
            }
        }
        let (l, _) = leave?;
        pivot(&mut t, &mut z, l, e);
        std::mem::swap(&mut basic[l], &mut nonbasic[e]);
    }
    let mut x = vec![Rat::ZERO; n];
    for (i, &b) in basic.iter().enumerate() {
        if b < n {
            x[b] = t[i][0].clone();
        }
    }
    Some(x)
}

fn pivot(t: &mut [Vec<Rat>], z: &mut [Rat], l: usize, e: usize) {
    // Solve row l for the entering variable.
    let a = t[l][1 + e].clone();
    let inv = -a.recip();
    let mut row: Vec<Rat> = t[l].iter().map(|v| v * &inv).collect();
    row[1 + e] = a.recip();
    t[l] = row.clone();
    let substitute = |target: &mut Vec<Rat>| {
        let f = target[1 + e].clone();
        if f.is_zero() {
            return;
        }
        for (k, v) in row.iter().enumerate() {
            if k == 1 + e {
                target[k] = &f * v;
            } else if !v.is_zero() {
                target[k] = &target[k] + &(&f * v);
            }
        }
    };
    for (i, r) in t.iter_mut().enumerate() {
        if i != l {
            substitute(r);
        }
    }
    let mut zz = z.to_vec();
    substitute(&mut zz);
    z.clone_from_slice(&zz);
}

/// All monomials in `vars` of total degree at most `deg`, as polynomials,
/// in a fixed order (degree, then lexicographic).
pub(crate) fn monomials(vars: &[String], deg: u32) -> Vec<Poly> {
    let mut out = vec![Poly::one()];
    let mut frontier = vec![(Poly::one(), 0usize)];
    for _ in 0..deg {
        let mut next = Vec::new();
        for (m, start) in &frontier {
            for (k, v) in vars.iter().enumerate().skip(*start) {
                let p = m * &Poly::var(v);
                out.push(p.clone());
                next.push((p, k));
            }
        }
        frontier = next;
    }
    out
}

/// Largest dense tableau (rows times columns) the sign-condition LP builds.
const MAX_TABLEAU_ENTRIES: usize = 2_000_000;

/// Multipliers `lambda_i` with nonnegative coefficients, at least one of
/// them on a strict condition nonzero, such that `sum lambda_i * g_i` has no
/// positive coefficient. With `g_i > 0` (strict) or `g_i >= 0` required on
/// the positive orthant, that is a contradiction: the left side would be
/// `> 0`, the right side is `<= 0`. Multiplier monomials up to `max_deg` in
/// `vars` are tried, lowest degree first.
#[cfg(test)]
pub(crate) fn positive_combination(
    conditions: &[(Poly, bool)],
    vars: &[String],
    max_deg: u32,
) -> Option<Vec<Poly>> {
    positive_combination_in(conditions, vars, 0..=max_deg)
}

/// [`positive_combination`] with the multiplier degrees `degrees` only.
pub(crate) fn positive_combination_in(
    conditions: &[(Poly, bool)],
    vars: &[String],
    degrees: std::ops::RangeInclusive<u32>,
) -> Option<Vec<Poly>> {
    // Every variable, the multipliers' first: the rows' exponent vectors.
    let mut names: Vec<String> = vars.to_vec();
    for (g, _) in conditions {
        for v in g.vars() {
            if !names.contains(v) {
                names.push(v.clone());
            }
        }
    }
    for deg in degrees {
        let basis = monomials(vars, deg);
        // Column (i, mu): the polynomial mu * g_i. One row per monomial of
        // the products: its coefficient <= 0. A monomial times `g_i` has the
        // terms of `g_i` shifted, with the same coefficients, so the rows
        // come from the supports without multiplying.
        let cols: Vec<(usize, &Poly)> = (0..conditions.len())
            .flat_map(|i| basis.iter().map(move |mu| (i, mu)))
            .collect();
        let n = cols.len();
        let row_limit = (MAX_TABLEAU_ENTRIES / n.max(1)).saturating_sub(1);
        let shifts: Vec<Vec<u32>> = basis.iter().map(|mu| exponents(mu, &names)).collect();
        let supports: Vec<Vec<(Vec<u32>, &Rat)>> = conditions
            .iter()
            .map(|(g, _)| {
                let at = positions(g, &names);
                g.terms()
                    .iter()
                    .map(|t| (spread(&t.exps, &at, names.len()), &t.coef))
                    .collect()
            })
            .collect();
        let mut index: HashMap<Vec<u32>, usize> = HashMap::new();
        let mut entries: Vec<Vec<(usize, Rat)>> = Vec::new();
        for (j, (i, _)) in cols.iter().enumerate() {
            let shift = &shifts[j % basis.len()];
            for (exps, coef) in &supports[*i] {
                let mono: Vec<u32> = exps.iter().zip(shift).map(|(a, b)| a + b).collect();
                let next = entries.len();
                let r = *index.entry(mono).or_insert(next);
                if r == next {
                    // The simplex is dense: beyond this size (five masses,
                    // nine variables, degree-2 multipliers) it would take
                    // gigabytes. Such a case stays unknown rather than
                    // exhausting the machine.
                    if next >= row_limit {
                        return None;
                    }
                    entries.push(Vec::new());
                }
                entries[r].push((j, (*coef).clone()));
            }
        }
        let mut rows: Vec<Vec<Rat>> = entries
            .iter()
            .map(|e| {
                let mut row = vec![Rat::ZERO; n];
                for (j, c) in e {
                    row[*j] = c.clone();
                }
                row
            })
            .collect();
        let mut rhs = vec![Rat::ZERO; rows.len()];
        rows.push(vec![Rat::ONE; n]);
        rhs.push(Rat::ONE);
        let c: Vec<Rat> = cols
            .iter()
            .map(|(i, _)| {
                if conditions[*i].1 {
                    Rat::ONE
                } else {
                    Rat::ZERO
                }
            })
            .collect();
        let x = maximize(&c, &rows, &rhs)?;
        let value: Rat = x
            .iter()
            .zip(&c)
            .fold(Rat::ZERO, |acc, (a, b)| &acc + &(a * b));
        if value.signum() > 0 {
            let mut lambdas = vec![Poly::zero(); conditions.len()];
            for ((i, mu), xi) in cols.iter().zip(&x) {
                if !xi.is_zero() {
                    lambdas[*i] = &lambdas[*i] + &mu.scale(xi);
                }
            }
            // Clear denominators for readable certificates, with one common
            // factor: scaling the multipliers separately would change the
            // combination.
            return Some(integral_multiples(&lambdas));
        }
    }
    None
}

/// The exponents of the monomial `mu` over `names`.
fn exponents(mu: &Poly, names: &[String]) -> Vec<u32> {
    match mu.terms().first() {
        Some(t) => spread(&t.exps, &positions(mu, names), names.len()),
        None => vec![0; names.len()],
    }
}

/// Where each variable of `p` sits in `names` (which holds them all).
fn positions(p: &Poly, names: &[String]) -> Vec<usize> {
    p.vars()
        .iter()
        .map(|v| {
            names
                .iter()
                .position(|n| n == v)
                .expect("every variable is named")
        })
        .collect()
}

/// `exps`, in the order `at` maps into `names`, over all `width` names.
fn spread(exps: &[u32], at: &[usize], width: usize) -> Vec<u32> {
    let mut e = vec![0; width];
    for (x, &k) in exps.iter().zip(at) {
        e[k] = *x;
    }
    e
}

/// `ps` times one positive rational so that all their coefficients are
/// integers without a common factor.
fn integral_multiples(ps: &[Poly]) -> Vec<Poly> {
    let mut den = Int::ONE;
    let mut num = Int::ZERO;
    for t in ps.iter().flat_map(|p| p.terms()) {
        den = den.lcm(t.coef.denom());
        num = num.gcd(t.coef.numer());
    }
    if num.is_zero() {
        return ps.to_vec();
    }
    let scale = Rat::new(den, num);
    ps.iter().map(|p| p.scale(&scale)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    #[test]
    fn simplex_solves_a_textbook_problem() {
        // max 3x + 2y s.t. x + y <= 4, x + 3y <= 6, x <= 3: optimum (3, 1).
        let r = |v: &[i64]| v.iter().map(|&a| Rat::from(a)).collect::<Vec<_>>();
        let x = maximize(
            &r(&[3, 2]),
            &[r(&[1, 1]), r(&[1, 3]), r(&[1, 0])],
            &r(&[4, 6, 3]),
        )
        .unwrap();
        assert_eq!(x, r(&[3, 1]));
    }

    #[test]
    fn design_note_a2_example_is_found() {
        // A2 with the zero above both resonances: P1 = c12 m3 - c23 m1 > 0 and
        // P2 = c23 m1 (m2 - m3) - c12 m3 (m1 + m2) > 0 contradict each other:
        // (m1 + m2) P1 + P2 = -c23 m1 (m1 + m3).
        let g1 = p("c12*m3 - c23*m1");
        let g2 = p("c23*m1*(m2 - m3) - c12*m3*(m1 + m2)");
        let vars: Vec<String> = ["c12", "c23", "m1", "m2", "m3"].map(String::from).to_vec();
        let l = positive_combination(&[(g1.clone(), true), (g2.clone(), true)], &vars, 1).unwrap();
        let combo = &(&l[0] * &g1) + &(&l[1] * &g2);
        assert!(combo.all_coefs_negative() || combo.is_zero(), "{combo}");
        assert!(l.iter().all(|x| x.is_zero() || x.all_coefs_positive()));
    }

    #[test]
    fn multipliers_are_cleared_with_one_common_factor() {
        // Clearing each multiplier on its own would give [1, x]: a different
        // combination.
        let r = |s: &str| s.parse::<Rat>().unwrap();
        let ps = [
            Poly::constant(r("1/2")),
            p("x").scale(&r("3/4")),
            Poly::zero(),
        ];
        assert_eq!(integral_multiples(&ps), [p("2"), p("3*x"), Poly::zero()]);
    }

    #[test]
    fn feasible_conditions_give_no_certificate() {
        let vars: Vec<String> = ["x", "y"].map(String::from).to_vec();
        let conds = [(p("x - y"), true), (p("2*y - x"), true)]; // y < x < 2y is feasible
        assert!(positive_combination(&conds, &vars, 2).is_none());
    }
}
