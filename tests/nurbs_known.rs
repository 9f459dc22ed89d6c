//! Known values and textbook identities: NURBS circles (seed 000 section 2-23) lie exactly on
//! their circle, before and after degree elevation; Bernstein identities; de Casteljau equals
//! the B-spline evaluation of a Bezier curve; the Bezier derivative is `n` times the forward
//! differences (seed 000 section 2-6, seed 001); Bezier degree elevation gives the seed's
//! explicit poles (seed 000 eq. 2-62).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{circle9, dist};
use nurbsx::nurbs::bernstein::{all_bernstein, bernstein, bernstein_max, binomial};
use nurbsx::nurbs::{NurbsCurve, Point3};
use proptest::prelude::*;

/// The 7-pole circle of radius r (equilateral triangle, three 120-degree arcs with middle
/// weights cos 60 = 1/2).
fn circle7(r: f64) -> NurbsCurve {
    let s3 = 3f64.sqrt();
    let pts = [
        [r, 0.],
        [r, r * s3],
        [-r / 2., r * s3 / 2.],
        [-2. * r, 0.],
        [-r / 2., -r * s3 / 2.],
        [r, -r * s3],
        [r, 0.],
    ];
    NurbsCurve::new(
        2,
        vec![0., 0., 0., 1. / 3., 1. / 3., 2. / 3., 2. / 3., 1., 1., 1.],
        pts.iter().map(|q| [q[0], q[1], 0.]).collect(),
        Some(vec![1., 0.5, 1., 0.5, 1., 0.5, 1.]),
    )
    .unwrap()
}

fn radius_error(c: &NurbsCurve, r: f64, samples: u32) -> f64 {
    (0..=samples)
        .map(|i| {
            let u = f64::from(i) / f64::from(samples);
            let p = c.point_at(u).unwrap();
            ((p[0].hypot(p[1]) - r) / r).abs().max(p[2].abs())
        })
        .fold(0.0, f64::max)
}

#[test]
fn nurbs_circles_are_exact() {
    for r in [1.0, 0.001, 37.5, 1e4] {
        for c in [circle9(r), circle7(r)] {
            let e = radius_error(&c, r, 5000);
            assert!(e <= 1e-14, "r={r}: relative radius error {e:e}");
            for t in [1, 2, 3] {
                let el = c.elevate(t).unwrap();
                let e = radius_error(&el, r, 5000);
                assert!(e <= 1e-12, "r={r} t={t}: relative radius error {e:e}");
            }
        }
    }
    // Quarter points of the 9-pole circle are the axis points.
    let c = circle9(2.0);
    for (u, p) in [
        (0.25, [0., 2., 0.]),
        (0.5, [-2., 0., 0.]),
        (0.75, [0., -2., 0.]),
    ] {
        assert!(dist(c.point_at(u).unwrap(), p) < 1e-15);
    }
}

/// Independent de Casteljau (seed 000 section 2-3): repeated linear interpolation.
fn de_casteljau(points: &[Point3], t: f64) -> Point3 {
    let mut b = points.to_vec();
    let n = b.len();
    for r in 1..n {
        for i in 0..n - r {
            b[i] = std::array::from_fn(|k| (1.0 - t) * b[i][k] + t * b[i + 1][k]);
        }
    }
    b[0]
}

fn bezier(points: Vec<Point3>) -> NurbsCurve {
    let n = points.len();
    let mut knots = vec![0.0; n];
    knots.extend(std::iter::repeat_n(1.0, n));
    NurbsCurve::new(n - 1, knots, points, None).unwrap()
}

