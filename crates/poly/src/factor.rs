//! Factorization of multivariate polynomials over Q into irreducibles.
//!
//! [`factor`] writes `p = unit * prod fi^ei` with each `fi` irreducible over
//! Q, primitive with integer coefficients and a positive leading coefficient
//! (in the term order of [`Poly`]).
//!
//! # Algorithm
//!
//! 1. rational content (the unit) and monomial content (each variable to its
//!    least exponent, giving factors such as `m1` or `c12`);
//! 2. recursively, for a primitive `f`:
//!    - one variable: [`crate::factor_univariate`];
//!    - multi-homogeneous (in any set of gradings, found by linear
//!      algebra on the exponents): one variable per grading is set to 1,
//!      the smaller polynomial is factored and its factors are
//!      homogenized back (a bijection on irreducible factors, see
//!      `crate::homog`). The polynomials of `mms` are homogeneous in the
//!      springs and in the masses, so this removes lifting levels and turns
//!      many small inputs univariate;
//!    - degree 1 in some variable `x`: `f = a x + b` is irreducible once its
//!      content `gcd(a, b)` is split off (the content is factored
//!      recursively). This is the common case for the multilinear
//!      polynomials of `mms`;
//!    - otherwise a main variable `x` of least degree (then fewest leading
//!      terms) is chosen and the content in `x` is split off
//!      ([`crate::content_and_pp`]) and factored recursively;
//! 3. `f`, primitive in `x`, is evaluated at integer points for the other
//!    variables (fixed pseudo-random sequence, leading coefficient
//!    non-zero) and the images are factored with Zassenhaus. A square-free
//!    irreducible image proves `f` irreducible (every factorization of `f`
//!    maps to one of the image with the same degrees);
//! 4. otherwise the image factorization that keeps the largest square-free
//!    part, then has the fewest factors, is lifted variable by variable
//!    (Wang's EEZ lifting with a multivariate Diophantine solver over Q;
//!    the univariate Diophantine maps are precomputed as integer matrices)
//!    with *known leading coefficients*. Repeated image factors `u^e` are
//!    lifted as powers (the error is divided by `prod u^(e-1)` before the
//!    Diophantine step), so non-square-free inputs rarely need gcds. The
//!    leading coefficients come from distributing the irreducible factors
//!    of `L = lc_x(f)` (factored recursively, fewer variables) over the
//!    image factors, filtered by a divisibility condition at the point;
//!    when several distributions pass, each is first tried by cheap
//!    bivariate lifts (all variables but one at the point), which reject
//!    a misplaced factor of `L` without a full lift. The variables of `L`
//!    are lifted first, and for large inputs a point with zeros (same
//!    image factorization pattern) is tried first, which keeps the Taylor
//!    expansions sparse. If no distribution lifts, the lc trick is used:
//!    `L^(E-1) f` is lifted with every factor given the leading
//!    coefficient `L`. A lift is accepted only if the product is exactly
//!    right (checked level by level inside the lift); the factors are then
//!    the primitive parts in `x`, each irreducible because its image is;
//! 5. if the lift fails for a square-free image (extraneous factors),
//!    subsets of the image factors are lifted as two-factor splittings
//!    `L f = G1 G2` by increasing size; a success splits `f` (both parts
//!    factored again), and if no subset lifts, `f` is irreducible. A
//!    non-square-free `f` whose images did not separate its factors goes
//!    through [`crate::square_free`] first.
//!
//! Every factor returned has been confirmed by exact arithmetic, and
//! irreducibility is only claimed by the arguments above, never on luck.

use crate::factor_uni::{
    factor_squarefree, factor_univariate, is_squarefree_mod_some_prime, z_primitive, SplitMix,
};
use crate::gcd::content_and_pp;
use crate::homog::Dehom;
use crate::int::Int;
use crate::poly::{Poly, Term};
use crate::rat::Rat;
use crate::sqfree::square_free;
use crate::upoly::UPoly;
use std::cmp::Ordering;
use std::fmt;

/// A factorization over Q: `unit * prod factors[i].0 ^ factors[i].1`.
///
/// Every factor is irreducible over Q, has integer coefficients with gcd 1
/// and a positive leading coefficient; factors are distinct and sorted by
/// total degree, then number of terms, then text.
///
/// ```
/// use poly::{factor, Poly, Rat};
/// let p: Poly = "-2*m1^2*c12*Omega^2 + 2*m1^2*c12^3".parse().unwrap();
/// let f = factor(&p);
/// assert_eq!(f.unit, Rat::from(-2));
/// assert_eq!(f.to_string(), "-2 * c12 * m1^2 * (Omega + c12) * (Omega - c12)");
/// assert_eq!(f.expand(), p);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Factorization {
    /// The rational constant in front.
    pub unit: Rat,
    /// Irreducible factors with their multiplicities.
    pub factors: Vec<(Poly, u32)>,
}

impl Factorization {
    /// Multiplies the factorization out again.
    ///
    /// ```
    /// use poly::{factor, Poly};
    /// let p: Poly = "(x*y - 1)^2*(x + y)*6".parse().unwrap();
    /// assert_eq!(factor(&p).expand(), p);
    /// ```
    pub fn expand(&self) -> Poly {
        let mut acc = Poly::constant(self.unit.clone());
        for (f, e) in &self.factors {
            acc = &acc * &f.pow(*e);
        }
        acc
    }

    /// True when there is no factor of positive degree (a constant input).
    pub fn is_constant(&self) -> bool {
        self.factors.is_empty()
    }
}

impl fmt::Display for Factorization {
    /// `unit * f1^e1 * f2 * ...`, with factors of several terms in
    /// parentheses and a unit of 1 omitted (unless there are no factors).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts: Vec<String> = Vec::new();
        if self.factors.is_empty() || !self.unit.is_one() {
            parts.push(self.unit.to_string());
        }
        for (p, e) in &self.factors {
            let base = if p.num_terms() > 1 {
                format!("({p})")
            } else {
                p.to_string()
            };
            if *e == 1 {
                parts.push(base);
            } else {
                parts.push(format!("{base}^{e}"));
            }
        }
        write!(f, "{}", parts.join(" * "))
    }
}

/// Factors `p` into irreducible polynomials over Q.
///
/// The result satisfies `factor(p).expand() == p`; see [`Factorization`] for
/// the normalization of the factors. The zero polynomial gives unit 0 and no
/// factors.
///
/// ```
/// use poly::{factor, Poly};
/// // The discriminant in Omega of m2*m3*Omega^2 - c23*(m1+m2+m3)*Omega + c1*c23.
/// let d: Poly = "c23^2*(m1+m2+m3)^2 - 4*m2*m3*c1*c23".parse().unwrap();
/// let f = factor(&d);
/// assert_eq!(f.factors.len(), 2);
/// assert_eq!(f.factors[0].0.to_string(), "c23");
/// assert_eq!(f.factors[1].0.num_terms(), 7);
/// assert_eq!(f.expand(), d);
/// ```
pub fn factor(p: &Poly) -> Factorization {
    if p.is_zero() {
        return Factorization {
            unit: Rat::ZERO,
            factors: Vec::new(),
        };
    }
    let (_, q) = p.primitive();
    let mut out: Vec<(Poly, u32)> = Vec::new();
    let q = split_monomial_content(&q, 1, &mut out);
    if !q.is_constant() {
        factor_primitive(&q, 1, &mut out);
    }
    // Merge equal factors and sort.
    out.sort_by(|a, b| cmp_factor(&a.0, &b.0));
    let mut factors: Vec<(Poly, u32)> = Vec::new();
    for (f, e) in out {
        match factors.last_mut() {
            Some((g, k)) if *g == f => *k += e,
            _ => factors.push((f, e)),
        }
    }
    // The unit: lex leading coefficients multiply.
    let mut lc = Rat::ONE;
    for (f, e) in &factors {
        lc = &lc * &f.leading_coef().pow(*e as i32);
    }
    let unit = &p.leading_coef() / &lc;
    Factorization { unit, factors }
}

