//! `mms diagnose`: where a model and a recording differ, which physics the
//! model left out, and how much adding it improves the fit. A time-domain
//! recording also gets the time-domain diagnosis (Coulomb friction,
//! backlash) from its samples.

use crate::identify::IdentifyFormat;
use crate::recording::RecordingArgs;
use ident::amplitude::{
    amplitude_dependence, AmplitudeDependence, AmplitudeOptions, DampingTrend, Level,
    StiffnessTrend,
};
use ident::diagnose::{
    diagnose, model_from_simulation, DiagnoseOptions, Diagnosis, EffectKind, Selection,
};
use ident::nonlinear::{
    diagnose_closed_loop, diagnose_time, LoopRecord, TimeDiagnosis, TimeOptions,
};
use mms::model_file::ModelFile;
use mms::response::ChainResponse;
use mms::simulate::{ClosedLoop, Controller, SimOptions, Simulator};
use plot::{Bode, Style};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// `--select`: how an effect earns its parameters.
#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq, Debug)]
pub enum SelectArg {
    /// Bayesian information criterion on all lines.
    Bic,
    /// Validation on held-out lines (every 4th).
    Holdout,
}

/// Where the model comes from.
pub enum ModelSource {
    /// A model file.
    File(PathBuf),
    /// A simulated FRF whose chain model is identified.
    Simulation(PathBuf),
}

/// `--reference`, `--controller`, `--disturbance`: the position loop a
/// recording was taken in.
pub struct LoopArgs {
    pub reference: String,
    pub controller: String,
    pub disturbance: Option<String>,
}

/// The loop read from the recording.
struct LoopData {
    controller: Controller,
    reference: Vec<f64>,
    disturbance: Option<Vec<f64>>,
}

impl LoopData {
    fn record(&self) -> LoopRecord<'_> {
        LoopRecord {
            controller: &self.controller,
            reference: &self.reference,
            disturbance: self.disturbance.as_deref(),
        }
    }
}

/// Options of `mms diagnose` beyond the recording.
pub struct DiagnoseArgs<'a> {
    pub recording: &'a RecordingArgs,
    /// `None`: only the amplitude comparison of the levels.
    pub model: Option<&'a ModelSource>,
    /// Recordings of the same system at other excitation levels.
    pub levels: &'a [PathBuf],
    pub select: SelectArg,
    pub tolerance: f64,
    pub band: Option<(f64, f64)>,
    pub closed_loop: Option<LoopArgs>,
    pub format: IdentifyFormat,
    pub out: Option<&'a Path>,
}

