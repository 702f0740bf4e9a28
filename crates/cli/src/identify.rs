//! `mms identify`: classify a recording, fit the candidate structures,
//! report (Markdown, HTML or JSON), with Bode plots and the best model as
//! a model file when `--out DIR` is given.

use crate::notes::{
    candidate_note, classify_note, equivalent_family, failed_mark, identify_note, no_equivalent,
};
use crate::recording::RecordingArgs;
use crate::report::{Links, Outcome};
use frf::Frf;
use ident::classify::feature_name;
use ident::identify::{
    identify_with_progress, CandidateFit, Equivalent, Identification, IdentifyOptions, Progress,
};
use ident::operating::{
    compare_operating_points, Finding, OperatingPointComparison, Recording as OperatingRecording,
};
use ident::stability::{verdict_stability, Cut, Stability};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use mms::model_file::{ModelFile, Motion};
use mms::response::{ChainResponse, Effects};
use mms::Output;
use plot::{Bode, Style};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Report formats of `mms identify`.
#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq, Debug)]
pub enum IdentifyFormat {
    /// Markdown.
    Md,
    /// One self-contained HTML page with inline SVG plots.
    Html,
    /// JSON for machines.
    Json,
}

/// Options of `mms identify` beyond the recording.
pub struct IdentifyArgs<'a> {
    pub recording: &'a RecordingArgs,
    pub masses: Option<usize>,
    pub fit_gain: bool,
    pub band: Option<(f64, f64)>,
    /// Recordings of the same rig at other operating points.
    pub operating_points: &'a [PathBuf],
    pub format: IdentifyFormat,
    pub out: Option<&'a Path>,
}

/// Runs the identification; returns the report text for stdout when no
/// `--out` directory is given.
pub fn run(args: &IdentifyArgs) -> Result<Option<String>, String> {
    outcome(args, Links::new(args.format, args.out, ""))?.deliver(args.format, args.out)
}

