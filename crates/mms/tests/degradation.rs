//! Rule (2) against the transfer functions: for N <= 4 a model is
//! degradation-free exactly when the numerator and denominator of its
//! transfer function have no common factor.
//!
//! Two routes: the library's `common_factor` (multivariate gcd of the `poly`
//! crate), and an independent one written here: a common factor involving
//! `Omega` survives specialisation of all parameters to numbers (Euclid over
//! Q in `Omega`), and one free of `Omega` would divide the leading
//! coefficient of `den` in `Omega`, which is a monomial in the masses, so it
//! would be a mass dividing the numerator.

use mms::{Model, Output};
use poly::{Poly, Rat};
use std::collections::BTreeMap;

/// Dense univariate polynomial over Q, coefficient k = power k.
fn univariate(p: &Poly, var: &str, pt: &BTreeMap<String, Rat>) -> Vec<Rat> {
    let mut v: Vec<Rat> = p
        .coeffs_in(var)
        .iter()
        .map(|c| c.eval(pt).unwrap())
        .collect();
    while v.last().is_some_and(|c| c.is_zero()) {
        v.pop();
    }
    v
}

fn rem(a: &[Rat], b: &[Rat]) -> Vec<Rat> {
    let mut a = a.to_vec();
    while a.len() >= b.len() && !a.is_empty() {
        let f = &a[a.len() - 1] / &b[b.len() - 1];
        let shift = a.len() - b.len();
        for (i, bi) in b.iter().enumerate() {
            let t = &f * bi;
            a[shift + i] = &a[shift + i] - &t;
        }
        a.pop();
        while a.last().is_some_and(|c| c.is_zero()) {
            a.pop();
        }
    }
    a
}

/// Degree of the gcd of two univariate polynomials over Q.
fn gcd_degree(a: Vec<Rat>, b: Vec<Rat>) -> usize {
    let (mut a, mut b) = (a, b);
    while !b.is_empty() {
        let r = rem(&a, &b);
        a = b;
        b = r;
    }
    a.len() - 1
}

/// Independent test for a non-constant common factor of `num` and `den` in
/// the variable `var`.
fn shares_factor(num: &Poly, den: &Poly, var: &str, params: &[String]) -> bool {
    // Omega-free part: den's leading coefficient must be a monomial.
    let lead = den.lead_in(var);
    assert_eq!(lead.num_terms(), 1, "leading coefficient {lead}");
    let mass_factor = lead
        .vars()
        .iter()
        .any(|v| num.div_exact(&Poly::var(v)).is_some());
    // Omega-dependent part: two specialisations must both show it.
    let mut degs = Vec::new();
    for seed in 0..2i64 {
        let pt: BTreeMap<String, Rat> = params
            .iter()
            .enumerate()
            .map(|(i, p)| (p.clone(), Rat::from(2 + (i as i64 * 7 + seed * 13) % 23)))
            .collect();
        let (a, b) = (univariate(num, var, &pt), univariate(den, var, &pt));
        assert_eq!(
            b.len() - 1,
            den.degree(var) as usize,
            "leading coefficient vanished"
        );
        degs.push(gcd_degree(a, b));
    }
    mass_factor || degs.iter().all(|&d| d > 0)
}

#[test]
fn rule2_is_coprimality_of_the_undamped_tf() {
    for n in 1..=4 {
        for m in mms::basic_models(n).unwrap() {
            let tf = m.undamped_tf();
            let free = m.is_degradation_free();
            let g = tf.common_factor();
            assert_eq!(g.is_constant(), free, "{m}: gcd {g}");
            assert_eq!(
                shares_factor(&tf.num, &tf.den, "Omega", &m.undamped_parameters()),
                !free,
                "{m}"
            );
            let red = tf.reduced();
            assert!(red.common_factor().is_constant());
            // the cancelled factor is the determinant of the part that is
            // not excited or not observed: the grounded part, 0 - 1 - ... - gap
            if !free {
                assert_eq!(g.degree("Omega") as usize, m.gap(), "{m}: {g}");
                assert!(!g.has_var(&format!("m{}", m.gap() + 1)), "{m}: {g}");
            }
        }
    }
}

#[test]
fn rule2_is_coprimality_of_the_damped_tf() {
    for n in 1..=4 {
        for m in mms::basic_models(n).unwrap() {
            let tf = m.damped_tf(Output::Acceleration);
            let free = m.is_degradation_free();
            assert_eq!(
                shares_factor(&tf.num, &tf.den, "s", &m.parameters()),
                !free,
                "{m}"
            );
            assert_eq!(poly::gcd(&tf.num, &tf.den).is_constant(), free, "{m}");
        }
    }
}

#[test]
fn a_degraded_model_reduces_to_a_smaller_one() {
    // Gap 1, actuator against the ground: m1 is not excited, and the TF is
    // that of the free part m2 - m3 with force on m2 and sensor on m2
    // relative to m1 (which does not move): the 2-mass model act (1,0),
    // sensor (1,0) renamed.
    let m = Model::new(3, 1, mms::Port::new(2, 0), mms::Port::new(2, 1)).unwrap();
    let small = Model::new(2, 0, mms::Port::new(1, 0), mms::Port::new(1, 0)).unwrap();
    let rename = |q: &Poly| {
        q.rename(|v| match v {
            "m1" => "m2".into(),
            "m2" => "m3".into(),
            "c12" => "c23".into(),
            other => other.into(),
        })
    };
    let want = small.undamped_tf();
    assert_eq!(
        m.undamped_tf().reduced(),
        mms::UndampedTf {
            num: rename(&want.num),
            den: rename(&want.den)
        }
    );
}
