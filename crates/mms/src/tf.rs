//! Symbolic transfer functions of a [`Model`], undamped (in `Omega`) and
//! damped (in `s`).
//!
//! Both come from the dynamic stiffness matrix of the chain,
//! `A = C - Omega*M` (undamped, `Omega = omega^2 = -s^2`) or
//! `A = C + s*D + s^2*M` (damped). The receptance (force to position) is
//! `c^T A^-1 b = c^T adj(A) b / det(A)`. Because `A` is tridiagonal, `det(A)`
//! and the needed entries of `adj(A)` are continuants: with `theta_k` the
//! leading and `phi_k` the trailing principal minors,
//! `adj(A)[i][j] = theta_(i-1) * prod_(k=i..j-1) c_(k,k+1) * phi_(j+1)` for
//! `i <= j` (the off-diagonal entries are `-c`). The tests check the result
//! against exact Gaussian elimination over Q.

use crate::model::Model;
use poly::{Int, Poly, Rat};
use serde::{Serialize, Serializer};
use std::fmt;
use std::str::FromStr;

/// Name of the frequency variable of undamped transfer functions,
/// `Omega = omega^2 = -s^2`.
pub const OMEGA: &str = "Omega";
/// Name of the Laplace variable of damped transfer functions.
pub const S: &str = "s";

/// The measured quantity: position (receptance), velocity (mobility) or
/// acceleration (inertance), each per unit of actuator force.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Output {
    /// Position, `X/F`: receptance.
    Position,
    /// Velocity, `sX/F`: mobility.
    Velocity,
    /// Acceleration, `s^2 X/F`: inertance.
    Acceleration,
}

impl Output {
    /// All three outputs, in the order position, velocity, acceleration.
    pub const ALL: [Output; 3] = [Output::Position, Output::Velocity, Output::Acceleration];

    /// The power of `s` that turns a position into this output (0, 1, 2).
    pub fn s_power(self) -> u32 {
        match self {
            Output::Position => 0,
            Output::Velocity => 1,
            Output::Acceleration => 2,
        }
    }

    /// Lower-case name: `position`, `velocity`, `acceleration`.
    pub fn as_str(self) -> &'static str {
        match self {
            Output::Position => "position",
            Output::Velocity => "velocity",
            Output::Acceleration => "acceleration",
        }
    }
}

impl fmt::Display for Output {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Error for an unknown [`Output`] name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown output {0:?} (expected position, velocity or acceleration)")]
pub struct ParseOutputError(pub String);

impl FromStr for Output {
    type Err = ParseOutputError;
    /// Accepts the names and the TF names, case-insensitively:
    /// `position`/`receptance`/`x`, `velocity`/`mobility`/`v`,
    /// `acceleration`/`inertance`/`a`.
    fn from_str(s: &str) -> Result<Output, ParseOutputError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "position" | "receptance" | "x" | "pos" => Ok(Output::Position),
            "velocity" | "mobility" | "v" | "vel" => Ok(Output::Velocity),
            "acceleration" | "inertance" | "a" | "acc" => Ok(Output::Acceleration),
            _ => Err(ParseOutputError(s.to_string())),
        }
    }
}

fn ser_poly<S: Serializer>(p: &Poly, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&p.to_string())
}

/// Undamped inertance (force to acceleration) `num/den` in `Omega`.
///
/// Normal form: `num` and `den` have integer coefficients without a common
/// integer factor (the joint content is divided out), and the leading
/// coefficient of `den` in `Omega` is positive (its first term in
/// [`poly`]'s term order is positive; for these models all its terms share
/// one sign). The rigid-body factor `Omega` of `det(C - Omega*M)` is
/// removed. Common symbolic factors of `num` and `den` are *not* cancelled:
/// they occur exactly for degraded models (see [`Model::is_degradation_free`]).
///
/// The receptance is `-num/(Omega*den)`; see [`UndampedTf::output`].
///
/// ```
/// let tf = mms::Model::from_id("A2").unwrap().undamped_tf();
/// // eq. (21) and (10) of the paper
/// assert_eq!(tf.num, "c12*c23 - c12*m3*Omega".parse().unwrap());
/// assert_eq!(tf.den.degree("Omega"), 2);
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct UndampedTf {
    /// Numerator of the inertance.
    #[serde(serialize_with = "ser_poly")]
    pub num: Poly,
    /// Denominator of the inertance.
    #[serde(serialize_with = "ser_poly")]
    pub den: Poly,
}

