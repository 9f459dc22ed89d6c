//! Whether a NURBS really is the kind of geometry its [`Shape`] label says, so that writers
//! label it (STEP `curve_form`/`surface_form`) only when it is true.
//!
//! The checks, each on points of the geometry itself (not on its metadata), within 1e-9 of
//! the control polygon's size:
//! - `Line`: every pole on the line through the first and last pole;
//! - `Polyline`: degree 1;
//! - `CircularArc`: degree 2, rational, and the curve's points at every knot and at three
//!   points inside each knot span lie in one plane at one distance from one centre (the
//!   circumcentre of the start, middle and end points);
//! - `EllipticArc` / `ParabolicArc` / `HyperbolicArc`: degree 2, every pole in one plane, and
//!   each rational quadratic segment of that conic type: with its end weights `w0`, `w2` and
//!   middle weight `w1`, `w1^2 / (w0 w2)` below 1, equal to 1, above 1 (NURBS Book 7.3: the
//!   conic shape factor; a polynomial segment is parabolic);
//! - `Plane`: every pole in one plane;
//! - `Cylinder`, `Cone`: every v-isoparametric line straight (degree 1 in v) and the
//!   u-isoparametric curves at both v ends circular arcs (as above) whose centres lie on one
//!   axis normal to their planes; a cylinder's two radii equal;
//! - `Sphere`: the surface's points on a 5 x 5 grid of every knot span at one distance from
//!   one centre (least-squares sphere through them);
//! - `Torus`, `Revolution`: the u-isoparametric curves at the v knots circular arcs centred
//!   on one axis and normal to it; a torus's v-isoparametric curves circles of one radius;
//! - `Extrusion`: every v-isoparametric curve a straight segment, all with one direction
//!   and length;
//! - `Ruled`: degree 1 in v.

use super::Shape;
use crate::nurbs::derivatives::{cross, dot, norm};
use crate::nurbs::{Geometry, NurbsCurve, NurbsSurface, Point3, bounding_box_diagonal};

fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Relative tolerance of every check.
const TOL: f64 = 1e-9;

/// Points of a curve at its knots and three points inside each non-empty span.
fn curve_samples(c: &NurbsCurve) -> Vec<Point3> {
    let (a, b) = c.domain();
    let mut ts: Vec<f64> = c
        .knots()
        .iter()
        .copied()
        .filter(|k| *k >= a && *k <= b)
        .collect();
    ts.dedup();
    let mut out = Vec::with_capacity(ts.len() * 4);
    for w in ts.windows(2) {
        for k in 0..4 {
            out.push(c.point_at_unchecked(w[0] + (w[1] - w[0]) * k as f64 / 4.0));
        }
    }
    out.push(c.point_at_unchecked(b));
    out
}

/// The unit normal of the plane through `points`, if they span one (`None` when all are
/// collinear); `Err` when they are not coplanar within `tol`.
fn plane_normal(points: &[Point3], tol: f64) -> Result<Option<Point3>, String> {
    let Some(&p0) = points.first() else {
        return Ok(None);
    };
    // The farthest point from p0, then the point farthest from that line.
    let far = points
        .iter()
        .copied()
        .max_by(|a, b| norm(sub(*a, p0)).total_cmp(&norm(sub(*b, p0))))
        .unwrap_or(p0);
    let d = sub(far, p0);
    let n = points
        .iter()
        .map(|&p| cross(d, sub(p, p0)))
        .max_by(|a, b| norm(*a).total_cmp(&norm(*b)))
        .unwrap_or([0.0; 3]);
    if norm(n) <= tol * norm(d).max(f64::MIN_POSITIVE) {
        return Ok(None);
    }
    let n = [n[0] / norm(n), n[1] / norm(n), n[2] / norm(n)];
    for &p in points {
        let off = dot(sub(p, p0), n).abs();
        if off > tol {
            return Err(format!("points leave their plane by {off:e}"));
        }
    }
    Ok(Some(n))
}

