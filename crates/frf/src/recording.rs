//! One entry point for measurement files: [`read_recording`].
//!
//! The format follows the extension, and the content where the extension
//! leaves it open:
//!
//! | extension | content | result |
//! |---|---|---|
//! | `.csv` | header with `freq_hz` | FRF as written ([`crate::csv`]) |
//! | `.csv` | other header | time domain, default columns `t,u,y` |
//! | `.uff`, `.unv`, `.58` | universal file, dataset 58 ([`crate::uff`]) | FRF as written |
//! | `.mat` | MATLAB level-5 MAT-file ([`crate::mat`]) | time domain |
//! | `.dat`, `.txt` | whitespace-separated numbers, no header | time domain, columns by number |
//! | other | sniffed: MAT header, UFF `-1` line, a CSV header, else numbers | as above |
//!
//! Time-domain recordings are turned into an FRF with the H1 estimator of
//! [`crate::welch`] (options in [`RecordingOptions::welch`]); a caller
//! that wants a repeating record estimated over its periods without
//! naming one finds them with [`crate::period::periodic_options`].
//!
//! **Signals** are named with [`SignalRef`], the CLI syntax `VAR[:COL]`:
//! a `.mat` variable or a CSV column name, or a column number (from 1) for
//! headerless matrices. For a `.mat` matrix variable, samples run along
//! the longer dimension and `COL` (from 1) picks a channel along the
//! shorter one: `Acceleration:1` is the first row of a 3 x N variable, and
//! `result:2` the second column of an N x 2 one (a square matrix counts
//! its rows as samples). A vector needs no `COL`.
//!
//! **Defaults** where unambiguous: CSV columns `u` and `y` (and `t` for the
//! sample rate); a `.mat` file whose only non-scalar numeric variable
//! (besides a time vector `t`) has two channels gives `u` = channel 1 and
//! `y` = channel 2; a two-column matrix gives `u` = 1, `y` = 2. Otherwise
//! the error lists what is available.
//!
//! **Sample rate**: [`RecordingOptions::fs`] wins; else for `.mat` a scalar
//! variable `Fs` or `fs`, else a time vector `t`; for CSV the `t` column;
//! a headerless matrix needs `fs`.
//!
//! **Errors** ([`RecordingError`]) print as one line naming the file and
//! the place: `path:LINE: message` for text files, `path: variable 'Force':
//! message` for MAT-files, `path: dataset 2 (line 40): message` for
//! universal files, `path: message` for the file as a whole.
//!
//! ```
//! use frf::recording::{read_recording, RecordingOptions, Source};
//!
//! let dir = std::env::temp_dir().join(format!("frf-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("motor.csv");
//! let mut text = String::from("# drive test\nfreq_hz,mag_db,phase_deg\n");
//! for k in 1..=20 {
//!     text.push_str(&format!("{k},{},-90\n", -40.0 * (k as f64).log10()));
//! }
//! std::fs::write(&path, text).unwrap();
//! let rec = read_recording(&path, &RecordingOptions::default())?;
//! assert_eq!(rec.source, Source::FrfFile);
//! assert_eq!(rec.frf.len(), 20);
//!
//! std::fs::write(&path, "freq_hz,re,im\n1,2,3\n2,nan,1\n").unwrap();
//! let err = read_recording(&path, &RecordingOptions::default()).unwrap_err();
//! assert_eq!(err.to_string(), format!("{}:3: column 're': 'nan' is not a finite number", path.display()));
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok::<(), frf::recording::RecordingError>(())
//! ```

use crate::csv::{self, CsvError};
use crate::mat::{self, MatError, MatFile, MatVariable};
use crate::period::Period;
use crate::uff::{self, UffError};
use crate::welch::{self, sample_rate_from_times, WelchOptions};
use crate::{Frf, MIN_LINES};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A signal named as `VAR[:COL]`; see the [module documentation](self).
///
/// ```
/// use frf::recording::SignalRef;
/// let s: SignalRef = "Acceleration:2".parse().unwrap();
/// assert_eq!((s.name.as_str(), s.channel), ("Acceleration", Some(2)));
/// let s: SignalRef = "vir".parse().unwrap();
/// assert_eq!(s.channel, None);
/// assert_eq!(s.to_string(), "vir");
/// assert!("x:0".parse::<SignalRef>().is_err());
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SignalRef {
    /// Variable or column name, or a column number for headerless
    /// matrices.
    pub name: String,
    /// Channel of a matrix variable, counted from 1.
    pub channel: Option<usize>,
}

impl SignalRef {
    /// A reference without a channel.
    pub fn new(name: impl Into<String>) -> SignalRef {
        SignalRef {
            name: name.into(),
            channel: None,
        }
    }

    /// A reference to one channel (from 1) of a matrix variable.
    pub fn channel(name: impl Into<String>, channel: usize) -> SignalRef {
        SignalRef {
            name: name.into(),
            channel: Some(channel),
        }
    }
}

impl FromStr for SignalRef {
    type Err = String;

    fn from_str(s: &str) -> Result<SignalRef, String> {
        let s = s.trim();
        // Only a numeric suffix is a channel, so names with ':' in them
        // (CSV headers) still work.
        let (name, channel) = match s.rsplit_once(':') {
            Some((n, c)) if !c.is_empty() && c.bytes().all(|b| b.is_ascii_digit()) => {
                let c: usize = c
                    .parse()
                    .map_err(|_| format!("'{s}': channel number too large"))?;
                if c == 0 {
                    return Err(format!("'{s}': channels count from 1"));
                }
                (n.trim(), Some(c))
            }
            _ => (s, None),
        };
        if name.is_empty() {
            return Err(format!("'{s}': empty signal name"));
        }
        Ok(SignalRef {
            name: name.to_string(),
            channel,
        })
    }
}

impl fmt::Display for SignalRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.channel {
            Some(c) => write!(f, "{}:{c}", self.name),
            None => f.write_str(&self.name),
        }
    }
}

/// How to read a recording. `Default` picks everything automatically.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RecordingOptions {
    /// Input signal (time-domain files only).
    pub u: Option<SignalRef>,
    /// Output signal (time-domain files only).
    pub y: Option<SignalRef>,
    /// Sample rate in Hz; overrides the file's.
    pub fs: Option<f64>,
    /// The .mat variable (a positive scalar, e.g. `Data.settings.fs`) that
    /// holds the sample rate; overrides the file's own.
    pub fs_variable: Option<String>,
    /// H1 estimation options for time-domain files.
    pub welch: WelchOptions,
    /// Universal files: the dataset to read, by its position in the file
    /// (from 1, counting every dataset). Needed when the file holds more
    /// than one FRF.
    pub dataset: Option<usize>,
    /// The excitation injected into a closed loop (time-domain files):
    /// the FRF is then the 3-point estimate `S_xy / S_xu`
    /// ([`crate::welch::three_point`]) instead of H1 from `u` to `y`.
    pub excitation: Option<SignalRef>,
}

/// The kind of file that was read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// CSV with `freq_hz`.
    FrfCsv,
    /// CSV with time-domain columns.
    TimeCsv,
    /// Headerless numeric matrix.
    Matrix,
    /// Universal file, dataset 58.
    Uff,
    /// MATLAB level-5 MAT-file.
    Mat,
}

/// Where the FRF of a [`Recording`] came from.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// Read as written from an FRF file.
    FrfFile,
    /// Estimated (H1, Welch) from time-domain samples.
    TimeDomain {
        /// Sample rate in Hz.
        fs: f64,
        /// Samples per signal.
        n_samples: usize,
        /// Segments averaged.
        averages: usize,
        /// Segment length.
        nfft: usize,
        /// The input signal, e.g. `result:1`.
        input: String,
        /// The output signal.
        output: String,
        /// The period of a periodic estimate: given, or found in the
        /// excitation, which repeats at it; `None` for Welch's averages.
        period: Option<Period>,
    },
}

