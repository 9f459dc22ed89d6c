//! Fitting curves and surfaces to points (NURBS Book chapter 9; seed 000 section 2-25):
//!
//! - [`interpolate`]: global curve interpolation (A9.1; eqs. 2-125 .. 2-129): parameters by
//!   the uniform, chord-length or centripetal method, knots by averaging, the linear system
//!   `A P = Q` solved by LU decomposition with partial pivoting (a system that is singular
//!   to working precision is refused).
//! - [`approximate`]: least-squares curve approximation with a given number of poles
//!   (NURBS Book section 9.4.1, eqs. 9.63 .. 9.69; seed 000 eqs. 2-135 .. 2-144): the end
//!   points are interpolated, the other poles minimise the sum of squared distances of the
//!   data points from the curve at their parameters, knots by eqs. 9.68 / 9.69.
//! - [`fit_surface`]: surface interpolation (A9.4) and least-squares approximation (A9.7)
//!   over a grid of points, with the parameters of A9.3 (the lines' parameters averaged).
//!
//! Every fit reports its [`Residual`]: the distances of the data points from the result at
//! their parameters, measured after the fit.

use super::basis::basis_funs;
use super::knots::find_span;
use super::{GeometryError, Grid, MAX_DEGREE, NurbsCurve, NurbsSurface, Point3, distance};

/// The most points one fit accepts along one direction (checked before the `n^2` system
/// is built).
pub const MAX_FIT_POINTS: usize = 2000;

/// The most points of a grid a surface fit accepts.
pub const MAX_FIT_GRID_POINTS: usize = 250_000;

/// How the data points get their parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ParamMethod {
    /// Equally spaced (eq. 2-125).
    Uniform,
    /// Proportional to the chord lengths (eq. 2-126).
    #[default]
    ChordLength,
    /// Proportional to the square roots of the chord lengths (eq. 2-127).
    Centripetal,
}

/// The distances of the data points from a fitted curve or surface at their parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Residual {
    /// The largest distance.
    pub max: f64,
    /// The root mean square of the distances (over every data point, the interpolated
    /// ends included).
    pub rms: f64,
}

impl Residual {
    fn of(distances: impl Iterator<Item = f64>) -> Self {
        let (mut max, mut sum, mut count) = (0.0f64, 0.0, 0usize);
        for d in distances {
            max = max.max(d);
            sum += d * d;
            count += 1;
        }
        let rms = if count == 0 {
            0.0
        } else {
            (sum / count as f64).sqrt()
        };
        Residual { max, rms }
    }

    fn of_curve(curve: &NurbsCurve, points: &[Point3], t: &[f64]) -> Self {
        Residual::of(
            points
                .iter()
                .zip(t)
                .map(|(q, &u)| distance(curve.point_at_unchecked(u), *q)),
        )
    }
}

/// A fitted curve and how far the data points are from it.
#[derive(Debug, Clone)]
pub struct CurveFit {
    /// The curve.
    pub curve: NurbsCurve,
    /// The parameters of the data points.
    pub parameters: Vec<f64>,
    /// The data points' distances from the curve at their parameters.
    pub residual: Residual,
}

/// A fitted surface and how far the data points are from it.
#[derive(Debug, Clone)]
pub struct SurfaceFit {
    /// The surface.
    pub surface: NurbsSurface,
    /// The parameters of the grid's rows (u) and columns (v).
    pub parameters: (Vec<f64>, Vec<f64>),
    /// The data points' distances from the surface at their parameters.
    pub residual: Residual,
}

/// The parameter steps between consecutive points (eqs. 2-125 .. 2-127, before
/// normalisation): 1, the chord length, or its square root.
fn steps(points: &[Point3], method: ParamMethod) -> Vec<f64> {
    points
        .windows(2)
        .map(|w| match method {
            ParamMethod::Uniform => 1.0,
            ParamMethod::ChordLength => distance(w[0], w[1]),
            ParamMethod::Centripetal => distance(w[0], w[1]).sqrt(),
        })
        .collect()
}

