//! Adaptive tessellation under a chord tolerance: curves to polylines by the
//! osculating-circle rule (seed 004), surfaces to conforming triangle meshes. Writing them
//! out (OBJ, STL, glTF, pictures) is the pipeline's business (`pipeline::mesh`).
//!
//! ## Curves (seed 004)
//! At a parameter `u` the osculating circle has radius `r = 1 / kappa`,
//! `kappa = |C' x C''| / |C'|^3`. A chord spanning the angle `theta` of that circle has the
//! sagitta `r (1 - cos(theta / 2))`; setting it to the tolerance gives
//! `theta = 2 acos(1 - tol / r)` (computed as `4 asin(sqrt(tol / 2r))`, the same angle
//! without the rounding of `1 - tol / r` to 1 for tiny tolerances), and the parameter step
//! covering one such sector is
//! `du = theta r / |C'(u)|` (arc length over speed). Steps stop at every knot (the
//! curvature may jump there), `theta` is capped at a quarter turn, and a straight piece
//! (`kappa = 0`) takes a quarter of the knot span. The step is computed with `0.8 tol`
//! (the osculating circle is only a local model), and every resulting chord is then
//! *verified* by sampling: any segment whose sampled distance to the curve exceeds `tol`
//! is halved until it passes. Before the walk, a knot span whose control polygon lies
//! within `tol` of the span's chord line and runs forward along it is that one chord,
//! proven without sampling (convex hull and variation diminishing properties, NURBS Book
//! section 4.2; see `span_within_chord`): a line is its two ends, a degree-1 polyline its
//! own vertices, and a straight span inside a curved B-spline one chord.
//!
//! Derivatives: a local A2.3 (DersBasisFuns) + A3.2/A4.2 evaluation of `C'` and `C''`
//! (the shared derivative module is written in parallel; this one can be switched to it).
//!
//! ## Surfaces
//! A global tensor grid of parameters: initially the knot lines, each span cut in `degree`
//! parts; then every cell is split in two triangles (diagonal `(i, j)-(i+1, j+1)`), and a
//! lattice of points in each triangle (barycentric step 1/6: edge midpoints, thirds,
//! centroid) is compared with the surface at the same barycentric parameters. A failing
//! edge marks its whole grid column or row for halving; failing interior points mark both.
//! Refining whole rows and columns keeps the mesh conforming (no T-junctions, no cracks:
//! every interior edge belongs to exactly two triangles).

use std::collections::HashSet;

use super::knots::{find_span, runs};
use super::vector::{cross, dot, norm, sub};
use super::{GeometryError, NurbsCurve, NurbsSurface, Point3};

/// A polyline approximating a curve: `params[k]` maps to `points[k]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Polyline {
    /// Curve parameters, increasing, from the domain start to its end.
    pub params: Vec<f64>,
    /// The curve points at those parameters.
    pub points: Vec<Point3>,
}

/// A triangle mesh approximating a surface.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions (on the surface).
    pub vertices: Vec<Point3>,
    /// The `(u, v)` parameters of each vertex.
    pub params: Vec<[f64; 2]>,
    /// Unit vertex normals: area-weighted average of the adjacent triangles' normals
    /// (zero where all adjacent triangles are degenerate).
    pub normals: Vec<Point3>,
    /// Triangles as vertex index triples, counter-clockwise seen from `S_u x S_v`.
    pub triangles: Vec<[usize; 3]>,
}

/// Most points or vertices [`NurbsCurve::tessellate`] and [`NurbsSurface::tessellate`]
/// produce before they give up; callers with their own limit use the `_within` forms.
pub const MAX_TESSELLATION_POINTS: usize = 4_000_000;

/// What bounds a tessellation: the most points (curves) or vertices (surfaces) it may
/// produce, and a stop test polled at bounded intervals (every [`STOP_POLL`] chords, cells
/// or samples), so a caller can abandon work whose result nobody waits for.
pub struct Budget<'a> {
    /// Most points or vertices.
    pub max_points: usize,
    /// Returns true when the work should stop.
    pub stop: &'a dyn Fn() -> bool,
}

