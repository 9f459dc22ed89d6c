//! Clamping and unclamping (seed 000 section 2-29; NURBS Book section 12.2, A12.1
//! UnclampCurve), per end, for curves and per end and direction for surfaces.
//!
//! - **Clamping** an end inserts the end parameter (`u_p` or `u_{n+1}`) until its
//!   multiplicity is at least `p` (A5.1), then drops the knots and poles outside: the new
//!   end knot has multiplicity `p + 1` and the first/last pole is the end point. Exact; the
//!   domain is unchanged.
//! - **Unclamping** an end first clamps it, then replaces the `p` outer knots by the
//!   "wrap-around" values of seed formulas 2-168 / 2-169,
//!   `u_{p-i-1} = u_{p-i} - (u_{n-i+1} - u_{n-i})` and
//!   `u_{n+i+2} = u_{n+i+1} + (u_{p+i+1} - u_{p+i})`, `i = 0..p-1`,
//!   and computes the `p - 1` new poles at that end as A12.1 does (inverse knot insertion).
//!   The spacings are read from the curve clamped at *both* ends, whose last (first) span is
//!   never empty, so the new first (last) knot is always strictly below `u_p` (above
//!   `u_{n+1}`) and the result really is unclamped. Exact in exact arithmetic; the domain is
//!   unchanged. For a closed curve with C^(p-1) seam continuity these knots make the poles
//!   wrap (figure 2-125c), which [`periodic`](super::periodic) relies on.

use super::insert::{Bundle, Dir, insert_bundle};
use super::knots::multiplicity;
use super::{GeometryError, Hpoint, NurbsCurve, NurbsSurface};

/// Clamps the start of every row (exact).
pub(super) fn clamp_start_bundle(b: &Bundle) -> Bundle {
    let p = b.degree;
    let a = b.knots[p];
    let s = multiplicity(&b.knots, a);
    let ins = insert_bundle(b, a, p.saturating_sub(s));
    // k: last index of the run of `a`; the first non-empty span is [u_k, u_{k+1}] and only
    // poles k-p.. influence the domain. u_{k-p} is not used by the basis on that span, so it
    // may be set to `a` (A2.2 reads u_{k-p+1}..u_{k+p} only).
    let k = ins.knots.partition_point(|&x| x <= a) - 1;
    let first = k - p;
    let mut knots = vec![a; p + 1];
    knots.extend_from_slice(&ins.knots[k + 1..]);
    Bundle {
        degree: p,
        knots,
        rows: ins.rows.iter().map(|r| r[first..].to_vec()).collect(),
    }
}

/// Clamps the end of every row (exact).
pub(super) fn clamp_end_bundle(b: &Bundle) -> Bundle {
    let p = b.degree;
    let e = b.knots[b.poles()];
    let s = multiplicity(&b.knots, e);
    let ins = insert_bundle(b, e, p.saturating_sub(s));
    // lo: first index of the run of `e`; the last non-empty span is [u_{lo-1}, u_lo] and
    // only poles ..=lo-1 influence the domain.
    let lo = ins.knots.partition_point(|&x| x < e);
    let mut knots = ins.knots[..lo].to_vec();
    knots.extend(std::iter::repeat_n(e, p + 1));
    Bundle {
        degree: p,
        knots,
        rows: ins.rows.iter().map(|r| r[..lo].to_vec()).collect(),
    }
}

/// Clamps both ends.
pub(super) fn clamp_bundle(b: &Bundle) -> Bundle {
    clamp_end_bundle(&clamp_start_bundle(b))
}

/// Whether the first `p + 1` knots are equal.
pub(super) fn start_clamped(degree: usize, knots: &[f64]) -> bool {
    knots[0] == knots[degree]
}

/// Whether the last `p + 1` knots are equal.
pub(super) fn end_clamped(degree: usize, knots: &[f64]) -> bool {
    let m = knots.len() - 1;
    knots[m - degree] == knots[m]
}

/// Unclamps the start (A12.1, left end). `spacing[i] = u_{n-i+1} - u_{n-i}` of the curve
/// clamped at both ends, `i = 0..p-1`.
fn unclamp_start_with(b: &Bundle, spacing: &[f64]) -> Bundle {
    let mut c = clamp_start_bundle(b);
    let p = c.degree;
    let u = &mut c.knots;
    for i in 0..p.saturating_sub(1) {
        u[p - i - 1] = u[p - i] - spacing[i];
        // A12.1: alfa = (U[p] - U[k]) / (U[p+j+1] - U[k]), Pw[j] = (Pw[j] - alfa Pw[j+1]) / (1 - alfa).
        let mut k = p - 1;
        for j in (0..=i).rev() {
            let alfa = (u[p] - u[k]) / (u[p + j + 1] - u[k]);
            for row in &mut c.rows {
                row[j] = unlerp_left(row[j], row[j + 1], alfa);
            }
            k = k.saturating_sub(1);
        }
    }
    // The first knot only shapes N_0 outside the domain; it continues the pattern.
    u[0] = u[1] - spacing[p - 1];
    c
}

