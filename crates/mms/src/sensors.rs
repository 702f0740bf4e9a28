//! Several sensors on one chain: exactly which structures a sensor set
//! tells apart.
//!
//! # Definitions
//!
//! A [`SensorSet`] is one chain and actuator (a [`Model`]: `N` masses,
//! the gap, the actuator and its sensor, the *first* sensor) read by
//! further sensors at the same time, e.g. a motor encoder and a load
//! encoder. Sensor `i` (counted from 0, the first sensor) gives the model
//! `model.with_sensor(port_i)` ([`Model::with_sensor`], rule (1)) and its
//! own undamped inertance `G_i = num_i/den_i` ([`Model::undamped_tf`]).
//! All of them share the parameters (masses and springs).
//!
//! Two sensor-set structures `A` and `B` with the same `N` and the same
//! number of sensors are compared sensor by sensor (the `i`-th of `A` with
//! the `i`-th of `B`; the gaps may differ). A positive parameter point `q`
//! of `B` *reproduces* a positive point `p` of `A` when
//!
//! ```text
//! G^B_i(q) = kappa * G^A_i(p)   for every sensor i, one common constant kappa != 0,
//! ```
//!
//! as rational functions of `Omega`. One common factor, because a fitted
//! gain is no information: scaling every parameter of `q` by `t > 0`
//! divides every `G_i` by `t`, so a positive `kappa` can always be taken
//! as 1 and only its sign is left (a reversed sensor set). The structures
//! are *indistinguishable* when every positive point of either is
//! reproduced by some positive point of the other, and *distinguishable*
//! when some positive point of one is reproduced by no positive point of
//! the other. With one sensor this is the single-FRF question of
//! [`crate::structural_equivalences`].
//!
//! # Decision ([`sensor_set_distinguishability`])
//!
//! Exact arithmetic only (`poly`'s [`Rat`] and [`Poly`]); `f64` is for
//! display.
//!
//! 1. **Indistinguishable, proven**
//!    ([`SensorSetVerdict::Indistinguishable`]): every transfer function of
//!    `B` equals the one of `A` times one common constant after one
//!    renaming of the parameters, the identity or the mirror renaming
//!    ([`crate::mirror_renaming`], an involution, so it does not matter on
//!    which side it is applied); the test of
//!    [`crate::identical_transfer_functions`] run on the whole vector with
//!    one factor. Or Vajda's criterion on the *joint* moment invariants
//!    ([`sensor_set_identifiability`]: the invariants of every sensor's
//!    reduced transfer function over the `lc` of its denominator, a
//!    denominator invariant already listed for an earlier sensor not
//!    repeated): the same form in `A` and `B` for every sensor, and in both
//!    the joint invariants independent (generic rank of the Jacobian =
//!    number of non-constant invariants). Like the single-sensor
//!    criterion, it is generic: the parameter maps cover open sets of the
//!    common coefficient space. Two or more sensors rarely meet it: the
//!    joint invariants soon outnumber the parameters.
//! 2. **Distinguishable, with a witness**
//!    ([`SensorSetVerdict::Distinguishable`], [`DistinguishabilityWitness`]):
//!    a positive rational point `p` of one structure that no positive point
//!    of the other reproduces (pseudo-random, [`XorShift`] with a fixed seed
//!    per direction: a point of `A` against `B`, one of `B` against `A`).
//!    The proof picks a *pivot* sensor `k` and back-solves
//!    ([`crate::back_solve`]) the other structure's `k`-th model against
//!    `G_k(p)` and against `-G_k(p)` (the two signs of `kappa`): that gives
//!    every positive point reproducing the pivot's transfer function,
//!    exactly (minimal polynomials and isolating intervals,
//!    [`crate::backsolve::AlgebraicNumber`]). If there is none for either
//!    sign, the pivot's transfer function alone already separates them at
//!    `p` ([`Obstruction`]); a first pass looks for such a sensor in both
//!    directions with the back-solve's quick obstructions only (degrees,
//!    coefficient signs, invariant relations; no elimination, so cheap and
//!    deterministic). The second pass tries the sensors in order as pivots
//!    with the full back-solve (with small limits for both directions
//!    first, then with the default ones for a direction still undecided:
//!    from 4 masses on one pivot can run for minutes while another decides
//!    in a second), and each solution `q` is shown to differ at another
//!    sensor `i`: a coefficient of `Omega^j` of the cross-multiplied
//!    difference
//!
//!    ```text
//!    D_i(q) = num^B_i(q) * den^A_i(p) - kappa * num^A_i(p) * den^B_i(q)
//!    ```
//!
//!    (zero for every `j` exactly when `G^B_i(q) = kappa * G^A_i(p)`; the
//!    denominators never vanish identically, their leading coefficient is
//!    the product of the masses) is enclosed in an interval with exact
//!    rational interval arithmetic over the box of the parameters'
//!    isolating intervals. The parameters are positive, so every monomial
//!    is monotone in each of them and ranges over
//!    `[prod lo^e, prod hi^e]`. The intervals are refined by bisection on
//!    the sign of each minimal polynomial until the enclosure excludes 0,
//!    up to a limit.
//! 3. **Matched at the witness point**
//!    ([`SensorSetVerdict::MatchedAtWitnessPoints`]): a solution `q` is
//!    rational and every `D_i(q)` vanishes exactly, so `q` reproduces `p`
//!    at every sensor. This is proven at `p`, for both directions, but it
//!    is evidence, not a proof, of indistinguishability everywhere.
//! 4. **Undecided** ([`SensorSetVerdict::Undecided`]), with the reasons: for
//!    every pivot the back-solve gave a positive-dimensional family
//!    ([`BackSolution::Families`]) or failed (limits), or some irrational
//!    solution could not be separated within the refinement limit (it may
//!    reproduce `p` exactly: an equality of irrational numbers is not
//!    decided here).
//!
//! A witness proves a statement at one point `p`: *this* sensor set
//! separates the structures at `p`. That the point is pseudo-random makes
//! it evidence, no proof, that they are separated almost everywhere.
//!
//! # Checking a witness ([`check_distinguishability_witness`])
//!
//! The checker recomputes the claim from the stored data with its own code,
//! using only `poly` arithmetic and the models' transfer functions: the
//! point is positive, every stored box isolates exactly one root of its
//! minimal polynomial (Sturm count), the box is consistent with the pivot's
//! transfer function (every coefficient of the pivot's difference encloses
//! 0), and the named coefficient of the named sensor's difference is
//! enclosed away from 0, by another route than the prover's (enclosures of
//! each transfer-function coefficient, combined by interval arithmetic, and
//! its own bisection), consistent with the stored interval. Obstructions by
//! degree, coefficient sign or invariant relation are re-derived (the
//! relation is verified symbolically on the structure). What it takes from
//! the back-solve is that the list of solutions is complete, and the two
//! obstructions it cannot re-derive without the elimination
//! ([`Obstruction::NotPositive`], [`Obstruction::Contradiction`]); the
//! returned [`WitnessCheck`] counts those.
//!
//! # Pairs ([`two_sensor_pairs`])
//!
//! For every pair of rule-(3) models that one FRF cannot tell apart
//! ([`crate::structural_equivalences`] of [`crate::rule3_models`]) and every
//! second sensor port valid for both chains that is neither model's first
//! sensor: the verdict for the two two-sensor sets. For `N = 3` the
//! one-sensor groups are {A1, A4, B1, C1, C3}, {A2, A5} and {C2, C4}, which
//! gives 14 pairs, all decided in milliseconds: the second sensor alone
//! separates 12 of them (their second transfer functions belong to
//! structures one FRF tells apart), C2 / C4 stay identical and C1 / C3 are
//! matched at the witness points (docs/identification.md).
//!
//! ```
//! use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
//! use mms::{Model, Port};
//!
//! // One FRF cannot tell A1 (force and encoder on m1) from A4 (both on
//! // m2): Vajda's criterion, Tab. 7. Nor can the FRF from the force to the
//! // other encoder (A2 and its reciprocal). Both encoders at once can,
//! // with a checkable witness.
//! let a1 = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
//! let a4 = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
//! let verdict = sensor_set_distinguishability(&a1, &a4)?;
//! let SensorSetVerdict::Distinguishable(w) = &verdict else { panic!("{verdict}") };
//! assert_eq!(w.separations.len(), 2); // both A4 sets matching A1 at the m1 encoder
//! assert!(mms::sensors::check_distinguishability_witness(&a1, &a4, w).is_ok());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::backsolve::{back_solve_with, BackSolution, Limits, NoSolution, Solution, Target};
use crate::enumerate::rule3_models;
use crate::identifiability::{
    identical_tf_vectors, invariant_rank, moment_invariants, structural_equivalences,
    MomentInvariant, ParameterRenaming, RankCertificate, RankOptions, Renamable, TfPart,
};
use crate::model::{Model, ModelError, Port};
use crate::tf::{UndampedTf, OMEGA};
use crate::xorshift::XorShift;
use poly::{count_roots_in, Poly, Rat, UPoly};
use serde::{Serialize, Serializer};
use std::collections::BTreeMap;
use std::fmt;

fn ser_display<T: fmt::Display, S: Serializer>(x: &T, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(x)
}

fn ser_rats<S: Serializer>(v: &[Rat], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(v.iter().map(Rat::to_string))
}

fn ser_upoly<S: Serializer>(p: &UPoly, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&p.to_text("x"))
}

// ---------------------------------------------------------------------------
// Sensor sets

/// Errors when building or comparing [`SensorSet`]s.
///
/// ```
/// use mms::sensors::{SensorSet, SensorSetError};
/// assert_eq!(SensorSet::from_models(&[]), Err(SensorSetError::Empty));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SensorSetError {
    /// No model was given.
    #[error("a sensor set needs at least one model")]
    Empty,
    /// A sensor port violates rule (1) on the chain.
    #[error("invalid sensor: {0}")]
    InvalidSensor(ModelError),
    /// A model of the list is not the first model's chain and actuator.
    #[error("{other} is not the chain and actuator of {first} read by another sensor")]
    Mismatch {
        /// The first model.
        first: Model,
        /// The model that differs in `N`, gap or actuator.
        other: Model,
    },
    /// A sensor is listed twice.
    #[error("sensor s{}.{} appears twice", .0.plus, .0.minus)]
    DuplicateSensor(Port),
    /// The two sets have different numbers of masses.
    #[error("the sensor sets have {a} and {b} masses")]
    DifferentMasses {
        /// `N` of the first set.
        a: usize,
        /// `N` of the second set.
        b: usize,
    },
    /// The two sets have different numbers of sensors.
    #[error("the sensor sets have {a} and {b} sensors")]
    DifferentSensorCounts {
        /// Sensors of the first set.
        a: usize,
        /// Sensors of the second set.
        b: usize,
    },
}

