//! Global curve interpolation through points (NURBS Book A9.1; seed 000 section 2-25,
//! eqs. 2-125 .. 2-129): parameters by the uniform, chord-length or centripetal method,
//! knots by averaging, and the linear system `A P = Q` solved by LU decomposition with
//! partial pivoting (a system that is singular to working precision is refused).

use super::basis::basis_funs;
use super::knots::find_span;
use super::{GeometryError, MAX_DEGREE, NurbsCurve, Point3, distance};

/// The most points one interpolation accepts (checked before the `n^2` system is built).
pub const MAX_FIT_POINTS: usize = 2000;

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

/// The parameters `t_0 = 0 < ... < t_n = 1` of the points (eqs. 2-125 .. 2-127). Error if
/// two consecutive points coincide (chord-length, centripetal) or fewer than 2 points.
pub fn parameters(points: &[Point3], method: ParamMethod) -> Result<Vec<f64>, GeometryError> {
    let n = points.len();
    if n < 2 {
        return Err(GeometryError::InvalidArgument(
            "interpolation needs at least 2 points".into(),
        ));
    }
    let steps: Vec<f64> = match method {
        ParamMethod::Uniform => vec![1.0; n - 1],
        ParamMethod::ChordLength | ParamMethod::Centripetal => points
            .windows(2)
            .map(|w| {
                let d = distance(w[0], w[1]);
                if method == ParamMethod::Centripetal {
                    d.sqrt()
                } else {
                    d
                }
            })
            .collect(),
    };
    if let Some(k) = steps.iter().position(|&s| !(s.is_finite() && s > 0.0)) {
        return Err(GeometryError::InvalidArgument(format!(
            "points {k} and {} coincide (or are not finite): no parameters",
            k + 1
        )));
    }
    let total: f64 = steps.iter().sum();
    let mut t = Vec::with_capacity(n);
    let mut acc = 0.0;
    t.push(0.0);
    for s in &steps[..n - 2] {
        acc += s;
        t.push(acc / total);
    }
    t.push(1.0);
    Ok(t)
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

/// Solves `A X = B` (A square, row-major; B with 3 columns) by LU decomposition with partial
/// pivoting. Error if a pivot is zero or below `n * eps` times the largest entry of its
/// column (singular to working precision).
fn solve(mut a: Vec<f64>, mut b: Vec<Point3>) -> Result<Vec<Point3>, GeometryError> {
    let n = b.len();
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for k in 0..n {
        let (piv, big) = (k..n)
            .map(|r| (r, a[r * n + k].abs()))
            .fold((k, -1.0), |best, c| if c.1 > best.1 { c } else { best });
        // A NaN pivot is refused as well.
        if big.is_nan() || big <= n as f64 * f64::EPSILON * scale {
            return Err(GeometryError::InvalidArgument(format!(
                "the interpolation system is singular (pivot {big:e} in column {k}): choose \
                 other parameters or points"
            )));
        }
        if piv != k {
            for c in 0..n {
                a.swap(k * n + c, piv * n + c);
            }
            b.swap(k, piv);
        }
        for r in k + 1..n {
            let f = a[r * n + k] / a[k * n + k];
            if f == 0.0 {
                continue;
            }
            for c in k..n {
                a[r * n + c] -= f * a[k * n + c];
            }
            let bk = b[k];
            for (x, y) in b[r].iter_mut().zip(bk) {
                *x -= f * y;
            }
        }
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
    Ok(b)
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
) -> Result<NurbsCurve, GeometryError> {
    check_fit(points.len(), p)?;
    let t = parameters(points, method)?;
    interpolate_at(points, &t, p, dimension)
}

fn check_fit(count: usize, p: usize) -> Result<(), GeometryError> {
    if count > MAX_FIT_POINTS {
        return Err(GeometryError::InvalidArgument(format!(
            "{count} points, above the interpolation limit of {MAX_FIT_POINTS}"
        )));
    }
    if p == 0 || p > MAX_DEGREE || count < p + 1 {
        return Err(GeometryError::InvalidArgument(format!(
            "degree {p} needs 1 <= p <= {MAX_DEGREE} and at least p + 1 points, got {count}"
        )));
    }
    Ok(())
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
    let knots = averaged_knots(t, p);
    let n = points.len();
    let mut a = vec![0.0; n * n];
    let mut row = vec![0.0; p + 1];
    for (k, &tk) in t.iter().enumerate() {
        let span = find_span(p, n, &knots, tk);
        basis_funs(span, tk, p, &knots, &mut row);
        for (j, &v) in row.iter().enumerate() {
            a[k * n + span - p + j] = v;
        }
    }
    let poles = solve(a, points.to_vec())?;
    NurbsCurve::with_dimension(p, knots, poles, None, dimension)
}
