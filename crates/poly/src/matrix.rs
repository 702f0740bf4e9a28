//! Determinants, cofactors and adjugates of square matrices of [`Poly`],
//! and the rank of matrices over `Q` ([`rank`]).
//!
//! A matrix is a slice of rows, `m[i][j]` being row `i`, column `j`. Three
//! determinant algorithms are provided and agree exactly:
//!
//! - [`det_bareiss`]: fraction-free Gaussian elimination (Bareiss) with
//!   exact polynomial division, pivoting on the non-zero candidate with
//!   fewest terms; `O(n^3)` operations, but the intermediate entries are
//!   products of minors, which is costly with many variables;
//! - [`det_minors`]: expansion by minors along the rows, sharing each minor
//!   between all the terms that need it (dynamic programming over column
//!   sets, `O(n 2^n)` products in the worst case, fewer for sparse
//!   matrices), division-free; every intermediate is a genuine minor, so
//!   there is no expression swell;
//! - [`det`]: [`det_minors`] up to size [`MINORS_AUTO_MAX`], Bareiss above.
//!   (Measured: generic 6x6 matrices, one own variable per entry plus shared ones,
//!   0.1 s by minors against about a minute by Bareiss; a 10-mass chain
//!   `C - Omega M`, 14 ms against 16 ms.)
//! - [`det_laplace`]: plain recursive Laplace expansion along the first row,
//!   `O(n!)`, an independent reference for tests;
//! - [`det_univariate`]: Bareiss over `Z[x]` for matrices of [`UPoly`].
//!
//! The functions without a `try_` prefix panic on a non-square matrix (a
//! programming error in `mms`); the `try_` variants return
//! [`MatrixError`] instead.

use crate::poly::Poly;
use crate::rat::Rat;
use crate::upoly::UPoly;
use std::collections::BTreeMap;

/// Error for malformed matrix arguments.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MatrixError {
    /// A row does not have as many entries as there are rows.
    #[error("matrix is not square: row {row} has {len} entries, expected {expected}")]
    NotSquare {
        /// Index of the offending row.
        row: usize,
        /// Its number of entries.
        len: usize,
        /// The number of rows.
        expected: usize,
    },
    /// A row or column index is outside the matrix.
    #[error("index ({i}, {j}) is outside a {n}x{n} matrix")]
    IndexOutOfRange {
        /// Row index.
        i: usize,
        /// Column index.
        j: usize,
        /// Matrix size.
        n: usize,
    },
    /// The matrix is too large for the exponential-time reference algorithm.
    #[error("matrix of size {n} is too large for this algorithm (at most {max})")]
    TooLarge {
        /// Matrix size.
        n: usize,
        /// Largest supported size.
        max: usize,
    },
}

/// Checks that `m` is square and returns its size.
///
/// ```
/// use poly::{check_square, MatrixError, Poly};
/// let ok = vec![vec![Poly::int(1), Poly::int(2)], vec![Poly::int(3), Poly::int(4)]];
/// assert_eq!(check_square(&ok), Ok(2));
/// let bad = vec![vec![Poly::int(1), Poly::int(2)], vec![Poly::int(3)]];
/// assert!(matches!(check_square(&bad), Err(MatrixError::NotSquare { row: 1, .. })));
/// ```
pub fn check_square<T>(m: &[Vec<T>]) -> Result<usize, MatrixError> {
    let n = m.len();
    for (row, r) in m.iter().enumerate() {
        if r.len() != n {
            return Err(MatrixError::NotSquare {
                row,
                len: r.len(),
                expected: n,
            });
        }
    }
    Ok(n)
}

/// Determinant of a square polynomial matrix (1 for the empty matrix).
///
/// Panics if `m` is not square; see [`try_det`] for a checked version.
///
/// ```
/// use poly::{det, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// // C - Omega*M for two masses joined by one spring.
/// let m = vec![
///     vec![p("c12 - Omega*m1"), p("-c12")],
///     vec![p("-c12"), p("c12 - Omega*m2")],
/// ];
/// assert_eq!(det(&m), p("m1*m2*Omega^2 - c12*(m1 + m2)*Omega"));
/// ```
pub fn det(m: &[Vec<Poly>]) -> Poly {
    try_det(m).unwrap_or_else(|e| panic!("det: {e}"))
}

