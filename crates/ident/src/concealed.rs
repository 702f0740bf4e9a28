//! The concealed-effect benchmark: seeded, reproducible recordings of
//! random chains with one or two effects the model given to the diagnosis
//! lacks (or none), and the score of the diagnosis and of the
//! identification on them.
//!
//! A case ([`case`]) draws, from its seed and index alone:
//!
//! - a chain of 2 to 5 masses among the paper's rule (3) models (every
//!   actuator and sensor placement), link modes of 5 to 80 Hz, 1 to 5 %
//!   damping per link, masses and stiffnesses on a random physical scale;
//!   position, velocity or acceleration output (acceleration in FRF
//!   files: a sampled acceleration reads its own sample's input, which no
//!   dead time of a chain model describes); one sensor, or a second one
//!   on another mass;
//! - what is concealed: nothing (a third of the cases and more: the
//!   controls), one effect or two, each from barely detectable to large
//!   (see [`EffectKind`]; the time-domain effects only in time-domain
//!   records, a force offset only inside a position loop, hysteretic
//!   damping only in FRFs, which have no causal time-domain form);
//! - the nominal model: the chain without the effects, every parameter
//!   off by up to ±30 %;
//! - the record: an FRF file (log-spaced lines with relative noise, with
//!   or without its standard deviation), or a time-domain recording
//!   (10^4 to 10^6 samples, output noise 0.1 to 5 % of the output's
//!   motion) excited by random noise, a periodic multisine (full, odd,
//!   odd-odd, or band-limited so that some lines carry no excitation), a
//!   swept sine or back-and-forth motion profiles, in an open loop or
//!   inside a position loop (the excitation injected at the plant input).
//!
//! [`run_case`] diagnoses the case as `mms diagnose` would
//! ([`crate::diagnosis::diagnose_recording`], or
//! [`crate::diagnosis::diagnose_sensors`] with two sensors) with the
//! default options, and, on the controls, identifies the structure
//! ([`crate::identify::identify`], [`crate::joint::identify_sensors`]);
//! [`Summary::of`] scores a set of outcomes: the confusion matrix of true
//! kinds against headlines, parameter accuracy per kind, the false-effect
//! rate on the controls, accuracy per cell of excitation, domain and
//! loop, time against record length, and the identification rate.
//!
//! ```
//! use ident::concealed::{case, Record};
//!
//! // The same seed and index give the same case, everywhere.
//! let a = case(7, 3)?;
//! let b = case(7, 3)?;
//! assert_eq!(a.truth, b.truth);
//! assert_eq!(a.concealed, b.concealed);
//! match &a.record {
//!     Record::Frf { frf, .. } => assert!(frf.len() >= 300),
//!     Record::Time { samples, .. } => assert!(samples[0].u.len() >= 10_000),
//! }
//! # Ok::<(), ident::concealed::CaseError>(())
//! ```

use crate::diagnose::EffectKind;
use crate::diagnosis::{
    diagnose_recording, diagnose_sensors, DiagnosisOptions, Domain, OutputRecording,
    RecordingDiagnosis,
};
use crate::identify::{identify, IdentifyOptions};
use crate::joint::{identify_sensors, SensorOutput};
use crate::nonlinear::LoopRecord;
use frf::welch::WelchOptions;
use frf::{Complex64, Frf, Samples};
use mms::model_file::{ModelFile, Motion};
use mms::response::{ChainResponse, Effects, Parameters};
use mms::simulate::{default_backlash_link, ClosedLoop, Controller, SimOptions, Simulator};
use mms::xorshift::XorShift;
use mms::{Model, Output, Port};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// The version of the case generator and its scoring: outcomes kept from
/// another version are not comparable.
pub const BENCHMARK_VERSION: u32 = 5;

/// Why a case could not be drawn.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CaseError {
    /// No draw of the chain gave a usable case (a loop that would not
    /// stay stable, features that coincide) within the attempts.
    #[error("case {0}: no usable draw in {1} attempts")]
    Exhausted(usize, usize),
}

/// How a time-domain record is excited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Excitation {
    /// Gaussian noise, low-passed at the band's top.
    Noise,
    /// A random-phase multisine on every line of the band.
    Multisine,
    /// On the odd lines only.
    OddMultisine,
    /// On the lines `4k + 1` only (odd-odd: neither even nor `4k + 3`).
    OddOddMultisine,
    /// On the lines of a part of the band only; the rest carry no
    /// excitation.
    BandLimitedMultisine,
    /// A logarithmic swept sine over the band, repeated.
    Sweep,
    /// Back-and-forth moves (smoothed force pulses, or a position
    /// reference inside a loop), with little or no other excitation.
    MotionProfile,
}

impl Excitation {
    const ALL: [Excitation; 7] = [
        Excitation::Noise,
        Excitation::Multisine,
        Excitation::OddMultisine,
        Excitation::OddOddMultisine,
        Excitation::BandLimitedMultisine,
        Excitation::Sweep,
        Excitation::MotionProfile,
    ];

    /// Periodic excitations, whose H1 estimate takes one period per
    /// segment.
    pub fn is_periodic(self) -> bool {
        matches!(
            self,
            Excitation::Multisine
                | Excitation::OddMultisine
                | Excitation::OddOddMultisine
                | Excitation::BandLimitedMultisine
        )
    }

    /// JSON and table name.
    pub fn as_str(self) -> &'static str {
        match self {
            Excitation::Noise => "noise",
            Excitation::Multisine => "multisine",
            Excitation::OddMultisine => "odd_multisine",
            Excitation::OddOddMultisine => "odd_odd_multisine",
            Excitation::BandLimitedMultisine => "band_limited_multisine",
            Excitation::Sweep => "sweep",
            Excitation::MotionProfile => "motion_profile",
        }
    }
}

/// One concealed effect: its kind and the value of the parameter the
/// diagnosis reports for it (for an extra mode, the resonance it adds,
/// Hz).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Concealed {
    /// The effect.
    pub kind: EffectKind,
    /// Its parameter, in the diagnosis's units and name
    /// ([`EffectKind::parameter_name`]; `resonance_hz` for an extra mode).
    pub value: f64,
}

/// The record of a case.
#[derive(Clone, Debug)]
pub enum Record {
    /// An FRF file.
    Frf {
        /// Each sensor's FRF (one or two), on the same lines.
        frf: Vec<Frf>,
        /// Whether the file gives each line's standard deviation.
        std_dev: bool,
    },
    /// A time-domain recording.
    Time {
        /// Each sensor's samples (the same input).
        samples: Vec<Samples>,
        /// Each sensor's FRF, estimated as `mms diagnose` estimates it.
        frf: Vec<Frf>,
        /// How it was estimated (a multisine: one period per segment).
        welch: WelchOptions,
        /// How it was excited.
        excitation: Excitation,
        /// The position loop it was taken in, if any.
        closed_loop: Option<LoopSpec>,
    },
}

