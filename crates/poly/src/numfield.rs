//! Real number fields `Q(theta)` and polynomials over them.
//!
//! A [`RealField`] is `Q[x]/(f)` for an irreducible integer polynomial `f`
//! together with one real root `theta` of `f`, isolated by a rational
//! interval. Its elements ([`FieldElem`]) are polynomials in `theta` of
//! degree below `deg f` with rational coefficients; their arithmetic is
//! exact, and their sign is decided exactly by interval evaluation at
//! `theta`, refining the isolating interval until the enclosure leaves 0
//! (an element that is not zero in the field is not zero at `theta`, since
//! `f` is irreducible). On top of that: polynomials over the field
//! ([`FieldPoly`]), their gcd, square-free decomposition, Sturm sequences,
//! the isolation of their real roots by rational intervals, and the
//! interleaving of the roots of several of them ([`RealField::interleave_roots`],
//! the same reading as [`crate::interleave_roots`] over Q). Square linear
//! systems are solved over the field by Gaussian elimination.
//!
//! ```
//! use poly::{RealField, UPoly};
//! // theta = sqrt(2), the positive root of x^2 - 2.
//! let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
//! let t = k.generator();
//! assert_eq!(k.to_text(&k.mul(&t, &t), "theta"), "2");
//! let e = k.sub(&t, &k.from_rat(&"141/100".parse().unwrap()));
//! assert_eq!(k.sign(&e), 1); // sqrt(2) > 1.41
//! ```

use crate::factor_uni::factor_univariate;
use crate::int::Int;
use crate::poly::Poly;
use crate::rat::Rat;
use crate::roots::{real_roots, SharedRoot};
use crate::upoly::{pseudo_div_raw, UPoly};
use std::cell::RefCell;
use std::collections::BTreeMap;

/// Why a [`RealField`] could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FieldError {
    /// The defining polynomial is constant or zero.
    #[error("the defining polynomial of a field is constant")]
    Constant,
    /// The defining polynomial factors over Q.
    #[error("the defining polynomial of a field is not irreducible over Q")]
    Reducible,
    /// The interval holds no root or more than one.
    #[error("the interval does not isolate one root of the defining polynomial")]
    NotIsolating,
}

/// An element of a [`RealField`]: `sum c_i theta^i`, lowest degree first,
/// without trailing zeros (zero has no coefficients), of degree below the
/// field's. Only meaningful together with its field.
///
/// ```
/// use poly::{RealField, UPoly};
/// let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
/// let a = k.add(&k.generator(), &k.one()); // sqrt 2 + 1
/// assert_eq!(a.coeffs().len(), 2);
/// assert_eq!(a.as_rat(), None);
/// assert_eq!(k.mul(&a, &k.sub(&k.generator(), &k.one())).as_rat(), Some(1.into()));
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct FieldElem {
    coeffs: Vec<Rat>,
}

impl FieldElem {
    /// The coefficients of the powers of `theta`, lowest first.
    pub fn coeffs(&self) -> &[Rat] {
        &self.coeffs
    }

    /// True for the zero element.
    pub fn is_zero(&self) -> bool {
        self.coeffs.is_empty()
    }

    /// The element as a rational, if it lies in Q.
    pub fn as_rat(&self) -> Option<Rat> {
        match self.coeffs.len() {
            0 => Some(Rat::ZERO),
            1 => Some(self.coeffs[0].clone()),
            _ => None,
        }
    }

    /// `num / den` (`den` non-zero) in lowest terms, `num` of degree below
    /// the field's.
    fn over(num: &UPoly, den: &Int) -> FieldElem {
        FieldElem::trimmed(
            num.coeffs()
                .iter()
                .map(|v| Rat::new(v.clone(), den.clone()))
                .collect(),
        )
    }

    fn trimmed(mut coeffs: Vec<Rat>) -> FieldElem {
        while coeffs.last().is_some_and(Rat::is_zero) {
            coeffs.pop();
        }
        FieldElem { coeffs }
    }
}

/// A polynomial in one variable with coefficients in a [`RealField`],
/// lowest degree first, without trailing zeros.
///
/// ```
/// use poly::{FieldPoly, RealField, UPoly};
/// let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
/// // x^2 - 2 over Q(sqrt 2) has the root sqrt 2: divisible by x - sqrt 2.
/// let f = FieldPoly::new(vec![k.from_rat(&(-2).into()), k.zero(), k.one()]);
/// let g = FieldPoly::new(vec![k.neg(&k.generator()), k.one()]);
/// assert_eq!(k.poly_div_exact(&f, &g).unwrap().degree(), Some(1));
/// assert_eq!(f.derivative().degree(), Some(1));
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct FieldPoly {
    coeffs: Vec<FieldElem>,
}

impl FieldPoly {
    /// From coefficients, lowest degree first (trailing zeros removed).
    pub fn new(mut coeffs: Vec<FieldElem>) -> FieldPoly {
        while coeffs.last().is_some_and(FieldElem::is_zero) {
            coeffs.pop();
        }
        FieldPoly { coeffs }
    }

    /// The coefficients, lowest degree first.
    pub fn coeffs(&self) -> &[FieldElem] {
        &self.coeffs
    }

    /// The degree; `None` for the zero polynomial.
    pub fn degree(&self) -> Option<usize> {
        self.coeffs.len().checked_sub(1)
    }

    /// True for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.coeffs.is_empty()
    }

    /// True for constants, zero included.
    pub fn is_constant(&self) -> bool {
        self.coeffs.len() <= 1
    }

    /// The derivative.
    pub fn derivative(&self) -> FieldPoly {
        FieldPoly::new(
            self.coeffs
                .iter()
                .enumerate()
                .skip(1)
                .map(|(i, c)| {
                    FieldElem::trimmed(c.coeffs.iter().map(|v| v * &Rat::from(i as i64)).collect())
                })
                .collect(),
        )
    }
}

/// The real number field `Q(theta)`: `theta` the one root of an
/// irreducible integer polynomial in an isolating interval, which the
/// field narrows as signs need it (interior mutability: a field is not
/// shared between threads).
///
/// ```
/// use poly::{RealField, Rat, UPoly};
/// // The real root of x^3 - 2 in (1, 2): the cube root of 2.
/// let k = RealField::new(UPoly::from_i64s(&[-2, 0, 0, 1]), Rat::from(1), Rat::from(2)).unwrap();
/// let t = k.generator();
/// let inv = k.inv(&t).unwrap();
/// assert_eq!(k.to_text(&inv, "theta"), "1/2*theta^2");
/// assert!((k.to_f64(&inv) - 2f64.powf(-1.0 / 3.0)).abs() < 1e-12);
/// assert!(RealField::new(UPoly::from_i64s(&[-1, 0, 1]), Rat::from(0), Rat::from(2)).is_err());
/// ```
#[derive(Debug, Clone)]
pub struct RealField {
    minimal: UPoly,
    /// An isolating interval of `theta`: `lo == hi` (only in degree 1)
    /// or `lo < hi` with the defining polynomial non-zero at both ends
    /// and of opposite signs there.
    bounds: RefCell<(Rat, Rat)>,
    /// The interval the field was built with.
    initial: (Rat, Rat),
}

/// Bisection steps that refining an interval may take before it gives up
/// (an element non-zero in the field is non-zero at `theta`, so only an
/// element of more than this many bits of cancellation ends so).
const MAX_REFINEMENTS: usize = 100_000;

/// Rounds of four halvings the floating-point filter of
/// [`RealField::sign`] tries: past about 2^-60 of `theta` the `f64`
/// bounds no longer narrow.
const FLOAT_REFINEMENTS: usize = 16;

/// Halvings of [`RealField::positive_simple_roots`] before it gives up.
const MAX_DESCARTES_DEPTH: usize = 96;

/// `[lo, hi]` pushed outwards by more than the rounding of the operation
/// that made each bound (and of [`Rat::to_f64`], a few units in the last
/// place); `None` unless both are finite.
fn widened(lo: f64, hi: f64) -> Option<(f64, f64)> {
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    const REL: f64 = 1.0 / (1u64 << 48) as f64;
    const ABS: f64 = 1e-300;
    Some((lo - lo.abs() * REL - ABS, hi + hi.abs() * REL + ABS))
}

fn mid(lo: &Rat, hi: &Rat) -> Rat {
    &(lo + hi) * &Rat::new(Int::ONE, Int::from(2))
}

fn negated(a: &Rat) -> Rat {
    -a
}

/// `[a, b] * [c, d]` over the rationals.
fn interval_mul(a: &(Rat, Rat), b: &(Rat, Rat)) -> (Rat, Rat) {
    let p = [&a.0 * &b.0, &a.0 * &b.1, &a.1 * &b.0, &a.1 * &b.1];
    let lo = p.iter().min().cloned().unwrap_or(Rat::ZERO);
    let hi = p.iter().max().cloned().unwrap_or(Rat::ZERO);
    (lo, hi)
}

