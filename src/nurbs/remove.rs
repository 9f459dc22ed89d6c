//! Knot removal within a tolerance (NURBS Book A5.8 RemoveCurveKnot; surfaces per direction,
//! a removal is done only if every row passes).
//!
//! The tolerance is a *geometric* bound on the change of the curve (or surface). A5.8 tests
//! each removal on the homogeneous poles; as in the Book (eq. 5.30) the test value for a
//! rational curve is `TOL = d * w_min / (1 + |P|_max)` (`d` the tolerance, `w_min` the
//! smallest weight, `|P|_max` the largest pole distance from the origin); for a polynomial
//! curve `TOL = d`. Successive removals (the same knot several times, or several knots in
//! [`remove_all_removable`](NurbsCurve::remove_all_removable)) each spend part of that
//! budget: the sum of their A5.8 error values must stay within `TOL`, so the total change
//! stays within `d` (the Book's A5.8 checks each removal alone, which can add up).

use super::insert::{Bundle, Dir};
use super::knots::{multiplicity, runs};
use super::{GeometryError, Hpoint, NurbsCurve, NurbsSurface};

fn dist4(a: Hpoint, b: Hpoint) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2) + (a[3] - b[3]).powi(2))
        .sqrt()
}

/// Outcome of [`remove_bundle`].
struct Removal {
    bundle: Bundle,
    removed: usize,
    /// Homogeneous budget spent.
    spent: f64,
    /// The error value of the first refused removal, if any.
    refused: Option<f64>,
}

/// A5.8: tries to remove the interior knot `u` up to `num` times from every row, spending at
/// most `budget` (homogeneous error units). Preconditions (callers): `u` strictly inside the
/// domain, `1 <= num <= multiplicity`.
fn remove_bundle(b: &Bundle, u: f64, num: usize, budget: f64) -> Removal {
    let p = b.degree;
    let knots = &b.knots;
    let n = b.poles() - 1;
    let m = n + p + 1;
    let ord = p + 1;
    let s = multiplicity(knots, u);
    let r = knots.partition_point(|&x| x <= u) - 1;
    let fout = (2 * r - s - p) / 2;
    let mut first = r - p;
    let mut last = r - s;
    let mut rows = b.rows.clone();
    let mut t = 0usize;
    let mut spent = 0.0;
    let mut refused = None;
    let uk = |i: usize| knots[i];
    while t < num {
        let off = first - 1;
        let mut temps = Vec::with_capacity(rows.len());
        let mut worst: f64 = 0.0;
        for pw in &rows {
            let mut temp = vec![[0.0; 4]; last + 2 - off];
            temp[0] = pw[off];
            temp[last + 1 - off] = pw[last + 1];
            let (mut i, mut j) = (first, last);
            let (mut ii, mut jj) = (1usize, last - off);
            // Signed: j - i may become negative.
            while (j as isize) - (i as isize) > t as isize {
                let alfi = (u - uk(i)) / (uk(i + ord + t) - uk(i));
                let alfj = (u - uk(j - t)) / (uk(j + ord) - uk(j - t));
                for c in 0..4 {
                    temp[ii][c] = (pw[i][c] - (1.0 - alfi) * temp[ii - 1][c]) / alfi;
                    temp[jj][c] = (pw[j][c] - alfj * temp[jj + 1][c]) / (1.0 - alfj);
                }
                i += 1;
                ii += 1;
                j -= 1;
                jj -= 1;
            }
            let d = if ((j as isize) - (i as isize)) < t as isize {
                dist4(temp[ii - 1], temp[jj + 1])
            } else {
                let alfi = (u - uk(i)) / (uk(i + ord + t) - uk(i));
                let a = temp[ii + t + 1];
                let c = temp[ii - 1];
                let mix = [
                    alfi * a[0] + (1.0 - alfi) * c[0],
                    alfi * a[1] + (1.0 - alfi) * c[1],
                    alfi * a[2] + (1.0 - alfi) * c[2],
                    alfi * a[3] + (1.0 - alfi) * c[3],
                ];
                dist4(pw[i], mix)
            };
            // NaN (overflow) counts as a failure.
            worst = if d.is_nan() {
                f64::INFINITY
            } else {
                worst.max(d)
            };
            temps.push(temp);
        }
        if spent + worst > budget {
            refused = Some(worst);
            break;
        }
        spent += worst;
        for (pw, temp) in rows.iter_mut().zip(&temps) {
            let (mut i, mut j) = (first, last);
            while (j as isize) - (i as isize) > t as isize {
                pw[i] = temp[i - off];
                pw[j] = temp[j - off];
                i += 1;
                j -= 1;
            }
        }
        first -= 1;
        last += 1;
        t += 1;
    }
    if t == 0 {
        return Removal {
            bundle: b.clone(),
            removed: 0,
            spent,
            refused,
        };
    }
    let mut new_knots = knots[..=r - t].to_vec();
    new_knots.extend_from_slice(&knots[r + 1..=m]);
    let (mut i, mut j) = (fout, fout);
    for k in 1..t {
        if k % 2 == 1 {
            i += 1;
        } else {
            j -= 1;
        }
    }
    for pw in &mut rows {
        // A5.8's final shift: poles i+1..=n move down to start at j (memmove).
        pw.copy_within(i + 1..=n, j);
        pw.truncate(n + 1 - t);
    }
    Removal {
        bundle: Bundle {
            degree: p,
            knots: new_knots,
            rows,
        },
        removed: t,
        spent,
        refused,
    }
}

