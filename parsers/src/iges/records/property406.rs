//! Entity 406, Property (IGES 5.3, type 406): `NP`, then `NP` property values whose types
//! the form defines. Declared here: form 1 (Definition Levels, the level list a DE level
//! field may point to) and form 15 (Name). Neither holds a DE pointer among its values;
//! their declarations give the count check and the check of the trailing associativity
//! and property pointers (IGES 5.3 section 2.2.4.5.2).

use super::{Count, Field, Schema, Type};

/// Form 1, Definition Levels: `NP`, then the `NP` level numbers.
pub(super) const DEFINITION_LEVELS: Schema = Schema {
    entity: 406,
    name: "Definition Levels Property",
    fields: &[
        Field::one("NP", Type::Integer),
        Field::times("LEVEL", Type::Flag, Count::Field("NP")),
    ],
};

/// Form 15, Name: `NP` (1), then the name.
pub(super) const NAME: Schema = Schema {
    entity: 406,
    name: "Name Property",
    fields: &[
        Field::one("NP", Type::Flag),
        Field::one("NAME", Type::String),
    ],
};
