//! Structural identifiability and structural equivalence of the undamped
//! models (Sec. 5 and Tab. 5 of the paper), exactly over Q.
//!
//! # Moment invariants
//!
//! The undamped inertance `num/den` ([`Model::undamped_tf`], with a common
//! factor of `num` and `den` cancelled, see [`UndampedTf::reduced`]) is
//! normalized by the leading coefficient `lc(den)` of its denominator in
//! [`OMEGA`]. Its *moment invariants* (Vajda 1981) are the rational
//! functions of the parameters
//!
//! ```text
//! coef_k(num) / lc(den)   and   coef_k(den) / lc(den)
//! ```
//!
//! for every power `Omega^k` present in `num` resp. `den`
//! ([`moment_invariants`]). Two parameter points at which `num` and `den`
//! have no common root give the same transfer function exactly when all
//! moment invariants agree. The leading `1` of the
//! denominator is always constant; an invariant is *not identically
//! constant* when it depends on a parameter. Zero coefficients (powers of
//! `Omega` that do not occur) are not listed; they are constant anyway.
//!
//! Normalizing by `lc(den)` instead of the paper's "first denominator
//! coefficient" `den(0)` changes neither the rank below (both sets generate
//! the same field of rational functions: `x/den(0) = (x/lc)/(den(0)/lc)`)
//! nor, for these models, the count of non-constant invariants.
//!
//! # Determinable parameters
//!
//! The number of *determinable parameters* is the generic rank of the
//! Jacobian `J` of the non-constant moment invariants with respect to the
//! undamped parameters ([`Model::undamped_parameters`]: masses and springs).
//! [`identifiability`] works with the polynomial matrix
//! `L = diag(lc-power) * J * diag(p)` (rows cleared of denominators, columns
//! scaled by the parameters), which has the same generic rank, and
//! establishes it as follows ([`RankCertificate`]):
//!
//! 1. **Lower bound, always proven.** The exact rank over Q of `L` at up to
//!    four pseudo-random positive integer points (fixed seed, so results are
//!    deterministic). A minor that does not vanish at a point is a non-zero
//!    polynomial, so the generic rank is at least the rank at any point.
//! 2. **Upper bound by counting or symmetry.** The rank can never exceed
//!    the number of parameters nor the number of non-constant invariants,
//!    nor the number of parameters minus the dimension of the group of
//!    *scaling symmetries* `p_i -> t^(w_i) p_i` leaving every invariant
//!    unchanged ([`ScalingSymmetry`], found exactly from the exponent
//!    vectors: each independent weight vector `w` gives the kernel vector
//!    `(w_i p_i)_i` of `J`). If the sampled rank reaches this bound, it is
//!    proven ([`RankCertificate::Counting`],
//!    [`RankCertificate::ScalingSymmetries`]).
//! 3. **Exact rank by symbolic elimination.** Otherwise `L` is eliminated
//!    fraction-free (Bareiss) over the field of rational functions,
//!    pivoting on the non-singular block found at the random point; after
//!    `r` steps the remaining entries are exactly the `(r+1)`-minors that
//!    border that block, and the rank is `r` iff they all vanish
//!    identically ([`RankCertificate::SymbolicElimination`]). Since every
//!    row of `L` is homogeneous in the masses and in the springs, one mass
//!    and one spring are set to 1 first, which is exact for the zero test of
//!    homogeneous minors. This proves the rank of all eleven 3-mass models
//!    (B2, C2, C4) and of every model with 4 and 5 masses (below a second
//!    per model in a debug build).
//! 4. If the elimination exceeds its work limit
//!    ([`RankOptions::symbolic_work_limit`]; most 6-mass models do), the
//!    sampled rank is reported unproven ([`RankCertificate::Sampled`]). It is then the
//!    generic rank unless every sampled point is a common zero of all the
//!    maximal non-vanishing minors; by the Schwartz-Zippel lemma each point
//!    is one with probability at most `deg / 2^30`, `deg` the degree of such
//!    a minor.
//!
//! *Why the uniform scaling gives no bound here.* Scaling all masses and
//! springs by one factor `t` leaves the denominator invariants
//! `coef_k(den)/lc(den)` unchanged (all coefficients of `den` are
//! homogeneous of degree `N`), but `num` is homogeneous of degree `N - 1`,
//! so `coef_k(num)/lc(den)` is multiplied by `1/t`: the inertance carries the
//! gain, and scaling all masses and springs scales the gain. The Euler
//! relation gives `J p = (-f_num, 0)`, not zero: the uniform scaling is no
//! symmetry, and `#parameters - 1` is *not* an upper bound. The same holds
//! for the two-parameter family of weighted scalings (masses by `t^a`,
//! springs by `t^b`, `Omega` by `t^(b-a)`): `coef_k(num)/lc(den)` has weight
//! `(k - N) a + (N - 1 - k) b` and `coef_k(den)/lc(den)` has weight
//! `(k + 1 - N)(a - b)`, which all vanish only for `a = b = 0`. General
//! diagonal scalings are searched by [`ScalingSymmetry`]; for all models
//! with 3 to 5 masses there are none. So the 5 determinable parameters of A1
//! (out of 5) are consistent: the gain normalization of the paper's Tab. 5
//! is what makes full identifiability possible.
//!
//! # Structural equivalence
//!
//! Two models with the same number of masses are *structurally equivalent*
//! ([`structural_equivalences`]) when
//!
//! - their transfer functions are identical after a renaming of parameters
//!   induced by a renumbering of the masses ([`identical_transfer_functions`]:
//!   the identity, e.g. a model and its reciprocal such as C2 and C4, or the
//!   mirroring of the free part, see [`Model::mirrored`]); this is checked
//!   exactly, not assumed, and also finds identities beyond renumbering and
//!   reciprocity (see [`ParameterRenaming::Identity`]); or
//! - Vajda's criterion as the paper applies it (Sec. 5, A2 and A5): both
//!   have the same symbolic form ([`Identifiability::same_form`]: the same
//!   powers of `Omega` in numerator and denominator, the same constant
//!   invariants, the same fixed signs on positive parameters, and so the
//!   same number of non-constant invariants), and in both the non-constant
//!   invariants are independent (determinable parameters = non-constant
//!   invariants). Then each parameter map covers an open set of the common
//!   coefficient space; the criterion is generic (it says nothing about
//!   the parameter sets of measure zero, e.g. pole-zero cancellation).
//!
//! For the eleven 3-mass models this gives the groups {A1, A4, B1, C1, C3}
//! (the collocated models, by Vajda's criterion; cf. Tab. 7 of the paper),
//! {A2, A5} and {C2, C4}. A2 and A5 satisfy Vajda's criterion as the paper
//! states, but they are even identical up to renaming: A5 is the reciprocal
//! of the mirrored A2 (`m1 <-> m3`, `c12 <-> c23`), a pair that the paper's
//! rule (3) keeps as two models (see [`crate::redundancy_report`] with
//! [`crate::Symmetry::RenumberingAndReciprocity`]). B2, C2 and C4 have the same
//! form as the collocated models but only 4 determinable parameters, so the
//! criterion does not apply (the paper's second example: C2 cannot fit B2).
//!
//! ```
//! use mms::{identifiability, Model, RankCertificate};
//!
//! let a2 = identifiability(&Model::from_id("A2")?);
//! assert_eq!(a2.parameters, ["m1", "m2", "m3", "c12", "c23"]);
//! assert_eq!(a2.nonconstant_invariants, 4);
//! assert_eq!(a2.determinable_parameters, 4);
//! assert!(a2.is_proven()); // the rank cannot exceed the 4 invariants
//! assert_eq!(a2.invariants[0].to_string(), "Num Omega^1: -c12/(m1*m2)");
//!
//! let c2 = identifiability(&Model::from_id("C2")?);
//! assert_eq!((c2.nonconstant_invariants, c2.determinable_parameters), (5, 4));
//! assert_eq!(c2.certificate, RankCertificate::SymbolicElimination); // proven 4, not 5
//! # Ok::<(), mms::ModelError>(())
//! ```

