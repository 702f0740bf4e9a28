//! `mms sample FILE.json`: the variety sampler on every unknown type of an
//! analysis table ([`mms::analysis::sample_cell`]): how often points on
//! each type's own region show it, and whether any shows a type the table
//! certifies impossible. Evidence for the cells the analysis leaves open,
//! never a verdict.

use crate::output::write_atomic;
use indicatif::{ProgressBar, ProgressStyle};
use mms::analysis::{analysis_source, cells, sample_cell, CellSample, FrfType, Status};
use mms::table::AnalysisTable;
use mms::Model;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Output formats of `mms sample`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SampleFormat {
    /// A Markdown report.
    Md,
    /// JSON: one entry per model with its cells' counts.
    Json,
}

/// The options of one run.
pub struct Options {
    pub starts: u64,
    pub jobs: usize,
    pub cache: Option<PathBuf>,
    pub format: SampleFormat,
}

/// Mixed with each cell's name into its sampler's seed: the same counts
/// on every run.
const SEED: u64 = 0x5A3F_1E00;

/// One model's counts, as written.
#[derive(Serialize)]
struct ModelSamples {
    id: String,
    /// The cells of its unknown types.
    cells: Vec<CellSample>,
    /// Types the table certifies impossible that a cell's sampler read,
    /// with how often.
    impossible_read: BTreeMap<FrfType, u64>,
    /// For each unknown type, the possible generic types that gather into
    /// it ([`mms::analysis::gathers_into`]): why the limits of generic
    /// types leave it open, and where a witness would be approached from.
    limit_of: BTreeMap<FrfType, Vec<FrfType>>,
}

/// A cache file: one cell's counts with what they were made from.
#[derive(Serialize, Deserialize)]
struct Entry {
    fingerprint: String,
    sample: CellSample,
}

