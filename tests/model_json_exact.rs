//! Model JSON keeps every f64 bit for bit: a control point written with Rust's shortest
//! round-trip digits (`{:?}`, as nurbsx writes) and read back by nurbsx's model JSON
//! reader is the same number. A JSON number parser that rounds long decimals through a
//! fast approximate path gets some of them one ulp off (seen on fitted curves); this test
//! draws a million bit patterns spread over the whole exponent range.

// Helpers outside #[test] functions panic on purpose: a failed helper is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nurbsx::nurbs::Geometry;
use nurbsx::pipeline::{InputKind, Settings, load};

/// SplitMix64 (Steele, Lea, Flood 2014): a fixed, reproducible stream of bit patterns.
fn splitmix(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[test]
fn model_json_reads_back_every_bit() {
    let mut state = 7;
    let per_file = 20_000;
    let files = if cfg!(debug_assertions) { 10 } else { 50 };
    let mut checked = 0usize;
    for _ in 0..files {
        let mut xs = Vec::with_capacity(per_file);
        while xs.len() < per_file {
            let x = f64::from_bits(splitmix(&mut state));
            if x.is_finite() {
                xs.push(x);
            }
        }
        // A degree-1 curve through the numbers as 3-D poles.
        let n = xs.len() / 3;
        let poles: Vec<String> = xs
            .chunks(3)
            .take(n)
            .map(|p| format!("[{:?},{:?},{:?}]", p[0], p[1], p[2]))
            .collect();
        let knots: Vec<String> = (0..n + 2)
            .map(|i| format!("{:?}", i.clamp(1, n) as f64))
            .collect();
        let text = format!(
            "{{\"degree\":1,\"knots\":[{}],\"control_points\":[{}]}}",
            knots.join(","),
            poles.join(",")
        );
        let loaded = load(text.as_bytes(), Some(InputKind::Json), &Settings::default()).unwrap();
        let Geometry::Curve(c) = &loaded.document.entities[0].geometry else {
            panic!("a curve");
        };
        for (got, want) in c.control_points().iter().flatten().zip(&xs) {
            assert_eq!(got.to_bits(), want.to_bits(), "{want:?} read as {got:?}");
            checked += 1;
        }
    }
    assert_eq!(checked, files * (per_file / 3) * 3);
}
