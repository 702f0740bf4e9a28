//! Diagnosis of what a model is missing: given a recording and a model
//! that should describe it, say whether the mismatch is only a parameter
//! error or some physics the model lacks, where it shows, and which effect
//! from a small library explains it best.
//!
//! Steps:
//!
//! 1. **Noise.** Every line's log-error `e_k = ln(G_k / H_k)` has a noise
//!    standard deviation `sigma_k` per real and imaginary part: the line's
//!    own uncertainty ([`frf::uncertainty::line_uncertainty`]: its standard
//!    deviation, else its coherence with [`DiagnoseOptions::averages`])
//!    if the recording has either, else one value
//!    from the scatter of the residual itself (the median absolute second
//!    difference, which a smooth model error does not reach: for white noise
//!    `var(e_{k+1} - 2 e_k + e_{k-1}) = 6 sigma^2`).
//! 2. **Calibration.** The chain's parameters are fitted within
//!    [`DiagnoseOptions::tolerance`] of their nominal values (clamped in
//!    log space), with a Gaussian prior of half that width so that moves
//!    the data do not ask for cost something. A parameter error is not
//!    missing physics; a parameter pinned at its bound is evidence that
//!    something else is wrong, and all parameters moved by one common
//!    factor are a gain error.
//! 3. **Mismatch.** The calibrated residual, normalised by the noise
//!    (`|e_k|^2 / (2 sigma_k^2)`, mean 1 for noise alone), smoothed over a
//!    few lines; runs above [`DiagnoseOptions::band_threshold`] are the
//!    bands where the model is wrong, each with its RMS errors.
//! 4. **Hypotheses.** Each effect of [`Effects`] (time delay, first-order
//!    lag, gain error, hysteretic damping, viscous friction to the ground)
//!    is added to the model with one parameter, fitted jointly with the
//!    chain's parameters (same bounds and prior) by Levenberg-Marquardt from
//!    the calibrated parameters and a start read off the residual.
//! 5. **Selection.** By the Bayesian information criterion on the
//!    noise-normalised cost: an effect is kept if its cost drop exceeds
//!    `ln(2 lines)` (the price of its one parameter) plus
//!    [`DiagnoseOptions::margin`]; kept effects are ranked by that score.
//!    If none is kept, the verdict is `none`.
//!
//! An extra mode (one more mass at either end or inside the chain) is a
//! hypothesis too; several effects are kept by forward selection, and
//! [`Selection::Holdout`] validates on held-out lines instead of BIC.
//!
//! ```
//! use frf::Frf;
//! use ident::diagnose::{diagnose, DiagnoseOptions, EffectKind};
//! use mms::model_file::{ModelFile, Motion};
//! use mms::response::{ChainResponse, Effects, Parameters};
//! use mms::{Model, Output};
//!
//! // The true system has a 0.3 ms dead time the model does not know of.
//! let a2 = Model::from_id("A2")?;
//! let truth = [0.01, 0.012, 0.02, 400.0, 900.0, 0.03, 0.05];
//! let f: Vec<f64> = (0..800).map(|k| 5.0 * 1.004f64.powi(k)).collect();
//! let delayed = Effects { time_delay_s: Some(3e-4), ..Effects::default() };
//! let h = ChainResponse::with_effects(&a2, Output::Position, &delayed)
//!     .eval_many(&truth, &f)?;
//! let data = Frf::new(f, h, None)?;
//! // The model's parameters are 10 % off.
//! let nominal: Vec<f64> = truth.iter().map(|p| p * 1.1).collect();
//! let model = ModelFile {
//!     model: a2,
//!     output: Output::Position,
//!     parameters: Parameters::from_values(&a2, nominal)?,
//!     gain: 1.0,
//!     motion: Motion::Translational,
//!     effects: Effects::default(),
//! };
//! let d = diagnose(&data, &model, &DiagnoseOptions::default())?;
//! assert_eq!(d.effects[0].kind, EffectKind::TimeDelay);
//! let delay = d.effects[0].parameters["delay_s"];
//! assert!((delay / 3e-4 - 1.0).abs() < 0.01);
//! assert!(d.after.rms_deg < 0.01 && d.before.rms_deg > 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::evidence::{CalibrationNote, Evidence, ExtendedChain, FrequencyEvidence};
use crate::fit::solve_spd;
use crate::selection::{forward_select, none, Trial};
use frf::welch::effective_samples;
use frf::Frf;
use mms::model_file::ModelFile;
use mms::response::{ChainResponse, EffectGradient, Effects, Parameters, ResponseError};
use num_complex::Complex64;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::{LN_10, PI};

/// Options of [`diagnose`].
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnoseOptions {
    /// Calibration bound on masses and springs: each stays within a factor
    /// `1 + tolerance` of its nominal value (either way, in log space).
    pub tolerance: f64,
    /// The same for dampers, which are rarely known as well as masses and
    /// springs.
    pub damper_tolerance: f64,
    /// Number of averages behind the recording's coherence (used only if
    /// the recording has a coherence and no standard deviation per line).
    pub averages: f64,
    /// Lines of the running mean of the normalised cost for the bands.
    pub band_window: usize,
    /// A band is where the smoothed normalised cost exceeds this (1: noise
    /// alone).
    pub band_threshold: f64,
    /// Narrower runs are not reported as bands.
    pub min_band_lines: usize,
    /// What an effect must gain beyond the BIC price of its parameter.
    pub margin: f64,
    /// Iteration limit of each Levenberg-Marquardt fit.
    pub max_iterations: usize,
    /// How an effect earns its parameters: by BIC on all lines, or by
    /// validation on held-out lines.
    pub selection: Selection,
}

/// How the diagnosis decides whether an effect is kept
/// ([`DiagnoseOptions::selection`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Selection {
    /// Bayesian information criterion on all lines: an effect is kept if
    /// its cost drop exceeds `ln(2 lines)` per parameter plus
    /// [`DiagnoseOptions::margin`].
    #[default]
    Bic,
    /// Validation on held-out lines: every [`HOLDOUT_EVERY`]th line (the
    /// 4th, 8th, ...) is left out of every fit, and an effect is kept if it
    /// lowers the noise-normalised cost on those lines by more than
    /// [`DiagnoseOptions::margin`].
    Holdout,
}

/// [`Selection::Holdout`] holds out every this many lines.
pub const HOLDOUT_EVERY: usize = 4;

impl Default for DiagnoseOptions {
    fn default() -> DiagnoseOptions {
        DiagnoseOptions {
            tolerance: crate::diagnosis::DEFAULT_TOLERANCE,
            damper_tolerance: 0.5,
            averages: 16.0,
            band_window: 9,
            band_threshold: 2.5,
            min_band_lines: 5,
            margin: 10.0,
            max_iterations: 60,
            selection: Selection::Bic,
        }
    }
}

/// The effects the diagnosis tries (JSON `kind`).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum EffectKind {
    /// Dead time `e^(-s T)`; parameter `delay_s`.
    TimeDelay,
    /// First-order lag; parameter `corner_hz`.
    Lowpass,
    /// A wrong actuator or sensor constant; parameter `factor`.
    GainError,
    /// Structural damping of every spring; parameter `loss_factor`.
    HystereticDamping,
    /// Viscous friction: a damper from the driven mass to the ground;
    /// parameter `viscous_ns_per_m`.
    ViscousFriction,
    /// The pre-sliding stiffness of friction at rest: a spring from the
    /// driven mass to the ground (a rigid-body mode becomes a resonance);
    /// parameter `pre_sliding_n_per_m`. Friction at rest also damps what
    /// it holds, so unless the model (or an effect kept before) has viscous
    /// friction, the hypothesis fits that damper with the spring and
    /// reports it as `viscous_ns_per_m` too.
    PreSlidingFriction,
    /// Coulomb (dry) friction on the driven mass, a force of constant size
    /// against the velocity (time domain only, [`crate::nonlinear`] and
    /// [`crate::idim`]); parameter `coulomb_n`.
    CoulombFriction,
    /// A dead zone in the spring next to the driven mass (time domain
    /// only, [`crate::nonlinear`]); parameter `gap`.
    Backlash,
    /// A constant force bias on the driven mass (time domain only,
    /// [`crate::nonlinear`] and [`crate::idim`]); parameter `force_n`,
    /// either sign.
    Offset,
    /// An unmodelled mass and compliance: the model refitted with one more
    /// mass (at the free end of the chain, or at its start for a free
    /// chain); parameters `resonance_hz` and `antiresonance_hz`, the
    /// features the extra mass adds.
    ExtraMode,
    /// Nothing is missing: the calibrated model explains the data.
    None,
}

impl EffectKind {
    /// The hypotheses tried, in a fixed order (ties keep it).
    pub const HYPOTHESES: [EffectKind; 6] = [
        EffectKind::TimeDelay,
        EffectKind::Lowpass,
        EffectKind::GainError,
        EffectKind::HystereticDamping,
        EffectKind::ViscousFriction,
        EffectKind::PreSlidingFriction,
    ];

    /// Every kind with one parameter that a model file can hold.
    pub const WITH_PARAMETER: [EffectKind; 9] = [
        EffectKind::TimeDelay,
        EffectKind::Lowpass,
        EffectKind::GainError,
        EffectKind::HystereticDamping,
        EffectKind::ViscousFriction,
        EffectKind::PreSlidingFriction,
        EffectKind::CoulombFriction,
        EffectKind::Backlash,
        EffectKind::Offset,
    ];

    /// The section of a model file's `[effects]` table that holds this
    /// effect's parameter: `friction` for the three kinds of friction (a
    /// damper, a spring at rest and a dry force on the same mass), else the
    /// JSON name.
    pub fn model_file_section(self) -> &'static str {
        match self {
            EffectKind::ViscousFriction
            | EffectKind::PreSlidingFriction
            | EffectKind::CoulombFriction => "friction",
            other => other.as_str(),
        }
    }

    /// JSON name.
    pub fn as_str(self) -> &'static str {
        match self {
            EffectKind::TimeDelay => "time_delay",
            EffectKind::Lowpass => "lowpass",
            EffectKind::GainError => "gain_error",
            EffectKind::HystereticDamping => "hysteretic_damping",
            EffectKind::ViscousFriction => "viscous_friction",
            EffectKind::PreSlidingFriction => "pre_sliding_friction",
            EffectKind::CoulombFriction => "coulomb_friction",
            EffectKind::Backlash => "backlash",
            EffectKind::Offset => "offset",
            EffectKind::ExtraMode => "extra_mode",
            EffectKind::None => "none",
        }
    }

    /// Name of the effect's parameter (`None` for [`EffectKind::None`] and
    /// for [`EffectKind::ExtraMode`], which has two).
    pub fn parameter_name(self) -> Option<&'static str> {
        match self {
            EffectKind::ExtraMode => None,
            EffectKind::TimeDelay => Some("delay_s"),
            EffectKind::Lowpass => Some("corner_hz"),
            EffectKind::GainError => Some("factor"),
            EffectKind::HystereticDamping => Some("loss_factor"),
            EffectKind::ViscousFriction => Some("viscous_ns_per_m"),
            EffectKind::PreSlidingFriction => Some("pre_sliding_n_per_m"),
            EffectKind::CoulombFriction => Some("coulomb_n"),
            EffectKind::Backlash => Some("gap"),
            EffectKind::Offset => Some("force_n"),
            EffectKind::None => None,
        }
    }

    /// `base` with this effect set to `value`.
    fn apply(self, base: &Effects, value: f64) -> Effects {
        let mut e = *base;
        match self {
            EffectKind::TimeDelay => e.time_delay_s = Some(value),
            EffectKind::Lowpass => e.lowpass_hz = Some(value),
            EffectKind::GainError => e.gain_factor = Some(value),
            EffectKind::HystereticDamping => e.loss_factor = Some(value),
            EffectKind::ViscousFriction => e.viscous_friction = Some(value),
            EffectKind::PreSlidingFriction => e.pre_sliding_stiffness = Some(value),
            EffectKind::CoulombFriction => e.coulomb_friction = Some(value),
            EffectKind::Backlash => e.backlash_gap = Some(value),
            EffectKind::Offset => e.offset_force = Some(value),
            EffectKind::ExtraMode | EffectKind::None => {}
        }
        e
    }

    /// `dG/dv` of this effect's parameter `v` (zero for the kinds an FRF
    /// does not show).
    fn derivative(self, d: &EffectGradient) -> Complex64 {
        match self {
            EffectKind::TimeDelay => d.time_delay_s,
            EffectKind::Lowpass => d.lowpass_hz,
            EffectKind::GainError => d.gain_factor,
            EffectKind::HystereticDamping => d.loss_factor,
            EffectKind::ViscousFriction => d.viscous_friction,
            EffectKind::PreSlidingFriction => d.pre_sliding_stiffness,
            EffectKind::CoulombFriction
            | EffectKind::Backlash
            | EffectKind::Offset
            | EffectKind::ExtraMode
            | EffectKind::None => Complex64::new(0.0, 0.0),
        }
    }

    /// The value already in `base`, if any.
    fn current(self, base: &Effects) -> Option<f64> {
        match self {
            EffectKind::TimeDelay => base.time_delay_s,
            EffectKind::Lowpass => base.lowpass_hz,
            EffectKind::GainError => base.gain_factor,
            EffectKind::HystereticDamping => base.loss_factor,
            EffectKind::ViscousFriction => base.viscous_friction,
            EffectKind::PreSlidingFriction => base.pre_sliding_stiffness,
            EffectKind::CoulombFriction => base.coulomb_friction,
            EffectKind::Backlash => base.backlash_gap,
            EffectKind::Offset => base.offset_force,
            EffectKind::ExtraMode | EffectKind::None => None,
        }
    }
}

