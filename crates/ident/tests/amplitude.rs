//! The amplitude comparison against known truths: three-mode FRFs at two
//! levels with noise drawn as the coherence says (8 averages), either the
//! same system at both levels (nothing may be flagged) or with one mode
//! softened and more damped at the higher level (that mode, and only it,
//! must be flagged, with the right size).

use frf::Frf;
use ident::amplitude::{
    amplitude_dependence, AmplitudeOptions, DampingTrend, Level, StiffnessTrend,
};
use mms::xorshift::XorShift;
use num_complex::Complex64;

const AVERAGES: usize = 8;
const COHERENCE: f64 = 0.998;

/// (frequency Hz, damping ratio, residue) of each mode.
type Modes = [(f64, f64, f64); 3];

const MODES: Modes = [(4.0, 0.015, 1.0), (8.0, 0.01, 0.6), (13.0, 0.02, 0.8)];

/// A modal sum on 0.05 Hz lines up to 20 Hz, with complex log-normal noise
/// of the variance a coherence of `COHERENCE` over `AVERAGES` implies.
fn level(rng: &mut XorShift, label: &str, modes: &Modes, rms: f64) -> Level {
    let f: Vec<f64> = (1..=400).map(|k| 0.05 * k as f64).collect();
    let sigma = ((1.0 - COHERENCE) / (2.0 * AVERAGES as f64 * COHERENCE)).sqrt();
    let h: Vec<Complex64> = f
        .iter()
        .map(|&x| {
            let clean: Complex64 = modes
                .iter()
                .map(|&(fi, z, r)| {
                    let q = x / fi;
                    r / Complex64::new(1.0 - q * q, 2.0 * z * q)
                })
                .sum();
            clean * Complex64::new(sigma * rng.normal(), sigma * rng.normal()).exp()
        })
        .collect();
    let n = f.len();
    Level {
        label: label.into(),
        frf: Frf::new(f, h, Some(vec![COHERENCE; n])).unwrap(),
        averages: AVERAGES,
        input_rms: rms,
        distortion: None,
    }
}

#[test]
fn a_linear_system_shows_no_amplitude_dependence() {
    let mut zs = Vec::new();
    for seed in 1..=10 {
        let mut rng = XorShift::new(seed);
        // Given high level first: the reference is the lower input RMS.
        let high = level(&mut rng, "high", &MODES, 5.0);
        let low = level(&mut rng, "low", &MODES, 1.0);
        let a = amplitude_dependence(&[high, low], &AmplitudeOptions::default()).unwrap();
        assert_eq!(a.levels[0].label, "low");
        assert!((a.levels[1].ratio - 5.0).abs() < 1e-12);
        assert_eq!(a.modes.len(), 3, "seed {seed}: {:?}", a.modes);
        assert!(
            a.levels[1].bands.is_empty(),
            "seed {seed}: {:?}",
            a.levels[1]
        );
        // The cost of noise alone is about 1.
        assert!(
            (0.7..1.3).contains(&a.levels[1].cost),
            "{}",
            a.levels[1].cost
        );
        for (m, &(f, z, _)) in a.modes.iter().zip(&MODES) {
            let s = &m.shifts[0];
            assert_eq!(s.stiffness, StiffnessTrend::None, "seed {seed}: {s:?}");
            assert_eq!(s.damping_trend, DampingTrend::None, "seed {seed}: {s:?}");
            // The local fit finds the mode: frequency within 0.05 %, damping
            // within 3 % (measured: 0.02 % and 1.4 %).
            let e = &m.estimates[0];
            eprintln!(
                "seed {seed} mode {f}: f error {:+.2e}, damping error {:+.3}, shift z {:+.2}, damping z {:+.2}",
                e.f_hz / f - 1.0,
                e.damping / z - 1.0,
                s.shift_z,
                s.damping_z
            );
            assert!((e.f_hz / f - 1.0).abs() < 5e-4, "seed {seed}: {e:?} vs {f}");
            assert!(
                (e.damping / z - 1.0).abs() < 0.03,
                "seed {seed}: {e:?} vs {z}"
            );
            zs.push(s.shift_z);
            zs.push(s.damping_z);
        }
        assert!(a.changed.is_empty(), "{:?}", a.changed);
    }
    // The standard deviations are honest: the z-scores of noise alone
    // scatter with a standard deviation near 1.
    let sd = (zs.iter().map(|z| z * z).sum::<f64>() / zs.len() as f64).sqrt();
    eprintln!("z-score standard deviation {sd:.3} over {}", zs.len());
    assert!((0.6..1.4).contains(&sd), "{sd}");
}

