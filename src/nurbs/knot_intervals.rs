//! Knot intervals (seed 003, after Sederberg, Zheng and Song 2003, "Knot intervals and
//! multi-degree splines"): a knot vector written as the differences of consecutive knots,
//! attached to the control polygon, and interval halving.
//!
//! # Layout
//!
//! A curve of degree `p` with poles `P_0 .. P_n` has the knot vector `u_0 .. u_m`,
//! `m = n + p + 1` (NURBS Book form). Seed 003 drops the outermost knots `u_0` and `u_m`
//! (no basis function on the domain depends on them) and writes the remaining ones as the
//! `n + p - 1` intervals `d_j = u_{j+2} - u_{j+1}`:
//!
//! - odd degree `p = 2k + 1`: the edge `P_i P_{i+1}` carries `d_{i+k}` (the middle interval of
//!   the knots `u_{i+1} .. u_{i+p+1}` that its two poles' polar labels span);
//! - even degree `p = 2k`: the pole `P_i` carries `d_{i+k-1}` (the middle interval of its
//!   polar label `u_{i+1} .. u_{i+p}`);
//! - the rest are the phantom end intervals, `(p - 1) / 2` (odd) or `(p - 2) / 2` (even) at
//!   each end, which sit on edges or poles beyond the end poles;
//! - a zero interval is a repeated knot.
//!
//! # Origin and the outermost knots
//!
//! The intervals fix the knots up to a translation; the origin is the first knot `u_0`
//! ([`KnotIntervals::origin`]). The two outermost intervals `u_1 - u_0` and `u_m - u_{m-1}`,
//! which seed 003's notation leaves out, are kept separately ([`KnotIntervals::outer`]) so
//! that no knot is lost; they are zero for a clamped curve. The knots come back as the sums
//! `u_0 = origin`, `u_{i+1} = u_i + (interval i)`, left to right, in `f64`.
//!
//! Each interval is the rounded difference `u_{i+1} - u_i`. The sum `u_i + d_i` gives
//! `u_{i+1}` back bit for bit except when the difference rounded at a tie and so does the
//! sum (a contrived case: `2^-53` followed by `1 + 2^-52`, where every `f64` sum from
//! `2^-53` in that binade lands on a tie, so no interval reaches the knot).
//! [`KnotIntervals::inexact_knot`] finds such a knot; model JSON refuses to write a curve
//! that has one in knot-interval form rather than move its knot.

use super::{GeometryError, NurbsCurve, NurbsSurface};

/// A knot vector in knot-interval form (see the module documentation for the layout).
#[derive(Debug, Clone, PartialEq)]
pub struct KnotIntervals {
    /// The first knot `u_0`.
    pub origin: f64,
    /// `u_1 - u_0` and `u_m - u_{m-1}`: the outermost intervals, which seed 003 leaves out.
    pub outer: [f64; 2],
    /// Seed 003's intervals `d_j = u_{j+2} - u_{j+1}`, `j = 0 .. n + p - 2`.
    pub intervals: Vec<f64>,
}

impl KnotIntervals {
    /// The knot-interval form of a valid knot vector (non-decreasing, finite, at least two
    /// knots more than the degree, as every curve's and surface's knot vector is).
    pub fn from_knots(knots: &[f64]) -> KnotIntervals {
        let all: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let last = all.len().saturating_sub(1);
        KnotIntervals {
            origin: knots.first().copied().unwrap_or(0.0),
            outer: [
                all.first().copied().unwrap_or(0.0),
                all.get(last).copied().unwrap_or(0.0),
            ],
            intervals: all.get(1..last).map(<[f64]>::to_vec).unwrap_or_default(),
        }
    }

