//! The a-priori point estimate of tessellation against the closed form for a circle and
//! against the real tessellation: the service refuses work from this estimate before doing
//! it, so it must not exceed what the work really takes (else it would refuse requests
//! that fit) and must not be far below it (else the limit would only trip during the work).

// Test helpers outside #[test] functions fail loudly on purpose.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use std::f64::consts::PI;

use common::circle9 as circle;
use nurbsx::nurbs::{Grid, NurbsSurface};

/// The circle swept along z over height 1: a cylinder, straight along v.
fn cylinder(r: f64) -> NurbsSurface {
    let c = circle(r);
    let points = Grid::from_fn(9, 2, |i, j| {
        let p = c.control_points()[i];
        [p[0], p[1], j as f64]
    });
    let weights = Grid::from_fn(9, 2, |i, _| c.weight(i));
    NurbsSurface::new(
        2,
        1,
        c.knots().to_vec(),
        vec![0., 0., 1., 1.],
        points,
        Some(weights),
    )
    .unwrap()
}

/// Chords of sagitta `tol` around a circle of radius `r`: the chord angle satisfies
/// `r (1 - cos(theta / 2)) = tol`, so there are `2 pi / theta` of them.
fn closed_form_chords(r: f64, tol: f64) -> f64 {
    let theta = 2.0 * (1.0 - tol / r).acos();
    2.0 * PI / theta
}

#[test]
fn the_circle_estimate_matches_the_closed_form_and_bounds_the_work() {
    for (r, tol) in [(1.0, 1e-2), (1.0, 1e-4), (5.0, 1e-3), (0.01, 1e-7)] {
        let c = circle(r);
        let estimate = c.tessellation_estimate(tol);
        let exact = closed_form_chords(r, tol) + 1.0;
        assert!(
            (estimate - exact).abs() <= 0.01 * exact + 1.0,
            "r {r} tol {tol}: estimate {estimate}, closed form {exact}"
        );
        let real = c.tessellate(tol).unwrap().points.len() as f64;
        assert!(
            estimate <= real && real <= 3.0 * estimate,
            "r {r} tol {tol}: estimate {estimate}, real {real}"
        );
    }
    // Far below the floating-point resolution of the curve: a huge finite estimate, found
    // at once (the sagitta form does not round tol / r away).
    let tiny = circle(1.0).tessellation_estimate(1e-300);
    assert!(tiny.is_finite() && tiny > 1e140, "{tiny}");
}

#[test]
fn the_cylinder_estimate_bounds_the_work() {
    for (r, tol) in [(1.0, 1e-2), (2.0, 1e-3)] {
        let s = cylinder(r);
        let estimate = s.tessellation_estimate(tol);
        // Around: the circle's chords; along the straight direction: one.
        let exact = (closed_form_chords(r, tol) + 1.0) * 2.0;
        assert!(
            (estimate - exact).abs() <= 0.02 * exact + 2.0,
            "r {r} tol {tol}: estimate {estimate}, closed form {exact}"
        );
        // The mesher halves both directions where a cell's interior fails, so the straight
        // direction gets refined too: the real count is above the estimate by up to an
        // order of magnitude (the estimate is a lower bound, and the vertex limit is also
        // enforced during the work).
        let real = s.tessellate(tol).unwrap().vertices.len() as f64;
        assert!(
            estimate <= real && real <= 16.0 * estimate,
            "r {r} tol {tol}: estimate {estimate}, real {real}"
        );
    }
}
