//! Entity 314, Color Definition, and entity 304, Line Font Definition (IGES 5.3 sections
//! 4.76 and 4.70): the entities a negated DE color or line font field names, declared for the
//! pointer and arity checks. nurbsx carries neither (colors and line fonts are reported
//! as not carried).
//!
//! | type, form | name | parameters |
//! | --- | --- | --- |
//! | 314 | Color Definition | red, green and blue in percent, then the color's name (optional) |
//! | 304, 1 | Line Font Definition (template) | orientation, the 308 subfigure repeated along the curve, its spacing and scale |
//! | 304, 2 | Line Font Definition (pattern) | `M`, `M` segment lengths, the visible/blank pattern as a hexadecimal string |

use super::{Count, Field, Schema, Type};

/// 314, Color Definition.
pub(super) const COLOR: Schema = Schema {
    entity: 314,
    name: "Color Definition",
    fields: &[
        Field::one("CC1", Type::Real),
        Field::one("CC2", Type::Real),
        Field::one("CC3", Type::Real),
        Field::optional("CNAME", Type::String),
    ],
};

/// 304 form 1, Line Font Definition by a repeated subfigure.
pub(super) const LINE_FONT_TEMPLATE: Schema = Schema {
    entity: 304,
    name: "Line Font Definition (template)",
    fields: &[
        Field::one("M", Type::Flag),
        Field::one("DE", Type::Pointer(&[308])),
        Field::one("L", Type::Real),
        Field::one("SCALE", Type::Real),
    ],
};

/// 304 form 2, Line Font Definition by a pattern.
pub(super) const LINE_FONT_PATTERN: Schema = Schema {
    entity: 304,
    name: "Line Font Definition (pattern)",
    fields: &[
        Field::one("M", Type::Integer),
        Field::times("T", Type::Real, Count::Field("M")),
        Field::one("PATTERN", Type::String),
    ],
};
