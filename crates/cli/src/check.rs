//! `mms check FILE.json`: re-verifies the witnesses and certificates of an
//! `mms analyze --format json` file with the independent checker
//! ([`mms::check`]), showing progress on stderr and, with `--cache DIR`,
//! keeping a record of every model it verified.
//!
//! The record (`DIR/<model ID>.json`) holds the model's entry as the file
//! gave it (without `similar`, which depends on the whole table) and the
//! report of its check, by this `mms` version and
//! [`mms::check::CHECKER_VERSION`]. A later check reuses it only for an
//! entry equal to the recorded one, so an interrupted check resumes, and
//! the table merged from checked slices, whose entries are the slices'
//! own, is checked without checking its models twice; coverage and the
//! similar systems, which depend on the whole file, are checked every
//! time. A record is as trustworthy as the directory that holds it: it is
//! the user's own memory of checks, not something to accept from others.
//! Unreadable, stale or foreign records are reported and the model is
//! checked again.

use crate::output::write_atomic;
use crate::progress::ModelProgress;
use mms::check::{CheckHooks, CheckReport, CHECKER_VERSION};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

const FORMAT: &str = "mms-check-record";

/// The layout of [`Record`]; raise it when the layout changes.
const LAYOUT_VERSION: u32 = 1;

/// One record of a verified model.
#[derive(Serialize, Deserialize)]
struct Record {
    format: String,
    fingerprint: String,
    /// The model's ID (also the file name).
    model: String,
    report: CheckReport,
    /// The model's entry exactly as checked (without `similar`).
    entry: Value,
}

/// The one-line summary, or the failing step prefixed by the file name;
/// `jobs` models at a time (0: one per core), keeping and reusing records
/// in `cache` when given.
pub fn run(path: &Path, jobs: usize, cache: Option<&Path>) -> Result<String, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let threads = crate::progress::threads(jobs);
    if let Some(dir) = cache {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create cache directory: {e}", dir.display()))?;
    }
    let hooks = Hooks::new(cache);
    let result = mms::check::check_file_with(&text, threads, &hooks);
    hooks.progress.bar.finish_and_clear();
    let report = result.map_err(|e| format!("{}: {e}", path.display()))?;
    let recalled = hooks.recalled.load(Ordering::Relaxed);
    let mut line = report.to_string();
    if recalled > 0 {
        let dir = cache.map_or(String::new(), |d| d.display().to_string());
        line.push_str(&format!(
            "; {recalled} of {} models by their records in {dir}",
            report.models
        ));
    }
    Ok(line + "\n")
}

/// Progress on stderr (indicatif draws nothing when it is not a terminal)
/// and the records.
struct Hooks {
    dir: Option<PathBuf>,
    fingerprint: String,
    progress: ModelProgress,
    recalled: AtomicUsize,
}

impl Hooks {
    fn new(dir: Option<&Path>) -> Hooks {
        Hooks {
            dir: dir.map(Path::to_path_buf),
            fingerprint: format!(
                "check record layout {LAYOUT_VERSION}; mms {} checker {CHECKER_VERSION}",
                env!("CARGO_PKG_VERSION")
            ),
            progress: ModelProgress::new("check", 0),
            recalled: AtomicUsize::new(0),
        }
    }

    fn path(&self, id: &str) -> Option<PathBuf> {
        // IDs are generic or paper IDs; anything else never names a file.
        let plain = !id.is_empty()
            && id
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '.' || c == '*');
        Some(self.dir.as_ref()?.join(format!("{id}.json"))).filter(|_| plain)
    }

    fn warn(&self, why: &str) {
        self.progress
            .bar
            .suspend(|| eprintln!("mms: warning: {why}; checking the model again"));
    }

    /// The record at `path` for `entry`: `Ok(None)` when there is none or
    /// it records another entry, `Err` when it cannot be used.
    fn load(&self, path: &Path, entry: &Value) -> Result<Option<CheckReport>, String> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(format!("{}: cannot read: {e}", path.display())),
        };
        let bad = |why: &str| format!("{}: {why}", path.display());
        let record: Record =
            serde_json::from_str(&text).map_err(|e| bad(&format!("not a check record ({e})")))?;
        if record.format != FORMAT {
            return Err(bad("not a check record (format tag)"));
        }
        if record.fingerprint != self.fingerprint {
            return Err(bad(&format!(
                "stale (written by \"{}\", this check is \"{}\")",
                record.fingerprint, self.fingerprint
            )));
        }
        // Another table's entry for the same ID (another engine, an edited
        // file) is simply checked again, and its record replaced.
        Ok(
            (record.entry == *entry && Some(record.model.as_str()) == entry["id"].as_str())
                .then_some(record.report),
        )
    }
}

impl CheckHooks for Hooks {
    fn planned(&self, count: usize) {
        self.progress.bar.set_length(count as u64);
    }

    fn recall(&self, entry: &Value) -> Option<CheckReport> {
        let path = self.path(entry["id"].as_str()?)?;
        match self.load(&path, entry) {
            Ok(Some(report)) => {
                self.recalled.fetch_add(1, Ordering::Relaxed);
                Some(report)
            }
            Ok(None) => None,
            Err(why) => {
                self.warn(&why);
                None
            }
        }
    }

    fn checked(&self, entry: &Value, report: &CheckReport) {
        let Some(id) = entry["id"].as_str() else {
            return;
        };
        let Some(path) = self.path(id) else { return };
        let record = Record {
            format: FORMAT.to_string(),
            fingerprint: self.fingerprint.clone(),
            model: id.to_string(),
            report: report.clone(),
            entry: entry.clone(),
        };
        // A record that cannot be written costs a check next time, never
        // this one.
        let written = serde_json::to_string(&record)
            .map_err(|e| e.to_string())
            .and_then(|text| write_atomic(&path, &(text + "\n")));
        if let Err(why) = written {
            self.progress
                .bar
                .suspend(|| eprintln!("mms: warning: {why}; the model is not recorded"));
        }
    }

    fn started(&self, id: &str) {
        self.progress.start(&[id.to_string()]);
    }

    fn finished(&self, id: &str) {
        self.progress.end(&[id.to_string()]);
        self.progress.bar.inc(1);
    }
}
