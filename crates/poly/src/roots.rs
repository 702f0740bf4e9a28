//! Exact real-root isolation for univariate polynomials over Z (hence Q).
//!
//! # Algorithm
//!
//! 1. Square-free decomposition `p = c * prod fi^mi` (Yun, [`UPoly::square_free`]);
//!    `s = prod fi` has the roots of `p`, each simple.
//! 2. The root 0 is split off; the positive roots of `s(x)` and of `s(-x)`
//!    are isolated separately in `(0, B)`, `B` a power of two above the
//!    Kioustelidis bound `2 * max_{a_{n-k} < 0} (|a_{n-k}| / a_n)^(1/k)`.
//! 3. Descartes' rule of signs with bisection (Vincent–Collins–Akritas):
//!    the sign variations of `(x + 1)^n q(1 / (x + 1))` bound the number of
//!    roots of `q` in `(0, 1)` and are exact when 0 or 1; otherwise the
//!    interval is halved (`2^n q(x/2)` and its Taylor shift by 1). A midpoint
//!    that is a root is reported exactly and divided out. The shifts run on
//!    fixed-width two's-complement limb arrays sized per node with headroom
//!    for the node's coefficient growth (exact, no allocation per addition).
//! 4. Isolating intervals with an endpoint that is a root (a rational root
//!    found as a midpoint, or 0) are shrunk by exact-sign bisection.
//! 5. The multiplicity of each root is the `mi` of the factor `fi` that
//!    vanishes there or changes sign across the interval.
//!
//! [`SturmSequence`], [`count_roots_in`] and [`count_real_roots`] count roots
//! by a Sturm sequence instead: an independent route, used by the tests to
//! check the isolation. It is much slower for large inputs (the chain's
//! coefficients grow to about `deg * bits` bits: ~0.1 s for degree 30 with
//! 500-bit coefficients, against ~1 ms for [`real_roots`]).
//!
//! ```
//! use poly::{real_roots, Rat, UPoly};
//! // (x^2 - 2) (3x - 1)^2
//! let p = &UPoly::from_i64s(&[-2, 0, 1]) * &UPoly::from_i64s(&[-1, 3]).pow(2);
//! let roots = real_roots(&p);
//! assert_eq!(roots.len(), 3);
//! assert_eq!(roots.iter().map(|r| r.multiplicity).collect::<Vec<_>>(), [1, 2, 1]);
//! let third: Rat = "1/3".parse().unwrap();
//! assert!(roots[1].lo < third && third < roots[1].hi);
//! assert!((roots[2].to_f64() - 2f64.sqrt()).abs() < 1.0);
//! ```

use crate::int::Int;
use crate::rat::Rat;
use crate::upoly::{gcd_pp, pseudo_div_raw, UPoly};
use num_bigint::BigInt;
use num_traits::{One, Signed, Zero};

/// A real root of a polynomial, isolated with rational endpoints.
///
/// Invariant: `lo == hi` means the root is exactly that rational; otherwise
/// `lo < hi`, the open interval `(lo, hi)` contains exactly one distinct real
/// root and neither endpoint is a root. Intervals produced by this module
/// never contain 0 in their interior.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct RealRoot {
    /// Lower endpoint.
    pub lo: Rat,
    /// Upper endpoint.
    pub hi: Rat,
    /// Multiplicity of the root in the polynomial.
    pub multiplicity: u32,
}

/// A real root of some of several polynomials (see [`interleave_roots`]).
///
/// Same interval invariant as [`RealRoot`], with respect to every
/// polynomial that has the root.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct SharedRoot {
    /// Lower endpoint.
    pub lo: Rat,
    /// Upper endpoint.
    pub hi: Rat,
    /// Multiplicity in each polynomial, in input order (0: not a root).
    pub multiplicities: Vec<u32>,
}

/// Why a root could not be refined.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RootError {
    /// The polynomial is zero: every number is a root.
    #[error("the zero polynomial has no isolated roots")]
    ZeroPolynomial,
    /// The requested width is zero or negative.
    #[error("the target width must be positive")]
    NonPositiveWidth,
    /// The interval does not isolate a root of the given polynomial.
    #[error("the interval does not isolate a root of the polynomial")]
    NotIsolating,
}

fn mid(lo: &Rat, hi: &Rat) -> Rat {
    let num = &(lo.numer() * hi.denom()) + &(hi.numer() * lo.denom());
    let den = &(lo.denom() * hi.denom()) * &Int::from(2);
    Rat::new(num, den)
}

/// Bisects `(lo, hi)`, where `q` changes sign and has one root, until
/// `done(lo, hi)`; a midpoint that is a root collapses the interval onto it.
fn bisect(q: &UPoly, lo: &mut Rat, hi: &mut Rat, mut done: impl FnMut(&Rat, &Rat) -> bool) {
    let s_lo = q.sign_at(lo);
    while lo != hi && !done(lo, hi) {
        let m = mid(lo, hi);
        let sm = q.sign_at(&m);
        if sm == 0 {
            *lo = m.clone();
            *hi = m;
            return;
        }
        if sm == s_lo {
            *lo = m;
        } else {
            *hi = m;
        }
    }
}

/// `s` with the linear factors of `lo` and `hi` divided out where they are
/// roots (`s` square-free, so once is enough).
fn strip_endpoint_roots(s: &UPoly, lo: &Rat, hi: &Rat) -> UPoly {
    let mut q = s.clone();
    for e in [lo, hi] {
        if q.sign_at(e) == 0 {
            if let Some(d) = q.div_exact(&UPoly::linear_root(e)) {
                q = d;
            }
        }
    }
    q
}

impl RealRoot {
    /// True when the root is known exactly (`lo == hi`).
    pub fn is_exact(&self) -> bool {
        self.lo == self.hi
    }

    /// The root if it is known exactly.
    pub fn exact(&self) -> Option<&Rat> {
        self.is_exact().then_some(&self.lo)
    }

    /// Width `hi - lo`.
    pub fn width(&self) -> Rat {
        &self.hi - &self.lo
    }

    /// Midpoint of the interval (the root itself when exact).
    pub fn midpoint(&self) -> Rat {
        mid(&self.lo, &self.hi)
    }

    /// Midpoint as `f64`: an approximation of the root within half the width
    /// (plus rounding).
    pub fn to_f64(&self) -> f64 {
        self.midpoint().to_f64()
    }

    /// True when the root is > 0 (relies on intervals not straddling 0).
    pub fn is_positive(&self) -> bool {
        self.lo.signum() >= 0 && self.hi.signum() > 0
    }

    /// True when the root is < 0 (relies on intervals not straddling 0).
    pub fn is_negative(&self) -> bool {
        self.hi.signum() <= 0 && self.lo.signum() < 0
    }

    /// Shrinks the interval by exact bisection until `hi - lo <= width` (or
    /// the root is found exactly). `p` is the polynomial the root was
    /// isolated from (any polynomial with exactly one distinct root in the
    /// interval works).
    ///
    /// ```
    /// use poly::{real_roots, Rat, UPoly};
    /// let p = UPoly::from_i64s(&[-2, 0, 1]); // x^2 - 2
    /// let mut r = real_roots(&p).pop().unwrap();
    /// let w: Rat = "1/1000000".parse().unwrap();
    /// r.refine(&p, &w).unwrap();
    /// assert!(r.width() <= w);
    /// assert!(p.sign_at(&r.lo) < 0 && p.sign_at(&r.hi) > 0);
    /// assert!((r.to_f64() - 2f64.sqrt()).abs() < 1e-6);
    /// ```
    pub fn refine(&mut self, p: &UPoly, width: &Rat) -> Result<(), RootError> {
        if p.is_zero() {
            return Err(RootError::ZeroPolynomial);
        }
        if width.signum() <= 0 {
            return Err(RootError::NonPositiveWidth);
        }
        if self.lo > self.hi {
            return Err(RootError::NotIsolating);
        }
        if self.lo == self.hi {
            return if p.sign_at(&self.lo) == 0 {
                Ok(())
            } else {
                Err(RootError::NotIsolating)
            };
        }
        let s = p.square_free_part();
        let endpoint_root = s.sign_at(&self.lo) == 0 || s.sign_at(&self.hi) == 0;
        if !endpoint_root && &self.width() <= width {
            return Ok(());
        }
        let q = if endpoint_root {
            strip_endpoint_roots(&s, &self.lo, &self.hi)
        } else {
            s.clone()
        };
        if q.sign_at(&self.lo) * q.sign_at(&self.hi) >= 0 {
            return Err(RootError::NotIsolating);
        }
        bisect(&q, &mut self.lo, &mut self.hi, |lo, hi| {
            &(hi - lo) <= width && (!endpoint_root || (s.sign_at(lo) != 0 && s.sign_at(hi) != 0))
        });
        Ok(())
    }
}

impl SharedRoot {
    /// True when the root is known exactly (`lo == hi`).
    pub fn is_exact(&self) -> bool {
        self.lo == self.hi
    }

    /// Midpoint of the interval (the root itself when exact).
    pub fn midpoint(&self) -> Rat {
        mid(&self.lo, &self.hi)
    }

    /// Midpoint as `f64`.
    pub fn to_f64(&self) -> f64 {
        self.midpoint().to_f64()
    }

    /// True when the root is > 0 (relies on intervals not straddling 0).
    pub fn is_positive(&self) -> bool {
        self.lo.signum() >= 0 && self.hi.signum() > 0
    }

    /// True when the root is < 0 (relies on intervals not straddling 0).
    pub fn is_negative(&self) -> bool {
        self.hi.signum() <= 0 && self.lo.signum() < 0
    }

