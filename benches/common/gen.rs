//! Deterministic generator of large, realistic B-spline documents (shared by
//! `examples/gen_large.rs`, `examples/throughput.rs` and `benches/exchange.rs`).
//!
//! The mix imitates what Open CASCADE writes for a mechanical part: mostly surfaces
//! (bicubic 8x8 .. 20x20, some other degrees), a third of them rational, and curves of
//! degree 1..9 (a third rational, so they become the 7-part complex instances in STEP),
//! clamped and unclamped knot vectors, coordinates with full f64 precision. The PRNG is a
//! fixed-seed 64-bit LCG so every run writes the same bytes.

use nurbsx::exchange::{Document, Entity, Format, LengthUnit, Meta, Source};
use nurbsx::nurbs::{Geometry, Grid, NurbsCurve, NurbsSurface};

/// A tiny fixed-seed PRNG (Knuth's MMIX LCG, top 53 bits).
pub struct Lcg(pub u64);

impl Lcg {
    /// Uniform in `[0, 1)`.
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform integer in `lo..=hi`.
    pub fn int(&mut self, lo: usize, hi: usize) -> usize {
        lo + ((self.next() * (hi - lo + 1) as f64) as usize).min(hi - lo)
    }
}

/// A knot vector for `n` poles of degree `p`: clamped (multiplicity p+1 at the ends) or
/// unclamped (uniform), with a random parameter scale as CAD systems produce.
fn knots(rng: &mut Lcg, p: usize, n: usize, clamped: bool) -> Vec<f64> {
    let scale = 1.0 + 99.0 * rng.next();
    let m = n + p + 1;
    if clamped {
        let spans = n - p;
        let mut inner: Vec<f64> = (1..spans).map(|_| rng.next()).collect();
        inner.sort_by(f64::total_cmp);
        let mut k = vec![0.0; p + 1];
        k.extend(inner.iter().map(|x| x * scale));
        k.extend(std::iter::repeat_n(scale, p + 1));
        k
    } else {
        (0..m).map(|i| i as f64 * scale / (m - 1) as f64).collect()
    }
}

/// A pole near `base` with full-precision coordinates.
fn pole(rng: &mut Lcg, base: [f64; 3]) -> [f64; 3] {
    [
        base[0] + 10.0 * rng.next(),
        base[1] + 10.0 * rng.next(),
        base[2] + 10.0 * rng.next(),
    ]
}

fn curve(rng: &mut Lcg) -> NurbsCurve {
    let p = rng.int(1, 9);
    let n = rng.int(p + 1, p + 30);
    let clamped = rng.next() < 0.8;
    let k = knots(rng, p, n, clamped);
    let base = [200.0 * rng.next(), 200.0 * rng.next(), 200.0 * rng.next()];
    let pts = (0..n).map(|_| pole(rng, base)).collect();
    let w = (rng.next() < 0.33).then(|| (0..n).map(|_| 0.5 + 1.5 * rng.next()).collect());
    NurbsCurve::new(p, k, pts, w).expect("generated curve is valid")
}

fn surface(rng: &mut Lcg) -> NurbsSurface {
    let (pu, pv) = if rng.next() < 0.8 {
        (3, 3)
    } else {
        (rng.int(1, 5), rng.int(1, 5))
    };
    let nu = rng.int((pu + 1).max(8), 20);
    let nv = rng.int((pv + 1).max(8), 20);
    let (cu, cv) = (rng.next() < 0.85, rng.next() < 0.85);
    let ku = knots(rng, pu, nu, cu);
    let kv = knots(rng, pv, nv, cv);
    let base = [200.0 * rng.next(), 200.0 * rng.next(), 200.0 * rng.next()];
    let pts = Grid::from_fn(nu, nv, |_, _| pole(rng, base));
    let w = (rng.next() < 0.33).then(|| Grid::from_fn(nu, nv, |_, _| 0.5 + 1.5 * rng.next()));
    NurbsSurface::new(pu, pv, ku, kv, pts, w).expect("generated surface is valid")
}

/// The first `count` entities of the deterministic sequence (40 % surfaces).
pub fn entities(count: usize) -> Vec<Entity> {
    let mut rng = Lcg(0x5eed_2026);
    (0..count)
        .map(|i| {
            let geometry = if rng.next() < 0.4 {
                Geometry::Surface(surface(&mut rng))
            } else {
                Geometry::Curve(curve(&mut rng))
            };
            Entity {
                id: compact_str::format_compact!("E{i}"),
                geometry,
                source: Source::default(),
                meta: Meta::default(),
            }
        })
        .collect()
}

/// A document of `count` entities in millimetres.
pub fn document(format: Format, count: usize) -> Document {
    let mut d = Document::new(format, LengthUnit::Mm);
    d.entities = entities(count);
    d
}

/// Fixed export options (a fixed time stamp so output is byte-identical run to run).
pub fn export_options() -> nurbsx::exchange::ExportOptions {
    nurbsx::exchange::ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".to_owned()),
        file_name: "gen_large".to_owned(),
        ..Default::default()
    }
}

/// A file of about `target_bytes` in `format`: the entity count is found from a 500-entity
/// sample's bytes per entity. Returns the text and the document written.
pub fn file_of_size(format: Format, target_bytes: usize) -> (String, Document) {
    let opts = export_options();
    let sample = document(format, 500);
    let sample_len = nurbsx::exchange::write(&sample, format, &opts)
        .expect("sample writes")
        .len();
    let count = (target_bytes as f64 / (sample_len as f64 / 500.0)).ceil() as usize;
    let doc = document(format, count.max(1));
    let text = nurbsx::exchange::write(&doc, format, &opts).expect("document writes");
    (text, doc)
}
