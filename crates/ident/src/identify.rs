//! The paper's procedure for a user (Sec. 4.4 and 5) in one call: classify
//! the measured FRF, take the candidate structures that can show its type,
//! fit each, rank them, and say which stay indistinguishable and which
//! extra sensor would separate them.
//!
//! Starts of the fits:
//!
//! 1. **Back-solved** (the undamped closed forms): the classified
//!    antiresonances and resonances and the measured level give an undamped
//!    inertance `K prod(Omega - z_i) / prod(Omega - p_k)`; every positive
//!    parameter set of the candidate with exactly this inertance
//!    ([`mms::backsolve`]) is a start, with dampers from the measured
//!    damping ratios. When the candidate can reproduce the type, this
//!    start is already the undamped answer and the fit only adds damping.
//! 2. **Multi-start**, when the target cannot be formed (features outside
//!    the band, zeros off the axis) or the candidate has no exact solution:
//!    deterministic pseudo-random parameter sets scaled to the measured
//!    level and band, each briefly fitted, the best finished.
//!
//! ```
//! use ident::identify::{identify, IdentifyOptions};
//! use ident::synth::{synthetic, SynthOptions};
//! use mms::xorshift::XorShift;
//! use mms::Model;
//!
//! // A recording of the paper's B2 (Tab. 6 parameters), noise-free.
//! let b2 = Model::from_id("B2")?;
//! let mut rng = XorShift::new(3);
//! let s = synthetic(&mut rng, Some(b2), &SynthOptions { lines: 800, ..SynthOptions::default() })?;
//! let id = identify(&s.frf, s.output, &IdentifyOptions::default())?;
//! assert_eq!(id.classification.frf_type, s.frf_type);
//! // The generating structure fits (within 0.05 dB) and is ranked first
//! // or among the indistinguishable.
//! let best = &id.candidates[0];
//! assert!(best.fit.rms_db < 0.05);
//! assert!(id.candidates.iter().any(|c| c.model == b2 && c.fit.rms_db < 0.05));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::advice::{sensor_advice, Candidate, SensorAdvice};
use crate::classify::{classify, Classification, ClassifyError, ClassifyOptions};
use crate::fit::{fit, Fit, FitError, FitOptions, Gain};
use crate::notes::{CandidateNote, IdentifyNote};
use crate::start::{feature_starts, roots, FeatureTarget};
use frf::Frf;
use mms::analysis::{analyze, Feature, FrfType, SearchLimits, Status};
use mms::backsolve::{back_solve, BackSolution, NoSolution, Target};
use mms::response::Parameters;
use mms::xorshift::XorShift;
use mms::{Model, Output};
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Options of [`identify`].
#[derive(Clone, Debug, PartialEq)]
pub struct IdentifyOptions {
    /// Number of masses; `None`: one more than the resonances found (a
    /// single rigid mass when there are none).
    pub masses: Option<usize>,
    /// The actuator and sensor constants: known (the FRF in SI units) or
    /// fitted with the first mass held (see [`Gain`]).
    pub gain: Gain,
    /// Options of the classification.
    pub classify: ClassifyOptions,
    /// Multi-starts per candidate when no back-solved start exists.
    pub multistarts: usize,
    /// Seed of the multi-starts.
    pub seed: u64,
    /// Candidates whose fit is worse than the best by less than this
    /// (RMS of the complex log error, in dB-equivalent) or half the noise
    /// level, whichever is larger, are indistinguishable from it. Default
    /// 0.25 dB: about the repeatability of a good FRF measurement, and
    /// enough for structures whose undamped FRFs agree exactly but whose
    /// dampers cannot copy one another's damping to the last digit.
    pub indistinguishable_db: f64,
    /// An extra sensor separates two candidates when their predicted
    /// readings differ by more than this (RMS dB).
    pub sensor_threshold_db: f64,
}

impl Default for IdentifyOptions {
    fn default() -> IdentifyOptions {
        IdentifyOptions {
            masses: None,
            gain: Gain::Known(1.0),
            classify: ClassifyOptions::default(),
            multistarts: 12,
            seed: 1,
            indistinguishable_db: 0.25,
            sensor_threshold_db: 3.0,
        }
    }
}

/// How a candidate's fit was started.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StartKind {
    /// From an exact back-solved undamped parameter set.
    BackSolved,
    /// From the parameters whose undamped features match the measured ones
    /// best (no exact solution exists).
    FeatureMatched,
    /// From the best of several pseudo-random starts.
    MultiStart,
}

/// One fitted candidate structure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CandidateFit {
    /// Paper ID (3 masses) or generic ID.
    pub id: String,
    /// The structure.
    #[serde(skip)]
    pub model: Model,
    /// The fit.
    pub fit: Fit,
    /// RMS of the complex log error `ln(G/H)` in dB-equivalent (the cost the
    /// ranking uses: magnitude and phase together).
    pub score_db: f64,
    /// How the fit was started.
    pub start: StartKind,
    /// Exact undamped parameter sets that reproduce the classified
    /// features (0 when none or not tried).
    pub back_solutions: usize,
    /// 1 for the best.
    pub rank: usize,
    /// A parameter ended at an end of its physical range (see
    /// [`CandidateNote::AtRangeEnd`]): the fit degenerated into a chain
    /// with fewer masses or a rigid link, so it failed as this structure.
    /// Such fits are ranked after every fit that did not fail.
    pub failed: bool,
    /// Remarks on plausibility (parameter spread, damping) and on the
    /// start.
    pub notes: Vec<CandidateNote>,
}

/// The result of [`identify`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Identification {
    /// The measured FRF's type and features.
    pub classification: Classification,
    /// Number of masses of the candidates.
    pub masses: usize,
    /// Every candidate, best first.
    pub candidates: Vec<CandidateFit>,
    /// Groups of candidates that fit equally well (the first group holds
    /// the best).
    pub indistinguishable: Vec<Vec<String>>,
    /// Extra sensors that would separate the best group, best first.
    pub sensor_advice: Vec<SensorAdvice>,
    /// The paper's Tab. 7 for this recording: from the best fit's undamped
    /// transfer function, every positive parameter set of each other
    /// candidate that reproduces it exactly (damping aside).
    pub equivalents: Vec<Equivalent>,
    /// The data's inertance is negative below its features, where every
    /// chain's is `1 / (sum of masses) > 0`: the sensor (or actuator)
    /// counts the other way, and the gain was taken negative.
    pub sensor_reversed: bool,
    /// How the scale was fixed, how candidates were chosen, and the like.
    pub notes: Vec<IdentifyNote>,
}