#[test]
fn a_softening_joint_is_found_at_its_mode() {
    for seed in 11..=15 {
        let mut rng = XorShift::new(seed);
        let mut soft = MODES;
        // The 8 Hz mode: 1.5 % lower and twice the damping at the higher
        // level.
        soft[1].0 *= 0.985;
        soft[1].1 *= 2.0;
        let low = level(&mut rng, "low", &MODES, 1.0);
        let high = level(&mut rng, "high", &soft, 8.0);
        let a = amplitude_dependence(&[low, high], &AmplitudeOptions::default()).unwrap();
        assert_eq!(a.modes.len(), 3, "seed {seed}");
        for (i, m) in a.modes.iter().enumerate() {
            let s = &m.shifts[0];
            if i == 1 {
                eprintln!(
                    "seed {seed}: shift {:+.4} % (z {:+.1}), damping change {:+.5} (z {:+.1})",
                    100.0 * s.shift_rel,
                    s.shift_z,
                    s.damping_change,
                    s.damping_z
                );
                assert_eq!(s.stiffness, StiffnessTrend::Softening, "seed {seed}: {s:?}");
                assert_eq!(
                    s.damping_trend,
                    DampingTrend::Increase,
                    "seed {seed}: {s:?}"
                );
                assert!((s.shift_rel + 0.015).abs() < 1e-3, "seed {seed}: {s:?}");
                assert!(
                    (s.damping_change / 0.01 - 1.0).abs() < 0.05,
                    "seed {seed}: {s:?}"
                );
            } else {
                assert_eq!(s.stiffness, StiffnessTrend::None, "seed {seed}: {s:?}");
                assert_eq!(s.damping_trend, DampingTrend::None, "seed {seed}: {s:?}");
            }
        }
        // The FRF differs beyond the noise around the 8 Hz mode (out to the
        // antiresonances it moves), not at the other two peaks.
        let bands = &a.levels[1].bands;
        let covered = |f: f64| bands.iter().any(|b| b.f_lo_hz <= f && f <= b.f_hi_hz);
        assert!(covered(8.0), "seed {seed}: {bands:?}");
        assert!(!covered(4.0) && !covered(13.0), "seed {seed}: {bands:?}");
        assert_eq!(a.changed, [1], "seed {seed}");
    }
}

#[test]
fn bad_levels_are_errors() {
    let mut rng = XorShift::new(99);
    let one = level(&mut rng, "one", &MODES, 1.0);
    let o = AmplitudeOptions::default();
    assert!(amplitude_dependence(std::slice::from_ref(&one), &o).is_err());
    // Different lines.
    let mut other = level(&mut rng, "other", &MODES, 2.0);
    other.frf = other.frf.band(1.0, 15.0).unwrap();
    let e = amplitude_dependence(&[one.clone(), other], &o).unwrap_err();
    assert!(e.to_string().contains("other"), "{e}");
    // One average: no noise estimate.
    let mut single = level(&mut rng, "single", &MODES, 2.0);
    single.averages = 1;
    let e = amplitude_dependence(&[one.clone(), single], &o).unwrap_err();
    assert!(e.to_string().contains("single"), "{e}");
    // Equal levels: nothing to compare.
    let same = level(&mut rng, "same", &MODES, 1.0);
    assert!(amplitude_dependence(&[one, same], &o).is_err());
}
