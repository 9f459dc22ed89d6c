//! The annotation entities (IGES 5.3 chapter 4, types 202-230): notes, leaders
//! and dimensions, declared for the pointer and arity checks. nurbsx converts none of
//! them. Their pointers name the notes (212 General Note, or the 213 New General Note in
//! its place), leaders (214), witness lines (106 form 40) and the geometry they annotate.
//!
//! | type | name | parameters |
//! | --- | --- | --- |
//! | 202 | Angular Dimension | note, two witness lines, vertex `XV, YV`, leader arc radius, two leaders |
//! | 204 | Curve Dimension | note, the first curve, the second curve (0 for none), two leaders, two witness lines (0 for none) |
//! | 206 | Diameter Dimension | note, two leaders (the second 0 when absent), arc center `XC, YC` |
//! | 208 | Flag Note | lower-left corner, rotation, note, `N`, `N` leaders |
//! | 210 | General Label | note, `N`, `N` leaders |
//! | 212 | General Note | `NS`, `NS` × (characters, box width and height, font code, slant, rotation, mirror, rotate flag, start point, text) |
//! | 213 | New General Note | text width and height, justification, area location, area rotation, base line position, normal interline spacing, `NS`, `NS` × (character display, character width and height, intercharacter and interline spacing, font style, character angle, control code string, characters, box width and height, character set or font, slant, rotation, mirror, rotate flag, start point, text) |
//! | 214 | Leader (Arrow) | `N`, arrowhead height and width, depth, head `XH, YH`, `N` segment tails `X, Y` |
//! | 216 | Linear Dimension | note, two leaders, two witness lines |
//! | 218 | Ordinate Dimension | note, then form 0: a witness line or a leader; form 1: a witness line and a leader |
//! | 220 | Point Dimension | note, leader, and the geometry enclosing the note (optional) |
//! | 222 | Radius Dimension | note, leader, arc center `XC, YC`; form 1: a second leader |
//! | 228 | General Symbol | note, `N`, `N` geometry entities, `M`, `M` leaders |
//! | 230 | Sectioned Area | exterior curve, fill pattern, passing point, line distance, angle, `N`, `N` island curves |
//!
//! The font code of a 212 string (FC) and the character set of a 213 string are values,
//! or negated pointers to a 310 Text Font Definition. IGES 5.3 sections 4.55-4.68 define
//! the annotation entities (204 Curve Dimension: 4.56; 213 New General Note: 4.61). The
//! 213 field names below describe the parameters; they are not the standard's.

use super::{Count, Field, Schema, Type};

/// A pointer to the note of a dimension or label.
const NOTE: Type = Type::Pointer(&[212, 213]);
/// A pointer to a leader.
const LEADER: Type = Type::Pointer(&[214]);
/// A pointer to a witness line (106 form 40).
const WITNESS: Type = Type::Pointer(&[106]);

/// 202 Angular Dimension.
pub(super) const ANGULAR_DIMENSION: Schema = Schema {
    entity: 202,
    name: "Angular Dimension",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEWIT1", WITNESS),
        Field::one("DEWIT2", WITNESS),
        Field::one("XV", Type::Real),
        Field::one("YV", Type::Real),
        Field::one("R", Type::Real),
        Field::one("DEARW1", LEADER),
        Field::one("DEARW2", LEADER),
    ],
};

/// 206 Diameter Dimension.
pub(super) const DIAMETER_DIMENSION: Schema = Schema {
    entity: 206,
    name: "Diameter Dimension",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEARW1", LEADER),
        Field::one("DEARW2", LEADER),
        Field::one("XC", Type::Real),
        Field::one("YC", Type::Real),
    ],
};

/// 208 Flag Note.
pub(super) const FLAG_NOTE: Schema = Schema {
    entity: 208,
    name: "Flag Note",
    fields: &[
        Field::one("corner", Type::Point),
        Field::one("A", Type::Real),
        Field::one("DENOTE", NOTE),
        Field::one("N", Type::Integer),
        Field::times("DEARW", LEADER, Count::Field("N")),
    ],
};

/// 210 General Label.
pub(super) const GENERAL_LABEL: Schema = Schema {
    entity: 210,
    name: "General Label",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("N", Type::Integer),
        Field::times("DEARW", LEADER, Count::Field("N")),
    ],
};

/// 212 General Note.
pub(super) const GENERAL_NOTE: Schema = Schema {
    entity: 212,
    name: "General Note",
    fields: &[
        Field::one("NS", Type::Integer),
        Field::group(
            "string",
            Count::Field("NS"),
            &[
                Field::one("NC", Type::Flag),
                Field::one("WT", Type::Real),
                Field::one("HT", Type::Real),
                Field::one("FC", Type::ValueOrPointer(&[310])),
                Field::one("SL", Type::Real),
                Field::one("A", Type::Real),
                Field::one("M", Type::Flag),
                Field::one("VH", Type::Flag),
                Field::one("start", Type::Point),
                Field::one("TEXT", Type::String),
            ],
        ),
    ],
};

/// 214 Leader (Arrow).
pub(super) const LEADER_ARROW: Schema = Schema {
    entity: 214,
    name: "Leader (Arrow)",
    fields: &[
        Field::one("N", Type::Integer),
        Field::one("AH", Type::Real),
        Field::one("AW", Type::Real),
        Field::one("ZT", Type::Real),
        Field::one("XH", Type::Real),
        Field::one("YH", Type::Real),
        Field::group(
            "segment",
            Count::Field("N"),
            &[Field::one("X", Type::Real), Field::one("Y", Type::Real)],
        ),
    ],
};

