//! Entity 112, Parametric Spline Curve (IGES 5.3 section 4.14).

use super::{Count, DirectoryEntry, Entity, Field, Head, Schema, Type, Values};

/// `N` checked: at least one segment, and the parameter count `N + 1 + 12 N + 12` fits.
fn segments(h: &Head) -> Result<usize, String> {
    let n = h.count("N")?;
    if n == 0 {
        return Err("N = 0 segments; IGES 5.3 requires N >= 1".to_owned());
    }
    n.checked_mul(13)
        .and_then(|v| v.checked_add(13))
        .ok_or_else(|| "112 parameter count overflows".to_owned())?;
    Ok(n)
}

/// The declaration: CTYPE, H, NDIM, N, the `N + 1` break points `T(1)..T(N+1)`, per
/// segment the twelve coefficients `AX, BX, CX, DX, AY, .., DY, AZ, .., DZ`, then the
/// twelve values at the terminate point `TPX0..TPX3, TPY0..TPY3, TPZ0..TPZ3`.
pub(super) const SCHEMA: Schema = Schema {
    entity: 112,
    name: "Parametric Spline Curve",
    fields: &[
        Field::one("CTYPE", Type::Flag),
        Field::one("H", Type::Flag),
        Field::one("NDIM", Type::Flag),
        Field::one("N", Type::Integer),
        Field::times(
            "T",
            Type::Real,
            Count::Formula {
                formula: "N + 1",
                of: |h| segments(h).map(|n| n + 1),
            },
        ),
        Field::times(
            "coefficients",
            Type::Real,
            Count::Formula {
                formula: "12 N",
                of: |h| segments(h).map(|n| 12 * n),
            },
        ),
        Field::times(
            "terminate point",
            Type::Real,
            Count::Formula {
                formula: "12",
                of: |_| Ok(12),
            },
        ),
    ],
};

/// Entity 112, Parametric Spline Curve: on segment `i`, with `s = u - T(i)`,
/// `X(u) = AX + BX s + CX s^2 + DX s^3` (and Y, Z alike).
#[derive(Debug, Clone, PartialEq)]
pub struct SplineCurve112 {
    /// CTYPE: 1 linear, 2 quadratic, 3 cubic, 4 Wilson-Fowler, 5 modified Wilson-Fowler,
    /// 6 B-spline.
    pub ctype: i64,
    /// H: the degree of continuity with respect to arc length.
    pub continuity: i64,
    /// NDIM: 2 (planar) or 3.
    pub ndim: i64,
    /// `T(1)..T(N+1)`.
    pub breakpoints: Vec<f64>,
    /// Per segment `[[AX, BX, CX, DX], [AY, ..], [AZ, ..]]`.
    pub segments: Vec<[[f64; 4]; 3]>,
    /// `[[TPX0..TPX3], [TPY0..], [TPZ0..]]`: value, first derivative, second derivative / 2!
    /// and third / 3! at `T(N+1)`.
    pub terminate: [[f64; 4]; 3],
}

/// Twelve reals as three rows of four.
pub(super) fn rows(c: &[f64]) -> [[f64; 4]; 3] {
    let mut out = [[0.0; 4]; 3];
    for (k, &x) in c.iter().take(12).enumerate() {
        out[k / 4][k % 4] = x;
    }
    out
}

impl Entity for SplineCurve112 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        SplineCurve112 {
            ctype: v.int("CTYPE"),
            continuity: v.int("H"),
            ndim: v.int("NDIM"),
            breakpoints: v.reals("T"),
            segments: v.reals("coefficients").chunks_exact(12).map(rows).collect(),
            terminate: rows(&v.reals("terminate point")),
        }
    }
}
