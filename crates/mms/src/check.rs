//! An independent checker for the output of `mms analyze --format json`
//! (an [`AnalysisTable`]).
//!
//! The checker re-verifies every verdict of such a file with exact
//! arithmetic. It shares nothing with the prover of [`crate::analysis`] but
//! the `poly` crate's arithmetic and the model's structure ([`Model`]): it
//! reads the JSON itself, re-derives the transfer function from the mass and
//! stiffness matrices, classifies FRF types with its own code and recomputes
//! every stratum, critical polynomial and sign condition a certificate
//! relies on. A bug in the prover cannot hide in the check.
//!
//! Per model it verifies:
//!
//! 1. the transfer function: the file's `numerator` and `denominator` equal
//!    `c^T adj(K - Omega*M) b` and `det(K - Omega*M) / Omega` up to nonzero
//!    rational constants (the file's polynomials are used from then on);
//! 2. every *possible* type: its witness assigns a positive rational to
//!    exactly the model's undamped parameters, and the reduced transfer
//!    function there has that type (exact real-root isolation); or its
//!    path (a double or triple zero shown by continuity, see
//!    [`crate::analysis::MergePath`]) gives every parameter a rational
//!    function of `s` without zero or pole on `[0, 1]` and positive there;
//!    along the path the transfer function, reduced by its gcd and its
//!    zero roots, has the numerator `h^2 m` (`h = gcd(n, n')` of degree
//!    zero or one in `Omega`: a double zero kept all along); the leading
//!    and lowest coefficients of `m`, `h` and the denominator, the
//!    resultants of the denominator with `m` and `h`, and the
//!    denominator's discriminant have no root in `[0, 1]`; of the
//!    discriminant of `m` and the resultant of `h` and `m` one has exactly
//!    one root in `(0, 1)` and the other none (Sturm sequences; resultants
//!    as Sylvester determinants, interpolated in `s`); and the wanted type
//!    is the type at `s = 0` with the two neighbouring zeros merged that
//!    the type at `s = 1` shows met there (a simple pair gone off the
//!    axis, or a simple zero and the double zero swapped), the same for
//!    every such pair; for a pair, the first principal subresultant
//!    coefficient of `m` and `m'` is not zero at the meeting; or its
//!    algebraic witness ([`crate::analysis::AlgebraicWitness`]): the field
//!    is rebuilt (the defining polynomial irreducible over Q, one root in
//!    the interval), every parameter is positive at `theta`, the claimed
//!    cancelled poles and multiple zeros divide the transfer function
//!    exactly and are no roots of what remains, and the rest's positive
//!    roots, isolated together by Descartes' rule over the field, are
//!    simple, hold every pole, and give the type with the posed roots; or
//!    its isolated witness ([`crate::analysis::IsolatedWitness`], read by
//!    its own code in `check/isolated.rs`): the posed conditions, with the
//!    fixed parameters substituted, are a square system in the free ones
//!    with exactly one solution in the box by Krawczyk's test in exact
//!    interval arithmetic (a pose's factors replacing numerator and
//!    denominator where its cofactors multiply out to both), and the rests
//!    left by the posed roots have, on the whole box, one sign at the
//!    partition's points and at most one sign variation (Descartes' rule)
//!    on each piece, not one for both, every pole placed;
//! 3. every *impossible* type: its certificate, a tree of proofs over
//!    strata (see [`crate::analysis::Proof`] for the format): the stratum's
//!    substitutions, the coverage of its critical polynomials (leading
//!    coefficients, values at `Omega = 0`, resultants computed here as
//!    Sylvester determinants) by the listed factors, each factor's proof
//!    (sign-definiteness, cancellation counting, or a wall with its own
//!    proof, checked recursively) and the proof for the open part (counting,
//!    multiplicities, Descartes' rule, connected regions with sample
//!    points, or refuted sign conditions); or one of two structural
//!    theorems that hold on the whole orthant, whose premises it checks on
//!    the model's matrices and polynomials; or a limit of generic types
//!    (`limits`): the reduced TF's leading and constant coefficients of
//!    one sign, numerator and denominator square-free and coprime at the
//!    certificate's point (exact gcds), and every generic type that
//!    gathers into the type (every gathering written out here, not the
//!    prover's recursion) listed and certified impossible in the same
//!    model;
//! 4. the derived fields, where present: the pole-zero cancellations, the
//!    critical factors (coverage, `cancels`, each status's proof), the
//!    count of moment invariants and the determinable parameters (the rank
//!    of its own Jacobian at a point, against the listed unidentifiable
//!    directions multiplied out; or, where the file claims only a range,
//!    each end of it).
//!
//! The checker relies on three theorems it cannot check by computation:
//! the roots of the denominator are real and positive for all positive
//! parameters (eigenvalues of a symmetric definite pencil); an unreduced
//! symmetric tridiagonal matrix has simple eigenvalues (premise checked:
//! `M` diagonal positive, `K` tridiagonal with negative or zero
//! off-diagonal entries; `simple_resonances`); and a collocated receptance
//! is a sum of modal terms with positive residues (premise checked:
//! actuator = sensor, rigid-body pole uncancelled; `collocated_modes`).
//!
//! ```
//! use mms::analysis::{analyze, SearchLimits};
//! use mms::check::{check_file, CheckError};
//! use mms::table::{AnalysisTable, Covers, TableModel};
//!
//! let a2 = mms::Model::from_id("A2")?;
//! let analysis = TableModel::new(analyze(&a2, &SearchLimits::default()));
//! let table = AnalysisTable::new(Covers::Models(vec!["A2".into()]), vec![analysis]);
//! let mut file = table.to_value();
//! let report = check_file(&file.to_string())?;
//! assert_eq!(report.witnesses, 3); // ARR, RAR and R
//! assert_eq!(report.to_string(), "checked 3 witnesses and 5 certificates: all valid");
//!
//! // A witness moved off the cancellation wall no longer shows type R.
//! let verdict = &mut file["models"][0]["types"][2];
//! assert_eq!(verdict["type"], "R");
//! verdict["witness"]["m1"] = "17/3".into();
//! let err = check_file(&file.to_string()).unwrap_err();
//! assert!(matches!(err, CheckError::Type { .. }));
//! assert!(err.to_string().starts_with("model A2, type R: witness"), "{err}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod isolated;

/// The checker's reading of a box witness (its JSON form), as text: for
/// the prover's tests, which compare a box they find with this reading.
#[cfg(test)]
pub(crate) fn isolated_type(
    num: &Poly,
    den: &Poly,
    params: &[String],
    v: &Value,
) -> Result<String, String> {
    isolated::read_isolated(num, den, params, v).map(|t| t.to_string())
}

use crate::model::{Model, Port};
use crate::table::{AnalysisTable, TableError};
use poly::{
    adjugate, count_roots_in, det, gcd, interleave_roots, psc, square_free, sylvester_matrix,
    FieldElem, FieldPoly, Int, Poly, Rat, RealField, UPoly,
};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fmt;
use std::rc::Rc;

/// The frequency variable `Omega = omega^2` of the undamped transfer function.
const OMEGA: &str = "Omega";
/// The generator of an algebraic witness's field, as the table names it.
const THETA: &str = "theta";

/// Deepest nesting of `completed_square` definiteness arguments accepted.
const MAX_DEFINITENESS_DEPTH: usize = 16;

/// Largest Polya exponent accepted (the multiplied polynomial grows fast).
const MAX_POLYA_POWER: u64 = 64;

/// The checker's version: raised whenever a change makes it accept or
/// reject a file differently, so that a record of an earlier check (see
/// [`CheckHooks::recall`]) made by another version is not reused.
pub const CHECKER_VERSION: u32 = 1;

/// What a successful check covered.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CheckReport {
    /// Models checked (each with its transfer function).
    pub models: usize,
    /// Witnesses of possible types checked.
    pub witnesses: usize,
    /// Certificates of impossible types checked.
    pub certificates: usize,
    /// Proofs checked inside the certificates, nested wall proofs included.
    pub proofs: usize,
    /// Types the file leaves unknown (nothing to check).
    pub unknown: usize,
    /// Critical factors whose sign the file leaves `undetermined` (no
    /// claim, nothing to check).
    pub undetermined_factors: usize,
}

impl CheckReport {
    /// Adds the counts of `other` (a report of other models) to these.
    pub fn add(&mut self, other: &CheckReport) {
        self.models += other.models;
        self.witnesses += other.witnesses;
        self.certificates += other.certificates;
        self.proofs += other.proofs;
        self.unknown += other.unknown;
        self.undetermined_factors += other.undetermined_factors;
    }
}

impl fmt::Display for CheckReport {
    /// `checked 25 witnesses and 193 certificates: all valid`, with the
    /// number of unknown types appended when there are any.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "checked {} witnesses and {} certificates: all valid",
            self.witnesses, self.certificates
        )?;
        if self.unknown > 0 {
            write!(f, " ({} types left unknown)", self.unknown)?;
        }
        Ok(())
    }
}

/// Why a file is rejected. The message is one line and names the model,
/// the type and the failing step.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CheckError {
    /// The text is not an analysis table this version reads.
    #[error("{0}")]
    Table(#[from] TableError),
    /// The JSON lacks a key or has a value of the wrong kind outside a model.
    #[error("{path}: {problem}")]
    Malformed {
        /// Where, e.g. `models[2]`.
        path: String,
        /// What is wrong.
        problem: String,
    },
    /// A model-level step failed (model structure, transfer function).
    #[error("model {model}: {step}")]
    Model {
        /// The model's ID.
        model: String,
        /// The failing step.
        step: String,
    },
    /// The verdict on one type failed its check.
    #[error("model {model}, type {frf_type}: {step}")]
    Type {
        /// The model's ID.
        model: String,
        /// The type as written in the file.
        frf_type: String,
        /// The failing step.
        step: String,
    },
}

/// Checks a whole file, an [`AnalysisTable`] as written by `mms analyze
/// --format json`. See the [module docs](self).
pub fn check_file(text: &str) -> Result<CheckReport, CheckError> {
    check_file_on(text, 1)
}

/// [`check_file`] with the models checked on `threads` threads (at least
/// one). The report, and the error when several models fail (the first in
/// the file's order), are the same for every number of threads.
///
/// ```
/// use mms::analysis::{analyze, SearchLimits};
/// use mms::check::{check_file, check_file_on};
/// use mms::table::{AnalysisTable, Covers, TableModel};
///
/// let models: Vec<TableModel> = ["A1", "A2", "B1"]
///     .iter()
///     .map(|id| TableModel::new(analyze(&mms::Model::from_id(id).unwrap(), &SearchLimits::default())))
///     .collect();
/// let covers = Covers::Models(vec!["A1".into(), "A2".into(), "B1".into()]);
/// let text = AnalysisTable::new(covers, models).to_json();
/// assert_eq!(check_file_on(&text, 3)?, check_file(&text)?);
/// # Ok::<(), mms::check::CheckError>(())
/// ```
pub fn check_file_on(text: &str, threads: usize) -> Result<CheckReport, CheckError> {
    check_file_with(text, threads, &NoHooks)
}

/// What a caller of [`check_file_with`] sees of a long check, and where it
/// may keep the models it has verified, so that an interrupted check
/// resumes and a table merged from checked slices is not checked twice.
/// Every method does nothing by default. Called from several threads.
pub trait CheckHooks: Sync {
    /// The report of an earlier check of exactly this model entry (the
    /// object of the file's `models` array without its `similar`, which
    /// depends on the whole file) by this [`CHECKER_VERSION`], if the
    /// caller kept one; the entry is then not checked again. Coverage and
    /// `similar` are always checked.
    fn recall(&self, _entry: &Value) -> Option<CheckReport> {
        None
    }
    /// The model entry `entry` was checked and is valid, with `report`.
    fn checked(&self, _entry: &Value, _report: &CheckReport) {}
    /// The file holds `count` models (told once, before the first starts).
    fn planned(&self, _count: usize) {}
    /// The model `id` is being checked (or recalled).
    fn started(&self, _id: &str) {}
    /// The model `id` is done, valid or not.
    fn finished(&self, _id: &str) {}
}

/// The [`CheckHooks`] that keep nothing and show nothing.
pub struct NoHooks;

impl CheckHooks for NoHooks {}

/// [`check_file_on`] with `hooks` told of each model as it starts and
/// ends, and asked first whether it already verified a model entry. The
/// report, and the error when a model fails, are those of
/// [`check_file_on`]: a recalled report stands for the model's check.
///
/// ```
/// use mms::analysis::{analyze, SearchLimits};
/// use mms::check::{check_file_on, check_file_with, CheckHooks, CheckReport};
/// use mms::table::{AnalysisTable, Covers, TableModel};
/// use serde_json::Value;
/// use std::sync::Mutex;
///
/// /// Remembers verified entries in memory.
/// #[derive(Default)]
/// struct Memory(Mutex<Vec<(Value, CheckReport)>>);
/// impl CheckHooks for Memory {
///     fn recall(&self, entry: &Value) -> Option<CheckReport> {
///         let kept = self.0.lock().unwrap();
///         kept.iter().find(|(e, _)| e == entry).map(|(_, r)| r.clone())
///     }
///     fn checked(&self, entry: &Value, report: &CheckReport) {
///         self.0.lock().unwrap().push((entry.clone(), report.clone()));
///     }
/// }
///
/// let a1 = TableModel::new(analyze(&mms::Model::from_id("A1")?, &SearchLimits::default()));
/// let text = AnalysisTable::new(Covers::Models(vec!["A1".into()]), vec![a1]).to_json();
/// let memory = Memory::default();
/// let first = check_file_with(&text, 1, &memory)?;
/// assert_eq!(memory.0.lock().unwrap().len(), 1);
/// // The second time the model is recalled, with the same report.
/// assert_eq!(check_file_with(&text, 1, &memory)?, first);
/// assert_eq!(first, check_file_on(&text, 1)?);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn check_file_with(
    text: &str,
    threads: usize,
    hooks: &dyn CheckHooks,
) -> Result<CheckReport, CheckError> {
    // The typed table holds the file to the format; the walk reads the
    // file's own tree, rather than printing every polynomial of the typed
    // table back into one.
    AnalysisTable::from_json(text).map_err(CheckError::Table)?;
    let v: Value = serde_json::from_str(text).map_err(|e| TableError::Json(e.to_string()))?;
    check_tree(&v, threads, hooks)
}

/// Checks a table: every model it covers, every verdict with its witness
/// or certificate, and the derived fields. The table is read as the
/// claims it makes: the check walks its JSON tree with its own code and
/// re-derives everything, using none of the prover's methods.
pub fn check_table(table: &AnalysisTable) -> Result<CheckReport, CheckError> {
    check_tree(&table.to_value(), 1, &NoHooks)
}

/// [`check_table`] of a table's JSON tree, the models on `threads` threads.
fn check_tree(
    v: &Value,
    threads: usize,
    hooks: &dyn CheckHooks,
) -> Result<CheckReport, CheckError> {
    let models = v["models"]
        .as_array()
        .ok_or_else(|| CheckError::Malformed {
            path: "models".into(),
            problem: "expected an array".into(),
        })?;
    // An empty table claims nothing: "all valid" would be a wrong answer.
    if models.is_empty() {
        return Err(CheckError::Malformed {
            path: "models".into(),
            problem: "empty: the file claims no model".into(),
        });
    }
    check_coverage(v, models)?;
    hooks.planned(models.len());
    let mut report = CheckReport::default();
    for r in check_models(models, threads, hooks) {
        report.add(&r?);
    }
    // With every class present, the similar systems follow from the
    // verdicts just checked.
    if v.get("covers").and_then(|c| c.get("masses")).is_some() {
        check_similar(models)?;
    }
    Ok(report)
}

/// Each model's check, in the file's order, up to and including the
/// first failing one. The models go to `threads` threads one at a time as
/// each thread frees (their costs differ by orders of magnitude); a thread
/// skips the models after a known failure, but never one before it, so
/// the first failure in the file's order is always found.
fn check_models(
    models: &[Value],
    threads: usize,
    hooks: &dyn CheckHooks,
) -> Vec<Result<CheckReport, CheckError>> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;
    let next = AtomicUsize::new(0);
    let first_failure = AtomicUsize::new(usize::MAX);
    let results: Mutex<Vec<Option<Result<CheckReport, CheckError>>>> =
        Mutex::new(vec![None; models.len()]);
    let work = || loop {
        let i = next.fetch_add(1, Ordering::Relaxed);
        if i >= models.len() {
            break;
        }
        if i > first_failure.load(Ordering::Relaxed) {
            continue;
        }
        let m = &models[i];
        let id = m.get("id").and_then(Value::as_str).unwrap_or("?");
        hooks.started(id);
        let own = own_claims(m);
        let r = match hooks.recall(&own) {
            Some(report) => Ok(report),
            None => {
                let r = check_model_at(m, &format!("models[{i}]"), true);
                if let Ok(report) = &r {
                    hooks.checked(&own, report);
                }
                r
            }
        };
        hooks.finished(id);
        if r.is_err() {
            first_failure.fetch_min(i, Ordering::Relaxed);
        }
        results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(r);
    };
    std::thread::scope(|scope| {
        for _ in 1..threads.max(1) {
            scope.spawn(work);
        }
        work();
    });
    let results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    let mut out = Vec::new();
    for r in results {
        // Every model up to the first failure was checked.
        let Some(r) = r else { break };
        let failed = r.is_err();
        out.push(r);
        if failed {
            break;
        }
    }
    out
}

/// A model's entry as its own check reads it: without `similar`, which
/// is checked against the whole table (and which a slice does not have).
fn own_claims(m: &Value) -> std::borrow::Cow<'_, Value> {
    match m.as_object() {
        Some(o) if o.contains_key("similar") => {
            let mut own = o.clone();
            own.remove("similar");
            std::borrow::Cow::Owned(Value::Object(own))
        }
        _ => std::borrow::Cow::Borrowed(m),
    }
}

/// Every model's `similar`, where given: for each type it can show, the
/// other models of the file (another structure) that can show it too, in
/// the file's order, recomputed from the file's (checked) verdicts.
fn check_similar(models: &[Value]) -> Result<(), CheckError> {
    let mut possible: Vec<(String, String, Vec<String>)> = Vec::with_capacity(models.len());
    for (i, m) in models.iter().enumerate() {
        let path = format!("models[{i}]");
        let bad = |e: String| CheckError::Malformed {
            path: path.clone(),
            problem: e,
        };
        let id = str_field(m, "id", &path).map_err(bad)?.to_string();
        let generic = str_field(m, "generic_id", &path).map_err(bad)?.to_string();
        let mut types = Vec::new();
        for (j, t) in arr_field(m, "types", &path)
            .map_err(bad)?
            .iter()
            .enumerate()
        {
            let vpath = format!("{path}.types[{j}]");
            if str_field(t, "status", &vpath).map_err(bad)? == "possible" {
                types.push(str_field(t, "type", &vpath).map_err(bad)?.to_string());
            }
        }
        possible.push((id, generic, types));
    }
    for (i, m) in models.iter().enumerate() {
        let (id, generic, types) = &possible[i];
        let err = |step: String| CheckError::Model {
            model: id.clone(),
            step,
        };
        let path = format!("models[{i}]");
        // Optional: a file without it claims no similar systems.
        if m.get("similar").is_none() {
            continue;
        }
        let listed = arr_field(m, "similar", &path).map_err(err)?;
        if listed.len() != types.len() {
            return Err(err(format!(
                "similar: {} entries for {} possible types",
                listed.len(),
                types.len()
            )));
        }
        for (t, entry) in types.iter().zip(listed) {
            let spath = format!("similar[{t}]");
            let ty = str_field(entry, "type", &spath).map_err(err)?;
            if ty != t {
                return Err(err(format!("similar: {ty} where {t} was expected")));
            }
            let want: Vec<&str> = possible
                .iter()
                .filter(|(_, g, ts)| g != generic && ts.contains(t))
                .map(|(other, ..)| other.as_str())
                .collect();
            let have: Vec<&str> = arr_field(entry, "models", &spath)
                .map_err(err)?
                .iter()
                .filter_map(Value::as_str)
                .collect();
            if have != want {
                return Err(err(format!(
                    "similar[{t}]: the file lists {have:?}, its verdicts give {want:?}"
                )));
            }
        }
    }
    Ok(())
}

/// The file's `covers` holds it to what it claims: `{"masses": N}`, every
/// class of `N` masses (under renumbering) once, or `{"models": [ids]}`,
/// exactly those models; a file that says neither is refused, since a
/// pruned table would otherwise pass as a complete one.
fn check_coverage(v: &Value, models: &[Value]) -> Result<(), CheckError> {
    let malformed = |path: &str, problem: String| CheckError::Malformed {
        path: path.into(),
        problem,
    };
    let covers = v.get("covers").ok_or_else(|| {
        malformed(
            "file",
            "missing key \"covers\": the file does not say what it covers (every class of N \
             masses, or a list of models); write it with mms analyze"
                .into(),
        )
    })?;
    let mut structures = Vec::with_capacity(models.len());
    for (i, m) in models.iter().enumerate() {
        let path = format!("models[{i}]");
        let id = str_field(m, "id", &path).map_err(|e| malformed(&path, e))?;
        let model = read_model(m, &path).map_err(|e| malformed(&path, e))?;
        structures.push((id.to_string(), model));
    }
    // Every class of N masses, or every `count`-th from `index - 1` (a
    // slice of such a table).
    let (masses, slice) = match (covers.get("masses"), covers.get("slice")) {
        (Some(n), _) => (Some(n), None),
        (None, Some(s)) => {
            let number = |key: &str| {
                s.get("shard")
                    .and_then(|sh| sh.get(key))
                    .and_then(Value::as_u64)
                    .map(index)
            };
            let (k, c) = (number("index"), number("count"));
            match (k, c) {
                (Some(k), Some(c)) if k >= 1 && k <= c => (s.get("masses"), Some((k, c))),
                _ => {
                    return Err(malformed(
                        "covers.slice",
                        "expected a shard K/N with 1 <= K <= N".into(),
                    ))
                }
            }
        }
        (None, None) => (None, None),
    };
    if let Some(n) = masses {
        let n = n
            .as_u64()
            .filter(|&n| (1..=crate::model::MAX_MASSES as u64).contains(&n))
            .ok_or_else(|| malformed("covers.masses", format!("not a number of masses: {n}")))?;
        let classes = crate::enumerate::equivalence_classes(index(n), crate::Symmetry::Renumbering)
            .map_err(|e| malformed("covers.masses", e.to_string()))?;
        let held = |c: usize| slice.is_none_or(|(k, count)| c % count + 1 == k);
        let mut seen: Vec<Option<String>> = vec![None; classes.len()];
        for (id, model) in &structures {
            let Some(c) = classes.iter().position(|c| c.contains(model)) else {
                return Err(malformed(
                    "models",
                    format!("{id} is not a model of {n} masses"),
                ));
            };
            if !held(c) {
                let (k, count) = slice.unwrap_or((1, 1));
                return Err(malformed(
                    "models",
                    format!("{id} is not in slice {k}/{count} of the classes of {n} masses"),
                ));
            }
            if let Some(other) = &seen[c] {
                return Err(malformed(
                    "models",
                    format!("{id} and {other} are the same class: a class appears twice"),
                ));
            }
            seen[c] = Some(id.clone());
        }
        if let Some(c) = (0..classes.len()).find(|&c| held(c) && seen[c].is_none()) {
            return Err(malformed(
                "models",
                format!(
                    "the class of {} is missing: the file covers {n} masses, {} classes, and \
                     lists {}",
                    classes[c][0].id(),
                    classes.len(),
                    structures.len()
                ),
            ));
        }
        return Ok(());
    }
    let listed = covers
        .get("models")
        .and_then(Value::as_array)
        .ok_or_else(|| {
            malformed(
                "covers",
                "expected {\"masses\": N} or {\"models\": [ids]}".into(),
            )
        })?;
    let ids: Vec<&str> = listed.iter().filter_map(Value::as_str).collect();
    if ids.len() != listed.len() {
        return Err(malformed(
            "covers.models",
            "expected model IDs (strings)".into(),
        ));
    }
    // A model is named by the paper's ID or the generic one: compared as
    // the structures they name.
    let mut covered = Vec::with_capacity(ids.len());
    for id in &ids {
        let model =
            Model::from_id(id).map_err(|e| malformed("covers.models", format!("{id}: {e}")))?;
        match structures.iter().filter(|(_, m)| *m == model).count() {
            1 => {}
            0 => return Err(malformed("models", format!("{id} is covered but missing"))),
            _ => return Err(malformed("models", format!("{id} appears more than once"))),
        }
        covered.push(model);
    }
    if let Some((extra, _)) = structures.iter().find(|(_, m)| !covered.contains(m)) {
        return Err(malformed(
            "models",
            format!("{extra} is not among the models the file covers"),
        ));
    }
    Ok(())
}

