//! One call from a recording and a model to one reconciled verdict:
//! [`diagnose_recording`].
//!
//! The frequency-domain hypotheses ([`crate::diagnose`]: dead time, lag,
//! gain error, hysteretic damping, viscous friction, an extra mode) are
//! tried on the recording's FRF, every line weighted by its uncertainty
//! ([`frf::uncertainty`]); a time-domain recording also gets the
//! time-domain hypotheses ([`crate::nonlinear`]: Coulomb friction,
//! backlash) on its samples. Each domain keeps only effects that lower the
//! prediction error on data held out of its fits (every fourth line; every
//! fourth of 16 blocks of the record). The two then compete on one
//! criterion both can be scored on: the drop of that held-out prediction
//! error in noise units, `-2 ln` of the likelihood ratio of the model
//! after to the calibrated model on the held-out data (for lines, the
//! drop of `sum |e_k|^2 / sigma_k^2` with each line's own uncertainty; for
//! samples, `n ln(RSS_before / RSS_after)`, the noise level profiled out
//! and `n` the independent samples, fewer than the samples when the
//! model's error is smooth).
//! The headline is the effect whose domain gains more there, and
//! [`Verdict`] says which domain decided and why. A time-domain comparison
//! in which the model, with the effects it earned, still leaves most of
//! the output unexplained is not informative and cannot lead.
//!
//! ```
//! use frf::Frf;
//! use ident::diagnose::EffectKind;
//! use ident::diagnosis::{diagnose_recording, Domain, DiagnosisOptions};
//! use mms::model_file::{ModelFile, Motion};
//! use mms::response::{ChainResponse, Effects, Parameters};
//! use mms::{Model, Output};
//!
//! // A measured FRF of a two-mass drive with a 0.5 ms dead time and 1 %
//! // noise; the model's parameters are 8 % off and it knows no delay.
//! let a2 = Model::from_id("A2")?;
//! let truth = [0.01, 0.012, 0.02, 400.0, 900.0, 0.03, 0.05];
//! let f: Vec<f64> = (0..600).map(|k| 5.0 * 1.006f64.powi(k)).collect();
//! let delayed = Effects { time_delay_s: Some(5e-4), ..Effects::default() };
//! let mut rng = mms::xorshift::XorShift::new(4);
//! let h: Vec<_> = ChainResponse::with_effects(&a2, Output::Position, &delayed)
//!     .eval_many(&truth, &f)?
//!     .into_iter()
//!     .map(|h| h * (1.0 + 0.01 * frf::Complex64::new(rng.normal(), rng.normal())))
//!     .collect();
//! let frf = Frf::new(f, h, None)?;
//! let nominal: Vec<f64> = truth.iter().map(|p| p * 1.08).collect();
//! let model = ModelFile {
//!     model: a2,
//!     output: Output::Position,
//!     parameters: Parameters::from_values(&a2, nominal)?,
//!     gain: 1.0,
//!     motion: Motion::Translational,
//!     effects: Effects::default(),
//! };
//! let d = diagnose_recording(&frf, None, &model, None, &DiagnosisOptions::default())?;
//! assert_eq!(d.verdict.headline, EffectKind::TimeDelay);
//! assert_eq!(d.verdict.decided_by, Some(Domain::Frequency));
//! let delay = d.verdict.effects[0].parameters["delay_s"];
//! assert!((delay / 5e-4 - 1.0).abs() < 0.05);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::diagnose::{
    diagnose, DiagnoseError, DiagnoseOptions, Diagnosis, EffectKind, EffectVerdict, Selection,
};
use crate::evidence::Evidence;
use crate::nonlinear::{
    diagnose_closed_loop, diagnose_time, diagnose_time_outputs, held_out_error,
    held_out_error_outputs, LoopFeedback, LoopRecord, TimeDiagnoseError, TimeDiagnosis,
    TimeOptions,
};
use crate::operating::{
    compare_operating_points, within_pairing_range, Finding, OperatingPointComparison, Recording,
};
use crate::stability::Cut;
use crate::{classify, ClassifyOptions};
use frf::welch::WelchOptions;
use frf::{Complex64, Frf, Samples};
use mms::model_file::ModelFile;
use mms::response::{ChainResponse, Effects};
use mms::simulate::Simulator;
use rayon::prelude::*;
use serde::Serialize;

/// The default calibration tolerance: each mass and spring within a
/// factor 1.5 of its nominal value. A model from a data sheet or a CAD
/// file is often 30 % off, and a calibration that cannot reach the
/// parameters leaves a misfit that some effect would be named for.
pub const DEFAULT_TOLERANCE: f64 = 0.5;

/// Options of [`diagnose_recording`].
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnosisOptions {
    /// Calibration bound on masses and springs: each stays within a factor
    /// `1 + tolerance` of its nominal value (dampers within the
    /// hypotheses' own wider bounds).
    pub tolerance: f64,
    /// The lines to compare, Hz; `None`: the band the classification finds
    /// informative ([`crate::classify()`]).
    pub band_hz: Option<(f64, f64)>,
    /// How an effect earns its parameters in the frequency domain: on
    /// held-out lines (the default, as the time domain does on held-out
    /// blocks), or by BIC on all lines.
    pub selection: Selection,
    /// How the recording's H1 estimate was made (segment length or
    /// period): the simulated models' curves use the same.
    pub welch: WelchOptions,
    /// The time-domain search (calibration and forward selection, which
    /// simulate the stretch hundreds of times) runs on at most this many
    /// samples from the start of an open-loop record (three times as many
    /// in a closed loop, whose reference may take longer to visit every
    /// motion); the models it chose are then refitted on the whole record
    /// and kept only if its held-out blocks confirm them
    /// ([`TimeDiagnosis::whole_record`]). The figures that compare the two
    /// domains on held-out samples use the search's stretch.
    pub time_samples: usize,
    /// Rerun the diagnosis on the halves of the record and at half the
    /// segment length, and report whether the headline holds.
    pub stability: bool,
}

impl Default for DiagnosisOptions {
    fn default() -> DiagnosisOptions {
        DiagnosisOptions {
            tolerance: DEFAULT_TOLERANCE,
            band_hz: None,
            selection: Selection::Holdout,
            welch: WelchOptions::default(),
            time_samples: 4096,
            stability: true,
        }
    }
}

/// Which half of the diagnosis decided the verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Domain {
    /// The FRF and the linear effects.
    Frequency,
    /// The samples and the nonlinear effects.
    Time,
}

/// Why the verdict is what it is (JSON: `{"kind": ..., fields}`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Reason {
    /// No line of the recording carries information (no excitation, no
    /// coherence), or fewer lines than the model has parameters: nothing
    /// can be compared, and nothing is named.
    NothingInformative,
    /// Neither domain has an effect that lowers the held-out error: the
    /// calibrated model explains the recording within its noise, or no
    /// hypothesis helps.
    NothingMissing,
    /// An FRF file: the frequency domain is the only one.
    FrequencyDomainOnly,
    /// The FRF has no informative band (a motion profile reaches few
    /// lines above the noise): the time domain alone names the effects.
    TimeDomainOnly,
    /// The model after the time-domain diagnosis still leaves this share
    /// of the output RMS, more than [`TimeOptions::informative`]: that
    /// comparison cannot decide, and the frequency domain does.
    TimeDomainNotInformative {
        /// RMS of the output error over the RMS of the output.
        unexplained: f64,
    },
    /// Only one domain names an effect.
    OnlyOneDomainNames,
    /// The model after the frequency-domain diagnosis still misses the FRF
    /// by this RMS log error (nepers, magnitude and phase together), more
    /// than [`INFORMATIVE_LOG_ERROR`] (in a closed loop the H1 estimate is
    /// biased where the loop feeds noise back): the informative time domain
    /// decides.
    FrequencyDomainNotInformative {
        /// RMS of `|ln(G_model / H)|` over the band's lines.
        log_error: f64,
    },
    /// Both domains name effects; the one whose model predicts the
    /// held-out samples better leads (both models' gains over the
    /// calibrated linear model on those samples, in noise units).
    StrongerHeldOutEvidence {
        /// The frequency domain's gain.
        frequency: f64,
        /// The time domain's gain.
        time: f64,
    },
    /// The frequency domain names effects, but its model, simulated from
    /// the recorded input, does not lower the prediction error on the
    /// held-out samples by more than `price` (its gain there, in noise
    /// units, is `gain`): what it fits in the FRF is not in the record
    /// (a bias of the estimate, leakage, a model error), so it is not
    /// named. The time domain decides.
    FrequencyEffectsNotConfirmed {
        /// The frequency domain model's gain on the held-out samples.
        gain: f64,
        /// What it had to exceed.
        price: f64,
    },
}