/// A position loop a record was taken in, as a user knows it.
#[derive(Clone, Debug)]
pub struct LoopSpec {
    /// The controller law.
    pub controller: Controller,
    /// The reference, one sample per sample.
    pub reference: Vec<f64>,
    /// The excitation added to the controller's output (`None` for a
    /// motion profile without one).
    pub disturbance: Option<Vec<f64>>,
}

/// A drawn case and its truth.
#[derive(Clone, Debug)]
pub struct Case {
    /// Its index in the run.
    pub index: usize,
    /// The system that made the record: the chain (with one mass more for
    /// an extra mode) and its effects.
    pub truth: ModelFile,
    /// The model the diagnosis is given.
    pub nominal: ModelFile,
    /// What the nominal model lacks, empty for a control.
    pub concealed: Vec<Concealed>,
    /// Each output's sensor in the nominal chain (the first is the
    /// model's).
    pub sensors: Vec<Port>,
    /// The noise level: relative per line (FRF), or of the output's
    /// motion (time domain).
    pub noise: f64,
    /// The band the chain's features span, Hz.
    pub band_hz: (f64, f64),
    /// The record.
    pub record: Record,
}

impl Case {
    /// Samples per output (0 for an FRF file).
    pub fn samples(&self) -> usize {
        match &self.record {
            Record::Frf { .. } => 0,
            Record::Time { samples, .. } => samples[0].u.len(),
        }
    }

    /// The case's cell: excitation (`frf_file` for an FRF), loop.
    pub fn cell(&self) -> Cell {
        match &self.record {
            Record::Frf { std_dev, .. } => Cell {
                excitation: if *std_dev {
                    "frf_file_with_std_dev"
                } else {
                    "frf_file"
                }
                .into(),
                closed_loop: false,
            },
            Record::Time {
                excitation,
                closed_loop,
                ..
            } => Cell {
                excitation: excitation.as_str().into(),
                closed_loop: closed_loop.is_some(),
            },
        }
    }
}

/// Where a case sits among the record kinds.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Cell {
    /// The excitation (`frf_file` and `frf_file_with_std_dev` for FRF
    /// files).
    pub excitation: String,
    /// Taken inside a position loop.
    pub closed_loop: bool,
}

/// The domain an effect shows in: the time domain's for the effects its
/// diagnosis tries.
fn effect_domain(kind: EffectKind) -> &'static str {
    match kind {
        EffectKind::None => "none",
        k if crate::nonlinear::HYPOTHESES.contains(&k) => "time",
        _ => "frequency",
    }
}

/// How many draws a case may take before it gives up.
const ATTEMPTS: usize = 40;

/// The case `index` of the run with `seed`.
pub fn case(seed: u64, index: usize) -> Result<Case, CaseError> {
    // A generator per case, so that any case can be drawn alone.
    let mut mix = XorShift::new(
        seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (index as u64).wrapping_add(0x632B_E59B),
    );
    for _ in 0..ATTEMPTS {
        let mut rng = XorShift::new(mix.next_u64());
        if let Some(c) = draw(&mut rng, index) {
            return Ok(c);
        }
    }
    Err(CaseError::Exhausted(index, ATTEMPTS))
}

/// One of `items`, uniformly.
fn pick<T: Copy>(rng: &mut XorShift, items: &[T]) -> T {
    items[(rng.next_u64() % items.len() as u64) as usize]
}

/// The undamped features (antiresonances, resonances) of `model` at
/// `values`, Hz, each sorted.
fn features(model: &Model, values: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let nu = model.undamped_parameters().len();
    let (num, den) = crate::start::UndampedCoefficients::new(model).eval(&values[..nu]);
    let hz = |c: &[f64]| -> Vec<f64> {
        let mut f: Vec<f64> = crate::start::roots(c)
            .iter()
            .filter(|z| z.re > 0.0 && z.im.abs() <= 1e-6 * z.norm())
            .map(|z| z.re.sqrt() / (2.0 * PI))
            .collect();
        f.sort_by(f64::total_cmp);
        f
    };
    (hz(&num), hz(&den))
}

/// A model file of `model` with `values`, unit gain, translational.
fn file(model: Model, output: Output, values: Vec<f64>, effects: Effects) -> Option<ModelFile> {
    Some(ModelFile {
        model,
        output,
        parameters: Parameters::from_values(&model, values).ok()?,
        gain: 1.0,
        motion: Motion::Translational,
        effects,
    })
}

/// The chain: a rule (3) model of 2 to 5 masses and its parameters
/// (masses, springs, dampers), on a random physical scale.
fn chain(rng: &mut XorShift) -> Option<(Model, Vec<f64>)> {
    let n = pick(rng, &[2, 2, 2, 3, 3, 3, 4, 4, 5]);
    let all = mms::rule3_models(n).ok()?;
    let model = pick(rng, &all);
    // A scale of the masses (a small servo to a machine axis); the modes
    // set the springs.
    let scale = 10f64.powf(-2.0 + 3.0 * rng.uniform());
    let masses: Vec<f64> = (0..n).map(|_| scale * rng.log_uniform(0.3, 3.0)).collect();
    let mut values = masses.clone();
    let mut dampers = Vec::new();
    for i in (0..n).filter(|&i| model.has_link(i)) {
        let reduced = if i == 0 {
            masses[0]
        } else {
            masses[i - 1] * masses[i] / (masses[i - 1] + masses[i])
        };
        let w = 2.0 * PI * rng.log_uniform(5.0, 80.0);
        let c = reduced * w * w;
        values.push(c);
        dampers.push(2.0 * rng.log_uniform(0.01, 0.05) * (c * reduced).sqrt());
    }
    values.extend(dampers);
    Some((model, values))
}

/// The record kind of a case.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Frf {
        std_dev: bool,
    },
    Time {
        excitation: Excitation,
        closed: bool,
    },
}

