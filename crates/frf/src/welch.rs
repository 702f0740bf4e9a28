//! H1 frequency response estimation with Welch averaging.
//!
//! From a sampled input `u` and output `y` at rate `fs`, the record is cut
//! into segments of `nfft` samples; each segment is detrended, windowed and
//! transformed; the auto and cross spectra are averaged over the segments:
//!
//! ```text
//! S_uu = mean |U|^2,  S_yy = mean |Y|^2,  S_uy = mean conj(U) Y
//! H1 = S_uy / S_uu,   coherence = |S_uy|^2 / (S_uu S_yy)
//! ```
//!
//! The lines are `k fs / nfft` for `k = 1 ..= nfft / 2` (DC is dropped: it
//! carries the offsets and drift that detrending removes). H1 is unbiased
//! by noise on the output; the coherence tells how much of the output is
//! explained linearly by the input at each line.
//!
//! Every line also gets a standard deviation ([`Frf::std_dev`]):
//! * random excitation: the classic `var|H1| = (1 - g^2) / (2 n g^2) |H|^2`
//!   (Bendat and Piersol) with `g^2` the coherence and `n` the *effective*
//!   number of averages, which counts overlapping segments for less by the
//!   window's own overlap correlation (Welch): Hann at 50 % gives about
//!   `n / 1.06` for long records;
//! * periodic excitation: the scatter of the per-period spectra `U_p`,
//!   `Y_p` about their means, carried to the ratio of the means (at
//!   least two periods after the transient; with one, the standard
//!   deviation is left out and users estimate it from the data);
//! * a line without input power (below `1e-12` of the strongest line, such
//!   as the unexcited lines of a multisine, or, periodic, a mean input
//!   within three of its standard deviations of zero) gets `+inf`: it
//!   carries no information and is no part of any band.
//!
//! Two modes:
//! * random excitation (default): Hann window, 50 % overlap, linear
//!   detrending of each segment (recordings drift, e.g. a position under
//!   constant velocity), `nfft` from [`default_nfft`] unless given;
//! * periodic excitation ([`WelchOptions::period`]): one segment per
//!   period, rectangular window, no overlap, the first period dropped as
//!   the transient; with a steady-state periodic input this is leakage
//!   free, and the FRF is the ratio of the period-averaged output and
//!   input spectra, exact up to noise, which averaging reduces on the
//!   input as on the output (H1 would keep the input noise's bias). A drift common to the periods (the
//!   position of an axis that turns at a constant speed: a ramp under the
//!   periodic motion) is taken out first, its slope from the change of
//!   the period means, which a periodic signal does not have; the mean of
//!   one period would leave the ramp as a sawtooth leaking into every
//!   line.
//!
//! ```
//! use frf::welch::{h1, WelchOptions};
//!
//! // y[n] = 0.5 u[n-1]: H(f) = 0.5 exp(-2 pi i f / fs).
//! let fs = 100.0;
//! let mut state = 12345u64;
//! let u: Vec<f64> = (0..4096)
//!     .map(|_| {
//!         state ^= state << 13;
//!         state ^= state >> 7;
//!         state ^= state << 17;
//!         (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
//!     })
//!     .collect();
//! let y: Vec<f64> = (0..u.len()).map(|n| if n > 0 { 0.5 * u[n - 1] } else { 0.0 }).collect();
//! let est = h1(&u, &y, fs, &WelchOptions { nfft: Some(256), ..Default::default() })?;
//! assert_eq!(est.nfft, 256);
//! assert_eq!(est.frf.len(), 128);
//! let (f, h) = (est.frf.freq_hz()[9], est.frf.response()[9]);
//! let exact = frf::Complex64::from_polar(0.5, -2.0 * std::f64::consts::PI * f / fs);
//! assert!((h - exact).norm() < 0.02);
//! # Ok::<(), frf::welch::WelchError>(())
//! ```

use crate::fft::FftPlan;
use crate::{Frf, FrfError};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Smallest `nfft` that [`default_nfft`] picks when the record allows it.
pub const MIN_DEFAULT_NFFT: usize = 64;
/// Largest `nfft` that [`default_nfft`] picks.
pub const MAX_DEFAULT_NFFT: usize = 65536;
/// Number of averages [`default_nfft`] aims for. It balances the variance
/// of a line against the resolution: with 16 averages a line of coherence
/// 0.5 is known to 1.6 dB (`sqrt(0.5 / 32)` nepers), enough to measure a
/// lightly damped antiresonance where a collocated sensor sees little
/// motion, while a 10 s record still resolves 1 Hz. A record too short for
/// it gets fewer.
pub const DEFAULT_AVERAGES: usize = 16;

/// Segment window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Window {
    /// Periodic Hann window `sin^2(pi n / nfft)`: low leakage for random
    /// excitation. Default overlap 50 %.
    #[default]
    Hann,
    /// No window: for periodic excitation with one period per segment.
    /// Default overlap 0.
    Rectangular,
}

impl Window {
    /// The overlap used when [`WelchOptions::overlap`] is `None`.
    pub fn default_overlap(self) -> f64 {
        match self {
            Window::Hann => 0.5,
            Window::Rectangular => 0.0,
        }
    }

    fn weights(self, n: usize) -> Vec<f64> {
        match self {
            Window::Hann => (0..n)
                .map(|i| (PI * i as f64 / n as f64).sin().powi(2))
                .collect(),
            Window::Rectangular => vec![1.0; n],
        }
    }
}

/// What is removed from each segment before windowing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Detrend {
    /// Nothing.
    None,
    /// The mean.
    Mean,
    /// The least-squares straight line (mean and slope).
    Linear,
}

/// Options of [`h1`]. `Default` gives Hann, 50 % overlap, linear
/// detrending and [`default_nfft`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WelchOptions {
    /// Segment length; `None` for [`default_nfft`]. Any length >= 2 (not
    /// only powers of two).
    pub nfft: Option<usize>,
    /// Segment window (ignored with `period`: rectangular).
    pub window: Window,
    /// Overlap of consecutive segments as a fraction in `[0, 1)`; `None`
    /// for the window's [`Window::default_overlap`].
    pub overlap: Option<f64>,
    /// Per-segment detrending; `None` for [`Detrend::Linear`], or
    /// [`Detrend::Mean`] with `period` (a straight line fitted to one period
    /// of a periodic signal is not zero and would leak into every line).
    pub detrend: Option<Detrend>,
    /// Samples per period of a periodic excitation: then `nfft = period`,
    /// rectangular window, no overlap, and the first period is dropped as
    /// the transient (so at least two periods are needed). `nfft`, if
    /// given, must equal it, and `overlap`, if given, must be 0.
    pub period: Option<usize>,
}

/// Result of [`h1`].
#[derive(Clone, Debug, PartialEq)]
pub struct H1Estimate {
    /// The H1 estimate with its coherence, lines `k fs / nfft`,
    /// `k = 1 ..= nfft / 2`.
    pub frf: Frf,
    /// Number of segments averaged.
    pub averages: usize,
    /// Segment length.
    pub nfft: usize,
    /// Window used.
    pub window: Window,
    /// Overlap used, as a fraction.
    pub overlap: f64,
    /// Detrending used.
    pub detrend: Detrend,
    /// The effective number of independent averages behind the standard
    /// deviation (fewer than `averages` when segments overlap).
    pub effective_averages: f64,
}

/// Input power below this fraction of the strongest line is no excitation.
const NO_EXCITATION: f64 = 1e-12;

