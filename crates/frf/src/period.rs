//! The period of a repeating excitation, read from the signal itself.
//!
//! A multisine, a repeated sweep or a back-and-forth motion profile
//! repeats at a whole number of samples. Estimated over whole periods, its
//! FRF is free of leakage at the excited lines, and the scatter between
//! periods gives each line's noise (see [`crate::welch`]); estimated with
//! Welch windows instead, the lines between the harmonics carry leakage
//! and the harmonics carry the window's bias. A recording that holds its
//! excitation therefore says by itself whether it is periodic.
//!
//! The method: the autocorrelation (by FFT, over the whole record) marks
//! the lags where the signal resembles itself shifted; the first such lag
//! past the signal's own decorrelation is the period if the periods,
//! averaged sample by sample, leave a scatter within
//! [`MAX_REPETITION_SPREAD`] of the signal. The check on the periods, not
//! the autocorrelation alone, decides: a slow or narrow-band signal
//! correlates with itself at many lags without repeating.

use crate::fft::FftPlan;
use crate::welch::WelchOptions;
use num_complex::Complex64;

/// The fewest whole periods a record must hold for its period to be read:
/// the first is the transient, and the scatter between the others needs
/// at least three.
pub const MIN_REPETITIONS: usize = 4;

/// The largest RMS scatter of the periods about their mean, as a share of
/// the mean period's RMS, at which a signal counts as repeating: a
/// recorded excitation repeats to within its measurement noise (a few per
/// cent); noise read at any lag scatters by about its own level (1), and
/// a signal whose period is not a whole number of samples drifts against
/// itself over the record.
pub const MAX_REPETITION_SPREAD: f64 = 0.1;

/// The autocorrelation, as a share of the signal's power, above which a
/// lag is tried as the period.
const LIKENESS: f64 = 0.8;

/// The autocorrelation below which the signal has forgotten itself: lags
/// before the first such one are its own smoothness, not a repetition.
const FORGOTTEN: f64 = 0.5;

/// Lags tried as the period at most (the first local maxima of the
/// autocorrelation above [`LIKENESS`]).
const TRIED: usize = 8;

/// The number of samples after which `x` repeats, or `None` where it does
/// not repeat at least [`MIN_REPETITIONS`] times to within
/// [`MAX_REPETITION_SPREAD`] (random noise, a single sweep, a signal whose
/// period is not a whole number of samples, a constant).
///
/// ```
/// use frf::period::repetition_period;
/// // Six periods of 100 samples of a two-tone signal.
/// let x: Vec<f64> = (0..600)
///     .map(|k| {
///         let t = k as f64 / 100.0;
///         (2.0 * std::f64::consts::PI * 3.0 * t).sin() + 0.5 * (2.0 * std::f64::consts::PI * 7.0 * t).cos()
///     })
///     .collect();
/// assert_eq!(repetition_period(&x), Some(100));
/// // A sweep over the same samples does not repeat.
/// let sweep: Vec<f64> = (0..600).map(|k| (k as f64 * k as f64 / 2000.0).sin()).collect();
/// assert_eq!(repetition_period(&sweep), None);
/// ```
pub fn repetition_period(x: &[f64]) -> Option<usize> {
    let n = x.len();
    if n < 4 * MIN_REPETITIONS || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let m = (2 * n).next_power_of_two();
    let mut z: Vec<Complex64> = x
        .iter()
        .map(|v| Complex64::new(v - mean, 0.0))
        .chain(std::iter::repeat(Complex64::new(0.0, 0.0)))
        .take(m)
        .collect();
    let plan = FftPlan::new(m);
    plan.forward(&mut z);
    z.iter_mut()
        .for_each(|v| *v = Complex64::new(v.norm_sqr(), 0.0));
    plan.inverse(&mut z);
    let r0 = z[0].re;
    if !(r0 > 0.0 && r0.is_finite()) {
        return None;
    }
    // The unbiased autocorrelation as a share of the power: a periodic
    // signal reaches 1 at its period whatever the lag.
    let likeness = |l: usize| z[l].re / r0 * n as f64 / (n - l) as f64;
    let longest = n / MIN_REPETITIONS;
    let start = (1..=longest).find(|&l| likeness(l) < FORGOTTEN)?;
    let mut tried = 0;
    for l in start.max(2)..=longest {
        let here = likeness(l);
        if here < LIKENESS || likeness(l - 1) > here || (l < longest && likeness(l + 1) > here) {
            continue;
        }
        if spread(x, l).is_some_and(|s| s <= MAX_REPETITION_SPREAD) {
            return Some(l);
        }
        tried += 1;
        if tried == TRIED {
            break;
        }
    }
    None
}

