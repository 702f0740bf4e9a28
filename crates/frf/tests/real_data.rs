//! Measured recordings from `shared/data/real/` (see its README for their
//! sources), read through the public entry point.
//!
//! Reference values were computed independently with Python (numpy 2.4.6,
//! scipy 1.17.1), not with this crate:
//!
//! ```python
//! # random excitation (sperte, emps, robot_arm)
//! f, Puu = scipy.signal.welch(u, fs, window='hann', nperseg=N, noverlap=N//2, detrend='linear')
//! f, Pyy = scipy.signal.welch(y, fs, window='hann', nperseg=N, noverlap=N//2, detrend='linear')
//! f, Puy = scipy.signal.csd(u, y, fs, window='hann', nperseg=N, noverlap=N//2, detrend='linear')
//! H = Puy / Puu;  C = abs(Puy)**2 / (Puu * Pyy)      # printed at bin k
//! # periodic excitation (F-16): periods 2..9 of 8192 samples; the ramp
//! # through the period means taken out, then each period's mean
//! t = P * np.arange(1, 9); m = [x[s:s+P].mean() for s in t]
//! x = x - np.polyfit(t, m, 1)[0] * np.arange(len(x))      # u and y alike
//! U = np.fft.fft(u.reshape(9, P)[1:] - mean, axis=1); Y likewise
//! H = Y.mean(0) / U.mean(0)                 # the ratio of the mean spectra
//! dU, dY = U - U.mean(0), Y - Y.mean(0); p = 8; q = p * (p - 1)
//! vu, vy = (abs(dU)**2).sum(0) / q, (abs(dY)**2).sum(0) / q
//! cyu = (dY * dU.conj()).sum(0) / q
//! var = (vy + abs(H)**2 * vu - 2 * (H.conj() * cyu).real) / abs(U.mean(0))**2
//! C = 1 / (1 + p * var / abs(H)**2)         # the periodic "coherence"
//! ```
//!
//! scipy's bin `k` is line `k` here, at index `k - 1` (DC is dropped).
//! Both compute the same sums, so they agree to rounding: the tolerance is
//! 1e-9 relative for H1 and 1e-9 absolute for the coherence.

use frf::recording::{read_recording, RecordingOptions, Source};
use frf::welch::WelchOptions;
use frf::{Complex64, Frf};
use std::path::PathBuf;

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/real")
        .join(rel)
}

/// Checks line `k` (scipy's bin `k`) against a reference H1 and coherence.
fn check_line(frf: &Frf, k: usize, f: f64, h: Complex64, coh: f64) {
    let i = k - 1;
    assert!(
        (frf.freq_hz()[i] - f).abs() < 1e-9 * f,
        "line {k}: {} Hz vs {f}",
        frf.freq_hz()[i]
    );
    let got = frf.response()[i];
    assert!(
        (got - h).norm() <= 1e-9 * h.norm(),
        "line {k}: H1 {got} vs {h}"
    );
    let c = frf.coherence().unwrap()[i];
    assert!((c - coh).abs() <= 1e-9, "line {k}: coherence {c} vs {coh}");
}

fn time_domain(source: &Source) -> (f64, usize, usize, usize) {
    match source {
        Source::TimeDomain {
            fs,
            n_samples,
            averages,
            nfft,
            ..
        } => (*fs, *n_samples, *averages, *nfft),
        other => panic!("not a time-domain recording: {other:?}"),
    }
}

