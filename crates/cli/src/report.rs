//! A command's result in every format (Markdown, one HTML page, JSON), to
//! stdout or with its figures and files into `--out DIR`; and `mms report`,
//! which joins the identification and the diagnosis of one recording into
//! one report.

use crate::diagnose::{DiagnoseArgs, LoopArgs, ModelSource, SelectArg};
use crate::identify::{IdentifyArgs, IdentifyFormat};
use crate::output::write_dir_atomic;
use crate::recording::RecordingArgs;
use mms::model_file::ModelFile;
use plot::Bode;
use rayon::prelude::*;
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;

/// Where a report's Markdown links its figures: nowhere (stdout, HTML,
/// JSON), or to `PREFIX NAME.svg` beside it in the output directory.
#[derive(Clone, Copy)]
pub struct Links {
    on: bool,
    prefix: &'static str,
}

impl Links {
    /// Links for a report of `format` written to `out` (if any), with the
    /// figures' file names starting with `prefix`.
    pub fn new(format: IdentifyFormat, out: Option<&Path>, prefix: &'static str) -> Links {
        Links {
            on: format == IdentifyFormat::Md && out.is_some(),
            prefix,
        }
    }

    /// The link to the figure `name` (its SVG), if the Markdown shows it.
    pub fn to(&self, name: &str) -> Option<String> {
        self.on.then(|| format!("{}.svg", self.file(name)))
    }

    /// The file name (without extension) of the figure `name`.
    pub fn file(&self, name: &str) -> String {
        format!("{}{name}", self.prefix)
    }
}

/// What one command found, ready for every format.
pub struct Outcome {
    /// The HTML page's title, e.g. "mms identify".
    pub title: &'static str,
    /// The report's verdict (in Markdown, before its first section), its
    /// figures linked as [`Links`] said.
    pub verdict: String,
    /// The report's sections, in Markdown.
    pub sections: String,
    pub json: Value,
    /// Each figure with its file name (without extension).
    pub figures: Vec<(String, Bode)>,
    /// Further files of the output directory (name, text), e.g. model files.
    pub files: Vec<(String, String)>,
    /// The fitted model a diagnosis can start from, with the sensors of a
    /// recording with several outputs.
    pub fitted: Option<(ModelFile, Vec<mms::Port>)>,
}

impl Outcome {
    /// An outcome whose Markdown report is `markdown`, with no files and
    /// no fitted model.
    pub fn new(
        title: &'static str,
        markdown: &str,
        json: Value,
        figures: Vec<(String, Bode)>,
    ) -> Outcome {
        let (verdict, sections) = split_verdict(markdown);
        Outcome {
            title,
            verdict: verdict.to_string(),
            sections: sections.to_string(),
            json,
            figures,
            files: Vec::new(),
            fitted: None,
        }
    }

    /// The HTML page of this outcome with its figures drawn.
    fn html_page(&self, interactive: &str, statics: &[&str]) -> String {
        html_page(
            self.title,
            &self.verdict,
            &self.sections,
            self.figures.len(),
            interactive,
            statics,
        )
    }

    /// The report's text in `format`.
    pub fn render(&self, format: IdentifyFormat) -> Result<String, String> {
        Ok(match format {
            IdentifyFormat::Md => format!("{}{}", self.verdict, self.sections),
            IdentifyFormat::Html => {
                // The interactive and the static figures side by side.
                let (interactive, statics) = rayon::join(
                    || interactive_figures(&self.figures),
                    || {
                        self.figures
                            .par_iter()
                            .map(|(_, f)| f.to_svg())
                            .collect::<Vec<_>>()
                    },
                );
                let statics: Vec<&str> = statics.iter().map(String::as_str).collect();
                self.html_page(&interactive, &statics)
            }
            IdentifyFormat::Json => {
                let mut s =
                    serde_json::to_string_pretty(&self.json).map_err(|e| format!("JSON: {e}"))?;
                s.push('\n');
                s
            }
        })
    }

    /// The report for stdout, or `None` once it is written with its
    /// figures and files into `out`: every figure as SVG and PNG, the
    /// files, then `report.{md,html,json}`, as one set.
    pub fn deliver(
        &self,
        format: IdentifyFormat,
        out: Option<&Path>,
    ) -> Result<Option<String>, String> {
        let Some(dir) = out else {
            return self.render(format).map(Some);
        };
        let ext = match format {
            IdentifyFormat::Md => "md",
            IdentifyFormat::Html => "html",
            IdentifyFormat::Json => "json",
        };
        // Every figure's SVG and PNG (the PNG's rasterising and deflate
        // take longest), beside the HTML page's interactive figures; the
        // page's static figures are the same SVGs.
        let (drawn, interactive): (Vec<(String, Vec<u8>)>, Option<String>) = rayon::join(
            || {
                self.figures
                    .par_iter()
                    .map(|(_, f)| rayon::join(|| f.to_svg(), || f.to_png()))
                    .collect()
            },
            || (format == IdentifyFormat::Html).then(|| interactive_figures(&self.figures)),
        );
        let report = match interactive {
            Some(interactive) => {
                let statics: Vec<&str> = drawn.iter().map(|(svg, _)| svg.as_str()).collect();
                self.html_page(&interactive, &statics)
            }
            None => self.render(format)?,
        };
        let mut files: Vec<(String, Vec<u8>)> = Vec::new();
        for ((name, _), (svg, png)) in self.figures.iter().zip(drawn) {
            files.push((format!("{name}.svg"), svg.into_bytes()));
            files.push((format!("{name}.png"), png));
        }
        for (name, text) in &self.files {
            files.push((name.clone(), text.clone().into_bytes()));
        }
        files.push((format!("report.{ext}"), report.into_bytes()));
        write_dir_atomic(dir, &files)?;
        Ok(None)
    }
}