/// Order of factors: total degree, number of terms, text.
fn cmp_factor(a: &Poly, b: &Poly) -> Ordering {
    a.total_degree()
        .cmp(&b.total_degree())
        .then(a.num_terms().cmp(&b.num_terms()))
        .then_with(|| a.to_string().cmp(&b.to_string()))
        .then_with(|| a.vars().cmp(b.vars()))
}

/// Pushes `v^(k * mult)` for every variable `v^k` dividing `q` and returns
/// the quotient.
fn split_monomial_content(q: &Poly, mult: u32, out: &mut Vec<(Poly, u32)>) -> Poly {
    let mins = q.monomial_content();
    if mins.iter().all(|&m| m == 0) {
        return q.clone();
    }
    for (v, &m) in q.vars().iter().zip(&mins) {
        if m > 0 {
            out.push((Poly::var(v), m * mult));
        }
    }
    q.div_monomial(&mins)
}

/// Integer primitive part with positive leading coefficient.
fn normalize(p: &Poly) -> Poly {
    p.primitive().1
}

/// Factors a primitive integer polynomial with positive leading coefficient
/// and no monomial content; pushes factors with multiplicities times `mult`.
fn factor_primitive(f: &Poly, mult: u32, out: &mut Vec<(Poly, u32)>) {
    if f.is_constant() {
        return;
    }
    let f = &split_monomial_content(f, mult, out);
    if f.is_constant() {
        return;
    }
    let vars = f.vars().to_vec();
    if vars.len() == 1 {
        let x = &vars[0];
        let Some((_, u)) = UPoly::from_poly(f, x) else {
            out.push((f.clone(), mult));
            return;
        };
        let (_, fs) = factor_univariate(&u);
        for (g, e) in fs {
            out.push((g.to_poly(x), e * mult));
        }
        return;
    }
    // Multi-homogeneous: factor with fewer variables (see crate::homog).
    if let Some(d) = Dehom::of(f) {
        let g = d.dehomogenize(f);
        let mut parts = Vec::new();
        factor_primitive(&normalize(&g), mult, &mut parts);
        let homs: Option<Vec<(Poly, u32)>> = parts
            .into_iter()
            .map(|(a, e)| d.homogenize(&a).map(|h| (normalize(&h), e)))
            .collect();
        if let Some(hs) = homs {
            out.extend(hs);
            return;
        }
        // Not reached (factors of a graded polynomial are graded) unless
        // the weights overflow: factor without the gradings.
    }
    // Degree and number of leading terms per variable.
    let mut deg = vec![0u32; vars.len()];
    let mut lead_terms = vec![0usize; vars.len()];
    for t in f.terms() {
        for (i, &e) in t.exps.iter().enumerate() {
            match e.cmp(&deg[i]) {
                Ordering::Greater => {
                    deg[i] = e;
                    lead_terms[i] = 1;
                }
                Ordering::Equal => lead_terms[i] += 1,
                Ordering::Less => {}
            }
        }
    }
    // Degree 1 in some variable: irreducible up to the content.
    if let Some(i) = (0..vars.len())
        .filter(|&i| deg[i] == 1)
        .min_by_key(|&i| lead_terms[i])
    {
        let x = &vars[i];
        let (cont, pp) = content_and_pp(f, x);
        let cont = normalize(&cont);
        if !cont.is_constant() {
            factor_primitive(&cont, mult, out);
        }
        out.push((normalize(&pp), mult));
        return;
    }
    // Main variable: least degree, then fewest leading terms, then name.
    let i = (0..vars.len())
        .min_by_key(|&i| (deg[i], lead_terms[i]))
        .expect("non-constant");
    let x = vars[i].clone();
    let (cont, pp) = content_and_pp(f, &x);
    let cont = normalize(&cont);
    let pp = normalize(&pp);
    if !cont.is_constant() {
        factor_primitive(&cont, mult, out);
        factor_primitive(&pp, mult, out);
        return;
    }
    factor_by_lifting(&pp, &x, mult, out);
}

// ---------------------------------------------------------------------------
// Images.

/// Integer image of an integral `f` with every variable but `x` replaced by
/// `vals` (by index in `f.vars()`), lowest degree first, full length.
fn image_int(f: &Poly, xi: usize, vals: &[i64], powers: &mut [Vec<Int>]) -> Vec<Int> {
    let n = f.terms().iter().map(|t| t.exps[xi]).max().unwrap_or(0) as usize;
    let mut out = vec![Int::ZERO; n + 1];
    for t in f.terms() {
        let mut m = t.coef.numer().clone();
        for (j, &e) in t.exps.iter().enumerate() {
            if j != xi && e > 0 {
                let pw = &mut powers[j];
                while pw.len() <= e as usize {
                    let next = pw.last().expect("1 is there") * &Int::from(vals[j]);
                    pw.push(next);
                }
                m = &m * &pw[e as usize];
            }
        }
        let k = t.exps[xi] as usize;
        out[k] = &out[k] + &m;
    }
    out
}

// ---------------------------------------------------------------------------
// Square-free case.

/// One evaluation point with the factorization of the image.
struct Image {
    /// Values of the other variables, in the order of `ys`.
    point: Vec<i64>,
    /// Irreducible primitive factors of `f(x, point)` and multiplicities.
    factors: Vec<(Vec<Int>, u32)>,
    /// Degree of the square-free part of the image.
    rad_degree: usize,
}

impl Image {
    fn is_squarefree(&self) -> bool {
        self.factors.iter().all(|(_, e)| *e == 1)
    }
    /// Ranking: largest square-free part first (a smaller one means the
    /// point merged factors), then fewest factors.
    fn key(&self) -> (std::cmp::Reverse<usize>, usize) {
        (std::cmp::Reverse(self.rad_degree), self.factors.len())
    }
}

/// Deterministic sequence of evaluation points and their images.
struct ImageSource {
    rng: SplitMix,
    attempts: u64,
}

impl ImageSource {
    /// The image of `f` at the next point, `None` if the leading coefficient
    /// in `x` (index `xi` of `f.vars()`) vanishes there. Values are non-zero
    /// integers whose range grows slowly with the number of attempts.
    fn next(&mut self, f: &Poly, xi: usize, ys_idx: &[usize]) -> Option<Image> {
        self.attempts += 1;
        let range = 8 + 4 * (self.attempts / 10).min(1 << 20);
        let nv = f.vars().len();
        let vals: Vec<i64> = (0..nv)
            .map(|_| {
                let v = (self.rng.next() % range) as i64 + 1;
                if self.rng.next() & 1 == 1 {
                    -v
                } else {
                    v
                }
            })
            .collect();
        image_at(f, xi, ys_idx, &vals)
    }
}

/// The image of `f` at `vals` (one value per variable of `f`, the one of
/// `x` ignored), `None` if the leading coefficient in `x` vanishes there.
fn image_at(f: &Poly, xi: usize, ys_idx: &[usize], vals: &[i64]) -> Option<Image> {
    let nv = f.vars().len();
    let n = f.terms().iter().map(|t| t.exps[xi]).max().unwrap_or(0) as usize;
    let mut powers: Vec<Vec<Int>> = vec![vec![Int::ONE]; nv];
    let img = image_int(f, xi, vals, &mut powers);
    if img.len() != n + 1 || img[n].is_zero() {
        return None;
    }
    let factors: Vec<(Vec<Int>, u32)> = if is_squarefree_mod_some_prime(&img) {
        factor_squarefree(&z_primitive(&img))
            .into_iter()
            .map(|u| (u, 1))
            .collect()
    } else {
        factor_univariate(&UPoly::new(img))
            .1
            .into_iter()
            .map(|(u, e)| (u.coeffs().to_vec(), e))
            .collect()
    };
    let rad_degree = factors.iter().map(|(u, _)| u.len() - 1).sum();
    let point: Vec<i64> = ys_idx.iter().map(|&j| vals[j]).collect();
    Some(Image {
        point,
        factors,
        rad_degree,
    })
}

