//! Concealed-effect recordings: the simulator draws a random 3-mass
//! structure, adds one effect (or none) and noise, and the diagnosis gets
//! only the recording and a model whose parameters are perturbed. Scores
//! the top-1 kind per effect and the accuracy of the effect's parameter.

use frf::Frf;
use ident::diagnose::{diagnose, DiagnoseOptions, EffectKind};
use ident::synth::{synthetic, SynthOptions};
use mms::model_file::{ModelFile, Motion};
use mms::response::{ChainResponse, Effects, Parameters};
use mms::xorshift::XorShift;
use num_complex::Complex64;
use std::collections::BTreeMap;
use std::time::Instant;

/// One concealed-effect case: the recording, the perturbed nominal model,
/// the truth.
struct Case {
    data: Frf,
    nominal: ModelFile,
    kind: EffectKind,
    value: Option<f64>,
    /// Every concealed effect and its value (the resonance the extra mass
    /// adds for `extra_mode`).
    truth: Vec<(EffectKind, f64)>,
}

fn draw(seed: u64, kind: EffectKind) -> Case {
    let mut case = draw_many(seed, &[kind]);
    case.kind = kind;
    case.value = case.truth.first().map(|t| t.1);
    case
}

/// The lower node of a link name (`c1` -> 0, `c12` -> 1, `d23` -> 2).
fn link_node(name: &str) -> usize {
    let digits = &name[1..];
    if digits == "1" {
        0
    } else {
        digits[..digits.len() - 1].parse().unwrap()
    }
}

/// `model` with one more mass: the new mass is mass `p + 1` (masses above
/// `p` move up); `p = N` hangs it at the free end, `p = 0` on a free chain
/// puts it before the first mass, otherwise link `p` (0: the ground's) is
/// split into two springs in series with the old stiffness. The new mass
/// is `ratio` times the smallest; an added spring is tuned to `f_hz` with
/// the new mass alone. `None` if the placement does not exist.
fn with_extra_mass(
    model: &mms::Model,
    p: &Parameters,
    pos: usize,
    ratio: f64,
    f_hz: f64,
    zeta: f64,
) -> Option<(mms::Model, Vec<f64>)> {
    let n = model.n_masses();
    let split = pos < n && model.has_link(pos);
    if pos < n && !split && !(pos == 0 && model.gap() == 0) {
        return None;
    }
    let up = |i: usize| if i > pos { i + 1 } else { i };
    let port = |q: mms::Port| mms::Port::new(up(q.plus), up(q.minus));
    let gap = if model.gap() > pos {
        model.gap() + 1
    } else {
        model.gap()
    };
    let ext = mms::Model::new(n + 1, gap, port(model.actuator()), port(model.sensor())).ok()?;
    let smallest = p.values()[..n]
        .iter()
        .cloned()
        .fold(f64::INFINITY, f64::min);
    let m_new = ratio * smallest;
    let w = 2.0 * std::f64::consts::PI * f_hz;
    let mut values: BTreeMap<String, f64> = BTreeMap::new();
    let mut added = 0.0;
    for (name, v) in p.iter() {
        if let Some(index) = name.strip_prefix('m') {
            let i: usize = index.parse().unwrap();
            values.insert(mms::mass_name(up(i)), v);
            continue;
        }
        let link = |i: usize| {
            if name.starts_with('c') {
                mms::spring_name(i)
            } else {
                mms::damper_name(i)
            }
        };
        let i = link_node(name);
        if split && i == pos {
            // Two springs in series, c_a + c_b = m_new w^2 (at least 4 c
            // for a real split) and c_a c_b / (c_a + c_b) = c.
            if name.starts_with('c') {
                let sum = (m_new * w * w).max(4.5 * v);
                let disc = (sum * sum - 4.0 * v * sum).sqrt();
                values.insert(link(pos), 0.5 * (sum + disc));
                values.insert(link(pos + 1), 0.5 * (sum - disc));
                added = sum;
            } else {
                values.insert(link(pos), 2.0 * v);
                values.insert(link(pos + 1), 2.0 * v);
            }
        } else {
            values.insert(link(up(i)), v);
        }
    }
    let mut m_ext = m_new;
    if !split {
        added = m_new * w * w;
    } else {
        m_ext = added / (w * w);
        m_ext = m_ext.max(m_new);
    }
    let out: Vec<f64> = ext
        .parameters()
        .iter()
        .map(|name| match values.get(name) {
            Some(&v) => v,
            None if name.starts_with('m') => m_ext,
            None if name.starts_with('c') => added,
            None => 2.0 * zeta * (added * m_ext).sqrt(),
        })
        .collect();
    Some((ext, out))
}

