//! Entity 122, Tabulated Cylinder (IGES 5.3 section 4.19).

use super::{CURVES, DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: the directrix DE, then the terminate point `LX, LY, LZ` of the
/// generatrix.
pub(super) const SCHEMA: Schema = Schema {
    entity: 122,
    name: "Tabulated Cylinder",
    fields: &[
        Field::one("DE", Type::Pointer(CURVES)),
        Field::one("LX, LY, LZ", Type::Point),
    ],
};

/// Entity 122, Tabulated Cylinder: the directrix swept along the line from its start
/// point to `L`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TabulatedCylinder122 {
    /// DE: the directrix.
    pub directrix: i64,
    /// `LX, LY, LZ`: the generatrix's terminate point.
    pub end: [f64; 3],
}

impl Entity for TabulatedCylinder122 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        TabulatedCylinder122 {
            directrix: v.int("DE"),
            end: v.point("LX, LY, LZ").unwrap_or([0.0; 3]),
        }
    }
}
