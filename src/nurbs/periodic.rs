//! Conversion between the periodic form and the open (clamped) form.
//!
//! The periodic form is the flat, unclamped knot vector with wrapped poles described in
//! [`layout`](super::layout) (Open CASCADE's unperiodized layout, spec.md d.1/d.2).
//!
//! - [`NurbsCurve::to_open`] cuts a curve at its seam: it clamps both ends (knot insertion,
//!   A5.1, then the outer knots and poles are dropped). Exact, same domain.
//! - [`NurbsCurve::to_periodic`] builds the classic periodic form (`p` wrapped poles, simple
//!   seam knot): the curve is clamped, its seam continuity is measured, and both ends are
//!   unclamped with the wrap-around knots of seed formulas 2-168 / 2-169 (A12.1). For a
//!   closed curve that is C^(p-1) at the seam *in homogeneous coordinates* the new end poles
//!   then coincide with the poles at the other end (seed figure 2-125c); they are set to
//!   the mean of each wrapped group so the wrap holds exactly. Continuity is homogeneous
//!   because the periodic form shares poles and weights across the seam: a rational curve
//!   whose weights are not C^(p-1) across the seam (e.g. the three-arc circle with double
//!   knots, which is only C^0 homogeneously) has no such form.

use super::clamp::{clamp_bundle, unclamp_bundle};
use super::insert::{Bundle, Dir};
use super::{GeometryError, Hpoint, NurbsCurve, NurbsSurface};

/// Homogeneous derivatives `0..=kmax` at the start (`at_end == false`) or end of one clamped
/// row, from the derivative control points of A3.3 CurveDerivCpts:
/// `P^(k)_i = (p - k + 1) / (u_{i+p+1} - u_{i+k}) (P^(k-1)_{i+1} - P^(k-1)_i)`,
/// `C^(k)(a) = P^(k)_0`, `C^(k)(b) = P^(k)_{n-k}`.
fn end_derivatives(p: usize, u: &[f64], row: &[Hpoint], kmax: usize, at_end: bool) -> Vec<Hpoint> {
    let n = row.len() - 1;
    let lo = if at_end { n - kmax } else { 0 };
    let mut level: Vec<Hpoint> = row[lo..=lo + kmax].to_vec();
    let mut out = vec![if at_end { level[kmax] } else { level[0] }];
    for k in 1..=kmax {
        let next: Vec<Hpoint> = (0..level.len() - 1)
            .map(|j| {
                let i = lo + j;
                let f = (p - k + 1) as f64 / (u[i + p + 1] - u[i + k]);
                let (a, b) = (level[j], level[j + 1]);
                [
                    f * (b[0] - a[0]),
                    f * (b[1] - a[1]),
                    f * (b[2] - a[2]),
                    f * (b[3] - a[3]),
                ]
            })
            .collect();
        level = next;
        // After k levels, entry j is P^(k)_{lo + j}; the end wants P^(k)_{n-k}.
        out.push(if at_end { level[n - k - lo] } else { level[0] });
    }
    out
}