use crate::model::{mass_name, spring_name, Model};
use crate::tf::{UndampedTf, OMEGA};
use crate::xorshift::XorShift;
use poly::{Int, Poly, Rat};
use serde::{Serialize, Serializer};
use std::collections::BTreeMap;
use std::fmt;

fn ser_display<T: fmt::Display, S: Serializer>(x: &T, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(x)
}

/// The polynomial of the transfer function a [`MomentInvariant`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum TfPart {
    /// The numerator `num`.
    Numerator,
    /// The denominator `den`.
    Denominator,
}

impl TfPart {
    /// `Num` or `Den`.
    pub fn as_str(self) -> &'static str {
        match self {
            TfPart::Numerator => "Num",
            TfPart::Denominator => "Den",
        }
    }
}

/// One moment invariant `coef_k(part) / lc(den)`, as a reduced fraction
/// `numerator / denominator` of polynomials in the parameters.
///
/// Normal form: `numerator` and `denominator` are coprime, `denominator` has
/// integer coefficients without common factor and a positive leading
/// coefficient, so two invariants are equal exactly when their fields are.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct MomentInvariant {
    /// Numerator or denominator of the transfer function.
    pub part: TfPart,
    /// The power `k` of `Omega` whose coefficient this is.
    pub power: u32,
    /// Numerator of the reduced fraction.
    #[serde(serialize_with = "ser_display")]
    pub numerator: Poly,
    /// Denominator of the reduced fraction.
    #[serde(serialize_with = "ser_display")]
    pub denominator: Poly,
}

impl MomentInvariant {
    /// `coef / lead`, reduced and normalized.
    fn new(part: TfPart, power: u32, coef: &Poly, lead: &Poly) -> MomentInvariant {
        let g = poly::gcd(coef, lead);
        let a = coef.div_exact(&g).expect("the gcd divides its argument");
        let b = lead.div_exact(&g).expect("the gcd divides its argument");
        let (cb, b) = b.primitive();
        MomentInvariant {
            part,
            power,
            numerator: a.scale(&cb.recip()),
            denominator: b,
        }
    }

    /// True when the invariant does not depend on any parameter.
    pub fn is_constant(&self) -> bool {
        self.numerator.is_constant() && self.denominator.is_constant()
    }

    /// The value of a constant invariant; `None` for a non-constant one.
    pub fn constant_value(&self) -> Option<Rat> {
        let n = self.numerator.as_constant()?;
        let d = self.denominator.as_constant()?;
        Some(&n / &d)
    }

    /// The sign (+1 or -1) the invariant has at every point with all
    /// parameters positive, when the coefficients of its numerator and of
    /// its denominator each have one sign; `None` otherwise.
    pub fn sign_on_positive_parameters(&self) -> Option<i32> {
        let sign = |p: &Poly| {
            if p.all_coefs_positive() {
                Some(1)
            } else if p.all_coefs_negative() {
                Some(-1)
            } else {
                None
            }
        };
        Some(sign(&self.numerator)? * sign(&self.denominator)?)
    }

    /// Exact value at a parameter point; `None` if a parameter is missing
    /// or the denominator vanishes there.
    pub fn eval(&self, point: &BTreeMap<String, Rat>) -> Option<Rat> {
        let d = self.denominator.eval(point).ok()?;
        if d.is_zero() {
            return None;
        }
        Some(&self.numerator.eval(point).ok()? / &d)
    }

    /// The fraction as text: `-c12/(m1*m2)`, `1`.
    pub fn fraction(&self) -> String {
        let n = &self.numerator;
        let d = &self.denominator;
        if d.is_constant() {
            // The denominator is primitive, hence 1.
            return n.to_string();
        }
        let n = if n.num_terms() > 1 {
            format!("({n})")
        } else {
            n.to_string()
        };
        if d.num_terms() > 1 || d.total_degree() > 1 || !d.leading_coef().is_one() {
            format!("{n}/({d})")
        } else {
            format!("{n}/{d}")
        }
    }
}

impl fmt::Display for MomentInvariant {
    /// `Num Omega^1: -c12/(m1*m2)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} {OMEGA}^{}: {}",
            self.part.as_str(),
            self.power,
            self.fraction()
        )
    }
}

/// The moment invariants of a transfer function: `coef_k(num)/lc(den)` and
/// `coef_k(den)/lc(den)` for the powers `k` of [`OMEGA`] present, the
/// numerator's first, each part by descending power.
///
/// The transfer function is used as given; cancel a common factor first
/// ([`UndampedTf::reduced`]) to get the invariants of the input-output
/// behaviour ([`identifiability`] does).
///
/// ```
/// use mms::{moment_invariants, Model};
/// let tf = Model::from_id("A3")?.undamped_tf();
/// let text: Vec<String> = moment_invariants(&tf).iter().map(|i| i.to_string()).collect();
/// assert_eq!(text[0], "Num Omega^0: c12*c23/(m1*m2*m3)");
/// assert_eq!(text[1], "Den Omega^2: 1");
/// assert_eq!(text.len(), 4);
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn moment_invariants(tf: &UndampedTf) -> Vec<MomentInvariant> {
    let lead = tf.den.lead_in(OMEGA);
    let mut out = Vec::new();
    for (part, p) in [(TfPart::Numerator, &tf.num), (TfPart::Denominator, &tf.den)] {
        for (k, c) in p.coeffs_in(OMEGA).iter().enumerate().rev() {
            if !c.is_zero() {
                out.push(MomentInvariant::new(part, k as u32, c, &lead));
            }
        }
    }
    out
}

