//! The IGES 5.3 surface entities other than 128 as exact NURBS: 108 plane, 114 parametric
//! spline surface, 118 ruled surface, 120 surface of revolution, 122 tabulated cylinder and
//! the analytic surfaces 190-198. Each surface is built in its definition space, then its
//! own 124 chain is applied to the Euclidean poles (exact for affine maps).
//!
//! Unbounded surfaces (108 form 0, 190-198) are bounded by the extent their uses need,
//! never by an invented size: the model-space boundary curves of the 144 Trimmed Surfaces
//! (their 142 curves' C(t)) and 510 Faces (their 508 loops' 504 edge curves) that name
//! them, and the bounding curve of a bounded 108. Those curves' poles are mapped into the
//! surface's frame through the exact inverse of its parameterisation (the coordinates
//! along the frame's axes for planes and axial directions, the angle about the axis for the
//! rotational directions). By the convex hull property every boundary curve lies in the
//! convex hull of its poles, and so does the face they bound; the box of the poles'
//! parameters therefore contains the face (in angle: when the poles span at most half a
//! turn, the wedge they span is convex and contains the hull; otherwise the full turn is
//! taken). Spheres and tori take the full latitude / minor circle.

use nurbsx_parsers::iges::DirectoryEntry;
use nurbsx_parsers::iges::records::{
    Cone194, Cylinder192, Direction123, Plane108, PlaneSurface190, Point116, Revolution120,
    RuledSurface118, Sphere196, SplineSurface114, TabulatedCylinder122, Torus198,
};

use super::curves::{self, CurveOut, ParamMap, power_to_bernstein};
use super::read::{Context, decoded, entity_location, name_of};
use super::vector::{apply_linear, cross, dot, norm, scale, sub, unit};
use crate::exchange::{Diagnostic, Meta, Shape};
use crate::nurbs::sweep::{self, Frame};
use crate::nurbs::transform::{Affine, apply};
use crate::nurbs::{GeometryError, Grid, NurbsSurface, Point3};

use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// A surface entity converted: the NURBS (own 124 chain applied, file units), its kind and
/// its metadata.
pub(super) struct SurfaceOut {
    pub surface: NurbsSurface,
    pub meta: Meta,
}

