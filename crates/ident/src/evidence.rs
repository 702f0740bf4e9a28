//! What the diagnoses found, as numbers: the figures each hypothesis was
//! scored on ([`Evidence`]), what the calibration ran into
//! ([`CalibrationNote`]) and what a time record shows of a nonlinearity
//! ([`RecordEvidence`]). The libraries return these; the formatter writes
//! the sentences.

use crate::diagnose::{EffectKind, EffectVerdict, FitSummary};
use crate::nonlinear::TimeFit;
use serde::Serialize;

/// The figures behind one hypothesis's score, by the domain it was tried
/// in.
///
/// ```
/// use ident::diagnose::{diagnose, DiagnoseOptions, EffectKind};
/// use ident::evidence::Evidence;
/// # use frf::Frf;
/// # use mms::model_file::{ModelFile, Motion};
/// # use mms::response::{ChainResponse, Effects, Parameters};
/// # use mms::{Model, Output};
/// # let a2 = Model::from_id("A2")?;
/// # let truth = [0.01, 0.012, 0.02, 400.0, 900.0, 0.03, 0.05];
/// # let f: Vec<f64> = (0..800).map(|k| 5.0 * 1.004f64.powi(k)).collect();
/// # let delayed = Effects { time_delay_s: Some(3e-4), ..Effects::default() };
/// # let h = ChainResponse::with_effects(&a2, Output::Position, &delayed).eval_many(&truth, &f)?;
/// # let model = ModelFile {
/// #     model: a2, output: Output::Position,
/// #     parameters: Parameters::from_values(&a2, truth.iter().map(|p| p * 1.1).collect())?,
/// #     gain: 1.0, motion: Motion::Translational, effects: Effects::default(),
/// # };
/// let d = diagnose(&Frf::new(f, h, None)?, &model, &DiagnoseOptions::default())?;
/// let Evidence::Frequency(e) = &d.effects[0].evidence else { panic!() };
/// // The dead time takes the phase error from degrees to nothing.
/// assert!(e.before.rms_deg > 1.0 && e.after.rms_deg < 0.01);
/// assert!(e.cost_before - e.cost_after > e.price);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "domain", rename_all = "snake_case")]
pub enum Evidence {
    /// The verdict `none`: no hypothesis earned its parameters; the best of
    /// them, if any could be fitted.
    Nothing {
        /// The best rejected hypothesis.
        best: Option<Box<EffectVerdict>>,
    },
    /// A hypothesis fitted to the FRF.
    Frequency(FrequencyEvidence),
    /// A hypothesis fitted by simulating the record.
    Time(TimeEvidence),
    /// A term of the inverse-dynamics regression.
    InverseDynamics(RegressionEvidence),
}

/// A frequency-domain hypothesis's cost and errors.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrequencyEvidence {
    /// The effects kept before it (forward selection), to which it was
    /// added.
    pub added_to: Vec<EffectKind>,
    /// The cost is on held-out lines (else on the fitted lines, by BIC).
    pub held_out: bool,
    /// The cost without it, in noise units.
    pub cost_before: f64,
    /// The cost with it.
    pub cost_after: f64,
    /// What its drop must exceed: the margin on held-out lines, its
    /// parameters' BIC price plus the margin otherwise.
    pub price: f64,
    /// RMS errors without it.
    pub before: FitSummary,
    /// RMS errors with it.
    pub after: FitSummary,
    /// For an extra mass: the chain it makes.
    pub extended: Option<ExtendedChain>,
}

/// The chain an extra mass makes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ExtendedChain {
    /// Its masses.
    pub masses: usize,
    /// Its structure ID.
    pub id: String,
}

/// A time-domain hypothesis's errors, price and checks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimeEvidence {
    /// Errors without it.
    pub before: TimeFit,
    /// Errors with it.
    pub after: TimeFit,
    /// Its BIC gain on the fitted samples.
    pub bic_gain: f64,
    /// Its BIC price (and margin).
    pub price: f64,
    /// The share of the misfit it removes, when that is less than needed.
    pub too_small_share: Option<ShareShortfall>,
    /// Its figures on the held-out samples, if any are held out.
    pub held_out: Option<HeldOutSamples>,
    /// It lowers the held-out error by more than its price (or nothing
    /// was held out).
    pub validated: bool,
    /// Its force as a share of the RMS actuator force, when that is too
    /// small to tell from a drift.
    pub too_small_force: Option<ForceShortfall>,
}

