//! Knot-vector classification (seed 2-29, ISO 10303-42 knot_type) on hand-made vectors of
//! each kind, and periodic <-> open conversion on random periodic curves and surfaces,
//! closed curves of lower seam continuity, and Open CASCADE's periodic circle (spec.md c.4).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{bbox_diagonal, dist};
use nurbsx::nurbs::layout::{KnotType, Layout, classify_knots, knot_type};
use nurbsx::nurbs::{GeometryError, Grid, NurbsCurve, NurbsSurface, Point3};
use proptest::prelude::*;

const REL: f64 = 1e-12;

/// Largest distance at 1000 parameters (plus knots) of `a`'s domain, relative to its size.
fn deviation(a: &NurbsCurve, b: &NurbsCurve) -> f64 {
    let (s, e) = a.domain();
    assert_eq!(a.domain(), b.domain(), "domains differ");
    let mut t: Vec<f64> = (0..1000)
        .map(|i| (s + (e - s) * f64::from(i) / 999.0).clamp(s, e))
        .collect();
    t.extend(a.knots().iter().copied().filter(|&k| k >= s && k <= e));
    t.iter()
        .map(|&x| dist(a.point_at(x).unwrap(), b.point_at(x).unwrap()))
        .fold(0.0, f64::max)
        / bbox_diagonal(a.control_points())
}

/// A periodic curve in flat form: knots by wrapping `gaps`, poles `unique` wrapped `p`
/// times (seed figure 2-124 generalised to random spacing and weights).
fn periodic_curve(
    p: usize,
    unique: &[Point3],
    weights: Option<&[f64]>,
    gaps: &[f64],
    offset: f64,
) -> NurbsCurve {
    let nn = unique.len();
    let mut knots = vec![offset];
    for i in 0..nn + 2 * p {
        knots.push(knots[i] + gaps[i % nn]);
    }
    let points: Vec<Point3> = (0..nn + p).map(|i| unique[i % nn]).collect();
    let w = weights.map(|w| (0..nn + p).map(|i| w[i % nn]).collect());
    NurbsCurve::new(p, knots, points, w).unwrap()
}

fn arb_periodic(rational: bool) -> impl Strategy<Value = NurbsCurve> {
    (1usize..=4, 0usize..5).prop_flat_map(move |(p, extra)| {
        let nn = p + 1 + extra;
        (
            Just(p),
            prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), nn),
            prop::collection::vec(0.3f64..3.0, nn),
            prop::collection::vec(0.2f64..2.0, nn),
            -5.0f64..5.0,
        )
            .prop_map(move |(p, pts, w, gaps, off)| {
                periodic_curve(p, &pts, rational.then_some(w.as_slice()), &gaps, off)
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn periodic_open_round_trip(c in prop_oneof![arb_periodic(false), arb_periodic(true)]) {
        let p = c.degree();
        prop_assert_eq!(c.layout(1e-9), Layout::Periodic { wrapped: p });
        prop_assert!(c.is_closed(1e-9));
        prop_assert!(c.seam_continuity(1e-9).unwrap() + 1 >= p);
        let open = c.to_open().unwrap();
        prop_assert_eq!(open.domain(), c.domain());
        prop_assert!(open.is_clamped_start() && open.is_clamped_end());
        prop_assert!(deviation(&c, &open) < REL);
        let open_is_periodic = matches!(open.layout(1e-9), Layout::Periodic { .. });
        prop_assert!(!open_is_periodic);
        let back = open.to_periodic(1e-9).unwrap();
        prop_assert_eq!(back.domain(), c.domain());
        prop_assert_eq!(back.is_rational(), c.is_rational());
        prop_assert!(deviation(&c, &back) < REL, "{}", deviation(&c, &back));
        prop_assert_eq!(back.layout(1e-9), Layout::Periodic { wrapped: p });
        // The wrap-around knots of 2-168/2-169 reproduce the original periodic knots.
        let range = c.knots()[c.knots().len() - 1] - c.knots()[0];
        for (a, b) in back.knots().iter().zip(c.knots()) {
            prop_assert!((a - b).abs() <= 1e-12 * range);
        }
        // Already periodic: to_periodic keeps it.
        let again = c.to_periodic(1e-9).unwrap();
        prop_assert!(deviation(&c, &again) < REL);
    }

    #[test]
    fn closed_c0_curve_is_refused_with_its_continuity(
        pts in prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), 5..9),
        p in 2usize..=3,
    ) {
        let mut pts = pts;
        let first = pts[0];
        pts.push(first);
        let n = pts.len();
        let mut knots = vec![0.0; p + 1];
        for i in 1..n - p {
            knots.push(i as f64);
        }
        knots.extend(vec![(n - p) as f64; p + 1]);
        let c = NurbsCurve::new(p, knots, pts, None).unwrap();
        prop_assert!(c.is_closed(0.0));
        prop_assert_eq!(c.seam_continuity(1e-9), Some(0));
        match c.to_periodic(1e-9) {
            Err(GeometryError::InvalidArgument(m)) => prop_assert!(m.contains("C^0"), "{m}"),
            other => panic!("expected refusal, got {other:?}"),
        }
    }

    #[test]
    fn periodic_surface_in_u(c in arb_periodic(true), shift in prop::array::uniform3(-3.0f64..3.0)) {
        // Columns: the periodic curve and translated copies (a periodic "tube" in u).
        let nu = c.num_poles();
        let nv = 3;
        let pts = Grid::from_fn(nu, nv, |i, j| {
            let q = c.control_points()[i];
            let k = j as f64;
            [q[0] + k * shift[0], q[1] + k * shift[1], q[2] + k * shift[2] + k]
        });
        let w = Grid::from_fn(nu, nv, |i, _| c.weight(i));
        let s = NurbsSurface::new(c.degree(), 2, c.knots().to_vec(), vec![0., 0., 0., 1., 1., 1.], pts, Some(w)).unwrap();
        prop_assert_eq!(s.layout_u(1e-9), Layout::Periodic { wrapped: c.degree() });
        prop_assert_eq!(s.layout_v(1e-9), Layout::PiecewiseBezier);
        prop_assert!(s.is_closed_u(1e-9));
        prop_assert!(!s.is_closed_v(1e-9));
        let open = s.to_open_u().unwrap();
        let back = open.to_periodic_u(1e-9).unwrap();
        prop_assert_eq!(back.layout_u(1e-9), Layout::Periodic { wrapped: c.degree() });
        let ((u0, u1), (v0, v1)) = s.domain();
        let size = bbox_diagonal(s.control_points().as_slice());
        for i in 0..=32 {
            for j in 0..=32 {
                let u = (u0 + (u1 - u0) * f64::from(i) / 32.0).min(u1);
                let v = (v0 + (v1 - v0) * f64::from(j) / 32.0).min(v1);
                let p = s.point_at(u, v).unwrap();
                prop_assert!(dist(p, open.point_at(u, v).unwrap()) <= REL * size);
                prop_assert!(dist(p, back.point_at(u, v).unwrap()) <= REL * size);
            }
        }
    }
}

