//! Model files (TOML): every key, the round trip, and one-line errors that
//! name the line.

use mms::model_file::{ModelFile, Motion};
use mms::{Model, Output, Port};

const A2_TAB4: &str = r#"
# Tab. 4 of the paper
masses = 3
gap = 0
actuator = [1, 0]
sensor = [2, 0]
output = "position"

[parameters]
m1 = 0.01
m2 = 0.01
m3 = 0.02
c12 = 100
c23 = 1_00.0
d12 = 0.01
d23 = 1e-2
"#;

#[test]
fn reads_topology_keys_and_parameters() {
    let f = ModelFile::parse(A2_TAB4).unwrap();
    assert_eq!(
        f.model,
        Model::new(3, 0, Port::new(1, 0), Port::new(2, 0)).unwrap()
    );
    assert_eq!(f.model.paper_id(), Some("A2"));
    assert_eq!(f.output, Output::Position);
    assert_eq!(f.gain, 1.0);
    assert_eq!(f.motion, Motion::Translational);
    assert!(f.effects.is_empty());
    let want = [0.01, 0.01, 0.02, 100.0, 100.0, 0.01, 0.01];
    assert_eq!(f.parameters.values(), want);
}

#[test]
fn structure_key_generic_ids_effects_and_round_trip() {
    let text = r#"
structure = "N4-g1-a2.1-s4.1"
output = "acceleration"
gain = 2.5
motion = "rotary"
[parameters]
m1 = 1
m2 = 2
m3 = 3
m4 = 4
c1 = 10
c23 = 20
c34 = 30
d1 = 0
d23 = 0.1
d34 = 0.2
[effects]
time_delay = { delay_s = 2.5e-4 }
lowpass = { corner_hz = 800 }
gain_error = { factor = 0.9 }
hysteretic_damping = { loss_factor = 0.01 }
friction = { viscous_ns_per_m = 3, pre_sliding_n_per_m = 450 }
"#;
    let f = ModelFile::parse(text).unwrap();
    assert_eq!(f.model.id(), "N4-g1-a2.1-s4.1");
    assert_eq!(f.gain, 2.5);
    assert_eq!(f.motion, Motion::Rotary);
    assert_eq!(f.effects.time_delay_s, Some(2.5e-4));
    assert_eq!(f.effects.lowpass_hz, Some(800.0));
    assert_eq!(f.effects.gain_factor, Some(0.9));
    assert_eq!(f.effects.loss_factor, Some(0.01));
    assert_eq!(f.effects.viscous_friction, Some(3.0));
    assert_eq!(f.effects.pre_sliding_stiffness, Some(450.0));
    let written = f.to_toml();
    assert_eq!(ModelFile::parse(&written).unwrap(), f);
    // Deterministic: writing the re-read file gives the same bytes.
    assert_eq!(ModelFile::parse(&written).unwrap().to_toml(), written);
    assert!(
        written.contains("time_delay = { delay_s = 0.00025 }"),
        "{written}"
    );
}

