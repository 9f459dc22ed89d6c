//! Entity 510, Face (IGES 5.3 section 4.146).

use super::{Count, DirectoryEntry, Entity, Field, SURFACES, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: SURF, N, OF, then `N` loops.
pub(super) const SCHEMA: Schema = Schema {
    entity: 510,
    name: "Face",
    fields: &[
        Field::one("SURF", Type::Pointer(SURFACES)),
        Field::one("N", Type::Integer),
        Field::one("OF", Type::Flag),
        Field::times("LOOP", Type::Pointer(&[508]), Count::Field("N")),
    ],
};

/// Entity 510, Face.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Face510 {
    /// SURF: the underlying surface.
    pub surface: i64,
    /// OF: 1 when the first loop is the outer one.
    pub outer_first: i64,
    /// LOOP: the 508 loops.
    pub loops: Vec<i64>,
}

impl Entity for Face510 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        Face510 {
            surface: v.int("SURF"),
            outer_first: v.int("OF"),
            loops: v.ints("LOOP"),
        }
    }
}

impl WriteParams for Face510 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(510);
        w.int(self.surface);
        w.int(super::count(self.loops.len()));
        w.int(self.outer_first);
        self.loops.iter().for_each(|&l| w.int(l));
        Ok(())
    }
}
