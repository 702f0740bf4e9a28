//! Which FRF types a model can show for positive parameters, with proofs.
//!
//! [`analyze`] lists every a-priori candidate type ([`candidate_types`]) of
//! a model's undamped transfer function and decides each one:
//!
//! - **possible**, with a *witness*: exact rational parameters whose TF has
//!   that type, confirmed by exact root isolation ([`frf_type_at`]);
//! - **impossible**, with a *certificate* ([`Proof`]) that an independent
//!   checker re-verifies with exact arithmetic;
//! - **unknown** when neither is found; never dropped.
//!
//! ```
//! use mms::analysis::{analyze, SearchLimits, Status};
//! let a2 = mms::Model::from_id("A2")?;
//! let result = analyze(&a2, &SearchLimits::default());
//! let possible: Vec<String> = result.types.iter()
//!     .filter(|v| v.status == Status::Possible)
//!     .map(|v| v.frf_type.to_string())
//!     .collect();
//! assert_eq!(possible, ["ARR", "RAR", "R"]); // the paper's Tab. 3
//! assert!(result.types.iter().all(|v| v.status != Status::Unknown));
//! # Ok::<(), mms::ModelError>(())
//! ```

mod algebraic;
mod block_scale;
mod cancellations;
mod configurations;
mod continuity;
mod explain;
mod frf_type;
mod isolated;
mod limits;
mod lp;
mod pole_signs;
mod prover;
mod rename;
mod sampling;
mod targeted;
mod variety;
mod walls;

pub use continuity::PATH_VARIABLE;
pub use explain::{explain, ExplainFormat};
pub use frf_type::{
    candidate_types, frf_type_at, frf_type_at_algebraic, frf_type_of, frf_type_over, Feature,
    FrfType, ParseFrfTypeError, Token,
};
pub use limits::gathers_into;
#[cfg(test)]
pub(crate) use limits::limits_of_generic_types;
pub use pole_signs::{BlockPoleSigns, BlockSign, PoleSigns, RemainderFactor};
pub use prover::{
    ConditionRule, Definiteness, FactorProof, OpenProof, Proof, RegionSample, SearchLimits,
    SignCase, SignCondition, Substitution, UnlistedRole,
};
pub use sampling::{cells, sample_cell, Cell, CellSample, SAMPLER_VERSION, SAMPLING_RANGE};

use crate::model::Model;
use crate::tf::OMEGA;
use poly::{Poly, Rat};
use prover::Prover;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};

/// The verdict on one candidate type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Shown by a witness.
    Possible,
    /// Ruled out by a certificate.
    Impossible,
    /// Neither witnessed nor refuted by the search.
    Unknown,
}

/// One candidate type and its verdict.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TypeVerdict {
    /// The type.
    #[serde(rename = "type")]
    pub frf_type: FrfType,
    /// Possible, impossible or unknown.
    pub status: Status,
    /// Parameters showing the type (possible types).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub witness: Option<BTreeMap<String, Rat>>,
    /// The proof that it cannot occur (impossible types).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub certificate: Option<Proof>,
    /// A path along which the type shows by continuity (possible types
    /// without a witness point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<MergePath>,
    /// A point with algebraic coordinates where the type shows (possible
    /// types with neither a rational witness nor a path).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub algebraic: Option<AlgebraicWitness>,
    /// A box holding exactly one point where the type shows (possible
    /// types with none of the witnesses above).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub isolated: Option<IsolatedWitness>,
}

/// The name of the generator `theta` of an [`AlgebraicWitness`]'s field.
pub const FIELD_GENERATOR: &str = "theta";

/// A witness point whose coordinates lie in a real number field
/// `Q(theta)`, where a root coincidence (a cancelled pole, a multiple
/// zero) has no rational point nearby that one can pose: `theta` is the
/// one root of the irreducible `minimal` in `interval`, and every
/// parameter a polynomial in `theta` with rational coefficients, positive
/// at `theta`. `mms check` rebuilds the field, re-derives the transfer
/// function at the point over it and reads the type with exact signs.
///
/// ```
/// use mms::analysis::AlgebraicWitness;
/// let w: AlgebraicWitness = serde_json::from_str(
///     r#"{"minimal": "theta^2 - 2", "interval": ["1", "2"], "parameters": {"m1": "theta + 1", "c1": "3/2"}}"#,
/// ).unwrap();
/// let (k, point) = w.field_point().unwrap();
/// assert!((k.to_f64(&point["m1"]) - 2.414213562373095).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AlgebraicWitness {
    /// The defining polynomial of `theta`, in [`FIELD_GENERATOR`].
    pub minimal: Poly,
    /// An isolating interval of `theta`.
    pub interval: [Rat; 2],
    /// Each parameter as a polynomial in `theta`.
    pub parameters: BTreeMap<String, Poly>,
    /// The cancelled poles posed: each a root of the numerator and the
    /// denominator at the point.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cancelled: Vec<Rat>,
    /// The multiple zeros posed, with their multiplicities.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub multiple: Vec<(Rat, u32)>,
}

