//! The NURBS surface type: two degrees, two flat knot vectors, a control net and optional
//! weights, indexed `(i, j)` with `i` along u and `j` along v.

use std::sync::Arc;

use super::basis::basis_funs;
use super::curve::{check_points, check_weights};
use super::knots::{self, find_span};
use super::{GeometryError, Grid, Hpoint, MAX_DEGREE, Point3};

/// A tensor-product B-spline or NURBS surface.
///
/// Storage follows [`NurbsCurve`](super::NurbsCurve): Euclidean control points exactly as
/// read, `weights: None` when polynomial. The control net is a [`Grid`] indexed `(i, j)`,
/// `i` along u (`0..nu`), `j` along v (`0..nv`).
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface(Arc<SurfaceData>);

/// The data of a [`NurbsSurface`], behind one shared pointer: a clone (a face's surface
/// and the entity it came from, an edge's curve and its entity) shares the knots, poles
/// and weights instead of copying them. Every value is immutable once checked.
#[derive(Debug, Clone, PartialEq)]
struct SurfaceData {
    degree_u: usize,
    degree_v: usize,
    knots_u: Vec<f64>,
    knots_v: Vec<f64>,
    points: Grid<Point3>,
    weights: Option<Grid<f64>>,
    dimension: usize,
}

impl NurbsSurface {
    /// Builds a 3-D surface, checking every invariant in both directions (see
    /// [`NurbsCurve::new`](super::NurbsCurve::new)); `weights`, when present, must have the
    /// net's shape.
    pub fn new(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        points: Grid<Point3>,
        weights: Option<Grid<f64>>,
    ) -> Result<Self, GeometryError> {
        Self::with_dimension(degree_u, degree_v, knots_u, knots_v, points, weights, 3)
    }

    /// Builds a surface of dimension 2 or 3 (2: every z is 0).
    pub fn with_dimension(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        points: Grid<Point3>,
        weights: Option<Grid<f64>>,
        dimension: usize,
    ) -> Result<Self, GeometryError> {
        knots::validate(degree_u, points.nu(), &knots_u)?;
        knots::validate(degree_v, points.nv(), &knots_v)?;
        check_points(points.as_slice(), dimension)?;
        let points = if dimension == 2 {
            points.map(|&[x, y, _]| [x, y, 0.0])
        } else {
            points
        };
        if let Some(w) = &weights {
            if w.nu() != points.nu() || w.nv() != points.nv() {
                return Err(GeometryError::WeightCount {
                    weights: w.as_slice().len(),
                    poles: points.as_slice().len(),
                });
            }
            check_weights(w.as_slice(), points.as_slice().len())?;
        }
        Ok(NurbsSurface(Arc::new(SurfaceData {
            degree_u,
            degree_v,
            knots_u,
            knots_v,
            points,
            weights,
            dimension,
        })))
    }

    /// Builds a surface from a homogeneous net `(w x, w y, w z, w)`; `rational == false`
    /// drops the weights.
    pub fn from_homogeneous(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        hnet: &Grid<Hpoint>,
        rational: bool,
        dimension: usize,
    ) -> Result<Self, GeometryError> {
        let (points, weights) = super::split_homogeneous(hnet.as_slice(), rational, dimension);
        let (nu, nv) = (hnet.nu(), hnet.nv());
        let points = Grid::from_u_major(nu, nv, points)
            .ok_or_else(|| GeometryError::InvalidArgument("control net shape".into()))?;
        let weights = match weights {
            Some(w) => Some(
                Grid::from_u_major(nu, nv, w)
                    .ok_or_else(|| GeometryError::InvalidArgument("weight net shape".into()))?,
            ),
            None => None,
        };
        Self::with_dimension(
            degree_u, degree_v, knots_u, knots_v, points, weights, dimension,
        )
    }

    /// Degree in u.
    pub fn degree_u(&self) -> usize {
        self.0.degree_u
    }

    /// Degree in v.
    pub fn degree_v(&self) -> usize {
        self.0.degree_v
    }

    /// Flat knot vector in u.
    pub fn knots_u(&self) -> &[f64] {
        &self.0.knots_u
    }

    /// Flat knot vector in v.
    pub fn knots_v(&self) -> &[f64] {
        &self.0.knots_v
    }

    /// The control net.
    pub fn control_points(&self) -> &Grid<Point3> {
        &self.0.points
    }

    /// The weights, or `None` when polynomial.
    pub fn weights(&self) -> Option<&Grid<f64>> {
        self.0.weights.as_ref()
    }

