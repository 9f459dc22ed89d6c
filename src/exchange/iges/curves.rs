//! The IGES 5.3 curve entities other than 126 as exact NURBS: 100 circular arc, 104 conic
//! arc, 106 copious data, 110 line, 112 parametric spline curve, and the 102 composite curve
//! of any of them. Each curve is built in its definition space, then its own 124 chain is
//! applied (affine maps move the Euclidean poles exactly, weights unchanged).
//!
//! The parameter maps (README, "Parameterisation"): lines, polylines, parabolas and
//! parametric splines keep the IGES parameter (identity); circular, elliptic and hyperbolic
//! arcs are rational quadratics whose NURBS parameter equals the conic's angle (or
//! hyperbolic parameter) at every knot and follows the exact [`ArcMap`] in between.

use nurbsx_parsers::iges::DirectoryEntry;
use nurbsx_parsers::iges::records::{
    CircularArc100, CompositeCurve102, ConicArc104, CopiousData106, Line110, SplineCurve112,
};

use super::read::{Context, decoded, entity_location};
use super::vector::{add, norm, scale, sub};
use crate::exchange::{Diagnostic, Meta, Shape};
use crate::nurbs::bernstein::binomial;
use crate::nurbs::conic::{ArcMap, ConicKind, conic_arc, line_segment, parabola_arc, polyline};
use crate::nurbs::{Geometry, NurbsCurve, Point3};

/// How the NURBS parameter relates to the parameter IGES 5.3 defines for the entity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum ParamMap {
    /// The same parameter (possibly shifted, for the later pieces of a composite).
    Identity,
    /// The conic parameter `t` <-> `u` through the exact map of the rational arc.
    Arc(ArcMap),
}

/// A curve entity converted: the NURBS (own 124 chain applied, file units), its kind and
/// parameter map, and its metadata.
#[derive(Debug, Clone)]
pub(super) struct CurveOut {
    pub curve: NurbsCurve,
    pub shape: Option<Shape>,
    pub map: ParamMap,
    pub meta: Meta,
}