/// An undamped transfer function for one [`Output`], written as
/// `sign * s^s_power * Omega^omega_power * num/den` with `s^2 = -Omega`.
///
/// From the inertance `G_a = num/den`: acceleration is `+1 * num/den`,
/// velocity `G_a/s = -s * num/(Omega*den)`, position
/// `G_a/s^2 = -num/(Omega*den)`. The odd power of `s` for velocity cannot be
/// written in `Omega` and is kept explicit.
///
/// ```
/// use mms::{Model, Output};
/// let r = Model::from_id("A1").unwrap().undamped_tf().output(Output::Position);
/// assert_eq!((r.sign, r.s_power, r.omega_power), (-1, 0, -1));
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct OmegaTf {
    /// The output this is the transfer function of.
    pub output: Output,
    /// Overall sign, +1 or -1.
    pub sign: i32,
    /// Explicit power of `s` (0 or 1).
    pub s_power: u32,
    /// Power of `Omega` (0 or -1).
    pub omega_power: i32,
    /// Numerator polynomial in `Omega` (the inertance numerator).
    #[serde(serialize_with = "ser_poly")]
    pub num: Poly,
    /// Denominator polynomial in `Omega` (the inertance denominator).
    #[serde(serialize_with = "ser_poly")]
    pub den: Poly,
}

impl OmegaTf {
    /// Exact value at a parameter point and a value of `Omega` for position
    /// and acceleration; `None` for velocity (needs `s`), at a pole, or when
    /// a parameter is missing.
    pub fn eval(
        &self,
        params: &std::collections::BTreeMap<String, Rat>,
        omega: &Rat,
    ) -> Option<Rat> {
        if self.s_power != 0 {
            return None;
        }
        let mut pt = params.clone();
        pt.insert(OMEGA.to_string(), omega.clone());
        let n = self.num.eval(&pt).ok()?;
        let mut d = self.den.eval(&pt).ok()?;
        if self.omega_power < 0 {
            d = &d * &omega.pow(-self.omega_power);
        }
        if d.is_zero() {
            return None;
        }
        let v = &n / &d;
        Some(if self.sign < 0 { -v } else { v })
    }
}

/// Damped transfer function `num/den` in `s` for one [`Output`], from
/// `C + s*D + s^2*M`.
///
/// The rigid-body factor `s^2` of the determinant is removed and then the
/// output's power of `s` applied: with `Q = det/s^2` and `P = c^T adj b`,
/// acceleration is `P/Q`, velocity `P/(s*Q)`, position `P/(s^2*Q)`; `den`
/// includes that power of `s`. Normal form as for [`UndampedTf`]: integer
/// coefficients, joint content removed, positive leading coefficient of
/// `den` in `s`.
///
/// ```
/// use mms::{Model, Output};
/// let tf = Model::from_id("A1").unwrap().damped_tf(Output::Velocity);
/// assert_eq!(tf.den.min_degree("s"), 1); // one integrator left: s * Q(s)
/// assert_eq!(tf.den.degree("s"), 5);
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct DampedTf {
    /// The output.
    pub output: Output,
    /// Numerator polynomial in `s`.
    #[serde(serialize_with = "ser_poly")]
    pub num: Poly,
    /// Denominator polynomial in `s`.
    #[serde(serialize_with = "ser_poly")]
    pub den: Poly,
}

