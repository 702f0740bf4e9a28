//! `mms identify` and `mms diagnose` with several `--y`: one chain read by
//! several sensors, identified by `ident::joint::identify_sensors` or
//! diagnosed output by output with `ident::diagnosis::diagnose_recording`,
//! formatted here.

use crate::diagnose::{
    json as diagnosis_json, load_model, markdown as diagnosis_markdown,
    options as diagnose_options, verdict_text, DiagnoseArgs,
};
use crate::identify::{
    fitted_model, fmt_sig, model_curve, parameters_json, progress_bar, show, IdentifyArgs,
};
use crate::notes::{failed_mark, sensors_note};
use crate::recording::SensorRecording;
use crate::report::{Links, Outcome};
use ident::classify::feature_name;
use ident::diagnose::EffectKind;
use ident::diagnosis::{
    diagnose_sensors, log_error_after, Domain, OutputRecording, RecordingDiagnosis,
    INFORMATIVE_LOG_ERROR,
};
use ident::identify::IdentifyOptions;
use ident::joint::{
    identify_sensors_with_progress, RuledOutBy, SensorOutput, SensorsIdentification,
};
use mms::response::ChainResponse;
use mms::{Model, Output, Port};
use plot::{Bode, Style};
use serde_json::{json, Value};
use std::fmt::Write as _;

/// Identifies the chain from every output of the recording.
pub fn outcome(
    args: &IdentifyArgs,
    options: &IdentifyOptions,
    links: Links,
) -> Result<Outcome, String> {
    let name = args.recording.path()?.display().to_string();
    if !args.operating_points.is_empty() {
        return Err(format!(
            "{name}: --operating-point compares one output; give a single --y with it"
        ));
    }
    let outputs: Vec<SensorRecording> = args.recording.read_outputs(&[])?;
    let output: Output = args.recording.output.into();
    let inputs: Vec<SensorOutput> = outputs
        .iter()
        .map(|o| SensorOutput {
            name: o.signal.clone(),
            frf: &o.recording.frf,
            location: o.location,
        })
        .collect();
    let bar = progress_bar();
    let id = identify_sensors_with_progress(&inputs, output, options, &|p| show(&bar, p))
        .map_err(|e| format!("{name}: {e}"))?;
    bar.finish_and_clear();
    let plots = bode(&outputs, output, &id);
    let md = markdown(&name, &id, links.to("bode").as_deref());
    let mut outcome = Outcome::new(
        "mms identify",
        &md,
        to_json(&id),
        vec![(links.file("bode"), plots)],
    );
    // The model file of the best candidate, read by the first output's
    // sensor, with every output's sensor (`mms diagnose` reads them); a
    // sensor mounted the other way round (its output's sign reversed) has
    // no port of its own, so then the places are in the report only.
    let reversed = id.outputs.iter().any(|o| o.sensor_reversed);
    if let Some(best) = id.candidates.first() {
        let sensors: Vec<mms::Port> = if reversed {
            Vec::new()
        } else {
            best.models.iter().map(|m| m.sensor()).collect()
        };
        let file = fitted_model(best.models[0], &best.fit, output);
        outcome.files = vec![("model.toml".into(), file.to_toml_with_sensors(&sensors))];
        outcome.fitted = Some((file, sensors));
    }
    Ok(outcome)
}

/// Each output's measurement and the best candidate's curve for it.
fn bode(outputs: &[SensorRecording], output: Output, id: &SensorsIdentification) -> Bode {
    let mut b = Bode::new(format!(
        "Measured FRFs of {} sensors and the joint fit",
        outputs.len()
    ));
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for (k, o) in outputs.iter().enumerate() {
        let frf = &o.recording.frf;
        let f = frf.freq_hz();
        let c = &id.outputs[k].classification;
        lo = lo.min(c.band_hz.0.max(f[0]));
        hi = hi.max(c.band_hz.1.min(f[f.len() - 1]));
        b = b.trace(
            format!("{} ({})", o.signal, c.frf_type),
            f,
            frf.response(),
            Style::points(),
        );
        if let Some(best) = id.candidates.first() {
            let sign = if id.outputs[k].sensor_reversed {
                -1.0
            } else {
                1.0
            };
            let h = model_curve(
                &ChainResponse::new(&best.models[k], output),
                best.fit.parameters.values(),
                sign * best.fit.gain,
                f,
            );
            b = b.trace(
                format!(
                    "{} at {}, joint fit ({:.2} dB)",
                    o.signal,
                    location_name(best.models[k].sensor()),
                    best.per_output[k].0
                ),
                f,
                &h,
                Style::line(),
            );
        }
    }
    if lo < hi {
        b = b.view(lo, hi);
    }
    b
}

