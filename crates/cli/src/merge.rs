//! `mms merge`: reads the slices of a table and joins them
//! ([`mms::table::merge`]).

use mms::table::{merge, AnalysisTable};
use std::path::PathBuf;

/// The whole table as JSON, or the first problem naming its file.
pub fn run(files: &[PathBuf]) -> Result<String, String> {
    let mut slices = Vec::with_capacity(files.len());
    for path in files {
        let name = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{name}: cannot read: {e}"))?;
        let table = AnalysisTable::from_json(&text).map_err(|e| format!("{name}: {e}"))?;
        slices.push((name, table));
    }
    Ok(merge(slices).map_err(|e| e.to_string())?.to_json())
}