    /// Shrinks the interval until `hi - lo <= width`, using one of `polys`
    /// (the slice given to [`interleave_roots`]) that has the root.
    pub fn refine(&mut self, polys: &[UPoly], width: &Rat) -> Result<(), RootError> {
        let Some(p) = self
            .multiplicities
            .iter()
            .zip(polys)
            .find(|(m, _)| **m > 0)
            .map(|(_, p)| p)
        else {
            return Err(RootError::NotIsolating);
        };
        let mut r = RealRoot {
            lo: self.lo.clone(),
            hi: self.hi.clone(),
            multiplicity: 1,
        };
        r.refine(p, width)?;
        self.lo = r.lo;
        self.hi = r.hi;
        Ok(())
    }
}

/// All distinct real roots of `p` in ascending order, with multiplicities.
///
/// Rational roots hit by the bisection are reported exactly (`lo == hi`);
/// other roots get disjoint isolating intervals with dyadic endpoints
/// (refine them with [`RealRoot::refine`]). Constants and the zero
/// polynomial give an empty list.
///
/// ```
/// use poly::{real_roots, Rat, UPoly};
/// // x^3 (x - 2)(x + 3)
/// let p = &UPoly::from_i64s(&[0, 0, 0, 1]) * &UPoly::from_i64s(&[-6, 1, 1]);
/// let r = real_roots(&p);
/// assert_eq!(r.len(), 3);
/// assert_eq!(r[1].exact(), Some(&Rat::ZERO));
/// assert_eq!(r[1].multiplicity, 3);
/// assert!(r[0].is_negative() && r[2].is_positive());
/// ```
pub fn real_roots(p: &UPoly) -> Vec<RealRoot> {
    roots_with(p, true)
}

/// The real roots of `p` that are > 0, ascending (see [`real_roots`]).
///
/// ```
/// use poly::{positive_roots, UPoly};
/// let p = UPoly::from_i64s(&[-6, 1, 1]); // (x - 2)(x + 3)
/// let r = positive_roots(&p);
/// assert_eq!(r.len(), 1);
/// assert!(r[0].lo <= 2.into() && r[0].hi >= 2.into());
/// ```
pub fn positive_roots(p: &UPoly) -> Vec<RealRoot> {
    roots_with(p, false)
        .into_iter()
        .filter(RealRoot::is_positive)
        .collect()
}

/// How many roots of `p`, counted with multiplicity, are not real and
/// positive: `deg p` minus the positive real roots. 0 for constants and the
/// zero polynomial.
///
/// ```
/// use poly::{count_nonpositive_or_nonreal, UPoly};
/// // (x^2 + 1)(x - 1)^2 x: 2 non-real, one at 0, a double positive root.
/// let p = &(&UPoly::from_i64s(&[1, 0, 1]) * &UPoly::from_i64s(&[1, -2, 1]))
///     * &UPoly::x();
/// assert_eq!(count_nonpositive_or_nonreal(&p), 3);
/// ```
pub fn count_nonpositive_or_nonreal(p: &UPoly) -> usize {
    let Some(deg) = p.degree() else {
        return 0;
    };
    let pos: usize = positive_roots(p)
        .iter()
        .map(|r| r.multiplicity as usize)
        .sum();
    deg.saturating_sub(pos)
}

fn roots_with(p: &UPoly, with_negative: bool) -> Vec<RealRoot> {
    let factors = p.square_free();
    if factors.is_empty() {
        return Vec::new();
    }
    let s = if factors.len() == 1 {
        factors[0].0.clone()
    } else {
        factors.iter().fold(UPoly::one(), |acc, (f, _)| &acc * f)
    };
    isolate_squarefree(&s, with_negative)
        .into_iter()
        .map(|(lo, hi)| {
            let multiplicity = if factors.len() == 1 {
                factors[0].1
            } else {
                multiplicity_in(&factors, &lo, &hi)
            };
            RealRoot {
                lo,
                hi,
                multiplicity,
            }
        })
        .collect()
}

/// Multiplicity of the root isolated by `[lo, hi]` (with respect to a
/// square-free multiple of all factors) in `prod fi^mi`; 0 if not a root.
fn multiplicity_in(factors: &[(UPoly, u32)], lo: &Rat, hi: &Rat) -> u32 {
    for (f, m) in factors {
        let hit = if lo == hi {
            f.sign_at(lo) == 0
        } else {
            f.sign_at(lo) * f.sign_at(hi) < 0
        };
        if hit {
            return *m;
        }
    }
    0
}

/// All distinct real roots of all `polys`, ascending, each with its
/// multiplicity in every polynomial (0 where it is not a root). The
/// intervals are disjoint, so the sequence gives the interleaving order of
/// the roots: for a transfer function `num/den` in `Omega`, the positive
/// entries read as antiresonances (roots of `num`) and resonances (roots of
/// `den`). Zero polynomials and constants contribute no roots.
///
/// ```
/// use poly::{interleave_roots, UPoly};
/// let num = UPoly::from_i64s(&[3, -4, 1]); // (x - 1)(x - 3)
/// let den = UPoly::from_i64s(&[0, 8, -6, 1]); // x (x - 2)(x - 4)
/// let order: String = interleave_roots(&[num, den])
///     .iter()
///     .map(|r| if r.multiplicities[0] > 0 { 'A' } else { 'R' })
///     .collect();
/// assert_eq!(order, "RARAR");
/// ```
pub fn interleave_roots(polys: &[UPoly]) -> Vec<SharedRoot> {
    let decomps: Vec<Vec<(UPoly, u32)>> = polys.iter().map(UPoly::square_free).collect();
    let mut s = UPoly::one();
    for d in &decomps {
        for (f, _) in d {
            let g = gcd_pp(&s, f);
            let extra = f.div_exact(&g).unwrap_or_else(|| f.clone());
            s = &s * &extra;
        }
    }
    if s.is_constant() {
        return Vec::new();
    }
    isolate_squarefree(&s, true)
        .into_iter()
        .map(|(lo, hi)| {
            let multiplicities = decomps
                .iter()
                .map(|d| multiplicity_in(d, &lo, &hi))
                .collect();
            SharedRoot {
                lo,
                hi,
                multiplicities,
            }
        })
        .collect()
}

/// Isolating intervals (or exact points) of the roots of a square-free,
/// non-constant `s`, ascending; negative roots only if `with_negative`.
fn isolate_squarefree(s: &UPoly, with_negative: bool) -> Vec<(Rat, Rat)> {
    let z = s.x_valuation();
    let core: Vec<BigInt> = s.coeffs()[z..].iter().map(Int::to_big).collect();
    let mut out = Vec::new();
    if with_negative && core.len() >= 2 {
        let negq: Vec<BigInt> = core
            .iter()
            .enumerate()
            .map(|(i, c)| if i % 2 == 1 { -c } else { c.clone() })
            .collect();
        for (lo, hi) in positive_isolation(negq).into_iter().rev() {
            out.push((-hi, -lo));
        }
    }
    if z > 0 {
        out.push((Rat::ZERO, Rat::ZERO));
    }
    if core.len() >= 2 {
        out.extend(positive_isolation(core));
    }
    // Every endpoint is 0, a power of two above all roots, or a bisection
    // midpoint, and every midpoint that is a root was reported exactly: so
    // an endpoint is a root only if it equals a neighbouring exact root.
    let is_exact_at = |i: Option<usize>, x: &Rat, out: &[(Rat, Rat)]| {
        i.and_then(|i| out.get(i))
            .is_some_and(|(lo, hi)| lo == hi && lo == x)
    };
    for i in 0..out.len() {
        let (lo, hi) = &out[i];
        if lo != hi
            && (is_exact_at(i.checked_sub(1), lo, &out) || is_exact_at(Some(i + 1), hi, &out))
        {
            let (mut lo, mut hi) = out[i].clone();
            let q = strip_endpoint_roots(s, &lo, &hi);
            bisect(&q, &mut lo, &mut hi, |a, b| {
                s.sign_at(a) != 0 && s.sign_at(b) != 0
            });
            out[i] = (lo, hi);
        }
    }
    debug_assert!(out
        .iter()
        .all(|(lo, hi)| lo == hi || (s.sign_at(lo) != 0 && s.sign_at(hi) != 0)));
    out
}

/// `c * 2^e` as a rational.
fn dyadic(c: &BigInt, e: i64) -> Rat {
    if e >= 0 {
        Rat::from_int(Int::from(c << (e as u64)))
    } else {
        Rat::new(
            Int::from(c.clone()),
            Int::from(BigInt::one() << ((-e) as u64)),
        )
    }
}

/// Divides all coefficients by their largest common power of two.
fn strip_pow2(v: &mut [BigInt]) {
    let tz = v.iter().filter_map(BigInt::trailing_zeros).min();
    if let Some(tz) = tz {
        if tz > 0 {
            for c in v.iter_mut() {
                *c >>= tz;
            }
        }
    }
}

