//! # frf: measured frequency response functions
//!
//! The measurement layer of `mms`: it turns files into a validated [`Frf`]
//! (frequencies in Hz, complex response, optional coherence) and knows
//! nothing of masses or models.
//!
//! Modules:
//! * [`recording`]: the entry point [`read_recording`], which picks the
//!   format by extension and content and returns a [`Recording`]; errors
//!   name the file and the line, variable or dataset;
//! * [`csv`]: FRF CSV (`freq_hz,re,im` or `freq_hz,mag_db,phase_deg`,
//!   optional `coherence`) reader and writer, time-domain CSV, headerless
//!   numeric matrices;
//! * [`uff`]: universal file dataset 58 (ASCII) reader and writer;
//! * [`mat`]: MATLAB level-5 MAT-file reader (numeric variables,
//!   uncompressed or zlib-compressed);
//! * [`period`]: the period of a repeating excitation, read from the
//!   signal;
//! * [`welch`]: H1 estimation with Welch averaging, for random or periodic
//!   excitation, with a standard deviation per line;
//! * [`uncertainty`]: the relative uncertainty of every line, from the
//!   FRF's standard deviation, its coherence or the scatter of the data;
//! * [`fft`]: the discrete Fourier transform of any length (radix-2 and
//!   Bluestein).
//!
//! ```
//! use frf::Frf;
//! use num_complex::Complex64;
//!
//! let frf = Frf::new(
//!     vec![1.0, 2.0, 3.0],
//!     vec![Complex64::new(1.0, 0.0), Complex64::new(0.5, -0.5), Complex64::new(0.1, -0.2)],
//!     None,
//! )?;
//! assert_eq!(frf.len(), 3);
//! assert!(Frf::new(vec![2.0, 1.0], vec![Complex64::new(1.0, 0.0); 2], None).is_err());
//! # Ok::<(), frf::FrfError>(())
//! ```

#![warn(missing_docs)]

pub mod csv;
pub mod fft;
pub mod mat;
pub mod period;
pub mod recording;
pub mod uff;
pub mod uncertainty;
pub mod welch;

pub use csv::{parse_frf_csv, write_csv, CsvLayout};
pub use num_complex::Complex64;
pub use recording::{
    read_recording, Recording, RecordingError, RecordingOptions, Samples, SignalRef, Source,
};
pub use uff::{parse_uff, write_frf_uff, Spacing};
pub use uncertainty::{line_uncertainty, LineUncertainty};
pub use welch::{h1, H1Estimate, WelchOptions, Window};

/// Fewest frequency lines the file readers accept: fewer cannot show a
/// resonance, and usually mean a truncated or mis-read file.
pub const MIN_LINES: usize = 10;

/// A frequency response function on a grid of frequency lines.
///
/// Invariants (checked by [`Frf::new`] and [`Frf::with_std_dev`]): at least
/// one line; all vectors of equal length; frequencies finite, non-negative
/// and strictly increasing; response values finite; coherence, where
/// given, finite and in `[0, 1]`; standard deviation, where given,
/// non-negative and not NaN (`+inf` marks a line that carries no
/// information, e.g. one the excitation did not reach).
#[derive(Clone, Debug, PartialEq)]
pub struct Frf {
    freq_hz: Vec<f64>,
    response: Vec<Complex64>,
    coherence: Option<Vec<f64>>,
    std_dev: Option<Vec<f64>>,
}