/// Checks one model object of such a file (an element of its `models`
/// array: the serialized [`crate::analysis::ModelAnalysis`]): every verdict
/// it lists. That it lists every type is the file's claim, which
/// [`check_file`] holds it to.
pub fn check_analysis(model: &Value) -> Result<CheckReport, CheckError> {
    check_model_at(model, "model", false)
}

// ---------------------------------------------------------------------------
// JSON access

fn field<'a>(v: &'a Value, key: &str, path: &str) -> Result<&'a Value, String> {
    if !v.is_object() {
        return Err(format!("{path}: expected an object"));
    }
    v.get(key)
        .ok_or_else(|| format!("{path}: missing key \"{key}\""))
}

fn str_field<'a>(v: &'a Value, key: &str, path: &str) -> Result<&'a str, String> {
    field(v, key, path)?
        .as_str()
        .ok_or_else(|| format!("{path}.{key}: expected a string"))
}

fn arr_field<'a>(v: &'a Value, key: &str, path: &str) -> Result<&'a Vec<Value>, String> {
    field(v, key, path)?
        .as_array()
        .ok_or_else(|| format!("{path}.{key}: expected an array"))
}

fn uint_field(v: &Value, key: &str, path: &str) -> Result<u64, String> {
    field(v, key, path)?
        .as_u64()
        .ok_or_else(|| format!("{path}.{key}: expected a nonnegative integer"))
}

fn int_field(v: &Value, key: &str, path: &str) -> Result<i64, String> {
    field(v, key, path)?
        .as_i64()
        .ok_or_else(|| format!("{path}.{key}: expected an integer"))
}

fn bool_field(v: &Value, key: &str, path: &str) -> Result<bool, String> {
    field(v, key, path)?
        .as_bool()
        .ok_or_else(|| format!("{path}.{key}: expected true or false"))
}

fn rat_value(v: &Value, path: &str) -> Result<Rat, String> {
    let s = v
        .as_str()
        .ok_or_else(|| format!("{path}: expected a rational as a string"))?;
    s.parse::<Rat>()
        .map_err(|e| format!("{path}: not a rational ({e}): {s:?}"))
}

fn poly_value(v: &Value, path: &str) -> Result<Poly, String> {
    let s = v
        .as_str()
        .ok_or_else(|| format!("{path}: expected a polynomial as a string"))?;
    s.parse::<Poly>()
        .map_err(|e| format!("{path}: not a polynomial ({e}): {s:?}"))
}

fn poly_field(v: &Value, key: &str, path: &str) -> Result<Poly, String> {
    poly_value(field(v, key, path)?, &format!("{path}.{key}"))
}

fn polys_field(v: &Value, key: &str, path: &str) -> Result<Vec<Poly>, String> {
    arr_field(v, key, path)?
        .iter()
        .enumerate()
        .map(|(i, x)| poly_value(x, &format!("{path}.{key}[{i}]")))
        .collect()
}

fn index(i: u64) -> usize {
    usize::try_from(i).unwrap_or(usize::MAX)
}

// ---------------------------------------------------------------------------
// Polynomial helpers

/// `p = c * q` for a nonzero rational `c` (both nonzero).
fn proportional(p: &Poly, q: &Poly) -> bool {
    if p.is_zero() || q.is_zero() {
        return false;
    }
    p.scale(&p.leading_coef().recip()) == q.scale(&q.leading_coef().recip())
}

/// The constant `c` with `p = c * q`, if there is one.
fn ratio(p: &Poly, q: &Poly) -> Option<Rat> {
    if !proportional(p, q) {
        return None;
    }
    Some(&p.leading_coef() / &q.leading_coef())
}

/// No coefficient is negative (the zero polynomial included).
fn nonnegative_coefs(p: &Poly) -> bool {
    p.terms().iter().all(|t| t.coef.signum() >= 0)
}

/// The resultant in `Omega`, as the determinant of the Sylvester matrix.
/// When its entries are polynomials in one variable (a path's `s`), the
/// determinant is taken at enough integers and interpolated
/// ([`interpolated_det`]): the expansion over polynomial entries costs
/// far more on long paths.
fn sylvester_resultant(a: &Poly, b: &Poly) -> Poly {
    let m = sylvester_matrix(a, b, OMEGA);
    let mut vars: BTreeSet<&String> = BTreeSet::new();
    for e in m.iter().flatten() {
        vars.extend(e.vars());
    }
    match vars.into_iter().collect::<Vec<_>>().as_slice() {
        [v] => interpolated_det(&m, v),
        _ => det(&m),
    }
}

/// The determinant of `m`, whose entries are polynomials in `v` alone:
/// each row scaled to integer coefficients, the determinant's degree is at
/// most the sum over the rows of their entries' largest degree, `D`; it is
/// evaluated exactly at `v = 0, 1, ..., D` (fraction-free elimination) and
/// interpolated from its forward differences, `sum_j Delta^j f(0) C(v, j)`.
fn interpolated_det(m: &[Vec<Poly>], v: &str) -> Poly {
    let mut scale = Int::from(1);
    let rows: Vec<Vec<Vec<Int>>> = m
        .iter()
        .map(|row| {
            let den = row
                .iter()
                .flat_map(|e| e.terms())
                .fold(Int::from(1), |l, t| l.lcm(t.coef.denom()));
            scale = &scale * &den;
            row.iter()
                .map(|e| {
                    let mut c = vec![Int::from(0); e.degree(v) as usize + 1];
                    for t in e.terms() {
                        let k = e
                            .vars()
                            .iter()
                            .position(|x| x == v)
                            .map_or(0, |i| t.exps[i]);
                        c[k as usize] = (t.coef.numer() * &den).div_exact(t.coef.denom());
                    }
                    c
                })
                .collect()
        })
        .collect();
    let bound: usize = rows
        .iter()
        .map(|row| row.iter().map(|c| c.len() - 1).max().unwrap_or(0))
        .sum();
    let mut diff: Vec<Int> = (0..=bound)
        .map(|i| {
            let x = Int::from(i as i64);
            let at: Vec<Vec<Int>> = rows
                .iter()
                .map(|row| {
                    row.iter()
                        .map(|c| c.iter().rev().fold(Int::from(0), |acc, k| &(&acc * &x) + k))
                        .collect()
                })
                .collect();
            integer_det(at)
        })
        .collect();
    // Forward differences in place: diff[j] = Delta^j f(0).
    for j in 1..diff.len() {
        for i in (j..diff.len()).rev() {
            diff[i] = &diff[i] - &diff[i - 1];
        }
    }
    // sum_j diff[j] v (v - 1) ... (v - j + 1) / j!, over the integers
    // times D!, then divided by D! and the rows' scale.
    let mut factorial = Int::from(1);
    for k in 2..=bound as i64 {
        factorial = &factorial * &Int::from(k);
    }
    let mut total = vec![Int::from(0); bound + 1];
    let mut falling = vec![Int::from(1)]; // v (v - 1) ... (v - j + 1)
    let mut weight = factorial.clone(); // D! / j!
    for (j, d) in diff.iter().enumerate() {
        if j > 0 {
            weight = weight.div_exact(&Int::from(j as i64));
            let k = Int::from(j as i64 - 1);
            let mut next = vec![Int::from(0); falling.len() + 1];
            for (e, c) in falling.iter().enumerate() {
                next[e + 1] = &next[e + 1] + c;
                next[e] = &next[e] - &(c * &k);
            }
            falling = next;
        }
        let w = d * &weight;
        for (e, c) in falling.iter().enumerate() {
            total[e] = &total[e] + &(c * &w);
        }
    }
    let x = Poly::var(v);
    let den = &factorial * &scale;
    total
        .into_iter()
        .enumerate()
        .filter(|(_, c)| !c.is_zero())
        .fold(Poly::zero(), |acc, (e, c)| {
            &acc + &x.pow(e as u32).scale(&Rat::new(c, den.clone()))
        })
}

/// The determinant of a square integer matrix by fraction-free (Bareiss)
/// elimination: every division is exact.
fn integer_det(mut a: Vec<Vec<Int>>) -> Int {
    let n = a.len();
    if n == 0 {
        return Int::from(1);
    }
    let mut sign = 1;
    let mut prev = Int::from(1);
    for k in 0..n - 1 {
        let Some(p) = (k..n).find(|&r| !a[r][k].is_zero()) else {
            return Int::from(0);
        };
        if p != k {
            a.swap(p, k);
            sign = -sign;
        }
        for i in k + 1..n {
            for j in k + 1..n {
                let t = &(&a[i][j] * &a[k][k]) - &(&a[i][k] * &a[k][j]);
                a[i][j] = t.div_exact(&prev);
            }
        }
        prev = a[k][k].clone();
    }
    let d = a[n - 1][n - 1].clone();
    if sign < 0 {
        -d
    } else {
        d
    }
}

/// The discriminant in `Omega` of `p` (degree `d >= 2`):
/// `(-1)^(d(d-1)/2) Res(p, p') / lc(p)`.
fn discriminant_of(p: &Poly) -> Result<Poly, String> {
    let d = p.degree(OMEGA);
    let res = sylvester_resultant(p, &p.derivative(OMEGA));
    let lc = p.lead_in(OMEGA);
    let q = res
        .div_exact(&lc)
        .ok_or_else(|| format!("the leading coefficient of {p} does not divide Res(p, p')"))?;
    Ok(if (d * (d - 1) / 2) % 2 == 1 { -q } else { q })
}

/// `x = beta/alpha`.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Sub {
    var: String,
    alpha: Poly,
    beta: Poly,
}

impl fmt::Display for Sub {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = ({})/({})", self.var, self.beta, self.alpha)
    }
}

impl Sub {
    fn parse(v: &Value, path: &str) -> Result<Sub, String> {
        Ok(Sub {
            var: str_field(v, "var", path)?.to_string(),
            alpha: poly_field(v, "alpha", path)?,
            beta: poly_field(v, "beta", path)?,
        })
    }

    /// `p(var = beta/alpha) * alpha^deg_var(p)`.
    fn apply(&self, p: &Poly) -> Poly {
        let d = p.degree(&self.var);
        let mut out = Poly::zero();
        for (k, c) in p.coeffs_in(&self.var).iter().enumerate() {
            if c.is_zero() {
                continue;
            }
            let k = k as u32;
            out = &out + &(&(c * &self.beta.pow(k)) * &self.alpha.pow(d - k));
        }
        out
    }

    /// `alpha*var - beta`.
    fn wall_poly(&self) -> Poly {
        &(&self.alpha * &Poly::var(&self.var)) - &self.beta
    }
}

fn subs_key(subs: &[Sub]) -> String {
    subs.iter()
        .map(|s| s.to_string())
        .collect::<Vec<_>>()
        .join("; ")
}

fn subs_text(subs: &[Sub]) -> String {
    format!("[{}]", subs_key(subs))
}

/// The critical factors of the whole orthant the file lists (`critical`):
/// together they cover every critical polynomial of the model (leading
/// coefficients and values at `Omega = 0` of the TF's parts, their
/// resultants and discriminants, computed here), each divides one of them,
/// `cancels` says whether it divides a resultant of a numerator part and a
/// denominator part, and each `status` carries its proof: `definite` its
/// `sign` and `definiteness` argument (checked as in a certificate),
/// `wall` the `substitution` whose graph is its zero set; `undetermined`
/// claims nothing. An undetermined factor may be left out, with only its
/// `size` (six masses have factors of millions of terms): it then claims
/// nothing and covers nothing, so what is left of a critical polynomial
/// once the listed factors are divided out may be nonconstant only in a
/// file that leaves one out. Returns the number of undetermined factors.
fn check_critical(
    m: &Value,
    path: &str,
    top: &Stratum,
    checker: &mut ModelChecker,
) -> Result<usize, String> {
    let mut factors = Vec::new();
    let mut undetermined = 0;
    let mut leaves_one_out = false;
    for (i, e) in arr_field(m, "critical", path)?.iter().enumerate() {
        let cpath = format!("critical[{i}]");
        if e.get("factor").is_none() {
            if str_field(e, "status", &cpath)? != "undetermined" {
                return Err(format!(
                    "{cpath}: only an undetermined factor may be left out (no `factor`)"
                ));
            }
            field(e, "size", &cpath)?;
            undetermined += 1;
            leaves_one_out = true;
            continue;
        }
        let f = poly_field(e, "factor", &cpath)?;
        if f.is_constant() {
            return Err(format!("{cpath}: {f} is a constant"));
        }
        let divides = |c: &Critical| !c.poly.is_zero() && c.poly.div_exact(&f).is_some();
        if !top.critical.iter().any(divides) {
            return Err(format!("{cpath}: {f} divides no critical polynomial"));
        }
        let cancels = top
            .critical
            .iter()
            .any(|c| c.role == Role::Cancel && divides(c));
        if bool_field(e, "cancels", &cpath)? != cancels {
            return Err(format!(
                "{cpath}: {f} {} a resultant of a numerator and a denominator part: cancels \
                 must be {cancels}",
                if cancels { "divides" } else { "divides no" }
            ));
        }
        match str_field(e, "status", &cpath)? {
            "definite" => {
                let sign = int_field(e, "sign", &cpath)?;
                let d = field(e, "definiteness", &cpath)?;
                checker
                    .check_definite(&f, sign, d, &format!("{cpath}.definiteness"))
                    .map_err(|err| format!("{cpath}: {f} is not shown definite: {err}"))?;
            }
            "wall" => {
                let sub = Sub::parse(
                    field(e, "substitution", &cpath)?,
                    &format!("{cpath}.substitution"),
                )?;
                if !checker.params.contains(&sub.var) {
                    return Err(format!("{cpath}: {} is not a parameter", sub.var));
                }
                if !proportional(&f, &sub.wall_poly()) {
                    return Err(format!(
                        "{cpath}: {f} is not a constant multiple of the wall {}",
                        sub.wall_poly()
                    ));
                }
            }
            "undetermined" => undetermined += 1,
            other => return Err(format!("{cpath}.status: unknown status {other:?}")),
        }
        factors.push(f);
    }
    // A factor left out covers nothing, so whatever the listed ones leave
    // of a critical polynomial is then no error, and not worth dividing out.
    if leaves_one_out {
        return Ok(undetermined);
    }
    let factors: Vec<&Poly> = factors.iter().collect();
    for c in top.critical.iter().filter(|c| !c.poly.is_zero()) {
        if let Some(rest) = uncovered(&c.poly, &factors) {
            return Err(format!(
                "critical: {} is not covered by the listed factors (left {rest})",
                c.what
            ));
        }
    }
    Ok(undetermined)
}

/// What is left of `p` once every power of `factors` is divided out, if
/// that is not a nonzero constant (`p` is then not covered by them).
/// The premises of a factor treated by counting: a type with every pole
/// (`every_pole`, the factor cancels a pole) or with fewer resonances than
/// the stratum has poles (the factor cancels none), and every boundary
/// factor of the stratum definite (no pole escapes to zero or infinity).
fn counting_premises(
    resonances: u32,
    degree: u32,
    boundary_definite: bool,
    every_pole: bool,
) -> Result<(), String> {
    if every_pole && resonances != degree {
        return Err(format!(
            "the type has {resonances} resonances, the stratum's denominator degree {degree}"
        ));
    }
    if !every_pole && resonances >= degree {
        return Err(format!(
            "the type has {resonances} resonances, not fewer than the stratum's denominator degree {degree}"
        ));
    }
    if !boundary_definite {
        return Err("a boundary factor has no definite proof".into());
    }
    Ok(())
}

/// `p` in an error message: in full up to a few hundred characters, else
/// by its size (a six-mass critical polynomial can be hundreds of megabytes).
fn abridged(p: &Poly) -> String {
    if p.num_terms() <= 20 {
        p.to_string()
    } else {
        format!(
            "a polynomial of {} terms and total degree {}",
            p.num_terms(),
            p.total_degree()
        )
    }
}

/// True when `a` is shown to have no common factor of positive degree with
/// any of `others`. For each variable `x` of `a` the other variables are
/// set to integers where the leading coefficient of `a` in `x` does not
/// vanish; a common factor `g` keeps its degree in `x` there (its leading
/// coefficient divides `a`'s) and divides both images, so when the images
/// are coprime `g` is free of `x`. Free of every variable of `a`, it is a
/// constant. This never computes a multivariate gcd, whose cost on the
/// six-mass discriminants is out of reach. `false` may also mean that no
/// tried point separated them.
fn coprime_to_all(a: &Poly, others: &[&Poly]) -> bool {
    const TRIES: i64 = 4;
    if others.iter().any(|b| b.is_zero()) {
        return a.is_constant() && !a.is_zero();
    }
    let mut vars: Vec<&String> = a.vars().iter().collect();
    for b in others {
        for v in b.vars() {
            if !vars.contains(&v) {
                vars.push(v);
            }
        }
    }
    vars.sort();
    for x in a.vars() {
        let lead = a.lead_in(x);
        let mut pending: Vec<&Poly> = others.to_vec();
        for k in 0..TRIES {
            if pending.is_empty() {
                break;
            }
            // Distinct small integers, different for every try.
            let point: BTreeMap<String, Rat> = vars
                .iter()
                .enumerate()
                .filter(|(_, v)| **v != x)
                .map(|(i, v)| ((*v).clone(), Rat::from(2 + (7 * i as i64 + 13 * k) % 29)))
                .collect();
            if lead.eval(&point).map_or(true, |l| l.is_zero()) {
                continue;
            }
            let image = |p: &Poly| -> Option<UPoly> {
                let q = p.eval_except(x, &point).ok()?;
                UPoly::from_poly(&q, x).map(|(_, u)| u)
            };
            let Some(ua) = image(a) else { continue };
            pending.retain(|b| match image(b) {
                Some(ub) if !ub.is_zero() => !ua.gcd(&ub).is_constant(),
                _ => true,
            });
        }
        if !pending.is_empty() {
            return false;
        }
    }
    true
}

fn uncovered(p: &Poly, factors: &[&Poly]) -> Option<Poly> {
    let mut rest = p.clone();
    loop {
        let mut divided = false;
        for f in factors {
            while let Some(q) = rest.div_exact(f) {
                rest = q;
                divided = true;
            }
        }
        if !divided {
            break;
        }
    }
    (!rest.is_constant() || rest.is_zero()).then_some(rest)
}

/// The coefficients of the reduced TF (numerator and denominator, in
/// `Omega`) that are not constant once divided by the denominator's leading
/// one, with that leading coefficient: the input-output invariants `c /
/// lead` that can carry information on the parameters.
fn nonconstant_coefficients(top: &Stratum) -> Result<(Poly, Vec<Poly>), String> {
    let dc = top.den.coeffs_in(OMEGA);
    let lead = dc
        .last()
        .filter(|c| !c.is_zero())
        .ok_or("the denominator is zero")?
        .clone();
    let coefficients = top
        .num
        .coeffs_in(OMEGA)
        .into_iter()
        .chain(dc)
        .filter(|c| !c.is_zero() && !proportional(c, &lead))
        .collect();
    Ok((lead, coefficients))
}

/// How many invariants the reduced TF has ([`nonconstant_coefficients`]).
fn nonconstant_invariants(top: &Stratum) -> Result<usize, String> {
    Ok(nonconstant_coefficients(top)?.1.len())
}

/// The rows of the Jacobian of the non-constant invariants `c / lead`
/// (see [`nonconstant_invariants`]) with respect to `params`, each times
/// `lead^2` so that they are polynomials: `lead dc/dp - c dlead/dp`.
fn invariant_jacobian(top: &Stratum, params: &[String]) -> Result<Vec<Vec<Poly>>, String> {
    let (lead, coefficients) = nonconstant_coefficients(top)?;
    Ok(coefficients
        .iter()
        .map(|c| {
            params
                .iter()
                .map(|p| &(&lead * &c.derivative(p)) - &(c * &lead.derivative(p)))
                .collect()
        })
        .collect())
}

/// A point of the positive orthant for sampling ranks: small distinct
/// integers, shifted by `shift`.
fn rank_point(params: &[String], shift: usize) -> BTreeMap<String, Rat> {
    params
        .iter()
        .enumerate()
        .map(|(j, p)| (p.clone(), Rat::from(((5 * j + 3 * shift) % 17 + 2) as i64)))
        .collect()
}

/// `determinable_parameters`, the generic rank of the Jacobian of the
/// non-constant invariants with respect to the undamped parameters. Upper
/// bound: the number of invariants, and the number of parameters less the
/// listed `unidentifiable_directions` (each a polynomial vector field that
/// the Jacobian maps to zero, multiplied out here; independent, checked at
/// a point). Lower bound: the rank at a point (a non-vanishing minor there
/// is a non-zero polynomial), at up to four points. The two must meet,
/// unless the file claims a range: `determinable_parameters_at_most`, at
/// or above the upper bound shown here.
fn check_determinable(
    m: &Value,
    path: &str,
    top: &Stratum,
    params: &[String],
) -> Result<(), String> {
    let claimed = uint_field(m, "determinable_parameters", path)? as usize;
    let jac = invariant_jacobian(top, params)?;
    let mut directions: Vec<Vec<Poly>> = Vec::new();
    if m.get("unidentifiable_directions").is_some() {
        for (i, d) in arr_field(m, "unidentifiable_directions", path)?
            .iter()
            .enumerate()
        {
            let dpath = format!("unidentifiable_directions[{i}]");
            let obj = d
                .as_object()
                .ok_or_else(|| format!("{dpath}: expected an object of parameter: polynomial"))?;
            let mut v = vec![Poly::zero(); params.len()];
            for (name, c) in obj {
                let j = params
                    .iter()
                    .position(|p| p == name)
                    .ok_or_else(|| format!("{dpath}: {name} is not a parameter of the model"))?;
                v[j] = poly_value(c, &format!("{dpath}.{name}"))?;
            }
            for (r, row) in jac.iter().enumerate() {
                let image = row
                    .iter()
                    .zip(&v)
                    .fold(Poly::zero(), |acc, (a, b)| &acc + &(a * b));
                if !image.is_zero() {
                    return Err(format!(
                        "{dpath}: invariant {r} changes along it (the Jacobian maps it to {image})"
                    ));
                }
            }
            directions.push(v);
        }
    }
    if !directions.is_empty() {
        let at = rank_point(params, 0);
        let values: Result<Vec<Vec<Rat>>, _> = directions
            .iter()
            .map(|v| v.iter().map(|c| c.eval(&at)).collect())
            .collect();
        let values = values.map_err(|e| format!("unidentifiable_directions: {e}"))?;
        if poly::rank(values) < directions.len() {
            return Err(format!(
                "unidentifiable_directions: the {} directions are not independent at {}",
                directions.len(),
                point_text(&at)
            ));
        }
    }
    let upper = jac
        .len()
        .min(params.len() - directions.len().min(params.len()));
    if claimed > upper {
        return Err(format!(
            "determinable_parameters: the file says {claimed}, more than {upper} ({} invariants, \
             {} parameters, {} unidentifiable directions)",
            jac.len(),
            params.len(),
            directions.len()
        ));
    }
    let mut best = 0;
    for shift in 0..4 {
        let at = rank_point(params, shift);
        let values: Result<Vec<Vec<Rat>>, _> = jac
            .iter()
            .map(|row| row.iter().map(|x| x.eval(&at)).collect())
            .collect();
        best = best.max(poly::rank(
            values.map_err(|e| format!("determinable_parameters: {e}"))?,
        ));
        if best >= claimed {
            break;
        }
    }
    if best < claimed {
        return Err(format!(
            "determinable_parameters: the file says {claimed}, the Jacobian's rank at four \
             points is at most {best}"
        ));
    }
    // A sampled rank is claimed as a range: the lower bound just checked,
    // and an upper bound the checker must reach on its own.
    let at_most = match m.get("determinable_parameters_at_most") {
        Some(_) => Some(uint_field(m, "determinable_parameters_at_most", path)? as usize),
        None => None,
    };
    match at_most {
        Some(most) if most <= claimed => Err(format!(
            "determinable_parameters_at_most: the file says {most}, not above \
             determinable_parameters ({claimed}): an exact rank is claimed without it"
        )),
        Some(most) if most < upper => Err(format!(
            "determinable_parameters_at_most: the file says {most} and proves no bound below \
             {upper}: list the unidentifiable directions"
        )),
        Some(_) => Ok(()),
        None if claimed < upper => Err(format!(
            "determinable_parameters: the file says {claimed} and proves no bound below {upper}: \
             list the unidentifiable directions, or claim a range with \
             determinable_parameters_at_most"
        )),
        None => Ok(()),
    }
}