/// A one-parameter group of scalings `p_i -> t^(w_i) p_i` of the
/// parameters under which every moment invariant is unchanged: a proven
/// direction in which the parameters cannot be determined.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct ScalingSymmetry {
    /// The non-zero integer weights `w_i` (coprime, first one positive), by
    /// parameter name in the order of [`Identifiability::parameters`].
    #[serde(serialize_with = "ser_weights")]
    pub weights: Vec<(String, Int)>,
}

fn ser_weights<S: Serializer>(w: &[(String, Int)], s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(Some(w.len()))?;
    for (name, x) in w {
        m.serialize_entry(name, &x.to_string())?;
    }
    m.end()
}

impl fmt::Display for ScalingSymmetry {
    /// `m1^1 c1^-1`: the exponents of `t`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (name, w)) in self.weights.iter().enumerate() {
            if i > 0 {
                f.write_str(" ")?;
            }
            write!(f, "{name}^{w}")?;
        }
        Ok(())
    }
}

/// Identifiability of the undamped model: the columns of Tab. 5 of the
/// paper and the data behind them. See the [module documentation](self)
/// for what is proven and what is probabilistic.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Identifiability {
    /// The model.
    pub model: Model,
    /// The undamped parameters, masses then springs
    /// ([`Model::undamped_parameters`]).
    pub parameters: Vec<String>,
    /// All moment invariants (see [`moment_invariants`]) of the reduced
    /// undamped transfer function, constant ones included.
    pub invariants: Vec<MomentInvariant>,
    /// Number of not identically constant moment invariants (Tab. 5).
    pub nonconstant_invariants: usize,
    /// Number of determinable parameters (Tab. 5): the generic rank of the
    /// Jacobian of the non-constant invariants with respect to the
    /// parameters. Always a proven lower bound; proven exact when
    /// [`Identifiability::is_proven`], otherwise the rank at sampled points
    /// (exact with overwhelming probability).
    pub determinable_parameters: usize,
    /// A proven upper bound of the generic rank: equal to
    /// `determinable_parameters` when proven, otherwise the least of the
    /// number of parameters, the number of non-constant invariants and the
    /// number of parameters minus the number of scaling symmetries.
    pub rank_upper_bound: usize,
    /// How [`Identifiability::determinable_parameters`] is established.
    pub certificate: RankCertificate,
    /// A basis of the scaling symmetries of the invariants (empty for every
    /// degradation-free model with 3 to 5 masses; a parameter missing from
    /// the reduced transfer function of a degraded model is one).
    pub scaling_symmetries: Vec<ScalingSymmetry>,
    /// The directions in which the parameters can move without changing
    /// any moment invariant, hence the FRF: `parameters.len() -
    /// determinable_parameters` of them, independent, spanning the kernel
    /// of the Jacobian. Each is a proof of the upper bound that a checker
    /// verifies by multiplication (the Jacobian times the direction is the
    /// zero polynomial). Empty when every parameter is determinable, or
    /// when the rank is only [`RankCertificate::Sampled`].
    pub unidentifiable_directions: Vec<UnidentifiableDirection>,
}

/// A polynomial vector field on the parameters along which every moment
/// invariant of the model is constant: moving the parameters along it
/// leaves the FRF unchanged, so the data cannot tell those parameter sets
/// apart.
///
/// ```
/// use mms::{identifiability, Model};
/// // B2: m2 and m3 hang on c23 beyond the sensor; only combinations of
/// // them reach the FRF.
/// let id = identifiability(&Model::from_id("B2")?);
/// assert_eq!(id.unidentifiable_directions.len(), 1);
/// let d = &id.unidentifiable_directions[0];
/// assert_eq!(d.to_string(), "m2: -m2*m3, m3: m2*m3, c23: c23*m2 - c23*m3");
/// # Ok::<(), mms::ModelError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnidentifiableDirection {
    /// `(parameter, component)` in the order of the parameters; zero
    /// components are left out.
    pub components: Vec<(String, Poly)>,
}

impl fmt::Display for UnidentifiableDirection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (name, c)) in self.components.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{name}: {c}")?;
        }
        Ok(())
    }
}

impl Serialize for UnidentifiableDirection {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.components.len()))?;
        for (name, c) in &self.components {
            map.serialize_entry(name, &c.to_string())?;
        }
        map.end()
    }
}

/// Read back in the file's order of the parameters (a JSON file written
/// through a sorted map lists them by name).
impl<'de> serde::Deserialize<'de> for UnidentifiableDirection {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Components;
        impl<'de> serde::de::Visitor<'de> for Components {
            type Value = UnidentifiableDirection;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a map from parameter names to polynomials")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut map: A,
            ) -> Result<Self::Value, A::Error> {
                let mut components = Vec::new();
                while let Some(entry) = map.next_entry::<String, Poly>()? {
                    components.push(entry);
                }
                Ok(UnidentifiableDirection { components })
            }
        }
        d.deserialize_map(Components)
    }
}

/// How the number of determinable parameters (the generic rank of the
/// Jacobian) is established. The rank at a random point is always a proven
/// lower bound; the variants say what proves the upper bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum RankCertificate {
    /// The rank equals the number of parameters or of non-constant
    /// invariants, which it can never exceed.
    Counting,
    /// The rank equals the number of parameters minus the number of
    /// independent [`ScalingSymmetry`]s.
    ScalingSymmetries,
    /// Exact fraction-free elimination of the (scaled) Jacobian over the
    /// field of rational functions: all minors bordering a non-singular
    /// block vanish identically.
    SymbolicElimination,
    /// Not proven: the symbolic elimination was too large. The rank at the
    /// sampled points, exact with overwhelming probability.
    Sampled,
}

impl Identifiability {
    /// True when the number of determinable parameters is proven (lower
    /// bound = upper bound).
    pub fn is_proven(&self) -> bool {
        self.certificate != RankCertificate::Sampled
    }

