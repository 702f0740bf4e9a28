//! Time-domain diagnosis of nonlinear effects: given the sampled input
//! `u[k]` (actuator force before the model's gain), output `y[k]` and a
//! model that should describe them, decide whether Coulomb friction
//! (`friction {coulomb_n}`), backlash (`backlash {gap}`) or a constant
//! force offset (`offset {force_n}`) is missing, several of them, or
//! nothing ([`diagnose_time`]). A record taken in a closed position loop
//! is simulated inside that loop ([`diagnose_closed_loop`]): the recorded
//! controller, driven by the simulated position and the recorded
//! reference, keeps the simulation on the reference as it kept the real
//! system, where an open-loop simulation from the recorded input would
//! integrate every force error into a drift.
//!
//! Steps:
//!
//! 1. **Evidence** the FRF alone cannot give: the H1 estimate's coherence
//!    (a nonlinearity turns part of the output into "noise" uncorrelated
//!    with the input), the FRF of the record's first half against its
//!    second half (amplitude dependence when the two halves have different
//!    input levels, compared with the coherence's noise), and, for a
//!    periodic input with unexcited lines, the output at unexcited odd and
//!    even lines (odd harmonics are the mark of an odd nonlinearity such as
//!    friction or backlash).
//! 2. **Calibration.** The model is simulated with [`mms::simulate`] from
//!    the recorded input; Levenberg-Marquardt on the time-domain output
//!    error adjusts the chain's parameters (log scale, forward-difference
//!    Jacobian) within `1 + tolerance` of their nominal values (dampers
//!    within `1 + damper_tolerance`).
//! 3. **Hypotheses.** Each effect's parameter is first placed by a grid
//!    (logarithmic; linear for the signed offset) and a golden-section
//!    search with the calibrated chain held fixed, then fitted jointly with
//!    the chain's parameters by the same Levenberg-Marquardt.
//! 4. **Selection** by the Bayesian information criterion of a Gaussian
//!    output error: an effect's score is `n ln(RSS_0 / RSS_1) - ln n -
//!    margin` for `n` samples, kept if positive and, when the calibrated
//!    linear model leaves more than [`TimeOptions::adequate`] of the output
//!    RMS, if it removes at least [`TimeOptions::min_share`] of that
//!    residual's energy; a Coulomb or offset force must also reach
//!    [`MIN_FORCE_SHARE`] of the RMS actuator force. Forward selection:
//!    the best effect is kept, then each remaining one is added and
//!    everything refitted; a further effect must earn its parameter
//!    against the model with the kept ones and always remove
//!    [`TimeOptions::min_share`] of what they leave. If nothing is kept
//!    the verdict is `none` (the calibrated linear model explains the
//!    record within its noise).
//!
//! ```
//! use ident::diagnose::EffectKind;
//! use ident::nonlinear::{diagnose_time, TimeOptions};
//! use mms::model_file::{ModelFile, Motion};
//! use mms::response::{Effects, Parameters};
//! use mms::simulate::simulate;
//! use mms::{Model, Output, Port};
//!
//! // One 2 kg mass on a spring to nothing (a free mass) with 0.8 N of dry
//! // friction, pushed by a two-tone force.
//! let m = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0))?;
//! let truth = ModelFile {
//!     model: m,
//!     output: Output::Velocity,
//!     parameters: Parameters::from_values(&m, vec![2.0])?,
//!     gain: 1.0,
//!     motion: Motion::Translational,
//!     effects: Effects { coulomb_friction: Some(0.8), ..Effects::default() },
//! };
//! let fs = 200.0;
//! let u: Vec<f64> = (0..800)
//!     .map(|k| {
//!         let t = k as f64 / fs;
//!         2.0 * (2.0 * std::f64::consts::PI * 1.5 * t).sin() + (17.0 * t).cos()
//!     })
//!     .collect();
//! let y = simulate(&truth, &u, fs)?;
//! // The nominal model: no friction, the mass 5 % off.
//! let nominal = ModelFile {
//!     parameters: Parameters::from_values(&m, vec![2.1])?,
//!     effects: Effects::default(),
//!     ..truth.clone()
//! };
//! let d = diagnose_time(&u, &y, fs, &nominal, &TimeOptions::default())?;
//! assert_eq!(d.effects[0].kind, EffectKind::CoulombFriction);
//! assert!((d.effects[0].parameters["coulomb_n"] / 0.8 - 1.0).abs() < 0.01);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::diagnose::{BeforeAfter, EffectKind, EffectVerdict};
use crate::evidence::{
    AmplitudeEvidence, CalibrationNote, CoherenceEvidence, ControllerEvidence, Evidence,
    ForceShortfall, HarmonicEvidence, HeldOutSamples, RecordEvidence, ShareShortfall, TimeEvidence,
};
use crate::fit::solve_spd;
use crate::idim::{idim_ls, IdimOptions, InverseDynamics};
use crate::selection::{forward_select, none, Trial};
use frf::welch::{effective_samples, h1, WelchOptions};
use frf::Frf;
use mms::model_file::ModelFile;
use mms::response::Parameters;
use mms::simulate::{
    default_backlash_link, ClosedLoop, Controller, Feedback, SimOptions, SimulateError, Simulator,
};
use num_complex::Complex64;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::LN_10;

/// How the diagnosis simulates a model: its dead time is what a
/// recording's FRF shows, the drive's hold included, and the simulation
/// holds each sample itself.
pub(crate) const RECORDED: SimOptions = SimOptions {
    friction_mass: None,
    backlash_link: None,
    substeps: None,
    delay_includes_hold: true,
};

/// Options of [`diagnose_time`].
#[derive(Clone, Debug, PartialEq)]
pub struct TimeOptions {
    /// Calibration bound on masses and springs: each stays within a factor
    /// `1 + tolerance` of its nominal value.
    pub tolerance: f64,
    /// The same for dampers (and a viscous friction the model has).
    pub damper_tolerance: f64,
    /// What an effect must gain beyond the BIC price of its parameter.
    pub margin: f64,
    /// The share of the calibrated model's residual energy an effect must
    /// remove as well, when that residual exceeds [`TimeOptions::adequate`]
    /// of the output RMS. BIC alone counts every sample as independent
    /// noise; when the linear model misses structure (modes it lacks), a
    /// small relative gain over tens of thousands of samples would pass it.
    pub min_share: f64,
    /// The relative RMS error below which the calibrated linear model
    /// counts as adequate, so that BIC alone decides.
    pub adequate: f64,
    /// Iteration limit of each Levenberg-Marquardt fit.
    pub max_iterations: usize,
    /// How the H1 estimates behind the FRF figures (`rms_db`, `rms_deg`)
    /// and the evidence are made: the user's segment length or period, so
    /// that they describe the lines the user looks at.
    pub welch: WelchOptions,
    /// Leave every fourth of 16 blocks of the record out of every fit, and
    /// keep an effect only if it also lowers the output error there by
    /// more than the price of its parameter.
    pub holdout: bool,
    /// The time-domain comparison is informative when the model after the
    /// diagnosis leaves at most this share of the output RMS; beyond it the
    /// model misses more than its effects explain, and the verdict of
    /// [`crate::diagnosis`] does not rest on it.
    pub informative: f64,
    /// Open loop: compare the positions high-passed at this corner (Hz,
    /// zero phase), so that the drift of a free axis, which integrates
    /// every slow force the model does not know of, does not swamp the
    /// dynamics; `None`: only the initial state's trend is taken out.
    pub highpass_hz: Option<f64>,
    /// Open loop, without [`TimeOptions::highpass_hz`]: high-pass at this
    /// corner only where the data show a drift the model cannot explain,
    /// i.e. where more than [`DRIFT_SHARE`] of the calibrated linear
    /// model's error lies below it ([`TimeDiagnosis::highpass_hz`] says
    /// whether it was). Slow motion is otherwise compared as it is: a
    /// friction shows at the velocity reversals of slow moves.
    pub drift_corner_hz: Option<f64>,
    /// Search on the first this many samples only (`None`: the whole
    /// record): the calibration and the forward selection simulate the
    /// stretch hundreds of times. The chosen models are then refitted on
    /// the whole record and the effects kept only if the whole record's
    /// held-out blocks confirm them ([`TimeDiagnosis::whole_record`]);
    /// their values come from every sample.
    pub search_samples: Option<usize>,
}

/// Levenberg-Marquardt iterations of each refit on the whole record,
/// which starts from the search's solution.
pub const WHOLE_RECORD_ITERATIONS: usize = 4;

/// The share of the calibrated linear model's output error below
/// [`TimeOptions::drift_corner_hz`] above which it is a drift to take out.
pub const DRIFT_SHARE: f64 = 0.5;

/// The blocks of [`TimeOptions::holdout`]: the record is cut into this
/// many, and every fourth (the 4th, 8th, ...) is held out.
pub const HOLDOUT_BLOCKS: usize = 16;

impl Default for TimeOptions {
    fn default() -> TimeOptions {
        TimeOptions {
            tolerance: crate::diagnosis::DEFAULT_TOLERANCE,
            damper_tolerance: 0.5,
            margin: 10.0,
            min_share: 0.1,
            adequate: 0.05,
            max_iterations: 30,
            welch: WelchOptions::default(),
            holdout: true,
            informative: 0.5,
            highpass_hz: None,
            drift_corner_hz: None,
            search_samples: None,
        }
    }
}

/// Errors of a model against the record, in the frequency and the time
/// domain.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimeFit {
    /// RMS of `20 log10 |H1_rec / H1_model|` over the lines with coherence
    /// of at least 0.5, where `H1_model` is the H1 estimate of the
    /// simulated output from the same input.
    pub rms_db: f64,
    /// RMS of the wrapped phase difference over the same lines, degrees.
    pub rms_deg: f64,
    /// RMS of the time-domain output error `y - y_model`, in the output's
    /// units.
    pub rms_time: f64,
    /// `rms_time` over the RMS of what is compared of `y`: in an open
    /// loop, its motion about the trend of its initial rigid-body state
    /// (and above [`TimeOptions::highpass_hz`]); in a closed loop, `y`.
    pub rms_time_rel: f64,
}