/// The undamped parameter sets of one structure that reproduce the best
/// fit's undamped transfer function exactly (analytic back-solving).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Equivalent {
    /// The structure.
    pub id: String,
    /// Parameter names (masses, then springs).
    pub parameters: Vec<String>,
    /// Finitely many sets (two for A4 and B1, Tab. 7), in the order of
    /// `parameters`.
    pub sets: Vec<Vec<f64>>,
    /// A family instead (its free parameters and their ranges), with
    /// sample members in `sets`.
    pub family: Option<EquivalentFamily>,
    /// Why there is none, if there is none.
    pub none: Option<NoEquivalent>,
}

/// A family of equivalent parameter sets of one structure.
///
/// ```
/// use ident::identify::{EquivalentFamily, FreeRange};
///
/// let f = EquivalentFamily {
///     dimension: 1,
///     free: vec!["m1".into()],
///     ranges: vec![FreeRange { lo: 0.5, hi: None }],
/// };
/// assert_eq!(
///     serde_json::to_string(&f)?,
///     r#"{"dimension":1,"free":["m1"],"ranges":[{"lo":0.5,"hi":null}]}"#
/// );
/// # Ok::<(), serde_json::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EquivalentFamily {
    /// How many parameters are free.
    pub dimension: usize,
    /// The free parameters.
    pub free: Vec<String>,
    /// For one free parameter: the open intervals of it on which every
    /// parameter is positive (empty for more free parameters).
    pub ranges: Vec<FreeRange>,
}

/// An open interval of a free parameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FreeRange {
    /// The lower end.
    pub lo: f64,
    /// The upper end; `None`: unbounded.
    pub hi: Option<f64>,
}

/// Why a structure has no set equivalent to the best fit.
///
/// ```
/// use ident::identify::NoEquivalent;
/// use mms::backsolve::NoSolution;
///
/// let n = NoEquivalent::NoSolution { reason: NoSolution::Contradiction };
/// assert_eq!(
///     serde_json::to_string(&n)?,
///     r#"{"kind":"no_solution","reason":{"kind":"contradiction"}}"#
/// );
/// # Ok::<(), serde_json::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum NoEquivalent {
    /// No positive parameter set reproduces the best fit's undamped
    /// transfer function, for this reason (proved by the back-solution).
    NoSolution {
        /// The reason (serialised as an object whose `kind` names it).
        #[serde(serialize_with = "crate::notes::ser_no_solution")]
        reason: NoSolution,
    },
    /// The back-solution could not run: its error.
    NotBackSolved {
        /// The error's message.
        error: String,
    },
}

/// Why identification failed.
#[derive(Debug, thiserror::Error)]
pub enum IdentifyError {
    /// The FRF could not be classified.
    #[error(transparent)]
    Classify(#[from] ClassifyError),
    /// A fit could not run.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// No structure of that many masses.
    #[error("no models of {0} masses (1 to {max})", max = mms::MAX_MASSES)]
    Masses(usize),
    /// The type read implies more masses than are inferred from an FRF
    /// without being asked for.
    #[error(
        "the FRF reads as type {frf_type}, {masses} masses: more than the \
         {INFERRED_MAX_MASSES} inferred from one FRF unless the number of masses is given; \
         features that many are mostly noise read as modes (narrow the band, or give the masses)"
    )]
    TooManyFeatures {
        /// The masses the type implies.
        masses: usize,
        /// The type read.
        frf_type: String,
    },
    /// Evaluating a model failed.
    #[error(transparent)]
    Response(#[from] mms::response::ResponseError),
    /// Outputs of several sensors that cannot be identified together.
    #[error("{0}")]
    Outputs(String),
}

/// Identifies the structure and parameters behind `frf` (see the module
/// docs).
pub fn identify(
    frf: &Frf,
    output: Output,
    options: &IdentifyOptions,
) -> Result<Identification, IdentifyError> {
    identify_with_progress(frf, output, options, &|_| {})
}

/// How far a long identification has come: candidates fitted of all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Candidates fitted so far.
    pub done: usize,
    /// All candidates.
    pub total: usize,
}

/// [`identify`], reporting each fitted candidate to `progress` (from the
/// fitting threads, in the order they finish), so that a caller can show
/// how far a long run has come.
///
/// ```
/// use ident::identify::{identify_with_progress, IdentifyOptions, Progress};
/// use ident::synth::{synthetic, SynthOptions};
/// use std::sync::Mutex;
///
/// let s = synthetic(&mut mms::xorshift::XorShift::new(3), None, &SynthOptions::default())?;
/// let seen = Mutex::new(Vec::new());
/// let id = identify_with_progress(&s.frf, s.output, &IdentifyOptions::default(), &|p: Progress| {
///     seen.lock().unwrap().push(p);
/// })?;
/// let seen = seen.into_inner().unwrap();
/// assert_eq!(seen.len(), seen[0].total);
/// assert!(seen.iter().any(|p| p.done == p.total));
/// assert!(id.candidates.len() <= seen[0].total);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn identify_with_progress(
    frf: &Frf,
    output: Output,
    options: &IdentifyOptions,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Identification, IdentifyError> {
    let Measured {
        classification,
        data,
        target,
        options,
        sensor_reversed,
        binned_from,
    } = measured(frf, output, options)?;
    let options = &options;
    let mut notes = Vec::new();
    if let Some(read) = binned_from {
        notes.push(IdentifyNote::Binned {
            lines: read,
            max_bins: MAX_LINES,
        });
    }
    let resonances = classification.frf_type.resonances() as usize;
    let masses = options.masses.unwrap_or(resonances + 1);
    if options.masses.is_none() && masses > INFERRED_MAX_MASSES {
        return Err(IdentifyError::TooManyFeatures {
            masses,
            frf_type: classification.frf_type.to_string(),
        });
    }
    if masses == 0 || masses > mms::MAX_MASSES {
        return Err(IdentifyError::Masses(masses));
    }
    let t = &classification.frf_type;
    let candidates = structures_showing(masses, t, &mut notes)?;

    let zeta = mean_damping(&classification);
    let fitting = Fitting::new(output, &data, zeta, classification.noise_db, progress);
    let mut search_notes = Vec::new();
    let (mut fits, mut masses) = fitting.open_search(
        &candidates,
        masses,
        resonances,
        target.as_ref(),
        options,
        &mut search_notes,
    )?;
    let mut sensor_reversed = sensor_reversed;
    let mut gain = options.gain;
    // The polarity is read from the level below the features: where a
    // pair of them was missed below the band, that level is another
    // one's, and the fits of the other polarity tell.
    if sensor_reversed && options.masses.is_none() && fitting.lacks_fit(&fits) {
        let turned = IdentifyOptions {
            gain: match options.gain {
                Gain::Known(g) => Gain::Known(-g),
                Gain::Fit(g) => Gain::Fit(-g),
            },
            ..options.clone()
        };
        let mut turned_notes = Vec::new();
        let (turned_fits, turned_masses) = fitting.open_search(
            &candidates,
            resonances + 1,
            resonances,
            None,
            &turned,
            &mut turned_notes,
        )?;
        let (kept, other) = (
            fits.first().map_or(f64::INFINITY, |f| f.score_db),
            turned_fits.first().map_or(f64::INFINITY, |f| f.score_db),
        );
        if other <= kept * MORE_MODES_SCORE_RATIO && !fitting.lacks_fit(&turned_fits) {
            notes.push(IdentifyNote::PolarityFromFit {
                score_db: other,
                reversed_db: kept,
            });
            (fits, masses, search_notes, sensor_reversed, gain) =
                (turned_fits, turned_masses, turned_notes, false, turned.gain);
        }
    }
    // The scale the fits used.
    notes.push(match gain {
        Gain::Known(gain) => IdentifyNote::GainKnown { gain },
        Gain::Fit(_) => IdentifyNote::GainFitted,
    });
    if sensor_reversed {
        notes.push(IdentifyNote::SensorReversed);
    }
    notes.extend(search_notes);
    for (i, f) in fits.iter_mut().enumerate() {
        f.rank = i + 1;
    }
    let tolerance = options
        .indistinguishable_db
        .max(classification.noise_db * 0.5);
    let indistinguishable = groups(
        fits.iter().map(|f| (f.id.as_str(), f.score_db, f.failed)),
        tolerance,
    );
    let best_group: Vec<Candidate> = fits
        .iter()
        .take(indistinguishable.first().map_or(0, Vec::len))
        .map(|f| Candidate {
            name: f.id.clone(),
            model: f.model,
            parameters: f.fit.parameters.clone(),
            gain: f.fit.gain,
        })
        .collect();
    let sensor_advice = if best_group.len() > 1 {
        sensor_advice(&best_group, data.freq_hz(), options.sensor_threshold_db)?
    } else {
        Vec::new()
    };
    let equivalents = if masses <= EQUIVALENTS_MAX_MASSES {
        fits.first()
            .map(|best| equivalents(best, &fits))
            .unwrap_or_default()
    } else {
        notes.push(IdentifyNote::EquivalentsNotSolved { masses });
        Vec::new()
    };
    Ok(Identification {
        classification,
        masses,
        candidates: fits,
        indistinguishable,
        sensor_advice,
        equivalents,
        sensor_reversed,
        notes,
    })
}