#[test]
fn errors_name_the_line() {
    let cases: &[(&str, &str)] = &[
        ("structure = \"A2\"\noutput = \"position\"\nfoo = 1\n", "line 3: unknown key 'foo'"),
        (
            "structure = \"A9\"\n",
            "line 1: invalid model ID \"A9\": expected a paper ID A1..A5, B1, B2, C1..C4 or N{N}-g{gap}-a{act+}.{act-}-s{meas+}.{meas-}",
        ),
        ("structure = \"A2\"\n[parameters]\n", "missing key 'output'"),
        (
            "structure = \"A2\"\noutput = \"force\"\n[parameters]\n",
            "line 2: unknown output \"force\" (expected position, velocity or acceleration)",
        ),
        (
            "structure = \"A1\"\noutput = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nm3 = -1\n",
            "line 6: parameter 'm3': a mass must be positive, not -1",
        ),
        (
            "structure = \"A1\"\noutput = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nm3 = 5e-324\n",
            "line 6: parameter 'm3': 5e-324 is outside the range of a mass (1e-12 to 1e12)",
        ),
        (
            "structure = \"A1\"\noutput = \"position\"\ngain = 0\n[parameters]\n",
            "line 3: 'gain': a gain must not be zero",
        ),
        (
            "structure = \"A1\"\noutput = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nm3 = nan\n",
            "line 6: 'm3' must be finite",
        ),
        (
            "structure = \"A1\"\noutput = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nm3 = 1\nc12 = 1\nc23 = 1\nd12 = 0\n",
            "line 3: missing parameter 'd23'",
        ),
        (
            "structure = \"A1\"\noutput = \"position\"\n[parameters]\nc1 = 1\n",
            "line 4: unknown parameter 'c1' (model A1 has m1, m2, m3, c12, c23, d12, d23)",
        ),
        (
            "structure = \"A1\"\nmasses = 3\n",
            "line 1: 'structure' and 'masses' exclude each other",
        ),
        (
            "masses = 3\ngap = 1\nactuator = [1, 0]\nsensor = [2, 0]\n",
            "line 2: rule (1) violated: actuator point 1 must satisfy gap+1 = 2 <= n+ <= N = 3",
        ),
        ("masses = 3\ngap = 0\nactuator = [1]\n", "line 3: 'actuator' must be [plus, minus], e.g. [2, 0]"),
        ("masses = [\n", "line 1: invalid TOML"),
    ];
    for (text, want) in cases {
        let got = ModelFile::parse(text).unwrap_err().to_string();
        assert!(got.starts_with(want), "{text:?}\n got: {got}\nwant: {want}");
        assert!(!got.contains('\n'), "one line: {got:?}");
    }
}

#[test]
fn effect_errors() {
    let base = "structure = \"A1\"\noutput = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nm3 = 1\nc12 = 1\nc23 = 1\nd12 = 0\nd23 = 0\n[effects]\n";
    for (tail, want) in [
        (
            "stiction = { force = 1 }\n",
            "line 12: unknown effect 'stiction'",
        ),
        (
            "backlash = { gap = -1e-4 }\n",
            "line 12: 'gap': a backlash gap must be non-negative, not -0.0001",
        ),
        (
            "time_delay = { delay_s = 1e300 }\n",
            "line 12: 'delay_s': 1e300 is outside the range of a time delay (1e-12 to 1e3)",
        ),
        (
            "friction = { coulomb = 1 }\n",
            "line 12: unknown key 'coulomb' in effect 'friction' (expected viscous_ns_per_m or coulomb_n or pre_sliding_n_per_m)",
        ),
        (
            "friction = {}\n",
            "line 12: effect 'friction' needs 'viscous_ns_per_m' or 'coulomb_n'",
        ),
        (
            "friction = { coulomb_n = \"big\" }\n",
            "line 12: 'coulomb_n' must be a number",
        ),
        (
            "time_delay = { delay = 1 }\n",
            "line 12: unknown key 'delay' in effect 'time_delay' (expected delay_s)",
        ),
        (
            "lowpass = { corner_hz = 0 }\n",
            "line 12: 'corner_hz': a corner frequency must not be zero",
        ),
        ("lowpass = 5\n", "line 12: 'lowpass' must be a table"),
    ] {
        let got = ModelFile::parse(&format!("{base}{tail}"))
            .unwrap_err()
            .to_string();
        assert!(got.starts_with(want), "got: {got}\nwant: {want}");
    }
}

/// The time-domain effects (Coulomb friction beside viscous friction in
/// one `friction` table, backlash) read and write back to the same value.
#[test]
fn nonlinear_effects_round_trip() {
    let base = "structure = \"A2\"\noutput = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nm3 = 1\nc12 = 1\nc23 = 1\nd12 = 0\nd23 = 0\n[effects]\n";
    for (tail, coulomb, viscous, gap) in [
        ("friction = { coulomb_n = 2.5 }\n", Some(2.5), None, None),
        (
            "friction = { viscous_ns_per_m = 0.5, coulomb_n = 12 }\nbacklash = { gap = 1e-4 }\n",
            Some(12.0),
            Some(0.5),
            Some(1e-4),
        ),
        ("backlash = { gap = 0 }\n", None, None, Some(0.0)),
    ] {
        let f = ModelFile::parse(&format!("{base}{tail}")).unwrap();
        assert_eq!(f.effects.coulomb_friction, coulomb, "{tail}");
        assert_eq!(f.effects.viscous_friction, viscous, "{tail}");
        assert_eq!(f.effects.backlash_gap, gap, "{tail}");
        let written = f.to_toml();
        assert_eq!(ModelFile::parse(&written).unwrap(), f, "{written}");
        assert_eq!(ModelFile::parse(&written).unwrap().to_toml(), written);
    }
}

