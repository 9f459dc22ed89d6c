//! Splitting at a parameter (knot insertion to multiplicity `p`, NURBS Book A5.1, then
//! cutting the knot vector and the poles; section 5.3 "curve splitting") and joining two
//! curves end to start.
//!
//! Each half keeps its parameter range: splitting a curve with domain `[a, b]` at `t` gives
//! halves with domains `[a, t]` and `[t, b]`, the cut ends clamped and the outer ends as
//! they were (clamped or not).

use super::clamp::{clamp_end_bundle, clamp_start_bundle};
use super::insert::{Bundle, Dir, insert_bundle};
use super::knots::multiplicity;
use super::{GeometryError, NurbsCurve, NurbsSurface};

/// Splits every row at `t`, strictly inside the domain (checked by the callers).
fn split_bundle(b: &Bundle, t: f64) -> (Bundle, Bundle) {
    let p = b.degree;
    let s = multiplicity(&b.knots, t);
    let ins = insert_bundle(b, t, p.saturating_sub(s));
    let lo = ins.knots.partition_point(|&x| x < t);
    let hi = ins.knots.partition_point(|&x| x <= t) - 1;
    let mut left_knots = ins.knots[..lo].to_vec();
    left_knots.extend(std::iter::repeat_n(t, p + 1));
    let mut right_knots = vec![t; p + 1];
    right_knots.extend_from_slice(&ins.knots[hi + 1..]);
    let left = Bundle {
        degree: p,
        knots: left_knots,
        rows: ins.rows.iter().map(|r| r[..lo].to_vec()).collect(),
    };
    let right = Bundle {
        degree: p,
        knots: right_knots,
        rows: ins.rows.iter().map(|r| r[hi - p..].to_vec()).collect(),
    };
    (left, right)
}

fn check_split(b: &Bundle, t: f64) -> Result<(), GeometryError> {
    let (start, end) = b.domain();
    if !(t > start && t < end) {
        return Err(GeometryError::InvalidArgument(format!(
            "split parameter {t} must lie strictly inside the domain [{start}, {end}]"
        )));
    }
    Ok(())
}

impl NurbsCurve {
    /// Splits the curve at `t` into the pieces on `[u_p, t]` and `[t, u_{n+1}]` (A5.1
    /// insertion of `t` up to multiplicity `p`, then the knot vector and poles are cut).
    /// Exact; each piece keeps its parameters. Error if `t` is not strictly inside the domain.
    pub fn split_at(&self, t: f64) -> Result<(NurbsCurve, NurbsCurve), GeometryError> {
        let b = self.to_bundle();
        check_split(&b, t)?;
        let (l, r) = split_bundle(&b, t);
        Ok((self.with_bundle(l)?, self.with_bundle(r)?))
    }

    /// Joins `other` after `self`: the end of `self` must meet the start of `other` within
    /// `tolerance` (else [`GeometryError::ToleranceExceeded`] with the gap). Degrees,
    /// rationality and dimensions must agree (else [`GeometryError::InvalidArgument`]).
    ///
    /// The end of `self` and the start of `other` are clamped (exact), `other`'s parameters
    /// are shifted to continue at the end of `self`'s domain, and, for rational curves,
    /// `other`'s weights are all scaled (which leaves it unchanged) so that the two junction
    /// weights agree. The junction pole is the midpoint of the two end points, so each side
    /// moves by at most half the gap; the junction knot gets multiplicity `p` (C0; remove
    /// it with [`remove_knot`](Self::remove_knot) if the pieces are smoother). The result's
    /// domain is `[start of self, end of self + length of other's domain]`.
    pub fn join(&self, other: &NurbsCurve, tolerance: f64) -> Result<NurbsCurve, GeometryError> {
        let p = self.degree();
        if other.degree() != p {
            return Err(GeometryError::InvalidArgument(format!(
                "join: degrees differ ({p} and {})",
                other.degree()
            )));
        }
        if other.is_rational() != self.is_rational() {
            return Err(GeometryError::InvalidArgument(
                "join: one curve is rational and the other is not".into(),
            ));
        }
        if other.dimension() != self.dimension() {
            return Err(GeometryError::InvalidArgument(format!(
                "join: dimensions differ ({} and {})",
                self.dimension(),
                other.dimension()
            )));
        }
        if !(tolerance >= 0.0 && tolerance.is_finite()) {
            return Err(GeometryError::InvalidArgument(format!(
                "join: tolerance {tolerance} must be finite and non-negative"
            )));
        }
        let left = clamp_end_bundle(&self.to_bundle());
        let right = clamp_start_bundle(&other.to_bundle());
        let (l_row, r_row) = match (left.rows.first(), right.rows.first()) {
            (Some(l), Some(r)) => (l, r),
            _ => return Err(GeometryError::InvalidArgument("join: empty curve".into())),
        };
        let (Some(&hl), Some(&hr)) = (l_row.last(), r_row.first()) else {
            return Err(GeometryError::InvalidArgument("join: empty curve".into()));
        };
        let pl = super::from_homogeneous(hl);
        let pr = super::from_homogeneous(hr);
        let gap =
            ((pl[0] - pr[0]).powi(2) + (pl[1] - pr[1]).powi(2) + (pl[2] - pr[2]).powi(2)).sqrt();
        if gap.is_nan() || gap > tolerance {
            return Err(GeometryError::ToleranceExceeded {
                what: "join: gap between end and start",
                bound: gap,
                tolerance,
            });
        }
        let scale = hl[3] / hr[3];
        let (_, end) = left.domain();
        let (start2, _) = right.domain();
        let shift = end - start2;
        let mut knots = left.knots[..left.poles()].to_vec();
        knots.extend(std::iter::repeat_n(end, p));
        knots.extend(right.knots[p + 1..].iter().map(|&k| k + shift));
        let mid = [
            (pl[0] + pr[0]) / 2.0,
            (pl[1] + pr[1]) / 2.0,
            (pl[2] + pr[2]) / 2.0,
        ];
        let mut row = l_row.clone();
        if let Some(last) = row.last_mut() {
            *last = super::to_homogeneous(mid, hl[3]);
        }
        row.extend(
            r_row[1..]
                .iter()
                .map(|h| [h[0] * scale, h[1] * scale, h[2] * scale, h[3] * scale]),
        );
        self.with_bundle(Bundle {
            degree: p,
            knots,
            rows: vec![row],
        })
    }
}

impl NurbsSurface {
    /// Splits at `u` into the surfaces on `[u_p, u]` and `[u, u_{n+1}]` in u (A5.3 insertion
    /// to multiplicity `p`, then cut). Exact; parameters kept.
    pub fn split_at_u(&self, u: f64) -> Result<(NurbsSurface, NurbsSurface), GeometryError> {
        self.split_dir(Dir::U, u)
    }

    /// Splits at `v` in the v direction (as [`split_at_u`](Self::split_at_u)).
    pub fn split_at_v(&self, v: f64) -> Result<(NurbsSurface, NurbsSurface), GeometryError> {
        self.split_dir(Dir::V, v)
    }

    fn split_dir(&self, dir: Dir, t: f64) -> Result<(NurbsSurface, NurbsSurface), GeometryError> {
        let b = self.to_bundle(dir);
        check_split(&b, t)?;
        let (l, r) = split_bundle(&b, t);
        Ok((self.with_bundle(dir, l)?, self.with_bundle(dir, r)?))
    }
}
