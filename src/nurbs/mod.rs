//! # The NURBS core
//!
//! One exact model for every B-spline and NURBS curve and surface nurbsx reads or writes,
//! and the textbook algorithms on it. Citations are to Piegl & Tiller, *The NURBS Book*,
//! 2nd ed. (algorithm numbers A2.1 ...), and to the seed texts in `shared/seeds/`.
//!
//! **Layering rule:** this module imports nothing from the format layer, the HTTP service or
//! the CLI (checked by `.ci/run`). It knows geometry only.
//!
//! ## Representation
//! - [`NurbsCurve`] / [`NurbsSurface`]: degree(s), *flat* knot vector(s), Euclidean control
//!   points stored exactly as read, optional weights (`None` = polynomial), dimension 2 or 3.
//! - Checked constructors only; serde deserialisation goes through them ([`serde_form`]).
//! - The valid domain is `[u_p, u_{n+1}]`; unclamped knot vectors are first-class.
//! - Algorithms lift poles to homogeneous [`Hpoint`]s `(w x, w y, w z, w)` internally.
//!
//! ## Modules
//! - [`knots`]: validation, span search (A2.1), multiplicities, domain.
//! - [`basis`]: basis functions and their derivatives (A2.2, A2.3).
//! - [`curve`], [`surface`], [`grid`]: the types.
//! - [`derivatives`], [`differential`], [`batch`]: derivatives of any order (A3.2, A3.6, A4.2,
//!   A4.4), normals, curvature and torsion, batch evaluation (its span lookup and
//!   register-resident A2.2 live in the private `kernels`).
//! - [`insert`], [`remove`], [`bezier`], [`split`], [`clamp`], [`layout`], [`periodic`]:
//!   knot insertion and refinement (A5.1, A5.3, A5.4), removal (A5.8), Bezier decomposition
//!   (A5.6), split and join, clamping and unclamping (A12.1), knot-vector classification,
//!   periodic <-> open.
//! - [`elevate`], [`reduce`]: degree elevation (A5.9, A5.10) and reduction (A5.11).
//! - [`transform`]: affine maps (IGES 124), reversal, reparameterisation, isoparametric curves.
//! - [`conic`], [`sweep`]: exact constructions: lines, polylines, conic arcs (A7.1) with the
//!   exact map between the conic's parameter and the NURBS parameter; surfaces of revolution
//!   (A8.1), extrusions, ruled surfaces and the ISO 10303-42 quadrics; [`coons`]: bilinearly
//!   blended Coons patches on common bases.
//! - [`project`]: point inversion on surfaces (section 6.1) and pcurves of curves lying on
//!   surfaces, fitted at the curve's own parameters.
//! - [`fit`]: global curve interpolation (A9.1) with uniform, chord-length and centripetal
//!   parameters and averaged knots; least-squares curve approximation with a given pole
//!   count (section 9.4.1); surface interpolation (A9.4) and approximation (A9.7) over a
//!   grid; each with the residual at the data points.
//! - [`measure`]: curve length and surface area by adaptive Gauss-Kronrod quadrature with
//!   an error estimate, and the directed (one-sided Hausdorff) distance between shapes.
//! - [`tessellate`]: adaptive tessellation of curves (osculating-circle rule, seed 004) and
//!   surfaces.

pub mod basis;
pub mod batch;
pub mod bernstein;
pub mod bezier;
pub mod clamp;
pub mod conic;
pub mod coons;
pub mod curve;
pub mod derivatives;
pub mod differential;
mod double_double;
pub mod elevate;
mod error;
pub mod fit;
pub mod grid;
pub mod insert;
mod kernels;
pub mod knot_intervals;
pub mod knots;
pub mod layout;
pub mod measure;
pub mod periodic;
pub mod project;
pub mod reduce;
pub mod remove;
pub mod serde_form;
pub mod split;
pub mod surface;
pub mod sweep;
pub mod tessellate;
pub mod transform;
pub mod vector;

pub use curve::NurbsCurve;
pub use error::GeometryError;
pub use grid::Grid;
pub use surface::NurbsSurface;

/// A Euclidean point or vector `[x, y, z]` (z = 0 for 2-D geometry).
pub type Point3 = [f64; 3];

