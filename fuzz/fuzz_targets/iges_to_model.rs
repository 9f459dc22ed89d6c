//! IGES bytes -> model: must never panic, hang or blow memory, whatever the input.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = nurbsx::exchange::read(data, &Default::default());
    // Force the IGES path too: a valid-looking Start record followed by the fuzz data.
    let mut bytes = format!("{:<72}S{:>7}\n", "", 1).into_bytes();
    bytes.extend_from_slice(data);
    let _ = nurbsx::exchange::read(&bytes, &Default::default());
    // The conformance checks of `validate` (every entity's declared pointers, cycles).
    let validate = nurbsx::exchange::ImportOptions {
        conformance: true,
        ..Default::default()
    };
    let _ = nurbsx::exchange::read(&bytes, &validate);
});
