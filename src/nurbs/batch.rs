//! Fast batch evaluation: many points (and first derivatives) of one curve or surface per
//! call, for the HTTP/CLI batch APIs, tessellation and sampling.
//!
//! What makes it fast, compared with calling [`NurbsCurve::point_at`] in a loop:
//! - the poles are packed once per call (or once per [`CurveEvaluator`] /
//!   [`SurfaceEvaluator`]) as `[x, y, z, w]`, contiguous in memory;
//! - the kernels are monomorphised per degree: degrees 1-5 (equal in u and v for surfaces)
//!   with the degree as a constant, so every loop unrolls and A2.2's scratch arrays become
//!   registers (`kernels::basis`); others with scratch arrays of the tier's size (`p < 8`,
//!   else [`MAX_DEGREE`]) chosen once per call;
//! - the knot span comes from a per-evaluator lookup (`kernels::SpanIndex`: equal buckets
//!   over the domain and a short scan) instead of A2.1's binary search, with the same result;
//! - surfaces of equal degree 1-5 evaluate random points two at a time, the A2.2 recurrences
//!   of both as the lanes of packed operations (`kernels::basis_pair`);
//! - first derivatives of the basis come from the last level of A2.2 at no extra division
//!   ([`basis_funs_ders1`]);
//! - sorted parameters reuse the previous knot span (incremental span search instead of
//!   A2.1's binary search);
//! - grids ([`NurbsSurface::evaluate_grid`]) compute every u-basis and v-basis once, and the
//!   v-contraction `T_i(v) = sum_l N_l(v) w_ij P_ij` once per (row, v): a grid point then
//!   costs `p + 1` four-component multiply-adds.
//!
//! **Exactness:** every point (except [`CurveEvaluator::points_sorted_bezier`], which is
//! within rounding) equals the single-point [`NurbsCurve::point_at`] /
//! [`NurbsSurface::point_at`] bit for bit: the kernels perform the same floating-point
//! operations in the same order (A2.2 basis functions, `f = N w`, `t += f P`, division by the
//! weight last). The tests check it.
//!
//! **Errors:** a parameter outside the domain stops the call with
//! [`GeometryError::OutOfDomain`] naming it; `out` then holds the values computed before it.

use super::basis::{basis_funs, basis_funs_ders1, basis_funs_ders1_in, basis_funs_in};
use super::kernels::{SpanIndex, basis, basis_lanes, basis_pair};
use super::knots::find_span;
use super::{GeometryError, Grid, MAX_DEGREE, NurbsCurve, NurbsSurface, Point3};

/// The knot span of `u`, trying `hint` and the spans after it first (parameters sorted
/// ascending hit the hint or its successors). Always the span A2.1
/// ([`find_span`]) returns.
#[inline]
fn span_from_hint(p: usize, poles: usize, knots: &[f64], u: f64, hint: usize) -> usize {
    // Only below the domain end: there A2.1 has its own rule (last non-empty span).
    if hint >= p && hint < poles && u >= knots[hint] && u < knots[poles] {
        // Bounded forward scan; a large jump falls back to the binary search. Since
        // u < knots[poles], the scan stops at s <= poles - 1 at the latest.
        for s in hint..(hint + 8).min(poles) {
            if u < knots[s + 1] {
                return s;
            }
        }
    }
    find_span(p, poles, knots, u)
}

fn check_range(t: f64, (start, end): (f64, f64)) -> Result<(), GeometryError> {
    if t >= start && t <= end {
        Ok(())
    } else {
        Err(GeometryError::OutOfDomain { t, start, end })
    }
}

fn reserve<T>(out: &mut Vec<T>, n: usize) -> Result<(), GeometryError> {
    out.try_reserve(n).map_err(|_| {
        GeometryError::InvalidArgument(format!("cannot allocate {n} evaluation results"))
    })
}

/// The length of the leading run of `xs` inside `[a, b)` (`[a, b]` when `CLOSED`); NaN is
/// outside. Tests eight values at a time without branching (the common case is a long run
/// of sorted parameters), then finds the end in the last block.
#[inline(always)]
fn run_len<const CLOSED: bool>(xs: &[f64], a: f64, b: f64) -> usize {
    let inside = |x: f64| (x >= a) & if CLOSED { x <= b } else { x < b };
    let mut n = 0;
    for block in xs.chunks_exact(8) {
        if !block.iter().fold(true, |all, &x| all & inside(x)) {
            break;
        }
        n += 8;
    }
    let tail = xs.get(n..).unwrap_or(&[]);
    n + tail.iter().position(|&x| !inside(x)).unwrap_or(tail.len())
}

/// Packs Euclidean poles and weights as `[x, y, z, w]` (`w = 1` when polynomial).
fn pack(points: &[Point3], weight: impl Fn(usize) -> f64) -> Vec<[f64; 4]> {
    points
        .iter()
        .enumerate()
        .map(|(i, q)| [q[0], q[1], q[2], weight(i)])
        .collect()
}

/// Whether the scratch size `N` comes from one of [`by_degree!`]'s exact arms, where the
/// degree is `N - 1`, a compile-time constant.
const fn exact(n: usize) -> bool {
    n <= 6
}

/// Calls `$e` with the const scratch size `N` and the degree as a literal for degrees 1-5
/// (so the kernels are fully unrolled), else with the tier's size and the runtime degree.
macro_rules! by_degree {
    ($p:expr, |$n:ident, $deg:ident| $e:expr) => {
        match $p {
            1 => {
                const $n: usize = 2;
                let $deg = 1;
                $e
            }
            2 => {
                const $n: usize = 3;
                let $deg = 2;
                $e
            }
            3 => {
                const $n: usize = 4;
                let $deg = 3;
                $e
            }
            4 => {
                const $n: usize = 5;
                let $deg = 4;
                $e
            }
            5 => {
                const $n: usize = 6;
                let $deg = 5;
                $e
            }
            d if d < 8 => {
                const $n: usize = 8;
                let $deg = d;
                $e
            }
            d => {
                const $n: usize = MAX_DEGREE + 1;
                let $deg = d;
                $e
            }
        }
    };
}

