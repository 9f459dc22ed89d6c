//! Entity 102, Composite Curve (IGES 5.3 section 4.4).

use super::{CURVES, Count, DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: `N`, then `N` pointers to the constituent curves, in order.
pub(super) const SCHEMA: Schema = Schema {
    entity: 102,
    name: "Composite Curve",
    fields: &[
        Field::one("N", Type::Integer),
        Field::times("DE", Type::Pointer(CURVES), Count::Field("N")),
    ],
};

/// Entity 102, Composite Curve: the DE pointers of its constituents, in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompositeCurve102 {
    /// The constituents' DE pointers.
    pub members: Vec<i64>,
}

impl Entity for CompositeCurve102 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        CompositeCurve102 {
            members: v.ints("DE"),
        }
    }
}

impl WriteParams for CompositeCurve102 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(102);
        w.int(super::count(self.members.len()));
        self.members.iter().for_each(|&m| w.int(m));
        Ok(())
    }
}