impl Reason {
    /// The JSON name of the reason (its `kind`).
    pub fn kind(&self) -> &'static str {
        match self {
            Reason::NothingInformative => "nothing_informative",
            Reason::NothingMissing => "nothing_missing",
            Reason::FrequencyDomainOnly => "frequency_domain_only",
            Reason::TimeDomainOnly => "time_domain_only",
            Reason::TimeDomainNotInformative { .. } => "time_domain_not_informative",
            Reason::OnlyOneDomainNames => "only_one_domain_names",
            Reason::FrequencyDomainNotInformative { .. } => "frequency_domain_not_informative",
            Reason::StrongerHeldOutEvidence { .. } => "stronger_held_out_evidence",
            Reason::FrequencyEffectsNotConfirmed { .. } => "frequency_effects_not_confirmed",
        }
    }
}

/// What a frequency-domain model must gain on the held-out samples of a
/// time record, in noise units, for its effects to be named: the price
/// the time domain's own effects pay there.
pub const CONFIRMATION_PRICE: f64 = 10.0;

/// The frequency-domain comparison is informative when the model after
/// its diagnosis meets the FRF within this RMS log error, nepers
/// (magnitude and phase together: 0.5 is a factor 1.65 or 29 degrees),
/// as the time domain's is when it leaves at most half of the output.
pub const INFORMATIVE_LOG_ERROR: f64 = 0.5;

/// The RMS log error (nepers, magnitude and phase together) by which the
/// model after a frequency-domain diagnosis misses the FRF: informative up
/// to [`INFORMATIVE_LOG_ERROR`].
pub fn log_error_after(d: &Diagnosis) -> f64 {
    let a = d.fit.after;
    ((a.rms_db * std::f64::consts::LN_10 / 20.0).powi(2) + a.rms_deg.to_radians().powi(2)).sqrt()
}

/// The reconciled verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// The domain whose effects lead; `None` when nothing is named.
    pub decided_by: Option<Domain>,
    /// The leading effect ([`EffectKind::None`] when nothing is named).
    pub headline: EffectKind,
    /// The deciding domain's kept effects, best first (`[none]` when
    /// nothing is named).
    pub effects: Vec<EffectVerdict>,
    /// Why.
    pub reason: Reason,
    /// The drop of the prediction error on the held-out lines, in noise
    /// units, from the calibrated model to the model after the
    /// frequency-domain diagnosis (`None` without it).
    pub frequency_evidence: Option<f64>,
    /// The same on the held-out samples for the time-domain diagnosis
    /// (`None` without samples).
    pub time_evidence: Option<f64>,
    /// The RMS output errors on the held-out samples (`None` without
    /// samples or held-out blocks).
    pub held_out_errors: Option<HeldOutErrors>,
    /// How the frequency domain's model did on the held-out samples within
    /// its band, against its calibrated model without the effects (`None`
    /// without samples, or when it names nothing).
    pub confirmation: Option<Confirmation>,
}

/// The frequency domain's effects checked on the samples: its calibrated
/// model and its model after the diagnosis, as fitted, simulated from the
/// recorded input and compared on the held-out samples within the band
/// the diagnosis compared ([`crate::nonlinear::held_out_band_errors`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Confirmation {
    /// The band, Hz.
    pub band_hz: (f64, f64),
    /// RMS error of the calibrated model without the effects.
    pub before: f64,
    /// RMS error of the model after the diagnosis.
    pub after: f64,
    /// The held-out samples counted as independent.
    pub effective_samples: f64,
    /// The drop of the prediction error in noise units,
    /// `effective_samples ln(before^2 / after^2)`.
    pub gain: f64,
    /// The RMS of the recorded output there within the band.
    pub output: f64,
    /// The samples can tell: the calibrated model meets the band's motion
    /// within [`CONFIRMATION_ADEQUATE`] of its RMS. Where it misses more
    /// (a slow misfit the FRF does not weigh, a model the samples do not
    /// follow), a dead time or a damping that the FRF shows plainly is
    /// lost in that error, and the check does not decide.
    pub informative: bool,
}

/// The largest share of the band's output RMS the calibrated model may
/// miss for the samples to check a frequency domain's effects
/// ([`Confirmation::informative`]).
pub const CONFIRMATION_ADEQUATE: f64 = 0.25;

/// RMS output errors on the samples held out of the time-domain fits,
/// each model's chain calibrated on the fitted samples and simulated from
/// the recorded input (or inside the loop), compared as the time-domain
/// diagnosis compares: how the frequency domain's model does in the time
/// domain, a cross-check the verdict reports but does not rest on (a
/// position's error is dominated by its slow motion, where a dead time
/// hardly shows).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HeldOutErrors {
    /// The time domain's calibrated linear model.
    pub linear: f64,
    /// The frequency domain's model after the diagnosis (`None` if it
    /// cannot be simulated).
    pub frequency_model: Option<f64>,
    /// The time domain's model after the diagnosis.
    pub time_model: f64,
}

/// The curves of the report's Bode plot, on the recording's lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Curves {
    /// Frequencies, Hz.
    pub freq_hz: Vec<f64>,
    /// The recording.
    pub recording: Vec<Complex64>,
    /// The nominal model.
    pub nominal: Vec<Complex64>,
    /// The model after the diagnosis.
    pub after: Vec<Complex64>,
    /// `true`: the models' curves are H1 estimates of their simulated
    /// outputs (the deciding model has a nonlinear effect); `false`: their
    /// transfer functions.
    pub simulated: bool,
    /// The recording's standard deviation per line, if it has one.
    pub std_dev: Option<Vec<f64>>,
    /// The recording's squared coherence per line, if it has one.
    pub coherence: Option<Vec<f64>>,
}

/// The result of [`diagnose_recording`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RecordingDiagnosis {
    /// The reconciled verdict.
    pub verdict: Verdict,
    /// The lines compared in the frequency domain, Hz (`None` when no line
    /// is informative).
    pub band_hz: Option<(f64, f64)>,
    /// The frequency-domain diagnosis on that band.
    pub frequency_domain: Option<Diagnosis>,
    /// The time-domain diagnosis of the samples, if there are any.
    pub time_domain: Option<TimeDiagnosis>,
    /// The headline rerun on the halves of the record and at half the
    /// segment length (open-loop time-domain recordings with
    /// [`DiagnosisOptions::stability`]).
    pub stability: Option<DiagnosisStability>,
    /// The model after the diagnosis: the deciding domain's (the
    /// frequency domain's calibrated model when nothing is named).
    #[serde(serialize_with = "crate::diagnose::ser_model")]
    pub model_after: ModelFile,
    /// The curves of the Bode plot.
    #[serde(skip)]
    pub curves: Curves,
}