/// Determinant, or an error if `m` is not square.
///
/// ```
/// use poly::{try_det, Poly};
/// assert!(try_det(&[vec![Poly::int(1), Poly::int(2)]]).is_err());
/// assert_eq!(try_det(&[]).unwrap(), Poly::one());
/// ```
pub fn try_det(m: &[Vec<Poly>]) -> Result<Poly, MatrixError> {
    let n = check_square(m)?;
    if n <= MINORS_AUTO_MAX {
        return Ok(minors_unchecked(m, n));
    }
    Ok(bareiss_unchecked(m.to_vec(), n))
}

/// Determinant by fraction-free elimination (Bareiss), whatever the
/// sparsity. Errors if `m` is not square.
///
/// ```
/// use poly::{det_bareiss, det_laplace, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let m = vec![
///     vec![p("a"), p("b"), p("c")],
///     vec![p("d"), p("e"), p("f")],
///     vec![p("g"), p("h"), p("i")],
/// ];
/// assert_eq!(det_bareiss(&m).unwrap(), det_laplace(&m).unwrap());
/// ```
pub fn det_bareiss(m: &[Vec<Poly>]) -> Result<Poly, MatrixError> {
    let n = check_square(m)?;
    Ok(bareiss_unchecked(m.to_vec(), n))
}

fn bareiss_unchecked(mut a: Vec<Vec<Poly>>, n: usize) -> Poly {
    if n == 0 {
        return Poly::one();
    }
    let mut negate = false;
    let mut prev = Poly::one();
    for k in 0..n {
        // Pivot: the non-zero candidate with fewest terms (first on ties).
        let Some(piv) = (k..n)
            .filter(|&r| !a[r][k].is_zero())
            .min_by_key(|&r| (a[r][k].num_terms(), r))
        else {
            return Poly::zero();
        };
        if piv != k {
            a.swap(piv, k);
            negate = !negate;
        }
        if k + 1 == n {
            break;
        }
        let (top, rest) = a.split_at_mut(k + 1);
        let pivot_row = &top[k];
        let pkk = &pivot_row[k];
        for row in rest.iter_mut() {
            let aik = std::mem::take(&mut row[k]);
            for j in k + 1..n {
                let aij = std::mem::take(&mut row[j]);
                let akj = &pivot_row[j];
                let num = if aik.is_zero() || akj.is_zero() {
                    pkk * &aij
                } else if aij.is_zero() {
                    -(&aik * akj)
                } else {
                    &(pkk * &aij) - &(&aik * akj)
                };
                row[j] = if num.is_zero() {
                    num
                } else {
                    num.div_exact(&prev)
                        .expect("Bareiss division is exact (Sylvester identity)")
                };
            }
        }
        prev = a[k][k].clone();
    }
    let d = a[n - 1][n - 1].clone();
    if negate {
        -d
    } else {
        d
    }
}