/// The effective number of independent averages of `count` segments of
/// window `w` advancing by `step` (Welch 1967): the variance of an averaged
/// spectrum is `(1 + 2 sum_j (1 - j/K) rho(j step)^2) / K` of a single
/// segment's, with `rho` the window's normalised overlap correlation.
///
/// ```
/// use frf::welch::{effective_averages, Window};
/// // No overlap: every segment counts.
/// assert_eq!(effective_averages(&vec![1.0; 64], 64, 10), 10.0);
/// // Hann at 50 %: rho = 1/6, so 100 segments count as about 94.7.
/// let hann: Vec<f64> = (0..256).map(|i| (std::f64::consts::PI * i as f64 / 256.0).sin().powi(2)).collect();
/// let k = effective_averages(&hann, 128, 100);
/// assert!((k - 100.0 / (1.0 + 2.0 * 0.99 / 36.0)).abs() < 0.05, "{k}");
/// ```
pub fn effective_averages(w: &[f64], step: usize, count: usize) -> f64 {
    if count == 0 {
        return 0.0;
    }
    let norm: f64 = w.iter().map(|x| x * x).sum();
    if norm == 0.0 {
        return count as f64;
    }
    let k = count as f64;
    let mut sum = 0.0;
    for j in 1..count {
        let shift = j * step;
        if shift >= w.len() {
            break;
        }
        let rho: f64 = (0..w.len() - shift)
            .map(|i| w[i] * w[i + shift])
            .sum::<f64>()
            / norm;
        sum += (1.0 - j as f64 / k) * rho * rho;
    }
    k / (1.0 + 2.0 * sum)
}

/// Why [`h1`] could not estimate.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum WelchError {
    /// Input and output differ in length.
    #[error("input has {u} samples but output has {y}")]
    LengthMismatch {
        /// Input samples.
        u: usize,
        /// Output samples.
        y: usize,
    },
    /// The sample rate is not a positive finite number.
    #[error("sample rate {0} Hz is not a positive finite number")]
    SampleRate(f64),
    /// Too few samples for even one segment.
    #[error("{samples} samples are too few: need at least {needed}")]
    TooShort {
        /// Samples available.
        samples: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A NaN or infinite sample.
    #[error("{signal} sample {index} is not finite")]
    NotFinite {
        /// `"input"` or `"output"`.
        signal: &'static str,
        /// 0-based sample index.
        index: usize,
    },
    /// Contradictory or out-of-range options.
    #[error("{0}")]
    Options(String),
    /// The estimate did not pass [`Frf::new`] (cannot happen for finite
    /// data, kept so that no path panics).
    #[error("estimate rejected: {0}")]
    Frf(#[from] FrfError),
}

/// Number of segments of length `nfft` advancing by `step` that fit in
/// `n` samples (trailing samples that do not fill a segment are unused).
pub fn segment_count(n: usize, nfft: usize, step: usize) -> usize {
    if nfft == 0 || step == 0 || n < nfft {
        0
    } else {
        (n - nfft) / step + 1
    }
}

fn step_of(nfft: usize, overlap: f64) -> usize {
    // floor(overlap * nfft) samples shared, as scipy.signal does for 50 %.
    let shared = (overlap * nfft as f64).floor() as usize;
    nfft.saturating_sub(shared).max(1)
}

/// The default segment length for `n` samples: the largest power of two in
/// [`MIN_DEFAULT_NFFT`] ..= [`MAX_DEFAULT_NFFT`] that gives at least
/// [`DEFAULT_AVERAGES`] segments with this overlap (a fraction). A record too
/// short for that gets [`MIN_DEFAULT_NFFT`] (fewer averages), and one
/// shorter than that the largest power of two that fits.
///
/// ```
/// use frf::welch::default_nfft;
/// // 40000 samples, Hann 50 %: 4096 gives (40000 - 4096) / 2048 + 1 = 18.
/// assert_eq!(default_nfft(40_000, 0.5), 4096);
/// assert_eq!(default_nfft(40, 0.5), 32);
/// ```
pub fn default_nfft(n: usize, overlap: f64) -> usize {
    let mut p = MAX_DEFAULT_NFFT;
    while p > MIN_DEFAULT_NFFT && segment_count(n, p, step_of(p, overlap)) < DEFAULT_AVERAGES {
        p /= 2;
    }
    if p > n && n >= 1 {
        p = 1 << (usize::BITS - 1 - n.leading_zeros());
    }
    p
}

/// Removes the mean or the least-squares line from `x` in place.
fn detrend(x: &mut [f64], how: Detrend) {
    let n = x.len();
    if n == 0 || how == Detrend::None {
        return;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    if how == Detrend::Mean || n == 1 {
        x.iter_mut().for_each(|v| *v -= mean);
        return;
    }
    // Centred abscissa makes slope and mean independent.
    let c = (n as f64 - 1.0) / 2.0;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, &v) in x.iter().enumerate() {
        let t = i as f64 - c;
        sxy += t * (v - mean);
        sxx += t * t;
    }
    let slope = sxy / sxx;
    for (i, v) in x.iter_mut().enumerate() {
        *v -= mean + slope * (i as f64 - c);
    }
}

/// Largest relative deviation of one time step from the mean step that
/// [`sample_rate_from_times`] accepts: 1 %, because time stamps are often
/// written with few digits (at 4 kHz, six decimals round each step by up
/// to 0.4 %) or stored in single precision; real jitter or a dropped
/// sample is far larger.
pub const TIME_STEP_TOLERANCE: f64 = 0.01;

/// Why a time vector does not define a sample rate.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct TimeAxisError {
    /// 0-based index of the offending sample (0 for the whole vector).
    pub index: usize,
    /// What is wrong.
    pub message: String,
}

/// The sample rate `(n - 1) / (t[n-1] - t[0])` of uniformly spaced time
/// stamps, after checking that every step is within
/// [`TIME_STEP_TOLERANCE`] of the mean step.
///
/// ```
/// use frf::welch::sample_rate_from_times;
/// let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.001).collect();
/// assert!((sample_rate_from_times(&t)? - 1000.0).abs() < 1e-9);
/// let mut gap = t.clone();
/// gap[50] += 0.0005;
/// assert_eq!(sample_rate_from_times(&gap).unwrap_err().index, 50);
/// # Ok::<(), frf::welch::TimeAxisError>(())
/// ```
pub fn sample_rate_from_times(t: &[f64]) -> Result<f64, TimeAxisError> {
    let n = t.len();
    if n < 2 {
        return Err(TimeAxisError {
            index: 0,
            message: format!("{n} time stamps cannot define a sample rate"),
        });
    }
    if let Some(index) = t.iter().position(|v| !v.is_finite()) {
        return Err(TimeAxisError {
            index,
            message: "time stamp is not finite".to_string(),
        });
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(TimeAxisError {
            index: n - 1,
            message: "time does not increase".to_string(),
        });
    }
    for i in 1..n {
        let step = t[i] - t[i - 1];
        if (step - dt).abs() > TIME_STEP_TOLERANCE * dt {
            return Err(TimeAxisError {
                index: i,
                message: format!(
                    "non-uniform time: step {step:e} s differs from the mean step {dt:e} s by more than {} %",
                    TIME_STEP_TOLERANCE * 100.0
                ),
            });
        }
    }
    Ok(1.0 / dt)
}