#[test]
fn sperte_motor_side_defaults_match_scipy() {
    // `result` is the only variable (40000 x 2): u = column 1 (noise
    // voltage), y = column 2 (motor position). No Fs in the file: 4 kHz
    // from the measurement script.
    // The scipy reference was computed with 8192-sample segments (the
    // default is shorter: see `default_nfft_gives_16_averages` below).
    let path = data("sperte/setup18_motor_side_v0.3.mat");
    let opts = RecordingOptions {
        fs: Some(4000.0),
        welch: WelchOptions {
            nfft: Some(8192),
            ..Default::default()
        },
        ..Default::default()
    };
    let rec = read_recording(&path, &opts).unwrap();
    let (fs, n, averages, nfft) = time_domain(&rec.source);
    assert_eq!((fs, n, averages, nfft), (4000.0, 40_000, 8, 8192));
    let Source::TimeDomain { input, output, .. } = &rec.source else {
        unreachable!()
    };
    assert_eq!((input.as_str(), output.as_str()), ("result:1", "result:2"));
    assert_eq!(rec.frf.len(), 4096);
    let frf = &rec.frf;
    check_line(
        frf,
        5,
        2.44140625,
        Complex64::new(-16.97419921252691, -0.4847638727764074),
        0.8607220540248354,
    );
    check_line(
        frf,
        20,
        9.765625,
        Complex64::new(-0.9445640455570427, 0.05487448024607254),
        0.9769815353023695,
    );
    check_line(
        frf,
        100,
        48.828125,
        Complex64::new(0.0651293830040573, -0.03123136649612557),
        0.9033658807481642,
    );
    check_line(
        frf,
        400,
        195.3125,
        Complex64::new(-0.0024306253919295913, 0.0027468147027374236),
        0.4026801951217552,
    );
    check_line(
        frf,
        1000,
        488.28125,
        Complex64::new(-0.002386407180304038, -0.0016778693835727302),
        0.4878989984500837,
    );
    // Plausible coherence over the mid band 20-200 Hz (scipy: mean
    // 0.7728685378202884), and a position response falling with
    // frequency (an integrator and a mass line): |H| at 10 Hz is more than
    // 100 times |H| at 200 Hz.
    let band = frf.band(20.0, 200.0).unwrap();
    let c = band.coherence().unwrap();
    let mean = c.iter().sum::<f64>() / c.len() as f64;
    assert!((mean - 0.7728685378202884).abs() < 1e-9, "{mean}");
    assert!(mean > 0.7);
    assert!(frf.response()[19].norm() > 100.0 * frf.response()[409].norm());
}

#[test]
fn default_nfft_gives_16_averages() {
    // The default segment length balances resolution against averages:
    // the largest power of two with at least 16 Hann segments at 50 %.
    for (rel, u, y, fs, want) in [
        // 40000 samples: 4096 gives 18 segments, 8192 only 8.
        (
            "sperte/setup18_motor_side_v0.3.mat",
            "result:1",
            "result:2",
            Some(4000.0),
            (18, 4096),
        ),
        // 160000 samples: 16384 gives 18.
        (
            "sperte/setup18_motor_side_v0.5.mat",
            "result:1",
            "result:2",
            Some(4000.0),
            (18, 16384),
        ),
        // 24841 samples: 2048 gives 23, 4096 only 11.
        ("emps/DATA_EMPS.mat", "vir", "qm", None, (23, 2048)),
    ] {
        let opts = RecordingOptions {
            u: Some(u.parse().unwrap()),
            y: Some(y.parse().unwrap()),
            fs,
            ..Default::default()
        };
        let rec = read_recording(data(rel), &opts).unwrap();
        let (_, _, averages, nfft) = time_domain(&rec.source);
        assert_eq!((averages, nfft), want, "{rel}");
        // Every line has a standard deviation, and where the coherence is
        // high it is small against the response.
        let sd = rec.frf.std_dev().unwrap();
        let coh = rec.frf.coherence().unwrap();
        for i in 0..rec.frf.len() {
            if coh[i] > 0.9 {
                assert!(sd[i] < 0.1 * rec.frf.response()[i].norm(), "{rel} line {i}");
            }
        }
    }
}

