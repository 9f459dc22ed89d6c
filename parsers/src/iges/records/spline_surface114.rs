//! Entity 114, Parametric Spline Surface (IGES 5.3 section 4.15).

use super::{Count, DirectoryEntry, Entity, Field, Head, Schema, Type, Values};

/// `M` and `N` checked: at least one segment each, and the parameter count fits.
fn segments(h: &Head) -> Result<(usize, usize), String> {
    let (m, n) = (h.count("M")?, h.count("N")?);
    if m == 0 || n == 0 {
        return Err(format!(
            "M = {m}, N = {n} segments; IGES 5.3 requires M, N >= 1"
        ));
    }
    m.checked_add(1)
        .and_then(|a| a.checked_mul(n.checked_add(1)?))
        .and_then(|a| a.checked_mul(48))
        .ok_or_else(|| "114 parameter count overflows".to_owned())?;
    Ok((m, n))
}

/// The declaration: CTYPE, PTYPE, M, N, the break points `TU(1)..TU(M+1)` and
/// `TV(1)..TV(N+1)`, then for `i = 1..M` the patches `(i, 1)..(i, N)` of 48 coefficients
/// each (16 for X, Y, Z) followed by 48 arbitrary values (the patch `(i, N+1)`). The
/// standard then lists `48 (N + 1)` more arbitrary values (the row `M + 1`), declared
/// optional as some writers leave them out.
pub(super) const SCHEMA: Schema = Schema {
    entity: 114,
    name: "Parametric Spline Surface",
    fields: &[
        Field::one("CTYPE", Type::Flag),
        Field::one("PTYPE", Type::Flag),
        Field::one("M", Type::Integer),
        Field::one("N", Type::Integer),
        Field::times(
            "TU",
            Type::Real,
            Count::Formula {
                formula: "M + 1",
                of: |h| segments(h).map(|(m, _)| m + 1),
            },
        ),
        Field::times(
            "TV",
            Type::Real,
            Count::Formula {
                formula: "N + 1",
                of: |h| segments(h).map(|(_, n)| n + 1),
            },
        ),
        Field::times(
            "coefficients",
            Type::Real,
            Count::Formula {
                formula: "48 M (N + 1)",
                of: |h| segments(h).map(|(m, n)| 48 * m * (n + 1)),
            },
        ),
        Field::optional_times(
            "arbitrary row M + 1",
            Type::Real,
            Count::Formula {
                formula: "48 (N + 1)",
                of: |h| segments(h).map(|(_, n)| 48 * (n + 1)),
            },
        ),
    ],
};

/// Entity 114, Parametric Spline Surface: on patch `(i, j)`, with `s = u - TU(i)` and
/// `t = v - TV(j)`, `X(u, v) = sum over a, b in 0..4 of c[4 b + a] s^a t^b` where `c` is
/// the patch's `AX, BX, CX, DX, EX, FX, GX, HX, KX, LX, MX, NX, PX, QX, RX, SX`.
#[derive(Debug, Clone, PartialEq)]
pub struct SplineSurface114 {
    /// CTYPE: the boundary type (1 linear .. 6 B-spline).
    pub ctype: i64,
    /// PTYPE: 0 unspecified, 1 Cartesian product.
    pub ptype: i64,
    /// `TU(1)..TU(M+1)`.
    pub breakpoints_u: Vec<f64>,
    /// `TV(1)..TV(N+1)`.
    pub breakpoints_v: Vec<f64>,
    /// Patch `(i, j)` (0-based) at `i * N + j`: the 16 coefficients of X, Y and Z.
    pub patches: Vec<[[f64; 16]; 3]>,
}

impl Entity for SplineSurface114 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        let tu = v.reals("TU");
        let tv = v.reals("TV");
        let n = tv.len().saturating_sub(1);
        let data = v.reals("coefficients");
        let mut patches = Vec::with_capacity(data.len() / 48);
        // Rows of N + 1 patches; the last of each row is the arbitrary one.
        for row in data.chunks_exact(48 * (n + 1)) {
            for p in row.chunks_exact(48).take(n) {
                let mut c = [[0.0; 16]; 3];
                for (k, &x) in p.iter().enumerate() {
                    c[k / 16][k % 16] = x;
                }
                patches.push(c);
            }
        }
        SplineSurface114 {
            ctype: v.int("CTYPE"),
            ptype: v.int("PTYPE"),
            breakpoints_u: tu,
            breakpoints_v: tv,
            patches,
        }
    }
}