/// One chain and actuator read by several sensors at once (see the
/// [module documentation](self)): a [`Model`], whose sensor is the first
/// sensor, and further distinct sensor ports, each valid by rule (1).
///
/// ```
/// use mms::{sensors::SensorSet, Model, Port};
/// let a2 = Model::from_id("A2")?; // force on m1, position of m2
/// let set = SensorSet::new(a2, &[Port::new(1, 0)])?; // and of m1
/// assert_eq!(set.n_sensors(), 2);
/// assert_eq!(set.models()[1].name(), "A1");
/// assert_eq!(set.to_string(), "A2 + s1.0");
/// assert_eq!(SensorSet::from_models(&set.models())?, set);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct SensorSet {
    model: Model,
    extra: Vec<Port>,
}

impl SensorSet {
    /// `model` read also by the sensors `extra`, in this order. Each must
    /// satisfy rule (1) on the chain and differ from every earlier sensor.
    ///
    /// ```
    /// use mms::{sensors::{SensorSet, SensorSetError}, Model, Port};
    /// let c2 = Model::from_id("C2")?; // gap 2, sensor (3, 2)
    /// assert!(SensorSet::new(c2, &[Port::new(3, 0)]).is_ok());
    /// assert!(matches!(SensorSet::new(c2, &[Port::new(2, 0)]), Err(SensorSetError::InvalidSensor(_))));
    /// assert_eq!(SensorSet::new(c2, &[Port::new(3, 2)]), Err(SensorSetError::DuplicateSensor(Port::new(3, 2))));
    /// # Ok::<(), mms::ModelError>(())
    /// ```
    pub fn new(model: Model, extra: &[Port]) -> Result<SensorSet, SensorSetError> {
        let mut seen = vec![model.sensor()];
        for &port in extra {
            model
                .with_sensor(port)
                .map_err(SensorSetError::InvalidSensor)?;
            if seen.contains(&port) {
                return Err(SensorSetError::DuplicateSensor(port));
            }
            seen.push(port);
        }
        Ok(SensorSet {
            model,
            extra: extra.to_vec(),
        })
    }

    /// The set of the sensors of `models`, which must share `N`, gap and
    /// actuator; the first model's sensor is the first sensor.
    ///
    /// ```
    /// use mms::{sensors::{SensorSet, SensorSetError}, Model};
    /// let m = |id: &str| Model::from_id(id).unwrap();
    /// let set = SensorSet::from_models(&[m("A1"), m("A3")])?; // force on m1, read m1 and m3
    /// assert_eq!(set.sensors().len(), 2);
    /// assert!(matches!(SensorSet::from_models(&[m("A1"), m("A4")]), Err(SensorSetError::Mismatch { .. })));
    /// # Ok::<(), SensorSetError>(())
    /// ```
    pub fn from_models(models: &[Model]) -> Result<SensorSet, SensorSetError> {
        let (first, rest) = models.split_first().ok_or(SensorSetError::Empty)?;
        for m in rest {
            if m.n_masses() != first.n_masses()
                || m.gap() != first.gap()
                || m.actuator() != first.actuator()
            {
                return Err(SensorSetError::Mismatch {
                    first: *first,
                    other: *m,
                });
            }
        }
        let extra: Vec<Port> = rest.iter().map(Model::sensor).collect();
        SensorSet::new(*first, &extra)
    }

    /// The model of the first sensor.
    ///
    /// ```
    /// let set = mms::sensors::SensorSet::new(mms::Model::from_id("B2")?, &[])?;
    /// assert_eq!(set.first().name(), "B2");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn first(&self) -> Model {
        self.model
    }

    /// All sensor ports, the first sensor first.
    ///
    /// ```
    /// use mms::{sensors::SensorSet, Model, Port};
    /// let set = SensorSet::new(Model::from_id("A2")?, &[Port::new(3, 0)])?;
    /// assert_eq!(set.sensors(), [Port::new(2, 0), Port::new(3, 0)]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn sensors(&self) -> Vec<Port> {
        std::iter::once(self.model.sensor())
            .chain(self.extra.iter().copied())
            .collect()
    }

    /// Number of sensors (at least 1).
    ///
    /// ```
    /// let set = mms::sensors::SensorSet::new(mms::Model::from_id("A1")?, &[])?;
    /// assert_eq!(set.n_sensors(), 1);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn n_sensors(&self) -> usize {
        1 + self.extra.len()
    }

    /// Number of masses `N`.
    ///
    /// ```
    /// let set = mms::sensors::SensorSet::new(mms::Model::from_id("A1")?, &[])?;
    /// assert_eq!(set.n_masses(), 3);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn n_masses(&self) -> usize {
        self.model.n_masses()
    }

    /// One model per sensor: the chain and actuator with that sensor.
    ///
    /// ```
    /// use mms::{sensors::SensorSet, Model, Port};
    /// let set = SensorSet::new(Model::from_id("C2")?, &[Port::new(3, 0)])?;
    /// assert_eq!(set.models()[1].id(), "N3-g2-a3.1-s3.0");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn models(&self) -> Vec<Model> {
        self.sensors()
            .into_iter()
            .map(|p| {
                self.model
                    .with_sensor(p)
                    .expect("sensors are validated on construction")
            })
            .collect()
    }

    /// The undamped inertance of every sensor ([`Model::undamped_tf`], not
    /// reduced), the first sensor first.
    ///
    /// ```
    /// use mms::{sensors::SensorSet, Model, Port};
    /// let set = SensorSet::new(Model::from_id("A2")?, &[Port::new(1, 0)])?;
    /// let tfs = set.transfer_functions();
    /// assert_eq!(tfs[0].den, tfs[1].den); // one chain, one actuator
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn transfer_functions(&self) -> Vec<UndampedTf> {
        self.models().iter().map(Model::undamped_tf).collect()
    }

    /// The shared undamped parameters ([`Model::undamped_parameters`]).
    ///
    /// ```
    /// let set = mms::sensors::SensorSet::new(mms::Model::from_id("C2")?, &[])?;
    /// assert_eq!(set.parameters(), ["m1", "m2", "m3", "c1", "c12"]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn parameters(&self) -> Vec<String> {
        self.model.undamped_parameters()
    }
}

impl fmt::Display for SensorSet {
    /// The first model's name, then `+ s{plus}.{minus}` per further sensor.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.model.name())?;
        for p in &self.extra {
            write!(f, " + s{}.{}", p.plus, p.minus)?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// Joint moment invariants

/// A moment invariant of one sensor's transfer function.
///
/// ```
/// use mms::{sensors::sensor_set_identifiability, sensors::SensorSet, Model, Port};
/// let set = SensorSet::new(Model::from_id("A2")?, &[Port::new(1, 0)])?;
/// let id = sensor_set_identifiability(&set);
/// assert_eq!(id.invariants[0].to_string(), "sensor 1: Num Omega^1: -c12/(m1*m2)");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct SensorInvariant {
    /// The sensor, counted from 0 (the first sensor).
    pub sensor: usize,
    /// The invariant of its reduced transfer function.
    pub invariant: MomentInvariant,
}

impl fmt::Display for SensorInvariant {
    /// `sensor 1: Num Omega^1: ...`, the sensor counted from 1.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "sensor {}: {}", self.sensor + 1, self.invariant)
    }
}

/// Joint identifiability of a sensor set: the moment invariants of every
/// sensor (see the [module documentation](self)) and the generic rank of
/// their Jacobian, established like [`crate::identifiability()`]'s.
///
/// ```
/// use mms::{sensors::{sensor_set_identifiability, SensorSet}, Model, Port};
/// // A2 alone determines 4 of its 5 parameters; with m1 read as well, all 5.
/// let set = SensorSet::new(Model::from_id("A2")?, &[Port::new(1, 0)])?;
/// let id = sensor_set_identifiability(&set);
/// assert_eq!(id.determinable_parameters, 5);
/// assert!(id.is_proven() && id.is_locally_identifiable());
/// assert!(!id.invariants_independent()); // more invariants than parameters
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct SensorSetIdentifiability {
    /// The sensor set.
    pub set: SensorSet,
    /// The undamped parameters, masses then springs.
    pub parameters: Vec<String>,
    /// The invariants of every sensor's reduced transfer function, sensor
    /// by sensor; an invariant equal to one of an earlier sensor (the
    /// shared denominator) is not repeated.
    pub invariants: Vec<SensorInvariant>,
    /// Number of non-constant invariants.
    pub nonconstant_invariants: usize,
    /// Generic rank of the Jacobian of the non-constant invariants: a
    /// proven lower bound, exact when [`SensorSetIdentifiability::is_proven`].
    pub determinable_parameters: usize,
    /// A proven upper bound of that rank.
    pub rank_upper_bound: usize,
    /// How the rank is established.
    pub certificate: RankCertificate,
}

impl SensorSetIdentifiability {
    /// True when the rank is proven.
    ///
    /// ```
    /// use mms::{sensors::{sensor_set_identifiability, SensorSet}, Model, Port};
    /// let set = SensorSet::new(Model::from_id("B2")?, &[Port::new(2, 1)])?;
    /// assert!(sensor_set_identifiability(&set).is_proven());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn is_proven(&self) -> bool {
        self.certificate != RankCertificate::Sampled
    }

    /// True when the non-constant invariants are independent (proven when
    /// `true`).
    ///
    /// ```
    /// use mms::{sensors::{sensor_set_identifiability, SensorSet}, Model};
    /// let a1 = SensorSet::new(Model::from_id("A1")?, &[])?;
    /// assert!(sensor_set_identifiability(&a1).invariants_independent()); // 5 of 5
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn invariants_independent(&self) -> bool {
        self.determinable_parameters == self.nonconstant_invariants
    }

    /// True when all parameters are locally identifiable (proven when
    /// `true`).
    ///
    /// ```
    /// use mms::{sensors::{sensor_set_identifiability, SensorSet}, Model, Port};
    /// let c2 = Model::from_id("C2")?; // 4 of 5 alone (Tab. 5)
    /// let alone = sensor_set_identifiability(&SensorSet::new(c2, &[])?);
    /// // m3 against m1 as well: all 5; m3 against the ground adds only 1/m3.
    /// let s31 = sensor_set_identifiability(&SensorSet::new(c2, &[Port::new(3, 1)])?);
    /// let s30 = sensor_set_identifiability(&SensorSet::new(c2, &[Port::new(3, 0)])?);
    /// assert!(!alone.is_locally_identifiable() && s31.is_locally_identifiable());
    /// assert_eq!(s30.determinable_parameters, 4);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn is_locally_identifiable(&self) -> bool {
        self.determinable_parameters == self.parameters.len()
    }

    /// Same symbolic form, sensor by sensor: the same invariants (sensor,
    /// part, power of `Omega`), the same constant values and the same fixed
    /// signs on positive parameters.
    ///
    /// ```
    /// use mms::{sensors::{sensor_set_identifiability, SensorSet}, Model, Port};
    /// let id = |m: &str, extra: &[Port]| {
    ///     sensor_set_identifiability(&SensorSet::new(Model::from_id(m).unwrap(), extra).unwrap())
    /// };
    /// assert!(id("A1", &[]).same_form(&id("A4", &[])));
    /// let m2 = [Port::new(2, 0)];
    /// assert!(!id("A1", &m2).same_form(&id("A5", &m2)));
    /// ```
    pub fn same_form(&self, other: &SensorSetIdentifiability) -> bool {
        same_joint_form(&self.invariants, &other.invariants)
    }

    /// Vajda's criterion on the joint invariants: the same form and, in
    /// both sets, independent non-constant invariants.
    ///
    /// ```
    /// use mms::{sensors::{sensor_set_identifiability, SensorSet}, Model, Port};
    /// let id = |m: &str, extra: &[Port]| {
    ///     sensor_set_identifiability(&SensorSet::new(Model::from_id(m).unwrap(), extra).unwrap())
    /// };
    /// // One sensor: the paper's A1 ~ A4. With m3 read too, more invariants
    /// // than parameters: the criterion no longer applies.
    /// assert!(id("A1", &[]).structurally_equivalent_by_invariants(&id("A4", &[])));
    /// let m3 = [Port::new(3, 0)];
    /// assert!(!id("A1", &m3).structurally_equivalent_by_invariants(&id("A4", &m3)));
    /// ```
    pub fn structurally_equivalent_by_invariants(&self, other: &SensorSetIdentifiability) -> bool {
        self.same_form(other) && self.invariants_independent() && other.invariants_independent()
    }
}

