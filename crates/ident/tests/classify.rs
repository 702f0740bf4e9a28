//! Tests of `ident::classify` on FRFs built here, independently of the
//! classifier: synthetic pole/zero products with deterministic noise, and
//! the paper's 3-mass models with the parameters of Tab. 4, Tab. 6 and
//! Fig. 3, from `mms`'s damped transfer functions evaluated here.
//!
//! Frequencies are compared with the undamped natural frequencies of the
//! generating factors within 2 % (`FREQ_TOL`).

use frf::{Complex64, Frf};
use ident::notes::ClassifyNote;
use ident::{classify, Classification, ClassifyError, ClassifyOptions};
use mms::analysis::Feature;
use mms::xorshift::XorShift;
use mms::{Model, Output};
use poly::{Poly, Rat};
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// Relative tolerance of feature frequencies.
const FREQ_TOL: f64 = 0.02;

/// A factor of the inertance numerator off the positive real Omega axis.
#[derive(Clone, Copy, Debug)]
enum NmFactor {
    /// `1 - s^2/a^2`: a zero at `Omega = -a^2`.
    NegativeOmega { a_hz: f64 },
    /// `(1 + 2 za s/w + s^2/w^2)(1 - 2 zb s/w + s^2/w^2)`: a complex Omega
    /// zero pair near `w^2` (for `za = zb` exactly the undamped
    /// `(1 - Omega/w^2)^2 + 4 z^2 Omega/w^2`), one s-pair in each half plane.
    ComplexOmega { f_hz: f64, za: f64, zb: f64 },
}

/// Inertance `K prod(zero factors) prod(nm factors) / prod(pole factors)`
/// with factors `1 + 2 zeta s/w + s^2/w^2` given as `(f_hz, zeta)`.
#[derive(Clone, Debug)]
struct Synth {
    zeros: Vec<(f64, f64)>,
    poles: Vec<(f64, f64)>,
    nm: Vec<NmFactor>,
}

fn quad(s: Complex64, f_hz: f64, zeta: f64) -> Complex64 {
    let w = 2.0 * PI * f_hz;
    1.0 + 2.0 * zeta * s / w + s * s / (w * w)
}

impl Synth {
    fn inertance(&self, f_hz: f64) -> Complex64 {
        let s = Complex64::new(0.0, 2.0 * PI * f_hz);
        let mut g = Complex64::new(0.02, 0.0);
        for &(f, z) in &self.zeros {
            g *= quad(s, f, z);
        }
        for &(f, z) in &self.poles {
            g /= quad(s, f, z);
        }
        for nm in &self.nm {
            g *= match *nm {
                NmFactor::NegativeOmega { a_hz } => {
                    let a = 2.0 * PI * a_hz;
                    1.0 - s * s / (a * a)
                }
                NmFactor::ComplexOmega { f_hz, za, zb } => quad(s, f_hz, za) * quad(s, f_hz, -zb),
            };
        }
        g
    }

    /// Expected features `(kind, f_hz, multiplicity)` in increasing frequency.
    fn expected(&self) -> Vec<(Feature, f64, u32)> {
        let mut v: Vec<(Feature, f64, u32)> = Vec::new();
        let all = self
            .zeros
            .iter()
            .map(|z| (Feature::Antiresonance, z.0))
            .chain(self.poles.iter().map(|p| (Feature::Resonance, p.0)));
        for (k, f) in all {
            match v.iter_mut().find(|e| e.0 == k && e.1 == f) {
                Some(e) => e.2 += 1,
                None => v.push((k, f, 1)),
            }
        }
        v.sort_by(|a, b| a.1.total_cmp(&b.1));
        v
    }
}

#[derive(Clone, Copy, Debug)]
enum Grid {
    Log { f0: f64, f1: f64, n: usize },
    Linear { f0: f64, f1: f64, n: usize },
}

impl Grid {
    fn lines(self) -> Vec<f64> {
        match self {
            Grid::Log { f0, f1, n } => (0..n)
                .map(|i| f0 * (f1 / f0).powf(i as f64 / (n - 1) as f64))
                .collect(),
            Grid::Linear { f0, f1, n } => (0..n)
                .map(|i| f0 + (f1 - f0) * i as f64 / (n - 1) as f64)
                .collect(),
        }
    }
}

/// `response` on the grid, times `1 + noise (n1 + j n2)` with standard
/// normal `n1`, `n2`.
fn noisy(response: impl Fn(f64) -> Complex64, grid: Grid, noise: f64, seed: u64) -> Frf {
    let freq = grid.lines();
    let mut rng = XorShift::new(seed);
    let response = freq
        .iter()
        .map(|&f| response(f) * Complex64::new(1.0 + noise * rng.normal(), noise * rng.normal()))
        .collect();
    Frf::new(freq, response, None).unwrap()
}

/// `inertance` as the given output (divided by `(j w)^(2-k)`), with noise.
fn measure(
    inertance: impl Fn(f64) -> Complex64,
    output: Output,
    grid: Grid,
    noise: f64,
    seed: u64,
) -> Frf {
    let to_output = |f: f64| {
        let jw = Complex64::new(0.0, 2.0 * PI * f);
        inertance(f) / jw.powu(2 - output.s_power())
    };
    noisy(to_output, grid, noise, seed)
}