/// Runs the diagnosis; returns the report for stdout when no `--out`
/// directory is given.
pub fn run(args: &DiagnoseArgs) -> Result<Option<String>, String> {
    let rec = args.recording.read()?;
    let levels = amplitude(args, &rec)?;
    let Some(model_source) = args.model else {
        return match &levels {
            Some((levels, a)) => amplitude_only(args, levels, a),
            None => Err("give the model: --model MODEL.toml or --simulation FILE".into()),
        };
    };
    let amplitude = levels.map(|(_, a)| a);
    let model = match model_source {
        ModelSource::File(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
            ModelFile::parse(&text).map_err(|e| match e.line {
                Some(l) => format!("{}:{l}: {}", path.display(), e.message),
                None => format!("{}: {}", path.display(), e.message),
            })?
        }
        ModelSource::Simulation(path) => {
            let sim = frf::read_recording(path, &frf::RecordingOptions::default())
                .map_err(|e| e.to_string())?;
            model_from_simulation(&sim.frf, args.recording.output.into())
                .map_err(|e| format!("{}: {e}", path.display()))?
        }
    };
    let source = match model_source {
        ModelSource::File(path) => format!("Model: `{}` ({}).", path.display(), model.model.id()),
        ModelSource::Simulation(path) => format!(
            "Model: {} identified from the simulation `{}` (reproduced within {} dB).",
            model.model.id(),
            path.display(),
            ident::diagnose::SIMULATION_TOLERANCE_DB
        ),
    };
    if !(args.tolerance.is_finite() && args.tolerance > 0.0 && args.tolerance < 10.0) {
        return Err(format!(
            "--tolerance {}: expected a fraction such as 0.2 (0 < t < 10)",
            args.tolerance
        ));
    }
    let options = DiagnoseOptions {
        tolerance: args.tolerance,
        selection: match args.select {
            SelectArg::Bic => Selection::Bic,
            SelectArg::Holdout => Selection::Holdout,
        },
        ..DiagnoseOptions::default()
    };
    let name = args.recording.path()?.display().to_string();
    // The lines the data can be trusted on: --band, else the band the
    // classification trusts (coherence, outliers), as `mms identify` uses.
    let (lo, hi) = match args.band {
        Some(b) => b,
        None => ident::classify(&rec.frf, model.output, &ident::ClassifyOptions::default())
            .map(|c| c.band_hz)
            .unwrap_or((0.0, f64::INFINITY)),
    };
    let data = rec
        .frf
        .band(lo.max(f64::MIN_POSITIVE), hi)
        .ok_or_else(|| format!("{name}: no frequency lines in the band {lo}..{hi} Hz"))?;
    let mut linear = model.clone();
    // The FRF knows nothing of the nonlinear effects.
    linear.effects.coulomb_friction = None;
    linear.effects.backlash_gap = None;
    let d = diagnose(&data, &linear, &options).map_err(|e| format!("{name}: {e}"))?;
    // A time-domain recording is also checked for the nonlinear effects. If
    // one is found it leads the report (with the frequency-domain diagnosis
    // inside); if not, the frequency-domain report stands, with the check
    // noted, so that a linear effect (a dead time) is not hidden behind a
    // time-domain "none".
    let mut time_check = None;
    let looped = match &args.closed_loop {
        Some(l) => Some(read_loop(args.recording, l, rec.samples.as_ref())?),
        None => None,
    };
    if let Some(samples) = &rec.samples {
        let options = TimeOptions {
            tolerance: args.tolerance,
            welch: args.recording.welch(),
            ..TimeOptions::default()
        };
        let td = match &looped {
            None => diagnose_time(&samples.u, &samples.y, samples.fs, &model, &options),
            Some(l) => diagnose_closed_loop(
                &samples.u,
                &samples.y,
                samples.fs,
                &model,
                &l.record(),
                &options,
            ),
        }
        .map_err(|e| format!("{name}: time-domain diagnosis: {e}"))?;
        if td
            .effects
            .first()
            .is_some_and(|e| e.kind != EffectKind::None)
        {
            let record = looped.as_ref().map(|l| l.record());
            return run_time(
                args,
                &name,
                &source,
                &rec.frf,
                samples,
                &model,
                record,
                td,
                d,
                amplitude.as_ref(),
            );
        }
        time_check = Some(td);
    }
    let plot = bode(&data, &model, &d);
    let report = match args.format {
        IdentifyFormat::Json => {
            let mut v = serde_json::to_value(&d).map_err(|e| format!("JSON: {e}"))?;
            if let Some(td) = &time_check {
                v["time_domain"] = serde_json::json!({
                    "effects": td.effects,
                    "rejected": td.rejected,
                    "evidence": td.evidence,
                    "rms_time_rel": td.fit.before.rms_time_rel,
                    "closed_loop": td.closed_loop,
                    "inverse_dynamics": td.inverse_dynamics,
                });
            }
            if let Some(a) = &amplitude {
                v["amplitude_dependence"] =
                    serde_json::to_value(a).map_err(|e| format!("JSON: {e}"))?;
            }
            let mut s = serde_json::to_string_pretty(&v).map_err(|e| format!("JSON: {e}"))?;
            s.push('\n');
            s
        }
        IdentifyFormat::Md | IdentifyFormat::Html => {
            let mut m = markdown(
                &name,
                &source,
                &d,
                (args.format == IdentifyFormat::Md && args.out.is_some()).then_some("bode.svg"),
            );
            if let Some(td) = &time_check {
                m.push_str(&time_check_note(td));
            }
            if let Some(a) = &amplitude {
                m.push_str(&amplitude_markdown(a));
            }
            if args.format == IdentifyFormat::Md {
                m
            } else {
                crate::identify::html_page("mms diagnose", &m, &plot.to_svg())
            }
        }
    };
    finish(args, &plot, &d.model_after, report)
}

