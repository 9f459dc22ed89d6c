//! Random documents for the writers' equivalence tests (test-only): rational and polynomial
//! curves and surfaces, 2-D curves, uniform/Bezier/odd knot vectors, odd values (-0.0,
//! 1e-300, +-1e300, subnormals), names, forms, plane normals and parameter ranges, from a
//! seed that proptest draws.

use crate::exchange::{Document, Entity, Format, LengthUnit, Meta, Source};
use crate::nurbs::{Geometry, Grid, NurbsCurve, NurbsSurface};

/// A small deterministic PRNG for the generated documents (proptest draws the seed).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 11
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn unit(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 53) as f64
    }
    /// A coordinate: full precision mostly, odd values often.
    fn coord(&mut self) -> f64 {
        const ODD: [f64; 14] = [
            0.0,
            -0.0,
            1e-300,
            -1e300,
            1e300,
            5e-324,
            2.2250738585072e-310,
            0.5,
            -0.25,
            1e16,
            1e-5,
            9.5367431640625e-7,
            123_456_789.0,
            -3.0,
        ];
        match self.below(4) {
            0 => ODD[self.below(ODD.len())],
            1 => (self.unit() * 2000.0 - 1000.0).round() / 8.0,
            _ => self.unit() * 400.0 - 200.0,
        }
    }
}

fn knots(rng: &mut Rng, p: usize, n: usize) -> Vec<f64> {
    let m = n + p + 1;
    let scale = [1.0, 1e-300, 1e300, 7.3, 0.1][rng.below(5)];
    match rng.below(4) {
        // uniform (UNIFORM_ subtype when the scale is 1)
        0 => (0..m).map(|i| i as f64 * scale).collect(),
        // clamped with integer interior (QUASI_UNIFORM_, or BEZIER_ when n = p + 1)
        1 => {
            let spans = n - p;
            let mut k = vec![0.0; p + 1];
            k.extend((1..spans).map(|i| i as f64 * scale));
            k.extend(std::iter::repeat_n(spans as f64 * scale, p + 1));
            k
        }
        // clamped, random interior
        _ => {
            let mut inner: Vec<f64> = (1..n - p).map(|_| rng.unit() * scale).collect();
            inner.sort_by(f64::total_cmp);
            let mut k = vec![0.0; p + 1];
            k.extend(inner);
            k.extend(std::iter::repeat_n(scale, p + 1));
            k
        }
    }
}

fn weights(rng: &mut Rng, n: usize) -> Option<Vec<f64>> {
    match rng.below(3) {
        0 => None,
        1 => Some(vec![[1.0, 0.5, 2.0][rng.below(3)]; n]),
        _ => Some((0..n).map(|_| 0.25 + rng.unit() * 4.0).collect()),
    }
}

fn meta(rng: &mut Rng) -> Meta {
    Meta {
        name: [
            None,
            Some(""),
            Some("edge 1"),
            Some("it's"),
            Some("\u{fc}ber"),
        ][rng.below(5)]
        .map(str::to_owned),
        form: [
            None,
            Some("circular_arc"),
            Some("PLANE_SURF"),
            Some("bogus"),
        ][rng.below(4)]
        .map(std::borrow::Cow::Borrowed),
        self_intersect: [None, Some(false), Some(true)][rng.below(3)],
        plane_normal: [
            None,
            Some([0.0, 0.0, 1.0]),
            Some([0.0, 0.0, -1.0]),
            Some([0.6, 0.8, 0.0]),
        ][rng.below(4)]
        .map(Box::new),
        parameter_range: [
            None,
            Some(crate::exchange::ParameterRange {
                u: (0.0, 0.5),
                v: Some((0.25, 0.75)),
            }),
            Some(crate::exchange::ParameterRange {
                u: (0.1, 0.2),
                v: None,
            }),
            Some(crate::exchange::ParameterRange {
                u: (-1.0, 1e300),
                v: Some((0.0, 1.0)),
            }),
        ][rng.below(4)]
        .map(Box::new),
        ..Meta::default()
    }
}

pub(crate) fn random_document(seed: u64, format: Format) -> Document {
    let mut rng = Rng(seed);
    let mut doc = Document::new(format, LengthUnit::Mm);
    let count = 1 + rng.below(5);
    for i in 0..count {
        let geometry = if rng.below(3) == 0 {
            let (pu, pv) = (1 + rng.below(3), 1 + rng.below(3));
            let (nu, nv) = (pu + 1 + rng.below(4), pv + 1 + rng.below(4));
            let (ku, kv) = (knots(&mut rng, pu, nu), knots(&mut rng, pv, nv));
            let pts = Grid::from_fn(nu, nv, |_, _| [rng.coord(), rng.coord(), rng.coord()]);
            let w = weights(&mut rng, nu * nv).map(|w| Grid::from_fn(nu, nv, |i, j| w[i * nv + j]));
            NurbsSurface::new(pu, pv, ku, kv, pts, w)
                .ok()
                .map(Geometry::Surface)
        } else {
            let p = 1 + rng.below(4);
            let n = p + 1 + rng.below(6);
            let k = knots(&mut rng, p, n);
            let dim = 2 + rng.below(2);
            let pts = (0..n)
                .map(|_| {
                    let z = if dim == 2 { 0.0 } else { rng.coord() };
                    [rng.coord(), rng.coord(), z]
                })
                .collect();
            let w = weights(&mut rng, n);
            NurbsCurve::with_dimension(p, k, pts, w, dim)
                .ok()
                .map(Geometry::Curve)
        };
        let Some(geometry) = geometry else { continue };
        doc.entities.push(Entity {
            id: compact_str::format_compact!("E{i}"),
            geometry,
            source: Source::default(),
            meta: meta(&mut rng),
        });
    }
    doc
}
