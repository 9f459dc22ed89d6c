//! # Lengths, areas and distances between shapes
//!
//! - [`curve_length`]: `integral |C'(u)| du` and [`surface_area`]:
//!   `integral integral |S_u x S_v| du dv`, by adaptive Gauss-Kronrod quadrature (the
//!   7-point Gauss rule embedded in the 15-point Kronrod rule, per direction for surfaces).
//!   The domain starts cut at every distinct knot (the integrand is smooth inside a span);
//!   the piece with the largest error estimate `|K15 - G7|` is halved until the estimates
//!   add up to at most the requested tolerance, or a piece limit is reached (then the result
//!   says it did not converge, with the estimate reached).
//! - [`directed_distance`]: the largest distance from the points of some curves or surfaces
//!   to the nearest of other curves or surfaces (one side of the Hausdorff distance): each
//!   shape is sampled in every knot span, each sample's nearest samples of the other side
//!   (a k-d tree) start point inversions (NURBS Book section 6.1, `super::project`) on
//!   their shapes, and the largest distances found are refined by a local search. The
//!   result does not depend on how either side is parameterised; it is a sampled estimate
//!   from below (a deviation narrower than the sample spacing can be missed).

use super::project::{invert_curve_near, invert_surface};
use super::vector::{cross, dist, norm};
use super::{GeometryError, NurbsCurve, NurbsSurface, Point3};

/// The most pieces one curve length is cut into.
pub const MAX_LENGTH_PIECES: usize = 4000;
/// The most cells one surface area is cut into.
pub const MAX_AREA_CELLS: usize = 2000;

/// Abscissae of the 15-point Kronrod rule on `[-1, 1]` (the non-negative half, descending;
/// the odd entries are the 7-point Gauss nodes).
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights of [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_18,
    0.140_653_259_715_525_92,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_83,
];
/// Gauss weights of the nodes `XGK[1], XGK[3], XGK[5], XGK[7]`.
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// The 15 nodes on `[-1, 1]` with their Kronrod and Gauss weights (0 for Kronrod-only
/// nodes).
fn rule() -> [(f64, f64, f64); 15] {
    let mut out = [(0.0, 0.0, 0.0); 15];
    for k in 0..7 {
        let g = if k % 2 == 1 { WG[k / 2] } else { 0.0 };
        out[k] = (-XGK[k], WGK[k], g);
        out[14 - k] = (XGK[k], WGK[k], g);
    }
    out[7] = (0.0, WGK[7], WG[3]);
    out
}

/// A measured quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// The value (the Kronrod sums).
    pub value: f64,
    /// The estimate of its error: the sum over the pieces of `|Kronrod - Gauss|`.
    pub error: f64,
    /// Whether `error` reached the requested tolerance.
    pub converged: bool,
    /// How many pieces (curves) or cells (surfaces) the domain was cut into.
    pub pieces: usize,
}

/// One piece of an adaptive integration: its cell, value, error estimate, and what its
/// rule found out about how to cut it.
struct Piece<C, H> {
    cell: C,
    value: f64,
    error: f64,
    hint: H,
}

/// Halves the piece with the largest error until the errors add up to `tolerance` or
/// `max` pieces are reached. `rule(cell)` gives a cell's value, error and a hint for
/// `halve(cell, hint)`, which gives its halves, or `None` when it is too small to cut.
fn adaptive<C: Copy, H: Copy>(
    initial: Vec<C>,
    tolerance: f64,
    max: usize,
    rule: impl Fn(&C) -> Result<(f64, f64, H), GeometryError>,
    halve: impl Fn(&C, H) -> Option<[C; 2]>,
) -> Result<Measured, GeometryError> {
    let piece = |cell: C| -> Result<Piece<C, H>, GeometryError> {
        let (value, error, hint) = rule(&cell)?;
        Ok(Piece {
            cell,
            value,
            error,
            hint,
        })
    };
    let mut pieces = initial
        .into_iter()
        .map(piece)
        .collect::<Result<Vec<_>, GeometryError>>()?;
    loop {
        let error: f64 = pieces.iter().map(|p| p.error).sum();
        let done = |converged: bool, pieces: &[Piece<C, H>]| Measured {
            value: pieces.iter().map(|p| p.value).sum(),
            error,
            converged,
            pieces: pieces.len(),
        };
        if error <= tolerance {
            return Ok(done(true, &pieces));
        }
        if pieces.len() >= max {
            return Ok(done(false, &pieces));
        }
        let Some(worst) =
            (0..pieces.len()).max_by(|&a, &b| pieces[a].error.total_cmp(&pieces[b].error))
        else {
            return Ok(done(false, &pieces));
        };
        let Some([a, b]) = halve(&pieces[worst].cell, pieces[worst].hint) else {
            return Ok(done(false, &pieces));
        };
        pieces[worst] = piece(a)?;
        pieces.push(piece(b)?);
    }
}

