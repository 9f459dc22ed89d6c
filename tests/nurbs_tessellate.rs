//! Tessellation: the chord error of curve polylines and the deviation of surface meshes are
//! measured independently (denser sampling than the tessellator's own check, and for the
//! circle and the sphere the exact geometric distance), the circle's segment count follows
//! the sagitta formula, and meshes have no cracks.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use std::collections::HashMap;
use std::f64::consts::{FRAC_1_SQRT_2, PI};

use common::{Ends, arb_curve, arb_surface, bbox_diagonal, circle9, dist};
use nurbsx::nurbs::tessellate::{Mesh, Polyline, point_segment_distance};
use nurbsx::nurbs::{Grid, NurbsCurve, NurbsSurface, Point3};
use proptest::prelude::*;

/// Largest distance from the curve to each chord, 64 samples per segment.
fn sampled_chord_error(c: &NurbsCurve, pl: &Polyline) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..pl.params.len() - 1 {
        let (u0, u1) = (pl.params[k], pl.params[k + 1]);
        for s in 1..64 {
            let u = u0 + (u1 - u0) * f64::from(s) / 64.0;
            let d = point_segment_distance(c.point_at(u).unwrap(), pl.points[k], pl.points[k + 1]);
            worst = worst.max(d);
        }
    }
    worst
}

/// Structural checks: params increasing from the domain start to its end, points on the
/// curve, every knot of the domain present.
fn check_polyline(c: &NurbsCurve, pl: &Polyline) -> Result<(), TestCaseError> {
    let (a, b) = c.domain();
    prop_assert_eq!(pl.params.len(), pl.points.len());
    prop_assert_eq!(pl.params.first().copied(), Some(a));
    prop_assert_eq!(pl.params.last().copied(), Some(b));
    prop_assert!(pl.params.windows(2).all(|w| w[0] < w[1]));
    for (u, p) in pl.params.iter().zip(&pl.points) {
        prop_assert_eq!(c.point_at(*u).unwrap(), *p);
    }
    for &k in c.knots() {
        if k > a && k < b {
            prop_assert!(pl.params.contains(&k), "knot {} missing", k);
        }
    }
    Ok(())
}

/// A full sphere of radius r: the 5-pole semicircle meridian revolved by the 9-pole circle
/// (NURBS Book section 8.5, surface of revolution), biquadratic rational.
fn sphere(r: f64) -> NurbsSurface {
    let w = FRAC_1_SQRT_2;
    let meridian = [
        (0., -1., 1.),
        (1., -1., w),
        (1., 0., 1.),
        (1., 1., w),
        (0., 1., 1.),
    ];
    let circle = [
        (1., 0., 1.),
        (1., 1., w),
        (0., 1., 1.),
        (-1., 1., w),
        (-1., 0., 1.),
        (-1., -1., w),
        (0., -1., 1.),
        (1., -1., w),
        (1., 0., 1.),
    ];
    let points = Grid::from_fn(5, 9, |i, j| {
        let (rr, z, _) = meridian[i];
        let (x, y, _) = circle[j];
        [r * rr * x, r * rr * y, r * z]
    });
    let weights = Grid::from_fn(5, 9, |i, j| meridian[i].2 * circle[j].2);
    NurbsSurface::new(
        2,
        2,
        vec![0., 0., 0., 0.5, 0.5, 1., 1., 1.],
        vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.],
        points,
        Some(weights),
    )
    .unwrap()
}

fn mid(a: Point3, b: Point3) -> Point3 {
    std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
}