/// The identification of the recording, in every format.
pub fn outcome(args: &IdentifyArgs, links: Links) -> Result<Outcome, String> {
    let options = IdentifyOptions {
        masses: args.masses,
        gain: if args.fit_gain {
            ident::fit::Gain::Fit(1.0)
        } else {
            ident::fit::Gain::Known(1.0)
        },
        classify: ident::ClassifyOptions {
            band_hz: args.band,
            ..ident::ClassifyOptions::default()
        },
        ..IdentifyOptions::default()
    };
    // Several outputs, or one with its sensor's place: the chain read by
    // those sensors.
    if args.recording.y.len() > 1 || args.recording.y.iter().any(|y| y.contains('@')) {
        return crate::sensors::outcome(args, &options, links);
    }
    let rec = args.recording.read()?;
    let output: Output = args.recording.output.into();
    let name = args.recording.path()?.display().to_string();
    let bar = progress_bar();
    let id =
        identify_with_progress(&rec.frf, output, &options, &|p| show(&bar, p)).map_err(|e| {
            match args.band {
                // The error concerns the band's lines (too few of them, a
                // fit on them): say which band.
                Some((lo, hi)) => format!("{name}: in the band {lo}-{hi} Hz: {e}"),
                None => format!("{name}: {e}"),
            }
        })?;
    bar.finish_and_clear();
    // A time-domain recording is identified again on other cuts of it.
    let stability = match (&rec.samples, &rec.source) {
        (Some(s), frf::Source::TimeDomain { nfft, .. }) => Some(verdict_stability(
            s,
            &rec.source.welch(&args.recording.welch()),
            *nfft,
            output,
            &options,
            &id,
        )),
        _ => None,
    };
    let operating = operating_points(args, &rec, output, &options, &id)?;
    // A figure of a million points helps nobody: the lines the
    // identification worked on.
    let shown = frf::uncertainty::log_binned(&rec.frf, ident::identify::MAX_LINES);
    let mut figures = vec![(links.file("bode"), bode(&shown, output, &id))];
    if let Some(e) = &rec.excitation {
        figures.push((links.file("loop"), loop_plot(e)));
    }
    let closed = match (&rec.excitation, rec.possible_excitations.is_empty()) {
        (Some(e), _) => Some(closed_loop_section(e, links.to("loop").as_deref())),
        (None, false) => Some(possible_excitation_note(&rec.possible_excitations)),
        (None, true) => None,
    };
    let mut json = to_json(&id, stability.as_ref());
    if rec.excitation.is_none() && !rec.possible_excitations.is_empty() {
        json["possible_excitations"] = json!(rec.possible_excitations);
    }
    if let Some(e) = &rec.excitation {
        let peak = e.peak_sensitivity_db();
        let (to_u, to_y) = e.median_coherences();
        json["closed_loop"] = json!({
            "excitation": e.name,
            "estimate": "3-point",
            "median_coherence_to_input": to_u,
            "median_coherence_to_output": to_y,
            "peak_sensitivity_db": peak.map(|p| p.0),
            "peak_sensitivity_hz": peak.map(|p| p.1),
            "modulus_margin": peak.map(|p| 10f64.powf(-p.0 / 20.0)),
            "sensitivity": curve_json(&e.sensitivity),
            "process_sensitivity": curve_json(&e.process_sensitivity),
        });
    }
    if !operating.is_empty() {
        json["operating_points"] = Value::Array(
            operating
                .iter()
                .map(|(name, c)| json!({ "recording": name, "comparison": c }))
                .collect(),
        );
    }
    if let Some((estimate, _)) = crate::recording::periodic_estimate(&rec.source) {
        json["estimate"] = estimate;
    }
    let mut md = crate::recording::with_periodic_estimate(
        markdown(&name, &id, stability.as_ref(), links.to("bode").as_deref()),
        &rec.source,
    );
    md.push_str(closed.as_deref().unwrap_or(""));
    md.push_str(&operating_markdown(&name, &operating));
    let mut outcome = Outcome::new("mms identify", &md, json, figures);
    if let Some(best) = id.candidates.first() {
        let file = fitted_model(best.model, &best.fit, output);
        outcome.files = vec![("model.toml".into(), file.to_toml())];
        outcome.fitted = Some((file, Vec::new()));
    }
    Ok(outcome)
}

/// The model file of a fitted structure.
pub fn fitted_model(model: mms::Model, fit: &ident::fit::Fit, output: Output) -> ModelFile {
    ModelFile {
        model,
        output,
        parameters: fit.parameters.clone(),
        gain: fit.gain,
        motion: Motion::Translational,
        effects: Effects::default(),
    }
}

/// One tick per fitted candidate on stderr (indicatif draws nothing when
/// stderr is not a terminal).
pub fn progress_bar() -> ProgressBar {
    // Drawn from the first report on, when the number of candidates is
    // known.
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} candidates, {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix("identify");
    bar
}

/// Shows `p` on `bar`.
pub fn show(bar: &ProgressBar, p: Progress) {
    bar.set_length(p.total as u64);
    bar.set_position(p.done as u64);
    if bar.is_hidden() {
        bar.set_draw_target(ProgressDrawTarget::stderr());
    }
}

/// The `--operating-point` recordings, each read with the options of the
/// main one, classified as it was and compared with it.
fn operating_points(
    args: &IdentifyArgs,
    rec: &frf::Recording,
    output: Output,
    options: &IdentifyOptions,
    id: &Identification,
) -> Result<Vec<(String, OperatingPointComparison)>, String> {
    let frf = &rec.frf;
    let mut out = Vec::new();
    for path in args.operating_points {
        let name = path.display().to_string();
        let other = args.recording.read_file(path)?;
        // Lines of records at different rates sit on different grids and
        // see different holds and filters: a comparison needs one rate.
        if let (Some(a), Some(b)) = (&rec.samples, &other.samples) {
            if (a.fs / b.fs - 1.0).abs() > 1e-9 {
                return Err(format!(
                    "{name}: sampled at {} Hz, {} at {} Hz: resample one of them before \
                     comparing operating points",
                    b.fs,
                    args.recording.path()?.display(),
                    a.fs
                ));
            }
        }
        let c = ident::classify(&other.frf, output, &options.classify)
            .map_err(|e| format!("{name}: {e}"))?;
        out.push((
            name,
            compare_operating_points(&id.classification, frf, &c, &other.frf),
        ));
    }
    Ok(out)
}

