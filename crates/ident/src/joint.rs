//! Identification from several sensors on one chain: a motor and a load
//! encoder, or any outputs recorded with the same input. Each output names
//! where its sensor sits in the chain ([`SensorLocation`]); every candidate
//! structure (masses, gap, actuator, and the sensors at those locations)
//! is fitted to all outputs at once with one parameter set
//! ([`crate::fit::fit_outputs`]), and ranked by the pooled error. The same
//! candidates fitted to the first output alone show what one sensor could
//! not tell apart; the candidates the other outputs rule out are listed
//! ([`SensorsIdentification::ruled_out`]).
//!
//! Masses are counted from the ground side as everywhere in `mms` (for a
//! free chain, from the end the numbering starts at); `N` stands for the
//! last mass of whichever chain is tried.
//!
//! ```
//! use frf::Frf;
//! use ident::identify::IdentifyOptions;
//! use ident::joint::{identify_sensors, SensorOutput};
//! use mms::response::ChainResponse;
//! use mms::{Model, Output, Port};
//!
//! // A free two-mass drive read at the motor (mass 1) and the load (mass 2).
//! let motor = Model::new(2, 0, Port::new(1, 0), Port::new(1, 0))?;
//! let load = Model::new(2, 0, Port::new(1, 0), Port::new(2, 0))?;
//! let truth = [0.02, 0.05, 3000.0, 0.2];
//! let f: Vec<f64> = (0..600).map(|k| 2.0 * 1.008f64.powi(k)).collect();
//! let frf = |m: &Model| -> Result<Frf, Box<dyn std::error::Error>> {
//!     let h = ChainResponse::new(m, Output::Position).eval_many(&truth, &f)?;
//!     Ok(Frf::new(f.clone(), h, None)?)
//! };
//! let (h1, h2) = (frf(&motor)?, frf(&load)?);
//! let outputs = [
//!     SensorOutput { name: "motor".into(), frf: &h1, location: Some("1".parse()?) },
//!     SensorOutput { name: "load".into(), frf: &h2, location: Some("N".parse()?) },
//! ];
//! let id = identify_sensors(&outputs, Output::Position, &IdentifyOptions::default())?;
//! assert_eq!(id.candidates[0].id, "N2-g0-a1.0-s1.0+s2.0");
//! assert!(id.candidates[0].fit.rms_db < 0.01);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::classify::Classification;
use crate::fit::{fit_outputs, Fit, FitOptions, Gain};
use crate::identify::{
    back_solution, fit_candidate, fit_options, groups, mean_damping, measured, score,
    undamped_starts, with_dampers, IdentifyError, IdentifyOptions, Measured, Progress,
};
use crate::notes::SensorsNote;
use frf::Frf;
use mms::analysis::{analyze, SearchLimits, Status};
use mms::response::Parameters;
use mms::sensors::{sensor_set_distinguishability, SensorSet, SensorSetVerdict};
use mms::{Model, Output, Port};
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

/// A mass of the chain: its number from the ground side, or the last.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum MassRef {
    /// Mass `k` (from 1); 0 is the ground.
    Mass(usize),
    /// The last mass of the chain, whatever its number.
    Last,
}

/// Where a sensor sits in the chain: it reads the motion of mass `plus`
/// relative to `minus` (0: the ground), as [`Port`] does, with `plus`
/// possibly the last mass of whichever chain is tried.
///
/// ```
/// use ident::joint::{MassRef, SensorLocation};
/// let load: SensorLocation = "N".parse()?;
/// assert_eq!(load.plus, MassRef::Last);
/// assert_eq!(load.port(3).map(|p| (p.plus, p.minus)), Some((3, 0)));
/// let relative: SensorLocation = "3.1".parse()?;
/// assert_eq!(relative.to_string(), "3.1");
/// assert!("0".parse::<SensorLocation>().is_err());
/// # Ok::<(), ident::joint::LocationError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SensorLocation {
    /// The mass read.
    pub plus: MassRef,
    /// The reference: a mass, or 0 for the ground.
    pub minus: usize,
}

/// A sensor location that cannot be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("sensor location '{0}': expected PLUS[.MINUS] with PLUS a mass from 1 or N (the last mass), MINUS a mass or 0 (the ground)")]
pub struct LocationError(pub String);

