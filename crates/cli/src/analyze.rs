//! `mms analyze`: the FRF types each model can show, with witnesses and
//! certificates (the paper's Tab. 3).

use crate::TableFormat3;
use mms::analysis::{analyze, ModelAnalysis, SearchLimits, Status};
use mms::Model;
use serde_json::json;
use std::collections::BTreeMap;
use std::fmt::Write;

/// Analyses of `models`, and for every possible type the other models (of
/// `peers`, analysed too) that can show it.
pub struct Table {
    pub models: Vec<Model>,
    pub analyses: Vec<ModelAnalysis>,
    /// (model id, type) -> ids of the other models with that type possible.
    pub similar: BTreeMap<(String, String), Vec<String>>,
}

pub fn table(models: &[Model], peers: &[Model]) -> Table {
    let limits = SearchLimits::default();
    let analyses: Vec<ModelAnalysis> = models.iter().map(|m| analyze(m, &limits)).collect();
    let peer_analyses: Vec<ModelAnalysis> = peers
        .iter()
        .map(|p| {
            analyses
                .iter()
                .find(|a| a.generic_id == p.id())
                .cloned()
                .unwrap_or_else(|| analyze(p, &limits))
        })
        .collect();
    let mut similar = BTreeMap::new();
    for a in &analyses {
        for t in a.possible() {
            let others: Vec<String> = peer_analyses
                .iter()
                .filter(|b| b.generic_id != a.generic_id)
                .filter(|b| b.possible().contains(&t))
                .map(|b| b.id.clone())
                .collect();
            similar.insert((a.id.clone(), t.to_string()), others);
        }
    }
    Table {
        models: models.to_vec(),
        analyses,
        similar,
    }
}

/// Tab. 5 of a model: determinable parameters and non-constant moment
/// invariants.
fn tab5(t: &Table, a: &ModelAnalysis) -> (usize, usize) {
    let m = t
        .models
        .iter()
        .find(|m| m.id() == a.generic_id)
        .expect("analysed model");
    let idf = mms::identifiability(m);
    (idf.determinable_parameters, idf.nonconstant_invariants)
}

fn status_count(a: &ModelAnalysis, s: Status) -> usize {
    a.types.iter().filter(|v| v.status == s).count()
}

fn similar_cell(t: &Table, a: &ModelAnalysis, sep: &str) -> String {
    a.possible()
        .iter()
        .map(|ty| {
            let others = &t.similar[&(a.id.clone(), ty.to_string())];
            if others.is_empty() {
                "-".to_string()
            } else {
                others.join(",")
            }
        })
        .collect::<Vec<_>>()
        .join(sep)
}

pub fn render(t: &Table, format: TableFormat3) -> Result<String, String> {
    let mut s = String::new();
    match format {
        TableFormat3::Json => {
            let models: Vec<serde_json::Value> = t
                .analyses
                .iter()
                .map(|a| {
                    let mut v = serde_json::to_value(a).map_err(|e| e.to_string())?;
                    let similar: Vec<serde_json::Value> = a
                        .possible()
                        .iter()
                        .map(|ty| {
                            json!({"type": ty.to_string(),
                                   "models": t.similar[&(a.id.clone(), ty.to_string())]})
                        })
                        .collect();
                    v["similar"] = json!(similar);
                    if let Some(m) = t.models.iter().find(|m| m.id() == a.generic_id) {
                        let idf = mms::identifiability(m);
                        v["determinable_parameters"] = json!(idf.determinable_parameters);
                        v["moment_invariants"] = json!(idf.nonconstant_invariants);
                    }
                    Ok(v)
                })
                .collect::<Result<_, String>>()?;
            s = serde_json::to_string_pretty(&json!({ "models": models }))
                .map_err(|e| e.to_string())?;
            s.push('\n');
        }
        TableFormat3::Table => {
            let _ = writeln!(
                s,
                "{:<16} {:<44} {:<40} {:>10} {:>7} {:>12} {:>8}",
                "ID",
                "Possible FRF types",
                "Pot. similar systems",
                "impossible",
                "unknown",
                "determinable",
                "moments"
            );
            for a in &t.analyses {
                let types: Vec<String> = a.possible().iter().map(|t| t.to_string()).collect();
                let (det, mom) = tab5(t, a);
                let _ = writeln!(
                    s,
                    "{:<16} {:<44} {:<40} {:>10} {:>7} {:>12} {:>8}",
                    a.id,
                    types.join(", "),
                    similar_cell(t, a, "; "),
                    status_count(a, Status::Impossible),
                    status_count(a, Status::Unknown),
                    det,
                    mom
                );
            }
            for a in &t.analyses {
                for u in a.unknown() {
                    let _ = writeln!(s, "unknown: {} {}", a.id, u);
                }
            }
        }
        TableFormat3::Md => {
            s.push_str("| ID | Possible FRF types | Pot. similar systems | Impossible (certified) | Unknown | Determinable parameters | Non-constant moment invariants |\n");
            s.push_str("|---|---|---|---|---|---|---|\n");
            for a in &t.analyses {
                let types: Vec<String> = a.possible().iter().map(|t| format!("`{t}`")).collect();
                let unknown: Vec<String> = a.unknown().iter().map(|t| format!("`{t}`")).collect();
                let (det, mom) = tab5(t, a);
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {det} | {mom} |",
                    a.id,
                    types.join(", "),
                    similar_cell(t, a, "; "),
                    status_count(a, Status::Impossible),
                    if unknown.is_empty() {
                        "0".to_string()
                    } else {
                        unknown.join(", ")
                    }
                );
            }
        }
        TableFormat3::Tex => {
            s.push_str("\\begin{tabular}{lllrr}\n\\hline\nID & Possible FRF types & Pot. similar systems & Impossible & Unknown \\\\\n\\hline\n");
            for a in &t.analyses {
                let types: Vec<String> = a
                    .possible()
                    .iter()
                    .map(|t| tex_type(&t.to_string()))
                    .collect();
                let _ = writeln!(
                    s,
                    "{} & {} & {} & {} & {} \\\\",
                    a.id.replace('*', "$^*$"),
                    types.join(", "),
                    similar_cell(t, a, "; "),
                    status_count(a, Status::Impossible),
                    status_count(a, Status::Unknown)
                );
            }
            s.push_str("\\hline\n\\end{tabular}\n");
        }
    }
    Ok(s)
}

/// `A^2RR (nm)` as LaTeX: `A$^2$RR (nm)`.
pub fn tex_type(t: &str) -> String {
    let mut out = String::new();
    let mut chars = t.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '^' {
            let mut k = String::new();
            while let Some(d) = chars.peek().filter(|d| d.is_ascii_digit()) {
                k.push(*d);
                chars.next();
            }
            let _ = write!(out, "$^{{{k}}}$");
        } else {
            out.push(c);
        }
    }
    out
}

pub fn run(models: &[Model], format: TableFormat3) -> Result<String, String> {
    let n = models.first().map(|m| m.n_masses()).unwrap_or(0);
    // Similar systems are looked up among all classes of the same size,
    // which is cheap up to 3 masses; beyond, among the models given.
    let peers = if n <= 3 && models.len() == 1 {
        crate::class_representatives(n)?
    } else {
        models.to_vec()
    };
    render(&table(models, &peers), format)
}
