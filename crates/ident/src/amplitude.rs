//! Amplitude dependence: the same system recorded at several excitation
//! levels ([`amplitude_dependence`]). A linear system has one FRF whatever
//! the level; friction or clearance at a joint makes the modes that deform
//! the joint move in frequency and damping as the amplitude grows. This is
//! the frequency-domain route to those effects when they sit inside the
//! structure (not at the actuator, where [`crate::nonlinear`] simulates
//! them).
//!
//! Steps:
//!
//! 1. **Noise** of each level's H1 estimate from its coherence and number
//!    of averages: `var ln H = (1 - g^2) / (2 n g^2)` per real/imaginary
//!    part (for a periodic excitation the averages are the periods, and
//!    the coherence measures how the periods differ).
//! 2. **Bands**: `ln(H_level / H_ref)` against the reference (the lowest
//!    input RMS) in units of the combined noise; runs of the smoothed
//!    normalised cost above the threshold are reported as bands (the same
//!    rule as the mismatch bands of [`crate::diagnose`]).
//! 3. **Modes**: the resonance peaks of the reference (prominence at least
//!    [`AmplitudeOptions::min_prominence_db`]); at each level the peak of
//!    its own FRF nearest to the reference's (within half the distance to
//!    the neighbouring peaks: a mode may move by more than its width),
//!    fitted over three half-power half-widths either side of that
//!    level's peak (within its neighbouring dips) by a local rational
//!    model `(b0 + b1 s + b2 s^2) / (s^2 + a1 s + a0)` (Sanathanan-Koerner
//!    iterations weighted by the noise). The standard deviations of the
//!    frequency and the damping ratio come from the fit's covariance,
//!    scaled up by the reduced chi-square when the local model misses more
//!    than the noise (neighbouring modes, distortion).
//! 4. **Distortion** of periodic records ([`Distortion`]): the output at
//!    the unexcited lines just above the excitation, relative to the
//!    excited lines, at each level; its growth beyond the input's is
//!    nonlinear distortion growing with the level.
//! 5. **Reading**: a frequency shift or damping change beyond
//!    [`AmplitudeOptions::z_threshold`] standard deviations names the
//!    physics: softening with more damping is a joint that slips more as
//!    the amplitude grows (friction at an interface); softening alone a
//!    joint that loosens (clearance opening, slip); stiffening a clearance
//!    closing into contact; less damping alone Coulomb sliding (its
//!    equivalent damping falls as the amplitude grows).
//!
//! ```
//! use frf::Frf;
//! use ident::amplitude::{amplitude_dependence, AmplitudeOptions, Level, StiffnessTrend};
//! use num_complex::Complex64;
//!
//! // One mode at 10 Hz (2 % damping) at a low level, and at 9.8 Hz at a
//! // level four times higher: a softening joint. Coherence 0.999, 8
//! // averages.
//! let f: Vec<f64> = (1..400).map(|k| 5.0 + 0.025 * k as f64).collect();
//! let level = |label: &str, f0: f64, rms: f64| {
//!     let h: Vec<Complex64> = f
//!         .iter()
//!         .map(|&x| {
//!             let s = Complex64::new(0.0, x / f0);
//!             1.0 / (s * s + 0.04 * s + 1.0)
//!         })
//!         .collect();
//!     Level {
//!         label: label.into(),
//!         frf: Frf::new(f.clone(), h, Some(vec![0.999; f.len()])).unwrap(),
//!         averages: 8,
//!         input_rms: rms,
//!         distortion: None,
//!     }
//! };
//! let a = amplitude_dependence(
//!     &[level("low", 10.0, 1.0), level("high", 9.8, 4.0)],
//!     &AmplitudeOptions::default(),
//! )?;
//! let shift = &a.modes[0].shifts[0];
//! assert_eq!(shift.stiffness, StiffnessTrend::Softening);
//! assert!((shift.shift_hz + 0.2).abs() < 1e-6);
//! # Ok::<(), ident::amplitude::AmplitudeError>(())
//! ```

use crate::diagnose::{Band, DiagnoseOptions};
use frf::welch::{h1, WelchOptions};
use frf::Frf;
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::LN_10;

/// One excitation level: the H1 estimate of a recording of the system at
/// that level.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    /// A name for reports (e.g. the file).
    pub label: String,
    /// The H1 estimate, with its coherence.
    pub frf: Frf,
    /// Segments (periods) averaged in the estimate.
    pub averages: usize,
    /// RMS of the input (mean removed), in the input's units.
    pub input_rms: f64,
    /// Nonlinear distortion of a periodic record, if known.
    pub distortion: Option<Distortion>,
}

