//! Sylvester matrices, subresultants, resultants, discriminants and
//! Sturm–Habicht sequences with respect to one variable.
//!
//! # Conventions
//!
//! Let `a`, `b` have degrees `m`, `n` in the variable `x` (coefficients are
//! polynomials in the other variables). The Sylvester matrix has the rows
//! `x^(n-1) a, ..., x a, a, x^(m-1) b, ..., x b, b`, written as coefficient
//! vectors from `x^(m+n-1)` down to `x^0`, and the resultant is its
//! determinant:
//!
//! `Res(a, b) = lc(a)^n * prod b(alpha) = (-1)^(m n) lc(b)^m * prod a(beta)`
//!
//! over the roots `alpha` of `a` and `beta` of `b`.
//!
//! For `0 <= j < min(m, n)` the (classical, determinantal) `j`-th
//! subresultant `S_j(a, b)` is the determinant of the `(m+n-2j)`-square
//! matrix built from the rows `x^(n-j-1) a, ..., a, x^(m-j-1) b, ..., b`: its
//! first `m+n-2j-1` columns (the highest powers of `x`) and, as last column,
//! the polynomials of the rows themselves. It has degree at most `j` in `x`;
//! its coefficient of `x^j` is the principal subresultant coefficient
//! `psc_j(a, b)`, and `S_0 = psc_0 = Res(a, b)`. `deg gcd(a, b)` is the least
//! `j` with `psc_j != 0` (`min(m, n)` if there is none). Swapping the
//! arguments gives `S_j(b, a) = (-1)^((m-j)(n-j)) S_j(a, b)`.
//!
//! # Algorithms
//!
//! - The chain ([`subresultant_chain`], [`subresultants`],
//!   [`sturm_habicht`]) is computed by Ducos' variant of the subresultant
//!   algorithm (pseudo-remainders, exact divisions by principal
//!   coefficients, Lazard's formula for the gaps of defective chains).
//! - [`resultant`] and [`psc`] for degrees up to 10 use the Bezout matrix
//!   instead: `det Bez(a, b) = (-1)^(m(m-1)/2) lc(a)^(m-n) Res(a, b)`, and the
//!   leading principal minors of the Bezout matrix (highest powers first)
//!   give every `psc_j`, all from one division-free expansion by minors
//!   (see [`crate::leading_principal_minors`]). With many parameters this
//!   avoids the intermediate swell of the remainder sequence (for the 5-mass
//!   chain's discriminant about 20 times faster). Higher degrees use the
//!   chain.
//!
//! The tests check both routes against the determinantal definition, the
//! Sylvester determinant and the product formula over known roots.

use crate::gcd::prem_coeffs;
use crate::poly::Poly;

/// Coefficients of `p` in `var` (lowest first), treating
/// the zero polynomial as having no coefficients.
fn coeffs(p: &Poly, var: &str) -> Vec<Poly> {
    p.coeffs_in(var)
}

fn neg_all(v: &[Poly]) -> Vec<Poly> {
    v.iter().map(|c| -c).collect()
}

fn div_all(v: &[Poly], d: &Poly) -> Vec<Poly> {
    if d.as_constant().is_some_and(|c| c.is_one()) {
        return v.to_vec();
    }
    v.iter()
        .map(|c| {
            c.div_exact(d)
                .expect("subresultant division is exact (structure theorem)")
        })
        .collect()
}

fn mul_all(v: &[Poly], f: &Poly) -> Vec<Poly> {
    if f.as_constant().is_some_and(|c| c.is_one()) {
        return v.to_vec();
    }
    v.iter().map(|c| f * c).collect()
}

/// Classical subresultants `S_0..S_{n-1}` of coefficient vectors with
/// `deg f = m >= deg g = n >= 1`, as coefficient vectors (empty = zero).
fn chain_coeffs(f: &[Poly], g: &[Poly]) -> Vec<Vec<Poly>> {
    let m = f.len() - 1;
    let n = g.len() - 1;
    debug_assert!(m >= n && n >= 1);
    let mut out: Vec<Vec<Poly>> = vec![Vec::new(); n];
    // s: principal coefficient of the subresultant similar to `a`
    // (psc_n = lc(g)^(m-n); 1 when m = n).
    let mut s = g[n].pow((m - n) as u32);
    let mut a: Vec<Poly> = g.to_vec();
    let mut b: Vec<Poly> = prem_coeffs(f, &neg_all(g));
    loop {
        if b.is_empty() {
            break;
        }
        let d = a.len() - 1;
        let e = b.len() - 1;
        out[d - 1] = b.clone();
        let delta = d - e;
        let c = if delta > 1 {
            // S_e = lc(b)^(delta-1) b / s^(delta-1)
            let num = mul_all(&b, &b[e].pow((delta - 1) as u32));
            let c = div_all(&num, &s.pow((delta - 1) as u32));
            out[e] = c.clone();
            c
        } else {
            b.clone()
        };
        if e == 0 {
            break;
        }
        let divisor = &s.pow(delta as u32) * &a[d];
        let next = div_all(&prem_coeffs(&a, &neg_all(&b)), &divisor);
        s = c[e].clone();
        a = c;
        b = next;
    }
    out
}