/// "first" or "second": how the reports name the recordings of an
/// operating-point comparison.
pub fn recording_name(r: OperatingRecording) -> &'static str {
    match r {
        OperatingRecording::First => "first",
        OperatingRecording::Second => "second",
    }
}

/// The report section of the operating-point comparisons.
pub fn operating_markdown(
    name: &str,
    comparisons: &[(String, OperatingPointComparison)],
) -> String {
    let mut s = String::new();
    for (other, c) in comparisons {
        let _ = writeln!(
            s,
            "\n## Operating points: `{name}` (first) and `{other}` (second)\n"
        );
        let which = recording_name;
        if c.paired.is_empty() {
            s.push_str(
                "The types of the two recordings share no feature: they cannot be compared \
                 feature by feature (different structures, or a feature one classification \
                 did not claim).\n",
            );
        } else if c.findings.is_empty() && c.lone.is_empty() {
            s.push_str(
                "Every feature of the type holds for both recordings within the noise: \
                 nothing differs between the operating points.\n",
            );
        }
        for f in &c.findings {
            let _ = match f {
                Finding::PreSlidingFriction {
                    recording,
                    freq_hz,
                    stiffness,
                } => writeln!(
                    s,
                    "- **Pre-sliding friction** in the {} recording only: a resonance at {:.4} Hz \
                     below every feature of the other, whose low band moves as a rigid body: a \
                     stiffness to ground{}, the friction on which the axis rests at standstill.",
                    which(*recording),
                    freq_hz,
                    stiffness.map_or(String::new(), |k| format!(
                        " of {k:.4e} (input units per output unit, from the other recording's \
                         rigid-body inertia)"
                    ))
                ),
                Finding::ModeShift {
                    feature,
                    freq_hz,
                    z,
                } => writeln!(
                    s,
                    "- **Mode shift:** the {} moves from {:.4} Hz to {:.4} Hz ({:+.1} %), {}.",
                    feature_name(*feature),
                    freq_hz.0,
                    freq_hz.1,
                    100.0 * (freq_hz.1 / freq_hz.0 - 1.0),
                    match z {
                        Some(z) => format!(
                            "{:.1} standard deviations of the difference of the two local fits",
                            z.abs()
                        ),
                        None => "beyond the resolution (no local fit)".to_string(),
                    }
                ),
                Finding::DampingChange {
                    feature,
                    freq_hz,
                    damping,
                    z,
                } => writeln!(
                    s,
                    "- **Damping change:** the {} near {:.4} / {:.4} Hz has a damping ratio of \
                     {:.4} in the first recording and {:.4} in the second, {:.1} standard \
                     deviations of the difference.",
                    feature_name(*feature),
                    freq_hz.0,
                    freq_hz.1,
                    damping.0,
                    damping.1,
                    z.abs()
                ),
            };
        }
        s.push_str(
            "\n| feature | first (Hz) | second (Hz) | shift | shift / sd | damping first | \
             damping second | damping / sd | holds for |\n\
             |---|---:|---:|---:|---:|---:|---:|---:|---|\n",
        );
        let mut rows: Vec<(f64, String)> = c
            .paired
            .iter()
            .map(|p| {
                (
                    p.freq_hz.0,
                    format!(
                        "| {} | {} | {} | {:+.2} % | {} | {} | {} | {} | {} |",
                        feature_name(p.kind),
                        with_sd(p.freq_hz.0, p.sd_hz.map(|s| s.0)),
                        with_sd(p.freq_hz.1, p.sd_hz.map(|s| s.1)),
                        100.0 * p.shift,
                        match p.shift_z {
                            Some(z) => format!("{z:+.1}"),
                            None => format!("- (resolution {:.2} %)", 100.0 * p.resolution),
                        },
                        p.fits.map_or("-".into(), |f| format!("{:.4}", f.0.damping)),
                        p.fits.map_or("-".into(), |f| format!("{:.4}", f.1.damping)),
                        p.damping_z.map_or("-".into(), |z| format!("{z:+.1}")),
                        if p.shifted || p.damping_changed {
                            "each its own"
                        } else {
                            "both"
                        }
                    ),
                )
            })
            .collect();
        rows.extend(c.lone.iter().map(|l| {
            let (a, b) = match l.recording {
                OperatingRecording::First => (format!("{:.4}", l.freq_hz), "-".to_string()),
                OperatingRecording::Second => ("-".to_string(), format!("{:.4}", l.freq_hz)),
            };
            (
                l.freq_hz,
                format!(
                    "| {} | {a} | {b} | - | - | - | - | - | the {} only |",
                    feature_name(l.kind),
                    which(l.recording)
                ),
            )
        }));
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, r) in rows {
            s.push_str(&r);
            s.push('\n');
        }
    }
    s
}

