//! Analytic back-solving: every positive parameter set of a model structure
//! whose undamped inertance equals a given rational function (Sec. 5 and
//! Tabs. 4, 6, 7 of the paper).
//!
//! # Problem
//!
//! A [`Target`] is an undamped inertance `n(Omega)/d(Omega)` with exact
//! rational coefficients, kept in lowest terms. A parameter set `p` (masses
//! and springs, all `> 0`) of a [`Model`] reproduces it when the model's
//! inertance `num_S(p)/den_S(p)` ([`Model::undamped_tf`]) is the *same
//! rational function*: `num_S(p) * d - den_S(p) * n == 0` in `Omega`. Nothing
//! is normalised away: the gain is part of the inertance (scaling all masses
//! and springs by `t` scales the inertance by `1/t`), so equal poles and zeros
//! are not enough.
//!
//! Because `n/d` is in lowest terms, `d` divides `den_S(p)`; with the quotient
//! `q(p; Omega)` of `den_S` by `d` (a polynomial division in `Omega` with
//! symbolic coefficients) the condition is equivalent to
//!
//! ```text
//! remainder(den_S(p), d) == 0   and   num_S(p) == q(p) * n   (coefficientwise in Omega).
//! ```
//!
//! In the usual case `deg d = deg den_S` the quotient is the constant
//! `lc(den_S)/lc(d) = m1*...*mN / lc(d)`; a lower degree of `d` means the
//! solution must cancel a pole against a zero, and `q` carries that factor.
//!
//! # Method (exact; completeness by algebra, not by restarts)
//!
//! 1. **Quick exact obstructions.** Degrees (the structure's relative degree
//!    is fixed), the sign of every coefficient whose sign is fixed on
//!    positive parameters, and the *invariant relations* of the structure
//!    ([`invariant_relations`]): polynomial identities that the coefficients
//!    of every transfer function of the structure satisfy, found by exact
//!    interpolation and then verified symbolically. C2 and C4 have
//!    `d0*n2 - d2*n0 = 0` (`den_S = m3*num_S + c12*m3^2*Omega`), the linkage
//!    of eqs. (62)-(63) of the paper; B2 has one of degree 4.
//! 2. **Elimination with splitting.** The coefficient equations are
//!    multilinear in the parameters (every parameter enters `det(C - Omega*M)`
//!    and the adjugate at most linearly). Each step removes the factors that
//!    cannot vanish for positive parameters (monomials, polynomials whose
//!    coefficients all have one sign) after an exact factorization over Q
//!    ([`poly::factor`]), splits the branch when an equation still factors,
//!    and solves one equation `a*x + b = 0` that is linear in a parameter
//!    `x`, preferring a coefficient `a` that cannot vanish (else it splits
//!    into `a != 0` and `a = b = 0`). `x = -b/a` is substituted into every
//!    equation (`a^k * g(-b/a)`) and into the earlier solutions, which
//!    therefore stay rational functions of the remaining parameters.
//!    When no equation is linear in any parameter, one parameter `y` is
//!    eliminated by resultants against the equation of lowest degree in it
//!    ([`poly::subresultant_chain`]); the first subresultant gives `y` as a
//!    rational function wherever its leading coefficient does not vanish,
//!    and the gcd of the equations over the number field below otherwise.
//! 3. **End of a branch.** Either no equation is left (the remaining
//!    parameters are free: a [`Family`] with rational expressions, or a
//!    single rational point), or one irreducible equation in the last two
//!    parameters is left (a family on a curve: C2 and C4 on their
//!    hypersurface, see [`Dependent`]), or the equations are univariate in
//!    the last parameter `t`: their gcd is split into irreducible factors
//!    `f` over Q ([`poly::factor_univariate`]) and the real roots of each are
//!    isolated exactly ([`poly::real_roots`]). Anything else stops with
//!    [`BackSolveError::Unsupported`]; growth is bounded by [`Limits`]
//!    (sizes, degrees, branches and a time budget), which ends in
//!    [`BackSolveError::LimitExceeded`] instead of a hang.
//! 4. **Verification.** For a root of `f`, every parameter is an element of
//!    the number field `Q[t]/(f)`; all original coefficient equations are
//!    evaluated there and must vanish *exactly* (extraneous candidates of
//!    the resultants are dropped). Signs are decided exactly (refining the
//!    isolating interval of the root until the polynomial representing the
//!    parameter has no root in it), the minimal polynomial of each
//!    parameter comes from linear algebra in the field, and its isolating
//!    interval is the one of its exactly isolated real roots nearest to a
//!    2^-200-accurate value. Families are verified by substituting the
//!    parametrisation into every equation symbolically (the result must be
//!    the zero polynomial, or a multiple of the curve's equation); for one
//!    free parameter the admissible set (all parameters `> 0`) is a union
//!    of open intervals with exactly isolated algebraic ends, found by
//!    testing one exact point between consecutive critical values (roots of
//!    numerators and denominators; for a curve also its discriminant,
//!    leading coefficient and the resultants with them).
//!
//! All 3-mass structures back-solve in milliseconds (release build); 4-mass
//! chains work when the elimination stays small and otherwise stop at the
//! limits.
//!
//! ```
//! use mms::backsolve::{back_solve, BackSolution, Target};
//! use mms::Model;
//!
//! // A1 with m1 = 1, m2 = 2, m3 = 3, c12 = 4, c23 = 5 (exact integers).
//! let a1 = Model::from_id("A1")?;
//! let target = Target::from_model_f64(&a1, &[1.0, 2.0, 3.0, 4.0, 5.0])?;
//! // A1 is globally identifiable: its own parameters come back, alone.
//! let BackSolution::Points(points) = back_solve(&a1, &target)? else { panic!() };
//! assert_eq!(points.len(), 1);
//! assert_eq!(points[0].values, [1.0, 2.0, 3.0, 4.0, 5.0]);
//! // A4 reproduces the same inertance with two parameter sets (cf. Tab. 7).
//! let a4 = back_solve(&Model::from_id("A4")?, &target)?;
//! assert_eq!(a4.points().len(), 2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::model::Model;
use crate::tf::OMEGA;
use crate::xorshift::XorShift;
use poly::{
    count_roots_in, factor, factor_univariate, real_roots, Int, Poly, Rat, RealRoot, UPoly,
};
use std::cmp::Ordering;
use std::collections::BTreeMap;
use std::fmt;

/// Errors of [`back_solve`] and of building a [`Target`].
///
/// ```
/// use mms::backsolve::{BackSolveError, Target};
/// let e = Target::from_f64(&[1.0], &[f64::INFINITY]).unwrap_err();
/// assert!(matches!(e, BackSolveError::NonFinite(_)));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BackSolveError {
    /// The target denominator is the zero polynomial.
    #[error("the target denominator is zero")]
    ZeroDenominator,
    /// The target numerator is the zero polynomial: no chain has a zero
    /// inertance.
    #[error("the target numerator is zero")]
    ZeroNumerator,
    /// A floating-point input is NaN or infinite.
    #[error("non-finite input value {0}")]
    NonFinite(String),
    /// The number of parameter values does not match the model.
    #[error("model {model} has {expected} undamped parameters, {got} values were given")]
    ParameterCount {
        /// The model's name.
        model: String,
        /// Its number of undamped parameters.
        expected: usize,
        /// The number of values given.
        got: usize,
    },
    /// A parameter value is not positive.
    #[error("parameter {name} = {value} is not positive")]
    NonPositiveParameter {
        /// Parameter name.
        name: String,
        /// The value given.
        value: String,
    },
    /// A size or work limit of [`Limits`] was reached.
    #[error("limit exceeded: {0}")]
    LimitExceeded(String),
    /// The elimination reached a system it does not handle (no equation
    /// linear in a parameter and not univariate).
    #[error("unsupported system: {0}")]
    Unsupported(String),
}

/// Work limits of [`back_solve_with`], so that large models fail with
/// [`BackSolveError::LimitExceeded`] instead of running for long.
///
/// ```
/// let l = mms::backsolve::Limits::default();
/// assert_eq!(l.max_parameters, 9); // up to 5 masses
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest number of undamped parameters (`2N - 1`) accepted.
    pub max_parameters: usize,
    /// Largest number of branches explored by the elimination.
    pub max_branches: usize,
    /// Largest number of terms of any equation during the elimination.
    pub max_terms: usize,
    /// Largest degree of a univariate eliminant.
    pub max_degree: usize,
    /// Largest number of monomials tried when searching invariant relations.
    pub max_relation_monomials: usize,
    /// Wall-clock budget of one call: a safety net for inputs whose exact
    /// arithmetic explodes although every size limit holds (large 4-mass
    /// systems), checked between the steps of the elimination and of the
    /// back-substitution.
    pub max_time: std::time::Duration,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_parameters: 9,
            max_branches: 512,
            max_terms: 4000,
            max_degree: 48,
            max_relation_monomials: 220,
            max_time: std::time::Duration::from_secs(20),
        }
    }
}

// ---------------------------------------------------------------------------
// Target

/// An undamped inertance `n(Omega)/d(Omega)` with exact rational
/// coefficients (lowest power of `Omega` first).
///
/// Normal form, so that two targets are equal exactly when they are the same
/// rational function: common factors of `n` and `d` are cancelled, all
/// coefficients are integers without a common factor, and the leading
/// coefficient of `d` is positive.
///
/// ```
/// use mms::backsolve::Target;
/// use poly::Rat;
/// // (2 - 4*Omega) / (6 + 2*Omega - 4*Omega^2) = (1 - 2*Omega)/(...)
/// let r = |v: &[i64]| v.iter().map(|&x| Rat::from(x)).collect::<Vec<_>>();
/// let t = Target::new(r(&[2, -4]), r(&[6, 2, -4]))?;
/// // 6 + 2W - 4W^2 = -2 (2W - 3)(W + 1) shares nothing with 1 - 2W: only content and sign go.
/// assert_eq!(t.num(), r(&[-1, 2]).as_slice());
/// assert_eq!(t.den(), r(&[-3, -1, 2]).as_slice());
/// assert_eq!(t.eval_f64(1.0), 1.0 / -2.0);
/// # Ok::<(), mms::backsolve::BackSolveError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Target {
    num: Vec<Rat>,
    den: Vec<Rat>,
}

/// Content and primitive part of a list of rationals as an integer
/// polynomial (`v = c * u`, `u` primitive with positive leading coefficient).
fn rat_upoly(v: &[Rat]) -> (Rat, UPoly) {
    let mut den = Int::ONE;
    for r in v {
        den = den.lcm(r.denom());
    }
    let ints: Vec<Int> = v
        .iter()
        .map(|r| r.numer() * &den.div_exact(r.denom()))
        .collect();
    let (c, u) = UPoly::new(ints).primitive();
    (Rat::new(c, den), u)
}

fn upoly_rats(u: &UPoly) -> Vec<Rat> {
    u.coeffs()
        .iter()
        .map(|c| Rat::from_int(c.clone()))
        .collect()
}

fn rat_of_f64(x: f64) -> Result<Rat, BackSolveError> {
    Rat::from_f64(x).ok_or_else(|| BackSolveError::NonFinite(x.to_string()))
}

impl Target {
    /// A target from numerator and denominator coefficients (ascending
    /// powers of `Omega`), brought into normal form.
    ///
    /// ```
    /// use mms::backsolve::{BackSolveError, Target};
    /// use poly::Rat;
    /// assert_eq!(Target::new(vec![Rat::ONE], vec![]), Err(BackSolveError::ZeroDenominator));
    /// ```
    pub fn new(num: Vec<Rat>, den: Vec<Rat>) -> Result<Target, BackSolveError> {
        let (cn, un) = rat_upoly(&num);
        let (cd, ud) = rat_upoly(&den);
        if ud.is_zero() {
            return Err(BackSolveError::ZeroDenominator);
        }
        if un.is_zero() {
            return Err(BackSolveError::ZeroNumerator);
        }
        let g = un.gcd(&ud);
        let un = un.div_exact(&g).expect("the gcd divides");
        let ud = ud.div_exact(&g).expect("the gcd divides");
        // n/d = (cn/cd) * un/ud with un, ud primitive: the reduced fraction
        // p/q of cn/cd gives a content-free pair (p*un, q*ud).
        let c = &cn / &cd;
        let (p, q) = (c.numer().clone(), c.denom().clone());
        let mut num = upoly_rats(&un.scale(&p));
        let mut den = upoly_rats(&ud.scale(&q));
        if den.last().is_some_and(|l| l.signum() < 0) {
            num = num.iter().map(|x| -x).collect();
            den = den.iter().map(|x| -x).collect();
        }
        Ok(Target { num, den })
    }

    /// [`Target::new`] from `f64` coefficients, each converted exactly.
    ///
    /// ```
    /// let t = mms::backsolve::Target::from_f64(&[0.5], &[1.0, 0.25])?;
    /// assert_eq!(t.eval_f64(2.0), 0.5 / 1.5);
    /// # Ok::<(), mms::backsolve::BackSolveError>(())
    /// ```
    pub fn from_f64(num: &[f64], den: &[f64]) -> Result<Target, BackSolveError> {
        let n = num
            .iter()
            .map(|&x| rat_of_f64(x))
            .collect::<Result<_, _>>()?;
        let d = den
            .iter()
            .map(|&x| rat_of_f64(x))
            .collect::<Result<_, _>>()?;
        Target::new(n, d)
    }

