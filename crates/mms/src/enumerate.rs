//! Enumeration of models (Sec. 2, Tab. 1 of the paper) and their
//! equivalence classes under renumbering of the masses.
//!
//! A renumbering relabels the masses (the ground stays 0) and carries the
//! springs, the actuator and the sensor along; two models are equivalent
//! when one is a renumbering of the other ([`Model::renumber`]). A
//! renumbering must map the grounded part `0 - 1 - ... - gap` (a path ending
//! in the fixed ground) onto itself, so it is the identity there, and it maps
//! the free part `gap+1 - ... - N` (a path) onto itself, so it is the
//! identity or the reversal ([`Model::mirrored`]). With `gap = 0` the free
//! part is the whole chain. Every class thus has one or two members.
//!
//! The paper's rule (3) is meant to pick one model per class, but it does
//! not: its first condition `n_act+ <= n_meas+` removes models whose
//! *reciprocal* (actuator and sensor swapped) is kept, which is not a
//! renumbering. See [`redundancy_report`].

use crate::model::{check_n, Model, ModelError, Port};
use serde::Serialize;
use std::collections::BTreeMap;

/// Which identifications define the classes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Symmetry {
    /// Renumbering of masses only (the paper's definition of redundancy).
    Renumbering,
    /// Renumbering and, in addition, swapping actuator and sensor (which
    /// leaves the transfer function unchanged by reciprocity).
    RenumberingAndReciprocity,
}

/// All models satisfying rule (1), in [`Model`] order.
///
/// ```
/// assert_eq!(mms::basic_models(3).unwrap().len(), 34); // Tab. 1
/// ```
pub fn basic_models(n: usize) -> Result<Vec<Model>, ModelError> {
    check_n(n)?;
    let mut out = Vec::new();
    for gap in 0..n {
        for ap in gap + 1..=n {
            for am in 0..=gap {
                for sp in gap + 1..=n {
                    for sm in 0..=gap {
                        out.push(Model::new(n, gap, Port::new(ap, am), Port::new(sp, sm))?);
                    }
                }
            }
        }
    }
    Ok(out)
}

/// Models satisfying rules (1) and (2).
///
/// ```
/// assert_eq!(mms::degradation_free_models(3).unwrap().len(), 17); // Tab. 1
/// ```
pub fn degradation_free_models(n: usize) -> Result<Vec<Model>, ModelError> {
    Ok(basic_models(n)?
        .into_iter()
        .filter(Model::is_degradation_free)
        .collect())
}

/// Models satisfying rules (1), (2) and (3): the paper's set (11 for `N = 3`).
///
/// ```
/// let ids: Vec<_> = mms::rule3_models(3).unwrap().iter().map(|m| m.name()).collect();
/// assert_eq!(ids, ["A1", "A2", "A3", "A4", "A5", "B1", "B2", "C1", "C2", "C4", "C3"]);
/// ```
pub fn rule3_models(n: usize) -> Result<Vec<Model>, ModelError> {
    Ok(degradation_free_models(n)?
        .into_iter()
        .filter(Model::satisfies_rule3)
        .collect())
}

impl Model {
    /// All models equivalent to this one under `sym`, sorted (this one
    /// included).
    pub fn orbit(&self, sym: Symmetry) -> Vec<Model> {
        let mut v = vec![*self, self.mirrored()];
        if sym == Symmetry::RenumberingAndReciprocity {
            let r = self.reciprocal();
            v.push(r);
            v.push(r.mirrored());
        }
        v.sort();
        v.dedup();
        v
    }

    /// The smallest model (in [`Model`] order) of the class of this one.
    pub fn canonical(&self, sym: Symmetry) -> Model {
        self.orbit(sym)[0]
    }

    /// The member of this model's renumbering class that the tables
    /// analyse: the one the paper's rule (3) keeps where it keeps one, else
    /// the smallest.
    ///
    /// ```
    /// let m = mms::Model::from_id("N5-g2-a4.2-s3.2")?;
    /// assert_eq!(m.representative().id(), "N5-g2-a4.2-s5.2");
    /// assert_eq!(m.representative().representative(), m.representative());
    /// # Ok::<(), mms::ModelError>(())
    /// ```
    pub fn representative(&self) -> Model {
        let orbit = self.orbit(Symmetry::Renumbering);
        orbit
            .iter()
            .copied()
            .find(Model::satisfies_rule3)
            .unwrap_or(orbit[0])
    }
}