/// Parameters evaluated together by the sorted curve path's lane kernel.
const LANES: usize = 4;

/// A curve prepared for repeated evaluation: packed poles, reusable across calls.
#[derive(Debug, Clone)]
pub struct CurveEvaluator<'a> {
    curve: &'a NurbsCurve,
    poles: Vec<[f64; 4]>,
    spans: SpanIndex,
}

impl<'a> CurveEvaluator<'a> {
    /// Packs the curve's poles once.
    pub fn new(curve: &'a NurbsCurve) -> Self {
        let poles = pack(curve.control_points(), |i| curve.weight(i));
        let spans = SpanIndex::new(curve.degree(), poles.len(), curve.knots());
        CurveEvaluator {
            curve,
            poles,
            spans,
        }
    }

    /// The curve evaluated.
    pub fn curve(&self) -> &NurbsCurve {
        self.curve
    }

    /// The point at `u` (A3.1 / A4.1), bit-identical to [`NurbsCurve::point_at`].
    pub fn point(&self, u: f64) -> Result<Point3, GeometryError> {
        check_range(u, self.curve.domain())?;
        let span = self.spans.find(self.curve.knots(), u);
        Ok(by_degree!(self.curve.degree(), |N, p| self
            .point_in_span::<N>(p, u, span)))
    }

    /// The point and first derivative `[C(u), C'(u)]` at `u`; `C(u)` is bit-identical to
    /// [`NurbsCurve::point_at`], `C'` follows A3.2 + A4.2 with `d = 1`.
    pub fn point_and_derivative(&self, u: f64) -> Result<[Point3; 2], GeometryError> {
        check_range(u, self.curve.domain())?;
        let span = self.spans.find(self.curve.knots(), u);
        Ok(by_degree!(self.curve.degree(), |N, p| self
            .point_and_derivative_in_span::<N>(p, u, span)))
    }

    /// The points at `us` (any order), appended to `out` after clearing it.
    pub fn points(&self, us: &[f64], out: &mut Vec<Point3>) -> Result<(), GeometryError> {
        by_degree!(self.curve.degree(), |N, p| self
            .points_impl::<N, false, false, _>(p, us, out, |o, x| o.push(x[0])))
    }

    /// The points at `us`, fastest when `us` is sorted ascending (the knot span of the
    /// previous parameter is tried first); correct for any order.
    pub fn points_sorted(&self, us: &[f64], out: &mut Vec<Point3>) -> Result<(), GeometryError> {
        by_degree!(self.curve.degree(), |N, p| self
            .points_impl::<N, true, false, _>(p, us, out, |o, x| o.push(x[0])))
    }

    /// `[C(u), C'(u)]` for every `u` in `us` (any order; sorted is faster), appended to `out`
    /// after clearing it.
    pub fn points_and_derivatives(
        &self,
        us: &[f64],
        out: &mut Vec<[Point3; 2]>,
    ) -> Result<(), GeometryError> {
        by_degree!(self.curve.degree(), |N, p| self
            .points_impl::<N, true, true, _>(p, us, out, |o, x| o.push(x)))
    }

    /// The points at sorted parameters by the per-span **Bezier form**: when the knot span
    /// changes, its Bezier poles are computed once (blossoms `b(a^(p-i), b^i)` by de Boor's
    /// algorithm on the homogeneous poles, NURBS Book 5.2 / seed 000 blossoming), then each
    /// point is a Bernstein combination (A1.3 AllBernstein) at `t = (u - a) / (b - a)`: no
    /// division per point for polynomial curves, one for rational ones. The parameters of a
    /// span are found as one run (block-wise range test) and evaluated in a tight loop. The
    /// fastest path for sampling grids (about 7x [`points_sorted`](Self::points_sorted) for a
    /// cubic).
    ///
    /// Not bit-identical to [`NurbsCurve::point_at`]: both round differently, and the
    /// difference is of the order of the rounding of either: relative to the size of the
    /// span's homogeneous poles over the weight at `u`, at most `(p + 1) 2.5e-16` in the
    /// tests (`1e-15` for cubics; observed `<= 4.5e-16` for `p <= 3`), polynomial and
    /// rational; within `1e-14` of the model size (control-point bounding-box diagonal) for
    /// degrees 1..=9, clamped or not (`tests/nurbs_batch_kernels.rs`). A parameter exactly at
    /// an interior knot belongs to the span A2.1 gives (the one starting there). Unsorted
    /// input is correct, only slower.
    pub fn points_sorted_bezier(
        &self,
        us: &[f64],
        out: &mut Vec<Point3>,
    ) -> Result<(), GeometryError> {
        if self.curve.is_rational() {
            by_degree!(self.curve.degree(), |N, p| self
                .bezier_impl::<N, true>(p, us, out))
        } else {
            by_degree!(self.curve.degree(), |N, p| self
                .bezier_impl::<N, false>(p, us, out))
        }
    }