    /// The undamped inertance of `model` at exact positive parameter values,
    /// given in the order of [`Model::undamped_parameters`].
    ///
    /// ```
    /// use mms::{backsolve::Target, Model};
    /// let a2 = Model::from_id("A2")?;
    /// let v: Vec<poly::Rat> = [1, 1, 2, 100, 100].iter().map(|&x| x.into()).collect();
    /// let t = Target::from_model(&a2, &v)?;
    /// assert_eq!(t.eval_f64(0.0), 1.0 / 4.0); // rigid body: 1/(m1 + m2 + m3)
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_model(model: &Model, values: &[Rat]) -> Result<Target, BackSolveError> {
        let names = model.undamped_parameters();
        if names.len() != values.len() {
            return Err(BackSolveError::ParameterCount {
                model: model.name(),
                expected: names.len(),
                got: values.len(),
            });
        }
        for (n, v) in names.iter().zip(values) {
            if v.signum() <= 0 {
                return Err(BackSolveError::NonPositiveParameter {
                    name: n.clone(),
                    value: v.to_string(),
                });
            }
        }
        let point: BTreeMap<String, Rat> =
            names.iter().cloned().zip(values.iter().cloned()).collect();
        let tf = model.undamped_tf();
        let coeffs = |p: &Poly| -> Vec<Rat> {
            p.coeffs_in(OMEGA)
                .iter()
                .map(|c| c.eval(&point).expect("all parameters have values"))
                .collect()
        };
        Target::new(coeffs(&tf.num), coeffs(&tf.den))
    }

    /// [`Target::from_model`] with `f64` values, each converted exactly
    /// (`0.1` becomes the dyadic rational nearest to 0.1).
    ///
    /// ```
    /// use mms::{backsolve::Target, Model};
    /// let c3 = Model::from_id("C3")?;
    /// assert!(Target::from_model_f64(&c3, &[0.04, 0.005, 0.04, 68.0, 59.0]).is_ok());
    /// assert!(Target::from_model_f64(&c3, &[0.04, 0.005, 0.04, 68.0]).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_model_f64(model: &Model, values: &[f64]) -> Result<Target, BackSolveError> {
        let v: Vec<Rat> = values
            .iter()
            .map(|&x| rat_of_f64(x))
            .collect::<Result<_, _>>()?;
        Target::from_model(model, &v)
    }

    /// Numerator coefficients, lowest power first.
    ///
    /// ```
    /// let t = mms::backsolve::Target::from_f64(&[3.0, -1.0], &[2.0, 0.0, 1.0])?;
    /// assert_eq!((t.num().len(), t.den().len()), (2, 3));
    /// assert_eq!((t.num_degree(), t.den_degree()), (1, 2));
    /// assert_eq!(t.num_poly().to_string(), "-Omega + 3");
    /// assert_eq!(t.den_poly().to_string(), "Omega^2 + 2");
    /// # Ok::<(), mms::backsolve::BackSolveError>(())
    /// ```
    pub fn num(&self) -> &[Rat] {
        &self.num
    }

    /// Denominator coefficients, lowest power first.
    pub fn den(&self) -> &[Rat] {
        &self.den
    }

    /// Degree of the numerator in `Omega`.
    pub fn num_degree(&self) -> usize {
        self.num.len() - 1
    }

    /// Degree of the denominator in `Omega`.
    pub fn den_degree(&self) -> usize {
        self.den.len() - 1
    }

    /// Exact value at `Omega = omega`; `None` at a pole.
    ///
    /// ```
    /// let t = mms::backsolve::Target::from_f64(&[1.0], &[-1.0, 1.0])?;
    /// assert_eq!(t.eval(&2.into()), Some(1.into()));
    /// assert_eq!(t.eval(&1.into()), None);
    /// # Ok::<(), mms::backsolve::BackSolveError>(())
    /// ```
    pub fn eval(&self, omega: &Rat) -> Option<Rat> {
        let d = horner(&self.den, omega);
        (!d.is_zero()).then(|| &horner(&self.num, omega) / &d)
    }

    /// Floating-point value at `Omega = omega` (infinite at a pole).
    ///
    /// ```
    /// let t = mms::backsolve::Target::from_f64(&[2.0], &[4.0])?;
    /// assert_eq!(t.eval_f64(10.0), 0.5);
    /// # Ok::<(), mms::backsolve::BackSolveError>(())
    /// ```
    pub fn eval_f64(&self, omega: f64) -> f64 {
        let h = |c: &[Rat]| c.iter().rev().fold(0.0, |acc, x| acc * omega + x.to_f64());
        h(&self.num) / h(&self.den)
    }

    fn poly(c: &[Rat]) -> Poly {
        let cs: Vec<Poly> = c.iter().map(|x| Poly::constant(x.clone())).collect();
        Poly::from_coeffs_in(OMEGA, &cs)
    }

    /// The numerator as a polynomial in `Omega`.
    pub fn num_poly(&self) -> Poly {
        Target::poly(&self.num)
    }

    /// The denominator as a polynomial in `Omega`.
    pub fn den_poly(&self) -> Poly {
        Target::poly(&self.den)
    }
}

fn horner(c: &[Rat], x: &Rat) -> Rat {
    c.iter().rev().fold(Rat::ZERO, |acc, a| &(&acc * x) + a)
}

impl fmt::Display for Target {
    /// `(num) / (den)` in `Omega`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}) / ({})", self.num_poly(), self.den_poly())
    }
}

// ---------------------------------------------------------------------------
// Results

/// A real algebraic number: the root of `poly` (irreducible over Q, integer
/// coefficients) in the isolating interval `[lo, hi]` (`lo == hi` for a
/// rational number), with a floating-point approximation.
///
/// ```
/// use mms::backsolve::AlgebraicNumber;
/// let half = AlgebraicNumber::rational(&"1/2".parse()?);
/// assert_eq!(half.value, 0.5);
/// assert_eq!(half.poly.to_text("x"), "2*x - 1");
/// assert!(half.is_rational());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct AlgebraicNumber {
    /// The minimal polynomial (primitive, positive leading coefficient).
    pub poly: UPoly,
    /// Lower end of the isolating interval.
    pub lo: Rat,
    /// Upper end of the isolating interval.
    pub hi: Rat,
    /// The value as `f64`.
    pub value: f64,
}

impl AlgebraicNumber {
    /// The rational number `r`.
    pub fn rational(r: &Rat) -> AlgebraicNumber {
        AlgebraicNumber {
            poly: UPoly::linear_root(r).primitive_part(),
            lo: r.clone(),
            hi: r.clone(),
            value: r.to_f64(),
        }
    }

    /// True when the number is rational (its minimal polynomial is linear).
    ///
    /// ```
    /// use mms::backsolve::AlgebraicNumber;
    /// let x = AlgebraicNumber::rational(&poly::Rat::from(3));
    /// assert_eq!((x.is_rational(), x.as_rational()), (true, Some(3.into())));
    /// ```
    pub fn is_rational(&self) -> bool {
        self.poly.degree() == Some(1)
    }

    /// The exact value when rational.
    pub fn as_rational(&self) -> Option<Rat> {
        if !self.is_rational() {
            return None;
        }
        let c = self.poly.coeffs();
        Some(-&(&Rat::from_int(c[0].clone()) / &Rat::from_int(c[1].clone())))
    }

    fn from_root(poly: &UPoly, root: &RealRoot) -> AlgebraicNumber {
        let mut r = root.clone();
        let w = refine_width(&r);
        let _ = r.refine(poly, &w);
        AlgebraicNumber {
            poly: poly.clone(),
            lo: r.lo.clone(),
            hi: r.hi.clone(),
            value: r.to_f64(),
        }
    }
}

impl fmt::Display for AlgebraicNumber {
    /// The value, followed by the exact description unless rational.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(r) = self.as_rational() {
            return write!(f, "{}", r);
        }
        write!(
            f,
            "{} (root of {} in [{}, {}])",
            self.value,
            self.poly.to_text("x"),
            self.lo.to_f64(),
            self.hi.to_f64()
        )
    }
}

/// Width to which an isolating interval is refined for an `f64` value: about
/// 2^-60 relative to the magnitude of the root.
fn refine_width(r: &RealRoot) -> Rat {
    let mag = r.lo.abs().max(r.hi.abs());
    let base = if mag.is_zero() { Rat::ONE } else { mag };
    &base * &Rat::new(Int::ONE, Int::from(2).pow(60))
}

/// One positive parameter set reproducing the target.
///
/// ```
/// use mms::{backsolve::{back_solve, Target}, Model};
/// let a1 = Model::from_id("A1")?;
/// let t = Target::from_model_f64(&a1, &[1.0, 2.0, 3.0, 4.0, 5.0])?;
/// let r = back_solve(&a1, &t)?;
/// let s = &r.points()[0];
/// assert_eq!(s.get("c23"), Some(5.0));
/// assert!(s.exact[0].is_rational());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Parameter names ([`Model::undamped_parameters`]).
    pub parameters: Vec<String>,
    /// The values, in the order of `parameters`.
    pub values: Vec<f64>,
    /// Exact values: minimal polynomial and isolating interval of each.
    pub exact: Vec<AlgebraicNumber>,
}

impl Solution {
    /// The value of the parameter `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .position(|p| p == name)
            .map(|i| self.values[i])
    }
}

impl fmt::Display for Solution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parts: Vec<String> = self
            .parameters
            .iter()
            .zip(&self.values)
            .map(|(n, v)| format!("{n} = {v:.6e}"))
            .collect();
        f.write_str(&parts.join(", "))
    }
}

/// A rational function `num/den` of the free parameters of a [`Family`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RationalFunction {
    /// Numerator.
    pub num: Poly,
    /// Denominator (primitive, positive leading coefficient).
    pub den: Poly,
}

impl RationalFunction {
    /// Exact value; `None` where the denominator vanishes or a variable is
    /// missing.
    ///
    /// ```
    /// use mms::backsolve::RationalFunction;
    /// let f = RationalFunction { num: "t".parse()?, den: "2*t - 1".parse()? };
    /// let at = [("t".to_string(), poly::Rat::from(1))].into_iter().collect();
    /// assert_eq!(f.eval(&at), Some(1.into()));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn eval(&self, point: &BTreeMap<String, Rat>) -> Option<Rat> {
        let d = self.den.eval(point).ok()?;
        if d.is_zero() {
            return None;
        }
        Some(&self.num.eval(point).ok()? / &d)
    }

    /// Floating-point value (NaN or infinite where undefined).
    ///
    /// ```
    /// use mms::backsolve::RationalFunction;
    /// let f = RationalFunction { num: "1".parse()?, den: "t".parse()? };
    /// let at = [("t".to_string(), 4.0)].into_iter().collect();
    /// assert_eq!(f.eval_f64(&at), 0.25);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn eval_f64(&self, point: &BTreeMap<String, f64>) -> f64 {
        match (self.num.eval_f64(point), self.den.eval_f64(point)) {
            (Ok(n), Ok(d)) => n / d,
            _ => f64::NAN,
        }
    }
}

impl fmt::Display for RationalFunction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den.as_constant().is_some_and(|c| c.is_one()) {
            write!(f, "{}", self.num)
        } else {
            write!(f, "({}) / ({})", self.num, self.den)
        }
    }
}

/// An open interval of a free parameter; `hi == None` means `+infinity`.
/// The lower end is `0` or an algebraic number.
///
/// ```
/// use mms::backsolve::{AlgebraicNumber, Interval};
/// let i = Interval { lo: AlgebraicNumber::rational(&1.into()), hi: None, branches: 1 };
/// assert!(i.contains_f64(2.0) && !i.contains_f64(1.0));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Interval {
    /// Lower end (excluded).
    pub lo: AlgebraicNumber,
    /// Upper end (excluded); `None` for `+infinity`.
    pub hi: Option<AlgebraicNumber>,
    /// Number of members for each value inside: 1 for a rational family,
    /// the number of admissible roots of [`Dependent::poly`] otherwise.
    pub branches: usize,
}

impl Interval {
    /// True when `x` lies strictly inside (by the `f64` ends).
    pub fn contains_f64(&self, x: f64) -> bool {
        x > self.lo.value && self.hi.as_ref().is_none_or(|h| x < h.value)
    }
}

impl fmt::Display for Interval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.hi {
            Some(h) => write!(f, "({}, {})", self.lo.value, h.value)?,
            None => write!(f, "({}, inf)", self.lo.value)?,
        }
        if self.branches != 1 {
            write!(f, " ({} branches)", self.branches)?;
        }
        Ok(())
    }
}