/// The report (see the module docs) on the table in `path`.
pub fn run(path: &Path, opts: &Options) -> Result<String, String> {
    if opts.starts == 0 || opts.starts > 1_000_000_000 {
        return Err(format!(
            "--starts {}: give from 1 to 10^9 starts per cell",
            opts.starts
        ));
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let table = AnalysisTable::from_json(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    if let Some(dir) = &opts.cache {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create cache directory: {e}", dir.display()))?;
    }
    // One job per cell of each analysis source with unknown types: models
    // that share a source (reciprocal twins) have the same variety.
    let mut models: Vec<(String, Model, Vec<FrfType>, Vec<FrfType>)> = Vec::new();
    let mut limit_of: Vec<BTreeMap<FrfType, Vec<FrfType>>> = Vec::new();
    for m in &table.models {
        let a = &m.analysis;
        let model = Model::from_id(&a.generic_id)
            .map_err(|e| format!("{}: model {}: {e}", path.display(), a.generic_id))?;
        let with = |s: Status| -> Vec<FrfType> {
            a.types
                .iter()
                .filter(|v| v.status == s)
                .map(|v| v.frf_type.clone())
                .collect()
        };
        let unknown = with(Status::Unknown);
        if !unknown.is_empty() {
            // The degrees: the candidates include the type with every zero
            // positive and the one with every pole.
            let r = a.types.iter().map(|v| v.frf_type.resonances()).max();
            let z = a.types.iter().map(|v| v.frf_type.antiresonances()).max();
            let (r, z) = (r.unwrap_or(0), z.unwrap_or(0));
            let generic: Vec<FrfType> = with(Status::Possible)
                .into_iter()
                .filter(|g| g.is_generic(r))
                .collect();
            limit_of.push(
                unknown
                    .iter()
                    .map(|t| {
                        let from: Vec<FrfType> = generic
                            .iter()
                            .filter(|g| mms::analysis::gathers_into(g, t, z, r))
                            .cloned()
                            .collect();
                        (t.clone(), from)
                    })
                    .collect(),
            );
            models.push((a.id.clone(), model, unknown, with(Status::Impossible)));
        }
    }
    let mut jobs: Vec<(Model, mms::analysis::Cell)> = Vec::new();
    let mut of_model: Vec<Vec<usize>> = Vec::new();
    for (_, model, unknown, _) in &models {
        let source = analysis_source(model);
        let mut mine = Vec::new();
        for cell in cells(model, unknown) {
            // The source's names make the cell the same for its twins.
            let k = match jobs.iter().position(|(s, c)| *s == source && *c == cell) {
                Some(k) => k,
                None => {
                    jobs.push((source, cell));
                    jobs.len() - 1
                }
            };
            mine.push(k);
        }
        of_model.push(mine);
    }
    let samples = sample_all(&jobs, opts)?;
    let out: Vec<ModelSamples> = models
        .iter()
        .zip(&of_model)
        .zip(limit_of)
        .map(|(((id, _, _, impossible), mine), limit_of)| {
            let cells: Vec<CellSample> = mine.iter().map(|&k| samples[k].clone()).collect();
            let mut impossible_read = BTreeMap::new();
            for c in &cells {
                for (t, n) in &c.seen {
                    if impossible.contains(t) {
                        *impossible_read.entry(t.clone()).or_default() += n;
                    }
                }
            }
            ModelSamples {
                id: id.clone(),
                cells,
                impossible_read,
                limit_of,
            }
        })
        .collect();
    Ok(match opts.format {
        SampleFormat::Json => {
            let mut s = serde_json::to_string_pretty(&out).expect("the counts serialize");
            s.push('\n');
            s
        }
        SampleFormat::Md => markdown(&out, opts.starts, path, table.engine_version),
    })
}

/// Every job's counts, `opts.jobs` at a time, from the cache where it
/// holds them; in the order of `jobs`.
fn sample_all(
    jobs: &[(Model, mms::analysis::Cell)],
    opts: &Options,
) -> Result<Vec<CellSample>, String> {
    let total = jobs.len() as u64 * opts.starts;
    let progress = ProgressBar::new(total);
    progress.set_style(
        ProgressStyle::with_template(
            "{prefix} [{bar:30}] {percent}% of {len} starts, {elapsed} (eta {eta}) {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    progress.set_prefix("sample");
    progress.enable_steady_tick(std::time::Duration::from_secs(1));
    let fingerprint = format!(
        "sampler {}; starts {}; seed {SEED:#x}",
        mms::analysis::SAMPLER_VERSION,
        opts.starts
    );
    let one = |k: usize| -> Result<CellSample, String> {
        let job = &jobs[k];
        let name = cell_name(job);
        let file = opts.cache.as_ref().map(|d| d.join(format!("{name}.json")));
        if let Some(f) = &file {
            if let Ok(text) = std::fs::read_to_string(f) {
                match serde_json::from_str::<Entry>(&text) {
                    // The counts are the structure's; the types asked
                    // about are this table's.
                    Ok(mut e)
                        if e.fingerprint == fingerprint
                            && (
                                e.sample.cell.cancelled,
                                e.sample.cell.pairs,
                                &e.sample.cell.multiple,
                            ) == (job.1.cancelled, job.1.pairs, &job.1.multiple) =>
                    {
                        progress.inc(opts.starts);
                        e.sample.cell = job.1.clone();
                        return Ok(e.sample);
                    }
                    Ok(_) => {}
                    Err(e) => progress.suspend(|| {
                        eprintln!("mms: warning: {}: {e}; sampling again", f.display())
                    }),
                }
            }
        }
        // The seed depends on the cell alone, not on which other cells the
        // table has open, so a cached cell is the cell sampled afresh.
        let seed = SEED ^ crate::analyze_cache::fnv1a(name.as_bytes());
        let mut done = 0;
        let sample = sample_cell(&job.0, &job.1, opts.starts, seed, |i| {
            progress.inc(i - done);
            done = i;
        });
        if let Some(f) = &file {
            let entry = Entry {
                fingerprint: fingerprint.clone(),
                sample: sample.clone(),
            };
            let text = serde_json::to_string(&entry).expect("a cache entry serializes");
            write_atomic(f, &text)?;
        }
        Ok(sample)
    };
    let threads = crate::progress::threads(opts.jobs).clamp(1, jobs.len().max(1));
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<CellSample, String>>>> =
        Mutex::new((0..jobs.len()).map(|_| None).collect());
    let work = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        if k >= jobs.len() {
            break;
        }
        let r = one(k);
        results.lock().unwrap_or_else(|e| e.into_inner())[k] = Some(r);
    };
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(work);
        }
    });
    progress.finish_and_clear();
    results
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect()
}

/// A cell's name: the source model, its cancelled poles (and the pairs
/// among them, if any) and multiple zeros (also its cache file's name).
fn cell_name((model, cell): &(Model, mms::analysis::Cell)) -> String {
    let mults: Vec<String> = cell.multiple.iter().map(u32::to_string).collect();
    let pairs = match cell.pairs {
        0 => String::new(),
        p => format!("-p{p}"),
    };
    format!(
        "{}-c{}{pairs}-m{}",
        model.id(),
        cell.cancelled,
        mults.join("_")
    )
}

