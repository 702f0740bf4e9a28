//! What a reader of an identification should know, as data: the band
//! and line decisions of the classification ([`ClassifyNote`]), how the
//! candidates were chosen and the scale fixed ([`IdentifyNote`]), remarks
//! on one fitted candidate ([`CandidateNote`]) and on an identification
//! from several sensors ([`SensorsNote`]). The libraries return these; the
//! formatter writes the sentences.
//!
//! Every note serialises as an object whose `kind` names the variant in
//! snake case, beside its fields: `{"kind": "at_band_edge", "feature":
//! "resonance", "freq_hz": 212.5}`.

use crate::classify::{ser_feature, ser_type};
use mms::analysis::{Feature, FrfType};
use mms::backsolve::NoSolution;
use mms::Output;
use serde::{Serialize, Serializer};

/// A decision of [`classify`](crate::classify::classify) about the band,
/// the lines or the features, in the order it was taken.
///
/// ```
/// use frf::{Complex64, Frf};
/// use ident::notes::ClassifyNote;
/// use ident::{classify, ClassifyOptions};
/// use mms::Output;
///
/// // An antiresonance at 40 Hz and a resonance at 60 Hz (1 % damping),
/// // from 0 Hz in 0.5 Hz steps, classified in the band 10 .. 150 Hz.
/// let factor = |s: Complex64, f: f64| {
///     let w = 2.0 * std::f64::consts::PI * f;
///     1.0 + 0.02 * s / w + (s / w) * (s / w)
/// };
/// let freq: Vec<f64> = (0..=400).map(|i| 0.5 * i as f64).collect();
/// let response = freq
///     .iter()
///     .map(|&f| {
///         let s = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
///         factor(s, 40.0) / factor(s, 60.0)
///     })
///     .collect();
/// let frf = Frf::new(freq, response, None)?;
/// let options = ClassifyOptions { band_hz: Some((10.0, 150.0)), ..ClassifyOptions::default() };
/// let c = classify(&frf, Output::Acceleration, &options).unwrap();
/// assert_eq!(c.notes[0], ClassifyNote::ZeroHzLeftOut);
/// assert_eq!(
///     c.notes[1],
///     ClassifyNote::BandAsGiven { low_hz: 10.0, high_hz: 150.0, lines: 281 }
/// );
/// # Ok::<(), frf::FrfError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ClassifyNote {
    /// The lines' uncertainty comes from the coherence with a number of
    /// averages assumed, the count not being known.
    AssumedAverages {
        /// The averages assumed.
        averages: f64,
    },
    /// The 0 Hz line is left out: the inertance is undefined there.
    ZeroHzLeftOut,
    /// Lines without excitation (or with a zero response) carry no
    /// information and are left out.
    Unexcited {
        /// How many.
        lines: usize,
    },
    /// The band the caller gave: every line in it is used, each weighted by
    /// its uncertainty.
    BandAsGiven {
        /// Its first line, Hz.
        low_hz: f64,
        /// Its last line, Hz.
        high_hz: f64,
        /// The lines in it.
        lines: usize,
    },
    /// No coherence or standard deviation tells which lines inform: the
    /// whole range is used, each line weighted by its uncertainty.
    BandWholeRange {
        /// Its first line, Hz.
        low_hz: f64,
        /// Its last line, Hz.
        high_hz: f64,
        /// The lines in it.
        lines: usize,
    },
    /// The band chosen from the line uncertainty: the widest run of
    /// informative lines.
    BandInformative {
        /// Its first line, Hz.
        low_hz: f64,
        /// Its last line, Hz.
        high_hz: f64,
        /// The informative lines in it.
        informative_lines: usize,
        /// All excited lines of the FRF.
        excited_lines: usize,
        /// The largest smoothed uncertainty of an informative line, in
        /// nepers.
        max_std_dev_nepers: f64,
        /// The same in dB.
        max_std_dev_db: f64,
    },
    /// Less certain lines inside the band are kept with their low weight.
    LowWeightKept {
        /// How many.
        lines: usize,
        /// The widest gap of less certain lines the band bridges, in
        /// decades.
        max_gap_decades: f64,
    },
    /// Informative lines outside the band are not used.
    InformativeOutside {
        /// How many.
        lines: usize,
    },
    /// Lines with a zero response are left out.
    ZeroResponse {
        /// How many.
        lines: usize,
    },
    /// Too many lines scatter like outliers to be outliers: all are kept.
    OutliersKept {
        /// How many.
        lines: usize,
    },
    /// Isolated outlier lines are left out.
    OutliersLeftOut {
        /// Their frequencies, Hz, increasing.
        at_hz: Vec<f64>,
    },
    /// Two features of one kind closer than their widths are taken as one
    /// (a peak split by noise); the more confident stays.
    Merged {
        /// Their kind.
        #[serde(serialize_with = "ser_feature")]
        feature: Feature,
        /// The lower, Hz.
        first_hz: f64,
        /// The higher, Hz.
        second_hz: f64,
    },
    /// A feature found from its phase step alone, without an extremum of
    /// the magnitude.
    PhaseOnly {
        /// Its kind (an antiresonance's phase rises, a resonance's falls).
        #[serde(serialize_with = "ser_feature")]
        feature: Feature,
        /// Where, Hz.
        freq_hz: f64,
        /// Its phase change, degrees.
        phase_change_deg: f64,
    },
    /// Feature candidates not claimed: the lines there are too uncertain
    /// for their phase, so a phase step there can be a turn of noise.
    PhaseUndetermined {
        /// Where, Hz.
        at_hz: Vec<f64>,
        /// The smoothed line uncertainty above which the phase is not
        /// determined, radians.
        max_std_dev_rad: f64,
    },
    /// A resonance and an antiresonance so close that the undamped model
    /// may cancel them: both confidences are capped.
    NearCancellation {
        /// The lower feature's kind.
        #[serde(serialize_with = "ser_feature")]
        first: Feature,
        /// Where, Hz.
        first_hz: f64,
        /// The higher feature's kind.
        #[serde(serialize_with = "ser_feature")]
        second: Feature,
        /// Where, Hz.
        second_hz: f64,
        /// Their distance relative to the lower (0.05: 5 %).
        relative_separation: f64,
        /// The cap on both confidences.
        confidence_cap: f64,
    },
    /// The gain-phase budget: how much more the level and the phase rise
    /// from the bottom to the top of the band than the features explain.
    GainPhaseBudget {
        /// The unexplained level rise, dB.
        level_db: f64,
        /// The unexplained phase rise, degrees.
        phase_deg: f64,
    },
    /// The unexplained level rise comes with a phase rise: an
    /// antiresonance may have been missed.
    LevelRiseWithPhaseRise,
    /// The level falls more than the features explain: a resonance missed
    /// or just outside the band.
    LevelFalls,
    /// The phase falls more than the features explain: a delay, or a
    /// resonance missed.
    PhaseFalls,
    /// No gain-phase budget: too few feature-free lines at the band ends.
    NoBudget,
    /// A grid so coarse that a resonance and an antiresonance closer than
    /// two lines can be missed: every confidence is scaled down.
    CoarseGrid {
        /// The median distance of neighbouring lines relative to the lower
        /// (0.2: 20 %).
        relative_spacing: f64,
        /// The factor every confidence is scaled by.
        confidence_scale: f64,
    },
    /// A feature at the band edge, whose confidence is lowered.
    AtBandEdge {
        /// Its kind.
        #[serde(serialize_with = "ser_feature")]
        feature: Feature,
        /// Where, Hz.
        freq_hz: f64,
    },
    /// A feature found but left out of the type: its confidence is below
    /// the minimum.
    LeftOut {
        /// Its kind.
        #[serde(serialize_with = "ser_feature")]
        feature: Feature,
        /// Where, Hz.
        freq_hz: f64,
        /// Its confidence.
        confidence: f64,
        /// The minimum confidence of a feature of the type.
        min_confidence: f64,
    },
    /// With the features divided out, the inertance is not flat at the
    /// bottom of the band, where a free chain's is: a feature just below
    /// the band, or a wrong output kind. The level budget is not used for
    /// nm and the type's confidence is capped.
    UnflatBottom {
        /// The slope, `ln|G|` per `ln w`.
        slope: f64,
        /// The output the FRF was read as.
        output: Output,
        /// The cap on the type's confidence.
        confidence_cap: f64,
    },
}

