//! Hostile input: random truncations and byte substitutions of a valid IGES file must give
//! a document or a located error, never a panic (pitfalls.md G31). Also a hand-made hostile
//! header (K = 2^31 - 1) that must be refused without allocating.
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../parsers/tests/iges_support/mod.rs"]
mod iges_util;

use iges_util::{Builder, De};
use nurbsx::exchange::{self, ImportOptions};
use proptest::prelude::*;

fn valid_file() -> String {
    let mut b = Builder::new(",,4Htest,8Hfile.igs,,,,,,,,,1.,2,2HMM,,,,1.E-7,,,,11,0,;");
    let t = b.entity(
        De {
            ty: 124,
            ..De::default()
        },
        "124,0.,-1.,0.,10.,1.,0.,0.,20.,0.,0.,1.,30.;",
    );
    b.entity(
        De { transform: t as i64, ..De::default() },
        "126,3,2,0,0,1,0,0.,0.,0.,0.5,1.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,2.,2.,1.,-1.,3.,3.,0.5,0.,1.;",
    );
    let s = b.entity(
        De { ty: 128, ..De::default() },
        "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;",
    );
    b.entity(
        De {
            ty: 144,
            ..De::default()
        },
        &format!("144,{s},1,0,0;"),
    );
    b.entity(
        De {
            ty: 102,
            ..De::default()
        },
        "102,2,3,999999999;",
    );
    b.build()
}

fn check(text: &str) {
    match exchange::iges::read(text, &ImportOptions::default()) {
        Ok(doc) => {
            for d in &doc.diagnostics {
                let _ = d.to_string();
            }
        }
        Err(e) => assert!(
            e.location.line.is_some() || e.location.section.is_some(),
            "{e}"
        ),
    }
}

#[test]
fn the_valid_file_reads() {
    let doc = exchange::iges::read(&valid_file(), &ImportOptions::default()).unwrap();
    // The file's curve and surface, and the four sides of the domain that bounds its 144
    // (N1 = 0: the face's outer loop).
    let boundary = |e: &&nurbsx::exchange::Entity| e.source.entity == "144 (domain boundary)";
    assert_eq!(doc.entities.iter().filter(|e| !boundary(e)).count(), 2);
    assert_eq!(doc.entities.iter().filter(boundary).count(), 4);
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
}

#[test]
fn huge_counts_are_refused_cleanly() {
    for line in [
        "126,2147483647,3,0,0,1,0,0.,0.,1.;",
        "126,9223372036854775807,3,0,0,1,0,0.,0.,1.;",
        "128,2147483647,2147483647,3,3,0,0,1,0,0,0.;",
        "128,-5,1,1,1,0,0,1,0,0,0.;",
        "126,3,0,0,0,1,0,0.;",
    ] {
        let mut b = Builder::new(",,;");
        b.entity(
            De {
                ty: line[..3].parse().unwrap(),
                ..De::default()
            },
            line,
        );
        let doc = exchange::iges::read(&b.build(), &ImportOptions::default()).unwrap();
        assert!(doc.entities.is_empty());
        let d = doc
            .diagnostics
            .iter()
            .find(|d| d.code == "iges.entity")
            .unwrap();
        assert_eq!(d.location.entity.as_deref(), Some("D1"), "{line}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn truncations_never_panic(cut in 0usize..2000) {
        let text = valid_file();
        let cut = cut.min(text.len());
        check(&text[..cut]);
    }

    #[test]
    fn substitutions_never_panic(
        edits in proptest::collection::vec((0usize..2000, prop::sample::select(
            b"0123456789,;H .-+ED\nPGT9".to_vec())), 1..6)
    ) {
        let mut bytes = valid_file().into_bytes();
        let len = bytes.len();
        for (pos, c) in edits {
            bytes[pos % len] = c;
        }
        let text = String::from_utf8(bytes).unwrap();
        check(&text);
    }
}
