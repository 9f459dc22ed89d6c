//! Entity 412, Rectangular Array Subfigure Instance, and entity 414, Circular Array
//! Subfigure Instance (IGES 5.3 sections 4.136 and 4.137), declared for the pointer and
//! arity checks. nurbsx converts neither (their copies are not expanded).
//!
//! | type | name | parameters |
//! | --- | --- | --- |
//! | 412 | Rectangular Array Subfigure Instance | base entity, scale (default 1.0), lower left corner `X, Y, Z`, columns `NC`, rows `NR`, column and row distances, rotation angle, `LC`, DO-DON'T flag, `LC` position numbers |
//! | 414 | Circular Array Subfigure Instance | base entity, instance locations `NE`, circle center `X, Y, Z`, radius, start and delta angles, `LC`, DO-DON'T flag, `LC` position numbers |
//!
//! Both sections list the entities valid as the base entity: a Group Associativity
//! Instance (402), a Point (116), Line (110), Circular Arc (100), Conic Arc (104),
//! Parametric Spline Curve (112), Rational B-Spline Curve (126), any annotation entity, a
//! Rectangular or Circular Array Subfigure Instance (412, 414) or a Subfigure Definition
//! (308). The annotation entities are types 202-230 and the 106 Copious Data forms 20,
//! 21, 31-38 and 40 (centerlines, sections, witness lines); the check is by type, so a
//! 106 of any form passes.

use super::{Count, Field, Schema, Type};

/// The base entity of an array (section 4.136, and 4.137 alike).
const BASE: Type = Type::Pointer(&[
    402, 116, 110, 100, 104, 112, 126, 106, 202, 204, 206, 208, 210, 212, 213, 214, 216, 218, 220,
    222, 228, 230, 412, 414, 308,
]);

/// The end of both arrays: `LC` (0: all positions), the DO-DON'T flag (0 DO, 1 DON'T),
/// then the `LC` position numbers processed (DO) or left out (DON'T).
const DO_DONT: [Field; 3] = [
    Field::one("LC", Type::Integer),
    Field::one("DDF", Type::Flag),
    Field::times("N", Type::Integer, Count::Field("LC")),
];

/// 412, Rectangular Array Subfigure Instance (section 4.136): `12 + LC` parameters.
pub(super) const RECTANGULAR_ARRAY: Schema = Schema {
    entity: 412,
    name: "Rectangular Array Subfigure Instance",
    fields: &[
        Field::one("DE", BASE),
        Field::one("S", Type::Real),
        Field::one("corner", Type::Point),
        Field::one("NC", Type::Integer),
        Field::one("NR", Type::Integer),
        Field::one("DX", Type::Real),
        Field::one("DY", Type::Real),
        Field::one("AX", Type::Real),
        DO_DONT[0],
        DO_DONT[1],
        DO_DONT[2],
    ],
};

/// 414, Circular Array Subfigure Instance (section 4.137): `10 + LC` parameters.
pub(super) const CIRCULAR_ARRAY: Schema = Schema {
    entity: 414,
    name: "Circular Array Subfigure Instance",
    fields: &[
        Field::one("DE", BASE),
        Field::one("NE", Type::Integer),
        Field::one("center", Type::Point),
        Field::one("R", Type::Real),
        Field::one("AS", Type::Real),
        Field::one("AD", Type::Real),
        DO_DONT[0],
        DO_DONT[1],
        DO_DONT[2],
    ],
};
