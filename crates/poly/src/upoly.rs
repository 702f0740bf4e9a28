//! Dense univariate polynomials over Z.
//!
//! [`UPoly`] is the work horse of the univariate layer: exact arithmetic,
//! pseudo-division, gcd, square-free decomposition (Yun), exact evaluation at
//! rationals and conversions to and from the multivariate [`Poly`]. Real-root
//! isolation built on it lives in [`crate::real_roots`] and friends.
//!
//! ```
//! use poly::{Poly, UPoly};
//! // (x - 1)^2 (x + 2) from text, split into content and primitive part.
//! let p: Poly = "2*x^3 - 6*x + 4".parse().unwrap();
//! let (c, u) = UPoly::from_poly(&p, "x").unwrap();
//! assert_eq!(c.to_string(), "2");
//! assert_eq!(u.to_text("x"), "x^3 - 3*x + 2");
//! let sqf = u.square_free();
//! assert_eq!(sqf.len(), 2);
//! assert_eq!((sqf[0].0.to_text("x"), sqf[0].1), ("x + 2".to_string(), 1));
//! assert_eq!((sqf[1].0.to_text("x"), sqf[1].1), ("x - 1".to_string(), 2));
//! ```

use crate::int::Int;
use crate::poly::{Poly, Term};
use crate::rat::Rat;
use num_bigint::BigInt;
use num_traits::{One, Signed};
use std::fmt;
use std::ops::{Add, Mul, Neg, Sub};

/// A dense univariate polynomial with integer coefficients, lowest degree
/// first, without trailing zeros (the zero polynomial has no coefficients).
///
/// ```
/// use poly::UPoly;
/// let a = UPoly::from_i64s(&[-1, 0, 1]); // x^2 - 1
/// let b = UPoly::from_i64s(&[1, 1]); // x + 1
/// assert_eq!(a.div_exact(&b), Some(UPoly::from_i64s(&[-1, 1])));
/// assert_eq!((&b * &b).to_string(), "x^2 + 2*x + 1");
/// assert_eq!(a.gcd(&(&b * &b)), b);
/// ```
#[derive(Clone, PartialEq, Eq, Hash, Debug, Default)]
pub struct UPoly {
    coeffs: Vec<Int>,
}

static INT_ZERO: Int = Int::ZERO;

impl UPoly {
    /// From coefficients, lowest degree first (trailing zeros are removed).
    pub fn new(mut coeffs: Vec<Int>) -> UPoly {
        while coeffs.last().is_some_and(|c| c.is_zero()) {
            coeffs.pop();
        }
        UPoly { coeffs }
    }

    /// Coefficients, lowest degree first.
    pub fn coeffs(&self) -> &[Int] {
        &self.coeffs
    }

    /// Degree; `None` for the zero polynomial.
    pub fn degree(&self) -> Option<usize> {
        self.coeffs.len().checked_sub(1)
    }