/// Why [`diagnose_recording`] cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DiagnosisError {
    /// The frequency-domain diagnosis failed.
    #[error(transparent)]
    Frequency(#[from] DiagnoseError),
    /// The time-domain diagnosis failed.
    #[error("time-domain diagnosis: {0}")]
    Time(#[from] TimeDiagnoseError),
    /// A band with no line of the recording.
    #[error("no frequency lines in the band {0} to {1} Hz")]
    EmptyBand(f64, f64),
    /// Options out of range.
    #[error("invalid option: {0}")]
    Options(String),
}

/// Diagnoses what `model` misses of a recording: its FRF `frf` and, for a
/// time-domain recording, the `samples` it was estimated from (taken
/// inside the position loop `closed_loop`, if given); see the module
/// documentation.
pub fn diagnose_recording(
    frf: &Frf,
    samples: Option<&Samples>,
    model: &ModelFile,
    closed_loop: Option<&LoopRecord>,
    options: &DiagnosisOptions,
) -> Result<RecordingDiagnosis, DiagnosisError> {
    let o = options;
    if !(o.tolerance.is_finite() && o.tolerance > 0.0) {
        return Err(DiagnosisError::Options(format!(
            "tolerance {} must be positive",
            o.tolerance
        )));
    }
    let band = band_of(frf, model, o);
    // The time domain compares what the whole record's band holds (slower
    // motion is the drift of a free axis), in the reruns too.
    let corner = band.map(|b| b.0).filter(|&f| f > 0.0);
    let cuts = match samples {
        Some(s) if o.stability && closed_loop.is_none() => cuts(s, frf, &o.welch),
        _ => Vec::new(),
    };
    // Every diagnosis below is independent of the others: the whole
    // record's two domains and each rerun's run side by side, on as many
    // cores as there are (the time-domain parts dominate); the results do
    // not depend on which core ran them.
    let whole = || -> Result<_, DiagnosisError> {
        // The frequency domain first: its calibrated chain is where the
        // time domain starts (an output error from a chain 30 % off has
        // many local minima; the FRF's calibration has few).
        let fd = frequency_part(frf, band, model, samples.map(|s| s.fs), o)?;
        let (frequency_model, td) = match (&fd, samples) {
            (Some(f), Some(s)) => {
                let td = time_part(
                    s,
                    0..s.u.len(),
                    &time_start(model, f),
                    closed_loop,
                    corner,
                    o,
                )?;
                let error = frequency_model_error(s, model, closed_loop, f, &td, o);
                (error, Some(td))
            }
            // An FRF without information (a motion profile): the time
            // domain alone, from the model as given.
            (None, Some(s)) => {
                let td = time_part(s, 0..s.u.len(), model, closed_loop, corner, o)?;
                (None, Some(td))
            }
            _ => (None, None),
        };
        let confirmation = match (&fd, samples, band) {
            (Some(f), Some(s), Some(b)) if names(&f.effects) => {
                let w = time_window(s.u.len(), closed_loop.is_some(), o);
                let record = closed_loop.map(|l| l.window(0..w));
                confirm(
                    &s.u[..w],
                    &s.y[..w],
                    &[],
                    s.fs,
                    model,
                    f,
                    record.as_ref(),
                    b,
                    o,
                )
            }
            _ => None,
        };
        let errors = cross_check(fd.as_ref(), td.as_ref(), frequency_model);
        Ok((fd, td, errors, confirmation))
    };
    let (main, reruns) = rayon::join(whole, || {
        cuts.par_iter()
            .map(|c| rerun(c, samples, model, corner, o))
            .collect::<Vec<_>>()
    });
    let (fd, td, errors, confirmation) = main?;
    let verdict = reconcile(fd.as_ref(), td.as_ref(), errors, confirmation);
    let stability = (!cuts.is_empty()).then(|| DiagnosisStability {
        runs: reruns
            .into_iter()
            .map(|r| r.verdict(&verdict, td.as_ref()))
            .collect(),
    });
    let model_after = match (verdict.decided_by, &fd, &td) {
        (Some(Domain::Time), _, Some(t)) => t.model_after.clone(),
        (_, Some(f), _) => f.model_after.clone(),
        _ => model.clone(),
    };
    let curves = curves(frf, samples, model, &model_after, closed_loop, &o.welch)?;
    Ok(RecordingDiagnosis {
        verdict,
        band_hz: band,
        frequency_domain: fd,
        time_domain: td,
        stability,
        model_after,
        curves,
    })
}

/// One output of a recording with several sensors: its FRF, its samples
/// (for a time-domain recording) and the model's chain read at its sensor.
#[derive(Clone, Copy, Debug)]
pub struct OutputRecording<'a> {
    /// The output's FRF.
    pub frf: &'a Frf,
    /// The samples it was estimated from, if any.
    pub samples: Option<&'a Samples>,
    /// The model's chain with this output's sensor.
    pub chain: mms::Model,
}

/// The diagnosis of a recording with several sensors
/// ([`diagnose_sensors`]).
#[derive(Clone, Debug, Serialize)]
pub struct SensorsDiagnosis {
    /// Each output's own diagnosis ([`diagnose_recording`] with the chain
    /// read at its sensor), in the order given.
    pub outputs: Vec<RecordingDiagnosis>,
    /// One diagnosis of every output at once, one parameter set and one
    /// set of effects for the rig: in the frequency domain over each
    /// output's band ([`crate::diagnose::diagnose_outputs`]), in the time
    /// domain on the samples of all outputs
    /// ([`crate::nonlinear::diagnose_time_outputs`]), reconciled as one
    /// recording's two domains are (no band of its own, no reruns, no
    /// curves). `None` when an output has no informative band or the
    /// outputs have too few lines for the model.
    pub joint: Option<RecordingDiagnosis>,
}

/// Why [`diagnose_sensors`] cannot run: the output (its index) whose
/// diagnosis failed, or `None` for the joint one.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{error}")]
pub struct SensorsDiagnosisError {
    /// The output at fault, if one is.
    pub output: Option<usize>,
    /// What went wrong.
    pub error: DiagnosisError,
}

/// Diagnoses what `model` misses of a recording with several sensors:
/// each output on its own, as [`diagnose_recording`] does, and then all
/// of them at once in both domains ([`SensorsDiagnosis::joint`]), so that
/// the rig gets one verdict in which every output weighs by its own
/// uncertainty.
/// Each output's chain must be `model`'s chain read at its sensor.
///
/// A recording taken inside a position loop (`closed_loop`) is closed on
/// the first output: its controller reads that output, and every other
/// output is simulated inside the same loop and compared where its own
/// sensor sits.
///
/// ```
/// use frf::Frf;
/// use ident::diagnose::EffectKind;
/// use ident::diagnosis::{diagnose_sensors, DiagnosisOptions, OutputRecording};
/// use mms::model_file::ModelFile;
/// use mms::response::{ChainResponse, Effects};
/// use mms::{Model, Output, Port};
///
/// // Motor and load encoder of a free two-mass drive with a 0.5 ms dead
/// // time the model lacks.
/// let text = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
///             output = \"position\"\n[parameters]\nm1 = 0.02\nm2 = 0.05\n\
///             c12 = 3000\nd12 = 0.2\n";
/// let model = ModelFile::parse(text)?;
/// let load = Model::new(2, 0, Port::new(1, 0), Port::new(2, 0))?;
/// let delay = Effects { time_delay_s: Some(5e-4), ..Effects::default() };
/// let f: Vec<f64> = (0..300).map(|k| 5.0 * 1.012f64.powi(k)).collect();
/// let frf = |m: &Model| -> Result<Frf, Box<dyn std::error::Error>> {
///     let r = ChainResponse::with_effects(m, Output::Position, &delay);
///     let h = f.iter().map(|&f| r.eval(model.parameters.values(), f)).collect::<Result<_, _>>()?;
///     Ok(Frf::new(f.clone(), h, None)?)
/// };
/// let (motor, at_load) = (frf(&model.model)?, frf(&load)?);
/// let outputs = [
///     OutputRecording { frf: &motor, samples: None, chain: model.model },
///     OutputRecording { frf: &at_load, samples: None, chain: load },
/// ];
/// let d = diagnose_sensors(&outputs, &model, None, &DiagnosisOptions::default())?;
/// assert_eq!(d.outputs.len(), 2);
/// let joint = d.joint.expect("both outputs have a band");
/// assert_eq!(joint.verdict.headline, EffectKind::TimeDelay);
/// assert!((joint.verdict.effects[0].parameters["delay_s"] / 5e-4 - 1.0).abs() < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn diagnose_sensors(
    outputs: &[OutputRecording],
    model: &ModelFile,
    closed_loop: Option<&LoopRecord>,
    options: &DiagnosisOptions,
) -> Result<SensorsDiagnosis, SensorsDiagnosisError> {
    let mut each = Vec::with_capacity(outputs.len());
    for (i, out) in outputs.iter().enumerate() {
        let file = ModelFile {
            model: out.chain,
            ..model.clone()
        };
        let fail = |error| SensorsDiagnosisError {
            output: Some(i),
            error,
        };
        // The loop as this output sees it: closed on the first.
        let record = match (closed_loop, i) {
            (None, _) => None,
            (Some(l), 0) => Some(*l),
            (Some(l), _) => {
                let Some(first) = outputs[0].samples else {
                    return Err(fail(DiagnosisError::Options(
                        "a loop closed on the first output needs its samples".into(),
                    )));
                };
                Some(LoopRecord {
                    feedback: Some(LoopFeedback {
                        sensor: outputs[0].chain.sensor(),
                        y: &first.y,
                    }),
                    ..*l
                })
            }
        };
        let d = diagnose_recording(out.frf, out.samples, &file, record.as_ref(), options)
            .map_err(fail)?;
        each.push(d);
    }
    let joint = joint_diagnosis(outputs, &each, model, closed_loop, options).map_err(|error| {
        SensorsDiagnosisError {
            output: None,
            error,
        }
    })?;
    Ok(SensorsDiagnosis {
        outputs: each,
        joint,
    })
}

