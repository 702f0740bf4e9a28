//! The uncertainty of each line of an FRF, from whichever source there is.
//!
//! Every consumer of a measured FRF (classification, fitting, diagnosis,
//! plots) weighs a line by its *relative* standard deviation: that of
//! `ln|H|` in nepers, which is also that of the phase in radians for a
//! circular error. [`line_uncertainty`] takes it from, in this order:
//!
//! 1. the FRF's own standard deviation ([`Frf::std_dev`]: from the H1
//!    estimate, or a `std_dev` column of the file);
//! 2. its coherence `g^2` and a number of averages `n` given by the caller
//!    (or, where the caller does not know it, [`ASSUMED_AVERAGES`], the
//!    count [`crate::welch::default_nfft`] aims for, and the result says
//!    so): `sqrt((1 - g^2) / (2 n g^2))` (Bendat and Piersol);
//! 3. the data themselves: the local scatter of the second differences of
//!    `ln H` over `ln f` ([`scatter`]), a robust scale (the lower quartile
//!    of the absolute residuals over 41 lines) that curvature near
//!    resonances inflates only where it fills three quarters of the window.
//!
//! ```
//! use frf::uncertainty::{line_uncertainty, Source};
//! use frf::{Complex64, Frf};
//!
//! let f: Vec<f64> = (1..=50).map(|k| k as f64).collect();
//! let h: Vec<Complex64> = f.iter().map(|&f| Complex64::new(1.0 / (f * f), 0.0)).collect();
//! let frf = Frf::new(f, h, Some(vec![0.5; 50]))?;
//! // With 8 averages, coherence 0.5 gives sqrt(0.5 / 8) = 0.25 nepers.
//! let u = line_uncertainty(&frf, Some(8.0));
//! assert_eq!(u.source, Source::Coherence);
//! assert!((u.relative[10] - 0.25).abs() < 1e-12);
//! // Without the averages, 16 are assumed: sqrt(0.5 / 16).
//! let u = line_uncertainty(&frf, None);
//! assert_eq!(u.source, Source::CoherenceAssumedAverages);
//! assert!((u.relative[10] - (0.5f64 / 16.0).sqrt()).abs() < 1e-12);
//! // Without a coherence, the smooth curve's scatter is tiny.
//! let bare = Frf::new(frf.freq_hz().to_vec(), frf.response().to_vec(), None)?;
//! let u = line_uncertainty(&bare, None);
//! assert_eq!(u.source, Source::Scatter);
//! assert!(u.relative[10] < 1e-6);
//! # Ok::<(), frf::FrfError>(())
//! ```

use crate::Frf;
use num_complex::Complex64;
use std::f64::consts::PI;

/// The averages assumed behind a coherence whose count is not known.
pub const ASSUMED_AVERAGES: f64 = crate::welch::DEFAULT_AVERAGES as f64;

/// Half the window of the scatter estimate, in lines.
pub const SCATTER_HALF_WINDOW: usize = 20;
/// The lower quartile of `|N(0, 1)|`: rescales a lower quartile of absolute
/// residuals to a standard deviation.
const Q25_ABS_NORMAL: f64 = 0.318_639_363_964_375_5;

/// Where the uncertainty of the lines came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The FRF's own standard deviation (estimate or file).
    Given,
    /// The coherence and the number of averages.
    Coherence,
    /// The coherence and [`ASSUMED_AVERAGES`] (the count was not known).
    CoherenceAssumedAverages,
    /// The scatter of the data between neighbouring lines.
    Scatter,
}

/// The relative standard deviation of every line (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct LineUncertainty {
    /// Per line: the standard deviation of `ln|H|` in nepers and of the
    /// phase in radians; `+inf` for a line without information.
    pub relative: Vec<f64>,
    /// Where it came from.
    pub source: Source,
}