/// For `q` with positive leading coefficient: `e` such that `q` has no root
/// in `[2^e, oo)`, or `None` if no coefficient is negative (then `q > 0` on
/// `(0, oo)`).
///
/// Kioustelidis' bound rounded up to a power of two: `e = 1 + max` over
/// negative `a_{n-k}` of the least `s` with `a_n 2^(k s) >= |a_{n-k}|`.
/// For `x >= 2^e` each such term obeys `|a_{n-k}| x^(n-k) <= a_n x^n 2^-k`,
/// so `q(x) >= a_n x^n (1 - sum 2^-k) > 0`.
fn positive_root_bound_exp(q: &[BigInt]) -> Option<i64> {
    let n = q.len() - 1;
    let bn = q[n].bits() as i64;
    let mut emax: Option<i64> = None;
    for k in 1..=n {
        let c = &q[n - k];
        if c.is_negative() {
            let a = -c;
            let kk = k as i64;
            // 2^(d-1) < |a| / a_n < 2^(d+1), so the least s lies in
            // ceil((d - 1) / k) ..= ceil((d + 1) / k).
            let d = a.bits() as i64 - bn;
            let ceil_div = |x: i64| -((-x).div_euclid(kk));
            let mut sk = ceil_div(d - 1);
            while !dominates(&q[n], kk * sk, &a) {
                sk += 1;
            }
            emax = Some(emax.map_or(sk, |m| m.max(sk)));
        }
    }
    emax.map(|m| m + 1)
}

/// `lead * 2^sh >= a` for `lead, a > 0`.
fn dominates(lead: &BigInt, sh: i64, a: &BigInt) -> bool {
    if sh >= 0 {
        (lead << sh as u64) >= *a
    } else {
        *lead >= (a << (-sh) as u64)
    }
}

enum Work {
    /// `q` has, up to a positive factor, the roots of `s(B (c + x) / 2^k)`.
    Node { q: Fixed, c: BigInt, k: i64 },
    /// The exact root `B c / 2^k`.
    Root { c: BigInt, k: i64 },
}

/// Roots in `(0, oo)` of a square-free `q` with `q(0) != 0`, `deg q >= 1`,
/// ascending, as exact points or isolating intervals with dyadic endpoints.
fn positive_isolation(mut q: Vec<BigInt>) -> Vec<(Rat, Rat)> {
    let n = q.len() - 1;
    if q[n].is_negative() {
        for c in q.iter_mut() {
            *c = -&*c;
        }
    }
    let Some(e) = positive_root_bound_exp(&q) else {
        return Vec::new(); // no sign variation: no positive root
    };
    // q(B x), times 2^(-e n) if e < 0.
    for (i, c) in q.iter_mut().enumerate() {
        let sh = if e >= 0 {
            e as u64 * i as u64
        } else {
            (-e) as u64 * (n - i) as u64
        };
        *c <<= sh;
    }
    strip_pow2(&mut q);
    let mut out = Vec::new();
    bisect_01(&q, |found| {
        out.push(match found {
            Found::Root { c, k } => {
                let r = dyadic(&c, e - k);
                (r.clone(), r)
            }
            Found::Interval { c, k } => (dyadic(&c, e - k), dyadic(&(&c + 1u32), e - k)),
        })
    });
    out
}

/// A root of the polynomial given to [`bisect_01`], in `(0, 1)`.
enum Found {
    /// Exactly `c / 2^k`.
    Root { c: BigInt, k: i64 },
    /// The only root in `(c / 2^k, (c + 1) / 2^k)`.
    Interval { c: BigInt, k: i64 },
}

/// The roots in `(0, 1)` of a square-free `q` with `q(0) != 0` and `q(1) !=
/// 0`, ascending, by Descartes' rule on halves (Vincent, Collins and
/// Akritas) in fixed-width integers.
fn bisect_01(q: &[BigInt], mut found: impl FnMut(Found)) {
    let mut stack = vec![Work::Node {
        q: Fixed::from_big(q),
        c: BigInt::zero(),
        k: 0,
    }];
    while let Some(w) = stack.pop() {
        match w {
            Work::Root { c, k } => found(Found::Root { c, k }),
            Work::Node { mut q, c, k } => {
                q.fit();
                match q.descartes_01() {
                    0 => {}
                    1 => found(Found::Interval { c, k }),
                    _ => {
                        let (l, r, mid_root) = q.split();
                        let c2: BigInt = c << 1u32;
                        let c2p: BigInt = &c2 + 1u32;
                        stack.push(Work::Node {
                            q: r,
                            c: c2p.clone(),
                            k: k + 1,
                        });
                        if mid_root {
                            stack.push(Work::Root { c: c2p, k: k + 1 });
                        }
                        stack.push(Work::Node {
                            q: l,
                            c: c2,
                            k: k + 1,
                        });
                    }
                }
            }
        }
    }
}

/// Fixed-width two's-complement integers (little-endian 64-bit limbs) for
/// the bisection: the Taylor shifts are long runs of additions, which on
/// flat limb arrays need no allocation and no sign juggling.
mod fixed_limbs {
    /// `dst += src` (same width, wrapping; callers leave enough headroom).
    pub(super) fn add(dst: &mut [u64], src: &[u64]) {
        let mut carry = false;
        for (a, &b) in dst.iter_mut().zip(src) {
            let (s1, c1) = a.overflowing_add(b);
            let (s2, c2) = s1.overflowing_add(u64::from(carry));
            *a = s2;
            carry = c1 || c2;
        }
    }

    /// `x <- -x`.
    pub(super) fn negate(x: &mut [u64]) {
        let mut carry = true;
        for a in x.iter_mut() {
            let (v, c) = (!*a).overflowing_add(u64::from(carry));
            *a = v;
            carry = c;
        }
    }

    pub(super) fn is_negative(x: &[u64]) -> bool {
        x.last().is_some_and(|&t| (t as i64) < 0)
    }

    /// -1, 0 or 1.
    pub(super) fn sign(x: &[u64]) -> i32 {
        if is_negative(x) {
            -1
        } else if x.iter().any(|&a| a != 0) {
            1
        } else {
            0
        }
    }

    /// Bits of the magnitude beyond the sign: `|x| <= 2^bits`.
    pub(super) fn sig_bits(x: &[u64]) -> u64 {
        let fill = if is_negative(x) { u64::MAX } else { 0 };
        for (i, &a) in x.iter().enumerate().rev() {
            let v = a ^ fill;
            if v != 0 {
                return i as u64 * 64 + 64 - u64::from(v.leading_zeros());
            }
        }
        0
    }

    /// `x <- x * 2^s` (the result must fit).
    pub(super) fn shl(x: &mut [u64], s: u64) {
        let w = x.len();
        let (limbs, bits) = ((s / 64) as usize, (s % 64) as u32);
        if limbs > 0 {
            for i in (0..w).rev() {
                x[i] = if i >= limbs { x[i - limbs] } else { 0 };
            }
        }
        if bits > 0 {
            for i in (0..w).rev() {
                let low = if i > 0 { x[i - 1] >> (64 - bits) } else { 0 };
                x[i] = (x[i] << bits) | low;
            }
        }
    }

    /// `x <- floor(x / 2^s)`.
    pub(super) fn sar(x: &mut [u64], s: u64) {
        let w = x.len();
        let fill = if is_negative(x) { u64::MAX } else { 0 };
        let (limbs, bits) = ((s / 64) as usize, (s % 64) as u32);
        if limbs > 0 {
            for i in 0..w {
                x[i] = if i + limbs < w { x[i + limbs] } else { fill };
            }
        }
        if bits > 0 {
            for i in 0..w {
                let high = if i + 1 < w { x[i + 1] } else { fill };
                x[i] = (x[i] >> bits) | (high << (64 - bits));
            }
        }
    }

    /// Trailing zero bits; `None` for zero.
    pub(super) fn trailing_zeros(x: &[u64]) -> Option<u64> {
        x.iter()
            .position(|&a| a != 0)
            .map(|i| i as u64 * 64 + u64::from(x[i].trailing_zeros()))
    }
}

/// A polynomial (lowest degree first) with coefficients as two's-complement
/// integers of `w` limbs each, stored row after row.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Fixed {
    w: usize,
    d: Vec<u64>,
}

impl Fixed {
    /// Headroom in bits for one node: the Descartes test and the children
    /// multiply coefficients by at most `2^m (m + 1)` and `2^(2m) (m + 1)^2`.
    fn headroom(m: usize) -> u64 {
        let lg = 64 - u64::from((m as u64 + 1).leading_zeros());
        2 * m as u64 + 2 * lg + 2
    }

    fn width_for(bits: u64, m: usize) -> usize {
        // magnitude bits + headroom + sign bit
        ((bits + Fixed::headroom(m) + 1) / 64 + 1) as usize
    }

    fn from_big(q: &[BigInt]) -> Fixed {
        let bits = q.iter().map(BigInt::bits).max().unwrap_or(0);
        let w = Fixed::width_for(bits, q.len().saturating_sub(1));
        let mut d = vec![0u64; q.len() * w];
        for (row, c) in d.chunks_mut(w).zip(q) {
            let (sign, mag) = c.to_u64_digits();
            row[..mag.len()].copy_from_slice(&mag);
            if sign == num_bigint::Sign::Minus {
                fixed_limbs::negate(row);
            }
        }
        Fixed { w, d }
    }

    #[cfg(test)]
    fn to_big(&self) -> Vec<BigInt> {
        self.d
            .chunks(self.w)
            .map(|row| {
                let mut r = row.to_vec();
                let neg = fixed_limbs::is_negative(&r);
                if neg {
                    fixed_limbs::negate(&mut r);
                }
                let m = BigInt::from(num_bigint::BigUint::new(
                    r.iter()
                        .flat_map(|&a| [a as u32, (a >> 32) as u32])
                        .collect(),
                ));
                if neg {
                    -m
                } else {
                    m
                }
            })
            .collect()
    }

    /// Number of coefficients.
    fn len(&self) -> usize {
        self.d.len() / self.w
    }

    fn row(&self, i: usize) -> &[u64] {
        &self.d[i * self.w..(i + 1) * self.w]
    }