fn same_joint_form(a: &[SensorInvariant], b: &[SensorInvariant]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            let (i, j) = (&x.invariant, &y.invariant);
            x.sensor == y.sensor
                && i.part == j.part
                && i.power == j.power
                && i.constant_value() == j.constant_value()
                && i.sign_on_positive_parameters() == j.sign_on_positive_parameters()
        })
}

fn joint_invariants(set: &SensorSet) -> Vec<SensorInvariant> {
    let mut out: Vec<SensorInvariant> = Vec::new();
    for (sensor, tf) in set.transfer_functions().iter().enumerate() {
        for invariant in moment_invariants(&tf.reduced()) {
            // The denominator is shared; a repeated function adds nothing.
            if !out.iter().any(|s| s.invariant == invariant) {
                out.push(SensorInvariant { sensor, invariant });
            }
        }
    }
    out
}

/// The joint moment invariants of a sensor set and the number of
/// parameters they determine (default [`RankOptions`]).
///
/// ```
/// use mms::{sensors::{sensor_set_identifiability, SensorSet}, Model};
/// // One sensor: the same numbers as mms::identifiability (Tab. 5).
/// let c2 = SensorSet::new(Model::from_id("C2")?, &[])?;
/// let id = sensor_set_identifiability(&c2);
/// assert_eq!((id.nonconstant_invariants, id.determinable_parameters), (5, 4));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn sensor_set_identifiability(set: &SensorSet) -> SensorSetIdentifiability {
    let parameters = set.parameters();
    let invariants = joint_invariants(set);
    let nonconstant: Vec<&MomentInvariant> = invariants
        .iter()
        .map(|s| &s.invariant)
        .filter(|i| !i.is_constant())
        .collect();
    let rank = invariant_rank(
        &set.first(),
        &parameters,
        &nonconstant,
        &RankOptions::default(),
    );
    SensorSetIdentifiability {
        set: set.clone(),
        nonconstant_invariants: nonconstant.len(),
        parameters,
        invariants,
        determinable_parameters: rank.determinable,
        rank_upper_bound: rank.upper_bound,
        certificate: rank.certificate,
    }
}

// ---------------------------------------------------------------------------
// Verdicts

/// Which of the two compared structures a witness point belongs to.
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // Encoders at m1 and m2; the force on m1 (A1) or on m2 (A4).
/// let a = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
/// let b = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// assert_eq!(w.generated_by, mms::sensors::Side::A); // a point of A1 + m2
/// assert_eq!(w.generated_by.to_string(), "A");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Side {
    /// The first argument.
    A,
    /// The second argument.
    B,
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::A => "A",
            Side::B => "B",
        })
    }
}

impl Side {
    fn other(self) -> Side {
        match self {
            Side::A => Side::B,
            Side::B => Side::A,
        }
    }
}

/// Why two sensor sets are indistinguishable.
///
/// ```
/// use mms::{sensors::IndistinguishableReason, ParameterRenaming};
/// let r = IndistinguishableReason::IdenticalTransferFunctions {
///     renaming: ParameterRenaming::Mirror,
///     factor: 1.into(),
/// };
/// assert_eq!(r.to_string(), "identical transfer functions up to the mirror renaming");
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub enum IndistinguishableReason {
    /// Every transfer function of `B` is `factor` times the one of `A` after
    /// `renaming` (proven, for every parameter point).
    IdenticalTransferFunctions {
        /// The renaming of `A`'s parameters.
        renaming: ParameterRenaming,
        /// `G^B_i = factor * renamed(G^A_i)` for every sensor `i`.
        #[serde(serialize_with = "ser_display")]
        factor: Rat,
    },
    /// Vajda's criterion on the joint invariants (generic): the same form
    /// and, in both, `invariants` independent non-constant invariants.
    IndependentJointInvariants {
        /// Number of non-constant joint invariants.
        invariants: usize,
    },
}

impl fmt::Display for IndistinguishableReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IndistinguishableReason::IdenticalTransferFunctions { renaming, factor } => {
                f.write_str("identical transfer functions")?;
                if *renaming == ParameterRenaming::Mirror {
                    f.write_str(" up to the mirror renaming")?;
                }
                if !factor.is_one() {
                    write!(f, " times {factor}")?;
                }
                Ok(())
            }
            IndistinguishableReason::IndependentJointInvariants { invariants } => write!(
                f,
                "same form, {invariants} independent joint moment invariants"
            ),
        }
    }
}

/// Why no positive parameter point reproduces the pivot's transfer function
/// (a [`NoSolution`] of the back-solve, in checkable form).
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, Obstruction, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // A2 + m1 reads a collocated FRF as second sensor, A5 + m1 does not:
/// // numerator degree 2 against 1, for either sign of the factor.
/// let a = SensorSet::new(Model::from_id("A2")?, &[Port::new(1, 0)])?;
/// let b = SensorSet::new(Model::from_id("A5")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// assert_eq!(w.obstructions[0].obstruction, Obstruction::Degree { structure: (1, 2), target: (2, 2) });
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub enum Obstruction {
    /// The degrees `(num, den)` of the reduced target are impossible for
    /// the structure's degrees.
    Degree {
        /// `(deg num, deg den)` of the structure's transfer function.
        structure: (usize, usize),
        /// `(deg num, deg den)` of the target in lowest terms.
        target: (usize, usize),
    },
    /// A coefficient of fixed sign on positive parameters has another sign
    /// in the target (denominator degrees equal, `lc(den) > 0`).
    SignPattern {
        /// Numerator or denominator.
        part: TfPart,
        /// The power of `Omega`.
        power: u32,
        /// Its sign for every positive parameter point (0: absent).
        structure_sign: i32,
        /// Its sign in the target.
        target_sign: i32,
    },
    /// The target violates a polynomial identity of the structure's
    /// coefficients ([`crate::invariant_relations`]), in `n0, n1, ..`
    /// (numerator coefficients) and `d0, d1, ..` (denominator).
    ViolatedRelation {
        /// The relation.
        #[serde(serialize_with = "ser_display")]
        relation: Poly,
        /// Its value at the target in the normal form of [`Target`].
        #[serde(serialize_with = "ser_display")]
        value: Rat,
    },
    /// Real solutions exist, none positive (from the elimination).
    NotPositive {
        /// Number of real candidates.
        candidates: usize,
    },
    /// The elimination ends in a contradiction on every branch.
    Contradiction,
}

impl fmt::Display for Obstruction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Obstruction::Degree { structure, target } => write!(
                f,
                "degrees (num, den) {target:?} impossible for a structure of degrees {structure:?}"
            ),
            Obstruction::SignPattern {
                part,
                power,
                structure_sign,
                target_sign,
            } => write!(
                f,
                "{} {OMEGA}^{power} has sign {target_sign}, the structure's always {structure_sign}",
                part.as_str()
            ),
            Obstruction::ViolatedRelation { relation, .. } => {
                write!(f, "violates the invariant relation {relation} = 0")
            }
            Obstruction::NotPositive { candidates } => {
                write!(f, "{candidates} real solution(s), none positive")
            }
            Obstruction::Contradiction => f.write_str("no positive solution (elimination)"),
        }
    }
}

fn parse_coefficient(text: &str) -> Option<(TfPart, u32)> {
    let (part, rest) = text.split_once(' ')?;
    let part = match part {
        "Num" => TfPart::Numerator,
        "Den" => TfPart::Denominator,
        _ => return None,
    };
    let power = rest.strip_prefix("Omega^")?.parse().ok()?;
    Some((part, power))
}

impl Obstruction {
    fn from_no_solution(r: &NoSolution) -> Obstruction {
        match r {
            NoSolution::Degree { structure, target } => Obstruction::Degree {
                structure: *structure,
                target: *target,
            },
            NoSolution::SignPattern {
                coefficient,
                structure_sign,
                target_sign,
            } => match parse_coefficient(coefficient) {
                Some((part, power)) => Obstruction::SignPattern {
                    part,
                    power,
                    structure_sign: *structure_sign,
                    target_sign: *target_sign,
                },
                // Not reachable with the back-solve's labels; keep the
                // claim, as one the checker cannot re-derive.
                None => Obstruction::Contradiction,
            },
            NoSolution::ViolatedRelation {
                relation, value, ..
            } => Obstruction::ViolatedRelation {
                relation: relation.clone(),
                value: value.clone(),
            },
            NoSolution::NotPositive { candidates } => Obstruction::NotPositive {
                candidates: candidates.len(),
            },
            NoSolution::Contradiction => Obstruction::Contradiction,
        }
    }
}

/// The obstruction for one sign of the common factor.
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // Encoders at m1 and m2; the force on m1 (A1) or on m2 (A4).
/// let a = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
/// let b = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// // A1's FRF with a negative factor has a negative static term: no chain's.
/// assert_eq!(w.obstructions.len(), 1);
/// assert_eq!(w.obstructions[0].factor_sign, -1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct SignObstruction {
    /// The sign of `kappa` (`+1` or `-1`).
    pub factor_sign: i32,
    /// Why no positive point reproduces `kappa * G_pivot(p)`.
    pub obstruction: Obstruction,
}

