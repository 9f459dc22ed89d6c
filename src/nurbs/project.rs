//! # Points and curves onto surfaces
//!
//! - [`invert_curve`]: the parameter of the curve point closest to a given point (NURBS
//!   Book section 6.1, eqs. 6.3 to 6.5).
//! - [`invert_surface`]: the parameters `(u, v)` of the surface point closest to a given
//!   point, by Newton iteration on `f = r . S_u = 0`, `g = r . S_v = 0` with
//!   `r = S(u, v) - P` (NURBS Book section 6.1, eqs. 6.6 to 6.8), started from the caller's
//!   guess or from the best point of a sampling of every knot span.
//! - [`pcurve_by_projection`]: the parameter-space image of a 3-D curve that lies on a
//!   surface (the pcurve of ISO 10303-42 clause 4.4.2 / the IGES 142 BPTR curve), as a 2-D
//!   polynomial B-spline parameterised like the 3-D curve: the curve's points at its own
//!   parameters are inverted, a cubic is interpolated through their images (A9.1 at the
//!   given parameters), and the sampling is doubled until the surface point of the pcurve
//!   lies within the tolerance of the curve. The deviation reached is returned: it is a
//!   measured figure, never assumed.

use super::fit::{MAX_FIT_POINTS, interpolate_at};
use super::vector::{dist, dot, norm, sub};
use super::{GeometryError, NurbsCurve, NurbsSurface, Point3};

/// Where a point lands on a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inversion {
    /// Parameter in u.
    pub u: f64,
    /// Parameter in v.
    pub v: f64,
    /// Distance from the point to `S(u, v)`.
    pub distance: f64,
}

/// Newton steps before giving up (each step at least halves the error near a solution).
const MAX_NEWTON: usize = 40;
/// Samples per knot span and direction in the start search.
const START_SAMPLES: usize = 4;
/// Largest start grid per direction (files with many spans are sampled more coarsely).
const MAX_START_GRID: usize = 96;

fn clamp_to(x: f64, (a, b): (f64, f64)) -> f64 {
    x.clamp(a, b)
}

