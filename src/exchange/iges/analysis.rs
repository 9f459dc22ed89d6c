//! What the data says about the IGES PROP flags: clamped ends, periodic layout, closure and
//! planarity. The reader compares the flags with these, the writer computes the flags from
//! them (pitfalls.md A2, A4, B11).

use crate::nurbs::vector::{cross, dist, dot, norm, sub};
use crate::nurbs::{NurbsCurve, NurbsSurface, Point3};

/// Relative tolerance for "equal" coordinates and knots: a few ulps of double precision
/// at the size of the model, far below any modelling resolution.
const REL_TOL: f64 = 1e-10;

/// Relative tolerance for knot intervals and weights in the periodic test: files written by
/// Open CASCADE carry 9-10 significant digits, so a period of 2 pi repeats only to ~1e-9.
const KNOT_TOL: f64 = 1e-8;

/// A distance tolerance scaled to the size of a point set (its largest coordinate).
pub fn tolerance<'a>(points: impl Iterator<Item = &'a Point3>) -> f64 {
    tolerance_of(points.flat_map(|p| p.iter().copied()))
}

/// [`tolerance`] of coordinates given one by one.
pub fn tolerance_of(values: impl Iterator<Item = f64>) -> f64 {
    let m = values.fold(0.0f64, |m, x| m.max(x.abs()));
    REL_TOL * m.max(1.0)
}

/// Whether both ends of a knot vector repeat `degree + 1` times (the usual clamped form).
pub use crate::nurbs::knots::clamped;

/// Whether the knots and poles are a periodic B-spline written out flat (the form Open
/// CASCADE's `SetNotPeriodic` produces, and the uniform textbook form): with period
/// `T = u_{n+1} - u_p` (the domain length) there is a shift `s` with `n + 1 - p <= s <= n`
/// such that the whole knot sequence repeats, `u_{i+s} - u_i = T` for every `i`, and the
/// `w = n + 1 - s` wrapped poles (and weights) repeat the first ones, `P_{i+s} = P_i`.
/// A clamped knot vector never qualifies (its end knots cannot repeat shifted by `T`).
pub fn periodic_layout(
    knots: &[f64],
    degree: usize,
    poles: usize,
    point: &dyn Fn(usize) -> Point3,
    weight: &dyn Fn(usize) -> f64,
    tol: f64,
) -> bool {
    if poles <= degree || knots.len() != poles + degree + 1 {
        return false;
    }
    let period = knots[poles] - knots[degree];
    let ktol = KNOT_TOL * period.abs().max(1.0);
    (poles - degree..poles).any(|s| {
        (0..knots.len() - s).all(|i| ((knots[i + s] - knots[i]) - period).abs() <= ktol)
            && (0..poles - s).all(|i| {
                dist(point(i), point(s + i)) <= tol
                    && (weight(i) - weight(s + i)).abs() <= KNOT_TOL * weight(i).abs()
            })
    })
}

/// Whether a curve's two ends meet (evaluated at its domain ends).
pub fn curve_closed(c: &NurbsCurve, tol: f64) -> bool {
    let (a, b) = c.domain();
    dist(c.point_at_unchecked(a), c.point_at_unchecked(b)) <= tol
}

/// Whether a curve has the periodic layout.
pub fn curve_periodic(c: &NurbsCurve, tol: f64) -> bool {
    let pts = c.control_points();
    periodic_layout(
        c.knots(),
        c.degree(),
        c.num_poles(),
        &|i| pts[i],
        &|i| c.weight(i),
        tol,
    )
}

/// Sample parameters spread over `[a, b]` (ends included).
fn samples(a: f64, b: f64, n: usize) -> impl Iterator<Item = f64> {
    (0..=n).map(move |k| a + (b - a) * (k as f64 / n as f64))
}