fn degree_of(p: &Poly, var: &str) -> usize {
    p.degree(var) as usize
}

/// The classical subresultant chain `[S_0, S_1, ..., S_{k-1}]` of `a` and
/// `b` in `var`, `k = min(deg a, deg b)` (see the module documentation for
/// the exact determinantal definition and signs). Empty when either
/// polynomial is zero or of degree 0 in `var`. Entries may be zero (always
/// below the degree of the gcd, and in the gaps of defective chains).
///
/// ```
/// use poly::{subresultant_chain, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// // Both vanish at x = 1: S_0 = Res = 0 and S_1 is a multiple of the gcd.
/// let s = subresultant_chain(&p("x^3 - x"), &p("x^2 + x*y - 1 - y"), "x");
/// assert_eq!(s.len(), 2);
/// assert!(s[0].is_zero());
/// // S_1 = prem(a, b) = y*(y + 1)*(x - 1)
/// assert_eq!(s[1].to_string(), "x*y^2 + x*y - y^2 - y");
/// ```
pub fn subresultant_chain(a: &Poly, b: &Poly, var: &str) -> Vec<Poly> {
    if a.is_zero() || b.is_zero() {
        return Vec::new();
    }
    let (m, n) = (degree_of(a, var), degree_of(b, var));
    if m == 0 || n == 0 {
        return Vec::new();
    }
    let (f, g, swapped) = if m >= n { (a, b, false) } else { (b, a, true) };
    let chain = chain_coeffs(&coeffs(f, var), &coeffs(g, var));
    chain
        .iter()
        .enumerate()
        .map(|(j, c)| {
            let s = Poly::from_coeffs_in(var, c);
            if swapped && ((m - j) * (n - j)) % 2 == 1 {
                -s
            } else {
                s
            }
        })
        .collect()
}

/// The subresultant polynomial remainder sequence of `a` and `b` in `var`:
/// `[A, B, S_{d_2 - 1}(A, B), S_{d_3 - 1}(A, B), ...]` where `(A, B)` is
/// `(a, b)` if `deg a >= deg b` and `(b, a)` otherwise, `d_i` is the degree
/// of the `i`-th element, and the sequence stops before the first zero. The
/// degrees strictly decrease after `B`; each element is a non-zero multiple
/// (by a factor free of `var`) of the corresponding Euclidean remainder, and
/// the last element is a multiple of `gcd(a, b)`. Zero inputs are dropped.
///
/// ```
/// use poly::{subresultants, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let prs = subresultants(&p("x^2 - 1"), &p("x - y"), "x");
/// assert_eq!(prs.len(), 3);
/// assert_eq!(prs[2], p("y^2 - 1")); // S_0 = Res(x^2 - 1, x - y)
/// ```
pub fn subresultants(a: &Poly, b: &Poly, var: &str) -> Vec<Poly> {
    let (f, g) = if degree_of(a, var) >= degree_of(b, var) {
        (a, b)
    } else {
        (b, a)
    };
    let mut out: Vec<Poly> = [f, g]
        .into_iter()
        .filter(|p| !p.is_zero())
        .cloned()
        .collect();
    if out.len() < 2 {
        return out;
    }
    let chain = subresultant_chain(f, g, var);
    let mut d = degree_of(g, var);
    while d >= 1 {
        let s = &chain[d - 1];
        if s.is_zero() {
            break;
        }
        out.push(s.clone());
        d = degree_of(s, var);
    }
    out
}

/// Principal subresultant coefficients `[psc_0, ..., psc_{k-1}]`,
/// `k = min(deg a, deg b)`: `psc_j` is the coefficient of `var^j` in `S_j(a, b)`
/// (zero when `S_j` is defective or zero). `psc_0 = Res(a, b)`.
///
/// ```
/// use poly::{psc, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// // a and b share the factor x - 1 (degree 1): psc_0 = 0, psc_1 != 0.
/// let c = psc(&p("(x - 1)*(x + 2)"), &p("(x - 1)*(x - 3)"), "x");
/// assert!(c[0].is_zero() && !c[1].is_zero());
/// ```
pub fn psc(a: &Poly, b: &Poly, var: &str) -> Vec<Poly> {
    if a.is_zero() || b.is_zero() {
        return Vec::new();
    }
    let (m, n) = (degree_of(a, var), degree_of(b, var));
    if m == 0 || n == 0 {
        return Vec::new();
    }
    if m.max(n) <= BEZOUT_MAX {
        if m >= n {
            return psc_bezout(a, b, var);
        }
        return psc_bezout(b, a, var)
            .into_iter()
            .enumerate()
            .map(|(j, c)| if ((m - j) * (n - j)) % 2 == 1 { -c } else { c })
            .collect();
    }
    subresultant_chain(a, b, var)
        .iter()
        .enumerate()
        .map(|(j, s)| {
            s.coeffs_in(var)
                .into_iter()
                .nth(j)
                .unwrap_or_else(Poly::zero)
        })
        .collect()
}

