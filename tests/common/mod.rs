//! Test support shared by the integration tests: proptest strategies for random valid NURBS
//! curves and surfaces (rational and polynomial, clamped and unclamped, with repeated
//! interior knots), geometric comparison by sampling, and where FreeCAD is.
//!
//! Every test file that uses it declares `mod common;`; not every file uses every item.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

use nurbsx::nurbs::{Grid, NurbsCurve, NurbsSurface, Point3};
use proptest::prelude::*;

/// `freecadcmd` (or `FreeCADCmd`) found on PATH.
pub fn find_freecadcmd() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| ["freecadcmd", "FreeCADCmd"].map(|name| dir.join(name)))
        .find(|candidate| candidate.is_file())
}

/// How the ends of a random knot vector look.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ends {
    /// End multiplicity degree + 1.
    Clamped,
    /// Distinct outer knots (end multiplicity 1).
    Unclamped,
    /// Either, at random.
    Any,
}

/// A random non-decreasing knot vector for `poles` control points of degree `p`: random
/// positive gaps (some interior knots repeated up to `p` times), shifted and scaled so the
/// domain does not always start at 0.
pub fn arb_knots(p: usize, poles: usize, ends: Ends) -> impl Strategy<Value = Vec<f64>> {
    let m = poles + p + 1;
    let clamped = match ends {
        Ends::Clamped => Just(true).boxed(),
        Ends::Unclamped => Just(false).boxed(),
        Ends::Any => any::<bool>().boxed(),
    };
    (
        clamped,
        prop::collection::vec(0.05f64..2.0, m),
        prop::collection::vec(0usize..4, m),
        -5.0f64..5.0,
    )
        .prop_map(move |(clamped, gaps, repeat, offset)| {
            // Build distinct values with a multiplicity each, then flatten to m knots.
            let mut knots = Vec::with_capacity(m);
            let mut t = offset;
            if clamped {
                knots.extend(std::iter::repeat_n(t, p + 1));
            } else {
                knots.push(t);
            }
            let mut i = 0;
            let tail = if clamped { p + 1 } else { 1 };
            while knots.len() < m - tail {
                t += gaps[i % gaps.len()];
                // Interior multiplicity 1 mostly, up to p sometimes.
                let mult = if repeat[i % repeat.len()] == 0 {
                    1 + (i % p.max(1))
                } else {
                    1
                }
                .min(m - tail - knots.len());
                knots.extend(std::iter::repeat_n(t, mult));
                i += 1;
            }
            t += gaps[(i + 1) % gaps.len()];
            knots.extend(std::iter::repeat_n(t, tail));
            knots
        })
}

/// A random valid 3-D curve of degree `1..=max_degree` with `degree + 1 ..= degree + 8`
/// poles in `[-10, 10]^3`; rational with weights in `[0.2, 5]` when `rational`.
pub fn arb_curve(
    max_degree: usize,
    rational: bool,
    ends: Ends,
) -> impl Strategy<Value = NurbsCurve> {
    (1..=max_degree, 0usize..8)
        .prop_flat_map(move |(p, extra)| {
            let n = p + 1 + extra;
            (
                Just(p),
                arb_knots(p, n, ends),
                prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), n),
                prop::collection::vec(0.2f64..5.0, n),
            )
        })
        .prop_filter_map("valid curve", move |(p, knots, points, weights)| {
            NurbsCurve::new(p, knots, points, rational.then_some(weights)).ok()
        })
}

/// A random valid 3-D surface, degrees `1..=max_degree` in each direction.
pub fn arb_surface(
    max_degree: usize,
    rational: bool,
    ends: Ends,
) -> impl Strategy<Value = NurbsSurface> {
    (1..=max_degree, 1..=max_degree, 0usize..4, 0usize..4)
        .prop_flat_map(move |(p, q, eu, ev)| {
            let (nu, nv) = (p + 1 + eu, q + 1 + ev);
            (
                Just((p, q, nu, nv)),
                arb_knots(p, nu, ends),
                arb_knots(q, nv, ends),
                prop::collection::vec(prop::array::uniform3(-10.0f64..10.0), nu * nv),
                prop::collection::vec(0.2f64..5.0, nu * nv),
            )
        })
        .prop_filter_map("valid surface", move |((p, q, nu, nv), ku, kv, pts, w)| {
            let points = Grid::from_u_major(nu, nv, pts)?;
            let weights = if rational {
                Some(Grid::from_u_major(nu, nv, w)?)
            } else {
                None
            };
            NurbsSurface::new(p, q, ku, kv, points, weights).ok()
        })
}