/// `0, s_0, s_0 + s_1, ...` divided by the total, the last exactly 1.
fn normalised(steps: &[f64]) -> Vec<f64> {
    let total: f64 = steps.iter().sum();
    let mut t = Vec::with_capacity(steps.len() + 1);
    let mut acc = 0.0;
    t.push(0.0);
    for s in &steps[..steps.len() - 1] {
        acc += s;
        t.push(acc / total);
    }
    t.push(1.0);
    t
}

/// The parameters `t_0 = 0 < ... < t_n = 1` of the points (eqs. 2-125 .. 2-127). Error if
/// two consecutive points coincide (chord-length, centripetal) or fewer than 2 points.
pub fn parameters(points: &[Point3], method: ParamMethod) -> Result<Vec<f64>, GeometryError> {
    if points.len() < 2 {
        return Err(GeometryError::InvalidArgument(
            "a fit needs at least 2 points".into(),
        ));
    }
    let steps = steps(points, method);
    if let Some(k) = steps.iter().position(|&s| !(s.is_finite() && s > 0.0)) {
        return Err(GeometryError::InvalidArgument(format!(
            "points {k} and {} coincide (or are not finite): no parameters",
            k + 1
        )));
    }
    Ok(normalised(&steps))
}

/// The parameters of a grid's rows (`u`, one per index `i`) and columns (`v`, one per
/// index `j`) by A9.3: each line of points along a direction gets its parameters
/// (eqs. 2-125 .. 2-127) and the lines' parameters are averaged; a line whose points all
/// coincide (a degenerate edge, such as a sphere's pole) is left out of the average.
///
/// Errors: fewer than 2 points in a direction, every line degenerate, or averaged
/// parameters that are not strictly increasing (points that coincide across the grid).
pub fn grid_parameters(
    grid: &Grid<Point3>,
    method: ParamMethod,
) -> Result<(Vec<f64>, Vec<f64>), GeometryError> {
    let along = |count: usize, lines: usize, line: &dyn Fn(usize) -> Vec<Point3>, name: &str| {
        if count < 2 {
            return Err(GeometryError::InvalidArgument(format!(
                "a surface fit needs at least 2 points along {name}"
            )));
        }
        let mut sum = vec![0.0; count];
        let mut used = 0usize;
        for l in 0..lines {
            let s = steps(&line(l), method);
            let total: f64 = s.iter().sum();
            if !total.is_finite() {
                return Err(GeometryError::InvalidArgument(
                    "a grid point is not finite".into(),
                ));
            }
            if total == 0.0 {
                continue;
            }
            used += 1;
            for (acc, t) in sum.iter_mut().zip(normalised(&s)) {
                *acc += t;
            }
        }
        if used == 0 {
            return Err(GeometryError::InvalidArgument(format!(
                "every line of the grid along {name} is one point: no parameters"
            )));
        }
        let mut t: Vec<f64> = sum.iter().map(|s| s / used as f64).collect();
        t[0] = 0.0;
        t[count - 1] = 1.0;
        if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(GeometryError::InvalidArgument(format!(
                "the grid's points {k} and {} along {name} coincide on every line: no \
                 parameters",
                k + 1
            )));
        }
        Ok(t)
    };
    let (nu, nv) = (grid.nu(), grid.nv());
    let u = along(nu, nv, &|j| (0..nu).map(|i| *grid.get(i, j)).collect(), "u")?;
    let v = along(nv, nu, &|i| grid.row(i).to_vec(), "v")?;
    Ok((u, v))
}

/// The knot vector by averaging (eq. 2-129): `p + 1` copies of `t_0` and of `t_n` (0 and 1
/// for the normalised parameters of [`parameters`]), and
/// `u_{j+p} = (t_j + ... + t_{j+p-1}) / p` for `j = 1 .. n - p`.
pub fn averaged_knots(t: &[f64], p: usize) -> Vec<f64> {
    let n = t.len() - 1;
    let mut u = vec![t[0]; p + 1];
    for j in 1..=n - p {
        u.push(t[j..j + p].iter().sum::<f64>() / p as f64);
    }
    u.extend(std::iter::repeat_n(t[n], p + 1));
    u
}