/// The recording, the calibrated model and the improved model, with the
/// mismatch bands shaded, and the residual panel.
fn bode(frf: &frf::Frf, before: &ModelFile, d: &Diagnosis) -> Bode {
    let f = frf.freq_hz();
    let eval = |m: &ModelFile| {
        let g = ChainResponse::with_effects(&m.model, m.output, &m.effects);
        crate::identify::model_curve(&g, m.parameters.values(), m.gain, f)
    };
    let mut b = Bode::new("Recording, model, and model with the missing physics")
        .trace("recording", f, frf.response(), Style::points())
        .trace("model (nominal)", f, &eval(before), Style::dashed())
        .trace(
            "model after diagnosis",
            f,
            &eval(&d.model_after),
            Style::line(),
        );
    for band in &d.mismatch {
        b = b.band(band.f_lo_hz, band.f_hi_hz, "mismatch");
    }
    b.residual()
}

fn markdown(name: &str, source: &str, d: &Diagnosis, plot: Option<&str>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Diagnosis of `{name}`\n");
    let _ = writeln!(s, "{source}\n");
    let best = d.effects.first();
    let verdict = match best {
        Some(e) if e.kind != EffectKind::None => {
            let causes = effect_names(&d.effects);
            let bands: Vec<String> = d
                .mismatch
                .iter()
                .map(|b| format!("{:.4} and {:.4} Hz", b.f_lo_hz, b.f_hi_hz))
                .collect();
            format!(
                "The recording differs from the model{}; most likely cause: {}; after adding {} \
                 the error drops from {:.3} dB / {:.2} deg to {:.3} dB / {:.2} deg RMS.",
                if bands.is_empty() {
                    String::new()
                } else {
                    format!(" between {}", bands.join(", "))
                },
                causes.join(" together with "),
                if causes.len() > 1 { "them" } else { "it" },
                d.fit.before.rms_db,
                d.fit.before.rms_deg,
                d.fit.after.rms_db,
                d.fit.after.rms_deg
            )
        }
        _ => format!(
            "Nothing is missing: after calibration the model explains the recording within the noise \
             ({:.3} dB / {:.2} deg RMS).",
            d.fit.before.rms_db, d.fit.before.rms_deg
        ),
    };
    let _ = writeln!(s, "{verdict}\n");
    if let Some(p) = plot {
        let _ = writeln!(s, "![Bode plot: recording, model, improved model]({p})\n");
    }
    s.push_str(
        "## Mismatch bands\n\n| from (Hz) | to (Hz) | RMS dB | RMS deg |\n|---:|---:|---:|---:|\n",
    );
    for b in &d.mismatch {
        let _ = writeln!(
            s,
            "| {:.4} | {:.4} | {:.3} | {:.2} |",
            b.f_lo_hz, b.f_hi_hz, b.rms_db, b.rms_deg
        );
    }
    effects_and_calibration(&mut s, "Effects", &d.effects, &d.rejected, &d.calibration);
    s
}

/// The effects table (kept, then rejected) and the calibration notes.
fn effects_and_calibration(
    s: &mut String,
    title: &str,
    effects: &[ident::diagnose::EffectVerdict],
    rejected: &[ident::diagnose::EffectVerdict],
    calibration: &[String],
) {
    let _ = write!(
        s,
        "\n## {title}\n\n| kind | parameters | step | score | evidence |\n|---|---|---:|---:|---|\n"
    );
    for e in effects.iter().chain(rejected) {
        let params: Vec<String> = e
            .parameters
            .iter()
            .map(|(k, v)| format!("{k} = {v:.4e}"))
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {} |",
            e.kind.as_str(),
            params.join(", "),
            e.step,
            e.score,
            e.evidence
        );
    }
    if !calibration.is_empty() {
        s.push_str("\n## Calibration\n\n");
        for c in calibration {
            let _ = writeln!(s, "- {c}");
        }
    }
}

