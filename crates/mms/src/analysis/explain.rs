//! A verdict written out for a reader: the witness and its roots, or the
//! certificate as a derivation in the style of the paper's eqs. (22)-(31).

use super::prover::{
    ConditionRule, Definiteness, FactorProof, OpenProof, Proof, Substitution, UnlistedRole,
};
use super::LARGEST_LISTED_FACTOR;
use super::{FrfType, ModelAnalysis, Status};
use crate::render::{render_poly, RenderOptions};
use crate::tf::OMEGA;
use poly::{real_roots, Poly, Rat, UPoly};
use std::fmt::Write;

/// Markdown (inline LaTeX) or a LaTeX fragment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExplainFormat {
    /// Markdown with `$...$` math.
    Markdown,
    /// LaTeX.
    Latex,
}

struct W {
    latex: bool,
    out: String,
}

/// `f1 * (f2)^k * ...`: a certificate's factor list as text.
fn factor_product(w: &W, factors: &[super::RemainderFactor]) -> String {
    let parts: Vec<String> = factors
        .iter()
        .map(|f| {
            if f.exponent == 1 {
                w.poly(&f.factor)
            } else {
                format!("({})^{}", w.poly(&f.factor), f.exponent)
            }
        })
        .collect();
    parts.join(" * ")
}

impl W {
    fn poly(&self, p: &Poly) -> String {
        if self.latex {
            format!("${}$", render_poly(p, OMEGA, &RenderOptions::latex()))
        } else {
            render_poly(p, OMEGA, &RenderOptions::markdown())
        }
    }

    /// Escapes LaTeX specials outside `$...$` and turns `**x**` bold.
    fn text(&self, s: &str) -> String {
        if !self.latex {
            return s.to_string();
        }
        let mut out = String::new();
        for (i, seg) in s.split('$').enumerate() {
            if i > 0 {
                out.push('$');
            }
            if i % 2 == 1 {
                out.push_str(seg);
                continue;
            }
            let mut bold = false;
            let parts: Vec<&str> = seg.split("**").collect();
            for (j, p) in parts.iter().enumerate() {
                if j > 0 {
                    out.push_str(if bold { "}" } else { "\\textbf{" });
                    bold = !bold;
                }
                for c in p.chars() {
                    match c {
                        '^' => out.push_str("\\^{}"),
                        '_' | '&' | '%' | '#' => {
                            out.push('\\');
                            out.push(c);
                        }
                        _ => out.push(c),
                    }
                }
            }
            if bold {
                out.push('}');
            }
        }
        out
    }

    fn heading(&mut self, level: usize, s: &str) {
        let s = &self.text(s);
        if self.latex {
            let cmd = ["section", "subsection", "subsubsection", "paragraph"][level.min(3)];
            let _ = writeln!(self.out, "\\{cmd}*{{{s}}}\n");
        } else {
            let _ = writeln!(self.out, "{} {s}\n", "#".repeat(level + 1));
        }
    }

    fn para(&mut self, s: &str) {
        let s = self.text(s);
        let _ = writeln!(self.out, "{s}\n");
    }

    fn item(&mut self, depth: usize, s: &str) {
        let s = &self.text(s);
        if self.latex {
            let _ = writeln!(
                self.out,
                "{}\\textbullet\\ {s}\\\\",
                "\\quad ".repeat(depth)
            );
        } else {
            let _ = writeln!(self.out, "{}- {s}", "  ".repeat(depth));
        }
    }

    fn sub(&self, s: &Substitution) -> String {
        let p = &Poly::var(&s.var) * &s.alpha;
        format!("{} = {}", self.poly(&p), self.poly(&s.beta))
    }
}

