//! Knot-operation benchmarks: a single knot insertion (NURBS Book A5.1) on a cubic curve
//! with 20 poles, and on a rational bicubic 20 x 20 surface in each direction (A5.3).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use nurbsx::nurbs::{Grid, NurbsCurve, NurbsSurface};

/// Clamped uniform knots for `n` poles of degree `p` on [0, 1].
fn knots(p: usize, n: usize) -> Vec<f64> {
    let spans = n - p;
    let mut k = vec![0.0; p + 1];
    for i in 1..spans {
        k.push(i as f64 / spans as f64);
    }
    k.extend(vec![1.0; p + 1]);
    k
}

fn bench(c: &mut Criterion) {
    let pts: Vec<[f64; 3]> = (0..20)
        .map(|i| {
            let t = f64::from(i);
            [t, (t * 0.7).sin(), (t * 0.3).cos()]
        })
        .collect();
    let curve = NurbsCurve::new(3, knots(3, 20), pts, None).unwrap();
    c.bench_function("insert_knot cubic curve 20 poles", |b| {
        b.iter(|| black_box(&curve).insert_knot(black_box(0.4321), 1).unwrap())
    });
    let net = Grid::from_fn(20, 20, |i, j| {
        let (x, y) = (i as f64, j as f64);
        [x, y, (x * 0.3).sin() * (y * 0.2).cos()]
    });
    let w = Grid::from_fn(20, 20, |i, j| 1.0 + 0.5 * ((i + 2 * j) % 3) as f64);
    let surface = NurbsSurface::new(3, 3, knots(3, 20), knots(3, 20), net, Some(w)).unwrap();
    c.bench_function("insert_knot_u rational bicubic 20x20", |b| {
        b.iter(|| {
            black_box(&surface)
                .insert_knot_u(black_box(0.4321), 1)
                .unwrap()
        })
    });
    c.bench_function("insert_knot_v rational bicubic 20x20", |b| {
        b.iter(|| {
            black_box(&surface)
                .insert_knot_v(black_box(0.4321), 1)
                .unwrap()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
