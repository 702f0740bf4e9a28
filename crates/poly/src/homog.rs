//! Multi-homogeneity: gradings of a polynomial and dehomogenization.
//!
//! A weight vector `w` (one rational weight per variable) is a *grading* of
//! `f` when every term of `f` has the same weighted degree `<w, e>`. The
//! gradings form a linear space: the null space of the matrix whose rows
//! are the differences `e_t - e_0` of the exponent vectors. Take a basis in
//! reduced echelon form: each basis vector `w_k` has weight 1 at its own
//! *free* variable `z_k` and 0 at the other free variables.
//!
//! Setting every free variable to 1 is injective on the terms of `f` (two
//! terms of equal image differ only in free variables, and `<w_k, .>` picks
//! out the exponent of `z_k`), and it respects factorizations: the factors
//! of a graded polynomial are graded, and a polynomial `a` in the remaining
//! variables that divides the image has a unique *homogenization* without
//! monomial content in the free variables, `z_k` to the power
//! `D_k - <w_k, e>` in the term with exponents `e`, `D_k` the largest
//! `<w_k, e>` over the terms of `a`. For `f` without monomial content,
//! homogenization maps the irreducible factors of the image one-to-one onto
//! those of `f` (the lowest powers of each `z_k` multiply, so a product of
//! homogenizations has no monomial content either, hence equals the
//! homogenization of the product).
//!
//! Factoring the image instead of `f` removes one variable per independent
//! grading; the polynomials of `mms` are homogeneous in the spring
//! constants and in the masses (and more), so this removes the most
//! expensive lifting steps, and many small inputs become univariate.

use crate::poly::{Poly, Term};

/// A dehomogenization: which variables stay, and for each free variable
/// its (integer-scaled) weights on the staying ones.
pub(crate) struct Dehom {
    vars: Vec<String>,
    /// Indices (into `vars`) of the variables that stay.
    keep: Vec<usize>,
    /// Per free variable: its index, the weights `L * w[v]` for `v` in
    /// `keep` (same order) and the common scale `L > 0`.
    free: Vec<(usize, Vec<i64>, i64)>,
}

fn gcd_i128(a: i128, b: i128) -> i128 {
    let (mut a, mut b) = (a.unsigned_abs(), b.unsigned_abs());
    // Word-sized operands (the usual case): 64-bit remainders are much
    // cheaper than 128-bit ones.
    if let (Ok(mut x), Ok(mut y)) = (u64::try_from(a), u64::try_from(b)) {
        while y != 0 {
            let t = x % y;
            x = y;
            y = t;
        }
        return x as i128;
    }
    while b != 0 {
        let t = a % b;
        a = b;
        b = t;
    }
    a as i128
}

/// `v / gcd(v)` (sign kept); `v` unchanged if it is zero.
fn reduce(v: &mut [i128]) {
    let g = v.iter().fold(0, |g, &x| gcd_i128(g, x));
    if g > 1 {
        v.iter_mut().for_each(|x| *x /= g);
    }
}

/// `x * a - y * b`, `None` on overflow.
fn comb(x: i128, a: i128, y: i128, b: i128) -> Option<i128> {
    x.checked_mul(a)?.checked_sub(y.checked_mul(b)?)
}