/// A homogeneous point `[w x, w y, w z, w]`.
pub type Hpoint = [f64; 4];

/// The highest degree the core handles. Evaluation uses stack buffers of this size; the
/// exchange layer applies a lower, configurable limit (25 by default, as Open CASCADE).
pub const MAX_DEGREE: usize = 64;

/// A curve or a surface.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// A curve.
    Curve(NurbsCurve),
    /// A surface.
    Surface(NurbsSurface),
}

impl Geometry {
    /// Whether the geometry carries weights.
    pub fn is_rational(&self) -> bool {
        match self {
            Geometry::Curve(c) => c.is_rational(),
            Geometry::Surface(s) => s.is_rational(),
        }
    }

    /// 2 or 3.
    pub fn dimension(&self) -> usize {
        match self {
            Geometry::Curve(c) => c.dimension(),
            Geometry::Surface(s) => s.dimension(),
        }
    }
}

/// Euclidean distance between two points.
#[inline]
pub fn distance(a: Point3, b: Point3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The axis-aligned bounding box `(lo, hi)` of some points (`(+inf, -inf)` when empty).
pub fn bounding_box<'a>(points: impl IntoIterator<Item = &'a Point3>) -> (Point3, Point3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            // Plain comparisons, not `f64::min`/`max`: the same result (a NaN coordinate
            // compares false and is skipped, as `min` skips it; `lo`/`hi` are never NaN)
            // in one `minsd`/`maxsd` instead of a NaN-checking sequence. Readers compute
            // this for every B-spline's closure check.
            if p[k] < lo[k] {
                lo[k] = p[k];
            }
            if p[k] > hi[k] {
                hi[k] = p[k];
            }
        }
    }
    (lo, hi)
}

/// The diagonal of the bounding box of some points: the "model size" that relative
/// tolerances refer to (0 for a single point or no points).
pub fn bounding_box_diagonal(points: &[Point3]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let (lo, hi) = bounding_box(points);
    distance(lo, hi)
}

/// Lifts a Euclidean point with weight `w` to `(w x, w y, w z, w)`.
#[inline]
pub fn to_homogeneous(p: Point3, w: f64) -> Hpoint {
    [p[0] * w, p[1] * w, p[2] * w, w]
}

/// Projects `(w x, w y, w z, w)` back to `(x, y, z)`.
#[inline]
pub fn from_homogeneous(h: Hpoint) -> Point3 {
    [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
}

/// Splits homogeneous poles into Euclidean points and (when `rational`) weights. For 2-D
/// geometry z is forced to exactly 0 (it is 0 up to rounding after projection).
pub(crate) fn split_homogeneous(
    h: &[Hpoint],
    rational: bool,
    dimension: usize,
) -> (Vec<Point3>, Option<Vec<f64>>) {
    let points = h
        .iter()
        .map(|&q| {
            let mut p = if rational {
                from_homogeneous(q)
            } else {
                [q[0], q[1], q[2]]
            };
            if dimension == 2 {
                p[2] = 0.0;
            }
            p
        })
        .collect();
    let weights = rational.then(|| h.iter().map(|q| q[3]).collect());
    (points, weights)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The comparison form equals a fold with `f64::min`/`max` (the reference), NaN
        /// coordinates included (both skip them).
        #[test]
        fn bounding_box_is_the_min_max_fold(
            pts in proptest::collection::vec(
                proptest::array::uniform3(prop_oneof![-1e6..1e6f64, Just(f64::NAN), Just(-0.0), Just(0.0)]),
                0..20,
            ),
        ) {
            let (lo, hi) = bounding_box(&pts);
            let mut rlo = [f64::INFINITY; 3];
            let mut rhi = [f64::NEG_INFINITY; 3];
            for p in &pts {
                for k in 0..3 {
                    rlo[k] = rlo[k].min(p[k]);
                    rhi[k] = rhi[k].max(p[k]);
                }
            }
            for k in 0..3 {
                // Equal as numbers (the sign of a zero bound is not specified by `min`).
                prop_assert!(lo[k] == rlo[k], "{:?} {:?}", lo, rlo);
                prop_assert!(hi[k] == rhi[k], "{:?} {:?}", hi, rhi);
            }
        }
    }
}