impl FromStr for SensorLocation {
    type Err = LocationError;
    fn from_str(s: &str) -> Result<SensorLocation, LocationError> {
        let bad = || LocationError(s.to_string());
        let t = s.trim();
        let (plus, minus) = match t.split_once('.') {
            Some((a, b)) => (a, Some(b)),
            None => (t, None),
        };
        let plus = match plus {
            "N" | "n" => MassRef::Last,
            p => match p.parse::<usize>() {
                Ok(k) if k >= 1 => MassRef::Mass(k),
                _ => return Err(bad()),
            },
        };
        let minus = match minus {
            None => 0,
            Some(m) => m.parse::<usize>().map_err(|_| bad())?,
        };
        if let MassRef::Mass(k) = plus {
            if minus >= k {
                return Err(bad());
            }
        }
        Ok(SensorLocation { plus, minus })
    }
}

impl From<Port> for SensorLocation {
    /// The place of a sensor port: its masses by number.
    fn from(p: Port) -> SensorLocation {
        SensorLocation {
            plus: MassRef::Mass(p.plus),
            minus: p.minus,
        }
    }
}

impl fmt::Display for SensorLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.plus {
            MassRef::Mass(k) => write!(f, "{k}")?,
            MassRef::Last => f.write_str("N")?,
        }
        if self.minus > 0 {
            write!(f, ".{}", self.minus)?;
        }
        Ok(())
    }
}

impl Serialize for SensorLocation {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

impl SensorLocation {
    /// The fewest masses a chain with a sensor here has: the mass read, or
    /// one more than the reference when that is the last mass.
    ///
    /// ```
    /// use ident::joint::SensorLocation;
    /// assert_eq!("3".parse::<SensorLocation>()?.min_masses(), 3);
    /// assert_eq!("N.2".parse::<SensorLocation>()?.min_masses(), 3);
    /// assert_eq!("N".parse::<SensorLocation>()?.min_masses(), 1);
    /// # Ok::<(), ident::joint::LocationError>(())
    /// ```
    pub fn min_masses(&self) -> usize {
        match self.plus {
            MassRef::Mass(k) => k,
            MassRef::Last => self.minus + 1,
        }
    }

    /// The port in a chain of `masses` masses (`None` if the location lies
    /// outside it).
    pub fn port(&self, masses: usize) -> Option<Port> {
        let plus = match self.plus {
            MassRef::Mass(k) => k,
            MassRef::Last => masses,
        };
        (plus <= masses && self.minus < plus).then(|| Port::new(plus, self.minus))
    }
}

/// One measured output: a name for the report, its FRF (same input as the
/// others) and where its sensor sits (`None`: anywhere the structure
/// allows, as for a single recording).
#[derive(Clone, Debug)]
pub struct SensorOutput<'a> {
    /// The output's name (e.g. the signal it was estimated from).
    pub name: String,
    /// Its FRF from the common input.
    pub frf: &'a Frf,
    /// Its sensor's location in the chain.
    pub location: Option<SensorLocation>,
}

/// What the classification found in one output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputReading {
    /// The output's name.
    pub name: String,
    /// Its sensor's location (`None`: free).
    pub location: Option<SensorLocation>,
    /// Its type, features and band.
    pub classification: Classification,
    /// Below its features the output counts the other way (its FRF was
    /// turned before the joint fit).
    pub sensor_reversed: bool,
}

/// One candidate: a chain with its actuator, read by one sensor per output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SensorsCandidate {
    /// The first output's structure ID, `+s<port>` for each further sensor
    /// (e.g. `N2-g0-a1.0-s1.0+s2.0`).
    pub id: String,
    /// The structure each output reads, in the order of the outputs.
    #[serde(skip)]
    pub models: Vec<Model>,
    /// The joint fit: one parameter set and gain, errors over every line.
    pub fit: Fit,
    /// Each output's RMS errors under the joint fit: `(dB, degrees)`.
    pub per_output: Vec<(f64, f64)>,
    /// RMS of `ln(G/H)` over all outputs in dB-equivalent (the ranking).
    pub score_db: f64,
    /// The same structure fitted to the first output alone.
    pub first_output_score_db: f64,
    /// 1 for the best.
    pub rank: usize,
    /// A parameter ended at an end of its physical range: the fit
    /// degenerated into another structure, so it failed as this one.
    /// Such fits are ranked after every fit that did not fail.
    pub failed: bool,
}

/// A structure the first output alone could not rule out and the others
/// do.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RuledOut {
    /// The candidate's ID.
    pub id: String,
    /// How the other outputs rule it out.
    pub by: RuledOutBy,
}