/// Determinant of a square matrix of univariate integer polynomials
/// ([`UPoly`], `Z[x]`), by Bareiss' fraction-free elimination with exact
/// division in `Z[x]`. No rational number is formed, so the entries stay
/// within the Hadamard bound of the minors; for small matrices whose
/// entries are polynomials in one variable this is many times faster than
/// [`det`] on the same entries as [`Poly`] with rational coefficients.
/// Errors if `m` is not square.
///
/// ```
/// use poly::{det_laplace, det_univariate, Poly, UPoly};
/// // [[x, 2], [3, x + 1]]: x^2 + x - 6 = (x - 2)(x + 3).
/// let m = vec![
///     vec![UPoly::from_i64s(&[0, 1]), UPoly::from_i64s(&[2])],
///     vec![UPoly::from_i64s(&[3]), UPoly::from_i64s(&[1, 1])],
/// ];
/// let d = det_univariate(&m).unwrap();
/// assert_eq!(d, UPoly::from_i64s(&[-6, 1, 1]));
/// // The same as the general determinant of the same matrix.
/// let as_poly: Vec<Vec<Poly>> =
///     m.iter().map(|r| r.iter().map(|u| u.to_poly("x")).collect()).collect();
/// assert_eq!(d.to_poly("x"), det_laplace(&as_poly).unwrap());
/// ```
pub fn det_univariate(m: &[Vec<UPoly>]) -> Result<UPoly, MatrixError> {
    let n = check_square(m)?;
    if n == 0 {
        return Ok(UPoly::one());
    }
    let mut a = m.to_vec();
    let mut negate = false;
    let mut prev = UPoly::one();
    for k in 0..n {
        // Pivot: the non-zero candidate of lowest degree (first on ties).
        let Some(piv) = (k..n)
            .filter(|&r| !a[r][k].is_zero())
            .min_by_key(|&r| (a[r][k].degree(), r))
        else {
            return Ok(UPoly::zero());
        };
        if piv != k {
            a.swap(piv, k);
            negate = !negate;
        }
        let (top, rest) = a.split_at_mut(k + 1);
        let pivot_row = &top[k];
        for row in rest.iter_mut() {
            let aik = std::mem::take(&mut row[k]);
            for j in k + 1..n {
                let num = &(&pivot_row[k] * &row[j]) - &(&aik * &pivot_row[j]);
                row[j] = num
                    .div_exact(&prev)
                    .expect("Bareiss division is exact (Sylvester identity)");
            }
        }
        prev = a[k][k].clone();
    }
    let d = a[n - 1][n - 1].clone();
    Ok(if negate { -d } else { d })
}

/// Largest size for which [`det`] uses [`det_minors`] (larger matrices use
/// [`det_bareiss`]).
pub const MINORS_AUTO_MAX: usize = 16;

/// Largest size accepted by [`det_minors`].
pub const MINORS_MAX: usize = 24;

/// Determinant by expansion by minors along the rows, each minor computed
/// once (division-free; cost grows with the number of non-zero minors, so it
/// is fast for banded matrices). Errors if `m` is not square or larger than
/// [`MINORS_MAX`].
///
/// ```
/// use poly::{det_minors, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let m = vec![vec![p("x"), p("y")], vec![p("y"), p("x")]];
/// assert_eq!(det_minors(&m).unwrap(), p("x^2 - y^2"));
/// ```
pub fn det_minors(m: &[Vec<Poly>]) -> Result<Poly, MatrixError> {
    let n = check_square(m)?;
    if n > MINORS_MAX {
        return Err(MatrixError::TooLarge { n, max: MINORS_MAX });
    }
    Ok(minors_unchecked(m, n))
}

fn minors_unchecked(m: &[Vec<Poly>], n: usize) -> Poly {
    minors_dp(m, n, |_, _| {})
}

/// The leading principal minors `[D_1, ..., D_n]` (`D_k` = determinant of
/// the top-left `k x k` block), all from one division-free expansion by
/// minors. Errors if `m` is not square or larger than [`MINORS_MAX`].
///
/// ```
/// use poly::{leading_principal_minors, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let m = vec![vec![p("a"), p("b")], vec![p("c"), p("d")]];
/// assert_eq!(leading_principal_minors(&m).unwrap(), vec![p("a"), p("a*d - b*c")]);
/// ```
pub fn leading_principal_minors(m: &[Vec<Poly>]) -> Result<Vec<Poly>, MatrixError> {
    let n = check_square(m)?;
    if n > MINORS_MAX {
        return Err(MatrixError::TooLarge { n, max: MINORS_MAX });
    }
    let mut out = Vec::with_capacity(n);
    minors_dp(m, n, |k, level| {
        out.push(level.get(&((1u32 << k) - 1)).cloned().unwrap_or_default());
    });
    Ok(out)
}