/// The knot vector of a least-squares fit with `poles` poles to points at the parameters
/// `t` (NURBS Book eqs. 9.68 / 9.69; seed 000 eqs. 2-142 .. 2-144): with `m + 1` points and
/// `n + 1` poles, `d = (m + 1) / (n - p + 1)`, and for `j = 1 .. n - p`, `i = int(j d)`,
/// `alpha = j d - i`, `u_{p+j} = (1 - alpha) t_{i-1} + alpha t_i`; every knot span then
/// holds at least one parameter. Needs `p + 1 <= poles <= t.len()` (checked by the
/// callers, [`check_poles`]).
fn approximation_knots(t: &[f64], p: usize, poles: usize) -> Vec<f64> {
    let (m1, n) = (t.len(), poles - 1);
    let d = m1 as f64 / (n - p + 1) as f64;
    let mut u = vec![t[0]; p + 1];
    for j in 1..=n - p {
        let jd = j as f64 * d;
        // jd < m + 1, so i <= m; i >= 1 since d >= 1.
        let i = (jd.floor() as usize).clamp(1, m1 - 1);
        let alpha = jd - i as f64;
        u.push((1.0 - alpha) * t[i - 1] + alpha * t[i]);
    }
    u.extend(std::iter::repeat_n(t[m1 - 1], p + 1));
    u
}

/// An LU decomposition with partial pivoting of a square matrix, solved for many right
/// sides (one factorisation per fit direction).
struct Lu {
    n: usize,
    a: Vec<f64>,
    /// Row `k` was swapped with row `swaps[k]` at step `k`.
    swaps: Vec<usize>,
}

impl Lu {
    /// Factors `a` (row-major, `n x n`). Error if a pivot is zero or below `n * eps` times
    /// the largest entry (singular to working precision).
    fn factor(mut a: Vec<f64>, n: usize) -> Result<Lu, GeometryError> {
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut swaps = Vec::with_capacity(n);
        for k in 0..n {
            let (piv, big) = (k..n)
                .map(|r| (r, a[r * n + k].abs()))
                .fold((k, -1.0), |best, c| if c.1 > best.1 { c } else { best });
            // A NaN pivot is refused as well.
            if big.is_nan() || big <= n as f64 * f64::EPSILON * scale {
                return Err(GeometryError::InvalidArgument(format!(
                    "the fitting system is singular (pivot {big:e} in column {k}): choose \
                     other parameters, points or pole counts"
                )));
            }
            if piv != k {
                for c in 0..n {
                    a.swap(k * n + c, piv * n + c);
                }
            }
            swaps.push(piv);
            for r in k + 1..n {
                let f = a[r * n + k] / a[k * n + k];
                a[r * n + k] = f;
                if f == 0.0 {
                    continue;
                }
                for c in k + 1..n {
                    a[r * n + c] -= f * a[k * n + c];
                }
            }
        }
        Ok(Lu { n, a, swaps })
    }

    /// Solves `A X = B` for `B` with 3 columns, in place.
    fn solve(&self, b: &mut [Point3]) {
        let (n, a) = (self.n, &self.a);
        for (k, &piv) in self.swaps.iter().enumerate() {
            b.swap(k, piv);
        }
        for r in 0..n {
            let mut x = b[r];
            for c in 0..r {
                for d in 0..3 {
                    x[d] -= a[r * n + c] * b[c][d];
                }
            }
            b[r] = x;
        }
        for k in (0..n).rev() {
            let mut x = b[k];
            for c in k + 1..n {
                for d in 0..3 {
                    x[d] -= a[k * n + c] * b[c][d];
                }
            }
            b[k] = x.map(|v| v / a[k * n + k]);
        }
    }
}

fn check_fit(count: usize, p: usize) -> Result<(), GeometryError> {
    if count > MAX_FIT_POINTS {
        return Err(GeometryError::InvalidArgument(format!(
            "{count} points, above the fitting limit of {MAX_FIT_POINTS}"
        )));
    }
    if p == 0 || p > MAX_DEGREE || count < p + 1 {
        return Err(GeometryError::InvalidArgument(format!(
            "degree {p} needs 1 <= p <= {MAX_DEGREE} and at least p + 1 points, got {count}"
        )));
    }
    Ok(())
}

