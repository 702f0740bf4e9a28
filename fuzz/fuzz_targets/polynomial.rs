//! The polynomial text form: every accepted polynomial prints to a text
//! that reads back to it.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(p) = text.parse::<poly::Poly>() {
        let back: poly::Poly = p.to_string().parse().expect("a printed polynomial reads back");
        assert_eq!(back, p);
    }
});