    fn row_mut(&mut self, i: usize) -> &mut [u64] {
        &mut self.d[i * self.w..(i + 1) * self.w]
    }

    /// `row[j] += row[j + 1]`.
    fn add_next(d: &mut [u64], w: usize, j: usize) {
        let (x, y) = d.split_at_mut((j + 1) * w);
        fixed_limbs::add(&mut x[j * w..], &y[..w]);
    }

    /// Re-chooses the width for the current coefficients and degree.
    fn fit(&mut self) {
        let bits = self
            .d
            .chunks(self.w)
            .map(fixed_limbs::sig_bits)
            .max()
            .unwrap_or(0)
            + 1;
        let w = Fixed::width_for(bits, self.len().saturating_sub(1));
        if w == self.w {
            return;
        }
        let mut d = vec![0u64; self.len() * w];
        for (new, old) in d.chunks_mut(w).zip(self.d.chunks(self.w)) {
            let fill = if fixed_limbs::is_negative(old) {
                u64::MAX
            } else {
                0
            };
            for (i, a) in new.iter_mut().enumerate() {
                *a = old.get(i).copied().unwrap_or(fill);
            }
        }
        *self = Fixed { w, d };
    }

    /// In-place `q(x) <- q(x + 1)`.
    fn taylor_shift1(&mut self) {
        let (w, n) = (self.w, self.len().saturating_sub(1));
        for i in 0..n {
            for j in (i..n).rev() {
                Fixed::add_next(&mut self.d, w, j);
            }
        }
    }

    /// Sign variations of `(x + 1)^n q(1 / (x + 1))`, capped at 2: an upper
    /// bound for the number of roots of `q` in `(0, 1)`, exact when 0 or 1.
    fn descartes_01(&self) -> u32 {
        let (w, n) = (self.w, self.len().saturating_sub(1));
        if n == 0 {
            return 0;
        }
        let mut a = vec![0u64; self.d.len()];
        for (dst, src) in a.chunks_mut(w).zip(self.d.chunks(w).rev()) {
            dst.copy_from_slice(src);
        }
        let mut count = 0;
        let mut last = 0;
        let mut see = |s: i32, count: &mut u32| {
            if s != 0 {
                if last != 0 && s != last {
                    *count += 1;
                }
                last = s;
            }
        };
        // After round i of the shift, a[i] is final: count on the fly.
        for i in 0..n {
            for j in (i..n).rev() {
                Fixed::add_next(&mut a, w, j);
            }
            see(fixed_limbs::sign(&a[i * w..(i + 1) * w]), &mut count);
            if count >= 2 {
                return 2;
            }
        }
        see(fixed_limbs::sign(&a[n * w..]), &mut count);
        count.min(2)
    }

    /// Divides all coefficients by their largest common power of two.
    fn strip_pow2(&mut self) {
        let tz = self
            .d
            .chunks(self.w)
            .filter_map(fixed_limbs::trailing_zeros)
            .min();
        if let Some(tz) = tz.filter(|&t| t > 0) {
            for row in self.d.chunks_mut(self.w) {
                fixed_limbs::sar(row, tz);
            }
        }
    }

    /// The halves: `l = 2^m q(x/2)` (roots in `(0, 1/2)` moved to `(0, 1)`)
    /// and `r = l(x + 1)`, with the factor `x - 1` of `l` divided out first
    /// when the midpoint is a root (reported as the third value).
    fn split(&self) -> (Fixed, Fixed, bool) {
        let (w, m) = (self.w, self.len() - 1);
        let mut l = self.clone();
        for i in 0..m {
            fixed_limbs::shl(l.row_mut(i), (m - i) as u64);
        }
        let mut sum = vec![0u64; w];
        for i in 0..=m {
            fixed_limbs::add(&mut sum, l.row(i));
        }
        let mid_root = fixed_limbs::sign(&sum) == 0;
        if mid_root {
            // b[m-1] = l[m], b[i-1] = l[i] + b[i]
            let mut b = Fixed {
                w,
                d: l.d[w..].to_vec(),
            };
            for i in (0..m.saturating_sub(1)).rev() {
                Fixed::add_next(&mut b.d, w, i);
            }
            l = b;
        }
        let mut r = l.clone();
        r.taylor_shift1();
        l.strip_pow2();
        r.strip_pow2();
        (l, r, mid_root)
    }
}

/// `p` with its content divided out, sign kept.
fn reduce_content(p: UPoly) -> UPoly {
    let (c, pp) = p.primitive();
    if c.is_negative() {
        -pp
    } else {
        pp
    }
}

/// Sturm sequence of the square-free part of a non-constant `p`:
/// `p0 = p, p1 = p', p_{i+1} = -(positive constant) * (p_{i-1} mod p_i)`,
/// each then divided by the last element (a gcd of `p` and `p'`).
///
/// The terms are those of the subresultant remainder sequence, each with
/// the sign that makes it a positive multiple of the Sturm term: its
/// divisions are exact by factors known in advance, where taking every
/// remainder's primitive part costs a gcd of the (large) coefficients per
/// term. Only the terms' signs at points are read, so any positive
/// multiples count the same roots.
fn sturm_chain(p: &UPoly) -> Vec<UPoly> {
    let mut prs = vec![reduce_content(p.clone()), reduce_content(p.derivative())];
    // sign[i] * prs[i] is a positive multiple of the i-th Sturm term.
    let mut sign = vec![1i32, 1];
    // Collins' subresultant recurrence: r_{i+1} = prem(r_{i-1}, r_i) /
    // (g h^delta), then g = lc(r_i), h = g^delta / h^(delta - 1).
    let (mut g, mut h) = (Int::ONE, Int::ONE);
    loop {
        let i = prs.len() - 1;
        let (a, b) = (&prs[i - 1], &prs[i]);
        if b.is_constant() {
            break;
        }
        let lc = b.leading_coeff();
        let delta = (a.coeffs().len() - b.coeffs().len()) as u32;
        // lc^e a = q b + r with e steps; prem takes lc^(delta + 1).
        let (_, r, e) = pseudo_div_raw(a, b, false);
        if r.is_zero() {
            break;
        }
        let divisor = &g * &h.pow(delta);
        let r = r.scale(&lc.pow(delta + 1 - e));
        let r = UPoly::new(r.coeffs().iter().map(|c| c.div_exact(&divisor)).collect());
        // rem(s_{i-1}, s_i) = sign[i-1] * r * divisor / lc^(delta + 1) up
        // to a positive factor, and s_{i+1} is its negative.
        let lc_odd = lc.is_negative() && (delta + 1) % 2 == 1;
        let s =
            -sign[i - 1] * if divisor.is_negative() { -1 } else { 1 } * if lc_odd { -1 } else { 1 };
        g = lc;
        h = match delta {
            0 => h,
            1 => g.clone(),
            d => g.pow(d).div_exact(&h.pow(d - 1)),
        };
        prs.push(r);
        sign.push(s);
    }
    let mut chain: Vec<UPoly> = prs
        .into_iter()
        .zip(sign)
        .map(|(r, s)| if s < 0 { -r } else { r })
        .collect();
    // A positive multiple of the last term, primitive: every term is
    // divisible by it over Z (Gauss's lemma).
    let last = reduce_content(chain[chain.len() - 1].clone());
    if !last.is_constant() {
        for c in chain.iter_mut() {
            if let Some(d) = c.div_exact(&last) {
                *c = d;
            }
        }
    }
    chain
}

fn variations(signs: impl Iterator<Item = i32>) -> usize {
    let mut last = 0;
    let mut count = 0;
    for s in signs.filter(|&s| s != 0) {
        if last != 0 && s != last {
            count += 1;
        }
        last = s;
    }
    count
}

/// A Sturm sequence, for counting the distinct real roots of a polynomial
/// in many intervals (the chain is computed once).
///
/// It is built for the square-free part of the polynomial (the chain of
/// `p, p'` divided by its last element), so counts are of distinct roots and
/// half-open intervals `(lo, hi]` are counted correctly even when an endpoint
/// is a root. This route is independent of [`real_roots`].
///
/// ```
/// use poly::{SturmSequence, UPoly};
/// let p = &UPoly::from_i64s(&[-2, 1]).pow(2) * &UPoly::from_i64s(&[1, 0, 1]); // (x-2)^2 (x^2+1)
/// let s = SturmSequence::new(&p);
/// assert_eq!(s.count_real(), 1);
/// assert_eq!(s.count_in(&1.into(), &2.into()), 1);
/// assert_eq!(s.count_in(&2.into(), &3.into()), 0);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SturmSequence {
    chain: Vec<UPoly>,
}

impl SturmSequence {
    /// The Sturm sequence of `p` (empty for constants and zero, which then
    /// count no roots).
    pub fn new(p: &UPoly) -> SturmSequence {
        let chain = if p.is_constant() {
            Vec::new()
        } else {
            sturm_chain(p)
        };
        SturmSequence { chain }
    }

    /// The polynomials of the chain, starting with the square-free part of
    /// `p` (up to a constant factor).
    pub fn chain(&self) -> &[UPoly] {
        &self.chain
    }

    /// Sign variations of the chain at `x` (zeros skipped).
    pub fn variations_at(&self, x: &Rat) -> usize {
        variations(self.chain.iter().map(|c| c.sign_at(x)))
    }

    /// Number of distinct real roots in the half-open interval `(lo, hi]`;
    /// 0 when `lo >= hi`.
    pub fn count_in(&self, lo: &Rat, hi: &Rat) -> usize {
        if self.chain.is_empty() || lo >= hi {
            return 0;
        }
        self.variations_at(lo)
            .saturating_sub(self.variations_at(hi))
    }