#[test]
fn sperte_with_the_authors_nfft_10000() {
    // nfft 10000 is not a power of two (Bluestein transform); 7 segments.
    let path = data("sperte/setup18_motor_side_v0.3.mat");
    let opts = RecordingOptions {
        u: Some("result:1".parse().unwrap()),
        y: Some("result:2".parse().unwrap()),
        fs: Some(4000.0),
        welch: WelchOptions {
            nfft: Some(10_000),
            ..Default::default()
        },
        ..Default::default()
    };
    let rec = read_recording(&path, &opts).unwrap();
    assert_eq!(time_domain(&rec.source), (4000.0, 40_000, 7, 10_000));
    let frf = &rec.frf;
    check_line(
        frf,
        3,
        1.2,
        Complex64::new(-49.04792400292326, -24.753087409232023),
        0.6056229718011282,
    );
    check_line(
        frf,
        25,
        10.0,
        Complex64::new(-0.9116956831368258, -0.0001424494240131096),
        0.9877217159920483,
    );
    check_line(
        frf,
        250,
        100.0,
        Complex64::new(-0.017303519635694157, 0.011024455734732382),
        0.9574135107512156,
    );
}

#[test]
fn f16_periodic_multisine_matches_numpy() {
    // Force (1 x 73728) to the driving-point acceleration (row 1 of the
    // 3 x 73728 Acceleration); Fs = 400 from the file; 9 periods of 8192.
    let path = data("f16_gvt/F16Data_FullMSine_Level1.mat");
    let opts = RecordingOptions {
        u: Some("Force".parse().unwrap()),
        y: Some("Acceleration:1".parse().unwrap()),
        welch: WelchOptions {
            period: Some(8192),
            ..Default::default()
        },
        ..Default::default()
    };
    let rec = read_recording(&path, &opts).unwrap();
    assert_eq!(time_domain(&rec.source), (400.0, 73_728, 8, 8192));
    let frf = &rec.frf;
    check_line(
        frf,
        41,
        2.001953125,
        Complex64::new(0.012594058126776211, 0.0031136833333953243),
        0.999940049045026,
    );
    check_line(
        frf,
        101,
        4.931640625,
        Complex64::new(0.009390149710338878, 0.001610762772710564),
        0.9999796122600855,
    );
    check_line(
        frf,
        205,
        10.009765625,
        Complex64::new(0.01691671641577593, 0.0006787029464780898),
        0.9999944154841601,
    );
    check_line(
        frf,
        307,
        14.990234375,
        Complex64::new(0.008604693463073168, 0.00030110400977698473),
        0.9999936228714431,
    );
    // The multisine excites lines 41 ..= 307 (2.0 - 15.0 Hz; numpy: input
    // power elsewhere below 1e-3 of the peak); there the periods agree and
    // the coherence exceeds 0.999 (numpy minimum 0.999378).
    let c = frf.coherence().unwrap();
    assert!(c[40..307].iter().all(|&v| v > 0.999));
}

#[test]
fn emps_sample_rate_from_t() {
    // vir (controller output, V) to qm (motor position, m); fs from the
    // time vector t: (n - 1) / (t[n-1] - t[0]) = 1000 Hz (numpy).
    let path = data("emps/DATA_EMPS.mat");
    let opts = RecordingOptions {
        u: Some("vir".parse().unwrap()),
        y: Some("qm".parse().unwrap()),
        welch: WelchOptions {
            nfft: Some(4096),
            ..Default::default()
        },
        ..Default::default()
    };
    let rec = read_recording(&path, &opts).unwrap();
    let (fs, n, averages, nfft) = time_domain(&rec.source);
    assert!((fs - 1000.0).abs() < 1e-6, "{fs}");
    // 24841 samples: 4096 gives (24841 - 4096) / 2048 + 1 = 11 segments.
    assert_eq!((n, averages, nfft), (24_841, 11, 4096));
    let frf = &rec.frf;
    let f = |k: usize| k as f64 * fs / 4096.0;
    check_line(
        frf,
        1,
        f(1),
        Complex64::new(-0.019227225998428812, -0.04496630956564135),
        0.4213531851118968,
    );
    check_line(
        frf,
        4,
        f(4),
        Complex64::new(-0.005998612219939635, 0.0012464451791249374),
        0.7155082100908581,
    );
    check_line(
        frf,
        10,
        f(10),
        Complex64::new(-0.0016709701695514021, -3.427582163621505e-05),
        0.9691808972570813,
    );
    check_line(
        frf,
        40,
        f(40),
        Complex64::new(-9.43943857187813e-05, 8.25110748543526e-07),
        0.9953542218200044,
    );
    // A missing variable names itself and lists what is there.
    let bad = RecordingOptions {
        u: Some("force".parse().unwrap()),
        ..opts
    };
    let e = read_recording(&path, &bad).unwrap_err().to_string();
    assert!(
        e.contains("DATA_EMPS.mat: variable 'force': not in the file (variables: "),
        "{e}"
    );
    assert!(e.contains("vir (24841x1 double)"), "{e}");
}