/// The output (and input) at the unexcited lines just above a periodic
/// excitation's band, where an odd nonlinearity puts its third-order
/// products: above the highest excited line `f_top`, up to `3 f_top`.
/// From the average of the periods after the first (noise averages out,
/// periodic distortion stays). A linear system leaves only noise there,
/// which does not grow relative to the excited lines as the level rises.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Distortion {
    /// Mean output power at those lines over the mean at the excited
    /// lines, dB.
    pub output_db: f64,
    /// The same for the input (a shaker's own distortion shows here).
    pub input_db: f64,
    /// How many lines were averaged.
    pub lines: usize,
}

impl Distortion {
    /// The distortion of `u`, `y` over whole periods of `period` samples
    /// (the first dropped); `None` with fewer than two periods or no
    /// unexcited line above the excitation.
    ///
    /// ```
    /// use ident::amplitude::Distortion;
    ///
    /// // Lines 1 to 4 of a 64-sample period, three periods; the output
    /// // adds a cube, whose products reach line 12.
    /// let u: Vec<f64> = (0..192)
    ///     .map(|k| {
    ///         let t = 2.0 * std::f64::consts::PI * (k % 64) as f64 / 64.0;
    ///         (1..=4).map(|l| (l as f64 * t + l as f64).cos()).sum::<f64>()
    ///     })
    ///     .collect();
    /// let linear = Distortion::of_periodic(&u, &u, 64).unwrap();
    /// let cubic: Vec<f64> = u.iter().map(|v| v + 0.01 * v * v * v).collect();
    /// let d = Distortion::of_periodic(&u, &cubic, 64).unwrap();
    /// assert_eq!(d.lines, 8); // lines 5 to 12
    /// assert!(linear.output_db < -200.0 && d.output_db > -60.0);
    /// ```
    pub fn of_periodic(u: &[f64], y: &[f64], period: usize) -> Option<Distortion> {
        let periods = u.len().min(y.len()) / period.max(1);
        if period < 8 || periods < 2 {
            return None;
        }
        let half = period / 2;
        let mut su = vec![Complex64::new(0.0, 0.0); half];
        let mut sy = su.clone();
        for p in 1..periods {
            let r = p * period..(p + 1) * period;
            let (fu, fy) = (frf::fft::fft_real(&u[r.clone()]), frf::fft::fft_real(&y[r]));
            for k in 1..half {
                su[k] += fu[k];
                sy[k] += fy[k];
            }
        }
        let pu: Vec<f64> = su.iter().map(|z| z.norm_sqr()).collect();
        let py: Vec<f64> = sy.iter().map(|z| z.norm_sqr()).collect();
        let top = pu.iter().cloned().fold(0.0, f64::max);
        if top == 0.0 {
            return None;
        }
        // Excited: within 30 dB of the strongest input line.
        let excited: Vec<bool> = pu.iter().map(|&p| p > 1e-3 * top).collect();
        let last = excited.iter().rposition(|&e| e)?;
        let mean = |v: &[f64], pick: &dyn Fn(usize) -> bool| {
            let (sum, n) = (1..half)
                .filter(|&k| pick(k))
                .fold((0.0, 0usize), |(s, n), k| (s + v[k], n + 1));
            (sum / n.max(1) as f64, n)
        };
        let above = |k: usize| k > last && k <= 3 * last && !excited[k];
        let (yo, lines) = mean(&py, &above);
        if lines == 0 {
            return None;
        }
        let (ye, _) = mean(&py, &|k| excited[k]);
        let (uo, _) = mean(&pu, &above);
        let (ue, _) = mean(&pu, &|k| excited[k]);
        let db = |a: f64, b: f64| 10.0 * (a / b).log10();
        Some(Distortion {
            output_db: db(yo, ye),
            input_db: db(uo, ue),
            lines,
        })
    }
}