    /// True for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.coeffs.is_empty()
    }

    /// The zero polynomial.
    pub fn zero() -> UPoly {
        UPoly { coeffs: Vec::new() }
    }

    /// The constant 1.
    pub fn one() -> UPoly {
        UPoly::constant(Int::ONE)
    }

    /// The constant polynomial `c`.
    pub fn constant(c: Int) -> UPoly {
        UPoly::new(vec![c])
    }

    /// The polynomial `x`.
    pub fn x() -> UPoly {
        UPoly::monomial(Int::ONE, 1)
    }

    /// The monomial `c * x^k`.
    pub fn monomial(c: Int, k: usize) -> UPoly {
        let mut v = vec![Int::ZERO; k + 1];
        v[k] = c;
        UPoly::new(v)
    }

    /// From machine-integer coefficients, lowest degree first.
    ///
    /// ```
    /// use poly::UPoly;
    /// assert_eq!(UPoly::from_i64s(&[2, 0, -3, 0]).to_string(), "-3*x^2 + 2");
    /// ```
    pub fn from_i64s(coeffs: &[i64]) -> UPoly {
        UPoly::new(coeffs.iter().map(|&c| Int::from(c)).collect())
    }

    /// The primitive linear polynomial `d*x - n` vanishing exactly at the
    /// rational `r = n/d`.
    ///
    /// ```
    /// use poly::{Rat, UPoly};
    /// let r: Rat = "-2/3".parse().unwrap();
    /// assert_eq!(UPoly::linear_root(&r).to_string(), "3*x + 2");
    /// ```
    pub fn linear_root(r: &Rat) -> UPoly {
        UPoly::new(vec![-r.numer(), r.denom().clone()])
    }

    /// The coefficient of `x^i` (zero beyond the degree).
    pub fn coeff(&self, i: usize) -> &Int {
        self.coeffs.get(i).unwrap_or(&INT_ZERO)
    }

    /// The leading coefficient (zero for the zero polynomial).
    pub fn leading_coeff(&self) -> Int {
        self.coeffs.last().cloned().unwrap_or(Int::ZERO)
    }

    /// True for constants, the zero polynomial included.
    pub fn is_constant(&self) -> bool {
        self.coeffs.len() <= 1
    }

    /// The exponent of the lowest non-zero term: the multiplicity of the
    /// root 0 (0 for the zero polynomial).
    pub fn x_valuation(&self) -> usize {
        self.coeffs.iter().take_while(|c| c.is_zero()).count()
    }

    /// Multiplies every coefficient by `c`.
    pub fn scale(&self, c: &Int) -> UPoly {
        if c.is_zero() {
            return UPoly::zero();
        }
        UPoly {
            coeffs: self.coeffs.iter().map(|a| a * c).collect(),
        }
    }

    /// `self^e` (`self^0 = 1`).
    pub fn pow(&self, e: u32) -> UPoly {
        let mut result = UPoly::one();
        let mut base = self.clone();
        let mut e = e;
        while e > 0 {
            if e & 1 == 1 {
                result = &result * &base;
            }
            e >>= 1;
            if e > 0 {
                base = &base * &base;
            }
        }
        result
    }

    /// Pseudo-division by a non-zero `d`: `(q, r)` with
    /// `lc(d)^(deg self - deg d + 1) * self = q * d + r` and `deg r < deg d`.
    /// When `deg self < deg d` the result is `(0, self)`. `None` if `d` is zero.
    ///
    /// ```
    /// use poly::{Int, UPoly};
    /// let a = UPoly::from_i64s(&[1, 0, 1]); // x^2 + 1
    /// let d = UPoly::from_i64s(&[1, 2]); // 2x + 1
    /// let (q, r) = a.pseudo_div(&d).unwrap();
    /// assert_eq!(&(&q * &d) + &r, a.scale(&Int::from(4)));
    /// assert_eq!(r, UPoly::from_i64s(&[5]));
    /// ```
    pub fn pseudo_div(&self, d: &UPoly) -> Option<(UPoly, UPoly)> {
        let n = d.degree()?;
        let m = match self.degree() {
            Some(m) if m >= n => m,
            _ => return Some((UPoly::zero(), self.clone())),
        };
        let (q, r, e) = pseudo_div_raw(self, d, true);
        // Bring the multiplier up to lc(d)^(m - n + 1).
        let missing = (m - n + 1) as u32 - e;
        if missing == 0 {
            return Some((q, r));
        }
        let f = d.leading_coeff().pow(missing);
        Some((q.scale(&f), r.scale(&f)))
    }

    /// The pseudo-remainder (second part of [`UPoly::pseudo_div`]); `None` if
    /// `d` is zero.
    pub fn pseudo_rem(&self, d: &UPoly) -> Option<UPoly> {
        self.pseudo_div(d).map(|(_, r)| r)
    }

    /// Exact division in Z\[x\]: `Some(q)` with `self = q * d`, `None` when `d`
    /// is zero or does not divide `self` with an integer quotient.
    pub fn div_exact(&self, d: &UPoly) -> Option<UPoly> {
        let n = d.degree()?;
        if self.is_zero() {
            return Some(UPoly::zero());
        }
        let m = self.degree()?;
        if m < n {
            return None;
        }
        let lc = &d.coeffs[n];
        let mut r = self.coeffs.clone();
        let mut q = vec![Int::ZERO; m - n + 1];
        for k in (0..=m - n).rev() {
            let top = &r[k + n];
            if top.is_zero() {
                continue;
            }
            let (qc, rem) = top.div_rem(lc);
            if !rem.is_zero() {
                return None;
            }
            for (i, di) in d.coeffs.iter().enumerate() {
                if !di.is_zero() {
                    r[k + i] = &r[k + i] - &(&qc * di);
                }
            }
            q[k] = qc;
        }
        if r.iter().any(|c| !c.is_zero()) {
            return None;
        }
        Some(UPoly::new(q))
    }

    /// The content: gcd of the coefficients, >= 0 (0 for the zero polynomial).
    pub fn content(&self) -> Int {
        // Start from the smallest coefficient: the running gcd then stays
        // small and each further step is one cheap division.
        let Some(start) = self
            .coeffs
            .iter()
            .filter(|c| !c.is_zero())
            .min_by_key(|c| c.bits())
        else {
            return Int::ZERO;
        };
        let mut g = start.abs();
        for c in &self.coeffs {
            if g.is_one() {
                break;
            }
            g = int_gcd(&g, c);
        }
        g
    }

    /// Splits `self = c * p` with `p` primitive (coefficient gcd 1) and with a
    /// positive leading coefficient; `c` carries the sign. `(0, 0)` for zero.
    ///
    /// ```
    /// use poly::{Int, UPoly};
    /// let (c, p) = UPoly::from_i64s(&[6, 0, -4]).primitive();
    /// assert_eq!(c, Int::from(-2));
    /// assert_eq!(p, UPoly::from_i64s(&[-3, 0, 2]));
    /// ```
    pub fn primitive(&self) -> (Int, UPoly) {
        if self.is_zero() {
            return (Int::ZERO, UPoly::zero());
        }
        let mut c = self.content();
        if self.leading_coeff().is_negative() {
            c = -c;
        }
        if c.is_one() {
            return (c, self.clone());
        }
        let p = UPoly {
            coeffs: self.coeffs.iter().map(|a| a.div_exact(&c)).collect(),
        };
        (c, p)
    }

    /// The primitive part with positive leading coefficient (see
    /// [`UPoly::primitive`]).
    pub fn primitive_part(&self) -> UPoly {
        self.primitive().1
    }

    /// The derivative.
    pub fn derivative(&self) -> UPoly {
        UPoly::new(
            self.coeffs
                .iter()
                .enumerate()
                .skip(1)
                .map(|(i, c)| c * &Int::from(i))
                .collect(),
        )
    }

    /// The greatest common divisor in Z\[x\], normalised to a positive
    /// leading coefficient: `gcd(content) * gcd(primitive parts)`.
    /// `gcd(0, 0) = 0` and `gcd(a, 0)` is `a` up to sign.
    ///
    /// Algorithm: a modular gcd over primes near 2^63 (images whose leading
    /// coefficients survive have a gcd of at least the true degree, so one
    /// image of degree 0 proves coprimality; otherwise Chinese remaindering,
    /// with the result confirmed by exact division), falling back to the
    /// primitive polynomial remainder sequence when the primes run out.
    ///
    /// ```
    /// use poly::UPoly;
    /// let a = UPoly::from_i64s(&[-2, 0, 2]); // 2x^2 - 2
    /// let b = UPoly::from_i64s(&[2, 4, 2]); // 2(x + 1)^2
    /// assert_eq!(a.gcd(&b).to_string(), "2*x + 2");
    /// ```
    pub fn gcd(&self, other: &UPoly) -> UPoly {
        if self.is_zero() {
            return other.primitive_part().scale(&other.content());
        }
        if other.is_zero() {
            return self.primitive_part().scale(&self.content());
        }
        let (ca, pa) = self.primitive();
        let (cb, pb) = other.primitive();
        let c = ca.gcd(&cb);
        gcd_pp(&pa, &pb).scale(&c)
    }

    /// Square-free decomposition (Yun): `[(f1, m1), (f2, m2), ...]` with the
    /// `fi` primitive, of positive degree, with positive leading coefficients,
    /// pairwise coprime and square-free, the `mi` strictly increasing, and
    /// `self = c * prod fi^mi` where `c = self.primitive().0`.
    /// Constants and the zero polynomial give an empty list.
    ///
    /// ```
    /// use poly::UPoly;
    /// let x1 = UPoly::from_i64s(&[-1, 1]); // x - 1
    /// let x2 = UPoly::from_i64s(&[2, 1]); // x + 2
    /// let p = (&x1.pow(3) * &x2).scale(&poly::Int::from(-5));
    /// assert_eq!(p.square_free(), vec![(x2, 1), (x1, 3)]);
    /// ```
    pub fn square_free(&self) -> Vec<(UPoly, u32)> {
        let mut out = Vec::new();
        if self.is_constant() {
            return out;
        }
        // Over Z with primitive gcds every quotient below is exact in Z[x]
        // (Gauss), and `b` stays primitive with positive leading coefficient.
        let f = self.primitive_part();
        let df = f.derivative();
        let a0 = gcd_pp(&f, &df);
        let Some(mut b) = f.div_exact(&a0) else {
            return out;
        };
        let Some(c) = df.div_exact(&a0) else {
            return out;
        };
        let mut d = &c - &b.derivative();
        let mut i = 1u32;
        while !b.is_constant() {
            let a = if d.is_zero() {
                b.clone()
            } else {
                gcd_pp(&b, &d)
            };
            let (Some(nb), Some(nc)) = (b.div_exact(&a), d.div_exact(&a)) else {
                // Unreachable: `a` divides both `b` and `d`.
                return out;
            };
            if !a.is_constant() {
                out.push((a, i));
            }
            d = &nc - &nb.derivative();
            b = nb;
            i += 1;
        }
        out
    }

    /// The square-free part: the primitive polynomial with positive leading
    /// coefficient that has the same roots as `self`, each simple. Zero for
    /// zero, 1 for non-zero constants.
    pub fn square_free_part(&self) -> UPoly {
        if self.is_zero() {
            return UPoly::zero();
        }
        let f = self.primitive_part();
        let g = gcd_pp(&f, &f.derivative());
        f.div_exact(&g).unwrap_or(f)
    }

    /// `d^deg * self(n/d)` as an integer (`d > 0` keeps the sign of the value).
    pub(crate) fn eval_homog(&self, n: &Int, d: &Int) -> Int {
        if self.is_zero() {
            return Int::ZERO;
        }
        if let Some(v) = self.eval_homog_i128(n, d) {
            return Int::from(BigInt::from(v));
        }
        Int::from(self.eval_homog_big(&n.to_big(), &d.to_big()))
    }

    /// [`UPoly::eval_homog`] in `i128`; `None` on overflow or big inputs.
    fn eval_homog_i128(&self, n: &Int, d: &Int) -> Option<i128> {
        let (Int::Small(n), Int::Small(d)) = (n, d) else {
            return None;
        };
        let (n, d) = (*n as i128, *d as i128);
        let mut it = self.coeffs.iter().rev();
        let mut acc = it.next()?.to_i64()? as i128;
        let mut dp: i128 = 1;
        for c in it {
            acc = acc.checked_mul(n)?;
            if d != 1 {
                dp = dp.checked_mul(d)?;
            }
            let c = c.to_i64()? as i128;
            if c != 0 {
                acc = acc.checked_add(c.checked_mul(dp)?)?;
            }
        }
        Some(acc)
    }

    /// [`UPoly::eval_homog`] on big integers; powers of two as denominators
    /// (the endpoints of isolating intervals) become shifts.
    fn eval_homog_big(&self, n: &BigInt, d: &BigInt) -> BigInt {
        let deg = self.coeffs.len() - 1;
        let mut acc = self.coeffs[deg].to_big();
        let shift = d
            .trailing_zeros()
            .filter(|_| d.magnitude().count_ones() == 1 && !d.is_negative());
        let mut dp = BigInt::one();
        for (j, c) in self.coeffs[..deg].iter().rev().enumerate() {
            acc *= n;
            if shift.is_none() {
                dp *= d;
            }
            if c.is_zero() {
                continue;
            }
            let term = match (c, shift) {
                (Int::Small(v), Some(s)) => BigInt::from(*v) << (s * (j as u64 + 1)),
                (Int::Big(b), Some(s)) => b << (s * (j as u64 + 1)),
                (Int::Small(v), None) => &dp * *v,
                (Int::Big(b), None) => b * &dp,
            };
            acc += term;
        }
        acc
    }

    /// The value at an integer.
    pub fn eval_int(&self, x: &Int) -> Int {
        self.eval_homog(x, &Int::ONE)
    }

    /// The exact value at a rational.
    ///
    /// ```
    /// use poly::{Rat, UPoly};
    /// let p = UPoly::from_i64s(&[-1, 0, 3]); // 3x^2 - 1
    /// let v = p.eval(&"1/3".parse().unwrap());
    /// assert_eq!(v, "-2/3".parse::<Rat>().unwrap());
    /// ```
    pub fn eval(&self, x: &Rat) -> Rat {
        let Some(deg) = self.degree() else {
            return Rat::ZERO;
        };
        let v = self.eval_homog(x.numer(), x.denom());
        Rat::new(v, x.denom().pow(deg as u32))
    }

    /// The exact sign (-1, 0 or 1) of the value at a rational.
    pub fn sign_at(&self, x: &Rat) -> i32 {
        self.eval_homog(x.numer(), x.denom()).signum()
    }

    /// Floating-point value by Horner's rule.
    pub fn eval_f64(&self, x: f64) -> f64 {
        self.coeffs
            .iter()
            .rev()
            .fold(0.0, |acc, c| acc * x + c.to_f64())
    }

    /// Text in the variable `var`, highest power first, in the syntax of
    /// [`Poly`] (so `self.to_text(v) == self.to_poly(v).to_string()`).
    ///
    /// ```
    /// use poly::UPoly;
    /// let p = UPoly::from_i64s(&[-7, 0, -1, 3]);
    /// assert_eq!(p.to_text("Omega"), "3*Omega^3 - Omega^2 - 7");
    /// ```
    pub fn to_text(&self, var: &str) -> String {
        if self.is_zero() {
            return "0".to_string();
        }
        let mut s = String::new();
        let mut first = true;
        for (k, c) in self.coeffs.iter().enumerate().rev() {
            if c.is_zero() {
                continue;
            }
            let neg = c.is_negative();
            if first {
                if neg {
                    s.push('-');
                }
                first = false;
            } else {
                s.push_str(if neg { " - " } else { " + " });
            }
            let a = c.abs();
            let mut factors: Vec<String> = Vec::new();
            if !a.is_one() || k == 0 {
                factors.push(a.to_string());
            }
            match k {
                0 => {}
                1 => factors.push(var.to_string()),
                _ => factors.push(format!("{var}^{k}")),
            }
            s.push_str(&factors.join("*"));
        }
        s
    }

    /// Splits a polynomial in the single variable `var` as `p = c * u` with
    /// `u` primitive and of positive leading coefficient. `None` if another
    /// variable occurs; a constant gives `(p, 1)`, zero gives `(0, 0)`.
    ///
    /// ```
    /// use poly::{Poly, UPoly};
    /// let p: Poly = "-1/2*s^2 + 3/4".parse().unwrap();
    /// let (c, u) = UPoly::from_poly(&p, "s").unwrap();
    /// assert_eq!(c.to_string(), "-1/4");
    /// assert_eq!(u.to_text("s"), "2*s^2 - 3");
    /// assert_eq!(u.to_poly("s").scale(&c), p);
    /// assert!(UPoly::from_poly(&"s*t".parse().unwrap(), "s").is_none());
    /// ```
    pub fn from_poly(p: &Poly, var: &str) -> Option<(Rat, UPoly)> {
        if p.vars().iter().any(|v| v != var) {
            return None;
        }
        if p.is_zero() {
            return Some((Rat::ZERO, UPoly::zero()));
        }
        let rats: Vec<Rat> = p
            .coeffs_in(var)
            .iter()
            .map(|c| c.as_constant())
            .collect::<Option<_>>()?;
        let mut den = Int::ONE;
        for r in &rats {
            den = den.lcm(r.denom());
        }
        let ints: Vec<Int> = rats
            .iter()
            .map(|r| r.numer() * &den.div_exact(r.denom()))
            .collect();
        let (c, u) = UPoly::new(ints).primitive();
        Some((Rat::new(c, den), u))
    }

    /// The multivariate polynomial in `var` with the same coefficients.
    pub fn to_poly(&self, var: &str) -> Poly {
        let vars = [var.to_string()];
        let terms = self
            .coeffs
            .iter()
            .enumerate()
            .filter(|(_, c)| !c.is_zero())
            .map(|(i, c)| Term {
                exps: vec![i as u32],
                coef: Rat::from_int(c.clone()),
            })
            .collect();
        Poly::from_terms(&vars, terms)
    }

    /// The reciprocal polynomial `x^deg * self(1/x)` (coefficients reversed;
    /// its degree drops by the multiplicity of the root 0).
    pub fn reverse(&self) -> UPoly {
        let mut v = self.coeffs.clone();
        v.reverse();
        UPoly::new(v)
    }

    /// `self(-x)`: the roots negated.
    pub fn negate_x(&self) -> UPoly {
        UPoly {
            coeffs: self
                .coeffs
                .iter()
                .enumerate()
                .map(|(i, c)| if i % 2 == 1 { -c } else { c.clone() })
                .collect(),
        }
    }

    /// `self(x + a)` (Taylor shift): the roots moved by `-a`.
    ///
    /// ```
    /// use poly::{Int, UPoly};
    /// let p = UPoly::from_i64s(&[0, 0, 1]); // x^2
    /// assert_eq!(p.taylor_shift(&Int::from(-1)).to_string(), "x^2 - 2*x + 1");
    /// ```
    pub fn taylor_shift(&self, a: &Int) -> UPoly {
        let mut v = self.coeffs.clone();
        let n = v.len();
        if a.is_zero() || n < 2 {
            return self.clone();
        }
        for i in 0..n - 1 {
            for j in (i..n - 1).rev() {
                let t = &v[j + 1] * a;
                v[j] = &v[j] + &t;
            }
        }
        UPoly::new(v)
    }
}