/// A simple (non-composite) curve entity: 100, 104, 106, 110, 112 or 126. `None` with an
/// error diagnostic when it cannot be converted, or a warning when the entity has no
/// bounded curve to convert (points, an unbounded line).
pub(super) fn simple_curve(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<CurveOut> {
    let mut meta = Meta {
        name: super::read::name_of(entry),
        form: Some(super::form_text(entry.form)),
        ..Meta::default()
    };
    let built = match entry.entity_type {
        100 => circular_arc(cx, entry, diags),
        104 => conic(cx, entry, diags),
        106 => copious(cx, entry, diags),
        110 => line(cx, entry, diags),
        112 => spline(cx, entry, diags),
        126 => {
            let (g, m) = super::read::read_curve(cx, entry, None, diags)?;
            let Geometry::Curve(curve) = g else {
                return None;
            };
            return Some(CurveOut {
                curve,
                shape: None,
                map: ParamMap::Identity,
                meta: m,
            });
        }
        t => {
            diags.push(Diagnostic::error(
                "entity.unsupported",
                format!("a type {t} entity is not a curve nurbsx converts here"),
                entity_location(entry),
            ));
            return None;
        }
    }?;
    let (curve, shape, map) = built;
    let chain = cx.transforms(entry, &mut meta, diags)?;
    let curve = match chain.map_or(Ok(curve.clone()), |m| curve.transform(&m)) {
        Ok(c) => c,
        Err(e) => {
            diags.push(invalid(entry, &e.to_string()));
            return None;
        }
    };
    meta.shape = shape;
    Some(CurveOut {
        curve,
        shape,
        map,
        meta,
    })
}

fn invalid(entry: &DirectoryEntry, why: &str) -> Diagnostic {
    Diagnostic::error(
        "geometry.invalid",
        format!(
            "{} entity has no valid exact NURBS form: {why}; entity not loaded",
            entry.entity_type
        ),
        entity_location(entry),
    )
}

type Built = (NurbsCurve, Option<Shape>, ParamMap);

fn built(
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
    r: Result<NurbsCurve, crate::nurbs::GeometryError>,
    shape: Shape,
    map: ParamMap,
) -> Option<Built> {
    match r {
        Ok(c) => Some((c, Some(shape), map)),
        Err(e) => {
            diags.push(invalid(entry, &e.to_string()));
            None
        }
    }
}

/// The angle of `v` in `[0, 2 pi)` (the range Open CASCADE reports for circle parameters).
fn angle_of(v: [f64; 2]) -> f64 {
    let a = v[1].atan2(v[0]);
    if a < 0.0 {
        a + std::f64::consts::TAU
    } else {
        a
    }
}

/// 100 (IGES 5.3 section 4.3): `x = X1 + r cos t`, `y = Y1 + r sin t`, `z = ZT`,
/// counterclockwise from the start to the terminate point; equal points make a full circle.
/// The start angle is taken in `[0, 2 pi)`.
fn circular_arc(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let a = decoded(cx.file.decode::<CircularArc100>(entry), diags)?;
    let s = [a.start[0] - a.centre[0], a.start[1] - a.centre[1]];
    let e = [a.end[0] - a.centre[0], a.end[1] - a.centre[1]];
    let r = s[0].hypot(s[1]);
    let r_end = e[0].hypot(e[1]);
    let written = [
        a.centre[0],
        a.centre[1],
        a.start[0],
        a.start[1],
        a.end[0],
        a.end[1],
    ];
    let tol = cx.tolerance(&[a.centre[0], a.centre[1], a.start[0], a.start[1], a.zt]);
    if (r - r_end).abs() > cx.written_tolerance(&written) {
        diags.push(Diagnostic::warning(
            "arc_radius_mismatch",
            format!(
                "the start point is at radius {r} and the terminate point at {r_end}; the arc keeps the start radius and ends at the terminate point's angle (as Open CASCADE does)"
            ),
            entity_location(entry),
        ));
    }
    let t0 = angle_of(s);
    let mut t1 = angle_of(e);
    if (s[0] - e[0]).hypot(s[1] - e[1]) <= tol {
        t1 = t0 + std::f64::consts::TAU;
    } else if t1 <= t0 {
        t1 += std::f64::consts::TAU;
    }
    let c = [a.centre[0], a.centre[1], a.zt];
    let r3 = conic_arc(ConicKind::Elliptic, c, [r, 0.0, 0.0], [0.0, r, 0.0], t0, t1);
    match r3 {
        Ok((curve, map)) => Some((curve, Some(Shape::CircularArc), ParamMap::Arc(map))),
        Err(e) => {
            diags.push(invalid(entry, &e.to_string()));
            None
        }
    }
}

/// The type of a conic by IGES 5.3 section 4.5: with
/// `Q1 = det [[A, B/2, D/2], [B/2, C, E/2], [D/2, E/2, F]]`, `Q2 = A C - B^2/4`,
/// `Q3 = A + C`: ellipse when `Q2 > 0` and `Q1 Q3 < 0`, hyperbola when `Q2 < 0` and
/// `Q1 != 0`, parabola when `Q2 = 0` and `Q1 != 0`. `Q2` is taken as 0 within a relative
/// rounding of `1e-12` of the quadratic coefficients (a parabola written as `A = 1, C = 0`
/// has `Q2 = 0` exactly; one written from rotated axes rounds).
pub(super) fn conic_form(k: [f64; 6]) -> Option<i64> {
    let [a, b, c, d, e, f] = k;
    let q1 = a * (c * f - e * e / 4.0) - b / 2.0 * (b / 2.0 * f - e * d / 4.0)
        + d / 2.0 * (b * e / 4.0 - c * d / 2.0);
    let q2 = a * c - b * b / 4.0;
    let q3 = a + c;
    let scale2 = (a * a).max(b * b).max(c * c);
    let q2 = if q2.abs() <= 1e-12 * scale2 { 0.0 } else { q2 };
    if q2 > 0.0 && q1 * q3 < 0.0 {
        Some(1)
    } else if q2 < 0.0 && q1 != 0.0 {
        Some(2)
    } else if q2 == 0.0 && q1 != 0.0 {
        Some(3)
    } else {
        None
    }
}

/// 104 (IGES 5.3 section 4.5): the conic `A x^2 + B x y + C y^2 + D x + E y + F = 0` in the
/// plane `z = ZT`, classified by its coefficients (the form number is checked against
/// them). The centre and principal axes come from the coefficients (rotation by
/// `phi = atan2(B, A - C) / 2`), so conics outside the standard position are read too.
///
/// - Ellipse `C + cos t X + sin t Y` (X the major semi-axis, `X x Y` along +z):
///   counterclockwise from the start to the terminate point, equal points a full ellipse.
/// - Hyperbola `C + cosh t X + sinh t Y` (X to the branch's vertex) and parabola
///   `V + t^2 X + 2 t Y` (X along the axis, `Y` half a unit across it): from the start to
///   the terminate point, `Y` oriented so that `t` increases along the arc.
///
/// The start and terminate parameters are the exact inverses of these maps at the points
/// (`atan2` of the point in the conjugate frame, `asinh`, the coordinate across the axis).
fn conic(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<ConicArc104>(entry), diags)?;
    let loc = entity_location(entry);
    let Some(form) = conic_form(rec.coefficients) else {
        diags.push(Diagnostic::error(
            "conic.degenerate",
            format!(
                "coefficients A..F = {:?} define no ellipse, hyperbola or parabola (IGES 5.3 section 4.5); entity not loaded",
                rec.coefficients
            ),
            loc,
        ));
        return None;
    };
    // Form 0 names no conic: the type is the coefficients' (IGES 5.3 section 4.5).
    if rec.form != 0 && form != rec.form {
        diags.push(Diagnostic::warning(
            "form_mismatch",
            format!(
                "form {} but the coefficients define a{} (form {form}); read as the coefficients say",
                rec.form,
                ["n ellipse", " hyperbola", " parabola"][usize::try_from(form - 1).unwrap_or(0)]
            ),
            loc.clone(),
        ));
    }
    let [a, b, c, d, e, f] = rec.coefficients;
    let z = rec.zt;
    let tol = cx.tolerance(&[rec.start[0], rec.start[1], rec.end[0], rec.end[1], z]);
    // An end point is off its conic only beyond what the digits written allow.
    let off = cx.written_tolerance(&[rec.start[0], rec.start[1], rec.end[0], rec.end[1]]);
    let phi = 0.5 * b.atan2(a - c);
    let (cp, sp) = (phi.cos(), phi.sin());
    let e1 = [cp, sp];
    let e2 = [-sp, cp];
    // Eigenvalues of [[A, B/2], [B/2, C]] along e1 and e2.
    let l1 = a * cp * cp + b * cp * sp + c * sp * sp;
    let l2 = a * sp * sp - b * sp * cp + c * cp * cp;
    let on = |p: [f64; 2], o: [f64; 2], u: [f64; 2]| (p[0] - o[0]) * u[0] + (p[1] - o[1]) * u[1];
    let p3 = |o: [f64; 2], x: f64, u: [f64; 2], y: f64, v: [f64; 2]| -> Point3 {
        [o[0] + x * u[0] + y * v[0], o[1] + x * u[1] + y * v[1], z]
    };
    if form == 3 {
        // Parabola: one eigenvalue is zero; make l1 the non-zero one (along e1).
        let (l1, e1, e2) = if l1.abs() >= l2.abs() {
            (l1, e1, e2)
        } else {
            (l2, e2, [-e1[0], -e1[1]])
        };
        let dd = d * e1[0] + e * e1[1];
        let ee = d * e2[0] + e * e2[1];
        if ee == 0.0 || l1 == 0.0 {
            diags.push(invalid(entry, "the parabola's axis coefficient is zero"));
            return None;
        }
        // l1 x'^2 + dd x' + ee y' + F = 0, so y' - yv = -(l1 / ee) (x' - xv)^2.
        let xv = -dd / (2.0 * l1);
        let yv = -(l1 * xv * xv + dd * xv + f) / ee;
        let vertex = p3([0.0, 0.0], xv, e1, yv, e2);
        let v2 = [vertex[0], vertex[1]];
        let k = -l1 / ee;
        let mut t0 = on(rec.start, v2, e1);
        let mut t1 = on(rec.end, v2, e1);
        // x' - xv = 2 t |Y| with |Y| = 1/2; X = k e2 (y' - yv = k (x' - xv)^2 = t^2 k).
        let mut y = [0.5 * e1[0], 0.5 * e1[1], 0.0];
        if t1 < t0 {
            y = scale(y, -1.0);
            (t0, t1) = (-t0, -t1);
        }
        for (p, t) in [(rec.start, t0), (rec.end, t1)] {
            let q = add(
                vertex,
                add(scale([k * e2[0], k * e2[1], 0.0], t * t), scale(y, 2.0 * t)),
            );
            if (q[0] - p[0]).hypot(q[1] - p[1]) > off.max(1e-9 * (1.0 + t * t * k.abs())) {
                diags.push(off_conic(entry, p, q));
            }
        }
        let r = parabola_arc(vertex, [k * e2[0], k * e2[1], 0.0], y, t0, t1);
        return built(entry, diags, r, Shape::ParabolicArc, ParamMap::Identity);
    }
    // Ellipse or hyperbola: centre from the gradient's zero.
    let det = a * c - b * b / 4.0;
    let cx0 = (b * e / 4.0 - c * d / 2.0) / det;
    let cy0 = (b * d / 4.0 - a * e / 2.0) / det;
    let centre = [cx0, cy0];
    let f0 = f + (d * cx0 + e * cy0) / 2.0;
    let (r1, r2) = (-f0 / l1, -f0 / l2);
    if form == 1 {
        if !(r1 > 0.0 && r2 > 0.0) {
            diags.push(invalid(entry, "the ellipse has no real points"));
            return None;
        }
        let (a1, a2) = (r1.sqrt(), r2.sqrt());
        // X along the major axis, Y = z x X.
        let (ax, ay, ux, uy) = if a1 >= a2 {
            (a1, a2, e1, e2)
        } else {
            (a2, a1, e2, [-e1[0], -e1[1]])
        };
        let param = |p: [f64; 2]| angle_of([on(p, centre, ux) / ax, on(p, centre, uy) / ay]);
        let t0 = param(rec.start);
        let mut t1 = param(rec.end);
        if (rec.start[0] - rec.end[0]).hypot(rec.start[1] - rec.end[1]) <= tol {
            t1 = t0 + std::f64::consts::TAU;
        } else if t1 <= t0 {
            t1 += std::f64::consts::TAU;
        }
        let c3 = [cx0, cy0, z];
        for (p, t) in [(rec.start, t0), (rec.end, t1)] {
            let q = p3(centre, ax * t.cos(), ux, ay * t.sin(), uy);
            if (q[0] - p[0]).hypot(q[1] - p[1]) > off.max(1e-9 * ax) {
                diags.push(off_conic(entry, p, q));
            }
        }
        let x = [ax * ux[0], ax * ux[1], 0.0];
        let y = [ay * uy[0], ay * uy[1], 0.0];
        let shape = if (ax - ay).abs() <= 1e-12 * ax {
            Shape::CircularArc
        } else {
            Shape::EllipticArc
        };
        return match conic_arc(ConicKind::Elliptic, c3, x, y, t0, t1) {
            Ok((curve, map)) => Some((curve, Some(shape), ParamMap::Arc(map))),
            Err(e) => {
                diags.push(invalid(entry, &e.to_string()));
                None
            }
        };
    }
    // Hyperbola: the transverse axis is the one with a positive -F'/l.
    let (at, bt, ut, uc) = if r1 > 0.0 && r2 < 0.0 {
        (r1.sqrt(), (-r2).sqrt(), e1, e2)
    } else if r2 > 0.0 && r1 < 0.0 {
        (r2.sqrt(), (-r1).sqrt(), e2, [-e1[0], -e1[1]])
    } else {
        diags.push(invalid(entry, "the hyperbola is degenerate (F' = 0)"));
        return None;
    };
    // The branch of the start point.
    let sign = if on(rec.start, centre, ut) >= 0.0 {
        1.0
    } else {
        -1.0
    };
    if on(rec.end, centre, ut) * sign < 0.0 {
        diags.push(invalid(
            entry,
            "the start and terminate points lie on different branches of the hyperbola",
        ));
        return None;
    }
    let x = [sign * at * ut[0], sign * at * ut[1], 0.0];
    let mut y = [bt * uc[0], bt * uc[1], 0.0];
    let mut t0 = (on(rec.start, centre, uc) / bt).asinh();
    let mut t1 = (on(rec.end, centre, uc) / bt).asinh();
    if t1 < t0 {
        y = scale(y, -1.0);
        (t0, t1) = (-t0, -t1);
    }
    let c3 = [cx0, cy0, z];
    for (p, t) in [(rec.start, t0), (rec.end, t1)] {
        let q = add(c3, add(scale(x, t.cosh()), scale(y, t.sinh())));
        if (q[0] - p[0]).hypot(q[1] - p[1]) > off.max(1e-9 * at * t.cosh()) {
            diags.push(off_conic(entry, p, q));
        }
    }
    match conic_arc(ConicKind::Hyperbolic, c3, x, y, t0, t1) {
        Ok((curve, map)) => Some((curve, Some(Shape::HyperbolicArc), ParamMap::Arc(map))),
        Err(e) => {
            diags.push(invalid(entry, &e.to_string()));
            None
        }
    }
}

