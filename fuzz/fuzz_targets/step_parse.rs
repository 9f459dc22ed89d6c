//! The bare STEP parser (`nurbsx_parsers::step::parse`): scan + decode every instance +
//! reference checks, on arbitrary text. Must never panic, hang or over-allocate.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nurbsx_parsers::{Limits, step};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = step::parse(text, &Limits::default());
});