/// A frequency and, from a local fit, its standard deviation.
fn with_sd(f_hz: f64, sd_hz: Option<f64>) -> String {
    match sd_hz {
        Some(sd) => format!("{f_hz:.4} ± {sd:.4}"),
        None => format!("{f_hz:.4}"),
    }
}

/// Parameters as a JSON object, name to value.
pub fn parameters_json(p: &mms::response::Parameters) -> serde_json::Map<String, Value> {
    p.iter().map(|(k, v)| (k.to_string(), json!(v))).collect()
}

fn candidate_json(c: &CandidateFit) -> Value {
    let m = &c.model;
    let params = parameters_json(&c.fit.parameters);
    json!({
        "id": c.id,
        "masses": m.n_masses(),
        "gap": m.gap(),
        "actuator": [m.actuator().plus, m.actuator().minus],
        "sensor": [m.sensor().plus, m.sensor().minus],
        "parameters": params,
        "gain": c.fit.gain,
        "fit": {"rms_db": c.fit.rms_db, "rms_deg": c.fit.rms_deg},
        "start": c.start,
        "back_solutions": c.back_solutions,
        "rank": c.rank,
        "failed": c.failed,
        "notes": c.notes.iter().map(candidate_note).collect::<Vec<_>>(),
        "note_data": c.notes,
    })
}

/// An equivalent's JSON: `family` and `none` as sentences, their data
/// beside them.
fn equivalent_json(e: &Equivalent) -> Value {
    json!({
        "id": e.id,
        "parameters": e.parameters,
        "sets": e.sets,
        "family": e.family.as_ref().map(equivalent_family),
        "none": e.none.as_ref().map(no_equivalent),
        "family_data": e.family,
        "none_data": e.none,
    })
}

/// The JSON of the schema.
fn to_json(id: &Identification, stability: Option<&Stability>) -> Value {
    let c = &id.classification;
    json!({
        "classification": {
            "type": c.frf_type.to_string(),
            "confidence": c.confidence,
            "band_hz": [c.band_hz.0, c.band_hz.1],
            "uncertainty": c.uncertainty_name(),
            "noise_db": c.noise_db,
            "features": c.features.iter().map(|f| json!({
                "kind": feature_name(f.kind),
                "freq_hz": f.freq_hz,
                "multiplicity": f.multiplicity,
                "confidence": f.confidence,
                "damping_ratio": f.damping_ratio,
                "in_type": f.in_type,
            })).collect::<Vec<_>>(),
            "notes": c.notes.iter().map(classify_note).collect::<Vec<_>>(),
            "note_data": c.notes,
        },
        "masses": id.masses,
        "candidates": id.candidates.iter().map(candidate_json).collect::<Vec<_>>(),
        "indistinguishable": id.indistinguishable,
        "sensor_advice": id.sensor_advice,
        "equivalents": id.equivalents.iter().map(equivalent_json).collect::<Vec<_>>(),
        "sensor_reversed": id.sensor_reversed,
        "stability": stability.map(|s| json!({"stable": s.stable(), "runs": s.runs})),
        "notes": id.notes.iter().map(identify_note).collect::<Vec<_>>(),
        "note_data": id.notes,
    })
}

