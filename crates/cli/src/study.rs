//! `mms study`: the study of N-mass models as one report (Markdown or LaTeX):
//! Tab. 1, the models, every transfer function, and the algebra behind the
//! FRF types (pole-zero cancellation and double-root conditions).

use crate::ReportFormat;
use mms::render::{render_poly, RenderOptions};
use poly::Poly;
use std::fmt::Write;

/// Tab. 1 of the paper as printed (N = 1..5): basic, degradation-free, rule (3).
const PAPER_TAB1: [(usize, usize, usize, usize); 5] = [
    (1, 1, 1, 1),
    (2, 8, 5, 3),
    (3, 34, 17, 11),
    (4, 104, 50, 29),
    (5, 259, 129, 73),
];

struct Doc {
    tex: bool,
    s: String,
}

impl Doc {
    fn heading(&mut self, level: usize, title: &str) {
        if self.tex {
            let cmd = match level {
                1 => "section",
                2 => "subsection",
                _ => "subsubsection",
            };
            let _ = writeln!(self.s, "\\{cmd}*{{{}}}\n", tex_escape(title));
        } else {
            let _ = writeln!(self.s, "{} {title}\n", "#".repeat(level + 1));
        }
    }

    fn para(&mut self, text: &str) {
        let t = if self.tex {
            tex_escape(text)
        } else {
            text.to_string()
        };
        let _ = writeln!(self.s, "{t}\n");
    }

    fn table(&mut self, header: &[&str], rows: &[Vec<String>]) {
        if self.tex {
            let _ = writeln!(
                self.s,
                "\\begin{{tabular}}{{{}}}\n\\hline",
                "l".repeat(header.len())
            );
            let h: Vec<String> = header.iter().map(|x| tex_escape(x)).collect();
            let _ = writeln!(self.s, "{} \\\\ \\hline", h.join(" & "));
            for r in rows {
                let r: Vec<String> = r.iter().map(|x| tex_escape(x)).collect();
                let _ = writeln!(self.s, "{} \\\\", r.join(" & "));
            }
            let _ = writeln!(self.s, "\\hline\n\\end{{tabular}}\n");
        } else {
            let _ = writeln!(self.s, "| {} |", header.join(" | "));
            let _ = writeln!(self.s, "|{}", "---|".repeat(header.len()));
            for r in rows {
                let _ = writeln!(self.s, "| {} |", r.join(" | "));
            }
            self.s.push('\n');
        }
    }

    /// A display formula given as LaTeX.
    fn math(&mut self, latex: &str) {
        if self.tex {
            let _ = writeln!(self.s, "\\[ {latex} \\]\n");
        } else {
            let _ = writeln!(self.s, "$$ {latex} $$\n");
        }
    }
}

fn tex_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '_' | '%' | '&' | '#' | '$' | '{' | '}' => {
                out.push('\\');
                out.push(c);
            }
            '*' => out.push_str("$^*$"),
            '`' => {}
            _ => out.push(c),
        }
    }
    out
}

fn factored_latex(p: &Poly, opts: &RenderOptions) -> String {
    if p.is_zero() {
        return "0".into();
    }
    let f = poly::factor(p);
    let mut parts: Vec<String> = Vec::new();
    let minus_one = poly::Rat::from(-1);
    let sign = if f.unit == minus_one { "-" } else { "" };
    if !f.unit.is_one() && f.unit != minus_one {
        parts.push(render_poly(&Poly::constant(f.unit.clone()), "Omega", opts));
    }
    for (q, k) in &f.factors {
        let body = render_poly(q, "Omega", opts);
        let already = body.starts_with(r"\left(") && body.ends_with(r"\right)");
        let wrapped = if q.num_terms() > 1 && !already {
            format!(r"\left({body}\right)")
        } else {
            body
        };
        parts.push(if *k > 1 {
            format!("{wrapped}^{{{k}}}")
        } else {
            wrapped
        });
    }
    if parts.is_empty() {
        return format!("{sign}1");
    }
    format!("{sign}{}", parts.join(r" \cdot "))
}

/// The paper's Tab. 3 ("Possible FRF types"), as printed.
const PAPER_TAB3: [(&str, &[&str]); 11] = [
    ("A1", &["ARAR"]),
    ("A2", &["ARR", "RAR", "R"]),
    ("A3", &["RR"]),
    ("A4", &["ARAR", "AR"]),
    ("A5", &["ARR", "RAR", "R"]),
    ("B1", &["ARAR", "AR"]),
    (
        "B2",
        &[
            "RRAA", "AARR", "RA", "ARRA", "RR (nm)", "AR", "A^2RR", "RRA^2", "C",
        ],
    ),
    ("C1", &["ARAR"]),
    ("C2", &["ARRA"]),
    ("C3", &["ARAR"]),
    ("C4", &["ARRA"]),
];

