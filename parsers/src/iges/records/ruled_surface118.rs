//! Entity 118, Ruled Surface (IGES 5.3 section 4.17).

use super::{CURVES, DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: the two curves DE1, DE2, DIRFLG and DEVFLG.
pub(super) const SCHEMA: Schema = Schema {
    entity: 118,
    name: "Ruled Surface",
    fields: &[
        Field::one("DE1", Type::Pointer(CURVES)),
        Field::one("DE2", Type::Pointer(CURVES)),
        Field::one("DIRFLG", Type::Flag),
        Field::one("DEVFLG", Type::Flag),
    ],
};

/// Entity 118, Ruled Surface: lines joining points of equal relative arc length (form 0)
/// or of equal relative parameter value (form 1) of the two curves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RuledSurface118 {
    /// DE1: the first curve.
    pub first: i64,
    /// DE2: the second curve.
    pub second: i64,
    /// DIRFLG: 0 joins first to first and last to last, 1 first to last.
    pub reversed: i64,
    /// DEVFLG: 1 developable, 0 possibly not.
    pub developable: i64,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for RuledSurface118 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        RuledSurface118 {
            first: v.int("DE1"),
            second: v.int("DE2"),
            reversed: v.int("DIRFLG"),
            developable: v.int("DEVFLG"),
            form: entry.form,
        }
    }
}
