//! `mms benchmark --cases N --seed S`: the concealed-effect benchmark
//! ([`ident::concealed`]): draw the cases, diagnose (and, on the controls,
//! identify) each, and report the scores. Cases run side by side with
//! `--jobs`; with `--cache DIR` each finished case is kept, so an
//! interrupted run resumes.

use crate::output::write_atomic;
use crate::progress::{threads, ModelProgress};
use ident::concealed::{case, run_case, Outcome, Summary, BENCHMARK_VERSION};
use ident::diagnose::EffectKind;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Output formats of `mms benchmark`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchmarkFormat {
    /// A Markdown report of the scores.
    Md,
    /// JSON: the scores and every case's outcome.
    Json,
}

/// The options of one run.
pub struct Options {
    pub cases: usize,
    pub seed: u64,
    pub jobs: usize,
    pub cache: Option<PathBuf>,
    pub format: BenchmarkFormat,
}

/// A cache file: one case's outcome and what it was made from.
#[derive(Serialize, Deserialize)]
struct Entry {
    version: u32,
    seed: u64,
    outcome: Outcome,
}

/// The report of one run.
pub fn run(o: &Options) -> Result<String, String> {
    if o.cases == 0 || o.cases > 1_000_000 {
        return Err(format!("--cases {}: give from 1 to 10^6 cases", o.cases));
    }
    if let Some(dir) = &o.cache {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create cache directory: {e}", dir.display()))?;
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads(o.jobs))
        .build()
        .map_err(|e| e.to_string())?;
    let progress = ModelProgress::with_unit("benchmark", o.cases as u64, "cases");
    let start = std::time::Instant::now();
    let outcomes: Vec<Outcome> = pool.install(|| {
        (0..o.cases)
            .into_par_iter()
            .map(|i| -> Result<Outcome, String> {
                let cached = o.cache.as_deref().and_then(|d| recall(d, o.seed, i));
                let outcome = match cached {
                    Some(c) => c,
                    None => {
                        let name = format!("case {i}");
                        progress.start(std::slice::from_ref(&name));
                        let c = case(o.seed, i).map_err(|e| e.to_string())?;
                        let outcome = run_case(&c);
                        progress.end(&[name]);
                        if let Some(d) = &o.cache {
                            keep(d, o.seed, &outcome)?;
                        }
                        outcome
                    }
                };
                progress.bar.inc(1);
                Ok(outcome)
            })
            .collect::<Result<Vec<_>, _>>()
    })?;
    progress.bar.finish_and_clear();
    let summary = Summary::of(&outcomes);
    eprintln!(
        "benchmark: {} cases in {:.0} s",
        o.cases,
        start.elapsed().as_secs_f64()
    );
    match o.format {
        BenchmarkFormat::Md => Ok(markdown(o, &summary)),
        BenchmarkFormat::Json => {
            let v = serde_json::json!({
                "version": BENCHMARK_VERSION,
                "seed": o.seed,
                "summary": summary,
                "outcomes": outcomes,
            });
            serde_json::to_string_pretty(&v)
                .map(|s| s + "\n")
                .map_err(|e| format!("JSON: {e}"))
        }
    }
}

fn cache_file(dir: &Path, seed: u64, index: usize) -> PathBuf {
    dir.join(format!("case-{seed}-{index}.json"))
}

/// A kept outcome of this version, seed and index, if there is one.
fn recall(dir: &Path, seed: u64, index: usize) -> Option<Outcome> {
    let text = std::fs::read_to_string(cache_file(dir, seed, index)).ok()?;
    let e: Entry = serde_json::from_str(&text).ok()?;
    (e.version == BENCHMARK_VERSION && e.seed == seed && e.outcome.index == index)
        .then_some(e.outcome)
}

fn keep(dir: &Path, seed: u64, outcome: &Outcome) -> Result<(), String> {
    let e = Entry {
        version: BENCHMARK_VERSION,
        seed,
        outcome: outcome.clone(),
    };
    let text = serde_json::to_string(&e).map_err(|e| format!("JSON: {e}"))?;
    write_atomic(&cache_file(dir, seed, outcome.index), &text)
}

