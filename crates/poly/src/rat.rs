//! Exact rational numbers over [`Int`].

use crate::int::Int;
use std::cmp::Ordering;
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};
use std::str::FromStr;

/// An exact rational number `num/den` in lowest terms with `den > 0`.
///
/// ```
/// use poly::Rat;
/// let a: Rat = "3/4".parse().unwrap();
/// let b = Rat::from(1) / Rat::from(4);
/// assert_eq!((&a + &b).to_string(), "1");
/// assert!(a > b);
/// ```
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Rat {
    num: Int,
    den: Int,
}

/// Error when parsing a [`Rat`] from text.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid rational number {0:?}")]
pub struct ParseRatError(pub String);

impl Rat {
    /// Zero.
    pub const ZERO: Rat = Rat {
        num: Int::ZERO,
        den: Int::ONE,
    };
    /// One.
    pub const ONE: Rat = Rat {
        num: Int::ONE,
        den: Int::ONE,
    };

    /// `num/den`, reduced. Panics if `den` is zero.
    pub fn new(num: Int, den: Int) -> Rat {
        assert!(!den.is_zero(), "zero denominator");
        if den.is_one() {
            return Rat { num, den };
        }
        let g = num.gcd(&den);
        let (mut n, mut d) = if g.is_one() {
            (num, den)
        } else {
            (num.div_exact(&g), den.div_exact(&g))
        };
        if d.is_negative() {
            n = -n;
            d = -d;
        }
        Rat { num: n, den: d }
    }

    /// An integer as a rational.
    pub fn from_int(n: Int) -> Rat {
        Rat {
            num: n,
            den: Int::ONE,
        }
    }

    /// Numerator (carries the sign).
    pub fn numer(&self) -> &Int {
        &self.num
    }

    /// Denominator (always > 0).
    pub fn denom(&self) -> &Int {
        &self.den
    }

    /// True for zero.
    pub fn is_zero(&self) -> bool {
        self.num.is_zero()
    }

    /// True for one.
    pub fn is_one(&self) -> bool {
        self.num.is_one() && self.den.is_one()
    }

    /// True when the denominator is 1.
    pub fn is_integer(&self) -> bool {
        self.den.is_one()
    }

    /// -1, 0 or 1.
    pub fn signum(&self) -> i32 {
        self.num.signum()
    }

    /// Absolute value.
    pub fn abs(&self) -> Rat {
        Rat {
            num: self.num.abs(),
            den: self.den.clone(),
        }
    }

    /// Multiplicative inverse. Panics on zero.
    pub fn recip(&self) -> Rat {
        Rat::new(self.den.clone(), self.num.clone())
    }

    /// `self^e` for a signed exponent (a negative exponent inverts).
    pub fn pow(&self, e: i32) -> Rat {
        let r = Rat {
            num: self.num.pow(e.unsigned_abs()),
            den: self.den.pow(e.unsigned_abs()),
        };
        if e < 0 {
            r.recip()
        } else {
            r
        }
    }

    /// Nearest `f64`, computed without overflowing for huge numerators and
    /// denominators.
    pub fn to_f64(&self) -> f64 {
        let (n, d) = (self.num.to_f64(), self.den.to_f64());
        if n.is_finite() && d.is_finite() && n.abs() < 9.0e15 && d < 9.0e15 {
            return n / d;
        }
        self.scaled_to_f64(0)
    }

    /// `self * 2^-shift` as `f64`, for any size of numerator and
    /// denominator: an integer quotient of 62 to 64 bits (truncated:
    /// relative error below 2^-61) rounded to `f64`, then the power of two
    /// in steps that stay in range (0 or a subnormal where it underflows).
    pub(crate) fn scaled_to_f64(&self, shift: i64) -> f64 {
        if self.num.is_zero() {
            return 0.0;
        }
        let k = self.den.bits() as i64 - self.num.bits() as i64 + 64;
        let (nb, db) = (self.num.to_big(), self.den.to_big());
        let q = if k >= 0 {
            (nb << (k as u64)) / db
        } else {
            nb / (db << ((-k) as u64))
        };
        let mut v = Int::from(q).to_f64();
        let mut e = -k - shift;
        while e > 1000 {
            v *= 2f64.powi(1000);
            e -= 1000;
        }
        while e < -1000 {
            v *= 2f64.powi(-1000);
            e += 1000;
        }
        v * 2f64.powi(e as i32)
    }