/// Draws one case; `None` when the draw is unusable (try again).
fn draw(rng: &mut XorShift, index: usize) -> Option<Case> {
    let (model, values) = chain(rng)?;
    let (zeros, poles) = features(&model, &values);
    let all: Vec<f64> = zeros.iter().chain(&poles).copied().collect();
    let f_min = all.iter().copied().fold(f64::INFINITY, f64::min);
    let f_max = all.iter().copied().fold(0.0, f64::max);
    if !(f_min.is_finite() && f_max > 0.0) {
        return None;
    }
    // Features a tenth apart at least: nearer ones merge at the damping
    // drawn, and no recording would show them as two.
    let mut sorted = all.clone();
    sorted.sort_by(f64::total_cmp);
    if sorted.windows(2).any(|w| w[1] < 1.1 * w[0]) {
        return None;
    }
    let kind = if rng.uniform() < 0.3 {
        Kind::Frf {
            std_dev: rng.uniform() < 0.5,
        }
    } else {
        Kind::Time {
            excitation: pick(rng, &Excitation::ALL),
            closed: rng.uniform() < 0.3,
        }
    };
    let closed = matches!(kind, Kind::Time { closed: true, .. });
    // A position loop reads a position. A sampled acceleration reads the
    // input of its own sample (the mass line has no hold delay, the rest
    // of the chain half a sample), which no dead time describes: records
    // of it are FRF files here.
    let output = match kind {
        Kind::Time { closed: true, .. } => Output::Position,
        Kind::Time { .. } => pick(rng, &[Output::Position, Output::Velocity]),
        Kind::Frf { .. } => pick(
            rng,
            &[Output::Position, Output::Velocity, Output::Acceleration],
        ),
    };
    let sensors = {
        let first = model.sensor();
        let others: Vec<usize> = (1..=model.n_masses())
            .filter(|&k| k != first.plus && model.with_sensor(Port::new(k, 0)).is_ok())
            .collect();
        if rng.uniform() < 0.25 && !others.is_empty() {
            vec![first, Port::new(pick(rng, &others), 0)]
        } else {
            vec![first]
        }
    };
    // The band the features span, and the sample rate above it.
    let band = (f_min / 4.0, 3.0 * f_max);
    let fs = [500.0, 1000.0, 2000.0, 4000.0, 8000.0, 16000.0]
        .into_iter()
        .find(|&fs| fs >= 20.0 * band.1)?;
    let band = (band.0, band.1.min(fs / 5.0));

    // What is concealed: nothing in 35 % of the cases, one effect in 50 %,
    // two in 15 %.
    let time = matches!(kind, Kind::Time { .. });
    // Every effect the diagnosis tries: the frequency domain's, an extra
    // mode, the time domain's (in this order, which the draws index).
    let possible: Vec<EffectKind> = EffectKind::HYPOTHESES
        .into_iter()
        .chain([EffectKind::ExtraMode])
        .chain(crate::nonlinear::HYPOTHESES)
        .filter(|&k| allowed(k, &model, time, closed))
        .collect();
    let r = rng.uniform();
    let count = if r < 0.35 {
        0
    } else if r < 0.85 {
        1
    } else {
        2
    };
    let mut kinds: Vec<EffectKind> = Vec::new();
    while kinds.len() < count.min(possible.len()) {
        let k = pick(rng, &possible);
        if !kinds.contains(&k) {
            kinds.push(k);
        }
    }
    kinds.sort();

    let noise = rng.log_uniform(0.001, 0.05);
    let mut truth = file(model, output, values.clone(), Effects::default())?;
    // A sampled drive holds its input over each sample, half a sample of
    // dead time, which the simulation has and a model of the drive knows
    // (the nominal below): the delay the diagnosis reports includes it.
    let hold = if time { 0.5 / fs } else { 0.0 };
    let mut concealed = Vec::new();
    // The frequency-domain effects first (the time-domain ones size
    // themselves on the linear truth's motion).
    for &k in &kinds {
        if effect_domain(k) != "frequency" {
            continue;
        }
        let total: f64 = values[..model.n_masses()].iter().sum();
        let value = match k {
            EffectKind::TimeDelay => {
                // A phase lag of 3 to 90 degrees at the band's top.
                let t = rng.log_uniform(3.0, 90.0) / (360.0 * band.1);
                truth.effects.time_delay_s = Some(t);
                t + hold
            }
            EffectKind::Lowpass => {
                let fc = band.1 * rng.log_uniform(0.3, 1.0);
                truth.effects.lowpass_hz = Some(fc);
                fc
            }
            EffectKind::GainError => {
                let g = rng.log_uniform(1.5, 4.0);
                let g = if rng.uniform() < 0.5 { g } else { 1.0 / g };
                truth.effects.gain_factor = Some(g);
                g
            }
            EffectKind::HystereticDamping => {
                let eta = rng.log_uniform(0.03, 0.3);
                truth.effects.loss_factor = Some(eta);
                eta
            }
            EffectKind::ViscousFriction => {
                // The rigid-body mode's corner b / (2 pi M) from the band's
                // bottom to a tenth of the first feature.
                let corner = rng.log_uniform(band.0, (0.1 * f_min).max(1.5 * band.0));
                let b = 2.0 * PI * total * corner;
                truth.effects.viscous_friction = Some(b);
                b
            }
            EffectKind::PreSlidingFriction => {
                let f = rng.log_uniform(1.5 * band.0, 0.5 * f_min);
                let k = total * (2.0 * PI * f).powi(2);
                let zeta = rng.log_uniform(0.05, 0.2);
                truth.effects.pre_sliding_stiffness = Some(k);
                truth.effects.viscous_friction = Some(2.0 * zeta * (k * total).sqrt());
                k
            }
            EffectKind::ExtraMode => {
                let (ext, ext_values, added) = extra_mass(rng, &model, &values, band)?;
                truth = ModelFile {
                    model: ext,
                    parameters: Parameters::from_values(&ext, ext_values).ok()?,
                    ..truth
                };
                added
            }
            _ => return None,
        };
        concealed.push(Concealed { kind: k, value });
    }

    // The nominal model: the chain without the effects, every parameter
    // off by up to 30 %.
    let off: Vec<f64> = values
        .iter()
        .map(|v| v * (1.0 + 0.3 * (2.0 * rng.uniform() - 1.0)))
        .collect();
    let mut nominal = file(model, output, off, Effects::default())?;
    if time {
        nominal.effects.time_delay_s = Some(hold);
    }

    let record = match kind {
        Kind::Frf { std_dev } => {
            if kinds.iter().any(|&k| effect_domain(k) == "time") {
                return None;
            }
            frf_record(rng, &truth, &sensors, band, noise, std_dev)?
        }
        Kind::Time { excitation, closed } => {
            let mut rec = TimeDraw {
                rng,
                truth: &mut truth,
                sensors: &sensors,
                fs,
                band,
                f_min,
                noise,
                excitation,
                closed,
            };
            let (record, time_concealed) = rec.record(&kinds)?;
            concealed.extend(time_concealed);
            record
        }
    };
    concealed.sort_by_key(|a| a.kind);
    Some(Case {
        index,
        truth,
        nominal,
        concealed,
        sensors,
        noise,
        band_hz: band,
        record,
    })
}

