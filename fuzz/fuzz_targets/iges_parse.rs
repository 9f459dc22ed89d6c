//! The bare IGES parser (`nurbsx_parsers::iges::parse`): sections, Global, directory, then
//! every entity's parameter data and the typed 126/128 records, on arbitrary text. Must
//! never panic, hang or over-allocate.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nurbsx_parsers::iges::{self, records};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(file) = iges::parse(text) else {
        return;
    };
    for entry in file.entries.iter().flatten() {
        let _ = file.parameters(entry);
        let _ = file.decode::<records::Curve126>(entry);
        let _ = file.decode::<records::Surface128>(entry);
        let _ = file.decode::<records::Transform124>(entry);
        let _ = file.decode::<records::Loop508>(entry);
    }
});