/// How [`identify`](crate::identify::identify) prepared its candidates and
/// fixed the scale, and what it could not fit, in that order.
///
/// ```
/// use ident::identify::{identify, IdentifyOptions};
/// use ident::notes::IdentifyNote;
/// use ident::synth::{synthetic, SynthOptions};
/// use mms::Model;
///
/// let b2 = Model::from_id("B2")?;
/// let mut rng = mms::xorshift::XorShift::new(3);
/// let s = synthetic(&mut rng, Some(b2), &SynthOptions::default())?;
/// let id = identify(&s.frf, s.output, &IdentifyOptions::default())?;
/// assert_eq!(
///     id.notes,
///     [
///         IdentifyNote::CandidatesFromTypeTable { masses: 3, frf_type: s.frf_type.clone() },
///         IdentifyNote::GainKnown { gain: 1.0 },
///     ]
/// );
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum IdentifyNote {
    /// More lines than an identification works on were averaged into
    /// log-spaced bins, each weighted by its lines' uncertainty.
    Binned {
        /// The lines read.
        lines: usize,
        /// The most bins ([`MAX_LINES`](crate::identify::MAX_LINES)).
        max_bins: usize,
    },
    /// The candidates are the structures whose exact FRF-type table lists
    /// the classified type as possible.
    CandidatesFromTypeTable {
        /// Their masses.
        masses: usize,
        /// The classified type (serialised as its text).
        #[serde(serialize_with = "ser_type")]
        frf_type: FrfType,
    },
    /// The candidates are the structures whose transfer function has the
    /// degrees the classified type needs (above 3 masses, where the exact
    /// type table is not used).
    CandidatesFromDegrees {
        /// Their masses.
        masses: usize,
        /// The classified type (serialised as its text).
        #[serde(serialize_with = "ser_type")]
        frf_type: FrfType,
    },
    /// No structure of that many masses can show the classified type:
    /// every structure is fitted instead.
    NoStructureShowsType {
        /// The masses.
        masses: usize,
        /// The classified type (serialised as its text).
        #[serde(serialize_with = "ser_type")]
        frf_type: FrfType,
    },
    /// The actuator and sensor gain is known: the parameters are absolute.
    GainKnown {
        /// The gain (negative for a reversed sensor).
        gain: f64,
    },
    /// The gain is fitted and `m1` held at its start value: only ratios of
    /// parameters are identified.
    GainFitted,
    /// Below its features the inertance is negative, where every chain's
    /// is `1 / (sum of masses) > 0`: the sensor (or actuator) counts the
    /// other way, and the gain is taken negative.
    SensorReversed,
    /// The exactly equivalent parameter sets (the paper's Tab. 7) are
    /// back-solved up to [`EQUIVALENTS_MAX_MASSES`](crate::identify::EQUIVALENTS_MAX_MASSES)
    /// masses only: above, the exact elimination of one candidate can
    /// take minutes, which no work limit bounds without depending on the
    /// machine's speed.
    EquivalentsNotSolved {
        /// The masses of the candidates.
        masses: usize,
    },
    /// The level below the features read said the sensor counts the other
    /// way, but the fits of that polarity missed the lines by far more
    /// than their scatter and those of the sensor's own polarity explain
    /// them far better: features missed between or below the lines had set
    /// that level.
    PolarityFromFit {
        /// The best fit taken (RMS of the complex log error, dB-equivalent).
        score_db: f64,
        /// The best fit with the sensor taken as reversed.
        reversed_db: f64,
    },
    /// The structures that can show the type read missed the lines by far
    /// more than their scatter (an antiresonance closer to its resonance
    /// than the line spacing shows in no type): every other structure of
    /// these masses and modes was fitted too and ranked with them.
    TypeOpened {
        /// The masses.
        masses: usize,
        /// The structures added.
        structures: usize,
        /// The best fit of all (RMS of the complex log error,
        /// dB-equivalent).
        score_db: f64,
        /// The best fit of those showing the type read.
        type_db: f64,
    },
    /// The structures of the type read missed the lines by far more than
    /// their scatter, and those with a mode more (a resonance and
    /// antiresonance closer than the line spacing, or sharper than it,
    /// show in no type) explain them far better: the candidates have
    /// `masses` masses.
    MassesFromFit {
        /// The masses taken.
        masses: usize,
        /// The best fit with them (RMS of the complex log error,
        /// dB-equivalent).
        score_db: f64,
        /// The best fit with one mass fewer.
        fewer_db: f64,
    },
    /// The structures of the type read missed the lines by far more than
    /// their scatter; those with a mode more were fitted too but did not
    /// explain the lines far better, so they are not the candidates.
    MoreModesTried {
        /// Their masses.
        masses: usize,
        /// Their best fit (dB-equivalent).
        score_db: f64,
        /// The best fit kept.
        kept_db: f64,
    },
    /// A candidate could not be fitted; the others were.
    NotFitted {
        /// The candidate's ID.
        structure: String,
        /// The error's message.
        error: String,
    },
}