/// Mesh checks: vertices on the surface at their parameters; at every edge midpoint and
/// triangle centroid the surface point at the averaged parameters is within `tol` of the
/// averaged vertices; every edge is used by one (boundary) or two (interior) triangles,
/// and interior edges by exactly two.
fn check_mesh(s: &NurbsSurface, m: &Mesh, tol: f64) -> f64 {
    let ((u0, u1), (v0, v1)) = s.domain();
    assert_eq!(m.vertices.len(), m.params.len());
    assert_eq!(m.normals.len(), m.vertices.len());
    for (p, uv) in m.vertices.iter().zip(&m.params) {
        assert_eq!(s.point_at(uv[0], uv[1]).unwrap(), *p);
    }
    let mut worst: f64 = 0.0;
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &m.triangles {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            let uv = mid2(m.params[a], m.params[b]);
            let d = dist(
                s.point_at(uv[0], uv[1]).unwrap(),
                mid(m.vertices[a], m.vertices[b]),
            );
            worst = worst.max(d);
        }
        let uv: [f64; 2] = std::array::from_fn(|k| {
            (m.params[t[0]][k] + m.params[t[1]][k] + m.params[t[2]][k]) / 3.0
        });
        let c: Point3 = std::array::from_fn(|k| {
            (m.vertices[t[0]][k] + m.vertices[t[1]][k] + m.vertices[t[2]][k]) / 3.0
        });
        let uv = [uv[0].clamp(u0, u1), uv[1].clamp(v0, v1)];
        worst = worst.max(dist(s.point_at(uv[0], uv[1]).unwrap(), c));
    }
    assert!(worst <= tol, "mesh deviation {worst:e} > {tol:e}");
    let on_boundary = |a: usize, b: usize| {
        let (p, q) = (m.params[a], m.params[b]);
        (p[0] == q[0] && (p[0] == u0 || p[0] == u1)) || (p[1] == q[1] && (p[1] == v0 || p[1] == v1))
    };
    for (&(a, b), &n) in &edges {
        if on_boundary(a, b) {
            assert_eq!(n, 1, "boundary edge {a}-{b} used {n} times");
        } else {
            assert_eq!(
                n, 2,
                "interior edge {a}-{b} used {n} times (crack or overlap)"
            );
        }
    }
    worst
}

fn mid2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn random_curves_meet_the_chord_tolerance(
        c in arb_curve(5, true, Ends::Any),
        rel in prop::sample::select(vec![1e-2, 1e-3, 1e-4]),
    ) {
        let tol = rel * bbox_diagonal(c.control_points());
        let pl = c.tessellate(tol).unwrap();
        check_polyline(&c, &pl)?;
        let err = sampled_chord_error(&c, &pl);
        prop_assert!(err <= tol, "chord error {:e} > tol {:e}", err, tol);
    }

}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn random_surfaces_meet_the_tolerance(s in arb_surface(3, true, Ends::Any)) {
        let tol = 2e-2 * bbox_diagonal(s.control_points().as_slice());
        let m = s.tessellate(tol).unwrap();
        check_mesh(&s, &m, tol);
    }
}

#[test]
fn circle_polyline_follows_the_sagitta_formula() {
    for (r, tol) in [(5.0, 1e-3), (1.0, 1e-2), (100.0, 1e-4), (2.0, 1e-6)] {
        let c = circle9(r);
        let pl = c.tessellate(tol).unwrap();
        // Exact geometric check: a chord of a circle is farthest from the arc at its middle,
        // at distance r - |midpoint|.
        let sagitta = pl
            .points
            .windows(2)
            .map(|w| r - (mid(w[0], w[1])[0].hypot(mid(w[0], w[1])[1])))
            .fold(0.0, f64::max);
        assert!(sagitta <= tol * (1.0 + 1e-9), "r={r}: sagitta {sagitta:e}");
        let sampled = sampled_chord_error(&c, &pl);
        assert!(sampled <= tol, "r={r}: sampled chord error {sampled:e}");
        // A chord with sagitta <= tol subtends at most 2 acos(1 - tol / r), so at least
        // pi / acos(1 - tol / r) segments are needed; the osculating rule should not use
        // many more.
        let ideal = PI / (1.0 - tol / r).acos();
        let n = (pl.points.len() - 1) as f64;
        assert!(n >= ideal.floor(), "r={r}: {n} segments < {ideal}");
        assert!(n <= 1.3 * ideal + 4.0, "r={r}: {n} segments >> {ideal}");
    }
}