/// The distinct knots of the domain `[a, b]` (the spans' ends).
fn breaks(knots: &[f64], p: usize, (a, b): (f64, f64)) -> Vec<f64> {
    let mut out: Vec<f64> = knots[p..knots.len() - p]
        .iter()
        .copied()
        .filter(|&k| k >= a && k <= b)
        .collect();
    out.dedup();
    if out.len() < 2 {
        out = vec![a, b];
    }
    out
}

/// Whether `[a, b]` can still be halved into two intervals of non-zero width.
fn halves(a: f64, b: f64) -> Option<(f64, f64, f64)> {
    let m = 0.5 * (a + b);
    (m > a && m < b).then_some((a, m, b))
}

/// The arc length of a curve, `integral |C'(u)| du` over its domain, to `tolerance`
/// (absolute, model units). Error: a non-positive or non-finite tolerance, or derivatives
/// that cannot be evaluated.
pub fn curve_length(curve: &NurbsCurve, tolerance: f64) -> Result<Measured, GeometryError> {
    check_tolerance(tolerance)?;
    let nodes = rule();
    let spans: Vec<(f64, f64)> = breaks(curve.knots(), curve.degree(), curve.domain())
        .windows(2)
        .map(|w| (w[0], w[1]))
        .collect();
    adaptive(
        spans,
        tolerance,
        MAX_LENGTH_PIECES,
        |&(a, b)| {
            let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
            let (mut k, mut g) = (0.0, 0.0);
            for &(x, wk, wg) in &nodes {
                let d = curve.derivatives(c + h * x, 1)?;
                let speed = norm(d[1]);
                k += wk * speed;
                g += wg * speed;
            }
            Ok((k * h, ((k - g) * h).abs(), ()))
        },
        |&(a, b), ()| halves(a, b).map(|(a, m, b)| [(a, m), (m, b)]),
    )
}

/// The area of a surface, `integral integral |S_u x S_v| du dv` over its domain, to
/// `tolerance` (absolute, model units squared). A cell is halved across the direction
/// whose Gauss rule disagrees more with the Kronrod rule. Errors as [`curve_length`].
pub fn surface_area(surface: &NurbsSurface, tolerance: f64) -> Result<Measured, GeometryError> {
    check_tolerance(tolerance)?;
    let nodes = rule();
    let (du, dv) = surface.domain();
    let bu = breaks(surface.knots_u(), surface.degree_u(), du);
    let bv = breaks(surface.knots_v(), surface.degree_v(), dv);
    let mut cells = Vec::with_capacity((bu.len() - 1) * (bv.len() - 1));
    for wu in bu.windows(2) {
        for wv in bv.windows(2) {
            cells.push((wu[0], wu[1], wv[0], wv[1]));
        }
    }
    adaptive(
        cells,
        tolerance,
        MAX_AREA_CELLS,
        |&(u0, u1, v0, v1)| {
            let (cu, hu) = (0.5 * (u0 + u1), 0.5 * (u1 - u0));
            let (cv, hv) = (0.5 * (v0 + v1), 0.5 * (v1 - v0));
            // Kronrod x Kronrod, Gauss in u x Kronrod in v, Kronrod x Gauss.
            let (mut kk, mut gk, mut kg) = (0.0, 0.0, 0.0);
            for &(x, wku, wgu) in &nodes {
                for &(y, wkv, wgv) in &nodes {
                    let d = surface.derivatives(cu + hu * x, cv + hv * y, 1)?;
                    let f = norm(cross(d[1][0], d[0][1]));
                    kk += wku * wkv * f;
                    gk += wgu * wkv * f;
                    kg += wku * wgv * f;
                }
            }
            let scale = hu * hv;
            let (eu, ev) = (((kk - gk) * scale).abs(), ((kk - kg) * scale).abs());
            Ok((kk * scale, eu + ev, eu >= ev))
        },
        |&(u0, u1, v0, v1), across_u| {
            let cut_u = || halves(u0, u1).map(|(a, m, b)| [(a, m, v0, v1), (m, b, v0, v1)]);
            let cut_v = || halves(v0, v1).map(|(a, m, b)| [(u0, u1, a, m), (u0, u1, m, b)]);
            if across_u {
                cut_u().or_else(cut_v)
            } else {
                cut_v().or_else(cut_u)
            }
        },
    )
}