/// Whether the surface closes in u (`dir = 0`) or v (`dir = 1`): the boundary curves at
/// both ends of that direction coincide at sample points.
pub fn surface_closed(s: &NurbsSurface, dir: usize, tol: f64) -> bool {
    let ((u0, u1), (v0, v1)) = s.domain();
    let n = 4 * (s.control_points().nu() + s.control_points().nv()).min(64);
    if dir == 0 {
        samples(v0, v1, n)
            .all(|v| dist(s.point_at_unchecked(u0, v), s.point_at_unchecked(u1, v)) <= tol)
    } else {
        samples(u0, u1, n)
            .all(|u| dist(s.point_at_unchecked(u, v0), s.point_at_unchecked(u, v1)) <= tol)
    }
}

/// Whether every row (dir 0: along u for each v index; dir 1: along v) has the periodic
/// layout.
pub fn surface_periodic(s: &NurbsSurface, dir: usize, tol: f64) -> bool {
    let net = s.control_points();
    let (nu, nv) = (net.nu(), net.nv());
    if dir == 0 {
        (0..nv).all(|j| {
            periodic_layout(
                s.knots_u(),
                s.degree_u(),
                nu,
                &|i| *net.get(i, j),
                &|i| s.weight(i, j),
                tol,
            )
        })
    } else {
        (0..nu).all(|i| {
            periodic_layout(
                s.knots_v(),
                s.degree_v(),
                nv,
                &|j| *net.get(i, j),
                &|j| s.weight(i, j),
                tol,
            )
        })
    }
}

/// The unit normal of the plane holding all `points`, if they span one: `None` when they
/// are collinear (no unique plane) or not coplanar within `tol`. The sign is chosen with
/// `z >= 0` (then `y`, then `x`), as Open CASCADE writes it.
pub fn plane_normal(points: &[Point3], tol: f64) -> Option<Point3> {
    let p0 = *points.first()?;
    let far = points
        .iter()
        .copied()
        .max_by(|a, b| norm(sub(*a, p0)).total_cmp(&norm(sub(*b, p0))))?;
    let d = sub(far, p0);
    if norm(d) <= tol {
        return None;
    }
    let best = points
        .iter()
        .map(|&q| cross(d, sub(q, p0)))
        .max_by(|a, b| norm(*a).total_cmp(&norm(*b)))?;
    let len = norm(best);
    // Collinear (within tolerance): the plane is not determined.
    if len <= tol * norm(d) {
        return None;
    }
    let mut n = [best[0] / len, best[1] / len, best[2] / len];
    let flip = if n[2] != 0.0 {
        n[2] < 0.0
    } else if n[1] != 0.0 {
        n[1] < 0.0
    } else {
        n[0] < 0.0
    };
    if flip {
        n = [-n[0], -n[1], -n[2]];
    }
    on_plane(points, n, tol).then_some(n)
}

/// The significant digits and the decimal exponent of the shortest decimal that reads back
/// as `x` (`0.70710678` has 8 digits, exponent -1); `None` for 0 and non-finite values.
fn decimal_digits(x: f64) -> Option<(i32, i32)> {
    if x == 0.0 || !x.is_finite() {
        return None;
    }
    // `{:e}` is the shortest round-trip form: `d.ddddde-X`, at most 24 bytes for an f64
    // (`2.2250738585072014e-308`), written into the stack (no allocation per value).
    let mut text = StackText::default();
    std::fmt::Write::write_fmt(&mut text, format_args!("{:e}", x.abs())).ok()?;
    let text = std::str::from_utf8(text.bytes.get(..text.len)?).ok()?;
    let (mantissa, exponent) = text.split_once('e')?;
    let digits = mantissa.bytes().filter(u8::is_ascii_digit).count();
    Some((i32::try_from(digits).ok()?, exponent.parse().ok()?))
}

/// A short text written in place ([`decimal_digits`]); writing past its 32 bytes fails.
#[derive(Default)]
struct StackText {
    bytes: [u8; 32],
    len: usize,
}

