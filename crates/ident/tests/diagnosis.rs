//! The one-call diagnosis ([`ident::diagnosis::diagnose_recording`]) on
//! linear recordings that hold nothing but parameter error and noise: it
//! must name nothing. Seeded cases of 2 to 4 masses, noise 0.5 to 2 % and
//! every parameter off by up to ±8 %, as measured FRFs with their
//! standard deviation per line.

mod common;
use common::{chain_parameters, log_uniform, model_file};
use frf::welch::{h1, WelchOptions};
use frf::{Complex64, Frf, Samples};
use ident::diagnose::EffectKind;
use ident::diagnosis::{diagnose_recording, DiagnosisOptions, Domain, Reason};
use mms::model_file::ModelFile;
use mms::response::{ChainResponse, Parameters};
use mms::simulate::simulate;
use mms::xorshift::XorShift;
use mms::{Model, Output};
use std::f64::consts::PI;

const FS: f64 = 1000.0;
const PERIOD: usize = 1000;

/// A random chain of `n` masses satisfying rule (3), masses 0.5-2, link
/// modes 4-60 Hz, 2-8 % damping per link.
fn chain(rng: &mut XorShift, n: usize) -> (Model, Vec<f64>) {
    let all = mms::rule3_models(n).unwrap();
    let model = all[(rng.uniform() * all.len() as f64) as usize % all.len()];
    let values = chain_parameters(rng, &model, (4.0, 60.0));
    (model, values)
}

/// The truth and a nominal model with every parameter off by up to ±8 %.
fn models(rng: &mut XorShift, n: usize, output: Output) -> (ModelFile, ModelFile) {
    let (model, values) = chain(rng, n);
    let truth = model_file(model, output, values.clone());
    let off: Vec<f64> = values
        .iter()
        .map(|v| v * (1.0 + 0.08 * (2.0 * rng.uniform() - 1.0)))
        .collect();
    let nominal = ModelFile {
        parameters: Parameters::from_values(&model, off).unwrap(),
        ..truth.clone()
    };
    (truth, nominal)
}

/// `g` at `values` on the lines `f`, with relative noise `noise` on the
/// real and imaginary part of `ln H`, its standard deviation given.
fn noisy_frf(g: &ChainResponse, values: &[f64], f: &[f64], noise: f64, rng: &mut XorShift) -> Frf {
    let h: Vec<Complex64> = f
        .iter()
        .map(|&f| {
            let h = g.eval(values, f).unwrap();
            h * (Complex64::new(noise * rng.normal(), noise * rng.normal())).exp()
        })
        .collect();
    let sd: Vec<f64> = h.iter().map(|h| noise * h.norm()).collect();
    Frf::new(f.to_vec(), h, None)
        .unwrap()
        .with_std_dev(sd)
        .unwrap()
}

/// A measured FRF of a random linear chain on 400 log-spaced lines 1-200
/// Hz with relative noise 0.5-2 % (its standard deviation given per line).
fn frf_case(seed: u64) -> (Frf, ModelFile, String) {
    let mut rng = XorShift::new(seed);
    let n = 2 + (seed % 3) as usize;
    let output =
        [Output::Position, Output::Velocity, Output::Acceleration][(seed / 3 % 3) as usize];
    let (truth, nominal) = models(&mut rng, n, output);
    let noise = log_uniform(&mut rng, 0.005, 0.02);
    let f: Vec<f64> = (0..400)
        .map(|k| (200f64.ln() * k as f64 / 399.0).exp())
        .collect();
    let g = ChainResponse::new(&truth.model, output);
    let frf = noisy_frf(&g, truth.parameters.values(), &f, noise, &mut rng);
    let label = format!(
        "FRF seed {seed}: {} {output:?}, noise {:.2} %",
        truth.model.id(),
        100.0 * noise
    );
    (frf, nominal, label)
}

/// A random-phase multisine on the lines 1-100 Hz, 8 periods.
fn multisine(rng: &mut XorShift) -> Vec<f64> {
    let phases: Vec<f64> = (0..100).map(|_| 2.0 * PI * rng.uniform()).collect();
    let one: Vec<f64> = (0..PERIOD)
        .map(|k| {
            (1..=100)
                .map(|l| (2.0 * PI * (l * k) as f64 / PERIOD as f64 + phases[l - 1]).cos())
                .sum::<f64>()
                / 7.0
        })
        .collect();
    (0..8).flat_map(|_| one.iter().copied()).collect()
}