/// Centre, unit normal and radius of a circular arc, or why it is not one.
fn circle(c: &NurbsCurve) -> Result<(Point3, Point3, f64), String> {
    if c.degree() != 2 || !c.is_rational() {
        return Err("a circular arc is a rational quadratic".into());
    }
    let pts = curve_samples(c);
    let tol = TOL * bounding_box_diagonal(c.control_points()).max(f64::MIN_POSITIVE);
    let (a, b) = c.domain();
    let (p, q, r) = (
        c.point_at_unchecked(a),
        c.point_at_unchecked(0.5 * (a + b)),
        c.point_at_unchecked(b),
    );
    let n = plane_normal(&pts, tol)?.ok_or("the arc's points are collinear")?;
    // Circumcentre of p, q, r: p + (|u|^2 (v x w) ... ) in the standard form.
    let (u, v) = (sub(q, p), sub(r, p));
    let w = cross(u, v);
    let ww = dot(w, w);
    let centre = if norm(v) > tol && ww > 0.0 {
        let t1 = cross(w, u);
        let t2 = cross(v, w);
        let k1 = dot(v, v) / (2.0 * ww);
        let k2 = dot(u, u) / (2.0 * ww);
        [
            p[0] + k1 * t1[0] + k2 * t2[0],
            p[1] + k1 * t1[1] + k2 * t2[1],
            p[2] + k1 * t1[2] + k2 * t2[2],
        ]
    } else {
        // A full circle: start = end; the centre is the midpoint of start and middle.
        [
            (p[0] + q[0]) / 2.0,
            (p[1] + q[1]) / 2.0,
            (p[2] + q[2]) / 2.0,
        ]
    };
    let radius = norm(sub(p, centre));
    for x in &pts {
        let off = (norm(sub(*x, centre)) - radius).abs();
        if off > tol {
            return Err(format!("a point of the arc is {off:e} off the circle"));
        }
    }
    Ok((centre, n, radius))
}

/// The conic type of each rational quadratic segment: `w1^2 / (w0 w2)` compared with 1.
fn conic_segments(c: &NurbsCurve, want: std::cmp::Ordering) -> Result<(), String> {
    if c.degree() != 2 {
        return Err("a conic arc is quadratic".into());
    }
    let tol = TOL * bounding_box_diagonal(c.control_points()).max(f64::MIN_POSITIVE);
    plane_normal(c.control_points(), tol)?;
    // Each Bezier segment after knot insertion (A5.1) at the interior knots: split there.
    let mut rest = c.clone();
    let (a, b) = c.domain();
    let mut interior: Vec<f64> = c
        .knots()
        .iter()
        .copied()
        .filter(|k| *k > a && *k < b)
        .collect();
    interior.dedup();
    let mut pieces = Vec::new();
    for k in interior {
        let (l, r) = rest.split_at(k).map_err(|e| e.to_string())?;
        pieces.push(l);
        rest = r;
    }
    pieces.push(rest);
    for s in &pieces {
        let w = [s.weight(0), s.weight(1), s.weight(2)];
        let k = w[1] * w[1] / (w[0] * w[2]);
        let got = if (k - 1.0).abs() <= 1e-12 {
            std::cmp::Ordering::Equal
        } else if k < 1.0 {
            std::cmp::Ordering::Less
        } else {
            std::cmp::Ordering::Greater
        };
        if got != want {
            return Err(format!("a segment's conic shape factor is {k}"));
        }
    }
    Ok(())
}

/// The end points of a straight curve, or why it is not straight.
fn segment(c: &NurbsCurve, tol: f64) -> Result<(Point3, Point3), String> {
    let ps = c.control_points();
    let (Some(&p0), Some(&p1)) = (ps.first(), ps.last()) else {
        return Err("no poles".into());
    };
    let d = sub(p1, p0);
    let len = norm(d);
    for &p in ps {
        let off = if len > 0.0 {
            norm(cross(d, sub(p, p0))) / len
        } else {
            norm(sub(p, p0))
        };
        if off > tol {
            return Err(format!("a pole is {off:e} off the line"));
        }
    }
    Ok((p0, p1))
}

