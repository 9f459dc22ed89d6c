//! Classification of knot vectors (seed 000 section 2-29: clamped / unclamped, uniform /
//! non-uniform; ISO 10303-42 `knot_type`) and detection of the periodic form.
//!
//! Knot values are compared with a relative tolerance of [`KNOT_REL_TOL`] times the knot
//! vector's total range, because exchanged files print knots with a limited number of
//! digits (`1/3` is never exactly equally spaced).
//!
//! **Periodic form** (pitfalls.md A.3, spec.md d.1/d.2). nurbsx has no separate periodic
//! type: a periodic curve is stored as Open CASCADE writes it after `SetNotPeriodic`, a flat
//! unclamped knot vector with wrapped poles. With `n + 1` poles, degree `p`, domain
//! `[u_p, u_{n+1}]` of length `T`, and `w` wrapped poles (`1 <= w <= p`, index period
//! `N = n + 1 - w`), the data is periodic when
//! - the knots wrap: `u_{i+N} = u_i + T` for every `i` with `i + N <= n + p + 1`, and
//! - the poles wrap homogeneously: `P_{i+N} = P_i` and `w_{i+N} = w_i` for `i < w`.
//!
//! `w = p` is the classic periodic curve with a simple seam knot (C^(p-1) at the seam, seed
//! figure 2-124); smaller `w` is an Open CASCADE periodic curve whose seam knot has
//! multiplicity `p + 1 - w` (C^(w-1)), e.g. the degree-2 circle of spec.md c.4 with `w = 1`.

use super::insert::{Bundle, Dir};
use super::knots::{clamped, to_distinct};
use super::{NurbsCurve, NurbsSurface};

/// Relative tolerance (of the knot range) for comparing knot values and spacings.
pub const KNOT_REL_TOL: f64 = 1e-10;

/// The ISO 10303-42 `knot_type` of a knot vector, which a STEP writer puts in `knot_spec`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnotType {
    /// Equally spaced knots, all multiplicity 1 (`.UNIFORM_KNOTS.`).
    UniformKnots,
    /// Equally spaced distinct knots, end multiplicity `p + 1`, interior 1
    /// (`.QUASI_UNIFORM_KNOTS.`).
    QuasiUniformKnots,
    /// Equally spaced distinct knots, end multiplicity `p + 1`, interior `p`; also a single
    /// Bezier span (`.PIECEWISE_BEZIER_KNOTS.`).
    PiecewiseBezierKnots,
    /// Anything else (`.UNSPECIFIED.`).
    Unspecified,
}

impl KnotType {
    /// The Part 21 enumeration literal, e.g. `.QUASI_UNIFORM_KNOTS.`.
    pub fn step_name(self) -> &'static str {
        match self {
            KnotType::UniformKnots => ".UNIFORM_KNOTS.",
            KnotType::QuasiUniformKnots => ".QUASI_UNIFORM_KNOTS.",
            KnotType::PiecewiseBezierKnots => ".PIECEWISE_BEZIER_KNOTS.",
            KnotType::Unspecified => ".UNSPECIFIED.",
        }
    }
}

/// What a knot vector (and, for [`Layout::Periodic`], its poles) looks like; the most
/// specific kind wins (periodic, then uniform / quasi-uniform / piecewise Bezier, then
/// clamped / unclamped).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// Periodic form with `wrapped` repeated poles (see the module documentation).
    Periodic {
        /// Number of wrapped poles `w` (`p` for a simple seam knot).
        wrapped: usize,
    },
    /// [`KnotType::UniformKnots`] (unclamped, equally spaced, not periodic).
    Uniform,
    /// [`KnotType::QuasiUniformKnots`].
    QuasiUniform,
    /// [`KnotType::PiecewiseBezierKnots`].
    PiecewiseBezier,
    /// Both ends clamped (multiplicity `p + 1`), otherwise non-uniform.
    Clamped,
    /// At least one end not clamped, non-uniform.
    Unclamped,
}

impl Layout {
    /// The name `nurbsx info` prints: "periodic", "uniform", "quasi-uniform",
    /// "piecewise Bezier", "clamped" or "unclamped".
    pub fn name(&self) -> &'static str {
        match self {
            Layout::Periodic { .. } => "periodic",
            Layout::Uniform => "uniform",
            Layout::QuasiUniform => "quasi-uniform",
            Layout::PiecewiseBezier => "piecewise Bezier",
            Layout::Clamped => "clamped",
            Layout::Unclamped => "unclamped",
        }
    }
}

impl std::fmt::Display for Layout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

fn knot_tol(knots: &[f64]) -> f64 {
    match (knots.first(), knots.last()) {
        (Some(a), Some(b)) => KNOT_REL_TOL * (b - a).abs(),
        _ => 0.0,
    }
}