/// Gcd of two integers, >= 0. One division step first brings the larger
/// operand down to the size of the smaller (the binary gcd behind
/// [`Int::gcd`] is slow when the sizes differ a lot, e.g. a running content
/// that has become small against a big coefficient).
fn int_gcd(a: &Int, b: &Int) -> Int {
    if a.is_zero() {
        return b.abs();
    }
    if b.is_zero() {
        return a.abs();
    }
    if let (Int::Small(_), Int::Small(_)) = (a, b) {
        return a.gcd(b);
    }
    let (big, small) = if a.bits() >= b.bits() { (a, b) } else { (b, a) };
    let r = big.div_rem(small).1;
    small.gcd(&r)
}

/// Pseudo-division without the final padding: `(q, r, e)` with
/// `lc(d)^e * a = q * d + r`, `deg r < deg d`, `e` the number of elimination
/// steps. `d` must be non-zero. The quotient is only computed if `want_q`.
pub(crate) fn pseudo_div_raw(a: &UPoly, d: &UPoly, want_q: bool) -> (UPoly, UPoly, u32) {
    let n = d.coeffs.len() - 1;
    let lc = &d.coeffs[n];
    let mut r = a.coeffs.clone();
    let mut q: Vec<Int> = Vec::new();
    let mut e = 0u32;
    while r.len() > n {
        let m = r.len() - 1;
        let top = r[m].clone();
        let s = m - n;
        if !lc.is_one() {
            for c in r.iter_mut() {
                if !c.is_zero() {
                    *c = &*c * lc;
                }
            }
            if want_q {
                for c in q.iter_mut() {
                    *c = &*c * lc;
                }
            }
        }
        for (i, di) in d.coeffs.iter().enumerate() {
            if !di.is_zero() {
                r[s + i] = &r[s + i] - &(&top * di);
            }
        }
        if want_q {
            if q.is_empty() {
                q = vec![Int::ZERO; s + 1];
            }
            q[s] = &q[s] + &top;
        }
        e += 1;
        while r.last().is_some_and(|c| c.is_zero()) {
            r.pop();
        }
    }
    (UPoly::new(q), UPoly::new(r), e)
}