/// H1 estimate of the response from `u` to `y`, sampled at `fs` Hz.
///
/// The closed-loop (3-point, indirect) estimate from an excitation `x`
/// injected into a running loop: the plant `P = S_xy / S_xu` and the two
/// loop functions it comes from, each from the excitation with the same
/// segments, window and detrending as [`h1`].
#[derive(Clone, Debug, PartialEq)]
pub struct ThreePoint {
    /// The plant from `u` to `y`, `S_xy / S_xu`. Its standard deviation per
    /// line combines those of the two loop functions (relative variances
    /// add), and its coherence is the one that gives that uncertainty
    /// with Bendat and Piersol's formula.
    pub plant: Frf,
    /// From the excitation to the plant input, `S_xu / S_xx`: the
    /// (input) sensitivity when `x` is added at the plant input.
    pub sensitivity: Frf,
    /// From the excitation to the output, `S_xy / S_xx`: the process
    /// sensitivity.
    pub process_sensitivity: Frf,
    /// Segments averaged.
    pub averages: usize,
    /// Segment length.
    pub nfft: usize,
}

/// The 3-point estimate of the plant from `u` to `y` in a closed loop
/// excited by `x`; see [`ThreePoint`]. Unlike [`h1`] from `u` to `y`, it
/// is not biased by the noise on `y` that the controller feeds back into
/// `u`: that noise is uncorrelated with `x`.
///
/// ```
/// use frf::welch::{three_point, WelchOptions};
///
/// // A loop u = x - 0.5 y_meas around the plant y = 0.8 u[n-1], with
/// // sensor noise n that the controller feeds back into u.
/// let mut state = 7u64;
/// let mut white = || {
///     state ^= state << 13; state ^= state >> 7; state ^= state << 17;
///     (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
/// };
/// let n = 65536;
/// let (mut u, mut y, mut x) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
/// for k in 0..n {
///     x[k] = white();
///     let y_true = if k > 0 { 0.8 * u[k - 1] } else { 0.0 };
///     y[k] = y_true + 0.3 * white();
///     u[k] = x[k] - 0.5 * y[k];
/// }
/// // Short segments, many averages.
/// let opts = WelchOptions { nfft: Some(256), ..WelchOptions::default() };
/// let est = three_point(&x, &u, &y, 100.0, &opts)?;
/// // P = 0.8 e^(-i w / fs): the mean error over the lines is small; H1
/// // from u to y is far off, biased by the fed-back noise.
/// let error = |f: &frf::Frf| {
///     f.freq_hz().iter().zip(f.response()).map(|(&f, h)| {
///         let p = frf::Complex64::from_polar(0.8, -2.0 * std::f64::consts::PI * f / 100.0);
///         (h - p).norm()
///     }).sum::<f64>() / f.len() as f64
/// };
/// assert!(error(&est.plant) < 0.02, "{}", error(&est.plant));
/// let biased = frf::welch::h1(&u, &y, 100.0, &opts)?;
/// assert!(error(&biased.frf) > 0.035, "{}", error(&biased.frf));
/// # Ok::<(), frf::welch::WelchError>(())
/// ```
pub fn three_point(
    x: &[f64],
    u: &[f64],
    y: &[f64],
    fs: f64,
    opts: &WelchOptions,
) -> Result<ThreePoint, WelchError> {
    if x.len() != u.len() {
        return Err(WelchError::LengthMismatch {
            u: x.len(),
            y: u.len(),
        });
    }
    let s = h1(x, u, fs, opts)?;
    let ps = h1(x, y, fs, opts)?;
    let (sf, psf) = (&s.frf, &ps.frf);
    let rel = |f: &Frf| f.relative_std_dev().unwrap_or_else(|| vec![0.0; f.len()]);
    let (rs, rps) = (rel(sf), rel(psf));
    let mut response = Vec::with_capacity(sf.len());
    let mut std_dev = Vec::with_capacity(sf.len());
    let mut coherence = Vec::with_capacity(sf.len());
    for k in 0..sf.len() {
        let p = psf.response()[k] / sf.response()[k];
        let r = (rs[k] * rs[k] + rps[k] * rps[k]).sqrt();
        let finite = p.is_finite() && r.is_finite();
        response.push(if p.is_finite() {
            p
        } else {
            Complex64::new(0.0, 0.0)
        });
        std_dev.push(if finite { r * p.norm() } else { f64::INFINITY });
        // (1 - g) / g = sum of the two loop functions' (1 - g_i) / g_i.
        let odds = |g: f64| (1.0 - g) / g.max(1e-300);
        let c = match (sf.coherence(), psf.coherence()) {
            (Some(a), Some(b)) => 1.0 / (1.0 + odds(a[k]) + odds(b[k])),
            _ => 0.0,
        };
        coherence.push(if c.is_finite() { c } else { 0.0 });
    }
    let plant = Frf::new(sf.freq_hz().to_vec(), response, Some(coherence))
        .and_then(|f| f.with_std_dev(std_dev))
        .map_err(|e| WelchError::Options(format!("the 3-point estimate: {e}")))?;
    Ok(ThreePoint {
        plant,
        sensitivity: s.frf,
        process_sensitivity: ps.frf,
        averages: s.averages,
        nfft: s.nfft,
    })
}

/// `x` less the ramp through the means of its periods (starting at
/// `starts`, `period` samples each): the slope is the least-squares slope
/// of the period means against their start, which a periodic signal
/// leaves at zero.
pub(crate) fn without_ramp(x: &[f64], starts: &[usize], period: usize) -> Vec<f64> {
    let means: Vec<(f64, f64)> = starts
        .iter()
        .map(|&s| {
            let m = x[s..s + period].iter().sum::<f64>() / period as f64;
            (s as f64, m)
        })
        .collect();
    let n = means.len() as f64;
    let (ts, ms) = means
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, m)| (a + t / n, b + m / n));
    let (num, den) = means.iter().fold((0.0, 0.0), |(a, b), (t, m)| {
        (a + (t - ts) * (m - ms), b + (t - ts) * (t - ts))
    });
    let slope = if den > 0.0 { num / den } else { 0.0 };
    x.iter()
        .enumerate()
        .map(|(k, v)| v - slope * k as f64)
        .collect()
}

