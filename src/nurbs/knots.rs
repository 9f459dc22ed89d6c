//! Knot vectors: validation, span search (NURBS Book A2.1), multiplicities and the domain.
//!
//! nurbsx stores the *full (flat)* knot vector `U = {u_0, ..., u_m}` with
//! `m + 1 = n + p + 2` values for `n + 1` control points of degree `p`
//! (NURBS Book eq. 2.x; seed text 000, section 2-29). The valid parameter domain is
//! `[u_p, u_{n+1}]`, *not* `[u_0, u_m]`: for unclamped knot vectors the outer `p` knots on
//! each side only shape the basis functions near the ends.

use super::GeometryError;

/// Checks a flat knot vector for `poles` control points of degree `degree`.
///
/// Rules (each failure names the index): `knots.len() == poles + degree + 1`; every knot
/// finite; non-decreasing; no value repeated more than `degree + 1` times, and none more
/// than `degree` times strictly inside the domain; a non-empty domain `u_p < u_{n+1}`.
pub fn validate(degree: usize, poles: usize, knots: &[f64]) -> Result<(), GeometryError> {
    if degree == 0 || degree > super::MAX_DEGREE {
        return Err(GeometryError::BadDegree {
            degree,
            max: super::MAX_DEGREE,
        });
    }
    if poles < degree + 1 {
        return Err(GeometryError::TooFewPoles { poles, degree });
    }
    if knots.len() != poles + degree + 1 {
        return Err(GeometryError::KnotCount {
            knots: knots.len(),
            poles,
            degree,
        });
    }
    for (index, &value) in knots.iter().enumerate() {
        if !value.is_finite() {
            return Err(GeometryError::NonFiniteKnot { index, value });
        }
        if index > 0 && value < knots[index - 1] {
            return Err(GeometryError::DecreasingKnot {
                index,
                value,
                previous: knots[index - 1],
            });
        }
    }
    let (start, end) = (knots[degree], knots[poles]);
    if start >= end {
        return Err(GeometryError::EmptyDomain { start, end });
    }
    for (index, value, multiplicity) in runs(knots) {
        let max = if value > start && value < end {
            degree
        } else {
            degree + 1
        };
        if multiplicity > max {
            return Err(GeometryError::Multiplicity {
                index,
                value,
                multiplicity,
                max,
            });
        }
    }
    Ok(())
}

/// Iterates over runs of equal knots: `(first index, value, multiplicity)`.
pub fn runs(knots: &[f64]) -> impl Iterator<Item = (usize, f64, usize)> + '_ {
    let mut i = 0;
    std::iter::from_fn(move || {
        let value = *knots.get(i)?;
        let start = i;
        while i < knots.len() && knots[i] == value {
            i += 1;
        }
        Some((start, value, i - start))
    })
}

/// Whether both ends of a knot vector of degree `p` repeat `p + 1` times (the usual
/// clamped form: the boundary curve at each end is then the end row of poles).
pub fn clamped(knots: &[f64], p: usize) -> bool {
    let n = knots.len();
    n > 2 * p + 1
        && knots[..=p].iter().all(|&k| k == knots[0])
        && knots[n - p - 1..].iter().all(|&k| k == knots[n - 1])
}

/// The breakpoints of a knot vector of degree `p` (clamped or not), in increasing order:
/// its clamped ends and every knot strictly inside the domain with multiplicity exactly
/// `p`, each with the index of the pole the curve passes through there (NURBS Book
/// eq. 3.10 at a clamped end; at an interior knot of multiplicity `p`, eq. 2.5 leaves one
/// basis function, of the pole before the knot's first copy). A curve cut at breakpoints is
/// a slice of its poles, and a surface's isocurve at one is a row of its net.
pub fn breakpoints(knots: &[f64], p: usize) -> impl Iterator<Item = (f64, usize)> + '_ {
    let len = knots.len();
    let poles = len.saturating_sub(p + 1);
    runs(knots).filter_map(move |(start, x, m)| {
        if start == 0 {
            (m == p + 1).then_some((x, 0))
        } else if start + m == len {
            (m == p + 1 && poles > 0).then(|| (x, poles - 1))
        } else {
            (m == p && start > p && start + m <= poles).then(|| (x, start - 1))
        }
    })
}

/// The distinct knot values and their multiplicities (STEP's `knots` and
/// `knot_multiplicities`).
pub fn to_distinct(knots: &[f64]) -> (Vec<f64>, Vec<usize>) {
    runs(knots).map(|(_, v, m)| (v, m)).unzip()
}

/// The flat knot vector from distinct values and multiplicities; `None` on length mismatch
/// or if the total overflows `usize`.
pub fn from_distinct<M>(values: &[f64], multiplicities: M) -> Option<Vec<f64>>
where
    M: IntoIterator<Item = usize>,
    M::IntoIter: ExactSizeIterator + Clone,
{
    let multiplicities = multiplicities.into_iter();
    if values.len() != multiplicities.len() {
        return None;
    }
    let total = multiplicities
        .clone()
        .try_fold(0usize, |acc, m| acc.checked_add(m))?;
    let mut out = Vec::with_capacity(total);
    for (&v, m) in values.iter().zip(multiplicities) {
        out.extend(std::iter::repeat_n(v, m));
    }
    Some(out)
}

/// The valid domain `[u_p, u_{n+1}]` of a knot vector for degree `p` and `n + 1 = poles`.
#[inline]
pub fn domain(degree: usize, poles: usize, knots: &[f64]) -> (f64, f64) {
    (knots[degree], knots[poles])
}