/// The paper's Tab. 5: (ID, determinable parameters, non-constant moment
/// invariants), as printed.
const PAPER_TAB5: [(&str, usize, usize); 11] = [
    ("A1", 5, 5),
    ("A2", 4, 4),
    ("A3", 3, 3),
    ("A4", 5, 5),
    ("A5", 4, 4),
    ("B1", 5, 5),
    ("B2", 4, 5),
    ("C1", 5, 5),
    ("C2", 4, 5),
    ("C3", 5, 5),
    ("C4", 4, 5),
];

/// Pushes the headings of an explanation two levels down (Markdown) or
/// keeps LaTeX sectioning one level down.
fn demote(text: &str, tex: bool) -> String {
    if tex {
        text.replace("\\section*", "\\subsubsection*")
            .replace("\\subsection*", "\\paragraph*")
    } else {
        text.lines()
            .map(|l| {
                if l.starts_with('#') {
                    format!("##{l}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
            + "\n"
    }
}

pub fn run(n: usize, format: ReportFormat) -> Result<String, String> {
    let listing = crate::enumerate::listing(n)?;
    let models = crate::class_representatives(n)?;
    let tex = format == ReportFormat::Tex;
    let mut d = Doc {
        tex,
        s: String::new(),
    };
    if tex {
        d.s.push_str(
            "\\documentclass{article}\n\\usepackage{amsmath}\n\\usepackage[margin=2cm]{geometry}\n\
             \\allowdisplaybreaks\n\\begin{document}\n",
        );
        let _ = writeln!(
            d.s,
            "\\title{{Multiple-mass models of {n} masses}}\n\\date{{}}\n\\maketitle\n"
        );
    } else {
        let _ = writeln!(d.s, "# Multiple-mass models of {n} masses\n");
    }
    d.para(&format!(
        "Generated by mms {}. Every polynomial below was derived exactly (rational arithmetic) \
         from the chain graph; nothing was typed in by hand.",
        env!("CARGO_PKG_VERSION")
    ));

    // Tab. 1
    d.heading(1, "Number of models (the paper's Tab. 1)");
    d.para(
        "Rule (1) places the gap, actuator and sensor; rule (2) drops degraded models (masses not \
         excited or not observed); the paper's rule (3) is meant to drop renamings. The last \
         columns count the true classes under renumbering of the masses, and with reciprocal \
         pairs (actuator and sensor swapped) merged as well.",
    );
    let mut rows = Vec::new();
    for &(k, pb, pd, p3) in &PAPER_TAB1 {
        let c = mms::counts(k).map_err(|e| e.to_string())?;
        let mark = |ours: usize, paper: usize| {
            if ours == paper {
                ours.to_string()
            } else {
                format!("{ours} (paper: {paper})")
            }
        };
        rows.push(vec![
            k.to_string(),
            mark(c.basic, pb),
            mark(c.degradation_free, pd),
            mark(c.rule3, p3),
            c.classes.to_string(),
            c.classes_with_reciprocity.to_string(),
        ]);
    }
    d.table(
        &[
            "masses",
            "basic",
            "degradation-free",
            "rule (3)",
            "classes",
            "classes with reciprocity",
        ],
        &rows,
    );
    for k in 1..=5 {
        let r = mms::redundancy_report(k, mms::Symmetry::Renumbering).map_err(|e| e.to_string())?;
        if !r.rule3_is_exact() {
            let dup: Vec<String> = r
                .rule3_duplicates
                .iter()
                .map(|g| g.iter().map(|m| m.name()).collect::<Vec<_>>().join(" = "))
                .collect();
            let unrep: Vec<String> = r
                .unrepresented
                .iter()
                .map(|g| g.iter().map(|m| m.name()).collect::<Vec<_>>().join(" = "))
                .collect();
            let mut t = format!(
                "{k} masses: rule (3) keeps {} models for {} classes.",
                r.rule3_count, r.class_count
            );
            if !dup.is_empty() {
                let _ = write!(t, " Renamings kept twice: {}.", dup.join("; "));
            }
            if !unrep.is_empty() {
                let _ = write!(t, " Classes with no model kept: {}.", unrep.join("; "));
            }
            d.para(&t);
        }
    }

    // Models
    d.heading(
        1,
        &format!("The {} model classes of {n} masses", models.len()),
    );
    let rows: Vec<Vec<String>> = models
        .iter()
        .map(|m| {
            let cls = listing
                .models
                .iter()
                .filter(|(x, _)| {
                    x.canonical(mms::Symmetry::Renumbering)
                        == m.canonical(mms::Symmetry::Renumbering)
                })
                .map(|(x, _)| x.id())
                .filter(|x| *x != m.id())
                .collect::<Vec<_>>();
            vec![
                m.paper_label().unwrap_or_else(|| "-".into()),
                format!("`{}`", m.id()),
                m.gap().to_string(),
                format!("{}-{}", m.actuator().plus, m.actuator().minus),
                format!("{}-{}", m.sensor().plus, m.sensor().minus),
                if m.is_collocated() { "yes" } else { "no" }.into(),
                if cls.is_empty() {
                    "-".into()
                } else {
                    cls.join(", ")
                },
            ]
        })
        .collect();
    d.table(
        &[
            "ID",
            "generic ID",
            "gap",
            "actuator",
            "sensor",
            "collocated",
            "renamings",
        ],
        &rows,
    );

    // Tab. 3
    let table = crate::analyze::table(&models, &models);
    d.heading(1, "FRF types (the paper's Tab. 3)");
    d.para(
        "For every model, every a-priori candidate type of the undamped TF (orders of \
         antiresonances A and resonances R, coincident roots A^k/R^k, pole-zero cancellation, \
         zeros off the positive axis (nm), constant C) is decided: possible with an exact \
         rational witness, or impossible with a certificate that `mms check` re-verifies \
         independently. `mms prove ID TYPE` writes out any single verdict.",
    );
    let mut rows = Vec::new();
    for a in &table.analyses {
        let types: Vec<String> = a.possible().iter().map(|t| t.to_string()).collect();
        let similar: Vec<String> = a
            .possible()
            .iter()
            .map(|t| {
                let o = &table.similar[&(a.id.clone(), t.to_string())];
                if o.is_empty() {
                    "-".to_string()
                } else {
                    o.join(",")
                }
            })
            .collect();
        let paper = PAPER_TAB3
            .iter()
            .find(|(id, _)| *id == a.id)
            .map(|(_, t)| *t);
        let agrees = match paper {
            Some(p) => {
                let mut x: Vec<&str> = p.to_vec();
                let mut y: Vec<&str> = types.iter().map(String::as_str).collect();
                x.sort();
                y.sort();
                if x == y {
                    "yes".to_string()
                } else {
                    format!("no (paper: {})", p.join(", "))
                }
            }
            None => "-".to_string(),
        };
        rows.push(vec![
            a.id.clone(),
            types.join(", "),
            similar.join("; "),
            a.types
                .iter()
                .filter(|v| v.status == mms::analysis::Status::Impossible)
                .count()
                .to_string(),
            a.unknown().len().to_string(),
            agrees,
        ]);
    }
    d.table(
        &[
            "ID",
            "possible FRF types",
            "pot. similar systems",
            "impossible (certified)",
            "unknown",
            "as printed",
        ],
        &rows,
    );
    d.heading(2, "Witnesses");
    let mut rows = Vec::new();
    for a in &table.analyses {
        for v in a
            .types
            .iter()
            .filter(|v| v.status == mms::analysis::Status::Possible)
        {
            let w = v.witness.as_ref().map(|w| {
                w.iter()
                    .map(|(k, x)| format!("{k}={x}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            });
            rows.push(vec![
                a.id.clone(),
                v.frf_type.to_string(),
                w.unwrap_or_default(),
            ]);
        }
    }
    d.table(&["ID", "type", "witness (exact parameters)"], &rows);
    d.heading(2, "Proofs");
    d.para(
        "Below, the proofs of the impossible orderings that the paper argues by hand \
         (Sec. 4.3) or leaves open, written out from the certificates. The remaining \
         impossible candidates follow from counting (resonances, multiplicities, Descartes' \
         rule) or from collocation; every certificate is in `mms analyze --format json`.",
    );
    let fmt = if tex {
        mms::analysis::ExplainFormat::Latex
    } else {
        mms::analysis::ExplainFormat::Markdown
    };
    for a in &table.analyses {
        for v in &a.types {
            let Some(c) = &v.certificate else { continue };
            let interesting = matches!(
                c.open,
                mms::analysis::OpenProof::SignConditions { .. }
                    | mms::analysis::OpenProof::Regions { var: Some(_), .. }
            ) && v.frf_type.tokens.len() as u32 >= a.denominator.degree("Omega");
            if interesting {
                if let Some(text) = mms::analysis::explain(a, &v.frf_type, fmt) {
                    d.s.push_str(&demote(&text, tex));
                }
            }
        }
    }

    d.heading(1, "Determinable parameters (the paper's Tab. 5)");
    d.para(
        "Determinable parameters: the generic rank of the Jacobian of the moment invariants \
         (the TF coefficients divided by the leading denominator coefficient) with respect to \
         the parameters; proven exactly (counting bound, scaling symmetries, or exact \
         elimination over the rational functions). Moment invariants: how many of them are \
         not identically constant.",
    );
    let mut rows = Vec::new();
    for m in &models {
        let idf = mms::identifiability(m);
        let paper = PAPER_TAB5.iter().find(|(id, ..)| Some(*id) == m.paper_id());
        let mark = |ours: usize, theirs: Option<usize>| match theirs {
            Some(p) if p != ours => format!("{ours} (paper: {p})"),
            _ => ours.to_string(),
        };
        rows.push(vec![
            m.name(),
            idf.parameters.len().to_string(),
            mark(idf.determinable_parameters, paper.map(|p| p.1)),
            mark(idf.nonconstant_invariants, paper.map(|p| p.2)),
            format!("{:?}", idf.certificate),
        ]);
    }
    d.table(
        &[
            "ID",
            "parameters",
            "determinable",
            "non-constant moment invariants",
            "proof",
        ],
        &rows,
    );
    let groups = mms::structural_equivalences(&models);
    let mut lines = Vec::new();
    for g in groups.iter().filter(|g| !g.members.is_empty()) {
        let names: Vec<String> = g.models().iter().map(|m| m.name()).collect();
        lines.push(names.join(" ~ "));
    }
    if !lines.is_empty() {
        d.para(&format!(
            "Structurally equivalent groups: {}.",
            lines.join("; ")
        ));
    }

    // Derivations
    d.heading(1, "Transfer functions");
    d.para(
        "Undamped inertance (force to acceleration) G = Num/Den in Omega = w^2 = -s^2, with the \
         rigid-body factor removed; receptance is -Num/(Omega Den). Abbreviations as in the \
         paper: m_{1.2} = m1 m2, m_{1+2} = m1 + m2.",
    );
    let latex = RenderOptions::latex();
    for m in &models {
        let tf = m.undamped_tf();
        d.heading(
            2,
            &format!("{} ({})", m.paper_label().unwrap_or_else(|| m.id()), m.id()),
        );
        let a = m.actuator();
        let se = m.sensor();
        d.para(&format!(
            "Gap {}, actuator {}-{}, sensor {}-{}{}.",
            m.gap(),
            a.plus,
            a.minus,
            se.plus,
            se.minus,
            if m.is_collocated() {
                ", collocated"
            } else {
                ""
            }
        ));
        d.math(&format!(
            r"\mathrm{{Num}} = {}",
            render_poly(&tf.num, "Omega", &latex)
        ));
        d.math(&format!(
            r"\mathrm{{Den}} = {}",
            render_poly(&tf.den, "Omega", &latex)
        ));
        let res = poly::resultant(&tf.num, &tf.den, "Omega");
        d.para("Resultant (zero exactly where a pole and a zero coincide, i.e. pole-zero cancellation):");
        d.math(&format!(
            r"\mathrm{{Res}}_\Omega(\mathrm{{Num}}, \mathrm{{Den}}) = {}",
            factored_latex(&res, &latex)
        ));
        if tf.num.degree("Omega") >= 2 {
            d.para("Discriminant of the numerator (zero where two zeros coincide):");
            d.math(&format!(
                r"\mathrm{{Disc}}_\Omega(\mathrm{{Num}}) = {}",
                factored_latex(&poly::discriminant(&tf.num, "Omega"), &latex)
            ));
        }
        if tf.den.degree("Omega") >= 2 {
            d.para("Discriminant of the denominator (zero where two poles coincide):");
            d.math(&format!(
                r"\mathrm{{Disc}}_\Omega(\mathrm{{Den}}) = {}",
                factored_latex(&poly::discriminant(&tf.den, "Omega"), &latex)
            ));
        }
    }
    if tex {
        d.s.push_str("\\end{document}\n");
    }
    Ok(d.s)
}
