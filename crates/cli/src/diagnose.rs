//! `mms diagnose`: parses the arguments, calls
//! [`ident::diagnosis::diagnose_recording`] (or the amplitude comparison of
//! the levels) and formats its result.

use crate::identify::IdentifyFormat;
use crate::recording::RecordingArgs;
use crate::report::{Links, Outcome};
use ident::amplitude::{
    amplitude_dependence, AmplitudeDependence, AmplitudeOptions, DampingTrend, Level,
    StiffnessTrend,
};
use ident::diagnose::{model_from_simulation, Diagnosis, EffectVerdict, Selection, Unresolved};
use ident::diagnosis::{
    compare_operating_diagnoses, diagnose_recording, validate, DiagnosisOptions, Domain, HoldsFor,
    OperatingPointDiagnosis, Reason, RecordingDiagnosis, Validation,
};
use ident::evidence::{CalibrationNote, Evidence, RecordEvidence};
use ident::nonlinear::{LoopRecord, TimeDiagnosis};
use mms::model_file::ModelFile;
use mms::simulate::Controller;
use plot::{Bode, Style};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// `--select`: how an effect earns its parameters.
#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq, Debug)]
pub enum SelectArg {
    /// Bayesian information criterion on all lines.
    Bic,
    /// Validation on held-out lines (every 4th), as the time domain
    /// validates on held-out blocks.
    Holdout,
}

/// How a recording is diagnosed: the flags `mms diagnose` and `mms report`
/// share.
#[derive(clap::Args)]
pub struct DiagnosisFlags {
    /// How an effect must earn its parameters: bic (information
    /// criterion on all lines) or holdout (every 4th line held out of
    /// the fits, the effect must lower their cost).
    #[arg(long, value_enum, default_value_t = SelectArg::Holdout)]
    pub select: SelectArg,
    /// How far calibration may move each parameter from its nominal
    /// value (fraction).
    #[arg(long, value_name = "FRACTION", default_value_t = ident::diagnosis::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    /// Closed-loop recording: the position reference (VAR[:COL], as for
    /// --u). The model is then simulated inside the loop of
    /// --controller, driven by this reference, instead of from the
    /// recorded input.
    #[arg(long, value_name = "VAR[:COL]", requires = "controller")]
    pub reference: Option<String>,
    /// The position controller of a closed-loop recording, u = kv (kp
    /// (r - q) - v) with v the backward difference of the FIR-filtered
    /// position: kp=K,kv=K[,filter=A:B:..][,saturation=S]. Each value
    /// is a number or, in a .mat recording, the name of a scalar
    /// variable (kp=kp,kv=kv). Default filter 0.5:0.5 (v = (q[k] -
    /// q[k-2]) fs / 2).
    #[arg(long, value_name = "SPEC", requires = "reference")]
    pub controller: Option<String>,
    /// A known signal added to the controller output of a closed-loop
    /// recording (VAR[:COL]), e.g. injected pulses.
    #[arg(long, value_name = "VAR[:COL]", requires = "reference")]
    pub disturbance: Option<String>,
}

impl DiagnosisFlags {
    /// The position loop the flags describe, if any.
    pub fn closed_loop(&self) -> Option<LoopArgs> {
        match (&self.reference, &self.controller) {
            (Some(reference), Some(controller)) => Some(LoopArgs {
                reference: reference.clone(),
                controller: controller.clone(),
                disturbance: self.disturbance.clone(),
            }),
            _ => None,
        }
    }
}

/// Where the model comes from.
pub enum ModelSource {
    /// A model file.
    File(PathBuf),
    /// A simulated FRF whose chain model is identified.
    Simulation(PathBuf),
    /// The best fit of an identification of the same recording, with the
    /// sensors of a recording with several outputs.
    Fitted(Box<ModelFile>, Vec<mms::Port>),
}

/// `--reference`, `--controller`, `--disturbance`: the position loop a
/// recording was taken in.
#[derive(Clone)]
pub struct LoopArgs {
    pub reference: String,
    pub controller: String,
    pub disturbance: Option<String>,
}

/// The loop read from the recording.
pub struct LoopData {
    controller: Controller,
    reference: Vec<f64>,
    disturbance: Option<Vec<f64>>,
}

