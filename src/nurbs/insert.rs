//! Knot insertion (NURBS Book A5.1 CurveKnotIns, A5.3 SurfaceKnotIns) and knot refinement
//! (A5.4 RefineKnotVectCurve, applied per direction for surfaces as in A5.5).
//!
//! All knot algorithms of this crate (insertion, removal, Bezier decomposition, split,
//! clamping, periodic conversion) run on a `Bundle`: several homogeneous control polygons
//! that share one degree and one knot vector. A curve is a bundle of one polygon; a surface
//! seen along u is the bundle of its `nv` columns `(0..nu, j)`, and along v the bundle of its
//! `nu` rows `(i, 0..nv)`. So every curve algorithm is also the per-direction surface
//! algorithm (A5.3 and A5.5 are exactly "A5.1/A5.4 applied to every row with shared
//! alphas"), with one code path to test.
//!
//! Policy: insertion never raises a multiplicity above the degree `p` (A5.1's precondition
//! `r + s <= p`), not even at the domain ends; to reach `p + 1` at an end use
//! [`clamp_start`](NurbsCurve::clamp_start) / [`clamp_end`](NurbsCurve::clamp_end), which
//! also drop the poles that no longer influence the domain.

use super::knots::{find_span, multiplicity};
use super::{GeometryError, Grid, Hpoint, NurbsCurve, NurbsSurface};

/// Homogeneous control polygons sharing a degree and a flat knot vector (see the module
/// documentation). Invariant: every row has `knots.len() - degree - 1` poles.
#[derive(Debug, Clone)]
pub(super) struct Bundle {
    pub(super) degree: usize,
    pub(super) knots: Vec<f64>,
    pub(super) rows: Vec<Vec<Hpoint>>,
}

impl Bundle {
    /// Number of poles per row (`n + 1`).
    pub(super) fn poles(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// The valid domain `[u_p, u_{n+1}]`.
    pub(super) fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.poles()])
    }

    /// Applies `f` to every row, keeping degree and replacing knots.
    pub(super) fn map_rows(
        &self,
        knots: Vec<f64>,
        f: impl FnMut(&Vec<Hpoint>) -> Vec<Hpoint>,
    ) -> Bundle {
        Bundle {
            degree: self.degree,
            knots,
            rows: self.rows.iter().map(f).collect(),
        }
    }
}

/// A surface direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Dir {
    /// Along u (the bundle of columns).
    U,
    /// Along v (the bundle of rows).
    V,
}

impl NurbsCurve {
    /// The curve as a bundle of one homogeneous polygon.
    pub(super) fn to_bundle(&self) -> Bundle {
        Bundle {
            degree: self.degree(),
            knots: self.knots().to_vec(),
            rows: vec![self.homogeneous()],
        }
    }

    /// A curve with this curve's rationality and dimension from a one-row bundle.
    pub(super) fn with_bundle(&self, b: Bundle) -> Result<NurbsCurve, GeometryError> {
        let row = b
            .rows
            .into_iter()
            .next()
            .ok_or_else(|| GeometryError::InvalidArgument("empty bundle".into()))?;
        NurbsCurve::from_homogeneous(
            b.degree,
            b.knots,
            &row,
            self.is_rational(),
            self.dimension(),
        )
    }
}

impl NurbsSurface {
    /// The surface seen along `dir` as a bundle (see the module documentation).
    pub(super) fn to_bundle(&self, dir: Dir) -> Bundle {
        let h = self.homogeneous();
        let (nu, nv) = (h.nu(), h.nv());
        match dir {
            Dir::U => Bundle {
                degree: self.degree_u(),
                knots: self.knots_u().to_vec(),
                rows: (0..nv)
                    .map(|j| (0..nu).map(|i| *h.get(i, j)).collect())
                    .collect(),
            },
            Dir::V => Bundle {
                degree: self.degree_v(),
                knots: self.knots_v().to_vec(),
                rows: (0..nu).map(|i| h.row(i).to_vec()).collect(),
            },
        }
    }

    /// A surface like this one with direction `dir` replaced by the bundle `b`.
    pub(super) fn with_bundle(&self, dir: Dir, b: Bundle) -> Result<NurbsSurface, GeometryError> {
        let len = b.poles();
        if b.rows.iter().any(|r| r.len() != len) {
            return Err(GeometryError::InvalidArgument("ragged bundle".into()));
        }
        let net = match dir {
            Dir::U => Grid::from_fn(len, b.rows.len(), |i, j| b.rows[j][i]),
            Dir::V => Grid::from_fn(b.rows.len(), len, |i, j| b.rows[i][j]),
        };
        let (du, dv, ku, kv) = match dir {
            Dir::U => (b.degree, self.degree_v(), b.knots, self.knots_v().to_vec()),
            Dir::V => (self.degree_u(), b.degree, self.knots_u().to_vec(), b.knots),
        };
        NurbsSurface::from_homogeneous(du, dv, ku, kv, &net, self.is_rational(), self.dimension())
    }
}