/// The time-domain diagnosis of a time-domain recording, with the
/// frequency-domain diagnosis `fd` of its H1 estimate attached.
#[allow(clippy::too_many_arguments)]
fn run_time(
    args: &DiagnoseArgs,
    name: &str,
    source: &str,
    recorded: &frf::Frf,
    samples: &frf::Samples,
    model: &ModelFile,
    record: Option<LoopRecord>,
    mut d: TimeDiagnosis,
    fd: Diagnosis,
    amplitude: Option<&AmplitudeDependence>,
) -> Result<Option<String>, String> {
    d.mismatch = fd.mismatch.clone();
    d.frequency_domain = Some(fd);
    let plot = time_bode(
        recorded,
        &args.recording.welch(),
        samples,
        model,
        record.as_ref(),
        &d,
    )?;
    let markdown = |plot: Option<&str>| {
        let mut m = time_markdown(name, source, &d, plot);
        if let Some(a) = amplitude {
            m.push_str(&amplitude_markdown(a));
        }
        m
    };
    let report = match args.format {
        IdentifyFormat::Json => {
            let mut v = serde_json::to_value(&d).map_err(|e| format!("JSON: {e}"))?;
            if let Some(a) = amplitude {
                v["amplitude_dependence"] =
                    serde_json::to_value(a).map_err(|e| format!("JSON: {e}"))?;
            }
            let mut s = serde_json::to_string_pretty(&v).map_err(|e| format!("JSON: {e}"))?;
            s.push('\n');
            s
        }
        IdentifyFormat::Md => markdown(args.out.map(|_| "bode.svg")),
        IdentifyFormat::Html => {
            crate::identify::html_page("mms diagnose", &markdown(None), &plot.to_svg())
        }
    };
    finish(args, &plot, &d.model_after, report)
}

/// The recording's H1 estimate and those of the nominal and diagnosed
/// models simulated from the recorded input (in a closed loop: inside the
/// loop, with the simulated input), with the same options (`--nfft`,
/// `--period`), so the curves share their lines.
fn time_bode(
    recorded: &frf::Frf,
    welch: &frf::WelchOptions,
    samples: &frf::Samples,
    model: &ModelFile,
    record: Option<&LoopRecord>,
    d: &TimeDiagnosis,
) -> Result<Bode, String> {
    let sim = |m: &ModelFile| -> Result<frf::Frf, String> {
        let (u, y) = match record {
            None => {
                let y = mms::simulate::simulate(m, &samples.u, samples.fs)
                    .map_err(|e| e.to_string())?;
                (samples.u.clone(), y)
            }
            Some(r) => {
                let q = &samples.y;
                let run = Simulator::new(m, samples.fs, &SimOptions::default())
                    .and_then(|s| {
                        s.run_closed_loop(&ClosedLoop {
                            controller: r.controller,
                            reference: r.reference,
                            disturbance: r.disturbance,
                            initial_position: q[0],
                            initial_velocity: (q[2] - q[0]) * samples.fs / 2.0,
                        })
                    })
                    .map_err(|e| e.to_string())?;
                (run.u, run.y)
            }
        };
        frf::h1(&u, &y, samples.fs, welch)
            .map(|e| e.frf)
            .map_err(|e| format!("H1 estimate: {e}"))
    };
    let (nominal, after) = (sim(model)?, sim(&d.model_after)?);
    let f = recorded.freq_hz();
    let mut b = Bode::new("Recording and simulated models (H1 from the recorded input)")
        .trace("recording", f, recorded.response(), Style::points())
        .trace("model (nominal)", f, nominal.response(), Style::dashed())
        .trace("model after diagnosis", f, after.response(), Style::line());
    for band in &d.mismatch {
        b = b.band(band.f_lo_hz, band.f_hi_hz, "mismatch");
    }
    Ok(b.residual())
}

/// `**kind** (parameter = value, ...)` for each effect, best first.
fn effect_names(effects: &[ident::diagnose::EffectVerdict]) -> Vec<String> {
    effects
        .iter()
        .map(|e| {
            let params: Vec<String> = e
                .parameters
                .iter()
                .map(|(k, v)| format!("{k} = {v:.4e}"))
                .collect();
            format!("**{}** ({})", e.kind.as_str(), params.join(", "))
        })
        .collect()
}

