//! Evaluation kernels for the batch paths ([`batch`](super::batch)): a per-knot-vector span
//! lookup that replaces A2.1's binary search, and A2.2 with the degree as a compile-time
//! constant so the basis functions live in registers.
//!
//! Both return exactly what the textbook routines return: [`SpanIndex::find`] the span
//! [`find_span`] (A2.1) gives, [`basis`] the values [`basis_funs`](super::basis::basis_funs)
//! (A2.2) gives, bit for bit (same floating-point operations in the same order). The batch
//! kernels built on them therefore stay bit-identical to `point_at`.

use super::knots::find_span;

/// Buckets per knot span in a [`SpanIndex`]: two, so that for uniform knots the guess is the
/// span itself or its neighbour despite rounding of the bucket position.
const BUCKETS_PER_SPAN: usize = 2;

/// Upper bound on the buckets of a [`SpanIndex`] (32 KiB of `u32`): long knot vectors fall
/// back to a short scan or the binary search, never to a large table.
const MAX_BUCKETS: usize = 1 << 13;

/// Steps of the local scan from the bucket's guess before falling back to A2.1's binary
/// search (clustered knots put many spans in one bucket).
const MAX_SCAN: usize = 6;

/// Span search by lookup (replaces A2.1 FindSpan's binary search in the batch kernels): the
/// domain `[u_p, u_{n+1}]` is cut into equal buckets, each remembering the span of its left
/// edge; a parameter's bucket is one multiplication away, and a short scan from that guess
/// finds the span A2.1 returns. For uniform knots the guess is right or one off; clustered
/// knots fall back to the binary search, so the cost is never above A2.1's by more than the
/// scan.
#[derive(Debug, Clone)]
pub(crate) struct SpanIndex {
    degree: usize,
    poles: usize,
    start: f64,
    end: f64,
    scale: f64,
    /// The span of each bucket's left edge, always in `degree..poles`.
    table: Vec<u32>,
    /// A2.1's span at the domain end (the last non-empty span).
    end_span: usize,
}

impl SpanIndex {
    /// The lookup for a validated knot vector of `poles` poles and degree `degree`.
    pub(crate) fn new(degree: usize, poles: usize, knots: &[f64]) -> Self {
        let (start, end) = (knots[degree], knots[poles]);
        let spans = poles - degree;
        let buckets = spans.saturating_mul(BUCKETS_PER_SPAN).clamp(1, MAX_BUCKETS);
        // A degenerate scale (overflow for a tiny domain) only makes the guess useless: the
        // bucket is clamped and the scan or the binary search still finds the span.
        let scale = buckets as f64 / (end - start);
        let end_span = find_span(degree, poles, knots, end);
        let table = (0..buckets)
            .map(|b| {
                let edge = start + b as f64 / scale;
                let s = if edge >= start && edge < end {
                    find_span(degree, poles, knots, edge)
                } else {
                    end_span
                };
                // Spans index poles, and poles fit u32 in any geometry the model holds;
                // should one not, the guess is the first span and the search corrects it.
                u32::try_from(s).unwrap_or(0)
            })
            .collect();
        SpanIndex {
            degree,
            poles,
            start,
            end,
            scale,
            table,
            end_span,
        }
    }

    /// The span A2.1 ([`find_span`]) returns for `u`, which the caller has checked to lie in
    /// the domain (a NaN or out-of-domain `u` gives some valid span, never a panic).
    #[inline(always)]
    pub(crate) fn find(&self, knots: &[f64], u: f64) -> usize {
        if u >= self.end {
            return self.end_span;
        }
        // `as` saturates (NaN -> 0), and the bucket is clamped: any u gives a table entry.
        let b = ((u - self.start) * self.scale) as usize;
        let guess = self
            .table
            .get(b.min(self.table.len().saturating_sub(1)))
            .map_or(self.degree, |&s| s as usize);
        let mut s = guess.clamp(self.degree, self.poles - 1);
        // For u in [u_p, u_{n+1}) the answer is the unique s in p..=n with
        // u_s <= u < u_{s+1}; the scan keeps s in that range because u_p <= u < u_{n+1}.
        for _ in 0..MAX_SCAN {
            match (knots.get(s), knots.get(s + 1)) {
                (Some(&lo), _) if u < lo && s > self.degree => s -= 1,
                (_, Some(&hi)) if u >= hi && s + 1 < self.poles => s += 1,
                _ => return s,
            }
        }
        find_span(self.degree, self.poles, knots, u)
    }