/// Degrees and multiplicities of the factors of an image, sorted.
fn pattern(im: &Image) -> Vec<(usize, u32)> {
    let mut v: Vec<(usize, u32)> = im.factors.iter().map(|(u, e)| (u.len(), *e)).collect();
    v.sort_unstable();
    v
}

/// Polynomials with at least this many terms are lifted from points with
/// zeros where possible (below, the extra image factorizations cost more
/// than they save).
const ZERO_POINT_MIN_TERMS: usize = 64;

/// `im` with as many coordinates set to 0 as keep the pattern of its
/// factorization (last lifted variables first), `None` if none can be.
/// At 0 the Taylor expansions of the lifting are plain coefficients and
/// the intermediate factors stay sparse; the point is only a choice (the
/// lift checks its result), so this never affects correctness.
fn zero_point(f: &Poly, xi: usize, ys_idx: &[usize], im: &Image) -> Option<Image> {
    let want = pattern(im);
    let mut vals = vec![0i64; f.vars().len()];
    for (&j, &v) in ys_idx.iter().zip(&im.point) {
        vals[j] = v;
    }
    let mut best: Option<Image> = None;
    for &j in ys_idx.iter().rev() {
        let old = vals[j];
        vals[j] = 0;
        match image_at(f, xi, ys_idx, &vals) {
            Some(z) if pattern(&z) == want => best = Some(z),
            _ => vals[j] = old,
        }
    }
    best
}

/// Number of good evaluation points whose images are compared.
const IMAGES: usize = 3;

/// Factors `f`, primitive (over Z and in `x`), of degree >= 2 in `x`, with
/// at least one other variable, by lifting the factorization of images.
fn factor_by_lifting(f: &Poly, x: &str, mult: u32, out: &mut Vec<(Poly, u32)>) {
    let vars = f.vars().to_vec();
    let xi = vars.iter().position(|v| v == x).expect("x occurs");
    let lead = f.lead_in(x);
    // The variables of the leading coefficient are lifted first: a wrong
    // distribution of its factors then fails at an early, cheap level.
    let mut ys_idx: Vec<usize> = (0..vars.len()).filter(|&j| j != xi).collect();
    ys_idx.sort_by_key(|&j| (!lead.has_var(&vars[j]), j));
    let ys: Vec<String> = ys_idx.iter().map(|&j| vars[j].clone()).collect();
    // Evaluation points. The leading coefficient is a non-zero polynomial,
    // so good points exist and the search ends.
    let mut source = ImageSource {
        rng: SplitMix(0x00c0_ffee ^ (f.num_terms() as u64)),
        attempts: 0,
    };
    let mut images: Vec<Image> = Vec::new();
    while images.len() < IMAGES && (source.attempts < 100 || images.is_empty()) {
        let Some(im) = source.next(f, xi, &ys_idx) else {
            continue;
        };
        if im.factors.len() == 1 && im.factors[0].1 == 1 {
            // An irreducible image of full degree: f is irreducible.
            out.push((f.clone(), mult));
            return;
        }
        images.push(im);
    }
    images.sort_by_key(|im| im.key());
    // Full lift at the best points, first at the best one with zeros.
    if let Some(best) = images.first() {
        let zeroed = if f.num_terms() >= ZERO_POINT_MIN_TERMS {
            zero_point(f, xi, &ys_idx, best)
        } else {
            None
        };
        if let Some(im) = &zeroed {
            // Only with known leading coefficients: the lc trick is not
            // worth it here, the random points follow.
            if lead.num_terms() > 1 {
                if let Some(hs) = lift_with_lead_assignment(f, x, &ys, &lead, im) {
                    for (h, e) in hs {
                        out.push((h, e * mult));
                    }
                    return;
                }
            } else if let Some(hs) = lift_all(f, x, &ys, &lead, im) {
                for (h, e) in hs {
                    out.push((h, e * mult));
                }
                return;
            }
        }
        for im in images.iter().take(2) {
            if im.key() != best.key() {
                break;
            }
            if lead.num_terms() > 1 {
                if let Some(hs) = lift_with_lead_assignment(f, x, &ys, &lead, im) {
                    for (h, e) in hs {
                        out.push((h, e * mult));
                    }
                    return;
                }
            }
            if let Some(hs) = lift_all(f, x, &ys, &lead, im) {
                for (h, e) in hs {
                    out.push((h, e * mult));
                }
                return;
            }
        }
    }
    match images.first() {
        Some(im) if im.is_squarefree() => split_by_subsets(f, x, &ys, &lead, im, mult, out),
        _ => {
            // Repeated factors that the images did not separate: Yun.
            let parts = square_free(f).1;
            if parts.len() == 1 && parts[0].1 == 1 {
                // Square-free after all but no image showed it (unlucky
                // points): find a square-free image, which exists.
                loop {
                    let Some(im) = source.next(f, xi, &ys_idx) else {
                        continue;
                    };
                    if !im.is_squarefree() {
                        continue;
                    }
                    if im.factors.len() == 1 {
                        out.push((f.clone(), mult));
                    } else {
                        split_by_subsets(f, x, &ys, &lead, &im, mult, out);
                    }
                    return;
                }
            }
            for (g, e) in parts {
                factor_primitive(&g, mult * e, out);
            }
        }
    }
}

/// Square-free `f` whose image at `im` has extraneous factors: looks for a
/// true factor among subsets of the image factors (by increasing size); if
/// none lifts, `f` is irreducible.
fn split_by_subsets(
    f: &Poly,
    x: &str,
    ys: &[String],
    lead: &Poly,
    im: &Image,
    mult: u32,
    out: &mut Vec<(Poly, u32)>,
) {
    let r = im.factors.len();
    for s in 1..=r / 2 {
        let mut idx: Vec<usize> = (0..s).collect();
        loop {
            if let Some(h) = lift_split(f, x, ys, lead, im, &idx) {
                let q = f.div_exact(&h).expect("a lifted factor divides");
                factor_primitive(&h, mult, out);
                factor_primitive(&normalize(&q), mult, out);
                return;
            }
            // Next combination.
            let mut i = s;
            let mut advanced = false;
            while i > 0 {
                i -= 1;
                if idx[i] < r - s + i {
                    idx[i] += 1;
                    for j in i + 1..s {
                        idx[j] = idx[j - 1] + 1;
                    }
                    advanced = true;
                    break;
                }
            }
            if !advanced {
                break;
            }
        }
    }
    out.push((f.clone(), mult));
}

/// Maximal number of leading-coefficient assignments enumerated.
const MAX_ASSIGNMENTS: usize = 4096;
/// Maximal number of assignments passing the divisibility filter that are
/// screened by bivariate lifts.
const MAX_LC_CANDIDATES: usize = 64;
/// Maximal number of assignments that are lifted in full.
const MAX_LC_TRIES: usize = 6;

