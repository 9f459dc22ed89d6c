//! Entity 308, Subfigure Definition, and entity 408, Singular Subfigure Instance (IGES 5.3
//! sections 4.73 and 4.133).

use super::{Count, DirectoryEntry, Entity, Field, Schema, Type, Values};

/// The 308 declaration: DEPTH, NAME, `N`, then `N` pointers to the entities it groups.
pub(super) const DEFINITION_SCHEMA: Schema = Schema {
    entity: 308,
    name: "Subfigure Definition",
    fields: &[
        Field::one("DEPTH", Type::Flag),
        Field::one("NAME", Type::String),
        Field::one("N", Type::Integer),
        Field::times("DE", Type::Pointer(&[]), Count::Field("N")),
    ],
};

/// Entity 308, Subfigure Definition.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SubfigureDefinition308 {
    /// DEPTH: how deeply subfigures nest below this one.
    pub depth: i64,
    /// NAME.
    pub name: Option<String>,
    /// The entities of the subfigure.
    pub members: Vec<i64>,
}

impl Entity for SubfigureDefinition308 {
    const SCHEMA: Schema = DEFINITION_SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        let name = match v.take("NAME") {
            super::Value::String(s) => s.map(str::to_owned),
            _ => None,
        };
        SubfigureDefinition308 {
            depth: v.int("DEPTH"),
            name,
            members: v.ints("DE"),
        }
    }
}

/// The 408 declaration: DE (the 308), X, Y, Z (translation) and the optional scale S.
pub(super) const INSTANCE_SCHEMA: Schema = Schema {
    entity: 408,
    name: "Singular Subfigure Instance",
    fields: &[
        Field::one("DE", Type::Pointer(&[308])),
        Field::one("X", Type::Real),
        Field::one("Y", Type::Real),
        Field::one("Z", Type::Real),
        Field::optional("S", Type::Real),
    ],
};

/// Entity 408, Singular Subfigure Instance: the definition placed by `x' = S x + T`, then
/// by the instance's own 124 (DE field 7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubfigureInstance408 {
    /// DE: the 308 Subfigure Definition.
    pub definition: i64,
    /// X, Y, Z: the translation.
    pub translation: [f64; 3],
    /// S: the scale (1 when absent).
    pub scale: f64,
}

impl Entity for SubfigureInstance408 {
    const SCHEMA: Schema = INSTANCE_SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        SubfigureInstance408 {
            definition: v.int("DE"),
            translation: [
                v.real("X").unwrap_or(0.0),
                v.real("Y").unwrap_or(0.0),
                v.real("Z").unwrap_or(0.0),
            ],
            scale: v.real("S").unwrap_or(1.0),
        }
    }
}