    /// Number of distinct real roots (variations at minus and plus infinity).
    pub fn count_real(&self) -> usize {
        let at_minus = variations(self.chain.iter().map(|c| {
            let s = c.leading_coeff().signum();
            if c.degree().unwrap_or(0) % 2 == 1 {
                -s
            } else {
                s
            }
        }));
        let at_plus = variations(self.chain.iter().map(|c| c.leading_coeff().signum()));
        at_minus.saturating_sub(at_plus)
    }

    /// Number of distinct real roots > 0.
    pub fn count_positive(&self) -> usize {
        let at_plus = variations(self.chain.iter().map(|c| c.leading_coeff().signum()));
        self.variations_at(&Rat::ZERO).saturating_sub(at_plus)
    }
}

/// Number of distinct real roots of `p` in the half-open interval
/// `(lo, hi]`, by a Sturm sequence (independent of [`real_roots`]; use
/// [`SturmSequence`] to count in many intervals). 0 when `lo >= hi`, for
/// constants and for the zero polynomial.
///
/// ```
/// use poly::{count_roots_in, UPoly};
/// let p = UPoly::from_i64s(&[-2, 1]).pow(2); // (x - 2)^2
/// assert_eq!(count_roots_in(&p, &1.into(), &2.into()), 1);
/// assert_eq!(count_roots_in(&p, &2.into(), &3.into()), 0);
/// ```
pub fn count_roots_in(p: &UPoly, lo: &Rat, hi: &Rat) -> usize {
    if p.is_constant() || lo >= hi {
        return 0;
    }
    // The square-free part's roots in (lo, hi) are those of
    // q(x) = s(lo + (hi - lo) x) in (0, 1), counted by Descartes' rule on
    // halves: of high degree and with large coefficients, much faster than
    // a Sturm chain, whose terms' coefficients grow with every step.
    let s = p.square_free_part();
    let at_hi = usize::from(s.sign_at(hi) == 0);
    // s is square-free: a root at either end is simple, divided out.
    let mut q = affine_image(&strip_endpoint_roots(&s, lo, hi), lo, hi);
    if q.len() < 2 {
        return at_hi;
    }
    if q[q.len() - 1].is_negative() {
        q.iter_mut().for_each(|c| *c = -&*c);
    }
    let mut inside = 0;
    bisect_01(&q, |_| inside += 1);
    inside + at_hi
}

/// The integer coefficients, lowest first, of a positive multiple of
/// `s(lo + (hi - lo) x)`.
fn affine_image(s: &UPoly, lo: &Rat, hi: &Rat) -> Vec<BigInt> {
    let (a, b) = (lo.numer().to_big(), lo.denom().to_big());
    let w = hi - lo;
    let (c, d) = (w.numer().to_big(), w.denom().to_big());
    let coeffs: Vec<BigInt> = s.coeffs().iter().map(Int::to_big).collect();
    let n = coeffs.len() - 1;
    // b^n s((b x + a) / b) by Horner's rule, then x -> c x / d times d^n.
    let mut acc: Vec<BigInt> = vec![coeffs[n].clone()];
    let mut bpow = BigInt::one();
    for i in (0..n).rev() {
        bpow *= &b;
        let mut next = vec![BigInt::zero(); acc.len() + 1];
        for (j, v) in acc.iter().enumerate() {
            next[j] += v * &a;
            next[j + 1] += v * &b;
        }
        next[0] += &coeffs[i] * &bpow;
        acc = next;
    }
    let mut cpow = BigInt::one();
    let mut dpows: Vec<BigInt> = Vec::with_capacity(n + 1);
    let mut dp = BigInt::one();
    for _ in 0..=n {
        dpows.push(dp.clone());
        dp *= &d;
    }
    for (j, v) in acc.iter_mut().enumerate() {
        *v = &*v * &cpow * &dpows[n - j];
        cpow *= &c;
    }
    while acc.len() > 1 && acc.last().is_some_and(|v| v.is_zero()) {
        acc.pop();
    }
    acc
}

/// Number of distinct real roots of `p` by a Sturm sequence (signs at
/// minus and plus infinity). 0 for constants and the zero polynomial.
///
/// ```
/// use poly::{count_real_roots, UPoly};
/// // (x^2 + 1)(x^2 - 1)
/// assert_eq!(count_real_roots(&UPoly::from_i64s(&[-1, 0, 0, 0, 1])), 2);
/// ```
pub fn count_real_roots(p: &UPoly) -> usize {
    SturmSequence::new(p).count_real()
}

#[cfg(test)]
mod tests {
    use super::*;

    // BigInt reference versions of the bisection kernels.

    /// In-place `a(x) <- a(x + 1)`.
    fn taylor_shift1(a: &mut [BigInt]) {
        let n = a.len().saturating_sub(1);
        for i in 0..n {
            for j in (i..n).rev() {
                let (x, y) = a.split_at_mut(j + 1);
                x[j] += &y[0];
            }
        }
    }

    /// `q(x) / (x - 1)` for `q(1) = 0`.
    fn div_x_minus_1(q: &[BigInt]) -> Vec<BigInt> {
        let m = q.len() - 1;
        let mut b = vec![BigInt::zero(); m];
        b[m - 1] = q[m].clone();
        for i in (1..m).rev() {
            b[i - 1] = &q[i] + &b[i];
        }
        b
    }

    /// Reference Descartes test on BigInt coefficients.
    fn descartes_01_big(q: &[BigInt]) -> u32 {
        let mut a: Vec<BigInt> = q.iter().rev().cloned().collect();
        taylor_shift1(&mut a);
        let signs: Vec<i32> = a
            .iter()
            .map(|c| {
                if c.is_positive() {
                    1
                } else if c.is_negative() {
                    -1
                } else {
                    0
                }
            })
            .collect();
        (variations(signs.into_iter()) as u32).min(2)
    }

    fn up(c: &[i64]) -> UPoly {
        UPoly::from_i64s(c)
    }

    fn q(s: &str) -> Rat {
        s.parse().unwrap()
    }

    fn big(s: &str) -> Int {
        s.parse().unwrap()
    }

    /// `d x - n`, the linear factor of the root `n/d`.
    fn lin(r: &str) -> UPoly {
        UPoly::linear_root(&q(r))
    }

    fn product(factors: &[(UPoly, u32)]) -> UPoly {
        factors
            .iter()
            .fold(UPoly::one(), |acc, (f, m)| &acc * &f.pow(*m))
    }

    /// Checks `real_roots(p)` against independent facts: `sqf` is a
    /// square-free polynomial with the roots of `p` (built from the known
    /// factors), and Sturm counts (a different algorithm).
    fn check(p: &UPoly, sqf: &UPoly) -> Vec<RealRoot> {
        let roots = real_roots(p);
        let sturm = SturmSequence::new(p);
        for (i, r) in roots.iter().enumerate() {
            assert!(r.lo <= r.hi, "{r:?}");
            assert!(r.multiplicity >= 1);
            if r.is_exact() {
                assert_eq!(p.sign_at(&r.lo), 0, "exact root is not a root: {r:?}");
                assert_eq!(sqf.sign_at(&r.lo), 0);
            } else {
                assert_ne!(p.sign_at(&r.lo), 0, "endpoint is a root: {r:?}");
                assert_ne!(p.sign_at(&r.hi), 0, "endpoint is a root: {r:?}");
                assert!(
                    sqf.sign_at(&r.lo) * sqf.sign_at(&r.hi) < 0,
                    "no sign change in {r:?}"
                );
                assert_eq!(sturm.count_in(&r.lo, &r.hi), 1, "Sturm: {r:?}");
            }
            assert!(r.lo.signum() >= 0 || r.hi.signum() <= 0, "straddles 0");
            if let Some(next) = roots.get(i + 1) {
                assert!(r.hi <= next.lo, "not ascending/disjoint");
                assert!(r.lo < next.lo);
                // Between two consecutive roots Sturm sees nothing (or just
                // the next root if it sits exactly on the left endpoint).
                let expect = usize::from(next.is_exact());
                assert_eq!(sturm.count_in(&r.hi, &next.lo), expect);
            }
        }
        assert_eq!(roots.len(), sturm.count_real(), "total count vs Sturm");
        let positive = roots.iter().filter(|r| r.is_positive()).count();
        assert_eq!(positive, sturm.count_positive());
        assert_eq!(roots.len(), count_real_roots(sqf));
        roots
    }

    fn mults(roots: &[RealRoot]) -> Vec<u32> {
        roots.iter().map(|r| r.multiplicity).collect()
    }

    fn contains(r: &RealRoot, x: &Rat) -> bool {
        if r.is_exact() {
            &r.lo == x
        } else {
            &r.lo < x && x < &r.hi
        }
    }

    #[test]
    fn mixed_rational_and_irrational_roots() {
        // (x^2 - 2)(3x - 1)^2 (x + 5)
        let factors = [(up(&[-2, 0, 1]), 1), (lin("1/3"), 2), (lin("-5"), 1)];
        let p = product(&factors);
        let sqf = &(&up(&[-2, 0, 1]) * &lin("1/3")) * &lin("-5");
        let r = check(&p, &sqf);
        assert_eq!(mults(&r), [1, 1, 2, 1]);
        assert!(contains(&r[0], &q("-5")));
        assert!(contains(&r[2], &q("1/3")));
        // -sqrt 2 and sqrt 2: x^2 - 2 changes sign across the intervals.
        let two = up(&[-2, 0, 1]);
        assert!(two.sign_at(&r[1].lo) * two.sign_at(&r[1].hi) < 0 && r[1].hi.signum() <= 0);
        assert!(two.sign_at(&r[3].lo) * two.sign_at(&r[3].hi) < 0 && r[3].lo.signum() >= 0);
        // Same roots for any non-zero multiple.
        assert_eq!(real_roots(&p.scale(&Int::from(-12))), r);
    }

