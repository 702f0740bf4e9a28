//! Square-free factorization of multivariate polynomials over Q.
//!
//! `p = unit * prod f^k` with every `f` primitive over Z (positive leading
//! coefficient), square-free, and the `f` pairwise coprime. The factors are
//! found in layers, which keeps them finer than the bare definition needs:
//!
//! 1. the monomial content: each variable `v` dividing `p` exactly `k`
//!    times gives the factor `(v, k)`;
//! 2. for the remaining variable `x` of least degree (first in variable
//!    order on ties), the primitive part in `x` is split by Yun's algorithm
//!    (gcds with the derivative, exact divisions); if it is linear in `x` it
//!    is irreducible and kept whole;
//! 3. the content in `x` (a polynomial in fewer variables) is factored
//!    recursively.
//!
//! Factors from different layers are kept apart even when they have the same
//! multiplicity (they are coprime), so for example `Omega * c23 * (...)`
//! yields three factors.

use crate::gcd::{content_and_pp, gcd};
use crate::poly::{Poly, Term};
use crate::rat::Rat;

/// Square-free factorization over Q: `(unit, [(f, k), ...])` with
/// `p == unit * prod f^k`, each `f` a non-constant primitive integer
/// polynomial with positive leading coefficient, square-free, pairwise
/// coprime, and every `k >= 1`. Sorted by multiplicity, then by the text of
/// the factor. `square_free(0) = (0, [])`; a constant `c` gives `(c, [])`.
///
/// ```
/// use poly::{square_free, Poly, Rat};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let (unit, fs) = square_free(&p("-2*Omega*(Omega*m1 - c12)^2*(m1 + m2)^3"));
/// assert_eq!(unit, Rat::from(-2));
/// let text: Vec<(String, u32)> = fs.iter().map(|(f, k)| (f.to_string(), *k)).collect();
/// assert_eq!(
///     text,
///     [("Omega".to_string(), 1), ("Omega*m1 - c12".to_string(), 2), ("m1 + m2".to_string(), 3)]
/// );
/// ```
pub fn square_free(p: &Poly) -> (Rat, Vec<(Poly, u32)>) {
    if p.is_zero() {
        return (Rat::ZERO, Vec::new());
    }
    let (unit, q) = p.primitive();
    let mut out: Vec<(Poly, u32)> = Vec::new();
    sqf_rec(&q, &mut out);
    out.sort_by(|(f, k), (g, l)| k.cmp(l).then_with(|| f.to_string().cmp(&g.to_string())));
    (unit, out)
}

/// The square-free part (radical) of `p`: the product of the distinct
/// factors of [`square_free`], normalized (primitive, positive leading
/// coefficient); 0 for 0 and 1 for a non-zero constant.
///
/// ```
/// use poly::{square_free_part, Poly};
/// let p: Poly = "3*(x - y)^3*(x + 1)*x^2".parse().unwrap();
/// assert_eq!(square_free_part(&p), "x*(x - y)*(x + 1)".parse().unwrap());
/// ```
pub fn square_free_part(p: &Poly) -> Poly {
    if p.is_zero() {
        return Poly::zero();
    }
    let (_, fs) = square_free(p);
    fs.iter()
        .fold(Poly::one(), |acc, (f, _)| &acc * f)
        .primitive_part()
}

/// True if `p` has no repeated non-constant factor (constants are
/// square-free, zero is not).
///
/// ```
/// use poly::{is_square_free, Poly};
/// assert!(is_square_free(&"x^2 - y".parse::<Poly>().unwrap()));
/// assert!(!is_square_free(&"x^2*y - 2*x*y + y".parse::<Poly>().unwrap()));
/// ```
pub fn is_square_free(p: &Poly) -> bool {
    if p.is_zero() {
        return false;
    }
    square_free(p).1.iter().all(|(_, k)| *k == 1)
}

/// `q`: primitive integer polynomial with positive leading coefficient.
fn sqf_rec(q: &Poly, out: &mut Vec<(Poly, u32)>) {
    if q.is_constant() {
        return;
    }
    // 1. Monomial content.
    let vars = q.vars().to_vec();
    let mins: Vec<u32> = (0..vars.len())
        .map(|i| q.terms().iter().map(|t| t.exps[i]).min().unwrap_or(0))
        .collect();
    let q = if mins.iter().any(|&e| e > 0) {
        for (v, &e) in vars.iter().zip(&mins) {
            if e > 0 {
                out.push((Poly::var(v), e));
            }
        }
        let terms = q
            .terms()
            .iter()
            .map(|t| Term {
                exps: t.exps.iter().zip(&mins).map(|(a, b)| a - b).collect(),
                coef: t.coef.clone(),
            })
            .collect();
        Poly::from_terms(&vars, terms)
    } else {
        q.clone()
    };
    if q.is_constant() {
        return;
    }
    // 2. Yun on the primitive part in the variable of least degree (first in
    //    variable order on ties); 3. recurse on the content.
    let x = q
        .vars()
        .iter()
        .min_by_key(|v| q.degree(v))
        .expect("non-constant")
        .clone();
    let (cont, pp) = content_and_pp(&q, &x);
    if pp.degree(&x) == 1 {
        // Primitive and linear in x: irreducible.
        out.push((pp, 1));
    } else {
        out.extend(yun(&pp, &x));
    }
    sqf_rec(&cont.primitive_part(), out);
}

