//! Entity 418, Nodal Load/Constraint (IGES 5.3 section 4.139), declared for the pointer
//! and arity checks: the load or constraint cases of one finite element node. nurbsx
//! converts no finite element entity.
//!
//! | type | name | parameters |
//! | --- | --- | --- |
//! | 418 | Nodal Load/Constraint | `NC`, type (1 load, 2 constraint), the 134 node, `NC` 406 Tabular Data Properties (form 11, property type 12: the load or constraint data of each case) |

use super::{Count, Field, Schema, Type};

/// 418, Nodal Load/Constraint: `3 + NC` parameters.
pub(super) const SCHEMA: Schema = Schema {
    entity: 418,
    name: "Nodal Load/Constraint",
    fields: &[
        Field::one("NC", Type::Integer),
        Field::one("TYPE", Type::Flag),
        Field::one("NODE", Type::Pointer(&[134])),
        Field::times("TABDATA", Type::Pointer(&[406]), Count::Field("NC")),
    ],
};