impl std::fmt::Write for StackText {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len.checked_add(s.len()).ok_or(std::fmt::Error)?;
        self.bytes
            .get_mut(self.len..end)
            .ok_or(std::fmt::Error)?
            .copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// Half a unit in the last decimal place the writer used for `values`: the most significant
/// digits among them are taken as the writer's precision (a value shown with fewer had
/// trailing zeros), and the largest value's last place at that precision is the rounding any
/// of them may carry (`0.479, 10.019, 8.508`: 5 digits, 0.5e-3). 0 when no value is
/// finite and non-zero. One pass: the largest last place is that of the largest exponent.
pub fn written_rounding(values: impl IntoIterator<Item = f64>) -> f64 {
    digits_and_exponent(values).map_or(0.0, |(digits, exponent)| {
        0.5 * 10f64.powi(exponent - digits + 1)
    })
}

/// The fewest significant digits a writer is taken to have used for the numbers of a
/// B-spline's net: single precision. A net written with fewer (`0.5`, `10.`) is taken as
/// exact to that many, so that short numbers never widen a check beyond it.
const LEAST_WRITTEN_DIGITS: i32 = 6;

/// The most significant digits and the largest decimal exponent among `values`.
fn digits_and_exponent(values: impl IntoIterator<Item = f64>) -> Option<(i32, i32)> {
    values
        .into_iter()
        .filter_map(decimal_digits)
        .reduce(|(md, me), (d, e)| (md.max(d), me.max(e)))
}

/// How far a point of a B-spline may lie from the one its writer meant when its poles and
/// weights carry only the digits written. The writer's precision is the most significant
/// digits among all of them (at least [`LEAST_WRITTEN_DIGITS`]; a circle's irrational
/// weight shows it), so each coordinate is within `e`, half a unit in that last place of
/// the largest coordinate, and each weight within `dw` likewise. Each pole is then within
/// `sqrt 3 e` and, a point being a convex combination of the poles (NURBS Book eq. 4.2,
/// positive weights), the point too; a weight moves a point by at most `dw / w_min` times
/// the polygon's diameter (the derivative of eq. 4.2 in `w_i` is
/// `N_i (P_i - C) / sum N_j w_j`); equal weights cancel and count for nothing. For
/// full-precision values (17 digits) this is a few units in the last place.
pub fn written_point_rounding(points: &[Point3], weights: &[f64]) -> f64 {
    let coordinates = digits_and_exponent(points.iter().flatten().copied());
    let ws = digits_and_exponent(weights.iter().copied());
    let digits = [coordinates, ws]
        .iter()
        .flatten()
        .map(|&(d, _)| d)
        .fold(LEAST_WRITTEN_DIGITS, i32::max);
    let rounding =
        |de: Option<(i32, i32)>| de.map_or(0.0, |(_, e)| 0.5 * 10f64.powi(e - digits + 1));
    let least = weights.iter().copied().fold(f64::INFINITY, f64::min);
    let most = weights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // Equal weights cancel in eq. 4.2 whatever their rounding.
    let weight = if least > 0.0 && least.is_finite() && most > least {
        rounding(ws) / least
    } else {
        0.0
    };
    let diameter = match points.first() {
        Some(&p0) => {
            2.0 * points
                .iter()
                .map(|&q| norm(sub(q, p0)))
                .fold(0.0f64, f64::max)
        }
        None => 0.0,
    };
    3f64.sqrt() * rounding(coordinates) + diameter * weight
}

/// How far from the plane through `points[0]` with normal `n` the points may lie when both
/// were written with the digits the writer used. The most significant digits among the
/// coordinates is taken as the writer's precision for them (a value shown with fewer had
/// trailing zeros); the normal's own digits give its rounding, unless it is a unit vector
/// as written (`0.,0.,1.`, `0.6,0.,0.8`: within 1e-12), which is taken as exact. The normal's rounding is turned over the
/// polygon's extent, plus two points' rounding, plus [`tolerance`].
pub fn plane_tolerance(points: &[Point3], n: Point3) -> f64 {
    let len = norm(n);
    let Some(&p0) = points.first() else {
        return 0.0;
    };
    if len.is_nan() || len <= 0.0 {
        return 0.0;
    }
    let normal = if (len - 1.0).abs() <= 1e-12 {
        0.0
    } else {
        written_rounding(n) / len
    };
    let coordinate = written_rounding(points.iter().flatten().copied());
    let extent = points
        .iter()
        .map(|&q| norm(sub(q, p0)))
        .fold(0.0f64, f64::max);
    let sqrt3 = 3f64.sqrt();
    tolerance(points.iter()) + extent * normal * sqrt3 + 2.0 * sqrt3 * coordinate
}

/// Whether all points lie within `tol` of the plane through the first point with unit
/// normal `n`.
pub fn on_plane(points: &[Point3], n: Point3, tol: f64) -> bool {
    let len = norm(n);
    if len.is_nan() || len <= 0.0 {
        return false;
    }
    let Some(&p0) = points.first() else {
        return true;
    };
    points
        .iter()
        .all(|&q| (dot(sub(q, p0), n) / len).abs() <= tol)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shortest round-trip decimals worked by hand: digits and exponent, and the
    /// written rounding of the doc comment's example (5 digits, largest exponent 1).
    #[test]
    fn written_rounding_follows_the_digits_written() {
        assert_eq!(decimal_digits(0.12345678), Some((8, -1)));
        assert_eq!(decimal_digits(-10.019), Some((5, 1)));
        assert_eq!(decimal_digits(2.2250738585072014e-308), Some((17, -308)));
        assert_eq!(decimal_digits(f64::MAX), Some((17, 308)));
        assert_eq!(decimal_digits(0.0), None);
        assert_eq!(decimal_digits(f64::NAN), None);
        assert_eq!(written_rounding([0.479, 10.019, 8.508]), 0.5e-3);
        assert_eq!(written_rounding([0.0, f64::INFINITY]), 0.0);
        // One digit is the precision; the last place of 3 at one digit is 1.
        assert_eq!(written_rounding([1e-5, 3.0]), 0.5);
    }

    /// `x` rounded to `digits` significant decimal digits, as a writer printing them does.
    fn round_to(x: f64, digits: usize) -> f64 {
        format!("{x:.*e}", digits - 1).parse().unwrap()
    }

    /// The bound holds against an independent computation: rational quadratic arcs (one
    /// Bezier segment, middle weight cos(a/2), NURBS Book eq. 7.33) of random centre, radius,
    /// plane and sweep are written with 6 to 12 significant digits; every sample of the
    /// curve so written lies within `written_point_rounding` of the true arc (its distance
    /// from the centre, computed by trigonometry, not by the curve). Full-precision numbers
    /// give a bound of a few units in the last place.
    #[test]
    fn written_point_rounding_bounds_what_rounding_moves() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..300 {
            let digits = 6 + case % 7;
            let centre = [
                rand() * 200.0 - 100.0,
                rand() * 200.0 - 100.0,
                rand() * 50.0,
            ];
            let radius = 0.5 + rand() * 300.0;
            let sweep = 0.2 + rand() * 2.6;
            // An orthonormal frame of a random plane.
            let a = [rand() - 0.5, rand() - 0.5, rand() - 0.5];
            let b = [rand() - 0.5, rand() - 0.5, rand() - 0.5];
            let n = cross(a, b);
            let unit = |v: Point3| {
                let l = norm(v);
                [v[0] / l, v[1] / l, v[2] / l]
            };
            let (x, y) = (unit(a), unit(cross(n, a)));
            let at = |t: f64, r: f64| {
                [0, 1, 2].map(|i| centre[i] + r * (t.cos() * x[i] + t.sin() * y[i]))
            };
            let w = (sweep / 2.0).cos();
            let exact_poles = [
                at(0.0, radius),
                at(sweep / 2.0, radius / w),
                at(sweep, radius),
            ];
            let poles: Vec<Point3> = exact_poles
                .iter()
                .map(|p| p.map(|c| round_to(c, digits)))
                .collect();
            let weights = vec![1.0, round_to(w, digits), 1.0];
            let bound = written_point_rounding(&poles, &weights);
            let curve = NurbsCurve::new(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                poles.clone(),
                Some(weights.clone()),
            )
            .unwrap();
            let worst = (0..=32)
                .map(|k| {
                    let p = curve.point_at(f64::from(k) / 32.0).unwrap();
                    (norm(sub(p, centre)) - radius).abs()
                })
                .fold(0.0f64, f64::max);
            assert!(
                worst <= bound,
                "case {case}: {digits} digits, off {worst:e} > {bound:e}"
            );
            // Not a vacuous bound: within a few hundred times the digits' last place.
            let scale = norm(centre) + 2.0 * radius;
            assert!(
                bound <= 500.0 * scale * 10f64.powi(-(digits as i32)),
                "case {case}: {bound:e}"
            );
        }
        // Full precision: a few units in the last place of the largest coordinate.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let poles = [[100.0, 0.0, 0.0], [100.0, 100.0, 0.0], [0.0, 100.0, 0.0]];
        assert!(written_point_rounding(&poles, &[1.0, h, 1.0]) < 1e-12);
        // Short numbers are taken as written with six digits, never coarser: coordinates
        // within 5e-5 (sqrt 3 of that a pole), the weight 0.5 within 5e-6 (over the least
        // weight 0.5, times the diameter 2 x 14.14): 3.69e-4, not the 5 that one digit of
        // `10.` would give.
        let coarse = written_point_rounding(&[[10.0, 0.0, 0.0], [0.0, 10.0, 0.0]], &[1.0, 0.5]);
        let expected = 3f64.sqrt() * 5e-5 + 2.0 * 200f64.sqrt() * 1e-5;
        assert!(
            (coarse - expected).abs() <= 1e-15,
            "{coarse:e} vs {expected:e}"
        );
        // Equal weights cancel: only the coordinates' rounding is left.
        let equal = written_point_rounding(&[[10.0, 0.0, 0.0], [0.0, 10.0, 0.0]], &[0.5, 0.5]);
        assert_eq!(equal, 3f64.sqrt() * 5e-5);
    }