/// What every candidate of one identification is fitted with.
struct Fitting<'a> {
    output: Output,
    data: &'a Frf,
    zeta: f64,
    noise_db: f64,
    progress: &'a (dyn Fn(Progress) + Sync),
    /// Whether the lines are far enough apart to hide a mode between two
    /// of them ([`HIDING_SPACING`]).
    hides: bool,
}

impl<'a> Fitting<'a> {
    fn new(
        output: Output,
        data: &'a Frf,
        zeta: f64,
        noise_db: f64,
        progress: &'a (dyn Fn(Progress) + Sync),
    ) -> Fitting<'a> {
        let mut spacing: Vec<f64> = data
            .freq_hz()
            .windows(2)
            .map(|w| (w[1] / w[0]).ln())
            .collect();
        let hides = !spacing.is_empty() && {
            let k = spacing.len() / 2;
            *spacing.select_nth_unstable_by(k, f64::total_cmp).1 >= HIDING_SPACING
        };
        Fitting {
            output,
            data,
            zeta,
            noise_db,
            progress,
            hides,
        }
    }

    /// Whether the best of `fits` misses the lines by far more than their
    /// scatter ([`LACK_OF_FIT_DB`]) on a grid coarse enough to hide a
    /// mode between its lines ([`HIDING_SPACING`]).
    fn lacks_fit(&self, fits: &[CandidateFit]) -> bool {
        self.hides
            && fits
                .first()
                .is_some_and(|b| b.score_db > LACK_OF_FIT_DB.max(LACK_OF_FIT_NOISE * self.noise_db))
    }

    /// The candidates fitted, best first, with their masses: those of the
    /// type read, and where they miss the lines by far more than their
    /// scatter, the other structures and those with more modes.
    fn open_search(
        &self,
        candidates: &[Model],
        mut masses: usize,
        resonances: usize,
        target: Option<&(Vec<f64>, Vec<f64>)>,
        options: &IdentifyOptions,
        notes: &mut Vec<IdentifyNote>,
    ) -> Result<(Vec<CandidateFit>, usize), IdentifyError> {
        let fit_all = |candidates: &[Model], notes: &mut Vec<IdentifyNote>| {
            fit_candidates(
                candidates,
                self.output,
                self.data,
                target,
                self.zeta,
                options,
                self.progress,
                notes,
            )
        };
        let mut fits = fit_all(candidates, notes);
        // An antiresonance closer to its resonance than the line spacing
        // shows in no type, and the type read may exclude the structure:
        // every structure of these masses and modes is compared on the
        // lines.
        if options.masses.is_none() && self.lacks_fit(&fits) {
            let others: Vec<Model> = structures_with_resonances(masses, resonances)?
                .into_iter()
                .filter(|m| !candidates.contains(m))
                .collect();
            if !others.is_empty() {
                let before = fits.first().map_or(f64::NAN, |b| b.score_db);
                fits.extend(fit_all(&others, notes));
                sort_fits(&mut fits);
                notes.push(IdentifyNote::TypeOpened {
                    masses,
                    structures: others.len(),
                    score_db: fits.first().map_or(f64::NAN, |b| b.score_db),
                    type_db: before,
                });
            }
        }
        // A resonance and its antiresonance missed the same way: where the
        // best still misses the lines by far more than their noise, the
        // structures with a mode more are fitted too (and two more, up to
        // MORE_MODES_MAX_MASSES, where one more does not do), and taken if
        // they explain the lines far better.
        let mut modes = resonances;
        'more: while options.masses.is_none() && masses < INFERRED_MAX_MASSES {
            if !self.lacks_fit(&fits) {
                break;
            }
            let Some(best) = fits.first() else { break };
            for extra in 1..=2 {
                if extra == 2 && masses + 2 > MORE_MODES_MAX_MASSES.min(INFERRED_MAX_MASSES) {
                    break;
                }
                let tried = structures_with_resonances(masses + extra, modes + extra)?;
                let more = fit_all(&tried, notes);
                let Some(next) = more.first() else { break };
                let (lines, p_best, p_next) = (
                    self.data.len(),
                    best.model.parameters().len(),
                    next.model.parameters().len(),
                );
                // A mode more must bring the fit down to what a well-read
                // chain attains: one that only takes a share off a phase
                // trend (a dead time no chain has) is not a missed mode.
                let explains = next.score_db <= best.score_db * MORE_MODES_SCORE_RATIO
                    && !self.lacks_fit(&more)
                    && 2 * lines >= p_next + 2 * p_next.saturating_sub(p_best);
                if explains {
                    notes.push(IdentifyNote::MassesFromFit {
                        masses: masses + extra,
                        score_db: next.score_db,
                        fewer_db: best.score_db,
                    });
                    masses += extra;
                    modes += extra;
                    fits = more;
                    continue 'more;
                }
                notes.push(IdentifyNote::MoreModesTried {
                    masses: masses + extra,
                    score_db: next.score_db,
                    kept_db: best.score_db,
                });
            }
            break;
        }
        Ok((fits, masses))
    }
}