/// How further outputs rule a candidate out.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RuledOutBy {
    /// The exact type table: with this chain, the sensor of output `output`
    /// (counted from 0) cannot show the type classified there (up to 3
    /// masses; above, the degrees of its transfer function).
    Type {
        /// The output, counted from 0.
        output: usize,
    },
    /// The joint fit: its score is worse than the best's by `excess_db`,
    /// beyond the tolerance.
    Fit {
        /// The score above the best candidate's, dB-equivalent.
        excess_db: f64,
    },
}

/// The result of [`identify_sensors`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SensorsIdentification {
    /// Number of masses of the candidates.
    pub masses: usize,
    /// Each output's classification, in the order given.
    pub outputs: Vec<OutputReading>,
    /// Every candidate, best first.
    pub candidates: Vec<SensorsCandidate>,
    /// Groups of candidates whose joint fits are equally good (the first
    /// group holds the best).
    pub indistinguishable: Vec<Vec<String>>,
    /// The candidates whose fit to the first output alone is as good as the
    /// best one's: what that sensor alone could not tell apart.
    pub first_output_alone: Vec<String>,
    /// Those of `first_output_alone` that the other outputs rule out, and
    /// how.
    pub ruled_out: Vec<RuledOut>,
    /// The best candidate against each other one that the first output
    /// alone or the joint fit leaves beside it, decided exactly with every
    /// output's sensor (`mms::sensors`; up to 3 masses).
    pub exact: Vec<ExactComparison>,
    /// How the candidates were chosen, what was not fitted, and the like.
    pub notes: Vec<SensorsNote>,
}

/// The best candidate against another, decided exactly with the sensors of
/// every output: whether any parameter set of the other reproduces every
/// output of the best at once.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExactComparison {
    /// The other candidate.
    pub id: String,
    /// The exact verdict, with its proof or witness.
    pub verdict: SensorSetVerdict,
}

impl ExactComparison {
    /// The other candidate cannot be told from the best with these
    /// sensors: proven, or matched exactly at the witness points.
    pub fn indistinguishable(&self) -> bool {
        matches!(
            self.verdict,
            SensorSetVerdict::Indistinguishable(_)
                | SensorSetVerdict::MatchedAtWitnessPoints { .. }
        )
    }
}

/// Most masses for which [`identify_sensors`] decides the exact
/// comparisons (their cost grows fast with the chain).
pub const EXACT_MAX_MASSES: usize = 3;

/// Identifies one chain from several outputs (see the module docs).
pub fn identify_sensors(
    outputs: &[SensorOutput],
    output: Output,
    options: &IdentifyOptions,
) -> Result<SensorsIdentification, IdentifyError> {
    identify_sensors_with_progress(outputs, output, options, &|_| {})
}

