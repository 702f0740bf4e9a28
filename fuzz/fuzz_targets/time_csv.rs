//! A time-domain table (CSV) read as input and output columns, the
//! sample rate from its time column or given.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(table) = frf::csv::parse_table(text) {
        let names = table.names.clone();
        if names.len() >= 2 {
            let _ = frf::csv::time_series_from_table(&table, &names[0], &names[names.len() - 1], None);
            let _ = frf::csv::time_series_from_table(&table, &names[0], &names[1], Some(1000.0));
        }
    }
});