/// The frequency-domain diagnosis of every output at once, each over the
/// band its own diagnosis compared (`None` if one has none).
fn joint_frequency_part(
    outputs: &[OutputRecording],
    each: &[RecordingDiagnosis],
    model: &ModelFile,
    o: &DiagnosisOptions,
) -> Result<Option<Diagnosis>, DiagnosisError> {
    let mut lines = Vec::with_capacity(outputs.len());
    for (out, d) in outputs.iter().zip(each) {
        let Some((lo, hi)) = d.band_hz else {
            return Ok(None);
        };
        let data = out
            .frf
            .band(lo.max(f64::MIN_POSITIVE), hi)
            .ok_or(DiagnosisError::EmptyBand(lo, hi))?;
        lines.push(unsampled(data, model, out.chain, out.samples.map(|s| s.fs)));
    }
    let frfs: Vec<crate::diagnose::OutputFrf> = lines
        .iter()
        .zip(outputs)
        .map(|(frf, out)| crate::diagnose::OutputFrf {
            frf,
            chain: out.chain,
        })
        .collect();
    let linear = ModelFile {
        effects: model.effects.linear(),
        ..model.clone()
    };
    match crate::diagnose::diagnose_outputs(&frfs, &linear, &frequency_options(o)) {
        Ok(f) => Ok(Some(f)),
        Err(DiagnoseError::TooFewLines { .. }) => Ok(None),
        Err(e) => Err(e.into()),
    }
}

/// Every output at once, in both domains, reconciled (see
/// [`SensorsDiagnosis::joint`]).
fn joint_diagnosis(
    outputs: &[OutputRecording],
    each: &[RecordingDiagnosis],
    model: &ModelFile,
    closed_loop: Option<&LoopRecord>,
    o: &DiagnosisOptions,
) -> Result<Option<RecordingDiagnosis>, DiagnosisError> {
    let Some(fd) = joint_frequency_part(outputs, each, model, o)? else {
        return Ok(None);
    };
    let first = ModelFile {
        model: outputs[0].chain,
        ..time_start(model, &fd)
    };
    // Samples of every output (one recording: the same input).
    let samples: Option<Vec<&Samples>> = outputs.iter().map(|out| out.samples).collect();
    let td = match samples {
        None => None,
        Some(samples) => {
            let s = samples[0];
            let corner = each[0].band_hz.map(|b| b.0).filter(|&f| f > 0.0);
            let w = time_window(s.u.len(), closed_loop.is_some(), o);
            let others: Vec<(&[f64], mms::Port)> = samples[1..]
                .iter()
                .zip(&outputs[1..])
                .map(|(t, out)| (&t.y[..w.min(t.y.len())], out.chain.sensor()))
                .collect();
            let record = closed_loop.map(|l| l.window(0..w));
            let to = TimeOptions {
                search_samples: Some(w),
                ..time_options(o, corner)
            };
            let others_all: Vec<(&[f64], mms::Port)> = samples[1..]
                .iter()
                .zip(&outputs[1..])
                .map(|(t, out)| (&t.y[..], out.chain.sensor()))
                .collect();
            let td =
                diagnose_time_outputs(&s.u, &s.y, &others_all, s.fs, &first, closed_loop, &to)?;
            // The frequency domain's model on the same held-out samples of
            // every output, each weighted as the time domain weighs it.
            let weighted: Vec<(&[f64], mms::Port, f64)> = others
                .iter()
                .zip(&td.output_weights)
                .map(|(&(y, p), &w)| (y, p, w))
                .collect();
            // (An extra mass inside the chain renumbers the others' places:
            // then only the first output could be compared, so nothing is.)
            let same_chain = fd.model_after.model.n_masses() == first.model.n_masses();
            let frequency_model = same_chain
                .then(|| {
                    held_out_error_outputs(
                        &s.u[..w],
                        &s.y[..w],
                        &weighted,
                        s.fs,
                        &with_input_effects(&fd, &first),
                        record.as_ref(),
                        &scored_as(o, &td),
                    )
                })
                .flatten();
            let confirmation = names(&fd.effects)
                .then(|| {
                    let band = each
                        .iter()
                        .filter_map(|d| d.band_hz)
                        .fold((f64::INFINITY, 0.0f64), |(lo, hi), (a, b)| {
                            (lo.min(a), hi.max(b))
                        });
                    same_chain
                        .then(|| {
                            confirm(
                                &s.u[..w],
                                &s.y[..w],
                                &weighted,
                                s.fs,
                                &first,
                                &fd,
                                record.as_ref(),
                                band,
                                o,
                            )
                        })
                        .flatten()
                })
                .flatten();
            Some((td, frequency_model, confirmation))
        }
    };
    let (td, frequency_model, confirmation) = match td {
        Some((t, f, c)) => (Some(t), f, c),
        None => (None, None, None),
    };
    let errors = cross_check(Some(&fd), td.as_ref(), frequency_model);
    let verdict = reconcile(Some(&fd), td.as_ref(), errors, confirmation);
    let model_after = match (verdict.decided_by, &td) {
        (Some(Domain::Time), Some(t)) => t.model_after.clone(),
        _ => fd.model_after.clone(),
    };
    Ok(Some(RecordingDiagnosis {
        verdict,
        band_hz: None,
        frequency_domain: Some(fd),
        time_domain: td,
        stability: None,
        model_after,
        curves: Curves {
            freq_hz: Vec::new(),
            recording: Vec::new(),
            nominal: Vec::new(),
            after: Vec::new(),
            simulated: false,
            std_dev: None,
            coherence: None,
        },
    }))
}

/// The frequency-domain options of the recording's.
fn frequency_options(o: &DiagnosisOptions) -> DiagnoseOptions {
    DiagnoseOptions {
        tolerance: o.tolerance,
        selection: o.selection,
        ..DiagnoseOptions::default()
    }
}

/// The lines to compare: the user's band, else the informative one.
fn band_of(frf: &Frf, model: &ModelFile, o: &DiagnosisOptions) -> Option<(f64, f64)> {
    match o.band_hz {
        Some(b) => Some(b),
        None => crate::classify(frf, model.output, &crate::ClassifyOptions::default())
            .map(|c| c.band_hz)
            .ok(),
    }
}

/// The frequency-domain diagnosis on `band` (`None` without a band, or
/// with fewer lines than the model has parameters: nothing can be told
/// from it).
fn frequency_part(
    frf: &Frf,
    band: Option<(f64, f64)>,
    model: &ModelFile,
    fs: Option<f64>,
    o: &DiagnosisOptions,
) -> Result<Option<Diagnosis>, DiagnosisError> {
    let Some((lo, hi)) = band else {
        return Ok(None);
    };
    let data = frf
        .band(lo.max(f64::MIN_POSITIVE), hi)
        .ok_or(DiagnosisError::EmptyBand(lo, hi))?;
    let data = unsampled(data, model, model.model, fs);
    // The FRF knows nothing of the nonlinear effects.
    let linear = ModelFile {
        effects: model.effects.linear(),
        ..model.clone()
    };
    match diagnose(&data, &linear, &frequency_options(o)) {
        Ok(f) => Ok(Some(f)),
        Err(DiagnoseError::TooFewLines { .. }) => Ok(None),
        Err(e) => Err(e.into()),
    }
}

/// `frf` (estimated from samples at rate `fs`, the input held over each
/// sample) as the transfer function of `chain` times its hold's half
/// sample of delay would show it: divided, line by line, by what sampling
/// changes beyond that delay (the hold's droop, the images folded back
/// from above the Nyquist frequency; [`ChainResponse::held_factor`], from
/// `model`'s values). Those are a fraction of a percent to a few percent
/// in the top of a band that reaches a tenth of the rate, smooth in the
/// frequency: a pole-zero pair or a lag would otherwise be fitted to them.
/// Unchanged without a rate, for an acceleration (read at the instant its
/// input changes) or where the factor cannot be evaluated.
fn unsampled(frf: Frf, model: &ModelFile, chain: mms::Model, fs: Option<f64>) -> Frf {
    let Some(fs) = fs else {
        return frf;
    };
    if model.output == mms::Output::Acceleration {
        return frf;
    }
    let g = ChainResponse::new(&chain, model.output);
    let Ok(c) = g.held_factor(model.parameters.values(), frf.freq_hz(), fs) else {
        return frf;
    };
    if c.iter().any(|c| !(c.norm() > 0.0 && c.norm().is_finite())) {
        return frf;
    }
    let h: Vec<Complex64> = frf.response().iter().zip(&c).map(|(h, c)| h / c).collect();
    let coherence = frf.coherence().map(<[f64]>::to_vec);
    let std_dev = frf.std_dev().map(|s| {
        s.iter()
            .zip(&c)
            .map(|(s, c)| s / c.norm())
            .collect::<Vec<f64>>()
    });
    let Ok(out) = Frf::new(frf.freq_hz().to_vec(), h, coherence) else {
        return frf;
    };
    match std_dev {
        Some(sd) => out.with_std_dev(sd).unwrap_or(frf),
        None => out,
    }
}