/// The result of [`diagnose_time`]: `effects`, `rejected`, `fit`,
/// `calibration`, `noise` and `model_after` as in the frequency-domain
/// [`crate::diagnose::Diagnosis`], plus `evidence`, `samples`, `fs`, the
/// loop, the inverse dynamics and the held-out figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimeDiagnosis {
    /// Kept effects, best first; `[none]` if nothing is missing.
    pub effects: Vec<EffectVerdict>,
    /// Hypotheses that did not earn their parameter, best first.
    pub rejected: Vec<EffectVerdict>,
    /// Errors before and after.
    pub fit: BeforeAfter<TimeFit>,
    /// Calibration notes: parameters pinned at their bounds.
    pub calibration: Vec<CalibrationNote>,
    /// What the record shows before any model: the loop's law,
    /// coherence, amplitude dependence, harmonics.
    pub evidence: RecordEvidence,
    /// RMS of the time-domain residual of the model after the diagnosis
    /// (output units): the noise plus what no hypothesis explains.
    pub noise: f64,
    /// The calibrated model with the best kept effect.
    #[serde(serialize_with = "crate::diagnose::ser_model")]
    pub model_after: ModelFile,
    /// Samples in the record.
    pub samples: usize,
    /// Sample rate, Hz.
    pub fs: f64,
    /// Whether the model was simulated inside the recorded position loop
    /// ([`diagnose_closed_loop`]).
    pub closed_loop: bool,
    /// The inverse-dynamics identification (IDIM-LS) of a one-mass model
    /// in a closed loop: the second method, free of simulation.
    pub inverse_dynamics: Option<InverseDynamics>,
    /// The output error on the held-out blocks ([`TimeOptions::holdout`]).
    pub held_out: Option<TimeHeldOut>,
    /// Whether the calibrated linear model explains enough of the output
    /// ([`TimeOptions::informative`]) for the comparison to decide
    /// anything.
    pub informative: bool,
    /// The corner of the high-pass the comparison applied, Hz (given, or
    /// taken where the data showed a drift; `None`: none).
    pub highpass_hz: Option<f64>,
    /// With several outputs, each further output's weight in the output
    /// error: the first output's noise over its own (empty for one
    /// output).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub output_weights: Vec<f64>,
    /// Where the search used the first samples only
    /// ([`TimeOptions::search_samples`]): the check on the whole record.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub whole_record: Option<WholeRecord>,
    /// The sample of the whole record at which a model diverged inside
    /// the loop, where the search's stretch stayed finite: the verdict
    /// rests on that stretch alone.
    pub whole_record_diverged_at: Option<usize>,
}

/// The search's models refitted on the whole record (each from the
/// search's solution, on the whole record's fitted blocks) and compared on
/// its held-out blocks: the effects stay only if they lower the error
/// there by more than the price of their parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WholeRecord {
    /// Samples the search used (from the first).
    pub search_samples: usize,
    /// Samples in the record.
    pub samples: usize,
    /// The held-out sums of squares, the figures of
    /// [`TimeHeldOut`] on the whole record.
    pub held_out: TimeHeldOut,
    /// `-2 ln` of the likelihood ratio there ([`TimeHeldOut::evidence`]).
    pub gain: f64,
    /// What the effects must gain: `ln` of the effective held-out samples
    /// per effect parameter.
    pub price: f64,
    /// Whether the whole record keeps the search's effects (always for a
    /// search that named none).
    pub confirmed: bool,
}

/// The output error on the samples held out of every fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimeHeldOut {
    /// Samples held out.
    pub samples: usize,
    /// Sum of squares of the calibrated linear model's error there.
    pub before: f64,
    /// The same for the model after the diagnosis.
    pub after: f64,
    /// The held-out samples counted as independent
    /// ([`frf::welch::effective_samples`] of that model's error there, every
    /// output's): a smooth error (the model still misses slow motion) has
    /// far fewer independent samples than samples; white noise has as
    /// many.
    pub effective_samples: f64,
}

impl TimeHeldOut {
    /// The drop of the held-out prediction error in noise units, `-2 ln`
    /// of the likelihood ratio with the noise level profiled out and the
    /// samples counted by [`TimeHeldOut::effective_samples`].
    pub fn evidence(&self) -> f64 {
        if self.after > 0.0 && self.before > 0.0 {
            self.effective_samples * (self.before / self.after).ln()
        } else {
            0.0
        }
    }
}

/// Why a time-domain diagnosis cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TimeDiagnoseError {
    /// The model cannot be simulated.
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    /// Bad samples or options.
    #[error("{0}")]
    Input(String),
    /// The controller law does not reproduce the recorded input.
    #[error(
        "{0}: more than {pct} % off, so the simulated loop would not be the recorded one",
        pct = 100.0 * CONTROLLER_TOLERANCE
    )]
    Controller(String),
}

/// The effects the time-domain diagnosis tries.
pub(crate) const HYPOTHESES: [EffectKind; 3] = [
    EffectKind::CoulombFriction,
    EffectKind::Backlash,
    EffectKind::Offset,
];

/// The largest relative RMS error of a controller law on the record
/// ([`Controller::check`]) that [`diagnose_closed_loop`] accepts: beyond
/// it the simulated loop would not be the recorded one.
pub const CONTROLLER_TOLERANCE: f64 = 0.1;

/// Above this relative RMS error of the controller law the diagnosis runs
/// but warns in its evidence.
pub const CONTROLLER_WARNING: f64 = 0.01;

/// The smallest Coulomb or offset force, as a share of the RMS actuator
/// force, that the time-domain diagnosis reports. Smaller forces are below
/// what a drive constant is known to, and in an open-loop simulation of a
/// free body a tiny offset is a drift compensator: it lowers the output
/// error of any slightly imperfect fit.
pub const MIN_FORCE_SHARE: f64 = 0.01;

/// The closed position loop a record was taken in: the controller, the
/// reference, and a known signal added to the controller output (e.g.
/// injected pulses; `None` if there is none).
#[derive(Clone, Copy, Debug)]
pub struct LoopRecord<'a> {
    /// The controller law.
    pub controller: &'a Controller,
    /// The position reference, one sample per record sample.
    pub reference: &'a [f64],
    /// A known signal added to the controller output.
    pub disturbance: Option<&'a [f64]>,
    /// The output the controller reads, when it is not the diagnosed one
    /// (`None`: the diagnosed output closes the loop).
    pub feedback: Option<LoopFeedback<'a>>,
}

impl<'a> LoopRecord<'a> {
    /// The loop around a model whose output recorded `y` (at `fs`),
    /// starting in the recorded motion: at `y`'s first sample, every mass
    /// at the velocity of the output the controller reads.
    pub fn closed_loop(&self, y: &[f64], fs: f64) -> ClosedLoop<'a> {
        let read = self.feedback.map_or(y, |f| f.y);
        ClosedLoop {
            controller: self.controller,
            reference: self.reference,
            disturbance: self.disturbance,
            initial_position: y[0],
            initial_velocity: (read[2] - read[0]) * fs / 2.0,
            feedback: self.feedback.map(|f| Feedback {
                sensor: f.sensor,
                initial_position: f.y[0],
            }),
            observed: &[],
        }
    }

    /// The loop over the samples in `range`.
    pub fn window(&self, range: std::ops::Range<usize>) -> LoopRecord<'a> {
        LoopRecord {
            controller: self.controller,
            reference: &self.reference[range.clone()],
            disturbance: self.disturbance.map(|d| &d[range.clone()]),
            feedback: self.feedback.map(|f| LoopFeedback {
                sensor: f.sensor,
                y: &f.y[range],
            }),
        }
    }
}

/// The output a loop is closed on, beside the one diagnosed (a motor
/// encoder feeding the controller while the load's encoder is compared).
#[derive(Clone, Copy, Debug)]
pub struct LoopFeedback<'a> {
    /// Its place in the model's chain.
    pub sensor: mms::Port,
    /// Its recorded samples, one per record sample.
    pub y: &'a [f64],
}

/// A simulation's first output, its input inside a loop, and its output
/// at each further output's place.
type Run = (Vec<f64>, Option<Vec<f64>>, Vec<Vec<f64>>);

/// A further output of the record beside the first, compared in the same
/// output error (several sensors of one chain): its samples, its place in
/// the chain (read as the model's output), and its weight (the first
/// output's noise over its own).
struct Extra<'a> {
    y: &'a [f64],
    place: mms::Port,
    weight: f64,
}

/// The output-error problem: which parameters move, their bounds.
struct Problem<'a> {
    file: &'a ModelFile,
    u: &'a [f64],
    /// The first output: at the model's sensor.
    y: &'a [f64],
    /// Further outputs, at their own places.
    extra: Vec<Extra<'a>>,
    fs: f64,
    /// Indices (in the model's parameter order) of the fitted parameters;
    /// `usize::MAX` stands for the model's viscous friction.
    free: Vec<usize>,
    /// Force scale of an offset's coordinate (`force_n = x * offset_scale`;
    /// the other effects are fitted in their logarithm).
    offset_scale: f64,
    /// The loop the record was taken in, and the motion at its start.
    closed: Option<ClosedLoop<'a>>,
    /// How the H1 estimates of the fit figures are taken.
    welch: &'a WelchOptions,
    /// Samples left out of every fit ([`TimeOptions::holdout`]).
    held: Vec<bool>,
    /// The trend's basis for `held` ([`Problem::hold`] keeps them together).
    trend_basis: TrendBasis,
    /// Polynomial degree + 1 of the trend taken out of the output error:
    /// the rigid-body states at the start of an open-loop record, which a
    /// simulation from rest does not know (2 for a position: offset and
    /// velocity; 1 for a velocity; 0 for an acceleration or a closed
    /// loop, which holds the position itself).
    trend: usize,
    /// The zero-phase low-pass whose output is subtracted from the output
    /// error ([`TimeOptions::highpass_hz`]).
    highpass: Option<crate::idim::ZeroPhase>,
}