impl Level {
    /// The level of a time-domain recording: its H1 estimate with `welch`
    /// and its input RMS (and, for a periodic record, its
    /// [`Distortion`]).
    ///
    /// ```
    /// use frf::WelchOptions;
    /// use ident::amplitude::Level;
    ///
    /// // Four periods of 64 samples of a three-tone input; the output is
    /// // twice the input.
    /// let u: Vec<f64> = (0..256)
    ///     .map(|k| {
    ///         let t = 2.0 * std::f64::consts::PI * (k % 64) as f64 / 64.0;
    ///         t.sin() + (3.0 * t).cos() + (5.0 * t).sin()
    ///     })
    ///     .collect();
    /// let y: Vec<f64> = u.iter().map(|v| 2.0 * v).collect();
    /// let welch = WelchOptions { period: Some(64), ..WelchOptions::default() };
    /// let level = Level::from_samples("run.csv", &u, &y, 64.0, &welch)?;
    /// assert_eq!(level.averages, 3); // the first period is dropped
    /// assert!((level.input_rms - 1.5f64.sqrt()).abs() < 1e-12);
    /// assert!((level.frf.response()[2].norm() - 2.0).abs() < 1e-12); // 3 Hz
    /// # Ok::<(), ident::amplitude::AmplitudeError>(())
    /// ```
    pub fn from_samples(
        label: &str,
        u: &[f64],
        y: &[f64],
        fs: f64,
        welch: &WelchOptions,
    ) -> Result<Level, AmplitudeError> {
        let est = h1(u, y, fs, welch)
            .map_err(|e| AmplitudeError(format!("{label}: H1 estimate: {e}")))?;
        let n = u.len().max(1) as f64;
        let mean = u.iter().sum::<f64>() / n;
        let input_rms = (u.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        Ok(Level {
            label: label.to_string(),
            frf: est.frf,
            averages: est.averages,
            input_rms,
            distortion: welch.period.and_then(|p| Distortion::of_periodic(u, y, p)),
        })
    }
}

/// Standard deviations of a difference beyond which a mode's frequency or
/// damping has changed (the default of [`AmplitudeOptions::z_threshold`],
/// and the threshold of [`crate::operating`]).
pub const Z_THRESHOLD: f64 = 3.0;

/// Options of [`amplitude_dependence`].
#[derive(Clone, Debug, PartialEq)]
pub struct AmplitudeOptions {
    /// Only these lines (Hz, inclusive); `None`: from the first to the last
    /// line where every level's coherence reaches `min_coherence`.
    pub band_hz: Option<(f64, f64)>,
    /// Lines with a lower coherence at any level are left out of the
    /// default band's edges and of the peak search.
    pub min_coherence: f64,
    /// A change counts when it exceeds this many standard deviations.
    pub z_threshold: f64,
    /// A resonance peak must stand this far above the lower of the dips
    /// that separate it from higher peaks (dB).
    pub min_prominence_db: f64,
}

impl Default for AmplitudeOptions {
    fn default() -> AmplitudeOptions {
        AmplitudeOptions {
            band_hz: None,
            min_coherence: 0.5,
            z_threshold: Z_THRESHOLD,
            min_prominence_db: 3.0,
        }
    }
}

/// Why the comparison cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct AmplitudeError(pub String);

/// A level as reported, in order of input RMS.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelSummary {
    /// Its label.
    pub label: String,
    /// Input RMS.
    pub input_rms: f64,
    /// Input RMS over the reference's (the first level's).
    pub ratio: f64,
    /// Averages behind its coherence.
    pub averages: usize,
    /// Median standard deviation of `20 log10 |H|` over the band's lines
    /// (dB), from the coherence.
    pub noise_db: f64,
    /// RMS of `20 log10 |H / H_ref|` over the band (0 for the reference).
    pub change_db: f64,
    /// RMS of the phase difference to the reference over the band (deg).
    pub change_deg: f64,
    /// Mean of `|ln(H / H_ref)|^2 / (2 sigma^2)` over the band: 1 for
    /// noise alone (0 for the reference).
    pub cost: f64,
    /// Bands where the FRF differs from the reference's beyond the noise.
    pub bands: Vec<Band>,
    /// Its nonlinear distortion, for a periodic record.
    pub distortion: Option<Distortion>,
}

/// A mode's local fit at one level.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ModeEstimate {
    /// Undamped natural frequency, Hz.
    pub f_hz: f64,
    /// Its standard deviation, Hz.
    pub f_sigma_hz: f64,
    /// Damping ratio.
    pub damping: f64,
    /// Its standard deviation.
    pub damping_sigma: f64,
    /// `20 log10 |H|` at the peak line of the level's estimate (dB).
    pub peak_db: f64,
}

/// How a mode's frequency moves with the level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StiffnessTrend {
    /// Within the noise.
    None,
    /// Lower frequency at the higher level.
    Softening,
    /// Higher frequency at the higher level.
    Stiffening,
}

