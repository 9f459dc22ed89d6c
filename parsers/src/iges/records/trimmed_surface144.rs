//! Entity 144, Trimmed (Parametric) Surface (IGES 5.3 section 4.34).

use super::{Count, DirectoryEntry, Entity, Field, SURFACES, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: PTS, N1, N2, PTO, then `N2` inner boundaries PTI.
pub(super) const SCHEMA: Schema = Schema {
    entity: 144,
    name: "Trimmed Parametric Surface",
    fields: &[
        Field::one("PTS", Type::Pointer(SURFACES)),
        Field::one("N1", Type::Flag),
        Field::one("N2", Type::Integer),
        Field::one("PTO", Type::Pointer(&[142])),
        Field::times("PTI", Type::Pointer(&[142]), Count::Field("N2")),
    ],
};

/// Entity 144, Trimmed Surface.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrimmedSurface144 {
    /// PTS: the untrimmed surface.
    pub surface: i64,
    /// N1: 0 when the outer boundary is the surface's own boundary, 1 otherwise.
    pub outer_given: i64,
    /// PTO: the outer boundary (a 142; 0 when `N1 = 0`).
    pub outer: i64,
    /// PTI: the inner boundaries (142s).
    pub inner: Vec<i64>,
}

impl Entity for TrimmedSurface144 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        TrimmedSurface144 {
            surface: v.int("PTS"),
            outer_given: v.int("N1"),
            outer: v.int("PTO"),
            inner: v.ints("PTI"),
        }
    }
}

impl WriteParams for TrimmedSurface144 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(144);
        w.int(self.surface);
        w.int(self.outer_given);
        w.int(super::count(self.inner.len()));
        w.int(self.outer);
        self.inner.iter().for_each(|&b| w.int(b));
        Ok(())
    }
}