impl AlgebraicWitness {
    /// The witness of `point` in `field`, with its posed cancelled poles
    /// and multiple zeros.
    pub fn new(
        field: &poly::RealField,
        point: &BTreeMap<String, poly::FieldElem>,
        cancelled: &[Rat],
        multiple: &[(Rat, u32)],
    ) -> Self {
        let (lo, hi) = field.isolating_interval();
        AlgebraicWitness {
            cancelled: cancelled.to_vec(),
            multiple: multiple.to_vec(),
            minimal: field.minimal().to_poly(FIELD_GENERATOR),
            interval: [lo, hi],
            parameters: point
                .iter()
                .map(|(k, v)| (k.clone(), field.to_poly(v, FIELD_GENERATOR)))
                .collect(),
        }
    }

    /// The field and the point over it; `None` if `minimal` is not an
    /// irreducible polynomial in `theta` isolated by `interval`, or a
    /// coordinate has another variable.
    pub fn field_point(&self) -> Option<(poly::RealField, BTreeMap<String, poly::FieldElem>)> {
        let (_, u) = poly::UPoly::from_poly(&self.minimal, FIELD_GENERATOR)?;
        let [lo, hi] = self.interval.clone();
        let field = poly::RealField::new(u, lo, hi).ok()?;
        let point = self
            .parameters
            .iter()
            .map(|(k, p)| Some((k.clone(), field.element_of(p, FIELD_GENERATOR)?)))
            .collect::<Option<_>>()?;
        Some((field, point))
    }
}

/// A witness point enclosed in a box of rationals, where a root
/// coincidence (a cancelled pole, a multiple zero) has no point one can
/// compute exactly: the posed roots and the `fixed` parameters are
/// rationals, and the root conditions (the numerator and the denominator
/// zero at each cancelled pole, the numerator and its first `mu - 1`
/// derivatives zero at each multiple zero of multiplicity `mu`) are a
/// square system in the `free` parameters with exactly one solution in
/// their box, by Krawczyk's test in exact interval arithmetic. At that
/// solution the posed roots divide the transfer function exactly, and the
/// rest's roots are placed by the `partition` of `(0, inf)`: at its
/// points neither rest vanishes, and in each piece Descartes' rule, the
/// same for every point of the box, allows at most one root of each and
/// not one of both. `mms check` repeats every step with its own code.
///
/// ```
/// use mms::analysis::IsolatedWitness;
/// let w: IsolatedWitness = serde_json::from_str(
///     r#"{"fixed": {"m1": "1"}, "free": {"c1": ["1999/1000", "2001/1000"]},
///         "cancelled": ["2"], "partition": ["1", "3"]}"#,
/// ).unwrap();
/// assert_eq!(w.free["c1"][0].to_string(), "1999/1000");
/// assert!(w.multiple.is_empty() && w.poses.is_empty());
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IsolatedWitness {
    /// The parameters held at rationals.
    pub fixed: BTreeMap<String, Rat>,
    /// The box of the other parameters: each `[lower, upper]`.
    pub free: BTreeMap<String, [Rat; 2]>,
    /// The cancelled poles posed: each a root of the numerator and the
    /// denominator at the point.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cancelled: Vec<Rat>,
    /// The multiple zeros posed, with their multiplicities.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub multiple: Vec<(Rat, u32)>,
    /// The cancelled poles posed by two other polynomials than the
    /// numerator and the denominator (where those two meet tangentially,
    /// as when the chain's two blocks share an eigenvalue).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub poses: Vec<PolePose>,
    /// Points of `(0, inf)`, increasing, that part the roots of what
    /// remains; every multiple zero is one of them.
    pub partition: Vec<Rat>,
}