/// How a mode's damping moves with the level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DampingTrend {
    /// Within the noise.
    None,
    /// More damping at the higher level.
    Increase,
    /// Less damping at the higher level.
    Decrease,
}

/// A mode at a higher level against the reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Shift {
    /// The higher level's label.
    pub level: String,
    /// `f_level - f_ref`, Hz.
    pub shift_hz: f64,
    /// `shift_hz / f_ref`.
    pub shift_rel: f64,
    /// `shift_hz` over its standard deviation (both levels' combined).
    pub shift_z: f64,
    /// `damping_level - damping_ref` (damping ratio).
    pub damping_change: f64,
    /// `damping_change` over its standard deviation.
    pub damping_z: f64,
    /// Change of the peak magnitude, dB.
    pub peak_db_change: f64,
    /// The frequency's trend.
    pub stiffness: StiffnessTrend,
    /// The damping's trend.
    pub damping_trend: DampingTrend,
}

/// One resonance of the reference, tracked over the levels.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModeShift {
    /// The reference's natural frequency, Hz.
    pub f_ref_hz: f64,
    /// The lines of the reference's local fit, Hz.
    pub window_hz: (f64, f64),
    /// Its fit at each level, in the order of [`AmplitudeDependence::levels`].
    pub estimates: Vec<ModeEstimate>,
    /// Each higher level against the reference.
    pub shifts: Vec<Shift>,
}

/// The result of [`amplitude_dependence`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AmplitudeDependence {
    /// The levels, in order of input RMS; the first is the reference.
    pub levels: Vec<LevelSummary>,
    /// The compared lines, Hz.
    pub band_hz: (f64, f64),
    /// The reference's resonances, in frequency order.
    pub modes: Vec<ModeShift>,
    /// Resonance peaks whose local fit failed at some level (Hz).
    pub unfitted_hz: Vec<f64>,
    /// The modes (indices into `modes`) whose frequency or damping changes
    /// beyond the noise at the highest level, the most significant change
    /// (frequency and damping z-scores together) first.
    pub changed: Vec<usize>,
    /// For periodic records: the output's distortion at unexcited lines
    /// grows with the level by more than 6 dB beyond the input's own.
    pub distortion_grows: Option<bool>,
}

/// Per-part variance of `ln H` per line from the coherence, with a floor
/// (a perfectly coherent line still has rounding and quantisation).
fn log_variance(frf: &Frf, averages: usize) -> Vec<f64> {
    let n = averages.max(1) as f64;
    match frf.coherence() {
        Some(c) => c
            .iter()
            .map(|&g| {
                let g = g.clamp(1e-6, 1.0);
                ((1.0 - g) / (2.0 * n * g)).max(1e-10)
            })
            .collect(),
        None => vec![1e-10; frf.len()],
    }
}