/// An exactly described positive parameter value: the root of
/// `minimal_polynomial` in `[lo, hi]` (`lo == hi` for a rational value).
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // Encoders at m1 and m2; the force on m1 (A1) or on m2 (A4).
/// let a = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
/// let b = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// for e in &w.separations[0].solution {
///     assert!(e.lo.signum() > 0 && e.lo <= e.hi);
///     assert!(e.lo == e.hi || e.minimal_polynomial.sign_at(&e.lo) != e.minimal_polynomial.sign_at(&e.hi));
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ParameterEnclosure {
    /// The parameter name.
    pub name: String,
    /// Its minimal polynomial, in `x`.
    #[serde(serialize_with = "ser_upoly")]
    pub minimal_polynomial: UPoly,
    /// Lower end, positive.
    #[serde(serialize_with = "ser_display")]
    pub lo: Rat,
    /// Upper end.
    #[serde(serialize_with = "ser_display")]
    pub hi: Rat,
}

/// One back-solved point of the other structure and the sensor that
/// separates it from the witness point.
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // Encoders at m1 and m2; the force on m1 (A1) or on m2 (A4).
/// let a = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
/// let b = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// // A4 reproduces A1's FRF with two parameter sets (Tab. 7); the
/// // encoder at m1 tells each of them apart from A1.
/// assert_eq!(w.separations.len(), 2);
/// for s in &w.separations {
///     assert_eq!(s.sensor, 1);
///     assert!(s.lo.signum() > 0 || s.hi.signum() < 0);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Separation {
    /// The sign of `kappa` it reproduces the pivot with.
    pub factor_sign: i32,
    /// The point, one enclosure per parameter of the other structure, in
    /// the order of its parameters (refined as far as the proof needed).
    pub solution: Vec<ParameterEnclosure>,
    /// The separating sensor, counted from 0.
    pub sensor: usize,
    /// The power `j` of `Omega` in that sensor's difference `D` (see the
    /// [module documentation](self)).
    pub power: u32,
    /// Lower end of the enclosure of the coefficient over the box.
    #[serde(serialize_with = "ser_display")]
    pub lo: Rat,
    /// Upper end; `lo > 0` or `hi < 0`.
    #[serde(serialize_with = "ser_display")]
    pub hi: Rat,
}

/// A proof that two sensor sets are distinguishable: a positive point of
/// one that no positive point of the other reproduces, at every sensor at
/// once. Check it with [`check_distinguishability_witness`].
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // Encoders at m1 and m2; the force on m1 (A1) or on m2 (A4).
/// let a = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
/// let b = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// assert_eq!(
///     w.to_string(),
///     "at a point of A, the 2 point(s) of B reproducing sensor 1 differ at sensor 2"
/// );
/// assert_eq!(w.parameters, ["m1", "m2", "m3", "c12", "c23"]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct DistinguishabilityWitness {
    /// The structure the point belongs to.
    pub generated_by: Side,
    /// Its parameters ([`SensorSet::parameters`]).
    pub parameters: Vec<String>,
    /// The point, in the order of `parameters`.
    #[serde(serialize_with = "ser_rats")]
    pub point: Vec<Rat>,
    /// The sensor (from 0) whose transfer function was back-solved.
    pub pivot: usize,
    /// The signs of `kappa` for which no positive point reproduces the
    /// pivot at all.
    pub obstructions: Vec<SignObstruction>,
    /// Every positive point reproducing the pivot (for the other signs),
    /// each separated at another sensor.
    pub separations: Vec<Separation>,
}

impl fmt::Display for DistinguishabilityWitness {
    /// One line; sensors counted from 1.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let other = self.generated_by.other();
        let pivot = self.pivot + 1;
        if self.separations.is_empty() {
            let why: Vec<String> = self
                .obstructions
                .iter()
                .map(|o| o.obstruction.to_string())
                .collect();
            return write!(
                f,
                "at a point of {}, sensor {pivot} alone: no positive point of {other} reproduces it ({})",
                self.generated_by,
                why.join("; ")
            );
        }
        let mut by: Vec<usize> = self.separations.iter().map(|s| s.sensor + 1).collect();
        by.sort_unstable();
        by.dedup();
        let by: Vec<String> = by.iter().map(usize::to_string).collect();
        write!(
            f,
            "at a point of {}, the {} point(s) of {other} reproducing sensor {pivot} differ at sensor {}",
            self.generated_by,
            self.separations.len(),
            by.join(", ")
        )
    }
}

/// A rational point of the other structure that reproduces the witness
/// point exactly at every sensor: evidence of indistinguishability, not a
/// proof.
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// let a = SensorSet::new(Model::from_id("C1")?, &[Port::new(3, 0)])?;
/// let b = SensorSet::new(Model::from_id("C3")?, &[Port::new(3, 0)])?;
/// let v = sensor_set_distinguishability(&a, &b)?;
/// let SensorSetVerdict::MatchedAtWitnessPoints { a_by_b, .. } = &v else { panic!("{v}") };
/// assert_eq!(a_by_b.matching_point[1], a_by_b.point[0]); // C3's m2 is C1's m1
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct WitnessMatch {
    /// The structure the point belongs to.
    pub generated_by: Side,
    /// The point, in the order of the generating structure's parameters.
    #[serde(serialize_with = "ser_rats")]
    pub point: Vec<Rat>,
    /// The sensor whose transfer function was back-solved.
    pub pivot: usize,
    /// The sign of the common factor.
    pub factor_sign: i32,
    /// The reproducing point of the other structure, in the order of its
    /// parameters.
    #[serde(serialize_with = "ser_rats")]
    pub matching_point: Vec<Rat>,
}

/// Why one pivot of one direction did not decide.
///
/// ```
/// use mms::sensors::{DirectionOutcome, Side, UndecidedKind, UndecidedReason};
/// let r = UndecidedReason { generated_by: Side::B, pivot: 0, kind: UndecidedKind::Family { dimension: 1 } };
/// assert!(matches!(r.kind, UndecidedKind::Family { dimension: 1 }));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum UndecidedKind {
    /// The back-solve found a family of this dimension.
    Family {
        /// Its number of free parameters.
        dimension: usize,
    },
    /// The back-solve stopped (limits, unsupported system).
    BackSolve(String),
    /// A solution (these values) could not be separated within the
    /// refinement limit.
    NotSeparated {
        /// Its parameter values.
        solution: Vec<f64>,
    },
}

/// One pivot of one direction that did not decide.
///
/// ```
/// use mms::sensors::{DirectionOutcome, Side, UndecidedKind, UndecidedReason};
/// let r = UndecidedReason { generated_by: Side::B, pivot: 0, kind: UndecidedKind::Family { dimension: 1 } };
/// assert_eq!(r.to_string(), "A reproduces sensor 1 of B on a family of dimension 1");
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UndecidedReason {
    /// The structure of the witness point.
    pub generated_by: Side,
    /// The back-solved sensor.
    pub pivot: usize,
    /// Why it did not decide.
    pub kind: UndecidedKind,
}

impl fmt::Display for UndecidedReason {
    /// Sensors counted from 1.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pivot = self.pivot + 1;
        let other = self.generated_by.other();
        match &self.kind {
            UndecidedKind::Family { dimension } => write!(
                f,
                "{other} reproduces sensor {pivot} of {} on a family of dimension {dimension}",
                self.generated_by
            ),
            UndecidedKind::BackSolve(e) => {
                write!(f, "back-solving {other} at sensor {pivot} stopped: {e}")
            }
            UndecidedKind::NotSeparated { solution } => write!(
                f,
                "a point of {other} reproducing sensor {pivot} could not be separated ({solution:?})"
            ),
        }
    }
}

/// What one direction (a point of one structure against the other) found
/// when it did not separate.
///
/// ```
/// use mms::sensors::{DirectionOutcome, Side, UndecidedKind, UndecidedReason};
/// let r = UndecidedReason { generated_by: Side::B, pivot: 0, kind: UndecidedKind::Family { dimension: 1 } };
/// let o = DirectionOutcome::Undecided(vec![r.clone(), r]);
/// assert_eq!(o.to_string().matches("family").count(), 2);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum DirectionOutcome {
    /// A rational point of the other structure matches exactly.
    Matched(WitnessMatch),
    /// No pivot decided.
    Undecided(Vec<UndecidedReason>),
}

impl fmt::Display for DirectionOutcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DirectionOutcome::Matched(m) => write!(
                f,
                "a point of {} is matched exactly by a rational point of {}",
                m.generated_by,
                m.generated_by.other()
            ),
            DirectionOutcome::Undecided(r) => {
                let parts: Vec<String> = r.iter().map(UndecidedReason::to_string).collect();
                f.write_str(&parts.join("; "))
            }
        }
    }
}

/// The verdict of [`sensor_set_distinguishability`] (see the
/// [module documentation](self)).
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// let a = SensorSet::new(Model::from_id("B1")?, &[Port::new(3, 1)])?;
/// let b = SensorSet::new(Model::from_id("C3")?, &[Port::new(3, 1)])?;
/// let v = sensor_set_distinguishability(&a, &b)?;
/// assert!(matches!(v, SensorSetVerdict::Distinguishable(_)));
/// assert!(v.to_string().starts_with("distinguishable: at a point of A"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum SensorSetVerdict {
    /// Indistinguishable, proven (generically for Vajda's criterion).
    Indistinguishable(IndistinguishableReason),
    /// Distinguishable, with a checkable witness.
    Distinguishable(Box<DistinguishabilityWitness>),
    /// Both witness points are reproduced exactly by rational points of
    /// the other structure: evidence of indistinguishability, not a proof.
    MatchedAtWitnessPoints {
        /// A point of `A` matched by `B`.
        a_by_b: WitnessMatch,
        /// A point of `B` matched by `A`.
        b_by_a: WitnessMatch,
    },
    /// Neither proven nor refuted; at least one direction is undecided.
    Undecided {
        /// A point of `A` against `B`.
        a_by_b: DirectionOutcome,
        /// A point of `B` against `A`.
        b_by_a: DirectionOutcome,
    },
}

impl SensorSetVerdict {
    /// `indistinguishable`, `distinguishable`, `matched at the witness
    /// points` or `undecided`.
    ///
    /// ```
    /// use mms::sensors::{sensor_set_distinguishability, SensorSet};
    /// let a2 = SensorSet::new(mms::Model::from_id("A2")?, &[])?;
    /// let v = sensor_set_distinguishability(&a2, &a2)?;
    /// assert_eq!(v.kind(), "indistinguishable");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn kind(&self) -> &'static str {
        match self {
            SensorSetVerdict::Indistinguishable(_) => "indistinguishable",
            SensorSetVerdict::Distinguishable(_) => "distinguishable",
            SensorSetVerdict::MatchedAtWitnessPoints { .. } => "matched at the witness points",
            SensorSetVerdict::Undecided { .. } => "undecided",
        }
    }
}