impl LoopData {
    pub fn record(&self) -> LoopRecord<'_> {
        LoopRecord {
            controller: &self.controller,
            reference: &self.reference,
            disturbance: self.disturbance.as_deref(),
            feedback: None,
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
    /// Another recording of the same rig to check the diagnosis on.
    pub validate: Option<&'a Path>,
    /// A recording of the same rig at another operating point, diagnosed
    /// with the same model and compared.
    pub operating_points: &'a [PathBuf],
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
    outcome(args, Links::new(args.format, args.out, ""))?.deliver(args.format, args.out)
}

/// The diagnosis of the recording (or, without a model, the comparison of
/// its excitation levels), in every format.
pub fn outcome(args: &DiagnoseArgs, links: Links) -> Result<Outcome, String> {
    // Several outputs, or one with its sensor's place: the model read at
    // every sensor.
    if args.recording.y.len() > 1 || args.recording.y.iter().any(|y| y.contains('@')) {
        return crate::sensors::diagnose(args, links);
    }
    if args.validate.is_some() && !args.operating_points.is_empty() {
        return Err(format!(
            "{}: give --validate or --operating-point, not both (both diagnose the other \
             recording with this model)",
            args.recording.path()?.display()
        ));
    }
    let rec = args.recording.read()?;
    // Each further level, read once: for the amplitude comparison and, with
    // a model, as another operating point.
    let level_recordings: Vec<frf::Recording> = args
        .levels
        .iter()
        .map(|p| args.recording.read_file(p))
        .collect::<Result<_, _>>()?;
    let levels = amplitude(args, &rec, &level_recordings)?;
    let Some(model_source) = args.model else {
        return match &levels {
            Some((levels, a)) => amplitude_only(args, levels, a, links),
            None => Err("give the model: --model MODEL.toml or --simulation FILE".into()),
        };
    };
    let amplitude = levels.map(|(_, a)| a);
    let (model, _, source) = load_model(args, model_source)?;
    model_on_lines(&model, model_source, &rec.frf)?;
    let options = options(args, &rec.source)?;
    let name = args.recording.path()?.display().to_string();
    let looped = match &args.closed_loop {
        Some(l) => Some(read_loop(args.recording, l, rec.samples.as_ref())?),
        None => None,
    };
    // A recording of the rig (inside its loop) diagnosed with the model.
    let diagnosed = |r: &frf::Recording, looped: Option<&LoopData>, name: &str| {
        let record = looped.map(|l| l.record());
        diagnose_recording(
            &r.frf,
            r.samples.as_ref(),
            &model,
            record.as_ref(),
            &options,
        )
        .map_err(|e| format!("{name}: {e}"))
    };
    let d = diagnosed(&rec, looped.as_ref(), &name)?;
    // Another operating point of the rig, and each further excitation
    // level as one: diagnosed with the same model and compared with this
    // recording (the levels' modes are also compared one by one, in the
    // amplitude section).
    let other_point = |path: &Path, other: &frf::Recording| -> Result<OtherPoint, String> {
        let looped = other_loop(args, path, other)?;
        let od = diagnosed(other, looped.as_ref(), &path.display().to_string())?;
        let c = compare_operating_diagnoses(&d, &rec.frf, &od, &other.frf);
        Ok((path.display().to_string(), c, od))
    };
    let operating: Vec<OtherPoint> = args
        .operating_points
        .iter()
        .map(|p| other_point(p, &args.recording.read_file(p)?))
        .collect::<Result<_, _>>()?;
    let level_points: Vec<OtherPoint> = args
        .levels
        .iter()
        .zip(&level_recordings)
        .map(|(p, other)| other_point(p, other))
        .collect::<Result<_, _>>()?;
    let validation = match args.validate {
        None => None,
        Some(path) => {
            let (other, looped) = read_other(args, path)?;
            let record = looped.as_ref().map(|l| l.record());
            let v = validate(
                &d,
                &other.frf,
                other.samples.as_ref(),
                &model,
                record.as_ref(),
                &options,
            )
            .map_err(|e| format!("{}: {e}", path.display()))?;
            Some((path.display().to_string(), v))
        }
    };
    let plot = bode(&d);
    let err = |e: serde_json::Error| format!("JSON: {e}");
    let mut report = json(&d, amplitude.as_ref(), validation.as_ref().map(|v| &v.1))?;
    let point = |(other, c, od): &OtherPoint| -> Result<serde_json::Value, String> {
        Ok(serde_json::json!({
            "recording": other,
            "comparison": serde_json::to_value(c).map_err(err)?,
            "diagnosis": json(od, None, None)?,
        }))
    };
    if !operating.is_empty() {
        report["operating_points"] = operating
            .iter()
            .map(point)
            .collect::<Result<Vec<_>, _>>()?
            .into();
    }
    if !level_points.is_empty() {
        report["levels"] = level_points
            .iter()
            .map(point)
            .collect::<Result<Vec<_>, _>>()?
            .into();
    }
    if let Some((estimate, _)) = crate::recording::periodic_estimate(&rec.source) {
        report["estimate"] = estimate;
    }
    let mut m = crate::recording::with_periodic_estimate(
        markdown(&name, &source, &d, links.to("bode").as_deref()),
        &rec.source,
    );
    if rec.excitation.is_none() && !rec.possible_excitations.is_empty() {
        m.push_str(&crate::identify::possible_excitation_note(
            &rec.possible_excitations,
        ));
    }
    if let Some((other, v)) = &validation {
        m.push_str(&validation_markdown(other, v));
    }
    for (other, c, _) in &operating {
        m.push_str(&operating_markdown(
            &name,
            other,
            c,
            "Operating points",
            true,
        ));
    }
    for (other, c, _) in &level_points {
        m.push_str(&operating_markdown(
            &name,
            other,
            c,
            "Excitation levels",
            false,
        ));
    }
    if let Some(a) = &amplitude {
        m.push_str(&amplitude_markdown(a));
    }
    let mut outcome = Outcome::new("mms diagnose", &m, report, vec![(links.file("bode"), plot)]);
    outcome.files = vec![("model_after.toml".into(), d.model_after.to_toml())];
    Ok(outcome)
}

/// A model file whose FRF cannot be evaluated on the recording's lines
/// (a singular chain, values so large or small that they overflow) is the
/// model file's fault: the error names it, not the recording.
pub fn model_on_lines(
    model: &ModelFile,
    source: &ModelSource,
    frf: &frf::Frf,
) -> Result<(), String> {
    let ModelSource::File(path) = source else {
        return Ok(());
    };
    let g = mms::response::ChainResponse::with_effects(
        &model.model,
        model.output,
        &model.effects.linear(),
    );
    let bad = |what: String| {
        Err(format!(
            "{}: the model cannot be evaluated at the recording's lines: {what}",
            path.display()
        ))
    };
    match g.eval_many(model.parameters.values(), frf.freq_hz()) {
        Err(e) => bad(e.to_string()),
        Ok(h) => match h.iter().zip(frf.freq_hz()).find(|(h, _)| !h.is_finite()) {
            Some((_, f)) => bad(format!("its FRF is not finite at {f} Hz")),
            None => Ok(()),
        },
    }
}

/// The model of `--model` or `--simulation`, the sensors its file lists
/// for a recording with several outputs, and a sentence naming it.
pub fn load_model(
    args: &DiagnoseArgs,
    model_source: &ModelSource,
) -> Result<(ModelFile, Vec<mms::Port>, String), String> {
    let (model, sensors) = match model_source {
        ModelSource::File(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
            ModelFile::parse_with_sensors(&text).map_err(|e| match e.line {
                Some(l) => format!("{}:{l}: {}", path.display(), e.message),
                None => format!("{}: {}", path.display(), e.message),
            })?
        }
        ModelSource::Simulation(path) => {
            let sim = frf::read_recording(path, &frf::RecordingOptions::default())
                .map_err(|e| e.to_string())?;
            let model = model_from_simulation(&sim.frf, args.recording.output.into())
                .map_err(|e| format!("{}: {e}", path.display()))?;
            (model, Vec::new())
        }
        ModelSource::Fitted(model, sensors) => ((**model).clone(), sensors.clone()),
    };
    let source = match model_source {
        ModelSource::File(path) => format!("Model: `{}` ({}).", path.display(), model.model.id()),
        ModelSource::Simulation(path) => format!(
            "Model: {} identified from the simulation `{}` (reproduced within {} dB).",
            model.model.id(),
            path.display(),
            ident::diagnose::SIMULATION_TOLERANCE_DB
        ),
        // Named as the identification names it: by the paper's ID where
        // there is one.
        ModelSource::Fitted(..) => format!(
            "Model: {}, the best fit of the identification above.",
            match model.model.paper_id() {
                Some(p) => format!("{p} ({})", model.model.id()),
                None => model.model.id(),
            }
        ),
    };
    Ok((model, sensors, source))
}

/// The diagnosis options of the flags, for a recording from `source`
/// (whose samples are cut and estimated again as its FRF was).
pub fn options(args: &DiagnoseArgs, source: &frf::Source) -> Result<DiagnosisOptions, String> {
    if !(args.tolerance.is_finite() && args.tolerance > 0.0 && args.tolerance < 10.0) {
        return Err(format!(
            "--tolerance {}: expected a fraction such as 0.2 (0 < t < 10)",
            args.tolerance
        ));
    }
    Ok(DiagnosisOptions {
        tolerance: args.tolerance,
        band_hz: args.band,
        selection: match args.select {
            SelectArg::Bic => Selection::Bic,
            SelectArg::Holdout => Selection::Holdout,
        },
        welch: source.welch(&args.recording.welch()),
        ..DiagnosisOptions::default()
    })
}

/// The JSON report: the verdict, the deciding domain's effects, fit and
/// model at the top, each domain's diagnosis inside (a value, so that a
/// report can hold one diagnosis inside another).
pub fn json(
    d: &RecordingDiagnosis,
    amplitude: Option<&AmplitudeDependence>,
    validation: Option<&Validation>,
) -> Result<serde_json::Value, String> {
    let err = |e: serde_json::Error| format!("JSON: {e}");
    let mut v = serde_json::to_value(d).map_err(err)?;
    // Kinds split viscous from Coulomb friction from version 2 on; the
    // evidence is figures, not sentences, from version 3 on; the other
    // operating points are a list (`operating_points`) from version 4 on.
    v["version"] = serde_json::json!(JSON_VERSION);
    v["effects"] = serde_json::to_value(&d.verdict.effects).map_err(err)?;
    v["fit"] = match (d.verdict.decided_by, &d.frequency_domain, &d.time_domain) {
        (Some(Domain::Time), _, Some(t)) => serde_json::to_value(t.fit).map_err(err)?,
        (_, Some(f), _) => serde_json::to_value(f.fit).map_err(err)?,
        _ => serde_json::Value::Null,
    };
    v["mismatch"] = match &d.frequency_domain {
        Some(f) => serde_json::to_value(&f.mismatch).map_err(err)?,
        None => serde_json::json!([]),
    };
    if let Some(a) = amplitude {
        v["amplitude_dependence"] = serde_json::to_value(a).map_err(err)?;
    }
    if let Some(val) = validation {
        v["validation"] = serde_json::to_value(val).map_err(err)?;
    }
    Ok(v)
}

/// The version of the JSON report of `mms diagnose`.
pub const JSON_VERSION: u32 = 4;

/// The recording, the nominal model and the model after the diagnosis,
/// with the mismatch bands shaded, and the residual panel.
fn bode(d: &RecordingDiagnosis) -> Bode {
    let c = &d.curves;
    let title = if c.simulated {
        "Recording and simulated models (H1 from the recorded input)"
    } else {
        "Recording, model, and model with the missing physics"
    };
    let mut b = Bode::new(title).trace("recording", &c.freq_hz, &c.recording, Style::points());
    if let Some(s) = &c.std_dev {
        b = b.uncertainty(s);
    }
    b = b
        .trace("model (nominal)", &c.freq_hz, &c.nominal, Style::dashed())
        .trace("model after diagnosis", &c.freq_hz, &c.after, Style::line());
    if let Some(g) = &c.coherence {
        b = b.coherence(g);
    }
    if let Some(f) = &d.frequency_domain {
        for band in &f.mismatch {
            b = b.band(band.f_lo_hz, band.f_hi_hz, "mismatch");
        }
    }
    // The compared lines with some context fill the figure.
    if let Some((lo, hi)) = d.band_hz {
        b = b.view(lo.max(c.freq_hz.first().copied().unwrap_or(lo)), hi);
    }
    b.residual()
}

/// `**kind** (parameter = value, ...)` for each effect, best first.
fn effect_names(effects: &[EffectVerdict]) -> Vec<String> {
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

/// A held-out gain in noise units, in words.
fn evidence(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{x:.1}"))
}

/// The verdict in words: what is missing, which domain decided and why.
pub fn verdict_text(d: &RecordingDiagnosis) -> String {
    let v = &d.verdict;
    let mut s = match (v.decided_by, &d.frequency_domain, &d.time_domain) {
        (None, None, Some(t)) if matches!(v.reason, Reason::NothingMissing) => format!(
            "Nothing is missing: no effect lowers the prediction error on held-out samples; the \
             calibrated model leaves {} % of the output RMS.",
            percent(t.fit.before.rms_time_rel)
        ),
        (None, None, _) => "Nothing can be compared: no line of the recording carries \
                            information (no excitation energy or no coherence), so no \
                            effect is named."
            .to_string(),
        (None, Some(f), _) => format!(
            "Nothing is missing: no effect lowers the prediction error on held-out data; the \
             calibrated model explains the recording to {:.3} dB / {:.2} deg RMS.",
            f.fit.before.rms_db, f.fit.before.rms_deg
        ),
        (Some(domain), fd, td) => {
            let causes = effect_names(&v.effects);
            let figures = match (domain, fd, td) {
                (Domain::Time, _, Some(t)) => format!(
                    "the time-domain error falls from {} % to {} % of the output RMS, the FRF \
                     error from {:.3} dB / {:.2} deg to {:.3} dB / {:.2} deg",
                    percent(t.fit.before.rms_time_rel),
                    percent(t.fit.after.rms_time_rel),
                    t.fit.before.rms_db,
                    t.fit.before.rms_deg,
                    t.fit.after.rms_db,
                    t.fit.after.rms_deg
                ),
                (_, Some(f), _) => format!(
                    "the FRF error falls from {:.3} dB / {:.2} deg to {:.3} dB / {:.2} deg RMS",
                    f.fit.before.rms_db,
                    f.fit.before.rms_deg,
                    f.fit.after.rms_db,
                    f.fit.after.rms_deg
                ),
                _ => String::new(),
            };
            format!(
                "Most likely missing: {}; with {} {figures}. Decided in the {} domain.",
                causes.join(" together with "),
                if causes.len() > 1 { "them" } else { "it" },
                match domain {
                    Domain::Frequency => "frequency",
                    Domain::Time => "time",
                }
            )
        }
    };
    let why = match v.reason {
        Reason::NothingMissing | Reason::TimeDomainOnly
            if d.frequency_domain.is_none() && d.time_domain.is_some() =>
        {
            "The FRF has no informative band (too few lines above the noise, as behind a \
             motion profile): the time domain alone decides."
                .into()
        }
        Reason::NothingInformative | Reason::NothingMissing | Reason::TimeDomainOnly => {
            String::new()
        }
        Reason::FrequencyDomainOnly => {
            "The recording is an FRF: the frequency domain is the only one.".into()
        }
        Reason::TimeDomainNotInformative { unexplained } => format!(
            "The time-domain comparison is not informative: simulated from the recorded input, \
             the model leaves {} % of the output RMS even with the effects it earned (more than \
             {:.0} %), so it cannot decide.",
            percent(unexplained),
            100.0 * ident::nonlinear::TimeOptions::default().informative
        ),
        Reason::OnlyOneDomainNames => format!(
            "Only this domain names an effect that lowers the prediction error on held-out data \
             (gain in noise units: frequency domain {}, time domain {}).",
            evidence(v.frequency_evidence),
            evidence(v.time_evidence)
        ),
        Reason::FrequencyDomainNotInformative { log_error } => format!(
            "The frequency-domain comparison is not informative: with the effects it earned the \
             model still misses the FRF by {log_error:.2} nepers RMS (more than {}; in a closed \
             loop the H1 estimate is biased where the loop feeds noise back), so the time domain \
             decides.",
            ident::diagnosis::INFORMATIVE_LOG_ERROR
        ),
        Reason::StrongerHeldOutEvidence { frequency, time } => format!(
            "Both domains name effects; this one's model predicts the samples held out of every \
             fit better (drop of the prediction error in noise units: frequency domain \
             {frequency:.1}, time domain {time:.1})."
        ),
        Reason::FrequencyEffectsNotConfirmed { gain, price } => format!(
            "The frequency domain's effects are not named: simulated from the recorded input, \
             its model lowers the prediction error on the held-out samples by {gain:.1} noise \
             units, not more than {price:.1}, so what they fit in the FRF (a bias of the \
             estimate, leakage or a model error) is not in the record."
        ),
    };
    if !why.is_empty() {
        s.push(' ');
        s.push_str(&why);
    }
    s
}

pub fn markdown(name: &str, source: &str, d: &RecordingDiagnosis, plot: Option<&str>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Diagnosis of `{name}`\n");
    // A section of a report on several outputs names no model of its own.
    if !source.is_empty() {
        let _ = writeln!(s, "{source}\n");
    }
    if let Some(flipped) = flipped_cuts(d) {
        let _ = writeln!(
            s,
            "**Uncertain:** the headline changes on {flipped} of the record (see Stability).\n"
        );
    }
    let _ = writeln!(s, "{}\n", verdict_text(d));
    if let Some(e) = &d.verdict.held_out_errors {
        let _ = writeln!(
            s,
            "Cross-check on the held-out samples (RMS output error, each model's chain \
             calibrated in the time domain): calibrated linear model {:.4e}, the frequency \
             domain's model {}, the time domain's {:.4e}.\n",
            e.linear,
            e.frequency_model
                .map_or("- (cannot be simulated)".into(), |x| format!("{x:.4e}")),
            e.time_model
        );
    }
    if let Some(p) = plot {
        let _ = writeln!(s, "![Bode plot: recording, model, improved model]({p})\n");
    }
    if let Some(st) = &d.stability {
        s.push_str(
            "## Stability\n\nThe same diagnosis on other cuts of the record: a headline that \
             changes is uncertain.\n\n| cut | headline | decided by | same headline |\n\
             |---|---|---|---|\n",
        );
        for r in &st.runs {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} |",
                crate::identify::cut_name(r.cut),
                match &r.error {
                    Some(e) => format!("not diagnosed: {e}"),
                    None => r.headline.as_str().to_string(),
                },
                match r.decided_by {
                    Some(Domain::Frequency) => "frequency domain",
                    Some(Domain::Time) => "time domain",
                    None => "-",
                },
                if r.same_headline { "yes" } else { "**no**" }
            );
        }
        s.push('\n');
    }
    if let Some(f) = &d.frequency_domain {
        frequency_markdown(&mut s, d.band_hz, f);
    }
    if let Some(t) = &d.time_domain {
        time_markdown(&mut s, t);
    }
    let _ = writeln!(
        s,
        "\n## Model after diagnosis\n\n```toml\n{}```",
        d.model_after.to_toml()
    );
    s
}