/// A model's FRF (times its gain) on the plot's lines; NaN where it cannot
/// be evaluated, which the plot draws as a gap.
pub fn model_curve(
    g: &ChainResponse,
    values: &[f64],
    gain: f64,
    freq_hz: &[f64],
) -> Vec<num_complex::Complex64> {
    freq_hz
        .iter()
        .map(|&x| {
            g.eval(values, x)
                .map(|z| z * gain)
                .unwrap_or(num_complex::Complex64::new(f64::NAN, f64::NAN))
        })
        .collect()
}

/// Data, the best fit and the rest of its indistinguishable group.
fn bode(frf: &Frf, output: Output, id: &Identification) -> Bode {
    let (lo, hi) = id.classification.band_hz;
    let f = frf.freq_hz();
    let mut b = Bode::new(format!(
        "Measured FRF ({}) and fitted models",
        id.classification.frf_type
    ))
    .trace("measured", f, frf.response(), Style::points());
    if let Some(s) = frf.std_dev() {
        b = b.uncertainty(s);
    }
    let group = id.indistinguishable.first().map_or(1, Vec::len);
    for (k, c) in id.candidates.iter().take(group.clamp(1, 4)).enumerate() {
        let h = model_curve(
            &ChainResponse::new(&c.model, output),
            c.fit.parameters.values(),
            c.fit.gain,
            f,
        );
        let style = if k == 0 {
            Style::line()
        } else {
            Style::dashed()
        };
        b = b.trace(
            format!("{} (fit {:.2} dB)", c.id, c.fit.rms_db),
            f,
            &h,
            style,
        );
    }
    if lo > f[0] || hi < f[f.len() - 1] {
        b = b.band(f[0], lo, "outside the band");
        b = b.band(hi, f[f.len() - 1], "outside the band");
    }
    if let Some(g) = frf.coherence() {
        b = b.coherence(g);
    }
    // The analysed band with some context fills the figure.
    b.view(lo.max(f[0]), hi.min(f[f.len() - 1])).residual()
}

pub fn fmt_sig(x: f64) -> String {
    // Four significant digits, deterministic.
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = 3 - x.abs().log10().floor() as i32;
    if (0..=8).contains(&digits) {
        format!("{:.*}", digits as usize, x)
    } else {
        format!("{x:.3e}")
    }
}

