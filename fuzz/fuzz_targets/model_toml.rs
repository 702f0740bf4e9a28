//! A model file (TOML), with and without further sensors.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = mms::model_file::ModelFile::parse(text);
    let _ = mms::model_file::ModelFile::parse_with_sensors(text);
});