#[test]
fn hand_made_knot_vectors_are_classified() {
    // Seed 2-29 examples.
    let uniform: Vec<f64> = (-3..=5).map(f64::from).collect(); // U1 = {-3..5}
    assert_eq!(knot_type(3, &uniform), KnotType::UniformKnots);
    assert_eq!(classify_knots(3, &uniform), Layout::Uniform);
    let quasi = [0., 0., 0., 0., 1., 2., 3., 4., 4., 4., 4.];
    assert_eq!(knot_type(3, &quasi), KnotType::QuasiUniformKnots);
    assert_eq!(classify_knots(3, &quasi), Layout::QuasiUniform);
    let nonuniform_clamped = [0., 0., 0., 2., 3., 6., 7., 7., 7.];
    assert_eq!(knot_type(2, &nonuniform_clamped), KnotType::Unspecified);
    assert_eq!(classify_knots(2, &nonuniform_clamped), Layout::Clamped);
    let repeated = [0., 0., 0., 0., 1., 2., 2., 3., 4., 5., 5., 5., 5.];
    assert_eq!(classify_knots(3, &repeated), Layout::Clamped);
    let nonuniform_unclamped = [-2., -1., 0., 4., 5., 6., 7.];
    assert_eq!(classify_knots(2, &nonuniform_unclamped), Layout::Unclamped);
    let half_clamped = [0., 0., 1., 2., 3., 4.];
    assert_eq!(classify_knots(1, &half_clamped), Layout::Unclamped);
    assert_eq!(knot_type(1, &half_clamped), KnotType::Unspecified);
    // Piecewise Bezier: ends p+1, interior p, equal spacing; a single Bezier span too.
    let pw = [0., 0., 0., 0., 1., 1., 1., 2., 2., 2., 2.];
    assert_eq!(knot_type(3, &pw), KnotType::PiecewiseBezierKnots);
    assert_eq!(classify_knots(3, &pw), Layout::PiecewiseBezier);
    assert_eq!(
        knot_type(2, &[0., 0., 0., 1., 1., 1.]),
        KnotType::PiecewiseBezierKnots
    );
    // Unequal spacing is not piecewise Bezier in the ISO sense.
    assert_eq!(
        knot_type(2, &[0., 0., 0., 1., 1., 3., 3., 3.]),
        KnotType::Unspecified
    );
    // Equal spacing printed with 12 digits still counts.
    let thirds = [0., 0., 0., 0.333333333333, 0.666666666667, 1., 1., 1.];
    assert_eq!(knot_type(2, &thirds), KnotType::QuasiUniformKnots);
    // Degree 1, simple interior knots: quasi-uniform (documented choice).
    assert_eq!(
        knot_type(1, &[0., 0., 1., 2., 2.]),
        KnotType::QuasiUniformKnots
    );
    assert_eq!(
        KnotType::QuasiUniformKnots.step_name(),
        ".QUASI_UNIFORM_KNOTS."
    );
    assert_eq!(KnotType::UniformKnots.step_name(), ".UNIFORM_KNOTS.");
    assert_eq!(
        KnotType::PiecewiseBezierKnots.step_name(),
        ".PIECEWISE_BEZIER_KNOTS."
    );
    assert_eq!(KnotType::Unspecified.step_name(), ".UNSPECIFIED.");
    assert_eq!(Layout::PiecewiseBezier.to_string(), "piecewise Bezier");
    assert_eq!(Layout::Periodic { wrapped: 3 }.name(), "periodic");
}