    /// The Bezier-form loop: one span at a time, the Bezier poles computed once for the run of
    /// parameters that fall in it, then a tight loop over that run (no span test, no capacity
    /// check per point: the run is known before the points are written).
    #[inline(always)]
    fn bezier_impl<const N: usize, const RATIONAL: bool>(
        &self,
        p: usize,
        us: &[f64],
        out: &mut Vec<Point3>,
    ) -> Result<(), GeometryError> {
        let p = if exact(N) { N - 1 } else { p };
        out.clear();
        reserve(out, us.len())?;
        let knots = self.curve.knots();
        let dom = self.curve.domain();
        let end_span = self.spans.end_span();
        let mut q = [[0.0; 4]; N];
        let mut rest = us;
        while let Some(&u) = rest.first() {
            check_range(u, dom)?;
            let s = self.spans.find(knots, u);
            let (a, b) = (knots[s], knots[s + 1]);
            let inv = 1.0 / (b - a);
            self.bezier_poles(p, s, &mut q);
            // The run of parameters in this span: [a, b), closed at the domain end, whose
            // end A2.1 assigns to the last non-empty span. NaN ends the run (then fails the
            // range check above); `max(1)` guarantees progress whatever the input.
            let run = if s == end_span {
                run_len::<true>(rest, a, b)
            } else {
                run_len::<false>(rest, a, b)
            }
            .max(1);
            let (now, later) = rest.split_at(run);
            rest = later;
            let q = &q;
            out.extend(now.iter().map(move |&x| {
                // The closure's body is compiled on its own (inside `fold`): restate the
                // degree as the constant it is so that every loop unrolls.
                let p = if exact(N) { N - 1 } else { p };
                let t = (x - a) * inv;
                let bs = bernstein::<N>(p, t, 1.0 - t);
                if RATIONAL {
                    let mut c = [0.0; 4];
                    for (bk, qk) in bs.iter().zip(&q[..=p]) {
                        for i in 0..4 {
                            c[i] += bk * qk[i];
                        }
                    }
                    [c[0] / c[3], c[1] / c[3], c[2] / c[3]]
                } else {
                    let mut c = [0.0; 3];
                    for (bk, qk) in bs.iter().zip(&q[..=p]) {
                        for i in 0..3 {
                            c[i] += bk * qk[i];
                        }
                    }
                    c
                }
            }));
        }
        Ok(())
    }

    /// Homogeneous Bezier poles of knot span `s`: `Q_i = blossom(a^(p-i), b^i)`, each by
    /// de Boor's algorithm with the argument `a` on the first `p - i` levels and `b` on the
    /// rest (the blossom is symmetric); every step is a convex combination, so the poles are
    /// accurate to a few ulps of the span's homogeneous poles.
    #[inline(always)]
    fn bezier_poles<const N: usize>(&self, p: usize, s: usize, q: &mut [[f64; 4]; N]) {
        let knots = self.curve.knots();
        let (a, b) = (knots[s], knots[s + 1]);
        let rational = self.curve.is_rational();
        for (i, qi) in q.iter_mut().enumerate().take(p + 1) {
            let mut d = [[0.0; 4]; N];
            for (j, dj) in d.iter_mut().enumerate().take(p + 1) {
                let pw = self.poles[s - p + j];
                let w = if rational { pw[3] } else { 1.0 };
                *dj = [pw[0] * w, pw[1] * w, pw[2] * w, w];
            }
            for r in 1..=p {
                let t = if r <= p - i { a } else { b };
                for j in (r..=p).rev() {
                    let k = s - p + j;
                    let alpha = (t - knots[k]) / (knots[k + p + 1 - r] - knots[k]);
                    let prev = d[j - 1];
                    for c in 0..4 {
                        d[j][c] = (1.0 - alpha) * prev[c] + alpha * d[j][c];
                    }
                }
            }
            *qi = d[p];
        }
    }

    /// The batch loop. `D1`: compute the first derivative too; `SORTED`: incremental span
    /// search. `p` is a literal at the call sites for low degrees, so everything unrolls.
    #[inline(always)]
    fn points_impl<const N: usize, const SORTED: bool, const D1: bool, T>(
        &self,
        p: usize,
        us: &[f64],
        out: &mut Vec<T>,
        push: impl Fn(&mut Vec<T>, [Point3; 2]),
    ) -> Result<(), GeometryError> {
        out.clear();
        reserve(out, us.len())?;
        let (knots, n) = (self.curve.knots(), self.poles.len());
        let dom = self.curve.domain();
        let mut span = p;
        let mut rest = us;
        while let Some((&u, tail)) = rest.split_first() {
            // Sorted points only (no derivative, compile-time degree): four parameters of
            // one knot span at a time through the lane kernel, bit-identical to one at a
            // time. Where four do not share a span (a knot between them), one parameter
            // goes the single way and the next four are tried.
            if SORTED && !D1 && exact(N) {
                if let Some((&four, after)) = rest.split_first_chunk::<LANES>() {
                    if let Some(s) = self.common_span(p, four, span) {
                        span = s;
                        for q in self.points_in_span_lanes::<N>(four, s) {
                            push(out, [q, [0.0; 3]]);
                        }
                        rest = after;
                        continue;
                    }
                }
            }
            rest = tail;
            check_range(u, dom)?;
            span = if SORTED {
                span_from_hint(p, n, knots, u, span)
            } else {
                self.spans.find(knots, u)
            };
            if D1 {
                push(out, self.point_and_derivative_in_span::<N>(p, u, span));
            } else {
                push(out, [self.point_in_span::<N>(p, u, span), [0.0; 3]]);
            }
        }
        Ok(())
    }