    /// True when the non-constant moment invariants are independent:
    /// determinable parameters = non-constant invariants (Vajda's condition).
    /// A `true` is proven (the rank is a proven lower bound and can never
    /// exceed the number of invariants).
    pub fn invariants_independent(&self) -> bool {
        self.determinable_parameters == self.nonconstant_invariants
    }

    /// True when all parameters are locally identifiable: determinable
    /// parameters = parameters (proven when `true`).
    pub fn is_locally_identifiable(&self) -> bool {
        self.determinable_parameters == self.parameters.len()
    }

    /// The powers of `Omega` present in the numerator, descending.
    pub fn numerator_powers(&self) -> Vec<u32> {
        self.powers(TfPart::Numerator)
    }

    /// The powers of `Omega` present in the denominator, descending.
    pub fn denominator_powers(&self) -> Vec<u32> {
        self.powers(TfPart::Denominator)
    }

    fn powers(&self, part: TfPart) -> Vec<u32> {
        self.invariants
            .iter()
            .filter(|i| i.part == part)
            .map(|i| i.power)
            .collect()
    }

    /// Same symbolic form of the transfer function: the same number of
    /// masses, the same invariants (part and power of `Omega`), the same
    /// constant invariants with the same values, and the same fixed signs
    /// on positive parameters ([`MomentInvariant::sign_on_positive_parameters`]).
    pub fn same_form(&self, other: &Identifiability) -> bool {
        self.model.n_masses() == other.model.n_masses()
            && self.invariants.len() == other.invariants.len()
            && self.invariants.iter().zip(&other.invariants).all(|(a, b)| {
                a.part == b.part
                    && a.power == b.power
                    && a.constant_value() == b.constant_value()
                    && a.sign_on_positive_parameters() == b.sign_on_positive_parameters()
            })
    }

    /// Vajda's criterion as the paper uses it (Sec. 5): the same symbolic
    /// form and, in both models, independent non-constant invariants.
    pub fn structurally_equivalent_by_invariants(&self, other: &Identifiability) -> bool {
        self.same_form(other) && self.invariants_independent() && other.invariants_independent()
    }
}

/// Settings of the rank computation of [`identifiability_with`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct RankOptions {
    /// Number of pseudo-random points at which the Jacobian is evaluated
    /// (the search stops at the first that reaches the proven upper bound).
    /// Default 4.
    pub points: usize,
    /// Seed of the point generator (xorshift64*; 0 is taken as 1). The default
    /// is fixed, so results are reproducible.
    pub seed: u64,
    /// Budget of the symbolic elimination, in products of term counts of
    /// multiplied polynomials; beyond it the rank stays
    /// [`RankCertificate::Sampled`]. The default, `2 * 10^7`, is about three
    /// times what the hardest 5-mass model needs (about a second in a debug
    /// build) and gives up on most 6-mass models; 0 disables the
    /// elimination, `u64::MAX` removes the limit.
    pub symbolic_work_limit: u64,
}

impl Default for RankOptions {
    fn default() -> RankOptions {
        RankOptions {
            points: 4,
            seed: 0x9e37_79b9_7f4a_7c15,
            symbolic_work_limit: 20_000_000,
        }
    }
}

/// Sample points for the rank: positive integers.
trait PositiveSample {
    /// A positive integer in `1 ..= 2^30`.
    fn positive(&mut self) -> Rat;
}

impl PositiveSample for XorShift {
    fn positive(&mut self) -> Rat {
        Rat::from(((self.next_u64() >> 34) + 1) as i64)
    }
}

/// A basis of the null space `{w : rows * w = 0}` over Q, each vector scaled
/// to coprime integers with a positive first non-zero entry.
fn null_space(rows: &[Vec<Rat>], cols: usize) -> Vec<Vec<Int>> {
    // Reduced row echelon form.
    let mut m: Vec<Vec<Rat>> = rows.to_vec();
    let mut pivots = Vec::new();
    let mut r = 0;
    for c in 0..cols {
        let Some(p) = (r..m.len()).find(|&i| !m[i][c].is_zero()) else {
            continue;
        };
        m.swap(r, p);
        let inv = m[r][c].recip();
        m[r] = m[r].iter().map(|x| x * &inv).collect();
        let pivot = m[r].clone();
        for (i, row) in m.iter_mut().enumerate() {
            if i != r && !row[c].is_zero() {
                let f = row[c].clone();
                for (x, y) in row.iter_mut().zip(&pivot) {
                    *x = &*x - &(&f * y);
                }
            }
        }
        pivots.push(c);
        r += 1;
    }
    let mut basis = Vec::new();
    for free in (0..cols).filter(|c| !pivots.contains(c)) {
        let mut w = vec![Rat::ZERO; cols];
        w[free] = Rat::ONE;
        for (i, &pc) in pivots.iter().enumerate() {
            w[pc] = -m[i][free].clone();
        }
        // Clear denominators, divide by the content.
        let mut den = Int::ONE;
        for x in &w {
            den = den.lcm(x.denom());
        }
        let mut ints: Vec<Int> = w
            .iter()
            .map(|x| x.numer() * &den.div_exact(x.denom()))
            .collect();
        let g = ints.iter().fold(Int::ZERO, |g, x| g.gcd(x));
        let negative = ints
            .iter()
            .find(|x| !x.is_zero())
            .is_some_and(Int::is_negative);
        for x in &mut ints {
            *x = x.div_exact(&g);
            if negative {
                *x = -x.clone();
            }
        }
        basis.push(ints);
    }
    basis
}

/// Exponent vector of each term of `p` over `params` (variables not in
/// `params` are ignored; they do not occur in moment invariants).
fn exponent_vectors(p: &Poly, params: &[String]) -> Vec<Vec<Rat>> {
    let idx: Vec<Option<usize>> = p
        .vars()
        .iter()
        .map(|v| params.iter().position(|q| q == v))
        .collect();
    p.terms()
        .iter()
        .map(|t| {
            let mut e = vec![Rat::ZERO; params.len()];
            for (x, i) in t.exps.iter().zip(&idx) {
                if let Some(i) = i {
                    e[*i] = Rat::from(*x as i64);
                }
            }
            e
        })
        .collect()
}