    #[test]
    fn small_hand_cases() {
        let r = check(&up(&[7, 3]), &up(&[7, 3]));
        assert_eq!(r.len(), 1);
        assert!(contains(&r[0], &q("-7/3")));
        let r = check(&UPoly::x(), &UPoly::x());
        assert_eq!((r[0].exact(), r[0].multiplicity), (Some(&Rat::ZERO), 1));
        let r = check(&UPoly::x().pow(2), &UPoly::x());
        assert_eq!((r[0].exact(), r[0].multiplicity), (Some(&Rat::ZERO), 2));
        let p = up(&[0, 1, 0, -1]); // -x (x - 1)(x + 1)
        let r = check(&p, &p);
        assert_eq!(r.len(), 3);
        for (root, x) in r.iter().zip(["-1", "0", "1"]) {
            assert!(contains(root, &q(x)));
        }
        let r = check(&lin("1").pow(5), &lin("1"));
        assert_eq!(mults(&r), [5]);
        let r = check(&up(&[-1, 0, 2]), &up(&[-1, 0, 2])); // 2x^2 - 1
        assert_eq!(r.len(), 2);
        let half = up(&[-1, 0, 2]);
        assert!(r
            .iter()
            .all(|x| half.sign_at(&x.lo) * half.sign_at(&x.hi) < 0));
    }

    #[test]
    fn very_close_roots() {
        // (x - 1)(x - 1 - 10^-30)
        let e = Int::from(10).pow(30);
        let a = lin("1");
        let b = UPoly::new(vec![-(&e + &Int::ONE), e.clone()]);
        let p = &a * &b;
        let r = check(&p, &p);
        assert_eq!(mults(&r), [1, 1]);
        let other = Rat::new(&e + &Int::ONE, e.clone());
        assert!(contains(&r[0], &Rat::ONE));
        assert!(contains(&r[1], &other));
        // And a double root next to a simple one.
        let p2 = &a.pow(2) * &b;
        let r2 = check(&p2, &p);
        assert_eq!(mults(&r2), [2, 1]);
    }

    #[test]
    fn wilkinson_degree_20() {
        let w = (1..=20).fold(UPoly::one(), |acc, k| &acc * &up(&[-k, 1]));
        assert!(w.coeffs().iter().any(|c| matches!(c, Int::Big(_))));
        let r = check(&w, &w);
        assert_eq!(r.len(), 20);
        for (k, root) in r.iter().enumerate() {
            assert!(contains(root, &Rat::from(k as i64 + 1)), "{root:?}");
            assert_eq!(root.multiplicity, 1);
        }
        // Wilkinson's perturbation w(x) - 2^-23 x^19 keeps only 10 real roots
        // (Wilkinson 1963; the other ten form five complex pairs).
        let pert = &w.scale(&Int::from(1 << 23)) - &UPoly::monomial(Int::ONE, 19);
        let sqf = pert.square_free_part();
        assert_eq!(sqf, pert);
        let r = check(&pert, &pert);
        assert_eq!(r.len(), 10);
        let mut last = r[9].clone();
        last.refine(&pert, &q("1/100")).unwrap();
        assert!((last.to_f64() - 20.85).abs() < 0.05, "{}", last.to_f64());
    }

    #[test]
    fn no_real_roots() {
        let p = &up(&[1, 0, 1]) * &up(&[7, 0, 1, 0, 1]);
        assert!(check(&p, &p).is_empty());
        assert_eq!(count_nonpositive_or_nonreal(&p), 6);
        assert!(real_roots(&UPoly::constant(Int::from(3))).is_empty());
        assert!(real_roots(&UPoly::zero()).is_empty());
        assert_eq!(count_real_roots(&UPoly::zero()), 0);
    }

    #[test]
    fn root_at_zero() {
        // x^3 (x - 2)(x + 3)
        let p = &UPoly::x().pow(3) * &up(&[-6, 1, 1]);
        let sqf = &UPoly::x() * &up(&[-6, 1, 1]);
        let r = check(&p, &sqf);
        assert_eq!(mults(&r), [1, 3, 1]);
        assert_eq!(r[1].exact(), Some(&Rat::ZERO));
        assert!(contains(&r[0], &q("-3")) && contains(&r[2], &q("2")));
        assert_eq!(count_nonpositive_or_nonreal(&p), 4);
        // Tiny positive root next to 0: x (2^40 x - 1)(x + 1)
        let t =
            &(&UPoly::x() * &UPoly::new(vec![Int::from(-1), Int::from(1i64 << 40)])) * &up(&[1, 1]);
        let r = check(&t, &t);
        assert_eq!(r.len(), 3);
        assert_eq!(r[1].exact(), Some(&Rat::ZERO));
        assert!(contains(&r[2], &Rat::new(Int::ONE, Int::from(1i64 << 40))));
    }

    #[test]
    fn large_coefficients() {
        // (x - 2^70)(2^65 x + 3)(x^2 - 3)(x - (2^64 + 1)/3)^2
        let two = Int::from(2);
        let a = UPoly::new(vec![-two.pow(70), Int::ONE]);
        let b = UPoly::new(vec![Int::from(3), two.pow(65)]);
        let c = up(&[-3, 0, 1]);
        let d = UPoly::new(vec![-(&two.pow(64) + &Int::ONE), Int::from(3)]);
        let p = product(&[
            (a.clone(), 1),
            (b.clone(), 1),
            (c.clone(), 1),
            (d.clone(), 2),
        ]);
        assert!(p.coeffs().iter().all(|x| x.bits() > 64 || x.is_zero()));
        let sqf = &(&a * &b) * &(&c * &d);
        let r = check(&p, &sqf);
        assert_eq!(mults(&r), [1, 1, 1, 2, 1]);
        assert!(contains(&r[1], &Rat::new(Int::from(-3), two.pow(65))));
        assert!(contains(
            &r[3],
            &Rat::new(&two.pow(64) + &Int::ONE, Int::from(3))
        ));
        assert!(contains(&r[4], &Rat::from_int(two.pow(70))));
        // Coefficients of ~300 bits.
        let huge = big("2037035976334486086268445688409378161051468393665936250636140449354381299763336706183397377");
        let e = UPoly::new(vec![-huge.clone(), Int::ONE]); // x - huge
        let f = UPoly::new(vec![Int::ONE, huge.clone()]); // huge x + 1
        let p = &(&e * &f) * &up(&[-5, 0, 1]);
        let r = check(&p, &p);
        assert_eq!(r.len(), 4);
        assert!(contains(&r[3], &Rat::from_int(huge.clone())));
        assert!(contains(&r[1], &Rat::new(Int::from(-1), huge)));
    }

    #[test]
    fn chebyshev_roots_match_cosines() {
        // T_{n+1} = 2x T_n - T_{n-1}; roots cos((2k - 1) pi / (2n)).
        let n = 24;
        let mut t = (up(&[1]), up(&[0, 1]));
        for _ in 1..n {
            let next = &(&up(&[0, 2]) * &t.1) - &t.0;
            t = (t.1, next);
        }
        let tn = t.1;
        assert_eq!(tn.degree(), Some(n));
        let r = check(&tn, &tn);
        assert_eq!(r.len(), n);
        for (i, root) in r.iter().enumerate() {
            let k = (n - i) as f64;
            let x = ((2.0 * k - 1.0) * std::f64::consts::PI / (2.0 * n as f64)).cos();
            assert!(root.lo.to_f64() - 1e-12 <= x && x <= root.hi.to_f64() + 1e-12);
        }
    }

    #[test]
    fn many_rational_roots_degree_30() {
        // prod_{k=-15}^{14} (7x - k): 30 rational roots k/7, several of them
        // dyadic multiples of the bound (k = 0 exactly).
        let p = (-15..15).fold(UPoly::one(), |acc, k| &acc * &up(&[-k, 7]));
        let r = check(&p, &p);
        assert_eq!(r.len(), 30);
        for (i, root) in r.iter().enumerate() {
            let k = i as i64 - 15;
            assert!(
                contains(root, &Rat::new(Int::from(k), Int::from(7))),
                "{root:?}"
            );
        }
    }

    #[test]
    fn dyadic_roots_are_found_exactly_and_endpoints_avoided() {
        // Roots at 1/2, 1, 3/2, 2, 4 and an irrational one at sqrt(3) near them.
        let p = product(&[
            (lin("1/2"), 1),
            (lin("1"), 2),
            (lin("3/2"), 1),
            (lin("2"), 1),
            (lin("4"), 3),
            (up(&[-3, 0, 1]), 1),
        ]);
        let sqf = p.square_free_part();
        let r = check(&p, &sqf);
        assert_eq!(mults(&r), [1, 1, 2, 1, 1, 1, 3]);
        let exact: Vec<Rat> = r.iter().filter_map(|x| x.exact().cloned()).collect();
        assert!(!exact.is_empty());
        for x in &exact {
            assert_eq!(p.sign_at(x), 0);
        }
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
    }

