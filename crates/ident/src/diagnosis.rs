//! One call from a recording and a model to one reconciled verdict:
//! [`diagnose_recording`].
//!
//! The frequency-domain hypotheses ([`crate::diagnose`]: dead time, lag,
//! gain error, hysteretic damping, viscous friction, an extra mode) are
//! tried on the recording's FRF, every line weighted by its uncertainty
//! ([`frf::uncertainty`]); a time-domain recording also gets the
//! time-domain hypotheses ([`crate::nonlinear`]: Coulomb friction,
//! backlash, a force offset) on its samples. Each domain keeps only effects
//! that lower the prediction error on data held out of its fits (every
//! fourth line; every fourth block of the record). The two then compete on
//! one criterion both can be scored on: the share of the held-out misfit
//! beyond the noise that the kept effects remove. The headline is the
//! effect that wins there, and [`Verdict`] says which domain decided and
//! why. A time-domain comparison in which the calibrated linear model
//! leaves most of the output unexplained is not informative and cannot
//! lead.
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
use crate::nonlinear::{
    diagnose_closed_loop, diagnose_time, LoopRecord, TimeDiagnoseError, TimeDiagnosis, TimeOptions,
};
use frf::welch::WelchOptions;
use frf::{Complex64, Frf, Samples};
use mms::model_file::ModelFile;
use mms::response::{ChainResponse, Effects};
use mms::simulate::{ClosedLoop, SimOptions, Simulator};
use serde::Serialize;

/// Options of [`diagnose_recording`].
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnosisOptions {
    /// Calibration bound on masses and springs: each stays within a factor
    /// `1 + tolerance` of its nominal value (dampers within the
    /// hypotheses' own wider bounds).
    pub tolerance: f64,
    /// The lines to compare, Hz; `None`: the band the classification finds
    /// informative ([`crate::classify`]).
    pub band_hz: Option<(f64, f64)>,
    /// How an effect earns its parameters in the frequency domain: on
    /// held-out lines (the default, as the time domain does on held-out
    /// blocks), or by BIC on all lines.
    pub selection: Selection,
    /// How the recording's H1 estimate was made (segment length or
    /// period): the simulated models' curves use the same.
    pub welch: WelchOptions,
}

impl Default for DiagnosisOptions {
    fn default() -> DiagnosisOptions {
        DiagnosisOptions {
            tolerance: 0.2,
            band_hz: None,
            selection: Selection::Holdout,
            welch: WelchOptions::default(),
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
    /// The model after the time-domain diagnosis still leaves this share
    /// of the output RMS, more than [`TimeOptions::informative`]: that
    /// comparison cannot decide, and the frequency domain does.
    TimeDomainNotInformative {
        /// RMS of the output error over the RMS of the output.
        unexplained: f64,
    },
    /// Only one domain names an effect.
    OnlyOneDomainNames,
    /// Both domains name effects; the one whose effects remove the larger
    /// share of the held-out misfit leads.
    LargerHeldOutShare {
        /// Share removed by the frequency-domain effects.
        frequency: f64,
        /// Share removed by the time-domain effects.
        time: f64,
    },
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
    /// The share of the held-out misfit the frequency-domain effects
    /// remove (`None` without a frequency-domain diagnosis).
    pub frequency_share: Option<f64>,
    /// The same for the time-domain effects (`None` without samples).
    pub time_share: Option<f64>,
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
    // The lines to compare: the user's band, else the informative one.
    let band = match o.band_hz {
        Some(b) => Some(b),
        None => crate::classify(frf, model.output, &crate::ClassifyOptions::default())
            .map(|c| c.band_hz)
            .ok(),
    };
    let data = match band {
        Some((lo, hi)) => Some(
            frf.band(lo.max(f64::MIN_POSITIVE), hi)
                .ok_or(DiagnosisError::EmptyBand(lo, hi))?,
        ),
        None => None,
    };
    // The FRF knows nothing of the nonlinear effects.
    let mut linear = model.clone();
    linear.effects.coulomb_friction = None;
    linear.effects.backlash_gap = None;
    linear.effects.offset_force = None;
    let fd_options = DiagnoseOptions {
        tolerance: o.tolerance,
        selection: o.selection,
        ..DiagnoseOptions::default()
    };
    // A band with fewer lines than the model has parameters is as good as
    // none: nothing can be told from it.
    let fd = match &data {
        Some(d) => match diagnose(d, &linear, &fd_options) {
            Ok(f) => Some(f),
            Err(DiagnoseError::TooFewLines { .. }) => None,
            Err(e) => return Err(e.into()),
        },
        None => None,
    };
    let td = match samples {
        Some(s) if fd.is_some() => {
            let to = TimeOptions {
                // The time domain compares what the FRF band holds: slower
                // motion is the drift of a free axis.
                highpass_hz: band.map(|b| b.0).filter(|&f| f > 0.0),
                tolerance: o.tolerance,
                welch: o.welch.clone(),
                ..TimeOptions::default()
            };
            Some(match closed_loop {
                None => diagnose_time(&s.u, &s.y, s.fs, model, &to)?,
                Some(l) => diagnose_closed_loop(&s.u, &s.y, s.fs, model, l, &to)?,
            })
        }
        _ => None,
    };
    let verdict = reconcile(fd.as_ref(), td.as_ref());
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
        model_after,
        curves,
    })
}

