//! Arbitrary-precision integers with a machine-word fast path.
//!
//! [`Int`] keeps values that fit in an `i64` inline and only falls back to
//! [`num_bigint::BigInt`] when an operation overflows. Every operation is
//! exact: the fast path is an optimisation, never a source of rounding.

use num_bigint::{BigInt, Sign};
use num_integer::Integer;
use num_traits::{One, Signed, ToPrimitive, Zero};
use std::cmp::Ordering;
use std::fmt;
use std::ops::{Add, Mul, Neg, Sub};
use std::str::FromStr;

/// gcd(a, w) for a big `a` and a word `w`: one division, then words.
fn mixed_gcd(a: &num_bigint::BigUint, w: u64) -> Int {
    if w == 0 {
        return Int::from_big(BigInt::from(a.clone()));
    }
    let (mut x, mut y) = (w, (a % w).to_u64().expect("a remainder below a word"));
    while y != 0 {
        let t = x % y;
        x = y;
        y = t;
    }
    match i64::try_from(x) {
        Ok(v) => Int::Small(v),
        Err(_) => Int::Big(BigInt::from(x)),
    }
}

/// Stein's binary gcd in two machine words: big integers of up to 128 bits
/// are most of those the exact algebra meets, and num-bigint's gcd shifts
/// them as vectors of words.
fn binary_gcd_u128(mut a: u128, mut b: u128) -> u128 {
    if a == 0 || b == 0 {
        return a | b;
    }
    let shift = (a | b).trailing_zeros();
    a >>= a.trailing_zeros();
    loop {
        b >>= b.trailing_zeros();
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        b -= a;
        if b == 0 {
            return a << shift;
        }
    }
}

/// Lehmer's gcd (Knuth, TAOCP 4.5.2, Algorithm L): Euclid's quotients
/// found from the leading 64 bits, then applied to the whole numbers at
/// once, until both fit in two words. num-bigint's binary gcd shifts and
/// subtracts whole numbers bit by bit.
fn lehmer_gcd(a: &num_bigint::BigUint, b: &num_bigint::BigUint) -> num_bigint::BigUint {
    use num_bigint::BigUint;
    let (mut u, mut v) = if a >= b {
        (a.clone(), b.clone())
    } else {
        (b.clone(), a.clone())
    };
    while !v.is_zero() {
        if let (Some(x), Some(y)) = (u.to_u128(), v.to_u128()) {
            return BigUint::from(binary_gcd_u128(x, y));
        }
        let shift = u.bits() - 64;
        let lead = |w: &BigUint| i128::from((w >> shift).to_u64().expect("64 leading bits"));
        let (mut uh, mut vh) = (lead(&u), lead(&v));
        // u' = A u + B v and v' = C u + D v after the steps taken; a step
        // is taken only when both bounds of the quotient agree, so it is
        // Euclid's. The cofactors stay below 2^65 in magnitude.
        let (mut ca, mut cb, mut cc, mut cd) = (1i128, 0i128, 0i128, 1i128);
        while vh + cc > 0 && vh + cd > 0 && uh + ca >= 0 && uh + cb >= 0 {
            let q = (uh + ca) / (vh + cc);
            if q != (uh + cb) / (vh + cd) {
                break;
            }
            (ca, cc) = (cc, ca - q * cc);
            (cb, cd) = (cd, cb - q * cd);
            (uh, vh) = (vh, uh - q * vh);
        }
        if cb == 0 {
            let r = &u % &v;
            u = v;
            v = r;
        } else {
            let combine = |x: i128, y: i128| -> BigUint {
                let (px, py) = (&u * x.unsigned_abs(), &v * y.unsigned_abs());
                match (x >= 0, y >= 0) {
                    (true, false) => px - py,
                    (false, true) => py - px,
                    _ => px + py,
                }
            };
            let (nu, nv) = (combine(ca, cb), combine(cc, cd));
            u = nu;
            v = nv;
        }
    }
    u
}

/// An exact integer: `i64` while it fits, a big integer otherwise.
///
/// The representation is canonical (a value that fits in `i64` is always
/// `Small`), so derived equality and hashing are value equality.
///
/// ```
/// use poly::Int;
/// let a = Int::from(i64::MAX);
/// let b = &a + &Int::from(1);
/// assert_eq!(b.to_string(), "9223372036854775808");
/// assert_eq!(&b - &Int::from(1), a);
/// ```
#[derive(Clone, PartialEq, Eq, Hash)]
pub enum Int {
    /// A value in `i64` range.
    Small(i64),
    /// A value outside `i64` range.
    Big(BigInt),
}

impl Int {
    /// Zero.
    pub const ZERO: Int = Int::Small(0);
    /// One.
    pub const ONE: Int = Int::Small(1);

