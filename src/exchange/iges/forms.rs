//! The IGES form numbers of 126 (IGES 5.3 section 4.23: 1 line, 2 circular arc, 3 elliptic
//! arc, 4 parabolic arc, 5 hyperbolic arc) and 128 (section 4.24: 1 plane, 2 right circular
//! cylinder, 3 cone, 4 sphere, 5 torus, 6 surface of revolution, 7 tabulated cylinder,
//! 8 ruled surface) from the source kind a document keeps ([`Shape`]), written only when a
//! check of the geometry agrees. The checks (README, "IGES form numbers"):
//!
//! - line: every pole on the line through the end points;
//! - circular arc: degree 2, rational, poles in one plane, and 17 samples at one distance
//!   from the centre of the circle through the start, middle and end points;
//! - elliptic / parabolic / hyperbolic arc: degree 2, poles in one plane, and every Bezier
//!   segment of that conic type (normalised middle weight `w1 / sqrt(w0 w2)` below, equal
//!   to or above 1; NURBS Book section 7.2);
//! - plane: every pole in one plane;
//! - surfaces of revolution (cylinder, cone, sphere, torus, revolution): the u-direction
//!   curves at 5 values of v are circles (as above) whose centres lie on one line (the
//!   axis) perpendicular to their planes; then cylinder: equal radii and straight
//!   v-direction curves; cone: straight v-direction curves with radii that differ; sphere:
//!   every sample at one distance from one point of the axis; torus: v-direction curves that
//!   are circles whose centres are at one distance from the axis;
//! - tabulated cylinder: `S(u, v) - S(u, v0)` the same for every u (5 x 5 samples);
//! - ruled surface: degree 1 in v.
//!
//! Polylines have no form (0, no warning). A kind whose check fails is written as form 0
//! with a warning naming the failed check.

use super::analysis;
use super::vector::{cross, dot, norm, sub};
use crate::exchange::{Diagnostic, Document, Location, Shape};
use crate::nurbs::{Geometry, NurbsCurve, NurbsSurface, Point3};

/// `n` samples of the curve over its domain, ends included.
fn samples(c: &NurbsCurve, n: usize) -> Vec<Point3> {
    let (a, b) = c.domain();
    (0..n)
        .map(|i| c.point_at_unchecked(a + (b - a) * (i as f64) / ((n - 1) as f64)))
        .collect()
}

/// Whether every pole lies on the line through the end points.
fn straight(c: &NurbsCurve, tol: f64) -> bool {
    let p = c.control_points();
    let (Some(&a), Some(&b)) = (p.first(), p.last()) else {
        return false;
    };
    let d = sub(b, a);
    let l = norm(d);
    l > tol && p.iter().all(|&q| norm(cross(sub(q, a), d)) / l <= tol)
}

/// The circle through the start, middle and end of a degree-2 rational planar curve, when
/// 17 samples lie on it: `(centre, unit normal, radius)`.
fn circle(c: &NurbsCurve, tol: f64) -> Option<(Point3, Point3, f64)> {
    if c.degree() != 2 || !c.is_rational() {
        return None;
    }
    let s = samples(c, 17);
    let (a, m) = (s[0], s[8]);
    // A full circle starts and ends at the same point: use a quarter-way sample.
    let b = if norm(sub(s[16], a)) <= tol {
        s[4]
    } else {
        s[16]
    };
    let (u, v) = (sub(m, a), sub(b, a));
    let n = cross(u, v);
    let nn = dot(n, n);
    if nn <= tol * tol * tol * tol {
        return None;
    }
    // Circumcentre of a, m, b.
    let w = cross(n, u);
    let centre_off = {
        let t1 = cross(v, n);
        let k1 = dot(u, u) / (2.0 * nn);
        let k2 = dot(v, v) / (2.0 * nn);
        [
            t1[0] * k1 + w[0] * k2,
            t1[1] * k1 + w[1] * k2,
            t1[2] * k1 + w[2] * k2,
        ]
    };
    let centre = [
        a[0] + centre_off[0],
        a[1] + centre_off[1],
        a[2] + centre_off[2],
    ];
    let r = norm(centre_off);
    let unit = [n[0] / nn.sqrt(), n[1] / nn.sqrt(), n[2] / nn.sqrt()];
    let ok = s.iter().all(|&p| {
        (norm(sub(p, centre)) - r).abs() <= tol && dot(sub(p, centre), unit).abs() <= tol
    }) && analysis::on_plane(c.control_points(), unit, tol);
    ok.then_some((centre, unit, r))
}