/// A cancelled pole of an [`IsolatedWitness`] posed as the common root of
/// two `factors` (polynomials in the parameters and `Omega`) instead of
/// the numerator's and the denominator's: the cofactors show that both
/// of these vanish wherever the factors do,
/// `numerator = n0 f0 + n1 f1` and `denominator = d0 f0 + d1 f1`. A
/// `double` pole is cancelled twice: the denominator is a constant times
/// `f0 f1`, so it has a double root where both vanish, and the numerator's
/// derivative is posed to vanish there too.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PolePose {
    /// The index of the pole in the witness's `cancelled`.
    pub pole: usize,
    /// Cancelled twice.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub double: bool,
    /// `[f0, f1]`.
    pub factors: [Poly; 2],
    /// `[n0, n1]`.
    pub numerator: [Poly; 2],
    /// `[d0, d1]`.
    pub denominator: [Poly; 2],
}

/// A double or triple zero shown by continuity instead of at a rational
/// point.
///
/// Each parameter is a rational function of [`PATH_VARIABLE`] `s`, positive
/// on `[0, 1]`. Along the path exactly one thing happens: two simple zeros
/// meet as a double zero (the type at `s = 0` shows them split, the type
/// at `s = 1` without them, off the real axis), or a simple zero crosses a
/// double zero that stays double all along (the two swap places between
/// `s = 0` and `s = 1`: a triple zero at the crossing); no pole or zero
/// meets a pole, reaches `0` or leaves to infinity, and nothing else
/// meets. So the type with the two zeros merged is shown at that `s` (an
/// algebraic number), which `mms check` confirms by re-deriving every one
/// of these conditions exactly.
///
/// ```
/// use mms::analysis::MergePath;
/// let path: MergePath = serde_json::from_str(
///     r#"{"parameters": {"m1": ["1 + s", "1"], "c1": ["2", "1 + s"]}}"#,
/// ).unwrap();
/// assert_eq!(path.parameters["c1"][1].to_string(), "s + 1");
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MergePath {
    /// Each parameter as `[numerator, denominator]`, polynomials in `s`.
    pub parameters: BTreeMap<String, [Poly; 2]>,
}

/// A pole-zero cancellation: a factor of `Res(num, den)` that vanishes for
/// some positive parameters, and the TF reduced on it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cancellation {
    /// The condition `factor = 0`.
    pub condition: Poly,
    /// Its parametrization.
    pub substitution: Substitution,
    /// The reduced TF on the condition, `(num)/(den)`.
    pub reduced: String,
    /// Reduced numerator on the condition.
    pub num: Poly,
    /// Reduced denominator on the condition.
    pub den: Poly,
}

/// Undetermined critical factors with more terms than this are listed by
/// their size only: at six masses one discriminant factor runs to millions
/// of terms (hundreds of megabytes of text) and claims nothing. The largest
/// at five masses has 33455 terms.
pub const LARGEST_LISTED_FACTOR: usize = 100_000;

/// A critical factor of the whole orthant and what the engine knows of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CriticalFactor {
    /// The irreducible factor; `None` for an undetermined one of more than
    /// [`LARGEST_LISTED_FACTOR`] terms (then `size` says how large).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor: Option<Poly>,
    /// For a factor left out: its number of terms and total degree.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<FactorSize>,
    /// It divides a resultant of a numerator and a denominator part (a
    /// pole-zero cancellation where it vanishes).
    pub cancels: bool,
    /// Definite, a wall, or undetermined.
    pub status: FactorStatus,
    /// For a definite factor: +1 or -1.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sign: Option<i32>,
    /// For a definite factor: the argument, as in a certificate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub definiteness: Option<Definiteness>,
    /// For a wall: the parametrization of its zero set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub substitution: Option<Substitution>,
}

/// How large a critical factor is that an analysis does not write out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FactorSize {
    /// Number of terms.
    pub terms: usize,
    /// Total degree.
    pub total_degree: u32,
}

/// What is known of a [`CriticalFactor`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FactorStatus {
    /// Keeps one sign on the orthant (`sign` and `definiteness` say which
    /// and why).
    Definite,
    /// Vanishes on the graph of `substitution`.
    Wall,
    /// Neither shown; no claim.
    Undetermined,
}