/// A positive-dimensional set of parameter sets that all reproduce the
/// target: the parameters in `free` are chosen freely (subject to
/// positivity), every parameter is a rational function of them.
///
/// ```
/// use mms::{backsolve::{back_solve, BackSolution, Target}, Model};
/// let a2 = Model::from_id("A2")?;
/// let t = Target::from_model_f64(&a2, &[0.01, 0.01, 0.02, 100.0, 100.0])?;
/// let BackSolution::Families { families, .. } = back_solve(&a2, &t)? else { panic!() };
/// let fam = &families[0];
/// assert_eq!(fam.dimension(), 1);
/// // The generating parameters are a member of the family.
/// let i = fam.parameters.iter().position(|p| p == &fam.free[0]).unwrap();
/// let gen = [0.01, 0.01, 0.02, 100.0, 100.0];
/// let member = fam.member_f64(&[gen[i]]).unwrap();
/// for (a, b) in member.iter().zip(gen) {
///     assert!((a - b).abs() <= 1e-9 * b);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Family {
    /// Parameter names ([`Model::undamped_parameters`]).
    pub parameters: Vec<String>,
    /// The free parameters (a subset of `parameters`).
    pub free: Vec<String>,
    /// For a family on a curve: one more parameter, tied to the free one by
    /// a polynomial equation (none of the parameters is then a rational
    /// function of a single other one, e.g. C2 and C4).
    pub dependent: Option<Dependent>,
    /// Every parameter as a rational function of the free ones and of the
    /// dependent one (each of those is itself), in the order of `parameters`.
    pub expressions: Vec<RationalFunction>,
    /// For one free parameter: the open intervals of it on which members
    /// with every parameter positive exist (exact ends). Empty for more
    /// free parameters.
    pub intervals: Vec<Interval>,
    /// Some members (values in the order of `parameters`), each checked
    /// exactly to be positive.
    pub samples: Vec<Vec<f64>>,
}

/// The dependent parameter of a family on a curve: `var` is a root of
/// `poly`, a polynomial in `var` and the free parameter.
///
/// ```
/// use mms::{backsolve::{back_solve, Target}, Model};
/// // C2 reproduces its own inertance on a curve: no parameter is a rational
/// // function of a single other one.
/// let c2 = Model::from_id("C2")?;
/// let v = [0.011, 0.0044, 0.030, 190.0, 96.0];
/// let t = Target::from_model_f64(&c2, &v)?;
/// let r = back_solve(&c2, &t)?;
/// let fam = &r.families()[0];
/// let dep = fam.dependent.as_ref().unwrap();
/// assert_eq!(fam.dimension(), 1);
/// assert!(dep.poly.degree(&dep.var) >= 2);
/// let exact: Vec<poly::Rat> = v.iter().map(|&x| poly::Rat::from_f64(x).unwrap()).collect();
/// assert!(fam.contains(&exact));
/// assert!(!fam.members_f64(&[v[fam.parameters.iter().position(|p| p == &fam.free[0]).unwrap()]]).is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Dependent {
    /// The parameter.
    pub var: String,
    /// The irreducible polynomial tying it to the free parameter.
    pub poly: Poly,
}

impl Family {
    /// Number of free parameters.
    pub fn dimension(&self) -> usize {
        self.free.len()
    }

    /// The member with the free parameters at `free` (in the order of
    /// [`Family::free`]), exactly; `None` when some parameter would not be
    /// positive or is undefined there, and for a family on a curve (see
    /// [`Family::members_f64`] and [`Family::contains`]).
    pub fn member(&self, free: &[Rat]) -> Option<Vec<Rat>> {
        if free.len() != self.free.len() || self.dependent.is_some() {
            return None;
        }
        let point: BTreeMap<String, Rat> = self
            .free
            .iter()
            .cloned()
            .zip(free.iter().cloned())
            .collect();
        let v: Vec<Rat> = self
            .expressions
            .iter()
            .map(|e| e.eval(&point))
            .collect::<Option<_>>()?;
        v.iter().all(|x| x.signum() > 0).then_some(v)
    }

    /// [`Family::member`] at `f64` free values (converted exactly).
    pub fn member_f64(&self, free: &[f64]) -> Option<Vec<f64>> {
        let f: Vec<Rat> = free
            .iter()
            .map(|&x| Rat::from_f64(x))
            .collect::<Option<_>>()?;
        Some(self.member(&f)?.iter().map(Rat::to_f64).collect())
    }

    /// All members with the free parameters at `free` and every parameter
    /// positive, as `f64` values: one for a rational family, one per
    /// admissible root of the dependent parameter for a family on a curve.
    pub fn members_f64(&self, free: &[f64]) -> Vec<Vec<f64>> {
        if self.dependent.is_none() {
            return self.member_f64(free).into_iter().collect();
        }
        match free.first().and_then(|&x| Rat::from_f64(x)) {
            Some(ts) if free.len() == 1 => curve_members(self, &ts),
            _ => Vec::new(),
        }
    }

    /// Exact membership of a parameter point (values in the order of
    /// [`Family::parameters`]): every expression, evaluated at the point's
    /// free (and dependent) parameters, gives the point's value, all values
    /// are positive, and the point lies on the curve of a curve family.
    pub fn contains(&self, point: &[Rat]) -> bool {
        if point.len() != self.parameters.len() || point.iter().any(|v| v.signum() <= 0) {
            return false;
        }
        let at: BTreeMap<String, Rat> = self
            .parameters
            .iter()
            .cloned()
            .zip(point.iter().cloned())
            .collect();
        if let Some(dep) = &self.dependent {
            if !dep.poly.eval(&at).is_ok_and(|v| v.is_zero()) {
                return false;
            }
        }
        self.expressions
            .iter()
            .zip(point)
            .all(|(e, v)| e.eval(&at).as_ref() == Some(v))
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "family of dimension {}, free: {}",
            self.dimension(),
            self.free.join(", ")
        )?;
        if let Some(d) = &self.dependent {
            writeln!(f, "  {} is a root of {} = 0", d.var, d.poly)?;
        }
        for (p, e) in self.parameters.iter().zip(&self.expressions) {
            writeln!(f, "  {p} = {e}")?;
        }
        for i in &self.intervals {
            writeln!(f, "  {} in {i}", self.free[0])?;
        }
        Ok(())
    }
}

/// Why no positive parameter set reproduces the target.
///
/// ```
/// use mms::{backsolve::{back_solve, NoSolution, Target}, Model};
/// // All coefficients positive: a chain's denominator alternates in sign.
/// let t = Target::from_f64(&[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0])?;
/// let r = back_solve(&Model::from_id("A1")?, &t)?;
/// assert!(matches!(r.no_solution(), Some(NoSolution::SignPattern { .. })));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum NoSolution {
    /// The degrees of the target cannot be those of the structure: its
    /// relative degree `deg den - deg num` is fixed on positive parameters and
    /// a reduced target cannot have a higher degree than the structure.
    Degree {
        /// `(deg num, deg den)` of the structure.
        structure: (usize, usize),
        /// `(deg num, deg den)` of the target (lowest terms).
        target: (usize, usize),
    },
    /// A coefficient whose sign is fixed on positive parameters has another
    /// sign (or is not zero although the structure has no such term).
    SignPattern {
        /// Which coefficient, e.g. `Num Omega^1`.
        coefficient: String,
        /// Its sign for every positive parameter set (0: absent).
        structure_sign: i32,
        /// Its sign in the target (with the denominator's leading coefficient positive).
        target_sign: i32,
    },
    /// The target violates an identity satisfied by the coefficients of every
    /// transfer function of the structure ([`invariant_relations`]).
    ViolatedRelation {
        /// The relation, in `n0, n1, ..` (numerator coefficients of
        /// `Omega^0, Omega^1, ..`) and `d0, d1, ..` (denominator).
        relation: Poly,
        /// Its value at the target (normal form of [`Target`]).
        value: Rat,
        /// The size of the violation independent of scaling: `|value|`
        /// divided by the sum of the absolute values of the relation's terms
        /// at the target (0 when satisfied, at most 1).
        relative: f64,
    },
    /// Real solutions of the eliminated system exist but each has a
    /// parameter `<= 0` (values in the order of the parameters; solutions
    /// cut off earlier by a factor that cannot vanish for positive parameters
    /// are not listed).
    NotPositive {
        /// The real candidates found.
        candidates: Vec<Vec<f64>>,
    },
    /// Every branch of the elimination ends in a polynomial that cannot
    /// vanish for positive parameters (or in no real root).
    Contradiction,
}

impl fmt::Display for NoSolution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NoSolution::Degree { structure, target } => write!(
                f,
                "degrees (num, den) = {target:?} of the target are impossible for a structure of degrees {structure:?}"
            ),
            NoSolution::SignPattern {
                coefficient,
                structure_sign,
                target_sign,
            } => write!(
                f,
                "coefficient {coefficient} has sign {target_sign} in the target but {structure_sign} for every positive parameter set"
            ),
            NoSolution::ViolatedRelation {
                relation, relative, ..
            } => write!(
                f,
                "the target violates the invariant relation {relation} = 0 of the structure \
                 (relative violation {relative:.3e})"
            ),
            NoSolution::NotPositive { candidates } => write!(
                f,
                "{} real solution(s), none with all parameters positive",
                candidates.len()
            ),
            NoSolution::Contradiction => f.write_str(
                "the coefficient equations have no solution with all parameters positive",
            ),
        }
    }
}

/// All positive parameter sets of a structure reproducing a [`Target`].
///
/// ```
/// use mms::{backsolve::{back_solve, Target}, Model};
/// let b1 = Model::from_id("B1")?;
/// let t = Target::from_model_f64(&b1, &[0.04, 0.005, 0.035, 53.5, 58.9])?;
/// let r = back_solve(&b1, &t)?;
/// assert_eq!(r.points().len(), 2); // B1 is identifiable only locally (Tab. 7)
/// assert!(r.families().is_empty() && r.no_solution().is_none());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum BackSolution {
    /// Finitely many (at least one), sorted by their values.
    Points(Vec<Solution>),
    /// At least one positive-dimensional family, and possibly isolated
    /// points besides.
    Families {
        /// The families.
        families: Vec<Family>,
        /// Isolated solutions not produced as part of a family.
        isolated: Vec<Solution>,
    },
    /// None, with the reason.
    NoSolution(NoSolution),
}

impl BackSolution {
    /// The isolated solutions (empty for [`BackSolution::NoSolution`]).
    pub fn points(&self) -> &[Solution] {
        match self {
            BackSolution::Points(p) => p,
            BackSolution::Families { isolated, .. } => isolated,
            BackSolution::NoSolution(_) => &[],
        }
    }

    /// The families (empty unless [`BackSolution::Families`]).
    pub fn families(&self) -> &[Family] {
        match self {
            BackSolution::Families { families, .. } => families,
            _ => &[],
        }
    }

    /// The reason when there is no solution.
    pub fn no_solution(&self) -> Option<&NoSolution> {
        match self {
            BackSolution::NoSolution(r) => Some(r),
            _ => None,
        }
    }
}

