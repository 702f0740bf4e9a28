//! The `--cache DIR` of `mms analyze`: one file per finished model, so that a
//! long run that is interrupted (Ctrl-C, a lost session) resumes where it
//! stopped instead of starting over.
//!
//! [`mms::analysis::ModelAnalysis`] serialises but does not deserialise, so
//! the cache holds the [`Summary`] of an analysis: exactly what every output
//! format renders, including the full analysis JSON of `--format json`.
//!
//! Invariants:
//! - A file `DIR/<generic model ID>.json` is written only after its model's
//!   analysis has finished, through a temporary file and a rename
//!   ([`crate::output::write_atomic`]), so it is either complete or absent,
//!   whenever the run is stopped. A run stopped during a write may leave a
//!   hidden `.<ID>.json.tmp<pid>` file; it is never read and may be deleted.
//! - A file is used only if its format tag, its fingerprint (cache layout
//!   version, `mms` version, search limits), its model ID and the checksum
//!   of its summary all match. Anything else (unreadable, not JSON, stale,
//!   edited, another model's) is reported as a warning on stderr, and the
//!   model is recomputed and its file rewritten; a bad file is never fatal
//!   and never used.
//! - A summary loaded from the cache renders to the same bytes as a fresh
//!   one: it holds only strings, integers, booleans and nulls (exact
//!   rationals are strings), which round-trip through JSON exactly. The
//!   checksum is taken over the compact serialisation and recomputed from
//!   the parsed value on load, so a summary that did not round-trip would be
//!   rejected rather than rendered differently.
//!
//! The checksum (FNV-1a, 64 bits) catches accidental damage and hand edits,
//! not deliberate forgery; the cache is a local work directory, not an
//! exchange format (`mms check` is the tool for untrusted results).

use crate::analyze::Summary;
use mms::analysis::SearchLimits;
use mms::Model;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

const FORMAT: &str = "mms-analyze-cache";

/// The layout of [`Summary`] and [`Entry`]. Bump it whenever either changes,
/// or the analysis changes its results without a change of the crate
/// version, so that old files are recomputed rather than misread.
const LAYOUT_VERSION: u32 = 8;

/// One cache file.
#[derive(Serialize, Deserialize)]
struct Entry {
    format: String,
    fingerprint: String,
    /// The generic ID of the model (also the file name).
    model: String,
    /// Wall time the analysis took when it was computed.
    seconds: f64,
    /// `fnv1a64:` and 16 hex digits, over the compact JSON of `summary`.
    checksum: String,
    summary: serde_json::Value,
}

/// A cache directory for one configuration of the analysis.
pub struct Cache {
    dir: PathBuf,
    fingerprint: String,
}

/// A summary found in the cache, with the time it took to compute.
pub struct Hit {
    pub summary: Summary,
    pub seconds: f64,
}

impl Cache {
    /// Opens (creating it if needed) the cache directory for analyses with
    /// `limits`.
    pub fn open(dir: &Path, limits: &SearchLimits) -> Result<Cache, String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create cache directory: {e}", dir.display()))?;
        Ok(Cache {
            dir: dir.to_path_buf(),
            fingerprint: format!(
                "cache layout {LAYOUT_VERSION}; mms {} engine {}; {limits:?}",
                env!("CARGO_PKG_VERSION"),
                mms::analysis::ENGINE_VERSION
            ),
        })
    }

    fn path(&self, model: &Model) -> PathBuf {
        self.dir.join(format!("{}.json", model.id()))
    }

    /// The cached summary of `model`: `Ok(None)` when there is no file,
    /// `Err` (a message naming the file) when there is one that cannot be
    /// used.
    pub fn load(&self, model: &Model) -> Result<Option<Hit>, String> {
        let path = self.path(model);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(format!("{}: cannot read: {e}", path.display())),
        };
        let bad = |why: &str| format!("{}: {why}", path.display());
        let entry: Entry =
            serde_json::from_str(&text).map_err(|e| bad(&format!("not a cache file ({e})")))?;
        if entry.format != FORMAT {
            return Err(bad("not a cache file (format tag)"));
        }
        if entry.fingerprint != self.fingerprint {
            return Err(bad(&format!(
                "stale (written for \"{}\", this run is \"{}\")",
                entry.fingerprint, self.fingerprint
            )));
        }
        let id = model.id();
        if entry.model != id {
            return Err(bad(&format!("holds model {}, not {id}", entry.model)));
        }
        if entry.checksum != checksum(&entry.summary)? {
            return Err(bad("checksum mismatch (damaged or edited)"));
        }
        let summary: Summary = serde_json::from_value(entry.summary)
            .map_err(|e| bad(&format!("unreadable summary ({e})")))?;
        if summary.generic_id != id {
            return Err(bad(&format!(
                "summary of model {}, not {id}",
                summary.generic_id
            )));
        }
        Ok(Some(Hit {
            summary,
            seconds: entry.seconds,
        }))
    }

    /// Stores the summary of `model` (atomically).
    pub fn store(&self, model: &Model, summary: &Summary, seconds: f64) -> Result<(), String> {
        let summary = serde_json::to_value(summary).map_err(|e| e.to_string())?;
        let entry = Entry {
            format: FORMAT.to_string(),
            fingerprint: self.fingerprint.clone(),
            model: model.id(),
            seconds,
            checksum: checksum(&summary)?,
            summary,
        };
        let text = serde_json::to_string_pretty(&entry).map_err(|e| e.to_string())? + "\n";
        crate::output::write_atomic(&self.path(model), &text)
    }
}

fn checksum(v: &serde_json::Value) -> Result<String, String> {
    let text = serde_json::to_string(v).map_err(|e| e.to_string())?;
    Ok(format!("fnv1a64:{:016x}", fnv1a(text.as_bytes())))
}

/// FNV-1a, 64 bits: a checksum that stays the same across versions of
/// Rust and platforms (unlike `std`'s hashers).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}
