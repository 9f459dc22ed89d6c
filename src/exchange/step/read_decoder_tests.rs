//! The STEP B-spline decoder ([`Scanned::bspline`], with its private one-pass text reader)
//! gives exactly the record of the general path (the grammar, then the records' attribute
//! reader), errors included: on every repository file, on written files and on damaged
//! copies, under default and tight parameter limits.

use super::*;
use crate::exchange::ExportOptions;
use crate::exchange::test_files::repository_files;
use crate::nurbs::Grid;
use nurbsx_parsers::Limits;
use nurbsx_parsers::step::scan;
use nurbsx_parsers::step::schema::{At, BSplineKind, bspline_kind};
use proptest::prelude::*;

/// The general path, written out: decode the instance, classify it, read its attributes.
fn general<'a>(s: &Scanned<'a>, raw: &RawInstance<'a>) -> Result<Option<BSpline<'a>>, DecodeError> {
    let inst = s.decode(raw)?;
    let (line, column) = s.locate(raw.offset());
    let at = At {
        id: raw.id,
        line,
        column,
    };
    Ok(match bspline_kind(&inst.body) {
        None => None,
        Some(BSplineKind::Curve) => Some(BSpline::Curve(BSplineCurve::from_instance(&inst, at)?)),
        Some(BSplineKind::Surface) => {
            Some(BSpline::Surface(BSplineSurface::from_instance(&inst, at)?))
        }
    })
}

/// Every instance decodes the same through the decoder and the general path (compared as
/// `Debug` text too, which keeps `-0.0` and NaN bits apart where `PartialEq` would not);
/// returns how many B-splines decoded.
fn same_both_ways(text: &str, limits: &Limits) -> usize {
    let Ok(s) = scan(text, limits) else {
        return 0;
    };
    let mut decoded = 0;
    for raw in &s.instances {
        let one = s.bspline(raw);
        let two = general(&s, raw);
        assert_eq!(format!("{one:?}"), format!("{two:?}"), "#{}", raw.id);
        assert_eq!(one, two);
        decoded += usize::from(matches!(one, Ok(Some(_))));
    }
    decoded
}

#[test]
fn repository_files_decode_the_same_both_ways() {
    let paths = repository_files(&["samples", "tests"], &["step", "stp"]);
    assert!(paths.len() > 50, "sample files not found");
    let mut entities = 0;
    for p in &paths {
        let Ok(text) = std::fs::read_to_string(p) else {
            continue;
        };
        let decoded = same_both_ways(&text, &Limits::default());
        if p.to_string_lossy().contains("samples/freecad") {
            entities += decoded;
        }
    }
    assert!(
        entities > 100,
        "only {entities} B-splines decoded in the FreeCAD samples"
    );
}

/// A fixed-seed 64-bit LCG (deterministic documents).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn int(&mut self, lo: usize, hi: usize) -> usize {
        lo + ((self.next() * (hi - lo + 1) as f64) as usize).min(hi - lo)
    }
}

fn clamped_knots(rng: &mut Lcg, p: usize, n: usize) -> Vec<f64> {
    let scale = 1.0 + 99.0 * rng.next();
    let mut inner: Vec<f64> = (1..n - p).map(|_| rng.next() * scale).collect();
    inner.sort_by(f64::total_cmp);
    let mut k = vec![-scale * 0.25; p + 1];
    k.extend(inner);
    k.extend(std::iter::repeat_n(scale, p + 1));
    k
}

/// Curves and surfaces, rational or not, with names that need `''` escapes.
fn document(seed: u64, count: usize) -> Document {
    let mut rng = Lcg(seed);
    let mut doc = Document::new(Format::Step, LengthUnit::Mm);
    for i in 0..count {
        let pole = |rng: &mut Lcg| {
            [
                1e3 * (rng.next() - 0.5),
                1e-3 * rng.next(),
                -(rng.next() * 10.0),
            ]
        };
        let geometry = if rng.next() < 0.5 {
            let p = rng.int(1, 5);
            let n = rng.int(p + 1, p + 12);
            let k = clamped_knots(&mut rng, p, n);
            let pts = (0..n).map(|_| pole(&mut rng)).collect();
            let w = (rng.next() < 0.5).then(|| (0..n).map(|_| 0.5 + rng.next()).collect());
            Geometry::Curve(NurbsCurve::new(p, k, pts, w).expect("valid curve"))
        } else {
            let (pu, pv) = (rng.int(1, 3), rng.int(1, 3));
            let (nu, nv) = (rng.int(pu + 1, pu + 5), rng.int(pv + 1, pv + 5));
            let ku = clamped_knots(&mut rng, pu, nu);
            let kv = clamped_knots(&mut rng, pv, nv);
            let pts = Grid::from_fn(nu, nv, |_, _| pole(&mut rng));
            let w = (rng.next() < 0.5).then(|| Grid::from_fn(nu, nv, |_, _| 0.5 + rng.next()));
            Geometry::Surface(NurbsSurface::new(pu, pv, ku, kv, pts, w).expect("valid surface"))
        };
        doc.entities.push(Entity {
            id: compact_str::format_compact!("E{i}"),
            geometry,
            source: Source::default(),
            meta: Meta {
                name: (i % 3 == 0).then(|| format!("part {i} o'clock")),
                ..Meta::default()
            },
        });
    }
    doc
}