/// `(c^T adj(A) b, det(A))` for a symmetric tridiagonal `A` given by its
/// diagonal and its off-diagonal *link weights* `w` (`A[i][i+1] = -w[i]`).
fn tridiagonal_bilinear(diag: &[Poly], w: &[Poly], c: &[i64], b: &[i64]) -> (Poly, Poly) {
    let n = diag.len();
    // theta[k] = det of the leading k x k block, k = 0..=n.
    let mut theta = vec![Poly::one(), diag[0].clone()];
    for k in 2..=n {
        let t = &(&diag[k - 1] * &theta[k - 1]) - &(&w[k - 2].pow(2) * &theta[k - 2]);
        theta.push(t);
    }
    // phi[k] = det of the trailing block from row k (1-based) on, phi[n+1] = 1.
    let mut phi = vec![Poly::zero(); n + 2];
    phi[n + 1] = Poly::one();
    phi[n] = diag[n - 1].clone();
    for k in (1..n).rev() {
        phi[k] = &(&diag[k - 1] * &phi[k + 1]) - &(&w[k - 1].pow(2) * &phi[k + 2]);
    }
    let adj = |i: usize, j: usize| -> Poly {
        // 1-based, symmetric.
        let (i, j) = (i.min(j), i.max(j));
        let mut p = &theta[i - 1] * &phi[j + 1];
        for wk in &w[i - 1..j - 1] {
            if wk.is_zero() {
                return Poly::zero();
            }
            p = &p * wk;
        }
        p
    };
    let mut num = Poly::zero();
    for (i, &ci) in c.iter().enumerate() {
        for (j, &bj) in b.iter().enumerate() {
            if ci != 0 && bj != 0 {
                num = &num + &adj(i + 1, j + 1).scale(&Rat::from(ci * bj));
            }
        }
    }
    (num, theta.swap_remove(n))
}

/// Link weights of the chain between consecutive masses (`w[i]` between mass
/// `i+1` and `i+2`, zero at the gap) and the diagonal of the stiffness-like
/// matrix, for link weight `link(i)` (`i` as in [`crate::spring_name`]).
fn chain(
    model: &Model,
    link: impl Fn(usize) -> Poly,
    mass_term: impl Fn(usize) -> Poly,
) -> (Vec<Poly>, Vec<Poly>) {
    let n = model.n_masses();
    let lw: Vec<Poly> = (0..n)
        .map(|i| {
            if model.has_link(i) {
                link(i)
            } else {
                Poly::zero()
            }
        })
        .collect();
    let diag: Vec<Poly> = (0..n)
        .map(|i| {
            let mut d = &lw[i] + &mass_term(i + 1);
            if i + 1 < n {
                d = &d + &lw[i + 1];
            }
            d
        })
        .collect();
    (diag, lw[1..].to_vec())
}

/// Sign of the leading coefficient of `p` in `var` (first term in term order).
fn lead_sign(p: &Poly, var: &str) -> i32 {
    p.lead_in(var).leading_coef().signum()
}

/// Rational gcd of all coefficients of `a` and `b` (positive; 1 if both zero).
fn joint_content(a: &Poly, b: &Poly) -> Rat {
    let mut num = Int::ZERO;
    let mut den = Int::ONE;
    for t in a.terms().iter().chain(b.terms()) {
        num = num.gcd(t.coef.numer());
        den = den.lcm(t.coef.denom());
    }
    if num.is_zero() {
        Rat::ONE
    } else {
        Rat::new(num, den)
    }
}

/// Puts `num/den` into normal form (see [`UndampedTf`]).
pub(crate) fn normalize(num: Poly, den: Poly, var: &str) -> (Poly, Poly) {
    let mut g = joint_content(&num, &den);
    if lead_sign(&den, var) < 0 {
        g = -g;
    }
    let inv = g.recip();
    (num.scale(&inv), den.scale(&inv))
}

impl Model {
    /// `(c^T adj(C - Omega*M) b, det(C - Omega*M))`, unnormalised: the
    /// receptance is their ratio. Useful for cross-checks.
    pub fn undamped_adjugate_form(&self) -> (Poly, Poly) {
        let om = Poly::var(OMEGA);
        let (diag, w) = chain(
            self,
            |i| Poly::var(&crate::spring_name(i)),
            |k| -(&om * &Poly::var(&crate::mass_name(k))),
        );
        tridiagonal_bilinear(&diag, &w, &self.output_vector(), &self.input_vector())
    }

    /// `(c^T adj(C + s*D + s^2*M) b, det(C + s*D + s^2*M))`, unnormalised:
    /// the damped receptance is their ratio.
    pub fn damped_adjugate_form(&self) -> (Poly, Poly) {
        let s = Poly::var(S);
        let s2 = s.pow(2);
        let (diag, w) = chain(
            self,
            |i| &Poly::var(&crate::spring_name(i)) + &(&s * &Poly::var(&crate::damper_name(i))),
            |k| &s2 * &Poly::var(&crate::mass_name(k)),
        );
        tridiagonal_bilinear(&diag, &w, &self.output_vector(), &self.input_vector())
    }