impl fmt::Display for SensorSetVerdict {
    /// The kind and a one-line reason.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", self.kind())?;
        match self {
            SensorSetVerdict::Indistinguishable(r) => write!(f, "{r}"),
            SensorSetVerdict::Distinguishable(w) => write!(f, "{w}"),
            SensorSetVerdict::MatchedAtWitnessPoints { .. } => f.write_str(
                "a rational point of each is reproduced exactly by the other (evidence, not a proof)",
            ),
            SensorSetVerdict::Undecided { a_by_b, b_by_a } => write!(f, "{a_by_b}; {b_by_a}"),
        }
    }
}

// ---------------------------------------------------------------------------
// The decision

/// Seeds of the witness points, one per direction, so that the result
/// does not depend on what ran before.
const SEED_A: u64 = 0x5e45_0125_a11c_e001;
const SEED_B: u64 = 0x5e45_0125_b0b0_0002;

/// Bisections of every irrational parameter before a solution counts as
/// not separated. The back-solve's intervals start at about 2^-60
/// relative width; this goes about 2^-128 further.
const MAX_BISECTIONS: usize = 128;

/// Decides whether the sensor sets `a` and `b` are distinguishable (see the
/// [module documentation](self) for definitions and method). Errors when
/// they differ in `N` or in the number of sensors.
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, IndistinguishableReason, SensorSet, SensorSetVerdict};
/// use mms::{Model, ParameterRenaming, Port};
///
/// // C2 and C4 have one FRF (reciprocity); read m3 against the ground as
/// // well, and the second FRFs are equal too: F33 + G01 = F33 + G02.
/// let c2 = SensorSet::new(Model::from_id("C2")?, &[Port::new(3, 0)])?;
/// let c4 = SensorSet::new(Model::from_id("C4")?, &[Port::new(3, 0)])?;
/// let v = sensor_set_distinguishability(&c2, &c4)?;
/// assert_eq!(
///     v,
///     SensorSetVerdict::Indistinguishable(IndistinguishableReason::IdenticalTransferFunctions {
///         renaming: ParameterRenaming::Identity,
///         factor: 1.into(),
///     })
/// );
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn sensor_set_distinguishability(
    a: &SensorSet,
    b: &SensorSet,
) -> Result<SensorSetVerdict, SensorSetError> {
    comparable(a, b)?;
    if a.first().gap() == b.first().gap() {
        let ra: Vec<Renamable> = a.models().iter().map(Renamable::new).collect();
        if let Some((renaming, factor)) = identical_tf_vectors(&ra, &b.transfer_functions()) {
            return Ok(SensorSetVerdict::Indistinguishable(
                IndistinguishableReason::IdenticalTransferFunctions { renaming, factor },
            ));
        }
    }
    // Vajda's criterion; the (cheap) form first, the ranks only if needed.
    if same_joint_form(&joint_invariants(a), &joint_invariants(b)) {
        let (ia, ib) = (sensor_set_identifiability(a), sensor_set_identifiability(b));
        if ia.structurally_equivalent_by_invariants(&ib) {
            return Ok(SensorSetVerdict::Indistinguishable(
                IndistinguishableReason::IndependentJointInvariants {
                    invariants: ia.nonconstant_invariants,
                },
            ));
        }
    }
    let probes = [
        Probe::new(a, b, Side::A, SEED_A),
        Probe::new(b, a, Side::B, SEED_B),
    ];
    // The cheap obstructions of both directions before any elimination.
    if let Some(w) = probes.iter().find_map(Probe::quick) {
        return Ok(SensorSetVerdict::Distinguishable(w));
    }
    // Small eliminations first: one pivot can run for minutes (from 4
    // masses on) while another decides in a second. Only a direction left
    // undecided is retried with the default limits.
    let small = Limits {
        max_terms: 300,
        ..Limits::default()
    };
    let mut outcomes: [Option<DirectionOutcome>; 2] = [None, None];
    for limits in [&small, &Limits::default()] {
        for (probe, outcome) in probes.iter().zip(outcomes.iter_mut()) {
            if matches!(outcome, Some(DirectionOutcome::Matched(_))) {
                continue;
            }
            match probe.full(limits) {
                Direction::Separated(w) => return Ok(SensorSetVerdict::Distinguishable(w)),
                Direction::Other(o) => *outcome = Some(o),
            }
        }
    }
    let [Some(a_by_b), Some(b_by_a)] = outcomes else {
        unreachable!("both directions ran")
    };
    Ok(match (a_by_b, b_by_a) {
        (DirectionOutcome::Matched(x), DirectionOutcome::Matched(y)) => {
            SensorSetVerdict::MatchedAtWitnessPoints {
                a_by_b: x,
                b_by_a: y,
            }
        }
        (x, y) => SensorSetVerdict::Undecided {
            a_by_b: x,
            b_by_a: y,
        },
    })
}

fn comparable(a: &SensorSet, b: &SensorSet) -> Result<(), SensorSetError> {
    if a.n_masses() != b.n_masses() {
        return Err(SensorSetError::DifferentMasses {
            a: a.n_masses(),
            b: b.n_masses(),
        });
    }
    if a.n_sensors() != b.n_sensors() {
        return Err(SensorSetError::DifferentSensorCounts {
            a: a.n_sensors(),
            b: b.n_sensors(),
        });
    }
    Ok(())
}

enum Direction {
    Separated(Box<DistinguishabilityWitness>),
    Other(DirectionOutcome),
}

/// A positive integer point in `1 ..= 1000` per parameter: small numbers
/// keep the back-solve's algebraic numbers small.
fn witness_point(n: usize, seed: u64) -> Vec<Rat> {
    let mut rng = XorShift::new(seed);
    (0..n)
        .map(|_| Rat::from((rng.next_u64() % 1000 + 1) as i64))
        .collect()
}

/// The transfer functions of `set` at `p`, as polynomials in `Omega`.
fn tfs_at(set: &SensorSet, p: &[Rat]) -> Vec<(Poly, Poly)> {
    let point: BTreeMap<String, Rat> = set.parameters().into_iter().zip(p.to_vec()).collect();
    let at = |q: &Poly| {
        let c: Vec<Poly> = q
            .coeffs_in(OMEGA)
            .iter()
            .map(|c| Poly::constant(c.eval(&point).expect("every parameter has a value")))
            .collect();
        Poly::from_coeffs_in(OMEGA, &c)
    };
    set.transfer_functions()
        .iter()
        .map(|tf| (at(&tf.num), at(&tf.den)))
        .collect()
}

fn ascending(p: &Poly) -> Vec<Rat> {
    p.coeffs_in(OMEGA)
        .iter()
        .map(|c| c.as_constant().unwrap_or(Rat::ZERO))
        .collect()
}

/// A pseudo-random point of `generating` against `other`.
struct Probe {
    side: Side,
    parameters: Vec<String>,
    point: Vec<Rat>,
    /// The generating transfer functions at the point, in `Omega`.
    at_p: Vec<(Poly, Poly)>,
    other_models: Vec<Model>,
    other_tfs: Vec<UndampedTf>,
}

impl Probe {
    fn new(generating: &SensorSet, other: &SensorSet, side: Side, seed: u64) -> Probe {
        let parameters = generating.parameters();
        let point = witness_point(parameters.len(), seed);
        Probe {
            side,
            at_p: tfs_at(generating, &point),
            parameters,
            point,
            other_models: other.models(),
            other_tfs: other.transfer_functions(),
        }
    }

    /// `sign * G_pivot(p)`.
    fn target(&self, pivot: usize, sign: i32) -> Target {
        let (num, den) = &self.at_p[pivot];
        let s = Rat::from(sign as i64);
        let n: Vec<Rat> = ascending(num).iter().map(|c| c * &s).collect();
        Target::new(n, ascending(den)).expect("a chain's inertance is not zero")
    }

    fn witness(
        &self,
        pivot: usize,
        obstructions: Vec<SignObstruction>,
        separations: Vec<Separation>,
    ) -> Box<DistinguishabilityWitness> {
        Box::new(DistinguishabilityWitness {
            generated_by: self.side,
            parameters: self.parameters.clone(),
            point: self.point.clone(),
            pivot,
            obstructions,
            separations,
        })
    }

    /// Pass 1, obstructions only (degrees, signs, invariant relations; no
    /// elimination, so cheap and deterministic): a sensor that no positive
    /// point of the other structure reproduces is a witness on its own, and
    /// spares the elimination (which takes seconds from 4 masses on).
    fn quick(&self) -> Option<Box<DistinguishabilityWitness>> {
        let limits = Limits {
            max_branches: 0,
            ..Limits::default()
        };
        (0..self.at_p.len()).find_map(|pivot| {
            let obstructions = [1, -1]
                .into_iter()
                .map(|sign| {
                    match back_solve_with(
                        &self.other_models[pivot],
                        &self.target(pivot, sign),
                        &limits,
                    ) {
                        Ok(BackSolution::NoSolution(r)) => Some(SignObstruction {
                            factor_sign: sign,
                            obstruction: Obstruction::from_no_solution(&r),
                        }),
                        _ => None,
                    }
                })
                .collect::<Option<Vec<_>>>()?;
            Some(self.witness(pivot, obstructions, Vec::new()))
        })
    }