fn point_text(at: &BTreeMap<String, Rat>) -> String {
    let parts: Vec<String> = at.iter().map(|(k, v)| format!("{k} = {v}")).collect();
    parts.join(", ")
}

/// Every pole-zero cancellation the file lists (`pzc`): its condition is
/// the wall of its substitution, the transfer function there equals the
/// listed reduced one up to a factor free of `Omega`, and a pole really
/// cancels
/// (the listed denominator has a lower degree in `Omega` than the reduced
/// transfer function's off the wall).
fn check_pzc(
    m: &Value,
    path: &str,
    (num, den): (&Poly, &Poly),
    top: &Stratum,
) -> Result<(), String> {
    let r = top.den_degree;
    for (i, e) in arr_field(m, "pzc", path)?.iter().enumerate() {
        let epath = format!("pzc[{i}]");
        let sub = Sub::parse(
            field(e, "substitution", &epath)?,
            &format!("{epath}.substitution"),
        )?;
        let condition = poly_field(e, "condition", &epath)?;
        if !proportional(&condition, &sub.wall_poly()) {
            return Err(format!(
                "{epath}: condition {condition} is not the wall {} of {sub}",
                sub.wall_poly()
            ));
        }
        let (n_l, d_l) = (poly_field(e, "num", &epath)?, poly_field(e, "den", &epath)?);
        if d_l.is_zero() {
            return Err(format!("{epath}.den: zero"));
        }
        // num / den at var = beta/alpha is apply(num) alpha^dd / (apply(den)
        // alpha^dn): cross-multiplied with the listed quotient, which may
        // differ from it by a factor free of Omega (the reduction divides
        // out parameters too), which changes no root in Omega.
        let (dn, dd) = (num.degree(&sub.var), den.degree(&sub.var));
        let lhs = &(&n_l * &sub.apply(den)) * &sub.alpha.pow(dn);
        let rhs = &(&d_l * &sub.apply(num)) * &sub.alpha.pow(dd);
        let g = gcd(&lhs, &rhs);
        let free_of_omega = |p: &Poly| p.div_exact(&g).is_some_and(|q| q.degree(OMEGA) == 0);
        if lhs.is_zero() || rhs.is_zero() || !free_of_omega(&lhs) || !free_of_omega(&rhs) {
            return Err(format!(
                "{epath}: ({n_l})/({d_l}) is not the transfer function on {sub}"
            ));
        }
        if d_l.degree(OMEGA) >= r {
            return Err(format!(
                "{epath}: no pole cancels on {sub}: the denominator keeps degree {} in Omega",
                d_l.degree(OMEGA)
            ));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// FRF types

/// Every FRF type a transfer function with a numerator of degree `a` and
/// a denominator of degree `r` in `Omega` can show before anything is
/// known of its parameters: `k` of its poles cancelled by zeros, the other
/// `r - k` poles in runs of coincident ones, any number of the other
/// `a - k` zeros positive (in runs) and the rest off the positive axis
/// (`(nm)`), runs of zeros and poles in any order. Written here from that
/// definition, apart from the prover's enumeration.
fn a_priori_types(a: u32, r: u32) -> Vec<Ty> {
    fn runs(poles: u32, zeros: u32, seq: &mut Vec<Tok>, nm: bool, out: &mut Vec<Ty>) {
        if poles == 0 && zeros == 0 {
            let t = Ty {
                toks: seq.clone(),
                nm,
            };
            if !out.contains(&t) {
                out.push(t);
            }
            return;
        }
        for mult in 1..=poles {
            seq.push(Tok { zero: false, mult });
            runs(poles - mult, zeros, seq, nm, out);
            seq.pop();
        }
        for mult in 1..=zeros {
            seq.push(Tok { zero: true, mult });
            runs(poles, zeros - mult, seq, nm, out);
            seq.pop();
        }
    }
    let mut out = Vec::new();
    for k in 0..=a.min(r) {
        for positive in 0..=a - k {
            runs(r - k, positive, &mut Vec::new(), positive < a - k, &mut out);
        }
    }
    out
}

/// Every type the generic type `g` (simple tokens, `a` zeros in all)
/// turns into as its roots gather, written forwards: its tokens cut into
/// consecutive runs, pairs of its zeros off the axis landing on runs or
/// alone between them (one point per landing), and each point read as
/// `A^(z-p)`, `R^(p-z)` or nothing. Apart from the prover's recursion,
/// which matches `g` against one wanted type.
fn limit_images(g: &Ty, a: u32) -> Vec<Ty> {
    let zeros = g.toks.iter().filter(|k| k.zero).count() as u32;
    let off = a.saturating_sub(zeros);
    let n = g.toks.len();
    let mut out: Vec<Ty> = Vec::new();
    for cuts in 0u32..(1 << n.saturating_sub(1)) {
        let mut groups: Vec<(u32, u32)> = Vec::new();
        let mut cur = (0, 0);
        for (i, k) in g.toks.iter().enumerate() {
            if k.zero {
                cur.0 += 1;
            } else {
                cur.1 += 1;
            }
            if i + 1 == n || cuts & (1 << i) != 0 {
                groups.push(cur);
                cur = (0, 0);
            }
        }
        // Slot 2j: between runs j - 1 and j (a list of landing points);
        // slot 2j + 1: on run j.
        let slots = 2 * groups.len() + 1;
        let mut stack: Vec<(usize, u32, Vec<Tok>)> = vec![(0, off / 2, Vec::new())];
        while let Some((slot, left, toks)) = stack.pop() {
            if slot == slots {
                let ty = Ty {
                    toks,
                    nm: off - 2 * (off / 2 - left) > 0,
                };
                if !out.contains(&ty) {
                    out.push(ty);
                }
                continue;
            }
            if slot % 2 == 0 {
                // Close the gap, or land `e` more pairs at one more point
                // in it and stay.
                stack.push((slot + 1, left, toks.clone()));
                for e in 1..=left {
                    let mut t = toks.clone();
                    t.push(Tok {
                        zero: true,
                        mult: 2 * e,
                    });
                    stack.push((slot, left - e, t));
                }
            } else {
                let (z, p) = groups[slot / 2];
                for e in 0..=left {
                    let mut t = toks.clone();
                    let z = z + 2 * e;
                    if z != p {
                        t.push(Tok {
                            zero: z > p,
                            mult: z.abs_diff(p),
                        });
                    }
                    stack.push((slot + 1, left - e, t));
                }
            }
        }
    }
    out
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Tok {
    /// Antiresonance (a zero of the numerator); else a resonance.
    zero: bool,
    mult: u32,
}

#[derive(Clone, Debug, PartialEq, Eq)]
struct Ty {
    toks: Vec<Tok>,
    nm: bool,
}

impl Ty {
    fn parse(s: &str) -> Result<Ty, String> {
        let bad = || format!("not an FRF type: {s:?}");
        let (body, nm) = match s.strip_suffix(" (nm)") {
            Some(b) => (b, true),
            None => (s, false),
        };
        if body == "C" {
            return Ok(Ty {
                toks: Vec::new(),
                nm,
            });
        }
        if body.is_empty() {
            return Err(bad());
        }
        let b = body.as_bytes();
        let mut toks = Vec::new();
        let mut i = 0;
        while i < b.len() {
            let zero = match b[i] {
                b'A' => true,
                b'R' => false,
                _ => return Err(bad()),
            };
            i += 1;
            let mut mult = 1;
            if i < b.len() && b[i] == b'^' {
                i += 1;
                let start = i;
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
                mult = body[start..i].parse::<u32>().map_err(|_| bad())?;
                if mult < 2 {
                    return Err(bad());
                }
            }
            toks.push(Tok { zero, mult });
        }
        Ok(Ty { toks, nm })
    }

    fn resonances(&self) -> u32 {
        self.toks.iter().filter(|t| !t.zero).map(|t| t.mult).sum()
    }

    /// `(AR)^k`: simple, alternating, from an antiresonance to a resonance.
    fn rigid_body_interlacing(&self) -> bool {
        !self.nm
            && self.toks.iter().all(|t| t.mult == 1)
            && self.toks.windows(2).all(|w| w[0].zero != w[1].zero)
            && self.toks.len().is_multiple_of(2)
            && self.toks.first().is_none_or(|t| t.zero)
    }

    fn multiple_resonance(&self) -> bool {
        self.toks.iter().any(|t| !t.zero && t.mult > 1)
    }
}

impl fmt::Display for Ty {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.toks.is_empty() {
            f.write_str("C")?;
        }
        for t in &self.toks {
            f.write_str(if t.zero { "A" } else { "R" })?;
            if t.mult > 1 {
                write!(f, "^{}", t.mult)?;
            }
        }
        if self.nm {
            f.write_str(" (nm)")?;
        }
        Ok(())
    }
}

/// The type of `num/den` at a full parameter point: substitute, cancel the
/// common factor, isolate the real roots exactly.
fn classify(num: &Poly, den: &Poly, point: &BTreeMap<String, Rat>) -> Result<Ty, String> {
    let at = |p: &Poly, what: &str| -> Result<UPoly, String> {
        let mut q = p.clone();
        for (name, value) in point {
            q = q.subs(name, value);
        }
        match UPoly::from_poly(&q, OMEGA) {
            Some((_, u)) if !u.is_zero() => Ok(u),
            Some(_) => Err(format!("the {what} vanishes identically at the point")),
            None => Err(format!("the {what} still depends on {:?}", q.vars())),
        }
    };
    let n = at(num, "numerator")?;
    let d = at(den, "denominator")?;
    let g = n.gcd(&d);
    let n = n
        .div_exact(&g)
        .ok_or("the gcd does not divide the numerator")?;
    let d = d
        .div_exact(&g)
        .ok_or("the gcd does not divide the denominator")?;
    read_type(&interleave_roots(&[n.clone(), d]), n.degree().unwrap_or(0))
}

/// The type of a reduced TF from its numerator's and denominator's
/// interleaved roots, `zeros` the numerator's degree.
fn read_type(roots: &[poly::SharedRoot], zeros: usize) -> Result<Ty, String> {
    let mut toks = Vec::new();
    let mut positive_zeros = 0u32;
    for r in roots {
        if !r.is_positive() {
            continue;
        }
        let (mn, md) = (r.multiplicities[0], r.multiplicities[1]);
        match (mn > 0, md > 0) {
            (true, false) => {
                positive_zeros += mn;
                toks.push(Tok {
                    zero: true,
                    mult: mn,
                });
            }
            (false, true) => toks.push(Tok {
                zero: false,
                mult: md,
            }),
            _ => return Err("a root shared by the reduced numerator and denominator".into()),
        }
    }
    let nm = zeros as u64 > positive_zeros as u64;
    Ok(Ty { toks, nm })
}

/// The type at a point over a real number field whose transfer function
/// has the claimed cancelled poles and multiple zeros: each divided out
/// exactly, then the rests' positive roots isolated together by Descartes'
/// rule over the field, every one simple (so the rests share none), every
/// pole among them, and no multiple zero a root of the rests.
fn classify_posed(
    nf: &RealField,
    num: &Poly,
    den: &Poly,
    point: &BTreeMap<String, FieldElem>,
    cancelled: &[Rat],
    multiple: &[(Rat, u32)],
) -> Result<Ty, String> {
    let at = |p: &Poly, what: &str| -> Result<FieldPoly, String> {
        let u = nf
            .univariate(p, OMEGA, point)
            .map_err(|v| format!("the {what} still depends on {v}"))?;
        if u.is_zero() {
            return Err(format!("the {what} vanishes identically at the point"));
        }
        Ok(u)
    };
    let mut n = at(num, "numerator")?;
    let mut d = at(den, "denominator")?;
    let linear = |r: &Rat| FieldPoly::new(vec![nf.from_rat(&-r), nf.one()]);
    for r in cancelled {
        n = nf
            .poly_div_exact(&n, &linear(r))
            .ok_or_else(|| format!("the cancelled pole {r} is no root of the numerator"))?;
        d = nf
            .poly_div_exact(&d, &linear(r))
            .ok_or_else(|| format!("the cancelled pole {r} is no root of the denominator"))?;
    }
    for (r, k) in multiple {
        for _ in 0..*k {
            n = nf
                .poly_div_exact(&n, &linear(r))
                .ok_or_else(|| format!("{r} is no zero of multiplicity {k}"))?;
        }
    }
    // A cancelled pole may stay a pole of the rest (a double pole
    // cancelled once): its root is read below as a resonance, and were it
    // a zero of the rest as well, the product's root there is not simple.
    for (r, k) in multiple {
        if nf.sign_at(&n, r) == 0 {
            return Err(format!("the zero at {r} has a multiplicity above {k}"));
        }
        if nf.sign_at(&d, r) == 0 {
            return Err(format!("the zero at {r} is also a pole"));
        }
    }
    let product = nf.poly_mul(&n, &d);
    let roots = nf
        .positive_simple_roots(&product)
        .ok_or("the positive roots of the rest are not all simple")?;
    // (lower end, upper end, token); the multiple zeros are points.
    let mut found: Vec<(Rat, Rat, Tok)> = Vec::new();
    let mut rest_zeros = 0usize;
    for (lo, hi) in roots {
        let zero = if lo == hi {
            nf.sign_at(&n, &lo) == 0
        } else {
            nf.sign_at(&n, &lo) != nf.sign_at(&n, &hi)
        };
        rest_zeros += usize::from(zero);
        found.push((lo, hi, Tok { zero, mult: 1 }));
    }
    let poles = found.iter().filter(|f| !f.2.zero).count();
    if poles != d.degree().unwrap_or(0) {
        return Err("a pole of the reduced transfer function is not positive real".into());
    }
    for (r, k) in multiple {
        for f in found.iter_mut().filter(|f| &f.0 < r && r < &f.1) {
            let left = nf.sign_at(&product, &f.0) != nf.sign_at(&product, r);
            if left {
                f.1 = r.clone();
            } else {
                f.0 = r.clone();
            }
        }
        found.push((
            r.clone(),
            r.clone(),
            Tok {
                zero: true,
                mult: *k,
            },
        ));
    }
    found.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
    Ok(Ty {
        toks: found.into_iter().map(|f| f.2).collect(),
        nm: n.degree().unwrap_or(0) > rest_zeros,
    })
}

/// Cancelled poles, and multiple zeros with their multiplicities.
type PosedRoots = (Vec<Rat>, Vec<(Rat, u32)>);

/// The posed roots of a witness `v` (under `what`): its `cancelled` poles
/// and its `multiple` zeros as `[place, multiplicity]`, each optional.
fn posed_roots(v: &Value, what: &str) -> Result<PosedRoots, String> {
    let array = |key: &str| -> Result<&[Value], String> {
        match v.get(key) {
            None => Ok(&[]),
            Some(a) => a
                .as_array()
                .map(Vec::as_slice)
                .ok_or_else(|| format!("{what}.{key}: expected an array")),
        }
    };
    let cancelled = array("cancelled")?
        .iter()
        .enumerate()
        .map(|(i, r)| rat_value(r, &format!("{what}.cancelled[{i}]")))
        .collect::<Result<_, _>>()?;
    let multiple = array("multiple")?
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let path = format!("{what}.multiple[{i}]");
            let pair = e
                .as_array()
                .filter(|a| a.len() == 2)
                .ok_or_else(|| format!("{path}: expected [place, multiplicity]"))?;
            let k = pair[1]
                .as_u64()
                .filter(|k| (2..=64).contains(k))
                .ok_or_else(|| format!("{path}: a multiplicity from 2 to 64 expected"))?;
            Ok((rat_value(&pair[0], &path)?, k as u32))
        })
        .collect::<Result<_, String>>()?;
    Ok((cancelled, multiple))
}

/// The field and the point of an algebraic witness: `minimal` an
/// irreducible polynomial in `theta` with one root in `interval`, and a
/// polynomial in `theta` for exactly `params`, each positive at `theta`.
fn parse_algebraic_point(
    v: &Value,
    params: &[String],
) -> Result<(RealField, BTreeMap<String, FieldElem>), String> {
    const PATH: &str = "algebraic";
    let minimal = poly_field(v, "minimal", PATH)?;
    if minimal.vars().iter().any(|x| x != THETA) {
        return Err(format!(
            "{PATH}.minimal: a polynomial in {THETA} alone is expected"
        ));
    }
    let (_, minimal) = UPoly::from_poly(&minimal, THETA)
        .ok_or_else(|| format!("{PATH}.minimal: not a polynomial in {THETA}"))?;
    let ends = arr_field(v, "interval", PATH)?;
    let end = |i: usize| -> Result<Rat, String> {
        ends.get(i)
            .and_then(Value::as_str)
            .ok_or_else(|| format!("{PATH}.interval: expected two rationals as strings"))?
            .parse()
            .map_err(|e| format!("{PATH}.interval[{i}]: {e}"))
    };
    if ends.len() != 2 {
        return Err(format!(
            "{PATH}.interval: expected two rationals as strings"
        ));
    }
    let nf = RealField::new(minimal, end(0)?, end(1)?).map_err(|e| format!("{PATH}: {e}"))?;
    let obj = field(v, "parameters", PATH)?.as_object().ok_or_else(|| {
        format!("{PATH}.parameters: expected an object of polynomials in {THETA}")
    })?;
    let mut point = BTreeMap::new();
    for (k, x) in obj {
        if !params.contains(k) {
            return Err(format!(
                "{PATH}.parameters: {k} is not an undamped parameter of the model"
            ));
        }
        let p = poly_value(x, &format!("{PATH}.parameters.{k}"))?;
        let e = nf.element_of(&p, THETA).ok_or_else(|| {
            format!("{PATH}.parameters.{k}: a polynomial in {THETA} alone is expected")
        })?;
        if nf.sign(&e) <= 0 {
            return Err(format!(
                "{PATH}.parameters: {k} = {p} is not positive at {THETA}"
            ));
        }
        point.insert(k.clone(), e);
    }
    for p in params {
        if !point.contains_key(p) {
            return Err(format!("{PATH}.parameters: no value for {p}"));
        }
    }
    Ok((nf, point))
}

/// A point assigning a positive rational to exactly `params`.
fn parse_point(v: &Value, params: &[String], path: &str) -> Result<BTreeMap<String, Rat>, String> {
    let obj = v
        .as_object()
        .ok_or_else(|| format!("{path}: expected an object of parameter values"))?;
    let mut point = BTreeMap::new();
    for (k, x) in obj {
        if !params.contains(k) {
            return Err(format!(
                "{path}: {k} is not an undamped parameter of the model"
            ));
        }
        let r: Rat = match x {
            Value::String(s) => s
                .parse()
                .map_err(|e| format!("{path}.{k}: not a rational ({e}): {s:?}"))?,
            Value::Number(n) => Rat::from(
                n.as_i64()
                    .ok_or_else(|| format!("{path}.{k}: not an integer or a rational string"))?,
            ),
            _ => return Err(format!("{path}.{k}: expected a rational")),
        };
        if r.signum() <= 0 {
            return Err(format!("{path}: {k} = {r} is not positive"));
        }
        point.insert(k.clone(), r);
    }
    for p in params {
        if !point.contains_key(p) {
            return Err(format!("{path}: no value for {p}"));
        }
    }
    Ok(point)
}

// ---------------------------------------------------------------------------
// Strata

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    /// Leading coefficient or value at `Omega = 0` of a part.
    Boundary,
    /// Resultant of a numerator part and a denominator part.
    Cancel,
    /// Discriminant-like or same-side resultant.
    Other,
}

#[derive(Clone, Debug)]
struct Critical {
    poly: Poly,
    role: Role,
    what: String,
}

#[derive(Clone, Debug)]
struct Part {
    poly: Poly,
    mult: u32,
    num: bool,
}

#[derive(Debug)]
struct Stratum {
    subs: Vec<Sub>,
    vars: Vec<String>,
    /// The transfer function on the stratum, its common factor divided out.
    num: Poly,
    den: Poly,
    den_degree: u32,
    parts: Vec<Part>,
    critical: Vec<Critical>,
}

impl Stratum {
    fn build(num0: &Poly, den0: &Poly, params: &[String], subs: &[Sub]) -> Result<Stratum, String> {
        let mut eliminated: BTreeSet<&str> = BTreeSet::new();
        let (mut num, mut den) = (num0.clone(), den0.clone());
        for s in subs {
            if !params.contains(&s.var) {
                return Err(format!("substitution {s}: {} is not a parameter", s.var));
            }
            if !eliminated.insert(s.var.as_str()) {
                return Err(format!("substitution {s}: {} is eliminated twice", s.var));
            }
            for (name, p) in [("alpha", &s.alpha), ("beta", &s.beta)] {
                if !p.all_coefs_positive() {
                    return Err(format!(
                        "substitution {s}: {name} = {p} does not have all coefficients positive"
                    ));
                }
                if let Some(v) = p
                    .vars()
                    .iter()
                    .find(|v| !params.contains(v) || eliminated.contains(v.as_str()))
                {
                    return Err(format!(
                        "substitution {s}: {name} involves {v}, which is not a remaining parameter"
                    ));
                }
            }
            num = s.apply(&num);
            den = s.apply(&den);
        }
        if num.is_zero() || den.is_zero() {
            return Err("the numerator or denominator vanishes on the stratum".into());
        }
        let g = gcd(&num, &den);
        if !g.is_constant() {
            num = num
                .div_exact(&g)
                .ok_or("the gcd does not divide the numerator")?;
            den = den
                .div_exact(&g)
                .ok_or("the gcd does not divide the denominator")?;
        }
        let vars: Vec<String> = params
            .iter()
            .filter(|p| !eliminated.contains(p.as_str()))
            .cloned()
            .collect();
        let mut parts = Vec::new();
        for (p, is_num) in [(&num, true), (&den, false)] {
            let (unit, factors) = square_free(p);
            // The decomposition must multiply back to `p`.
            let back = factors
                .iter()
                .fold(Poly::constant(unit), |acc, (f, k)| &acc * &f.pow(*k));
            if &back != p {
                return Err(format!(
                    "the square-free decomposition of {p} does not multiply back"
                ));
            }
            for (f, mult) in factors {
                if f.degree(OMEGA) >= 1 {
                    parts.push(Part {
                        poly: f,
                        mult,
                        num: is_num,
                    });
                }
            }
        }
        let side = |p: &Part| if p.num { "numerator" } else { "denominator" };
        let mut critical = Vec::new();
        for p in &parts {
            let c = p.poly.coeffs_in(OMEGA);
            critical.push(Critical {
                poly: c.last().cloned().unwrap_or_else(Poly::zero),
                role: Role::Boundary,
                what: format!("the leading coefficient of {} part {}", side(p), p.poly),
            });
            critical.push(Critical {
                poly: c[0].clone(),
                role: Role::Boundary,
                what: format!("the value at Omega = 0 of {} part {}", side(p), p.poly),
            });
            if p.poly.degree(OMEGA) >= 2 {
                critical.push(Critical {
                    poly: sylvester_resultant(&p.poly, &p.poly.derivative(OMEGA)),
                    role: Role::Other,
                    what: format!("Res(p, dp/dOmega) of {} part {}", side(p), p.poly),
                });
            }
        }
        for i in 0..parts.len() {
            for j in i + 1..parts.len() {
                let (a, b) = (&parts[i], &parts[j]);
                critical.push(Critical {
                    poly: sylvester_resultant(&a.poly, &b.poly),
                    role: if a.num != b.num {
                        Role::Cancel
                    } else {
                        Role::Other
                    },
                    what: format!("the resultant of parts {} and {}", a.poly, b.poly),
                });
            }
        }
        Ok(Stratum {
            subs: subs.to_vec(),
            vars,
            den_degree: den.degree(OMEGA),
            num,
            den,
            parts,
            critical,
        })
    }