    /// The undamped inertance in `Omega` in normal form (see [`UndampedTf`]).
    ///
    /// ```
    /// let tf = mms::Model::from_id("A4").unwrap().undamped_tf();
    /// // eq. (34): Num_A4 = (c12 - m1*Omega)*(c23 - m3*Omega)
    /// assert_eq!(tf.num, "(c12 - m1*Omega)*(c23 - m3*Omega)".parse().unwrap());
    /// ```
    pub fn undamped_tf(&self) -> UndampedTf {
        let (p, det) = self.undamped_adjugate_form();
        let q = det
            .div_exact(&Poly::var(OMEGA))
            .expect("det(C - Omega*M) has the rigid-body factor Omega");
        // inertance = -Omega * receptance = -Omega*p/det = -p/q
        let (num, den) = normalize(-p, q, OMEGA);
        UndampedTf { num, den }
    }

    /// The damped transfer function in `s` for `output`, in normal form (see
    /// [`DampedTf`]).
    ///
    /// ```
    /// use mms::{Model, Output};
    /// let tf = Model::new(1, 0, mms::Port::new(1, 0), mms::Port::new(1, 0))
    ///     .unwrap()
    ///     .damped_tf(Output::Position);
    /// assert_eq!((tf.num.to_string(), tf.den.to_string()), ("1".into(), "m1*s^2".into()));
    /// ```
    pub fn damped_tf(&self, output: Output) -> DampedTf {
        let (p, det) = self.damped_adjugate_form();
        let s2 = Poly::var(S).pow(2);
        let q = det
            .div_exact(&s2)
            .expect("det(C + s*D + s^2*M) has the rigid-body factor s^2");
        let den = q.mul_var_pow(S, 2 - output.s_power());
        let (num, den) = normalize(p, den, S);
        DampedTf { output, num, den }
    }
}

impl UndampedTf {
    /// The normalized greatest common divisor of `num` and `den`
    /// ([`poly::gcd`]); `1` when they are coprime. A non-constant common
    /// factor is the signature of a degraded model.
    ///
    /// ```
    /// use mms::{Model, Port};
    /// // Gap 1 with the actuator against the ground: m1 is never excited.
    /// let m = Model::new(3, 1, Port::new(2, 0), Port::new(2, 1)).unwrap();
    /// assert_eq!(m.undamped_tf().common_factor(), "m1*Omega - c1".parse().unwrap());
    /// assert!(Model::from_id("B1").unwrap().undamped_tf().common_factor().is_constant());
    /// ```
    pub fn common_factor(&self) -> Poly {
        poly::gcd(&self.num, &self.den)
    }

    /// The transfer function with [`UndampedTf::common_factor`] cancelled,
    /// in normal form.
    pub fn reduced(&self) -> UndampedTf {
        let g = self.common_factor();
        let (num, den) = normalize(
            self.num.div_exact(&g).expect("gcd divides num"),
            self.den.div_exact(&g).expect("gcd divides den"),
            OMEGA,
        );
        UndampedTf { num, den }
    }

    /// The transfer function for `output`, with the factor `s`/`Omega`
    /// explicit (see [`OmegaTf`]).
    pub fn output(&self, output: Output) -> OmegaTf {
        let (sign, s_power, omega_power) = match output {
            Output::Acceleration => (1, 0, 0),
            Output::Velocity => (-1, 1, -1),
            Output::Position => (-1, 0, -1),
        };
        OmegaTf {
            output,
            sign,
            s_power,
            omega_power,
            num: self.num.clone(),
            den: self.den.clone(),
        }
    }

    /// The receptance (force to position) `-num/(Omega*den)`.
    pub fn receptance(&self) -> OmegaTf {
        self.output(Output::Position)
    }

    /// The mobility (force to velocity) `-s*num/(Omega*den)`.
    pub fn mobility(&self) -> OmegaTf {
        self.output(Output::Velocity)
    }

    /// The inertance (force to acceleration) `num/den`.
    pub fn inertance(&self) -> OmegaTf {
        self.output(Output::Acceleration)
    }