/// The amplitude dependence of `levels` (at least two, on the same lines);
/// see the module documentation.
pub fn amplitude_dependence(
    levels: &[Level],
    o: &AmplitudeOptions,
) -> Result<AmplitudeDependence, AmplitudeError> {
    let bad = |s: String| Err(AmplitudeError(s));
    if levels.len() < 2 {
        return bad(format!(
            "{} level(s): the amplitude dependence needs at least two",
            levels.len()
        ));
    }
    if !(o.z_threshold > 0.0 && o.min_prominence_db >= 0.0) {
        return bad("the threshold must be positive, the prominence non-negative".into());
    }
    let mut order: Vec<usize> = (0..levels.len()).collect();
    order.sort_by(|&a, &b| levels[a].input_rms.total_cmp(&levels[b].input_rms));
    let levels: Vec<&Level> = order.iter().map(|&i| &levels[i]).collect();
    let reference = levels[0];
    for l in &levels {
        if l.frf.freq_hz() != reference.frf.freq_hz() {
            return bad(format!(
                "{}: its {} lines differ from the {} of {}: estimate every level with the same \
                 segment length or period",
                l.label,
                l.frf.len(),
                reference.frf.len(),
                reference.label
            ));
        }
        if l.averages < 2 {
            return bad(format!(
                "{}: one average gives no noise estimate (use a shorter segment or more periods)",
                l.label
            ));
        }
        if !(l.input_rms.is_finite() && l.input_rms > 0.0) {
            return bad(format!(
                "{}: input RMS {} is not positive",
                l.label, l.input_rms
            ));
        }
    }
    if reference.input_rms == levels[levels.len() - 1].input_rms {
        return bad("all levels have the same input RMS: nothing to compare".into());
    }
    let freq = reference.frf.freq_hz();
    let var: Vec<Vec<f64>> = levels
        .iter()
        .map(|l| log_variance(&l.frf, l.averages))
        .collect();
    // The band: the user's, else where every level is coherent.
    let coherent = |k: usize| {
        levels
            .iter()
            .all(|l| l.frf.coherence().is_none_or(|c| c[k] >= o.min_coherence))
    };
    let (lo, hi) = match o.band_hz {
        Some(b) => b,
        None => {
            let first = (0..freq.len()).find(|&k| coherent(k));
            let last = (0..freq.len()).rfind(|&k| coherent(k));
            match (first, last) {
                (Some(a), Some(b)) => (freq[a], freq[b]),
                _ => {
                    return bad(format!(
                        "no line has a coherence of at least {} at every level",
                        o.min_coherence
                    ))
                }
            }
        }
    };
    // Lines with a zero response at some level have no log ratio.
    let lines: Vec<usize> = (0..freq.len())
        .filter(|&k| freq[k] >= lo && freq[k] <= hi && freq[k] > 0.0)
        .filter(|&k| levels.iter().all(|l| l.frf.response()[k].norm() > 0.0))
        .collect();
    if lines.len() < 9 {
        return bad(format!(
            "{} lines in the band {lo}..{hi} Hz: at least 9 are needed",
            lines.len()
        ));
    }
    let f: Vec<f64> = lines.iter().map(|&k| freq[k]).collect();

    // Each level against the reference, line by line.
    let band_options = DiagnoseOptions::default();
    let mut summaries = Vec::new();
    for (i, l) in levels.iter().enumerate() {
        let sd_db: Vec<f64> = lines
            .iter()
            .map(|&k| var[i][k].sqrt() * 20.0 / LN_10)
            .collect();
        let mut summary = LevelSummary {
            label: l.label.clone(),
            input_rms: l.input_rms,
            ratio: l.input_rms / reference.input_rms,
            averages: l.averages,
            noise_db: median(&sd_db),
            change_db: 0.0,
            change_deg: 0.0,
            cost: 0.0,
            bands: Vec::new(),
            distortion: l.distortion,
        };
        if i > 0 {
            let e: Vec<Complex64> = lines
                .iter()
                .map(|&k| (l.frf.response()[k] / reference.frf.response()[k]).ln())
                .collect();
            let sigma: Vec<f64> = lines
                .iter()
                .map(|&k| (var[i][k] + var[0][k]).sqrt())
                .collect();
            let c = e.len() as f64;
            summary.change_db =
                (e.iter().map(|z| z.re * z.re).sum::<f64>() / c).sqrt() * 20.0 / LN_10;
            summary.change_deg = (e.iter().map(|z| z.im * z.im).sum::<f64>() / c)
                .sqrt()
                .to_degrees();
            summary.cost = e
                .iter()
                .zip(&sigma)
                .map(|(z, s)| z.norm_sqr() / (2.0 * s * s))
                .sum::<f64>()
                / c;
            summary.bands = crate::diagnose::bands(&f, &e, &sigma, &band_options);
        }
        summaries.push(summary);
    }

    // Resonances of each level (the reference's are the modes tracked).
    let usable: Vec<bool> = lines.iter().map(|&k| coherent(k)).collect();
    let responses: Vec<Vec<Complex64>> = levels
        .iter()
        .map(|l| lines.iter().map(|&k| l.frf.response()[k]).collect())
        .collect();
    let level_peaks: Vec<Vec<usize>> = (0..levels.len())
        .map(|i| {
            let sd_db: Vec<f64> = lines
                .iter()
                .map(|&k| var[i][k].sqrt() * 20.0 / LN_10)
                .collect();
            peaks(&responses[i], &sd_db, &usable, o.min_prominence_db)
        })
        .collect();
    let reference_peaks = &level_peaks[0];
    let mut modes = Vec::new();
    let mut unfitted_hz = Vec::new();
    for (j, &p) in reference_peaks.iter().enumerate() {
        // A level's resonance is its peak nearest to the reference's,
        // within half the distance to the reference's neighbouring peaks
        // (a mode may move out of the reference's window).
        let from = if j == 0 {
            0
        } else {
            (reference_peaks[j - 1] + p).div_ceil(2)
        };
        let to = match reference_peaks.get(j + 1) {
            Some(&q) => (p + q) / 2,
            None => f.len() - 1,
        };
        let mut estimates = Vec::new();
        let mut window_hz = (f[0], f[0]);
        for (i, own) in level_peaks.iter().enumerate() {
            let Some(k) = own
                .iter()
                .enumerate()
                .filter(|(_, &q)| q >= from && q <= to)
                .min_by_key(|(_, &q)| q.abs_diff(p))
                .map(|(n, _)| n)
            else {
                break;
            };
            let (a, b) = window(&responses[i], own, k);
            let h = &responses[i][a..=b];
            let s: Vec<f64> = lines[a..=b].iter().map(|&l| var[i][l].sqrt()).collect();
            match local_mode(&f[a..=b], h, &s, f[own[k]]) {
                Some(e) => estimates.push(e),
                None => break,
            }
            if i == 0 {
                window_hz = (f[a], f[b]);
            }
        }
        if estimates.len() < levels.len() {
            unfitted_hz.push(f[p]);
            continue;
        }
        let r = estimates[0];
        let shifts = levels
            .iter()
            .zip(&estimates)
            .skip(1)
            .map(|(l, e)| shift(&l.label, &r, e, o.z_threshold))
            .collect();
        modes.push(ModeShift {
            f_ref_hz: r.f_hz,
            window_hz,
            estimates,
            shifts,
        });
    }
    let (changed, distortion_grows) = verdict(&summaries, &modes);
    Ok(AmplitudeDependence {
        levels: summaries,
        band_hz: (f[0], f[f.len() - 1]),
        modes,
        unfitted_hz,
        changed,
        distortion_grows,
    })
}

