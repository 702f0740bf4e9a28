//! `mms`: the command-line front end. It parses arguments, calls the `mms`
//! and `poly` libraries and formats what they return.

mod algebra;
mod analyze;
mod analyze_cache;
mod benchmark;
mod check;
mod derive;
mod diagnose;
mod enumerate;
mod identify;
mod merge;
mod notes;
mod output;
mod progress;
mod recording;
mod report;
mod sample;
mod sensors;
mod study;
mod tables;

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;

// The exact algebra allocates and frees many small integers and vectors;
// mimalloc serves that pattern faster than glibc's allocator (measured in
// docs/performance.md).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(
    name = "mms",
    version,
    about = "Multiple-mass models of electromechanical motion systems: enumeration, exact transfer functions, FRF types",
    long_about = None
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// How a recording is identified: the flags `mms identify` and `mms
/// report` share.
#[derive(clap::Args)]
pub struct IdentificationFlags {
    /// Number of masses (default: one more than the resonances found).
    #[arg(long, value_name = "N")]
    masses: Option<usize>,
    /// The FRF is not in SI units (e.g. volts in, encoder counts out):
    /// fit a gain and hold m1, so only parameter ratios are identified.
    #[arg(long)]
    fit_gain: bool,
    /// Only use the lines in this band (e.g. the excitation band of a
    /// multisine), as LO:HI in Hz.
    #[arg(long, value_name = "LO:HI")]
    band: Option<String>,
}

/// Which models a command works on: all classes of N masses, or one model.
#[derive(clap::Args, Clone)]
#[group(required = true, multiple = false)]
pub struct Selection {
    /// All models of N masses (the paper's rule (3) representatives).
    #[arg(long, value_name = "N")]
    masses: Option<usize>,
    /// One model: a paper ID for 3 masses (A1..A5, B1, B2, C1..C4, star
    /// optional) or a generic ID such as N4-g1-a2.1-s3.1.
    #[arg(value_name = "ID")]
    id: Option<String>,
}