/// One self-contained HTML page: the report's verdict (its Markdown
/// before the first section), the figures drawn interactively, the
/// sections, and the figures' SVGs as the static view.
/// `interactive` holds the figures' HTML ([`Bode::to_html`]), `statics`
/// their SVGs.
fn html_page(
    title: &str,
    verdict: &str,
    sections: &str,
    figures: usize,
    interactive: &str,
    statics: &[&str],
) -> String {
    let mut s = format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{title}</title>\n\
         <style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}\
         table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:2px 6px}}\
         code{{overflow-wrap:anywhere}}\
         .mms-readout{{font-size:0.85em;min-height:2.6em;color:#333}}\
         .mms-bode canvas{{cursor:crosshair}}</style>\n\
         </head><body>\n"
    );
    s.push_str(&markdown_to_html(verdict));
    let _ = write!(
        s,
        "<h2>Bode plot{}</h2>\n<p><small>Drag across a panel to zoom in frequency, \
         double-click to return; click a legend entry to hide or show its curve.</small></p>\n",
        if figures > 1 { "s" } else { "" }
    );
    s.push_str(interactive);
    s.push_str(&markdown_to_html(sections));
    s.push_str("<details><summary>Static figures (SVG)</summary>\n");
    statics.iter().for_each(|svg| s.push_str(svg));
    s.push_str("</details>\n</body></html>\n");
    s
}

/// The report's Markdown as HTML (CommonMark with tables, by
/// pulldown-cmark; raw HTML in the text is escaped, as the text comes from
/// file and variable names).
fn markdown_to_html(md: &str) -> String {
    use pulldown_cmark::{Event, Options, Parser};
    let events = Parser::new_ext(md, Options::ENABLE_TABLES).map(|e| match e {
        Event::Html(t) | Event::InlineHtml(t) => Event::Text(t),
        other => other,
    });
    let mut out = String::new();
    pulldown_cmark::html::push_html(&mut out, events);
    out
}

/// The figures drawn interactively, one `figure-K` element each; the
/// last one carries the script.
fn interactive_figures(figures: &[(String, Bode)]) -> String {
    (figures.iter().enumerate())
        .map(|(k, (_, f))| f.to_html(&format!("figure-{}", k + 1), k + 1 == figures.len()))
        .collect()
}

/// A report's verdict (everything before its first section) and its
/// sections.
pub fn split_verdict(md: &str) -> (&str, &str) {
    let split = md.find("\n## ").map_or(md.len(), |i| i + 1);
    md.split_at(split)
}

/// Every heading one level lower (`#` becomes `##`), outside code blocks:
/// a command's report as a part of a joined one.
fn demote(md: &str) -> String {
    let mut s = String::with_capacity(md.len() + 64);
    let mut fenced = false;
    for line in md.split_inclusive('\n') {
        if line.starts_with("```") {
            fenced = !fenced;
        }
        if !fenced && line.starts_with('#') {
            s.push('#');
        }
        s.push_str(line);
    }
    s
}

/// The version of `mms report`'s JSON; the identification and diagnosis
/// inside it are those of `mms identify` and `mms diagnose`.
pub const JSON_VERSION: u32 = 1;

/// A report's verdict as part of a joined one: its headings demoted and
/// its title (the first line, if a heading) replaced by `heading`.
fn retitled(verdict: &str, heading: &str) -> String {
    let rest = match verdict.split_once('\n') {
        Some((first, rest)) if first.starts_with("# ") => rest,
        _ => verdict,
    };
    format!("{heading}\n{}", demote(rest))
}

/// The arguments of `mms report`: those of `mms identify` and `mms
/// diagnose` that concern one recording.
pub struct ReportArgs<'a> {
    pub recording: &'a RecordingArgs,
    pub masses: Option<usize>,
    pub fit_gain: bool,
    pub band: Option<(f64, f64)>,
    /// The model to diagnose; `None`: the identification's best fit.
    pub model: Option<&'a ModelSource>,
    pub select: SelectArg,
    pub tolerance: f64,
    pub closed_loop: Option<LoopArgs>,
    pub format: IdentifyFormat,
    pub out: Option<&'a Path>,
}

