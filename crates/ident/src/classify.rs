//! FRF-type classification of a measured, damped, noisy FRF.
//!
//! [`classify`] reads the paper's FRF type (Tantau et al., Sec. 4 and
//! Tab. 3: antiresonances `A` and resonances `R` in increasing frequency,
//! `A^2` for a double zero, `(nm)` for zeros off the positive real `Omega`
//! axis) from a measured [`Frf`], with a confidence for every feature, and
//! the band in which the data were trusted.
//!
//! # Algorithm
//!
//! 1. **Band.** Lines at 0 Hz and outside [`ClassifyOptions::band_hz`]
//!    are dropped, and so are lines the excitation did not reach (an
//!    infinite standard deviation). Every line has a relative standard
//!    deviation ([`frf::uncertainty::line_uncertainty`]: the FRF's own, or
//!    from its coherence and [`ClassifyOptions::averages`], or from the
//!    scatter of the data). With a user's band, that is the band: every
//!    line in it is used, weighted by its uncertainty. Without one, a line
//!    is informative when its uncertainty, smoothed by a running median
//!    over [`ClassifyOptions::smoothing_lines`], is at most
//!    [`ClassifyOptions::informative_std_dev`]; runs of informative lines
//!    are joined across gaps up to [`ClassifyOptions::max_gap_decades`]
//!    (at an antiresonance a collocated sensor sees little motion, so the
//!    uncertainty rises there by nature: those lines stay in the band with
//!    their low weight), and the band is the run with the most informative
//!    lines, counted by the share of a decade each covers (a band measured
//!    on a linear grid has most of its lines at the top). Isolated
//!    outlier lines (a line far off a curve on which its
//!    two neighbours on each side agree) are left out.
//! 2. **Inertance.** The response is multiplied by `(j w)^(2-k)` (`k` the
//!    output's power of `s`), which removes the rigid-body slope: every
//!    model has a rigid-body mode, so the inertance is flat apart from its
//!    features. The analysis works on `ln|G|` and the unwrapped phase over
//!    `x = ln w`.
//! 3. **Noise.** The noise of a line is the larger of its own
//!    uncertainty (step 1) and the local scatter of the data
//!    ([`frf::uncertainty::scatter`]: the robust scale of the
//!    second-difference residuals of `ln G` over 41 lines), so that an
//!    optimistic estimate (few averages, leakage) cannot make noise
//!    significant.
//! 4. **Candidates.** Every local maximum (resonance candidate) and minimum
//!    (antiresonance candidate) of `ln|G|` whose prominence (looking up to
//!    a factor 2 in frequency to either side) exceeds
//!    [`ClassifyOptions::detection_sigma`] noise standard deviations of a
//!    difference of two lines. Candidates at 8 or more are *strong*: they
//!    bound the neighbourhood of the others.
//! 5. **Phase confirmation.** The neighbourhood of a candidate reaches
//!    half-way to the next strong candidate, at most a factor 1.8 in
//!    frequency. Within `+-10 zeta` of it (`zeta` from the half-power
//!    width; +-35 % in frequency when that is unknown) a second-order
//!    factor with a linear background is fitted to the complex data
//!    (`G (1 - w^2/w0^2 + 2 j zeta w/w0) = p0 + p1 ln(w/wc)` for a peak,
//!    the same for `1/G` for a dip): the natural frequency `w0` and the
//!    damping ratio `zeta`. The phase change across the candidate is the
//!    mean unwrapped phase right of it minus the mean left of it, both
//!    outside `3 zeta`; it is compared with what a resonance (`-m 180 deg`),
//!    an antiresonance (`+m 180 deg`, `m = 2` for a double zero) or a zero
//!    pair off the positive `Omega` axis (0 deg or the wrong way) would give
//!    between the same lines. Then every candidate is evaluated again with
//!    the damped factors of the other features found divided out, until
//!    the set of features no longer changes (at most three rounds): the
//!    phase tails of close, heavily damped neighbours would otherwise bias
//!    the phase change. Last, steps of the phase left over (at least
//!    63 deg and 6 noise standard deviations between the means over
//!    +-16 % in frequency) are candidates too: features without an
//!    extremum of the magnitude.
//! 6. **Confidence.** `agreement x significance x (0.6 + 0.4 magnitude)`,
//!    where *agreement* is a Gaussian in the phase error (tolerance 36 deg
//!    and the phase noise), *significance* a logistic in the phase change
//!    over its noise (0.5 at 4 sigma), *magnitude* a logistic in the
//!    prominence over its noise (0.5 at 4 sigma; 0 for a phase step without
//!    an extremum, which so gets at most 0.6). A phase change alone can
//!    carry a shallow, heavily damped feature; a magnitude extremum without
//!    the matching phase change cannot. Features within `5 zeta` (or three
//!    lines) of a band edge, or without a phase reference on one side, get
//!    a factor 0.6, those whose reference on one side lies inside their own
//!    transition (a close neighbour) 0.85; a dip and a peak closer than
//!    [`ClassifyOptions::near_cancellation`] (a near pole-zero cancellation)
//!    are capped at 0.4. Of two features of one kind within half their
//!    half-power bandwidths (a peak split by noise) the weaker goes.
//!    Features under [`ClassifyOptions::min_confidence`] are listed but not
//!    in the type. No feature is claimed where the lines' own uncertainty,
//!    as a running median over 41 lines, exceeds 0.5 rad: there the phase
//!    unwraps by random turns (a closed loop's 3-point estimate far above
//!    its bandwidth), and its steps are noise.
//!    On a grid coarser than 16 % between lines (median), a resonance and
//!    an antiresonance can hide between two lines: every confidence is
//!    then scaled by `0.15 / spacing` in `ln w` (at least 0.3).
//! 7. **Non-minimum phase.** Two kinds of evidence, both taken from the
//!    data with the damped factors of all features divided out (so that
//!    the valley between two resonances is no dip): a prominent dip (0.5 at
//!    10 noise standard deviations and 2 dB) whose phase does not rise
//!    (complex `Omega` zeros near the axis), and the Bode gain-phase budget
//!    of the whole curve: the level at the top of the band relative to the
//!    bottom is what zeros without an antiresonance (negative or complex
//!    `Omega`) add, and they add no net phase. A level excess of at least
//!    3 dB and 5 noise standard deviations without a matching phase rise
//!    (which would be a missed antiresonance) is `nm`; its confidence is
//!    capped at 0.9, since a resonance just above the band raises the top
//!    level in the same way. The budget is not used when the bottom of the
//!    band is not flat (slope over 1 in `ln|G|` per `ln w`): there a
//!    feature just below the band, or a wrong output kind, would pass for
//!    a level excess.
//!
//! Limitations: a pure delay (sampling, ZOH) is not removed, so the phase
//! budget of data with a large delay is noted, not used; a dip of complex
//! `Omega` zeros that is a single line wide is taken for an outlier; an
//! antiresonance and a resonance closer than about two half-power
//! bandwidths with damping ratios of 8 % or more can vanish together (the
//! damped FRF then shows neither) or be found only without noise.

use crate::notes::ClassifyNote;
pub use frf::uncertainty::Source as UncertaintySource;
use frf::uncertainty::{line_uncertainty, scatter, second_differences};
use frf::Frf;
use mms::analysis::{Feature, FrfType, Token};
use mms::Output;
use num_complex::Complex64;
use serde::{Serialize, Serializer};
use std::f64::consts::{LN_10, PI};

/// Decibels per neper (natural-log unit of magnitude).
const DB_PER_NEPER: f64 = 20.0 / LN_10;
/// The lower quartile of `|N(0, 1)|`: a robust scale that tolerates up to
/// three quarters of the window being curvature near features.
const Q25_ABS_NORMAL: f64 = 0.318_639_363_964_375_5;
/// Smallest noise standard deviation in nepers (0.009 dB): rounding-level
/// scatter of noise-free data must not make every ripple significant.
const SIGMA_FLOOR: f64 = 1e-3;
/// Largest noise standard deviation (nepers) a line can get from its own
/// uncertainty (coherence near 0 would give infinity).
const SIGMA_CEILING: f64 = 10.0;
/// Largest half-width in `ln w` of the local fit (about +-35 % in frequency).
const FIT_HALF_WIDTH: f64 = 0.3;
/// Median line spacing in `ln w` (16 % in frequency) above which all
/// confidences are scaled by `COARSE_SPACING / spacing` (at least 0.3).
const COARSE_SPACING: f64 = 0.15;
/// Farthest reach in `ln w` (a factor 1.8 in frequency) of the
/// neighbourhood of a candidate: its phase references and its fit.
const NEIGHBOURHOOD: f64 = 0.6;
/// Most lines of one phase reference zone (a dense grid is thinned).
const ZONE_MAX_LINES: usize = 200;
/// Most lines of one local fit (a dense grid is thinned).
const FIT_MAX_LINES: usize = 400;
/// Farthest distance in `ln w` (a factor 2 in frequency) the prominence of
/// an extremum looks on either side.
const PROMINENCE_REACH: f64 = 0.7;
/// Candidates at this many noise standard deviations bound the others.
const STRONG_SIGMA: f64 = 8.0;
/// A phase step between two lines beyond this (150 deg) is ambiguous in
/// sign: the magnitude decides ([`Data::unwrap_phase`]).
const AMBIGUOUS_STEP: f64 = 150.0 * PI / 180.0;
/// Lines on either side of an ambiguous step that tell a notch or a peak
/// several lines wide ([`Data::unwrap_phase`]).
const AMBIGUOUS_FLANK: usize = 3;

/// Features and nm dips under this confidence are not reported at all.
const REPORT_CONFIDENCE: f64 = 0.1;
/// Confidence cap of a near pole-zero cancellation.
const NEAR_CANCELLATION_CAP: f64 = 0.4;
/// Confidence factor of a feature at a band edge or with one side missing.
const EDGE_FACTOR: f64 = 0.6;
/// Confidence factor of a feature whose phase reference on one side is
/// inside its own transition (a close neighbour).
const PARTIAL_FACTOR: f64 = 0.85;
/// Model tolerance of a phase change: tails of neighbours, background.
const PHASE_TOLERANCE: f64 = 0.2 * PI;
/// Smallest level excess (nepers, 3 dB) that counts as zeros without
/// antiresonance.
const LEVEL_MIN_EXCESS: f64 = 0.35;
/// Prominence (noise standard deviations) at which a dip without a phase
/// rise is nm evidence of confidence 0.5.
const NM_DIP_SIGMA: f64 = 10.0;
/// Depth (nepers, 2 dB) at which a dip without a phase rise is nm evidence
/// of confidence 0.5.
const NM_DIP_DEPTH: f64 = 0.23;
/// Most rounds of evaluation with the other features divided out.
const DEFLATION_ROUNDS: usize = 3;
/// Half-width in `ln w` of the windows of the phase-step search.
const PHASE_STEP_HALF: f64 = 0.15;
/// Smallest phase step (radians) of a feature without a magnitude extremum.
const PHASE_STEP_MIN: f64 = 0.35 * PI;
/// The smoothed uncertainty of the lines (radians of phase) above which a
/// feature is not claimed. The phase difference of two neighbouring lines
/// of noise `s` exceeds `pi`, and unwrapping then steps by a whole turn,
/// with probability `2 Phi(-pi / (s sqrt 2))`: 1e-5 per line at 0.5 rad,
/// 0.5 % at 0.8. Above this level a random walk of turns, not the system,
/// makes the phase steps a feature is read from.
const PHASE_UNDETERMINED: f64 = 0.5;
/// Half the window (lines) of the running median of the lines' own
/// uncertainty for [`PHASE_UNDETERMINED`]: wide enough that the few lines
/// of low coherence at an antiresonance (where a collocated sensor sees
/// little motion) do not count as a region without phase.
const PHASE_WINDOW_HALF: usize = 20;

/// Cap of the type's confidence when the bottom of the band is not flat.
const UNFLAT_BOTTOM_CAP: f64 = 0.5;
/// Confidence cap of nm evidence from the level budget alone.
const LEVEL_CAP: f64 = 0.9;
/// Share of the band's `ln w` span used as low and high reference regions
/// of the budget.
const BUDGET_REGION: f64 = 0.15;