/// Lifts all image factors with their true leading coefficients, found by
/// distributing the irreducible factors `q_k^m_k` of `L = lc_x(f)` over the
/// image factors (`lc(h_i) = prod q_k^n_ik`, `sum_i e_i n_ik = m_k`).
/// Assignments are filtered by a necessary condition at the evaluation
/// point: `lc(u_i)` divides `cont(L) * l_i(a)` (the image of `h_i` is an
/// integer multiple of the primitive `u_i`, and the integer content of
/// `lc(h_i)` divides `cont(L)`). Lifting `f / cont(L)` then avoids the
/// growth of the lc trick. `None` if no assignment lifts.
fn lift_with_lead_assignment(
    f: &Poly,
    x: &str,
    ys: &[String],
    lead: &Poly,
    im: &Image,
) -> Option<Vec<(Poly, u32)>> {
    let lf = factor(lead);
    let r = im.factors.len();
    let exps: Vec<u32> = im.factors.iter().map(|(_, e)| *e).collect();
    let a: Vec<Rat> = im.point.iter().map(|&v| Rat::from(v)).collect();
    let qa: Vec<Rat> = lf
        .factors
        .iter()
        .map(|(q, _)| eval_all(q, ys, &a))
        .collect();
    let cont = lf.unit.abs();
    // Per irreducible factor of L: all distributions n with sum e_i n_i = m.
    let mut per_k: Vec<Vec<Vec<u32>>> = Vec::new();
    for (_, m) in &lf.factors {
        let mut acc = Vec::new();
        distributions(&exps, *m, &mut vec![0; r], 0, &mut acc);
        per_k.push(acc);
    }
    let total: usize = per_k
        .iter()
        .map(|v| v.len())
        .try_fold(1usize, |acc, n| acc.checked_mul(n))
        .unwrap_or(usize::MAX);
    if total == 0 || total > MAX_ASSIGNMENTS {
        return None;
    }
    // Assignments passing the divisibility filter, as (leads, images).
    let mut candidates: Vec<(Vec<Poly>, Vec<QPoly>)> = Vec::new();
    let mut choice = vec![0usize; per_k.len()];
    for _ in 0..total {
        // l_i(a) for this assignment.
        let mut la = vec![Rat::ONE; r];
        for (k, &c) in choice.iter().enumerate() {
            for (i, &n) in per_k[k][c].iter().enumerate() {
                if n > 0 {
                    la[i] = &la[i] * &qa[k].pow(n as i32);
                }
            }
        }
        let pass = la.iter().zip(&im.factors).all(|(l, (u, _))| {
            let v = (&cont * l).numer().clone();
            let lc = u.last().expect("non-zero");
            !v.is_zero() && v.div_rem(lc).1.is_zero()
        });
        if pass {
            let leads: Vec<Poly> = (0..r)
                .map(|i| {
                    let mut l = Poly::one();
                    for (k, &c) in choice.iter().enumerate() {
                        let n = per_k[k][c][i];
                        if n > 0 {
                            l = &l * &lf.factors[k].0.pow(n);
                        }
                    }
                    l
                })
                .collect();
            let images: Vec<QPoly> = im
                .factors
                .iter()
                .zip(&la)
                .map(|((u, _), l)| with_lead(u, l))
                .collect();
            candidates.push((leads, images));
            if candidates.len() >= MAX_LC_CANDIDATES {
                break;
            }
        }
        // Next assignment (mixed radix).
        for (k, c) in choice.iter_mut().enumerate() {
            *c += 1;
            if *c < per_k[k].len() {
                break;
            }
            *c = 0;
        }
    }
    let big_f = f.scale(&cont.recip());
    if candidates.len() > 1 && ys.len() > 1 {
        // Several candidates: a wrong one fails the bivariate lift in some
        // variable of a misplaced lc factor, far cheaper than a full lift.
        let bivariate = bivariate_images(&big_f, ys, &a);
        candidates.retain(|(leads, images)| {
            bivariate.iter().all(|(j, fj)| {
                let lj: Vec<Poly> = leads.iter().map(|l| eval_except(l, ys, &a, *j)).collect();
                let (yj, aj) = (&ys[*j..*j + 1], &a[*j..*j + 1]);
                hensel_lift(fj, x, yj, aj, images.clone(), &exps, &lj).is_some()
            })
        });
    }
    for (leads, images) in candidates.into_iter().take(MAX_LC_TRIES) {
        if let Some(gs) = hensel_lift(&big_f, x, ys, &a, images, &exps, &leads) {
            // The lift reproduced f / cont exactly, so the product of the
            // normalized factors is f up to a constant, fixed by the
            // leading coefficients.
            let hs: Vec<Poly> = gs.iter().map(normalize).collect();
            if same_up_to_lc(&hs, &exps, f) {
                return Some(hs.into_iter().zip(exps).collect());
            }
        }
    }
    None
}

/// For each variable `ys[j]` of `f`, `f` with every other `ys` at `a`
/// (`(j, image)`, last variables first).
fn bivariate_images(f: &Poly, ys: &[String], a: &[Rat]) -> Vec<(usize, Poly)> {
    (0..ys.len())
        .rev()
        .filter(|&j| f.has_var(&ys[j]))
        .map(|j| (j, eval_except(f, ys, a, j)))
        .collect()
}

/// `p` with every `ys[l]`, `l != j`, at `a[l]`.
fn eval_except(p: &Poly, ys: &[String], a: &[Rat], j: usize) -> Poly {
    let mut q = p.clone();
    for (l, (y, v)) in ys.iter().zip(a).enumerate() {
        if l != j {
            q = q.subs(y, v);
        }
    }
    q
}

/// All `n` (pushed to `acc`) with `sum_i w_i n_i = m`, filling from `i`.
fn distributions(w: &[u32], m: u32, cur: &mut Vec<u32>, i: usize, acc: &mut Vec<Vec<u32>>) {
    if acc.len() > MAX_ASSIGNMENTS {
        return;
    }
    if i == w.len() {
        if m == 0 {
            acc.push(cur.clone());
        }
        return;
    }
    let mut n = 0;
    while n * w[i] <= m {
        cur[i] = n;
        distributions(w, m - n * w[i], cur, i + 1, acc);
        n += 1;
    }
    cur[i] = 0;
}

/// Lifts all image factors at once with their multiplicities (lc trick).
/// Returns the irreducible factors of `f` with multiplicities, or `None` if
/// the image has extraneous factors.
fn lift_all(f: &Poly, x: &str, ys: &[String], lead: &Poly, im: &Image) -> Option<Vec<(Poly, u32)>> {
    let total: u32 = im.factors.iter().map(|(_, e)| e).sum();
    let a: Vec<Rat> = im.point.iter().map(|&v| Rat::from(v)).collect();
    let la = eval_all(lead, ys, &a);
    let images: Vec<Vec<Rat>> = im.factors.iter().map(|(u, _)| with_lead(u, &la)).collect();
    let exps: Vec<u32> = im.factors.iter().map(|(_, e)| *e).collect();
    let big_f = f * &lead.pow(total - 1);
    let leads = vec![lead.clone(); exps.len()];
    let gs = hensel_lift(&big_f, x, ys, &a, images, &exps, &leads)?;
    let hs: Vec<Poly> = gs
        .iter()
        .map(|g| normalize(&content_and_pp(g, x).1))
        .collect();
    // prod g_i^e_i = L^(E-1) f exactly, so the primitive parts multiply to
    // f up to a constant (Gauss), fixed by the leading coefficients.
    if !same_up_to_lc(&hs, &exps, f) {
        return None;
    }
    Some(hs.into_iter().zip(exps).collect())
}

/// `prod hs[i]^es[i]` and `f`, known to agree up to a constant factor,
/// are equal: compares their leading coefficients (the lex leading term of
/// a product is the product of the leading terms).
fn same_up_to_lc(hs: &[Poly], es: &[u32], f: &Poly) -> bool {
    let mut lc = Rat::ONE;
    for (h, &e) in hs.iter().zip(es) {
        lc = &lc * &h.leading_coef().pow(e as i32);
    }
    lc == f.leading_coef()
}

