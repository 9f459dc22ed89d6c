//! Degree elevation and reduction timings: a rational bicubic 20x20 surface elevated 3 -> 5
//! in both directions (A5.10), and curve elevation / reduction (A5.9, A5.11); curve
//! tessellation of a curved rational cubic and of a degree-1 polyline.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use nurbsx::nurbs::{Grid, NurbsCurve, NurbsSurface};

/// Uniform clamped knots for `poles` control points of degree `p`.
fn knots(p: usize, poles: usize) -> Vec<f64> {
    let spans = poles - p;
    let mut k = vec![0.0; p + 1];
    k.extend((1..spans).map(|i| i as f64 / spans as f64));
    k.extend(std::iter::repeat_n(1.0, p + 1));
    k
}

fn surface() -> NurbsSurface {
    let n = 20;
    let points = Grid::from_fn(n, n, |i, j| {
        let (x, y) = (i as f64, j as f64);
        [x, y, (0.3 * x).sin() * (0.2 * y).cos() * 3.0]
    });
    let weights = Grid::from_fn(n, n, |i, j| 1.0 + 0.5 * ((i * 7 + j * 3) % 5) as f64 / 4.0);
    NurbsSurface::new(3, 3, knots(3, n), knots(3, n), points, Some(weights)).unwrap()
}

fn curve(poles: usize) -> NurbsCurve {
    let points = (0..poles)
        .map(|i| {
            let t = i as f64;
            [t, (0.7 * t).sin() * 4.0, (0.3 * t).cos()]
        })
        .collect();
    let weights = (0..poles).map(|i| 1.0 + (i % 3) as f64 * 0.25).collect();
    NurbsCurve::new(3, knots(3, poles), points, Some(weights)).unwrap()
}

fn bench(c: &mut Criterion) {
    let s = surface();
    c.bench_function(
        "surface 20x20 rational bicubic elevate 3->5 (u and v)",
        |b| b.iter(|| black_box(&s).elevate(2).unwrap()),
    );
    let cv = curve(200);
    c.bench_function("curve 200 poles rational cubic elevate +2", |b| {
        b.iter(|| black_box(&cv).elevate(2).unwrap())
    });
    let e = cv.elevate(1).unwrap();
    c.bench_function("curve 200 poles quartic (elevated) reduce", |b| {
        b.iter(|| black_box(&e).reduce(1e-9).unwrap())
    });
    c.bench_function("curve 200 poles rational cubic tessellate 1e-3", |b| {
        b.iter(|| black_box(&cv).tessellate(1e-3).unwrap())
    });
    let zigzag = NurbsCurve::new(
        1,
        knots(1, 200),
        (0..200).map(|i| [i as f64, (i % 2) as f64, 0.0]).collect(),
        None,
    )
    .unwrap();
    c.bench_function(
        "curve 200-vertex polyline (degree 1) tessellate 1e-3",
        |b| b.iter(|| black_box(&zigzag).tessellate(1e-3).unwrap()),
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(std::time::Duration::from_millis(500))
        .measurement_time(std::time::Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