    fn linear_parts(&self) -> Vec<&Part> {
        // Numerator parts come first in `parts`, each side in square-free order.
        self.parts
            .iter()
            .filter(|p| p.poly.degree(OMEGA) == 1)
            .collect()
    }

    /// The part of degree >= 2 proportional to `other`, unique for its side
    /// and multiplicity.
    fn unique_nonlinear(&self, other: &Poly) -> Result<&Part, String> {
        let part = self
            .parts
            .iter()
            .find(|p| p.poly.degree(OMEGA) >= 2 && proportional(&p.poly, other))
            .ok_or_else(|| format!("{other} is not a part of degree >= 2 of the stratum"))?;
        let same = self
            .parts
            .iter()
            .filter(|p| p.poly.degree(OMEGA) >= 2 && p.num == part.num && p.mult == part.mult)
            .count();
        if same != 1 {
            return Err(format!(
                "{other} is not the only part of degree >= 2 of its side and multiplicity"
            ));
        }
        Ok(part)
    }
}

// ---------------------------------------------------------------------------
// The checker of one model

/// A factor of a certificate's list, with its roles on the stratum.
struct Entry<'a> {
    poly: Poly,
    kind: &'a str,
    v: &'a Value,
    path: String,
    cancels: bool,
    boundary: bool,
}

struct ModelChecker {
    params: Vec<String>,
    collocated: bool,
    /// Why the pencil is not block-unreduced-tridiagonal, if it is not.
    jacobi: Result<(), String>,
    /// The model's mass and stiffness matrices.
    mass: Vec<Vec<Poly>>,
    stiff: Vec<Vec<Poly>>,
    /// Actuator and sensor vectors.
    input: Vec<i64>,
    output: Vec<i64>,
    num: Poly,
    den: Poly,
    strata: HashMap<String, Rc<Stratum>>,
    definite_ok: HashSet<String>,
    /// Per stratum and factor, whether it divides a resultant of the parts
    /// and a boundary polynomial; per stratum and list of factors, what
    /// they leave of the critical polynomials, and the lists whose
    /// leftovers were shown coprime to the parts' resultants and the
    /// boundary. All are functions of the stratum and the polynomials
    /// alone, and the certificates of a model repeat them hundreds of
    /// times (one stratum and one list in 401 proofs of N6-g5-a6.1-s6.5).
    roles: HashMap<String, (bool, bool)>,
    coverage: HashMap<String, Result<Leftovers, String>>,
    coprime_ok: HashSet<String>,
    proofs: usize,
}

/// What the listed factors of a proof leave of the critical polynomials
/// they do not cover, each with what the polynomial is.
type Leftovers = Rc<Vec<(String, Poly)>>;

fn check_model_at(m: &Value, path: &str, complete: bool) -> Result<CheckReport, CheckError> {
    let id = m
        .get("id")
        .and_then(Value::as_str)
        .ok_or_else(|| CheckError::Malformed {
            path: path.to_string(),
            problem: "missing key \"id\" (a string)".into(),
        })?
        .to_string();
    let model_err = |step: String| CheckError::Model {
        model: id.clone(),
        step,
    };
    let model = read_model(m, path).map_err(model_err)?;
    let num = poly_field(m, "numerator", path).map_err(model_err)?;
    let den = poly_field(m, "denominator", path).map_err(model_err)?;
    verify_tf(&model, &num, &den).map_err(model_err)?;
    let mut checker = ModelChecker {
        params: model.undamped_parameters(),
        collocated: model.actuator() == model.sensor(),
        jacobi: unreduced_blocks(&model),
        mass: model.mass_matrix(),
        stiff: model.stiffness_matrix(),
        input: model.input_vector(),
        output: model.output_vector(),
        num,
        den,
        strata: HashMap::new(),
        definite_ok: HashSet::new(),
        roles: HashMap::new(),
        coverage: HashMap::new(),
        coprime_ok: HashSet::new(),
        proofs: 0,
    };
    let mut report = CheckReport {
        models: 1,
        ..CheckReport::default()
    };
    let types = arr_field(m, "types", path).map_err(model_err)?;
    // Every verdict, for the certificates that rest on other types' (each
    // of those is checked in its own turn below).
    let mut verdicts: Vec<(Ty, &str)> = Vec::with_capacity(types.len());
    for (j, verdict) in types.iter().enumerate() {
        let vpath = format!("types[{j}]");
        let name = str_field(verdict, "type", &vpath).map_err(model_err)?;
        let t = Ty::parse(name).map_err(|e| model_err(format!("{vpath}: {e}")))?;
        let status = str_field(verdict, "status", &vpath).map_err(model_err)?;
        verdicts.push((t, status));
    }
    for (j, verdict) in types.iter().enumerate() {
        let vpath = format!("types[{j}]");
        let name = str_field(verdict, "type", &vpath).map_err(model_err)?;
        let type_err = |step: String| CheckError::Type {
            model: id.clone(),
            frf_type: name.to_string(),
            step,
        };
        let t = Ty::parse(name).map_err(type_err)?;
        match str_field(verdict, "status", &vpath).map_err(type_err)? {
            "possible" => {
                match (
                    verdict.get("path"),
                    verdict.get("algebraic"),
                    verdict.get("isolated"),
                ) {
                    (Some(p), _, _) => checker.check_path(p, &t).map_err(type_err)?,
                    (None, Some(a), _) => checker.check_algebraic(a, &t).map_err(type_err)?,
                    (None, None, Some(b)) => checker.check_isolated(b, &t).map_err(type_err)?,
                    (None, None, None) => {
                        let w = field(verdict, "witness", &vpath).map_err(type_err)?;
                        checker.check_witness(w, &t).map_err(type_err)?;
                    }
                }
                report.witnesses += 1;
            }
            "impossible" => {
                let c = field(verdict, "certificate", &vpath).map_err(type_err)?;
                let limits = c
                    .get("open")
                    .and_then(|o| o.get("kind"))
                    .and_then(Value::as_str)
                    == Some("limits");
                if limits {
                    checker
                        .check_limits(c, &t, &verdicts)
                        .map_err(|e| type_err(format!("limits: {e}")))?;
                } else {
                    checker
                        .check_proof(c, &[], &t, "certificate", "")
                        .map_err(type_err)?;
                }
                report.certificates += 1;
            }
            "unknown" => report.unknown += 1,
            other => {
                return Err(type_err(format!(
                    "{vpath}.status: unknown status {other:?}"
                )))
            }
        }
    }
    // The reduced TF (the whole orthant's stratum) for the derived fields.
    let top = checker.stratum(&[]).map_err(model_err)?;
    if m.get("pzc").is_some() {
        check_pzc(m, path, (&checker.num, &checker.den), &top).map_err(model_err)?;
    }
    if let Some(v) = m.get("moment_invariants") {
        let listed = v
            .as_u64()
            .ok_or_else(|| model_err(format!("{path}.moment_invariants: expected a count")))?;
        let own = nonconstant_invariants(&top).map_err(model_err)?;
        if listed != own as u64 {
            return Err(model_err(format!(
                "moment_invariants: the file says {listed}, the reduced TF has {own}"
            )));
        }
    }
    if m.get("critical").is_some() {
        report.undetermined_factors +=
            check_critical(m, path, &top, &mut checker).map_err(model_err)?;
    }
    if m.get("determinable_parameters").is_some() {
        check_determinable(m, path, &top, &checker.params).map_err(model_err)?;
    }
    if complete {
        // Every type a TF of these degrees can show a priori must have its
        // verdict here, once: a table with a verdict cut out claims less.
        let mut listed: Vec<Ty> = Vec::with_capacity(types.len());
        for (j, verdict) in types.iter().enumerate() {
            let vpath = format!("types[{j}]");
            let name = str_field(verdict, "type", &vpath).map_err(model_err)?;
            let t = Ty::parse(name).map_err(|e| model_err(format!("{vpath}: {e}")))?;
            if listed.contains(&t) {
                return Err(model_err(format!("{vpath}: type {t} appears twice")));
            }
            listed.push(t);
        }
        let (a, r) = (top.num.degree(OMEGA), top.den_degree);
        if let Some(t) = a_priori_types(a, r)
            .into_iter()
            .find(|t| !listed.contains(t))
        {
            return Err(model_err(format!(
                "type {t} has no verdict: every type of a numerator of degree {a} and a \
                 denominator of degree {r} in Omega must have one"
            )));
        }
    }
    report.proofs = checker.proofs;
    Ok(report)
}

fn read_model(m: &Value, path: &str) -> Result<Model, String> {
    let n = uint_field(m, "masses", path)?;
    let gap = uint_field(m, "gap", path)?;
    let port = |key: &str| -> Result<Port, String> {
        let a = arr_field(m, key, path)?;
        let pair: Vec<u64> = a.iter().filter_map(Value::as_u64).collect();
        if a.len() != 2 || pair.len() != 2 {
            return Err(format!("{path}.{key}: expected [plus, minus]"));
        }
        Ok(Port::new(index(pair[0]), index(pair[1])))
    };
    let model = Model::new(index(n), index(gap), port("actuator")?, port("sensor")?)
        .map_err(|e| format!("not a valid model: {e}"))?;
    let generic = str_field(m, "generic_id", path)?;
    if generic != model.id() {
        return Err(format!(
            "generic_id {generic} does not match the structure {}",
            model.id()
        ));
    }
    Ok(model)
}

/// The premise of `simple_resonances`: `M` diagonal with entries positive
/// on the orthant (no subtraction), `K` symmetric tridiagonal with every
/// off-diagonal entry zero (a gap: a new block starts) or negative on the
/// orthant. Then `M^(-1/2) K M^(-1/2)` is block diagonal with unreduced
/// symmetric tridiagonal blocks, whose eigenvalues are simple; the TF is a
/// sum of one term per block, so its reduced poles are simple.
fn unreduced_blocks(model: &Model) -> Result<(), String> {
    let mass = model.mass_matrix();
    let stiff = model.stiffness_matrix();
    let n = mass.len();
    for i in 0..n {
        for j in 0..n {
            let (m, k) = (&mass[i][j], &stiff[i][j]);
            if i == j {
                if !m.all_coefs_positive() {
                    return Err(format!("M[{i}][{i}] = {m} is not positive"));
                }
                continue;
            }
            if !m.is_zero() {
                return Err(format!("M[{i}][{j}] = {m} is not zero"));
            }
            if *k != stiff[j][i] {
                return Err(format!("K is not symmetric at [{i}][{j}]"));
            }
            let far = i.abs_diff(j) > 1;
            if (far && !k.is_zero()) || (!far && !k.is_zero() && !k.all_coefs_negative()) {
                return Err(format!(
                    "K[{i}][{j}] = {k} breaks the tridiagonal chain form"
                ));
            }
        }
    }
    Ok(())
}

/// The file's `num/den` against `c^T adj(K - Omega*M) b` and
/// `det(K - Omega*M) / Omega`.
fn verify_tf(model: &Model, num: &Poly, den: &Poly) -> Result<(), String> {
    let om = Poly::var(OMEGA);
    let mass = model.mass_matrix();
    let stiff = model.stiffness_matrix();
    let pencil: Vec<Vec<Poly>> = stiff
        .iter()
        .zip(&mass)
        .map(|(kr, mr)| kr.iter().zip(mr).map(|(k, m)| k - &(&om * m)).collect())
        .collect();
    let d = det(&pencil);
    let den_check = d
        .div_exact(&om)
        .filter(|q| (q * &om) == d)
        .ok_or("det(K - Omega*M) has no factor Omega")?;
    let adj = adjugate(&pencil);
    let (c, b) = (model.output_vector(), model.input_vector());
    let mut num_check = Poly::zero();
    for (i, ci) in c.iter().enumerate() {
        for (j, bj) in b.iter().enumerate() {
            if *ci != 0 && *bj != 0 {
                num_check = &num_check + &adj[i][j].scale(&Rat::from(ci * bj));
            }
        }
    }
    if num_check.is_zero() || !proportional(num, &num_check) {
        return Err(format!(
            "transfer function: the numerator {num} is not a constant multiple of c^T adj(K - Omega*M) b = {num_check}"
        ));
    }
    if !proportional(den, &den_check) {
        return Err(format!(
            "transfer function: the denominator {den} is not a constant multiple of det(K - Omega*M)/Omega = {den_check}"
        ));
    }
    Ok(())
}

impl ModelChecker {
    /// A type certified as a limit of impossible generic types: the
    /// certificate's point makes the reduced numerator and denominator
    /// square-free and coprime, so the points with a multiple or shared
    /// root are nowhere dense; their leading and constant coefficients in
    /// `Omega` have one sign, so no root reaches 0 or infinity; and every
    /// generic type (simple tokens, every pole) that gathers into `t`
    /// ([`limit_images`], written forwards here) is listed and has the
    /// verdict "impossible", checked in its own turn. A generic type cannot
    /// carry such a certificate, so none rests on itself.
    fn check_limits(&mut self, c: &Value, t: &Ty, verdicts: &[(Ty, &str)]) -> Result<(), String> {
        if !arr_field(c, "stratum", "certificate")?.is_empty()
            || !arr_field(c, "factors", "certificate")?.is_empty()
            || c.get("unlisted").is_some()
        {
            return Err("a limit of generic types holds on the whole orthant alone: expected no stratum, factors or unlisted".into());
        }
        let open = field(c, "open", "certificate")?;
        let top = self.stratum(&[])?;
        let (num, den) = (top.num.clone(), top.den.clone());
        let (a, r) = (num.degree(OMEGA), top.den_degree);
        let generic = |x: &Ty| x.resonances() == r && x.toks.iter().all(|k| k.mult == 1);
        if generic(t) {
            return Err(format!("{t} is generic: it cannot be its own limit"));
        }
        let one_signed = |p: Poly| p.all_coefs_positive() || p.all_coefs_negative();
        for (what, p) in [("numerator", &num), ("denominator", &den)] {
            let lead = p.lead_in(OMEGA);
            let at_zero = p.subs(OMEGA, &Rat::ZERO);
            if !one_signed(lead.clone()) || !one_signed(at_zero.clone()) {
                return Err(format!(
                    "the {what}'s leading coefficient {lead} or value at Omega = 0, {at_zero}, is not of one sign"
                ));
            }
        }
        let point = parse_point(
            field(open, "point", "certificate.open")?,
            &self.params,
            "certificate.open.point",
        )?;
        let n = num.eval_except(OMEGA, &point)?;
        let d = den.eval_except(OMEGA, &point)?;
        for (what, p) in [("numerator", &n), ("denominator", &d)] {
            if !gcd(p, &p.derivative(OMEGA)).is_constant() {
                return Err(format!("at the point the {what} {p} has a multiple root"));
            }
        }
        if !gcd(&n, &d).is_constant() {
            return Err("at the point numerator and denominator share a root".into());
        }
        let mut listed: Vec<Ty> = Vec::new();
        for (i, g) in arr_field(open, "generic", "certificate.open")?
            .iter()
            .enumerate()
        {
            let name = g
                .as_str()
                .ok_or_else(|| format!("certificate.open.generic[{i}]: expected a type"))?;
            listed.push(Ty::parse(name)?);
        }
        let mut own: Vec<Ty> = Vec::new();
        for g in a_priori_types(a, r).into_iter().filter(|g| generic(g)) {
            if !limit_images(&g, a).contains(t) {
                continue;
            }
            match verdicts.iter().find(|(x, _)| *x == g) {
                Some((_, "impossible")) => {}
                Some((_, status)) => {
                    return Err(format!(
                        "the generic type {g} gathers into it and is {status}"
                    ))
                }
                None => {
                    return Err(format!(
                        "the generic type {g} gathers into it and has no verdict"
                    ))
                }
            }
            if !listed.contains(&g) {
                return Err(format!(
                    "the generic type {g} gathers into it and is not listed"
                ));
            }
            own.push(g);
        }
        if let Some(x) = listed.iter().find(|x| !own.contains(x)) {
            return Err(format!("{x} is listed but does not gather into it"));
        }
        self.proofs += 1;
        Ok(())
    }

    fn check_witness(&self, w: &Value, t: &Ty) -> Result<(), String> {
        let point = parse_point(w, &self.params, "witness")?;
        let got = classify(&self.num, &self.den, &point).map_err(|e| format!("witness: {e}"))?;
        if &got != t {
            return Err(format!("witness: the type there is {got}, not {t}"));
        }
        Ok(())
    }

    /// A point over a real number field: see the module docs, item 2.
    fn check_algebraic(&self, v: &Value, t: &Ty) -> Result<(), String> {
        let (nf, point) = parse_algebraic_point(v, &self.params)?;
        let (cancelled, multiple) = posed_roots(v, "algebraic")?;
        let got = classify_posed(&nf, &self.num, &self.den, &point, &cancelled, &multiple)
            .map_err(|e| format!("algebraic: {e}"))?;
        if &got != t {
            return Err(format!("algebraic: the type there is {got}, not {t}"));
        }
        Ok(())
    }

    /// A point isolated in a box: see the module docs, item 2.
    fn check_isolated(&self, v: &Value, t: &Ty) -> Result<(), String> {
        let got = isolated::read_isolated(&self.num, &self.den, &self.params, v)?;
        if &got != t {
            return Err(format!("isolated: the type there is {got}, not {t}"));
        }
        Ok(())
    }

    /// A double or triple zero shown by continuity: see the module docs,
    /// item 2.
    fn check_path(&self, v: &Value, t: &Ty) -> Result<(), String> {
        const S: &str = "s";
        let obj = v
            .get("parameters")
            .and_then(Value::as_object)
            .ok_or("path: expected an object of parameters")?;
        let names: Vec<&String> = obj.keys().collect();
        if names.len() != self.params.len() || names.iter().any(|n| !self.params.contains(n)) {
            return Err(format!(
                "path: the parameters are {names:?}, not {:?}",
                self.params
            ));
        }
        let mut path: BTreeMap<String, (Poly, Poly)> = BTreeMap::new();
        for (name, pq) in obj {
            let fail = || format!("path: {name}: expected [numerator, denominator] in s");
            let pair = pq.as_array().filter(|a| a.len() == 2).ok_or_else(fail)?;
            let p = poly_value(&pair[0], "path")?;
            let q = poly_value(&pair[1], "path")?;
            if p.vars().iter().chain(q.vars()).any(|x| x != S) {
                return Err(fail());
            }
            // Positive on [0, 1]: p q has no root there and is positive at 0.
            let pq = UPoly::from_poly(&(&p * &q), S).ok_or_else(fail)?;
            if pq.0.signum() * pq.1.sign_at(&Rat::ZERO) <= 0
                || count_roots_in(&pq.1, &Rat::ZERO, &Rat::ONE) > 0
            {
                return Err(format!("path: {name} is not positive on [0, 1]"));
            }
            path.insert(name.clone(), (p, q));
        }
        // The types at the ends.
        let mut ends: Vec<Ty> = Vec::new();
        for s in [Rat::ZERO, Rat::ONE] {
            let point: BTreeMap<String, Rat> = path
                .iter()
                .map(|(k, (p, q))| {
                    let at = |f: &Poly| f.subs(S, &s).as_constant().unwrap_or(Rat::ZERO);
                    (k.clone(), &at(p) / &at(q))
                })
                .collect();
            ends.push(
                classify(&self.num, &self.den, &point)
                    .map_err(|e| format!("path at s = {s}: {e}"))?,
            );
        }
        // The transfer function along the path, denominators cleared term
        // by term.
        let along = |f: &Poly| -> Poly {
            let degrees: Vec<u32> = f.vars().iter().map(|x| f.degree(x)).collect();
            let mut out = Poly::zero();
            for term in f.terms() {
                let mut m = Poly::constant(term.coef.clone());
                for ((x, &e), &d) in f.vars().iter().zip(&term.exps).zip(&degrees) {
                    match path.get(x) {
                        Some((p, q)) => m = &(&m * &p.pow(e)) * &q.pow(d - e),
                        None => m = &m * &Poly::var(x).pow(e),
                    }
                }
                out = &out + &m;
            }
            out
        };
        let rootless = |p: &Poly, what: &str| -> Result<(), String> {
            let ok = UPoly::from_poly(p, S).is_some_and(|(c, u)| {
                !c.is_zero()
                    && u.sign_at(&Rat::ZERO) != 0
                    && count_roots_in(&u, &Rat::ZERO, &Rat::ONE) == 0
            });
            if ok {
                Ok(())
            } else {
                Err(format!(
                    "path: the {what} has a root on [0, 1] (or is not a polynomial in s)"
                ))
            }
        };
        let (n, d) = (along(&self.num), along(&self.den));
        // Not zero anywhere on the path: the gcd's content in s cannot make
        // the transfer function vanish at some s.
        rootless(
            &d.lead_in(OMEGA),
            "denominator's leading coefficient before reduction",
        )?;
        let g = gcd(&n, &d);
        let reduce = |p: &Poly| -> Result<Poly, String> {
            let p = p.div_exact(&g).ok_or("path: the gcd does not divide")?;
            let mut p = p;
            while !p.is_zero() && p.subs(OMEGA, &Rat::ZERO).is_zero() {
                p = p
                    .div_exact(&Poly::var(OMEGA))
                    .ok_or("path: Omega does not divide")?;
            }
            Ok(p)
        };
        let (n, d) = (reduce(&n)?, reduce(&d)?);
        // A double zero kept along the path: n = h^2 m, h of degree one.
        let common = gcd(&n, &n.derivative(OMEGA));
        let (h, m) = match common.degree(OMEGA) {
            0 => (None, n),
            1 => {
                let h0 = common.subs(OMEGA, &Rat::ZERO);
                let h1 = common.lead_in(OMEGA);
                let h = common
                    .div_exact(&gcd(&h0, &h1))
                    .ok_or("path: the double zero's content does not divide")?;
                let m = n
                    .div_exact(&(&h * &h))
                    .ok_or("path: the double zero's square does not divide")?;
                (Some(h), m)
            }
            k => return Err(format!("path: {k} zeros stay multiple along the path")),
        };
        rootless(&m.lead_in(OMEGA), "numerator's leading coefficient")?;
        rootless(&d.lead_in(OMEGA), "denominator's leading coefficient")?;
        rootless(&m.subs(OMEGA, &Rat::ZERO), "numerator's value at 0")?;
        rootless(&d.subs(OMEGA, &Rat::ZERO), "denominator's value at 0")?;
        rootless(&sylvester_resultant(&m, &d), "resultant")?;
        if d.degree(OMEGA) >= 2 {
            rootless(&discriminant_of(&d)?, "denominator's discriminant")?;
        }
        if let Some(h) = &h {
            rootless(&h.lead_in(OMEGA), "double zero's leading coefficient")?;
            rootless(&h.subs(OMEGA, &Rat::ZERO), "double zero's value at 0")?;
            rootless(
                &sylvester_resultant(h, &d),
                "resultant of the double zero and the poles",
            )?;
        }
        // Roots in (0, 1), none at the ends.
        let inner = |p: &Poly, what: &str| -> Result<(usize, UPoly), String> {
            let u = UPoly::from_poly(p, S)
                .map(|(_, u)| u)
                .ok_or_else(|| format!("path: the {what} depends on more than s"))?;
            if u.is_zero() || u.sign_at(&Rat::ZERO) == 0 || u.sign_at(&Rat::ONE) == 0 {
                return Err(format!("path: the {what} vanishes at an end"));
            }
            Ok((count_roots_in(&u, &Rat::ZERO, &Rat::ONE), u))
        };
        let (pairs, disc) = if m.degree(OMEGA) >= 2 {
            let (k, u) = inner(&discriminant_of(&m)?, "numerator's discriminant")?;
            (k, Some(u))
        } else {
            (0, None)
        };
        let crossings = match &h {
            Some(h) => inner(&sylvester_resultant(h, &m), "resultant of the double zero")?.0,
            None => 0,
        };
        // Which two neighbouring zeros of the type at s = 0 meet, and the
        // type at the meeting.
        let [before, after] = [&ends[0], &ends[1]];
        let zero = |k: &Tok, mult: u32| k.zero && k.mult == mult;
        let mut merged: BTreeSet<String> = BTreeSet::new();
        for i in 0..before.toks.len().saturating_sub(1) {
            let (x, y) = (before.toks[i], before.toks[i + 1]);
            let mut moved = before.clone();
            let mult = if (pairs, crossings) == (1, 0) && zero(&x, 1) && zero(&y, 1) {
                moved.toks.drain(i..=i + 1);
                moved.nm = true;
                2
            } else if (pairs, crossings) == (0, 1)
                && ((zero(&x, 1) && zero(&y, 2)) || (zero(&x, 2) && zero(&y, 1)))
            {
                moved.toks.swap(i, i + 1);
                3
            } else {
                continue;
            };
            if &moved != after {
                continue;
            }
            let mut at = before.clone();
            at.toks.splice(i..=i + 1, [Tok { zero: true, mult }]);
            merged.insert(at.to_string());
        }
        match merged.len() {
            0 => {
                return Err(format!(
                    "path: from {before} at s = 0 to {after} at s = 1 with {pairs} meeting(s) of two zeros and {crossings} crossing(s) of the double zero, no one event gives a type"
                ))
            }
            1 if merged.contains(&t.to_string()) => {}
            _ => {
                return Err(format!(
                    "path: from {before} to {after} the event gives {}, not {t}",
                    merged.into_iter().collect::<Vec<_>>().join(" or ")
                ))
            }
        }
        if pairs == 1 && m.degree(OMEGA) >= 3 {
            let disc = disc.as_ref().ok_or("path: no discriminant")?;
            let p1 = psc(&m, &m.derivative(OMEGA), OMEGA)
                .get(1)
                .and_then(|p| UPoly::from_poly(p, S))
                .map(|(_, u)| u)
                .ok_or("path: no first principal subresultant coefficient")?;
            if p1.is_zero() || count_roots_in(&disc.gcd(&p1), &Rat::ZERO, &Rat::ONE) > 0 {
                return Err("path: more than two zeros meet".into());
            }
        }
        Ok(())
    }

