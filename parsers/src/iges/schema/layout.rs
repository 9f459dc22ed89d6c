//! Parameter-slot arithmetic for entities 126 and 128, in one place (spec.md b.1, b.2).
//!
//! Indices are 1-based as in the IGES 5.3 tables (index 0 is the entity type number), so
//! `CurveLayout::knots` is 7 for every curve. All arithmetic is checked: a hostile
//! `K = 2^31 - 1` gives an error here, before anything is allocated.

/// Slots of a 126 Rational B-Spline Curve (IGES 5.3 section 4.23).
///
/// With `N = 1 + K - M` and `A = N + 2M`:
/// knots `T(-M)..T(N+M)` at `7..=7+A` (`K+M+2` values), weights at `8+A..=8+A+K`,
/// control points at `9+A+K..=11+A+4K`, `V(0)` at `12+A+4K`, `V(1)` at `13+A+4K`,
/// the normal at `14+A+4K..=16+A+4K`. Parameter count after the type: `17 + 5K + M`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurveLayout {
    /// `K`: upper index of the sum (`K + 1` control points).
    pub k: usize,
    /// `M`: degree.
    pub m: usize,
    /// `A = N + 2M = K + M + 1`.
    pub a: usize,
    /// Index of the first knot `T(-M)` (always 7).
    pub knots: usize,
    /// Number of knots, `K + M + 2`.
    pub knot_count: usize,
    /// Index of `W(0)`.
    pub weights: usize,
    /// Number of control points, `K + 1`.
    pub poles: usize,
    /// Index of `X0`.
    pub points: usize,
    /// Index of `V(0)` (`V(1)` follows).
    pub v0: usize,
    /// Index of `XNORM` (`YNORM`, `ZNORM` follow).
    pub normal: usize,
    /// Last index that must be present (`ZK`, the last control point coordinate).
    pub required: usize,
    /// Last index of the full record (`ZNORM`), `17 + 5K + M`.
    pub full: usize,
}

/// Slots of a 128 Rational B-Spline Surface (IGES 5.3 section 4.24).
///
/// With `N1 = 1 + K1 - M1`, `N2 = 1 + K2 - M2`, `A = N1 + 2 M1`, `B = N2 + 2 M2`,
/// `C = (1 + K1)(1 + K2)`: S knots at `10..=10+A`, T knots at `11+A..=11+A+B`, weights
/// `W(0,0), W(1,0), ..` (first index fastest) at `12+A+B..=11+A+B+C`, control points at
/// `12+A+B+C..=11+A+B+4C`, then `U(0), U(1), V(0), V(1)` at `12+A+B+4C..=15+A+B+4C`.
/// Parameter count after the type: `21 + 5 K1 + 5 K2 + 4 K1 K2 + M1 + M2`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SurfaceLayout {
    /// `K1`, `K2`: upper indices in u and v.
    pub k: [usize; 2],
    /// `M1`, `M2`: degrees in u and v.
    pub m: [usize; 2],
    /// Index of the first u knot `S(-M1)` (always 10).
    pub knots_u: usize,
    /// Index of the first v knot `T(-M2)`.
    pub knots_v: usize,
    /// Knot counts `K1 + M1 + 2`, `K2 + M2 + 2`.
    pub knot_count: [usize; 2],
    /// Number of control points in each direction `K1 + 1`, `K2 + 1`.
    pub poles: [usize; 2],
    /// Index of `W(0,0)`.
    pub weights: usize,
    /// Index of `X(0,0)`.
    pub points: usize,
    /// Index of `U(0)` (`U(1)`, `V(0)`, `V(1)` follow).
    pub range: usize,
    /// Last index that must be present (last control point coordinate).
    pub required: usize,
    /// Last index of the full record (`V(1)`).
    pub full: usize,
}

fn to_usize(v: i64, what: &str) -> Result<usize, String> {
    usize::try_from(v).map_err(|_| format!("{what} = {v} is negative"))
}

fn overflow(what: &str) -> String {
    format!("{what} overflows")
}

impl CurveLayout {
    /// The layout for upper index `k` and degree `m`; requires `1 <= m <= k`.
    pub fn new(k: i64, m: i64) -> Result<Self, String> {
        let ku = to_usize(k, "K")?;
        let mu = to_usize(m, "M")?;
        if mu == 0 || mu > ku {
            return Err(format!("degree M = {m} must satisfy 1 <= M <= K = {k}"));
        }
        let of = || overflow("126 parameter count");
        let a = ku
            .checked_add(mu)
            .and_then(|v| v.checked_add(1))
            .ok_or_else(of)?;
        let knots = 7;
        let weights = a.checked_add(8).ok_or_else(of)?;
        let points = weights
            .checked_add(ku)
            .and_then(|v| v.checked_add(1))
            .ok_or_else(of)?;
        let four_k = ku.checked_mul(4).ok_or_else(of)?;
        let required = a
            .checked_add(11)
            .and_then(|v| v.checked_add(four_k))
            .ok_or_else(of)?;
        Ok(CurveLayout {
            k: ku,
            m: mu,
            a,
            knots,
            knot_count: a + 1,
            weights,
            poles: ku + 1,
            points,
            v0: required + 1,
            normal: required + 3,
            required,
            full: required.checked_add(5).ok_or_else(of)?,
        })
    }
}

