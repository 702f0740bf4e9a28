//! `mms algebra`: the algebra benchmark pipeline for every model class of N
//! masses: Num, Den, Res_Omega(Num, Den), Disc_Omega(Num), Disc_Omega(Den),
//! each factored into irreducibles over Q.

use crate::AlgebraFormat;
use indicatif::{ProgressBar, ProgressStyle};
use poly::Poly;
use serde_json::json;
use std::fmt::Write;
use std::time::Instant;

const OMEGA: &str = "Omega";

struct Item {
    name: &'static str,
    poly: Poly,
    factors: Option<poly::Factorization>,
    /// Seconds spent computing the polynomial (Num and Den: the transfer
    /// function, shared) and factoring it.
    compute_seconds: f64,
    factor_seconds: f64,
}

fn pipeline(model: &mms::Model) -> Vec<Item> {
    let t = Instant::now();
    let tf = model.undamped_tf();
    let (num, den) = (tf.num, tf.den);
    let t_tf = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let res = poly::resultant(&num, &den, OMEGA);
    let t_res = t.elapsed().as_secs_f64();
    let disc = |p: &Poly| {
        let t = Instant::now();
        let d = if p.degree(OMEGA) >= 1 {
            poly::discriminant(p, OMEGA)
        } else {
            Poly::zero()
        };
        (d, t.elapsed().as_secs_f64())
    };
    let (dn, t_dn) = disc(&num);
    let (dd, t_dd) = disc(&den);
    [
        ("num", num, t_tf),
        ("den", den, t_tf),
        ("res", res, t_res),
        ("disc_num", dn, t_dn),
        ("disc_den", dd, t_dd),
    ]
    .into_iter()
    .map(|(name, poly, compute_seconds)| {
        // A discriminant of a polynomial of degree 0 in Omega is undefined:
        // reported as zero with no factor list.
        let t = Instant::now();
        let factors = (!poly.is_zero()).then(|| poly::factor(&poly));
        Item {
            name,
            poly,
            factors,
            compute_seconds,
            factor_seconds: t.elapsed().as_secs_f64(),
        }
    })
    .collect()
}

/// Runs the pipeline on the representatives of the model classes of `n` masses.
pub fn run(n: usize, format: AlgebraFormat) -> Result<String, String> {
    let models = crate::class_representatives(n)?;
    // One tick per model class on stderr; indicatif draws nothing when
    // stderr is not a terminal (pipes, CI, the comparison script).
    let progress = ProgressBar::new(models.len() as u64);
    progress.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} classes, {elapsed} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    progress.set_prefix(format!("algebra N={n}"));
    let start = Instant::now();
    let mut results = Vec::new();
    for m in &models {
        progress.set_message(m.name());
        let t = Instant::now();
        let items = pipeline(m);
        results.push((m, items, t.elapsed().as_secs_f64()));
        progress.inc(1);
    }
    let total = start.elapsed().as_secs_f64();
    progress.finish_and_clear();
    Ok(match format {
        AlgebraFormat::Json => {
            let models: Vec<_> = results
                .iter()
                .map(|(m, items, secs)| {
                    let polys: Vec<_> = items
                        .iter()
                        .map(|it| {
                            let (unit, factors) = match &it.factors {
                                Some(f) => (
                                    f.unit.to_string(),
                                    f.factors
                                        .iter()
                                        .map(|(p, k)| {
                                            json!({"factor": p.to_string(), "multiplicity": k})
                                        })
                                        .collect::<Vec<_>>(),
                                ),
                                None => ("0".to_string(), Vec::new()),
                            };
                            json!({
                                "name": it.name,
                                "terms": it.poly.num_terms(),
                                "unit": unit,
                                "factors": factors,
                                "compute_seconds": it.compute_seconds,
                                "factor_seconds": it.factor_seconds,
                            })
                        })
                        .collect();
                    json!({"id": m.name(), "polys": polys, "seconds": secs})
                })
                .collect();
            let v = json!({"masses": n, "models": models, "total_seconds": total});
            serde_json::to_string_pretty(&v).map_err(|e| e.to_string())? + "\n"
        }
        AlgebraFormat::Text => {
            let mut s = String::new();
            for (m, items, secs) in &results {
                let _ = writeln!(s, "{}  ({:.3} ms)", m.name(), secs * 1e3);
                for it in items {
                    let _ = write!(
                        s,
                        "  {:<8} {:>6} terms  [{:>9.3} + {:>9.3} ms]  ",
                        it.name,
                        it.poly.num_terms(),
                        it.compute_seconds * 1e3,
                        it.factor_seconds * 1e3
                    );
                    match &it.factors {
                        None => {
                            let _ = writeln!(s, "undefined (degree 0 in Omega)");
                        }
                        Some(f) => {
                            let list: Vec<String> = f
                                .factors
                                .iter()
                                .map(|(p, k)| {
                                    let t = if p.num_terms() > 6 {
                                        format!(
                                            "<{} terms, degree {}>",
                                            p.num_terms(),
                                            p.total_degree()
                                        )
                                    } else {
                                        format!("({p})")
                                    };
                                    if *k > 1 {
                                        format!("{t}^{k}")
                                    } else {
                                        t
                                    }
                                })
                                .collect();
                            let _ = writeln!(s, "{} * {}", f.unit, list.join(" * "));
                        }
                    }
                }
            }
            let _ = writeln!(
                s,
                "{} model classes of {n} masses in {:.3} ms",
                results.len(),
                total * 1e3
            );
            s
        }
    })
}