/// The scaling symmetries of the invariants: weights `w` such that every
/// term of the numerator and of the denominator of every invariant has the
/// same weighted degree `e . w`.
fn scaling_symmetries(params: &[String], invs: &[&MomentInvariant]) -> Vec<ScalingSymmetry> {
    let mut rows = Vec::new();
    for inv in invs {
        let mut e = exponent_vectors(&inv.numerator, params);
        e.extend(exponent_vectors(&inv.denominator, params));
        let (first, rest) = e.split_first().expect("an invariant has terms");
        rows.extend(
            rest.iter()
                .map(|x| x.iter().zip(first).map(|(a, b)| a - b).collect()),
        );
    }
    null_space(&rows, params.len())
        .into_iter()
        .map(|w| ScalingSymmetry {
            weights: params
                .iter()
                .zip(w)
                .filter(|(_, x)| !x.is_zero())
                .map(|(n, x)| (n.clone(), x))
                .collect(),
        })
        .collect()
}

/// The scaled Jacobian `L = diag(r_i) * J * diag(p_j)` of the invariants
/// `a_i/b_i` with respect to `params`: a polynomial matrix with the generic
/// rank of `J` (the scalings are invertible over `Q(p)`).
///
/// For a monomial `b_i` (always the case here: `lc(den)` is a product of
/// masses) `r_i = b_i` and `L_ij = p_j da_i/dp_j - e_ij a_i`, `e_ij` the
/// exponent of `p_j` in `b_i`; otherwise `r_i = b_i^2` and
/// `L_ij = p_j (b_i da_i/dp_j - a_i db_i/dp_j)`.
fn scaled_jacobian(params: &[String], invs: &[&MomentInvariant]) -> Vec<Vec<Poly>> {
    invs.iter()
        .map(|inv| {
            let (a, b) = (&inv.numerator, &inv.denominator);
            params
                .iter()
                .map(|p| {
                    let pj = Poly::var(p);
                    if b.num_terms() == 1 {
                        let e = Rat::from(b.degree(p) as i64);
                        &(&pj * &a.derivative(p)) - &a.scale(&e)
                    } else {
                        let d = &(b * &a.derivative(p)) - &(a * &b.derivative(p));
                        &pj * &d
                    }
                })
                .collect()
        })
        .collect()
}

/// Rank of the polynomial matrix `l` at up to `options.points`
/// pseudo-random positive integer points: the pivots of the best point,
/// stopping early when their number reaches `bound`. A minor that does not
/// vanish at a point is a non-zero polynomial, so the rank is a proven lower
/// bound of the generic rank.
fn sampled_pivots(
    l: &[Vec<Poly>],
    params: &[String],
    bound: usize,
    options: &RankOptions,
) -> Vec<(usize, usize)> {
    let mut rng = XorShift::new(options.seed);
    let mut best = Vec::new();
    if bound == 0 {
        return best;
    }
    for _ in 0..options.points {
        let point: BTreeMap<String, Rat> =
            params.iter().map(|p| (p.clone(), rng.positive())).collect();
        let rows = l
            .iter()
            .map(|row| {
                row.iter()
                    .map(|x| {
                        x.eval(&point)
                            .expect("the Jacobian involves only parameters")
                    })
                    .collect()
            })
            .collect();
        let p = poly::pivots(rows);
        if p.len() > best.len() {
            best = p;
        }
        if best.len() >= bound {
            break;
        }
    }
    best
}

/// True when every non-zero entry of `row` is homogeneous in the variables
/// `group`, all of the same degree.
fn row_homogeneous(row: &[Poly], group: &[String]) -> bool {
    let mut degree = None;
    for x in row {
        let idx: Vec<usize> = x
            .vars()
            .iter()
            .enumerate()
            .filter(|(_, v)| group.contains(v))
            .map(|(i, _)| i)
            .collect();
        for t in x.terms() {
            let d: u32 = idx.iter().map(|&i| t.exps[i]).sum();
            if *degree.get_or_insert(d) != d {
                return false;
            }
        }
    }
    true
}

/// The exact rank of the polynomial matrix `l` over `Q(p)` by fraction-free
/// (Bareiss) elimination, pivoting first on `hint` (pivots found at a
/// point, see [`poly::pivots`]), then on any non-zero entry left. After `s` steps
/// the remaining entries are the `(s+1)`-minors bordering the pivot block,
/// so the elimination stops exactly at the rank.
///
/// For each group of variables (`groups`, e.g. masses and springs) in which
/// every row is homogeneous, the group's first variable is set to 1 first:
/// every minor is then homogeneous in the group and vanishes exactly when
/// its dehomogenization does. `None` when the work (the sum of the products
/// of the term counts of the multiplied entries) would exceed `work_limit`.
fn symbolic_rank(
    l: &[Vec<Poly>],
    hint: &[(usize, usize)],
    groups: &[Vec<String>],
    work_limit: u64,
) -> Option<usize> {
    let mut m: Vec<Vec<Poly>> = l.to_vec();
    for g in groups {
        if let Some(first) = g.first() {
            if m.iter().all(|row| row_homogeneous(row, g)) {
                for x in m.iter_mut().flatten() {
                    *x = x.subs(first, &Rat::ONE);
                }
            }
        }
    }
    let rows = m.len();
    let cols = m.first().map_or(0, Vec::len);
    // Pivot rows and columns of the hint first, in order.
    let first_hinted = |hinted: Vec<usize>, n: usize| -> Vec<usize> {
        let rest: Vec<usize> = (0..n).filter(|i| !hinted.contains(i)).collect();
        hinted.into_iter().chain(rest).collect()
    };
    let row_order = first_hinted(hint.iter().map(|&(r, _)| r).collect(), rows);
    let col_order = first_hinted(hint.iter().map(|&(_, c)| c).collect(), cols);
    let mut a: Vec<Vec<Poly>> = row_order
        .iter()
        .map(|&i| col_order.iter().map(|&j| m[i][j].clone()).collect())
        .collect();
    let mut prev = Poly::one();
    let mut s = 0;
    let mut work = 0u64;
    while s < rows.min(cols) {
        // Pivot: (s, s) if non-zero, else the first non-zero entry left.
        let Some((pi, pj)) = (s..rows)
            .flat_map(|i| (s..cols).map(move |j| (i, j)))
            .find(|&(i, j)| !a[i][j].is_zero())
        else {
            break;
        };
        a.swap(s, pi);
        for row in a.iter_mut() {
            row.swap(s, pj);
        }
        for i in s + 1..rows {
            for j in s + 1..cols {
                work += (a[s][s].num_terms() * a[i][j].num_terms()
                    + a[i][s].num_terms() * a[s][j].num_terms()) as u64;
                if work > work_limit {
                    return None;
                }
                let x = &(&a[s][s] * &a[i][j]) - &(&a[i][s] * &a[s][j]);
                a[i][j] = x.div_exact(&prev).expect("Bareiss division is exact");
            }
        }
        prev = a[s][s].clone();
        s += 1;
    }
    Some(s)
}