/// Whether every Bezier segment of a planar degree-2 curve has the conic type `sign`
/// (-1 ellipse, 0 parabola, +1 hyperbola) by its normalised middle weight.
fn conic_type(c: &NurbsCurve, sign: i32, tol: f64) -> bool {
    if c.degree() != 2 || analysis::plane_normal(c.control_points(), tol).is_none() {
        return false;
    }
    let Ok(segments) = c.bezier_segments() else {
        return false;
    };
    segments.iter().all(|s| {
        let w = [s.weight(0), s.weight(1), s.weight(2)];
        let k = w[1] / (w[0] * w[2]).sqrt();
        match sign {
            -1 => k < 1.0 - 1e-12,
            0 => (k - 1.0).abs() <= 1e-12,
            _ => k > 1.0 + 1e-12,
        }
    })
}

/// Runs a kind's `check` on a net of `points` and `weights` at the net-relative tolerance,
/// at least `at_least` (the precision a label was checked to when read,
/// [`crate::exchange::Meta::shape_tolerance`]); when it fails, again at four times what the
/// digits of the poles and weights allow ([`analysis::written_point_rounding`]: a check
/// compares the distances of two samples from a centre estimated from three more), if that
/// is more. So a circle written with 8 digits is a circle to 8 digits, and exact numbers
/// (the usual case) pay for one check only.
fn within_written(
    points: &[Point3],
    weights: Option<&[f64]>,
    at_least: f64,
    check: impl Fn(f64) -> Result<i64, String>,
) -> Result<i64, String> {
    let tol = analysis::tolerance(points.iter()).max(at_least);
    check(tol).or_else(|why| {
        let written = 4.0 * analysis::written_point_rounding(points, weights.unwrap_or_default());
        if written > tol {
            check(written)
        } else {
            Err(why)
        }
    })
}

/// The 126 form of a curve of kind `shape`: `Ok(form)`, or `Err(why)` when the geometry does
/// not pass the kind's check ([`within_written`]).
pub fn curve_form(c: &NurbsCurve, shape: Option<Shape>, at_least: f64) -> Result<i64, String> {
    if shape.is_none() {
        return Ok(0);
    }
    within_written(c.control_points(), c.weights(), at_least, |tol| {
        curve_form_within(c, shape, tol)
    })
}

/// [`curve_form`] at the tolerance `tol`.
fn curve_form_within(c: &NurbsCurve, shape: Option<Shape>, tol: f64) -> Result<i64, String> {
    match shape {
        None | Some(Shape::Polyline) => Ok(0),
        Some(Shape::Line) => straight(c, tol)
            .then_some(1)
            .ok_or_else(|| "not every pole lies on the line through its ends".to_owned()),
        Some(Shape::CircularArc) => circle(c, tol).map(|_| 2).ok_or_else(|| {
            "not a planar rational quadratic at one radius from one centre".to_owned()
        }),
        Some(Shape::EllipticArc) => conic_type(c, -1, tol)
            .then_some(3)
            .ok_or_else(|| "not a planar quadratic of elliptic segments".to_owned()),
        Some(Shape::ParabolicArc) => conic_type(c, 0, tol)
            .then_some(4)
            .ok_or_else(|| "not a planar quadratic of parabolic segments".to_owned()),
        Some(Shape::HyperbolicArc) => conic_type(c, 1, tol)
            .then_some(5)
            .ok_or_else(|| "not a planar quadratic of hyperbolic segments".to_owned()),
        Some(s) => Err(format!("{s:?} is a surface kind")),
    }
}

