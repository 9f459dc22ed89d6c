//! Entity 126, Rational B-Spline Curve (IGES 5.3 section 4.23).

use super::{Count, DirectoryEntry, Entity, Field, Head, Schema, Type, Values, count};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// `K` and `M` checked: `1 <= M <= K`, and the parameter count `17 + 5K + M` fits.
fn k_m(h: &Head) -> Result<(usize, usize), String> {
    let (k, m) = (h.count("K")?, h.count("M")?);
    if m == 0 || m > k {
        return Err(format!("degree M = {m} must satisfy 1 <= M <= K = {k}"));
    }
    k.checked_mul(5)
        .and_then(|v| v.checked_add(m))
        .and_then(|v| v.checked_add(17))
        .ok_or_else(|| "126 parameter count overflows".to_owned())?;
    Ok((k, m))
}

/// The declaration: parameters 1-6, then `A + 1 = K + M + 2` knots `T(-M)..T(N+M)`,
/// `K + 1` weights, `K + 1` control points, `V(0)`, `V(1)` and the unit normal (the last
/// three optional here: some writers end the record early).
pub(super) const SCHEMA: Schema = Schema {
    entity: 126,
    name: "Rational B-Spline Curve",
    fields: &[
        Field::one("K", Type::Integer),
        Field::one("M", Type::Integer),
        Field::one("PROP1", Type::Flag),
        Field::one("PROP2", Type::Flag),
        Field::one("PROP3", Type::Flag),
        Field::one("PROP4", Type::Flag),
        Field::times(
            "knot",
            Type::Real,
            Count::Formula {
                formula: "K + M + 2",
                of: |h| k_m(h).map(|(k, m)| k + m + 2),
            },
        ),
        Field::times(
            "weight",
            Type::Real,
            Count::Formula {
                formula: "K + 1",
                of: |h| k_m(h).map(|(k, _)| k + 1),
            },
        ),
        Field::times(
            "X, Y, Z",
            Type::Point,
            Count::Formula {
                formula: "K + 1",
                of: |h| k_m(h).map(|(k, _)| k + 1),
            },
        ),
        Field::optional("V(0)", Type::Real),
        Field::optional("V(1)", Type::Real),
        Field::optional("XNORM, YNORM, ZNORM", Type::Point),
    ],
};

/// Entity 126, Rational B-Spline Curve (IGES 5.3 section 4.23).
///
/// | index | name | meaning |
/// |---|---|---|
/// | 1 | K | upper index of the sum |
/// | 2 | M | degree |
/// | 3-6 | PROP1-4 | planar, closed, polynomial, periodic (0/1) |
/// | 7.. | T(-M)..T(N+M) | `K+M+2` knots |
/// | .. | W(0)..W(K) | weights |
/// | .. | X0,Y0,Z0..ZK | control points |
/// | .. | V(0), V(1) | parameter range (optional here) |
/// | .. | XNORM,YNORM,ZNORM | unit normal if planar (optional here) |
///
/// The PROP flags are kept as written (0/1 per the spec; other values are kept for the
/// exchange layer to report).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve126 {
    /// Degree `M`.
    pub degree: usize,
    /// PROP1: 1 = planar.
    pub planar: i64,
    /// PROP2: 1 = closed.
    pub closed: i64,
    /// PROP3: 1 = polynomial, 0 = rational.
    pub polynomial: i64,
    /// PROP4: 1 = periodic.
    pub periodic: i64,
    /// `K + M + 2` knots `T(-M)..T(K+1)`.
    pub knots: Vec<f64>,
    /// `K + 1` weights.
    pub weights: Vec<f64>,
    /// `K + 1` control points (Euclidean).
    pub points: Vec<[f64; 3]>,
    /// `V(0)`, absent when the record ends before it.
    pub v0: Option<f64>,
    /// `V(1)`.
    pub v1: Option<f64>,
    /// The unit normal, absent when the record ends before it.
    pub normal: Option<[f64; 3]>,
    /// Parameters after the full record (the associativity and property pointer groups
    /// with their counts).
    pub extra: usize,
}

impl Entity for Curve126 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        Curve126 {
            // The count check accepted M as a count.
            degree: usize::try_from(v.int("M")).unwrap_or(0),
            planar: v.int("PROP1"),
            closed: v.int("PROP2"),
            polynomial: v.int("PROP3"),
            periodic: v.int("PROP4"),
            knots: v.reals("knot"),
            weights: v.reals("weight"),
            points: v.points("X, Y, Z"),
            v0: v.real("V(0)"),
            v1: v.real("V(1)"),
            normal: v.point("XNORM, YNORM, ZNORM"),
            extra: v.extra,
        }
    }
}

impl WriteParams for Curve126 {
    /// The parameters in the declaration's order; `V(0), V(1)` and the normal are written when
    /// present (a missing range or normal ends the record early).
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(126);
        w.int(count(self.points.len().saturating_sub(1)));
        w.int(count(self.degree));
        for f in [self.planar, self.closed, self.polynomial, self.periodic] {
            w.int(f);
        }
        for &x in self.knots.iter().chain(&self.weights) {
            w.real(x)?;
        }
        for &x in self.points.iter().flatten() {
            w.real(x)?;
        }
        if let (Some(a), Some(b)) = (self.v0, self.v1) {
            w.real(a)?;
            w.real(b)?;
            if let Some(n) = self.normal {
                for x in n {
                    w.real(x)?;
                }
            }
        }
        Ok(())
    }
}