/// `truth` driven by the periodic `u` (periods of [`PERIOD`] samples at
/// [`FS`]) with output noise `noise` times the output's RMS about its
/// mean: the FRF over the periods, the samples and how the FRF was made.
fn recorded(
    truth: &ModelFile,
    u: Vec<f64>,
    noise: f64,
    rng: &mut XorShift,
) -> (Frf, Samples, WelchOptions) {
    let clean = simulate(truth, &u, FS).unwrap();
    let mean = clean.iter().sum::<f64>() / clean.len() as f64;
    let rms = (clean.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / clean.len() as f64).sqrt();
    let y: Vec<f64> = clean
        .iter()
        .map(|v| v + noise * rms * rng.normal())
        .collect();
    let welch = WelchOptions {
        period: Some(PERIOD),
        ..WelchOptions::default()
    };
    let frf = h1(&u, &y, FS, &welch).unwrap().frf;
    let samples = Samples {
        u,
        y,
        fs: FS,
        excitation: None,
    };
    (frf, samples, welch)
}

/// A time-domain recording of a random linear chain: a random-phase
/// multisine on the lines 1-100 Hz, 8 periods at 1 kHz, output noise
/// 0.5-2 % of the output's RMS about its mean.
fn time_case(seed: u64) -> (Frf, Samples, ModelFile, WelchOptions, String) {
    let mut rng = XorShift::new(seed);
    let n = 2 + (seed % 3) as usize;
    let output = [Output::Position, Output::Velocity][(seed / 3 % 2) as usize];
    let (truth, mut nominal) = models(&mut rng, n, output);
    // The sampled system's own delay, which its model knows: the input is
    // held over each sample (a zero-order hold: half a sample).
    nominal.effects.time_delay_s = Some(0.5 / FS);
    let noise = log_uniform(&mut rng, 0.005, 0.02);
    let u = multisine(&mut rng);
    let (frf, samples, welch) = recorded(&truth, u, noise, &mut rng);
    let label = format!(
        "time seed {seed}: {} {output:?}, noise {:.2} %",
        truth.model.id(),
        100.0 * noise
    );
    (frf, samples, nominal, welch, label)
}

/// Cases where something is named, printed with what.
fn named(label: &str, d: &ident::diagnosis::RecordingDiagnosis) -> bool {
    let v = &d.verdict;
    let fd = d.frequency_domain.as_ref().map(|f| {
        f.effects
            .iter()
            .chain(&f.rejected)
            .map(|e| format!("{} {:.1}", e.kind.as_str(), e.score))
            .collect::<Vec<_>>()
    });
    eprintln!(
        "{label}: {:?} {:?} ({:?}); frequency domain {fd:?}",
        v.headline, v.decided_by, v.reason
    );
    v.headline != EffectKind::None
}

#[test]
fn linear_frfs_with_parameter_error_and_noise_name_nothing() {
    let mut count = 0;
    for seed in 0..20 {
        let (frf, nominal, label) = frf_case(100 + seed);
        let d =
            diagnose_recording(&frf, None, &nominal, None, &DiagnosisOptions::default()).unwrap();
        count += named(&label, &d) as usize;
    }
    assert!(count <= 1, "{count} of 20 linear FRFs got an effect named");
}

#[test]
fn linear_time_recordings_with_parameter_error_and_noise_name_nothing() {
    let mut count = 0;
    for seed in 0..20 {
        let (frf, samples, nominal, welch, label) = time_case(200 + seed);
        let o = DiagnosisOptions {
            welch,
            ..DiagnosisOptions::default()
        };
        let d = diagnose_recording(&frf, Some(&samples), &nominal, None, &o).unwrap();
        count += named(&label, &d) as usize;
        match &d.time_domain {
            // The time domain ran on the samples; if it decided, it is
            // informative.
            Some(td) => {
                if d.verdict.decided_by == Some(Domain::Time) {
                    assert!(td.informative, "{label}");
                }
            }
            // A position at 1-2 % white noise of its RMS carries
            // information only on the first few lines (it falls as 1/f^2
            // and faster): nothing to compare, said as such.
            None => assert_eq!(d.verdict.reason, Reason::NothingInformative, "{label}"),
        }
    }
    assert!(
        count <= 1,
        "{count} of 20 linear recordings got an effect named"
    );
}