impl Source {
    /// The estimation options behind this FRF, from those `asked`: with
    /// the period where one was found in the excitation, so that cuts and
    /// re-estimates of the samples are read the same way.
    ///
    /// ```
    /// use frf::period::Period;
    /// use frf::{Source, WelchOptions};
    /// let source = Source::TimeDomain {
    ///     fs: 1000.0,
    ///     n_samples: 8000,
    ///     averages: 7,
    ///     nfft: 1000,
    ///     input: "u".into(),
    ///     output: "y".into(),
    ///     period: Some(Period::Found(1000)),
    /// };
    /// assert_eq!(source.welch(&WelchOptions::default()).period, Some(1000));
    /// assert_eq!(Source::FrfFile.welch(&WelchOptions::default()).period, None);
    /// ```
    pub fn welch(&self, asked: &WelchOptions) -> WelchOptions {
        match self {
            Source::TimeDomain {
                period: Some(Period::Found(p)),
                ..
            } => WelchOptions {
                period: Some(*p),
                ..asked.clone()
            },
            _ => asked.clone(),
        }
    }
}

/// The samples a time-domain recording's FRF was estimated from.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples {
    /// Input signal.
    pub u: Vec<f64>,
    /// Output signal.
    pub y: Vec<f64>,
    /// Sample rate, Hz.
    pub fs: f64,
    /// The excitation injected into a closed loop, if one was named.
    pub excitation: Option<Vec<f64>>,
}

impl Samples {
    /// The FRF of the samples in `range` with `welch`: the 3-point
    /// estimate from the excitation if there is one, else H1.
    pub fn frf(
        &self,
        range: std::ops::Range<usize>,
        welch: &WelchOptions,
    ) -> Result<Frf, crate::welch::WelchError> {
        let (u, y) = (&self.u[range.clone()], &self.y[range.clone()]);
        match &self.excitation {
            Some(x) => Ok(crate::welch::three_point(&x[range], u, y, self.fs, welch)?.plant),
            None => Ok(welch::h1(u, y, self.fs, welch)?.frf),
        }
    }
}

/// A measured FRF and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: Format,
    /// The FRF, with coherence where the file gave one or it was
    /// estimated.
    pub frf: Frf,
    /// FRF file or time domain.
    pub source: Source,
    /// The input and output samples of a time-domain recording (for
    /// time-domain analyses); `None` for FRF files.
    pub samples: Option<Samples>,
    /// With an excitation: the loop functions behind the 3-point FRF.
    pub excitation: Option<Excitation>,
    /// Without one: signals of the file that look like an excitation
    /// injected into a closed loop (named `d`, `r`, `w`, `noise`,
    /// `excitation`, `disturbance` or `dist`, as long as the input), which
    /// `--excitation` could use.
    pub possible_excitations: Vec<String>,
}

/// The loop functions of a 3-point estimate, from the excitation.
#[derive(Clone, Debug, PartialEq)]
pub struct Excitation {
    /// The excitation signal's name.
    pub name: String,
    /// From the excitation to the plant input: the sensitivity when the
    /// excitation is added at the plant input.
    pub sensitivity: Frf,
    /// From the excitation to the output: the process sensitivity.
    pub process_sensitivity: Frf,
}

impl Excitation {
    /// The median coherence from the excitation to the plant input and to
    /// the output, over the excited lines (finite uncertainty).
    pub fn median_coherences(&self) -> (f64, f64) {
        let median = |f: &Frf| -> f64 {
            let sd = f.std_dev();
            let mut c: Vec<f64> = f
                .coherence()
                .unwrap_or(&[])
                .iter()
                .enumerate()
                .filter(|(k, _)| sd.is_none_or(|s| s[*k].is_finite()))
                .map(|(_, &g)| g)
                .collect();
            if c.is_empty() {
                return f64::NAN;
            }
            c.sort_by(f64::total_cmp);
            c[c.len() / 2]
        };
        (median(&self.sensitivity), median(&self.process_sensitivity))
    }

    /// The modulus margin's reciprocal, `max |S|` in dB, and where, over
    /// the lines with finite uncertainty (excited lines).
    pub fn peak_sensitivity_db(&self) -> Option<(f64, f64)> {
        let sd = self.sensitivity.std_dev();
        let f = self.sensitivity.freq_hz();
        self.sensitivity
            .response()
            .iter()
            .enumerate()
            .filter(|(k, h)| h.is_finite() && sd.is_none_or(|s| s[*k].is_finite()))
            .map(|(k, h)| (20.0 * h.norm().log10(), f[k]))
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }
}

/// Why a recording could not be read. Displays as one line naming the file
/// and the place.
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    /// The file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A problem with the file as a whole (or with the options for it).
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A problem at a line of a text file.
    #[error("{}:{line}: {message}", path.display())]
    Text {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A problem with a variable of a MAT-file.
    #[error("{}: variable '{variable}': {message}", path.display())]
    Variable {
        /// The file.
        path: PathBuf,
        /// The variable.
        variable: String,
        /// What is wrong.
        message: String,
    },
    /// A problem in a dataset of a universal file.
    #[error("{}: dataset {dataset} (line {line}): {message}", path.display())]
    Dataset {
        /// The file.
        path: PathBuf,
        /// 1-based position of the dataset in the file.
        dataset: usize,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

impl RecordingError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            RecordingError::Io { path, .. }
            | RecordingError::File { path, .. }
            | RecordingError::Text { path, .. }
            | RecordingError::Variable { path, .. }
            | RecordingError::Dataset { path, .. } => path,
        }
    }
}

/// Control characters from the file (a stray `\r`, bytes of a garbled
/// name) would break the one-line display: they become `?`.
fn one_line(s: impl Into<String>) -> String {
    s.into()
        .chars()
        .map(|c| if c.is_control() { '?' } else { c })
        .collect()
}

/// Builds errors for one file.
struct Ctx<'a> {
    path: &'a Path,
    /// Signals that look like an excitation ([`Recording::possible_excitations`]).
    possible_excitations: std::cell::RefCell<Vec<String>>,
    /// The samples behind an estimate, kept for [`Recording::samples`].
    samples: std::cell::RefCell<Option<Samples>>,
    /// The loop functions of a 3-point estimate.
    excitation: std::cell::RefCell<Option<Excitation>>,
}

impl Ctx<'_> {
    fn file(&self, message: impl Into<String>) -> RecordingError {
        RecordingError::File {
            path: self.path.to_path_buf(),
            message: one_line(message),
        }
    }

    fn variable(&self, variable: &str, message: impl Into<String>) -> RecordingError {
        RecordingError::Variable {
            path: self.path.to_path_buf(),
            variable: one_line(variable),
            message: one_line(message),
        }
    }

    fn csv(&self, e: CsvError) -> RecordingError {
        match e.line {
            Some(line) => RecordingError::Text {
                path: self.path.to_path_buf(),
                line,
                message: one_line(e.message),
            },
            None => self.file(e.message),
        }
    }

    fn uff(&self, e: UffError) -> RecordingError {
        match e.dataset {
            Some(dataset) => RecordingError::Dataset {
                path: self.path.to_path_buf(),
                dataset,
                line: e.line,
                message: one_line(e.message),
            },
            None => RecordingError::Text {
                path: self.path.to_path_buf(),
                line: e.line,
                message: one_line(e.message),
            },
        }
    }

    fn mat(&self, e: MatError) -> RecordingError {
        match e.variable {
            Some(v) => self.variable(&v, e.message),
            None => self.file(e.message),
        }
    }
}

/// The sample rates a recording may have, Hz: positive, finite, and
/// within what a measurement of a motion system can be (a sample a week
/// to a terahertz); anything outside is a unit or parsing mistake.
pub const SAMPLE_RATE_RANGE_HZ: (f64, f64) = (1e-6, 1e12);

/// `Ok` for a sample rate inside [`SAMPLE_RATE_RANGE_HZ`], else why not.
///
/// ```
/// use frf::recording::check_sample_rate;
/// assert!(check_sample_rate(4000.0).is_ok());
/// assert!(check_sample_rate(-5.0).unwrap_err().contains("positive"));
/// assert!(check_sample_rate(1e-320).unwrap_err().contains("outside"));
/// assert!(check_sample_rate(f64::NAN).is_err());
/// ```
pub fn check_sample_rate(fs: f64) -> Result<(), String> {
    let (lo, hi) = SAMPLE_RATE_RANGE_HZ;
    if !(fs.is_finite() && fs > 0.0) {
        return Err(format!(
            "sample rate {fs} Hz is not a positive finite number"
        ));
    }
    if !(lo..=hi).contains(&fs) {
        return Err(format!(
            "sample rate {fs:e} Hz is outside {lo:e} to {hi:e} Hz"
        ));
    }
    Ok(())
}