    fn stratum(&mut self, subs: &[Sub]) -> Result<Rc<Stratum>, String> {
        let key = subs_key(subs);
        if let Some(s) = self.strata.get(&key) {
            return Ok(s.clone());
        }
        let s = Rc::new(Stratum::build(&self.num, &self.den, &self.params, subs)?);
        self.strata.insert(key, s.clone());
        Ok(s)
    }

    /// Checks the proof `p` that `t` does not occur on the stratum `expect`.
    /// `jp` is the JSON path of `p`, `ctx` the prefix naming the wall.
    fn check_proof(
        &mut self,
        p: &Value,
        expect: &[Sub],
        t: &Ty,
        jp: &str,
        ctx: &str,
    ) -> Result<(), String> {
        self.proofs += 1;
        let err = |e: String| format!("{ctx}{e}");
        let subs: Vec<Sub> = arr_field(p, "stratum", jp)
            .map_err(err)?
            .iter()
            .enumerate()
            .map(|(i, v)| Sub::parse(v, &format!("{jp}.stratum[{i}]")))
            .collect::<Result<_, _>>()
            .map_err(err)?;
        if subs != expect {
            return Err(err(format!(
                "the stratum is {}, expected {}",
                subs_text(&subs),
                subs_text(expect)
            )));
        }
        let s = self
            .stratum(&subs)
            .map_err(|e| err(format!("stratum: {e}")))?;
        let open = field(p, "open", jp).map_err(err)?;
        let open_jp = format!("{jp}.open");
        let kind = str_field(open, "kind", &open_jp).map_err(err)?;

        // The factors and their roles.
        let list = arr_field(p, "factors", jp).map_err(err)?;
        let mut entries = Vec::with_capacity(list.len());
        for (i, v) in list.iter().enumerate() {
            let path = format!("{jp}.factors[{i}]");
            let poly = poly_field(v, "factor", &path).map_err(err)?;
            let fkind = str_field(v, "kind", &path).map_err(err)?;
            if poly.is_constant() {
                return Err(err(format!("factor {i}: {poly} is constant")));
            }
            if let Some(x) = poly.vars().iter().find(|x| !s.vars.contains(x)) {
                return Err(err(format!(
                    "factor {i}: {poly} involves {x}, which is not a parameter of the stratum"
                )));
            }
            let divides = |role: Role| {
                s.critical
                    .iter()
                    .filter(|c| c.role == role)
                    .any(|c| !c.poly.is_zero() && c.poly.div_exact(&poly).is_some())
            };
            let (cancels, boundary) = *self
                .roles
                .entry(format!("{}|{poly}", subs_key(&subs)))
                .or_insert_with(|| (divides(Role::Cancel), divides(Role::Boundary)));
            entries.push(Entry {
                cancels,
                boundary,
                poly,
                kind: fkind,
                v,
                path,
            });
        }

        // Whether the certificate leaves factors unlisted, with the one
        // role that allows it.
        let unlisted = match p.get("unlisted") {
            None => false,
            Some(v) if v.as_str() == Some("needs_cancellation") => true,
            Some(v) => {
                return Err(err(format!(
                    "{jp}.unlisted: expected \"needs_cancellation\", found {v}"
                )))
            }
        };
        let mut remainders: Leftovers = Rc::default();
        let factors_key = {
            let texts: Vec<String> = entries.iter().map(|e| e.poly.to_string()).collect();
            format!("{}|{}|{unlisted}", subs_key(&subs), texts.join(";"))
        };

        // Coverage of the critical polynomials (not needed when the type
        // has more resonances than the stratum has poles anywhere).
        if !matches!(
            kind,
            "too_many_resonances"
                | "simple_resonances"
                | "collocated_modes"
                | "pole_signs"
                | "block_pole_signs"
        ) {
            let covered = self
                .coverage
                .entry(factors_key.clone())
                .or_insert_with(|| {
                    let factors: Vec<&Poly> = entries.iter().map(|e| &e.poly).collect();
                    let mut left = Vec::new();
                    for c in &s.critical {
                        if c.poly.is_zero() {
                            return Err(format!("critical polynomial: {} is zero", c.what));
                        }
                        if let Some(rest) = uncovered(&c.poly, &factors) {
                            if !unlisted {
                                return Err(format!(
                                    "critical polynomial: {} is not covered by the factors (left {})",
                                    c.what,
                                    abridged(&rest)
                                ));
                            }
                            left.push((c.what.clone(), rest));
                        }
                    }
                    Ok(Rc::new(left))
                })
                .clone();
            remainders = covered.map_err(err)?;
        }

        let boundary_definite = entries.iter().all(|e| !e.boundary || e.kind == "definite");
        let r_t = t.resonances();
        if unlisted {
            let step = |m: String| err(format!("the unlisted factors (needs_cancellation): {m}"));
            counting_premises(r_t, s.den_degree, boundary_definite, false).map_err(step)?;
            // No irreducible factor of what the listed factors leave may
            // divide a resultant of the parts (it would cancel a pole) or a
            // boundary polynomial (it would need a definite proof).
            let others: Vec<&Poly> = s
                .critical
                .iter()
                .filter(|c| c.role != Role::Other)
                .map(|c| &c.poly)
                .collect();
            if !self.coprime_ok.contains(&factors_key) {
                for (what, rest) in remainders.iter() {
                    if !coprime_to_all(rest, &others) {
                        return Err(step(format!(
                            "what the listed factors leave of {what} is not shown coprime to the resultants of the parts and the boundary polynomials"
                        )));
                    }
                }
                self.coprime_ok.insert(factors_key);
            }
        }
        self.check_open(open, &open_jp, kind, &s, &entries, t)
            .map_err(err)?;

        for (i, e) in entries.iter().enumerate() {
            let step = |m: String| err(format!("factor {i} ({}) {}: {m}", e.poly, e.kind));
            match e.kind {
                "definite" => {
                    let sign = int_field(e.v, "sign", &e.path).map_err(step)?;
                    let d = field(e.v, "definiteness", &e.path).map_err(step)?;
                    self.check_definite(&e.poly, sign, d, &format!("{}.definiteness", e.path))
                        .map_err(step)?;
                }
                "needs_no_cancellation" => {
                    if !e.cancels {
                        return Err(step(
                            "the factor divides no resultant of a numerator part and a denominator part"
                                .into(),
                        ));
                    }
                    counting_premises(r_t, s.den_degree, boundary_definite, true).map_err(step)?;
                }
                "needs_cancellation" => {
                    if e.cancels {
                        return Err(step(
                            "the factor divides a resultant of a numerator part and a denominator part"
                                .into(),
                        ));
                    }
                    counting_premises(r_t, s.den_degree, boundary_definite, false).map_err(step)?;
                }
                "wall" => {
                    let sub = Sub::parse(
                        field(e.v, "substitution", &e.path).map_err(step)?,
                        &format!("{}.substitution", e.path),
                    )
                    .map_err(step)?;
                    if !s.vars.contains(&sub.var) {
                        return Err(step(format!(
                            "{} is not a remaining parameter of the stratum",
                            sub.var
                        )));
                    }
                    if !proportional(&e.poly, &sub.wall_poly()) {
                        return Err(step(format!(
                            "the factor is not a constant multiple of {}",
                            sub.wall_poly()
                        )));
                    }
                    let child = field(e.v, "proof", &e.path).map_err(step)?;
                    let mut next = s.subs.clone();
                    next.push(sub.clone());
                    self.check_proof(
                        child,
                        &next,
                        t,
                        &format!("{}.proof", e.path),
                        &format!("{ctx}on wall {sub}: "),
                    )?;
                }
                other => return Err(step(format!("unknown kind {other:?}"))),
            }
        }
        Ok(())
    }

    /// `sign * f > 0` on the positive orthant, by the claimed argument.
    fn check_definite(&mut self, f: &Poly, sign: i64, d: &Value, jp: &str) -> Result<(), String> {
        if sign != 1 && sign != -1 {
            return Err(format!("sign {sign} is not +1 or -1"));
        }
        let g = if sign == 1 { f.clone() } else { -f.clone() };
        let key = format!("{g}|{d}");
        if self.definite_ok.contains(&key) {
            return Ok(());
        }
        positive_by(&g, d, jp, 0)?;
        self.definite_ok.insert(key);
        Ok(())
    }

    fn check_open(
        &mut self,
        open: &Value,
        jp: &str,
        kind: &str,
        s: &Stratum,
        entries: &[Entry],
        t: &Ty,
    ) -> Result<(), String> {
        let r_t = t.resonances();
        let counts = |name: &str| -> Result<(), String> {
            let res = uint_field(open, "resonances", jp)?;
            let deg = uint_field(open, "degree", jp)?;
            if res != r_t as u64 || deg != s.den_degree as u64 {
                return Err(format!(
                    "{name}: the file says {res} resonances and degree {deg}, but the type has {r_t} and the stratum's denominator degree {}",
                    s.den_degree
                ));
            }
            Ok(())
        };
        match kind {
            "too_many_resonances" => {
                counts(kind)?;
                if r_t <= s.den_degree {
                    return Err(format!(
                        "too_many_resonances: the type has {r_t} resonances, the stratum's denominator degree is {}",
                        s.den_degree
                    ));
                }
                Ok(())
            }
            "too_few_resonances" => {
                counts(kind)?;
                if r_t >= s.den_degree {
                    return Err(format!(
                        "too_few_resonances: the type has {r_t} resonances, the stratum's denominator degree is {}",
                        s.den_degree
                    ));
                }
                Ok(())
            }
            "multiplicity" => {
                if multiplicities_fit(s, t) {
                    return Err(
                        "multiplicity: the type's multiplicities fit the stratum's parts".into(),
                    );
                }
                Ok(())
            }
            "simple_resonances" => {
                self.jacobi
                    .clone()
                    .map_err(|e| format!("simple_resonances: {e}"))?;
                if !t.multiple_resonance() {
                    return Err("simple_resonances: the type has no multiple resonance".into());
                }
                Ok(())
            }
            "collocated_modes" => {
                if !self.collocated {
                    return Err("collocated_modes: the model is not collocated".into());
                }
                // The rigid-body pole stays: numerator and denominator are
                // of one sign at Omega = 0 (recomputed, not read).
                for (what, p) in [("numerator", &self.num), ("denominator", &self.den)] {
                    let at_zero = p.subs(OMEGA, &Rat::ZERO);
                    if !(at_zero.all_coefs_positive() || at_zero.all_coefs_negative()) {
                        return Err(format!(
                            "collocated_modes: the {what} at Omega = 0, {at_zero}, changes sign"
                        ));
                    }
                }
                if t.rigid_body_interlacing() {
                    return Err("collocated_modes: the type is of the form (AR)^k".into());
                }
                Ok(())
            }
            "pole_signs" => self
                .check_pole_signs(open, jp, t)
                .map_err(|e| format!("pole_signs: {e}")),
            "block_pole_signs" => self
                .check_block_pole_signs(open, jp, t)
                .map_err(|e| format!("block_pole_signs: {e}")),
            "descartes" => check_descartes(open, jp, s, t),
            "regions" => self.check_regions(open, jp, s, entries, t),
            "sign_conditions" => check_sign_conditions(open, jp, s, t),
            other => Err(format!("open: unknown kind {other:?}")),
        }
    }

    /// The denominator is one block's determinant (a free block's divided
    /// by `Omega`); the numerator's pseudo-remainder by it factors into
    /// one-signed factors, `Omega` and diagonal entries `K_jj - Omega*M_jj`
    /// of the block (roots strictly inside the block's spectrum); no
    /// placement of those roots among the poles gives `t`'s parities.
    fn check_pole_signs(&self, open: &Value, jp: &str, t: &Ty) -> Result<(), String> {
        self.jacobi.clone()?;
        let om = Poly::var(OMEGA);
        let n_res = self.den.degree(OMEGA);
        if t.toks.iter().any(|k| !k.zero && k.mult > 1) || t.resonances() != n_res {
            return Err(format!(
                "the type needs {} simple resonances, the denominator has degree {n_res}",
                n_res
            ));
        }
        // The block whose determinant the denominator is.
        let size = self.mass.len();
        let mut starts = vec![0];
        for i in 1..size {
            if self.stiff[i - 1][i].is_zero() {
                starts.push(i);
            }
        }
        starts.push(size);
        let mut found = None;
        for w in starts.windows(2) {
            let idx: Vec<usize> = (w[0]..w[1]).collect();
            if idx.len() < 2 {
                continue;
            }
            let pencil: Vec<Vec<Poly>> = idx
                .iter()
                .map(|&i| {
                    idx.iter()
                        .map(|&j| &self.stiff[i][j] - &(&om * &self.mass[i][j]))
                        .collect()
                })
                .collect();
            let d = det(&pencil);
            let free = d.subs(OMEGA, &Rat::ZERO).is_zero();
            let p = if free {
                match d.div_exact(&om) {
                    Some(q) => q,
                    None => continue,
                }
            } else {
                d
            };
            if let Some(q) = self.den.div_exact(&p) {
                if q.degree(OMEGA) == 0 && &q * &p == self.den {
                    found = Some((idx, free, p));
                    break;
                }
            }
        }
        let (block, free, p) =
            found.ok_or("the denominator is not the determinant of one block of the pencil")?;
        // The pseudo-remainder, recomputed.
        let deg_p = p.degree(OMEGA);
        let lc_p = p.coeffs_in(OMEGA)[deg_p as usize].clone();
        let mut r = self.num.clone();
        let mut e = 0u32;
        while !r.is_zero() && r.degree(OMEGA) >= deg_p {
            let d = r.degree(OMEGA);
            let lr = r.coeffs_in(OMEGA)[d as usize].clone();
            r = &(&lc_p * &r) - &(&(&lr * &om.pow(d - deg_p)) * &p);
            e += 1;
        }
        let unit: Rat = str_field(open, "remainder_unit", jp)?
            .parse()
            .map_err(|_| format!("{jp}.remainder_unit: not a rational"))?;
        let list = arr_field(open, "remainder_factors", jp)?;
        let mut product = Poly::constant(unit.clone());
        let mut sign: i64 = unit.signum() as i64;
        let mut anchors: Vec<i64> = Vec::new();
        for (i, f) in list.iter().enumerate() {
            let fp = format!("{jp}.remainder_factors[{i}]");
            let (g, k) = listed_factor(f, &fp)?;
            product = &product * &g.pow(k);
            if g.degree(OMEGA) == 0 {
                let s = one_sign(&g).ok_or(format!("{fp}: {g} changes sign"))?;
                sign *= s.pow(k);
            } else if g == om {
                // Positive at every pole.
            } else if g.degree(OMEGA) == 1 && k == 1 {
                let s = block
                    .iter()
                    .find_map(|&j| {
                        let diag = &self.stiff[j][j] - &(&om * &self.mass[j][j]);
                        ratio(&g, &diag)
                    })
                    .ok_or(format!(
                        "{fp}: {g} is no diagonal entry K_jj - Omega*M_jj of the block"
                    ))?;
                anchors.push(s.signum() as i64);
            } else {
                return Err(format!("{fp}: {g}^{k} is not allowed"));
            }
        }
        if product != r {
            return Err(format!(
                "the factors multiply to {product}, the pseudo-remainder is {r}"
            ));
        }
        let lc_sign = one_sign(&lc_p).ok_or("the leading coefficient of the block changes sign")?;
        let at_zero = one_sign(&self.num.subs(OMEGA, &Rat::ZERO))
            .ok_or("the numerator at Omega = 0 changes sign")?;
        let deg_n = self.num.degree(OMEGA);
        let at_inf = one_sign(&self.num.coeffs_in(OMEGA)[deg_n as usize])
            .ok_or("the numerator's leading coefficient changes sign")?;
        let at_pole = sign * lc_sign.pow(e);
        // The type's antiresonances per interval.
        let mut counts = vec![0u32; deg_p as usize + 1];
        let mut j = 0;
        for k in &t.toks {
            if k.zero {
                counts[j] += k.mult;
            } else {
                j += 1;
            }
        }
        let total: u32 = counts.iter().sum();
        if total > deg_n || (total == deg_n) == t.nm {
            return Ok(());
        }
        // Every placement: rho_j above `lowest..deg_p` poles... as the number
        // of poles below it, 0 allowed for a free block (its lowest
        // eigenvalue is 0), never all of them.
        let lowest = u32::from(!free);
        if !anchors.is_empty() && lowest >= deg_p {
            return Err("no placement of the diagonal entries exists".into());
        }
        let mut pos = vec![lowest; anchors.len()];
        loop {
            let mut signs = vec![at_zero];
            for i in 0..deg_p {
                let mut v = at_pole;
                for (s, k) in anchors.iter().zip(&pos) {
                    v *= if i >= *k { -s } else { *s };
                }
                signs.push(v);
            }
            signs.push(at_inf);
            let fits = signs
                .windows(2)
                .zip(&counts)
                .all(|(w, c)| (w[0] != w[1]) == (c % 2 == 1));
            if fits {
                return Err(format!(
                    "the type fits the placement with {pos:?} poles below the diagonal entries"
                ));
            }
            let mut i = 0;
            loop {
                if i == pos.len() {
                    return Ok(());
                }
                pos[i] += 1;
                if pos[i] < deg_p {
                    break;
                }
                pos[i] = lowest;
                i += 1;
            }
        }
    }