impl RealField {
    /// The field of the one root of `minimal` in the interval `[lo, hi]`
    /// (`lo < hi` with no root at either end, or `lo == hi` a rational
    /// root of a linear `minimal`). Fails if `minimal` is constant or not
    /// irreducible over Q, or the interval does not isolate one root.
    pub fn new(minimal: UPoly, lo: Rat, hi: Rat) -> Result<RealField, FieldError> {
        if minimal.is_constant() {
            return Err(FieldError::Constant);
        }
        let (_, factors) = factor_univariate(&minimal);
        if factors.len() != 1 || factors[0].1 != 1 {
            return Err(FieldError::Reducible);
        }
        let minimal = factors[0].0.clone();
        if lo > hi {
            return Err(FieldError::NotIsolating);
        }
        if lo == hi {
            if minimal.sign_at(&lo) != 0 {
                return Err(FieldError::NotIsolating);
            }
        } else if minimal.sign_at(&lo) * minimal.sign_at(&hi) >= 0
            || crate::count_roots_in(&minimal, &lo, &hi) != 1
        {
            return Err(FieldError::NotIsolating);
        }
        Ok(RealField {
            minimal,
            initial: (lo.clone(), hi.clone()),
            bounds: RefCell::new((lo, hi)),
        })
    }

    /// One field per distinct real root of `p`, ascending by the root:
    /// each irreducible factor of `p` with its roots isolated. A linear
    /// factor gives its rational root exactly.
    ///
    /// ```
    /// use poly::{RealField, UPoly};
    /// // (x - 1)(x^2 - 3): the roots -sqrt(3), 1, sqrt(3).
    /// let p = &UPoly::from_i64s(&[-1, 1]) * &UPoly::from_i64s(&[-3, 0, 1]);
    /// let roots: Vec<f64> = RealField::real_roots_of(&p).iter().map(|k| k.theta_f64()).collect();
    /// assert_eq!(roots.len(), 3);
    /// assert!((roots[0] + 3f64.sqrt()).abs() < 1e-12 && roots[1] == 1.0);
    /// ```
    pub fn real_roots_of(p: &UPoly) -> Vec<RealField> {
        let (_, factors) = factor_univariate(p);
        let mut out: Vec<RealField> = Vec::new();
        for (f, _) in factors {
            for r in real_roots(&f) {
                if let Ok(k) = RealField::new(f.clone(), r.lo, r.hi) {
                    out.push(k);
                }
            }
        }
        out.sort_by(|a, b| a.theta_f64().total_cmp(&b.theta_f64()));
        out
    }

    /// The defining polynomial (primitive, positive leading coefficient).
    pub fn minimal(&self) -> &UPoly {
        &self.minimal
    }

    /// The field's degree over Q.
    pub fn degree(&self) -> usize {
        self.minimal.degree().unwrap_or(0)
    }

    /// The isolating interval the field was built with (the shortest
    /// description of `theta`; [`Self::interval`] narrows as signs need).
    pub fn isolating_interval(&self) -> (Rat, Rat) {
        self.initial.clone()
    }

    /// The isolating interval of `theta` as narrowed so far.
    pub fn interval(&self) -> (Rat, Rat) {
        self.bounds.borrow().clone()
    }

    /// `theta` to about double precision.
    pub fn theta_f64(&self) -> f64 {
        self.narrow_to(&Rat::new(Int::ONE, Int::from(1i64 << 60)));
        let (lo, hi) = self.interval();
        mid(&lo, &hi).to_f64()
    }

    /// Halves the isolating interval once (unless `theta` is exact).
    fn bisect(&self) {
        let mut b = self.bounds.borrow_mut();
        if b.0 == b.1 {
            return;
        }
        let m = mid(&b.0, &b.1);
        let sm = self.minimal.sign_at(&m);
        if sm == 0 {
            *b = (m.clone(), m);
        } else if sm == self.minimal.sign_at(&b.0) {
            b.0 = m;
        } else {
            b.1 = m;
        }
    }

    /// Narrows the isolating interval to at most `width`.
    fn narrow_to(&self, width: &Rat) {
        for _ in 0..MAX_REFINEMENTS {
            let (lo, hi) = self.interval();
            if &(&hi - &lo) <= width {
                return;
            }
            self.bisect();
        }
    }

    /// The element of the rational coefficients `c` (lowest first), reduced
    /// modulo the defining polynomial.
    pub fn element(&self, c: Vec<Rat>) -> FieldElem {
        if c.len() <= self.degree() {
            return FieldElem::trimmed(c);
        }
        let (x, den) = over_common_denominator(&c);
        self.reduced(&UPoly::new(x), &den)
    }

    /// Zero.
    pub fn zero(&self) -> FieldElem {
        FieldElem::default()
    }

    /// One.
    pub fn one(&self) -> FieldElem {
        self.from_rat(&Rat::ONE)
    }

    /// A rational as an element.
    pub fn from_rat(&self, r: &Rat) -> FieldElem {
        self.element(vec![r.clone()])
    }

    /// `theta` itself.
    pub fn generator(&self) -> FieldElem {
        self.element(vec![Rat::ZERO, Rat::ONE])
    }

    /// `a + b`.
    pub fn add(&self, a: &FieldElem, b: &FieldElem) -> FieldElem {
        let n = a.coeffs.len().max(b.coeffs.len());
        let z = Rat::ZERO;
        FieldElem::trimmed(
            (0..n)
                .map(|i| a.coeffs.get(i).unwrap_or(&z) + b.coeffs.get(i).unwrap_or(&z))
                .collect(),
        )
    }

    /// `-a`.
    pub fn neg(&self, a: &FieldElem) -> FieldElem {
        FieldElem {
            coeffs: a.coeffs.iter().map(negated).collect(),
        }
    }

    /// `a - b`.
    pub fn sub(&self, a: &FieldElem, b: &FieldElem) -> FieldElem {
        self.add(a, &self.neg(b))
    }

    /// `a * r` for a rational `r`.
    pub fn scale(&self, a: &FieldElem, r: &Rat) -> FieldElem {
        FieldElem::trimmed(a.coeffs.iter().map(|c| c * r).collect())
    }

    /// `a * b`.
    ///
    /// Over the integers: each factor's coefficients over one common
    /// denominator, their product and its reduction modulo the integer
    /// defining polynomial without a fraction, and one division back into
    /// lowest terms per coefficient. Over the rationals every product and
    /// sum of coefficients took a gcd; this was the better part of the
    /// number-field searches' time at six masses.
    pub fn mul(&self, a: &FieldElem, b: &FieldElem) -> FieldElem {
        if a.is_zero() || b.is_zero() {
            return self.zero();
        }
        if let Some(r) = a.as_rat() {
            return self.scale(b, &r);
        }
        if let Some(r) = b.as_rat() {
            return self.scale(a, &r);
        }
        let (x, dx) = over_common_denominator(&a.coeffs);
        let (y, dy) = over_common_denominator(&b.coeffs);
        self.reduced(&(&UPoly::new(x) * &UPoly::new(y)), &(&dx * &dy))
    }

    /// The element `c / den` (`den` non-zero) of any degree: `c`'s
    /// pseudo-remainder `r` by the integer defining polynomial `f`
    /// (`lc(f)^e c = q f + r`) over `lc(f)^e den`, so no step divides.
    fn reduced(&self, c: &UPoly, den: &Int) -> FieldElem {
        let (_, r, e) = pseudo_div_raw(c, &self.minimal, false);
        FieldElem::over(&r, &(den * &self.minimal.leading_coeff().pow(e)))
    }

    /// `a^e`.
    pub fn pow(&self, a: &FieldElem, e: u32) -> FieldElem {
        let mut out = self.one();
        let mut base = a.clone();
        let mut e = e;
        while e > 0 {
            if e & 1 == 1 {
                out = self.mul(&out, &base);
            }
            e >>= 1;
            if e > 0 {
                base = self.mul(&base, &base);
            }
        }
        out
    }

