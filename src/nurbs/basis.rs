//! B-spline basis functions (NURBS Book A2.2 BasisFuns and A2.3 DersBasisFuns).
//!
//! Both work on stack buffers for the degrees met in practice, so the hot evaluation paths
//! allocate nothing; [`ders_basis_funs`] falls back to one heap buffer above degree 7.

use super::MAX_DEGREE;

/// The `p + 1` non-zero basis functions `N_{span-p,p}(u) .. N_{span,p}(u)` (A2.2), written to
/// `out[..=p]`. `span` comes from [`find_span`](super::knots::find_span).
#[inline]
pub fn basis_funs(span: usize, u: f64, p: usize, knots: &[f64], out: &mut [f64]) {
    // Small degrees use small scratch arrays: zeroing two 65-entry arrays per call is a
    // measurable part of a bicubic point evaluation. The arithmetic is the same in every
    // branch, so results are bit-identical whichever branch runs.
    if p < 4 {
        basis_funs_in::<4>(span, u, p, knots, out);
    } else if p < 8 {
        basis_funs_in::<8>(span, u, p, knots, out);
    } else {
        basis_funs_in::<{ MAX_DEGREE + 1 }>(span, u, p, knots, out);
    }
}

/// A2.2 with scratch arrays of `N > p` entries.
#[inline(always)]
pub(crate) fn basis_funs_in<const N: usize>(
    span: usize,
    u: f64,
    p: usize,
    knots: &[f64],
    out: &mut [f64],
) {
    let mut left = [0.0; N];
    let mut right = [0.0; N];
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

/// The `p + 1` non-zero basis functions (A2.2, bit-identical to [`basis_funs`]) and their
/// first derivatives, written to `out[..=p]` and `der[..=p]`.
///
/// The derivatives come from the last level of A2.2 at no extra division: with
/// `T_r = N_{i,p-1} / (u_{i+p} - u_i)` (`i = span - p + 1 + r`), the quotient A2.2 already
/// forms, `N'_{span-p+r,p} = p (T_{r-1} - T_r)` (NURBS Book eq. 2.7, `T_{-1} = T_p = 0`).
#[inline]
pub fn basis_funs_ders1(
    span: usize,
    u: f64,
    p: usize,
    knots: &[f64],
    out: &mut [f64],
    der: &mut [f64],
) {
    if p < 4 {
        basis_funs_ders1_in::<4>(span, u, p, knots, out, der);
    } else if p < 8 {
        basis_funs_ders1_in::<8>(span, u, p, knots, out, der);
    } else {
        basis_funs_ders1_in::<{ MAX_DEGREE + 1 }>(span, u, p, knots, out, der);
    }
}

/// [`basis_funs_ders1`] with scratch arrays of `N > p` entries.
#[inline(always)]
pub(crate) fn basis_funs_ders1_in<const N: usize>(
    span: usize,
    u: f64,
    p: usize,
    knots: &[f64],
    out: &mut [f64],
    der: &mut [f64],
) {
    if N == 4 && p == 3 {
        let (b, d) = cubic::<true>(span, u, knots);
        out[..4].copy_from_slice(&b);
        der[..4].copy_from_slice(&d);
        return;
    }
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    out[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        if j == p {
            let pf = p as f64;
            let mut prev = 0.0;
            for r in 0..j {
                let temp = out[r] / (right[r + 1] + left[j - r]);
                out[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
                der[r] = pf * (prev - temp);
                prev = temp;
            }
            der[p] = pf * prev;
        } else {
            for r in 0..j {
                let temp = out[r] / (right[r + 1] + left[j - r]);
                out[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
        }
        out[j] = saved;
    }
}

/// A2.2 for `p = 3` written out, register-only (the loops and scratch arrays of the general
/// version cost store-forwarding stalls in the hot kernels). The operations are those of the
/// loop, in the same order (including the `0.0 +` of `saved`, which keeps the sign of zero),
/// so the values are bit-identical. With `D1`, the first derivatives as in
/// [`basis_funs_ders1`].
#[inline(always)]
fn cubic<const D1: bool>(span: usize, u: f64, knots: &[f64]) -> ([f64; 4], [f64; 4]) {
    let k = &knots[span - 2..span + 4];
    let (l1, l2, l3) = (u - k[2], u - k[1], u - k[0]);
    let (r1, r2, r3) = (k[3] - u, k[4] - u, k[5] - u);
    // j = 1
    let t = 1.0 / (r1 + l1);
    let o0 = 0.0 + r1 * t;
    let o1 = l1 * t;
    // j = 2
    let t = o0 / (r1 + l2);
    let a0 = 0.0 + r1 * t;
    let s = l2 * t;
    let t = o1 / (r2 + l1);
    let a1 = s + r2 * t;
    let a2 = l1 * t;
    // j = 3
    let t0 = a0 / (r1 + l3);
    let b0 = 0.0 + r1 * t0;
    let s = l3 * t0;
    let t1 = a1 / (r2 + l2);
    let b1 = s + r2 * t1;
    let s = l2 * t1;
    let t2 = a2 / (r3 + l1);
    let b2 = s + r3 * t2;
    let b3 = l1 * t2;
    let d = if D1 {
        [3.0 * (0.0 - t0), 3.0 * (t0 - t1), 3.0 * (t1 - t2), 3.0 * t2]
    } else {
        [0.0; 4]
    };
    ([b0, b1, b2, b3], d)
}

/// The non-zero basis functions and their derivatives up to order `n` (NURBS Book A2.3
/// DersBasisFuns).
///
/// `ders` is a flat row-major table with rows of `p + 1` entries:
/// `ders[k * (p + 1) + j]` is the `k`-th derivative of `N_{span-p+j,p}` at `u`, for
/// `k = 0..=n`; it must hold at least `(n + 1) * (p + 1)` values. Any order works:
/// rows `k > p` are set to zero (a degree-`p` polynomial piece has no higher derivatives).
/// Row 0 is bit-identical to [`basis_funs`].
///
/// No heap allocation for `p < 8`; above that one scratch buffer of `(p + 1)^2 + 2 (p + 1)`
/// values is allocated per call.
pub fn ders_basis_funs(span: usize, u: f64, p: usize, n: usize, knots: &[f64], ders: &mut [f64]) {
    let stride = p + 1;
    if p < 4 {
        let mut ndu = [0.0; 16];
        let mut a = [0.0; 8];
        ders_inner::<4>(span, u, p, n, knots, &mut ndu, &mut a, ders);
    } else if p < 8 {
        let mut ndu = [0.0; 64];
        let mut a = [0.0; 16];
        ders_inner::<8>(span, u, p, n, knots, &mut ndu, &mut a, ders);
    } else {
        let mut scratch = vec![0.0; stride * stride + 2 * stride];
        let (ndu, a) = scratch.split_at_mut(stride * stride);
        ders_basis_funs_in(span, u, p, n, knots, ndu, a, ders);
    }
}

/// A2.3 on caller-provided scratch: `ndu` holds `(p + 1)^2` values, `a` holds `2 (p + 1)`.
/// `ndu[j * (p + 1) + r]` stores the book's `ndu[j][r]`: basis functions in the upper
/// triangle (`r >= j`), knot differences in the lower one.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn ders_basis_funs_in(
    span: usize,
    u: f64,
    p: usize,
    n: usize,
    knots: &[f64],
    ndu: &mut [f64],
    a: &mut [f64],
    ders: &mut [f64],
) {
    ders_inner::<{ MAX_DEGREE + 1 }>(span, u, p, n, knots, ndu, a, ders);
}

/// A2.3 with `left`/`right` scratch of `N > p` entries on the stack.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn ders_inner<const N: usize>(
    span: usize,
    u: f64,
    p: usize,
    n: usize,
    knots: &[f64],
    ndu: &mut [f64],
    a: &mut [f64],
    ders: &mut [f64],
) {
    let s = p + 1;
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    ndu[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle: knot differences.
            ndu[j * s + r] = right[r + 1] + left[j - r];
            let temp = ndu[r * s + j - 1] / ndu[j * s + r];
            // Upper triangle: basis functions.
            ndu[r * s + j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j * s + j] = saved;
    }
    for j in 0..=p {
        ders[j] = ndu[j * s + p];
    }
    let nd = n.min(p);
    // Derivatives (Piegl & Tiller eq. 2.9), two alternating rows of coefficients a[s1], a[s2].
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, s);
        a[0] = 1.0;
        for k in 1..=nd {
            let mut d = 0.0;
            let pk = p - k;
            if r >= k {
                let rk = r - k;
                a[s2] = a[s1] / ndu[(pk + 1) * s + rk];
                d = a[s2] * ndu[rk * s + pk];
            }
            // j1 = 1 if r - k >= -1 else k - r; j2 = k - 1 if r - 1 <= p - k else p - r.
            let j1 = if r + 1 >= k { 1 } else { k - r };
            let j2 = if r <= pk + 1 { k - 1 } else { p - r };
            for j in j1..=j2 {
                // Here r + j >= k, so rk + j is non-negative.
                let rkj = r + j - k;
                a[s2 + j] = (a[s1 + j] - a[s1 + j - 1]) / ndu[(pk + 1) * s + rkj];
                d += a[s2 + j] * ndu[rkj * s + pk];
            }
            if r <= pk {
                a[s2 + k] = -a[s1 + k - 1] / ndu[(pk + 1) * s + r];
                d += a[s2 + k] * ndu[r * s + pk];
            }
            ders[k * s + r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    // Multiply by p! / (p - k)!.
    let mut f = p as f64;
    for k in 1..=nd {
        for v in &mut ders[k * s..(k + 1) * s] {
            *v *= f;
        }
        f *= (p - k) as f64;
    }
    for v in &mut ders[(nd + 1) * s..(n + 1) * s] {
        *v = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::knots::find_span;

    /// Cox-de Boor recursion (NURBS Book eq. 2.5), independent of A2.2.
    fn cox_de_boor(i: usize, p: usize, u: f64, k: &[f64]) -> f64 {
        if p == 0 {
            return if k[i] <= u && u < k[i + 1] { 1.0 } else { 0.0 };
        }
        let mut v = 0.0;
        if k[i + p] > k[i] {
            v += (u - k[i]) / (k[i + p] - k[i]) * cox_de_boor(i, p - 1, u, k);
        }
        if k[i + p + 1] > k[i + 1] {
            v += (k[i + p + 1] - u) / (k[i + p + 1] - k[i + 1]) * cox_de_boor(i + 1, p - 1, u, k);
        }
        v
    }

    /// Derivative by eq. 2.7 recursion: N'_{i,p} = p (N_{i,p-1}/(u_{i+p}-u_i) - ...).
    fn cox_der(i: usize, p: usize, k_ord: usize, u: f64, k: &[f64]) -> f64 {
        if k_ord == 0 {
            return cox_de_boor(i, p, u, k);
        }
        if p == 0 {
            return 0.0;
        }
        let mut v = 0.0;
        if k[i + p] > k[i] {
            v += cox_der(i, p - 1, k_ord - 1, u, k) / (k[i + p] - k[i]);
        }
        if k[i + p + 1] > k[i + 1] {
            v -= cox_der(i + 1, p - 1, k_ord - 1, u, k) / (k[i + p + 1] - k[i + 1]);
        }
        p as f64 * v
    }

    #[test]
    fn ders_match_recursive_definition() {
        for p in 1..=4usize {
            // Clamped, with a double interior knot (a C^(p-2) joint) when p >= 2.
            let mut k = vec![0.0; p + 1];
            k.extend([0.7, 1.0]);
            if p >= 2 {
                k.push(1.0);
            }
            k.extend([2.5, 3., 3.2]);
            k.extend(std::iter::repeat_n(4.0, p + 1));
            let k = &k[..];
            let poles = k.len() - p - 1;
            for t in 0..=50 {
                let u = 3.99 * f64::from(t) / 50.0;
                let span = find_span(p, poles, k, u);
                let n = p + 2;
                let mut ders = vec![f64::NAN; (n + 1) * (p + 1)];
                ders_basis_funs(span, u, p, n, k, &mut ders);
                let mut b = [0.0; 8];
                basis_funs(span, u, p, k, &mut b);
                let (mut b1, mut d1) = ([0.0; 8], [0.0; 8]);
                basis_funs_ders1(span, u, p, k, &mut b1, &mut d1);
                for j in 0..=p {
                    assert_eq!(b1[j].to_bits(), b[j].to_bits());
                    let want = ders[p + 1 + j];
                    assert!((d1[j] - want).abs() <= 1e-12 * (1.0 + want.abs()));
                }
                for j in 0..=p {
                    assert_eq!(ders[j].to_bits(), b[j].to_bits());
                    for ord in 0..=n {
                        let want = cox_der(span - p + j, p, ord, u, k);
                        let got = ders[ord * (p + 1) + j];
                        assert!(
                            (got - want).abs() <= 1e-9 * (1.0 + want.abs()),
                            "p={p} u={u} j={j} k={ord}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn high_degree_uses_heap_path() {
        let p = 9;
        let knots: Vec<f64> = (0..2 * p + 2).map(|k| k as f64).collect();
        let u = 9.3;
        let span = find_span(p, p + 1, &knots, u);
        let mut ders = vec![0.0; 12 * (p + 1)];
        ders_basis_funs(span, u, p, 11, &knots, &mut ders);
        // Partition of unity and its derivatives: sum of k-th derivatives is 0 for k >= 1.
        let sum0: f64 = ders[..=p].iter().sum();
        assert!((sum0 - 1.0).abs() < 1e-12);
        for k in 1..=11 {
            let s: f64 = ders[k * (p + 1)..(k + 1) * (p + 1)].iter().sum();
            let scale: f64 = ders[k * (p + 1)..(k + 1) * (p + 1)]
                .iter()
                .map(|v| v.abs())
                .sum();
            assert!(s.abs() <= 1e-10 * scale.max(1.0), "k={k} sum={s}");
        }
        assert!(ders[10 * (p + 1)..].iter().all(|&v| v == 0.0));
        for j in 0..=p {
            let want = cox_der(span - p + j, p, 3, u, &knots);
            assert!((ders[3 * (p + 1) + j] - want).abs() < 1e-9 * (1.0 + want.abs()));
        }
    }
}
