//! Knot intervals (seed 003, after Sederberg, Zheng and Song 2003): the seed's example, the
//! conversion both ways (bit-identical round trips), the model JSON form with its checks,
//! and interval halving against the seed's own halving formula and a hand-computed knot
//! list.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{Ends, arb_curve, arb_surface, bbox_diagonal, curve_deviation, surface_deviation};
use nurbsx::nurbs::knot_intervals::KnotIntervals;
use nurbsx::nurbs::serde_form::KnotIntervalForm;
use nurbsx::nurbs::{Geometry, NurbsCurve, Point3};
use proptest::prelude::*;

/// Seed 003 figure 2: a cubic B-spline with the knot vector [1,2,3,4,6,9,10,11] (the seed's
/// notation drops the outermost knot at each end; here they repeat the end knots, outer
/// intervals 0) and six poles.
fn seed_cubic() -> NurbsCurve {
    let points: Vec<Point3> = vec![
        [0.0, 0.0, 0.0],
        [1.0, 2.0, 0.0],
        [3.0, 3.0, 0.5],
        [5.0, 1.0, 1.0],
        [7.0, 2.5, 0.0],
        [8.0, 0.0, -1.0],
    ];
    let knots = vec![1.0, 1.0, 2.0, 3.0, 4.0, 6.0, 9.0, 10.0, 11.0, 11.0];
    NurbsCurve::new(3, knots, points, Some(vec![1.0, 0.5, 2.0, 1.0, 0.8, 1.0])).unwrap()
}

#[test]
fn seed_example_gives_the_seed_intervals_on_the_edges() {
    let k = seed_cubic().knot_intervals();
    // Differences of consecutive knots of [1,2,3,4,6,9,10,11].
    assert_eq!(k.intervals, [1.0, 1.0, 1.0, 2.0, 3.0, 1.0, 1.0]);
    assert_eq!(k.origin, 1.0);
    assert_eq!(k.outer, [0.0, 0.0]);
    // Odd degree: one interval per edge P0P1 .. P4P5, and (p - 1) / 2 = 1 phantom interval
    // at each end.
    assert_eq!(KnotIntervals::phantoms(3), 1);
    assert_eq!(k.on_polygon(3), [1.0, 1.0, 2.0, 3.0, 1.0]);
    assert_eq!(k.to_knots().unwrap(), seed_cubic().knots());
}

#[test]
fn even_degree_puts_one_interval_on_each_pole() {
    // Quadratic, 5 poles: n + p - 1 = 5 intervals, 0 phantoms; pole P_i carries
    // u_{i+2} - u_{i+1}.
    let knots = vec![0.0, 0.0, 0.0, 1.0, 3.0, 4.0, 6.0, 6.0];
    let k = KnotIntervals::from_knots(&knots);
    assert_eq!(KnotIntervals::phantoms(2), 0);
    assert_eq!(k.on_polygon(2), [0.0, 1.0, 2.0, 1.0, 2.0]);
    // Quartic: (p - 2) / 2 = 1 phantom at each end.
    assert_eq!(KnotIntervals::phantoms(4), 1);
}

#[test]
fn halving_the_seed_example_inserts_the_midpoints_and_keeps_the_curve() {
    let c = seed_cubic();
    let h = c.halve().unwrap();
    // The domain [3, 9] has the spans [3,4], [4,6], [6,9]: midpoints 3.5, 5, 7.5.
    assert_eq!(
        h.knots(),
        [
            1.0, 1.0, 2.0, 3.0, 3.5, 4.0, 5.0, 6.0, 7.5, 9.0, 10.0, 11.0, 11.0
        ]
    );
    assert_eq!(h.control_points().len(), 9);
    // Every interval of the domain is now two halves; the edge intervals outside it stay.
    assert_eq!(
        h.knot_intervals().intervals,
        [1.0, 1.0, 0.5, 0.5, 1.0, 1.0, 1.5, 1.5, 1.0, 1.0]
    );
    assert!(curve_deviation(&c, &h, 400) <= 1e-12);
}

