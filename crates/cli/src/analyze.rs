//! `mms analyze`: the FRF types each model can show, with witnesses and
//! certificates (the paper's Tab. 3).
//!
//! Every model is analysed on its own (in parallel with `--jobs`) and
//! reduced to a [`Summary`], everything any output format needs; the output
//! is rendered from the summaries in the order of the model list. So the
//! output does not depend on the number of jobs, on the order in which the
//! jobs finish, or on which summaries came from the `--cache` directory.

use crate::analyze_cache::{Cache, Hit};
use crate::progress::ModelProgress;
use crate::TableFormat3;
use indicatif::ProgressBar;
use mms::analysis::{analysis_source, analyze, analyze_each, ModelAnalysis, SearchLimits, Status};
use mms::identifiability::{Identifiability, UnidentifiableDirection};
use mms::table::{
    AnalysisTable, Covers, ModelTiming, RunTiming, Shard, SimilarSystems, TableModel,
};
use mms::Model;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// (model id, type) -> ids of the other models with that type possible.
pub type Similar = BTreeMap<(String, String), Vec<String>>;

/// Analyses of `models`, and for every possible type the other models that
/// can show it (the study's Tab. 3).
pub struct Table {
    pub analyses: Vec<ModelAnalysis>,
    pub similar: Similar,
}

pub fn table(models: &[Model]) -> Table {
    let limits = SearchLimits::default();
    let analyses = analyze_each(models, &limits);
    let types: Vec<Types> = analyses
        .iter()
        .map(|a| Types {
            id: &a.id,
            generic_id: &a.generic_id,
            possible: a.possible().iter().map(|t| t.to_string()).collect(),
        })
        .collect();
    let similar = similar_map(&types, &types);
    Table { analyses, similar }
}

/// What the lookup of similar systems needs of an analysis.
struct Types<'a> {
    id: &'a str,
    generic_id: &'a str,
    possible: Vec<String>,
}

/// For every possible type of every target, the other peers (by generic
/// ID) with that type possible, in the order of `peers`.
fn similar_map(targets: &[Types], peers: &[Types]) -> Similar {
    let mut similar = BTreeMap::new();
    for a in targets {
        for t in &a.possible {
            let others: Vec<String> = peers
                .iter()
                .filter(|b| b.generic_id != a.generic_id)
                .filter(|b| b.possible.contains(t))
                .map(|b| b.id.to_string())
                .collect();
            similar.insert((a.id.to_string(), t.clone()), others);
        }
    }
    similar
}

/// One model's analysis as the output formats use it. Unlike
/// [`ModelAnalysis`] it deserialises, so it can be cached (see
/// [`crate::analyze_cache`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The paper's ID for 3 masses, else the generic ID.
    pub id: String,
    pub generic_id: String,
    /// The possible types, in the order of the analysis, as displayed.
    pub possible: Vec<String>,
    /// The undecided types, in the order of the analysis.
    pub unknown: Vec<String>,
    /// The number of types ruled out by a certificate.
    pub impossible: usize,
    /// Tab. 5: determinable parameters and non-constant moment invariants.
    pub determinable_parameters: usize,
    /// Where the rank is only sampled: its proven upper bound
    /// (`determinable_parameters` is then a proven lower bound).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub determinable_parameters_at_most: Option<usize>,
    pub moment_invariants: usize,
    /// The proof of the upper bound of `determinable_parameters`.
    pub unidentifiable_directions: Vec<UnidentifiableDirection>,
    /// The whole analysis, as the table file holds it.
    pub analysis: ModelAnalysis,
}

impl Summary {
    /// `idf`: the identifiability of `model` or of its reciprocal (the
    /// same transfer function in the same parameters).
    fn new(a: &ModelAnalysis, idf: &Identifiability) -> Result<Summary, String> {
        Ok(Summary {
            id: a.id.clone(),
            generic_id: a.generic_id.clone(),
            possible: a.possible().iter().map(|t| t.to_string()).collect(),
            unknown: a.unknown().iter().map(|t| t.to_string()).collect(),
            impossible: a
                .types
                .iter()
                .filter(|v| v.status == Status::Impossible)
                .count(),
            determinable_parameters: idf.determinable_parameters,
            determinable_parameters_at_most: (!idf.is_proven()).then_some(idf.rank_upper_bound),
            moment_invariants: idf.nonconstant_invariants,
            unidentifiable_directions: idf.unidentifiable_directions.clone(),
            analysis: a.clone(),
        })
    }

