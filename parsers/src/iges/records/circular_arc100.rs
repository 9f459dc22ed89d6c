//! Entity 100, Circular Arc (IGES 5.3 section 4.3).

use super::{DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: ZT, the centre `X1, Y1`, the start `X2, Y2` and the terminate point
/// `X3, Y3`, all in the definition space (the plane `z = ZT`).
pub(super) const SCHEMA: Schema = Schema {
    entity: 100,
    name: "Circular Arc",
    fields: &[
        Field::one("ZT", Type::Real),
        Field::one("X1", Type::Real),
        Field::one("Y1", Type::Real),
        Field::one("X2", Type::Real),
        Field::one("Y2", Type::Real),
        Field::one("X3", Type::Real),
        Field::one("Y3", Type::Real),
    ],
};

/// Entity 100, Circular Arc: counterclockwise (about the definition space's `+z`) from the
/// start point to the terminate point; equal points make a full circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircularArc100 {
    /// ZT: the plane `z = ZT` of the definition space.
    pub zt: f64,
    /// `X1, Y1`: the centre.
    pub centre: [f64; 2],
    /// `X2, Y2`: the start point.
    pub start: [f64; 2],
    /// `X3, Y3`: the terminate point.
    pub end: [f64; 2],
}

impl Entity for CircularArc100 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        let mut r = |n| v.real(n).unwrap_or(0.0);
        CircularArc100 {
            zt: r("ZT"),
            centre: [r("X1"), r("Y1")],
            start: [r("X2"), r("Y2")],
            end: [r("X3"), r("Y3")],
        }
    }
}