/// The ISO 10303-42 `knot_type` of a flat knot vector of degree `degree` (see
/// [`KnotType`]). For degree 1, clamped equally spaced knots with simple interior knots are
/// reported as quasi-uniform (they are piecewise Bezier too).
pub fn knot_type(degree: usize, knots: &[f64]) -> KnotType {
    let (values, mults) = to_distinct(knots);
    if values.len() < 2 {
        return KnotType::Unspecified;
    }
    let tol = knot_tol(knots);
    let h = (values[values.len() - 1] - values[0]) / (values.len() - 1) as f64;
    let equal = values.windows(2).all(|w| ((w[1] - w[0]) - h).abs() <= tol);
    if !equal {
        return KnotType::Unspecified;
    }
    let last = mults.len() - 1;
    let interior = &mults[1..last];
    if mults.iter().all(|&m| m == 1) {
        return KnotType::UniformKnots;
    }
    if mults[0] == degree + 1 && mults[last] == degree + 1 {
        if interior.is_empty() {
            return KnotType::PiecewiseBezierKnots;
        }
        if interior.iter().all(|&m| m == 1) {
            return KnotType::QuasiUniformKnots;
        }
        if interior.iter().all(|&m| m == degree) {
            return KnotType::PiecewiseBezierKnots;
        }
    }
    KnotType::Unspecified
}

/// The layout of a knot vector alone (never [`Layout::Periodic`], which needs the poles).
pub fn classify_knots(degree: usize, knots: &[f64]) -> Layout {
    match knot_type(degree, knots) {
        KnotType::UniformKnots => Layout::Uniform,
        KnotType::QuasiUniformKnots => Layout::QuasiUniform,
        KnotType::PiecewiseBezierKnots => Layout::PiecewiseBezier,
        KnotType::Unspecified => {
            let m = knots.len() - 1;
            if knots[0] == knots[degree] && knots[m - degree] == knots[m] {
                Layout::Clamped
            } else {
                Layout::Unclamped
            }
        }
    }
}

/// The largest `w` for which every row of the bundle is in periodic form (module
/// documentation); poles are compared with `tolerance` (Euclidean distance) and weights
/// with [`KNOT_REL_TOL`] relative.
pub(super) fn periodic_wrap_bundle(b: &Bundle, tolerance: f64) -> Option<usize> {
    let p = b.degree;
    let np = b.poles();
    let u = &b.knots;
    let m = u.len() - 1;
    let (a, e) = b.domain();
    let period = e - a;
    let ktol = knot_tol(u);
    (1..=p).rev().find(|&w| {
        let Some(nn) = np.checked_sub(w).filter(|&nn| nn >= 1) else {
            return false;
        };
        let knots_wrap = (0..=m - nn).all(|i| (u[i + nn] - u[i] - period).abs() <= ktol);
        knots_wrap
            && b.rows.iter().all(|row| {
                (0..w).all(|i| {
                    let (h0, h1) = (row[i], row[i + nn]);
                    let (p0, p1) = (super::from_homogeneous(h0), super::from_homogeneous(h1));
                    let d = ((p0[0] - p1[0]).powi(2)
                        + (p0[1] - p1[1]).powi(2)
                        + (p0[2] - p1[2]).powi(2))
                    .sqrt();
                    d <= tolerance && (h0[3] - h1[3]).abs() <= KNOT_REL_TOL * h0[3].max(h1[3])
                })
            })
    })
}

impl NurbsCurve {
    /// The layout of the knot vector, [`Layout::Periodic`] when the data is in periodic
    /// form (poles compared within `tolerance`; see the module documentation).
    pub fn layout(&self, tolerance: f64) -> Layout {
        match periodic_wrap_bundle(&self.to_bundle(), tolerance) {
            Some(wrapped) => Layout::Periodic { wrapped },
            None => classify_knots(self.degree(), self.knots()),
        }
    }

    /// The ISO 10303-42 `knot_type` a STEP writer should put in `knot_spec`.
    pub fn knot_type(&self) -> KnotType {
        knot_type(self.degree(), self.knots())
    }

    /// Whether the start and end points of the domain are within `tolerance`.
    pub fn is_closed(&self, tolerance: f64) -> bool {
        let (a, b) = self.domain();
        let (p, q) = (self.point_at_unchecked(a), self.point_at_unchecked(b));
        let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
        d <= tolerance
    }
}

impl NurbsSurface {
    /// The layout of the u knot vector ([`Layout::Periodic`] if every column wraps).
    pub fn layout_u(&self, tolerance: f64) -> Layout {
        self.layout_dir(Dir::U, tolerance)
    }

    /// The layout of the v knot vector ([`Layout::Periodic`] if every row wraps).
    pub fn layout_v(&self, tolerance: f64) -> Layout {
        self.layout_dir(Dir::V, tolerance)
    }