/// The lines of the local fit of peak `peaks[j]` of `h`: three half-power
/// half-widths either side of the peak (at least 5 lines), but not beyond
/// the lowest lines separating it from its neighbouring peaks; at least 9
/// lines (five unknowns and some redundancy). Far from the peak the
/// neighbours' tails and the antiresonances dominate, which the local
/// model describes only roughly.
pub(crate) fn window(h: &[Complex64], peaks: &[usize], j: usize) -> (usize, usize) {
    let n = h.len();
    let p = peaks[j];
    let dip = |a: usize, b: usize| {
        (a..=b)
            .min_by(|&x, &y| h[x].norm().total_cmp(&h[y].norm()))
            .unwrap_or(a)
    };
    let lo = if j == 0 { 0 } else { dip(peaks[j - 1], p) };
    let hi = match peaks.get(j + 1) {
        Some(&q) => dip(p, q),
        None => n - 1,
    };
    let half_power = h[p].norm() / std::f64::consts::SQRT_2;
    let left = (lo..p)
        .rev()
        .find(|&k| h[k].norm() < half_power)
        .unwrap_or(lo);
    let right = (p + 1..=hi)
        .find(|&k| h[k].norm() < half_power)
        .unwrap_or(hi);
    let half = (3 * (p - left).max(right - p)).max(5);
    let mut a = p.saturating_sub(half).max(lo);
    let mut b = (p + half).min(hi);
    while b - a + 1 < 9 && (a > 0 || b + 1 < n) {
        a = a.saturating_sub(1);
        b = (b + 1).min(n - 1);
    }
    (a, b)
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        f64::NAN
    } else {
        s[s.len() / 2]
    }
}

/// Resonance peaks of `|h|`: interior local maxima on usable lines whose
/// topographic prominence (height above the higher of the lowest points
/// on either side before a higher line) is at least `min_db` and six
/// noise standard deviations.
fn peaks(h: &[Complex64], sd_db: &[f64], usable: &[bool], min_db: f64) -> Vec<usize> {
    let db: Vec<f64> = h.iter().map(|z| 20.0 * z.norm().log10()).collect();
    let n = db.len();
    (1..n.saturating_sub(1))
        .filter(|&k| usable[k] && db[k] > db[k - 1] && db[k] >= db[k + 1])
        .filter(|&k| {
            let mut left = db[k];
            for j in (0..k).rev() {
                if db[j] > db[k] {
                    break;
                }
                left = left.min(db[j]);
            }
            let mut right = db[k];
            for &v in &db[k + 1..] {
                if v > db[k] {
                    break;
                }
                right = right.min(v);
            }
            let prominence = db[k] - left.max(right);
            prominence >= min_db.max(6.0 * sd_db[k])
        })
        .collect()
}