/// The analysis of one model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelAnalysis {
    /// The paper's ID for 3 masses, else the generic ID.
    pub id: String,
    /// The generic ID (`N3-g0-a1.0-s2.0`).
    pub generic_id: String,
    /// Number of masses.
    pub masses: usize,
    /// The gap.
    pub gap: usize,
    /// Actuator `[plus, minus]`.
    pub actuator: [usize; 2],
    /// Sensor `[plus, minus]`.
    pub sensor: [usize; 2],
    /// Numerator of the undamped TF in `Omega`.
    pub numerator: Poly,
    /// Denominator of the undamped TF in `Omega`.
    pub denominator: Poly,
    /// Every candidate type with its verdict: possible first.
    pub types: Vec<TypeVerdict>,
    /// Pole-zero cancellations.
    pub pzc: Vec<Cancellation>,
    /// The critical factors of the orthant.
    pub critical: Vec<CriticalFactor>,
}

impl ModelAnalysis {
    /// The possible types, in the order of [`ModelAnalysis::types`].
    pub fn possible(&self) -> Vec<&FrfType> {
        self.with_status(Status::Possible)
    }

    /// The types left undecided.
    pub fn unknown(&self) -> Vec<&FrfType> {
        self.with_status(Status::Unknown)
    }

    /// This analysis, of `model`, carried over to the other member of its
    /// renumbering class ([`Model::mirrored`]): the same verdicts, every
    /// witness, certificate, cancellation and critical factor renamed to
    /// that member's parameters.
    ///
    /// ```
    /// use mms::analysis::{analyze, SearchLimits};
    /// let a2 = mms::Model::from_id("A2")?;
    /// let carried = analyze(&a2, &SearchLimits::default()).mirrored(&a2);
    /// assert_eq!(carried.generic_id, a2.mirrored().id());
    /// assert_eq!(carried.denominator, a2.mirrored().undamped_tf().den);
    /// # Ok::<(), mms::ModelError>(())
    /// ```
    pub fn mirrored(&self, model: &Model) -> ModelAnalysis {
        rename::Renaming::mirror(model).analysis(self, &model.mirrored())
    }

    /// This analysis, of `from`, carried over to `to`: a member of the
    /// renumbering class of `from` or of its reciprocal's (the same
    /// transfer function by reciprocity, so that nothing but the ports
    /// changes). `None` when `to` is neither.
    ///
    /// ```
    /// use mms::analysis::{analyze, SearchLimits};
    /// let m = mms::Model::from_id("N4-g0-a1.0-s3.0")?;
    /// let a = analyze(&m, &SearchLimits::default());
    /// let twin = a.carried_over(&m, &m.reciprocal()).unwrap();
    /// assert_eq!((twin.actuator, twin.sensor), (a.sensor, a.actuator));
    /// assert_eq!(twin.types, a.types);
    /// assert!(a.carried_over(&m, &mms::Model::from_id("A1")?).is_none());
    /// # Ok::<(), mms::ModelError>(())
    /// ```
    pub fn carried_over(&self, from: &Model, to: &Model) -> Option<ModelAnalysis> {
        if *to == *from || to.reciprocal() == *from {
            Some(rename::Renaming::identity(from).analysis(self, to))
        } else if *to == from.mirrored() || to.reciprocal() == from.mirrored() {
            Some(rename::Renaming::mirror(from).analysis(self, to))
        } else {
            None
        }
    }

    fn with_status(&self, s: Status) -> Vec<&FrfType> {
        self.types
            .iter()
            .filter(|v| v.status == s)
            .map(|v| &v.frf_type)
            .collect()
    }
}

/// The version of the decision procedure: raised whenever a change can
/// alter a verdict, a witness or a certificate, so that stored analyses
/// (e.g. `mms analyze --cache`) made by another version are recomputed.
pub const ENGINE_VERSION: u32 = 46;