    /// The determinable parameters as shown: the number, or where the rank
    /// is only sampled the number with its proven upper bound.
    pub fn determinable(&self) -> String {
        match self.determinable_parameters_at_most {
            Some(most) => format!("{} (at most {most})", self.determinable_parameters),
            None => self.determinable_parameters.to_string(),
        }
    }

    fn types(&self) -> Types<'_> {
        Types {
            id: &self.id,
            generic_id: &self.generic_id,
            possible: self.possible.clone(),
        }
    }
}

/// How `mms analyze` runs: the command-line flags beyond the selection.
pub struct Options {
    /// Models analysed at a time; 0: one per core.
    pub jobs: usize,
    /// Where finished analyses are kept and looked up.
    pub cache: Option<PathBuf>,
    /// Add the per-model times to `--format json`.
    pub timings: bool,
    /// Only this slice of the classes (with `--masses`).
    pub shard: Option<Shard>,
}

/// A finished model: its summary, the wall time of its analysis (as
/// recorded in the cache for cached ones) and whether it came from the cache.
struct Done {
    summary: Summary,
    seconds: f64,
    cached: bool,
}

/// The models of one job, by their index in the model list.
type JobResult = Result<Vec<(usize, Done)>, String>;

/// A finished batch.
struct Batch {
    done: Vec<Done>,
    wall_seconds: f64,
    threads: usize,
}

/// Analyses `models`, `opts.jobs` at a time, and returns their summaries in
/// the order of `models`.
fn analyse_all(models: &[Model], opts: &Options) -> Result<Batch, String> {
    let limits = SearchLimits::default();
    let cache = opts
        .cache
        .as_deref()
        .map(|dir| Cache::open(dir, &limits))
        .transpose()?;
    let progress = ModelProgress::new("analyze", models.len() as u64);
    // Models that share an analysis source (reciprocal twins, members of
    // one class) are one job: the source is analysed once, or read from
    // the cache, and carried over to each of them.
    let mut jobs: Vec<(Model, Vec<usize>)> = Vec::new();
    for (i, m) in models.iter().enumerate() {
        let source = analysis_source(m);
        match jobs.iter_mut().find(|(s, _)| *s == source) {
            Some((_, members)) => members.push(i),
            None => jobs.push((source, vec![i])),
        }
    }
    let one = |(source, members): &(Model, Vec<usize>)| {
        let names: Vec<String> = members.iter().map(|&i| models[i].name()).collect();
        progress.start(&names);
        let done = analyse_shared(
            source,
            members,
            models,
            &limits,
            cache.as_ref(),
            &progress.bar,
        );
        progress.end(&names);
        done
    };
    let start = Instant::now();
    let threads = crate::progress::threads(opts.jobs).min(jobs.len().max(1));
    // A shared queue in the order of `jobs`: each worker takes the next job
    // when it is free, so one slow class never waits behind a batch
    // assigned in advance.
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<JobResult>>> =
        Mutex::new((0..jobs.len()).map(|_| None).collect());
    let work = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let Some(job) = jobs.get(k) else { break };
        let r = one(job);
        results.lock().unwrap_or_else(|e| e.into_inner())[k] = Some(r);
    };
    if threads == 1 {
        work();
    } else {
        std::thread::scope(|scope| -> Result<(), String> {
            for _ in 0..threads {
                std::thread::Builder::new()
                    // The exact algebra recurses; give the workers the stack
                    // of a main thread rather than the 2 MiB default.
                    .stack_size(8 << 20)
                    .spawn_scoped(scope, work)
                    .map_err(|e| format!("--jobs {}: cannot start a worker: {e}", opts.jobs))?;
            }
            Ok(())
        })?;
    }
    let done = results
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect::<Result<Vec<_>, String>>();
    // Back into the order of `models`.
    let mut done: Vec<(usize, Done)> = done?.into_iter().flatten().collect();
    done.sort_by_key(|(i, _)| *i);
    let done: Vec<Done> = done.into_iter().map(|(_, d)| d).collect();
    progress.bar.finish_and_clear();
    Ok(Batch {
        done,
        wall_seconds: start.elapsed().as_secs_f64(),
        threads,
    })
}

