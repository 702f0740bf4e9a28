//! The per-line standard deviation of the H1 estimate, checked against the
//! scatter of independent estimates (Monte Carlo): the predicted standard
//! deviation of one estimate must match how much estimates from independent
//! noise realisations of the same system actually differ.

use frf::csv::{parse_frf_csv, write_csv, CsvLayout};
use frf::welch::{h1, WelchOptions};
use frf::{Complex64, Frf};
use std::f64::consts::PI;

/// xorshift64 with a sum-of-twelve Gaussian: deterministic noise.
struct Noise(u64);
impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        (0..12).map(|_| self.uniform()).sum::<f64>() - 6.0
    }
}

/// A lightly damped resonance `y[n] = b0 u[n] + 1.6 y[n-1] - 0.81 y[n-2]`
/// (poles at radius 0.9).
fn resonator(u: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; u.len()];
    for n in 0..u.len() {
        let y1 = if n >= 1 { y[n - 1] } else { 0.0 };
        let y2 = if n >= 2 { y[n - 2] } else { 0.0 };
        y[n] = 0.1 * u[n] + 1.6 * y1 - 0.81 * y2;
    }
    y
}

/// Over `runs` independent records, the ratio of the measured scatter of
/// H1 at each line to the mean predicted standard deviation; the median
/// over the lines of that ratio.
fn scatter_ratio(runs: usize, record: usize, opts: &WelchOptions, periodic: bool) -> f64 {
    let mut estimates: Vec<Frf> = Vec::new();
    let mut noise = Noise(0x9e37_79b9_7f4a_7c15);
    // One period of a random-phase multisine over every line.
    let period = opts.period.unwrap_or(0);
    let multisine: Vec<f64> = if periodic {
        let phases: Vec<f64> = (0..period / 2)
            .map(|_| 2.0 * PI * noise.uniform())
            .collect();
        (0..period)
            .map(|n| {
                phases
                    .iter()
                    .enumerate()
                    .skip(1)
                    .map(|(k, p)| (2.0 * PI * (k * n) as f64 / period as f64 + p).cos())
                    .sum::<f64>()
                    / (period as f64).sqrt()
            })
            .collect()
    } else {
        Vec::new()
    };
    for _ in 0..runs {
        let u: Vec<f64> = if periodic {
            (0..record).map(|n| multisine[n % period]).collect()
        } else {
            (0..record).map(|_| noise.gauss()).collect()
        };
        let clean = resonator(&u);
        let rms = (clean.iter().map(|v| v * v).sum::<f64>() / record as f64).sqrt();
        let y: Vec<f64> = clean
            .iter()
            .map(|v| v + 0.3 * rms * noise.gauss())
            .collect();
        estimates.push(h1(&u, &y, 1.0, opts).unwrap().frf);
    }
    let lines = estimates[0].len();
    let mut ratios = Vec::new();
    for k in 1..lines {
        let mean = estimates.iter().map(|e| e.response()[k]).sum::<Complex64>() / runs as f64;
        let var = estimates
            .iter()
            .map(|e| (e.response()[k] - mean).norm_sqr())
            .sum::<f64>()
            / (runs as f64 - 1.0);
        // per real or imaginary part
        let measured = (var / 2.0).sqrt();
        let predicted = estimates
            .iter()
            .map(|e| e.std_dev().unwrap()[k])
            .sum::<f64>()
            / runs as f64;
        if predicted.is_finite() && predicted > 0.0 {
            ratios.push(measured / predicted);
        }
    }
    ratios.sort_by(f64::total_cmp);
    ratios[ratios.len() / 2]
}

#[test]
fn random_excitation_std_dev_matches_the_scatter_of_independent_estimates() {
    // 16 Hann segments at 50 % overlap: the effective averages must count
    // the overlap; a ratio near 1 (within 15 %, the sampling error of a
    // standard deviation over 200 runs and the coherence's own bias) says
    // the prediction is right.
    let opts = WelchOptions {
        nfft: Some(128),
        ..Default::default()
    };
    let r = scatter_ratio(200, 128 * 17 / 2, &opts, false);
    assert!((0.85..1.15).contains(&r), "measured / predicted = {r}");
}

#[test]
fn periodic_excitation_std_dev_matches_the_scatter_of_independent_estimates() {
    // 8 periods after the transient: the scatter over periods predicts the
    // scatter over independent records.
    let opts = WelchOptions {
        period: Some(128),
        ..Default::default()
    };
    let r = scatter_ratio(200, 128 * 9, &opts, true);
    assert!((0.85..1.15).contains(&r), "measured / predicted = {r}");
}

#[test]
fn lines_without_excitation_carry_no_information() {
    // A multisine on the even lines only: the odd lines get an infinite
    // standard deviation.
    let period = 64;
    let u: Vec<f64> = (0..period * 4)
        .map(|n| {
            (1..period / 4)
                .map(|j| (2.0 * PI * (2 * j * n) as f64 / period as f64 + j as f64).cos())
                .sum()
        })
        .collect();
    let y = resonator(&u);
    let y: Vec<f64> = y
        .iter()
        .enumerate()
        .map(|(n, v)| v + 1e-3 * ((n * 7919) % 13) as f64)
        .collect();
    let est = h1(
        &u,
        &y,
        64.0,
        &WelchOptions {
            period: Some(period),
            ..Default::default()
        },
    )
    .unwrap();
    let sd = est.frf.std_dev().unwrap();
    for (k, s) in sd.iter().enumerate() {
        let line = k + 1;
        let excited = line % 2 == 0 && line < period / 2;
        assert_eq!(s.is_finite(), excited, "line {line}: {s}");
    }
}

#[test]
fn csv_carries_the_std_dev_including_lines_without_information() {
    let f: Vec<f64> = (1..=12).map(|k| k as f64).collect();
    let h: Vec<Complex64> = f.iter().map(|&x| Complex64::new(1.0 / x, -0.5)).collect();
    let mut sd: Vec<f64> = f.iter().map(|x| 0.01 * x).collect();
    sd[3] = f64::INFINITY;
    let frf = Frf::new(f, h, None).unwrap().with_std_dev(sd).unwrap();
    let text = write_csv(&frf, CsvLayout::ReIm);
    assert!(text.starts_with("freq_hz,re,im,std_dev\n"), "{text}");
    assert_eq!(parse_frf_csv(&text).unwrap(), frf);
    // inf is a value only in the std_dev column; negative is refused with
    // its line.
    let bad = text.replacen("1e0,-5e-1", "inf,-5e-1", 1);
    let err = parse_frf_csv(&bad).unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("finite"), "{err}");
    let neg = text.replace(",1e-2\n", ",-1e-2\n");
    let err = parse_frf_csv(&neg).unwrap_err().to_string();
    assert!(
        err.contains("line 2") && err.contains("standard deviation"),
        "{err}"
    );
}