    /// The weight of pole `(i, j)` (1 when polynomial).
    #[inline]
    pub fn weight(&self, i: usize, j: usize) -> f64 {
        self.0.weights.as_ref().map_or(1.0, |w| *w.get(i, j))
    }

    /// Whether the surface carries weights.
    pub fn is_rational(&self) -> bool {
        self.0.weights.is_some()
    }

    /// 2 or 3.
    pub fn dimension(&self) -> usize {
        self.0.dimension
    }

    /// The valid domain `([u_p, u_{n+1}], [v_q, v_{m+1}])`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        (
            knots::domain(self.0.degree_u, self.0.points.nu(), &self.0.knots_u),
            knots::domain(self.0.degree_v, self.0.points.nv(), &self.0.knots_v),
        )
    }

    /// The control net in homogeneous form.
    pub fn homogeneous(&self) -> Grid<Hpoint> {
        Grid::from_fn(self.0.points.nu(), self.0.points.nv(), |i, j| {
            super::to_homogeneous(*self.0.points.get(i, j), self.weight(i, j))
        })
    }

    /// Decomposes the surface into
    /// `(degree_u, degree_v, knots_u, knots_v, points, weights, dimension)`.
    #[allow(clippy::type_complexity)]
    pub fn into_parts(
        self,
    ) -> (
        usize,
        usize,
        Vec<f64>,
        Vec<f64>,
        Grid<Point3>,
        Option<Grid<f64>>,
        usize,
    ) {
        let d = Arc::unwrap_or_clone(self.0);
        (
            d.degree_u,
            d.degree_v,
            d.knots_u,
            d.knots_v,
            d.points,
            d.weights,
            d.dimension,
        )
    }

    /// Checks that `(u, v)` lies in the domain.
    pub fn check_parameter(&self, u: f64, v: f64) -> Result<(), GeometryError> {
        let ((u0, u1), (v0, v1)) = self.domain();
        if !(u >= u0 && u <= u1) {
            return Err(GeometryError::OutOfDomain {
                t: u,
                start: u0,
                end: u1,
            });
        }
        if !(v >= v0 && v <= v1) {
            return Err(GeometryError::OutOfDomain {
                t: v,
                start: v0,
                end: v1,
            });
        }
        Ok(())
    }

    /// The point at `(u, v)` (NURBS Book A3.5; A4.3 for rational surfaces).
    pub fn point_at(&self, u: f64, v: f64) -> Result<Point3, GeometryError> {
        self.check_parameter(u, v)?;
        Ok(self.point_at_unchecked(u, v))
    }

    /// [`point_at`](Self::point_at) for parameters already known to be in the domain.
    #[inline]
    pub fn point_at_unchecked(&self, u: f64, v: f64) -> Point3 {
        // Basis buffers sized to the degrees: zeroing two MAX_DEGREE + 1 arrays on every
        // call costs more than a bicubic evaluation (same arithmetic, same bits).
        match self.0.degree_u.max(self.0.degree_v) {
            0..4 => self.point_in::<4>(u, v),
            4..8 => self.point_in::<8>(u, v),
            _ => self.point_in::<{ MAX_DEGREE + 1 }>(u, v),
        }
    }

    /// [`NurbsSurface::point_at_unchecked`] with basis buffers of `N > degree` entries.
    #[inline(always)]
    fn point_in<const N: usize>(&self, u: f64, v: f64) -> Point3 {
        let (p, q) = (self.0.degree_u, self.0.degree_v);
        let su = find_span(p, self.0.points.nu(), &self.0.knots_u, u);
        let sv = find_span(q, self.0.points.nv(), &self.0.knots_v, v);
        let mut nu = [0.0; N];
        let mut nv = [0.0; N];
        basis_funs(su, u, p, &self.0.knots_u, &mut nu);
        basis_funs(sv, v, q, &self.0.knots_v, &mut nv);
        let mut s = [0.0; 4];
        for (k, nk) in nu[..=p].iter().enumerate() {
            let i = su - p + k;
            let row = self.0.points.row(i);
            let mut t = [0.0; 4];
            for (l, nl) in nv[..=q].iter().enumerate() {
                let j = sv - q + l;
                let w = self.weight(i, j);
                let f = nl * w;
                t[0] += f * row[j][0];
                t[1] += f * row[j][1];
                t[2] += f * row[j][2];
                t[3] += f;
            }
            for c in 0..4 {
                s[c] += nk * t[c];
            }
        }
        [s[0] / s[3], s[1] / s[3], s[2] / s[3]]
    }
}
