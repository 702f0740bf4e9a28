//! Linear algebra over Q: square systems and inverses by Gaussian
//! elimination with exact fractions.
//!
//! The matrices here are small (a handful of rows), dense and of rational
//! entries; the polynomial matrices of [`crate::det`] and friends are
//! another domain.

use crate::rat::Rat;

/// The solution of `a x = b` for a square `a`; `None` if `a` is singular or
/// not square, or `b` has another length.
///
/// ```
/// use poly::{solve_rat, Rat};
/// let r = |v: i64| Rat::from(v);
/// let a = vec![vec![r(2), r(1)], vec![r(1), r(3)]];
/// let x = solve_rat(&a, &[r(3), r(5)]).unwrap();
/// assert_eq!(x, vec!["4/5".parse().unwrap(), "7/5".parse().unwrap()]);
/// assert!(solve_rat(&[vec![r(1), r(2)], vec![r(2), r(4)]], &[r(1), r(1)]).is_none());
/// ```
pub fn solve_rat(a: &[Vec<Rat>], b: &[Rat]) -> Option<Vec<Rat>> {
    let n = a.len();
    if b.len() != n {
        return None;
    }
    let columns: Vec<Vec<Rat>> = b.iter().map(|v| vec![v.clone()]).collect();
    let x = eliminate(a, &columns)?;
    Some(x.into_iter().map(|mut row| row.remove(0)).collect())
}

/// The inverse of a square matrix over Q; `None` if it is singular or not
/// square.
///
/// ```
/// use poly::{inverse_rat, Rat};
/// let r = |v: i64| Rat::from(v);
/// let inv = inverse_rat(&[vec![r(2), r(1)], vec![r(1), r(1)]]).unwrap();
/// assert_eq!(inv, vec![vec![r(1), r(-1)], vec![r(-1), r(2)]]);
/// ```
pub fn inverse_rat(a: &[Vec<Rat>]) -> Option<Vec<Vec<Rat>>> {
    let n = a.len();
    let identity: Vec<Vec<Rat>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i == j { Rat::ONE } else { Rat::ZERO })
                .collect()
        })
        .collect();
    eliminate(a, &identity)
}

/// `a^-1 b` for a square `a` and `b` of as many rows, by Gauss-Jordan
/// elimination with the first nonzero pivot of each column.
fn eliminate(a: &[Vec<Rat>], b: &[Vec<Rat>]) -> Option<Vec<Vec<Rat>>> {
    let n = a.len();
    if a.iter().any(|row| row.len() != n) || b.len() != n {
        return None;
    }
    let mut rows: Vec<Vec<Rat>> = a
        .iter()
        .zip(b)
        .map(|(r, s)| r.iter().chain(s).cloned().collect())
        .collect();
    let width = rows.first().map_or(0, Vec::len);
    for col in 0..n {
        let pivot = (col..n).find(|&i| !rows[i][col].is_zero())?;
        rows.swap(col, pivot);
        let inv = rows[col][col].recip();
        for v in rows[col].iter_mut() {
            *v = &*v * &inv;
        }
        let pivot_row = rows[col].clone();
        for (i, row) in rows.iter_mut().enumerate() {
            if i == col || row[col].is_zero() {
                continue;
            }
            let f = row[col].clone();
            for (v, p) in row[col..width].iter_mut().zip(&pivot_row[col..width]) {
                *v = &*v - &(&f * p);
            }
        }
    }
    Some(rows.into_iter().map(|r| r[n..].to_vec()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_inverse_times_its_matrix_is_the_identity() {
        // A 4x4 matrix with a zero in the first pivot place (a swap).
        let m: Vec<Vec<Rat>> = [[0, 2, -1, 3], [1, 1, 0, -2], [4, -3, 5, 1], [2, 0, 1, 7]]
            .iter()
            .map(|r| r.iter().map(|&v| Rat::from(v)).collect())
            .collect();
        let inv = inverse_rat(&m).unwrap();
        for (i, row) in m.iter().enumerate() {
            for j in 0..4 {
                let s = row
                    .iter()
                    .zip(&inv)
                    .fold(Rat::ZERO, |acc, (a, inv_row)| &acc + &(a * &inv_row[j]));
                assert_eq!(s, if i == j { Rat::ONE } else { Rat::ZERO });
            }
        }
        let b: Vec<Rat> = (1..=4).map(Rat::from).collect();
        let x = solve_rat(&m, &b).unwrap();
        for (row, bi) in m.iter().zip(&b) {
            let s = row
                .iter()
                .zip(&x)
                .fold(Rat::ZERO, |acc, (a, xi)| &acc + &(a * xi));
            assert_eq!(&s, bi);
        }
    }
}