/// The structures of `masses` masses that can show the type read, with
/// the note saying how they were chosen (every structure when none can).
fn structures_showing(
    masses: usize,
    t: &FrfType,
    notes: &mut Vec<IdentifyNote>,
) -> Result<Vec<Model>, IdentifyError> {
    let all = mms::rule3_models(masses).map_err(|_| IdentifyError::Masses(masses))?;
    let resonances = t.resonances() as usize;
    let candidates: Vec<Model> = if masses <= 3 {
        notes.push(IdentifyNote::CandidatesFromTypeTable {
            masses,
            frf_type: t.clone(),
        });
        all.iter()
            .copied()
            .filter(|m| {
                analyze(m, &SearchLimits::default())
                    .types
                    .iter()
                    .any(|v| v.frf_type == *t && v.status == Status::Possible)
            })
            .collect()
    } else {
        notes.push(IdentifyNote::CandidatesFromDegrees {
            masses,
            frf_type: t.clone(),
        });
        all.iter()
            .copied()
            .filter(|m| {
                let tf = m.undamped_tf();
                tf.den.degree(mms::OMEGA) as usize == resonances
                    && tf.num.degree(mms::OMEGA) >= t.antiresonances()
            })
            .collect()
    };
    if candidates.is_empty() {
        notes.push(IdentifyNote::NoStructureShowsType {
            masses,
            frf_type: t.clone(),
        });
        return Ok(all);
    }
    Ok(candidates)
}

/// The structures of `masses` masses with `resonances` resonances,
/// whatever their antiresonances.
fn structures_with_resonances(
    masses: usize,
    resonances: usize,
) -> Result<Vec<Model>, IdentifyError> {
    Ok(mms::rule3_models(masses)
        .map_err(|_| IdentifyError::Masses(masses))?
        .into_iter()
        .filter(|m| m.undamped_tf().den.degree(mms::OMEGA) as usize == resonances)
        .collect())
}