/// A force offset (`offset {force_n}`, either sign) reads and writes back;
/// a non-finite one is an error naming the line.
#[test]
fn offset_round_trip_and_errors() {
    let base = "structure = \"A2\"\noutput = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nm3 = 1\nc12 = 1\nc23 = 1\nd12 = 0\nd23 = 0\n[effects]\n";
    for (tail, want) in [
        ("offset = { force_n = -3.16 }\n", -3.16),
        (
            "friction = { coulomb_n = 20 }\noffset = { force_n = 0.5 }\n",
            0.5,
        ),
    ] {
        let f = ModelFile::parse(&format!("{base}{tail}")).unwrap();
        assert_eq!(f.effects.offset_force, Some(want), "{tail}");
        let written = f.to_toml();
        assert_eq!(ModelFile::parse(&written).unwrap(), f, "{written}");
    }
    for (tail, want) in [
        (
            "offset = { force_n = nan }\n",
            "line 12: 'force_n' must be finite",
        ),
        (
            "offset = { force = 1 }\n",
            "line 12: unknown key 'force' in effect 'offset' (expected force_n)",
        ),
    ] {
        let got = ModelFile::parse(&format!("{base}{tail}"))
            .unwrap_err()
            .to_string();
        assert!(got.starts_with(want), "got: {got}\nwant: {want}");
    }
}

/// The sensors of a recording with several outputs: read in order, written
/// back, and every wrong list refused with the line named.
#[test]
fn sensors_of_several_outputs() {
    // A2 (gap 0, actuator [1, 0]) read at masses 2, 3 and 1.
    let text = A2_TAB4.replace(
        "sensor = [2, 0]\n",
        "sensor = [2, 0]\nsensors = [[2, 0], [3, 0], [1, 0]]\n",
    );
    let (file, sensors) = ModelFile::parse_with_sensors(&text).unwrap();
    assert_eq!(
        sensors,
        vec![Port::new(2, 0), Port::new(3, 0), Port::new(1, 0)]
    );
    // One model: the sensors do not change the file's chain or parameters.
    assert_eq!(file, ModelFile::parse(A2_TAB4).unwrap());
    let again = ModelFile::parse_with_sensors(&file.to_toml_with_sensors(&sensors)).unwrap();
    assert_eq!(again, (file.clone(), sensors));
    // Without the key: none, and the same text as before.
    assert!(ModelFile::parse_with_sensors(A2_TAB4).unwrap().1.is_empty());
    assert_eq!(file.to_toml_with_sensors(&[]), file.to_toml());
    let err = |list: &str| {
        let t = A2_TAB4.replace(
            "sensor = [2, 0]\n",
            &format!("sensor = [2, 0]\nsensors = {list}\n"),
        );
        ModelFile::parse(&t).unwrap_err().to_string()
    };
    assert_eq!(
        err("[[3, 0], [2, 0]]"),
        "line 7: 'sensors' must start with the model's sensor [2, 0]"
    );
    assert!(
        err("[2, 0]").starts_with("line 7: 'sensors' must be [plus, minus]"),
        "{}",
        err("[2, 0]")
    );
    // Past the last mass, or a reference beyond the gap (rule (1)).
    assert!(err("[[2, 0], [3, 1]]").starts_with("line 7: 'sensors': no sensor at [3, 1]"));
    assert!(
        err("[[2, 0], [4, 0]]").starts_with("line 7: 'sensors': no sensor at [4, 0]"),
        "{}",
        err("[[2, 0], [4, 0]]")
    );
    assert!(
        err("3").starts_with("line 7: 'sensors' must be a list"),
        "{}",
        err("3")
    );
}