/// `(1 - a) p + a q`.
#[inline]
pub(super) fn lerp(p: Hpoint, q: Hpoint, a: f64) -> Hpoint {
    let b = 1.0 - a;
    [
        b * p[0] + a * q[0],
        b * p[1] + a * q[1],
        b * p[2] + a * q[2],
        b * p[3] + a * q[3],
    ]
}

/// Inserts `u` `r` times into every row (A5.1, with the alphas computed once for all rows as
/// in A5.3). Preconditions (checked by the callers): `u_p <= u <= u_{n+1}` and
/// `r + s <= p` where `s` is the current multiplicity of `u`.
pub(super) fn insert_bundle(b: &Bundle, u: f64, r: usize) -> Bundle {
    if r == 0 {
        return b.clone();
    }
    let p = b.degree;
    let up = &b.knots;
    let n = b.poles() - 1;
    // k: the last index with u_k <= u, so u_k <= u < u_{k+1} (A5.1's span).
    let k = up.partition_point(|&x| x <= u) - 1;
    let s = multiplicity(up, u);
    let mut uq = Vec::with_capacity(up.len() + r);
    uq.extend_from_slice(&up[..=k]);
    uq.extend(std::iter::repeat_n(u, r));
    uq.extend_from_slice(&up[k + 1..]);
    // alphas[j - 1][i], A5.3's "alpha" table shared by all rows.
    let alphas: Vec<Vec<f64>> = (1..=r)
        .map(|j| {
            let l = k - p + j;
            (0..=p - j - s)
                .map(|i| (u - up[l + i]) / (up[i + k + 1] - up[l + i]))
                .collect()
        })
        .collect();
    b.map_rows(uq, |pw| {
        let mut qw = vec![[0.0; 4]; n + 1 + r];
        qw[..=k - p].copy_from_slice(&pw[..=k - p]);
        qw[k - s + r..].copy_from_slice(&pw[k - s..]);
        let mut rw: Vec<Hpoint> = pw[k - p..=k - s].to_vec();
        let mut l = k - p;
        for j in 1..=r {
            l = k - p + j;
            for (i, &a) in alphas[j - 1].iter().enumerate() {
                rw[i] = lerp(rw[i], rw[i + 1], a);
            }
            qw[l] = rw[0];
            qw[k + r - j - s] = rw[p - j - s];
        }
        if l + 1 < k - s {
            qw[l + 1..k - s].copy_from_slice(&rw[1..k - s - l]);
        }
        qw
    })
}

/// Checks `u` and `times` for a public insertion into `b`.
fn check_insert(b: &Bundle, u: f64, times: usize) -> Result<(), GeometryError> {
    let (start, end) = b.domain();
    if !(u >= start && u <= end) {
        return Err(GeometryError::OutOfDomain { t: u, start, end });
    }
    let s = multiplicity(&b.knots, u);
    let total = s.saturating_add(times);
    if total > b.degree {
        return Err(GeometryError::InvalidArgument(format!(
            "inserting knot {u} {times} time(s) would raise its multiplicity from {s} to \
             {total}, above the degree {} (use clamp_start/clamp_end for end multiplicity p+1)",
            b.degree
        )));
    }
    Ok(())
}

/// Refines every row with the sorted knots `x` (A5.4 RefineKnotVectCurve). Preconditions:
/// `x` sorted, non-empty, inside the domain, resulting multiplicities at most `p`.
fn refine_bundle(b: &Bundle, x: &[f64]) -> Bundle {
    let p = b.degree;
    let u = &b.knots;
    let np = b.poles();
    let n = np - 1;
    let m = n + p + 1;
    let r = x.len() - 1;
    let a = find_span(p, np, u, x[0]);
    let bb = find_span(p, np, u, x[r]) + 1;
    let mut ubar = vec![0.0; m + r + 2];
    ubar[..=a].copy_from_slice(&u[..=a]);
    for j in bb + p..=m {
        ubar[j + r + 1] = u[j];
    }
    let mut rows = Vec::with_capacity(b.rows.len());
    for (row_index, pw) in b.rows.iter().enumerate() {
        let mut qw = vec![[0.0; 4]; np + r + 1];
        qw[..=a - p].copy_from_slice(&pw[..=a - p]);
        for j in bb - 1..=n {
            qw[j + r + 1] = pw[j];
        }
        // Knots are rebuilt identically for every row; keep the first row's.
        let mut ub = ubar.clone();
        let mut i = bb + p - 1;
        let mut k = bb + p + r;
        for j in (0..=r).rev() {
            while x[j] <= u[i] && i > a {
                qw[k - p - 1] = pw[i - p - 1];
                ub[k] = u[i];
                k -= 1;
                i -= 1;
            }
            qw[k - p - 1] = qw[k - p];
            for l in 1..=p {
                let ind = k - p + l;
                let alfa = ub[k + l] - x[j];
                if alfa == 0.0 {
                    qw[ind - 1] = qw[ind];
                } else {
                    let alfa = alfa / (ub[k + l] - u[i - p + l]);
                    qw[ind - 1] = lerp(qw[ind], qw[ind - 1], alfa);
                }
            }
            ub[k] = x[j];
            k = k.wrapping_sub(1);
        }
        if row_index == 0 {
            ubar = ub;
        }
        rows.push(qw);
    }
    Bundle {
        degree: p,
        knots: ubar,
        rows,
    }
}