/// Checks a pole count of a least-squares fit to `count` points of degree `p`.
fn check_poles(count: usize, p: usize, poles: usize) -> Result<(), GeometryError> {
    check_fit(count, p)?;
    if poles < p + 1 || poles >= count {
        return Err(GeometryError::InvalidArgument(format!(
            "a least-squares fit of degree {p} to {count} points needs p + 1 <= poles < \
             points, got {poles} poles (interpolate for as many poles as points)"
        )));
    }
    Ok(())
}

/// The interpolation solver of one direction (A9.1): the knots averaged over `t`, the
/// matrix `N_{j,p}(t_k)` factored.
struct Interpolation {
    knots: Vec<f64>,
    lu: Lu,
}

impl Interpolation {
    fn new(t: &[f64], p: usize) -> Result<Self, GeometryError> {
        let knots = averaged_knots(t, p);
        let n = t.len();
        let mut a = vec![0.0; n * n];
        let mut row = vec![0.0; p + 1];
        for (k, &tk) in t.iter().enumerate() {
            let span = find_span(p, n, &knots, tk);
            basis_funs(span, tk, p, &knots, &mut row);
            for (j, &v) in row.iter().enumerate() {
                a[k * n + span - p + j] = v;
            }
        }
        Ok(Interpolation {
            knots,
            lu: Lu::factor(a, n)?,
        })
    }

    fn poles(&self, points: &[Point3]) -> Vec<Point3> {
        let mut b = points.to_vec();
        self.lu.solve(&mut b);
        b
    }
}

/// The least-squares solver of one direction (NURBS Book eqs. 9.63 .. 9.67; seed 000 eqs.
/// 2-135 .. 2-141): the knots of eqs. 9.68 / 9.69, the basis values at the interior
/// parameters, and `N^T N` factored.
struct LeastSquares {
    poles: usize,
    knots: Vec<f64>,
    /// For each interior parameter `t_k` (`k = 1 .. m - 1`): the first pole index its
    /// `p + 1` non-zero basis functions belong to, and their values.
    rows: Vec<(usize, Vec<f64>)>,
    /// `N^T N` over the interior poles `1 .. n - 1` (`None` with 2 poles: no unknowns).
    lu: Option<Lu>,
}

impl LeastSquares {
    fn new(t: &[f64], p: usize, poles: usize) -> Result<Self, GeometryError> {
        let knots = approximation_knots(t, p, poles);
        let m = t.len() - 1;
        let unknowns = poles - 2;
        let mut ntn = vec![0.0; unknowns * unknowns];
        let mut rows = Vec::with_capacity(m.saturating_sub(1));
        for &tk in &t[1..m] {
            let span = find_span(p, poles, &knots, tk);
            let mut values = vec![0.0; p + 1];
            basis_funs(span, tk, p, &knots, &mut values);
            let first = span - p;
            // Eq. 9.66: (N^T N)_{a,b} = sum_k N_a(t_k) N_b(t_k), a, b in 1 .. n - 1.
            for (ia, &na) in values.iter().enumerate() {
                let a = first + ia;
                if a == 0 || a == poles - 1 {
                    continue;
                }
                for (ib, &nb) in values.iter().enumerate() {
                    let b = first + ib;
                    if b == 0 || b == poles - 1 {
                        continue;
                    }
                    ntn[(a - 1) * unknowns + b - 1] += na * nb;
                }
            }
            rows.push((first, values));
        }
        let lu = if unknowns == 0 {
            None
        } else {
            Some(Lu::factor(ntn, unknowns)?)
        };
        Ok(LeastSquares {
            poles,
            knots,
            rows,
            lu,
        })
    }

