//! `mms enumerate`: the counts of the paper's Tab. 1, the true renumbering
//! classes, and the list of models.

use crate::TableFormat;
use mms::{Model, Symmetry};
use serde_json::json;
use std::fmt::Write;

/// Everything `enumerate` reports for N masses.
pub struct Listing {
    pub counts: mms::Counts,
    pub report: mms::RedundancyReport,
    /// Degradation-free models with their class index (1-based).
    pub models: Vec<(Model, usize)>,
}

pub fn listing(n: usize) -> Result<Listing, String> {
    let err = |e: mms::ModelError| format!("--masses {n}: {e}");
    let counts = mms::counts(n).map_err(err)?;
    let report = mms::redundancy_report(n, Symmetry::Renumbering).map_err(err)?;
    let classes = mms::equivalence_classes(n, Symmetry::Renumbering).map_err(err)?;
    let mut models: Vec<(Model, usize)> = classes
        .iter()
        .enumerate()
        .flat_map(|(k, c)| c.iter().map(move |m| (*m, k + 1)))
        .collect();
    models.sort();
    Ok(Listing {
        counts,
        report,
        models,
    })
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn port(p: mms::Port) -> String {
    format!("{}-{}", p.plus, p.minus)
}

fn disagreement_text(l: &Listing, md: bool) -> String {
    let mut s = String::new();
    if l.report.rule3_is_exact() {
        let _ = writeln!(
            s,
            "The paper's rule (3) keeps exactly one model of every renumbering class."
        );
        return s;
    }
    let list = |ms: &[Model]| -> String {
        ms.iter()
            .map(|m| {
                if md {
                    format!("`{}`", m.name())
                } else {
                    m.name()
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let _ = writeln!(
        s,
        "The paper's rule (3) keeps {} models, but there are {} renumbering classes.",
        l.report.rule3_count, l.report.class_count
    );
    if !l.report.rule3_duplicates.is_empty() {
        let _ = writeln!(s, "Kept by rule (3) although renamings of each other:");
        for g in &l.report.rule3_duplicates {
            let _ = writeln!(s, "{} {}", if md { "-" } else { "  -" }, list(g));
        }
    }
    if !l.report.unrepresented.is_empty() {
        let _ = writeln!(s, "Classes of which rule (3) keeps no model:");
        for g in &l.report.unrepresented {
            let _ = writeln!(s, "{} {}", if md { "-" } else { "  -" }, list(g));
        }
    }
    s
}

pub fn run(n: usize, format: TableFormat) -> Result<String, String> {
    let l = listing(n)?;
    let c = &l.counts;
    Ok(match format {
        TableFormat::Json => {
            let models: Vec<_> = l
                .models
                .iter()
                .map(|(m, class)| {
                    json!({
                        "id": m.id(),
                        "paper_id": m.paper_label(),
                        "masses": m.n_masses(),
                        "gap": m.gap(),
                        "actuator": [m.actuator().plus, m.actuator().minus],
                        "sensor": [m.sensor().plus, m.sensor().minus],
                        "collocated": m.is_collocated(),
                        "paper_rule3": m.satisfies_rule3(),
                        "class": class,
                    })
                })
                .collect();
            let dup: Vec<Vec<String>> = l
                .report
                .rule3_duplicates
                .iter()
                .map(|g| g.iter().map(Model::id).collect())
                .collect();
            let unrep: Vec<Vec<String>> = l
                .report
                .unrepresented
                .iter()
                .map(|g| g.iter().map(Model::id).collect())
                .collect();
            let v = json!({
                "masses": n,
                "basic": c.basic,
                "degradation_free": c.degradation_free,
                "paper_rule3": c.rule3,
                "classes": c.classes,
                "classes_with_reciprocity": c.classes_with_reciprocity,
                "rule3_duplicates": dup,
                "rule3_unrepresented": unrep,
                "models": models,
            });
            serde_json::to_string_pretty(&v).map_err(|e| e.to_string())? + "\n"
        }
        TableFormat::Table | TableFormat::Md => {
            let md = format == TableFormat::Md;
            let mut s = String::new();
            let rows = [
                ("basic combinations, rule (1)", c.basic),
                ("degradation-free, rules (1) and (2)", c.degradation_free),
                ("paper's rule (3)", c.rule3),
                ("classes under renumbering of masses", c.classes),
                (
                    "classes, reciprocal pairs also merged",
                    c.classes_with_reciprocity,
                ),
            ];
            if md {
                let _ = writeln!(s, "## Models of {n} masses\n");
                let _ = writeln!(s, "| count | models |\n|---|---:|");
                for (k, v) in rows {
                    let _ = writeln!(s, "| {k} | {v} |");
                }
                let _ = writeln!(s);
            } else {
                let _ = writeln!(s, "Models of {n} masses");
                for (k, v) in rows {
                    let _ = writeln!(s, "  {k:<40} {v:>5}");
                }
            }
            let _ = writeln!(s);
            s.push_str(&disagreement_text(&l, md));
            let _ = writeln!(s);
            let header = [
                "ID",
                "generic ID",
                "gap",
                "actuator",
                "sensor",
                "collocated",
                "rule (3)",
                "class",
            ];
            let body: Vec<[String; 8]> = l
                .models
                .iter()
                .map(|(m, class)| {
                    [
                        m.paper_label().unwrap_or_else(|| "-".into()),
                        m.id(),
                        m.gap().to_string(),
                        port(m.actuator()),
                        port(m.sensor()),
                        yes(m.is_collocated()).into(),
                        yes(m.satisfies_rule3()).into(),
                        class.to_string(),
                    ]
                })
                .collect();
            if md {
                let _ = writeln!(s, "| {} |", header.join(" | "));
                let _ = writeln!(s, "|{}", "---|".repeat(header.len()));
                for r in &body {
                    let _ = writeln!(s, "| {} |", r.join(" | "));
                }
            } else {
                let mut w = header.map(str::len);
                for r in &body {
                    for (i, x) in r.iter().enumerate() {
                        w[i] = w[i].max(x.len());
                    }
                }
                let line = |cells: Vec<&str>| -> String {
                    cells
                        .iter()
                        .enumerate()
                        .map(|(i, x)| format!("{x:<width$}", width = w[i]))
                        .collect::<Vec<_>>()
                        .join("  ")
                        .trim_end()
                        .to_string()
                };
                let _ = writeln!(s, "{}", line(header.to_vec()));
                for r in &body {
                    let _ = writeln!(s, "{}", line(r.iter().map(String::as_str).collect()));
                }
            }
            s
        }
    })
}
