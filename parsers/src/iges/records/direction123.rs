//! Entity 123, Direction (IGES 5.3 section 4.20).

use super::{DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: `X, Y, Z` (not all zero).
pub(super) const SCHEMA: Schema = Schema {
    entity: 123,
    name: "Direction",
    fields: &[Field::one("X, Y, Z", Type::Point)],
};

/// Entity 123, Direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction123 {
    /// `X, Y, Z`.
    pub direction: [f64; 3],
}

impl Entity for Direction123 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        Direction123 {
            direction: v.point("X, Y, Z").unwrap_or([0.0; 3]),
        }
    }
}
