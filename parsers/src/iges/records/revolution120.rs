//! Entity 120, Surface of Revolution (IGES 5.3 section 4.18).

use super::{CURVES, DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: the axis L (a 110 line), the generatrix C, the start and terminate
/// angles SA, TA (radians).
pub(super) const SCHEMA: Schema = Schema {
    entity: 120,
    name: "Surface of Revolution",
    fields: &[
        Field::one("L", Type::Pointer(&[110])),
        Field::one("C", Type::Pointer(CURVES)),
        Field::one("SA", Type::Real),
        Field::one("TA", Type::Real),
    ],
};

/// Entity 120, Surface of Revolution: the generatrix rotated about the axis line (right-hand
/// rule about the direction from its start to its end point) from SA to TA.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Revolution120 {
    /// L: the axis (a 110).
    pub axis: i64,
    /// C: the generatrix.
    pub generatrix: i64,
    /// SA, TA: start and terminate angles in radians.
    pub angles: [f64; 2],
}

impl Entity for Revolution120 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        Revolution120 {
            axis: v.int("L"),
            generatrix: v.int("C"),
            angles: [v.real("SA").unwrap_or(0.0), v.real("TA").unwrap_or(0.0)],
        }
    }
}