/// A frequency band where the calibrated model misses the data by more
/// than the noise explains.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Band {
    /// Lowest line of the band, Hz.
    pub f_lo_hz: f64,
    /// Highest line of the band, Hz.
    pub f_hi_hz: f64,
    /// RMS of `20 log10 |G_rec / G_model|` over the band's lines.
    pub rms_db: f64,
    /// RMS of the wrapped phase difference over the band's lines.
    pub rms_deg: f64,
}

/// One hypothesis's outcome.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectVerdict {
    /// Which effect.
    pub kind: EffectKind,
    /// Its fitted parameter (empty for `none`).
    pub parameters: BTreeMap<String, f64>,
    /// The figures it was scored on.
    pub evidence: Evidence,
    /// BIC improvement over the calibrated model without it, less the
    /// margin: positive means kept. For an effect added to others (`step`
    /// 2 and up), the improvement over the model with those others; with
    /// [`Selection::Holdout`], the drop of the held-out cost less the
    /// margin.
    pub score: f64,
    /// Forward selection: 1 for the best single effect, 2 for the effect
    /// added to it, and so on; the kept effects are fitted jointly in
    /// `model_after`. For a rejected hypothesis, the step at which it
    /// failed; 0 for `none`.
    pub step: usize,
    /// Not kept although its score may be positive: the band cannot
    /// resolve it (see [`Unresolved`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unresolved: Option<Unresolved>,
    /// The standard error of each of `parameters` (where one is known),
    /// from the fit's Jacobian with the noise level the residual shows
    /// and its correlation across lines or samples.
    #[serde(skip_serializing_if = "BTreeMap::is_empty", default)]
    pub standard_errors: BTreeMap<String, f64>,
}

/// Why the data cannot resolve a hypothesis that lowers the cost: it does
/// not earn its parameters, whatever its score.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Unresolved {
    /// Within the band it cannot be told apart from this kept effect. A
    /// first-order lag whose corner lies above the band shows there as a
    /// dead time of `1 / (2 pi f_c)` plus a droop at the band's top that
    /// a chain's parameter error also makes, so the data cannot split the
    /// phase lag between the two.
    LikeKept(EffectKind),
    /// What the effect acts through lies outside the band (Hz): the mode
    /// an extra mass adds, the corner of a lag far above the band, the
    /// resonance a pre-sliding spring makes above it. The band sees only
    /// a tail of it, which a chain's parameter error also makes.
    OutsideBand(f64),
    /// A parameter of the effect lies at the bound of its search range:
    /// the fit asks for more than a physical value, or for nothing.
    AtBound {
        /// The parameter (an extra mass's new mass, spring or damper by
        /// its name in the extended chain).
        parameter: String,
        /// Its value.
        value: f64,
    },
    /// The value at which the effect is absent (no delay, a corner at
    /// infinity, a factor of 1, no damping, no spring) lies within three
    /// standard errors of the estimate.
    WithinUncertainty {
        /// The parameter.
        parameter: String,
        /// The estimate's distance from the absent value, in standard
        /// errors.
        sigmas: f64,
    },
    /// The resonance and antiresonance an extra mass adds lie closer
    /// together than three standard errors of their separation: a nearly
    /// cancelled pole-zero pair that fits noise, not a mode.
    PoleOnZero {
        /// `|ln(f_resonance / f_antiresonance)|`.
        separation: f64,
        /// Its standard error.
        standard_error: f64,
    },
    /// The chain without the extra mass, refitted from the extended
    /// chain's values with the mass merged back into its neighbours,
    /// predicts the held-out lines within the price of the mass's
    /// parameters: the mass only moved the calibration to a better fit
    /// of the chain that was there, it adds no mode of its own.
    MergedChainFits {
        /// What the extra mass still gains over the merged chain, in the
        /// units of the selection's evidence.
        gain: f64,
    },
}

/// How many standard errors an effect's estimate must lie from the value
/// at which it is absent, and an extra mode's resonance from its
/// antiresonance, for the effect to be named.
pub const SIGNIFICANCE_SIGMAS: f64 = 3.0;

/// RMS errors of a model against the recording.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FitSummary {
    /// RMS over the lines of `20 log10 |G_rec / G_model|`, dB.
    pub rms_db: f64,
    /// RMS over the lines of the wrapped phase difference, degrees.
    pub rms_deg: f64,
}

/// Before and after (the JSON `fit` object), in whichever figures the
/// diagnosis measures: [`FitSummary`] on an FRF, the time-domain
/// diagnosis's [`crate::nonlinear::TimeFit`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BeforeAfter<T = FitSummary> {
    /// The calibrated model without a new effect.
    pub before: T,
    /// The model after the kept effects (equal to `before` if none).
    pub after: T,
}

/// The result of [`diagnose`]: `mismatch`, `effects`, `rejected`, `fit`,
/// `calibration`, `noise`, `model_after`, `held_out` in JSON.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Bands of the calibrated residual beyond the noise, in frequency order.
    pub mismatch: Vec<Band>,
    /// Kept effects, best first; `[none]` if nothing is missing.
    pub effects: Vec<EffectVerdict>,
    /// Hypotheses that did not earn their parameter, best first.
    pub rejected: Vec<EffectVerdict>,
    /// Before (calibrated) and after (best effect) errors.
    pub fit: BeforeAfter,
    /// Evidence from the calibration: parameters pinned at their bounds,
    /// a common scale of all parameters.
    pub calibration: Vec<CalibrationNote>,
    /// The noise level per real/imaginary part of the log error (median
    /// over the lines), nepers.
    pub noise: f64,
    /// The model after the diagnosis: calibrated parameters and the best
    /// kept effect added to the input's effects.
    #[serde(serialize_with = "ser_model")]
    pub model_after: ModelFile,
    /// With [`Selection::Holdout`]: the prediction error on the held-out
    /// lines before and after the kept effects.
    pub held_out: Option<HeldOut>,
    /// The calibrated model: the input model with its parameters fitted
    /// and no effect added (where the time domain starts).
    #[serde(skip)]
    pub calibrated: ModelFile,
    /// Copy of `fit.before`, for Rust callers.
    #[serde(skip)]
    pub before: FitSummary,
    /// Copy of `fit.after`, for Rust callers.
    #[serde(skip)]
    pub after: FitSummary,
}

/// The prediction error on lines left out of every fit, in noise units:
/// `sum |e_k|^2 / sigma_k^2` over those lines (real and imaginary parts),
/// which noise alone puts near `2 lines`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HeldOut {
    /// Lines held out.
    pub lines: usize,
    /// The calibrated model's cost on them.
    pub before: f64,
    /// The cost of the model after the diagnosis.
    pub after: f64,
    /// The held-out residuals (real and imaginary parts) counted as
    /// independent ([`frf::welch::effective_samples`] of the model after's
    /// residual along the held-out lines): a residual that is still a
    /// smooth curve (a model error, a bias of the estimate) has far fewer
    /// independent values than lines.
    pub effective_lines: f64,
}

impl HeldOut {
    /// The drop of the held-out prediction error, `-2 ln` of the
    /// likelihood ratio with the noise level profiled out: each line's
    /// measured uncertainty fixes the lines' relative weights, and the
    /// scale is what the residual shows, so an uncertainty that leaves
    /// out a bias does not inflate the evidence. The same figure as the
    /// time domain's ([`crate::nonlinear::TimeHeldOut::evidence`]).
    pub fn evidence(&self) -> f64 {
        profiled_gain(self.before, self.after, self.effective_lines)
    }
}

/// `n ln(before / after)`: the drop of a sum of squares from `before` to
/// `after` in noise units with the noise level profiled out, for `n`
/// independent residuals (0 when either is not positive).
pub(crate) fn profiled_gain(before: f64, after: f64, n: f64) -> f64 {
    if before > 0.0 && after > 0.0 && before.is_finite() && after.is_finite() {
        n * (before / after).ln()
    } else {
        0.0
    }
}

pub(crate) fn ser_model<S: serde::Serializer>(m: &ModelFile, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut parameters = BTreeMap::new();
    for (k, v) in m.parameters.iter() {
        parameters.insert(k.to_string(), v);
    }
    // The sections of the model file's `[effects]` table, where both
    // frictions share `friction`.
    let mut effects: BTreeMap<&str, BTreeMap<&str, f64>> = BTreeMap::new();
    for kind in EffectKind::WITH_PARAMETER {
        if let (Some(v), Some(name)) = (kind.current(&m.effects), kind.parameter_name()) {
            effects
                .entry(kind.model_file_section())
                .or_default()
                .insert(name, v);
        }
    }
    let mut map = s.serialize_map(Some(5))?;
    map.serialize_entry("structure", &m.model.id())?;
    map.serialize_entry("output", m.output.as_str())?;
    map.serialize_entry("gain", &m.gain)?;
    map.serialize_entry("parameters", &parameters)?;
    map.serialize_entry("effects", &effects)?;
    map.end()
}

/// Why a diagnosis cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DiagnoseError {
    /// The model cannot be evaluated (bad parameters, a singular line).
    #[error(transparent)]
    Response(#[from] ResponseError),
    /// A line where the recording is zero or not finite.
    #[error("the recording is zero or not finite at {0} Hz")]
    BadLine(f64),
    /// A nominal parameter that is not positive and finite.
    #[error("nominal parameter {0} must be positive and finite")]
    Parameter(String),
    /// Too few lines for the parameters.
    #[error("{lines} lines for {parameters} parameters")]
    TooFewLines {
        /// Lines of the recording.
        lines: usize,
        /// Parameters to fit.
        parameters: usize,
    },
    /// Options out of range.
    #[error("invalid option: {0}")]
    Options(String),
    /// A simulated FRF that no chain model reproduces
    /// ([`model_from_simulation`]).
    #[error("{0}")]
    Simulation(String),
}

/// How closely the model found by [`model_from_simulation`] must reproduce
/// the simulated FRF: RMS of the complex log error in dB-equivalent (the
/// identification's `score_db`). A noise-free simulation of a chain is
/// fitted far closer than this; a looser fit means the simulation is not
/// a chain model of this library.
pub const SIMULATION_TOLERANCE_DB: f64 = 0.05;

/// The chain model behind a simulated, noise-free FRF (`mms diagnose
/// --simulation`): [`crate::identify::identify`] on the simulation, first
/// with the gain known (SI units), then with the gain fitted; the best
/// candidate is taken if it reproduces the simulation within
/// [`SIMULATION_TOLERANCE_DB`], else the error says how close it came.
///
/// ```
/// use ident::diagnose::model_from_simulation;
/// use ident::synth::{synthetic, SynthOptions};
/// use mms::response::ChainResponse;
/// use mms::xorshift::XorShift;
/// use mms::Model;
///
/// let a2 = Model::from_id("A2")?;
/// let s = synthetic(&mut XorShift::new(2), Some(a2), &SynthOptions::default())?;
/// let m = model_from_simulation(&s.frf, s.output)?;
/// // The model's FRF is the simulation's, within the stated tolerance.
/// let g = ChainResponse::new(&m.model, m.output);
/// for (&f, &h) in s.frf.freq_hz().iter().zip(s.frf.response()) {
///     let e = (g.eval(m.parameters.values(), f)? * m.gain / h).ln();
///     assert!(e.norm() < 0.05);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn model_from_simulation(sim: &Frf, output: mms::Output) -> Result<ModelFile, DiagnoseError> {
    use crate::identify::{identify, IdentifyOptions};
    let mut closest: Option<(String, f64)> = None;
    for gain in [crate::fit::Gain::Known(1.0), crate::fit::Gain::Fit(1.0)] {
        let options = IdentifyOptions {
            gain,
            ..IdentifyOptions::default()
        };
        let id = identify(sim, output, &options)
            .map_err(|e| DiagnoseError::Simulation(format!("cannot identify a model: {e}")))?;
        let Some(best) = id.candidates.first() else {
            continue;
        };
        if best.score_db <= SIMULATION_TOLERANCE_DB {
            return Ok(ModelFile {
                model: best.model,
                output,
                parameters: best.fit.parameters.clone(),
                gain: best.fit.gain,
                motion: mms::model_file::Motion::Translational,
                effects: Effects::default(),
            });
        }
        if closest.as_ref().is_none_or(|c| best.score_db < c.1) {
            closest = Some((best.id.clone(), best.score_db));
        }
    }
    Err(DiagnoseError::Simulation(match closest {
        Some((id, db)) => format!(
            "no chain model reproduces the simulation within {SIMULATION_TOLERANCE_DB} dB \
             (closest: {id}, {db:.3} dB); give a model file with --model instead"
        ),
        None => "no chain model fits the simulation; give a model file with --model instead".into(),
    }))
}