    fn from_big(b: BigInt) -> Int {
        match b.to_i64() {
            Some(v) => Int::Small(v),
            None => Int::Big(b),
        }
    }

    /// The value as a big integer.
    pub fn to_big(&self) -> BigInt {
        match self {
            Int::Small(v) => BigInt::from(*v),
            Int::Big(b) => b.clone(),
        }
    }

    /// As a big integer, borrowed where it is one: the arithmetic of a big
    /// operand then copies no digits.
    fn as_big(&self) -> std::borrow::Cow<'_, BigInt> {
        match self {
            Int::Small(v) => std::borrow::Cow::Owned(BigInt::from(*v)),
            Int::Big(b) => std::borrow::Cow::Borrowed(b),
        }
    }

    /// True for zero.
    pub fn is_zero(&self) -> bool {
        matches!(self, Int::Small(0))
    }

    /// True for one.
    pub fn is_one(&self) -> bool {
        matches!(self, Int::Small(1))
    }

    /// -1, 0 or 1.
    pub fn signum(&self) -> i32 {
        match self {
            Int::Small(v) => v.signum() as i32,
            Int::Big(b) => match b.sign() {
                Sign::Minus => -1,
                Sign::NoSign => 0,
                Sign::Plus => 1,
            },
        }
    }

    /// True for values < 0.
    pub fn is_negative(&self) -> bool {
        self.signum() < 0
    }

    /// Absolute value.
    pub fn abs(&self) -> Int {
        match self {
            Int::Small(v) => match v.checked_abs() {
                Some(a) => Int::Small(a),
                None => Int::Big(BigInt::from(*v).abs()),
            },
            Int::Big(b) => Int::from_big(b.abs()),
        }
    }

    /// Greatest common divisor, always >= 0; gcd(0, 0) = 0.
    pub fn gcd(&self, other: &Int) -> Int {
        match (self, other) {
            (Int::Small(a), Int::Small(b)) => {
                let (mut a, mut b) = (a.unsigned_abs(), b.unsigned_abs());
                while b != 0 {
                    let t = a % b;
                    a = b;
                    b = t;
                }
                if a <= i64::MAX as u64 {
                    Int::Small(a as i64)
                } else {
                    Int::Big(BigInt::from(a))
                }
            }
            (Int::Small(a), Int::Big(b)) | (Int::Big(b), Int::Small(a)) => {
                mixed_gcd(b.magnitude(), a.unsigned_abs())
            }
            (Int::Big(a), Int::Big(b)) => {
                match (a.magnitude().to_u128(), b.magnitude().to_u128()) {
                    (Some(x), Some(y)) => Int::from(binary_gcd_u128(x, y)),
                    _ => Int::from_big(BigInt::from(lehmer_gcd(a.magnitude(), b.magnitude()))),
                }
            }
        }
    }

    /// Least common multiple, always >= 0.
    pub fn lcm(&self, other: &Int) -> Int {
        if self.is_zero() || other.is_zero() {
            return Int::ZERO;
        }
        let g = self.gcd(other);
        (&self.div_exact(&g) * other).abs()
    }

    /// Quotient of an exact division. The caller guarantees `other | self`;
    /// in debug builds a non-zero remainder panics.
    pub fn div_exact(&self, other: &Int) -> Int {
        match (self, other) {
            (Int::Small(a), Int::Small(b)) => {
                debug_assert!(
                    *b != 0 && a.wrapping_rem(*b) == 0,
                    "inexact division {a}/{b}"
                );
                match a.checked_div(*b) {
                    Some(q) => Int::Small(q),
                    None => Int::from_big(BigInt::from(*a) / BigInt::from(*b)),
                }
            }
            _ => {
                let (q, r) = self.as_big().div_rem(&other.as_big());
                debug_assert!(r.is_zero(), "inexact division");
                Int::from_big(q)
            }
        }
    }

    /// Floor division and the matching non-negative remainder for `other > 0`
    /// (Euclidean for positive divisors).
    pub fn div_mod_floor(&self, other: &Int) -> (Int, Int) {
        match (self, other) {
            (Int::Small(a), Int::Small(b)) if *b != 0 && !(*a == i64::MIN && *b == -1) => {
                let (q, r) = a.div_mod_floor(b);
                (Int::Small(q), Int::Small(r))
            }
            _ => {
                let (q, r) = self.as_big().div_mod_floor(&other.as_big());
                (Int::from_big(q), Int::from_big(r))
            }
        }
    }

    /// Truncating division with remainder (remainder has the sign of `self`).
    pub fn div_rem(&self, other: &Int) -> (Int, Int) {
        match (self, other) {
            (Int::Small(a), Int::Small(b)) if *b != 0 && !(*a == i64::MIN && *b == -1) => {
                (Int::Small(a / b), Int::Small(a % b))
            }
            _ => {
                let (q, r) = self.as_big().div_rem(&other.as_big());
                (Int::from_big(q), Int::from_big(r))
            }
        }
    }

    /// `self` raised to `e`.
    pub fn pow(&self, e: u32) -> Int {
        let mut result = Int::ONE;
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

    /// Nearest `f64` (may be infinite for huge values).
    pub fn to_f64(&self) -> f64 {
        match self {
            Int::Small(v) => *v as f64,
            Int::Big(b) => b.to_f64().unwrap_or(if b.is_negative() {
                f64::NEG_INFINITY
            } else {
                f64::INFINITY
            }),
        }
    }

    /// The value as `i64` if it fits.
    pub fn to_i64(&self) -> Option<i64> {
        match self {
            Int::Small(v) => Some(*v),
            Int::Big(_) => None,
        }
    }

    /// Number of bits of the absolute value.
    pub fn bits(&self) -> u64 {
        match self {
            Int::Small(v) => 64 - v.unsigned_abs().leading_zeros() as u64,
            Int::Big(b) => b.bits(),
        }
    }

    /// Floor of the square root for `self >= 0`.
    pub fn isqrt(&self) -> Int {
        Int::from_big(self.to_big().sqrt())
    }

    /// Residue in `[0, m)` for a word-size modulus `m > 0`.
    pub fn rem_u64(&self, m: u64) -> u64 {
        match self {
            Int::Small(v) => (*v as i128).rem_euclid(m as i128) as u64,
            Int::Big(b) => {
                let r = b.mod_floor(&BigInt::from(m));
                r.to_u64().expect("residue fits")
            }
        }
    }
}

