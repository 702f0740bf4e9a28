//! Dense univariate polynomials over Z.

use crate::int::Int;

/// A dense univariate polynomial with integer coefficients, lowest degree
/// first, without trailing zeros (the zero polynomial has no coefficients).
#[derive(Clone, PartialEq, Eq, Hash, Debug, Default)]
pub struct UPoly {
    coeffs: Vec<Int>,
}

impl UPoly {
    /// From coefficients, lowest degree first (trailing zeros are removed).
    pub fn new(mut coeffs: Vec<Int>) -> UPoly {
        while coeffs.last().is_some_and(|c| c.is_zero()) {
            coeffs.pop();
        }
        UPoly { coeffs }
    }

    /// Coefficients, lowest degree first.
    pub fn coeffs(&self) -> &[Int] {
        &self.coeffs
    }

    /// Degree; `None` for the zero polynomial.
    pub fn degree(&self) -> Option<usize> {
        self.coeffs.len().checked_sub(1)
    }

    /// True for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.coeffs.is_empty()
    }
}