/// The homogeneous test value for the geometric tolerance `d` (eq. 5.30).
fn homogeneous_tolerance(b: &Bundle, rational: bool, d: f64) -> f64 {
    if !rational {
        return d;
    }
    let mut wmin = f64::INFINITY;
    let mut pmax: f64 = 0.0;
    for h in b.rows.iter().flatten() {
        wmin = wmin.min(h[3]);
        let q = super::from_homogeneous(*h);
        pmax = pmax.max((q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt());
    }
    d * wmin / (1.0 + pmax)
}

fn check_tolerance(tolerance: f64) -> Result<(), GeometryError> {
    if tolerance >= 0.0 && tolerance.is_finite() {
        Ok(())
    } else {
        Err(GeometryError::InvalidArgument(format!(
            "removal tolerance {tolerance} must be finite and non-negative"
        )))
    }
}

/// Public single-knot removal on a bundle: checks, then A5.8.
fn remove_checked(
    b: &Bundle,
    rational: bool,
    u: f64,
    times: usize,
    tolerance: f64,
) -> Result<(Bundle, usize), GeometryError> {
    check_tolerance(tolerance)?;
    let (start, end) = b.domain();
    if !(u > start && u < end) {
        return Err(GeometryError::InvalidArgument(format!(
            "knot {u} to remove is not strictly inside the domain [{start}, {end}]"
        )));
    }
    let s = multiplicity(&b.knots, u);
    if s == 0 {
        return Err(GeometryError::InvalidArgument(format!("{u} is not a knot")));
    }
    if times == 0 {
        return Ok((b.clone(), 0));
    }
    let tol = homogeneous_tolerance(b, rational, tolerance);
    let out = remove_bundle(b, u, times.min(s), tol);
    if out.removed == 0 {
        let scale = if tol > 0.0 { tolerance / tol } else { 1.0 };
        return Err(GeometryError::ToleranceExceeded {
            what: "knot removal",
            bound: out.refused.unwrap_or(f64::INFINITY) * scale,
            tolerance,
        });
    }
    Ok((out.bundle, out.removed))
}

/// Removes every interior knot as often as the shared budget allows, knot by knot.
fn remove_all(
    b: &Bundle,
    rational: bool,
    tolerance: f64,
) -> Result<(Bundle, usize), GeometryError> {
    check_tolerance(tolerance)?;
    let mut budget = homogeneous_tolerance(b, rational, tolerance);
    let mut cur = b.clone();
    let mut total = 0;
    let (start, end) = b.domain();
    let values: Vec<f64> = runs(&b.knots)
        .map(|(_, v, _)| v)
        .filter(|&v| v > start && v < end)
        .collect();
    for v in values {
        let s = multiplicity(&cur.knots, v);
        if s == 0 {
            continue;
        }
        let out = remove_bundle(&cur, v, s, budget);
        budget -= out.spent;
        total += out.removed;
        cur = out.bundle;
    }
    Ok((cur, total))
}

impl NurbsCurve {
    /// Removes the interior knot `u` up to `times` times while the curve moves by at most
    /// `tolerance` (NURBS Book A5.8 RemoveCurveKnot with the eq. 5.30 tolerance for rational
    /// curves; see the module documentation). Returns the curve and how many copies were
    /// removed (`<= times`, stopping at the first refused removal).
    ///
    /// Errors: `u` not a knot strictly inside the domain, or a negative/non-finite tolerance
    /// ([`GeometryError::InvalidArgument`]); not even one removal within the tolerance
    /// ([`GeometryError::ToleranceExceeded`], with the geometric error bound of that removal).
    pub fn remove_knot(
        &self,
        u: f64,
        times: usize,
        tolerance: f64,
    ) -> Result<(NurbsCurve, usize), GeometryError> {
        let (b, k) = remove_checked(&self.to_bundle(), self.is_rational(), u, times, tolerance)?;
        Ok((self.with_bundle(b)?, k))
    }

    /// Removes as many interior knots as possible with a total change of at most
    /// `tolerance` (A5.8 on each distinct interior knot in turn, sharing the budget).
    /// Returns the curve and the number of knots removed.
    pub fn remove_all_removable(
        &self,
        tolerance: f64,
    ) -> Result<(NurbsCurve, usize), GeometryError> {
        let (b, k) = remove_all(&self.to_bundle(), self.is_rational(), tolerance)?;
        Ok((self.with_bundle(b)?, k))
    }
}

impl NurbsSurface {
    /// Removes the u knot `u` up to `times` times (A5.8 on every column; a removal is done
    /// only if every column passes, with the eq. 5.30 tolerance over the whole net).
    /// Returns the surface and the number removed. Errors as [`NurbsCurve::remove_knot`].
    pub fn remove_knot_u(
        &self,
        u: f64,
        times: usize,
        tolerance: f64,
    ) -> Result<(NurbsSurface, usize), GeometryError> {
        self.remove_dir(Dir::U, u, times, tolerance)
    }

    /// Removes the v knot `v` up to `times` times (A5.8 on every row).
    pub fn remove_knot_v(
        &self,
        v: f64,
        times: usize,
        tolerance: f64,
    ) -> Result<(NurbsSurface, usize), GeometryError> {
        self.remove_dir(Dir::V, v, times, tolerance)
    }

    /// Removes as many u and then v knots as possible with a total change of at most
    /// `tolerance` (half the budget per direction). Returns the surface and the count.
    pub fn remove_all_removable(
        &self,
        tolerance: f64,
    ) -> Result<(NurbsSurface, usize), GeometryError> {
        let (bu, ku) = remove_all(&self.to_bundle(Dir::U), self.is_rational(), tolerance / 2.0)?;
        let s = self.with_bundle(Dir::U, bu)?;
        let (bv, kv) = remove_all(&s.to_bundle(Dir::V), s.is_rational(), tolerance / 2.0)?;
        Ok((s.with_bundle(Dir::V, bv)?, ku + kv))
    }

    fn remove_dir(
        &self,
        dir: Dir,
        t: f64,
        times: usize,
        tolerance: f64,
    ) -> Result<(NurbsSurface, usize), GeometryError> {
        let (b, k) = remove_checked(
            &self.to_bundle(dir),
            self.is_rational(),
            t,
            times,
            tolerance,
        )?;
        Ok((self.with_bundle(dir, b)?, k))
    }
}
