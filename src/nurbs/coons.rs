//! Bilinearly blended Coons patches (NURBS Book section 10.5; seed 001, Coons patches):
//! `S = R1 + R2 - T`, where R1 is the ruled surface between the boundaries `C0 = S(u, 0)`
//! and `C1 = S(u, 1)`, R2 the ruled surface between `D0 = S(0, v)` and `D1 = S(1, v)`, and
//! T the bilinear patch of the four corners.
//!
//! All three are written on common bases: the opposite boundaries are made compatible by
//! degree elevation (A5.9) and knot refinement (A5.4) (as for [`super::sweep::ruled`]),
//! and the direction in which a surface is linear is raised to the other pair's degree and
//! knots by linear precision: `v = sum_j g_j N_{j,q}(v)` with the Greville abscissae
//! `g_j = (v_{j+1} + ... + v_{j+q}) / q`, so the linear blend `(1 - v) A + v B` has the poles
//! `(1 - g_j) A + g_j B` on any knot vector of degree q >= 1 (exact, the same as degree
//! elevation of the degree-1 blend followed by knot refinement). The poles of S are then
//! the sums of the poles.
//!
//! Polynomial boundaries only: a Coons patch of rational boundaries is not the sum of the
//! homogeneous nets (the weights would be blended too), so those are refused.

use super::sweep::ruled;
use super::{GeometryError, Grid, NurbsCurve, NurbsSurface, Point3, distance};

/// The Greville abscissae of a knot vector of degree `p` (`knots.len() - p - 1` values).
fn greville(knots: &[f64], p: usize) -> Vec<f64> {
    (0..knots.len() - p - 1)
        .map(|j| knots[j + 1..=j + p].iter().sum::<f64>() / p as f64)
        .collect()
}

/// Degree, knots and the two pole rows of a compatible pair of curves.
type CompatiblePair = (usize, Vec<f64>, Vec<Point3>, Vec<Point3>);

/// The two compatible pole rows of a pair of opposite boundaries on `[0, 1]`, with their
/// degree and knots (through [`ruled`], which elevates and refines them).
fn compatible(a: &NurbsCurve, b: &NurbsCurve) -> Result<CompatiblePair, GeometryError> {
    let r = ruled(&a.reparameterize(0.0, 1.0)?, &b.reparameterize(0.0, 1.0)?)?;
    let net = r.control_points();
    let first = (0..net.nu()).map(|i| *net.get(i, 0)).collect();
    let second = (0..net.nu()).map(|i| *net.get(i, 1)).collect();
    Ok((r.degree_u(), r.knots_u().to_vec(), first, second))
}

/// The bilinearly blended Coons patch of `c0 = S(u, 0)`, `c1 = S(u, 1)`, `d0 = S(0, v)` and
/// `d1 = S(1, v)`, on `[0, 1] x [0, 1]` (each boundary is reparameterised onto [0, 1]).
/// The corners must agree within `tolerance` (`c0` start = `d0` start, `c0` end = `d1`
/// start, `c1` start = `d0` end, `c1` end = `d1` end); the patch then reproduces each
/// boundary up to the corner mismatch and rounding.
///
/// Errors ([`GeometryError::InvalidArgument`]): a rational boundary, corners further apart
/// than `tolerance`, a negative or non-finite tolerance.
pub fn coons(
    c0: &NurbsCurve,
    c1: &NurbsCurve,
    d0: &NurbsCurve,
    d1: &NurbsCurve,
    tolerance: f64,
) -> Result<NurbsSurface, GeometryError> {
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(GeometryError::InvalidArgument(format!(
            "Coons patch: tolerance {tolerance} must be a finite number >= 0"
        )));
    }
    let curves = [c0, c1, d0, d1];
    if curves.iter().any(|c| c.is_rational()) {
        return Err(GeometryError::InvalidArgument(
            "Coons patch: rational boundaries are not supported (the bilinear blend of \
             rational curves is not the sum of their nets)"
                .into(),
        ));
    }
    let ends = |c: &NurbsCurve| -> Result<(Point3, Point3), GeometryError> {
        let (a, b) = c.domain();
        Ok((c.point_at(a)?, c.point_at(b)?))
    };
    let (c00, c01) = ends(c0)?;
    let (c10, c11) = ends(c1)?;
    let (d00, d01) = ends(d0)?;
    let (d10, d11) = ends(d1)?;
    for (name, p, q) in [
        ("S(0,0)", c00, d00),
        ("S(1,0)", c01, d10),
        ("S(0,1)", c10, d01),
        ("S(1,1)", c11, d11),
    ] {
        let gap = distance(p, q);
        // A NaN gap (non-finite poles) is refused as well.
        if gap.is_nan() || gap > tolerance {
            return Err(GeometryError::InvalidArgument(format!(
                "Coons patch: the boundaries miss each other at the corner {name} by {gap:e}, \
                 above the tolerance {tolerance:e}"
            )));
        }
    }
    let mid = |p: Point3, q: Point3| -> Point3 { std::array::from_fn(|k| 0.5 * (p[k] + q[k])) };
    let corners = [mid(c00, d00), mid(c01, d10), mid(c10, d01), mid(c11, d11)];
    let (p, knots_u, a0, a1) = compatible(&c0.clamp()?, &c1.clamp()?)?;
    let (q, knots_v, b0, b1) = compatible(&d0.clamp()?, &d1.clamp()?)?;
    let (gu, gv) = (greville(&knots_u, p), greville(&knots_v, q));
    let blend = |a: Point3, b: Point3, t: f64| -> Point3 {
        std::array::from_fn(|k| (1.0 - t) * a[k] + t * b[k])
    };
    let points = Grid::from_fn(gu.len(), gv.len(), |i, j| {
        let (s, t) = (gu[i], gv[j]);
        let r1 = blend(a0[i], a1[i], t);
        let r2 = blend(b0[j], b1[j], s);
        let t0 = blend(corners[0], corners[1], s);
        let t1 = blend(corners[2], corners[3], s);
        let tb = blend(t0, t1, t);
        std::array::from_fn(|k| r1[k] + r2[k] - tb[k])
    });
    NurbsSurface::new(p, q, knots_u, knots_v, points, None)
}
