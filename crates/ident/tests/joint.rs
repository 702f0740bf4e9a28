//! Identification from several sensors: synthetic chains read by two
//! sensors, identified jointly.

use frf::Frf;
use ident::fit::Gain;
use ident::identify::IdentifyOptions;
use ident::joint::{identify_sensors, RuledOutBy, SensorOutput};
use ident::synth::{synthetic, SynthOptions};
use mms::response::{ChainResponse, Parameters};
use mms::xorshift::XorShift;
use mms::{Model, Output, Port};
use num_complex::Complex64;

/// The FRFs of `model`'s chain read at its own sensor and at `second`,
/// with `noise` relative complex noise per line (a draw of the parameters
/// from `rng`), the second sensor's structure and the true parameters.
pub fn two_sensor_recording(
    rng: &mut XorShift,
    model: Model,
    second: Port,
    noise: f64,
) -> (Frf, Frf, Model, Parameters) {
    let s = synthetic(
        rng,
        Some(model),
        &SynthOptions {
            lines: 800,
            ..SynthOptions::default()
        },
    )
    .unwrap();
    let other = Model::new(model.n_masses(), model.gap(), model.actuator(), second).unwrap();
    let f = s.frf.freq_hz().to_vec();
    let mut read = |m: &Model| {
        let mut h = ChainResponse::new(m, Output::Position)
            .eval_many(s.parameters.values(), &f)
            .unwrap();
        for z in &mut h {
            let e = Complex64::new(rng.normal(), rng.normal()) * (noise / 2f64.sqrt());
            *z *= Complex64::new(1.0, 0.0) + e;
        }
        Frf::new(f.clone(), h, None).unwrap()
    };
    let first = read(&model);
    let second_frf = read(&other);
    (first, second_frf, other, s.parameters)
}

/// The paper's A1 (Tab. 7 structure, collocated at mass 1) read also at
/// mass 3. With the motor-side sensor alone, A1 and A4 are one equivalence
/// class (Vajda: same form, independent invariants; `mms` proves it
/// independently here), so the first output alone fits both equally; the
/// load output's type rules A4 out, and the joint fit returns A1's
/// parameters, all five undamped ones determinable.
#[test]
fn a_load_encoder_separates_what_the_motor_encoder_cannot() {
    let a1 = Model::from_id("A1").unwrap();
    let a4 = Model::from_id("A4").unwrap();
    let groups = mms::structural_equivalences(&[a1, a4]);
    assert_eq!(groups.len(), 1, "A1 and A4 are one class with one sensor");
    let mut rng = XorShift::new(3);
    let (h1, h2, _, truth) = two_sensor_recording(&mut rng, a1, Port::new(3, 0), 0.01);
    let outputs = [
        SensorOutput {
            name: "motor".into(),
            frf: &h1,
            location: None,
        },
        SensorOutput {
            name: "load".into(),
            frf: &h2,
            location: Some("3".parse().unwrap()),
        },
    ];
    let id = identify_sensors(&outputs, Output::Position, &IdentifyOptions::default()).unwrap();
    let best = &id.candidates[0];
    assert_eq!(best.id, "A1+s3.0", "{:?}", id.indistinguishable);
    assert!(
        id.first_output_alone.iter().any(|c| c == "A4+s3.0"),
        "{:?}",
        id.first_output_alone
    );
    let a4_out = id
        .ruled_out
        .iter()
        .find(|r| r.id == "A4+s3.0")
        .expect("A4 ruled out");
    assert_eq!(a4_out.by, RuledOutBy::Type { output: 1 });
    // 1 % noise per line on 800 lines: the undamped parameters within 1 %.
    for (got, want) in best
        .fit
        .parameters
        .values()
        .iter()
        .zip(truth.values())
        .take(5)
    {
        assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
    }
    // Each output's error is the noise's: 1 % relative is 0.06 dB RMS.
    for (db, _) in &best.per_output {
        assert!(*db < 0.12, "{db}");
    }
}

/// A free two-mass drive driven at the motor, read at the motor and at
/// the load, with the gain fitted (units unknown): driven at the load
/// instead, the same sensors would read the antiresonance at the load and
/// the resonance alone at the motor. The joint fit picks the drive side
/// and no other structure fits both outputs as well.
#[test]
fn the_joint_fit_separates_the_drive_side() {
    let motor_driven = Model::new(2, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
    let mut rng = XorShift::new(11);
    let (h1, h2, _, _) = two_sensor_recording(&mut rng, motor_driven, Port::new(2, 0), 0.01);
    let outputs = [
        SensorOutput {
            name: "motor".into(),
            frf: &h1,
            location: Some("1".parse().unwrap()),
        },
        SensorOutput {
            name: "load".into(),
            frf: &h2,
            location: Some("N".parse().unwrap()),
        },
    ];
    let options = IdentifyOptions {
        gain: Gain::Fit(1.0),
        ..IdentifyOptions::default()
    };
    let id = identify_sensors(&outputs, Output::Position, &options).unwrap();
    assert_eq!(id.candidates[0].id, "N2-g0-a1.0-s1.0+s2.0");
    assert_eq!(
        id.indistinguishable[0].len(),
        1,
        "{:?}",
        id.indistinguishable
    );
    // The fitted gain scales the chain: ratios of the parameters are what
    // is identified, and the joint fit reproduces both outputs.
    assert!(id.candidates[0].fit.rms_db < 0.12);
}

#[test]
fn a_sensor_outside_the_chain_is_an_error() {
    let m = Model::new(2, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
    let mut rng = XorShift::new(2);
    let (h1, h2, _, _) = two_sensor_recording(&mut rng, m, Port::new(2, 0), 0.01);
    let outputs = [
        SensorOutput {
            name: "motor".into(),
            frf: &h1,
            location: None,
        },
        SensorOutput {
            name: "load".into(),
            frf: &h2,
            location: Some("5".parse().unwrap()),
        },
    ];
    let e = identify_sensors(&outputs, Output::Position, &IdentifyOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("load") && e.contains("outside"), "{e}");
    assert!(identify_sensors(&[], Output::Position, &IdentifyOptions::default()).is_err());
}
