//! Entity 316, Units Data (IGES 5.3 section 4.77), declared for the arity check: `NP`, then
//! `NP` × (unit type, unit, scale factor), strings and a real, so no DE pointer. nurbsx
//! reads the model units from the Global section only.

use super::{Count, Field, Schema, Type};

/// 316, Units Data: `1 + 3 NP` parameters.
pub(super) const SCHEMA: Schema = Schema {
    entity: 316,
    name: "Units Data",
    fields: &[
        Field::one("NP", Type::Integer),
        Field::group(
            "unit",
            Count::Field("NP"),
            &[
                Field::one("TYP", Type::String),
                Field::one("VAL", Type::String),
                Field::one("SF", Type::Real),
            ],
        ),
    ],
};