/// Identifiability of the undamped `model` (one column of Tab. 5).
///
/// Uses the undamped transfer function with a common factor of numerator
/// and denominator cancelled ([`UndampedTf::reduced`]; degradation-free
/// models have none) and the parameters [`Model::undamped_parameters`].
///
/// ```
/// use mms::{identifiability, Model};
/// let a1 = identifiability(&Model::from_id("A1")?);
/// assert_eq!(a1.parameters.len(), 5);
/// assert_eq!((a1.nonconstant_invariants, a1.determinable_parameters), (5, 5));
/// assert!(a1.is_proven() && a1.is_locally_identifiable());
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn identifiability(model: &Model) -> Identifiability {
    identifiability_with(model, &RankOptions::default())
}

/// [`identifiability`] with explicit [`RankOptions`].
///
/// ```
/// use mms::{identifiability_with, Model, RankCertificate, RankOptions};
/// let b2 = Model::from_id("B2")?;
/// let sampled_only = RankOptions { symbolic_work_limit: 0, ..RankOptions::default() };
/// let id = identifiability_with(&b2, &sampled_only);
/// assert_eq!(id.determinable_parameters, 4); // proven lower bound
/// assert_eq!(id.rank_upper_bound, 5); // counting bound only
/// assert_eq!(id.certificate, RankCertificate::Sampled);
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn identifiability_with(model: &Model, options: &RankOptions) -> Identifiability {
    let tf = model.undamped_tf().reduced();
    let parameters = model.undamped_parameters();
    let invariants = moment_invariants(&tf);
    let nonconstant: Vec<&MomentInvariant> =
        invariants.iter().filter(|i| !i.is_constant()).collect();
    let rank = invariant_rank(model, &parameters, &nonconstant, options);
    Identifiability {
        model: *model,
        nonconstant_invariants: nonconstant.len(),
        invariants,
        determinable_parameters: rank.determinable,
        rank_upper_bound: rank.upper_bound,
        certificate: rank.certificate,
        scaling_symmetries: rank.scaling,
        unidentifiable_directions: rank
            .directions
            .into_iter()
            .map(|v| UnidentifiableDirection {
                components: parameters
                    .iter()
                    .zip(v)
                    .filter(|(_, c)| !c.is_zero())
                    .map(|(n, c)| (n.clone(), c))
                    .collect(),
            })
            .collect(),
        parameters,
    }
}

/// The generic rank of the Jacobian of some invariants and how it is
/// established (see [`invariant_rank`]).
pub(crate) struct InvariantRank {
    /// Proven lower bound; the rank when the certificate is not `Sampled`.
    pub(crate) determinable: usize,
    /// Proven upper bound.
    pub(crate) upper_bound: usize,
    pub(crate) certificate: RankCertificate,
    pub(crate) scaling: Vec<ScalingSymmetry>,
    /// A basis of the Jacobian's kernel as vector fields on the parameters
    /// (see [`Identifiability::unidentifiable_directions`]); empty when the
    /// rank is only sampled.
    pub(crate) directions: Vec<Vec<Poly>>,
}

/// The generic rank of the Jacobian of the non-constant invariants
/// `nonconstant` (of one transfer function or of several sharing the
/// parameters of `model`) with respect to `parameters`, established as the
/// module documentation describes: sampled lower bound, counting and
/// scaling upper bounds, symbolic elimination in between.
pub(crate) fn invariant_rank(
    model: &Model,
    parameters: &[String],
    nonconstant: &[&MomentInvariant],
    options: &RankOptions,
) -> InvariantRank {
    let scaling = scaling_symmetries(parameters, nonconstant);
    let k = parameters.len();
    let counting = k.min(nonconstant.len());
    let bound = counting.min(k - scaling.len());
    let l = scaled_jacobian(parameters, nonconstant);
    let hint = sampled_pivots(&l, parameters, bound, options);
    let (determinable, upper_bound, certificate) = if hint.len() == bound {
        let c = if bound == counting {
            RankCertificate::Counting
        } else {
            RankCertificate::ScalingSymmetries
        };
        (bound, bound, c)
    } else {
        let groups = [model.masses(), model.springs()];
        match symbolic_rank(&l, &hint, &groups, options.symbolic_work_limit) {
            Some(r) => (r, r, RankCertificate::SymbolicElimination),
            None => (hint.len(), bound, RankCertificate::Sampled),
        }
    };
    let directions = if certificate == RankCertificate::Sampled || hint.len() != determinable {
        Vec::new()
    } else {
        kernel_directions(&l, parameters, &hint).unwrap_or_default()
    };
    InvariantRank {
        determinable,
        upper_bound,
        certificate,
        scaling,
        directions,
    }
}

/// A basis of the kernel of the scaled Jacobian `l` (rank `r`, with a
/// non-singular `r x r` block at the pivots `hint`) as vector fields on the
/// parameters: for each column `j` outside the block, Cramer's rule on the
/// block's rows and columns plus `j` gives `w` with `l w = 0`, and `v_c =
/// p_c w_c` is then a kernel vector of the unscaled Jacobian; divided by the
/// gcd of its components. Independent, since each has a non-zero component
/// at its own `j` and none at the others. `None` if some row of `l` does not
/// vanish on one (the rank is then not `r`).
fn kernel_directions(
    l: &[Vec<Poly>],
    params: &[String],
    hint: &[(usize, usize)],
) -> Option<Vec<Vec<Poly>>> {
    let rows: Vec<usize> = hint.iter().map(|&(r, _)| r).collect();
    let block: Vec<usize> = hint.iter().map(|&(_, c)| c).collect();
    let mut out = Vec::new();
    for j in (0..params.len()).filter(|j| !block.contains(j)) {
        let cols: Vec<usize> = block.iter().copied().chain([j]).collect();
        let mut w = vec![Poly::zero(); params.len()];
        for (t, &c) in cols.iter().enumerate() {
            let minor: Vec<Vec<Poly>> = rows
                .iter()
                .map(|&i| {
                    cols.iter()
                        .filter(|&&x| x != c)
                        .map(|&x| l[i][x].clone())
                        .collect()
                })
                .collect();
            let d = if minor.is_empty() {
                Poly::one()
            } else {
                poly::det(&minor)
            };
            w[c] = if t % 2 == 0 { d } else { -d };
        }
        let vanishes = |row: &Vec<Poly>| {
            cols.iter()
                .fold(Poly::zero(), |acc, &c| &acc + &(&row[c] * &w[c]))
                .is_zero()
        };
        if !l.iter().all(vanishes) {
            return None;
        }
        let v: Vec<Poly> = w
            .iter()
            .zip(params)
            .map(|(x, p)| x * &Poly::var(p))
            .collect();
        let g = poly::gcd_many(&v);
        out.push(
            v.iter()
                .map(|x| x.div_exact(&g).expect("gcd divides"))
                .collect(),
        );
    }
    Some(out)
}