fn off_conic(entry: &DirectoryEntry, p: [f64; 2], q: Point3) -> Diagnostic {
    Diagnostic::warning(
        "conic_point_off",
        format!(
            "the end point ({}, {}) is not on the conic; the arc ends at ({}, {}), the conic's point of the same parameter",
            p[0], p[1], q[0], q[1]
        ),
        entity_location(entry),
    )
}

/// 110 (IGES 5.3 section 4.13): form 0, `P1 + t (P2 - P1)` for `t` in `[0, 1]`, is a
/// degree-1 segment on `[0, 1]` (identity map). Forms 1 (ray) and 2 (line) are unbounded:
/// used as a 120's axis they give a direction; alone they are not represented.
fn line(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let l = decoded(cx.file.decode::<Line110>(entry), diags)?;
    if l.form != 0 {
        diags.push(Diagnostic::warning(
            "unbounded.not_represented",
            format!(
                "110 form {} is an unbounded {}; a NURBS is bounded, so it is not represented (a bounded use, such as a 120's axis, still reads it)",
                l.form,
                if l.form == 1 { "ray" } else { "line" }
            ),
            entity_location(entry),
        )
        .not_carried());
        return None;
    }
    let r = line_segment(l.start, l.end, 0.0, 1.0);
    built(entry, diags, r, Shape::Line, ParamMap::Identity)
}

