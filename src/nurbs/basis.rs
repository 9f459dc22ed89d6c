//! B-spline basis functions (NURBS Book A2.2 BasisFuns and A2.3 DersBasisFuns).
//!
//! Both work on stack buffers sized by [`MAX_DEGREE`](super::MAX_DEGREE), so the hot
//! evaluation paths allocate nothing.

use super::MAX_DEGREE;

/// The `p + 1` non-zero basis functions `N_{span-p,p}(u) .. N_{span,p}(u)` (A2.2), written to
/// `out[..=p]`. `span` comes from [`find_span`](super::knots::find_span).
#[inline]
pub fn basis_funs(span: usize, u: f64, p: usize, knots: &[f64], out: &mut [f64]) {
    let mut left = [0.0; MAX_DEGREE + 1];
    let mut right = [0.0; MAX_DEGREE + 1];
    out[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
}