    /// The ISO 10303-42 `knot_type` for `knot_spec`: the common type of both directions,
    /// `Unspecified` when they differ.
    pub fn knot_type(&self) -> KnotType {
        let ku = knot_type(self.degree_u(), self.knots_u());
        let kv = knot_type(self.degree_v(), self.knots_v());
        if ku == kv { ku } else { KnotType::Unspecified }
    }

    /// Whether `S(u_start, v)` and `S(u_end, v)` are within `tolerance` at every v knot and
    /// 64 evenly spaced v values (a sampled check). With u knots clamped at both ends, the
    /// two boundary curves are the first and last rows of poles: equal weights and poles
    /// within `tolerance` make them so everywhere (their difference is a convex combination
    /// of the poles' differences, NURBS Book eq. 4.2), which is decided without sampling.
    pub fn is_closed_u(&self, tolerance: f64) -> bool {
        let (poles, last) = (
            self.control_points(),
            self.control_points().nu().saturating_sub(1),
        );
        if clamped(self.knots_u(), self.degree_u())
            && (0..poles.nv()).all(|j| {
                close(*poles.get(0, j), *poles.get(last, j), tolerance)
                    && self.weights().is_none_or(|w| w.get(0, j) == w.get(last, j))
            })
        {
            return true;
        }
        // Clamped both ways, the boundary curves start and end at the corner poles (NURBS
        // Book eq. 3.10): corners apart decide "open" without evaluating, as the first and
        // last samples would.
        if self.corners_apart(Dir::U, tolerance) {
            return false;
        }
        let ((u0, u1), (v0, v1)) = self.domain();
        sample_params(v0, v1, self.knots_v()).all(|v| {
            close(
                self.point_at_unchecked(u0, v),
                self.point_at_unchecked(u1, v),
                tolerance,
            )
        })
    }

    /// Whether `S(u, v_start)` and `S(u, v_end)` are within `tolerance` (decided from the
    /// poles or sampled as [`is_closed_u`](Self::is_closed_u)).
    pub fn is_closed_v(&self, tolerance: f64) -> bool {
        let (poles, last) = (
            self.control_points(),
            self.control_points().nv().saturating_sub(1),
        );
        if clamped(self.knots_v(), self.degree_v())
            && (0..poles.nu()).all(|i| {
                close(*poles.get(i, 0), *poles.get(i, last), tolerance)
                    && self.weights().is_none_or(|w| w.get(i, 0) == w.get(i, last))
            })
        {
            return true;
        }
        if self.corners_apart(Dir::V, tolerance) {
            return false;
        }
        let ((u0, u1), (v0, v1)) = self.domain();
        sample_params(u0, u1, self.knots_u()).all(|u| {
            close(
                self.point_at_unchecked(u, v0),
                self.point_at_unchecked(u, v1),
                tolerance,
            )
        })
    }

    /// Whether the surface is clamped in both directions and a pair of corner poles facing
    /// each other across `dir` (first and last row of `dir`, at either end of the other
    /// direction) is farther apart than `tolerance`: the two boundary curves of `dir` then
    /// differ at that end, where each passes through its corner pole.
    fn corners_apart(&self, dir: Dir, tolerance: f64) -> bool {
        let poles = self.control_points();
        let (nu, nv) = (poles.nu(), poles.nv());
        if nu == 0
            || nv == 0
            || !clamped(self.knots_u(), self.degree_u())
            || !clamped(self.knots_v(), self.degree_v())
        {
            return false;
        }
        let pairs = match dir {
            Dir::U => [((0, 0), (nu - 1, 0)), ((0, nv - 1), (nu - 1, nv - 1))],
            Dir::V => [((0, 0), (0, nv - 1)), ((nu - 1, 0), (nu - 1, nv - 1))],
        };
        pairs
            .iter()
            .any(|&((i, j), (k, l))| !close(*poles.get(i, j), *poles.get(k, l), tolerance))
    }

    fn layout_dir(&self, dir: Dir, tolerance: f64) -> Layout {
        let b = self.to_bundle(dir);
        match periodic_wrap_bundle(&b, tolerance) {
            Some(wrapped) => Layout::Periodic { wrapped },
            None => classify_knots(b.degree, &b.knots),
        }
    }
}

fn close(p: [f64; 3], q: [f64; 3], tolerance: f64) -> bool {
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt() <= tolerance
}

fn sample_params<'a>(a: f64, b: f64, knots: &'a [f64]) -> impl Iterator<Item = f64> + 'a {
    (0..=64)
        .map(move |i| (a + (b - a) * f64::from(i) / 64.0).clamp(a, b))
        .chain(knots.iter().copied().filter(move |&k| k >= a && k <= b))
}