impl fmt::Display for BackSolution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for s in self.points() {
            writeln!(f, "{s}")?;
        }
        for fam in self.families() {
            write!(f, "{fam}")?;
        }
        if let Some(r) = self.no_solution() {
            writeln!(f, "no solution: {r}")?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// The structure: coefficient polynomials of the model's inertance

struct Structure {
    params: Vec<String>,
    /// Coefficients of `Omega^k` of the inertance numerator (index `k`).
    num: Vec<Poly>,
    /// Coefficients of `Omega^k` of the denominator.
    den: Vec<Poly>,
}

impl Structure {
    fn new(model: &Model) -> Structure {
        let tf = model.undamped_tf();
        Structure {
            params: model.undamped_parameters(),
            num: tf.num.coeffs_in(OMEGA),
            den: tf.den.coeffs_in(OMEGA),
        }
    }

    /// Named coefficient slots `(name, polynomial)` of the non-zero
    /// coefficients: `n{k}` then `d{k}`.
    fn slots(&self) -> Vec<(String, Poly)> {
        let mut v = Vec::new();
        for (k, p) in self.num.iter().enumerate() {
            if !p.is_zero() {
                v.push((format!("n{k}"), p.clone()));
            }
        }
        for (k, p) in self.den.iter().enumerate() {
            if !p.is_zero() {
                v.push((format!("d{k}"), p.clone()));
            }
        }
        v
    }
}

// ---------------------------------------------------------------------------
// Exact linear algebra over Q

/// A basis of the null space of the matrix `rows` (`ncols` columns).
fn nullspace(mut rows: Vec<Vec<Rat>>, ncols: usize) -> Vec<Vec<Rat>> {
    let mut pivots: Vec<usize> = Vec::new();
    let mut r = 0;
    for c in 0..ncols {
        let Some(p) = (r..rows.len()).find(|&i| !rows[i][c].is_zero()) else {
            continue;
        };
        rows.swap(r, p);
        let inv = rows[r][c].recip();
        for x in rows[r].iter_mut() {
            *x = &*x * &inv;
        }
        let pivot_row = rows[r].clone();
        for (i, row) in rows.iter_mut().enumerate() {
            if i != r && !row[c].is_zero() {
                let f = row[c].clone();
                for (x, y) in row.iter_mut().zip(&pivot_row) {
                    if !y.is_zero() {
                        *x = &*x - &(&f * y);
                    }
                }
            }
        }
        pivots.push(c);
        r += 1;
        if r == rows.len() {
            break;
        }
    }
    let mut basis = Vec::new();
    for free in (0..ncols).filter(|c| !pivots.contains(c)) {
        let mut v = vec![Rat::ZERO; ncols];
        v[free] = Rat::ONE;
        for (i, &pc) in pivots.iter().enumerate() {
            v[pc] = -&rows[i][free];
        }
        basis.push(v);
    }
    basis
}

/// Rank of a matrix over Q.
fn rank(rows: Vec<Vec<Rat>>, ncols: usize) -> usize {
    ncols - nullspace(rows, ncols).len()
}

// ---------------------------------------------------------------------------
// Invariant relations (implicitization by exact interpolation)

/// All monomials (exponent vectors) of total degree `deg` in `n` variables.
fn monomials(n: usize, deg: u32) -> Vec<Vec<u32>> {
    if n == 0 {
        return if deg == 0 { vec![vec![]] } else { vec![] };
    }
    let mut out = Vec::new();
    for e in (0..=deg).rev() {
        for mut rest in monomials(n - 1, deg - e) {
            rest.insert(0, e);
            out.push(rest);
        }
    }
    out
}

fn binomial(n: usize, k: usize) -> usize {
    (0..k).fold(1usize, |acc, i| acc.saturating_mul(n - i) / (i + 1))
}

const PRIMES: [u64; 2] = [(1 << 61) - 1, (1 << 62) - 57];

fn mulmod(a: u64, b: u64, p: u64) -> u64 {
    ((a as u128 * b as u128) % p as u128) as u64
}

fn invmod(a: u64, p: u64) -> u64 {
    // Fermat: a^(p-2).
    let (mut base, mut e, mut r) = (a % p, p - 2, 1u64);
    while e > 0 {
        if e & 1 == 1 {
            r = mulmod(r, base, p);
        }
        base = mulmod(base, base, p);
        e >>= 1;
    }
    r
}

/// Null space basis modulo the prime `p`, in reduced echelon form: one
/// vector per non-pivot column, 1 there and 0 at the other non-pivot
/// columns. Returns the non-pivot columns and the vectors.
fn nullspace_mod(mut rows: Vec<Vec<u64>>, ncols: usize, p: u64) -> (Vec<usize>, Vec<Vec<u64>>) {
    let mut pivots: Vec<usize> = Vec::new();
    let mut r = 0;
    for c in 0..ncols {
        let Some(k) = (r..rows.len()).find(|&i| rows[i][c] != 0) else {
            continue;
        };
        rows.swap(r, k);
        let inv = invmod(rows[r][c], p);
        for x in rows[r].iter_mut() {
            *x = mulmod(*x, inv, p);
        }
        let pivot_row = rows[r].clone();
        for (i, row) in rows.iter_mut().enumerate() {
            if i != r && row[c] != 0 {
                let f = row[c];
                for (x, &y) in row.iter_mut().zip(&pivot_row) {
                    *x = (*x + p - mulmod(f, y, p)) % p;
                }
            }
        }
        pivots.push(c);
        r += 1;
        if r == rows.len() {
            break;
        }
    }
    let free: Vec<usize> = (0..ncols).filter(|c| !pivots.contains(c)).collect();
    let basis = free
        .iter()
        .map(|&fc| {
            let mut v = vec![0u64; ncols];
            v[fc] = 1;
            for (i, &pc) in pivots.iter().enumerate() {
                v[pc] = (p - rows[i][fc]) % p;
            }
            v
        })
        .collect();
    (free, basis)
}

/// The rational `r/s` with `r = s*u (mod m)` and `|r|, s < sqrt(m/2)`, if any.
fn rational_reconstruction(u: &Int, m: &Int) -> Option<Rat> {
    let bound = m.div_mod_floor(&Int::from(2)).0.isqrt();
    let (mut r0, mut r1) = (m.clone(), u.clone());
    let (mut s0, mut s1) = (Int::ZERO, Int::ONE);
    while r1 >= bound {
        let (q, rem) = r0.div_rem(&r1);
        r0 = std::mem::replace(&mut r1, rem);
        let s = &s0 - &(&q * &s1);
        s0 = std::mem::replace(&mut s1, s);
    }
    if s1.is_zero() || s1.abs() >= bound {
        return None;
    }
    Some(Rat::new(r1, s1))
}

/// The lowest-degree homogeneous polynomial relations `R(n0, .., d0, ..)`
/// that hold identically for the coefficients of the structure's inertance
/// (`R(num_S(p), den_S(p)) == 0` for all parameters `p`), verified
/// symbolically. Empty when the coefficients are algebraically independent
/// up to the common scale (the structure's image is not a hypersurface).
///
/// The candidates are the null space of the matrix of all monomials of a
/// degree at random integer points, computed modulo two word-size primes
/// and lifted by Chinese remaindering and rational reconstruction; only the
/// symbolic check decides.
fn relations(s: &Structure, limits: &Limits) -> Vec<Poly> {
    let slots = s.slots();
    let k = slots.len();
    let mut rng = XorShift::new(0x5eed_ba5e);
    let point = |rng: &mut XorShift| -> BTreeMap<String, Rat> {
        s.params
            .iter()
            .map(|p| (p.clone(), Rat::from((rng.next_u64() % 1000 + 2) as i64)))
            .collect()
    };
    // Dimension of the cone over the image: rank of the Jacobian together
    // with the coefficient vector itself (the scaling direction).
    let p0 = point(&mut rng);
    let cols: Vec<Vec<Rat>> = s
        .params
        .iter()
        .map(|x| {
            slots
                .iter()
                .map(|(_, f)| f.derivative(x).eval(&p0).expect("all parameters set"))
                .collect()
        })
        .chain(std::iter::once(
            slots
                .iter()
                .map(|(_, f)| f.eval(&p0).expect("all parameters set"))
                .collect(),
        ))
        .collect();
    if rank(cols, k) >= k {
        return Vec::new();
    }
    let names: Vec<String> = slots.iter().map(|(n, _)| n.clone()).collect();
    for deg in 1..=8u32 {
        let count = binomial(k + deg as usize - 1, deg as usize);
        if count > limits.max_relation_monomials {
            break;
        }
        let monos = monomials(k, deg);
        let values: Vec<Vec<Int>> = (0..count + 8)
            .map(|_| {
                let p = point(&mut rng);
                slots
                    .iter()
                    .map(|(_, f)| f.eval(&p).expect("set").numer().clone())
                    .collect()
            })
            .collect();
        let mut lifted: Option<(Vec<usize>, Vec<Vec<Int>>, Int)> = None;
        for &pr in &PRIMES {
            let rows: Vec<Vec<u64>> = values
                .iter()
                .map(|v| {
                    let vm: Vec<u64> = v.iter().map(|x| x.rem_u64(pr)).collect();
                    monos
                        .iter()
                        .map(|m| {
                            m.iter().zip(&vm).fold(1u64, |acc, (&e, &x)| {
                                (0..e).fold(acc, |a, _| mulmod(a, x, pr))
                            })
                        })
                        .collect()
                })
                .collect();
            let (free, basis) = nullspace_mod(rows, count, pr);
            let basis: Vec<Vec<Int>> = basis
                .into_iter()
                .map(|v| v.into_iter().map(Int::from).collect())
                .collect();
            let prm = Int::from(pr);
            lifted = Some(match lifted {
                None => (free, basis, prm),
                Some((f0, b0, m0)) => {
                    if f0 != free {
                        // An unlucky prime: keep the first image only.
                        (f0, b0, m0)
                    } else {
                        // CRT: x = a (mod m0), x = b (mod pr).
                        let inv = Int::from(invmod(m0.rem_u64(pr), pr));
                        let comb: Vec<Vec<Int>> = b0
                            .iter()
                            .zip(&basis)
                            .map(|(va, vb)| {
                                va.iter()
                                    .zip(vb)
                                    .map(|(a, b)| {
                                        let diff = (b - a).div_mod_floor(&prm).1;
                                        let t = (&diff * &inv).div_mod_floor(&prm).1;
                                        a + &(&m0 * &t)
                                    })
                                    .collect()
                            })
                            .collect();
                        (free, comb, &m0 * &prm)
                    }
                }
            });
        }
        let Some((_, basis, modulus)) = lifted else {
            continue;
        };
        if basis.is_empty() {
            continue;
        }
        let mut out = Vec::new();
        for v in basis {
            let coefs: Option<Vec<Rat>> = v
                .iter()
                .map(|x| rational_reconstruction(x, &modulus))
                .collect();
            let Some(coefs) = coefs else { continue };
            let terms: Vec<poly::Term> = monos
                .iter()
                .zip(&coefs)
                .filter(|(_, c)| !c.is_zero())
                .map(|(m, c)| poly::Term {
                    exps: m.clone(),
                    coef: c.clone(),
                })
                .collect();
            let r = Poly::from_terms(&names, terms).primitive_part();
            // Symbolic verification: substitute the coefficient polynomials.
            let mut sub = r.clone();
            for (n, f) in &slots {
                sub = sub.subs_poly(n, f);
            }
            if sub.is_zero() {
                out.push(r);
            }
        }
        if out.is_empty() {
            continue;
        }
        out.sort_by_key(|p| p.to_string());
        return out;
    }
    Vec::new()
}

/// The invariant relations of a structure: the homogeneous polynomials
/// `R(n0, n1, .., d0, d1, ..)` of lowest degree with `R = 0` for the
/// inertance coefficients of *every* parameter set (`nk`, `dk`: coefficient
/// of `Omega^k` in the numerator resp. denominator of
/// [`Model::undamped_tf`]). A target violating one cannot be reproduced.
///
/// They exist exactly when the model has fewer determinable parameters than
/// non-constant moment invariants (Tab. 5: B2, C2, C4); they are found by
/// exact interpolation at integer points and verified by substituting the
/// symbolic coefficients.
///
/// ```
/// use mms::{backsolve::invariant_relations, Model};
/// let c2 = invariant_relations(&Model::from_id("C2")?);
/// // den = m3*num + c12*m3^2*Omega: Den(0)/Num(0) = lc(Den)/lc(Num) = m3
/// assert_eq!(c2.len(), 1);
/// assert_eq!(c2[0].to_string(), "d0*n2 - d2*n0");
/// assert!(invariant_relations(&Model::from_id("A1")?).is_empty());
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn invariant_relations(model: &Model) -> Vec<Poly> {
    relations(&Structure::new(model), &Limits::default())
}

// ---------------------------------------------------------------------------
// Dense univariate arithmetic over Q, and number fields Q[t]/(f)

fn q_trim(mut v: Vec<Rat>) -> Vec<Rat> {
    while v.last().is_some_and(Rat::is_zero) {
        v.pop();
    }
    v
}

fn q_sub(a: &[Rat], b: &[Rat]) -> Vec<Rat> {
    let n = a.len().max(b.len());
    q_trim(
        (0..n)
            .map(|i| {
                let x = a.get(i).cloned().unwrap_or(Rat::ZERO);
                let y = b.get(i).cloned().unwrap_or(Rat::ZERO);
                &x - &y
            })
            .collect(),
    )
}

fn q_mul(a: &[Rat], b: &[Rat]) -> Vec<Rat> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![Rat::ZERO; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        if x.is_zero() {
            continue;
        }
        for (j, y) in b.iter().enumerate() {
            out[i + j] = &out[i + j] + &(x * y);
        }
    }
    q_trim(out)
}

/// Quotient and remainder of `a` by `b != 0`.
fn q_divrem(a: &[Rat], b: &[Rat]) -> (Vec<Rat>, Vec<Rat>) {
    let mut r = q_trim(a.to_vec());
    let db = b.len() - 1;
    let lead_inv = b[db].recip();
    if r.len() <= db {
        return (Vec::new(), r);
    }
    let mut q = vec![Rat::ZERO; r.len() - db];
    while r.len() > db {
        let k = r.len() - 1 - db;
        let c = &r[r.len() - 1] * &lead_inv;
        for (j, y) in b.iter().enumerate() {
            r[k + j] = &r[k + j] - &(&c * y);
        }
        q[k] = c;
        r.pop();
        r = q_trim(r);
    }
    (q_trim(q), r)
}

/// The number field `Q[t]/(f)`, `f` irreducible; elements are coefficient
/// vectors of degree `< deg f`.
struct Field {
    f: Vec<Rat>,
    deadline: std::time::Instant,
}

impl Field {
    fn new(f: &UPoly, budget: &Budget) -> Field {
        Field {
            f: upoly_rats(f),
            deadline: budget.deadline,
        }
    }

    fn check(&self) -> Result<(), BackSolveError> {
        Budget {
            deadline: self.deadline,
        }
        .check()
    }

    fn degree(&self) -> usize {
        self.f.len() - 1
    }

    fn reduce(&self, a: &[Rat]) -> Vec<Rat> {
        q_divrem(a, &self.f).1
    }

    fn mul(&self, a: &[Rat], b: &[Rat]) -> Vec<Rat> {
        self.reduce(&q_mul(a, b))
    }

