//! Degree reduction by one with a computed error bound, for curves and for surfaces per
//! direction (NURBS Book A5.11 DegreeReduceCurve, Bezier step eqs. 5.41-5.46; seed 000
//! section 2-10, eqs. 2-66 .. 2-69).
//!
//! Like A5.11 the curve is processed Bezier segment by Bezier segment: (1) the curve is
//! clamped and each knot span is extracted as a Bezier segment by local knot insertion
//! (A5.1, equivalent to A5.6 DecomposeCurve); (2) each segment is reduced from degree `p`
//! to `p - 1` by the two-sided inversion of degree elevation (eqs. 5.41-5.44), whose error
//! is a known combination of one or two Bernstein polynomials (eqs. 5.45, 5.46); (3) every
//! interior knot is removed again until its multiplicity is one less than in the input (the
//! continuity `C^{p-m}` is kept), each removal measuring the change of the control polygon
//! it makes (as A5.8 / A5.11's `Br`). Errors are accumulated per knot span as in A5.11's
//! error vector `e[]`.
//!
//! All steps run in homogeneous space on poles that are first centred at the control
//! polygon's box centre and scaled by its radius `R`, so the homogeneous error `E` is
//! measured in units where `|C| <= 1`. The Euclidean error then satisfies
//! `|C' - C| = |E_xyz - C E_w| / (w + E_w) <= sqrt(2) |E| / (w_min - |E|)` (Cauchy-Schwarz,
//! convex hull property), multiplied back by `R`. For polynomial curves `E_w = 0` and the
//! bound is `R |E_xyz|`.

use super::bernstein::bernstein_max;
use super::double_double::DoubleDouble as Dd;
use super::elevate::{clamp_flat, elevate_flat_precise};
use super::knots::{multiplicity, runs};
use super::{GeometryError, Grid, NurbsCurve, NurbsSurface, Point3};

/// Reduces one Bezier segment of degree `p` (flat poles, `dim` wide) to degree `p - 1`
/// (eqs. 5.41-5.44). Returns the new poles and the largest value of the homogeneous error
/// curve (eqs. 5.45, 5.46 with the Bernstein maxima instead of 1, both exact maxima or upper
/// bounds of them).
fn bezier_reduce(q: &[f64], dim: usize, p: usize, norm: &Norm<'_>) -> (Vec<f64>, f64) {
    let mut out = vec![0.0; p * dim];
    let r = (p - 1) / 2;
    let alpha = |i: usize| i as f64 / p as f64;
    let qk = |k: usize| &q[k * dim..(k + 1) * dim];
    out[..dim].copy_from_slice(qk(0));
    out[(p - 1) * dim..].copy_from_slice(qk(p));
    // Forward: P_i = (Q_i - a_i P_{i-1}) / (1 - a_i).
    let forward_end = if p % 2 == 0 { r } else { r.saturating_sub(1) };
    for i in 1..=forward_end {
        let a = alpha(i);
        for c in 0..dim {
            out[i * dim + c] = (q[i * dim + c] - a * out[(i - 1) * dim + c]) / (1.0 - a);
        }
    }
    // Backward: P_i = (Q_{i+1} - (1 - a_{i+1}) P_{i+1}) / a_{i+1}.
    for i in ((r + 1)..=(p.saturating_sub(2))).rev() {
        let a = alpha(i + 1);
        for c in 0..dim {
            out[i * dim + c] = (q[(i + 1) * dim + c] - (1.0 - a) * out[(i + 1) * dim + c]) / a;
        }
    }
    let mut d = vec![0.0; dim];
    let err = if p % 2 == 0 {
        // One equation left: Q_{r+1} = (P_r + P_{r+1}) / 2 (a_{r+1} = 1/2).
        for c in 0..dim {
            d[c] = q[(r + 1) * dim + c] - 0.5 * (out[r * dim + c] + out[(r + 1) * dim + c]);
        }
        norm(&d) * bernstein_max(r + 1, p)
    } else if p == 1 {
        0.0
    } else {
        // P_r from both sides, averaged; the error curve is
        // (P_r^L - P_r^R) / 2 * ((1 - a_r) B_r - a_{r+1} B_{r+1}).
        let (ar, ar1) = (alpha(r), alpha(r + 1));
        for c in 0..dim {
            let left = (q[r * dim + c] - ar * out[(r - 1) * dim + c]) / (1.0 - ar);
            let right = (q[(r + 1) * dim + c] - (1.0 - ar1) * out[(r + 1) * dim + c]) / ar1;
            out[r * dim + c] = 0.5 * (left + right);
            d[c] = 0.5 * (left - right);
        }
        // |x - y| <= max(x, y) for x, y >= 0.
        norm(&d) * ((1.0 - ar) * bernstein_max(r, p)).max(ar1 * bernstein_max(r + 1, p))
    };
    (out, err)
}

