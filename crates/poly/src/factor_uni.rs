//! Factorization of univariate polynomials over Z (Zassenhaus).
//!
//! [`factor_univariate`] splits a [`UPoly`] into its content (with sign) and
//! irreducible primitive factors with multiplicities:
//!
//! 1. content and sign, powers of `x`, square-free decomposition (Yun, only
//!    when an image modulo a prime shows that the input is not square-free);
//! 2. for each square-free part: degree <= 1 is irreducible, degree 2 is
//!    decided by the discriminant; otherwise several primes `p` (fixed list,
//!    `p` not dividing the leading coefficient, square-free image) are tried,
//!    the image is factored modulo each of them (distinct-degree factorization
//!    then Cantor-Zassenhaus equal-degree splitting with a fixed-seed PRNG),
//!    and the prime with the fewest factors is kept. The possible degrees of
//!    true factors (subset sums of the modular factor degrees, intersected
//!    over all primes) often prove irreducibility at once;
//! 3. multifactor quadratic Hensel lifting (factor tree) modulo `p^k > 2B`,
//!    `B = 2^(n-1) ||f||_2` (Mignotte/Landau: every factor `h` of `f` has
//!    `||lc(f)/lc(h) h||_inf <= 2^deg(h) ||f||_2`);
//! 4. Zassenhaus recombination: subsets of the lifted factors by increasing
//!    size, pruned by the degree set and a constant-term divisibility test,
//!    confirmed by exact division over Z. What is left is irreducible.
//!
//! All arithmetic is exact; modular arithmetic uses `u64` residues with
//! `u128` products, lifting uses big integers.

use crate::int::Int;
use crate::rat::Rat;
use crate::upoly::UPoly;
use num_bigint::BigInt;
use num_integer::Integer;
use num_traits::{One, Signed, ToPrimitive, Zero};

/// Factors a univariate polynomial over Z into irreducibles.
///
/// Returns `(c, [(f1, e1), ...])` with `p = c * prod fi^ei`, where `c` is the
/// content of `p` carrying the sign of its leading coefficient, and the `fi`
/// are distinct irreducible primitive polynomials of positive degree with
/// positive leading coefficients. Factors are sorted by degree, then by
/// their coefficients compared from the leading one down. The zero polynomial gives
/// `(0, [])` and a constant `c` gives `(c, [])`.
///
/// ```
/// use poly::{factor_univariate, Int, UPoly};
/// // -2 (x - 1)^2 (x^2 + x + 1) = -2 (x - 1) (x^3 - 1)
/// let x1 = UPoly::from_i64s(&[-1, 1]);
/// let x3 = UPoly::from_i64s(&[-1, 0, 0, 1]);
/// let p = (&x1 * &x3).scale(&Int::from(-2));
/// let (c, fs) = factor_univariate(&p);
/// assert_eq!(c, Int::from(-2));
/// assert_eq!(fs, vec![(x1, 2), (UPoly::from_i64s(&[1, 1, 1]), 1)]);
/// ```
pub fn factor_univariate(p: &UPoly) -> (Int, Vec<(UPoly, u32)>) {
    if p.is_zero() {
        return (Int::ZERO, Vec::new());
    }
    let coeffs = p.coeffs();
    let mut content = z_content(coeffs);
    if coeffs.last().is_some_and(|c| c.is_negative()) {
        content = -content;
    }
    let mut out: Vec<(Vec<Int>, u32)> = Vec::new();
    let mut f: Vec<Int> = coeffs.iter().map(|c| c.div_exact(&content)).collect();
    // Powers of x.
    let v = f.iter().take_while(|c| c.is_zero()).count();
    if v > 0 {
        out.push((vec![Int::ZERO, Int::ONE], v as u32));
        f.drain(..v);
    }
    if f.len() > 1 {
        for (part, e) in square_free_parts(&f) {
            for g in factor_squarefree(&part) {
                out.push((g, e));
            }
        }
    }
    out.sort_by(|a, b| cmp_zpoly(&a.0, &b.0));
    (
        content,
        out.into_iter().map(|(c, e)| (UPoly::new(c), e)).collect(),
    )
}

/// The distinct rational roots of a univariate polynomial over Z, in
/// increasing order.
///
/// Only the linear factors are sought, so no recombination is needed: the
/// roots modulo a prime `p` (where the polynomial stays square-free) come
/// from `gcd(f, x^p - x)` split by Cantor-Zassenhaus, each is lifted by
/// Newton's iteration modulo `p^(2^j)` until the modulus exceeds twice the
/// bound `|lc| + max |a_i|` on `lc * root`, and a candidate is kept only if
/// the polynomial vanishes there exactly. When `f` has no root modulo `p`
/// it has no rational root, which is the common case and costs one modular
/// power. The zero polynomial has no listed roots.
///
/// ```
/// use poly::{rational_roots, Rat, UPoly};
/// // (2x - 3)(x^2 + 1)(x + 5)^2: the roots 3/2 and -5.
/// let p = &(&UPoly::from_i64s(&[-3, 2]) * &UPoly::from_i64s(&[1, 0, 1]))
///     * &UPoly::from_i64s(&[5, 1]).pow(2);
/// let roots = rational_roots(&p);
/// assert_eq!(roots, vec![Rat::from(-5), "3/2".parse().unwrap()]);
/// ```
pub fn rational_roots(p: &UPoly) -> Vec<Rat> {
    if p.is_zero() {
        return Vec::new();
    }
    let mut f = z_primitive(p.coeffs());
    let mut roots = Vec::new();
    let v = f.iter().take_while(|c| c.is_zero()).count();
    if v > 0 {
        roots.push(Rat::ZERO);
        f.drain(..v);
    }
    if f.len() > 1 {
        let found = match nonzero_roots_modular(&f) {
            Some(r) => r,
            // Not square-free modulo the primes tried: its square-free part
            // has the same roots and is square-free modulo almost all.
            None => {
                let part = UPoly::new(f.clone()).square_free_part();
                nonzero_roots_modular(&z_primitive(part.coeffs()))
                    .unwrap_or_else(|| roots_from_factors(&part))
            }
        };
        roots.extend(found);
    }
    roots.sort();
    roots.dedup();
    roots
}