fn time_markdown(name: &str, source: &str, d: &TimeDiagnosis, plot: Option<&str>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Diagnosis of `{name}` (time domain)\n");
    let _ = writeln!(
        s,
        "{} samples at {} Hz, simulated with the model {}.\n",
        d.samples,
        d.fs,
        if d.closed_loop {
            "inside the recorded position loop (controller and reference)"
        } else {
            "from the recorded input"
        }
    );
    let (b, a) = (&d.fit.before, &d.fit.after);
    let verdict = match d.effects.first() {
        Some(e) if e.kind != EffectKind::None => {
            let causes = effect_names(&d.effects);
            format!(
                "Most likely missing: {}; adding {} brings the time-domain error from {:.4e} to \
                 {:.4e} ({} % to {} % of the output RMS), and the FRF error from {:.3} dB / \
                 {:.2} deg to {:.3} dB / {:.2} deg.",
                causes.join(" together with "),
                if causes.len() > 1 { "them" } else { "it" },
                b.rms_time,
                a.rms_time,
                ident::nonlinear::percent(b.rms_time_rel),
                ident::nonlinear::percent(a.rms_time_rel),
                b.rms_db,
                b.rms_deg,
                a.rms_db,
                a.rms_deg
            )
        }
        _ => format!(
            "No nonlinear effect is missing: the calibrated linear model leaves {} % of the \
             output RMS in the time domain ({:.3} dB / {:.2} deg on the FRF).",
            ident::nonlinear::percent(b.rms_time_rel),
            b.rms_db,
            b.rms_deg
        ),
    };
    let _ = writeln!(s, "{verdict}\n");
    if let Some(p) = plot {
        let _ = writeln!(s, "![Bode plot: recording and simulated models]({p})\n");
    }
    s.push_str("## Evidence\n\n");
    for e in &d.evidence {
        let _ = writeln!(s, "- {e}");
    }
    effects_and_calibration(
        &mut s,
        "Effects (time domain)",
        &d.effects,
        &d.rejected,
        &d.calibration,
    );
    let _ = writeln!(
        s,
        "\n## Model after diagnosis\n\n```toml\n{}```",
        d.model_after.to_toml()
    );
    if let Some(id) = &d.inverse_dynamics {
        s.push_str(&inverse_dynamics_section(id));
    }
    if let Some(fd) = &d.frequency_domain {
        s.push_str("\n## Frequency domain (H1 estimate, linear effects)\n\n");
        if d.closed_loop {
            s.push_str(
                "In a closed loop the H1 estimate from the controller output to the position \
                 is biased where the loop feeds noise back (low coherence); read this part with \
                 care.\n\n",
            );
        }
        let body = markdown(name, source, fd, None);
        // Drop its title; keep the verdict and tables.
        let body = body
            .split_once('\n')
            .map_or("", |(_, rest)| rest)
            .trim_start();
        s.push_str(&body.replace("\n## ", "\n### "));
    }
    s
}

/// The time-domain check of a recording where it found no nonlinear effect.
fn time_check_note(td: &TimeDiagnosis) -> String {
    let mut s = String::from("\n## Time-domain check (Coulomb friction, backlash, offset)\n\n");
    let _ = writeln!(
        s,
        "Simulated {}, the calibrated linear model leaves {} % of the output RMS; neither \
         Coulomb friction nor backlash nor a force offset earns its parameter.\n",
        if td.closed_loop {
            "inside the recorded position loop"
        } else {
            "from the recorded input"
        },
        ident::nonlinear::percent(td.fit.before.rms_time_rel)
    );
    for e in &td.evidence {
        let _ = writeln!(s, "- {e}");
    }
    if let Some(id) = &td.inverse_dynamics {
        s.push_str(&inverse_dynamics_section(id));
    }
    s
}