    /// The exact value of a finite `f64`. Returns `None` for NaN or infinity.
    pub fn from_f64(x: f64) -> Option<Rat> {
        if !x.is_finite() {
            return None;
        }
        if x == 0.0 {
            return Some(Rat::ZERO);
        }
        let bits = x.to_bits();
        let sign = if bits >> 63 == 1 { -1i64 } else { 1 };
        let exp = ((bits >> 52) & 0x7ff) as i32;
        let frac = bits & ((1u64 << 52) - 1);
        let (mant, e) = if exp == 0 {
            (frac, -1074)
        } else {
            (frac | (1u64 << 52), exp - 1075)
        };
        let m = Int::from(mant as i64 * sign);
        Some(if e >= 0 {
            Rat::from_int(&m * &Int::from(2).pow(e as u32))
        } else {
            Rat::new(m, Int::from(2).pow((-e) as u32))
        })
    }

    /// A dyadic rational `q / 2^e` at or below `self`, within a relative
    /// `2^(2 - bits)` of it (`q` has about `bits` bits): a short stand-in
    /// for a long rational. An integer of at most `bits` bits is kept.
    ///
    /// ```
    /// use poly::Rat;
    /// let third: Rat = "1/3".parse().unwrap();
    /// assert_eq!(third.round_to_bits(4).to_string(), "5/16"); // 0.0101b
    /// assert_eq!(Rat::from(5).round_to_bits(2).to_string(), "4");
    /// assert_eq!(Rat::from(-5).round_to_bits(2).to_string(), "-6");
    /// assert_eq!(Rat::from(5).round_to_bits(3).to_string(), "5");
    /// ```
    pub fn round_to_bits(&self, bits: u32) -> Rat {
        if self.is_zero() || (self.den.is_one() && self.num.bits() <= u64::from(bits)) {
            return self.clone();
        }
        // |self| * 2^e has about `bits` bits before the point.
        let e = i64::from(bits) - (self.num.bits() as i64 - self.den.bits() as i64) - 1;
        let power = Rat::from_int(Int::from(2).pow(e.unsigned_abs() as u32));
        let scaled = if e >= 0 { self * &power } else { self / &power };
        let q = Rat::from_int(scaled.floor());
        if e >= 0 {
            &q / &power
        } else {
            &q * &power
        }
    }

    /// Floor as an integer.
    pub fn floor(&self) -> Int {
        self.num.div_mod_floor(&self.den).0
    }
}

impl Default for Rat {
    fn default() -> Self {
        Rat::ZERO
    }
}

impl From<i64> for Rat {
    fn from(v: i64) -> Self {
        Rat::from_int(Int::from(v))
    }
}

impl From<i32> for Rat {
    fn from(v: i32) -> Self {
        Rat::from_int(Int::from(v))
    }
}

impl From<Int> for Rat {
    fn from(v: Int) -> Self {
        Rat::from_int(v)
    }
}