    /// Inverse by the extended Euclidean algorithm; `None` for zero.
    fn inv(&self, a: &[Rat]) -> Option<Vec<Rat>> {
        let a = self.reduce(a);
        if a.is_empty() {
            return None;
        }
        // Invariant: r_i = s_i * a (mod f).
        let (mut r0, mut r1) = (self.f.clone(), a);
        let (mut s0, mut s1): (Vec<Rat>, Vec<Rat>) = (Vec::new(), vec![Rat::ONE]);
        while r1.len() > 1 {
            let (q, r) = q_divrem(&r0, &r1);
            let s = q_sub(&s0, &q_mul(&q, &s1));
            r0 = std::mem::replace(&mut r1, r);
            s0 = std::mem::replace(&mut s1, s);
        }
        if r1.is_empty() {
            return None; // a shares a factor with f: impossible for f irreducible
        }
        let c = r1[0].recip();
        Some(self.reduce(&s1.iter().map(|x| x * &c).collect::<Vec<_>>()))
    }

    /// Value of a polynomial in the parameters at field elements.
    fn eval(
        &self,
        p: &Poly,
        values: &BTreeMap<String, Vec<Rat>>,
    ) -> Result<Vec<Rat>, BackSolveError> {
        let vars = p.vars();
        let mut acc: Vec<Rat> = Vec::new();
        let mut cache: BTreeMap<(usize, u32), Vec<Rat>> = BTreeMap::new();
        for t in p.terms() {
            self.check()?;
            let mut m = vec![t.coef.clone()];
            for (i, &e) in t.exps.iter().enumerate() {
                if e == 0 {
                    continue;
                }
                let pw = cache
                    .entry((i, e))
                    .or_insert_with(|| {
                        let x = &values[&vars[i]];
                        let mut r = vec![Rat::ONE];
                        for _ in 0..e {
                            r = self.mul(&r, x);
                        }
                        r
                    })
                    .clone();
                m = self.mul(&m, &pw);
            }
            let neg: Vec<Rat> = m.iter().map(|x| -x).collect();
            acc = q_sub(&acc, &neg);
        }
        Ok(acc)
    }