/// A remark on one fitted candidate's parameters or start, as an engineer
/// would make it.
///
/// ```
/// use ident::notes::CandidateNote;
///
/// let n = CandidateNote::HeavilyDamped { damper: "d2".into(), damping_ratio: 0.8 };
/// assert_eq!(
///     serde_json::to_string(&n)?,
///     r#"{"kind":"heavily_damped","damper":"d2","damping_ratio":0.8}"#
/// );
/// # Ok::<(), serde_json::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CandidateNote {
    /// The fitted masses span more than a factor 1000.
    MassSpread {
        /// The heaviest mass over the lightest.
        factor: f64,
    },
    /// A mass or a spring ended at an end of its physical range
    /// (`mms::ranges`), which the fit may not leave: the data drive it
    /// towards zero or infinity, so the structure degenerates into one with
    /// fewer masses or a rigid link.
    AtRangeEnd {
        /// The parameter's name.
        parameter: String,
        /// Its value, the end of the range.
        value: f64,
    },
    /// A link's damping ratio on its own, against the lightest mass, is
    /// above 0.5.
    HeavilyDamped {
        /// The damper's parameter name.
        damper: String,
        /// That damping ratio.
        damping_ratio: f64,
    },
    /// No positive undamped parameter set reproduces the classified
    /// features: the fit started elsewhere.
    NoBackSolution {
        /// Why (serialised as an object whose `kind` names the reason).
        #[serde(serialize_with = "ser_no_solution")]
        reason: NoSolution,
        /// The structure's undamped parameters.
        parameters: usize,
        /// How many of them the FRF determines (Tab. 5); fewer than
        /// `parameters` when the structure has fewer degrees of freedom
        /// than its FRF type has numbers.
        determinable: usize,
    },
}