impl FromStr for Rat {
    type Err = ParseRatError;
    /// Accepts `a`, `a/b` and decimals `a.b` (exactly, `0.1` = `1/10`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = || ParseRatError(s.to_string());
        let t = s.trim();
        if let Some((a, b)) = t.split_once('/') {
            let n: Int = a.trim().parse().map_err(|_| err())?;
            let d: Int = b.trim().parse().map_err(|_| err())?;
            if d.is_zero() {
                return Err(err());
            }
            return Ok(Rat::new(n, d));
        }
        if let Some((a, b)) = t.split_once('.') {
            if b.is_empty() || !b.bytes().all(|c| c.is_ascii_digit()) {
                return Err(err());
            }
            let neg = a.starts_with('-');
            let ip: Int = if a.is_empty() || a == "-" || a == "+" {
                Int::ZERO
            } else {
                a.parse().map_err(|_| err())?
            };
            let fp: Int = b.parse().map_err(|_| err())?;
            let scale = Int::from(10).pow(b.len() as u32);
            let frac = Rat::new(fp, scale);
            let ip = Rat::from_int(ip.abs());
            let v = &ip + &frac;
            return Ok(if neg { -v } else { v });
        }
        t.parse::<Int>().map(Rat::from_int).map_err(|_| err())
    }
}

impl Ord for Rat {
    fn cmp(&self, other: &Self) -> Ordering {
        if self.den == other.den {
            return self.num.cmp(&other.num);
        }
        (&self.num * &other.den).cmp(&(&other.num * &self.den))
    }
}

impl PartialOrd for Rat {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl fmt::Display for Rat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den.is_one() {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

impl fmt::Debug for Rat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl Add for &Rat {
    type Output = Rat;
    /// With the denominators' gcd `g` taken out first (Knuth, TAOCP
    /// 4.5.1): the sum is then in lowest terms after one more gcd, of the
    /// new numerator and `g` only, and needs none where `g = 1`.
    fn add(self, rhs: &Rat) -> Rat {
        if self.den.is_one() && rhs.den.is_one() {
            return Rat::from_int(&self.num + &rhs.num);
        }
        if self.den == rhs.den {
            return Rat::new(&self.num + &rhs.num, self.den.clone());
        }
        let g = self.den.gcd(&rhs.den);
        if g.is_one() {
            return Rat {
                num: &(&self.num * &rhs.den) + &(&rhs.num * &self.den),
                den: &self.den * &rhs.den,
            };
        }
        let (da, db) = (self.den.div_exact(&g), rhs.den.div_exact(&g));
        let t = &(&self.num * &db) + &(&rhs.num * &da);
        // Zero only for `rhs = -self`, whose denominators are equal.
        debug_assert!(!t.is_zero());
        let h = t.gcd(&g);
        if h.is_one() {
            Rat {
                num: t,
                den: &da * &rhs.den,
            }
        } else {
            Rat {
                num: t.div_exact(&h),
                den: &da * &rhs.den.div_exact(&h),
            }
        }
    }
}

impl Sub for &Rat {
    type Output = Rat;
    fn sub(self, rhs: &Rat) -> Rat {
        self + &(-rhs)
    }
}

impl Mul for &Rat {
    type Output = Rat;
    /// Each numerator's gcd with the other's denominator taken out first
    /// (Knuth, TAOCP 4.5.1): the product is then in lowest terms, and the
    /// gcds are of the smaller operands rather than of the product.
    fn mul(self, rhs: &Rat) -> Rat {
        if self.den.is_one() && rhs.den.is_one() {
            return Rat::from_int(&self.num * &rhs.num);
        }
        if self.num.is_zero() || rhs.num.is_zero() {
            return Rat::ZERO;
        }
        let g1 = self.num.gcd(&rhs.den);
        let g2 = rhs.num.gcd(&self.den);
        let part = |x: &Int, g: &Int| {
            if g.is_one() {
                x.clone()
            } else {
                x.div_exact(g)
            }
        };
        Rat {
            num: &part(&self.num, &g1) * &part(&rhs.num, &g2),
            den: &part(&self.den, &g2) * &part(&rhs.den, &g1),
        }
    }
}

impl Div for &Rat {
    type Output = Rat;
    /// Panics on division by zero.
    fn div(self, rhs: &Rat) -> Rat {
        assert!(!rhs.is_zero(), "division by zero");
        Rat::new(&self.num * &rhs.den, &self.den * &rhs.num)
    }
}

impl Neg for &Rat {
    type Output = Rat;
    fn neg(self) -> Rat {
        Rat {
            num: -&self.num,
            den: self.den.clone(),
        }
    }
}

impl Neg for Rat {
    type Output = Rat;
    fn neg(self) -> Rat {
        -(&self)
    }
}

macro_rules! forward_owned {
    ($($tr:ident $m:ident),*) => {$(
        impl $tr for Rat {
            type Output = Rat;
            fn $m(self, rhs: Rat) -> Rat { (&self).$m(&rhs) }
        }
        impl $tr<&Rat> for Rat {
            type Output = Rat;
            fn $m(self, rhs: &Rat) -> Rat { (&self).$m(rhs) }
        }
    )*};
}
forward_owned!(Add add, Sub sub, Mul mul, Div div);

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A fraction whose numerator and denominator are each a product of
    /// two parts, small, word-sized or the extremes of `i64`, so that
    /// numerators and denominators of one and two words, shared factors and
    /// the `i64` edges are all met.
    fn fraction() -> impl Strategy<Value = Rat> {
        let part = prop_oneof![
            -50i64..50,
            any::<i64>(),
            Just(i64::MIN),
            Just(i64::MAX),
            (1i64..1000).prop_map(|k| k * 6),
        ];
        (part.clone(), part.clone(), part.clone(), part).prop_map(|(a, b, c, d)| {
            let n = &Int::from(a) * &Int::from(b);
            let d = (&Int::from(c) * &Int::from(d)).abs();
            Rat::new(n, if d.is_zero() { Int::ONE } else { d })
        })
    }

