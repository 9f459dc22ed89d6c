//! Entity 430, Solid Instance (IGES 5.3 section 4.142), declared for the pointer and arity
//! checks: one pointer, `PTR`, to the solid it replicates (placed by the instance's own
//! DE transformation matrix). nurbsx does not convert it.
//!
//! | type, form | name | parameters |
//! | --- | --- | --- |
//! | 430, 0 | Solid Instance | a primitive, Boolean tree, solid assembly or solid instance |
//! | 430, 1 | Solid Instance | a Manifold Solid B-Rep Object |
//!
//! The forms differ in what the pointer names, not in the layout: one declaration for
//! both, allowing either kind (the check is by type, not form).

use super::{Field, Schema, Type};

/// 430, Solid Instance: the solid is a CSG primitive (150 block, 152 wedge, 154 cylinder,
/// 156 cone frustum, 158 sphere, 160 torus, 162 solid of revolution, 164 solid of linear
/// extrusion, 168 ellipsoid), a 180 Boolean tree, a 184 solid assembly, another 430 or a
/// 186 Manifold Solid B-Rep Object.
pub(super) const SCHEMA: Schema = Schema {
    entity: 430,
    name: "Solid Instance",
    fields: &[Field::one(
        "PTR",
        Type::Pointer(&[
            150, 152, 154, 156, 158, 160, 162, 164, 168, 180, 184, 430, 186,
        ]),
    )],
};
