//! Entity 110, Line (IGES 5.3 section 4.13).

use super::{DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: the start point `X1, Y1, Z1` and the terminate point `X2, Y2, Z2`.
pub(super) const SCHEMA: Schema = Schema {
    entity: 110,
    name: "Line",
    fields: &[
        Field::one("X1, Y1, Z1", Type::Point),
        Field::one("X2, Y2, Z2", Type::Point),
    ],
};

/// Entity 110, Line: `P(t) = P1 + t (P2 - P1)`, `t` in `[0, 1]` (form 0, a segment),
/// `[0, inf)` (form 1, a ray) or all reals (form 2, a line).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line110 {
    /// `P1`.
    pub start: [f64; 3],
    /// `P2`.
    pub end: [f64; 3],
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for Line110 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        Line110 {
            start: v.point("X1, Y1, Z1").unwrap_or([0.0; 3]),
            end: v.point("X2, Y2, Z2").unwrap_or([0.0; 3]),
            form: entry.form,
        }
    }
}