    /// Pass 2: every positive point of the other structure reproducing a
    /// pivot (the sensors in order), each separated at another sensor; or
    /// an exact match, or why neither. `limits` bound each back-solve.
    fn full(&self, limits: &Limits) -> Direction {
        let side = self.side;
        let (other_tfs, at_p) = (&self.other_tfs, &self.at_p);
        let mut reasons = Vec::new();
        'pivot: for (pivot, other_model) in self.other_models.iter().enumerate() {
            let undecided = |kind| UndecidedReason {
                generated_by: side,
                pivot,
                kind,
            };
            let mut obstructions = Vec::new();
            let mut solutions: Vec<(i32, Solution)> = Vec::new();
            for sign in [1, -1] {
                match back_solve_with(other_model, &self.target(pivot, sign), limits) {
                    Ok(BackSolution::Points(points)) => {
                        solutions.extend(points.into_iter().map(|s| (sign, s)));
                    }
                    Ok(BackSolution::Families { families, .. }) => {
                        let dimension = families.iter().map(|f| f.dimension()).max().unwrap_or(0);
                        reasons.push(undecided(UndecidedKind::Family { dimension }));
                        continue 'pivot;
                    }
                    Ok(BackSolution::NoSolution(r)) => obstructions.push(SignObstruction {
                        factor_sign: sign,
                        obstruction: Obstruction::from_no_solution(&r),
                    }),
                    Err(e) => {
                        reasons.push(undecided(UndecidedKind::BackSolve(e.to_string())));
                        continue 'pivot;
                    }
                }
            }
            let mut separations = Vec::new();
            let mut stuck = None;
            let mut diffs: BTreeMap<i32, Vec<(usize, u32, Poly)>> = BTreeMap::new();
            for (sign, q) in &solutions {
                let d = diffs
                    .entry(*sign)
                    .or_insert_with(|| differences(other_tfs, at_p, pivot, *sign));
                match separate(*sign, q, d) {
                    Outcome::Separated(s) => separations.push(s),
                    Outcome::Matched(values) => {
                        return Direction::Other(DirectionOutcome::Matched(WitnessMatch {
                            generated_by: side,
                            point: self.point.clone(),
                            pivot,
                            factor_sign: *sign,
                            matching_point: values,
                        }));
                    }
                    Outcome::NotSeparated => {
                        stuck.get_or_insert_with(|| q.values.clone());
                    }
                }
            }
            if let Some(solution) = stuck {
                reasons.push(undecided(UndecidedKind::NotSeparated { solution }));
                continue;
            }
            return Direction::Separated(self.witness(pivot, obstructions, separations));
        }
        Direction::Other(DirectionOutcome::Undecided(reasons))
    }
}

/// The coefficients `D_ij` (polynomials in the other structure's
/// parameters) of every sensor `i` but the pivot, by sensor then power;
/// identically zero ones are left out (they cannot separate).
fn differences(
    other: &[UndampedTf],
    at_p: &[(Poly, Poly)],
    pivot: usize,
    sign: i32,
) -> Vec<(usize, u32, Poly)> {
    let s = Rat::from(sign as i64);
    let mut out = Vec::new();
    for (i, (tf, (num, den))) in other.iter().zip(at_p).enumerate() {
        if i == pivot {
            continue;
        }
        let d = &(&tf.num * den) - &(num * &tf.den).scale(&s);
        for (j, c) in d.coeffs_in(OMEGA).into_iter().enumerate() {
            if !c.is_zero() {
                out.push((i, j as u32, c));
            }
        }
    }
    out
}

enum Outcome {
    Separated(Separation),
    Matched(Vec<Rat>),
    NotSeparated,
}

/// An isolating interval of a real algebraic number that can be bisected.
struct Isolated {
    poly: UPoly,
    lo: Rat,
    hi: Rat,
}

impl Isolated {
    fn bisect(&mut self) {
        if self.lo == self.hi {
            return;
        }
        let m = &(&self.lo + &self.hi) / &Rat::from(2);
        let sm = self.poly.sign_at(&m);
        if sm == 0 {
            self.lo = m.clone();
            self.hi = m;
        } else if sm == self.poly.sign_at(&self.lo) {
            self.lo = m;
        } else {
            self.hi = m;
        }
    }
}

/// Interval enclosure of `p` over a box of positive parameters: each
/// monomial is monotone in each parameter, so it ranges over
/// `[prod lo^e, prod hi^e]` (times its coefficient).
fn enclose(p: &Poly, boxes: &BTreeMap<&str, (&Rat, &Rat)>) -> (Rat, Rat) {
    let ends: Vec<(&Rat, &Rat)> = p.vars().iter().map(|v| boxes[v.as_str()]).collect();
    let (mut lo, mut hi) = (Rat::ZERO, Rat::ZERO);
    for t in p.terms() {
        let (mut a, mut b) = (t.coef.clone(), t.coef.clone());
        for (&e, (l, h)) in t.exps.iter().zip(&ends) {
            if e > 0 {
                a = &a * &l.pow(e as i32);
                b = &b * &h.pow(e as i32);
            }
        }
        if t.coef.signum() < 0 {
            std::mem::swap(&mut a, &mut b);
        }
        lo = &lo + &a;
        hi = &hi + &b;
    }
    (lo, hi)
}

/// Separates one back-solved point `q` from the witness point: the first
/// coefficient (by sensor, then power) whose enclosure excludes 0, refining
/// the parameters' intervals as needed.
fn separate(sign: i32, q: &Solution, diffs: &[(usize, u32, Poly)]) -> Outcome {
    let mut params: Vec<Isolated> = q
        .exact
        .iter()
        .map(|x| Isolated {
            poly: x.poly.clone(),
            lo: x.lo.clone(),
            hi: x.hi.clone(),
        })
        .collect();
    for round in 0..=MAX_BISECTIONS {
        if params.iter().all(|x| x.lo.signum() > 0) {
            let boxes: BTreeMap<&str, (&Rat, &Rat)> = q
                .parameters
                .iter()
                .zip(&params)
                .map(|(n, x)| (n.as_str(), (&x.lo, &x.hi)))
                .collect();
            for (sensor, power, d) in diffs {
                let (lo, hi) = enclose(d, &boxes);
                if lo.signum() > 0 || hi.signum() < 0 {
                    return Outcome::Separated(Separation {
                        factor_sign: sign,
                        solution: q
                            .parameters
                            .iter()
                            .zip(&params)
                            .map(|(n, x)| ParameterEnclosure {
                                name: n.clone(),
                                minimal_polynomial: x.poly.clone(),
                                lo: x.lo.clone(),
                                hi: x.hi.clone(),
                            })
                            .collect(),
                        sensor: *sensor,
                        power: *power,
                        lo,
                        hi,
                    });
                }
            }
            if params.iter().all(|x| x.lo == x.hi) {
                // Exact values and no coefficient off zero: every one is 0.
                return Outcome::Matched(params.into_iter().map(|x| x.lo).collect());
            }
        }
        if round < MAX_BISECTIONS {
            params.iter_mut().for_each(Isolated::bisect);
        }
    }
    Outcome::NotSeparated
}

// ---------------------------------------------------------------------------
// The pairs table

/// Two models that one FRF cannot tell apart, a second sensor, and the
/// verdict for the two sensor sets (first sensor, `second`).
///
/// ```
/// let pairs = mms::sensors::two_sensor_pairs(3)?;
/// // A1 + m3 reads A3's FRF, A4 + m3 reads A5's: the second sensor alone
/// // tells them apart (numerator degrees 0 and 1).
/// assert!(pairs[0]
///     .to_string()
///     .starts_with("A1 / A4 + s3.0: distinguishable: at a point of A, sensor 2 alone"));
/// # Ok::<(), mms::ModelError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SensorPair {
    /// The first model (earlier in [`crate::rule3_models`] order).
    pub a: Model,
    /// The second model.
    pub b: Model,
    /// The second sensor, the same port on both chains.
    pub second: Port,
    /// The verdict for `a + second` against `b + second`.
    pub verdict: SensorSetVerdict,
}

impl fmt::Display for SensorPair {
    /// `A1 / A4 + s3.0: distinguishable: ...`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} / {} + s{}.{}: {}",
            self.a.name(),
            self.b.name(),
            self.second.plus,
            self.second.minus,
            self.verdict
        )
    }
}

/// For every pair of rule-(3) models of `n` masses that
/// [`crate::structural_equivalences`] groups together and every second
/// sensor port valid (rule (1)) on both chains that is neither model's own
/// sensor: the verdict of [`sensor_set_distinguishability`] for the two
/// two-sensor sets. Ordered by group, then pair (in model order), then
/// port.
///
/// 3 masses take milliseconds. 4 masses give 99 pairs and take minutes
/// (back-solves of up to a minute each); 4 of them stay
/// [`SensorSetVerdict::Undecided`]: irrational solutions that cannot be
/// separated (they may match exactly) or back-solves that stop at their
/// limits, one of them at the time budget, so that verdict can depend on
/// the machine's speed.
///
/// ```
/// use mms::sensors::two_sensor_pairs;
/// let pairs = two_sensor_pairs(3)?;
/// assert_eq!(pairs.len(), 14);
/// let c = pairs.iter().find(|p| p.a.name() == "C2").unwrap();
/// assert_eq!((c.b.name(), c.second), ("C4".to_string(), mms::Port::new(3, 0)));
/// assert_eq!(c.verdict.kind(), "indistinguishable");
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn two_sensor_pairs(n: usize) -> Result<Vec<SensorPair>, ModelError> {
    let models = rule3_models(n)?;
    let mut out = Vec::new();
    for group in structural_equivalences(&models) {
        let members = group.models();
        for (x, a) in members.iter().enumerate() {
            for b in &members[x + 1..] {
                // rule3_models order within the pair
                let (a, b) = if a <= b { (a, b) } else { (b, a) };
                for second in common_ports(a, b) {
                    let sa = SensorSet::new(*a, &[second]).expect("the port is valid on a");
                    let sb = SensorSet::new(*b, &[second]).expect("the port is valid on b");
                    let verdict = sensor_set_distinguishability(&sa, &sb)
                        .expect("same N and number of sensors");
                    out.push(SensorPair {
                        a: *a,
                        b: *b,
                        second,
                        verdict,
                    });
                }
            }
        }
    }
    Ok(out)
}

/// Ports valid on both chains (plus beyond both gaps, minus on both
/// grounded sides) that are neither model's sensor, in port order.
fn common_ports(a: &Model, b: &Model) -> Vec<Port> {
    let n = a.n_masses();
    let (lo_gap, hi_gap) = (a.gap().min(b.gap()), a.gap().max(b.gap()));
    let mut out = Vec::new();
    for plus in hi_gap + 1..=n {
        for minus in 0..=lo_gap {
            let p = Port::new(plus, minus);
            if p != a.sensor() && p != b.sensor() {
                out.push(p);
            }
        }
    }
    out
}

// ---------------------------------------------------------------------------
// The independent checker
//
// Shares nothing with the prover above but the models' transfer functions
// and `poly`: it encloses each transfer-function coefficient on its own and
// combines them by interval arithmetic, bisects with its own code, and
// re-derives the obstructions from the structure's polynomials. A bug in
// the prover cannot hide in the check.