/// The samples of a stretch of `len` the time-domain search uses (from
/// its start): at most [`DiagnosisOptions::time_samples`] of an open
/// loop, three times as many in a closed loop.
fn time_window(len: usize, closed: bool, o: &DiagnosisOptions) -> usize {
    let cap = o.time_samples.max(64);
    len.min(if closed { 3 * cap } else { cap })
}

/// The time-domain diagnosis of the samples in `range`: searched on
/// their first samples ([`time_window`]), checked and valued on all.
fn time_part(
    s: &Samples,
    range: std::ops::Range<usize>,
    model: &ModelFile,
    closed_loop: Option<&LoopRecord>,
    corner: Option<f64>,
    o: &DiagnosisOptions,
) -> Result<TimeDiagnosis, DiagnosisError> {
    let to = TimeOptions {
        search_samples: Some(time_window(range.len(), closed_loop.is_some(), o)),
        ..time_options(o, corner)
    };
    let (u, y) = (&s.u[range.clone()], &s.y[range.clone()]);
    Ok(match closed_loop {
        None => diagnose_time(u, y, s.fs, model, &to)?,
        Some(l) => diagnose_closed_loop(u, y, s.fs, model, &l.window(range), &to)?,
    })
}

/// How the frequency domain's model does on the held-out samples of the
/// time domain's window (`frequency_model`, from
/// [`frequency_model_error`]), next to the time domain's models.
fn cross_check(
    fd: Option<&Diagnosis>,
    td: Option<&TimeDiagnosis>,
    frequency_model: Option<f64>,
) -> Option<HeldOutErrors> {
    let (_, t) = (fd?, td?);
    let h = t.held_out?;
    Some(HeldOutErrors {
        linear: (h.before / h.samples as f64).sqrt(),
        frequency_model,
        time_model: (h.after / h.samples as f64).sqrt(),
    })
}

/// The RMS error of the frequency domain's model `f` on the held-out
/// samples of the time domain's window (the record's first samples), as
/// the time domain `t` scored its own models (with the high-pass it
/// applied, if it applied one).
fn frequency_model_error(
    s: &Samples,
    model: &ModelFile,
    closed_loop: Option<&LoopRecord>,
    f: &Diagnosis,
    t: &TimeDiagnosis,
    o: &DiagnosisOptions,
) -> Option<f64> {
    let w = time_window(s.u.len(), closed_loop.is_some(), o);
    let m = with_input_effects(f, model);
    let loop_window = closed_loop.map(|l| l.window(0..w));
    held_out_error(
        &s.u[..w],
        &s.y[..w],
        s.fs,
        &m,
        loop_window.as_ref(),
        &scored_as(o, t),
    )
}

/// The time-domain options under which `t` scored its models: its
/// high-pass, if it applied one, and no other.
fn scored_as(o: &DiagnosisOptions, t: &TimeDiagnosis) -> TimeOptions {
    TimeOptions {
        highpass_hz: t.highpass_hz,
        drift_corner_hz: None,
        ..time_options(o, None)
    }
}

/// The frequency domain's effects checked on the samples `u`, `y` (and
/// further outputs): its calibrated model against its model after, both
/// as fitted, on the held-out samples within `band`.
#[allow(clippy::too_many_arguments)]
fn confirm(
    u: &[f64],
    y: &[f64],
    others: &[(&[f64], mms::Port, f64)],
    fs: f64,
    model: &ModelFile,
    f: &Diagnosis,
    record: Option<&LoopRecord>,
    band: (f64, f64),
    o: &DiagnosisOptions,
) -> Option<Confirmation> {
    // A simulated acceleration reads its own sample's input (the mass
    // line has no hold delay, the rest half a sample), so its samples
    // differ from the transfer function the FRF was fitted with by up to
    // half a sample of phase: no check of the effects.
    if model.output == mms::Output::Acceleration {
        return None;
    }
    let before = ModelFile {
        model: model.model,
        ..f.calibrated.clone()
    };
    let after = with_input_effects(f, model);
    let (e, independent, output) = crate::nonlinear::held_out_band_errors(
        u,
        y,
        others,
        fs,
        &[&before, &after],
        record,
        band,
        &time_options(o, None),
    )?;
    Some(Confirmation {
        band_hz: band,
        before: e[0],
        after: e[1],
        effective_samples: independent,
        gain: crate::diagnose::profiled_gain(e[0] * e[0], e[1] * e[1], independent),
        output,
        informative: e[0] <= CONFIRMATION_ADEQUATE * output,
    })
}

/// Where the time domain starts: `model` with the chain's parameters of
/// the frequency domain's calibration (its effects are `model`'s own).
fn time_start(model: &ModelFile, f: &Diagnosis) -> ModelFile {
    ModelFile {
        parameters: f.calibrated.parameters.clone(),
        ..model.clone()
    }
}

/// The frequency domain's model after `f` with the input model's
/// nonlinear effects back, which the FRF could not see.
fn with_input_effects(f: &Diagnosis, model: &ModelFile) -> ModelFile {
    ModelFile {
        effects: Effects {
            coulomb_friction: model.effects.coulomb_friction,
            backlash_gap: model.effects.backlash_gap,
            offset_force: model.effects.offset_force,
            ..f.model_after.effects
        },
        ..f.model_after.clone()
    }
}

/// A cut of the record for a rerun: its cut, its samples' range and the
/// H1 options.
struct CutSpec {
    cut: Cut,
    range: std::ops::Range<usize>,
    welch: WelchOptions,
}

/// The cuts of an open-loop record: its halves at the same segment
/// length, and the whole at half the segment length (not for periodic
/// records, whose period is fixed).
fn cuts(s: &Samples, frf: &Frf, welch: &WelchOptions) -> Vec<CutSpec> {
    let n = s.u.len();
    // The segment length behind `frf`: its first line is fs / nfft.
    let nfft = frf
        .freq_hz()
        .first()
        .map_or(0, |&f| (s.fs / f).round() as usize);
    let same = WelchOptions {
        nfft: welch.period.is_none().then_some(nfft),
        ..welch.clone()
    };
    let half = match welch.period {
        Some(p) if p > 0 => n / (2 * p) * p,
        _ => n / 2,
    };
    let mut out = vec![
        CutSpec {
            cut: Cut::FirstHalf,
            range: 0..half,
            welch: same.clone(),
        },
        CutSpec {
            cut: Cut::SecondHalf,
            range: half..n,
            welch: same,
        },
    ];
    if welch.period.is_none() && nfft >= 128 {
        out.push(CutSpec {
            cut: Cut::SegmentLength(nfft / 2),
            range: 0..n,
            welch: WelchOptions {
                nfft: Some(nfft / 2),
                ..welch.clone()
            },
        });
    }
    out
}

/// A rerun's diagnoses; its time domain is `None` when it would see the
/// same samples as the whole record's (a cut that starts where the record
/// does), whose result it then shares.
struct RerunResult {
    cut: Cut,
    result: Result<RerunParts, String>,
}

/// A rerun's frequency-domain diagnosis, its time-domain one (`None` when
/// shared with the whole record's), whether it is shared, and the
/// frequency domain's check on the cut's samples.
type RerunParts = (
    Option<Diagnosis>,
    Option<TimeDiagnosis>,
    bool,
    Option<Confirmation>,
);

/// The diagnosis of one cut (open loop).
fn rerun(
    c: &CutSpec,
    samples: Option<&Samples>,
    model: &ModelFile,
    corner: Option<f64>,
    o: &DiagnosisOptions,
) -> RerunResult {
    let result = (|| -> Result<_, String> {
        let s = samples.ok_or("no samples")?;
        let est = s
            .frf(c.range.clone(), &c.welch)
            .map_err(|e| e.to_string())?;
        let band = band_of(&est, model, o);
        // The same samples as the whole record (another segment length):
        // the same time-domain result, shared.
        let here = time_window(c.range.len(), false, o);
        let shared = c.range == (0..s.u.len());
        let fd = frequency_part(&est, band, model, Some(s.fs), o).map_err(|e| e.to_string())?;
        let start = fd
            .as_ref()
            .map_or_else(|| model.clone(), |f| time_start(model, f));
        let td = (!shared)
            .then(|| {
                time_part(s, c.range.clone(), &start, None, corner, o).map_err(|e| e.to_string())
            })
            .transpose()?;
        let confirmation = match (&fd, band) {
            (Some(f), Some(b)) if names(&f.effects) => {
                let w = c.range.start..c.range.start + here;
                confirm(&s.u[w.clone()], &s.y[w], &[], s.fs, model, f, None, b, o)
            }
            _ => None,
        };
        Ok((fd, td, shared, confirmation))
    })();
    RerunResult { cut: c.cut, result }
}