/// Unclamps the end (A12.1, right end). `spacing[i] = u_{p+i+1} - u_{p+i}` of the curve
/// clamped at both ends.
fn unclamp_end_with(b: &Bundle, spacing: &[f64]) -> Bundle {
    let mut c = clamp_end_bundle(b);
    let p = c.degree;
    let n = c.poles() - 1;
    let u = &mut c.knots;
    for i in 0..p.saturating_sub(1) {
        u[n + i + 2] = u[n + i + 1] + spacing[i];
        // A12.1: alfa = (U[n+1] - U[n-j]) / (U[n-j+i+2] - U[n-j]),
        // Pw[n-j] = (Pw[n-j] - (1 - alfa) Pw[n-j-1]) / alfa.
        for j in (0..=i).rev() {
            let alfa = (u[n + 1] - u[n - j]) / (u[n - j + i + 2] - u[n - j]);
            for row in &mut c.rows {
                row[n - j] = unlerp_right(row[n - j - 1], row[n - j], alfa);
            }
        }
    }
    u[n + p + 1] = u[n + p] + spacing[p - 1];
    c
}

/// `(p - a q) / (1 - a)`: the `x` with `p = (1 - a) x + a q`.
#[inline]
fn unlerp_left(p: Hpoint, q: Hpoint, a: f64) -> Hpoint {
    let d = 1.0 - a;
    [
        (p[0] - a * q[0]) / d,
        (p[1] - a * q[1]) / d,
        (p[2] - a * q[2]) / d,
        (p[3] - a * q[3]) / d,
    ]
}

/// `(p - (1 - a) q) / a`: the `x` with `p = (1 - a) q + a x`.
#[inline]
fn unlerp_right(q: Hpoint, p: Hpoint, a: f64) -> Hpoint {
    let d = 1.0 - a;
    [
        (p[0] - d * q[0]) / a,
        (p[1] - d * q[1]) / a,
        (p[2] - d * q[2]) / a,
        (p[3] - d * q[3]) / a,
    ]
}

/// The spacings 2-168 uses at the start: the last `p` spans of the doubly clamped vector.
fn start_spacing(clamped: &Bundle) -> Vec<f64> {
    let u = &clamped.knots;
    let n = clamped.poles() - 1;
    (0..clamped.degree)
        .map(|i| u[n - i + 1] - u[n - i])
        .collect()
}

/// The spacings 2-169 uses at the end: the first `p` spans of the doubly clamped vector.
fn end_spacing(clamped: &Bundle) -> Vec<f64> {
    let u = &clamped.knots;
    let p = clamped.degree;
    (0..p).map(|i| u[p + i + 1] - u[p + i]).collect()
}

/// Unclamps the start of every row (see the module documentation); an unclamped start is
/// kept as it is (it already is an unclamped form; re-deriving its outer poles could only
/// change them, and for rational data can give non-positive weights).
pub(super) fn unclamp_start_bundle(b: &Bundle) -> Bundle {
    if !start_clamped(b.degree, &b.knots) {
        return b.clone();
    }
    let spacing = start_spacing(&clamp_bundle(b));
    unclamp_start_with(b, &spacing)
}

/// Unclamps the end of every row; an unclamped end is kept as it is.
pub(super) fn unclamp_end_bundle(b: &Bundle) -> Bundle {
    if !end_clamped(b.degree, &b.knots) {
        return b.clone();
    }
    let spacing = end_spacing(&clamp_bundle(b));
    unclamp_end_with(b, &spacing)
}

/// Unclamps both ends with the spacings of the doubly clamped vector (so, for a closed
/// C^(p-1) curve, the knots wrap: figure 2-125c).
///
/// Ends that are already unclamped are kept as they are: unclamping the unclamped form of
/// a periodic rational curve returns it unchanged (re-deriving it from the clamped form
/// could give non-positive weights).
pub(super) fn unclamp_bundle(b: &Bundle) -> Bundle {
    match (
        start_clamped(b.degree, &b.knots),
        end_clamped(b.degree, &b.knots),
    ) {
        (false, false) => return b.clone(),
        (true, false) => return unclamp_start_bundle(b),
        (false, true) => return unclamp_end_bundle(b),
        (true, true) => {}
    }
    let clamped = clamp_bundle(b);
    let (s0, s1) = (start_spacing(&clamped), end_spacing(&clamped));
    unclamp_end_with(&unclamp_start_with(&clamped, &s0), &s1)
}

/// Unclamping extrapolates the homogeneous poles; for a rational curve the new end weights
/// can come out zero or negative, which the model (and ISO 10303-42) forbids. Say so.
fn explain_unclamp(e: GeometryError) -> GeometryError {
    match e {
        GeometryError::BadWeight { index, value } => GeometryError::InvalidArgument(format!(
            "unclamping gives weight {value} at pole {index}: this rational geometry has no \
             unclamped form with positive weights on the 2-168/2-169 knots"
        )),
        other => other,
    }
}

