//! Lengths, areas, closest points and the Hausdorff distance against closed forms and an
//! independent reference:
//! - circle and 240-degree arc lengths (`2 pi r`, `r 4 pi / 3`), sphere and torus areas
//!   (`4 pi r^2`, `4 pi^2 R r`) to the requested tolerance, the error estimate covering the
//!   true error;
//! - a C2 cubic B-spline's length against a 40-point Gauss-Legendre rule on 64 pieces of
//!   every span, with the derivative from the Cox-de Boor recursion written out here;
//! - closest points on a circle and a sphere against the closed forms;
//! - the same circle with other parameterisations (shifted start angle, elevated degree,
//!   reversed, reparameterised) is at Hausdorff distance ~0 from it, a moved copy at the
//!   distance moved.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::f64::consts::PI;

use nurbsx::nurbs::conic::{ConicKind, conic_arc};
use nurbsx::nurbs::measure::{Shape, curve_length, directed_distance, surface_area};
use nurbsx::nurbs::project::{invert_curve, invert_surface};
use nurbsx::nurbs::sweep::{Frame, sphere, torus};
use nurbsx::nurbs::{NurbsCurve, NurbsSurface};

fn circle(r: f64, start: f64, sweep: f64) -> NurbsCurve {
    conic_arc(
        ConicKind::Elliptic,
        [1.0, -2.0, 0.5],
        [r, 0.0, 0.0],
        [0.0, r, 0.0],
        start,
        start + sweep,
    )
    .unwrap()
    .0
}

fn frame() -> Frame {
    Frame {
        origin: [0.5, 0.25, -1.0],
        x: [1.0, 0.0, 0.0],
        y: [0.0, 1.0, 0.0],
        z: [0.0, 0.0, 1.0],
    }
}

fn ball(r: f64) -> NurbsSurface {
    sphere(&frame(), r, (0.0, 2.0 * PI), (-PI / 2.0, PI / 2.0))
        .unwrap()
        .0
}

#[test]
fn circle_and_arc_lengths() {
    for (r, tol) in [(1.0, 1e-10), (3.0, 1e-12), (250.0, 1e-8)] {
        let m = curve_length(&circle(r, 0.0, 2.0 * PI), tol).unwrap();
        assert!(m.converged, "{m:?}");
        let err = (m.value - 2.0 * PI * r).abs();
        assert!(err <= tol, "r {r}: {m:?}, error {err:e}");
        let arc = curve_length(&circle(r, 0.3, 4.0 * PI / 3.0), tol).unwrap();
        let err = (arc.value - 4.0 * PI / 3.0 * r).abs();
        assert!(arc.converged && err <= tol, "r {r}: {arc:?}, error {err:e}");
    }
    // A tolerance that cannot be reached within the piece limit is reported, not hidden.
    let m = curve_length(&circle(1.0, 0.0, 2.0 * PI), 1e-30).unwrap();
    assert!(!m.converged);
    assert!((m.value - 2.0 * PI).abs() < 1e-12);
    assert!(curve_length(&circle(1.0, 0.0, 1.0), 0.0).is_err());
}

#[test]
fn sphere_and_torus_areas() {
    for (r, tol) in [(1.0, 1e-9), (4.0, 1e-8)] {
        let m = surface_area(&ball(r), tol).unwrap();
        let err = (m.value - 4.0 * PI * r * r).abs();
        assert!(m.converged && err <= tol, "r {r}: {m:?}, error {err:e}");
    }
    let (big, small) = (5.0, 1.5);
    let t = torus(&frame(), big, small, (0.0, 2.0 * PI), (0.0, 2.0 * PI))
        .unwrap()
        .0;
    let m = surface_area(&t, 1e-8).unwrap();
    let err = (m.value - 4.0 * PI * PI * big * small).abs();
    assert!(m.converged && err <= 1e-8, "{m:?}, error {err:e}");
}