/// Expansion by minors; `visit(k, level)` sees, after each row `k - 1`, the
/// non-zero minors on rows `0..k` keyed by their column masks.
fn minors_dp(
    m: &[Vec<Poly>],
    n: usize,
    mut visit: impl FnMut(usize, &BTreeMap<u32, Poly>),
) -> Poly {
    // level[mask] = det of rows 0..k, columns in mask (|mask| = k).
    let mut level: BTreeMap<u32, Poly> = BTreeMap::new();
    level.insert(0, Poly::one());
    for (k, row) in m.iter().enumerate().take(n) {
        // All products for one new minor are summed in one pass.
        let mut terms: BTreeMap<u32, Vec<(&Poly, &Poly, bool)>> = BTreeMap::new();
        for (&mask, val) in &level {
            for (j, e) in row.iter().enumerate() {
                if e.is_zero() || mask & (1 << j) != 0 {
                    continue;
                }
                // Expanding the k-th row of the minor on columns mask|j: the
                // sign is (-1)^(number of chosen columns to the right of j).
                let after = (mask >> (j + 1)).count_ones();
                terms
                    .entry(mask | (1 << j))
                    .or_default()
                    .push((e, val, after % 2 == 1));
            }
        }
        let mut next: BTreeMap<u32, Poly> = terms
            .into_iter()
            .map(|(mask, ops)| (mask, Poly::sum_of_products(&ops)))
            .collect();
        next.retain(|_, v| !v.is_zero());
        level = next;
        debug_assert!(level.keys().all(|mk| mk.count_ones() as usize == k + 1));
        visit(k + 1, &level);
    }
    level.remove(&((1u32 << n) - 1)).unwrap_or_default()
}

/// Largest size accepted by [`det_laplace`].
pub const LAPLACE_MAX: usize = 9;

/// Determinant by plain recursive Laplace expansion along the first row:
/// `O(n!)`, meant as an independent check of [`det`] in tests. Errors if `m`
/// is not square or larger than [`LAPLACE_MAX`].
///
/// ```
/// use poly::{det_laplace, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let m = vec![vec![p("a"), p("b")], vec![p("c"), p("d")]];
/// assert_eq!(det_laplace(&m).unwrap(), p("a*d - b*c"));
/// ```
pub fn det_laplace(m: &[Vec<Poly>]) -> Result<Poly, MatrixError> {
    let n = check_square(m)?;
    if n > LAPLACE_MAX {
        return Err(MatrixError::TooLarge {
            n,
            max: LAPLACE_MAX,
        });
    }
    let cols: Vec<usize> = (0..n).collect();
    Ok(laplace_rec(m, 0, &cols))
}

fn laplace_rec(m: &[Vec<Poly>], row: usize, cols: &[usize]) -> Poly {
    if cols.is_empty() {
        return Poly::one();
    }
    let mut acc = Poly::zero();
    for (t, &c) in cols.iter().enumerate() {
        let e = &m[row][c];
        if e.is_zero() {
            continue;
        }
        let rest: Vec<usize> = cols.iter().copied().filter(|&x| x != c).collect();
        let term = e * &laplace_rec(m, row + 1, &rest);
        acc = if t % 2 == 0 {
            &acc + &term
        } else {
            &acc - &term
        };
    }
    acc
}

/// The matrix with row `i` and column `j` removed. Errors if `m` is not
/// square or the indices are out of range.
///
/// ```
/// use poly::{minor, Poly};
/// let m: Vec<Vec<Poly>> = (0..3)
///     .map(|i| (0..3).map(|j| Poly::int(3 * i + j)).collect())
///     .collect();
/// let s = minor(&m, 1, 0).unwrap();
/// assert_eq!(s, vec![vec![Poly::int(1), Poly::int(2)], vec![Poly::int(7), Poly::int(8)]]);
/// ```
pub fn minor(m: &[Vec<Poly>], i: usize, j: usize) -> Result<Vec<Vec<Poly>>, MatrixError> {
    let n = check_square(m)?;
    if i >= n || j >= n {
        return Err(MatrixError::IndexOutOfRange { i, j, n });
    }
    Ok(m.iter()
        .enumerate()
        .filter(|&(r, _)| r != i)
        .map(|(_, row)| {
            row.iter()
                .enumerate()
                .filter(|&(c, _)| c != j)
                .map(|(_, e)| e.clone())
                .collect()
        })
        .collect())
}