/// The local rational fit `(b0 + b1 s + b2 s^2) / (s^2 + a1 s + a0)` in
/// `s = j f / f_p` on the lines `f` (noise `sigma` per part of `ln H`):
/// Sanathanan-Koerner iterations, each a linear least-squares problem
/// weighted by the previous denominator and the noise. `None` if the fit
/// gives no lightly damped resonance inside the lines.
pub(crate) fn local_mode(
    f: &[f64],
    h: &[Complex64],
    sigma: &[f64],
    f_peak: f64,
) -> Option<ModeEstimate> {
    let s: Vec<Complex64> = f.iter().map(|&x| Complex64::new(0.0, x / f_peak)).collect();
    // Start: the resonance at the peak with 2 % damping.
    let mut den: Vec<Complex64> = s.iter().map(|&s| s * s + 0.04 * s + 1.0).collect();
    let mut theta = [0.0; 5];
    let mut cov = [0.0; 25];
    for _ in 0..30 {
        // Rows: real and imaginary parts of (H D - N) w, with the unknowns
        // a0, a1, b0, b1, b2; the known H s^2 w on the right.
        let mut rows: Vec<[f64; 5]> = Vec::with_capacity(2 * f.len());
        let mut rhs = Vec::with_capacity(2 * f.len());
        for k in 0..f.len() {
            let w = 1.0 / (den[k].norm() * h[k].norm() * sigma[k]);
            let cols = [
                h[k] * w,
                h[k] * s[k] * w,
                Complex64::new(-w, 0.0),
                -s[k] * w,
                -s[k] * s[k] * w,
            ];
            let r = -h[k] * s[k] * s[k] * w;
            rows.push(cols.map(|c| c.re));
            rhs.push(r.re);
            rows.push(cols.map(|c| c.im));
            rhs.push(r.im);
        }
        let (t, c) = least_squares(&rows, &rhs)?;
        let change = (t[0] - theta[0]).abs() + (t[1] - theta[1]).abs();
        theta = t;
        cov = c;
        den = s.iter().map(|&s| s * s + theta[1] * s + theta[0]).collect();
        if change < 1e-12 {
            break;
        }
    }
    let (a0, a1) = (theta[0], theta[1]);
    if !(a0 > 0.0 && a1 > 0.0) {
        return None;
    }
    let f_hz = f_peak * a0.sqrt();
    let damping = a1 / (2.0 * a0.sqrt());
    if !(f_hz >= f[0] && f_hz <= f[f.len() - 1] && damping < 0.5) {
        return None;
    }
    // Delta method on f = f_p sqrt(a0) and zeta = a1 / (2 sqrt(a0)).
    let var = |g: [f64; 2]| {
        (g[0] * g[0] * cov[0] + 2.0 * g[0] * g[1] * cov[1] + g[1] * g[1] * cov[6]).max(0.0)
    };
    let f_sigma_hz = var([f_peak / (2.0 * a0.sqrt()), 0.0]).sqrt();
    let damping_sigma = var([-a1 / (4.0 * a0.powf(1.5)), 1.0 / (2.0 * a0.sqrt())]).sqrt();
    let peak_db = h
        .iter()
        .map(|z| 20.0 * z.norm().log10())
        .fold(f64::NEG_INFINITY, f64::max);
    Some(ModeEstimate {
        f_hz,
        f_sigma_hz,
        damping,
        damping_sigma,
        peak_db,
    })
}

