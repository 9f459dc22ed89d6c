//! Affine transforms (IGES 5.3 entity 124, `x' = R x + T`), reversal, affine
//! reparameterisation and isoparametric curves (NURBS Book sections 4.4 "invariance",
//! 5.x reversal, A3.5 / A4.3 for the iso-curve contraction).

use super::basis::basis_funs;
use super::knots::{breakpoints, find_span};
use super::{GeometryError, Grid, Hpoint, MAX_DEGREE, NurbsCurve, NurbsSurface, Point3};

/// A 3x4 affine matrix `[[r11, r12, r13, t1], [r21, r22, r23, t2], [r31, r32, r33, t3]]`,
/// the layout of IGES entity 124 (`x' = R x + T`).
pub type Affine = [[f64; 4]; 3];

/// The identity map.
pub const IDENTITY: Affine = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

/// The affine map `a` after `b`: `x -> a(b(x))` (IGES 5.3 section 4.21: a 124 that refers
/// to another 124 composes this way; ISO 10303-42 placements of nested items likewise).
pub fn compose(a: &Affine, b: &Affine) -> Affine {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| {
            let lin = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
            if c == 3 { lin + a[r][3] } else { lin }
        })
    })
}

/// Applies an affine matrix to a point.
#[inline]
pub fn apply(m: &Affine, p: Point3) -> Point3 {
    std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
}

fn check_matrix(m: &Affine) -> Result<(), GeometryError> {
    if m.iter().flatten().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(GeometryError::InvalidArgument(
            "transform: matrix entries must be finite".into(),
        ))
    }
}

/// The dimension of transformed poles: 2 if the input was 2-D and every transformed z is
/// exactly 0, else 3.
fn result_dimension(dimension: usize, points: &[Point3]) -> usize {
    if dimension == 2 && points.iter().all(|q| q[2] == 0.0) {
        2
    } else {
        3
    }
}

/// Maps a knot vector by `u -> a + b - u` and reverses it (NURBS Book section 5.x,
/// "reversing a curve"). The domain ends map exactly onto each other, and values are kept
/// monotone and on the right side of the domain ends despite rounding, so the reversed
/// vector is valid and has exactly the same domain.
fn reverse_knots(knots: &[f64], a: f64, b: f64) -> Vec<f64> {
    knots.iter().rev().map(|&u| mirror(u, a, b)).collect()
}

/// `u -> a + b - u`, with the domain ends mapped exactly onto each other and values kept on
/// their side of the domain ends despite rounding (the map [`reverse_knots`] applies).
fn mirror(u: f64, a: f64, b: f64) -> f64 {
    let s = a + b;
    if u == a {
        b
    } else if u == b {
        a
    } else if u < a {
        (s - u).max(b)
    } else if u > b {
        (s - u).min(a)
    } else {
        (s - u).clamp(a, b)
    }
}

/// Maps a knot vector affinely so that `[a, b]` becomes `[c, d]` (ends exact, order kept).
fn map_knots(knots: &[f64], (a, b): (f64, f64), (c, d): (f64, f64)) -> Vec<f64> {
    let scale = (d - c) / (b - a);
    knots
        .iter()
        .map(|&u| {
            if u == a {
                c
            } else if u == b {
                d
            } else {
                let v = c + (u - a) * scale;
                if u > a && u < b { v.clamp(c, d) } else { v }
            }
        })
        .collect()
}

fn check_interval(c: f64, d: f64) -> Result<(), GeometryError> {
    if c.is_finite() && d.is_finite() && c < d {
        Ok(())
    } else {
        Err(GeometryError::InvalidArgument(format!(
            "reparameterize: [{c}, {d}] is not a finite interval with start < end"
        )))
    }
}

impl NurbsCurve {
    /// The curve under the affine map `x' = R x + T` (IGES 124 matrix layout, see
    /// [`Affine`]).
    ///
    /// Applied to the Euclidean poles, weights unchanged. This is exact for rational curves
    /// too: `C(u) = sum R_i(u) P_i` with rational basis functions `R_i` that sum to 1, so
    /// `A C(u) + T = sum R_i(u) (A P_i + T)` (affine invariance, NURBS Book eq. 4.x).
    /// A 2-D curve stays 2-D if every image has z = 0.
    pub fn transform(&self, m: &Affine) -> Result<NurbsCurve, GeometryError> {
        check_matrix(m)?;
        let points: Vec<Point3> = self.control_points().iter().map(|&q| apply(m, q)).collect();
        let dim = result_dimension(self.dimension(), &points);
        NurbsCurve::with_dimension(
            self.degree(),
            self.knots().to_vec(),
            points,
            self.weights().map(<[f64]>::to_vec),
            dim,
        )
    }

