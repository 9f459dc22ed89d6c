//! Affine-map helpers for the entity conversions (and the core's vector helpers, re-exported).

use crate::nurbs::Point3;
use crate::nurbs::transform::Affine;
pub(super) use crate::nurbs::transform::compose;
pub(super) use crate::nurbs::vector::{add, cross, dot, norm, scale, sub, unit};

/// The linear part of an affine map applied to a direction.
pub(super) fn apply_linear(m: &Affine, d: Point3) -> Point3 {
    std::array::from_fn(|r| m[r][0] * d[0] + m[r][1] * d[1] + m[r][2] * d[2])
}

/// The inverse of an affine map (Cramer's rule on the 3 x 3 part); `None` when singular.
pub(super) fn invert(m: &Affine) -> Option<Affine> {
    let r = |i: usize| [m[i][0], m[i][1], m[i][2]];
    let (r0, r1, r2) = (r(0), r(1), r(2));
    let det = dot(r0, cross(r1, r2));
    if !(det.abs() > 0.0 && det.is_finite()) {
        return None;
    }
    // Columns of the inverse are the cross products of the rows, over the determinant.
    let c0 = scale(cross(r1, r2), 1.0 / det);
    let c1 = scale(cross(r2, r0), 1.0 / det);
    let c2 = scale(cross(r0, r1), 1.0 / det);
    let inv: [[f64; 3]; 3] = std::array::from_fn(|i| [c0[i], c1[i], c2[i]]);
    let t = [m[0][3], m[1][3], m[2][3]];
    Some(std::array::from_fn(|i| {
        let mt = -(inv[i][0] * t[0] + inv[i][1] * t[1] + inv[i][2] * t[2]);
        [inv[i][0], inv[i][1], inv[i][2], mt]
    }))
}