/// See the [module documentation](self) for the method. With periodic
/// excitation the estimate is exact up to rounding:
///
/// ```
/// use frf::welch::{h1, WelchOptions};
/// use frf::Complex64;
/// use std::f64::consts::PI;
///
/// // Three periods of 64 samples; y is u delayed by one sample, so
/// // H(f) = exp(-2 pi i f / fs) at every line.
/// let period = 64;
/// let u: Vec<f64> = (0..3 * period)
///     .map(|n| (1..32).map(|k| (2.0 * PI * (k * n) as f64 / 64.0 + k as f64).cos()).sum())
///     .collect();
/// let y: Vec<f64> = (0..u.len()).map(|n| u[(n + u.len() - 1) % u.len()]).collect();
/// let est = h1(&u, &y, 64.0, &WelchOptions { period: Some(period), ..Default::default() })?;
/// assert_eq!(est.averages, 2); // the first period is dropped
/// for (f, h) in est.frf.freq_hz().iter().zip(est.frf.response()).take(31) {
///     assert!((h - Complex64::from_polar(1.0, -2.0 * PI * f / 64.0)).norm() < 1e-12);
/// }
/// # Ok::<(), frf::welch::WelchError>(())
/// ```
pub fn h1(u: &[f64], y: &[f64], fs: f64, opts: &WelchOptions) -> Result<H1Estimate, WelchError> {
    if u.len() != y.len() {
        return Err(WelchError::LengthMismatch {
            u: u.len(),
            y: y.len(),
        });
    }
    if !(fs.is_finite() && fs > 0.0) {
        return Err(WelchError::SampleRate(fs));
    }
    if let Some(index) = u.iter().position(|v| !v.is_finite()) {
        return Err(WelchError::NotFinite {
            signal: "input",
            index,
        });
    }
    if let Some(index) = y.iter().position(|v| !v.is_finite()) {
        return Err(WelchError::NotFinite {
            signal: "output",
            index,
        });
    }
    let n = u.len();
    if let Some(o) = opts.overlap {
        if !(0.0..1.0).contains(&o) {
            return Err(WelchError::Options(format!(
                "overlap {o} is outside [0, 1)"
            )));
        }
    }

    // (segment starts, nfft, window, overlap, detrend)
    let (starts, nfft, window, overlap, how): (Vec<usize>, usize, Window, f64, Detrend) =
        if let Some(period) = opts.period {
            if period < 2 {
                return Err(WelchError::Options(format!(
                    "period {period} is too short: need at least 2 samples"
                )));
            }
            if let Some(nfft) = opts.nfft {
                if nfft != period {
                    return Err(WelchError::Options(format!(
                        "nfft {nfft} contradicts period {period} (periodic mode uses one period per segment)"
                    )));
                }
            }
            if opts.overlap.is_some_and(|o| o != 0.0) {
                return Err(WelchError::Options(
                    "periodic mode uses no overlap".to_string(),
                ));
            }
            let periods = n / period;
            if periods < 2 {
                return Err(WelchError::TooShort {
                    samples: n,
                    needed: period.saturating_mul(2),
                });
            }
            let starts = (1..periods).map(|p| p * period).collect();
            let how = opts.detrend.unwrap_or(Detrend::Mean);
            (starts, period, Window::Rectangular, 0.0, how)
        } else {
            let overlap = opts.overlap.unwrap_or(opts.window.default_overlap());
            let nfft = match opts.nfft {
                Some(k) => k,
                None => default_nfft(n, overlap),
            };
            if nfft < 2 {
                return Err(WelchError::Options(format!(
                    "nfft {nfft} is too small: need at least 2"
                )));
            }
            if n < nfft {
                return Err(WelchError::TooShort {
                    samples: n,
                    needed: nfft,
                });
            }
            let step = step_of(nfft, overlap);
            let count = segment_count(n, nfft, step);
            let starts = (0..count).map(|s| s * step).collect();
            let how = opts.detrend.unwrap_or(Detrend::Linear);
            (starts, nfft, opts.window, overlap, how)
        };

    // Periodic mode: the ramp common to the periods.
    let (u, y) = match (opts.period, how) {
        (Some(_), Detrend::Mean | Detrend::Linear) if starts.len() >= 2 => (
            without_ramp(u, &starts, nfft),
            without_ramp(y, &starts, nfft),
        ),
        _ => (u.to_vec(), y.to_vec()),
    };
    let (u, y) = (u.as_slice(), y.as_slice());
    // One complex transform carries both signals (below); separating them
    // leaves each with rounding of the order of the other's size, so an
    // input many decades smaller than the output would come back polluted
    // by the output and look coherent with it. A power of two brings the
    // input near the output's level (exactly, and undone exactly after);
    // within 2^20 it is not needed, and the arithmetic stays as it was.
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    let ratio = rms(y) / rms(u);
    let scale = if ratio.is_finite() && ratio > 0.0 && ratio.log2().abs() > 20.0 {
        2f64.powi(ratio.log2().round() as i32)
    } else {
        1.0
    };
    let lines = nfft / 2;
    let plan = FftPlan::new(nfft);
    let w = window.weights(nfft);
    let mut s_uu = vec![0.0; lines];
    let mut s_yy = vec![0.0; lines];
    let mut s_uy = vec![Complex64::new(0.0, 0.0); lines];
    let mut us = vec![0.0; nfft];
    let mut ys = vec![0.0; nfft];
    let mut z = vec![Complex64::new(0.0, 0.0); nfft];
    // Periodic mode: each period's input and output spectra, for their
    // means and scatter.
    let periodic = opts.period.is_some();
    let mut per_period: Vec<Vec<(Complex64, Complex64)>> = Vec::new();
    for &s in &starts {
        us.copy_from_slice(&u[s..s + nfft]);
        ys.copy_from_slice(&y[s..s + nfft]);
        detrend(&mut us, how);
        detrend(&mut ys, how);
        // Both real signals in one complex transform: z = u + i y gives
        // U_k = (Z_k + conj Z_{N-k}) / 2 and Y_k = (Z_k - conj Z_{N-k}) / 2i.
        for i in 0..nfft {
            z[i] = Complex64::new(scale * us[i] * w[i], ys[i] * w[i]);
        }
        plan.forward(&mut z);
        let mut this_period = Vec::with_capacity(if periodic { lines } else { 0 });
        for k in 1..=lines {
            let zk = z[k];
            let zm = z[nfft - k].conj();
            let uk = (zk + zm) * 0.5 / scale;
            let yk = (zk - zm) * Complex64::new(0.0, -0.5);
            s_uu[k - 1] += uk.norm_sqr();
            s_yy[k - 1] += yk.norm_sqr();
            s_uy[k - 1] += uk.conj() * yk;
            if periodic {
                this_period.push((uk, yk));
            }
        }
        if periodic {
            per_period.push(this_period);
        }
    }

    let freq: Vec<f64> = (1..=lines).map(|k| k as f64 * fs / nfft as f64).collect();
    let mut response = Vec::with_capacity(lines);
    let mut coherence = Vec::with_capacity(lines);
    for k in 0..lines {
        // A line without input power has no estimate: report 0 with zero
        // coherence rather than NaN.
        response.push(if s_uu[k] > 0.0 {
            s_uy[k] / s_uu[k]
        } else {
            Complex64::new(0.0, 0.0)
        });
        let den = s_uu[k] * s_yy[k];
        // Cauchy-Schwarz bounds it by 1; rounding may not.
        coherence.push(if den > 0.0 {
            (s_uy[k].norm_sqr() / den).clamp(0.0, 1.0)
        } else {
            0.0
        });
    }
    let count = starts.len();
    let effective = if periodic {
        count as f64
    } else {
        effective_averages(&w, step_of(nfft, overlap), count)
    };
    let strongest = s_uu.iter().copied().fold(0.0, f64::max);
    let std_dev: Option<Vec<f64>> = if periodic && count >= 2 {
        let mut sd = Vec::with_capacity(lines);
        for k in 0..lines {
            let (g, sd_k, coh) = periodic_line(&per_period, k, NO_EXCITATION * strongest);
            response[k] = g;
            coherence[k] = coh;
            sd.push(sd_k);
        }
        Some(sd)
    } else if !periodic && effective >= 2.0 {
        Some(
            (0..lines)
                .map(|k| {
                    let g = coherence[k];
                    if s_uu[k] <= NO_EXCITATION * strongest || g == 0.0 {
                        return f64::INFINITY;
                    }
                    ((1.0 - g) / (2.0 * effective * g)).sqrt() * response[k].norm()
                })
                .collect(),
        )
    } else {
        None
    };
    let mut frf = Frf::new(freq, response, Some(coherence))?;
    if let Some(sd) = std_dev {
        frf = frf.with_std_dev(sd)?;
    }
    Ok(H1Estimate {
        frf,
        averages: count,
        nfft,
        window,
        overlap,
        detrend: how,
        effective_averages: effective,
    })
}

