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
//! // The resultant in Omega vanishes exactly where Num and Den share a root:
//! // Res = lc(num)^2 * den(c12/m2) = m2^2 * (-c12^2).
//! let r = poly::resultant(&num, &den, "Omega");
//! assert_eq!(r.to_string(), "-c12^2*m2^2");
//! ```

mod int;
mod parse;
mod poly;
mod rat;
#[cfg(feature = "serde")]
mod serde_text;

pub use crate::int::Int;
pub use crate::parse::ParsePolyError;
pub use crate::poly::{var_cmp, Poly, Term};
pub use crate::rat::{ParseRatError, Rat};
mod upoly;
pub use crate::upoly::UPoly;
mod matrix;
pub use crate::matrix::{
    adjugate, check_square, cofactor, det, det_bareiss, det_laplace, det_minors, det_univariate,
    leading_principal_minors, mat_mul, minor, pivots, rank, try_adjugate, try_cofactor, try_det,
    MatrixError, LAPLACE_MAX, MINORS_AUTO_MAX, MINORS_MAX,
};
mod gcd;
pub use crate::gcd::{content_and_pp, content_in, gcd, gcd_many, lcm, primitive_part_in};
mod roots;
pub use crate::roots::{
    count_nonpositive_or_nonreal, count_real_roots, count_roots_in, interleave_roots,
    positive_roots, real_roots, RealRoot, RootError, SharedRoot, SturmSequence,
};
mod factor_uni;
pub use crate::factor_uni::{factor_univariate, rational_roots};
mod resultant;
pub use crate::resultant::{
    bezout_matrix, discriminant, psc, resultant, sturm_habicht, sturm_habicht_principal,
    subresultant_chain, subresultants, sylvester_matrix,
};
mod factor;
mod homog;
pub use crate::factor::{factor, Factorization};
mod sqfree;
pub use crate::sqfree::{is_square_free, square_free, square_free_part};
mod interval;
pub use crate::interval::RatInterval;
mod linear;
pub use crate::linear::{inverse_rat, solve_rat};
mod numfield;
pub use crate::numfield::{FieldElem, FieldError, FieldPoly, RealField};