/// Writes out the verdict on `t` for `analysis`' model; `None` when `t` is
/// not among its candidate types.
///
/// ```
/// use mms::analysis::{analyze, explain, ExplainFormat, SearchLimits};
/// // B2 cannot show RAAR (the paper's Sec. 4.3.7), by sign conditions.
/// let a = analyze(&mms::Model::from_id("B2")?, &SearchLimits::default());
/// let text = explain(&a, &"RAAR".parse().unwrap(), ExplainFormat::Markdown).unwrap();
/// assert!(text.contains("impossible"));
/// assert!(text.contains("multipliers"));
/// # Ok::<(), mms::ModelError>(())
/// ```
pub fn explain(analysis: &ModelAnalysis, t: &FrfType, format: ExplainFormat) -> Option<String> {
    let v = analysis.types.iter().find(|v| &v.frf_type == t)?;
    let mut w = W {
        latex: format == ExplainFormat::Latex,
        out: String::new(),
    };
    w.heading(0, &format!("Model {}: FRF type {}", analysis.id, t));
    let (num, den) = (w.poly(&analysis.numerator), w.poly(&analysis.denominator));
    w.para(&format!(
        "Masses {}, gap {}, actuator {}-{}, sensor {}-{}. Undamped TF in Omega = w^2: numerator {num}, denominator {den}.",
        analysis.masses,
        analysis.gap,
        analysis.actuator[0],
        analysis.actuator[1],
        analysis.sensor[0],
        analysis.sensor[1],
    ));
    match v.status {
        Status::Possible if v.algebraic.is_some() => {
            let a = v.algebraic.as_ref()?;
            let (k, point) = a.field_point()?;
            let [lo, hi] = &a.interval;
            let coords: Vec<String> = point
                .iter()
                .map(|(name, x)| {
                    let text = w.poly(&a.parameters[name]);
                    match x.as_rat() {
                        Some(_) => format!("{name} = {text}"),
                        None => format!("{name} = {text} (about {:.6})", k.to_f64(x)),
                    }
                })
                .collect();
            w.para(&format!(
                "Verdict: **possible**. Witness (exact) over the real number field Q(theta), theta the root of {} in [{lo}, {hi}] (about {:.9}): {}.",
                w.poly(&a.minimal),
                k.theta_f64(),
                coords.join(", ")
            ));
            let mut posed: Vec<String> = a
                .cancelled
                .iter()
                .map(|r| format!("a pole cancelled at Omega = {r}"))
                .collect();
            posed.extend(
                a.multiple
                    .iter()
                    .map(|(r, m)| format!("a zero of multiplicity {m} at Omega = {r}")),
            );
            if !posed.is_empty() {
                w.para(&format!(
                    "The point solves the root conditions of {} exactly; these roots divide out of num and den over the field, and every positive root of what remains is simple and isolated by Descartes' rule with exact signs in the field.",
                    posed.join(" and ")
                ));
            }
        }
        Status::Possible if v.isolated.is_some() => {
            let b = v.isolated.as_ref()?;
            let fixed: Vec<String> = b.fixed.iter().map(|(k, x)| format!("{k} = {x}")).collect();
            let free: Vec<String> = b
                .free
                .iter()
                .map(|(k, [lo, hi])| {
                    let mid = (lo.to_f64() + hi.to_f64()) / 2.0;
                    let rel = (hi.to_f64() - lo.to_f64()) / mid.abs();
                    format!("{k} = {mid:.12} (a box of relative width {rel:.0e})")
                })
                .collect();
            let mut posed: Vec<String> = b
                .cancelled
                .iter()
                .enumerate()
                .map(|(i, r)| match b.poses.iter().find(|q| q.pole == i) {
                    Some(q) => format!(
                        "a pole cancelled {}at Omega = {r}, where {} and {} vanish (and with them num and den, by the cofactors in the witness{})",
                        if q.double { "twice " } else { "" },
                        w.poly(&q.factors[0]),
                        w.poly(&q.factors[1]),
                        if q.double { "; den is their product, num's derivative vanishes there too" } else { "" }
                    ),
                    None => format!("a pole cancelled at Omega = {r}"),
                })
                .collect();
            posed.extend(
                b.multiple
                    .iter()
                    .map(|(r, m)| format!("a zero of multiplicity {m} at Omega = {r}")),
            );
            let points: Vec<String> = b.partition.iter().map(|x| x.to_string()).collect();
            w.para(&format!(
                "Verdict: **possible**. Witness (exact, isolated in a box): with {}, the root conditions of {} are a square system in {}, which has exactly one solution in the box (Krawczyk's test, in exact rational interval arithmetic).",
                fixed.join(", "),
                posed.join(" and "),
                free.join(", ")
            ));
            w.para(&format!(
                "At that solution the posed roots divide num and den exactly; the points {} of (0, inf) are roots of neither rest on the whole box, and between them Descartes' rule (the same on the whole box) places each remaining zero and pole, so the type is {t} there.",
                if points.is_empty() { "(none)".to_string() } else { points.join(", ") }
            ));
        }
        Status::Possible if v.witness.is_none() => {
            let path = v.path.as_ref()?;
            let (split, gone, event) =
                super::continuity::path_ends(&analysis.numerator, &analysis.denominator, path)?;
            let what = match event {
                super::continuity::PathEvent::PairMeets => {
                    "two zeros meet exactly once, as a double zero"
                }
                super::continuity::PathEvent::CrossesDoubleZero => {
                    "a simple zero crosses the double zero (which stays double all along) exactly once, making a triple zero"
                }
            };
            w.para(&format!(
                "Verdict: **possible**, shown by continuity. Along the path below (each parameter a rational function of s, positive for 0 <= s <= 1) the type at s = 0 is {split} and at s = 1 {gone}; in between {what}, while no other zero or pole meets another, reaches 0 or leaves to infinity. So the type is {t} at that s."
            ));
            let rows: Vec<String> = path
                .parameters
                .iter()
                .map(|(k, [p, q])| format!("{k} = ({}) / ({})", w.poly(p), w.poly(q)))
                .collect();
            w.para(&format!("Path: {}.", rows.join("; ")));
        }
        Status::Possible => {
            let p = v.witness.as_ref()?;
            w.para(&format!(
                "Verdict: **possible**. Witness (exact): {}.",
                point_text(p)
            ));
            let mut n = analysis.numerator.clone();
            let mut d = analysis.denominator.clone();
            for (k, x) in p {
                n = n.subs(k, x);
                d = d.subs(k, x);
            }
            let nu = UPoly::from_poly(&n, OMEGA).map(|x| x.1);
            let du = UPoly::from_poly(&d, OMEGA).map(|x| x.1);
            if let (Some(nu), Some(du)) = (nu, du) {
                let g = nu.gcd(&du);
                if !g.is_constant() {
                    w.para(&format!(
                        "Pole-zero cancellation: num and den share {}.",
                        w.poly(&g.to_poly(OMEGA))
                    ));
                }
                let roots = |u: &UPoly| -> String {
                    let width = Rat::new(1.into(), 1_000_000_000_i64.into());
                    let r: Vec<String> = real_roots(u)
                        .into_iter()
                        .map(|mut x| {
                            // Shrink the isolating interval so the rounding is honest.
                            let _ = x.refine(u, &width);
                            let m = if x.multiplicity > 1 {
                                format!(" (x{})", x.multiplicity)
                            } else {
                                String::new()
                            };
                            format!("{:.6}{m}", x.to_f64())
                        })
                        .collect();
                    if r.is_empty() {
                        "none".into()
                    } else {
                        r.join(", ")
                    }
                };
                w.para(&format!(
                    "Real zeros of num (isolated exactly, shown rounded): {}; real zeros of den: {}.",
                    roots(&nu),
                    roots(&du)
                ));
            }
        }
        Status::Impossible => {
            let c = v.certificate.as_ref()?;
            if matches!(c.open, OpenProof::Limits { .. }) {
                // One argument for every point at once: no strata.
                w.para("Verdict: **impossible** on the whole positive orthant, walls included, as a limit of generic types.");
                w.heading(1, "On the whole positive orthant");
                open(&mut w, &c.open);
            } else {
                w.para("Verdict: **impossible** on the whole positive orthant. The proof cuts the parameter space into strata; on each, the open part (off its walls) and every wall are covered.");
                proof(&mut w, c, 1);
            }
        }
        Status::Unknown => {
            w.para("Verdict: **unknown**: neither a witness nor a certificate was found.");
        }
    }
    Some(w.out)
}

