//! An FRF table (CSV): parsed, and every accepted FRF written back and
//! read again to the same lines.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(frf) = frf::csv::parse_frf_csv(text) {
        let back = frf::csv::write_csv(&frf, frf::csv::CsvLayout::ReIm);
        let again = frf::csv::parse_frf_csv(&back).expect("a written FRF reads back");
        assert_eq!(again.freq_hz().len(), frf.freq_hz().len());
    }
});