/// Lifts the two-factor splitting of a square-free image given by the
/// subset `idx`. Returns the (normalized) true factor whose image is the
/// subset product.
fn lift_split(
    f: &Poly,
    x: &str,
    ys: &[String],
    lead: &Poly,
    im: &Image,
    idx: &[usize],
) -> Option<Poly> {
    let a: Vec<Rat> = im.point.iter().map(|&v| Rat::from(v)).collect();
    let la = eval_all(lead, ys, &a);
    let mut u1: Vec<Int> = vec![Int::ONE];
    let mut u2: Vec<Int> = vec![Int::ONE];
    for (i, (u, _)) in im.factors.iter().enumerate() {
        if idx.contains(&i) {
            u1 = z_mul(&u1, u);
        } else {
            u2 = z_mul(&u2, u);
        }
    }
    let images = vec![with_lead(&u1, &la), with_lead(&u2, &la)];
    let big_f = f * lead;
    let leads = [lead.clone(), lead.clone()];
    let gs = hensel_lift(&big_f, x, ys, &a, images, &[1, 1], &leads)?;
    let h = normalize(&content_and_pp(&gs[0], x).1);
    if h.degree(x) == 0 || h.degree(x) >= f.degree(x) {
        return None;
    }
    f.div_exact(&h)?;
    Some(h)
}

fn z_mul(a: &[Int], b: &[Int]) -> Vec<Int> {
    let mut v = vec![Int::ZERO; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            v[i + j] = &v[i + j] + &(x * y);
        }
    }
    v
}

/// `u` scaled to the leading coefficient `la`.
fn with_lead(u: &[Int], la: &Rat) -> Vec<Rat> {
    let s = la / &Rat::from_int(u.last().expect("non-zero").clone());
    u.iter().map(|c| &Rat::from_int(c.clone()) * &s).collect()
}

/// Value of a polynomial in (a subset of) `ys` at `a`.
fn eval_all(p: &Poly, ys: &[String], a: &[Rat]) -> Rat {
    let mut q = p.clone();
    for (y, v) in ys.iter().zip(a) {
        q = q.subs(y, v);
    }
    q.as_constant().expect("all variables substituted")
}

// ---------------------------------------------------------------------------
// Dense univariate polynomials over Q.

type QPoly = Vec<Rat>;

fn q_trim(v: &mut QPoly) {
    while v.last().is_some_and(|c| c.is_zero()) {
        v.pop();
    }
}

fn q_mul(a: &[Rat], b: &[Rat]) -> QPoly {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut v = vec![Rat::ZERO; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        if x.is_zero() {
            continue;
        }
        for (j, y) in b.iter().enumerate() {
            v[i + j] = &v[i + j] + &(x * y);
        }
    }
    q_trim(&mut v);
    v
}

fn q_sub(a: &[Rat], b: &[Rat]) -> QPoly {
    let n = a.len().max(b.len());
    let mut v: QPoly = (0..n)
        .map(|i| match (a.get(i), b.get(i)) {
            (Some(x), Some(y)) => x - y,
            (Some(x), None) => x.clone(),
            (None, Some(y)) => -y,
            (None, None) => Rat::ZERO,
        })
        .collect();
    q_trim(&mut v);
    v
}

fn q_divrem(a: &[Rat], b: &[Rat]) -> (QPoly, QPoly) {
    let nb = b.len();
    if a.len() < nb {
        return (Vec::new(), a.to_vec());
    }
    let inv = b[nb - 1].recip();
    let mut r = a.to_vec();
    let mut q = vec![Rat::ZERO; a.len() - nb + 1];
    for i in (0..q.len()).rev() {
        if r[i + nb - 1].is_zero() {
            continue;
        }
        let c = &r[i + nb - 1] * &inv;
        for j in 0..nb {
            r[i + j] = &r[i + j] - &(&c * &b[j]);
        }
        q[i] = c;
    }
    q_trim(&mut r);
    q_trim(&mut q);
    (q, r)
}

/// Inverse of `a` modulo `m` (coprime), of degree < deg m.
fn q_inv_mod(a: &[Rat], m: &[Rat]) -> QPoly {
    let (mut r0, mut r1) = (m.to_vec(), q_divrem(a, m).1);
    let (mut s0, mut s1): (QPoly, QPoly) = (Vec::new(), vec![Rat::ONE]);
    while !r1.is_empty() {
        let (q, r) = q_divrem(&r0, &r1);
        let s2 = q_sub(&s0, &q_mul(&q, &s1));
        r0 = r1;
        r1 = r;
        s0 = s1;
        s1 = s2;
    }
    let inv = r0[0].recip();
    let s: QPoly = s0.iter().map(|c| c * &inv).collect();
    q_divrem(&s, m).1
}

fn q_from_poly(p: &Poly, x: &str) -> QPoly {
    let mut v: QPoly = p
        .coeffs_in(x)
        .iter()
        .map(|c| c.as_constant().unwrap_or(Rat::ZERO))
        .collect();
    q_trim(&mut v);
    v
}

fn q_to_poly(q: &[Rat], x: &str) -> Poly {
    let vars = [x.to_string()];
    let terms = q
        .iter()
        .enumerate()
        .filter(|(_, c)| !c.is_zero())
        .map(|(i, c)| Term {
            exps: vec![i as u32],
            coef: c.clone(),
        })
        .collect();
    Poly::from_terms(&vars, terms)
}

// ---------------------------------------------------------------------------
// Hensel lifting with known leading coefficients (Wang's EEZ).

struct Lifter<'a> {
    x: &'a str,
    ys: &'a [String],
    a: &'a [Rat],
    /// Univariate images of the factors (all `ys` at `a`).
    units: Vec<QPoly>,
    /// `s_i` with `sum s_i prod_{l != i} u_l = 1`.
    bezout: Vec<QPoly>,
    /// The linear maps `c -> (c s_i) mod u_i` for `deg c < n`, as integer
    /// matrices over a common denominator: row `k` is the image of `x^k`.
    maps: Vec<(Vec<Vec<Int>>, Int)>,
    /// Degree bound for each `y`.
    bounds: Vec<u32>,
}

/// Common denominator `d` and integer numerators of a list of rationals.
fn over_common_denominator(v: &[Rat]) -> (Vec<Int>, Int) {
    let mut d = Int::ONE;
    for c in v {
        d = d.lcm(c.denom());
    }
    let nums = v
        .iter()
        .map(|c| c.numer() * &d.div_exact(c.denom()))
        .collect();
    (nums, d)
}

/// The matrix of `c -> (c s) mod u` on polynomials of degree < n.
fn reduction_map(s: &[Rat], u: &[Rat], n: usize) -> (Vec<Vec<Int>>, Int) {
    let du = u.len() - 1;
    let mut rows: Vec<QPoly> = Vec::with_capacity(n);
    let mut cur = q_divrem(s, u).1;
    for _ in 0..n {
        let mut row = cur.clone();
        row.resize(du, Rat::ZERO);
        rows.push(row);
        // cur = (x * cur) mod u
        let mut shifted = vec![Rat::ZERO];
        shifted.extend(cur.iter().cloned());
        cur = q_divrem(&shifted, u).1;
    }
    let flat: Vec<Rat> = rows.iter().flatten().cloned().collect();
    let (nums, d) = over_common_denominator(&flat);
    let mat = nums.chunks(du.max(1)).map(|c| c.to_vec()).collect();
    (mat, d)
}

/// `(y - a)^d`.
fn shift_pow(y: &str, a: &Rat, d: u32) -> Poly {
    (&Poly::var(y) - &Poly::constant(a.clone())).pow(d)
}