#[derive(Subcommand)]
enum Command {
    /// Count and list the models of N masses (the paper's Tab. 1 and more).
    Enumerate {
        /// Number of masses.
        #[arg(long, value_name = "N")]
        masses: usize,
        #[arg(long, value_enum, default_value_t = TableFormat::Table)]
        format: TableFormat,
    },
    /// Derive transfer functions symbolically from the chain graph.
    Derive {
        #[command(flatten)]
        selection: Selection,
        #[arg(long, value_enum, default_value_t = DeriveFormat::Text)]
        format: DeriveFormat,
        /// Measured quantity: position (receptance), velocity, or acceleration (inertance).
        #[arg(long, value_enum, default_value_t = OutputArg::Acceleration)]
        output: OutputArg,
        /// The damped TF in s instead of the undamped TF in Omega = w^2.
        #[arg(long)]
        damped: bool,
        /// Write the paper's abbreviations m_{1.2} = m1*m2, m_{1+2} = m1+m2 (md and tex).
        #[arg(long)]
        abbreviate: bool,
    },
    /// Benchmark pipeline: Num, Den, Res(Num, Den), Disc(Num), Disc(Den) and their factorizations.
    Algebra {
        /// Number of masses.
        #[arg(long, value_name = "N")]
        masses: usize,
        #[arg(long, value_enum, default_value_t = AlgebraFormat::Text)]
        format: AlgebraFormat,
    },
    /// Which FRF types each model can show, with witnesses and certificates (Tab. 3).
    ///
    /// Long runs (--masses 4 and up): progress on stderr when it is a
    /// terminal, and a closing line with the wall time and the total, median
    /// and maximum analysis time per model.
    Analyze {
        #[command(flatten)]
        selection: Selection,
        #[arg(long, value_enum, default_value_t = TableFormat3::Table)]
        format: TableFormat3,
        /// Analyse N models at a time (0: one per core). The output is the
        /// same, byte for byte, for every N.
        #[arg(long, value_name = "N", default_value_t = 1)]
        jobs: usize,
        /// Keep every finished model's analysis in DIR (one file per model,
        /// written atomically) and reuse it when rerun with the same DIR: an
        /// interrupted run resumes where it stopped. Unusable or stale files
        /// are recomputed, with a warning.
        #[arg(long, value_name = "DIR")]
        cache: Option<PathBuf>,
        /// Add analysis times to --format json (a "timing" object per model
        /// and one for the run), which makes the output differ between runs.
        #[arg(long)]
        timings: bool,
        /// Analyse only slice K of N of the classes (with --masses and
        /// --format json), e.g. one task of a Slurm array or a Kubernetes
        /// indexed Job; `mms merge` joins the N files into the table.
        #[arg(long, value_name = "K/N", allow_hyphen_values = true)]
        shard: Option<String>,
    },
    /// Join the slices of a table (`mms analyze --masses N --shard K/N
    /// --format json`, one file each) into the whole table, as one run
    /// writes it; slices of other versions or settings, overlaps and gaps
    /// are refused.
    Merge {
        /// The slice files, in any order.
        #[arg(value_name = "FILE", required = true)]
        files: Vec<PathBuf>,
        /// Write the table to this file (atomically) instead of stdout.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Write out the derivation of one verdict: witness or certificate (eqs. 22-31 style).
    Prove {
        /// Model ID (paper ID for 3 masses, or generic).
        #[arg(value_name = "ID")]
        id: String,
        /// FRF type, e.g. ARR, A^2RR, "RR (nm)", C.
        #[arg(value_name = "TYPE")]
        frf_type: String,
        #[arg(long, value_enum, default_value_t = ReportFormat::Md)]
        format: ReportFormat,
    },
    /// Re-verify every witness and certificate of an `analyze --format json`
    /// file with the independent exact checker.
    ///
    /// Progress on stderr when it is a terminal; with --cache an
    /// interrupted check resumes.
    Check {
        /// The JSON file written by `mms analyze --format json` (the whole
        /// table, a slice of it, or one model).
        #[arg(value_name = "FILE")]
        file: PathBuf,
        /// Check N models at a time (0: one per core). The output is the
        /// same for every N.
        #[arg(long, value_name = "N", default_value_t = 1)]
        jobs: usize,
        /// Keep a record of every model verified in DIR (one file per
        /// model, written atomically) and take a model whose entry equals
        /// a record's as verified: an interrupted check resumes, and a
        /// table merged from checked slices checks only what depends on
        /// the whole table. Records of other versions are not used.
        #[arg(long, value_name = "DIR")]
        cache: Option<PathBuf>,
    },
    /// Sample every unknown type of an analysis table on its own region
    /// (the variety of its cancelled poles and multiple zeros): how often
    /// points there show it, and whether any shows a type the table
    /// certifies impossible. Evidence for the open cells, not a verdict.
    ///
    /// Long runs show progress on stderr when it is a terminal; with
    /// --cache an interrupted run resumes.
    Sample {
        /// The JSON file written by `mms analyze --format json`.
        #[arg(value_name = "FILE")]
        file: PathBuf,
        /// Starts per cell (coincidence structure of a model's unknown
        /// types).
        #[arg(long, value_name = "N", default_value_t = 100_000)]
        starts: u64,
        /// Sample N cells at a time (0: one per core). The output is the
        /// same for every N.
        #[arg(long, value_name = "N", default_value_t = 1)]
        jobs: usize,
        /// Keep every finished cell's counts in DIR and reuse them when
        /// rerun with the same DIR, starts and version.
        #[arg(long, value_name = "DIR")]
        cache: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = sample::SampleFormat::Md)]
        format: sample::SampleFormat,
        /// Write to this file (atomically) instead of stdout.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// The concealed-effect benchmark: seeded recordings of random chains
    /// with one or two effects the model lacks (or none), diagnosed (and
    /// the controls identified) with the default options; prints the
    /// confusion matrix, parameter accuracy, the false-effect rate,
    /// accuracy per excitation, domain and loop, and time per case.
    ///
    /// Long runs show progress on stderr when it is a terminal; with
    /// --cache an interrupted run resumes.
    Benchmark {
        /// Number of cases.
        #[arg(long, value_name = "N", default_value_t = 200)]
        cases: usize,
        /// Seed of the cases (the same seed, the same cases).
        #[arg(long, value_name = "S", default_value_t = 1)]
        seed: u64,
        /// Run N cases at a time (0: one per core).
        #[arg(long, value_name = "N", default_value_t = 1)]
        jobs: usize,
        /// Keep every finished case's outcome in DIR and reuse it when
        /// rerun with the same DIR, seed and generator version.
        #[arg(long, value_name = "DIR")]
        cache: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = benchmark::BenchmarkFormat::Md)]
        format: benchmark::BenchmarkFormat,
        /// Write to this file (atomically) instead of stdout.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Estimate or convert the FRF of a recording (H1 with Welch averaging
    /// for time-domain data) and write it as CSV or UFF58.
    Frf {
        #[command(flatten)]
        recording: recording::RecordingArgs,
        #[arg(long, value_enum, default_value_t = recording::FrfFormat::Csv)]
        format: recording::FrfFormat,
        /// Write to this file (atomically) instead of stdout.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Identify structure and parameters from a measured FRF: classify its
    /// type, fit every candidate structure, rank them, name the
    /// indistinguishable ones and the extra sensor that would separate them.
    Identify {
        #[command(flatten)]
        recording: recording::RecordingArgs,
        #[command(flatten)]
        identification: IdentificationFlags,
        /// A recording of the same rig at another operating point
        /// (standstill and moving, another speed or level), read with the
        /// same options: its features are compared with this one's, and a
        /// stiffness to ground that one operating point alone shows is
        /// named as pre-sliding friction. May be given more than once.
        #[arg(long = "operating-point", value_name = "FILE")]
        operating_points: Vec<PathBuf>,
        #[arg(long, value_enum, default_value_t = identify::IdentifyFormat::Md)]
        format: identify::IdentifyFormat,
        /// Write report, Bode plots (SVG, PNG) and the best model
        /// (model.toml) into this directory instead of the report to stdout.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Diagnose where a model and a recording differ: calibrate the model's
    /// parameters (within a tolerance), locate the mismatch bands, name the
    /// missing physics (delay, lag, gain error, hysteretic damping,
    /// friction, an extra mass, or nothing; several at once by forward
    /// selection), add it and report the improvement. On a time-domain
    /// recording also the time-domain diagnosis: Coulomb friction or
    /// backlash, fitted by simulating the model from the recorded input.
    /// With --level, recordings at other excitation levels: which modes
    /// shift in frequency or damping with the level beyond the noise.
    Diagnose {
        #[command(flatten)]
        recording: recording::RecordingArgs,
        /// The model file (TOML), e.g. the model.toml `mms identify --out` writes.
        /// Give exactly one of --model and --simulation (or neither, with
        /// --level: then only the amplitude comparison runs).
        #[arg(long, value_name = "MODEL.toml")]
        model: Option<PathBuf>,
        /// A simulated FRF (FRF CSV or UFF58) in place of --model: the chain
        /// model that reproduces it (within 0.05 dB) is identified and
        /// diagnosed.
        #[arg(long, value_name = "FILE")]
        simulation: Option<PathBuf>,
        /// Another time-domain recording of the same system at a different
        /// excitation level (repeatable), read with the same --u, --y,
        /// --fs, --nfft, --period: the modes' frequency and damping are
        /// compared across the levels against the noise (amplitude
        /// dependence: friction or clearance at a joint). Without --model
        /// and --simulation only this comparison runs.
        #[arg(long = "level", value_name = "FILE")]
        levels: Vec<PathBuf>,
        /// Another recording of the same rig, read with the same flags (and
        /// in a closed loop the same --reference, --controller,
        /// --disturbance variables): diagnosed with the same model, it says
        /// which effects and parameters carry over and how the model after
        /// this diagnosis fits it.
        #[arg(long, value_name = "FILE")]
        validate: Option<PathBuf>,
        /// A recording of the same rig at another operating point
        /// (standstill and moving, another speed), read with the same
        /// flags: diagnosed with the same model, the report says which
        /// effects each operating point shows, and compares the two FRFs
        /// feature by feature (mode shifts, damping changes, pre-sliding
        /// friction at standstill). Repeat for several.
        #[arg(long = "operating-point", value_name = "FILE")]
        operating_points: Vec<PathBuf>,
        #[command(flatten)]
        diagnosis: diagnose::DiagnosisFlags,
        /// Only use the lines in this band, as LO:HI in Hz (default: the
        /// band the classification trusts).
        #[arg(long, value_name = "LO:HI")]
        band: Option<String>,
        #[arg(long, value_enum, default_value_t = identify::IdentifyFormat::Md)]
        format: identify::IdentifyFormat,
        /// Write report, Bode plots and model_after.toml into this directory.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// One report on one recording: identify it, diagnose it with --model
    /// (or, without, with the identification's best fit), and join both
    /// into one page: the two verdicts first, then the Bode plots, then
    /// each one's tables.
    Report {
        #[command(flatten)]
        recording: recording::RecordingArgs,
        /// The model file (TOML) to diagnose the recording with; without it
        /// (and without --simulation), the best fit of the identification.
        #[arg(long, value_name = "MODEL.toml", conflicts_with = "simulation")]
        model: Option<PathBuf>,
        /// A simulated FRF (FRF CSV or UFF58) whose chain model is
        /// diagnosed, as for `mms diagnose --simulation`.
        #[arg(long, value_name = "FILE")]
        simulation: Option<PathBuf>,
        #[command(flatten)]
        identification: IdentificationFlags,
        #[command(flatten)]
        diagnosis: diagnose::DiagnosisFlags,
        #[arg(long, value_enum, default_value_t = identify::IdentifyFormat::Md)]
        format: identify::IdentifyFormat,
        /// Write the report, every Bode plot (identify-*.svg/png,
        /// diagnose-*.svg/png), model.toml and model_after.toml into this
        /// directory.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// The full study of N masses as one report (default: the paper's 3 masses).
    Study {
        /// Number of masses.
        #[arg(long, value_name = "N", default_value_t = 3)]
        masses: usize,
        #[arg(long, value_enum, default_value_t = ReportFormat::Md)]
        format: ReportFormat,
        /// Write the report to this file (atomically) instead of stdout.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
}

#[derive(ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum TableFormat {
    Table,
    Json,
    Md,
}

#[derive(ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum DeriveFormat {
    Text,
    Json,
    Md,
    Tex,
}

#[derive(ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum TableFormat3 {
    Table,
    Json,
    Md,
    Tex,
    /// A Markdown document: counts, what the types say about the
    /// structure, rule (3), the table, the undecided verdicts.
    Report,
}

#[derive(ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum AlgebraFormat {
    Text,
    Json,
}