/// The cuts of the record on which the headline changes, if any.
fn flipped_cuts(d: &RecordingDiagnosis) -> Option<String> {
    let st = d.stability.as_ref().filter(|st| !st.stable())?;
    Some(cut_names(st.runs.iter().filter(|r| !r.same_headline)))
}

/// The cuts of `runs`, as a list in words.
fn cut_names<'a>(runs: impl Iterator<Item = &'a ident::diagnosis::DiagnosisRerun>) -> String {
    let names: Vec<String> = runs.map(|r| crate::identify::cut_name(r.cut)).collect();
    spoken_list(&names)
}

/// `a`, `a and b`, `a, b and c`.
fn spoken_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// The validation on another recording: what carries over, how the model
/// fits there.
/// The operating-point section: each effect and which recording it holds
/// for, then the features of the two FRFs.
fn operating_markdown(
    name: &str,
    other: &str,
    c: &OperatingPointDiagnosis,
    heading: &str,
    features: bool,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n## {heading}: the diagnoses of `{name}` (first) and `{other}` (second)\n"
    );
    let _ = writeln!(
        s,
        "Both diagnosed with the same model; the models after them: {} and {}.\n",
        c.structures.0, c.structures.1
    );
    if c.effects.is_empty() {
        s.push_str(
            "Neither verdict names an effect: nothing is missing at either operating point.\n",
        );
    } else {
        s.push_str(
            "| effect | parameter | first | second | holds for |\n|---|---|---:|---:|---|\n",
        );
        for e in &c.effects {
            let value = |v: Option<f64>| v.map_or("-".to_string(), crate::identify::fmt_sig);
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} |",
                match e.other_kind {
                    Some(o) => format!("{} / {}", e.kind.as_str(), o.as_str()),
                    None => e.kind.as_str().to_string(),
                },
                e.parameter,
                value(e.values.0),
                value(e.values.1),
                match e.holds_for {
                    HoldsFor::Both => "both",
                    HoldsFor::First => "the first only",
                    HoldsFor::Second => "the second only",
                }
            );
        }
    }
    if let Some(r) = c.pre_sliding_as_extra_mode {
        let _ = writeln!(
            s,
            "\nThe extra mode at {} Hz that one diagnosis alone adds is the pre-sliding friction \
             of the comparison below, seen twice: a stiffness to ground, which the chain can \
             take only as one more mass.",
            crate::identify::fmt_sig(r)
        );
    }
    if c.effects.iter().any(|e| e.other_kind.is_some()) {
        s.push_str(
            "\nA dead time and a first-order lag are one phase lag here: `lag_s` is the dead \
             time, or the lag's 1 / (2 pi f_c), its delay well below the corner.\n",
        );
    }
    if let Some(p) = &c.pre_sliding_named {
        let which = crate::identify::recording_name(p.recording);
        let _ = writeln!(
            s,
            "\nThe pre-sliding friction the {which} diagnosis names (a spring to ground of {}) \
             is the finding of the comparison below, seen by two methods: the resonance at {} Hz \
             that only the {which} recording has{}.",
            crate::identify::fmt_sig(p.fitted_n_per_m),
            crate::identify::fmt_sig(p.freq_hz),
            match p.from_features_n_per_m {
                Some(k) => format!(
                    ", a stiffness of {} with the other recording's rigid-body inertia",
                    crate::identify::fmt_sig(k)
                ),
                None => String::new(),
            }
        );
    }
    match &c.features {
        // Levels: the amplitude section compares their modes one by one.
        _ if !features => s.push_str(
            "\nThe modes of the levels are compared one by one in the amplitude section below.\n",
        ),
        Some(f) => s.push_str(&crate::identify::operating_markdown(
            name,
            &[(other.to_string(), f.clone())],
        )),
        None => {
            s.push_str("\nThe features were not compared: a recording could not be classified.\n")
        }
    }
    s
}