/// A model that knows the drive's hold (half a sample of dead time, as a
/// fitted FRF shows it) is simulated with the hold once: the sampled
/// simulation holds each sample itself. Its time-domain error on the
/// recording of the same chain is then the recording's noise (0.5 %);
/// with the hold applied twice, the half sample of extra lag misses the
/// velocity under a 1-100 Hz multisine at 1 kHz by 1.4-3.3 %.
#[test]
fn the_holds_half_sample_is_simulated_once() {
    for seed in 0..4 {
        let mut rng = XorShift::new(700 + seed);
        let (model, values) = chain(&mut rng, 2 + (seed % 2) as usize);
        let truth = model_file(model, Output::Velocity, values);
        let mut nominal = truth.clone();
        nominal.effects.time_delay_s = Some(0.5 / FS);
        let noise = 0.005;
        let u = multisine(&mut rng);
        let (frf, samples, welch) = recorded(&truth, u, noise, &mut rng);
        let o = DiagnosisOptions {
            welch,
            ..DiagnosisOptions::default()
        };
        let d = diagnose_recording(&frf, Some(&samples), &nominal, None, &o).unwrap();
        let td = d
            .time_domain
            .expect("a multisine's samples are informative");
        let rel = td.fit.before.rms_time_rel;
        assert!(
            rel < 1.3 * noise,
            "seed {seed}: {} misses {rel} of the output, noise {noise}",
            model.id()
        );
    }
}

/// Two sensors on a random linear chain of 2-3 masses: the model's own and
/// one on another mass, each FRF on 300 log-spaced lines 1-200 Hz with its
/// own relative noise of 0.5-2 % (standard deviation given), the truth
/// with a dead time `delay` (seconds; 0 for none) and the nominal model
/// every parameter off by up to ±8 %.
fn two_sensor_case(seed: u64, delay: f64) -> (Vec<(Frf, Model)>, ModelFile, String) {
    let mut rng = XorShift::new(seed);
    let n = 2 + (seed % 2) as usize;
    let (truth, nominal) = models(&mut rng, n, Output::Position);
    let m = truth.model;
    let other = (1..=n)
        .rev()
        .find_map(|k| {
            let port = mms::Port::new(k, 0);
            (port != m.sensor())
                .then(|| Model::new(n, m.gap(), m.actuator(), port).ok())
                .flatten()
        })
        .expect("a chain of two masses or more has a second place for a sensor");
    let effects = mms::response::Effects {
        time_delay_s: (delay > 0.0).then_some(delay),
        ..mms::response::Effects::default()
    };
    let f: Vec<f64> = (0..300)
        .map(|k| (200f64.ln() * k as f64 / 299.0).exp())
        .collect();
    let mut outputs = Vec::new();
    for chain in [m, other] {
        let noise = log_uniform(&mut rng, 0.005, 0.02);
        let g = ChainResponse::with_effects(&chain, Output::Position, &effects);
        let frf = noisy_frf(&g, truth.parameters.values(), &f, noise, &mut rng);
        outputs.push((frf, chain));
    }
    let label = format!(
        "two sensors, seed {seed}: {} and {}, delay {:.2} ms",
        m.id(),
        other.id(),
        1e3 * delay
    );
    (outputs, nominal, label)
}