/// Decides every candidate FRF type of `model` (see the module docs).
///
/// The verdicts are the same for every member of the model's renumbering
/// class, and for its reciprocal (actuator and sensor swapped, the same
/// transfer function): one of these models, [`analysis_source`], is
/// analysed, and its analysis carried over to the others
/// ([`ModelAnalysis::carried_over`]), renamed where the mirror renumbers
/// (the witnesses' points, the certificates' polynomials and masses).
/// Where the proof rules and searches leave types open, the witness
/// searches run on the mirrored member too, whose random draws go by its
/// own parameters and so fall elsewhere.
///
/// ```
/// use mms::analysis::{analyze, SearchLimits};
/// let m = mms::Model::from_id("N4-g0-a1.0-s3.0")?;
/// let mirror = m.mirrored(); // N4-g0-a4.0-s2.0
/// let limits = SearchLimits::default();
/// let statuses = |a: &mms::analysis::ModelAnalysis| -> Vec<String> {
///     let mut v: Vec<String> =
///         a.types.iter().map(|t| format!("{} {:?}", t.frf_type, t.status)).collect();
///     v.sort();
///     v
/// };
/// assert_eq!(statuses(&analyze(&m, &limits)), statuses(&analyze(&mirror, &limits)));
/// assert_eq!(statuses(&analyze(&m, &limits)), statuses(&analyze(&m.reciprocal(), &limits)));
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn analyze(model: &Model, limits: &SearchLimits) -> ModelAnalysis {
    let source = analysis_source(model);
    analyze_source(&source, limits)
        .carried_over(&source, model)
        .expect("the source is of the model's class or its reciprocal's")
}

/// The analyses of `models`, in their order, each [`analysis_source`]
/// analysed once however many of `models` share it.
///
/// ```
/// use mms::analysis::{analyze_each, SearchLimits};
/// use mms::Model;
/// let m = Model::from_id("N4-g0-a1.0-s3.0")?;
/// let models = [m, m.reciprocal(), m.mirrored()];
/// let a = analyze_each(&models, &SearchLimits::default());
/// assert_eq!(a[1].generic_id, m.reciprocal().id());
/// assert_eq!(a[0].numerator, a[1].numerator); // reciprocity
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn analyze_each(models: &[Model], limits: &SearchLimits) -> Vec<ModelAnalysis> {
    let mut done: BTreeMap<Model, ModelAnalysis> = BTreeMap::new();
    models
        .iter()
        .map(|m| {
            let source = analysis_source(m);
            done.entry(source)
                .or_insert_with(|| analyze_source(&source, limits))
                .carried_over(&source, m)
                .expect("the source is of the model's class or its reciprocal's")
        })
        .collect()
}

/// The model whose analysis [`analyze`] carries over to `model`: of the
/// representatives ([`Model::representative`]) of the model's class and of
/// its reciprocal's class, the first in the tables' order. Reciprocal
/// models have the same transfer function in the same parameters, so their
/// two classes need one analysis between them.
///
/// ```
/// use mms::analysis::analysis_source;
/// let m = mms::Model::from_id("N5-g2-a4.2-s5.2")?;
/// assert_eq!(analysis_source(&m).id(), "N5-g2-a3.2-s4.2"); // its mirror's reciprocal
/// assert_eq!(analysis_source(&analysis_source(&m)), analysis_source(&m));
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn analysis_source(model: &Model) -> Model {
    let own = model.representative();
    let other = model.reciprocal().representative();
    let key = |m: &Model| (m.paper_id().is_none(), m.paper_id(), *m);
    if key(&other) < key(&own) {
        other
    } else {
        own
    }
}

/// The analysis of a model that is its own [`analysis_source`].
fn analyze_source(model: &Model, limits: &SearchLimits) -> ModelAnalysis {
    let own = analyze_rational(model, limits);
    let mirror = model.mirrored();
    let own = if mirror == *model || own.unknown().is_empty() {
        own
    } else {
        let other = mirror_witnesses(&mirror, &own, limits);
        completed(own, &other)
    };
    let own = completion(model, own, Completion::Algebraic);
    // The number fields and the boxes are searched once, not again on the
    // mirror: the mirror's number-field search (its linear sets ordered
    // by other names) decided none of the types this one left open at
    // four and five masses, for a twentieth of the 5-mass table's time,
    // and the box sampler's variety is the same under other names.
    let own = completion(model, own, Completion::Isolated);
    limits::limits_of_generic_types(model, own)
}

/// The searches that complete an analysis, last of all.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Completion {
    /// At points over real number fields ([`Prover::algebraic_search`]).
    Algebraic,
    /// At points isolated in a box ([`Prover::isolated_search`]).
    Isolated,
}

