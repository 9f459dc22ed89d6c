//! Entity 104, Conic Arc (IGES 5.3 section 4.5).

use super::{DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: the coefficients `A..F` of `A x^2 + B x y + C y^2 + D x + E y + F = 0`,
/// ZT, the start `X1, Y1` and the terminate point `X2, Y2` (definition space).
pub(super) const SCHEMA: Schema = Schema {
    entity: 104,
    name: "Conic Arc",
    fields: &[
        Field::one("A", Type::Real),
        Field::one("B", Type::Real),
        Field::one("C", Type::Real),
        Field::one("D", Type::Real),
        Field::one("E", Type::Real),
        Field::one("F", Type::Real),
        Field::one("ZT", Type::Real),
        Field::one("X1", Type::Real),
        Field::one("Y1", Type::Real),
        Field::one("X2", Type::Real),
        Field::one("Y2", Type::Real),
    ],
};

/// Entity 104, Conic Arc. The form number (1 ellipse, 2 hyperbola, 3 parabola) is DE
/// field 15; the coefficients decide the type (checked by the consumer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConicArc104 {
    /// `A, B, C, D, E, F`.
    pub coefficients: [f64; 6],
    /// ZT: the plane `z = ZT` of the definition space.
    pub zt: f64,
    /// `X1, Y1`: the start point.
    pub start: [f64; 2],
    /// `X2, Y2`: the terminate point.
    pub end: [f64; 2],
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for ConicArc104 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        let mut r = |n| v.real(n).unwrap_or(0.0);
        ConicArc104 {
            coefficients: [r("A"), r("B"), r("C"), r("D"), r("E"), r("F")],
            zt: r("ZT"),
            start: [r("X1"), r("Y1")],
            end: [r("X2"), r("Y2")],
            form: entry.form,
        }
    }
}
