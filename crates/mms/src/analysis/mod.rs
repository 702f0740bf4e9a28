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

mod configurations;
mod explain;
mod frf_type;
mod lp;
mod pole_signs;
mod prover;
mod targeted;
mod walls;

pub use explain::{explain, ExplainFormat};
pub use frf_type::{
    candidate_types, frf_type_at, frf_type_of, Feature, FrfType, ParseFrfTypeError, Token,
};
pub use pole_signs::{BlockPoleSigns, BlockSign, PoleSigns, RemainderFactor};
pub use prover::{
    ConditionRule, Definiteness, FactorProof, OpenProof, Proof, RegionSample, SearchLimits,
    SignCase, SignCondition, Substitution,
};

use crate::model::Model;
use crate::tf::OMEGA;
use poly::{Poly, Rat};
use prover::Prover;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

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

/// A critical factor of the whole orthant and what the engine knows of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CriticalFactor {
    /// The irreducible factor.
    pub factor: Poly,
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
pub const ENGINE_VERSION: u32 = 10;

/// Decides every candidate FRF type of `model` (see the module docs).
pub fn analyze(model: &Model, limits: &SearchLimits) -> ModelAnalysis {
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
        });
    }
    // Rare generic types: a targeted search, then the verdicts it changes.
    let unknown: Vec<FrfType> = verdicts
        .iter()
        .filter(|v| v.status == Status::Unknown)
        .map(|v| v.frf_type.clone())
        .collect();
    let found = prover.targeted_search(&unknown, 0x7A26_E7ED)
        + prover.partial_wall_search(&unknown, limits.partial_wall_depth)
        + prover.root_condition_search(&unknown, 0x2007_C0DE)
        + prover.cancellation_search(&unknown, 0xCA2C_E11E)
        + prover.discriminant_search(&unknown, 0xD15C_0001)
        + prover.elimination_search(&unknown, 0xE11_4A7E);
    if found > 0 {
        for v in verdicts.iter_mut().filter(|v| v.status == Status::Unknown) {
            if let Some(w) = prover.witnesses.get(&v.frf_type) {
                v.status = Status::Possible;
                v.witness = Some(w.clone());
            }
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
    let rank = |s: Status| match s {
        Status::Possible => 0,
        Status::Unknown => 1,
        Status::Impossible => 2,
    };
    verdicts.sort_by_key(|v| rank(v.status)); // stable: keeps candidate order
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
            CriticalFactor {
                factor: f.poly.clone(),
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