/// Knot span index (NURBS Book A2.1 FindSpan): the `k` in `p..=n` with
/// `u_k <= u < u_{k+1}`; at the domain end `u = u_{n+1}` the last non-empty span.
///
/// `n + 1 = poles`. `u` must lie in the domain (callers check); values outside are clamped
/// to the first or last span. Binary search, `O(log n)`.
#[inline]
pub fn find_span(degree: usize, poles: usize, knots: &[f64], u: f64) -> usize {
    let n = poles - 1;
    if u >= knots[n + 1] {
        // A2.1 returns n here; with an unclamped end u_n may equal u_{n+1}, so step back to
        // the last span of non-zero length.
        let mut k = n;
        while k > degree && knots[k] >= knots[n + 1] {
            k -= 1;
        }
        return k;
    }
    degree + knots[degree + 1..=n].partition_point(|&x| x <= u)
}

/// Multiplicity of the value `u` in the knot vector (0 if absent).
pub fn multiplicity(knots: &[f64], u: f64) -> usize {
    let lo = knots.partition_point(|&x| x < u);
    let hi = knots.partition_point(|&x| x <= u);
    hi - lo
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Breakpoints are the knots where one basis function is 1 (A2.2 evaluated there):
    /// the clamped ends and the interior knots of multiplicity `p`, not a simple knot nor
    /// an unclamped end, each with that function's pole.
    #[test]
    fn breakpoints_are_where_one_basis_function_is_one() {
        let cases: [(usize, &[f64]); 3] = [
            (3, &[0., 0., 0., 0., 1., 1., 1., 2., 3., 3., 3., 3.]),
            (2, &[0., 0., 0., 1., 1., 2., 3., 3., 4., 4., 4.]),
            (2, &[0., 1., 2., 3., 3., 4., 5., 6.]),
        ];
        for (p, knots) in cases {
            let poles = knots.len() - p - 1;
            let found: Vec<(f64, usize)> = breakpoints(knots, p).collect();
            let (a, b) = domain(p, poles, knots);
            let mut expected = Vec::new();
            let mut values: Vec<f64> = knots.to_vec();
            values.dedup();
            for x in values.into_iter().filter(|&x| x >= a && x <= b) {
                let span = find_span(p, poles, knots, x);
                let mut n = vec![0.0; p + 1];
                crate::nurbs::basis::basis_funs(span, x, p, knots, &mut n);
                if let Some(j) = n.iter().position(|&v| v == 1.0) {
                    let interior = x > a && x < b;
                    // An end counts only when clamped (p + 1 copies).
                    if interior || multiplicity(knots, x) == p + 1 {
                        expected.push((x, span - p + j));
                    }
                }
            }
            assert_eq!(found, expected, "{knots:?}");
        }
    }

    #[test]
    fn span_search_matches_linear_scan() {
        let knots = [0., 0., 0., 1., 2., 2., 3., 4., 4., 4.];
        let (p, poles) = (2, 7);
        for k in 0..=400 {
            let u = 4.0 * f64::from(k) / 400.0;
            let s = find_span(p, poles, &knots, u);
            assert!(
                knots[s] <= u && (u < knots[s + 1] || (u == 4.0 && s == 6)),
                "u={u} s={s}"
            );
        }
    }

    #[test]
    fn unclamped_domain_and_end_span() {
        // p = 3, knots 0..7, 4 poles: domain [3, 4] (pitfalls.md A.1).
        let knots: Vec<f64> = (0..8).map(f64::from).collect();
        assert_eq!(domain(3, 4, &knots), (3.0, 4.0));
        assert_eq!(find_span(3, 4, &knots, 4.0), 3);
        // End knot u_{n+1} doubled inside the unclamped tail: last non-empty span.
        let knots = [0., 1., 2., 3., 4., 4., 5., 6.];
        assert_eq!(find_span(3, 4, &knots, 4.0), 3);
    }

    #[test]
    fn validation_names_the_index() {
        assert_eq!(
            validate(2, 3, &[0., 0., 0., 1., 0.5, 1.]),
            Err(GeometryError::DecreasingKnot {
                index: 4,
                value: 0.5,
                previous: 1.0
            })
        );
        assert!(matches!(
            validate(2, 4, &[0., 0., 0., 0.5, 0.5, 0.5, 1., 1.]),
            Err(GeometryError::KnotCount { .. })
        ));
        assert!(matches!(
            validate(2, 6, &[0., 0., 0., 0.5, 0.5, 0.5, 1., 1., 1.]),
            Err(GeometryError::Multiplicity {
                index: 3,
                multiplicity: 3,
                max: 2,
                ..
            })
        ));
        assert!(matches!(
            validate(1, 2, &[0., f64::NAN, 1., 1.]),
            Err(GeometryError::NonFiniteKnot { index: 1, .. })
        ));
        assert!(validate(2, 3, &[0., 0., 0., 1., 1., 1.]).is_ok());
    }

    #[test]
    fn distinct_round_trip() {
        let flat = vec![0., 0., 0., 0.5, 1., 1., 1.];
        let (v, m) = to_distinct(&flat);
        assert_eq!(v, vec![0., 0.5, 1.]);
        assert_eq!(m, vec![3, 1, 3]);
        assert_eq!(from_distinct(&v, m.iter().copied()).unwrap(), flat);
    }
}