/// The models `members` (indices into `models`) of one analysis source:
/// each from the cache when it holds a usable file; the others carried over
/// from the source's analysis, read from the cache or computed once (and
/// stored). The computing time goes to the first model that needed it.
fn analyse_shared(
    source: &Model,
    members: &[usize],
    models: &[Model],
    limits: &SearchLimits,
    cache: Option<&Cache>,
    progress: &ProgressBar,
) -> JobResult {
    let lookup = |m: &Model| -> Option<Hit> {
        match cache?.load(m) {
            Ok(hit) => hit,
            // A bad cache file costs a recomputation, never the run.
            Err(why) => {
                progress.suspend(|| eprintln!("mms: warning: {why}; recomputing"));
                None
            }
        }
    };
    let mut analysis: Option<ModelAnalysis> = None;
    let mut idfs: Vec<(Model, Identifiability)> = Vec::new();
    let mut out = Vec::new();
    // The source first (when it is a member): its cached analysis serves
    // the others.
    let mut order: Vec<usize> = members.to_vec();
    order.sort_by_key(|&i| models[i] != *source);
    for i in order {
        let model = &models[i];
        if let Some(hit) = lookup(model) {
            if *model == *source {
                analysis = Some(hit.summary.analysis.clone());
            }
            out.push((
                i,
                Done {
                    summary: hit.summary,
                    seconds: hit.seconds,
                    cached: true,
                },
            ));
            progress.inc(1);
            continue;
        }
        let start = Instant::now();
        if analysis.is_none() {
            // A member source came first and missed the cache.
            let stored = if members.iter().any(|&j| models[j] == *source) {
                None
            } else {
                lookup(source)
            };
            analysis = Some(match stored {
                Some(hit) => hit.summary.analysis,
                None => analyze(source, limits),
            });
        }
        let a = analysis
            .as_ref()
            .expect("set above")
            .carried_over(source, model)
            .expect("a model is of its source's class or its reciprocal's");
        // The reciprocal's identifiability is this model's: computed once.
        let known = idfs
            .iter()
            .position(|(m, _)| *m == *model || *m == model.reciprocal());
        let k = known.unwrap_or_else(|| {
            idfs.push((*model, mms::identifiability(model)));
            idfs.len() - 1
        });
        let summary = Summary::new(&a, &idfs[k].1)?;
        let seconds = start.elapsed().as_secs_f64();
        if let Some(cache) = cache {
            cache.store(model, &summary, seconds)?;
        }
        out.push((
            i,
            Done {
                summary,
                seconds,
                cached: false,
            },
        ));
        progress.inc(1);
    }
    Ok(out)
}

/// The stderr line closing a run: wall time, and total, median and maximum
/// of the per-model analysis times.
fn timing_line(batch: &Batch) -> String {
    let n = batch.done.len();
    let cached = batch.done.iter().filter(|d| d.cached).count();
    let mut secs: Vec<f64> = batch.done.iter().map(|d| d.seconds).collect();
    secs.sort_by(f64::total_cmp);
    let median = match n {
        0 => 0.0,
        _ if n % 2 == 1 => secs[n / 2],
        _ => (secs[n / 2 - 1] + secs[n / 2]) / 2.0,
    };
    let slowest = batch
        .done
        .iter()
        .max_by(|a, b| a.seconds.total_cmp(&b.seconds))
        .map(|d| format!(" ({})", d.summary.id))
        .unwrap_or_default();
    format!(
        "mms: analyzed {n} models ({cached} from cache) in {:.2} s with {} job{}; per model: total {:.2} s, median {:.2} s, max {:.2} s{slowest}",
        batch.wall_seconds,
        batch.threads,
        if batch.threads == 1 { "" } else { "s" },
        secs.iter().sum::<f64>(),
        median,
        secs.last().copied().unwrap_or(0.0),
    )
}

/// The `--timings` fields of `--format json`.
struct Timings {
    models: Vec<ModelTiming>,
    run: RunTiming,
}