/// How [`identify_sensors`](crate::joint::identify_sensors) chose its
/// candidates and what it could not fit.
///
/// ```
/// use ident::notes::SensorsNote;
///
/// let n = SensorsNote::NotFitted { candidate: "A1+s3".into() };
/// assert_eq!(serde_json::to_string(&n)?, r#"{"kind":"not_fitted","candidate":"A1+s3"}"#);
/// # Ok::<(), serde_json::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SensorsNote {
    /// The candidates are every chain and actuator (rules (1) and (2) with
    /// the first sensor) with the sensors at the given locations whose
    /// outputs can each show the type classified there (outputs with fewer
    /// resonances than the most are not used to choose).
    CandidatesShowingTypes {
        /// Their masses.
        masses: usize,
    },
    /// A sensor's place names a mass beyond what the types read: the
    /// chain has at least that many masses (a resonance and antiresonance
    /// closer than the line spacing show in no type).
    MassesFromSensorPlaces {
        /// The masses tried.
        masses: usize,
        /// The masses the most resonant output's type implies.
        from_types: usize,
    },
    /// No chain shows every output's type with the sensors at these
    /// locations: every such chain is fitted instead.
    NoChainShowsTypes {
        /// The masses.
        masses: usize,
    },
    /// A candidate none of whose starts could be fitted.
    NotFitted {
        /// The candidate's ID.
        candidate: String,
    },
}