/// Options of [`classify`]; [`Default`] gives the documented defaults.
///
/// ```
/// use ident::ClassifyOptions;
/// // analyse the excitation band only, every line weighted by its uncertainty
/// let o = ClassifyOptions {
///     band_hz: Some((5.0, 500.0)),
///     ..Default::default()
/// };
/// assert_eq!(o.min_confidence, 0.5);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClassifyOptions {
    /// Without a user's band, a line is informative when its smoothed
    /// relative standard deviation is at most this, in nepers (default
    /// 0.2: 1.7 dB and 11 deg, what a resonance or antiresonance needs to
    /// stand out of a few lines; with `n` averages that is a coherence
    /// above `1 / (1 + 0.08 n)`, 0.24 for 40 averages).
    pub informative_std_dev: f64,
    /// Odd number of lines of the running median that smooths the
    /// uncertainty before that test (default 5).
    pub smoothing_lines: usize,
    /// Gaps of uninformative lines up to this width in decades are bridged
    /// (default 0.15, a factor 1.41 in frequency: the drop of the
    /// coherence at a lightly damped antiresonance measured with a noisy
    /// sensor).
    pub max_gap_decades: f64,
    /// Effective number of averages behind the FRF's coherence, used when
    /// the FRF has a coherence but no standard deviation of its own: the
    /// uncertainty of each line then comes from its coherence (default
    /// `None`: 16 averages are assumed, and the notes say so).
    pub averages: Option<u32>,
    /// Restrict the analysis to this band in Hz, e.g. the excitation band
    /// (default `None`: all lines).
    pub band_hz: Option<(f64, f64)>,
    /// Smallest prominence of a candidate extremum, in noise standard
    /// deviations of a difference of two lines (default 3).
    pub detection_sigma: f64,
    /// Features from this confidence on make up the type (default 0.5).
    pub min_confidence: f64,
    /// A dip and a peak closer than this relative frequency separation are
    /// a near pole-zero cancellation (default 0.03, i.e. 3 %).
    pub near_cancellation: f64,
    /// Data whose median line scatter exceeds this many dB are refused
    /// (default 4 dB).
    pub max_noise_db: f64,
    /// Fewest usable lines (default 8, at least 5).
    pub min_lines: usize,
}

impl Default for ClassifyOptions {
    fn default() -> Self {
        ClassifyOptions {
            informative_std_dev: 0.2,
            smoothing_lines: 5,
            max_gap_decades: 0.15,
            averages: None,
            band_hz: None,
            detection_sigma: 3.0,
            min_confidence: 0.5,
            near_cancellation: 0.03,
            max_noise_db: 4.0,
            min_lines: 8,
        }
    }
}

impl ClassifyOptions {
    fn validate(&self) -> Result<(), ClassifyError> {
        let bad = |name, value, expected| {
            Err(ClassifyError::InvalidOption {
                name,
                value,
                expected,
            })
        };
        let t = self.informative_std_dev;
        if !(t.is_finite() && t > 0.0) {
            return bad("informative_std_dev", t, "> 0");
        }
        if self.smoothing_lines % 2 != 1 {
            return bad(
                "smoothing_lines",
                self.smoothing_lines as f64,
                "an odd number of lines",
            );
        }
        if !(self.max_gap_decades.is_finite() && self.max_gap_decades >= 0.0) {
            return bad("max_gap_decades", self.max_gap_decades, ">= 0");
        }
        if self.averages == Some(0) {
            return bad("averages", 0.0, ">= 1");
        }
        if let Some((lo, hi)) = self.band_hz {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return bad("band_hz", lo, "finite lo < hi");
            }
        }
        if !(self.detection_sigma.is_finite() && self.detection_sigma > 0.0) {
            return bad("detection_sigma", self.detection_sigma, "> 0");
        }
        let c = self.min_confidence;
        if !(c.is_finite() && c > 0.0 && c <= 1.0) {
            return bad("min_confidence", c, "in (0, 1]");
        }
        if !(self.near_cancellation.is_finite() && self.near_cancellation >= 0.0) {
            return bad("near_cancellation", self.near_cancellation, ">= 0");
        }
        if !(self.max_noise_db.is_finite() && self.max_noise_db > 0.0) {
            return bad("max_noise_db", self.max_noise_db, "> 0");
        }
        if self.min_lines < 5 {
            return bad("min_lines", self.min_lines as f64, ">= 5");
        }
        Ok(())
    }
}

/// Why an FRF could not be classified.
///
/// ```
/// use frf::{Complex64, Frf};
/// use ident::{classify, ClassifyError, ClassifyOptions};
/// let frf = Frf::new(vec![1.0, 2.0, 3.0], vec![Complex64::new(1.0, 0.0); 3], None)?;
/// let err = classify(&frf, mms::Output::Acceleration, &ClassifyOptions::default()).unwrap_err();
/// assert_eq!(err, ClassifyError::TooFewLines { got: 3, min: 8 });
/// # Ok::<(), frf::FrfError>(())
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ClassifyError {
    /// An option is out of range.
    #[error("option {name} = {value} is invalid: expected {expected}")]
    InvalidOption {
        /// The option's field name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it should be.
        expected: &'static str,
    },
    /// Too few lines remain (positive frequency, inside the requested band,
    /// not outliers, non-zero response).
    #[error("only {got} usable frequency lines; at least {min} are needed")]
    TooFewLines {
        /// Usable lines.
        got: usize,
        /// The required number ([`ClassifyOptions::min_lines`]).
        min: usize,
    },
    /// The lines are nowhere informative for long enough.
    #[error(
        "no informative band: the smoothed line uncertainty is at best {best:.3} nepers and \
         at most {threshold} for at most {longest_run} lines ({min_lines} needed); \
         the measurement is too poorly excited to classify (give --band to use every line)"
    )]
    NoInformativeBand {
        /// [`ClassifyOptions::informative_std_dev`].
        threshold: f64,
        /// Lowest smoothed relative standard deviation (nepers).
        best: f64,
        /// Well-excited lines of the best band.
        longest_run: usize,
        /// [`ClassifyOptions::min_lines`].
        min_lines: usize,
    },
    /// The line-to-line scatter is too large for any feature to be judged.
    #[error(
        "too noisy to classify: median line scatter {noise_db:.1} dB exceeds {limit_db:.1} dB"
    )]
    TooNoisy {
        /// Median noise standard deviation of `|G|` in dB.
        noise_db: f64,
        /// [`ClassifyOptions::max_noise_db`].
        limit_db: f64,
    },
}

/// One resonance or antiresonance found in the data.
///
/// ```
/// use ident::ClassifiedFeature;
/// use mms::analysis::Feature;
/// let f = ClassifiedFeature { kind: Feature::Resonance, freq_hz: 12.0, multiplicity: 1,
///     confidence: 0.97, damping_ratio: Some(0.01), prominence_db: 30.0,
///     phase_change_deg: -178.0, in_type: true };
/// assert!(f.in_type && f.confidence > 0.9);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClassifiedFeature {
    /// Resonance (peak, phase falls) or antiresonance (dip, phase rises).
    #[serde(serialize_with = "ser_feature")]
    pub kind: Feature,
    /// Undamped natural frequency estimate in Hz (local fit; the extremum
    /// when the fit fails).
    pub freq_hz: f64,
    /// Coincident roots: 2 for a double antiresonance (360 deg phase rise).
    pub multiplicity: u32,
    /// Confidence in `[0, 1]`; see the module documentation.
    pub confidence: f64,
    /// Damping ratio estimate (local fit or half-power width).
    pub damping_ratio: Option<f64>,
    /// Prominence of the extremum of `|G|` in dB (the height above, or
    /// depth below, the higher of the two lowest, or lower of the two
    /// highest, points on either side before the curve passes it); 0 for a
    /// feature found from its phase alone.
    pub prominence_db: f64,
    /// Measured phase change across the feature in degrees (between the
    /// reference lines; up to +-180 deg times the multiplicity).
    pub phase_change_deg: f64,
    /// Whether the feature is part of the type (confidence at least
    /// [`ClassifyOptions::min_confidence`]).
    pub in_type: bool,
}

/// A dip whose phase does not rise: zeros off the positive real `Omega`
/// axis (complex `Omega` zeros close to it).
///
/// ```
/// let d = ident::NmDip { freq_hz: 80.0, depth_db: 12.0, phase_change_deg: 3.0, confidence: 0.9 };
/// assert!(d.phase_change_deg.abs() < 90.0);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NmDip {
    /// Frequency of the dip in Hz.
    pub freq_hz: f64,
    /// Prominence of the dip in dB.
    pub depth_db: f64,
    /// Phase change across the dip in degrees (near 0 or negative).
    pub phase_change_deg: f64,
    /// Confidence in `[0, 1]`.
    pub confidence: f64,
}

/// Evidence for zeros off the positive real `Omega` axis (`(nm)`).
///
/// ```
/// let e = ident::NmEvidence { confidence: 0.85, level_excess_db: Some(14.0),
///     phase_excess_deg: Some(-4.0), dips: vec![] };
/// assert!(e.confidence > 0.5);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NmEvidence {
    /// Combined confidence in `[0, 1]` that the FRF is `(nm)`.
    pub confidence: f64,
    /// Level at the top of the band relative to the bottom, in dB, after
    /// the features found are divided out (`None` when the band has no
    /// feature-free lines at both ends). Zeros without antiresonance raise
    /// it; missed or out-of-band resonances lower it.
    pub level_excess_db: Option<f64>,
    /// Net phase change over the band not explained by the features, in
    /// degrees (about 0 for nm zeros, +180 per missed antiresonance, and
    /// negative for a delay or a missed resonance).
    pub phase_excess_deg: Option<f64>,
    /// Dips without a phase rise.
    pub dips: Vec<NmDip>,
}

/// The result of [`classify`].
///
/// ```
/// # use frf::{Complex64, Frf};
/// # use ident::{classify, ClassifyOptions};
/// # let freq: Vec<f64> = (0..300).map(|i| 10.0 * 10f64.powf(i as f64 / 150.0)).collect();
/// # let response = freq.iter().map(|&f| Complex64::new(1.0 + 0.01 * f, 0.0)).collect();
/// # let frf = Frf::new(freq, response, None)?;
/// let c = classify(&frf, mms::Output::Acceleration, &ClassifyOptions::default()).unwrap();
/// println!("{} in {:.1}..{:.1} Hz", c.frf_type, c.band_hz.0, c.band_hz.1);
/// for f in c.features.iter().filter(|f| f.in_type) {
///     println!("{:?} at {:.2} Hz ({:.0} %)", f.kind, f.freq_hz, 100.0 * f.confidence);
/// }
/// # Ok::<(), frf::FrfError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Classification {
    /// The output the FRF was read as.
    pub output: Output,
    /// The FRF type (serialised as its text, e.g. `"A^2RR"`, `"RR (nm)"`).
    #[serde(serialize_with = "ser_type")]
    pub frf_type: FrfType,
    /// Confidence of the type as a whole: the least certain of its
    /// decisions (each feature in or out, nm or not); on a coarse grid at
    /// most the grid's scale factor, and at most 0.5 when the bottom of
    /// the band is not flat (a feature just below it; see the notes).
    pub confidence: f64,
    /// The band in Hz (first and last line used).
    pub band_hz: (f64, f64),
    /// Where the uncertainty of the lines came from.
    #[serde(serialize_with = "ser_source")]
    pub uncertainty: UncertaintySource,
    /// Lines analysed.
    pub lines_used: usize,
    /// Lines of the FRF not analysed (outside the band, 0 Hz, outliers).
    pub lines_ignored: usize,
    /// Median noise standard deviation of `|G|` in dB.
    pub noise_db: f64,
    /// Features found, in increasing frequency, including those below the
    /// minimum confidence (`in_type == false`).
    pub features: Vec<ClassifiedFeature>,
    /// Evidence for `(nm)`, `None` when there is none at all.
    pub nonminimum_phase: Option<NmEvidence>,
    /// What a reader should know: band decisions, rejected features,
    /// cancellations, budgets.
    pub notes: Vec<ClassifyNote>,
}