/// For each possible type of `a`, the other classes that can show it
/// (joined by `inner`, `-` for none), the types joined by `sep`.
pub fn similar_cell(similar: &Similar, a: &Summary, sep: &str, inner: &str) -> String {
    a.possible
        .iter()
        .map(|ty| {
            let others = &similar[&(a.id.clone(), ty.clone())];
            if others.is_empty() {
                "-".to_string()
            } else {
                others.join(inner)
            }
        })
        .collect::<Vec<_>>()
        .join(sep)
}

fn render(
    summaries: Vec<Summary>,
    similar: &Similar,
    format: TableFormat3,
    timings: Option<&Timings>,
    covers: &Covers,
    threads: usize,
) -> Result<String, String> {
    let mut s = String::new();
    match format {
        TableFormat3::Report => {
            let n = summaries.first().map_or(0, |a| a.analysis.masses);
            s = crate::tables::report(n, &summaries, similar)?;
        }
        TableFormat3::Json => {
            let models: Vec<TableModel> = summaries
                .into_iter()
                .enumerate()
                .map(|(i, a)| TableModel {
                    // A slice's similar systems are those of the whole
                    // table: `mms merge` fills them in.
                    similar: (!matches!(covers, Covers::Slice { .. })).then(|| {
                        a.analysis
                            .possible()
                            .into_iter()
                            .map(|ty| SimilarSystems {
                                frf_type: ty.clone(),
                                models: similar[&(a.id.clone(), ty.to_string())].clone(),
                            })
                            .collect()
                    }),
                    determinable_parameters: Some(a.determinable_parameters),
                    determinable_parameters_at_most: a.determinable_parameters_at_most,
                    moment_invariants: Some(a.moment_invariants),
                    unidentifiable_directions: Some(a.unidentifiable_directions),
                    timing: timings.map(|t| t.models[i].clone()),
                    analysis: a.analysis,
                })
                .collect();
            // What the file covers, by which engine and search: a reader
            // can tell a complete table from a pruned or foreign one.
            let mut table = AnalysisTable::new(covers.clone(), models);
            table.timing = timings.map(|t| t.run.clone());
            s = table.to_json_on(threads);
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
            for a in &summaries {
                let _ = writeln!(
                    s,
                    "{:<16} {:<44} {:<40} {:>10} {:>7} {:>12} {:>8}",
                    a.id,
                    a.possible.join(", "),
                    similar_cell(similar, a, "; ", ","),
                    a.impossible,
                    a.unknown.len(),
                    a.determinable(),
                    a.moment_invariants
                );
            }
            for a in &summaries {
                for u in &a.unknown {
                    let _ = writeln!(s, "unknown: {} {}", a.id, u);
                }
            }
        }
        TableFormat3::Md => {
            s.push_str("| ID | Possible FRF types | Pot. similar systems | Impossible (certified) | Unknown | Determinable parameters | Non-constant moment invariants |\n");
            s.push_str("|---|---|---|---|---|---|---|\n");
            for a in &summaries {
                let types: Vec<String> = a.possible.iter().map(|t| format!("`{t}`")).collect();
                let unknown: Vec<String> = a.unknown.iter().map(|t| format!("`{t}`")).collect();
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} |",
                    a.id,
                    types.join(", "),
                    similar_cell(similar, a, "; ", ","),
                    a.impossible,
                    if unknown.is_empty() {
                        "0".to_string()
                    } else {
                        unknown.join(", ")
                    },
                    a.determinable(),
                    a.moment_invariants
                );
            }
        }
        TableFormat3::Tex => {
            s.push_str("\\begin{tabular}{lllrr}\n\\hline\nID & Possible FRF types & Pot. similar systems & Impossible & Unknown \\\\\n\\hline\n");
            for a in &summaries {
                let types: Vec<String> = a.possible.iter().map(|t| tex_type(t)).collect();
                let _ = writeln!(
                    s,
                    "{} & {} & {} & {} & {} \\\\",
                    a.id.replace('*', "$^*$"),
                    types.join(", "),
                    similar_cell(similar, a, "; ", ","),
                    a.impossible,
                    a.unknown.len()
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

pub fn run(models: &[Model], format: TableFormat3, opts: &Options) -> Result<String, String> {
    if opts.timings && format != TableFormat3::Json {
        return Err("--timings adds timing fields to --format json only".into());
    }
    let n = models.first().map(|m| m.n_masses()).unwrap_or(0);
    // A slice: the classes at the slice's positions in the class order.
    let sliced: Vec<Model>;
    let models = match opts.shard {
        None => models,
        Some(shard) => {
            let classes = mms::equivalence_classes(n, mms::Symmetry::Renumbering)
                .map_err(|e| format!("--masses {n}: {e}"))?;
            sliced = models
                .iter()
                .copied()
                .filter(|m| {
                    classes
                        .iter()
                        .position(|c| c.contains(m))
                        .is_some_and(|c| shard.holds(c))
                })
                .collect();
            &sliced[..]
        }
    };
    // Similar systems are looked up among all classes of the same size,
    // which is cheap up to 3 masses; beyond, among the models given.
    let peers = if n <= 3 && models.len() == 1 {
        crate::class_representatives(n)?
    } else {
        models.to_vec()
    };
    // The models, then the peers not among them, as one batch: one progress
    // bar, one pool of jobs, one cache.
    let mut work = models.to_vec();
    for p in &peers {
        if !work.iter().any(|m| m.id() == p.id()) {
            work.push(*p);
        }
    }
    let batch = analyse_all(&work, opts)?;
    if batch.done.len() > 1 {
        eprintln!("{}", timing_line(&batch));
    }
    let timings = opts.timings.then(|| Timings {
        models: batch.done[..models.len()]
            .iter()
            .map(|d| ModelTiming {
                seconds: d.seconds,
                cached: d.cached,
            })
            .collect(),
        run: RunTiming {
            wall_seconds: batch.wall_seconds,
            threads: batch.threads,
            models_analysed: batch.done.len(),
            models_from_cache: batch.done.iter().filter(|d| d.cached).count(),
        },
    });
    let threads = batch.threads;
    // Moved, not cloned: a 5-mass table's analyses are a few GB.
    let mut summaries: Vec<Summary> = batch.done.into_iter().map(|d| d.summary).collect();
    let own = &summaries[..models.len()];
    // Every peer is in `work`, whose summaries are in the same order.
    let peer_types: Vec<Types> = peers
        .iter()
        .filter_map(|p| work.iter().position(|m| m.id() == p.id()))
        .map(|i| summaries[i].types())
        .collect();
    let own_types: Vec<Types> = own.iter().map(Summary::types).collect();
    let similar = similar_map(&own_types, &peer_types);
    // What the file claims to cover, which `mms check` holds it to: every
    // class of N masses, or the models given.
    let ids: Vec<String> = models.iter().map(|m| m.id()).collect();
    let every_class = crate::class_representatives(n)
        .is_ok_and(|reps| reps.iter().map(|m| m.id()).eq(ids.iter().cloned()));
    let covers = match opts.shard {
        Some(shard) => Covers::Slice { masses: n, shard },
        None if every_class => Covers::Masses(n),
        None => Covers::Models(ids),
    };
    summaries.truncate(models.len());
    render(
        summaries,
        &similar,
        format,
        timings.as_ref(),
        &covers,
        threads,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use mms::analysis::{analyze, SearchLimits};
    use mms::{identifiability, identifiability_with, Model, RankOptions};

    /// B2 has 4 determinable parameters of 5 (the paper's Tab. 5). With
    /// the symbolic proof it is one number; with the rank only sampled (as
    /// at six masses) the summary keeps the proven upper bound, 5 by
    /// counting, and shows the range.
    #[test]
    fn a_sampled_rank_is_shown_as_a_range() {
        let b2 = Model::from_id("B2").unwrap();
        let a = analyze(&b2, &SearchLimits::default());
        let proven = Summary::new(&a, &identifiability(&b2)).unwrap();
        assert_eq!(proven.determinable_parameters_at_most, None);
        assert_eq!(proven.determinable(), "4");
        let sampled_only = RankOptions {
            symbolic_work_limit: 0,
            ..RankOptions::default()
        };
        let sampled = Summary::new(&a, &identifiability_with(&b2, &sampled_only)).unwrap();
        assert_eq!(sampled.determinable_parameters, 4);
        assert_eq!(sampled.determinable_parameters_at_most, Some(5));
        assert_eq!(sampled.determinable(), "4 (at most 5)");
    }
}