    /// `1 / a`, by the extended Euclidean algorithm against the defining
    /// polynomial over the integers: pseudo-remainders, each with its
    /// cofactor of `a`'s numerator and the pair's common content divided
    /// out. `None` for zero. Over the rationals every step's products and
    /// sums took a gcd each, and in fields of degree 20 and more with
    /// coefficients of hundreds of digits one inverse took seconds.
    pub fn inv(&self, a: &FieldElem) -> Option<FieldElem> {
        if a.is_zero() {
            return None;
        }
        if let Some(r) = a.as_rat() {
            return Some(self.from_rat(&r.recip()));
        }
        let (num, den) = over_common_denominator(&a.coeffs);
        // Invariant: s * num == r (mod minimal), for (r0, s0) and (r1, s1).
        let (mut r0, mut s0) = (self.minimal.clone(), UPoly::zero());
        let (mut r1, mut s1) = (UPoly::new(num), UPoly::one());
        while r1.degree().is_some_and(|d| d > 0) {
            let (q, r, e) = pseudo_div_raw(&r0, &r1, true);
            let s = &s0.scale(&r1.leading_coeff().pow(e)) - &(&q * &s1);
            // The pair's common content out: the numbers stay small.
            let g = r.content().gcd(&s.content());
            let (r, s) = if g.is_one() || g.is_zero() {
                (r, s)
            } else {
                let cut =
                    |p: &UPoly| UPoly::new(p.coeffs().iter().map(|v| v.div_exact(&g)).collect());
                (cut(&r), cut(&s))
            };
            r0 = std::mem::replace(&mut r1, r);
            s0 = std::mem::replace(&mut s1, s);
        }
        // s1 * num == c, so 1/a = den * s1 / c.
        let c = r1.coeffs().first()?.clone();
        Some(self.reduced(&s1.scale(&den), &c))
    }

    /// `a / b`; `None` when `b` is zero.
    pub fn div(&self, a: &FieldElem, b: &FieldElem) -> Option<FieldElem> {
        Some(self.mul(a, &self.inv(b)?))
    }

    /// A rational interval holding the value of `a` at `theta`, by interval
    /// evaluation on the isolating interval as narrowed so far.
    pub fn enclosure(&self, a: &FieldElem) -> (Rat, Rat) {
        let b = self.interval();
        let mut acc = (Rat::ZERO, Rat::ZERO);
        for c in a.coeffs.iter().rev() {
            let p = interval_mul(&acc, &b);
            acc = (&p.0 + c, &p.1 + c);
        }
        acc
    }

    /// An `f64` interval holding the value of `a` at `theta`, by interval
    /// evaluation in floating point with every bound pushed outwards past
    /// its rounding; `None` where a number leaves the range of `f64`.
    fn float_enclosure(&self, a: &FieldElem) -> Option<(f64, f64)> {
        let coeffs = a
            .coeffs
            .iter()
            .map(|c| {
                let v = c.to_f64();
                widened(v, v)
            })
            .collect::<Option<Vec<_>>>()?;
        let (lo, hi) = self.interval();
        horner_enclosure(&coeffs, &lo, &hi)
    }

    /// The sign of a non-rational `a` where floating-point enclosures on
    /// `theta`'s interval, narrowed four halvings at a time, decide it;
    /// `None` where a number leaves the range of `f64` or the interval
    /// passes the resolution of `f64` first.
    fn float_sign(&self, a: &FieldElem) -> Option<i32> {
        for _ in 0..FLOAT_REFINEMENTS {
            match self.float_enclosure(a)? {
                (lo, _) if lo > 0.0 => return Some(1),
                (_, hi) if hi < 0.0 => return Some(-1),
                _ => {}
            }
            // Past the resolution of f64 a narrower interval no longer
            // narrows the floating-point bounds.
            let (l, h) = self.interval();
            let (lf, hf) = (l.to_f64(), h.to_f64());
            if l == h || hf - lf <= lf.abs().max(hf.abs()) * 1e-17 {
                return None;
            }
            for _ in 0..4 {
                self.bisect();
            }
        }
        None
    }

    /// The sign of `a` at `theta`: -1, 0 or 1, exactly. Narrows the
    /// isolating interval until an enclosure of `a` leaves 0: in floating
    /// point first (a filter: its bounds are rigorous), then exactly.
    pub fn sign(&self, a: &FieldElem) -> i32 {
        if a.is_zero() {
            return 0;
        }
        if let Some(r) = a.as_rat() {
            return r.signum();
        }
        if let Some(s) = self.float_sign(a) {
            return s;
        }
        // Exactly: the sign of the integer polynomial of `a` on an interval
        // of `theta` that holds none of its roots (Sturm's count). Before
        // each count, a floating-point filter on `a` scaled by a power of
        // two, which keeps huge coefficients in range and the sign as it
        // is: an enclosure of the polynomial over the whole interval that
        // leaves 0 means no root there, what the count would find at the
        // same interval, so the interval is narrowed exactly as far.
        let scaled = scaled_coefficients(&a.coeffs);
        let g = UPoly::new(over_common_denominator(&a.coeffs).0);
        let mut sturm: Option<crate::SturmSequence> = None;
        for _ in 0..MAX_REFINEMENTS {
            let (lo, hi) = self.interval();
            if lo == hi {
                return g.sign_at(&lo);
            }
            match scaled.as_ref().and_then(|c| horner_enclosure(c, &lo, &hi)) {
                Some((l, _)) if l > 0.0 => return 1,
                Some((_, h)) if h < 0.0 => return -1,
                _ => {}
            }
            let sturm = sturm.get_or_insert_with(|| crate::SturmSequence::new(&g));
            // Roots in (lo, hi]; hi itself is no root of an irreducible
            // defining polynomial's field element unless it is theta.
            if sturm.count_in(&lo, &hi) == 0 && g.sign_at(&lo) != 0 {
                return g.sign_at(&hi);
            }
            self.bisect();
        }
        // Unreachable short of astronomically many bits: an element that
        // is not zero in the field is not zero at theta.
        g.sign_at(&mid(&self.interval().0, &self.interval().1))
    }

    /// `a` at `theta` to about double precision.
    pub fn to_f64(&self, a: &FieldElem) -> f64 {
        if let Some(r) = a.as_rat() {
            return r.to_f64();
        }
        for _ in 0..200 {
            let (lo, hi) = self.enclosure(a);
            let (l, h) = (lo.to_f64(), hi.to_f64());
            if l == h || (h - l).abs() <= 1e-17 * l.abs().max(h.abs()) {
                return 0.5 * (l + h);
            }
            for _ in 0..8 {
                self.bisect();
            }
        }
        let (lo, hi) = self.enclosure(a);
        mid(&lo, &hi).to_f64()
    }

    /// `a` as a polynomial in `var` (for printing and storing).
    pub fn to_poly(&self, a: &FieldElem, var: &str) -> Poly {
        let coeffs: Vec<Poly> = a.coeffs.iter().map(|c| Poly::constant(c.clone())).collect();
        Poly::from_coeffs_in(var, &coeffs)
    }

    /// `a` as text in `var`.
    pub fn to_text(&self, a: &FieldElem, var: &str) -> String {
        self.to_poly(a, var).to_string()
    }

    /// The element a polynomial in `var` alone stands for (reduced modulo
    /// the defining polynomial); `None` if it has another variable.
    pub fn element_of(&self, p: &Poly, var: &str) -> Option<FieldElem> {
        if p.vars().iter().any(|v| v != var) {
            return None;
        }
        let coeffs = p.coeffs_in(var);
        Some(
            self.element(
                coeffs
                    .iter()
                    .map(|c| c.as_constant().unwrap_or(Rat::ZERO))
                    .collect(),
            ),
        )
    }

    /// The polynomial `p` in `keep` over the field, every other variable
    /// replaced by its value in `point`; `Err` names a variable without
    /// one.
    ///
    /// ```
    /// use poly::{Poly, RealField, UPoly};
    /// use std::collections::BTreeMap;
    /// let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
    /// let p: Poly = "a*x^2 - 2*x + a".parse().unwrap();
    /// let f = k.univariate(&p, "x", &BTreeMap::from([("a".to_string(), k.generator())])).unwrap();
    /// assert_eq!(f.degree(), Some(2)); // sqrt(2) x^2 - 2x + sqrt(2): a double root at 1/sqrt(2)
    /// ```
    pub fn univariate(
        &self,
        p: &Poly,
        keep: &str,
        point: &BTreeMap<String, FieldElem>,
    ) -> Result<FieldPoly, String> {
        let vars = p.vars();
        let k = vars.iter().position(|v| v == keep);
        // Powers of each variable's value, up to its degree, each as an
        // integer polynomial in theta over a denominator.
        let mut powers: Vec<Vec<(UPoly, Int)>> = Vec::with_capacity(vars.len());
        for (i, v) in vars.iter().enumerate() {
            if Some(i) == k {
                powers.push(Vec::new());
                continue;
            }
            let value = point.get(v).ok_or_else(|| v.clone())?;
            let d = p.degree(v) as usize;
            let mut pw = vec![self.one()];
            for j in 1..=d {
                pw.push(self.mul(&pw[j - 1], value));
            }
            powers.push(
                pw.iter()
                    .map(|e| {
                        let (num, den) = over_common_denominator(&e.coeffs);
                        (UPoly::new(num), den)
                    })
                    .collect(),
            );
        }
        // Each term and each coefficient's sum over the integers, reduced
        // by the defining polynomial without a fraction, and brought into
        // lowest terms once per coefficient: a product and a sum of field
        // elements took a gcd per coefficient each, which was most of the
        // time of the large determinants evaluated at six masses.
        let lc = self.minimal.leading_coeff();
        let top = k.map_or(0, |k| p.degree(&vars[k]) as usize);
        let mut sums: Vec<(UPoly, Int)> = vec![(UPoly::zero(), Int::ONE); top + 1];
        for t in p.terms() {
            let mut num = UPoly::constant(t.coef.numer().clone());
            let mut den = t.coef.denom().clone();
            let mut at = 0usize;
            for (i, &e) in t.exps.iter().enumerate() {
                if Some(i) == k {
                    at = e as usize;
                } else if e > 0 {
                    let (pn, pd) = &powers[i][e as usize];
                    let (_, r, steps) = pseudo_div_raw(&(&num * pn), &self.minimal, false);
                    num = r;
                    den = &den * pd;
                    if steps > 0 {
                        den = &den * &lc.pow(steps);
                    }
                }
            }
            let (sum, sum_den) = &sums[at];
            sums[at] = if sum.is_zero() {
                (num, den)
            } else if *sum_den == den {
                (sum + &num, den)
            } else {
                let g = sum_den.gcd(&den);
                let (a, b) = (sum_den.div_exact(&g), den.div_exact(&g));
                (&sum.scale(&b) + &num.scale(&a), &a * &den)
            };
        }
        let coeffs = sums
            .iter()
            .map(|(num, den)| FieldElem::over(num, den))
            .collect();
        Ok(FieldPoly::new(coeffs))
    }