    /// `x + y`, `x * y` and `x - y` against `Rat::new` of the schoolbook
    /// formulas.
    fn schoolbook(x: &Rat, y: &Rat) -> Result<(), TestCaseError> {
        let (a, b, c, d) = (x.numer(), x.denom(), y.numer(), y.denom());
        prop_assert_eq!(x + y, Rat::new(&(a * d) + &(c * b), b * d));
        prop_assert_eq!(x * y, Rat::new(a * c, b * d));
        prop_assert_eq!(x - y, Rat::new(&(a * d) - &(c * b), b * d));
        Ok(())
    }

    proptest! {
        /// The sum and product with the gcds taken out first are the
        /// fractions `Rat::new` reduces from the schoolbook formulas: for
        /// any two fractions, a fraction and its negative, two with equal
        /// denominators, and two whose denominators divide one another.
        #[test]
        fn sums_and_products_are_the_schoolbook_fractions_reduced(
            x in fraction(), y in fraction(), k in -1000i64..1000,
        ) {
            schoolbook(&x, &y)?;
            schoolbook(&x, &-&x)?;
            let same = Rat::new(&(y.numer() * x.denom()) + &Int::from(k), x.denom().clone());
            schoolbook(&x, &same)?;
            let finer = Rat::new(y.numer().clone(), x.denom() * y.denom());
            schoolbook(&x, &finer)?;
        }
    }

    #[test]
    fn parse_forms() {
        assert_eq!(
            "0.1".parse::<Rat>().unwrap(),
            Rat::new(Int::from(1), Int::from(10))
        );
        assert_eq!(
            "-2.50".parse::<Rat>().unwrap(),
            Rat::new(Int::from(-5), Int::from(2))
        );
        assert_eq!(
            "6/-4".parse::<Rat>().unwrap(),
            Rat::new(Int::from(-3), Int::from(2))
        );
        assert!("1/0".parse::<Rat>().is_err());
        assert!("abc".parse::<Rat>().is_err());
    }

    #[test]
    fn f64_roundtrip_is_exact() {
        for x in [0.1, -3.75, 1e-300, 6.02e23] {
            let r = Rat::from_f64(x).unwrap();
            assert_eq!(r.to_f64(), x);
        }
        assert!(Rat::from_f64(f64::NAN).is_none());
    }
}