/// The lines of one output in a [`Problem`]: the chain read at that
/// output's sensor, and the end of its lines (they follow the previous
/// output's).
#[derive(Clone, Debug)]
struct Segment {
    chain: mms::Model,
    end: usize,
}

/// The fitting problem shared by the calibration and every hypothesis.
/// Its lines are those of one output, or of several one after another,
/// each compared with the chain read at its own sensor ([`Segment`]); the
/// parameters and effects are one set for all.
#[derive(Clone)]
struct Problem<'a> {
    /// The model; its chain is the first output's.
    file: ModelFile,
    segments: Vec<Segment>,
    freq: &'a [f64],
    data: &'a [Complex64],
    /// `1 / sigma_k` per line in the fits (zero on held-out lines).
    inv_sigma: Vec<f64>,
    /// `1 / sigma_k` on the held-out lines, zero elsewhere (all zero
    /// without held-out validation).
    test_sigma: Vec<f64>,
    nominal_ln: Vec<f64>,
    /// `1 / tau` of each parameter's log prior.
    prior: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

/// A fitted state: log-parameters (and the effect's log-value), cost.
#[derive(Clone, Debug)]
struct State {
    x: Vec<f64>,
    /// Noise-normalised data cost plus prior cost.
    cost: f64,
}

impl Problem<'_> {
    fn np(&self) -> usize {
        self.nominal_ln.len()
    }

    /// The prior's residual rows: each log-parameter's distance from its
    /// nominal value in prior standard deviations.
    fn prior_rows<'b>(&'b self, x: &'b [f64]) -> impl Iterator<Item = f64> + 'b {
        x.iter()
            .zip(&self.nominal_ln)
            .zip(&self.prior)
            .map(|((x, n), w)| (x - n) * w)
    }

    /// The effects at state `x` with the effects `kinds` (their
    /// log-values follow the chain's parameters in `x`, in this order).
    fn effects(&self, kinds: &[EffectKind], x: &[f64]) -> Effects {
        kinds
            .iter()
            .enumerate()
            .fold(self.file.effects, |e, (i, k)| {
                k.apply(&e, x[self.np() + i].exp())
            })
    }

    /// The held-out cost at state `x`: `sum |e_k / sigma_k|^2` over the
    /// held-out lines.
    fn test_cost(&self, kinds: &[EffectKind], x: &[f64]) -> Result<f64, ResponseError> {
        Ok(self
            .errors(kinds, x)?
            .iter()
            .zip(&self.test_sigma)
            .map(|(e, w)| e.norm_sqr() * w * w)
            .sum())
    }

    /// The held-out residuals at `x` counted as independent
    /// ([`HeldOut::effective_lines`]).
    fn held_out_count(&self, kinds: &[EffectKind], x: &[f64]) -> f64 {
        let Ok(e) = self.errors(kinds, x) else {
            return 0.0;
        };
        let (re, im): (Vec<f64>, Vec<f64>) = e
            .iter()
            .zip(&self.test_sigma)
            .filter(|(_, &w)| w > 0.0)
            .map(|(e, w)| (e.re * w, e.im * w))
            .unzip();
        effective_samples(&re) + effective_samples(&im)
    }

    /// The covariance of the state `x` (log-parameters, then the effects'
    /// log-values), row-major: the inverse of the Gauss-Newton matrix,
    /// the data's part divided by the noise level the fitted residual
    /// shows (at least the one its uncertainty gives: that is a floor,
    /// which leaves out bias) and by the residual's correlation along the
    /// lines (a smooth misfit carries less information than as many
    /// independent errors: [`frf::welch::effective_samples`]), the prior's
    /// part as it is. `None` where the matrix is singular.
    fn covariance(&self, kinds: &[EffectKind], x: &[f64]) -> Option<Vec<f64>> {
        let nx = x.len();
        let mut jac = Vec::new();
        let r = self.residuals(kinds, x, Some(&mut jac)).ok()?;
        let fitted: Vec<usize> = (0..self.freq.len())
            .filter(|&k| self.inv_sigma[k] > 0.0)
            .collect();
        let m = 2 * fitted.len();
        if m <= nx {
            return None;
        }
        let ss: f64 = fitted
            .iter()
            .map(|&k| r[2 * k].powi(2) + r[2 * k + 1].powi(2))
            .sum();
        let scale = (ss / (m - nx) as f64).max(1.0);
        let re: Vec<f64> = fitted.iter().map(|&k| r[2 * k]).collect();
        let im: Vec<f64> = fitted.iter().map(|&k| r[2 * k + 1]).collect();
        let independent = (effective_samples(&re) + effective_samples(&im)).max(1.0);
        let inflate = (m as f64 / independent).max(1.0);
        // The data's information, discounted by the noise level and the
        // correlation the residual shows; the prior's as it is (it says
        // how far the parameters are known, whatever the data).
        let rows = 2 * self.freq.len();
        let (data, _) = crate::fit::normal_equations(&jac[..rows * nx], &r[..rows], nx);
        let (prior, _) = crate::fit::normal_equations(&jac[rows * nx..], &r[rows..], nx);
        let a: Vec<f64> = data
            .iter()
            .zip(&prior)
            .map(|(d, p)| d / (scale * inflate) + p)
            .collect();
        let mut cov = vec![0.0; nx * nx];
        for j in 0..nx {
            let mut unit = vec![0.0; nx];
            unit[j] = 1.0;
            let col = solve_spd(&a, &unit, nx)?;
            for i in 0..nx {
                cov[i * nx + j] = col[i];
            }
        }
        Some(cov)
    }

    /// Unweighted log errors `ln(G/H)` at state `x`.
    fn errors(&self, kinds: &[EffectKind], x: &[f64]) -> Result<Vec<Complex64>, ResponseError> {
        let p: Vec<f64> = x[..self.np()].iter().map(|v| v.exp()).collect();
        let effects = self.effects(kinds, x);
        let mut out = Vec::with_capacity(self.freq.len());
        for (s, lines) in self.segment_lines() {
            let r = ChainResponse::with_effects(&s.chain, self.file.output, &effects);
            for k in lines {
                out.push(log_error(
                    r.eval(&p, self.freq[k])? * self.file.gain / self.data[k],
                ));
            }
        }
        Ok(out)
    }

    /// Each output's segment and its line indices.
    fn segment_lines(&self) -> impl Iterator<Item = (&Segment, std::ops::Range<usize>)> {
        self.segments.iter().scan(0, |start, s| {
            let lines = *start..s.end;
            *start = s.end;
            Some((s, lines))
        })
    }

    /// Weighted residuals (data rows, then prior rows) and, if asked, the
    /// Jacobian with respect to `x` (row-major).
    fn residuals(
        &self,
        kinds: &[EffectKind],
        x: &[f64],
        jac: Option<&mut Vec<f64>>,
    ) -> Result<Vec<f64>, ResponseError> {
        let np = self.np();
        let nx = x.len();
        let p: Vec<f64> = x[..np].iter().map(|v| v.exp()).collect();
        let effects = self.effects(kinds, x);
        let mut r = Vec::with_capacity(2 * self.freq.len() + np);
        let Some(jac) = jac else {
            for (s, lines) in self.segment_lines() {
                let resp = ChainResponse::with_effects(&s.chain, self.file.output, &effects);
                for k in lines {
                    let e = log_error(resp.eval(&p, self.freq[k])? * self.file.gain / self.data[k]);
                    r.push(self.inv_sigma[k] * e.re);
                    r.push(self.inv_sigma[k] * e.im);
                }
            }
            r.extend(self.prior_rows(x));
            return Ok(r);
        };
        // The effects' columns from the same solves as the chain's:
        // d ln G / d ln v = v (dG/dv) / G.
        let values: Vec<f64> = (0..kinds.len()).map(|i| x[np + i].exp()).collect();
        jac.clear();
        jac.reserve((2 * self.freq.len() + np) * nx);
        let mut grad = vec![Complex64::new(0.0, 0.0); np];
        for (s, lines) in self.segment_lines() {
            let resp = ChainResponse::with_effects(&s.chain, self.file.output, &effects);
            for k in lines {
                let (f, h, w) = (self.freq[k], self.data[k], self.inv_sigma[k]);
                let (g, de) = resp.eval_with_effect_gradient(&p, f, &mut grad)?;
                let e = log_error(g * self.file.gain / h);
                r.push(w * e.re);
                r.push(w * e.im);
                let base = jac.len();
                jac.resize(base + 2 * nx, 0.0);
                for i in 0..np {
                    // d ln G / d ln p = p (dG/dp) / G.
                    let d = grad[i] * p[i] / g;
                    jac[base + i] = w * d.re;
                    jac[base + nx + i] = w * d.im;
                }
                for (i, (kind, v)) in kinds.iter().zip(&values).enumerate() {
                    let d = kind.derivative(&de) * *v / g;
                    jac[base + np + i] = w * d.re;
                    jac[base + nx + np + i] = w * d.im;
                }
            }
        }
        r.extend(self.prior_rows(x));
        for i in 0..np {
            let base = jac.len();
            jac.resize(base + nx, 0.0);
            jac[base + i] = self.prior[i];
        }
        Ok(r)
    }

    /// Levenberg-Marquardt from `x0` with `x` clamped to `[lo, hi]` after
    /// every step (the effects' bounds appended for a hypothesis).
    fn fit(
        &self,
        kinds: &[EffectKind],
        x0: Vec<f64>,
        lo: &[f64],
        hi: &[f64],
        max_iterations: usize,
    ) -> Result<State, ResponseError> {
        let nx = x0.len();
        let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
        let mut x = x0;
        let mut jac = Vec::new();
        let mut r = self.residuals(kinds, &x, Some(&mut jac))?;
        let mut c = cost(&r);
        let mut lambda = 1e-3;
        for _ in 0..max_iterations {
            let (a, g) = crate::fit::normal_equations(&jac, &r, nx);
            let mut accepted = None;
            while lambda < 1e12 {
                let mut m = a.clone();
                for i in 0..nx {
                    m[i * nx + i] += lambda * a[i * nx + i].max(1e-12);
                }
                let Some(step) = solve_spd(&m, &g, nx) else {
                    lambda *= 4.0;
                    continue;
                };
                let trial: Vec<f64> = (0..nx)
                    .map(|i| (x[i] - step[i]).clamp(lo[i], hi[i]))
                    .collect();
                match self.residuals(kinds, &trial, None) {
                    Ok(tr) if cost(&tr) < c => {
                        accepted = Some((trial, cost(&tr)));
                        lambda = (lambda / 3.0).max(1e-9);
                        break;
                    }
                    _ => lambda *= 4.0,
                }
            }
            let Some((trial, tc)) = accepted else { break };
            let drop = c - tc;
            let rel = drop / c.max(f64::MIN_POSITIVE);
            x = trial;
            r = self.residuals(kinds, &x, Some(&mut jac))?;
            c = cost(&r);
            // A step that gains less than 1e-3 noise units (or a relative
            // 1e-9) is far below any difference the selection looks at.
            if rel < 1e-6 || drop < 1e-3 {
                break;
            }
        }
        Ok(State { x, cost: c })
    }
}

/// Robust noise level of log errors: the median absolute second
/// difference, pooled over the real and imaginary parts, scaled to a
/// standard deviation (`1.4826 MAD`, `var` of a second difference `6
/// sigma^2`).
fn scatter(e: &[Complex64]) -> f64 {
    let mut d: Vec<f64> = e
        .windows(3)
        .flat_map(|w| {
            let s = w[2] - 2.0 * w[1] + w[0];
            [s.re.abs(), s.im.abs()]
        })
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    d.sort_by(f64::total_cmp);
    1.4826 * d[d.len() / 2] / 6f64.sqrt()
}

pub(crate) fn summary(e: &[Complex64]) -> FitSummary {
    let n = e.len().max(1) as f64;
    FitSummary {
        rms_db: (e.iter().map(|z| z.re * z.re).sum::<f64>() / n).sqrt() * 20.0 / LN_10,
        rms_deg: (e.iter().map(|z| z.im * z.im).sum::<f64>() / n)
            .sqrt()
            .to_degrees(),
    }
}