/// A port as the report names it: `mass 2`, `mass 3 - mass 1`.
fn location_name(p: mms::Port) -> String {
    if p.minus == 0 {
        format!("mass {}", p.plus)
    } else {
        format!("mass {} - mass {}", p.plus, p.minus)
    }
}

fn to_json(id: &SensorsIdentification) -> Value {
    json!({
        "masses": id.masses,
        "outputs": id.outputs.iter().map(|o| {
            let c = &o.classification;
            json!({
                "name": o.name,
                "location": o.location,
                "type": c.frf_type.to_string(),
                "band_hz": [c.band_hz.0, c.band_hz.1],
                "noise_db": c.noise_db,
                "sensor_reversed": o.sensor_reversed,
                "features": c.features.iter().filter(|f| f.in_type).map(|f| json!({
                    "kind": feature_name(f.kind),
                    "freq_hz": f.freq_hz,
                    "damping_ratio": f.damping_ratio,
                })).collect::<Vec<_>>(),
            })
        }).collect::<Vec<_>>(),
        "candidates": id.candidates.iter().map(|c| {
            let params = parameters_json(&c.fit.parameters);
            json!({
                "id": c.id,
                "rank": c.rank,
                "sensors": c.models.iter().map(|m| [m.sensor().plus, m.sensor().minus]).collect::<Vec<_>>(),
                "actuator": [c.models[0].actuator().plus, c.models[0].actuator().minus],
                "gap": c.models[0].gap(),
                "parameters": params,
                "gain": c.fit.gain,
                "fit": {"rms_db": c.fit.rms_db, "rms_deg": c.fit.rms_deg},
                "per_output": c.per_output.iter().map(|e| json!({"rms_db": e.0, "rms_deg": e.1})).collect::<Vec<_>>(),
                "score_db": c.score_db,
                "first_output_score_db": c.first_output_score_db,
                "failed": c.failed,
            })
        }).collect::<Vec<_>>(),
        "indistinguishable": id.indistinguishable,
        "first_output_alone": id.first_output_alone,
        "ruled_out": id.ruled_out,
        "exact": id.exact.iter().map(|e| json!({
            "id": e.id,
            "verdict": e.verdict.kind(),
            "indistinguishable": e.indistinguishable(),
            "reason": e.verdict.to_string(),
        })).collect::<Vec<_>>(),
        "notes": id.notes.iter().map(sensors_note).collect::<Vec<_>>(),
        "note_data": id.notes,
    })
}