fn validation_markdown(other: &str, v: &Validation) -> String {
    let mut s = format!("\n## Validation on `{other}`\n\n");
    let o = &v.other.verdict;
    let _ = writeln!(
        s,
        "Diagnosed with the same model, the other recording reads: {} ({}). Structure after \
         the diagnosis: {} here, {} there.\n",
        if o.headline == ident::diagnose::EffectKind::None {
            "nothing missing".to_string()
        } else {
            effect_names(&o.effects).join(" together with ")
        },
        match o.decided_by {
            Some(Domain::Frequency) => "frequency domain",
            Some(Domain::Time) => "time domain",
            None => "no domain names an effect",
        },
        v.structure,
        v.other_structure
    );
    match (&v.other.stability, flipped_cuts(&v.other)) {
        (_, Some(flipped)) => {
            let _ = writeln!(
                s,
                "There the headline is uncertain: it changes on {flipped} of that record.\n"
            );
        }
        (Some(st), None) => {
            let _ = writeln!(
                s,
                "There the headline holds on {} of that record.\n",
                cut_names(st.runs.iter())
            );
        }
        (None, None) => {}
    }
    s.push_str("| effect | parameter | here | there | change |\n|---|---|---:|---:|---:|\n");
    for e in &v.effects {
        let _ = writeln!(
            s,
            "| {} | {} | {:.4e} | {} | {} |",
            e.kind.as_str(),
            e.parameter,
            e.value,
            e.other_value
                .map_or("not kept".into(), |x| format!("{x:.4e}")),
            e.change
                .map_or("-".into(), |c| format!("{:+.1} %", 100.0 * c))
        );
    }
    if let Some((a, b)) = v.phase_lag_s {
        let _ = writeln!(
            s,
            "\nLow-frequency phase lag (dead time plus `1/(2 pi f_c)` of a lag): {:.4e} s here, \
             {:.4e} s there ({:+.1} %).",
            a,
            b,
            100.0 * (b / a - 1.0)
        );
    }
    let f = &v.fit_on_other;
    let _ = writeln!(
        s,
        "\nOn the other recording's band: the nominal model misses it by {:.3} dB / {:.2} deg \
         RMS, the model after this diagnosis (unchanged) by {:.3} dB / {:.2} deg, the model \
         after its own diagnosis by {:.3} dB / {:.2} deg.",
        f.nominal.rms_db,
        f.nominal.rms_deg,
        f.first_model.rms_db,
        f.first_model.rms_deg,
        f.own_model.rms_db,
        f.own_model.rms_deg
    );
    s
}