/// The resultant `Res(a, b)` with respect to `var`:
/// `lc(a)^deg(b) * prod b(alpha)` over the roots `alpha` of `a`, i.e. the
/// determinant of [`sylvester_matrix`].
///
/// Conventions: `Res(a, b) = 0` if `a` or `b` is zero; if `deg a = 0` (a
/// non-zero constant in `var`) `Res(a, b) = a^deg(b)`, and if `deg b = 0`
/// `Res(a, b) = b^deg(a)` (so the resultant of two non-zero constants is 1);
/// `Res(b, a) = (-1)^(deg a * deg b) Res(a, b)`.
///
/// ```
/// use poly::{resultant, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let num = p("m2*Omega - c12");
/// let den = p("m1*m2*Omega^2 - c12*(m1 + m2)*Omega");
/// // m2^2 * den(c12/m2) = m2^2 * (-c12^2)
/// assert_eq!(resultant(&num, &den, "Omega"), p("-c12^2*m2^2"));
/// assert_eq!(resultant(&p("x - r"), &p("x - s"), "x"), p("r - s"));
/// ```
pub fn resultant(a: &Poly, b: &Poly, var: &str) -> Poly {
    if a.is_zero() || b.is_zero() {
        return Poly::zero();
    }
    let (m, n) = (a.degree(var), b.degree(var));
    if m == 0 {
        return a.pow(n);
    }
    if n == 0 {
        return b.pow(m);
    }
    // Over the primitive integer parts, so the determinant's arithmetic
    // needs no gcd per addition: Res(ca A, cb B) = ca^n cb^m Res(A, B).
    let ((ca, pa), (cb, pb)) = (a.primitive(), b.primitive());
    let r = resultant_integer(&pa, &pb, var, m, n);
    if ca.is_one() && cb.is_one() {
        r
    } else {
        r.scale(&(ca.pow(n as i32) * cb.pow(m as i32)))
    }
}

/// [`resultant`] of `a` and `b` of degrees `m, n >= 1` in `var`.
fn resultant_integer(a: &Poly, b: &Poly, var: &str, m: u32, n: u32) -> Poly {
    if m.max(n) as usize <= BEZOUT_MAX {
        if m >= n {
            return resultant_bezout(a, b, var);
        }
        let r = resultant_bezout(b, a, var);
        return if (m * n) % 2 == 1 { -r } else { r };
    }
    subresultant_chain(a, b, var)
        .into_iter()
        .next()
        .expect("non-empty chain")
}

/// The discriminant of `p` in `var`:
/// `(-1)^(n(n-1)/2) Res(p, p') / lc(p)` with `n = deg p`, which equals
/// `lc(p)^(2n-2) prod_{i<j} (alpha_i - alpha_j)^2` over the roots of `p`.
///
/// Conventions: 0 for the zero polynomial, 1 when `deg p` is 0 or 1.
///
/// ```
/// use poly::{discriminant, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// assert_eq!(discriminant(&p("a*x^2 + b*x + c"), "x"), p("b^2 - 4*a*c"));
/// assert_eq!(discriminant(&p("x^3 + p*x + q"), "x"), p("-4*p^3 - 27*q^2"));
/// ```
pub fn discriminant(p: &Poly, var: &str) -> Poly {
    if p.is_zero() {
        return Poly::zero();
    }
    let n = p.degree(var);
    if n <= 1 {
        return Poly::one();
    }
    // Over the primitive integer part: disc(c P) = c^(2n-2) disc(P).
    let (c, pp) = p.primitive();
    if !c.is_one() {
        return discriminant(&pp, var).scale(&c.pow(2 * n as i32 - 2));
    }
    if n as usize <= BEZOUT_MAX {
        return discriminant_bezout(p, var);
    }
    let r = resultant(p, &p.derivative(var), var);
    let q = r
        .div_exact(&p.lead_in(var))
        .expect("lc(p) divides Res(p, p')");
    if (n * (n - 1) / 2) % 2 == 1 {
        -q
    } else {
        q
    }
}

