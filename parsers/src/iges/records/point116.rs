//! Entity 116, Point (IGES 5.3 section 4.16), as the location of an analytic surface.

use super::{DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: `X, Y, Z` and the display symbol PTR.
pub(super) const SCHEMA: Schema = Schema {
    entity: 116,
    name: "Point",
    fields: &[
        Field::one("X, Y, Z", Type::Point),
        Field::optional("PTR", Type::Pointer(&[308])),
    ],
};

/// Entity 116, Point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point116 {
    /// `X, Y, Z`.
    pub point: [f64; 3],
}

impl Entity for Point116 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        Point116 {
            point: v.point("X, Y, Z").unwrap_or([0.0; 3]),
        }
    }
}