    /// Minimal polynomial over Q of the element `a` (primitive, integer).
    fn min_poly(&self, a: &[Rat]) -> Result<UPoly, BackSolveError> {
        let n = self.degree();
        let mut powers: Vec<Vec<Rat>> = vec![vec![Rat::ONE]];
        loop {
            self.check()?;
            let next = self.mul(powers.last().expect("non-empty"), a);
            powers.push(next);
            let k = powers.len();
            let rows: Vec<Vec<Rat>> = (0..n.max(1))
                .map(|i| {
                    powers
                        .iter()
                        .map(|p| p.get(i).cloned().unwrap_or(Rat::ZERO))
                        .collect()
                })
                .collect();
            let ns = nullspace(rows, k);
            if let Some(v) = ns.into_iter().next() {
                return Ok(rat_upoly(&v).1);
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Exact signs at real algebraic numbers

/// Sign of `u` at the root of the irreducible `f` isolated by `root`, where
/// `u` does not vanish (f does not divide u): the interval is bisected
/// until `u` has no root in it.
fn sign_at_root(u: &UPoly, f: &UPoly, root: &RealRoot) -> i32 {
    if root.is_exact() {
        return u.sign_at(&root.lo);
    }
    let mut r = root.clone();
    loop {
        let (slo, shi) = (u.sign_at(&r.lo), u.sign_at(&r.hi));
        if slo != 0 && slo == shi && count_roots_in(u, &r.lo, &r.hi) == 0 {
            return slo;
        }
        let w = &r.width() * &Rat::new(Int::ONE, Int::from(4));
        if r.refine(f, &w).is_err() || r.is_exact() {
            return u.sign_at(&r.lo);
        }
    }
}

/// A rational approximation of a root of `f`, within `2^-200` relative.
fn approx_root(f: &UPoly, root: &RealRoot) -> Rat {
    let mut r = root.clone();
    let mag = r.lo.abs().max(r.hi.abs());
    let base = if mag.is_zero() { Rat::ONE } else { mag };
    let w = &base * &Rat::new(Int::ONE, Int::from(2).pow(200));
    let _ = r.refine(f, &w);
    r.midpoint()
}

/// The root of the irreducible `g` nearest to `x`, as an [`AlgebraicNumber`].
fn nearest_root(g: &UPoly, x: &Rat) -> AlgebraicNumber {
    if g.degree() == Some(1) {
        let c = g.coeffs();
        return AlgebraicNumber::rational(
            &-&(&Rat::from_int(c[0].clone()) / &Rat::from_int(c[1].clone())),
        );
    }
    let roots = real_roots(g);
    let mut best: Option<(Rat, RealRoot)> = None;
    for mut r in roots {
        let w = refine_width(&r);
        let _ = r.refine(g, &w);
        let d = (&r.midpoint() - x).abs();
        if best.as_ref().is_none_or(|(bd, _)| &d < bd) {
            best = Some((d, r));
        }
    }
    let (_, r) = best.expect("a real root exists: the value is real");
    AlgebraicNumber::from_root(g, &r)
}

// ---------------------------------------------------------------------------
// The elimination

/// A parameter eliminated from the system.
#[derive(Clone, Debug)]
enum Solved {
    /// `var = num/den`, a rational function of the unknowns left.
    Rational { var: String, num: Poly, den: Poly },
    /// `var` is a common root of `polys`, polynomials in `var` and in
    /// unknowns eliminated later (by a resultant step); `hint = (num, den)`
    /// from the first subresultant gives `var = num/den` wherever `den` does
    /// not vanish.
    Algebraic {
        var: String,
        polys: Vec<Poly>,
        hint: Option<(Poly, Poly)>,
    },
}

impl Solved {
    fn var(&self) -> &str {
        match self {
            Solved::Rational { var, .. } | Solved::Algebraic { var, .. } => var,
        }
    }
}

#[derive(Clone, Debug)]
struct Branch {
    eqs: Vec<Poly>,
    unknowns: Vec<String>,
    chain: Vec<Solved>,
}

enum Component {
    /// The last unknown `var` is a root of `poly`.
    Roots {
        var: String,
        poly: UPoly,
        chain: Vec<Solved>,
    },
    /// No equations left: `free` are free.
    Free {
        free: Vec<String>,
        chain: Vec<Solved>,
    },
    /// One irreducible equation `poly(t, y) = 0` in the last two unknowns.
    Curve {
        t: String,
        y: String,
        poly: Poly,
        chain: Vec<Solved>,
    },
}

/// Result of simplifying one equation on the positive orthant.
enum Simplified {
    Zero,
    Infeasible,
    /// The distinct irreducible factors that can vanish.
    Factors(Vec<Poly>),
}

fn simplify(e: &Poly) -> Simplified {
    if e.is_zero() {
        return Simplified::Zero;
    }
    let m = e.monomial_content();
    let e = if m.iter().any(|&x| x > 0) {
        e.div_monomial(&m)
    } else {
        e.clone()
    };
    if e.is_constant() || e.orthant_sign().is_some() {
        return Simplified::Infeasible;
    }
    // Full factorization only for moderate sizes: it removes factors that
    // cannot vanish and splits branches, but is not needed for correctness
    // (every result is verified).
    const FACTOR_TERMS: usize = 150;
    if e.num_terms() > FACTOR_TERMS {
        return Simplified::Factors(vec![e.primitive_part()]);
    }
    let out: Vec<Poly> = factor(&e.primitive_part())
        .factors
        .into_iter()
        .map(|(f, _)| f)
        .filter(|f| !f.is_constant() && f.orthant_sign().is_none())
        .collect();
    if out.is_empty() {
        Simplified::Infeasible
    } else {
        Simplified::Factors(out)
    }
}

/// `a^k * g(x = -b/a)` with `k = deg_x g`, and `k`.
fn subst_linear(g: &Poly, x: &str, a: &Poly, b: &Poly) -> (Poly, u32) {
    if !g.has_var(x) {
        return (g.clone(), 0);
    }
    let cs = g.coeffs_in(x);
    let k = cs.len() - 1;
    let nb = -b;
    let mut pa = vec![Poly::one()];
    let mut pb = vec![Poly::one()];
    for i in 1..=k {
        pa.push(&pa[i - 1] * a);
        pb.push(&pb[i - 1] * &nb);
    }
    let mut acc = Poly::zero();
    for (i, c) in cs.iter().enumerate() {
        if !c.is_zero() {
            acc = &acc + &(&(c * &pb[i]) * &pa[k - i]);
        }
    }
    (acc, k as u32)
}

/// The fraction `num/den` after substituting `x = -b/a`, reduced; `None`
/// when the denominator vanishes identically.
fn subst_fraction(num: &Poly, den: &Poly, x: &str, a: &Poly, b: &Poly) -> Option<(Poly, Poly)> {
    let (p, kp) = subst_linear(num, x, a, b);
    let (q, kq) = subst_linear(den, x, a, b);
    let (n, d) = if kq >= kp {
        (&p * &a.pow(kq - kp), q)
    } else {
        (p, &q * &a.pow(kp - kq))
    };
    (!d.is_zero()).then(|| reduce_fraction(n, d))
}

/// `num/den` with a primitive denominator of positive leading coefficient,
/// in lowest terms when small (the gcd of large multivariate polynomials
/// with huge coefficients is expensive, and a common factor is harmless:
/// it cannot vanish at a solution of the branch, where every divisor of
/// the elimination is non-zero).
fn reduce_fraction(num: Poly, den: Poly) -> (Poly, Poly) {
    const GCD_TERMS: usize = 60;
    if num.num_terms() + den.num_terms() > GCD_TERMS {
        let (nm, dm) = (num.monomial_content(), den.monomial_content());
        let common: Vec<u32> = den
            .vars()
            .iter()
            .zip(&dm)
            .map(|(v, &e)| {
                num.vars()
                    .iter()
                    .position(|w| w == v)
                    .map_or(0, |i| e.min(nm[i]))
            })
            .collect();
        let m = Poly::from_terms(
            den.vars(),
            vec![poly::Term {
                exps: common,
                coef: Rat::ONE,
            }],
        );
        let (num, den) = if m.is_constant() {
            (num, den)
        } else {
            (
                num.div_exact(&m).expect("monomial divides"),
                den.div_exact(&m).expect("monomial divides"),
            )
        };
        let (c, den) = den.primitive();
        return (num.scale(&c.recip()), den);
    }
    let g = poly::gcd(&num, &den);
    let (num, den) = if g.is_constant() {
        (num, den)
    } else {
        (
            num.div_exact(&g).expect("gcd divides"),
            den.div_exact(&g).expect("gcd divides"),
        )
    };
    let (c, den) = den.primitive();
    (num.scale(&c.recip()), den)
}

/// The wall-clock budget of one call ([`Limits::max_time`]).
struct Budget {
    deadline: std::time::Instant,
}

impl Budget {
    fn check(&self) -> Result<(), BackSolveError> {
        if std::time::Instant::now() > self.deadline {
            Err(BackSolveError::LimitExceeded(
                "time budget exhausted (exact arithmetic grew too large)".to_string(),
            ))
        } else {
            Ok(())
        }
    }
}

struct Engine<'a> {
    limits: &'a Limits,
    budget: &'a Budget,
    branches: usize,
    components: Vec<Component>,
}

impl Engine<'_> {
    fn run(&mut self, root: Branch) -> Result<(), BackSolveError> {
        let mut stack = vec![root];
        while let Some(b) = stack.pop() {
            self.branches += 1;
            if self.branches > self.limits.max_branches {
                return Err(BackSolveError::LimitExceeded(format!(
                    "more than {} elimination branches",
                    self.limits.max_branches
                )));
            }
            self.process(b, &mut stack)?;
        }
        Ok(())
    }

    /// Runs one branch until it ends, splits (pushing onto `stack`) or dies.
    fn process(&mut self, mut b: Branch, stack: &mut Vec<Branch>) -> Result<(), BackSolveError> {
        loop {
            self.budget.check()?;
            // 1. Simplify; split on the first equation with several factors.
            let mut eqs: Vec<Poly> = Vec::new();
            let mut split: Option<Vec<Poly>> = None;
            for e in &b.eqs {
                if e.num_terms() > self.limits.max_terms {
                    return Err(BackSolveError::LimitExceeded(format!(
                        "an equation with {} terms (limit {})",
                        e.num_terms(),
                        self.limits.max_terms
                    )));
                }
                match simplify(e) {
                    Simplified::Zero => {}
                    Simplified::Infeasible => return Ok(()),
                    Simplified::Factors(fs) => {
                        if fs.len() > 1 && split.is_none() {
                            split = Some(fs);
                        } else {
                            eqs.push(fs.iter().fold(Poly::one(), |acc, f| &acc * f));
                        }
                    }
                }
            }
            eqs.sort_by_cached_key(|x| (x.num_terms(), x.to_string()));
            eqs.dedup();
            if let Some(fs) = split {
                for f in fs.into_iter().rev() {
                    let mut nb = b.clone();
                    nb.eqs = eqs.clone();
                    nb.eqs.push(f);
                    stack.push(nb);
                }
                return Ok(());
            }
            b.eqs = eqs;
            // 2. Quick positivity test of the parameters solved rationally.
            for c in &b.chain {
                if let Solved::Rational { num, den, .. } = c {
                    if num.is_zero() {
                        return Ok(());
                    }
                    if let (Some(sn), Some(sd)) = (num.orthant_sign(), den.orthant_sign()) {
                        if sn != sd {
                            return Ok(());
                        }
                    }
                }
            }
            // 3. No equation left.
            if b.eqs.is_empty() {
                self.components.push(Component::Free {
                    free: b.unknowns.clone(),
                    chain: b.chain.clone(),
                });
                return Ok(());
            }
            // 4. A linear elimination.
            if let Some((i, x, definite)) = best_linear(&b.eqs) {
                let f = b.eqs.remove(i);
                let cs = f.coeffs_in(&x);
                let (bb, a) = (cs[0].clone(), cs[1].clone());
                if !definite {
                    // a = 0 (and then b = 0) in a branch of its own.
                    let mut zero = b.clone();
                    zero.eqs.push(a.clone());
                    zero.eqs.push(bb.clone());
                    stack.push(zero);
                }
                b.eqs = b
                    .eqs
                    .iter()
                    .map(|g| subst_linear(g, &x, &a, &bb).0)
                    .collect();
                for c in b.chain.iter_mut() {
                    match c {
                        Solved::Rational { num, den, .. } => {
                            // A denominator vanishing on the whole branch:
                            // no solution with it non-zero lies here.
                            let Some(f) = subst_fraction(num, den, &x, &a, &bb) else {
                                return Ok(());
                            };
                            (*num, *den) = f;
                        }
                        Solved::Algebraic { polys, hint, .. } => {
                            for g in polys.iter_mut() {
                                *g = subst_linear(g, &x, &a, &bb).0.primitive_part();
                            }
                            *hint = hint
                                .as_ref()
                                .and_then(|(num, den)| subst_fraction(num, den, &x, &a, &bb));
                        }
                    }
                }
                let (num, den) = reduce_fraction(-&bb, a);
                b.chain.push(Solved::Rational {
                    var: x.clone(),
                    num,
                    den,
                });
                b.unknowns.retain(|u| u != &x);
                continue;
            }
            // 5. Univariate in the last unknown.
            if b.unknowns.len() == 1 && b.eqs.iter().all(|e| e.vars().len() == 1) {
                let t = b.unknowns[0].clone();
                let mut g: Option<UPoly> = None;
                for e in &b.eqs {
                    let (_, u) = UPoly::from_poly(e, &t).expect("univariate in t");
                    g = Some(match g {
                        None => u,
                        Some(h) => h.gcd(&u),
                    });
                }
                let g = g.expect("at least one equation");
                let deg = g.degree().unwrap_or(0);
                if deg > self.limits.max_degree {
                    return Err(BackSolveError::LimitExceeded(format!(
                        "univariate eliminant of degree {deg} (limit {})",
                        self.limits.max_degree
                    )));
                }
                if deg > 0 {
                    self.components.push(Component::Roots {
                        var: t,
                        poly: g,
                        chain: b.chain.clone(),
                    });
                }
                return Ok(());
            }
            // 6. No linear equation: eliminate one unknown by resultants
            //    against the equation of lowest degree in it.
            if b.unknowns.len() >= 2 {
                if let Some((y, pivot)) = best_resultant(&b.eqs) {
                    let p = b.eqs.remove(pivot);
                    let mut keep = vec![p.clone()];
                    let mut next = Vec::new();
                    let mut hint = None;
                    for g in &b.eqs {
                        if g.has_var(&y) {
                            self.budget.check()?;
                            keep.push(g.clone());
                            let chain = poly::subresultant_chain(&p, g, &y);
                            if hint.is_none() {
                                if let Some(s1) = chain.get(1).filter(|s| s.degree(&y) == 1) {
                                    let c = s1.coeffs_in(&y);
                                    hint = Some(reduce_fraction(-&c[0], c[1].clone()));
                                }
                            }
                            next.push(chain.into_iter().next().unwrap_or_else(Poly::zero));
                        } else {
                            next.push(g.clone());
                        }
                    }
                    b.eqs = next;
                    b.chain.push(Solved::Algebraic {
                        var: y.clone(),
                        polys: keep,
                        hint,
                    });
                    b.unknowns.retain(|u| u != &y);
                    continue;
                }
            }
            // 7. One equation in two unknowns: a curve of solutions.
            let rational = b.chain.iter().all(|c| matches!(c, Solved::Rational { .. }));
            if b.unknowns.len() == 2 && b.eqs.len() == 1 && rational {
                let p = b.eqs[0].clone();
                let (u, v) = (b.unknowns[0].clone(), b.unknowns[1].clone());
                let (t, y) = if p.degree(&u) < p.degree(&v) {
                    (v, u)
                } else {
                    (u, v)
                };
                self.components.push(Component::Curve {
                    t,
                    y,
                    poly: p,
                    chain: b.chain.clone(),
                });
                return Ok(());
            }
            return Err(BackSolveError::Unsupported(format!(
                "no equation is linear in a parameter and none can be eliminated by resultants \
                 (unknowns {}; {} equation(s))",
                b.unknowns.join(", "),
                b.eqs.len()
            )));
        }
    }
}

/// The best equation and parameter for a linear elimination: equation
/// index, parameter, and whether its coefficient cannot vanish.
fn best_linear(eqs: &[Poly]) -> Option<(usize, String, bool)> {
    /// (coefficient may vanish, its terms, the equation's terms, its variables)
    type Key = (bool, usize, usize, usize);
    let mut best: Option<(Key, usize, String)> = None;
    for (i, e) in eqs.iter().enumerate() {
        for x in e.vars() {
            if e.degree(x) != 1 {
                continue;
            }
            let a = e.lead_in(x);
            let definite = a.is_constant() || a.orthant_sign().is_some();
            let key = (!definite, a.num_terms(), e.num_terms(), e.vars().len());
            if best.as_ref().is_none_or(|(k, ..)| key < *k) {
                best = Some((key, i, x.clone()));
            }
        }
    }
    best.map(|(k, i, x)| (i, x, !k.0))
}

/// The unknown to eliminate by resultants and the pivot equation: among
/// unknowns occurring in at least two equations, the least sum of the pivot's
/// degree and the largest other degree in it (small resultants), then the
/// fewest terms.
fn best_resultant(eqs: &[Poly]) -> Option<(String, usize)> {
    let mut vars: Vec<String> = eqs.iter().flat_map(|e| e.vars().to_vec()).collect();
    vars.sort();
    vars.dedup();
    let mut best: Option<((u32, usize), String, usize)> = None;
    for y in vars {
        let with: Vec<usize> = (0..eqs.len()).filter(|&i| eqs[i].has_var(&y)).collect();
        if with.len() < 2 {
            continue;
        }
        let pivot = *with
            .iter()
            .min_by_key(|&&i| (eqs[i].degree(&y), eqs[i].num_terms()))
            .expect("non-empty");
        let others = with
            .iter()
            .filter(|&&i| i != pivot)
            .map(|&i| eqs[i].degree(&y))
            .max()
            .unwrap_or(0);
        let terms: usize = with.iter().map(|&i| eqs[i].num_terms()).sum();
        let key = (eqs[pivot].degree(&y) + others, terms);
        if best.as_ref().is_none_or(|(k, ..)| key < *k) {
            best = Some((key, y, pivot));
        }
    }
    best.map(|(_, y, i)| (y, i))
}

// ---------------------------------------------------------------------------
// Back-substitution, verification and the public entry points

/// `a^k * p(x = num/den)`, sequentially for every (rational) chain entry;
/// zero exactly when `p` vanishes on the parametrisation.
fn substitute_chain(p: &Poly, chain: &[Solved]) -> Poly {
    let mut acc = p.clone();
    for c in chain {
        let Solved::Rational { var, num, den } = c else {
            continue;
        };
        if !acc.has_var(var) {
            continue;
        }
        let cs = acc.coeffs_in(var);
        let k = cs.len() - 1;
        let mut out = Poly::zero();
        for (i, ci) in cs.iter().enumerate() {
            if !ci.is_zero() {
                out = &out + &(&(ci * &num.pow(i as u32)) * &den.pow((k - i) as u32));
            }
        }
        acc = out;
    }
    acc
}

/// Polynomials over a number field: coefficient `i` (an element of the
/// field) of `y^i`, no zero leading coefficient.
fn kpoly_trim(mut v: Vec<Vec<Rat>>) -> Vec<Vec<Rat>> {
    while v.last().is_some_and(|c| c.is_empty()) {
        v.pop();
    }
    v
}

fn kpoly_gcd(
    field: &Field,
    a: Vec<Vec<Rat>>,
    b: Vec<Vec<Rat>>,
    budget: &Budget,
) -> Result<Vec<Vec<Rat>>, BackSolveError> {
    let (mut a, mut b) = (kpoly_trim(a), kpoly_trim(b));
    while !b.is_empty() {
        budget.check()?;
        let inv = field
            .inv(b.last().expect("non-empty"))
            .expect("non-zero lead");
        let mut r = a;
        while r.len() >= b.len() {
            let c = field.mul(r.last().expect("non-empty"), &inv);
            let shift = r.len() - b.len();
            for (j, bj) in b.iter().enumerate() {
                r[shift + j] = q_sub(&r[shift + j], &field.mul(&c, bj));
            }
            r.pop();
            r = kpoly_trim(r);
        }
        a = std::mem::replace(&mut b, r);
    }
    Ok(a)
}

/// Every parameter as an element of the field, from the chain (each entry
/// depends only on `t` and on entries created after it). `hints`: use the
/// subresultant formulas of algebraic entries where defined, else gcds.
/// `None` when the factor carries no solution (a denominator or a common
/// root vanishes there).
fn evaluate_chain(
    field: &Field,
    t: Option<&str>,
    chain: &[Solved],
    hints: bool,
    budget: &Budget,
) -> Result<Option<BTreeMap<String, Vec<Rat>>>, BackSolveError> {
    let mut values: BTreeMap<String, Vec<Rat>> = BTreeMap::new();
    if let Some(t) = t {
        values.insert(t.to_string(), field.reduce(&[Rat::ZERO, Rat::ONE]));
    }
    for c in chain.iter().rev() {
        budget.check()?;
        match c {
            Solved::Rational { var, num, den } => {
                let n = field.eval(num, &values)?;
                let Some(dinv) = field.inv(&field.eval(den, &values)?) else {
                    return Ok(None); // the denominator vanishes here
                };
                values.insert(var.clone(), field.mul(&n, &dinv));
            }
            Solved::Algebraic { var, polys, hint } => {
                if hints {
                    if let Some((num, den)) = hint {
                        if let Some(dinv) = field.inv(&field.eval(den, &values)?) {
                            let v = field.mul(&field.eval(num, &values)?, &dinv);
                            values.insert(var.clone(), v);
                            continue;
                        }
                    }
                }
                let mut h: Vec<Vec<Rat>> = Vec::new();
                for p in polys {
                    let cs: Vec<Vec<Rat>> = p
                        .coeffs_in(var)
                        .iter()
                        .map(|c| field.eval(c, &values))
                        .collect::<Result<_, _>>()?;
                    h = kpoly_gcd(field, h, cs, budget)?;
                }
                match h.len() {
                    0 | 1 => return Ok(None), // no common root: extraneous
                    2 => {
                        let inv = field.inv(&h[1]).expect("non-zero lead");
                        let v: Vec<Rat> = field.mul(&h[0], &inv).iter().map(|x| -x).collect();
                        values.insert(var.clone(), v);
                    }
                    _ => {
                        return Err(BackSolveError::Unsupported(format!(
                            "{var} is not determined rationally by the other parameters \
                             (common factor of degree {} in it)",
                            h.len() - 1
                        )))
                    }
                }
            }
        }
    }
    Ok(Some(values))
}

/// Positive solutions of one zero-dimensional component: for every
/// irreducible factor `f` of the eliminant `g` in `t` (or the single point
/// `Q` when `t` is `None`), the parameters as elements of `Q[t]/(f)`,
/// verified exactly, then at every real root of `f`.
#[allow(clippy::too_many_arguments)]
fn solve_points(
    params: &[String],
    eqs: &[Poly],
    t: Option<&str>,
    g: &UPoly,
    chain: &[Solved],
    budget: &Budget,
    points: &mut Vec<Solution>,
    rejected: &mut Vec<Vec<f64>>,
) -> Result<(), BackSolveError> {
    let factors: Vec<UPoly> = match t {
        Some(_) => factor_univariate(g).1.into_iter().map(|(f, _)| f).collect(),
        None => vec![UPoly::x()],
    };
    for f in factors {
        let field = Field::new(&f, budget);
        let verified =
            |values: &Option<BTreeMap<String, Vec<Rat>>>| -> Result<bool, BackSolveError> {
                let Some(values) = values else {
                    return Ok(false);
                };
                for e in eqs {
                    if !field.eval(e, values)?.is_empty() {
                        return Ok(false);
                    }
                }
                Ok(true)
            };
        // The subresultant formulas first; the gcds where they fail.
        let mut values = evaluate_chain(&field, t, chain, true, budget)?;
        if !verified(&values)? {
            values = evaluate_chain(&field, t, chain, false, budget)?;
            if !verified(&values)? {
                continue;
            }
        }
        let values = values.expect("verified");
        let mut minpolys: Vec<UPoly> = Vec::new();
        for p in params {
            minpolys.push(field.min_poly(&values[p])?);
        }
        for root in real_roots(&f) {
            let t_approx = approx_root(&f, &root);
            let mut exact = Vec::new();
            let mut positive = true;
            let mut approx = Vec::new();
            for (p, mp) in params.iter().zip(&minpolys) {
                let v = &values[p];
                let sign = if v.is_empty() {
                    0
                } else {
                    let (c, u) = rat_upoly(v);
                    c.signum() * sign_at_root(&u, &f, &root)
                };
                positive &= sign > 0;
                let x = horner(v, &t_approx);
                approx.push(x.to_f64());
                exact.push(nearest_root(mp, &x));
            }
            if positive {
                points.push(Solution {
                    parameters: params.to_vec(),
                    values: exact.iter().map(|a| a.value).collect(),
                    exact,
                });
            } else {
                rejected.push(approx);
            }
        }
    }
    Ok(())
}

/// Every parameter as a rational function: the chain's solutions, the
/// remaining unknowns as themselves.
fn expressions_of(params: &[String], chain: &[Solved]) -> Vec<RationalFunction> {
    params
        .iter()
        .map(|p| match chain.iter().find(|c| c.var() == p) {
            Some(Solved::Rational { num, den, .. }) => RationalFunction {
                num: num.clone(),
                den: den.clone(),
            },
            _ => RationalFunction {
                num: Poly::var(p),
                den: Poly::one(),
            },
        })
        .collect()
}

/// A family from a component without equations.
fn make_family(
    params: &[String],
    eqs: &[Poly],
    free: &[String],
    chain: &[Solved],
) -> Result<Option<Family>, BackSolveError> {
    if let Some(c) = chain.iter().find(|c| matches!(c, Solved::Algebraic { .. })) {
        return Err(BackSolveError::Unsupported(format!(
            "a family on which {} is algebraic, not rational, in the free parameters",
            c.var()
        )));
    }
    for e in eqs {
        if !substitute_chain(e, chain).is_zero() {
            return Err(BackSolveError::Unsupported(
                "a family failed its symbolic verification".to_string(),
            ));
        }
    }
    let mut fam = Family {
        parameters: params.to_vec(),
        free: free.to_vec(),
        dependent: None,
        expressions: expressions_of(params, chain),
        intervals: Vec::new(),
        samples: Vec::new(),
    };
    if free.len() == 1 {
        let t = &free[0];
        let mut polys: Vec<UPoly> = Vec::new();
        for e in &fam.expressions {
            for p in [&e.num, &e.den] {
                if let Some((_, u)) = UPoly::from_poly(p, t) {
                    polys.push(u);
                }
            }
        }
        for cell in cells(&polys) {
            let at: BTreeMap<String, Rat> =
                [(t.clone(), cell.sample.clone())].into_iter().collect();
            let admissible = fam
                .expressions
                .iter()
                .all(|e| e.eval(&at).is_some_and(|v| v.signum() > 0));
            if !admissible {
                continue;
            }
            let lo = cell.lo.value;
            let cands: Vec<f64> = match &cell.hi {
                Some(h) => [0.25, 0.5, 0.75]
                    .iter()
                    .map(|w| lo + (h.value - lo) * w)
                    .collect(),
                None => {
                    let s = if lo > 0.0 { lo } else { 1.0 };
                    vec![s * 1.5, s * 2.0, s * 4.0]
                }
            };
            for c in cands {
                if let Some(m) = fam.member_f64(&[c]) {
                    fam.samples.push(m);
                }
            }
            if let Some(m) = fam.member(std::slice::from_ref(&cell.sample)) {
                fam.samples.push(m.iter().map(Rat::to_f64).collect());
            }
            fam.intervals.push(Interval {
                lo: cell.lo,
                hi: cell.hi,
                branches: 1,
            });
        }
        if fam.intervals.is_empty() {
            return Ok(None);
        }
    } else {
        fam.samples = grid_samples(&fam);
    }
    Ok(Some(fam))
}

/// A one-dimensional family on the curve `poly(t, y) = 0`.
fn make_curve_family(
    params: &[String],
    eqs: &[Poly],
    (t, y): (&str, &str),
    p: &Poly,
    chain: &[Solved],
) -> Result<Option<Family>, BackSolveError> {
    for e in eqs {
        let sub = substitute_chain(e, chain);
        if !sub.is_zero() && sub.div_exact(p).is_none() {
            return Err(BackSolveError::Unsupported(
                "a curve family failed its symbolic verification".to_string(),
            ));
        }
    }
    let mut fam = Family {
        parameters: params.to_vec(),
        free: vec![t.to_string()],
        dependent: Some(Dependent {
            var: y.to_string(),
            poly: p.clone(),
        }),
        expressions: expressions_of(params, chain),
        intervals: Vec::new(),
        samples: Vec::new(),
    };
    // Critical values of t: where the number of real roots y can change
    // (leading coefficient, discriminant), where y = 0, and where a
    // numerator or denominator of an expression vanishes on the curve.
    let mut crit: Vec<Poly> = vec![
        p.lead_in(y),
        poly::discriminant(p, y),
        p.subs(y, &Rat::ZERO),
    ];
    for e in &fam.expressions {
        for q in [&e.num, &e.den] {
            let r = if q.has_var(y) {
                poly::resultant(p, q, y)
            } else {
                q.clone()
            };
            if r.is_zero() {
                return Ok(None); // vanishes on the whole curve
            }
            crit.push(r);
        }
    }
    let polys: Vec<UPoly> = crit
        .iter()
        .filter_map(|c| UPoly::from_poly(c, t).map(|(_, u)| u))
        .collect();
    for cell in cells(&polys) {
        let branches = curve_members(&fam, &cell.sample);
        if branches.is_empty() {
            continue;
        }
        fam.samples.extend(branches.iter().cloned());
        fam.intervals.push(Interval {
            lo: cell.lo,
            hi: cell.hi,
            branches: branches.len(),
        });
    }
    Ok((!fam.intervals.is_empty()).then_some(fam))
}

/// The members of a curve family at `t = ts` with every parameter positive
/// (signs decided exactly at the isolated roots `y`), as `f64` values.
fn curve_members(fam: &Family, ts: &Rat) -> Vec<Vec<f64>> {
    let Some(dep) = &fam.dependent else {
        return Vec::new();
    };
    let (t, y) = (&fam.free[0], &dep.var);
    if ts.signum() <= 0 {
        return Vec::new();
    }
    let Some((_, py)) = UPoly::from_poly(&dep.poly.subs(t, ts), y) else {
        return Vec::new();
    };
    if py.is_zero() {
        return Vec::new();
    }
    let sqf = py.square_free_part();
    let mut out = Vec::new();
    'roots: for root in real_roots(&sqf).into_iter().filter(RealRoot::is_positive) {
        for e in &fam.expressions {
            let mut sign = 1;
            for q in [&e.num, &e.den] {
                let Some((c, u)) = UPoly::from_poly(&q.subs(t, ts), y) else {
                    continue 'roots;
                };
                if u.is_zero() || vanishes_at(&u.gcd(&sqf), &root) {
                    continue 'roots;
                }
                sign *= c.signum() * sign_at_root(&u, &sqf, &root);
            }
            if sign <= 0 {
                continue 'roots;
            }
        }
        let ya = approx_root(&sqf, &root);
        let at: BTreeMap<String, Rat> = [(t.clone(), ts.clone()), (y.clone(), ya)]
            .into_iter()
            .collect();
        let vals: Option<Vec<f64>> = fam
            .expressions
            .iter()
            .map(|e| e.eval(&at).map(|v| v.to_f64()))
            .collect();
        if let Some(v) = vals {
            out.push(v);
        }
    }
    out
}

/// True when `g` (a divisor of the polynomial that `root` isolates a root
/// of) vanishes at that root.
fn vanishes_at(g: &UPoly, root: &RealRoot) -> bool {
    if g.is_constant() {
        return false;
    }
    if root.is_exact() {
        g.sign_at(&root.lo) == 0
    } else {
        g.sign_at(&root.lo) * g.sign_at(&root.hi) < 0
    }
}

/// One open cell of the positive half-line cut at the positive roots of
/// some polynomials, with an exact interior point.
struct Cell {
    lo: AlgebraicNumber,
    hi: Option<AlgebraicNumber>,
    sample: Rat,
}

/// The cells of `(0, inf)` between consecutive positive roots of `polys`.
fn cells(polys: &[UPoly]) -> Vec<Cell> {
    let mut prod = UPoly::one();
    for p in polys.iter().filter(|p| !p.is_constant()) {
        prod = &prod * p;
    }
    let sqf = prod.square_free_part();
    let mut roots: Vec<RealRoot> = real_roots(&sqf)
        .into_iter()
        .filter(RealRoot::is_positive)
        .collect();
    // Make every interval's lower end positive, so that it is a point of
    // the gap before it.
    for r in roots.iter_mut() {
        while !r.is_exact() && r.lo.signum() <= 0 {
            let w = &r.width() * &Rat::new(Int::ONE, Int::from(2));
            let _ = r.refine(&sqf, &w);
        }
    }
    let half = Rat::new(Int::ONE, Int::from(2));
    // Exact interior point of the gap between roots `left` and `right`:
    // interval ends are never roots, exact roots are bisected.
    let gap_point = |left: Option<&RealRoot>, right: Option<&RealRoot>| -> Rat {
        match (left, right) {
            (None, None) => Rat::ONE,
            (None, Some(r)) if r.is_exact() => &r.lo * &half,
            (None, Some(r)) => r.lo.clone(),
            (Some(l), None) if l.is_exact() => &l.lo * &Rat::from(2),
            (Some(l), None) => l.hi.clone(),
            (Some(l), Some(_)) if !l.is_exact() => l.hi.clone(),
            (Some(_), Some(r)) if !r.is_exact() => r.lo.clone(),
            (Some(l), Some(r)) => &(&l.lo + &r.lo) * &half,
        }
    };
    let (_, fs) = factor_univariate(&sqf);
    let endpoint = |r: &RealRoot| -> AlgebraicNumber {
        let f = fs
            .iter()
            .map(|(f, _)| f)
            .find(|f| {
                if r.is_exact() {
                    f.sign_at(&r.lo) == 0
                } else {
                    f.sign_at(&r.lo) * f.sign_at(&r.hi) < 0
                }
            })
            .expect("the root belongs to a factor");
        AlgebraicNumber::from_root(f, r)
    };
    (0..=roots.len())
        .map(|k| {
            let left = k.checked_sub(1).map(|i| &roots[i]);
            let right = roots.get(k);
            Cell {
                lo: left.map_or_else(|| AlgebraicNumber::rational(&Rat::ZERO), endpoint),
                hi: right.map(endpoint),
                sample: gap_point(left, right),
            }
        })
        .collect()
}

/// Members of a family with several free parameters, from a logarithmic
/// grid `10^-6 .. 10^6` (four points per decade) in every free parameter,
/// each checked exactly (the grid is coarse: a narrow admissible region can
/// be missed, then fewer or no samples are given).
fn grid_samples(fam: &Family) -> Vec<Vec<f64>> {
    let d = fam.free.len();
    let steps: Vec<f64> = (-24..=24).map(|k| 10f64.powf(k as f64 / 4.0)).collect();
    let mut found: Vec<Vec<f64>> = Vec::new();
    let total = steps.len().pow(d as u32).min(200_000);
    for idx in 0..total {
        let mut rem = idx;
        let mut vals = Vec::with_capacity(d);
        for _ in 0..d {
            vals.push(steps[rem % steps.len()]);
            rem /= steps.len();
        }
        let point: BTreeMap<String, f64> =
            fam.free.iter().cloned().zip(vals.iter().copied()).collect();
        if fam.expressions.iter().all(|e| e.eval_f64(&point) > 0.0) {
            if let Some(m) = fam.member_f64(&vals) {
                found.push(m);
            }
        }
    }
    if found.len() <= 3 {
        return found;
    }
    let n = found.len();
    vec![found[0].clone(), found[n / 2].clone(), found[n - 1].clone()]
}

/// Checks degrees and fixed signs; `Some(reason)` when they already exclude
/// every positive parameter set.
fn quick_obstruction(s: &Structure, target: &Target) -> Option<NoSolution> {
    let sn = s.num.len().saturating_sub(1);
    let sd = s.den.len() - 1;
    let (tn, td) = (target.num_degree(), target.den_degree());
    let fixed_top = |v: &[Poly]| v.last().is_some_and(|p| p.orthant_sign().is_some());
    let relative = |num: usize, den: usize| den as i64 - num as i64;
    let degree_bad = td > sd
        || tn > sn
        || (fixed_top(&s.num) && fixed_top(&s.den) && relative(sn, sd) != relative(tn, td));
    if degree_bad || td < tn {
        return Some(NoSolution::Degree {
            structure: (sn, sd),
            target: (tn, td),
        });
    }
    if td != sd || s.den[sd].orthant_sign() != Some(1) {
        return None;
    }
    // num_S = lambda * n, den_S = lambda * d with lambda = lc(den_S)/lc(d) > 0.
    let check = |part: &str, sv: &[Poly], tv: &[Rat]| -> Option<NoSolution> {
        for k in 0..sv.len().max(tv.len()) {
            let ts = tv.get(k).map_or(0, Rat::signum);
            let ss = match sv.get(k) {
                None => Some(0),
                Some(p) if p.is_zero() => Some(0),
                Some(p) => p.orthant_sign(),
            };
            if let Some(ss) = ss {
                if ss != ts {
                    return Some(NoSolution::SignPattern {
                        coefficient: format!("{part} Omega^{k}"),
                        structure_sign: ss,
                        target_sign: ts,
                    });
                }
            }
        }
        None
    };
    check("Num", &s.num, &target.num).or_else(|| check("Den", &s.den, &target.den))
}

/// The coefficient equations of `num_S/den_S == n/d` (see the module docs).
fn equations(s: &Structure, target: &Target) -> Vec<Poly> {
    let d = &target.den;
    let dd = d.len() - 1;
    let lead_inv = d[dd].recip();
    let mut rem: Vec<Poly> = s.den.clone();
    let sd = rem.len() - 1;
    let mut q: Vec<Poly> = vec![Poly::zero(); sd + 1 - dd];
    for i in (dd..=sd).rev() {
        let c = rem[i].scale(&lead_inv);
        for (j, dj) in d.iter().enumerate() {
            rem[i - dd + j] = &rem[i - dd + j] - &c.scale(dj);
        }
        q[i - dd] = c;
    }
    let mut eqs: Vec<Poly> = rem[..dd].to_vec();
    let n = &target.num;
    let top = (s.num.len().max(q.len() + n.len() - 1)).max(1);
    for k in 0..top {
        let mut e = s.num.get(k).cloned().unwrap_or_else(Poly::zero);
        for (i, qi) in q.iter().enumerate() {
            if k >= i && k - i < n.len() {
                e = &e - &qi.scale(&n[k - i]);
            }
        }
        eqs.push(e);
    }
    eqs.into_iter()
        .filter(|e| !e.is_zero())
        .map(|e| e.primitive_part())
        .collect()
}

/// All positive parameter sets of `model` whose undamped inertance equals
/// `target`, with the default [`Limits`]. See the [module docs](self) for
/// the method.
///
/// ```
/// use mms::{backsolve::{back_solve, NoSolution, Target}, Model};
/// // B2 (Tab. 6) as the generating model; C2 cannot reproduce it exactly.
/// let b2 = Model::from_id("B2")?;
/// let t = Target::from_model_f64(&b2, &[0.01, 0.01, 0.01, 100.0, 200.0])?;
/// let c2 = back_solve(&Model::from_id("C2")?, &t)?;
/// assert!(matches!(c2.no_solution(), Some(NoSolution::ViolatedRelation { .. })));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn back_solve(model: &Model, target: &Target) -> Result<BackSolution, BackSolveError> {
    back_solve_with(model, target, &Limits::default())
}