#[test]
fn robot_arm_headerless_matrix() {
    // Two columns, 1024 rows, no sample time: work in cycles per sample.
    let path = data("robot_arm/robot_arm.dat");
    let opts = RecordingOptions {
        fs: Some(1.0),
        welch: WelchOptions {
            nfft: Some(128),
            ..Default::default()
        },
        ..Default::default()
    };
    let rec = read_recording(&path, &opts).unwrap();
    // 1024 samples: 128 gives (1024 - 128) / 64 + 1 = 15 segments.
    assert_eq!(time_domain(&rec.source), (1.0, 1024, 15, 128));
    let frf = &rec.frf;
    check_line(
        frf,
        3,
        0.0234375,
        Complex64::new(-0.057456430030530296, -0.007026855590395399),
        0.8392838160274932,
    );
    check_line(
        frf,
        10,
        0.078125,
        Complex64::new(-0.9857928599135773, 0.013006127888969482),
        0.9938302364253467,
    );
    check_line(
        frf,
        30,
        0.234375,
        Complex64::new(-0.20726502668573193, -0.026604316723173125),
        0.6978804030984254,
    );
    check_line(
        frf,
        60,
        0.46875,
        Complex64::new(-0.12929753475022587, -0.3077135665509697),
        0.07523225649469405,
    );
    // Without a sample rate the file cannot be read.
    let e = read_recording(&path, &RecordingOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.ends_with("robot_arm.dat: no sample rate: a headerless matrix has no time column, so give the sample rate"), "{e}");
}

#[test]
fn other_real_files_read_and_garble_safely() {
    // The remaining recordings decode (all are zlib-compressed v7 files).
    for (rel, n) in [
        ("sperte/setup18_motor_side_v0.5.mat", 160_000),
        ("f16_gvt/F16Data_FullMSine_Level7.mat", 73_728),
        ("emps/DATA_EMPS_PULSES.mat", 0),
    ] {
        let bytes = std::fs::read(data(rel)).unwrap();
        let mat = frf::mat::read_mat(&bytes).unwrap();
        if n > 0 {
            assert!(mat.variables.iter().any(|v| v.numel() >= n), "{rel}");
        }
        // A truncated real file is an error, not a panic.
        assert!(
            frf::mat::read_mat(&bytes[..bytes.len() / 2]).is_err(),
            "{rel}"
        );
    }
}

/// The fields of a MATLAB struct are variables named by their path: the
/// TU/e 2025 closed-loop record (`Data.signals.u`, nested two deep) and the
/// 2018 record (`Data.y2`), against scipy's `loadmat(..., squeeze_me=True,
/// struct_as_record=False)` of the same files. A struct truncated anywhere
/// is an error, not a panic.
#[test]
fn struct_fields_read_by_path() {
    let bytes = std::fs::read(data("tue_motion_2025/motor_side_stationary.mat")).unwrap();
    let mat = frf::mat::read_mat(&bytes).unwrap();
    assert_eq!(mat.get("Data.settings.fs").unwrap().scalar(), Some(4000.0));
    let u = mat.get("Data.signals.u").unwrap();
    assert_eq!(u.dims, vec![240_000, 1]);
    assert_eq!(u.real[12345], -0.46216094493865967);
    assert_eq!(
        mat.get("Data.signals.y").unwrap().real[200_000],
        0.0031415927223861217
    );
    assert_eq!(
        mat.get("Data.signals.d").unwrap().real[7],
        -0.2851995825767517
    );
    // The file name is a MATLAB string object: listed, not read.
    assert!(mat
        .skipped
        .iter()
        .any(|s| s.name == "Data.FileName" && s.class == "opaque object"));
    for cut in [bytes.len() / 3, bytes.len() - 100] {
        assert!(frf::mat::read_mat(&bytes[..cut]).is_err(), "{cut}");
    }
    let bytes = std::fs::read(data("tue_motion_2018/scan_10hz_with_feedforward.mat")).unwrap();
    let mat = frf::mat::read_mat(&bytes).unwrap();
    assert_eq!(mat.get("Data.y2").unwrap().real[30_000], 8.3409284952809);
    assert_eq!(mat.get("Data.u").unwrap().real[100], 0.033356489783915255);
    let t = &mat.get("Data.Time").unwrap().real;
    assert_eq!(t[1] - t[0], 0.00048828125);
}

