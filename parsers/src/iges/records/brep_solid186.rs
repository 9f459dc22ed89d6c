//! Entity 186, Manifold Solid B-Rep Object (IGES 5.3 section 4.49).

use super::{Count, DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: SHELL, SOF, `N`, then per void VOID (a 514) and VOF.
pub(super) const SCHEMA: Schema = Schema {
    entity: 186,
    name: "Manifold Solid B-Rep Object",
    fields: &[
        Field::one("SHELL", Type::Pointer(&[514])),
        Field::one("SOF", Type::Flag),
        Field::one("N", Type::Integer),
        Field::group(
            "void",
            Count::Field("N"),
            &[
                Field::one("VOID", Type::Pointer(&[514])),
                Field::one("VOF", Type::Flag),
            ],
        ),
    ],
};

/// Entity 186, Manifold Solid B-Rep Object.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BrepSolid186 {
    /// SHELL, SOF: the outer 514 Shell and 1 when its orientation agrees with the solid's
    /// outward normal.
    pub shell: (i64, i64),
    /// `(VOID, VOF)`: the void shells and their orientation flags.
    pub voids: Vec<(i64, i64)>,
}

impl Entity for BrepSolid186 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        BrepSolid186 {
            shell: (v.int("SHELL"), v.int("SOF")),
            voids: v
                .groups("void")
                .into_iter()
                .map(|mut g| (g.int("VOID"), g.int("VOF")))
                .collect(),
        }
    }
}

impl WriteParams for BrepSolid186 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(186);
        w.int(self.shell.0);
        w.int(self.shell.1);
        w.int(super::count(self.voids.len()));
        for &(s, of) in &self.voids {
            w.int(s);
            w.int(of);
        }
        Ok(())
    }
}