/// A point of an axis, its unit direction, and `(axial position, radius)` of sampled circles.
type Axis = (Point3, Point3, Vec<(f64, f64)>);

/// The axis of a surface whose u-direction curves are circles about one line:
/// `(point, unit direction, [(axial position, radius)] at the sampled v)`.
fn rotation_axis(s: &NurbsSurface, tol: f64) -> Option<Axis> {
    let (_, (v0, v1)) = s.domain();
    let mut circles = Vec::new();
    for j in 0..5 {
        let v = v0 + (v1 - v0) * f64::from(j) / 4.0;
        let c = s.iso_v(v).ok()?;
        // A row on the axis (sphere, cone apex) is a point: no circle, no constraint.
        let pts = samples(&c, 3);
        if norm(sub(pts[0], pts[1])) <= tol && norm(sub(pts[1], pts[2])) <= tol {
            continue;
        }
        circles.push(circle(&c, tol)?);
    }
    let (c0, n0, _) = *circles.first()?;
    // A circle's normal, from chords of about its radius, turns by about tol / radius.
    let ok = circles.iter().all(|&(c, n, r)| {
        norm(cross(n, n0)) <= 1e-9f64.max(tol / r) && norm(cross(sub(c, c0), n0)) <= tol
    });
    if !ok {
        return None;
    }
    let rows = circles
        .iter()
        .map(|&(c, _, r)| (dot(sub(c, c0), n0), r))
        .collect();
    Some((c0, n0, rows))
}

/// The 128 form of a surface of kind `shape`, or why not. IGES 5.3 section 4.24 does not
/// say which parameter runs around a cylinder or along a ruling, so the check passes when
/// the surface passes it with u and v as written or exchanged.
pub fn surface_form(s: &NurbsSurface, shape: Option<Shape>, at_least: f64) -> Result<i64, String> {
    if shape.is_none() {
        return Ok(0);
    }
    within_written(
        s.control_points().as_slice(),
        s.weights().map(|w| w.as_slice()),
        at_least,
        |tol| {
            surface_form_as_written(s, shape, tol).or_else(|why| {
                s.swap_uv()
                    .ok()
                    .and_then(|t| surface_form_as_written(&t, shape, tol).ok())
                    .ok_or(why)
            })
        },
    )
}