/// Why a set of vectors is not a valid [`Frf`]. Line numbers are 0-based
/// indices into the vectors; readers of files translate them to file
/// lines.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FrfError {
    /// No frequency lines at all.
    #[error("no frequency lines")]
    Empty,
    /// The vectors differ in length.
    #[error("{what} has {got} values, expected {expected}")]
    Length {
        /// Which vector.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The number of frequencies.
        expected: usize,
    },
    /// A NaN or infinite value.
    #[error("{what} at index {index} is not finite")]
    NotFinite {
        /// Which vector.
        what: &'static str,
        /// Index of the value.
        index: usize,
    },
    /// A negative frequency.
    #[error("frequency at index {index} is negative ({value} Hz)")]
    NegativeFrequency {
        /// Index of the value.
        index: usize,
        /// The frequency.
        value: f64,
    },
    /// A frequency above [`MAX_FREQUENCY_HZ`].
    #[error("frequency at index {index} ({value:e} Hz) is above {max:e} Hz", max = MAX_FREQUENCY_HZ)]
    FrequencyRange {
        /// Index of the value.
        index: usize,
        /// The frequency.
        value: f64,
    },
    /// Frequencies not strictly increasing.
    #[error("frequency at index {index} ({value} Hz) does not increase")]
    NotIncreasing {
        /// Index of the value.
        index: usize,
        /// The frequency.
        value: f64,
    },
    /// Coherence outside `[0, 1]`.
    #[error("coherence at index {index} is {value}, outside [0, 1]")]
    CoherenceRange {
        /// Index of the value.
        index: usize,
        /// The coherence.
        value: f64,
    },
    /// A standard deviation that is negative or NaN.
    #[error("standard deviation at index {index} is {value}, not >= 0")]
    StdDevRange {
        /// Index of the value.
        index: usize,
        /// The standard deviation.
        value: f64,
    },
}

/// The highest frequency an FRF line may have, Hz: the top of
/// [`recording::SAMPLE_RATE_RANGE_HZ`]; a line above it is a unit or
/// parsing mistake (`1e300` Hz), not a measurement.
///
/// ```
/// use frf::{Complex64, Frf};
/// let err = Frf::new(vec![1.0, 1e300], vec![Complex64::new(1.0, 0.0); 2], None).unwrap_err();
/// assert_eq!(err.message_without_index(), "frequency 1e300 Hz is above 1e12 Hz");
/// ```
pub const MAX_FREQUENCY_HZ: f64 = recording::SAMPLE_RATE_RANGE_HZ.1;

impl FrfError {
    /// The 0-based index of the offending value, if the error has one.
    ///
    /// ```
    /// use frf::{Complex64, Frf};
    /// let err = Frf::new(vec![1.0, 3.0, 2.0], vec![Complex64::new(1.0, 0.0); 3], None).unwrap_err();
    /// assert_eq!(err.index(), Some(2));
    /// ```
    pub fn index(&self) -> Option<usize> {
        match self {
            FrfError::Empty | FrfError::Length { .. } => None,
            FrfError::NotFinite { index, .. }
            | FrfError::NegativeFrequency { index, .. }
            | FrfError::FrequencyRange { index, .. }
            | FrfError::NotIncreasing { index, .. }
            | FrfError::CoherenceRange { index, .. }
            | FrfError::StdDevRange { index, .. } => Some(*index),
        }
    }

    /// The message without the index, for readers that report the place
    /// themselves (a file line, say).
    ///
    /// ```
    /// use frf::{Complex64, Frf};
    /// let err = Frf::new(vec![1.0, -2.0], vec![Complex64::new(1.0, 0.0); 2], None).unwrap_err();
    /// assert_eq!(err.message_without_index(), "frequency -2 Hz is negative");
    /// ```
    pub fn message_without_index(&self) -> String {
        match self {
            FrfError::NotFinite { what, .. } => format!("{what} is not finite"),
            FrfError::NegativeFrequency { value, .. } => {
                format!("frequency {value} Hz is negative")
            }
            FrfError::FrequencyRange { value, .. } => {
                format!("frequency {value:e} Hz is above {MAX_FREQUENCY_HZ:e} Hz")
            }
            FrfError::NotIncreasing { value, .. } => {
                format!("frequency {value} Hz does not increase")
            }
            FrfError::CoherenceRange { value, .. } => {
                format!("coherence {value} is outside [0, 1]")
            }
            FrfError::StdDevRange { value, .. } => {
                format!("standard deviation {value} is not >= 0")
            }
            FrfError::Empty | FrfError::Length { .. } => self.to_string(),
        }
    }
}