/// Why a witness was rejected.
///
/// ```
/// use mms::sensors::WitnessError;
/// let e = WitnessError::Pivot(7);
/// assert_eq!(e.to_string(), "the pivot sensor 7 does not exist");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WitnessError {
    /// The sensor sets cannot be compared.
    #[error("the sensor sets cannot be compared: {0}")]
    Incomparable(#[from] SensorSetError),
    /// The point is not a positive point of the generating structure.
    #[error("bad witness point: {0}")]
    Point(String),
    /// The pivot index is out of range.
    #[error("the pivot sensor {0} does not exist")]
    Pivot(usize),
    /// A sign of the common factor is not accounted for exactly once.
    #[error("factor sign {sign}: {reason}")]
    Coverage {
        /// The sign.
        sign: i32,
        /// What is wrong.
        reason: String,
    },
    /// An obstruction does not hold.
    #[error("obstruction for factor sign {sign} does not hold: {reason}")]
    Obstruction {
        /// The sign.
        sign: i32,
        /// What is wrong.
        reason: String,
    },
    /// A separation does not hold.
    #[error("separation {index}: {reason}")]
    Separation {
        /// Index into [`DistinguishabilityWitness::separations`].
        index: usize,
        /// What is wrong.
        reason: String,
    },
}

/// What [`check_distinguishability_witness`] verified, and what it took
/// from the back-solve.
///
/// ```
/// use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // Encoders at m1 and m2; the force on m1 (A1) or on m2 (A4).
/// let a = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
/// let b = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// let c = mms::sensors::check_distinguishability_witness(&a, &b, &w)?;
/// assert_eq!((c.separations_verified, c.obstructions_verified, c.obstructions_trusted), (2, 1, 0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct WitnessCheck {
    /// Separations verified: box isolating, consistent with the pivot,
    /// coefficient enclosed away from 0.
    pub separations_verified: usize,
    /// Obstructions re-derived (degree, sign pattern, invariant relation).
    pub obstructions_verified: usize,
    /// Obstructions taken from the back-solve's elimination
    /// ([`Obstruction::NotPositive`], [`Obstruction::Contradiction`]).
    pub obstructions_trusted: usize,
}

/// Bisections the checker may add to a stored box.
const CHECK_BISECTIONS: usize = 96;

/// Checks a [`DistinguishabilityWitness`] for the sets `a` and `b` (in the
/// order they were compared) independently of the prover (see the
/// [module documentation](self)). Completeness of the back-solved list is
/// the back-solve's claim and is not re-checked.
///
/// ```
/// use mms::sensors::{check_distinguishability_witness, sensor_set_distinguishability, SensorSet, SensorSetVerdict};
/// use mms::{Model, Port};
/// // Encoders at m1 and m2; the force on m1 (A1) or on m2 (A4).
/// let a = SensorSet::new(Model::from_id("A1")?, &[Port::new(2, 0)])?;
/// let b = SensorSet::new(Model::from_id("A4")?, &[Port::new(1, 0)])?;
/// let SensorSetVerdict::Distinguishable(w) = sensor_set_distinguishability(&a, &b)? else { panic!() };
/// let check = check_distinguishability_witness(&a, &b, &w)?;
/// assert_eq!(check.separations_verified + check.obstructions_verified + check.obstructions_trusted,
///            w.separations.len() + w.obstructions.len());
/// let mut bad = (*w).clone();
/// bad.point[0] = &bad.point[0] + &poly::Rat::ONE; // another point: the stored solutions do not fit
/// assert!(check_distinguishability_witness(&a, &b, &bad).is_err());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn check_distinguishability_witness(
    a: &SensorSet,
    b: &SensorSet,
    w: &DistinguishabilityWitness,
) -> Result<WitnessCheck, WitnessError> {
    comparable(a, b)?;
    let (generating, other) = match w.generated_by {
        Side::A => (a, b),
        Side::B => (b, a),
    };
    let names = generating.first().undamped_parameters();
    if w.parameters != names {
        return Err(WitnessError::Point(format!(
            "parameters {:?}, expected {names:?}",
            w.parameters
        )));
    }
    if w.point.len() != names.len() || w.point.iter().any(|x| x.signum() <= 0) {
        return Err(WitnessError::Point(
            "one positive value per parameter expected".into(),
        ));
    }
    if w.pivot >= generating.n_sensors() {
        return Err(WitnessError::Pivot(w.pivot));
    }
    let at: BTreeMap<String, Rat> = names.iter().cloned().zip(w.point.clone()).collect();
    // Generating side: exact coefficients, ascending powers.
    let gen: Vec<(Vec<Rat>, Vec<Rat>)> = generating
        .models()
        .iter()
        .map(|m| {
            let tf = m.undamped_tf();
            let ev = |p: &Poly| -> Vec<Rat> {
                p.coeffs_in(OMEGA)
                    .iter()
                    .map(|c| c.eval(&at).expect("all parameters set"))
                    .collect()
            };
            (ev(&tf.num), ev(&tf.den))
        })
        .collect();
    // Other side: coefficient polynomials, ascending powers.
    let oth: Vec<(Vec<Poly>, Vec<Poly>)> = other
        .models()
        .iter()
        .map(|m| {
            let tf = m.undamped_tf();
            (tf.num.coeffs_in(OMEGA), tf.den.coeffs_in(OMEGA))
        })
        .collect();
    for sign in [1, -1] {
        let obs = w
            .obstructions
            .iter()
            .filter(|o| o.factor_sign == sign)
            .count();
        let seps = w
            .separations
            .iter()
            .filter(|s| s.factor_sign == sign)
            .count();
        if !((obs == 1 && seps == 0) || (obs == 0 && seps > 0)) {
            return Err(WitnessError::Coverage {
                sign,
                reason: format!("{obs} obstruction(s) and {seps} separation(s)"),
            });
        }
    }
    if let Some(x) = w
        .obstructions
        .iter()
        .map(|o| o.factor_sign)
        .chain(w.separations.iter().map(|s| s.factor_sign))
        .find(|s| *s != 1 && *s != -1)
    {
        return Err(WitnessError::Coverage {
            sign: x,
            reason: "a factor sign is +1 or -1".into(),
        });
    }
    let mut check = WitnessCheck {
        separations_verified: 0,
        obstructions_verified: 0,
        obstructions_trusted: 0,
    };
    for o in &w.obstructions {
        let err = |reason: String| WitnessError::Obstruction {
            sign: o.factor_sign,
            reason,
        };
        let (gn, gd) = &gen[w.pivot];
        let (on, od) = &oth[w.pivot];
        if check_obstruction(&o.obstruction, o.factor_sign, gn, gd, on, od).map_err(err)? {
            check.obstructions_verified += 1;
        } else {
            check.obstructions_trusted += 1;
        }
    }
    let other_names = other.parameters();
    for (index, s) in w.separations.iter().enumerate() {
        check_separation(s, w.pivot, &other_names, &gen, &oth)
            .map_err(|reason| WitnessError::Separation { index, reason })?;
        check.separations_verified += 1;
    }
    Ok(check)
}

/// `sign * gn / gd` in lowest terms, `lc(den) > 0`, ascending coefficients.
fn checker_target(sign: i32, gn: &[Rat], gd: &[Rat]) -> (Vec<Rat>, Vec<Rat>) {
    let s = Rat::from(sign as i64);
    let to_poly = |v: &[Rat], f: &Rat| {
        let c: Vec<Poly> = v.iter().map(|x| Poly::constant(x * f)).collect();
        Poly::from_coeffs_in(OMEGA, &c)
    };
    let (n, d) = (to_poly(gn, &s), to_poly(gd, &Rat::ONE));
    let g = poly::gcd(&n, &d);
    let (n, d) = (
        n.div_exact(&g).expect("gcd divides"),
        d.div_exact(&g).expect("gcd divides"),
    );
    let coeffs = |p: &Poly| -> Vec<Rat> {
        p.coeffs_in(OMEGA)
            .iter()
            .map(|c| c.as_constant().unwrap_or(Rat::ZERO))
            .collect()
    };
    let (mut n, mut d) = (coeffs(&n), coeffs(&d));
    if d.last().is_some_and(|x| x.signum() < 0) {
        n.iter_mut().for_each(|x| *x = -x.clone());
        d.iter_mut().for_each(|x| *x = -x.clone());
    }
    (n, d)
}

/// `Some(+1/-1)` when every coefficient of `p` has that sign, `Some(0)` for
/// the zero polynomial, `None` otherwise.
fn fixed_sign(p: Option<&Poly>) -> Option<i32> {
    let Some(p) = p.filter(|p| !p.is_zero()) else {
        return Some(0);
    };
    let signs: Vec<i32> = p.terms().iter().map(|t| t.coef.signum()).collect();
    if signs.iter().all(|&s| s > 0) {
        Some(1)
    } else if signs.iter().all(|&s| s < 0) {
        Some(-1)
    } else {
        None
    }
}

/// Re-derives an obstruction: `Ok(true)` verified, `Ok(false)` one only the
/// elimination gives (trusted), `Err` when the claim is false.
fn check_obstruction(
    o: &Obstruction,
    sign: i32,
    gn: &[Rat],
    gd: &[Rat],
    on: &[Poly],
    od: &[Poly],
) -> Result<bool, String> {
    let (tn, td) = checker_target(sign, gn, gd);
    let (tdn, tdd) = (tn.len() - 1, td.len() - 1);
    let (sn, sd) = (on.len() - 1, od.len() - 1);
    // deg den of the structure is fixed: its top coefficient is a product
    // of masses; everything below relies on it.
    if fixed_sign(od.last()) != Some(1) {
        return Err("the structure's leading denominator coefficient is not positive".into());
    }
    match o {
        Obstruction::Degree { structure, target } => {
            if *structure != (sn, sd) || *target != (tdn, tdd) {
                return Err(format!(
                    "degrees are structure {:?}, target {:?}",
                    (sn, sd),
                    (tdn, tdd)
                ));
            }
            // A cancellation lowers both degrees alike and the numerator's
            // top may vanish, so the relative degree can only grow; with a
            // numerator top of fixed sign it is fixed.
            let rel_s = sd as i64 - sn as i64;
            let rel_t = tdd as i64 - tdn as i64;
            let num_top_fixed = matches!(fixed_sign(on.last()), Some(s) if s != 0);
            let impossible =
                tdd > sd || tdn > sn || rel_t < rel_s || (num_top_fixed && rel_t != rel_s);
            if impossible {
                Ok(true)
            } else {
                Err("these degrees are possible".into())
            }
        }
        Obstruction::SignPattern {
            part,
            power,
            structure_sign,
            target_sign,
        } => {
            // Equal denominator degrees: num_S = l*n, den_S = l*d with
            // l = lc(den_S)/lc(d) > 0, so every coefficient keeps its sign.
            if tdd != sd {
                return Err("the target has a lower denominator degree".into());
            }
            let (sv, tv) = match part {
                TfPart::Numerator => (on, &tn),
                TfPart::Denominator => (od, &td),
            };
            let k = *power as usize;
            let ss = fixed_sign(sv.get(k)).ok_or("the coefficient has no fixed sign")?;
            let ts = tv.get(k).map_or(0, Rat::signum);
            if ss != *structure_sign || ts != *target_sign {
                return Err(format!("signs are structure {ss}, target {ts}"));
            }
            if ss == ts {
                return Err("the signs agree".into());
            }
            Ok(true)
        }
        Obstruction::ViolatedRelation { relation, value } => {
            if tdd != sd {
                return Err("the target has a lower denominator degree".into());
            }
            // R(coefficients of the structure) == 0 identically and R
            // homogeneous: then R(l*n, l*d) = l^e R(n, d) = 0 for a match.
            let degrees: Vec<u32> = relation
                .terms()
                .iter()
                .map(|t| t.exps.iter().sum())
                .collect();
            if degrees.windows(2).any(|w| w[0] != w[1]) {
                return Err("the relation is not homogeneous".into());
            }
            let slot = |v: &str| -> Option<(bool, usize)> {
                let (is_num, k) = if let Some(k) = v.strip_prefix('n') {
                    (true, k)
                } else {
                    (false, v.strip_prefix('d')?)
                };
                Some((is_num, k.parse().ok()?))
            };
            let mut symbolic = relation.clone();
            let mut at_target = BTreeMap::new();
            for v in relation.vars() {
                let (is_num, k) = slot(v).ok_or(format!("unknown variable {v}"))?;
                let (sv, tv) = if is_num { (on, &tn) } else { (od, &td) };
                let c = sv.get(k).cloned().unwrap_or_else(Poly::zero);
                // The structure's coefficients hold no variable named like
                // a slot (no dampers in the undamped model).
                symbolic = symbolic.subs_poly(v, &c);
                at_target.insert(v.clone(), tv.get(k).cloned().unwrap_or(Rat::ZERO));
            }
            if !symbolic.is_zero() {
                return Err("the relation does not hold on the structure".into());
            }
            let r = relation.eval(&at_target).map_err(|e| e.to_string())?;
            // Our normal form differs from the stored one by a positive factor.
            if r.is_zero() || r.signum() != value.signum() {
                return Err(format!("the relation's value at the target is {r}"));
            }
            Ok(true)
        }
        Obstruction::NotPositive { .. } | Obstruction::Contradiction => Ok(false),
    }
}