impl RerunResult {
    /// The rerun's verdict against the whole record's.
    fn verdict(self, whole: &Verdict, whole_td: Option<&TimeDiagnosis>) -> DiagnosisRerun {
        match self.result {
            Ok((fd, td, shared, confirmation)) => {
                let td = if shared { whole_td.cloned() } else { td };
                let v = reconcile(fd.as_ref(), td.as_ref(), None, confirmation);
                DiagnosisRerun {
                    cut: self.cut,
                    same_headline: v.headline == whole.headline,
                    headline: v.headline,
                    decided_by: v.decided_by,
                    error: None,
                }
            }
            Err(e) => DiagnosisRerun {
                cut: self.cut,
                headline: EffectKind::None,
                decided_by: None,
                error: Some(e),
                same_headline: false,
            },
        }
    }
}

/// A rerun of the diagnosis on another cut of the record.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DiagnosisRerun {
    /// The cut.
    pub cut: Cut,
    /// Its headline.
    pub headline: EffectKind,
    /// Which domain decided it.
    pub decided_by: Option<Domain>,
    /// Why it could not run, if it could not.
    pub error: Option<String>,
    /// The same headline as the whole record's.
    pub same_headline: bool,
}

/// The reruns of a diagnosis on the halves of the record and at half the
/// segment length.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DiagnosisStability {
    /// One per cut.
    pub runs: Vec<DiagnosisRerun>,
}

impl DiagnosisStability {
    /// No rerun changed the headline.
    pub fn stable(&self) -> bool {
        self.runs.iter().all(|r| r.same_headline)
    }
}

/// The options of the time-domain half, compared above `corner`.
fn time_options(o: &DiagnosisOptions, corner: Option<f64>) -> TimeOptions {
    TimeOptions {
        drift_corner_hz: corner,
        tolerance: o.tolerance,
        welch: o.welch.clone(),
        ..TimeOptions::default()
    }
}

/// Whether a diagnosis names an effect.
fn names(effects: &[EffectVerdict]) -> bool {
    effects.first().is_some_and(|e| e.kind != EffectKind::None)
}

/// The verdict from the two domains' diagnoses.
fn reconcile(
    fd: Option<&Diagnosis>,
    td: Option<&TimeDiagnosis>,
    held_out_errors: Option<HeldOutErrors>,
    confirmation: Option<Confirmation>,
) -> Verdict {
    // The drops are -2 ln of likelihood ratios on held-out data in both
    // domains: lines with their measured uncertainty, samples with the
    // noise level profiled out.
    let none = || {
        vec![EffectVerdict {
            kind: EffectKind::None,
            parameters: Default::default(),
            evidence: Evidence::Nothing { best: None },
            score: 0.0,
            step: 0,
            unresolved: None,
            standard_errors: Default::default(),
        }]
    };
    let frequency_evidence = fd.map(|d| d.held_out.map_or(0.0, |h| h.evidence()));
    let time_evidence = td.map(|d| d.held_out.map_or(0.0, |h| h.evidence()));
    let verdict = |domain: Option<Domain>, reason: Reason| {
        let effects = match domain {
            Some(Domain::Frequency) => fd.map_or_else(none, |d| d.effects.clone()),
            Some(Domain::Time) => td.map_or_else(none, |d| d.effects.clone()),
            None => none(),
        };
        Verdict {
            decided_by: domain,
            headline: effects[0].kind,
            effects,
            reason,
            frequency_evidence,
            time_evidence,
            held_out_errors,
            confirmation,
        }
    };
    let Some(fd) = fd else {
        return match td {
            Some(t) if t.informative && names(&t.effects) => {
                verdict(Some(Domain::Time), Reason::TimeDomainOnly)
            }
            Some(t) if t.informative => verdict(None, Reason::NothingMissing),
            _ => verdict(None, Reason::NothingInformative),
        };
    };
    let fd_names = names(&fd.effects);
    let Some(td) = td else {
        return match fd_names {
            true => verdict(Some(Domain::Frequency), Reason::FrequencyDomainOnly),
            false => verdict(None, Reason::NothingMissing),
        };
    };
    if !td.informative {
        let reason = Reason::TimeDomainNotInformative {
            unexplained: td.fit.after.rms_time_rel,
        };
        return verdict(fd_names.then_some(Domain::Frequency), reason);
    }
    let log_error = log_error_after(fd);
    if log_error > INFORMATIVE_LOG_ERROR && names(&td.effects) {
        return verdict(
            Some(Domain::Time),
            Reason::FrequencyDomainNotInformative { log_error },
        );
    }
    let td_names = names(&td.effects);
    // One criterion for both domains: the prediction error on the same
    // held-out samples. A frequency-domain model must lower it too, or
    // what it fits is not in the record.
    let on_samples = td.held_out.zip(held_out_errors).and_then(|(h, e)| {
        let gain = |rms: f64| {
            crate::diagnose::profiled_gain(e.linear * e.linear, rms * rms, h.effective_samples)
        };
        e.frequency_model.map(|f| (gain(f), gain(e.time_model)))
    });
    if fd_names {
        if let Some(c) = confirmation.filter(|c| c.informative) {
            if c.gain <= CONFIRMATION_PRICE {
                let reason = Reason::FrequencyEffectsNotConfirmed {
                    gain: c.gain,
                    price: CONFIRMATION_PRICE,
                };
                return verdict(td_names.then_some(Domain::Time), reason);
            }
        }
    }
    match (fd_names, td_names) {
        (false, false) => verdict(None, Reason::NothingMissing),
        (true, false) => verdict(Some(Domain::Frequency), Reason::OnlyOneDomainNames),
        (false, true) => verdict(Some(Domain::Time), Reason::OnlyOneDomainNames),
        (true, true) => {
            let (f, t) = on_samples.unwrap_or((
                frequency_evidence.unwrap_or(0.0),
                time_evidence.unwrap_or(0.0),
            ));
            let domain = if t > f {
                Domain::Time
            } else {
                Domain::Frequency
            };
            verdict(
                Some(domain),
                Reason::StrongerHeldOutEvidence {
                    frequency: f,
                    time: t,
                },
            )
        }
    }
}

/// The Bode plot's curves: the transfer functions of the nominal model and
/// the model after, or, when either has a nonlinear effect, the H1
/// estimates of their outputs simulated from the recorded input (in a
/// closed loop: inside the loop), with the recording's H1 options so that
/// the curves share its lines.
fn curves(
    frf: &Frf,
    samples: Option<&Samples>,
    nominal: &ModelFile,
    after: &ModelFile,
    closed_loop: Option<&LoopRecord>,
    welch: &WelchOptions,
) -> Result<Curves, DiagnosisError> {
    let nonlinear = |m: &ModelFile| m.effects.linear() != m.effects;
    let simulated = samples.is_some() && (nonlinear(nominal) || nonlinear(after));
    let curve = |m: &ModelFile| -> Result<Vec<Complex64>, DiagnosisError> {
        match (samples, simulated) {
            (Some(s), true) => simulated_frf(m, s, closed_loop, welch, frf),
            _ => Ok(transfer_function(m, frf.freq_hz())),
        }
    };
    Ok(Curves {
        freq_hz: frf.freq_hz().to_vec(),
        recording: frf.response().to_vec(),
        nominal: curve(nominal)?,
        after: curve(after)?,
        simulated,
        std_dev: frf.std_dev().map(<[f64]>::to_vec),
        coherence: frf.coherence().map(<[f64]>::to_vec),
    })
}

/// The model's transfer function (its linear effects) on `f`; NaN where it
/// cannot be evaluated (a plot leaves such points out).
fn transfer_function(m: &ModelFile, f: &[f64]) -> Vec<Complex64> {
    let g = ChainResponse::with_effects(&m.model, m.output, &m.effects.linear());
    f.iter()
        .map(|&f| {
            g.eval(m.parameters.values(), f)
                .map(|v| v * m.gain)
                .unwrap_or(Complex64::new(f64::NAN, f64::NAN))
        })
        .collect()
}

