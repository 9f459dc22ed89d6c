//! Entity 502 form 1, Vertex List (IGES 5.3 section 4.143, the Vertex entity, and
//! 4.143.1).

use super::{Count, DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: `N`, then `N` points `X, Y, Z`.
pub(super) const SCHEMA: Schema = Schema {
    entity: 502,
    name: "Vertex List",
    fields: &[
        Field::one("N", Type::Integer),
        Field::times("X, Y, Z", Type::Point, Count::Field("N")),
    ],
};

/// Entity 502, Vertex List: the vertices a 504 Edge List and a 508 Loop index (from 1).
#[derive(Debug, Clone, PartialEq)]
pub struct VertexList502 {
    /// The vertices, in order.
    pub points: Vec<[f64; 3]>,
}

impl Entity for VertexList502 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        VertexList502 {
            points: v.points("X, Y, Z"),
        }
    }
}

impl WriteParams for VertexList502 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(502);
        w.int(super::count(self.points.len()));
        for p in &self.points {
            for &x in p {
                w.real(x)?;
            }
        }
        Ok(())
    }
}