/// Least squares of `rows x = rhs` (five unknowns) by Householder QR on
/// unit-norm columns; returns `x` and its covariance `(A^T A)^-1` scaled
/// by the reduced chi-square when above 1 (the residual is in noise
/// units, so a larger one means the model misses more than the noise).
// Row and column indices of a small dense matrix read better as indices.
#[allow(clippy::needless_range_loop)]
fn least_squares(rows: &[[f64; 5]], rhs: &[f64]) -> Option<([f64; 5], [f64; 25])> {
    const P: usize = 5;
    let m = rows.len();
    if m <= P {
        return None;
    }
    let mut scale = [0.0; P];
    for (j, sc) in scale.iter_mut().enumerate() {
        *sc = rows.iter().map(|r| r[j] * r[j]).sum::<f64>().sqrt();
        if !(*sc > 0.0 && sc.is_finite()) {
            return None;
        }
    }
    let mut a: Vec<[f64; P]> = rows
        .iter()
        .map(|r| std::array::from_fn(|j| r[j] / scale[j]))
        .collect();
    let mut b = rhs.to_vec();
    for j in 0..P {
        let norm = (j..m).map(|i| a[i][j] * a[i][j]).sum::<f64>().sqrt();
        if norm == 0.0 {
            return None;
        }
        let alpha = if a[j][j] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (j..m).map(|i| a[i][j]).collect();
        v[0] -= alpha;
        let vv = v.iter().map(|x| x * x).sum::<f64>();
        if vv == 0.0 {
            continue;
        }
        for c in j..P {
            let d = (j..m).map(|i| v[i - j] * a[i][c]).sum::<f64>() * 2.0 / vv;
            for i in j..m {
                a[i][c] -= d * v[i - j];
            }
        }
        let d = (j..m).map(|i| v[i - j] * b[i]).sum::<f64>() * 2.0 / vv;
        for i in j..m {
            b[i] -= d * v[i - j];
        }
    }
    // R is the upper triangle of a; the residual is b[P..].
    let mut rinv = [[0.0; P]; P];
    for i in (0..P).rev() {
        if a[i][i].abs() < 1e-13 {
            return None;
        }
        rinv[i][i] = 1.0 / a[i][i];
        for j in i + 1..P {
            let s: f64 = (i + 1..=j).map(|k| a[i][k] * rinv[k][j]).sum();
            rinv[i][j] = -s / a[i][i];
        }
    }
    let mut x = [0.0; P];
    for i in 0..P {
        x[i] = (i..P).map(|k| rinv[i][k] * b[k]).sum::<f64>() / scale[i];
    }
    let chi2 = b[P..].iter().map(|v| v * v).sum::<f64>() / (m - P) as f64;
    let inflate = chi2.max(1.0);
    let mut cov = [0.0; P * P];
    for i in 0..P {
        for j in 0..P {
            let s: f64 = (i.max(j)..P).map(|k| rinv[i][k] * rinv[j][k]).sum();
            cov[i * P + j] = s * inflate / (scale[i] * scale[j]);
        }
    }
    Some((x, cov))
}

/// A difference of two estimates in standard deviations of the
/// difference, from their standard deviations `sd_a` and `sd_b`.
pub(crate) fn z_score(difference: f64, sd_a: f64, sd_b: f64) -> f64 {
    difference / sd_a.hypot(sd_b).max(f64::MIN_POSITIVE)
}

/// A mode at a higher level against the reference, and what it names.
fn shift(label: &str, r: &ModeEstimate, e: &ModeEstimate, z: f64) -> Shift {
    let shift_hz = e.f_hz - r.f_hz;
    let shift_z = z_score(shift_hz, e.f_sigma_hz, r.f_sigma_hz);
    let damping_change = e.damping - r.damping;
    let damping_z = z_score(damping_change, e.damping_sigma, r.damping_sigma);
    let stiffness = if shift_z <= -z {
        StiffnessTrend::Softening
    } else if shift_z >= z {
        StiffnessTrend::Stiffening
    } else {
        StiffnessTrend::None
    };
    let damping_trend = if damping_z >= z {
        DampingTrend::Increase
    } else if damping_z <= -z {
        DampingTrend::Decrease
    } else {
        DampingTrend::None
    };
    Shift {
        level: label.to_string(),
        shift_hz,
        shift_rel: shift_hz / r.f_hz,
        shift_z,
        damping_change,
        damping_z,
        peak_db_change: e.peak_db - r.peak_db,
        stiffness,
        damping_trend,
    }
}

/// The summary: the changing modes at the highest level, the most
/// significant change (frequency and damping together) first, and whether
/// the distortion grows with the level if the records are periodic.
fn verdict(levels: &[LevelSummary], modes: &[ModeShift]) -> (Vec<usize>, Option<bool>) {
    let top = &levels[levels.len() - 1];
    let strength = |s: &Shift| s.shift_z.hypot(s.damping_z);
    let mut changed: Vec<(usize, f64)> = modes
        .iter()
        .enumerate()
        .filter_map(|(i, m)| m.shifts.last().map(|s| (i, s)))
        .filter(|(_, s)| {
            s.stiffness != StiffnessTrend::None || s.damping_trend != DampingTrend::None
        })
        .map(|(i, s)| (i, strength(s)))
        .collect();
    changed.sort_by(|a, b| b.1.total_cmp(&a.1));
    // A linear system's unexcited lines hold noise, which falls relative
    // to the excited lines as the level rises; growth there beyond the
    // input's own is the output's nonlinearity.
    let grows = match (levels[0].distortion, top.distortion) {
        (Some(a), Some(b)) => {
            Some(b.output_db - a.output_db - (b.input_db - a.input_db).max(0.0) > 6.0)
        }
        _ => None,
    };
    (changed.into_iter().map(|(i, _)| i).collect(), grows)
}