#[derive(ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum ReportFormat {
    Md,
    Tex,
}

#[derive(ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum OutputArg {
    Position,
    Velocity,
    Acceleration,
}

impl From<OutputArg> for mms::Output {
    fn from(o: OutputArg) -> Self {
        match o {
            OutputArg::Position => mms::Output::Position,
            OutputArg::Velocity => mms::Output::Velocity,
            OutputArg::Acceleration => mms::Output::Acceleration,
        }
    }
}

/// One model of every renumbering class of `n` masses, in the tables'
/// order ([`mms::class_representatives`]).
pub fn class_representatives(n: usize) -> Result<Vec<mms::Model>, String> {
    mms::class_representatives(n).map_err(|e| format!("--masses {n}: {e}"))
}

/// The models a selection names.
pub fn select(sel: &Selection) -> Result<Vec<mms::Model>, String> {
    match (&sel.masses, &sel.id) {
        (Some(n), _) => class_representatives(*n),
        (None, Some(id)) => mms::Model::from_id(id)
            .map(|m| vec![m])
            .map_err(|e| e.to_string()),
        (None, None) => Err("give --masses N or a model ID".into()),
    }
}

/// `LO:HI` in Hz, `0 <= LO < HI`.
fn parse_band(s: &str) -> Result<(f64, f64), String> {
    let bad = || format!("--band {s}: expected LO:HI in Hz with 0 <= LO < HI, e.g. 2:15");
    let (lo, hi) = s.split_once(':').ok_or_else(bad)?;
    let lo: f64 = lo.trim().parse().map_err(|_| bad())?;
    let hi: f64 = hi.trim().parse().map_err(|_| bad())?;
    if lo.is_finite() && hi.is_finite() && lo >= 0.0 && lo < hi {
        Ok((lo, hi))
    } else {
        Err(bad())
    }
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Enumerate { masses, format } => {
            output::emit(None, &enumerate::run(masses, format)?)
        }
        Command::Derive {
            selection,
            format,
            output,
            damped,
            abbreviate,
        } => {
            let models = select(&selection)?;
            let text = derive::run(&models, format, output.into(), damped, abbreviate)?;
            output::emit(None, &text)
        }
        Command::Analyze {
            selection,
            format,
            jobs,
            cache,
            timings,
            shard,
        } => {
            let shard = match shard {
                None => None,
                Some(spec) => {
                    let shard: mms::table::Shard =
                        spec.parse().map_err(|e| format!("--shard: {e}"))?;
                    if selection.masses.is_none() || format != TableFormat3::Json {
                        return Err(format!(
                            "--shard {spec}: slices a table: give --masses N and --format json"
                        ));
                    }
                    Some(shard)
                }
            };
            let models = select(&selection)?;
            let opts = analyze::Options {
                jobs,
                cache,
                timings,
                shard,
            };
            output::emit(None, &analyze::run(&models, format, &opts)?)
        }
        Command::Merge { files, out } => output::emit(out.as_deref(), &merge::run(&files)?),
        Command::Prove {
            id,
            frf_type,
            format,
        } => {
            let model = mms::Model::from_id(&id).map_err(|e| e.to_string())?;
            let t: mms::analysis::FrfType = frf_type
                .parse()
                .map_err(|e: mms::analysis::ParseFrfTypeError| e.to_string())?;
            let a = mms::analysis::analyze(&model, &mms::analysis::SearchLimits::default());
            let fmt = match format {
                ReportFormat::Md => mms::analysis::ExplainFormat::Markdown,
                ReportFormat::Tex => mms::analysis::ExplainFormat::Latex,
            };
            let text = mms::analysis::explain(&a, &t, fmt).ok_or_else(|| {
                format!(
                    "type {t} is not a candidate of {id}: its TF has numerator degree {} and denominator degree {} in Omega",
                    a.numerator.degree("Omega"),
                    a.denominator.degree("Omega")
                )
            })?;
            output::emit(None, &text)
        }
        Command::Benchmark {
            cases,
            seed,
            jobs,
            cache,
            format,
            out,
        } => {
            let opts = benchmark::Options {
                cases,
                seed,
                jobs,
                cache,
                format,
            };
            output::emit(out.as_deref(), &benchmark::run(&opts)?)
        }
        Command::Check { file, jobs, cache } => {
            output::emit(None, &check::run(&file, jobs, cache.as_deref())?)
        }
        Command::Sample {
            file,
            starts,
            jobs,
            cache,
            format,
            out,
        } => {
            let opts = sample::Options {
                starts,
                jobs,
                cache,
                format,
            };
            output::emit(out.as_deref(), &sample::run(&file, &opts)?)
        }
        Command::Algebra { masses, format } => output::emit(None, &algebra::run(masses, format)?),
        Command::Frf {
            recording,
            format,
            out,
        } => output::emit(out.as_deref(), &recording::run(&recording, format)?),
        Command::Identify {
            recording,
            identification,
            operating_points,
            format,
            out,
        } => {
            let args = identify::IdentifyArgs {
                recording: &recording,
                masses: identification.masses,
                fit_gain: identification.fit_gain,
                band: identification.band.as_deref().map(parse_band).transpose()?,
                operating_points: &operating_points,
                format,
                out: out.as_deref(),
            };
            output::emit_report(identify::run(&args)?)
        }
        Command::Diagnose {
            recording,
            model,
            simulation,
            levels,
            validate,
            operating_points,
            diagnosis,
            band,
            format,
            out,
        } => {
            let model = match (model, simulation) {
                (Some(m), None) => Some(diagnose::ModelSource::File(m)),
                (None, Some(s)) => Some(diagnose::ModelSource::Simulation(s)),
                (Some(_), Some(_)) => {
                    return Err("give either --model or --simulation, not both".into())
                }
                // The amplitude comparison alone needs no model.
                (None, None) if !levels.is_empty() => None,
                (None, None) => {
                    return Err("give the model: --model MODEL.toml or --simulation FILE".into())
                }
            };
            let args = diagnose::DiagnoseArgs {
                recording: &recording,
                model: model.as_ref(),
                levels: &levels,
                validate: validate.as_deref(),
                operating_points: &operating_points,
                select: diagnosis.select,
                tolerance: diagnosis.tolerance,
                band: band.as_deref().map(parse_band).transpose()?,
                closed_loop: diagnosis.closed_loop(),
                format,
                out: out.as_deref(),
            };
            output::emit_report(diagnose::run(&args)?)
        }
        Command::Report {
            recording,
            model,
            simulation,
            identification,
            diagnosis,
            format,
            out,
        } => {
            let source = match (model, simulation) {
                (Some(m), _) => Some(diagnose::ModelSource::File(m)),
                (None, Some(s)) => Some(diagnose::ModelSource::Simulation(s)),
                (None, None) => None,
            };
            let args = report::ReportArgs {
                recording: &recording,
                masses: identification.masses,
                fit_gain: identification.fit_gain,
                band: identification.band.as_deref().map(parse_band).transpose()?,
                model: source.as_ref(),
                select: diagnosis.select,
                tolerance: diagnosis.tolerance,
                closed_loop: diagnosis.closed_loop(),
                format,
                out: out.as_deref(),
            };
            output::emit_report(report::run(&args)?)
        }
        Command::Study {
            masses,
            format,
            out,
        } => {
            let text = study::run(masses, format)?;
            output::emit(out.as_deref(), &text)
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("mms: error: {e}");
            ExitCode::from(2)
        }
    }
}