/// The largest spread of a periodic excitation's periods about their
/// mean (after the first, the transient), as a share of the mean
/// period's RMS, above which a period is refused: a recorded input
/// repeats to within its noise; read at a wrong period, the periods are
/// as unlike as random signals (a spread of about the square root of the
/// number of periods less one).
pub const MAX_PERIOD_SPREAD: f64 = 0.5;

/// Reads a measurement file into an FRF; see the
/// [module documentation](self) for formats, defaults and errors.
///
/// ```
/// use frf::recording::{read_recording, RecordingOptions, Source};
///
/// // A time-domain CSV: y[n] = 2 u[n-1], sampled at 100 Hz.
/// let mut s = 1u64;
/// let u: Vec<f64> = (0..2048)
///     .map(|_| { s = s.wrapping_mul(6364136223846793005).wrapping_add(1); (s >> 11) as f64 / 2f64.powi(53) - 0.5 })
///     .collect();
/// let mut text = String::from("t,u,y\n");
/// for n in 0..u.len() {
///     let y = if n > 0 { 2.0 * u[n - 1] } else { 0.0 };
///     text.push_str(&format!("{},{},{y}\n", n as f64 / 100.0, u[n]));
/// }
/// let path = std::env::temp_dir().join(format!("frf-doc-rec-{}.csv", std::process::id()));
/// std::fs::write(&path, text).unwrap();
///
/// let rec = read_recording(&path, &RecordingOptions::default())?;
/// let Source::TimeDomain { fs, nfft, averages, .. } = rec.source else { unreachable!() };
/// assert_eq!((fs, nfft, averages), (100.0, 128, 31));
/// assert!((rec.frf.response()[0].norm() - 2.0).abs() < 0.05);
/// # std::fs::remove_file(&path).unwrap();
/// # Ok::<(), frf::recording::RecordingError>(())
/// ```
pub fn read_recording(
    path: impl AsRef<Path>,
    opts: &RecordingOptions,
) -> Result<Recording, RecordingError> {
    let path = path.as_ref();
    let ctx = Ctx {
        path,
        possible_excitations: std::cell::RefCell::new(Vec::new()),
        samples: std::cell::RefCell::new(None),
        excitation: std::cell::RefCell::new(None),
    };
    let bytes = std::fs::read(path).map_err(|source| RecordingError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    if let Some(fs) = opts.fs {
        check_sample_rate(fs).map_err(|why| ctx.file(why))?;
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let kind = match ext.as_str() {
        "csv" => Kind::Csv,
        "uff" | "unv" | "58" => Kind::Uff,
        "mat" => Kind::Mat,
        "dat" | "txt" => Kind::Matrix,
        _ => sniff(&bytes),
    };
    if let (Some(name), false) = (&opts.fs_variable, kind == Kind::Mat) {
        return Err(ctx.file(format!(
            "--fs {name}: a sample rate by variable name needs a .mat recording; give it in Hz"
        )));
    }
    if opts.dataset.is_some() && kind != Kind::Uff {
        return Err(ctx.file("a dataset number applies to universal files only"));
    }
    let (format, frf, source) = match kind {
        Kind::Mat => read_mat_recording(&ctx, &bytes, opts)?,
        Kind::Uff => {
            no_signals(&ctx, opts, "a universal file")?;
            (
                Format::Uff,
                read_uff_frf(&ctx, &bytes, opts)?,
                Source::FrfFile,
            )
        }
        Kind::Csv => {
            let text = utf8(&ctx, &bytes)?;
            let table = csv::parse_table(text).map_err(|e| ctx.csv(e))?;
            if csv::is_frf_table(&table) {
                no_signals(&ctx, opts, "an FRF file")?;
                let frf = csv::frf_from_table(&table).map_err(|e| ctx.csv(e))?;
                (Format::FrfCsv, frf, Source::FrfFile)
            } else {
                let (u, y) = (
                    csv_column(&ctx, opts.u.as_ref(), "u")?,
                    csv_column(&ctx, opts.y.as_ref(), "y")?,
                );
                let ts =
                    csv::time_series_from_table(&table, &u, &y, opts.fs).map_err(|e| ctx.csv(e))?;
                let x = match opts.excitation.as_ref() {
                    Some(r) => {
                        let name = csv_column(&ctx, Some(r), "")?;
                        let xs = csv::time_series_from_table(&table, &name, &y, opts.fs)
                            .map_err(|e| ctx.csv(e))?;
                        Some((xs.u, name))
                    }
                    None => None,
                };
                let (frf, source) = estimate(&ctx, &ts.u, &ts.y, ts.fs, opts, u, y, x)?;
                (Format::TimeCsv, frf, source)
            }
        }
        Kind::Matrix => {
            let text = utf8(&ctx, &bytes)?;
            let m = csv::parse_matrix(text).map_err(|e| ctx.csv(e))?;
            let (frf, source) = matrix_recording(&ctx, &m, opts)?;
            (Format::Matrix, frf, source)
        }
    };
    Ok(Recording {
        path: path.to_path_buf(),
        format,
        frf,
        source,
        samples: ctx.samples.take(),
        excitation: ctx.excitation.take(),
        possible_excitations: ctx.possible_excitations.take(),
    })
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Csv,
    Uff,
    Mat,
    Matrix,
}

/// The format of a file with an unknown extension, from its first bytes.
fn sniff(bytes: &[u8]) -> Kind {
    if bytes.len() >= 128 && bytes.starts_with(b"MATLAB") {
        return Kind::Mat;
    }
    let first = bytes
        .split(|&b| b == b'\n')
        .map(|l| l.trim_ascii())
        .find(|l| !l.is_empty() && !l.starts_with(b"#") && !l.starts_with(b"%"));
    match first {
        Some(b"-1") => Kind::Uff,
        Some(l) if l.contains(&b',') => Kind::Csv,
        _ => Kind::Matrix,
    }
}

fn utf8<'a>(ctx: &Ctx<'_>, bytes: &'a [u8]) -> Result<&'a str, RecordingError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        RecordingError::Text {
            path: ctx.path.to_path_buf(),
            line,
            message: "not UTF-8 text".into(),
        }
    })
}

fn no_signals(ctx: &Ctx<'_>, opts: &RecordingOptions, what: &str) -> Result<(), RecordingError> {
    if opts.u.is_some() || opts.y.is_some() || opts.excitation.is_some() {
        return Err(ctx.file(format!(
            "is {what}: input, output and excitation signals apply to time-domain recordings only"
        )));
    }
    Ok(())
}

fn csv_column(
    ctx: &Ctx<'_>,
    r: Option<&SignalRef>,
    default: &str,
) -> Result<String, RecordingError> {
    match r {
        None => Ok(default.to_string()),
        Some(SignalRef {
            name,
            channel: None,
        }) => Ok(name.clone()),
        Some(r) => Err(ctx.file(format!(
            "'{r}': a CSV column has one channel; name the column without ':'"
        ))),
    }
}

