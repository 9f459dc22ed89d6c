//! Entity 143, Bounded Surface (IGES 5.3 section 4.33), and the 141 Boundary entities it
//! names (section 4.31).

use super::{CURVES, Count, DirectoryEntry, Entity, Field, SURFACES, Schema, Type, Values};

/// The 143 declaration: TYPE, SPTR, `N`, then `N` pointers BDPT to 141 Boundaries.
pub(super) const SCHEMA: Schema = Schema {
    entity: 143,
    name: "Bounded Surface",
    fields: &[
        Field::one("TYPE", Type::Flag),
        Field::one("SPTR", Type::Pointer(SURFACES)),
        Field::one("N", Type::Integer),
        Field::times("BDPT", Type::Pointer(&[141]), Count::Field("N")),
    ],
};

/// Entity 143, Bounded Surface.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BoundedSurface143 {
    /// TYPE: 0 model-space boundaries only, 1 with parameter-space curves too.
    pub kind: i64,
    /// SPTR: the untrimmed surface.
    pub surface: i64,
    /// BDPT: the 141 Boundaries (the first is the outer one).
    pub boundaries: Vec<i64>,
}

impl Entity for BoundedSurface143 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        BoundedSurface143 {
            kind: v.int("TYPE"),
            surface: v.int("SPTR"),
            boundaries: v.ints("BDPT"),
        }
    }
}

/// The 141 declaration: TYPE, PREF, SPTR, `N`, then per curve CRVPT, SENSE, `K` and `K`
/// parameter-space curves PSCPT.
pub(super) const BOUNDARY_SCHEMA: Schema = Schema {
    entity: 141,
    name: "Boundary",
    fields: &[
        Field::one("TYPE", Type::Flag),
        Field::one("PREF", Type::Flag),
        Field::one("SPTR", Type::Pointer(SURFACES)),
        Field::one("N", Type::Integer),
        Field::group(
            "curve",
            Count::Field("N"),
            &[
                Field::one("CRVPT", Type::Pointer(CURVES)),
                Field::one("SENSE", Type::Flag),
                Field::one("K", Type::Integer),
                Field::times("PSCPT", Type::Pointer(CURVES), Count::Field("K")),
            ],
        ),
    ],
};

/// One model-space curve of a 141 with its sense and parameter-space curves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BoundaryCurve {
    /// CRVPT: the model-space curve.
    pub curve: i64,
    /// SENSE: 1 as the curve runs, 2 reversed.
    pub sense: i64,
    /// PSCPT: its curves in the surface's parameter space.
    pub parameter_curves: Vec<i64>,
}

/// Entity 141, Boundary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Boundary141 {
    /// TYPE: 0 model space only, 1 with parameter-space curves.
    pub kind: i64,
    /// PREF: preferred representation (0 unspecified, 1 model, 2 parameter, 3 equal).
    pub preferred: i64,
    /// SPTR: the surface.
    pub surface: i64,
    /// The curves, in order.
    pub curves: Vec<BoundaryCurve>,
}

impl Entity for Boundary141 {
    const SCHEMA: Schema = BOUNDARY_SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        Boundary141 {
            kind: v.int("TYPE"),
            preferred: v.int("PREF"),
            surface: v.int("SPTR"),
            curves: v
                .groups("curve")
                .into_iter()
                .map(|mut c| BoundaryCurve {
                    curve: c.int("CRVPT"),
                    sense: c.int("SENSE"),
                    parameter_curves: c.ints("PSCPT"),
                })
                .collect(),
        }
    }
}