/// The Sylvester matrix of `a` and `b` in `var` (size `m + n`), rows
/// `x^(n-1) a, ..., a, x^(m-1) b, ..., b` as coefficient vectors from the
/// highest power down. Its determinant is [`resultant`] (the zero polynomial
/// is treated as having degree 0, so the only mismatch is `Res(0, c) = 0`
/// for a constant `c`, where the matrix is empty).
///
/// ```
/// use poly::{det, sylvester_matrix, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let s = sylvester_matrix(&p("a*x^2 + b*x + c"), &p("2*a*x + b"), "x");
/// assert_eq!(s.len(), 3);
/// assert_eq!(s[2], vec![Poly::zero(), p("2*a"), p("b")]);
/// assert_eq!(det(&s), p("-a*(b^2 - 4*a*c)"));
/// ```
pub fn sylvester_matrix(a: &Poly, b: &Poly, var: &str) -> Vec<Vec<Poly>> {
    let (m, n) = (degree_of(a, var), degree_of(b, var));
    let size = m + n;
    let row = |p: &Poly, deg: usize, shift: usize| -> Vec<Poly> {
        let mut c = coeffs(p, var);
        c.resize(deg + 1, Poly::zero());
        let mut r = vec![Poly::zero(); size];
        for (k, ck) in c.into_iter().enumerate() {
            // coefficient of x^k times x^shift lands in column size-1-(k+shift)
            r[size - 1 - (k + shift)] = ck;
        }
        r
    };
    let mut out = Vec::with_capacity(size);
    for i in (0..n).rev() {
        out.push(row(a, m, i));
    }
    for i in (0..m).rev() {
        out.push(row(b, n, i));
    }
    out
}

/// The Bezout matrix of `a` and `b` in `var` (`deg a = m >= deg b`, `m >= 1`):
/// the `m x m` symmetric matrix `B` with
/// `(a(x) b(y) - a(y) b(x)) / (x - y) = sum B[i][j] x^i y^j`.
/// Its determinant is `(-1)^(m(m-1)/2) lc(a)^(m - deg b) Res(a, b)`.
/// Empty if `a` is zero or constant in `var`.
///
/// ```
/// use poly::{bezout_matrix, det, resultant, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let (a, b) = (p("x^2 + u*x + v"), p("x - w"));
/// let bz = bezout_matrix(&a, &b, "x");
/// // m = 2: det = -lc(a)^1 * Res(a, b)
/// assert_eq!(det(&bz), -resultant(&a, &b, "x"));
/// ```
pub fn bezout_matrix(a: &Poly, b: &Poly, var: &str) -> Vec<Vec<Poly>> {
    let m = if a.is_zero() { 0 } else { degree_of(a, var) };
    let mut bz = vec![vec![Poly::zero(); m]; m];
    if m == 0 {
        return bz;
    }
    let ca = coeffs(a, var);
    let mut cb = coeffs(b, var);
    cb.resize(m + 1, Poly::zero());
    for p in 1..=m {
        for q in 0..p {
            let c = Poly::sum_of_products(&[(&ca[p], &cb[q], false), (&ca[q], &cb[p], true)]);
            if c.is_zero() {
                continue;
            }
            for r in 0..p - q {
                let (i, j) = (q + r, p - 1 - r);
                bz[i][j] = &bz[i][j] + &c;
            }
        }
    }
    bz
}

/// Largest degree for which resultants and principal subresultant
/// coefficients are computed from the Bezout matrix (expansion by minors,
/// `O(m 2^m)` products) rather than by the subresultant algorithm.
const BEZOUT_MAX: usize = 10;

/// `[psc_0, ..., psc_{n-1}]` for `deg a = m >= deg b = n >= 1`, from the
/// leading principal minors `D_k` of the Bezout matrix with rows and columns
/// reversed (highest powers first):
/// `D_k = (-1)^(k(k-1)/2) lc(a)^(m-n) psc_{m-k}(a, b)` for `m-n < k <= m`
/// (Bezoutian/subresultant relation; the case `k = m` is the determinant).
fn psc_bezout(a: &Poly, b: &Poly, var: &str) -> Vec<Poly> {
    let m = degree_of(a, var);
    let n = degree_of(b, var);
    let bz = bezout_matrix(a, b, var);
    let rev: Vec<Vec<Poly>> = (0..m)
        .map(|i| (0..m).map(|j| bz[m - 1 - i][m - 1 - j].clone()).collect())
        .collect();
    let minors = crate::matrix::leading_principal_minors(&rev).expect("square, small");
    let lc_pow = a.lead_in(var).pow((m - n) as u32);
    let mut out = vec![Poly::zero(); n];
    for k in m - n + 1..=m {
        let d = &minors[k - 1];
        let d = if m > n {
            d.div_exact(&lc_pow)
                .expect("lc(a)^(m-n) divides the Bezout minors")
        } else {
            d.clone()
        };
        out[m - k] = if (k * (k - 1) / 2) % 2 == 1 { -d } else { d };
    }
    out
}