    /// The knot span shared by `us` (hint: the previous span), if they are all inside the
    /// domain, ascending, and in one span. A2.1's span is non-decreasing in `u`, so equal
    /// spans at both ends of an ascending run mean one span for all of it.
    #[inline(always)]
    fn common_span(&self, p: usize, us: [f64; LANES], hint: usize) -> Option<usize> {
        let dom = self.curve.domain();
        let ascending = us.windows(2).all(|w| w[0] <= w[1]);
        let inside = us.iter().all(|&u| u >= dom.0 && u <= dom.1);
        if !(ascending && inside) {
            return None;
        }
        let (knots, n) = (self.curve.knots(), self.poles.len());
        let first = span_from_hint(p, n, knots, us[0], hint);
        let last = span_from_hint(p, n, knots, us[LANES - 1], first);
        (first == last).then_some(first)
    }

    /// [`Self::point_in_span`] for [`LANES`] parameters of one span (`N - 1` a compile-time
    /// degree): the same operations in the same order in every lane.
    #[inline(always)]
    fn points_in_span_lanes<const N: usize>(
        &self,
        us: [f64; LANES],
        span: usize,
    ) -> [Point3; LANES] {
        let p = N - 1;
        let nb = basis_lanes::<N, LANES>(span, us, self.curve.knots());
        let poles = &self.poles[span - p..=span];
        let mut out = [[0.0; 3]; LANES];
        if self.curve.is_rational() {
            let mut c = [[0.0; 4]; LANES];
            for (nj, q) in nb.iter().zip(poles) {
                for l in 0..LANES {
                    let f = nj[l] * q[3];
                    c[l][0] += f * q[0];
                    c[l][1] += f * q[1];
                    c[l][2] += f * q[2];
                    c[l][3] += f;
                }
            }
            for l in 0..LANES {
                out[l] = [c[l][0] / c[l][3], c[l][1] / c[l][3], c[l][2] / c[l][3]];
            }
        } else {
            for (nj, q) in nb.iter().zip(poles) {
                for l in 0..LANES {
                    out[l][0] += nj[l] * q[0];
                    out[l][1] += nj[l] * q[1];
                    out[l][2] += nj[l] * q[2];
                }
            }
        }
        out
    }

    /// Same operations, in the same order, as `NurbsCurve::point_at_unchecked`.
    #[inline(always)]
    fn point_in_span<const N: usize>(&self, p: usize, u: f64, span: usize) -> Point3 {
        // exact(N) only for by_degree!'s exact arms: a compile-time degree.
        let p = if exact(N) { N - 1 } else { p };
        let nb: [f64; N] = if exact(N) {
            basis::<N>(span, u, self.curve.knots())
        } else {
            let mut nb = [0.0; N];
            basis_funs_in::<N>(span, u, p, self.curve.knots(), &mut nb);
            nb
        };
        let poles = &self.poles[span - p..=span];
        if self.curve.is_rational() {
            let mut c = [0.0; 4];
            for (nj, q) in nb.iter().zip(poles) {
                let f = nj * q[3];
                c[0] += f * q[0];
                c[1] += f * q[1];
                c[2] += f * q[2];
                c[3] += f;
            }
            [c[0] / c[3], c[1] / c[3], c[2] / c[3]]
        } else {
            let mut c = [0.0; 3];
            for (nj, q) in nb.iter().zip(poles) {
                c[0] += nj * q[0];
                c[1] += nj * q[1];
                c[2] += nj * q[2];
            }
            c
        }
    }

    #[inline(always)]
    fn point_and_derivative_in_span<const N: usize>(
        &self,
        p: usize,
        u: f64,
        span: usize,
    ) -> [Point3; 2] {
        let p = if exact(N) { N - 1 } else { p };
        let mut n0 = [0.0; N];
        let mut n1 = [0.0; N];
        basis_funs_ders1_in::<N>(span, u, p, self.curve.knots(), &mut n0, &mut n1);
        let poles = &self.poles[span - p..=span];
        let mut c = [0.0; 4];
        let mut d = [0.0; 4];
        if self.curve.is_rational() {
            for ((a, b), q) in n0.iter().zip(&n1).zip(poles) {
                let f = a * q[3];
                c[0] += f * q[0];
                c[1] += f * q[1];
                c[2] += f * q[2];
                c[3] += f;
                let g = b * q[3];
                d[0] += g * q[0];
                d[1] += g * q[1];
                d[2] += g * q[2];
                d[3] += g;
            }
            let pt = [c[0] / c[3], c[1] / c[3], c[2] / c[3]];
            // A4.2 with k = 1: C' = (A' - w' C) / w.
            let der = [
                (d[0] - d[3] * pt[0]) / c[3],
                (d[1] - d[3] * pt[1]) / c[3],
                (d[2] - d[3] * pt[2]) / c[3],
            ];
            [pt, der]
        } else {
            for ((a, b), q) in n0.iter().zip(&n1).zip(poles) {
                c[0] += a * q[0];
                c[1] += a * q[1];
                c[2] += a * q[2];
                d[0] += b * q[0];
                d[1] += b * q[1];
                d[2] += b * q[2];
            }
            [[c[0], c[1], c[2]], [d[0], d[1], d[2]]]
        }
    }
}

impl NurbsCurve {
    /// The points at `us` in any order (A3.1 / A4.1), written to `out` (cleared first);
    /// bit-identical to [`point_at`](Self::point_at) for each.
    pub fn points_at(&self, us: &[f64], out: &mut Vec<Point3>) -> Result<(), GeometryError> {
        CurveEvaluator::new(self).points(us, out)
    }

    /// [`points_at`](Self::points_at) for parameters sorted ascending (a sampling grid):
    /// the knot span is found incrementally. Correct, only slower, for unsorted input.
    pub fn points_at_sorted(&self, us: &[f64], out: &mut Vec<Point3>) -> Result<(), GeometryError> {
        CurveEvaluator::new(self).points_sorted(us, out)
    }