/// The cofactor `(-1)^(i+j) det(minor(m, i, j))`.
///
/// Panics if `m` is not square or `(i, j)` is out of range; see
/// [`try_cofactor`].
///
/// ```
/// use poly::{cofactor, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let m = vec![vec![p("a"), p("b")], vec![p("c"), p("d")]];
/// assert_eq!(cofactor(&m, 0, 1), p("-c"));
/// ```
pub fn cofactor(m: &[Vec<Poly>], i: usize, j: usize) -> Poly {
    try_cofactor(m, i, j).unwrap_or_else(|e| panic!("cofactor: {e}"))
}

/// Checked [`cofactor`].
///
/// ```
/// use poly::{try_cofactor, Poly};
/// let m = vec![vec![Poly::int(5)]];
/// assert_eq!(try_cofactor(&m, 0, 0).unwrap(), Poly::one());
/// assert!(try_cofactor(&m, 0, 1).is_err());
/// ```
pub fn try_cofactor(m: &[Vec<Poly>], i: usize, j: usize) -> Result<Poly, MatrixError> {
    let d = try_det(&minor(m, i, j)?)?;
    Ok(if (i + j) % 2 == 1 { -d } else { d })
}

/// The adjugate (transposed cofactor matrix): `adj[j][i] = cofactor(m, i, j)`,
/// so that `m * adj = adj * m = det(m) * I`.
///
/// Panics if `m` is not square; see [`try_adjugate`].
///
/// ```
/// use poly::{adjugate, Poly};
/// let p = |s: &str| s.parse::<Poly>().unwrap();
/// let m = vec![vec![p("a"), p("b")], vec![p("c"), p("d")]];
/// let adj = adjugate(&m);
/// assert_eq!(adj, vec![vec![p("d"), p("-b")], vec![p("-c"), p("a")]]);
/// ```
pub fn adjugate(m: &[Vec<Poly>]) -> Vec<Vec<Poly>> {
    try_adjugate(m).unwrap_or_else(|e| panic!("adjugate: {e}"))
}

/// Checked [`adjugate`]. The adjugate of the empty matrix is empty; that of
/// a 1x1 matrix is `[[1]]`.
///
/// ```
/// use poly::{try_adjugate, Poly};
/// assert_eq!(try_adjugate(&[vec![Poly::int(7)]]).unwrap(), vec![vec![Poly::one()]]);
/// ```
pub fn try_adjugate(m: &[Vec<Poly>]) -> Result<Vec<Vec<Poly>>, MatrixError> {
    let n = check_square(m)?;
    let mut adj = vec![vec![Poly::zero(); n]; n];
    for i in 0..n {
        for (j, adj_row) in adj.iter_mut().enumerate() {
            adj_row[i] = try_cofactor(m, i, j)?;
        }
    }
    Ok(adj)
}