/// Bands of `e` (log errors; `sigma` per line) whose smoothed normalised
/// cost exceeds the threshold.
pub(crate) fn bands(
    freq: &[f64],
    e: &[Complex64],
    sigma: &[f64],
    o: &DiagnoseOptions,
) -> Vec<Band> {
    let n = e.len();
    let z: Vec<f64> = e
        .iter()
        .zip(sigma)
        .map(|(e, s)| e.norm_sqr() / (2.0 * s * s))
        .collect();
    let half = o.band_window / 2;
    let mut prefix = vec![0.0; n + 1];
    for k in 0..n {
        prefix[k + 1] = prefix[k] + z[k];
    }
    let above: Vec<bool> = (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(half), (k + half + 1).min(n));
            (prefix[b] - prefix[a]) / (b - a) as f64 > o.band_threshold
        })
        .collect();
    // Runs above the threshold, merged across gaps shorter than the window
    // (one noisy dip inside a band does not split it).
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    while k < n {
        if !above[k] {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && above[k] {
            k += 1;
        }
        match runs.last_mut() {
            Some(last) if start - last.1 <= o.band_window => last.1 = k,
            _ => runs.push((start, k)),
        }
    }
    runs.into_iter()
        .filter(|(a, b)| b - a >= o.min_band_lines)
        .map(|(a, b)| {
            let s = summary(&e[a..b]);
            Band {
                f_lo_hz: freq[a],
                f_hi_hz: freq[b - 1],
                rms_db: s.rms_db,
                rms_deg: s.rms_deg,
            }
        })
        .collect()
}

/// Diagnoses what `model` misses of `data`; see the module docs.
pub fn diagnose(
    data: &Frf,
    model: &ModelFile,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    diagnose_outputs(
        &[OutputFrf {
            frf: data,
            chain: model.model,
        }],
        model,
        options,
    )
}

/// One output of [`diagnose_outputs`]: its FRF and the model's chain read
/// at that output's sensor.
#[derive(Clone, Copy, Debug)]
pub struct OutputFrf<'a> {
    /// The output's FRF (the lines to compare).
    pub frf: &'a Frf,
    /// The model's chain with this output's sensor.
    pub chain: mms::Model,
}

/// Diagnoses what `model` misses of several outputs of one recording at
/// once: one parameter set and one set of effects for all, each output
/// compared with the chain read at its own sensor, every line weighted by
/// its own uncertainty (or, without one, by its output's residual scatter).
/// An effect is named when it earns its parameters on all outputs
/// together. The mismatch bands are the first output's.
///
/// ```
/// use frf::Frf;
/// use ident::diagnose::{diagnose_outputs, DiagnoseOptions, OutputFrf};
/// use mms::model_file::ModelFile;
/// use mms::response::{ChainResponse, Effects};
/// use mms::{Model, Output, Port};
///
/// // A free two-mass drive read at the motor and at the load, both with a
/// // dead time of 1 ms that the model lacks.
/// let text = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
///             output = \"position\"\n[parameters]\nm1 = 0.02\nm2 = 0.05\n\
///             c12 = 3000\nd12 = 0.2\n";
/// let model = ModelFile::parse(text)?;
/// let load = Model::new(2, 0, Port::new(1, 0), Port::new(2, 0))?;
/// let delay = Effects { time_delay_s: Some(1e-3), ..Effects::default() };
/// let f: Vec<f64> = (0..300).map(|k| 5.0 * 1.012f64.powi(k)).collect();
/// let frf = |m: &Model| -> Result<Frf, Box<dyn std::error::Error>> {
///     let r = ChainResponse::with_effects(m, Output::Position, &delay);
///     let h = f.iter().map(|&f| r.eval(model.parameters.values(), f)).collect::<Result<_, _>>()?;
///     Ok(Frf::new(f.clone(), h, None)?)
/// };
/// let (motor, at_load) = (frf(&model.model)?, frf(&load)?);
/// let d = diagnose_outputs(
///     &[
///         OutputFrf { frf: &motor, chain: model.model },
///         OutputFrf { frf: &at_load, chain: load },
///     ],
///     &model,
///     &DiagnoseOptions::default(),
/// )?;
/// assert_eq!(d.effects[0].kind.as_str(), "time_delay");
/// assert!((d.effects[0].parameters["delay_s"] / 1e-3 - 1.0).abs() < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn diagnose_outputs(
    outputs: &[OutputFrf],
    model: &ModelFile,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let o = options;
    if outputs.is_empty() {
        return Err(DiagnoseError::Options("no output to compare".into()));
    }
    for out in outputs {
        let c = &out.chain;
        if (c.n_masses(), c.gap(), c.actuator())
            != (
                model.model.n_masses(),
                model.model.gap(),
                model.model.actuator(),
            )
        {
            return Err(DiagnoseError::Options(format!(
                "output chain {} is not the model's chain {} read at another sensor",
                c.id(),
                model.model.id()
            )));
        }
    }
    for (name, ok) in [
        ("tolerance", o.tolerance > 0.0 && o.tolerance.is_finite()),
        (
            "damper_tolerance",
            o.damper_tolerance > 0.0 && o.damper_tolerance.is_finite(),
        ),
        ("averages", o.averages >= 1.0 && o.averages.is_finite()),
        ("band_window", o.band_window >= 1),
        ("band_threshold", o.band_threshold.is_finite()),
        ("margin", o.margin.is_finite()),
    ] {
        if !ok {
            return Err(DiagnoseError::Options(name.into()));
        }
    }
    if !(model.gain.is_finite() && model.gain != 0.0) {
        return Err(DiagnoseError::Options(format!("model gain {}", model.gain)));
    }
    // Lines the excitation did not reach (an infinite standard deviation:
    // between the lines of an odd or a band-limited multisine) carry no
    // information: they belong to no comparison, and go before the
    // held-out lines are chosen, which would otherwise be unexcited ones.
    let mut excited: Vec<Option<Frf>> = Vec::with_capacity(outputs.len());
    for out in outputs {
        let Some(sd) = out
            .frf
            .std_dev()
            .filter(|sd| sd.iter().any(|v| !v.is_finite()))
        else {
            excited.push(None);
            continue;
        };
        let keep: Vec<usize> = (0..sd.len()).filter(|&k| sd[k].is_finite()).collect();
        match out.frf.lines(&keep) {
            Some(f) => excited.push(Some(f)),
            None => {
                return Err(DiagnoseError::TooFewLines {
                    lines: 0,
                    parameters: model.model.parameters().len() + 1,
                })
            }
        }
    }
    let kept: Vec<OutputFrf> = outputs
        .iter()
        .zip(&excited)
        .map(|(out, e)| OutputFrf {
            frf: e.as_ref().unwrap_or(out.frf),
            chain: out.chain,
        })
        .collect();
    let outputs = &kept[..];
    let freq_all: Vec<f64> = outputs
        .iter()
        .flat_map(|out| out.frf.freq_hz().iter().copied())
        .collect();
    let h_all: Vec<Complex64> = outputs
        .iter()
        .flat_map(|out| out.frf.response().iter().copied())
        .collect();
    let segments: Vec<Segment> = outputs
        .iter()
        .scan(0, |end, out| {
            *end += out.frf.len();
            Some(Segment {
                chain: out.chain,
                end: *end,
            })
        })
        .collect();
    let (freq, h) = (&freq_all[..], &h_all[..]);
    if let Some(k) = h
        .iter()
        .position(|z| !(z.norm() > 0.0 && z.norm().is_finite()))
    {
        return Err(DiagnoseError::BadLine(freq[k]));
    }
    let names = model.model.parameters();
    let np = names.len();
    if freq.len() < np + 2 {
        return Err(DiagnoseError::TooFewLines {
            lines: freq.len(),
            parameters: np + 1,
        });
    }
    let mut nominal_ln = Vec::with_capacity(np);
    for (name, v) in model.parameters.iter() {
        if !(v > 0.0 && v.is_finite()) {
            return Err(DiagnoseError::Parameter(name.to_string()));
        }
        nominal_ln.push(v.ln());
    }
    let n_undamped = model.model.n_masses() + model.model.springs().len();
    let width: Vec<f64> = (0..np)
        .map(|i| {
            if i < n_undamped {
                o.tolerance.ln_1p()
            } else {
                o.damper_tolerance.ln_1p()
            }
        })
        .collect();
    let holdout = o.selection == Selection::Holdout;
    // Held-out lines (zero weight in every fit) for Selection::Holdout.
    let held: Vec<bool> = (0..freq.len())
        .map(|k| holdout && k % HOLDOUT_EVERY == HOLDOUT_EVERY - 1)
        .collect();
    let mut problem = Problem {
        file: model.clone(),
        segments: segments.clone(),
        freq,
        data: h,
        inv_sigma: vec![1.0; freq.len()],
        test_sigma: vec![0.0; freq.len()],
        lo: nominal_ln.iter().zip(&width).map(|(v, w)| v - w).collect(),
        hi: nominal_ln.iter().zip(&width).map(|(v, w)| v + w).collect(),
        // The prior's standard deviation is half the tolerance: the bound
        // is its two-sigma point.
        prior: width.iter().map(|w| 2.0 / w).collect(),
        nominal_ln: nominal_ln.clone(),
    };
    within_physical_ranges(&names, &mut problem.lo, &mut problem.hi);

    // Noise: each line's own uncertainty (its standard deviation, else its
    // coherence and the averages), else the scatter of the nominal
    // residual, then again of the calibrated one (a badly wrong nominal
    // model can have sharp residual features at its resonances).
    // Output by output: the noise of two sensors need not be alike.
    let measured_sigma: Vec<Option<Vec<f64>>> = outputs
        .iter()
        .map(|out| {
            let data = out.frf;
            (data.std_dev().is_some() || data.coherence().is_some()).then(|| {
                frf::uncertainty::line_uncertainty(data, Some(o.averages))
                    .relative
                    .iter()
                    .map(|s| s.max(1e-6))
                    .collect()
            })
        })
        .collect();
    let set_sigma = |p: &mut Problem, e: &[Complex64]| -> Vec<f64> {
        let mut sigma = Vec::with_capacity(e.len());
        let mut start = 0;
        for (seg, measured) in segments.iter().zip(&measured_sigma) {
            match measured {
                Some(s) => sigma.extend_from_slice(s),
                None => sigma.extend(std::iter::repeat_n(
                    scatter(&e[start..seg.end]).max(1e-6),
                    seg.end - start,
                )),
            }
            start = seg.end;
        }
        p.inv_sigma = sigma
            .iter()
            .zip(&held)
            .map(|(s, &out)| if out { 0.0 } else { 1.0 / s })
            .collect();
        p.test_sigma = sigma
            .iter()
            .zip(&held)
            .map(|(s, &out)| if out { 1.0 / s } else { 0.0 })
            .collect();
        sigma
    };
    let e0 = problem.errors(&[], &nominal_ln)?;
    set_sigma(&mut problem, &e0);
    let (lo, hi) = (problem.lo.clone(), problem.hi.clone());
    let first = problem.fit(&[], nominal_ln.clone(), &lo, &hi, o.max_iterations)?;
    let e1 = problem.errors(&[], &first.x)?;
    let sigma = set_sigma(&mut problem, &e1);
    let calibrated = problem.fit(&[], first.x, &lo, &hi, o.max_iterations)?;
    let e_before = problem.errors(&[], &calibrated.x)?;
    let before = summary(&e_before);
    let first_lines = segments[0].end;
    let mismatch = bands(
        &freq[..first_lines],
        &e_before[..first_lines],
        &sigma[..first_lines],
        o,
    );

    let mut calibration = Vec::new();
    for i in 0..np {
        let d = calibrated.x[i] - nominal_ln[i];
        if d.abs() > 0.999 * width[i] {
            calibration.push(CalibrationNote::Pinned {
                parameter: names[i].clone(),
                upper: d > 0.0,
                value: calibrated.x[i].exp(),
                nominal: nominal_ln[i].exp(),
            });
        }
    }
    let common = (0..np)
        .map(|i| calibrated.x[i] - nominal_ln[i])
        .sum::<f64>()
        / np as f64;
    if common.abs() > 0.5 * o.tolerance.ln_1p() {
        calibration.push(CalibrationNote::CommonFactor {
            factor: common.exp(),
        });
    }

    // Hypotheses, by forward selection: the best single effect, then each
    // remaining effect added to those kept, each kept only if it earns its
    // parameters by the same criterion.
    let f_lo = freq.iter().cloned().fold(f64::INFINITY, f64::min);
    let f_hi = freq.iter().cloned().fold(0.0, f64::max);
    let ctx = Context {
        o,
        rows: 2.0 * held.iter().filter(|&&out| !out).count() as f64,
        held: held.iter().filter(|&&out| out).count().max(1),
        f_lo,
        f_hi,
        total_mass: (0..model.model.n_masses())
            .map(|i| calibrated.x[i].exp())
            .sum(),
        input: &model.effects,
        original: (&model.model, &calibrated.x[..np]),
    };
    let test_cost = problem.test_cost(&[], &calibrated.x)?;
    let test_before = test_cost;
    let calibrated_file = ModelFile {
        parameters: Parameters::from_values(
            &model.model,
            calibrated.x[..np].iter().map(|v| v.exp()).collect(),
        )?,
        ..model.clone()
    }
    .within_ranges();
    let start = Fitted {
        problem,
        kinds: Vec::new(),
        extended: false,
        state: calibrated.clone(),
        test_cost,
    };
    // Forward selection, then every kept effect must stand out of its
    // uncertainty in the joint fit (where one effect no longer masks
    // another); the first that does not is barred and the selection
    // runs again without it.
    let mut barred: Vec<EffectVerdict> = Vec::new();
    let selected = loop {
        let selected = select_effects(&start, &ctx, o, holdout, &barred)?;
        let failing = selected.kept.iter().find_map(|v| {
            let why = significance(v.kind, &selected.state, &ctx, true)
                .1
                .or_else(|| {
                    (v.kind == EffectKind::ExtraMode)
                        .then(|| merged_chain_fits(&start, &selected.state, &ctx))
                        .flatten()
                });
            why.map(|why| EffectVerdict {
                parameters: selected.state.parameters(v.kind, &ctx),
                unresolved: Some(why),
                ..v.clone()
            })
        });
        match failing {
            Some(v) if barred.len() < EffectKind::HYPOTHESES.len() + 1 => barred.push(v),
            _ => break selected,
        }
    };
    let base = selected.state;
    let mut rejected = selected.rejected;
    rejected.extend(barred);
    let kept = selected.kept;
    let errors_after = base.problem.errors(&base.kinds, &base.state.x)?;
    let after = summary(&errors_after);
    let model_after = base.model_file()?;
    let effects = if kept.is_empty() {
        vec![none(&rejected)]
    } else {
        // The parameters of the final joint fit.
        kept.into_iter()
            .map(|v| EffectVerdict {
                parameters: base.parameters(v.kind, &ctx),
                standard_errors: significance(v.kind, &base, &ctx, true).0,
                ..v
            })
            .collect()
    };
    let mut noise: Vec<f64> = sigma.iter().copied().filter(|s| s.is_finite()).collect();
    if noise.is_empty() {
        noise.push(f64::INFINITY);
    }
    noise.sort_by(f64::total_cmp);
    Ok(Diagnosis {
        mismatch,
        effects,
        rejected,
        fit: BeforeAfter { before, after },
        calibration,
        noise: noise[noise.len() / 2],
        model_after,
        calibrated: calibrated_file,
        held_out: holdout.then_some(HeldOut {
            lines: ctx.held,
            before: test_before,
            after: base.test_cost,
            effective_lines: base.problem.held_out_count(&base.kinds, &base.state.x),
        }),
        before,
        after,
    })
}