/// Coefficient of `(y - a)^d` in the Taylor expansion of `e` at `y = a`:
/// `sum_{k >= d} C(k, d) a^(k-d) c_k` over the coefficients `c_k` of `y^k`,
/// in one pass over the terms.
fn taylor_coeff(e: &Poly, y: &str, a: &Rat, d: u32) -> Poly {
    let Some(i) = e.vars().iter().position(|v| v == y) else {
        return if d == 0 { e.clone() } else { Poly::zero() };
    };
    let deg = e.terms().iter().map(|t| t.exps[i]).max().unwrap_or(0);
    if deg < d {
        return Poly::zero();
    }
    if a.is_zero() {
        return e.coeffs_in(y).swap_remove(d as usize);
    }
    // w[k - d] = C(k, d) a^(k - d).
    let mut w: Vec<Rat> = Vec::with_capacity((deg - d + 1) as usize);
    let mut binom = Int::ONE;
    let mut apow = Rat::ONE;
    for k in d..=deg {
        if k > d {
            binom = (&binom * &Int::from(k as i64)).div_exact(&Int::from((k - d) as i64));
            apow = &apow * a;
        }
        w.push(&Rat::from_int(binom.clone()) * &apow);
    }
    let terms: Vec<Term> = e
        .terms()
        .iter()
        .filter(|t| t.exps[i] >= d)
        .map(|t| {
            let mut exps = t.exps.clone();
            let k = exps[i];
            exps[i] = 0;
            Term {
                exps,
                coef: &t.coef * &w[(k - d) as usize],
            }
        })
        .collect();
    Poly::from_terms_like(e, terms)
}

fn product(ps: &[Poly]) -> Poly {
    let mut acc = Poly::one();
    for p in ps {
        acc = &acc * p;
    }
    acc
}

/// Products of all but one factor.
fn cofactors(us: &[Poly]) -> Vec<Poly> {
    (0..us.len())
        .map(|i| {
            let others: Vec<Poly> = us
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, u)| u.clone())
                .collect();
            product(&others)
        })
        .collect()
}

impl Lifter<'_> {
    /// Solves `sum sigma_i * prod_{l != i} us[l] = c` for `sigma_i` with
    /// `deg_x sigma_i < deg_x us[i]`, where the `us` (given at each level
    /// `m` with `ys[m..]` evaluated) and `c` involve `x` and `ys[..m]`.
    fn diophant(&self, levels: &[(Vec<Poly>, Vec<Poly>)], m: usize, c: &Poly) -> Vec<Poly> {
        if m == 0 {
            let cq = q_from_poly(c, self.x);
            let n = self.maps.first().map_or(0, |m| m.0.len());
            if cq.len() > n {
                // Not reached while lifting (deg c < n); the general formula.
                return self
                    .units
                    .iter()
                    .zip(&self.bezout)
                    .map(|(u, s)| q_to_poly(&q_divrem(&q_mul(&cq, s), u).1, self.x))
                    .collect();
            }
            let (cn, cd) = over_common_denominator(&cq);
            return self
                .maps
                .iter()
                .map(|(mat, d)| {
                    let du = mat.first().map_or(0, |r| r.len());
                    let den = d * &cd;
                    let mut acc = vec![Int::ZERO; du];
                    for (ck, row) in cn.iter().zip(mat) {
                        if ck.is_zero() {
                            continue;
                        }
                        for (a, r) in acc.iter_mut().zip(row) {
                            if !r.is_zero() {
                                *a = &*a + &(ck * r);
                            }
                        }
                    }
                    let coeffs: QPoly = acc.into_iter().map(|a| Rat::new(a, den.clone())).collect();
                    q_to_poly(&coeffs, self.x)
                })
                .collect();
        }
        let y = &self.ys[m - 1];
        let a = &self.a[m - 1];
        let bs = &levels[m].1;
        let mut sigma = self.diophant(levels, m - 1, &c.subs(y, a));
        let mut e = c - &sum_products(&sigma, bs);
        for d in 1..=self.bounds[m - 1] {
            if e.is_zero() {
                break;
            }
            let cd = taylor_coeff(&e, y, a, d);
            if cd.is_zero() {
                continue;
            }
            let delta = self.diophant(levels, m - 1, &cd);
            let t = shift_pow(y, a, d);
            for (i, di) in delta.iter().enumerate() {
                if di.is_zero() {
                    continue;
                }
                let dt = di * &t;
                e = &e - &(&dt * &bs[i]);
                sigma[i] = &sigma[i] + &dt;
            }
        }
        sigma
    }
}

fn sum_products(a: &[Poly], b: &[Poly]) -> Poly {
    let mut acc = Poly::zero();
    for (x, y) in a.iter().zip(b) {
        if !x.is_zero() {
            acc = &acc + &(x * y);
        }
    }
    acc
}

/// `prod ps[i]^es[i]`.
fn product_pow(ps: &[Poly], es: &[u32]) -> Poly {
    let mut acc = Poly::one();
    for (p, &e) in ps.iter().zip(es) {
        acc = &acc * &p.pow(e);
    }
    acc
}