/// How many units of work (chords verified, cells tested, grid points evaluated) pass
/// between two polls of [`Budget::stop`].
pub const STOP_POLL: usize = 1024;

impl Budget<'_> {
    /// Counts one unit of work in `work`; every [`STOP_POLL`] units, asks
    /// [`Budget::stop`].
    fn tick(&self, work: &mut usize) -> Result<(), TessellationError> {
        *work += 1;
        if *work % STOP_POLL == 0 && (self.stop)() {
            return Err(TessellationError::Stopped);
        }
        Ok(())
    }
}

/// Why a bounded tessellation did not finish.
#[derive(Debug, Clone, PartialEq)]
pub enum TessellationError {
    /// Bad tolerance, or intervals at floating-point resolution without meeting it.
    Geometry(GeometryError),
    /// More than [`Budget::max_points`] points or vertices would be needed.
    TooManyPoints {
        /// The limit.
        limit: usize,
    },
    /// [`Budget::stop`] returned true.
    Stopped,
}

impl From<GeometryError> for TessellationError {
    fn from(e: GeometryError) -> Self {
        TessellationError::Geometry(e)
    }
}

/// The old single-error form of a bounded tessellation's failure.
fn as_geometry_error(e: TessellationError, what: &'static str, tolerance: f64) -> GeometryError {
    match e {
        TessellationError::Geometry(g) => g,
        TessellationError::TooManyPoints { .. } | TessellationError::Stopped => {
            too_many(what, tolerance)
        }
    }
}

/// A budget of [`MAX_TESSELLATION_POINTS`] that never stops.
fn default_budget() -> Budget<'static> {
    Budget {
        max_points: MAX_TESSELLATION_POINTS,
        stop: &|| false,
    }
}

/// Parameter length of a chord whose sagitta on the osculating circle is `tol`, at a point
/// with speed `speed` and curvature `kappa` (seed 004: `r (1 - cos(theta / 2)) = tol`,
/// written as `2 r sin^2(theta / 4) = tol` so that a tiny `tol / r` does not round to 0),
/// capped at a quarter turn; `None` where the curve is straight or stationary.
fn sagitta_step(speed: f64, kappa: f64, tol: f64) -> Option<f64> {
    if !(speed > 0.0 && speed.is_finite() && kappa > 0.0 && kappa.is_finite()) {
        return None;
    }
    let radius = 1.0 / kappa;
    let quarter = std::f64::consts::FRAC_PI_2;
    let theta = (4.0 * (tol / (2.0 * radius)).sqrt().min(1.0).asin()).min(quarter);
    let du = theta * radius / speed;
    (du.is_finite() && du > 0.0).then_some(du)
}

/// Samples taken per knot span by the a-priori estimates, and the most samples in all.
const ESTIMATE_SAMPLES_PER_SPAN: usize = 16;
const ESTIMATE_SAMPLES: usize = 1 << 16;

/// Sample parameters for an estimate over `breaks` (the distinct knots of the domain):
/// `(u, du)` pairs, `du` the parameter length each sample stands for. At most
/// [`ESTIMATE_SAMPLES`] (plus one per span when spans are fewer) whatever the knot count:
/// when spans outnumber the budget, every k-th span is sampled and stands for k spans.
fn estimate_samples(breaks: &[f64]) -> Vec<(f64, f64)> {
    let spans = breaks.len().saturating_sub(1);
    if spans == 0 {
        return Vec::new();
    }
    let per_span = (ESTIMATE_SAMPLES / spans).clamp(1, ESTIMATE_SAMPLES_PER_SPAN);
    let stride = spans.div_ceil(ESTIMATE_SAMPLES).max(1);
    let mut out = Vec::new();
    for w in breaks.windows(2).step_by(stride) {
        let h = (w[1] - w[0]) / per_span as f64;
        for k in 0..per_span {
            out.push((w[0] + h * (k as f64 + 0.5), h * stride as f64));
        }
    }
    out
}