/// Euclidean distance.
pub fn dist(a: Point3, b: Point3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Diagonal of the axis-aligned box around some points (the "model size" tolerances are
/// relative to).
pub fn bbox_diagonal(points: &[Point3]) -> f64 {
    nurbsx::nurbs::bounding_box_diagonal(points)
}

/// `samples` parameters spread over `[a, b]`: both ends, every knot inside, and evenly
/// spaced values, so spans and knot boundaries are all exercised.
pub fn params(a: f64, b: f64, knots: &[f64], samples: usize) -> Vec<f64> {
    let mut t: Vec<f64> = (0..samples)
        // The last sample must be exactly `b`: `a + (b - a) * 1.0` can round above it.
        .map(|i| (a + (b - a) * i as f64 / (samples - 1) as f64).min(b))
        .collect();
    t.extend(knots.iter().copied().filter(|&k| k >= a && k <= b));
    t
}

/// Largest distance between two curves over `samples` parameters of the first curve's
/// domain, divided by the first curve's control-polygon size (relative deviation).
/// Panics if the domains differ (a shape-preserving operation must keep the domain).
pub fn curve_deviation(a: &NurbsCurve, b: &NurbsCurve, samples: usize) -> f64 {
    let (s, e) = a.domain();
    assert_eq!(a.domain(), b.domain(), "domains differ");
    let size = bbox_diagonal(a.control_points()).max(f64::MIN_POSITIVE);
    params(s, e, a.knots(), samples)
        .into_iter()
        .map(|t| dist(a.point_at(t).unwrap(), b.point_at(t).unwrap()))
        .fold(0.0, f64::max)
        / size
}

/// Largest distance between two surfaces over a `n x n` grid (plus knot lines) of the first
/// surface's domain, relative to its control-net size. Panics if the domains differ.
pub fn surface_deviation(a: &NurbsSurface, b: &NurbsSurface, n: usize) -> f64 {
    let ((u0, u1), (v0, v1)) = a.domain();
    assert_eq!(a.domain(), b.domain(), "domains differ");
    let size = bbox_diagonal(a.control_points().as_slice()).max(f64::MIN_POSITIVE);
    let us = params(u0, u1, a.knots_u(), n);
    let vs = params(v0, v1, a.knots_v(), n);
    let mut worst: f64 = 0.0;
    for &u in &us {
        for &v in &vs {
            worst = worst.max(dist(a.point_at(u, v).unwrap(), b.point_at(u, v).unwrap()));
        }
    }
    worst / size
}

/// `a - b`.
pub fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Euclidean length.
pub fn norm(a: Point3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Dot product.
pub fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
pub fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The 9-pole quadratic NURBS circle of radius r around the origin in the xy plane (square
/// control polygon, weights 1 and sqrt(2)/2; seed 000 figure 2-80, section 2-23).
pub fn circle9(r: f64) -> NurbsCurve {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let sq = [
        [1., 0.],
        [1., 1.],
        [0., 1.],
        [-1., 1.],
        [-1., 0.],
        [-1., -1.],
        [0., -1.],
        [1., -1.],
        [1., 0.],
    ];
    NurbsCurve::new(
        2,
        vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.],
        sq.iter().map(|q| [r * q[0], r * q[1], 0.]).collect(),
        Some(vec![1., w, 1., w, 1., w, 1., w, 1.]),
    )
    .unwrap()
}

/// The poles and middle weight of a 100-degree circular arc of radius 37.5 about
/// (12, -3, 7) in the plane of x = (1, 2, 2) / 3, y = (2, 1, -2) / 3: one rational Bezier
/// segment whose middle pole is at radius r / w, w = cos 50 degrees (NURBS Book eq. 7.33),
/// every number a tilted plane makes irrational.
pub fn tilted_arc() -> ([Point3; 3], f64) {
    let (r, sweep) = (37.5, 100f64.to_radians());
    let w = (sweep / 2.0).cos();
    let at = |t: f64, rad: f64| -> Point3 {
        let (x, y) = ([1.0, 2.0, 2.0], [2.0, 1.0, -2.0]);
        let c = [12.0, -3.0, 7.0];
        [0, 1, 2].map(|i| c[i] + rad * (t.cos() * x[i] + t.sin() * y[i]) / 3.0)
    };
    ([at(0.0, r), at(sweep / 2.0, r / w), at(sweep, r)], w)
}

/// `x` with 8 significant digits, as many CAD writers print reals.
pub fn eight_digits(x: f64) -> String {
    format!("{x:.7E}")
}
