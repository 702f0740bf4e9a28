//! A MATLAB .mat file (level 5, compressed or not), and a walk over what
//! it holds.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(file) = frf::mat::read_mat(data) {
        for v in &file.variables {
            let _ = (v.numel(), v.scalar(), v.shape2());
            let _ = file.fields(&v.name);
        }
    }
});
