//! Entity 504, Edge List (IGES 5.3 section 4.144, the Edge entity, and 4.144.1).

use super::{CURVES, Count, DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: `N`, then per edge CURV, SVP, SV, TVP, TV.
pub(super) const SCHEMA: Schema = Schema {
    entity: 504,
    name: "Edge List",
    fields: &[
        Field::one("N", Type::Integer),
        Field::group(
            "edge",
            Count::Field("N"),
            &[
                Field::one("CURV", Type::Pointer(CURVES)),
                Field::one("SVP", Type::Pointer(&[502])),
                Field::one("SV", Type::Flag),
                Field::one("TVP", Type::Pointer(&[502])),
                Field::one("TV", Type::Flag),
            ],
        ),
    ],
};

/// One edge of a 504: its model-space curve and its start and end vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// CURV: the model-space curve.
    pub curve: i64,
    /// SVP, SV: the start vertex (a 502 Vertex List and an index into it).
    pub start: (i64, i64),
    /// TVP, TV: the end vertex.
    pub end: (i64, i64),
}

/// Entity 504, Edge List.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EdgeList504 {
    /// The edges.
    pub edges: Vec<Edge>,
}

impl Entity for EdgeList504 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        EdgeList504 {
            edges: v
                .groups("edge")
                .into_iter()
                .map(|mut e| Edge {
                    curve: e.int("CURV"),
                    start: (e.int("SVP"), e.int("SV")),
                    end: (e.int("TVP"), e.int("TV")),
                })
                .collect(),
        }
    }
}

impl WriteParams for EdgeList504 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(504);
        w.int(super::count(self.edges.len()));
        for e in &self.edges {
            for x in [e.curve, e.start.0, e.start.1, e.end.0, e.end.1] {
                w.int(x);
            }
        }
        Ok(())
    }
}