/// The rational roots of `f` (primitive, `f(0) != 0`, degree >= 1) by
/// lifting its roots modulo a prime; `None` if `f` is square-free modulo
/// none of the primes tried.
fn nonzero_roots_modular(f: &[Int]) -> Option<Vec<Rat>> {
    let lc = f.last().expect("degree >= 1");
    // A small prime: x^p mod f takes log2(p) squarings, and the lifting
    // doubles the digits at each step whatever p is.
    let p = (1009u64..20_000)
        .step_by(2)
        .filter(|&p| is_prime(p) && lc.rem_u64(p) != 0)
        // A square-free f is square-free modulo all primes but the few
        // dividing its discriminant: three failures say f has a square
        // factor, and each try costs a reduction and a gcd of full degree.
        .take(3)
        .find(|&p| Fp::new(p).is_squarefree(&Fp::new(p).reduce_z(f)))?;
    let fp = Fp::new(p);
    let a = fp.monic(&fp.reduce_z(f));
    let h = fp.powmod(&[0, 1], p, &a);
    let linear = fp.gcd(&a, &fp.sub_poly(&h, &[0, 1]));
    if linear.len() < 2 {
        return Some(Vec::new());
    }
    let mut factors = Vec::new();
    fp.edf(&linear, 1, &mut SplitMix(0x5EED ^ p), &mut factors);
    // |lc * root| <= |lc| + max |a_i| (Cauchy's bound times |lc|).
    let largest = f.iter().map(|c| c.abs()).max().expect("non-empty");
    let bound = (&lc.abs() + &largest).to_big() * 2u32;
    let fz: Vec<BigInt> = f.iter().map(|c| c.to_big()).collect();
    let dz: Vec<BigInt> = fz
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, c)| c * BigInt::from(i))
        .collect();
    let horner = |c: &[BigInt], x: &BigInt, m: &BigInt| -> BigInt {
        c.iter()
            .rev()
            .fold(BigInt::zero(), |acc, k| bmod(&(acc * x + k), m))
    };
    let lcz = lc.to_big();
    let exact = UPoly::new(f.to_vec());
    let mut out = Vec::new();
    for g in factors {
        // g = x + c: the root -c.
        let r0 = fp.sub(0, g[0]);
        let d0 = fp
            .reduce_z(&f[1..])
            .iter()
            .enumerate()
            .fold(0u64, |acc, (i, c)| {
                // f'(r0) mod p from the coefficients i * a_i.
                let term = fp.mul(fp.mul(*c, (i as u64 + 1) % p), pow_mod(r0, i as u64, fp));
                (acc + term) % p
            });
        // Newton's step with the inverse of f'(r) carried along by its own
        // Newton step (s <- s (2 - f'(r) s)), so no extended Euclid.
        let mut r = BigInt::from(r0);
        let mut s = BigInt::from(fp.inv(d0));
        let mut m = BigInt::from(p);
        while m <= bound {
            m = &m * &m;
            r = bmod(&(&r - horner(&fz, &r, &m) * &s), &m);
            let ds = horner(&dz, &r, &m) * &s;
            s = bmod(&(&s * (BigInt::from(2) - ds)), &m);
        }
        let half = &m >> 1;
        let y = symmetric(&(&lcz * &r), &m, &half);
        let candidate = Rat::new(Int::from(y), lc.clone());
        if exact.sign_at(&candidate) == 0 {
            out.push(candidate);
        }
    }
    Some(out)
}

/// `x^e` modulo `p`.
fn pow_mod(x: u64, mut e: u64, fp: Fp) -> u64 {
    let (mut base, mut acc) = (x, 1u64);
    while e > 0 {
        if e & 1 == 1 {
            acc = fp.mul(acc, base);
        }
        base = fp.mul(base, base);
        e >>= 1;
    }
    acc
}

/// The rational roots from a full factorization: the fallback of
/// [`rational_roots`] for inputs no listed prime keeps square-free.
fn roots_from_factors(p: &UPoly) -> Vec<Rat> {
    factor_univariate(p)
        .1
        .iter()
        .filter(|(g, _)| g.degree() == Some(1))
        .map(|(g, _)| Rat::new(-g.coeff(0).clone(), g.coeff(1).clone()))
        .collect()
}

/// Deterministic order of integer polynomials: degree, then coefficients
/// from the leading one down.
pub(crate) fn cmp_zpoly(a: &[Int], b: &[Int]) -> std::cmp::Ordering {
    a.len()
        .cmp(&b.len())
        .then_with(|| a.iter().rev().cmp(b.iter().rev()))
}

/// Square-free decomposition of a primitive polynomial with positive leading
/// coefficient and non-zero constant term: `[(part, multiplicity)]`.
fn square_free_parts(f: &[Int]) -> Vec<(Vec<Int>, u32)> {
    if is_squarefree_mod_some_prime(f) {
        return vec![(f.to_vec(), 1)];
    }
    UPoly::new(f.to_vec())
        .square_free()
        .into_iter()
        .map(|(u, e)| (u.coeffs().to_vec(), e))
        .collect()
}

/// True when the image of `f` modulo one of a few primes not dividing the
/// leading coefficient is square-free (which proves `f` square-free). A
/// `false` answer proves nothing.
pub(crate) fn is_squarefree_mod_some_prime(f: &[Int]) -> bool {
    if f.len() <= 2 {
        return true;
    }
    let lc = f.last().expect("non-zero");
    for &p in &[
        2305843009213693951u64,
        4611686018427387847,
        1000000007,
        998244353,
    ] {
        if lc.rem_u64(p) == 0 {
            continue;
        }
        let fp = Fp::new(p);
        let a = fp.reduce_z(f);
        if fp.is_squarefree(&a) {
            return true;
        }
    }
    false
}

/// Factors a square-free primitive polynomial of positive degree (positive
/// leading coefficient) into irreducible primitive factors with positive
/// leading coefficients, in the order of [`cmp_zpoly`].
pub(crate) fn factor_squarefree(f: &[Int]) -> Vec<Vec<Int>> {
    let mut f = z_primitive(f);
    let mut out = Vec::new();
    let v = f.iter().take_while(|c| c.is_zero()).count();
    if v > 0 {
        out.push(vec![Int::ZERO, Int::ONE]);
        f.drain(..v);
    }
    if f.len() > 1 {
        out.extend(factor_sqfree_core(&f));
    }
    out.sort_by(|a, b| cmp_zpoly(a, b));
    out
}