/// One line of a periodic estimate from each period's input and output
/// spectra `(U_p, Y_p)`: the ratio of their means `G = mean Y / mean U`,
/// its standard deviation per real and imaginary part from their scatter
/// between periods (first order: `var G = (var Y + |G|^2 var U - 2 Re(conj G
/// cov(Y, U))) / |mean U|^2`, the variances those of the means), and the
/// coherence that gives that deviation with as many averages
/// (`1 / (1 + p var G / |G|^2)`).
///
/// Averaging the spectra before dividing takes out noise on the input as
/// well as on the output (a closed loop feeds the sensor noise back into
/// the plant input), where H1 would be biased by it. A line whose mean
/// input is within three of its standard deviations of zero, or below
/// `floor` in power, carries no excitation: `+inf` and coherence 0.
fn periodic_line(
    per_period: &[Vec<(Complex64, Complex64)>],
    k: usize,
    floor: f64,
) -> (Complex64, f64, f64) {
    let p = per_period.len() as f64;
    let (su, sy) = per_period.iter().fold(
        (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0)),
        |(a, b), q| (a + q[k].0, b + q[k].1),
    );
    let (ub, yb) = (su / p, sy / p);
    let (mut vu, mut vy, mut cyu) = (0.0, 0.0, Complex64::new(0.0, 0.0));
    for q in per_period {
        let (du, dy) = (q[k].0 - ub, q[k].1 - yb);
        vu += du.norm_sqr();
        vy += dy.norm_sqr();
        cyu += dy * du.conj();
    }
    // Of the means: the scatter over p - 1, divided by p.
    let of_mean = p * (p - 1.0);
    let (vu, vy, cyu) = (vu / of_mean, vy / of_mean, cyu / of_mean);
    let power = ub.norm_sqr();
    if power <= floor || power <= 9.0 * vu {
        let g = if power > 0.0 {
            yb / ub
        } else {
            Complex64::new(0.0, 0.0)
        };
        return (g, f64::INFINITY, 0.0);
    }
    let g = yb / ub;
    let var = ((vy + g.norm_sqr() * vu - 2.0 * (g.conj() * cyu).re) / power).max(0.0);
    let gg = g.norm_sqr();
    let coh = if gg > 0.0 {
        1.0 / (1.0 + p * var / gg)
    } else {
        0.0
    };
    (g, (var / 2.0).sqrt(), coh)
}

