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

/// Where one removal of the knot at index `r` (multiplicity `s`) splits its equations.
///
/// Removing one copy of `u = U_r` replaces the poles `P_first..=P_last` (`first = r - p`,
/// `last = r - s`) by `Q_first..Q_(last-1)`, tied by the knot insertion equations (NURBS Book
/// eq. 5.28, A5.8) `P_k = a_k Q_k + (1 - a_k) Q_(k-1)`, `a_k = (u - U_k) / (U_(k+p+1) - U_k)`,
/// `k = first..=last`, with `Q_(first-1) = P_(first-1)` and `Q_last = P_(last+1)`: one
/// equation more than unknowns. A5.8 solves the first half forward (dividing by `a_k`) and
/// the second half backward (dividing by `1 - a_k`) and tests where they meet. Any split
/// point gives the same exact result, but rounding grows by `1 / a_k` or `1 / (1 - a_k)` per
/// step, which near a knot of high multiplicity reaches 1e5 for a symmetric split (an
/// exactly inserted knot then fails a 1e-9 removal). So the split `m` (forward through
/// `m`, backward down to `m + 2`, equation `m + 1` left over as the test) is the one whose
/// rounding amplification, in the new poles and in the test, is the smallest.
fn best_split(knots: &[f64], p: usize, r: usize, s: usize) -> usize {
    let (first, last) = (r - p, r - s);
    let u = knots[r];
    let a = |k: usize| (u - knots[k]) / (knots[k + p + 1] - knots[k]);
    // Forward: gf[k] bounds the rounding of Q_k in units of one step's rounding.
    let mut gf = vec![0.0f64; last + 1 - first + 1];
    for k in first..=last {
        let ak = a(k);
        gf[k + 1 - first] = (1.0 + (1.0 - ak).abs() * gf[k - first]) / ak.abs();
    }
    // Backward: gb[k] for Q_k computed from equation k + 1 down.
    let mut gb = vec![0.0f64; last + 1 - first + 1];
    for k in (first + 1..=last).rev() {
        let ak = a(k);
        gb[k - 1 - first + 1] = (1.0 + ak.abs() * gb[k - first + 1]) / (1.0 - ak).abs();
    }
    // gf index k + 1 - first holds Q_k (index 0: Q_(first-1), exact); gb likewise, its last
    // slot Q_last exact.
    let mut best = (f64::INFINITY, last - 1);
    for m in first - 1..last {
        let t = m + 1;
        let at = a(t);
        let test = at.abs() * gb[t + 1 - first] + (1.0 - at).abs() * gf[t - first];
        let poles = gf[..=m + 1 - first]
            .iter()
            .chain(&gb[m + 2 - first..])
            .fold(0.0f64, |w, &g| w.max(g));
        let score = test.max(poles);
        // NaN (overflowed amplification) never wins.
        if score < best.0 {
            best = (score, m);
        }
    }
    best.1
}

/// Tries to remove the interior knot `u` up to `num` times from every row, one copy at a
/// time (A5.8's removals in sequence, each on the poles the previous one left, as in A5.8),
/// spending at most `budget` (homogeneous error units). Each removal's error value is the
/// distance by which its left-over equation misses: the curve without the knot, with `u`
/// inserted again, has exactly the old poles except that one, so the curve moves by at most
/// that distance (homogeneous; basis functions sum to one). Preconditions (callers): `u`
/// strictly inside the domain, `1 <= num <= multiplicity`.
fn remove_bundle(b: &Bundle, u: f64, num: usize, budget: f64) -> Removal {
    let p = b.degree;
    let mut knots = b.knots.clone();
    let mut rows = b.rows.clone();
    let mut spent = 0.0;
    let mut refused = None;
    let mut removed = 0;
    let mut scratch: Vec<Hpoint> = Vec::with_capacity(p + 2);
    while removed < num {
        let s = multiplicity(&knots, u);
        let r = knots.partition_point(|&x| x <= u) - 1;
        let (first, last) = (r - p, r - s);
        let m = best_split(&knots, p, r, s);
        let a = |k: usize| (u - knots[k]) / (knots[k + p + 1] - knots[k]);
        let mut worst: f64 = 0.0;
        let mut solved: Vec<Vec<Hpoint>> = Vec::with_capacity(rows.len());
        for pw in &rows {
            // q[k + 1 - first] = Q_k for k = first - 1..=last.
            scratch.clear();
            scratch.resize(last + 2 - first, [0.0; 4]);
            let q = &mut scratch;
            q[0] = pw[first - 1];
            q[last + 1 - first] = pw[last + 1];
            for k in first..=m {
                let ak = a(k);
                let prev = q[k - first];
                for c in 0..4 {
                    q[k + 1 - first][c] = (pw[k][c] - (1.0 - ak) * prev[c]) / ak;
                }
            }
            for k in (m + 2..=last).rev() {
                let ak = a(k);
                let next = q[k + 1 - first];
                for c in 0..4 {
                    q[k - first][c] = (pw[k][c] - ak * next[c]) / (1.0 - ak);
                }
            }
            let t = m + 1;
            let at = a(t);
            let (hi, lo) = (q[t + 1 - first], q[t - first]);
            let mix = [
                at * hi[0] + (1.0 - at) * lo[0],
                at * hi[1] + (1.0 - at) * lo[1],
                at * hi[2] + (1.0 - at) * lo[2],
                at * hi[3] + (1.0 - at) * lo[3],
            ];
            let d = dist4(pw[t], mix);
            // NaN (overflow) counts as a failure.
            worst = if d.is_nan() {
                f64::INFINITY
            } else {
                worst.max(d)
            };
            solved.push(q[1..last + 1 - first].to_vec());
        }
        if spent + worst > budget {
            refused = Some(worst);
            break;
        }
        spent += worst;
        for (pw, new) in rows.iter_mut().zip(&solved) {
            // P_first..=P_last become Q_first..Q_(last-1): one pole fewer.
            pw.splice(first..=last, new.iter().copied());
        }
        knots.remove(r);
        removed += 1;
    }
    Removal {
        bundle: Bundle {
            degree: p,
            knots,
            rows,
        },
        removed,
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
