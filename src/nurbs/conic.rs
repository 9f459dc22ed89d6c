//! Exact NURBS forms of lines, polylines and conic arcs, with the exact map between the
//! conic's own parameter and the NURBS parameter.
//!
//! - Elliptic arcs (circles and ellipses) `C + cos t X + sin t Y` and hyperbolic arcs
//!   `C + cosh t X + sinh t Y` are rational quadratics in equal segments, each the symmetric
//!   arc of NURBS Book A7.1 (seed 000 eq. 2-119/2-120): end poles on the conic, the middle
//!   pole where the end tangents meet, middle weight `cos a` (elliptic) or `cosh a`
//!   (hyperbolic) for a segment of half-sweep `a`. X and Y are conjugate semi-diameters, so
//!   one routine covers circles (X = r x, Y = r y), ellipses and arcs of both that start
//!   anywhere.
//! - Interior knots of multiplicity 2 sit *at* the segment ends' values of `t`: the NURBS
//!   parameter equals `t` at every knot. Inside a segment the standard form is not
//!   parameterised by `t`; with `s` the segment's Bezier parameter in `[0, 1]`, its half
//!   sweep `a` and `psi = t - t_mid`, the rational parameterisation obeys
//!   `tan(psi/2) = tan(a/2) (2 s - 1)` (elliptic; `tanh` for hyperbolic), which is the
//!   half-angle substitution `cos psi = (1 - q^2)/(1 + q^2)`, `sin psi = 2q/(1 + q^2)` with
//!   `q = tan(psi/2)` written in Bernstein form. [`ArcMap`] evaluates that relation and its
//!   inverse exactly (up to rounding).
//! - Parabolas `V + t^2 X + 2 t Y` and lines are polynomial in `t`, so their NURBS
//!   parameter *is* `t`.

use super::vector::{add, scale};
use super::{GeometryError, NurbsCurve, Point3};

/// Which conic family an arc belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConicKind {
    /// `C + cos t X + sin t Y` (circles and ellipses).
    Elliptic,
    /// `C + cosh t X + sinh t Y` (one branch of a hyperbola).
    Hyperbolic,
}

/// Largest sweep of one segment: 90 degrees for elliptic arcs (A7.1 uses at most 90 degrees
/// per segment, which keeps the middle weight >= cos 45 deg), 2 for hyperbolic arcs (middle
/// weight <= cosh 1).
fn max_segment_sweep(kind: ConicKind) -> f64 {
    match kind {
        ConicKind::Elliptic => std::f64::consts::FRAC_PI_2,
        ConicKind::Hyperbolic => 2.0,
    }
}

/// Largest hyperbolic parameter accepted: `cosh 700` is near the top of f64.
const MAX_HYPERBOLIC_T: f64 = 700.0;

/// The exact, monotone map between a conic's parameter `t` and the NURBS parameter `u` of
/// the curve [`conic_arc`] built (and of the rotation direction of [`super::sweep`]'s
/// surfaces). `u == t` at every segment end (the knots).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcMap {
    kind: ConicKind,
    t0: f64,
    t1: f64,
    segments: usize,
}

impl ArcMap {
    /// The map of `[t0, t1]` split into the standard number of segments.
    pub(super) fn new(kind: ConicKind, t0: f64, t1: f64) -> Result<Self, GeometryError> {
        if !(t0.is_finite() && t1.is_finite()) || t0 >= t1 {
            return Err(GeometryError::InvalidArgument(format!(
                "conic arc range [{t0}, {t1}] is not an increasing finite interval"
            )));
        }
        let sweep = t1 - t0;
        match kind {
            ConicKind::Elliptic if sweep > std::f64::consts::TAU * (1.0 + 1e-12) => {
                return Err(GeometryError::InvalidArgument(format!(
                    "elliptic arc sweep {sweep} exceeds a full turn"
                )));
            }
            ConicKind::Hyperbolic if t0.abs().max(t1.abs()) > MAX_HYPERBOLIC_T => {
                return Err(GeometryError::InvalidArgument(format!(
                    "hyperbolic arc range [{t0}, {t1}] is beyond |t| <= {MAX_HYPERBOLIC_T}"
                )));
            }
            _ => {}
        }
        // A sweep a hair above a whole number of segments (rounding of a degree-to-radian
        // conversion) does not earn an extra segment.
        let n = (sweep / max_segment_sweep(kind) - 1e-9).ceil().max(1.0);
        // The elliptic sweep is bounded above; the hyperbolic one by 2 * 700 / 2.
        let segments = n as usize;
        Ok(ArcMap {
            kind,
            t0,
            t1,
            segments,
        })
    }

    /// The conic family.
    pub fn kind(&self) -> ConicKind {
        self.kind
    }

