//! The direct decoding path against the general one (tokens, `from_params`, `Grid::from_fn`):
//! the same document, bit for bit (every pole, weight and knot, compared through `{:?}`,
//! which prints each `f64` exactly and tells `-0.0` from `0.0`), with the same diagnostics in
//! the same order, on every IGES file in the repository (FreeCAD samples, bad and odd inputs,
//! fuzz regressions) and on random documents written by the IGES writer, with and without
//! unit conversion.

use super::{Path, read_with};
use crate::exchange::test_documents::random_document;
use crate::exchange::test_files::repository_files;
use crate::exchange::{ExportOptions, Format, ImportOptions, LengthUnit};

fn option_variants() -> Vec<ImportOptions> {
    let converted = ImportOptions {
        target_units: Some(LengthUnit::In),
        ..ImportOptions::default()
    };
    let mut small = ImportOptions::default();
    small.limits.max_params_per_entity = 40;
    small.limits.max_poles = 6;
    vec![ImportOptions::default(), converted, small]
}

/// Reads `text` both ways with every option variant and compares.
fn assert_same(text: &str, what: &str) {
    for options in option_variants() {
        let direct = read_with(text, &options, Path::Direct);
        let general = read_with(text, &options, Path::General);
        assert_eq!(
            format!("{direct:?}"),
            format!("{general:?}"),
            "{what}: the direct and general paths differ"
        );
    }
}

#[test]
fn repository_files_read_identically() {
    let files = repository_files(&["samples", "tests"], &["igs", "iges"]);
    assert!(files.len() >= 50, "only {} IGES files found", files.len());
    let mut surfaces = 0;
    for path in &files {
        let bytes = std::fs::read(path).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert_same(&text, &path.display().to_string());
        if let Ok(doc) = read_with(&text, &ImportOptions::default(), Path::Direct) {
            surfaces += doc
                .entities
                .iter()
                .filter(|e| matches!(e.geometry, crate::nurbs::Geometry::Surface(_)))
                .count();
        }
    }
    assert!(
        surfaces > 10,
        "only {surfaces} surfaces read: the comparison is too thin"
    );
}

#[test]
fn written_documents_read_identically() {
    for seed in 0..300u64 {
        let doc = random_document(seed, Format::Iges);
        for units in [None, Some(LengthUnit::M)] {
            let options = ExportOptions {
                units,
                timestamp: Some("2026-01-01T00:00:00".to_owned()),
                ..ExportOptions::default()
            };
            let Ok(text) = crate::exchange::iges::write(&doc, &options) else {
                continue;
            };
            assert_same(&text, &format!("random document {seed}"));
            // Damaged copies: one byte of the P section changed, one P line dropped.
            let p_start = text.find("P      1").map_or(0, |i| i.saturating_sub(72));
            for (k, c) in [
                (3usize, b'x'),
                (17, b','),
                (29, b';'),
                (41, b' '),
                (55, b'D'),
            ] {
                let mut b = text.clone().into_bytes();
                let at = p_start + (seed as usize * 13 + k * 7) % (b.len() - p_start).max(1);
                if at < b.len() && b[at] != b'\n' {
                    b[at] = c;
                }
                assert_same(
                    &String::from_utf8_lossy(&b),
                    &format!("damaged document {seed}/{k}"),
                );
            }
        }
    }
}