/// Whether effect `k` can be concealed in a record of `model`.
fn allowed(k: EffectKind, model: &Model, time: bool, closed: bool) -> bool {
    let free_driven = model.actuator().plus > model.gap();
    match k {
        // No causal time-domain form.
        EffectKind::HystereticDamping => !time,
        // Friction to the ground on a driven mass that moves as a rigid
        // body.
        EffectKind::ViscousFriction | EffectKind::PreSlidingFriction => free_driven,
        EffectKind::CoulombFriction => time,
        EffectKind::Backlash => time && default_backlash_link(model).is_some(),
        // In an open loop a constant force is the operating point's.
        EffectKind::Offset => time && closed,
        EffectKind::ExtraMode => model.n_masses() < 6,
        _ => true,
    }
}

/// A chain with one mass more at its free end, tuned to add a resonance
/// inside `band`: the extended model, its parameters and the resonance it
/// adds (Hz; the extended chain's resonance farthest from the original's).
fn extra_mass(
    rng: &mut XorShift,
    model: &Model,
    values: &[f64],
    band: (f64, f64),
) -> Option<(Model, Vec<f64>, f64)> {
    let n = model.n_masses();
    let ext = Model::new(n + 1, model.gap(), model.actuator(), model.sensor()).ok()?;
    let old = model.parameters();
    let mut by_name: BTreeMap<String, f64> = old.iter().cloned().zip(values.to_vec()).collect();
    let last = values[n - 1];
    let m = last * rng.log_uniform(0.05, 0.5);
    let f = rng.log_uniform(2.0 * band.0, band.1 / 1.5);
    let c = m * (2.0 * PI * f).powi(2);
    by_name.insert(mms::mass_name(n + 1), m);
    by_name.insert(mms::spring_name(n), c);
    by_name.insert(
        mms::damper_name(n),
        2.0 * rng.log_uniform(0.01, 0.05) * (c * m).sqrt(),
    );
    let ext_values: Vec<f64> = ext
        .parameters()
        .iter()
        .map(|p| by_name.get(p).copied())
        .collect::<Option<_>>()?;
    let (_, old_poles) = features(model, values);
    let (_, new_poles) = features(&ext, &ext_values);
    let added = new_poles
        .iter()
        .map(|&p| {
            let d = old_poles
                .iter()
                .map(|&q| (p / q).ln().abs())
                .fold(f64::INFINITY, f64::min);
            (d, p)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))?
        .1;
    // The added mode inside the band, and apart from the others.
    let apart = new_poles
        .iter()
        .filter(|&&p| p != added)
        .all(|&p| (p / added).ln().abs() > 0.05);
    (added > band.0 && added < band.1 && apart).then_some((ext, ext_values, added))
}

/// An FRF file of the truth at each sensor: log-spaced lines over `band`
/// with relative complex noise.
fn frf_record(
    rng: &mut XorShift,
    truth: &ModelFile,
    sensors: &[Port],
    band: (f64, f64),
    noise: f64,
    std_dev: bool,
) -> Option<Record> {
    let lines = pick(rng, &[300usize, 500, 1000, 2000]);
    let f: Vec<f64> = (0..lines)
        .map(|k| band.0 * (band.1 / band.0).powf(k as f64 / (lines - 1) as f64))
        .collect();
    let mut out = Vec::new();
    for s in sensors {
        let chain = truth.model.with_sensor(*s).ok()?;
        let g = ChainResponse::with_effects(&chain, truth.output, &truth.effects);
        let h = g.eval_many(truth.parameters.values(), &f).ok()?;
        let h: Vec<Complex64> = h
            .into_iter()
            .map(|h| h * (Complex64::new(noise * rng.normal(), noise * rng.normal())).exp())
            .collect();
        let sd: Vec<f64> = h.iter().map(|h| noise * h.norm()).collect();
        let mut frf = Frf::new(f.clone(), h, None).ok()?;
        if std_dev {
            frf = frf.with_std_dev(sd).ok()?;
        }
        out.push(frf);
    }
    Some(Record::Frf { frf: out, std_dev })
}

/// The drawing of a time-domain record.
struct TimeDraw<'a> {
    rng: &'a mut XorShift,
    truth: &'a mut ModelFile,
    sensors: &'a [Port],
    fs: f64,
    band: (f64, f64),
    f_min: f64,
    noise: f64,
    excitation: Excitation,
    closed: bool,
}

/// How steeply an excitation's spectrum rises over the band, as test
/// engineers shape it so that the output stays above a white sensor
/// noise: `f^2` for a position (a free mass's response falls as
/// `1/f^2`), `f` for a velocity, flat for an acceleration.
fn shaping(output: Output) -> i32 {
    match output {
        Output::Position => 2,
        Output::Velocity => 1,
        Output::Acceleration => 0,
    }
}