/// `a` (an analysis of `model`) with the types it leaves unknown searched
/// by `search`, from its witnesses: after every search over the
/// rationals, so that a type keeps a rational witness wherever one was
/// found, and one over a number field before a box.
fn completion(model: &Model, a: ModelAnalysis, search: Completion) -> ModelAnalysis {
    let open: Vec<FrfType> = a.unknown().into_iter().cloned().collect();
    if open.is_empty() {
        return a;
    }
    let tf = model.undamped_tf();
    let mut prover = Prover::new(model, tf.num.clone(), tf.den.clone());
    for v in &a.types {
        if let Some(w) = &v.witness {
            prover.witnesses.insert(v.frf_type.clone(), w.clone());
        }
        if let Some(p) = &v.path {
            prover.paths.insert(v.frf_type.clone(), p.clone());
        }
        if let Some(w) = &v.algebraic {
            prover.algebraic.insert(v.frf_type.clone(), w.clone());
        }
        if let Some(w) = &v.isolated {
            prover.isolated.insert(v.frf_type.clone(), w.clone());
        }
    }
    match search {
        Completion::Algebraic => prover.algebraic_search(&open, ALGEBRAIC_SEED),
        Completion::Isolated => {
            prover.isolated_search(&open, ISOLATED_SEED) + prover.block_scale_search(&open)
        }
    };
    let found: Vec<TypeVerdict> = open
        .iter()
        .filter_map(|t| {
            // A field of degree one is a rational point.
            let witness = prover.witnesses.get(t).cloned();
            let algebraic = witness
                .is_none()
                .then(|| prover.algebraic.get(t).cloned())
                .flatten();
            let isolated = (witness.is_none() && algebraic.is_none())
                .then(|| prover.isolated.get(t).cloned())
                .flatten();
            (witness.is_some() || algebraic.is_some() || isolated.is_some()).then(|| TypeVerdict {
                frf_type: t.clone(),
                status: Status::Possible,
                witness,
                certificate: None,
                path: None,
                algebraic,
                isolated,
            })
        })
        .collect();
    completed(a, &found)
}

/// The witness searches of `mirror` (the other member of the class of
/// `own`'s model) for every type `own` leaves unknown, as verdicts of
/// `own`'s model. Its random draws go by its own parameters, so they fall
/// elsewhere. Its proof rules are not run again: they work on the same
/// polynomials under other names.
fn mirror_witnesses(
    mirror: &Model,
    own: &ModelAnalysis,
    limits: &SearchLimits,
) -> Vec<TypeVerdict> {
    let tf = mirror.undamped_tf();
    let mut prover = Prover::new(mirror, tf.num.clone(), tf.den.clone());
    prover.search(limits);
    let top = prover.stratum(&[]);
    let candidates = candidate_types(top.num.degree(OMEGA), top.den.degree(OMEGA));
    // Only what `own` leaves open: a type `own` witnessed would be searched
    // for nothing, and such searches were half the time of the slowest
    // models.
    let open: BTreeSet<&FrfType> = own.unknown().into_iter().collect();
    let wanted: Vec<FrfType> = candidates
        .iter()
        .filter(|t| !prover.witnesses.contains_key(t) && open.contains(t))
        .cloned()
        .collect();
    search_unknown(&mut prover, &wanted, limits);
    // Candidates first, then the other types witnessed: the order in which
    // `completed` adds those `own` does not list.
    let extra = prover.witnesses.keys().filter(|t| !candidates.contains(t));
    let back = rename::Renaming::mirror(mirror);
    candidates
        .iter()
        .chain(extra)
        .filter_map(|t| {
            let witness = prover.witnesses.get(t).cloned();
            let path = match witness {
                Some(_) => None,
                None => Some(prover.paths.get(t)?.clone()),
            };
            Some(back.verdict(&TypeVerdict {
                frf_type: t.clone(),
                status: Status::Possible,
                witness,
                certificate: None,
                path,
                algebraic: None,
                isolated: None,
            }))
        })
        .collect()
}

/// `own` with every type it leaves unknown decided as `other` (the same
/// model's analysis by another route) decides it, and the types `other`
/// witnesses that `own` does not list added.
fn completed(mut own: ModelAnalysis, other: &[TypeVerdict]) -> ModelAnalysis {
    for v in other {
        match own.types.iter_mut().find(|o| o.frf_type == v.frf_type) {
            Some(o) if o.status == Status::Unknown => *o = v.clone(),
            // A witness against a certificate would be a bug in the prover.
            Some(o) => debug_assert!(
                o.status == v.status || v.status == Status::Unknown,
                "{}: {} is {:?} and {:?}",
                own.id,
                o.frf_type,
                o.status,
                v.status
            ),
            None if v.status == Status::Possible => own.types.push(v.clone()),
            None => {}
        }
    }
    own.types.sort_by_key(|v| status_rank(v.status)); // stable
    own
}