    /// The denominator is `c` times the pole polynomials of
    /// the listed blocks (each block's determinant, a free block's divided
    /// by `Omega`), `c` free of `Omega` and of one sign; the TF is
    /// `-Omega * sum_B n_B / d_B` with the listed `n_B` (checked as a polynomial
    /// identity). At a pole of block `B` the numerator then has the sign of
    /// `-c * n_B * prod_{B' != B} p_B'`: each `p_B'` by how many of its
    /// roots lie above, `n_B` (or its pseudo-remainder by `p_B`) from its
    /// factors, each of one sign, `Omega`, or a multiple of the
    /// determinant of a proper run of the block's masses, whose
    /// eigenvalues interlace with the block's (Cauchy). No interleaving and
    /// no placement gives the type's parities.
    fn check_block_pole_signs(&self, open: &Value, jp: &str, t: &Ty) -> Result<(), String> {
        self.jacobi.clone()?;
        let om = Poly::var(OMEGA);
        let size = self.mass.len();
        let pencil = |lo: usize, hi: usize| -> Vec<Vec<Poly>> {
            (lo..hi)
                .map(|i| {
                    (lo..hi)
                        .map(|j| &self.stiff[i][j] - &(&om * &self.mass[i][j]))
                        .collect()
                })
                .collect()
        };
        let list = arr_field(open, "blocks", jp)?;
        if list.is_empty() {
            return Err("no blocks".into());
        }
        // (first mass, last mass + 1, d_B, p_B, free, n_B), 0-based.
        let mut blocks = Vec::new();
        let mut taken = vec![false; size];
        for (k, b) in list.iter().enumerate() {
            let bp = format!("{jp}.blocks[{k}]");
            let masses = arr_field(b, "masses", &bp)?;
            let idx: Vec<usize> = masses
                .iter()
                .map(|v| v.as_u64().filter(|&i| i >= 1 && (i as usize) <= size))
                .collect::<Option<Vec<u64>>>()
                .ok_or(format!("{bp}.masses: not masses of the model"))?
                .into_iter()
                .map(|i| i as usize - 1)
                .collect();
            let (Some(&lo), Some(&last)) = (idx.first(), idx.last()) else {
                return Err(format!("{bp}.masses: empty"));
            };
            let hi = last + 1;
            if idx.iter().enumerate().any(|(i, &m)| m != lo + i) {
                return Err(format!("{bp}.masses: not consecutive"));
            }
            // A whole block: joined inside, cut from its neighbours.
            let joined = (lo + 1..hi).all(|i| !self.stiff[i - 1][i].is_zero());
            let cut = (lo == 0 || self.stiff[lo - 1][lo].is_zero())
                && (hi == size || self.stiff[hi - 1][hi].is_zero());
            if !joined || !cut {
                return Err(format!("{bp}.masses: not a block of the chain"));
            }
            if idx.iter().any(|&i| taken[i]) {
                return Err(format!("{bp}.masses: listed twice"));
            }
            idx.iter().for_each(|&i| taken[i] = true);
            let d = det(&pencil(lo, hi));
            let free = d.subs(OMEGA, &Rat::ZERO).is_zero();
            let p = if free {
                d.div_exact(&om)
                    .ok_or(format!("{bp}: det/Omega is not exact"))?
            } else {
                d.clone()
            };
            let n = poly_field(b, "numerator", &bp)?;
            // A block without a term has no poles in the TF: its poles
            // would all cancel, which the argument does not allow for.
            if n.is_zero() {
                return Err(format!("{bp}.numerator: zero"));
            }
            // The term itself, not just the sum of the terms: the identity
            // below holds for n_A + t d_A, n_B - t d_B too, and collocation
            // and the signs speak of the true c_B^T P_B^-1 b_B.
            let adj = adjugate(&pencil(lo, hi));
            let mut own = Poly::zero();
            for i in lo..hi {
                for j in lo..hi {
                    let w = self.output[i] * self.input[j];
                    if w != 0 {
                        own = &own + &adj[i - lo][j - lo].scale(&Rat::from(w));
                    }
                }
            }
            if own != n {
                return Err(format!("{bp}.numerator: not c_B^T adj(P_B) b_B = {own}"));
            }
            blocks.push((lo, hi, d, p, free, n, bp, b));
        }
        // The denominator's form.
        let prod_p = blocks.iter().fold(Poly::one(), |a, b| &a * &b.3);
        let rest = self
            .den
            .div_exact(&prod_p)
            .ok_or("the blocks' pole polynomials do not divide the denominator")?
            .coeffs_in(OMEGA);
        // `den = c * prod p_B`, `c` free of Omega (a power of Omega would
        // change the degree and (nm) rules below).
        if rest.len() != 1 {
            return Err("the denominator over the pole polynomials depends on Omega".into());
        }
        let c_sign = one_sign(&rest[0]).ok_or("the denominator's remaining factor changes sign")?;
        // The TF as the sum of the block terms.
        let prod_d = blocks.iter().fold(Poly::one(), |a, b| &a * &b.2);
        let mut sum = Poly::zero();
        for (k, b) in blocks.iter().enumerate() {
            let mut term = b.5.clone();
            for (l, o) in blocks.iter().enumerate() {
                if l != k {
                    term = &term * &o.2;
                }
            }
            sum = &sum + &term;
        }
        if &self.num * &prod_d != -(&(&om * &self.den) * &sum) {
            return Err("num * prod d_B != -Omega * den * sum_B n_B prod_{B' != B} d_B'".into());
        }
        let deg_n = self.num.degree(OMEGA);
        let at_inf = one_sign(&self.num.coeffs_in(OMEGA)[deg_n as usize])
            .ok_or("the numerator's leading coefficient changes sign")?;
        // Per block: its events (poles and minors), read off the factors.
        let mut infos: Vec<CheckBlock> = Vec::new();
        for (lo, hi, _, p, free, n, bp, entry) in &blocks {
            let (lo, hi, free) = (*lo, *hi, *free);
            let deg_p = p.degree(OMEGA);
            let lc_p = p.coeffs_in(OMEGA)[deg_p as usize].clone();
            let lead =
                one_sign(&lc_p).ok_or(format!("{bp}: the leading coefficient changes sign"))?;
            let remainder = bool_field(entry, "remainder", bp)?;
            if remainder && deg_p == 0 {
                return Err(format!("{bp}: a remainder by a constant"));
            }
            // The polynomial whose factors are listed, recomputed.
            let mut target = n.clone();
            let mut e = 0u32;
            if remainder {
                while !target.is_zero() && target.degree(OMEGA) >= deg_p {
                    let d = target.degree(OMEGA);
                    let lr = target.coeffs_in(OMEGA)[d as usize].clone();
                    target = &(&lc_p * &target) - &(&(&lr * &om.pow(d - deg_p)) * p);
                    e += 1;
                }
            }
            let unit: Rat = str_field(entry, "unit", bp)?
                .parse()
                .map_err(|_| format!("{bp}.unit: not a rational"))?;
            let mut product = Poly::constant(unit.clone());
            let mut base = unit.signum() as i64 * lead.pow(e);
            let mut runs: Vec<CheckRun> = Vec::new();
            for (i, f) in arr_field(entry, "factors", bp)?.iter().enumerate() {
                let fp = format!("{bp}.factors[{i}]");
                let (g, k) = listed_factor(f, &fp)?;
                product = &product * &g.pow(k);
                if g.degree(OMEGA) == 0 {
                    base *= one_sign(&g)
                        .ok_or(format!("{fp}: {g} changes sign"))?
                        .pow(k);
                } else if g != om {
                    let mut found = None;
                    'runs: for a in lo..hi {
                        for z in a + 1..=hi {
                            if z - a == hi - lo {
                                continue;
                            }
                            if let Some(r) = ratio(&g, &det(&pencil(a, z))) {
                                found = Some(CheckRun {
                                    first: a - lo,
                                    len: z - a,
                                    sign: r.signum() as i64,
                                    exponent: k,
                                });
                                break 'runs;
                            }
                        }
                    }
                    runs.push(found.ok_or(format!(
                        "{fp}: {g} is no multiple of the determinant of a proper run of the block"
                    ))?);
                }
            }
            if product != target {
                return Err(format!(
                    "{bp}: the factors multiply to {product}, not to {}",
                    if remainder {
                        "the pseudo-remainder"
                    } else {
                        "n_B"
                    }
                ));
            }
            // (n_B is nonzero, so b_B is.)
            let mut collocated = 0;
            for s in [1, -1] {
                if collocated == 0 && (lo..hi).all(|i| self.output[i] == s * self.input[i]) {
                    collocated = s;
                }
            }
            let mut omega_power = 0;
            while n.coeffs_in(OMEGA)[omega_power as usize].is_zero() {
                omega_power += 1;
            }
            infos.push(CheckBlock {
                size: hi - lo,
                free,
                lead,
                direct: !remainder,
                base,
                runs,
                collocated,
                omega_power,
                degree: n.degree(OMEGA),
                n_lead: one_sign(&n.coeffs_in(OMEGA)[n.degree(OMEGA) as usize]),
                n_low: one_sign(&n.coeffs_in(OMEGA)[omega_power as usize]),
            });
        }
        if infos.len() > 2 {
            return Err("more than two blocks".into());
        }
        let total_poles: u32 = infos.iter().map(|b| b.pole_count() as u32).sum();
        // The type: simple resonances; the reduced numerator has degree
        // deg num - (cancelled poles), and (nm) says whether it has fewer
        // positive zeros.
        if t.multiple_resonance() {
            return Err("the type has a multiple resonance".into());
        }
        // Per interval between resonances: the zeros with multiplicity,
        // and each zero's multiplicity (a multiple zero is one point).
        let mut counts = vec![0u32];
        let mut points: Vec<Vec<u32>> = vec![Vec::new()];
        for k in &t.toks {
            if k.zero {
                *counts.last_mut().expect("one") += k.mult;
                points.last_mut().expect("one").push(k.mult);
            } else {
                counts.push(0);
                points.push(Vec::new());
            }
        }
        let res = counts.len() as u32 - 1;
        let positive: u32 = counts.iter().sum();
        if res > total_poles || deg_n + res < total_poles {
            return Ok(());
        }
        let reduced = deg_n + res - total_poles;
        if positive > reduced || (positive < reduced) != t.nm {
            return Ok(());
        }
        // One block whose term is a product of minors: its positive zeros
        // are the minors' eigenvalues, counted exactly.
        let exact = infos.len() == 1 && infos[0].direct;
        let at_zero_poly = self.num.subs(OMEGA, &Rat::ZERO);
        let at_zero = if exact {
            if t.nm != at_zero_poly.is_zero() {
                return Ok(());
            }
            0
        } else {
            one_sign(&at_zero_poly).ok_or("the numerator at Omega = 0 changes sign")?
        };
        let per_block: Vec<Vec<Vec<CheckEvent>>> = infos.iter().map(block_orders).collect();
        let mut tried = 0usize;
        let mut fits = None;
        let mut visit = |order: &[(usize, CheckEvent)], shared: &[(usize, bool)]| {
            tried += 1;
            if fits.is_none()
                && configuration_fits(
                    &infos,
                    order,
                    shared,
                    -c_sign,
                    at_zero,
                    at_inf,
                    exact,
                    (&counts, &points),
                )
            {
                fits = Some(format!("{order:?} shared {shared:?}"));
            }
        };
        match per_block.len() {
            1 => {
                for o in &per_block[0] {
                    let order: Vec<(usize, CheckEvent)> =
                        o.iter().map(|e| (0, e.clone())).collect();
                    visit(&order, &[]);
                }
            }
            _ => {
                for a in &per_block[0] {
                    for b in &per_block[1] {
                        interleave(a, b, &mut visit);
                    }
                }
            }
        }
        if tried > CHECK_MAX_CONFIGURATIONS {
            return Err(format!("{tried} configurations: too many to check"));
        }
        match fits {
            Some(c) => Err(format!("the type fits the configuration {c}")),
            None => Ok(()),
        }
    }

    fn check_regions(
        &mut self,
        open: &Value,
        jp: &str,
        s: &Stratum,
        entries: &[Entry],
        t: &Ty,
    ) -> Result<(), String> {
        let walls: Vec<Sub> = arr_field(open, "walls", jp)?
            .iter()
            .enumerate()
            .map(|(i, v)| Sub::parse(v, &format!("{jp}.walls[{i}]")))
            .collect::<Result<_, _>>()?;
        let gaps = polys_field(open, "gaps", jp)?;
        let samples = arr_field(open, "samples", jp)?;
        let var = field(open, "var", jp)?;
        let x = match var {
            Value::Null => {
                if !walls.is_empty() || !gaps.is_empty() {
                    return Err("regions: walls without a variable".into());
                }
                if let Some(e) = entries.iter().find(|e| e.kind != "definite") {
                    return Err(format!(
                        "regions: factor {} has no definite proof, but there are no walls",
                        e.poly
                    ));
                }
                None
            }
            Value::String(x) => Some(x.as_str()),
            _ => return Err(format!("{jp}.var: expected a string or null")),
        };
        if let Some(x) = x {
            if !s.vars.contains(&x.to_string()) {
                return Err(format!("regions: {x} is not a parameter of the stratum"));
            }
            for (i, w) in walls.iter().enumerate() {
                if w.var != x {
                    return Err(format!("regions: wall {i} ({w}) is not in {x}"));
                }
                for (name, p) in [("alpha", &w.alpha), ("beta", &w.beta)] {
                    if !p.all_coefs_positive() {
                        return Err(format!(
                            "regions: wall {i} ({w}): {name} does not have all coefficients positive"
                        ));
                    }
                    if let Some(v) = p.vars().iter().find(|v| *v == x || !s.vars.contains(v)) {
                        return Err(format!("regions: wall {i} ({w}): {name} involves {v}"));
                    }
                }
            }
            // The non-definite factors are exactly the walls.
            let mut used = vec![false; walls.len()];
            for e in entries.iter().filter(|e| e.kind != "definite") {
                let hit = (0..walls.len())
                    .find(|&i| !used[i] && proportional(&e.poly, &walls[i].wall_poly()))
                    .ok_or_else(|| {
                        format!(
                            "regions: factor {} has no definite proof and is no wall",
                            e.poly
                        )
                    })?;
                used[hit] = true;
            }
            if let Some(i) = used.iter().position(|u| !u) {
                return Err(format!(
                    "regions: wall {i} ({}) is not a factor without a definite proof",
                    walls[i]
                ));
            }
            if gaps.len() + 1 != walls.len().max(1) {
                return Err(format!(
                    "regions: {} gaps for {} walls",
                    gaps.len(),
                    walls.len()
                ));
            }
            for (i, w) in walls.windows(2).enumerate() {
                let gap = &(&w[1].beta * &w[0].alpha) - &(&w[0].beta * &w[1].alpha);
                if gap != gaps[i] {
                    return Err(format!("regions: gap {i} is {}, expected {gap}", gaps[i]));
                }
                if !gap.all_coefs_positive() {
                    return Err(format!(
                        "regions: gap {i} ({gap}) does not have all coefficients positive"
                    ));
                }
            }
        }
        if samples.len() != walls.len() + 1 {
            return Err(format!(
                "regions: {} samples for {} walls",
                samples.len(),
                walls.len()
            ));
        }
        for (j, sample) in samples.iter().enumerate() {
            let sp = format!("{jp}.samples[{j}]");
            let step = |m: String| format!("regions: sample {j}: {m}");
            let point = parse_point(
                field(sample, "point", &sp)?,
                &self.params,
                &format!("{sp}.point"),
            )
            .map_err(step)?;
            let eval = |p: &Poly| {
                p.eval(&point)
                    .map_err(|v| step(format!("no value for {v}")))
            };
            for sub in &s.subs {
                let (a, b) = (eval(&sub.alpha)?, eval(&sub.beta)?);
                if &point[&sub.var] * &a != b {
                    return Err(step(format!(
                        "the point is not on the stratum: {sub} fails"
                    )));
                }
            }
            if let Some(x) = x {
                let xv = &point[x];
                let value =
                    |w: &Sub| -> Result<Rat, String> { Ok(&eval(&w.beta)? / &eval(&w.alpha)?) };
                if j > 0 {
                    let lo = value(&walls[j - 1])?;
                    if *xv <= lo {
                        return Err(step(format!(
                            "{x} = {xv} is not above wall {} ({lo})",
                            j - 1
                        )));
                    }
                }
                if j < walls.len() {
                    let hi = value(&walls[j])?;
                    if *xv >= hi {
                        return Err(step(format!("{x} = {xv} is not below wall {j} ({hi})")));
                    }
                }
            }
            let got = classify(&self.num, &self.den, &point).map_err(step)?;
            let claimed = Ty::parse(str_field(sample, "type", &sp)?).map_err(step)?;
            if got != claimed {
                return Err(step(format!(
                    "the type there is {got}, the file says {claimed}"
                )));
            }
            if &got == t {
                return Err(step(format!("the type there is {t} itself")));
            }
        }
        Ok(())
    }
}

/// `g > 0` on the open positive orthant by the argument `d`.
/// `1` or `-1` if every coefficient of `q` has that sign (so `q` has that
/// sign on the whole orthant), else `None`.
fn one_sign(q: &Poly) -> Option<i64> {
    if q.all_coefs_positive() {
        Some(1)
    } else if q.all_coefs_negative() {
        Some(-1)
    } else {
        None
    }
}

/// A `{"factor", "exponent"}` entry of a certificate (exponent at least 1).
fn listed_factor(f: &Value, fp: &str) -> Result<(Poly, u32), String> {
    let g = poly_field(f, "factor", fp)?;
    let k = uint_field(f, "exponent", fp)?;
    match u32::try_from(k) {
        Ok(k) if k > 0 => Ok((g, k)),
        _ => Err(format!("{fp}: exponent {k}")),
    }
}

/// Configurations the block pole-sign check enumerates at most.
const CHECK_MAX_CONFIGURATIONS: usize = 2_000_000;

/// A block of a block pole-sign certificate, as the checker reads it.
struct CheckBlock {
    size: usize,
    free: bool,
    lead: i64,
    /// The factors are `n_B`'s own (its zeros are the runs' eigenvalues).
    direct: bool,
    base: i64,
    runs: Vec<CheckRun>,
    /// `s` when the sensor vector on the block is `s` times the
    /// actuator's (`s = +-1`), else `0`.
    collocated: i64,
    /// How often `Omega` divides `n_B`.
    omega_power: u32,
    /// The degree of `n_B` in `Omega`.
    degree: u32,
    /// The signs of `n_B`'s leading and lowest coefficients in `Omega`,
    /// where they have one on the orthant.
    n_lead: Option<i64>,
    n_low: Option<i64>,
}

impl CheckBlock {
    /// The block's eigenvalue index (1-based) of its lowest pole.
    fn lowest_pole(&self) -> usize {
        if self.free {
            2
        } else {
            1
        }
    }

    fn pole_count(&self) -> usize {
        self.size + 1 - self.lowest_pole()
    }
}

/// A run of a block's masses whose determinant is a listed factor.
struct CheckRun {
    first: usize,
    len: usize,
    sign: i64,
    exponent: u32,
}

/// An event of one block's spectrum.
#[derive(Clone, Debug, PartialEq)]
enum CheckEvent {
    /// The block's eigenvalue `index`; `on` the runs with an eigenvalue on
    /// it; `n_sign` the sign of `n_B` there (when `on` is empty).
    Pole {
        index: usize,
        on: Vec<usize>,
        n_sign: i64,
    },
    /// An eigenvalue of run `run` strictly between two of the block's.
    Eig { run: usize },
}

/// Every order of one block's events: each run's eigenvalue `i` (of `k`,
/// block of `n`) at a position from the block's eigenvalue `i` to `i+n-k`
/// (Cauchy), on an eigenvalue (position `2j`, neither the block's lowest
/// nor its highest) or in the gap above it (`2j+1`); increasing, equal only in a gap and only for
/// a run inside the block (a run at an end takes one gap per eigenvalue).
/// A remainder's runs act only through the poles (signs, cancellation).
fn block_orders(b: &CheckBlock) -> Vec<Vec<CheckEvent>> {
    let n = b.size;
    let mut per_run: Vec<Vec<Vec<usize>>> = Vec::new();
    for r in &b.runs {
        let at_end = r.first == 0 || r.first + r.len == n;
        let mut seqs: Vec<Vec<usize>> = vec![Vec::new()];
        for i in 1..=r.len {
            let mut grown = Vec::new();
            for sq in &seqs {
                for q in 2 * i..=2 * (i + n - r.len) {
                    // Not on the block's extreme eigenvalues: those of a
                    // proper run of an irreducible tridiagonal pencil lie
                    // strictly inside (Perron-Frobenius).
                    if q % 2 == 0 && (q / 2 == 1 || q / 2 == n) {
                        continue;
                    }
                    if let Some(&last) = sq.last() {
                        if q < last || (q == last && (at_end || q % 2 == 0)) {
                            continue;
                        }
                    }
                    let mut v = sq.clone();
                    v.push(q);
                    grown.push(v);
                }
            }
            seqs = grown;
        }
        // A common eigenvalue of the block and a run at its end is one of
        // the block beyond the run's neighbour (expand det P across the
        // spring between them; the run less its mass at that spring
        // interlaces the run strictly): n - len - 1 of them at most.
        if at_end {
            seqs.retain(|sq| sq.iter().filter(|&&q| q % 2 == 0).count() + r.len < n);
        }
        per_run.push(seqs);
    }
    // Every combination of the runs' positions.
    let mut combos: Vec<Vec<usize>> = vec![Vec::new()];
    for seqs in &per_run {
        combos = combos
            .iter()
            .flat_map(|c| {
                (0..seqs.len()).map(move |i| {
                    let mut v = c.clone();
                    v.push(i);
                    v
                })
            })
            .collect();
    }
    combos.retain(|c| union_cauchy(b, &per_run, c) && end_ties_shared(b, &per_run, c));
    let mut out: Vec<Vec<CheckEvent>> = Vec::new();
    for c in combos {
        let at = |q: usize| -> Vec<usize> {
            let mut v = Vec::new();
            for (r, seqs) in per_run.iter().enumerate() {
                v.extend(seqs[c[r]].iter().filter(|&&x| x == q).map(|_| r));
            }
            v
        };
        let mut orders: Vec<Vec<CheckEvent>> = vec![Vec::new()];
        for q in 2..=2 * n {
            if q % 2 == 0 {
                if q / 2 < b.lowest_pole() {
                    continue;
                }
                let mut n_sign = b.base;
                for (r, run) in b.runs.iter().enumerate() {
                    if run.exponent % 2 == 1 {
                        let below = per_run[r][c[r]].iter().filter(|&&x| x < q).count() as u32;
                        n_sign *= run.sign * (-1i64).pow(below);
                    }
                }
                let ev = CheckEvent::Pole {
                    index: q / 2,
                    on: at(q),
                    n_sign,
                };
                orders.iter_mut().for_each(|o| o.push(ev.clone()));
            } else if b.direct {
                let here = at(q);
                if here.is_empty() {
                    continue;
                }
                // All distinct orders of the eigenvalues in this gap.
                let mut perms: Vec<Vec<usize>> = vec![Vec::new()];
                for _ in 0..here.len() {
                    let mut grown = Vec::new();
                    for p in &perms {
                        let mut left = here.clone();
                        for x in p {
                            let i = left.iter().position(|y| y == x).expect("present");
                            left.remove(i);
                        }
                        left.sort_unstable();
                        left.dedup();
                        for x in left {
                            let mut v = p.clone();
                            v.push(x);
                            grown.push(v);
                        }
                    }
                    perms = grown;
                }
                let mut grown = Vec::new();
                for o in &orders {
                    for p in &perms {
                        let mut v = o.clone();
                        v.extend(p.iter().map(|&r| CheckEvent::Eig { run: r }));
                        grown.push(v);
                    }
                }
                orders = grown;
            }
        }
        for o in orders {
            if !out.contains(&o) {
                out.push(o);
            }
        }
    }
    out
}

/// Cauchy interlacing for every set of runs no spring joins (the matrix
/// on their masses is block diagonal, so its spectrum is theirs together):
/// with `k` masses in a block of `n`, the set's `i`-th smallest eigenvalue
/// sits at a position from `2i` to `2(i+n-k)`.
fn union_cauchy(b: &CheckBlock, per_run: &[Vec<Vec<usize>>], c: &[usize]) -> bool {
    let n = b.size;
    for set in 0u64..(1u64 << b.runs.len()) {
        if set.count_ones() < 2 {
            continue;
        }
        // Which run owns each mass; two runs may neither share a mass nor
        // touch.
        let mut owner: Vec<Option<usize>> = vec![None; n];
        let mut apart = true;
        for (r, run) in b.runs.iter().enumerate() {
            if set & (1 << r) == 0 {
                continue;
            }
            for slot in &mut owner[run.first..run.first + run.len] {
                if slot.is_some() {
                    apart = false;
                }
                *slot = Some(r);
            }
        }
        for m in 1..n {
            if let (Some(x), Some(y)) = (owner[m - 1], owner[m]) {
                if x != y {
                    apart = false;
                }
            }
        }
        if !apart {
            continue;
        }
        let k = owner.iter().filter(|o| o.is_some()).count();
        let mut positions: Vec<usize> = Vec::new();
        for (r, seqs) in per_run.iter().enumerate() {
            if set & (1 << r) != 0 {
                positions.extend(seqs[c[r]].iter().copied());
            }
        }
        positions.sort_unstable();
        for (i, q) in positions.iter().enumerate() {
            let i = i + 1;
            if *q < 2 * i || *q > 2 * (i + n - k) {
                return false;
            }
        }
    }
    true
}

/// A run at one end of the block and the run at the other end, with one
/// mass between them: a block eigenvalue on an eigenvalue of the first is
/// one of the second (det P expanded across the spring to the mass
/// between), so every position on an eigenvalue the first takes, the
/// second takes too.
fn end_ties_shared(b: &CheckBlock, per_run: &[Vec<Vec<usize>>], c: &[usize]) -> bool {
    let n = b.size;
    for (x, rx) in b.runs.iter().enumerate() {
        for (y, ry) in b.runs.iter().enumerate() {
            let ends = (rx.first == 0 && ry.first + ry.len == n)
                || (ry.first == 0 && rx.first + rx.len == n);
            if x == y || !ends || rx.len + ry.len + 1 != n {
                continue;
            }
            let ys = &per_run[y][c[y]];
            if per_run[x][c[x]]
                .iter()
                .any(|q| q % 2 == 0 && !ys.contains(q))
            {
                return false;
            }
        }
    }
    true
}