    /// [`points_at_sorted`](Self::points_at_sorted) through the per-span Bezier form: the
    /// fastest path for sampling, equal to `point_at` up to rounding (not bit for bit); see
    /// [`CurveEvaluator::points_sorted_bezier`].
    pub fn points_at_sorted_bezier(
        &self,
        us: &[f64],
        out: &mut Vec<Point3>,
    ) -> Result<(), GeometryError> {
        CurveEvaluator::new(self).points_sorted_bezier(us, out)
    }

    /// `[C(u), C'(u)]` for each `u` in `us`, written to `out` (cleared first).
    pub fn points_and_derivatives_at(
        &self,
        us: &[f64],
        out: &mut Vec<[Point3; 2]>,
    ) -> Result<(), GeometryError> {
        CurveEvaluator::new(self).points_and_derivatives(us, out)
    }
}

/// The Bernstein polynomials of degree `p` at `t` (`t1 = 1 - t`): A1.3 AllBernstein, with
/// the cubic written out (register-only; the loop stalls on its scratch array).
#[inline(always)]
fn bernstein<const N: usize>(p: usize, t: f64, t1: f64) -> [f64; N] {
    let mut b = [0.0; N];
    if N == 4 && p == 3 {
        let (tt, tt1) = (t * t, t1 * t1);
        b[0] = tt1 * t1;
        b[1] = 3.0 * t * tt1;
        b[2] = 3.0 * tt * t1;
        b[3] = tt * t;
        return b;
    }
    b[0] = 1.0;
    for j in 1..=p {
        let mut saved = 0.0;
        for bk in &mut b[..j] {
            let temp = *bk;
            *bk = saved + t1 * temp;
            saved = t * temp;
        }
        b[j] = saved;
    }
    b
}

/// A surface prepared for repeated evaluation: the control net packed u-major as
/// `[x, y, z, w]`, reusable across calls.
#[derive(Debug, Clone)]
pub struct SurfaceEvaluator<'a> {
    surface: &'a NurbsSurface,
    poles: Vec<[f64; 4]>,
    nu: usize,
    nv: usize,
    spans_u: SpanIndex,
    spans_v: SpanIndex,
    /// The poles as `[x, y, z, 1]` and their weights apart: `t += f [x, y, z, 1]` is
    /// `t[0..3] += f P, t[3] += f` exactly (`f * 1 = f`), as one 4-wide operation.
    unit: Vec<[f64; 4]>,
    weights: Vec<f64>,
}

/// The scratch for one grid evaluation: spans and basis values per parameter.
struct Bases {
    spans: Vec<usize>,
    /// `(d + 1) * (p + 1)` values per parameter (A2.3 table).
    vals: Vec<f64>,
    stride: usize,
}

impl Bases {
    /// Spans (incremental search) and basis functions (`d = 0`) or basis functions and
    /// first derivatives (`d = 1`, layout of A2.3) of every parameter, checking each against
    /// the domain.
    fn new(
        ts: &[f64],
        p: usize,
        poles: usize,
        knots: &[f64],
        d: usize,
    ) -> Result<Self, GeometryError> {
        let dom = (knots[p], knots[poles]);
        let stride = (d + 1) * (p + 1);
        let mut spans = Vec::new();
        reserve(&mut spans, ts.len())?;
        let mut vals = Vec::new();
        let total = ts.len().checked_mul(stride).ok_or_else(|| {
            GeometryError::InvalidArgument("too many grid parameters".to_string())
        })?;
        reserve(&mut vals, total)?;
        vals.resize(total, 0.0);
        let mut span = p;
        for (k, &t) in ts.iter().enumerate() {
            check_range(t, dom)?;
            span = span_from_hint(p, poles, knots, t, span);
            spans.push(span);
            let row = &mut vals[k * stride..(k + 1) * stride];
            // Scratch sized by the degree (zeroing the largest scratch for every parameter
            // was most of a small grid's time); the same arithmetic in every size.
            if d == 0 {
                basis_funs(span, t, p, knots, row);
            } else {
                let (n0, n1) = row.split_at_mut(p + 1);
                basis_funs_ders1(span, t, p, knots, n0, n1);
            }
        }
        Ok(Bases {
            spans,
            vals,
            stride,
        })
    }

    /// The range of pole rows `first..=last` any parameter touches.
    fn rows(&self, p: usize) -> (usize, usize) {
        let lo = self.spans.iter().min().map_or(p, |&s| s - p);
        let hi = self.spans.iter().max().copied().unwrap_or(p);
        (lo, hi)
    }
}

/// Number of `[f64; 4]` entries of v-contracted rows kept at once in grid evaluation
/// (2 MiB): bounds memory whatever the grid and net sizes.
const GRID_BLOCK: usize = 1 << 16;

impl<'a> SurfaceEvaluator<'a> {
    /// Packs the surface's control net once.
    pub fn new(surface: &'a NurbsSurface) -> Self {
        let net = surface.control_points();
        let (nu, nv) = (net.nu(), net.nv());
        let poles = match surface.weights() {
            Some(w) => pack(net.as_slice(), |k| w.as_slice()[k]),
            None => pack(net.as_slice(), |_| 1.0),
        };
        SurfaceEvaluator {
            surface,
            nu,
            nv,
            spans_u: SpanIndex::new(surface.degree_u(), nu, surface.knots_u()),
            spans_v: SpanIndex::new(surface.degree_v(), nv, surface.knots_v()),
            unit: poles.iter().map(|q| [q[0], q[1], q[2], 1.0]).collect(),
            weights: poles.iter().map(|q| q[3]).collect(),
            poles,
        }
    }

    /// The surface evaluated.
    pub fn surface(&self) -> &NurbsSurface {
        self.surface
    }