/// 216 Linear Dimension.
pub(super) const LINEAR_DIMENSION: Schema = Schema {
    entity: 216,
    name: "Linear Dimension",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEARW1", LEADER),
        Field::one("DEARW2", LEADER),
        Field::one("DEWIT1", WITNESS),
        Field::one("DEWIT2", WITNESS),
    ],
};

/// 218 Ordinate Dimension form 0: the note and one witness line or leader.
pub(super) const ORDINATE_DIMENSION: Schema = Schema {
    entity: 218,
    name: "Ordinate Dimension",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEWIT", Type::Pointer(&[106, 214])),
    ],
};

/// 218 Ordinate Dimension form 1: the note, a witness line and a leader.
pub(super) const ORDINATE_DIMENSION_WITH_LEADER: Schema = Schema {
    entity: 218,
    name: "Ordinate Dimension (form 1)",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEWIT", WITNESS),
        Field::one("DEARW", LEADER),
    ],
};

/// 220 Point Dimension: the note, the leader and, optionally, the geometry
/// enclosing the note (a circular arc or composite curve; 0 for none).
pub(super) const POINT_DIMENSION: Schema = Schema {
    entity: 220,
    name: "Point Dimension",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEARW", LEADER),
        Field::optional("DEGEOM", Type::Pointer(&[])),
    ],
};

/// 222 Radius Dimension form 0.
pub(super) const RADIUS_DIMENSION: Schema = Schema {
    entity: 222,
    name: "Radius Dimension",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEARW", LEADER),
        Field::one("XC", Type::Real),
        Field::one("YC", Type::Real),
    ],
};

/// 222 Radius Dimension form 1: a second leader after the center.
pub(super) const RADIUS_DIMENSION_TWO_LEADERS: Schema = Schema {
    entity: 222,
    name: "Radius Dimension (form 1)",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DEARW", LEADER),
        Field::one("XC", Type::Real),
        Field::one("YC", Type::Real),
        Field::one("DEARW2", LEADER),
    ],
};

/// 228 General Symbol.
pub(super) const GENERAL_SYMBOL: Schema = Schema {
    entity: 228,
    name: "General Symbol",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("N", Type::Integer),
        Field::times("DEGEOM", Type::Pointer(&[]), Count::Field("N")),
        Field::one("M", Type::Integer),
        Field::times("DEARW", LEADER, Count::Field("M")),
    ],
};

/// 230 Sectioned Area.
pub(super) const SECTIONED_AREA: Schema = Schema {
    entity: 230,
    name: "Sectioned Area",
    fields: &[
        Field::one("EXTERIOR", Type::Pointer(&[])),
        Field::one("PATTERN", Type::Flag),
        Field::one("point", Type::Point),
        Field::one("DISTANCE", Type::Real),
        Field::one("ANGLE", Type::Real),
        Field::one("N", Type::Integer),
        Field::times("ISLAND", Type::Pointer(&[]), Count::Field("N")),
    ],
};

/// 204 Curve Dimension (IGES 5.3 section 4.56): the dimension of a curve's length (or of
/// the distance along two curves), with its note, the curves, two leaders and two optional
/// witness lines.
pub(super) const CURVE_DIMENSION: Schema = Schema {
    entity: 204,
    name: "Curve Dimension",
    fields: &[
        Field::one("DENOTE", NOTE),
        Field::one("DECURV1", Type::Pointer(&[])),
        Field::one("DECURV2", Type::Pointer(&[])),
        Field::one("DEARR1", LEADER),
        Field::one("DEARR2", LEADER),
        Field::one("DEWIT1", WITNESS),
        Field::one("DEWIT2", WITNESS),
    ],
};

/// 213 New General Note (IGES 5.3 section 4.61): the note's area, then per string its
/// character layout and the 212 string's fields (box, font, slant, rotation, mirror,
/// rotate flag, start point, text).
pub(super) const NEW_GENERAL_NOTE: Schema = Schema {
    entity: 213,
    name: "New General Note",
    fields: &[
        Field::one("text width", Type::Real),
        Field::one("text height", Type::Real),
        Field::one("justification", Type::Flag),
        Field::one("area location", Type::Point),
        Field::one("area rotation", Type::Real),
        Field::one("base line", Type::Point),
        Field::one("interline spacing", Type::Real),
        Field::one("NS", Type::Integer),
        Field::group(
            "string",
            Count::Field("NS"),
            &[
                Field::one("character display", Type::Flag),
                Field::one("character width", Type::Real),
                Field::one("character height", Type::Real),
                Field::one("intercharacter spacing", Type::Real),
                Field::one("line spacing", Type::Real),
                Field::one("font style", Type::Flag),
                Field::one("character angle", Type::Real),
                Field::one("control codes", Type::String),
                Field::one("characters", Type::Flag),
                Field::one("box width", Type::Real),
                Field::one("box height", Type::Real),
                Field::one("character set", Type::ValueOrPointer(&[310])),
                Field::one("slant angle", Type::Real),
                Field::one("rotation angle", Type::Real),
                Field::one("mirror", Type::Flag),
                Field::one("rotate", Type::Flag),
                Field::one("start", Type::Point),
                Field::one("TEXT", Type::String),
            ],
        ),
    ],
};
