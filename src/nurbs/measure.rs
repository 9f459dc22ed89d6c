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
//!   shape is sampled in every knot span, each sample's nearest sample of the other side
//!   starts a point inversion (NURBS Book section 6.1, `super::project`) on that sample's
//!   shape. The result does not depend on how either side is parameterised.

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
/// The most samples of one curve, and per direction of one surface.
const MAX_SAMPLES: usize = 256;
/// The fewest samples of one curve, and per direction of one surface.
const MIN_SAMPLES: usize = 32;

/// Sample parameters of one direction: `SPAN_SAMPLES` per knot span, between
/// `MIN_SAMPLES` and `MAX_SAMPLES` in all, every knot among them when there is room.
fn sample_parameters(knots: &[f64], p: usize, domain: (f64, f64)) -> Vec<f64> {
    let b = breaks(knots, p, domain);
    let spans = b.len() - 1;
    let per = SPAN_SAMPLES.max(MIN_SAMPLES.div_ceil(spans));
    if spans * per > MAX_SAMPLES {
        let n = MAX_SAMPLES;
        return (0..=n)
            .map(|i| domain.0 + (domain.1 - domain.0) * i as f64 / n as f64)
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

/// A sample: the shape's index, its parameters, the point.
#[derive(Debug, Clone, Copy)]
struct Sample {
    shape: usize,
    at: (f64, f64),
    point: Point3,
}

fn samples(shapes: &[Shape<'_>]) -> Vec<Sample> {
    let mut out = Vec::new();
    for (shape, s) in shapes.iter().enumerate() {
        match s {
            Shape::Curve(c) => {
                for u in sample_parameters(c.knots(), c.degree(), c.domain()) {
                    out.push(Sample {
                        shape,
                        at: (u, 0.0),
                        point: c.point_at_unchecked(u),
                    });
                }
            }
            Shape::Surface(f) => {
                let (du, dv) = f.domain();
                let vs = sample_parameters(f.knots_v(), f.degree_v(), dv);
                for u in sample_parameters(f.knots_u(), f.degree_u(), du) {
                    for &v in &vs {
                        out.push(Sample {
                            shape,
                            at: (u, v),
                            point: f.point_at_unchecked(u, v),
                        });
                    }
                }
            }
        }
    }
    out
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

/// The largest distance from a sample point of `from` to the nearest shape of `to` (one
/// side of the Hausdorff distance; the other side swaps the arguments). `None` when either
/// side is empty. `stop` is polled between samples: when it returns true the search ends
/// with `Ok(None)`.
pub fn directed_distance(
    from: &[Shape<'_>],
    to: &[Shape<'_>],
    stop: &dyn Fn() -> bool,
) -> Result<Option<Farthest>, GeometryError> {
    let targets = samples(to);
    if targets.is_empty() {
        return Ok(None);
    }
    let mut worst: Option<Farthest> = None;
    for (k, s) in samples(from).into_iter().enumerate() {
        if k % 256 == 0 && stop() {
            return Ok(None);
        }
        // The nearest few samples of `to` start inversions on their shapes (more than one:
        // on a closed shape the nearest sample can sit at the wrong end of the seam, where
        // the iteration cannot cross). A sample's own distance bounds the result: the
        // inversion keeps the best point it met.
        let mut nearest: Vec<(f64, &Sample)> = Vec::with_capacity(NEWTON_STARTS + 1);
        for t in &targets {
            let d = dist(t.point, s.point);
            if nearest.len() < NEWTON_STARTS || d < nearest[nearest.len() - 1].0 {
                let at = nearest.partition_point(|x| x.0 <= d);
                nearest.insert(at, (d, t));
                nearest.truncate(NEWTON_STARTS);
            }
        }
        let mut best: Option<(f64, usize, (f64, f64))> = None;
        for &(d0, start) in &nearest {
            let (d, at) = match to[start.shape] {
                Shape::Curve(c) => invert_curve_near(c, s.point, start.at.0)
                    .map(|(u, d)| (d, (u, 0.0)))
                    .ok_or_else(|| not_finite("curve"))?,
                Shape::Surface(f) => invert_surface(f, s.point, Some(start.at))
                    .map(|i| (i.distance, (i.u, i.v)))
                    .ok_or_else(|| not_finite("surface"))?,
            };
            let (d, at) = if d <= d0 { (d, at) } else { (d0, start.at) };
            if best.is_none_or(|b| d < b.0) {
                best = Some((d, start.shape, at));
            }
        }
        let Some((distance, shape, at)) = best else {
            return Ok(None);
        };
        if worst.is_none_or(|w| distance > w.distance) {
            worst = Some(Farthest {
                distance,
                from: s.shape,
                at: s.at,
                point: s.point,
                to: shape,
                nearest_at: at,
            });
        }
    }
    Ok(worst)
}

fn not_finite(kind: &str) -> GeometryError {
    GeometryError::InvalidArgument(format!(
        "a {kind}'s derivatives are not finite: no distance"
    ))
}