    /// Exact inertance at a parameter point and a value of `Omega`; `None`
    /// at a pole or when a parameter is missing.
    pub fn eval(
        &self,
        params: &std::collections::BTreeMap<String, Rat>,
        omega: &Rat,
    ) -> Option<Rat> {
        self.inertance().eval(params, omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Port;
    use std::collections::BTreeMap;

    /// The inlined power is the runtime's `powi`, bit for bit, so the
    /// sampler's draws do not move.
    #[test]
    fn power_is_powi_bit_for_bit() {
        let mut x = 0.137_f64;
        for _ in 0..2000 {
            // A deterministic spread over many magnitudes.
            x = (x * 7.31 + 0.017).fract() * 40.0 - 20.0;
            let v = x.exp() * x.signum();
            for e in -12..13 {
                assert_eq!(power(v, e).to_bits(), v.powi(e).to_bits(), "{v}^{e}");
            }
        }
    }

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    #[test]
    fn one_mass() {
        let m = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
        let tf = m.undamped_tf();
        assert_eq!((tf.num, tf.den), (p("1"), p("m1")));
    }

    #[test]
    fn two_mass_collocated_by_hand() {
        // Force and sensor on m1 of m1 -c12- m2 (free): X1/F = (c12 - m2 W)/(W (m1 m2 W - c12 (m1+m2)))
        // by hand from the 2x2 inverse; inertance = -W X1/F.
        let m = Model::new(2, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
        let tf = m.undamped_tf();
        assert_eq!(tf.num, p("m2*Omega - c12"));
        assert_eq!(tf.den, p("m1*m2*Omega - c12*m1 - c12*m2"));
    }

    #[test]
    fn normal_form_removes_joint_content_and_fixes_sign() {
        let (n, d) = normalize(p("-6*x + 4"), p("-2*x^2 + 8"), "x");
        assert_eq!((n, d), (p("3*x - 2"), p("x^2 - 4")));
    }

    /// The compiled coefficients against the exact polynomials evaluated
    /// over the rationals, and their log-gradients against central
    /// differences, on a 4-mass chain (powers up to the fourth).
    #[test]
    fn compiled_coefficients_match_exact_values_and_differences() {
        let m = Model::from_id("N4-g1-a2.1-s4.1").unwrap();
        let tf = m.undamped_tf();
        let names = m.undamped_parameters();
        let compiled = UndampedCoefficients::new(&m);
        let x: Vec<f64> = (0..names.len()).map(|i| 0.5 + 0.37 * i as f64).collect();
        let point: BTreeMap<String, Rat> = names
            .iter()
            .zip(&x)
            .map(|(n, v)| (n.clone(), Rat::from_f64(*v).unwrap()))
            .collect();
        let exact_at = |p: &Poly| -> Vec<f64> {
            p.coeffs_in(OMEGA)
                .iter()
                .map(|c| c.subs_point(&point).as_constant().unwrap().to_f64())
                .collect()
        };
        let (num, den) = compiled.eval(&x);
        let with = compiled.eval_with_log_gradients(&x);
        for (got, want) in [(&num, exact_at(&tf.num)), (&den, exact_at(&tf.den))] {
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() <= 1e-13 * w.abs().max(1.0), "{g} vs {w}");
            }
        }
        assert_eq!((&with.num, &with.den), (&num, &den));
        // d c / d log x_j = x_j d c / d x_j, by central differences in log x_j.
        let h = 1e-6;
        for j in 0..x.len() {
            let shifted = |s: f64| {
                let mut y = x.clone();
                y[j] *= s.exp();
                compiled.eval(&y).1
            };
            let (up, down) = (shifted(h), shifted(-h));
            for (i, g) in (0..den.len()).map(|i| (i, with.den_gradient.row(i)[j])) {
                let fd = (up[i] - down[i]) / (2.0 * h);
                assert!(
                    (g - fd).abs() <= 1e-6 * fd.abs().max(1.0),
                    "coefficient {i}, {j}: {g} vs {fd}"
                );
            }
        }
    }

    #[test]
    fn output_names_parse() {
        assert_eq!("Inertance".parse::<Output>().unwrap(), Output::Acceleration);
        assert_eq!("mobility".parse::<Output>().unwrap(), Output::Velocity);
        assert!("jerk".parse::<Output>().is_err());
    }
}

/// A structure's undamped inertance coefficients (ascending in `Omega`) as
/// fast `f64` functions of its undamped parameters (in the order of
/// [`Model::undamped_parameters`]): for searches and starts that evaluate
/// the TF at many points.
///
/// ```
/// use mms::UndampedCoefficients;
/// let a2 = mms::Model::from_id("A2").unwrap();
/// let (num, den) = UndampedCoefficients::new(&a2).eval(&[1.0; 5]);
/// let exact = a2.undamped_tf();
/// assert_eq!(num.len() as u32, exact.num.degree(mms::OMEGA) + 1);
/// assert_eq!(den.len() as u32, exact.den.degree(mms::OMEGA) + 1);
/// // Den at Omega = 0 is c12 c23 (m1 + m2 + m3) = 3.
/// assert_eq!(den[0], 3.0);
/// ```
#[derive(Clone, Debug)]
pub struct UndampedCoefficients {
    num: Vec<Compiled>,
    den: Vec<Compiled>,
}

/// Numerator and denominator coefficients (ascending) at a point, with
/// their derivatives in the logarithms of the parameters.
#[derive(Clone, Debug)]
pub(crate) struct CoefficientsWithGradients {
    pub num: Vec<f64>,
    pub den: Vec<f64>,
    pub num_gradient: Gradients,
    pub den_gradient: Gradients,
}

/// The gradients of a list of coefficients, one row per coefficient, in
/// one buffer: the sampler evaluates them at every Gauss-Newton step, and
/// a buffer per row made the allocator the largest cost there.
#[derive(Clone, Debug)]
pub(crate) struct Gradients {
    width: usize,
    data: Vec<f64>,
}

impl Gradients {
    /// The gradient of coefficient `i`.
    pub(crate) fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.width..(i + 1) * self.width]
    }
}