/// [`identify_sensors`], reporting each jointly fitted candidate to
/// `progress`.
pub fn identify_sensors_with_progress(
    outputs: &[SensorOutput],
    output: Output,
    options: &IdentifyOptions,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<SensorsIdentification, IdentifyError> {
    if outputs.is_empty() {
        return Err(IdentifyError::Outputs("no output given".into()));
    }
    let mut notes = Vec::new();
    let mut readings = Vec::with_capacity(outputs.len());
    let mut measured_outputs: Vec<Measured> = Vec::with_capacity(outputs.len());
    for o in outputs {
        let m = measured(o.frf, output, options)?;
        readings.push(OutputReading {
            name: o.name.clone(),
            location: o.location,
            classification: m.classification.clone(),
            sensor_reversed: m.sensor_reversed,
        });
        measured_outputs.push(m);
    }
    let resonances: Vec<usize> = readings
        .iter()
        .map(|r| r.classification.frf_type.resonances() as usize)
        .collect();
    let most = resonances.iter().copied().max().unwrap_or(0);
    // A sensor placed at mass k says the chain has at least k masses,
    // whatever the types read (a pair of features below the line spacing
    // is missed there).
    let placed = outputs
        .iter()
        .filter_map(|o| o.location.map(|l| l.min_masses()))
        .max()
        .unwrap_or(0);
    let masses = options.masses.unwrap_or((most + 1).max(placed));
    // Too many features read is said as such, before the count they
    // imply is checked against what a chain can have.
    if options.masses.is_none() && most + 1 > crate::identify::INFERRED_MAX_MASSES {
        return Err(IdentifyError::TooManyFeatures {
            masses: most + 1,
            frf_type: readings
                .iter()
                .max_by_key(|r| r.classification.frf_type.resonances())
                .map(|r| r.classification.frf_type.to_string())
                .unwrap_or_default(),
        });
    }
    if masses == 0 || masses > mms::MAX_MASSES {
        return Err(IdentifyError::Masses(masses));
    }
    for (o, r) in outputs.iter().zip(&readings) {
        if let Some(loc) = o.location {
            if loc.port(masses).is_none() {
                return Err(IdentifyError::Outputs(format!(
                    "{}: sensor location {loc} lies outside a chain of {masses} masses",
                    r.name
                )));
            }
        }
    }
    let tuples = candidates(masses, outputs, &readings, most);
    if tuples.is_empty() {
        return Err(IdentifyError::Outputs(format!(
            "no chain of {masses} masses has its sensors at these locations"
        )));
    }
    // Jointly fitted: the tuples whose every output can show its type;
    // compared on the first output alone: those whose first can.
    let joint_ok = |t: &Tuple| t.shows.iter().all(|&ok| ok);
    let filtered = tuples.iter().any(joint_ok);
    let first_filtered = tuples.iter().any(|t| t.shows[0]);
    if options.masses.is_none() && placed > most + 1 {
        notes.push(SensorsNote::MassesFromSensorPlaces {
            masses,
            from_types: most + 1,
        });
    }
    notes.push(if filtered {
        SensorsNote::CandidatesShowingTypes { masses }
    } else {
        SensorsNote::NoChainShowsTypes { masses }
    });
    let candidates: Vec<Vec<Model>> = tuples
        .iter()
        .filter(|t| !filtered || joint_ok(t))
        .map(|t| t.models.clone())
        .collect();
    let first_only: Vec<&Tuple> = tuples
        .iter()
        .filter(|t| filtered && !joint_ok(t) && (t.shows[0] || !first_filtered))
        .collect();
    // The joint fit sees each output's informative lines, turned where
    // the output counts the other way, with the caller's gain.
    let turned: Vec<Frf> = measured_outputs
        .iter()
        .map(|m| {
            if m.sensor_reversed {
                m.data.negated()
            } else {
                m.data.clone()
            }
        })
        .collect();
    let zetas: Vec<f64> = measured_outputs
        .iter()
        .map(|m| mean_damping(&m.classification))
        .collect();
    let positive = IdentifyOptions {
        gain: match options.gain {
            Gain::Known(g) => Gain::Known(g.abs()),
            Gain::Fit(g) => Gain::Fit(g.abs()),
        },
        ..options.clone()
    };
    let fit_opts: FitOptions = fit_options(&positive, 200);
    // Single-output fits, each structure once (the first output's are the
    // comparison; every output's are starts of the joint fits).
    let mut single: BTreeMap<(usize, Model), Option<Fit>> = BTreeMap::new();
    let first_models: Vec<Vec<Model>> = first_only.iter().map(|t| vec![t.models[0]]).collect();
    for models in candidates.iter().chain(&first_models) {
        for (i, m) in models.iter().enumerate() {
            single.entry((i, *m)).or_insert_with(|| {
                fit_candidate(
                    m,
                    output,
                    &turned[i],
                    measured_outputs[i].target.as_ref(),
                    zetas[i],
                    &positive,
                )
                .ok()
                .map(|r| r.0)
            });
        }
    }
    let mut fits: Vec<SensorsCandidate> = Vec::new();
    for (done, models) in candidates.iter().enumerate() {
        progress(Progress {
            done,
            total: candidates.len(),
        });
        let id = candidate_id(models);
        let channels: Vec<(Model, &Frf)> = models.iter().copied().zip(turned.iter()).collect();
        let mut best: Option<crate::fit::OutputsFit> = None;
        // Starts: each output's single fit, and every exact parameter set
        // that reproduces an output's classified features (one output's
        // fit may have found the other of two such sets, Tab. 7, which
        // the other outputs tell apart).
        let mut starts: Vec<(Parameters, f64)> = Vec::new();
        for (i, m) in models.iter().enumerate() {
            if let Some(Some(start)) = single.get(&(i, *m)) {
                starts.push((start.parameters.clone(), start.gain.abs()));
            }
            let solution = back_solution(m, measured_outputs[i].target.as_ref());
            for undamped in solution.as_ref().map(undamped_starts).unwrap_or_default() {
                if let Ok(p) = Parameters::from_values(m, with_dampers(m, &undamped, zetas[i])) {
                    starts.push((p, 1.0));
                }
            }
        }
        for (start, gain) in &starts {
            let mut o = fit_opts.clone();
            if let Gain::Fit(_) = o.gain {
                o.gain = Gain::Fit(*gain);
            }
            let Ok(f) = fit_outputs(&channels, output, start, &o) else {
                continue;
            };
            if best.as_ref().is_none_or(|b| score(&f.fit) < score(&b.fit)) {
                best = Some(f);
            }
        }
        let Some(best) = best else {
            notes.push(SensorsNote::NotFitted { candidate: id });
            continue;
        };
        let first = single
            .get(&(0, models[0]))
            .and_then(|f| f.as_ref())
            .map_or(f64::INFINITY, score);
        fits.push(SensorsCandidate {
            id,
            failed: crate::identify::degenerate(&models[0], &best.fit),
            models: models.clone(),
            score_db: score(&best.fit),
            per_output: best.per_output,
            fit: best.fit,
            first_output_score_db: first,
            rank: 0,
        });
    }
    progress(Progress {
        done: candidates.len(),
        total: candidates.len(),
    });
    fits.sort_by(|a, b| {
        a.failed
            .cmp(&b.failed)
            .then_with(|| crate::identify::by_score(a.score_db, b.score_db))
            .then_with(|| a.models.cmp(&b.models))
    });
    for (i, f) in fits.iter_mut().enumerate() {
        f.rank = i + 1;
    }
    let noise = readings
        .iter()
        .map(|r| r.classification.noise_db)
        .fold(0.0, f64::max);
    let tolerance = options.indistinguishable_db.max(noise * 0.5);
    let indistinguishable = groups(
        fits.iter().map(|f| (f.id.as_str(), f.score_db, f.failed)),
        tolerance,
    );
    // The first output alone: every tuple whose first structure could
    // show its type, fitted or not jointly.
    let mut first_scores: Vec<(String, f64, Option<usize>)> = fits
        .iter()
        .map(|f| (f.id.clone(), f.first_output_score_db, None))
        .collect();
    for t in &first_only {
        let score_db = single
            .get(&(0, t.models[0]))
            .and_then(|f| f.as_ref())
            .map_or(f64::INFINITY, score);
        let failing = t.shows.iter().position(|&ok| !ok);
        first_scores.push((candidate_id(&t.models), score_db, failing));
    }
    let first_best = first_scores
        .iter()
        .map(|f| f.1)
        .fold(f64::INFINITY, f64::min);
    let best_group = indistinguishable.first().cloned().unwrap_or_default();
    let joint_best = fits.first().map_or(f64::INFINITY, |f| f.score_db);
    let mut first_output_alone = Vec::new();
    let mut ruled_out = Vec::new();
    for (id, score_db, failing) in &first_scores {
        if *score_db > first_best + tolerance {
            continue;
        }
        first_output_alone.push(id.clone());
        if best_group.contains(id) {
            continue;
        }
        let by = match failing {
            Some(output) => RuledOutBy::Type { output: *output },
            None => RuledOutBy::Fit {
                excess_db: fits
                    .iter()
                    .find(|f| f.id == *id)
                    .map_or(f64::INFINITY, |f| f.score_db - joint_best),
            },
        };
        ruled_out.push(RuledOut { id: id.clone(), by });
    }
    let mut exact = Vec::new();
    if let Some(best) = fits.first().filter(|_| masses <= EXACT_MAX_MASSES) {
        let set = |models: &[Model]| SensorSet::from_models(models).ok();
        let others: Vec<String> = first_output_alone
            .iter()
            .chain(&best_group)
            .filter(|id| **id != best.id)
            .fold(Vec::new(), |mut v, id| {
                if !v.contains(id) {
                    v.push(id.clone());
                }
                v
            });
        let models_of = |id: &str| -> Option<Vec<Model>> {
            fits.iter()
                .find(|f| f.id == id)
                .map(|f| f.models.clone())
                .or_else(|| {
                    first_only
                        .iter()
                        .find(|t| candidate_id(&t.models) == id)
                        .map(|t| t.models.clone())
                })
        };
        if let Some(a) = set(&best.models) {
            for id in others {
                let Some(b) = models_of(&id).and_then(|m| set(&m)) else {
                    continue;
                };
                if let Ok(verdict) = sensor_set_distinguishability(&a, &b) {
                    exact.push(ExactComparison { id, verdict });
                }
            }
        }
    }
    Ok(SensorsIdentification {
        masses,
        outputs: readings,
        candidates: fits,
        indistinguishable,
        first_output_alone,
        ruled_out,
        exact,
        notes,
    })
}

/// The ID of a candidate: the first output's structure, then `+s<port>`
/// for each further sensor.
fn candidate_id(models: &[Model]) -> String {
    let mut id = models[0].name();
    for m in &models[1..] {
        let p = m.sensor();
        id.push_str(&format!("+s{}.{}", p.plus, p.minus));
    }
    id
}

/// Every chain and actuator of `masses` masses with one sensor per output
/// at its location, each a valid structure (rules (1) and (2) for the
/// first sensor, rule (1) for the others), and, where the exact type table
/// exists (up to 3 masses) or the degrees decide, whether it can show each output's
/// type (each output's verdict in [`Tuple::shows`]); mirror images of a
/// free chain once.
fn candidates(
    masses: usize,
    outputs: &[SensorOutput],
    readings: &[OutputReading],
    most: usize,
) -> Vec<Tuple> {
    let mut all: Vec<Vec<Model>> = Vec::new();
    for gap in 0..masses {
        let ports: Vec<Port> = (gap + 1..=masses)
            .flat_map(|plus| (0..=gap).map(move |minus| Port::new(plus, minus)))
            .collect();
        for &act in &ports {
            // Each output's allowed sensors on this chain.
            let mut choices: Vec<Vec<Model>> = Vec::new();
            for (i, o) in outputs.iter().enumerate() {
                let allowed: Vec<Port> = match o.location {
                    Some(loc) => loc.port(masses).into_iter().collect(),
                    None => ports.clone(),
                };
                let models: Vec<Model> = allowed
                    .into_iter()
                    .filter_map(|p| Model::new(masses, gap, act, p).ok())
                    .filter(|m| i > 0 || m.is_degradation_free())
                    .collect();
                choices.push(models);
            }
            // The cartesian product, in order.
            let mut tuples: Vec<Vec<Model>> = vec![Vec::new()];
            for c in &choices {
                tuples = tuples
                    .into_iter()
                    .flat_map(|t| {
                        c.iter().map(move |m| {
                            let mut t = t.clone();
                            t.push(*m);
                            t
                        })
                    })
                    .collect();
            }
            all.extend(tuples.into_iter().filter(|t| t.len() == outputs.len()));
        }
    }
    // A free chain and its mirror image are one physical chain.
    let mirror = |t: &Vec<Model>| -> Option<Vec<Model>> {
        if t[0].gap() != 0 {
            return None;
        }
        let n = t[0].n_masses();
        let flip = |p: Port| Port::new(n + 1 - p.plus, 0);
        t.iter()
            .map(|m| Model::new(n, 0, flip(m.actuator()), flip(m.sensor())).ok())
            .collect()
    };
    let set: std::collections::BTreeSet<Vec<Model>> = all.iter().cloned().collect();
    all.retain(|t| match mirror(t) {
        Some(m) if set.contains(&m) => *t <= m,
        _ => true,
    });
    let mut possible: BTreeMap<(usize, Model), bool> = BTreeMap::new();
    let mut shows = |i: usize, m: &Model, r: &OutputReading| -> bool {
        let t = &r.classification.frf_type;
        *possible.entry((i, *m)).or_insert_with(|| {
            if masses <= 3 {
                analyze(m, &SearchLimits::default())
                    .types
                    .iter()
                    .any(|v| v.frf_type == *t && v.status == Status::Possible)
            } else {
                let tf = m.undamped_tf();
                tf.den.degree(mms::OMEGA) as usize == t.resonances() as usize
                    && tf.num.degree(mms::OMEGA) >= t.antiresonances()
            }
        })
    };
    all.into_iter()
        .map(|t| {
            let shows = t
                .iter()
                .zip(readings)
                .enumerate()
                .map(|(i, (m, r))| {
                    r.classification.frf_type.resonances() as usize != most || shows(i, m, r)
                })
                .collect();
            Tuple { models: t, shows }
        })
        .collect()
}

/// A chain read by one sensor per output.
struct Tuple {
    /// The structure each output reads.
    models: Vec<Model>,
    /// Whether each output's structure can show the type classified there.
    shows: Vec<bool>,
}