/// Converts a surface entity of type 108, 114, 118, 120, 122 or 190-198.
pub(super) fn surface(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<SurfaceOut> {
    let mut meta = Meta {
        name: name_of(entry),
        form: Some(super::form_text(entry.form)),
        ..Meta::default()
    };
    let chain = cx.transforms(entry, &mut meta, diags)?;
    let built = match entry.entity_type {
        108 => plane108(cx, entry, chain.as_ref(), diags),
        114 => spline114(cx, entry, diags),
        118 => ruled118(cx, entry, diags),
        120 => revolution120(cx, entry, diags),
        122 => tabulated122(cx, entry, diags),
        190..=198 => analytic19x(cx, entry, chain.as_ref(), diags),
        _ => None,
    };
    let (surface, shape) = built?;
    let surface = match chain.map_or(Ok(surface.clone()), |m| surface.transform(&m)) {
        Ok(s) => s,
        Err(e) => {
            diags.push(invalid(entry, &e));
            return None;
        }
    };
    meta.shape = shape;
    Some(SurfaceOut { surface, meta })
}

type Built = (NurbsSurface, Option<Shape>);

fn invalid(entry: &DirectoryEntry, e: &GeometryError) -> Diagnostic {
    Diagnostic::error(
        "geometry.invalid",
        format!(
            "{} entity has no valid exact NURBS form: {e}; entity not loaded",
            entry.entity_type
        ),
        entity_location(entry),
    )
}

fn refused(entry: &DirectoryEntry, code: &str, why: String) -> Diagnostic {
    Diagnostic::error(
        code,
        format!("{why}; entity not loaded"),
        entity_location(entry),
    )
}

fn done(
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
    r: Result<NurbsSurface, GeometryError>,
    shape: Option<Shape>,
) -> Option<Built> {
    match r {
        Ok(s) => Some((s, shape)),
        Err(e) => {
            diags.push(invalid(entry, &e));
            None
        }
    }
}

/// A curve a surface names (a 102 only when its pieces join), or an error diagnostic on
/// the surface. The curve's own diagnostics are reported where the curve itself is read.
fn curve_ref(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    pointer: i64,
    what: &str,
    diags: &mut Vec<Diagnostic>,
) -> Option<CurveOut> {
    let Some(target) = cx.file.entry(pointer) else {
        diags.push(refused(
            entry,
            "pointer.invalid",
            format!("the {what} pointer {pointer} names no directory entry"),
        ));
        return None;
    };
    let mut scratch = Vec::new();
    let out = if target.entity_type == 102 {
        match curves::composite(cx, target, true, &mut scratch) {
            Some(curves::Composite::Joined(c)) => Some(*c),
            _ => None,
        }
    } else {
        curves::simple_curve(cx, target, &mut scratch)
    };
    if out.is_none() {
        diags.push(refused(
            entry,
            "reference.unreadable",
            format!(
                "its {what} D{} (type {}) has no exact NURBS form (see that entity's diagnostics)",
                target.pointer, target.entity_type
            ),
        ));
    }
    out
}

/// 114 (IGES 5.3 section 4.15): patch `(i, j)` is `sum c[4 b + a] s^a t^b` with
/// `s = u - TU(i)`, `t = v - TV(j)`. Each patch becomes a Bezier patch by the exact
/// power-to-Bernstein change of basis in s, then in t (the basis is a tensor product);
/// the knots are the break points with multiplicity equal to the degree, so the NURBS
/// parameters are the IGES parameters `(u, v)`. Degrees are the highest powers with a
/// non-zero coefficient (at most 3). Rows shared by neighbouring patches take the earlier
/// patch's values; a gap between them is a warning.
fn spline114(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<SplineSurface114>(entry), diags)?;
    let (tu, tv) = (&rec.breakpoints_u, &rec.breakpoints_v);
    let increasing =
        |t: &[f64]| t.windows(2).all(|w| w[1] > w[0]) && t.iter().all(|x| x.is_finite());
    if !increasing(tu) || !increasing(tv) {
        diags.push(refused(
            entry,
            "geometry.invalid",
            "the break points TU or TV do not increase".to_owned(),
        ));
        return None;
    }
    let (m, n) = (tu.len() - 1, tv.len() - 1);
    let (mut du, mut dv) = (1usize, 1usize);
    for p in &rec.patches {
        for c in p {
            for (k, &x) in c.iter().enumerate() {
                if x != 0.0 {
                    du = du.max(k % 4);
                    dv = dv.max(k / 4);
                }
            }
        }
    }
    let (nu, nv) = (du * m + 1, dv * n + 1);
    let mut net: Vec<Option<Point3>> = vec![None; nu * nv];
    let mut gap = 0.0f64;
    for i in 0..m {
        for j in 0..n {
            let Some(patch) = rec.patches.get(i * n + j) else {
                continue;
            };
            let (hu, hv) = (tu[i + 1] - tu[i], tv[j + 1] - tv[j]);
            // Bernstein net of each coordinate: first along s for every power of t, then
            // along t for every Bernstein index in s.
            let mut coords = [[[0.0; 4]; 4]; 3];
            for (axis, c) in patch.iter().enumerate() {
                let mut by_t = [[0.0; 4]; 4]; // [b][r]
                for (b, row) in by_t.iter_mut().enumerate() {
                    let s_poly: Vec<f64> = (0..4).map(|a| c[4 * b + a]).collect();
                    for (r, x) in power_to_bernstein(&s_poly, hu, du).into_iter().enumerate() {
                        row[r] = x;
                    }
                }
                for r in 0..=du {
                    let t_poly: Vec<f64> = (0..4).map(|b| by_t[b][r]).collect();
                    for (q, x) in power_to_bernstein(&t_poly, hv, dv).into_iter().enumerate() {
                        coords[axis][r][q] = x;
                    }
                }
            }
            for r in 0..=du {
                for q in 0..=dv {
                    let p = [coords[0][r][q], coords[1][r][q], coords[2][r][q]];
                    let slot = &mut net[(du * i + r) * nv + dv * j + q];
                    match slot {
                        Some(old) => gap = gap.max(norm(sub(*old, p))),
                        None => *slot = Some(p),
                    }
                }
            }
        }
    }
    let points: Vec<Point3> = net
        .into_iter()
        .map(|p| p.unwrap_or([f64::NAN; 3]))
        .collect();
    let tol = cx.tolerance(&points.iter().flatten().copied().collect::<Vec<_>>());
    if gap > tol {
        diags.push(Diagnostic::warning(
            "spline_gap",
            format!("neighbouring patches are {gap} apart on a shared boundary; the earlier patch's values are used"),
            entity_location(entry),
        ));
    }
    let knots = |t: &[f64], d: usize| {
        let mut k = vec![t[0]; d + 1];
        for &x in &t[1..t.len() - 1] {
            k.extend(std::iter::repeat_n(x, d));
        }
        k.extend(std::iter::repeat_n(t[t.len() - 1], d + 1));
        k
    };
    let grid = Grid::from_u_major(nu, nv, points)?;
    let r = NurbsSurface::new(du, dv, knots(tu, du), knots(tv, dv), grid, None);
    done(entry, diags, r, None)
}