/// The IDIM-LS estimates as a Markdown section.
fn inverse_dynamics_section(id: &ident::idim::InverseDynamics) -> String {
    let mut s = String::from("\n## Inverse dynamics (IDIM-LS, second method)\n\n");
    let _ = writeln!(
        s,
        "Force residual of `F = M q'' + ...` with `q'`, `q''` from the position filtered at \
         {} Hz (zero phase, order {}) and decimated by {} ({} samples, condition number \
         {:.1}): {:.2} % of the force RMS for the model's own terms, {:.2} % with the selected \
         effects.\n",
        id.cutoff_hz,
        id.order,
        id.decimation,
        id.samples,
        id.condition,
        100.0 * id.rel_err_before,
        100.0 * id.rel_err
    );
    s.push_str("| parameter | value | std |\n|---|---:|---:|\n");
    for e in &id.estimates {
        let _ = writeln!(s, "| {} | {:.4e} | {:.2e} |", e.name, e.value, e.std);
    }
    effects_and_calibration(
        &mut s,
        "Effects (inverse dynamics)",
        &id.effects,
        &id.rejected,
        &[],
    );
    s
}

/// Reads the loop of `--reference`, `--controller` and `--disturbance`
/// from the recording.
fn read_loop(
    rec: &RecordingArgs,
    l: &LoopArgs,
    samples: Option<&frf::Samples>,
) -> Result<LoopData, String> {
    let path = rec.path()?;
    let Some(samples) = samples else {
        return Err(format!(
            "--reference needs a time-domain recording; {} is an FRF",
            path.display()
        ));
    };
    // Another signal of the same file, read as the input of the same
    // output.
    let signal = |flag: &str, var: &str| -> Result<Vec<f64>, String> {
        let args = RecordingArgs {
            u: Some(var.to_string()),
            ..rec.clone()
        };
        let r = args.read().map_err(|e| format!("--{flag} {var}: {e}"))?;
        let s = r
            .samples
            .ok_or_else(|| format!("--{flag} {var}: no samples"))?;
        if s.u.len() != samples.u.len() {
            return Err(format!(
                "--{flag} {var}: {} samples, the recording has {}",
                s.u.len(),
                samples.u.len()
            ));
        }
        Ok(s.u)
    };
    let reference = signal("reference", &l.reference)?;
    let disturbance = l
        .disturbance
        .as_deref()
        .map(|d| signal("disturbance", d))
        .transpose()?;
    let controller = parse_controller(&l.controller, path)?;
    Ok(LoopData {
        controller,
        reference,
        disturbance,
    })
}

/// `kp=K,kv=K[,filter=A:B:..][,saturation=S]`; a value that is not a number
/// names a scalar variable of the .mat recording `path`.
fn parse_controller(spec: &str, path: &Path) -> Result<Controller, String> {
    let bad = |m: String| format!("--controller {spec}: {m}");
    let mut mat: Option<frf::mat::MatFile> = None;
    let mut value = |key: &str, v: &str| -> Result<f64, String> {
        if let Ok(x) = v.trim().parse::<f64>() {
            return Ok(x);
        }
        if mat.is_none() {
            let is_mat = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("mat"));
            if !is_mat {
                return Err(bad(format!(
                    "{key}={v} is not a number (variable names need a .mat recording)"
                )));
            }
            let bytes =
                std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
            mat = Some(frf::mat::read_mat(&bytes).map_err(|e| format!("{}: {e}", path.display()))?);
        }
        let var = mat.as_ref().and_then(|m| m.get(v.trim()));
        match var.map(|x| x.scalar()) {
            Some(Some(x)) => Ok(x),
            Some(None) => Err(bad(format!("variable '{v}' is not a real scalar"))),
            None => Err(bad(format!(
                "{key}={v}: no such number or variable in {}",
                path.display()
            ))),
        }
    };
    let (mut kp, mut kv) = (None, None);
    let mut c = Controller::new(1.0, 1.0);
    for part in spec.split(',').filter(|p| !p.trim().is_empty()) {
        let (key, v) = part
            .split_once('=')
            .ok_or_else(|| bad(format!("'{part}' is not KEY=VALUE")))?;
        match key.trim() {
            "kp" => kp = Some(value("kp", v)?),
            "kv" => kv = Some(value("kv", v)?),
            "saturation" => c.saturation = Some(value("saturation", v)?),
            "filter" => {
                c.filter = v
                    .split(':')
                    .map(|t| {
                        t.trim()
                            .parse::<f64>()
                            .map_err(|_| bad(format!("filter tap '{t}' is not a number")))
                    })
                    .collect::<Result<_, _>>()?
            }
            other => {
                return Err(bad(format!(
                    "unknown key '{other}' (expected kp, kv, filter, saturation)"
                )))
            }
        }
    }
    match (kp, kv) {
        (Some(p), Some(v)) => {
            c.kp = p;
            c.kv = v;
            Ok(c)
        }
        _ => Err(bad("give both kp and kv".into())),
    }
}

