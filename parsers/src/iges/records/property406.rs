//! Entity 406, Property (IGES 5.3, type 406): `NP`, then `NP` property values whose types
//! the form defines. None holds a DE pointer among its values; their declarations give the
//! count check and the check of the trailing associativity and property pointers (IGES 5.3
//! section 2.2.4.5.2). Declared here:
//!
//! | form | name | values after `NP` |
//! | --- | --- | --- |
//! | 1 | Definition Levels | `NP` level numbers |
//! | 2 | Region Restriction | vias, components and circuitry flags |
//! | 3 | Level Function | function code, description (optional) |
//! | 5 | Line Widening | width, cornering, extension flag, justification, extension value (optional) |
//! | 15 | Name | the name |
//! | 16 | Drawing Size | width, height |
//! | 17 | Drawing Units | units flag, units name |
//! | 18 | Intercharacter Spacing | spacing |
//! | 19 | Line Font Pattern | pattern code |
//! | 20 | Highlight | highlight flag (optional) |
//! | 21 | Pick | pick flag (optional) |
//! | 23 | Associativity Group Type | type number, name |
//! | 28 | Dimension Units | secondary position, units indicator, character set, format, fraction flag, precision |
//! | 29 | Dimension Tolerance | secondary flag, type, placement, upper and lower tolerance, sign suppression, fraction flag, precision |
//! | 30 | Dimension Display Data | type, label position, character set, `L` string, decimal symbol, witness angle, alignment, level, placement, arrowhead orientation, initial value, `NS`, `NS` × (note, start and end index) |
//!
//! The other forms are not declared (their parameters unchecked).

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

/// A property whose values are the listed fields after `NP` (which is not a count of
/// parameters here: the form fixes them).
macro_rules! fixed {
    ($name:ident, $title:literal, [$($field:expr),* $(,)?]) => {
        pub(super) const $name: Schema = Schema {
            entity: 406,
            name: $title,
            fields: &[Field::one("NP", Type::Flag), $($field),*],
        };
    };
}

fixed!(
    REGION_RESTRICTION,
    "Region Restriction Property",
    [
        Field::one("VIAS", Type::Flag),
        Field::one("COMPONENTS", Type::Flag),
        Field::one("CIRCUITRY", Type::Flag),
    ]
);
fixed!(
    LEVEL_FUNCTION,
    "Level Function Property",
    [
        Field::one("FC", Type::Flag),
        Field::optional("DESCRIPTION", Type::String),
    ]
);
fixed!(
    LINE_WIDENING,
    "Line Widening Property",
    [
        Field::one("WIDTH", Type::Real),
        Field::one("CORNERING", Type::Flag),
        Field::one("EXTENSION FLAG", Type::Flag),
        Field::one("JUSTIFICATION", Type::Flag),
        Field::optional("EXTENSION", Type::Real),
    ]
);
fixed!(
    DRAWING_SIZE,
    "Drawing Size Property",
    [Field::one("X", Type::Real), Field::one("Y", Type::Real),]
);
fixed!(
    DRAWING_UNITS,
    "Drawing Units Property",
    [
        Field::one("FLAG", Type::Flag),
        Field::one("UNITS", Type::String),
    ]
);
fixed!(
    INTERCHARACTER_SPACING,
    "Intercharacter Spacing Property",
    [Field::one("ISCP", Type::Real),]
);
fixed!(
    LINE_FONT_PATTERN,
    "Line Font Pattern Property",
    [Field::one("LFPC", Type::Flag),]
);
fixed!(
    HIGHLIGHT,
    "Highlight Property",
    [Field::optional("HIGHLIGHT", Type::Flag),]
);
fixed!(PICK, "Pick Property", [Field::optional("PICK", Type::Flag)]);
fixed!(
    ASSOCIATIVITY_GROUP_TYPE,
    "Associativity Group Type Property",
    [
        Field::one("TYPE", Type::Flag),
        Field::one("NAME", Type::String),
    ]
);
fixed!(
    DIMENSION_UNITS,
    "Dimension Units Property",
    [
        Field::one("SDP", Type::Flag),
        Field::one("UI", Type::Flag),
        Field::one("CS", Type::Flag),
        Field::one("FORMAT", Type::String),
        Field::one("FF", Type::Flag),
        Field::one("PRECISION", Type::Flag),
    ]
);
fixed!(
    DIMENSION_TOLERANCE,
    "Dimension Tolerance Property",
    [
        Field::one("STF", Type::Flag),
        Field::one("TT", Type::Flag),
        Field::one("TPF", Type::Flag),
        Field::one("UPPER", Type::Real),
        Field::one("LOWER", Type::Real),
        Field::one("SS", Type::Flag),
        Field::one("FF", Type::Flag),
        Field::one("PRECISION", Type::Flag),
    ]
);
fixed!(
    DIMENSION_DISPLAY_DATA,
    "Dimension Display Data Property",
    [
        Field::one("DT", Type::Flag),
        Field::one("LP", Type::Flag),
        Field::one("CS", Type::Flag),
        Field::one("L", Type::String),
        Field::one("DS", Type::Flag),
        Field::one("WLA", Type::Real),
        Field::one("TA", Type::Flag),
        Field::one("TL", Type::Flag),
        Field::one("TP", Type::Flag),
        Field::one("AHO", Type::Flag),
        Field::one("IV", Type::Real),
        Field::one("NS", Type::Integer),
        Field::group(
            "note",
            Count::Field("NS"),
            &[
                Field::one("NOTE", Type::Flag),
                Field::one("START", Type::Flag),
                Field::one("END", Type::Flag),
            ],
        ),
    ]
);
