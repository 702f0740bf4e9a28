//! End-to-end tests of `mms frf` and `mms identify` on recordings made by
//! the project's own simulator (known truth) and on the real recordings in
//! ../shared/data/real, and their behaviour on bad input.

use ident::synth::{synthetic, SynthOptions};
use mms::xorshift::XorShift;
use mms::Model;
use std::path::{Path, PathBuf};
mod common;
use common::{mms, real_data};

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("identify", name)
}

/// A noise-free recording of `id` as FRF CSV, with 1 % noise if asked.
fn recording(dir: &Path, id: &str, noise: f64, seed: u64) -> (PathBuf, ident::synth::Synthetic) {
    let model = Model::from_id(id).unwrap();
    let s = synthetic(
        &mut XorShift::new(seed),
        Some(model),
        &SynthOptions {
            lines: 1200,
            noise,
            ..SynthOptions::default()
        },
    )
    .unwrap();
    let path = dir.join(format!("{id}.csv"));
    std::fs::write(&path, frf::write_csv(&s.frf, frf::CsvLayout::ReIm)).unwrap();
    (path, s)
}

#[test]
fn identify_json_names_the_generating_structure_among_the_best() {
    let dir = temp_dir("json");
    for (id, seed) in [("A1", 3), ("B2", 4), ("C1", 5)] {
        let (path, s) = recording(&dir, id, 0.0, seed);
        let (code, out, err) = mms(&["identify", path.to_str().unwrap(), "--format", "json"]);
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        // The schema of the issue.
        assert_eq!(v["classification"]["type"], s.frf_type.to_string());
        let band = v["classification"]["band_hz"].as_array().unwrap();
        assert!(band[0].as_f64().unwrap() < band[1].as_f64().unwrap());
        let features = v["classification"]["features"].as_array().unwrap();
        let found: Vec<f64> = features
            .iter()
            .filter(|f| f["in_type"] == true)
            .map(|f| f["freq_hz"].as_f64().unwrap())
            .collect();
        assert_eq!(found.len(), s.features.len());
        for (got, (_, want)) in found.iter().zip(&s.features) {
            assert!((got / want - 1.0).abs() < 0.02, "{id}: {got} vs {want}");
        }
        let cands = v["candidates"].as_array().unwrap();
        assert!(cands
            .iter()
            .all(|c| c["fit"]["rms_db"].is_number() && c["rank"].is_number()));
        // The generating structure is in the first indistinguishable group
        // and fits within 0.05 dB.
        let group = v["indistinguishable"][0].as_array().unwrap();
        assert!(group.iter().any(|g| g == id), "{id} not in {group:?}");
        let me = cands.iter().find(|c| c["id"] == id).unwrap();
        assert!(me["fit"]["rms_db"].as_f64().unwrap() < 0.05, "{me}");
        assert_eq!(me["masses"], 3);
        // Every notes array has its notes as data beside it, one object per
        // sentence, tagged by its kind.
        let holders = [&v, &v["classification"]].into_iter().chain(cands);
        for h in holders {
            let (notes, data) = (h["notes"].as_array(), h["note_data"].as_array());
            let (notes, data) = (notes.unwrap(), data.unwrap());
            assert_eq!(notes.len(), data.len(), "{h}");
            assert!(data.iter().all(|d| d["kind"].is_string()), "{h}");
        }
        let scale = v["note_data"]
            .as_array()
            .unwrap()
            .iter()
            .position(|d| d == &serde_json::json!({"kind": "gain_known", "gain": 1.0}))
            .unwrap_or_else(|| panic!("{}", v["note_data"]));
        assert_eq!(
            v["notes"][scale],
            "scale: the actuator/sensor gain is taken as known (1); parameters are absolute"
        );
    }
}