/// A 110 of any form as the axis of a 120: its start point and unit direction (after its
/// own 124 chain).
pub(super) fn axis_line(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<(Point3, Point3)> {
    let l = decoded(cx.file.decode::<Line110>(entry), diags)?;
    let mut meta = Meta::default();
    let chain = cx.transforms(entry, &mut meta, diags)?;
    let (p, q) = match chain {
        Some(m) => (
            crate::nurbs::transform::apply(&m, l.start),
            crate::nurbs::transform::apply(&m, l.end),
        ),
        None => (l.start, l.end),
    };
    let d = sub(q, p);
    let n = norm(d);
    if !(n > 0.0 && n.is_finite()) {
        diags.push(invalid(entry, "the axis line has coincident end points"));
        return None;
    }
    Some((p, scale(d, 1.0 / n)))
}

/// 106 (IGES 5.3 sections 4.7, 4.11): forms 11, 12 and 13 (linear paths) and 63 (closed planar
/// curve) are polylines through the points, the parameter being the point index
/// `0, 1, ..` (IGES 5.3 defines no parameter for it); form 63
/// is closed by repeating the first point when the last differs. Forms 1-3 are point
/// sets, not curves: not represented (a warning). Form 13's vectors are not carried (an
/// info). Other forms are annotation: not represented.
fn copious(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<CopiousData106>(entry), diags)?;
    let loc = entity_location(entry);
    match rec.form {
        11 | 12 | 13 | 63 => {}
        1..=3 => {
            diags.push(
                Diagnostic::warning(
                    "points.not_represented",
                    format!(
                        "106 form {} holds {} points, not a curve; points are not represented",
                        rec.form,
                        rec.points.len()
                    ),
                    loc,
                )
                .not_carried(),
            );
            return None;
        }
        f => {
            diags.push(
                Diagnostic::warning(
                    "annotation.not_represented",
                    format!(
                        "106 form {f} is annotation (IGES 5.3 sections 4.8-4.10); not represented"
                    ),
                    loc,
                )
                .not_carried(),
            );
            return None;
        }
    }
    let expected_ip = match rec.form {
        11 | 63 => 1,
        12 => 2,
        _ => 3,
    };
    if rec.ip != expected_ip {
        diags.push(Diagnostic::warning(
            "form_mismatch",
            format!(
                "106 form {} goes with IP = {expected_ip}, the entity has IP = {}; read as IP says",
                rec.form, rec.ip
            ),
            loc.clone(),
        ));
    }
    if !rec.vectors.is_empty() {
        diags.push(Diagnostic::info(
            "vectors_dropped",
            format!(
                "the {} vectors of the IP = 3 data are not carried (a NURBS has no place for them)",
                rec.vectors.len()
            ),
            loc.clone(),
        )
        .not_carried());
    }
    let mut points = rec.points;
    if rec.form == 63 && points.first() != points.last() {
        if let Some(&p) = points.first() {
            points.push(p);
        }
    }
    let params: Vec<f64> = (0..points.len()).map(|i| i as f64).collect();
    let r = polyline(&points, &params);
    built(entry, diags, r, Shape::Polyline, ParamMap::Identity)
}