fn markdown(name: &str, id: &SensorsIdentification, plot: Option<&str>) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Identification of `{name}` from {} outputs\n",
        id.outputs.len()
    );
    let group = id.indistinguishable.first().cloned().unwrap_or_default();
    match id.candidates.first() {
        None => s.push_str("No candidate could be fitted.\n\n"),
        Some(b) => {
            let _ = write!(
                s,
                "{} candidate structures of {} masses, each fitted to every output at once with \
                 one parameter set. Best joint fit: **{}** ({:.3} dB, {:.2} deg RMS over all \
                 outputs)",
                id.candidates.len(),
                id.masses,
                b.id,
                b.fit.rms_db,
                b.fit.rms_deg
            );
            if group.len() > 1 {
                let _ = write!(
                    s,
                    "; {} structures fit all outputs equally well: {}",
                    group.len(),
                    group.join(", ")
                );
            }
            s.push_str(".\n\n");
        }
    }
    if id.first_output_alone.len() > 1 || !id.ruled_out.is_empty() {
        let _ = writeln!(
            s,
            "The first output alone fits {} structures equally well ({}). {}\n",
            id.first_output_alone.len(),
            id.first_output_alone.join(", "),
            if id.ruled_out.is_empty() {
                "The other outputs rule none of them out.".to_string()
            } else {
                let each: Vec<String> = id
                    .ruled_out
                    .iter()
                    .map(|r| match r.by {
                        RuledOutBy::Type { output } => format!(
                            "{} (its sensor for {} cannot show the type {} at all)",
                            r.id,
                            id.outputs[output].name,
                            id.outputs[output].classification.frf_type
                        ),
                        RuledOutBy::Fit { excess_db } => {
                            format!("{} (its joint fit is {excess_db:.2} dB worse)", r.id)
                        }
                    })
                    .collect();
                format!("The other outputs rule out {}.", each.join("; "))
            }
        );
    }
    if !id.exact.is_empty() {
        let same: Vec<&str> = id
            .exact
            .iter()
            .filter(|e| e.indistinguishable())
            .map(|e| e.id.as_str())
            .collect();
        let _ = writeln!(
            s,
            "Exactly, with these sensors (every parameter set, not only the fitted one): {}\n",
            if same.is_empty() {
                "no other candidate reproduces the best one's outputs; the best is determined by \
                 the structure of the sensors."
                    .to_string()
            } else {
                format!(
                    "{} reproduce every output of the best one and stay indistinguishable from it.",
                    same.join(", ")
                )
            }
        );
        s.push_str("| candidate | against the best, exactly |\n|---|---|\n");
        for e in &id.exact {
            let _ = writeln!(s, "| {} | {} |", e.id, e.verdict);
        }
        s.push('\n');
    }
    if let Some(p) = plot {
        let _ = writeln!(s, "![Bode plot: every output, measured and fitted]({p})\n");
    }
    s.push_str(
        "## Outputs\n\n| output | sensor | type | band (Hz) | features |\n|---|---|---|---|---|\n",
    );
    for o in &id.outputs {
        let c = &o.classification;
        let features: Vec<String> = c
            .features
            .iter()
            .filter(|f| f.in_type)
            .map(|f| format!("{} {} Hz", feature_name(f.kind), fmt_sig(f.freq_hz)))
            .collect();
        let _ = writeln!(
            s,
            "| {} | {}{} | {} | {}-{} | {} |",
            o.name,
            o.location.map_or("any".to_string(), |l| format!("at {l}")),
            if o.sensor_reversed {
                " (counts the other way)"
            } else {
                ""
            },
            c.frf_type,
            fmt_sig(c.band_hz.0),
            fmt_sig(c.band_hz.1),
            if features.is_empty() {
                "-".to_string()
            } else {
                features.join(", ")
            }
        );
    }
    s.push_str("\n## Candidates\n\n| rank | structure | joint fit (dB / deg) |");
    for o in &id.outputs {
        let _ = write!(s, " {} (dB / deg) |", o.name);
    }
    s.push_str(" first output alone (score dB) |\n|---:|---|---:|");
    for _ in &id.outputs {
        s.push_str("---:|");
    }
    s.push_str("---:|\n");
    for c in &id.candidates {
        let failed = failed_mark(c.failed);
        let _ = write!(
            s,
            "| {} | {}{failed} | {:.3} / {:.2} |",
            c.rank, c.id, c.fit.rms_db, c.fit.rms_deg
        );
        for e in &c.per_output {
            let _ = write!(s, " {:.3} / {:.2} |", e.0, e.1);
        }
        let _ = writeln!(s, " {:.3} |", c.first_output_score_db);
    }
    if let Some(b) = id.candidates.first() {
        s.push_str("\n## Parameters of the best joint fit\n\n| parameter | value |\n|---|---:|\n");
        for (k, v) in b.fit.parameters.iter() {
            let _ = writeln!(s, "| {k} | {} |", fmt_sig(v));
        }
        let _ = writeln!(s, "| gain | {} |", fmt_sig(b.fit.gain));
    }
    if !id.notes.is_empty() {
        s.push_str("\n## Notes\n\n");
        for n in &id.notes {
            let _ = writeln!(s, "- {}", sensors_note(n));
        }
    }
    s
}