/// `N_{i,p}(u)` by the Cox-de Boor recursion (right-open spans, the last span closed).
fn basis(knots: &[f64], i: usize, p: usize, u: f64) -> f64 {
    if p == 0 {
        let last = knots[knots.len() - 1];
        let inside = knots[i] <= u && u < knots[i + 1];
        let at_end = u == last && knots[i] < knots[i + 1] && knots[i + 1] == last;
        return if inside || at_end { 1.0 } else { 0.0 };
    }
    let mut v = 0.0;
    let d1 = knots[i + p] - knots[i];
    if d1 > 0.0 {
        v += (u - knots[i]) / d1 * basis(knots, i, p - 1, u);
    }
    let d2 = knots[i + p + 1] - knots[i + 1];
    if d2 > 0.0 {
        v += (knots[i + p + 1] - u) / d2 * basis(knots, i + 1, p - 1, u);
    }
    v
}

/// `N'_{i,p}(u) = p / (u_{i+p} - u_i) N_{i,p-1} - p / (u_{i+p+1} - u_{i+1}) N_{i+1,p-1}`.
fn basis_derivative(knots: &[f64], i: usize, p: usize, u: f64) -> f64 {
    let mut v = 0.0;
    let d1 = knots[i + p] - knots[i];
    if d1 > 0.0 {
        v += p as f64 / d1 * basis(knots, i, p - 1, u);
    }
    let d2 = knots[i + p + 1] - knots[i + 1];
    if d2 > 0.0 {
        v -= p as f64 / d2 * basis(knots, i + 1, p - 1, u);
    }
    v
}