/// The primitive part (positive leading coefficient) of the gcd of `a` and
/// `b`; a zero operand gives the primitive part of the other.
pub(crate) fn gcd_pp(a: &UPoly, b: &UPoly) -> UPoly {
    if a.is_zero() {
        return b.primitive_part();
    }
    if b.is_zero() {
        return a.primitive_part();
    }
    let (a, b) = if a.coeffs.len() >= b.coeffs.len() {
        (a, b)
    } else {
        (b, a)
    };
    if b.is_constant() {
        return UPoly::one();
    }
    if a == b {
        return a.primitive_part();
    }
    if let Some(g) = modular::gcd(a, b) {
        return g;
    }
    prs_gcd(a.primitive_part(), b.primitive_part())
}

/// Gcd of primitive `a`, `b` (`deg a >= deg b >= 1`) by the primitive
/// polynomial remainder sequence; primitive with positive leading coefficient.
fn prs_gcd(mut a: UPoly, mut b: UPoly) -> UPoly {
    loop {
        let (_, r, _) = pseudo_div_raw(&a, &b, false);
        if r.is_zero() {
            return b.primitive_part();
        }
        if r.is_constant() {
            return UPoly::one();
        }
        a = b;
        b = r.primitive_part();
    }
}

/// Arithmetic modulo word-size primes: a modular gcd (image degrees,
/// Chinese remaindering, confirmation by exact division).
mod modular {
    use super::UPoly;
    use crate::int::Int;
    use num_bigint::BigInt;
    use num_integer::Integer;
    use num_traits::{One, ToPrimitive};

    /// Primes are taken downward from here (2^31 - 1, itself prime), so that
    /// products of residues fit in `u64`.
    #[cfg(test)]
    const PRIME_START: u64 = (1 << 31) - 1;