/// The witness searches for the types the proof rules leave open, in a
/// fixed order: each draws its random points per wanted type in turn, so
/// what one finds changes the draws of those after it. Returns how many
/// types they witnessed.
fn search_unknown(prover: &mut Prover, unknown: &[FrfType], limits: &SearchLimits) -> usize {
    prover.targeted_search(unknown, 0x7A26_E7ED)
        + prover.partial_wall_search(unknown, limits.partial_wall_depth)
        + prover.root_condition_search(unknown, 0x2007_C0DE)
        + prover.cancellation_search(unknown, 0xCA2C_E11E)
        + prover.discriminant_search(unknown, 0xD15C_0001)
        + prover.elimination_search(unknown, 0xE11_4A7E)
        + prover.symmetric_search(unknown, limits)
        + prover.resting_mass_search(unknown, 0x2E57_1A55)
        + prover.neighbour_search(unknown)
        + prover.close_merge_search(unknown)
        + prover.wall_targeted_search(unknown)
        + prover.merge_search(unknown)
        + prover.double_zero_chart_search(unknown)
        + prover.double_zero_chart_points(unknown)
        + prover.root_condition_pencil_search(unknown, 0x9E2C_11A5)
        + prover.root_walk_search(unknown)
}

/// The seed of [`Prover::algebraic_search`]'s draws.
const ALGEBRAIC_SEED: u64 = 0xA16E_B2A1;
/// The seed of [`Prover::isolated_search`]'s sampler.
const ISOLATED_SEED: u64 = 0x150_1A7E;

/// Possible types first, then unknown ones, then impossible ones.
fn status_rank(s: Status) -> u8 {
    match s {
        Status::Possible => 0,
        Status::Unknown => 1,
        Status::Impossible => 2,
    }
}

/// The search on `model` alone, without what its mirror decides: the
/// verdicts may then depend on which member of a class is analysed (the
/// search's samples and walls are in the member's own parameters).
pub fn analyze_alone(model: &Model, limits: &SearchLimits) -> ModelAnalysis {
    let a = completion(
        model,
        analyze_rational(model, limits),
        Completion::Algebraic,
    );
    let a = completion(model, a, Completion::Isolated);
    limits::limits_of_generic_types(model, a)
}