/// One forward selection of the effects from the calibrated state
/// `start`, leaving out the `barred` kinds.
fn select_effects<'a>(
    start: &Fitted<'a>,
    ctx: &Context,
    o: &DiagnoseOptions,
    holdout: bool,
    barred: &[EffectVerdict],
) -> Result<crate::selection::Selected<Fitted<'a>>, DiagnoseError> {
    // The extra mass's placement found in the first step.
    let mut placement: Option<Placement> = None;
    forward_select(start.clone(), |base, kept, step| {
        let e_base = base.problem.errors(&base.kinds, &base.state.x)?;
        let summary_base = summary(&e_base);
        // From the second step on, the misfit the effects kept so far leave
        // counts as noise: the cost drops are divided by the base's cost
        // per row (if above 1), so that an effect added to others must
        // explain a share of what is left, not just some noise units of a
        // large remaining misfit.
        let misfit = if step == 1 {
            1.0
        } else if holdout {
            (base.test_cost / (2.0 * ctx.held as f64)).max(1.0)
        } else {
            (base.state.cost / ctx.rows).max(1.0)
        };
        let kinds: Vec<EffectKind> = EffectKind::HYPOTHESES
            .into_iter()
            .chain([EffectKind::ExtraMode])
            .filter(|&kind| {
                !(kept.contains(&kind)
                    || base.kinds.contains(&kind)
                    || (kind == EffectKind::ExtraMode && base.extended)
                    || (kind == EffectKind::PreSlidingFriction
                        && !rests_on_friction(&base.problem.file.model))
                    || barred.iter().any(|b| b.kind == kind))
            })
            .collect();
        // The hypotheses are independent fits: both cores take them in
        // turn, and the trials keep their order.
        let reuse = placement.as_ref();
        let trials = kinds
            .par_iter()
            .map(|&kind| -> Result<Option<PlacedTrial>, DiagnoseError> {
                let (fitted, new_placement) = match kind {
                    EffectKind::ExtraMode => match extra_mode(base, &e_base, ctx, reuse) {
                        Some((f, p)) => (f, Some(p)),
                        None => return Ok(None),
                    },
                    _ => match add_effect(base, kind, &e_base, ctx) {
                        Some(f) => (f, None),
                        None => return Ok(None),
                    },
                };
                let n_new = if kind == EffectKind::ExtraMode {
                    3
                } else {
                    fitted.kinds.len() - base.kinds.len()
                };
                let effective = fitted
                    .problem
                    .held_out_count(&fitted.kinds, &fitted.state.x);
                let score = if holdout {
                    profiled_gain(base.test_cost, fitted.test_cost, effective) - o.margin
                } else {
                    (base.state.cost - fitted.state.cost) / misfit
                        - n_new as f64 * ctx.rows.ln()
                        - o.margin
                };
                let after = summary(&fitted.problem.errors(&fitted.kinds, &fitted.state.x)?);
                let (cost_before, cost_after, price) = if holdout {
                    (base.test_cost, fitted.test_cost, o.margin)
                } else {
                    (
                        base.state.cost,
                        fitted.state.cost,
                        n_new as f64 * ctx.rows.ln() + o.margin,
                    )
                };
                let evidence = Evidence::Frequency(FrequencyEvidence {
                    added_to: kept.to_vec(),
                    held_out: holdout,
                    cost_before,
                    cost_after,
                    price,
                    before: summary_base,
                    after,
                    extended: (kind == EffectKind::ExtraMode).then(|| {
                        let m = &fitted.problem.file.model;
                        ExtendedChain {
                            masses: m.n_masses(),
                            id: m.id(),
                        }
                    }),
                });
                let (standard_errors, insignificant) = significance(kind, &fitted, ctx, false);
                let unresolved = unresolved(kind, kept, &fitted, ctx).or(insignificant);
                let trial = Trial {
                    verdict: EffectVerdict {
                        kind,
                        parameters: fitted.parameters(kind, ctx),
                        evidence,
                        score,
                        step,
                        unresolved,
                        standard_errors,
                    },
                    state: fitted,
                };
                Ok(Some((trial, new_placement)))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut tried: Vec<Trial<Fitted>> = Vec::with_capacity(trials.len());
        for (trial, p) in trials.into_iter().flatten() {
            if let Some(p) = p {
                placement.get_or_insert(p);
            }
            tried.push(trial);
        }
        Ok::<_, DiagnoseError>(tried)
    })
}

/// True if the driven mass moves as a rigid body (it lies on the free side
/// of the chain's gap), so that friction at rest can ground it: a mass
/// already held by the chain's own spring to the ground has no rigid-body
/// mode for a pre-sliding stiffness to turn into a resonance, and a spring
/// added there would only copy that spring's calibration.
fn rests_on_friction(model: &mms::Model) -> bool {
    model.actuator().plus > model.gap()
}

/// Why the band cannot resolve hypothesis `kind` fitted in `fitted` on
/// top of `kept`, if it cannot: a dead time and a first-order lag whose
/// corner lies above the band (either added to the other), or an extra
/// mass whose added resonance lies outside the band.
fn unresolved(
    kind: EffectKind,
    kept: &[EffectKind],
    fitted: &Fitted,
    ctx: &Context,
) -> Option<Unresolved> {
    let other = match kind {
        EffectKind::Lowpass => EffectKind::TimeDelay,
        EffectKind::TimeDelay => EffectKind::Lowpass,
        EffectKind::ExtraMode => {
            let mode = fitted.added_mode(ctx)?;
            return (!mode.in_band).then_some(Unresolved::OutsideBand(mode.resonance_hz));
        }
        _ => return None,
    };
    if !kept.contains(&other) {
        return None;
    }
    let corner = fitted.parameters(EffectKind::Lowpass, ctx)["corner_hz"];
    (corner > ctx.f_hi).then_some(Unresolved::LikeKept(other))
}

/// The standard errors of effect `kind`'s reported parameters in
/// `fitted`, and why the data do not resolve it, if they do not: a lag's
/// corner or a pre-sliding resonance outside the band, and with
/// `statistical` a parameter at the bound of its range, the value at
/// which the effect is absent within [`SIGNIFICANCE_SIGMAS`] standard
/// errors or an extra mode whose resonance and antiresonance lie within
/// their uncertainty of each other (tested on the final joint fit, where
/// one effect no longer masks another: with an effect missing, the misfit
/// it leaves inflates every other's uncertainty and can push a parameter
/// to its bound).
fn significance(
    kind: EffectKind,
    fitted: &Fitted,
    ctx: &Context,
    statistical: bool,
) -> (BTreeMap<String, f64>, Option<Unresolved>) {
    let mut errors = BTreeMap::new();
    let problem = &fitted.problem;
    let np = problem.np();
    let x = &fitted.state.x;
    let nx = x.len();
    let cov = problem.covariance(&fitted.kinds, x);
    let se_ln = |i: usize| cov.as_ref().map(|c| c[i * nx + i].max(0.0).sqrt());
    let (lo, hi) = ctx.state_bounds(problem, &fitted.kinds);
    let at_bound = |i: usize| {
        let tol = 1e-6 * (hi[i] - lo[i]).max(1.0);
        x[i] - lo[i] <= tol || hi[i] - x[i] <= tol
    };
    if kind == EffectKind::ExtraMode {
        // The new mass, spring and damper (no prior of their own).
        let names = problem.file.model.parameters();
        for i in (0..np).filter(|&i| statistical && problem.prior[i] == 0.0) {
            if at_bound(i) {
                let parameter = names[i].clone();
                return (
                    errors,
                    Some(Unresolved::AtBound {
                        parameter,
                        value: x[i].exp(),
                    }),
                );
            }
        }
        let Some(mode) = fitted.added_mode(ctx) else {
            return (errors, None);
        };
        let Some(cov) = &cov else {
            return (errors, None);
        };
        // The features' gradients in the log-parameters, by central
        // differences, and their variances by the delta method.
        let h = 1e-4;
        let mut g_res = vec![0.0; np];
        let mut g_anti = vec![0.0; np];
        for i in 0..np {
            let (mut up, mut down) = (x.clone(), x.clone());
            up[i] += h;
            down[i] -= h;
            let (Some(a), Some(b)) = (
                fitted.added_mode_at(ctx, &up),
                fitted.added_mode_at(ctx, &down),
            ) else {
                return (errors, None);
            };
            g_res[i] = (a.resonance_hz.ln() - b.resonance_hz.ln()) / (2.0 * h);
            if let (Some(p), Some(q)) = (a.antiresonance_hz, b.antiresonance_hz) {
                g_anti[i] = (p.ln() - q.ln()) / (2.0 * h);
            }
        }
        let quad = |g: &[f64]| -> f64 {
            (0..np)
                .map(|i| (0..np).map(|j| g[i] * cov[i * nx + j] * g[j]).sum::<f64>())
                .sum::<f64>()
                .max(0.0)
        };
        errors.insert(
            "resonance_hz".into(),
            mode.resonance_hz * quad(&g_res).sqrt(),
        );
        if let Some(a) = mode.antiresonance_hz {
            errors.insert("antiresonance_hz".into(), a * quad(&g_anti).sqrt());
            let g: Vec<f64> = g_res.iter().zip(&g_anti).map(|(r, a)| r - a).collect();
            let se = quad(&g).sqrt();
            let separation = (mode.resonance_hz / a).ln().abs();
            if statistical && separation < SIGNIFICANCE_SIGMAS * se {
                return (
                    errors,
                    Some(Unresolved::PoleOnZero {
                        separation,
                        standard_error: se,
                    }),
                );
            }
        }
        return (errors, None);
    }
    let Some(i) = fitted.kinds.iter().position(|&k| k == kind) else {
        return (errors, None);
    };
    let Some(name) = kind.parameter_name() else {
        return (errors, None);
    };
    // The effect's own coordinates: its parameter, and the damper a
    // pre-sliding spring brought with it.
    let mut own = vec![(np + i, name)];
    if kind == EffectKind::PreSlidingFriction {
        if let Some(j) = fitted.kinds[i..]
            .iter()
            .position(|&k| k == EffectKind::ViscousFriction)
        {
            own.push((np + i + j, "viscous_ns_per_m"));
        }
    }
    for &(k, n) in &own {
        if let Some(se) = se_ln(k) {
            errors.insert(n.to_string(), x[k].exp() * se);
        }
    }
    let k = np + i;
    if statistical && at_bound(k) {
        return (
            errors,
            Some(Unresolved::AtBound {
                parameter: name.to_string(),
                value: x[k].exp(),
            }),
        );
    }
    let v = x[k].exp();
    match kind {
        EffectKind::Lowpass if v > 3.0 * ctx.f_hi => {
            return (errors, Some(Unresolved::OutsideBand(v)));
        }
        EffectKind::PreSlidingFriction => {
            let f = (v / ctx.total_mass).sqrt() / (2.0 * PI);
            if f > ctx.f_hi {
                return (errors, Some(Unresolved::OutsideBand(f)));
            }
        }
        _ => {}
    }
    // How far the estimate lies from the effect's absent value: a factor
    // of 1 for a gain, zero (or a corner at infinity) for the others,
    // whose log-values then lie at minus infinity; in standard errors of
    // the estimate (of `1/f_c` for a corner).
    let Some(se) = se_ln(k) else {
        return (errors, None);
    };
    // The input model's own value, where it has one (a record's known
    // hold delay), is the value to tell the estimate from.
    let sigmas = match (kind.current(ctx.input), kind) {
        (Some(c), _) if c > 0.0 => (x[k] - c.ln()).abs() / se,
        (_, EffectKind::GainError) if statistical => gain_sigmas(fitted, i, ctx),
        (_, EffectKind::GainError) => x[k].abs() / se,
        _ => 1.0 / se,
    };
    // (A NaN distance is no distance.)
    if statistical && (sigmas.is_nan() || sigmas < SIGNIFICANCE_SIGMAS) {
        return (
            errors,
            Some(Unresolved::WithinUncertainty {
                parameter: name.to_string(),
                sigmas,
            }),
        );
    }
    (errors, None)
}

/// Whether the chain of `start` (without the extra mass), refitted from
/// `fitted`'s extended chain with the extra mass merged back into its
/// neighbours (its springs and dampers in series where it split a link),
/// predicts as well: then what the mass gained was a better calibration
/// of the chain that was there (an escape from the calibration's local
/// minimum, or from the prior on the mass it took weight from), not a
/// mode. Judged by the selection's own evidence and price.
fn merged_chain_fits(start: &Fitted, fitted: &Fitted, ctx: &Context) -> Option<Unresolved> {
    if !fitted.extended {
        return None;
    }
    let problem = &start.problem;
    let ext = fitted.problem.file.model;
    let np_ext = fitted.problem.np();
    let values: Vec<f64> = fitted.state.x[..np_ext].iter().map(|v| v.exp()).collect();
    let effects = &fitted.state.x[np_ext..];
    let (lo, hi) = ctx.state_bounds(problem, &fitted.kinds);
    let holdout = problem.test_sigma.iter().any(|&w| w > 0.0);
    let n = problem.file.model.n_masses();
    let mut best: Option<f64> = None;
    for (_, map, at) in extended_models(&problem.file.model)
        .into_iter()
        .filter(|(e, _, _)| *e == ext)
    {
        let merged = merged_back(&map, at, &values, n, problem.np(), ext.n_masses())?;
        let mut x0: Vec<f64> = merged.iter().map(|v| v.ln()).collect();
        x0.extend_from_slice(effects);
        for ((v, l), h) in x0.iter_mut().zip(&lo).zip(&hi) {
            *v = v.clamp(*l, *h);
        }
        let Ok(state) = problem.fit(&fitted.kinds, x0, &lo, &hi, ctx.o.max_iterations) else {
            continue;
        };
        let Some(lost) = deviance_lost(problem, &fitted.kinds, &state, fitted, ctx) else {
            continue;
        };
        // Without held-out lines the mass's three parameters are priced as
        // the selection prices them.
        let gain = if holdout {
            lost
        } else {
            lost - 3.0 * ctx.rows.ln()
        };
        best = Some(best.map_or(gain, |b: f64| b.min(gain)));
    }
    let gain = best?;
    (gain <= ctx.o.margin).then_some(Unresolved::MergedChainFits { gain })
}

/// The original chain's values from an extended chain's `values` (a mass
/// inserted as node `at + 1` by [`extended_models`], with `map` the
/// sources of its parameters): old parameters as they are, the two halves
/// of a split spring or damper in series, and the extra mass added to the
/// mass it hangs on (half to each neighbour where it sits between two).
fn merged_back(
    map: &[Source],
    at: usize,
    values: &[f64],
    n: usize,
    np: usize,
    n_ext: usize,
) -> Option<Vec<f64>> {
    let mut out = vec![f64::NAN; np];
    let mut halves: Vec<Vec<f64>> = vec![Vec::new(); np];
    let mut extra = 0.0;
    for (i, (s, &v)) in map.iter().zip(values).enumerate() {
        match *s {
            Source::Old(j) => out[j] = v,
            Source::Split(j) => halves[j].push(v),
            Source::New if i < n_ext => extra += v,
            Source::New => {}
        }
    }
    for (j, h) in halves.iter().enumerate() {
        if let [a, b] = h[..] {
            out[j] = 1.0 / (1.0 / a + 1.0 / b);
        }
    }
    // The old masses the extra one hangs on (0-based): the last at the
    // free end, the first before a free chain's first mass or where it
    // splits the ground's link, else the two it sits between.
    let targets: Vec<usize> = if at >= n || at == 0 {
        vec![if at >= n { n - 1 } else { 0 }]
    } else {
        vec![at - 1, at]
    };
    let share = extra / targets.len() as f64;
    for t in targets {
        out[t] += share;
    }
    out.iter().all(|v| v.is_finite() && *v > 0.0).then_some(out)
}

/// How far a gain error's factor lies from 1, in standard errors, read
/// from the profile of the fit rather than its curvature: the joint fit is
/// refitted with the factor held at 1, and the deviance it loses (on the
/// held-out lines if there are any, else on the fitted ones in units of
/// their misfit per row) is the square of the distance. A factor common to
/// every output is all but a common scale of the chain's parameters, which
/// only their prior tells apart, so the curvature's standard error
/// describes the prior, not what the data say about a factor of 1.
fn gain_sigmas(fitted: &Fitted, i: usize, ctx: &Context) -> f64 {
    let problem = &fitted.problem;
    let k = problem.np() + i;
    let mut kinds = fitted.kinds.clone();
    kinds.remove(i);
    let mut x0 = fitted.state.x.clone();
    x0.remove(k);
    let (lo, hi) = ctx.state_bounds(problem, &kinds);
    let Ok(null) = problem.fit(&kinds, x0, &lo, &hi, ctx.o.max_iterations) else {
        return f64::NAN;
    };
    deviance_lost(problem, &kinds, &null, fitted, ctx).map_or(f64::NAN, |d| d.max(0.0).sqrt())
}

/// The evidence `fitted` holds over a `null` fit (with its problem and
/// effect kinds) that lacks one of its hypotheses, in the selection's
/// units: on the held-out lines if there are any (the noise level profiled
/// out, `fitted`'s residuals counted by their effective number), else the
/// drop of the fitted cost in units of `fitted`'s misfit per row. `None`
/// where the null's held-out lines cannot be evaluated.
fn deviance_lost(
    problem: &Problem,
    kinds: &[EffectKind],
    null: &State,
    fitted: &Fitted,
    ctx: &Context,
) -> Option<f64> {
    if problem.test_sigma.iter().any(|&w| w > 0.0) {
        let test = problem.test_cost(kinds, &null.x).ok()?;
        let n = fitted
            .problem
            .held_out_count(&fitted.kinds, &fitted.state.x);
        Some(profiled_gain(test, fitted.test_cost, n))
    } else {
        Some((null.cost - fitted.state.cost) / (fitted.state.cost / ctx.rows).max(1.0))
    }
}

/// What every hypothesis needs to know besides its base.
struct Context<'a> {
    o: &'a DiagnoseOptions,
    /// Residual rows of the data in the fits (two per fitted line).
    rows: f64,
    /// Held-out lines.
    held: usize,
    f_lo: f64,
    f_hi: f64,
    /// Total mass of the calibrated model (the friction range's scale).
    total_mass: f64,
    /// The input model's effects (their values are starts).
    input: &'a Effects,
    /// The input model and its calibrated log-parameters (to name the
    /// features an extra mass adds).
    original: (&'a mms::Model, &'a [f64]),
}