/// Yun's square-free decomposition of `f`, primitive in `x` with positive
/// degree: the non-constant `(a_i, i)` with `f = const * prod a_i^i`.
fn yun(f: &Poly, x: &str) -> Vec<(Poly, u32)> {
    let fp = f.derivative(x);
    let g = gcd(f, &fp);
    if g.is_constant() {
        return vec![(f.primitive_part(), 1)];
    }
    let mut out = Vec::new();
    let mut c = f.div_exact(&g).expect("gcd divides f");
    let mut d = &fp.div_exact(&g).expect("gcd divides f'") - &c.derivative(x);
    let mut i = 1u32;
    while c.degree(x) > 0 {
        let a = gcd(&c, &d);
        if !a.is_constant() {
            out.push((a.clone(), i));
        }
        c = c.div_exact(&a).expect("gcd divides c");
        d = &d.div_exact(&a).expect("gcd divides d") - &c.derivative(x);
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcd::gcd;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    /// Checks every documented property of the result, and the expected
    /// factors when given.
    fn check(input: &str, unit: &str, want: &[(&str, u32)]) {
        let f = p(input);
        let (u, fs) = square_free(&f);
        assert_eq!(u, unit.parse::<Rat>().unwrap(), "unit of {input}");
        let got: Vec<(Poly, u32)> = fs.clone();
        let expect: Vec<(Poly, u32)> = want.iter().map(|(s, k)| (p(s), *k)).collect();
        assert_eq!(got, expect, "factors of {input}");
        // Recombination.
        let prod = fs
            .iter()
            .fold(Poly::constant(u), |acc, (g, k)| &acc * &g.pow(*k));
        assert_eq!(prod, f);
        for (i, (g, _)) in fs.iter().enumerate() {
            assert_eq!(g.primitive_part(), *g);
            assert!(!g.is_constant());
            // Square-free: coprime to each partial derivative.
            for v in g.vars() {
                assert!(
                    gcd(g, &g.derivative(v)).is_constant(),
                    "{g} not square-free"
                );
            }
            for (h, _) in &fs[i + 1..] {
                assert!(gcd(g, h).is_constant(), "{g} and {h} not coprime");
            }
        }
    }

    #[test]
    fn trivial_inputs() {
        assert_eq!(square_free(&Poly::zero()), (Rat::ZERO, vec![]));
        check("-3/4", "-3/4", &[]);
        check("x", "1", &[("x", 1)]);
        check("-2*x^3*y", "-2", &[("y", 1), ("x", 3)]);
    }

    #[test]
    fn univariate() {
        check("(x - 1)^2*(x + 1)", "1", &[("x + 1", 1), ("x - 1", 2)]);
        check(
            "6*(x^2 + 1)*(x - 2)^3*(x + 3)^3",
            "6",
            &[("x^2 + 1", 1), ("(x - 2)*(x + 3)", 3)],
        );
        check("x^4 - 2*x^2 + 1", "1", &[("x^2 - 1", 2)]);
    }

    #[test]
    fn multivariate() {
        check(
            "(x*y - z)^2*(x + y + z)*(y^2 + 1)^3",
            "1",
            &[("x + y + z", 1), ("x*y - z", 2), ("y^2 + 1", 3)],
        );
        // Repeated factor hidden in the content w.r.t. the first variable.
        check(
            "(a + b)*(m1 - m2)^2*(m1 + m2)^2",
            "1",
            &[("a + b", 1), ("(m1 - m2)*(m1 + m2)", 2)],
        );
        // Paper PZC resultant: c12^2*c23*m3^2*(c12*m3 - c23*m1).
        check(
            "-c12^2*c23*m3^2*(c12*m3 - c23*m1)",
            "-1",
            &[("c12*m3 - c23*m1", 1), ("c23", 1), ("c12", 2), ("m3", 2)],
        );
    }

    #[test]
    fn discriminant_square_factor() {
        // The discriminant of a product f*g contains Res(f, g)^2.
        let f = p("Omega^2*m1*m2 - Omega*c12*(m1 + m2) + c12*c23");
        let g = p("Omega*m3 - c23");
        let d = crate::resultant::discriminant(&(&f * &g), "Omega");
        let r = crate::resultant::resultant(&f, &g, "Omega");
        let (_, fs) = square_free(&d);
        let prod = fs.iter().fold(
            Poly::one(),
            |acc, (h, k)| {
                if *k >= 2 {
                    &acc * &h.pow(*k)
                } else {
                    acc
                }
            },
        );
        assert!(prod.div_exact(&r.primitive_part().pow(2)).is_some());
        assert!(is_square_free(&f));
        assert!(!is_square_free(&d));
    }

    #[test]
    fn radical() {
        assert_eq!(square_free_part(&p("-(x^2 - 1)^2*y^3")), p("(x^2 - 1)*y"));
        assert_eq!(square_free_part(&p("5")), Poly::one());
        assert_eq!(square_free_part(&Poly::zero()), Poly::zero());
    }
}