/// [`analyze_alone`] without the search over number fields.
fn analyze_rational(model: &Model, limits: &SearchLimits) -> ModelAnalysis {
    let tf = model.undamped_tf();
    let mut prover = Prover::new(model, tf.num.clone(), tf.den.clone());
    prover.search(limits);
    let top = prover.stratum(&[]);
    let (a, r) = (top.num.degree(OMEGA), top.den.degree(OMEGA));
    let mut candidates = candidate_types(a, r);
    for t in prover.witnesses.keys() {
        if !candidates.contains(t) {
            candidates.push(t.clone());
        }
    }
    let mut verdicts = Vec::new();
    for t in candidates {
        let proof = if prover.witnesses.contains_key(&t) {
            None
        } else {
            prover.prove(&[], &t, limits)
        };
        let witness = prover.witnesses.get(&t).cloned();
        let status = match (&witness, &proof) {
            (Some(_), _) => Status::Possible,
            (None, Some(_)) => Status::Impossible,
            (None, None) => Status::Unknown,
        };
        verdicts.push(TypeVerdict {
            frf_type: t,
            status,
            witness,
            certificate: if status == Status::Impossible {
                proof
            } else {
                None
            },
            path: None,
            algebraic: None,
            isolated: None,
        });
    }
    // Before the searches, so that none is spent on a type the limits of
    // generic types already decide; they run once more at the end.
    limits::certify_limits(model, &mut verdicts);
    // Rare generic types: a targeted search, then the verdicts it changes.
    let unknown: Vec<FrfType> = verdicts
        .iter()
        .filter(|v| v.status == Status::Unknown)
        .map(|v| v.frf_type.clone())
        .collect();
    if search_unknown(&mut prover, &unknown, limits) > 0 {
        for v in verdicts.iter_mut().filter(|v| v.status == Status::Unknown) {
            if let Some(w) = prover.witnesses.get(&v.frf_type) {
                v.status = Status::Possible;
                v.witness = Some(w.clone());
            } else if let Some(p) = prover.paths.get(&v.frf_type) {
                v.status = Status::Possible;
                v.path = Some(p.clone());
            }
        }
    }
    for v in verdicts.iter_mut().filter(|v| v.status == Status::Unknown) {
        if let Some(p) = prover.late_block_proof(&v.frf_type) {
            v.status = Status::Impossible;
            v.certificate = Some(p);
        }
    }
    // A witness of a certified type would be a bug in the prover; the
    // tests run the N=3 and N=4 analyses with this check.
    debug_assert!(
        verdicts
            .iter()
            .all(|v| v.status != Status::Impossible || !prover.witnesses.contains_key(&v.frf_type)),
        "{model}: a witness for a type certified impossible"
    );
    verdicts.sort_by_key(|v| status_rank(v.status)); // stable: keeps candidate order
    let pzc = top
        .factors
        .iter()
        .filter(|f| f.cancels && f.definite.is_none())
        .filter_map(|f| {
            let w = f.wall.clone()?;
            let s = prover.stratum(std::slice::from_ref(&w));
            Some(Cancellation {
                condition: f.poly.clone(),
                substitution: w,
                reduced: format!("({})/({})", s.num, s.den),
                num: s.num.clone(),
                den: s.den.clone(),
            })
        })
        .collect();
    let critical = top
        .factors
        .iter()
        .map(|f| {
            let (status, sign, definiteness, substitution) = match (&f.definite, &f.wall) {
                (Some((sign, d)), _) => {
                    (FactorStatus::Definite, Some(*sign), Some(d.clone()), None)
                }
                (None, Some(w)) => (FactorStatus::Wall, None, None, Some(w.clone())),
                (None, None) => (FactorStatus::Undetermined, None, None, None),
            };
            let omitted =
                status == FactorStatus::Undetermined && f.poly.num_terms() > LARGEST_LISTED_FACTOR;
            CriticalFactor {
                factor: (!omitted).then(|| f.poly.clone()),
                size: omitted.then(|| FactorSize {
                    terms: f.poly.num_terms(),
                    total_degree: f.poly.total_degree(),
                }),
                cancels: f.cancels,
                status,
                sign,
                definiteness,
                substitution,
            }
        })
        .collect();
    ModelAnalysis {
        critical,
        id: model.name(),
        generic_id: model.id(),
        masses: model.n_masses(),
        gap: model.gap(),
        actuator: [model.actuator().plus, model.actuator().minus],
        sensor: [model.sensor().plus, model.sensor().minus],
        numerator: tf.num,
        denominator: tf.den,
        types: verdicts,
        pzc,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A verdict left unknown is taken from the other analysis, with its
    /// witness or certificate; a decided one is kept.
    #[test]
    fn unknown_verdicts_are_completed_from_the_other_member() {
        let a2 = Model::from_id("A2").unwrap();
        let limits = SearchLimits::default();
        let own = analyze_alone(&a2, &limits);
        let other = analyze_alone(&a2.mirrored(), &limits).mirrored(&a2.mirrored());
        let mut blanked = own.clone();
        for v in blanked.types.iter_mut().step_by(2) {
            *v = TypeVerdict {
                status: Status::Unknown,
                witness: None,
                certificate: None,
                ..v.clone()
            };
        }
        let done = completed(blanked, &other.types);
        let by_type = |a: &ModelAnalysis| -> BTreeMap<String, TypeVerdict> {
            a.types
                .iter()
                .map(|v| (v.frf_type.to_string(), v.clone()))
                .collect()
        };
        let (own, other, done) = (by_type(&own), by_type(&other), by_type(&done));
        assert_eq!(done.len(), own.len());
        for (k, (t, v)) in done.iter().enumerate() {
            assert_eq!(v.status, own[t].status, "{t}");
            // Every other verdict was blanked (in the analysis's order,
            // not this map's): each one is either its own or the other's.
            assert!(*v == own[t] || *v == other[t], "{t} ({k})");
        }
        assert!(done
            .iter()
            .any(|(t, v)| *v == other[t] && other[t] != own[t]));
    }
}