    fn mul(a: u64, b: u64, p: u64) -> u64 {
        if p <= 1 << 32 {
            (a * b) % p
        } else {
            ((a as u128 * b as u128) % p as u128) as u64
        }
    }

    fn sub(a: u64, b: u64, p: u64) -> u64 {
        if a >= b {
            a - b
        } else {
            a + (p - b)
        }
    }

    fn pow(mut a: u64, mut e: u64, p: u64) -> u64 {
        let mut r = 1u64;
        while e > 0 {
            if e & 1 == 1 {
                r = mul(r, a, p);
            }
            a = mul(a, a, p);
            e >>= 1;
        }
        r
    }

    /// Inverse of a residue coprime to `p` (extended Euclid).
    fn inv(a: u64, p: u64) -> u64 {
        let (mut r0, mut r1) = (p as i128, a as i128);
        let (mut t0, mut t1) = (0i128, 1i128);
        while r1 != 0 {
            let q = r0 / r1;
            (r0, r1) = (r1, r0 - q * r1);
            (t0, t1) = (t1, t0 - q * t1);
        }
        t0.rem_euclid(p as i128) as u64
    }

    pub(super) fn reduce(u: &UPoly, p: u64) -> Vec<u64> {
        let mut v: Vec<u64> = u.coeffs().iter().map(|c| c.rem_u64(p)).collect();
        while v.last() == Some(&0) {
            v.pop();
        }
        v
    }

    /// Monic gcd of two polynomials over Z/p (empty for 0).
    fn gcd_mod(mut a: Vec<u64>, mut b: Vec<u64>, p: u64) -> Vec<u64> {
        if a.len() < b.len() {
            std::mem::swap(&mut a, &mut b);
        }
        while !b.is_empty() {
            // a <- a mod b, then swap.
            let nb = b.len() - 1;
            let binv = inv(b[nb], p);
            while a.len() > nb {
                let m = a.len() - 1;
                let f = mul(a[m], binv, p);
                let s = m - nb;
                for (i, &bi) in b.iter().enumerate() {
                    a[s + i] = sub(a[s + i], mul(f, bi, p), p);
                }
                while a.last() == Some(&0) {
                    a.pop();
                }
            }
            std::mem::swap(&mut a, &mut b);
        }
        if let Some(&lc) = a.last() {
            let li = inv(lc, p);
            for c in a.iter_mut() {
                *c = mul(*c, li, p);
            }
        }
        a
    }

    /// Deterministic Miller-Rabin (these bases suffice for every `u64`).
    pub(super) fn is_prime(n: u64) -> bool {
        const BASES: [u64; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];
        if n < 2 {
            return false;
        }
        for &b in &BASES {
            if n.is_multiple_of(b) {
                return n == b;
            }
        }
        let s = (n - 1).trailing_zeros();
        let d = (n - 1) >> s;
        'bases: for &b in &BASES {
            let mut x = pow(b, d, n);
            if x == 1 || x == n - 1 {
                continue;
            }
            for _ in 1..s {
                x = mul(x, x, n);
                if x == n - 1 {
                    continue 'bases;
                }
            }
            return false;
        }
        true
    }

    /// The 32 largest primes below 2^31, descending (checked by a test).
    const FIRST_PRIMES: [u64; 32] = [
        2147483647, 2147483629, 2147483587, 2147483579, 2147483563, 2147483549, 2147483543,
        2147483497, 2147483489, 2147483477, 2147483423, 2147483399, 2147483353, 2147483323,
        2147483269, 2147483249, 2147483237, 2147483179, 2147483171, 2147483137, 2147483123,
        2147483077, 2147483069, 2147483059, 2147483053, 2147483033, 2147483029, 2147482951,
        2147482949, 2147482943, 2147482937, 2147482921,
    ];

    /// The primes below 2^31, descending.
    pub(super) fn primes() -> impl Iterator<Item = u64> {
        let last = FIRST_PRIMES[FIRST_PRIMES.len() - 1];
        FIRST_PRIMES.iter().copied().chain(
            (1..last / 2)
                .map(move |k| last - 2 * k)
                .filter(|&n| is_prime(n)),
        )
    }

    /// The primes as the definition generates them.
    #[cfg(test)]
    pub(super) fn primes_by_search() -> impl Iterator<Item = u64> {
        (0..PRIME_START / 2)
            .map(|k| PRIME_START - 2 * k)
            .filter(|&n| is_prime(n))
    }

    /// Number of bits of an upper bound for the coefficients of any divisor
    /// of `b` (Landau-Mignotte: `2^deg * ||b||_2`).
    fn divisor_bits(b: &UPoly) -> u64 {
        let n = b.coeffs().len() as u64;
        let max_bits = b.coeffs().iter().map(Int::bits).max().unwrap_or(0);
        n + max_bits + (64 - n.leading_zeros() as u64) / 2 + 1
    }

    /// Primitive part of the gcd of non-constant `a`, `b`, by a modular
    /// method.
    ///
    /// For a prime `p` dividing neither leading coefficient, the gcd of the
    /// images has degree >= the true one, so an image of degree 0 proves
    /// coprimality; images of larger than minimal degree come from unlucky
    /// primes and are dropped. Images scaled to the leading coefficient
    /// `gcd(lc a, lc b)` are combined by Chinese remaindering (symmetric
    /// residues); once a new prime leaves the combination unchanged, its
    /// primitive part is accepted only if it divides both inputs exactly (it
    /// then has degree <= and hence = the true degree, so it is the gcd).
    /// `None` if no answer is confirmed within a generous number of primes
    /// (the caller then falls back to the remainder sequence).
    pub(super) fn gcd(a: &UPoly, b: &UPoly) -> Option<UPoly> {
        let lc_gcd = a.leading_coeff().gcd(&b.leading_coeff());
        let need_bits = lc_gcd.bits() + divisor_bits(a).min(divisor_bits(b)) + 2;
        let max_primes = (need_bits / 30) as usize * 2 + 8;
        let mut best_deg = usize::MAX;
        let mut acc: Vec<BigInt> = Vec::new();
        let mut modulus = BigInt::one();
        for p in primes().take(max_primes) {
            let (ra, rb) = (reduce(a, p), reduce(b, p));
            if ra.len() != a.coeffs().len() || rb.len() != b.coeffs().len() {
                continue; // p divides a leading coefficient
            }
            let g = gcd_mod(ra, rb, p);
            let deg = g.len().saturating_sub(1);
            if deg == 0 {
                return Some(UPoly::one());
            }
            if deg > best_deg {
                continue; // unlucky prime
            }
            let lcp = lc_gcd.rem_u64(p);
            let img = g.iter().map(|&c| mul(c, lcp, p));
            let pb = BigInt::from(p);
            if deg < best_deg {
                best_deg = deg;
                let half = p / 2;
                acc = img
                    .map(|c| {
                        if c > half {
                            BigInt::from(c) - &pb
                        } else {
                            BigInt::from(c)
                        }
                    })
                    .collect();
                modulus = pb;
                continue;
            }
            // x <- x + modulus * t, t = (img - x) / modulus mod p, |t| <= p/2.
            let minv = inv(modulus.mod_floor(&pb).to_u64()?, p);
            let mut stable = true;
            for (x, c) in acc.iter_mut().zip(img) {
                let xm = x.mod_floor(&pb).to_u64()?;
                let t = mul(sub(c, xm, p), minv, p);
                if t != 0 {
                    stable = false;
                    let t = if t > p / 2 {
                        BigInt::from(t) - &pb
                    } else {
                        BigInt::from(t)
                    };
                    *x += &modulus * t;
                }
            }
            modulus *= &pb;
            if stable {
                let cand =
                    UPoly::new(acc.iter().map(|x| Int::from(x.clone())).collect()).primitive_part();
                if a.div_exact(&cand).is_some() && b.div_exact(&cand).is_some() {
                    return Some(cand);
                }
            }
        }
        None
    }
}