/// Core of the factorization: `f` primitive, square-free, positive leading
/// coefficient, degree >= 1, `f(0) != 0`.
fn factor_sqfree_core(f: &[Int]) -> Vec<Vec<Int>> {
    let n = f.len() - 1;
    if n == 1 {
        return vec![f.to_vec()];
    }
    if n == 2 {
        return factor_quadratic(f);
    }
    // Choose a prime.
    let Some(choice) = choose_prime(f) else {
        // Unreachable for a square-free f (all but finitely many primes are
        // good and the list is long); be safe and report f unsplit only if
        // no prime works, which cannot happen for square-free input.
        return vec![f.to_vec()];
    };
    if choice.factors.len() == 1 || choice.proven_irreducible {
        return vec![f.to_vec()];
    }
    let p = choice.p;
    // Lifting bound: p^k > 2 * 2^n * ||f||_2 (one extra bit of margin).
    let mut norm2 = BigInt::zero();
    for c in f {
        let b = c.to_big();
        norm2 += &b * &b;
    }
    let bound: BigInt = (norm2.sqrt() + 1u32) << (n + 1);
    let pb = BigInt::from(p);
    let mut k = 1u32;
    let mut pk = pb.clone();
    while pk <= bound {
        pk *= &pb;
        k += 1;
    }
    let fz: Vec<BigInt> = f.iter().map(|c| c.to_big()).collect();
    let lifted = hensel_lift(&fz, &choice.factors, p, k);
    recombine(fz, lifted, &pk, &choice.allowed)
}

/// Degree-2 case: reducible iff the discriminant is a perfect square.
fn factor_quadratic(f: &[Int]) -> Vec<Vec<Int>> {
    let (c, b, a) = (&f[0], &f[1], &f[2]);
    let disc = &(b * b) - &(&Int::from(4) * &(a * c));
    if disc.is_negative() {
        return vec![f.to_vec()];
    }
    let s = disc.isqrt();
    if &s * &s != disc {
        return vec![f.to_vec()];
    }
    // Roots (-b +- s) / (2a): factors 2a x + b -+ s, made primitive.
    let two_a = &Int::from(2) * a;
    let g1 = z_primitive(&[b - &s, two_a.clone()]);
    let g2 = z_primitive(&[b + &s, two_a]);
    let mut v = vec![g1, g2];
    v.sort_by(|x, y| cmp_zpoly(x, y));
    v
}

// ---------------------------------------------------------------------------
// Z[x] helpers on coefficient vectors (lowest degree first).

/// Gcd of the coefficients (non-negative).
pub(crate) fn z_content(a: &[Int]) -> Int {
    let mut g = Int::ZERO;
    for c in a {
        g = g.gcd(c);
        if g.is_one() {
            break;
        }
    }
    g
}

/// Primitive part with positive leading coefficient.
pub(crate) fn z_primitive(a: &[Int]) -> Vec<Int> {
    let mut g = z_content(a);
    if g.is_zero() {
        return a.to_vec();
    }
    if a.last().is_some_and(|c| c.is_negative()) {
        g = -g;
    }
    if g.is_one() {
        return a.to_vec();
    }
    a.iter().map(|c| c.div_exact(&g)).collect()
}

/// Exact division in Z[x]: `Some(q)` with `a = q b`, else `None`.
fn big_div_exact(a: &[BigInt], b: &[BigInt]) -> Option<Vec<BigInt>> {
    let (na, nb) = (a.len(), b.len());
    if nb == 0 {
        return None;
    }
    if na < nb {
        return if a.iter().all(|c| c.is_zero()) {
            Some(Vec::new())
        } else {
            None
        };
    }
    // Quick rejection: constant terms.
    if !b[0].is_zero() && !(&a[0] % &b[0]).is_zero() {
        return None;
    }
    let lb = &b[nb - 1];
    let mut r = a.to_vec();
    let mut q = vec![BigInt::zero(); na - nb + 1];
    for i in (0..=na - nb).rev() {
        let c = &r[i + nb - 1];
        if c.is_zero() {
            continue;
        }
        let (qc, rem) = c.div_rem(lb);
        if !rem.is_zero() {
            return None;
        }
        for j in 0..nb {
            r[i + j] -= &qc * &b[j];
        }
        q[i] = qc;
    }
    if r.iter().any(|c| !c.is_zero()) {
        return None;
    }
    Some(q)
}

// ---------------------------------------------------------------------------
// Arithmetic modulo a word-size prime.

/// The field Z/p for an odd prime `p < 2^63`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fp {
    p: u64,
}

/// Dense polynomial over Z/p, lowest degree first, no trailing zeros.
pub(crate) type Pp = Vec<u64>;

