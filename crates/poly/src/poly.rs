//! Sparse multivariate polynomials over Q with named variables.
//!
//! Invariants of [`Poly`] (every constructor and operation keeps them, so
//! derived equality is mathematical equality):
//! - `vars` is sorted by [`var_cmp`] and lists exactly the variables that
//!   occur with a positive exponent in some term;
//! - `terms` are sorted strictly descending in lexicographic order (the first
//!   variable most significant) and no coefficient is zero.

use crate::int::Int;
use crate::rat::Rat;
use std::cmp::Ordering;
use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::hash::{BuildHasherDefault, Hasher};
use std::ops::{Add, Mul, Neg, Sub};
use std::sync::Arc;

/// Order of variable names: alphabetic prefix, then the number that follows
/// it by value (`c2 < c12`), then the whole string. `Omega` sorts before the
/// lower-case parameter names, so polynomials in Omega print in powers of
/// Omega first.
pub fn var_cmp(a: &str, b: &str) -> Ordering {
    if a == b {
        return Ordering::Equal;
    }
    /// Alphabetic prefix, digit run (leading zeros stripped) and whether
    /// there is one, rest.
    fn split(s: &str) -> (&str, bool, &str, &str) {
        let bytes = s.as_bytes();
        let idx = bytes
            .iter()
            .position(|c| c.is_ascii_digit())
            .unwrap_or(s.len());
        let end = bytes[idx..]
            .iter()
            .position(|c| !c.is_ascii_digit())
            .map_or(s.len(), |k| idx + k);
        let digits = &s[idx..end];
        let trimmed = digits.trim_start_matches('0');
        (&s[..idx], !digits.is_empty(), trimmed, &s[end..])
    }
    let (pa, da, na, ra) = split(a);
    let (pb, db, nb, rb) = split(b);
    // Numbers beyond u128 compare as absent, as `str::parse` would have it.
    let fits =
        |t: &str| t.len() < 39 || (t.len() == 39 && t <= "340282366920938463463374607431768211455");
    let (da, db) = (da && fits(na), db && fits(nb));
    let num_cmp = match (da, db) {
        (false, false) => Ordering::Equal,
        (false, true) => Ordering::Less,
        (true, false) => Ordering::Greater,
        (true, true) => na.len().cmp(&nb.len()).then_with(|| na.cmp(nb)),
    };
    pa.cmp(pb)
        .then(num_cmp)
        .then_with(|| ra.cmp(rb))
        .then_with(|| a.cmp(b))
}

/// One term: exponents (one per variable of the owning polynomial) and a
/// non-zero coefficient.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Term {
    /// Exponent of each variable, in the order of [`Poly::vars`].
    pub exps: Vec<u32>,
    /// The coefficient, never zero inside a [`Poly`].
    pub coef: Rat,
}

/// A sparse multivariate polynomial over Q with named variables.
///
/// ```
/// use poly::Poly;
/// let p: Poly = "m1*m2*Omega^2 - (c12*m1 + c12*m2)*Omega".parse().unwrap();
/// let q = Poly::var("Omega");
/// let r = p.div_exact(&q).unwrap();
/// assert_eq!(r.to_string(), "Omega*m1*m2 - c12*m1 - c12*m2");
/// assert_eq!(r.degree("Omega"), 1);
/// ```
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Poly {
    vars: Arc<[String]>,
    terms: Vec<Term>,
}

fn lex_cmp(a: &[u32], b: &[u32]) -> Ordering {
    a.cmp(b)
}

/// Largest exponent of each of the `n` variables over `terms`.
fn max_exps(terms: &[Term], n: usize) -> Vec<u32> {
    let mut m = vec![0u32; n];
    for t in terms {
        for (x, &e) in m.iter_mut().zip(&t.exps) {
            *x = (*x).max(e);
        }
    }
    m
}

/// Coefficients as `i64` if all are integers in machine range.
fn small_coefs(ts: &[Term]) -> Option<Vec<i64>> {
    ts.iter()
        .map(|t| {
            if t.coef.is_integer() {
                t.coef.numer().to_i64()
            } else {
                None
            }
        })
        .collect()
}

/// A fast deterministic hasher for packed monomials (multiply-fold mixing).
#[derive(Default)]
struct MonoHasher(u64);

impl Hasher for MonoHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, x: u64) {
        let m = ((self.0 ^ x) as u128).wrapping_mul(0x9e37_79b9_7f4a_7c15_f39c_c060_5ced_c835);
        self.0 = (m as u64) ^ ((m >> 64) as u64);
    }
    fn write_u128(&mut self, x: u128) {
        self.write_u64(x as u64);
        self.write_u64((x >> 64) as u64);
    }
}

type MonoMap<K, V> = HashMap<K, V, BuildHasherDefault<MonoHasher>>;

/// A packed monomial key: `u64` when the layout fits, else `u128`.
trait Key: Copy + Eq + std::hash::Hash + Ord + Add<Output = Self> {
    fn from_u128(x: u128) -> Self;
    fn to_u128(self) -> u128;
}

impl Key for u64 {
    fn from_u128(x: u128) -> Self {
        x as u64
    }
    fn to_u128(self) -> u128 {
        self as u128
    }
}

impl Key for u128 {
    fn from_u128(x: u128) -> Self {
        x
    }
    fn to_u128(self) -> u128 {
        self
    }
}

/// One signed product of a sum of products: packed monomials and
/// coefficients of both factors, and whether it is subtracted.
struct PackedPair<'a, K> {
    ka: Vec<K>,
    a: &'a [Term],
    kb: Vec<K>,
    b: &'a [Term],
    neg: bool,
}