/// Checks and sorts the knots to insert by [`refine_bundle`].
fn check_refine(b: &Bundle, x: &[f64]) -> Result<Vec<f64>, GeometryError> {
    let (start, end) = b.domain();
    if let Some(&t) = x.iter().find(|&&t| !(t >= start && t <= end)) {
        return Err(GeometryError::OutOfDomain { t, start, end });
    }
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    for (_, value, count) in super::knots::runs(&sorted) {
        let s = multiplicity(&b.knots, value);
        if s + count > b.degree {
            return Err(GeometryError::InvalidArgument(format!(
                "refinement would raise the multiplicity of knot {value} from {s} to {}, \
                 above the degree {}",
                s + count,
                b.degree
            )));
        }
    }
    Ok(sorted)
}

/// Public refinement on a bundle: checks, then A5.4 (nothing to do for an empty list).
fn refine_checked(b: &Bundle, x: &[f64]) -> Result<Bundle, GeometryError> {
    let sorted = check_refine(b, x)?;
    if sorted.is_empty() {
        return Ok(b.clone());
    }
    Ok(refine_bundle(b, &sorted))
}

impl NurbsCurve {
    /// Inserts the knot `u` `times` times (NURBS Book A5.1 CurveKnotIns, in homogeneous space;
    /// a rational curve stays rational). The geometry and the domain are unchanged.
    ///
    /// Errors: `u` not finite or outside the domain ([`GeometryError::OutOfDomain`]); the
    /// resulting multiplicity would exceed the degree ([`GeometryError::InvalidArgument`]).
    /// `times == 0` returns a copy.
    pub fn insert_knot(&self, u: f64, times: usize) -> Result<NurbsCurve, GeometryError> {
        let b = self.to_bundle();
        check_insert(&b, u, times)?;
        self.with_bundle(insert_bundle(&b, u, times))
    }

    /// Inserts all knots of `x` at once (NURBS Book A5.4 RefineKnotVectCurve; `x` need not
    /// be sorted, values may repeat). Same errors as [`insert_knot`](Self::insert_knot),
    /// judged on the final multiplicities.
    pub fn refine(&self, x: &[f64]) -> Result<NurbsCurve, GeometryError> {
        self.with_bundle(refine_checked(&self.to_bundle(), x)?)
    }
}

impl NurbsSurface {
    /// Inserts `u` `times` times in the u direction (NURBS Book A5.3 SurfaceKnotIns, "U
    /// direction": the alphas are computed once and applied to every column). Errors as
    /// [`NurbsCurve::insert_knot`].
    pub fn insert_knot_u(&self, u: f64, times: usize) -> Result<NurbsSurface, GeometryError> {
        self.insert_dir(Dir::U, u, times)
    }

    /// Inserts `v` `times` times in the v direction (A5.3, "V direction").
    pub fn insert_knot_v(&self, v: f64, times: usize) -> Result<NurbsSurface, GeometryError> {
        self.insert_dir(Dir::V, v, times)
    }

    /// Refines the u knot vector with `x` (A5.5 RefineKnotVectSurface, u direction: A5.4 on
    /// every column).
    pub fn refine_u(&self, x: &[f64]) -> Result<NurbsSurface, GeometryError> {
        self.with_bundle(Dir::U, refine_checked(&self.to_bundle(Dir::U), x)?)
    }

    /// Refines the v knot vector with `x` (A5.5, v direction).
    pub fn refine_v(&self, x: &[f64]) -> Result<NurbsSurface, GeometryError> {
        self.with_bundle(Dir::V, refine_checked(&self.to_bundle(Dir::V), x)?)
    }

    fn insert_dir(&self, dir: Dir, t: f64, times: usize) -> Result<NurbsSurface, GeometryError> {
        let b = self.to_bundle(dir);
        check_insert(&b, t, times)?;
        self.with_bundle(dir, insert_bundle(&b, t, times))
    }
}
