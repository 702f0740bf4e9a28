//! `mms diagnose`: where a model and a recording differ, which physics the
//! model left out, and how much adding it improves the fit.

use crate::identify::IdentifyFormat;
use crate::recording::RecordingArgs;
use ident::diagnose::{diagnose, DiagnoseOptions, Diagnosis, EffectKind};
use mms::model_file::ModelFile;
use mms::response::ChainResponse;
use plot::{Bode, Style};
use std::fmt::Write as _;
use std::path::Path;

/// Options of `mms diagnose` beyond the recording.
pub struct DiagnoseArgs<'a> {
    pub recording: &'a RecordingArgs,
    pub model: &'a Path,
    pub tolerance: f64,
    pub band: Option<(f64, f64)>,
    pub format: IdentifyFormat,
    pub out: Option<&'a Path>,
}

/// Runs the diagnosis; returns the report for stdout when no `--out`
/// directory is given.
pub fn run(args: &DiagnoseArgs) -> Result<Option<String>, String> {
    let rec = args.recording.read()?;
    let text = std::fs::read_to_string(args.model)
        .map_err(|e| format!("{}: cannot read: {e}", args.model.display()))?;
    let model = ModelFile::parse(&text).map_err(|e| match e.line {
        Some(l) => format!("{}:{l}: {}", args.model.display(), e.message),
        None => format!("{}: {}", args.model.display(), e.message),
    })?;
    if !(args.tolerance.is_finite() && args.tolerance > 0.0 && args.tolerance < 10.0) {
        return Err(format!(
            "--tolerance {}: expected a fraction such as 0.2 (0 < t < 10)",
            args.tolerance
        ));
    }
    let options = DiagnoseOptions {
        tolerance: args.tolerance,
        ..DiagnoseOptions::default()
    };
    let name = args.recording.recording.display().to_string();
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
    let d = diagnose(&data, &model, &options).map_err(|e| format!("{name}: {e}"))?;
    let plot = bode(&data, &model, &d);
    let report = match args.format {
        IdentifyFormat::Json => {
            let mut s = serde_json::to_string_pretty(&d).map_err(|e| format!("JSON: {e}"))?;
            s.push('\n');
            s
        }
        IdentifyFormat::Md => markdown(&name, &d, args.out.map(|_| "bode.svg")),
        IdentifyFormat::Html => {
            crate::identify::html_page("mms diagnose", &markdown(&name, &d, None), &plot.to_svg())
        }
    };
    let Some(dir) = args.out else {
        return Ok(Some(report));
    };
    crate::identify::write_report_dir(
        dir,
        args.format,
        &plot,
        &[("model_after.toml", d.model_after.to_toml())],
        &report,
    )?;
    Ok(None)
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

fn markdown(name: &str, d: &Diagnosis, plot: Option<&str>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Diagnosis of `{name}`\n");
    let best = d.effects.first();
    let verdict = match best {
        Some(e) if e.kind != EffectKind::None => {
            let params: Vec<String> = e
                .parameters
                .iter()
                .map(|(k, v)| format!("{k} = {v:.4e}"))
                .collect();
            let bands: Vec<String> = d
                .mismatch
                .iter()
                .map(|b| format!("{:.4} and {:.4} Hz", b.f_lo_hz, b.f_hi_hz))
                .collect();
            format!(
                "The recording differs from the model{}; most likely cause: **{}** ({}); after adding it \
                 the error drops from {:.3} dB / {:.2} deg to {:.3} dB / {:.2} deg RMS.",
                if bands.is_empty() {
                    String::new()
                } else {
                    format!(" between {}", bands.join(", "))
                },
                e.kind.as_str(),
                params.join(", "),
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
    s.push_str("\n## Effects\n\n| kind | parameters | score | evidence |\n|---|---|---:|---|\n");
    for e in d.effects.iter().chain(&d.rejected) {
        let params: Vec<String> = e
            .parameters
            .iter()
            .map(|(k, v)| format!("{k} = {v:.4e}"))
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {} |",
            e.kind.as_str(),
            params.join(", "),
            e.score,
            e.evidence
        );
    }
    if !d.calibration.is_empty() {
        s.push_str("\n## Calibration\n\n");
        for c in &d.calibration {
            let _ = writeln!(s, "- {c}");
        }
    }
    s
}