impl Context<'_> {
    /// The range searched for a one-parameter effect.
    fn bounds(&self, kind: EffectKind) -> (f64, f64) {
        let (lo, hi) = self.searched(kind);
        let range = match kind {
            EffectKind::TimeDelay => &mms::ranges::TIME_DELAY,
            EffectKind::Lowpass => &mms::ranges::CORNER_FREQUENCY,
            EffectKind::GainError => &mms::ranges::GAIN_FACTOR,
            EffectKind::HystereticDamping => &mms::ranges::LOSS_FACTOR,
            EffectKind::ViscousFriction => &mms::ranges::VISCOUS_FRICTION,
            EffectKind::PreSlidingFriction => &mms::ranges::PRE_SLIDING_STIFFNESS,
            _ => return (lo, hi),
        };
        // Within the physical range, so the model written reads back.
        let lo = lo.clamp(range.min, range.max);
        (lo, hi.clamp(lo, range.max))
    }

    /// The range the band and the model suggest for a one-parameter effect.
    fn searched(&self, kind: EffectKind) -> (f64, f64) {
        match kind {
            EffectKind::TimeDelay => (1e-3 / self.f_hi, 1.0 / self.f_lo),
            EffectKind::Lowpass => (0.1 * self.f_lo, 1e3 * self.f_hi),
            EffectKind::GainError => (0.01, 100.0),
            EffectKind::HystereticDamping => (1e-5, 1.0),
            EffectKind::ViscousFriction => (
                1e-4 * self.total_mass * 2.0 * PI * self.f_lo,
                1e2 * self.total_mass * 2.0 * PI * self.f_hi,
            ),
            // The total mass on the spring resonates from a tenth of the
            // band's lowest line (0.1 dB there) to its highest.
            EffectKind::PreSlidingFriction => (
                self.total_mass * (2.0 * PI * 0.1 * self.f_lo).powi(2),
                self.total_mass * (2.0 * PI * self.f_hi).powi(2),
            ),
            EffectKind::ExtraMode
            | EffectKind::CoulombFriction
            | EffectKind::Backlash
            | EffectKind::Offset
            | EffectKind::None => (1.0, 1.0),
        }
    }

    /// Log bounds of a state with the effects `kinds`: the chain's, then
    /// one pair per effect.
    fn state_bounds(&self, problem: &Problem, kinds: &[EffectKind]) -> (Vec<f64>, Vec<f64>) {
        let mut lo = problem.lo.clone();
        let mut hi = problem.hi.clone();
        for &k in kinds {
            let (a, b) = self.bounds(k);
            lo.push(a.ln());
            hi.push(b.ln());
        }
        (lo, hi)
    }
}

/// A fitted model: the problem (the input's chain, or the chain with one
/// more mass), the effects added, the state and its held-out cost.
#[derive(Clone)]
struct Fitted<'a> {
    problem: Problem<'a>,
    kinds: Vec<EffectKind>,
    /// True if the chain has the extra mass.
    extended: bool,
    state: State,
    test_cost: f64,
}

impl Fitted<'_> {
    /// The reported parameters of effect `kind` in this state.
    fn parameters(&self, kind: EffectKind, ctx: &Context) -> BTreeMap<String, f64> {
        let mut out = BTreeMap::new();
        let np = self.problem.np();
        if let (Some(i), Some(name)) = (
            self.kinds.iter().position(|&k| k == kind),
            kind.parameter_name(),
        ) {
            out.insert(name.to_string(), self.state.x[np + i].exp());
            // The damper a pre-sliding spring brought with it (a viscous
            // friction cannot be added after it).
            if kind == EffectKind::PreSlidingFriction {
                if let Some(j) = self.kinds[i..]
                    .iter()
                    .position(|&k| k == EffectKind::ViscousFriction)
                {
                    out.insert(
                        "viscous_ns_per_m".to_string(),
                        self.state.x[np + i + j].exp(),
                    );
                }
            }
        }
        if kind == EffectKind::ExtraMode {
            if let Some(mode) = self.added_mode(ctx) {
                out.insert("resonance_hz".to_string(), mode.resonance_hz);
                if let Some(a) = mode.antiresonance_hz {
                    out.insert("antiresonance_hz".to_string(), a);
                }
            }
        }
        out
    }

    /// The mode the extra mass of this state adds, if it has one.
    fn added_mode(&self, ctx: &Context) -> Option<AddedMode> {
        self.added_mode_at(ctx, &self.state.x)
    }

    /// The mode the extra mass adds at the state `at`.
    fn added_mode_at(&self, ctx: &Context, at: &[f64]) -> Option<AddedMode> {
        if !self.extended {
            return None;
        }
        let (m, x) = ctx.original;
        let old: Vec<f64> = x.iter().map(|v| v.exp()).collect();
        let np = self.problem.np();
        let new: Vec<f64> = at[..np].iter().map(|v| v.exp()).collect();
        added_features(
            m,
            &old,
            &self.problem.file.model,
            &new,
            (ctx.f_lo, ctx.f_hi),
        )
    }

    /// The model file of this state.
    fn model_file(&self) -> Result<ModelFile, ResponseError> {
        let np = self.problem.np();
        let file = &self.problem.file;
        Ok(ModelFile {
            parameters: Parameters::from_values(
                &file.model,
                self.state.x[..np].iter().map(|v| v.exp()).collect(),
            )?,
            effects: self.problem.effects(&self.kinds, &self.state.x),
            ..file.clone()
        }
        .within_ranges())
    }
}