/// How many independent values a sum of squares of `x` carries: the
/// Satterthwaite degrees of freedom `(tr C)^2 / tr(C^2)` of a stationary
/// Gaussian sequence with covariance `C`, which a spectral density `S`
/// gives as `2 T (int S df)^2 / int S^2 df`, here from a Welch estimate
/// of `x`'s spectrum (Hann, half-overlapping segments, at least eight).
/// White noise gives about `x.len()` (a few per cent less, the estimate's
/// own scatter); an error that is a smooth curve, whose power sits in a
/// few low lines, far fewer. Capped at `x.len()`.
///
/// ```
/// use frf::welch::effective_samples;
/// // A white sequence keeps almost all of its samples.
/// let mut s = 1u64;
/// let white: Vec<f64> = (0..4096)
///     .map(|_| {
///         s ^= s << 13; s ^= s >> 7; s ^= s << 17;
///         (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
///     })
///     .collect();
/// assert!(effective_samples(&white) > 3500.0);
/// // A slow sine over the same samples counts as a handful.
/// let slow: Vec<f64> = (0..4096).map(|k| (k as f64 / 500.0).sin()).collect();
/// assert!(effective_samples(&slow) < 60.0);
/// ```
pub fn effective_samples(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 16 {
        return n as f64;
    }
    // The largest power of two with at least eight half-overlapping
    // segments.
    let mut nfft = 8usize;
    while segment_count(n, 2 * nfft, nfft) >= 8 {
        nfft *= 2;
    }
    let step = nfft / 2;
    let count = segment_count(n, nfft, step);
    let w = Window::Hann.weights(nfft);
    let plan = FftPlan::new(nfft);
    let lines = nfft / 2 + 1;
    let mut power = vec![0.0; lines];
    let mut z = vec![Complex64::new(0.0, 0.0); nfft];
    for s in 0..count {
        let seg = &x[s * step..s * step + nfft];
        for i in 0..nfft {
            z[i] = Complex64::new(seg[i] * w[i], 0.0);
        }
        plan.forward(&mut z);
        for (p, zk) in power.iter_mut().zip(&z) {
            *p += zk.norm_sqr();
        }
    }
    // One-sided: the lines inside the band count twice.
    let weight = |k: usize| if k == 0 || 2 * k == nfft { 1.0 } else { 2.0 };
    let (mut sum, mut sum2) = (0.0, 0.0);
    for (k, p) in power.iter().enumerate() {
        sum += weight(k) * p;
        sum2 += weight(k) * p * p;
    }
    if !(sum > 0.0 && sum2 > 0.0) {
        return n as f64;
    }
    (n as f64 / nfft as f64 * sum * sum / sum2).min(n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64: deterministic white sequence, uniform in [-1, 1).
    struct Xorshift(u64);
    impl Xorshift {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
        fn white(&mut self, n: usize) -> Vec<f64> {
            (0..n).map(|_| self.next()).collect()
        }
    }

    /// A periodic response riding on a ramp (an axis turning at constant
    /// speed) gives the H1 of the periodic part alone: the exact response
    /// of a one-sample delay times 0.5 at every excited line, where the
    /// mean of each period would leave a sawtooth leaking into them.
    #[test]
    fn periodic_h1_takes_out_a_common_ramp() {
        let period = 64;
        let one = Xorshift(7).white(period);
        let u: Vec<f64> = (0..6 * period).map(|k| one[k % period]).collect();
        let y: Vec<f64> = (0..u.len())
            .map(|k| 0.5 * u[(k + u.len() - 1) % u.len()] + 3.0 + 0.02 * k as f64)
            .collect();
        let opts = WelchOptions {
            period: Some(period),
            ..WelchOptions::default()
        };
        let est = h1(&u, &y, 64.0, &opts).unwrap();
        for (k, h) in est.frf.response().iter().enumerate() {
            let f = (k + 1) as f64;
            let want = Complex64::from_polar(0.5, -2.0 * std::f64::consts::PI * f / 64.0);
            assert!((h - want).norm() < 1e-9, "line {f}: {h} vs {want}");
        }
    }

    /// A resonant second-order section
    /// `H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)`
    /// with poles at radius 0.9, angle 0.2 pi, and zeros inside the unit
    /// circle (|z|^2 = 1/3), so |H| > 0 on the whole band.
    struct Biquad {
        b: [f64; 3],
        a: [f64; 2],
    }

    impl Biquad {
        fn resonant() -> Biquad {
            let (r, theta) = (0.9f64, 0.2 * PI);
            Biquad {
                b: [0.3, 0.2, 0.1],
                a: [-2.0 * r * theta.cos(), r * r],
            }
        }

        /// Direct form I, zero initial state.
        fn filter(&self, u: &[f64]) -> Vec<f64> {
            let mut y = vec![0.0; u.len()];
            for n in 0..u.len() {
                let at = |v: &[f64], k: usize| if n >= k { v[n - k] } else { 0.0 };
                y[n] = self.b[0] * u[n] + self.b[1] * at(u, 1) + self.b[2] * at(u, 2)
                    - self.a[0] * at(&y, 1)
                    - self.a[1] * at(&y, 2);
            }
            y
        }

        /// The exact response at `z = exp(i w)`, `w = 2 pi f / fs`.
        fn response(&self, w: f64) -> Complex64 {
            let zi = Complex64::from_polar(1.0, -w);
            let num = self.b[0] + self.b[1] * zi + self.b[2] * zi * zi;
            let den = 1.0 + self.a[0] * zi + self.a[1] * zi * zi;
            num / den
        }
    }

    #[test]
    fn noise_free_h1_matches_exact_response() {
        let fs = 1000.0;
        let sys = Biquad::resonant();
        let u = Xorshift(0x1234_5678).white(1 << 16);
        let y = sys.filter(&u);
        let est = h1(
            &u,
            &y,
            fs,
            &WelchOptions {
                nfft: Some(512),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(est.nfft, 512);
        assert_eq!(est.frf.len(), 256);
        // (65536 - 512) / 256 + 1 segments at 50 % overlap.
        assert_eq!(est.averages, 255);
        let coh = est.frf.coherence().unwrap();
        let mut worst: f64 = 0.0;
        for (k, (&f, &h)) in est.frf.freq_hz().iter().zip(est.frf.response()).enumerate() {
            assert!((f - (k + 1) as f64 * fs / 512.0).abs() < 1e-12);
            let exact = sys.response(2.0 * PI * f / fs);
            worst = worst.max((h - exact).norm() / exact.norm());
            // Without noise only leakage from outside each segment lowers
            // the coherence; with an impulse response decaying as 0.9^n it
            // stays above 0.99.
            assert!(coh[k] > 0.99, "coherence {} at {f} Hz", coh[k]);
        }
        // Tolerance 1 %: the remaining error is segment leakage (the
        // filter's memory crossing segment edges), averaged over 255
        // segments; a wrong conjugation or scaling is off by O(1).
        assert!(worst < 0.01, "worst relative error {worst}");
    }

    #[test]
    fn output_noise_lowers_coherence_but_not_h1() {
        let fs = 1.0;
        let sys = Biquad::resonant();
        let mut rng = Xorshift(0xdead_beef);
        let u = rng.white(1 << 17);
        let clean = sys.filter(&u);
        let sigma_n = 0.1;
        let noisy: Vec<f64> = clean.iter().map(|v| v + sigma_n * rng.next()).collect();
        let opts = WelchOptions {
            nfft: Some(256),
            ..Default::default()
        };
        let est = h1(&u, &noisy, fs, &opts).unwrap();
        // The same input without noise: the difference is the noise's
        // effect alone (window leakage is common to both).
        let reference = h1(&u, &clean, fs, &opts).unwrap();
        let k_avg = est.averages as f64;
        // Uniform [-1, 1) has variance 1/3; noise variance sigma^2 / 3.
        let (var_u, var_n) = (1.0 / 3.0, sigma_n * sigma_n / 3.0);
        let coh = est.frf.coherence().unwrap();
        let (mut sum, mut sum_var) = (Complex64::new(0.0, 0.0), 0.0);
        let mut low_coherence_lines = 0;
        for (k, &c) in coh.iter().enumerate() {
            let f = est.frf.freq_hz()[k];
            let exact = sys.response(2.0 * PI * f / fs);
            let snr = exact.norm_sqr() * var_u / var_n;
            let expected_coh = snr / (1.0 + snr);
            // Coherence estimate vs its theoretical value: the estimator's
            // spread with K = 1023 averages is about (1 - g) sqrt(2 / K)
            // < 0.045, plus a small leakage loss.
            assert!(
                (c - expected_coh).abs() < 0.05,
                "{f}: coherence {} vs {expected_coh}",
                c
            );
            if expected_coh < 0.9 {
                low_coherence_lines += 1;
            }
            // Standard deviation of |H1 - H| / |H| is sqrt((1 - g) / (2 K g)),
            // at most ~0.06 here; allow 5 of them at every line.
            let sd = ((1.0 - expected_coh) / (2.0 * k_avg * expected_coh)).sqrt();
            let rel = (est.frf.response()[k] - reference.frf.response()[k]) / exact;
            assert!(
                rel.norm() < 5.0 * sd,
                "{f}: rel error {} vs sd {sd}",
                rel.norm()
            );
            sum += rel;
            sum_var += sd * sd;
        }
        // The noise really matters somewhere (else the test proves nothing).
        assert!(low_coherence_lines > 20, "{low_coherence_lines}");
        // Unbiased: the mean relative deviation over the 128 lines is
        // within 4 standard deviations of that mean (sqrt(sum sd^2) / L).
        let lines = est.frf.len() as f64;
        let mean = sum.norm() / lines;
        assert!(
            mean < 4.0 * sum_var.sqrt() / lines,
            "mean relative deviation {mean}"
        );
    }

    /// H1 is linear in each signal: an input 1e-20 (or 1e20) times as
    /// large gives an FRF 1e20 (1e-20) times as large and the same
    /// coherence, and an input unrelated to the output stays incoherent
    /// however small it is. (Two signals in one complex transform leave
    /// each with rounding of the other's size: unscaled, an input 1e20
    /// times smaller than the output read a coherence near 0.6.)
    #[test]
    fn h1_does_not_depend_on_the_scale_of_the_input() {
        let sys = Biquad::resonant();
        let mut rng = Xorshift(0x5eed);
        let u = rng.white(1 << 14);
        let y: Vec<f64> = sys
            .filter(&u)
            .iter()
            .map(|v| v + 0.1 * rng.next())
            .collect();
        let unrelated = rng.white(1 << 14);
        let opts = WelchOptions {
            nfft: Some(256),
            ..Default::default()
        };
        let reference = h1(&u, &y, 1.0, &opts).unwrap();
        let alone = h1(&u, &unrelated, 1.0, &opts).unwrap();
        let mean = |e: &H1Estimate| {
            let c = e.frf.coherence().unwrap();
            c.iter().sum::<f64>() / c.len() as f64
        };
        for factor in [1e-20, 1e20] {
            let scaled: Vec<f64> = u.iter().map(|v| v * factor).collect();
            let est = h1(&scaled, &y, 1.0, &opts).unwrap();
            for k in 0..est.frf.len() {
                let want = reference.frf.response()[k] / factor;
                let got = est.frf.response()[k];
                assert!((got / want - 1.0).norm() < 1e-12, "{factor}: line {k}");
                let (a, b) = (
                    est.frf.coherence().unwrap()[k],
                    reference.frf.coherence().unwrap()[k],
                );
                assert!((a - b).abs() < 1e-12, "{factor}: line {k}");
            }
            let unrelated_est = h1(&scaled, &unrelated, 1.0, &opts).unwrap();
            // About 1 / averages for unrelated signals, at any scale.
            assert!(
                (mean(&unrelated_est) - mean(&alone)).abs() < 1e-9,
                "{factor}"
            );
            assert!(
                mean(&unrelated_est) < 0.1,
                "{factor}: {}",
                mean(&unrelated_est)
            );
        }
    }

    /// Noise on the measured input (a closed loop feeds the sensor noise
    /// back into it) biases H1 towards zero by the input's signal-to-noise
    /// power ratio; the ratio of the period-averaged spectra is not
    /// biased, and its standard deviation, carried from the scatter of
    /// both spectra, covers its error as a standard deviation should.
    #[test]
    fn periodic_estimate_is_free_of_input_noise_bias() {
        let (period, periods) = (128usize, 60usize);
        let mut rng = Xorshift(11);
        let one = rng.white(period);
        let clean: Vec<f64> = (0..period * periods).map(|k| one[k % period]).collect();
        // y = 0.5 u delayed by one sample, measured with 1 % noise; u
        // measured with noise of its own size.
        let y: Vec<f64> = (0..clean.len())
            .map(|k| 0.5 * clean[(k + clean.len() - 1) % clean.len()] + 0.01 * rng.next())
            .collect();
        let u: Vec<f64> = clean.iter().map(|v| v + rng.next()).collect();
        let opts = WelchOptions {
            period: Some(period),
            ..WelchOptions::default()
        };
        let est = h1(&u, &y, 1.0, &opts).unwrap();
        let sd = est.frf.std_dev().unwrap();
        let (mut errors, mut ratios) = (Vec::new(), Vec::new());
        for (k, (&f, h)) in est.frf.freq_hz().iter().zip(est.frf.response()).enumerate() {
            if !sd[k].is_finite() {
                continue;
            }
            let truth = Complex64::from_polar(0.5, -2.0 * PI * f);
            // Per real and imaginary part: |error|^2 / (2 sd^2) is about 1.
            errors.push((h - truth).norm_sqr() / (2.0 * sd[k] * sd[k]));
            ratios.push((h / truth).re);
        }
        assert!(errors.len() > 40, "{} lines", errors.len());
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let normalised = mean(&errors);
        assert!(
            (0.6..1.6).contains(&normalised),
            "normalised squared error {normalised}"
        );
        // The estimate over the truth is 1 on average; H1's is about
        // 1 / (1 + 1 / SNR), a half with input noise as strong as the
        // input.
        let ratio = mean(&ratios);
        assert!((ratio - 1.0).abs() < 0.03, "estimate over truth {ratio}");
        let welch = h1(&u, &y, 1.0, &WelchOptions::default()).unwrap();
        let biased: Vec<f64> = welch
            .frf
            .freq_hz()
            .iter()
            .zip(welch.frf.response())
            .map(|(&f, h)| (h / Complex64::from_polar(0.5, -2.0 * PI * f)).re)
            .collect();
        assert!(mean(&biased) < 0.7, "H1 over truth {}", mean(&biased));
    }

    #[test]
    fn periodic_excitation_is_exact() {
        // Multisine with random phases on every line 1 .. P/2 - 1, nine
        // periods; the first period carries the transient and is dropped.
        let (period, periods, fs) = (256usize, 9usize, 400.0);
        let mut rng = Xorshift(42);
        let phases: Vec<f64> = (0..period / 2).map(|_| PI * rng.next()).collect();
        let one: Vec<f64> = (0..period)
            .map(|n| {
                (1..period / 2)
                    .map(|k| (2.0 * PI * (k * n) as f64 / period as f64 + phases[k]).cos())
                    .sum()
            })
            .collect();
        let u: Vec<f64> = (0..period * periods).map(|n| one[n % period]).collect();
        let sys = Biquad::resonant();
        let y = sys.filter(&u);
        let est = h1(
            &u,
            &y,
            fs,
            &WelchOptions {
                period: Some(period),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(est.averages, periods - 1);
        assert_eq!(est.window, Window::Rectangular);
        assert_eq!(est.nfft, period);
        let coh = est.frf.coherence().unwrap();
        for (k, &c) in coh.iter().enumerate().take(period / 2 - 1) {
            let f = est.frf.freq_hz()[k];
            let exact = sys.response(2.0 * PI * f / fs);
            // The transient decays as 0.9^n: after one period (256
            // samples) it is ~2e-12 of the response, so 1e-9 holds.
            let rel = (est.frf.response()[k] - exact).norm() / exact.norm();
            assert!(rel < 1e-9, "line {}: {rel:e}", k + 1);
            assert!(c > 1.0 - 1e-9);
        }
    }

    #[test]
    fn linear_trend_is_removed() {
        // A ramp added to the output (drift) must not change H1 beyond
        // rounding when every segment is linearly detrended.
        let sys = Biquad::resonant();
        let u = Xorshift(99).white(1 << 14);
        let y = sys.filter(&u);
        let drifting: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(n, v)| v + 5.0 + 0.01 * n as f64)
            .collect();
        let opts = WelchOptions {
            nfft: Some(256),
            ..Default::default()
        };
        let a = h1(&u, &y, 1.0, &opts).unwrap();
        let b = h1(&u, &drifting, 1.0, &opts).unwrap();
        for (ha, hb) in a.frf.response().iter().zip(b.frf.response()) {
            assert!((ha - hb).norm() < 1e-9 * (1.0 + ha.norm()));
        }
        // Without detrending the ramp leaks into the low lines.
        let raw = WelchOptions {
            detrend: Some(Detrend::None),
            ..opts
        };
        let c = h1(&u, &drifting, 1.0, &raw).unwrap();
        assert!((c.frf.response()[0] - a.frf.response()[0]).norm() > 0.1);
    }

    #[test]
    fn default_nfft_rule() {
        // Hann 50 %: the largest power of two with >= 16 segments.
        for &n in &[1000usize, 40_000, 73_728, 1_000_000] {
            let p = default_nfft(n, 0.5);
            assert!(p.is_power_of_two());
            assert!(segment_count(n, p, p / 2) >= 16 || p == MIN_DEFAULT_NFFT);
            assert!(p == MAX_DEFAULT_NFFT || segment_count(n, 2 * p, p) < 16);
        }
        assert_eq!(default_nfft(100_000_000, 0.5), MAX_DEFAULT_NFFT);
        // Rectangular, no overlap: 16 * 2048 <= 40000 < 16 * 4096.
        assert_eq!(default_nfft(40_000, 0.0), 2048);
        assert_eq!(default_nfft(100, 0.5), 64);
    }

    #[test]
    fn non_power_of_two_nfft() {
        // nfft = 500 goes through Bluestein; lines at k fs / 500.
        let sys = Biquad::resonant();
        let u = Xorshift(5).white(50_000);
        let y = sys.filter(&u);
        let est = h1(
            &u,
            &y,
            500.0,
            &WelchOptions {
                nfft: Some(500),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(est.frf.len(), 250);
        assert!((est.frf.freq_hz()[0] - 1.0).abs() < 1e-12);
        for (&f, &h) in est.frf.freq_hz().iter().zip(est.frf.response()) {
            let exact = sys.response(2.0 * PI * f / 500.0);
            // 2 %: segment leakage with 199 averages, largest (about 1 %)
            // at the first line, where per-segment detrending also acts.
            let rel = (h - exact).norm() / exact.norm();
            assert!(rel < 0.02, "{f}: {rel}");
        }
    }

    #[test]
    fn errors() {
        let u = vec![0.0; 100];
        let y = vec![0.0; 99];
        assert!(matches!(
            h1(&u, &y, 1.0, &Default::default()),
            Err(WelchError::LengthMismatch { .. })
        ));
        assert!(matches!(
            h1(&u, &u, 0.0, &Default::default()),
            Err(WelchError::SampleRate(_))
        ));
        assert!(matches!(
            h1(&u, &u, f64::NAN, &Default::default()),
            Err(WelchError::SampleRate(_))
        ));
        let mut bad = u.clone();
        bad[7] = f64::INFINITY;
        assert_eq!(
            h1(&u, &bad, 1.0, &Default::default()),
            Err(WelchError::NotFinite {
                signal: "output",
                index: 7
            })
        );
        let big = WelchOptions {
            nfft: Some(101),
            ..Default::default()
        };
        assert!(matches!(
            h1(&u, &u, 1.0, &big),
            Err(WelchError::TooShort { .. })
        ));
        let periodic = WelchOptions {
            period: Some(60),
            ..Default::default()
        };
        assert!(matches!(
            h1(&u, &u, 1.0, &periodic),
            Err(WelchError::TooShort { .. })
        ));
        let clash = WelchOptions {
            period: Some(50),
            nfft: Some(40),
            ..Default::default()
        };
        assert!(matches!(
            h1(&u, &u, 1.0, &clash),
            Err(WelchError::Options(_))
        ));
        let overlap = WelchOptions {
            overlap: Some(1.0),
            ..Default::default()
        };
        assert!(matches!(
            h1(&u, &u, 1.0, &overlap),
            Err(WelchError::Options(_))
        ));
        // All-zero input: no input power anywhere; zeros, not NaN.
        let est = h1(
            &u,
            &u,
            1.0,
            &WelchOptions {
                nfft: Some(20),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(est
            .frf
            .response()
            .iter()
            .all(|h| *h == Complex64::new(0.0, 0.0)));
        assert!(est.frf.coherence().unwrap().iter().all(|&c| c == 0.0));
    }

    /// A SPERTE record's signals (4 kHz) at segment length `nfft`.
    fn sperte(nfft: Option<usize>) -> crate::recording::RecordingOptions {
        crate::recording::RecordingOptions {
            u: Some(sig("result:1")),
            y: Some(sig("result:2")),
            fs: Some(4000.0),
            welch: WelchOptions {
                nfft,
                ..WelchOptions::default()
            },
            ..Default::default()
        }
    }

    fn sig(s: &str) -> crate::recording::SignalRef {
        s.parse().unwrap()
    }

    /// The H1 estimates, coherences and standard deviations of the real
    /// recordings are those of the transforms this crate used before
    /// rustfft, within 1e-12 of each line's size: Welch averaging at the
    /// default power-of-two segment length and at an odd one (Bluestein's
    /// path then), periodic averaging (F16, 8192-sample periods) and the
    /// 3-point estimate of a closed loop (TU/e 2018).
    #[test]
    fn estimates_equal_those_of_the_reference_transforms() {
        use crate::recording::{read_recording, RecordingOptions};
        let real =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/real");
        let cases = [
            ("sperte/setup18_motor_side_v0.3.mat", sperte(None)),
            ("sperte/setup29_load_side_v0.5.mat", sperte(Some(3000))),
            (
                "f16_gvt/F16Data_FullMSine_Level1.mat",
                RecordingOptions {
                    u: Some(sig("Force")),
                    y: Some(sig("Acceleration:1")),
                    welch: WelchOptions {
                        period: Some(8192),
                        ..WelchOptions::default()
                    },
                    ..RecordingOptions::default()
                },
            ),
            (
                "tue_motion_2018/scan_10hz_with_feedforward.mat",
                RecordingOptions {
                    u: Some(sig("Data.u")),
                    y: Some(sig("Data.y1")),
                    excitation: Some(sig("Data.r")),
                    ..RecordingOptions::default()
                },
            ),
        ];
        // Lines the record measures: a standard deviation of at most a
        // tenth of the response.
        const MEASURED: f64 = 0.1;
        for (file, options) in &cases {
            let path = real.join(file);
            let planned = read_recording(&path, options).unwrap().frf;
            let reference =
                crate::fft::reference::with(|| read_recording(&path, options).unwrap().frf);
            assert_eq!(planned.freq_hz(), reference.freq_hz(), "{file}");
            let mut worst = 0.0f64;
            let (mut worst_coherence, mut worst_std) = (0.0f64, 0.0f64);
            let (mut worst_measured, mut worst_against_sigma) = (0.0f64, 0.0f64);
            for k in 0..planned.len() {
                let (a, b) = (planned.response()[k], reference.response()[k]);
                let size = a.norm().max(b.norm());
                // Against the line's own standard deviation: the change is
                // eight orders of magnitude below what the record can tell.
                if let Some(d) = planned.std_dev() {
                    if d[k] > 0.0 {
                        worst_against_sigma = worst_against_sigma.max((a - b).norm() / d[k]);
                    }
                    assert!(
                        (a - b).norm() <= 1e-12 * size + 1e-8 * d[k],
                        "{file} line {k}: {a} vs {b}, standard deviation {}",
                        d[k]
                    );
                }
                if size > 0.0 {
                    let rel = (a - b).norm() / size;
                    worst = worst.max(rel);
                    // Only what the record measures: a line at the noise
                    // floor carries the transform's rounding, which is
                    // relative to the segment's whole energy.
                    if planned.std_dev().is_none_or(|d| d[k] <= MEASURED * size) {
                        worst_measured = worst_measured.max(rel);
                    }
                }
                if let (Some(c), Some(d)) = (planned.coherence(), reference.coherence()) {
                    worst_coherence = worst_coherence.max((c[k] - d[k]).abs());
                }
                if let (Some(c), Some(d)) = (planned.std_dev(), reference.std_dev()) {
                    if c[k] != d[k] {
                        worst_std = worst_std.max((c[k] - d[k]).abs() / c[k].abs().max(d[k].abs()));
                    }
                }
            }
            eprintln!(
                "{file}: H1 {worst_measured:e} (measured lines), {worst:e} (all lines), \
                 {worst_against_sigma:e} of the standard deviation; \
                 coherence {worst_coherence:e}; standard deviation {worst_std:e}"
            );
            // Derived from ratios of the averaged spectra, which amplify
            // the transform's rounding (the standard deviation goes with
            // (1 - coherence) / coherence, steep near a coherence of 1).
            assert!(
                worst_coherence <= 1e-10,
                "{file}: coherence {worst_coherence:e}"
            );
            assert!(
                worst_std <= 1e-9,
                "{file}: standard deviation {worst_std:e}"
            );
        }
    }

    /// The H1 estimate's time with the planner's transforms and with the
    /// reference ones, for docs/performance.md (release: `cargo test
    /// --release -p frf --lib -- --ignored h1_speed --nocapture`): the
    /// 500000 samples of SPERTE setup 29 at the default segment length
    /// (a power of two) and at 3000 and 3001 samples (odd lengths).
    #[test]
    #[ignore = "timing; meaningful in release only"]
    fn h1_speed() {
        use crate::recording::read_recording;
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/data/real/sperte/setup29_load_side_v0.5.mat");
        for nfft in [None, Some(3000), Some(3001)] {
            let options = sperte(nfft);
            let samples = read_recording(&path, &options).unwrap().samples.unwrap();
            let time = |f: &dyn Fn() -> H1Estimate| {
                let mut best = f64::INFINITY;
                let mut est = None;
                for _ in 0..7 {
                    let t = std::time::Instant::now();
                    est = Some(f());
                    best = best.min(t.elapsed().as_secs_f64());
                }
                (best, est.unwrap())
            };
            let run = || h1(&samples.u, &samples.y, samples.fs, &options.welch).unwrap();
            let (planned, e) = time(&run);
            let (reference, _) = time(&|| crate::fft::reference::with(run));
            eprintln!(
                "nfft {}: planner {:.1} ms, reference {:.1} ms",
                e.nfft,
                planned * 1e3,
                reference * 1e3
            );
        }
    }
}