    /// The conic parameter range `[t0, t1]` (also the NURBS domain).
    pub fn range(&self) -> (f64, f64) {
        (self.t0, self.t1)
    }

    /// Number of rational quadratic segments.
    pub fn segments(&self) -> usize {
        self.segments
    }

    /// The value of `t` (and `u`) at segment end `i` (`0..=segments`), exact at both ends.
    pub fn knot(&self, i: usize) -> f64 {
        if i == 0 {
            self.t0
        } else if i >= self.segments {
            self.t1
        } else {
            self.t0 + (self.t1 - self.t0) * (i as f64 / self.segments as f64)
        }
    }

    /// The segment holding `x` (a value of `t` or `u`; both share the segment ends).
    fn segment_of(&self, x: f64) -> usize {
        let mut i = 0;
        while i + 1 < self.segments && x >= self.knot(i + 1) {
            i += 1;
        }
        i
    }

    /// `tan` or `tanh`.
    fn half(&self, x: f64) -> f64 {
        match self.kind {
            ConicKind::Elliptic => x.tan(),
            ConicKind::Hyperbolic => x.tanh(),
        }
    }

    /// Inverse of [`Self::half`].
    fn half_inv(&self, x: f64) -> f64 {
        match self.kind {
            ConicKind::Elliptic => x.atan(),
            ConicKind::Hyperbolic => x.atanh(),
        }
    }

    /// Segment `i`'s ends, middle and the tangent of its quarter sweep.
    fn segment(&self, i: usize) -> (f64, f64, f64, f64) {
        let (a, b) = (self.knot(i), self.knot(i + 1));
        let mid = 0.5 * (a + b);
        (a, b, mid, self.half(0.25 * (b - a)))
    }

    /// The NURBS parameter of conic parameter `t` (clamped to the range).
    pub fn to_nurbs(&self, t: f64) -> f64 {
        let t = t.clamp(self.t0, self.t1);
        let i = self.segment_of(t);
        let (a, b, mid, tq) = self.segment(i);
        if t == a || t == b {
            return t;
        }
        // tan(psi/2) = tan(sweep/4) (2 s - 1), psi = t - mid.
        let s = 0.5 * (1.0 + self.half(0.5 * (t - mid)) / tq);
        // Rounding must not step outside the segment (and so the domain).
        (a + s * (b - a)).clamp(a, b)
    }

    /// The conic parameter of NURBS parameter `u` (clamped to the domain): the exact inverse
    /// of [`Self::to_nurbs`].
    pub fn from_nurbs(&self, u: f64) -> f64 {
        let u = u.clamp(self.t0, self.t1);
        let i = self.segment_of(u);
        let (a, b, mid, tq) = self.segment(i);
        if u == a || u == b {
            return u;
        }
        let s = (u - a) / (b - a);
        (mid + 2.0 * self.half_inv(tq * (2.0 * s - 1.0))).clamp(a, b)
    }

    /// `du/dt` at conic parameter `t`, for derivatives by the chain rule.
    pub fn derivative(&self, t: f64) -> f64 {
        let t = t.clamp(self.t0, self.t1);
        let i = self.segment_of(t);
        let (a, b, mid, tq) = self.segment(i);
        let h = self.half(0.5 * (t - mid));
        // d/dx tan x = 1 + tan^2 x; d/dx tanh x = 1 - tanh^2 x.
        let dh = match self.kind {
            ConicKind::Elliptic => 1.0 + h * h,
            ConicKind::Hyperbolic => 1.0 - h * h,
        };
        (b - a) * 0.25 * dh / tq
    }
}

fn finite(points: &[Point3]) -> bool {
    points.iter().flatten().all(|c| c.is_finite())
}

/// Poles and weights of the arc `C + f(t) X + g(t) Y` over `map`'s range (A7.1).
pub(super) fn arc_poles(
    map: &ArcMap,
    centre: Point3,
    x: Point3,
    y: Point3,
) -> (Vec<Point3>, Vec<f64>) {
    let on_conic = |t: f64| match map.kind {
        ConicKind::Elliptic => add(centre, add(scale(x, t.cos()), scale(y, t.sin()))),
        ConicKind::Hyperbolic => add(centre, add(scale(x, t.cosh()), scale(y, t.sinh()))),
    };
    let n = map.segments;
    let mut poles = Vec::with_capacity(2 * n + 1);
    let mut weights = Vec::with_capacity(2 * n + 1);
    poles.push(on_conic(map.t0));
    weights.push(1.0);
    for i in 0..n {
        let (a, b, mid, _) = map.segment(i);
        let half = 0.5 * (b - a);
        // The middle pole: where the end tangents meet, C + X_mid / cos(half) with X_mid the
        // semi-diameter at the segment's middle (cosh for the hyperbola).
        let (xm, w) = match map.kind {
            ConicKind::Elliptic => (add(scale(x, mid.cos()), scale(y, mid.sin())), half.cos()),
            ConicKind::Hyperbolic => (add(scale(x, mid.cosh()), scale(y, mid.sinh())), half.cosh()),
        };
        poles.push(add(centre, scale(xm, 1.0 / w)));
        weights.push(w);
        poles.push(on_conic(b));
        weights.push(1.0);
    }
    // A full turn closes exactly (cos 2 pi rounds to 1, sin 2 pi does not round to 0).
    if map.kind == ConicKind::Elliptic
        && ((map.t1 - map.t0) - std::f64::consts::TAU).abs() <= 1e-12 * std::f64::consts::TAU
    {
        poles[2 * n] = poles[0];
    }
    (poles, weights)
}