impl Frf {
    /// A validated FRF; see the type's invariants.
    pub fn new(
        freq_hz: Vec<f64>,
        response: Vec<Complex64>,
        coherence: Option<Vec<f64>>,
    ) -> Result<Frf, FrfError> {
        let n = freq_hz.len();
        if n == 0 {
            return Err(FrfError::Empty);
        }
        if response.len() != n {
            return Err(FrfError::Length {
                what: "response",
                got: response.len(),
                expected: n,
            });
        }
        for (index, &f) in freq_hz.iter().enumerate() {
            if !f.is_finite() {
                return Err(FrfError::NotFinite {
                    what: "frequency",
                    index,
                });
            }
            if f < 0.0 {
                return Err(FrfError::NegativeFrequency { index, value: f });
            }
            if f > MAX_FREQUENCY_HZ {
                return Err(FrfError::FrequencyRange { index, value: f });
            }
            if index > 0 && f <= freq_hz[index - 1] {
                return Err(FrfError::NotIncreasing { index, value: f });
            }
        }
        if let Some(index) = response
            .iter()
            .position(|z| !z.re.is_finite() || !z.im.is_finite())
        {
            return Err(FrfError::NotFinite {
                what: "response",
                index,
            });
        }
        if let Some(c) = &coherence {
            if c.len() != n {
                return Err(FrfError::Length {
                    what: "coherence",
                    got: c.len(),
                    expected: n,
                });
            }
            for (index, &value) in c.iter().enumerate() {
                if !value.is_finite() {
                    return Err(FrfError::NotFinite {
                        what: "coherence",
                        index,
                    });
                }
                if !(0.0..=1.0).contains(&value) {
                    return Err(FrfError::CoherenceRange { index, value });
                }
            }
        }
        Ok(Frf {
            freq_hz,
            response,
            coherence,
            std_dev: None,
        })
    }

    /// The same FRF with a standard deviation per line: the standard
    /// deviation of the estimate's error `H_est - H` in each of its real and
    /// imaginary parts (a circular error), in the units of the response.
    /// Divided by `|H|` it is the standard deviation of `ln|H|` in nepers
    /// and of the phase in radians. `+inf` marks a line without
    /// information.
    ///
    /// ```
    /// use frf::{Complex64, Frf};
    /// let frf = Frf::new(vec![1.0, 2.0], vec![Complex64::new(2.0, 0.0); 2], None)?
    ///     .with_std_dev(vec![0.2, f64::INFINITY])?;
    /// assert_eq!(frf.relative_std_dev().unwrap(), vec![0.1, f64::INFINITY]);
    /// assert!(frf.clone().with_std_dev(vec![0.1, -1.0]).is_err());
    /// # Ok::<(), frf::FrfError>(())
    /// ```
    pub fn with_std_dev(mut self, std_dev: Vec<f64>) -> Result<Frf, FrfError> {
        if std_dev.len() != self.len() {
            return Err(FrfError::Length {
                what: "standard deviation",
                got: std_dev.len(),
                expected: self.len(),
            });
        }
        if let Some(index) = std_dev.iter().position(|s| s.is_nan() || *s < 0.0) {
            return Err(FrfError::StdDevRange {
                index,
                value: std_dev[index],
            });
        }
        self.std_dev = Some(std_dev);
        Ok(self)
    }