/// A reason without a positive back-solution as an object tagged by its
/// `kind`; the relation and its value as their exact text.
pub(crate) fn ser_no_solution<S: Serializer>(r: &NoSolution, s: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    #[serde(tag = "kind", rename_all = "snake_case")]
    enum Reason<'a> {
        Degree {
            structure: (usize, usize),
            target: (usize, usize),
        },
        SignPattern {
            coefficient: &'a str,
            structure_sign: i32,
            target_sign: i32,
        },
        ViolatedRelation {
            relation: String,
            value: String,
            relative: f64,
        },
        NotPositive {
            candidates: &'a [Vec<f64>],
        },
        Contradiction,
    }
    let reason = match r {
        NoSolution::Degree { structure, target } => Reason::Degree {
            structure: *structure,
            target: *target,
        },
        NoSolution::SignPattern {
            coefficient,
            structure_sign,
            target_sign,
        } => Reason::SignPattern {
            coefficient,
            structure_sign: *structure_sign,
            target_sign: *target_sign,
        },
        NoSolution::ViolatedRelation {
            relation,
            value,
            relative,
        } => Reason::ViolatedRelation {
            relation: relation.to_string(),
            value: value.to_string(),
            relative: *relative,
        },
        NoSolution::NotPositive { candidates } => Reason::NotPositive { candidates },
        NoSolution::Contradiction => Reason::Contradiction,
    };
    reason.serialize(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn notes_serialise_tagged_by_kind() {
        let n = ClassifyNote::AtBandEdge {
            feature: Feature::Resonance,
            freq_hz: 212.5,
        };
        assert_eq!(
            serde_json::to_value(&n).unwrap(),
            json!({"kind": "at_band_edge", "feature": "resonance", "freq_hz": 212.5})
        );
        assert_eq!(
            serde_json::to_value(ClassifyNote::NoBudget).unwrap(),
            json!({"kind": "no_budget"})
        );
        let n = IdentifyNote::CandidatesFromTypeTable {
            masses: 3,
            frf_type: "A^2RR".parse().unwrap(),
        };
        assert_eq!(
            serde_json::to_value(&n).unwrap(),
            json!({"kind": "candidates_from_type_table", "masses": 3, "frf_type": "A^2RR"})
        );
        let n = CandidateNote::NoBackSolution {
            reason: NoSolution::SignPattern {
                coefficient: "Num Omega^1".into(),
                structure_sign: 1,
                target_sign: -1,
            },
            parameters: 5,
            determinable: 4,
        };
        assert_eq!(
            serde_json::to_value(&n).unwrap(),
            json!({
                "kind": "no_back_solution",
                "reason": {
                    "kind": "sign_pattern",
                    "coefficient": "Num Omega^1",
                    "structure_sign": 1,
                    "target_sign": -1
                },
                "parameters": 5,
                "determinable": 4
            })
        );
    }
}