    /// The value of `p` (every variable given) in the field.
    pub fn eval(&self, p: &Poly, point: &BTreeMap<String, FieldElem>) -> Result<FieldElem, String> {
        let f = self.univariate(p, "", point)?;
        Ok(f.coeffs.first().cloned().unwrap_or_default())
    }

    /// `f(x)` at a rational `x`.
    pub fn eval_poly_at(&self, f: &FieldPoly, x: &Rat) -> FieldElem {
        let mut acc = self.zero();
        for c in f.coeffs.iter().rev() {
            acc = self.add(&self.scale(&acc, x), c);
        }
        acc
    }

    /// The sign of `f(x)` at a rational `x`.
    pub fn sign_at(&self, f: &FieldPoly, x: &Rat) -> i32 {
        self.sign(&self.eval_poly_at(f, x))
    }

    /// `f` divided by its leading coefficient (zero stays zero).
    pub fn monic(&self, f: &FieldPoly) -> FieldPoly {
        let Some(lc) = f.coeffs.last() else {
            return f.clone();
        };
        let Some(inv) = self.inv(lc) else {
            return f.clone();
        };
        FieldPoly::new(f.coeffs.iter().map(|c| self.mul(c, &inv)).collect())
    }

    /// `f * g`.
    pub fn poly_mul(&self, f: &FieldPoly, g: &FieldPoly) -> FieldPoly {
        if f.is_zero() || g.is_zero() {
            return FieldPoly::default();
        }
        let mut c = vec![self.zero(); f.coeffs.len() + g.coeffs.len() - 1];
        for (i, x) in f.coeffs.iter().enumerate() {
            for (j, y) in g.coeffs.iter().enumerate() {
                c[i + j] = self.add(&c[i + j], &self.mul(x, y));
            }
        }
        FieldPoly::new(c)
    }

    /// Quotient and remainder of `f` by a non-zero `g`.
    pub fn poly_div_rem(&self, f: &FieldPoly, g: &FieldPoly) -> Option<(FieldPoly, FieldPoly)> {
        let dg = g.degree()?;
        let inv = self.inv(&g.coeffs[dg])?;
        let mut r = f.coeffs.clone();
        let mut q = vec![self.zero(); f.coeffs.len().saturating_sub(dg)];
        while r.len() > dg && !r.is_empty() {
            let top = r.len() - 1;
            let c = self.mul(&r[top], &inv);
            if !c.is_zero() {
                for (i, gc) in g.coeffs.iter().enumerate() {
                    let at = top - dg + i;
                    r[at] = self.sub(&r[at], &self.mul(&c, gc));
                }
                q[top - dg] = c;
            }
            r.pop();
            while r.last().is_some_and(FieldElem::is_zero) {
                r.pop();
            }
        }
        Some((FieldPoly::new(q), FieldPoly::new(r)))
    }

    /// The monic gcd of `f` and `g` (zero when both are zero).
    pub fn poly_gcd(&self, f: &FieldPoly, g: &FieldPoly) -> FieldPoly {
        let (mut a, mut b) = (f.clone(), g.clone());
        while !b.is_zero() {
            let Some((_, r)) = self.poly_div_rem(&a, &b) else {
                break;
            };
            a = std::mem::replace(&mut b, self.monic(&r));
        }
        self.monic(&a)
    }

    /// `f / g` when `g` divides `f`.
    pub fn poly_div_exact(&self, f: &FieldPoly, g: &FieldPoly) -> Option<FieldPoly> {
        let (q, r) = self.poly_div_rem(f, g)?;
        r.is_zero().then_some(q)
    }

    /// The square-free decomposition `f = c * prod f_k^k` (Yun): the monic,
    /// pairwise coprime, non-constant `f_k` with their `k`, ascending.
    pub fn square_free(&self, f: &FieldPoly) -> Vec<(FieldPoly, u32)> {
        if f.is_constant() {
            return Vec::new();
        }
        let f = self.monic(f);
        let d = f.derivative();
        let mut a = self.poly_gcd(&f, &d);
        let mut b = self.poly_div_exact(&f, &a).unwrap_or_default();
        let mut c = self.poly_div_exact(&d, &a).unwrap_or_default();
        let mut out = Vec::new();
        let mut k = 1;
        loop {
            let bd = b.derivative();
            let diff = FieldPoly::new(
                (0..c.coeffs.len().max(bd.coeffs.len()))
                    .map(|i| {
                        let z = self.zero();
                        self.sub(
                            c.coeffs.get(i).unwrap_or(&z),
                            bd.coeffs.get(i).unwrap_or(&z),
                        )
                    })
                    .collect(),
            );
            a = self.poly_gcd(&b, &diff);
            if !a.is_constant() {
                out.push((a.clone(), k));
            }
            b = self.poly_div_exact(&b, &a).unwrap_or_default();
            if b.is_constant() {
                break;
            }
            c = self.poly_div_exact(&diff, &a).unwrap_or_default();
            k += 1;
        }
        out
    }

    /// The Sturm sequence of a square-free `f`: `f`, `f'`, then the negated
    /// remainders.
    fn sturm_chain(&self, f: &FieldPoly) -> Vec<FieldPoly> {
        let mut chain = vec![f.clone(), f.derivative()];
        loop {
            let n = chain.len();
            if chain[n - 1].is_zero() {
                chain.pop();
                break;
            }
            let Some((_, r)) = self.poly_div_rem(&chain[n - 2], &chain[n - 1]) else {
                break;
            };
            if r.is_zero() {
                break;
            }
            chain.push(FieldPoly::new(
                r.coeffs.iter().map(|c| self.neg(c)).collect(),
            ));
        }
        chain
    }

    fn variations(&self, chain: &[FieldPoly], x: &Rat) -> usize {
        let mut last = 0;
        let mut n = 0;
        for p in chain {
            let s = self.sign_at(p, x);
            if s != 0 {
                if last != 0 && s != last {
                    n += 1;
                }
                last = s;
            }
        }
        n
    }

    /// A power of two above the absolute value of every root of `f`
    /// (Cauchy's bound on the monic polynomial, from enclosures).
    fn root_bound(&self, f: &FieldPoly) -> Rat {
        // From floating-point enclosures where they exist: no inverse.
        let lead = &f.coeffs[f.coeffs.len() - 1];
        if self.sign(lead) != 0 {
            let enc: Option<Vec<(f64, f64)>> =
                f.coeffs.iter().map(|c| self.float_enclosure(c)).collect();
            if let Some(enc) = enc {
                let (l, h) = enc[enc.len() - 1];
                let low = l.abs().min(h.abs());
                let top = enc[..enc.len() - 1]
                    .iter()
                    .map(|(l, h)| l.abs().max(h.abs()))
                    .fold(0.0, f64::max);
                if low > 0.0 && l * h > 0.0 {
                    let bound = 1.0 + top / low * (1.0 + 1e-9);
                    if bound.is_finite() && bound < 1e300 {
                        let mut b = Rat::ONE;
                        let two = Rat::from(2);
                        let mut bf = 1.0;
                        while bf <= bound {
                            b = &b * &two;
                            bf *= 2.0;
                        }
                        return b;
                    }
                }
            }
        }
        let f = self.monic(f);
        let n = f.coeffs.len() - 1;
        let mut m = Rat::ZERO;
        for c in &f.coeffs[..n] {
            let (lo, hi) = self.enclosure(c);
            m = m.max(lo.abs()).max(hi.abs());
        }
        let mut b = Rat::ONE;
        let bound = &m + &Rat::ONE;
        while b <= bound {
            b = &b * &Rat::from(2);
        }
        b
    }