/// Bernstein coefficients of the polynomial `sum a_k s^k` on `s` in `[0, h]`, of degree
/// `n`: with `s = h r`, `b_j = sum_{k <= j} C(j, k) / C(n, k) a_k h^k` (the power-to-
/// Bernstein change of basis, seed 000 "matrix form" of the Bezier curve).
pub(super) fn power_to_bernstein(a: &[f64], h: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|j| {
            (0..=j)
                .map(|k| {
                    let ak = a.get(k).copied().unwrap_or(0.0);
                    binomial(j, k) / binomial(n, k) * ak * h.powi(i32::try_from(k).unwrap_or(0))
                })
                .sum()
        })
        .collect()
}

/// 112 (IGES 5.3 section 4.14): on segment `i`, `X(u) = AX + BX s + CX s^2 + DX s^3` with
/// `s = u - T(i)`. Each segment becomes a Bezier segment by the exact power-to-Bernstein
/// change of basis; the knots are the break points with multiplicity equal to the degree
/// (full multiplicity: the pieces join with whatever continuity they have, nothing is
/// smoothed or removed), so the NURBS parameter is the IGES parameter `u`. The degree is the
/// highest with a non-zero coefficient (at most 3, at least 1). The terminate-point values
/// are checked against the last segment (a warning when they differ).
fn spline(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<SplineCurve112>(entry), diags)?;
    let loc = entity_location(entry);
    let t = &rec.breakpoints;
    if !t.windows(2).all(|w| w[1] > w[0]) || t.iter().any(|x| !x.is_finite()) {
        diags.push(invalid(
            entry,
            "the break points T(1)..T(N+1) do not increase",
        ));
        return None;
    }
    if !(rec.ndim == 2 || rec.ndim == 3) {
        diags.push(Diagnostic::warning(
            "flag_invalid",
            format!(
                "NDIM = {}; IGES 5.3 allows 2 or 3 (the Z polynomials are used as written)",
                rec.ndim
            ),
            loc.clone(),
        ));
    }
    let degree = rec
        .segments
        .iter()
        .flat_map(|s| s.iter())
        .map(|c| (1..4).rev().find(|&k| c[k] != 0.0).unwrap_or(1))
        .max()
        .unwrap_or(1);
    let n = rec.segments.len();
    let mut points: Vec<Point3> = Vec::with_capacity(degree * n + 1);
    let mut knots = vec![t[0]; degree + 1];
    let tol = cx.tolerance(
        &rec.segments
            .iter()
            .flat_map(|s| s.iter().map(|c| c[0]))
            .collect::<Vec<_>>(),
    );
    let mut worst_gap = 0.0f64;
    for (i, seg) in rec.segments.iter().enumerate() {
        let h = t[i + 1] - t[i];
        let coords: Vec<Vec<f64>> = seg
            .iter()
            .map(|c| power_to_bernstein(c, h, degree))
            .collect();
        for (j, ((&x, &y), &z)) in coords[0].iter().zip(&coords[1]).zip(&coords[2]).enumerate() {
            let p = [x, y, z];
            if j == 0 && i > 0 {
                // The previous segment's end: the joint is the earlier segment's value.
                if let Some(&q) = points.last() {
                    worst_gap = worst_gap.max(norm(sub(p, q)));
                }
                continue;
            }
            points.push(p);
        }
        let k = if i + 1 < n { t[i + 1] } else { t[n] };
        knots.extend(std::iter::repeat_n(
            k,
            if i + 1 < n { degree } else { degree + 1 },
        ));
    }
    if worst_gap > tol {
        diags.push(Diagnostic::warning(
            "spline_gap",
            format!("consecutive segments are {worst_gap} apart at a break point; each joint is the earlier segment's end"),
            loc.clone(),
        ));
    }
    // The terminate-point values: value and derivatives / k! at T(N+1).
    if let Some(last) = rec.segments.last() {
        let h = t[n] - t[n - 1];
        let mut off = 0.0f64;
        for (axis, c) in last.iter().enumerate() {
            let v = c[0] + h * (c[1] + h * (c[2] + h * c[3]));
            off = off.max((v - rec.terminate[axis][0]).abs());
        }
        if off > tol {
            diags.push(Diagnostic::warning(
                "spline_terminate",
                format!("the terminate-point values differ from the last segment's end by {off}; the segments are used"),
                loc.clone(),
            ));
        }
    }
    let r = NurbsCurve::new(degree, knots, points, None);
    match r {
        Ok(c) => Some((c, None, ParamMap::Identity)),
        Err(e) => {
            diags.push(invalid(entry, &e.to_string()));
            None
        }
    }
}

