//! `mms derive`: symbolic transfer functions in text, JSON, Markdown, LaTeX.

use crate::DeriveFormat;
use mms::render::{render_poly, RenderOptions};
use mms::{Model, Output};
use poly::Poly;
use serde_json::json;
use std::fmt::Write;

/// One derived transfer function, as numerator and denominator polynomials
/// of the full TF (sign and powers of Omega folded in; `s_power` is an
/// extra factor s^s_power that Omega cannot express).
pub struct Derived {
    pub model: Model,
    pub var: &'static str,
    pub numerator: Poly,
    pub denominator: Poly,
    pub s_power: u32,
    /// The TF as one rendered fraction, per format.
    tf: TfKind,
}

enum TfKind {
    Undamped(mms::OmegaTf),
    Damped(mms::DampedTf),
}

impl TfKind {
    fn render(&self, opts: &RenderOptions) -> String {
        match self {
            TfKind::Undamped(t) => t.render(opts),
            TfKind::Damped(t) => t.render(opts),
        }
    }
}

pub fn derive(model: &Model, output: Output, damped: bool) -> Derived {
    if damped {
        let tf = model.damped_tf(output);
        Derived {
            model: *model,
            var: "s",
            numerator: tf.num.clone(),
            denominator: tf.den.clone(),
            s_power: 0,
            tf: TfKind::Damped(tf),
        }
    } else {
        let tf = model.undamped_tf().output(output);
        let mut num = tf.num.clone();
        if tf.sign < 0 {
            num = -num;
        }
        let mut den = tf.den.clone();
        if tf.omega_power < 0 {
            den = den.mul_var_pow("Omega", (-tf.omega_power) as u32);
        }
        Derived {
            model: *model,
            var: "Omega",
            numerator: num,
            denominator: den,
            s_power: tf.s_power,
            tf: TfKind::Undamped(tf),
        }
    }
}

fn output_name(o: Output, damped: bool) -> String {
    let what = match o {
        Output::Position => "position (receptance)",
        Output::Velocity => "velocity (mobility)",
        Output::Acceleration => "acceleration (inertance)",
    };
    if damped {
        format!("{what}, damped, in s")
    } else {
        format!("{what}, undamped, in Omega = w^2 = -s^2")
    }
}

fn header(m: &Model) -> String {
    let a = m.actuator();
    let s = m.sensor();
    format!(
        "gap {}, actuator {}-{}, sensor {}-{}{}",
        m.gap(),
        a.plus,
        a.minus,
        s.plus,
        s.minus,
        if m.is_collocated() {
            ", collocated"
        } else {
            ""
        }
    )
}

pub fn run(
    models: &[Model],
    format: DeriveFormat,
    output: Output,
    damped: bool,
    abbreviate: bool,
) -> Result<String, String> {
    let items: Vec<Derived> = models.iter().map(|m| derive(m, output, damped)).collect();
    let text_opts = RenderOptions::text().with_abbreviations(abbreviate);
    let mut s = String::new();
    match format {
        DeriveFormat::Json => {
            let arr: Vec<_> = items
                .iter()
                .map(|d| {
                    let m = &d.model;
                    json!({
                        "id": m.name(),
                        "generic_id": m.id(),
                        "masses": m.n_masses(),
                        "gap": m.gap(),
                        "actuator": [m.actuator().plus, m.actuator().minus],
                        "sensor": [m.sensor().plus, m.sensor().minus],
                        "collocated": m.is_collocated(),
                        "output": output.as_str(),
                        "damped": damped,
                        "variable": d.var,
                        "s_power": d.s_power,
                        "numerator": render_poly(&d.numerator, d.var, &text_opts),
                        "denominator": render_poly(&d.denominator, d.var, &text_opts),
                    })
                })
                .collect();
            s = serde_json::to_string_pretty(&json!({ "models": arr }))
                .map_err(|e| e.to_string())?;
            s.push('\n');
        }
        DeriveFormat::Text => {
            for d in &items {
                let m = &d.model;
                let _ = writeln!(
                    s,
                    "{}  {}  {}",
                    m.paper_label().unwrap_or_else(|| m.id()),
                    m.id(),
                    header(m)
                );
                let _ = writeln!(s, "  {}", output_name(output, damped));
                let _ = writeln!(s, "  G   = {}", d.tf.render(&text_opts));
                let _ = writeln!(
                    s,
                    "  Num = {}",
                    render_poly(&d.numerator, d.var, &text_opts)
                );
                let _ = writeln!(
                    s,
                    "  Den = {}",
                    render_poly(&d.denominator, d.var, &text_opts)
                );
                if d.s_power > 0 {
                    let _ = writeln!(s, "  (times s^{})", d.s_power);
                }
                s.push('\n');
            }
        }
        DeriveFormat::Md => {
            let opts = RenderOptions::markdown().with_abbreviations(abbreviate);
            let _ = writeln!(
                s,
                "## Transfer functions: {}\n",
                output_name(output, damped)
            );
            for d in &items {
                let m = &d.model;
                let _ = writeln!(
                    s,
                    "### {} (`{}`)\n\n{}.\n",
                    m.paper_label().unwrap_or_else(|| m.id()),
                    m.id(),
                    header(m)
                );
                let latex = RenderOptions::latex().with_abbreviations(abbreviate);
                let _ = writeln!(s, "$$G = {}$$\n", d.tf.render(&latex));
                let _ = writeln!(s, "- Num = {}", render_poly(&d.numerator, d.var, &opts));
                let _ = writeln!(s, "- Den = {}\n", render_poly(&d.denominator, d.var, &opts));
            }
        }
        DeriveFormat::Tex => {
            let opts = RenderOptions::latex().with_abbreviations(abbreviate);
            let _ = writeln!(s, "% Transfer functions: {}", output_name(output, damped));
            for d in &items {
                let m = &d.model;
                let _ = writeln!(
                    s,
                    "\\subsection*{{{} (\\texttt{{{}}})}}\n{}.\n\\begin{{align*}}",
                    m.paper_label().unwrap_or_else(|| m.id()),
                    m.id(),
                    header(m)
                );
                let _ = writeln!(s, "  G &= {} \\\\", d.tf.render(&opts));
                let _ = writeln!(
                    s,
                    "  \\mathrm{{Num}} &= {} \\\\",
                    render_poly(&d.numerator, d.var, &opts)
                );
                let _ = writeln!(
                    s,
                    "  \\mathrm{{Den}} &= {}",
                    render_poly(&d.denominator, d.var, &opts)
                );
                let _ = writeln!(s, "\\end{{align*}}\n");
            }
        }
    }
    Ok(s)
}
