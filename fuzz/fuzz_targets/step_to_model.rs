//! STEP bytes -> model: must never panic, hang or blow memory, whatever the input.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut bytes = b"ISO-10303-21;\n".to_vec();
    bytes.extend_from_slice(data);
    let _ = nurbsx::exchange::read(&bytes, &Default::default());
    let _ = nurbsx::exchange::read(data, &Default::default());
    // The conformance checks of `validate` (every instance decoded, references, cycles).
    let validate = nurbsx::exchange::ImportOptions {
        conformance: true,
        ..Default::default()
    };
    let _ = nurbsx::exchange::read(&bytes, &validate);
});