/// The H1 estimate of `m`'s output simulated from the recorded input (or
/// inside the recorded loop), on the lines of `like`.
fn simulated_frf(
    m: &ModelFile,
    s: &Samples,
    closed_loop: Option<&LoopRecord>,
    welch: &WelchOptions,
    like: &Frf,
) -> Result<Vec<Complex64>, DiagnosisError> {
    let sim =
        Simulator::new(m, s.fs, &crate::nonlinear::RECORDED).map_err(TimeDiagnoseError::from)?;
    let run = match closed_loop {
        None => sim.run(&s.u).map(|y| (s.u.clone(), y)),
        Some(l) => sim
            .run_closed_loop(&l.closed_loop(&s.y, s.fs))
            .map(|run| (run.u, run.y)),
    };
    // A model that diverges inside the loop has no curve to draw: the plot
    // leaves it out, the verdict stands.
    let (u, y) = match run {
        Ok(r) => r,
        Err(mms::simulate::SimulateError::Diverged(_)) => {
            return Ok(vec![Complex64::new(f64::NAN, f64::NAN); like.len()]);
        }
        Err(e) => return Err(TimeDiagnoseError::from(e).into()),
    };
    // Same options, same lines; a different grid (it cannot happen with
    // the recording's own options) or an output with no estimate (a
    // simulation that left the finite numbers) leaves the curve out.
    match frf::h1(&u, &y, s.fs, welch) {
        Ok(est) if est.frf.freq_hz() == like.freq_hz() => Ok(est.frf.response().to_vec()),
        _ => Ok(vec![Complex64::new(f64::NAN, f64::NAN); like.len()]),
    }
}

/// A diagnosis checked on another recording of the same rig
/// ([`validate`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Validation {
    /// The structure of the model after the first diagnosis.
    pub structure: String,
    /// The structure of the model after the diagnosis of the other
    /// recording with the same nominal model.
    pub other_structure: String,
    /// Each effect of the first verdict and what the other recording
    /// gives for it.
    pub effects: Vec<CarriedEffect>,
    /// The low-frequency phase lag of the models after the two diagnoses,
    /// seconds: the dead time plus `1 / (2 pi f_c)` of a first-order lag,
    /// which one record may split differently from another (`None` when
    /// neither model has either).
    pub phase_lag_s: Option<(f64, f64)>,
    /// Errors on the other recording's band.
    pub fit_on_other: FitOnOther,
    /// The other recording's own diagnosis.
    pub other: Box<RecordingDiagnosis>,
}

/// One effect of a diagnosis on another recording.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CarriedEffect {
    /// The effect.
    pub kind: EffectKind,
    /// Its parameter.
    pub parameter: String,
    /// Its value from the first recording.
    pub value: f64,
    /// Its value from the other recording, if that diagnosis keeps the
    /// same kind (in either domain).
    pub other_value: Option<f64>,
    /// `other_value / value - 1`.
    pub change: Option<f64>,
}

/// How the models do on the other recording's FRF (its band).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FitOnOther {
    /// The nominal model.
    pub nominal: crate::diagnose::FitSummary,
    /// The model after the first recording's diagnosis, as it is.
    pub first_model: crate::diagnose::FitSummary,
    /// The model after the other recording's own diagnosis.
    pub own_model: crate::diagnose::FitSummary,
}

/// Checks the diagnosis `first` of one recording on another recording of
/// the same rig (`frf`, `samples`, taken inside `closed_loop` if given):
/// diagnoses it with the same nominal `model` and `options`, and says
/// which effects and parameters carry over and how the first model after
/// the diagnosis, unchanged, fits the other recording.
pub fn validate(
    first: &RecordingDiagnosis,
    frf: &Frf,
    samples: Option<&Samples>,
    model: &ModelFile,
    closed_loop: Option<&LoopRecord>,
    options: &DiagnosisOptions,
) -> Result<Validation, DiagnosisError> {
    let other = diagnose_recording(frf, samples, model, closed_loop, options)?;
    let kept = |d: &RecordingDiagnosis| -> Vec<EffectVerdict> {
        let mut all = Vec::new();
        if let Some(f) = &d.frequency_domain {
            all.extend(f.effects.iter().cloned());
        }
        if let Some(t) = &d.time_domain {
            all.extend(t.effects.iter().cloned());
        }
        all
    };
    let theirs = kept(&other);
    let mut effects = Vec::new();
    for e in first
        .verdict
        .effects
        .iter()
        .filter(|e| e.kind != EffectKind::None)
    {
        for (name, &value) in &e.parameters {
            let other_value = theirs
                .iter()
                .find(|t| t.kind == e.kind)
                .and_then(|t| t.parameters.get(name).copied());
            effects.push(CarriedEffect {
                kind: e.kind,
                parameter: name.clone(),
                value,
                other_value,
                change: other_value.map(|v| v / value - 1.0),
            });
        }
    }
    let lag = |m: &ModelFile| -> Option<f64> {
        let e = &m.effects;
        if e.time_delay_s.is_none() && e.lowpass_hz.is_none() {
            return None;
        }
        Some(
            e.time_delay_s.unwrap_or(0.0)
                + e.lowpass_hz
                    .map_or(0.0, |f| 1.0 / (2.0 * std::f64::consts::PI * f)),
        )
    };
    let phase_lag_s = match (lag(&first.model_after), lag(&other.model_after)) {
        (None, None) => None,
        (a, b) => Some((a.unwrap_or(0.0), b.unwrap_or(0.0))),
    };
    // The other recording's band (all of it if nothing was informative).
    let data = match other.band_hz {
        Some((lo, hi)) => frf
            .band(lo.max(f64::MIN_POSITIVE), hi)
            .ok_or(DiagnosisError::EmptyBand(lo, hi))?,
        None => frf.clone(),
    };
    let on = |m: &ModelFile| {
        let g = transfer_function(m, data.freq_hz());
        let e: Vec<Complex64> = g
            .iter()
            .zip(data.response())
            .map(|(g, h)| (g / h).ln())
            .filter(|z| z.is_finite())
            .collect();
        crate::diagnose::summary(&e)
    };
    Ok(Validation {
        structure: first.model_after.model.id(),
        other_structure: other.model_after.model.id(),
        effects,
        phase_lag_s,
        fit_on_other: FitOnOther {
            nominal: on(model),
            first_model: on(&first.model_after),
            own_model: on(&other.model_after),
        },
        other: Box::new(other),
    })
}

/// The low-frequency phase lag of a dead time (its delay) or a
/// first-order lag (`1 / (2 pi f_c)`), s; `None` for other effects.
fn phase_lag(e: &EffectVerdict) -> Option<f64> {
    match e.kind {
        EffectKind::TimeDelay => e.parameters.get("delay_s").copied(),
        EffectKind::Lowpass => e
            .parameters
            .get("corner_hz")
            .map(|f| 1.0 / (2.0 * std::f64::consts::PI * f)),
        _ => None,
    }
}

/// Which of two operating points a verdict holds for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HoldsFor {
    /// Both recordings.
    Both,
    /// The first recording only.
    First,
    /// The second recording only.
    Second,
}

/// One effect's parameter at two operating points.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectAcross {
    /// The effect (in the first recording that names it).
    pub kind: EffectKind,
    /// The other recording's kind where it differs: a dead time in one
    /// and a first-order lag in the other are one phase lag, compared by
    /// the parameter `lag_s` (the dead time, or the lag's `1 / (2 pi f_c)`,
    /// its delay at frequencies well below the corner).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other_kind: Option<EffectKind>,
    /// Its parameter.
    pub parameter: String,
    /// Its value at the first and the second operating point, where that
    /// recording's verdict names the effect.
    pub values: (Option<f64>, Option<f64>),
    /// Which recordings name it.
    pub holds_for: HoldsFor,
}

/// Two recordings of one rig at different operating points, each
/// diagnosed with the same model ([`compare_operating_diagnoses`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OperatingPointDiagnosis {
    /// Every effect either verdict names, the first recording's first.
    pub effects: Vec<EffectAcross>,
    /// The two FRFs compared feature by feature, each classified on its
    /// diagnosis's band ([`crate::operating`]).
    pub features: Option<OperatingPointComparison>,
    /// The resonance (Hz) of an extra mass that only one diagnosis adds
    /// and that lies within the pairing range of the pre-sliding friction
    /// the feature comparison names in that recording: one finding seen
    /// twice (the chain can take a stiffness to ground only as one more
    /// mass).
    pub pre_sliding_as_extra_mode: Option<f64>,
    /// The pre-sliding friction one diagnosis names, where the feature
    /// comparison names it in the same recording: one finding seen by two
    /// methods.
    pub pre_sliding_named: Option<PreSlidingSeenTwice>,
    /// The structure of the model after each diagnosis.
    pub structures: (String, String),
}

