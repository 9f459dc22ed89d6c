//! The NURBS curve type: degree, flat knots, Euclidean control points, optional weights.

use std::sync::Arc;

use super::basis::basis_funs;
use super::knots::{self, find_span};
use super::{GeometryError, Hpoint, MAX_DEGREE, Point3};

/// A B-spline or NURBS curve in 2-D or 3-D.
///
/// Control points are stored *Euclidean* (not multiplied by their weights) exactly as read,
/// with `weights: None` for a polynomial curve, so that import -> export is bit-exact.
/// Algorithms lift the poles to homogeneous form internally ([`NurbsCurve::homogeneous`]).
/// 2-D curves (STEP pcurves) keep `z = 0` internally and report [`dimension`] 2.
///
/// The only way to build one is the checked constructor [`NurbsCurve::new`] (also used by
/// deserialisation), so every value of this type satisfies the invariants listed there.
///
/// [`dimension`]: NurbsCurve::dimension
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve(Arc<CurveData>);

/// The data of a [`NurbsCurve`], behind one shared pointer: a clone (a face's surface
/// and the entity it came from, an edge's curve and its entity) shares the knots, poles
/// and weights instead of copying them. Every value is immutable once checked.
#[derive(Debug, Clone, PartialEq)]
struct CurveData {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<Point3>,
    weights: Option<Vec<f64>>,
    dimension: usize,
}

impl NurbsCurve {
    /// Builds a 3-D curve, checking every invariant:
    /// `1 <= degree <= MAX_DEGREE`; at least `degree + 1` poles;
    /// `knots.len() == poles + degree + 1`; knots finite and non-decreasing with valid
    /// multiplicities ([`knots::validate`]); coordinates finite; weights, when present, one per
    /// pole, finite and positive.
    ///
    /// ```
    /// # use nurbsx::nurbs::NurbsCurve;
    /// let c = NurbsCurve::new(1, vec![0., 0., 1., 1.], vec![[0., 0., 0.], [2., 0., 0.]], None)?;
    /// assert_eq!(c.point_at(0.25)?, [0.5, 0., 0.]);
    /// # Ok::<(), nurbsx::nurbs::GeometryError>(())
    /// ```
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<Point3>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, GeometryError> {
        Self::with_dimension(degree, knots, points, weights, 3)
    }

    /// Builds a curve of the given dimension (2 or 3). For dimension 2, every `z` must be 0.
    pub fn with_dimension(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<Point3>,
        weights: Option<Vec<f64>>,
        dimension: usize,
    ) -> Result<Self, GeometryError> {
        knots::validate(degree, points.len(), &knots)?;
        check_points(&points, dimension)?;
        let points = canonical_z(points, dimension);
        if let Some(w) = &weights {
            check_weights(w, points.len())?;
        }
        Ok(NurbsCurve(Arc::new(CurveData {
            degree,
            knots,
            points,
            weights,
            dimension,
        })))
    }

    /// Builds a curve from homogeneous poles `(w x, w y, w z, w)`, projecting them back to
    /// Euclidean points. `rational == false` drops the weights (they must then all be 1).
    pub fn from_homogeneous(
        degree: usize,
        knots: Vec<f64>,
        hpoles: &[Hpoint],
        rational: bool,
        dimension: usize,
    ) -> Result<Self, GeometryError> {
        let (points, weights) = super::split_homogeneous(hpoles, rational, dimension);
        Self::with_dimension(degree, knots, points, weights, dimension)
    }

    /// The degree `p`.
    pub fn degree(&self) -> usize {
        self.0.degree
    }

    /// The flat knot vector `u_0 .. u_{n+p+1}`.
    pub fn knots(&self) -> &[f64] {
        &self.0.knots
    }

    /// The Euclidean control points (z = 0 for 2-D curves).
    pub fn control_points(&self) -> &[Point3] {
        &self.0.points
    }

    /// The weights, or `None` for a polynomial curve.
    pub fn weights(&self) -> Option<&[f64]> {
        self.0.weights.as_deref()
    }

    /// The weight of pole `i` (1 for polynomial curves).
    #[inline]
    pub fn weight(&self, i: usize) -> f64 {
        self.0.weights.as_ref().map_or(1.0, |w| w[i])
    }

    /// Whether the curve carries weights.
    pub fn is_rational(&self) -> bool {
        self.0.weights.is_some()
    }

    /// Number of control points `n + 1`.
    pub fn num_poles(&self) -> usize {
        self.0.points.len()
    }

    /// 2 or 3.
    pub fn dimension(&self) -> usize {
        self.0.dimension
    }