impl Default for Int {
    fn default() -> Self {
        Int::ZERO
    }
}

impl From<i64> for Int {
    fn from(v: i64) -> Self {
        Int::Small(v)
    }
}

impl From<i32> for Int {
    fn from(v: i32) -> Self {
        Int::Small(v as i64)
    }
}

impl From<u64> for Int {
    fn from(v: u64) -> Self {
        Int::from_big(BigInt::from(v))
    }
}

impl From<u128> for Int {
    fn from(v: u128) -> Self {
        match i64::try_from(v) {
            Ok(small) => Int::Small(small),
            Err(_) => Int::Big(BigInt::from(v)),
        }
    }
}

impl From<usize> for Int {
    fn from(v: usize) -> Self {
        Int::from_big(BigInt::from(v))
    }
}

impl From<BigInt> for Int {
    fn from(v: BigInt) -> Self {
        Int::from_big(v)
    }
}

impl FromStr for Int {
    type Err = num_bigint::ParseBigIntError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if let Ok(v) = s.parse::<i64>() {
            return Ok(Int::Small(v));
        }
        BigInt::from_str(s).map(Int::from_big)
    }
}

impl Ord for Int {
    fn cmp(&self, other: &Self) -> Ordering {
        match (self, other) {
            (Int::Small(a), Int::Small(b)) => a.cmp(b),
            _ => self.as_big().cmp(&other.as_big()),
        }
    }
}

impl PartialOrd for Int {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl fmt::Display for Int {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Int::Small(v) => write!(f, "{v}"),
            Int::Big(b) => write!(f, "{b}"),
        }
    }
}