/// Removes one copy of the knot at index `r` (last index of its run, multiplicity `s`,
/// strictly inside a clamped vector) from a degree-`p` flat B-spline (A5.8 with one
/// removal). The new poles are solved from both ends of the affected range; the one
/// equation left over gives the residual `d`: re-inserting the knot reproduces the old
/// polygon except one pole, moved by `d`, so the curve moves by at most `|d|` on the support
/// of that pole's basis function. Returns `(|d|, support start, support end)`.
fn remove_once(
    p: usize,
    knots: &mut Vec<f64>,
    poles: &mut Vec<f64>,
    dim: usize,
    r: usize,
    s: usize,
    norm: &Norm<'_>,
) -> (f64, f64, f64) {
    let u = knots[r];
    let first = r - p;
    let last = r - s;
    let np = poles.len() / dim;
    let unknowns = last - first;
    let h = unknowns / 2;
    let mut q = vec![0.0; (np - 1) * dim];
    q[..first * dim].copy_from_slice(&poles[..first * dim]);
    q[last * dim..].copy_from_slice(&poles[(last + 1) * dim..]);
    let alpha = |k: usize| (u - knots[k]) / (knots[k + p + 1] - knots[k]);
    for k in first..first + h {
        let a = alpha(k);
        for c in 0..dim {
            q[k * dim + c] = (poles[k * dim + c] - (1.0 - a) * q[(k - 1) * dim + c]) / a;
        }
    }
    for k in ((first + h + 1)..=last).rev() {
        let a = alpha(k);
        for c in 0..dim {
            q[(k - 1) * dim + c] = (poles[k * dim + c] - a * q[k * dim + c]) / (1.0 - a);
        }
    }
    let k = first + h;
    let a = alpha(k);
    let d: Vec<f64> = (0..dim)
        .map(|c| poles[k * dim + c] - (a * q[k * dim + c] + (1.0 - a) * q[(k - 1) * dim + c]))
        .collect();
    let support = (knots[k], knots[k + p + 1]);
    knots.remove(r);
    *poles = q;
    (norm(&d), support.0, support.1)
}

/// A norm on one flat pole (for a surface row: the largest point norm in the row).
type Norm<'a> = dyn Fn(&[f64]) -> f64 + 'a;