fn pct(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

/// The Markdown report.
fn markdown(o: &Options, s: &Summary) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "# Concealed-effect benchmark\n\n{} cases, seed {}, generator version {}; \
         {} diagnoses failed with an error.\n",
        s.cases, o.seed, BENCHMARK_VERSION, s.errors
    );
    let share = |x: &ident::concealed::Share| format!("{} of {} ({})", x.hits, x.of, pct(x.rate()));
    let _ = writeln!(m, "| score | result |\n|---|---|");
    let _ = writeln!(
        m,
        "| headline right, cases with an effect | {} |",
        share(&s.effect_right)
    );
    let _ = writeln!(
        m,
        "| nothing named, controls | {} |",
        share(&s.controls_clean)
    );
    let _ = writeln!(
        m,
        "| identification right, one sensor | {} |",
        share(&s.identified[0])
    );
    let _ = writeln!(
        m,
        "| identification right, two sensors | {} |",
        share(&s.identified[1])
    );
    let within: ident::concealed::Share =
        s.parameter_within_15
            .values()
            .fold(Default::default(), |a, b| ident::concealed::Share {
                hits: a.hits + b.hits,
                of: a.of + b.of,
            });
    let _ = writeln!(
        m,
        "| parameter within 15 %, right headlines | {} |",
        share(&within)
    );
    let worst = s
        .cells
        .iter()
        .min_by(|a, b| a.1.rate().total_cmp(&b.1.rate()));
    if let Some((cell, x)) = worst {
        let _ = writeln!(m, "| weakest cell | {cell}: {} |", share(x));
    }

    // The confusion matrix: rows the true kind, columns the headline.
    let mut named: Vec<EffectKind> = s
        .confusion
        .values()
        .flat_map(|r| r.keys().copied())
        .collect();
    named.sort();
    named.dedup();
    let _ = write!(m, "\n## Confusion matrix\n\nRows: the (first) concealed kind; columns: the headline.\n\n| concealed |");
    for k in &named {
        let _ = write!(m, " {} |", k.as_str());
    }
    let _ = write!(m, "\n|---|");
    for _ in &named {
        m.push_str("---:|");
    }
    m.push('\n');
    for (truth, row) in &s.confusion {
        let _ = write!(m, "| {} |", truth.as_str());
        for k in &named {
            match row.get(k) {
                Some(c) => _ = write!(m, " {c} |"),
                None => m.push_str(" |"),
            }
        }
        m.push('\n');
    }

    let _ = writeln!(
        m,
        "\n## Parameters of right headlines\n\n| kind | within 15 % | median error |\n|---|---|---|"
    );
    for (k, x) in &s.parameter_within_15 {
        let _ = writeln!(
            m,
            "| {} | {} | {} |",
            k.as_str(),
            share(x),
            s.parameter_median.get(k).map_or("-".into(), |e| pct(*e))
        );
    }

    let _ = writeln!(
        m,
        "\n## Cells\n\nRight: the headline one of the concealed kinds, or nothing named on a control.\n\n\
         | excitation / concealed / loop | right |\n|---|---|"
    );
    for (cell, x) in &s.cells {
        let _ = writeln!(m, "| {cell} | {} |", share(x));
    }

    let _ = writeln!(
        m,
        "\n## Time per case\n\n| samples | cases | median | largest |\n|---|---|---|---|"
    );
    for (decade, (count, median, max)) in &s.time {
        let _ = writeln!(m, "| {decade} | {count} | {median:.2} s | {max:.2} s |");
    }
    let (count, median, max) = s.two_mass_per_100k;
    let _ = writeln!(
        m,
        "\nPer 100 000 samples, time records of 2-mass chains with one sensor ({count} cases): \
         median {median:.2} s, largest {max:.2} s."
    );
    m
}