/// A renaming of parameters induced by a renumbering of the masses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum ParameterRenaming {
    /// No renaming: the transfer functions are equal as they stand. A model
    /// and its reciprocal ([`Model::reciprocal`]) are; so are, for a gap
    /// `>= 1`, two models that differ by swapping only the plus points (or
    /// only the minus points) of actuator and sensor: the chain splits at
    /// the gap into a grounded block `G` and a free block `F`, and the
    /// receptance is `F[meas+][act+] + G[meas-][act-]` with `F`, `G`
    /// symmetric. Up to 4 masses such a swap is a reciprocity or a
    /// renumbering; from 5 masses on it is not always (e.g.
    /// `N5-g2-a3.1-s4.2` and `N5-g2-a4.1-s3.2`).
    Identity,
    /// The renaming of [`Model::mirrored`]: mass `gap + k` becomes mass
    /// `N + 1 - k` and the springs of the free part follow
    /// ([`mirror_renaming`]).
    Mirror,
}

/// The renaming of parameters that goes with [`Model::mirrored`]: mass
/// `gap + k` to mass `N + 1 - k`, the spring between masses `i` and `i + 1`
/// of the free part to the spring between their images; the grounded part
/// keeps its names. Only the names that change are listed.
///
/// ```
/// let b2 = mms::Model::from_id("B2").unwrap(); // gap 1: m2 -c23- m3 is free
/// let r = mms::mirror_renaming(&b2);
/// assert_eq!(r.get("m2").map(String::as_str), Some("m3"));
/// assert_eq!(r.get("m3").map(String::as_str), Some("m2"));
/// assert_eq!(r.len(), 2); // c1, c23 and m1 keep their names
/// ```
pub fn mirror_renaming(model: &Model) -> BTreeMap<String, String> {
    let (n, gap) = (model.n_masses(), model.gap());
    let mut map = BTreeMap::new();
    for i in gap + 1..=n {
        let j = model.mirrored_mass(i);
        if i != j {
            map.insert(mass_name(i), mass_name(j));
        }
    }
    // Spring i joins masses i and i+1; in the free part (i > gap) its image
    // joins n+gap-i and n+gap+1-i, i.e. it is spring n+gap-i.
    for i in gap + 1..n {
        let j = n + gap - i;
        if i != j {
            map.insert(spring_name(i), spring_name(j));
        }
    }
    map
}

/// If the undamped transfer functions of `a` and `b` are equal up to a
/// constant factor after a [`ParameterRenaming`] applied to `a`, the
/// renaming and the factor `kappa` with `TF_b = kappa * renamed(TF_a)`.
/// Models with different `N` or gap have different parameters and give
/// `None`.
///
/// The test is exact: `num_a' * den_b = kappa * num_b * den_a'`.
///
/// ```
/// use mms::{identical_transfer_functions, Model, ParameterRenaming};
/// let c2 = Model::from_id("C2")?;
/// let c4 = Model::from_id("C4")?;
/// let (renaming, kappa) = identical_transfer_functions(&c2, &c4).unwrap();
/// assert_eq!(renaming, ParameterRenaming::Identity); // reciprocity
/// assert!(kappa.is_one());
/// let a2 = Model::from_id("A2")?;
/// let mirror = identical_transfer_functions(&a2, &a2.mirrored()).unwrap();
/// assert_eq!(mirror.0, ParameterRenaming::Mirror);
/// assert_eq!(identical_transfer_functions(&a2, &Model::from_id("A3")?), None);
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn identical_transfer_functions(a: &Model, b: &Model) -> Option<(ParameterRenaming, Rat)> {
    if a.n_masses() != b.n_masses() || a.gap() != b.gap() {
        return None;
    }
    identical_tfs(&Renamable::new(a), &b.undamped_tf())
}

/// A model's transfer function and its image under [`mirror_renaming`].
pub(crate) struct Renamable {
    tf: UndampedTf,
    mirrored: UndampedTf,
}

impl Renamable {
    pub(crate) fn new(model: &Model) -> Renamable {
        let tf = model.undamped_tf();
        let map = mirror_renaming(model);
        let rename = |p: &Poly| p.rename(|v| map.get(v).cloned().unwrap_or_else(|| v.to_string()));
        let mirrored = UndampedTf {
            num: rename(&tf.num),
            den: rename(&tf.den),
        };
        Renamable { tf, mirrored }
    }
}

/// See [`identical_transfer_functions`]; `a` and `b` have the same `N` and gap.
fn identical_tfs(a: &Renamable, b: &UndampedTf) -> Option<(ParameterRenaming, Rat)> {
    identical_tf_vectors(std::slice::from_ref(a), std::slice::from_ref(b))
}

/// The first [`ParameterRenaming`] (identity, then mirror) under which
/// every `b[i]` is `kappa * renamed(a[i])` with one common constant
/// `kappa`, and that `kappa`; `a` and `b` have the same length and their
/// models the same `N` and gap. One common factor because a fitted gain
/// absorbs one factor for all sensors at once, not one per sensor.
pub(crate) fn identical_tf_vectors(
    a: &[Renamable],
    b: &[UndampedTf],
) -> Option<(ParameterRenaming, Rat)> {
    debug_assert_eq!(a.len(), b.len());
    'renaming: for renaming in [ParameterRenaming::Identity, ParameterRenaming::Mirror] {
        let mut common: Option<Rat> = None;
        for (ra, tb) in a.iter().zip(b) {
            let ta = match renaming {
                ParameterRenaming::Identity => &ra.tf,
                ParameterRenaming::Mirror => &ra.mirrored,
            };
            let lhs = &ta.num * &tb.den;
            let rhs = &tb.num * &ta.den;
            if lhs.is_zero() || rhs.is_zero() {
                if lhs.is_zero() && rhs.is_zero() {
                    // Both zero: equal for any factor.
                    continue;
                }
                continue 'renaming;
            }
            // tb.num / tb.den = kappa * ta.num / ta.den  <=>  lhs = kappa * rhs
            let kappa = &lhs.leading_coef() / &rhs.leading_coef();
            if lhs != rhs.scale(&kappa) || common.as_ref().is_some_and(|k| *k != kappa) {
                continue 'renaming;
            }
            common = Some(kappa);
        }
        return Some((renaming, common.unwrap_or(Rat::ONE)));
    }
    None
}