    /// The same FRF with the sign of the response turned (a sensor that
    /// counts the other way); coherence and standard deviation unchanged.
    ///
    /// ```
    /// use frf::{Complex64, Frf};
    /// let frf = Frf::new(vec![1.0], vec![Complex64::new(2.0, -1.0)], Some(vec![0.9]))?;
    /// let turned = frf.negated();
    /// assert_eq!(turned.response()[0], Complex64::new(-2.0, 1.0));
    /// assert_eq!(turned.coherence(), frf.coherence());
    /// # Ok::<(), frf::FrfError>(())
    /// ```
    pub fn negated(&self) -> Frf {
        Frf {
            response: self.response.iter().map(|z| -z).collect(),
            ..self.clone()
        }
    }

    /// The standard deviation of each line, if the FRF was estimated or
    /// read with one (see [`Frf::with_std_dev`]).
    pub fn std_dev(&self) -> Option<&[f64]> {
        self.std_dev.as_deref()
    }

    /// The standard deviation of each line relative to its magnitude:
    /// that of `ln|H|` in nepers and of the phase in radians (`+inf` where
    /// the response is 0). `None` without a standard deviation.
    pub fn relative_std_dev(&self) -> Option<Vec<f64>> {
        self.std_dev.as_ref().map(|s| {
            s.iter()
                .zip(&self.response)
                .map(|(s, h)| {
                    let a = h.norm();
                    if a > 0.0 {
                        s / a
                    } else {
                        f64::INFINITY
                    }
                })
                .collect()
        })
    }

    /// Number of frequency lines.
    pub fn len(&self) -> usize {
        self.freq_hz.len()
    }

    /// Never true: an [`Frf`] has at least one line.
    pub fn is_empty(&self) -> bool {
        self.freq_hz.is_empty()
    }

    /// Frequencies in Hz, strictly increasing.
    pub fn freq_hz(&self) -> &[f64] {
        &self.freq_hz
    }

    /// Complex response at each frequency (output per input, in the units
    /// of the recording).
    pub fn response(&self) -> &[Complex64] {
        &self.response
    }

    /// Coherence at each frequency, if the FRF was estimated or read with
    /// one.
    pub fn coherence(&self) -> Option<&[f64]> {
        self.coherence.as_deref()
    }

    /// The lines with `lo_hz <= f <= hi_hz`, or `None` if there are none.
    pub fn band(&self, lo_hz: f64, hi_hz: f64) -> Option<Frf> {
        let keep: Vec<usize> = (0..self.len())
            .filter(|&i| self.freq_hz[i] >= lo_hz && self.freq_hz[i] <= hi_hz)
            .collect();
        self.lines(&keep)
    }

    /// The lines at the given indices (strictly increasing, in range), with
    /// their coherence and standard deviation; `None` if `keep` is empty,
    /// not increasing or out of range.
    ///
    /// ```
    /// use frf::{Complex64, Frf};
    /// let frf = Frf::new(vec![1.0, 2.0, 3.0], vec![Complex64::new(1.0, 0.0); 3], None)?
    ///     .with_std_dev(vec![0.1, 0.2, 0.3])?;
    /// let odd = frf.lines(&[0, 2]).unwrap();
    /// assert_eq!(odd.freq_hz(), &[1.0, 3.0]);
    /// assert_eq!(odd.std_dev().unwrap(), &[0.1, 0.3]);
    /// assert!(frf.lines(&[2, 0]).is_none());
    /// # Ok::<(), frf::FrfError>(())
    /// ```
    pub fn lines(&self, keep: &[usize]) -> Option<Frf> {
        let valid = !keep.is_empty()
            && keep.windows(2).all(|w| w[0] < w[1])
            && keep.last().is_some_and(|&i| i < self.len());
        if !valid {
            return None;
        }
        let pick = |v: &Vec<f64>| keep.iter().map(|&i| v[i]).collect();
        Some(Frf {
            freq_hz: pick(&self.freq_hz),
            response: keep.iter().map(|&i| self.response[i]).collect(),
            coherence: self.coherence.as_ref().map(pick),
            std_dev: self.std_dev.as_ref().map(pick),
        })
    }
}