/// H1 estimate with the file's context, checked for [`MIN_LINES`].
#[allow(clippy::too_many_arguments)]
fn estimate(
    ctx: &Ctx<'_>,
    u: &[f64],
    y: &[f64],
    fs: f64,
    opts: &RecordingOptions,
    input: String,
    output: String,
    excitation: Option<(Vec<f64>, String)>,
) -> Result<(Frf, Source), RecordingError> {
    // Every source of the rate (flag, variable, time column) ends here.
    check_sample_rate(fs).map_err(|why| ctx.file(why))?;
    // A constant channel has no spectrum: nothing to estimate, and the
    // ratio of two zero spectra would read as noise.
    let x_name = excitation.as_ref().map(|e| e.1.clone()).unwrap_or_default();
    let channels = [("input", &input, u), ("output", &output, y)];
    let all = channels.into_iter().chain(
        excitation
            .as_ref()
            .map(|(x, _)| ("excitation", &x_name, x.as_slice())),
    );
    for (what, name, x) in all {
        if let Some(&first) = x.first() {
            if x.iter().all(|&v| v == first) {
                return Err(ctx.file(format!(
                    "the {what} {name} is constant ({first} in all {} samples): there is \
                     nothing to estimate an FRF from",
                    x.len()
                )));
            }
        }
    }
    // Only a period given is used: read without one, the 2018 scan's
    // harmonics (found by `crate::period`) are too noisy to classify in
    // the band its documented commands use.
    let (welch, period) = (opts.welch.clone(), opts.welch.period.map(Period::Given));
    if let Some(period) = opts.welch.period.filter(|&p| p >= 2) {
        // A period must fit the record whole, and the excitation (the
        // injected one, else the input) must repeat at it.
        let n = u.len();
        if !n.is_multiple_of(period) {
            return Err(ctx.file(format!(
                "a period of {period} samples: the record's {n} samples are not a whole \
                 number of periods ({} periods and {} samples)",
                n / period,
                n % period
            )));
        }
        let (signal, what) = match &excitation {
            Some((x, name)) => (x.as_slice(), name.as_str()),
            None => (u, input.as_str()),
        };
        if let Some(spread) = crate::period::spread(signal, period) {
            if spread > MAX_PERIOD_SPREAD {
                return Err(ctx.file(format!(
                    "a period of {period} samples: {what} does not repeat at it (its periods \
                     differ from their mean by {:.0} % of its RMS, more than {:.0} %)",
                    100.0 * spread,
                    100.0 * MAX_PERIOD_SPREAD
                )));
            }
        }
    }
    let (frf, averages, nfft, kept, loop_functions) = match &excitation {
        Some((x, name)) => {
            if x.len() != u.len() {
                return Err(ctx.file(format!(
                    "the excitation {name} has {} samples but the input {input} has {}",
                    x.len(),
                    u.len()
                )));
            }
            let est = welch::three_point(x, u, y, fs, &welch).map_err(|e| {
                ctx.file(format!(
                    "estimating the FRF from {input} to {output} with the excitation {name}: {e}"
                ))
            })?;
            // An excitation that does not reach the plant input explains
            // nothing of it. Unrelated signals have some coherence by
            // chance: with n averages it exceeds c at a line with
            // probability (1 - c)^(n - 1), so a line counts only above the
            // 1 % level (and 0.1), and the excitation reaches u if 5 % of
            // the lines it excites do (all of a random excitation's, the
            // harmonics of a periodic one).
            let n = est.averages.max(2) as f64;
            let level = (1.0 - 0.01f64.powf(1.0 / (n - 1.0))).max(0.1);
            let sd = est.sensitivity.std_dev();
            let coh: Vec<f64> = est
                .sensitivity
                .coherence()
                .unwrap_or(&[])
                .iter()
                .enumerate()
                .filter(|(k, _)| welch.period.is_none() || sd.is_none_or(|d| d[*k].is_finite()))
                .map(|(_, &g)| g)
                .collect();
            let above = coh.iter().filter(|&&g| g > level).count();
            if above * 20 < coh.len().max(1) {
                let best = coh.iter().cloned().fold(0.0, f64::max);
                return Err(ctx.file(format!(
                    "the excitation {name} does not reach the input {input}: its coherence \
                     with it exceeds {level:.3} (chance with {} averages) at {above} of {} \
                     lines (at most {best:.3})",
                    est.averages,
                    coh.len()
                )));
            }
            let functions = Excitation {
                name: name.clone(),
                sensitivity: est.sensitivity,
                process_sensitivity: est.process_sensitivity,
            };
            (
                est.plant,
                est.averages,
                est.nfft,
                Some(x.clone()),
                Some(functions),
            )
        }
        None => {
            let est = welch::h1(u, y, fs, &welch).map_err(|e| {
                ctx.file(format!("estimating the FRF from {input} to {output}: {e}"))
            })?;
            (est.frf, est.averages, est.nfft, None, None)
        }
    };
    if frf.len() < MIN_LINES {
        return Err(ctx.file(format!(
            "only {} frequency lines (nfft {nfft}); at least {MIN_LINES} are needed",
            frf.len()
        )));
    }
    *ctx.samples.borrow_mut() = Some(Samples {
        u: u.to_vec(),
        y: y.to_vec(),
        fs,
        excitation: kept,
    });
    *ctx.excitation.borrow_mut() = loop_functions;
    let source = Source::TimeDomain {
        fs,
        n_samples: u.len(),
        averages,
        nfft,
        input,
        output,
        period,
    };
    Ok((frf, source))
}

fn matrix_recording(
    ctx: &Ctx<'_>,
    m: &csv::Matrix,
    opts: &RecordingOptions,
) -> Result<(Frf, Source), RecordingError> {
    let column = |r: Option<&SignalRef>, default: usize| -> Result<usize, RecordingError> {
        let Some(r) = r else {
            if m.cols == 2 {
                return Ok(default);
            }
            return Err(ctx.file(format!(
                "the matrix has {} columns: pick the input and output columns by number (e.g. u = 1, y = 2)",
                m.cols
            )));
        };
        if r.channel.is_some() {
            return Err(ctx.file(format!(
                "'{r}': pick a column of a headerless matrix by its number alone"
            )));
        }
        let c: usize = r.name.parse().map_err(|_| {
            ctx.file(format!(
                "'{}' is not a column number (a headerless matrix has no column names)",
                r.name
            ))
        })?;
        if c == 0 || c > m.cols {
            return Err(ctx.file(format!(
                "column {c} is out of range: the matrix has columns 1 to {}",
                m.cols
            )));
        }
        Ok(c)
    };
    let (cu, cy) = (column(opts.u.as_ref(), 1)?, column(opts.y.as_ref(), 2)?);
    let fs = opts.fs.ok_or_else(|| {
        ctx.file("no sample rate: a headerless matrix has no time column, so give the sample rate")
    })?;
    let u = m.column(cu).unwrap_or_default();
    let y = m.column(cy).unwrap_or_default();
    let x = match opts.excitation.as_ref() {
        Some(r) => {
            let cx = column(Some(r), 0)?;
            Some((
                m.column(cx).unwrap_or_default().to_vec(),
                format!("column {cx}"),
            ))
        }
        None => None,
    };
    estimate(
        ctx,
        u,
        y,
        fs,
        opts,
        format!("column {cu}"),
        format!("column {cy}"),
        x,
    )
}

/// Why `name` is not in the file: the fields of the deepest struct on its
/// path that exists, else every variable.
fn not_found(mat: &MatFile, name: &str) -> String {
    let mut path = name;
    while let Some((parent, _)) = path.rsplit_once('.') {
        let fields = mat.fields(parent);
        if !fields.is_empty() {
            let field = &name[parent.len() + 1..];
            let field = field.split('.').next().unwrap_or(field);
            if fields.iter().any(|f| f == field) {
                return format!(
                    "'{parent}.{field}' is a struct, not a signal (fields: {})",
                    mat.fields(&format!("{parent}.{field}")).join(", ")
                );
            }
            return format!(
                "struct '{parent}' has no field '{field}' (fields: {})",
                fields.join(", ")
            );
        }
        path = parent;
    }
    format!("not in the file (variables: {})", inventory(mat))
}

/// One line per numeric variable (and skipped ones), for messages.
fn inventory(mat: &MatFile) -> String {
    let mut parts: Vec<String> = mat
        .variables
        .iter()
        .map(|v| {
            let dims: Vec<String> = v.dims.iter().map(|d| d.to_string()).collect();
            format!("{} ({} {})", v.name, dims.join("x"), v.class)
        })
        .collect();
    parts.extend(
        mat.skipped
            .iter()
            .map(|s| format!("{} ({}, not numeric)", s.name, s.class)),
    );
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join(", ")
    }
}

/// The samples of one channel of a variable.
fn channel(ctx: &Ctx<'_>, v: &MatVariable, ch: Option<usize>) -> Result<Vec<f64>, RecordingError> {
    if v.imag.is_some() {
        return Err(ctx.variable(&v.name, "is complex; expected real samples"));
    }
    let Some((r, c)) = v.shape2() else {
        return Err(ctx.variable(
            &v.name,
            format!(
                "has {} dimensions; expected a vector or a matrix",
                v.dims.len()
            ),
        ));
    };
    if r == 0 || c == 0 {
        return Err(ctx.variable(&v.name, "is empty"));
    }
    if r == 1 || c == 1 {
        return match ch {
            None | Some(1) => Ok(v.real.clone()),
            Some(k) => Err(ctx.variable(
                &v.name,
                format!("is a vector ({r}x{c}): channel {k} does not exist"),
            )),
        };
    }
    // Samples along the longer dimension; a square matrix has samples in
    // rows (channels in columns), as MATLAB stores signals.
    let (samples, channels, by_columns) = if r >= c { (r, c, true) } else { (c, r, false) };
    let k = ch.ok_or_else(|| {
        ctx.variable(
            &v.name,
            format!(
                "has {channels} channels ({r}x{c}): pick one as {0}:1 .. {0}:{channels}",
                v.name
            ),
        )
    })?;
    if k > channels {
        return Err(ctx.variable(
            &v.name,
            format!("channel {k} is out of range: it has channels 1 to {channels} ({r}x{c})"),
        ));
    }
    let k = k - 1;
    Ok(if by_columns {
        v.real[k * samples..(k + 1) * samples].to_vec()
    } else {
        (0..samples).map(|j| v.real[k + r * j]).collect()
    })
}