/// A share of the misfit removed that is less than needed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ShareShortfall {
    /// The share it removes.
    pub share: f64,
    /// The share needed.
    pub needed: f64,
    /// It is the first effect: the misfit is the calibrated model's (else
    /// what the kept effects leave).
    pub first: bool,
    /// For a first effect, the output share the calibrated model leaves
    /// above which the rule applies.
    pub adequate: f64,
}

/// A hypothesis's output error on the held-out samples.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HeldOutSamples {
    /// RMS error without it.
    pub before: f64,
    /// RMS error with it.
    pub after: f64,
    /// Samples held out.
    pub samples: usize,
    /// `samples ln(before^2 / after^2)`.
    pub gain: f64,
    /// `ln(samples)`.
    pub price: f64,
}

/// A force too small next to the actuator's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ForceShortfall {
    /// The force over the RMS actuator force.
    pub share: f64,
    /// The share needed.
    pub needed: f64,
}

/// An inverse-dynamics term's figures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RegressionEvidence {
    /// The force residual without it, over the force RMS.
    pub residual_before: f64,
    /// The force residual with it.
    pub residual_after: f64,
    /// The share of the residual energy it removes.
    pub share: f64,
    /// Its BIC gain.
    pub bic_gain: f64,
    /// Its BIC price (and margin).
    pub price: f64,
}

/// What the calibration of the model's own parameters ran into.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "note", rename_all = "snake_case")]
pub enum CalibrationNote {
    /// A parameter stopped at a bound of its tolerance: evidence that
    /// something else is wrong.
    Pinned {
        /// The parameter.
        parameter: String,
        /// At the upper bound (else the lower).
        upper: bool,
        /// Its calibrated value.
        value: f64,
        /// Its nominal value.
        nominal: f64,
    },
    /// All parameters moved by one factor: a gain error looks like this.
    CommonFactor {
        /// The factor.
        factor: f64,
    },
}

/// What a time record shows before any model: the loop's law, the
/// coherence, the FRF's dependence on the level, harmonics.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RecordEvidence {
    /// In a closed loop, how well the controller law reproduces the input.
    pub controller: Option<ControllerEvidence>,
    /// The H1 coherence.
    pub coherence: Option<CoherenceEvidence>,
    /// The first half's FRF against the second half's.
    pub amplitude: Option<AmplitudeEvidence>,
    /// Output power at unexcited lines of a sparse input spectrum.
    pub harmonics: Option<HarmonicEvidence>,
}

/// The controller law on the recorded output and reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ControllerEvidence {
    /// Position gain.
    pub kp: f64,
    /// Velocity gain.
    pub kv: f64,
    /// The position filter's taps.
    pub filter: Vec<f64>,
    /// The output limit, if any.
    pub saturation: Option<f64>,
    /// RMS of `u - law` over the RMS of `u`.
    pub rms_rel: f64,
    /// Largest `|u - law|`.
    pub max_abs: f64,
    /// Samples where the law saturated.
    pub saturated: usize,
    /// `rms_rel` above which the simulated loop and its estimates are
    /// suspect (exceeded: a warning).
    pub warning_above: f64,
}

/// The coherence of the H1 estimate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CoherenceEvidence {
    /// Mean coherence over the lines of at least 0.5.
    pub mean: f64,
    /// Those lines.
    pub lines: usize,
    /// Lines below 0.9.
    pub below_0_9: usize,
    /// All lines.
    pub total: usize,
}

/// The FRF at two levels: the record's halves.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AmplitudeEvidence {
    /// Input RMS of the first half.
    pub input_rms_first: f64,
    /// Input RMS of the second half.
    pub input_rms_second: f64,
    /// RMS difference of the FRF magnitudes, dB.
    pub differ_db: f64,
    /// Over these lines (coherence at least 0.5 in both).
    pub lines: usize,
    /// What noise alone gives, dB.
    pub noise_db: f64,
}

/// Output power at unexcited lines relative to the excited ones.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HarmonicEvidence {
    /// Unexcited odd lines.
    pub odd_lines: usize,
    /// Their power, dB relative to the excited lines.
    pub odd_db: f64,
    /// Unexcited even lines.
    pub even_lines: usize,
    /// Their power, dB.
    pub even_db: f64,
}