impl Dehom {
    /// The gradings of `f` (at least two terms), `None` if it has none.
    ///
    /// The space of gradings is kept as an integer basis `W` (initially
    /// all unit vectors) and cut down by each difference `r = e_t - e_0`
    /// that some `w` is not orthogonal to: with `d_i = w_i . r` and a pivot
    /// `d_p != 0`, the vectors `d_p w_i - d_i w_p` (`i != p`) span the
    /// gradings orthogonal to `r` as well. A difference orthogonal to all
    /// of `W` costs a few dot products, and `W` shrinks at most `n` times.
    pub(crate) fn of(f: &Poly) -> Option<Dehom> {
        let vars = f.vars().to_vec();
        let n = vars.len();
        if n < 2 || f.num_terms() < 2 {
            return None;
        }
        let mut w: Vec<Vec<i128>> = (0..n)
            .map(|c| (0..n).map(|k| i128::from(k == c)).collect())
            .collect();
        let e0 = &f.terms()[0].exps;
        let mut r = vec![0i128; n];
        let mut d = Vec::with_capacity(n);
        for t in &f.terms()[1..] {
            for ((x, &a), &b) in r.iter_mut().zip(&t.exps).zip(e0) {
                *x = a as i128 - b as i128;
            }
            d.clear();
            for wi in &w {
                let mut acc: i128 = 0;
                for (a, b) in wi.iter().zip(&r) {
                    acc = acc.checked_add(a.checked_mul(*b)?)?;
                }
                d.push(acc);
            }
            let Some(p) = d.iter().position(|&x| x != 0) else {
                continue;
            };
            let wp = w.remove(p);
            let dp = d.remove(p);
            for (wi, &di) in w.iter_mut().zip(&d) {
                if di != 0 {
                    for (x, &y) in wi.iter_mut().zip(&wp) {
                        *x = comb(*x, dp, y, di)?;
                    }
                    reduce(wi);
                }
            }
            if w.is_empty() {
                return None;
            }
        }
        // Reduced echelon form of W, pivots preferably on high-degree
        // variables (they are eliminated): each row then has weight L at
        // its own free variable and 0 at the other free variables.
        let mut deg = vec![0u32; n];
        for t in f.terms() {
            for (x, &e) in deg.iter_mut().zip(&t.exps) {
                *x = (*x).max(e);
            }
        }
        let mut cols: Vec<usize> = (0..n).collect();
        cols.sort_by_key(|&i| (std::cmp::Reverse(deg[i]), i));
        let mut pivots: Vec<usize> = Vec::new();
        let mut row = 0;
        for &c in &cols {
            if row == w.len() {
                break;
            }
            let Some(k) = (row..w.len()).find(|&k| w[k][c] != 0) else {
                continue;
            };
            w.swap(row, k);
            let pr = w[row].clone();
            for (i, wi) in w.iter_mut().enumerate() {
                if i == row || wi[c] == 0 {
                    continue;
                }
                let (a, b) = (pr[c], wi[c]);
                for (x, &y) in wi.iter_mut().zip(&pr) {
                    *x = comb(*x, a, y, b)?;
                }
                reduce(wi);
            }
            pivots.push(c);
            row += 1;
        }
        // Later eliminations may flip the sign of earlier rows.
        for (wi, &c) in w.iter_mut().zip(&pivots) {
            if wi[c] < 0 {
                wi.iter_mut().for_each(|x| *x = -*x);
            }
        }
        let keep: Vec<usize> = (0..n).filter(|i| !pivots.contains(i)).collect();
        let free = w
            .iter()
            .zip(&pivots)
            .map(|(wi, &c)| {
                let weights: Option<Vec<i64>> =
                    keep.iter().map(|&v| i64::try_from(wi[v]).ok()).collect();
                Some((c, weights?, i64::try_from(wi[c]).ok()?))
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Dehom { vars, keep, free })
    }

    /// Number of variables removed.
    #[cfg(test)]
    pub(crate) fn removed(&self) -> usize {
        self.free.len()
    }

    /// `f` with every free variable set to 1 (`f` over the variables this
    /// was made from).
    pub(crate) fn dehomogenize(&self, f: &Poly) -> Poly {
        debug_assert_eq!(f.vars(), &self.vars[..]);
        let names: Vec<String> = self.keep.iter().map(|&i| self.vars[i].clone()).collect();
        let terms = f
            .terms()
            .iter()
            .map(|t| Term {
                exps: self.keep.iter().map(|&i| t.exps[i]).collect(),
                coef: t.coef.clone(),
            })
            .collect();
        Poly::from_terms(&names, terms)
    }

    /// The homogenization of `a` (a polynomial in the staying variables)
    /// without monomial content in the free variables; `None` if `a` is
    /// not the image of a graded polynomial.
    pub(crate) fn homogenize(&self, a: &Poly) -> Option<Poly> {
        // Position of each variable of `a` among `keep`.
        let pos: Vec<usize> = a
            .vars()
            .iter()
            .map(|v| self.keep.iter().position(|&i| &self.vars[i] == v))
            .collect::<Option<_>>()?;
        let n = self.vars.len();
        let mut terms: Vec<Term> = a
            .terms()
            .iter()
            .map(|t| {
                let mut e = vec![0u32; n];
                for (&p, &x) in pos.iter().zip(&t.exps) {
                    e[self.keep[p]] = x;
                }
                Term {
                    exps: e,
                    coef: t.coef.clone(),
                }
            })
            .collect();
        for (fi, w, l) in &self.free {
            let s: Vec<i64> = a
                .terms()
                .iter()
                .map(|t| {
                    pos.iter().zip(&t.exps).try_fold(0i64, |acc, (&p, &x)| {
                        acc.checked_add(w[p].checked_mul(x as i64)?)
                    })
                })
                .collect::<Option<_>>()?;
            let top = *s.iter().max()?;
            for (t, &si) in terms.iter_mut().zip(&s) {
                let d = top.checked_sub(si)?;
                if d % l != 0 {
                    return None;
                }
                t.exps[*fi] = u32::try_from(d / l).ok()?;
            }
        }
        Some(Poly::from_terms(&self.vars, terms))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rat::Rat;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    #[test]
    fn no_grading() {
        assert!(Dehom::of(&p("x^2 + y + 1")).is_none());
        assert!(Dehom::of(&p("x*y + x + y")).is_none());
    }

    #[test]
    fn roundtrip() {
        for s in [
            "x^2 - y^2",
            "(c12*m3 - c23*m1)^2",
            "a^2*b + 3*a*c^2*b - 7*c^3*d",
            "x^3*y + y^3*z + z^3*x",
            "c1*c2*m1^2 - 3*c1^2*m1*m2 + c2^2*m2^2 - c1*c2*m1*m2",
            "x^2*y - 2*z^3",
        ] {
            let f = p(s);
            let d = Dehom::of(&f).expect(s);
            let g = d.dehomogenize(&f);
            assert_eq!(g.num_terms(), f.num_terms(), "{s}");
            assert_eq!(g.vars().len() + d.removed(), f.vars().len(), "{s}");
            assert_eq!(d.homogenize(&g).unwrap(), f, "{s}");
        }
    }

    #[test]
    fn factors_homogenize() {
        let a = p("c12*m3 - c23*m1");
        let b = p("c12^2*m1*m2 + c23^2*m3^2 - 5*c12*c23*m2^2");
        let f = &a * &b;
        let d = Dehom::of(&f).unwrap();
        for h in [&a, &b] {
            let mut img = h.clone();
            for (i, _, _) in &d.free {
                img = img.subs(&d.vars[*i], &Rat::ONE);
            }
            assert_eq!(&d.homogenize(&img).unwrap(), h);
        }
    }
}