fn read_mat_recording(
    ctx: &Ctx<'_>,
    bytes: &[u8],
    opts: &RecordingOptions,
) -> Result<(Format, Frf, Source), RecordingError> {
    let mat = mat::read_mat(bytes).map_err(|e| ctx.mat(e))?;
    let lookup = |r: &SignalRef| -> Result<(Vec<f64>, String), RecordingError> {
        match mat.get(&r.name) {
            Some(v) => Ok((channel(ctx, v, r.channel)?, r.to_string())),
            None => {
                let message = match mat.skipped.iter().find(|s| s.name == r.name) {
                    Some(s) => format!("is not numeric (class {})", s.class),
                    None => not_found(&mat, &r.name),
                };
                Err(ctx.variable(&r.name, message))
            }
        }
    };
    let ((u, un), (y, yn)) = match (&opts.u, &opts.y) {
        (Some(u), Some(y)) => (lookup(u)?, lookup(y)?),
        (None, None) => {
            // The unambiguous case: one non-scalar variable besides `t`,
            // with exactly two channels.
            let signals: Vec<&MatVariable> = mat
                .variables
                .iter()
                .filter(|v| v.numel() > 1 && v.name != "t")
                .collect();
            match signals[..] {
                [v] if v
                    .shape2()
                    .is_some_and(|(r, c)| r.min(c) == 2 && r.max(c) > 2) =>
                {
                    (
                        lookup(&SignalRef::channel(v.name.clone(), 1))?,
                        lookup(&SignalRef::channel(v.name.clone(), 2))?,
                    )
                }
                _ => {
                    return Err(ctx.file(format!(
                        "choose the input and output signals (u, y) among the variables: {}",
                        inventory(&mat)
                    )))
                }
            }
        }
        _ => {
            return Err(ctx.file(format!(
                "give both the input and the output signal (variables: {})",
                inventory(&mat)
            )))
        }
    };
    if u.len() != y.len() {
        return Err(ctx.file(format!(
            "input {un} has {} samples but output {yn} has {}",
            u.len(),
            y.len()
        )));
    }
    let fs = match (opts.fs, &opts.fs_variable) {
        (Some(fs), _) => fs,
        (None, Some(name)) => {
            let v = mat.get(name).ok_or_else(|| {
                let why = match mat.skipped.iter().find(|s| &s.name == name) {
                    Some(s) => format!("is not numeric (class {})", s.class),
                    None => not_found(&mat, name),
                };
                ctx.variable(name, why)
            })?;
            match v.scalar() {
                Some(fs) => {
                    check_sample_rate(fs).map_err(|why| ctx.variable(name, why))?;
                    fs
                }
                None => {
                    return Err(ctx.variable(name, "a sample rate must be a positive real scalar"))
                }
            }
        }
        (None, None) => mat_sample_rate(ctx, &mat, u.len())?,
    };
    let x = opts.excitation.as_ref().map(lookup).transpose()?;
    if x.is_none() {
        const NAMES: [&str; 7] = ["d", "r", "w", "noise", "excitation", "disturbance", "dist"];
        *ctx.possible_excitations.borrow_mut() = mat
            .variables
            .iter()
            .filter(|v| v.numel() == u.len() && v.name != un && v.name != yn)
            .filter(|v| {
                let last = v.name.rsplit('.').next().unwrap_or(&v.name);
                NAMES.contains(&last.to_ascii_lowercase().as_str())
            })
            .map(|v| v.name.clone())
            .collect();
    }
    let (frf, source) = estimate(ctx, &u, &y, fs, opts, un, yn, x)?;
    Ok((Format::Mat, frf, source))
}

/// `Fs` or `fs` (a positive scalar, also as a struct field such as
/// `Data.settings.fs`), else the time vector `t` (or a struct field `t` or
/// `Time`).
fn mat_sample_rate(ctx: &Ctx<'_>, mat: &MatFile, n: usize) -> Result<f64, RecordingError> {
    let last = |v: &&MatVariable| v.name.rsplit('.').next().unwrap_or(&v.name).to_string();
    let field = |want: &[&str]| -> Option<String> {
        mat.variables
            .iter()
            .find(|v| want.contains(&last(v).as_str()))
            .map(|v| v.name.clone())
    };
    let rate_names: Vec<String> = ["Fs", "fs"]
        .iter()
        .map(|s| s.to_string())
        .chain(field(&["Fs", "fs"]))
        .collect();
    for name in rate_names.iter().map(String::as_str) {
        if let Some(v) = mat.get(name) {
            let fs = v
                .scalar()
                .ok_or_else(|| ctx.variable(name, "a sample rate must be a real scalar"))?;
            check_sample_rate(fs).map_err(|why| ctx.variable(name, why))?;
            return Ok(fs);
        }
    }
    let time_name = if mat.get("t").is_some() {
        Some("t".to_string())
    } else {
        field(&["t", "Time", "time"])
    };
    if let Some(t) = time_name.as_deref().and_then(|t| mat.get(t)) {
        let tn = t.name.as_str();
        let times = channel(ctx, t, None)?;
        if times.len() != n {
            return Err(ctx.variable(
                tn,
                format!(
                    "has {} time stamps but the signals have {n} samples",
                    times.len()
                ),
            ));
        }
        return sample_rate_from_times(&times)
            .map_err(|e| ctx.variable(tn, format!("sample {}: {e}", e.index + 1)));
    }
    Err(ctx.file(format!(
        "no sample rate: give it, or store a scalar Fs or a time vector t (variables: {})",
        inventory(mat)
    )))
}

