//! IGES parsing throughput on a synthetic file generated here: 10 000 entity-126 curves
//! (degree 3, 20 poles, rational) and 1 000 entity-128 surfaces (10 x 10 poles), written
//! by the crate's writer. Measures bytes per second for (a) sections + Global + DEs only and
//! (b) the full decode of every 126/128 record.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nurbsx_parsers::iges::records::{Curve126, Surface128};
use nurbsx_parsers::iges::writer::{WriteParams, write_with};
use nurbsx_parsers::iges::{self, DirectoryEntry, Global};

/// One entity to write.
enum Record {
    Curve(Curve126),
    Surface(Surface128),
}

fn synthetic() -> String {
    let mut entities = Vec::new();
    let mut x = 0.123_456_789_f64;
    let mut next = || {
        // A cheap deterministic sequence of "ugly" reals (full 17-digit output).
        x = (x * 3.987_654_321 + 0.1).fract();
        x * 200.0 - 100.0
    };
    for _ in 0..10_000 {
        let n = 20;
        let mut knots = vec![0.0; 4];
        knots.extend((1..n - 3).map(|k| k as f64 / (n - 3) as f64));
        knots.extend([1.0; 4]);
        let c = Curve126 {
            degree: 3,
            planar: 0,
            closed: 0,
            polynomial: 0,
            periodic: 0,
            knots,
            weights: (0..n).map(|_| 1.0 + next().abs() / 100.0).collect(),
            points: (0..n).map(|_| [next(), next(), next()]).collect(),
            v0: Some(0.0),
            v1: Some(1.0),
            normal: Some([0.0, 0.0, 0.0]),
            extra: 0,
        };
        entities.push((126, Record::Curve(c)));
    }
    for _ in 0..1_000 {
        let n = 10;
        let mut knots = vec![0.0; 4];
        knots.extend((1..n - 3).map(|k| k as f64 / (n - 3) as f64));
        knots.extend([1.0; 4]);
        let s = Surface128 {
            degree: [3, 3],
            poles: [n, n],
            closed: [0, 0],
            polynomial: 1,
            periodic: [0, 0],
            knots_u: knots.clone(),
            knots_v: knots,
            weights: vec![1.0; n * n],
            points: (0..n * n).map(|_| [next(), next(), next()]).collect(),
            range: Some([0.0, 1.0, 0.0, 1.0]),
            extra: 0,
        };
        entities.push((128, Record::Surface(s)));
    }
    let global = Global {
        param_delimiter: ',',
        record_delimiter: ';',
        units_flag: Some(2),
        units_name: Some("MM".into()),
        ..Global::default()
    };
    let des: Vec<DirectoryEntry> = entities
        .iter()
        .map(|&(entity_type, _)| DirectoryEntry {
            entity_type,
            ..DirectoryEntry::default()
        })
        .collect();
    write_with(
        "synthetic benchmark file",
        &global,
        &des,
        0,
        |i, w| match &entities[i].1 {
            Record::Curve(c) => c.write_params(w),
            Record::Surface(s) => s.write_params(w),
        },
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let text = synthetic();
    let mut g = c.benchmark_group("iges_parse");
    g.throughput(Throughput::Bytes(text.len() as u64));
    g.sample_size(10);
    g.bench_function("sections_global_directory", |b| {
        b.iter(|| iges::parse(&text).unwrap().entries.len())
    });
    g.bench_function("decode_all_126_128", |b| {
        b.iter(|| {
            let file = iges::parse(&text).unwrap();
            let mut poles = 0usize;
            for e in file.entries.iter().flatten() {
                poles += match e.entity_type {
                    126 => file.decode::<Curve126>(e).record.unwrap().points.len(),
                    _ => file.decode::<Surface128>(e).record.unwrap().points.len(),
                };
            }
            poles
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
