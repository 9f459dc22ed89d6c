//! Entity 124, Transformation Matrix (IGES 5.3 section 4.21).

use super::{DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

const NAMES: [&str; 12] = [
    "R11", "R12", "R13", "T1", "R21", "R22", "R23", "T2", "R31", "R32", "R33", "T3",
];

/// The declaration: twelve reals, row by row.
pub(super) const SCHEMA: Schema = Schema {
    entity: 124,
    name: "Transformation Matrix",
    fields: &[
        Field::one(NAMES[0], Type::Real),
        Field::one(NAMES[1], Type::Real),
        Field::one(NAMES[2], Type::Real),
        Field::one(NAMES[3], Type::Real),
        Field::one(NAMES[4], Type::Real),
        Field::one(NAMES[5], Type::Real),
        Field::one(NAMES[6], Type::Real),
        Field::one(NAMES[7], Type::Real),
        Field::one(NAMES[8], Type::Real),
        Field::one(NAMES[9], Type::Real),
        Field::one(NAMES[10], Type::Real),
        Field::one(NAMES[11], Type::Real),
    ],
};

/// Entity 124, Transformation Matrix (IGES 5.3 section 4.21): `x' = R x + T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform124 {
    /// Rows `[R11 R12 R13 T1], [R21 R22 R23 T2], [R31 R32 R33 T3]`.
    pub rows: [[f64; 4]; 3],
    /// Form number: 0/1 transforms, 10-12 coordinate systems.
    pub form: i64,
}

impl Transform124 {
    /// Applies the map to a point: `R x + T`.
    pub fn apply(&self, x: [f64; 3]) -> [f64; 3] {
        let r = &self.rows;
        [
            r[0][0] * x[0] + r[0][1] * x[1] + r[0][2] * x[2] + r[0][3],
            r[1][0] * x[0] + r[1][1] * x[1] + r[1][2] * x[2] + r[1][3],
            r[2][0] * x[0] + r[2][1] * x[1] + r[2][2] * x[2] + r[2][3],
        ]
    }

    /// Applies the rotation part only (for directions such as a plane normal).
    pub fn apply_linear(&self, x: [f64; 3]) -> [f64; 3] {
        let r = &self.rows;
        [
            r[0][0] * x[0] + r[0][1] * x[1] + r[0][2] * x[2],
            r[1][0] * x[0] + r[1][1] * x[1] + r[1][2] * x[2],
            r[2][0] * x[0] + r[2][1] * x[1] + r[2][2] * x[2],
        ]
    }
}

impl Entity for Transform124 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        let mut rows = [[0.0; 4]; 3];
        for (k, name) in NAMES.iter().enumerate() {
            rows[k / 4][k % 4] = v.real(name).unwrap_or(0.0);
        }
        Transform124 {
            rows,
            form: entry.form,
        }
    }
}

impl WriteParams for Transform124 {
    /// The twelve reals, row by row.
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(124);
        for &x in self.rows.iter().flatten() {
            w.real(x)?;
        }
        Ok(())
    }
}