fn check_tolerance(tolerance: f64) -> Result<(), GeometryError> {
    if tolerance.is_finite() && tolerance > 0.0 {
        Ok(())
    } else {
        Err(GeometryError::InvalidArgument(format!(
            "the tolerance must be positive and finite, got {tolerance}"
        )))
    }
}

/// A curve or surface of one side of a distance.
#[derive(Debug, Clone, Copy)]
pub enum Shape<'a> {
    /// A curve.
    Curve(&'a NurbsCurve),
    /// A surface.
    Surface(&'a NurbsSurface),
}

/// Inversions per sample, from its nearest samples on the other side.
const NEWTON_STARTS: usize = 3;
/// Samples per knot span and direction.
const SPAN_SAMPLES: usize = 8;
/// The most samples of one curve.
const MAX_CURVE_SAMPLES: usize = 256;
/// The most samples per direction of one surface.
const MAX_SURFACE_SAMPLES: usize = 48;
/// The fewest samples of one curve, and per direction of one surface.
const MIN_SAMPLES: usize = 32;
/// The samples of one side of a distance: above it, every shape is sampled more coarsely
/// (down to [`FLOOR_SAMPLES`] per direction).
const MAX_SIDE_SAMPLES: usize = 100_000;
/// The fewest samples per direction when a side is sampled coarsely.
const FLOOR_SAMPLES: usize = 5;

/// Sample parameters of one direction: `SPAN_SAMPLES` per knot span, at least
/// `MIN_SAMPLES.min(max)` and at most `max` in all (plus the end), every knot among them
/// when there is room.
fn sample_parameters(knots: &[f64], p: usize, domain: (f64, f64), max: usize) -> Vec<f64> {
    let b = breaks(knots, p, domain);
    let spans = b.len() - 1;
    let per = SPAN_SAMPLES.max(MIN_SAMPLES.min(max).div_ceil(spans));
    if spans * per > max {
        return (0..=max)
            .map(|i| domain.0 + (domain.1 - domain.0) * i as f64 / max as f64)
            .collect();
    }
    let mut out = Vec::with_capacity(spans * per + 1);
    for w in b.windows(2) {
        for i in 0..per {
            out.push(w[0] + (w[1] - w[0]) * i as f64 / per as f64);
        }
    }
    out.push(domain.1);
    out
}

/// A sample: the shape's index, its parameters, the point, and the parameter distance to
/// its farther neighbour sample in each direction (the span a refinement searches).
#[derive(Debug, Clone, Copy)]
struct Sample {
    shape: usize,
    at: (f64, f64),
    point: Point3,
    step: (f64, f64),
}

/// The parameter distance from `ps[i]` to its farther neighbour.
fn step_at(ps: &[f64], i: usize) -> f64 {
    let before = if i > 0 { ps[i] - ps[i - 1] } else { 0.0 };
    let after = ps.get(i + 1).map_or(0.0, |n| n - ps[i]);
    before.max(after)
}

/// The samples of some shapes: [`sample_parameters`] in every direction, more coarsely
/// when the full sampling would exceed [`MAX_SIDE_SAMPLES`].
fn samples(shapes: &[Shape<'_>]) -> Vec<Sample> {
    let params = |shape: &Shape<'_>, curve_max: usize, surface_max: usize| match shape {
        Shape::Curve(c) => (
            sample_parameters(c.knots(), c.degree(), c.domain(), curve_max),
            vec![0.0],
        ),
        Shape::Surface(f) => {
            let (du, dv) = f.domain();
            (
                sample_parameters(f.knots_u(), f.degree_u(), du, surface_max),
                sample_parameters(f.knots_v(), f.degree_v(), dv, surface_max),
            )
        }
    };
    let mut caps = (MAX_CURVE_SAMPLES, MAX_SURFACE_SAMPLES);
    let total: usize = shapes
        .iter()
        .map(|s| {
            let (u, v) = params(s, caps.0, caps.1);
            u.len() * v.len()
        })
        .sum();
    if total > MAX_SIDE_SAMPLES {
        let f = MAX_SIDE_SAMPLES as f64 / total as f64;
        let cap = |max: usize, f: f64| ((max as f64 * f) as usize).max(FLOOR_SAMPLES);
        caps = (
            cap(MAX_CURVE_SAMPLES, f),
            cap(MAX_SURFACE_SAMPLES, f.sqrt()),
        );
    }
    let mut out = Vec::new();
    for (shape, s) in shapes.iter().enumerate() {
        let (us, vs) = params(s, caps.0, caps.1);
        for (i, &u) in us.iter().enumerate() {
            for (j, &v) in vs.iter().enumerate() {
                let (point, step) = match s {
                    Shape::Curve(c) => (c.point_at_unchecked(u), (step_at(&us, i), 0.0)),
                    Shape::Surface(f) => (
                        f.point_at_unchecked(u, v),
                        (step_at(&us, i), step_at(&vs, j)),
                    ),
                };
                out.push(Sample {
                    shape,
                    at: (u, v),
                    point,
                    step,
                });
            }
        }
    }
    out
}

/// A k-d tree over sample points, stored implicitly (the median of each range at its
/// middle), built and searched with explicit stacks.
struct Tree<'s> {
    samples: &'s [Sample],
    order: Vec<usize>,
}