/// `mms diagnose` with several `--y`: the model read at each output's
/// sensor, diagnosed against that output; the effects every output names.
pub fn diagnose(args: &DiagnoseArgs, links: Links) -> Result<Outcome, String> {
    let name = args.recording.path()?.display().to_string();
    if !args.levels.is_empty() || args.validate.is_some() || !args.operating_points.is_empty() {
        return Err(format!(
            "{name}: --level, --validate and --operating-point compare one output; give a \
             single --y with them"
        ));
    }
    let Some(source) = args.model else {
        return Err("give the model: --model MODEL.toml or --simulation FILE".into());
    };
    let (model, sensors, source_text) = load_model(args, source)?;
    let outputs = args.recording.read_outputs(&sensors)?;
    let Some(first) = outputs.first() else {
        return Err(format!("{name}: no output to diagnose"));
    };
    crate::diagnose::model_on_lines(&model, source, &first.recording.frf)?;
    let options = diagnose_options(args, &first.recording.source)?;
    let chain = model.model;
    let n = chain.n_masses();
    let mut ports = Vec::with_capacity(outputs.len());
    let mut inputs = Vec::with_capacity(outputs.len());
    for o in &outputs {
        let port = match o.location {
            Some(l) => l.port(n).ok_or_else(|| {
                format!(
                    "{name}: --y {}: sensor location {l} lies outside the model's {n} masses",
                    o.signal
                )
            })?,
            // Only the first may leave it free (`read_outputs`).
            None => chain.sensor(),
        };
        let m = Model::new(n, chain.gap(), chain.actuator(), port).map_err(|e| {
            format!(
                "{name}: --y {}: the model's chain ({}) has no sensor at {}: {e}",
                o.signal,
                chain.id(),
                location_name(port)
            )
        })?;
        ports.push(port);
        inputs.push(OutputRecording {
            frf: &o.recording.frf,
            samples: o.recording.samples.as_ref(),
            chain: m,
        });
    }
    // The loop is closed on the first output.
    let looped = match (&args.closed_loop, outputs.first()) {
        (Some(l), Some(first)) => Some(crate::diagnose::read_loop(
            args.recording,
            l,
            first.recording.samples.as_ref(),
        )?),
        _ => None,
    };
    let record = looped.as_ref().map(|l| l.record());
    let diagnosis = diagnose_sensors(&inputs, &model, record.as_ref(), &options).map_err(|e| {
        match e.output {
            Some(i) => format!("{name}: --y {}: {}", outputs[i].signal, e.error),
            None => format!("{name}: all outputs at once: {}", e.error),
        }
    })?;
    let joint = diagnosis.joint;
    let runs: Vec<(&SensorRecording, Port, RecordingDiagnosis)> = outputs
        .iter()
        .zip(ports)
        .zip(diagnosis.outputs)
        .map(|((o, p), d)| (o, p, d))
        .collect();
    let common = common_effects(&runs);
    let mut plot = Bode::new(format!(
        "{} outputs and the model after each diagnosis",
        runs.len()
    ));
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for (o, port, d) in &runs {
        let c = &d.curves;
        plot = plot
            .trace(
                format!("{} (recording)", o.signal),
                &c.freq_hz,
                &c.recording,
                Style::points(),
            )
            .trace(
                format!("{} at {}, model after", o.signal, location_name(*port)),
                &c.freq_hz,
                &c.after,
                Style::line(),
            );
        if let Some((a, b)) = d.band_hz {
            lo = lo.min(a.max(c.freq_hz.first().copied().unwrap_or(a)));
            hi = hi.max(b);
        }
    }
    if lo < hi {
        plot = plot.view(lo, hi);
    }
    let mut each = Vec::new();
    for (o, port, d) in &runs {
        let v: Value = diagnosis_json(d, None, None)?;
        each.push(json!({
            "name": o.signal,
            "location": o.location,
            "sensor": [port.plus, port.minus],
            "diagnosis": v,
        }));
    }
    let json = json!({
        "version": crate::diagnose::JSON_VERSION,
        "outputs": each,
        "joint": match &joint {
            Some(j) => diagnosis_json(j, None, None)?,
            None => Value::Null,
        },
        "common_effects": common.iter().map(|c| json!({
            "kind": c.kind.as_str(),
            "parameter": c.parameter,
            "values": c.values,
            "spread": c.spread,
        })).collect::<Vec<_>>(),
    });
    let md = diagnose_markdown(
        &name,
        &source_text,
        &runs,
        (&common, joint.as_ref()),
        links.to("bode").as_deref(),
    );
    let mut outcome = Outcome::new("mms diagnose", &md, json, vec![(links.file("bode"), plot)]);
    outcome.files = vec![("model_after.toml".into(), runs[0].2.model_after.to_toml())];
    Ok(outcome)
}

/// An effect every output names, with its value on each.
struct CommonEffect {
    kind: EffectKind,
    parameter: Option<&'static str>,
    values: Vec<f64>,
    /// `max / min - 1` of the values (0 without a parameter).
    spread: f64,
}

/// The effect kinds in every output's verdict, in the first output's order.
fn common_effects(runs: &[(&SensorRecording, Port, RecordingDiagnosis)]) -> Vec<CommonEffect> {
    let Some((_, _, first)) = runs.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in &first.verdict.effects {
        if e.kind == EffectKind::None {
            continue;
        }
        let parameter = e.kind.parameter_name();
        let mut values = Vec::new();
        let mut everywhere = true;
        for (_, _, d) in runs {
            match d.verdict.effects.iter().find(|x| x.kind == e.kind) {
                Some(x) => {
                    if let Some(v) = parameter.and_then(|p| x.parameters.get(p)) {
                        values.push(*v);
                    }
                }
                None => everywhere = false,
            }
        }
        if !everywhere {
            continue;
        }
        let (lo, hi) = values
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
        out.push(CommonEffect {
            kind: e.kind,
            parameter,
            spread: if values.is_empty() || lo <= 0.0 {
                0.0
            } else {
                hi / lo - 1.0
            },
            values,
        });
    }
    out
}