    /// The valid parameter domain `[u_p, u_{n+1}]`.
    pub fn domain(&self) -> (f64, f64) {
        knots::domain(self.0.degree, self.0.points.len(), &self.0.knots)
    }

    /// The control points in homogeneous form `(w x, w y, w z, w)`.
    pub fn homogeneous(&self) -> Vec<Hpoint> {
        (0..self.0.points.len())
            .map(|i| super::to_homogeneous(self.0.points[i], self.weight(i)))
            .collect()
    }

    /// Decomposes the curve into its parts `(degree, knots, points, weights, dimension)`.
    pub fn into_parts(self) -> (usize, Vec<f64>, Vec<Point3>, Option<Vec<f64>>, usize) {
        let d = Arc::unwrap_or_clone(self.0);
        (d.degree, d.knots, d.points, d.weights, d.dimension)
    }

    /// Checks that `u` lies in the domain.
    pub fn check_parameter(&self, u: f64) -> Result<(), GeometryError> {
        let (start, end) = self.domain();
        if u >= start && u <= end {
            Ok(())
        } else {
            Err(GeometryError::OutOfDomain { t: u, start, end })
        }
    }

    /// The point at `u` (NURBS Book A3.1, and A4.1 for rational curves: evaluate in
    /// homogeneous space, then divide by the weight).
    pub fn point_at(&self, u: f64) -> Result<Point3, GeometryError> {
        self.check_parameter(u)?;
        Ok(self.point_at_unchecked(u))
    }

    /// [`point_at`](Self::point_at) for a parameter already known to be in the domain.
    #[inline]
    pub fn point_at_unchecked(&self, u: f64) -> Point3 {
        // The basis buffer sized to the degree: zeroing a MAX_DEGREE + 1 array on every
        // call costs more than a low-degree evaluation (same arithmetic, same bits).
        match self.0.degree {
            0..4 => self.point_in::<4>(u),
            4..8 => self.point_in::<8>(u),
            _ => self.point_in::<{ MAX_DEGREE + 1 }>(u),
        }
    }

    /// [`NurbsCurve::point_at_unchecked`] with a basis buffer of `N > degree` entries.
    #[inline(always)]
    fn point_in<const N: usize>(&self, u: f64) -> Point3 {
        let p = self.0.degree;
        let span = find_span(p, self.0.points.len(), &self.0.knots, u);
        let mut n = [0.0; N];
        basis_funs(span, u, p, &self.0.knots, &mut n);
        let base = span - p;
        match &self.0.weights {
            None => {
                let mut c = [0.0; 3];
                for (j, nj) in n[..=p].iter().enumerate() {
                    let q = self.0.points[base + j];
                    c[0] += nj * q[0];
                    c[1] += nj * q[1];
                    c[2] += nj * q[2];
                }
                c
            }
            Some(w) => {
                let mut c = [0.0; 4];
                for (j, nj) in n[..=p].iter().enumerate() {
                    let q = self.0.points[base + j];
                    let f = nj * w[base + j];
                    c[0] += f * q[0];
                    c[1] += f * q[1];
                    c[2] += f * q[2];
                    c[3] += f;
                }
                [c[0] / c[3], c[1] / c[3], c[2] / c[3]]
            }
        }
    }
}

/// 2-D geometry has no z: store it as +0.0 (a file may carry `-0.`), so that equal 2-D
/// data is equal bit for bit whatever format it came from.
fn canonical_z(points: Vec<Point3>, dimension: usize) -> Vec<Point3> {
    if dimension == 2 {
        points.into_iter().map(|[x, y, _]| [x, y, 0.0]).collect()
    } else {
        points
    }
}

pub(super) fn check_points(points: &[Point3], dimension: usize) -> Result<(), GeometryError> {
    if dimension != 2 && dimension != 3 {
        return Err(GeometryError::Dimension {
            index: 0,
            found: dimension,
            expected: 3,
        });
    }
    for (index, q) in points.iter().enumerate() {
        if !q.iter().all(|c| c.is_finite()) {
            return Err(GeometryError::NonFinitePoint { index });
        }
        if dimension == 2 && q[2] != 0.0 {
            return Err(GeometryError::Dimension {
                index,
                found: 3,
                expected: 2,
            });
        }
    }
    Ok(())
}

pub(super) fn check_weights(weights: &[f64], poles: usize) -> Result<(), GeometryError> {
    if weights.len() != poles {
        return Err(GeometryError::WeightCount {
            weights: weights.len(),
            poles,
        });
    }
    for (index, &value) in weights.iter().enumerate() {
        if !(value.is_finite() && value > 0.0) {
            return Err(GeometryError::BadWeight { index, value });
        }
    }
    Ok(())
}
