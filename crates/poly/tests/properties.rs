//! Algebraic laws on seeded random polynomials: each case is checked
//! against an identity that holds for every polynomial (ring laws), or
//! against a second route to the same answer (a gcd that must contain a
//! planted common factor, a factorization or square-free decomposition
//! multiplied back, a resultant that must vanish exactly when a common
//! factor was planted). The generator is seeded, so a failure names its
//! case and reproduces.

use poly::{factor, gcd, is_square_free, resultant, square_free, square_free_part, Poly, Rat};

/// A linear congruential generator: enough to spread cases, and the
/// same on every machine.
struct Cases(u64);

impl Cases {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }

    /// A polynomial of up to `terms` terms in `vars`, each exponent up to
    /// `max_deg`, with coefficients that are small integers or halves and
    /// thirds (never the zero polynomial).
    fn poly(&mut self, vars: &[&str], terms: usize, max_deg: u32) -> Poly {
        let mut acc = Poly::zero();
        for _ in 0..terms {
            let num = (self.next() % 13) as i64 - 6;
            let den = [1, 1, 2, 3][(self.next() % 4) as usize];
            let c = Rat::new(num.into(), den.into());
            let mut t = Poly::constant(c);
            for v in vars {
                t = t.mul_var_pow(v, self.next() % (max_deg + 1));
            }
            acc = &acc + &t;
        }
        if acc.is_zero() {
            Poly::var(vars[0])
        } else {
            acc
        }
    }
}

const VARS: [&str; 3] = ["x", "y", "z"];

#[test]
fn ring_laws_hold() {
    let mut r = Cases(1);
    for case in 0..60 {
        let a = r.poly(&VARS, 1 + case % 5, 3);
        let b = r.poly(&VARS, 1 + case % 4, 3);
        let c = r.poly(&VARS[..2], 1 + case % 3, 2);
        assert_eq!(&(&a + &b) + &c, &a + &(&b + &c), "case {case}");
        assert_eq!(&a + &b, &b + &a, "case {case}");
        assert_eq!(&a * &b, &b * &a, "case {case}");
        assert_eq!(&(&a * &b) * &c, &a * &(&b * &c), "case {case}");
        assert_eq!(&a * &(&b + &c), &(&a * &b) + &(&a * &c), "case {case}");
        assert!((&a - &a).is_zero(), "case {case}");
        assert_eq!(&a * &Poly::one(), a, "case {case}");
        // Exact division undoes multiplication.
        assert_eq!((&a * &b).div_exact(&b), Some(a.clone()), "case {case}");
        // The text form reads back to the same polynomial.
        assert_eq!(a.to_string().parse::<Poly>().unwrap(), a, "case {case}");
    }
}

#[test]
fn gcd_divides_both_and_holds_the_planted_factor() {
    let mut r = Cases(2);
    for case in 0..40 {
        let f = r.poly(&VARS, 1 + case % 3, 2);
        let a = &f * &r.poly(&VARS, 1 + case % 4, 2);
        let b = &f * &r.poly(&VARS, 2 + case % 3, 2);
        let g = gcd(&a, &b);
        assert!(
            a.div_exact(&g).is_some(),
            "case {case}: {g} does not divide {a}"
        );
        assert!(
            b.div_exact(&g).is_some(),
            "case {case}: {g} does not divide {b}"
        );
        assert!(
            g.div_exact(&f).is_some(),
            "case {case}: {f} does not divide {g}"
        );
    }
}

#[test]
fn factorization_and_square_free_parts_multiply_back() {
    let mut r = Cases(3);
    for case in 0..25 {
        let a = r.poly(&VARS[..2], 1 + case % 3, 2);
        let b = r.poly(&VARS[..2], 1 + case % 2, 2);
        // A square planted: p = a^2 b.
        let p = &(&a * &a) * &b;
        assert_eq!(factor(&p).expand(), p, "case {case}: factor");
        let (c, parts) = square_free(&p);
        let mut back = Poly::constant(c);
        for (q, e) in &parts {
            back = &back * &q.pow(*e);
        }
        assert_eq!(back, p, "case {case}: square-free decomposition");
        let s = square_free_part(&p);
        assert!(is_square_free(&s), "case {case}: {s}");
        assert!(
            p.div_exact(&s).is_some(),
            "case {case}: {s} does not divide {p}"
        );
        if !a.is_constant() {
            // The square's base survives in the square-free part.
            let sa = square_free_part(&a);
            assert!(s.div_exact(&sa).is_some(), "case {case}: {sa} not in {s}");
        }
    }
}

#[test]
fn resultant_vanishes_exactly_with_a_common_factor() {
    let mut r = Cases(4);
    let mut common = 0;
    for case in 0..40 {
        let a = r.poly(&VARS[..2], 2 + case % 3, 3);
        let b = r.poly(&VARS[..2], 2 + case % 2, 3);
        if a.degree("x") == 0 || b.degree("x") == 0 {
            continue;
        }
        let c = r.poly(&VARS[..2], 2, 2);
        if c.degree("x") > 0 {
            common += 1;
            let res = resultant(&(&a * &c), &(&b * &c), "x");
            assert!(
                res.is_zero(),
                "case {case}: a common factor in x, resultant {res}"
            );
        }
        // Without one (gcd constant in x), the resultant is not zero.
        if gcd(&a, &b).degree("x") == 0 {
            let res = resultant(&a, &b, "x");
            assert!(!res.is_zero(), "case {case}: coprime in x, resultant zero");
        }
    }
    assert!(common >= 10, "only {common} planted cases");
}