impl fmt::Debug for Int {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl Add for &Int {
    type Output = Int;
    fn add(self, rhs: &Int) -> Int {
        if let (Int::Small(a), Int::Small(b)) = (self, rhs) {
            if let Some(s) = a.checked_add(*b) {
                return Int::Small(s);
            }
        }
        Int::from_big(&*self.as_big() + &*rhs.as_big())
    }
}

impl Sub for &Int {
    type Output = Int;
    fn sub(self, rhs: &Int) -> Int {
        if let (Int::Small(a), Int::Small(b)) = (self, rhs) {
            if let Some(s) = a.checked_sub(*b) {
                return Int::Small(s);
            }
        }
        Int::from_big(&*self.as_big() - &*rhs.as_big())
    }
}

impl Mul for &Int {
    type Output = Int;
    fn mul(self, rhs: &Int) -> Int {
        if let (Int::Small(a), Int::Small(b)) = (self, rhs) {
            if let Some(s) = a.checked_mul(*b) {
                return Int::Small(s);
            }
        }
        Int::from_big(&*self.as_big() * &*rhs.as_big())
    }
}

impl Neg for &Int {
    type Output = Int;
    fn neg(self) -> Int {
        match self {
            Int::Small(v) => match v.checked_neg() {
                Some(n) => Int::Small(n),
                None => Int::Big(-BigInt::from(*v)),
            },
            Int::Big(b) => Int::from_big(-b),
        }
    }
}

macro_rules! forward_owned {
    ($($tr:ident $m:ident),*) => {$(
        impl $tr for Int {
            type Output = Int;
            fn $m(self, rhs: Int) -> Int { (&self).$m(&rhs) }
        }
        impl $tr<&Int> for Int {
            type Output = Int;
            fn $m(self, rhs: &Int) -> Int { (&self).$m(rhs) }
        }
    )*};
}
forward_owned!(Add add, Sub sub, Mul mul);

impl Neg for Int {
    type Output = Int;
    fn neg(self) -> Int {
        -(&self)
    }
}

impl Zero for Int {
    fn zero() -> Self {
        Int::ZERO
    }
    fn is_zero(&self) -> bool {
        Int::is_zero(self)
    }
}

impl One for Int {
    fn one() -> Self {
        Int::ONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The word-sized shortcut for a big and a small operand agrees with
        /// num-bigint's gcd, for every sign and for operands sharing a
        /// factor (so that the gcd is not 1).
        #[test]
        fn gcd_of_big_and_small_matches_bigint(
            a in any::<i64>(), b in any::<i64>(), k in any::<i64>(), f in 1i64..1_000_000,
        ) {
            let big = &(&Int::from(a) * &Int::from(b)) * &Int::from(f);
            let small = &Int::from(k % 1_000_000_007) * &Int::from(f);
            let want = Int::from_big(big.to_big().gcd(&small.to_big()));
            prop_assert_eq!(big.gcd(&small), want.clone());
            prop_assert_eq!(small.gcd(&big), want);
        }
    }

    proptest! {
        /// Two big operands of up to 128 bits take the two-word path; it
        /// agrees with num-bigint's gcd, also when they share a factor.
        #[test]
        fn gcd_of_two_words_matches_bigint(
            a in any::<i64>(), b in any::<i64>(), c in any::<i64>(), d in any::<i64>(),
            f in 1i64..1_000_000_007,
        ) {
            let x = &(&Int::from(a) * &Int::from(b)) * &Int::from(f);
            let y = &(&Int::from(c) * &Int::from(d)) * &Int::from(f);
            let want = Int::from_big(x.to_big().gcd(&y.to_big()));
            prop_assert_eq!(x.gcd(&y), want.clone());
            prop_assert_eq!(y.gcd(&x), want);
        }
    }

    proptest! {
        /// Lehmer's gcd of big operands (up to eight words, with a shared
        /// factor of up to four) agrees with num-bigint's binary gcd.
        #[test]
        fn lehmer_gcd_matches_bigint(
            x in proptest::collection::vec(any::<u64>(), 1..8),
            y in proptest::collection::vec(any::<u64>(), 1..8),
            f in proptest::collection::vec(any::<u64>(), 0..4),
        ) {
            let big = |w: &[u64]| {
                w.iter().fold(num_bigint::BigUint::from(1u8), |acc, &d| (acc << 64) + d)
            };
            let g = big(&f);
            let (a, b) = (big(&x) * &g, big(&y) * &g);
            let want = a.gcd(&b);
            prop_assert_eq!(lehmer_gcd(&a, &b), want.clone());
            prop_assert_eq!(lehmer_gcd(&b, &a), want);
        }
    }

    #[test]
    fn overflow_promotes_and_demotes() {
        let m = Int::from(i64::MAX);
        let p = &m * &m;
        assert!(matches!(p, Int::Big(_)));
        let back = p.div_exact(&m);
        assert!(matches!(back, Int::Small(_)));
        assert_eq!(back, m);
        assert_eq!((-&Int::from(i64::MIN)).to_string(), "9223372036854775808");
        // i64::MIN / -1 is 2^63, one past i64: promoted, not an overflow
        // (a primitive part of a polynomial with content -1 hit this).
        let q = Int::from(i64::MIN).div_exact(&Int::from(-1));
        assert_eq!(q.to_string(), "9223372036854775808");
    }

    #[test]
    fn gcd_matches_bigint() {
        let a = Int::from(-48);
        let b = Int::from(180);
        assert_eq!(a.gcd(&b), Int::from(12));
        let big = Int::from(1u64 << 63).pow(3);
        assert_eq!(big.gcd(&Int::from(6)), Int::from(2));
        assert_eq!(
            Int::from(i64::MIN).gcd(&Int::ZERO).to_string(),
            "9223372036854775808"
        );
    }

    #[test]
    fn floor_division() {
        let (q, r) = Int::from(-7).div_mod_floor(&Int::from(2));
        assert_eq!((q, r), (Int::from(-4), Int::from(1)));
        assert_eq!(Int::from(-7).rem_u64(5), 3);
    }
}