/// The frequency-domain section: band, mismatch, effects, held-out lines.
fn frequency_markdown(s: &mut String, band: Option<(f64, f64)>, f: &Diagnosis) {
    s.push_str("## Frequency domain (FRF, linear effects)\n\n");
    if let Some((lo, hi)) = band {
        let _ = write!(
            s,
            "Lines {lo:.4} to {hi:.4} Hz, each weighted by its uncertainty (median {:.4} \
             nepers). ",
            f.noise
        );
    }
    if let Some(h) = &f.held_out {
        let _ = write!(
            s,
            "Held-out lines ({}, every {}th): cost {:.1} -> {:.1} noise units (noise alone: \
             about {}).",
            h.lines,
            ident::diagnose::HOLDOUT_EVERY,
            h.before,
            h.after,
            2 * h.lines
        );
    }
    s.push_str(
        "\n\n### Mismatch bands\n\n| from (Hz) | to (Hz) | RMS dB | RMS deg |\n|---:|---:|---:|---:|\n",
    );
    for b in &f.mismatch {
        let _ = writeln!(
            s,
            "| {:.4} | {:.4} | {:.3} | {:.2} |",
            b.f_lo_hz, b.f_hi_hz, b.rms_db, b.rms_deg
        );
    }
    effects_and_calibration(s, "Effects", &f.effects, &f.rejected, &f.calibration);
}