impl Problem<'_> {
    /// The model at `x`: the free log-parameters, then one coordinate per
    /// effect of `kinds`.
    fn model(&self, kinds: &[EffectKind], x: &[f64]) -> Result<ModelFile, TimeDiagnoseError> {
        let mut values = self.file.parameters.values().to_vec();
        let mut effects = self.file.effects;
        for (&i, &v) in self.free.iter().zip(x) {
            if i == usize::MAX {
                effects.viscous_friction = Some(v.exp());
            } else {
                values[i] = v.exp();
            }
        }
        for (&kind, &v) in kinds.iter().zip(&x[self.free.len()..]) {
            match kind {
                EffectKind::CoulombFriction => effects.coulomb_friction = Some(v.exp()),
                EffectKind::Backlash => effects.backlash_gap = Some(v.exp()),
                EffectKind::Offset => effects.offset_force = Some(v * self.offset_scale),
                _ => {}
            }
        }
        let parameters = Parameters::from_values(&self.file.model, values)
            .map_err(|e| TimeDiagnoseError::Simulate(e.into()))?;
        Ok(ModelFile {
            parameters,
            effects,
            ..self.file.clone()
        })
    }

    /// The simulated output, and in a closed loop the simulated input.
    /// With further outputs, also the simulated output at each of their
    /// places.
    fn run(&self, kinds: &[EffectKind], x: &[f64]) -> Result<Run, TimeDiagnoseError> {
        let m = self.model(kinds, x)?;
        let sim = Simulator::new(&m, self.fs, &RECORDED)?;
        let places: Vec<mms::Port> = self.extra.iter().map(|e| e.place).collect();
        Ok(match &self.closed {
            None if places.is_empty() => (sim.run(self.u)?, None, Vec::new()),
            None => {
                let (y, at) = sim.run_at(self.u, &places)?;
                (y, None, at)
            }
            Some(cl) => {
                let observed: Vec<(mms::Port, f64)> =
                    self.extra.iter().map(|e| (e.place, e.y[0])).collect();
                let run = sim.run_closed_loop(&ClosedLoop {
                    observed: &observed,
                    ..*cl
                })?;
                (run.y, Some(run.u), run.at)
            }
        })
    }

    /// Errors of the model at `x` against the record; in a closed loop the
    /// H1 estimate uses the simulated input.
    fn time_fit(
        &self,
        kinds: &[EffectKind],
        x: &[f64],
        measured: Option<&Frf>,
    ) -> Result<TimeFit, TimeDiagnoseError> {
        let (y_sim, u_sim, _) = self.run(kinds, x)?;
        let start = self.initial_state(kinds, &y_sim);
        let u = u_sim.as_deref().unwrap_or(self.u);
        let mut fit = time_fit(u, self.y, (&y_sim, &start), self.fs, self.welch, measured);
        // Relative to the output's own motion about the trend of its
        // initial state: an axis that turns at a constant speed has an
        // output RMS that says nothing of how well its dynamics are met.
        let t = self.slow(&[], self.y);
        let n = self.y.len().max(1) as f64;
        let rms_y = (self
            .y
            .iter()
            .zip(&t)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        fit.rms_time_rel = if rms_y > 0.0 {
            fit.rms_time / rms_y
        } else {
            0.0
        };
        Ok(fit)
    }

    /// Holds out `held` from every fit from now on.
    fn hold(&mut self, held: Vec<bool>) {
        self.trend_basis = TrendBasis::new(&held, MAX_TREND_TERMS);
        self.held = held;
    }

    /// The trend of the initial rigid-body states that best fits the
    /// record's difference from the simulation `sim` on the fitted samples.
    fn initial_state(&self, kinds: &[EffectKind], sim: &[f64]) -> Vec<f64> {
        let d: Vec<f64> = self.y.iter().zip(sim).map(|(a, b)| a - b).collect();
        self.slow(kinds, &d)
    }

    /// The part of `d` the comparison leaves out: the trend of the initial
    /// state and, with [`TimeOptions::highpass_hz`], what is slower than
    /// the corner.
    fn slow(&self, kinds: &[EffectKind], d: &[f64]) -> Vec<f64> {
        // A model with a dry force of its own has no unknown constant
        // force left for the trend to take.
        let terms = if kinds.contains(&EffectKind::CoulombFriction) {
            self.trend.min(2)
        } else {
            self.trend
        };
        let mut t = self.trend_basis.trend(d, &self.held, terms);
        if let Some(lp) = &self.highpass {
            let rest: Vec<f64> = d.iter().zip(&t).map(|(a, b)| a - b).collect();
            let slow = lp.apply(&rest);
            for (t, s) in t.iter_mut().zip(slow) {
                *t += s;
            }
        }
        t
    }

    /// The simulated output plus [`Problem::initial_state`].
    fn with_initial_state(&self, kinds: &[EffectKind], sim: &[f64]) -> Vec<f64> {
        let t = self.initial_state(kinds, sim);
        sim.iter().zip(&t).map(|(s, t)| s + t).collect()
    }

    /// The output error on every sample (after the initial state) of the
    /// first output, then those of the further outputs (each about its
    /// own slow part, times its weight); `None` if the simulation fails.
    fn all_errors(&self, kinds: &[EffectKind], x: &[f64]) -> Option<Vec<Vec<f64>>> {
        let (s, _, at) = self.run(kinds, x).ok()?;
        let s = self.with_initial_state(kinds, &s);
        let mut all = Vec::with_capacity(1 + at.len());
        all.push(self.y.iter().zip(&s).map(|(a, b)| a - b).collect());
        for (e, sim) in self.extra.iter().zip(at) {
            let d: Vec<f64> = e.y.iter().zip(&sim).map(|(a, b)| a - b).collect();
            let slow = self.slow(kinds, &d);
            all.push(
                d.iter()
                    .zip(&slow)
                    .map(|(d, t)| (d - t) * e.weight)
                    .collect(),
            );
        }
        Some(all)
    }

    /// Residual `y - y_model` on the fitted samples and its sum of squares
    /// (infinite if the simulation fails, so a search steps away from
    /// there).
    fn residual(&self, kinds: &[EffectKind], x: &[f64]) -> (Vec<f64>, f64) {
        match self.all_errors(kinds, x) {
            Some(all) => {
                // Plain loops: this runs once per simulation of a search.
                let mut r = Vec::with_capacity(all.iter().map(Vec::len).sum());
                for e in &all {
                    for (&v, &h) in e.iter().zip(&self.held) {
                        if !h {
                            r.push(v);
                        }
                    }
                }
                let rss = r.iter().map(|v| v * v).sum();
                (r, rss)
            }
            None => (Vec::new(), f64::INFINITY),
        }
    }

    /// Sum of squares of the output error on the held-out samples.
    fn test_rss(&self, kinds: &[EffectKind], x: &[f64]) -> f64 {
        match self.all_errors(kinds, x) {
            Some(all) => all
                .iter()
                .map(|e| {
                    e.iter()
                        .zip(&self.held)
                        .filter(|(_, &h)| h)
                        .map(|(v, _)| v * v)
                        .sum::<f64>()
                })
                .sum(),
            None => f64::INFINITY,
        }
    }

    /// The fitted and the held-out output errors at `x` counted as
    /// independent ([`frf::welch::effective_samples`]): a model whose
    /// error is still a smooth signal has far fewer independent samples
    /// than samples.
    fn effective_counts(&self, kinds: &[EffectKind], x: &[f64]) -> (f64, f64) {
        let Some(all) = self.all_errors(kinds, x) else {
            return (0.0, 0.0);
        };
        let (mut fit, mut test) = (Vec::new(), Vec::new());
        for e in &all {
            for (&v, &h) in e.iter().zip(&self.held) {
                if h {
                    test.push(v);
                } else {
                    fit.push(v);
                }
            }
        }
        (effective_samples(&fit), effective_samples(&test))
    }

    /// The columns `d(model)/dx_i = -(d residual)/dx_i` at `x`, whose
    /// residual is `r`, by forward differences (backward at an upper
    /// bound `hi`): one simulation each, side by side, so that the cores
    /// stay busy to the end of a diagnosis (each column is computed as
    /// alone). `None` where a step cannot be simulated.
    fn jacobian(
        &self,
        kinds: &[EffectKind],
        x: &[f64],
        hi: &[f64],
        r: &[f64],
    ) -> Option<Vec<Vec<f64>>> {
        (0..x.len())
            .into_par_iter()
            .map(|i| {
                let mut xi = x.to_vec();
                let step = if xi[i] + 1e-4 > hi[i] { -1e-4 } else { 1e-4 };
                xi[i] += step;
                let (ri, rssi) = self.residual(kinds, &xi);
                (rssi.is_finite() && ri.len() == r.len())
                    .then(|| r.iter().zip(&ri).map(|(a, b)| (a - b) / step).collect())
            })
            .collect()
    }

    /// The covariance of the coordinates at `x` (row-major): the inverse
    /// of the Gauss-Newton matrix of forward differences (one simulation
    /// per coordinate) times the residual's variance, inflated by its
    /// correlation from sample to sample. `None` where it is singular.
    fn covariance(&self, kinds: &[EffectKind], x: &[f64], hi: &[f64]) -> Option<Vec<f64>> {
        let p = x.len();
        let (r, rss) = self.residual(kinds, x);
        if !rss.is_finite() || r.len() <= p {
            return None;
        }
        let jac = self.jacobian(kinds, x, hi, &r)?;
        let mut a = vec![0.0; p * p];
        for i in 0..p {
            for j in 0..=i {
                let v: f64 = jac[i].iter().zip(&jac[j]).map(|(a, b)| a * b).sum();
                a[i * p + j] = v;
                a[j * p + i] = v;
            }
        }
        let variance = rss / (r.len() - p) as f64;
        let scale = variance * (r.len() as f64 / effective_samples(&r).max(1.0)).max(1.0);
        let mut cov = vec![0.0; p * p];
        for j in 0..p {
            let mut unit = vec![0.0; p];
            unit[j] = 1.0;
            let col = solve_spd(&a, &unit, p)?;
            for i in 0..p {
                cov[i * p + j] = col[i] * scale;
            }
        }
        Some(cov)
    }

    /// Levenberg-Marquardt on the output error from `x`, each step clamped
    /// to `[lo, hi]`, until a step lowers the RSS, or the linearised model
    /// predicts it would, by less than [`MIN_GAIN`] of itself. Returns the
    /// state and its RSS.
    fn fit(
        &self,
        kinds: &[EffectKind],
        mut x: Vec<f64>,
        lo: &[f64],
        hi: &[f64],
        iterations: usize,
    ) -> (Vec<f64>, f64) {
        let p = x.len();
        let (mut r, mut rss) = self.residual(kinds, &x);
        if !rss.is_finite() || p == 0 {
            return (x, rss);
        }
        let mut lambda = 1e-3;
        for _ in 0..iterations {
            let Some(jac) = self.jacobian(kinds, &x, hi, &r) else {
                return (x, rss);
            };
            let mut a = vec![0.0; p * p];
            let mut g = vec![0.0; p];
            for i in 0..p {
                for j in 0..=i {
                    let s: f64 = jac[i].iter().zip(&jac[j]).map(|(a, b)| a * b).sum();
                    a[i * p + j] = s;
                    a[j * p + i] = s;
                }
                g[i] = jac[i].iter().zip(&r).map(|(a, b)| a * b).sum();
            }
            let mut improved = false;
            for _ in 0..8 {
                let mut m = a.clone();
                for i in 0..p {
                    m[i * p + i] += lambda * a[i * p + i] + 1e-12 * (1.0 + a[i * p + i]);
                }
                let Some(d) = solve_spd(&m, &g, p) else {
                    lambda *= 10.0;
                    continue;
                };
                let xn: Vec<f64> = (0..p).map(|i| (x[i] + d[i]).clamp(lo[i], hi[i])).collect();
                // The linearised model's gain for a step inside the
                // bounds: a larger damping only shortens the step and its
                // predicted gain, so below the threshold no further try is
                // worth a simulation. (A step cut at a bound can gain less
                // than a shorter one that is not: those are tried.)
                let inside = (0..p).all(|i| xn[i] == x[i] + d[i]);
                let quadratic: f64 = (0..p)
                    .map(|i| d[i] * (0..p).map(|j| a[i * p + j] * d[j]).sum::<f64>())
                    .sum();
                let predicted = 2.0 * d.iter().zip(&g).map(|(d, g)| d * g).sum::<f64>() - quadratic;
                if inside && predicted < MIN_GAIN * rss {
                    break;
                }
                let (rn, rssn) = self.residual(kinds, &xn);
                if rssn < rss {
                    let gain = (rss - rssn) / rss;
                    x = xn;
                    r = rn;
                    rss = rssn;
                    lambda = (lambda / 3.0).max(1e-9);
                    improved = gain > MIN_GAIN;
                    break;
                }
                lambda *= 4.0;
            }
            if !improved {
                break;
            }
        }
        (x, rss)
    }

    /// The best fit of the effects `kinds` whose last one is new: a grid
    /// of its coordinate over `[ll, lh]` with everything else fixed at each
    /// of `bases`, a golden section from each of the (up to three; one for
    /// a further effect) best local minima, the joint fit, then polishing
    /// rounds.
    #[allow(clippy::too_many_arguments)]
    fn search(
        &self,
        kinds: &[EffectKind],
        bases: &[&Vec<f64>],
        lo: &[f64],
        hi: &[f64],
        (ll, lh): (f64, f64),
        iterations: usize,
    ) -> Option<(Vec<f64>, f64)> {
        let mut lo_k = lo.to_vec();
        lo_k.push(ll);
        let mut hi_k = hi.to_vec();
        hi_k.push(lh);
        let mut best: Option<(Vec<f64>, f64)> = None;
        for base in bases {
            let with = |v: f64| -> f64 {
                let mut x = base.to_vec();
                x.push(v);
                self.residual(kinds, &x).1
            };
            // The chain (and any kept effect) has absorbed part of the new
            // effect, so the grid's best point need not be the joint fit's.
            let grid: Vec<f64> = (0..9).map(|k| ll + (lh - ll) * k as f64 / 8.0).collect();
            let costs: Vec<f64> = grid.iter().map(|&v| with(v)).collect();
            let mut minima: Vec<usize> = (0..9)
                .filter(|&k| {
                    (k == 0 || costs[k] <= costs[k - 1]) && (k == 8 || costs[k] <= costs[k + 1])
                })
                .collect();
            minima.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]));
            // A further effect on top of kept ones, or an offset (whose cost
            // is smooth): its best minimum only.
            let single = kinds.len() > 1 || kinds.last() == Some(&EffectKind::Offset);
            minima.truncate(if single { 1 } else { 3 });
            for &m in &minima {
                let (a, b) = (grid[m.saturating_sub(1)], grid[(m + 1).min(8)]);
                let (v, _) = golden(a, b, with, 14);
                let mut x = base.to_vec();
                x.push(v);
                let (x, rss) = self.fit(kinds, x, &lo_k, &hi_k, iterations);
                if rss.is_finite() && best.as_ref().is_none_or(|b| rss < b.1) {
                    best = Some((x, rss));
                }
            }
        }
        let (mut x, mut rss) = best?;
        // Polish: the chain and the effect trade off along a narrow valley
        // where the joint fit may stall; alternate a golden section on the
        // effect (the rest fixed) with a fresh joint fit.
        let e = x.len() - 1;
        let width = (0.05 * (lh - ll)).min(0.4);
        for _ in 0..2 {
            let at = |v: f64| -> f64 {
                let mut xv = x.clone();
                xv[e] = v;
                self.residual(kinds, &xv).1
            };
            let c = x[e];
            let (v, _) = golden((c - width).max(ll), (c + width).min(lh), at, 12);
            let mut xv = x.clone();
            xv[e] = v;
            let (xn, rn) = self.fit(kinds, xv, &lo_k, &hi_k, iterations);
            if rn < rss * (1.0 - 1e-6) {
                x = xn;
                rss = rn;
            } else {
                break;
            }
        }
        Some((x, rss))
    }
}