impl NurbsCurve {
    /// Clamps the start: the first `p + 1` knots become `u_p` and the first pole the start
    /// point (knot insertion A5.1, then the outer knots and poles are dropped; seed 2-29).
    /// Exact; same domain; a clamped start is returned unchanged.
    pub fn clamp_start(&self) -> Result<NurbsCurve, GeometryError> {
        self.with_bundle(clamp_start_bundle(&self.to_bundle()))
    }

    /// Clamps the end: the last `p + 1` knots become `u_{n+1}` (as [`clamp_start`](Self::clamp_start)).
    pub fn clamp_end(&self) -> Result<NurbsCurve, GeometryError> {
        self.with_bundle(clamp_end_bundle(&self.to_bundle()))
    }

    /// Clamps both ends (exact; same domain).
    pub fn clamp(&self) -> Result<NurbsCurve, GeometryError> {
        self.with_bundle(clamp_bundle(&self.to_bundle()))
    }

    /// Unclamps the start (NURBS Book A12.1 left end, knots by seed formula 2-168; see the
    /// module documentation). Exact up to rounding; same domain. An unclamped start is
    /// returned as it is.
    ///
    /// Rational curves: the new end poles are extrapolated in homogeneous space and their
    /// weights can become non-positive; then [`GeometryError::InvalidArgument`] says so
    /// (polynomial curves always succeed).
    pub fn unclamp_start(&self) -> Result<NurbsCurve, GeometryError> {
        if !self.is_clamped_start() {
            // Bit for bit: no round trip through homogeneous poles.
            return Ok(self.clone());
        }
        self.with_bundle(unclamp_start_bundle(&self.to_bundle()))
            .map_err(explain_unclamp)
    }

    /// Unclamps the end (A12.1 right end, knots by seed formula 2-169).
    pub fn unclamp_end(&self) -> Result<NurbsCurve, GeometryError> {
        if !self.is_clamped_end() {
            return Ok(self.clone());
        }
        self.with_bundle(unclamp_end_bundle(&self.to_bundle()))
            .map_err(explain_unclamp)
    }

    /// Unclamps both ends (A12.1); ends already unclamped are kept, so an unclamped curve
    /// comes back unchanged.
    pub fn unclamp(&self) -> Result<NurbsCurve, GeometryError> {
        if !self.is_clamped_start() && !self.is_clamped_end() {
            return Ok(self.clone());
        }
        self.with_bundle(unclamp_bundle(&self.to_bundle()))
            .map_err(explain_unclamp)
    }

    /// Whether the first `p + 1` knots are equal.
    pub fn is_clamped_start(&self) -> bool {
        start_clamped(self.degree(), self.knots())
    }

    /// Whether the last `p + 1` knots are equal.
    pub fn is_clamped_end(&self) -> bool {
        end_clamped(self.degree(), self.knots())
    }
}

/// Which end of a parameter direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// The start `u_p`.
    Start,
    /// The end `u_{n+1}`.
    End,
    /// Both ends.
    Both,
}

impl NurbsSurface {
    /// Clamps the given end(s) in u (seed 2-29; A5.3 insertion per column). Exact.
    pub fn clamp_u(&self, end: End) -> Result<NurbsSurface, GeometryError> {
        self.clamp_dir(Dir::U, end, false)
    }

    /// Clamps the given end(s) in v. Exact.
    pub fn clamp_v(&self, end: End) -> Result<NurbsSurface, GeometryError> {
        self.clamp_dir(Dir::V, end, false)
    }

    /// Unclamps the given end(s) in u (A12.1 per column, knots 2-168 / 2-169).
    pub fn unclamp_u(&self, end: End) -> Result<NurbsSurface, GeometryError> {
        self.clamp_dir(Dir::U, end, true)
    }

    /// Unclamps the given end(s) in v (A12.1 per row).
    pub fn unclamp_v(&self, end: End) -> Result<NurbsSurface, GeometryError> {
        self.clamp_dir(Dir::V, end, true)
    }

    /// Clamps all four ends (exact; same domain).
    pub fn clamp(&self) -> Result<NurbsSurface, GeometryError> {
        self.clamp_u(End::Both)?.clamp_v(End::Both)
    }

    fn clamp_dir(&self, dir: Dir, end: End, un: bool) -> Result<NurbsSurface, GeometryError> {
        let b = self.to_bundle(dir);
        let out = match (end, un) {
            (End::Start, false) => clamp_start_bundle(&b),
            (End::End, false) => clamp_end_bundle(&b),
            (End::Both, false) => clamp_bundle(&b),
            (End::Start, true) => unclamp_start_bundle(&b),
            (End::End, true) => unclamp_end_bundle(&b),
            (End::Both, true) => unclamp_bundle(&b),
        };
        self.with_bundle(dir, out).map_err(explain_unclamp)
    }
}