/// Where the period of a periodic FRF estimate came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Period {
    /// Given by the caller, in samples.
    Given(usize),
    /// Read from the excitation, which repeats at it ([`repetition_period`]).
    Found(usize),
}

impl Period {
    /// Samples per period.
    pub fn samples(self) -> usize {
        match self {
            Period::Given(p) | Period::Found(p) => p,
        }
    }
}

/// The largest scatter of the output's periods (less a ramp common to
/// them, which the periodic estimate takes out) at which a found period
/// is used: an output in steady state repeats to within its noise; one
/// that drifts faster than a ramp (a free mass pushed by a force with a
/// mean) does not, and its periods would leak into every line.
pub const MAX_OUTPUT_SPREAD: f64 = 0.5;

/// The estimation options for a record with `output` and `signals` that
/// may carry its period, in order of trust (a named excitation alone;
/// else the input, then the output): `asked` as it is where it names a
/// period or a segment length (the caller chose), else with the period of
/// the first signal that repeats ([`repetition_period`]) where the output
/// repeats at it too ([`MAX_OUTPUT_SPREAD`]), so that a periodic record
/// is estimated over whole periods without a flag. The output counts
/// among `signals` because inside a loop the plant input carries the
/// sensor noise fed back, and may not repeat to within
/// [`MAX_REPETITION_SPREAD`] where the motion does. The period, given or
/// found, comes with the options.
///
/// ```
/// use frf::period::{periodic_options, Period};
/// use frf::WelchOptions;
/// let x: Vec<f64> = (0..1000).map(|k| ((k % 50) as f64 / 50.0 * 6.0).sin()).collect();
/// let y: Vec<f64> = x.iter().map(|v| 2.0 * v + 0.001 * x.len() as f64).collect();
/// let (o, p) = periodic_options(&WelchOptions::default(), &[&x], &y);
/// assert_eq!((o.period, p), (Some(50), Some(Period::Found(50))));
/// // A segment length asked for is kept: the caller chose Welch.
/// let asked = WelchOptions { nfft: Some(128), ..Default::default() };
/// assert_eq!(periodic_options(&asked, &[&x], &y), (asked.clone(), None));
/// // An output that runs away quadratically is no periodic response.
/// let away: Vec<f64> = (0..1000).map(|k| x[k] + 1e-4 * (k * k) as f64).collect();
/// assert_eq!(periodic_options(&WelchOptions::default(), &[&x], &away).1, None);
/// ```
pub fn periodic_options(
    asked: &WelchOptions,
    signals: &[&[f64]],
    output: &[f64],
) -> (WelchOptions, Option<Period>) {
    if let Some(p) = asked.period {
        return (asked.clone(), Some(Period::Given(p)));
    }
    if asked.nfft.is_some() {
        return (asked.clone(), None);
    }
    let found = signals
        .iter()
        .find_map(|x| repetition_period(x))
        .filter(|&p| spread(&without_ramp(output, p), p).is_some_and(|s| s <= MAX_OUTPUT_SPREAD));
    match found {
        Some(p) => (
            WelchOptions {
                period: Some(p),
                ..asked.clone()
            },
            Some(Period::Found(p)),
        ),
        None => (asked.clone(), None),
    }
}