/// The equivalence classes of the degradation-free models with `n` masses
/// under `sym`: each class sorted, classes sorted by their first member.
///
/// ```
/// use mms::Symmetry;
/// assert_eq!(mms::equivalence_classes(3, Symmetry::Renumbering).unwrap().len(), 11);
/// assert_eq!(mms::equivalence_classes(4, Symmetry::Renumbering).unwrap().len(), 30);
/// ```
pub fn equivalence_classes(n: usize, sym: Symmetry) -> Result<Vec<Vec<Model>>, ModelError> {
    let mut classes: BTreeMap<Model, Vec<Model>> = BTreeMap::new();
    for m in degradation_free_models(n)? {
        classes.entry(m.canonical(sym)).or_default().push(m);
    }
    Ok(classes.into_values().collect())
}

/// One model of every renumbering class of `n` masses, in the order of
/// the tables: the member the paper's rule (3) keeps where it keeps one,
/// else the first of the class; the paper's IDs (3 masses) in the paper's
/// order, then generic IDs.
///
/// ```
/// let reps = mms::class_representatives(3)?;
/// let ids: Vec<String> = reps.iter().map(|m| m.name()).collect();
/// assert_eq!(ids[..3], ["A1", "A2", "A3"]);
/// assert_eq!(reps.len(), 11);
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn class_representatives(n: usize) -> Result<Vec<Model>, ModelError> {
    let classes = equivalence_classes(n, Symmetry::Renumbering)?;
    let mut reps: Vec<Model> = classes.iter().map(|c| c[0].representative()).collect();
    reps.sort_by_key(|m| (m.paper_id().is_none(), m.paper_id(), *m));
    Ok(reps)
}

/// The model counts of Tab. 1 for `n` masses, plus the true class counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// Number of masses.
    pub n: usize,
    /// Rule (1): "Basic combinations".
    pub basic: usize,
    /// Rules (1)+(2): "Degradation-free".
    pub degradation_free: usize,
    /// Rules (1)+(2)+(3): "+ Redundancy-free" as printed in the paper.
    pub rule3: usize,
    /// Classes of degradation-free models under renumbering.
    pub classes: usize,
    /// Classes under renumbering and reciprocity.
    pub classes_with_reciprocity: usize,
}

/// Counts for `n` masses.
///
/// ```
/// let c = mms::counts(5).unwrap();
/// assert_eq!((c.basic, c.degradation_free, c.rule3), (259, 129, 73)); // Tab. 1
/// ```
pub fn counts(n: usize) -> Result<Counts, ModelError> {
    Ok(Counts {
        n,
        basic: basic_models(n)?.len(),
        degradation_free: degradation_free_models(n)?.len(),
        rule3: rule3_models(n)?.len(),
        classes: equivalence_classes(n, Symmetry::Renumbering)?.len(),
        classes_with_reciprocity: equivalence_classes(n, Symmetry::RenumberingAndReciprocity)?
            .len(),
    })
}

/// How the paper's rule (3) compares with the equivalence classes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RedundancyReport {
    /// Number of masses.
    pub n: usize,
    /// The identifications used for the classes.
    pub symmetry: Symmetry,
    /// Number of models kept by rule (3).
    pub rule3_count: usize,
    /// Number of classes.
    pub class_count: usize,
    /// Models kept by rule (3) that are equivalent to each other: one list
    /// per class with two or more kept members.
    pub rule3_duplicates: Vec<Vec<Model>>,
    /// Classes of which rule (3) keeps no member.
    pub unrepresented: Vec<Vec<Model>>,
}

impl RedundancyReport {
    /// True when rule (3) keeps exactly one model per class.
    pub fn rule3_is_exact(&self) -> bool {
        self.rule3_duplicates.is_empty() && self.unrepresented.is_empty()
    }
}

/// Compares rule (3) with the classes under `sym`.
///
/// ```
/// use mms::Symmetry;
/// let r = mms::redundancy_report(3, Symmetry::Renumbering).unwrap();
/// assert!(r.rule3_is_exact()); // the paper's 11 models for N = 3 are right
/// let r = mms::redundancy_report(4, Symmetry::Renumbering).unwrap();
/// assert_eq!((r.rule3_count, r.class_count), (29, 30));
/// ```
pub fn redundancy_report(n: usize, sym: Symmetry) -> Result<RedundancyReport, ModelError> {
    let classes = equivalence_classes(n, sym)?;
    let rule3_count = rule3_models(n)?.len();
    let mut rule3_duplicates = Vec::new();
    let mut unrepresented = Vec::new();
    for class in &classes {
        let kept: Vec<Model> = class
            .iter()
            .copied()
            .filter(Model::satisfies_rule3)
            .collect();
        match kept.len() {
            0 => unrepresented.push(class.clone()),
            1 => {}
            _ => rule3_duplicates.push(kept),
        }
    }
    Ok(RedundancyReport {
        n,
        symmetry: sym,
        rule3_count,
        class_count: classes.len(),
        rule3_duplicates,
        unrepresented,
    })
}