fn ser_source<S: Serializer>(t: &UncertaintySource, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(source_name(*t))
}

/// The stable JSON name of an uncertainty source.
fn source_name(t: UncertaintySource) -> &'static str {
    match t {
        UncertaintySource::Given => "given",
        UncertaintySource::Coherence => "coherence",
        UncertaintySource::CoherenceAssumedAverages => "coherence_assumed_averages",
        UncertaintySource::Scatter => "scatter",
    }
}

impl Classification {
    /// Where the lines' uncertainty came from, as its stable JSON name:
    /// `given` (the FRF's standard deviation), `coherence`,
    /// `coherence_assumed_averages` or `scatter`.
    pub fn uncertainty_name(&self) -> &'static str {
        source_name(self.uncertainty)
    }
}

pub(crate) fn ser_type<S: Serializer>(t: &FrfType, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(t)
}

pub(crate) fn ser_feature<S: Serializer>(f: &Feature, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(feature_name(*f))
}

/// Classify a measured FRF: its type in the paper's vocabulary, every
/// feature with a confidence, the nm evidence and the band. See the
/// module documentation for the rules.
///
/// `output` says what `frf` measures (position, velocity or acceleration
/// per force); the classifier works on the inertance.
///
/// ```
/// use frf::{Complex64, Frf};
/// use ident::{classify, ClassifyOptions};
/// use mms::Output;
///
/// // Inertance with an antiresonance at 40 Hz and a resonance at 60 Hz,
/// // 1 % damping, as a receptance on a log grid from 10 to 200 Hz.
/// let factor = |s: Complex64, f: f64| {
///     let w = 2.0 * std::f64::consts::PI * f;
///     1.0 + 0.02 * s / w + (s / w) * (s / w)
/// };
/// let freq: Vec<f64> = (0..400).map(|i| 10.0 * 20f64.powf(i as f64 / 399.0)).collect();
/// let response = freq
///     .iter()
///     .map(|&f| {
///         let s = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
///         factor(s, 40.0) / factor(s, 60.0) / (s * s)
///     })
///     .collect();
/// let frf = Frf::new(freq, response, None)?;
/// let c = classify(&frf, Output::Position, &ClassifyOptions::default()).unwrap();
/// assert_eq!(c.frf_type.to_string(), "AR");
/// assert!((c.features[0].freq_hz - 40.0).abs() < 0.4);
/// assert!(c.features.iter().all(|f| f.confidence > 0.9));
/// # Ok::<(), frf::FrfError>(())
/// ```
pub fn classify(
    frf: &Frf,
    output: Output,
    options: &ClassifyOptions,
) -> Result<Classification, ClassifyError> {
    options.validate()?;
    let mut notes = Vec::new();
    let uncertainty = line_uncertainty(frf, options.averages.map(f64::from));
    if uncertainty.source == UncertaintySource::CoherenceAssumedAverages {
        notes.push(ClassifyNote::AssumedAverages {
            averages: frf::uncertainty::ASSUMED_AVERAGES,
        });
    }
    let band = select_band(
        frf,
        &uncertainty.relative,
        uncertainty.source,
        options,
        &mut notes,
    )?;
    let mut data = Data::inertance(frf, output, &band, &uncertainty.relative, &mut notes);
    remove_outliers(&mut data, &mut notes);
    if data.len() < options.min_lines {
        return Err(ClassifyError::TooFewLines {
            got: data.len(),
            min: options.min_lines,
        });
    }
    data.unwrap_phase();
    data.estimate_noise();
    let noise = median(&data.sigma);
    if noise * DB_PER_NEPER > options.max_noise_db {
        return Err(ClassifyError::TooNoisy {
            noise_db: noise * DB_PER_NEPER,
            limit_db: options.max_noise_db,
        });
    }

    let cands = candidates(&data, options.detection_sigma);
    let mut found = find_features(&data, &cands, &mut notes);
    drop_where_phase_undetermined(&data, &mut found, &mut notes);
    mark_near_cancellations(&mut found, options.near_cancellation, &mut notes);
    let resid = without_features(&data, &found);
    let nm_dips = nm_dips(&resid, &found, options.detection_sigma);
    let dips: Vec<&Eval> = nm_dips.iter().collect();

    let budget = budget(&resid, &found, &dips);
    let mut nm = nm_evidence(budget.as_ref(), &dips, &mut notes);

    // A grid coarser than COARSE_SPACING can hide a pole-zero pair between
    // two lines, which also spoils the budget: every confidence is scaled.
    let spacing_ln = median(&data.x.windows(2).map(|w| w[1] - w[0]).collect::<Vec<_>>());
    let resolution = (COARSE_SPACING / spacing_ln).clamp(0.3, 1.0);
    if resolution < 1.0 {
        notes.push(ClassifyNote::CoarseGrid {
            relative_spacing: spacing_ln.exp() - 1.0,
            confidence_scale: resolution,
        });
        for e in &mut found {
            e.confidence *= resolution;
        }
        if let Some(e) = &mut nm {
            e.confidence *= resolution;
        }
    }
    let nm_flag = nm
        .as_ref()
        .is_some_and(|e| e.confidence >= options.min_confidence);

    for e in found.iter().filter(|e| e.edge) {
        notes.push(ClassifyNote::AtBandEdge {
            feature: feature_of(e),
            freq_hz: e.x0.exp() / (2.0 * PI),
        });
    }
    let mut features: Vec<ClassifiedFeature> = found
        .iter()
        .map(|e| ClassifiedFeature {
            kind: if e.dip {
                Feature::Antiresonance
            } else {
                Feature::Resonance
            },
            freq_hz: e.x0.exp() / (2.0 * PI),
            multiplicity: e.m,
            confidence: e.confidence,
            damping_ratio: e.zeta,
            prominence_db: e.prom * DB_PER_NEPER,
            phase_change_deg: e.dphi.to_degrees(),
            in_type: e.confidence >= options.min_confidence,
        })
        .collect();
    features.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    for f in features.iter().filter(|f| !f.in_type) {
        notes.push(ClassifyNote::LeftOut {
            feature: f.kind,
            freq_hz: f.freq_hz,
            confidence: f.confidence,
            min_confidence: options.min_confidence,
        });
    }
    let tokens = features
        .iter()
        .filter(|f| f.in_type)
        .map(|f| Token {
            feature: f.kind,
            multiplicity: f.multiplicity,
        })
        .collect();
    let frf_type = FrfType {
        tokens,
        nonminimum_phase: nm_flag,
    };
    let confidence = features
        .iter()
        .map(|f| f.confidence.max(1.0 - f.confidence))
        .chain(nm.iter().map(|e| e.confidence.max(1.0 - e.confidence)))
        // on a coarse grid, the absence of features is no more certain
        .fold(resolution, f64::min);
    let mut confidence = confidence;
    if let Some(slope) = budget.as_ref().and_then(|b| b.low_slope) {
        if slope.abs() > 1.0 {
            notes.push(ClassifyNote::UnflatBottom {
                slope,
                output,
                confidence_cap: UNFLAT_BOTTOM_CAP,
            });
            confidence = confidence.min(UNFLAT_BOTTOM_CAP);
        }
    }
    Ok(Classification {
        output,
        frf_type,
        confidence,
        band_hz: (data.f[0], data.f[data.len() - 1]),
        uncertainty: uncertainty.source,
        lines_used: data.len(),
        lines_ignored: frf.len() - data.len(),
        noise_db: noise * DB_PER_NEPER,
        features,
        nonminimum_phase: nm,
        notes,
    })
}

/// The name of a feature kind in reports and JSON.
///
/// ```
/// use mms::analysis::Feature;
/// assert_eq!(ident::classify::feature_name(Feature::Antiresonance), "antiresonance");
/// ```
pub fn feature_name(f: Feature) -> &'static str {
    match f {
        Feature::Antiresonance => "antiresonance",
        Feature::Resonance => "resonance",
    }
}

fn logistic(t: f64) -> f64 {
    1.0 / (1.0 + (-t).exp())
}

/// `a` wrapped to `(-pi, pi]`.
fn wrap(a: f64) -> f64 {
    let b = a.rem_euclid(2.0 * PI);
    if b > PI {
        b - 2.0 * PI
    } else {
        b
    }
}

fn mean(v: impl IntoIterator<Item = f64>) -> f64 {
    let (s, n) = v
        .into_iter()
        .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        0.0
    } else {
        s / n as f64
    }
}

/// Median of a non-empty slice (upper median for even lengths).
fn median(v: &[f64]) -> f64 {
    quantile(v, 0.5)
}

fn quantile(v: &[f64], q: f64) -> f64 {
    let mut w = v.to_vec();
    let k = ((w.len() as f64 - 1.0) * q).round() as usize;
    let (_, x, _) = w.select_nth_unstable_by(k, f64::total_cmp);
    *x
}

fn running_median(v: &[f64], half: usize) -> Vec<f64> {
    (0..v.len())
        .map(|i| median(&v[i.saturating_sub(half)..(i + half + 1).min(v.len())]))
        .collect()
}

/// Drops the features that lie where the phase is not determined (see
/// [`PHASE_UNDETERMINED`]) and notes how many.
fn drop_where_phase_undetermined(d: &Data, found: &mut Vec<Eval>, notes: &mut Vec<ClassifyNote>) {
    let smooth = running_median(&d.given, PHASE_WINDOW_HALF);
    let before = found.len();
    let mut dropped_hz = Vec::new();
    found.retain(|e| {
        let i = d.x.partition_point(|&x| x < e.x0).min(d.len() - 1);
        let keep = smooth[i] <= PHASE_UNDETERMINED;
        if !keep {
            dropped_hz.push(e.x0.exp() / (2.0 * PI));
        }
        keep
    });
    if found.len() < before {
        notes.push(ClassifyNote::PhaseUndetermined {
            at_hz: dropped_hz,
            max_std_dev_rad: PHASE_UNDETERMINED,
        });
    }
}

/// Step 1: the indices of the lines in the band; `sigma` is the relative
/// uncertainty of every line of `frf`.
fn select_band(
    frf: &Frf,
    sigma: &[f64],
    source: UncertaintySource,
    o: &ClassifyOptions,
    notes: &mut Vec<ClassifyNote>,
) -> Result<Vec<usize>, ClassifyError> {
    let f = frf.freq_hz();
    let (lo, hi) = o.band_hz.unwrap_or((0.0, f64::INFINITY));
    let in_range = |i: usize| f[i] > 0.0 && f[i] >= lo && f[i] <= hi;
    let eligible: Vec<usize> = (0..frf.len())
        .filter(|&i| in_range(i) && sigma[i].is_finite())
        .collect();
    if f[0] == 0.0 {
        notes.push(ClassifyNote::ZeroHzLeftOut);
    }
    let unexcited = (0..frf.len())
        .filter(|&i| in_range(i) && !sigma[i].is_finite())
        .count();
    if unexcited > 0 {
        notes.push(ClassifyNote::Unexcited { lines: unexcited });
    }
    if eligible.len() < o.min_lines {
        return Err(ClassifyError::TooFewLines {
            got: eligible.len(),
            min: o.min_lines,
        });
    }
    if o.band_hz.is_some() || source == UncertaintySource::Scatter {
        let (low_hz, high_hz) = (f[eligible[0]], f[eligible[eligible.len() - 1]]);
        let lines = eligible.len();
        notes.push(if o.band_hz.is_some() {
            ClassifyNote::BandAsGiven {
                low_hz,
                high_hz,
                lines,
            }
        } else {
            ClassifyNote::BandWholeRange {
                low_hz,
                high_hz,
                lines,
            }
        });
        return Ok(eligible);
    }
    let c: Vec<f64> = eligible.iter().map(|&i| sigma[i]).collect();
    let cs = running_median(&c, o.smoothing_lines / 2);
    let good: Vec<bool> = cs.iter().map(|&g| g <= o.informative_std_dev).collect();
    let max_gap = o.max_gap_decades * LN_10;
    // The share of ln f each line covers: half-way to its neighbours.
    let n = eligible.len();
    let lnf = |p: usize| f[eligible[p]].ln();
    let cover: Vec<f64> = (0..n)
        .map(|p| 0.5 * (lnf((p + 1).min(n - 1)) - lnf(p.saturating_sub(1))))
        .collect();
    // (first, last, informative count, informative ln-width) as positions
    // in `eligible`
    let mut runs: Vec<(usize, usize, usize, f64)> = Vec::new();
    let mut cur: Option<(usize, usize, usize, f64)> = None;
    for p in (0..n).filter(|&p| good[p]) {
        cur = match cur {
            Some((s, e, k, w)) if p == e + 1 || lnf(p) - lnf(e) <= max_gap => {
                Some((s, p, k + 1, w + cover[p]))
            }
            Some(r) => {
                runs.push(r);
                Some((p, p, 1, cover[p]))
            }
            None => Some((p, p, 1, cover[p])),
        };
    }
    runs.extend(cur);
    let best_sigma = cs.iter().copied().fold(f64::INFINITY, f64::min);
    let best = runs
        .iter()
        .filter(|r| r.2 >= o.min_lines)
        .max_by(|a, b| a.3.total_cmp(&b.3).then(b.0.cmp(&a.0)));
    let Some(&(s, e, k, _)) = best else {
        let longest = runs.iter().map(|r| r.2).max().unwrap_or(0);
        return Err(ClassifyError::NoInformativeBand {
            threshold: o.informative_std_dev,
            best: best_sigma,
            longest_run: longest,
            min_lines: o.min_lines,
        });
    };
    let total_good = good.iter().filter(|&&g| g).count();
    notes.push(ClassifyNote::BandInformative {
        low_hz: f[eligible[s]],
        high_hz: f[eligible[e]],
        informative_lines: k,
        excited_lines: eligible.len(),
        max_std_dev_nepers: o.informative_std_dev,
        max_std_dev_db: o.informative_std_dev * DB_PER_NEPER,
    });
    if e + 1 - s > k {
        notes.push(ClassifyNote::LowWeightKept {
            lines: e + 1 - s - k,
            max_gap_decades: o.max_gap_decades,
        });
    }
    if total_good > k {
        notes.push(ClassifyNote::InformativeOutside {
            lines: total_good - k,
        });
    }
    Ok(eligible[s..=e].to_vec())
}