/// Product of two matrices (rows of `a` times columns of `b`); `None` if
/// the inner dimensions differ or a row is ragged.
///
/// ```
/// use poly::{mat_mul, Poly};
/// let a = vec![vec![Poly::int(1), Poly::int(2)]];
/// let b = vec![vec![Poly::var("x")], vec![Poly::var("y")]];
/// assert_eq!(mat_mul(&a, &b).unwrap(), vec![vec!["x + 2*y".parse::<Poly>().unwrap()]]);
/// ```
pub fn mat_mul(a: &[Vec<Poly>], b: &[Vec<Poly>]) -> Option<Vec<Vec<Poly>>> {
    let inner = b.len();
    let cols = b.first().map_or(0, |r| r.len());
    if a.iter().any(|r| r.len() != inner) || b.iter().any(|r| r.len() != cols) {
        return None;
    }
    Some(
        a.iter()
            .map(|row| {
                (0..cols)
                    .map(|j| {
                        row.iter()
                            .zip(b)
                            .filter(|(x, brow)| !x.is_zero() && !brow[j].is_zero())
                            .fold(Poly::zero(), |acc, (x, brow)| &acc + &(x * &brow[j]))
                    })
                    .collect()
            })
            .collect(),
    )
}

/// Gaussian elimination over `Q` with row pivoting: the pivots `(row,
/// column)` (original indices) in elimination order. Their number is the
/// rank, and for every `s` the rows and columns of the first `s` pivots
/// form a non-singular submatrix.
///
/// ```
/// use poly::{pivots, Rat};
/// let r = |x: i64| Rat::from(x);
/// let m = vec![vec![r(0), r(2)], vec![r(1), r(3)]];
/// assert_eq!(pivots(m), vec![(1, 0), (0, 1)]);
/// ```
pub fn pivots(mut rows: Vec<Vec<Rat>>) -> Vec<(usize, usize)> {
    let cols = rows.first().map_or(0, Vec::len);
    let mut order: Vec<usize> = (0..rows.len()).collect();
    let mut out = Vec::new();
    let mut r = 0;
    for c in 0..cols {
        if r == rows.len() {
            break;
        }
        let Some(p) = (r..rows.len()).find(|&i| !rows[i][c].is_zero()) else {
            continue;
        };
        rows.swap(r, p);
        order.swap(r, p);
        let inv = rows[r][c].recip();
        let pivot: Vec<Rat> = rows[r].iter().map(|x| x * &inv).collect();
        for row in rows.iter_mut().skip(r + 1) {
            if row[c].is_zero() {
                continue;
            }
            let f = row[c].clone();
            for (x, y) in row.iter_mut().zip(&pivot).skip(c) {
                *x = &*x - &(&f * y);
            }
        }
        rows[r] = pivot;
        out.push((order[r], c));
        r += 1;
    }
    out
}

/// The rank of a matrix over `Q` (rows of equal length; 0 for no rows),
/// by exact Gaussian elimination ([`pivots`]).
///
/// ```
/// use poly::{rank, Rat};
/// let r = |x: i64| Rat::from(x);
/// // The third row is the sum of the first two.
/// let m = vec![vec![r(1), r(2), r(3)], vec![r(0), r(1), r(1)], vec![r(1), r(3), r(4)]];
/// assert_eq!(rank(m), 2);
/// ```
pub fn rank(m: Vec<Vec<Rat>>) -> usize {
    pivots(m).len()
}

#[cfg(test)]
pub(crate) mod tests {