/// Short text of a classification for failure messages.
fn summary(c: &Classification) -> String {
    let feats: Vec<String> = c
        .features
        .iter()
        .map(|f| {
            format!(
                "{}{}@{:.2}Hz c={:.2} z={:?} dphi={:.0} prom={:.1}dB{}",
                if f.kind == Feature::Antiresonance {
                    "A"
                } else {
                    "R"
                },
                f.multiplicity,
                f.freq_hz,
                f.confidence,
                f.damping_ratio.map(|z| (z * 1e4).round() / 1e4),
                f.phase_change_deg,
                f.prominence_db,
                if f.in_type { "" } else { " (out)" }
            )
        })
        .collect();
    format!(
        "type {} conf {:.2} band {:.1}..{:.1} noise {:.3} dB\n  features {:?}\n  nm {:?}\n  notes {:?}",
        c.frf_type, c.confidence, c.band_hz.0, c.band_hz.1, c.noise_db, feats, c.nonminimum_phase, c.notes
    )
}

/// `None` when `c` has type `ty` and the in-type features match `expected`
/// (kind, multiplicity, frequency within `FREQ_TOL`); else what is wrong.
fn mismatch(c: &Classification, ty: &str, expected: &[(Feature, f64, u32)]) -> Option<String> {
    let got: Vec<_> = c.features.iter().filter(|f| f.in_type).collect();
    let ok = c.frf_type.to_string() == ty
        && got.len() == expected.len()
        && got.iter().zip(expected).all(|(g, e)| {
            g.kind == e.0
                && g.multiplicity == e.2
                && (g.freq_hz / e.1 - 1.0).abs() <= FREQ_TOL
                && (0.0..=1.0).contains(&g.confidence)
        });
    (!ok).then(|| format!("expected {ty} {expected:?}\n  {}", summary(c)))
}

fn cases() -> Vec<(&'static str, Synth)> {
    let s = |zeros: &[(f64, f64)], poles: &[(f64, f64)], nm: &[NmFactor]| Synth {
        zeros: zeros.to_vec(),
        poles: poles.to_vec(),
        nm: nm.to_vec(),
    };
    vec![
        (
            "ARAR",
            s(
                &[(30.0, 0.01), (120.0, 0.02)],
                &[(45.0, 0.01), (200.0, 0.02)],
                &[],
            ),
        ),
        (
            "RRA",
            s(&[(150.0, 0.02)], &[(25.0, 0.005), (60.0, 0.01)], &[]),
        ),
        (
            "ARR",
            s(&[(40.0, 0.01)], &[(55.0, 0.01), (130.0, 0.02)], &[]),
        ),
        (
            "RAR",
            s(&[(80.0, 0.02)], &[(30.0, 0.005), (140.0, 0.03)], &[]),
        ),
        (
            "A^2RR",
            s(
                &[(50.0, 0.01), (50.0, 0.01)],
                &[(90.0, 0.01), (160.0, 0.02)],
                &[],
            ),
        ),
        (
            "ARRA",
            s(
                &[(30.0, 0.01), (200.0, 0.02)],
                &[(50.0, 0.01), (110.0, 0.02)],
                &[],
            ),
        ),
        (
            "ARAR",
            s(
                &[(30.0, 0.05), (120.0, 0.05)],
                &[(45.0, 0.05), (200.0, 0.05)],
                &[],
            ),
        ),
        (
            "RR (nm)",
            s(
                &[],
                &[(40.0, 0.01), (150.0, 0.01)],
                &[NmFactor::ComplexOmega {
                    f_hz: 80.0,
                    za: 0.22,
                    zb: 0.2,
                }],
            ),
        ),
        (
            "ARR (nm)",
            s(
                &[(40.0, 0.01)],
                &[(55.0, 0.01), (130.0, 0.02)],
                &[NmFactor::NegativeOmega { a_hz: 200.0 }],
            ),
        ),
    ]
}