fn written(seed: u64, count: usize) -> String {
    let opts = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".to_owned()),
        ..ExportOptions::default()
    };
    super::super::write::write(&document(seed, count), &opts).expect("document writes")
}

#[test]
fn written_files_decode_the_same_both_ways() {
    for seed in 1..6 {
        let text = written(seed, 30);
        assert_eq!(same_both_ways(&text, &Limits::default()), 30, "seed {seed}");
        // And the document read is the one written (entity count; values are the
        // round-trip tests' business).
        let doc = read(&text, &ImportOptions::default()).expect("reads");
        assert_eq!(doc.entities.len(), 30);
    }
}

/// The written file, one statement per B-spline instance, as offsets.
fn bspline_spans(text: &str) -> Vec<(usize, usize)> {
    let limits = Limits::default();
    let Ok(s) = scan(text, &limits) else {
        return Vec::new();
    };
    s.instances
        .iter()
        .filter(|r| matches!(s.bspline(r), Ok(Some(_))))
        .map(|r| (r.body_offset(), r.body_offset() + r.body_len()))
        .collect()
}

#[derive(Debug, Clone)]
enum Edit {
    Delete(usize),
    Duplicate(usize),
    Replace(usize, u8),
    Insert(usize, &'static str),
    /// `1.` -> `1`: an INTEGER where a REAL is expected (the general path widens it).
    Integer(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    let bytes = prop::sample::select(b"#(),.'$*/ 0123456789E+-_AFTUX\t\n".to_vec());
    let inserts = prop::sample::select(vec![
        " ", "\r\n", "\t", "/* c */", "''", "'", "(", ")", ",", "1", "$", "E5", "A()", "#0",
    ]);
    prop_oneof![
        any::<usize>().prop_map(Edit::Delete),
        any::<usize>().prop_map(Edit::Duplicate),
        (any::<usize>(), bytes).prop_map(|(i, c)| Edit::Replace(i, c)),
        (any::<usize>(), inserts).prop_map(|(i, s)| Edit::Insert(i, s)),
        any::<usize>().prop_map(Edit::Integer),
    ]
}

/// Applies `edits` inside the body `lo..hi` of one instance.
fn apply(text: &str, (lo, hi): (usize, usize), edits: &[Edit]) -> String {
    let mut b = text.as_bytes().to_vec();
    let mut hi = hi;
    for e in edits {
        if hi <= lo + 1 {
            break;
        }
        let at = |i: usize| lo + i % (hi - lo);
        match e {
            Edit::Delete(i) => {
                b.remove(at(*i));
                hi -= 1;
            }
            Edit::Duplicate(i) => {
                let k = at(*i);
                b.insert(k, b[k]);
                hi += 1;
            }
            Edit::Replace(i, c) => {
                let k = at(*i);
                b[k] = *c;
            }
            Edit::Insert(i, s) => {
                let k = at(*i);
                b.splice(k..k, s.bytes());
                hi += s.len();
            }
            Edit::Integer(n) => {
                let spots: Vec<usize> = (lo + 1..hi)
                    .filter(|&k| {
                        b[k] == b'.'
                            && b[k - 1].is_ascii_digit()
                            && matches!(b.get(k + 1), Some(b',' | b')'))
                    })
                    .collect();
                if !spots.is_empty() {
                    b.remove(spots[n % spots.len()]);
                    hi -= 1;
                }
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

fn base_file() -> &'static (String, Vec<(usize, usize)>) {
    static CACHE: std::sync::OnceLock<(String, Vec<(usize, usize)>)> = std::sync::OnceLock::new();
    CACHE.get_or_init(|| {
        let text = written(7, 12);
        let spans = bspline_spans(&text);
        (text, spans)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    /// Damaged copies of a written file (bytes deleted, duplicated, replaced, whitespace
    /// and comments inserted, reals turned into integers, in one B-spline body) read the
    /// decode the same through the decoder and the general path, errors included, under
    /// default and tight parameter limits.
    #[test]
    fn damaged_files_read_the_same(
        pick in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..4),
        max_params in 10usize..400,
        max_depth in 1usize..4,
    ) {
        let (text, spans) = base_file();
        prop_assume!(!spans.is_empty());
        let damaged = apply(text, *pick.get(spans), &edits);
        same_both_ways(&damaged, &Limits::default());
        let tight = Limits {
            max_params_per_entity: max_params,
            max_nesting_depth: max_depth,
            ..Limits::default()
        };
        same_both_ways(&damaged, &tight);
    }
}