#[cfg(test)]
mod tests {
    use crate::nurbs::NurbsSurface;
    use crate::nurbs::grid::Grid;
    use crate::nurbs::sweep::{Frame, torus};
    use crate::nurbs::vector::dist;

    /// The largest distance between the two boundary curves of `s` in u (`along_u`) or v,
    /// from 2001 evaluations each: the oracle the pole-row decision must agree with.
    fn boundary_gap(s: &NurbsSurface, along_u: bool) -> f64 {
        let ((u0, u1), (v0, v1)) = s.domain();
        (0..=2000)
            .map(|k| {
                let x = k as f64 / 2000.0;
                if along_u {
                    let v = v0 + (v1 - v0) * x;
                    dist(s.point_at_unchecked(u0, v), s.point_at_unchecked(u1, v))
                } else {
                    let u = u0 + (u1 - u0) * x;
                    dist(s.point_at_unchecked(u, v0), s.point_at_unchecked(u, v1))
                }
            })
            .fold(0.0, f64::max)
    }

    /// Closed in both directions (a rational torus, poles decide), and a bilinear patch
    /// whose far edge is moved by half or twice the tolerance: the verdict is the dense
    /// evaluation's in every case, in both directions.
    #[test]
    fn closedness_from_the_poles_agrees_with_evaluation() {
        let tau = 2.0 * std::f64::consts::PI;
        let f = Frame {
            origin: [1.0, -2.0, 0.5],
            x: [0.0, 1.0, 0.0],
            y: [0.0, 0.0, 1.0],
            z: [1.0, 0.0, 0.0],
        };
        let (t, _) = torus(&f, 30.0, 6.0, (0.0, tau), (0.0, tau)).unwrap();
        assert!(t.is_closed_u(1e-9) && t.is_closed_v(1e-9));
        assert!(boundary_gap(&t, true) <= 1e-9 && boundary_gap(&t, false) <= 1e-9);
        let tol = 1e-6;
        for (shift, want) in [(0.5 * tol, true), (2.0 * tol, false)] {
            // Rows u = 0 and u = 1 of a 2 x 3 net at the same place but for `shift`.
            let poles = Grid::from_fn(2, 3, |i, j| [i as f64 * shift, j as f64, 0.0]);
            let s = NurbsSurface::new(
                1,
                2,
                vec![0.0, 0.0, 1.0, 1.0],
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                poles,
                None,
            )
            .unwrap();
            assert_eq!(s.is_closed_u(tol), want, "{shift}");
            assert_eq!(boundary_gap(&s, true) <= tol, want);
            assert!(!s.is_closed_v(tol) && boundary_gap(&s, false) > tol);
        }
    }

    /// Nets closed in one direction and open in the other, with the rows facing each other
    /// across the open direction apart at one corner only, or only inside (corners within
    /// tolerance: the sampled check decides): every verdict is the dense evaluation's.
    #[test]
    fn corner_poles_decide_only_what_evaluation_decides() {
        let tol = 1e-6;
        // A bicubic-by-quadratic net, rows i (u) and columns j (v); `bend` moves one pole
        // of the last row (u = 1) by `by` in z.
        let net = |bend: (usize, usize), by: f64, closed_u: bool| {
            Grid::from_fn(4, 3, |i, j| {
                let mut p = [i as f64, (j * j) as f64, (i * j) as f64 * 0.25];
                if closed_u && i == 3 {
                    p = [0.0, (j * j) as f64, 0.0];
                }
                if (i, j) == bend {
                    p[2] += by;
                }
                p
            })
        };
        let surface = |poles| {
            NurbsSurface::new(
                3,
                2,
                vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                poles,
                None,
            )
            .unwrap()
        };
        for (bend, by) in [
            ((3, 0), 0.5 * tol),
            ((3, 0), 2.0 * tol),
            ((3, 2), 2.0 * tol),
            // Inside only: the boundary curves are 0.75 and 1.5 tolerances apart at most
            // (the quadratic middle basis function peaks at 1/2).
            ((3, 1), 1.5 * tol),
            ((3, 1), 3.0 * tol),
        ] {
            // The net and its transpose (the same verdicts across v).
            let s = surface(net(bend, by, true));
            let t = s.swap_uv().unwrap();
            for x in [&s, &t] {
                let at = format!("{bend:?} {by}");
                assert_eq!(x.is_closed_u(tol), boundary_gap(x, true) <= tol, "{at}");
                assert_eq!(x.is_closed_v(tol), boundary_gap(x, false) <= tol, "{at}");
            }
        }
        // Closed across u with every corner in place; open across v at every corner.
        let s = surface(net((0, 0), 0.0, true));
        assert!(s.is_closed_u(tol) && !s.is_closed_v(tol));
    }
}