fn markdown(models: &[ModelSamples], starts: u64, path: &Path, engine: u32) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# The unknown types of {} on their own regions\n",
        path.display()
    );
    // A type is asked about in its structure's cell and, with cancelled
    // pairs, in their cells too: counted once per model, read if any of
    // them read it.
    let (mut types, mut read) = (0, 0);
    for m in models {
        let mut asked: BTreeMap<&FrfType, bool> = BTreeMap::new();
        for c in &m.cells {
            for t in &c.cell.types {
                *asked.entry(t).or_default() |= c.seen.contains_key(t);
            }
        }
        types += asked.len();
        read += asked.values().filter(|&&r| r).count();
    }
    let _ = writeln!(
        s,
        "`mms sample` (mms {}, sampler {}; the table of engine {engine}), {starts} starts per cell (coincidence \
         structure of a model's unknown types), log-uniform parameters within \
         e^-3 .. e^3, projected onto the cell's variety and read in f64 with the \
         posed roots divided out (points where the conditions' Jacobian drops \
         rank, or with two roots within a relative 1e-6, not read). Where the \
         chain's gap splits it into two blocks, a structure with two or more \
         cancelled poles is sampled again with pairs of them cancelled together \
         at an eigenvalue both blocks have (the column \"pairs\"): the single \
         structure cannot read those points. Evidence, not proof: a type read is possible in all \
         likelihood; one never read lies, if anywhere, in a region thinner than \
         the sampler reaches.\n",
        env!("CARGO_PKG_VERSION"),
        mms::analysis::SAMPLER_VERSION
    );
    let _ = writeln!(
        s,
        "{read} of the {types} unknown types were read at least once; {} never.\n",
        types - read
    );
    let flagged: Vec<String> = models
        .iter()
        .filter(|m| !m.impossible_read.is_empty())
        .map(|m| {
            let list: Vec<String> = m
                .impossible_read
                .iter()
                .map(|(t, n)| format!("`{t}` {n}"))
                .collect();
            format!("- {}: {}", m.id, list.join(", "))
        })
        .collect();
    if flagged.is_empty() {
        let _ = writeln!(
            s,
            "No point was read as a type the table certifies impossible.\n"
        );
    } else {
        let _ = writeln!(
            s,
            "Points read as types the table certifies impossible (an f64 misreading \
             or a wrong certificate; worth a look):\n\n{}\n",
            flagged.join("\n")
        );
    }
    let _ = writeln!(
        s,
        "| model | cancelled | pairs | multiple zeros | converged | read | unknown types (times read) |"
    );
    let _ = writeln!(s, "|---|---:|---:|---|---:|---:|---|");
    for m in models {
        for c in &m.cells {
            let mults: Vec<String> = c.cell.multiple.iter().map(u32::to_string).collect();
            let list: Vec<String> = c
                .cell
                .types
                .iter()
                .map(|t| format!("`{t}` {}", c.seen.get(t).copied().unwrap_or(0)))
                .collect();
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} |",
                m.id,
                c.cell.cancelled,
                c.cell.pairs,
                if mults.is_empty() {
                    "-".to_string()
                } else {
                    mults.join(", ")
                },
                c.converged,
                c.read,
                list.join(", ")
            );
        }
    }
    let _ = writeln!(
        s,
        "\n## Limits of possible generic types\n\nEvery point of a type is a limit of generic points (simple roots, every \
         pole) whose roots gather into it (docs/analysis.md, \"Limits of generic types\"). \
         Where only impossible generic types gather into a type, the analysis certifies it \
         impossible; each type below has possible generic types that gather into it, so \
         continuity leaves it open, and its witness, if any, lies next to points of them. \
         A type with none (\"-\") has an unknown generic type gathering into it, or the \
         rule's premises do not hold for its model.\n"
    );
    let _ = writeln!(
        s,
        "| model | unknown type | possible generic types gathering into it |"
    );
    let _ = writeln!(s, "|---|---|---|");
    for m in models {
        for (t, from) in &m.limit_of {
            let list: Vec<String> = from.iter().map(|g| format!("`{g}`")).collect();
            let _ = writeln!(
                s,
                "| {} | `{t}` | {} |",
                m.id,
                if list.is_empty() {
                    "-".to_string()
                } else {
                    format!("{}: {}", list.len(), list.join(", "))
                }
            );
        }
    }
    s
}