impl TimeDraw<'_> {
    /// The record, with the time-domain effects of `kinds` added to the
    /// truth and sized on its motion.
    fn record(&mut self, kinds: &[EffectKind]) -> Option<(Record, Vec<Concealed>)> {
        let fs = self.fs;
        // Long enough for the default H1 estimate (16 averages, half
        // overlapping) to put five lines below the lowest feature.
        let needed = (8.5 * 5.0 * fs / self.f_min).max(1e4);
        if needed > 1e6 {
            return None;
        }
        let n = self.rng.log_uniform(needed, 1e6).round() as usize;
        let (u, reference, period) = self.excitation(n)?;
        // A multisine keeps whole periods.
        let n = u.len();
        let controller = self.closed.then(|| self.controller());
        // The linear truth's run sizes the time-domain effects: the force
        // the plant sees, and the deflection of the spring a backlash
        // would sit in (over the first stretch).
        let link = default_backlash_link(&self.truth.model);
        let (force_rms, spread) = {
            let linear = ModelFile {
                effects: self.truth.effects.linear(),
                ..self.truth.clone()
            };
            let sim = Simulator::new(&linear, fs, &SimOptions::default()).ok()?;
            let m = (n / 4).clamp(1000.min(n), 50_000);
            let place = link.map(|i| Port::new(i + 1, i));
            let (force, deflection) = match &controller {
                None => {
                    let at: Vec<Port> = place.into_iter().collect();
                    let (_, d) = sim.run_at(&u[..m], &at).ok()?;
                    (rms(&u[..m]), d.into_iter().next())
                }
                Some(c) => {
                    let observed: Vec<(Port, f64)> = place.into_iter().map(|p| (p, 0.0)).collect();
                    let run = sim
                        .run_closed_loop(&ClosedLoop {
                            disturbance: Some(&u[..m]),
                            observed: &observed,
                            ..ClosedLoop::new(c, &reference[..m])
                        })
                        .ok()?;
                    if grows(&run.y) {
                        return None;
                    }
                    (rms(&run.u), run.at.into_iter().next())
                }
            };
            let spread = deflection.map(|d| {
                let mean = d.iter().sum::<f64>() / d.len() as f64;
                (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
            });
            (force, spread)
        };
        if !(force_rms > 0.0 && force_rms.is_finite()) {
            return None;
        }
        let mut concealed = Vec::new();
        for &k in kinds {
            let value = match k {
                EffectKind::CoulombFriction => {
                    let f = force_rms * self.rng.log_uniform(0.02, 0.5);
                    self.truth.effects.coulomb_friction = Some(f);
                    f
                }
                EffectKind::Offset => {
                    let f = force_rms * self.rng.log_uniform(0.02, 0.3);
                    let f = if self.rng.uniform() < 0.5 { f } else { -f };
                    self.truth.effects.offset_force = Some(f);
                    f
                }
                EffectKind::Backlash => {
                    let g = spread? * self.rng.log_uniform(0.3, 3.0);
                    if !(g > 0.0 && g.is_finite()) {
                        return None;
                    }
                    self.truth.effects.backlash_gap = Some(g);
                    g
                }
                _ => continue,
            };
            concealed.push(Concealed { kind: k, value });
        }
        let sim = Simulator::new(self.truth, fs, &SimOptions::default()).ok()?;
        let others: Vec<Port> = self.sensors[1..].to_vec();
        let (clean, at, u_rec, loop_spec) = match &controller {
            None => {
                let (y, at) = sim.run_at(&u, &others).ok()?;
                (y, at, u.clone(), None)
            }
            Some(c) => {
                // The sensor noise, fed back through the law, is a
                // disturbance of its own (the law is linear in what it
                // reads): simulated with it, the recorded input satisfies
                // the law on the noisy reading exactly.
                let draft = sim
                    .run_closed_loop(&ClosedLoop {
                        disturbance: Some(&u),
                        ..ClosedLoop::new(c, &reference)
                    })
                    .ok()?;
                let sigma = self.noise * motion_rms(&draft.y);
                let e: Vec<f64> = (0..n).map(|_| sigma * self.rng.normal()).collect();
                let fed_back = law_of_noise(c, &e, fs);
                let d_total: Vec<f64> = u.iter().zip(&fed_back).map(|(a, b)| a + b).collect();
                let observed: Vec<(Port, f64)> = others.iter().map(|&p| (p, 0.0)).collect();
                let run = sim
                    .run_closed_loop(&ClosedLoop {
                        disturbance: Some(&d_total),
                        observed: &observed,
                        ..ClosedLoop::new(c, &reference)
                    })
                    .ok()?;
                let y: Vec<f64> = run.y.iter().zip(&e).map(|(y, e)| y + e).collect();
                if !y.iter().all(|v| v.is_finite()) || grows(&y) {
                    return None;
                }
                let excited = (self.excitation != Excitation::MotionProfile).then(|| u.clone());
                let spec = LoopSpec {
                    controller: c.clone(),
                    reference: reference.clone(),
                    disturbance: excited,
                };
                // The record's noise is already in y.
                (y, run.at, run.u, Some(spec))
            }
        };
        let mut outputs: Vec<Vec<f64>> = vec![clean];
        outputs.extend(at);
        let mut samples = Vec::with_capacity(outputs.len());
        for (i, y) in outputs.into_iter().enumerate() {
            if !y.iter().all(|v| v.is_finite()) {
                return None;
            }
            let y = if loop_spec.is_some() && i == 0 {
                y
            } else {
                let sigma = self.noise * motion_rms(&y);
                y.iter().map(|v| v + sigma * self.rng.normal()).collect()
            };
            samples.push(Samples {
                u: u_rec.clone(),
                y,
                fs,
                excitation: loop_spec.as_ref().and_then(|l| l.disturbance.clone()),
            });
        }
        let welch = WelchOptions {
            period,
            ..WelchOptions::default()
        };
        let frf: Vec<Frf> = samples
            .iter()
            .map(|s| s.frf(0..n, &welch).ok())
            .collect::<Option<_>>()?;
        Some((
            Record::Time {
                samples,
                frf,
                welch,
                excitation: self.excitation,
                closed_loop: loop_spec,
            },
            concealed,
        ))
    }

    /// A position controller for the chain's total mass, `kv (kp (r - y)
    /// minus v)`, closing the loop at 5 to 20 % of the lowest feature with
    /// 0.7 damping for a rigid body.
    fn controller(&mut self) -> Controller {
        let total: f64 = self.truth.parameters.values()[..self.truth.model.n_masses()]
            .iter()
            .sum();
        let wc = 2.0 * PI * self.f_min * self.rng.log_uniform(0.05, 0.2);
        let kv = 1.4 * total * wc;
        let kp = wc / 1.4;
        Controller::new(kp, kv)
    }

    /// The excitation of `n` samples (the plant's force in an open loop,
    /// the injected disturbance inside one), the position reference (zero
    /// but for a motion profile inside a loop), and the period of a
    /// multisine.
    fn excitation(&mut self, n: usize) -> Option<(Vec<f64>, Vec<f64>, Option<usize>)> {
        let (fs, band) = (self.fs, self.band);
        let rng = &mut *self.rng;
        let mut reference = vec![0.0; n];
        let (u, period) = match self.excitation {
            Excitation::Noise => {
                let mut x: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
                // Rising as f^k from the band's bottom to its top (one
                // first-order shelf per power), then low-passed there.
                let top = band.1.min(0.45 * fs);
                let shelf = shelf_section(band.0, top, fs);
                let mut sections = vec![shelf; shaping(self.truth.output) as usize];
                sections.extend(crate::idim::butterworth(4, top, fs));
                for s in &sections {
                    let mut z = (0.0, 0.0);
                    for v in x.iter_mut() {
                        *v = biquad(s, &mut z, *v);
                    }
                }
                (x, None)
            }
            Excitation::Multisine
            | Excitation::OddMultisine
            | Excitation::OddOddMultisine
            | Excitation::BandLimitedMultisine => {
                // One period puts its first line at or below a fifth of the
                // lowest feature; at least four periods.
                let mut p = 64usize;
                while fs / (p as f64) > self.f_min / 5.0 {
                    p *= 2;
                }
                if n / p < 4 {
                    return None;
                }
                let df = fs / p as f64;
                let (lo, hi) = match self.excitation {
                    Excitation::BandLimitedMultisine => {
                        let a = band.0 * rng.log_uniform(1.0, 6.0);
                        (a, (a * rng.log_uniform(4.0, 20.0)).min(band.1))
                    }
                    _ => band,
                };
                let k_lo = ((lo / df).ceil() as usize).max(1);
                let k_hi = ((hi / df).floor() as usize).min(p / 2 - 1);
                let lines: Vec<usize> = (k_lo..=k_hi)
                    .filter(|&k| match self.excitation {
                        Excitation::OddMultisine => k % 2 == 1,
                        Excitation::OddOddMultisine => k % 4 == 1,
                        _ => true,
                    })
                    .collect();
                if lines.len() < 8 {
                    return None;
                }
                let phases: Vec<f64> = lines.iter().map(|_| 2.0 * PI * rng.uniform()).collect();
                let k = shaping(self.truth.output);
                let amplitudes: Vec<f64> = lines
                    .iter()
                    .map(|&l| (l as f64 * df / band.0).max(1.0).powi(k))
                    .collect();
                let one = multisine_period(p, &lines, &phases, &amplitudes);
                // Whole periods, at least the samples drawn (10^4 at least)
                // but never past 10^6.
                let periods = n.div_ceil(p).min(1_000_000 / p);
                let u: Vec<f64> = (0..periods * p).map(|k| one[k % p]).collect();
                (u, Some(p))
            }
            Excitation::Sweep => {
                // Logarithmic sweeps over the band, each 2 to 20 s or the
                // record.
                let t_sweep = (n as f64 / fs).min(rng.log_uniform(2.0, 20.0));
                let len = (t_sweep * fs) as usize;
                let (f0, f1) = band;
                let k = (f1 / f0).ln() / t_sweep;
                let power = shaping(self.truth.output);
                let u: Vec<f64> = (0..n)
                    .map(|i| {
                        let t = (i % len) as f64 / fs;
                        // The amplitude follows the instantaneous
                        // frequency as a multisine's lines do.
                        (k * t).exp().powi(power)
                            * (2.0 * PI * f0 * ((k * t).exp() - 1.0) / k).sin()
                    })
                    .collect();
                (u, None)
            }
            Excitation::MotionProfile => {
                // Back-and-forth moves of a few tenths of a second to
                // seconds, each a smoothed force pulse (accelerate, then
                // brake); inside a loop they are the reference.
                let move_s = rng.log_uniform(0.2, 2.0) * (5.0 / self.f_min).min(1.0);
                let len = ((move_s * fs) as usize).max(8);
                let pause = len / 2;
                let cycle = 2 * (2 * len + pause);
                let shape = |i: usize| -> f64 {
                    // One move: a raised-cosine pulse up, then one down.
                    let j = i % cycle;
                    let dir = if j < cycle / 2 { 1.0 } else { -1.0 };
                    let j = j % (cycle / 2);
                    if j >= 2 * len {
                        return 0.0;
                    }
                    let s = if j < len { 1.0 } else { -1.0 };
                    let phase = (j % len) as f64 / len as f64;
                    dir * s * (PI * phase).sin().powi(2)
                };
                let u: Vec<f64> = (0..n).map(shape).collect();
                if self.closed {
                    // The position of the pulse pattern, as a reference of
                    // unit stroke; no injected excitation.
                    let mut v = 0.0;
                    let mut x = 0.0;
                    for (i, r) in reference.iter_mut().enumerate() {
                        v += u[i] / fs;
                        x += v / fs;
                        *r = x;
                    }
                    let stroke = reference.iter().fold(0.0f64, |a, r| a.max(r.abs()));
                    if stroke > 0.0 {
                        reference.iter_mut().for_each(|r| *r /= stroke);
                    }
                    // A small dither keeps the plant's input from being
                    // the law alone.
                    (vec![0.0; n], None)
                } else {
                    (u, None)
                }
            }
        };
        let scale = rms(&u);
        let u = if scale > 0.0 {
            u.iter().map(|v| v / scale).collect()
        } else {
            u
        };
        if self.closed && self.excitation != Excitation::MotionProfile {
            // Inside a loop at standstill: the excitation is the
            // injected disturbance, scaled to the force a controller
            // exerts over the band.
            let total: f64 = self.truth.parameters.values()[..self.truth.model.n_masses()]
                .iter()
                .sum();
            let w = 2.0 * PI * self.f_min;
            let level = total * w * w * 1e-3;
            return Some((u.iter().map(|v| v * level).collect(), reference, period));
        }
        let len = u.len();
        reference.truncate(len);
        Some((u, reference, period))
    }
}

