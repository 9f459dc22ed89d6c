//! Entity 320, Network Subfigure Definition, and entity 420, Network Subfigure Instance
//! (IGES 5.3 sections 4.78 and 4.140): the schematic symbols with connect points, declared
//! for the pointer and arity checks. nurbsx converts neither.
//!
//! | type | name | parameters |
//! | --- | --- | --- |
//! | 320 | Network Subfigure Definition | `DEPTH`, `NAME`, `N`, `N` member entities, type flag, primary reference designator, its 312 text display template (0 for none), `NC`, `NC` 132 connect points |
//! | 420 | Network Subfigure Instance | the 320 definition, translation `X, Y, Z`, scale factors `XS`, `YS`, `ZS` (defaults 1.0, `XS`, `XS`), type flag, primary reference designator, its 312 text display template (0 for none), `NC`, `NC` 132 connect points (0 for none) |
//!
//! The definition a 420 names may be a 416 External Reference standing for it (section
//! 4.138: forms 3 and 4 replace a 320, and the reference is treated as the definition it
//! replaces).

use super::{Count, Field, Schema, Type};

/// A pointer to the text display template of the primary reference designator (0 for
/// none).
const TEMPLATE: Type = Type::Pointer(&[312]);
/// A pointer to a Connect Point (type 132).
const CONNECT_POINT: Type = Type::Pointer(&[132]);

/// 320, Network Subfigure Definition (section 4.78).
pub(super) const DEFINITION: Schema = Schema {
    entity: 320,
    name: "Network Subfigure Definition",
    fields: &[
        Field::one("DEPTH", Type::Flag),
        Field::one("NAME", Type::String),
        Field::one("N", Type::Integer),
        Field::times("DE", Type::Pointer(&[]), Count::Field("N")),
        Field::one("TF", Type::Flag),
        Field::one("PRD", Type::String),
        Field::one("PTR", TEMPLATE),
        Field::one("NC", Type::Integer),
        Field::times("CP", CONNECT_POINT, Count::Field("NC")),
    ],
};

/// 420, Network Subfigure Instance (section 4.140).
pub(super) const INSTANCE: Schema = Schema {
    entity: 420,
    name: "Network Subfigure Instance",
    fields: &[
        Field::one("DE", Type::Pointer(&[320, 416])),
        Field::one("translation", Type::Point),
        Field::one("XS", Type::Real),
        Field::one("YS", Type::Real),
        Field::one("ZS", Type::Real),
        Field::one("TF", Type::Flag),
        Field::one("PRD", Type::String),
        Field::one("DPTR", TEMPLATE),
        Field::one("NC", Type::Integer),
        Field::times("CPTR", CONNECT_POINT, Count::Field("NC")),
    ],
};