/// The 3-point closed-loop estimate on both TU/e 2025 records (`--u
/// Data.signals.u --y Data.signals.y --excitation Data.signals.d`, nfft
/// 16384 by default) against scipy: `csd(d, y) / csd(d, u)` with the same
/// Hann window, half overlap and linear detrending, at lines 41, 164, 500
/// and 614 (10, 40, 122, 150 Hz).
#[test]
fn tue_closed_loop_three_point_matches_scipy() {
    let cases = [
        (
            "tue_motion_2025/motor_side_1rads.mat",
            [
                (41, -0.5489532108964188, -0.20487379625125535),
                (164, -0.006471033129191854, -0.011817120072115944),
                (500, -0.005266355391670458, 0.0061843456528263814),
                (614, -0.0025638970705437023, 0.004279656982742679),
            ],
        ),
        (
            "tue_motion_2025/motor_side_stationary.mat",
            [
                (41, -0.8879921362049918, -0.08266564572607814),
                (164, -0.005766575668294229, -0.001719200311733435),
                (500, -0.0053813698690637676, 0.005940294877561304),
                (614, -0.002982083790631014, 0.0037068163866442972),
            ],
        ),
    ];
    for (rel, lines) in cases {
        let opts = RecordingOptions {
            u: Some("Data.signals.u".parse().unwrap()),
            y: Some("Data.signals.y".parse().unwrap()),
            excitation: Some("Data.signals.d".parse().unwrap()),
            ..Default::default()
        };
        let rec = read_recording(data(rel), &opts).unwrap();
        assert_eq!(time_domain(&rec.source), (4000.0, 240_000, 28, 16384));
        for (k, re, im) in lines {
            let want = Complex64::new(re, im);
            let got = rec.frf.response()[k - 1];
            assert!(
                (got - want).norm() <= 1e-9 * want.norm(),
                "{rel} line {k}: {got} vs {want}"
            );
        }
        // The loop functions come along, and the excitation reaches u.
        let e = rec.excitation.as_ref().unwrap();
        assert_eq!(e.name, "Data.signals.d");
        let (db, _) = e.peak_sensitivity_db().unwrap();
        assert!(db > 0.0 && db < 20.0, "{db}");
    }
}

/// `--fs VAR`: the sample rate from a named .mat variable; a variable
/// that is no positive scalar, or one that is not there (the fields of the
/// struct reached are listed), is an error naming it.
#[test]
fn sample_rate_from_a_named_variable() {
    let path = data("tue_motion_2025/motor_side_stationary.mat");
    let opts = |fs: &str| RecordingOptions {
        u: Some("Data.signals.u".parse().unwrap()),
        y: Some("Data.signals.y".parse().unwrap()),
        fs_variable: Some(fs.into()),
        ..Default::default()
    };
    let rec = read_recording(&path, &opts("Data.settings.fs")).unwrap();
    assert_eq!(time_domain(&rec.source).0, 4000.0);
    let e = read_recording(&path, &opts("Data.signals.u"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("'Data.signals.u'") && e.contains("positive real scalar"),
        "{e}"
    );
    let e = read_recording(&path, &opts("Data.settings.rate"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("fields: runtime, fs, samples"), "{e}");
}