/// The report to stdout, or with the plot and `model_after.toml` into
/// `--out DIR`.
fn finish(
    args: &DiagnoseArgs,
    plot: &Bode,
    model_after: &ModelFile,
    report: String,
) -> Result<Option<String>, String> {
    let Some(dir) = args.out else {
        return Ok(Some(report));
    };
    crate::identify::write_report_dir(
        dir,
        args.format,
        plot,
        &[("model_after.toml", model_after.to_toml())],
        &report,
    )?;
    Ok(None)
}

/// The amplitude dependence of the recording and the `--level` recordings,
/// with the levels (`None` without `--level`).
fn amplitude(
    args: &DiagnoseArgs,
    rec: &frf::Recording,
) -> Result<Option<(Vec<Level>, AmplitudeDependence)>, String> {
    if args.levels.is_empty() {
        return Ok(None);
    }
    let welch = args.recording.welch();
    let level = |path: &Path, rec: &frf::Recording| -> Result<Level, String> {
        let name = path.display().to_string();
        let s = rec.samples.as_ref().ok_or_else(|| {
            format!("{name}: the amplitude dependence (--level) needs time-domain recordings")
        })?;
        Level::from_samples(&name, &s.u, &s.y, s.fs, &welch).map_err(|e| e.to_string())
    };
    let main = args.recording.path()?;
    let mut levels = vec![level(main, rec)?];
    for path in args.levels {
        levels.push(level(path, &args.recording.read_file(path)?)?);
    }
    let options = AmplitudeOptions {
        band_hz: args.band,
        ..AmplitudeOptions::default()
    };
    let a = amplitude_dependence(&levels, &options)
        .map_err(|e| format!("{}: amplitude dependence: {e}", main.display()))?;
    Ok(Some((levels, a)))
}

/// `mms diagnose REC --level REC2 ...` without a model: the amplitude
/// comparison alone, with a Bode plot of the levels (the residual panel
/// relative to the lowest level).
fn amplitude_only(
    args: &DiagnoseArgs,
    levels: &[Level],
    a: &AmplitudeDependence,
) -> Result<Option<String>, String> {
    let name = args.recording.path()?.display().to_string();
    let (lo, hi) = a.band_hz;
    let mut plot = Bode::new("Excitation levels (H1 estimates)");
    // In the report's order: the reference (lowest input RMS) first.
    for (i, summary) in a.levels.iter().enumerate() {
        let Some(l) = levels.iter().find(|l| l.label == summary.label) else {
            continue;
        };
        let band = l.frf.band(lo, hi).unwrap_or_else(|| l.frf.clone());
        let style = if i == 0 {
            Style::points()
        } else {
            Style::line()
        };
        // The file name: whole paths do not fit the legend.
        let file = Path::new(&l.label)
            .file_name()
            .map_or(l.label.clone(), |f| f.to_string_lossy().into_owned());
        plot = plot.trace(
            format!("{file} ({:.3e} RMS in)", l.input_rms),
            band.freq_hz(),
            band.response(),
            style,
        );
    }
    for m in &a.modes {
        if m.shifts
            .iter()
            .any(|s| s.stiffness != StiffnessTrend::None || s.damping_trend != DampingTrend::None)
        {
            plot = plot.band(m.window_hz.0, m.window_hz.1, "amplitude-dependent mode");
        }
    }
    let plot = plot.residual();
    let report = match args.format {
        IdentifyFormat::Json => {
            let v = serde_json::json!({ "amplitude_dependence": a });
            let mut s = serde_json::to_string_pretty(&v).map_err(|e| format!("JSON: {e}"))?;
            s.push('\n');
            s
        }
        IdentifyFormat::Md | IdentifyFormat::Html => {
            let mut m = format!("# Amplitude dependence of `{name}`\n");
            if args.format == IdentifyFormat::Md && args.out.is_some() {
                m.push_str("\n![Bode plot: the levels](bode.svg)\n");
            }
            m.push_str(
                amplitude_markdown(a)
                    .trim_start()
                    .trim_start_matches("## Amplitude dependence\n"),
            );
            if args.format == IdentifyFormat::Md {
                m
            } else {
                crate::identify::html_page("mms diagnose", &m, &plot.to_svg())
            }
        }
    };
    match args.out {
        None => Ok(Some(report)),
        Some(dir) => {
            crate::identify::write_report_dir(dir, args.format, &plot, &[], &report)?;
            Ok(None)
        }
    }
}