/// Whether the relative-parameter correspondence of two rails is exact in their NURBS
/// forms: both keep the IGES parameter (affine), or both are conic arcs of the same kind,
/// sweep and number of segments (then the map from relative NURBS parameter to relative
/// IGES parameter is the same function on both).
fn same_relative_map(a: &ParamMap, b: &ParamMap) -> bool {
    match (a, b) {
        (ParamMap::Identity, ParamMap::Identity) => true,
        (ParamMap::Arc(x), ParamMap::Arc(y)) => {
            let (sx, sy) = (x.range().1 - x.range().0, y.range().1 - y.range().0);
            x.kind() == y.kind()
                && x.segments() == y.segments()
                && (sx - sy).abs() <= 1e-12 * sx.abs().max(sy.abs())
        }
        _ => false,
    }
}

/// 118 (IGES 5.3 section 4.17): lines joining the points of equal relative parameter
/// (form 1) or equal relative arc length (form 0) of the two curves, the second reversed
/// when DIRFLG = 1. Form 1 is [`sweep::ruled`] (C1 reparameterised affinely onto C0's
/// domain), exact when both rails' NURBS parameters relate to their IGES parameters by the
/// same relative map ([`same_relative_map`]); otherwise it is refused. Form 0 is the same
/// surface when each rail's IGES parameter is proportional to its arc length (110 lines
/// and 100 circular arcs), which is the only case read; other form 0 surfaces are refused
/// (the arc-length correspondence of general curves has no exact rational form).
fn ruled118(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<RuledSurface118>(entry), diags)?;
    let kind_of = |p: i64| cx.file.entry(p).map_or(0, |e| e.entity_type);
    if rec.form == 0 {
        let uniform = |p: i64| matches!(kind_of(p), 100 | 110);
        if !(uniform(rec.first) && uniform(rec.second)) {
            diags.push(refused(
                entry,
                "ruled.arc_length",
                format!(
                    "form 0 joins points of equal relative arc length; with rails of types {} and {} that correspondence has no exact rational form (only 110 lines and 100 circular arcs, whose parameter is proportional to arc length, are read)",
                    kind_of(rec.first),
                    kind_of(rec.second)
                ),
            ));
            return None;
        }
    }
    let c0 = curve_ref(cx, entry, rec.first, "first curve", diags)?;
    let c1 = curve_ref(cx, entry, rec.second, "second curve", diags)?;
    if !same_relative_map(&c0.map, &c1.map) {
        diags.push(refused(
            entry,
            "ruled.parameterisation",
            "the rails' NURBS parameters do not relate to their IGES parameters by the same relative map (e.g. a line and a circular arc), so the equal-relative-parameter rulings are not those of a NURBS ruled surface".to_owned(),
        ));
        return None;
    }
    let second = if rec.reversed == 1 {
        match c1.curve.reverse() {
            Ok(c) => c,
            Err(e) => {
                diags.push(invalid(entry, &e));
                return None;
            }
        }
    } else {
        c1.curve
    };
    done(
        entry,
        diags,
        sweep::ruled(&c0.curve, &second),
        Some(Shape::Ruled),
    )
}