/// The working data: inertance lines of the band.
#[derive(Clone)]
struct Data {
    /// Index of each line in the original FRF.
    orig: Vec<usize>,
    f: Vec<f64>,
    /// `ln w`.
    x: Vec<f64>,
    /// `ln |G|`.
    y: Vec<f64>,
    /// `arg G`, wrapped until [`Data::unwrap_phase`].
    phi: Vec<f64>,
    /// Noise standard deviation of `y` (and of `phi` in radians).
    sigma: Vec<f64>,
    /// The line's own relative uncertainty (step 1).
    given: Vec<f64>,
}

impl Data {
    /// Step 2: `G = H (j w)^(2-k)`.
    fn inertance(
        frf: &Frf,
        output: Output,
        band: &[usize],
        uncertainty: &[f64],
        notes: &mut Vec<ClassifyNote>,
    ) -> Data {
        let mut d = Data {
            orig: Vec::new(),
            f: Vec::new(),
            x: Vec::new(),
            y: Vec::new(),
            phi: Vec::new(),
            sigma: Vec::new(),
            given: Vec::new(),
        };
        let mut zero = 0;
        for &i in band {
            let f = frf.freq_hz()[i];
            let w = 2.0 * PI * f;
            let jw = Complex64::new(0.0, w);
            let h = frf.response()[i];
            let g = match output {
                Output::Position => h * jw * jw,
                Output::Velocity => h * jw,
                Output::Acceleration => h,
            };
            let a = g.norm();
            if !(a > 0.0 && a.is_finite()) {
                zero += 1;
                continue;
            }
            d.orig.push(i);
            d.given.push(uncertainty[i]);
            d.f.push(f);
            d.x.push(w.ln());
            d.y.push(a.ln());
            d.phi.push(g.arg());
        }
        if zero > 0 {
            notes.push(ClassifyNote::ZeroResponse { lines: zero });
        }
        d
    }

    fn len(&self) -> usize {
        self.x.len()
    }

    fn retain(&mut self, keep: &[bool]) {
        let pick = |v: &mut Vec<f64>| {
            let mut it = keep.iter();
            v.retain(|_| *it.next().unwrap_or(&true));
        };
        pick(&mut self.f);
        pick(&mut self.x);
        pick(&mut self.y);
        pick(&mut self.phi);
        pick(&mut self.given);
        let mut it = keep.iter();
        self.orig.retain(|_| *it.next().unwrap_or(&true));
    }

    /// Unwraps the phase line by line. A step of nearly half a turn
    /// between two lines (a lightly damped feature no wider than one line)
    /// is ambiguous in sign; the magnitude decides it: across a dip the
    /// phase rises (an antiresonance, the minimum-phase reading), across a
    /// peak it falls (a resonance). The dip or peak is the two lines
    /// against their neighbours; where those tell neither, as in a noisy
    /// notch several lines wide (a motor-side antiresonance, where the
    /// sensor barely moves and the coherence falls), both lines against
    /// the extremes of the [`AMBIGUOUS_FLANK`] lines on either side.
    fn unwrap_phase(&mut self) {
        let n = self.len();
        let wrapped = self.phi.clone();
        for i in 1..n {
            let mut d = wrap(wrapped[i] - wrapped[i - 1]);
            if d.abs() > AMBIGUOUS_STEP && i >= 2 && i + 1 < n {
                let y = &self.y;
                let (lo, hi) = (y[i - 1].min(y[i]), y[i - 1].max(y[i]));
                let (a, b) = (y[i - 2], y[i + 1]);
                let left = &y[(i - 1).saturating_sub(AMBIGUOUS_FLANK)..i - 1];
                let right = &y[i + 1..(i + 1 + AMBIGUOUS_FLANK).min(n)];
                let top = |v: &[f64]| v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                let bottom = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
                let (dip, peak) = (lo < a && lo < b, hi > a && hi > b);
                let wide_dip = hi < top(left) && hi < top(right);
                let wide_peak = lo > bottom(left) && lo > bottom(right);
                if dip && d < 0.0 {
                    d += 2.0 * PI;
                } else if peak && d > 0.0 {
                    d -= 2.0 * PI;
                } else if !dip && !peak && wide_dip && !wide_peak && d < 0.0 {
                    d += 2.0 * PI;
                } else if !dip && !peak && wide_peak && !wide_dip && d > 0.0 {
                    d -= 2.0 * PI;
                }
            }
            self.phi[i] = self.phi[i - 1] + d;
        }
    }

    /// Second-difference residuals `(ln|G|, phase)` of every interior line
    /// ([`second_differences`]).
    fn residuals(&self) -> Vec<(f64, f64)> {
        second_differences(&self.x, &self.y, &self.phi)
    }

    /// Step 3: the noise standard deviation of every line.
    fn estimate_noise(&mut self) {
        let local = scatter(&self.x, &self.y, &self.phi);
        self.sigma = local
            .iter()
            .zip(&self.given)
            .map(|(&sc, &g)| {
                let sc = if sc.is_finite() { sc } else { SIGMA_FLOOR };
                sc.max(g.min(SIGMA_CEILING)).max(SIGMA_FLOOR)
            })
            .collect();
    }
}

/// Leaves out isolated outliers: a line far (10 sigma and 0.9 dB) from the
/// value on which the linear extrapolations from its two left and its two
/// right neighbours agree. A resonance or antiresonance between two lines
/// is never one: there the two extrapolations disagree in phase.
fn remove_outliers(d: &mut Data, notes: &mut Vec<ClassifyNote>) {
    let n = d.len();
    if n < 7 {
        return;
    }
    let r = d.residuals();
    let all: Vec<f64> = r.iter().flat_map(|&(a, b)| [a.abs(), b.abs()]).collect();
    let sg = (quantile(&all, 0.25) / Q25_ABS_NORMAL).max(SIGMA_FLOOR);
    let (x, y, p) = (&d.x, &d.y, &d.phi);
    let mut keep = vec![true; n];
    for i in 2..n - 2 {
        let extrapolate = |a: usize, b: usize| {
            let t = (x[i] - x[b]) / (x[b] - x[a]);
            (y[b] + (y[b] - y[a]) * t, p[b] + wrap(p[b] - p[a]) * t)
        };
        let (yl, pl) = extrapolate(i - 2, i - 1);
        let (yr, pr) = extrapolate(i + 2, i + 1);
        if (yl - yr).abs() > 5.0 * sg || wrap(pl - pr).abs() > 5.0 * sg {
            continue;
        }
        let (ym, pm) = (0.5 * (yl + yr), pl + 0.5 * wrap(pr - pl));
        let dev = (y[i] - ym).abs().max(wrap(p[i] - pm).abs());
        if dev > (10.0 * sg).max(0.1) {
            keep[i] = false;
        }
    }
    let out = keep.iter().filter(|&&k| !k).count();
    if out == 0 {
        return;
    }
    if out * 10 > n {
        notes.push(ClassifyNote::OutliersKept { lines: out });
        return;
    }
    let at_hz = (0..n).filter(|&i| !keep[i]).map(|i| d.f[i]).collect();
    notes.push(ClassifyNote::OutliersLeftOut { at_hz });
    d.retain(&keep);
}

/// A local extremum of `ln|G|`.
#[derive(Clone, Debug)]
struct Candidate {
    idx: usize,
    dip: bool,
    /// Prominence in nepers.
    prom: f64,
    /// Prominence in noise standard deviations of a difference of lines.
    z: f64,
    strong: bool,
    /// A phase step without an extremum of the magnitude.
    phase_only: bool,
}

/// Local maxima of `y` over `x` with their prominence: the height above
/// the higher of the two lowest points reached on either side before a
/// higher point, the end, or a distance `reach` in `x`. Plateaus count
/// once, at their middle. (The reach keeps noise maxima on a long slope
/// from walking the whole band.)
fn peaks(x: &[f64], y: &[f64], reach: f64) -> Vec<(usize, f64)> {
    // Each peak's prominence is the lower of two range minima, bounded by
    // the nearest higher line and by the reach on each side: with those
    // bounds from one pass of a monotonic stack and a binary search, and
    // the minima from a sparse table, the work is n log n (a scan from
    // every peak would be quadratic on noisy data with many small peaks).
    let n = y.len();
    let prev_higher = nearest_higher(y, false);
    let next_higher = nearest_higher(y, true);
    let minima = RangeMin::new(y);
    let mut out = Vec::new();
    let mut i = 1;
    while i + 1 < n {
        if y[i] <= y[i - 1] {
            i += 1;
            continue;
        }
        let mut j = i;
        while j + 1 < n && y[j + 1] == y[i] {
            j += 1;
        }
        if j + 1 < n && y[j + 1] < y[i] {
            let h = y[i];
            // Left: the lines after both the nearest higher one and the
            // last one beyond the reach.
            let beyond = x[..i].partition_point(|&xk| x[i] - xk > reach);
            let from = prev_higher[i].map_or(0, |g| g + 1).max(beyond);
            let left = h.min(minima.min(from, i));
            // Right: up to the nearest higher line and the first beyond
            // the reach (the plateau's last line is as high as its first).
            let within = j + 1 + x[j + 1..].partition_point(|&xk| xk - x[j] <= reach);
            let to = next_higher[j].unwrap_or(n).min(within);
            let right = h.min(minima.min(j + 1, to));
            out.push(((i + j) / 2, h - left.max(right)));
        }
        i = j + 1;
    }
    out
}

/// For every line, the nearest line before it (`after`: after it) that is
/// strictly higher, by a monotonic stack in one pass.
fn nearest_higher(y: &[f64], after: bool) -> Vec<Option<usize>> {
    let n = y.len();
    let mut out = vec![None; n];
    let mut stack: Vec<usize> = Vec::new();
    let order: Box<dyn Iterator<Item = usize>> = if after {
        Box::new((0..n).rev())
    } else {
        Box::new(0..n)
    };
    for k in order {
        while stack.last().is_some_and(|&t| y[t] <= y[k]) {
            stack.pop();
        }
        out[k] = stack.last().copied();
        stack.push(k);
    }
    out
}