/// `base` with the one-parameter effect `kind` added, fitted jointly with
/// everything in `base`; `e_base` is `base`'s residual.
fn add_effect<'a>(
    base: &Fitted<'a>,
    kind: EffectKind,
    e_base: &[Complex64],
    ctx: &Context,
) -> Option<Fitted<'a>> {
    let problem = &base.problem;
    let (lo_e, hi_e) = ctx.bounds(kind);
    // Starts: the present value if the model has the effect already, a
    // value read off the residual where that is direct, else the best of a
    // coarse log grid (evaluated without refitting).
    let mut starts: Vec<f64> = kind.current(ctx.input).into_iter().collect();
    match kind {
        EffectKind::TimeDelay => {
            // The phase error of a missing delay is -w T: least squares.
            let (mut num, mut den) = (0.0, 0.0);
            for ((&f, e), w) in problem.freq.iter().zip(e_base).zip(&problem.inv_sigma) {
                let w2 = if *w > 0.0 { 1.0 } else { 0.0 };
                let om = 2.0 * PI * f;
                num += w2 * om * e.im;
                den += w2 * om * om;
            }
            starts.push(num / den);
        }
        EffectKind::GainError => {
            let mean = e_base.iter().map(|e| e.re).sum::<f64>() / e_base.len() as f64;
            starts.push((-mean).exp());
        }
        _ => {}
    }
    for k in 0..7 {
        starts.push(lo_e * (hi_e / lo_e).powf((k as f64 + 0.5) / 7.0));
    }
    let mut kinds = base.kinds.clone();
    kinds.push(kind);
    // Friction at rest holds and damps: its spring comes with a damper
    // unless one is there already (a damping ratio of 0.05 to start).
    let damper = kind == EffectKind::PreSlidingFriction
        && !kinds.contains(&EffectKind::ViscousFriction)
        && problem.file.effects.viscous_friction.is_none();
    if damper {
        kinds.push(EffectKind::ViscousFriction);
    }
    let (lo_v, hi_v) = ctx.bounds(EffectKind::ViscousFriction);
    let mut best: Option<(f64, Vec<f64>)> = None;
    for s in starts {
        if !s.is_finite() {
            continue;
        }
        let mut x = base.state.x.clone();
        x.push(s.clamp(lo_e, hi_e).ln());
        if damper {
            let k = s.clamp(lo_e, hi_e);
            let b = 0.1 * (k * ctx.total_mass).sqrt();
            x.push(b.clamp(lo_v, hi_v).ln());
        }
        let Ok(r) = problem.residuals(&kinds, &x, None) else {
            continue;
        };
        let c: f64 = r.iter().map(|v| v * v).sum();
        if best.as_ref().is_none_or(|b| c < b.0) {
            best = Some((c, x));
        }
    }
    let (_, x0) = best?;
    let (lo, hi) = ctx.state_bounds(problem, &kinds);
    let mut state = problem
        .fit(&kinds, x0, &lo, &hi, ctx.o.max_iterations)
        .ok()?;
    // A factor is all but a common scale of the chain's parameters: the
    // calibration, which had no factor, may have pressed them against
    // their bounds to imitate it, and from there the fit finds only part
    // of it. So the factor is also fitted from the nominal chain.
    if kind == EffectKind::GainError {
        let np = problem.np();
        let mut x = problem.nominal_ln.clone();
        x.extend_from_slice(&base.state.x[np..]);
        if let Ok(e) = problem.errors(&base.kinds, &x) {
            let mean = e.iter().map(|e| e.re).sum::<f64>() / e.len().max(1) as f64;
            x.push((-mean).clamp(lo_e.ln(), hi_e.ln()));
            if let Ok(other) = problem.fit(&kinds, x, &lo, &hi, ctx.o.max_iterations) {
                if other.cost < state.cost {
                    state = other;
                }
            }
        }
    }
    let test_cost = problem.test_cost(&kinds, &state.x).ok()?;
    Some(Fitted {
        problem: problem.clone(),
        kinds,
        extended: base.extended,
        state,
        test_cost,
    })
}

/// Where the extra mass's parameters start: an old parameter (by index),
/// half of an old spring or damper split in two (each part twice as stiff),
/// or a new one.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    Old(usize),
    Split(usize),
    New,
}

/// Places one more mass in the chain: at the free end, before the first
/// mass (free chains), or between two masses (or the ground and the first
/// mass) that a spring joins, splitting it in two. Each placement is the
/// extended model and, for every parameter of it, its [`Source`].
fn extended_models(m: &mms::Model) -> Vec<(mms::Model, Vec<Source>, usize)> {
    let n = m.n_masses();
    if n >= mms::MAX_MASSES {
        return Vec::new();
    }
    let old = m.parameters();
    let mut out = Vec::new();
    // The new mass becomes mass p + 1; old masses above p move up by one.
    // p = n: at the free end; p = 0 on a free chain: before the first mass;
    // otherwise the link p (p = 0: the ground's) is split.
    for p in (0..=n).rev() {
        let split = p < n && m.has_link(p);
        if p < n && !split && !(p == 0 && m.gap() == 0) {
            continue;
        }
        let shift = |q: mms::Port| shifted_port(q, p);
        let gap = if m.gap() > p { m.gap() + 1 } else { m.gap() };
        let Ok(e) = mms::Model::new(n + 1, gap, shift(m.actuator()), shift(m.sensor())) else {
            continue;
        };
        let mut names: BTreeMap<String, Source> = BTreeMap::new();
        for (j, name) in old.iter().enumerate() {
            let (kind, rest) = name.split_at(1);
            if kind == "m" {
                let i: usize = rest.parse().unwrap_or(0);
                names.insert(mms::mass_name(shifted_node(i, p)), Source::Old(j));
                continue;
            }
            let link = |i: usize| {
                if kind == "c" {
                    mms::spring_name(i)
                } else {
                    mms::damper_name(i)
                }
            };
            let i = link_index(rest);
            if split && i == p {
                names.insert(link(p), Source::Split(j));
                names.insert(link(p + 1), Source::Split(j));
            } else {
                names.insert(link(shifted_node(i, p)), Source::Old(j));
            }
        }
        let map = e
            .parameters()
            .iter()
            .map(|q| names.get(q).copied().unwrap_or(Source::New))
            .collect();
        out.push((e, map, p));
    }
    out
}

/// Node `i` of a chain once a mass is inserted as node `at + 1`.
fn shifted_node(i: usize, at: usize) -> usize {
    if i > at {
        i + 1
    } else {
        i
    }
}

/// Port `q` of a chain once a mass is inserted as node `at + 1`.
fn shifted_port(q: mms::Port, at: usize) -> mms::Port {
    mms::Port::new(shifted_node(q.plus, at), shifted_node(q.minus, at))
}

/// The outputs' segments on the chain `ext`, which has a mass inserted as
/// node `at + 1` ([`extended_models`]), each ending at `end(old end)`.
fn extended_segments(
    segments: &[Segment],
    ext: &mms::Model,
    at: usize,
    end: impl Fn(usize) -> usize,
) -> Option<Vec<Segment>> {
    segments
        .iter()
        .map(|s| {
            let chain = mms::Model::new(
                ext.n_masses(),
                ext.gap(),
                ext.actuator(),
                shifted_port(s.chain.sensor(), at),
            )
            .ok()?;
            Some(Segment {
                chain,
                end: end(s.end),
            })
        })
        .collect()
}

/// The lower node index of a link name's digits (`1` -> 0, `12` -> 1,
/// `9_10` -> 9).
fn link_index(digits: &str) -> usize {
    if let Some((a, _)) = digits.split_once('_') {
        return a.parse().unwrap_or(0);
    }
    if digits == "1" {
        0
    } else {
        digits[..digits.len() - 1].parse().unwrap_or(0)
    }
}

/// The extra-mode hypothesis: for each placement and each of the largest
/// residual peaks, a new mass tuned to the peak (a fifth of the smallest
/// mass on a new spring; or, splitting a spring, the mass whose local
/// resonance on the two halves is the peak), then all parameters refitted
/// (the old ones under the calibration's bounds and prior, the new ones
/// free within two decades) together with `base`'s effects.
fn extra_mode<'a>(
    base: &Fitted<'a>,
    e_base: &[Complex64],
    ctx: &Context,
    reuse: Option<&Placement>,
) -> Option<(Fitted<'a>, Placement)> {
    let problem = &base.problem;
    let file = &problem.file;
    let n = file.model.n_masses();
    let np = problem.np();
    let old: Vec<f64> = base.state.x[..np].iter().map(|v| v.exp()).collect();
    let effect_x = &base.state.x[np..];
    let smallest = old[..n].iter().cloned().fold(f64::INFINITY, f64::min);
    let missing =
        missing_mass(file, &old[..n], e_base, &problem.inv_sigma).filter(|&m| m > smallest);
    // The three largest local maxima of the residual's magnitude (on the
    // fitted lines).
    let mag: Vec<f64> = e_base
        .iter()
        .zip(&problem.inv_sigma)
        .map(|(e, w)| if *w > 0.0 { e.norm() } else { 0.0 })
        .collect();
    let mut peaks: Vec<usize> = (1..mag.len().saturating_sub(1))
        .filter(|&k| mag[k] > 0.0 && mag[k] >= mag[k - 1] && mag[k] >= mag[k + 1])
        .collect();
    peaks.sort_by(|&a, &b| mag[b].total_cmp(&mag[a]));
    peaks.truncate(3);
    // The screening fits see every second line only (half the time; the
    // placements and peaks differ by far more than that loses).
    let sub: Vec<usize> = (0..problem.freq.len()).step_by(2).collect();
    let sub_freq: Vec<f64> = sub.iter().map(|&k| problem.freq[k]).collect();
    let sub_data: Vec<Complex64> = sub.iter().map(|&k| problem.data[k]).collect();
    let sub_inv: Vec<f64> = sub.iter().map(|&k| problem.inv_sigma[k]).collect();
    let sub_test = vec![0.0; sub.len()];
    // (screened cost, placement, its start values, screened state).
    type Screened = (f64, mms::Model, Vec<Source>, Vec<f64>, Vec<f64>, usize);
    let mut screened: Vec<Screened> = Vec::new();
    if let Some((ext, map, fitted, at)) = reuse {
        // A later step: the placement and the new parameters of the first
        // step's fit, the old parameters of the base (no screening).
        let values: Vec<f64> = map
            .iter()
            .zip(fitted)
            .map(|(s, v)| match *s {
                Source::Old(j) => old[j],
                _ => *v,
            })
            .collect();
        let mut x: Vec<f64> = values.iter().map(|v| v.ln()).collect();
        x.extend_from_slice(effect_x);
        screened.push((0.0, *ext, map.clone(), values, x, *at));
    }
    let placements = if reuse.is_some() {
        Vec::new()
    } else {
        extended_models(&file.model)
    };
    for (ext, map, at) in placements {
        let n_ext = ext.n_masses();
        let n_links = ext.springs().len();
        // The spring a split placement halves (its stiffness sets the new
        // mass).
        let split_spring = map.iter().find_map(|s| match s {
            Source::Split(j) if *j >= n && *j < n + n_links - 1 => Some(old[*j]),
            _ => None,
        });
        // Each peak with a mass tuned to it; and a missing heavy mass, on
        // the largest peak.
        let starts = peaks
            .iter()
            .map(|&k| (k, None))
            .chain(missing.zip(peaks.first()).map(|(m, &k)| (k, Some(m))));
        for (k, heavy) in starts {
            let w = 2.0 * PI * problem.freq[k];
            let (m_new, c_new) = match (split_spring, heavy) {
                (Some(c), None) => ((4.0 * c / (w * w)).min(5.0 * smallest), 2.0 * c),
                (None, None) => (0.2 * smallest, 0.2 * smallest * w * w),
                (Some(c), Some(m)) => (m, 2.0 * c),
                (None, Some(m)) => (m, m * w * w),
            };
            let d_new = 2.0 * 0.02 * (c_new * m_new).sqrt();
            let values: Vec<f64> = map
                .iter()
                .enumerate()
                .map(|(i, s)| match *s {
                    Source::Old(j) => old[j],
                    Source::Split(j) => 2.0 * old[j],
                    Source::New if i < n_ext => m_new,
                    Source::New if i < n_ext + n_links => c_new,
                    Source::New => d_new,
                })
                .collect();
            let screen = |lines| -> Option<State> {
                // Every second line of each output.
                let segments = extended_segments(&problem.segments, &ext, at, |e| e.div_ceil(2))?;
                let p = extended_problem(problem, ext, segments, &map, &values, lines)?;
                let mut x0: Vec<f64> = values.iter().map(|v| v.ln()).collect();
                x0.extend_from_slice(effect_x);
                let (lo, hi) = ctx.state_bounds(&p, &base.kinds);
                // A short fit ranks the placements and peaks; only the
                // best is finished (below), which keeps the hypothesis
                // within the diagnosis's time budget.
                p.fit(&base.kinds, x0, &lo, &hi, 12).ok()
            };
            let Some(state) = screen((&sub_freq[..], &sub_data[..], &sub_inv[..], &sub_test[..]))
            else {
                continue;
            };
            screened.push((state.cost, ext, map.clone(), values, state.x, at));
        }
    }
    // Stable: equal costs keep the order of placements and peaks.
    screened.sort_by(|a, b| a.0.total_cmp(&b.0));
    // The best screens are finished in turn until one adds its mode within
    // the band (a fit can also spend the extra mass on a mode far outside
    // it, which the band cannot resolve); else the first finished.
    let mut first: Option<(Fitted<'a>, Placement)> = None;
    for (_, ext, map, values, x, at) in screened.into_iter().take(FINISHED_SCREENS) {
        let Some(done) = finish_extra_mode(base, ctx, (ext, map, at), &values, x) else {
            continue;
        };
        if done.0.added_mode(ctx).is_some_and(|m| m.in_band) {
            return Some(done);
        }
        first.get_or_insert(done);
    }
    first
}

/// The mass a free chain lacks by the level of its lowest fitted lines,
/// which lie on the rigid-body mass line `1 / (M w^2)` below the first
/// feature: the model's total mass times `|H_model / H_data| - 1`, from the
/// median over up to five lines; `None` on a grounded chain (its low band
/// is a compliance, which a mass does not change) or if the model is not
/// lighter than the data.
fn missing_mass(
    file: &ModelFile,
    masses: &[f64],
    e: &[Complex64],
    inv_sigma: &[f64],
) -> Option<f64> {
    if file.model.has_link(0) {
        return None;
    }
    let mut level: Vec<f64> = e
        .iter()
        .zip(inv_sigma)
        .filter(|(_, w)| **w > 0.0)
        .map(|(e, _)| e.re)
        .take(5)
        .collect();
    level.sort_by(f64::total_cmp);
    let ratio = level.get(level.len() / 2)?.exp();
    let total: f64 = masses.iter().sum();
    (ratio > 1.0).then_some(total * (ratio - 1.0))
}

/// How many screened placements [`extra_mode`] finishes at most.
const FINISHED_SCREENS: usize = 3;

/// The full fit of one extra-mass placement from its screened state `x`.
fn finish_extra_mode<'a>(
    base: &Fitted<'a>,
    ctx: &Context,
    (ext, map, at): (mms::Model, Vec<Source>, usize),
    values: &[f64],
    x: Vec<f64>,
) -> Option<(Fitted<'a>, Placement)> {
    let problem = &base.problem;
    let segments = extended_segments(&problem.segments, &ext, at, |e| e)?;
    let ext_problem = extended_problem(
        problem,
        ext,
        segments,
        &map,
        values,
        (
            problem.freq,
            problem.data,
            &problem.inv_sigma,
            &problem.test_sigma,
        ),
    )?;
    let (lo, hi) = ctx.state_bounds(&ext_problem, &base.kinds);
    let state = ext_problem
        .fit(&base.kinds, x, &lo, &hi, ctx.o.max_iterations)
        .ok()?;
    let test_cost = ext_problem.test_cost(&base.kinds, &state.x).ok()?;
    let fitted: Vec<f64> = state.x[..map.len()].iter().map(|v| v.exp()).collect();
    Some((
        Fitted {
            problem: ext_problem,
            kinds: base.kinds.clone(),
            extended: true,
            state,
            test_cost,
        },
        (ext, map, fitted, at),
    ))
}