/// [`surface_form`] with u and v as written: the surfaces of revolution turn about the axis
/// in u; a ruled surface is straight in v.
fn surface_form_as_written(
    s: &NurbsSurface,
    shape: Option<Shape>,
    tol: f64,
) -> Result<i64, String> {
    let ((u0, u1), (v0, v1)) = s.domain();
    let v_curves_straight = || {
        (0..5).all(|i| {
            s.iso_u(u0 + (u1 - u0) * f64::from(i) / 4.0)
                .is_ok_and(|c| straight(&c, tol))
        })
    };
    let revolution = || {
        rotation_axis(s, tol)
            .ok_or_else(|| "the u-direction curves are not circles about one axis".to_owned())
    };
    match shape {
        None => Ok(0),
        Some(Shape::Plane) => analysis::plane_normal(s.control_points().as_slice(), tol)
            .map(|_| 1)
            .ok_or_else(|| "the poles do not lie in one plane".to_owned()),
        Some(Shape::Cylinder) => {
            let (_, _, rows) = revolution()?;
            let r0 = rows.first().map_or(0.0, |r| r.1);
            (rows.iter().all(|r| (r.1 - r0).abs() <= tol) && v_curves_straight())
                .then_some(2)
                .ok_or_else(|| "radii differ or the generators are not straight".to_owned())
        }
        Some(Shape::Cone) => {
            let (_, _, rows) = revolution()?;
            let r0 = rows.first().map_or(0.0, |r| r.1);
            (rows.iter().any(|r| (r.1 - r0).abs() > tol) && v_curves_straight())
                .then_some(3)
                .ok_or_else(|| "equal radii or generators that are not straight".to_owned())
        }
        Some(Shape::Sphere) => {
            let (p, n, _) = revolution()?;
            // The centre is the axis point equidistant from the poles of the domain's
            // corners: all samples must be at one distance from one axis point. With
            // samples a, b: |a - (p + h n)| = |b - (p + h n)| fixes h.
            let a = s.point_at_unchecked(u0, 0.5 * (v0 + v1));
            let b = s.point_at_unchecked(u0, v0 + 0.2 * (v1 - v0));
            let (da, db) = (sub(a, p), sub(b, p));
            let denom = 2.0 * dot(sub(da, db), n);
            if denom.abs() <= tol {
                return Err("no centre on the axis".to_owned());
            }
            let h = (dot(da, da) - dot(db, db)) / denom;
            let centre = [p[0] + h * n[0], p[1] + h * n[1], p[2] + h * n[2]];
            let r = norm(sub(a, centre));
            let ok = (0..5).all(|i| {
                (0..5).all(|j| {
                    let q = s.point_at_unchecked(
                        u0 + (u1 - u0) * f64::from(i) / 4.0,
                        v0 + (v1 - v0) * f64::from(j) / 4.0,
                    );
                    (norm(sub(q, centre)) - r).abs() <= tol
                })
            });
            ok.then_some(4)
                .ok_or_else(|| "the samples are not at one distance from a centre".to_owned())
        }
        Some(Shape::Torus) => {
            let (p, n, _) = revolution()?;
            let mut dist = None;
            for i in 0..5 {
                let c = s
                    .iso_u(u0 + (u1 - u0) * f64::from(i) / 4.0)
                    .map_err(|e| e.to_string())?;
                let (centre, _, _) =
                    circle(&c, tol).ok_or("a v-direction curve is not a circle")?;
                let d = norm(cross(sub(centre, p), n));
                if dist.is_some_and(|d0: f64| (d - d0).abs() > tol) {
                    return Err("the minor circles' centres are not on one circle".to_owned());
                }
                dist = Some(d);
            }
            Ok(5)
        }
        Some(Shape::Revolution) => revolution().map(|_| 6),
        Some(Shape::Extrusion) => {
            let base = |u: f64| s.point_at_unchecked(u, v0);
            let ok = (0..5).all(|j| {
                let v = v0 + (v1 - v0) * f64::from(j) / 4.0;
                let d0 = sub(s.point_at_unchecked(u0, v), base(u0));
                (0..5).all(|i| {
                    let u = u0 + (u1 - u0) * f64::from(i) / 4.0;
                    norm(sub(sub(s.point_at_unchecked(u, v), base(u)), d0)) <= tol
                })
            });
            ok.then_some(7)
                .ok_or_else(|| "the v-direction offsets differ along u".to_owned())
        }
        Some(Shape::Ruled) => (s.degree_v() == 1)
            .then_some(8)
            .ok_or_else(|| "not of degree 1 in v".to_owned()),
        Some(s) => Err(format!("{s:?} is a curve kind")),
    }
}

/// The form of an entity's geometry, or why its kind's check failed. The check passes within
/// the net-relative tolerance, at least `at_least` (the precision a label was checked to
/// when read, [`crate::exchange::Meta::shape_tolerance`]; 0 when none), or else within four
/// times what the digits of the poles and weights allow.
pub fn form(geometry: &Geometry, shape: Option<Shape>, at_least: f64) -> Result<i64, String> {
    match geometry {
        Geometry::Curve(c) => curve_form(c, shape, at_least),
        Geometry::Surface(s) => surface_form(s, shape, at_least),
    }
}

/// The kind IGES 5.3 gives a form number of a 126 (section 4.23: 1-5) or a 128 (section
/// 4.24: 1-8); `None` for form 0 (the data decides), 128 form 9 (general quadric, no kind
/// in nurbsx) and undefined forms.
fn shape_of_form(entity_type: i64, form: i64) -> Option<Shape> {
    let kinds: &[Shape] = match entity_type {
        126 => &[
            Shape::Line,
            Shape::CircularArc,
            Shape::EllipticArc,
            Shape::ParabolicArc,
            Shape::HyperbolicArc,
        ],
        128 => &[
            Shape::Plane,
            Shape::Cylinder,
            Shape::Cone,
            Shape::Sphere,
            Shape::Torus,
            Shape::Revolution,
            Shape::Extrusion,
            Shape::Ruled,
        ],
        _ => &[],
    };
    let index = usize::try_from(form.checked_sub(1)?).ok()?;
    kinds.get(index).copied()
}