/// The Markdown section of the amplitude dependence: the verdict, the
/// levels, the bands beyond the noise and the modes.
fn amplitude_markdown(a: &AmplitudeDependence) -> String {
    let mut s = String::from("\n## Amplitude dependence\n\n");
    let _ = writeln!(s, "{}\n", a.verdict);
    let _ = writeln!(
        s,
        "Lines {:.4} to {:.4} Hz. The noise is each level's coherence over its averages; the \
         cost is the mean of |ln(H / H_ref)|^2 / (2 sigma^2), 1 for noise alone; the \
         distortion is the power at the unexcited lines above a periodic excitation (to 3 \
         times its top) relative to the excited lines.\n",
        a.band_hz.0, a.band_hz.1
    );
    s.push_str(
        "| level | input RMS | ratio | averages | noise (dB) | change (dB RMS) | change (deg RMS) | cost | distortion out (in), dB |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for l in &a.levels {
        let _ = writeln!(
            s,
            "| `{}` | {:.4e} | {:.2} | {} | {:.4} | {:.3} | {:.2} | {:.1} | {} |",
            l.label,
            l.input_rms,
            l.ratio,
            l.averages,
            l.noise_db,
            l.change_db,
            l.change_deg,
            l.cost,
            l.distortion.map_or("-".to_string(), |d| format!(
                "{:.1} ({:.1})",
                d.output_db, d.input_db
            ))
        );
    }
    for l in a.levels.iter().skip(1) {
        let _ = write!(s, "\nBands where `{}` differs beyond the noise: ", l.label);
        if l.bands.is_empty() {
            s.push_str("none.\n");
        } else {
            let b: Vec<String> = l
                .bands
                .iter()
                .map(|b| {
                    format!(
                        "{:.3}-{:.3} Hz ({:.3} dB / {:.2} deg)",
                        b.f_lo_hz, b.f_hi_hz, b.rms_db, b.rms_deg
                    )
                })
                .collect();
            let _ = writeln!(s, "{}.", b.join(", "));
        }
    }
    s.push_str(
        "\n### Modes\n\n| mode (Hz) | level | f (Hz) | shift (Hz) | shift (%) | z | damping | change | z | peak (dB) | reading |\n\
         |---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for m in &a.modes {
        let r = &m.estimates[0];
        let _ = writeln!(
            s,
            "| {:.3} | `{}` | {:.4} ± {:.4} | | | | {:.4} ± {:.4} | | | {:.2} | reference |",
            m.f_ref_hz,
            a.levels[0].label,
            r.f_hz,
            r.f_sigma_hz,
            r.damping,
            r.damping_sigma,
            r.peak_db
        );
        for (sh, e) in m.shifts.iter().zip(&m.estimates[1..]) {
            let _ = writeln!(
                s,
                "| | `{}` | {:.4} ± {:.4} | {:+.4} | {:+.2} | {:.1} | {:.4} ± {:.4} | {:+.4} | {:.1} | {:.2} ({:+.2}) | {} |",
                sh.level,
                e.f_hz,
                e.f_sigma_hz,
                sh.shift_hz,
                100.0 * sh.shift_rel,
                sh.shift_z,
                e.damping,
                e.damping_sigma,
                sh.damping_change,
                sh.damping_z,
                e.peak_db,
                sh.peak_db_change,
                sh.reading
            );
        }
    }
    if !a.unfitted_hz.is_empty() {
        let f: Vec<String> = a.unfitted_hz.iter().map(|f| format!("{f:.3}")).collect();
        let _ = writeln!(
            s,
            "\nPeaks without a resonance fit at every level (Hz): {}.",
            f.join(", ")
        );
    }
    s
}