    #[test]
    fn random_polynomials_agree_with_sturm() {
        let mut g = Lcg(2024);
        for _ in 0..150 {
            let deg = 1 + g.next() as usize % 12;
            let mut c: Vec<i64> = (0..=deg).map(|_| g.small(20)).collect();
            if c[deg] == 0 {
                c[deg] = 3;
            }
            let mut p = up(&c);
            if g.next().is_multiple_of(3) {
                let f = up(&[g.small(5), 1 + g.next() as i64 % 3]);
                p = &p * &f.pow(2);
            }
            let sqf = p.square_free_part();
            let r = check(&p, &sqf);
            // Multiplicities: the root of each interval divides p exactly m
            // times; checked through the decomposition product.
            let total: u32 = r.iter().map(|x| x.multiplicity).sum();
            let real_deg: u32 = p
                .square_free()
                .iter()
                .map(|(f, m)| count_real_roots(f) as u32 * m)
                .sum();
            assert_eq!(total, real_deg);
        }
    }

    #[test]
    fn refine_shrinks_and_keeps_the_root() {
        let p = &(&up(&[-2, 0, 1]) * &lin("1/3").pow(2)) * &lin("-5");
        let w = q("1/1000000000000");
        for mut r in real_roots(&p) {
            let before = r.clone();
            r.refine(&p, &w).unwrap();
            assert!(r.width() <= w);
            assert!(before.lo <= r.lo && r.hi <= before.hi);
            if !r.is_exact() {
                assert_eq!(count_roots_in(&p, &r.lo, &r.hi), 1);
            }
            assert_eq!(r.multiplicity, before.multiplicity);
        }
        let mut r = positive_roots(&p).pop().unwrap();
        r.refine(&p, &q("1/1000000000000000000000000000000"))
            .unwrap();
        assert!((r.to_f64() - 2f64.sqrt()).abs() < 1e-15);
        // Errors instead of panics.
        let mut r = real_roots(&p)[0].clone();
        assert_eq!(r.refine(&p, &Rat::ZERO), Err(RootError::NonPositiveWidth));
        assert_eq!(r.refine(&UPoly::zero(), &w), Err(RootError::ZeroPolynomial));
        assert_eq!(r.refine(&up(&[1, 0, 1]), &w), Err(RootError::NotIsolating));
        let mut bad = RealRoot {
            lo: q("2"),
            hi: q("1"),
            multiplicity: 1,
        };
        assert_eq!(bad.refine(&p, &w), Err(RootError::NotIsolating));
        // An interval with a root at an endpoint is moved off it.
        let s = &lin("1") * &up(&[-2, 0, 1]);
        let mut r = RealRoot {
            lo: q("1"),
            hi: q("2"),
            multiplicity: 1,
        };
        r.refine(&s, &q("10")).unwrap();
        assert_eq!((r.lo.clone(), r.hi.clone()), (q("5/4"), q("3/2")));
        // A midpoint hitting the root collapses the interval.
        let s = &lin("1") * &lin("3/2");
        let mut r = RealRoot {
            lo: q("1"),
            hi: q("2"),
            multiplicity: 1,
        };
        r.refine(&s, &q("10")).unwrap();
        assert_eq!(r.exact(), Some(&q("3/2")));
    }

    #[test]
    fn positive_root_bound_is_valid_and_tight() {
        let mut g = Lcg(99);
        for _ in 0..200 {
            let deg = 1 + g.next() as usize % 10;
            let mut c: Vec<i64> = (0..=deg).map(|_| g.small(1000)).collect();
            c[deg] = 1 + g.next() as i64 % 50;
            let p = up(&c);
            let big: Vec<BigInt> = p.coeffs().iter().map(Int::to_big).collect();
            let Some(e) = positive_root_bound_exp(&big) else {
                assert!(c.iter().all(|&x| x >= 0));
                continue;
            };
            let b = dyadic(&BigInt::one(), e);
            // No root in [B, oo): checked by Sturm up to a far bound (any
            // root is below 1 + max |a_i / a_n| <= 1001).
            assert_ne!(p.sign_at(&b), 0);
            assert_eq!(count_roots_in(&p, &b, &Rat::from(1 << 20)), 0);
        }
        // Exactly known cases: x - 1 has bound 2 (s = 0), x^2 - 16 has 8.
        let exp = |c: &[i64]| {
            positive_root_bound_exp(&c.iter().map(|&x| BigInt::from(x)).collect::<Vec<_>>())
        };
        assert_eq!(exp(&[-1, 1]), Some(1));
        assert_eq!(exp(&[-16, 0, 1]), Some(3));
        assert_eq!(exp(&[-17, 0, 1]), Some(4));
        assert_eq!(exp(&[1, 1]), None);
        assert_eq!(exp(&[-1, 1024]), Some(-9));
    }

    /// Random BigInts of assorted sizes and signs, including 0 and values
    /// near limb boundaries.
    fn random_bigs(g: &mut Lcg, count: usize) -> Vec<BigInt> {
        (0..count)
            .map(|_| {
                let bits = g.next() % 300;
                let mut x = BigInt::from(g.next()) << bits;
                x += BigInt::from(g.next());
                match g.next() % 6 {
                    0 => BigInt::zero(),
                    1 => -x,
                    2 => (BigInt::one() << (64 * (1 + g.next() % 4))) - 1u32,
                    3 => -(BigInt::one() << (64 * (1 + g.next() % 4))),
                    _ => x,
                }
            })
            .collect()
    }

    #[test]
    fn fixed_width_limbs_match_bigint() {
        let mut g = Lcg(77);
        for _ in 0..200 {
            let count = 1 + g.next() as usize % 8;
            let v = random_bigs(&mut g, count);
            let f = Fixed::from_big(&v);
            assert_eq!(f.to_big(), v);
            let mut f2 = f.clone();
            f2.fit();
            assert_eq!(f2.to_big(), v);
            for (i, x) in v.iter().enumerate() {
                let row = f.row(i);
                let sign = if x.is_positive() {
                    1
                } else if x.is_negative() {
                    -1
                } else {
                    0
                };
                assert_eq!(fixed_limbs::sign(row), sign);
                let sb = fixed_limbs::sig_bits(row);
                assert!(x.abs() <= BigInt::one() << sb);
                assert!(sb == 0 || x.abs() >= BigInt::one() << (sb - 1));
                assert_eq!(fixed_limbs::trailing_zeros(row), x.trailing_zeros());
                let s = g.next() % 130;
                // two more limbs, sign-extended, so that the shift fits
                let fill = if x.is_negative() { u64::MAX } else { 0 };
                let mut r = row.to_vec();
                r.extend([fill, fill]);
                fixed_limbs::shl(&mut r, s);
                let mut back = Fixed {
                    w: f.w + 2,
                    d: r.clone(),
                };
                assert_eq!(back.to_big()[0], x << s, "shl {x} by {s}");
                fixed_limbs::sar(&mut back.d, s);
                assert_eq!(back.to_big()[0], x.clone());
                let t = g.next() % 130;
                let mut q = row.to_vec();
                fixed_limbs::sar(&mut q, t);
                // floor division, as BigInt's >> on negative numbers
                assert_eq!(Fixed { w: f.w, d: q }.to_big()[0], x >> t);
            }
        }
    }

    #[test]
    fn fixed_width_bisection_kernels_match_bigint() {
        let mut g = Lcg(31);
        for round in 0..300 {
            let deg = 1 + g.next() as usize % 12;
            let mut v: Vec<BigInt> = (0..=deg)
                .map(|_| BigInt::from(g.small(1 << 40)) << (g.next() % 200))
                .collect();
            if v[deg].is_zero() {
                v[deg] = BigInt::from(-3);
            }
            if round % 3 == 0 {
                // a root at the midpoint 1/2: multiply by 2x - 1
                let mut w = vec![BigInt::zero(); deg + 2];
                for (i, c) in v.iter().enumerate() {
                    w[i] -= c;
                    w[i + 1] += c << 1u32;
                }
                v = w;
            }
            let f = Fixed::from_big(&v);
            assert_eq!(f.descartes_01(), descartes_01_big(&v));
            let mut t = f.clone();
            t.taylor_shift1();
            let mut tb = v.clone();
            taylor_shift1(&mut tb);
            assert_eq!(t.to_big(), tb);
            // Children by the reference route.
            let m = v.len() - 1;
            let mut l: Vec<BigInt> = v.iter().enumerate().map(|(i, x)| x << (m - i)).collect();
            let mid_root = l.iter().sum::<BigInt>().is_zero();
            assert_eq!(mid_root, round % 3 == 0);
            if mid_root {
                l = div_x_minus_1(&l);
            }
            let mut r = l.clone();
            taylor_shift1(&mut r);
            let strip = |v: &mut Vec<BigInt>| {
                if let Some(tz) = v.iter().filter_map(BigInt::trailing_zeros).min() {
                    for c in v.iter_mut() {
                        *c >>= tz;
                    }
                }
            };
            strip(&mut l);
            strip(&mut r);
            let (fl, fr, fmid) = f.split();
            assert_eq!(fmid, mid_root);
            assert_eq!(fl.to_big(), l);
            assert_eq!(fr.to_big(), r);
        }
    }

    /// The Sturm chain by primitive remainders, each divided by its
    /// content: the reference for the subresultant chain.
    fn primitive_sturm_chain(p: &UPoly) -> Vec<UPoly> {
        let mut chain = vec![reduce_content(p.clone()), reduce_content(p.derivative())];
        loop {
            let (a, b) = (&chain[chain.len() - 2], &chain[chain.len() - 1]);
            if b.is_constant() {
                break;
            }
            let (_, r, e) = pseudo_div_raw(a, b, false);
            if r.is_zero() {
                break;
            }
            let negative_multiplier = b.leading_coeff().is_negative() && e % 2 == 1;
            let r = reduce_content(r);
            chain.push(if negative_multiplier { r } else { -r });
        }
        let g = chain[chain.len() - 1].clone();
        if !g.is_constant() {
            for c in chain.iter_mut() {
                *c = c.div_exact(&g).unwrap();
            }
        }
        chain
    }