/// The RMS of the periods of `period` samples (the first, the transient,
/// left out) about their sample-by-sample mean, over the mean period's
/// RMS about its own mean; `None` with fewer than three such periods or
/// a mean period without power.
pub fn spread(x: &[f64], period: usize) -> Option<f64> {
    let periods = x.len().checked_div(period)?;
    if periods < 3 {
        return None;
    }
    let rest = &x[period..periods * period];
    let k = (periods - 1) as f64;
    let mut mean = vec![0.0; period];
    for c in rest.chunks_exact(period) {
        mean.iter_mut().zip(c).for_each(|(m, v)| *m += v / k);
    }
    let level = mean.iter().sum::<f64>() / period as f64;
    let power = mean.iter().map(|v| (v - level).powi(2)).sum::<f64>() / period as f64;
    if !(power > 0.0 && power.is_finite()) {
        return None;
    }
    let scatter = rest
        .chunks_exact(period)
        .flat_map(|c| c.iter().zip(&mean).map(|(a, b)| (a - b).powi(2)))
        .sum::<f64>()
        / rest.len() as f64;
    Some((scatter / power).sqrt())
}

/// `x` less the straight line through the means of its whole periods
/// after the first (as the periodic estimate takes it out).
fn without_ramp(x: &[f64], period: usize) -> Vec<f64> {
    let periods = x.len() / period.max(1);
    if periods < 3 {
        return x.to_vec();
    }
    let starts: Vec<usize> = (1..periods).map(|p| p * period).collect();
    crate::welch::without_ramp(x, &starts, period)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Xorshift(u64);
    impl Xorshift {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// A periodic random signal with 5 % noise on top is read at its
    /// period, not at a multiple; the same noise alone is not periodic.
    #[test]
    fn a_noisy_periodic_signal_is_read_at_its_period() {
        let mut rng = Xorshift(3);
        let one: Vec<f64> = (0..777).map(|_| rng.next()).collect();
        let x: Vec<f64> = (0..777 * 9)
            .map(|k| one[k % 777] + 0.05 * rng.next())
            .collect();
        assert_eq!(repetition_period(&x), Some(777));
        let noise: Vec<f64> = (0..777 * 9).map(|_| rng.next()).collect();
        assert_eq!(repetition_period(&noise), None);
    }

    /// Raised-cosine force pulses back and forth, with pauses: smooth over
    /// hundreds of samples and half-wave antisymmetric, so the
    /// autocorrelation is high at short lags and -1 at half the period.
    #[test]
    fn a_motion_profile_is_read_at_its_cycle() {
        let len = 300;
        let cycle = 2 * (2 * len + len / 2);
        let shape = |i: usize| -> f64 {
            let j = i % cycle;
            let dir = if j < cycle / 2 { 1.0 } else { -1.0 };
            let j = j % (cycle / 2);
            if j >= 2 * len {
                return 0.0;
            }
            let s = if j < len { 1.0 } else { -1.0 };
            let phase = (j % len) as f64 / len as f64;
            dir * s * (std::f64::consts::PI * phase).sin().powi(2)
        };
        let x: Vec<f64> = (0..cycle * 5 + 123).map(shape).collect();
        assert_eq!(repetition_period(&x), Some(cycle));
        // Three cycles are too few to read a period and its scatter.
        let short: Vec<f64> = (0..cycle * 3 + 10).map(shape).collect();
        assert_eq!(repetition_period(&short), None);
    }

    /// A sine whose period is not a whole number of samples drifts
    /// against itself over a long record and is not taken as periodic.
    #[test]
    fn a_period_between_samples_is_not_read() {
        let x: Vec<f64> = (0..200_000)
            .map(|k| (2.0 * std::f64::consts::PI * k as f64 / 100.37).sin())
            .collect();
        assert_eq!(repetition_period(&x), None);
        assert_eq!(repetition_period(&[0.0; 1000]), None);
        assert_eq!(repetition_period(&[1.0, f64::NAN, 2.0]), None);
    }
}