impl Fp {
    pub(crate) fn new(p: u64) -> Fp {
        Fp { p }
    }
    pub(crate) fn p(&self) -> u64 {
        self.p
    }
    #[inline]
    pub(crate) fn sub(&self, a: u64, b: u64) -> u64 {
        if a >= b {
            a - b
        } else {
            a + self.p - b
        }
    }
    #[inline]
    pub(crate) fn mul(&self, a: u64, b: u64) -> u64 {
        if self.p <= u32::MAX as u64 {
            (a * b) % self.p
        } else {
            ((a as u128 * b as u128) % self.p as u128) as u64
        }
    }
    /// Inverse of a non-zero residue.
    pub(crate) fn inv(&self, a: u64) -> u64 {
        // Extended Euclid (p prime, a != 0 mod p).
        let (mut r0, mut r1) = (self.p as i128, (a % self.p) as i128);
        let (mut s0, mut s1) = (0i128, 1i128);
        while r1 != 0 {
            let q = r0 / r1;
            (r0, r1) = (r1, r0 - q * r1);
            (s0, s1) = (s1, s0 - q * s1);
        }
        debug_assert_eq!(r0, 1, "inverse of a unit");
        s0.rem_euclid(self.p as i128) as u64
    }
    pub(crate) fn reduce_z(&self, a: &[Int]) -> Pp {
        let mut v: Pp = a.iter().map(|c| c.rem_u64(self.p)).collect();
        trim(&mut v);
        v
    }
    fn mul_poly(&self, a: &[u64], b: &[u64]) -> Pp {
        if a.is_empty() || b.is_empty() {
            return Vec::new();
        }
        let mut acc = vec![0u128; a.len() + b.len() - 1];
        let p = self.p as u128;
        // Accumulate with occasional reduction (products < 2^126).
        for (i, &x) in a.iter().enumerate() {
            if x == 0 {
                continue;
            }
            for (j, &y) in b.iter().enumerate() {
                let t = acc[i + j] + x as u128 * y as u128;
                acc[i + j] = if t >= p << 64 { t % p } else { t };
            }
        }
        let mut v: Pp = acc.into_iter().map(|c| (c % p) as u64).collect();
        trim(&mut v);
        v
    }
    fn sub_poly(&self, a: &[u64], b: &[u64]) -> Pp {
        let n = a.len().max(b.len());
        let mut v: Pp = (0..n)
            .map(|i| {
                self.sub(
                    a.get(i).copied().unwrap_or(0),
                    b.get(i).copied().unwrap_or(0),
                )
            })
            .collect();
        trim(&mut v);
        v
    }
    /// Quotient and remainder; `b` non-zero.
    fn divrem(&self, a: &[u64], b: &[u64]) -> (Pp, Pp) {
        let nb = b.len();
        if a.len() < nb {
            return (Vec::new(), a.to_vec());
        }
        let inv = self.inv(b[nb - 1]);
        let mut r = a.to_vec();
        let mut q = vec![0u64; a.len() - nb + 1];
        for i in (0..q.len()).rev() {
            let c = r[i + nb - 1];
            if c == 0 {
                continue;
            }
            let qc = self.mul(c, inv);
            q[i] = qc;
            for j in 0..nb {
                r[i + j] = self.sub(r[i + j], self.mul(qc, b[j]));
            }
        }
        trim(&mut r);
        trim(&mut q);
        (q, r)
    }
    fn rem(&self, a: &[u64], b: &[u64]) -> Pp {
        self.divrem(a, b).1
    }
    fn monic(&self, a: &[u64]) -> Pp {
        match a.last() {
            None => Vec::new(),
            Some(&l) => {
                let inv = self.inv(l);
                a.iter().map(|&c| self.mul(c, inv)).collect()
            }
        }
    }
    /// Monic gcd (zero for two zeros).
    fn gcd(&self, a: &[u64], b: &[u64]) -> Pp {
        let (mut a, mut b) = (a.to_vec(), b.to_vec());
        while !b.is_empty() {
            let r = self.rem(&a, &b);
            a = b;
            b = r;
        }
        self.monic(&a)
    }
    /// `(s, t)` with `s a + t b = 1` for coprime `a`, `b`, `deg s < deg b`,
    /// `deg t < deg a`.
    fn bezout(&self, a: &[u64], b: &[u64]) -> (Pp, Pp) {
        // Extended Euclid tracking the cofactor of a only.
        let (mut r0, mut r1) = (a.to_vec(), b.to_vec());
        let (mut s0, mut s1): (Pp, Pp) = (vec![1], Vec::new());
        while !r1.is_empty() {
            let (q, r) = self.divrem(&r0, &r1);
            let s2 = self.sub_poly(&s0, &self.mul_poly(&q, &s1));
            r0 = r1;
            r1 = r;
            s0 = s1;
            s1 = s2;
        }
        // r0 is a non-zero constant (coprime inputs).
        let inv = self.inv(r0[0]);
        let s: Pp = s0.iter().map(|&c| self.mul(c, inv)).collect();
        let s = self.rem(&s, b);
        // t = (1 - s a) / b
        let num = self.sub_poly(&[1], &self.mul_poly(&s, a));
        let (t, _) = self.divrem(&num, b);
        (s, t)
    }
    fn derivative(&self, a: &[u64]) -> Pp {
        let mut v: Pp = a
            .iter()
            .enumerate()
            .skip(1)
            .map(|(i, &c)| self.mul(c, i as u64 % self.p))
            .collect();
        trim(&mut v);
        v
    }
    /// True if `a` (degree preserved, i.e. leading coefficient non-zero) is
    /// square-free over Z/p.
    pub(crate) fn is_squarefree(&self, a: &[u64]) -> bool {
        let d = self.derivative(a);
        if d.is_empty() {
            return a.len() <= 1;
        }
        self.gcd(a, &d).len() == 1
    }
    /// `b^e mod m`.
    fn powmod(&self, b: &[u64], mut e: u64, m: &[u64]) -> Pp {
        let mut result: Pp = self.rem(&[1], m);
        let mut base = self.rem(b, m);
        while e > 0 {
            if e & 1 == 1 {
                result = self.rem(&self.mul_poly(&result, &base), m);
            }
            e >>= 1;
            if e > 0 {
                base = self.rem(&self.mul_poly(&base, &base), m);
            }
        }
        result
    }

    /// Distinct-degree factorization of a monic square-free `f`:
    /// `[(product of the irreducible factors of degree d, d)]`.
    fn ddf(&self, f: &[u64]) -> Vec<(Pp, usize)> {
        let mut out = Vec::new();
        let mut f = f.to_vec();
        let x: Pp = vec![0, 1];
        let mut h = self.rem(&x, &f);
        let mut d = 0usize;
        while f.len() > 2 * (d + 1) {
            d += 1;
            h = self.powmod(&h, self.p, &f);
            let g = self.gcd(&f, &self.sub_poly(&h, &x));
            if g.len() > 1 {
                f = self.divrem(&f, &g).0;
                h = self.rem(&h, &f);
                out.push((g, d));
            }
        }
        if f.len() > 1 {
            let d = f.len() - 1;
            out.push((f, d));
        }
        out
    }

    /// Equal-degree splitting (Cantor-Zassenhaus) of a monic `g` whose
    /// irreducible factors all have degree `d`.
    fn edf(&self, g: &[u64], d: usize, rng: &mut SplitMix, out: &mut Vec<Pp>) {
        let n = g.len() - 1;
        if n == d {
            out.push(g.to_vec());
            return;
        }
        loop {
            let mut a: Pp = (0..n).map(|_| rng.next() % self.p).collect();
            trim(&mut a);
            if a.len() < 2 {
                continue;
            }
            // s = a^(1 + p + ... + p^(d-1)) mod g, then s^((p-1)/2).
            let mut t = a.clone();
            let mut s = a.clone();
            for _ in 1..d {
                t = self.powmod(&t, self.p, g);
                s = self.rem(&self.mul_poly(&s, &t), g);
            }
            let mut b = self.powmod(&s, (self.p - 1) / 2, g);
            if b.is_empty() {
                b = vec![self.p - 1];
            } else {
                b[0] = self.sub(b[0], 1);
                trim(&mut b);
            }
            let h = self.gcd(&b, g);
            if h.len() > 1 && h.len() < g.len() {
                let q = self.divrem(g, &h).0;
                self.edf(&h, d, rng, out);
                self.edf(&q, d, rng, out);
                return;
            }
        }
    }