    /// Sparse polynomials (remainders that drop several degrees at once),
    /// repeated factors, and coefficients of 40 digits: every term of the
    /// subresultant chain has the sign of the primitive chain's term at
    /// every point tried, so both count the same roots everywhere.
    #[test]
    fn the_subresultant_chain_has_the_signs_of_the_primitive_one() {
        let mut g = Lcg(77);
        let huge = big("1000000000000000000000000000000000000007");
        for round in 0..300 {
            let deg = 2 + g.next() as usize % 11;
            let mut c: Vec<Int> = (0..=deg)
                .map(|_| {
                    let v = if g.next().is_multiple_of(3) {
                        0
                    } else {
                        g.small(9)
                    };
                    Int::from(v)
                })
                .collect();
            if c[deg].is_zero() {
                c[deg] = Int::from(-2);
            }
            if round % 2 == 1 {
                c = c
                    .iter()
                    .map(|v| &(v * &huge) + &Int::from(g.small(3)))
                    .collect();
            }
            let mut p = UPoly::new(c);
            if g.next().is_multiple_of(3) {
                p = &p * &up(&[g.small(4), 1 + g.next() as i64 % 3]).pow(2);
            }
            let (new, old) = (sturm_chain(&p), primitive_sturm_chain(&p));
            assert_eq!(new.len(), old.len(), "{p:?}");
            for _ in 0..12 {
                let x = Rat::new(Int::from(g.small(40)), Int::from(1 + g.next() as i64 % 9));
                for (a, b) in new.iter().zip(&old) {
                    assert_eq!(a.sign_at(&x), b.sign_at(&x), "{p:?} at {x}");
                }
            }
            for (a, b) in new.iter().zip(&old) {
                assert_eq!(a.degree(), b.degree());
                assert_eq!(
                    a.leading_coeff().is_negative(),
                    b.leading_coeff().is_negative()
                );
            }
        }
    }

    /// Descartes' count in an interval against Sturm's: random
    /// polynomials with repeated factors and roots planted at the ends of
    /// the interval and at its midpoint, intervals of every width.
    #[test]
    fn roots_in_an_interval_by_descartes_agree_with_sturm() {
        let mut g = Lcg(4242);
        for round in 0..400 {
            let deg = 1 + g.next() as usize % 9;
            let mut c: Vec<i64> = (0..=deg).map(|_| g.small(12)).collect();
            if c[deg] == 0 {
                c[deg] = 1;
            }
            let lo = Rat::new(Int::from(g.small(30)), Int::from(1 + g.next() as i64 % 7));
            let hi = &lo
                + &Rat::new(
                    Int::from(1 + g.next() as i64 % 40),
                    Int::from(1 + g.next() as i64 % 9),
                );
            let mut p = up(&c);
            for planted in [&lo, &hi, &mid(&lo, &hi)] {
                match g.next() % 4 {
                    0 => p = &p * &UPoly::linear_root(planted),
                    1 => p = &p * &UPoly::linear_root(planted).pow(2),
                    _ => {}
                }
            }
            if round % 3 == 0 {
                p = &p * &up(&[g.small(6), 1 + g.next() as i64 % 4]).pow(2);
            }
            let want = SturmSequence::new(&p).count_in(&lo, &hi);
            assert_eq!(count_roots_in(&p, &lo, &hi), want, "{p:?} in ({lo}, {hi}]");
            assert_eq!(count_roots_in(&p, &hi, &lo), 0);
        }
        // 60 roots in (0, 1]: i / 60.
        let p = (1..=60).fold(UPoly::one(), |acc, i| &acc * &lin(&format!("{i}/60")));
        assert_eq!(count_roots_in(&p, &Rat::ZERO, &Rat::ONE), 60);
        assert_eq!(count_roots_in(&p, &q("1/60"), &q("59/60")), 58);
    }

    #[test]
    fn sturm_counts_by_hand() {
        // (x - 1)^3 (x + 2)(x^2 + 1)
        let p = product(&[(lin("1"), 3), (lin("-2"), 1), (up(&[1, 0, 1]), 1)]);
        assert_eq!(count_real_roots(&p), 2);
        assert_eq!(count_roots_in(&p, &q("-3"), &q("0")), 1);
        assert_eq!(count_roots_in(&p, &q("0"), &q("1")), 1);
        assert_eq!(count_roots_in(&p, &q("1"), &q("5")), 0);
        assert_eq!(count_roots_in(&p, &q("-2"), &q("1")), 1);
        assert_eq!(count_roots_in(&p, &q("-5"), &q("-2")), 1);
        assert_eq!(count_roots_in(&p, &q("5"), &q("-5")), 0);
        assert_eq!(count_roots_in(&UPoly::zero(), &q("-5"), &q("5")), 0);
    }

    #[test]
    fn interleaving_in_hand_known_order() {
        // num = (x - 1)(x - 3), den = x (x - 2)(x - 4): R A R A R.
        let num = &lin("1") * &lin("3");
        let den = &(&UPoly::x() * &lin("2")) * &lin("4");
        let s = interleave_roots(&[num.clone(), den.clone()]);
        let m: Vec<Vec<u32>> = s.iter().map(|r| r.multiplicities.clone()).collect();
        assert_eq!(m, [[0, 1], [1, 0], [0, 1], [1, 0], [0, 1]]);
        for (k, r) in s.iter().enumerate() {
            let x = Rat::from(k as i64);
            assert!(r.lo == x && r.hi == x || (r.lo < x && x < r.hi));
        }
        // Shared and repeated roots: num = (x - 2)^2 (x^2 - 3), den = (x - 2)(x + 1)^3 (x^2 - 5).
        let num = &lin("2").pow(2) * &up(&[-3, 0, 1]);
        let den = &(&lin("2") * &lin("-1").pow(3)) * &up(&[-5, 0, 1]);
        let s = interleave_roots(&[num.clone(), den.clone(), UPoly::zero(), UPoly::one()]);
        let m: Vec<Vec<u32>> = s.iter().map(|r| r.multiplicities.clone()).collect();
        // -sqrt5 < -sqrt3 < -1 < sqrt3 < 2 < sqrt5
        assert_eq!(
            m,
            [
                [0, 1, 0, 0],
                [1, 0, 0, 0],
                [0, 3, 0, 0],
                [1, 0, 0, 0],
                [2, 1, 0, 0],
                [0, 1, 0, 0]
            ]
        );
        for w in s.windows(2) {
            assert!(w[0].hi <= w[1].lo);
        }
        let all = &num * &den;
        let sqf = all.square_free_part();
        for r in &s {
            if r.is_exact() {
                assert_eq!(all.sign_at(&r.lo), 0);
            } else {
                assert!(sqf.sign_at(&r.lo) * sqf.sign_at(&r.hi) < 0);
                assert_eq!(count_roots_in(&all, &r.lo, &r.hi), 1);
            }
        }
        assert_eq!(s.len(), count_real_roots(&all));
        // The paper's collocated two-mass system (m1 = 1, m2 = 2, c12 = 3):
        // Num = m2 W - c12, Den = W (m1 m2 W - c12 (m1 + m2)); roots 3/2 and
        // 0, 9/2: the positive part reads "A R".
        let num = up(&[-3, 2]);
        let den = up(&[0, -9, 2]);
        let s = interleave_roots(&[num, den]);
        let kind: String = s
            .iter()
            .filter(|r| r.is_positive())
            .map(|r| if r.multiplicities[0] > 0 { 'A' } else { 'R' })
            .collect();
        assert_eq!(kind, "AR");
        assert!(s[0].is_exact() && s[0].lo.is_zero() && !s[0].is_positive());
        // Roots 10^-30 apart in different polynomials: A R.
        let e = Int::from(10).pow(30);
        let near = UPoly::new(vec![-(&e + &Int::ONE), e]);
        let mut s = interleave_roots(&[lin("1"), near.clone()]);
        let m: Vec<Vec<u32>> = s.iter().map(|r| r.multiplicities.clone()).collect();
        assert_eq!(m, [[1, 0], [0, 1]]);
        let polys = [lin("1"), near];
        s[1].refine(&polys, &q("1/1000")).unwrap();
        assert!(s[1].lo > Rat::ONE);
        assert!(interleave_roots(&[]).is_empty());
        assert!(interleave_roots(&[up(&[1, 0, 1])]).is_empty());
    }

    #[test]
    fn positive_roots_and_nonpositive_count() {
        // (x + 1)^2 (x - 2)^3 (x^2 + x + 1) x (4x - 1)
        let p = product(&[
            (lin("-1"), 2),
            (lin("2"), 3),
            (up(&[1, 1, 1]), 1),
            (UPoly::x(), 1),
            (lin("1/4"), 1),
        ]);
        let r = positive_roots(&p);
        assert_eq!(mults(&r), [1, 3]);
        assert!(contains(&r[0], &q("1/4")) && contains(&r[1], &q("2")));
        assert_eq!(count_nonpositive_or_nonreal(&p), 9 - 4);
        // Independent: Sturm on (0, oo) counts distinct positive roots.
        let bound = Rat::from(1000);
        assert_eq!(count_roots_in(&p, &Rat::ZERO, &bound), r.len());
        assert_eq!(count_nonpositive_or_nonreal(&UPoly::zero()), 0);
    }
}