/// The uncertainty of every line of `frf`; `averages` (the effective number
/// of averages behind its coherence) is used only when the FRF has a
/// coherence but no standard deviation ([`ASSUMED_AVERAGES`] when `None`).
pub fn line_uncertainty(frf: &Frf, averages: Option<f64>) -> LineUncertainty {
    if let Some(relative) = frf.relative_std_dev() {
        return LineUncertainty {
            relative,
            source: Source::Given,
        };
    }
    if let Some(c) = frf.coherence() {
        let (n, source) = match averages.filter(|n| *n >= 1.0) {
            Some(n) => (n, Source::Coherence),
            None => (ASSUMED_AVERAGES, Source::CoherenceAssumedAverages),
        };
        return LineUncertainty {
            relative: c.iter().map(|&g| from_coherence(g, n)).collect(),
            source,
        };
    }
    let x: Vec<f64> = frf.freq_hz().iter().map(|f| f.ln()).collect();
    let mag: Vec<f64> = frf.response().iter().map(|h| h.norm().ln()).collect();
    let phase: Vec<f64> = frf.response().iter().map(|h| h.arg()).collect();
    let mut relative = scatter(&x, &mag, &phase);
    for (s, (&f, m)) in relative.iter_mut().zip(frf.freq_hz().iter().zip(&mag)) {
        if !(f > 0.0 && m.is_finite()) {
            *s = f64::INFINITY;
        }
    }
    LineUncertainty {
        relative,
        source: Source::Scatter,
    }
}

/// `sqrt((1 - g^2) / (2 n g^2))`: the relative standard deviation of an H1
/// estimate with coherence `g^2` over `n` averages (`+inf` at `g^2 = 0`).
pub fn from_coherence(coherence: f64, averages: f64) -> f64 {
    if coherence > 0.0 {
        ((1.0 - coherence) / (2.0 * averages * coherence)).sqrt()
    } else {
        f64::INFINITY
    }
}

/// `a` wrapped to `(-pi, pi]`.
fn wrap(a: f64) -> f64 {
    let b = a.rem_euclid(2.0 * PI);
    if b > PI {
        b - 2.0 * PI
    } else {
        b
    }
}

/// Second-difference residuals `(ln|H|, phase)` of every interior line
/// over `x`, scaled to the noise standard deviation of a single line (a
/// residual of independent lines with equal noise has that deviation).
/// Phase differences are wrapped, so the phase may be wrapped or not.
/// Residual `k` belongs to line `k + 1`. Lines with a non-finite `x` or
/// magnitude give non-finite residuals.
pub fn second_differences(x: &[f64], mag: &[f64], phase: &[f64]) -> Vec<(f64, f64)> {
    let n = x.len();
    (1..n.saturating_sub(1))
        .map(|i| {
            let l = (x[i + 1] - x[i]) / (x[i + 1] - x[i - 1]);
            let scale = (1.0 + l * l + (1.0 - l) * (1.0 - l)).sqrt();
            let ey = mag[i] - (l * mag[i - 1] + (1.0 - l) * mag[i + 1]);
            let ep =
                -(l * wrap(phase[i - 1] - phase[i]) + (1.0 - l) * wrap(phase[i + 1] - phase[i]));
            (ey / scale, ep / scale)
        })
        .collect()
}

/// The local robust scatter of every line of `(x, ln|H|, phase)`: the
/// lower quartile of the absolute second-difference residuals (magnitude
/// and phase together) of the lines within [`SCATTER_HALF_WINDOW`],
/// rescaled to a standard deviation. Non-finite residuals are skipped; a
/// line with none in reach gets `+inf`.
///
/// ```
/// // White noise of 0.1 nepers on a flat curve is measured as about 0.1.
/// let mut state = 7u64;
/// let mut noise = || {
///     let mut s = 0.0;
///     for _ in 0..12 {
///         state ^= state << 13; state ^= state >> 7; state ^= state << 17;
///         s += (state >> 11) as f64 / (1u64 << 53) as f64;
///     }
///     0.1 * (s - 6.0)
/// };
/// let x: Vec<f64> = (0..400).map(|i| i as f64 * 0.01).collect();
/// let mag: Vec<f64> = x.iter().map(|_| noise()).collect();
/// let phase: Vec<f64> = x.iter().map(|_| noise()).collect();
/// let s = frf::uncertainty::scatter(&x, &mag, &phase);
/// assert!((s[200] - 0.1).abs() < 0.03, "{}", s[200]);
/// ```
pub fn scatter(x: &[f64], mag: &[f64], phase: &[f64]) -> Vec<f64> {
    let n = x.len();
    let r = second_differences(x, mag, phase);
    let abs: Vec<[f64; 2]> = r.iter().map(|&(a, b)| [a.abs(), b.abs()]).collect();
    (0..n)
        .map(|i| {
            let lo = i.saturating_sub(SCATTER_HALF_WINDOW + 1).min(abs.len());
            let hi = (i + SCATTER_HALF_WINDOW).min(abs.len());
            let mut w: Vec<f64> = abs[lo..hi]
                .iter()
                .flatten()
                .copied()
                .filter(|v| v.is_finite())
                .collect();
            if w.is_empty() {
                return f64::INFINITY;
            }
            let k = ((w.len() as f64 - 1.0) * 0.25).round() as usize;
            let (_, q, _) = w.select_nth_unstable_by(k, f64::total_cmp);
            *q / Q25_ABS_NORMAL
        })
        .collect()
}

