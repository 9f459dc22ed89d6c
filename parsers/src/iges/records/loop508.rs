//! Entity 508, Loop (IGES 5.3 section 4.145).

use super::{CURVES, Count, DirectoryEntry, Entity, Field, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: `N`, then per edge TYPE, EDGE, NDX, OF, K and `K` pairs ISOP, CURV
/// (the edge's curves in the parameter space of the face's surface).
pub(super) const SCHEMA: Schema = Schema {
    entity: 508,
    name: "Loop",
    fields: &[
        Field::one("N", Type::Integer),
        Field::group(
            "edge",
            Count::Field("N"),
            &[
                Field::one("TYPE", Type::Flag),
                Field::one("EDGE", Type::Pointer(&[504, 502])),
                Field::one("NDX", Type::Flag),
                Field::one("OF", Type::Flag),
                Field::one("K", Type::Integer),
                Field::group(
                    "parameter curve",
                    Count::Field("K"),
                    &[
                        Field::one("ISOP", Type::Flag),
                        Field::one("CURV", Type::Pointer(CURVES)),
                    ],
                ),
            ],
        ),
    ],
};

/// One edge use of a 508.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoopEdge {
    /// TYPE: 0 an edge of a 504 Edge List, 1 a vertex of a 502 Vertex List.
    pub kind: i64,
    /// EDGE: the 504 (or 502).
    pub edge: i64,
    /// NDX: the index into that list.
    pub index: i64,
    /// OF: 1 when the edge is used in its own direction.
    pub orientation: i64,
    /// `(ISOP, CURV)` pairs: the parameter-space curves and whether each is isoparametric.
    pub parameter_curves: Vec<(i64, i64)>,
}

/// Entity 508, Loop.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Loop508 {
    /// The edge uses, in order.
    pub edges: Vec<LoopEdge>,
}

impl Entity for Loop508 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        Loop508 {
            edges: v
                .groups("edge")
                .into_iter()
                .map(|mut e| LoopEdge {
                    kind: e.int("TYPE"),
                    edge: e.int("EDGE"),
                    index: e.int("NDX"),
                    orientation: e.int("OF"),
                    parameter_curves: e
                        .groups("parameter curve")
                        .into_iter()
                        .map(|mut p| (p.int("ISOP"), p.int("CURV")))
                        .collect(),
                })
                .collect(),
        }
    }
}

impl WriteParams for Loop508 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        w.int(508);
        w.int(super::count(self.edges.len()));
        for e in &self.edges {
            for x in [e.kind, e.edge, e.index, e.orientation] {
                w.int(x);
            }
            w.int(super::count(e.parameter_curves.len()));
            for &(isop, curve) in &e.parameter_curves {
                w.int(isop);
                w.int(curve);
            }
        }
        Ok(())
    }
}