fn diagnose_markdown(
    name: &str,
    source: &str,
    runs: &[(&SensorRecording, Port, RecordingDiagnosis)],
    (common, joint): (&[CommonEffect], Option<&RecordingDiagnosis>),
    plot: Option<&str>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Diagnosis of `{name}` from {} outputs\n", runs.len());
    let _ = writeln!(
        s,
        "{source} Each output is compared with the model read at its sensor.\n"
    );
    s.push_str("| output | sensor | named | decided by | phase error |\n|---|---|---|---|---|\n");
    for (o, port, d) in runs {
        let named: Vec<String> = d
            .verdict
            .effects
            .iter()
            .map(|e| {
                let p: Vec<String> = e
                    .parameters
                    .iter()
                    .map(|(k, v)| format!("{k} = {v:.4e}"))
                    .collect();
                if p.is_empty() {
                    e.kind.as_str().to_string()
                } else {
                    format!("{} ({})", e.kind.as_str(), p.join(", "))
                }
            })
            .collect();
        let phase = d.frequency_domain.as_ref().map_or("-".to_string(), |f| {
            format!(
                "{:.1} -> {:.1} deg",
                f.fit.before.rms_deg, f.fit.after.rms_deg
            )
        });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {phase} |",
            o.signal,
            location_name(*port),
            named.join(", "),
            d.verdict
                .decided_by
                .map_or("-".to_string(), |x| format!("{x:?}").to_lowercase())
        );
    }
    s.push('\n');
    if common.is_empty() {
        s.push_str("No effect is named by every output.\n\n");
    } else {
        for c in common {
            match c.parameter {
                Some(p) if !c.values.is_empty() => {
                    let values: Vec<String> = c.values.iter().map(|v| format!("{v:.4e}")).collect();
                    let _ = writeln!(
                        s,
                        "Every output names **{}** ({p} = {}; spread {:.1} %).\n",
                        c.kind.as_str(),
                        values.join(", "),
                        100.0 * c.spread
                    );
                }
                _ => {
                    let _ = writeln!(s, "Every output names **{}**.\n", c.kind.as_str());
                }
            }
        }
    }
    joint_markdown(&mut s, runs, joint);
    if let Some(p) = plot {
        let _ = writeln!(s, "![Bode plot: every output and its model after]({p})\n");
    }
    for (o, port, d) in runs {
        let section = diagnosis_markdown(
            &format!("{} at {}", o.signal, location_name(*port)),
            "",
            d,
            None,
        );
        // One heading level down: each output is a section of this report.
        for line in section.lines() {
            if line.starts_with('#') {
                s.push('#');
            }
            s.push_str(line);
            s.push('\n');
        }
    }
    s
}

/// The diagnosis of every output at once: its verdict with one parameter
/// set for the rig, which lines and samples it compared, and whether its
/// frequency domain is informative.
fn joint_markdown(
    s: &mut String,
    runs: &[(&SensorRecording, Port, RecordingDiagnosis)],
    joint: Option<&RecordingDiagnosis>,
) {
    s.push_str("## All outputs at once\n\n");
    let Some(j) = joint else {
        s.push_str(
            "Not diagnosed: an output has no informative band, or the outputs have fewer \
             lines than the model has parameters.\n\n",
        );
        return;
    };
    let bands: Vec<String> = runs
        .iter()
        .filter_map(|(o, _, d)| {
            d.band_hz
                .map(|(lo, hi)| format!("{} {lo:.4} to {hi:.4} Hz", o.signal))
        })
        .collect();
    let _ = write!(
        s,
        "One parameter set and one set of effects for every output together, each output read \
         at its own sensor: their FRFs ({}), each line weighted by its uncertainty",
        bands.join("; ")
    );
    match &j.time_domain {
        Some(t) => {
            let _ = write!(
                s,
                ", and their first {} samples, simulated once per trial and each output's error \
                 weighted by its own noise (the time-domain figures are the first output's).",
                t.samples
            );
        }
        None => s.push('.'),
    }
    let _ = writeln!(s, "\n\n{}\n", verdict_text(j));
    if let (Some(f), Some(Domain::Frequency)) = (&j.frequency_domain, j.verdict.decided_by) {
        let log_error = log_error_after(f);
        if log_error > INFORMATIVE_LOG_ERROR {
            let _ = writeln!(
                s,
                "Not informative: with one parameter set the model still misses the outputs' \
                 FRFs by {log_error:.2} nepers RMS (more than {INFORMATIVE_LOG_ERROR}), so what \
                 it names is no finding about the rig.\n"
            );
        }
    }
}
