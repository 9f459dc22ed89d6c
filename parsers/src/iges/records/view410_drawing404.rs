//! Entity 410, View, and entity 404, Drawing (IGES 5.3 sections 4.134 and
//! 4.135 for the two 410 forms, 4.96 for 404), declared for the
//! pointer and arity checks. nurbsx converts neither.
//!
//! | type, form | name | parameters |
//! | --- | --- | --- |
//! | 410, 0 | View | view number, scale, the six clipping planes (108, 0 for none) |
//! | 410, 1 | Perspective View | view number, scale, view plane normal, view reference point, center of projection, view up vector, view plane distance, the window `XL, XR, YB, YT`, depth clipping, back and front plane distances |
//! | 404, 0 | Drawing | `N`, `N` × (view, origin `X, Y`), `M`, `M` annotation entities |
//! | 404, 1 | Drawing With Rotation | as form 0, with a rotation angle after each view's origin |
//!
//! A view pointer names a 410 View or a 402 instance standing for views (forms 3, 4, 19).

use super::{Count, Field, Schema, Type};

/// A pointer to a view (0 for none).
const VIEW: Type = Type::Pointer(&[410, 402]);
/// A pointer to a clipping plane (0 for none).
const PLANE: Type = Type::Pointer(&[108]);

/// 410 form 0, View.
pub(super) const VIEW_SCHEMA: Schema = Schema {
    entity: 410,
    name: "View",
    fields: &[
        Field::one("VNO", Type::Flag),
        Field::one("SCALE", Type::Real),
        Field::one("XVMINP", PLANE),
        Field::one("YVMAXP", PLANE),
        Field::one("XVMAXP", PLANE),
        Field::one("YVMINP", PLANE),
        Field::one("ZVMINP", PLANE),
        Field::one("ZVMAXP", PLANE),
    ],
};

/// 410 form 1, Perspective View: no pointers; 22 parameters.
pub(super) const PERSPECTIVE_VIEW: Schema = Schema {
    entity: 410,
    name: "Perspective View",
    fields: &[
        Field::one("VNO", Type::Flag),
        Field::one("SCALE", Type::Real),
        Field::one("normal", Type::Point),
        Field::one("reference", Type::Point),
        Field::one("center", Type::Point),
        Field::one("up", Type::Point),
        Field::one("DISTANCE", Type::Real),
        Field::one("XL", Type::Real),
        Field::one("XR", Type::Real),
        Field::one("YB", Type::Real),
        Field::one("YT", Type::Real),
        Field::one("DEPTH", Type::Flag),
        Field::one("BACK", Type::Real),
        Field::one("FRONT", Type::Real),
    ],
};

/// The end of both 404 forms: `M`, then the `M` annotation entities.
const ANNOTATIONS: [Field; 2] = [
    Field::one("M", Type::Integer),
    Field::times("ANNOTATION", Type::Pointer(&[]), Count::Field("M")),
];

/// 404 form 0, Drawing.
pub(super) const DRAWING: Schema = Schema {
    entity: 404,
    name: "Drawing",
    fields: &[
        Field::one("N", Type::Integer),
        Field::group(
            "view",
            Count::Field("N"),
            &[
                Field::one("VIEW", VIEW),
                Field::one("X", Type::Real),
                Field::one("Y", Type::Real),
            ],
        ),
        ANNOTATIONS[0],
        ANNOTATIONS[1],
    ],
};

/// 404 form 1, Drawing With Rotation.
pub(super) const DRAWING_WITH_ROTATION: Schema = Schema {
    entity: 404,
    name: "Drawing With Rotation",
    fields: &[
        Field::one("N", Type::Integer),
        Field::group(
            "view",
            Count::Field("N"),
            &[
                Field::one("VIEW", VIEW),
                Field::one("X", Type::Real),
                Field::one("Y", Type::Real),
                Field::one("ANGLE", Type::Real),
            ],
        ),
        ANNOTATIONS[0],
        ANNOTATIONS[1],
    ],
};