/// The diagnosis of every output at once names nothing where there is
/// only parameter error and noise, and names a dead time both sensors
/// share, with its value (the truth the recordings were made with).
#[test]
fn two_sensors_diagnosed_at_once() {
    use ident::diagnosis::{diagnose_sensors, OutputRecording};
    let mut spurious = 0;
    let mut delays_found = 0;
    for seed in 0..10 {
        for delay in [0.0, 2e-4 + 1.8e-3 * (seed as f64 / 9.0)] {
            let (outputs, nominal, label) = two_sensor_case(300 + seed, delay);
            let inputs: Vec<OutputRecording> = outputs
                .iter()
                .map(|(frf, chain)| OutputRecording {
                    frf,
                    samples: None,
                    chain: *chain,
                })
                .collect();
            let d =
                diagnose_sensors(&inputs, &nominal, None, &DiagnosisOptions::default()).unwrap();
            assert_eq!(d.outputs.len(), 2, "{label}");
            let joint = d.joint.expect("both outputs have a band");
            assert!(joint.time_domain.is_none(), "{label}: FRFs only");
            let top = &joint.verdict.effects[0];
            eprintln!("{label}: {:?} {:?}", top.kind, top.parameters);
            if delay == 0.0 {
                spurious += (top.kind != EffectKind::None) as usize;
            } else if top.kind == EffectKind::TimeDelay {
                let found = top.parameters["delay_s"];
                assert!((found / delay - 1.0).abs() < 0.05, "{label}: {found}");
                delays_found += 1;
            }
        }
    }
    assert!(spurious <= 1, "{spurious} of 10 got an effect named");
    assert!(delays_found >= 9, "the delay named in {delays_found} of 10");
}

/// Two encoders of a linear chain recorded in the time domain, nothing but
/// parameter error and noise: the diagnosis of both at once (both domains,
/// one parameter set) names nothing, as one output's does.
#[test]
fn two_sensors_in_the_time_domain_name_nothing_when_nothing_is_missing() {
    use ident::diagnosis::{diagnose_sensors, OutputRecording};
    use mms::simulate::{SimOptions, Simulator};
    let mut named_count = 0;
    for seed in 0..6u64 {
        let mut rng = XorShift::new(400 + seed);
        let n = 2 + (seed % 2) as usize;
        let (truth, mut nominal) = models(&mut rng, n, Output::Position);
        nominal.effects.time_delay_s = Some(0.5 / FS);
        let m = truth.model;
        let place = (1..=n)
            .rev()
            .map(|k| mms::Port::new(k, 0))
            .find(|&p| p != m.sensor() && Model::new(n, m.gap(), m.actuator(), p).is_ok())
            .expect("a second place");
        let u = multisine(&mut rng);
        let (y1, at) = Simulator::new(&truth, FS, &SimOptions::default())
            .unwrap()
            .run_at(&u, &[place])
            .unwrap();
        let welch = WelchOptions {
            period: Some(PERIOD),
            ..WelchOptions::default()
        };
        let mut noisy = |y: &[f64]| -> Vec<f64> {
            let mean = y.iter().sum::<f64>() / y.len() as f64;
            let rms = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / y.len() as f64).sqrt();
            let noise = log_uniform(&mut rng, 0.005, 0.02);
            y.iter().map(|v| v + noise * rms * rng.normal()).collect()
        };
        let (y1, y2) = (noisy(&y1), noisy(&at[0]));
        let record = |y: Vec<f64>| {
            let frf = h1(&u, &y, FS, &welch).unwrap().frf;
            let s = Samples {
                u: u.clone(),
                y,
                fs: FS,
                excitation: None,
            };
            (frf, s)
        };
        let ((f1, s1), (f2, s2)) = (record(y1), record(y2));
        let second = Model::new(n, m.gap(), m.actuator(), place).unwrap();
        let outputs = [
            OutputRecording {
                frf: &f1,
                samples: Some(&s1),
                chain: m,
            },
            OutputRecording {
                frf: &f2,
                samples: Some(&s2),
                chain: second,
            },
        ];
        let o = DiagnosisOptions {
            welch: welch.clone(),
            stability: false,
            ..DiagnosisOptions::default()
        };
        let d = diagnose_sensors(&outputs, &nominal, None, &o).unwrap();
        let label = format!(
            "two sensors in time, seed {}: {} and {}",
            400 + seed,
            m.id(),
            second.id()
        );
        if let Some(j) = &d.joint {
            named_count += named(&label, j) as usize;
        }
    }
    assert!(named_count <= 1, "{named_count} of 6 got an effect named");
}