/// The knot vector of `map`'s segments: ends of multiplicity 3, segment ends of
/// multiplicity 2 (A7.1).
pub(super) fn arc_knots(map: &ArcMap) -> Vec<f64> {
    let n = map.segments;
    let mut knots = Vec::with_capacity(2 * n + 4);
    knots.extend([map.t0; 3]);
    for i in 1..n {
        let k = map.knot(i);
        knots.extend([k, k]);
    }
    knots.extend([map.t1; 3]);
    knots
}

/// The exact NURBS of `C + cos t X + sin t Y` (elliptic) or `C + cosh t X + sinh t Y`
/// (hyperbolic) for `t` in `[t0, t1]`, and the map between `t` and its parameter.
///
/// X and Y are conjugate semi-diameters, not normalised (a circle of radius r in the plane
/// of orthonormal x, y: `X = r x`, `Y = r y`). An elliptic sweep is at most a full turn.
/// NURBS Book A7.1; seed 000 eq. 2-119/2-120.
pub fn conic_arc(
    kind: ConicKind,
    centre: Point3,
    x: Point3,
    y: Point3,
    t0: f64,
    t1: f64,
) -> Result<(NurbsCurve, ArcMap), GeometryError> {
    if !finite(&[centre, x, y]) {
        return Err(GeometryError::InvalidArgument(
            "conic centre or semi-diameter is not finite".into(),
        ));
    }
    let map = ArcMap::new(kind, t0, t1)?;
    let (poles, weights) = arc_poles(&map, centre, x, y);
    let curve = NurbsCurve::new(2, arc_knots(&map), poles, Some(weights))?;
    Ok((curve, map))
}

/// The parabola `V + t^2 X + 2 t Y` for `t` in `[t0, t1]` (ISO 10303-42 parabola with
/// `X = a x`, `Y = a y`): one polynomial quadratic Bezier segment whose parameter is `t`.
/// The middle pole is the blossom `V + t0 t1 X + (t0 + t1) Y`.
pub fn parabola_arc(
    vertex: Point3,
    x: Point3,
    y: Point3,
    t0: f64,
    t1: f64,
) -> Result<NurbsCurve, GeometryError> {
    if !(t0.is_finite() && t1.is_finite()) || t0 >= t1 {
        return Err(GeometryError::InvalidArgument(format!(
            "parabola range [{t0}, {t1}] is not an increasing finite interval"
        )));
    }
    let at = |a: f64, b: f64| add(vertex, add(scale(x, a * b), scale(y, a + b)));
    let poles = vec![at(t0, t0), at(t0, t1), at(t1, t1)];
    NurbsCurve::new(2, vec![t0, t0, t0, t1, t1, t1], poles, None)
}

/// The segment `p0 + (u - u0)/(u1 - u0) (p1 - p0)` on `[u0, u1]`: degree 1, parameter `u`.
pub fn line_segment(p0: Point3, p1: Point3, u0: f64, u1: f64) -> Result<NurbsCurve, GeometryError> {
    polyline(&[p0, p1], &[u0, u1])
}

/// The degree-1 polyline through `points` reaching point `i` at parameter `params[i]`
/// (strictly increasing).
pub fn polyline(points: &[Point3], params: &[f64]) -> Result<NurbsCurve, GeometryError> {
    if points.len() < 2 || points.len() != params.len() {
        return Err(GeometryError::InvalidArgument(format!(
            "a polyline needs at least 2 points and one parameter each ({} points, {} parameters)",
            points.len(),
            params.len()
        )));
    }
    if params.iter().any(|p| !p.is_finite()) || params.windows(2).any(|w| w[0] >= w[1]) {
        return Err(GeometryError::InvalidArgument(
            "polyline parameters must be finite and strictly increasing".into(),
        ));
    }
    let mut knots = Vec::with_capacity(params.len() + 2);
    knots.push(params[0]);
    knots.extend_from_slice(params);
    knots.push(params[params.len() - 1]);
    NurbsCurve::new(1, knots, points.to_vec(), None)
}