/// Every type in every output form, on a log and a linear grid, with
/// 0 %, 1 %, 3 % and 5 % multiplicative complex noise: the type and the
/// feature frequencies within 2 %.
#[test]
fn synthetic_types_in_every_output_form_grid_and_noise_level() {
    let grids = [
        Grid::Log {
            f0: 5.0,
            f1: 800.0,
            n: 1500,
        },
        Grid::Linear {
            f0: 5.0,
            f1: 800.0,
            n: 3181,
        },
    ];
    let mut seed = 1;
    let mut failures = Vec::new();
    let mut runs = 0;
    for (ty, synth) in cases() {
        for output in Output::ALL {
            for grid in grids {
                for noise in [0.0, 0.01, 0.03, 0.05] {
                    seed += 1;
                    runs += 1;
                    let frf = measure(|f| synth.inertance(f), output, grid, noise, seed);
                    let ctx = format!("{ty} {output} {grid:?} noise {noise}");
                    match classify(&frf, output, &ClassifyOptions::default()) {
                        Ok(c) => {
                            if let Some(m) = mismatch(&c, ty, &synth.expected()) {
                                failures.push(format!("{ctx}: {m}"));
                            }
                        }
                        Err(e) => failures.push(format!("{ctx}: {e}")),
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {runs} failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Heavy damping: an antiresonance 5 % below a resonance, both 5 %
/// damped, leaves a dip of under 3 dB; the phase rise confirms it.
#[test]
fn shallow_heavily_damped_dip_is_recognised_by_its_phase() {
    let synth = Synth {
        zeros: vec![(38.0, 0.05)],
        poles: vec![(40.0, 0.05), (80.0, 0.05)],
        nm: vec![],
    };
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 1500,
    };
    for (seed, noise) in [(201, 0.0), (202, 0.01)] {
        let frf = measure(
            |f| synth.inertance(f),
            Output::Acceleration,
            grid,
            noise,
            seed,
        );
        let c = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap();
        if let Some(m) = mismatch(&c, "ARR", &synth.expected()) {
            panic!("noise {noise}: {m}");
        }
        let dip = &c.features[0];
        assert!(
            dip.prominence_db < 3.0 && dip.phase_change_deg > 90.0,
            "{}",
            summary(&c)
        );
    }
}

/// Heavier still, noise-free: an 8 % damped antiresonance 7.5 % above a
/// 5 % damped resonance. (With 3 % noise this case is no longer reliable:
/// see the module documentation of the classifier.)
#[test]
fn heavily_damped_close_antiresonance_without_noise() {
    let synth = Synth {
        zeros: vec![(43.0, 0.08)],
        poles: vec![(40.0, 0.05), (80.0, 0.05)],
        nm: vec![],
    };
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 1500,
    };
    let frf = measure(|f| synth.inertance(f), Output::Acceleration, grid, 0.0, 1);
    let c = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap();
    if let Some(m) = mismatch(&c, "RAR", &synth.expected()) {
        panic!("{m}");
    }
}

/// A phase rise of 180 deg with a flat magnitude (`F/|F|` of a 3 % damped
/// zero factor at 50 Hz; not a physical FRF, a probe of the phase-only
/// path): an antiresonance found from the phase alone, confidence at most
/// 0.6, and the budget notes that the level does not rise as a zero would
/// make it.
#[test]
fn phase_step_without_magnitude_change_is_found_from_the_phase_alone() {
    let grid = Grid::Log {
        f0: 5.0,
        f1: 500.0,
        n: 800,
    };
    let g = |f: f64| {
        let q = quad(Complex64::new(0.0, 2.0 * PI * f), 50.0, 0.03);
        q / q.norm()
    };
    let frf = measure(g, Output::Acceleration, grid, 0.0, 1);
    let c = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap();
    assert_eq!(c.features.len(), 1, "{}", summary(&c));
    let a = &c.features[0];
    assert_eq!(a.kind, Feature::Antiresonance);
    assert!((a.freq_hz / 50.0 - 1.0).abs() < FREQ_TOL, "{}", summary(&c));
    assert!(
        a.prominence_db == 0.0 && a.confidence <= 0.6,
        "{}",
        summary(&c)
    );
    assert!(
        c.notes.contains(&ClassifyNote::PhaseOnly {
            feature: Feature::Antiresonance,
            freq_hz: a.freq_hz,
            phase_change_deg: a.phase_change_deg,
        }),
        "{}",
        summary(&c)
    );
    assert!((a.phase_change_deg - 180.0).abs() < 30.0, "{}", summary(&c));
    assert!(
        c.notes.contains(&ClassifyNote::LevelFalls),
        "{}",
        summary(&c)
    );
}

fn arar() -> Synth {
    cases().into_iter().next().unwrap().1
}

/// 130 lines over 5 .. 800 Hz (4 % apart, wider than every half-power band
/// of the 1 % and 2 % damped features): the local fit still places the
/// features within 2 %.
#[test]
fn coarse_grid() {
    let synth = arar();
    for (seed, noise) in [(11, 0.0), (12, 0.01)] {
        let grid = Grid::Log {
            f0: 5.0,
            f1: 800.0,
            n: 130,
        };
        let frf = measure(
            |f| synth.inertance(f),
            Output::Acceleration,
            grid,
            noise,
            seed,
        );
        let c = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap();
        if let Some(m) = mismatch(&c, "ARAR", &synth.expected()) {
            panic!("noise {noise}: {m}");
        }
    }
}

/// A zero at 150 Hz and a pole at 153 Hz (2 % apart, 0.5 % damping) on top
/// of an AR FRF: both are reported, capped at confidence 0.4, and kept out
/// of the type.
#[test]
fn near_pole_zero_cancellation_is_reported_with_low_confidence() {
    let synth = Synth {
        zeros: vec![(40.0, 0.01), (150.0, 0.005)],
        poles: vec![(60.0, 0.01), (153.0, 0.005)],
        nm: vec![],
    };
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 3000,
    };
    let frf = measure(|f| synth.inertance(f), Output::Velocity, grid, 0.005, 21);
    let c = classify(&frf, Output::Velocity, &ClassifyOptions::default()).unwrap();
    let main = [
        (Feature::Antiresonance, 40.0, 1),
        (Feature::Resonance, 60.0, 1),
    ];
    if let Some(m) = mismatch(&c, "AR", &main) {
        panic!("{m}");
    }
    for (kind, f) in [(Feature::Antiresonance, 150.0), (Feature::Resonance, 153.0)] {
        let hit = c
            .features
            .iter()
            .find(|x| x.kind == kind && (x.freq_hz / f - 1.0).abs() < 0.005);
        let hit = hit.unwrap_or_else(|| panic!("{kind:?} at {f} Hz missing: {}", summary(&c)));
        assert!(!hit.in_type && hit.confidence <= 0.4, "{}", summary(&c));
    }
    let pair = c.notes.iter().find_map(|n| match n {
        ClassifyNote::NearCancellation {
            first: Feature::Antiresonance,
            first_hz,
            second: Feature::Resonance,
            second_hz,
            relative_separation,
            confidence_cap,
        } => Some((*first_hz, *second_hz, *relative_separation, *confidence_cap)),
        _ => None,
    });
    let (zero, pole, apart, cap) = pair.unwrap_or_else(|| panic!("{}", summary(&c)));
    assert!((zero / 150.0 - 1.0).abs() < 0.005 && (pole / 153.0 - 1.0).abs() < 0.005);
    assert!((apart - (pole / zero - 1.0)).abs() < 1e-9 && cap == 0.4);
    // the decision to leave the pair out is itself uncertain
    assert!(c.confidence <= 0.6 + 1e-12, "{}", summary(&c));
}

/// The last resonance (200 Hz, 2 % damping) 7 % below the top of the band:
/// still found, but with a lower confidence than the interior features.
#[test]
fn feature_at_the_band_edge_has_lower_confidence() {
    let synth = arar();
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 1500,
    };
    let frf = measure(|f| synth.inertance(f), Output::Position, grid, 0.01, 31);
    let options = ClassifyOptions {
        band_hz: Some((5.0, 215.0)),
        ..Default::default()
    };
    let c = classify(&frf, Output::Position, &options).unwrap();
    if let Some(m) = mismatch(&c, "ARAR", &synth.expected()) {
        panic!("{m}");
    }
    let last = c.features.last().unwrap();
    let inner = c.features[..c.features.len() - 1]
        .iter()
        .map(|f| f.confidence)
        .fold(1.0, f64::min);
    assert!(
        last.confidence <= 0.7 && last.confidence < inner,
        "{}",
        summary(&c)
    );
    assert!(
        c.notes.contains(&ClassifyNote::AtBandEdge {
            feature: last.kind,
            freq_hz: last.freq_hz,
        }),
        "{}",
        summary(&c)
    );
    assert!(c.band_hz.1 <= 215.0);
}

/// Coherence 0.1 below 8 Hz and above 600 Hz, 0.2 within 3 % of the two
/// antiresonances, 0.97 elsewhere: the band is 8 .. 600 Hz (the less
/// certain antiresonance lines stay in it with their low weight) and the
/// type is unchanged, whether the averages are known (30) or assumed.
#[test]
fn coherence_sets_the_band_and_bridges_antiresonance_gaps() {
    let synth = arar();
    let grid = Grid::Log {
        f0: 2.0,
        f1: 1000.0,
        n: 2000,
    };
    let base = measure(|f| synth.inertance(f), Output::Acceleration, grid, 0.01, 41);
    let coherence: Vec<f64> = base
        .freq_hz()
        .iter()
        .map(|&f| {
            if !(8.0..=600.0).contains(&f) {
                0.1
            } else if (f / 30.0 - 1.0).abs() < 0.03 || (f / 120.0 - 1.0).abs() < 0.03 {
                0.2
            } else {
                0.97
            }
        })
        .collect();
    let frf = Frf::new(
        base.freq_hz().to_vec(),
        base.response().to_vec(),
        Some(coherence),
    )
    .unwrap();
    for averages in [None, Some(30)] {
        let options = ClassifyOptions {
            averages,
            ..Default::default()
        };
        let c = classify(&frf, Output::Acceleration, &options).unwrap();
        if let Some(m) = mismatch(&c, "ARAR", &synth.expected()) {
            panic!("averages {averages:?}: {m}");
        }
        // 2 lines of running-median smoothing at 0.3 % spacing
        assert!((c.band_hz.0 / 8.0 - 1.0).abs() < 0.01, "{:?}", c.band_hz);
        assert!((c.band_hz.1 / 600.0 - 1.0).abs() < 0.01, "{:?}", c.band_hz);
        assert!(
            c.notes.iter().any(|n| matches!(
                n,
                ClassifyNote::LowWeightKept { lines, max_gap_decades }
                    if *lines > 0 && *max_gap_decades == options.max_gap_decades
            )),
            "{:?}",
            c.notes
        );
    }
}

/// A measurement model: H1 estimate over 20 averages with sensor noise at
/// 2 % of the median inertance level and the shaker's excitation 26 dB down
/// below 3 Hz and above 900 Hz. The coherence is
/// `1 / (1 + (noise / (excitation |G|))^2)` (so it drops at antiresonances)
/// and each line is perturbed with the matching standard deviation
/// `sqrt((1 - C) / (2 n C))`. Returns the FRF in the output's form.
fn h1_measurement(synth: &Synth, output: Output, seed: u64) -> Frf {
    let grid = Grid::Linear {
        f0: 1.0,
        f1: 1000.0,
        n: 4000,
    };
    let freq = grid.lines();
    let averages = 20.0;
    let level: Vec<f64> = freq.iter().map(|&f| synth.inertance(f).norm()).collect();
    let mut sorted = level.clone();
    sorted.sort_by(f64::total_cmp);
    let noise = 0.02 * sorted[sorted.len() / 2];
    let mut rng = XorShift::new(seed);
    let mut coherence = Vec::new();
    let mut response = Vec::new();
    for (i, &f) in freq.iter().enumerate() {
        let excitation = if (3.0..=900.0).contains(&f) {
            1.0
        } else {
            0.05
        };
        let rel = (noise / (excitation * level[i])).min(3.0);
        let c = 1.0 / (1.0 + rel * rel);
        let sd = ((1.0 - c) / (2.0 * averages * c)).sqrt();
        let jw = Complex64::new(0.0, 2.0 * PI * f);
        let h = synth.inertance(f) / jw.powu(2 - output.s_power());
        response.push(h * Complex64::new(1.0 + sd * rng.normal(), sd * rng.normal()));
        coherence.push(c);
    }
    Frf::new(freq, response, Some(coherence)).unwrap()
}

/// The H1 measurement model above, in every output form, with the number
/// of averages known: the band starts at the bottom of the excitation band
/// (within the smoothing of the coherence), the coherence drops at the
/// antiresonances are bridged, and the type is right. For the double
/// antiresonance the response stays below the noise from 3 Hz to 66 Hz, so
/// the band starts above it: the type lacks the `A^2`, and the
/// classifier says so (a slope at the bottom of the band, confidence at
/// most 0.5).
#[test]
fn h1_measurement_with_coherence_and_averages() {
    let options = ClassifyOptions {
        averages: Some(20),
        ..Default::default()
    };
    for (ty, synth) in cases() {
        for output in Output::ALL {
            let frf = h1_measurement(&synth, output, 401);
            let c = classify(&frf, output, &options).unwrap();
            if ty == "A^2RR" {
                assert!(c.band_hz.0 > 50.0, "{}", summary(&c));
                assert!(c.confidence <= 0.5, "{}", summary(&c));
                assert!(
                    c.notes.iter().any(|n| matches!(
                        n,
                        ClassifyNote::UnflatBottom { slope, output: o, confidence_cap }
                            if slope.abs() > 1.0 && *o == output && *confidence_cap == 0.5
                    )),
                    "{}",
                    summary(&c)
                );
                continue;
            }
            if let Some(m) = mismatch(&c, ty, &synth.expected()) {
                panic!("{ty} {output}: {m}");
            }
            // 3 Hz plus two lines of coherence smoothing; above 900 Hz the
            // inertance is high enough for the coherence to stay up
            assert!(c.band_hz.0 < 3.6 && c.band_hz.1 > 899.0, "{}", summary(&c));
        }
    }
}

/// A constant inertance with 1 % noise: no features, type `C`, no nm.
#[test]
fn flat_frf_has_type_c() {
    let grid = Grid::Linear {
        f0: 1.0,
        f1: 500.0,
        n: 1000,
    };
    for output in Output::ALL {
        let frf = measure(|_| Complex64::new(0.5, 0.0), output, grid, 0.01, 51);
        let c = classify(&frf, output, &ClassifyOptions::default()).unwrap();
        assert_eq!(c.frf_type.to_string(), "C", "{}", summary(&c));
        assert!(c.features.iter().all(|f| !f.in_type));
        assert!(
            c.nonminimum_phase
                .as_ref()
                .is_none_or(|e| e.confidence < 0.5),
            "{}",
            summary(&c)
        );
    }
}

/// Coherence at most 0.4 everywhere: an error that says why.
#[test]
fn low_coherence_everywhere_is_an_error() {
    let synth = arar();
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 500,
    };
    let base = measure(|f| synth.inertance(f), Output::Acceleration, grid, 0.5, 61);
    let coherence = (0..base.len())
        .map(|i| 0.2 + 0.2 * ((i % 7) as f64 / 6.0))
        .collect();
    let frf = Frf::new(
        base.freq_hz().to_vec(),
        base.response().to_vec(),
        Some(coherence),
    )
    .unwrap();
    let err = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap_err();
    assert!(
        matches!(err, ClassifyError::NoInformativeBand { longest_run: 0, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("no informative band"), "{err}");
}

/// 100 % multiplicative noise and no coherence: refused as too noisy.
#[test]
fn very_noisy_data_without_coherence_is_an_error() {
    let synth = arar();
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 500,
    };
    let frf = measure(|f| synth.inertance(f), Output::Acceleration, grid, 1.0, 71);
    let err = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap_err();
    assert!(matches!(err, ClassifyError::TooNoisy { .. }), "{err:?}");
}

/// Six lines (plus a 0 Hz line, which never counts) are too few.
#[test]
fn too_few_lines_is_an_error() {
    let freq = vec![0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0];
    let response = vec![Complex64::new(1.0, 0.0); 7];
    let frf = Frf::new(freq, response, None).unwrap();
    let err = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap_err();
    assert_eq!(err, ClassifyError::TooFewLines { got: 6, min: 8 });
}

/// 8 to 40 lines over 5 .. 800 Hz of an ARAR FRF (lines 14 % to 90 %
/// apart), with and without 3 % noise: never a panic; either a typed
/// `TooNoisy` error (a grid this coarse scatters like noise) or a sane
/// result: confidences in [0, 1], no feature in the type below 14 lines
/// (lines 48 % apart), and a wrong type only with an overall confidence of
/// at most 0.65.
#[test]
fn few_lines_give_sane_results() {
    let synth = arar();
    for n in 8..=40 {
        for (seed, noise) in [(301, 0.0), (302, 0.03)] {
            let grid = Grid::Log {
                f0: 5.0,
                f1: 800.0,
                n,
            };
            let frf = measure(
                |f| synth.inertance(f),
                Output::Velocity,
                grid,
                noise,
                seed + n as u64,
            );
            match classify(&frf, Output::Velocity, &ClassifyOptions::default()) {
                Err(ClassifyError::TooNoisy { .. }) => {}
                Err(e) => panic!("{n} lines: {e}"),
                Ok(c) => {
                    let ctx = format!("{n} lines, noise {noise}: {}", summary(&c));
                    for f in &c.features {
                        assert!((0.0..=1.0).contains(&f.confidence), "{ctx}");
                        assert!(f.freq_hz >= c.band_hz.0 * 0.9, "{ctx}");
                        assert!(f.freq_hz <= c.band_hz.1 * 1.1, "{ctx}");
                    }
                    assert!((0.0..=1.0).contains(&c.confidence), "{ctx}");
                    if n < 14 {
                        assert_eq!(c.frf_type.to_string(), "C", "{ctx}");
                    }
                    if c.frf_type.to_string() != "ARAR" {
                        assert!(c.confidence <= 0.65, "{ctx}");
                    }
                }
            }
        }
    }
}

/// Five lines replaced by garbage (3x the value, phase turned by 2 rad) are
/// left out and do not change the type.
#[test]
fn outlier_lines_are_left_out() {
    let synth = arar();
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 1500,
    };
    let base = measure(
        |f| synth.inertance(f),
        Output::Acceleration,
        grid,
        0.005,
        81,
    );
    let mut response = base.response().to_vec();
    let bad = [100, 400, 700, 1000, 1300];
    for &i in &bad {
        response[i] *= Complex64::from_polar(3.0, 2.0);
    }
    let frf = Frf::new(base.freq_hz().to_vec(), response, None).unwrap();
    let c = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap();
    if let Some(m) = mismatch(&c, "ARAR", &synth.expected()) {
        panic!("{m}");
    }
    assert_eq!(c.lines_ignored, bad.len(), "{}", summary(&c));
    let at_hz: Vec<f64> = bad.iter().map(|&i| frf.freq_hz()[i]).collect();
    assert!(
        c.notes.contains(&ClassifyNote::OutliersLeftOut { at_hz }),
        "{}",
        summary(&c)
    );
}

/// A receptance read as an inertance keeps a slope of -2 at the bottom of
/// the band: the notes name a wrong output kind (or a feature below the
/// band) and the type's confidence is at most 0.5.
#[test]
fn wrong_output_kind_is_noted() {
    let synth = arar();
    let grid = Grid::Log {
        f0: 5.0,
        f1: 800.0,
        n: 1500,
    };
    let frf = measure(|f| synth.inertance(f), Output::Position, grid, 0.0, 91);
    let c = classify(&frf, Output::Acceleration, &ClassifyOptions::default()).unwrap();
    assert!(
        c.notes.iter().any(|n| matches!(
            n,
            ClassifyNote::UnflatBottom { slope, output: Output::Acceleration, .. }
                if (slope + 2.0).abs() < 0.5
        )),
        "{}",
        summary(&c)
    );
    assert!(c.confidence <= 0.5, "{}", summary(&c));
}

/// The public result types serialise (JSON reports of the CLI).
#[test]
fn result_types_are_serialize() {
    fn is_serialize<T: serde::Serialize>() {}
    is_serialize::<Classification>();
    is_serialize::<ClassifyOptions>();
}

/// Parameters from decimal strings, exactly.
fn params(values: &[(&str, &str)]) -> BTreeMap<String, Rat> {
    values
        .iter()
        .map(|(k, v)| (k.to_string(), v.parse().unwrap()))
        .collect()
}

/// Coefficients (ascending) of `p` in `var` after substituting `point`.
fn coefficients(p: &Poly, var: &str, point: &BTreeMap<String, Rat>) -> Vec<f64> {
    let mut q = p.clone();
    for (k, v) in point {
        q = q.subs(k, v);
    }
    q.coeffs_in(var)
        .iter()
        .map(|c| {
            c.as_constant()
                .expect("all parameters substituted")
                .to_f64()
        })
        .collect()
}

fn horner(c: &[f64], s: Complex64) -> Complex64 {
    c.iter()
        .rev()
        .fold(Complex64::new(0.0, 0.0), |acc, &a| acc * s + a)
}

/// Roots of a real polynomial of degree at most 2 (ascending coefficients).
fn roots_upto_quadratic(c: &[f64]) -> Vec<Complex64> {
    match c.len() {
        0 | 1 => vec![],
        2 => vec![Complex64::new(-c[0] / c[1], 0.0)],
        3 => {
            let disc = Complex64::new(c[1] * c[1] - 4.0 * c[2] * c[0], 0.0).sqrt();
            vec![(-c[1] + disc) / (2.0 * c[2]), (-c[1] - disc) / (2.0 * c[2])]
        }
        n => panic!("degree {} in Omega: not a 3-mass model", n - 1),
    }
}

/// The type of the undamped inertance from its roots in Omega (simple roots
/// only, as for the parameter sets used here) and the expected features.
fn undamped_type(
    model: &Model,
    point: &BTreeMap<String, Rat>,
) -> (String, Vec<(Feature, f64, u32)>) {
    let tf = model.undamped_tf();
    let mut feats = Vec::new();
    let mut nm = false;
    for (poly, kind) in [
        (&tf.num, Feature::Antiresonance),
        (&tf.den, Feature::Resonance),
    ] {
        for r in roots_upto_quadratic(&coefficients(poly, mms::OMEGA, point)) {
            if r.im.abs() > 1e-9 * r.norm() || r.re <= 0.0 {
                nm = true;
            } else {
                feats.push((kind, r.re.sqrt() / (2.0 * PI), 1));
            }
        }
    }
    feats.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut ty: String = feats
        .iter()
        .map(|f| {
            if f.0 == Feature::Antiresonance {
                'A'
            } else {
                'R'
            }
        })
        .collect();
    if nm {
        ty.push_str(" (nm)");
    }
    (ty, feats)
}

/// The paper's examples: A2 with Tab. 4 (ARR, Sec. 5), B2 with Tab. 6
/// (ARRA, Sec. 5) and B2 with the parameters of Fig. 3 (RR (nm)), damped,
/// in all three output forms, noise-free and with 1 % noise. The expected
/// type is checked against the paper and against the undamped roots; the
/// features within 2 % of the undamped root frequencies.
#[test]
fn paper_models_have_the_papers_types() {
    let sets = [
        (
            "A2",
            "ARR",
            params(&[
                ("m1", "0.01"),
                ("m2", "0.01"),
                ("m3", "0.02"),
                ("c12", "100"),
                ("c23", "100"),
                ("d12", "0.01"),
                ("d23", "0.01"),
            ]),
        ),
        (
            "B2",
            "ARRA",
            params(&[
                ("m1", "0.01"),
                ("m2", "0.01"),
                ("m3", "0.01"),
                ("c1", "100"),
                ("c23", "200"),
                ("d1", "0.01"),
                ("d23", "0.01"),
            ]),
        ),
        (
            "B2",
            "RR (nm)",
            params(&[
                ("m1", "0.01"),
                ("m2", "0.02"),
                ("m3", "0.015"),
                ("c1", "200"),
                ("c23", "100"),
                ("d1", "0.01"),
                ("d23", "0.01"),
            ]),
        ),
    ];
    let mut failures = Vec::new();
    let mut seed = 100;
    for (id, paper_type, point) in &sets {
        let model = Model::from_id(id).unwrap();
        let mut names = model.parameters();
        names.sort();
        assert_eq!(names, point.keys().cloned().collect::<Vec<_>>(), "{id}");
        let (roots_type, expected) = undamped_type(&model, point);
        assert_eq!(&roots_type, paper_type, "{id}: undamped roots {expected:?}");
        for output in Output::ALL {
            let tf = model.damped_tf(output);
            let num = coefficients(&tf.num, mms::S, point);
            let den = coefficients(&tf.den, mms::S, point);
            let h = |f: f64| {
                let s = Complex64::new(0.0, 2.0 * PI * f);
                horner(&num, s) / horner(&den, s)
            };
            for noise in [0.0, 0.01] {
                seed += 1;
                let grid = Grid::Log {
                    f0: 1.0,
                    f1: 300.0,
                    n: 2500,
                };
                let frf = noisy(h, grid, noise, seed);
                let ctx = format!("{id} {paper_type} {output} noise {noise}");
                match classify(&frf, output, &ClassifyOptions::default()) {
                    Ok(c) => {
                        if let Some(m) = mismatch(&c, paper_type, &expected) {
                            failures.push(format!("{ctx}: {m}"));
                        }
                    }
                    Err(e) => failures.push(format!("{ctx}: {e}")),
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A lightly damped resonance that falls between two lines, behind a dead
/// time: the phase falls by a little more than half a turn from one line
/// to the next, which wrapping alone reads as a rise (+132 deg before the
/// magnitude decided the sign). The magnitude peak decides: the phase
/// falls across it, by half a turn plus what the delay adds over the
/// feature's neighbourhood, as without the delay it falls by half a turn.
#[test]
fn half_turn_between_two_lines_is_read_from_the_magnitude() {
    use frf::{Complex64, Frf};
    let f: Vec<f64> = (0..61).map(|k| 20.0 + 0.5 * k as f64).collect();
    let (f0, zeta) = (35.25, 0.00005);
    let frf = |delay: f64| {
        let h: Vec<Complex64> = f
            .iter()
            .map(|&f| {
                let r = f / f0;
                let g = Complex64::new(1.0 - r * r, 2.0 * zeta * r).inv();
                g * Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * f * delay)
            })
            .collect();
        Frf::new(f.clone(), h, None).unwrap()
    };
    // The step across the resonance is -pi + 2 atan(2 zeta r / (1 - r^2))
    // - 2 pi (0.5 Hz) T: beyond -pi for T = 8 ms.
    for (delay, lo, hi) in [(0.0, -200.0, -160.0), (0.008, -260.0, -180.0)] {
        let c =
            ident::classify(&frf(delay), mms::Output::Acceleration, &Default::default()).unwrap();
        let r = c
            .features
            .iter()
            .find(|x| x.kind == mms::analysis::Feature::Resonance && (x.freq_hz - f0).abs() < 0.3)
            .unwrap_or_else(|| panic!("delay {delay}: {c:?}"));
        assert!(
            (lo..hi).contains(&r.phase_change_deg),
            "delay {delay}: {}",
            r.phase_change_deg
        );
    }
}

/// A confidence bin: its lower edge, features reported, features real.
type Bin = (f64, usize, usize);

/// How often a feature claimed at a given confidence is real: synthetic
/// recordings from `ident::synth` (2-4 masses of the paper's rule (3)
/// structures, 150 log-spaced lines, position output, 1-30 % noise per
/// line, link damping 0.5-10 %, features as close as they come), every
/// reported feature binned by its
/// confidence and matched against the generating FRF's undamped features
/// (same kind within 3 % in frequency). Returns per bin (lower edge,
/// reported, real), and the true features inside the classified band with
/// how many of them the type claims.
fn calibration(recordings: u64) -> (Vec<Bin>, (usize, usize)) {
    use ident::synth::{synthetic, SynthOptions};
    let edges = [0.2, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0001];
    let mut bins = vec![(0usize, 0usize); edges.len() - 1];
    let (mut truths, mut found) = (0, 0);
    for seed in 0..recordings {
        let mut rng = XorShift::new(5000 + seed);
        let options = SynthOptions {
            masses: 2 + (seed % 3) as usize,
            lines: 150,
            noise: 0.01 * 30f64.powf(rng.uniform()),
            damping_ratio: (0.005, 0.1),
            min_separation: 1.0,
            ..SynthOptions::default()
        };
        let Ok(s) = synthetic(&mut rng, None, &options) else {
            continue;
        };
        let Ok(c) = classify(&s.frf, s.output, &ClassifyOptions::default()) else {
            continue;
        };
        for f in &c.features {
            let Some(b) = edges
                .windows(2)
                .position(|w| f.confidence >= w[0] && f.confidence < w[1])
            else {
                continue;
            };
            let real = s
                .features
                .iter()
                .any(|(k, hz)| *k == f.kind && (f.freq_hz / hz - 1.0).abs() < 0.03);
            bins[b].0 += 1;
            bins[b].1 += real as usize;
        }
        let (lo, hi) = c.band_hz;
        for (k, hz) in s.features.iter().filter(|(_, hz)| *hz > lo && *hz < hi) {
            truths += 1;
            found += c
                .features
                .iter()
                .any(|f| f.in_type && f.kind == *k && (f.freq_hz / hz - 1.0).abs() < 0.03)
                as usize;
        }
    }
    let table = edges
        .windows(2)
        .zip(bins)
        .map(|(w, (n, r))| (w[0], n, r))
        .collect();
    (table, (truths, found))
}

/// The confidence of a claimed feature is calibrated: of the features
/// claimed (confidence at least 0.5, the type's threshold) nine in ten or
/// more are real, and of those at 0.8 or more, 95 % or more; features
/// below the threshold are real less often than those above it.
#[test]
fn feature_confidence_is_calibrated() {
    let (table, _) = calibration(60);
    let rate = |lo: f64| {
        let (n, r) = table
            .iter()
            .filter(|b| b.0 >= lo - 1e-9)
            .fold((0, 0), |(n, r), b| (n + b.1, r + b.2));
        (r as f64 / n.max(1) as f64, n)
    };
    let (claimed, n_claimed) = rate(0.5);
    let (sure, n_sure) = rate(0.8);
    let below: (usize, usize) = table
        .iter()
        .filter(|b| b.0 < 0.5)
        .fold((0, 0), |(n, r), b| (n + b.1, r + b.2));
    eprintln!("{table:?}");
    assert!(n_claimed >= 100, "{table:?}");
    assert!(claimed >= 0.9, "claimed: {claimed} of {n_claimed}");
    assert!(sure >= 0.95, "at 0.8 or more: {sure} of {n_sure}");
    if below.0 >= 10 {
        assert!((below.1 as f64 / below.0 as f64) < claimed, "{table:?}");
    }
}

/// The full calibration table of docs/identification.md (600 recordings):
/// `cargo test --release -p ident --test classify -- --ignored
/// confidence_calibration_table --nocapture`.
#[test]
#[ignore]
fn confidence_calibration_table() {
    let (table, (truths, found)) = calibration(600);
    println!("| confidence | reported | real | share real |\n|---|---:|---:|---:|");
    for (lo, n, r) in table {
        println!(
            "| {lo:.1} - | {n} | {r} | {} |",
            if n > 0 {
                format!("{:.1} %", 100.0 * r as f64 / n as f64)
            } else {
                "-".into()
            }
        );
    }
    println!(
        "true features inside the band: {truths}, claimed in the type: {found} ({:.1} %)",
        100.0 * found as f64 / truths.max(1) as f64
    );
}

/// A motor-side antiresonance as a closed-loop test bench measures it: the
/// motor barely moves there, so the five lines of the notch have little
/// coherence (relative uncertainty 0.45) and scattered phases, and one
/// step between them comes within its noise of half a turn the wrong way
/// (a fall of 155 deg where the antiresonance rises). The notch's lowest
/// line is not beside that step, so the two lines alone do not make a dip;
/// against the lines on either side of the notch they do. The type must
/// be the collocated two-mass drive's AR, with the generating chain's
/// antiresonance `sqrt(c / m2)` and resonance within 2 %.
#[test]
fn noisy_notch_of_a_motor_side_antiresonance_reads_as_one() {
    let (m1, m2, c, d) = (2.0e-4, 1.7e-4, 11.5, 2.6e-4);
    let drive = |f: f64| {
        let s = Complex64::new(0.0, 2.0 * PI * f);
        let a = m1 * s * s + d * s + c;
        let b = m2 * s * s + d * s + c;
        b / (a * b - (d * s + c) * (d * s + c))
    };
    let f: Vec<f64> = (1..=200).map(|k| 0.5 * k as f64).collect();
    let mut h: Vec<Complex64> = f.iter().map(|&f| drive(f)).collect();
    let mut sd: Vec<f64> = h.iter().map(|h| 0.02 * h.norm()).collect();
    // The notch as measured on a test bench, around the chain's
    // antiresonance (40.5 .. 42.5 Hz): dB below the line at 40.0 Hz, and
    // phases in degrees.
    let level = h[79].norm();
    let notch: [(f64, f64); 5] = [
        (-7.3, 165.4),
        (-9.2, -166.8),
        (-5.6, -176.8),
        (-7.3, 28.4),
        (-4.7, 4.1),
    ];
    for (k, (db, deg)) in (80..85).zip(notch) {
        let m = level * 10f64.powf(db / 20.0);
        h[k] = Complex64::from_polar(m, deg.to_radians());
        sd[k] = 0.45 * m;
    }
    let frf = Frf::new(f, h, None).unwrap().with_std_dev(sd).unwrap();
    let o = ClassifyOptions {
        band_hz: Some((1.0, 100.0)),
        ..Default::default()
    };
    let got = classify(&frf, Output::Position, &o).unwrap();
    let hz = |w2: f64| w2.sqrt() / (2.0 * PI);
    let (anti, res) = (hz(c / m2), hz(c * (m1 + m2) / (m1 * m2)));
    let expected = [
        (Feature::Antiresonance, anti, 1),
        (Feature::Resonance, res, 1),
    ];
    let wrong = mismatch(&got, "AR", &expected);
    assert!(wrong.is_none(), "{}", wrong.unwrap_or_default());
}