#[test]
fn identify_out_dir_writes_report_plots_and_model_file() {
    let dir = temp_dir("out");
    let (path, s) = recording(&dir, "A1", 0.01, 9);
    let out = dir.join("report");
    let (code, stdout, err) = mms(&[
        "identify",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.is_empty());
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("![Bode plot: measured and fitted](bode.svg)"));
    assert!(md.contains(&format!("**FRF type {}**", s.frf_type)));
    let svg = std::fs::read_to_string(out.join("bode.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    let png = std::fs::read(out.join("bode.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // The best model, ready for `mms diagnose`: it reads back, and its FRF
    // matches the recording to within the noise.
    let toml = std::fs::read_to_string(out.join("model.toml")).unwrap();
    let file = mms::model_file::ModelFile::parse(&toml).unwrap();
    let g = mms::response::ChainResponse::new(&file.model, file.output);
    let mut sq = 0.0;
    for (&f, &h) in s.frf.freq_hz().iter().zip(s.frf.response()) {
        let e = (g.eval(file.parameters.values(), f).unwrap() * file.gain / h)
            .norm()
            .log10()
            * 20.0;
        sq += e * e;
    }
    let rms = (sq / s.frf.len() as f64).sqrt();
    // 1 % complex noise is about 0.06 dB RMS in magnitude.
    assert!(rms < 0.2, "{rms}");
    // No temporary files left behind.
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
    // HTML: one self-contained page with the SVG inline.
    let (code, html, _) = mms(&["identify", path.to_str().unwrap(), "--format", "html"]);
    assert_eq!(code, 0);
    assert!(html.starts_with("<!DOCTYPE html>") && html.contains("<svg"));
}

#[test]
fn frf_estimates_from_time_domain_and_converts_formats() {
    let dir = temp_dir("frf");
    let (path, s) = recording(&dir, "A2", 0.0, 1);
    // CSV -> UFF58 -> CSV keeps the FRF (UFF stores 13 significant digits
    // for values, 7 for frequencies).
    let uff = dir.join("a2.uff");
    let (code, _, err) = mms(&[
        "frf",
        path.to_str().unwrap(),
        "--format",
        "uff",
        "--out",
        uff.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, csv, err) = mms(&["frf", uff.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let back = frf::parse_frf_csv(&csv).unwrap();
    assert_eq!(back.len(), s.frf.len());
    for (a, b) in back.response().iter().zip(s.frf.response()) {
        assert!((a - b).norm() <= 1e-9 * b.norm());
    }
    // A real time-domain recording: H1 with coherence.
    let mat = real_data("sperte/setup18_motor_side_v0.3.mat");
    let (code, csv, err) = mms(&["frf", &mat, "--fs", "4000"]);
    assert_eq!(code, 0, "{err}");
    assert!(csv
        .lines()
        .any(|l| l.starts_with("freq_hz,re,im,coherence")));
}

#[test]
fn identify_runs_on_the_real_recordings() {
    // Each recording with the flags its README describes; the run must
    // succeed and name a type, a band inside the measured range and ranked
    // candidates.
    let cases: &[&[&str]] = &[
        &[
            "sperte/setup18_motor_side_v0.3.mat",
            "--fs",
            "4000",
            "--fit-gain",
        ],
        &[
            "sperte/setup29_load_side_v0.5.mat",
            "--fs",
            "4000",
            "--fit-gain",
        ],
        &[
            "f16_gvt/F16Data_FullMSine_Level1.mat",
            "--u",
            "Force",
            "--y",
            "Acceleration:1",
            "--period",
            "8192",
            "--output",
            "acceleration",
            "--band",
            "2:15",
        ],
        &[
            "robot_arm/robot_arm.dat",
            "--u",
            "1",
            "--y",
            "2",
            "--fs",
            "1",
            "--output",
            "acceleration",
            "--fit-gain",
            "--nfft",
            "256",
        ],
        &[
            "emps/DATA_EMPS.mat",
            "--u",
            "vir",
            "--y",
            "qm",
            "--fit-gain",
        ],
    ];
    for case in cases {
        let file = real_data(case[0]);
        let mut args = vec!["identify", file.as_str(), "--format", "json"];
        args.extend_from_slice(&case[1..]);
        let (code, out, err) = mms(&args);
        assert_eq!(code, 0, "{case:?}: {err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert!(v["classification"]["type"].is_string());
        let cands = v["candidates"].as_array().unwrap();
        assert!(!cands.is_empty(), "{case:?}");
        assert_eq!(cands[0]["rank"], 1);
    }
}

#[test]
fn bad_recordings_are_one_line_errors_with_exit_2() {
    let dir = temp_dir("bad");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().into_owned()
    };
    let rows = |f: &dyn Fn(usize) -> String| (1..=12).map(f).collect::<Vec<_>>().join("\n");
    let cases = [
        (
            write("noheader.csv", &rows(&|k| format!("{k},1,0"))),
            "noheader.csv:1:",
        ),
        (
            write(
                "cols.csv",
                &format!("freq,re,im\n{}", rows(&|k| format!("{k},1,0"))),
            ),
            "cols.csv:1:",
        ),
        (
            write(
                "nan.csv",
                &format!(
                    "freq_hz,re,im\n{}",
                    rows(&|k| if k == 5 {
                        "5,nan,0".into()
                    } else {
                        format!("{k},1,0")
                    })
                ),
            ),
            "nan.csv:6:",
        ),
        (
            write(
                "order.csv",
                &format!(
                    "freq_hz,re,im\n{}",
                    rows(&|k| if k == 7 {
                        "3,1,0".into()
                    } else {
                        format!("{k},1,0")
                    })
                ),
            ),
            "order.csv:8:",
        ),
        (
            write("short.csv", "freq_hz,re,im\n1,1,0\n2,1,0\n"),
            "short.csv",
        ),
        (
            real_data("sperte/setup18_motor_side_v0.3.mat"),
            "sample rate",
        ),
    ];
    for (file, want) in &cases {
        let out_dir = dir.join("never");
        let (code, out, err) = mms(&["identify", file, "--out", out_dir.to_str().unwrap()]);
        assert_eq!(code, 2, "{file}: {err}");
        assert!(out.is_empty());
        assert!(
            err.starts_with("mms: error: ") && err.contains(want),
            "{file}: {err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            !out_dir.join("report.md").exists(),
            "no report after an error"
        );
    }
    let mat = real_data("f16_gvt/F16Data_FullMSine_Level1.mat");
    let (code, _, err) = mms(&["identify", &mat, "--u", "Force", "--y", "Missing"]);
    assert_eq!(code, 2);
    assert!(err.contains("variable 'Missing'"), "{err}");
    let (code, _, err) = mms(&["identify", &mat, "--band", "15:2"]);
    assert_eq!(code, 2);
    assert!(err.contains("--band 15:2"), "{err}");
}

/// A1 (Tab. 7 parameters) on 1500 log-spaced lines, 2-80 Hz.
const A1_TRUTH: [f64; 7] = [0.0044, 0.0173, 0.0184, 46.8, 14.3, 0.002, 0.001];
/// The dead time concealed in `delayed.csv`.
const A1_DELAY: f64 = 4e-4;

/// Writes the A1 files of the diagnose tests into `dir`: `delayed.csv`
/// (the truth with a dead time and 0.5 % noise), `plain.csv` (without the
/// delay), `model.toml` (every parameter 10 % off, alternately up and
/// down) and `simulation.csv` (that model's noise-free FRF, the simulation
/// an engineer would have of the design).
fn a1_files(dir: &Path) -> [PathBuf; 4] {
    use mms::model_file::{ModelFile, Motion};
    use mms::response::{ChainResponse, Effects, Parameters};
    let a1 = Model::from_id("A1").unwrap();
    let f: Vec<f64> = (0..1500)
        .map(|k| 2.0 * (40.0f64).powf(k as f64 / 1499.0))
        .collect();
    let mut rng = XorShift::new(17);
    let write = |name: &str, p: &[f64], effects: &Effects, noise: f64, rng: &mut XorShift| {
        let g = ChainResponse::with_effects(&a1, mms::Output::Position, effects);
        let h: Vec<num_complex::Complex64> = f
            .iter()
            .map(|&x| {
                let n = num_complex::Complex64::new(rng.normal(), rng.normal()) * noise;
                g.eval(p, x).unwrap() * (1.0 + n)
            })
            .collect();
        let path = dir.join(name);
        let frf = frf::Frf::new(f.clone(), h, None).unwrap();
        std::fs::write(&path, frf::write_csv(&frf, frf::CsvLayout::ReIm)).unwrap();
        path
    };
    let delayed = write(
        "delayed.csv",
        &A1_TRUTH,
        &Effects {
            time_delay_s: Some(A1_DELAY),
            ..Effects::default()
        },
        0.005,
        &mut rng,
    );
    let plain = write("plain.csv", &A1_TRUTH, &Effects::default(), 0.005, &mut rng);
    let nominal: Vec<f64> = A1_TRUTH
        .iter()
        .enumerate()
        .map(|(i, v)| v * if i % 2 == 0 { 1.1 } else { 0.9 })
        .collect();
    let simulation = write(
        "simulation.csv",
        &nominal,
        &Effects::default(),
        0.0,
        &mut rng,
    );
    let file = ModelFile {
        model: a1,
        output: mms::Output::Position,
        parameters: Parameters::from_values(&a1, nominal).unwrap(),
        gain: 1.0,
        motion: Motion::Translational,
        effects: Effects::default(),
    };
    let model = dir.join("model.toml");
    std::fs::write(&model, file.to_toml()).unwrap();
    [delayed, plain, model, simulation]
}

/// Runs `mms diagnose ARGS --format json`, which must succeed.
fn diagnose_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["diagnose"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--format", "json"]);
    let (code, out, err) = mms(&all);
    assert_eq!(code, 0, "{args:?}: {err}");
    serde_json::from_str(&out).unwrap()
}

/// `mms diagnose` on a recording of A1 with a concealed dead time, given
/// a model file with parameters 10 % off: it names the delay and its size;
/// without the delay it says nothing is missing; a bad model file is a
/// one-line error naming the line.
#[test]
fn diagnose_names_a_concealed_delay_and_says_none_without_it() {
    let dir = temp_dir("diagnose");
    let [delayed, plain, model, _] = a1_files(&dir);
    let run =
        |rec: &Path| diagnose_json(&[rec.to_str().unwrap(), "--model", model.to_str().unwrap()]);
    let v = run(&delayed);
    assert_eq!(v["effects"][0]["kind"], "time_delay", "{}", v["effects"]);
    let got = v["effects"][0]["parameters"]["delay_s"].as_f64().unwrap();
    assert!((got / A1_DELAY - 1.0).abs() < 0.1, "{got}");
    let (before, after) = (&v["fit"]["before"], &v["fit"]["after"]);
    assert!(after["rms_deg"].as_f64().unwrap() < 0.5 * before["rms_deg"].as_f64().unwrap());
    assert!(!v["mismatch"].as_array().unwrap().is_empty());
    let v = run(&plain);
    assert_eq!(v["effects"][0]["kind"], "none", "{}", v["effects"]);
    // A bad model file.
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "structure = \"A1\"\noutput = \"position\"\n[parameters]\nm1 = -1\n",
    )
    .unwrap();
    let (code, _, err) = mms(&[
        "diagnose",
        plain.to_str().unwrap(),
        "--model",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("bad.toml:4:") && err.contains("m1"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1);
}

/// `mms diagnose` on a time-domain CSV (t,u,y) made by the project's
/// nonlinear simulator from a 2-mass chain (velocity of the far mass) with
/// 0.3 N of concealed Coulomb friction, given a model 8 % off (with the
/// drive's hold): the time-domain diagnosis names
/// friction with its force, the time-domain error drops, and the written
/// model_after.toml carries `coulomb_n` and reads back.
#[test]
fn diagnose_time_domain_finds_concealed_coulomb_friction() {
    use mms::model_file::{ModelFile, Motion};
    use mms::response::{Effects, Parameters};
    let dir = temp_dir("diagnose-time");
    let model = Model::new(2, 0, mms::Port::new(1, 0), mms::Port::new(2, 0)).unwrap();
    let truth = vec![1.0, 0.6, 2500.0, 2.0];
    let fs = 500.0;
    let mut rng = XorShift::new(5);
    let phases: Vec<f64> = (0..30)
        .map(|_| std::f64::consts::TAU * rng.uniform())
        .collect();
    let u: Vec<f64> = (0..2000)
        .map(|k| {
            let t = k as f64 / fs;
            let level = if k < 1000 { 1.0 } else { 3.0 };
            level
                * phases
                    .iter()
                    .enumerate()
                    .map(|(i, p)| (std::f64::consts::TAU * (2 * i + 1) as f64 * t + p).cos() * 0.25)
                    .sum::<f64>()
        })
        .collect();
    let file = |values: Vec<f64>, effects: Effects| ModelFile {
        model,
        output: mms::Output::Velocity,
        parameters: Parameters::from_values(&model, values).unwrap(),
        gain: 1.0,
        motion: Motion::Translational,
        effects,
    };
    let concealed = Effects {
        coulomb_friction: Some(0.3),
        ..Effects::default()
    };
    let y = mms::simulate::simulate(&file(truth.clone(), concealed), &u, fs).unwrap();
    let scale = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut csv = String::from("t,u,y\n");
    for (k, (u, y)) in u.iter().zip(&y).enumerate() {
        csv.push_str(&format!(
            "{},{u},{}\n",
            k as f64 / fs,
            y + 2e-3 * scale * rng.normal()
        ));
    }
    let rec = dir.join("run.csv");
    std::fs::write(&rec, csv).unwrap();
    let nominal: Vec<f64> = truth
        .iter()
        .enumerate()
        .map(|(i, v)| v * if i % 2 == 0 { 1.08 } else { 0.92 })
        .collect();
    let model_path = dir.join("model.toml");
    // The model of a sampled drive knows its hold: half a sample of dead
    // time. (Without it the calibration pins the damper at its bound to
    // imitate the lag, and the friction is read 9-13 % high.)
    let hold = Effects {
        time_delay_s: Some(0.5 / fs),
        ..Effects::default()
    };
    std::fs::write(&model_path, file(nominal, hold).to_toml()).unwrap();
    let out = dir.join("out");
    let args = [
        "diagnose",
        rec.to_str().unwrap(),
        "--model",
        model_path.to_str().unwrap(),
        "--format",
        "json",
    ];
    let (code, text, err) = mms(&args);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(
        v["effects"][0]["kind"], "coulomb_friction",
        "{}",
        v["effects"]
    );
    let got = v["effects"][0]["parameters"]["coulomb_n"].as_f64().unwrap();
    assert!((got / 0.3 - 1.0).abs() < 0.1, "{got}");
    let (before, after) = (&v["fit"]["before"], &v["fit"]["after"]);
    assert!(after["rms_time"].as_f64().unwrap() < 0.5 * before["rms_time"].as_f64().unwrap());
    assert_eq!(
        v["model_after"]["effects"]["friction"]["coulomb_n"].as_f64(),
        Some(got)
    );
    assert!(v["frequency_domain"]["effects"].is_array());
    // --out writes the report and a model file that reads back.
    let (code, _, err) = mms(&[&args[..4], &["--out", out.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{err}");
    let after =
        ModelFile::parse(&std::fs::read_to_string(out.join("model_after.toml")).unwrap()).unwrap();
    assert_eq!(after.effects.coulomb_friction, Some(got));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("Time domain") && report.contains("amplitude dependence"));
}

/// `--recording FILE` does what the positional recording does;
/// `--simulation FILE` (the design model's simulated FRF) stands in for
/// the model file and finds the same concealed delay; `--select holdout`
/// finds it too and says none without it; giving both or neither of a
/// pair of alternatives is a one-line error with exit code 2.
#[test]
fn diagnose_recording_and_simulation_flags_and_holdout() {
    let dir = temp_dir("diagnose-flags");
    let [delayed, plain, model, simulation] = a1_files(&dir);
    let (rec, plain, model, sim) = (
        delayed.to_str().unwrap(),
        plain.to_str().unwrap(),
        model.to_str().unwrap(),
        simulation.to_str().unwrap(),
    );
    let delay_of = |v: &serde_json::Value| {
        assert_eq!(v["effects"][0]["kind"], "time_delay", "{}", v["effects"]);
        v["effects"][0]["parameters"]["delay_s"].as_f64().unwrap()
    };
    let flag = diagnose_json(&["--recording", rec, "--model", model]);
    let positional = diagnose_json(&[rec, "--model", model]);
    assert_eq!(flag, positional);
    // From the simulation: a 3-mass model that reproduces it, and the
    // concealed delay within 10 %.
    let v = diagnose_json(&["--recording", rec, "--simulation", sim]);
    assert!(
        (delay_of(&v) / A1_DELAY - 1.0).abs() < 0.1,
        "{}",
        v["effects"]
    );
    assert!(v["model_after"]["structure"]
        .as_str()
        .unwrap()
        .starts_with("N3"));
    // Held-out validation.
    let v = diagnose_json(&[rec, "--model", model, "--select", "holdout"]);
    assert!((delay_of(&v) / A1_DELAY - 1.0).abs() < 0.1);
    let v = diagnose_json(&[plain, "--model", model, "--select", "holdout"]);
    assert_eq!(v["effects"][0]["kind"], "none", "{}", v["effects"]);
    // Alternatives: exactly one of each pair.
    let cases: [(&[&str], &str); 4] = [
        (&[rec, "--recording", rec, "--model", model], "exactly one"),
        (&["--model", model], "no recording"),
        (&[rec, "--model", model, "--simulation", sim], "not both"),
        (&[rec], "--model MODEL.toml or --simulation"),
    ];
    for (args, want) in cases {
        let mut all = vec!["diagnose"];
        all.extend_from_slice(args);
        let (code, out, err) = mms(&all);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty());
        assert!(err.contains(want), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    // A simulation no chain model reproduces (the delayed recording, noise
    // and dead time included) is an error naming the file.
    let (code, _, err) = mms(&["diagnose", plain, "--simulation", rec]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("delayed.csv") && err.contains("no chain model"),
        "{err}"
    );
}

/// `mms diagnose` on the EMPS record (closed position loop) with the
/// recorded controller: the one-mass model without Coulomb friction gets
/// `friction` (within 5 % of the published 20.39 N) and `offset`, the
/// JSON says the loop was closed and carries the IDIM-LS estimates; bad
/// loop options are one-line errors with exit code 2.
#[test]
fn diagnose_emps_closed_loop() {
    let dir = temp_dir("emps");
    let model = dir.join("emps.toml");
    std::fs::write(&model, common::EMPS_MODEL).unwrap();
    let mat = real_data("emps/DATA_EMPS.mat");
    let model = model.to_str().unwrap();
    let base = [
        "diagnose", &mat, "--u", "vir", "--y", "qm", "--fs", "1000", "--model", model,
    ];
    let mut args = base.to_vec();
    args.extend([
        "--reference",
        "qg",
        "--controller",
        "kp=kp,kv=kv",
        "--format",
        "json",
    ]);
    let (code, out, err) = mms(&args);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["version"], 4);
    assert_eq!(v["time_domain"]["closed_loop"], true);
    assert_eq!(v["verdict"]["decided_by"], "time", "{}", v["verdict"]);
    assert_eq!(
        v["effects"][0]["kind"], "coulomb_friction",
        "{}",
        v["effects"]
    );
    let fc = v["effects"][0]["parameters"]["coulomb_n"].as_f64().unwrap();
    assert!((fc / 20.39 - 1.0).abs() < 0.05, "{fc}");
    assert_eq!(v["effects"][1]["kind"], "offset", "{}", v["effects"]);
    assert!(v["model_after"]["effects"]["offset"]["force_n"].is_number());
    let id = &v["time_domain"]["inverse_dynamics"]["estimates"];
    assert_eq!(id[2]["name"], "coulomb_n");
    let fc_id = id[2]["value"].as_f64().unwrap();
    assert!((fc_id / 20.39 - 1.0).abs() < 0.02, "{fc_id}");

    let fs_num = "kp=160.18,kv=243.45,filter=0.5:0.5,saturation=10";
    let cases: [(&[&str], &str); 6] = [
        (
            &["--reference", "qg", "--controller", "kp=kp"],
            "give both kp and kv",
        ),
        (
            &["--reference", "qg", "--controller", "kp=nosuch,kv=kv"],
            "no such number or variable",
        ),
        (
            &["--reference", "qg", "--controller", "kp=1,kv=2,ki=3"],
            "unknown key 'ki'",
        ),
        (
            &["--reference", "nosuch", "--controller", fs_num],
            "--reference nosuch",
        ),
        // The law with a wrong gain does not reproduce vir.
        (
            &["--reference", "qg", "--controller", "kp=160.18,kv=100"],
            "controller law",
        ),
        (&["--reference", "qg"], "--controller"),
    ];
    for (extra, want) in cases {
        let mut all = base.to_vec();
        all.extend_from_slice(extra);
        let (code, out, err) = mms(&all);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(out.is_empty());
        assert!(err.contains(want), "{extra:?}: {err}");
        if !want.starts_with("--") {
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        }
    }
}

/// `mms diagnose` on recordings it cannot use: a record shorter than the
/// segment, a constant input, a constant output and a column with a NaN
/// are one-line errors naming the file and the channel (exit 2, nothing
/// on stdout); a record whose input and output are unrelated noise says
/// that nothing is informative and names no effect (exit 0).
#[test]
fn diagnose_bad_and_uninformative_recordings() {
    let dir = temp_dir("diagnose-bad");
    let [_, _, model, _] = a1_files(&dir);
    let model = model.to_str().unwrap();
    let mut rng = XorShift::new(17);
    let write = |name: &str, n: usize, f: &mut dyn FnMut(usize) -> (f64, f64)| {
        let mut text = String::from("t,u,y\n");
        for k in 0..n {
            let (u, y) = f(k);
            text.push_str(&format!("{},{u},{y}\n", k as f64 / 1000.0));
        }
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().into_owned()
    };
    let wave = |k: usize| (0.3 * k as f64).sin();
    let cases = [
        (
            write("short.csv", 100, &mut |k| (wave(k), wave(k + 3))),
            "short.csv",
            "too few",
        ),
        (
            write("flat_u.csv", 5000, &mut |k| (1.0, wave(k))),
            "flat_u.csv",
            "input u is constant",
        ),
        (
            write("flat_y.csv", 5000, &mut |k| (wave(k), 2.0)),
            "flat_y.csv",
            "output y is constant",
        ),
        (
            write("nan.csv", 5000, &mut |k| {
                (wave(k), if k == 7 { f64::NAN } else { wave(k + 1) })
            }),
            "nan.csv:9:",
            "column 'y'",
        ),
    ];
    for (path, place, what) in &cases {
        let (code, out, err) = mms(&["diagnose", path, "--model", model, "--nfft", "256"]);
        assert_eq!(code, 2, "{path}: {err}");
        assert!(out.is_empty(), "{path}: {out}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(place) && err.contains(what), "{path}: {err}");
    }
    let noise = write("noise.csv", 20000, &mut |_| (rng.normal(), rng.normal()));
    let v = diagnose_json(&[&noise, "--model", model]);
    assert_eq!(v["verdict"]["headline"], "none", "{}", v["verdict"]);
    assert_eq!(v["verdict"]["reason"]["kind"], "nothing_informative");
    assert_eq!(v["effects"][0]["kind"], "none");
}

/// `--excitation` errors: a constant excitation, and one that does not
/// reach the plant input (unrelated to u), are one-line errors naming the
/// file and the excitation, exit code 2.
#[test]
fn excitation_that_is_constant_or_does_not_reach_the_input() {
    let dir = temp_dir("excitation");
    let mut rng = XorShift::new(23);
    let mut text = String::from("t,u,y,flat,other\n");
    for k in 0..8000 {
        let u = rng.normal();
        let _ = std::fmt::Write::write_fmt(
            &mut text,
            format_args!(
                "{},{u},{},1.5,{}\n",
                k as f64 / 1000.0,
                0.5 * u,
                rng.normal()
            ),
        );
    }
    let path = dir.join("loop.csv");
    std::fs::write(&path, text).unwrap();
    let p = path.to_str().unwrap();
    for (x, want) in [
        ("flat", "excitation flat is constant"),
        ("other", "does not reach the input u"),
    ] {
        let (code, out, err) = mms(&["identify", p, "--excitation", x]);
        assert_eq!(code, 2, "{x}: {err}");
        assert!(out.is_empty());
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains("loop.csv") && err.contains(want), "{x}: {err}");
    }
}

/// Operating points recorded at different sample rates are refused: a
/// one-line error naming both files and rates, exit code 2.
#[test]
fn operating_points_at_different_rates_are_an_error() {
    let dir = temp_dir("operating-rates");
    let mut rng = XorShift::new(23);
    let mut write = |name: &str, fs: f64| {
        // A lightly damped mass-spring driven by noise (explicit Euler at
        // a fine step; only the rate of the written samples matters).
        let mut text = String::from("t,u,y\n");
        let (mut x, mut v) = (0.0f64, 0.0f64);
        for k in 0..8192 {
            let u = rng.normal();
            let dt = 1.0 / fs;
            let a = u - 400.0 * x - 2.0 * v;
            v += a * dt;
            x += v * dt;
            text.push_str(&format!("{},{u},{x}\n", k as f64 * dt));
        }
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().into_owned()
    };
    let a = write("at_1000.csv", 1000.0);
    let b = write("at_500.csv", 500.0);
    let (code, out, err) = mms(&["identify", &a, "--operating-point", &b]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty());
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("at_500.csv") && err.contains("500") && err.contains("1000"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Sample rates are numbers in a physical range: a negative one is read
/// as a number and refused as such (not as an unknown flag), an absurdly
/// small one from the flag or from a time column is refused too; each a
/// one-line error naming the file, exit code 2.
#[test]
fn sample_rates_outside_the_physical_range_are_refused() {
    let dir = temp_dir("sample-rates");
    let mut text = String::from("t,u,y\n");
    for k in 0..4096 {
        let t = k as f64 * 1e300;
        text.push_str(&format!(
            "{t:e},{},{}\n",
            (0.3 * k as f64).sin(),
            (0.3 * k as f64 + 0.5).sin()
        ));
    }
    let slow = dir.join("slow.csv");
    std::fs::write(&slow, text).unwrap();
    let path = real_data("sperte/setup18_motor_side_v0.3.mat");
    for (args, want) in [
        (
            vec![
                "frf",
                path.as_str(),
                "--u",
                "result:1",
                "--y",
                "result:2",
                "--fs",
                "-5",
            ],
            "positive",
        ),
        (
            vec![
                "frf",
                path.as_str(),
                "--u",
                "result:1",
                "--y",
                "result:2",
                "--fs",
                "1e-320",
            ],
            "outside",
        ),
        (vec!["frf", slow.to_str().unwrap()], "outside"),
    ] {
        let (code, out, err) = mms(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty());
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(
            err.contains(want) && (err.contains(".mat") || err.contains("slow.csv")),
            "{err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An input channel that is unrelated to the output and 1e30 times
/// smaller (a disconnected channel read in volts beside a position in
/// counts) is refused with one line and exit code 2, never given a type or
/// a model; the same input scaled to the output's size is refused the
/// same way, so the verdict does not depend on the units.
#[test]
fn an_input_unrelated_to_the_output_is_refused_at_any_scale() {
    let dir = temp_dir("unrelated-input");
    let mut rng = mms::xorshift::XorShift::new(11);
    for scale in [1e-30, 1.0] {
        let mut text = String::from("t,u,y\n");
        for k in 0..8192 {
            let (u, y) = (scale * rng.normal(), rng.normal());
            text.push_str(&format!("{},{u:e},{y:e}\n", k as f64 / 1000.0));
        }
        let path = dir.join(format!("unrelated-{scale:e}.csv"));
        std::fs::write(&path, text).unwrap();
        let p = path.to_str().unwrap();
        let (code, out, err) = mms(&["identify", p]);
        assert_eq!(code, 2, "{scale}: {out}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(
            err.contains(p) && err.contains("no informative band"),
            "{err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--out` writes only regular files, and a report directory as one set:
/// a FIFO or a link out of the folder in place of an output file is
/// refused with one line and exit code 2 and replaced by nothing; when one
/// file of a report directory cannot be written, the files already there
/// stay as they were (no mix of old and new), and no staging directory is
/// left behind.
#[cfg(unix)]
#[test]
fn out_writes_only_regular_files_and_whole_sets() {
    let dir = temp_dir("safe-out");
    let (csv, _) = recording(&dir, "A1", 0.0, 3);
    let csv = csv.to_str().unwrap();
    let fifo = dir.join("fifo.csv");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("skipped: mkfifo is not available");
        return;
    }
    let (code, _, err) = mms(&["frf", csv, "--out", fifo.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(!meta.is_file(), "the FIFO was replaced by a file");
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink("/etc/hostname", &link).unwrap();
    let (code, _, err) = mms(&["frf", csv, "--out", link.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    // A report directory whose report.md is a FIFO: nothing is replaced.
    let out = dir.join("report");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("bode.svg"), "old").unwrap();
    let status = std::process::Command::new("mkfifo")
        .arg(out.join("report.md"))
        .status()
        .unwrap();
    assert!(status.success());
    let (code, _, err) = mms(&["identify", csv, "--out", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert_eq!(
        std::fs::read_to_string(out.join("bode.svg")).unwrap(),
        "old"
    );
    assert!(!out.join("model.toml").exists());
    let staged = |d: &Path| -> Vec<String> {
        std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".tmp"))
            .collect()
    };
    assert!(staged(&dir).is_empty() && staged(&out).is_empty());
    // Without the FIFO the set is written whole.
    std::fs::remove_file(out.join("report.md")).unwrap();
    let (code, _, err) = mms(&["identify", csv, "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    for f in ["bode.svg", "bode.png", "model.toml", "report.md"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert_ne!(
        std::fs::read_to_string(out.join("bode.svg")).unwrap(),
        "old"
    );
    assert!(staged(&out).is_empty());
    // A link to a directory is followed.
    let linked = dir.join("linked");
    std::fs::create_dir(&linked).unwrap();
    let via = dir.join("via");
    std::os::unix::fs::symlink(&linked, &via).unwrap();
    let (code, _, err) = mms(&["identify", csv, "--out", via.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(linked.join("report.md").is_file() && staged(&linked).is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A model file whose values overflow (masses and a spring of 1e308: the
/// chain is singular at every line) is that file's fault: the one-line
/// error (exit code 2) names the model file, not the recording.
#[test]
fn diagnose_blames_a_model_that_cannot_be_evaluated() {
    let dir = temp_dir("blame-model");
    let (csv, _) = recording(&dir, "A1", 0.0, 5);
    let model = dir.join("huge.toml");
    std::fs::write(
        &model,
        "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\noutput = \"position\"\n\
         [parameters]\nm1 = 1e308\nm2 = 1e308\nc12 = 1e308\nd12 = 0.1\n",
    )
    .unwrap();
    let (m, c) = (model.to_str().unwrap(), csv.to_str().unwrap());
    let (code, _, err) = mms(&["diagnose", c, "--model", m]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains(m) && !err.contains(c), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Model values outside their physical range (mms::ranges) are that file's
/// fault: a mass of 5e-324 kg, a spring of 1e300 N/m, a dead time of
/// 1e300 s, a gain of 1e-300, a damper below zero. Each is one line (exit
/// code 2) naming the model file, the line of the value and the quantity,
/// never the recording. An FRF line at 1e300 Hz is refused the same way,
/// naming the recording and its line.
#[test]
fn values_outside_their_physical_range_are_refused() {
    let dir = temp_dir("physical-ranges");
    let (csv, _) = recording(&dir, "A1", 0.0, 5);
    let c = csv.to_str().unwrap();
    let head = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\noutput = \"position\"\n";
    for (name, body, line, quantity) in [
        ("tiny-mass", "[parameters]\nm1 = 5e-324\nm2 = 1\nc12 = 100\nd12 = 0.1\n", 7, "mass"),
        ("stiff", "[parameters]\nm1 = 1\nm2 = 1\nc12 = 1e300\nd12 = 0.1\n", 9, "stiffness"),
        ("negative-damper", "[parameters]\nm1 = 1\nm2 = 1\nc12 = 100\nd12 = -0.1\n", 10, "damping"),
        (
            "slow-delay",
            "[parameters]\nm1 = 1\nm2 = 1\nc12 = 100\nd12 = 0.1\n[effects]\ntime_delay = { delay_s = 1e300 }\n",
            12,
            "time delay",
        ),
        ("tiny-gain", "gain = 1e-300\n[parameters]\nm1 = 1\nm2 = 1\nc12 = 100\nd12 = 0.1\n", 6, "gain"),
    ] {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, format!("{head}{body}")).unwrap();
        let m = model.to_str().unwrap();
        let (code, _, err) = mms(&["diagnose", c, "--model", m]);
        assert_eq!(code, 2, "{name}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains(&format!("{m}:{line}: ")) && !err.contains(c)
                && err.contains(quantity),
            "{name}: {err}"
        );
    }
    let far = dir.join("far.csv");
    std::fs::write(&far, "freq_hz,re,im\n1,1,0\n2,1,0\n1e300,1,0\n").unwrap();
    let f = far.to_str().unwrap();
    let (code, _, err) = mms(&["identify", f]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains(&format!("{f}:4: ")) && err.contains("1e300"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `mms diagnose` with two encoders of a drive inside a position loop
/// closed on the first (the motor's): each output is simulated inside the
/// loop closed on the motor and both name the Coulomb friction the record
/// was made with; the law is checked on the output it reads.
#[test]
fn diagnose_two_encoders_in_a_loop_closed_on_the_first() {
    use mms::model_file::ModelFile;
    use mms::simulate::{ClosedLoop, Controller, Feedback, SimOptions, Simulator};
    let dir = temp_dir("two-encoders-loop");
    let fs = 1000.0;
    let n = 6000;
    let r: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 / fs;
            let w = 2.0 * std::f64::consts::PI;
            0.05 * (1.0 - (w * 0.5 * t).cos()) + 0.01 * (w * 1.7 * t).sin()
        })
        .collect();
    let c = Controller::new(40.0, 30.0);
    let model = |m1: f64, m2: f64, k: f64, sensor: usize| {
        format!(
            "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [{sensor}, 0]\n\
             output = \"position\"\ngain = 10.0\n[parameters]\nm1 = {m1:?}\nm2 = {m2:?}\n\
             c12 = {k:?}\nd12 = 3.0\n[effects]\nfriction = {{ viscous_ns_per_m = 5.0 }}\n"
        )
    };
    let truth = |sensor: usize| {
        let mut f = ModelFile::parse(&model(1.0, 2.0, 20000.0, sensor)).unwrap();
        f.effects.coulomb_friction = Some(4.0);
        f
    };
    let run = |sensor: usize| {
        Simulator::new(&truth(sensor), fs, &SimOptions::default())
            .unwrap()
            .run_closed_loop(&ClosedLoop {
                feedback: Some(Feedback {
                    sensor: mms::Port::new(1, 0),
                    initial_position: 0.0,
                }),
                ..ClosedLoop::new(&c, &r)
            })
            .unwrap()
    };
    let (motor, load) = (run(1), run(2));
    let mut rng = XorShift::new(26);
    let mut text = String::from("t,u,y1,y2,r\n");
    for (k, r) in r.iter().enumerate() {
        text.push_str(&format!(
            "{},{:e},{:e},{:e},{r:e}\n",
            k as f64 / fs,
            motor.u[k],
            motor.y[k] + 2e-7 * rng.normal(),
            load.y[k] + 2e-7 * rng.normal(),
        ));
    }
    let rec = dir.join("loop.csv");
    std::fs::write(&rec, text).unwrap();
    let nominal = dir.join("nominal.toml");
    std::fs::write(&nominal, model(1.05, 1.9, 21000.0, 1)).unwrap();
    let (rec, nominal) = (rec.to_str().unwrap(), nominal.to_str().unwrap());
    let base = [
        "diagnose",
        rec,
        "--u",
        "u",
        "--y",
        "y1",
        "--y",
        "y2@2",
        "--model",
        nominal,
        "--reference",
        "r",
    ];
    let mut args = base.to_vec();
    args.extend(["--controller", "kp=40,kv=30", "--format", "json"]);
    let (code, out, err) = mms(&args);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for k in 0..2 {
        let d = &v["outputs"][k]["diagnosis"];
        assert_eq!(d["time_domain"]["closed_loop"], true, "output {k}");
        let effects = d["time_domain"]["effects"].as_array().unwrap();
        let fc = effects
            .iter()
            .find(|e| e["kind"] == "coulomb_friction")
            .and_then(|e| e["parameters"]["coulomb_n"].as_f64())
            .unwrap_or_else(|| panic!("output {k}: {effects:?}"));
        assert!((fc / 4.0 - 1.0).abs() < 0.05, "output {k}: {fc}");
    }
    // Both encoders at once: the same friction, decided in the time domain.
    let joint = &v["joint"];
    assert_eq!(joint["effects"][0]["kind"], "coulomb_friction", "{joint}");
    let fc = joint["effects"][0]["parameters"]["coulomb_n"]
        .as_f64()
        .unwrap();
    assert!((fc / 4.0 - 1.0).abs() < 0.05, "joint: {fc}");
    // A law that does not describe the loop is refused, naming the output.
    let mut args = base.to_vec();
    args.extend(["--controller", "kp=40,kv=60"]);
    let (code, _, err) = mms(&args);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("controller law"), "{err}");
}