/// 120 (IGES 5.3 section 4.18): the generatrix rotated about the axis line from SA to TA
/// (radians; right-hand rule about the direction from the line's start to its end):
/// [`sweep::revolve`], u = the angle (exact [`ArcMap`](crate::nurbs::conic::ArcMap)),
/// v = the generatrix's parameter.
fn revolution120(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<Revolution120>(entry), diags)?;
    let Some(axis_entry) = cx.file.entry(rec.axis).filter(|e| e.entity_type == 110) else {
        diags.push(refused(
            entry,
            "pointer.invalid",
            format!("the axis pointer {} does not name a 110 line", rec.axis),
        ));
        return None;
    };
    let mut scratch = Vec::new();
    let Some((p, d)) = curves::axis_line(cx, axis_entry, &mut scratch) else {
        diags.extend(scratch);
        return None;
    };
    let profile = curve_ref(cx, entry, rec.generatrix, "generatrix", diags)?;
    let [sa, ta] = rec.angles;
    let r = sweep::revolve(&profile.curve, p, d, sa, ta).map(|(s, _)| s);
    done(entry, diags, r, Some(Shape::Revolution))
}

/// 122 (IGES 5.3 section 4.19): the directrix C swept along `L - C(start)`:
/// [`sweep::extrude`] with v in `[0, 1]`, u = the directrix's parameter.
fn tabulated122(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<TabulatedCylinder122>(entry), diags)?;
    let c = curve_ref(cx, entry, rec.directrix, "directrix", diags)?;
    let start = c.curve.point_at_unchecked(c.curve.domain().0);
    let r = sweep::extrude(&c.curve, sub(rec.end, start), 0.0, 1.0);
    done(entry, diags, r, Some(Shape::Extrusion))
}

/// A right-handed orthonormal frame with axis `z` and first axis `reference` projected
/// off `z`; without a usable reference, the world axis least aligned with `z`, projected.
fn frame(origin: Point3, z: Point3, reference: Option<Point3>) -> Option<Frame> {
    let z = unit(z)?;
    let off = |r: Point3| unit(sub(r, scale(z, dot(r, z))));
    let x = reference.and_then(off).or_else(|| {
        let k = (0..3)
            .min_by(|&a, &b| z[a].abs().total_cmp(&z[b].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[k] = 1.0;
        off(e)
    })?;
    Some(Frame {
        origin,
        x,
        y: cross(z, x),
        z,
    })
}

/// The poles of the boundary curves of the faces that use `entry` (144s and 510s), mapped
/// into its definition space by the inverse of its own 124 chain; `Err` with the reason when
/// there is none.
fn use_poles(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    chain: Option<&Affine>,
) -> Result<Vec<Point3>, String> {
    let Some(curves) = cx.boundaries.get(&entry.pointer) else {
        return Err("no 144 trimmed surface or 510 face uses it".to_owned());
    };
    let inverse = match chain {
        Some(m) => {
            Some(super::vector::invert(m).ok_or("its 124 transformation is singular".to_owned())?)
        }
        None => None,
    };
    let mut poles = Vec::new();
    for &c in curves {
        let mut scratch = Vec::new();
        let Some(target) = cx.file.entry(c) else {
            continue;
        };
        let out = if target.entity_type == 102 {
            match curves::composite(cx, target, false, &mut scratch) {
                Some(curves::Composite::Joined(c)) => vec![*c],
                Some(curves::Composite::Pieces(p)) => p.into_iter().map(|(_, c)| c).collect(),
                None => Vec::new(),
            }
        } else {
            curves::simple_curve(cx, target, &mut scratch)
                .into_iter()
                .collect()
        };
        for o in out {
            poles.extend(
                o.curve
                    .control_points()
                    .iter()
                    .map(|&p| inverse.as_ref().map_or(p, |m| apply(m, p))),
            );
        }
    }
    if poles.is_empty() {
        return Err("none of the boundary curves of its uses could be read in model space (a boundary given only in the surface's parameter space does not bound it)".to_owned());
    }
    Ok(poles)
}

/// The range of `f` over the points.
fn range(points: &[Point3], f: impl Fn(Point3) -> f64) -> (f64, f64) {
    points
        .iter()
        .map(|&p| f(p))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        })
}

