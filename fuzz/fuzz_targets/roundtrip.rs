//! Read -> write -> read: whatever reads must write, and what is written must read back
//! with bit-identical knots, weights and control points (same units, no ops in between).
#![no_main]

use libfuzzer_sys::fuzz_target;
use nurbsx::exchange::{self, ExportOptions, Format};

fuzz_target!(|data: &[u8]| {
    let Ok(doc) = exchange::read(data, &Default::default()) else {
        return;
    };
    let options = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".into()),
        ..ExportOptions::default()
    };
    for format in [Format::Step, Format::Iges] {
        let Ok(text) = exchange::write(&doc, format, &options) else {
            continue;
        };
        let back = exchange::read(text.as_bytes(), &Default::default())
            .unwrap_or_else(|e| panic!("nurbsx wrote a file it cannot read: {e}"));
        assert_eq!(back.entities.len(), doc.entities.len(), "entity count changed");
        for (a, b) in doc.entities.iter().zip(&back.entities) {
            assert_eq!(a.geometry, b.geometry, "geometry changed in {format:?} round trip");
        }
    }
});