    /// The rank against a second route: a square matrix has full rank
    /// exactly when its determinant (by minors) is non-zero, and a matrix
    /// with a row repeated as a combination of others loses one.
    #[test]
    fn rank_agrees_with_the_determinant() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 5) as i64 - 2
        };
        for n in 1..=5 {
            for _ in 0..40 {
                let m: Vec<Vec<i64>> = (0..n).map(|_| (0..n).map(|_| next()).collect()).collect();
                let p: Vec<Vec<Poly>> = m
                    .iter()
                    .map(|r| r.iter().map(|&x| Poly::int(x)).collect())
                    .collect();
                let q: Vec<Vec<Rat>> = m
                    .iter()
                    .map(|r| r.iter().map(|&x| Rat::from(x)).collect())
                    .collect();
                assert_eq!(rank(q.clone()) == n, !det(&p).is_zero(), "{m:?}");
                let mut extra = q.clone();
                let combo: Vec<Rat> = (0..n)
                    .map(|j| &(&q[0][j] * &Rat::from(3)) - &q[n - 1][j])
                    .collect();
                extra.push(combo);
                assert_eq!(rank(extra), rank(q), "{m:?}");
            }
        }
    }
    /// Bareiss over `Z[x]` against Laplace's expansion of the same
    /// matrices as polynomials over `Q`, a route that shares neither the
    /// elimination nor the division; zero pivots and singular matrices
    /// included (entries often zero, rows sometimes repeated).
    #[test]
    fn the_univariate_determinant_agrees_with_laplace() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % m) as i64
        };
        for n in 0..=5usize {
            for trial in 0..30 {
                let mut m: Vec<Vec<UPoly>> = (0..n)
                    .map(|_| {
                        (0..n)
                            .map(|_| {
                                if next(3) == 0 {
                                    return UPoly::zero();
                                }
                                let deg = next(3) as usize;
                                let c: Vec<i64> = (0..=deg).map(|_| next(41) - 20).collect();
                                UPoly::from_i64s(&c)
                            })
                            .collect()
                    })
                    .collect();
                if n > 1 && trial % 5 == 0 {
                    m[n - 1] = m[0].clone();
                }
                let q: Vec<Vec<Poly>> = m
                    .iter()
                    .map(|r| r.iter().map(|u| u.to_poly("x")).collect())
                    .collect();
                let d = det_univariate(&m).unwrap();
                assert_eq!(d.to_poly("x"), det_laplace(&q).unwrap(), "{m:?}");
                if n > 1 && trial % 5 == 0 {
                    assert!(d.is_zero());
                }
            }
        }
        let bad = vec![vec![UPoly::one(), UPoly::one()], vec![UPoly::one()]];
        assert!(matches!(
            det_univariate(&bad),
            Err(MatrixError::NotSquare { row: 1, .. })
        ));
    }

    use super::*;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    fn mat(rows: &[&[&str]]) -> Vec<Vec<Poly>> {
        rows.iter()
            .map(|r| r.iter().map(|s| p(s)).collect())
            .collect()
    }

    /// C - Omega*M for a free chain of n masses (springs c_{i,i+1}).
    pub(crate) fn chain(n: usize) -> Vec<Vec<Poly>> {
        let c = |i: usize| p(&format!("c{}{}", i, i + 1));
        let mut a = vec![vec![Poly::zero(); n]; n];
        for i in 0..n {
            let mut d = p(&format!("-Omega*m{}", i + 1));
            if i > 0 {
                d = &d + &c(i);
            }
            if i + 1 < n {
                d = &d + &c(i + 1);
            }
            a[i][i] = d;
            if i + 1 < n {
                a[i][i + 1] = -c(i + 1);
                a[i + 1][i] = -c(i + 1);
            }
        }
        a
    }

    fn generic(n: usize) -> Vec<Vec<Poly>> {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        p(&format!(
                            "a{i}{j} + {}*x{} - {}",
                            (i + 2 * j) % 3,
                            (i * j) % 4,
                            (i * 7 + j * 3) % 5
                        ))
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn small_known_determinants() {
        assert_eq!(det(&mat(&[&["a", "b"], &["c", "d"]])), p("a*d - b*c"));
        // Vandermonde: det = (y-x)(z-x)(z-y).
        let v = mat(&[&["1", "x", "x^2"], &["1", "y", "y^2"], &["1", "z", "z^2"]]);
        assert_eq!(det(&v), p("(y - x)*(z - x)*(z - y)"));
        assert_eq!(det_bareiss(&v).unwrap(), p("(y - x)*(z - x)*(z - y)"));
        // Singular: two equal rows.
        let s = mat(&[&["x", "y", "1"], &["x", "y", "1"], &["a", "b", "c"]]);
        assert!(det(&s).is_zero());
        assert!(det_bareiss(&s).unwrap().is_zero());
    }

    #[test]
    fn two_mass_chain_matches_paper_form() {
        // Two masses: det = Omega*(m1*m2*Omega - c12*(m1+m2)), eigenvalue 0.
        let d = det(&chain(2));
        assert_eq!(d, p("m1*m2*Omega^2 - c12*(m1 + m2)*Omega"));
        // Three masses: Omega * Den_A of the paper (free chain has Omega = 0).
        let d3 = det(&chain(3));
        let den_a = p(
            "m1*m2*m3*Omega^2 - (c12*(m1*m3 + m2*m3) + c23*m1*(m2 + m3))*Omega \
                       + c12*c23*(m1 + m2 + m3)",
        );
        assert_eq!(d3, -(&p("Omega") * &den_a));
    }

    #[test]
    fn algorithms_agree() {
        for n in 0..=5 {
            let g = generic(n);
            let l = det_laplace(&g).unwrap();
            assert_eq!(det_bareiss(&g).unwrap(), l, "generic n={n}");
            assert_eq!(det_minors(&g).unwrap(), l, "generic n={n}");
            let c = chain(n);
            let l = det_laplace(&c).unwrap();
            assert_eq!(det_bareiss(&c).unwrap(), l, "chain n={n}");
            assert_eq!(det(&c), l, "chain n={n}");
        }
    }

    #[test]
    fn zero_pivot_needs_row_swap() {
        // Leading entry zero: Bareiss must pivot.
        let m = mat(&[&["0", "x", "1"], &["y", "0", "2"], &["1", "1", "0"]]);
        let l = det_laplace(&m).unwrap();
        assert_eq!(l, p("2*x + y")); // by hand: -x*(0 - 2) + 1*(y - 0)
        assert_eq!(det_bareiss(&m).unwrap(), l);
        assert_eq!(det_minors(&m).unwrap(), l);
    }

    #[test]
    fn adjugate_identity() {
        for m in [generic(3), chain(4), mat(&[&["0", "x"], &["y", "0"]])] {
            let n = m.len();
            let d = det(&m);
            let adj = adjugate(&m);
            let prod = mat_mul(&m, &adj).unwrap();
            let prod2 = mat_mul(&adj, &m).unwrap();
            for i in 0..n {
                for j in 0..n {
                    let want = if i == j { d.clone() } else { Poly::zero() };
                    assert_eq!(prod[i][j], want);
                    assert_eq!(prod2[i][j], want);
                }
            }
        }
    }

    /// Timing of the determinant algorithms (run with `--ignored --nocapture`).
    #[test]
    #[ignore]
    fn timing_det() {
        use std::time::Instant;
        for (name, m, bareiss) in [
            ("chain 8", chain(8), true),
            ("chain 10", chain(10), true),
            ("generic 5", generic(5), true),
            // Bareiss needs about a minute here.
            ("generic 6", generic(6), false),
        ] {
            let t = Instant::now();
            let a = det_minors(&m).unwrap();
            let t_min = t.elapsed();
            let mut line = format!("{name}: minors {t_min:?}");
            if bareiss {
                let t = Instant::now();
                let b = det_bareiss(&m).unwrap();
                line += &format!(", Bareiss {:?}", t.elapsed());
                assert_eq!(a, b);
            }
            eprintln!("{line}, {} terms", a.num_terms());
        }
    }

    #[test]
    fn errors_not_panics() {
        let bad = mat(&[&["1", "2"], &["3"]]);
        assert!(matches!(
            try_det(&bad),
            Err(MatrixError::NotSquare {
                row: 1,
                len: 1,
                expected: 2
            })
        ));
        assert!(try_adjugate(&bad).is_err());
        let ok = mat(&[&["1", "2"], &["3", "4"]]);
        assert!(matches!(
            try_cofactor(&ok, 2, 0),
            Err(MatrixError::IndexOutOfRange { .. })
        ));
        assert!(det_laplace(&generic(10)).is_err());
        assert_eq!(try_det(&[]).unwrap(), Poly::one());
        assert_eq!(try_adjugate(&[]).unwrap(), Vec::<Vec<Poly>>::new());
    }
}