    /// Isolating intervals of the real roots of a square-free non-constant
    /// `f`, ascending: `(r, r)` for a rational root `r`, else `(lo, hi)`
    /// with one root inside, none at either end, never straddling 0.
    pub fn isolate_roots(&self, f: &FieldPoly) -> Vec<(Rat, Rat)> {
        if f.is_constant() {
            return Vec::new();
        }
        let chain = self.sturm_chain(f);
        let b = self.root_bound(f);
        let mut out = Vec::new();
        // (lo, hi] with its root count; 0 is the first split, so that no
        // interval straddles it.
        let mut stack = vec![(negated(&b), b.clone())];
        let mut first = true;
        while let Some((lo, hi)) = stack.pop() {
            let count = self
                .variations(&chain, &lo)
                .saturating_sub(self.variations(&chain, &hi));
            if count == 0 {
                continue;
            }
            // Endpoints are never roots: the bound is strict, and a split
            // point that is a root is cut out below.
            if count == 1 && !first {
                out.push((lo, hi));
                continue;
            }
            let m = if first { Rat::ZERO } else { mid(&lo, &hi) };
            first = false;
            if self.sign_at(f, &m) != 0 {
                stack.push((m.clone(), hi));
                stack.push((lo, m));
                continue;
            }
            // A rational root at the split point: kept exactly, and a
            // neighbourhood free of other roots cut out around it.
            out.push((m.clone(), m.clone()));
            let mut eps = &(&hi - &lo) / &Rat::from(4);
            loop {
                let (a, c) = (&m - &eps, &m + &eps);
                let clean = self.sign_at(f, &a) != 0
                    && self.sign_at(f, &c) != 0
                    && self
                        .variations(&chain, &a)
                        .saturating_sub(self.variations(&chain, &c))
                        == 1;
                if clean {
                    stack.push((c, hi));
                    stack.push((lo, a));
                    break;
                }
                eps = &eps / &Rat::from(2);
            }
        }
        out.sort();
        out
    }

    /// Isolating intervals `(lo, hi)` of the positive real roots of `f`,
    /// ascending, each holding exactly one root, a simple one, with `f`
    /// non-zero at both ends (a rational root too lies inside its interval). By Descartes' rule of signs on Moebius transforms of `f`
    /// (Vincent, Collins and Akritas), halving `(0, B)` for a root bound
    /// `B`: only additions, rational scalings and signs in the field, no
    /// division by a field element, so no growth of the field's numbers
    /// beyond the transforms' own. `None` for the zero polynomial, or
    /// where a positive root is multiple or lies closer to another than
    /// the halvings allowed resolve (an interval narrower than `B / 2^96`).
    ///
    /// ```
    /// use poly::{FieldPoly, RealField, UPoly};
    /// let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
    /// let t = k.generator();
    /// // (x - sqrt 2)(x - 1)(x + 3): the positive roots 1 and sqrt 2.
    /// let f = k.poly_mul(
    ///     &FieldPoly::new(vec![k.neg(&t), k.one()]),
    ///     &FieldPoly::new(vec![k.from_rat(&(-3).into()), k.from_rat(&2.into()), k.one()]),
    /// );
    /// let roots = k.positive_simple_roots(&f).unwrap();
    /// assert_eq!(roots.len(), 2);
    /// assert!(roots[0].0 <= 1.into() && roots[0].1 >= 1.into());
    /// let sq = k.poly_mul(&f, &f); // every root double: not isolated
    /// assert!(k.positive_simple_roots(&sq).is_none());
    /// ```
    pub fn positive_simple_roots(&self, f: &FieldPoly) -> Option<Vec<(Rat, Rat)>> {
        if f.is_zero() {
            return None;
        }
        // Roots at 0 divided out; the ends are checked against `f` itself.
        let v = f.coeffs.iter().take_while(|c| c.is_zero()).count();
        let g = FieldPoly::new(f.coeffs[v..].to_vec());
        if g.is_constant() {
            return Some(Vec::new());
        }
        let b = self.root_bound(&g);
        let d = g.coeffs.len() - 1;
        // h(x) = g(b x): the interval (a, a + w) is (0, 1) of h.
        let mut pw = Rat::ONE;
        let mut h = Vec::with_capacity(d + 1);
        for c in &g.coeffs {
            h.push(self.scale(c, &pw));
            pw = &pw * &b;
        }
        let mut out = Vec::new();
        let mut stack: Vec<(Vec<FieldElem>, Rat, Rat, usize)> = vec![(h, Rat::ZERO, b, 0)];
        while let Some((h, a, w, depth)) = stack.pop() {
            match self.descartes_01(&h) {
                0 => continue,
                1 => {
                    out.push((a.clone(), &a + &w));
                    continue;
                }
                _ => {}
            }
            if depth >= MAX_DESCARTES_DEPTH {
                return None;
            }
            // Split at 1/2, or just below it where that is a root: no end
            // of an interval is ever a root of `g`.
            let mut lambda = Rat::new(Int::ONE, Int::from(2));
            let mut j = 3;
            while self.sign(&self.eval_coeffs_at(&h, &lambda)) == 0 {
                lambda = &Rat::new(Int::ONE, Int::from(2)) - &Rat::from(2).pow(-j);
                j += 1;
            }
            let rest = &Rat::ONE - &lambda;
            // left(x) = h(lambda x), right(x) = h(lambda + (1 - lambda) x).
            let left = self.normalized(self.scaled_argument(&h, &lambda));
            let right = self.normalized(self.scaled_argument(&self.shifted(&h, &lambda), &rest));
            let m = &a + &(&w * &lambda);
            stack.push((right, m.clone(), &w * &rest, depth + 1));
            stack.push((left, a, &w * &lambda, depth + 1));
        }
        out.sort();
        // The first interval may start at 0, a root of `f` where `g` left
        // one out: moved off it, towards its own root.
        if v > 0 {
            if let Some(first) = out.first_mut() {
                let s_right_of_0 = self.sign(&g.coeffs[0]);
                while first.0.is_zero() {
                    let c = mid(&first.0, &first.1);
                    if self.sign_at(&g, &c) == s_right_of_0 {
                        first.0 = c;
                    } else {
                        first.1 = c;
                    }
                }
            }
        }
        Some(out)
    }

    /// `h(c)` for coefficients `h`, lowest first.
    fn eval_coeffs_at(&self, h: &[FieldElem], c: &Rat) -> FieldElem {
        h.iter()
            .rev()
            .fold(self.zero(), |acc, x| self.add(&self.scale(&acc, c), x))
    }

    /// The coefficients of `h(c x)`.
    fn scaled_argument(&self, h: &[FieldElem], c: &Rat) -> Vec<FieldElem> {
        let mut pw = Rat::ONE;
        h.iter()
            .map(|x| {
                let y = self.scale(x, &pw);
                pw = &pw * c;
                y
            })
            .collect()
    }

    /// The coefficients of `h(x + c)`.
    fn shifted(&self, h: &[FieldElem], c: &Rat) -> Vec<FieldElem> {
        let mut v = h.to_vec();
        let n = v.len();
        for i in 0..n.saturating_sub(1) {
            for j in (i..n - 1).rev() {
                v[j] = self.add(&v[j], &self.scale(&v[j + 1], c));
            }
        }
        v
    }

    /// `h` times a power of two that brings its largest coefficient near
    /// one: the roots and signs stay, and the transforms' values stay in
    /// the range of the floating-point filter of [`Self::sign`].
    fn normalized(&self, h: Vec<FieldElem>) -> Vec<FieldElem> {
        let m = h
            .iter()
            .filter_map(|c| self.float_enclosure(c))
            .map(|(l, u)| l.abs().max(u.abs()))
            .fold(0.0, f64::max);
        if !(m.is_finite() && m > 0.0) || (0.25..=4.0).contains(&m) {
            return h;
        }
        let e = m.log2().floor() as i32;
        let f = Rat::from(2).pow(-e);
        h.iter().map(|c| self.scale(c, &f)).collect()
    }

    /// Sign variations of `(x + 1)^n h(1 / (x + 1))`'s coefficients: a
    /// bound on the roots of `h` in `(0, 1)`, exact when 0 or 1.
    fn descartes_01(&self, h: &[FieldElem]) -> usize {
        let mut rev: Vec<FieldElem> = h.to_vec();
        rev.reverse();
        let t = self.shift_by_one(&rev);
        let mut last = 0;
        let mut n = 0;
        for c in &t {
            let s = self.sign(c);
            if s != 0 {
                if last != 0 && s != last {
                    n += 1;
                }
                last = s;
            }
        }
        n
    }

