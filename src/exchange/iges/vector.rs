//! Small vector and affine-map helpers for the entity conversions.

use crate::nurbs::Point3;
use crate::nurbs::transform::Affine;

pub(super) fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(super) fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn scale(a: Point3, s: f64) -> Point3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(super) fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn norm(a: Point3) -> f64 {
    dot(a, a).sqrt()
}

/// `a` scaled to unit length; `None` for a zero or non-finite vector.
pub(super) fn unit(a: Point3) -> Option<Point3> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

/// The affine map `a` after `b`: `x -> a(b(x))`.
pub(super) fn compose(a: &Affine, b: &Affine) -> Affine {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| {
            let lin = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
            if c == 3 { lin + a[r][3] } else { lin }
        })
    })
}

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