    /// The parameter of [`reverse`](Self::reverse)'s curve at which it passes where this
    /// curve is at `t`: `a + b - t`, with the domain's ends mapped exactly onto each other
    /// (as the reversed knots are), so that a range ending at a domain end still does after
    /// the reversal.
    pub fn reversed_parameter(&self, t: f64) -> f64 {
        let (a, b) = self.domain();
        mirror(t, a, b)
    }

    /// The same point set traversed the other way: `C'(u) = C(a + b - u)` on the same
    /// domain `[a, b]` (poles and weights reversed, knots mirrored).
    pub fn reverse(&self) -> Result<NurbsCurve, GeometryError> {
        let (a, b) = self.domain();
        let mut points = self.control_points().to_vec();
        points.reverse();
        let weights = self.weights().map(|w| w.iter().rev().copied().collect());
        NurbsCurve::with_dimension(
            self.degree(),
            reverse_knots(self.knots(), a, b),
            points,
            weights,
            self.dimension(),
        )
    }

    /// The same curve on the domain `[c, d]`: `C'(c + (d - c) s) = C(a + (b - a) s)`. The
    /// knot vector is mapped affinely, which changes no pole (the basis functions are
    /// invariant under an affine change of parameter).
    pub fn reparameterize(&self, c: f64, d: f64) -> Result<NurbsCurve, GeometryError> {
        check_interval(c, d)?;
        NurbsCurve::with_dimension(
            self.degree(),
            map_knots(self.knots(), self.domain(), (c, d)),
            self.control_points().to_vec(),
            self.weights().map(<[f64]>::to_vec),
            self.dimension(),
        )
    }
}

/// The isoparametric curve of `s` at parameter `t` of one direction (`in_u`: the fixed
/// parameter is u, the curve runs along v): for every pole `j` of the other direction,
/// `sum_k N_{k,p}(t) Pw_{k,j}` (A3.5 / A4.3 first stage), exact in homogeneous space. Only the
/// `p + 1` rows the basis functions touch are lifted to homogeneous form (`w x, w y, w z, w`,
/// the same products as [`NurbsSurface::homogeneous`]), not the net.
///
/// At a breakpoint ([`breakpoints`]: a clamped end, NURBS Book eq. 3.10, or an interior
/// knot of multiplicity `p`; one basis function is 1 there, the others 0) the curve is that
/// row of the net itself: its poles and weights are copied, not lifted and divided back (the
/// same curve with the net's own digits, where the basis functions computed in floating
/// point may sum the row with a rounding; an edge along a face's boundary asks for this on
/// every B-rep read).
fn iso_curve(s: &NurbsSurface, in_u: bool, t: f64) -> Result<NurbsCurve, GeometryError> {
    let (p, knots, q, other_knots) = if in_u {
        (s.degree_u(), s.knots_u(), s.degree_v(), s.knots_v())
    } else {
        (s.degree_v(), s.knots_v(), s.degree_u(), s.knots_u())
    };
    let net = s.control_points();
    let (fixed, free) = if in_u {
        (net.nu(), net.nv())
    } else {
        (net.nv(), net.nu())
    };
    let at = |k: usize, j: usize| if in_u { (k, j) } else { (j, k) };
    let dimension = s.dimension();
    let flat = |mut x: Point3| {
        if dimension == 2 {
            x[2] = 0.0;
        }
        x
    };
    // At a breakpoint (a clamped end, or an interior knot of multiplicity p, between arcs)
    // one basis function is 1 and the others 0: the isocurve is that row of the net.
    let row = breakpoints(knots, p)
        .find(|&(x, _)| x == t)
        .map(|(_, k)| k)
        .filter(|&k| k < fixed);
    if let Some(k) = row {
        let points = (0..free)
            .map(|j| {
                let (a, b) = at(k, j);
                flat(*net.get(a, b))
            })
            .collect();
        let weights = s.is_rational().then(|| {
            (0..free)
                .map(|j| {
                    let (a, b) = at(k, j);
                    s.weight(a, b)
                })
                .collect()
        });
        return NurbsCurve::with_dimension(q, other_knots.to_vec(), points, weights, dimension);
    }
    let span = find_span(p, fixed, knots, t);
    let mut n = [0.0; MAX_DEGREE + 1];
    basis_funs(span, t, p, knots, &mut n);
    let basis = &n[..=p];
    let h: Vec<Hpoint> = (0..free)
        .map(|j| {
            let mut sum = [0.0; 4];
            for (k, nk) in basis.iter().enumerate() {
                let (a, b) = at(span - p + k, j);
                let x = super::to_homogeneous(*net.get(a, b), s.weight(a, b));
                for c in 0..4 {
                    sum[c] += nk * x[c];
                }
            }
            sum
        })
        .collect();
    NurbsCurve::from_homogeneous(q, other_knots.to_vec(), &h, s.is_rational(), dimension)
}

