//! Entity 128, Rational B-Spline Surface (IGES 5.3 section 4.24).

use super::{Count, DirectoryEntry, Entity, Field, Head, Schema, Type, Values, count};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// `K1, K2, M1, M2` checked: `1 <= M1 <= K1`, `1 <= M2 <= K2`, and the parameter count
/// `21 + 5 K1 + 5 K2 + 4 K1 K2 + M1 + M2` fits.
fn counts(h: &Head) -> Result<[usize; 4], String> {
    let k = [h.count("K1")?, h.count("K2")?];
    let m = [h.count("M1")?, h.count("M2")?];
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
    let of = || "128 parameter count overflows".to_owned();
    let poles = (k[0].checked_add(1).ok_or_else(of)?)
        .checked_mul(k[1].checked_add(1).ok_or_else(of)?)
        .ok_or_else(of)?;
    poles
        .checked_mul(4)
        .and_then(|v| v.checked_add(k[0].checked_add(m[0])?))
        .and_then(|v| v.checked_add(k[1].checked_add(m[1])?))
        .and_then(|v| v.checked_add(21))
        .ok_or_else(of)?;
    Ok([k[0], k[1], m[0], m[1]])
}

/// The declaration: parameters 1-9, the u knots `S(-M1)..S(N1+M1)`, the v knots, the
/// weights and control points with the first index fastest, then `U(0), U(1), V(0), V(1)`
/// (optional here).
pub(super) const SCHEMA: Schema = Schema {
    entity: 128,
    name: "Rational B-Spline Surface",
    fields: &[
        Field::one("K1", Type::Integer),
        Field::one("K2", Type::Integer),
        Field::one("M1", Type::Integer),
        Field::one("M2", Type::Integer),
        Field::one("PROP1", Type::Flag),
        Field::one("PROP2", Type::Flag),
        Field::one("PROP3", Type::Flag),
        Field::one("PROP4", Type::Flag),
        Field::one("PROP5", Type::Flag),
        Field::times(
            "S knot",
            Type::Real,
            Count::Formula {
                formula: "K1 + M1 + 2",
                of: |h| counts(h).map(|[k1, _, m1, _]| k1 + m1 + 2),
            },
        ),
        Field::times(
            "T knot",
            Type::Real,
            Count::Formula {
                formula: "K2 + M2 + 2",
                of: |h| counts(h).map(|[_, k2, _, m2]| k2 + m2 + 2),
            },
        ),
        Field::times(
            "weight",
            Type::Real,
            Count::Formula {
                formula: "(K1 + 1)(K2 + 1)",
                of: |h| counts(h).map(|[k1, k2, _, _]| (k1 + 1) * (k2 + 1)),
            },
        ),
        Field::times(
            "X, Y, Z",
            Type::Point,
            Count::Formula {
                formula: "(K1 + 1)(K2 + 1)",
                of: |h| counts(h).map(|[k1, k2, _, _]| (k1 + 1) * (k2 + 1)),
            },
        ),
        Field::optional("U(0)", Type::Real),
        Field::optional("U(1)", Type::Real),
        Field::optional("V(0)", Type::Real),
        Field::optional("V(1)", Type::Real),
    ],
};

/// Entity 128, Rational B-Spline Surface (IGES 5.3 section 4.24).
///
/// Weights and control points are kept in the file's order, the **first index fastest**:
/// `W(0,0), W(1,0), .., W(K1,0), W(0,1), ..`; [`Surface128::index`] maps `(i, j)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface128 {
    /// `M1`, `M2`.
    pub degree: [usize; 2],
    /// `K1 + 1`, `K2 + 1`: control points along u and v.
    pub poles: [usize; 2],
    /// PROP1, PROP2: closed in u, in v.
    pub closed: [i64; 2],
    /// PROP3: 1 = polynomial.
    pub polynomial: i64,
    /// PROP4, PROP5: periodic in u, in v.
    pub periodic: [i64; 2],
    /// u knots `S(-M1)..S(N1+M1)`.
    pub knots_u: Vec<f64>,
    /// v knots `T(-M2)..T(N2+M2)`.
    pub knots_v: Vec<f64>,
    /// Weights, first index fastest.
    pub weights: Vec<f64>,
    /// Control points, first index fastest.
    pub points: Vec<[f64; 3]>,
    /// `U(0), U(1), V(0), V(1)` when all four are present.
    pub range: Option<[f64; 4]>,
    /// Parameters after the full record.
    pub extra: usize,
}

impl Surface128 {
    /// Position of pole `(i, j)` (i along u) in [`Surface128::points`] / `weights`.
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.poles[0] + i
    }
}

impl Entity for Surface128 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        // The count check accepted K1, K2, M1, M2 as counts.
        let mut count = |name| usize::try_from(v.int(name)).unwrap_or(0);
        let k = [count("K1"), count("K2")];
        let degree = [count("M1"), count("M2")];
        let range = match (
            v.real("U(0)"),
            v.real("U(1)"),
            v.real("V(0)"),
            v.real("V(1)"),
        ) {
            (Some(a), Some(b), Some(c), Some(d)) => Some([a, b, c, d]),
            _ => None,
        };
        Surface128 {
            degree,
            poles: [k[0] + 1, k[1] + 1],
            closed: [v.int("PROP1"), v.int("PROP2")],
            polynomial: v.int("PROP3"),
            periodic: [v.int("PROP4"), v.int("PROP5")],
            knots_u: v.reals("S knot"),
            knots_v: v.reals("T knot"),
            weights: v.reals("weight"),
            points: v.points("X, Y, Z"),
            range,
            extra: v.extra,
        }
    }
}

impl WriteParams for Surface128 {
    /// The parameters in the declaration's order; the range is written when present.
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(128);
        w.int(count(self.poles[0]) - 1);
        w.int(count(self.poles[1]) - 1);
        w.int(count(self.degree[0]));
        w.int(count(self.degree[1]));
        for f in [
            self.closed[0],
            self.closed[1],
            self.polynomial,
            self.periodic[0],
            self.periodic[1],
        ] {
            w.int(f);
        }
        for &x in self
            .knots_u
            .iter()
            .chain(&self.knots_v)
            .chain(&self.weights)
        {
            w.real(x)?;
        }
        for &x in self.points.iter().flatten() {
            w.real(x)?;
        }
        if let Some(r) = self.range {
            for x in r {
                w.real(x)?;
            }
        }
        Ok(())
    }
}