/// [`back_solve`] with explicit [`Limits`].
///
/// ```
/// use mms::{backsolve::{back_solve_with, BackSolveError, Limits, Target}, Model};
/// let a1 = Model::from_id("A1")?;
/// let t = Target::from_model_f64(&a1, &[1.0, 2.0, 3.0, 4.0, 5.0])?;
/// let tight = Limits { max_parameters: 3, ..Limits::default() };
/// assert!(matches!(back_solve_with(&a1, &t, &tight), Err(BackSolveError::LimitExceeded(_))));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn back_solve_with(
    model: &Model,
    target: &Target,
    limits: &Limits,
) -> Result<BackSolution, BackSolveError> {
    let params = model.undamped_parameters();
    if params.len() > limits.max_parameters {
        return Err(BackSolveError::LimitExceeded(format!(
            "{} parameters (limit {})",
            params.len(),
            limits.max_parameters
        )));
    }
    let s = Structure::new(model);
    if let Some(r) = quick_obstruction(&s, target) {
        return Ok(BackSolution::NoSolution(r));
    }
    // Invariant relations apply to the unreduced coefficients, i.e. when
    // the target has the structure's full denominator degree.
    if target.den_degree() == s.den.len() - 1 {
        let vals: BTreeMap<String, Rat> = target
            .num
            .iter()
            .enumerate()
            .map(|(k, c)| (format!("n{k}"), c.clone()))
            .chain(
                target
                    .den
                    .iter()
                    .enumerate()
                    .map(|(k, c)| (format!("d{k}"), c.clone())),
            )
            .collect();
        for r in relations(&s, limits) {
            let mut pt = vals.clone();
            for v in r.vars() {
                pt.entry(v.clone()).or_insert(Rat::ZERO);
            }
            let value = r.eval(&pt).expect("all coefficients set");
            if !value.is_zero() {
                let size: f64 = r
                    .terms()
                    .iter()
                    .map(|t| {
                        let mono = Poly::from_terms(r.vars(), vec![t.clone()]);
                        mono.eval(&pt).expect("all coefficients set").to_f64().abs()
                    })
                    .sum();
                return Ok(BackSolution::NoSolution(NoSolution::ViolatedRelation {
                    relative: value.to_f64().abs() / size,
                    relation: r,
                    value,
                }));
            }
        }
    }
    let eqs = equations(&s, target);
    let budget = Budget {
        deadline: std::time::Instant::now() + limits.max_time,
    };
    let mut engine = Engine {
        limits,
        budget: &budget,
        branches: 0,
        components: Vec::new(),
    };
    engine.run(Branch {
        eqs: eqs.clone(),
        unknowns: params.clone(),
        chain: Vec::new(),
    })?;
    let mut points: Vec<Solution> = Vec::new();
    let mut rejected: Vec<Vec<f64>> = Vec::new();
    let mut families: Vec<Family> = Vec::new();
    for c in std::mem::take(&mut engine.components) {
        match c {
            Component::Roots { var, poly, chain } => {
                solve_points(
                    &params,
                    &eqs,
                    Some(&var),
                    &poly,
                    &chain,
                    &budget,
                    &mut points,
                    &mut rejected,
                )?;
            }
            Component::Free { free, chain } => {
                if free.is_empty() {
                    let one = UPoly::one();
                    solve_points(
                        &params,
                        &eqs,
                        None,
                        &one,
                        &chain,
                        &budget,
                        &mut points,
                        &mut rejected,
                    )?;
                } else if let Some(f) = make_family(&params, &eqs, &free, &chain)? {
                    families.push(f);
                }
            }
            Component::Curve { t, y, poly, chain } => {
                if let Some(f) = make_curve_family(&params, &eqs, (&t, &y), &poly, &chain)? {
                    families.push(f);
                }
            }
        }
    }
    // Deterministic order, duplicates (from overlapping branches) removed.
    let cmp = |a: &Solution, b: &Solution| -> Ordering {
        a.values
            .iter()
            .zip(&b.values)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(Ordering::Equal)
    };
    points.sort_by(cmp);
    points.dedup_by(|a, b| {
        a.exact
            .iter()
            .zip(&b.exact)
            .all(|(x, y)| x.poly == y.poly && x.lo <= y.hi && y.lo <= x.hi)
    });
    families.sort_by_key(|f| {
        (
            f.free.clone(),
            f.expressions
                .iter()
                .map(|e| e.to_string())
                .collect::<Vec<_>>(),
        )
    });
    families.dedup();
    Ok(if !families.is_empty() {
        BackSolution::Families {
            families,
            isolated: points,
        }
    } else if !points.is_empty() {
        BackSolution::Points(points)
    } else if !rejected.is_empty() {
        BackSolution::NoSolution(NoSolution::NotPositive {
            candidates: rejected,
        })
    } else {
        BackSolution::NoSolution(NoSolution::Contradiction)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(s: &str) -> Rat {
        s.parse().unwrap()
    }

    #[test]
    fn target_normal_form_cancels_common_factors() {
        // (Omega - 1)(Omega - 2) / ((Omega - 1)(Omega - 3)) = (Omega - 2)/(Omega - 3)
        let t = Target::new(vec![r("2"), r("-3"), r("1")], vec![r("3"), r("-4"), r("1")]).unwrap();
        assert_eq!(t.num(), [r("-2"), r("1")]);
        assert_eq!(t.den(), [r("-3"), r("1")]);
        // Scaling and sign do not change the target.
        let u = Target::new(vec![r("4"), r("-2")], vec![r("6"), r("-2")]).unwrap();
        assert_eq!(t, u);
    }

    #[test]
    fn nullspace_and_rank() {
        let m = vec![vec![r("1"), r("2"), r("3")], vec![r("2"), r("4"), r("6")]];
        let ns = nullspace(m.clone(), 3);
        assert_eq!(ns.len(), 2);
        for v in &ns {
            for row in &m {
                let dot = row.iter().zip(v).fold(Rat::ZERO, |a, (x, y)| &a + &(x * y));
                assert!(dot.is_zero());
            }
        }
        assert_eq!(rank(m, 3), 1);
    }

    #[test]
    fn modular_nullspace_and_reconstruction() {
        let p = PRIMES[0];
        // x - 2y = 0 modulo p: the null vector (2, 1).
        let (free, basis) = nullspace_mod(vec![vec![1, p - 2]], 2, p);
        assert_eq!(free, [1]);
        assert_eq!(basis, [vec![2, 1]]);
        // -3/7 modulo p comes back.
        let m = Int::from(p);
        let x = (&Int::from(p - 3) * &Int::from(invmod(7, p)))
            .div_mod_floor(&m)
            .1;
        assert_eq!(rational_reconstruction(&x, &m), Some(r("-3/7")));
    }

    #[test]
    fn number_field_inverse_and_minimal_polynomial() {
        // Q(sqrt 2): (1 + t)^-1 = t - 1; t + 1 has minimal polynomial x^2 - 2x - 1.
        let budget = Budget {
            deadline: std::time::Instant::now() + std::time::Duration::from_secs(10),
        };
        let field = Field::new(&UPoly::from_i64s(&[-2, 0, 1]), &budget);
        let a = vec![r("1"), r("1")];
        assert_eq!(field.inv(&a).unwrap(), [r("-1"), r("1")]);
        assert_eq!(field.min_poly(&a).unwrap(), UPoly::from_i64s(&[-1, -2, 1]));
        // gcd over the field of (y - t)(y + 1) and (y - t)(y - 3): y - t.
        let yt = vec![vec![r("0"), r("-1")], vec![r("1")]];
        let f1 = vec![vec![r("0"), r("-1")], vec![r("1"), r("-1")], vec![r("1")]];
        let f2 = vec![vec![r("0"), r("3")], vec![r("-3"), r("-1")], vec![r("1")]];
        let g = kpoly_gcd(&field, f1, f2, &budget).unwrap();
        let inv = field.inv(&g[1]).unwrap();
        let monic: Vec<Vec<Rat>> = g.iter().map(|c| field.mul(c, &inv)).collect();
        assert_eq!(monic, yt);
    }

    #[test]
    fn simplification_drops_factors_that_cannot_vanish() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        assert!(matches!(simplify(&p("m1*m2 + c1")), Simplified::Infeasible));
        assert!(matches!(simplify(&Poly::zero()), Simplified::Zero));
        let Simplified::Factors(f) = simplify(&p("m1*(m2 + m3)*(m2 - 2*m3)*(c1 - m1)")) else {
            panic!()
        };
        assert_eq!(f, [p("c1 - m1"), p("m2 - 2*m3")]);
    }

    #[test]
    fn cells_and_signs_at_roots() {
        // Roots 1 and sqrt 2 cut (0, inf) into three cells.
        let c = cells(&[UPoly::from_i64s(&[-1, 1]), UPoly::from_i64s(&[-2, 0, 1])]);
        assert_eq!(c.len(), 3);
        assert_eq!(c[0].lo.value, 0.0);
        assert_eq!(c[1].lo.as_rational(), Some(Rat::ONE));
        assert!((c[2].lo.value - 2f64.sqrt()).abs() < 1e-12);
        assert!(c[2].hi.is_none());
        for (k, cell) in c.iter().enumerate() {
            let s = cell.sample.to_f64();
            assert!(
                s > cell.lo.value && cell.hi.as_ref().is_none_or(|h| s < h.value),
                "{k}"
            );
        }
        // x - 3/2 is negative at sqrt 2.
        let f = UPoly::from_i64s(&[-2, 0, 1]);
        let root = real_roots(&f).pop().unwrap();
        assert_eq!(sign_at_root(&UPoly::from_i64s(&[-3, 2]), &f, &root), -1);
    }

    #[test]
    fn quick_obstructions() {
        let s = Structure::new(&Model::from_id("A2").unwrap());
        // A2's numerator has degree 1 with a negative Omega coefficient.
        let t = Target::new(vec![r("1"), r("1")], vec![r("1"), r("-1"), r("1")]).unwrap();
        assert!(matches!(
            quick_obstruction(&s, &t),
            Some(NoSolution::SignPattern { .. })
        ));
        let t = Target::new(vec![r("1")], vec![r("1"), r("-1"), r("1")]).unwrap();
        assert!(matches!(
            quick_obstruction(&s, &t),
            Some(NoSolution::Degree { .. })
        ));
    }
}