/// The test value of eq. 5.30 (NURBS Book): `d * w_min / (1 + |P|_max)` for rational data.
fn homogeneous_tol(b: &Bundle, rational: bool, d: f64) -> f64 {
    if !rational {
        return d;
    }
    let mut wmin = f64::INFINITY;
    let mut pmax: f64 = 0.0;
    for h in b.rows.iter().flatten() {
        wmin = wmin.min(h[3]);
        let q = super::from_homogeneous(*h);
        pmax = pmax.max((q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt());
    }
    d * wmin / (1.0 + pmax)
}

/// Seam continuity of a clamped bundle in homogeneous coordinates: `None` if some row's end
/// points differ by more than `tol` (homogeneous), else the largest `k <= p` such that the
/// derivatives of orders `0..=k` agree for every row. Derivative differences of order `r`
/// are scaled by `h^r (p-r)!/p!` (`h` the shorter end span) to pole-sized distances.
fn seam_continuity_bundle(c: &Bundle, tol: f64) -> Option<usize> {
    let p = c.degree;
    let u = &c.knots;
    let n = c.poles() - 1;
    let h = (u[p + 1] - u[p]).min(u[n + 1] - u[n]);
    let mut found: Option<usize> = None;
    let starts: Vec<Vec<Hpoint>> = c
        .rows
        .iter()
        .map(|r| end_derivatives(p, u, r, p, false))
        .collect();
    let ends: Vec<Vec<Hpoint>> = c
        .rows
        .iter()
        .map(|r| end_derivatives(p, u, r, p, true))
        .collect();
    let mut scale = 1.0;
    for r in 0..=p {
        if r > 0 {
            scale *= h / (p - r + 1) as f64;
        }
        let ok = starts.iter().zip(&ends).all(|(s, e)| {
            let d = (0..4)
                .map(|c| (s[r][c] - e[r][c]).powi(2))
                .sum::<f64>()
                .sqrt();
            d * scale <= tol
        });
        if !ok {
            break;
        }
        found = Some(r);
    }
    found
}

/// The periodic form of a bundle (module documentation).
fn to_periodic_bundle(b: &Bundle, rational: bool, tolerance: f64) -> Result<Bundle, GeometryError> {
    if !(tolerance >= 0.0 && tolerance.is_finite()) {
        return Err(GeometryError::InvalidArgument(format!(
            "to_periodic: tolerance {tolerance} must be finite and non-negative"
        )));
    }
    let p = b.degree;
    let clamped = clamp_bundle(b);
    let tol = homogeneous_tol(&clamped, rational, tolerance);
    match seam_continuity_bundle(&clamped, tol) {
        None => {
            return Err(GeometryError::InvalidArgument(
                "to_periodic: the curve is not closed (in homogeneous coordinates) within the \
                 tolerance"
                    .into(),
            ));
        }
        Some(k) if k + 1 < p => {
            return Err(GeometryError::InvalidArgument(format!(
                "to_periodic: seam continuity is C^{k} (homogeneous); a periodic form of \
                 degree {p} needs C^{}",
                p - 1
            )));
        }
        Some(_) => {}
    }
    let mut out = unclamp_bundle(&clamped);
    let np = out.poles();
    let period = np - p;
    let mut worst: f64 = 0.0;
    for row in &mut out.rows {
        for r in 0..period.min(np) {
            let group: Vec<usize> = (r..np).step_by(period).collect();
            let count = group.len() as f64;
            let mut mean = [0.0; 4];
            for &i in &group {
                for c in 0..4 {
                    mean[c] += row[i][c] / count;
                }
            }
            for &i in &group {
                let d = (0..4)
                    .map(|c| (row[i][c] - mean[c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                worst = worst.max(d);
                row[i] = mean;
            }
        }
    }
    if worst.is_nan() || worst > tol {
        let geometric = if tol > 0.0 {
            worst * tolerance / tol
        } else {
            worst
        };
        return Err(GeometryError::ToleranceExceeded {
            what: "to_periodic: wrapped poles differ",
            bound: geometric,
            tolerance,
        });
    }
    Ok(out)
}

impl NurbsCurve {
    /// The open form: the curve clamped at both ends of its domain, i.e. cut at the seam of a
    /// periodic curve (A5.1 insertion up to multiplicity `p`, outer knots and poles dropped).
    /// Exact; same domain. Works for any curve (same as [`clamp`](Self::clamp)).
    pub fn to_open(&self) -> Result<NurbsCurve, GeometryError> {
        self.clamp()
    }

    /// The continuity order at the seam (end of the domain meeting its start), measured in
    /// homogeneous coordinates with `tolerance` (eq. 5.30 correction for rational curves):
    /// `None` if the curve is not closed, else `Some(k)` with `k <= p`.
    pub fn seam_continuity(&self, tolerance: f64) -> Option<usize> {
        let c = clamp_bundle(&self.to_bundle());
        let tol = homogeneous_tol(&c, self.is_rational(), tolerance);
        seam_continuity_bundle(&c, tol)
    }

    /// The classic periodic form (`p` wrapped poles, seam knot multiplicity 1, unclamped
    /// wrap-around knots), same geometry on the same domain (module documentation).
    ///
    /// Errors ([`GeometryError::InvalidArgument`]): not closed, or the seam continuity found
    /// (named in the message) is below C^(p-1); [`GeometryError::ToleranceExceeded`] if the
    /// wrapped poles still differ by more than `tolerance` after unclamping.
    pub fn to_periodic(&self, tolerance: f64) -> Result<NurbsCurve, GeometryError> {
        let b = to_periodic_bundle(&self.to_bundle(), self.is_rational(), tolerance)?;
        self.with_bundle(b)
    }
}

impl NurbsSurface {
    /// The open form in u: clamped at both u ends (exact).
    pub fn to_open_u(&self) -> Result<NurbsSurface, GeometryError> {
        self.clamp_u(super::clamp::End::Both)
    }

    /// The open form in v: clamped at both v ends (exact).
    pub fn to_open_v(&self) -> Result<NurbsSurface, GeometryError> {
        self.clamp_v(super::clamp::End::Both)
    }

    /// The periodic form in u: every column must be closed with homogeneous C^(p-1)
    /// continuity at the seam (as [`NurbsCurve::to_periodic`]).
    pub fn to_periodic_u(&self, tolerance: f64) -> Result<NurbsSurface, GeometryError> {
        let b = to_periodic_bundle(&self.to_bundle(Dir::U), self.is_rational(), tolerance)?;
        self.with_bundle(Dir::U, b)
    }

    /// The periodic form in v (every row; as [`to_periodic_u`](Self::to_periodic_u)).
    pub fn to_periodic_v(&self, tolerance: f64) -> Result<NurbsSurface, GeometryError> {
        let b = to_periodic_bundle(&self.to_bundle(Dir::V), self.is_rational(), tolerance)?;
        self.with_bundle(Dir::V, b)
    }
}