/// The pre-sliding friction named by a diagnosis (a fitted spring to the
/// ground) and by the feature comparison (a resonance that only one
/// operating point has).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PreSlidingSeenTwice {
    /// The recording both name it in.
    pub recording: Recording,
    /// The stiffness the diagnosis fitted (with its calibrated chain).
    pub fitted_n_per_m: f64,
    /// The stiffness from the resonance and the other recording's
    /// rigid-body inertia, if that could be read.
    pub from_features_n_per_m: Option<f64>,
    /// The resonance the feature comparison read (Hz).
    pub freq_hz: f64,
}

/// Compares the diagnoses `first` (of `first_frf`) and `second` (of
/// `second_frf`) of one rig at two operating points, both made with the
/// same model: which effects each verdict names and with which values (an
/// extra mass holds for both only if it adds its resonance within the
/// pairing range of [`crate::operating`] in both), and
/// the two FRFs feature by feature (`None` if either cannot be
/// classified).
///
/// ```
/// use frf::{Complex64, Frf};
/// use ident::diagnosis::{compare_operating_diagnoses, diagnose_recording, DiagnosisOptions, HoldsFor};
/// use ident::diagnose::EffectKind;
/// use mms::model_file::ModelFile;
///
/// // A two-mass drive seen at the motor; at the second operating point
/// // its measurement lags by a dead time of 1 ms, the first has none.
/// let text = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
///             output = \"position\"\n[parameters]\nm1 = 1e-3\nm2 = 1e-3\nc12 = 40\nd12 = 0.002\n";
/// let model = ModelFile::parse(text)?;
/// let f: Vec<f64> = (1..=600).map(|k| 0.25 * k as f64).collect();
/// let g = mms::response::ChainResponse::new(&model.model, model.output)
///     .eval_many(model.parameters.values(), &f)?;
/// let frf = |delay: f64| -> Frf {
///     let h = g.iter().zip(&f).map(|(g, &f)| {
///         g * Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * f * delay)
///     });
///     Frf::new(f.clone(), h.collect(), None).unwrap()
/// };
/// let (a, b) = (frf(0.0), frf(1e-3));
/// let o = DiagnosisOptions::default();
/// let da = diagnose_recording(&a, None, &model, None, &o)?;
/// let db = diagnose_recording(&b, None, &model, None, &o)?;
/// let c = compare_operating_diagnoses(&da, &a, &db, &b);
/// let delay = c.effects.iter().find(|e| e.kind == EffectKind::TimeDelay).unwrap();
/// assert_eq!(delay.holds_for, HoldsFor::Second);
/// assert!((delay.values.1.unwrap() / 1e-3 - 1.0).abs() < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn compare_operating_diagnoses(
    first: &RecordingDiagnosis,
    first_frf: &Frf,
    second: &RecordingDiagnosis,
    second_frf: &Frf,
) -> OperatingPointDiagnosis {
    fn named(d: &RecordingDiagnosis) -> Vec<&EffectVerdict> {
        d.verdict
            .effects
            .iter()
            .filter(|e| e.kind != EffectKind::None)
            .collect()
    }
    let (ours, theirs) = (named(first), named(second));
    // One effect at both operating points: the same kind; for an extra
    // mass also the same added resonance (another mode is another effect);
    // a dead time and a first-order lag with the same low-frequency lag are
    // one phase lag.
    let same = |a: &EffectVerdict, b: &EffectVerdict| {
        if a.kind != b.kind {
            return match (phase_lag(a), phase_lag(b)) {
                (Some(x), Some(y)) => within_pairing_range(x, y),
                _ => false,
            };
        }
        a.kind != EffectKind::ExtraMode
            || match (
                a.parameters.get("resonance_hz"),
                b.parameters.get("resonance_hz"),
            ) {
                (Some(&x), Some(&y)) => within_pairing_range(x, y),
                _ => false,
            }
    };
    let mut effects: Vec<EffectAcross> = Vec::new();
    let across = |e: &EffectVerdict, other: Option<&EffectVerdict>, first: bool| {
        if let Some(o) = other.filter(|o| o.kind != e.kind) {
            let (a, b) = (phase_lag(e), phase_lag(o));
            return vec![EffectAcross {
                kind: e.kind,
                other_kind: Some(o.kind),
                parameter: "lag_s".to_string(),
                values: if first { (a, b) } else { (b, a) },
                holds_for: HoldsFor::Both,
            }];
        }
        e.parameters
            .iter()
            .map(|(p, &v)| {
                let w = other.and_then(|o| o.parameters.get(p).copied());
                EffectAcross {
                    kind: e.kind,
                    other_kind: None,
                    parameter: p.clone(),
                    values: if first { (Some(v), w) } else { (w, Some(v)) },
                    holds_for: match (other.is_some(), first) {
                        (true, _) => HoldsFor::Both,
                        (false, true) => HoldsFor::First,
                        (false, false) => HoldsFor::Second,
                    },
                }
            })
            .collect::<Vec<_>>()
    };
    for &e in &ours {
        effects.extend(across(e, theirs.iter().copied().find(|t| same(e, t)), true));
    }
    for &t in theirs.iter().filter(|t| !ours.iter().any(|e| same(e, t))) {
        effects.extend(across(t, None, false));
    }
    let output = first.model_after.output;
    let classified = |d: &RecordingDiagnosis, frf: &Frf| {
        let o = ClassifyOptions {
            band_hz: d.band_hz,
            ..ClassifyOptions::default()
        };
        classify(frf, output, &o).ok()
    };
    let features = classified(first, first_frf)
        .zip(classified(second, second_frf))
        .map(|(a, b)| compare_operating_points(&a, first_frf, &b, second_frf));
    // The pre-sliding frictions the feature comparison names: the recording,
    // the resonance and the stiffness from the other's inertia.
    let pre_sliding = || {
        features
            .iter()
            .flat_map(|f| &f.findings)
            .filter_map(|finding| match finding {
                Finding::PreSlidingFriction {
                    recording,
                    freq_hz,
                    stiffness,
                } => Some((*recording, *freq_hz, *stiffness)),
                _ => None,
            })
    };
    let pre_sliding_as_extra_mode = pre_sliding().find_map(|(recording, freq_hz, _)| {
        let holds = match recording {
            Recording::First => HoldsFor::First,
            Recording::Second => HoldsFor::Second,
        };
        effects
            .iter()
            .filter(|e| {
                e.kind == EffectKind::ExtraMode
                    && e.parameter == "resonance_hz"
                    && e.holds_for == holds
            })
            .filter_map(|e| e.values.0.or(e.values.1))
            .find(|&r| within_pairing_range(r, freq_hz))
    });
    let pre_sliding_named = pre_sliding().find_map(|(recording, freq_hz, stiffness)| {
        let d = match recording {
            Recording::First => first,
            Recording::Second => second,
        };
        let fitted = d
            .verdict
            .effects
            .iter()
            .find(|e| e.kind == EffectKind::PreSlidingFriction)?
            .parameters
            .get("pre_sliding_n_per_m")
            .copied()?;
        Some(PreSlidingSeenTwice {
            recording,
            fitted_n_per_m: fitted,
            from_features_n_per_m: stiffness,
            freq_hz,
        })
    });
    OperatingPointDiagnosis {
        effects,
        features,
        pre_sliding_as_extra_mode,
        pre_sliding_named,
        structures: (first.model_after.model.id(), second.model_after.model.id()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reason's name is its JSON `kind`, for every reason.
    #[test]
    fn reason_kind_is_the_json_kind() {
        let all = [
            Reason::NothingInformative,
            Reason::NothingMissing,
            Reason::FrequencyDomainOnly,
            Reason::TimeDomainNotInformative { unexplained: 0.7 },
            Reason::OnlyOneDomainNames,
            Reason::FrequencyDomainNotInformative { log_error: 0.6 },
            Reason::StrongerHeldOutEvidence {
                frequency: 1.0,
                time: 2.0,
            },
            Reason::FrequencyEffectsNotConfirmed {
                gain: -3.0,
                price: CONFIRMATION_PRICE,
            },
        ];
        for r in all {
            let v = serde_json::to_value(r).unwrap();
            assert_eq!(v["kind"], r.kind(), "{v}");
        }
    }
}