/// Each of `cs` at `x`, with its derivatives in the logarithms of the
/// parameters.
pub(crate) fn eval_with_log_gradients(cs: &[Compiled], x: &[f64]) -> (Vec<f64>, Gradients) {
    let width = x.len();
    let powers = Powers::new(cs, x);
    let mut data = vec![0.0; cs.len() * width];
    let values = cs
        .iter()
        .enumerate()
        .map(|(i, c)| c.eval_with_log_gradient_at(&powers, &mut data[i * width..(i + 1) * width]))
        .collect();
    (values, Gradients { width, data })
}

/// Every power of every parameter that a list of [`Compiled`] raises it
/// to, each by [`power`] once per point instead of once per term (the
/// same bits: a term multiplies the same factors in the same order).
struct Powers {
    stride: usize,
    data: Vec<f64>,
}

impl Powers {
    fn new(cs: &[Compiled], x: &[f64]) -> Powers {
        let top = cs.iter().map(|c| c.top).max().unwrap_or(0) as usize;
        let stride = top + 1;
        let mut data = vec![1.0; x.len() * stride];
        for (i, &v) in x.iter().enumerate() {
            for e in 1..=top {
                data[i * stride + e] = power(v, e as i32);
            }
        }
        Powers { stride, data }
    }

    #[inline]
    fn get(&self, i: u32, e: i32) -> f64 {
        self.data[i as usize * self.stride + e as usize]
    }

    /// A term's value: its coefficient times its factors, in order.
    #[inline]
    fn term(&self, c: f64, factors: &[(u32, i32)]) -> f64 {
        factors.iter().fold(c, |acc, &(i, e)| acc * self.get(i, e))
    }
}

/// A polynomial in the parameters, its terms' coefficients with the end of
/// their factors `(parameter, power)` in one list (fewer pointers to
/// follow than a list per term).
#[derive(Clone, Debug)]
pub(crate) struct Compiled {
    terms: Vec<(f64, u32)>,
    factors: Vec<(u32, i32)>,
    /// The largest power of a parameter.
    top: u32,
}

/// `x^e` by the square-and-multiply of the runtime's `powi`
/// (compiler-builtins' `__powidf2`), the same products in the same order,
/// so the same bits, but inlined: the sampler raises to a power at every
/// term of every step, and the call was a tenth of its time.
#[inline]
pub(crate) fn power(mut x: f64, e: i32) -> f64 {
    let mut n = e.unsigned_abs();
    let mut r = 1.0;
    loop {
        if n & 1 != 0 {
            r *= x;
        }
        n >>= 1;
        if n == 0 {
            break;
        }
        x *= x;
    }
    if e < 0 {
        1.0 / r
    } else {
        r
    }
}

