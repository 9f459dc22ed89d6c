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
    let ins = inserted(b, t);
    (left_of(&ins, t), right_of(&ins, t))
}

/// `b` with `t` inserted up to multiplicity `p` (A5.1).
fn inserted(b: &Bundle, t: f64) -> Bundle {
    let s = multiplicity(&b.knots, t);
    insert_bundle(b, t, b.degree.saturating_sub(s))
}

/// The part of `ins` (where `t` has multiplicity `p`, [`inserted`]) on `[u_p, t]`.
fn left_of(ins: &Bundle, t: f64) -> Bundle {
    let p = ins.degree;
    let lo = ins.knots.partition_point(|&x| x < t);
    let mut knots = ins.knots[..lo].to_vec();
    knots.extend(std::iter::repeat_n(t, p + 1));
    Bundle {
        degree: p,
        knots,
        rows: ins.rows.iter().map(|r| r[..lo].to_vec()).collect(),
    }
}

/// The part of `ins` (where `t` has multiplicity `p`, [`inserted`]) on `[t, u_{n+1}]`.
fn right_of(ins: &Bundle, t: f64) -> Bundle {
    let p = ins.degree;
    let hi = ins.knots.partition_point(|&x| x <= t) - 1;
    let mut knots = vec![t; p + 1];
    knots.extend_from_slice(&ins.knots[hi + 1..]);
    Bundle {
        degree: p,
        knots,
        rows: ins.rows.iter().map(|r| r[hi - p..].to_vec()).collect(),
    }
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

    /// The piece of the curve on `[a, b]`, `u_p <= a < b <= u_{n+1}`, keeping its parameters:
    /// cut as [`split_at`](Self::split_at) cuts at each end strictly inside the domain
    /// (NURBS Book A5.1, exact), keeping only the part on the range's side. Error if the
    /// range is not inside the domain or is empty.
    pub fn piece(&self, a: f64, b: f64) -> Result<NurbsCurve, GeometryError> {
        let (s, e) = self.domain();
        if !(s <= a && a < b && b <= e) {
            return Err(GeometryError::InvalidArgument(format!(
                "range [{a}, {b}] is not inside the curve's domain [{s}, {e}]"
            )));
        }
        if a == s && b == e {
            return Ok(self.clone());
        }
        let (p, knots) = (self.degree(), self.knots());
        // Cut where a knot already has multiplicity `p` (a breakpoint of arcs): A5.1 inserts
        // nothing there, and the piece is a slice of the knots, poles and weights (copied,
        // not passed through the homogeneous form), as `right_of` and `left_of` cut.
        if (a == s || multiplicity(knots, a) >= p) && (b == e || multiplicity(knots, b) >= p) {
            let (k0, first, mut cut) = if a > s {
                let hi = knots.partition_point(|&x| x <= a) - 1;
                (hi + 1, hi - p, vec![a; p + 1])
            } else {
                (0, 0, Vec::with_capacity(knots.len()))
            };
            let (k1, last) = if b < e {
                let lo = knots.partition_point(|&x| x < b);
                (lo, lo)
            } else {
                (knots.len(), self.num_poles())
            };
            cut.extend_from_slice(&knots[k0..k1]);
            if b < e {
                cut.extend(std::iter::repeat_n(b, p + 1));
            }
            return NurbsCurve::with_dimension(
                p,
                cut,
                self.control_points()[first..last].to_vec(),
                self.weights().map(|w| w[first..last].to_vec()),
                self.dimension(),
            );
        }
        // Cut in homogeneous form, only the part kept at each end, one curve built.
        let mut cut = self.to_bundle();
        if a > s {
            cut = right_of(&inserted(&cut, a), a);
        }
        if b < e {
            cut = left_of(&inserted(&cut, b), b);
        }
        self.with_bundle(cut)
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
    /// The piece of the surface on `[a, b] x [c, d]` inside its domain, keeping its
    /// parameters: [`split_at_u`](Self::split_at_u) and [`split_at_v`](Self::split_at_v) at
    /// each end strictly inside the domain (NURBS Book A5.3, exact). Error if either range
    /// is empty or not inside the domain.
    pub fn piece(
        &self,
        (a, b): (f64, f64),
        (c, d): (f64, f64),
    ) -> Result<NurbsSurface, GeometryError> {
        let ((u0, u1), (v0, v1)) = self.domain();
        if !(u0 <= a && a < b && b <= u1 && v0 <= c && c < d && d <= v1) {
            return Err(GeometryError::InvalidArgument(format!(
                "range [{a}, {b}] x [{c}, {d}] is not inside the surface's domain [{u0}, {u1}] x [{v0}, {v1}]"
            )));
        }
        let mut out = self.clone();
        if a > u0 {
            out = out.split_at_u(a)?.1;
        }
        if b < u1 {
            out = out.split_at_u(b)?.0;
        }
        if c > v0 {
            out = out.split_at_v(c)?.1;
        }
        if d < v1 {
            out = out.split_at_v(d)?.0;
        }
        Ok(out)
    }

    /// Splits at `u` into the surfaces on `[u_p, u]` and `[u, u_{n+1}]` in u (A5.3 insertion
    /// to multiplicity `p`, then cut). Exact; parameters kept.
    pub fn split_at_u(&self, u: f64) -> Result<(NurbsSurface, NurbsSurface), GeometryError> {
        self.split_dir(Dir::U, u)
    }

    /// Splits at `v` in the v direction (as [`split_at_u`](Self::split_at_u)).
    pub fn split_at_v(&self, v: f64) -> Result<(NurbsSurface, NurbsSurface), GeometryError> {
        self.split_dir(Dir::V, v)
    }

    /// Moves the seam of a surface closed in u (first and last pole columns equal within
    /// `tolerance`, clamped ends: a NURBS cylinder, cone, torus or revolution) to `u = t`: the
    /// surface is split at `t` (A5.3) and the piece `[t, end]` is followed by `[start, t]`
    /// shifted by the period `end - start`, as [`NurbsCurve::join`] joins curves (the old
    /// seam's poles become the midpoints of its two columns: each side moves by at most half
    /// their gap, none for a surface closed exactly). The result on `[t, t + end - start]` is
    /// the same surface, `S'(x) = S(x)` for `x <= end` and `S'(x) = S(x - end + start)`
    /// beyond. Errors: `t` not strictly inside the domain, ends not clamped, or the surface
    /// not closed in u within `tolerance`.
    pub fn rotate_seam_u(&self, t: f64, tolerance: f64) -> Result<NurbsSurface, GeometryError> {
        self.rotate_seam(Dir::U, t, tolerance)
    }

    /// Moves the seam of a surface closed in v to `v = t` (as
    /// [`rotate_seam_u`](Self::rotate_seam_u)).
    pub fn rotate_seam_v(&self, t: f64, tolerance: f64) -> Result<NurbsSurface, GeometryError> {
        self.rotate_seam(Dir::V, t, tolerance)
    }

    fn rotate_seam(&self, dir: Dir, t: f64, tolerance: f64) -> Result<NurbsSurface, GeometryError> {
        let b = self.to_bundle(dir);
        // A seam within rounding of a knot (a point inverted onto the surface a few ulps past
        // it) is moved to the knot: inserted as given, it would leave a sliver span whose
        // knots, shifted by the period below, round onto their neighbours (a multiplicity
        // above degree + 1).
        let (start, end) = b.domain();
        let t = b
            .knots
            .iter()
            .copied()
            .find(|k| (k - t).abs() <= 1e-12 * (end - start))
            .unwrap_or(t);
        check_split(&b, t)?;
        let p = b.degree;
        let n = b.knots.len();
        let clamped = b.knots[..=p].iter().all(|&k| k == start)
            && b.knots[n - p - 1..].iter().all(|&k| k == end);
        if !clamped {
            return Err(GeometryError::InvalidArgument(
                "seam: the surface's ends are not clamped".into(),
            ));
        }
        let (first, second) = split_bundle(&b, t);
        // `second` = [t, end] runs first; `first` = [start, t] follows, its homogeneous poles
        // scaled by one factor for every row (which leaves a rational surface unchanged) so
        // that the junction weights agree.
        let size = b
            .rows
            .iter()
            .flatten()
            .map(|h| super::vector::norm(super::from_homogeneous(*h)))
            .fold(1.0f64, f64::max);
        let mut scale: Option<f64> = None;
        for (r2, r1) in second.rows.iter().zip(&first.rows) {
            let (Some(&h2), Some(&h1)) = (r2.last(), r1.first()) else {
                return Err(GeometryError::InvalidArgument("seam: empty surface".into()));
            };
            let gap = super::vector::dist(super::from_homogeneous(h2), super::from_homogeneous(h1));
            let k = h2[3] / h1[3];
            let same_scale = scale.is_none_or(|s| (s - k).abs() <= 1e-12 * s.abs());
            if !(gap <= tolerance.max(1e-12 * size) && k.is_finite() && k > 0.0 && same_scale) {
                return Err(GeometryError::InvalidArgument(format!(
                    "seam: the surface is not closed in that direction (gap {gap:e})"
                )));
            }
            scale.get_or_insert(k);
        }
        let scale = scale.unwrap_or(1.0);
        let shift = end - start;
        let mut knots = second.knots[..second.poles()].to_vec();
        knots.extend(std::iter::repeat_n(end, p));
        knots.extend(first.knots[p + 1..].iter().map(|&k| k + shift));
        let rows = second
            .rows
            .iter()
            .zip(&first.rows)
            .map(|(r2, r1)| {
                let mut row = r2.clone();
                if let (Some(last), Some(&h1)) = (row.last_mut(), r1.first()) {
                    let (a, b) = (super::from_homogeneous(*last), super::from_homogeneous(h1));
                    let mid = [
                        0.5 * (a[0] + b[0]),
                        0.5 * (a[1] + b[1]),
                        0.5 * (a[2] + b[2]),
                    ];
                    *last = super::to_homogeneous(mid, last[3]);
                }
                row.extend(r1[1..].iter().map(|h| h.map(|x| x * scale)));
                row
            })
            .collect();
        self.with_bundle(
            dir,
            Bundle {
                degree: p,
                knots,
                rows,
            },
        )
    }

    fn split_dir(&self, dir: Dir, t: f64) -> Result<(NurbsSurface, NurbsSurface), GeometryError> {
        let b = self.to_bundle(dir);
        check_split(&b, t)?;
        let (l, r) = split_bundle(&b, t);
        Ok((self.with_bundle(dir, l)?, self.with_bundle(dir, r)?))
    }
}

#[cfg(test)]
mod tests {

    use crate::nurbs::sweep::{Frame, plane, torus};
    use crate::nurbs::vector::dist;

    fn frame() -> Frame {
        Frame {
            origin: [1.0, -2.0, 0.5],
            x: [0.0, 1.0, 0.0],
            y: [0.0, 0.0, 1.0],
            z: [1.0, 0.0, 0.0],
        }
    }

    /// A piece cut at breakpoints (knots of multiplicity `p`) is the slice of the net, and
    /// every piece, cut there or inside a span, traces the curve: compared by evaluation
    /// with the whole curve at 101 parameters of the range, and the slice pole for pole.
    #[test]
    fn pieces_at_breakpoints_are_slices_of_the_curve() {
        let tau = 2.0 * std::f64::consts::PI;
        let (t, _) = torus(&frame(), 30.0, 6.0, (0.0, tau), (0.0, tau)).unwrap();
        // A full circle of quarter arcs (double knots at the quarters), rational.
        let c = t.iso_v(0.0).unwrap();
        let k = c.knots().to_vec();
        let q = k[3];
        assert_eq!((k[3], k[4]), (q, q));
        let (s, e) = c.domain();
        for (a, b) in [
            (q, 2.0 * q),
            (s, q),
            (q, e),
            (q, 0.3 * e),
            (0.1 * e, 3.0 * q),
        ] {
            let piece = c.piece(a, b).unwrap();
            assert_eq!(piece.domain(), (a, b));
            for i in 0..=100 {
                let x = a + (b - a) * f64::from(i) / 100.0;
                let d = dist(piece.point_at_unchecked(x), c.point_at_unchecked(x));
                assert!(d <= 1e-12 * 30.0, "[{a}, {b}] at {x}: {d:e}");
            }
        }
        // Both ends on breakpoints: the poles and weights themselves, and the knots between.
        let piece = c.piece(q, 2.0 * q).unwrap();
        assert_eq!(piece.control_points(), &c.control_points()[2..5]);
        assert_eq!(piece.weights().unwrap(), &c.weights().unwrap()[2..5]);
        assert_eq!(piece.knots(), &[q, q, q, 2.0 * q, 2.0 * q, 2.0 * q]);
    }

    /// The isocurve at an interior breakpoint of the net (a double knot of the quadratic
    /// arcs) is that row of poles and weights, and traces the surface there (evaluation of
    /// the surface at 101 points).
    #[test]
    fn an_isocurve_at_a_breakpoint_is_a_row_of_the_net() {
        let tau = 2.0 * std::f64::consts::PI;
        let (t, _) = torus(&frame(), 30.0, 6.0, (0.0, tau), (0.0, tau)).unwrap();
        let ku = t.knots_u().to_vec();
        let q = ku[3];
        assert_eq!(ku[4], q);
        let iso = t.iso_u(q).unwrap();
        let g = t.control_points();
        let row: Vec<_> = (0..g.nv()).map(|j| *g.get(2, j)).collect();
        assert_eq!(iso.control_points(), row.as_slice());
        let ((_, _), (v0, v1)) = t.domain();
        for i in 0..=100 {
            let v = v0 + (v1 - v0) * f64::from(i) / 100.0;
            let d = dist(iso.point_at_unchecked(v), t.point_at_unchecked(q, v));
            assert!(d <= 1e-12 * 36.0, "{v}: {d:e}");
        }
        // Inside a span, the contraction (A3.5) still traces the surface.
        let inside = t.iso_u(0.5 * q).unwrap();
        let d = dist(
            inside.point_at_unchecked(1.0),
            t.point_at_unchecked(0.5 * q, 1.0),
        );
        assert!(d <= 1e-12 * 36.0, "{d:e}");
    }

    /// The surface with its seam moved is the same surface, evaluated at the shifted
    /// parameter (an evaluation of both at a grid, not the construction), in both
    /// directions of a torus and at a parameter inside a span and on a knot.
    #[test]
    fn a_rotated_seam_gives_the_same_surface() {
        let tau = 2.0 * std::f64::consts::PI;
        let (s, _) = torus(&frame(), 30.0, 6.0, (0.0, tau), (0.0, tau)).unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        for (along_u, t) in [(true, 0.37 * u1), (false, 0.5 * (v0 + v1)), (false, 1.3)] {
            let r = if along_u {
                s.rotate_seam_u(t, 0.0).unwrap()
            } else {
                s.rotate_seam_v(t, 0.0).unwrap()
            };
            let ((a0, a1), (b0, b1)) = r.domain();
            let period = if along_u { u1 - u0 } else { v1 - v0 };
            if along_u {
                assert_eq!((a0, b0, b1), (t, v0, v1));
                assert!((a1 - (t + period)).abs() <= 1e-12 * period);
            } else {
                assert_eq!((a0, a1, b0), (u0, u1, t));
                assert!((b1 - (t + period)).abs() <= 1e-12 * period);
            }
            for i in 0..=40 {
                for j in 0..=40 {
                    let x = a0 + (a1 - a0) * i as f64 / 40.0;
                    let y = b0 + (b1 - b0) * j as f64 / 40.0;
                    let (mut u, mut v) = (x, y);
                    let w = if along_u { &mut u } else { &mut v };
                    if *w > if along_u { u1 } else { v1 } {
                        *w -= period;
                    }
                    let d = dist(r.point_at(x, y).unwrap(), s.point_at(u, v).unwrap());
                    assert!(d <= 1e-13 * 36.0, "{along_u} at {t}: {d:e} at ({x}, {y})");
                }
            }
        }
        // A seam asked for an ulp off a knot (pi, where the torus's arcs meet) is moved to
        // the knot; without snapping, pi + 1 ulp shifted by 2 pi rounds to 3 pi and the knot
        // vector is refused.
        let pi = std::f64::consts::PI;
        assert!(s.knots_u().contains(&pi));
        for t in [pi.next_up(), pi.next_down()] {
            let r = s.rotate_seam_u(t, 0.0).unwrap();
            assert_eq!(r.domain().0.0, pi);
            let d = dist(
                r.point_at(pi + 0.5, 1.0).unwrap(),
                s.point_at(pi + 0.5, 1.0).unwrap(),
            );
            assert!(d <= 1e-13 * 36.0, "{d:e}");
        }
        // A plane is not closed.
        let p = plane(&frame(), (0.0, 1.0), (0.0, 1.0)).unwrap();
        assert!(p.rotate_seam_u(0.5, 1e-6).is_err());
    }
}