/// What [`interleave`] hands over: the merged order and the coincident
/// poles.
type ConfigurationVisitor<'a> = &'a mut dyn FnMut(&[(usize, CheckEvent)], &[(usize, bool)]);

/// Calls `visit` with every merge of two blocks' orders: `(block, event)`
/// in increasing order, and the positions `i` where the poles at `i` and
/// `i + 1` (one per block) coincide, the double root cancelling once
/// (`false`) or twice.
fn interleave(a: &[CheckEvent], b: &[CheckEvent], visit: ConfigurationVisitor) {
    fn go(
        seqs: [&[CheckEvent]; 2],
        at: [usize; 2],
        order: &mut Vec<(usize, CheckEvent)>,
        shared: &mut Vec<(usize, bool)>,
        visit: ConfigurationVisitor,
    ) {
        if at[0] == seqs[0].len() && at[1] == seqs[1].len() {
            visit(order, shared);
            return;
        }
        for k in 0..2 {
            if let Some(e) = seqs[k].get(at[k]) {
                order.push((k, e.clone()));
                let mut next = at;
                next[k] += 1;
                go(seqs, next, order, shared, visit);
                order.pop();
            }
        }
        if let (Some(e0 @ CheckEvent::Pole { .. }), Some(e1 @ CheckEvent::Pole { .. })) =
            (seqs[0].get(at[0]), seqs[1].get(at[1]))
        {
            for double in [false, true] {
                shared.push((order.len(), double));
                order.push((0, e0.clone()));
                order.push((1, e1.clone()));
                go(seqs, [at[0] + 1, at[1] + 1], order, shared, visit);
                order.pop();
                order.pop();
                shared.pop();
            }
        }
    }
    go([a, b], [0, 0], &mut Vec::new(), &mut Vec::new(), visit);
}

/// What a configuration says at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
enum CheckSample {
    /// A pole of the reduced TF (the numerator's sign there if known).
    Pole(Option<i64>),
    /// The reduced numerator's sign at a point that is no pole.
    Sign(i64),
    /// Zeros at a point (one block whose zeros are its runs' eigenvalues).
    Zeros(u32),
    /// At most this many zeros between the samples on either side: none
    /// when both blocks' terms `T_B = n_B / d_B` have one and the same sign
    /// on that open interval, one (simple) when all are strictly monotone
    /// there in one direction.
    Cap(u32),
}

/// Whether the type with `counts` antiresonances between its resonances
/// (`points`: each zero's multiplicity, in order) fits the configuration
/// `order` (with the coincident poles `shared`).
#[allow(clippy::too_many_arguments)]
fn configuration_fits(
    blocks: &[CheckBlock],
    order: &[(usize, CheckEvent)],
    shared: &[(usize, bool)],
    minus_c: i64,
    at_zero: i64,
    at_inf: i64,
    exact: bool,
    (counts, points): (&[u32], &[Vec<u32>]),
) -> bool {
    let sgn = |k: usize| (-1i64).pow(k as u32 % 2);
    let partner = |i: usize| shared.iter().any(|&(j, _)| j + 1 == i);
    // At coincident poles the terms' residues decide the cancellation: a
    // pole with a run's eigenvalue on it has none; otherwise the residue
    // has the sign of n_B times p_B' (the leading sign, flipped for each
    // of the block's poles above). Twice needs both gone or a zero sum.
    for &(j, double) in shared {
        let residue = |i: usize| -> Option<i64> {
            let (k, e) = &order[i];
            match e {
                CheckEvent::Pole { on, n_sign, .. } if on.is_empty() => {
                    let above = order[i + 1..]
                        .iter()
                        .filter(|(kk, ee)| kk == k && matches!(ee, CheckEvent::Pole { .. }))
                        .count();
                    Some(n_sign * blocks[*k].lead * sgn(above))
                }
                _ => None,
            }
        };
        let ok = match (residue(j), residue(j + 1)) {
            (None, None) => double,
            (Some(a), Some(b)) => !double || a != b,
            _ => !double,
        };
        if !ok {
            return false;
        }
    }
    // Eigenvalues of run `r` of block `k` before position `i` (those on a
    // pole count where the pole is).
    let eigs_before = |i: usize, k: usize, r: usize| -> usize {
        order[..i]
            .iter()
            .map(|(kk, e)| match e {
                CheckEvent::Eig { run } if *kk == k && *run == r => 1,
                CheckEvent::Pole { on, .. } if *kk == k => on.iter().filter(|&&x| x == r).count(),
                _ => 0,
            })
            .sum()
    };
    let poles_after = |i: usize, k: usize| -> usize {
        order[i + 1..]
            .iter()
            .filter(|(kk, e)| *kk == k && matches!(e, CheckEvent::Pole { .. }))
            .count()
    };
    // Points where the reduced TF divides out (Omega - x): (position, power).
    let mut cancel: Vec<(usize, u32)> = Vec::new();
    for (i, (_, e)) in order.iter().enumerate() {
        if partner(i) {
            continue;
        }
        if let Some(&(_, double)) = shared.iter().find(|&&(j, _)| j == i) {
            cancel.push((i, if double { 2 } else { 1 }));
        } else if let CheckEvent::Pole { on, .. } = e {
            if !on.is_empty() {
                cancel.push((i, 1));
            }
        }
    }
    let reduced = |i: usize, s: i64| -> i64 {
        cancel
            .iter()
            .filter(|&&(j, k)| j > i && k % 2 == 1)
            .fold(s, |s, _| -s)
    };
    // The sign of block k's term n_B / p_B just below position i (above
    // every event when i is the length), if its runs give every zero of
    // n_B.
    let term_sign = |i: usize, k: usize| -> Option<i64> {
        let b = &blocks[k];
        if !b.direct {
            return None;
        }
        let mut s = b.base * b.lead;
        for (r, run) in b.runs.iter().enumerate() {
            if run.exponent % 2 == 1 {
                s *= run.sign * sgn(eigs_before(i, k, r));
            }
        }
        let poles_above = order[i..]
            .iter()
            .filter(|(kk, e)| *kk == k && matches!(e, CheckEvent::Pole { .. }))
            .count();
        Some(s * sgn(poles_above))
    };
    // Whether T_B rises (+1) or falls (-1) just below position i: the
    // derivative of a collocated term is +-(P^-1 b)^T M (P^-1 b); else
    // d log|T_B| / dOmega sums 1/(Omega - z) over n_B's zeros z (0 counted
    // omega_power times) minus the same over d_B's roots (0 once for a
    // free block), each term of known sign when its root is on a known
    // side of the interval.
    let direction = |i: usize, k: usize| -> Option<i64> {
        let b = &blocks[k];
        if b.collocated != 0 {
            return Some(b.collocated);
        }
        let s = term_sign(i, k)?;
        // The term's zeros and poles by place (0 for Omega = 0, j + 1 for
        // order[j]), each as often as its multiplicity.
        let mut zeros: Vec<usize> = vec![0; b.omega_power as usize];
        let mut poles: Vec<usize> = vec![0; usize::from(b.free)];
        for (j, (kk, e)) in order.iter().enumerate() {
            if *kk != k {
                continue;
            }
            match e {
                CheckEvent::Pole { on, .. } => {
                    poles.push(j + 1);
                    for &r in on {
                        zeros.extend(std::iter::repeat_n(j + 1, b.runs[r].exponent as usize));
                    }
                }
                CheckEvent::Eig { run } => {
                    zeros.extend(std::iter::repeat_n(j + 1, b.runs[*run].exponent as usize));
                }
            }
        }
        zeros.sort_unstable();
        poles.sort_unstable();
        if zeros == poles {
            return None; // a constant term
        }
        // Above the interval (places past i) the term's log-derivative
        // gets -1/(z - Omega) per zero and +1/(r - Omega) per pole: every
        // zero paired with a pole at or below it leaves the sum positive.
        // Below (places up to i), +1/(Omega - z) per zero and -1/(Omega -
        // r) per pole: every pole paired with a zero at or above it.
        let (za, zb): (Vec<usize>, Vec<usize>) = zeros.iter().partition(|&&x| x > i);
        let (pa, pb): (Vec<usize>, Vec<usize>) = poles.iter().partition(|&&x| x > i);
        // Each of `needy` (sorted) matched with a distinct one of
        // `providers` (sorted) at least as near the interval: above it the
        // nearest are the lowest, below it the highest.
        let covered = |needy: &[usize], providers: &[usize], above: bool| -> bool {
            let n = needy.len();
            providers.len() >= n
                && (0..n).all(|t| {
                    if above {
                        providers[t] <= needy[t]
                    } else {
                        providers[providers.len() - 1 - t] >= needy[n - 1 - t]
                    }
                })
        };
        let rising = covered(&za, &pa, true) && covered(&pb, &zb, false);
        let falling = covered(&pa, &za, true) && covered(&zb, &pb, false);
        match (rising, falling) {
            (true, false) => Some(s),
            (false, true) => Some(-s),
            _ => None,
        }
    };
    // The reduced numerator's sign at a pole two blocks share that cancels
    // once (events i and i + 1): the numerator's derivative there, `-c
    // (n_B q_B + n_B' q_B')` with `q` the derivative of the other block's
    // pole polynomial, up to positive factors. Each product has the sign
    // of its block's residue times both `q`, so the sign is known where
    // the residues agree, or where a run's eigenvalue on one block's pole
    // takes its product away.
    let shared_pole_sign = |i: usize| -> Option<i64> {
        let product = |j: usize| -> Option<i64> {
            let (k, e) = &order[j];
            let CheckEvent::Pole { on, n_sign, .. } = e else {
                return None;
            };
            if !on.is_empty() {
                return Some(0);
            }
            let o = 1 - *k;
            let other_above = order[i + 2..]
                .iter()
                .filter(|(kk, ee)| *kk == o && matches!(ee, CheckEvent::Pole { .. }))
                .count();
            Some(minus_c * n_sign * blocks[o].lead * sgn(other_above))
        };
        let (a, b) = (product(i)?, product(i + 1)?);
        let s = match (a, b) {
            (0, 0) => return None,
            (0, x) | (x, 0) => x,
            (x, y) if x == y => x,
            _ => return None,
        };
        Some(reduced(i, s))
    };
    // At most so many zeros on the open interval from the gap below
    // position `from` to the gap below `to`, across the events `passed`
    // between them that gave no sample (eigenvalues of runs, poles a run's
    // eigenvalue cancels): no term has a pole there, so each is continuous
    // across them. None when every term has one and the same sign on every
    // gap and one term has no event inside (no zero there either); one when
    // every term is strictly monotone one way on every gap, and so on the
    // interval, with a simple zero if one term's derivative never vanishes
    // there (a collocated one, or one with no event inside).
    let cap_between = |from: usize, to: usize, passed: &[usize]| -> Option<u32> {
        let free_inside = |k: usize| passed.iter().all(|&j| order[j].0 != k);
        if blocks.len() == 2 && (free_inside(0) || free_inside(1)) {
            let first = term_sign(from, 0);
            if first.is_some()
                && (from..=to).all(|i| term_sign(i, 0) == first && term_sign(i, 1) == first)
            {
                return Some(0);
            }
        }
        let strict = (0..blocks.len()).any(|k| blocks[k].collocated != 0 || free_inside(k));
        let first = direction(from, 0);
        if strict
            && first.is_some()
            && (from..=to).all(|i| (0..blocks.len()).all(|k| direction(i, k) == first))
        {
            return Some(1);
        }
        None
    };
    let mut samples: Vec<CheckSample> = Vec::new();
    // Where the poles that stay are: the type's resonances.
    let mut resonances: Vec<usize> = Vec::new();
    // Where the open interval from the last sample starts (the gap below
    // that event), the events since then that gave no sample, and whether
    // one of them is a pole of a term (a double cancellation).
    let mut open: Option<usize> = None;
    let mut passed: Vec<usize> = Vec::new();
    let mut pole_inside = false;
    if !exact {
        let odd = cancel.iter().filter(|&&(_, k)| k % 2 == 1).count();
        samples.push(CheckSample::Sign(at_zero * sgn(odd)));
        open = Some(0);
    }
    for (i, (k, e)) in order.iter().enumerate() {
        if partner(i) {
            continue;
        }
        let before = samples.len();
        let width = if shared.iter().any(|&(j, _)| j == i) {
            2
        } else {
            1
        };
        let mut mark = |samples: &mut Vec<CheckSample>| {
            if samples.len() > before {
                let cap = match open {
                    Some(from) if !exact && !pole_inside => cap_between(from, i, &passed),
                    _ => None,
                };
                if let Some(z) = cap {
                    samples.insert(before, CheckSample::Cap(z));
                }
                open = Some(i + width);
                passed.clear();
                pole_inside = false;
            } else {
                passed.push(i);
                pole_inside |= width == 2;
            }
        };
        if let Some(&(_, double)) = shared.iter().find(|&&(j, _)| j == i) {
            if !double {
                samples.push(CheckSample::Pole(shared_pole_sign(i)));
                resonances.push(i);
            }
            mark(&mut samples);
            continue;
        }
        match e {
            CheckEvent::Pole { on, n_sign, .. } => {
                if exact {
                    if on.is_empty() {
                        samples.push(CheckSample::Pole(None));
                    } else {
                        let z: u32 = on.iter().map(|&r| blocks[*k].runs[r].exponent).sum();
                        if z > 1 {
                            samples.push(CheckSample::Zeros(z - 1));
                        }
                    }
                } else if on.is_empty() {
                    let mut s = minus_c * n_sign;
                    for (o, b) in blocks.iter().enumerate() {
                        if o != *k {
                            s *= b.lead * sgn(poles_after(i, o));
                        }
                    }
                    samples.push(CheckSample::Pole(Some(reduced(i, s))));
                    resonances.push(i);
                }
                mark(&mut samples);
            }
            CheckEvent::Eig { run } => {
                if exact {
                    samples.push(CheckSample::Zeros(blocks[*k].runs[*run].exponent));
                    continue;
                }
                // n_B = 0 here: num = -c * p_B * n_B' up to powers of Omega.
                let o = 1 - *k;
                let other = &blocks[o];
                // Past this block's own eigenvalues on either side: the
                // other block's eigenvalue, a cancelled pole of it or a
                // shared pole may coincide with this point, where the
                // numerator's order of vanishing is unknown.
                let is_own_eig =
                    |j: usize| order[j].0 == *k && matches!(order[j].1, CheckEvent::Eig { .. });
                let may_vanish = |j: usize| -> bool {
                    let shared_here = shared.iter().any(|&(s, _)| s == j || s + 1 == j);
                    shared_here
                        || (order[j].0 == o
                            && match &order[j].1 {
                                CheckEvent::Eig { .. } => true,
                                CheckEvent::Pole { on, .. } => !on.is_empty(),
                            })
                };
                let after = (i + 1..order.len()).find(|&j| !is_own_eig(j));
                let before = (0..i).rev().find(|&j| !is_own_eig(j));
                if !other.direct || after.is_some_and(may_vanish) || before.is_some_and(may_vanish)
                {
                    mark(&mut samples);
                    continue;
                }
                let mut n_other = other.base;
                for (r, run) in other.runs.iter().enumerate() {
                    if run.exponent % 2 == 1 {
                        n_other *= run.sign * sgn(eigs_before(i, o, r));
                    }
                }
                let s = minus_c * blocks[*k].lead * sgn(poles_after(i, *k)) * n_other;
                samples.push(CheckSample::Sign(reduced(i, s)));
                mark(&mut samples);
            }
        }
    }
    if !exact {
        if let (Some(from), false) = (open, pole_inside) {
            if let Some(z) = cap_between(from, order.len(), &passed) {
                samples.push(CheckSample::Cap(z));
            }
        }
        samples.push(CheckSample::Sign(at_inf));
    }
    if exact {
        let mut got = vec![0u32];
        for s in &samples {
            match s {
                CheckSample::Pole(_) => got.push(0),
                CheckSample::Zeros(z) => *got.last_mut().expect("one") += z,
                CheckSample::Sign(_) | CheckSample::Cap(_) => {}
            }
        }
        return got == counts;
    }
    // Spread each interval's antiresonances over the gaps between samples
    // (searching gap by gap, a multiple zero whole into one gap), with an
    // odd number between two known signs exactly where the sign changes.
    let n_poles = samples
        .iter()
        .filter(|s| matches!(s, CheckSample::Pole(_)))
        .count();
    if n_poles + 1 != counts.len() {
        return false;
    }
    if blocks.len() == 2 && !rolle_allows(blocks, order, shared, &resonances, counts) {
        return false;
    }
    // `next`: the first zero of the interval not yet placed.
    #[allow(clippy::too_many_arguments)]
    fn spread(
        samples: &[CheckSample],
        points: &[Vec<u32>],
        i: usize,
        interval: usize,
        next: usize,
        zeros_since: u32,
        last: i64,
        cap: Option<u32>,
    ) -> bool {
        let all = |interval: usize| points.get(interval).map_or(0, Vec::len);
        if i == samples.len() {
            return interval + 1 == points.len() && next == all(interval);
        }
        if let CheckSample::Cap(z) = samples[i] {
            return spread(
                samples,
                points,
                i + 1,
                interval,
                next,
                zeros_since,
                last,
                Some(z),
            );
        }
        let rest = &points[interval][next..];
        (0..=rest.len()).any(|j| {
            let z: u32 = rest[..j].iter().sum();
            if cap.is_some_and(|c| z > c) {
                return false;
            }
            let next = next + j;
            let since = zeros_since + z;
            let (since, last) = match samples[i] {
                CheckSample::Sign(x) | CheckSample::Pole(Some(x)) => {
                    if (x != last) != (since % 2 == 1) {
                        return false;
                    }
                    (0, x)
                }
                _ => (since, last),
            };
            match samples[i] {
                CheckSample::Pole(_) => {
                    next == all(interval)
                        && interval + 1 < points.len()
                        && spread(samples, points, i + 1, interval + 1, 0, since, last, None)
                }
                _ => spread(samples, points, i + 1, interval, next, since, last, None),
            }
        })
    }
    match samples[0] {
        CheckSample::Sign(first) => spread(&samples, points, 1, 0, 0, 0, first, None),
        _ => false,
    }
}

/// Rolle's bound on the zeros between two resonances (or `0`, or
/// infinity): the positive zeros of the numerator are those of `n_0 d_1 +
/// n_1 d_0`. If one of the two products has degree below `k`, the `k`-th
/// derivative of the sum is that of the other, `P`, whose roots are
/// events of the order (the poles of its `d`, `0` for a free block, the
/// runs' eigenvalues of its `n` when those give all of `n`'s zeros, `0` as
/// often as `Omega` divides `n`); between two of its roots `x_i <=
/// x_(i+k)` lies the `i`-th root of `P^(k)`, and an open interval holds at
/// most `k` zeros more than the `k`-th derivative has there. With the
/// other product of degree exactly `k - 1`, the `(k-1)`-th derivative is
/// `P^(k-1)` plus a constant: no zero where the two have one sign. The
/// same for the reversed polynomials, whose zeros are the inverses.
///
/// Also for the sum divided by `Omega - lambda` at each pole `lambda` two
/// blocks share: it divides both products (each holds one block's `d`),
/// so the lower product's degree and `k` drop by one per shared pole and
/// `P` keeps its other roots; where such a pole cancels twice the
/// quotient vanishes there besides the type's zeros.
fn rolle_allows(
    blocks: &[CheckBlock],
    order: &[(usize, CheckEvent)],
    shared: &[(usize, bool)],
    resonances: &[usize],
    counts: &[u32],
) -> bool {
    rolle_allows_on(blocks, order, shared, resonances, counts, false)
        && (shared.is_empty() || rolle_allows_on(blocks, order, shared, resonances, counts, true))
}

/// [`rolle_allows`] on the sum itself or, `divided`, on its quotient by
/// the shared poles' factors.
fn rolle_allows_on(
    blocks: &[CheckBlock],
    order: &[(usize, CheckEvent)],
    shared: &[(usize, bool)],
    resonances: &[usize],
    counts: &[u32],
    divided: bool,
) -> bool {
    // A coincident pair is one point: its second event takes the first's
    // place. Places are shifted by one so that 0 is Omega = 0.
    let place = |i: usize| {
        if shared.iter().any(|&(j, _)| j + 1 == i) {
            i
        } else {
            i + 1
        }
    };
    let infinity = order.len() + 1;
    let mut bounds: Vec<usize> = vec![0];
    bounds.extend(resonances.iter().map(|&i| place(i)));
    bounds.push(infinity);
    for low in 0..2 {
        // `low` contributes n_low d_high, of degree below k; P = n_high d_low.
        let high = 1 - low;
        let (bl, bh) = (&blocks[low], &blocks[high]);
        if !bh.direct {
            continue;
        }
        let cut = if divided { shared.len() } else { 0 };
        let Some(k) = (bl.degree as usize + bh.size + 1).checked_sub(cut) else {
            continue;
        };
        let in_pair = |i: usize| shared.iter().any(|&(j, _)| i == j || i == j + 1);
        let mut roots: Vec<usize> = vec![0; bh.omega_power as usize + usize::from(bl.free)];
        for (i, (b, e)) in order.iter().enumerate() {
            match e {
                CheckEvent::Pole { on, .. } => {
                    if *b == low {
                        if !(divided && in_pair(i)) {
                            roots.push(place(i));
                        }
                    } else {
                        for &r in on {
                            for _ in 0..bh.runs[r].exponent {
                                roots.push(place(i));
                            }
                        }
                    }
                }
                CheckEvent::Eig { run } => {
                    if *b == high {
                        for _ in 0..bh.runs[*run].exponent {
                            roots.push(place(i));
                        }
                    }
                }
            }
        }
        let Some(degree) = (bh.degree as usize + bl.size).checked_sub(cut) else {
            continue;
        };
        if roots.len() != degree || k == 0 || k > degree {
            continue;
        }
        roots.sort_unstable();
        // The lower product A = n_low d_high has degree k - 1 and at least
        // `za` roots at 0; P's leading and lowest signs, and A's.
        let sign_at_zero = |b: &CheckBlock| b.lead * (-1i64).pow((b.pole_count() % 2) as u32);
        let signs = bl.n_lead.zip(bl.n_low).zip(bh.n_lead.zip(bh.n_low));
        let za = bl.omega_power as usize + usize::from(bh.free);
        // P's nonzero roots, largest first: the roots of u^degree P(1/u)
        // are their inverses, in increasing order.
        let inverted: Vec<usize> = roots.iter().rev().copied().filter(|&r| r > 0).collect();
        // The reversed A part's degree, where it is below the reversed P's.
        let reversed = (za + inverted.len() > degree).then(|| degree - za);
        for from in 0..bounds.len() {
            for to in from + 1..bounds.len() {
                let (lo, hi) = (bounds[from], bounds[to]);
                let mut zeros = counts[from..to].iter().sum::<u32>() as usize;
                if divided {
                    // The quotient's own zero at a pole cancelled twice.
                    zeros += shared
                        .iter()
                        .filter(|&&(j, twice)| twice && lo < j + 1 && j + 1 < hi)
                        .count();
                }
                // E^(k) = P^(k): its i-th root lies between P's i-th and
                // (i + k)-th.
                if k < degree {
                    let derivative_roots = (0..degree - k)
                        .filter(|&i| roots[i] < hi && roots[i + k] > lo)
                        .count();
                    if zeros > k + derivative_roots {
                        return false;
                    }
                }
                let Some(((low_lead, low_low), (high_lead, high_low))) = signs else {
                    continue;
                };
                // E^(k-1) = P^(k-1) + a constant of A's leading sign: no
                // zero where P^(k-1) has that sign throughout.
                let j = k - 1;
                let clear = (0..degree - j).all(|i| roots[i + j] <= lo || roots[i] >= hi);
                if clear {
                    let above = (0..degree - j).filter(|&i| roots[i] >= hi).count();
                    let p_sign = high_lead * bl.lead * (-1i64).pow((above % 2) as u32);
                    if p_sign == low_lead * bh.lead && zeros > j {
                        return false;
                    }
                }
                // The same for u^degree E(1/u) on (1/hi, 1/lo), where A's
                // part has degree degree - za, below P's when za exceeds
                // P's roots at 0; leading signs those at 0+.
                let Some(j) = reversed else { continue };
                let n = inverted.len();
                let clear = (0..n - j).all(|i| inverted[i] <= lo || inverted[i + j] >= hi);
                if clear {
                    let below = (0..n - j).filter(|&i| inverted[i] <= lo).count();
                    let p_sign = high_low * sign_at_zero(bl) * (-1i64).pow((below % 2) as u32);
                    if p_sign == low_low * sign_at_zero(bh) && zeros > j {
                        return false;
                    }
                }
                let derivative_roots = (0..n.saturating_sub(j + 1))
                    .filter(|&i| inverted[i] > lo && inverted[i + j + 1] < hi)
                    .count();
                if zeros > j + 1 + derivative_roots {
                    return false;
                }
            }
        }
    }
    true
}