    /// `h(x + 1)`, coefficients lowest first.
    fn shift_by_one(&self, h: &[FieldElem]) -> Vec<FieldElem> {
        let mut v = h.to_vec();
        let n = v.len();
        for i in 0..n.saturating_sub(1) {
            for j in (i..n - 1).rev() {
                v[j] = self.add(&v[j], &v[j + 1]);
            }
        }
        v
    }

    /// All distinct real roots of all `polys`, ascending, each with its
    /// multiplicity in every polynomial (0 where it is not a root): the
    /// reading of [`crate::interleave_roots`] for polynomials over the
    /// field. Zero polynomials and constants contribute no roots.
    ///
    /// ```
    /// use poly::{FieldPoly, RealField, UPoly};
    /// let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
    /// let (t, one) = (k.generator(), k.one());
    /// // num = (x - sqrt 2)^2, den = (x - 1)(x - 3/2)
    /// let num = FieldPoly::new(vec![k.from_rat(&2.into()), k.scale(&t, &(-2).into()), one.clone()]);
    /// let den = FieldPoly::new(vec![k.from_rat(&"3/2".parse().unwrap()), k.from_rat(&"-5/2".parse().unwrap()), one]);
    /// let m: Vec<Vec<u32>> = k.interleave_roots(&[num, den]).into_iter().map(|r| r.multiplicities).collect();
    /// assert_eq!(m, vec![vec![0, 1], vec![2, 0], vec![0, 1]]); // 1 < sqrt 2 < 3/2
    /// ```
    pub fn interleave_roots(&self, polys: &[FieldPoly]) -> Vec<SharedRoot> {
        let decomps: Vec<Vec<(FieldPoly, u32)>> =
            polys.iter().map(|p| self.square_free(p)).collect();
        let mut s = FieldPoly::new(vec![self.one()]);
        for d in &decomps {
            for (f, _) in d {
                let g = self.poly_gcd(&s, f);
                let extra = self.poly_div_exact(f, &g).unwrap_or_else(|| f.clone());
                s = self.poly_mul(&s, &extra);
            }
        }
        self.isolate_roots(&s)
            .into_iter()
            .map(|(lo, hi)| {
                let multiplicities = decomps
                    .iter()
                    .map(|d| {
                        d.iter()
                            .find(|(f, _)| {
                                if lo == hi {
                                    self.sign_at(f, &lo) == 0
                                } else {
                                    self.sign_at(f, &lo) * self.sign_at(f, &hi) < 0
                                }
                            })
                            .map_or(0, |(_, k)| *k)
                    })
                    .collect();
                SharedRoot {
                    lo,
                    hi,
                    multiplicities,
                }
            })
            .collect()
    }

    /// The solution of the square system `a x = b` over the field, by
    /// Gaussian elimination; `None` if it is singular or not square.
    ///
    /// ```
    /// use poly::{RealField, UPoly};
    /// let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
    /// let (t, one) = (k.generator(), k.one());
    /// // x + y = 1, x - y = sqrt 2
    /// let x = k.solve(&[vec![one.clone(), one.clone()], vec![one.clone(), k.neg(&one)]], &[one.clone(), t]).unwrap();
    /// assert_eq!(k.to_text(&x[0], "theta"), "1/2*theta + 1/2");
    /// ```
    pub fn solve(&self, a: &[Vec<FieldElem>], b: &[FieldElem]) -> Option<Vec<FieldElem>> {
        let n = a.len();
        if b.len() != n || a.iter().any(|r| r.len() != n) {
            return None;
        }
        let mut m: Vec<Vec<FieldElem>> = a
            .iter()
            .zip(b)
            .map(|(r, v)| r.iter().cloned().chain([v.clone()]).collect())
            .collect();
        for col in 0..n {
            let p = (col..n).find(|&r| !m[r][col].is_zero())?;
            m.swap(col, p);
            let inv = self.inv(&m[col][col])?;
            for x in m[col][col..].iter_mut() {
                *x = self.mul(x, &inv);
            }
            let pivot = m[col].clone();
            for (r, row) in m.iter_mut().enumerate() {
                if r == col || row[col].is_zero() {
                    continue;
                }
                let f = row[col].clone();
                for (x, p) in row[col..].iter_mut().zip(&pivot[col..]) {
                    *x = self.sub(x, &self.mul(&f, p));
                }
            }
        }
        Some(m.into_iter().map(|r| r[n].clone()).collect())
    }
}

