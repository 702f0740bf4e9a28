//! The recording flags shared by every command that reads a measurement
//! (`mms frf`, `mms identify`), and `mms frf` itself: read a recording,
//! estimate its FRF, write it as CSV or UFF58.

use crate::OutputArg;
use frf::{read_recording, Recording, RecordingOptions, SignalRef, WelchOptions};
use std::path::{Path, PathBuf};

/// Where the data come from and what they measure.
#[derive(clap::Args, Clone)]
pub struct RecordingArgs {
    /// The recording: FRF CSV (freq_hz,re,im or freq_hz,mag_db,phase_deg),
    /// UFF dataset 58 (.uff/.unv), time-domain CSV (t,u,y), MATLAB v5
    /// .mat, or a headerless numeric matrix (.dat/.txt). Also accepted as
    /// --recording FILE; give exactly one of the two.
    #[arg(value_name = "RECORDING")]
    pub recording: Option<PathBuf>,
    /// The recording, as a flag (the same as the positional RECORDING).
    #[arg(long = "recording", value_name = "FILE")]
    pub recording_flag: Option<PathBuf>,
    /// Input signal of a time-domain recording: VAR[:COL] (a .mat variable
    /// or CSV column; COL picks a channel of a matrix, counted from 1; a
    /// column number for headerless matrices).
    #[arg(long, value_name = "VAR[:COL]")]
    pub u: Option<String>,
    /// Output signal of a time-domain recording, as for --u.
    #[arg(long, value_name = "VAR[:COL]")]
    pub y: Option<String>,
    /// Sample rate in Hz where the file has none (overrides the file's),
    /// or the .mat variable that holds it (e.g. Data.settings.fs).
    #[arg(long, value_name = "HZ|VAR")]
    pub fs: Option<String>,
    /// The measured quantity.
    #[arg(long, value_enum, default_value_t = OutputArg::Position)]
    pub output: OutputArg,
    /// Segment length of the H1 estimate (default: the largest power of two
    /// giving at least 16 averages).
    #[arg(long, value_name = "SAMPLES")]
    pub nfft: Option<usize>,
    /// Samples per period of a periodic excitation (multisine): rectangular
    /// window, one period per segment, the first period dropped.
    #[arg(long, value_name = "SAMPLES")]
    pub period: Option<usize>,
    /// UFF files with several FRFs: the dataset to read (from 1).
    #[arg(long, value_name = "N")]
    pub dataset: Option<usize>,
    /// The excitation injected into a closed loop (VAR[:COL], as for --u):
    /// the FRF becomes the 3-point estimate S_xy / S_xu from it, which the
    /// noise the controller feeds back does not bias, and the report adds
    /// the loop's sensitivity.
    #[arg(long, value_name = "VAR[:COL]")]
    pub excitation: Option<String>,
}

impl RecordingArgs {
    /// The recording's path: the positional RECORDING or --recording FILE,
    /// exactly one of them.
    pub fn path(&self) -> Result<&Path, String> {
        match (&self.recording, &self.recording_flag) {
            (Some(p), None) | (None, Some(p)) => Ok(p),
            (Some(a), Some(b)) => Err(format!(
                "two recordings given ({} and --recording {}): give exactly one",
                a.display(),
                b.display()
            )),
            (None, None) => Err("no recording given: pass RECORDING or --recording FILE".into()),
        }
    }

    /// The H1 options of `--nfft` and `--period`.
    pub fn welch(&self) -> WelchOptions {
        WelchOptions {
            nfft: self.nfft,
            period: self.period,
            ..WelchOptions::default()
        }
    }

    /// Reads the recording; errors are one line naming the file and place.
    pub fn read(&self) -> Result<Recording, String> {
        self.read_file(self.path()?)
    }

    /// Reads `path` with these flags (e.g. a simulated FRF next to the
    /// recording); errors are one line naming the file and place.
    pub fn read_file(&self, path: &Path) -> Result<Recording, String> {
        let signal = |flag: &str, s: &Option<String>| -> Result<Option<SignalRef>, String> {
            s.as_deref()
                .map(|v| {
                    v.parse::<SignalRef>()
                        .map_err(|e| format!("--{flag} {v}: {e}"))
                })
                .transpose()
        };
        let opts = RecordingOptions {
            u: signal("u", &self.u)?,
            y: signal("y", &self.y)?,
            fs: self.fs.as_deref().and_then(|v| v.trim().parse().ok()),
            fs_variable: self
                .fs
                .as_deref()
                .filter(|v| v.trim().parse::<f64>().is_err())
                .map(str::to_string),
            welch: self.welch(),
            dataset: self.dataset,
            excitation: signal("excitation", &self.excitation)?,
        };
        read_recording(path, &opts).map_err(|e| e.to_string())
    }
}

/// Output formats of `mms frf`.
#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq, Debug)]
pub enum FrfFormat {
    /// freq_hz,re,im[,coherence]
    Csv,
    /// freq_hz,mag_db,phase_deg[,coherence]
    CsvDb,
    /// Universal File Format dataset 58 (ASCII), with a coherence dataset.
    Uff,
}

/// `mms frf`: the FRF of a recording in the chosen format.
pub fn run(args: &RecordingArgs, format: FrfFormat) -> Result<String, String> {
    let rec = args.read()?;
    match format {
        FrfFormat::Csv => Ok(frf::write_csv(&rec.frf, frf::CsvLayout::ReIm)),
        FrfFormat::CsvDb => Ok(frf::write_csv(&rec.frf, frf::CsvLayout::MagDbPhaseDeg)),
        FrfFormat::Uff => frf::write_frf_uff(&rec.frf, frf::Spacing::Uneven)
            .map_err(|e| format!("{}: {e}", args.path().unwrap_or(Path::new("-")).display())),
    }
}