/// Lifts `F = prod G_i^e_i` from the univariate images `images` (pairwise
/// coprime, leading coefficients `lead(a)`) to factors with leading
/// coefficient `lead` in `x`. `None` when no such factorization exists.
///
/// With `G_i = g_i + sigma_i t^d + O(t^(d+1))`, `t = y - a`, the degree-`d`
/// Taylor coefficient of the error is
/// `prod u_l^(e_l - 1) * sum e_i sigma_i prod_{l != i} u_l` (`u` the images
/// at `t = 0`), so the usual Diophantine equation is solved after an exact
/// division by `prod u_l^(e_l - 1)`.
fn hensel_lift(
    big_f: &Poly,
    x: &str,
    ys: &[String],
    a: &[Rat],
    images: Vec<QPoly>,
    exps: &[u32],
    leads: &[Poly],
) -> Option<Vec<Poly>> {
    let k = ys.len();
    // F_j and L_j: ys[j..] evaluated.
    let mut fs = vec![big_f.clone(); k + 1];
    let mut ls = vec![leads.to_vec(); k + 1];
    for j in (0..k).rev() {
        fs[j] = fs[j + 1].subs(&ys[j], &a[j]);
        ls[j] = ls[j + 1].iter().map(|l| l.subs(&ys[j], &a[j])).collect();
    }
    // Univariate check and Bezout data.
    let units = images;
    let unit_polys: Vec<Poly> = units.iter().map(|u| q_to_poly(u, x)).collect();
    if product_pow(&unit_polys, exps) != fs[0] {
        return None;
    }
    let powered = exps.iter().any(|&e| e > 1);
    let bezout: Vec<QPoly> = units
        .iter()
        .enumerate()
        .map(|(i, u)| {
            let mut b: QPoly = vec![Rat::ONE];
            for (j, w) in units.iter().enumerate() {
                if j != i {
                    b = q_divrem(&q_mul(&b, w), u).1;
                }
            }
            q_inv_mod(&b, u)
        })
        .collect();
    let degs: Vec<u32> = units.iter().map(|u| (u.len() - 1) as u32).collect();
    let total_degree: usize = degs.iter().map(|&d| d as usize).sum();
    let maps = bezout
        .iter()
        .zip(&units)
        .map(|(s, u)| reduction_map(s, u, total_degree))
        .collect();
    let bounds: Vec<u32> = ys.iter().map(|y| big_f.degree(y)).collect();
    let lifter = Lifter {
        x,
        ys,
        a,
        units,
        bezout,
        maps,
        bounds,
    };
    let mut g: Vec<Poly> = unit_polys;
    for j in 0..k {
        // Diophantine data: levels[m] = (G with ys[m..j] at a, cofactors).
        let mut levels: Vec<(Vec<Poly>, Vec<Poly>)> = Vec::with_capacity(j + 1);
        {
            let mut us = vec![g.clone()];
            for m in (0..j).rev() {
                let prev: Vec<Poly> = us
                    .last()
                    .expect("non-empty")
                    .iter()
                    .map(|u| u.subs(&ys[m], &a[m]))
                    .collect();
                us.push(prev);
            }
            us.reverse();
            for u in us {
                let cf = cofactors(&u);
                levels.push((u, cf));
            }
        }
        // Impose the leading coefficient.
        for ((gi, &d), lj) in g.iter_mut().zip(&degs).zip(&ls[j + 1]) {
            let cur = gi.lead_in(x);
            *gi = &*gi + &(lj - &cur).mul_var_pow(x, d);
        }
        let y = &ys[j];
        let target = &fs[j + 1];
        // prod u_l^(e_l - 1) at this level.
        let repeated = if powered {
            let reduced: Vec<u32> = exps.iter().map(|e| e - 1).collect();
            Some(product_pow(&levels[j].0, &reduced))
        } else {
            None
        };
        let mut exact = false;
        for d in 1..=lifter.bounds[j] {
            let e = target - &product_pow(&g, exps);
            if e.is_zero() {
                exact = true;
                break;
            }
            let mut c = taylor_coeff(&e, y, &a[j], d);
            if c.is_zero() {
                continue;
            }
            if let Some(rep) = &repeated {
                c = c.div_exact(rep)?;
            }
            let sigma = lifter.diophant(&levels, j, &c);
            let t = shift_pow(y, &a[j], d);
            for ((gi, si), &ei) in g.iter_mut().zip(&sigma).zip(exps) {
                if !si.is_zero() {
                    let si = if ei > 1 {
                        si.scale(&Rat::new(Int::ONE, Int::from(ei as i64)))
                    } else {
                        si.clone()
                    };
                    *gi = &*gi + &(&si * &t);
                }
            }
        }
        if !exact && &product_pow(&g, exps) != target {
            return None;
        }
    }
    Some(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    fn check(f: &Poly) -> Factorization {
        let fa = factor(f);
        assert_eq!(fa.expand(), *f, "product of the factors of {f}");
        for (g, e) in &fa.factors {
            assert!(*e >= 1);
            assert!(g.is_integral());
            assert_eq!(g.primitive().0, Rat::ONE, "{g} primitive, positive lc");
        }
        for w in fa.factors.windows(2) {
            assert_eq!(cmp_factor(&w[0].0, &w[1].0), Ordering::Less);
        }
        fa
    }

    #[test]
    fn trivial_inputs() {
        let z = factor(&Poly::zero());
        assert_eq!(z.unit, Rat::ZERO);
        assert!(z.factors.is_empty());
        let c = check(&p("-3/4"));
        assert_eq!(c.unit, "-3/4".parse().unwrap());
        assert!(c.factors.is_empty());
        let m = check(&p("6*m1^2*c12*Omega"));
        assert_eq!(m.unit, Rat::from(6));
        assert_eq!(m.factors.len(), 3);
        assert_eq!(m.to_string(), "6 * Omega * c12 * m1^2");
    }

    #[test]
    fn discriminant_example() {
        let d = p("c23*(c23*(m1+m2+m3)^2 - 4*m2*m3*c1)");
        let f = check(&d);
        assert_eq!(f.factors.len(), 2);
        // Positive leading coefficient in the term order (c1 first).
        assert_eq!(f.factors[1].0, p("4*m2*m3*c1 - c23*(m1+m2+m3)^2"));
        assert_eq!(f.unit, Rat::from(-1));
    }

    #[test]
    fn rational_input_and_unit() {
        let f = check(&p("x^2/4 - y^2/9"));
        assert_eq!(f.unit, "1/36".parse().unwrap());
        let texts: Vec<String> = f.factors.iter().map(|(g, _)| g.to_string()).collect();
        assert_eq!(texts, ["3*x + 2*y", "3*x - 2*y"]);
        let g = check(&p("-(x*y - 1)^3*(x + y)^2*y^4/5"));
        assert_eq!(g.unit, "-1/5".parse().unwrap());
        assert_eq!(g.to_string(), "-1/5 * y^4 * (x + y)^2 * (x*y - 1)^3");
    }

    /// Known irreducibles: linear in some variable with coprime
    /// coefficients, quadratic forms of rank >= 3, the Klein quartic, ...
    const IRREDUCIBLE: [&str; 10] = [
        "x*y + z + 1",
        "x^2 + y^2 + z^2 + 1",
        "x^2 - 2*y^2 + 3*z^2",
        "x^3*y + y^3*z + z^3*x",
        "x^2 + y^3 + 1",
        "x^4 + y^4 + z",
        "x*z^2 - y^2 + 2",
        "y^2*z^2 + x^2 - 3*x*y*z + 5",
        "x^3 - 2*y^3",
        "x*y*z - x - y - z + 7",
    ];

    #[test]
    fn random_products_of_known_irreducibles() {
        let irr: Vec<Poly> = IRREDUCIBLE.iter().map(|s| normalize(&p(s))).collect();
        for g in &irr {
            let f = check(g);
            assert_eq!(f.factors, vec![(g.clone(), 1)], "{g} is irreducible");
        }
        let mut rng = SplitMix(2024);
        for round in 0..24 {
            let mut f = Poly::constant(Rat::new(Int::from(round as i64 - 11), Int::from(3)));
            if f.is_zero() {
                f = Poly::one();
            }
            let mut want: Vec<(Poly, u32)> = Vec::new();
            // Two to four distinct irreducibles with exponents 1..=3.
            let k = 2 + (rng.next() % 3) as usize;
            let mut chosen: Vec<usize> = Vec::new();
            while chosen.len() < k {
                let i = (rng.next() % irr.len() as u64) as usize;
                if !chosen.contains(&i) {
                    chosen.push(i);
                }
            }
            for &i in &chosen {
                let e = 1 + (rng.next() % 3) as u32;
                // Keep the products moderate.
                let e = if irr[i].total_degree() > 3 {
                    e.min(2)
                } else {
                    e
                };
                f = &f * &irr[i].pow(e);
                want.push((irr[i].clone(), e));
            }
            let fa = check(&f);
            want.sort_by(|a, b| cmp_factor(&a.0, &b.0));
            assert_eq!(fa.factors, want, "round {round}: {f}");
        }
    }

    #[test]
    fn extraneous_image_factors_are_recombined() {
        // x^2 - y is irreducible but its image at y = 4 splits.
        let f = p("(x^2 - y)*(x + y + 1)");
        let ys = vec!["y".to_string()];
        let lead = f.lead_in("x");
        let im = Image {
            point: vec![4],
            factors: vec![
                (vec![Int::from(-2), Int::ONE], 1),
                (vec![Int::from(2), Int::ONE], 1),
                (vec![Int::from(5), Int::ONE], 1),
            ],
            rad_degree: 3,
        };
        assert!(lift_all(&f, "x", &ys, &lead, &im).is_none());
        let mut out = Vec::new();
        split_by_subsets(&f, "x", &ys, &lead, &im, 2, &mut out);
        out.sort_by(|a, b| cmp_factor(&a.0, &b.0));
        assert_eq!(out, vec![(p("x + y + 1"), 2), (p("x^2 - y"), 2)]);
        // An irreducible polynomial with a split image stays whole.
        let g = p("x^2 - y");
        let im = Image {
            point: vec![4],
            factors: vec![
                (vec![Int::from(-2), Int::ONE], 1),
                (vec![Int::from(2), Int::ONE], 1),
            ],
            rad_degree: 2,
        };
        let mut out = Vec::new();
        split_by_subsets(&g, "x", &ys, &g.lead_in("x"), &im, 1, &mut out);
        assert_eq!(out, vec![(g.clone(), 1)]);
        // The same polynomials through the public entry point.
        assert_eq!(check(&f).factors.len(), 2);
        assert_eq!(check(&g).factors, vec![(g, 1)]);
    }

    #[test]
    fn leading_coefficients_are_distributed() {
        // Non-monomial leading coefficients in every variable, a square.
        let a = p("(y + z + 1)*x^2 + (y - z)*x + y*z + 2");
        let b = p("(y*z - 1)*x^2 + (y + 2)*x + z^2 + y");
        let f = &(&a * &a) * &b;
        let fa = check(&f);
        let mut want = vec![(normalize(&b), 1), (normalize(&a), 2)];
        want.sort_by(|u, v| cmp_factor(&u.0, &v.0));
        assert_eq!(fa.factors, want);
    }

    #[test]
    fn bivariate_and_multivariate_products() {
        let cases = [
            ("(x^2 + y^2 + 1)*(x^2 - y)", 2),
            ("(x^2*y + 3*y^2 - x)*(x^3 + y*x + 2)^2*(x - y)", 3),
            ("(x^2 + y*z + 1)*(x^2 - z^2*y + 3*x)*(y^2*x^2 + z)", 3),
            ("x^4 + y^4", 1),
            ("x^4 - y^4", 3),
            ("(x^2 - 2*y^2)*(x^2 - 3*y^2)*(x^2 - 6*y^2)", 3),
        ];
        for (s, count) in cases {
            let f = check(&p(s));
            assert_eq!(f.factors.len(), count, "{s}: {f}");
        }
    }
}

#[cfg(test)]
mod workload {
    //! Chain models: masses m1..mn, ground spring c1, springs c12, c23, ...
    use super::*;
    use std::time::Instant;

    pub(super) fn chain(n: usize) -> (Poly, Poly) {
        let v = |s: String| Poly::var(&s);
        let om = Poly::var("Omega");
        let spring = |i: usize| -> Poly {
            // spring between mass i and i+1 (1-based), i = 0 is the ground spring c1
            if i == 0 {
                v("c1".into())
            } else {
                v(format!("c{}{}", i, i + 1))
            }
        };
        let mut m = vec![vec![Poly::zero(); n]; n];
        for i in 0..n {
            let mut d = spring(i);
            if i + 1 < n {
                d = &d + &spring(i + 1);
                m[i][i + 1] = -spring(i + 1);
                m[i + 1][i] = -spring(i + 1);
            }
            m[i][i] = &d - &(&om * &v(format!("m{}", i + 1)));
        }
        let den = crate::matrix::det(&m);
        let num = driving_point_num(&m, 0);
        (num, den)
    }

    /// Minor of the dynamic stiffness matrix without row and column `k`.
    pub(super) fn driving_point_num(m: &[Vec<Poly>], k: usize) -> Poly {
        let minor: Vec<Vec<Poly>> = m
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != k)
            .map(|(_, r)| {
                r.iter()
                    .enumerate()
                    .filter(|(j, _)| *j != k)
                    .map(|(_, c)| c.clone())
                    .collect()
            })
            .collect();
        crate::matrix::det(&minor)
    }

    /// The chain matrix of `n` masses.
    pub(super) fn chain_matrix(n: usize) -> Vec<Vec<Poly>> {
        let v = |s: String| Poly::var(&s);
        let om = Poly::var("Omega");
        let spring = |i: usize| -> Poly {
            if i == 0 {
                v("c1".into())
            } else {
                v(format!("c{}{}", i, i + 1))
            }
        };
        let mut m = vec![vec![Poly::zero(); n]; n];
        for i in 0..n {
            let mut d = spring(i);
            if i + 1 < n {
                d = &d + &spring(i + 1);
                m[i][i + 1] = -spring(i + 1);
                m[i + 1][i] = -spring(i + 1);
            }
            m[i][i] = &d - &(&om * &v(format!("m{}", i + 1)));
        }
        m
    }

    fn run(n: usize, verbose: bool) -> Vec<(String, usize, usize, f64)> {
        let (num, den) = chain(n);
        let (num1, den1) = chain(n - 1);
        let t = Instant::now();
        let res = crate::resultant::resultant(&num, &den, "Omega");
        let dnum = crate::resultant::discriminant(&num, "Omega");
        let dden1 = crate::resultant::discriminant(&den1, "Omega");
        if verbose {
            println!("n={n} inputs computed in {:.3}s", t.elapsed().as_secs_f64());
        }
        let inputs = vec![
            ("Num".to_string(), num.clone()),
            ("Den".to_string(), den.clone()),
            ("Res(Num,Den)".to_string(), res),
            ("Disc(Num)".to_string(), dnum.clone()),
            ("Disc(Den_{n-1})".to_string(), dden1.clone()),
            // Products of pieces exercise the lifting.
            ("Num*Den".to_string(), &num * &den),
            (
                "Num^2*Den*Num_{n-1}".to_string(),
                &(&num.pow(2) * &den) * &num1,
            ),
            ("Disc(Num)*Den_{n-1}".to_string(), &dnum * &den1),
        ];
        let mut inputs = inputs;
        let m = chain_matrix(n);
        for k in 1..n - 1 {
            let numk = driving_point_num(&m, k);
            let t = Instant::now();
            let res = crate::resultant::resultant(&numk, &den, "Omega");
            let disc = crate::resultant::discriminant(&numk, "Omega");
            if verbose {
                println!(
                    "n={n} inputs for k={k} computed in {:.3}s",
                    t.elapsed().as_secs_f64()
                );
            }
            inputs.push((format!("Num_{k}"), numk));
            inputs.push((format!("Res(Num_{k},Den)"), res));
            inputs.push((format!("Disc(Num_{k})"), disc));
        }
        let mut rows = Vec::new();
        for (name, f) in inputs {
            if verbose {
                println!("n={n} {name:22} terms={:6} ...", f.num_terms());
            }
            let t = Instant::now();
            let fa = factor(&f);
            let dt = t.elapsed().as_secs_f64();
            assert_eq!(fa.expand(), f, "{name}");
            if verbose {
                println!("n={n} {name:22} factors={:3} {dt:.3}s", fa.factors.len());
            }
            rows.push((name, f.num_terms(), fa.factors.len(), dt));
        }
        rows
    }

    #[test]
    #[ignore = "writes inputs and factorizations to /tmp/factor_dump for an external check"]
    fn dump_for_external_check() {
        std::fs::create_dir_all("/tmp/factor_dump").unwrap();
        let mut k = 0;
        for n in 3..=5 {
            let (num, den) = chain(n);
            let m = chain_matrix(n);
            let mut polys = vec![
                crate::resultant::discriminant(&num, "Omega"),
                &num.pow(2) * &den,
            ];
            for j in 1..n - 1 {
                let numj = driving_point_num(&m, j);
                polys.push(crate::resultant::resultant(&numj, &den, "Omega"));
                polys.push(crate::resultant::discriminant(&numj, "Omega"));
            }
            for f in polys {
                if f.num_terms() > 3000 {
                    continue;
                }
                let fa = factor(&f);
                let mut txt = format!("{f}\n");
                for (g, e) in &fa.factors {
                    txt.push_str(&format!("{e} {g}\n"));
                }
                std::fs::write(format!("/tmp/factor_dump/{k}.txt"), txt).unwrap();
                k += 1;
            }
        }
    }

    #[test]
    fn chain3_factorizations() {
        for (name, terms, k, _) in run(3, false) {
            assert!(k >= 1, "{name} with {terms} terms");
        }
    }

    #[test]
    #[ignore = "timing report; run with --ignored --nocapture"]
    fn chain_timings() {
        for n in 3..=5 {
            run(n, true);
        }
    }
}