/// A term's value at `x`: its coefficient times its factors, in order.
fn term_value(c: f64, powers: &[(u32, i32)], x: &[f64]) -> f64 {
    powers
        .iter()
        .fold(c, |acc, &(i, e)| acc * power(x[i as usize], e))
}

impl Compiled {
    pub(crate) fn new(p: &Poly, names: &[String]) -> Compiled {
        let index: Vec<u32> = p
            .vars()
            .iter()
            .map(|v| {
                names
                    .iter()
                    .position(|n| n == v)
                    .expect("parameter of the model") as u32
            })
            .collect();
        let mut terms = Vec::with_capacity(p.terms().len());
        let mut factors = Vec::new();
        for t in p.terms() {
            factors.extend(
                t.exps
                    .iter()
                    .enumerate()
                    .filter(|(_, &e)| e > 0)
                    .map(|(i, &e)| (index[i], e as i32)),
            );
            terms.push((t.coef.to_f64(), factors.len() as u32));
        }
        let top = factors.iter().map(|&(_, e)| e as u32).max().unwrap_or(0);
        Compiled {
            terms,
            factors,
            top,
        }
    }

    pub(crate) fn eval(&self, x: &[f64]) -> f64 {
        self.terms(x).sum()
    }

    /// The value at the point whose `powers` are given.
    fn eval_at(&self, powers: &Powers) -> f64 {
        self.each_term().map(|(c, f)| powers.term(c, f)).sum()
    }

    /// The value and, added into `grad`, its derivatives in the logarithms
    /// of the parameters (each term's value times its power), at the point
    /// whose `powers` are given.
    fn eval_with_log_gradient_at(&self, powers: &Powers, grad: &mut [f64]) -> f64 {
        let mut sum = 0.0;
        for (c, factors) in self.each_term() {
            let t = powers.term(c, factors);
            sum += t;
            for &(i, e) in factors {
                grad[i as usize] += f64::from(e) * t;
            }
        }
        sum
    }

    /// Each term's value at `x`.
    fn terms<'a>(&'a self, x: &'a [f64]) -> impl Iterator<Item = f64> + 'a {
        self.each_term().map(|(c, powers)| term_value(c, powers, x))
    }

    /// Each term's coefficient and factors `(parameter, power)`.
    fn each_term(&self) -> impl Iterator<Item = (f64, &[(u32, i32)])> {
        let mut start = 0;
        self.terms.iter().map(move |&(c, end)| {
            let powers = &self.factors[start..end as usize];
            start = end as usize;
            (c, powers)
        })
    }

    /// The value at `x` divided by the sum of its terms' moduli: in
    /// `[-1, 1]`, and comparable between polynomials of any size (`0` for
    /// the zero polynomial).
    pub(crate) fn relative(&self, x: &[f64]) -> f64 {
        let (mut sum, mut scale) = (0.0, 0.0);
        for t in self.terms(x) {
            sum += t;
            scale += t.abs();
        }
        if scale > 0.0 {
            sum / scale
        } else {
            0.0
        }
    }
}

impl UndampedCoefficients {
    /// Compiles `model`'s undamped inertance.
    pub fn new(model: &Model) -> UndampedCoefficients {
        let tf = model.undamped_tf();
        let names = model.undamped_parameters();
        let compile = |p: &Poly| -> Vec<Compiled> {
            p.coeffs_in(OMEGA)
                .iter()
                .map(|c| Compiled::new(c, &names))
                .collect()
        };
        UndampedCoefficients {
            num: compile(&tf.num),
            den: compile(&tf.den),
        }
    }

    /// Numerator and denominator coefficients at `x`, ascending.
    pub fn eval(&self, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let values = |cs: &[Compiled]| {
            let powers = Powers::new(cs, x);
            cs.iter().map(|c| c.eval_at(&powers)).collect()
        };
        (values(&self.num), values(&self.den))
    }

    /// As [`Self::eval`], with each coefficient's derivatives in the
    /// logarithms of the parameters (a row per coefficient).
    pub(crate) fn eval_with_log_gradients(&self, x: &[f64]) -> CoefficientsWithGradients {
        let (num, num_gradient) = eval_with_log_gradients(&self.num, x);
        let (den, den_gradient) = eval_with_log_gradients(&self.den, x);
        CoefficientsWithGradients {
            num,
            den,
            num_gradient,
            den_gradient,
        }
    }
}