    /// The knot vector: `origin`, then the left-to-right sums of `outer[0]`, the
    /// intervals and `outer[1]`. Checks every interval: finite and `>= 0`, located as
    /// `knot_intervals[j]` (or `outer_knot_intervals[0|1]`) in the error.
    pub fn to_knots(&self) -> Result<Vec<f64>, GeometryError> {
        let located = |name: String, value: f64| -> Result<f64, GeometryError> {
            if !value.is_finite() {
                Err(GeometryError::InvalidArgument(format!(
                    "{name} = {value} is not finite"
                )))
            } else if value < 0.0 {
                Err(GeometryError::InvalidArgument(format!(
                    "{name} = {value} is negative (a knot interval is a difference of \
                     non-decreasing knots)"
                )))
            } else {
                Ok(value)
            }
        };
        if !self.origin.is_finite() {
            return Err(GeometryError::InvalidArgument(format!(
                "knot_origin = {} is not finite",
                self.origin
            )));
        }
        let mut knots = Vec::with_capacity(self.intervals.len() + 3);
        let mut u = self.origin;
        knots.push(u);
        let steps = std::iter::once(("outer_knot_intervals[0]".to_owned(), self.outer[0]))
            .chain(
                self.intervals
                    .iter()
                    .enumerate()
                    .map(|(j, &d)| (format!("knot_intervals[{j}]"), d)),
            )
            .chain(std::iter::once((
                "outer_knot_intervals[1]".to_owned(),
                self.outer[1],
            )));
        for (name, d) in steps {
            u += located(name, d)?;
            if !u.is_finite() {
                return Err(GeometryError::InvalidArgument(
                    "the knot intervals sum beyond the f64 range".into(),
                ));
            }
            knots.push(u);
        }
        Ok(knots)
    }

    /// The first knot of `knots` (the vector this form was made from) that
    /// [`to_knots`](Self::to_knots) does not give back bit for bit, if any.
    pub fn inexact_knot(&self, knots: &[f64]) -> Option<usize> {
        match self.to_knots() {
            Ok(back) => back
                .iter()
                .zip(knots)
                .position(|(a, b)| a.to_bits() != b.to_bits())
                .or((back.len() != knots.len()).then_some(back.len().min(knots.len()))),
            Err(_) => Some(0),
        }
    }

    /// How many of [`intervals`](Self::intervals) are phantom intervals at each end for
    /// degree `p >= 1`: `(p - 1) / 2` for odd `p`, `(p - 2) / 2` for even `p`.
    pub fn phantoms(p: usize) -> usize {
        if p % 2 == 1 {
            (p - 1) / 2
        } else {
            (p / 2).saturating_sub(1)
        }
    }

    /// The intervals on the control polygon for degree `p`: one per edge `P_i P_{i+1}`
    /// (odd `p`) or per pole `P_i` (even `p`), in order, without the phantom ones.
    pub fn on_polygon(&self, p: usize) -> &[f64] {
        let k = Self::phantoms(p);
        self.intervals
            .get(k..self.intervals.len().saturating_sub(k))
            .unwrap_or(&[])
    }
}

/// The midpoint of every non-degenerate knot span of the domain `[u_p, u_{n+1}]` (interval
/// halving, seed 003 section 2-2), in order. Errors when a span is too narrow for `f64` to
/// hold a value strictly inside it.
pub fn halving_knots(degree: usize, knots: &[f64]) -> Result<Vec<f64>, GeometryError> {
    let end = knots.len().saturating_sub(degree + 1);
    let mut out = Vec::new();
    for i in degree..end {
        let (a, b) = (knots[i], knots[i + 1]);
        if a < b {
            let mid = a + (b - a) * 0.5;
            if !(mid > a && mid < b) {
                return Err(GeometryError::InvalidArgument(format!(
                    "interval halving: the knot span [{a:e}, {b:e}] has no f64 value inside it"
                )));
            }
            out.push(mid);
        }
    }
    Ok(out)
}

impl NurbsCurve {
    /// Interval halving (seed 003 section 2-2): inserts the midpoint of every
    /// non-degenerate knot span of the domain by knot refinement (NURBS Book A5.4), so
    /// every non-zero interval inside the domain becomes two equal halves. For a clamped
    /// curve that is every non-zero interval; the intervals outside the domain of an
    /// unclamped curve (which no part of the curve spans) stay. The geometry and the
    /// domain are unchanged.
    pub fn halve(&self) -> Result<NurbsCurve, GeometryError> {
        self.refine(&halving_knots(self.degree(), self.knots())?)
    }

    /// The curve's knot vector in knot-interval form.
    pub fn knot_intervals(&self) -> KnotIntervals {
        KnotIntervals::from_knots(self.knots())
    }
}

impl NurbsSurface {
    /// Interval halving in u ([`NurbsCurve::halve`] on the u knot vector, A5.5).
    pub fn halve_u(&self) -> Result<NurbsSurface, GeometryError> {
        self.refine_u(&halving_knots(self.degree_u(), self.knots_u())?)
    }

    /// Interval halving in v ([`NurbsCurve::halve`] on the v knot vector, A5.5).
    pub fn halve_v(&self) -> Result<NurbsSurface, GeometryError> {
        self.refine_v(&halving_knots(self.degree_v(), self.knots_v())?)
    }
}