/// One sample of a second-order section (direct form II transposed).
fn biquad(&[b0, b1, b2, a1, a2]: &[f64; 5], z: &mut (f64, f64), x: f64) -> f64 {
    let y = b0 * x + z.0;
    z.0 = b1 * x - a1 * y + z.1;
    z.1 = b2 * x - a2 * y;
    y
}

/// One period of `p` samples of a multisine on `lines` with `phases` and
/// `amplitudes`.
fn multisine_period(p: usize, lines: &[usize], phases: &[f64], amplitudes: &[f64]) -> Vec<f64> {
    (0..p)
        .map(|k| {
            lines
                .iter()
                .zip(phases)
                .zip(amplitudes)
                .map(|((&l, &ph), &a)| a * (2.0 * PI * ((l * k) % p) as f64 / p as f64 + ph).cos())
                .sum()
        })
        .collect()
}

/// A first-order shelf `(s + w1) / (s + w2)` (bilinear, prewarped),
/// normalised to unit gain at DC: flat below `f1`, rising as `f` up to
/// `f2`, flat above.
fn shelf_section(f1: f64, f2: f64, fs: f64) -> [f64; 5] {
    let warp = |f: f64| 2.0 * fs * (PI * f / fs).tan();
    let (w1, w2) = (warp(f1), warp(f2));
    let c = 2.0 * fs;
    // H(z) = (b0 + b1 z^-1) / (1 + a1 z^-1), scaled by w2 / w1.
    let g = w2 / w1;
    let a0 = c + w2;
    [
        g * (c + w1) / a0,
        g * (w1 - c) / a0,
        0.0,
        (w2 - c) / a0,
        0.0,
    ]
}

/// Whether a loop's output grows: the RMS of its last tenth more than
/// a hundred times that of its first (an unstable loop that has not yet
/// left the finite numbers).
fn grows(y: &[f64]) -> bool {
    let k = (y.len() / 10).max(1);
    let (a, b) = (rms(&y[..k]), rms(&y[y.len() - k..]));
    !(a.is_finite() && b.is_finite()) || b > 100.0 * a.max(f64::MIN_POSITIVE)
}

/// RMS of `x`.
fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

