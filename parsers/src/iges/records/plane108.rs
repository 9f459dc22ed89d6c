//! Entity 108, Plane (IGES 5.3 section 4.12).

use super::{CURVES, DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The declaration: the coefficients `A, B, C, D` of `A x + B y + C z = D`, the bounding
/// curve PTR (0 for the unbounded form 0), the display symbol's location and SIZE.
pub(super) const SCHEMA: Schema = Schema {
    entity: 108,
    name: "Plane",
    fields: &[
        Field::one("A", Type::Real),
        Field::one("B", Type::Real),
        Field::one("C", Type::Real),
        Field::one("D", Type::Real),
        Field::one("PTR", Type::Pointer(CURVES)),
        Field::one("X, Y, Z", Type::Point),
        Field::one("SIZE", Type::Real),
    ],
};

/// Entity 108, Plane: form 0 unbounded, form 1 bounded by the closed curve PTR, form -1
/// a hole bounded by PTR.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane108 {
    /// `A, B, C, D`.
    pub coefficients: [f64; 4],
    /// PTR: the bounding closed curve (0 when unbounded).
    pub boundary: i64,
    /// The display symbol's location.
    pub symbol: [f64; 3],
    /// SIZE: the display symbol's size.
    pub size: f64,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for Plane108 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        let mut r = |n| v.real(n).unwrap_or(0.0);
        let coefficients = [r("A"), r("B"), r("C"), r("D")];
        Plane108 {
            coefficients,
            boundary: v.int("PTR"),
            symbol: v.point("X, Y, Z").unwrap_or([0.0; 3]),
            size: v.real("SIZE").unwrap_or(0.0),
            form: entry.form,
        }
    }
}