/// A random 2-mass chain with Coulomb friction of a fifth of the drive's
/// RMS force, 40 periods of the multisine (40 000 samples, ten times the
/// time domain's search stretch), 1 % noise: the search on the first
/// samples finds the friction, the whole record's held-out blocks confirm
/// it, and its value, fitted on every sample, is the truth's within 5 %.
#[test]
fn the_whole_record_confirms_and_values_what_the_search_found() {
    let mut rng = XorShift::new(31);
    let (mut truth, mut nominal) = models(&mut rng, 2, Output::Velocity);
    nominal.effects.time_delay_s = Some(0.5 / FS);
    let one = multisine(&mut rng);
    let u: Vec<f64> = (0..5).flat_map(|_| one.iter().copied()).collect();
    let f_rms = (u.iter().map(|v| v * v).sum::<f64>() / u.len() as f64).sqrt();
    let coulomb = 0.2 * f_rms;
    truth.effects.coulomb_friction = Some(coulomb);
    let (frf, samples, welch) = recorded(&truth, u, 0.01, &mut rng);
    let o = DiagnosisOptions {
        welch,
        stability: false,
        ..DiagnosisOptions::default()
    };
    let d = diagnose_recording(&frf, Some(&samples), &nominal, None, &o).unwrap();
    let td = d.time_domain.as_ref().expect("a time-domain part");
    let whole = td.whole_record.expect("searched on the first samples");
    assert_eq!(whole.samples, 40_000);
    assert_eq!(whole.search_samples, o.time_samples);
    assert!(whole.confirmed, "{whole:?}");
    assert_eq!(td.samples, 40_000);
    assert_eq!(
        td.effects[0].kind,
        EffectKind::CoulombFriction,
        "{:?}",
        td.effects
    );
    let got = td.effects[0].parameters["coulomb_n"];
    assert!(
        (got / coulomb - 1.0).abs() < 0.05,
        "{got} against {coulomb}"
    );
}

/// An odd-odd multisine (lines 1, 5, 9, ... of 1-100 Hz, 8 periods) on a
/// random 2-mass chain with a dead time of 3 ms the model lacks, 1 %
/// noise: the unexcited lines (three in four) carry no information and
/// go before the held-out lines are chosen (every 4th of all lines would
/// be unexcited ones), and the frequency domain names the dead time
/// within 5 %.
#[test]
fn an_odd_odd_multisine_names_a_dead_time_from_its_excited_lines() {
    let mut rng = XorShift::new(41);
    let (mut truth, mut nominal) = models(&mut rng, 2, Output::Velocity);
    nominal.effects.time_delay_s = Some(0.5 / FS);
    // The simulation holds the input over each sample (half a sample of
    // dead time, which the nominal model knows): the diagnosis reports
    // the 3 ms on top of it.
    truth.effects.time_delay_s = Some(3e-3);
    let phases: Vec<f64> = (0..100).map(|_| 2.0 * PI * rng.uniform()).collect();
    let one: Vec<f64> = (0..PERIOD)
        .map(|k| {
            (1..=100)
                .filter(|l| l % 4 == 1)
                .map(|l| (2.0 * PI * (l * k) as f64 / PERIOD as f64 + phases[l - 1]).cos())
                .sum::<f64>()
                / 4.0
        })
        .collect();
    let u: Vec<f64> = (0..8).flat_map(|_| one.iter().copied()).collect();
    let (frf, samples, welch) = recorded(&truth, u, 0.01, &mut rng);
    let unexcited = frf
        .std_dev()
        .unwrap()
        .iter()
        .filter(|s| s.is_infinite())
        .count();
    assert!(unexcited > frf.len() / 2, "{unexcited} of {}", frf.len());
    let o = DiagnosisOptions {
        welch,
        stability: false,
        ..DiagnosisOptions::default()
    };
    let d = diagnose_recording(&frf, Some(&samples), &nominal, None, &o).unwrap();
    let fd = d
        .frequency_domain
        .as_ref()
        .expect("a frequency-domain part");
    assert_eq!(
        fd.effects[0].kind,
        EffectKind::TimeDelay,
        "{:?}",
        fd.effects
    );
    let got = fd.effects[0].parameters["delay_s"] - 0.5 / FS;
    assert!((got / 3e-3 - 1.0).abs() < 0.05, "{got}");
}