/// Sample parameters of one direction: the distinct knots of the domain and
/// `START_SAMPLES - 1` points inside each span, at most `MAX_START_GRID`.
fn start_parameters(knots: &[f64], p: usize, (a, b): (f64, f64)) -> Vec<f64> {
    let mut breaks: Vec<f64> = knots[p..knots.len() - p]
        .iter()
        .copied()
        .filter(|&k| k >= a && k <= b)
        .collect();
    breaks.dedup();
    let spans = breaks.len().saturating_sub(1).max(1);
    let per = (MAX_START_GRID / spans).clamp(1, START_SAMPLES);
    if spans * per > MAX_START_GRID || breaks.len() < 2 {
        let n = MAX_START_GRID;
        return (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
    }
    let mut out = Vec::with_capacity(spans * per + 1);
    for w in breaks.windows(2) {
        for i in 0..per {
            out.push(w[0] + (w[1] - w[0]) * i as f64 / per as f64);
        }
    }
    out.push(b);
    out
}

/// The parameters of the point of `surface` closest to `point` (NURBS Book section 6.1).
///
/// `guess`: a start (the previous point of a curve being projected); without it the start is
/// the nearest of a sampling of every knot span. Iteration stops when the point is reached
/// (`|r|` below `1e-15` of the surface's size), when `r` is perpendicular to both tangents
/// (cosines below `1e-12`), or when the step no longer moves the point; parameters are kept
/// in the domain. Returns `None` only for a surface whose derivatives are not finite there.
pub fn invert_surface(
    surface: &NurbsSurface,
    point: Point3,
    guess: Option<(f64, f64)>,
) -> Option<Inversion> {
    let (du, dv) = surface.domain();
    let size = surface
        .control_points()
        .as_slice()
        .iter()
        .fold(1.0f64, |m, q| m.max(norm(*q)));
    if let Some((u, v)) = guess {
        return newton(
            surface,
            point,
            (clamp_to(u, du), clamp_to(v, dv)),
            (du, dv),
            size,
        );
    }
    // Newton from the nearest few samples that are distinct points: a degenerate edge
    // (a sphere's pole) is one point for many (u, v), and the nearest sample can be there
    // with a u from which the iteration cannot move.
    let us = start_parameters(surface.knots_u(), surface.degree_u(), du);
    let vs = start_parameters(surface.knots_v(), surface.degree_v(), dv);
    let mut samples: Vec<(f64, f64, f64, Point3)> = Vec::with_capacity(us.len() * vs.len());
    for &u in &us {
        for &v in &vs {
            let q = surface.point_at_unchecked(u, v);
            samples.push((dist(q, point), u, v, q));
        }
    }
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut starts: Vec<(f64, f64, f64, Point3)> = Vec::with_capacity(STARTS);
    for s in samples {
        if starts.len() == STARTS {
            break;
        }
        if starts.iter().all(|t| dist(t.3, s.3) > 1e-12 * size) {
            starts.push(s);
        }
    }
    // A start that lands on the point itself (within the rounding Newton stops at) is a
    // closest point no other start can beat: the rest are not run.
    // A start on the seam of a closed surface is also the same point at the other end of
    // the domain (kept once among the distinct points above); Newton is kept inside the
    // domain, so from one end it cannot reach a point just across the seam: both ends run.
    let other_end = |x: f64, (lo, hi): (f64, f64)| {
        if x == lo {
            Some(hi)
        } else if x == hi {
            Some(lo)
        } else {
            None
        }
    };
    let mut best: Option<Inversion> = None;
    'starts: for &(_, u, v, q) in &starts {
        let across = [
            other_end(u, du).map(|w| (w, v)),
            other_end(v, dv).map(|w| (u, w)),
        ];
        let same_point =
            |(a, b): (f64, f64)| dist(surface.point_at_unchecked(a, b), q) <= 1e-12 * size;
        let tries =
            std::iter::once((u, v)).chain(across.into_iter().flatten().filter(|&x| same_point(x)));
        for start in tries {
            let Some(found) = newton(surface, point, start, (du, dv), size) else {
                continue;
            };
            if best.is_none_or(|b| found.distance < b.distance) {
                best = Some(found);
            }
            if found.distance <= 1e-15 * size {
                break 'starts;
            }
        }
    }
    best
}

/// Where a point lands on a curve: the parameter of the curve point closest to it and the
/// distance (NURBS Book section 6.1, eqs. 6.3 to 6.5: Newton on `f(u) = C'(u) . (C(u) - P)`,
/// started from the nearest of samples of every knot span, parameters kept in the domain).
/// `None` only for a curve whose derivatives are not finite there.
pub fn invert_curve(curve: &NurbsCurve, point: Point3) -> Option<(f64, f64)> {
    let domain = curve.domain();
    let mut samples: Vec<(f64, f64)> = start_parameters(curve.knots(), curve.degree(), domain)
        .into_iter()
        .map(|u| (dist(curve.point_at_unchecked(u), point), u))
        .collect();
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    let size = curve_size(curve);
    let mut best: Option<(f64, f64)> = None;
    for &(_, start) in samples.iter().take(STARTS) {
        let found = curve_newton(curve, point, start, size)?;
        if best.is_none_or(|b| found.1 < b.1) {
            best = Some(found);
        }
        // A start that lands on the point (the rounding `curve_newton` stops at) is a
        // closest point no other start can beat: the rest are not run.
        if found.1 <= 1e-15 * size {
            break;
        }
    }
    best
}

/// [`invert_curve`] started at the parameter `start` (the parameter of a nearby point the
/// caller found) instead of a sampling of the curve.
pub fn invert_curve_near(curve: &NurbsCurve, point: Point3, start: f64) -> Option<(f64, f64)> {
    let domain = curve.domain();
    curve_newton(curve, point, clamp_to(start, domain), curve_size(curve))
}

/// The scale of a curve's coordinates for the distance tests of [`curve_newton`]: the
/// largest pole norm, at least 1.
fn curve_size(curve: &NurbsCurve) -> f64 {
    curve
        .control_points()
        .iter()
        .fold(1.0f64, |m, q| m.max(norm(*q)))
}

