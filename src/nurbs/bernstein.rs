//! Bernstein polynomials and binomial coefficients (NURBS Book A1.2 Bernstein, A1.3
//! AllBernstein; seed 000 sections 2-5 .. 2-9, seed 001).
//!
//! Used by Bezier degree elevation (coefficients of eq. 5.36 / seed 000 eq. 2-62) and by the
//! error bound of Bezier degree reduction (eqs. 5.41-5.46), where the largest value of
//! `B_{i,n}` on `[0, 1]`, reached at `t = i / n`, tightens the bound.

/// The binomial coefficient `C(n, k)` as `f64` (0 when `k > n`).
///
/// Computed by the multiplicative formula, each factor exact in `f64` for the degrees the
/// core supports ([`MAX_DEGREE`](super::MAX_DEGREE) = 64 gives values below 2^63; the
/// relative rounding error is a few ulps).
pub fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    let mut c = 1.0;
    for i in 0..k {
        // C(n, i + 1) = C(n, i) * (n - i) / (i + 1): an integer at every step.
        c = c * (n - i) as f64 / (i + 1) as f64;
    }
    c.round()
}

/// The Bernstein polynomial `B_{i,n}(t) = C(n, i) t^i (1 - t)^(n - i)` by the triangular
/// recurrence of A1.2 (`B_{i,n} = (1 - t) B_{i,n-1} + t B_{i-1,n-1}`), which is stable on
/// `[0, 1]`. Returns 0 for `i > n`.
pub fn bernstein(i: usize, n: usize, t: f64) -> f64 {
    if i > n {
        return 0.0;
    }
    let mut temp = vec![0.0; n + 1];
    temp[n - i] = 1.0;
    let t1 = 1.0 - t;
    for k in 1..=n {
        for j in (k..=n).rev() {
            temp[j] = t1 * temp[j] + t * temp[j - 1];
        }
    }
    temp[n]
}

/// All `n + 1` Bernstein polynomials of degree `n` at `t` (A1.3 AllBernstein).
// Index loops mirror the NURBS Book pseudo-code line by line, which is how they are checked.
#[allow(clippy::needless_range_loop)]
pub fn all_bernstein(n: usize, t: f64) -> Vec<f64> {
    let mut b = vec![0.0; n + 1];
    b[0] = 1.0;
    let t1 = 1.0 - t;
    for j in 1..=n {
        let mut saved = 0.0;
        for k in 0..j {
            let temp = b[k];
            b[k] = saved + t1 * temp;
            saved = t * temp;
        }
        b[j] = saved;
    }
    b
}

/// The maximum of `B_{i,n}` on `[0, 1]`, attained at `t = i / n` (0 when `i > n`).
pub fn bernstein_max(i: usize, n: usize) -> f64 {
    if i > n {
        return 0.0;
    }
    if n == 0 {
        return 1.0;
    }
    bernstein(i, n, i as f64 / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binomials_are_pascal() {
        for n in 1..40 {
            for k in 1..n {
                assert_eq!(
                    binomial(n, k),
                    binomial(n - 1, k - 1) + binomial(n - 1, k),
                    "{n} {k}"
                );
            }
        }
        assert_eq!(binomial(5, 7), 0.0);
    }

    #[test]
    fn recurrence_matches_closed_form() {
        for n in 0..12 {
            let all = all_bernstein(n, 0.3);
            for (i, b) in all.iter().enumerate() {
                let closed = binomial(n, i) * 0.3f64.powi(i as i32) * 0.7f64.powi((n - i) as i32);
                assert!((b - closed).abs() < 1e-15, "{n} {i}");
                assert!((bernstein(i, n, 0.3) - closed).abs() < 1e-15);
            }
        }
    }
}
