//! `mms check FILE.json`: re-verifies the witnesses and certificates of an
//! `mms analyze --format json` file with the independent checker
//! ([`mms::check`]).

use std::path::Path;

/// The one-line summary, or the failing step prefixed by the file name;
/// `jobs` models at a time (0: one per core).
pub fn run(path: &Path, jobs: usize) -> Result<String, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let threads = match jobs {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    let report = mms::check::check_file_on(&text, threads)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(format!("{report}\n"))
}
