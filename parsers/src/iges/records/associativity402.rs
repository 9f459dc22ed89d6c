//! Entity 402, Associativity Instance (IGES 5.3 section 4.80; its
//! predefined forms sections 4.81-4.95): the forms whose parameters
//! hold DE pointers, declared for the pointer and arity checks. The groups (forms 1, 7, 14
//! and 15) have a typed record, [`Group402`]: a group of trimmed surfaces is the set of
//! faces a reader sews into one shell (Open CASCADE writes a shell's faces so); the other
//! forms are converted to nothing.
//!
//! The parameter layout depends on the form (the Associativity Definition each form
//! stands for, IGES 5.3 type 302, section 4.69, and the predefined forms of type 402):
//!
//! | forms | name | parameters |
//! | --- | --- | --- |
//! | 1, 7, 14, 15 | Group (un)ordered, with/without back pointers | `N`, `N` DE pointers |
//! | 3 | Views Visible | `NV`, `NE`, `NV` 410 views, `NE` displayed entities |
//! | 4 | Views Visible, Color, Line Weight | `NV`, `NE`, `NV` × (410 view, line font value, 304 line font definition, color, line weight), `NE` displayed entities |
//! | 5 | Entity Label Display | `NL`, `NL` × (410 view, text location, 214 leader, label level, labelled entity) |
//! | 9 | Single Parent | `NP` (1), `NC`, the parent, `NC` children |
//! | 12 | External Reference File Index | `N`, `N` × (symbolic name, DE pointer) |
//! | 13 | Dimensioned Geometry | `ND` (1), `N`, the dimension, `N` geometry pointers |
//! | 16 | Planar | `NM` (1), `N`, the 124 transformation, `N` DE pointers |
//! | 18 | Flow | `NCF` (2), the six counts, type and function flags, then the lists |
//! | 19 | Segmented Views Visible | `N`, `N` × (410 view, breakpoint, display flag, color, line font, line weight) |
//! | 20 | Piping Flow | `NCF` (1), the six counts, type flag, then the lists |
//! | 21 | Dimensioned Geometry (new) | `ND` (1), `N`, the dimension, orientation flag, angle, `N` × (pointer, location) |
//!
//! Colors and line fonts of forms 4 and 19 are values, or negated pointers to a 314 Color
//! Definition or a 304 Line Font Definition, as the DE fields they stand in for (IGES 5.3
//! sections 2.2.4.4.4 and 2.2.4.4.13): [`Type::ValueOrPointer`]. The displayed entities of
//! forms 3 and 4 and the labelled entity of form 5 name entities whose DE view or label
//! display field names the 402 in turn: a pair of pointers by design, not a cycle.

use super::{Count, DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The entities a view pointer of these forms may name: a 410 View (form 0) or Perspective
/// View (form 1), or a 402 standing for views (forms 3, 4 and 19), as the DE view field.
const VIEW: Type = Type::Pointer(&[410, 402]);
/// A color value (0-8), or a negated pointer to a 314 Color Definition.
const COLOR: Type = Type::ValueOrPointer(&[314]);
/// A line font pattern value (0-5), or a negated pointer to a 304 Line Font Definition.
const LINE_FONT: Type = Type::ValueOrPointer(&[304]);

/// Forms 1, 7, 14 and 15: `N`, then `N` pointers to the members.
pub(super) const GROUP: Schema = Schema {
    entity: 402,
    name: "Group Associativity",
    fields: &[
        Field::one("N", Type::Integer),
        Field::times("DE", Type::Pointer(&[]), Count::Field("N")),
    ],
};

/// Entity 402 forms 1, 7, 14 and 15, a Group Associativity (IGES 5.3 sections 4.81, 4.83,
/// 4.88 and 4.89): form 1 unordered with back pointers, 7 unordered without, 14 ordered
/// with, 15 ordered without. Decode it only from an entry of one of those forms (the other
/// forms of 402 have other layouts).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Group402 {
    /// The members' DE pointers.
    pub members: Vec<i64>,
    /// Form number (1, 7, 14 or 15).
    pub form: i64,
}