    /// The poles fitting `q` (one point per parameter): the ends are `q`'s ends.
    fn poles(&self, q: &[Point3]) -> Vec<Point3> {
        let (n, m) = (self.poles - 1, q.len() - 1);
        let mut out = vec![[0.0; 3]; self.poles];
        out[0] = q[0];
        out[n] = q[m];
        let Some(lu) = &self.lu else {
            return out;
        };
        let mut r = vec![[0.0; 3]; n - 1];
        for ((first, values), qk) in self.rows.iter().zip(&q[1..m]) {
            // Eq. 9.63: R_k = Q_k - N_0(t_k) Q_0 - N_n(t_k) Q_m.
            let basis = |i: usize| {
                i.checked_sub(*first)
                    .and_then(|j| values.get(j))
                    .copied()
                    .unwrap_or(0.0)
            };
            let (n0, nn) = (basis(0), basis(n));
            let rk: Point3 = std::array::from_fn(|d| qk[d] - n0 * q[0][d] - nn * q[m][d]);
            // Eq. 9.67: R_i = sum_k N_i(t_k) R_k.
            for (j, &v) in values.iter().enumerate() {
                let i = first + j;
                if i == 0 || i == n {
                    continue;
                }
                for d in 0..3 {
                    r[i - 1][d] += v * rk[d];
                }
            }
        }
        lu.solve(&mut r);
        out[1..n].copy_from_slice(&r);
        out
    }
}

/// The polynomial curve of degree `p` through every point, at the parameters of `method`
/// with averaged knots (A9.1). `dimension` 2 or 3 (2: every z is 0).
///
/// Errors: fewer than `p + 1` points, more than [`MAX_FIT_POINTS`], degree 0 or above
/// [`MAX_DEGREE`], coincident consecutive points, a singular system.
pub fn interpolate(
    points: &[Point3],
    p: usize,
    method: ParamMethod,
    dimension: usize,
) -> Result<CurveFit, GeometryError> {
    check_fit(points.len(), p)?;
    let t = parameters(points, method)?;
    let curve = interpolate_at(points, &t, p, dimension)?;
    let residual = Residual::of_curve(&curve, points, &t);
    Ok(CurveFit {
        curve,
        parameters: t,
        residual,
    })
}

/// The polynomial curve of degree `p` with `C(t[k]) = points[k]` for the given strictly
/// increasing parameters (A9.1 with the parameters chosen by the caller, e.g. those of
/// another curve a fitted curve must share), knots averaged over `[t_0, t_n]` (eq. 2-129).
///
/// Errors: as [`interpolate`], and parameters that are not finite and strictly increasing
/// or not one per point.
pub fn interpolate_at(
    points: &[Point3],
    t: &[f64],
    p: usize,
    dimension: usize,
) -> Result<NurbsCurve, GeometryError> {
    check_fit(points.len(), p)?;
    if t.len() != points.len()
        || t.iter().any(|x| !x.is_finite())
        || t.windows(2).any(|w| w[1] <= w[0])
    {
        return Err(GeometryError::InvalidArgument(
            "interpolation parameters must be finite, strictly increasing and one per point".into(),
        ));
    }
    let fit = Interpolation::new(t, p)?;
    let poles = fit.poles(points);
    NurbsCurve::with_dimension(p, fit.knots, poles, None, dimension)
}

/// The polynomial curve of degree `p` with `poles` poles closest to the points in the
/// least-squares sense (NURBS Book section 9.4.1; seed 000 eqs. 2-135 .. 2-144): the
/// parameters of `method`, the knots of eqs. 9.68 / 9.69, the first and last point
/// interpolated, the other poles from the normal equations `(N^T N) P = R`.
///
/// Errors: as [`interpolate`], and a pole count outside `p + 1 <= poles < points`.
pub fn approximate(
    points: &[Point3],
    p: usize,
    poles: usize,
    method: ParamMethod,
    dimension: usize,
) -> Result<CurveFit, GeometryError> {
    check_poles(points.len(), p, poles)?;
    let t = parameters(points, method)?;
    let fit = LeastSquares::new(&t, p, poles)?;
    let net = fit.poles(points);
    let curve = NurbsCurve::with_dimension(p, fit.knots, net, None, dimension)?;
    let residual = Residual::of_curve(&curve, points, &t);
    Ok(CurveFit {
        curve,
        parameters: t,
        residual,
    })
}

