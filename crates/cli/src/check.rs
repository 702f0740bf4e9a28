//! `mms check FILE.json`: re-verifies the witnesses and certificates of an
//! `mms analyze --format json` file with the independent checker
//! ([`mms::check`]).

use std::path::Path;

/// The one-line summary, or the failing step prefixed by the file name.
pub fn run(path: &Path) -> Result<String, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let report = mms::check::check_file(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(format!("{report}\n"))
}