/// The quadratic halving rule of seed 003 section 2-2 (a generalisation of Chaikin's
/// algorithm): the edge `P_i P_{i+1}`, whose poles carry the intervals `d_i` and `d_{i+1}`,
/// gives the new poles
/// `Q_2i = ((d_i + 2 d_{i+1}) P_i + d_i P_{i+1}) / (2 (d_i + d_{i+1}))` and
/// `Q_2i+1 = (d_{i+1} P_i + (2 d_i + d_{i+1}) P_{i+1}) / (2 (d_i + d_{i+1}))`.
/// Checked on the edges whose two intervals both lie inside the domain.
#[test]
fn quadratic_halving_matches_the_seed_formula() {
    let knots = vec![0.0, 0.5, 1.0, 2.0, 4.5, 5.0, 8.0, 9.0, 9.25, 11.0];
    let points: Vec<Point3> = (0..7)
        .map(|i| {
            let t = f64::from(i);
            [t * 1.5, (t * 0.9).sin() * 3.0, t * t * 0.1]
        })
        .collect();
    let c = NurbsCurve::new(2, knots.clone(), points.clone(), None).unwrap();
    let h = c.halve().unwrap();
    assert!(curve_deviation(&c, &h, 400) <= 1e-12);
    let d = KnotIntervals::from_knots(&knots).intervals; // d[i] sits on P_i
    let (a, b) = c.domain();
    let mut checked = 0;
    for i in 0..points.len() - 1 {
        // d_i spans [u_{i+1}, u_{i+2}]: inside the domain for both poles of the edge?
        let inside = |j: usize| knots[j + 1] >= a && knots[j + 2] <= b && d[j] > 0.0;
        if !(inside(i) && inside(i + 1)) {
            continue;
        }
        let (di, dj) = (d[i], d[i + 1]);
        let (p, q) = (points[i], points[i + 1]);
        let q2i: Point3 =
            std::array::from_fn(|k| ((di + 2.0 * dj) * p[k] + di * q[k]) / (2.0 * (di + dj)));
        let q2i1: Point3 =
            std::array::from_fn(|k| (dj * p[k] + (2.0 * di + dj) * q[k]) / (2.0 * (di + dj)));
        // The new poles with the polar labels (mid(d_i), u_{i+2}) and (u_{i+2}, mid(d_{i+1})).
        let mid = knots[i + 1] + di / 2.0;
        let j = h.knots().iter().position(|&u| u == mid).unwrap() - 1;
        let size = bbox_diagonal(&points);
        for (got, want) in [
            (h.control_points()[j], q2i),
            (h.control_points()[j + 1], q2i1),
        ] {
            assert!(
                common::dist(got, want) <= 1e-14 * size,
                "edge {i}: {got:?} vs {want:?}"
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 4, "edges P1P2 .. P4P5 are inside the domain");
}

/// Against geomdl 5.4.0: the same halving done by its single knot insertion
/// (`operations.insert_knot`, one midpoint at a time; written by
/// `tests/data/knot_intervals/make_geomdl_halving.py`): same knots, poles and weights to
/// 1e-14 of the size.
#[test]
fn halving_matches_geomdl_knot_insertion() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/knot_intervals/geomdl_halving.json"
    );
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let cases = reference["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 2);
    for case in cases {
        let name = case["name"].as_str().unwrap();
        let c: NurbsCurve = serde_json::from_value(case["curve"].clone()).unwrap();
        let want: NurbsCurve = serde_json::from_value(case["halved"].clone()).unwrap();
        let h = c.halve().unwrap();
        assert_eq!(h.knots(), want.knots(), "{name}");
        let size = bbox_diagonal(c.control_points());
        for (i, (p, q)) in h
            .control_points()
            .iter()
            .zip(want.control_points())
            .enumerate()
        {
            assert!(
                common::dist(*p, *q) <= 1e-14 * size,
                "{name}: pole {i} {p:?} vs {q:?}"
            );
            assert!(
                (h.weight(i) - want.weight(i)).abs() <= 1e-14,
                "{name}: weight {i}"
            );
        }
        assert_eq!(
            h.control_points().len(),
            want.control_points().len(),
            "{name}"
        );
    }
}

#[test]
fn knot_interval_json_writes_and_reads_the_seed_example() {
    let c = seed_cubic();
    let text = serde_json::to_string(&KnotIntervalForm(&Geometry::Curve(c.clone()))).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(
        v["knot_intervals"],
        serde_json::json!([1.0, 1.0, 1.0, 2.0, 3.0, 1.0, 1.0])
    );
    assert_eq!(v["knot_origin"], serde_json::json!(1.0));
    assert!(v.get("knots").is_none(), "never both forms: {text}");
    assert!(
        v.get("outer_knot_intervals").is_none(),
        "clamped ends: {text}"
    );
    let back: NurbsCurve = serde_json::from_str(&text).unwrap();
    assert_eq!(back, c);
    // An unclamped curve keeps its outermost knots through `outer_knot_intervals`.
    let u = NurbsCurve::new(
        2,
        vec![0.0, 0.25, 1.0, 2.0, 2.5, 4.0],
        vec![[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0]],
        None,
    )
    .unwrap();
    let text = serde_json::to_string(&KnotIntervalForm(&Geometry::Curve(u.clone()))).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["outer_knot_intervals"], serde_json::json!([0.25, 1.5]));
    assert_eq!(serde_json::from_str::<NurbsCurve>(&text).unwrap(), u);
}