fn read_uff_frf(
    ctx: &Ctx<'_>,
    bytes: &[u8],
    opts: &RecordingOptions,
) -> Result<Frf, RecordingError> {
    let sets = uff::parse_uff(bytes).map_err(|e| ctx.uff(e))?;
    if sets.is_empty() {
        return Err(ctx.file("no dataset 58 in the file"));
    }
    let describe = |d: &uff::Uff58| {
        format!(
            "{} ({}, response {}:{} reference {}:{})",
            d.position,
            uff::function_type_name(d.function_type),
            d.response.node,
            d.response.direction,
            d.reference.node,
            d.reference.direction
        )
    };
    let list = |sets: &[&uff::Uff58]| {
        sets.iter()
            .map(|d| describe(d))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let all: Vec<&uff::Uff58> = sets.iter().collect();
    let chosen = match opts.dataset {
        Some(p) => *all.iter().find(|d| d.position == p).ok_or_else(|| {
            ctx.file(format!(
                "no dataset 58 at position {p}; datasets 58: {}",
                list(&all)
            ))
        })?,
        None => {
            let frfs: Vec<&uff::Uff58> = sets.iter().filter(|d| d.function_type == 4).collect();
            match frfs[..] {
                [one] => one,
                [] => {
                    return Err(ctx.file(format!(
                        "no frequency response function (type 4) among the datasets 58: {}",
                        list(&all)
                    )))
                }
                _ => {
                    return Err(ctx.file(format!(
                        "several FRFs; choose one by its dataset number: {}",
                        list(&frfs)
                    )))
                }
            }
        }
    };
    let frf = chosen.to_frf().map_err(|e| ctx.uff(e))?;
    // Attach a coherence and a standard deviation measured for the same
    // DOFs on the same lines.
    let coherence = sets
        .iter()
        .find_map(|o| chosen.coherence_for(o).map(|c| (o, c)));
    let std_dev = sets
        .iter()
        .find_map(|o| chosen.std_dev_for(o).map(|c| (o, c)));
    let in_dataset = |other: &uff::Uff58, e: crate::FrfError| RecordingError::Dataset {
        path: ctx.path.to_path_buf(),
        dataset: other.position,
        line: other.line,
        message: one_line(e.to_string()),
    };
    let frf = match coherence {
        Some((other, c)) => Frf::new(frf.freq_hz().to_vec(), frf.response().to_vec(), Some(c))
            .map_err(|e| in_dataset(other, e))?,
        None => frf,
    };
    match std_dev {
        Some((other, sd)) => frf.with_std_dev(sd).map_err(|e| in_dataset(other, e)),
        None => Ok(frf),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mat::writer::{file as mat_file, Data, Var};
    use crate::Complex64;

    /// A scratch directory removed at the end of the test.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str) -> Scratch {
            let dir = std::env::temp_dir().join(format!("frf-rec-{}-{name}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }

        fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
            let p = self.0.join(name);
            std::fs::write(&p, bytes).unwrap();
            p
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// y[n] = 0.5 u[n] + 0.25 u[n-1]: H = 0.5 + 0.25 exp(-i w).
    fn fir(u: &[f64]) -> Vec<f64> {
        (0..u.len())
            .map(|n| 0.5 * u[n] + if n > 0 { 0.25 * u[n - 1] } else { 0.0 })
            .collect()
    }

    fn check_fir(frf: &Frf, fs: f64) {
        for (&f, &h) in frf.freq_hz().iter().zip(frf.response()) {
            let exact =
                0.5 + 0.25 * Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * f / fs);
            // 2 %: Welch estimate of a two-tap filter from white noise.
            assert!(
                (h - exact).norm() < 0.02 * exact.norm(),
                "{f}: {h} vs {exact}"
            );
        }
    }

    fn opts(u: &str, y: &str) -> RecordingOptions {
        RecordingOptions {
            u: Some(u.parse().unwrap()),
            y: Some(y.parse().unwrap()),
            ..Default::default()
        }
    }

    /// A period is checked against the record: whole periods, and an
    /// input that repeats at it. A periodic input (8 periods of 512,
    /// 2 % noise) passes; the same record at a period that does not
    /// divide it, or white noise read as periodic, is a one-line error
    /// naming the file and the period.
    #[test]
    fn a_period_must_fit_the_record_and_the_input_repeat_at_it() {
        let dir = Scratch::new("period");
        let one = white(512, 3);
        let noise = white(4096, 4);
        let periodic: Vec<f64> = (0..4096).map(|k| one[k % 512] + 0.02 * noise[k]).collect();
        let csv = |u: &[f64]| -> String {
            let y = fir(u);
            let mut text = String::from("t,u,y\n");
            for n in 0..u.len() {
                text.push_str(&format!("{},{},{}\n", n as f64 / 500.0, u[n], y[n]));
            }
            text
        };
        let with = |period: usize| RecordingOptions {
            welch: WelchOptions {
                period: Some(period),
                ..WelchOptions::default()
            },
            ..RecordingOptions::default()
        };
        let good = dir.write("periodic.csv", csv(&periodic));
        assert!(read_recording(&good, &with(512)).is_ok());
        let e = read_recording(&good, &with(500)).unwrap_err().to_string();
        assert!(
            e.contains("periodic.csv") && e.contains("8 periods and 96 samples"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1);
        let random = dir.write("random.csv", csv(&white(4096, 5)));
        let e = read_recording(&random, &with(512)).unwrap_err().to_string();
        assert!(
            e.contains("random.csv") && e.contains("does not repeat"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1);
    }

    #[test]
    fn time_csv_default_and_named_columns() {
        let dir = Scratch::new("tcsv");
        let u = white(4096, 1);
        let y = fir(&u);
        let mut text = String::from("# bench log\nt,u,y,F\n");
        for n in 0..u.len() {
            text.push_str(&format!(
                "{},{},{},{}\n",
                n as f64 / 500.0,
                u[n],
                y[n],
                -u[n]
            ));
        }
        let p = dir.write("log.csv", &text);
        let rec = read_recording(&p, &RecordingOptions::default()).unwrap();
        assert_eq!(rec.format, Format::TimeCsv);
        let Source::TimeDomain {
            fs,
            n_samples,
            nfft,
            averages,
            ..
        } = rec.source.clone()
        else {
            panic!("{:?}", rec.source)
        };
        assert!((fs - 500.0).abs() < 1e-9);
        // Default nfft for 4096 samples (Hann, 50 %): 256 gives 31 segments,
        // 512 only 15.
        assert_eq!((n_samples, nfft, averages), (4096, 256, 31));
        check_fir(&rec.frf, 500.0);
        // Named columns: F = -u, so the response flips sign.
        let rec = read_recording(&p, &opts("F", "y")).unwrap();
        assert!(rec.frf.response()[3].re < 0.0);
        let e = read_recording(&p, &opts("force", "y")).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}:2: missing column 'force' (columns: t,u,y,F)",
                p.display()
            )
        );
        let e = read_recording(&p, &opts("u:2", "y")).unwrap_err();
        assert!(e.to_string().contains("one channel"), "{e}");
    }

    #[test]
    fn text_errors_name_file_and_line() {
        let dir = Scratch::new("terr");
        let frf_rows = |n: usize| -> String { (1..=n).map(|k| format!("{k},1,0\n")).collect() };
        let cases: Vec<(&str, String, String)> = vec![
            (
                "empty.csv",
                String::new(),
                ": empty file: no header line".into(),
            ),
            (
                "noheader.csv",
                frf_rows(12),
                ":1: no header: the first line holds numbers, expected column names".into(),
            ),
            (
                "unknown.csv",
                format!("freq_hz,real,im\n{}", frf_rows(12)),
                ":1: unknown column 'real'".into(),
            ),
            (
                "missing.csv",
                format!("# x\nfreq_hz,re\n{}", "1,2\n".repeat(12)),
                ":2: missing column 'im'".into(),
            ),
            (
                "nan.csv",
                format!("freq_hz,re,im\n{}5.5,NaN,0\n", frf_rows(5)),
                ":7: column 're': 'NaN' is not a finite number".into(),
            ),
            (
                "inf.csv",
                format!("freq_hz,re,im\n{}5.5,0,-inf\n", frf_rows(5)),
                ":7: column 'im': '-inf' is not a finite number".into(),
            ),
            (
                "order.csv",
                format!("freq_hz,re,im\n{}3,1,0\n", frf_rows(12)),
                ":14: frequency 3 Hz does not increase".into(),
            ),
            (
                "neg.csv",
                format!("freq_hz,re,im\n-1,0,0\n{}", frf_rows(12)),
                ":2: frequency -1 Hz is negative".into(),
            ),
            (
                "few.csv",
                format!("freq_hz,re,im\n{}", frf_rows(9)),
                ": only 9 frequency lines; at least 10 are needed".into(),
            ),
        ];
        for (name, text, tail) in cases {
            let p = dir.write(name, &text);
            let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
            let shown = e.to_string();
            assert!(
                shown.starts_with(&format!("{}{tail}", p.display())),
                "{name}: {shown}"
            );
            assert_eq!(shown.lines().count(), 1);
        }
        // Non-uniform time column: sample 40 late by half a step.
        let mut text = String::from("t,u,y\n");
        for n in 0..100 {
            let t = if n == 40 { 40.5e-3 } else { n as f64 * 1e-3 };
            text.push_str(&format!("{t},{},{}\n", n % 7, n % 3));
        }
        let p = dir.write("jitter.csv", &text);
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("{}:42: column 't': non-uniform time", p.display())),
            "{e}"
        );
        // Bytes that are not UTF-8, on line 3.
        let p = dir.write("bad.csv", b"freq_hz,re,im\n1,0,0\n\xff,0,0\n");
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert_eq!(e.to_string(), format!("{}:3: not UTF-8 text", p.display()));
        // A stray carriage return inside a column name stays on one line.
        let p = dir.write("cr.csv", format!("freq_hz,re,i\rm\n{}", frf_rows(12)));
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert_eq!(e.to_string(), format!("{}:1: unknown column 'i?m' (expected freq_hz,re,im or freq_hz,mag_db,phase_deg, optionally coherence and std_dev)", p.display()));
        // A file that does not exist.
        let e = read_recording(dir.0.join("none.csv"), &RecordingOptions::default()).unwrap_err();
        assert!(matches!(e, RecordingError::Io { .. }));
    }

    #[test]
    fn headerless_matrix() {
        let dir = Scratch::new("dat");
        let u = white(2048, 3);
        let y = fir(&u);
        let text: String = u
            .iter()
            .zip(&y)
            .map(|(a, b)| format!("  {a:.15e}\t{b:.15e}\n"))
            .collect();
        let p = dir.write("arm.dat", &text);
        let fs1 = RecordingOptions {
            fs: Some(1.0),
            ..Default::default()
        };
        let rec = read_recording(&p, &fs1).unwrap();
        assert_eq!(rec.format, Format::Matrix);
        check_fir(&rec.frf, 1.0);
        // Explicit columns, swapped: the inverse response.
        let swapped = RecordingOptions {
            u: Some("2".parse().unwrap()),
            y: Some("1".parse().unwrap()),
            ..fs1.clone()
        };
        let rec = read_recording(&p, &swapped).unwrap();
        let h = rec.frf.response()[0];
        let exact = 0.5
            + 0.25 * Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * rec.frf.freq_hz()[0]);
        assert!((h * exact - 1.0).norm() < 0.02);
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(e.to_string().contains("no sample rate"), "{e}");
        let out = RecordingOptions {
            u: Some("3".parse().unwrap()),
            y: Some("1".parse().unwrap()),
            ..fs1.clone()
        };
        let e = read_recording(&p, &out).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: column 3 is out of range: the matrix has columns 1 to 2",
                p.display()
            )
        );
        let named = RecordingOptions {
            u: Some("torque".parse().unwrap()),
            y: Some("2".parse().unwrap()),
            ..fs1
        };
        assert!(read_recording(&p, &named)
            .unwrap_err()
            .to_string()
            .contains("not a column number"));
    }

    fn mat_vars(n: usize) -> (Vec<f64>, Vec<f64>, Vec<Var>) {
        let u = white(n, 11);
        let y = fir(&u);
        let mut acc = Vec::with_capacity(3 * n);
        // 3 x N, column-major: sample j holds (y, u, -y) in rows 1..3.
        for j in 0..n {
            acc.extend_from_slice(&[y[j], u[j], -y[j]]);
        }
        let vars = vec![
            Var::double("Force", 1, n as i32, u.clone()),
            Var::double("Acceleration", 3, n as i32, acc),
            Var::double("Fs", 1, 1, vec![250.0]),
            Var {
                name: "note".into(),
                dims: vec![1, 2],
                class: 4,
                logical: false,
                data: Data::Char("ok".into()),
            },
        ];
        (u, y, vars)
    }

    #[test]
    fn mat_signals_channels_and_sample_rate() {
        let dir = Scratch::new("mat");
        let (_, _, vars) = mat_vars(4096);
        let p = dir.write("gvt.mat", mat_file(&vars, true, false));
        let rec = read_recording(&p, &opts("Force", "Acceleration:1")).unwrap();
        assert_eq!(rec.format, Format::Mat);
        let Source::TimeDomain {
            fs, input, output, ..
        } = rec.source.clone()
        else {
            panic!()
        };
        assert_eq!(
            (fs, input.as_str(), output.as_str()),
            (250.0, "Force", "Acceleration:1")
        );
        check_fir(&rec.frf, 250.0);
        // Channel 2 is the input itself: H = 1.
        let rec = read_recording(&p, &opts("Force", "Acceleration:2")).unwrap();
        assert!(rec.frf.response().iter().all(|h| (h - 1.0).norm() < 1e-9));
        let err = |o: &RecordingOptions| read_recording(&p, o).unwrap_err().to_string();
        let at = |v: &str, m: &str| format!("{}: variable '{v}': {m}", p.display());
        assert!(err(&opts("Forces", "Acceleration:1")).starts_with(&at("Forces", "not in the file (variables: Force (1x4096 double), Acceleration (3x4096 double), Fs (1x1 double), note (char, not numeric))")));
        assert_eq!(
            err(&opts("Force", "Acceleration")),
            at(
                "Acceleration",
                "has 3 channels (3x4096): pick one as Acceleration:1 .. Acceleration:3"
            )
        );
        assert_eq!(
            err(&opts("Force", "Acceleration:4")),
            at(
                "Acceleration",
                "channel 4 is out of range: it has channels 1 to 3 (3x4096)"
            )
        );
        assert_eq!(
            err(&opts("Force:2", "Acceleration:1")),
            at("Force", "is a vector (1x4096): channel 2 does not exist")
        );
        assert_eq!(
            err(&opts("note", "Force")),
            at("note", "is not numeric (class char)")
        );
        // Without u and y: two signal variables, so the choice is the user's.
        let e = err(&RecordingOptions::default());
        assert!(e.contains("choose the input and output signals"), "{e}");
        // --fs overrides Fs.
        let o = RecordingOptions {
            fs: Some(1000.0),
            ..opts("Force", "Acceleration:1")
        };
        let rec = read_recording(&p, &o).unwrap();
        assert!((rec.frf.freq_hz()[0] - 1000.0 / 256.0).abs() < 1e-12);
        // A negative Fs in the file.
        let mut bad = mat_vars(512).2;
        bad[2] = Var::double("Fs", 1, 1, vec![-4.0]);
        let p2 = dir.write("badfs.mat", mat_file(&bad, false, false));
        let e = read_recording(&p2, &opts("Force", "Acceleration:1")).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: variable 'Fs': sample rate -4 Hz is not a positive finite number",
                p2.display()
            )
        );
    }

    #[test]
    fn mat_default_n_by_2_and_time_vector() {
        let dir = Scratch::new("matdef");
        let n = 4000;
        let u = white(n, 5);
        let y = fir(&u);
        let mut both = u.clone();
        both.extend_from_slice(&y);
        let t: Vec<f64> = (0..n).map(|k| k as f64 / 2000.0).collect();
        let vars = vec![
            Var::double("result", n as i32, 2, both),
            Var::double("t", n as i32, 1, t),
        ];
        let p = dir.write("run.mat", mat_file(&vars, false, false));
        let rec = read_recording(&p, &RecordingOptions::default()).unwrap();
        let Source::TimeDomain {
            fs, input, output, ..
        } = rec.source.clone()
        else {
            panic!()
        };
        assert!((fs - 2000.0).abs() < 1e-9);
        assert_eq!((input.as_str(), output.as_str()), ("result:1", "result:2"));
        check_fir(&rec.frf, 2000.0);
        // No sample rate at all.
        let p = dir.write("nofs.mat", mat_file(&vars[..1], false, false));
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("{}: no sample rate", p.display())),
            "{e}"
        );
        // A jittery time vector.
        let mut t: Vec<f64> = (0..n).map(|k| k as f64 / 2000.0).collect();
        t[100] += 2e-4;
        let vars2 = vec![
            Var::double("result", n as i32, 2, vec![0.0; 2 * n]),
            Var::double("t", n as i32, 1, t),
        ];
        let p = dir.write("jit.mat", mat_file(&vars2, false, false));
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!(
                "{}: variable 't': sample 101: non-uniform time",
                p.display()
            )),
            "{e}"
        );
    }

    #[test]
    fn truncated_mat_is_an_error() {
        let dir = Scratch::new("mattrunc");
        let (_, _, vars) = mat_vars(1024);
        for compress in [false, true] {
            let bytes = mat_file(&vars, compress, false);
            let p = dir.write("cut.mat", &bytes[..bytes.len() * 2 / 3]);
            let e = read_recording(&p, &opts("Force", "Acceleration:1")).unwrap_err();
            assert!(e.to_string().starts_with(&p.display().to_string()), "{e}");
            assert_eq!(e.to_string().lines().count(), 1);
        }
        // Absurd dimensions (product overflows) and a size claim larger
        // than the file: errors naming the variable or the byte offset.
        let mut huge = Var::double("huge", 1, 1, vec![1.0]);
        huge.dims = vec![i32::MAX, i32::MAX, i32::MAX];
        let p = dir.write("huge.mat", mat_file(&[huge], true, false));
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: variable 'huge': absurd dimensions [2147483647, 2147483647, 2147483647]",
                p.display()
            )
        );
        let mut bytes = mat_file(&vars, false, false);
        bytes[132..136].copy_from_slice(&0x7fff_fff0u32.to_le_bytes());
        let p = dir.write("claim.mat", &bytes);
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!(
                "{}: element at byte 128 claims 2147483632 bytes but only",
                p.display()
            )),
            "{e}"
        );
        let p = dir.write("empty.mat", b"");
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(
            e.to_string().contains("too few for a MAT-file header"),
            "{e}"
        );
    }

    #[test]
    fn uff_standard_deviation_per_line() {
        let dir = Scratch::new("uff-sd");
        let freq: Vec<f64> = (1..=20).map(|k| k as f64).collect();
        let resp: Vec<Complex64> = freq.iter().map(|&f| Complex64::new(2.0 / f, 0.0)).collect();
        let mut sd: Vec<f64> = freq.iter().map(|f| 0.01 * f).collect();
        sd[4] = f64::INFINITY;
        let frf = Frf::new(freq.clone(), resp.clone(), None)
            .unwrap()
            .with_std_dev(sd.clone())
            .unwrap();
        let text = uff::write_frf_uff(&frf, uff::Spacing::Uneven).unwrap();
        let p = dir.write("sd.uff", &text);
        let back = read_recording(&p, &RecordingOptions::default())
            .unwrap()
            .frf;
        let got = back.std_dev().expect("the standard deviation is read back");
        assert_eq!(got[4], f64::INFINITY);
        for k in (0..20).filter(|&k| k != 4) {
            assert!((got[k] - sd[k]).abs() <= 1e-12 * sd[k], "line {k}");
        }
        // It weighs the lines: relative to |H| = 2 / f, 0.01 f / (2 / f),
        // 0.5 nepers at 10 Hz.
        let u = crate::uncertainty::line_uncertainty(&back, None);
        assert_eq!(u.source, crate::uncertainty::Source::Given);
        assert!((u.relative[9] - 0.5).abs() < 1e-12, "{}", u.relative[9]);
        // Another writer's dataset named "Standard Deviation", written as
        // records by hand: the same values.
        let named = text.replace("std_dev", "Standard Deviation");
        let p = dir.write("named.uff", &named);
        let other = read_recording(&p, &RecordingOptions::default())
            .unwrap()
            .frf;
        assert_eq!(other.std_dev(), back.std_dev());
        // On other DOFs it describes another function: not attached.
        let foreign: Vec<uff::Uff58> = uff::parse_uff(text.as_bytes())
            .unwrap()
            .into_iter()
            .enumerate()
            .map(|(i, mut d)| {
                if i == 1 {
                    d.response.node = 7;
                }
                d
            })
            .collect();
        let p = dir.write("foreign.uff", uff::write_uff58(&foreign));
        let rec = read_recording(&p, &RecordingOptions::default()).unwrap();
        assert!(rec.frf.std_dev().is_none());
    }

    #[test]
    fn uff_selection_and_coherence() {
        let dir = Scratch::new("uff");
        let freq: Vec<f64> = (1..=40).map(|k| k as f64).collect();
        let resp: Vec<Complex64> = freq
            .iter()
            .map(|&f| Complex64::new(1.0 / f, -1.0))
            .collect();
        let coh: Vec<f64> = freq.iter().map(|f| 0.5 + f / 100.0).collect();
        let frf = Frf::new(freq, resp, Some(coh)).unwrap();
        let text = uff::write_frf_uff(&frf, uff::Spacing::Even).unwrap();
        let p = dir.write("h.unv", &text);
        let rec = read_recording(&p, &RecordingOptions::default()).unwrap();
        assert_eq!(
            (rec.format, rec.source.clone()),
            (Format::Uff, Source::FrfFile)
        );
        assert_eq!(rec.frf.coherence().unwrap()[9], 0.6);
        // Two FRFs: the choice is the user's.
        let p = dir.write("two.uff", format!("{text}{text}"));
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(e.to_string().contains("several FRFs; choose one by its dataset number: 1 (frequency response function, response 1:0 reference 1:0), 3 ("), "{e}");
        let third = RecordingOptions {
            dataset: Some(3),
            ..Default::default()
        };
        assert_eq!(read_recording(&p, &third).unwrap().frf.len(), 40);
        // Dataset 2 is the coherence: an error naming dataset and line.
        let second = RecordingOptions {
            dataset: Some(2),
            ..Default::default()
        };
        let e = read_recording(&p, &second).unwrap_err();
        let opening = text.lines().position(|l| l == "    -1").unwrap();
        let second_open = text
            .lines()
            .skip(opening + 1)
            .position(|l| l == "    -1")
            .unwrap()
            + opening
            + 3;
        assert_eq!(
            e.to_string(),
            format!("{}: dataset 2 (line {second_open}): function type 6 (coherence) is not a frequency response function (4)", p.display())
        );
        // A broken value inside the second FRF's data.
        let mut lines: Vec<String> = format!("{text}{text}").lines().map(String::from).collect();
        let data_line = lines.len() - 8;
        lines[data_line] = "  1.0  garbage".into();
        let p = dir.write("bad.uff", lines.join("\n"));
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert!(
            matches!(e, RecordingError::Dataset { line, .. } if line == data_line + 1),
            "{e}"
        );
        // Empty universal file.
        let p = dir.write("empty.uff", "");
        let e = read_recording(&p, &RecordingOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("{}: no dataset 58 in the file", p.display())
        );
        // Options that do not apply.
        let e = read_recording(dir.write("h2.uff", &text), &opts("a", "b")).unwrap_err();
        assert!(e.to_string().contains("time-domain recordings only"), "{e}");
    }

    #[test]
    fn sniffs_unknown_extensions() {
        let dir = Scratch::new("sniff");
        let freq: Vec<f64> = (1..=12).map(|k| k as f64).collect();
        let frf = Frf::new(freq, vec![Complex64::new(1.0, 0.5); 12], None).unwrap();
        let p = dir.write("h.frf", csv::write_csv(&frf, csv::CsvLayout::ReIm));
        assert_eq!(
            read_recording(&p, &RecordingOptions::default())
                .unwrap()
                .format,
            Format::FrfCsv
        );
        let p = dir.write(
            "h.export",
            uff::write_frf_uff(&frf, uff::Spacing::Uneven).unwrap(),
        );
        assert_eq!(
            read_recording(&p, &RecordingOptions::default())
                .unwrap()
                .format,
            Format::Uff
        );
        let (_, _, vars) = mat_vars(600);
        let p = dir.write("gvt.bin", mat_file(&vars, true, true));
        let rec = read_recording(&p, &opts("Force", "Acceleration:1")).unwrap();
        assert_eq!(rec.format, Format::Mat);
    }

    #[test]
    fn garbled_files_give_errors_not_panics() {
        let dir = Scratch::new("fuzz");
        let freq: Vec<f64> = (1..=16).map(|k| k as f64 * 0.5).collect();
        let frf = Frf::new(
            freq,
            vec![Complex64::new(0.3, -0.2); 16],
            Some(vec![0.9; 16]),
        )
        .unwrap();
        let (_, _, vars) = mat_vars(256);
        let mut tcsv = String::from("t,u,y\n");
        for (n, v) in white(256, 9).iter().enumerate() {
            tcsv.push_str(&format!("{},{v},{}\n", n as f64 * 0.01, v * 2.0));
        }
        let files: Vec<(&str, Vec<u8>, RecordingOptions)> = vec![
            (
                "a.csv",
                csv::write_csv(&frf, csv::CsvLayout::MagDbPhaseDeg).into_bytes(),
                RecordingOptions::default(),
            ),
            (
                "t.csv",
                tcsv.into_bytes(),
                RecordingOptions {
                    welch: WelchOptions {
                        nfft: Some(64),
                        ..Default::default()
                    },
                    ..Default::default()
                },
            ),
            (
                "a.uff",
                uff::write_frf_uff(&frf, uff::Spacing::Uneven)
                    .unwrap()
                    .into_bytes(),
                RecordingOptions::default(),
            ),
            (
                "a.mat",
                mat_file(&vars, true, false),
                opts("Force", "Acceleration:1"),
            ),
            (
                "b.mat",
                mat_file(&vars, false, true),
                opts("Force", "Acceleration:1"),
            ),
        ];
        let mut rng = 0x0123_4567_89ab_cdefu64;
        for (name, bytes, o) in &files {
            let p = dir.0.join(name);
            // The intact file reads.
            std::fs::write(&p, bytes).unwrap();
            read_recording(&p, o).unwrap_or_else(|e| panic!("{e}"));
            // Truncations at 40 points, and 200 random byte changes: any
            // result but a panic is acceptable; a truncation must not
            // silently succeed for the binary formats.
            for k in 0..40 {
                let cut = bytes.len() * k / 40;
                std::fs::write(&p, &bytes[..cut]).unwrap();
                let r = read_recording(&p, o);
                if name.ends_with(".mat") {
                    assert!(r.is_err(), "{name} cut at {cut} read");
                }
            }
            for _ in 0..200 {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                let mut b = bytes.clone();
                let i = (rng as usize) % b.len();
                b[i] = (rng >> 32) as u8;
                std::fs::write(&p, &b).unwrap();
                let _ = read_recording(&p, o);
            }
        }
    }
}
