//! Entity 322, Attribute Table Definition (IGES 5.3 section 4.79), form 0, declared for
//! the arity check: the table name, the attribute list type, `NA`, then per attribute its
//! type, value data type and value count, integers all, so no DE pointer.
//!
//! | form | parameters |
//! | --- | --- |
//! | 0 | `NAME`, `ATYP`, `NA`, `NA` × (`AT`, `AVT`, `AVC`) |
//! | 1 | as form 0, each attribute followed by its `AVC` values |
//! | 2 | as form 1, each value followed by a pointer to a 312 Text Display Template |
//!
//! Only form 0 is declared. The values of forms 1 and 2 have the type the attribute's
//! `AVT` names (none, integer, real, string, pointer, not used, logical), so their
//! parameters' types come from the data; and the values of a 422 Attribute Table Instance
//! (section 4.141, forms 0 and 1: one row, or `NR` rows) follow the layout of the 322 its
//! DE structure field names, so its parameters come from another entity. Neither fits a
//! declaration; their parameters and pointers are unchecked.

use super::{Count, Field, Schema, Type};

/// 322 form 0, Attribute Table Definition: `3 + 3 NA` parameters.
pub(super) const DEFINITION: Schema = Schema {
    entity: 322,
    name: "Attribute Table Definition",
    fields: &[
        Field::one("NAME", Type::String),
        Field::one("ATYP", Type::Flag),
        Field::one("NA", Type::Integer),
        Field::group(
            "attribute",
            Count::Field("NA"),
            &[
                Field::one("AT", Type::Flag),
                Field::one("AVT", Type::Flag),
                Field::one("AVC", Type::Flag),
            ],
        ),
    ],
};