#[test]
fn straight_line_needs_only_its_knots_and_a_few_points() {
    let c = NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 1., 2., 2., 2., 2.],
        (0..5)
            .map(|i| [f64::from(i), 2.0 * f64::from(i), 0.])
            .collect(),
        None,
    )
    .unwrap();
    let pl = c.tessellate(1e-6).unwrap();
    assert_eq!(pl.params, vec![0., 1., 2.], "a line with one inner knot");
    assert!(sampled_chord_error(&c, &pl) <= 1e-6);
}

/// Largest distance from 4096 samples of the exact curve (evenly spaced in the domain, not
/// at the polyline's parameters) to the polyline as a whole.
fn curve_to_polyline(c: &NurbsCurve, pl: &Polyline) -> f64 {
    let (a, b) = c.domain();
    (0..=4096)
        .map(|k| {
            let x = c.point_at(a + (b - a) * f64::from(k) / 4096.0).unwrap();
            pl.points
                .windows(2)
                .map(|w| point_segment_distance(x, w[0], w[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_line_is_its_two_ends() {
    // Degree 1, a cubic with unevenly spaced collinear poles, a rational quadratic on a line.
    let lines = [
        NurbsCurve::new(
            1,
            vec![0., 0., 1., 1.],
            vec![[0., 0., 0.], [3., 4., 5.]],
            None,
        ),
        NurbsCurve::new(
            3,
            vec![0., 0., 0., 0., 1., 1., 1., 1.],
            vec![[1., 1., 1.], [1.5, 2., 2.5], [2.5, 4., 5.5], [4., 7., 10.]],
            None,
        ),
        NurbsCurve::new(
            2,
            vec![0., 0., 0., 2., 2., 2.],
            vec![[0., 0., 0.], [1., -1., 0.], [4., -4., 0.]],
            Some(vec![1., 3., 0.5]),
        ),
    ];
    for (k, c) in lines.into_iter().enumerate() {
        let c = c.unwrap();
        for tol in [1e-9, 1e-3, 1.0] {
            let pl = c.tessellate(tol).unwrap();
            assert_eq!(pl.points.len(), 2, "line {k} at {tol}: {:?}", pl.params);
            assert!(curve_to_polyline(&c, &pl) <= 1e-12, "line {k} at {tol}");
        }
    }
}

#[test]
fn a_degree_1_polyline_is_its_own_vertices() {
    // Two collinear segments in a row stay two (every knot is a vertex).
    let poles = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
        [3., 1., 1.],
    ];
    let c = NurbsCurve::new(1, vec![0., 0., 1., 2., 3., 4., 4.], poles.clone(), None).unwrap();
    for tol in [1e-9, 1e-2] {
        let pl = c.tessellate(tol).unwrap();
        assert_eq!(pl.params, vec![0., 1., 2., 3., 4.]);
        for (p, q) in pl.points.iter().zip(&poles) {
            assert!(dist(*p, *q) <= 1e-15, "{p:?} vs pole {q:?}");
        }
    }
}

#[test]
fn a_straight_span_inside_a_curved_spline_is_one_chord() {
    // Quadratic, spans [0,1], [1,2], [2,3]: the middle span's poles P1..P3 are collinear,
    // the outer spans bend (P0 and P4 off the line).
    let c = NurbsCurve::new(
        2,
        vec![0., 0., 0., 1., 2., 3., 3., 3.],
        vec![
            [0., 2., 0.],
            [1., 0., 0.],
            [2., 0., 0.],
            [3., 0., 0.],
            [4., 2., 0.],
        ],
        None,
    )
    .unwrap();
    for tol in [1e-2, 1e-4, 1e-6] {
        let pl = c.tessellate(tol).unwrap();
        let i = pl.params.iter().position(|&u| u == 1.0).unwrap();
        assert_eq!(pl.params[i + 1], 2.0, "at {tol}: {:?}", pl.params);
        // The curved spans need several chords each, and meet the tolerance.
        assert!(
            i >= 3 && pl.params.len() - i - 2 >= 3,
            "at {tol}: {:?}",
            pl.params
        );
        let err = curve_to_polyline(&c, &pl);
        assert!(err <= tol, "at {tol}: curve {err:e} from the polyline");
        assert!(sampled_chord_error(&c, &pl) <= tol);
    }
}

#[test]
fn a_folded_straight_span_is_not_one_chord() {
    // Collinear poles that run past the end (0 -> 3 -> 1): the curve goes out to x = 1.8
    // and back, so the chord [0, 1] does not cover it.
    let c = NurbsCurve::new(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        vec![[0., 0., 0.], [3., 0., 0.], [1., 0., 0.]],
        None,
    )
    .unwrap();
    let pl = c.tessellate(1e-3).unwrap();
    assert!(pl.points.len() > 2);
    assert!(curve_to_polyline(&c, &pl) <= 1e-3);
    assert!(sampled_chord_error(&c, &pl) <= 1e-3);
}

#[test]
fn bad_tolerances_are_refused() {
    let c = circle9(1.0);
    for t in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(c.tessellate(t).is_err());
        assert!(sphere(1.0).tessellate(t).is_err());
    }
}

#[test]
fn sphere_mesh_lies_within_tolerance() {
    for (r, tol) in [(1.0, 1e-2), (10.0, 2e-2)] {
        let s = sphere(r);
        let m = s.tessellate(tol).unwrap();
        // Vertices exactly on the sphere (up to rounding).
        for p in &m.vertices {
            let d = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            assert!((d - r).abs() <= 1e-13 * r, "vertex at radius {d}");
        }
        let worst = check_mesh(&s, &m, tol);
        assert!(
            worst > 0.2 * tol,
            "mesh much finer than needed: {worst:e} vs {tol:e}"
        );
        // Geometric check independent of the parameterisation: edge midpoints and centroids
        // are inside the sphere by at most tol.
        for t in &m.triangles {
            let [a, b, c] = t.map(|k| m.vertices[k]);
            for q in [mid(a, b), mid(b, c), mid(c, a)] {
                let d = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                assert!(
                    r - d <= tol * (1.0 + 1e-9),
                    "edge midpoint {:e} inside",
                    r - d
                );
            }
        }
        // Normals point outwards (the sphere is parameterised with outward S_u x S_v or
        // inward; either way consistently).
        let sign: Vec<f64> = m
            .normals
            .iter()
            .zip(&m.vertices)
            .filter(|(n, _)| n.iter().any(|x| *x != 0.0))
            .map(|(n, p)| (n[0] * p[0] + n[1] * p[1] + n[2] * p[2]).signum())
            .collect();
        assert!(sign.iter().all(|s| *s == sign[0]), "normals not consistent");
    }
}

#[test]
fn degenerate_geometry_terminates() {
    // All poles at one point: zero speed everywhere.
    let c = NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 1., 1., 1., 1.],
        vec![[1., 2., 3.]; 4],
        None,
    )
    .unwrap();
    let pl = c.tessellate(1e-9).unwrap();
    assert!(pl.points.len() <= 8);
    // A cusp (two coincident middle poles) and a huge tolerance.
    let c = NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 1., 1., 1., 1.],
        vec![[0., 0., 0.], [1., 1., 0.], [1., 1., 0.], [2., 0., 0.]],
        None,
    )
    .unwrap();
    for tol in [1e-8, 1e3] {
        let pl = c.tessellate(tol).unwrap();
        assert!(sampled_chord_error(&c, &pl) <= tol);
    }
    // A surface collapsed to a point: one cell per span, no refinement.
    let s = NurbsSurface::new(
        1,
        1,
        vec![0., 0., 1., 1.],
        vec![0., 0., 1., 1.],
        Grid::from_fn(2, 2, |_, _| [5., 5., 5.]),
        None,
    )
    .unwrap();
    let m = s.tessellate(1e-9).unwrap();
    assert_eq!(m.triangles.len(), 2);
    assert_eq!(m.normals, vec![[0.; 3]; 4]);
}