    /// The point at `(u, v)` (A3.5 / A4.3), bit-identical to [`NurbsSurface::point_at`].
    pub fn point(&self, u: f64, v: f64) -> Result<Point3, GeometryError> {
        self.surface.check_parameter(u, v)?;
        let (p, q) = (self.surface.degree_u(), self.surface.degree_v());
        Ok(if p == q {
            by_degree!(p, |N, d| self.kernel::<N, false, { exact(N) }>(d, d, u, v)
                [0])
        } else {
            by_degree!(p.max(q), |N, _d| self.kernel::<N, false, false>(p, q, u, v)
                [0])
        })
    }

    /// `[S, S_u, S_v]` at `(u, v)`: `S` bit-identical to [`NurbsSurface::point_at`], the
    /// partials by A3.6 + A4.4 with `d = 1`.
    pub fn point_and_partials(&self, u: f64, v: f64) -> Result<[Point3; 3], GeometryError> {
        self.surface.check_parameter(u, v)?;
        let (p, q) = (self.surface.degree_u(), self.surface.degree_v());
        Ok(if p == q {
            by_degree!(p, |N, d| self.kernel::<N, true, { exact(N) }>(d, d, u, v))
        } else {
            by_degree!(p.max(q), |N, _d| self.kernel::<N, true, false>(p, q, u, v))
        })
    }

    /// The points at `uvs` (any order), written to `out` (cleared first).
    pub fn points(&self, uvs: &[[f64; 2]], out: &mut Vec<Point3>) -> Result<(), GeometryError> {
        let (p, q) = (self.surface.degree_u(), self.surface.degree_v());
        if p == q {
            by_degree!(p, |N, d| self.points_impl::<N, false, { exact(N) }, _>(
                d,
                d,
                uvs,
                out,
                |x| x[0]
            ))
        } else {
            by_degree!(p.max(q), |N, _d| self.points_impl::<N, false, false, _>(
                p,
                q,
                uvs,
                out,
                |x| x[0]
            ))
        }
    }

    /// `[S, S_u, S_v]` at `uvs` (any order), written to `out` (cleared first).
    pub fn points_and_partials(
        &self,
        uvs: &[[f64; 2]],
        out: &mut Vec<[Point3; 3]>,
    ) -> Result<(), GeometryError> {
        let (p, q) = (self.surface.degree_u(), self.surface.degree_v());
        if p == q {
            by_degree!(p, |N, d| self.points_impl::<N, true, { exact(N) }, _>(
                d,
                d,
                uvs,
                out,
                |x| x
            ))
        } else {
            by_degree!(p.max(q), |N, _d| self.points_impl::<N, true, false, _>(
                p,
                q,
                uvs,
                out,
                |x| x
            ))
        }
    }

    #[inline(always)]
    fn points_impl<const N: usize, const D1: bool, const EXACT: bool, T>(
        &self,
        p: usize,
        q: usize,
        uvs: &[[f64; 2]],
        out: &mut Vec<T>,
        finish: impl Fn([Point3; 3]) -> T,
    ) -> Result<(), GeometryError> {
        out.clear();
        reserve(out, uvs.len())?;
        let ((u0, u1), (v0, v1)) = self.surface.domain();
        let check = |[u, v]: [f64; 2]| {
            check_range(u, (u0, u1))?;
            check_range(v, (v0, v1))
        };
        let mut rest = uvs;
        if EXACT && !D1 {
            // Two points per step: their computations are independent, and interleaved they
            // keep the core busy where one point's chain of dependent divisions would not.
            let mut pairs = uvs.chunks_exact(2);
            for pair in &mut pairs {
                let (a, b) = (pair[0], pair[1]);
                check(a)?;
                if let Err(e) = check(b) {
                    out.push(finish(self.kernel::<N, D1, EXACT>(p, q, a[0], a[1])));
                    return Err(e);
                }
                let [x, y] = self.point_pair::<N>(a, b);
                out.push(finish([x, [0.0; 3], [0.0; 3]]));
                out.push(finish([y, [0.0; 3], [0.0; 3]]));
            }
            rest = pairs.remainder();
        }
        for &[u, v] in rest {
            check([u, v])?;
            out.push(finish(self.kernel::<N, D1, EXACT>(p, q, u, v)));
        }
        Ok(())
    }

    /// Two points of a surface of degrees `N - 1` in both directions, computed side by side
    /// (the basis functions of both as the lanes of [`basis_pair`]); each bit-identical to
    /// `NurbsSurface::point_at` (the same operations as [`kernel`](Self::kernel)).
    #[inline(always)]
    fn point_pair<const N: usize>(&self, [ua, va]: [f64; 2], [ub, vb]: [f64; 2]) -> [Point3; 2] {
        let p = N - 1;
        let s = self.surface;
        let (ku, kv) = (s.knots_u(), s.knots_v());
        let (sua, sub) = (self.spans_u.find(ku, ua), self.spans_u.find(ku, ub));
        let (sva, svb) = (self.spans_v.find(kv, va), self.spans_v.find(kv, vb));
        let (bua, bub) = basis_pair::<N>(sua, ua, ku, sub, ub, ku);
        let (bva, bvb) = basis_pair::<N>(sva, va, kv, svb, vb, kv);
        let mut acc = [[0.0; 4]; 2];
        for k in 0..N {
            let sa = (sua - p + k) * self.nv + sva - p;
            let sb = (sub - p + k) * self.nv + svb - p;
            let (ra, rb) = (&self.unit[sa..sa + N], &self.unit[sb..sb + N]);
            let (wa, wb) = (&self.weights[sa..sa + N], &self.weights[sb..sb + N]);
            let mut ta = [0.0; 4];
            let mut tb = [0.0; 4];
            for l in 0..N {
                let fa = bva[l] * wa[l];
                let fb = bvb[l] * wb[l];
                for c in 0..4 {
                    ta[c] += fa * ra[l][c];
                    tb[c] += fb * rb[l][c];
                }
            }
            for c in 0..4 {
                acc[0][c] += bua[k] * ta[c];
                acc[1][c] += bub[k] * tb[c];
            }
        }
        acc.map(|a| [a[0] / a[3], a[1] / a[3], a[2] / a[3]])
    }