/// The relative fall of the RSS below which a time-domain fit stops: on
/// 4096 samples 0.04 units of the information criterion, far below any
/// effect's price, where each further step costs a simulation per
/// coordinate.
const MIN_GAIN: f64 = 1e-5;

/// A fitted state of the forward selection: the coordinates, their RSS on
/// the fitted samples, the figures, the held-out RSS and the bounds.
struct Fit {
    x: Vec<f64>,
    rss: f64,
    fit: TimeFit,
    test: f64,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

/// The parameters the calibration moves and their log bounds.
struct Calibration {
    /// Indices in the model's parameter order; `usize::MAX` for the
    /// model's viscous friction.
    free: Vec<usize>,
    /// Nominal log-values.
    x0: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

/// Every positive parameter (a zero damper stays zero) and a viscous
/// friction the model has, within `1 + tolerance` of its nominal value
/// (dampers within `1 + damper_tolerance`).
fn free_parameters(model: &ModelFile, o: &TimeOptions) -> Calibration {
    let names = model.model.parameters();
    let values = model.parameters.values();
    let mut c = Calibration {
        free: Vec::new(),
        x0: Vec::new(),
        lo: Vec::new(),
        hi: Vec::new(),
    };
    let mut push = |i: usize, v: f64, damper: bool| {
        let t = if damper {
            o.damper_tolerance
        } else {
            o.tolerance
        };
        let x = v.ln();
        c.free.push(i);
        c.x0.push(x);
        c.lo.push(x - (1.0 + t).ln());
        c.hi.push(x + (1.0 + t).ln());
    };
    for (i, (name, &v)) in names.iter().zip(values).enumerate() {
        if v > 0.0 {
            push(i, v, name.starts_with('d'));
        }
    }
    if let Some(v) = model.effects.viscous_friction.filter(|&v| v > 0.0) {
        push(usize::MAX, v, true);
    }
    c
}

/// The samples held out of every fit: every 4th of [`HOLDOUT_BLOCKS`]
/// blocks (none without `holdout`).
fn held_blocks(n: usize, holdout: bool) -> Vec<bool> {
    (0..n)
        .map(|k| holdout && (k * HOLDOUT_BLOCKS / n) % 4 == 3)
        .collect()
}

/// The terms of the trend of the operating point: none in a closed loop,
/// which holds the position itself; in an open loop the initial position
/// and velocity and a constant force (what holds an axis at a constant
/// speed against its friction), i.e. a quadratic in time for a position,
/// a line for a velocity, a constant for an acceleration.
fn trend_terms(closed: bool, output: mms::Output) -> usize {
    match (closed, output) {
        (true, _) => 0,
        (false, mms::Output::Position) => 3,
        (false, mms::Output::Velocity) => 2,
        (false, _) => 1,
    }
}

/// The zero-phase low-pass (second order, padded by three periods of the
/// corner) whose output the open-loop comparison of `n` samples leaves
/// out ([`TimeOptions::highpass_hz`]).
fn highpass(
    closed: bool,
    corner_hz: Option<f64>,
    fs: f64,
    n: usize,
) -> Option<crate::idim::ZeroPhase> {
    match (closed, corner_hz) {
        (false, Some(fc)) if fc > 0.0 && fc < 0.25 * fs => {
            let pad = ((3.0 * fs / fc) as usize).max(3);
            // The second order is one section.
            let section = crate::idim::butterworth(2, fc, fs)[0];
            Some(crate::idim::ZeroPhase::new(section, n, pad))
        }
        _ => None,
    }
}

/// The RMS output error of `model`, its chain calibrated on the fitted
/// samples as the time-domain diagnosis calibrates (its effects kept as
/// they are), on the samples [`TimeOptions::holdout`] holds out, compared
/// as that diagnosis compares (initial state, high-pass; inside the loop
/// `record`): the one figure on which a model from the frequency domain
/// and one from the time domain can both be scored. `None` without
/// held-out samples or when the model cannot be simulated (hysteretic
/// damping has no time-domain form).
pub fn held_out_error(
    u: &[f64],
    y: &[f64],
    fs: f64,
    model: &ModelFile,
    record: Option<&LoopRecord>,
    o: &TimeOptions,
) -> Option<f64> {
    held_out_error_outputs(u, y, &[], fs, model, record, o)
}

/// [`held_out_error`] of several outputs at once, as
/// [`diagnose_time_outputs`] compares them: `y` at the model's sensor,
/// and each of `others` (samples, place, weight) at its place, its error
/// about its own slow part times its weight
/// ([`TimeDiagnosis::output_weights`]); the RMS over every output's
/// held-out samples.
pub fn held_out_error_outputs(
    u: &[f64],
    y: &[f64],
    others: &[(&[f64], mms::Port, f64)],
    fs: f64,
    model: &ModelFile,
    record: Option<&LoopRecord>,
    o: &TimeOptions,
) -> Option<f64> {
    let n = u.len();
    if n != y.len() || n < 64 || !o.holdout || others.iter().any(|e| e.0.len() != n) {
        return None;
    }
    let Calibration { free, x0, lo, hi } = free_parameters(model, o);
    let problem = Problem {
        file: model,
        u,
        y,
        fs,
        free,
        extra: others
            .iter()
            .map(|&(y, place, weight)| Extra { y, place, weight })
            .collect(),
        offset_scale: 1.0,
        closed: record.map(|r| r.closed_loop(y, fs)),
        welch: &o.welch,
        held: held_blocks(n, true),
        trend_basis: TrendBasis::new(&held_blocks(n, true), MAX_TREND_TERMS),
        trend: trend_terms(record.is_some(), model.output),
        highpass: highpass(record.is_some(), o.highpass_hz, fs, n),
    };
    let n_test = (1 + others.len()) * problem.held.iter().filter(|&&h| h).count();
    let (x, fitted) = problem.fit(&[], x0, &lo, &hi, o.max_iterations);
    if !fitted.is_finite() {
        return None;
    }
    let rss = problem.test_rss(&[], &x);
    (rss.is_finite() && n_test > 0).then(|| (rss / n_test as f64).sqrt())
}

/// The errors of `models`, as they are (no calibration), on the samples
/// [`TimeOptions::holdout`] holds out, within `band` (Hz): each simulated
/// from the recorded input (or inside the loop `record`), the trend of
/// the initial state taken out as the time-domain diagnosis takes it out,
/// and the error band-passed (zero phase) to the lines a frequency-domain
/// diagnosis compared. The one figure on which that diagnosis's models
/// can be checked against the samples: outside its band it claims
/// nothing. Each output of `others` (samples, place, weight) counts as in
/// [`held_out_error_outputs`]. Returns each model's RMS error and the
/// held-out samples counted as independent
/// ([`frf::welch::effective_samples`] of the first model's error), and
/// the RMS of the recorded output there within the band (the first
/// output's, its initial state's trend taken out); `None` without
/// held-out samples or when a model cannot be simulated.
#[allow(clippy::too_many_arguments)]
pub fn held_out_band_errors(
    u: &[f64],
    y: &[f64],
    others: &[(&[f64], mms::Port, f64)],
    fs: f64,
    models: &[&ModelFile],
    record: Option<&LoopRecord>,
    band: (f64, f64),
    o: &TimeOptions,
) -> Option<(Vec<f64>, f64, f64)> {
    let n = u.len();
    if n != y.len() || n < 64 || !o.holdout || others.iter().any(|e| e.0.len() != n) {
        return None;
    }
    let held = held_blocks(n, true);
    let pad = |fc: f64| ((3.0 * fs / fc) as usize).max(3);
    let low = (band.0 > 0.0 && band.0 < 0.25 * fs).then(|| {
        crate::idim::ZeroPhase::new(crate::idim::butterworth(2, band.0, fs)[0], n, pad(band.0))
    });
    let high = (band.1 > 0.0 && band.1 < 0.4 * fs).then(|| {
        crate::idim::ZeroPhase::new(crate::idim::butterworth(2, band.1, fs)[0], n, pad(band.1))
    });
    let band_pass = |e: &[f64]| -> Vec<f64> {
        // The low-passed part at the band's top, less its own low-passed
        // part at the band's bottom.
        let e = match &high {
            Some(h) => h.apply(e),
            None => e.to_vec(),
        };
        match &low {
            Some(l) => {
                let slow = l.apply(&e);
                e.iter().zip(&slow).map(|(a, b)| a - b).collect()
            }
            None => e,
        }
    };
    let mut errors = Vec::with_capacity(models.len());
    let mut independent = 0.0;
    let mut output = 0.0;
    for (i, model) in models.iter().enumerate() {
        let problem = Problem {
            file: model,
            u,
            y,
            fs,
            free: Vec::new(),
            extra: others
                .iter()
                .map(|&(y, place, weight)| Extra { y, place, weight })
                .collect(),
            offset_scale: 1.0,
            closed: record.map(|r| r.closed_loop(y, fs)),
            welch: &o.welch,
            held: held.clone(),
            trend_basis: TrendBasis::new(&held, MAX_TREND_TERMS),
            trend: trend_terms(record.is_some(), model.output),
            highpass: None,
        };
        let all = problem.all_errors(&[], &[])?;
        let mut kept = Vec::new();
        for e in &all {
            let e = band_pass(e);
            kept.extend(e.iter().zip(&held).filter(|(_, &h)| h).map(|(v, _)| *v));
        }
        if kept.is_empty() || kept.iter().any(|v| !v.is_finite()) {
            return None;
        }
        if i == 0 {
            independent = effective_samples(&kept);
            let trend = problem.slow(&[], y);
            let motion: Vec<f64> = y.iter().zip(&trend).map(|(a, b)| a - b).collect();
            let motion = band_pass(&motion);
            let m: Vec<f64> = motion
                .iter()
                .zip(&held)
                .filter(|(_, &h)| h)
                .map(|(v, _)| *v)
                .collect();
            output = (m.iter().map(|v| v * v).sum::<f64>() / m.len().max(1) as f64).sqrt();
        }
        errors.push((kept.iter().map(|v| v * v).sum::<f64>() / kept.len() as f64).sqrt());
    }
    Some((errors, independent, output))
}

/// The most terms [`trend_terms`] asks for (a quadratic).
const MAX_TREND_TERMS: usize = 3;

/// The least-squares polynomials in time of a record's length, fitted on
/// the samples not held out: an orthonormal basis (on those samples) of
/// the powers of time, so that a trend costs a few dot products; it runs
/// once per simulation of a search.
struct TrendBasis {
    /// Orthonormal on the fitted samples; the first `k` span the
    /// polynomials of degree below `k`. A power that adds no direction (a
    /// record of fewer samples than terms) ends the list.
    q: Vec<Vec<f64>>,
}

impl TrendBasis {
    fn new(held: &[bool], terms: usize) -> TrendBasis {
        let n = held.len();
        let mut q: Vec<Vec<f64>> = Vec::new();
        // Time scaled to [-1, 1] keeps the powers well conditioned.
        let t: Vec<f64> = (0..n)
            .map(|k| 2.0 * k as f64 / (n.max(2) - 1) as f64 - 1.0)
            .collect();
        let dot = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(held)
                .filter(|(_, &h)| !h)
                .map(|((a, b), _)| a * b)
                .sum()
        };
        let mut power = vec![1.0; n];
        for _ in 0..terms.min(MAX_TREND_TERMS) {
            let size = dot(&power, &power).sqrt();
            let mut v = power.clone();
            // Modified Gram-Schmidt, twice: the second pass removes what
            // rounding left of the earlier directions.
            for _ in 0..2 {
                for b in &q {
                    let c = dot(&v, b);
                    v.iter_mut().zip(b).for_each(|(v, b)| *v -= c * b);
                }
            }
            let norm = dot(&v, &v).sqrt();
            if norm.is_nan() || norm <= 1e-10 * size {
                break;
            }
            v.iter_mut().for_each(|v| *v /= norm);
            q.push(v);
            power.iter_mut().zip(&t).for_each(|(p, t)| *p *= t);
        }
        TrendBasis { q }
    }