/// Minima of `y` over ranges in constant time after `n log n`
/// preparation (a sparse table: the minimum of each run of `2^l` lines).
struct RangeMin {
    levels: Vec<Vec<f64>>,
}

impl RangeMin {
    fn new(y: &[f64]) -> RangeMin {
        let mut levels = vec![y.to_vec()];
        let mut width = 1;
        while 2 * width <= y.len() {
            let prev = levels.last().expect("level 0");
            let next: Vec<f64> = (0..=y.len() - 2 * width)
                .map(|k| prev[k].min(prev[k + width]))
                .collect();
            levels.push(next);
            width *= 2;
        }
        RangeMin { levels }
    }

    /// The minimum over `y[a..b]`; infinite for an empty range.
    fn min(&self, a: usize, b: usize) -> f64 {
        if a >= b {
            return f64::INFINITY;
        }
        let l = (usize::BITS - 1 - (b - a).leading_zeros()) as usize;
        let w = 1 << l;
        self.levels[l][a].min(self.levels[l][b - w])
    }
}

/// Step 4: candidate peaks and dips, sorted by frequency.
fn candidates(d: &Data, detection_sigma: f64) -> Vec<Candidate> {
    let neg: Vec<f64> = d.y.iter().map(|v| -v).collect();
    let mut out: Vec<Candidate> = peaks(&d.x, &d.y, PROMINENCE_REACH)
        .into_iter()
        .map(|p| (p, false))
        .chain(
            peaks(&d.x, &neg, PROMINENCE_REACH)
                .into_iter()
                .map(|p| (p, true)),
        )
        .filter_map(|((idx, prom), dip)| {
            let z = prom / (d.sigma[idx] * std::f64::consts::SQRT_2);
            (z >= detection_sigma).then_some(Candidate {
                idx,
                dip,
                prom,
                z,
                strong: z >= STRONG_SIGMA,
                phase_only: false,
            })
        })
        .collect();
    out.sort_by_key(|c| c.idx);
    out
}

/// A candidate after the local fit and the phase check.
#[derive(Clone, Debug)]
struct Eval {
    /// Position of the candidate in the list of all candidates.
    id: usize,
    dip: bool,
    prom: f64,
    /// Line spacing in `ln w` at the candidate.
    dx: f64,
    /// `ln w0`.
    x0: f64,
    zeta: Option<f64>,
    m: u32,
    /// Measured phase change (radians).
    dphi: f64,
    /// Confidence as the feature of its magnitude kind.
    confidence: f64,
    /// Confidence as a dip of zeros off the positive `Omega` axis.
    nm_confidence: f64,
    edge: bool,
}

/// The kind of feature `e` is.
fn feature_of(e: &Eval) -> Feature {
    if e.dip {
        Feature::Antiresonance
    } else {
        Feature::Resonance
    }
}

/// Half the mean spacing in `ln w` around line `i`.
fn spacing(d: &Data, i: usize) -> f64 {
    let n = d.len();
    let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
    (d.x[b] - d.x[a]) / (b - a).max(1) as f64
}

/// Lines with `lo <= x <= hi`.
fn lines_in(d: &Data, lo: f64, hi: f64) -> std::ops::Range<usize> {
    let a = d.x.partition_point(|&x| x < lo);
    let b = d.x.partition_point(|&x| x <= hi);
    a..b.max(a)
}

/// Phase of a zero factor `1 - r^2 + 2 j zeta r`, `r = exp(x - x0)`, in
/// `[0, pi]` for `zeta >= 0`.
fn zero_phase(x: f64, x0: f64, zeta: f64) -> f64 {
    let r = (x - x0).exp();
    Complex64::new(1.0 - r * r, 2.0 * zeta * r).arg()
}

/// `ln |1 - r^2 + 2 j zeta r|`.
fn zero_level(x: f64, x0: f64, zeta: f64) -> f64 {
    let r = (x - x0).exp();
    Complex64::new(1.0 - r * r, 2.0 * zeta * r).norm().ln()
}

/// Least-squares fit of `H (1 - a v^2 + j b v) = p0 + p1 u` on `lines`,
/// with `v = exp(x - xc)`, `u = x - xc` and `H = exp(sign (ln G) / m)`
/// (`sign = +1` for a pole, `-1` for a zero), reweighted twice by the
/// fitted background so that every line counts with its relative error.
/// Returns `(ln w0, zeta)`; `zeta < 0` means the pair is in the right half
/// plane. `None` when singular or `a <= 0`.
fn local_fit(
    d: &Data,
    lines: std::ops::Range<usize>,
    xc: f64,
    sign: f64,
    m: f64,
) -> Option<(f64, f64)> {
    if lines.len() < 4 {
        return None;
    }
    // A dense grid is thinned to at most FIT_MAX_LINES evenly picked lines:
    // more do not sharpen a six-parameter fit, they only cost time.
    let stride = lines.len().div_ceil(FIT_MAX_LINES);
    let lines: Vec<usize> = lines.step_by(stride).collect();
    let ym = mean(lines.iter().map(|&i| d.y[i]));
    let pm = mean(lines.iter().map(|&i| d.phi[i]));
    let h: Vec<Complex64> = lines
        .iter()
        .map(|&i| (Complex64::new(d.y[i] - ym, d.phi[i] - pm) * (sign / m)).exp())
        .collect();
    let mut w = vec![1.0; h.len()];
    let mut sol = [0.0; 6];
    for _ in 0..3 {
        let mut a = [[0.0; 6]; 6];
        let mut rhs = [0.0; 6];
        for (k, &i) in lines.iter().enumerate() {
            let u = d.x[i] - xc;
            let v = u.exp();
            let (hr, hi) = (h[k].re, h[k].im);
            let rows = [
                ([hr * v * v, hi * v, 1.0, 0.0, u, 0.0], hr),
                ([hi * v * v, -hr * v, 0.0, 1.0, 0.0, u], hi),
            ];
            for (row, b) in rows {
                for p in 0..6 {
                    rhs[p] += w[k] * row[p] * b;
                    for q in 0..6 {
                        a[p][q] += w[k] * row[p] * row[q];
                    }
                }
            }
        }
        sol = solve6(a, rhs)?;
        for (k, &i) in lines.iter().enumerate() {
            let u = d.x[i] - xc;
            let bg = Complex64::new(sol[2] + sol[4] * u, sol[3] + sol[5] * u).norm_sqr();
            w[k] = if bg > 0.0 { 1.0 / bg } else { 1.0 };
        }
    }
    let (a, b) = (sol[0], sol[1]);
    if !(a > 0.0 && a.is_finite() && b.is_finite()) {
        return None;
    }
    Some((xc - 0.5 * a.ln(), b / (2.0 * a.sqrt())))
}