/// Fits every candidate (independent: on every core, collected in their
/// order, so the result does not depend on the threads), best first; a
/// candidate that cannot be fitted (e.g. its model is singular on the
/// grid) is noted and does not stop the others.
#[allow(clippy::too_many_arguments)]
fn fit_candidates(
    candidates: &[Model],
    output: Output,
    data: &Frf,
    target: Option<&(Vec<f64>, Vec<f64>)>,
    zeta: f64,
    options: &IdentifyOptions,
    progress: &(dyn Fn(Progress) + Sync),
    notes: &mut Vec<IdentifyNote>,
) -> Vec<CandidateFit> {
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, candidates.len().max(1));
    let total = candidates.len();
    let finished = AtomicUsize::new(0);
    let finished = &finished;
    let results: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = candidates
            .chunks(candidates.len().div_ceil(workers).max(1))
            .map(|chunk| {
                scope.spawn(move || {
                    chunk
                        .iter()
                        .map(|m| {
                            let fitted = fit_candidate(m, output, data, target, zeta, options);
                            let done = finished.fetch_add(1, Ordering::Relaxed) + 1;
                            progress(Progress { done, total });
                            (*m, fitted)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    let mut fits = Vec::new();
    for (model, result) in results {
        let (fit_result, start, back_solutions, why_not) = match result {
            Ok(r) => r,
            Err(e) => {
                notes.push(IdentifyNote::NotFitted {
                    structure: model.name(),
                    error: e.to_string(),
                });
                continue;
            }
        };
        let score_db = score(&fit_result);
        let mut notes = plausibility(&model, &fit_result);
        let failed = at_range_end(&notes);
        notes.extend(why_not);
        fits.push(CandidateFit {
            id: model.name(),
            model,
            fit: fit_result,
            score_db,
            start,
            back_solutions,
            rank: 0,
            failed,
            notes,
        });
    }
    sort_fits(&mut fits);
    fits
}

/// Fits that did not fail first, then by score, then by structure.
fn sort_fits(fits: &mut [CandidateFit]) {
    fits.sort_by(|a, b| {
        a.failed
            .cmp(&b.failed)
            .then_with(|| by_score(a.score_db, b.score_db))
            .then_with(|| a.model.cmp(&b.model))
    });
}

/// A best fit missing the lines by more than this (RMS of the complex
/// log error, dB-equivalent) and [`LACK_OF_FIT_NOISE`] times their
/// scatter has features the type read does not show: structures with a
/// mode more are tried. A well-read chain fits to a few tenths of a dB;
/// leakage and bias of a noise-excited estimate leave one to two dB.
pub const LACK_OF_FIT_DB: f64 = 1.5;

/// See [`LACK_OF_FIT_DB`].
pub const LACK_OF_FIT_NOISE: f64 = 4.0;

/// The median spacing of the lines (in `ln f`: 1.5 %) from which a
/// resonance and its antiresonance can hide between two lines: the
/// multisine grids of a short period. On denser grids a mode shows in the
/// type unless damped beyond reading, and a misfit there is more often a
/// dead time or friction no chain has, which a mode more only mimics
/// (the shared recordings' grids lie below 0.9 %).
pub const HIDING_SPACING: f64 = 0.015;

/// The most masses reached by trying two modes more than the type read
/// at once (fitting every 5-mass structure takes tens of seconds).
pub const MORE_MODES_MAX_MASSES: usize = 4;

/// Structures with a mode more than the type read are taken only if they
/// miss the lines by at most this share of the best fit's error: a ninth
/// of its squared error. A missed mode leaves the fewer masses several dB
/// that the mode more takes down to the scatter; a mode more fitted to
/// an estimate's leakage or bias takes off a half to two thirds.
pub const MORE_MODES_SCORE_RATIO: f64 = 1.0 / 3.0;

/// The most masses for which [`identify`] back-solves the exactly
/// equivalent parameter sets of every candidate
/// ([`Identification::equivalents`]) and starts its fits from exact
/// back-solutions.
pub const EQUIVALENTS_MAX_MASSES: usize = 3;

/// The most masses inferred from the features of an FRF: a type implying
/// more is refused unless the masses are given. Six and more modes read
/// from one FRF are, on the benchmark, noise above the excited band read
/// as modes, and fitting every chain of that many masses takes minutes.
pub const INFERRED_MAX_MASSES: usize = 5;

/// Groups of candidates in ranked order (`(id, score, failed)`, best
/// first) whose scores lie within `tolerance` of their group's first:
/// what the data cannot tell apart. A failed fit is like no other and
/// stands alone.
pub(crate) fn groups<'a>(
    ranked: impl Iterator<Item = (&'a str, f64, bool)>,
    tolerance: f64,
) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = Vec::new();
    let mut group_best = f64::NAN;
    for (id, score_db, failed) in ranked {
        match out.last_mut() {
            Some(g) if !failed && score_db <= group_best + tolerance => g.push(id.to_string()),
            _ => {
                group_best = score_db;
                out.push(vec![id.to_string()]);
            }
        }
    }
    out
}

/// Back-solves every candidate from the best fit's undamped transfer
/// function (the paper's Tab. 7).
fn equivalents(best: &CandidateFit, all: &[CandidateFit]) -> Vec<Equivalent> {
    let nu = best.model.undamped_parameters().len();
    let Ok(target) = Target::from_model_f64(&best.model, &best.fit.parameters.values()[..nu])
    else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for c in all {
        let parameters = c.model.undamped_parameters();
        let mut e = Equivalent {
            id: c.id.clone(),
            parameters,
            sets: Vec::new(),
            family: None,
            none: None,
        };
        match back_solve(&c.model, &target) {
            Ok(BackSolution::NoSolution(reason)) => {
                e.none = Some(NoEquivalent::NoSolution { reason })
            }
            Ok(sol) => {
                e.sets = sol.points().iter().map(|p| p.values.clone()).collect();
                if let Some(f) = sol.families().first() {
                    e.family = Some(EquivalentFamily {
                        dimension: f.dimension(),
                        free: f.free.clone(),
                        ranges: f
                            .intervals
                            .iter()
                            .map(|iv| FreeRange {
                                lo: iv.lo.value,
                                hi: iv.hi.as_ref().map(|h| h.value),
                            })
                            .collect(),
                    });
                    e.sets.extend(f.samples.iter().take(3).cloned());
                }
            }
            Err(err) => {
                e.none = Some(NoEquivalent::NotBackSolved {
                    error: err.to_string(),
                })
            }
        }
        out.push(e);
    }
    out
}

/// What [`identify`] and [`fit_structure`] take from the measurement
/// before any fit.
pub(crate) struct Measured {
    pub classification: Classification,
    /// The informative lines of the band.
    pub data: Frf,
    /// The undamped target from the features and level, made positive
    /// below the features.
    pub target: Option<(Vec<f64>, Vec<f64>)>,
    /// The caller's options, with the gain's sign turned for a reversed
    /// sensor.
    pub options: IdentifyOptions,
    pub sensor_reversed: bool,
    /// The lines read, when more than [`MAX_LINES`] were averaged into
    /// bins.
    pub binned_from: Option<usize>,
}

/// Candidates whose scores differ by less than this (dB) tie: structures
/// with the same FRF, where the optimiser's last digits decide nothing.
const TIE_DB: f64 = 1e-6;

/// The ranking of two candidates' scores, ties (on a grid of [`TIE_DB`],
/// so the order stays transitive) equal: the caller breaks them by the
/// structure's order, where a free chain (gap 0, the plain drive whose
/// driven mass is the motor) comes before a grounded equivalent.
pub(crate) fn by_score(a: f64, b: f64) -> std::cmp::Ordering {
    (a / TIE_DB).round().total_cmp(&(b / TIE_DB).round())
}

/// Most lines an identification works on: a finer FRF is averaged into
/// this many log-spaced bins first (`frf::uncertainty::log_binned`;
/// relative bin width about 3e-4 per decade it spans, finer than any
/// damping ratio a chain model is fitted to), so that the work stays
/// linear in the lines read.
pub const MAX_LINES: usize = 20_000;

pub(crate) fn measured(
    frf: &Frf,
    output: Output,
    options: &IdentifyOptions,
) -> Result<Measured, IdentifyError> {
    let binned = (frf.len() > MAX_LINES).then(|| frf::uncertainty::log_binned(frf, MAX_LINES));
    let lines_read = frf.len();
    let frf = binned.as_ref().unwrap_or(frf);
    let classification = classify(frf, output, &options.classify)?;
    let (lo, hi) = classification.band_hz;
    // Lines at 0 Hz carry no rigid-body information a chain can match, and
    // lines without information (no excitation, a zero response) none at
    // all.
    let sd = frf.std_dev();
    let keep: Vec<usize> = (0..frf.len())
        .filter(|&i| {
            let f = frf.freq_hz()[i];
            f > 0.0
                && f >= lo
                && f <= hi
                && frf.response()[i].norm() > 0.0
                && sd.is_none_or(|s| s[i].is_finite())
        })
        .collect();
    let data = frf.lines(&keep).unwrap_or_else(|| frf.clone());
    let mut target = undamped_target(&data, output, &classification);
    // Every chain's inertance tends to 1 / (sum of masses) > 0 below its
    // features; data that tend to a negative value come from a sensor (or
    // actuator) that counts the other way.
    let sensor_reversed = target
        .as_ref()
        .is_some_and(|(num, den)| num[0] / den[0] < 0.0);
    let mut options = options.clone();
    if sensor_reversed {
        if let Some((num, _)) = target.as_mut() {
            num.iter_mut().for_each(|a| *a = -*a);
        }
        options.gain = match options.gain {
            Gain::Known(g) => Gain::Known(-g),
            Gain::Fit(g) => Gain::Fit(-g),
        };
    }
    Ok(Measured {
        classification,
        data,
        target,
        options,
        sensor_reversed,
        binned_from: binned.is_some().then_some(lines_read),
    })
}

/// Fits one given structure to `frf` from the automatic start (classify,
/// back-solve, fit; multi-start when that fails): the fit of one candidate
/// of [`identify`], for a user who already knows the structure.
///
/// ```
/// use ident::identify::{fit_structure, IdentifyOptions};
/// use ident::synth::{synthetic, SynthOptions};
/// use mms::{xorshift::XorShift, Model};
///
/// let a1 = Model::from_id("A1")?;
/// let s = synthetic(&mut XorShift::new(5), Some(a1), &SynthOptions::default())?;
/// let fit = fit_structure(&s.frf, s.output, &a1, &IdentifyOptions::default())?;
/// assert!(fit.rms_db < 0.01);
/// // A1 has all 5 undamped parameters determinable (Tab. 5): they come back.
/// for (got, want) in fit.parameters.values().iter().zip(s.parameters.values()).take(5) {
///     assert!((got / want - 1.0).abs() < 1e-3);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn fit_structure(
    frf: &Frf,
    output: Output,
    model: &Model,
    options: &IdentifyOptions,
) -> Result<Fit, IdentifyError> {
    let Measured {
        classification,
        data,
        target,
        options,
        ..
    } = measured(frf, output, options)?;
    let options = &options;
    let zeta = mean_damping(&classification);
    Ok(fit_candidate(model, output, &data, target.as_ref(), zeta, options)?.0)
}

/// RMS of `ln(G/H)` over the lines, in dB-equivalent: magnitude (dB) and
/// phase (one radian counts as one neper, 8.69 dB) together.
pub(crate) fn score(f: &Fit) -> f64 {
    let db_per_rad = 20.0 / std::f64::consts::LN_10;
    (f.rms_db.powi(2) + (f.rms_deg.to_radians() * db_per_rad).powi(2)).sqrt()
}

/// Mean damping ratio of the classified resonances (2 % if none known).
pub(crate) fn mean_damping(c: &Classification) -> f64 {
    let z: Vec<f64> = c
        .features
        .iter()
        .filter(|f| f.in_type && f.kind == Feature::Resonance)
        .filter_map(|f| f.damping_ratio)
        .filter(|z| z.is_finite() && *z > 0.0)
        .collect();
    if z.is_empty() {
        0.02
    } else {
        (z.iter().sum::<f64>() / z.len() as f64).clamp(1e-4, 0.5)
    }
}

/// The undamped inertance the classified features and the measured level
/// imply: `K prod(Omega - z_i) / prod(Omega - p_k)` (coefficients,
/// ascending), or `None` if the type has zeros off the axis or too few
/// lines agree on the level.
fn undamped_target(data: &Frf, output: Output, c: &Classification) -> Option<(Vec<f64>, Vec<f64>)> {
    // Zeros off the axis are not in the shape: their factor is nearly
    // constant only well below them, so the level is then read from the
    // lowest tenth of the band alone.
    let nm = c.frf_type.nonminimum_phase;
    let omega2 = |f: f64| (2.0 * PI * f).powi(2);
    let mut num = vec![1.0];
    let mut den = vec![1.0];
    for feat in c.features.iter().filter(|f| f.in_type) {
        let root = omega2(feat.freq_hz);
        for _ in 0..feat.multiplicity {
            let p = if feat.kind == Feature::Antiresonance {
                &mut num
            } else {
                &mut den
            };
            // Multiply by (Omega - root).
            let mut next = vec![0.0; p.len() + 1];
            for (i, &a) in p.iter().enumerate() {
                next[i] -= a * root;
                next[i + 1] += a;
            }
            *p = next;
        }
    }
    let eval = |p: &[f64], x: f64| p.iter().rev().fold(0.0, |acc, &a| acc * x + a);
    // K from the lines: the measured inertance over the shape, real part;
    // the median shrugs off the lines near features, where damping makes
    // the ratio complex.
    let k_power = output.s_power() as i32;
    let lines = if nm {
        (data.len() / 10).max(5)
    } else {
        data.len()
    };
    let mut ratios: Vec<f64> = data
        .freq_hz()
        .iter()
        .zip(data.response())
        .take(lines)
        .filter_map(|(&f, &h)| {
            let jw = Complex64::new(0.0, 2.0 * PI * f);
            let inertance = h * jw.powi(2 - k_power);
            let shape = eval(&num, omega2(f)) / eval(&den, omega2(f));
            let r = inertance / shape;
            (shape.is_finite() && r.re.is_finite() && r.im.abs() < 0.2 * r.re.abs()).then_some(r.re)
        })
        .collect();
    if ratios.len() < 5 {
        return None;
    }
    ratios.sort_by(f64::total_cmp);
    let k = ratios[ratios.len() / 2];
    if k == 0.0 {
        return None;
    }
    Some((num.iter().map(|a| a * k).collect(), den))
}

/// The exact target of a measured undamped inertance. Measured feature
/// frequencies carry a few significant digits, not 53 bits: each
/// coefficient becomes the simplest rational within 1e-9 of it (relative),
/// which keeps the exact back-solving's numbers small and fast.
fn measured_target(num: &[f64], den: &[f64]) -> Result<Target, mms::BackSolveError> {
    let r =
        |v: &[f64]| -> Vec<poly::Rat> { v.iter().map(|&x| simplest_rational(x, 1e-9)).collect() };
    Target::new(r(num), r(den))
}

/// The rational with the smallest denominator within `rel * |x|` of `x`
/// (continued fraction convergents; 0 for 0 and non-finite input).
fn simplest_rational(x: f64, rel: f64) -> poly::Rat {
    if !x.is_finite() || x == 0.0 {
        return poly::Rat::from(0);
    }
    let tol = rel * x.abs();
    // Convergents h/k of the continued fraction of |x|, scaled so the
    // integers stay within i64 for the magnitudes of TF coefficients.
    let (sign, ax) = (x.signum(), x.abs());
    let (mut h0, mut h1) = (0i128, 1i128);
    let (mut k0, mut k1) = (1i128, 0i128);
    let mut r = ax;
    for _ in 0..64 {
        let a = r.floor();
        if a > 1e18 {
            break;
        }
        let a = a as i128;
        let (h2, k2) = (a * h1 + h0, a * k1 + k0);
        if h2.abs() > i64::MAX as i128 || k2 > i64::MAX as i128 {
            break;
        }
        (h0, h1, k0, k1) = (h1, h2, k1, k2);
        if (h1 as f64 / k1 as f64 - ax).abs() <= tol {
            break;
        }
        let frac = r - r.floor();
        if frac == 0.0 {
            break;
        }
        r = 1.0 / frac;
    }
    if k1 == 0 || (h1 as f64 / k1 as f64 - ax).abs() > tol {
        // Too large or too small for i64 convergents: the exact binary value.
        return poly::Rat::from_f64(x).unwrap_or_else(|| poly::Rat::from(0));
    }
    let q = &poly::Rat::from(h1 as i64) / &poly::Rat::from(k1 as i64);
    if sign < 0.0 {
        -q
    } else {
        q
    }
}

/// Dampers for a start: each link with damping ratio `zeta` on its own,
/// `d = 2 zeta sqrt(c m)` with `m` the reduced mass of the bodies it joins.
pub(crate) fn with_dampers(model: &Model, undamped: &[f64], zeta: f64) -> Vec<f64> {
    let n = model.n_masses();
    let masses = &undamped[..n];
    let springs = &undamped[n..];
    let mut v = undamped.to_vec();
    for (i, c) in (0..n).filter(|&i| model.has_link(i)).zip(springs) {
        let m = if i == 0 {
            masses[0]
        } else {
            masses[i - 1] * masses[i] / (masses[i - 1] + masses[i])
        };
        v.push(2.0 * zeta * (c * m).sqrt());
    }
    v
}

/// A fit with `options.fixed` held first, then released: damping can make
/// determinable what the undamped structure leaves free, and the first
/// phase brings the fit close without creeping along the valley.
fn fit_two_phase(
    model: &Model,
    output: Output,
    data: &Frf,
    start: &Parameters,
    options: &FitOptions,
) -> Result<Fit, FitError> {
    let first = fit(model, output, data, start, options)?;
    if options.fixed.is_empty() {
        return Ok(first);
    }
    let release = FitOptions {
        fixed: Vec::new(),
        gain: match options.gain {
            Gain::Known(g) => Gain::Known(g),
            Gain::Fit(_) => Gain::Fit(first.gain),
        },
        ..options.clone()
    };
    let second = fit(model, output, data, &first.parameters, &release)?;
    Ok(if score(&second) <= score(&first) {
        second
    } else {
        first
    })
}

pub(crate) fn fit_options(options: &IdentifyOptions, max_iterations: usize) -> FitOptions {
    FitOptions {
        gain: options.gain,
        max_iterations,
        ..FitOptions::default()
    }
}

/// The best fit of one candidate over its starts.
pub(crate) fn fit_candidate(
    model: &Model,
    output: Output,
    data: &Frf,
    target: Option<&(Vec<f64>, Vec<f64>)>,
    zeta: f64,
    options: &IdentifyOptions,
) -> Result<(Fit, StartKind, usize, Option<CandidateNote>), IdentifyError> {
    // Structures with fewer determinable parameters than parameters
    // (Tab. 5) have valleys of equally good fits; holding the surplus
    // parameters at their start values keeps the fit from creeping along
    // them. A family from the back-solution names its free parameters;
    // otherwise the first masses are held.
    // The rank at random points is what a fit meets (the generic rank
    // with probability one); the exact symbolic proof is for the tables
    // and can take a second per structure of five masses.
    let sampled = mms::RankOptions {
        symbolic_work_limit: 0,
        ..mms::RankOptions::default()
    };
    let surplus = model.undamped_parameters().len()
        - mms::identifiability_with(model, &sampled).determinable_parameters;
    let mut default_fixed: Vec<String> = model
        .masses()
        .into_iter()
        .filter(|m| !(matches!(options.gain, Gain::Fit(_)) && m == "m1"))
        .take(surplus)
        .collect();
    let mut starts: Vec<Vec<f64>> = Vec::new();
    let mut why_not: Option<CandidateNote> = None;
    if let Some(solution) = back_solution(model, target) {
        if let BackSolution::NoSolution(reason) = &solution {
            let parameters = model.undamped_parameters().len();
            why_not = Some(CandidateNote::NoBackSolution {
                reason: reason.clone(),
                parameters,
                determinable: parameters - surplus,
            });
        }
        starts = undamped_starts(&solution);
        if let Some(f) = solution.families().first() {
            default_fixed = f.free.clone();
        }
    }
    let back_solutions = starts.len();
    let mut kind = StartKind::BackSolved;
    if starts.is_empty() {
        if let Some(ft) = target.and_then(feature_target) {
            let tf = model.undamped_tf();
            if tf.num.degree(mms::OMEGA) as usize >= ft.antiresonances.len()
                && tf.den.degree(mms::OMEGA) as usize == ft.resonances.len()
            {
                starts = feature_starts(model, &ft, 24, options.seed)
                    .into_iter()
                    .take(6)
                    .map(|(x, _)| x)
                    .collect();
                kind = StartKind::FeatureMatched;
            }
        }
    }
    // Screen every start briefly with the surplus parameters held, then
    // finish the two best.
    let screen = FitOptions {
        fixed: default_fixed.clone(),
        ..fit_options(options, 4)
    };
    // Screening on every k-th line (at most ~300): ranking the starts
    // needs the shape of the cost, not its last digit.
    let step = data.len().div_ceil(300).max(1);
    let coarse = if step > 1 {
        let keep: Vec<usize> = (0..data.len()).step_by(step).collect();
        data.lines(&keep).unwrap_or_else(|| data.clone())
    } else {
        data.clone()
    };
    let mut screened: Vec<Parameters> = Vec::new();
    let mut scores: Vec<f64> = Vec::new();
    for undamped in &starts {
        let Ok(p) = Parameters::from_values(model, with_dampers(model, undamped, zeta)) else {
            continue;
        };
        if starts.len() <= 2 {
            // Few starts: finish them all, no screening pass.
            scores.push(0.0);
            screened.push(p);
        } else {
            let f = fit(model, output, &coarse, &p, &screen)?;
            scores.push(score(&f));
            screened.push(f.parameters);
        }
    }
    let mut order: Vec<usize> = (0..screened.len()).collect();
    order.sort_by(|&a, &b| scores[a].total_cmp(&scores[b]));
    let screened: Vec<Parameters> = order.into_iter().map(|i| screened[i].clone()).collect();
    let full = FitOptions {
        fixed: default_fixed.clone(),
        ..fit_options(options, 200)
    };
    let mut best: Option<Fit> = None;
    for s in screened.iter().take(2) {
        let f = fit_two_phase(model, output, data, s, &full)?;
        let good = score(&f) < 1.0;
        if best.as_ref().is_none_or(|b| score(&f) < score(b)) {
            best = Some(f);
        }
        if good {
            break;
        }
    }
    if let Some(b) = best.take() {
        // A start from the features that fits this well needs no more.
        if score(&b) < 1.0 {
            return Ok((b, kind, back_solutions, why_not));
        }
        best = Some(b);
    }
    let ms = multistart(model, output, data, zeta, &default_fixed, options)?;
    match best {
        Some(b) if score(&b) <= score(&ms) => Ok((b, kind, back_solutions, why_not)),
        _ => Ok((ms, StartKind::MultiStart, back_solutions, why_not)),
    }
}

/// Every positive undamped parameter set of `model` that reproduces the
/// measured undamped target exactly (`None` without a target, when the
/// model's degrees differ from the target's, or when back-solving fails).
pub(crate) fn back_solution(
    model: &Model,
    target: Option<&(Vec<f64>, Vec<f64>)>,
) -> Option<BackSolution> {
    let (num, den) = target?;
    // Above three masses the exact elimination of one structure can run
    // into its time budget (tens of seconds, most often without a
    // result): the feature-matched starts serve there.
    if model.n_masses() > EQUIVALENTS_MAX_MASSES {
        return None;
    }
    let tf = model.undamped_tf();
    let degrees_match = tf.num.degree(mms::OMEGA) as usize + 1 == num.len()
        && tf.den.degree(mms::OMEGA) as usize + 1 == den.len();
    if !degrees_match {
        return None;
    }
    back_solve(model, &measured_target(num, den).ok()?).ok()
}

/// The features of an undamped target `(num, den)`: its roots and static
/// level (`None` if a root is off the positive real axis).
fn feature_target((num, den): &(Vec<f64>, Vec<f64>)) -> Option<FeatureTarget> {
    let real = |c: &[f64]| -> Option<Vec<f64>> {
        roots(c)
            .iter()
            .map(|z| (z.im.abs() <= 1e-9 * z.norm() && z.re > 0.0).then_some(z.re))
            .collect()
    };
    Some(FeatureTarget {
        antiresonances: real(num)?,
        resonances: real(den)?,
        static_inertance: (num[0] / den[0]).abs(),
    })
}

/// The undamped starts a back-solution offers: its points, and members of
/// each family spread over the family's intervals (the damped data often
/// single out a member near an end of an interval, so the spread is
/// logistic: dense towards both ends).
pub(crate) fn undamped_starts(solution: &BackSolution) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = solution.points().iter().map(|s| s.values.clone()).collect();
    for fam in solution.families() {
        let before = out.len();
        if fam.dimension() == 1 {
            for iv in &fam.intervals {
                let lo = iv.lo.value;
                let hi = iv.hi.as_ref().map(|h| h.value);
                for k in 0..12 {
                    let u = -4.0 + 8.0 * k as f64 / 11.0;
                    let t = 1.0 / (1.0 + (-u).exp());
                    let x = match hi {
                        Some(hi) => lo + (hi - lo) * t,
                        // Unbounded above: spread over two decades.
                        None => lo.max(f64::MIN_POSITIVE) * (1.0 + 100.0 * t),
                    };
                    out.extend(fam.members_f64(&[x]));
                }
            }
        }
        if out.len() == before {
            out.extend(fam.samples.iter().cloned());
        }
    }
    out.retain(|v| v.iter().all(|x| x.is_finite() && *x > 0.0));
    out
}

/// Deterministic multi-start: masses around the level's total mass,
/// springs placing the uncoupled frequencies across the band; each start
/// briefly fitted, the best finished.
fn multistart(
    model: &Model,
    output: Output,
    data: &Frf,
    zeta: f64,
    fixed: &[String],
    options: &IdentifyOptions,
) -> Result<Fit, IdentifyError> {
    let n = model.n_masses();
    let n_springs = model.springs().len();
    let f = data.freq_hz();
    let (f_lo, f_hi) = (f[0], f[f.len() - 1]);
    // Total mass from the low-frequency inertance level (the rigid body).
    let k_power = output.s_power() as i32;
    let low = data.response()[..(data.len() / 20).max(1)]
        .iter()
        .zip(f)
        .map(|(&h, &fr)| (h * Complex64::new(0.0, 2.0 * PI * fr).powi(2 - k_power)).norm())
        .sum::<f64>()
        / (data.len() / 20).max(1) as f64;
    let total = if low > 0.0 && low.is_finite() {
        1.0 / low
    } else {
        1.0
    };
    let mut rng = XorShift::new(options.seed ^ (model.id().len() as u64) << 8 ^ model_hash(model));
    let short = FitOptions {
        fixed: fixed.to_vec(),
        ..fit_options(options, 25)
    };
    let mut trials: Vec<Fit> = Vec::new();
    for _ in 0..options.multistarts.max(1) {
        let masses: Vec<f64> = (0..n)
            .map(|_| total / n as f64 * rng.log_uniform(0.2, 5.0))
            .collect();
        let mean_mass = masses.iter().sum::<f64>() / n as f64;
        let springs: Vec<f64> = (0..n_springs)
            .map(|_| {
                let w = 2.0 * PI * rng.log_uniform(f_lo, f_hi);
                mean_mass * w * w
            })
            .collect();
        let mut undamped = masses;
        undamped.extend(springs);
        let p = Parameters::from_values(model, with_dampers(model, &undamped, zeta))?;
        if let Ok(t) = fit(model, output, data, &p, &short) {
            trials.push(t);
        }
    }
    trials.sort_by(|a, b| score(a).total_cmp(&score(b)));
    let full = FitOptions {
        fixed: fixed.to_vec(),
        ..fit_options(options, 200)
    };
    let mut best: Option<Fit> = None;
    for t in trials.iter().take(3) {
        let f = fit_two_phase(
            model,
            output,
            data,
            &t.parameters,
            &FitOptions {
                gain: match options.gain {
                    Gain::Known(g) => Gain::Known(g),
                    Gain::Fit(_) => Gain::Fit(t.gain),
                },
                ..full.clone()
            },
        )?;
        if best.as_ref().is_none_or(|b| score(&f) < score(b)) {
            best = Some(f);
        }
    }
    match best {
        Some(b) => Ok(b),
        None => {
            // Every start failed to evaluate: report the plain start.
            let p = Parameters::from_values(model, vec![1.0; model.parameters().len()])?;
            Ok(fit(model, output, data, &p, &full)?)
        }
    }
}

fn model_hash(m: &Model) -> u64 {
    m.id().bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    })
}