    /// The least-squares polynomial of degree `terms - 1` through `d` on
    /// the fitted samples, evaluated on every sample (zero for `terms ==
    /// 0`, and for a record too short for its terms).
    fn trend(&self, d: &[f64], held: &[bool], terms: usize) -> Vec<f64> {
        let mut t = vec![0.0; d.len()];
        if terms > self.q.len() {
            return t;
        }
        for b in &self.q[..terms] {
            let c: f64 = d
                .iter()
                .zip(b)
                .zip(held)
                .filter(|(_, &h)| !h)
                .map(|((d, b), _)| d * b)
                .sum();
            t.iter_mut().zip(b).for_each(|(t, b)| *t += c * b);
        }
        t
    }
}

/// Golden-section search of `f` over `[a, b]` (log values), from a
/// bracket around the best grid point.
fn golden(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64, iterations: usize) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iterations {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    if fc < fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

/// The time-domain diagnosis of `u`, `y` (sampled at `fs`) against
/// `model`; see the module documentation.
pub fn diagnose_time(
    u: &[f64],
    y: &[f64],
    fs: f64,
    model: &ModelFile,
    o: &TimeOptions,
) -> Result<TimeDiagnosis, TimeDiagnoseError> {
    diagnose_time_outputs(u, y, &[], fs, model, None, o)
}

/// The time-domain diagnosis of a record taken in a closed position loop:
/// the model is simulated inside the loop `record` (its controller driven
/// by the simulated position and the recorded reference), so that it
/// follows the reference like the real system instead of drifting as an
/// open-loop simulation from the recorded input does; calibration and the
/// hypotheses are fitted on that closed-loop output error. First the
/// controller law must reproduce the recorded input `u` from the recorded
/// `y` within [`CONTROLLER_TOLERANCE`]. For a one-mass model the
/// inverse-dynamics identification ([`crate::idim`]) is attached as a
/// second, simulation-free method.
///
/// ```
/// use ident::diagnose::EffectKind;
/// use ident::nonlinear::{diagnose_closed_loop, LoopRecord, TimeOptions};
/// use mms::model_file::ModelFile;
/// use mms::simulate::{ClosedLoop, Controller, SimOptions, Simulator};
///
/// // A 10 kg carriage with 4 N of dry friction, 40 N/V drive, in a P/P
/// // position loop following a smooth back-and-forth reference.
/// let text = "masses = 1\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
///             output = \"position\"\ngain = 40\n[parameters]\nm1 = 10\n\
///             [effects]\nfriction = { viscous_ns_per_m = 20 }\n";
/// let nominal = ModelFile::parse(text)?;
/// let mut truth = nominal.clone();
/// truth.effects.coulomb_friction = Some(4.0);
/// let fs = 1000.0;
/// let r: Vec<f64> = (0..3000)
///     .map(|k| 0.05 * (1.0 - (2.0 * std::f64::consts::PI * k as f64 / 1500.0).cos()))
///     .collect();
/// let c = Controller::new(100.0, 50.0);
/// let run = Simulator::new(&truth, fs, &SimOptions::default())?
///     .run_closed_loop(&ClosedLoop::new(&c, &r))?;
/// let rec = LoopRecord { controller: &c, reference: &r, disturbance: None, feedback: None };
/// let d = diagnose_closed_loop(&run.u, &run.y, fs, &nominal, &rec, &TimeOptions::default())?;
/// assert_eq!(d.effects[0].kind, EffectKind::CoulombFriction);
/// assert!((d.effects[0].parameters["coulomb_n"] / 4.0 - 1.0).abs() < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn diagnose_closed_loop(
    u: &[f64],
    y: &[f64],
    fs: f64,
    model: &ModelFile,
    record: &LoopRecord,
    o: &TimeOptions,
) -> Result<TimeDiagnosis, TimeDiagnoseError> {
    diagnose_time_outputs(u, y, &[], fs, model, Some(record), o)
}

/// The time-domain diagnosis of several outputs of one record at once:
/// `y` at the model's sensor and each of `others` at its place in the
/// chain (read as the model's output: several encoders), with one
/// parameter set and one set of effects, simulated once per trial (inside
/// `record`'s loop if given, closed as it says) and compared output by
/// output, each output's error weighted by the first output's noise over
/// its own (from the calibrated linear model's errors). The figures of the
/// fit (`rms_time_rel`, the FRF errors) are the first output's; the
/// held-out samples and the information criterion count every output's.
///
/// ```
/// use ident::diagnose::EffectKind;
/// use ident::nonlinear::{diagnose_time_outputs, TimeOptions};
/// use mms::model_file::ModelFile;
/// use mms::simulate::{SimOptions, Simulator};
/// use mms::Port;
///
/// // A free two-mass drive with dry friction on the motor, read at the
/// // motor and at the load.
/// let text = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
///             output = \"velocity\"\n[parameters]\nm1 = 1\nm2 = 2\nc12 = 4000\nd12 = 4\n";
/// let nominal = ModelFile::parse(text)?;
/// let mut truth = nominal.clone();
/// truth.effects.coulomb_friction = Some(0.5);
/// let fs = 500.0;
/// let u: Vec<f64> = (0..3000)
///     .map(|k| { let t = k as f64 / fs; 2.0 * (2.0 * std::f64::consts::PI * 1.3 * t).sin() + (9.0 * t).sin() })
///     .collect();
/// let sim = Simulator::new(&truth, fs, &SimOptions::default())?;
/// let (motor, at) = sim.run_at(&u, &[Port::new(2, 0)])?;
/// let d = diagnose_time_outputs(&u, &motor, &[(&at[0], Port::new(2, 0))], fs, &nominal, None, &TimeOptions::default())?;
/// assert_eq!(d.effects[0].kind, EffectKind::CoulombFriction);
/// assert!((d.effects[0].parameters["coulomb_n"] / 0.5 - 1.0).abs() < 0.05);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn diagnose_time_outputs(
    u: &[f64],
    y: &[f64],
    others: &[(&[f64], mms::Port)],
    fs: f64,
    model: &ModelFile,
    record: Option<&LoopRecord>,
    o: &TimeOptions,
) -> Result<TimeDiagnosis, TimeDiagnoseError> {
    let bad = |s: String| Err(TimeDiagnoseError::Input(s));
    if u.len() != y.len() {
        return bad(format!("u has {} samples, y {}", u.len(), y.len()));
    }
    for (i, (other, _)) in others.iter().enumerate() {
        if other.len() != u.len() {
            return bad(format!(
                "output {} has {} samples, u {}",
                i + 2,
                other.len(),
                u.len()
            ));
        }
        if let Some(k) = other.iter().position(|v| !v.is_finite()) {
            return bad(format!("output {} sample {k} is not finite", i + 2));
        }
        let (p, n) = (others[i].1, model.model.n_masses());
        if !(p.plus >= 1 && p.plus <= n && p.minus < p.plus) {
            return bad(format!(
                "output {}: [{}, {}] is not a place on a chain of {n} masses",
                i + 2,
                p.plus,
                p.minus
            ));
        }
    }
    if u.len() < 64 {
        return bad(format!("{} samples: at least 64 are needed", u.len()));
    }
    if let Some(k) = y.iter().position(|v| !v.is_finite()) {
        return bad(format!("output sample {k} is not finite"));
    }
    if !(fs.is_finite() && fs > 0.0) {
        return bad(format!("sample rate {fs} Hz must be positive and finite"));
    }
    if !(o.tolerance > 0.0 && o.damper_tolerance > 0.0 && o.margin.is_finite()) {
        return bad("tolerances must be positive, the margin finite".into());
    }
    // The search runs on the first samples; the whole record refits and
    // checks what it chose (TimeOptions::search_samples).
    let n_all = u.len();
    let w = o.search_samples.map_or(n_all, |k| k.clamp(64, n_all));
    let (u_all, y_all, others_all, record_all) = (u, y, others, record);
    if let Some(rec) = record {
        let lengths = [
            ("the reference", Some(rec.reference.len())),
            ("the disturbance", rec.disturbance.map(<[f64]>::len)),
            ("the controller's output", rec.feedback.map(|f| f.y.len())),
        ];
        for (what, len) in lengths {
            if let Some(len) = len.filter(|&l| l != n_all) {
                return bad(format!("{what} has {len} samples, the record {n_all}"));
            }
        }
    }
    let window_record = record.map(|r| r.window(0..w));
    let others_window: Vec<(&[f64], mms::Port)> =
        others.iter().map(|&(o, p)| (&o[..w], p)).collect();
    let (u, y, others, record) = (&u[..w], &y[..w], &others_window[..], window_record.as_ref());
    let n = u.len();
    // Check the model can be simulated at all before any search.
    Simulator::new(model, fs, &RECORDED)?;

    // Evidence from the H1 estimates.
    let mut evidence = RecordEvidence::default();
    // In a loop: the law must reproduce the recorded input, and the
    // simulation starts in the recorded motion.
    let closed = match record {
        None => None,
        Some(rec) => {
            if rec.reference.len() != n {
                return bad(format!(
                    "the reference has {} samples, the record {n}",
                    rec.reference.len()
                ));
            }
            // The law reads the output it is closed on.
            let read = match rec.feedback {
                None => y,
                Some(f) => {
                    if f.y.len() != n {
                        return bad(format!(
                            "the controller's output has {} samples, the record {n}",
                            f.y.len()
                        ));
                    }
                    if let Some(k) = f.y.iter().position(|v| !v.is_finite()) {
                        return bad(format!("the controller's output: sample {k} is not finite"));
                    }
                    f.y
                }
            };
            let check = rec
                .controller
                .check(rec.reference, read, u, rec.disturbance, fs)?;
            let law = format!(
                "controller law (kp = {}, kv = {}, position filter {:?}{}) on the recorded \
                 output and reference: reproduces the recorded input within {:.3} % RMS \
                 (largest difference {:.4e}{})",
                rec.controller.kp,
                rec.controller.kv,
                rec.controller.filter,
                rec.controller
                    .saturation
                    .map_or(String::new(), |s| format!(", saturation {s}")),
                100.0 * check.rms_rel,
                check.max_abs,
                if check.saturated > 0 {
                    format!(", saturated in {} samples", check.saturated)
                } else {
                    String::new()
                }
            );
            if check.rms_rel > CONTROLLER_TOLERANCE {
                return Err(TimeDiagnoseError::Controller(law));
            }
            // A law that is close but not right (EMPS with a plain backward
            // difference: 3.3 %) still moves the estimates: the report
            // warns above CONTROLLER_WARNING.
            evidence.controller = Some(ControllerEvidence {
                kp: rec.controller.kp,
                kv: rec.controller.kv,
                filter: rec.controller.filter.clone(),
                saturation: rec.controller.saturation,
                rms_rel: check.rms_rel,
                max_abs: check.max_abs,
                saturated: check.saturated,
                warning_above: CONTROLLER_WARNING,
            });
            Some(rec.closed_loop(y, fs))
        }
    };

    let names = model.model.parameters();
    let Calibration { free, x0, lo, hi } = free_parameters(model, o);
    // Scale of the force effects: the peak actuator force.
    let scale = model.gain * model.effects.gain_factor.unwrap_or(1.0);
    let f_max = u.iter().fold(0.0f64, |a, v| a.max(v.abs())) * scale.abs();
    let f_rms = (u.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt() * scale.abs();
    let mut problem = Problem {
        file: model,
        u,
        y,
        extra: others
            .iter()
            .map(|&(y, place)| Extra {
                y,
                place,
                weight: 1.0,
            })
            .collect(),
        fs,
        free,
        offset_scale: f_max,
        closed,
        welch: &o.welch,
        held: held_blocks(n, o.holdout),
        trend_basis: TrendBasis::new(&held_blocks(n, o.holdout), MAX_TREND_TERMS),
        trend: trend_terms(record.is_some(), model.output),
        highpass: highpass(record.is_some(), o.highpass_hz, fs, n),
    };
    let np = problem.free.len();
    // Every output's samples count.
    let outputs = 1 + others.len();
    let n_fit = outputs * problem.held.iter().filter(|&&h| !h).count();
    let n_test = outputs * n - n_fit;

    let welch = &o.welch;
    let measured = h1(u, y, fs, welch).ok();
    if let Some(est) = &measured {
        evidence.coherence = coherence_evidence(&est.frf);
    }
    evidence.amplitude = amplitude_evidence(u, y, fs, welch);
    evidence.harmonics = harmonic_evidence(u, y);

    // Calibration of the linear chain (with the model's own effects).
    let x_nominal = x0.clone();
    let (mut x_cal, mut rss_cal) = problem.fit(&[], x0, &lo, &hi, o.max_iterations);
    // A drift the calibrated linear model cannot explain, where the data
    // show one: most of its error below the corner.
    let mut applied_corner = o.highpass_hz;
    if let (None, Some(fc), None, true) = (
        problem.highpass.as_ref(),
        o.drift_corner_hz,
        record,
        rss_cal.is_finite(),
    ) {
        if let (Some(lp), Some(all)) = (
            highpass(false, Some(fc), fs, n),
            problem.all_errors(&[], &x_cal),
        ) {
            let e = &all[0];
            let slow = lp.apply(e);
            let total: f64 = e.iter().map(|v| v * v).sum();
            let below: f64 = slow.iter().map(|v| v * v).sum();
            if total > 0.0 && below > DRIFT_SHARE * total {
                problem.highpass = Some(lp);
                applied_corner = Some(fc);
                (x_cal, rss_cal) = problem.fit(&[], x_cal, &lo, &hi, o.max_iterations);
            }
        }
    }
    if !others.is_empty() && rss_cal.is_finite() {
        // Each further output weighs by the first's noise over its own,
        // both read off the calibrated linear model, then the calibration
        // is redone with those weights.
        let fitted_rms = |e: &[f64]| {
            let (s, k) = e
                .iter()
                .zip(&problem.held)
                .filter(|(_, &h)| !h)
                .fold((0.0, 0usize), |(s, k), (v, _)| (s + v * v, k + 1));
            (s / k.max(1) as f64).sqrt()
        };
        if let Some(all) = problem.all_errors(&[], &x_cal) {
            let first = fitted_rms(&all[0]);
            for (e, err) in problem.extra.iter_mut().zip(&all[1..]) {
                let own = fitted_rms(err) / e.weight;
                e.weight = if own > 0.0 && first > 0.0 {
                    first / own
                } else {
                    1.0
                };
            }
        }
        (x_cal, rss_cal) = problem.fit(&[], x_cal, &lo, &hi, o.max_iterations);
    }
    if !rss_cal.is_finite() {
        return bad("the nominal model cannot be simulated on this record".into());
    }
    let mut calibration = Vec::new();
    for (k, &i) in problem.free.iter().enumerate() {
        let name = if i == usize::MAX {
            "friction.viscous_ns_per_m"
        } else {
            names[i].as_str()
        };
        let at = |b: f64| (x_cal[k] - b).abs() < 1e-6;
        if at(lo[k]) || at(hi[k]) {
            calibration.push(CalibrationNote::Pinned {
                parameter: name.to_string(),
                upper: !at(lo[k]),
                value: x_cal[k].exp(),
                nominal: (0.5 * (lo[k] + hi[k])).exp(),
            });
        }
    }
    let measured_frf = measured.as_ref().map(|e| &e.frf);
    let before = problem.time_fit(&[], &x_cal, measured_frf)?;
    let test_cal = problem.test_rss(&[], &x_cal);

    let cal_model = problem.model(&[], &x_cal)?;
    let deflection = default_backlash_link(&model.model).and_then(|i| {
        let x = Simulator::new(&cal_model, fs, &RECORDED)
            .ok()?
            .positions(u)
            .ok()?;
        let node = |v: &[f64], k: usize| if k == 0 { 0.0 } else { v[k - 1] };
        Some(
            x.iter()
                .map(|p| (node(p, i + 1) - node(p, i)).abs())
                .fold(0.0f64, f64::max),
        )
    });
    // The range each effect's coordinate is searched over.
    let range = |kind: EffectKind| -> Option<(f64, f64)> {
        match kind {
            EffectKind::CoulombFriction if f_max > 0.0 => Some(((1e-4 * f_max).ln(), f_max.ln())),
            EffectKind::Backlash => match deflection {
                Some(d) if d > 0.0 => Some(((1e-4 * d).ln(), (4.0 * d).ln())),
                _ => None,
            },
            // Half the peak force either way (in units of the peak force).
            EffectKind::Offset if f_max > 0.0 => Some((-0.5, 0.5)),
            _ => None,
        }
    };
    // An effect's value from its coordinate.
    let value = |kind: EffectKind, v: f64| match kind {
        EffectKind::Offset => v * f_max,
        _ => v.exp(),
    };

    // Forward selection: each hypothesis alone on the calibrated chain
    // (step 1), then each remaining one added to those kept (step 2, ...),
    // everything refitted jointly. A further effect is scored against the
    // model with the kept ones.
    let base = Fit {
        x: x_cal.clone(),
        rss: rss_cal,
        fit: before,
        test: test_cal,
        lo: lo.clone(),
        hi: hi.clone(),
    };
    let selected = forward_select(base, |b, kinds, step| {
        let (x_base, rss_base, fit_base, test_base) = (&b.x, b.rss, b.fit, b.test);
        let (lo_base, hi_base) = (&b.lo, &b.hi);
        // Every remaining effect, also one that did not earn its parameter
        // alone: an offset can hide friction under the drift of an
        // open-loop simulation until it is removed.
        // In an open loop a constant force is part of the operating point
        // (the trend), so an offset cannot be told from it.
        let open_loop = problem.trend > 0;
        let candidates: Vec<(EffectKind, (f64, f64))> = HYPOTHESES
            .into_iter()
            .filter(|&kind| !(kinds.contains(&kind) || (open_loop && kind == EffectKind::Offset)))
            .filter_map(|kind| Some((kind, range(kind)?)))
            .collect();
        // Each hypothesis is its own search: both cores take them in turn,
        // and the trials keep their order.
        let trial = |&(kind, (ll, lh)): &(EffectKind, (f64, f64))| -> Result<Option<Trial<Fit>>, TimeDiagnoseError> {
            let mut with = kinds.to_vec();
            with.push(kind);
            // Step 1 starts from the calibrated and from the nominal chain:
            // a large effect can pull the linear calibration far off (an
            // offset, which the calibration cannot mimic, only from the
            // calibrated one).
            let bases: Vec<&Vec<f64>> = if kinds.is_empty() && kind != EffectKind::Offset {
                vec![x_base, &x_nominal]
            } else {
                vec![x_base]
            };
            let Some((x, rss)) =
                problem.search(&with, &bases, lo_base, hi_base, (ll, lh), o.max_iterations)
            else {
                return Ok(None);
            };
            // The samples counted as independent, from this model's own
            // errors on the fitted and the held-out samples.
            let (eff_fit, eff_test) = problem.effective_counts(&with, &x);
            let gain_bic = crate::diagnose::profiled_gain(rss_base, rss, eff_fit);
            let price = eff_fit.max(2.0).ln() + o.margin;
            let share = 1.0 - rss / rss_base;
            // On the held-out blocks the effect must lower the error by
            // more than its parameter's price there.
            let test = problem.test_rss(&with, &x);
            let gain_test = crate::diagnose::profiled_gain(test_base, test, eff_test);
            let validated = n_test == 0 || gain_test > eff_test.max(2.0).ln();
            // A further effect must always explain a share of what the kept
            // ones leave: that misfit is mostly the kept effects' imperfect
            // fit, which BIC would count as information.
            let enough =
                share >= o.min_share || (kinds.is_empty() && fit_base.rms_time_rel <= o.adequate);
            // A force effect must also matter next to the driving force.
            let force = match kind {
                EffectKind::CoulombFriction | EffectKind::Offset => {
                    value(kind, x[x.len() - 1]).abs()
                }
                _ => f64::INFINITY,
            };
            let relevant = force >= MIN_FORCE_SHARE * f_rms;
            // Its own parameter must stand out of its uncertainty and
            // lie inside its range.
            let (mut lo_k, mut hi_k) = (lo_base.clone(), hi_base.clone());
            lo_k.push(ll);
            hi_k.push(lh);
            let (standard_errors, unresolved) =
                time_significance(kind, &problem.covariance(&with, &x, &hi_k), &x, &lo_k, &hi_k, f_max);
            let score = if enough && relevant && validated {
                gain_bic - price
            } else {
                (gain_bic - price).min(-1.0)
            };
            let after = problem.time_fit(&with, &x, measured_frf)?;
            let evidence = Evidence::Time(TimeEvidence {
                before: fit_base,
                after,
                bic_gain: gain_bic,
                price,
                too_small_share: (!enough).then_some(ShareShortfall {
                    share,
                    needed: o.min_share,
                    first: kinds.is_empty(),
                    adequate: o.adequate,
                }),
                held_out: (n_test > 0).then(|| HeldOutSamples {
                    before: (test_base / n_test as f64).sqrt(),
                    after: (test / n_test as f64).sqrt(),
                    samples: n_test,
                    gain: gain_test,
                    price: (n_test as f64).ln(),
                }),
                validated,
                too_small_force: (!relevant).then_some(ForceShortfall {
                    share: force / f_rms,
                    needed: MIN_FORCE_SHARE,
                }),
            });
            let mut parameters = BTreeMap::new();
            let pname = kind.parameter_name().unwrap_or("value");
            parameters.insert(pname.to_string(), value(kind, x[x.len() - 1]));
            Ok(Some(Trial {
                verdict: EffectVerdict {
                    kind,
                    parameters,
                    evidence,
                    score,
                    step,
                    unresolved,
                    standard_errors,
                },
                state: Fit {
                    x,
                    rss,
                    fit: after,
                    test,
                    lo: lo_k,
                    hi: hi_k,
                },
            }))
        };
        let tried: Vec<Trial<Fit>> = candidates
            .par_iter()
            .map(trial)
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .flatten()
            .collect();
        Ok::<_, TimeDiagnoseError>(tried)
    })?;
    let mut kinds: Vec<EffectKind> = selected.kept.iter().map(|v| v.kind).collect();
    let mut kept = selected.kept;
    let mut rejected = selected.rejected;
    let Fit {
        x: mut x_base,
        rss: mut rss_base,
        fit: mut fit_base,
        test: test_base,
        lo: lo_base,
        hi: hi_base,
    } = selected.state;
    // How many of the held-out samples count as independent, from the
    // chosen model's error there.
    let independent = problem.effective_counts(&kinds, &x_base).1;
    // The held-out blocks chose the effects; their values come from every
    // sample.
    if n_test > 0 && !kinds.is_empty() {
        problem.hold(vec![false; n]);
        let (mut x, mut rss) =
            problem.fit(&kinds, x_base.clone(), &lo_base, &hi_base, o.max_iterations);
        // Polish a backlash as the search does: its error surface is
        // rugged (contacts come and go), so the joint fit may stall; a
        // golden section on the gap (the rest fixed), then a joint fit.
        // Friction and offset have smooth surfaces and need none.
        for (i, e) in (np..x.len()).enumerate() {
            if kinds[i] != EffectKind::Backlash {
                continue;
            }
            let width = (0.05 * (hi_base[e] - lo_base[e])).min(0.4);
            let at = |v: f64| -> f64 {
                let mut xv = x.clone();
                xv[e] = v;
                problem.residual(&kinds, &xv).1
            };
            let c = x[e];
            let (v, _) = golden(
                (c - width).max(lo_base[e]),
                (c + width).min(hi_base[e]),
                at,
                12,
            );
            let mut xv = x.clone();
            xv[e] = v;
            let (xn, rn) = problem.fit(&kinds, xv, &lo_base, &hi_base, o.max_iterations);
            if rn < rss * (1.0 - 1e-6) {
                (x, rss) = (xn, rn);
            }
        }
        if rss.is_finite() {
            fit_base = problem.time_fit(&kinds, &x, measured_frf)?;
            (x_base, rss_base) = (x, rss * n_fit as f64 / n as f64);
        }
    }
    // The kept effects' parameters from the final joint fit.
    for (e, &v) in kept.iter_mut().zip(&x_base[np..]) {
        let kind = e.kind;
        for p in e.parameters.values_mut() {
            *p = value(kind, v);
        }
    }
    let mut after = fit_base;
    let mut before = before;
    let mut noise = (rss_base / n_fit as f64).sqrt();
    let mut model_after = problem.model(&kinds, &x_base)?.within_ranges();
    let mut whole_record = None;
    let mut whole_record_diverged_at = None;
    if w < n_all {
        // A model that stays finite on the search's stretch may diverge
        // later inside the loop: then the verdict rests on the stretch,
        // and the report says where the whole record could not be run.
        let saved = (
            kept.clone(),
            rejected.clone(),
            noise,
            evidence.clone(),
            before,
            after,
            model_after.clone(),
        );
        let mut whole = || -> Result<(), TimeDiagnoseError> {
            // The whole record: both models refitted from the search's
            // solutions on its fitted blocks, compared on its held-out blocks.
            let held = held_blocks(n_all, o.holdout);
            let mut big = Problem {
                file: model,
                u: u_all,
                y: y_all,
                extra: others_all
                    .iter()
                    .zip(&problem.extra)
                    .map(|(&(y, place), e)| Extra {
                        y,
                        place,
                        weight: e.weight,
                    })
                    .collect(),
                fs,
                free: problem.free.clone(),
                offset_scale: problem.offset_scale,
                closed: record_all.map(|r| r.closed_loop(y_all, fs)),
                welch: &o.welch,
                trend_basis: TrendBasis::new(&held, MAX_TREND_TERMS),
                held,
                trend: problem.trend,
                highpass: problem
                    .highpass
                    .as_ref()
                    .and_then(|_| highpass(false, applied_corner, fs, n_all)),
            };
            let its = WHOLE_RECORD_ITERATIONS;
            // With nothing named there is nothing to confirm: the calibrated
            // chain is scored as the search left it (one simulation).
            let xc = if kinds.is_empty() {
                x_cal.clone()
            } else {
                big.fit(&[], x_cal.clone(), &lo, &hi, its).0
            };
            let test_c = big.test_rss(&[], &xc);
            let (xs, test_s) = if kinds.is_empty() {
                (xc.clone(), test_c)
            } else {
                let (xs, _) = big.fit(&kinds, x_base.clone(), &lo_base, &hi_base, its);
                let t = big.test_rss(&kinds, &xs);
                (xs, t)
            };
            let eff = big.effective_counts(&kinds, &xs).1;
            let n_test_all = outputs * big.held.iter().filter(|&&h| h).count();
            let held_out = TimeHeldOut {
                samples: n_test_all,
                before: test_c,
                after: test_s,
                effective_samples: eff,
            };
            let gain = held_out.evidence();
            let price = kinds.len() as f64 * eff.max(2.0).ln();
            let confirmed = kinds.is_empty() || n_test_all == 0 || gain > price;
            let measured_all = h1(u_all, y_all, fs, welch).ok();
            let frf_all = measured_all.as_ref().map(|e| &e.frf);
            let mut x_final = if confirmed { xs } else { xc.clone() };
            if !confirmed {
                // The search's effects do not hold on the record: rejected,
                // with the whole record's held-out figures.
                for mut v in kept.drain(..) {
                    v.score = v.score.min(-1.0);
                    if let Evidence::Time(t) = &mut v.evidence {
                        t.validated = false;
                        t.held_out = Some(HeldOutSamples {
                            before: (test_c / n_test_all as f64).sqrt(),
                            after: (test_s / n_test_all as f64).sqrt(),
                            samples: n_test_all,
                            gain,
                            price,
                        });
                    }
                    rejected.push(v);
                }
                rejected.sort_by(|a, b| b.score.total_cmp(&a.score));
                kinds.clear();
            }
            // The kept effects' values from every sample.
            if !kinds.is_empty() {
                big.hold(vec![false; n_all]);
                let (xf, rf) = big.fit(&kinds, x_final.clone(), &lo_base, &hi_base, its);
                if rf.is_finite() {
                    x_final = xf;
                    noise = (rf / (outputs * n_all) as f64).sqrt();
                }
            }
            for (e, &v) in kept.iter_mut().zip(&x_final[np..]) {
                let kind = e.kind;
                for p in e.parameters.values_mut() {
                    *p = value(kind, v);
                }
            }
            if let Some(est) = &measured_all {
                evidence.coherence = coherence_evidence(&est.frf);
            }
            before = big.time_fit(&[], &xc, frf_all)?;
            after = if kinds.is_empty() && x_final == xc {
                before
            } else {
                big.time_fit(&kinds, &x_final, frf_all)?
            };
            if kinds.is_empty() {
                noise = after.rms_time;
            }
            model_after = big.model(&kinds, &x_final)?.within_ranges();
            whole_record = Some(WholeRecord {
                search_samples: w,
                samples: n_all,
                held_out,
                gain,
                price,
                confirmed,
            });

            Ok(())
        };
        match whole() {
            Ok(()) => {}
            Err(TimeDiagnoseError::Simulate(SimulateError::Diverged(at))) => {
                (kept, rejected, noise, evidence, before, after, model_after) = saved;
                whole_record = None;
                whole_record_diverged_at = Some(at);
            }
            Err(e) => return Err(e),
        }
    }
    // Informative when the model, with whatever effects it earned, meets
    // most of the output.
    let informative = after.rms_time_rel <= o.informative;
    let effects = if kept.is_empty() {
        vec![none(&rejected)]
    } else {
        kept
    };

    // The simulation-free second method, where the model is a rigid body
    // driven by the recorded force.
    let inverse_dynamics = match (record, model.model.n_masses(), model.output) {
        (Some(_), 1, mms::Output::Position) => {
            let force: Vec<f64> = u_all.iter().map(|v| v * scale).collect();
            let options = IdimOptions {
                viscous: model.effects.viscous_friction.is_some(),
                ..IdimOptions::default()
            };
            idim_ls(&force, y_all, fs, &options).ok()
        }
        _ => None,
    };

    Ok(TimeDiagnosis {
        effects,
        rejected,
        fit: BeforeAfter { before, after },
        calibration,
        evidence,
        noise,
        model_after,
        samples: n_all,
        fs,
        closed_loop: record.is_some(),
        inverse_dynamics,
        held_out: (n_test > 0).then_some(TimeHeldOut {
            samples: n_test,
            before: test_cal,
            after: test_base,
            effective_samples: independent,
        }),
        informative,
        highpass_hz: problem.highpass.as_ref().and(applied_corner),
        output_weights: problem.extra.iter().map(|e| e.weight).collect(),
        whole_record,
        whole_record_diverged_at,
    })
}

/// The standard error of a time-domain effect's parameter (the last
/// coordinate of `x`, with covariance `cov`) and why the record does not
/// resolve it, if it does not: at the bound of its range, or its absent
/// value (no force, no gap) within
/// [`SIGNIFICANCE_SIGMAS`](crate::diagnose::SIGNIFICANCE_SIGMAS) standard
/// errors. An offset's coordinate is the force over `f_max`; the others'
/// are logarithms.
fn time_significance(
    kind: EffectKind,
    cov: &Option<Vec<f64>>,
    x: &[f64],
    lo: &[f64],
    hi: &[f64],
    f_max: f64,
) -> (BTreeMap<String, f64>, Option<crate::diagnose::Unresolved>) {
    use crate::diagnose::{Unresolved, SIGNIFICANCE_SIGMAS};
    let mut errors = BTreeMap::new();
    let p = x.len();
    let k = p - 1;
    let name = kind.parameter_name().unwrap_or("value").to_string();
    let (v, offset) = match kind {
        EffectKind::Offset => (x[k] * f_max, true),
        _ => (x[k].exp(), false),
    };
    let se = cov.as_ref().map(|c| c[k * p + k].max(0.0).sqrt());
    if let Some(se) = se {
        errors.insert(name.clone(), if offset { se * f_max } else { v * se });
    }
    let tol = 1e-6 * (hi[k] - lo[k]).max(1.0);
    if x[k] - lo[k] <= tol || hi[k] - x[k] <= tol {
        return (
            errors,
            Some(Unresolved::AtBound {
                parameter: name,
                value: v,
            }),
        );
    }
    let Some(se) = se else {
        return (errors, None);
    };
    let sigmas = if offset { x[k].abs() / se } else { 1.0 / se };
    if sigmas.is_nan() || sigmas < SIGNIFICANCE_SIGMAS {
        return (
            errors,
            Some(Unresolved::WithinUncertainty {
                parameter: name,
                sigmas,
            }),
        );
    }
    (errors, None)
}

/// Lines worth comparing: coherence of at least 0.5 (all lines if the
/// estimate has none, or none qualifies).
fn good_lines(frf: &Frf) -> Vec<usize> {
    let lines: Vec<usize> = match frf.coherence() {
        Some(c) => (0..frf.len()).filter(|&k| c[k] >= 0.5).collect(),
        None => Vec::new(),
    };
    if lines.is_empty() {
        (0..frf.len()).collect()
    } else {
        lines
    }
}

/// Errors of a simulated output `sim` against the record: in the time
/// domain with the initial state's trend `start` added, in the frequency
/// domain from the simulation itself (the trend is no response to `u`).
fn time_fit(
    u: &[f64],
    y: &[f64],
    (sim, start): (&[f64], &[f64]),
    fs: f64,
    welch: &WelchOptions,
    measured: Option<&Frf>,
) -> TimeFit {
    let n = y.len() as f64;
    let rms = |v: &mut dyn Iterator<Item = f64>| (v.map(|x| x * x).sum::<f64>() / n).sqrt();
    let rms_time = rms(&mut y.iter().zip(sim).zip(start).map(|((a, b), t)| a - b - t));
    let rms_y = rms(&mut y.iter().copied());
    let (mut rms_db, mut rms_deg) = (f64::NAN, f64::NAN);
    if let (Some(m), Ok(s)) = (measured, h1(u, sim, fs, welch)) {
        let lines = good_lines(m);
        let e: Vec<Complex64> = lines
            .iter()
            .map(|&k| (m.response()[k] / s.frf.response()[k]).ln())
            .filter(|z| z.is_finite())
            .collect();
        let c = e.len().max(1) as f64;
        rms_db = (e.iter().map(|z| z.re * z.re).sum::<f64>() / c).sqrt() * 20.0 / LN_10;
        rms_deg = (e.iter().map(|z| z.im * z.im).sum::<f64>() / c)
            .sqrt()
            .to_degrees();
    }
    TimeFit {
        rms_db,
        rms_deg,
        rms_time,
        rms_time_rel: if rms_y > 0.0 { rms_time / rms_y } else { 0.0 },
    }
}

/// Mean and minimum coherence over the lines above 0.5 and the share of
/// lines below 0.9: a nonlinearity lowers it where the noise does not.
fn coherence_evidence(frf: &Frf) -> Option<CoherenceEvidence> {
    let c = frf.coherence()?;
    let lines = good_lines(frf);
    let mean = lines.iter().map(|&k| c[k]).sum::<f64>() / lines.len() as f64;
    Some(CoherenceEvidence {
        mean,
        lines: lines.len(),
        below_0_9: c.iter().filter(|&&g| g < 0.9).count(),
        total: c.len(),
    })
}

/// The first half's FRF against the second half's, with their input
/// levels; the difference in noise units of the coherence.
fn amplitude_evidence(
    u: &[f64],
    y: &[f64],
    fs: f64,
    opts: &WelchOptions,
) -> Option<AmplitudeEvidence> {
    // A periodic record splits at a period boundary, so that each half is
    // made of whole periods.
    let half = match opts.period {
        Some(p) if p > 0 => u.len() / (2 * p) * p,
        _ => u.len() / 2,
    };
    let a = h1(&u[..half], &y[..half], fs, opts).ok()?;
    let b = h1(&u[half..2 * half], &y[half..2 * half], fs, opts).ok()?;
    let rms = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let (ua, ub) = (rms(&u[..half]), rms(&u[half..2 * half]));
    let (ca, cb) = (a.frf.coherence()?, b.frf.coherence()?);
    let (mut sum, mut noise, mut count) = (0.0, 0.0, 0usize);
    for k in 0..a.frf.len().min(b.frf.len()) {
        if ca[k] < 0.5 || cb[k] < 0.5 {
            continue;
        }
        let d = (a.frf.response()[k] / b.frf.response()[k]).norm().ln();
        // var ln|H| = (1 - g^2) / (2 n g^2) per estimate.
        let var = |g: f64, n: usize| (1.0 - g) / (2.0 * n as f64 * g);
        sum += d * d;
        noise += var(ca[k], a.averages) + var(cb[k], b.averages);
        count += 1;
    }
    if count == 0 {
        return None;
    }
    let db = |x: f64| (x / count as f64).sqrt() * 20.0 / LN_10;
    Some(AmplitudeEvidence {
        input_rms_first: ua,
        input_rms_second: ub,
        differ_db: db(sum),
        lines: count,
        noise_db: db(noise),
    })
}

/// For an input whose spectrum leaves lines out (a periodic multisine with
/// an integer number of periods), the output power at unexcited odd and
/// even lines relative to the excited ones: odd harmonics mark an odd
/// nonlinearity (friction, backlash), even ones an even nonlinearity.
fn harmonic_evidence(u: &[f64], y: &[f64]) -> Option<HarmonicEvidence> {
    let uf = frf::fft::fft_real(u);
    let yf = frf::fft::fft_real(y);
    let half = u.len() / 2;
    let pu: Vec<f64> = uf[1..half].iter().map(|z| z.norm_sqr()).collect();
    let top = pu.iter().cloned().fold(0.0, f64::max);
    if top == 0.0 {
        return None;
    }
    let excited: Vec<bool> = pu.iter().map(|&p| p > 1e-6 * top).collect();
    let count = excited.iter().filter(|&&e| e).count();
    let last = excited.iter().rposition(|&e| e)?;
    // Only a sparse input spectrum has lines to look at.
    if count * 2 > last + 1 || count < 3 {
        return None;
    }
    let mean = |pick: &dyn Fn(usize) -> bool| {
        let v: Vec<f64> = (0..=last)
            .filter(|&k| pick(k))
            .map(|k| yf[k + 1].norm_sqr())
            .collect();
        (v.iter().sum::<f64>() / v.len().max(1) as f64, v.len())
    };
    let (pe, _) = mean(&|k| excited[k]);
    // Line k + 1 of the record; its parity in units of the smallest
    // excited line (the multisine's fundamental).
    let base = excited.iter().position(|&e| e)? + 1;
    let parity = |k: usize| -> Option<bool> {
        let l = k + 1;
        l.is_multiple_of(base).then_some((l / base) % 2 == 1)
    };
    let (po, no) = mean(&|k| !excited[k] && parity(k) == Some(true));
    let (pv, nv) = mean(&|k| !excited[k] && parity(k) == Some(false));
    let db = |p: f64| 10.0 * (p / pe).log10();
    Some(HarmonicEvidence {
        odd_lines: no,
        odd_db: db(po),
        even_lines: nv,
        even_db: db(pv),
    })
}