/// Gauss-Legendre nodes and weights on [-1, 1] by Newton's iteration on `P_n`.
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|i| {
            let mut x = (PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / dp;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

#[test]
fn bspline_length_matches_an_independent_high_order_rule() {
    let knots = vec![0., 0., 0., 0., 0.2, 0.45, 0.5, 0.8, 1., 1., 1., 1.];
    let poles = vec![
        [0.0, 0.0, 0.0],
        [1.0, 2.0, 0.5],
        [3.0, 2.5, -1.0],
        [4.0, -1.0, 0.0],
        [6.0, 0.0, 2.0],
        [7.0, 3.0, 1.0],
        [9.0, 1.0, -0.5],
        [10.0, 0.0, 0.0],
    ];
    let curve = NurbsCurve::new(3, knots.clone(), poles.clone(), None).unwrap();
    let speed = |u: f64| {
        let mut d = [0.0; 3];
        for (i, p) in poles.iter().enumerate() {
            let n = basis_derivative(&knots, i, 3, u);
            for k in 0..3 {
                d[k] += n * p[k];
            }
        }
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    };
    let rule = gauss_legendre(40);
    let mut reference = 0.0;
    for w in knots[3..9].windows(2) {
        let pieces = 64;
        for j in 0..pieces {
            let a = w[0] + (w[1] - w[0]) * j as f64 / pieces as f64;
            let b = w[0] + (w[1] - w[0]) * (j + 1) as f64 / pieces as f64;
            let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
            reference += rule
                .iter()
                .map(|&(x, wt)| wt * h * speed(c + h * x))
                .sum::<f64>();
        }
    }
    for tol in [1e-6, 1e-9, 1e-12] {
        let m = curve_length(&curve, tol).unwrap();
        let err = (m.value - reference).abs();
        assert!(
            m.converged && err <= tol,
            "tol {tol}: {m:?} vs {reference}, {err:e}"
        );
        assert!(m.error >= 0.0 && m.error <= tol);
    }
}

#[test]
fn closest_points_on_a_circle_and_a_sphere() {
    let r = 2.0;
    let c = circle(r, 0.0, 2.0 * PI);
    let centre = [1.0, -2.0, 0.5];
    for p in [
        [4.0, 1.0, 0.5],
        [0.0, -2.5, 3.0],
        [1.3, -1.9, -0.2],
        [-5.0, 7.0, 0.0],
    ] {
        let (u, d) = invert_curve(&c, p).unwrap();
        let rel = [p[0] - centre[0], p[1] - centre[1]];
        let h = rel[0].hypot(rel[1]);
        let want = ((h - r).powi(2) + (p[2] - centre[2]).powi(2)).sqrt();
        assert!((d - want).abs() < 1e-12, "{p:?}: {d} vs {want}");
        let q = c.point_at(u).unwrap();
        let expect = [
            centre[0] + r * rel[0] / h,
            centre[1] + r * rel[1] / h,
            centre[2],
        ];
        assert!(
            (0..3).all(|k| (q[k] - expect[k]).abs() < 1e-9),
            "{q:?} vs {expect:?}"
        );
    }
    let s = ball(3.0);
    let o = frame().origin;
    for p in [
        [4.0, 1.0, 0.5],
        [0.5, 0.25, 9.0],
        [0.2, 0.0, -0.5],
        [-6.0, 2.0, 2.0],
    ] {
        let i = invert_surface(&s, p, None).unwrap();
        let rel = [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
        let n = (rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]).sqrt();
        assert!((i.distance - (n - 3.0).abs()).abs() < 1e-12, "{p:?}: {i:?}");
        let q = s.point_at(i.u, i.v).unwrap();
        assert!(
            (0..3).all(|k| (q[k] - (o[k] + 3.0 * rel[k] / n)).abs() < 1e-9),
            "{q:?}"
        );
    }
}

fn hausdorff(a: &[Shape<'_>], b: &[Shape<'_>]) -> f64 {
    let never = || false;
    let ab = directed_distance(a, b, &never).unwrap().unwrap().distance;
    let ba = directed_distance(b, a, &never).unwrap().unwrap().distance;
    ab.max(ba)
}

#[test]
fn hausdorff_distance_ignores_the_parameterisation() {
    let c = circle(2.0, 0.0, 2.0 * PI);
    let shifted = circle(2.0, 1.0, 2.0 * PI);
    let elevated = c.elevate(2).unwrap();
    let reversed = c.reverse().unwrap().reparameterize(-3.0, 7.0).unwrap();
    for (other, what) in [
        (&shifted, "start"),
        (&elevated, "elevated"),
        (&reversed, "reversed"),
    ] {
        let d = hausdorff(&[Shape::Curve(&c)], &[Shape::Curve(other)]);
        assert!(d < 1e-10, "{what}: {d:e}");
    }
    // Moved copies: the distance moved (a circle against its translate by d in its plane
    // or along its axis is at Hausdorff distance d).
    for (m, d) in [
        ([0.0, 0.0, 0.5], 0.5),
        ([0.3, 0.4, 0.0], 0.5),
        ([0.0, 0.0, 2.0], 2.0),
    ] {
        let mut t = nurbsx::nurbs::transform::IDENTITY;
        for k in 0..3 {
            t[k][3] = m[k];
        }
        let moved = shifted.transform(&t).unwrap();
        let h = hausdorff(&[Shape::Curve(&c)], &[Shape::Curve(&moved)]);
        assert!((h - d).abs() < 1e-9, "{m:?}: {h} vs {d}");
    }
    // Surfaces: the sphere against itself elevated and reversed, and against a larger
    // concentric sphere (distance the difference of the radii).
    let s = ball(3.0);
    let other = s.elevate_u(1).unwrap().reverse_v().unwrap();
    let d = hausdorff(&[Shape::Surface(&s)], &[Shape::Surface(&other)]);
    assert!(d < 1e-10, "{d:e}");
    let bigger = ball(3.25);
    let d = hausdorff(&[Shape::Surface(&s)], &[Shape::Surface(&bigger)]);
    assert!((d - 0.25).abs() < 1e-9, "{d}");
    // One shape against two: the half circles cover it.
    let (h1, h2) = c.split_at(0.5).unwrap();
    let d = hausdorff(&[Shape::Curve(&c)], &[Shape::Curve(&h1), Shape::Curve(&h2)]);
    assert!(d < 1e-10, "{d:e}");
    assert!(
        directed_distance(&[Shape::Curve(&c)], &[], &|| false)
            .unwrap()
            .is_none()
    );
}