/// Whether a parameter of `f` ended at an end of its physical range: the
/// fit degenerated into another structure ([`CandidateFit::failed`]).
pub(crate) fn degenerate(model: &Model, f: &Fit) -> bool {
    at_range_end(&plausibility(model, f))
}

/// Whether `notes` say a parameter ended at an end of its range.
fn at_range_end(notes: &[CandidateNote]) -> bool {
    notes
        .iter()
        .any(|n| matches!(n, CandidateNote::AtRangeEnd { .. }))
}

/// Remarks an engineer would make about a fitted parameter set.
fn plausibility(model: &Model, f: &Fit) -> Vec<CandidateNote> {
    let mut notes = Vec::new();
    let n = model.n_masses();
    let v = f.parameters.values();
    let masses = &v[..n];
    let (mn, mx) = masses
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &m| (a.min(m), b.max(m)));
    if mx / mn > 1e3 {
        notes.push(CandidateNote::MassSpread { factor: mx / mn });
    }
    let m = mn;
    let names = model.parameters();
    let n_links = model.springs().len();
    for (name, &x) in names.iter().zip(v).take(n + n_links) {
        let range = mms::ranges::of_parameter(name);
        if x <= range.min || x >= range.max {
            notes.push(CandidateNote::AtRangeEnd {
                parameter: name.clone(),
                value: x,
            });
        }
    }
    // Damping ratio of each link on its own, against the lightest mass (a
    // bound from above on the ratio against any body the link joins).
    for k in 0..n_links {
        let c = v[n + k];
        let d = v[n + n_links + k];
        let zeta = d / (2.0 * (c * m).sqrt());
        if zeta > 0.5 {
            notes.push(CandidateNote::HeavilyDamped {
                damper: names[n + n_links + k].clone(),
                damping_ratio: zeta,
            });
        }
    }
    notes
}