/// A gain error of 0.56 (a factor of 1.8) behind parameters 2-27 % off: a
/// factor common to the whole FRF is all but a common scale of the chain's
/// parameters, which the calibration imitates as far as their tolerance
/// lets it, pressing them to their bounds. The factor is still named, and
/// within 15 %: its distance from 1 is read from the fit's profile, not
/// from a curvature that only the parameters' prior bounds. (A case of the
/// concealed-effect benchmark, seed 51207, which named nothing before.)
#[test]
fn a_gain_error_behind_a_calibration_at_its_bounds_is_named() {
    let model = Model::new(2, 0, mms::Port::new(1, 0), mms::Port::new(2, 0)).unwrap();
    let values = vec![0.04742, 0.1343, 5648.3, 0.5520];
    let mut truth = model_file(model, Output::Acceleration, values.clone());
    truth.effects.gain_factor = Some(0.557);
    let off = [1.022, 1.087, 1.272, 1.063];
    let nominal = model_file(
        model,
        Output::Acceleration,
        values.iter().zip(off).map(|(v, f)| v * f).collect(),
    );
    let mut rng = XorShift::new(331);
    let f: Vec<f64> = (0..1000)
        .map(|k| 16.0 * (12f64.ln() * k as f64 / 999.0).exp())
        .collect();
    let g = ChainResponse::with_effects(&model, Output::Acceleration, &truth.effects);
    let frf = noisy_frf(&g, truth.parameters.values(), &f, 0.0024, &mut rng);
    let d = diagnose_recording(&frf, None, &nominal, None, &DiagnosisOptions::default()).unwrap();
    assert_eq!(d.verdict.headline, EffectKind::GainError, "{:?}", d.verdict);
    let factor = d.verdict.effects[0].parameters["factor"];
    assert!((factor / 0.557 - 1.0).abs() < 0.15, "factor {factor}");
}

/// Back-and-forth moves of a random 2-mass chain, each a raised-cosine
/// force pulse up and down over 0.3 s with pauses, 1 % noise, Coulomb
/// friction of a fifth of the peak force: the moves reach too few lines
/// for an informative FRF (its period's harmonics fall as the cube of
/// the frequency), so the recording is diagnosed in the time domain alone,
/// which names the friction and its value; it is no error.
#[test]
fn a_motion_profile_is_diagnosed_in_the_time_domain_alone() {
    let mut rng = XorShift::new(5);
    let (mut truth, nominal) = models(&mut rng, 2, Output::Position);
    let len = 300;
    let cycle = 2 * (2 * len + len / 2);
    let pulse = |i: usize| -> f64 {
        let j = i % cycle;
        let dir = if j < cycle / 2 { 1.0 } else { -1.0 };
        let j = j % (cycle / 2);
        if j >= 2 * len {
            return 0.0;
        }
        let s = if j < len { 1.0 } else { -1.0 };
        dir * s * (PI * (j % len) as f64 / len as f64).sin().powi(2)
    };
    let u: Vec<f64> = (0..12 * cycle).map(pulse).collect();
    let coulomb = 0.2;
    truth.effects.coulomb_friction = Some(coulomb);
    let clean = simulate(&truth, &u, FS).unwrap();
    let mean = clean.iter().sum::<f64>() / clean.len() as f64;
    let rms = (clean.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / clean.len() as f64).sqrt();
    let y: Vec<f64> = clean
        .iter()
        .map(|v| v + 0.01 * rms * rng.normal())
        .collect();
    // As a recording is read: the moves repeat, so the FRF is over them.
    let (welch, period) = frf::period::periodic_options(&WelchOptions::default(), &[&u], &y);
    assert_eq!(period, Some(frf::period::Period::Found(cycle)));
    let frf = h1(&u, &y, FS, &welch).unwrap().frf;
    let samples = Samples {
        u,
        y,
        fs: FS,
        excitation: None,
    };
    let o = DiagnosisOptions {
        welch,
        stability: false,
        ..DiagnosisOptions::default()
    };
    let d = diagnose_recording(&frf, Some(&samples), &nominal, None, &o).unwrap();
    assert!(d.frequency_domain.is_none(), "{:?}", d.band_hz);
    assert_eq!(d.verdict.decided_by, Some(Domain::Time), "{:?}", d.verdict);
    assert!(matches!(d.verdict.reason, Reason::TimeDomainOnly));
    assert_eq!(d.verdict.headline, EffectKind::CoulombFriction);
    let got = d.verdict.effects[0].parameters["coulomb_n"];
    assert!((got / coulomb - 1.0).abs() < 0.1, "{got} against {coulomb}");
}