impl NurbsSurface {
    /// The surface under `x' = R x + T` (IGES 124), applied to the Euclidean poles; exact for
    /// rational surfaces for the same reason as [`NurbsCurve::transform`].
    pub fn transform(&self, m: &Affine) -> Result<NurbsSurface, GeometryError> {
        check_matrix(m)?;
        let points = self.control_points().map(|&q| apply(m, q));
        let dim = result_dimension(self.dimension(), points.as_slice());
        NurbsSurface::with_dimension(
            self.degree_u(),
            self.degree_v(),
            self.knots_u().to_vec(),
            self.knots_v().to_vec(),
            points,
            self.weights().cloned(),
            dim,
        )
    }

    /// Reverses the u direction: `S'(u, v) = S(a + b - u, v)` on the same domain.
    pub fn reverse_u(&self) -> Result<NurbsSurface, GeometryError> {
        let ((a, b), _) = self.domain();
        let nu = self.control_points().nu();
        let nv = self.control_points().nv();
        let points = Grid::from_fn(nu, nv, |i, j| *self.control_points().get(nu - 1 - i, j));
        let weights = self
            .weights()
            .map(|w| Grid::from_fn(nu, nv, |i, j| *w.get(nu - 1 - i, j)));
        NurbsSurface::with_dimension(
            self.degree_u(),
            self.degree_v(),
            reverse_knots(self.knots_u(), a, b),
            self.knots_v().to_vec(),
            points,
            weights,
            self.dimension(),
        )
    }

    /// Reverses the v direction: `S'(u, v) = S(u, c + d - v)` on the same domain.
    pub fn reverse_v(&self) -> Result<NurbsSurface, GeometryError> {
        let (_, (c, d)) = self.domain();
        let nu = self.control_points().nu();
        let nv = self.control_points().nv();
        let points = Grid::from_fn(nu, nv, |i, j| *self.control_points().get(i, nv - 1 - j));
        let weights = self
            .weights()
            .map(|w| Grid::from_fn(nu, nv, |i, j| *w.get(i, nv - 1 - j)));
        NurbsSurface::with_dimension(
            self.degree_u(),
            self.degree_v(),
            self.knots_u().to_vec(),
            reverse_knots(self.knots_v(), c, d),
            points,
            weights,
            self.dimension(),
        )
    }

    /// The same surface with its parameters exchanged: `S'(u, v) = S(v, u)` (degrees, knot
    /// vectors, and the net and weights transposed; nothing is computed, so it is exact).
    pub fn swap_uv(&self) -> Result<NurbsSurface, GeometryError> {
        NurbsSurface::with_dimension(
            self.degree_v(),
            self.degree_u(),
            self.knots_v().to_vec(),
            self.knots_u().to_vec(),
            self.control_points().transposed(),
            self.weights().map(Grid::transposed),
            self.dimension(),
        )
    }

    /// Maps the u domain affinely onto `[c, d]` (poles unchanged).
    pub fn reparameterize_u(&self, c: f64, d: f64) -> Result<NurbsSurface, GeometryError> {
        check_interval(c, d)?;
        let (du, _) = self.domain();
        NurbsSurface::with_dimension(
            self.degree_u(),
            self.degree_v(),
            map_knots(self.knots_u(), du, (c, d)),
            self.knots_v().to_vec(),
            self.control_points().clone(),
            self.weights().cloned(),
            self.dimension(),
        )
    }

    /// Maps the v domain affinely onto `[c, d]` (poles unchanged).
    pub fn reparameterize_v(&self, c: f64, d: f64) -> Result<NurbsSurface, GeometryError> {
        check_interval(c, d)?;
        let (_, dv) = self.domain();
        NurbsSurface::with_dimension(
            self.degree_u(),
            self.degree_v(),
            self.knots_u().to_vec(),
            map_knots(self.knots_v(), dv, (c, d)),
            self.control_points().clone(),
            self.weights().cloned(),
            self.dimension(),
        )
    }

    /// The isoparametric curve `v -> S(u, v)` at fixed `u` (exact: the homogeneous net is
    /// contracted with the u basis functions, A3.5 / A4.3 first stage; degree `q`, knots
    /// `V`; rational iff the surface is).
    pub fn iso_u(&self, u: f64) -> Result<NurbsCurve, GeometryError> {
        let ((a, b), _) = self.domain();
        if !(u >= a && u <= b) {
            return Err(GeometryError::OutOfDomain {
                t: u,
                start: a,
                end: b,
            });
        }
        iso_curve(self, true, u)
    }

    /// The isoparametric curve `u -> S(u, v)` at fixed `v` (exact, as [`iso_u`]).
    ///
    /// [`iso_u`]: NurbsSurface::iso_u
    pub fn iso_v(&self, v: f64) -> Result<NurbsCurve, GeometryError> {
        let (_, (c, d)) = self.domain();
        if !(v >= c && v <= d) {
            return Err(GeometryError::OutOfDomain {
                t: v,
                start: c,
                end: d,
            });
        }
        iso_curve(self, false, v)
    }
}