/// The discriminant of `p` (degree `m >= 2` in `var`) from the Bezout
/// matrix of `p` and `p'`. Its last column (and, by symmetry, last row) is
/// `lc(p)` times the coefficients of `p'`: the entries come from
/// `a_m b_q - a_q b_m` with `b_m = 0`. Dividing that row and column by
/// `lc(p)` (small entries) leaves a matrix whose determinant is
/// `det Bez(p, p') / lc(p)^2 = (-1)^(m(m-1)/2) Res(p, p') / lc(p)`, the
/// discriminant, without dividing the large determinant.
fn discriminant_bezout(p: &Poly, var: &str) -> Poly {
    let m = degree_of(p, var);
    let lc = p.lead_in(var);
    let mut bz = bezout_matrix(p, &p.derivative(var), var);
    let last = m - 1;
    for row in bz.iter_mut() {
        if !row[last].is_zero() {
            row[last] = row[last]
                .div_exact(&lc)
                .expect("lc(p) divides the last column");
        }
    }
    for e in bz[last].iter_mut() {
        if !e.is_zero() {
            *e = e.div_exact(&lc).expect("lc(p) divides the last row");
        }
    }
    crate::matrix::det_minors(&bz).expect("square, small")
}

/// `Res(a, b)` for `deg a = m >= deg b = n >= 1` from the Bezout determinant.
fn resultant_bezout(a: &Poly, b: &Poly, var: &str) -> Poly {
    let m = degree_of(a, var);
    let n = degree_of(b, var);
    let d = crate::matrix::det_minors(&bezout_matrix(a, b, var)).expect("square, small");
    let d = if m > n {
        d.div_exact(&a.lead_in(var).pow((m - n) as u32))
            .expect("lc(a)^(m-n) divides the Bezout determinant")
    } else {
        d
    };
    if (m * (m - 1) / 2) % 2 == 1 {
        -d
    } else {
        d
    }
}

/// The Sturm–Habicht sequence `[StHa_0(p), ..., StHa_n(p)]` of `p` in `var`,
/// `n = deg p >= 1` (indexed by `j`): `StHa_n = p`, `StHa_{n-1} = p'` and,
/// for `j <= n - 2`, the signed subresultant
/// `StHa_j = (-1)^((n-j)(n-j-1)/2) S_j(p, p')`.
/// Empty for zero or constant `p`. `StHa_0 = lc(p) * discriminant(p)`.
///
/// ```
/// use poly::{sturm_habicht, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let s = sturm_habicht(&p("x^2 - 1"), "x");
/// assert_eq!(s, vec![p("4"), p("2*x"), p("x^2 - 1")]);
/// ```
pub fn sturm_habicht(p: &Poly, var: &str) -> Vec<Poly> {
    if p.is_zero() {
        return Vec::new();
    }
    let n = degree_of(p, var);
    if n == 0 {
        return Vec::new();
    }
    let dp = p.derivative(var);
    let mut out: Vec<Poly> = subresultant_chain(p, &dp, var)
        .into_iter()
        .enumerate()
        .map(|(j, s)| {
            let k = n - j;
            if (k * (k - 1) / 2) % 2 == 1 {
                -s
            } else {
                s
            }
        })
        .collect();
    out.push(dp);
    out.push(p.clone());
    out
}