/// Initial size of the accumulation table: the number of products, capped
/// (the table grows when needed; a large up-front table costs page faults).
fn table_capacity<K>(pairs: &[PackedPair<'_, K>]) -> usize {
    let products: usize = pairs.iter().map(|p| p.a.len() * p.b.len()).sum();
    products.min(1 << 14)
}

/// Accumulates all products with `i128` coefficients; `None` if a
/// coefficient is not a machine integer or a sum overflows.
fn acc_small<K: Key>(pairs: &[PackedPair<'_, K>]) -> Option<Vec<(K, Rat)>> {
    let products: usize = pairs.iter().map(|p| p.a.len() * p.b.len()).sum();
    if products <= SMALL_PRODUCTS {
        return acc_small_sorted(pairs);
    }
    let mut acc: MonoMap<K, i128> =
        MonoMap::with_capacity_and_hasher(table_capacity(pairs), Default::default());
    for pr in pairs {
        let ca = small_coefs(pr.a)?;
        let mut cb = small_coefs(pr.b)?;
        if pr.neg {
            for c in cb.iter_mut() {
                *c = c.checked_neg()?;
            }
        }
        for (&x, &cx) in pr.ka.iter().zip(&ca) {
            for (&y, &cy) in pr.kb.iter().zip(&cb) {
                let p = cx as i128 * cy as i128;
                let slot = acc.entry(x + y).or_insert(0);
                *slot = slot.checked_add(p)?;
            }
        }
    }
    Some(
        acc.into_iter()
            .filter(|&(_, c)| c != 0)
            .map(|(k, c)| {
                let c = match i64::try_from(c) {
                    Ok(v) => Rat::from(v),
                    Err(_) => Rat::from_int(Int::from(num_bigint::BigInt::from(c))),
                };
                (k, c)
            })
            .collect(),
    )
}

/// Up to this many products a sorted list beats the hash table.
const SMALL_PRODUCTS: usize = 64;

/// [`acc_small`] for few products: all of them listed, sorted, merged.
fn acc_small_sorted<K: Key>(pairs: &[PackedPair<'_, K>]) -> Option<Vec<(K, Rat)>> {
    let mut all: Vec<(K, i128)> = Vec::new();
    for pr in pairs {
        for (&x, s) in pr.ka.iter().zip(pr.a) {
            let cx = if s.coef.is_integer() {
                s.coef.numer().to_i64()?
            } else {
                return None;
            };
            for (&y, t) in pr.kb.iter().zip(pr.b) {
                let cy = if t.coef.is_integer() {
                    t.coef.numer().to_i64()?
                } else {
                    return None;
                };
                let p = cx as i128 * cy as i128;
                all.push((x + y, if pr.neg { p.checked_neg()? } else { p }));
            }
        }
    }
    all.sort_unstable_by_key(|x| std::cmp::Reverse(x.0));
    let mut out: Vec<(K, Rat)> = Vec::with_capacity(all.len());
    let mut i = 0;
    while i < all.len() {
        let k = all[i].0;
        let mut c = all[i].1;
        i += 1;
        while i < all.len() && all[i].0 == k {
            c = c.checked_add(all[i].1)?;
            i += 1;
        }
        if c != 0 {
            let c = match i64::try_from(c) {
                Ok(v) => Rat::from(v),
                Err(_) => Rat::from_int(Int::from(num_bigint::BigInt::from(c))),
            };
            out.push((k, c));
        }
    }
    Some(out)
}

/// Accumulates all products with [`Rat`] coefficients.
fn acc_rat<K: Key>(pairs: &[PackedPair<'_, K>]) -> Vec<(K, Rat)> {
    let mut acc: MonoMap<K, Rat> =
        MonoMap::with_capacity_and_hasher(table_capacity(pairs), Default::default());
    for pr in pairs {
        for (&x, s) in pr.ka.iter().zip(pr.a) {
            let sc = if pr.neg { -&s.coef } else { s.coef.clone() };
            for (&y, t) in pr.kb.iter().zip(pr.b) {
                let p = &sc * &t.coef;
                match acc.entry(x + y) {
                    std::collections::hash_map::Entry::Occupied(mut o) => {
                        let v = o.get() + &p;
                        *o.get_mut() = v;
                    }
                    std::collections::hash_map::Entry::Vacant(v) => {
                        v.insert(p);
                    }
                }
            }
        }
    }
    acc.into_iter().filter(|(_, c)| !c.is_zero()).collect()
}

/// `sum ±a_k b_k` on packed monomials (see [`Poly::sum_of_products`]).
fn dot_packed<K: Key>(
    vars: Arc<[String]>,
    ops: &[(&Poly, &Poly, bool)],
    pos: &[(Vec<usize>, Vec<usize>)],
    pk: &Packing,
) -> Poly {
    let keys = |p: &Poly, pos: &[usize]| -> Vec<K> {
        p.terms
            .iter()
            .map(|t| {
                K::from_u128(
                    t.exps
                        .iter()
                        .zip(pos)
                        .fold(0u128, |k, (&e, &i)| k | ((e as u128) << pk.shifts[i])),
                )
            })
            .collect()
    };
    let pairs: Vec<PackedPair<'_, K>> = ops
        .iter()
        .zip(pos)
        .map(|((a, b, neg), (pa, pb))| PackedPair {
            ka: keys(a, pa),
            a: &a.terms,
            kb: keys(b, pb),
            b: &b.terms,
            neg: *neg,
        })
        .collect();
    let mut out = match acc_small(&pairs) {
        Some(v) => v,
        None => acc_rat(&pairs),
    };
    out.sort_unstable_by_key(|x| std::cmp::Reverse(x.0));
    let terms = out
        .into_iter()
        .map(|(k, coef)| Term {
            exps: pk.unpack(k.to_u128()),
            coef,
        })
        .collect();
    let p = Poly { vars, terms };
    if ops.len() > 1 {
        // A variable may cancel out of a sum.
        p.drop_unused_vars()
    } else {
        p
    }
}

/// Exponent vectors packed into one `u128`, the first variable in the most
/// significant field, so that integer order is the lexicographic term order
/// and adding keys multiplies monomials. Each field has a guard bit above
/// its value bits (always 0 in a packed monomial), which makes the
/// componentwise comparison in [`Packing::sub`] a single subtraction.
struct Packing {
    shifts: Vec<u32>,
    masks: Vec<u128>,
    guard: u128,
    /// Number of bits used.
    bits: u32,
}

impl Packing {
    /// A layout holding exponents up to `max[i]` in field `i`; `None` if it
    /// needs more than 128 bits.
    fn new(max: &[u32]) -> Option<Packing> {
        let widths: Vec<u32> = max.iter().map(|&d| 33 - d.leading_zeros()).collect();
        let total: u32 = widths.iter().sum();
        if total > 128 {
            return None;
        }
        let mut shifts = Vec::with_capacity(max.len());
        let mut masks = Vec::with_capacity(max.len());
        let mut guard = 0u128;
        let mut s = total;
        for w in widths {
            s -= w;
            shifts.push(s);
            masks.push((1u128 << (w - 1)) - 1);
            guard |= 1u128 << (s + w - 1);
        }
        Some(Packing {
            shifts,
            masks,
            guard,
            bits: total,
        })
    }

    fn pack(&self, e: &[u32]) -> u128 {
        e.iter()
            .zip(&self.shifts)
            .fold(0u128, |k, (&x, &s)| k | ((x as u128) << s))
    }

    fn unpack(&self, k: u128) -> Vec<u32> {
        self.shifts
            .iter()
            .zip(&self.masks)
            .map(|(&s, &m)| ((k >> s) & m) as u32)
            .collect()
    }

    /// `m - l` if every field of `m` is at least that of `l`.
    fn sub(&self, m: u128, l: u128) -> Option<u128> {
        let d = (m | self.guard) - l;
        (d & self.guard == self.guard).then_some(d & !self.guard)
    }
}

impl Poly {
    /// The zero polynomial.
    pub fn zero() -> Poly {
        Poly {
            vars: Arc::from(Vec::<String>::new()),
            terms: Vec::new(),
        }
    }

    /// The constant polynomial `c`.
    pub fn constant(c: Rat) -> Poly {
        if c.is_zero() {
            return Poly::zero();
        }
        Poly {
            vars: Arc::from(Vec::<String>::new()),
            terms: vec![Term {
                exps: Vec::new(),
                coef: c,
            }],
        }
    }

    /// The constant 1.
    pub fn one() -> Poly {
        Poly::constant(Rat::ONE)
    }

    /// The integer constant `n`.
    pub fn int(n: i64) -> Poly {
        Poly::constant(Rat::from(n))
    }

    /// The polynomial consisting of the single variable `name`.
    pub fn var(name: &str) -> Poly {
        Poly {
            vars: Arc::from(vec![name.to_string()]),
            terms: vec![Term {
                exps: vec![1],
                coef: Rat::ONE,
            }],
        }
    }

    /// Builds a polynomial from terms over the given variables (any order,
    /// duplicates and zero coefficients allowed: they are normalised).
    ///
    /// Panics if a term has a different number of exponents than `vars`.
    pub fn from_terms(vars: &[String], terms: Vec<Term>) -> Poly {
        let mut order: Vec<usize> = (0..vars.len()).collect();
        order.sort_by(|&a, &b| var_cmp(&vars[a], &vars[b]));
        // Merge duplicate variable names.
        let mut names: Vec<String> = Vec::new();
        let mut target: Vec<usize> = vec![0; vars.len()];
        for &i in &order {
            if names.last() != Some(&vars[i]) {
                names.push(vars[i].clone());
            }
            target[i] = names.len() - 1;
        }
        let terms = terms
            .into_iter()
            .map(|t| {
                assert_eq!(t.exps.len(), vars.len(), "term arity");
                let mut e = vec![0u32; names.len()];
                for (i, x) in t.exps.iter().enumerate() {
                    e[target[i]] += x;
                }
                Term {
                    exps: e,
                    coef: t.coef,
                }
            })
            .collect();
        Poly::normalize(Arc::from(names), terms)
    }

    /// Sorts, merges equal monomials, drops zeros and unused variables.
    fn normalize(vars: Arc<[String]>, mut terms: Vec<Term>) -> Poly {
        terms.sort_by(|a, b| lex_cmp(&b.exps, &a.exps));
        let mut out: Vec<Term> = Vec::with_capacity(terms.len());
        for t in terms {
            match out.last_mut() {
                Some(last) if last.exps == t.exps => {
                    last.coef = &last.coef + &t.coef;
                }
                _ => {
                    if let Some(last) = out.last() {
                        if last.coef.is_zero() {
                            out.pop();
                        }
                    }
                    out.push(t);
                }
            }
        }
        if let Some(last) = out.last() {
            if last.coef.is_zero() {
                out.pop();
            }
        }
        Poly { vars, terms: out }.drop_unused_vars()
    }

    fn drop_unused_vars(self) -> Poly {
        let n = self.vars.len();
        let mut used = vec![false; n];
        let mut count = 0;
        for t in &self.terms {
            for (u, &e) in used.iter_mut().zip(&t.exps) {
                if e > 0 && !*u {
                    *u = true;
                    count += 1;
                }
            }
            if count == n {
                return self;
            }
        }
        if count == n {
            return self;
        }
        let vars: Vec<String> = self
            .vars
            .iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .map(|(v, _)| v.clone())
            .collect();
        let terms = self
            .terms
            .into_iter()
            .map(|t| Term {
                exps: t
                    .exps
                    .iter()
                    .zip(&used)
                    .filter(|(_, &u)| u)
                    .map(|(e, _)| *e)
                    .collect(),
                coef: t.coef,
            })
            .collect();
        Poly {
            vars: Arc::from(vars),
            terms,
        }
    }

    /// A polynomial from terms over the (shared) variable list of another
    /// polynomial: sorted, merged, unused variables dropped.
    pub(crate) fn from_terms_like(like: &Poly, terms: Vec<Term>) -> Poly {
        Poly::normalize(like.vars.clone(), terms)
    }

    /// The variables that occur, sorted by [`var_cmp`].
    pub fn vars(&self) -> &[String] {
        &self.vars
    }

    /// The terms, in descending lexicographic order of [`Poly::vars`].
    pub fn terms(&self) -> &[Term] {
        &self.terms
    }

    /// Number of terms.
    pub fn num_terms(&self) -> usize {
        self.terms.len()
    }

    /// True for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    /// The value if the polynomial is constant (zero included).
    pub fn as_constant(&self) -> Option<Rat> {
        match self.terms.len() {
            0 => Some(Rat::ZERO),
            1 if self.vars.is_empty() => Some(self.terms[0].coef.clone()),
            _ => None,
        }
    }

    /// True if no variable occurs.
    pub fn is_constant(&self) -> bool {
        self.vars.is_empty()
    }

    /// True if `name` occurs.
    pub fn has_var(&self, name: &str) -> bool {
        self.var_index(name).is_some()
    }

    fn var_index(&self, name: &str) -> Option<usize> {
        self.vars.binary_search_by(|v| var_cmp(v, name)).ok()
    }

    /// Degree in `name` (0 if it does not occur; 0 for the zero polynomial).
    pub fn degree(&self, name: &str) -> u32 {
        match self.var_index(name) {
            None => 0,
            Some(i) => self.terms.iter().map(|t| t.exps[i]).max().unwrap_or(0),
        }
    }

    /// Lowest exponent of `name` over all terms.
    pub fn min_degree(&self, name: &str) -> u32 {
        match self.var_index(name) {
            None => 0,
            Some(i) => self.terms.iter().map(|t| t.exps[i]).min().unwrap_or(0),
        }
    }

    /// Total degree (0 for the zero polynomial).
    pub fn total_degree(&self) -> u32 {
        self.terms
            .iter()
            .map(|t| t.exps.iter().sum::<u32>())
            .max()
            .unwrap_or(0)
    }

    /// True if every coefficient is an integer.
    pub fn is_integral(&self) -> bool {
        self.terms.iter().all(|t| t.coef.is_integer())
    }

    /// The leading coefficient in the term order (zero for the zero polynomial).
    pub fn leading_coef(&self) -> Rat {
        self.terms
            .first()
            .map(|t| t.coef.clone())
            .unwrap_or(Rat::ZERO)
    }

    /// Merged variable list of two polynomials and, for each, the position of
    /// its variables in the merged list.
    fn merge_vars(a: &[String], b: &[String]) -> (Vec<String>, Vec<usize>, Vec<usize>) {
        let mut out = Vec::with_capacity(a.len() + b.len());
        let (mut ia, mut ib) = (Vec::new(), Vec::new());
        let (mut i, mut j) = (0, 0);
        while i < a.len() || j < b.len() {
            let ord = if i == a.len() {
                Ordering::Greater
            } else if j == b.len() {
                Ordering::Less
            } else {
                var_cmp(&a[i], &b[j])
            };
            match ord {
                Ordering::Less => {
                    ia.push(out.len());
                    out.push(a[i].clone());
                    i += 1;
                }
                Ordering::Greater => {
                    ib.push(out.len());
                    out.push(b[j].clone());
                    j += 1;
                }
                Ordering::Equal => {
                    ia.push(out.len());
                    ib.push(out.len());
                    out.push(a[i].clone());
                    i += 1;
                    j += 1;
                }
            }
        }
        (out, ia, ib)
    }

    fn remap(&self, n: usize, pos: &[usize]) -> Vec<Term> {
        self.terms
            .iter()
            .map(|t| {
                let mut e = vec![0u32; n];
                for (k, &p) in pos.iter().enumerate() {
                    e[p] = t.exps[k];
                }
                Term {
                    exps: e,
                    coef: t.coef.clone(),
                }
            })
            .collect()
    }

    /// Both operands over one common variable list.
    fn aligned(&self, other: &Poly) -> (Arc<[String]>, Vec<Term>, Vec<Term>) {
        if Arc::ptr_eq(&self.vars, &other.vars) || self.vars == other.vars {
            return (self.vars.clone(), self.terms.clone(), other.terms.clone());
        }
        let (vars, ia, ib) = Poly::merge_vars(&self.vars, &other.vars);
        let n = vars.len();
        (Arc::from(vars), self.remap(n, &ia), other.remap(n, &ib))
    }

    /// Multiplies every coefficient by `c`.
    pub fn scale(&self, c: &Rat) -> Poly {
        if c.is_zero() {
            return Poly::zero();
        }
        if c.is_one() {
            return self.clone();
        }
        if c.is_integer() && c.numer() == &Int::from(-1) {
            return Poly {
                vars: self.vars.clone(),
                terms: self
                    .terms
                    .iter()
                    .map(|t| Term {
                        exps: t.exps.clone(),
                        coef: -&t.coef,
                    })
                    .collect(),
            };
        }
        Poly {
            vars: self.vars.clone(),
            terms: self
                .terms
                .iter()
                .map(|t| Term {
                    exps: t.exps.clone(),
                    coef: &t.coef * c,
                })
                .collect(),
        }
    }

    /// `self * m` for a one-term `m`: multiplying by a monomial keeps the
    /// term order, so no sorting or merging is needed.
    fn mul_term(&self, m: &Poly) -> Poly {
        let t = &m.terms[0];
        let same = Arc::ptr_eq(&self.vars, &m.vars) || self.vars == m.vars;
        let (vars, pos_s, pos_m): (Arc<[String]>, Vec<usize>, Vec<usize>) = if same {
            let id: Vec<usize> = (0..self.vars.len()).collect();
            (self.vars.clone(), id.clone(), id)
        } else {
            let (v, ia, ib) = Poly::merge_vars(&self.vars, &m.vars);
            (Arc::from(v), ia, ib)
        };
        let n = vars.len();
        let mut add = vec![0u32; n];
        for (&p, &e) in pos_m.iter().zip(&t.exps) {
            add[p] = e;
        }
        let one = t.coef.is_one();
        let terms = self
            .terms
            .iter()
            .map(|s| {
                let mut exps = add.clone();
                for (&p, &e) in pos_s.iter().zip(&s.exps) {
                    exps[p] += e;
                }
                Term {
                    exps,
                    coef: if one {
                        s.coef.clone()
                    } else {
                        &s.coef * &t.coef
                    },
                }
            })
            .collect();
        Poly { vars, terms }
    }

    /// `self^e`.
    pub fn pow(&self, e: u32) -> Poly {
        // Rational coefficients: the power of the primitive part, in
        // integers, scaled once (an integer product needs no gcd per
        // coefficient; with a 3/2 in the base this is 50 times faster).
        if e > 1 && e <= i32::MAX as u32 && !self.is_integral() {
            let (c, p) = self.primitive();
            return p.pow(e).scale(&c.pow(e as i32));
        }
        let mut result = Poly::one();
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

    /// Multiplies by `name^k`.
    pub fn mul_var_pow(&self, name: &str, k: u32) -> Poly {
        self * &Poly::var(name).pow(k)
    }

    /// Exact division: `Some(q)` with `self = q * other`, or `None` when
    /// `other` does not divide `self`. Panics if `other` is zero.
    pub fn div_exact(&self, other: &Poly) -> Option<Poly> {
        assert!(!other.is_zero(), "division by the zero polynomial");
        if let Some(c) = other.as_constant() {
            return Some(self.scale(&c.recip()));
        }
        if self.is_zero() {
            return Some(Poly::zero());
        }
        // A variable of the divisor missing from the dividend: no exact quotient.
        if other.vars.iter().any(|v| !self.has_var(v)) {
            return None;
        }
        let (vars, a, b) = self.aligned(other);
        let n = vars.len();
        let da = max_exps(&a, n);
        let db = max_exps(&b, n);
        // deg_v(q) = deg_v(self) - deg_v(other) for an exact quotient.
        if da.iter().zip(&db).any(|(x, y)| y > x) {
            return None;
        }
        match Packing::new(&da) {
            Some(pk) => {
                let bound: Vec<u32> = da.iter().zip(&db).map(|(x, y)| x - y).collect();
                Poly::div_packed(vars, &a, &b, &pk, pk.pack(&bound))
            }
            None => Poly::div_generic(vars, a, b),
        }
    }

    /// Sparse exact division on packed exponents (see [`Packing`]); every
    /// monomial met is bounded by the dividend's degrees because quotient
    /// terms beyond `bound` mean the division is not exact.
    fn div_packed(
        vars: Arc<[String]>,
        a: &[Term],
        b: &[Term],
        pk: &Packing,
        bound: u128,
    ) -> Option<Poly> {
        let kb: Vec<u128> = b.iter().map(|t| pk.pack(&t.exps)).collect();
        let lead = kb[0];
        let lead_inv = b[0].coef.recip();
        let mut rem: BTreeMap<u128, Rat> = a
            .iter()
            .map(|t| (pk.pack(&t.exps), t.coef.clone()))
            .collect();
        let mut quot: Vec<Term> = Vec::new();
        while let Some((m, c)) = rem.pop_last() {
            let qe = pk.sub(m, lead)?;
            pk.sub(bound, qe)?;
            let qc = &c * &lead_inv;
            for (t, &k) in b[1..].iter().zip(&kb[1..]) {
                let delta = &t.coef * &qc;
                match rem.entry(k + qe) {
                    std::collections::btree_map::Entry::Occupied(mut o) => {
                        let v = o.get() - &delta;
                        if v.is_zero() {
                            o.remove();
                        } else {
                            *o.get_mut() = v;
                        }
                    }
                    std::collections::btree_map::Entry::Vacant(v) => {
                        v.insert(-delta);
                    }
                }
            }
            quot.push(Term {
                exps: pk.unpack(qe),
                coef: qc,
            });
        }
        Some(Poly { vars, terms: quot }.drop_unused_vars())
    }

    /// Sparse exact division with exponent vectors as keys (any degrees).
    fn div_generic(vars: Arc<[String]>, a: Vec<Term>, b: Vec<Term>) -> Option<Poly> {
        let n = vars.len();
        let lead = &b[0];
        let lead_inv = lead.coef.recip();
        // Remainder kept as a sorted map, largest monomial last.
        let mut rem: BTreeMap<Vec<u32>, Rat> = a.into_iter().map(|t| (t.exps, t.coef)).collect();
        let mut quot: Vec<Term> = Vec::new();
        while let Some((m, c)) = rem.pop_last() {
            let mut qe = Vec::with_capacity(n);
            for (mk, lk) in m.iter().zip(&lead.exps) {
                if mk < lk {
                    return None;
                }
                qe.push(mk - lk);
            }
            let qc = &c * &lead_inv;
            for t in &b[1..] {
                let e: Vec<u32> = t.exps.iter().zip(&qe).map(|(x, y)| x + y).collect();
                let delta = &t.coef * &qc;
                match rem.get_mut(&e) {
                    Some(v) => {
                        *v = &*v - &delta;
                        if v.is_zero() {
                            rem.remove(&e);
                        }
                    }
                    None => {
                        rem.insert(e, -delta);
                    }
                }
            }
            quot.push(Term { exps: qe, coef: qc });
        }
        Some(Poly::normalize(vars, quot))
    }

    /// Coefficients as a polynomial in `name`: entry `i` is the coefficient of
    /// `name^i` (a polynomial in the other variables). Empty for zero.
    ///
    /// ```
    /// use poly::Poly;
    /// let p: Poly = "a*x^2 + b*x + 1".parse().unwrap();
    /// let c = p.coeffs_in("x");
    /// assert_eq!(c.len(), 3);
    /// assert_eq!(c[1].to_string(), "b");
    /// assert_eq!(Poly::from_coeffs_in("x", &c), p);
    /// ```
    pub fn coeffs_in(&self, name: &str) -> Vec<Poly> {
        if self.is_zero() {
            return Vec::new();
        }
        let Some(i) = self.var_index(name) else {
            return vec![self.clone()];
        };
        let deg = self.degree(name) as usize;
        let mut buckets: Vec<Vec<Term>> = vec![Vec::new(); deg + 1];
        for t in &self.terms {
            let mut e = t.exps.clone();
            let k = e[i] as usize;
            e[i] = 0;
            buckets[k].push(Term {
                exps: e,
                coef: t.coef.clone(),
            });
        }
        // Terms with equal exponents of `name` keep their relative order
        // (lex comparison is decided elsewhere), so every bucket is sorted
        // and free of duplicates already.
        buckets
            .into_iter()
            .map(|ts| {
                Poly {
                    vars: self.vars.clone(),
                    terms: ts,
                }
                .drop_unused_vars()
            })
            .collect()
    }

    /// Division by a divisor of degree one in `name` with a constant
    /// coefficient there, `divisor = a name + g`: `(q, r)` with `self = q
    /// divisor + r` and `r` free of `name` (`self` with `name = -g / a`).
    /// `None` if the divisor is not of that form. Two such divisors in
    /// different variables, each free of the other's, are a Gröbner basis
    /// in a lex order led by those variables, so dividing by one and then
    /// the other leaves zero exactly for the members of their ideal.
    ///
    /// ```
    /// use poly::Poly;
    /// let p: Poly = "x^2*y + x + 3".parse().unwrap();
    /// let d: Poly = "2*x - y".parse().unwrap();
    /// let (q, r) = p.div_rem_linear("x", &d).unwrap();
    /// assert!(!r.has_var("x"));
    /// assert_eq!(&(&q * &d) + &r, p);
    /// ```
    pub fn div_rem_linear(&self, name: &str, divisor: &Poly) -> Option<(Poly, Poly)> {
        let d = divisor.coeffs_in(name);
        let a = match d.as_slice() {
            [_, a] => a.as_constant().filter(|a| !a.is_zero())?,
            _ => return None,
        };
        let root = d[0].scale(&(-&a.recip()));
        let c = self.coeffs_in(name);
        if c.len() <= 1 {
            return Some((Poly::zero(), self.clone()));
        }
        // Horner's scheme by `name - root`: q_(k-1) = c_k + root q_k.
        let mut q = vec![Poly::zero(); c.len() - 1];
        let mut carry = Poly::zero();
        for k in (1..c.len()).rev() {
            carry = &c[k] + &(&root * &carry);
            q[k - 1] = carry.clone();
        }
        let r = &c[0] + &(&root * &carry);
        Some((Poly::from_coeffs_in(name, &q).scale(&a.recip()), r))
    }

    /// Inverse of [`Poly::coeffs_in`]: `sum coeffs[i] * name^i`.
    pub fn from_coeffs_in(name: &str, coeffs: &[Poly]) -> Poly {
        let x = Poly::var(name);
        let mut acc = Poly::zero();
        for c in coeffs.iter().rev() {
            acc = &(&acc * &x) + c;
        }
        acc
    }

    /// The leading coefficient in `name` (a polynomial in the other variables).
    pub fn lead_in(&self, name: &str) -> Poly {
        self.coeffs_in(name).pop().unwrap_or_else(Poly::zero)
    }

    /// Partial derivative with respect to `name`.
    pub fn derivative(&self, name: &str) -> Poly {
        let Some(i) = self.var_index(name) else {
            return Poly::zero();
        };
        let terms = self
            .terms
            .iter()
            .filter(|t| t.exps[i] > 0)
            .map(|t| {
                let mut e = t.exps.clone();
                let k = e[i];
                e[i] -= 1;
                Term {
                    exps: e,
                    coef: &t.coef * &Rat::from(k as i64),
                }
            })
            .collect();
        Poly::normalize(self.vars.clone(), terms)
    }

    /// Substitutes the value `v` for the variable `name`.
    pub fn subs(&self, name: &str, v: &Rat) -> Poly {
        let Some(i) = self.var_index(name) else {
            return self.clone();
        };
        let deg = self.degree(name) as usize;
        let mut powers = vec![Rat::ONE];
        for k in 1..=deg {
            powers.push(&powers[k - 1] * v);
        }
        let terms = self
            .terms
            .iter()
            .map(|t| {
                let mut e = t.exps.clone();
                let k = e[i] as usize;
                e[i] = 0;
                Term {
                    exps: e,
                    coef: &t.coef * &powers[k],
                }
            })
            .collect();
        Poly::normalize(self.vars.clone(), terms)
    }

    /// Substitutes the polynomial `q` for the variable `name`.
    pub fn subs_poly(&self, name: &str, q: &Poly) -> Poly {
        let c = self.coeffs_in(name);
        let mut acc = Poly::zero();
        for ci in c.iter().rev() {
            acc = &(&acc * q) + ci;
        }
        acc
    }

    /// Renames variables through `f` (names mapped to the same target merge).
    pub fn rename(&self, f: impl Fn(&str) -> String) -> Poly {
        let vars: Vec<String> = self.vars.iter().map(|v| f(v)).collect();
        Poly::from_terms(&vars, self.terms.clone())
    }

    /// Exact value at a rational point; `Err(name)` names a variable without a value.
    ///
    /// The sum is taken over the integers, every term brought to the common
    /// denominator `lcm(coefficient denominators) * prod d_i^D_i` (`x_i =
    /// n_i/d_i`, `D_i` the degree in `x_i`), and reduced once at the end: a
    /// sum of rationals would take a gcd per term, which dominated the
    /// evaluation of large conditions at sample points.
    ///
    /// ```
    /// use poly::{Poly, Rat};
    /// use std::collections::BTreeMap;
    /// let p: Poly = "x^2*y/3 - 2*x + 1/2".parse().unwrap();
    /// let point = BTreeMap::from([
    ///     ("x".to_string(), Rat::new(3.into(), 2.into())),
    ///     ("y".to_string(), Rat::from(-4)),
    /// ]);
    /// // 9/4 * (-4) / 3 - 3 + 1/2 = -3 - 3 + 1/2
    /// assert_eq!(p.eval(&point).unwrap(), Rat::new((-11).into(), 2.into()));
    /// ```
    pub fn eval(&self, point: &BTreeMap<String, Rat>) -> Result<Rat, String> {
        let given: Vec<Option<&Rat>> = self
            .vars
            .iter()
            .map(|v| point.get(v).map(Some).ok_or_else(|| v.clone()))
            .collect::<Result<_, _>>()?;
        let (num_pows, den_pows, coef_den) = self.common_denominator_powers(&given);
        let mut acc = Int::ZERO;
        for t in &self.terms {
            let mut m = if t.coef.denom().is_one() {
                &coef_den * t.coef.numer()
            } else {
                &coef_den.div_exact(t.coef.denom()) * t.coef.numer()
            };
            for (i, &e) in t.exps.iter().enumerate() {
                let top = den_pows[i].len() - 1;
                if e > 0 {
                    m = &m * &num_pows[i][e as usize];
                }
                if (e as usize) < top {
                    m = &m * &den_pows[i][top - e as usize];
                }
            }
            acc = &acc + &m;
        }
        let mut den = coef_den;
        for q in &den_pows {
            den = &den * &q[q.len() - 1];
        }
        Ok(Rat::new(acc, den))
    }

    /// For the sums at one common denominator of [`Poly::eval`] and
    /// [`Poly::subs_point`]: the powers of each given value's numerator and
    /// denominator up to the variable's degree (only `1` for a variable
    /// without a value), and the lcm of the coefficients' denominators.
    fn common_denominator_powers(
        &self,
        given: &[Option<&Rat>],
    ) -> (Vec<Vec<Int>>, Vec<Vec<Int>>, Int) {
        let mut num_pows: Vec<Vec<Int>> = Vec::with_capacity(given.len());
        let mut den_pows: Vec<Vec<Int>> = Vec::with_capacity(given.len());
        for (i, v) in given.iter().enumerate() {
            let (mut n, mut q) = (vec![Int::ONE], vec![Int::ONE]);
            if let Some(v) = v {
                let d = self.terms.iter().map(|t| t.exps[i]).max().unwrap_or(0) as usize;
                for k in 1..=d {
                    n.push(&n[k - 1] * v.numer());
                    q.push(&q[k - 1] * v.denom());
                }
            }
            num_pows.push(n);
            den_pows.push(q);
        }
        let mut coef_den = Int::ONE;
        for t in &self.terms {
            if !t.coef.denom().is_one() {
                coef_den = coef_den.lcm(t.coef.denom());
            }
        }
        (num_pows, den_pows, coef_den)
    }

    /// Substitutes every variable that `point` gives a value and keeps the
    /// others. The terms are summed over the integers at one common
    /// denominator and reduced once per remaining monomial: substituting
    /// one variable at a time would reduce a fraction at every term of
    /// every intermediate polynomial.
    ///
    /// ```
    /// use poly::{Poly, Rat};
    /// use std::collections::BTreeMap;
    /// let p: Poly = "a*x^2 + b*x + a*b".parse().unwrap();
    /// let point = BTreeMap::from([("a".to_string(), Rat::new(1.into(), 2.into())), ("b".to_string(), Rat::from(3))]);
    /// assert_eq!(p.subs_point(&point).to_string(), "1/2*x^2 + 3*x + 3/2");
    /// ```
    pub fn subs_point(&self, point: &BTreeMap<String, Rat>) -> Poly {
        let given: Vec<Option<&Rat>> = self.vars.iter().map(|v| point.get(v)).collect();
        if given.iter().all(Option::is_none) {
            return self.clone();
        }
        let (num_pows, den_pows, coef_den) = self.common_denominator_powers(&given);
        let mut sums: HashMap<Vec<u32>, Int> = HashMap::new();
        for t in &self.terms {
            let mut m = if t.coef.denom().is_one() {
                &coef_den * t.coef.numer()
            } else {
                &coef_den.div_exact(t.coef.denom()) * t.coef.numer()
            };
            let mut rest = t.exps.clone();
            for (i, v) in given.iter().enumerate() {
                if v.is_none() {
                    continue;
                }
                let e = t.exps[i] as usize;
                let top = den_pows[i].len() - 1;
                if e > 0 {
                    m = &m * &num_pows[i][e];
                }
                if e < top {
                    m = &m * &den_pows[i][top - e];
                }
                rest[i] = 0;
            }
            match sums.get_mut(&rest) {
                Some(acc) => *acc = &*acc + &m,
                None => {
                    sums.insert(rest, m);
                }
            }
        }
        let mut den = coef_den;
        for q in &den_pows {
            den = &den * &q[q.len() - 1];
        }
        let terms = sums
            .into_iter()
            .filter(|(_, c)| !c.is_zero())
            .map(|(exps, c)| Term {
                exps,
                coef: Rat::new(c, den.clone()),
            })
            .collect();
        Poly::normalize(self.vars.clone(), terms)
    }

    /// The value at `point` of every variable but `keep`: a polynomial in
    /// `keep` alone, built in one pass over the terms (substituting one
    /// variable at a time would rebuild a large polynomial once per
    /// variable). `Err(name)` names a variable without a value.
    ///
    /// ```
    /// use poly::{Poly, Rat};
    /// use std::collections::BTreeMap;
    /// let p: Poly = "a*x^2 + b*x + a*b".parse().unwrap();
    /// let point = BTreeMap::from([("a".to_string(), Rat::from(2)), ("b".to_string(), Rat::from(3))]);
    /// assert_eq!(p.eval_except("x", &point).unwrap().to_string(), "2*x^2 + 3*x + 6");
    /// // Keeping `a`, `x` has no value.
    /// assert_eq!(p.eval_except("a", &point), Err("x".to_string()));
    /// ```
    pub fn eval_except(&self, keep: &str, point: &BTreeMap<String, Rat>) -> Result<Poly, String> {
        let Some(k) = self.var_index(keep) else {
            return self.eval(point).map(Poly::constant);
        };
        let mut powers: Vec<Vec<Rat>> = Vec::with_capacity(self.vars.len());
        for (i, v) in self.vars.iter().enumerate() {
            if i == k {
                powers.push(Vec::new());
                continue;
            }
            let value = point.get(v).ok_or_else(|| v.clone())?;
            let d = self.terms.iter().map(|t| t.exps[i]).max().unwrap_or(0) as usize;
            let mut p = vec![Rat::ONE];
            for e in 1..=d {
                p.push(&p[e - 1] * value);
            }
            powers.push(p);
        }
        let mut coeffs = vec![Rat::ZERO; self.degree(keep) as usize + 1];
        for t in &self.terms {
            let mut m = t.coef.clone();
            for (i, &e) in t.exps.iter().enumerate() {
                if e > 0 && i != k {
                    m = &m * &powers[i][e as usize];
                }
            }
            let slot = &mut coeffs[t.exps[k] as usize];
            *slot = &*slot + &m;
        }
        let coeffs: Vec<Poly> = coeffs.into_iter().map(Poly::constant).collect();
        Ok(Poly::from_coeffs_in(keep, &coeffs))
    }

    /// Floating-point value at a point; `Err(name)` names a variable without a value.
    pub fn eval_f64(&self, point: &BTreeMap<String, f64>) -> Result<f64, String> {
        let vals: Vec<f64> = self
            .vars
            .iter()
            .map(|v| point.get(v).copied().ok_or_else(|| v.clone()))
            .collect::<Result<_, _>>()?;
        // Each power once per variable, not once per term: the same
        // `powi` values, so the same bits as taking them term by term.
        let top = max_exps(&self.terms, vals.len());
        let powers: Vec<Vec<f64>> = vals
            .iter()
            .zip(&top)
            .map(|(&v, &m)| (0..=m).map(|e| v.powi(e as i32)).collect())
            .collect();
        Ok(self
            .terms
            .iter()
            .map(|t| {
                t.exps
                    .iter()
                    .zip(&powers)
                    .fold(t.coef.to_f64(), |m, (&e, p)| m * p[e as usize])
            })
            .sum())
    }

    /// Splits `self = c * p` with `p` having integer coefficients whose gcd is
    /// 1 and a positive leading coefficient. Returns `(c, p)`; `(0, 0)` for zero.
    pub fn primitive(&self) -> (Rat, Poly) {
        if self.is_zero() {
            return (Rat::ZERO, Poly::zero());
        }
        let mut den = Int::ONE;
        for t in &self.terms {
            if !t.coef.is_integer() {
                den = den.lcm(t.coef.denom());
            }
        }
        let mut g = Int::ZERO;
        for t in &self.terms {
            if den.is_one() {
                g = g.gcd(t.coef.numer());
            } else {
                let v = t.coef.numer() * &den.div_exact(t.coef.denom());
                g = g.gcd(&v);
            }
            if g.is_one() {
                break;
            }
        }
        let mut c = Rat::new(g, den);
        if self.terms[0].coef.signum() < 0 {
            c = -c;
        }
        let p = self.scale(&c.recip());
        (c, p)
    }

    /// The least exponent of each variable over all terms (the monomial
    /// content), in the order of [`Poly::vars`]. Empty for zero.
    pub fn monomial_content(&self) -> Vec<u32> {
        let mut it = self.terms.iter();
        let Some(first) = it.next() else {
            return Vec::new();
        };
        let mut m = first.exps.clone();
        for t in it {
            if m.iter().all(|&x| x == 0) {
                break;
            }
            for (x, &e) in m.iter_mut().zip(&t.exps) {
                *x = (*x).min(e);
            }
        }
        m
    }

    /// `self` divided by the monomial with exponents `m` (one per variable,
    /// at most [`Poly::monomial_content`]); the term order is unchanged.
    pub fn div_monomial(&self, m: &[u32]) -> Poly {
        assert_eq!(m.len(), self.vars.len(), "one exponent per variable");
        let terms = self
            .terms
            .iter()
            .map(|t| Term {
                exps: t
                    .exps
                    .iter()
                    .zip(m)
                    .map(|(e, k)| e.checked_sub(*k).expect("monomial divides"))
                    .collect(),
                coef: t.coef.clone(),
            })
            .collect();
        Poly {
            vars: self.vars.clone(),
            terms,
        }
        .drop_unused_vars()
    }

    /// The primitive part (see [`Poly::primitive`]).
    pub fn primitive_part(&self) -> Poly {
        self.primitive().1
    }

    /// True when every coefficient is positive (an empty sum is not positive).
    /// Such a polynomial is > 0 wherever all variables are > 0.
    pub fn all_coefs_positive(&self) -> bool {
        !self.is_zero() && self.terms.iter().all(|t| t.coef.signum() > 0)
    }

    /// True when every coefficient is negative.
    pub fn all_coefs_negative(&self) -> bool {
        !self.is_zero() && self.terms.iter().all(|t| t.coef.signum() < 0)
    }

    /// `+1` / `-1` when every coefficient is positive / negative: then the
    /// polynomial has that sign wherever all its variables are positive
    /// (it cannot vanish on the open positive orthant). `None` otherwise.
    ///
    /// ```
    /// let p: poly::Poly = "m1*c12 + 2*m2".parse().unwrap();
    /// assert_eq!(p.orthant_sign(), Some(1));
    /// assert_eq!((-&p).orthant_sign(), Some(-1));
    /// assert_eq!("m1 - m2".parse::<poly::Poly>().unwrap().orthant_sign(), None);
    /// ```
    pub fn orthant_sign(&self) -> Option<i32> {
        if self.all_coefs_positive() {
            Some(1)
        } else if self.all_coefs_negative() {
            Some(-1)
        } else {
            None
        }
    }

    /// `sum_k ±a_k b_k` (the product subtracted when its flag is set) in
    /// one pass: all products are accumulated in a single table keyed by
    /// packed monomials, so the sum needs no intermediate polynomials.
    ///
    /// ```
    /// use poly::Poly;
    /// let p = |s: &str| s.parse::<Poly>().unwrap();
    /// let (a, b, c, d) = (p("x + y"), p("x - y"), p("x"), p("z"));
    /// let s = Poly::sum_of_products(&[(&a, &b, false), (&c, &d, true)]);
    /// assert_eq!(s, p("x^2 - y^2 - x*z"));
    /// ```
    pub fn sum_of_products(ops: &[(&Poly, &Poly, bool)]) -> Poly {
        let ops: Vec<(&Poly, &Poly, bool)> = ops
            .iter()
            .filter(|(a, b, _)| !a.is_zero() && !b.is_zero())
            .copied()
            .collect();
        if ops.is_empty() {
            return Poly::zero();
        }
        // Common variables and each operand's positions in them.
        let first = &ops[0].0.vars;
        let same = ops.iter().all(|(a, b, _)| {
            [&a.vars, &b.vars]
                .iter()
                .all(|v| Arc::ptr_eq(first, v) || first[..] == v[..])
        });
        let vars: Arc<[String]> = if same {
            first.clone()
        } else {
            let mut acc: Vec<String> = first.to_vec();
            for (a, b, _) in &ops {
                for v in [&a.vars, &b.vars] {
                    if acc[..] != v[..] {
                        acc = Poly::merge_vars(&acc, v).0;
                    }
                }
            }
            Arc::from(acc)
        };
        let positions = |p: &Poly| -> Vec<usize> {
            if same {
                return (0..p.vars.len()).collect();
            }
            // Both lists are sorted the same way: one walk.
            let mut out = Vec::with_capacity(p.vars.len());
            let mut k = 0;
            for v in p.vars.iter() {
                while vars[k] != *v {
                    k += 1;
                }
                out.push(k);
            }
            out
        };
        let n = vars.len();
        let mut maxes = vec![0u32; n];
        let mut pos = Vec::with_capacity(ops.len());
        for (a, b, _) in &ops {
            let (pa, pb) = (positions(a), positions(b));
            let (ma, mb) = (
                max_exps(&a.terms, a.vars.len()),
                max_exps(&b.terms, b.vars.len()),
            );
            let mut sum = vec![0u32; n];
            for (&i, &e) in pa.iter().zip(&ma) {
                sum[i] += e;
            }
            for (&i, &e) in pb.iter().zip(&mb) {
                sum[i] += e;
            }
            for (m, s) in maxes.iter_mut().zip(&sum) {
                *m = (*m).max(*s);
            }
            pos.push((pa, pb));
        }
        match Packing::new(&maxes) {
            Some(pk) if pk.bits <= 64 => dot_packed::<u64>(vars, &ops, &pos, &pk),
            Some(pk) => dot_packed::<u128>(vars, &ops, &pos, &pk),
            None => {
                let mut acc = Poly::zero();
                for (a, b, neg) in &ops {
                    let (v, x, y) = a.aligned(b);
                    let p = Poly::mul_generic(v, &x, &y);
                    acc = if *neg { &acc - &p } else { &acc + &p };
                }
                acc
            }
        }
    }

    fn mul_generic(vars: Arc<[String]>, a: &[Term], b: &[Term]) -> Poly {
        let mut acc: Vec<Term> = Vec::with_capacity(a.len() * b.len());
        for x in a {
            for y in b {
                acc.push(Term {
                    exps: x.exps.iter().zip(&y.exps).map(|(p, q)| p + q).collect(),
                    coef: &x.coef * &y.coef,
                });
            }
        }
        Poly::normalize(vars, acc)
    }

    /// `a + b` or `a - b` for term lists over the same variables, both
    /// sorted descending: a linear merge that clones only what it emits.
    fn merge_add(vars: Arc<[String]>, a: &[Term], b: &[Term], negate_b: bool) -> Poly {
        let mut out: Vec<Term> = Vec::with_capacity(a.len() + b.len());
        let (mut i, mut j) = (0, 0);
        let other = |t: &Term| Term {
            exps: t.exps.clone(),
            coef: if negate_b { -&t.coef } else { t.coef.clone() },
        };
        while i < a.len() && j < b.len() {
            match lex_cmp(&a[i].exps, &b[j].exps) {
                Ordering::Greater => {
                    out.push(a[i].clone());
                    i += 1;
                }
                Ordering::Less => {
                    out.push(other(&b[j]));
                    j += 1;
                }
                Ordering::Equal => {
                    let c = if negate_b {
                        &a[i].coef - &b[j].coef
                    } else {
                        &a[i].coef + &b[j].coef
                    };
                    if !c.is_zero() {
                        out.push(Term {
                            exps: a[i].exps.clone(),
                            coef: c,
                        });
                    }
                    i += 1;
                    j += 1;
                }
            }
        }
        out.extend(a[i..].iter().cloned());
        out.extend(b[j..].iter().map(other));
        Poly { vars, terms: out }.drop_unused_vars()
    }

    /// `self + rhs` or `self - rhs`.
    fn add_sub(&self, rhs: &Poly, negate: bool) -> Poly {
        if rhs.is_zero() {
            return self.clone();
        }
        if self.is_zero() {
            return if negate { -rhs } else { rhs.clone() };
        }
        if Arc::ptr_eq(&self.vars, &rhs.vars) || self.vars == rhs.vars {
            return Poly::merge_add(self.vars.clone(), &self.terms, &rhs.terms, negate);
        }
        let (vars, a, b) = self.aligned(rhs);
        Poly::merge_add(vars, &a, &b, negate)
    }

    /// Plain text, parseable by [`str::parse`]: terms in descending order,
    /// `*` between factors, `^` for powers.
    pub fn to_text(&self) -> String {
        self.to_string()
    }
}

impl Default for Poly {
    fn default() -> Self {
        Poly::zero()
    }
}

impl From<Rat> for Poly {
    fn from(c: Rat) -> Self {
        Poly::constant(c)
    }
}

impl From<i64> for Poly {
    fn from(c: i64) -> Self {
        Poly::int(c)
    }
}

impl Add for &Poly {
    type Output = Poly;
    fn add(self, rhs: &Poly) -> Poly {
        self.add_sub(rhs, false)
    }
}

impl Sub for &Poly {
    type Output = Poly;
    fn sub(self, rhs: &Poly) -> Poly {
        self.add_sub(rhs, true)
    }
}

impl Mul for &Poly {
    type Output = Poly;
    fn mul(self, rhs: &Poly) -> Poly {
        if self.is_zero() || rhs.is_zero() {
            return Poly::zero();
        }
        if rhs.terms.len() == 1 {
            return self.mul_term(rhs);
        }
        if self.terms.len() == 1 {
            return rhs.mul_term(self);
        }
        Poly::sum_of_products(&[(self, rhs, false)])
    }
}

impl Neg for &Poly {
    type Output = Poly;
    fn neg(self) -> Poly {
        self.scale(&Rat::from(-1))
    }
}

impl Neg for Poly {
    type Output = Poly;
    fn neg(self) -> Poly {
        -(&self)
    }
}

macro_rules! forward_owned {
    ($($tr:ident $m:ident),*) => {$(
        impl $tr for Poly {
            type Output = Poly;
            fn $m(self, rhs: Poly) -> Poly { (&self).$m(&rhs) }
        }
        impl $tr<&Poly> for Poly {
            type Output = Poly;
            fn $m(self, rhs: &Poly) -> Poly { (&self).$m(rhs) }
        }
        impl $tr<Poly> for &Poly {
            type Output = Poly;
            fn $m(self, rhs: Poly) -> Poly { self.$m(&rhs) }
        }
    )*};
}
forward_owned!(Add add, Sub sub, Mul mul);

impl fmt::Display for Poly {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.terms.is_empty() {
            return write!(f, "0");
        }
        for (k, t) in self.terms.iter().enumerate() {
            let neg = t.coef.signum() < 0;
            let c = t.coef.abs();
            if k == 0 {
                if neg {
                    write!(f, "-")?;
                }
            } else {
                write!(f, " {} ", if neg { '-' } else { '+' })?;
            }
            // Written piece by piece: a table's certificates print
            // polynomials of many thousand terms.
            let is_const = t.exps.iter().all(|&e| e == 0);
            let mut star = false;
            if !c.is_one() || is_const {
                write!(f, "{c}")?;
                star = true;
            }
            for (v, &e) in self.vars.iter().zip(&t.exps) {
                if e == 0 {
                    continue;
                }
                if star {
                    f.write_str("*")?;
                }
                star = true;
                f.write_str(v)?;
                if e > 1 {
                    write!(f, "^{e}")?;
                }
            }
        }
        Ok(())
    }
}

impl fmt::Debug for Poly {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Poly({self})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    #[test]
    fn division_by_two_linear_divisors_decides_their_ideal() {
        // The tridiagonal 3x3 determinant with the middle row as pivot
        // lies in the ideal of its two outer diagonal entries (expansion
        // by hand: d2 f0 f1 - b^2 f1 - c^2 f0); a lone f0 f1 + 1 does not.
        let (f0, f1) = (p("c1 + b - w*m1"), p("c - w*m3"));
        let det = &(&(&p("b + c - w*m2") * &f0) * &f1) - &(&(&p("b^2") * &f1) + &(&p("c^2") * &f0));
        let reduce = |x: &Poly| {
            let (q0, r0) = x.div_rem_linear("c1", &f0).unwrap();
            let (q1, r1) = r0.div_rem_linear("c", &f1).unwrap();
            assert_eq!(&(&(&q0 * &f0) + &(&q1 * &f1)) + &r1, *x);
            r1
        };
        assert!(reduce(&det).is_zero());
        assert_eq!(reduce(&(&(&f0 * &f1) + &Poly::one())), Poly::one());
        // Not linear in the variable, or a coefficient that is no constant.
        assert!(det.div_rem_linear("w", &p("w^2 - 1")).is_none());
        assert!(det.div_rem_linear("w", &p("m1*w - 1")).is_none());
    }

    #[test]
    fn eval_f64_is_the_term_by_term_sum() {
        // The powers taken once per variable give the same bits as `powi`
        // per term, the straightforward route.
        let q = p("3*x^7*y^2 - 5/7*x^3*y^5*z + x*z^9 - 2*y^11 + 13/3");
        for point in [(0.37, 2.9, 1.3), (1.7e3, 4.1e-4, 0.999), (-2.5, 0.0, 7.0)] {
            let at: BTreeMap<String, f64> = [("x", point.0), ("y", point.1), ("z", point.2)]
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect();
            let vals: Vec<f64> = q.vars.iter().map(|v| at[v]).collect();
            let direct: f64 = q
                .terms
                .iter()
                .map(|t| {
                    t.exps
                        .iter()
                        .zip(&vals)
                        .fold(t.coef.to_f64(), |m, (&e, &v)| m * v.powi(e as i32))
                })
                .sum();
            assert_eq!(q.eval_f64(&at).unwrap().to_bits(), direct.to_bits());
        }
    }

    #[test]
    fn natural_variable_order() {
        let mut v = vec!["m1", "c12", "c2", "Omega", "c1", "m10", "m2", "d1"];
        v.sort_by(|a, b| var_cmp(a, b));
        assert_eq!(v, ["Omega", "c1", "c2", "c12", "d1", "m1", "m2", "m10"]);
    }

    #[test]
    fn var_cmp_is_the_parsed_order() {
        // The order defined by parsing the digit run as a number.
        fn reference(a: &str, b: &str) -> Ordering {
            fn split(s: &str) -> (&str, Option<u128>, &str) {
                let idx = s.find(|c: char| c.is_ascii_digit()).unwrap_or(s.len());
                let (pre, rest) = s.split_at(idx);
                let end = rest
                    .find(|c: char| !c.is_ascii_digit())
                    .unwrap_or(rest.len());
                (pre, rest[..end].parse::<u128>().ok(), &rest[end..])
            }
            let (pa, na, ra) = split(a);
            let (pb, nb, rb) = split(b);
            pa.cmp(pb).then(na.cmp(&nb)).then(ra.cmp(rb)).then(a.cmp(b))
        }
        let names = [
            "",
            "c",
            "c1",
            "c01",
            "c001",
            "c2",
            "c12",
            "c1a",
            "c1b",
            "c10b",
            "m10",
            "m9",
            "Omega",
            "x",
            "x1y2",
            "x1y10",
            "a0",
            "a00",
            "1",
            "01",
            "10",
            "c340282366920938463463374607431768211455",
            "c340282366920938463463374607431768211456",
            "c999999999999999999999999999999999999999",
        ];
        for a in names {
            for b in names {
                assert_eq!(var_cmp(a, b), reference(a, b), "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn arithmetic_identities() {
        let a = p("x + y");
        let b = p("x - y");
        assert_eq!(&a * &b, p("x^2 - y^2"));
        assert_eq!(&(&a * &b) - &p("x^2"), p("-y^2"));
        assert!((&a - &a).is_zero());
        assert_eq!((&a - &a).vars().len(), 0);
        assert_eq!(a.pow(3), p("x^3 + 3*x^2*y + 3*x*y^2 + y^3"));
    }

    #[test]
    fn exact_division() {
        let f = p("(a + b)*(c - 2*a*b + 1)");
        assert_eq!(f.div_exact(&p("a + b")).unwrap(), p("c - 2*a*b + 1"));
        assert!(f.div_exact(&p("a + 2*b")).is_none());
        assert!(p("x + 1").div_exact(&p("y")).is_none());
    }

    #[test]
    fn primitive_and_sign() {
        let f = p("-6*x + 4/3*y");
        let (c, q) = f.primitive();
        assert_eq!(q, p("9*x - 2*y"));
        assert_eq!(q.scale(&c), f);
    }

    #[test]
    fn packed_arithmetic_edge_cases() {
        // i128 accumulation overflows (2 * (2^63 - 1)^2 > 2^127): Rat fallback.
        let m = i64::MAX;
        let f = p(&format!("{m}*x + {m}"));
        let sq = &f * &f;
        let mut pt = BTreeMap::new();
        pt.insert("x".to_string(), Rat::from(3));
        let v = f.eval(&pt).unwrap();
        assert_eq!(sq.eval(&pt).unwrap(), &v * &v);
        assert_eq!(sq.div_exact(&f).unwrap(), f);
        // Exponents too wide to pack into 128 bits: generic paths.
        let big = 1u32 << 29;
        let names: Vec<String> = ["a", "b", "c", "d", "e"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let mono = |e: [u32; 5], c: i64| Term {
            exps: e.to_vec(),
            coef: Rat::from(c),
        };
        let u = Poly::from_terms(&names, vec![mono([big; 5], 1), mono([0, 0, 0, 0, 1], 1)]);
        let w = Poly::from_terms(&names, vec![mono([big; 5], 1), mono([0, 0, 0, 0, 1], -1)]);
        let prod = &u * &w;
        let want = Poly::from_terms(
            &names,
            vec![mono([2 * big; 5], 1), mono([0, 0, 0, 0, 2], -1)],
        );
        assert_eq!(prod, want);
        assert_eq!(prod.div_exact(&u).unwrap(), w);
        // Inexact divisions are detected (quotient exponent beyond the bound).
        assert!(p("x^2").div_exact(&p("x + y")).is_none());
        assert!(p("x^3*y + 1").div_exact(&p("x*y - 1")).is_none());
        assert_eq!(p("x^2 - y^2").div_exact(&p("x - y")).unwrap(), p("x + y"));
        // Rational coefficients and cancellation in sums.
        let r = p("1/2*x + 1/3*y");
        assert_eq!(&(&r * &r) - &p("1/4*x^2 + 1/9*y^2"), p("1/3*x*y"));
        assert!((&r - &r).is_zero());
    }

    #[test]
    fn substitution_and_evaluation() {
        let f = p("x^2*y - 3*y + 1/2");
        let g = f.subs("x", &Rat::from(2));
        assert_eq!(g, p("y + 1/2"));
        let mut pt = BTreeMap::new();
        pt.insert("x".to_string(), Rat::from(2));
        pt.insert("y".to_string(), "1/3".parse().unwrap());
        assert_eq!(f.eval(&pt).unwrap(), "5/6".parse().unwrap());
        assert_eq!(f.subs_poly("x", &p("y + 1")), p("y^3 + 2*y^2 - 2*y + 1/2"));
        assert_eq!(f.derivative("x"), p("2*x*y"));
    }
}