impl Entity for Group402 {
    const SCHEMA: Schema = GROUP;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        Group402 {
            members: v.ints("DE"),
            form: entry.form,
        }
    }
}

impl WriteParams for Group402 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(402);
        w.int(super::count(self.members.len()));
        for &m in &self.members {
            w.int(m);
        }
        Ok(())
    }
}

/// Form 3: `NV`, `NE`, the `NV` views in which the entities are visible, then the `NE`
/// displayed entities.
pub(super) const VIEWS_VISIBLE: Schema = Schema {
    entity: 402,
    name: "Views Visible Associativity",
    fields: &[
        Field::one("NV", Type::Integer),
        Field::one("NE", Type::Integer),
        Field::times("VIEW", VIEW, Count::Field("NV")),
        Field::times("DE", Type::Pointer(&[]), Count::Field("NE")),
    ],
};

/// Form 4: `NV`, `NE`, per view the view, the line font value, the 304 line font
/// definition (when the value is 0), the color and the line weight; then the `NE`
/// displayed entities.
pub(super) const VIEWS_VISIBLE_WITH_ATTRIBUTES: Schema = Schema {
    entity: 402,
    name: "Views Visible, Color, Line Weight Associativity",
    fields: &[
        Field::one("NV", Type::Integer),
        Field::one("NE", Type::Integer),
        Field::group(
            "view",
            Count::Field("NV"),
            &[
                Field::one("VIEW", VIEW),
                Field::one("LINE FONT", Type::Flag),
                Field::one("LINE FONT DEFINITION", Type::Pointer(&[304])),
                Field::one("COLOR", COLOR),
                Field::one("LINE WEIGHT", Type::Flag),
            ],
        ),
        Field::times("DE", Type::Pointer(&[]), Count::Field("NE")),
    ],
};

/// Form 5: `NL`, then per label placement the view, the text location, the 214 leader, the
/// entity label level number and the labelled entity.
pub(super) const LABEL_DISPLAY: Schema = Schema {
    entity: 402,
    name: "Entity Label Display Associativity",
    fields: &[
        Field::one("NL", Type::Integer),
        Field::group(
            "label",
            Count::Field("NL"),
            &[
                Field::one("VIEW", VIEW),
                Field::one("LOCATION", Type::Point),
                Field::one("LEADER", Type::Pointer(&[214])),
                Field::one("LEVEL", Type::Flag),
                Field::one("DE", Type::Pointer(&[])),
            ],
        ),
    ],
};

/// Form 9: `NP` (1), `NC`, the parent, then `NC` children.
pub(super) const SINGLE_PARENT: Schema = Schema {
    entity: 402,
    name: "Single Parent Associativity",
    fields: &[
        Field::one("NP", Type::Flag),
        Field::one("NC", Type::Integer),
        Field::one("PDE", Type::Pointer(&[])),
        Field::times("CDE", Type::Pointer(&[]), Count::Field("NC")),
    ],
};

/// Form 12: `N`, then `N` pairs of a symbolic name and the entity it names.
pub(super) const EXTERNAL_REFERENCE_INDEX: Schema = Schema {
    entity: 402,
    name: "External Reference File Index",
    fields: &[
        Field::one("N", Type::Integer),
        Field::group(
            "symbol",
            Count::Field("N"),
            &[
                Field::one("NAME", Type::String),
                Field::one("DE", Type::Pointer(&[])),
            ],
        ),
    ],
};

/// Form 13: `ND` (1), `N`, the dimension entity, then `N` geometry entities.
pub(super) const DIMENSIONED_GEOMETRY: Schema = Schema {
    entity: 402,
    name: "Dimensioned Geometry",
    fields: &[
        Field::one("ND", Type::Flag),
        Field::one("N", Type::Integer),
        Field::one("DIMEN", Type::Pointer(&[])),
        Field::times("GEOM", Type::Pointer(&[]), Count::Field("N")),
    ],
};

/// Form 16: `NM` (1), `N`, the transformation matrix (0 for none), then `N` entities.
pub(super) const PLANAR: Schema = Schema {
    entity: 402,
    name: "Planar Associativity",
    fields: &[
        Field::one("NM", Type::Flag),
        Field::one("N", Type::Integer),
        Field::one("XFORM", Type::Pointer(&[124])),
        Field::times("DE", Type::Pointer(&[]), Count::Field("N")),
    ],
};

