//! Universal file format, dataset 58.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = frf::uff::parse_uff(data);
});