/// The principal Sturm–Habicht coefficients `[sthac_0, ..., sthac_n]`:
/// `sthac_j` is the coefficient of `var^j` in `StHa_j` (see
/// [`sturm_habicht`]); `sthac_n = lc(p)`, `sthac_{n-1} = n lc(p)`. For a
/// univariate `p` whose coefficients are all non-zero, the number of
/// distinct real roots is the number of sign permanences minus the number
/// of sign variations in this sequence.
///
/// ```
/// use poly::{sturm_habicht_principal, Poly};
/// let c = sturm_habicht_principal(&"x^2 + 1".parse::<Poly>().unwrap(), "x");
/// assert_eq!(c, vec![Poly::int(-4), Poly::int(2), Poly::int(1)]);
/// ```
pub fn sturm_habicht_principal(p: &Poly, var: &str) -> Vec<Poly> {
    if p.is_zero() {
        return Vec::new();
    }
    let n = degree_of(p, var);
    if n == 0 {
        return Vec::new();
    }
    let dp = p.derivative(var);
    let lc = p.lead_in(var);
    let mut out: Vec<Poly> = psc(p, &dp, var)
        .into_iter()
        .enumerate()
        .map(|(j, c)| {
            let k = n - j;
            if (k * (k - 1) / 2) % 2 == 1 {
                -c
            } else {
                c
            }
        })
        .collect();
    out.push(&lc * &Poly::int(n as i64));
    out.push(lc);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matrix::{det, det_laplace};

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    /// S_j by its determinantal definition (independent of the PRS).
    fn subresultant_by_det(a: &Poly, b: &Poly, x: &str, j: usize) -> Poly {
        let (m, n) = (a.degree(x) as usize, b.degree(x) as usize);
        let width = m + n - j;
        let size = m + n - 2 * j;
        let mut rows: Vec<(Vec<Poly>, Poly)> = Vec::new();
        let row = |q: &Poly, shift: usize| -> (Vec<Poly>, Poly) {
            let c = q.coeffs_in(x);
            let mut r = vec![Poly::zero(); width];
            for (k, ck) in c.into_iter().enumerate() {
                r[width - 1 - (k + shift)] = ck;
            }
            (r, q.mul_var_pow(x, shift as u32))
        };
        for i in (0..n - j).rev() {
            rows.push(row(a, i));
        }
        for i in (0..m - j).rev() {
            rows.push(row(b, i));
        }
        let mat: Vec<Vec<Poly>> = rows
            .into_iter()
            .map(|(r, poly)| {
                let mut v: Vec<Poly> = r[..size - 1].to_vec();
                v.push(poly);
                v
            })
            .collect();
        det(&mat)
    }

    fn check_chain(a: &Poly, b: &Poly, x: &str) {
        let chain = subresultant_chain(a, b, x);
        let k = (a.degree(x).min(b.degree(x))) as usize;
        assert_eq!(chain.len(), k);
        for (j, s) in chain.iter().enumerate() {
            assert_eq!(*s, subresultant_by_det(a, b, x, j), "S_{j}({a}, {b})");
        }
        if k > 0 {
            let syl = sylvester_matrix(a, b, x);
            assert_eq!(resultant(a, b, x), det(&syl));
            let chain_psc: Vec<Poly> = chain
                .iter()
                .enumerate()
                .map(|(j, s)| s.coeffs_in(x).into_iter().nth(j).unwrap_or_default())
                .collect();
            assert_eq!(psc(a, b, x), chain_psc, "psc({a}, {b})");
            if a.degree(x) >= b.degree(x) {
                assert_eq!(psc_bezout(a, b, x), chain_psc, "Bezout psc({a}, {b})");
                assert_eq!(resultant_bezout(a, b, x), chain[0]);
            }
        }
    }

    #[test]
    fn chain_matches_determinants() {
        let cases = [
            ("x^3 - x", "x^2 + x*y - 1 - y"),
            ("x^4 + a*x^3 - 2*x + 5", "3*x^2 + b*x - 1"),
            ("x^4 + a*x^3 - 2*x + 5", "3*x^3 + b*x - 1"),
            ("a*x^3 + b*x^2 + c*x + d", "e*x^3 + f*x + g"),
            // defective chains (degree gaps)
            ("x^5 + x^4 + 1", "x^4 + 1"),
            ("x^6 + y*x^3 + 1", "x^4 + y"),
            ("(x^2 + y)^2*(x - 1)", "(x^2 + y)*(x + 2)"),
            ("(x - 1)^3*(x + y)", "(x - 1)^2*(x*y + 2)"),
            (
                "x^8 + x^6 - 3*x^4 - 3*x^3 + 8*x^2 + 2*x - 5",
                "3*x^6 + 5*x^4 - 4*x^2 - 9*x + 21",
            ),
            ("x^2 - 1", "x - y"),
            ("2*x + 1", "3*x - 5"),
            ("y*x^3 + x^2 - z", "(y + 1)*x^3 + z*x - 2"),
            ("x^7 + y*x^2 + 1", "x^2 + z"),
            ("x^7 + y*x^2 + 1", "2*x^6 + x^3*z - 1"),
            ("(x^3 + y)*(x^2 - z)*(x + 1)", "(x^3 + y)*(x - 2)"),
            ("x^6 - 1", "x^4 + x^2 + 1"),
            ("x^5", "x^3"),
            ("y*x^4 + 3*x^2 + z*x - 2", "4*y*x^3 + 6*x + z"),
        ];
        for (a, b) in cases {
            let (a, b) = (p(a), p(b));
            check_chain(&a, &b, "x");
            check_chain(&b, &a, "x");
        }
    }

    #[test]
    fn resultant_product_formula() {
        // Res = lc(a)^n prod b(alpha): a = 2(x-1)(x-2)(x+3), b = x^2 - y.
        let a = p("2*(x - 1)*(x - 2)*(x + 3)");
        let b = p("x^2 - y");
        let want = &(&(&p("4") * &p("1 - y")) * &p("4 - y")) * &p("9 - y"); // lc(a)^2 = 4
        assert_eq!(resultant(&a, &b, "x"), want);
        // Res(b, a) = (-1)^(3*2) Res(a, b)
        assert_eq!(resultant(&b, &a, "x"), want);
        // Odd product of degrees flips the sign.
        let c = p("x - t");
        assert_eq!(resultant(&c, &a, "x"), a.subs_poly("x", &p("t")));
        assert_eq!(resultant(&a, &c, "x"), -a.subs_poly("x", &p("t")));
    }

    #[test]
    fn degenerate_conventions() {
        let b = p("x^2 + 1");
        assert_eq!(resultant(&Poly::zero(), &b, "x"), Poly::zero());
        assert_eq!(resultant(&b, &Poly::zero(), "x"), Poly::zero());
        assert_eq!(resultant(&p("3*y"), &b, "x"), p("9*y^2"));
        assert_eq!(resultant(&b, &p("3*y"), "x"), p("9*y^2"));
        assert_eq!(resultant(&p("2"), &p("5"), "x"), Poly::one());
        assert_eq!(discriminant(&Poly::zero(), "x"), Poly::zero());
        assert_eq!(discriminant(&p("7"), "x"), Poly::one());
        assert_eq!(discriminant(&p("a*x + b"), "x"), Poly::one());
        assert!(subresultant_chain(&Poly::zero(), &b, "x").is_empty());
        assert_eq!(subresultants(&b, &Poly::zero(), "x"), vec![b.clone()]);
        // Variable absent from both.
        assert_eq!(resultant(&p("y"), &p("z"), "x"), Poly::one());
    }

    #[test]
    fn discriminant_by_roots() {
        // disc = lc^(2n-2) prod_{i<j} (r_i - r_j)^2 for p = 3(x-1)(x-2)(x-4):
        // 3^4 * (1*9*4) = 2916.
        assert_eq!(
            discriminant(&p("3*(x - 1)*(x - 2)*(x - 4)"), "x"),
            p("2916")
        );
        // Quartic x^4 + a: disc = 256 a^3.
        assert_eq!(discriminant(&p("x^4 + a"), "x"), p("256*a^3"));
        // Double root -> zero discriminant.
        assert!(discriminant(&p("(x - y)^2*(x + 1)"), "x").is_zero());
    }

    #[test]
    fn sylvester_det_algorithms_agree() {
        let a = p("a*x^3 + b*x + c");
        let b = p("d*x^2 + e");
        let s = sylvester_matrix(&a, &b, "x");
        assert_eq!(det(&s), det_laplace(&s).unwrap());
        assert_eq!(resultant(&a, &b, "x"), det_laplace(&s).unwrap());
    }

    #[test]
    fn prs_structure() {
        let a = p("x^8 + x^6 - 3*x^4 - 3*x^3 + 8*x^2 + 2*x - 5");
        let b = p("3*x^6 + 5*x^4 - 4*x^2 - 9*x + 21");
        let prs = subresultants(&a, &b, "x");
        let degs: Vec<u32> = prs.iter().map(|q| q.degree("x")).collect();
        assert_eq!(degs, vec![8, 6, 4, 2, 1, 0]);
        // Knuth / Brown's classic subresultant PRS values.
        assert_eq!(prs[2], p("15*x^4 - 3*x^2 + 9"));
        assert_eq!(prs[3], p("65*x^2 + 125*x - 245"));
        assert_eq!(prs[4], p("9326*x - 12300"));
        assert_eq!(prs[5], p("260708"));
    }

    #[test]
    fn sturm_habicht_counts_real_roots() {
        // Generalized permanences minus variations (Basu-Pollack-Roy): over
        // consecutive non-zero entries at distance k, add
        // (-1)^(k(k-1)/2) * sign(product) when k is odd, 0 when k is even.
        fn count(c: &[Poly]) -> i32 {
            let nz: Vec<(usize, i32)> = c
                .iter()
                .enumerate()
                .rev()
                .map(|(j, q)| (j, q.as_constant().unwrap().signum()))
                .filter(|&(_, s)| s != 0)
                .collect();
            nz.windows(2)
                .map(|w| {
                    let k = w[0].0 - w[1].0;
                    if k % 2 == 0 {
                        0
                    } else {
                        let eps = if (k * (k - 1) / 2) % 2 == 0 { 1 } else { -1 };
                        eps * w[0].1 * w[1].1
                    }
                })
                .sum()
        }
        for (poly, roots) in [
            ("(x - 1)*(x - 2)*(x + 5)", 3),
            ("(x^2 + 1)*(x - 3)", 1),
            ("x^4 + 1", 0), // defective: sthac_2 = sthac_1 = 0
            ("x^5 - 1", 1),
            ("(x - 1)^2*(x + 1)", 2),
            ("(x^2 - 2)*(x^2 - 3)", 4),
        ] {
            let c = sturm_habicht_principal(&p(poly), "x");
            assert_eq!(count(&c), roots, "{poly}");
        }
        let f = p("a*x^3 + b*x + c");
        let st = sturm_habicht(&f, "x");
        let from_chain: Vec<Poly> = st
            .iter()
            .enumerate()
            .map(|(j, s)| s.coeffs_in("x").into_iter().nth(j).unwrap_or_default())
            .collect();
        assert_eq!(sturm_habicht_principal(&f, "x"), from_chain);
        assert_eq!(st[0], &p("a") * &discriminant(&f, "x"));
    }

    #[test]
    fn paper_num_b2_discriminant() {
        let num_b2 = p("m2*m3*Omega^2 - c23*(m1 + m2 + m3)*Omega + c1*c23");
        let d = discriminant(&num_b2, "Omega");
        // By the quadratic formula: B^2 - 4AC.
        let want = p("c23*(c23*(m1 + m2 + m3)^2 - 4*m2*m3*c1)");
        assert_eq!(d, want);
    }

    #[test]
    fn paper_pzc_condition() {
        let den_a = p(
            "m1*m2*m3*Omega^2 - (c12*(m1*m3 + m2*m3) + c23*m1*(m2 + m3))*Omega \
                       + c12*c23*(m1 + m2 + m3)",
        );
        let num_a2 = p("-m3*c12*Omega + c12*c23");
        let r = resultant(&num_a2, &den_a, "Omega");
        // Independent route: Res = lc(num)^2 * Den_A(c23/m3)
        //   = c12^2 * (a2*c23^2 + a1*c23*m3 + a0*m3^2)  (a_i: coefficients of Den_A).
        let a = den_a.coeffs_in("Omega");
        let by_root = &p("c12^2")
            * &(&(&(&a[2] * &p("c23^2")) + &(&a[1] * &p("c23*m3"))) + &(&a[0] * &p("m3^2")));
        assert_eq!(r, by_root);
        // Expanding by hand: c12^2*c23*m3^2*(c12*m3 - c23*m1), the PZC factor of eq. (32).
        assert_eq!(r, p("c12^2*c23*m3^2*(c12*m3 - c23*m1)"));
        assert!(r.div_exact(&p("c12*m3 - c23*m1")).is_some());
    }

    #[test]
    #[ignore]
    fn timing_chain5() {
        use std::time::Instant;
        let n = 5;
        let a = crate::matrix::tests::chain(n);
        let t = Instant::now();
        let d = det(&a);
        let t_det = t.elapsed();
        let den = d.div_exact(&p("Omega")).unwrap();
        let num = crate::matrix::cofactor(&a, 0, 0);
        let t = Instant::now();
        let r = resultant(&num, &den, "Omega");
        let t_res = t.elapsed();
        let t = Instant::now();
        let disc = discriminant(&den, "Omega");
        let t_disc = t.elapsed();
        let t = Instant::now();
        let rb = resultant_bezout(&den, &den.derivative("Omega"), "Omega");
        eprintln!("bezout res(den, den') {:?}", t.elapsed());
        let t = Instant::now();
        let rc = subresultant_chain(&den, &den.derivative("Omega"), "Omega");
        eprintln!("chain res(den, den') {:?}", t.elapsed());
        assert_eq!(rb, rc[0]);
        let t = Instant::now();
        let (_, sf) = crate::sqfree::square_free(&disc);
        eprintln!(
            "square_free(disc) {:?}: {:?}",
            t.elapsed(),
            sf.iter()
                .map(|(f, k)| (f.num_terms(), *k))
                .collect::<Vec<_>>()
        );
        let t = Instant::now();
        let g = crate::gcd::gcd(&disc, &disc.derivative("m1"));
        eprintln!(
            "gcd(disc, d disc/dm1) {:?}: {} terms",
            t.elapsed(),
            g.num_terms()
        );
        let t = Instant::now();
        let (x, y) = (&disc * &den, &disc * &num);
        eprintln!(
            "products {:?}: {} and {} terms",
            t.elapsed(),
            x.num_terms(),
            y.num_terms()
        );
        let t = Instant::now();
        let g = crate::gcd::gcd(&x, &y);
        eprintln!(
            "gcd(disc*den, disc*num) {:?}: {} terms",
            t.elapsed(),
            g.num_terms()
        );
        assert_eq!(g, disc.primitive_part());
        eprintln!(
            "5x5 chain: det {:?} ({} terms), Res(num, den) {:?} ({} terms), disc {:?} ({} terms)",
            t_det,
            d.num_terms(),
            t_res,
            r.num_terms(),
            t_disc,
            disc.num_terms()
        );
    }
}