impl<'s> Tree<'s> {
    fn new(samples: &'s [Sample]) -> Self {
        let mut order: Vec<usize> = (0..samples.len()).collect();
        let mut stack = vec![(0usize, order.len(), 0usize)];
        while let Some((lo, hi, axis)) = stack.pop() {
            if hi - lo < 2 {
                continue;
            }
            let mid = (lo + hi) / 2;
            order[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
                samples[a].point[axis].total_cmp(&samples[b].point[axis])
            });
            stack.push((lo, mid, (axis + 1) % 3));
            stack.push((mid + 1, hi, (axis + 1) % 3));
        }
        Tree { samples, order }
    }

    /// The `k` samples nearest to `q`, nearest first, with their distances.
    fn nearest(&self, q: Point3, k: usize) -> Vec<(f64, &'s Sample)> {
        let mut best: Vec<(f64, &'s Sample)> = Vec::with_capacity(k + 1);
        // (range, axis, squared distance from q to the range's side of the split)
        let mut stack = vec![(0usize, self.order.len(), 0usize, 0.0f64)];
        while let Some((lo, hi, axis, bound)) = stack.pop() {
            if lo >= hi || (best.len() == k && bound > best[k - 1].0 * best[k - 1].0) {
                continue;
            }
            let mid = (lo + hi) / 2;
            let s = &self.samples[self.order[mid]];
            let d = dist(s.point, q);
            if best.len() < k || d < best[best.len() - 1].0 {
                let at = best.partition_point(|x| x.0 <= d);
                best.insert(at, (d, s));
                best.truncate(k);
            }
            let diff = q[axis] - s.point[axis];
            let next = (axis + 1) % 3;
            let (near, far) = if diff < 0.0 {
                ((lo, mid), (mid + 1, hi))
            } else {
                ((mid + 1, hi), (lo, mid))
            };
            stack.push((far.0, far.1, next, diff * diff));
            stack.push((near.0, near.1, next, bound));
        }
        best
    }
}