/// The angular extent about the frame's z axis: the smallest arc holding every pole's
/// angle when it is at most half a turn (the wedge is then convex and holds the poles'
/// convex hull), else the full turn `[0, 2 pi]`. Poles on the axis constrain nothing.
fn angular_extent(f: &Frame, points: &[Point3], tol: f64) -> (f64, f64) {
    let mut angles: Vec<f64> = points
        .iter()
        .filter_map(|&p| {
            let d = sub(p, f.origin);
            let (x, y) = (dot(d, f.x), dot(d, f.y));
            (x.hypot(y) > tol).then(|| y.atan2(x).rem_euclid(TAU))
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    let (Some(&first), Some(&last)) = (angles.first(), angles.last()) else {
        return (0.0, TAU);
    };
    // The largest gap between consecutive angles (cyclically) is left out.
    let mut best = (first + TAU - last, first); // gap, start of the arc after it
    for w in angles.windows(2) {
        if w[1] - w[0] > best.0 {
            best = (w[1] - w[0], w[1]);
        }
    }
    let span = TAU - best.0;
    if span <= PI && span > 0.0 {
        (best.1, best.1 + span)
    } else {
        (0.0, TAU)
    }
}

/// The extent of an unbounded surface from the poles of its uses' boundaries (see the
/// module documentation), or a warning that it is not represented.
fn extent_or_warn(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    chain: Option<&Affine>,
    diags: &mut Vec<Diagnostic>,
) -> Option<Vec<Point3>> {
    match use_poles(cx, entry, chain) {
        Ok(p) => Some(p),
        Err(why) => {
            diags.push(Diagnostic::warning(
                "unbounded.not_represented",
                format!(
                    "{} is an unbounded surface and {why}; a NURBS is bounded, so it is not represented",
                    entry.entity_type
                ),
                entity_location(entry),
            )
            .not_carried());
            None
        }
    }
}

/// 108 (IGES 5.3 section 4.12): the plane `A x + B y + C z = D`, bounded (form 1, -1) by
/// its curve PTR or (form 0) by the faces that use it. Frame: origin the point of the plane
/// nearest the definition space's origin, z the unit normal, x the world axis least aligned
/// with it, projected; u, v the coordinates along x, y (identity maps).
fn plane108(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    chain: Option<&Affine>,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let rec = decoded(cx.file.decode::<Plane108>(entry), diags)?;
    let [a, b, c, d] = rec.coefficients;
    let n = [a, b, c];
    let nn = dot(n, n);
    let Some(f) = (nn > 0.0)
        .then(|| frame(scale(n, d / nn), n, None))
        .flatten()
    else {
        diags.push(refused(
            entry,
            "geometry.invalid",
            "the plane's normal (A, B, C) is zero".to_owned(),
        ));
        return None;
    };
    let poles = if rec.boundary != 0 {
        let curve = curve_ref(cx, entry, rec.boundary, "bounding curve", diags)?;
        curve.curve.control_points().to_vec()
    } else {
        extent_or_warn(cx, entry, chain, diags)?
    };
    let u = range(&poles, |p| dot(sub(p, f.origin), f.x));
    let v = range(&poles, |p| dot(sub(p, f.origin), f.y));
    done(entry, diags, sweep::plane(&f, u, v), Some(Shape::Plane))
}

/// The point of a 116 (its own chain applied: into the user's definition space).
fn point_of(cx: &Context<'_, '_>, pointer: i64, diags: &mut Vec<Diagnostic>) -> Option<Point3> {
    let e = cx.file.entry(pointer).filter(|e| e.entity_type == 116)?;
    let p = decoded(cx.file.decode::<Point116>(e), diags)?.point;
    let mut meta = Meta::default();
    let chain = cx.transforms(e, &mut meta, diags)?;
    Some(chain.map_or(p, |m| apply(&m, p)))
}

/// The direction of a 123 (the linear part of its own chain applied).
fn direction_of(cx: &Context<'_, '_>, pointer: i64, diags: &mut Vec<Diagnostic>) -> Option<Point3> {
    let e = cx.file.entry(pointer).filter(|e| e.entity_type == 123)?;
    let d = decoded(cx.file.decode::<Direction123>(e), diags)?.direction;
    let mut meta = Meta::default();
    let chain = cx.transforms(e, &mut meta, diags)?;
    Some(chain.map_or(d, |m| apply_linear(&m, d)))
}

/// 190-198 (IGES 5.3 sections 4.50-4.54) in the ISO 10303-42 parameterisations of
/// [`sweep`]: frame origin DELOC, z the axis (190: the normal), x DEREFD projected off z
/// (form 1) or the world axis least aligned with z, projected (form 0); u the angle about
/// z from x (radians, exact ArcMap), v the distance along z (cylinder, cone) or the
/// latitude / minor angle (sphere, torus). 194's SANGLE is in degrees.
fn analytic19x(
    cx: &Context<'_, '_>,
    entry: &DirectoryEntry,
    chain: Option<&Affine>,
    diags: &mut Vec<Diagnostic>,
) -> Option<Built> {
    let loc = entity_location(entry);
    let bad = |diags: &mut Vec<Diagnostic>, what: &str| {
        diags.push(Diagnostic::error(
            "pointer.invalid",
            format!("{what} is missing or unreadable; entity not loaded"),
            loc.clone(),
        ));
    };
    // The pointers (DELOC, DEAXIS or DENRML, DEREFD) and the kind with its sizes.
    let (location, axis, reference, kind) = match entry.entity_type {
        190 => {
            let r = decoded(cx.file.decode::<PlaneSurface190>(entry), diags)?;
            (r.location, r.normal, r.reference, Kind::Plane)
        }
        192 => {
            let r = decoded(cx.file.decode::<Cylinder192>(entry), diags)?;
            (r.location, r.axis, r.reference, Kind::Cylinder(r.radius))
        }
        194 => {
            let r = decoded(cx.file.decode::<Cone194>(entry), diags)?;
            let semi = r.semi_angle_degrees.to_radians();
            (r.location, r.axis, r.reference, Kind::Cone(r.radius, semi))
        }
        196 => {
            let r = decoded(cx.file.decode::<Sphere196>(entry), diags)?;
            (r.location, r.axis, r.reference, Kind::Sphere(r.radius))
        }
        198 => {
            let r = decoded(cx.file.decode::<Torus198>(entry), diags)?;
            let [major, minor] = r.radii;
            (r.location, r.axis, r.reference, Kind::Torus(major, minor))
        }
        _ => return None,
    };
    let Some(origin) = point_of(cx, location, diags) else {
        bad(diags, "DELOC (a 116 point)");
        return None;
    };
    // A form 0 sphere has no axis: the definition space's z.
    let axis = if axis == 0 && entry.entity_type == 196 {
        Some([0.0, 0.0, 1.0])
    } else {
        direction_of(cx, axis, diags)
    };
    let Some(axis) = axis else {
        bad(diags, "DEAXIS / DENRML (a 123 direction)");
        return None;
    };
    let reference = if reference == 0 {
        None
    } else {
        direction_of(cx, reference, diags)
    };
    let Some(f) = frame(origin, axis, reference) else {
        diags.push(refused(
            entry,
            "geometry.invalid",
            "the axis (or normal) is zero".to_owned(),
        ));
        return None;
    };
    let poles = extent_or_warn(cx, entry, chain, diags)?;
    let tol = cx.tolerance(&poles.iter().flatten().copied().collect::<Vec<_>>());
    let axial = range(&poles, |p| dot(sub(p, f.origin), f.z));
    let (r, shape) = match kind {
        Kind::Plane => {
            let u = range(&poles, |p| dot(sub(p, f.origin), f.x));
            let v = range(&poles, |p| dot(sub(p, f.origin), f.y));
            (sweep::plane(&f, u, v), Shape::Plane)
        }
        Kind::Cylinder(radius) => (
            sweep::cylinder(&f, radius, angular_extent(&f, &poles, tol), axial).map(|(s, _)| s),
            Shape::Cylinder,
        ),
        Kind::Cone(radius, semi) => {
            // The poles' hull may reach past the apex (v = -r / tan a): the face does not.
            let mut v = axial;
            if semi > 0.0 {
                v.0 = v.0.max(-radius / semi.tan());
            }
            (
                sweep::cone(&f, radius, semi, angular_extent(&f, &poles, tol), v).map(|(s, _)| s),
                Shape::Cone,
            )
        }
        Kind::Sphere(radius) => (
            sweep::sphere(
                &f,
                radius,
                angular_extent(&f, &poles, tol),
                (-FRAC_PI_2, FRAC_PI_2),
            )
            .map(|(s, _)| s),
            Shape::Sphere,
        ),
        Kind::Torus(major, minor) => (
            sweep::torus(&f, major, minor, angular_extent(&f, &poles, tol), (-PI, PI))
                .map(|(s, _)| s),
            Shape::Torus,
        ),
    };
    done(entry, diags, r, Some(shape))
}

/// The analytic surface kinds with their sizes.
enum Kind {
    Plane,
    Cylinder(f64),
    Cone(f64, f64),
    Sphere(f64),
    Torus(f64, f64),
}