impl fmt::Display for UPoly {
    /// The polynomial in the variable `x` (see [`UPoly::to_text`]).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.to_text("x"))
    }
}

impl Add for &UPoly {
    type Output = UPoly;
    fn add(self, rhs: &UPoly) -> UPoly {
        let (long, short) = if self.coeffs.len() >= rhs.coeffs.len() {
            (self, rhs)
        } else {
            (rhs, self)
        };
        let mut v = long.coeffs.clone();
        for (a, b) in v.iter_mut().zip(&short.coeffs) {
            *a = &*a + b;
        }
        UPoly::new(v)
    }
}

impl Sub for &UPoly {
    type Output = UPoly;
    fn sub(self, rhs: &UPoly) -> UPoly {
        let n = self.coeffs.len().max(rhs.coeffs.len());
        let v = (0..n).map(|i| self.coeff(i) - rhs.coeff(i)).collect();
        UPoly::new(v)
    }
}

impl Mul for &UPoly {
    type Output = UPoly;
    /// Schoolbook multiplication.
    fn mul(self, rhs: &UPoly) -> UPoly {
        if self.is_zero() || rhs.is_zero() {
            return UPoly::zero();
        }
        let mut v = vec![Int::ZERO; self.coeffs.len() + rhs.coeffs.len() - 1];
        for (i, a) in self.coeffs.iter().enumerate() {
            if a.is_zero() {
                continue;
            }
            for (j, b) in rhs.coeffs.iter().enumerate() {
                if !b.is_zero() {
                    v[i + j] = &v[i + j] + &(a * b);
                }
            }
        }
        UPoly::new(v)
    }
}

impl Neg for &UPoly {
    type Output = UPoly;
    fn neg(self) -> UPoly {
        UPoly {
            coeffs: self.coeffs.iter().map(|c| -c).collect(),
        }
    }
}

impl Neg for UPoly {
    type Output = UPoly;
    fn neg(self) -> UPoly {
        -(&self)
    }
}