impl SurfaceLayout {
    /// The layout for upper indices `k1`, `k2` and degrees `m1`, `m2`; requires
    /// `1 <= m1 <= k1` and `1 <= m2 <= k2`.
    pub fn new(k1: i64, k2: i64, m1: i64, m2: i64) -> Result<Self, String> {
        let k = [to_usize(k1, "K1")?, to_usize(k2, "K2")?];
        let m = [to_usize(m1, "M1")?, to_usize(m2, "M2")?];
        for d in 0..2 {
            if m[d] == 0 || m[d] > k[d] {
                return Err(format!(
                    "degree M{} = {} must satisfy 1 <= M{} <= K{} = {}",
                    d + 1,
                    m[d],
                    d + 1,
                    d + 1,
                    k[d]
                ));
            }
        }
        let of = || overflow("128 parameter count");
        let a = k[0]
            .checked_add(m[0])
            .and_then(|v| v.checked_add(1))
            .ok_or_else(of)?;
        let b = k[1]
            .checked_add(m[1])
            .and_then(|v| v.checked_add(1))
            .ok_or_else(of)?;
        let poles = [
            k[0].checked_add(1).ok_or_else(of)?,
            k[1].checked_add(1).ok_or_else(of)?,
        ];
        let c = poles[0].checked_mul(poles[1]).ok_or_else(of)?;
        let knots_u = 10;
        let knots_v = a.checked_add(11).ok_or_else(of)?;
        let weights = knots_v
            .checked_add(b)
            .and_then(|v| v.checked_add(1))
            .ok_or_else(of)?;
        let points = weights.checked_add(c).ok_or_else(of)?;
        let three_c = c.checked_mul(3).ok_or_else(of)?;
        let range = points.checked_add(three_c).ok_or_else(of)?;
        Ok(SurfaceLayout {
            k,
            m,
            knots_u,
            knots_v,
            knot_count: [a + 1, b + 1],
            poles,
            weights,
            points,
            range,
            required: range - 1,
            full: range.checked_add(3).ok_or_else(of)?,
        })
    }

    /// Number of control points `(K1 + 1)(K2 + 1)`.
    pub fn pole_count(&self) -> usize {
        self.poles[0] * self.poles[1]
    }

    /// Position of pole `(i, j)` in the file's order (first index fastest): `j (K1+1) + i`.
    pub fn file_index(&self, i: usize, j: usize) -> usize {
        j * self.poles[0] + i
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curve_matches_spec_formulas() {
        for (k, m) in [(1, 1), (3, 3), (6, 2), (10, 5)] {
            let l = CurveLayout::new(k, m).unwrap();
            let (k, m) = (usize::try_from(k).unwrap(), usize::try_from(m).unwrap());
            let n = 1 + k - m;
            let a = n + 2 * m;
            assert_eq!(l.knots, 7);
            assert_eq!(l.weights, 8 + a);
            assert_eq!(l.points, 9 + a + k);
            assert_eq!(l.required, 11 + a + 4 * k);
            assert_eq!(l.v0, 12 + a + 4 * k);
            assert_eq!(l.normal, 14 + a + 4 * k);
            assert_eq!(l.full, 17 + 5 * k + m);
            assert_eq!(l.knot_count, k + m + 2);
        }
    }

    #[test]
    fn surface_matches_spec_formulas() {
        for (k1, k2, m1, m2) in [(3, 2, 2, 1), (1, 1, 1, 1), (5, 7, 3, 2)] {
            let l = SurfaceLayout::new(k1, k2, m1, m2).unwrap();
            let [k1, k2, m1, m2] = [k1, k2, m1, m2].map(|x| usize::try_from(x).unwrap());
            assert_eq!(l.full, 21 + 5 * k1 + 5 * k2 + 4 * k1 * k2 + m1 + m2);
            assert_eq!(l.knots_v, 10 + k1 + m1 + 2);
            assert_eq!(l.weights, l.knots_v + k2 + m2 + 2);
        }
    }

    #[test]
    fn hostile_counts_are_errors() {
        assert!(CurveLayout::new(i64::MAX, 3).is_err());
        assert!(CurveLayout::new(-1, 1).is_err());
        assert!(CurveLayout::new(2, 3).is_err());
        assert!(SurfaceLayout::new(i64::MAX, i64::MAX, 1, 1).is_err());
        // 2^31 - 1 is representable: the layout exists, the record check refuses it.
        assert!(CurveLayout::new((1 << 31) - 1, 3).is_ok());
    }
}