/// The time-domain section: how it was simulated, whether it is
/// informative, the evidence and the effects.
fn time_markdown(s: &mut String, d: &TimeDiagnosis) {
    s.push_str("\n## Time domain (samples, nonlinear effects)\n\n");
    let _ = writeln!(
        s,
        "{} samples at {} Hz, simulated {}; the calibrated linear model leaves {} % of the \
         output RMS, {} % with the effects it earned{}.",
        d.samples,
        d.fs,
        if d.closed_loop {
            "inside the recorded position loop (controller and reference)"
        } else {
            "from the recorded input, with the initial rigid-body state fitted and the motion \
             slower than the band's lowest line left out"
        },
        percent(d.fit.before.rms_time_rel),
        percent(d.fit.after.rms_time_rel),
        if d.informative {
            String::new()
        } else {
            " (not informative: it cannot decide the verdict)".into()
        }
    );
    if let Some(h) = &d.held_out {
        let _ = writeln!(
            s,
            "Held-out samples ({}, every 4th of {} blocks): error {:.4e} -> {:.4e} RMS.",
            h.samples,
            ident::nonlinear::HOLDOUT_BLOCKS,
            (h.before / h.samples as f64).sqrt(),
            (h.after / h.samples as f64).sqrt()
        );
    }
    if let Some(r) = &d.whole_record {
        let h = &r.held_out;
        let _ = writeln!(
            s,
            "Searched on the first {} of {} samples; both models refitted on the whole record: \
             held-out error {:.4e} -> {:.4e} RMS, {:.1} noise units against a price of {:.1} \
             ({}).",
            r.search_samples,
            r.samples,
            (h.before / h.samples.max(1) as f64).sqrt(),
            (h.after / h.samples.max(1) as f64).sqrt(),
            r.gain,
            r.price,
            if r.confirmed {
                "the effects hold on the whole record"
            } else {
                "the search's effects do not hold on the whole record: rejected"
            }
        );
    }
    if let Some(at) = d.whole_record_diverged_at {
        let _ = writeln!(
            s,
            "Searched on the first samples only: a model diverged inside the loop at sample {at} \
             of the whole record, so the verdict rests on the searched stretch."
        );
    }
    s.push_str("\n### Evidence\n\n");
    for e in record_evidence(&d.evidence) {
        let _ = writeln!(s, "- {e}");
    }
    effects_and_calibration(
        s,
        "Effects (time domain)",
        &d.effects,
        &d.rejected,
        &d.calibration,
    );
    if let Some(id) = &d.inverse_dynamics {
        s.push_str(&inverse_dynamics_section(id));
    }
}

/// The effects table (kept, then rejected) and the calibration notes.
fn effects_and_calibration(
    s: &mut String,
    title: &str,
    effects: &[EffectVerdict],
    rejected: &[EffectVerdict],
    calibration: &[CalibrationNote],
) {
    let _ = write!(
        s,
        "\n### {title}\n\n| kind | parameters | step | score | evidence |\n|---|---|---:|---:|---|\n"
    );
    for e in effects.iter().chain(rejected) {
        let params: Vec<String> = e
            .parameters
            .iter()
            .map(|(k, v)| match e.standard_errors.get(k) {
                Some(se) => format!("{k} = {v:.4e} ± {se:.2e}"),
                None => format!("{k} = {v:.4e}"),
            })
            .collect();
        let unresolved = match &e.unresolved {
            None => String::new(),
            Some(Unresolved::LikeKept(k)) => format!(
                "; not kept: within the band it cannot be told from {}",
                k.as_str()
            ),
            Some(Unresolved::OutsideBand(hz)) => {
                format!("; not kept: what it acts through ({hz:.1} Hz) lies outside the band")
            }
            Some(Unresolved::AtBound { parameter, value }) => {
                format!("; not kept: {parameter} = {value:.4e} lies at the bound of its range")
            }
            Some(Unresolved::WithinUncertainty { parameter, sigmas }) => format!(
                "; not kept: {parameter} lies {sigmas:.1} standard errors from the value at \
                 which the effect is absent (at least {} needed)",
                ident::diagnose::SIGNIFICANCE_SIGMAS
            ),
            Some(Unresolved::PoleOnZero {
                separation,
                standard_error,
            }) => format!(
                "; not kept: the resonance and antiresonance it adds lie {:.2} % apart, within \
                 {} standard errors ({:.2} %) of each other",
                100.0 * separation.exp_m1(),
                ident::diagnose::SIGNIFICANCE_SIGMAS,
                100.0 * standard_error
            ),
            Some(Unresolved::MergedChainFits { gain }) => format!(
                "; not kept: the chain without the extra mass, refitted with it merged into \
                 its neighbours, predicts the held-out lines as well (the mass gains {gain:.1} \
                 over it): it moved the calibration, it adds no mode"
            ),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {}{unresolved} |",
            e.kind.as_str(),
            params.join(", "),
            e.step,
            e.score,
            evidence_text(&e.evidence)
        );
    }
    if !calibration.is_empty() {
        s.push_str("\n#### Calibration\n\n");
        for c in calibration {
            let _ = writeln!(s, "- {}", calibration_text(c));
        }
    }
}