    #[test]
    fn periodic_layout_of_a_closed_quadratic() {
        // Degree 2, 5 poles, the last 2 repeating the first 2, uniform knots.
        let pts = [
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 0., 0.],
            [1., 0., 0.],
        ];
        let knots: Vec<f64> = (0..8).map(f64::from).collect();
        assert!(periodic_layout(&knots, 2, 5, &|i| pts[i], &|_| 1.0, 1e-12));
        let mut k2 = knots.clone();
        k2[7] = 7.5;
        assert!(!periodic_layout(&k2, 2, 5, &|i| pts[i], &|_| 1.0, 1e-12));
        assert!(clamped(&[0., 0., 0., 1., 1., 1.], 2));
        // Open CASCADE's unperiodized circle (spec.md d.2): knots with multiplicity 2,
        // 7 poles of which only the last repeats the first.
        let t = 2.0 * std::f64::consts::PI / 3.0;
        let k = [-t, 0., 0., t, t, 2. * t, 2. * t, 3. * t, 3. * t, 4. * t];
        let c = [
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [-1., 1., 0.],
            [-1., 0., 0.],
            [0., -1., 0.],
            [1., 0., 0.],
        ];
        assert!(periodic_layout(&k, 2, 7, &|i| c[i], &|_| 1.0, 1e-12));
        let mut c2 = c;
        c2[6] = [1., 0.1, 0.];
        assert!(!periodic_layout(&k, 2, 7, &|i| c2[i], &|_| 1.0, 1e-12));
        // A clamped closed curve is closed but not periodic.
        let kc = [0., 0., 0., 1., 2., 3., 3., 3.];
        let cc = [
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 0.],
        ];
        assert!(!periodic_layout(&kc, 2, 5, &|i| cc[i], &|_| 1.0, 1e-12));
        assert!(!clamped(&knots, 2));
    }

    #[test]
    fn plane_normals() {
        let pts = [[0., 0., 1.], [1., 0., 1.], [1., 1., 1.]];
        assert_eq!(plane_normal(&pts, 1e-12), Some([0., 0., 1.]));
        assert_eq!(
            plane_normal(&[[0., 0., 0.], [1., 1., 1.], [2., 2., 2.]], 1e-12),
            None
        );
        assert_eq!(
            plane_normal(
                &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
                1e-12
            ),
            None
        );
    }
}
