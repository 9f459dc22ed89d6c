//! Throughput of the Part 21 layer on a synthetic file: 20 000 rational B-spline curves
//! (complex instances, 8 poles each) and their 160 000 CARTESIAN_POINTs, ~21 MB.
//!
//! - `scan`: structure, instance boundaries and the #id index (no parameter decoding);
//! - `parse`: scan + decode every instance + reference check (the eager tree);
//! - `records`: scan + typed B-spline records + their points (what the reader does).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nurbsx_parsers::Limits;
use nurbsx_parsers::real::write_real;
use nurbsx_parsers::step::schema::{At, BSplineCurve, CartesianPoint};
use nurbsx_parsers::step::{parse, scan};

fn synthetic(curves: usize) -> String {
    let mut s = String::from(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('bench'),'2;1');\nFILE_NAME('b','2026-01-01T00:00:00',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n",
    );
    let mut id = 1u64;
    let mut x = 0.123_456_789_f64;
    for _ in 0..curves {
        let first = id;
        for _ in 0..8 {
            s.push_str(&format!("#{id} = CARTESIAN_POINT('',("));
            for k in 0..3 {
                x = (x * 3.987_654_321 + 0.1).fract();
                write_real(&mut s, (x - 0.5) * 200.0).unwrap();
                if k < 2 {
                    s.push(',');
                }
            }
            s.push_str("));\n");
            id += 1;
        }
        let refs: Vec<String> = (first..id).map(|i| format!("#{i}")).collect();
        s.push_str(&format!(
            "#{id} = ( BOUNDED_CURVE() B_SPLINE_CURVE(3,({}),.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS((4,1,1,1,1,4),(0.,0.2,0.4,0.6,0.8,1.),.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE((1.,0.8,1.2,0.9,1.1,1.3,0.7,1.)) REPRESENTATION_ITEM('') );\n",
            refs.join(",")
        ));
        id += 1;
    }
    s.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    s
}

fn bench(c: &mut Criterion) {
    let text = synthetic(20_000);
    let limits = Limits::default();
    let mut g = c.benchmark_group("step");
    g.throughput(Throughput::Bytes(text.len() as u64));
    g.sample_size(10);
    g.bench_function("scan", |b| {
        b.iter(|| scan(&text, &limits).unwrap().instances.len())
    });
    g.bench_function("parse", |b| {
        b.iter(|| parse(&text, &limits).unwrap().errors.len())
    });
    g.bench_function("records", |b| {
        b.iter(|| {
            let s = scan(&text, &limits).unwrap();
            let mut poles = 0usize;
            for raw in &s.instances {
                if raw.keyword_initial().is_some() {
                    continue;
                }
                let inst = s.decode(raw).unwrap();
                let at = At {
                    id: raw.id,
                    line: 0,
                    column: 0,
                };
                let r = BSplineCurve::from_instance(&inst, at).unwrap();
                for &p in &r.control_points {
                    let praw = s.get(p).unwrap();
                    let pi = s.decode(praw).unwrap();
                    poles += CartesianPoint::from_instance(&pi, at)
                        .unwrap()
                        .coordinates
                        .len();
                }
            }
            poles
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