/// RMS of `x` about its least-squares quadratic in time: the motion a
/// sensor sees, without the drift of a free axis.
fn motion_rms(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 4 {
        return rms(x);
    }
    // Orthonormal basis of 1, t, t^2 on the samples, by Gram-Schmidt.
    let t: Vec<f64> = (0..n)
        .map(|k| 2.0 * k as f64 / (n - 1) as f64 - 1.0)
        .collect();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for d in 0..3 {
        let mut v: Vec<f64> = t.iter().map(|t| t.powi(d)).collect();
        for b in &basis {
            let c: f64 = v.iter().zip(b).map(|(a, b)| a * b).sum();
            v.iter_mut().zip(b).for_each(|(v, b)| *v -= c * b);
        }
        let norm = v.iter().map(|v| v * v).sum::<f64>().sqrt();
        v.iter_mut().for_each(|v| *v /= norm);
        basis.push(v);
    }
    let mut r = x.to_vec();
    for b in &basis {
        let c: f64 = x.iter().zip(b).map(|(a, b)| a * b).sum();
        r.iter_mut().zip(b).for_each(|(r, b)| *r -= c * b);
    }
    rms(&r)
}

/// What a controller adds to its output when its reading carries the
/// noise `e`: `-kv (kp e + v(e))`, `v` its filtered difference.
fn law_of_noise(c: &Controller, e: &[f64], fs: f64) -> Vec<f64> {
    let taps = &c.filter;
    let mut prev = 0.0;
    (0..e.len())
        .map(|k| {
            let ef: f64 = taps
                .iter()
                .enumerate()
                .map(|(i, t)| if k >= i { t * e[k - i] } else { 0.0 })
                .sum();
            let v = (ef - prev) * fs;
            prev = ef;
            -c.kv * (c.kp * e[k] + v)
        })
        .collect()
}

/// What the diagnosis said about a case, and how it scores.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// The case's index.
    pub index: usize,
    /// Its cell.
    pub cell: Cell,
    /// Masses of the nominal chain.
    pub masses: usize,
    /// Sensors.
    pub sensors: usize,
    /// Samples per output (0: an FRF file).
    pub samples: usize,
    /// The noise level.
    pub noise: f64,
    /// What was concealed.
    pub concealed: Vec<Concealed>,
    /// The headline (`none` when nothing is named).
    pub headline: EffectKind,
    /// Every effect the verdict names, with its parameters.
    pub named: Vec<(EffectKind, BTreeMap<String, f64>)>,
    /// The domain that decided (`None`: nothing named).
    pub decided_by: Option<String>,
    /// Why the verdict is what it is (the JSON `verdict.reason.kind`).
    #[serde(default)]
    pub reason: String,
    /// The headline is right: one of the concealed kinds, or `none` for a
    /// control.
    pub right: bool,
    /// The headline's parameter over the truth's, less one (a right
    /// headline with a parameter; the extra mode's resonance).
    pub parameter_error: Option<f64>,
    /// The diagnosis's error, if it failed.
    pub error: Option<String>,
    /// Wall time of the diagnosis, s.
    pub seconds: f64,
    /// On a control: whether the identification ranked the true
    /// structure first or among those it cannot tell from the first.
    pub identified: Option<bool>,
    /// Wall time of the identification, s.
    pub identify_seconds: Option<f64>,
}

/// Diagnoses a case with the default options, as `mms diagnose` does, and
/// on a control identifies its structure.
pub fn run_case(c: &Case) -> Outcome {
    let o = match &c.record {
        Record::Frf { .. } => DiagnosisOptions::default(),
        Record::Time { welch, .. } => DiagnosisOptions {
            welch: welch.clone(),
            ..DiagnosisOptions::default()
        },
    };
    let start = std::time::Instant::now();
    let result = diagnose_case(c, &o);
    let seconds = start.elapsed().as_secs_f64();
    let reason = result
        .as_ref()
        .map_or("", |d| d.verdict.reason.kind())
        .to_string();
    let (headline, named, decided_by, error) = match &result {
        Ok(d) => {
            let v = &d.verdict;
            let named: Vec<(EffectKind, BTreeMap<String, f64>)> = v
                .effects
                .iter()
                .filter(|e| e.kind != EffectKind::None)
                .map(|e| (e.kind, e.parameters.clone()))
                .collect();
            let by = v.decided_by.map(|d| match d {
                Domain::Frequency => "frequency".to_string(),
                Domain::Time => "time".to_string(),
            });
            (v.headline, named, by, None)
        }
        Err(e) => (EffectKind::None, Vec::new(), None, Some(e.clone())),
    };
    let right = error.is_none()
        && if c.concealed.is_empty() {
            headline == EffectKind::None
        } else {
            c.concealed.iter().any(|k| k.kind == headline)
        };
    let parameter_error = if right && headline != EffectKind::None {
        let truth = c.concealed.iter().find(|k| k.kind == headline);
        let name = match headline {
            EffectKind::ExtraMode => Some("resonance_hz"),
            k => k.parameter_name(),
        };
        match (truth, name, named.first()) {
            (Some(t), Some(name), Some((_, p))) => p.get(name).map(|v| v / t.value - 1.0),
            _ => None,
        }
    } else {
        None
    };
    let (identified, identify_seconds) = if c.concealed.is_empty() {
        let t = std::time::Instant::now();
        let id = identify_case(c);
        (Some(id), Some(t.elapsed().as_secs_f64()))
    } else {
        (None, None)
    };
    Outcome {
        index: c.index,
        cell: c.cell(),
        masses: c.nominal.model.n_masses(),
        sensors: c.sensors.len(),
        samples: c.samples(),
        noise: c.noise,
        concealed: c.concealed.clone(),
        headline,
        named,
        decided_by,
        reason,
        right,
        parameter_error,
        error,
        seconds,
        identified,
        identify_seconds,
    }
}

/// The diagnosis of a case, one sensor or all at once.
fn diagnose_case(c: &Case, o: &DiagnosisOptions) -> Result<RecordingDiagnosis, String> {
    let (frfs, samples, spec): (&[Frf], Option<&[Samples]>, Option<&LoopSpec>) = match &c.record {
        Record::Frf { frf, .. } => (frf, None, None),
        Record::Time {
            samples,
            frf,
            closed_loop,
            ..
        } => (frf, Some(samples), closed_loop.as_ref()),
    };
    let record = spec.map(|l| LoopRecord {
        controller: &l.controller,
        reference: &l.reference,
        disturbance: l.disturbance.as_deref(),
        feedback: None,
    });
    if c.sensors.len() == 1 {
        return diagnose_recording(
            &frfs[0],
            samples.map(|s| &s[0]),
            &c.nominal,
            record.as_ref(),
            o,
        )
        .map_err(|e| e.to_string());
    }
    let outputs: Vec<OutputRecording> = c
        .sensors
        .iter()
        .enumerate()
        .map(|(i, &s)| OutputRecording {
            frf: &frfs[i],
            samples: samples.map(|x| &x[i]),
            chain: c.nominal.model.with_sensor(s).expect("a mass of the chain"),
        })
        .collect();
    let d =
        diagnose_sensors(&outputs, &c.nominal, record.as_ref(), o).map_err(|e| e.to_string())?;
    // The rig's verdict: all outputs at once where there is one.
    Ok(match d.joint {
        Some(j) => j,
        None => d.outputs.into_iter().next().expect("one output at least"),
    })
}