/// `frf` averaged into at most `max_lines` log-spaced bins when it has
/// more lines (else a copy): each bin's response is the mean of its lines
/// weighted by their inverse variance ([`line_uncertainty`]), at the
/// weighted mean frequency, with the standard deviation of that mean.
/// Lines at 0 Hz or without information are left out; a bin with none
/// is dropped. A feature narrower than a bin (relative width
/// `ln(f_max / f_min) / max_lines`) is smeared, so `max_lines` should
/// keep that well below the damping ratios of interest.
///
/// Work is linear in the lines: a million-line FRF can be classified and
/// fitted on its bins.
///
/// ```
/// use frf::{Complex64, Frf};
/// use frf::uncertainty::log_binned;
/// let f: Vec<f64> = (1..=100_000).map(|k| k as f64 * 0.01).collect();
/// let h: Vec<Complex64> = f.iter().map(|&x| Complex64::new(1.0 / x, 0.0)).collect();
/// let frf = Frf::new(f, h, None)?.with_std_dev(vec![1e-3; 100_000])?;
/// let b = log_binned(&frf, 1000);
/// // Below 0.9 Hz a bin is narrower than the line spacing: those hold one
/// // line each, or none.
/// assert!(b.len() <= 1000 && b.len() > 600, "{}", b.len());
/// // Averaging lines shrinks the standard deviation by the root of their count.
/// let k = b.len() - 1;
/// assert!(b.std_dev().unwrap()[k] < 1e-3 / 10.0);
/// // The response stays 1/f at the bin's frequency (to the bin's curvature).
/// let rel = (b.response()[k].re * b.freq_hz()[k] - 1.0).abs();
/// assert!(rel < 1e-4, "{rel}");
/// # Ok::<(), frf::FrfError>(())
/// ```
pub fn log_binned(frf: &Frf, max_lines: usize) -> Frf {
    let n = frf.len();
    if n <= max_lines || max_lines < 2 {
        return frf.clone();
    }
    let sigma = line_uncertainty(frf, None).relative;
    let f = frf.freq_hz();
    let h = frf.response();
    let usable =
        |k: usize| f[k] > 0.0 && sigma[k].is_finite() && sigma[k] > 0.0 && h[k].norm() > 0.0;
    let Some(first) = (0..n).find(|&k| usable(k)) else {
        return frf.clone();
    };
    let last = (0..n).rev().find(|&k| usable(k)).unwrap_or(first);
    let (lo, hi) = (f[first].ln(), f[last].ln());
    let width = ((hi - lo) / max_lines as f64).max(f64::MIN_POSITIVE);
    let (mut freq, mut resp, mut sd) = (Vec::new(), Vec::new(), Vec::new());
    let mut k = first;
    while k <= last {
        let bin = (((f[k].ln() - lo) / width) as usize).min(max_lines - 1);
        let (mut w_sum, mut fw, mut hw) = (0.0, 0.0, Complex64::new(0.0, 0.0));
        while k <= last && (((f[k].ln() - lo) / width) as usize).min(max_lines - 1) == bin {
            if usable(k) {
                // Relative variance of line k, in units of its magnitude.
                let w = 1.0 / (sigma[k] * h[k].norm()).powi(2);
                w_sum += w;
                fw += w * f[k];
                hw += h[k] * w;
            }
            k += 1;
        }
        if w_sum > 0.0 {
            freq.push(fw / w_sum);
            resp.push(hw / w_sum);
            sd.push(w_sum.sqrt().recip());
        }
    }
    Frf::new(freq, resp, None)
        .and_then(|b| b.with_std_dev(sd))
        .unwrap_or_else(|_| frf.clone())
}