/// Gaussian elimination with partial pivoting on a 6x6 system.
fn solve6(mut a: [[f64; 6]; 6], mut b: [f64; 6]) -> Option<[f64; 6]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    for c in 0..6 {
        let p = (c..6).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() <= 1e-13 * scale {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..6 {
            let f = a[r][c] / a[c][c];
            let pivot = a[c];
            for (x, p) in a[r][c..].iter_mut().zip(&pivot[c..]) {
                *x -= f * p;
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 6];
    for c in (0..6).rev() {
        let s: f64 = (c + 1..6).map(|k| a[c][k] * x[k]).sum();
        x[c] = (b[c] - s) / a[c][c];
    }
    Some(x)
}

/// Vertex of the parabola through the extremum and its neighbours (the
/// extremum itself at the ends).
fn parabolic_vertex(d: &Data, i: usize) -> f64 {
    if i == 0 || i + 1 >= d.len() {
        return d.x[i];
    }
    let (x0, x1, x2) = (d.x[i - 1], d.x[i], d.x[i + 1]);
    let (y0, y1, y2) = (d.y[i - 1], d.y[i], d.y[i + 1]);
    let num = (x1 - x0).powi(2) * (y1 - y2) - (x1 - x2).powi(2) * (y1 - y0);
    let den = (x1 - x0) * (y1 - y2) - (x1 - x2) * (y1 - y0);
    if den == 0.0 {
        return x1;
    }
    (x1 - 0.5 * num / den).clamp(x0, x2)
}

/// Damping ratio from the half-power width of a peak (or the double-power
/// width of a dip), searched within `[lo, hi]`.
fn half_power_zeta(d: &Data, i: usize, dip: bool, lo: f64, hi: f64) -> Option<f64> {
    let s = if dip { -1.0 } else { 1.0 };
    let level = s * d.y[i] - 0.5 * std::f64::consts::LN_2;
    let cross = |j: usize, k: usize| {
        let (a, b) = (s * d.y[j] - level, s * d.y[k] - level);
        d.x[j] + (d.x[k] - d.x[j]) * a / (a - b)
    };
    let mut l = None;
    let mut j = i;
    while j > 0 && d.x[j - 1] >= lo {
        if s * d.y[j - 1] < level {
            l = Some(cross(j, j - 1));
            break;
        }
        j -= 1;
    }
    let mut r = None;
    let mut j = i;
    while j + 1 < d.len() && d.x[j + 1] <= hi {
        if s * d.y[j + 1] < level {
            r = Some(cross(j, j + 1));
            break;
        }
        j += 1;
    }
    let z = 0.5 * (r? - l?);
    (z > 0.0).then_some(z)
}

/// Centre and damping ratio of a phase step around line `i`: where the
/// phase crosses half-way between its means over the outer halves of
/// `+-PHASE_STEP_HALF` (within `[lo, hi]`), and `zeta = (step / pi) /
/// slope` from the slope there (a zero factor's phase rises with slope
/// `1/zeta` per unit `ln w` at its centre).
fn phase_step_centre(d: &Data, i: usize, lo: f64, hi: f64) -> Option<(f64, f64)> {
    let h = PHASE_STEP_HALF;
    let xc = d.x[i];
    let a = lo.max(xc - h);
    let b = hi.min(xc + h);
    let left: Vec<usize> = lines_in(d, a, 0.5 * (a + xc)).collect();
    let right: Vec<usize> = lines_in(d, 0.5 * (xc + b), b).collect();
    if left.is_empty() || right.is_empty() {
        return None;
    }
    let pl = mean(left.iter().map(|&k| d.phi[k]));
    let pr = mean(right.iter().map(|&k| d.phi[k]));
    let half = 0.5 * (pl + pr);
    let s = (pr - pl).signum();
    let span: Vec<usize> = (left[0]..=right[right.len() - 1]).collect();
    // the crossing nearest to the candidate line
    let k = span
        .windows(2)
        .filter(|w| s * (d.phi[w[0]] - half) <= 0.0 && s * (d.phi[w[1]] - half) > 0.0)
        .min_by(|u, v| {
            let du = (d.x[u[0]] - xc).abs();
            let dv = (d.x[v[0]] - xc).abs();
            du.total_cmp(&dv)
        })?[0];
    let t = (half - d.phi[k]) / (d.phi[k + 1] - d.phi[k]);
    let x0 = d.x[k] + t * (d.x[k + 1] - d.x[k]);
    let (p, q) = (
        k.saturating_sub(1).max(span[0]),
        (k + 2).min(span[span.len() - 1]),
    );
    let slope = (d.phi[q] - d.phi[p]) / (d.x[q] - d.x[p]);
    let zeta = ((pr - pl).abs() / PI).max(1.0).round() / slope.abs();
    (zeta.is_finite() && zeta > 0.0).then_some((x0, zeta.min(0.5)))
}

/// The neighbourhood of a candidate at `xc`: half-way to the nearest
/// anchor (another feature) on either side, or the band edge, but no
/// farther than `NEIGHBOURHOOD`.
fn bounds(d: &Data, xc: f64, anchors: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let left = anchors
        .clone()
        .filter(|&a| a < xc)
        .fold(f64::NEG_INFINITY, f64::max);
    let right = anchors.filter(|&a| a > xc).fold(f64::INFINITY, f64::min);
    between(d, xc, left, right)
}

/// [`bounds`] from the nearest anchors `left` and `right` of `xc`
/// (infinite where there is none).
fn between(d: &Data, xc: f64, left: f64, right: f64) -> (f64, f64) {
    let xl = if left.is_finite() {
        0.5 * (left + xc)
    } else {
        d.x[0]
    };
    let xr = if right.is_finite() {
        0.5 * (right + xc)
    } else {
        d.x[d.len() - 1]
    };
    (xl.max(xc - NEIGHBOURHOOD), xr.min(xc + NEIGHBOURHOOD))
}

/// The strong candidates' places, sorted, as anchors of every candidate's
/// neighbourhood: found by binary search, so that bounding all candidates
/// is n log n where a scan per candidate would be quadratic.
struct Anchors {
    x: Vec<f64>,
}

impl Anchors {
    fn new(d: &Data, candidates: &[Candidate]) -> Anchors {
        let mut x: Vec<f64> = candidates
            .iter()
            .filter(|o| o.strong)
            .map(|o| d.x[o.idx])
            .collect();
        x.sort_by(f64::total_cmp);
        Anchors { x }
    }

    /// The neighbourhood of candidate `c` between the strong candidates
    /// other than itself ([`bounds`]).
    fn bounds(&self, d: &Data, c: &Candidate) -> (f64, f64) {
        let xc = d.x[c.idx];
        let p = self.x.partition_point(|&a| a < xc);
        let q = self.x.partition_point(|&a| a <= xc);
        let left = p.checked_sub(1).map_or(f64::NEG_INFINITY, |i| self.x[i]);
        let right = self.x.get(q).copied().unwrap_or(f64::INFINITY);
        between(d, xc, left, right)
    }
}

/// Steps 5 and 6 for one candidate within its neighbourhood `(xl, xr)`.
fn evaluate(d: &Data, c: &Candidate, (xl, xr): (f64, f64)) -> Eval {
    let n = d.len();
    let xc = d.x[c.idx];
    let dx = spacing(d, c.idx);
    // +-10 zeta around a peak or dip whose half-power width is known is
    // plenty for the fit; the full width otherwise (heavy damping)
    let half = half_power_zeta(d, c.idx, c.dip, xl, xr).map_or(FIT_HALF_WIDTH, |z| {
        (10.0 * z).min(FIT_HALF_WIDTH).max(4.0 * dx)
    });
    let mut window = lines_in(d, xl.max(xc - half), xr.min(xc + half));
    if window.len() < 4 {
        window = c.idx.saturating_sub(2)..(c.idx + 3).min(n);
    }
    let sign = if c.dip { -1.0 } else { 1.0 };
    let fit_ok = |x0: f64, z: f64| {
        (x0 - xc).abs() <= (3.0 * dx).max(2.0 * z) && x0 > xl && x0 < xr && z > 0.0 && z < 0.5
    };
    let (mut x0, mut zeta) = if c.phase_only {
        // without a magnitude extremum the magnitude says little: the
        // centre and slope of the phase step place the feature
        phase_step_centre(d, c.idx, xl, xr).map_or((xc, None), |(x, z)| (x, Some(z)))
    } else {
        match local_fit(d, window.clone(), xc, sign, 1.0) {
            Some((x0, z)) if fit_ok(x0, z) => (x0, Some(z)),
            _ => (
                parabolic_vertex(d, c.idx),
                half_power_zeta(d, c.idx, c.dip, xl, xr),
            ),
        }
    };

    let mut phase = phase_check(d, c, x0, zeta, xl, xr, dx);
    if phase.m > 1 && !c.phase_only {
        if let Some((x2, z2)) = local_fit(d, window, xc, sign, phase.m as f64) {
            if fit_ok(x2, z2) {
                x0 = x2;
                zeta = Some(z2);
                let m = phase.m;
                phase = phase_check(d, c, x0, zeta, xl, xr, dx);
                phase.m = phase.m.max(m);
            }
        }
    }
    let zg = zeta.unwrap_or(0.01).clamp(0.001, 0.2);
    let near_edge =
        x0 - d.x[0] < (5.0 * zg).max(3.0 * dx) || d.x[n - 1] - x0 < (5.0 * zg).max(3.0 * dx);
    let side = if phase.missing_side || near_edge {
        EDGE_FACTOR
    } else if phase.partial {
        PARTIAL_FACTOR
    } else {
        1.0
    };
    // a phase step without an extremum has no magnitude evidence: at most 0.6
    let c_mag = if c.phase_only {
        0.0
    } else {
        logistic(c.z - 4.0)
    };
    let c_sig = logistic(phase.dphi.abs() / phase.sd - 4.0);
    let confidence = phase.agree_feature * c_sig * (0.6 + 0.4 * c_mag) * side;
    let nm_confidence = if c.dip {
        // Noise makes many shallow one-line dips without a phase change:
        // an nm dip must be clearly above the noise (0.5 at 10 sigma) and
        // at least about 2 dB deep.
        logistic(c.z - NM_DIP_SIGMA)
            * logistic((c.prom - NM_DIP_DEPTH) / 0.05)
            * phase.agree_other
            * (1.0 - phase.agree_single)
    } else {
        0.0
    };
    Eval {
        id: 0,
        dip: c.dip,
        prom: c.prom,
        dx,
        x0,
        zeta,
        m: phase.m,
        dphi: phase.dphi,
        confidence,
        nm_confidence,
        edge: side == EDGE_FACTOR,
    }
}

struct PhaseCheck {
    dphi: f64,
    sd: f64,
    m: u32,
    /// Agreement with the feature of the magnitude kind (best multiplicity).
    agree_feature: f64,
    /// Agreement with multiplicity 1.
    agree_single: f64,
    /// Agreement with "no change" or "the wrong way".
    agree_other: f64,
    missing_side: bool,
    partial: bool,
}

/// The phase change across a candidate and its agreement with the
/// hypotheses, between reference lines outside `3 zeta` on either side.
fn phase_check(
    d: &Data,
    c: &Candidate,
    x0: f64,
    zeta: Option<f64>,
    xl: f64,
    xr: f64,
    dx: f64,
) -> PhaseCheck {
    let zg = zeta.unwrap_or(0.01).clamp(0.001, 0.2);
    let g = (3.0 * zg).max(1.5 * dx);
    let mut partial = false;
    let mut missing_side = false;
    let centre = (c.idx..c.idx + 1).collect::<Vec<_>>();
    let mut zone = |lo: f64, hi: f64, fallback_lo: f64, fallback_hi: f64, far_left: bool| {
        // a dense grid is thinned to at most ZONE_MAX_LINES evenly picked lines
        let r = lines_in(d, lo, hi);
        let z: Vec<usize> = r
            .clone()
            .step_by(r.len().div_ceil(ZONE_MAX_LINES).max(1))
            .collect();
        if !z.is_empty() {
            return z;
        }
        // Inside the transition: the farthest line on this side, if any.
        let r = lines_in(d, fallback_lo, fallback_hi);
        let f: Vec<usize> = [r.start, r.end.saturating_sub(1)]
            .into_iter()
            .filter(|&i| r.contains(&i) && i != c.idx)
            .collect();
        let pick = if far_left { f.first() } else { f.last() };
        match pick {
            Some(&i) => {
                partial = true;
                vec![i]
            }
            None => {
                missing_side = true;
                centre.clone()
            }
        }
    };
    let left = zone(xl, x0 - g, xl, x0, true);
    let right = zone(x0 + g, xr, x0, xr, false);
    let avg = |v: &[usize], f: &dyn Fn(usize) -> f64| mean(v.iter().map(|&i| f(i)));
    let dphi = avg(&right, &|i| d.phi[i]) - avg(&left, &|i| d.phi[i]);
    let var = |v: &[usize]| avg(v, &|i| d.sigma[i].powi(2)) / v.len() as f64;
    let sd = (var(&left) + var(&right)).sqrt();
    let unit =
        avg(&right, &|i| zero_phase(d.x[i], x0, zg)) - avg(&left, &|i| zero_phase(d.x[i], x0, zg));
    let tau = (PHASE_TOLERANCE.powi(2) + sd * sd).sqrt();
    let agree = |e: f64| (-0.5 * ((dphi - e) / tau).powi(2)).exp();
    // resonance: -m * unit, antiresonance: +m * unit
    let s = if c.dip { 1.0 } else { -1.0 };
    let (m, agree_feature) = (1..=3u32)
        .map(|m| (m, agree(s * m as f64 * unit)))
        .fold((1, 0.0), |b, x| if x.1 > b.1 { x } else { b });
    PhaseCheck {
        dphi,
        sd,
        m,
        agree_feature,
        agree_single: agree(s * unit),
        agree_other: agree(0.0).max(agree(-s * unit)),
        missing_side,
        partial,
    }
}

/// Steps 5 and 6 for all candidates, in three rounds:
///
/// 1. every magnitude candidate on the data;
/// 2. again, each with the other features found so far divided out, so
///    that the phase tails of close, heavily damped neighbours do not bias
///    its phase change (repeated until the features no longer change, at
///    most three times);
/// 3. phase steps of what the features leave (a feature without an
///    extremum of the magnitude), with all features divided out.
fn find_features(d: &Data, mags: &[Candidate], notes: &mut Vec<ClassifyNote>) -> Vec<Eval> {
    let mut all: Vec<Candidate> = mags.to_vec();
    let anchors = Anchors::new(d, mags);
    let mags = &anchors;
    let mut evals: Vec<Eval> = (0..all.len())
        .map(|k| evaluate_candidate(d, d, mags, &all, k, &[]))
        .collect();
    let mut found = accepted(evals.clone(), &mut Vec::new());
    deflate(d, mags, &all, &mut evals, &mut found);
    let resid = without_features(d, &found);
    let steps = phase_steps(&resid, &found);
    if !steps.is_empty() {
        for c in steps {
            all.push(c);
            evals.push(evaluate_candidate(
                d,
                &resid,
                mags,
                &all,
                all.len() - 1,
                &found,
            ));
        }
        found = accepted(evals.clone(), &mut Vec::new());
        deflate(d, mags, &all, &mut evals, &mut found);
    }
    let found = accepted(evals, notes);
    for e in found.iter().filter(|e| all[e.id].phase_only) {
        notes.push(ClassifyNote::PhaseOnly {
            feature: feature_of(e),
            freq_hz: e.x0.exp() / (2.0 * PI),
            phase_change_deg: e.dphi.to_degrees(),
        });
    }
    found
}

/// Evaluates candidate `k` of `all` on `data` (the data, possibly with
/// other features divided out). Magnitude candidates are bounded by the
/// strong magnitude candidates `mags`, phase steps by the other features
/// `found`.
fn evaluate_candidate(
    d: &Data,
    data: &Data,
    mags: &Anchors,
    all: &[Candidate],
    k: usize,
    found: &[Eval],
) -> Eval {
    let mut e = evaluate(data, &all[k], bounds_of(d, mags, all, k, found));
    e.id = k;
    e
}

/// The neighbourhood of candidate `k` (see [`evaluate_candidate`]).
fn bounds_of(d: &Data, mags: &Anchors, all: &[Candidate], k: usize, found: &[Eval]) -> (f64, f64) {
    let c = &all[k];
    if c.phase_only {
        bounds(
            d,
            d.x[c.idx],
            found.iter().filter(|f| f.id != k).map(|f| f.x0),
        )
    } else {
        mags.bounds(d, c)
    }
}

/// Re-evaluates every candidate with the other features found divided
/// out, until the features no longer change (at most `DEFLATION_ROUNDS`).
fn deflate(
    d: &Data,
    mags: &Anchors,
    all: &[Candidate],
    evals: &mut Vec<Eval>,
    found: &mut Vec<Eval>,
) {
    let key = |v: &[Eval]| v.iter().map(|e| (e.id, e.m)).collect::<Vec<_>>();
    for _ in 0..DEFLATION_ROUNDS {
        // All features divided out once per round; each candidate gets its
        // own feature back on the lines it reads (its neighbourhood).
        let base = without_features(d, found);
        let mut work = base.clone();
        let next: Vec<Eval> = (0..all.len())
            .map(|k| {
                // noise extrema without any phase support stay as they are
                if evals[k].confidence < 0.01 && !all[k].strong {
                    return evals[k].clone();
                }
                let own: Vec<Eval> = found.iter().filter(|f| f.id == k).cloned().collect();
                let i = all[k].idx;
                let (xl, xr) = bounds_of(d, mags, all, k, found);
                let lines = lines_in(d, xl, xr);
                let lines = lines.start.min(i.saturating_sub(2))..lines.end.max(i + 3).min(d.len());
                for j in lines.clone() {
                    let (l, p) = feature_model(&own, d.x[j]);
                    work.y[j] = base.y[j] + l;
                    work.phi[j] = base.phi[j] + p;
                }
                let e = evaluate_candidate(d, &work, mags, all, k, found);
                for j in lines {
                    work.y[j] = base.y[j];
                    work.phi[j] = base.phi[j];
                }
                e
            })
            .collect();
        *evals = next;
        let next_found = accepted(evals.clone(), &mut Vec::new());
        let done = key(&next_found) == key(found);
        *found = next_found;
        if done {
            break;
        }
    }
}

/// Features of the magnitude kind with at least the report confidence;
/// of two of the same kind within half their half-power bandwidths (a
/// peak split by noise) the weaker goes.
fn accepted(evals: Vec<Eval>, notes: &mut Vec<ClassifyNote>) -> Vec<Eval> {
    let mut found: Vec<Eval> = evals
        .into_iter()
        .filter(|e| e.confidence >= REPORT_CONFIDENCE && e.confidence >= e.nm_confidence)
        .collect();
    found.sort_by(|a, b| a.x0.total_cmp(&b.x0));
    let mut out: Vec<Eval> = Vec::new();
    for e in found {
        if let Some(last) = out.last_mut() {
            let width = (0.5 * (last.zeta.unwrap_or(0.01) + e.zeta.unwrap_or(0.01)))
                .max(1.5 * last.dx.max(e.dx));
            if last.dip == e.dip && (e.x0 - last.x0).abs() < width {
                notes.push(ClassifyNote::Merged {
                    feature: feature_of(&e),
                    first_hz: last.x0.exp() / (2.0 * PI),
                    second_hz: e.x0.exp() / (2.0 * PI),
                });
                if e.confidence > last.confidence {
                    *last = e;
                }
                continue;
            }
        }
        out.push(e);
    }
    out
}

/// Phase steps of `r` (the data with the features divided out): lines
/// where the mean phase over the next `PHASE_STEP_HALF` in `ln w` differs
/// from the mean over the previous one by at least `PHASE_STEP_MIN` and 6
/// noise standard deviations, at a local extremum of that difference, with
/// full windows on both sides (so that a delay's steady phase fall makes
/// no step at the band edge), away from the features found.
fn phase_steps(r: &Data, found: &[Eval]) -> Vec<Candidate> {
    let n = r.len();
    let mut ps = vec![0.0; n + 1];
    let mut vs = vec![0.0; n + 1];
    for i in 0..n {
        ps[i + 1] = ps[i] + r.phi[i];
        vs[i + 1] = vs[i] + r.sigma[i].powi(2);
    }
    let h = PHASE_STEP_HALF;
    let step: Vec<Option<(f64, f64)>> = (0..n)
        .map(|i| {
            if r.x[i] - h < r.x[0] || r.x[i] + h > r.x[n - 1] {
                return None;
            }
            let l = r.x.partition_point(|&x| x < r.x[i] - h);
            let rr = r.x.partition_point(|&x| x <= r.x[i] + h);
            let (nl, nr) = (i - l, rr - i - 1);
            if nl < 2 || nr < 2 {
                return None;
            }
            let ml = (ps[i] - ps[l]) / nl as f64;
            let mr = (ps[rr] - ps[i + 1]) / nr as f64;
            let sd = ((vs[i] - vs[l]) / (nl * nl) as f64 + (vs[rr] - vs[i + 1]) / (nr * nr) as f64)
                .sqrt();
            Some((mr - ml, sd))
        })
        .collect();
    let mut picks: Vec<(usize, f64)> = (1..n.saturating_sub(1))
        .filter_map(|i| {
            let (v, sd) = step[i]?;
            let (a, _) = step[i - 1]?;
            let (b, _) = step[i + 1]?;
            let extremum = if v > 0.0 {
                v >= a && v > b
            } else {
                v <= a && v < b
            };
            let far = found
                .iter()
                .all(|f| (r.x[i] - f.x0).abs() > f.zeta.unwrap_or(0.01).max(2.0 * f.dx));
            (extremum && far && v.abs() >= PHASE_STEP_MIN && v.abs() >= 6.0 * sd).then_some((i, v))
        })
        .collect();
    // the strongest step of a neighbourhood only
    picks.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    let mut kept: Vec<(usize, f64)> = Vec::new();
    for p in picks {
        if kept.iter().all(|k| (r.x[k.0] - r.x[p.0]).abs() > h) {
            kept.push(p);
        }
    }
    kept.sort_by_key(|k| k.0);
    kept.into_iter()
        .map(|(idx, v)| Candidate {
            idx,
            dip: v > 0.0,
            prom: 0.0,
            z: 0.0,
            strong: false,
            phase_only: true,
        })
        .collect()
}

/// Caps adjacent dip-peak pairs closer than `separation` (relative).
fn mark_near_cancellations(found: &mut [Eval], separation: f64, notes: &mut Vec<ClassifyNote>) {
    let limit = (1.0 + separation).ln();
    for k in 1..found.len() {
        let (a, b) = (&found[k - 1], &found[k]);
        if a.dip != b.dip && (b.x0 - a.x0).abs() < limit {
            notes.push(ClassifyNote::NearCancellation {
                first: feature_of(a),
                first_hz: a.x0.exp() / (2.0 * PI),
                second: feature_of(b),
                second_hz: b.x0.exp() / (2.0 * PI),
                relative_separation: (b.x0 - a.x0).exp() - 1.0,
                confidence_cap: NEAR_CANCELLATION_CAP,
            });
            for j in [k - 1, k] {
                found[j].confidence = found[j].confidence.min(NEAR_CANCELLATION_CAP);
            }
        }
    }
}

/// Dips of `resid` (the data with the features divided out, so that the
/// valley between two resonances is no dip) away from the features, that
/// are better explained by zeros off the positive `Omega` axis than by an
/// antiresonance.
fn nm_dips(resid: &Data, found: &[Eval], detection_sigma: f64) -> Vec<Eval> {
    let rc = candidates(resid, detection_sigma);
    let anchors = Anchors::new(resid, &rc);
    rc.iter()
        .filter(|c| {
            let dx = spacing(resid, c.idx);
            c.dip
                && found.iter().all(|e| {
                    (resid.x[c.idx] - e.x0).abs() > (3.0 * e.zeta.unwrap_or(0.01)).max(2.0 * dx)
                })
        })
        .map(|c| evaluate(resid, c, anchors.bounds(resid, c)))
        .filter(|e| e.nm_confidence >= REPORT_CONFIDENCE && e.nm_confidence > e.confidence)
        .collect()
}

/// Step 7: the level and phase budget of the whole curve.
struct Budget {
    /// Top minus bottom level after the features are divided out (nepers).
    level: f64,
    level_sd: f64,
    /// Top minus bottom phase after the features are divided out (radians).
    phase: f64,
    /// Slope of `ln|G|` over `ln w` in the bottom region, if it spans at
    /// least 0.2.
    low_slope: Option<f64>,
}

/// The features' damped factors at `x`: `(ln|.|, arg)`.
fn feature_model(found: &[Eval], x: f64) -> (f64, f64) {
    found.iter().fold((0.0, 0.0), |(l, p), e| {
        let s = if e.dip { 1.0 } else { -1.0 } * e.m as f64;
        let z = e.zeta.unwrap_or(0.01).clamp(0.001, 0.2);
        (
            l + s * zero_level(x, e.x0, z),
            p + s * zero_phase(x, e.x0, z),
        )
    })
}

/// `d` with the damped factors of the features divided out.
fn without_features(d: &Data, found: &[Eval]) -> Data {
    let mut r = d.clone();
    for i in 0..r.len() {
        let (l, p) = feature_model(found, r.x[i]);
        r.y[i] -= l;
        r.phi[i] -= p;
    }
    r
}

/// The budget on `d`, the data with the features divided out; `found`
/// gives the zones left out around features, `dips` those around nm dips.
fn budget(d: &Data, found: &[Eval], dips: &[&Eval]) -> Option<Budget> {
    let n = d.len();
    let kept: Vec<usize> = (0..n)
        .filter(|&i| {
            let dx = spacing(d, i);
            found
                .iter()
                .all(|e| (d.x[i] - e.x0).abs() > (4.0 * e.zeta.unwrap_or(0.01)).max(2.0 * dx))
                && dips.iter().all(|e| (d.x[i] - e.x0).abs() > 0.1)
        })
        .collect();
    if kept.len() < 6 {
        return None;
    }
    let span = d.x[n - 1] - d.x[0];
    let mut lo: Vec<usize> = kept
        .iter()
        .copied()
        .filter(|&i| d.x[i] <= d.x[0] + BUDGET_REGION * span)
        .collect();
    if lo.len() < 3 {
        lo = kept[..3].to_vec();
    }
    let mut hi: Vec<usize> = kept
        .iter()
        .copied()
        .filter(|&i| d.x[i] >= d.x[n - 1] - BUDGET_REGION * span)
        .collect();
    if hi.len() < 3 {
        hi = kept[kept.len() - 3..].to_vec();
    }
    if lo.last() >= hi.first() {
        return None;
    }
    let avg = |v: &[usize], f: &dyn Fn(usize) -> f64| mean(v.iter().map(|&i| f(i)));
    let var = |v: &[usize]| avg(v, &|i| d.sigma[i].powi(2)) / v.len() as f64;
    let level = avg(&hi, &|i| d.y[i]) - avg(&lo, &|i| d.y[i]);
    let phase = avg(&hi, &|i| d.phi[i]) - avg(&lo, &|i| d.phi[i]);
    // damping and frequency errors of the features: 0.02 neper each
    let level_sd = (var(&lo) + var(&hi) + 4e-4 * found.len() as f64).sqrt();
    let low_slope = {
        let xs: Vec<f64> = lo.iter().map(|&i| d.x[i]).collect();
        let ys: Vec<f64> = lo.iter().map(|&i| d.y[i]).collect();
        let (mx, my) = (mean(xs.iter().copied()), mean(ys.iter().copied()));
        let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
        let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        (xs[xs.len() - 1] - xs[0] >= 0.2).then(|| sxy / sxx)
    };
    Some(Budget {
        level,
        level_sd,
        phase,
        low_slope,
    })
}

/// Combines the nm dips and the level budget.
fn nm_evidence(
    b: Option<&Budget>,
    dips: &[&Eval],
    notes: &mut Vec<ClassifyNote>,
) -> Option<NmEvidence> {
    let mut c_level = 0.0;
    if let Some(b) = b {
        let excess = b.level;
        // a positive unexplained phase means missed antiresonances, not nm
        let missed_zero = (-(((b.phase - 0.5 * PI).max(0.0)) / (0.25 * PI)).powi(2)).exp();
        // Below all features a free chain is flat: a slope at the bottom
        // is the tail of a feature just below the band (or a wrong output
        // kind), and it would pass for a level excess.
        let flat_bottom = b.low_slope.is_none_or(|s| s.abs() <= 1.0);
        c_level = if flat_bottom {
            (logistic(excess / b.level_sd - 5.0) * logistic((excess - LEVEL_MIN_EXCESS) / 0.07))
                .min(LEVEL_CAP)
                * missed_zero
        } else {
            0.0
        };
        notes.push(ClassifyNote::GainPhaseBudget {
            level_db: excess * DB_PER_NEPER,
            phase_deg: b.phase.to_degrees(),
        });
        if excess > LEVEL_MIN_EXCESS && b.phase > 0.5 * PI {
            notes.push(ClassifyNote::LevelRiseWithPhaseRise);
        }
        if excess < -LEVEL_MIN_EXCESS && excess.abs() > 5.0 * b.level_sd {
            notes.push(ClassifyNote::LevelFalls);
        }
        if b.phase < -0.5 * PI {
            notes.push(ClassifyNote::PhaseFalls);
        }
    } else {
        notes.push(ClassifyNote::NoBudget);
    }
    let nm_dips: Vec<NmDip> = dips
        .iter()
        .map(|e| NmDip {
            freq_hz: e.x0.exp() / (2.0 * PI),
            depth_db: e.prom * DB_PER_NEPER,
            phase_change_deg: e.dphi.to_degrees(),
            confidence: e.nm_confidence,
        })
        .collect();
    // The strongest dip counts: dips are not independent evidence.
    let c_dip = nm_dips.iter().map(|x| x.confidence).fold(0.0, f64::max);
    let confidence = 1.0 - (1.0 - c_level) * (1.0 - c_dip);
    if confidence < REPORT_CONFIDENCE && nm_dips.is_empty() {
        return None;
    }
    Some(NmEvidence {
        confidence,
        level_excess_db: b.map(|b| b.level * DB_PER_NEPER),
        phase_excess_deg: b.map(|b| b.phase.to_degrees()),
        dips: nm_dips,
    })
}

#[cfg(test)]
mod tests {

    /// The scan from every peak that [`peaks`] replaces: the reference
    /// for its equivalence.
    fn peaks_by_scan(x: &[f64], y: &[f64], reach: f64) -> Vec<(usize, f64)> {
        let n = y.len();
        let mut out = Vec::new();
        let mut i = 1;
        while i + 1 < n {
            if y[i] <= y[i - 1] {
                i += 1;
                continue;
            }
            let mut j = i;
            while j + 1 < n && y[j + 1] == y[i] {
                j += 1;
            }
            if j + 1 < n && y[j + 1] < y[i] {
                let h = y[i];
                let mut left = h;
                for k in (0..i).rev() {
                    if y[k] > h || x[i] - x[k] > reach {
                        break;
                    }
                    left = left.min(y[k]);
                }
                let mut right = h;
                for k in j + 1..n {
                    if y[k] > h || x[k] - x[j] > reach {
                        break;
                    }
                    right = right.min(y[k]);
                }
                out.push(((i + j) / 2, h - left.max(right)));
            }
            i = j + 1;
        }
        out
    }

    /// A candidate's neighbourhood from the sorted anchors equals the one
    /// from every strong candidate but itself.
    #[test]
    fn anchors_bound_as_the_scan_over_every_candidate() {
        let mut rng = mms::xorshift::XorShift::new(9);
        let n = 400;
        let f: Vec<f64> = (1..=n).map(|k| k as f64).collect();
        let d = Data {
            orig: (0..n).collect(),
            x: f.iter().map(|f| (2.0 * PI * f).ln()).collect(),
            f,
            y: vec![0.0; n],
            phi: vec![0.0; n],
            sigma: vec![0.01; n],
            given: vec![0.01; n],
        };
        let cands: Vec<Candidate> = (0..60)
            .map(|_| Candidate {
                idx: (rng.next_u64() % n as u64) as usize,
                dip: rng.uniform() < 0.5,
                prom: 1.0,
                z: 5.0,
                strong: rng.uniform() < 0.4,
                phase_only: false,
            })
            .collect();
        let anchors = Anchors::new(&d, &cands);
        for c in &cands {
            let scan = bounds(
                &d,
                d.x[c.idx],
                cands
                    .iter()
                    .filter(|o| o.strong && o.idx != c.idx)
                    .map(|o| d.x[o.idx]),
            );
            assert_eq!(anchors.bounds(&d, c), scan);
        }
    }

    /// The n log n prominences equal the scan's exactly, on noisy curves
    /// with plateaus (values rounded so that ties occur) and several
    /// reaches.
    #[test]
    fn peaks_equal_the_scan_from_every_peak() {
        let mut rng = mms::xorshift::XorShift::new(5);
        for case in 0..40 {
            let n = 50 + 37 * case;
            let x: Vec<f64> = (0..n).map(|k| (k as f64 / n as f64) * 3.0).collect();
            let y: Vec<f64> = (0..n)
                .map(|k| {
                    let t = k as f64 / n as f64;
                    ((8.0 * t).sin() * 5.0 + rng.normal() * (case % 4) as f64).round() / 2.0
                })
                .collect();
            for reach in [0.05, 0.7, 10.0] {
                assert_eq!(
                    peaks(&x, &y, reach),
                    peaks_by_scan(&x, &y, reach),
                    "case {case}, reach {reach}"
                );
            }
        }
    }

    use super::*;

    #[test]
    fn wrap_is_in_half_open_interval() {
        for a in [-7.0, -PI, -1.0, 0.0, 1.0, PI, 4.0, 10.0] {
            let w = wrap(a);
            assert!(w > -PI && w <= PI, "{a} -> {w}");
            // a whole number of turns apart
            let turns = (a - w) / (2.0 * PI);
            assert!((turns - turns.round()).abs() < 1e-12, "{a} -> {w}");
        }
        assert_eq!(wrap(-PI), PI);
    }

    #[test]
    fn prominence_of_two_peaks() {
        // peak 3 with saddle 1 towards the higher peak 5
        let y = [0.0, 3.0, 1.0, 5.0, 0.5];
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        assert_eq!(peaks(&x, &y, 10.0), vec![(1, 2.0), (3, 4.5)]);
        // within a reach of 1 the peak of 5 sees 1 on its left, not 0
        assert_eq!(peaks(&x, &y, 1.0), vec![(1, 2.0), (3, 4.0)]);
        // plateau counted once
        assert_eq!(peaks(&x, &[0.0, 2.0, 2.0, 2.0, 0.0], 10.0), vec![(2, 2.0)]);
        // edges are never peaks
        assert!(peaks(&x[..3], &[3.0, 1.0, 2.0], 10.0).is_empty());
    }

    #[test]
    fn solve6_solves() {
        let mut a = [[0.0; 6]; 6];
        for (i, row) in a.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = if i == j {
                    4.0
                } else {
                    1.0 / (1.0 + (i + j) as f64)
                };
            }
        }
        let x = [1.0, -2.0, 3.0, 0.5, -1.5, 2.5];
        let mut b = [0.0; 6];
        for i in 0..6 {
            b[i] = (0..6).map(|j| a[i][j] * x[j]).sum();
        }
        let got = solve6(a, b).unwrap();
        for i in 0..6 {
            assert!((got[i] - x[i]).abs() < 1e-12);
        }
        assert!(solve6([[0.0; 6]; 6], b).is_none());
    }

    fn data_from(g: impl Fn(f64) -> Complex64, n: usize, f0: f64, f1: f64) -> Data {
        let f: Vec<f64> = (0..n)
            .map(|i| f0 * (f1 / f0).powf(i as f64 / (n - 1) as f64))
            .collect();
        let h: Vec<Complex64> = f.iter().map(|&f| g(2.0 * PI * f)).collect();
        let frf = Frf::new(f, h, None).unwrap();
        let band: Vec<usize> = (0..n).collect();
        let given = vec![0.0; n];
        let mut d = Data::inertance(&frf, Output::Acceleration, &band, &given, &mut Vec::new());
        d.unwrap_phase();
        d.estimate_noise();
        d
    }

    #[test]
    fn local_fit_recovers_a_pole_and_a_zero() {
        // (1 + 2 0.02 s/w1 + s^2/w1^2) / (1 + 2 0.01 s/w2 + s^2/w2^2), w1 = 2 pi 50, w2 = 2 pi 80
        let q = |s: Complex64, w: f64, z: f64| 1.0 + 2.0 * z * s / w + s * s / (w * w);
        let (w1, w2) = (2.0 * PI * 50.0, 2.0 * PI * 80.0);
        let d = data_from(
            |w| {
                let s = Complex64::new(0.0, w);
                q(s, w1, 0.02) / q(s, w2, 0.01)
            },
            600,
            10.0,
            400.0,
        );
        let near = |f: f64| d.x.partition_point(|&x| x < (2.0 * PI * f).ln());
        let i = near(80.0);
        let (x0, z) = local_fit(
            &d,
            lines_in(&d, d.x[i] - 0.2, d.x[i] + 0.2),
            d.x[i],
            1.0,
            1.0,
        )
        .unwrap();
        assert!((x0 - w2.ln()).abs() < 2e-3, "{}", x0.exp() / (2.0 * PI));
        assert!((z - 0.01).abs() < 2e-3, "{z}");
        let i = near(50.0);
        let (x0, z) = local_fit(
            &d,
            lines_in(&d, d.x[i] - 0.2, d.x[i] + 0.2),
            d.x[i],
            -1.0,
            1.0,
        )
        .unwrap();
        assert!((x0 - w1.ln()).abs() < 2e-3, "{}", x0.exp() / (2.0 * PI));
        assert!((z - 0.02).abs() < 3e-3, "{z}");
    }

    #[test]
    fn noise_estimate_of_smooth_data_is_the_floor() {
        let d = data_from(
            |w| Complex64::new(1.0, 0.0) / (1.0 + w / 1000.0),
            200,
            1.0,
            100.0,
        );
        assert!(d.sigma.iter().all(|&s| s == SIGMA_FLOOR));
    }

    #[test]
    fn band_keeps_an_uncertain_antiresonance_and_picks_the_widest_run() {
        let n = 200;
        let f: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        // 16 averages: coherence 0.95 gives 0.04 nepers, 0.3 gives 0.27,
        // 0.1 gives 0.53.
        let mut coh = vec![0.95; n];
        for c in coh.iter_mut().take(20) {
            *c = 0.1; // poorly excited bottom
        }
        for c in coh.iter_mut().skip(100).take(6) {
            *c = 0.3; // a dip at an antiresonance: 6 lines near 100 Hz (< 0.15 decades)
        }
        let frf = Frf::new(f, vec![Complex64::new(1.0, 0.0); n], Some(coh)).unwrap();
        let o = ClassifyOptions {
            averages: Some(16),
            ..Default::default()
        };
        let u = line_uncertainty(&frf, Some(16.0));
        assert_eq!(u.source, UncertaintySource::Coherence);
        let mut notes = Vec::new();
        let band = select_band(&frf, &u.relative, u.source, &o, &mut notes).unwrap();
        assert_eq!(band.first(), Some(&20));
        assert_eq!(band.last(), Some(&(n - 1)));
        // The 6 lines of the dip, bridged.
        let bridged = ClassifyNote::LowWeightKept {
            lines: 6,
            max_gap_decades: o.max_gap_decades,
        };
        assert!(notes.contains(&bridged), "{notes:?}");
        // With a user's band every excited line in it is used.
        let o = ClassifyOptions {
            band_hz: Some((5.0, 50.0)),
            ..o
        };
        let band = select_band(&frf, &u.relative, u.source, &o, &mut Vec::new()).unwrap();
        assert_eq!((band[0], band.len()), (4, 46));
    }

    #[test]
    fn the_widest_run_is_measured_in_decades_not_lines() {
        // Lines 1..=1000 Hz on a linear grid: 1-30 Hz informative (30
        // lines, 1.5 decades), 31-99 Hz not, 100-1000 Hz informative (901
        // lines but 1 decade). The band is the low run.
        let n = 1000;
        let f: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let sigma: Vec<f64> = f
            .iter()
            .map(|&x| {
                if (31.0..100.0).contains(&x) {
                    1.0
                } else {
                    0.05
                }
            })
            .collect();
        let frf = Frf::new(f, vec![Complex64::new(1.0, 0.0); n], None).unwrap();
        let band = select_band(
            &frf,
            &sigma,
            UncertaintySource::Given,
            &ClassifyOptions::default(),
            &mut Vec::new(),
        )
        .unwrap();
        assert_eq!((band[0], *band.last().unwrap()), (0, 29));
    }

    #[test]
    fn options_are_validated() {
        let o = ClassifyOptions {
            smoothing_lines: 4,
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(ClassifyError::InvalidOption {
                name: "smoothing_lines",
                ..
            })
        ));
        let o = ClassifyOptions {
            band_hz: Some((10.0, 1.0)),
            ..Default::default()
        };
        assert!(o.validate().is_err());
        assert!(ClassifyOptions::default().validate().is_ok());
    }
}