fn point_text(p: &std::collections::BTreeMap<String, Rat>) -> String {
    p.iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn proof(w: &mut W, p: &Proof, level: usize) {
    let where_ = if p.stratum.is_empty() {
        "the open positive orthant".to_string()
    } else {
        let subs: Vec<String> = p.stratum.iter().map(|s| w.sub(s)).collect();
        format!("the wall {}", subs.join(", "))
    };
    w.heading(level, &format!("On {where_}"));
    open(w, &p.open);
    if !p.factors.is_empty() || p.unlisted.is_some() {
        w.para("Critical factors (leading and trailing coefficients, discriminants, resultants of the parts):");
        for f in &p.factors {
            match f {
                FactorProof::Definite {
                    factor,
                    sign,
                    definiteness,
                } => {
                    let s = format!(
                        "{} {} 0 for all positive parameters: {}",
                        w.poly(factor),
                        if *sign > 0 { ">" } else { "<" },
                        definite_text(definiteness)
                    );
                    w.item(0, &s);
                }
                FactorProof::NeedsNoCancellation { factor } => {
                    let s = format!(
                        "{} = 0 cancels a pole, but the type needs every pole: not there.",
                        w.poly(factor)
                    );
                    w.item(0, &s);
                }
                FactorProof::NeedsCancellation { factor } => {
                    let s = format!(
                        "{} = 0 cancels no pole, but the type needs a cancellation: covered by the cancellation walls.",
                        w.poly(factor)
                    );
                    w.item(0, &s);
                }
                FactorProof::Wall {
                    factor,
                    substitution,
                    ..
                } => {
                    let s = format!(
                        "{} = 0 is the wall {}: see below.",
                        w.poly(factor),
                        w.sub(substitution)
                    );
                    w.item(0, &s);
                }
            }
        }
        if let Some(UnlistedRole::NeedsCancellation) = p.unlisted {
            let s = format!("Every other factor (each of more than {LARGEST_LISTED_FACTOR} terms, not written out) cancels no pole, but the type needs a cancellation: covered by the cancellation walls.");
            w.item(0, &s);
        }
        w.out.push('\n');
        for f in &p.factors {
            if let FactorProof::Wall { proof: child, .. } = f {
                proof(w, child, level + 1);
            }
        }
    }
}

fn definite_text(d: &Definiteness) -> String {
    match d {
        Definiteness::NoSubtraction => "no subtraction (all coefficients of one sign)".into(),
        Definiteness::Polya { power, affine } => format!(
            "Polya: multiplied by ({}sum of the variables)^{power} all coefficients have one sign",
            if *affine { "1 + " } else { "" }
        ),
        Definiteness::CompletedSquare { var, inner } => format!(
            "completing the square in {var}: 4a*f = (2a*{var} + b)^2 + (4ac - b^2) with 4ac - b^2 > 0 by {}",
            definite_text(inner)
        ),
    }
}

fn open(w: &mut W, o: &OpenProof) {
    match o {
        OpenProof::TooManyResonances { resonances, degree } => w.para(&format!(
            "The type has {resonances} resonances, the denominator only degree {degree} here (and less on any wall)."
        )),
        OpenProof::TooFewResonances { resonances, degree } => w.para(&format!(
            "Off the walls no pole cancels, so there are {degree} resonances; the type has {resonances}."
        )),
        OpenProof::Multiplicity => w.para(
            "Off the walls the roots of each square-free part are simple and the parts share none: the type's multiplicities (or its zeros off the positive axis) do not match.",
        ),
        OpenProof::SimpleResonances => w.para(
            "Every resonance is simple, for all positive parameters: K - Omega*M is block diagonal, one block per connected part of the chain, and each block is an unreduced tridiagonal pencil with positive masses, whose eigenvalues are simple. The TF is a sum of one term per block, so after cancellation its denominator divides the product of the block determinants with every root once. The type has a multiple resonance.",
        ),
        OpenProof::CollocatedModes {
            num_at_zero,
            den_at_zero,
        } => {
            let s = format!(
                "Actuator and sensor are collocated: the TF is a sum of modal terms with positive residues. The rigid-body pole at Omega = 0 never cancels (numerator {} and denominator {} at Omega = 0 have one sign). So the TF rises from minus to plus infinity between consecutive poles, with one simple zero, and stays negative above the last pole: every type is (AR)^k. This one is not.",
                w.poly(num_at_zero),
                w.poly(den_at_zero)
            );
            w.para(&s)
        }
        OpenProof::PoleSigns(ps) => {
            let factors = factor_product(w, &ps.remainder_factors);
            let s = format!(
                "The denominator is the determinant of one chain block, with simple positive roots. At each of them the numerator has the sign of its pseudo-remainder by it, {} * {}: factors of one sign, powers of Omega, and diagonal entries K_jj - Omega*M_jj of the block, whose root K_jj/M_jj lies strictly between the block's lowest and highest eigenvalue. For every placement of those roots among the poles, the signs at 0, at the poles and at infinity fix the parity of the antiresonances between consecutive poles; the type matches none of them (and a pole where the numerator vanished would cancel, leaving fewer resonances than the type has).",
                ps.remainder_unit, factors
            );
            w.para(&s)
        }
        OpenProof::BlockPoleSigns(bp) => {
            let mut s = String::from(
                "The denominator is the product of the chain blocks' pole polynomials (each block's determinant, a free block's divided by Omega), and the TF is -Omega times the sum of one term n_B/d_B per block. At a pole of block B the numerator has the sign of -c * n_B times the other blocks' pole polynomials, where c is the remaining factor of the denominator (of one sign): the other blocks contribute the sign of how many of their poles lie above, and n_B ",
            );
            let parts: Vec<String> = bp
                .blocks
                .iter()
                .filter(|b| !b.factors.is_empty())
                .map(|b| {
                    let factors = factor_product(w, &b.factors);
                    format!(
                        "(masses {:?}: {} = {} * {})",
                        b.masses,
                        if b.remainder {
                            "its pseudo-remainder by the block's pole polynomial"
                        } else {
                            "n_B"
                        },
                        b.unit,
                        factors
                    )
                })
                .collect();
            s.push_str(&parts.join(", "));
            s.push_str(" factors into factors of one sign, powers of Omega and determinants of runs of the block's masses, whose eigenvalues interlace with the block's (Cauchy). For every interleaving of the blocks' spectra and every placement of those eigenvalues, the signs at 0, at the poles and at infinity fix the parity of the antiresonances between consecutive poles; the type matches none of them (and a pole where the numerator vanished would cancel, leaving fewer resonances than the type has).");
            w.para(&s)
        }
        OpenProof::Descartes {
            part,
            sign_changes,
            needed,
        } => {
            let s = format!(
                "Descartes' rule of signs: the coefficients of {} in Omega have definite signs with {sign_changes} sign changes, so its number of positive zeros is {sign_changes} minus an even number; the type needs {needed}.",
                w.poly(part)
            );
            w.para(&s)
        }
        OpenProof::Regions {
            var,
            walls,
            samples,
            ..
        } => {
            match var {
                None => w.para("No critical factor can vanish: the open part is connected and every root keeps its multiplicity, sign and order on it, so the type is the same everywhere, that of the sample:"),
                Some(x) => {
                    let ws: Vec<String> = walls.iter().map(|s| w.sub(s)).collect();
                    w.para(&format!(
                        "The only walls are {} (graphs over the other parameters that never cross), so the open part consists of {} connected regions in {x}, each with one type:",
                        ws.join(", "),
                        samples.len()
                    ));
                }
            }
            for s in samples {
                w.item(0, &format!("{} at {}", s.frf_type, point_text(&s.point)));
            }
            w.out.push('\n');
        }
        OpenProof::Limits { point, generic } => {
            let list: Vec<String> = generic.iter().map(|g| g.to_string()).collect();
            w.para(&format!(
                "The leading and constant coefficients of numerator and denominator have one sign, so their roots move continuously and never reach 0 or infinity; at {} both are square-free and coprime, so every point is a limit of points where all roots are simple and none is shared. Near a point of this type the roots of such a point gather in consecutive runs (poles stay real, zeros may land in conjugate pairs), each run becoming one of the type's tokens or cancelling out. The generic types that can gather into this one are {}, each impossible: so is this type.",
                point_text(point),
                if list.is_empty() {
                    "none".to_string()
                } else {
                    list.join(", ")
                }
            ));
        }
        OpenProof::SignConditions {
            linear_parts,
            cases,
        } => {
            let lp: Vec<String> = linear_parts.iter().map(|p| w.poly(p)).collect();
            w.para(&format!(
                "The rational roots are those of {}. Each way of placing them among the type's tokens forces sign conditions that contradict positivity:",
                lp.join(", ")
            ));
            for c in cases {
                let a: Vec<String> = c
                    .assignment
                    .iter()
                    .map(|x| match x {
                        Some(i) => format!("token {}", i + 1),
                        None => "off the positive axis".into(),
                    })
                    .collect();
                w.item(0, &format!("Placement: {}.", a.join(", ")));
                let mut combo = Poly::zero();
                for (cond, lambda) in c.conditions.iter().zip(&c.multipliers) {
                    let rel = if cond.strict { ">" } else { ">=" };
                    let why = rule_text(&cond.rule);
                    let s = format!("{} {rel} 0 ({why})", w.poly(&cond.reduced));
                    w.item(1, &s);
                    combo = &combo + &(lambda * &cond.reduced);
                }
                let ms: Vec<String> = c.multipliers.iter().map(|m| w.poly(m)).collect();
                let s = format!(
                    "With the multipliers {} the combination is {}, which has no positive coefficient: a contradiction.",
                    ms.join(", "),
                    w.poly(&combo)
                );
                w.item(1, &s);
            }
            w.out.push('\n');
        }
    }
}

fn rule_text(r: &ConditionRule) -> String {
    match r {
        ConditionRule::RootPositive { part } => format!("root {} is positive", part + 1),
        ConditionRule::RootNotPositive { part } => format!("root {} is not positive", part + 1),
        ConditionRule::RootOrder { lower, upper } => {
            format!("root {} below root {}", lower + 1, upper + 1)
        }
        ConditionRule::SignAt {
            part,
            derivative,
            roots_above,
            ..
        } => {
            if *derivative == 0 {
                format!("sign at root {}: {roots_above} roots above it", part + 1)
            } else {
                format!("sign of derivative {derivative} at root {}", part + 1)
            }
        }
        ConditionRule::RealRoots { .. } => "real simple roots: positive discriminant".into(),
    }
}