fn positive_by(g: &Poly, d: &Value, jp: &str, depth: usize) -> Result<(), String> {
    if depth > MAX_DEFINITENESS_DEPTH {
        return Err("definiteness nested too deeply".into());
    }
    match str_field(d, "method", jp)? {
        "no_subtraction" => {
            if !g.all_coefs_positive() {
                return Err(format!(
                    "no_subtraction: {g} does not have all coefficients positive"
                ));
            }
        }
        "polya" => {
            let power = uint_field(d, "power", jp)?;
            let affine = bool_field(d, "affine", jp)?;
            if power > MAX_POLYA_POWER {
                return Err(format!("polya: power {power} is too large"));
            }
            let mut sum = if affine { Poly::one() } else { Poly::zero() };
            for v in g.vars() {
                sum = &sum + &Poly::var(v);
            }
            let product = &sum.pow(power as u32) * g;
            if !product.all_coefs_positive() {
                return Err(format!(
                    "polya: ({sum})^{power} * ({g}) does not have all coefficients positive"
                ));
            }
        }
        "completed_square" => {
            let var = str_field(d, "var", jp)?;
            if g.degree(var) != 2 {
                return Err(format!("completed_square: {g} is not of degree 2 in {var}"));
            }
            let c = g.coeffs_in(var);
            if !c[2].all_coefs_positive() {
                return Err(format!(
                    "completed_square: the coefficient {} of {var}^2 does not have all coefficients positive",
                    c[2]
                ));
            }
            let inner = &(&c[2] * &c[0]).scale(&Rat::from(4)) - &(&c[1] * &c[1]);
            positive_by(
                &inner,
                field(d, "inner", jp)?,
                &format!("{jp}.inner"),
                depth + 1,
            )?;
        }
        other => return Err(format!("unknown definiteness method {other:?}")),
    }
    Ok(())
}

/// Whether the multiplicities of `t` can be those of the open part of `s`.
fn multiplicities_fit(s: &Stratum, t: &Ty) -> bool {
    let side = |num: bool| -> Vec<u32> {
        let mut v: Vec<u32> = s
            .parts
            .iter()
            .filter(|p| p.num == num)
            .flat_map(|p| std::iter::repeat_n(p.mult, p.poly.degree(OMEGA) as usize))
            .collect();
        v.sort_unstable();
        v
    };
    let mut have: Vec<u32> = t.toks.iter().filter(|k| !k.zero).map(|k| k.mult).collect();
    have.sort_unstable();
    if have != side(false) {
        return false;
    }
    let mut avail = side(true);
    let total = avail.len();
    for k in t.toks.iter().filter(|k| k.zero) {
        match avail.iter().position(|m| *m == k.mult) {
            Some(i) => {
                avail.remove(i);
            }
            None => return false,
        }
    }
    let used = total - avail.len();
    if t.nm {
        used < total
    } else {
        used == total
    }
}

fn check_descartes(open: &Value, jp: &str, s: &Stratum, t: &Ty) -> Result<(), String> {
    let given = poly_field(open, "part", jp)?;
    let part = s
        .parts
        .iter()
        .find(|p| p.num && proportional(&p.poly, &given))
        .ok_or_else(|| format!("descartes: {given} is not a numerator part of the stratum"))?;
    if s.parts
        .iter()
        .filter(|p| p.num && p.mult == part.mult)
        .count()
        != 1
    {
        return Err(format!(
            "descartes: {given} is not the only numerator part of multiplicity {}",
            part.mult
        ));
    }
    let mut signs = Vec::new();
    for (k, c) in part.poly.coeffs_in(OMEGA).iter().enumerate() {
        if c.is_zero() {
            continue;
        }
        signs.push(c.orthant_sign().map(i64::from).ok_or_else(|| {
            format!("descartes: the coefficient of Omega^{k} ({c}) has no fixed sign")
        })?);
    }
    let v = signs.windows(2).filter(|w| w[0] != w[1]).count() as u64;
    let needed = t
        .toks
        .iter()
        .filter(|k| k.zero && k.mult == part.mult)
        .count() as u64;
    let (fv, fneeded) = (
        uint_field(open, "sign_changes", jp)?,
        uint_field(open, "needed", jp)?,
    );
    if fv != v || fneeded != needed {
        return Err(format!(
            "descartes: the file says {fv} sign changes and {fneeded} needed, recomputed {v} and {needed}"
        ));
    }
    if needed <= v && (v - needed).is_multiple_of(2) {
        return Err(format!(
            "descartes: {needed} positive zeros are consistent with {v} sign changes"
        ));
    }
    Ok(())
}

/// The linear parts' data for the sign conditions: `(b, a, sign of a)` of
/// `a*Omega + b`, side and multiplicity.
struct Linear {
    a: Poly,
    b: Poly,
    sa: i64,
    num: bool,
    mult: u32,
}

/// Every assignment of the linear parts to the tokens of `t`.
fn assignments(lin: &[Linear], t: &Ty) -> Vec<Vec<Option<usize>>> {
    let mut acc: Vec<Vec<Option<usize>>> = vec![Vec::new()];
    for l in lin {
        let mut next = Vec::new();
        for a in &acc {
            for (i, k) in t.toks.iter().enumerate() {
                if k.zero == l.num && k.mult == l.mult && !a.contains(&Some(i)) {
                    let mut b = a.clone();
                    b.push(Some(i));
                    next.push(b);
                }
            }
            if l.num && t.nm {
                let mut b = a.clone();
                b.push(None);
                next.push(b);
            }
        }
        acc = next;
    }
    acc
}

fn assignment_text(a: &[Option<usize>]) -> String {
    let items: Vec<String> = a
        .iter()
        .map(|x| x.map_or("null".to_string(), |i| i.to_string()))
        .collect();
    format!("[{}]", items.join(", "))
}

fn check_sign_conditions(open: &Value, jp: &str, s: &Stratum, t: &Ty) -> Result<(), String> {
    let given = polys_field(open, "linear_parts", jp)?;
    let parts = s.linear_parts();
    let recomputed: Vec<&Poly> = parts.iter().map(|p| &p.poly).collect();
    if given.len() != parts.len() || given.iter().zip(&recomputed).any(|(g, r)| g != *r) {
        return Err(format!(
            "sign_conditions: linear_parts {:?}, recomputed {:?}",
            given.iter().map(|p| p.to_string()).collect::<Vec<_>>(),
            recomputed.iter().map(|p| p.to_string()).collect::<Vec<_>>()
        ));
    }
    if t.resonances() != s.den_degree {
        return Err(format!(
            "sign_conditions: the type has {} resonances, the stratum's denominator degree is {}",
            t.resonances(),
            s.den_degree
        ));
    }
    let mut lin = Vec::new();
    for p in &parts {
        let c = p.poly.coeffs_in(OMEGA);
        let sa = c[1].orthant_sign().map(i64::from).ok_or_else(|| {
            format!(
                "sign_conditions: the leading coefficient of linear part {} has no fixed sign",
                p.poly
            )
        })?;
        lin.push(Linear {
            a: c[1].clone(),
            b: c[0].clone(),
            sa,
            num: p.num,
            mult: p.mult,
        });
    }
    let expected = assignments(&lin, t);
    let cases = arr_field(open, "cases", jp)?;
    let mut seen: Vec<Vec<Option<usize>>> = Vec::new();
    for (ci, case) in cases.iter().enumerate() {
        let cp = format!("{jp}.cases[{ci}]");
        let a: Vec<Option<usize>> = arr_field(case, "assignment", &cp)?
            .iter()
            .map(|x| match x {
                Value::Null => Ok(None),
                _ => x
                    .as_u64()
                    .map(|i| Some(index(i)))
                    .ok_or_else(|| format!("{cp}.assignment: expected token indices or null")),
            })
            .collect::<Result<_, _>>()?;
        let name = assignment_text(&a);
        if !expected.contains(&a) {
            return Err(format!("sign_conditions case {name}: not an assignment of the linear parts to the type's tokens"));
        }
        if seen.contains(&a) {
            return Err(format!("sign_conditions case {name}: listed twice"));
        }
        check_case(case, &cp, s, t, &lin, &a)
            .map_err(|e| format!("sign_conditions case {name}: {e}"))?;
        seen.push(a);
    }
    if let Some(missing) = expected.iter().find(|a| !seen.contains(a)) {
        return Err(format!(
            "sign_conditions: the assignment {} has no case",
            assignment_text(missing)
        ));
    }
    Ok(())
}

fn check_case(
    case: &Value,
    cp: &str,
    s: &Stratum,
    t: &Ty,
    lin: &[Linear],
    a: &[Option<usize>],
) -> Result<(), String> {
    let conditions = arr_field(case, "conditions", cp)?;
    let multipliers = polys_field(case, "multipliers", cp)?;
    if multipliers.len() != conditions.len() {
        return Err(format!(
            "{} multipliers for {} conditions",
            multipliers.len(),
            conditions.len()
        ));
    }
    let taken: BTreeSet<usize> = a.iter().flatten().copied().collect();
    let mut reduced_all = Vec::new();
    let mut strict_all = Vec::new();
    for (i, c) in conditions.iter().enumerate() {
        let path = format!("{cp}.conditions[{i}]");
        let step = |m: String| format!("condition {i}: {m}");
        let rule = field(c, "rule", &path).map_err(step)?;
        let rp = format!("{path}.rule");
        let kind = str_field(rule, "rule", &rp).map_err(step)?;
        let strict = bool_field(c, "strict", &path).map_err(step)?;
        let derived = poly_field(c, "derived", &path).map_err(step)?;
        let square = poly_field(c, "square", &path).map_err(step)?;
        let positive = poly_field(c, "positive", &path).map_err(step)?;
        let reduced = poly_field(c, "reduced", &path).map_err(step)?;
        let part = |key: &str| -> Result<usize, String> {
            let i = index(uint_field(rule, key, &rp)?);
            if i >= lin.len() {
                return Err(format!("{rp}.{key}: no linear part {i}"));
            }
            Ok(i)
        };
        let assigned = |i: usize| -> Result<usize, String> {
            a[i].ok_or_else(|| format!("linear part {i} takes no token in this case"))
        };
        let expect: Poly = match kind {
            "root_positive" => {
                let p = part("part").map_err(step)?;
                assigned(p).map_err(step)?;
                (-lin[p].b.clone()).scale(&Rat::from(lin[p].sa))
            }
            "root_not_positive" => {
                let p = part("part").map_err(step)?;
                if a[p].is_some() {
                    return Err(step(format!("linear part {p} takes a token in this case")));
                }
                if strict {
                    return Err(step("root_not_positive cannot be strict".into()));
                }
                lin[p].b.scale(&Rat::from(lin[p].sa))
            }
            "root_order" => {
                let (l, u) = (part("lower").map_err(step)?, part("upper").map_err(step)?);
                let (tl, tu) = (assigned(l).map_err(step)?, assigned(u).map_err(step)?);
                if tl >= tu {
                    return Err(step(format!(
                        "part {l} takes token {tl}, not below token {tu} of part {u}"
                    )));
                }
                let (pl, pu) = (&lin[l], &lin[u]);
                (&(&pl.b * &pu.a) - &(&pu.b * &pl.a)).scale(&Rat::from(pl.sa * pu.sa))
            }
            "sign_at" => {
                let other = poly_field(rule, "other", &rp).map_err(step)?;
                let p = part("part").map_err(step)?;
                let k = uint_field(rule, "derivative", &rp).map_err(step)?;
                let above_claim = uint_field(rule, "roots_above", &rp).map_err(step)?;
                let ti = assigned(p).map_err(step)?;
                let op = s.unique_nonlinear(&other).map_err(step)?;
                let d = other.degree(OMEGA) as u64;
                if k >= d {
                    return Err(step(format!(
                        "derivative {k} of a polynomial of degree {d}"
                    )));
                }
                let slots: Vec<usize> = (0..t.toks.len())
                    .filter(|i| {
                        t.toks[*i].zero == op.num
                            && t.toks[*i].mult == op.mult
                            && !taken.contains(i)
                    })
                    .collect();
                let above = slots.iter().filter(|&&j| j > ti).count() as u64;
                if above != above_claim {
                    return Err(step(format!(
                        "roots_above is {above_claim}, the type gives {above}"
                    )));
                }
                let sl = other
                    .lead_in(OMEGA)
                    .orthant_sign()
                    .map(i64::from)
                    .ok_or_else(|| {
                        step(format!(
                            "the leading coefficient of {other} has no fixed sign"
                        ))
                    })?;
                let want = if k == 0 {
                    sl * if above.is_multiple_of(2) { 1 } else { -1 }
                } else {
                    if slots.len() as u64 != d {
                        return Err(step(format!(
                            "derivative {k}: not all {d} roots of {other} are tokens"
                        )));
                    }
                    if above == d {
                        sl * if (d - k).is_multiple_of(2) { 1 } else { -1 }
                    } else if above == 0 {
                        sl
                    } else {
                        return Err(step(format!(
                            "derivative {k}: the root is neither below nor above all roots of {other}"
                        )));
                    }
                };
                let mut q = other.clone();
                for _ in 0..k {
                    q = q.derivative(OMEGA);
                }
                let e = (d - k) as u32;
                let l = &lin[p];
                let minus_b = -l.b.clone();
                let mut value = Poly::zero();
                for (j, qj) in q.coeffs_in(OMEGA).iter().enumerate() {
                    if qj.is_zero() {
                        continue;
                    }
                    let j = j as u32;
                    value = &value + &(&(qj * &minus_b.pow(j)) * &l.a.pow(e - j));
                }
                let sgn = want * if e.is_multiple_of(2) { 1 } else { l.sa };
                value.scale(&Rat::from(sgn))
            }
            "real_roots" => {
                let other = poly_field(rule, "other", &rp).map_err(step)?;
                let op = s.unique_nonlinear(&other).map_err(step)?;
                let d = other.degree(OMEGA) as usize;
                let slots = (0..t.toks.len())
                    .filter(|i| {
                        t.toks[*i].zero == op.num
                            && t.toks[*i].mult == op.mult
                            && !taken.contains(i)
                    })
                    .count();
                if slots != d {
                    return Err(step(format!(
                        "real_roots: {slots} tokens for the {d} roots of {other}"
                    )));
                }
                let disc = discriminant_of(&other).map_err(step)?;
                match ratio(&derived, &disc) {
                    Some(c) if c.signum() > 0 => derived.clone(),
                    _ => {
                        return Err(step(format!(
                        "derived {derived} is not a positive multiple of the discriminant {disc}"
                    )))
                    }
                }
            }
            other => return Err(step(format!("unknown rule {other:?}"))),
        };
        if derived != expect {
            return Err(step(format!(
                "{kind}: derived is {derived}, the rule gives {expect}"
            )));
        }
        if square.is_zero() {
            return Err(step("square is zero".into()));
        }
        if !positive.all_coefs_positive() {
            return Err(step(format!(
                "positive = {positive} does not have all coefficients positive"
            )));
        }
        if &(&(&square * &square) * &positive) * &reduced != derived {
            return Err(step("derived != square^2 * positive * reduced".into()));
        }
        reduced_all.push(reduced);
        strict_all.push(strict);
    }
    let mut combination = Poly::zero();
    let mut strict_used = false;
    for (i, m) in multipliers.iter().enumerate() {
        if !nonnegative_coefs(m) {
            return Err(format!("multiplier {i} ({m}) has a negative coefficient"));
        }
        if let Some(v) = m.vars().iter().find(|v| !s.vars.contains(v)) {
            return Err(format!(
                "multiplier {i} ({m}) involves {v}, which is not a parameter of the stratum"
            ));
        }
        if !m.is_zero() && strict_all[i] {
            strict_used = true;
        }
        combination = &combination + &(m * &reduced_all[i]);
    }
    if !strict_used {
        return Err("no strict condition has a nonzero multiplier".into());
    }
    if combination.terms().iter().any(|t| t.coef.signum() > 0) {
        return Err(format!(
            "combination has a positive coefficient: {combination}"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checker's own enumeration of the types a TF can show a priori
    /// against the prover's (`candidate_types`): the same set, reached by
    /// another route (runs chosen one at a time, not compositions merged).
    #[test]
    fn a_priori_types_match_the_provers_candidates() {
        for a in 0..5 {
            for r in 1..6 {
                let mut ours: Vec<String> =
                    a_priori_types(a, r).iter().map(Ty::to_string).collect();
                let mut theirs: Vec<String> = crate::analysis::candidate_types(a, r)
                    .iter()
                    .map(|t| t.to_string())
                    .collect();
                ours.sort();
                theirs.sort();
                assert_eq!(ours, theirs, "a = {a}, r = {r}");
            }
        }
    }

    /// The checker's forward enumeration of what a generic type's roots
    /// gather into against the prover's recursion, which matches one
    /// wanted type: the same answer for every generic type and candidate
    /// of the degrees up to 4 and 4.
    #[test]
    fn limit_images_match_the_provers_recursion() {
        for a in 0..=4 {
            for r in 1..=4 {
                let all = a_priori_types(a, r);
                for g in all
                    .iter()
                    .filter(|g| g.resonances() == r && g.toks.iter().all(|k| k.mult == 1))
                {
                    let images = limit_images(g, a);
                    let gp: crate::analysis::FrfType = g.to_string().parse().unwrap();
                    for x in &all {
                        let xp: crate::analysis::FrfType = x.to_string().parse().unwrap();
                        assert_eq!(
                            crate::analysis::gathers_into(&gp, &xp, a, r),
                            images.contains(x),
                            "{g} -> {x} (a = {a}, r = {r})"
                        );
                    }
                }
            }
        }
    }

    /// N4-g0-a1.0-s2.0 with every non-generic impossible type left open
    /// and given to the limits rule: the table with its certificates, and
    /// the pointers (type index) of those it certified.
    fn limits_table() -> (Value, Vec<usize>) {
        use crate::analysis::{analyze, limits_of_generic_types, SearchLimits, Status};
        use crate::table::{AnalysisTable, Covers, TableModel};
        let m = Model::from_id("N4-g0-a1.0-s2.0").unwrap();
        let mut a = analyze(&m, &SearchLimits::default());
        let r = a.denominator.degree(OMEGA);
        for v in a.types.iter_mut() {
            if v.status == Status::Impossible && !v.frf_type.is_generic(r) {
                v.status = Status::Unknown;
                v.certificate = None;
            }
        }
        let a = limits_of_generic_types(&m, a);
        let table =
            AnalysisTable::new(Covers::Models(vec![m.id()]), vec![TableModel::new(a)]).to_value();
        let certified: Vec<usize> = table["models"][0]["types"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .filter(|(_, v)| v["certificate"]["open"]["kind"] == "limits")
            .map(|(i, _)| i)
            .collect();
        (table, certified)
    }

    #[test]
    fn limits_of_generic_types_are_checked_and_forgeries_refused() {
        let (table, certified) = limits_table();
        assert!(certified.len() > 10, "{}", certified.len());
        let report = check_file(&table.to_string()).unwrap_or_else(|e| panic!("{e}"));
        assert!(report.certificates >= certified.len());
        let types = |v: &Value| v["models"][0]["types"].as_array().unwrap().clone();
        let first = certified[0];
        let refused = |v: Value, what: &str| {
            let e = check_file(&v.to_string()).expect_err(what).to_string();
            assert!(e.contains("limits: "), "{what}: {e}");
            e
        };
        // A generic type dropped from the list.
        let mut v = table.clone();
        v["models"][0]["types"][first]["certificate"]["open"]["generic"]
            .as_array_mut()
            .unwrap()
            .pop();
        assert!(refused(v, "a generic type unlisted").contains("is not listed"));
        // The certificate moved to a type with a witness that is not generic.
        let ts = types(&table);
        let r = ts
            .iter()
            .map(|v| Ty::parse(v["type"].as_str().unwrap()).unwrap().resonances())
            .max()
            .unwrap();
        let witnessed = ts
            .iter()
            .position(|v| {
                v["status"] == "possible" && {
                    let t = Ty::parse(v["type"].as_str().unwrap()).unwrap();
                    t.toks.iter().any(|k| k.mult > 1) || t.resonances() < r
                }
            })
            .expect("a non-generic possible type");
        let mut v = table.clone();
        let cert = ts[first]["certificate"].clone();
        let w = &mut v["models"][0]["types"][witnessed];
        w["status"] = "impossible".into();
        w.as_object_mut().unwrap().remove("witness");
        w["certificate"] = cert.clone();
        refused(v, "a limit certificate on a witnessed type");
        // On a generic type.
        let generic = ts
            .iter()
            .position(|v| {
                v["status"] == "impossible" && {
                    let t = Ty::parse(v["type"].as_str().unwrap()).unwrap();
                    t.toks.iter().all(|k| k.mult == 1) && t.resonances() == r
                }
            })
            .unwrap();
        let mut v = table.clone();
        v["models"][0]["types"][generic]["certificate"] = cert.clone();
        assert!(refused(v, "on a generic type").contains("is generic"));
        // With more than the whole orthant's claim.
        let mut v = table.clone();
        v["models"][0]["types"][first]["certificate"]["unlisted"] = "needs_cancellation".into();
        assert!(refused(v, "with unlisted factors").contains("whole orthant alone"));
    }

    /// The interpolated Sylvester determinant of polynomials in `Omega`
    /// and `s` against the expansion of the same matrix over polynomial
    /// entries (poly's `det`), and against the resultant of two products
    /// of linear factors, `prod (a_i - b_j)` up to the leading terms.
    #[test]
    fn interpolated_resultants_match_the_expansion() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        let pairs = [
            (
                "(1/3*s^2 + 2)*Omega^3 - s*Omega + 7/2",
                "(s - 5)*Omega^2 + 3*s^3*Omega - 1/7",
            ),
            ("Omega^2 - 2*(2 - s)*Omega + 3", "2*Omega - 2*(2 - s)"),
            ("s^4*Omega^2 + Omega + s", "Omega^3 - s^2"),
        ];
        for (a, b) in pairs {
            let (a, b) = (p(a), p(b));
            let m = sylvester_matrix(&a, &b, OMEGA);
            assert_eq!(interpolated_det(&m, "s"), det(&m), "{a}, {b}");
        }
        // (Omega - s)(Omega - 2) and (Omega - 3 s): (s - 3 s)(2 - 3 s).
        let r = sylvester_resultant(&p("(Omega - s)*(Omega - 2)"), &p("Omega - 3*s"));
        assert_eq!(r, p("(s - 3*s)*(2 - 3*s)"));
        assert_eq!(integer_det(vec![]), Int::from(1));
    }
}
