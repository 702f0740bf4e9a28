//! The recording flags shared by every command that reads a measurement
//! (`mms frf`, `mms identify`), and `mms frf` itself: read a recording,
//! estimate its FRF, write it as CSV or UFF58.

use crate::OutputArg;
use frf::{read_recording, Recording, RecordingOptions, SignalRef, WelchOptions};
use ident::joint::SensorLocation;
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
    /// Output signal of a time-domain recording, as for --u. `mms
    /// identify` takes it more than once (one output per sensor, the same
    /// input), each with its sensor's place in the chain after `@`: PLUS[.MINUS]
    /// with PLUS a mass counted from the ground side or N for the last
    /// mass, MINUS the reference mass (default 0, the ground); e.g. `--y
    /// y1@1 --y y2@N` for a motor and a load encoder.
    #[arg(long, value_name = "VAR[:COL][@SENSOR]")]
    pub y: Vec<String>,
    /// Sample rate in Hz where the file has none (overrides the file's),
    /// or the .mat variable that holds it (e.g. Data.settings.fs).
    #[arg(long, value_name = "HZ|VAR", allow_negative_numbers = true)]
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
        if self.y.len() > 1 {
            return Err(format!(
                "--y is given {} times: only `mms identify` reads several outputs",
                self.y.len()
            ));
        }
        let y = match self.y.first() {
            None => None,
            Some(v) => Some(split_sensor(v)?.0),
        };
        let opts = RecordingOptions {
            u: signal("u", &self.u)?,
            y: signal("y", &y)?,
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

/// `VAR[:COL][@SENSOR]` as the signal and its sensor's location.
fn split_sensor(v: &str) -> Result<(String, Option<SensorLocation>), String> {
    match v.rsplit_once('@') {
        None => Ok((v.to_string(), None)),
        Some((signal, place)) => {
            let location = place.parse().map_err(|e| format!("--y {v}: {e}"))?;
            Ok((signal.to_string(), Some(location)))
        }
    }
}

/// One output of a recording read with several `--y`.
pub struct SensorRecording {
    /// The signal as given (without the location).
    pub signal: String,
    /// Where its sensor sits (`None`: not given).
    pub location: Option<SensorLocation>,
    /// The recording read with this output.
    pub recording: Recording,
}

impl RecordingArgs {
    /// Each `--y` read as its own recording with the same input and
    /// options, with its sensor's location; an error names the output.
    /// The first output may leave its place free (any the structure
    /// allows, as for a single recording); each further one must name it,
    /// on the command line (`@PLUS[.MINUS]`, which wins) or in `listed`:
    /// the sensors a model file lists, one per output in order.
    pub fn read_outputs(&self, listed: &[mms::Port]) -> Result<Vec<SensorRecording>, String> {
        let path = self.path()?;
        let mut out = Vec::with_capacity(self.y.len());
        for (k, v) in self.y.iter().enumerate() {
            let (signal, given) = split_sensor(v)?;
            let from_file = listed.get(k).map(|&p| SensorLocation::from(p));
            let location = given.or(from_file);
            if k > 0 && location.is_none() {
                return Err(format!(
                    "{}: --y {signal} has no sensor location: with several outputs, each after \
                     the first names where its sensor sits (e.g. --y {signal}@N, or the model \
                     file's 'sensors')",
                    path.display()
                ));
            }
            let one = RecordingArgs {
                y: vec![signal.clone()],
                ..self.clone()
            };
            let recording = one.read_file(path).map_err(|e| format!("--y {v}: {e}"))?;
            out.push(SensorRecording {
                signal,
                location,
                recording,
            });
        }
        Ok(out)
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

/// How a time-domain recording's FRF was estimated, where that is worth
/// saying: over the periods of its excitation, given or found in it. The
/// JSON value and a Markdown paragraph.
pub fn periodic_estimate(source: &frf::Source) -> Option<(serde_json::Value, String)> {
    let frf::Source::TimeDomain {
        fs,
        averages,
        period: Some(period),
        ..
    } = source
    else {
        return None;
    };
    let (samples, how) = match period {
        frf::period::Period::Given(p) => (*p, "given"),
        frf::period::Period::Found(p) => (*p, "found"),
    };
    let seconds = samples as f64 / fs;
    let json = serde_json::json!({
        "period_samples": samples,
        "period_s": seconds,
        "period": how,
        "periods_averaged": averages,
    });
    let whence = match period {
        frf::period::Period::Given(_) => "at the period given".to_string(),
        frf::period::Period::Found(_) => {
            "at a period found in the recording, which repeats at it (no --period given)"
                .to_string()
        }
    };
    let md = format!(
        "The FRF is the average over {averages} periods of {samples} samples ({} s), \
         {whence}: only the lines the excitation reaches carry an estimate, each with the \
         scatter between the periods as its noise.\n\n",
        crate::identify::fmt_sig(seconds)
    );
    Some((json, md))
}

/// `md` with the paragraph of [`periodic_estimate`] after its title.
pub fn with_periodic_estimate(md: String, source: &frf::Source) -> String {
    let Some((_, paragraph)) = periodic_estimate(source) else {
        return md;
    };
    match md.find("\n\n") {
        Some(i) => format!("{}{}{}", &md[..i + 2], paragraph, &md[i + 2..]),
        None => md + "\n\n" + &paragraph,
    }
}