/// Why a model is structurally equivalent to the representative of its
/// [`EquivalenceGroup`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub enum EquivalenceReason {
    /// The transfer functions are equal up to the constant `factor` after
    /// the `renaming` applied to the representative
    /// ([`identical_transfer_functions`]).
    IdenticalTransferFunction {
        /// The renaming of the representative's parameters.
        renaming: ParameterRenaming,
        /// `TF_model = factor * renamed(TF_representative)`.
        #[serde(serialize_with = "ser_display")]
        factor: Rat,
    },
    /// Vajda's criterion: the same symbolic form and, in both, independent
    /// non-constant moment invariants
    /// ([`Identifiability::structurally_equivalent_by_invariants`]).
    IndependentMomentInvariants,
}

impl fmt::Display for EquivalenceReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EquivalenceReason::IdenticalTransferFunction { renaming, factor } => {
                f.write_str("identical transfer function")?;
                if *renaming == ParameterRenaming::Mirror {
                    f.write_str(" up to the mirror renaming")?;
                }
                if !factor.is_one() {
                    write!(f, " times {factor}")?;
                }
                Ok(())
            }
            EquivalenceReason::IndependentMomentInvariants => {
                f.write_str("same form, independent moment invariants")
            }
        }
    }
}

/// One member of an [`EquivalenceGroup`] and why it is equivalent to the
/// group's representative.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Equivalence {
    /// The member.
    pub model: Model,
    /// The reason.
    pub reason: EquivalenceReason,
}

/// A group of structurally equivalent models.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct EquivalenceGroup {
    /// The first member in the order of the input.
    pub representative: Model,
    /// The other members, in the order of the input, each with its reason.
    pub members: Vec<Equivalence>,
}

impl EquivalenceGroup {
    /// All models of the group, the representative first.
    pub fn models(&self) -> Vec<Model> {
        std::iter::once(self.representative)
            .chain(self.members.iter().map(|e| e.model))
            .collect()
    }
}

/// Groups the structurally equivalent models of `models` (see the
/// [module documentation](self)): identical transfer functions after a
/// renaming induced by renumbering, or Vajda's criterion. Only groups with
/// two or more distinct models are returned, ordered by their
/// representative's position in the input; duplicates in the input are
/// ignored.
///
/// The relation is an equivalence (renamings compose; models with identical
/// transfer functions have the same identifiability), so each member is
/// related to the representative directly.
///
/// ```
/// use mms::{structural_equivalences, EquivalenceReason, Model, ParameterRenaming};
/// let ids = ["A1", "A2", "A4", "A5", "B2", "C2", "C4"];
/// let models: Vec<Model> = ids.iter().map(|id| Model::from_id(id)).collect::<Result<_, _>>()?;
/// let groups = structural_equivalences(&models);
/// let names: Vec<Vec<String>> = groups
///     .iter()
///     .map(|g| g.models().iter().map(Model::name).collect())
///     .collect();
/// assert_eq!(names, [["A1", "A4"], ["A2", "A5"], ["C2", "C4"]]);
/// // A1 and A4: Vajda's criterion (both collocated, 5 independent invariants)
/// assert_eq!(groups[0].members[0].reason, EquivalenceReason::IndependentMomentInvariants);
/// // A5 is the mirror image of A2 with actuator and sensor swapped
/// assert_eq!(
///     groups[1].members[0].reason.to_string(),
///     "identical transfer function up to the mirror renaming"
/// );
/// // C4 is C2 with actuator and sensor swapped (reciprocity)
/// assert_eq!(groups[2].members[0].reason.to_string(), "identical transfer function");
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn structural_equivalences(models: &[Model]) -> Vec<EquivalenceGroup> {
    let mut distinct: Vec<Model> = Vec::new();
    for m in models {
        if !distinct.contains(m) {
            distinct.push(*m);
        }
    }
    let tfs: Vec<Renamable> = distinct.iter().map(Renamable::new).collect();
    let n = distinct.len();
    // 1. Classes of identical transfer functions (union-find, the root the
    //    smallest index). Renamings compose, so the relation is transitive.
    let mut same_tf = UnionFind::new(n);
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (&distinct[i], &distinct[j]);
            if a.n_masses() == b.n_masses()
                && a.gap() == b.gap()
                && same_tf.find(i) != same_tf.find(j)
                && identical_tfs(&tfs[i], &tfs[j].tf).is_some()
            {
                same_tf.union(i, j);
            }
        }
    }
    // 2. Vajda's criterion between the classes, on one member each (the
    //    others have the same invariants up to renaming).
    let roots: Vec<usize> = (0..n).filter(|&i| same_tf.find(i) == i).collect();
    let ids: BTreeMap<usize, Identifiability> = roots
        .iter()
        .map(|&r| (r, identifiability(&distinct[r])))
        .collect();
    let mut groups = same_tf.clone();
    for (x, &r) in roots.iter().enumerate() {
        for &s in &roots[x + 1..] {
            if ids[&r].structurally_equivalent_by_invariants(&ids[&s]) {
                groups.union(r, s);
            }
        }
    }
    let mut members: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..n {
        members.entry(groups.find(i)).or_default().push(i);
    }
    members
        .into_iter()
        .filter(|(_, g)| g.len() > 1)
        .map(|(r, g)| EquivalenceGroup {
            representative: distinct[r],
            members: g
                .into_iter()
                .filter(|&i| i != r)
                .map(|i| {
                    let reason = if same_tf.find(i) == same_tf.find(r) {
                        let (renaming, factor) = identical_tfs(&tfs[r], &tfs[i].tf)
                            .expect("identical transfer functions after renaming are transitive");
                        EquivalenceReason::IdenticalTransferFunction { renaming, factor }
                    } else {
                        EquivalenceReason::IndependentMomentInvariants
                    };
                    Equivalence {
                        model: distinct[i],
                        reason,
                    }
                })
                .collect(),
        })
        .collect()
}

/// Disjoint sets over `0..n`; the root of a set is its smallest element.
#[derive(Clone)]
struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind((0..n).collect())
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }

    fn union(&mut self, i: usize, j: usize) {
        let (a, b) = (self.find(i), self.find(j));
        self.0[a.max(b)] = a.min(b);
    }
}
