//! Entities 190-198, the analytic surfaces of IGES 5.3 sections 4.50-4.54 (plane surface,
//! right circular cylindrical, conical, spherical and toroidal surface). Form 0 is the
//! unparameterised surface; form 1 adds the reference direction DEREFD that fixes the
//! parameterisation. Locations are 116 Points and directions 123 Directions.

use super::{DirectoryEntry, Entity, Field, Schema, Type, Values};

const POINT: Type = Type::Pointer(&[116]);
const DIRECTION: Type = Type::Pointer(&[123]);

/// 190: DELOC, DENRML, DEREFD (form 1).
pub(super) const PLANE_SCHEMA: Schema = Schema {
    entity: 190,
    name: "Plane Surface",
    fields: &[
        Field::one("DELOC", POINT),
        Field::one("DENRML", DIRECTION),
        Field::optional("DEREFD", DIRECTION),
    ],
};

/// 192: DELOC, DEAXIS, RADIUS, DEREFD (form 1).
pub(super) const CYLINDER_SCHEMA: Schema = Schema {
    entity: 192,
    name: "Right Circular Cylindrical Surface",
    fields: &[
        Field::one("DELOC", POINT),
        Field::one("DEAXIS", DIRECTION),
        Field::one("RADIUS", Type::Real),
        Field::optional("DEREFD", DIRECTION),
    ],
};

/// 194: DELOC, DEAXIS, RADIUS, SANGLE (degrees), DEREFD (form 1).
pub(super) const CONE_SCHEMA: Schema = Schema {
    entity: 194,
    name: "Right Circular Conical Surface",
    fields: &[
        Field::one("DELOC", POINT),
        Field::one("DEAXIS", DIRECTION),
        Field::one("RADIUS", Type::Real),
        Field::one("SANGLE", Type::Real),
        Field::optional("DEREFD", DIRECTION),
    ],
};

/// 196: DELOC, RADIUS, DEAXIS and DEREFD (form 1).
pub(super) const SPHERE_SCHEMA: Schema = Schema {
    entity: 196,
    name: "Spherical Surface",
    fields: &[
        Field::one("DELOC", POINT),
        Field::one("RADIUS", Type::Real),
        Field::optional("DEAXIS", DIRECTION),
        Field::optional("DEREFD", DIRECTION),
    ],
};

/// 198: DELOC, DEAXIS, MAJRAD, MINRAD, DEREFD (form 1).
pub(super) const TORUS_SCHEMA: Schema = Schema {
    entity: 198,
    name: "Toroidal Surface",
    fields: &[
        Field::one("DELOC", POINT),
        Field::one("DEAXIS", DIRECTION),
        Field::one("MAJRAD", Type::Real),
        Field::one("MINRAD", Type::Real),
        Field::optional("DEREFD", DIRECTION),
    ],
};

/// Entity 190, Plane Surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlaneSurface190 {
    /// DELOC: a point on the plane (116).
    pub location: i64,
    /// DENRML: the normal (123).
    pub normal: i64,
    /// DEREFD: the reference direction (123; 0 when absent).
    pub reference: i64,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for PlaneSurface190 {
    const SCHEMA: Schema = PLANE_SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        PlaneSurface190 {
            location: v.int("DELOC"),
            normal: v.int("DENRML"),
            reference: v.int("DEREFD"),
            form: entry.form,
        }
    }
}

/// Entity 192, Right Circular Cylindrical Surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder192 {
    /// DELOC: a point on the axis (116).
    pub location: i64,
    /// DEAXIS: the axis direction (123).
    pub axis: i64,
    /// RADIUS.
    pub radius: f64,
    /// DEREFD: the reference direction (0 when absent).
    pub reference: i64,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for Cylinder192 {
    const SCHEMA: Schema = CYLINDER_SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        Cylinder192 {
            location: v.int("DELOC"),
            axis: v.int("DEAXIS"),
            radius: v.real("RADIUS").unwrap_or(0.0),
            reference: v.int("DEREFD"),
            form: entry.form,
        }
    }
}

/// Entity 194, Right Circular Conical Surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone194 {
    /// DELOC: a point on the axis (116), where the radius is RADIUS.
    pub location: i64,
    /// DEAXIS: the axis direction (123).
    pub axis: i64,
    /// RADIUS at DELOC.
    pub radius: f64,
    /// SANGLE: the semi-angle in degrees.
    pub semi_angle_degrees: f64,
    /// DEREFD: the reference direction (0 when absent).
    pub reference: i64,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for Cone194 {
    const SCHEMA: Schema = CONE_SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        Cone194 {
            location: v.int("DELOC"),
            axis: v.int("DEAXIS"),
            radius: v.real("RADIUS").unwrap_or(0.0),
            semi_angle_degrees: v.real("SANGLE").unwrap_or(0.0),
            reference: v.int("DEREFD"),
            form: entry.form,
        }
    }
}

/// Entity 196, Spherical Surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere196 {
    /// DELOC: the centre (116).
    pub location: i64,
    /// RADIUS.
    pub radius: f64,
    /// DEAXIS: the axis (0 when absent, form 0).
    pub axis: i64,
    /// DEREFD: the reference direction (0 when absent).
    pub reference: i64,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for Sphere196 {
    const SCHEMA: Schema = SPHERE_SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        Sphere196 {
            location: v.int("DELOC"),
            radius: v.real("RADIUS").unwrap_or(0.0),
            axis: v.int("DEAXIS"),
            reference: v.int("DEREFD"),
            form: entry.form,
        }
    }
}

/// Entity 198, Toroidal Surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Torus198 {
    /// DELOC: the centre (116).
    pub location: i64,
    /// DEAXIS: the axis (123).
    pub axis: i64,
    /// MAJRAD, MINRAD.
    pub radii: [f64; 2],
    /// DEREFD: the reference direction (0 when absent).
    pub reference: i64,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for Torus198 {
    const SCHEMA: Schema = TORUS_SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        Torus198 {
            location: v.int("DELOC"),
            axis: v.int("DEAXIS"),
            radii: [
                v.real("MAJRAD").unwrap_or(0.0),
                v.real("MINRAD").unwrap_or(0.0),
            ],
            reference: v.int("DEREFD"),
            form: entry.form,
        }
    }
}
