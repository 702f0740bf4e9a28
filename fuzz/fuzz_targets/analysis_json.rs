//! An analysis file handed to `mms check`: refused or checked, never a
//! panic or a hang (libFuzzer's timeout catches the latter).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = mms::check::check_file(text);
});
