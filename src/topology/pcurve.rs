//! # Parameter-space curves of edges on faces
//!
//! The pcurve of an edge on a face (ISO 10303-42 clause 4.4.2 pcurve; IGES 5.3 section 4.32,
//! entity 142 BPTR) is the curve `t -> (u(t), v(t))` in the face surface's parameter plane
//! with `S(u(t), v(t)) = C(t)`, parameterised like the edge's 3-D curve `C`. The surfaces
//! here are NURBS (an analytic surface of the file converted exactly), so the file's own
//! pcurves, given in the analytic parameters, do not apply and [`edge_pcurve`] computes one,
//! exactly where it can:
//! - **Affine surfaces** (a plane: bilinear with a parallelogram of poles and equal weights):
//!   `S(u, v) = P00 + s A + r B` with `s`, `r` affine in `u`, `v`, so `(u, v)` is an affine
//!   function of the point, and affine maps commute with the rational B-spline combination
//!   (NURBS Book section 4.2, affine invariance): the pcurve is the 3-D curve with each pole
//!   mapped, same knots and weights. Exact for any NURBS edge.
//! - **Iso-parametric edges** (generators and seams of cylinders, cones, extrusions and
//!   revolutions, parallels and meridians of spheres, tori and revolutions): the edge lies
//!   on `u = u_c` (or `v = v_c`) and is the isocurve `v -> S(u_c, v)` (NURBS Book A3.5,
//!   [`NurbsSurface::iso_u`]) under an affine change of parameter `v = alpha t + beta`. This
//!   holds when both are the same NURBS parameterisation of the same curve, as a circle
//!   edge and the parallel of a cylinder built by the same arc layout (seed 000 sections 2-23
//!   and 2-24: the NURBS circle and cylinder); the interior knots must correspond under the
//!   map, and the agreement is then checked densely. The pcurve is the line from
//!   `(u_c, v(a))` to `(u_c, v(b))`, of degree 1. A point where the surface degenerates (a
//!   pole, an apex) takes the iso's `u_c`. The edge's points are located on the surface
//!   by the closed-form inverse of a quadric's parameterisation when the caller has it
//!   ([`QuadricMap`]: cylinders, cones, spheres, tori as [`crate::nurbs::sweep`] builds
//!   them; unchecked there, since the isocurve they select must hold the edge's ends and
//!   pass the deviation check below), by point inversion (NURBS Book section 6.1) otherwise.
//! - **Otherwise** (a rational change of parameter, a freeform surface): projection of the
//!   curve onto the surface within the edge tolerance
//!   ([`crate::nurbs::project::pcurve_by_projection`]).
//!
//! The deviation returned is an upper bound from the poles (strong convex hull property) or
//! measured by sampling `S(pcurve(t))` against `C(t)`, never assumed: an exact pcurve shows
//! rounding only (it is accepted as exact below 1e-12 of the
//! surface's size; above, projection is used).

use super::{Coedge, EdgeId, Loop, Model};
use crate::nurbs::project::{invert_curve, invert_surface, pcurve_by_projection};
use crate::nurbs::sweep::QuadricMap;
use crate::nurbs::vector::{add, cross, dist, dot, norm, sub};
use crate::nurbs::{
    GeometryError, NurbsCurve, NurbsSurface, Point3, bounding_box, bounding_box_diagonal, distance,
    knots::{breakpoints, clamped},
};

/// How a pcurve was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PcurveMethod {
    /// The 3-D curve under the inverse of an affine surface's map (planes).
    Affine,
    /// A line along an isocurve of the surface that the edge curve is, up to an affine
    /// change of parameter.
    Iso,
    /// Projected onto the surface and fitted within the edge tolerance.
    Projected,
}

/// A pcurve with its measured deviation from the 3-D curve.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgePcurve {
    /// The 2-D curve `(u(t), v(t))`, parameterised like the edge's 3-D curve over a domain
    /// that contains the edge's range.
    pub curve: NurbsCurve,
    /// Largest `|S(pcurve(t)) - C(t)|` found over the edge's range.
    pub deviation: f64,
    /// How it was obtained.
    pub method: PcurveMethod,
}

/// Samples per knot span of the edge curve (at least [`MIN_SAMPLES`] over the range) for the
/// deviation of an exact pcurve.
const SAMPLES_PER_SPAN: usize = 8;
/// Fewest samples over an edge's range.
const MIN_SAMPLES: usize = 32;
/// Relative size (of the surface's control net) below which a deviation is rounding.
const EXACT: f64 = 1e-12;
/// Rounding of one evaluation of a point, per basis term, relative to the largest pole
/// coordinates: a few units in the last place for the sums and the rational division, on
/// the curve's side and the surface's.
const EVALUATION_ROUNDING: f64 = 16.0 * f64::EPSILON;

/// The pcurve of the part `range` of `curve` on `surface` (see the module): exact for
/// affine surfaces and iso-parametric edges ([`exact_pcurve`]), else projected within
/// `tolerance`. `map` is the surface's own parameterisation when it is a quadric built by
/// [`crate::nurbs::sweep`] (it only saves point inversions; the result is the same).
///
/// Errors: those of [`pcurve_by_projection`] when no exact pcurve applies.
pub fn edge_pcurve(
    surface: &NurbsSurface,
    map: Option<&QuadricMap>,
    curve: &NurbsCurve,
    range: (f64, f64),
    tolerance: f64,
) -> Result<EdgePcurve, GeometryError> {
    if let Some(p) = exact_pcurve(surface, map, curve, range, tolerance) {
        return Ok(p);
    }
    let (p, deviation) = pcurve_by_projection(surface, curve, range, tolerance)?;
    Ok(EdgePcurve {
        curve: p,
        deviation,
        method: PcurveMethod::Projected,
    })
}

/// The exact pcurve of the part `range` of `curve` on `surface`, when one applies (see the
/// module): an iso-parametric one whose measured deviation is rounding (1e-12 of the
/// surface's size), or the affine map of a plane, whose deviation is the curve's own
/// distance from the plane (the map is the orthogonal projection onto it; no pcurve can do
/// better) and is accepted within `tolerance`. `map` as for [`edge_pcurve`].
pub fn exact_pcurve(
    surface: &NurbsSurface,
    map: Option<&QuadricMap>,
    curve: &NurbsCurve,
    range: (f64, f64),
    tolerance: f64,
) -> Option<EdgePcurve> {
    let (a, b) = range;
    let (ca, cb) = curve.domain();
    if !(a.is_finite() && b.is_finite() && a < b && a >= ca && b <= cb) {
        return None;
    }
    let size = bounding_box_diagonal(surface.control_points().as_slice());
    // The pcurve, a bound of its deviation from the poles, and the deviation accepted.
    let (p, method, bound, accept) = match affine(surface, curve) {
        Some(p) => {
            let bound = plane_bound(surface, curve, &p);
            (p, PcurveMethod::Affine, bound, tolerance.max(EXACT * size))
        }
        None => {
            let found = iso(surface, map, curve, range, size)?;
            let bound = match &found.along {
                Along::Line { line, ends } => iso_bound(curve, range, line, *ends),
                Along::Bound(bound) => *bound,
            };
            (found.pcurve, PcurveMethod::Iso, bound, EXACT * size)
        }
    };
    // The bound when it accepts the pcurve (the common case), else the sampled deviation.
    let deviation = match bound {
        Some(d) if d <= accept => d,
        _ => deviation(surface, curve, &p, range),
    };
    (deviation <= accept).then_some(EdgePcurve {
        curve: p,
        deviation,
        method,
    })
}