/// Whether the identification of a control finds its structure: ranked
/// first, or among the candidates it cannot tell from the first.
fn identify_case(c: &Case) -> bool {
    let frfs: &[Frf] = match &c.record {
        Record::Frf { frf, .. } => frf,
        Record::Time { frf, .. } => frf,
    };
    let truth = c.nominal.model;
    let o = IdentifyOptions::default();
    if c.sensors.len() == 1 {
        let Ok(id) = identify(&frfs[0], c.nominal.output, &o) else {
            return false;
        };
        let Some(first) = id.candidates.first() else {
            return false;
        };
        if first.model == truth {
            return true;
        }
        let Some(mine) = id.candidates.iter().find(|k| k.model == truth) else {
            return false;
        };
        return id
            .indistinguishable
            .first()
            .is_some_and(|g| g.contains(&mine.id));
    }
    let outputs: Vec<SensorOutput> = c
        .sensors
        .iter()
        .enumerate()
        .map(|(i, &s)| SensorOutput {
            name: format!("y{}", i + 1),
            frf: &frfs[i],
            location: Some(s.into()),
        })
        .collect();
    let Ok(id) = identify_sensors(&outputs, c.nominal.output, &o) else {
        return false;
    };
    let is_truth = |m: &[Model]| m.first() == Some(&truth);
    let Some(first) = id.candidates.first() else {
        return false;
    };
    if is_truth(&first.models) {
        return true;
    }
    let Some(mine) = id.candidates.iter().find(|k| is_truth(&k.models)) else {
        return false;
    };
    id.indistinguishable
        .first()
        .is_some_and(|g| g.contains(&mine.id))
}

/// A share: how many of how many.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Share {
    /// The cases that count.
    pub hits: usize,
    /// All cases.
    pub of: usize,
}

impl Share {
    fn add(&mut self, hit: bool) {
        self.of += 1;
        self.hits += hit as usize;
    }

    /// `hits / of` (1 for none).
    pub fn rate(&self) -> f64 {
        if self.of == 0 {
            1.0
        } else {
            self.hits as f64 / self.of as f64
        }
    }
}

/// The score of a set of outcomes.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// Cases.
    pub cases: usize,
    /// Cases whose diagnosis failed with an error.
    pub errors: usize,
    /// The headline right, over the cases with an effect.
    pub effect_right: Share,
    /// Nothing named, over the controls.
    pub controls_clean: Share,
    /// True kind (the first concealed, `none` for a control) against the
    /// headline: counts.
    pub confusion: BTreeMap<EffectKind, BTreeMap<EffectKind, usize>>,
    /// Per kind: right headlines whose parameter is within 15 %.
    pub parameter_within_15: BTreeMap<EffectKind, Share>,
    /// Per kind: the median absolute relative parameter error of right
    /// headlines.
    pub parameter_median: BTreeMap<EffectKind, f64>,
    /// Right (headline right, or nothing on a control) per cell of
    /// excitation, the concealed effects' domain and the loop.
    pub cells: BTreeMap<String, Share>,
    /// Median and largest diagnosis time per decade of samples (`frf` for
    /// FRF files), s.
    pub time: BTreeMap<String, (usize, f64, f64)>,
    /// The diagnosis time of the one-sensor time records of 2-mass chains
    /// per 100 000 samples: cases, median and largest, s (the target's
    /// unit: a cost linear in the record's length).
    pub two_mass_per_100k: (usize, f64, f64),
    /// The identification right on the controls, with one sensor and with
    /// two.
    pub identified: [Share; 2],
}

impl Summary {
    /// Scores `outcomes`.
    pub fn of(outcomes: &[Outcome]) -> Summary {
        let mut s = Summary {
            cases: outcomes.len(),
            ..Summary::default()
        };
        let mut errors: BTreeMap<EffectKind, Vec<f64>> = BTreeMap::new();
        let mut times: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        let mut per_100k: Vec<f64> = Vec::new();
        for o in outcomes {
            s.errors += o.error.is_some() as usize;
            let truth = o.concealed.first().map_or(EffectKind::None, |c| c.kind);
            *s.confusion
                .entry(truth)
                .or_default()
                .entry(o.headline)
                .or_default() += 1;
            if o.concealed.is_empty() {
                s.controls_clean.add(o.right);
            } else {
                s.effect_right.add(o.right);
            }
            if o.right && o.headline != EffectKind::None {
                if let Some(e) = o.parameter_error {
                    s.parameter_within_15
                        .entry(o.headline)
                        .or_default()
                        .add(e.abs() <= 0.15);
                    errors.entry(o.headline).or_default().push(e.abs());
                }
            }
            let domain = if o.concealed.is_empty() {
                "control"
            } else if o.concealed.iter().all(|c| effect_domain(c.kind) == "time") {
                "time_effect"
            } else if o
                .concealed
                .iter()
                .all(|c| effect_domain(c.kind) == "frequency")
            {
                "frequency_effect"
            } else {
                "both_domains"
            };
            let cell = format!(
                "{} / {} / {}",
                o.cell.excitation,
                domain,
                if o.cell.closed_loop { "closed" } else { "open" }
            );
            s.cells.entry(cell).or_default().add(o.right);
            let decade = if o.samples == 0 {
                "frf".to_string()
            } else {
                format!("1e{}", (o.samples as f64).log10().floor() as i32)
            };
            times.entry(decade).or_default().push(o.seconds);
            if o.samples > 0 && o.masses == 2 && o.sensors == 1 {
                per_100k.push(o.seconds * 1e5 / o.samples as f64);
            }
            if let Some(id) = o.identified {
                s.identified[(o.sensors >= 2) as usize].add(id);
            }
        }
        for (k, mut v) in errors {
            v.sort_by(f64::total_cmp);
            s.parameter_median.insert(k, v[v.len() / 2]);
        }
        for (k, mut v) in times {
            v.sort_by(f64::total_cmp);
            let max = v[v.len() - 1];
            s.time.insert(k, (v.len(), v[v.len() / 2], max));
        }
        per_100k.sort_by(f64::total_cmp);
        if let Some(&max) = per_100k.last() {
            s.two_mass_per_100k = (per_100k.len(), per_100k[per_100k.len() / 2], max);
        }
        s
    }
}