/// Undamped resonances (Hz) of `model` at `values`.
fn resonances_hz(model: &mms::Model, values: &[f64]) -> Vec<f64> {
    // From the denominator alone: a numerator with zeros off the positive
    // axis (a non-minimum-phase extension) still has real resonances.
    let nu = model.undamped_parameters().len();
    let (_, den) = ident::start::UndampedCoefficients::new(model).eval(&values[..nu]);
    let mut r: Vec<f64> = ident::start::roots(&den)
        .iter()
        .filter(|z| z.im.abs() <= 1e-9 * z.norm() && z.re > 0.0)
        .map(|z| z.re.sqrt() / (2.0 * std::f64::consts::PI))
        .collect();
    r.sort_by(f64::total_cmp);
    r
}

/// The resonance of `ext` farthest (in log frequency) from every resonance
/// of `model`: the one the extra mass adds.
fn added_resonance(model: &mms::Model, p: &[f64], ext: &mms::Model, q: &[f64]) -> Option<f64> {
    let old = resonances_hz(model, p);
    resonances_hz(ext, q)
        .into_iter()
        .map(|f| {
            let d = old
                .iter()
                .map(|g| (f / g).ln().abs())
                .fold(f64::INFINITY, f64::min);
            (d, f)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|x| x.1)
}

/// A recording with every effect of `kinds` concealed (random sizes).
fn draw_many(seed: u64, kinds: &[EffectKind]) -> Case {
    let mut rng = XorShift::new(seed);
    let lines = 400 + (rng.next_u64() % 401) as usize;
    let log_grid = rng.uniform() < 0.8;
    let options = SynthOptions {
        lines,
        log_grid,
        ..SynthOptions::default()
    };
    let s = loop {
        let s = synthetic(&mut rng, None, &options).expect("synthetic draw");
        // Friction grounds the driven mass; where a damper already joins
        // it to the ground, friction is only a larger damper (a parameter
        // error), so those structures do not carry a friction case.
        let driven_grounded = s.model.actuator().plus == 1 && s.model.gap() != 0;
        // A pre-sliding stiffness needs a driven mass that moves as a rigid
        // body (on the free side of the gap) to turn into a resonance.
        let rigid = s.model.actuator().plus > s.model.gap();
        if !(kinds.contains(&EffectKind::ViscousFriction) && driven_grounded)
            && (rigid || !kinds.contains(&EffectKind::PreSlidingFriction))
        {
            break s;
        }
    };
    let freq = s.frf.freq_hz().to_vec();
    let f_lo = freq[0];
    let f_hi = *freq.last().unwrap();
    let highest = s.features.last().expect("features").1;
    let total_mass: f64 = s.parameters.values()[..3].iter().sum();
    let mut effects = Effects::default();
    let mut truth = Vec::new();
    let mut structure = (s.model, s.parameters.values().to_vec());
    for &kind in kinds {
        let value = match kind {
            EffectKind::TimeDelay => {
                let t = rng.log_uniform(5e-5, 1e-3);
                effects.time_delay_s = Some(t);
                t
            }
            EffectKind::Lowpass => {
                let fc = highest * rng.log_uniform(1.5, 10.0);
                effects.lowpass_hz = Some(fc);
                fc
            }
            EffectKind::HystereticDamping => {
                let eta = rng.log_uniform(0.005, 0.05);
                effects.loss_factor = Some(eta);
                eta
            }
            EffectKind::ViscousFriction => {
                // A rigid-body corner b / (2 pi M) between 0.1 and 1 times
                // the lowest line.
                let b = 2.0 * std::f64::consts::PI * f_lo * total_mass * rng.log_uniform(0.1, 1.0);
                effects.viscous_friction = Some(b);
                b
            }
            EffectKind::PreSlidingFriction => {
                // The total mass on the spring resonates between 1.5 and 4
                // times the lowest line, damped by a little viscous
                // friction as friction at rest is (a damping ratio of
                // 0.05; an undamped line would be a singular reading).
                let w = 2.0 * std::f64::consts::PI * f_lo * rng.log_uniform(1.5, 4.0);
                let k = total_mass * w * w;
                effects.pre_sliding_stiffness = Some(k);
                effects.viscous_friction = Some(0.1 * total_mass * w);
                k
            }
            EffectKind::GainError => {
                // Factors within the calibration tolerance (a factor 1.5
                // by default) are a common scale of all parameters, which
                // the calibration absorbs by design; the cases are drawn
                // outside [0.55, 1.8].
                let g = if rng.uniform() < 0.5 {
                    rng.log_uniform(0.3, 0.55)
                } else {
                    rng.log_uniform(1.8, 3.3)
                };
                effects.gain_factor = Some(g);
                g
            }
            EffectKind::ExtraMode => {
                // A mass of 0.1-0.5 times the smallest at a random
                // placement, its added resonance well inside the band.
                let mut last = None;
                let mut attempts = 0;
                loop {
                    attempts += 1;
                    if attempts > 200 {
                        // No in-band placement: keep the last valid one.
                        let (ext, q, r) = last.expect("a valid extra-mass placement");
                        structure = (ext, q);
                        break r;
                    }
                    let pos = (rng.next_u64() % 4) as usize;
                    let ratio = rng.log_uniform(0.1, 0.5);
                    let f_new = rng.log_uniform(1.5 * f_lo, f_hi / 1.5);
                    let zeta = rng.log_uniform(0.005, 0.03);
                    let Some((ext, q)) =
                        with_extra_mass(&s.model, &s.parameters, pos, ratio, f_new, zeta)
                    else {
                        continue;
                    };
                    let Some(r) = added_resonance(&s.model, s.parameters.values(), &ext, &q) else {
                        continue;
                    };
                    if r > 1.3 * f_lo && r < f_hi / 1.3 {
                        structure = (ext, q);
                        break r;
                    }
                    last = Some((ext, q, r));
                }
            }
            // Backlash and offset are time-domain only (tests/nonlinear.rs,
            // tests/closed_loop.rs).
            EffectKind::CoulombFriction
            | EffectKind::Backlash
            | EffectKind::Offset
            | EffectKind::None => continue,
        };
        truth.push((kind, value));
    }
    let noise = rng.log_uniform(0.005, 0.02);
    let mut h = ChainResponse::with_effects(&structure.0, s.output, &effects)
        .eval_many(&structure.1, &freq)
        .expect("response");
    for z in &mut h {
        let e = Complex64::new(rng.normal(), rng.normal()) * (noise / 2f64.sqrt());
        *z *= Complex64::new(1.0, 0.0) + e;
    }
    let perturbed: Vec<f64> = s
        .parameters
        .values()
        .iter()
        .map(|p| p * (1.0 + 0.15 * (2.0 * rng.uniform() - 1.0)))
        .collect();
    Case {
        data: Frf::new(freq, h, None).expect("frf"),
        nominal: ModelFile {
            model: s.model,
            output: s.output,
            parameters: Parameters::from_values(&s.model, perturbed).expect("parameters"),
            gain: 1.0,
            motion: Motion::Translational,
            effects: Effects::default(),
        },
        kind: kinds.first().copied().unwrap_or(EffectKind::None),
        value: None,
        truth,
    }
}

/// The reported value of a kind's parameter (the added resonance for
/// `extra_mode`).
fn reported(v: &ident::diagnose::EffectVerdict) -> Option<f64> {
    match v.kind.parameter_name() {
        Some(name) => v.parameters.get(name).copied(),
        None => v.parameters.get("resonance_hz").copied(),
    }
}

const KINDS: [EffectKind; 8] = [
    EffectKind::None,
    EffectKind::TimeDelay,
    EffectKind::Lowpass,
    EffectKind::GainError,
    EffectKind::HystereticDamping,
    EffectKind::ViscousFriction,
    EffectKind::ExtraMode,
    EffectKind::PreSlidingFriction,
];

#[test]
fn concealed_effects_are_found() {
    let cases_per_kind = 10;
    let options = DiagnoseOptions::default();
    let mut table: BTreeMap<&str, (usize, usize, Vec<f64>)> = BTreeMap::new();
    let start = Instant::now();
    let mut runs = 0;
    let mut spurious = 0;
    for (k, &kind) in KINDS.iter().enumerate() {
        for i in 0..cases_per_kind {
            let case = draw(1000 * (k as u64 + 1) + i as u64, kind);
            let d = diagnose(&case.data, &case.nominal, &options).expect("diagnosis");
            runs += 1;
            let top = &d.effects[0];
            let entry = table.entry(kind.as_str()).or_default();
            entry.1 += 1;
            if d.effects.len() > 1 {
                spurious += 1;
                eprintln!(
                    "second effect: {} seed {} -> {:?}",
                    kind.as_str(),
                    1000 * (k + 1) + i,
                    d.effects
                        .iter()
                        .map(|e| (e.kind.as_str(), e.score))
                        .collect::<Vec<_>>()
                );
            }
            if top.kind == case.kind {
                entry.0 += 1;
                if let (Some(v), Some(got)) = (case.value, reported(top)) {
                    entry.2.push((got / v - 1.0).abs());
                }
            } else {
                eprintln!(
                    "miss: {} seed {} -> {} ({:?}) value {:?}",
                    kind.as_str(),
                    1000 * (k + 1) + i,
                    top.kind.as_str(),
                    top.evidence,
                    case.value
                );
            }
            assert!(
                d.after.rms_db <= d.before.rms_db + 1e-9 || d.effects[0].kind == EffectKind::None
            );
        }
    }
    let per = start.elapsed().as_secs_f64() / runs as f64;
    println!("| concealed effect | top-1 correct | median parameter error |");
    println!("|---|---|---|");
    for kind in KINDS {
        let (ok, n, errs) = &table[kind.as_str()];
        let mut errs = errs.clone();
        errs.sort_by(f64::total_cmp);
        let median = errs
            .get(errs.len() / 2)
            .map_or("-".to_string(), |e| format!("{:.1} %", 100.0 * e));
        println!("| {} | {ok}/{n} | {median} |", kind.as_str());
    }
    println!(
        "mean time per diagnosis: {:.1} ms (test profile)",
        per * 1e3
    );
    println!("cases with a second effect: {spurious}/{runs}");
    for kind in KINDS {
        let (ok, n, _) = &table[kind.as_str()];
        assert!(*ok * 10 >= *n * 8, "{}: {ok}/{n} correct", kind.as_str());
    }
    // A single concealed effect rarely gains a spurious second one.
    assert!(
        spurious * 100 <= runs * 15,
        "{spurious}/{runs} with a second effect"
    );
}

#[test]
fn json_has_the_issue_schema() {
    let case = draw(7, EffectKind::TimeDelay);
    let d = diagnose(&case.data, &case.nominal, &DiagnoseOptions::default()).unwrap();
    let v = serde_json::to_value(&d).unwrap();
    for key in ["mismatch", "effects", "fit", "model_after"] {
        assert!(v.get(key).is_some(), "{key} missing");
    }
    assert_eq!(v["effects"][0]["kind"], "time_delay");
    assert!(v["effects"][0]["parameters"]["delay_s"].is_number());
    assert!(v["fit"]["before"]["rms_db"].is_number());
    assert!(v["fit"]["after"]["rms_deg"].is_number());
    assert!(v["model_after"]["effects"]["time_delay"]["delay_s"].is_number());
    // A missing delay shows as a phase error: at least one band.
    assert!(!d.mismatch.is_empty());
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let case = draw(3, EffectKind::None);
    let mut h = case.data.response().to_vec();
    h[5] = Complex64::new(0.0, 0.0);
    let zero = Frf::new(case.data.freq_hz().to_vec(), h, None).unwrap();
    assert!(diagnose(&zero, &case.nominal, &DiagnoseOptions::default()).is_err());
    let bad = DiagnoseOptions {
        tolerance: -1.0,
        ..DiagnoseOptions::default()
    };
    assert!(diagnose(&case.data, &case.nominal, &bad).is_err());
    let short = case
        .data
        .band(case.data.freq_hz()[0], case.data.freq_hz()[3])
        .unwrap();
    assert!(diagnose(&short, &case.nominal, &DiagnoseOptions::default()).is_err());
}

#[test]
fn deterministic() {
    let case = draw(11, EffectKind::Lowpass);
    let o = DiagnoseOptions::default();
    let a = serde_json::to_string(&diagnose(&case.data, &case.nominal, &o).unwrap()).unwrap();
    let b = serde_json::to_string(&diagnose(&case.data, &case.nominal, &o).unwrap()).unwrap();
    assert_eq!(a, b);
}

/// Issue 6's benchmark: a 3-mass model on a 2000-line FRF in under 1 s.
/// Run in release: `cargo test --release -p ident --test diagnose --
/// --ignored --nocapture`.
#[test]
#[ignore = "timing; meaningful in release only"]
fn benchmark_2000_lines() {
    let mut rng = XorShift::new(42);
    let s = synthetic(&mut rng, None, &SynthOptions::default()).unwrap();
    let effects = Effects {
        time_delay_s: Some(2e-4),
        ..Effects::default()
    };
    let h = ChainResponse::with_effects(&s.model, s.output, &effects)
        .eval_many(s.parameters.values(), s.frf.freq_hz())
        .unwrap();
    let data = Frf::new(s.frf.freq_hz().to_vec(), h, None).unwrap();
    let nominal = ModelFile {
        model: s.model,
        output: s.output,
        parameters: Parameters::from_values(
            &s.model,
            s.parameters.values().iter().map(|p| p * 1.1).collect(),
        )
        .unwrap(),
        gain: 1.0,
        motion: Motion::Translational,
        effects: Effects::default(),
    };
    assert_eq!(data.len(), 2000);
    let start = Instant::now();
    let d = diagnose(&data, &nominal, &DiagnoseOptions::default()).unwrap();
    let t = start.elapsed().as_secs_f64();
    println!("2000-line 3-mass diagnosis: {:.0} ms", t * 1e3);
    assert_eq!(d.effects[0].kind, EffectKind::TimeDelay);
    assert!(t < 1.0, "{t} s");
}

/// A concealed extra mode: the recording comes from A1 with one more
/// light mass on a spring next to the driven and measured mass (as a
/// motor-side mode would be); the diagnosis gets A1 with parameters 10 %
/// off, must name `extra_mode`, place its resonance, and return a 4-mass
/// model that fits.
#[test]
fn concealed_extra_mode_is_found() {
    use mms::model_file::{ModelFile, Motion};
    use mms::response::{ChainResponse, Effects, Parameters};
    use mms::Model;
    let a1 = Model::from_id("A1").unwrap();
    let four = Model::from_id("N4-g0-a2.0-s2.0").unwrap();
    // A1 of Tab. 7 as masses 2..4, plus m1 = 2 g on c12 = 400 N/m (a local
    // mode near 71 Hz, above A1's features).
    let truth = [
        0.002, 0.0044, 0.0173, 0.0184, 400.0, 46.8, 14.3, 0.002, 0.002, 0.001,
    ];
    let f: Vec<f64> = (0..1200)
        .map(|k| 2.0 * (100.0f64).powf(k as f64 / 1199.0))
        .collect();
    let mut rng = mms::xorshift::XorShift::new(5);
    let g = ChainResponse::new(&four, mms::Output::Position);
    let h: Vec<num_complex::Complex64> = f
        .iter()
        .map(|&x| {
            let n = num_complex::Complex64::new(rng.normal(), rng.normal()) * 0.005;
            g.eval(&truth, x).unwrap() * (1.0 + n)
        })
        .collect();
    let data = frf::Frf::new(f, h, None).unwrap();
    let nominal = [
        0.0044 * 1.1,
        0.0173 * 0.9,
        0.0184 * 1.1,
        46.8 * 0.9,
        14.3 * 1.1,
        0.002,
        0.001,
    ];
    let file = ModelFile {
        model: a1,
        output: mms::Output::Position,
        parameters: Parameters::from_values(&a1, nominal.to_vec()).unwrap(),
        gain: 1.0,
        motion: Motion::Translational,
        effects: Effects::default(),
    };
    let d = ident::diagnose::diagnose(&data, &file, &Default::default()).unwrap();
    assert_eq!(
        d.effects[0].kind,
        ident::diagnose::EffectKind::ExtraMode,
        "{:?}",
        d.effects
    );
    assert_eq!(d.model_after.model.n_masses(), 4);
    // The added resonance: the 4-mass model's resonance that A1 lacks.
    let r = d.effects[0].parameters["resonance_hz"];
    let exact = ident::start::FeatureTarget::from_model(&four, &truth[..7]).unwrap();
    let nearest = exact
        .resonances
        .iter()
        .map(|w| w.sqrt() / (2.0 * std::f64::consts::PI))
        .map(|fr| (fr / r).ln().abs())
        .fold(f64::INFINITY, f64::min);
    assert!(nearest < 0.05, "{r} Hz vs {:?}", exact.resonances);
    assert!(d.fit.after.rms_db < 0.1, "{:?}", d.fit);
}

/// Held-out validation (every 4th line left out of the fits) against BIC
/// on the same concealed-effect cases: the same top-1 kind in most cases,
/// and `none` on every case without an effect.
#[test]
fn holdout_selection_agrees_with_bic() {
    let holdout = DiagnoseOptions {
        selection: ident::diagnose::Selection::Holdout,
        ..DiagnoseOptions::default()
    };
    let (mut same, mut correct, mut runs) = (0, 0, 0);
    for (k, &kind) in KINDS.iter().enumerate() {
        for i in 0..4 {
            let seed = 1000 * (k as u64 + 1) + i;
            let case = draw(seed, kind);
            let bic = diagnose(&case.data, &case.nominal, &DiagnoseOptions::default()).unwrap();
            let held = diagnose(&case.data, &case.nominal, &holdout).unwrap();
            runs += 1;
            same += usize::from(bic.effects[0].kind == held.effects[0].kind);
            correct += usize::from(held.effects[0].kind == kind);
            if kind == EffectKind::None {
                assert_eq!(held.effects[0].kind, EffectKind::None, "seed {seed}");
            }
            if held.effects[0].kind != kind {
                eprintln!(
                    "holdout miss: {} seed {seed} -> {} ({:?})",
                    kind.as_str(),
                    held.effects[0].kind.as_str(),
                    held.effects[0].evidence
                );
            }
        }
    }
    println!("holdout: same top-1 as BIC {same}/{runs}, correct {correct}/{runs}");
    assert!(same * 10 >= runs * 8, "same as BIC {same}/{runs}");
    assert!(correct * 10 >= runs * 8, "correct {correct}/{runs}");
}

/// Two concealed effects at once, from pairs that do not look alike: both
/// must be among the kept effects (forward selection), with their
/// parameters close to the truth.
#[test]
fn concealed_pairs_are_found() {
    let pairs = [
        (EffectKind::TimeDelay, EffectKind::HystereticDamping),
        (EffectKind::GainError, EffectKind::ExtraMode),
        (EffectKind::TimeDelay, EffectKind::ExtraMode),
    ];
    let options = DiagnoseOptions::default();
    let (mut both, mut runs) = (0, 0);
    let mut errors: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    for (k, &(a, b)) in pairs.iter().enumerate() {
        for i in 0..2 {
            let seed = 60_000 + 100 * k as u64 + i;
            let case = draw_many(seed, &[a, b]);
            let t = Instant::now();
            let d = diagnose(&case.data, &case.nominal, &options).unwrap();
            eprintln!("pair seed {seed}: {:.1} s", t.elapsed().as_secs_f64());
            runs += 1;
            let found: Vec<EffectKind> = d.effects.iter().map(|e| e.kind).collect();
            if found.contains(&a) && found.contains(&b) {
                both += 1;
                for (kind, value) in &case.truth {
                    let v = d.effects.iter().find(|e| e.kind == *kind).unwrap();
                    let got = reported(v).unwrap();
                    errors
                        .entry(kind.as_str())
                        .or_default()
                        .push((got / value - 1.0).abs());
                }
            } else {
                eprintln!(
                    "pair miss: {} + {} seed {seed} -> {:?} ({:?})",
                    a.as_str(),
                    b.as_str(),
                    found,
                    d.rejected
                        .iter()
                        .map(|e| (e.kind, e.score, &e.unresolved, &e.parameters))
                        .collect::<Vec<_>>()
                );
            }
        }
    }
    println!("pairs: both found {both}/{runs}");
    for (kind, e) in &mut errors {
        e.sort_by(f64::total_cmp);
        println!(
            "{kind}: median error {:.1} %, max {:.1} %",
            100.0 * e[e.len() / 2],
            100.0 * e[e.len() - 1]
        );
    }
    // Half at least: with one effect missing, the other's fit can run
    // to a bound or inside its uncertainty (an extra mass damped to take
    // up a missing dead time's phase), and a named effect must stand out
    // of both in the joint fit. The concealed-effect benchmark's pairs
    // (`mms benchmark`, docs/diagnosis.md) measure this at scale.
    assert!(both * 2 >= runs, "both found {both}/{runs}");
    // A gain is known only up to the common scale of the chain's
    // parameters, which the calibration may move within its tolerance (a
    // factor 1.5): beside an extra mass, that trade-off can take a third.
    let limit = |kind: &str| match kind {
        "gain_error" => 0.35,
        "hysteretic_damping" => 0.3,
        _ => 0.05,
    };
    for (kind, e) in &errors {
        assert!(e[e.len() / 2] < limit(kind), "{kind}: {e:?}");
    }
}

/// A hidden mass in the middle of the chain (between masses 1 and 2 of the
/// Tab. 7 A1, splitting their spring): the diagnosis must insert it there
/// and place its resonance within 5 %.
#[test]
fn hidden_middle_mass_is_found() {
    let a1 = mms::Model::from_id("A1").unwrap();
    let truth = [0.0044, 0.0173, 0.0184, 46.8, 14.3, 0.002, 0.001];
    let p = Parameters::from_values(&a1, truth.to_vec()).unwrap();
    let (ext, q) = with_extra_mass(&a1, &p, 1, 0.5, 25.0, 0.01).unwrap();
    let exact = added_resonance(&a1, &truth, &ext, &q).unwrap();
    let f: Vec<f64> = (0..1200)
        .map(|k| 2.0 * (50.0f64).powf(k as f64 / 1199.0))
        .collect();
    let mut rng = XorShift::new(8);
    let g = ChainResponse::new(&ext, mms::Output::Position);
    let h: Vec<Complex64> = f
        .iter()
        .map(|&x| {
            g.eval(&q, x).unwrap() * (1.0 + Complex64::new(rng.normal(), rng.normal()) * 0.005)
        })
        .collect();
    let data = Frf::new(f, h, None).unwrap();
    let nominal: Vec<f64> = truth
        .iter()
        .enumerate()
        .map(|(i, v)| v * if i % 2 == 0 { 1.08 } else { 0.93 })
        .collect();
    let file = ModelFile {
        model: a1,
        output: mms::Output::Position,
        parameters: Parameters::from_values(&a1, nominal).unwrap(),
        gain: 1.0,
        motion: Motion::Translational,
        effects: Effects::default(),
    };
    let d = diagnose(&data, &file, &DiagnoseOptions::default()).unwrap();
    assert_eq!(d.effects[0].kind, EffectKind::ExtraMode, "{:?}", d.effects);
    let r = d.effects[0].parameters["resonance_hz"];
    println!(
        "middle mass: {} ({}), resonance {r:.2} Hz vs {exact:.2} Hz",
        d.model_after.model.id(),
        ext.id()
    );
    assert!((r / exact - 1.0).abs() < 0.05, "{r} vs {exact}");
    assert_eq!(d.model_after.model, ext, "placement");
    assert!(d.fit.after.rms_db < 0.1, "{:?}", d.fit);
}

/// The extra_mode row of the concealed-effect table on its own, with the
/// added resonance's accuracy and the time per diagnosis (release: `cargo
/// test --release -p ident --test diagnose -- --ignored extra_mode_row
/// --nocapture`).
#[test]
#[ignore = "figures for docs/diagnosis.md; run in release"]
fn extra_mode_row() {
    let options = DiagnoseOptions::default();
    let (mut by_kind, mut placed) = (0, 0);
    let mut errs = Vec::new();
    let start = Instant::now();
    for i in 0..10u64 {
        let seed = 7000 + i;
        let case = draw(seed, EffectKind::ExtraMode);
        let d = diagnose(&case.data, &case.nominal, &options).unwrap();
        let top = &d.effects[0];
        let got = reported(top);
        if top.kind == EffectKind::ExtraMode {
            by_kind += 1;
            let e = (got.unwrap() / case.value.unwrap() - 1.0).abs();
            errs.push(e);
            placed += usize::from(e < 0.25);
        }
        println!(
            "seed {seed}: {} {:?} (truth {:?})",
            top.kind.as_str(),
            got,
            case.value
        );
    }
    errs.sort_by(f64::total_cmp);
    println!(
        "extra_mode: by kind {by_kind}/10, resonance within 25 % {placed}/10, median error {:.1} %, {:.0} ms per diagnosis",
        100.0 * errs.get(errs.len() / 2).copied().unwrap_or(f64::NAN),
        start.elapsed().as_secs_f64() * 100.0
    );
}