/// A pcurve lying on a seam of its surface (constant u at an end of a u-closed surface's
/// domain, or constant v), moved to the side the coedge needs: `ccw` when the coedge runs
/// with the face interior on its left in `(u, v)`. Along the u = u0 side the interior is at
/// larger u, so a counter-clockwise coedge runs there with decreasing v; along u = u1 with
/// increasing v (and in v: along v = v0 with increasing u, along v = v1 with decreasing u).
/// `None` when the pcurve is not on a seam: on a line `u = u0` or `u1` (`v = v0` or `v1`)
/// where `seam[0]` (`seam[1]`) says that line is one: the surface is closed in u (in v), or
/// the face uses the edge twice. The STEP reader gives the two coedges of a seam edge (used
/// twice by one face) their two sides with it, and a coedge that runs once along the seam
/// line of a closed surface (a sphere's lune between a meridian on the seam and another
/// meridian) the side its orientation asks for: with the other side, the loop would enclose
/// the lune's complement in `(u, v)`.
pub fn seam_side(
    surface: &NurbsSurface,
    p: &NurbsCurve,
    ccw: bool,
    seam: [bool; 2],
) -> Option<NurbsCurve> {
    if !(seam[0] || seam[1]) {
        return None;
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    let poles = p.control_points();
    let ends = || {
        let (a, b) = p.domain();
        (p.point_at_unchecked(a), p.point_at_unchecked(b))
    };
    let on = |k: usize, at: f64, span: f64| poles.iter().all(|q| (q[k] - at).abs() <= 1e-9 * span);
    let (k, lo, hi, rising) = if seam[0] && (on(0, u0, u1 - u0) || on(0, u1, u1 - u0)) {
        let (s, e) = ends();
        (0, u0, u1, e[1] > s[1])
    } else if seam[1] && (on(1, v0, v1 - v0) || on(1, v1, v1 - v0)) {
        let (s, e) = ends();
        (1, v0, v1, e[0] < s[0])
    } else {
        return None;
    };
    // rising: the pcurve's own direction is the one that belongs on the high side.
    let high = rising == ccw;
    at_coordinate(p, k, if high { hi } else { lo })
}

/// Whether `moved` ([`seam_side`] of `p`) traces on `surface` exactly what `p` traces, so
/// that a deviation measured with `p` holds for it: `moved` is `p`, or `p` lies exactly on
/// one side of a seam (every pole's coordinate at one end of the domain) and `moved` on the
/// other, of a surface clamped there whose first and last rows of poles and weights across
/// it are equal. `S(u0, v)` and `S(u1, v)` are then the same rational curve (at a clamped
/// end the isocurve is that row: NURBS Book eq. 3.10 there). Decided from the poles, without
/// evaluation.
pub fn same_trace(surface: &NurbsSurface, p: &NurbsCurve, moved: &NurbsCurve) -> bool {
    if moved == p {
        return true;
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    let (a, b) = (p.control_points(), moved.control_points());
    if a.len() != b.len() {
        return false;
    }
    let all_at = |poles: &[Point3], k: usize, x: f64| poles.iter().all(|q| q[k] == x);
    let crossed = |k: usize, lo: f64, hi: f64| {
        (all_at(a, k, lo) && all_at(b, k, hi)) || (all_at(a, k, hi) && all_at(b, k, lo))
    };
    let other_same = |k: usize| a.iter().zip(b).all(|(x, y)| x[1 - k] == y[1 - k]);
    let grid = surface.control_points();
    let w = |i: usize, j: usize| surface.weights().map(|g| *g.get(i, j));
    let (nu, nv) = (grid.nu(), grid.nv());
    if nu == 0 || nv == 0 {
        return false;
    }
    if crossed(0, u0, u1) && other_same(0) {
        let ends = clamped(surface.knots_u(), surface.degree_u());
        return ends
            && (0..nv).all(|j| grid.get(0, j) == grid.get(nu - 1, j) && w(0, j) == w(nu - 1, j));
    }
    if crossed(1, v0, v1) && other_same(1) {
        let ends = clamped(surface.knots_v(), surface.degree_v());
        return ends
            && (0..nu).all(|i| grid.get(i, 0) == grid.get(i, nv - 1) && w(i, 0) == w(i, nv - 1));
    }
    false
}

/// The two sides of the seam edges of a loop whose orientation in `(u, v)` is not known (IGES
/// faces, sewn faces): each coedge in `coedges` whose pcurve lies on a seam, and whose edge
/// `twice` says the face uses twice or whose surface is closed across that seam (an edge of
/// the face that runs along the seam line, as where a 270° face of a whole cylinder meets
/// its neighbour), takes the side nearest to where its neighbour in the loop ends (the
/// previous coedge; the next one's start when the previous is such a seam coedge too), so
/// the loop is continuous in `(u, v)`.
///
/// A loop of coedges that all lie on the seams of the directions in which the surface is
/// closed (a whole sphere cut along one meridian, whose poles' degenerate sides are not
/// written; a whole torus cut along its two seams) has no such neighbour. It bounds the whole domain, and only its counter-clockwise run (against the
/// face's `same_sense`) encloses that; the clockwise one encloses nothing of the domain. So
/// each of its coedges takes the side [`seam_side`] gives a counter-clockwise loop.
pub fn seam_sides_by_continuity(
    surface: &NurbsSurface,
    coedges: &mut [Coedge],
    same_sense: bool,
    twice: impl Fn(EdgeId) -> bool,
) {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let size = bounding_box_diagonal(surface.control_points().as_slice());
    let closed = [
        surface.is_closed_u(1e-9 * size),
        surface.is_closed_v(1e-9 * size),
    ];
    let on_seam = |p: &NurbsCurve, twice: bool| -> Option<(usize, f64, f64)> {
        let poles = p.control_points();
        let on =
            |k: usize, at: f64, span: f64| poles.iter().all(|q| (q[k] - at).abs() <= 1e-9 * span);
        if (twice || closed[0]) && (on(0, u0, u1 - u0) || on(0, u1, u1 - u0)) {
            Some((0, u0, u1))
        } else if (twice || closed[1]) && (on(1, v0, v1 - v0) || on(1, v1, v1 - v0)) {
            Some((1, v0, v1))
        } else {
            None
        }
    };
    // Walking ends of a coedge's pcurve.
    let ends = |c: &Coedge| -> Option<(Point3, Point3)> {
        let p = c.pcurve.as_ref()?;
        let (a, b) = p.domain();
        let (s, e) = (p.point_at_unchecked(a), p.point_at_unchecked(b));
        Some(if c.forward { (s, e) } else { (e, s) })
    };
    let n = coedges.len();
    let seam: Vec<Option<(usize, f64, f64)>> = coedges
        .iter()
        .map(|c| c.pcurve.as_ref().and_then(|p| on_seam(p, twice(c.edge))))
        .collect();
    let on_closed_seam = |c: &Coedge| c.pcurve.as_ref().and_then(|p| on_seam(p, false));
    if n >= 2 && coedges.iter().all(|c| on_closed_seam(c).is_some()) {
        for c in coedges.iter_mut() {
            let moved = c
                .pcurve
                .as_ref()
                .and_then(|p| seam_side(surface, p, c.forward == same_sense, closed));
            if let Some(m) = moved {
                c.pcurve = Some(m);
            }
        }
        return;
    }
    for i in 0..n {
        let Some((k, lo, hi)) = seam[i] else {
            continue;
        };
        let (prev, next) = ((i + n - 1) % n, (i + 1) % n);
        let target = if seam[prev].is_none() {
            ends(&coedges[prev]).map(|(_, e)| e[k])
        } else if seam[next].is_none() {
            ends(&coedges[next]).map(|(s, _)| s[k])
        } else {
            None
        };
        let Some(target) = target else { continue };
        let side = if (target - lo).abs() <= (target - hi).abs() {
            lo
        } else {
            hi
        };
        if let Some(p) = coedges[i].pcurve.as_mut() {
            if let Some(m) = at_coordinate(p, k, side) {
                *p = m;
            }
        }
    }
}

/// Whether a loop runs counter-clockwise in `(u, v)` (the signed area of its pcurves, walked
/// in loop order and sampled `LOOP_SAMPLES` times each, is positive); `None` when a coedge
/// has no pcurve or the loop is not closed in `(u, v)` (a loop around a closed surface
/// without a seam edge, or pcurves a period apart across a seam), within 1e-6 of the
/// surface's parameter domain (a gap at a pole, whose two ends and middle are one 3-D point,
/// counts as closed).
pub fn loop_counter_clockwise(surface: &NurbsSurface, coedges: &[Coedge]) -> Option<bool> {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let near = 1e-6 * (u1 - u0).hypot(v1 - v0);
    let size = bounding_box_diagonal(surface.control_points().as_slice());
    // Consecutive ends meet in (u, v), or at one point of a pole (a sphere's or cone's
    // apex, where the segment between them is the degenerate edge: its middle is that point
    // too). Ends a period apart across a seam are one 3-D point but not a pole: the polygon
    // through them crosses itself, and its signed area says nothing of the orientation.
    let at = |p: [f64; 2]| surface.point_at_unchecked(p[0].clamp(u0, u1), p[1].clamp(v0, v1));
    let joined = |p: [f64; 2], q: [f64; 2]| {
        let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
        (p[0] - q[0]).hypot(p[1] - q[1]) <= near
            || (dist(at(p), at(q)) <= 1e-9 * size && dist(at(p), at(mid)) <= 1e-9 * size)
    };
    let mut points: Vec<[f64; 2]> = Vec::new();
    let mut last: Option<[f64; 2]> = None;
    for c in coedges {
        let p = c.pcurve.as_ref()?;
        let (a, b) = p.domain();
        for k in 0..=LOOP_SAMPLES {
            let t = along(c, (a, b), k as f64 / LOOP_SAMPLES as f64);
            let [u, v, _] = p.point_at_unchecked(t);
            if k == 0 {
                if let Some(q) = last {
                    if !joined(q, [u, v]) {
                        return None;
                    }
                }
            }
            points.push([u, v]);
        }
        last = points.last().copied();
    }
    let first = *points.first()?;
    let end = last?;
    if !joined(end, first) {
        return None;
    }
    let n = points.len();
    let twice: f64 = (0..n)
        .map(|i| {
            let (p, q) = (points[i], points[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum();
    (twice.is_finite() && twice != 0.0).then_some(twice > 0.0)
}

/// Points per coedge at which [`loop_counter_clockwise`] samples a loop.
const LOOP_SAMPLES: usize = 16;

/// Most seams [`moved_seams`] offers.
const MAX_SEAMS: usize = 8;

/// The surface with its seam moved (exactly, [`NurbsSurface::rotate_seam_u`]) to the
/// parameter of each vertex of `loops` (in `model`) in each direction in which it is closed: the candidates
/// for a face whose edges cross the surface's seam but not the face's own. A periodic face
/// in a file (ISO 10303-42 face_surface on a cylinder, cone, torus or revolution) may place
/// its seam anywhere: Open CASCADE puts a pipe elbow's torus seam on the inner equator
/// (`v = pi`), while the NURBS torus starts at `v = 0`, so the closed edges that start on the
/// face's seam run across the NURBS one and no pcurve inside the domain exists. Moved to a
/// vertex of the face (where the face's seam edges meet its other edges), the seams agree.
/// Points off the surface (by more than `tolerance`), at its ends, or repeated are skipped;
/// at most `MAX_SEAMS` surfaces. A surface closed within `tolerance` only (an IGES 120
/// revolved by a rounded `2 pi`) is joined at its old seam within that gap.
pub fn moved_seams(
    surface: &NurbsSurface,
    model: &Model,
    loops: &[Loop],
    tolerance: f64,
) -> Vec<NurbsSurface> {
    let points: Vec<Point3> = loops
        .iter()
        .flat_map(|l| &l.coedges)
        .filter_map(|c| model.coedge_ends(c))
        .filter_map(|(v, _)| model.vertices.get(v.0).map(|v| v.point))
        .collect();
    let size = bounding_box_diagonal(surface.control_points().as_slice());
    let ((u0, u1), (v0, v1)) = surface.domain();
    let mut params: Vec<(f64, f64)> = Vec::new();
    for &q in &points {
        if let Some(hit) = invert_surface(surface, q, None) {
            if hit.distance <= tolerance.max(1e-9 * size) {
                params.push((hit.u, hit.v));
            }
        }
    }
    let mut out = Vec::new();
    for along_u in [true, false] {
        let (lo, hi) = if along_u { (u0, u1) } else { (v0, v1) };
        let mut seen: Vec<f64> = Vec::new();
        for &(u, v) in &params {
            let t = if along_u { u } else { v };
            let near = |x: f64| (x - t).abs() <= 1e-9 * (hi - lo);
            if near(lo) || near(hi) || seen.iter().any(|&x| near(x)) || out.len() >= MAX_SEAMS {
                continue;
            }
            seen.push(t);
            let moved = if along_u {
                surface.rotate_seam_u(t, tolerance)
            } else {
                surface.rotate_seam_v(t, tolerance)
            };
            match moved {
                Ok(m) => out.push(m),
                // Not closed in this direction.
                Err(_) => break,
            }
        }
    }
    out
}

/// The parameter of `[a, b]` a fraction `f` of the way along a coedge, in the direction its
/// loop runs.
fn along(c: &Coedge, (a, b): (f64, f64), f: f64) -> f64 {
    if c.forward {
        a + (b - a) * f
    } else {
        b - (b - a) * f
    }
}

/// Points per coedge at which [`seam_splits`] locates a loop on the surface.
const SEAM_SAMPLES: usize = 24;

/// A seam for a closed surface and the edges it must cut ([`seam_splits`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SeamPlan {
    /// The surface with its seam moved ([`NurbsSurface::rotate_seam_u`], exact) or as it was.
    pub surface: NurbsSurface,
    /// Edges crossing the seam and the curve parameter where they do: each is to be split
    /// there ([`Model::split_edge`]), so that each half has a pcurve inside the domain.
    pub splits: Vec<(EdgeId, f64)>,
}

/// A seam for a face on a surface closed in u or v whose loops both wind around it and do
/// not. ISO 10303-42 lets a face on a cylinder (cone, torus, revolution) have no seam edge:
/// Solid Edge writes a pipe between two full circles, pierced by two holes, as one face
/// whose circles start at 0 and 180 degrees and whose holes lie around 0 and 180 degrees.
/// A NURBS surface has its seam at one place, and a pcurve must stay inside the domain, so
/// - the seam goes where no loop that does not wind around is: in the middle of the widest
///   gap between them, or where it is if it already lies in a gap, or with no such loops at
///   the start of the first winding loop;
/// - each edge of a winding loop that the seam then crosses away from its ends is to be
///   split where it crosses ([`Model::split_edge`]; found by bisection on the side of the
///   seam of the point inverted onto the surface, to the curve parameter's rounding).
///
/// Loops are located by inverting 24 points per coedge; a loop winds when
/// its travel in the closed direction is more than half the period. `None` when a point is
/// off the surface by more than `tolerance`, when the loops that do not wind cover the whole
/// period, when an edge crosses the seam more than once, or when nothing would change.
pub fn seam_splits(
    surface: &NurbsSurface,
    model: &Model,
    loops: &[Loop],
    tolerance: f64,
) -> Option<SeamPlan> {
    let size = bounding_box_diagonal(surface.control_points().as_slice());
    let near = tolerance.max(1e-9 * size);
    let locate = |q: Point3| invert_surface(surface, q, None).filter(|h| h.distance <= near);
    // Per loop, per coedge in loop order: (edge, [(curve parameter, (u, v))]).
    type Track = Vec<(EdgeId, Vec<(f64, [f64; 2])>)>;
    let mut tracks: Vec<Track> = Vec::with_capacity(loops.len());
    for l in loops {
        let mut track = Vec::with_capacity(l.coedges.len());
        for c in &l.coedges {
            let e = model.edges.get(c.edge.0)?;
            let (a, b) = e.range;
            let mut pts = Vec::with_capacity(SEAM_SAMPLES + 1);
            for k in 0..=SEAM_SAMPLES {
                let t = along(c, (a, b), k as f64 / SEAM_SAMPLES as f64).clamp(a, b);
                let hit = locate(e.curve.point_at(t).ok()?)?;
                pts.push((t, [hit.u, hit.v]));
            }
            track.push((c.edge, pts));
        }
        tracks.push(track);
    }
    let domain = surface.domain();
    let mut current = surface.clone();
    let mut moved = false;
    let mut splits: Vec<(EdgeId, f64)> = Vec::new();
    for d in 0..2 {
        let (lo, hi) = if d == 0 { domain.0 } else { domain.1 };
        let period = hi - lo;
        let closed = if d == 0 {
            surface.is_closed_u(tolerance)
        } else {
            surface.is_closed_v(tolerance)
        };
        if !closed || period.is_nan() || period <= 0.0 {
            continue;
        }
        // Into (-period / 2, period / 2].
        let wrap = |x: f64| {
            let y = x.rem_euclid(period);
            if y > period / 2.0 { y - period } else { y }
        };
        let mut arcs: Vec<(f64, f64)> = Vec::new();
        let mut winding: Vec<usize> = Vec::new();
        for (k, track) in tracks.iter().enumerate() {
            let mut x: Option<f64> = None;
            let (mut min, mut max, mut start) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
            for (_, pts) in track {
                for (_, uv) in pts {
                    let y = match x {
                        None => {
                            start = uv[d];
                            uv[d]
                        }
                        Some(px) => px + wrap(uv[d] - px),
                    };
                    (min, max) = (min.min(y), max.max(y));
                    x = Some(y);
                }
            }
            let Some(end) = x else { continue };
            if (end - start).abs() > period / 2.0 {
                winding.push(k);
            } else {
                arcs.push((lo + (min - lo).rem_euclid(period), max - min));
            }
        }
        let Some(&first_winding) = winding.first() else {
            continue;
        };
        let seam = if arcs.is_empty() {
            tracks[first_winding].first()?.1.first()?.1[d]
        } else {
            arcs.sort_by(|a, b| a.0.total_cmp(&b.0));
            if arcs.iter().any(|a| a.1 >= period) {
                return None;
            }
            // Is the current seam (`lo`, also `hi`) in a gap?
            let covers = |&(s, l): &(f64, f64)| s + l > hi || s <= lo;
            if arcs.iter().any(covers) {
                let mut best = (0.0f64, 0.0f64);
                let mut reach = arcs[0].0 + arcs[0].1;
                for &(s, l) in &arcs[1..] {
                    if s > reach && s - reach > best.0 {
                        best = (s - reach, reach + (s - reach) / 2.0);
                    }
                    reach = reach.max(s + l);
                }
                let around = arcs[0].0 + period - reach;
                if around > best.0 {
                    best = (around, reach + around / 2.0);
                }
                if best.0 <= 0.0 {
                    return None;
                }
                lo + (best.1 - lo).rem_euclid(period)
            } else {
                lo
            }
        };
        let slack = 1e-9 * period;
        if (seam - lo).abs() > slack && (hi - seam).abs() > slack {
            current = if d == 0 {
                current.rotate_seam_u(seam, tolerance)
            } else {
                current.rotate_seam_v(seam, tolerance)
            }
            .ok()?;
            moved = true;
        }
        // The side of the seam of a curve point: negative before it, positive after.
        let side = |e: &super::Edge, t: f64| -> Option<f64> {
            let h = locate(e.curve.point_at(t).ok()?)?;
            Some(wrap([h.u, h.v][d] - seam))
        };
        for &k in &winding {
            for (edge, pts) in &tracks[k] {
                let e = model.edges.get(edge.0)?;
                let (a, b) = e.range;
                for w in pts.windows(2) {
                    let (ta, tb) = (w[0].0, w[1].0);
                    let (ga, gb) = (wrap(w[0].1[d] - seam), wrap(w[1].1[d] - seam));
                    // A crossing of the seam, not of its opposite line.
                    if (ga < 0.0) == (gb < 0.0) || (ga - gb).abs() > period / 2.0 {
                        continue;
                    }
                    let (mut inside, mut outside) = (ta, tb);
                    for _ in 0..80 {
                        let mid = 0.5 * (inside + outside);
                        if mid == inside || mid == outside {
                            break;
                        }
                        if (side(e, mid)? < 0.0) == (ga < 0.0) {
                            inside = mid;
                        } else {
                            outside = mid;
                        }
                    }
                    let mut t = 0.5 * (inside + outside);
                    // A knot within rounding of the crossing is the crossing (a circle crosses
                    // a quadric's seam at a knot): cut there, not a rounding error away,
                    // which would leave a sliver span.
                    if let Some(k) = e
                        .curve
                        .knots()
                        .iter()
                        .find(|&&k| (k - t).abs() <= 1e-10 * (b - a))
                    {
                        t = *k;
                    }
                    // At a vertex: the edge ends on the seam, nothing to cut.
                    if (t - a).abs() <= 1e-9 * (b - a) || (b - t).abs() <= 1e-9 * (b - a) {
                        continue;
                    }
                    if splits.iter().any(|(x, _)| x == edge) {
                        return None;
                    }
                    splits.push((*edge, t));
                }
            }
        }
    }
    (moved || !splits.is_empty()).then_some(SeamPlan {
        surface: current,
        splits,
    })
}

/// Largest `|S(p(t)) - C(t)|` at `SAMPLES_PER_SPAN` points per knot span of `curve` in
/// `range` (at least `MIN_SAMPLES`), the parameters clamped into the surface's domain.
fn deviation(
    surface: &NurbsSurface,
    curve: &NurbsCurve,
    p: &NurbsCurve,
    (a, b): (f64, f64),
) -> f64 {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let (pa, pb) = p.domain();
    let spans = curve
        .knots()
        .windows(2)
        .filter(|w| w[0] < w[1] && w[1] > a && w[0] < b)
        .count()
        .max(1);
    let n = (spans * SAMPLES_PER_SPAN).max(MIN_SAMPLES);
    let mut worst: f64 = 0.0;
    for k in 0..=n {
        let t = if k == n {
            b
        } else {
            a + (b - a) * k as f64 / n as f64
        };
        let [u, v, _] = p.point_at_unchecked(t.clamp(pa, pb));
        let d = dist(
            surface.point_at_unchecked(u.clamp(u0, u1), v.clamp(v0, v1)),
            curve.point_at_unchecked(t),
        );
        worst = worst.max(d);
    }
    if worst.is_nan() { f64::INFINITY } else { worst }
}

/// An iso-parametric pcurve with what bounds its deviation.
struct Iso {
    /// The line `t -> (u, v)` over the edge's range `[a, b]`.
    pcurve: NurbsCurve,
    /// The isocurve it runs along, or the bound already found.
    along: Along,
}

/// What an [`Iso`] runs along.
enum Along {
    /// The surface's isocurve through the pcurve, parameterised by the surface's free
    /// parameter, with the free parameter at `a` and at `b` ([`iso_bound`] compares the
    /// edge with its piece).
    Line { line: NurbsCurve, ends: (f64, f64) },
    /// A bound of the deviation, found without building the isocurve (a row of the net
    /// compared with the edge's poles: [`net_row`]); `None` when the
    /// comparison gave none.
    Bound(Option<f64>),
}

/// A bound of the deviation of a plane's pcurve ([`affine`]): the map is the orthogonal
/// projection onto the plane, so `|S(p(t)) - C(t)|` is `C(t)`'s distance from the plane, a
/// convex combination of its poles' distances (positive weights: NURBS Book section 4.2,
/// strong convex hull property), so at most the largest (plus the rounding of evaluating
/// it, [`EVALUATION_ROUNDING`]). `None` when a pole of the pcurve
/// is outside the surface's domain (the sampling then tells what clamping does).
fn plane_bound(surface: &NurbsSurface, curve: &NurbsCurve, p: &NurbsCurve) -> Option<f64> {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let inside = p
        .control_points()
        .iter()
        .all(|q| (u0..=u1).contains(&q[0]) && (v0..=v1).contains(&q[1]));
    if !inside {
        return None;
    }
    let g = surface.control_points();
    let (p00, p10, p01) = (*g.get(0, 0), *g.get(1, 0), *g.get(0, 1));
    let n = cross(sub(p10, p00), sub(p01, p00));
    let len = norm(n);
    if !(len.is_finite() && len > 0.0) {
        return None;
    }
    let poles = curve.control_points();
    let worst = poles
        .iter()
        .map(|&x| dot(sub(x, p00), n).abs() / len)
        .fold(0.0f64, f64::max);
    let magnitude = poles
        .iter()
        .chain(g.as_slice())
        .map(|q| norm(*q))
        .fold(0.0f64, f64::max);
    let rounding = EVALUATION_ROUNDING * (curve.degree() as f64 + 1.0) * magnitude;
    let bound = worst + rounding;
    bound.is_finite().then_some(bound)
}

/// A bound of the deviation of an iso-parametric pcurve: the edge's piece over `[a, b]` and
/// the piece of the isocurve `line` between `ends` (reversed when the edge runs down it),
/// each cut out exactly (NURBS Book A5.1), compared pole by pole ([`same_curve_bound`]).
/// `None` when their knots, degrees or pole counts do not match (the sampling then decides).
fn iso_bound(
    curve: &NurbsCurve,
    (a, b): (f64, f64),
    line: &NurbsCurve,
    (fa, fb): (f64, f64),
) -> Option<f64> {
    let (lo, hi) = (fa.min(fb), fa.max(fb));
    let edge = curve.piece(a, b).ok()?;
    let mut line = line.piece(lo, hi).ok()?;
    if fa > fb {
        line = line.reverse().ok()?;
    }
    same_curve_bound(&edge, &line)
}

/// A bound of `|C(t) - D(phi(t))|` over `C`'s domain, `phi` the increasing affine map of
/// `C`'s domain onto `D`'s, when the two have the same degree and pole count and `D`'s knots
/// are `phi` of `C`'s up to rounding: then both are combinations of their poles with the
/// same basis functions, so the distance is at most
/// - the largest distance between corresponding poles (equal weights: a convex combination
///   of the pole differences, NURBS Book section 4.2),
/// - plus, for weights proportional only up to a relative `e`, `4 e` times the poles'
///   extent (the normalised combination weights move by at most `2 e / (1 - e)` in sum),
/// - plus, for knots off `phi` by `k`, `2 p (p + 1) k / h` times the extent (`h` the
///   shortest non-empty span: a basis function's derivative in a knot is at most `p / h`),
/// - plus what evaluating either side rounds ([`EVALUATION_ROUNDING`] per basis term, of the
///   largest pole coordinates), so the bound covers any deviation measured by evaluation.
///
/// `None` when the structure differs or the mismatches are not rounding-sized.
fn same_curve_bound(c: &NurbsCurve, d: &NurbsCurve) -> Option<f64> {
    let kd = d.knots();
    if d.degree() != c.degree() || c.knots().len() != kd.len() {
        return None;
    }
    let poles = d.control_points();
    matched_bound(c, |k| kd[k], |i| (&poles[i], d.weight(i)))
}

/// [`same_curve_bound`] of `c` against a curve `D` of `c`'s degree and knot count given by
/// its knots `d_knot(k)` (non-decreasing) and its poles and weights `d_pole(i)`, for `k`
/// and `i` over `c`'s knot and pole indices: a row of a surface's net is compared with an
/// edge this way without being built as a curve first ([`net_row`]).
fn matched_bound<'a>(
    c: &'a NurbsCurve,
    d_knot: impl Fn(usize) -> f64,
    d_pole: impl Fn(usize) -> (&'a Point3, f64),
) -> Option<f64> {
    let p = c.degree();
    let kc = c.knots();
    let n = c.num_poles();
    let (c0, c1) = c.domain();
    let (d0, d1) = (d_knot(p), d_knot(n));
    let alpha = (d1 - d0) / (c1 - c0);
    if !(alpha.is_finite() && alpha > 0.0) {
        return None;
    }
    let span = d1 - d0;
    let mut knot_off = 0.0f64;
    let mut shortest = f64::INFINITY;
    for (k, &x) in kc.iter().enumerate() {
        let y = d_knot(k);
        knot_off = knot_off.max((d0 + (x - c0) * alpha - y).abs());
        if k > 0 {
            let h = y - d_knot(k - 1);
            if h > 0.0 {
                shortest = shortest.min(h);
            }
        }
    }
    let ratio = d_pole(0).1 / c.weight(0);
    if !(knot_off <= 1e-12 * span && ratio.is_finite() && ratio > 0.0) {
        return None;
    }
    let (mut weight_off, mut poles, mut magnitude) = (0.0f64, 0.0f64, 0.0f64);
    for (i, x) in c.control_points().iter().enumerate() {
        let (y, wy) = d_pole(i);
        weight_off = weight_off.max((wy / (ratio * c.weight(i)) - 1.0).abs());
        poles = poles.max(dist(*x, *y));
        magnitude = magnitude.max(norm(*x)).max(norm(*y));
    }
    // (A NaN pole distance would make the bound NaN: refused here as there.)
    if !(weight_off <= 1e-9 && poles.is_finite()) {
        return None;
    }
    let (lo, hi) = bounding_box(c.control_points().iter().chain((0..n).map(|i| d_pole(i).0)));
    let extent = distance(lo, hi);
    let pf = p as f64;
    let bound = poles
        + 4.0 * weight_off * extent
        + 2.0 * pf * (pf + 1.0) * (knot_off / shortest) * extent
        + EVALUATION_ROUNDING * (pf + 1.0) * magnitude;
    bound.is_finite().then_some(bound)
}

/// A surface whose point is an affine function of `(u, v)`: degree 1 in both directions,
/// 2 x 2 poles forming a parallelogram, equal weights. Returns the pcurve of `curve`:
/// each pole mapped to `(u, v)` by the inverse map (least squares in the plane).
fn affine(surface: &NurbsSurface, curve: &NurbsCurve) -> Option<NurbsCurve> {
    let g = surface.control_points();
    if surface.degree_u() != 1 || surface.degree_v() != 1 || g.nu() != 2 || g.nv() != 2 {
        return None;
    }
    let w = surface.weight(0, 0);
    if (0..2).any(|i| (0..2).any(|j| surface.weight(i, j) != w)) {
        return None;
    }
    let (p00, p10, p01, p11) = (*g.get(0, 0), *g.get(1, 0), *g.get(0, 1), *g.get(1, 1));
    let size = bounding_box_diagonal(g.as_slice());
    if dist(add(p00, p11), add(p10, p01)) > 1e-14 * size {
        return None;
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    let (ea, eb) = (sub(p10, p00), sub(p01, p00));
    let (aa, ab, bb) = (dot(ea, ea), dot(ea, eb), dot(eb, eb));
    let det = aa * bb - ab * ab;
    if !(det.is_finite() && det > 1e-12 * aa * bb) {
        return None;
    }
    let poles: Vec<Point3> = curve
        .control_points()
        .iter()
        .map(|&x| {
            let r = sub(x, p00);
            let (ra, rb) = (dot(ea, r), dot(eb, r));
            let s = (bb * ra - ab * rb) / det;
            let t = (aa * rb - ab * ra) / det;
            [u0 + s * (u1 - u0), v0 + t * (v1 - v0), 0.0]
        })
        .collect();
    with_poles(curve, poles)
}

/// A 2-D curve with `p`'s degree, knots and weights and the given poles.
fn with_poles(p: &NurbsCurve, poles: Vec<Point3>) -> Option<NurbsCurve> {
    NurbsCurve::with_dimension(
        p.degree(),
        p.knots().to_vec(),
        poles,
        p.weights().map(<[f64]>::to_vec),
        2,
    )
    .ok()
}

/// `p` with coordinate `k` of every pole set to `value` (a pcurve moved onto one side of a
/// seam).
fn at_coordinate(p: &NurbsCurve, k: usize, value: f64) -> Option<NurbsCurve> {
    let poles = p
        .control_points()
        .iter()
        .map(|q| {
            let mut q = *q;
            q[k] = value;
            q
        })
        .collect();
    with_poles(p, poles)
}

/// `x` moved onto the nearest of `targets` within `within`.
fn snap(x: f64, targets: &[f64], within: f64) -> f64 {
    targets
        .iter()
        .copied()
        .filter(|k| (k - x).abs() <= within)
        .min_by(|p, q| (p - x).abs().total_cmp(&(q - x).abs()))
        .unwrap_or(x)
}

/// The distinct knots strictly inside `(lo, hi)`.
fn inner_knots(knots: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let mut k: Vec<f64> = knots
        .iter()
        .copied()
        .filter(|&x| x > lo && x < hi)
        .collect();
    k.dedup();
    k
}

/// The iso-parametric pcurve of `curve` over `range` (see the module), or `None` when the
/// edge is not an isocurve of the surface up to an affine change of parameter.
fn iso(
    surface: &NurbsSurface,
    map: Option<&QuadricMap>,
    curve: &NurbsCurve,
    (a, b): (f64, f64),
    size: f64,
) -> Option<Iso> {
    if let Some(found) = net_row(surface, curve, (a, b), size) {
        return Some(found);
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    // The quadric's closed-form parameters of a point. Not checked here: the isocurve they
    // choose is checked at the edge's ends below and against the whole edge by the bound
    // (`iso_bound`) or the sampling of [`exact_pcurve`], which refuse a wrong one.
    let located = |point: Point3| {
        let (u, v) = map?.parameters(point);
        (u.is_finite() && v.is_finite()).then_some([u, v])
    };
    // Three interior points of the edge on the surface.
    let mut inner = [[0.0f64; 2]; 3];
    let mut guess = None;
    for (k, q) in inner.iter_mut().enumerate() {
        let t = a + (b - a) * (k + 1) as f64 / 4.0;
        let point = curve.point_at_unchecked(t);
        if let Some(found) = located(point) {
            *q = found;
            guess = Some((found[0], found[1]));
            continue;
        }
        let mut hit = invert_surface(surface, point, guess)?;
        // Newton from the previous point can stop on the far side of a closed surface.
        if hit.distance > EXACT * size && guess.is_some() {
            hit = invert_surface(surface, point, None)?;
        }
        if hit.distance > EXACT * size {
            return None;
        }
        *q = [hit.u, hit.v];
        guess = Some((hit.u, hit.v));
    }
    let spans = [u1 - u0, v1 - v0];
    let knots = [surface.knots_u(), surface.knots_v()];
    let lo_hi = [(u0, u1), (v0, v1)];
    // The direction whose parameter is the same at the three points (either side of a seam
    // counts as the same).
    let same = |k: usize| {
        let x = inner[0][k];
        inner.iter().all(|q| {
            let d = (q[k] - x).abs();
            d <= 1e-10 * spans[k] || (d - spans[k]).abs() <= 1e-10 * spans[k]
        })
    };
    let fixed = match (same(0), same(1)) {
        (true, false) => 0,
        (false, true) => 1,
        _ => return None,
    };
    let free = 1 - fixed;
    let c = snap(inner[0][fixed], knots[fixed], 1e-10 * spans[fixed]);
    let line = if fixed == 0 {
        surface.iso_u(c).ok()?
    } else {
        surface.iso_v(c).ok()?
    };
    // The direction of travel along the isocurve, from the three points.
    let f = [inner[0][free], inner[1][free], inner[2][free]];
    let rising = if f[0] < f[1] && f[1] < f[2] {
        true
    } else if f[0] > f[1] && f[1] > f[2] {
        false
    } else {
        return None;
    };
    let (lo, hi) = lo_hi[free];
    // Closed: the isocurve's ends meet (a clamped circle, or an unclamped periodic profile
    // whose first and last poles differ).
    let closed = {
        let (la, lb) = line.domain();
        dist(line.point_at_unchecked(la), line.point_at_unchecked(lb)) <= EXACT * size
    };
    let end = |t: f64, start: bool| -> Option<f64> {
        let point = curve.point_at_unchecked(t);
        // The isocurve's parameter is the surface's in the free direction.
        let (x, d) = match located(point) {
            Some(q) => {
                let (la, lb) = line.domain();
                let x = q[free].clamp(la, lb);
                (x, dist(line.point_at_unchecked(x), point))
            }
            None => invert_curve(&line, point)?,
        };
        if d > EXACT * size {
            return None;
        }
        let mut x = snap(x, knots[free], 1e-10 * spans[free]);
        // On the seam of a closed isocurve: the side the edge leaves from or arrives at.
        if closed && (x == lo || x == hi) {
            x = if rising == start { lo } else { hi };
        }
        Some(x)
    };
    let (fa, fb) = (end(a, true)?, end(b, false)?);
    let in_order = if rising {
        fa < f[0] && f[2] < fb
    } else {
        fa > f[0] && f[2] > fb
    };
    if !in_order {
        return None;
    }
    // The same parameterisation up to t -> fa + (t - a) alpha: the edge's interior knots
    // land on the isocurve's.
    let alpha = (fb - fa) / (b - a);
    let mapped: Vec<f64> = inner_knots(curve.knots(), a, b)
        .into_iter()
        .map(|t| fa + (t - a) * alpha)
        .collect();
    let mut theirs = inner_knots(line.knots(), fa.min(fb), fa.max(fb));
    if !rising {
        theirs.reverse();
    }
    if line.degree() != curve.degree()
        || mapped.len() != theirs.len()
        || mapped
            .iter()
            .zip(&theirs)
            .any(|(x, y)| (x - y).abs() > 1e-9 * spans[free])
    {
        return None;
    }
    let point = |x: f64| {
        let mut q = [0.0; 3];
        q[fixed] = c;
        q[free] = x;
        q
    };
    let pcurve =
        NurbsCurve::with_dimension(1, vec![a, a, b, b], vec![point(fa), point(fb)], None, 2)
            .ok()?;
    Some(Iso {
        pcurve,
        along: Along::Line {
            line,
            ends: (fa, fb),
        },
    })
}

/// The fast path of [`iso`], without any point inversion: the edge's curve is a row or
/// column of the surface's control net at a breakpoint of the fixed direction (a clamped
/// end, or an interior knot of multiplicity `p`: the isocurve there has exactly that row's
/// poles and weights, [`breakpoints`]), between two breakpoints of the free direction (the
/// isocurve's piece there is that slice of the row with the knots between, NURBS Book A5.1
/// inserting nothing at a breakpoint): the same poles and proportional weights in the same
/// or the reverse order, and the edge's knots an affine image of the piece's. A sphere's
/// meridian and parallel arcs between quarter points, a cylinder's circles and generators.
/// The pcurve is the line at that row, its free parameter the inverse of the affine map;
/// the deviation is bounded by comparing the edge with the slice pole by pole
/// ([`matched_bound`]) over the whole edge curve, which bounds it over any range of it.
fn net_row(
    surface: &NurbsSurface,
    curve: &NurbsCurve,
    (a, b): (f64, f64),
    size: f64,
) -> Option<Iso> {
    let grid = surface.control_points();
    let weights = surface.weights();
    let poles = curve.control_points();
    let n = poles.len();
    let (first, last) = (*poles.first()?, *poles.last()?);
    let tol = 1e-12 * size;
    let w = |i: usize, j: usize| weights.map_or(1.0, |g| *g.get(i, j));
    let t = curve.knots();
    for fixed in [1, 0] {
        let free = 1 - fixed;
        let (fixed_knots, fixed_degree) = if fixed == 0 {
            (surface.knots_u(), surface.degree_u())
        } else {
            (surface.knots_v(), surface.degree_v())
        };
        let (knots, degree) = if free == 0 {
            (surface.knots_u(), surface.degree_u())
        } else {
            (surface.knots_v(), surface.degree_v())
        };
        if curve.degree() != degree {
            continue;
        }
        // The pole `k` of the net's row (column) `index` along the free direction.
        let at = |index: usize, k: usize| {
            let (i, j) = if fixed == 1 { (k, index) } else { (index, k) };
            (grid.get(i, j), w(i, j))
        };
        for (c, index) in breakpoints(fixed_knots, fixed_degree) {
            for (lo, ia) in breakpoints(knots, degree) {
                // The edge starts or ends at this breakpoint's pole (the cheap test first).
                let near = |x: Point3| {
                    let q = at(index, ia).0;
                    (x[0] - q[0]).abs() <= tol
                        && (x[1] - q[1]).abs() <= tol
                        && (x[2] - q[2]).abs() <= tol
                };
                if !(near(first) || near(last)) {
                    continue;
                }
                let ib = ia + n - 1;
                // The piece from this breakpoint to the one at pole `ib`, if there is one.
                let Some((hi, _)) = breakpoints(knots, degree).find(|&(_, k)| k == ib) else {
                    continue;
                };
                if hi <= lo {
                    continue;
                }
                // Its knots: `lo` and `hi` p + 1 times, the free direction's knots between.
                let piece_knot = |k: usize| {
                    if k <= degree {
                        lo
                    } else if k >= n {
                        hi
                    } else {
                        knots[ia + k]
                    }
                };
                for reversed in [false, true] {
                    let start = if reversed { last } else { first };
                    if dist(start, *at(index, ia).0) > tol {
                        continue;
                    }
                    let pole = |k: usize| at(index, if reversed { ib - k } else { ia + k });
                    let ratio = curve.weight(0) / pole(0).1;
                    let same = (0..n).all(|k| {
                        let (q, wq) = pole(k);
                        dist(poles[k], *q) <= tol
                            && (curve.weight(k) - ratio * wq).abs() <= 1e-12 * ratio
                    });
                    if !same {
                        continue;
                    }
                    // t = alpha s + beta, s the surface parameter (mirrored when reversed).
                    let m = n + degree;
                    let s_of = |k: usize| {
                        if reversed {
                            piece_knot(m - k)
                        } else {
                            piece_knot(k)
                        }
                    };
                    if t.len() != m + 1 {
                        continue;
                    }
                    let (s0, s1) = (s_of(0), s_of(m));
                    let alpha = (t[m] - t[0]) / (s1 - s0);
                    let span = (t[m] - t[0]).abs();
                    let affine = (0..=m)
                        .all(|k| (t[k] - (t[0] + alpha * (s_of(k) - s0))).abs() <= 1e-12 * span);
                    if !affine || !alpha.is_finite() || alpha == 0.0 {
                        continue;
                    }
                    let s = |x: f64| s0 + (x - t[0]) / alpha;
                    let point = |x: f64| {
                        let mut q = [0.0; 3];
                        q[fixed] = c;
                        q[free] = s(x);
                        q
                    };
                    let pcurve = NurbsCurve::with_dimension(
                        1,
                        vec![a, a, b, b],
                        vec![point(a), point(b)],
                        None,
                        2,
                    )
                    .ok()?;
                    // The slice is the isocurve's piece (see above); compared with the whole
                    // edge curve (its knots negated when it runs the other way, an
                    // increasing affine image).
                    let sign = if reversed { -1.0 } else { 1.0 };
                    let bound = matched_bound(curve, |k| sign * s_of(k), pole);
                    return Some(Iso {
                        pcurve,
                        along: Along::Bound(bound),
                    });
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn on_surface(surface: &NurbsSurface, p: &NurbsCurve, t: f64) -> Point3 {
        let [u, v, _] = p.point_at_unchecked(t);
        surface.point_at_unchecked(u, v)
    }
    use crate::nurbs::sweep::{Frame, cylinder, plane, sphere};

    fn frame() -> Frame {
        Frame {
            origin: [1.0, 2.0, 3.0],
            x: [1.0, 0.0, 0.0],
            y: [0.0, 1.0, 0.0],
            z: [0.0, 0.0, 1.0],
        }
    }

    #[test]
    fn a_line_across_a_plane_maps_exactly() {
        let s = plane(&frame(), (-5.0, 5.0), (-2.0, 2.0)).unwrap();
        let c = NurbsCurve::new(
            2,
            vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            vec![[0.0, 1.0, 3.0], [3.0, 4.0, 3.0], [5.0, 2.5, 3.0]],
            Some(vec![1.0, 0.5, 1.0]),
        )
        .unwrap();
        let p = edge_pcurve(&s, None, &c, (0.2, 0.9), 1e-6).unwrap();
        assert_eq!(p.method, PcurveMethod::Affine);
        assert!(p.deviation <= 1e-14 * 10.0, "{:e}", p.deviation);
        for k in 0..=100 {
            let t = 0.2 + 0.7 * k as f64 / 100.0;
            assert!(dist(on_surface(&s, &p.curve, t), c.point_at_unchecked(t)) <= 1e-14 * 10.0);
        }
    }

    /// A curve lifted off a plane by up to 1e-8 gets the plane's pcurve with a deviation
    /// that bounds the distance found densely and is no more than the lift (plus rounding);
    /// a parallel of a cylinder with one pole moved by 1e-7 is no isocurve, and with a
    /// tolerance below that no exact pcurve is claimed.
    #[test]
    fn deviations_bound_what_evaluation_finds() {
        let s = plane(&frame(), (-5.0, 5.0), (-2.0, 2.0)).unwrap();
        let c = NurbsCurve::new(
            2,
            vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            vec![[0.0, 1.0, 3.0], [3.0, 4.0, 3.0 + 1e-8], [5.0, 2.5, 3.0]],
            Some(vec![1.0, 0.5, 1.0]),
        )
        .unwrap();
        let p = edge_pcurve(&s, None, &c, (0.0, 1.0), 1e-6).unwrap();
        assert_eq!(p.method, PcurveMethod::Affine);
        let mut worst: f64 = 0.0;
        for k in 0..=1000 {
            let t = k as f64 / 1000.0;
            worst = worst.max(dist(on_surface(&s, &p.curve, t), c.point_at_unchecked(t)));
        }
        assert!(
            worst > 1e-9 && worst <= p.deviation,
            "{worst:e} {:e}",
            p.deviation
        );
        assert!(p.deviation <= 1e-8 + 1e-13, "{:e}", p.deviation);

        let (cyl, map) =
            cylinder(&frame(), 2.0, (0.0, 2.0 * std::f64::consts::PI), (0.0, 4.0)).unwrap();
        let ((_, _), (v0, v1)) = cyl.domain();
        let par = cyl.iso_v(v0 + 0.5 * (v1 - v0)).unwrap();
        let mut poles = par.control_points().to_vec();
        poles[3][2] += 1e-7;
        let moved = NurbsCurve::new(
            par.degree(),
            par.knots().to_vec(),
            poles,
            par.weights().map(<[f64]>::to_vec),
        )
        .unwrap();
        for m in [None, Some(&map)] {
            assert!(exact_pcurve(&cyl, m, &par, par.domain(), 1e-9).is_some());
            assert!(exact_pcurve(&cyl, m, &moved, moved.domain(), 1e-9).is_none());
        }
    }

    /// An edge that is a boundary row of the net (a cylinder's bottom parallel, either way
    /// round) gets its iso line with a deviation bound taken from the row itself, which
    /// covers what dense evaluation finds; the row with one pole moved by 1e-7 is refused.
    #[test]
    fn a_boundary_row_is_bounded_from_the_net() {
        let (cyl, map) =
            cylinder(&frame(), 2.0, (0.0, 2.0 * std::f64::consts::PI), (0.0, 4.0)).unwrap();
        let size = bounding_box_diagonal(cyl.control_points().as_slice());
        let ((_, _), (v0, _)) = cyl.domain();
        let row = cyl.iso_v(v0).unwrap();
        for edge in [row.clone(), row.reverse().unwrap()] {
            let found = net_row(&cyl, &edge, edge.domain(), size).expect("a boundary row");
            assert!(matches!(found.along, Along::Bound(Some(_))));
            let p = exact_pcurve(&cyl, Some(&map), &edge, edge.domain(), 1e-9).expect("exact");
            assert_eq!(p.method, PcurveMethod::Iso);
            let (a, b) = edge.domain();
            let mut worst: f64 = 0.0;
            for k in 0..=1000 {
                let t = a + (b - a) * k as f64 / 1000.0;
                worst = worst.max(dist(
                    on_surface(&cyl, &p.curve, t),
                    edge.point_at_unchecked(t),
                ));
            }
            assert!(worst <= p.deviation, "{worst:e} {:e}", p.deviation);
            assert!(p.deviation <= EXACT * size, "{:e}", p.deviation);
        }
        let mut poles = row.control_points().to_vec();
        poles[3][0] += 1e-7;
        let moved = NurbsCurve::new(
            row.degree(),
            row.knots().to_vec(),
            poles,
            row.weights().map(<[f64]>::to_vec),
        )
        .unwrap();
        assert!(exact_pcurve(&cyl, Some(&map), &moved, moved.domain(), 1e-9).is_none());
        // The bound of the moved row against the row covers their distance found densely.
        let (kr, pr) = (row.knots(), row.control_points());
        let bound = matched_bound(&moved, |k| kr[k], |i| (&pr[i], row.weight(i))).expect("bound");
        let (a, b) = row.domain();
        let mut worst: f64 = 0.0;
        for k in 0..=1000 {
            let t = a + (b - a) * k as f64 / 1000.0;
            worst = worst.max(dist(moved.point_at_unchecked(t), row.point_at_unchecked(t)));
        }
        assert!(worst > 1e-9 && worst <= bound, "{worst:e} {bound:e}");
    }

    /// Generators and parallels of a cylinder get exact iso lines, the same whether the
    /// edge's points are located by point inversion or by the cylinder's closed-form map.
    #[test]
    fn a_generator_of_a_cylinder_is_an_iso_line() {
        let (s, map) =
            cylinder(&frame(), 2.0, (0.0, 2.0 * std::f64::consts::PI), (0.0, 4.0)).unwrap();
        let ((u0, u1), _) = s.domain();
        let u = u0 + 0.3 * (u1 - u0);
        let g = s.iso_u(u).unwrap().reparameterize(10.0, 20.0).unwrap();
        // A parallel: the isocurve in v at some height, over part of its range.
        let ((_, _), (v0, v1)) = s.domain();
        let par = s.iso_v(v0 + 0.7 * (v1 - v0)).unwrap();
        let (a, b) = par.domain();
        let r = (a + 0.1 * (b - a), a + 0.8 * (b - a));
        for (edge, range) in [(&g, (11.0, 19.0)), (&par, r)] {
            let by_inversion = edge_pcurve(&s, None, edge, range, 1e-6).unwrap();
            let by_map = edge_pcurve(&s, Some(&map), edge, range, 1e-6).unwrap();
            let size = bounding_box_diagonal(s.control_points().as_slice());
            for p in [&by_inversion, &by_map] {
                assert_eq!(p.method, PcurveMethod::Iso);
                // The deviation reported bounds the one found densely and is rounding.
                assert!(p.deviation <= EXACT * size, "{}", p.deviation);
                let mut worst: f64 = 0.0;
                for k in 0..=200 {
                    let t = range.0 + (range.1 - range.0) * k as f64 / 200.0;
                    let d = dist(on_surface(&s, &p.curve, t), edge.point_at_unchecked(t));
                    assert!(d <= 1e-14 * 10.0, "{d:e}");
                    worst = worst.max(d);
                }
                assert!(worst <= p.deviation, "{worst:e} > {:e}", p.deviation);
            }
            let (pi, pm) = (
                by_inversion.curve.control_points(),
                by_map.curve.control_points(),
            );
            for (x, y) in pi.iter().zip(pm) {
                assert!(dist(*x, *y) <= 1e-14 * (u1 - u0), "{x:?} {y:?}");
            }
        }
    }

    /// Arcs of a sphere between its quarter points (a meridian from the pole to the
    /// equator, a parallel along a quarter of the equator; reparameterised, and reversed)
    /// are slices of its net's rows at breakpoints: found without inversion (no map given)
    /// with a bound from the poles that covers what dense evaluation finds and is rounding.
    #[test]
    fn arcs_between_breakpoints_are_slices_of_the_net() {
        let tau = 2.0 * std::f64::consts::PI;
        let half = 0.5 * std::f64::consts::PI;
        let (s, _) = sphere(&frame(), 5.0, (0.0, tau), (-half, half)).unwrap();
        let size = bounding_box_diagonal(s.control_points().as_slice());
        let ((u0, u1), (v0, v1)) = s.domain();
        let (qu, vm) = (u0 + 0.25 * (u1 - u0), 0.5 * (v0 + v1));
        let meridian = s.iso_u(qu).unwrap().piece(v0, vm).unwrap();
        let parallel = s
            .iso_v(vm)
            .unwrap()
            .piece(qu, u0 + 0.5 * (u1 - u0))
            .unwrap();
        for arc in [meridian, parallel] {
            for edge in [
                arc.reparameterize(10.0, 20.0).unwrap(),
                arc.reverse().unwrap(),
            ] {
                let found = net_row(&s, &edge, edge.domain(), size).expect("a slice of a row");
                assert!(matches!(found.along, Along::Bound(Some(_))));
                let (a, b) = edge.domain();
                let range = (a + 0.2 * (b - a), b);
                let p = exact_pcurve(&s, None, &edge, range, 1e-9).expect("exact");
                assert_eq!(p.method, PcurveMethod::Iso);
                assert!(p.deviation <= EXACT * size, "{:e}", p.deviation);
                let mut worst: f64 = 0.0;
                for k in 0..=400 {
                    let t = range.0 + (range.1 - range.0) * f64::from(k) / 400.0;
                    worst = worst.max(dist(
                        on_surface(&s, &p.curve, t),
                        edge.point_at_unchecked(t),
                    ));
                }
                assert!(worst <= p.deviation, "{worst:e} {:e}", p.deviation);
            }
        }
    }

    /// The closed-form parameters are not checked where they are used: a map of another
    /// sphere (another centre) must still give no wrong pcurve. Whatever `edge_pcurve`
    /// returns for a meridian and a parallel of the sphere traces the edge within the
    /// deviation it reports (201 evaluations), and that deviation is within the tolerance.
    #[test]
    fn a_wrong_closed_form_map_gives_no_wrong_pcurve() {
        let tau = 2.0 * std::f64::consts::PI;
        let half = 0.5 * std::f64::consts::PI;
        let (s, right) = sphere(&frame(), 5.0, (0.0, tau), (-half, half)).unwrap();
        let mut moved = frame();
        moved.origin = [1.5, 2.0, 3.25];
        let (_, wrong) = sphere(&moved, 4.0, (0.0, tau), (-half, half)).unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        let meridian = s.iso_u(u0 + 0.25 * (u1 - u0)).unwrap();
        let parallel = s.iso_v(v0 + 0.5 * (v1 - v0)).unwrap();
        let tolerance = 1e-6;
        for edge in [&meridian, &parallel] {
            let (a, b) = edge.domain();
            let range = (a + 0.1 * (b - a), a + 0.6 * (b - a));
            let good = edge_pcurve(&s, Some(&right), edge, range, tolerance).unwrap();
            assert_eq!(good.method, PcurveMethod::Iso);
            let Ok(p) = edge_pcurve(&s, Some(&wrong), edge, range, tolerance) else {
                continue;
            };
            assert!(p.deviation <= tolerance, "{:e}", p.deviation);
            for k in 0..=200 {
                let t = range.0 + (range.1 - range.0) * f64::from(k) / 200.0;
                let d = dist(on_surface(&s, &p.curve, t), edge.point_at_unchecked(t));
                assert!(
                    d <= p.deviation.max(1e-14 * 5.0),
                    "{:?} at {t}: {d:e}",
                    p.method
                );
            }
        }
    }

    /// `same_trace`: a pcurve moved from one side of the seam of a closed NURBS cylinder
    /// (exactly closed: its first and last pole columns equal) traces the same points, one
    /// moved by a period on a surface whose seam columns differ does not, and one left where
    /// it was is the same curve. Checked against evaluation of the two traces.
    #[test]
    fn a_pcurve_moved_across_an_exact_seam_traces_the_same_points() {
        let tau = 2.0 * std::f64::consts::PI;
        let (s, _) = cylinder(&frame(), 2.0, (0.0, tau), (0.0, 1.0)).unwrap();
        assert!(s.is_closed_u(0.0));
        let ((u0, u1), (v0, v1)) = s.domain();
        let at = |u: f64| {
            NurbsCurve::with_dimension(
                1,
                vec![0.0, 0.0, 1.0, 1.0],
                vec![[u, v0, 0.0], [u, v1, 0.0]],
                None,
                2,
            )
            .unwrap()
        };
        let (low, high) = (at(u0), at(u1));
        assert!(same_trace(&s, &low, &high));
        assert!(same_trace(&s, &high, &low));
        assert!(same_trace(&s, &low, &low));
        for k in 0..=20 {
            let t = f64::from(k) / 20.0;
            assert_eq!(on_surface(&s, &low, t), on_surface(&s, &high, t));
        }
        // Not across a seam: a line inside the domain moved elsewhere.
        let mid = at(0.5 * (u0 + u1));
        assert!(!same_trace(&s, &mid, &low));
        // A half cylinder is not closed: its two ends are different lines.
        let (half, _) = cylinder(&frame(), 2.0, (0.0, 0.5 * tau), (0.0, 1.0)).unwrap();
        let ((h0, h1), _) = half.domain();
        assert!(!same_trace(&half, &at(h0), &at(h1)));
        assert!(
            dist(
                on_surface(&half, &at(h0), 0.5),
                on_surface(&half, &at(h1), 0.5)
            ) > 1.0
        );
    }

    /// The half cylinder `[h, 2h] x [0, 1]` of the NURBS domain `[0, 2h]` (h its mid
    /// parameter) bounded counter-clockwise is found counter-clockwise; with its seam side
    /// placed at `u = 0` instead of `2h` (one 3-D line, so the loop still closes in space) the
    /// loop crosses itself in `(u, v)` and its orientation is unknown (`None`), never a
    /// flipped face.
    #[test]
    fn a_seam_coedge_on_the_wrong_side_gives_no_orientation() {
        let tau = 2.0 * std::f64::consts::PI;
        let (s, _) = cylinder(&frame(), 2.0, (0.0, tau), (0.0, 1.0)).unwrap();
        let ((u0, u1), _) = s.domain();
        let h = 0.5 * (u0 + u1);
        let line = |a: [f64; 2], b: [f64; 2]| Coedge {
            edge: EdgeId(0),
            forward: true,
            pcurve: Some(
                NurbsCurve::with_dimension(
                    1,
                    vec![0.0, 0.0, 1.0, 1.0],
                    vec![[a[0], a[1], 0.0], [b[0], b[1], 0.0]],
                    None,
                    2,
                )
                .unwrap(),
            ),
            pcurve_deviation: None,
        };
        let with_seam_at = |x: f64| {
            vec![
                line([h, 0.0], [u1, 0.0]),
                line([x, 0.0], [x, 1.0]),
                line([u1, 1.0], [h, 1.0]),
                line([h, 1.0], [h, 0.0]),
            ]
        };
        assert_eq!(loop_counter_clockwise(&s, &with_seam_at(u1)), Some(true));
        assert_eq!(loop_counter_clockwise(&s, &with_seam_at(u0)), None);
    }
}