macro_rules! forward_owned {
    ($($tr:ident $m:ident),*) => {$(
        impl $tr for UPoly {
            type Output = UPoly;
            fn $m(self, rhs: UPoly) -> UPoly { (&self).$m(&rhs) }
        }
        impl $tr<&UPoly> for UPoly {
            type Output = UPoly;
            fn $m(self, rhs: &UPoly) -> UPoly { (&self).$m(rhs) }
        }
        impl $tr<UPoly> for &UPoly {
            type Output = UPoly;
            fn $m(self, rhs: UPoly) -> UPoly { self.$m(&rhs) }
        }
    )*};
}
forward_owned!(Add add, Sub sub, Mul mul);

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn up(c: &[i64]) -> UPoly {
        UPoly::from_i64s(c)
    }

    fn pp(s: &str) -> Poly {
        s.parse().unwrap()
    }

    /// Deterministic pseudo-random generator (64-bit LCG).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> u64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            self.0 >> 33
        }
        fn small(&mut self, r: i64) -> i64 {
            (self.next() % (2 * r as u64 + 1)) as i64 - r
        }
        fn poly(&mut self, deg: usize, r: i64) -> UPoly {
            let mut c: Vec<i64> = (0..=deg).map(|_| self.small(r)).collect();
            if c[deg] == 0 {
                c[deg] = 1;
            }
            up(&c)
        }
        /// A random polynomial of degree in `min..min + spread`.
        fn rpoly(&mut self, min: usize, spread: usize, r: i64) -> UPoly {
            let d = min + self.next() as usize % spread;
            self.poly(d, r)
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
    }

    fn big(s: &str) -> Int {
        s.parse().unwrap()
    }

    #[test]
    fn ring_operations_agree_with_poly() {
        let mut g = Lcg(7);
        for _ in 0..40 {
            let a = g.rpoly(0, 7, 9);
            let b = g.rpoly(0, 7, 1_000_000_007);
            let (pa, pb) = (a.to_poly("x"), b.to_poly("x"));
            assert_eq!((&a * &b).to_poly("x"), &pa * &pb);
            assert_eq!((&a + &b).to_poly("x"), &pa + &pb);
            assert_eq!((&a - &b).to_poly("x"), &pa - &pb);
            assert_eq!((-&a).to_poly("x"), -&pa);
            assert_eq!(a.derivative().to_poly("x"), pa.derivative("x"));
            assert_eq!(a.to_text("x"), pa.to_string());
            assert!((&a - &a).is_zero());
        }
        // Big path: (2^64 + 1) x times itself.
        let a = UPoly::monomial(big("18446744073709551617"), 1);
        assert_eq!(
            (&a * &a).to_string(),
            "340282366920938463500268095579187314689*x^2"
        );
    }

    #[test]
    fn display_forms() {
        assert_eq!(UPoly::zero().to_string(), "0");
        assert_eq!(up(&[-1]).to_string(), "-1");
        assert_eq!(up(&[0, -1]).to_text("Omega"), "-Omega");
        assert_eq!(up(&[1, -1, 0, 2]).to_text("s"), "2*s^3 - s + 1");
        // Parses back through the multivariate parser.
        let p = up(&[5, 0, -3, 1]);
        assert_eq!(pp(&p.to_text("y")), p.to_poly("y"));
    }

    #[test]
    fn exact_division() {
        let a = up(&[3, -1, 4]);
        let b = up(&[-2, 0, 7, 1]);
        let ab = &a * &b;
        assert_eq!(ab.div_exact(&b), Some(a.clone()));
        assert_eq!(ab.div_exact(&a), Some(b.clone()));
        assert_eq!((&ab + &UPoly::one()).div_exact(&b), None);
        // Divides over Q but not over Z.
        assert_eq!(up(&[1, 1]).div_exact(&up(&[2, 2])), None);
        assert_eq!(up(&[2, 2]).div_exact(&up(&[1, 1])), Some(up(&[2])));
        assert_eq!(a.div_exact(&UPoly::zero()), None);
        assert_eq!(UPoly::zero().div_exact(&a), Some(UPoly::zero()));
        assert_eq!(up(&[1]).div_exact(&a), None);
    }

    #[test]
    fn pseudo_division_identity() {
        let mut g = Lcg(11);
        for _ in 0..40 {
            let a = g.rpoly(0, 8, 50);
            let d = g.rpoly(1, 4, 50);
            let (q, r) = a.pseudo_div(&d).unwrap();
            assert!(r.is_zero() || r.degree() < d.degree());
            let m = a.degree().unwrap_or(0);
            let n = d.degree().unwrap();
            let k = if m >= n { (m - n + 1) as u32 } else { 0 };
            let lhs = a.scale(&d.leading_coeff().pow(k));
            assert_eq!(&(&q * &d) + &r, lhs);
            assert_eq!(a.pseudo_rem(&d), Some(r));
        }
        assert_eq!(up(&[1, 1]).pseudo_div(&UPoly::zero()), None);
    }

    #[test]
    fn content_and_primitive_part() {
        let p = up(&[12, -18, -6]);
        assert_eq!(p.content(), Int::from(6));
        let (c, q) = p.primitive();
        assert_eq!(c, Int::from(-6));
        assert_eq!(q, up(&[-2, 3, 1]));
        assert_eq!(q.scale(&c), p);
        assert_eq!(UPoly::zero().content(), Int::ZERO);
        assert_eq!(UPoly::zero().primitive(), (Int::ZERO, UPoly::zero()));
    }

    #[test]
    fn gcd_of_known_products() {
        let f = &up(&[-2, 0, 1]) * &up(&[-1, 3]).pow(2); // (x^2-2)(3x-1)^2
        let g = up(&[1, 0, 1]); // x^2 + 1
        let h = up(&[5, 1]); // x + 5
        assert_eq!((&f * &g).gcd(&(&f * &h)), f);
        assert_eq!(
            (&f * &g)
                .scale(&Int::from(-4))
                .gcd(&(&f * &h).scale(&Int::from(6))),
            f.scale(&Int::from(2))
        );
        assert_eq!(g.gcd(&h), UPoly::one());
        assert_eq!(f.gcd(&UPoly::zero()), f);
        assert_eq!((-&f).gcd(&UPoly::zero()), f);
        assert_eq!(UPoly::zero().gcd(&UPoly::zero()), UPoly::zero());
        assert_eq!(f.gcd(&f.derivative()), up(&[-1, 3]));
    }

    #[test]
    fn gcd_with_big_coefficients() {
        // gcd coefficients of ~200 bits: several primes and CRT are needed.
        let c = big("1606938044258990275541962092341162602522202993782792835301377"); // 2^200 + 1
        let f = UPoly::new(vec![c.clone(), big("-3"), c.clone() * Int::from(7)]);
        let f = f.primitive_part();
        let g = up(&[1, 1, 1]);
        let h = UPoly::new(vec![Int::from(3), c.clone()]);
        let (a, b) = (&f * &g, &f * &h);
        assert_eq!(a.gcd(&b), f);
        assert_eq!(
            modular::gcd(&a.primitive_part(), &b.primitive_part()),
            Some(f.clone())
        );
        // ~1000-bit gcd: many primes; the PRS agrees.
        let e = Int::from(2).pow(1000);
        let f = UPoly::new(vec![&e + &Int::ONE, Int::from(3), e.clone()]);
        let (a, b) = (&f * &g, &f * &up(&[-7, 2]));
        assert_eq!(modular::gcd(&a, &b), Some(f.clone()));
        assert_eq!(prs_gcd(a.clone(), b.clone()), f);
        assert_eq!(a.gcd(&b), f);
        // A repeated factor with big coefficients (gcd with the derivative).
        let h = &f.pow(2) * &g;
        assert_eq!(h.square_free(), vec![(g.clone(), 1), (f.clone(), 2)]);
    }

    #[test]
    fn prime_generation() {
        let ps: Vec<u64> = modular::primes().take(20).collect();
        assert_eq!(ps[0], 2_147_483_647); // 2^31 - 1
        assert!(ps.windows(2).all(|w| w[0] > w[1]));
        // Trial division: every generated number is prime and none is skipped.
        let trial = |n: u64| {
            n > 1
                && (2..)
                    .take_while(|d| d * d <= n)
                    .all(|d| !n.is_multiple_of(d))
        };
        let expect: Vec<u64> = (ps[19]..=ps[0]).rev().filter(|&n| trial(n)).collect();
        assert_eq!(ps, expect);
        // The table of the first primes agrees with the search, and the
        // sequence continues correctly past it.
        let table: Vec<u64> = modular::primes().take(40).collect();
        let search: Vec<u64> = modular::primes_by_search().take(40).collect();
        assert_eq!(table, search);
        assert!(modular::is_prime(9_223_372_036_854_775_783)); // largest below 2^63
        assert!(!modular::is_prime(9_223_372_036_854_775_807)); // 7^2 * 73 * ...
        assert!(!modular::is_prime(561)); // Carmichael
        assert!(!modular::is_prime(3_215_031_751)); // strong pseudoprime to 2, 3, 5, 7
        let small: Vec<u64> = (0..60).filter(|&n| modular::is_prime(n)).collect();
        assert_eq!(
            small,
            [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59]
        );
    }

    #[test]
    fn modular_gcd_agrees_with_prs() {
        let mut g = Lcg(3);
        for _ in 0..60 {
            let common = g.rpoly(0, 4, 30);
            let a = &common * &g.rpoly(1, 5, 30);
            let b = &common * &g.rpoly(1, 5, 30);
            let (a, b) = (a.primitive_part(), b.primitive_part());
            let (a, b) = if a.degree() >= b.degree() {
                (a, b)
            } else {
                (b, a)
            };
            if b.is_constant() {
                continue;
            }
            let m = modular::gcd(&a, &b).expect("small inputs");
            assert_eq!(m, prs_gcd(a.clone(), b.clone()));
            assert!(a.div_exact(&m).is_some() && b.div_exact(&m).is_some());
            assert!(common.is_zero() || m.div_exact(&common.primitive_part()).is_some());
        }
    }

    #[test]
    fn square_free_recovers_constructed_multiplicities() {
        let f1 = up(&[-2, 0, 1]);
        let f2 = up(&[-1, 3]);
        let f3 = up(&[1, 1, 1]);
        let f4 = up(&[5, 1]);
        let p = (&(&f1 * &f2.pow(2)) * &(&f3.pow(3) * &f4.pow(4))).scale(&Int::from(-6));
        let sqf = p.square_free();
        assert_eq!(
            sqf,
            vec![
                (f1.clone(), 1),
                (f2.clone(), 2),
                (f3.clone(), 3),
                (f4.clone(), 4)
            ]
        );
        let back = sqf
            .iter()
            .fold(UPoly::one(), |acc, (f, m)| &acc * &f.pow(*m));
        assert_eq!(back.scale(&p.primitive().0), p);
        assert_eq!(p.square_free_part(), &(&f1 * &f2) * &(&f3 * &f4));
        // Gaps in multiplicities and a power of x.
        let q = &UPoly::x().pow(5) * &f2.pow(2);
        assert_eq!(q.square_free(), vec![(f2.clone(), 2), (UPoly::x(), 5)]);
        assert!(UPoly::constant(Int::from(4)).square_free().is_empty());
        assert!(UPoly::zero().square_free().is_empty());
        assert_eq!(f3.square_free(), vec![(f3.clone(), 1)]);
    }

    #[test]
    fn square_free_random_products() {
        let mut g = Lcg(5);
        for _ in 0..30 {
            let a = g.rpoly(1, 3, 20);
            let b = g.rpoly(1, 3, 20);
            let p = &a.pow(1 + g.below(3) as u32) * &b.pow(1 + g.below(3) as u32);
            let sqf = p.square_free();
            let back = sqf
                .iter()
                .fold(UPoly::one(), |acc, (f, m)| &acc * &f.pow(*m));
            assert_eq!(back, p.primitive_part());
            for (i, (f, m)) in sqf.iter().enumerate() {
                assert_eq!(
                    f.gcd(&f.derivative()),
                    UPoly::one(),
                    "factor not square-free"
                );
                assert!(i == 0 || sqf[i - 1].1 < *m);
                for (h, _) in &sqf[i + 1..] {
                    assert_eq!(f.gcd(h), UPoly::one());
                }
            }
        }
    }

    #[test]
    fn evaluation() {
        let p = up(&[7, -3, 0, 2, -1]);
        let poly = p.to_poly("x");
        for s in ["0", "1", "-5/3", "22/7", "-1/1000", "123456789/2"] {
            let x: Rat = s.parse().unwrap();
            let mut pt = BTreeMap::new();
            pt.insert("x".to_string(), x.clone());
            let v = poly.eval(&pt).unwrap();
            assert_eq!(p.eval(&x), v);
            assert_eq!(p.sign_at(&x), v.signum());
            let f = p.eval_f64(x.to_f64());
            assert!((f - v.to_f64()).abs() <= 1e-9 * (1.0 + v.to_f64().abs()));
        }
        assert_eq!(p.eval_int(&Int::from(2)), Int::from(1)); // 7 - 6 + 16 - 16
                                                             // Big coefficients and points: the BigInt route (power-of-two and
                                                             // general denominators), against the multivariate evaluation.
        let e = Int::from(3).pow(50);
        let big = UPoly::new(vec![-&e, Int::from(5), Int::ZERO, e.clone(), Int::from(-1)]);
        let poly = big.to_poly("x");
        let huge = format!("{}/7", Int::from(2).pow(90));
        for s in [
            "12345/1024",
            "-7/3",
            "1/4",
            "-3",
            huge.as_str(),
            "5/281474976710656",
        ] {
            let x: Rat = s.parse().unwrap();
            let mut pt = BTreeMap::new();
            pt.insert("x".to_string(), x.clone());
            let v = poly.eval(&pt).unwrap();
            assert_eq!(big.eval(&x), v, "at {s}");
            assert_eq!(big.sign_at(&x), v.signum());
            assert_eq!(p.eval(&x), {
                let mut pt = BTreeMap::new();
                pt.insert("x".to_string(), x.clone());
                p.to_poly("x").eval(&pt).unwrap()
            });
        }
        assert_eq!(UPoly::zero().eval(&Rat::ONE), Rat::ZERO);
        assert_eq!(UPoly::zero().sign_at(&Rat::ONE), 0);
    }

    #[test]
    fn conversions() {
        let p = pp("3/2*Omega^3 - 9*Omega + 6/5");
        let (c, u) = UPoly::from_poly(&p, "Omega").unwrap();
        assert_eq!(c, "3/10".parse().unwrap());
        assert_eq!(u, up(&[4, -30, 0, 5]));
        assert_eq!(u.to_poly("Omega").scale(&c), p);
        let (c, u) = UPoly::from_poly(&pp("-4"), "x").unwrap();
        assert_eq!((c, u), (Rat::from(-4), UPoly::one()));
        assert_eq!(
            UPoly::from_poly(&Poly::zero(), "x"),
            Some((Rat::ZERO, UPoly::zero()))
        );
        assert!(UPoly::from_poly(&pp("x + y"), "x").is_none());
        assert!(UPoly::from_poly(&pp("y"), "x").is_none());
        assert_eq!(UPoly::zero().to_poly("x"), Poly::zero());
    }

    #[test]
    fn substitutions() {
        let p = up(&[3, -1, 0, 2, 5]);
        let x = pp("x");
        for a in [-3i64, 0, 1, 7] {
            let shifted = p.to_poly("x").subs_poly("x", &(&x + &Poly::int(a)));
            assert_eq!(p.taylor_shift(&Int::from(a)).to_poly("x"), shifted);
        }
        assert_eq!(
            p.negate_x().to_poly("x"),
            p.to_poly("x").subs_poly("x", &-&x)
        );
        assert_eq!(p.reverse(), up(&[5, 2, 0, -1, 3]));
        assert_eq!(up(&[0, 0, 1, 2]).reverse(), up(&[2, 1]));
        assert_eq!(up(&[0, 0, 1, 2]).x_valuation(), 2);
        assert_eq!(up(&[-1, 1]).pow(3), up(&[-1, 3, -3, 1]));
        assert_eq!(UPoly::linear_root(&Rat::from(4)), up(&[-4, 1]));
    }
}