/// A box parameter in the checker: the root of `poly` in `[lo, hi]`.
#[derive(Clone)]
struct CheckBox {
    poly: UPoly,
    lo: Rat,
    hi: Rat,
}

fn halve(b: &mut CheckBox) {
    if b.lo == b.hi {
        return;
    }
    let mid = &(&b.lo + &b.hi) / &Rat::from(2);
    let s_mid = b.poly.sign_at(&mid);
    if s_mid == 0 {
        b.lo = mid.clone();
        b.hi = mid;
    } else if s_mid * b.poly.sign_at(&b.hi) < 0 {
        b.lo = mid;
    } else {
        b.hi = mid;
    }
}

/// Range of the polynomial `p` over the box (positive ends): term by term,
/// each monomial between its values at the lower and the upper corner.
fn range(p: &Poly, at: &BTreeMap<String, CheckBox>) -> (Rat, Rat) {
    let mut lo = Rat::ZERO;
    let mut hi = Rat::ZERO;
    for t in p.terms() {
        let mut low_corner = Rat::ONE;
        let mut high_corner = Rat::ONE;
        for (v, &e) in p.vars().iter().zip(&t.exps) {
            let b = &at[v];
            for _ in 0..e {
                low_corner = &low_corner * &b.lo;
                high_corner = &high_corner * &b.hi;
            }
        }
        let x = &t.coef * &low_corner;
        let y = &t.coef * &high_corner;
        let (a, c) = if x <= y { (x, y) } else { (y, x) };
        lo = &lo + &a;
        hi = &hi + &c;
    }
    (lo, hi)
}

/// `sum_k [lo_k, hi_k] * r_k` by interval arithmetic.
fn dot(iv: &[(Rat, Rat)], r: &[Rat], j: usize) -> (Rat, Rat) {
    let mut lo = Rat::ZERO;
    let mut hi = Rat::ZERO;
    for (k, (a, b)) in iv.iter().enumerate() {
        if k > j || j - k >= r.len() {
            continue;
        }
        let f = &r[j - k];
        let (x, y) = (a * f, b * f);
        let (x, y) = if x <= y { (x, y) } else { (y, x) };
        lo = &lo + &x;
        hi = &hi + &y;
    }
    (lo, hi)
}

/// Enclosure of the coefficient of `Omega^j` of
/// `num_o(q) * den_g - sign * num_g * den_o(q)` over the box.
fn difference_range(
    sign: i32,
    other: &(Vec<Poly>, Vec<Poly>),
    gen: &(Vec<Rat>, Vec<Rat>),
    j: usize,
    at: &BTreeMap<String, CheckBox>,
) -> (Rat, Rat) {
    let num_o: Vec<(Rat, Rat)> = other.0.iter().map(|c| range(c, at)).collect();
    let den_o: Vec<(Rat, Rat)> = other.1.iter().map(|c| range(c, at)).collect();
    let (a_lo, a_hi) = dot(&num_o, &gen.1, j);
    let (b_lo, b_hi) = dot(&den_o, &gen.0, j);
    // a - sign * b
    if sign > 0 {
        (&a_lo - &b_hi, &a_hi - &b_lo)
    } else {
        (&a_lo + &b_lo, &a_hi + &b_hi)
    }
}

fn check_separation(
    s: &Separation,
    pivot: usize,
    names: &[String],
    gen: &[(Vec<Rat>, Vec<Rat>)],
    oth: &[(Vec<Poly>, Vec<Poly>)],
) -> Result<(), String> {
    let stored: Vec<&String> = s.solution.iter().map(|e| &e.name).collect();
    if stored.len() != names.len() || stored.iter().zip(names).any(|(a, b)| *a != b) {
        return Err(format!("parameters {stored:?}, expected {names:?}"));
    }
    let mut at: BTreeMap<String, CheckBox> = BTreeMap::new();
    for e in &s.solution {
        let p = &e.minimal_polynomial;
        let ok = if e.lo == e.hi {
            p.degree().is_some_and(|d| d >= 1) && p.sign_at(&e.lo) == 0
        } else {
            e.lo < e.hi
                && p.sign_at(&e.lo) != 0
                && p.sign_at(&e.hi) != 0
                && count_roots_in(p, &e.lo, &e.hi) == 1
        };
        if !ok {
            return Err(format!(
                "[{}, {}] does not isolate one root of {} for {}",
                e.lo,
                e.hi,
                p.to_text("x"),
                e.name
            ));
        }
        if e.lo.signum() <= 0 {
            return Err(format!("{} is not enclosed in positive numbers", e.name));
        }
        at.insert(
            e.name.clone(),
            CheckBox {
                poly: p.clone(),
                lo: e.lo.clone(),
                hi: e.hi.clone(),
            },
        );
    }
    if s.sensor == pivot || s.sensor >= gen.len() {
        return Err(format!("sensor {} cannot separate", s.sensor));
    }
    // Consistent with the pivot: a solution's pivot difference is 0, so
    // every enclosure of it contains 0.
    let coefficients =
        |i: usize| (oth[i].0.len() + gen[i].1.len()).max(oth[i].1.len() + gen[i].0.len()) - 1;
    for j in 0..coefficients(pivot) {
        let (lo, hi) = difference_range(s.factor_sign, &oth[pivot], &gen[pivot], j, &at);
        if lo.signum() > 0 || hi.signum() < 0 {
            return Err(format!(
                "the point does not reproduce the pivot sensor (Omega^{j} in [{lo}, {hi}])"
            ));
        }
    }
    if s.lo > s.hi || (s.lo.signum() <= 0 && s.hi.signum() >= 0) {
        return Err(format!(
            "the stored interval [{}, {}] contains 0",
            s.lo, s.hi
        ));
    }
    let j = s.power as usize;
    for _ in 0..=CHECK_BISECTIONS {
        let (lo, hi) = difference_range(s.factor_sign, &oth[s.sensor], &gen[s.sensor], j, &at);
        if hi < s.lo || lo > s.hi {
            return Err(format!(
                "the coefficient lies in [{lo}, {hi}], outside the stored [{}, {}]",
                s.lo, s.hi
            ));
        }
        if lo.signum() > 0 || hi.signum() < 0 {
            return if lo.signum() == s.lo.signum() {
                Ok(())
            } else {
                Err("the coefficient has the other sign".into())
            };
        }
        at.values_mut().for_each(halve);
    }
    Err(format!(
        "Omega^{j} of sensor {} is not enclosed away from 0",
        s.sensor
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficient_labels_parse() {
        assert_eq!(
            parse_coefficient("Num Omega^2"),
            Some((TfPart::Numerator, 2))
        );
        assert_eq!(
            parse_coefficient("Den Omega^0"),
            Some((TfPart::Denominator, 0))
        );
        assert_eq!(parse_coefficient("Num w^2"), None);
    }

    #[test]
    fn enclosures_agree_on_exact_points() {
        // At a degenerate box both enclosures are the exact value.
        let p: Poly = "3*m1^2*c12 - 2*m2 + 5".parse().unwrap();
        let v = |x: i64| Rat::from(x);
        let (r1, r2) = (v(2), v(7));
        let m: BTreeMap<&str, (&Rat, &Rat)> =
            [("m1", (&r1, &r1)), ("c12", (&r2, &r2)), ("m2", (&r2, &r2))]
                .into_iter()
                .collect();
        let exact = v(3 * 4 * 7 - 2 * 7 + 5);
        assert_eq!(enclose(&p, &m), (exact.clone(), exact.clone()));
        let b = |x: &Rat| CheckBox {
            poly: UPoly::linear_root(x),
            lo: x.clone(),
            hi: x.clone(),
        };
        let at: BTreeMap<String, CheckBox> = [("m1", b(&r1)), ("c12", b(&r2)), ("m2", b(&r2))]
            .into_iter()
            .map(|(k, x)| (k.to_string(), x))
            .collect();
        assert_eq!(range(&p, &at), (exact.clone(), exact));
    }

    #[test]
    fn bisection_keeps_the_root() {
        // sqrt(2) in [1, 2]
        let p = UPoly::from_i64s(&[-2, 0, 1]);
        let mut a = Isolated {
            poly: p.clone(),
            lo: Rat::from(1),
            hi: Rat::from(2),
        };
        let mut b = CheckBox {
            poly: p,
            lo: Rat::from(1),
            hi: Rat::from(2),
        };
        for _ in 0..30 {
            a.bisect();
            halve(&mut b);
        }
        assert_eq!((&a.lo, &a.hi), (&b.lo, &b.hi));
        let s = std::f64::consts::SQRT_2;
        assert!(a.lo.to_f64() <= s && s <= a.hi.to_f64());
        assert!(a.hi.to_f64() - a.lo.to_f64() < 1e-8);
    }
}