    /// The point (same operations, in the same order, as
    /// `NurbsSurface::point_at_unchecked`) and, when `D1`, the first partials. `EXACT`:
    /// both degrees are `N - 1`, a compile-time constant, so every loop unrolls.
    #[inline(always)]
    fn kernel<const N: usize, const D1: bool, const EXACT: bool>(
        &self,
        p: usize,
        q: usize,
        u: f64,
        v: f64,
    ) -> [Point3; 3] {
        let (p, q) = if EXACT { (N - 1, N - 1) } else { (p, q) };
        let s = self.surface;
        let su = self.spans_u.find(s.knots_u(), u);
        let sv = self.spans_v.find(s.knots_v(), v);
        let mut bu = [0.0; N];
        let mut bv = [0.0; N];
        let mut du = [0.0; N];
        let mut dv = [0.0; N];
        if D1 {
            basis_funs_ders1_in::<N>(su, u, p, s.knots_u(), &mut bu, &mut du);
            basis_funs_ders1_in::<N>(sv, v, q, s.knots_v(), &mut bv, &mut dv);
        } else if EXACT {
            (bu, bv) = basis_pair::<N>(su, u, s.knots_u(), sv, v, s.knots_v());
        } else {
            basis_funs_in::<N>(su, u, p, s.knots_u(), &mut bu);
            basis_funs_in::<N>(sv, v, q, s.knots_v(), &mut bv);
        }
        let mut acc = [[0.0; 4]; 3];
        for k in 0..=p {
            let start = (su - p + k) * self.nv + sv - q;
            let row = &self.poles[start..=start + q];
            let mut t = [0.0; 4];
            let mut t1 = [0.0; 4];
            for (l, pw) in row.iter().enumerate() {
                let f = bv[l] * pw[3];
                t[0] += f * pw[0];
                t[1] += f * pw[1];
                t[2] += f * pw[2];
                t[3] += f;
                if D1 {
                    let g = dv[l] * pw[3];
                    t1[0] += g * pw[0];
                    t1[1] += g * pw[1];
                    t1[2] += g * pw[2];
                    t1[3] += g;
                }
            }
            let nk = bu[k];
            for c in 0..4 {
                acc[0][c] += nk * t[c];
            }
            if D1 {
                let dk = du[k];
                for c in 0..4 {
                    acc[1][c] += dk * t[c];
                    acc[2][c] += nk * t1[c];
                }
            }
        }
        if D1 {
            project_partials(&acc)
        } else {
            let a = acc[0];
            [[a[0] / a[3], a[1] / a[3], a[2] / a[3]], [0.0; 3], [0.0; 3]]
        }
    }

    /// The points on the grid `us x vs`: `grid.get(i, j) = S(us[i], vs[j])`, bit-identical
    /// to [`NurbsSurface::point_at`]. Each u-basis and v-basis is computed once, and each
    /// v-contracted pole row once per `v`; parameters in ascending order are fastest (span
    /// search), any order is correct.
    pub fn grid(&self, us: &[f64], vs: &[f64]) -> Result<Grid<Point3>, GeometryError> {
        self.grid_impl::<0, Point3>(us, vs, |acc| {
            let a = acc[0];
            [a[0] / a[3], a[1] / a[3], a[2] / a[3]]
        })
    }

    /// `[S, S_u, S_v]` on the grid `us x vs` (see [`grid`](Self::grid)).
    pub fn grid_with_partials(
        &self,
        us: &[f64],
        vs: &[f64],
    ) -> Result<Grid<[Point3; 3]>, GeometryError> {
        self.grid_impl::<1, [Point3; 3]>(us, vs, project_partials)
    }