/// The kind a 126 or 128 of form `form` is labelled with, when its geometry passes that
/// kind's check ([`checked_label`]); 128 form 9 gives a `form_unchecked` warning (nurbsx
/// does not keep that label).
pub(super) fn labelled_shape(
    entity_type: i64,
    form_number: i64,
    geometry: &Geometry,
    location: &Location,
    diags: &mut Vec<Diagnostic>,
    written: impl FnOnce() -> f64,
) -> (Option<Shape>, Option<f64>) {
    if entity_type == 128 && form_number == 9 {
        diags.push(Diagnostic::warning(
            "form_unchecked",
            "form 9 (general quadric surface) has no check in nurbsx: the label is not kept (written as IGES form 0, STEP .UNSPECIFIED.)".to_owned(),
            location.clone(),
        ));
        return (None, None);
    }
    match shape_of_form(entity_type, form_number) {
        Some(shape) => checked_label(
            shape,
            || format!("form {form_number} ({shape:?})"),
            geometry,
            location,
            diags,
            written,
        ),
        None => (None, None),
    }
}

/// The kind `shape` a file labels its geometry with (`label()` names it: an IGES form
/// number, a STEP `curve_form`; built only for a warning), kept when the geometry passes the kind's check ([`form`]) to the precision
/// of the digits the file wrote (`written()`: four times
/// [`analysis::written_point_rounding`] of the entity's own numbers, stretched as its 124
/// chain and unit factor stretch them), with that precision when the check needs it
/// ([`crate::exchange::Meta::shape_tolerance`]: the geometry's own digits do not show it once
/// a 124, the unit factor or a trim has recomputed the poles). A label that fails gives a
/// `form_mismatch` warning: the data is read as written, and written as IGES form 0 / STEP
/// `.UNSPECIFIED.`.
pub(crate) fn checked_label(
    shape: Shape,
    label: impl FnOnce() -> String,
    geometry: &Geometry,
    location: &Location,
    diags: &mut Vec<Diagnostic>,
    written: impl FnOnce() -> f64,
) -> (Option<Shape>, Option<f64>) {
    // The geometry's own digits first (all it needs unless a 124, the unit factor or a trim
    // recomputed the poles), then the file's.
    let checked = form(geometry, Some(shape), 0.0)
        .map(|_| None)
        .or_else(|why| {
            let written = written();
            match form(geometry, Some(shape), written) {
                Ok(_) => Ok(Some(written)),
                Err(_) => Err(why),
            }
        });
    match checked {
        Ok(at) => (Some(shape), at),
        Err(why) => {
            diags.push(Diagnostic::warning(
                "form_mismatch",
                format!(
                    "{} but {why}; the data is read as written (and written as IGES form 0, STEP .UNSPECIFIED.)",
                    label()
                ),
                location.clone(),
            ));
            (None, None)
        }
    }
}

/// One warning per entity whose kind ([`crate::exchange::Meta::shape`]) does not pass its
/// check: the IGES writer gives it form 0.
pub fn form_warnings(document: &Document) -> Vec<Diagnostic> {
    document
        .entities
        .iter()
        .filter_map(|e| {
            let why = form(
                &e.geometry,
                e.meta.shape,
                e.meta.shape_tolerance.unwrap_or(0.0),
            )
            .err()?;
            Some(Diagnostic::warning(
                "form_unchecked",
                format!(
                    "labelled {:?} but {why}; written as IGES form 0 (shape given by the data)",
                    e.meta.shape?
                ),
                Location::at_entity(e.id.clone()),
            ))
        })
        .collect()
}