/// The outcome of a 102: one NURBS when the pieces join, else the pieces.
pub(super) enum Composite {
    Joined(Box<CurveOut>),
    Pieces(Vec<(DirectoryEntry, CurveOut)>),
}

/// 102 (IGES 5.3 section 4.4): the constituents, in order, each converted with its own
/// chain, then the 102's chain. With `join`, when every piece converts and each ends where
/// the next starts (within the model's tolerance), they are joined into one NURBS (degrees
/// raised to the highest by A5.9, polynomial pieces given unit weights, each piece's
/// parameter shifted to continue the previous one: the concatenation IGES 5.3 defines);
/// otherwise the converted pieces are returned separately. A constituent that is itself a
/// 102 is refused (IGES 5.3 does not nest composites).
pub(super) fn composite(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    join_pieces: bool,
    diags: &mut Vec<Diagnostic>,
) -> Option<Composite> {
    let rec = decoded(cx.file.decode::<CompositeCurve102>(entry), diags)?;
    let loc = entity_location(entry);
    let mut pieces = Vec::with_capacity(rec.members.len());
    let mut all = true;
    for &m in &rec.members {
        let Some(member) = cx.file.entry(m) else {
            diags.push(Diagnostic::warning(
                "pointer.invalid",
                format!("constituent pointer {m} names no directory entry; skipped"),
                loc.clone(),
            ));
            all = false;
            continue;
        };
        if member.entity_type == 102 {
            diags.push(Diagnostic::warning(
                "composite.nested",
                format!(
                    "constituent D{} is itself a 102 (IGES 5.3 does not nest composites); it is read on its own, not as part of this one",
                    member.pointer
                ),
                loc.clone(),
            ));
            all = false;
            continue;
        }
        match simple_curve(cx, member, diags) {
            Some(c) => pieces.push((member.clone(), c)),
            None => all = false,
        }
    }
    let mut meta = Meta {
        name: super::read::name_of(entry),
        form: Some(super::form_text(entry.form)),
        ..Meta::default()
    };
    let chain = cx.transforms(entry, &mut meta, diags)?;
    for (_, p) in &mut pieces {
        if let Some(m) = &chain {
            match p.curve.transform(m) {
                Ok(c) => p.curve = c,
                Err(e) => {
                    diags.push(invalid(entry, &e.to_string()));
                    return None;
                }
            }
            p.meta
                .transforms_applied
                .extend(meta.transforms_applied.iter().cloned());
        }
    }
    if pieces.is_empty() {
        diags.push(Diagnostic::error(
            "composite.empty",
            "no constituent of the composite curve could be read; entity not loaded".to_owned(),
            loc,
        ));
        return None;
    }
    if all && !join_pieces {
        diags.push(Diagnostic::info(
            "composite_edges",
            format!(
                "a face boundary (used by a 142, 504 or 508): its {} constituents are kept as separate curves, the edges of that boundary",
                pieces.len()
            ),
            loc,
        ));
    } else if all {
        match join(pieces.iter().map(|(_, p)| &p.curve), cx) {
            Ok((curve, gap)) => {
                if gap > 0.0 {
                    diags.push(Diagnostic::info(
                        "composite_gap",
                        format!("the constituents meet within {gap}; each joint is the midpoint of the two ends"),
                        loc.clone(),
                    ));
                }
                let shape = if pieces.iter().all(|(_, p)| p.shape == Some(Shape::Line)) {
                    Some(Shape::Polyline)
                } else {
                    None
                };
                meta.shape = shape;
                return Some(Composite::Joined(Box::new(CurveOut {
                    curve,
                    shape,
                    map: ParamMap::Identity,
                    meta,
                })));
            }
            Err(why) => diags.push(Diagnostic::info(
                "composite_pieces",
                format!("the constituents are kept as separate curves: {why}"),
                loc,
            )),
        }
    } else {
        diags.push(Diagnostic::warning(
            "composite_pieces",
            "not every constituent could be read; the others are kept as separate curves"
                .to_owned(),
            loc,
        ));
    }
    Some(Composite::Pieces(pieces))
}