/// Circles at the given v values, all centred on one axis normal to their planes.
fn coaxial_circles(s: &NurbsSurface, vs: &[f64], tol: f64) -> Result<Vec<f64>, String> {
    let mut radii = Vec::new();
    let mut axis: Option<(Point3, Point3)> = None;
    for &v in vs {
        let c = s.iso_v(v).map_err(|e| e.to_string())?;
        // A degenerate row (a pole of a sphere or a cone's apex) is a point on the axis.
        if bounding_box_diagonal(c.control_points()) <= tol {
            continue;
        }
        let (centre, n, r) = circle(&c)?;
        match axis {
            None => axis = Some((centre, n)),
            Some((o, a)) => {
                if norm(cross(a, n)) > TOL.sqrt() * 1e-3 {
                    return Err("circles with different normals".into());
                }
                let off = norm(cross(a, sub(centre, o)));
                if off > tol {
                    return Err(format!("a circle's centre is {off:e} off the axis"));
                }
            }
        }
        radii.push(r);
    }
    if radii.is_empty() {
        return Err("no circle".into());
    }
    Ok(radii)
}

fn v_knots(s: &NurbsSurface) -> Vec<f64> {
    let ((_, _), (v0, v1)) = s.domain();
    let mut vs: Vec<f64> = s
        .knots_v()
        .iter()
        .copied()
        .filter(|k| *k >= v0 && *k <= v1)
        .collect();
    vs.dedup();
    vs
}

/// `Ok` when `geometry` is the kind `shape` says; else what disagrees.
pub fn check_shape(shape: Shape, geometry: &Geometry) -> Result<(), String> {
    use std::cmp::Ordering;
    match (shape, geometry) {
        (Shape::Line, Geometry::Curve(c)) => {
            let tol = TOL * bounding_box_diagonal(c.control_points());
            segment(c, tol).map(|_| ())
        }
        (Shape::Polyline, Geometry::Curve(c)) => {
            if c.degree() == 1 {
                Ok(())
            } else {
                Err("a polyline is degree 1".into())
            }
        }
        (Shape::CircularArc, Geometry::Curve(c)) => circle(c).map(|_| ()),
        (Shape::EllipticArc, Geometry::Curve(c)) => conic_segments(c, Ordering::Less),
        (Shape::ParabolicArc, Geometry::Curve(c)) => conic_segments(c, Ordering::Equal),
        (Shape::HyperbolicArc, Geometry::Curve(c)) => conic_segments(c, Ordering::Greater),
        (Shape::Plane, Geometry::Surface(s)) => {
            let pts = s.control_points().as_slice();
            let tol = TOL * bounding_box_diagonal(pts);
            match plane_normal(pts, tol)? {
                Some(_) => Ok(()),
                None => Err("the poles are collinear".into()),
            }
        }
        (Shape::Cylinder | Shape::Cone, Geometry::Surface(s)) => {
            let tol = TOL * bounding_box_diagonal(s.control_points().as_slice());
            if s.degree_v() != 1 {
                return Err("the axial direction is not straight (degree 1 in v)".into());
            }
            let ((_, _), (v0, v1)) = s.domain();
            let radii = coaxial_circles(s, &[v0, v1], tol)?;
            if shape == Shape::Cylinder && radii.windows(2).any(|w| (w[0] - w[1]).abs() > tol) {
                return Err("the two end circles of a cylinder have different radii".into());
            }
            Ok(())
        }
        (Shape::Sphere, Geometry::Surface(s)) => sphere(s),
        (Shape::Torus | Shape::Revolution, Geometry::Surface(s)) => {
            let tol = TOL * bounding_box_diagonal(s.control_points().as_slice());
            coaxial_circles(s, &v_knots(s), tol)?;
            if shape == Shape::Torus {
                let ((u0, u1), _) = s.domain();
                let mut r0: Option<f64> = None;
                for u in [u0, 0.5 * (u0 + u1), u1] {
                    let c = s.iso_u(u).map_err(|e| e.to_string())?;
                    let (_, _, r) = circle(&c)?;
                    if r0.is_some_and(|q| (q - r).abs() > tol) {
                        return Err("the tube's circles have different radii".into());
                    }
                    r0 = Some(r);
                }
            }
            Ok(())
        }
        (Shape::Extrusion, Geometry::Surface(s)) => {
            let tol = TOL * bounding_box_diagonal(s.control_points().as_slice());
            let ((u0, u1), _) = s.domain();
            let mut dir: Option<Point3> = None;
            for k in 0..=8 {
                let c = s
                    .iso_u(u0 + (u1 - u0) * k as f64 / 8.0)
                    .map_err(|e| e.to_string())?;
                let (a, b) = segment(&c, tol)?;
                let d = sub(b, a);
                if dir.is_some_and(|e| norm(sub(d, e)) > tol) {
                    return Err("the generators differ".into());
                }
                dir = Some(d);
            }
            Ok(())
        }
        (Shape::Ruled, Geometry::Surface(s)) => {
            if s.degree_v() == 1 {
                Ok(())
            } else {
                Err("a ruled surface is degree 1 in v".into())
            }
        }
        _ => Err(format!("a {shape:?} label on the wrong kind of geometry")),
    }
}