/// Where the largest distance of [`directed_distance`] was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Farthest {
    /// The distance.
    pub distance: f64,
    /// The index of the shape of `from` the point is on.
    pub from: usize,
    /// The point's parameters on it (`v` is 0 for a curve).
    pub at: (f64, f64),
    /// The point.
    pub point: Point3,
    /// The index of the nearest shape of `to`.
    pub to: usize,
    /// The nearest point's parameters on that shape.
    pub nearest_at: (f64, f64),
}

/// A distance, the index of the shape it reaches and the parameters there.
type Hit = (f64, usize, (f64, f64));

/// The point of `to` nearest to `point`: inversions (NURBS Book section 6.1) started at
/// `hint` and at the nearest few samples of `to` (more than one: on a closed shape the
/// nearest sample can sit at the wrong end of the seam, where the iteration cannot cross).
/// A sample's own distance bounds the result. Returns `(distance, shape, parameters)`.
fn nearest_on(
    to: &[Shape<'_>],
    targets: &Tree<'_>,
    point: Point3,
    hint: Option<(usize, (f64, f64))>,
) -> Result<Option<Hit>, GeometryError> {
    let nearest = targets
        .nearest(point, NEWTON_STARTS)
        .into_iter()
        .map(|(d, t)| (d, t.shape, t.at));
    let starts = hint
        .map(|(shape, at)| (f64::INFINITY, shape, at))
        .into_iter()
        .chain(nearest);
    let mut best: Option<Hit> = None;
    for (d0, shape, start) in starts {
        let (d, at) = match to[shape] {
            Shape::Curve(c) => invert_curve_near(c, point, start.0)
                .map(|(u, d)| (d, (u, 0.0)))
                .ok_or_else(|| not_finite("curve"))?,
            Shape::Surface(f) => invert_surface(f, point, Some(start))
                .map(|i| (i.distance, (i.u, i.v)))
                .ok_or_else(|| not_finite("surface"))?,
        };
        let found = if d <= d0 {
            (d, shape, at)
        } else {
            (d0, shape, start)
        };
        if best.is_none_or(|b| found.0 < b.0) {
            best = Some(found);
        }
    }
    Ok(best)
}

/// Samples whose distances are refined by a local search (the largest ones).
const REFINED: usize = 4;
/// Golden-section steps per direction and round of a refinement.
const GOLDEN_STEPS: usize = 30;
/// Rounds of a refinement (u then v for surfaces).
const REFINE_ROUNDS: usize = 3;

/// The largest distance from a point of `from` to the nearest shape of `to` (one side of
/// the Hausdorff distance; the other side swaps the arguments): every sample's distance
/// (inversions from its nearest samples on the other side), then the largest few refined by a golden-section search for the
/// maximum between the neighbouring samples (coordinate-wise on surfaces). `None` when
/// either side is empty. `stop` is polled between samples: when it returns true the
/// search ends with `Ok(None)`.
pub fn directed_distance(
    from: &[Shape<'_>],
    to: &[Shape<'_>],
    stop: &dyn Fn() -> bool,
) -> Result<Option<Farthest>, GeometryError> {
    let target_samples = samples(to);
    if target_samples.is_empty() {
        return Ok(None);
    }
    let targets = Tree::new(&target_samples);
    let mut found: Vec<(Farthest, (f64, f64))> = Vec::new();
    for (k, s) in samples(from).into_iter().enumerate() {
        if k % 256 == 0 && stop() {
            return Ok(None);
        }
        let Some((distance, shape, at)) = nearest_on(to, &targets, s.point, None)? else {
            return Ok(None);
        };
        found.push((
            Farthest {
                distance,
                from: s.shape,
                at: s.at,
                point: s.point,
                to: shape,
                nearest_at: at,
            },
            s.step,
        ));
    }
    found.sort_by(|a, b| b.0.distance.total_cmp(&a.0.distance));
    let mut worst: Option<Farthest> = None;
    for (start, step) in found.into_iter().take(REFINED) {
        if stop() {
            return Ok(None);
        }
        let refined = refine(from, to, &targets, start, step)?;
        if worst.is_none_or(|w| refined.distance > w.distance) {
            worst = Some(refined);
        }
    }
    Ok(worst)
}

/// Searches for a larger distance around `start` (within `step` of its parameters):
/// golden-section maximisation along each parameter direction in turn.
fn refine(
    from: &[Shape<'_>],
    to: &[Shape<'_>],
    targets: &Tree<'_>,
    start: Farthest,
    step: (f64, f64),
) -> Result<Farthest, GeometryError> {
    let shape = from[start.from];
    let point_at = |(u, v): (f64, f64)| match shape {
        Shape::Curve(c) => c.point_at_unchecked(u),
        Shape::Surface(f) => f.point_at_unchecked(u, v),
    };
    let (du, dv) = match shape {
        Shape::Curve(c) => (c.domain(), (0.0, 0.0)),
        Shape::Surface(f) => f.domain(),
    };
    let mut best = start;
    let eval = |at: (f64, f64), best: &mut Farthest| -> Result<f64, GeometryError> {
        let point = point_at(at);
        let hint = Some((best.to, best.nearest_at));
        let Some((d, to_shape, nearest_at)) = nearest_on(to, targets, point, hint)? else {
            return Ok(0.0);
        };
        if d > best.distance {
            *best = Farthest {
                distance: d,
                from: best.from,
                at,
                point,
                to: to_shape,
                nearest_at,
            };
        }
        Ok(d)
    };
    let directions: &[usize] = match shape {
        Shape::Curve(_) => &[0],
        Shape::Surface(_) => &[0, 1],
    };
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..REFINE_ROUNDS {
        for &dir in directions {
            let centre = best.at;
            let (h, (lo, hi)) = if dir == 0 { (step.0, du) } else { (step.1, dv) };
            let c = if dir == 0 { centre.0 } else { centre.1 };
            let (mut a, mut b) = ((c - h).max(lo), (c + h).min(hi));
            if b <= a {
                continue;
            }
            let at = |x: f64| {
                if dir == 0 {
                    (x, centre.1)
                } else {
                    (centre.0, x)
                }
            };
            let mut x1 = b - ratio * (b - a);
            let mut x2 = a + ratio * (b - a);
            let mut f1 = eval(at(x1), &mut best)?;
            let mut f2 = eval(at(x2), &mut best)?;
            for _ in 0..GOLDEN_STEPS {
                if f1 >= f2 {
                    b = x2;
                    x2 = x1;
                    f2 = f1;
                    x1 = b - ratio * (b - a);
                    f1 = eval(at(x1), &mut best)?;
                } else {
                    a = x1;
                    x1 = x2;
                    f1 = f2;
                    x2 = a + ratio * (b - a);
                    f2 = eval(at(x2), &mut best)?;
                }
            }
        }
        if directions.len() == 1 {
            break;
        }
    }
    Ok(best)
}

fn not_finite(kind: &str) -> GeometryError {
    GeometryError::InvalidArgument(format!(
        "a {kind}'s derivatives are not finite: no distance"
    ))
}

#[cfg(test)]
mod tests {
    use super::{Sample, Tree};
    use crate::nurbs::vector::dist;

    #[test]
    fn the_tree_finds_the_nearest_samples_a_full_scan_finds() {
        let mut seed: u64 = 7;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 10.0 - 5.0
        };
        let samples: Vec<Sample> = (0..2000)
            .map(|k| Sample {
                shape: k,
                at: (0.0, 0.0),
                // Many equal coordinates too (a plane of points).
                point: [next(), next(), if k % 3 == 0 { 0.0 } else { next() }],
                step: (0.0, 0.0),
            })
            .collect();
        let tree = Tree::new(&samples);
        for _ in 0..300 {
            let q = [next(), next(), next()];
            let mut all: Vec<(f64, usize)> = samples
                .iter()
                .map(|s| (dist(s.point, q), s.shape))
                .collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0));
            let got: Vec<f64> = tree.nearest(q, 3).iter().map(|x| x.0).collect();
            let want: Vec<f64> = all[..3].iter().map(|x| x.0).collect();
            assert_eq!(got, want);
        }
        assert!(Tree::new(&[]).nearest([0.0; 3], 3).is_empty());
    }
}
