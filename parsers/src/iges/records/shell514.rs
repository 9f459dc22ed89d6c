//! Entity 514, Shell (IGES 5.3 section 4.147): form 1 closed, form 2 open.

use super::{Count, DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: `N`, then per face FACE (a 510) and OF (orientation flag).
pub(super) const SCHEMA: Schema = Schema {
    entity: 514,
    name: "Shell",
    fields: &[
        Field::one("N", Type::Integer),
        Field::group(
            "face",
            Count::Field("N"),
            &[
                Field::one("FACE", Type::Pointer(&[510])),
                Field::one("OF", Type::Flag),
            ],
        ),
    ],
};

/// Entity 514, Shell.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Shell514 {
    /// `(FACE, OF)`: the 510 Face and 1 when its normal agrees with the shell's outward
    /// direction (0 when reversed).
    pub faces: Vec<(i64, i64)>,
    /// Form number: 1 closed shell, 2 open shell.
    pub form: i64,
}

impl Entity for Shell514 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        Shell514 {
            faces: v
                .groups("face")
                .into_iter()
                .map(|mut f| (f.int("FACE"), f.int("OF")))
                .collect(),
            form: entry.form,
        }
    }
}

impl WriteParams for Shell514 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(514);
        w.int(super::count(self.faces.len()));
        for &(f, of) in &self.faces {
            w.int(f);
            w.int(of);
        }
        Ok(())
    }
}