/// Newton's iteration of [`invert_curve`] from `start`: the best `(u, distance)` it met
/// (`size` from [`curve_size`]).
fn curve_newton(curve: &NurbsCurve, point: Point3, start: f64, size: f64) -> Option<(f64, f64)> {
    let domain = curve.domain();
    let mut best: Option<(f64, f64)> = None;
    let mut u = start;
    for _ in 0..MAX_NEWTON {
        let d = curve.derivatives(u, 2).ok()?;
        let r = sub(d[0], point);
        let distance = norm(r);
        if best.is_none_or(|b| not_farther(distance, b.1)) {
            best = Some((u, distance));
        }
        let f = dot(d[1], r);
        // Eq. 6.4: zero distance, or r perpendicular to the tangent.
        if distance <= 1e-15 * size || f.abs() <= 1e-12 * norm(d[1]) * distance {
            break;
        }
        // Eq. 6.3: u' = u - f / f', f' = C'' . r + |C'|^2.
        let fp = dot(d[2], r) + dot(d[1], d[1]);
        if fp == 0.0 || !fp.is_finite() {
            break;
        }
        let next = clamp_to(u - f / fp, domain);
        // Eq. 6.5: the parameter no longer moves.
        if (next - u).abs() <= 1e-15 * (domain.1 - domain.0).max(1.0) {
            break;
        }
        u = next;
    }
    best
}

/// Whether a later Newton iterate at distance `d` replaces the best one at `best`: when it
/// is nearer, or as near up to round-off (near a minimum the distance changes only to
/// second order, so the later, better converged parameters are kept).
fn not_farther(d: f64, best: f64) -> bool {
    d <= best * (1.0 + 8.0 * f64::EPSILON)
}

/// Distinct starts of a search without a guess.
const STARTS: usize = 4;

fn newton(
    surface: &NurbsSurface,
    point: Point3,
    (mut u, mut v): (f64, f64),
    (du, dv): ((f64, f64), (f64, f64)),
    size: f64,
) -> Option<Inversion> {
    let eps_point = 1e-15 * size;
    let mut best: Option<Inversion> = None;
    for _ in 0..MAX_NEWTON {
        let skl = surface.derivatives(u, v, 2).ok()?;
        let (s, su, sv) = (skl[0][0], skl[1][0], skl[0][1]);
        let (suu, suv, svv) = (skl[2][0], skl[1][1], skl[0][2]);
        let r = sub(s, point);
        let d = norm(r);
        if best.is_none_or(|b| not_farther(d, b.distance)) {
            best = Some(Inversion { u, v, distance: d });
        }
        let f = dot(r, su);
        let g = dot(r, sv);
        // Eq. 6.8: zero distance, or r perpendicular to both tangents.
        if d <= eps_point || (f.abs() <= 1e-12 * norm(su) * d && g.abs() <= 1e-12 * norm(sv) * d) {
            break;
        }
        // Eq. 6.7: J delta = -kappa.
        let j00 = dot(su, su) + dot(r, suu);
        let j01 = dot(su, sv) + dot(r, suv);
        let j11 = dot(sv, sv) + dot(r, svv);
        let det = j00 * j11 - j01 * j01;
        let (step_u, step_v) = if det.is_finite() && det.abs() > 0.0 {
            ((-j11 * f + j01 * g) / det, (j01 * f - j00 * g) / det)
        } else if j00 > 0.0 && j11 > 0.0 {
            // A degenerate point (a sphere's pole): a step along each tangent alone.
            (-f / j00, -g / j11)
        } else {
            break;
        };
        let (nu, nv) = (clamp_to(u + step_u, du), clamp_to(v + step_v, dv));
        // Eq. 6.8's last test: the step no longer moves the point on the surface.
        let moved = norm([
            (nu - u) * su[0] + (nv - v) * sv[0],
            (nu - u) * su[1] + (nv - v) * sv[1],
            (nu - u) * su[2] + (nv - v) * sv[2],
        ]);
        u = nu;
        v = nv;
        if moved <= eps_point {
            let d = dist(surface.point_at_unchecked(u, v), point);
            if best.is_none_or(|b| d < b.distance) {
                best = Some(Inversion { u, v, distance: d });
            }
            break;
        }
    }
    best
}