/// All grid points at one distance from one centre (least-squares sphere:
/// `|p|^2 = 2 c.p + k`, four unknowns, normal equations).
fn sphere(s: &NurbsSurface) -> Result<(), String> {
    let tol = TOL * bounding_box_diagonal(s.control_points().as_slice());
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut pts = Vec::new();
    for i in 0..=8 {
        for j in 0..=8 {
            pts.push(s.point_at_unchecked(
                u0 + (u1 - u0) * i as f64 / 8.0,
                v0 + (v1 - v0) * j as f64 / 8.0,
            ));
        }
    }
    // Centred at the mean for conditioning.
    let n = pts.len() as f64;
    let mut m = [0.0; 3];
    for p in &pts {
        for k in 0..3 {
            m[k] += p[k] / n;
        }
    }
    let q: Vec<Point3> = pts.iter().map(|p| sub(*p, m)).collect();
    let mut a = [[0.0f64; 5]; 4];
    for p in &q {
        let row = [2.0 * p[0], 2.0 * p[1], 2.0 * p[2], 1.0];
        let rhs = dot(*p, *p);
        for r in 0..4 {
            for c in 0..4 {
                a[r][c] += row[r] * row[c];
            }
            a[r][4] += row[r] * rhs;
        }
    }
    // Gaussian elimination with partial pivoting.
    for col in 0..4 {
        let piv = (col..4)
            .max_by(|x, y| a[*x][col].abs().total_cmp(&a[*y][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        if a[col][col].abs() < f64::MIN_POSITIVE {
            return Err("degenerate point set".into());
        }
        let pivot_row = a[col];
        for (r, row) in a.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / pivot_row[col];
                for (x, p) in row.iter_mut().zip(pivot_row.iter()).skip(col) {
                    *x -= f * p;
                }
            }
        }
    }
    let c = [a[0][4] / a[0][0], a[1][4] / a[1][1], a[2][4] / a[2][2]];
    let radius = q.iter().map(|p| norm(sub(*p, c))).sum::<f64>() / n;
    for p in &q {
        let off = (norm(sub(*p, c)) - radius).abs();
        if off > tol {
            return Err(format!("a point is {off:e} off the sphere"));
        }
    }
    Ok(())
}