/// The degrees and, for an approximation, the pole counts of a surface fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SurfaceFitShape {
    /// Degree along u (the grid's rows, index `i`).
    pub degree_u: usize,
    /// Degree along v (the grid's columns, index `j`).
    pub degree_v: usize,
    /// Pole counts `(u, v)` of a least-squares fit; `None` interpolates.
    pub poles: Option<(usize, usize)>,
}

/// A surface fitted to a grid of points `Q_{i,j}` (`i` along u, `j` along v): with
/// `shape.poles` `None`, the interpolating surface (A9.4: curves through the grid's
/// columns, then through the rows of their poles, averaged knots); else the least-squares
/// surface with that many poles (A9.7: least-squares curves in u, then in v, the four
/// corners interpolated). Parameters by A9.3 ([`grid_parameters`]).
///
/// Errors: more than [`MAX_FIT_GRID_POINTS`] points or [`MAX_FIT_POINTS`] along a
/// direction, degrees or pole counts as for curves, parameters that cannot be formed, a
/// singular system.
pub fn fit_surface(
    grid: &Grid<Point3>,
    shape: SurfaceFitShape,
    method: ParamMethod,
    dimension: usize,
) -> Result<SurfaceFit, GeometryError> {
    let (nu, nv) = (grid.nu(), grid.nv());
    if nu.saturating_mul(nv) > MAX_FIT_GRID_POINTS {
        return Err(GeometryError::InvalidArgument(format!(
            "a grid of {nu} x {nv} points, above the surface fitting limit of \
             {MAX_FIT_GRID_POINTS}"
        )));
    }
    let SurfaceFitShape {
        degree_u: p,
        degree_v: q,
        poles,
    } = shape;
    match poles {
        None => {
            check_fit(nu, p)?;
            check_fit(nv, q)?;
        }
        Some((n_u, n_v)) => {
            check_poles(nu, p, n_u)?;
            check_poles(nv, q, n_v)?;
        }
    }
    let (tu, tv) = grid_parameters(grid, method)?;
    // One solver per direction: `fit(points)` gives the poles of one line.
    type Solve = Box<dyn Fn(&[Point3]) -> Vec<Point3>>;
    let solver =
        |t: &[f64], p: usize, poles: Option<usize>| -> Result<(Vec<f64>, Solve), GeometryError> {
            Ok(match poles {
                None => {
                    let s = Interpolation::new(t, p)?;
                    (s.knots.clone(), Box::new(move |q: &[Point3]| s.poles(q)))
                }
                Some(n) => {
                    let s = LeastSquares::new(t, p, n)?;
                    (s.knots.clone(), Box::new(move |q: &[Point3]| s.poles(q)))
                }
            })
        };
    let (knots_u, fit_u) = solver(&tu, p, poles.map(|x| x.0))?;
    let (knots_v, fit_v) = solver(&tv, q, poles.map(|x| x.1))?;
    // Along u, through each column j: R_{.,j}.
    let columns: Vec<Vec<Point3>> = (0..nv)
        .map(|j| fit_u(&(0..nu).map(|i| *grid.get(i, j)).collect::<Vec<_>>()))
        .collect();
    let rows_u = columns.first().map_or(0, Vec::len);
    // Along v, through each row i of R: P_{i,.}.
    let mut net = Vec::with_capacity(rows_u * knots_v.len());
    for i in 0..rows_u {
        let line: Vec<Point3> = columns.iter().map(|c| c[i]).collect();
        net.extend(fit_v(&line));
    }
    let cols_v = net.len() / rows_u.max(1);
    let net = Grid::from_u_major(rows_u, cols_v, net).ok_or_else(|| {
        GeometryError::InvalidArgument("the fitted net is not rectangular".into())
    })?;
    let surface = NurbsSurface::with_dimension(p, q, knots_u, knots_v, net, None, dimension)?;
    let residual = Residual::of((0..nu).flat_map(|i| {
        let (surface, tu, tv) = (&surface, &tu, &tv);
        (0..nv).map(move |j| distance(surface.point_at_unchecked(tu[i], tv[j]), *grid.get(i, j)))
    }));
    Ok(SurfaceFit {
        surface,
        parameters: (tu, tv),
        residual,
    })
}