/// Whether the surface meets itself along `u = min` and `u = max`, so a point there has two
/// u parameters: clamped ends with the first and last pole columns equal, or (an unclamped
/// periodic B-spline, as an extrusion of a periodic profile) the two boundary isocurves
/// equal at `CLOSURE_SAMPLES` points; both within `within` or rounding. `within` is the
/// caller's tolerance: a surface of revolution written with a rounded angle (IGES 120 with
/// `TA = 6.283185307`) is open by 1e-9 but closed for any curve given within 1e-6.
fn closed_in(surface: &NurbsSurface, along_u: bool, within: f64) -> bool {
    let g = surface.control_points();
    let (n, m) = (g.nu(), g.nv());
    let (knots, p) = if along_u {
        (surface.knots_u(), surface.degree_u())
    } else {
        (surface.knots_v(), surface.degree_v())
    };
    let clamped = knots[..=p].iter().all(|&k| k == knots[0])
        && knots[knots.len() - p - 1..]
            .iter()
            .all(|&k| k == knots[knots.len() - 1]);
    let size = g.as_slice().iter().fold(1.0f64, |a, q| a.max(norm(*q)));
    let gap = within.max(1e-12 * size);
    if clamped {
        return if along_u {
            (0..m).all(|j| dist(*g.get(0, j), *g.get(n - 1, j)) <= gap)
        } else {
            (0..n).all(|i| dist(*g.get(i, 0), *g.get(i, m - 1)) <= gap)
        };
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    (0..=CLOSURE_SAMPLES).all(|k| {
        let x = k as f64 / CLOSURE_SAMPLES as f64;
        let (a, b) = if along_u {
            let v = v0 + (v1 - v0) * x;
            (
                surface.point_at_unchecked(u0, v),
                surface.point_at_unchecked(u1, v),
            )
        } else {
            let u = u0 + (u1 - u0) * x;
            (
                surface.point_at_unchecked(u, v0),
                surface.point_at_unchecked(u, v1),
            )
        };
        dist(a, b) <= gap
    })
}

/// Points along the boundary isocurves at which [`closed_in`] compares an unclamped surface.
const CLOSURE_SAMPLES: usize = 16;

/// Largest number of samples a pcurve is fitted through.
const MAX_PCURVE_SAMPLES: usize = MAX_FIT_POINTS / 2;

/// The 2-D pcurve of the part `range` of `curve` on `surface`: a polynomial B-spline
/// `(u(t), v(t))` over `range` with `surface(pcurve(t))` within `tolerance` of `curve(t)`
/// where that could be reached, and the largest deviation found (checked at the fitted
/// points and midway between them).
///
/// On a surface closed in u or v (a cylinder's seam), the points take the side of the seam
/// that keeps the pcurve continuous and inside the domain (a start or end on the seam, or
/// past it by less than `tolerance`, is put on it). Where
/// the surface is degenerate (a sphere's pole, where every u gives the same point) the
/// parameter that is free there is taken from the neighbours.
///
/// Errors: an empty or non-finite range, a curve that leaves the surface by more than
/// 1e3 x `tolerance`, a curve that crosses a seam (its pcurve would jump), a fit that fails.
pub fn pcurve_by_projection(
    surface: &NurbsSurface,
    curve: &NurbsCurve,
    range: (f64, f64),
    tolerance: f64,
) -> Result<(NurbsCurve, f64), GeometryError> {
    let (a, b) = range;
    let (ca, cb) = curve.domain();
    if !(a.is_finite() && b.is_finite() && a < b && a >= ca && b <= cb && tolerance > 0.0) {
        return Err(GeometryError::InvalidArgument(format!(
            "pcurve range [{a}, {b}] is not an increasing part of the curve's domain [{ca}, {cb}] \
             or the tolerance {tolerance} is not positive"
        )));
    }
    let mut breaks: Vec<f64> = std::iter::once(a)
        .chain(curve.knots().iter().copied().filter(|&k| k > a && k < b))
        .chain(std::iter::once(b))
        .collect();
    breaks.dedup();
    // Where the curve is less than C2 (a knot of multiplicity above p - 2, as the double
    // knots of a rational circle) its pcurve is too, and one cubic through it would converge
    // as h^2: the pcurve is fitted piece by piece between such knots and the pieces joined
    // with a C0 knot (their common end is the same inverted point).
    let p = curve.degree();
    let hard: Vec<bool> = breaks
        .iter()
        .map(|&k| curve.knots().iter().filter(|&&x| x == k).count() + 2 > p)
        .collect();
    let spans = breaks.len() - 1;
    let mut per = (p + 1).max(3);
    loop {
        // The parameters of each piece (consecutive pieces share their end), projected all
        // together so that the whole pcurve takes one side of a seam.
        let mut bounds: Vec<(usize, usize)> = Vec::new();
        let mut all_t: Vec<f64> = vec![a];
        let mut first = 0;
        for last in 1..breaks.len() {
            if last < breaks.len() - 1 && !hard[last] {
                continue;
            }
            let from = all_t.len() - 1;
            all_t.extend(
                breaks[first..=last]
                    .windows(2)
                    .flat_map(|w| {
                        (0..per).map(move |i| w[0] + (w[1] - w[0]) * i as f64 / per as f64)
                    })
                    .skip(1)
                    .chain(std::iter::once(breaks[last])),
            );
            bounds.push((from, all_t.len() - 1));
            first = last;
        }
        let uv = project_points(surface, curve, &all_t, tolerance)?;
        let mut pieces: Vec<NurbsCurve> = Vec::with_capacity(bounds.len());
        for &(from, to) in &bounds {
            pieces.push(interpolate_at(&uv[from..=to], &all_t[from..=to], 3, 2)?);
        }
        let mut pieces = pieces.into_iter();
        let Some(mut pcurve) = pieces.next() else {
            return Err(GeometryError::InvalidArgument("pcurve: empty range".into()));
        };
        for piece in pieces {
            pcurve = pcurve.join(&piece, 1e-9 * (1.0 + norm(piece.control_points()[0])))?;
        }
        let deviation = deviation(surface, curve, &pcurve, &all_t);
        if deviation <= tolerance || spans * per * 2 + 1 > MAX_PCURVE_SAMPLES {
            return Ok((pcurve, deviation));
        }
        per *= 2;
    }
}

/// The images of `curve(t)` for each `t`, continued from point to point.
///
/// On a surface closed in u or v the inverted parameters are unwrapped (each point within
/// half a period of the one before) and the whole sequence is moved by the whole periods
/// that put it inside the domain, where a point past the seam by less than `tolerance` on
/// the surface (`tolerance / |S_u|` in u) is put on the seam: a curve that starts or ends
/// on the seam, or wanders across it by less than the tolerance, gets one continuous
/// pcurve. A sequence that spans more than that crosses the seam (an error).
fn project_points(
    surface: &NurbsSurface,
    curve: &NurbsCurve,
    t: &[f64],
    tolerance: f64,
) -> Result<Vec<Point3>, GeometryError> {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let closed = [
        closed_in(surface, true, tolerance),
        closed_in(surface, false, tolerance),
    ];
    let mut uv: Vec<Point3> = Vec::with_capacity(t.len());
    let mut free: Vec<(bool, bool)> = Vec::with_capacity(t.len());
    // |S_u|, |S_v| at each point: how far a parameter may pass the seam.
    let mut speed: Vec<[f64; 2]> = Vec::with_capacity(t.len());
    let mut previous: Option<(f64, f64)> = None;
    for &ti in t {
        let p = curve.point_at_unchecked(ti);
        let mut hit = invert_surface(surface, p, previous);
        // Newton from the previous point keeps its parameters in the domain: on a closed
        // surface a point just past the seam stops on it, at a distance that may still be
        // within the tolerance of a curve that is not exactly on the surface.
        let stopped_on_seam = |h: &Inversion| {
            (closed[0] && (h.u <= u0 || h.u >= u1)) || (closed[1] && (h.v <= v0 || h.v >= v1))
        };
        // A continued start that stopped in a local minimum (or on the seam): search the
        // whole surface.
        if hit.is_none_or(|h| h.distance > tolerance || stopped_on_seam(&h)) && previous.is_some() {
            let global = invert_surface(surface, p, None);
            if let (Some(g), Some(h)) = (global, hit) {
                if g.distance < h.distance {
                    hit = Some(g);
                }
            } else if hit.is_none() {
                hit = global;
            }
        }
        let Some(h) = hit else {
            return Err(GeometryError::InvalidArgument(format!(
                "the surface cannot be evaluated near the curve point at t = {ti}"
            )));
        };
        if h.distance > 1e3 * tolerance {
            return Err(GeometryError::InvalidArgument(format!(
                "the curve at t = {ti} is {:e} from the surface (tolerance {tolerance:e}): it \
                 does not lie on it",
                h.distance
            )));
        }
        let (u, v) = (h.u, h.v);
        // Degenerate directions: a zero tangent makes that parameter free at this point.
        let skl = surface.derivatives(u, v, 1)?;
        let scale = (u1 - u0).max(v1 - v0);
        let size = norm(skl[0][0]).max(1.0);
        let (su, sv) = (norm(skl[1][0]), norm(skl[0][1]));
        free.push((su * scale <= 1e-9 * size, sv * scale <= 1e-9 * size));
        speed.push([su, sv]);
        uv.push([u, v, 0.0]);
        previous = Some((u, v));
    }
    fill_free(&mut uv, &free);
    for k in [0usize, 1] {
        let (lo, hi) = if k == 0 { (u0, u1) } else { (v0, v1) };
        let period = hi - lo;
        if !closed[k] || period.is_nan() || period <= 0.0 {
            continue;
        }
        let wrap = |x: f64| {
            let y = x.rem_euclid(period);
            if y > period / 2.0 { y - period } else { y }
        };
        for i in 1..uv.len() {
            uv[i][k] = uv[i - 1][k] + wrap(uv[i][k] - uv[i - 1][k]);
        }
        // How far past the domain each point may be: its tolerance in parameter, but never
        // more than rounding for a point where the surface hardly moves.
        let slack: Vec<f64> = speed
            .iter()
            .map(|s| (tolerance / s[k]).min(1e-3 * period).max(1e-12 * period))
            .collect();
        let fits = |shift: f64| {
            uv.iter()
                .zip(&slack)
                .all(|(q, &e)| q[k] + shift >= lo - e && q[k] + shift <= hi + e)
        };
        let min = uv.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min);
        let j = -((min - lo) / period).floor();
        let Some(shift) = [j, j - 1.0, j + 1.0]
            .into_iter()
            .map(|j| j * period)
            .find(|&s| fits(s))
        else {
            return Err(GeometryError::InvalidArgument(
                "the curve crosses the surface's seam: its pcurve would jump".into(),
            ));
        };
        for q in &mut uv {
            q[k] = (q[k] + shift).clamp(lo, hi);
        }
    }
    Ok(uv)
}