    /// Monic irreducible factors of a monic square-free `f`, sorted.
    pub(crate) fn factor_monic(&self, f: &[u64]) -> Vec<Pp> {
        let mut rng = SplitMix(0x9e37_79b9_7f4a_7c15 ^ self.p);
        let mut out = Vec::new();
        for (g, d) in self.ddf(f) {
            self.edf(&g, d, &mut rng, &mut out);
        }
        out.sort_by(|a, b| a.len().cmp(&b.len()).then_with(|| a.cmp(b)));
        out
    }
}

fn trim(v: &mut Vec<u64>) {
    while v.last() == Some(&0) {
        v.pop();
    }
}

/// A small deterministic PRNG (SplitMix64).
#[derive(Clone, Debug)]
pub(crate) struct SplitMix(pub(crate) u64);

impl SplitMix {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

// ---------------------------------------------------------------------------
// Choice of the prime.

struct PrimeChoice {
    p: u64,
    /// Monic irreducible factors of `f mod p`.
    factors: Vec<Pp>,
    /// `allowed[d]`: a true factor of degree `d` is possible by the degree
    /// patterns of all primes tried.
    allowed: Vec<bool>,
    proven_irreducible: bool,
}

fn is_prime(n: u64) -> bool {
    if n < 2 {
        return false;
    }
    let mut d = 2u64;
    while d * d <= n {
        if n.is_multiple_of(d) {
            return false;
        }
        d += 1;
    }
    true
}

/// Number of good primes examined before choosing.
const GOOD_PRIMES: usize = 6;

/// Tries primes in increasing order starting above the degree (so the image
/// is more likely square-free), keeps the one with the fewest modular
/// factors, and intersects the achievable degree sets.
fn choose_prime(f: &[Int]) -> Option<PrimeChoice> {
    let n = f.len() - 1;
    let lc = &f[n];
    let mut allowed = vec![true; n + 1];
    let mut best: Option<(u64, Vec<Pp>)> = None;
    let mut good = 0;
    let mut cand = 5u64.max(n as u64 + 1) | 1;
    let mut tried = 0;
    while good < GOOD_PRIMES && tried < 2000 {
        tried += 1;
        let p = cand;
        cand += 2;
        if !is_prime(p) || lc.rem_u64(p) == 0 {
            continue;
        }
        let fp = Fp::new(p);
        let a = fp.reduce_z(f);
        if !fp.is_squarefree(&a) {
            continue;
        }
        good += 1;
        let facs = fp.factor_monic(&fp.monic(&a));
        // Subset sums of the factor degrees.
        let mut sums = vec![false; n + 1];
        sums[0] = true;
        for g in &facs {
            let d = g.len() - 1;
            for s in (d..=n).rev() {
                if sums[s - d] {
                    sums[s] = true;
                }
            }
        }
        for (x, y) in allowed.iter_mut().zip(&sums) {
            *x = *x && *y;
        }
        let better = match &best {
            None => true,
            Some((_, b)) => facs.len() < b.len(),
        };
        if better {
            best = Some((p, facs));
        }
        if allowed[1..n].iter().all(|&x| !x) {
            break;
        }
        if best.as_ref().is_some_and(|(_, b)| b.len() == 1) {
            break;
        }
    }
    let (p, factors) = best?;
    let proven_irreducible = allowed[1..n].iter().all(|&x| !x);
    Some(PrimeChoice {
        p,
        factors,
        allowed,
        proven_irreducible,
    })
}

// ---------------------------------------------------------------------------
// Hensel lifting over Z/p^k with big integers.

type Bp = Vec<BigInt>;

fn bmod(a: &BigInt, m: &BigInt) -> BigInt {
    a.mod_floor(m)
}

fn bp_trim(v: &mut Bp) {
    while v.last().is_some_and(|c| c.is_zero()) {
        v.pop();
    }
}

fn bp_reduce(a: &[BigInt], m: &BigInt) -> Bp {
    let mut v: Bp = a.iter().map(|c| bmod(c, m)).collect();
    bp_trim(&mut v);
    v
}

fn bp_mul(a: &[BigInt], b: &[BigInt], m: &BigInt) -> Bp {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut v = vec![BigInt::zero(); a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        if x.is_zero() {
            continue;
        }
        for (j, y) in b.iter().enumerate() {
            v[i + j] += x * y;
        }
    }
    bp_reduce(&v, m)
}

fn bp_add(a: &[BigInt], b: &[BigInt], m: &BigInt) -> Bp {
    let n = a.len().max(b.len());
    let z = BigInt::zero();
    let v: Bp = (0..n)
        .map(|i| a.get(i).unwrap_or(&z) + b.get(i).unwrap_or(&z))
        .collect();
    bp_reduce(&v, m)
}

fn bp_sub(a: &[BigInt], b: &[BigInt], m: &BigInt) -> Bp {
    let n = a.len().max(b.len());
    let z = BigInt::zero();
    let v: Bp = (0..n)
        .map(|i| a.get(i).unwrap_or(&z) - b.get(i).unwrap_or(&z))
        .collect();
    bp_reduce(&v, m)
}

/// Division by a monic `b` modulo `m`: `(q, r)`.
fn bp_divrem_monic(a: &[BigInt], b: &[BigInt], m: &BigInt) -> (Bp, Bp) {
    let nb = b.len();
    if a.len() < nb {
        return (Vec::new(), a.to_vec());
    }
    let mut r = a.to_vec();
    let mut q = vec![BigInt::zero(); a.len() - nb + 1];
    for i in (0..q.len()).rev() {
        let c = bmod(&r[i + nb - 1], m);
        if c.is_zero() {
            continue;
        }
        for j in 0..nb {
            r[i + j] -= &c * &b[j];
        }
        q[i] = c;
    }
    bp_trim(&mut q);
    (q, bp_reduce(&r, m))
}

fn bp_from_pp(a: &[u64]) -> Bp {
    a.iter().map(|&c| BigInt::from(c)).collect()
}

fn bmod_inv(a: &BigInt, m: &BigInt) -> BigInt {
    // Extended Euclid; a is invertible modulo m by construction.
    let (mut r0, mut r1) = (bmod(a, m), m.clone());
    let (mut s0, mut s1) = (BigInt::one(), BigInt::zero());
    while !r1.is_zero() {
        let (q, r) = r0.div_rem(&r1);
        let s2 = &s0 - &q * &s1;
        r0 = r1;
        r1 = r;
        s0 = s1;
        s1 = s2;
    }
    bmod(&s0, m)
}

/// One quadratic Hensel step (von zur Gathen & Gerhard, Alg. 15.10): from
/// `f = g h`, `s g + t h = 1` modulo `m` to the same modulo `m2 | m^2`, with
/// `h` monic.
fn hensel_step(f: &[BigInt], g: &mut Bp, h: &mut Bp, s: &mut Bp, t: &mut Bp, m2: &BigInt) {
    let e = bp_sub(f, &bp_mul(g, h, m2), m2);
    let (q, r) = bp_divrem_monic(&bp_mul(s, &e, m2), h, m2);
    let g_new = bp_add(&bp_add(g, &bp_mul(t, &e, m2), m2), &bp_mul(&q, g, m2), m2);
    let h_new = bp_add(h, &r, m2);
    let b = bp_sub(
        &bp_add(&bp_mul(s, &g_new, m2), &bp_mul(t, &h_new, m2), m2),
        &[BigInt::one()],
        m2,
    );
    let (c, d) = bp_divrem_monic(&bp_mul(s, &b, m2), &h_new, m2);
    let s_new = bp_sub(s, &d, m2);
    let t_new = bp_sub(
        &bp_sub(t, &bp_mul(t, &b, m2), m2),
        &bp_mul(&c, &g_new, m2),
        m2,
    );
    *g = g_new;
    *h = h_new;
    *s = s_new;
    *t = t_new;
}

/// Lifts the monic modular factors of `f` (`f = lc(f) prod factors mod p`)
/// to monic factors modulo `p^k` with a factor tree.
fn hensel_lift(f: &[BigInt], factors: &[Pp], p: u64, k: u32) -> Vec<Bp> {
    // Moduli p^(e_i), e_0 = 1, doubling up to k.
    let pb = BigInt::from(p);
    let mut mods = vec![pb.clone()];
    let mut e = 1u32;
    while e < k {
        e = (2 * e).min(k);
        mods.push(pb.pow(e));
    }
    let m = mods.last().expect("non-empty").clone();
    let f = bp_reduce(f, &m);
    let mut out = Vec::new();
    lift_node(&f, factors, &Fp::new(p), &mods, &mut out);
    out
}

fn lift_node(f: &[BigInt], factors: &[Pp], fp: &Fp, mods: &[BigInt], out: &mut Vec<Bp>) {
    let m = mods.last().expect("non-empty");
    if factors.len() == 1 {
        let lc = f.last().expect("non-zero");
        let inv = bmod_inv(lc, m);
        let g: Bp = f.iter().map(|c| bmod(&(c * &inv), m)).collect();
        out.push(g);
        return;
    }
    let mid = factors.len() / 2;
    let (left, right) = factors.split_at(mid);
    let p = fp.p();
    let lcp = f.last().expect("non-zero").mod_floor(&BigInt::from(p));
    let lcp = lcp.to_u64().expect("residue");
    let mut g0: Pp = vec![lcp];
    for a in left {
        g0 = fp.mul_poly(&g0, a);
    }
    let mut h0: Pp = vec![1];
    for b in right {
        h0 = fp.mul_poly(&h0, b);
    }
    let (s0, t0) = fp.bezout(&g0, &h0);
    let (mut g, mut h, mut s, mut t) = (
        bp_from_pp(&g0),
        bp_from_pp(&h0),
        bp_from_pp(&s0),
        bp_from_pp(&t0),
    );
    for m2 in &mods[1..] {
        let fm = bp_reduce(f, m2);
        hensel_step(&fm, &mut g, &mut h, &mut s, &mut t, m2);
    }
    lift_node(&g, left, fp, mods, out);
    lift_node(&h, right, fp, mods, out);
}

// ---------------------------------------------------------------------------
// Recombination.

fn symmetric(a: &BigInt, m: &BigInt, half: &BigInt) -> BigInt {
    let r = a.mod_floor(m);
    if &r > half {
        r - m
    } else {
        r
    }
}

fn big_primitive(a: &[BigInt]) -> Bp {
    let mut g = BigInt::zero();
    for c in a {
        g = g.gcd(c);
        if g.is_one() {
            break;
        }
    }
    if g.is_zero() {
        return a.to_vec();
    }
    if a.last().is_some_and(|c| c.is_negative()) {
        g = -g;
    }
    a.iter().map(|c| c / &g).collect()
}

/// Zassenhaus recombination of the monic lifted factors of `f` modulo `m`.
fn recombine(mut f: Bp, mut lifted: Vec<Bp>, m: &BigInt, allowed: &[bool]) -> Vec<Vec<Int>> {
    let half = m / 2u32;
    let mut out: Vec<Vec<Int>> = Vec::new();
    let mut s = 1usize;
    'outer: while 2 * s <= lifted.len() {
        let r = lifted.len();
        let lc = f.last().expect("non-zero").clone();
        let target0 = &lc * &f[0];
        // Enumerate subsets of size s as index combinations.
        let mut idx: Vec<usize> = (0..s).collect();
        loop {
            let deg: usize = idx.iter().map(|&i| lifted[i].len() - 1).sum();
            if deg < allowed.len() && allowed[deg] {
                // Constant-term test.
                let mut c0 = lc.clone();
                for &i in &idx {
                    c0 = (c0 * &lifted[i][0]).mod_floor(m);
                }
                let c0 = symmetric(&c0, m, &half);
                if !c0.is_zero() && (&target0 % &c0).is_zero() {
                    let mut g: Bp = vec![lc.clone()];
                    for &i in &idx {
                        g = bp_mul(&g, &lifted[i], m);
                    }
                    let g: Bp = g.iter().map(|c| symmetric(c, m, &half)).collect();
                    let g = big_primitive(&g);
                    if let Some(q) = big_div_exact(&f, &g) {
                        out.push(g.iter().map(|c| Int::from(c.clone())).collect());
                        f = q;
                        let mut k = 0;
                        lifted.retain(|_| {
                            let keep = !idx.contains(&k);
                            k += 1;
                            keep
                        });
                        continue 'outer;
                    }
                }
            }
            // Next combination.
            let mut i = s;
            loop {
                if i == 0 {
                    s += 1;
                    continue 'outer;
                }
                i -= 1;
                if idx[i] < r - s + i {
                    idx[i] += 1;
                    for j in i + 1..s {
                        idx[j] = idx[j - 1] + 1;
                    }
                    break;
                }
            }
        }
    }
    if f.len() > 1 {
        let g = big_primitive(&f);
        out.push(g.iter().map(|c| Int::from(c.clone())).collect());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn up(c: &[i64]) -> UPoly {
        UPoly::from_i64s(c)
    }

    fn expand(c: &Int, fs: &[(UPoly, u32)]) -> UPoly {
        let mut acc = UPoly::constant(c.clone());
        for (f, e) in fs {
            acc = &acc * &f.pow(*e);
        }
        acc
    }

    /// x^n - 1.
    fn xn1(n: usize) -> UPoly {
        let mut v = vec![Int::ZERO; n + 1];
        v[0] = Int::from(-1);
        v[n] = Int::ONE;
        UPoly::new(v)
    }

    fn num_divisors(n: usize) -> usize {
        (1..=n).filter(|d| n.is_multiple_of(*d)).count()
    }

    /// Euler's phi.
    fn phi(n: usize) -> usize {
        (1..=n)
            .filter(|k| num_integer::Integer::gcd(k, &n) == 1)
            .count()
    }

    fn check(p: &UPoly) -> (Int, Vec<(UPoly, u32)>) {
        let (c, fs) = factor_univariate(p);
        assert_eq!(expand(&c, &fs), *p, "product of the factors");
        for (f, _) in &fs {
            assert!(f.leading_coeff() > Int::ZERO);
            assert_eq!(z_content(f.coeffs()), Int::ONE);
        }
        for w in fs.windows(2) {
            assert_eq!(
                cmp_zpoly(w[0].0.coeffs(), w[1].0.coeffs()),
                std::cmp::Ordering::Less
            );
        }
        (c, fs)
    }

    #[test]
    fn trivial_inputs() {
        assert_eq!(factor_univariate(&UPoly::zero()), (Int::ZERO, vec![]));
        assert_eq!(factor_univariate(&up(&[-7])), (Int::from(-7), vec![]));
        let (c, fs) = check(&up(&[0, 0, 6]));
        assert_eq!(c, Int::from(6));
        assert_eq!(fs, vec![(up(&[0, 1]), 2)]);
        let (c, fs) = check(&up(&[4, -6]));
        assert_eq!(c, Int::from(-2));
        assert_eq!(fs, vec![(up(&[-2, 3]), 1)]);
    }

    #[test]
    fn cyclotomic_counts() {
        for n in 1..=40 {
            let (c, fs) = check(&xn1(n));
            assert_eq!(c, Int::ONE);
            assert_eq!(fs.len(), num_divisors(n), "x^{n} - 1");
            let mut degs: Vec<usize> = fs.iter().map(|f| f.0.degree().unwrap()).collect();
            let mut want: Vec<usize> = (1..=n).filter(|d| n % d == 0).map(phi).collect();
            degs.sort();
            want.sort();
            assert_eq!(degs, want, "degrees of the cyclotomic factors of x^{n} - 1");
            assert!(fs.iter().all(|f| f.1 == 1));
        }
        // x^105 - 1: Phi_105 has coefficient -2.
        let (_, fs) = check(&xn1(105));
        assert_eq!(fs.len(), 8);
        assert!(fs.iter().any(|f| f.0.coeffs().contains(&Int::from(-2))));
    }

    #[test]
    fn x4_plus_1_is_irreducible() {
        let f = up(&[1, 0, 0, 0, 1]);
        let (_, fs) = check(&f);
        assert_eq!(fs, vec![(f.clone(), 1)]);
        // It splits modulo every prime, so this exercises recombination.
        let fp = Fp::new(17);
        assert_eq!(fp.factor_monic(&fp.reduce_z(f.coeffs())).len(), 4);
        // x^8 + 1 too, and (x^4+1)(x^4-x^2+1)(x^2+x+1) with repetition.
        let g = up(&[1, 0, -1, 0, 1]);
        let h = up(&[1, 1, 1]);
        let p = &(&f.pow(2) * &g) * &h.pow(3);
        let (_, fs) = check(&p);
        assert_eq!(fs, vec![(h, 3), (g, 1), (f, 2)]);
    }

    /// Product over all sign choices of (x - (+-sqrt(a1) +- ... +- sqrt(ak))),
    /// computed as an iterated resultant: s_{i+1}(x) = s_i(x + sqrt a) s_i(x - sqrt a).
    fn swinnerton_dyer(primes: &[i64]) -> UPoly {
        // Represent polys in x with coefficients in Z[sqrt a] as pairs.
        let mut s = up(&[0, 1]);
        for &a in primes {
            // s(x + y) with y^2 = a: sum_k s_k (x+y)^k; split even/odd powers of y.
            let n = s.degree().unwrap();
            let mut even = vec![Int::ZERO; n + 1];
            let mut odd = vec![Int::ZERO; n + 1];
            for (k, c) in s.coeffs().iter().enumerate() {
                // (x + y)^k = sum_j C(k,j) x^(k-j) y^j
                let mut binom = Int::ONE;
                for j in 0..=k {
                    let ypow = Int::from(a).pow((j / 2) as u32);
                    let term = &(&binom * c) * &ypow;
                    if j % 2 == 0 {
                        even[k - j] = &even[k - j] + &term;
                    } else {
                        odd[k - j] = &odd[k - j] + &term;
                    }
                    binom =
                        (&binom * &Int::from((k - j) as i64)).div_exact(&Int::from((j + 1) as i64));
                }
            }
            // (E + y O)(E - y O) = E^2 - a O^2
            let e = UPoly::new(even);
            let o = UPoly::new(odd);
            s = &(&e * &e) - &(&o * &o).scale(&Int::from(a));
        }
        s
    }

    #[test]
    fn swinnerton_dyer_polynomials_are_irreducible() {
        let s2 = swinnerton_dyer(&[2, 3]);
        assert_eq!(s2, up(&[1, 0, -10, 0, 1]));
        for ps in [&[2, 3, 5][..], &[2, 3, 5, 7][..]] {
            let s = swinnerton_dyer(ps);
            let (c, fs) = check(&s);
            assert_eq!(c, Int::ONE);
            assert_eq!(fs, vec![(s.clone(), 1)]);
        }
        // A product of two of them and a cyclotomic factor splits correctly.
        let a = swinnerton_dyer(&[2, 3, 5]);
        let b = swinnerton_dyer(&[3, 5, 7]);
        let c = up(&[1, -1, 1, -1, 1]);
        let (_, fs) = check(&(&(&a * &b) * &c));
        assert_eq!(fs.len(), 3);
        assert_eq!(fs[0].0, c);
        assert!(fs.iter().any(|f| f.0 == a) && fs.iter().any(|f| f.0 == b));
    }

    #[test]
    fn swinnerton_dyer_degree_32() {
        // Splits into factors of degree <= 2 modulo every prime: 16 modular
        // factors to recombine.
        let s = swinnerton_dyer(&[2, 3, 5, 7, 11]);
        assert_eq!(s.degree(), Some(32));
        let (_, fs) = check(&s);
        assert_eq!(fs, vec![(s, 1)]);
    }

    #[test]
    fn products_of_known_irreducibles() {
        // Irreducible by Eisenstein (p = 2, 3, 5) or degree <= 1, so the
        // factorization of their product is known in advance.
        let irr = [
            up(&[2, 0, 0, 0, 0, 1]),           // x^5 + 2
            up(&[3, 3, 0, 3, 1]),              // x^4 + 3x^3 + 3x + 3
            up(&[-5, 10, 5, 0, 0, 0, 0, 7]),   // 7x^7 + 5x^2 + 10x - 5
            up(&[6, -4, 2, 0, 0, 0, 0, 0, 3]), // 3x^8 + 2x^2 - 4x + 6 (Eisenstein at 2)
            up(&[-1, 2]),
            up(&[1, 3]),
        ];
        let mut rng = SplitMix(7);
        for round in 0..12 {
            let mut p = up(&[1]);
            let mut want: Vec<(UPoly, u32)> = Vec::new();
            for f in &irr {
                let e = (rng.next() % 3) as u32;
                if e > 0 {
                    p = &p * &f.pow(e);
                    want.push((f.clone(), e));
                }
            }
            let scale = Int::from(if round % 2 == 0 { -3 } else { 10 });
            let p = p.scale(&scale);
            let (c, mut fs) = check(&p);
            assert_eq!(c, scale);
            want.sort_by(|a, b| cmp_zpoly(a.0.coeffs(), b.0.coeffs()));
            fs.sort_by(|a, b| cmp_zpoly(a.0.coeffs(), b.0.coeffs()));
            assert_eq!(fs, want);
        }
    }

    #[test]
    fn big_coefficients_and_quadratics() {
        // (10^20 x - 3)(x^2 - 2)(x^2 - 10^30 + ...)
        let big: Int = "100000000000000000000".parse().unwrap();
        let a = UPoly::new(vec![Int::from(-3), big.clone()]);
        let b = up(&[-2, 0, 1]);
        let c = UPoly::new(vec![&big * &big, Int::from(1), Int::from(1)]);
        let (_, fs) = check(&(&(&a * &b) * &c));
        assert_eq!(fs.len(), 3);
        // Quadratic with rational roots: 6x^2 - x - 2 = (2x + 1)(3x - 2).
        let (_, fs) = check(&up(&[-2, -1, 6]));
        assert_eq!(fs, vec![(up(&[1, 2]), 1), (up(&[-2, 3]), 1)]);
    }

    #[test]
    fn many_linear_factors() {
        // prod_{k=-6..6, k != 0} (k x + 1) * (x - 7): 13 linear factors.
        let mut p = up(&[-7, 1]);
        for k in -6..=6i64 {
            if k != 0 {
                p = &p * &up(&[1, k]);
            }
        }
        let (c, fs) = check(&p);
        assert_eq!(fs.len(), 13);
        assert!(fs.iter().all(|f| f.0.degree() == Some(1) && f.1 == 1));
        assert!(c.abs().is_one());
    }

    #[test]
    fn rational_roots_match_the_linear_factors() {
        // Roots with large numerators and denominators, a repeated one, an
        // irreducible quadratic and cubic, and a root at zero.
        let big = Int::from(10).pow(30) + Int::from(7);
        let r1 = UPoly::new(vec![-&big, Int::from(3)]); // root big/3
        let r2 = up(&[5, -7]); // 5/7
        let p = &(&(&r1 * &r2.pow(3)) * &up(&[2, 0, 1])) * &up(&[-2, 0, 0, 1]);
        let p = &p * &up(&[0, 1]);
        let want = vec![
            Rat::ZERO,
            "5/7".parse().unwrap(),
            Rat::new(big, Int::from(3)),
        ];
        assert_eq!(rational_roots(&p), want);
        assert_eq!(
            roots_from_factors(&p),
            vec![Rat::ZERO, want[2].clone(), want[1].clone()]
        );
        // No rational root: x^4 + 1, and 2x^2 - 1.
        assert!(rational_roots(&up(&[1, 0, 0, 0, 1])).is_empty());
        assert!(rational_roots(&up(&[-1, 0, 2])).is_empty());
        assert!(rational_roots(&UPoly::zero()).is_empty());
        assert!(rational_roots(&up(&[4])).is_empty());
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]
        /// Against the full factorization, an independent route.
        #[test]
        fn rational_roots_agree_with_factorization(
            linear in proptest::collection::vec((-40i64..40, 1i64..30, 1u32..3), 0..6),
            other in proptest::collection::vec(-9i64..9, 0..5),
        ) {
            let mut p = up(&[1]);
            for (a, b, e) in &linear {
                p = &p * &up(&[-*a, *b]).pow(*e);
            }
            let mut q = other.clone();
            q.push(1);
            p = &p * &up(&q);
            let mut want = roots_from_factors(&p);
            want.sort();
            proptest::prop_assert_eq!(rational_roots(&p), want);
        }
    }
}