/// The distinct knots inside the domain, with both domain ends.
fn domain_breaks(knots: &[f64], (a, b): (f64, f64)) -> Vec<f64> {
    let mut breaks: Vec<f64> = runs(knots)
        .map(|(_, v, _)| v)
        .filter(|&v| v > a && v < b)
        .collect();
    breaks.insert(0, a);
    breaks.push(b);
    breaks
}

/// Chords needed along one parameter direction by the osculating-circle rule: the integral
/// of `du / step(u)` over the samples, with one chord per span at least.
fn chords_along(samples: &[(f64, f64)], spans: usize, step: impl Fn(f64) -> Option<f64>) -> f64 {
    let walked: f64 = samples
        .iter()
        .map(|&(u, du)| step(u).map_or(0.0, |s| du / s))
        .sum();
    walked.max(spans as f64)
}

/// Distance from `x` to the segment `[a, b]`.
pub fn point_segment_distance(x: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 {
        (dot(sub(x, a), ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(
        x,
        [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]],
    ))
}

fn check_tolerance(tolerance: f64) -> Result<(), GeometryError> {
    if tolerance.is_finite() && tolerance > 0.0 {
        Ok(())
    } else {
        Err(GeometryError::InvalidArgument(format!(
            "tessellation: tolerance {tolerance} must be finite and > 0"
        )))
    }
}

/// Basis functions and their first two derivatives (NURBS Book A2.3 DersBasisFuns with
/// `n = min(2, p)`): `ders[k][j]` is the k-th derivative of `N_{span-p+j,p}(u)`.
// Index loops mirror the NURBS Book pseudo-code line by line, which is how they are checked.
#[allow(clippy::needless_range_loop)]
fn ders_basis_2(span: usize, u: f64, p: usize, knots: &[f64]) -> [Vec<f64>; 3] {
    let n = p.min(2);
    let w = p + 1;
    let mut ndu = vec![0.0; w * w];
    let mut left = vec![0.0; w];
    let mut right = vec![0.0; w];
    ndu[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j * w + r] = right[r + 1] + left[j - r];
            let temp = ndu[r * w + j - 1] / ndu[j * w + r];
            ndu[r * w + j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j * w + j] = saved;
    }
    let mut ders = [vec![0.0; w], vec![0.0; w], vec![0.0; w]];
    for j in 0..=p {
        ders[0][j] = ndu[j * w + p];
    }
    let mut a = [vec![0.0; w], vec![0.0; w]];
    let pi = p as isize;
    for r in 0..=p {
        let ri = r as isize;
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=n {
            let ki = k as isize;
            let mut d = 0.0;
            let rk = ri - ki;
            let pk = pi - ki;
            if ri >= ki {
                a[s2][0] = a[s1][0] / ndu[(pk + 1) as usize * w + rk as usize];
                d = a[s2][0] * ndu[rk as usize * w + pk as usize];
            }
            let j1: isize = if rk >= -1 { 1 } else { -rk };
            let j2: isize = if ri - 1 <= pk { ki - 1 } else { pi - ri };
            for j in j1..=j2 {
                let ju = j as usize;
                a[s2][ju] =
                    (a[s1][ju] - a[s1][ju - 1]) / ndu[(pk + 1) as usize * w + (rk + j) as usize];
                d += a[s2][ju] * ndu[(rk + j) as usize * w + pk as usize];
            }
            if ri <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[(pk + 1) as usize * w + r];
                d += a[s2][k] * ndu[r * w + pk as usize];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut f = p as f64;
    for k in 1..=n {
        for x in ders[k].iter_mut() {
            *x *= f;
        }
        f *= (p - k) as f64;
    }
    ders
}

/// `C(u)`, `C'(u)`, `C''(u)` (A3.2 on homogeneous poles, then A4.2's quotient rule).
fn curve_ders_2(c: &NurbsCurve, u: f64) -> [Point3; 3] {
    let p = c.degree();
    let span = find_span(p, c.num_poles(), c.knots(), u);
    let ders = ders_basis_2(span, u, p, c.knots());
    let mut h = [[0.0f64; 4]; 3];
    for (k, dk) in ders.iter().enumerate() {
        for (j, nj) in dk.iter().enumerate() {
            let i = span - p + j;
            let q = c.control_points()[i];
            let wi = c.weight(i);
            h[k][0] += nj * wi * q[0];
            h[k][1] += nj * wi * q[1];
            h[k][2] += nj * wi * q[2];
            h[k][3] += nj * wi;
        }
    }
    let w = h[0][3];
    let c0: Point3 = std::array::from_fn(|i| h[0][i] / w);
    let c1: Point3 = std::array::from_fn(|i| (h[1][i] - h[1][3] * c0[i]) / w);
    let c2: Point3 =
        std::array::from_fn(|i| (h[2][i] - 2.0 * h[1][3] * c1[i] - h[2][3] * c0[i]) / w);
    [c0, c1, c2]
}

/// The osculating-circle parameter step at `u` (seed 004, [`sagitta_step`]), or `None` for
/// a straight or stationary point.
fn osculating_step(c: &NurbsCurve, u: f64, tol: f64) -> Option<f64> {
    let [_, d1, d2] = curve_ders_2(c, u);
    let speed = norm(d1);
    sagitta_step(speed, norm(cross(d1, d2)) / (speed * speed * speed), tol)
}

fn too_many(what: &'static str, tolerance: f64) -> GeometryError {
    GeometryError::ToleranceExceeded {
        what,
        bound: f64::INFINITY,
        tolerance,
    }
}

/// Interior samples per segment used to verify a chord.
const CHORD_SAMPLES: usize = 15;

/// Golden-section iterations that sharpen the largest sampled chord distance.
const GOLDEN_STEPS: usize = 24;

/// Largest distance between the curve on `[u0, u1]` and the chord: the best of
/// [`CHORD_SAMPLES`] evenly spaced samples, then refined by a golden-section search on the
/// two sample intervals around it (the distance is unimodal there once the samples resolve
/// the curve), so a maximum falling between samples is not missed.
fn chord_error(c: &NurbsCurve, u0: f64, p0: Point3, u1: f64, p1: Point3) -> f64 {
    let h = (u1 - u0) / (CHORD_SAMPLES + 1) as f64;
    let f = |s: f64| point_segment_distance(c.point_at_unchecked(s), p0, p1);
    let (mut best_k, mut best) = (1, f64::NEG_INFINITY);
    for k in 1..=CHORD_SAMPLES {
        let d = f(u0 + h * k as f64);
        if d > best {
            best = d;
            best_k = k;
        }
    }
    let (mut lo, mut hi) = (u0 + h * (best_k - 1) as f64, u0 + h * (best_k + 1) as f64);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..GOLDEN_STEPS {
        if f1 < f2 {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        } else {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        }
    }
    best.max(f1).max(f2)
}

/// Whether the piece of `c` over the knot span `[k0, k1]` lies within `tol` of its chord
/// `C(k0) C(k1)`, decided from the span's `p + 1` poles (weights are positive):
/// - by the strong convex hull property (NURBS Book section 4.2) the piece lies in the
///   poles' convex hull, so its distance to the chord's line is at most the largest pole's;
/// - when the poles' projections on the chord run forward, so do the piece's (the span's
///   Bezier poles are convex combinations of consecutive poles, knot insertion A5.1, and a
///   Bezier piece crosses a plane no more often than its polygon: variation diminishing,
///   section 4.2), so the piece stays between the chord's ends and its distance to the
///   chord is its distance to the line.
///
/// A straight span (collinear poles in order) passes whatever the tolerance.
fn span_within_chord(c: &NurbsCurve, k0: f64, k1: f64, tol: f64) -> bool {
    let p = c.degree();
    let poles = c.control_points();
    let span = find_span(p, poles.len(), c.knots(), k0);
    let Some(hull) = span.checked_sub(p).and_then(|lo| poles.get(lo..=span)) else {
        return false;
    };
    let (p0, p1) = (c.point_at_unchecked(k0), c.point_at_unchecked(k1));
    let d = sub(p1, p0);
    let len = norm(d);
    if !(len > 0.0 && len.is_finite()) {
        return false;
    }
    let off_line = |q: Point3| norm(cross(sub(q, p0), d)) / len;
    hull.iter().all(|&q| off_line(q) <= tol)
        && hull.windows(2).all(|w| dot(sub(w[1], w[0]), d) >= 0.0)
}

impl NurbsCurve {
    /// A polyline within `tolerance` of the curve (chord error: the distance from the curve
    /// on each parameter interval to its chord, verified by sampling), by the
    /// osculating-circle rule of seed 004 (see the module notes). Both domain ends and
    /// every knot inside the domain are polyline vertices; a knot span whose poles lie
    /// within `tolerance` of its chord (a straight span) adds no other vertex.
    ///
    /// Errors: `tolerance` not finite and positive ([`GeometryError::InvalidArgument`]);
    /// more than [`MAX_TESSELLATION_POINTS`] needed ([`GeometryError::ToleranceExceeded`]).
    pub fn tessellate(&self, tolerance: f64) -> Result<Polyline, GeometryError> {
        self.tessellate_within(tolerance, &default_budget())
            .map_err(|e| as_geometry_error(e, "curve tessellation", tolerance))
    }

    /// The points a tessellation under `tolerance` needs, estimated before the work: the
    /// osculating-circle rule (seed 004) integrated over samples of the curvature,
    /// `sum du / step(u)` with `step` the parameter length of a chord of sagitta
    /// `tolerance`, at least one chord per knot span. The rule the tessellation walks with
    /// (at 0.8 `tolerance`, then halving chords that fail) takes more points than this on
    /// smooth curves, so an estimate above a limit means the work would exceed it too;
    /// the exception is a span whose poles lie within `tolerance` of its chord, which the
    /// work takes as one chord while the estimate may count more (an S-bend within the
    /// tolerance): there the estimate errs high.
    /// Costs at most about 65 000 evaluations whatever the size of the curve.
    pub fn tessellation_estimate(&self, tolerance: f64) -> f64 {
        let breaks = domain_breaks(self.knots(), self.domain());
        let samples = estimate_samples(&breaks);
        let chords = chords_along(&samples, breaks.len() - 1, |u| {
            osculating_step(self, u, tolerance)
        });
        chords + 1.0
    }

    /// [`NurbsCurve::tessellate`] under a [`Budget`]: stops with
    /// [`TessellationError::TooManyPoints`] past `budget.max_points` and with
    /// [`TessellationError::Stopped`] when `budget.stop` says so (polled every
    /// [`STOP_POLL`] steps).
    pub fn tessellate_within(
        &self,
        tolerance: f64,
        budget: &Budget<'_>,
    ) -> Result<Polyline, TessellationError> {
        check_tolerance(tolerance)?;
        let (a, b) = self.domain();
        let breaks = domain_breaks(self.knots(), (a, b));
        let too_many = || TessellationError::TooManyPoints {
            limit: budget.max_points,
        };
        let mut work = 0usize;
        let mut poll = || budget.tick(&mut work);
        let step_tol = 0.8 * tolerance;
        // 1. Osculating-circle steps, span by span; a span whose control polygon lies
        //    within the tolerance of its chord is that one chord (`true`: already proven).
        let mut params: Vec<(f64, bool)> = vec![(a, true)];
        for w in breaks.windows(2) {
            let (k0, k1) = (w[0], w[1]);
            if span_within_chord(self, k0, k1, tolerance) {
                params.push((k1, true));
                if params.len() > budget.max_points {
                    return Err(too_many());
                }
                continue;
            }
            let mut u = k0;
            loop {
                let du = osculating_step(self, u, step_tol)
                    .unwrap_or(0.25 * (k1 - k0))
                    .min(0.25 * (k1 - k0))
                    // A floor so that a huge curvature cannot stall the walk; the
                    // verification below refines where this is too coarse.
                    .max((k1 - k0) * 1e-9);
                if u + du >= k1 {
                    break;
                }
                if u + 1.5 * du >= k1 {
                    // Balance the last two steps instead of leaving a sliver.
                    params.push((u + 0.5 * (k1 - u), false));
                    break;
                }
                u += du;
                params.push((u, false));
                if params.len() > budget.max_points {
                    return Err(too_many());
                }
                poll()?;
            }
            params.push((k1, false));
            if params.len() > budget.max_points {
                return Err(too_many());
            }
        }
        // 2. Verify every chord; halve the failing ones (explicit stack, no recursion).
        let min_du = (b - a) * 1e-12;
        let mut out = Polyline {
            params: vec![a],
            points: vec![self.point_at_unchecked(a)],
        };
        let mut stack: Vec<(f64, Point3)> = Vec::new();
        for &(u1, proven) in &params[1..] {
            if proven {
                out.params.push(u1);
                out.points.push(self.point_at_unchecked(u1));
                continue;
            }
            stack.push((u1, self.point_at_unchecked(u1)));
            while let Some(&(ue, pe)) = stack.last() {
                let (us, ps) = match (out.params.last(), out.points.last()) {
                    (Some(&u), Some(&p)) => (u, p),
                    _ => break,
                };
                if ue - us > min_du && chord_error(self, us, ps, ue, pe) > tolerance {
                    let um = us + 0.5 * (ue - us);
                    stack.push((um, self.point_at_unchecked(um)));
                } else {
                    out.params.push(ue);
                    out.points.push(pe);
                    stack.pop();
                }
                if out.params.len() + stack.len() > budget.max_points {
                    return Err(too_many());
                }
                poll()?;
            }
        }
        Ok(out)
    }
}

/// Barycentric lattice step for the surface flatness test (1/6: contains edge midpoints,
/// edge thirds and the centroid).
const LATTICE: usize = 6;

/// Which grid intervals must be halved, from the lattice test on one cell's two triangles.
struct CellVerdict {
    split_u: bool,
    split_v: bool,
}

fn lerp3(p: [Point3; 3], w: [f64; 3]) -> Point3 {
    std::array::from_fn(|k| w[0] * p[0][k] + w[1] * p[1][k] + w[2] * p[2][k])
}

/// Tests the two triangles of cell `[u0, u1] x [v0, v1]` with corners `c[i][j]`.
fn test_cell(
    s: &NurbsSurface,
    (u0, u1): (f64, f64),
    (v0, v1): (f64, f64),
    c: [[Point3; 2]; 2],
    tol: f64,
) -> CellVerdict {
    // Triangles (00, 10, 11) and (00, 11, 01) in parameter and model space.
    let tris = [
        ([(u0, v0), (u1, v0), (u1, v1)], [c[0][0], c[1][0], c[1][1]]),
        ([(u0, v0), (u1, v1), (u0, v1)], [c[0][0], c[1][1], c[0][1]]),
    ];
    let mut verdict = CellVerdict {
        split_u: false,
        split_v: false,
    };
    let n = LATTICE;
    for (t, (uv, pts)) in tris.iter().enumerate() {
        for i in 0..=n {
            for j in 0..=(n - i) {
                let k = n - i - j;
                if i == n || j == n || k == n {
                    continue; // a vertex
                }
                let w = [
                    i as f64 / n as f64,
                    j as f64 / n as f64,
                    k as f64 / n as f64,
                ];
                let u = w[0] * uv[0].0 + w[1] * uv[1].0 + w[2] * uv[2].0;
                let v = w[0] * uv[0].1 + w[1] * uv[1].1 + w[2] * uv[2].1;
                let err = norm(sub(
                    s.point_at_unchecked(u.clamp(u0, u1), v.clamp(v0, v1)),
                    lerp3(*pts, w),
                ));
                if err <= tol {
                    continue;
                }
                // Classify the point: on a u edge (constant v), a v edge (constant u), or
                // inside / on the diagonal.
                let (uc, vc) = match t {
                    // Triangle 0: edge 00-10 is a u edge (k = 0 means the point is on
                    // the edge opposite vertex 2, i.e. 00-10).
                    0 => (k == 0, i == 0),
                    // Triangle 1: edge 11-01 (i = 0) is a u edge; edge 01-00 (j = 0) a
                    // v edge.
                    _ => (i == 0, j == 0),
                };
                if uc {
                    verdict.split_u = true;
                } else if vc {
                    verdict.split_v = true;
                } else {
                    verdict.split_u = true;
                    verdict.split_v = true;
                }
            }
        }
    }
    verdict
}

/// Distinct knots of the domain, each span cut into `parts` pieces.
fn initial_params(knots: &[f64], (a, b): (f64, f64), parts: usize) -> Vec<f64> {
    let ks = domain_breaks(knots, (a, b));
    let mut out = vec![a];
    for w in ks.windows(2) {
        for k in 1..parts {
            out.push(w[0] + (w[1] - w[0]) * k as f64 / parts as f64);
        }
        out.push(w[1]);
    }
    out
}

impl NurbsSurface {
    /// A conforming triangle mesh within `tolerance` of the surface (see the module notes):
    /// every vertex lies on the surface, and at every lattice point of every triangle
    /// (edge midpoints and thirds, centroid, ...) the flat triangle is within `tolerance` of
    /// the surface point at the same parameters.
    ///
    /// Errors: bad tolerance ([`GeometryError::InvalidArgument`]); more than
    /// [`MAX_TESSELLATION_POINTS`] vertices needed ([`GeometryError::ToleranceExceeded`]).
    pub fn tessellate(&self, tolerance: f64) -> Result<Mesh, GeometryError> {
        self.tessellate_within(tolerance, &default_budget())
            .map_err(|e| as_geometry_error(e, "surface tessellation", tolerance))
    }

    /// The vertices a tessellation under `tolerance` needs, estimated before the work: the
    /// mesh is a tensor grid, so the estimate is the product of the chords needed along u
    /// and along v ([`NurbsCurve::tessellation_estimate`]'s rule on the iso-parameter
    /// curves, with the curvature of `S_u`, `S_uu` (and `S_v`, `S_vv`), the largest over
    /// 9 iso-curves each way) plus one. A lower bound in practice: the mesher also halves
    /// the other direction where a cell's interior fails, up to about 10 times more
    /// vertices on a cylinder. Costs at most about 2 × 9 × 65 000 evaluations.
    pub fn tessellation_estimate(&self, tolerance: f64) -> f64 {
        let ((u0, u1), (v0, v1)) = self.domain();
        let ubreaks = domain_breaks(self.knots_u(), (u0, u1));
        let vbreaks = domain_breaks(self.knots_v(), (v0, v1));
        let (us, vs) = (estimate_samples(&ubreaks), estimate_samples(&vbreaks));
        let step = |d1: Point3, d2: Point3| {
            let speed = norm(d1);
            sagitta_step(
                speed,
                norm(cross(d1, d2)) / (speed * speed * speed),
                tolerance,
            )
        };
        let across = |k: usize, lo: f64, hi: f64| lo + (hi - lo) * k as f64 / 8.0;
        let mut nu: f64 = 0.0;
        let mut nv: f64 = 0.0;
        for k in 0..=8 {
            let v = across(k, v0, v1);
            nu = nu.max(chords_along(&us, ubreaks.len() - 1, |u| {
                let d = self.derivatives(u, v, 2).ok()?;
                step(d[1][0], d[2][0])
            }));
            let u = across(k, u0, u1);
            nv = nv.max(chords_along(&vs, vbreaks.len() - 1, |v| {
                let d = self.derivatives(u, v, 2).ok()?;
                step(d[0][1], d[0][2])
            }));
        }
        (nu + 1.0) * (nv + 1.0)
    }

    /// [`NurbsSurface::tessellate`] under a [`Budget`] (see
    /// [`NurbsCurve::tessellate_within`]; the stop test is polled every [`STOP_POLL`]
    /// cells tested or grid points evaluated).
    pub fn tessellate_within(
        &self,
        tolerance: f64,
        budget: &Budget<'_>,
    ) -> Result<Mesh, TessellationError> {
        check_tolerance(tolerance)?;
        let mut work = 0usize;
        let mut poll = || budget.tick(&mut work);
        let (du, dv) = self.domain();
        let mut us = initial_params(self.knots_u(), du, self.degree_u());
        let mut vs = initial_params(self.knots_v(), dv, self.degree_v());
        let mut grid: Vec<Point3>;
        // Cells (by their exact parameter bounds) that already passed the test.
        let mut passed: HashSet<[u64; 4]> = HashSet::new();
        loop {
            let (nu, nv) = (us.len(), vs.len());
            if nu.saturating_mul(nv) > budget.max_points {
                return Err(TessellationError::TooManyPoints {
                    limit: budget.max_points,
                });
            }
            grid = Vec::with_capacity(nu * nv);
            for &u in &us {
                for &v in &vs {
                    grid.push(self.point_at_unchecked(u, v));
                    poll()?;
                }
            }
            let mut split_u = vec![false; nu - 1];
            let mut split_v = vec![false; nv - 1];
            for i in 0..nu - 1 {
                for j in 0..nv - 1 {
                    let key = [us[i], us[i + 1], vs[j], vs[j + 1]].map(f64::to_bits);
                    if passed.contains(&key) {
                        continue; // unchanged since it last passed
                    }
                    poll()?;
                    let c = [
                        [grid[i * nv + j], grid[i * nv + j + 1]],
                        [grid[(i + 1) * nv + j], grid[(i + 1) * nv + j + 1]],
                    ];
                    let verdict =
                        test_cell(self, (us[i], us[i + 1]), (vs[j], vs[j + 1]), c, tolerance);
                    if !(verdict.split_u || verdict.split_v) {
                        passed.insert(key);
                    }
                    split_u[i] |= verdict.split_u;
                    split_v[j] |= verdict.split_v;
                }
            }
            if !split_u.contains(&true) && !split_v.contains(&true) {
                break;
            }
            let (nus, nvs) = (refine(&us, &split_u), refine(&vs, &split_v));
            if nus.len() == us.len() && nvs.len() == vs.len() {
                // Intervals at floating-point resolution: no further progress possible.
                return Err(too_many("surface tessellation", tolerance).into());
            }
            us = nus;
            vs = nvs;
        }
        // The mesh below takes 112 bytes a vertex; the set of cells that passed, up to 66 more.
        drop(passed);
        let (nu, nv) = (us.len(), vs.len());
        let mut mesh = Mesh {
            params: us
                .iter()
                .flat_map(|&u| vs.iter().map(move |&v| [u, v]))
                .collect(),
            vertices: grid,
            normals: Vec::new(),
            triangles: Vec::with_capacity(2 * (nu - 1) * (nv - 1)),
        };
        for i in 0..nu - 1 {
            for j in 0..nv - 1 {
                let (a, b) = (i * nv + j, (i + 1) * nv + j);
                mesh.triangles.push([a, b, b + 1]);
                mesh.triangles.push([a, b + 1, a + 1]);
            }
        }
        mesh.normals = vertex_normals(&mesh.vertices, &mesh.triangles);
        Ok(mesh)
    }
}

/// Halves the flagged intervals of a parameter list.
fn refine(ts: &[f64], split: &[bool]) -> Vec<f64> {
    let mut out = Vec::with_capacity(ts.len() * 2);
    out.push(ts[0]);
    for (k, w) in ts.windows(2).enumerate() {
        let mid = w[0] + 0.5 * (w[1] - w[0]);
        if split.get(k).copied().unwrap_or(false) && mid > w[0] && mid < w[1] {
            out.push(mid);
        }
        out.push(w[1]);
    }
    out
}

/// Area-weighted vertex normals.
fn vertex_normals(vertices: &[Point3], triangles: &[[usize; 3]]) -> Vec<Point3> {
    let mut acc = vec![[0.0; 3]; vertices.len()];
    for t in triangles {
        let n = cross(
            sub(vertices[t[1]], vertices[t[0]]),
            sub(vertices[t[2]], vertices[t[0]]),
        );
        for &v in t {
            for k in 0..3 {
                acc[v][k] += n[k];
            }
        }
    }
    for n in &mut acc {
        let l = norm(*n);
        if l > 0.0 {
            *n = [n[0] / l, n[1] / l, n[2] / l];
        }
    }
    acc
}