/// Where a parameter is free (degenerate point), takes it from the nearest point where it
/// is not; left as found when it is free everywhere.
fn fill_free(uv: &mut [Point3], free: &[(bool, bool)]) {
    for k in [0usize, 1] {
        let is_free = |i: usize| if k == 0 { free[i].0 } else { free[i].1 };
        let fixed: Vec<usize> = (0..uv.len()).filter(|&i| !is_free(i)).collect();
        if fixed.is_empty() {
            continue;
        }
        for i in 0..uv.len() {
            if is_free(i) {
                let nearest = fixed
                    .iter()
                    .copied()
                    .min_by_key(|&j| j.abs_diff(i))
                    .unwrap_or(i);
                uv[i][k] = uv[nearest][k];
            }
        }
    }
}

/// Largest `|surface(pcurve(t)) - curve(t)|` at the fitted parameters and midway between
/// them, evaluated at the nearest parameters inside the surface's domain.
fn deviation(surface: &NurbsSurface, curve: &NurbsCurve, pcurve: &NurbsCurve, t: &[f64]) -> f64 {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let at = |s: f64| {
        let [u, v, _] = pcurve.point_at_unchecked(s);
        dist(
            surface.point_at_unchecked(u.clamp(u0, u1), v.clamp(v0, v1)),
            curve.point_at_unchecked(s),
        )
    };
    let mut worst: f64 = 0.0;
    for (i, &s) in t.iter().enumerate() {
        worst = worst.max(at(s));
        if let Some(&next) = t.get(i + 1) {
            worst = worst.max(at(0.5 * (s + next)));
        }
    }
    if worst.is_nan() { f64::INFINITY } else { worst }
}