/// The figures a hypothesis was scored on, in words.
fn evidence_text(e: &Evidence) -> String {
    match e {
        Evidence::Nothing { best: None } => "no hypothesis could be fitted".into(),
        Evidence::Nothing { best: Some(v) } => format!(
            "no effect earns its parameter; best was {} ({})",
            v.kind.as_str(),
            evidence_text(&v.evidence)
        ),
        Evidence::Frequency(f) => {
            let cost = if f.held_out {
                format!(
                    "held-out cost {:.1} -> {:.1} noise units (margin {:.1})",
                    f.cost_before, f.cost_after, f.price
                )
            } else {
                format!(
                    "cost {:.1} -> {:.1} noise units (price {:.1})",
                    f.cost_before, f.cost_after, f.price
                )
            };
            let mut t = format!(
                "{cost}; {:.3} dB / {:.2} deg -> {:.3} dB / {:.2} deg",
                f.before.rms_db, f.before.rms_deg, f.after.rms_db, f.after.rms_deg
            );
            if let Some(x) = &f.extended {
                t = format!("one more mass ({} masses, {}): {t}", x.masses, x.id);
            }
            if !f.added_to.is_empty() {
                let with: Vec<&str> = f.added_to.iter().map(|k| k.as_str()).collect();
                t = format!("added to {}: {t}", with.join(" + "));
            }
            t
        }
        Evidence::Time(e) => {
            let mut t = format!(
                "time-domain error {:.4e} -> {:.4e} ({} % -> {} % of the output RMS); \
                 BIC gain {:.1} (price {:.1}); FRF {:.3} dB / {:.2} deg -> {:.3} dB / {:.2} deg",
                e.before.rms_time,
                e.after.rms_time,
                percent(e.before.rms_time_rel),
                percent(e.after.rms_time_rel),
                e.bic_gain,
                e.price,
                e.before.rms_db,
                e.before.rms_deg,
                e.after.rms_db,
                e.after.rms_deg
            );
            if let Some(sh) = &e.too_small_share {
                let _ = write!(
                    t,
                    "; removes only {:.1} % of the {} misfit (at least {:.0} % needed {}",
                    100.0 * sh.share,
                    if sh.first { "calibrated" } else { "remaining" },
                    100.0 * sh.needed,
                    if sh.first {
                        format!(
                            "when the model leaves more than {:.0} % of the output RMS): the \
                             model misses more than this effect explains",
                            100.0 * sh.adequate
                        )
                    } else {
                        "for a further effect)".to_string()
                    }
                );
            }
            if let Some(h) = &e.held_out {
                let _ = write!(
                    t,
                    "; held-out error {:.4e} -> {:.4e} RMS ({} samples, gain {:.1}, price {:.1})",
                    h.before, h.after, h.samples, h.gain, h.price
                );
            }
            if !e.validated {
                t.push_str(
                    "; does not lower the error on the held-out samples by its price: not named",
                );
            }
            if let Some(f) = &e.too_small_force {
                let _ = write!(
                    t,
                    "; its force is only {} % of the RMS actuator force (at least {:.0} % \
                     needed): too small to tell from a drift or the other effects' imperfect fit",
                    percent(f.share),
                    100.0 * f.needed
                );
            }
            t
        }
        Evidence::InverseDynamics(r) => format!(
            "force residual {:.2} % -> {:.2} % of the force RMS (removes {:.1} % of the residual \
             energy); BIC gain {:.1} (price {:.1})",
            100.0 * r.residual_before,
            100.0 * r.residual_after,
            100.0 * r.share,
            r.bic_gain,
            r.price
        ),
    }
}

/// A calibration note in words.
fn calibration_text(c: &CalibrationNote) -> String {
    match c {
        CalibrationNote::Pinned {
            parameter,
            upper,
            value,
            nominal,
        } => format!(
            "{parameter} pinned at its {} bound ({value:.4e}, nominal {nominal:.4e}, {:+.1} %)",
            if *upper { "upper" } else { "lower" },
            100.0 * (value / nominal - 1.0)
        ),
        CalibrationNote::CommonFactor { factor } => format!(
            "all parameters moved by a common factor {factor:.3} (a gain error looks like this)"
        ),
    }
}

/// What a time record shows before any model, one line each.
fn record_evidence(r: &RecordEvidence) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(c) = &r.controller {
        let mut law = format!(
            "controller law (kp = {}, kv = {}, position filter {:?}{}) on the recorded output \
             and reference: reproduces the recorded input within {:.3} % RMS (largest \
             difference {:.4e}{})",
            c.kp,
            c.kv,
            c.filter,
            c.saturation
                .map_or(String::new(), |s| format!(", saturation {s}")),
            100.0 * c.rms_rel,
            c.max_abs,
            if c.saturated > 0 {
                format!(", saturated in {} samples", c.saturated)
            } else {
                String::new()
            }
        );
        if c.rms_rel > c.warning_above {
            let _ = write!(
                law,
                "; more than {:.0} %: the simulated loop differs from the recorded one, and the \
                 estimates with it (check the gains, the velocity filter, a disturbance)",
                100.0 * c.warning_above
            );
        }
        out.push(law);
    }
    if let Some(c) = &r.coherence {
        out.push(format!(
            "coherence: mean {:.3} over {} lines with coherence >= 0.5; {} of {} lines below 0.9",
            c.mean, c.lines, c.below_0_9, c.total
        ));
    }
    if let Some(a) = &r.amplitude {
        out.push(format!(
            "amplitude dependence: input RMS {:.4e} (first half) vs {:.4e} (second half): FRF \
             magnitudes differ by {:.3} dB RMS over {} lines, noise alone {:.3} dB",
            a.input_rms_first, a.input_rms_second, a.differ_db, a.lines, a.noise_db
        ));
    }
    if let Some(h) = &r.harmonics {
        out.push(format!(
            "harmonics: output at {} unexcited odd lines {:.1} dB and at {} unexcited even lines \
             {:.1} dB relative to the excited lines",
            h.odd_lines, h.odd_db, h.even_lines, h.even_db
        ));
    }
    out
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
/// Another operating point: its recording's name, the comparison of the
/// two diagnoses, and its own diagnosis.
type OtherPoint = (String, OperatingPointDiagnosis, RecordingDiagnosis);

/// Another recording of the rig read with this one's flags, and its loop
/// when the diagnosis runs inside one.
fn read_other(
    args: &DiagnoseArgs,
    path: &Path,
) -> Result<(frf::Recording, Option<LoopData>), String> {
    let other = args.recording.read_file(path)?;
    let looped = other_loop(args, path, &other)?;
    Ok((other, looped))
}