/// An `f64` interval holding the polynomial of the coefficient intervals
/// `coeffs` (lowest first) over `[lo, hi]`, by Horner's rule in interval
/// arithmetic with every bound pushed outwards past its rounding; `None`
/// where a number leaves the range of `f64`.
fn horner_enclosure(coeffs: &[(f64, f64)], lo: &Rat, hi: &Rat) -> Option<(f64, f64)> {
    let t = widened(lo.to_f64(), hi.to_f64())?;
    let mut acc = (0.0, 0.0);
    for c in coeffs.iter().rev() {
        let p = [acc.0 * t.0, acc.0 * t.1, acc.1 * t.0, acc.1 * t.1];
        let (pl, ph) = (
            p.iter().copied().fold(f64::INFINITY, f64::min),
            p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        let m = widened(pl, ph)?;
        acc = widened(m.0 + c.0, m.1 + c.1)?;
    }
    Some(acc)
}

/// The coefficients `c` divided by one power of two that brings the
/// largest near 1, as `f64` intervals (see [`horner_enclosure`]); `None`
/// for zero.
fn scaled_coefficients(c: &[Rat]) -> Option<Vec<(f64, f64)>> {
    let shift = c
        .iter()
        .filter(|r| !r.is_zero())
        .map(|r| r.numer().bits() as i64 - r.denom().bits() as i64)
        .max()?;
    c.iter()
        .map(|r| {
            let v = r.scaled_to_f64(shift);
            widened(v, v)
        })
        .collect()
}

/// The numerators of `c` over their least common denominator, and that
/// denominator (positive).
fn over_common_denominator(c: &[Rat]) -> (Vec<Int>, Int) {
    let den = c.iter().fold(Int::ONE, |acc, v| {
        if v.denom().is_one() || &acc == v.denom() {
            acc
        } else {
            acc.lcm(v.denom())
        }
    });
    let nums = c
        .iter()
        .map(|v| {
            if v.denom() == &den {
                v.numer().clone()
            } else {
                v.numer() * &den.div_exact(v.denom())
            }
        })
        .collect();
    (nums, den)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sqrt2() -> RealField {
        RealField::new(UPoly::from_i64s(&[-2, 0, 1]), Rat::from(1), Rat::from(2)).unwrap()
    }

    fn rat(s: &str) -> Rat {
        s.parse().unwrap()
    }

    #[test]
    fn fields_refuse_reducible_or_unisolated_polynomials() {
        let p = UPoly::from_i64s(&[-1, 0, 1]);
        assert_eq!(
            RealField::new(p, Rat::from(0), Rat::from(2)).unwrap_err(),
            FieldError::Reducible
        );
        let q = UPoly::from_i64s(&[-2, 0, 1]);
        assert_eq!(
            RealField::new(q.clone(), Rat::from(-2), Rat::from(2)).unwrap_err(),
            FieldError::NotIsolating
        );
        assert_eq!(
            RealField::new(q, Rat::from(2), Rat::from(3)).unwrap_err(),
            FieldError::NotIsolating
        );
        assert_eq!(
            RealField::new(UPoly::from_i64s(&[3]), Rat::from(0), Rat::from(1)).unwrap_err(),
            FieldError::Constant
        );
    }

    #[test]
    fn inverses_multiply_to_one() {
        // theta the real root of x^5 - x - 1 (irreducible): every element
        // times its inverse is one, and the sign matches the double value.
        let k = RealField::real_roots_of(&UPoly::from_i64s(&[-1, -1, 0, 0, 0, 1])).remove(0);
        assert_eq!(k.degree(), 5);
        let t = k.generator();
        let samples = [
            k.add(&t, &k.from_rat(&rat("-7/6"))),
            k.sub(&k.pow(&t, 3), &k.from_rat(&rat("3/2"))),
            k.add(&k.pow(&t, 4), &k.scale(&t, &rat("-2"))),
        ];
        let theta = k.theta_f64();
        let values = [
            theta - 7.0 / 6.0,
            theta.powi(3) - 1.5,
            theta.powi(4) - 2.0 * theta,
        ];
        for (a, v) in samples.iter().zip(values) {
            let inv = k.inv(a).unwrap();
            assert_eq!(k.mul(a, &inv), k.one());
            assert_eq!(k.sign(a), if v > 0.0 { 1 } else { -1 });
            assert!((k.to_f64(a) - v).abs() < 1e-12 * v.abs().max(1.0));
        }
    }

    /// `a * b mod minimal` by schoolbook rational arithmetic: the product,
    /// then long division by the defining polynomial over Q.
    fn product_over_q(minimal: &UPoly, a: &[Rat], b: &[Rat]) -> Vec<Rat> {
        let f: Vec<Rat> = minimal
            .coeffs()
            .iter()
            .map(|c| Rat::from_int(c.clone()))
            .collect();
        let n = f.len() - 1;
        let mut c = vec![Rat::ZERO; (a.len() + b.len()).saturating_sub(1)];
        for (i, x) in a.iter().enumerate() {
            for (j, y) in b.iter().enumerate() {
                c[i + j] = &c[i + j] + &(x * y);
            }
        }
        while c.len() > n {
            let q = &c[c.len() - 1] / &f[n];
            let base = c.len() - 1 - n;
            for (i, fi) in f.iter().enumerate() {
                c[base + i] = &c[base + i] - &(&q * fi);
            }
            c.pop();
        }
        while c.last().is_some_and(Rat::is_zero) {
            c.pop();
        }
        c
    }

    /// Dense rational polynomials, lowest first: the extended Euclidean
    /// algorithm over Q, the reference for [`RealField::inv`].
    fn rat_trim(mut v: Vec<Rat>) -> Vec<Rat> {
        while v.last().is_some_and(Rat::is_zero) {
            v.pop();
        }
        v
    }

    fn rat_mul(a: &[Rat], b: &[Rat]) -> Vec<Rat> {
        if a.is_empty() || b.is_empty() {
            return Vec::new();
        }
        let mut c = vec![Rat::ZERO; a.len() + b.len() - 1];
        for (i, x) in a.iter().enumerate() {
            for (j, y) in b.iter().enumerate() {
                c[i + j] = &c[i + j] + &(x * y);
            }
        }
        rat_trim(c)
    }

    fn rat_sub(a: &[Rat], b: &[Rat]) -> Vec<Rat> {
        let n = a.len().max(b.len());
        let z = Rat::ZERO;
        rat_trim(
            (0..n)
                .map(|i| a.get(i).unwrap_or(&z) - b.get(i).unwrap_or(&z))
                .collect(),
        )
    }

    fn rat_div_rem(a: &[Rat], b: &[Rat]) -> (Vec<Rat>, Vec<Rat>) {
        let db = b.len() - 1;
        let inv = b[db].recip();
        let mut r = rat_trim(a.to_vec());
        let mut q = vec![Rat::ZERO; r.len().saturating_sub(db)];
        while r.len() > db {
            let top = r.len() - 1;
            let c = &r[top] * &inv;
            for (i, v) in b.iter().enumerate() {
                let at = top - db + i;
                r[at] = &r[at] - &(&c * v);
            }
            q[top - db] = c;
            r.pop();
            r = rat_trim(r);
        }
        (rat_trim(q), r)
    }

    /// `1 / a` by the extended Euclidean algorithm over Q.
    fn inverse_over_q(k: &RealField, a: &FieldElem) -> Vec<Rat> {
        let mut m: Vec<Rat> = k
            .minimal()
            .coeffs()
            .iter()
            .map(|c| Rat::from_int(c.clone()))
            .collect();
        let lc = m.last().unwrap().clone();
        m.iter_mut().for_each(|c| *c = &*c / &lc);
        let (mut r0, mut s0) = (m, Vec::<Rat>::new());
        let (mut r1, mut s1) = (a.coeffs().to_vec(), vec![Rat::ONE]);
        while r1.len() > 1 {
            let (q, r) = rat_div_rem(&r0, &r1);
            let s = rat_sub(&s0, &rat_mul(&q, &s1));
            r0 = std::mem::replace(&mut r1, r);
            s0 = std::mem::replace(&mut s1, s);
        }
        let inv_c = r1[0].recip();
        s1.iter().map(|v| v * &inv_c).collect()
    }

    /// Defining polynomials for the property tests: 3x^5 - 2x - 2 and
    /// 2x^3 - 3 (Eisenstein at 2 and 3, not monic), and x^4 - 10x^2 + 1
    /// (sqrt 2 + sqrt 3, monic).
    fn test_minimal(which: usize) -> UPoly {
        [
            UPoly::from_i64s(&[-2, -2, 0, 0, 0, 3]),
            UPoly::from_i64s(&[-3, 0, 0, 2]),
            UPoly::from_i64s(&[1, 0, -10, 0, 1]),
        ][which]
            .clone()
    }

    /// The rationals `p / q`.
    fn rats(v: &[(i64, i64)]) -> Vec<Rat> {
        v.iter()
            .map(|&(p, q)| Rat::new(Int::from(p), Int::from(q)))
            .collect()
    }

    proptest::proptest! {
        /// Products over the integers (common denominators, division-free
        /// reduction by a defining polynomial that is not monic) agree
        /// with the product over Q reduced by long division, and with the
        /// product of the values at `theta`; inverses by pseudo-remainders
        /// over the integers with the extended Euclidean algorithm over Q.
        #[test]
        fn products_and_inverses_agree_with_rational_arithmetic(
            a in proptest::collection::vec((-60i64..60, 1i64..24), 0..6),
            b in proptest::collection::vec((-60i64..60, 1i64..24), 0..6),
            which in 0usize..3,
        ) {
            let minimal = test_minimal(which);
            let k = RealField::real_roots_of(&minimal).pop().unwrap();
            let (a, b) = (k.element(rats(&a)), k.element(rats(&b)));
            let p = k.mul(&a, &b);
            proptest::prop_assert_eq!(p.coeffs(), &product_over_q(&minimal, a.coeffs(), b.coeffs())[..]);
            if !a.is_zero() {
                let inv = k.inv(&a).unwrap();
                proptest::prop_assert_eq!(inv.coeffs(), &inverse_over_q(&k, &a)[..]);
                proptest::prop_assert_eq!(k.mul(&a, &inv), k.one());
            }
            let (x, y) = (k.to_f64(&a), k.to_f64(&b));
            proptest::prop_assert!((k.to_f64(&p) - x * y).abs() <= 1e-9 * (x * y).abs().max(1.0));
        }
    }

    /// `p` with the values of `point` substituted, every product and sum
    /// by the field's arithmetic: the reference for `univariate`.
    fn univariate_by_field_arithmetic(
        k: &RealField,
        p: &Poly,
        keep: &str,
        point: &BTreeMap<String, FieldElem>,
    ) -> FieldPoly {
        let vars = p.vars();
        let at_of = |t: &crate::poly::Term| {
            vars.iter()
                .position(|v| v == keep)
                .map_or(0, |i| t.exps[i] as usize)
        };
        let top = p.terms().iter().map(at_of).max().unwrap_or(0);
        let mut coeffs = vec![k.zero(); top + 1];
        for t in p.terms() {
            let mut m = k.from_rat(&t.coef);
            for (i, &e) in t.exps.iter().enumerate() {
                if vars[i] != keep {
                    m = k.mul(&m, &k.pow(&point[&vars[i]], e));
                }
            }
            coeffs[at_of(t)] = k.add(&coeffs[at_of(t)], &m);
        }
        FieldPoly::new(coeffs)
    }

    proptest::proptest! {
        /// A polynomial in three variables with two of them given values in
        /// a field (non-monic defining polynomials among them) and the
        /// third kept: the same polynomial over the field as by the field's
        /// own products and sums.
        #[test]
        fn substitution_over_the_integers_agrees_with_field_arithmetic(
            terms in proptest::collection::vec(
                ((-9i64..9, 1i64..7), 0u32..4, 0u32..4, 0u32..3), 1..12),
            a in proptest::collection::vec((-30i64..30, 1i64..12), 0..5),
            b in proptest::collection::vec((-30i64..30, 1i64..12), 0..5),
            which in 0usize..3,
        ) {
            let minimal = test_minimal(which);
            let k = RealField::real_roots_of(&minimal).pop().unwrap();
            let text: Vec<String> = terms
                .iter()
                .map(|((p, q), ex, ey, ez)| format!("({p}/{q})*x^{ex}*y^{ey}*z^{ez}"))
                .collect();
            let p: Poly = text.join(" + ").parse().unwrap();
            let point: BTreeMap<String, FieldElem> = [
                ("x".to_string(), k.element(rats(&a))),
                ("y".to_string(), k.element(rats(&b))),
            ]
            .into_iter()
            .collect();
            let got = k.univariate(&p, "z", &point).unwrap();
            let want = univariate_by_field_arithmetic(&k, &p, "z", &point);
            proptest::prop_assert_eq!(got.coeffs(), want.coeffs());
        }
    }

    /// The sign as it was decided before the scaled floating-point filter:
    /// the floating-point phase, then Sturm's count at every step.
    fn sign_by_sturm_alone(k: &RealField, a: &FieldElem) -> i32 {
        if let Some(r) = a.as_rat() {
            return r.signum();
        }
        if let Some(s) = k.float_sign(a) {
            return s;
        }
        let g = UPoly::new(over_common_denominator(a.coeffs()).0);
        let sturm = crate::SturmSequence::new(&g);
        loop {
            let (lo, hi) = k.interval();
            if lo == hi {
                return g.sign_at(&lo);
            }
            if sturm.count_in(&lo, &hi) == 0 && g.sign_at(&lo) != 0 {
                return g.sign_at(&hi);
            }
            k.bisect();
        }
    }

    proptest::proptest! {
        /// Elements whose coefficients leave the range of f64 (scaled by
        /// 2^1100, alone or next to a rational a hair from a value of
        /// theta's powers): the same sign as Sturm's count alone, and the
        /// isolating interval narrowed exactly as far, so that every later
        /// reading of the field starts from the same interval.
        #[test]
        fn huge_elements_get_the_sign_and_interval_of_sturms_count(
            a in proptest::collection::vec((-60i64..60, 1i64..24), 1..6),
            which in 0usize..3,
            huge in proptest::bool::ANY,
            hair in 0usize..3,
        ) {
            let minimal = test_minimal(which);
            let field = || RealField::real_roots_of(&minimal).pop().unwrap();
            let (k, reference, probe) = (field(), field(), field());
            let scale = if huge { Rat::from_int(Int::from(2).pow(1100)) } else { Rat::ONE };
            let unscaled = rats(&a);
            let mut e = k.element(unscaled.iter().map(|c| c * &scale).collect());
            // Minus a rational a hair from its value (10^-8 or 10^-16): from
            // an easy sign to one that needs Sturm's count.
            if hair > 0 {
                let digits = Int::from(10).pow(8 * hair as u32);
                let v = Rat::from_f64(probe.to_f64(&probe.element(unscaled))).unwrap();
                let near = Rat::new((&v * &Rat::from_int(digits.clone())).floor(), digits);
                e = k.sub(&e, &k.from_rat(&(&near * &scale)));
            }
            proptest::prop_assert_eq!(k.sign(&e), sign_by_sturm_alone(&reference, &e));
            proptest::prop_assert_eq!(k.interval(), reference.interval());
        }
    }

    #[test]
    fn a_sign_at_a_hair_from_zero_is_exact() {
        // sqrt(2) - 1414213562373095/10^15 is about 4.9e-17: beyond f64's
        // resolution of sqrt(2), still decided.
        let k = sqrt2();
        let near = rat("1414213562373095/1000000000000000");
        let e = k.sub(&k.generator(), &k.from_rat(&near));
        assert_eq!(k.sign(&e), 1);
        let e = k.sub(
            &k.generator(),
            &k.from_rat(&rat("1414213562373096/1000000000000000")),
        );
        assert_eq!(k.sign(&e), -1);
    }

    /// `prod (x - r)` over the field.
    fn from_roots(k: &RealField, roots: &[FieldElem]) -> FieldPoly {
        let mut p = FieldPoly::new(vec![k.one()]);
        for r in roots {
            p = k.poly_mul(&p, &FieldPoly::new(vec![k.neg(r), k.one()]));
        }
        p
    }

    #[test]
    fn planted_roots_are_read_back_in_order_with_multiplicities() {
        let k = sqrt2();
        let t = k.generator();
        let q = |s: &str| k.from_rat(&rat(s));
        // num: (x - sqrt2)^2 (x - 3/2) (x + sqrt2), den: (x - 1)(x - (sqrt2 + 1/100))(x - 3/2)^0
        let num = from_roots(&k, &[t.clone(), t.clone(), q("3/2"), k.neg(&t)]);
        let den = from_roots(&k, &[q("1"), k.add(&t, &q("1/100")), q("0")]);
        let roots = k.interleave_roots(&[num, den]);
        let read: Vec<((f64, f64), Vec<u32>)> = roots
            .iter()
            .map(|r| ((r.lo.to_f64(), r.hi.to_f64()), r.multiplicities.clone()))
            .collect();
        let s = 2f64.sqrt();
        let want = [
            (-s, vec![1, 0]),
            (0.0, vec![0, 1]),
            (1.0, vec![0, 1]),
            (s, vec![2, 0]),
            (s + 0.01, vec![0, 1]),
            (1.5, vec![1, 0]),
        ];
        assert_eq!(read.len(), want.len());
        for (((lo, hi), m), (wx, wm)) in read.iter().zip(want.iter()) {
            assert_eq!(m, wm);
            assert!(lo <= wx && wx <= hi, "{wx} not in [{lo}, {hi}]");
        }
        // A root at 0 is found exactly (0 is the first split); no interval
        // straddles 0.
        assert!(roots[1].is_exact());
        assert!(roots
            .iter()
            .all(|r| r.is_exact() || r.lo.signum() * r.hi.signum() >= 0));
    }

    #[test]
    fn degree_one_fields_agree_with_the_rational_reading() {
        // Q itself, as the field of the root 2/3 of 3x - 2: the reading over
        // the field equals interleave_roots over Z.
        let k = RealField::new(UPoly::from_i64s(&[-2, 3]), rat("2/3"), rat("2/3")).unwrap();
        let num = UPoly::from_i64s(&[6, -5, 1]); // (x - 2)(x - 3)
        let den = UPoly::from_i64s(&[0, -1, 0, 1]); // x (x - 1)(x + 1)
        let lift = |u: &UPoly| {
            FieldPoly::new(
                u.coeffs()
                    .iter()
                    .map(|c| k.from_rat(&Rat::from_int(c.clone())))
                    .collect(),
            )
        };
        let over_k = k.interleave_roots(&[lift(&num), lift(&den)]);
        let over_q = crate::interleave_roots(&[num, den]);
        let m = |v: &[SharedRoot]| {
            v.iter()
                .map(|r| r.multiplicities.clone())
                .collect::<Vec<_>>()
        };
        assert_eq!(m(&over_k), m(&over_q));
    }

    #[test]
    fn gcd_and_square_free_parts_over_the_field() {
        let k = sqrt2();
        let t = k.generator();
        let a = from_roots(&k, &[t.clone(), k.from_rat(&rat("5"))]);
        let b = from_roots(&k, &[t.clone(), k.neg(&t)]);
        assert_eq!(k.poly_gcd(&a, &b), from_roots(&k, std::slice::from_ref(&t)));
        let f = from_roots(&k, &[t.clone(), t.clone(), t.clone(), k.one(), k.one()]);
        let sf = k.square_free(&f);
        assert_eq!(
            sf,
            vec![(from_roots(&k, &[k.one()]), 2), (from_roots(&k, &[t]), 3)]
        );
    }

    #[test]
    fn simple_positive_roots_by_descartes() {
        // Roots 1/2 (met at a midpoint), 1, sqrt 2, 3 and -1: positives
        // in order, simple, each interval holding its root with no root at
        // an end; a double root refuses.
        let k = sqrt2();
        let t = k.generator();
        let q = |s: &str| k.from_rat(&rat(s));
        let f = from_roots(&k, &[q("1/2"), q("1"), t.clone(), q("3"), q("-1")]);
        let roots = k.positive_simple_roots(&f).unwrap();
        let want = [0.5, 1.0, 2f64.sqrt(), 3.0];
        assert_eq!(roots.len(), 4);
        for ((lo, hi), w) in roots.iter().zip(want) {
            assert!(lo.to_f64() <= w && w <= hi.to_f64());
            if lo != hi {
                assert!(k.sign_at(&f, lo) * k.sign_at(&f, hi) < 0);
            }
        }
        let g = from_roots(&k, &[t.clone(), t, q("2")]);
        assert!(k.positive_simple_roots(&g).is_none());
    }

    #[test]
    fn linear_systems_solve_exactly() {
        let k = RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 0, 1])).remove(0);
        let t = k.generator();
        let a = vec![
            vec![t.clone(), k.one(), k.zero()],
            vec![k.one(), k.pow(&t, 2), k.one()],
            vec![k.zero(), k.one(), k.one()],
        ];
        // det = theta^3 - theta - 1 = 1 - theta, non-zero.
        let x = vec![k.one(), k.neg(&t), k.from_rat(&rat("1/3"))];
        let b: Vec<FieldElem> = a
            .iter()
            .map(|r| {
                r.iter()
                    .zip(&x)
                    .fold(k.zero(), |acc, (c, v)| k.add(&acc, &k.mul(c, v)))
            })
            .collect();
        assert_eq!(k.solve(&a, &b).unwrap(), x);
        let singular = vec![
            vec![k.one(), t.clone()],
            vec![t.clone(), k.from_rat(&rat("2"))],
        ];
        // det = 2 - theta^2, non-zero for the cube root of 2.
        assert!(k.solve(&singular, &[k.one(), k.one()]).is_some());
        let really = vec![vec![k.one(), t.clone()], vec![t.clone(), k.pow(&t, 2)]];
        assert!(k.solve(&really, &[k.one(), k.one()]).is_none());
    }
}
