//! Euclidean 3-vector arithmetic on [`Point3`], the one set of helpers every layer uses.

use super::Point3;

/// `a + b`.
#[inline]
pub fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline]
pub fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `f a`.
#[inline]
pub fn scale(a: Point3, f: f64) -> Point3 {
    [a[0] * f, a[1] * f, a[2] * f]
}

/// `a . b`.
#[inline]
pub fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
#[inline]
pub fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a|`.
#[inline]
pub fn norm(a: Point3) -> f64 {
    dot(a, a).sqrt()
}

/// `|a - b|`.
#[inline]
pub fn dist(a: Point3, b: Point3) -> f64 {
    norm(sub(a, b))
}

/// `a` scaled to unit length; `None` for a zero or non-finite vector.
#[inline]
pub fn unit(a: Point3) -> Option<Point3> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}