/// The lists of forms 18 and 20, after their counts and flags: flow associativities (402),
/// connect points (132), joins, flow names, text display templates (312) and continuation
/// flow associativities (402).
const FLOW_LISTS: [Field; 6] = [
    Field::times("FLOW", Type::Pointer(&[402]), Count::Field("NF")),
    Field::times("CONNECT", Type::Pointer(&[132]), Count::Field("NC")),
    Field::times("JOIN", Type::Pointer(&[]), Count::Field("NJ")),
    Field::times("FLOW NAME", Type::String, Count::Field("NN")),
    Field::times("TEXT", Type::Pointer(&[312]), Count::Field("NT")),
    Field::times("CONTINUATION", Type::Pointer(&[402]), Count::Field("NP")),
];

/// Form 18: `NCF` (2), the counts NF, NC, NJ, NN, NT, NP, the type and function flags,
/// then the lists.
pub(super) const FLOW: Schema = Schema {
    entity: 402,
    name: "Flow Associativity",
    fields: &[
        Field::one("NCF", Type::Flag),
        Field::one("NF", Type::Integer),
        Field::one("NC", Type::Integer),
        Field::one("NJ", Type::Integer),
        Field::one("NN", Type::Integer),
        Field::one("NT", Type::Integer),
        Field::one("NP", Type::Integer),
        Field::one("TF", Type::Flag),
        Field::one("FF", Type::Flag),
        FLOW_LISTS[0],
        FLOW_LISTS[1],
        FLOW_LISTS[2],
        FLOW_LISTS[3],
        FLOW_LISTS[4],
        FLOW_LISTS[5],
    ],
};

/// Form 19: `N`, then per segment the 410 view, breakpoint parameter, display flag, color,
/// line font and line weight.
pub(super) const SEGMENTED_VIEWS_VISIBLE: Schema = Schema {
    entity: 402,
    name: "Segmented Views Visible Associativity",
    fields: &[
        Field::one("N", Type::Integer),
        Field::group(
            "segment",
            Count::Field("N"),
            &[
                Field::one("VIEW", VIEW),
                Field::one("BREAKPOINT", Type::Real),
                Field::one("DISPLAY", Type::Flag),
                Field::one("COLOR", COLOR),
                Field::one("FONT", LINE_FONT),
                Field::one("WEIGHT", Type::Flag),
            ],
        ),
    ],
};

/// Form 20: `NCF` (1), the counts NF, NC, NJ, NN, NT, NP, the type flag, then the lists.
pub(super) const PIPING_FLOW: Schema = Schema {
    entity: 402,
    name: "Piping Flow Associativity",
    fields: &[
        Field::one("NCF", Type::Flag),
        Field::one("NF", Type::Integer),
        Field::one("NC", Type::Integer),
        Field::one("NJ", Type::Integer),
        Field::one("NN", Type::Integer),
        Field::one("NT", Type::Integer),
        Field::one("NP", Type::Integer),
        Field::one("TF", Type::Flag),
        FLOW_LISTS[0],
        FLOW_LISTS[1],
        FLOW_LISTS[2],
        FLOW_LISTS[3],
        FLOW_LISTS[4],
        FLOW_LISTS[5],
    ],
};

/// Form 21: `ND` (1), `N`, the dimension entity, its orientation flag and angle, then per
/// geometry entity its pointer and the dimension's location on it.
pub(super) const NEW_DIMENSIONED_GEOMETRY: Schema = Schema {
    entity: 402,
    name: "Dimensioned Geometry (form 21)",
    fields: &[
        Field::one("ND", Type::Flag),
        Field::one("N", Type::Integer),
        Field::one("DIMEN", Type::Pointer(&[])),
        Field::one("DIMORIENT", Type::Flag),
        Field::one("ANGLE", Type::Real),
        Field::group(
            "geometry",
            Count::Field("N"),
            &[
                Field::one("GEOM", Type::Pointer(&[])),
                Field::one("LOC", Type::Point),
            ],
        ),
    ],
};
