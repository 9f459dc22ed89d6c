//! Entity 310, Text Font Definition, and entity 312, Text Display Template (IGES 5.3
//! sections 4.74 and 4.75): the stroke fonts a font code may name and the text layouts a
//! property or associativity displays its values with, declared for the pointer and arity
//! checks. nurbsx converts neither.
//!
//! | type, form | name | parameters |
//! | --- | --- | --- |
//! | 310 | Text Font Definition | font code, font name, the font it supersedes, scale (grid units per text height), `NC`, `NC` × (character code, next character origin `NX, NY`, `NM`, `NM` × (pen up/down flag, `X, Y`)) |
//! | 312, 0 and 1 | Text Display Template | character box width and height, font code, slant angle, rotation angle, mirror flag, rotate flag, the lower left corner (form 0) or its increments (form 1) |
//!
//! The superseded font of a 310 and the font code of a 312 are values, or negated
//! pointers to a 310, as the font code of a 212 General Note string: [`Type::ValueOrPointer`].
//! The two forms of 312 differ in how the corner is read, not in the layout: one
//! declaration for both. The field names below describe the parameters (the 312's follow
//! the 212 string's); they are not all the standard's.

use super::{Count, Field, Schema, Type};

/// A font code: a value, or a negated pointer to a Text Font Definition.
const FONT: Type = Type::ValueOrPointer(&[310]);

/// 310, Text Font Definition (section 4.74).
pub(super) const TEXT_FONT: Schema = Schema {
    entity: 310,
    name: "Text Font Definition",
    fields: &[
        Field::one("FC", Type::Flag),
        Field::one("font name", Type::String),
        Field::one("superseded font", FONT),
        Field::one("scale", Type::Flag),
        Field::one("NC", Type::Integer),
        Field::group(
            "character",
            Count::Field("NC"),
            &[
                Field::one("character code", Type::Flag),
                Field::one("next X", Type::Flag),
                Field::one("next Y", Type::Flag),
                Field::one("NM", Type::Integer),
                Field::group(
                    "motion",
                    Count::Field("NM"),
                    &[
                        Field::one("pen up", Type::Flag),
                        Field::one("pen X", Type::Flag),
                        Field::one("pen Y", Type::Flag),
                    ],
                ),
            ],
        ),
    ],
};

/// 312, Text Display Template (section 4.75), both forms: ten parameters.
pub(super) const TEXT_TEMPLATE: Schema = Schema {
    entity: 312,
    name: "Text Display Template",
    fields: &[
        Field::one("WT", Type::Real),
        Field::one("HT", Type::Real),
        Field::one("FC", FONT),
        Field::one("SL", Type::Real),
        Field::one("A", Type::Real),
        Field::one("M", Type::Flag),
        Field::one("VH", Type::Flag),
        Field::one("corner", Type::Point),
    ],
};