/// A trial of one hypothesis, with the extra mass's placement it found.
type PlacedTrial<'a> = (Trial<Fitted<'a>>, Option<Placement>);

/// An extra mass's placement: the extended model, the sources of its
/// parameters and their fitted values.
type Placement = (mms::Model, Vec<Source>, Vec<f64>, usize);

/// The problem of one extra-mass placement started at `values`, on the
/// given lines (frequencies, data, fit weights, held-out weights); the old
/// parameters keep `problem`'s bounds and prior.
fn extended_problem<'b>(
    problem: &Problem,
    ext: mms::Model,
    segments: Vec<Segment>,
    map: &[Source],
    values: &[f64],
    lines: (&'b [f64], &'b [Complex64], &[f64], &[f64]),
) -> Option<Problem<'b>> {
    let parameters = Parameters::from_values(&ext, values.to_vec()).ok()?;
    let start_ln: Vec<f64> = values.iter().map(|v| v.ln()).collect();
    let wide = 100f64.ln();
    let index = |i: usize| match map[i] {
        Source::Old(j) => Some(j),
        _ => None,
    };
    let mut extended = Problem {
        file: ModelFile {
            model: ext,
            parameters,
            ..problem.file.clone()
        },
        segments,
        freq: lines.0,
        data: lines.1,
        inv_sigma: lines.2.to_vec(),
        test_sigma: lines.3.to_vec(),
        // The old parameters keep their prior around their *nominal*
        // values (as in the calibration); the new ones have none.
        nominal_ln: (0..values.len())
            .map(|i| index(i).map_or(start_ln[i], |j| problem.nominal_ln[j]))
            .collect(),
        prior: (0..values.len())
            .map(|i| index(i).map_or(0.0, |j| problem.prior[j]))
            .collect(),
        lo: (0..values.len())
            .map(|i| index(i).map_or(start_ln[i] - wide, |j| problem.lo[j]))
            .collect(),
        hi: (0..values.len())
            .map(|i| index(i).map_or(start_ln[i] + wide, |j| problem.hi[j]))
            .collect(),
    };
    within_physical_ranges(&ext.parameters(), &mut extended.lo, &mut extended.hi);
    Some(extended)
}

/// Narrows log bounds to the physical ranges of the parameters `names`
/// (mms::ranges), so that no fit leaves them: the model written reads
/// back. A range narrower than the bounds' own stays non-empty.
fn within_physical_ranges(names: &[String], lo: &mut [f64], hi: &mut [f64]) {
    for ((n, l), h) in names.iter().zip(lo.iter_mut()).zip(hi.iter_mut()) {
        let (a, b) = mms::ranges::of_parameter(n).ln_bounds();
        *l = l.clamp(a, b);
        *h = h.clamp(*l, b);
    }
}

/// The mode an extra mass adds: the undamped resonance of `ext` (values
/// `q`) farthest in log frequency from every resonance of `m` (values
/// `p`), preferring those within `band` (Hz) when the extra mass puts
/// more resonances there, and the same for the antiresonance if it adds
/// one. `None` if the extended model has no resonance.
fn added_features(
    m: &mms::Model,
    p: &[f64],
    ext: &mms::Model,
    q: &[f64],
    band: (f64, f64),
) -> Option<AddedMode> {
    let features = |model: &mms::Model, values: &[f64]| -> (Vec<f64>, Vec<f64>) {
        let nu = model.undamped_parameters().len();
        let (num, den) = crate::start::UndampedCoefficients::new(model).eval(&values[..nu]);
        let hz = |c: &[f64]| -> Vec<f64> {
            crate::start::roots(c)
                .iter()
                .filter(|z| z.re > 0.0 && z.im.abs() <= 1e-6 * z.norm())
                .map(|z| z.re.sqrt() / (2.0 * PI))
                .collect()
        };
        (hz(&num), hz(&den))
    };
    let (za, pa) = features(m, p);
    let (zb, pb) = features(ext, q);
    let inside = |f: &f64| *f >= band.0 && *f <= band.1;
    // The new feature is the one of the extended list farthest (in log
    // frequency) from every feature of the original, among those in the
    // band if the band gained one.
    let extra = |old: &[f64], new: &[f64]| -> (Option<f64>, bool) {
        let gained =
            new.iter().filter(|f| inside(f)).count() > old.iter().filter(|f| inside(f)).count();
        let farthest = new
            .iter()
            .filter(|f| !gained || inside(f))
            .map(|&f| {
                let d = old
                    .iter()
                    .map(|&g| (f / g).ln().abs())
                    .fold(f64::INFINITY, f64::min);
                (d, f)
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, f)| f);
        (farthest, gained)
    };
    let (resonance_hz, in_band) = extra(&pa, &pb);
    Some(AddedMode {
        resonance_hz: resonance_hz?,
        antiresonance_hz: if zb.len() > za.len() {
            extra(&za, &zb).0
        } else {
            None
        },
        in_band,
    })
}

/// What [`added_features`] finds.
struct AddedMode {
    resonance_hz: f64,
    antiresonance_hz: Option<f64>,
    /// The extra mass puts one more resonance into the band.
    in_band: bool,
}

/// The complex logarithm of a ratio of responses, `ln|z| + j arg z`: the
/// magnitude's logarithm from the squared modulus (half its logarithm,
/// without the `hypot` call that `ln` pays for range safety), falling back
/// to it where the square leaves the normal range. Equal to `z.ln()` to a
/// few units in the last place; this runs for every line of every fit.
fn log_error(z: Complex64) -> Complex64 {
    let m2 = z.norm_sqr();
    let re = if m2.is_normal() {
        0.5 * m2.ln()
    } else {
        z.norm().ln()
    };
    Complex64::new(re, z.im.atan2(z.re))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Merging an extra mass back gives back the chain it was inserted
    /// into: for every placement in a grounded and a free 3-mass chain,
    /// an extended chain whose new mass is tiny (and, at the free end,
    /// stiffly held) and whose split links are the halves in series has
    /// the original chain's response below the new mass's own mode, and
    /// the merged values are the original ones (the masses up to the tiny
    /// one).
    #[test]
    fn an_extra_mass_merged_back_gives_the_chain_it_was_inserted_into() {
        use mms::response::ChainResponse;
        let all = mms::rule3_models(3).unwrap();
        let grounded = all.iter().find(|m| m.has_link(0)).unwrap();
        let free = all.iter().find(|m| !m.has_link(0)).unwrap();
        for &m in [grounded, free] {
            let names = m.parameters();
            let orig: Vec<f64> = names
                .iter()
                .enumerate()
                .map(|(i, n)| match &n[..1] {
                    "m" => 1.0 + 0.3 * i as f64,
                    "c" => 1.0e4 * (1.0 + 0.5 * i as f64),
                    _ => 2.0 + 0.1 * i as f64,
                })
                .collect();
            let placements = extended_models(&m);
            assert!(!placements.is_empty());
            for (ext, map, at) in placements {
                let n_ext = ext.n_masses();
                let values: Vec<f64> = map
                    .iter()
                    .enumerate()
                    .map(|(i, s)| match *s {
                        Source::Old(j) => orig[j],
                        Source::Split(j) => 2.0 * orig[j],
                        Source::New if i < n_ext => 1e-6,
                        Source::New if i < n_ext + ext.springs().len() => 1e8,
                        Source::New => 1.0,
                    })
                    .collect();
                let merged =
                    merged_back(&map, at, &values, m.n_masses(), orig.len(), n_ext).unwrap();
                for (j, (a, b)) in merged.iter().zip(&orig).enumerate() {
                    assert!(
                        (a / b - 1.0).abs() < 1e-5,
                        "{} at {at}: {} {a} vs {b}",
                        ext.id(),
                        names[j]
                    );
                }
                let g = ChainResponse::new(&m, mms::Output::Position);
                let h = ChainResponse::new(&ext, mms::Output::Position);
                for f in [0.5, 5.0, 50.0] {
                    let (a, b) = (g.eval(&orig, f).unwrap(), h.eval(&values, f).unwrap());
                    assert!(
                        (a - b).norm() < 1e-4 * a.norm(),
                        "{} at {at}, {f} Hz: {a} vs {b}",
                        ext.id()
                    );
                }
            }
        }
    }

    /// Against the library's complex logarithm, over moduli from far
    /// below to far above the range where the squared modulus is normal,
    /// and every quadrant (the argument is the same call).
    #[test]
    fn log_error_equals_the_complex_logarithm() {
        for exp in [-200, -160, -20, -1, 0, 1, 30, 160, 200] {
            for k in 0..12 {
                let arg = -3.0 + 0.5 * k as f64;
                let z = Complex64::from_polar(10f64.powi(exp) * 1.37, arg);
                let (a, b) = (log_error(z), z.ln());
                assert!(
                    (a.re - b.re).abs() <= 4.0 * f64::EPSILON * b.re.abs().max(1.0),
                    "{z}: {a} against {b}"
                );
                assert_eq!(a.im, b.im, "{z}");
            }
        }
    }
}
