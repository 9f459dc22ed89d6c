//! The bare IGES parser (`nurbsx_parsers::iges::parse`): sections, Global, directory, then
//! every entity's parameter data and the typed 126/128 records, on arbitrary text. Must
//! never panic, hang or over-allocate.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nurbsx_parsers::iges::{self, schema};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(file) = iges::parse(text) else {
        return;
    };
    for entry in file.entries.iter().flatten() {
        let Ok(p) = file.parameters(entry) else {
            continue;
        };
        let _ = schema::Curve126::from_params(&p);
        let _ = schema::Surface128::from_params(&p);
    }
});