/// The loop of another recording `other` (at `path`) of the rig, when the
/// diagnosis runs inside one.
fn other_loop(
    args: &DiagnoseArgs,
    path: &Path,
    other: &frf::Recording,
) -> Result<Option<LoopData>, String> {
    let other_args = RecordingArgs {
        recording: Some(path.to_path_buf()),
        recording_flag: None,
        ..args.recording.clone()
    };
    match &args.closed_loop {
        Some(l) => Ok(Some(read_loop(&other_args, l, other.samples.as_ref())?)),
        None => Ok(None),
    }
}

pub fn read_loop(
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
            // The first output (its sensor's place, if given, left out).
            y: rec
                .y
                .first()
                .map(|y| y.split('@').next().unwrap_or(y).to_string())
                .into_iter()
                .collect(),
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
/// The amplitude dependence of the recording and the `--level` recordings,
/// with the levels (`None` without `--level`).
fn amplitude(
    args: &DiagnoseArgs,
    rec: &frf::Recording,
    others: &[frf::Recording],
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
        Level::from_samples(&name, &s.u, &s.y, s.fs, &rec.source.welch(&welch))
            .map_err(|e| e.to_string())
    };
    let main = args.recording.path()?;
    let mut levels = vec![level(main, rec)?];
    for (path, other) in args.levels.iter().zip(others) {
        levels.push(level(path, other)?);
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
    links: Links,
) -> Result<Outcome, String> {
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
    let json = serde_json::json!({ "version": JSON_VERSION, "amplitude_dependence": a });
    let mut m = format!("# Amplitude dependence of `{name}`\n");
    if let Some(link) = links.to("bode") {
        let _ = writeln!(m, "\n![Bode plot: the levels]({link})");
    }
    m.push_str(
        amplitude_markdown(a)
            .trim_start()
            .trim_start_matches("## Amplitude dependence\n"),
    );
    Ok(Outcome::new(
        "mms diagnose",
        &m,
        json,
        vec![(links.file("bode"), plot)],
    ))
}

/// What a mode's trends with the level name.
fn reading(stiffness: StiffnessTrend, damping: DampingTrend) -> &'static str {
    match (stiffness, damping) {
        (StiffnessTrend::None, DampingTrend::None) => "linear within the noise",
        (StiffnessTrend::Softening, DampingTrend::Increase) => {
            "softening with more damping: a joint that slips more as the amplitude grows \
             (friction at an interface the mode deforms)"
        }
        (StiffnessTrend::Softening, _) => {
            "softening: a joint that loosens as the amplitude grows (clearance opening or slip \
             at an interface the mode deforms)"
        }
        (StiffnessTrend::Stiffening, _) => {
            "stiffening: a clearance that closes into contact as the amplitude grows (hardening \
             stops at an interface the mode deforms)"
        }
        (StiffnessTrend::None, DampingTrend::Increase) => {
            "more damping: friction at a joint (slip dissipates more per cycle as the amplitude \
             grows)"
        }
        (StiffnessTrend::None, DampingTrend::Decrease) => {
            "less damping: Coulomb friction in sliding (its equivalent viscous damping falls as \
             the amplitude grows)"
        }
    }
}

/// The amplitude comparison in words: the changing modes at the highest
/// level, the most significant first, and the growth of the distortion.
fn amplitude_verdict(a: &AmplitudeDependence) -> String {
    let levels = &a.levels;
    let top = &levels[levels.len() - 1];
    let head = format!(
        "From `{}` to `{}` ({:.2} times the input RMS)",
        levels[0].label, top.label, top.ratio
    );
    let mut v = if a.changed.is_empty() {
        format!(
            "{head} no mode moves beyond the noise ({} modes tracked; the FRF changes by {:.3} \
             dB RMS): no amplitude dependence is seen.",
            a.modes.len(),
            top.change_db
        )
    } else {
        let parts: Vec<String> = a
            .changed
            .iter()
            .filter_map(|&i| a.modes.get(i))
            .filter_map(|m| m.shifts.last().map(|s| (m, s)))
            .map(|(m, s)| {
                format!(
                    "the mode at {:.3} Hz moves by {:+.3} Hz ({:+.2} %, z = {:.1}) and its \
                     damping ratio by {:+.4} (z = {:.1}): {}",
                    m.f_ref_hz,
                    s.shift_hz,
                    100.0 * s.shift_rel,
                    s.shift_z,
                    s.damping_change,
                    s.damping_z,
                    reading(s.stiffness, s.damping_trend)
                )
            })
            .collect();
        format!(
            "{head} {} of {} modes change beyond the noise: {}.",
            a.changed.len(),
            a.modes.len(),
            parts.join("; ")
        )
    };
    if let (Some(a0), Some(b), Some(grows)) =
        (levels[0].distortion, top.distortion, a.distortion_grows)
    {
        let _ = write!(
            v,
            " The output at the {} unexcited lines above the excitation (to 3 times its top) \
             goes from {:.1} dB to {:.1} dB relative to the excited lines (the input's from \
             {:.1} dB to {:.1} dB): {}",
            b.lines,
            a0.output_db,
            b.output_db,
            a0.input_db,
            b.input_db,
            if grows {
                "nonlinear distortion grows with the level."
            } else {
                "no growth of nonlinear distortion."
            }
        );
    }
    v
}

/// The Markdown section of the amplitude dependence: the verdict, the
/// levels, the bands beyond the noise and the modes.
fn amplitude_markdown(a: &AmplitudeDependence) -> String {
    let mut s = String::from("\n## Amplitude dependence\n\n");
    let _ = writeln!(s, "{}\n", amplitude_verdict(a));
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
                reading(sh.stiffness, sh.damping_trend)
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

/// `100 x` with three significant digits (at least two decimals): a
/// closed loop leaves errors of a few millionths of the output RMS.
fn percent(x: f64) -> String {
    let p = 100.0 * x;
    let digits = if p.abs() >= 1.0 || p == 0.0 || !p.is_finite() {
        2
    } else {
        // Three significant digits below 1 %.
        (2 - p.abs().log10().floor() as i64).max(2) as usize
    };
    format!("{p:.digits$}")
}

#[cfg(test)]
mod tests {
    use super::percent;

    #[test]
    fn percent_keeps_three_significant_digits_below_one() {
        assert_eq!(percent(0.25), "25.00");
        assert_eq!(percent(6.772e-5), "0.00677");
        assert_eq!(percent(0.0), "0.00");
    }
}