#[test]
fn bad_knot_interval_json_is_refused_with_the_place() {
    let curve = |extra: &str| {
        format!(r#"{{"degree":2,{extra},"control_points":[[0,0],[1,1],[2,0],[3,1]]}}"#)
    };
    let err = |json: String| {
        serde_json::from_str::<Geometry>(&json)
            .unwrap_err()
            .to_string()
    };
    let e = err(curve(r#""knot_intervals":[0,1,-2,1]"#));
    assert!(e.contains("knot_intervals[2] = -2 is negative"), "{e}");
    let e = err(curve(r#""knot_intervals":[0,1,1]"#));
    assert!(
        e.contains("knot_intervals has 3 values") && e.contains("need 4"),
        "{e}"
    );
    let e = err(curve(
        r#""knot_intervals":[0,1,1,0],"knots":[0,0,0,1,2,2,2]"#,
    ));
    assert!(e.contains("not both"), "{e}");
    let e = err(curve(r#""knots":[0,0,0,1,2,2,2],"knot_origin":3"#));
    assert!(e.contains("knot_origin"), "{e}");
    let e = err(curve(
        r#""knot_intervals":[0,1,1,0],"outer_knot_intervals":[0,-1]"#,
    ));
    assert!(
        e.contains("outer_knot_intervals[1] = -1 is negative"),
        "{e}"
    );
    let e = err(curve(r#""knot_intervals":[0,1e308,1e308,0]"#));
    assert!(e.contains("beyond the f64 range"), "{e}");
    let e = err(curve(r#""knot_origin":1"#));
    assert!(e.contains("needs knots"), "{e}");
    // Three zero intervals inside make a knot of multiplicity 3 > degree 2 inside the
    // domain: the curve constructor refuses it.
    let e = err(
        r#"{"degree":2,"knot_intervals":[0,1,0,0,1,0],"control_points":[[0,0],[1,1],[2,0],[3,1],[4,0],[5,1]]}"#
            .to_owned(),
    );
    assert!(e.contains("multiplicity"), "{e}");
    // Valid: two zero intervals at the ends are a clamped quadratic.
    let g: Geometry = serde_json::from_str(&curve(r#""knot_intervals":[0,1,1,0]"#)).unwrap();
    let Geometry::Curve(c) = g else {
        panic!("a curve")
    };
    assert_eq!(c.knots(), [0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0]);
}

#[test]
fn a_knot_no_interval_reaches_is_refused_when_writing() {
    // 1 + 2^-52 after 2^-53: every f64 sum from 2^-53 in that binade lands on a rounding
    // tie, so no interval gives the knot back; writing refuses instead of moving it.
    let x = 1.0 + f64::EPSILON;
    let y = f64::EPSILON / 2.0;
    assert_ne!(y + (x - y), x, "the tie case this test is about");
    let knots = vec![0.0, 0.0, y, x, x + 1.0, x + 1.0];
    assert_eq!(
        KnotIntervals::from_knots(&knots).inexact_knot(&knots),
        Some(3)
    );
    let c = NurbsCurve::new(
        1,
        knots,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        None,
    )
    .unwrap();
    let e = serde_json::to_string(&KnotIntervalForm(&Geometry::Curve(c.clone())))
        .unwrap_err()
        .to_string();
    assert!(e.contains("knot[3]"), "{e}");
    // A difference that overflows: refused too, never a panic.
    let wide = NurbsCurve::new(
        1,
        vec![-1.5e308, -1.5e308, 1.5e308, 1.5e308],
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
        None,
    )
    .unwrap();
    let e = serde_json::to_string(&KnotIntervalForm(&Geometry::Curve(wide)))
        .unwrap_err()
        .to_string();
    assert!(e.contains("knot-interval form"), "{e}");
    // Differences that are not exact in f64 still sum back.
    let knots = vec![0.0, 0.1, 0.3, 0.7, 1.1, 1.3];
    assert_ne!(0.7 - 0.3, 0.4);
    assert_eq!(KnotIntervals::from_knots(&knots).to_knots().unwrap(), knots);
}

/// A random non-decreasing knot vector: `origin`, then gaps of widely varying sizes
/// (zeros included).
fn arb_knot_vector(origin: std::ops::Range<f64>) -> impl Strategy<Value = Vec<f64>> {
    (
        origin,
        prop::collection::vec(
            prop_oneof![
                Just(0.0),
                0.0f64..1.0,
                (1e-9f64..1e-3),
                (1.0f64..1e6),
                (-60i32..10).prop_map(|e| 2f64.powi(e)),
            ],
            3..40,
        ),
    )
        .prop_map(|(origin, gaps)| {
            let mut k = vec![origin];
            for g in gaps {
                let last = *k.last().unwrap();
                k.push(last + g);
            }
            k
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Knot vectors starting at 0, built by f64 sums, come back bit for bit.
    #[test]
    fn knots_to_intervals_to_knots_is_bit_identical_from_zero(knots in arb_knot_vector(0.0..f64::MIN_POSITIVE)) {
        let k = KnotIntervals::from_knots(&knots);
        prop_assert_eq!(k.intervals.len(), knots.len() - 3);
        prop_assert!(k.intervals.iter().chain(&k.outer).all(|&d| d >= 0.0));
        let back = k.to_knots().unwrap();
        prop_assert_eq!(back.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                        knots.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
    }

    /// Any non-negative origin: still bit-identical.
    #[test]
    fn non_negative_knots_come_back_bit_identical(knots in arb_knot_vector(0.0..1e9)) {
        let back = KnotIntervals::from_knots(&knots).to_knots().unwrap();
        prop_assert_eq!(back, knots);
    }

    /// Halving keeps the curve (evaluation at many parameters, 1e-12 of the size), adds
    /// one knot per non-degenerate span of the domain, and the knots added are the span
    /// midpoints `(a + b) / 2`.
    #[test]
    fn halving_keeps_the_curve(c in arb_curve(6, true, Ends::Any)) {
        let h = c.halve().unwrap();
        prop_assert!(curve_deviation(&c, &h, 200) <= 1e-12);
        let p = c.degree();
        let k = c.knots();
        let spans: Vec<(f64, f64)> = (p..k.len() - p - 1)
            .map(|i| (k[i], k[i + 1]))
            .filter(|(a, b)| a < b)
            .collect();
        prop_assert_eq!(h.knots().len(), k.len() + spans.len());
        let mut want: Vec<f64> = k.to_vec();
        want.extend(spans.iter().map(|(a, b)| (a + b) / 2.0));
        want.sort_by(f64::total_cmp);
        for (got, want) in h.knots().iter().zip(&want) {
            prop_assert!((got - want).abs() <= 4.0 * f64::EPSILON * want.abs().max(1.0),
                "{} vs {}", got, want);
        }
        prop_assert_eq!(h.domain(), c.domain());
    }

    /// Surfaces: halving in u, v or both keeps the surface.
    #[test]
    fn surface_halving_keeps_the_surface(s in arb_surface(4, true, Ends::Any)) {
        let hu = s.halve_u().unwrap();
        let hv = s.halve_v().unwrap();
        let both = hu.halve_v().unwrap();
        prop_assert!(hu.control_points().nv() == s.control_points().nv());
        prop_assert!(hv.control_points().nu() == s.control_points().nu());
        for h in [&hu, &hv, &both] {
            prop_assert!(surface_deviation(&s, h, 20) <= 1e-12);
        }
    }
}