    /// A2.1's span at the domain end.
    #[inline(always)]
    pub(crate) fn end_span(&self) -> usize {
        self.end_span
    }
}

/// The `N` non-zero basis functions of degree `p = N - 1` at `u` in knot span `span` (A2.2
/// BasisFuns), bit-identical to [`basis_funs`](super::basis::basis_funs): the same
/// operations in the same order, with the degree a constant so the loops unroll and the
/// scratch arrays become registers. `N >= 1`; `span` from A2.1 (so `span >= p` and
/// `span + p < knots.len()`).
#[inline(always)]
pub(crate) fn basis<const N: usize>(span: usize, u: f64, knots: &[f64]) -> [f64; N] {
    let p = N - 1;
    let mut out = [0.0; N];
    out[0] = 1.0;
    if p == 0 {
        return out;
    }
    // knots[span + 1 - j] = k[p - j] and knots[span + j] = k[p - 1 + j] for j in 1..=p.
    let k = &knots[span + 1 - p..span + p + 1];
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    for j in 1..N {
        left[j] = u - k[p - j];
        right[j] = k[p - 1 + j] - u;
    }
    for j in 1..N {
        let mut saved = 0.0;
        for r in 0..j {
            let temp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
    out
}

/// [`basis`] for `L` parameters in the same knot span at once: the A2.2 recurrence runs
/// with every operation applied lane by lane, which the compiler turns into packed SIMD.
/// Each lane performs exactly [`basis`]'s operations in the same order (no fused
/// multiply-add: Rust does not contract), so every lane is bit-identical to [`basis`].
/// Returns `out[k][lane]`.
#[inline(always)]
pub(crate) fn basis_lanes<const N: usize, const L: usize>(
    span: usize,
    us: [f64; L],
    knots: &[f64],
) -> [[f64; L]; N] {
    let p = N - 1;
    let mut out = [[0.0; L]; N];
    out[0] = [1.0; L];
    if p == 0 {
        return out;
    }
    let k = &knots[span + 1 - p..span + p + 1];
    let mut left = [[0.0; L]; N];
    let mut right = [[0.0; L]; N];
    for j in 1..N {
        for l in 0..L {
            left[j][l] = us[l] - k[p - j];
            right[j][l] = k[p - 1 + j] - us[l];
        }
    }
    for j in 1..N {
        let mut saved = [0.0; L];
        for r in 0..j {
            let (rr, ll) = (right[r + 1], left[j - r]);
            for l in 0..L {
                let temp = out[r][l] / (rr[l] + ll[l]);
                out[r][l] = saved[l] + rr[l] * temp;
                saved[l] = ll[l] * temp;
            }
        }
        out[j] = saved;
    }
    out
}

/// [`basis`] for two parameters at once (`u` in span `su` of `ku`, `v` in span `sv` of `kv`,
/// both of degree `N - 1`): the two A2.2 recurrences run side by side as the two lanes of
/// each operation, which the compiler turns into packed SIMD (half the divisions of two
/// calls). Each lane performs exactly [`basis`]'s operations, so both results are
/// bit-identical to A2.2.
#[inline(always)]
pub(crate) fn basis_pair<const N: usize>(
    su: usize,
    u: f64,
    ku: &[f64],
    sv: usize,
    v: f64,
    kv: &[f64],
) -> ([f64; N], [f64; N]) {
    let p = N - 1;
    let mut out = [[1.0, 1.0]; N];
    if p == 0 {
        return ([1.0; N], [1.0; N]);
    }
    let a = &ku[su + 1 - p..su + p + 1];
    let b = &kv[sv + 1 - p..sv + p + 1];
    let mut left = [[0.0; 2]; N];
    let mut right = [[0.0; 2]; N];
    for j in 1..N {
        left[j] = [u - a[p - j], v - b[p - j]];
        right[j] = [a[p - 1 + j] - u, b[p - 1 + j] - v];
    }
    for j in 1..N {
        let mut saved = [0.0; 2];
        for r in 0..j {
            let (o, rr, ll) = (out[r], right[r + 1], left[j - r]);
            let temp = [o[0] / (rr[0] + ll[0]), o[1] / (rr[1] + ll[1])];
            out[r] = [saved[0] + rr[0] * temp[0], saved[1] + rr[1] * temp[1]];
            saved = [ll[0] * temp[0], ll[1] * temp[1]];
        }
        out[j] = saved;
    }
    let mut bu = [0.0; N];
    let mut bv = [0.0; N];
    for (k, o) in out.iter().enumerate() {
        bu[k] = o[0];
        bv[k] = o[1];
    }
    (bu, bv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::basis::basis_funs;

    /// Knot vectors with repeated interior knots, unclamped ends and a cluster.
    fn knot_vectors() -> Vec<(usize, Vec<f64>)> {
        vec![
            (1, vec![0., 0., 1., 2., 3., 3.]),
            (2, vec![0., 0., 0., 1., 2., 2., 3., 4., 4., 4.]),
            (3, (0..12).map(f64::from).collect()),
            (3, vec![0., 1., 2., 3., 4., 4., 5., 6.]),
            (
                3,
                vec![
                    0., 0., 0., 0., 0.001, 0.002, 0.003, 0.004, 0.005, 0.006, 0.5, 0.5, 0.5, 1.,
                    1., 1., 1.,
                ],
            ),
            (5, {
                let mut k = vec![-2.0; 6];
                k.extend([-1.5, -1.5, 0.25, 0.3, 7.0]);
                k.extend([9.0; 6]);
                k
            }),
        ]
    }

    #[test]
    fn span_index_equals_a21_everywhere() {
        for (p, knots) in knot_vectors() {
            let poles = knots.len() - p - 1;
            let idx = SpanIndex::new(p, poles, &knots);
            let (a, b) = (knots[p], knots[poles]);
            let mut us: Vec<f64> = (0..=2000)
                .map(|i| a + (b - a) * f64::from(i) / 2000.0)
                .collect();
            us.extend(knots.iter().copied().filter(|&k| k >= a && k <= b));
            // Neighbours of every knot, one ulp either side.
            for &k in &knots {
                us.push(f64::from_bits(k.to_bits().wrapping_add(1)).clamp(a, b));
                us.push(f64::from_bits(k.to_bits().wrapping_sub(1)).clamp(a, b));
            }
            for u in us {
                assert_eq!(
                    idx.find(&knots, u),
                    find_span(p, poles, &knots, u),
                    "p={p} u={u}"
                );
            }
            // Garbage in, some span out, no panic.
            for u in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, a - 1.0, b + 1.0] {
                let s = idx.find(&knots, u);
                assert!((p..poles).contains(&s));
            }
        }
    }

    #[test]
    fn register_basis_equals_a22_bit_for_bit() {
        fn check<const N: usize>(knots: &[f64]) {
            let p = N - 1;
            let poles = knots.len() - p - 1;
            let (a, b) = (knots[p], knots[poles]);
            for i in 0..=97 {
                let u = a + (b - a) * f64::from(i) / 97.0;
                let s = find_span(p, poles, knots, u);
                let mut want = [0.0; 16];
                basis_funs(s, u, p, knots, &mut want);
                let got = basis::<N>(s, u, knots);
                // The pair kernel, with this parameter in either lane.
                let v = a + (b - a) * f64::from((i * 37) % 98) / 97.0;
                let sv = find_span(p, poles, knots, v);
                let mut want_v = [0.0; 16];
                basis_funs(sv, v, p, knots, &mut want_v);
                let (pu, pv) = basis_pair::<N>(s, u, knots, sv, v, knots);
                for j in 0..N {
                    assert_eq!(got[j].to_bits(), want[j].to_bits(), "p={p} u={u} j={j}");
                    assert_eq!(pu[j].to_bits(), want[j].to_bits(), "pair p={p} u={u} j={j}");
                    assert_eq!(
                        pv[j].to_bits(),
                        want_v[j].to_bits(),
                        "pair p={p} v={v} j={j}"
                    );
                }
            }
        }
        let k: Vec<f64> = (0..40).map(|i| f64::from(i).sqrt()).collect();
        check::<2>(&k);
        check::<3>(&k);
        check::<4>(&k);
        check::<5>(&k);
        check::<6>(&k);
        check::<8>(&k);
        check::<10>(&k);
    }
}