/// `mms report`: identifies the recording, diagnoses it with the given
/// model (at the same time) or else with the identification's best fit,
/// and joins both: the two verdicts first, then the figures, then each
/// one's sections.
pub fn run(args: &ReportArgs) -> Result<Option<String>, String> {
    let name = args.recording.path()?.display().to_string();
    let identify_args = IdentifyArgs {
        recording: args.recording,
        masses: args.masses,
        fit_gain: args.fit_gain,
        band: args.band,
        operating_points: &[],
        format: args.format,
        out: args.out,
    };
    let identify_links = Links::new(args.format, args.out, "identify-");
    let diagnose_links = Links::new(args.format, args.out, "diagnose-");
    let (identified, diagnosed) = match args.model {
        // Neither needs the other: both at once.
        Some(model) => {
            let (i, d) = rayon::join(
                || crate::identify::outcome(&identify_args, identify_links),
                || crate::diagnose::outcome(&diagnose_args(args, model), diagnose_links),
            );
            (i?, d?)
        }
        None => {
            let i = crate::identify::outcome(&identify_args, identify_links)?;
            let (model, sensors) = i.fitted.clone().ok_or_else(|| {
                format!("{name}: no structure was fitted, so there is no model to diagnose; give --model")
            })?;
            let source = ModelSource::Fitted(Box::new(model), sensors);
            let d = crate::diagnose::outcome(&diagnose_args(args, &source), diagnose_links)?;
            (i, d)
        }
    };
    join(&name, identified, diagnosed).deliver(args.format, args.out)
}

/// The diagnosis of `mms report`'s recording with `model`.
fn diagnose_args<'a>(args: &'a ReportArgs<'a>, model: &'a ModelSource) -> DiagnoseArgs<'a> {
    DiagnoseArgs {
        recording: args.recording,
        model: Some(model),
        levels: &[],
        validate: None,
        operating_points: &[],
        select: args.select,
        tolerance: args.tolerance,
        band: args.band,
        closed_loop: args.closed_loop.clone(),
        format: args.format,
        out: args.out,
    }
}

/// One report of an identification and a diagnosis of the same recording:
/// both verdicts, then the sections of each.
fn join(name: &str, identified: Outcome, diagnosed: Outcome) -> Outcome {
    // The recording is named once: its file in the title, its path below.
    let file = Path::new(name)
        .file_name()
        .map_or(name.into(), |f| f.to_string_lossy());
    let mut verdict = format!("# Report on `{file}`\n\nRecording: `{name}`.\n\n");
    verdict.push_str(&retitled(&identified.verdict, "## Identification"));
    verdict.push_str(&retitled(&diagnosed.verdict, "## Diagnosis"));
    let mut sections = String::from("## Identification in detail\n\n");
    sections.push_str(&demote(&identified.sections));
    sections.push_str("\n## Diagnosis in detail\n\n");
    sections.push_str(&demote(&diagnosed.sections));
    let json = json!({
        "version": JSON_VERSION,
        "recording": name,
        "identification": identified.json,
        "diagnosis": diagnosed.json,
    });
    let mut figures = identified.figures;
    figures.extend(diagnosed.figures);
    let mut files = identified.files;
    files.extend(diagnosed.files);
    Outcome {
        title: "mms report",
        verdict,
        sections,
        json,
        figures,
        files,
        fitted: identified.fitted,
    }
}

#[cfg(test)]
mod tests {
    use super::{demote, markdown_to_html, split_verdict};

    /// Headings go one level down, the lines of a code block do not,
    /// whatever they start with.
    #[test]
    fn demote_skips_code_blocks() {
        let md = "# A\n\ntext # not a heading\n## B\n```toml\n# comment\n```\n### C\n";
        assert_eq!(
            demote(md),
            "## A\n\ntext # not a heading\n### B\n```toml\n# comment\n```\n#### C\n"
        );
    }

    /// The verdict ends where the first section starts; a report without
    /// sections is all verdict.
    #[test]
    fn verdict_is_what_precedes_the_first_section() {
        assert_eq!(
            split_verdict("# T\n\nv\n## S\nx\n"),
            ("# T\n\nv\n", "## S\nx\n")
        );
        assert_eq!(split_verdict("# T\n\nv\n"), ("# T\n\nv\n", ""));
    }

    /// Tables, emphasis, code and lists become their HTML elements, and
    /// text that looks like HTML stays text.
    #[test]
    fn report_markdown_becomes_html() {
        let md = "# Report\n\n**type** `C`, for <script>x</script>\n\n\
                  | structure | m1 |\n|---|---:|\n| A1 | 1e-3 |\n\n- one\n- two\n";
        let html = markdown_to_html(md);
        assert!(html.contains("<h1>Report</h1>"), "{html}");
        assert!(html.contains("<strong>type</strong>"), "{html}");
        assert!(html.contains("<code>C</code>"), "{html}");
        assert!(html.contains("&lt;script&gt;"), "{html}");
        assert!(!html.contains("<script>"), "{html}");
        assert!(html.contains("<th>structure</th>"), "{html}");
        assert!(
            html.contains("<td style=\"text-align: right\">1e-3</td>"),
            "{html}"
        );
        assert!(!html.contains("---"), "{html}");
        assert!(html.contains("<li>two</li>"), "{html}");
    }
}