fn markdown(
    name: &str,
    id: &Identification,
    stability: Option<&Stability>,
    plot: Option<&str>,
) -> String {
    let c = &id.classification;
    let mut s = String::new();
    let _ = writeln!(s, "# Identification of `{name}`\n");
    let best = id.candidates.first();
    let group = id.indistinguishable.first().cloned().unwrap_or_default();
    let _ = writeln!(
        s,
        "**FRF type {}** (confidence {:.2}) in the band {}-{} Hz; {} candidate \
         structures of {} masses. {}\n",
        c.frf_type,
        c.confidence,
        fmt_sig(c.band_hz.0),
        fmt_sig(c.band_hz.1),
        id.candidates.len(),
        id.masses,
        match (best, group.len()) {
            (Some(b), 1) => format!("Best fit: **{}** ({:.3} dB, {:.2} deg RMS).", b.id, b.fit.rms_db, b.fit.rms_deg),
            (Some(b), n) => format!(
                "Best fit: **{}** ({:.3} dB, {:.2} deg RMS); {} structures fit equally well and cannot be told apart from this FRF: {}.",
                b.id, b.fit.rms_db, b.fit.rms_deg, n, group.join(", ")
            ),
            (None, _) => "No candidate.".into(),
        }
    );
    if let Some(st) = stability.filter(|st| !st.stable()) {
        let flipped: Vec<String> = st
            .runs
            .iter()
            .filter(|r| !(r.same_type && r.same_structure))
            .map(|r| cut_name(r.cut))
            .collect();
        let _ = writeln!(
            s,
            "**Uncertain:** the verdict flips on {} of the record (see Stability).\n",
            flipped.join(", ")
        );
    }
    if let Some(p) = plot {
        let _ = writeln!(s, "![Bode plot: measured and fitted]({p})\n");
    }
    if let Some(st) = stability {
        s.push_str(&stability_section(st));
    }
    s.push_str("## Features\n\n| kind | f (Hz) | damping ratio | confidence | in type |\n|---|---:|---:|---:|---|\n");
    for f in &c.features {
        let _ = writeln!(
            s,
            "| {}{} | {} | {} | {:.2} | {} |",
            feature_name(f.kind),
            if f.multiplicity > 1 {
                format!(" (x{})", f.multiplicity)
            } else {
                String::new()
            },
            fmt_sig(f.freq_hz),
            f.damping_ratio.map_or("-".into(), |z| format!("{z:.4}")),
            f.confidence,
            if f.in_type { "yes" } else { "no" }
        );
    }
    s.push_str("\n## Candidates\n\n| rank | structure | RMS dB | RMS deg | start | notes |\n|---:|---|---:|---:|---|---|\n");
    for cand in &id.candidates {
        let _ = writeln!(
            s,
            "| {} | {}{} | {:.3} | {:.2} | {} | {} |",
            cand.rank,
            cand.id,
            failed_mark(cand.failed),
            cand.fit.rms_db,
            cand.fit.rms_deg,
            match cand.start {
                ident::identify::StartKind::BackSolved =>
                    format!("back-solved ({})", cand.back_solutions),
                ident::identify::StartKind::FeatureMatched => "feature-matched".into(),
                ident::identify::StartKind::MultiStart => "multi-start".into(),
            },
            cand.notes
                .iter()
                .map(candidate_note)
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    s.push_str("\n## Parameters\n\n");
    for cand in id.candidates.iter().take(group.len().max(1)) {
        let _ = writeln!(s, "**{}** (gain {}):\n", cand.id, fmt_sig(cand.fit.gain));
        s.push_str("| parameter | value |\n|---|---:|\n");
        for (k, v) in cand.fit.parameters.iter() {
            let _ = writeln!(s, "| {k} | {} |", fmt_sig(v));
        }
        s.push('\n');
    }
    if group.len() > 1 {
        s.push_str("## Which extra sensor would separate them\n\n");
        if id.sensor_advice.is_empty() {
            s.push_str(
                "No single extra position sensor separates them by more than the threshold.\n\n",
            );
        }
        for a in &id.sensor_advice {
            let pairs: Vec<String> = a
                .separates
                .iter()
                .map(|(x, y)| format!("{x}/{y}"))
                .collect();
            let _ = writeln!(
                s,
                "- a position sensor at mass {} separates {} (by at least {:.1} dB RMS)",
                a.mass,
                pairs.join(", "),
                a.min_difference_db
            );
        }
        s.push('\n');
    }
    if let Some(best) = id.candidates.first() {
        let _ = writeln!(
            s,
            "## Equivalent parameter sets (undamped, from the {} fit)\n\n\
             Every positive parameter set of each candidate whose undamped FRF equals \
             the best fit's exactly (the paper's Tab. 7), by exact back-solving.\n",
            best.id
        );
        for e in &id.equivalents {
            if let Some(why) = &e.none {
                let _ = writeln!(s, "- **{}**: none: {}", e.id, no_equivalent(why));
                continue;
            }
            let sets: Vec<String> = e
                .sets
                .iter()
                .map(|v| {
                    let kv: Vec<String> = e
                        .parameters
                        .iter()
                        .zip(v)
                        .map(|(k, x)| format!("{k} = {}", fmt_sig(*x)))
                        .collect();
                    kv.join(", ")
                })
                .collect();
            match &e.family {
                Some(f) => {
                    let _ = writeln!(
                        s,
                        "- **{}**: {}; e.g. {}",
                        e.id,
                        equivalent_family(f),
                        sets.join(" | ")
                    );
                }
                None => {
                    let _ = writeln!(
                        s,
                        "- **{}**: {} set(s): {}",
                        e.id,
                        sets.len(),
                        sets.join(" | ")
                    );
                }
            }
        }
        s.push('\n');
    }
    s.push_str("## Notes\n\n");
    let notes = id
        .notes
        .iter()
        .map(identify_note)
        .chain(c.notes.iter().map(classify_note));
    for n in notes {
        let _ = writeln!(s, "- {n}");
    }
    s
}

/// Signals of the file that look like an excitation, when none was given.
pub fn possible_excitation_note(names: &[String]) -> String {
    let list: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    format!(
        "\n## Closed loop?\n\nThe file also holds {} as long as the input. If the record was \
         taken in a closed loop with one of them injected, H1 from u to y is biased by the noise \
         the controller feeds back; give it as `--excitation` for the 3-point estimate.\n",
        list.join(", ")
    )
}

/// The loop behind a 3-point estimate: its excitation and peak
/// sensitivity.
/// The loop functions from the excitation: the sensitivity `S` (to the
/// plant input) and the process sensitivity `PS` (to the output).
fn loop_plot(e: &frf::recording::Excitation) -> Bode {
    let s = &e.sensitivity;
    let ps = &e.process_sensitivity;
    Bode::new(format!("Closed loop: S and PS from `{}`", e.name))
        .trace(
            "S (excitation to plant input)",
            s.freq_hz(),
            s.response(),
            Style::points(),
        )
        .trace(
            "PS (excitation to output)",
            ps.freq_hz(),
            ps.response(),
            Style::points(),
        )
}

/// A loop function as `[freq_hz, re, im]` rows for the JSON.
fn curve_json(f: &Frf) -> Value {
    Value::Array(
        f.freq_hz()
            .iter()
            .zip(f.response())
            .map(|(x, h)| json!([x, h.re, h.im]))
            .collect(),
    )
}

fn closed_loop_section(e: &frf::recording::Excitation, plot: Option<&str>) -> String {
    let mut s = format!(
        "\n## Closed loop\n\nThe FRF is the 3-point estimate `P = S_xy / S_xu` from the \
         excitation `{}` (the noise the controller feeds back from the output into the input \
         does not bias it, as it biases H1 from u to y).",
        e.name
    );
    if let Some((db, f)) = e.peak_sensitivity_db() {
        let _ = write!(
            s,
            " Peak sensitivity `max |S|` = {db:.2} dB at {f:.4} Hz: modulus margin {:.3}.",
            10f64.powf(-db / 20.0)
        );
    }
    let (to_u, to_y) = e.median_coherences();
    let _ = write!(
        s,
        " Median coherence from the excitation over the excited lines: {to_u:.3} to the \
         input, {to_y:.3} to the output."
    );
    s.push('\n');
    if let Some(p) = plot {
        let _ = writeln!(
            s,
            "\n![The loop's sensitivity S and process sensitivity PS from the excitation]({p})"
        );
    }
    s
}

pub fn cut_name(cut: Cut) -> String {
    match cut {
        Cut::FirstHalf => "the first half".into(),
        Cut::SecondHalf => "the second half".into(),
        Cut::SegmentLength(n) => format!("segments of {n} samples"),
    }
}

/// The reruns of the verdict on other cuts of the record.
fn stability_section(st: &Stability) -> String {
    let mut s = String::from(
        "## Stability\n\nThe same identification on other cuts of the record: a verdict \
         that flips is uncertain.\n\n| cut | FRF type | best structures | same type | same best |\n\
         |---|---|---|---|---|\n",
    );
    let yes = |b: bool| if b { "yes" } else { "**no**" };
    for r in &st.runs {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            cut_name(r.cut),
            r.frf_type.as_deref().unwrap_or("-"),
            match &r.error {
                Some(e) => format!("not identified: {e}"),
                None => r.best_group.join(", "),
            },
            yes(r.same_type),
            yes(r.same_structure)
        );
    }
    s.push('\n');
    s
}