    /// Grid evaluation with first derivatives when `D = 1`. `acc[0]` is the homogeneous
    /// point, `acc[1]`, `acc[2]` its u and v partials (zero when `D = 0`).
    fn grid_impl<const D: usize, T: Copy + Default>(
        &self,
        us: &[f64],
        vs: &[f64],
        finish: impl Fn(&[[f64; 4]; 3]) -> T,
    ) -> Result<Grid<T>, GeometryError> {
        let s = self.surface;
        let (p, q) = (s.degree_u(), s.degree_v());
        let bu = Bases::new(us, p, self.nu, s.knots_u(), D)?;
        let bv = Bases::new(vs, q, self.nv, s.knots_v(), D)?;
        let total = us
            .len()
            .checked_mul(vs.len())
            .ok_or_else(|| GeometryError::InvalidArgument("grid size overflows".to_string()))?;
        let mut data: Vec<T> = Vec::new();
        reserve(&mut data, total)?;
        data.resize(total, T::default());
        if total == 0 {
            return Grid::from_u_major(us.len(), vs.len(), data)
                .ok_or_else(|| GeometryError::InvalidArgument("grid shape".to_string()));
        }
        let (row0, row1) = bu.rows(p);
        let rows = row1 - row0 + 1;
        // v-contracted rows for a block of v values: tv[(jl * rows + r) * (D + 1) + e] is
        // sum_l N^(e)_l(v) w P over pole row row0 + r (e = 0: value, 1: v-derivative).
        let block = (GRID_BLOCK / (rows * (D + 1))).clamp(1, vs.len());
        let mut tv: Vec<[f64; 4]> = Vec::new();
        reserve(&mut tv, block * rows * (D + 1))?;
        tv.resize(block * rows * (D + 1), [0.0; 4]);
        let nvs = vs.len();
        for j0 in (0..nvs).step_by(block) {
            let j1 = (j0 + block).min(nvs);
            for j in j0..j1 {
                let sv = bv.spans[j];
                let vals = &bv.vals[j * bv.stride..(j + 1) * bv.stride];
                let (n0, n1) = vals.split_at(q + 1);
                for r in 0..rows {
                    let start = (row0 + r) * self.nv + sv - q;
                    let prow = &self.poles[start..=start + q];
                    let base = ((j - j0) * rows + r) * (D + 1);
                    let mut t = [0.0; 4];
                    for (nl, pw) in n0.iter().zip(prow) {
                        let f = nl * pw[3];
                        t[0] += f * pw[0];
                        t[1] += f * pw[1];
                        t[2] += f * pw[2];
                        t[3] += f;
                    }
                    tv[base] = t;
                    if D == 1 {
                        let mut t1 = [0.0; 4];
                        for (nl, pw) in n1.iter().zip(prow) {
                            let f = nl * pw[3];
                            t1[0] += f * pw[0];
                            t1[1] += f * pw[1];
                            t1[2] += f * pw[2];
                            t1[3] += f;
                        }
                        tv[base + 1] = t1;
                    }
                }
            }
            for (i, &su) in bu.spans.iter().enumerate() {
                let vals = &bu.vals[i * bu.stride..(i + 1) * bu.stride];
                let (n0, n1) = vals.split_at(p + 1);
                let first = su - p - row0;
                let out_row = &mut data[i * nvs + j0..i * nvs + j1];
                for (jl, cell) in out_row.iter_mut().enumerate() {
                    let base = (jl * rows + first) * (D + 1);
                    let mut acc = [[0.0; 4]; 3];
                    for k in 0..=p {
                        let t = tv[base + k * (D + 1)];
                        let nk = n0[k];
                        for c in 0..4 {
                            acc[0][c] += nk * t[c];
                        }
                        if D == 1 {
                            let dk = n1[k];
                            let t1 = tv[base + k * (D + 1) + 1];
                            for c in 0..4 {
                                acc[1][c] += dk * t[c];
                                acc[2][c] += nk * t1[c];
                            }
                        }
                    }
                    *cell = finish(&acc);
                }
            }
        }
        Grid::from_u_major(us.len(), nvs, data)
            .ok_or_else(|| GeometryError::InvalidArgument("grid shape".to_string()))
    }
}

/// `[S, S_u, S_v]` from homogeneous `[A, A_u, A_v]` (A4.4 with `d = 1`:
/// `S_u = (A_u - w_u S) / w`).
#[inline]
fn project_partials(acc: &[[f64; 4]; 3]) -> [Point3; 3] {
    let [a, au, av] = *acc;
    let w = a[3];
    let pt = [a[0] / w, a[1] / w, a[2] / w];
    let d = |h: [f64; 4]| {
        [
            (h[0] - h[3] * pt[0]) / w,
            (h[1] - h[3] * pt[1]) / w,
            (h[2] - h[3] * pt[2]) / w,
        ]
    };
    [pt, d(au), d(av)]
}

impl NurbsSurface {
    /// The points at `uvs` (any order), written to `out` (cleared first); bit-identical to
    /// [`point_at`](Self::point_at). Reuse a [`SurfaceEvaluator`] across calls to pack the
    /// net only once.
    pub fn points_at(&self, uvs: &[[f64; 2]], out: &mut Vec<Point3>) -> Result<(), GeometryError> {
        SurfaceEvaluator::new(self).points(uvs, out)
    }

    /// `[S, S_u, S_v]` at `(u, v)` (A3.6 + A4.4 with `d = 1`); `S` is bit-identical to
    /// [`point_at`](Self::point_at). Reads the net directly (no packing); for many points use
    /// [`points_and_partials_at`](Self::points_and_partials_at) or a [`SurfaceEvaluator`].
    pub fn point_and_partials(&self, u: f64, v: f64) -> Result<[Point3; 3], GeometryError> {
        self.check_parameter(u, v)?;
        let aders = self.homogeneous_derivatives(u, v, 1);
        let acc = [aders[0][0], aders[1][0], aders[0][1]];
        let mut r = project_partials(&acc);
        // The point itself through the point_at arithmetic, so it matches bit for bit.
        r[0] = self.point_at_unchecked(u, v);
        Ok(r)
    }

    /// `[S, S_u, S_v]` at `uvs` (any order), written to `out` (cleared first).
    pub fn points_and_partials_at(
        &self,
        uvs: &[[f64; 2]],
        out: &mut Vec<[Point3; 3]>,
    ) -> Result<(), GeometryError> {
        SurfaceEvaluator::new(self).points_and_partials(uvs, out)
    }

    /// The points on the grid `us x vs` (`get(i, j) = S(us[i], vs[j])`), bit-identical to
    /// [`point_at`](Self::point_at); see [`SurfaceEvaluator::grid`].
    pub fn evaluate_grid(&self, us: &[f64], vs: &[f64]) -> Result<Grid<Point3>, GeometryError> {
        SurfaceEvaluator::new(self).grid(us, vs)
    }

    /// `[S, S_u, S_v]` on the grid `us x vs`; see [`SurfaceEvaluator::grid_with_partials`].
    pub fn evaluate_grid_with_partials(
        &self,
        us: &[f64],
        vs: &[f64],
    ) -> Result<Grid<[Point3; 3]>, GeometryError> {
        SurfaceEvaluator::new(self).grid_with_partials(us, vs)
    }
}