/// Whether a diagnosis names an effect.
fn names(effects: &[EffectVerdict]) -> bool {
    effects.first().is_some_and(|e| e.kind != EffectKind::None)
}

/// The verdict from the two domains' diagnoses.
fn reconcile(fd: Option<&Diagnosis>, td: Option<&TimeDiagnosis>) -> Verdict {
    let none = || {
        vec![EffectVerdict {
            kind: EffectKind::None,
            parameters: Default::default(),
            evidence: String::new(),
            score: 0.0,
            step: 0,
        }]
    };
    let frequency_share = fd.map(|d| d.held_out.map_or(0.0, |h| h.explained()));
    let time_share = td.map(|d| d.held_out.map_or(0.0, |h| h.explained()));
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
            frequency_share,
            time_share,
        }
    };
    let Some(fd) = fd else {
        return verdict(None, Reason::NothingInformative);
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
    match (fd_names, names(&td.effects)) {
        (false, false) => verdict(None, Reason::NothingMissing),
        (true, false) => verdict(Some(Domain::Frequency), Reason::OnlyOneDomainNames),
        (false, true) => verdict(Some(Domain::Time), Reason::OnlyOneDomainNames),
        (true, true) => {
            let (f, t) = (frequency_share.unwrap_or(0.0), time_share.unwrap_or(0.0));
            let domain = if t > f {
                Domain::Time
            } else {
                Domain::Frequency
            };
            verdict(
                Some(domain),
                Reason::LargerHeldOutShare {
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
    let nonlinear = |m: &ModelFile| {
        m.effects.coulomb_friction.is_some()
            || m.effects.backlash_gap.is_some()
            || m.effects.offset_force.is_some()
    };
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
    })
}

/// The model's transfer function (its linear effects) on `f`; NaN where it
/// cannot be evaluated (a plot leaves such points out).
fn transfer_function(m: &ModelFile, f: &[f64]) -> Vec<Complex64> {
    let linear = Effects {
        coulomb_friction: None,
        backlash_gap: None,
        offset_force: None,
        ..m.effects
    };
    let g = ChainResponse::with_effects(&m.model, m.output, &linear);
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
    let sim = Simulator::new(m, s.fs, &SimOptions::default()).map_err(TimeDiagnoseError::from)?;
    let (u, y) = match closed_loop {
        None => (s.u.clone(), sim.run(&s.u).map_err(TimeDiagnoseError::from)?),
        Some(l) => {
            let q = &s.y;
            let run = sim
                .run_closed_loop(&ClosedLoop {
                    controller: l.controller,
                    reference: l.reference,
                    disturbance: l.disturbance,
                    initial_position: q[0],
                    initial_velocity: (q[2] - q[0]) * s.fs / 2.0,
                })
                .map_err(TimeDiagnoseError::from)?;
            (run.u, run.y)
        }
    };
    let est = frf::h1(&u, &y, s.fs, welch)
        .map_err(|e| TimeDiagnoseError::Input(format!("H1 of the simulated output: {e}")))?;
    // Same options, same lines; a different grid (it cannot happen with
    // the recording's own options) leaves the curve out.
    if est.frf.freq_hz() != like.freq_hz() {
        return Ok(vec![Complex64::new(f64::NAN, f64::NAN); like.len()]);
    }
    Ok(est.frf.response().to_vec())
}