fn norm4(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn norm3(v: &[f64]) -> f64 {
    v[..3].iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Reduces a flat B-spline (poles already centred and scaled) from degree `p` to `p - 1`:
/// clamp, Bezier decomposition, per-segment reduction, knot removal. Returns the knots, the
/// poles and the bound of the homogeneous error (in `norm`), accumulated per knot span.
fn reduce_flat(
    p: usize,
    knots: &[f64],
    flat: &[f64],
    dim: usize,
    norm: &Norm<'_>,
) -> (Vec<f64>, Vec<f64>, f64) {
    let (knots, pw) = clamp_flat(p, knots, flat, dim);
    let (a, b) = (knots[0], knots[knots.len() - 1]);
    // Interior distinct knots with their multiplicities in the clamped input.
    let interior: Vec<(f64, usize)> = runs(&knots)
        .filter(|&(_, v, _)| v > a && v < b)
        .map(|(_, v, m)| (v, m))
        .collect();
    let nseg = interior.len() + 1;
    let mut bounds: Vec<f64> = Vec::with_capacity(nseg + 1);
    bounds.push(a);
    bounds.extend(interior.iter().map(|&(v, _)| v));
    bounds.push(b);
    let ph = p - 1;
    let mut err = Vec::with_capacity(nseg);
    let mut red = Vec::with_capacity((nseg * ph + 1) * dim);
    // Bezier segments, one per non-empty span [U_k, U_{k+1}]: the span depends only on
    // poles k-p..=k and knots k-p..=k+p+1, so clamping that local piece at both ends
    // (A5.1) yields its Bezier poles in O(p^2), the whole decomposition in O(n p^2).
    let np = pw.len() / dim;
    for k in p..np {
        if knots[k] >= knots[k + 1] {
            continue;
        }
        let (_, seg) = clamp_flat(
            p,
            &knots[k - p..=k + p + 1],
            &pw[(k - p) * dim..(k + 1) * dim],
            dim,
        );
        let (rp, es) = bezier_reduce(&seg, dim, p, norm);
        err.push(es);
        // Adjacent segments share their end pole; keep the left one.
        let skip = if red.is_empty() { 0 } else { 1 };
        red.extend_from_slice(&rp[skip * dim..]);
    }
    let mut rk = Vec::with_capacity(nseg * ph + ph + 1);
    rk.extend(std::iter::repeat_n(a, ph + 1));
    for &(v, _) in &interior {
        rk.extend(std::iter::repeat_n(v, ph));
    }
    rk.extend(std::iter::repeat_n(b, ph + 1));
    // Remove each interior knot down to multiplicity m - 1.
    for &(v, m) in &interior {
        for _ in 0..(p - m) {
            let s = multiplicity(&rk, v);
            let r = rk.partition_point(|&x| x <= v) - 1;
            let (e, lo, hi) = remove_once(ph, &mut rk, &mut red, dim, r, s, norm);
            for (k, es) in err.iter_mut().enumerate() {
                if bounds[k] < hi && bounds[k + 1] > lo {
                    *es += e;
                }
            }
        }
    }
    (rk, red, err.iter().copied().fold(0.0, f64::max))
}

/// The centring and scaling applied before reduction (a linear map of homogeneous space, so
/// it commutes with every step; it makes the rational bound independent of the origin).
struct Frame {
    centre: Point3,
    /// Divisor of the centred coordinates (the radius, or 1 when it is 0).
    scale: f64,
    /// The control polygon's radius about `centre`. When it is 0 every centred coordinate is
    /// exactly 0, every linear step keeps it 0, and the reduced curve is exactly the same
    /// point: the Euclidean bound is then exactly 0, whatever rounding the weights saw.
    radius: f64,
}

impl Frame {
    fn of(points: &[Point3]) -> Frame {
        let (lo, hi) = super::bounding_box(points);
        let centre: Point3 = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
        let radius = points
            .iter()
            .map(|q| norm3(&[q[0] - centre[0], q[1] - centre[1], q[2] - centre[2]]))
            .fold(0.0, f64::max);
        Frame {
            centre,
            scale: if radius > 0.0 { radius } else { 1.0 },
            radius,
        }
    }

    /// Homogeneous, centred and scaled flat poles.
    fn lift(&self, points: &[Point3], weight: impl Fn(usize) -> f64) -> Vec<f64> {
        let mut flat = Vec::with_capacity(points.len() * 4);
        for (i, q) in points.iter().enumerate() {
            let w = weight(i);
            for (x, c) in q.iter().zip(self.centre) {
                flat.push(w * (x - c) / self.scale);
            }
            flat.push(w);
        }
        flat
    }

    /// The Euclidean bound from the homogeneous one (module notes).
    fn bound(&self, e: f64, rational: bool, wmin: f64) -> f64 {
        if self.radius == 0.0 {
            0.0
        } else if !rational {
            self.radius * e
        } else if e >= wmin {
            f64::INFINITY
        } else {
            self.radius * std::f64::consts::SQRT_2 * e / (wmin - e)
        }
    }

    /// Euclidean points and weights back from reduced flat poles.
    fn project(&self, red: &[f64], rational: bool, dimension: usize) -> (Vec<Point3>, Vec<f64>) {
        red.chunks_exact(4)
            .map(|h| {
                let w = if rational { h[3] } else { 1.0 };
                let mut q: Point3 = std::array::from_fn(|k| h[k] / w * self.scale + self.centre[k]);
                if dimension == 2 {
                    q[2] = 0.0;
                }
                (q, w)
            })
            .unzip()
    }
}

/// Argument checks shared by curves and surfaces.
/// One step of iterative refinement, and an a-posteriori bound.
///
/// Reduction is a linear map evaluated in floating point; on ill-conditioned knot spacing
/// (a short span next to a long one) knot removal amplifies rounding, so even a curve that
/// was exactly elevated comes back with poles off by ~1e-12 of its size. Re-elevating the
/// result (A5.9 in double-double) gives the residual on the input's clamped knots;
/// reducing that residual and adding it corrects the poles (classic iterative refinement).
///
/// The a-posteriori bound: the input and the re-elevated result are degree-`p` B-splines on
/// the same knots, so their difference is a B-spline whose poles are the pole differences,
/// and the basis functions are non-negative and sum to 1: `|dA(u)| <= max_i |dP_i|` (convex
/// hull property, NURBS Book P2.4). The smaller of this and the a-priori bound `e` is a
/// valid bound. When the knot vectors differ (they should not), the input is returned as is.
fn refine(
    p: usize,
    knots: &[f64],
    flat: &[f64],
    rk: &[f64],
    red: Vec<f64>,
    e: f64,
    norm: &Norm<'_>,
) -> (Vec<f64>, f64) {
    const DIM: usize = 4;
    let (ck, cflat) = clamp_flat(p, knots, flat, DIM);
    let residual_bound = |red: &[f64]| -> Option<(Vec<f64>, f64)> {
        let (ek, eflat) = elevate_flat_precise(p - 1, rk, red, DIM, 1, &|| false)?;
        if ek != ck || eflat.len() != cflat.len() {
            return None;
        }
        // The residual in double-double, rounded once: refinement can only correct what
        // the residual resolves.
        let diff: Vec<f64> = cflat
            .iter()
            .zip(&eflat)
            .map(|(&a, &b)| (Dd::of(a) - b).value())
            .collect();
        let worst = diff.chunks(DIM).map(norm).fold(0.0, f64::max);
        Some((diff, worst))
    };
    let Some((diff, before)) = residual_bound(&red) else {
        return (red, e);
    };
    let (dk, dred, _) = reduce_flat(p, &ck, &diff, DIM, norm);
    if dk != rk || dred.len() != red.len() {
        return (red, e.min(before));
    }
    let corrected: Vec<f64> = red.iter().zip(&dred).map(|(a, b)| a + b).collect();
    match residual_bound(&corrected) {
        Some((_, after)) if after <= before => (corrected, e.min(after)),
        _ => (red, e.min(before)),
    }
}

fn check_reduction(p: usize, tolerance: f64) -> Result<(), GeometryError> {
    if p < 2 {
        return Err(GeometryError::InvalidArgument(format!(
            "degree reduction: degree {p} cannot be reduced"
        )));
    }
    if tolerance.is_nan() || tolerance < 0.0 {
        return Err(GeometryError::InvalidArgument(format!(
            "degree reduction: tolerance {tolerance} must be >= 0"
        )));
    }
    Ok(())
}

/// Accepts or refuses a reduction: the bound must be finite and within the tolerance, and
/// every reduced weight positive.
fn accept(red: &[f64], rational: bool, bound: f64, tolerance: f64) -> Result<(), GeometryError> {
    let weights_ok = !rational || red.chunks_exact(4).all(|h| h[3] > 0.0);
    if weights_ok && bound.is_finite() && bound <= tolerance {
        Ok(())
    } else {
        Err(GeometryError::ToleranceExceeded {
            what: "degree reduction",
            bound: if weights_ok { bound } else { f64::INFINITY },
            tolerance,
        })
    }
}

impl NurbsCurve {
    /// Degree reduction from `p` to `p - 1` (NURBS Book A5.11 DegreeReduceCurve, Bezier
    /// reduction eqs. 5.41-5.46; seed 000 eqs. 2-66 .. 2-69). Returns the reduced curve and
    /// an upper bound of the parametric deviation `max |C(u) - C'(u)|` over the domain (in
    /// model units, see the module notes for how it is derived).
    ///
    /// Every interior knot's multiplicity drops by one (continuity is kept); the result is
    /// clamped, on the same domain, rational iff the input is. A curve obtained by degree
    /// elevation comes back exactly (bound at rounding level, which grows with the ratio of
    /// the domain length to the shortest knot span: knot removal divides by it).
    ///
    /// Errors: degree 1 or a negative/NaN tolerance ([`GeometryError::InvalidArgument`]);
    /// bound above `tolerance`, or not finite (a reduced weight could reach 0), or a reduced
    /// weight <= 0 ([`GeometryError::ToleranceExceeded`], carrying the bound).
    pub fn reduce(&self, tolerance: f64) -> Result<(NurbsCurve, f64), GeometryError> {
        let p = self.degree();
        check_reduction(p, tolerance)?;
        let rational = self.is_rational();
        let norm: &Norm<'_> = if rational { &norm4 } else { &norm3 };
        let frame = Frame::of(self.control_points());
        let flat = frame.lift(self.control_points(), |i| self.weight(i));
        let (rk, red, e) = reduce_flat(p, self.knots(), &flat, 4, norm);
        let (red, e) = refine(p, self.knots(), &flat, rk.as_slice(), red, e, norm);
        let wmin = self
            .weights()
            .map_or(1.0, |w| w.iter().copied().fold(f64::INFINITY, f64::min));
        let bound = frame.bound(e, rational, wmin);
        accept(&red, rational, bound, tolerance)?;
        let (points, weights) = frame.project(&red, rational, self.dimension());
        let c = NurbsCurve::with_dimension(
            p - 1,
            rk,
            points,
            rational.then_some(weights),
            self.dimension(),
        )?;
        Ok((c, bound))
    }
}

impl NurbsSurface {
    /// Degree reduction by one in u (A5.11 applied to every row of the net at once, as
    /// A5.10 does for elevation). The bound covers the whole surface: at fixed v the surface
    /// error is a convex combination of the rows' errors, so the per-row maximum bounds it.
    /// Same errors as [`NurbsCurve::reduce`].
    pub fn reduce_u(&self, tolerance: f64) -> Result<(NurbsSurface, f64), GeometryError> {
        reduce_surface(self, tolerance, false)
    }

    /// Degree reduction by one in v (the net is transposed, reduced in its first index and
    /// transposed back). Same errors as [`NurbsCurve::reduce`].
    pub fn reduce_v(&self, tolerance: f64) -> Result<(NurbsSurface, f64), GeometryError> {
        reduce_surface(self, tolerance, true)
    }
}

fn reduce_surface(
    s: &NurbsSurface,
    tolerance: f64,
    in_v: bool,
) -> Result<(NurbsSurface, f64), GeometryError> {
    let (p, knots) = if in_v {
        (s.degree_v(), s.knots_v())
    } else {
        (s.degree_u(), s.knots_u())
    };
    check_reduction(p, tolerance)?;
    let rational = s.is_rational();
    let (points, weights) = if in_v {
        (
            s.control_points().transposed(),
            s.weights().map(Grid::transposed),
        )
    } else {
        (s.control_points().clone(), s.weights().cloned())
    };
    let rows = points.nv();
    let frame = Frame::of(points.as_slice());
    let flat = frame.lift(points.as_slice(), |i| {
        weights.as_ref().map_or(1.0, |w| w.as_slice()[i])
    });
    let point_norm: fn(&[f64]) -> f64 = if rational { norm4 } else { norm3 };
    let row_norm = move |v: &[f64]| v.chunks_exact(4).map(point_norm).fold(0.0, f64::max);
    let (rk, red, e) = reduce_flat(p, knots, &flat, 4 * rows, &row_norm);
    let wmin = weights.as_ref().map_or(1.0, |w| {
        w.as_slice().iter().copied().fold(f64::INFINITY, f64::min)
    });
    let bound = frame.bound(e, rational, wmin);
    accept(&red, rational, bound, tolerance)?;
    let (pts, ws) = frame.project(&red, rational, s.dimension());
    let n = pts.len() / rows;
    let shape = || GeometryError::InvalidArgument("reduced net shape".into());
    let mut pts = Grid::from_u_major(n, rows, pts).ok_or_else(shape)?;
    let mut ws = Grid::from_u_major(n, rows, ws).ok_or_else(shape)?;
    if in_v {
        pts = pts.transposed();
        ws = ws.transposed();
    }
    let (du, dv) = if in_v { (0, 1) } else { (1, 0) };
    let (ku, kv) = if in_v {
        (s.knots_u().to_vec(), rk)
    } else {
        (rk, s.knots_v().to_vec())
    };
    let out = NurbsSurface::with_dimension(
        s.degree_u() - du,
        s.degree_v() - dv,
        ku,
        kv,
        pts,
        rational.then_some(ws),
        s.dimension(),
    )?;
    Ok((out, bound))
}