fn arb_bezier_points() -> impl Strategy<Value = Vec<Point3>> {
    prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), 2..12)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn bernstein_identities(n in 0usize..30, t in 0.0f64..=1.0) {
        let all = all_bernstein(n, t);
        // Partition of unity.
        let sum: f64 = all.iter().sum();
        prop_assert!((sum - 1.0).abs() <= 1e-14);
        for (i, &from_all) in all.iter().enumerate() {
            let b = bernstein(i, n, t);
            // Closed form C(n, i) t^i (1 - t)^(n - i).
            let closed = binomial(n, i) * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32);
            prop_assert!((b - closed).abs() <= 1e-13, "B_{},{} = {} vs {}", i, n, b, closed);
            prop_assert!((b - from_all).abs() <= 1e-15);
            // Symmetry B_{i,n}(t) = B_{n-i,n}(1 - t).
            prop_assert!((b - bernstein(n - i, n, 1.0 - t)).abs() <= 1e-14);
            prop_assert!(b >= 0.0 && b <= bernstein_max(i, n) + 1e-15);
        }
        // End-point values.
        prop_assert_eq!(bernstein(0, n, 0.0), 1.0);
        prop_assert_eq!(bernstein(n, n, 1.0), 1.0);
        if n > 0 {
            prop_assert_eq!(bernstein(1, n, 0.0), 0.0);
        }
    }

    #[test]
    fn de_casteljau_equals_b_spline_evaluation(pts in arb_bezier_points(), t in 0.0f64..=1.0) {
        let c = bezier(pts.clone());
        let size = common::bbox_diagonal(&pts).max(1.0);
        prop_assert!(dist(c.point_at(t).unwrap(), de_casteljau(&pts, t)) <= 1e-13 * size);
        // Bernstein form.
        let n = pts.len() - 1;
        let b = all_bernstein(n, t);
        let sum: Point3 = std::array::from_fn(|k| (0..=n).map(|i| b[i] * pts[i][k]).sum());
        prop_assert!(dist(c.point_at(t).unwrap(), sum) <= 1e-13 * size);
        // End-point interpolation.
        prop_assert_eq!(c.point_at(0.0).unwrap(), pts[0]);
        prop_assert!(dist(c.point_at(1.0).unwrap(), pts[n]) <= 1e-15 * size);
    }

    #[test]
    fn bezier_derivative_is_n_times_forward_differences(pts in arb_bezier_points(), t in 0.01f64..0.99) {
        let c = bezier(pts.clone());
        let n = pts.len() - 1;
        let diffs: Vec<Point3> = pts
            .windows(2)
            .map(|w| std::array::from_fn(|k| n as f64 * (w[1][k] - w[0][k])))
            .collect();
        let hodograph = de_casteljau(&diffs, t);
        // Central finite difference, O(h^2) error.
        let h = 1e-5;
        let (p, q) = (c.point_at(t + h).unwrap(), c.point_at(t - h).unwrap());
        let fd: Point3 = std::array::from_fn(|k| (p[k] - q[k]) / (2.0 * h));
        let size = common::bbox_diagonal(&pts).max(1.0) * (n * n) as f64;
        prop_assert!(dist(fd, hodograph) <= 1e-6 * size, "{:?} vs {:?}", fd, hodograph);
    }

    #[test]
    fn bezier_elevation_gives_the_seed_poles(pts in arb_bezier_points(), r in 1usize..4) {
        // Seed 000 eq. 2-62: b_i^(1) = i/(n+1) b_{i-1} + (1 - i/(n+1)) b_i, applied r times.
        let mut expected = pts.clone();
        for _ in 0..r {
            let n = expected.len() - 1;
            let mut next = Vec::with_capacity(n + 2);
            for i in 0..=n + 1 {
                let a = i as f64 / (n + 1) as f64;
                let prev = if i == 0 { [0.0; 3] } else { expected[i - 1] };
                let cur = if i == n + 1 { [0.0; 3] } else { expected[i] };
                next.push(std::array::from_fn(|k| a * prev[k] + (1.0 - a) * cur[k]));
            }
            expected = next;
        }
        let e = bezier(pts.clone()).elevate(r).unwrap();
        prop_assert_eq!(e.control_points().len(), expected.len());
        let size = common::bbox_diagonal(&pts).max(1.0);
        for (p, q) in e.control_points().iter().zip(&expected) {
            prop_assert!(dist(*p, *q) <= 1e-13 * size, "{:?} vs {:?}", p, q);
        }
    }
}
