//! # poly: exact polynomials over Q
//!
//! The algebra under `mms`, in layers (each testable alone):
//!
//! 1. coefficients: [`Int`] (machine word with big-integer fallback) and [`Rat`];
//! 2. polynomials: [`Poly`], sparse multivariate with named variables, and
//!    [`UPoly`], dense univariate over Z;
//! 3. algorithms: determinants of polynomial matrices, resultants and
//!    discriminants (subresultant PRS), GCD, square-free and full
//!    factorization over Q, and real-root isolation.
//!
//! `poly` knows nothing of masses or springs.
//!
//! ```
//! use poly::Poly;
//! let den: Poly = "m1*m2*Omega^2 - c12*(m1 + m2)*Omega".parse().unwrap();
//! let num: Poly = "m2*Omega - c12".parse().unwrap();
//! // The resultant in Omega vanishes exactly where Num and Den share a root.
//! let r = poly::resultant(&num, &den, "Omega");
//! assert_eq!(r.to_string(), "c12^2*m1*m2");
//! ```

mod int;
mod parse;
mod poly;
mod rat;

pub use crate::int::Int;
pub use crate::parse::ParsePolyError;
pub use crate::poly::{var_cmp, Poly, Term};
pub use crate::rat::{ParseRatError, Rat};
mod upoly;
pub use crate::upoly::UPoly;