/// Seed figure 2-124: cubic, U2 = {0..11}, 8 poles with P0 = P5, P1 = P6, P2 = P7: periodic,
/// domain [3, 8]. Breaking one wrapped pole makes it merely uniform.
#[test]
fn seed_closed_cubic_is_periodic() {
    let unique: Vec<Point3> = (0..5)
        .map(|i| {
            let a = f64::from(i) * 1.2566370614359172;
            [a.cos(), a.sin(), 0.0]
        })
        .collect();
    let pts: Vec<Point3> = (0..8).map(|i| unique[i % 5]).collect();
    let knots: Vec<f64> = (0..12).map(f64::from).collect();
    let c = NurbsCurve::new(3, knots.clone(), pts.clone(), None).unwrap();
    assert_eq!(c.domain(), (3.0, 8.0));
    assert_eq!(c.layout(1e-12), Layout::Periodic { wrapped: 3 });
    assert_eq!(c.knot_type(), KnotType::UniformKnots);
    assert!(c.is_closed(1e-12));
    assert!(c.seam_continuity(1e-12).unwrap() >= 2);
    let mut broken = pts;
    broken[7] = [5.0, 5.0, 5.0];
    let d = NurbsCurve::new(3, knots, broken, None).unwrap();
    assert_eq!(d.layout(1e-12), Layout::Uniform);
    assert!(!d.is_closed(1e-6));
    assert!(d.seam_continuity(1e-6).is_none());
    match d.to_periodic(1e-6) {
        Err(GeometryError::InvalidArgument(m)) => assert!(m.contains("not closed"), "{m}"),
        other => panic!("{other:?}"),
    }
}

/// Open CASCADE's periodic circle as written to STEP (spec.md c.4/d.2): degree 2, knots
/// (-2pi/3, 0, 0, 2pi/3, 2pi/3, 4pi/3, 4pi/3, 2pi, 2pi, 8pi/3), weights 1, 1/2, ...: periodic
/// with one wrapped pole (seam multiplicity 2), on the unit circle; its open form is clamped
/// and still the circle; it has 3 Bezier spans; the classic periodic form is refused
/// because the seam is only C^0 in homogeneous coordinates.
#[test]
fn occt_periodic_circle() {
    let t = 2.0 * std::f64::consts::PI / 3.0;
    let knots = vec![-t, 0., 0., t, t, 2. * t, 2. * t, 3. * t, 3. * t, 4. * t];
    let at = |k: usize, r: f64| {
        let a = (k as f64) * std::f64::consts::PI / 3.0;
        [r * a.cos(), r * a.sin(), 0.0]
    };
    let pts: Vec<Point3> = (0..7)
        .map(|k| at(k % 6, if k % 2 == 0 { 1.0 } else { 2.0 }))
        .collect();
    let w: Vec<f64> = (0..7).map(|k| if k % 2 == 0 { 1.0 } else { 0.5 }).collect();
    let c = NurbsCurve::new(2, knots, pts, Some(w)).unwrap();
    assert_eq!(c.domain(), (0.0, 3.0 * t));
    assert_eq!(c.layout(1e-12), Layout::Periodic { wrapped: 1 });
    let radius_ok = |c: &NurbsCurve| {
        let (a, b) = c.domain();
        for i in 0..=1000 {
            let p = c
                .point_at((a + (b - a) * f64::from(i) / 1000.0).min(b))
                .unwrap();
            assert!(
                ((p[0] * p[0] + p[1] * p[1]).sqrt() - 1.0).abs() < 1e-14,
                "{p:?}"
            );
        }
    };
    radius_ok(&c);
    let open = c.to_open().unwrap();
    assert!(open.is_clamped_start() && open.is_clamped_end());
    assert_eq!(open.num_poles(), 7);
    radius_ok(&open);
    assert_eq!(c.bezier_segments().unwrap().len(), 3);
    assert_eq!(c.seam_continuity(1e-9), Some(0));
    match c.to_periodic(1e-9) {
        Err(GeometryError::InvalidArgument(m)) => assert!(m.contains("C^0"), "{m}"),
        other => panic!("{other:?}"),
    }
}