/// Joins curves end to start (degree raised to the highest, unit weights where needed).
/// Returns the curve and the largest gap between consecutive ends.
fn join<'c>(
    curves: impl Iterator<Item = &'c NurbsCurve> + Clone,
    cx: &Context<'_, '_>,
) -> Result<(NurbsCurve, f64), String> {
    let degree = curves.clone().map(NurbsCurve::degree).max().unwrap_or(1);
    let rational = curves.clone().any(NurbsCurve::is_rational);
    let tol = cx.tolerance(
        &curves
            .clone()
            .flat_map(|c| c.control_points().iter().flatten().copied())
            .collect::<Vec<_>>(),
    );
    let mut out: Option<NurbsCurve> = None;
    let mut gap = 0.0f64;
    for c in curves {
        let mut c = if c.degree() < degree {
            c.elevate(degree - c.degree()).map_err(|e| e.to_string())?
        } else {
            c.clone()
        };
        if rational && !c.is_rational() {
            let (p, k, pts, _, dim) = c.into_parts();
            let n = pts.len();
            c = NurbsCurve::with_dimension(p, k, pts, Some(vec![1.0; n]), dim)
                .map_err(|e| e.to_string())?;
        }
        out = Some(match out {
            None => c,
            Some(prev) => {
                let (_, b) = prev.domain();
                let (a, _) = c.domain();
                let end = prev.point_at_unchecked(b);
                let start = c.point_at_unchecked(a);
                gap = gap.max(norm(sub(end, start)));
                prev.join(&c, tol).map_err(|e| e.to_string())?
            }
        });
    }
    out.map(|c| (c, gap))
        .ok_or_else(|| "no constituent".to_owned())
}
