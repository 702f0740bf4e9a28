//! A headerless numeric matrix: every accepted one is rectangular.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(m) = frf::csv::parse_matrix(text) {
        assert_eq!(m.columns.len(), m.cols);
        assert!(m.columns.iter().all(|c| c.len() == m.rows));
    }
});
