//! Entity 106, Copious Data (IGES 5.3 section 4.6), forms 1-3; the Linear Path forms 11-13
//! (section 4.7) and the Simple Closed Planar Curve form 63 (section 4.11).

use super::{Count, DirectoryEntry, Entity, Field, Head, Schema, Type, Values};

/// Reals per data point for the interpretation flag IP: 1 `x, y` pairs (common `ZT`),
/// 2 `x, y, z` triples, 3 sextuples `x, y, z, i, j, k` (point and vector).
fn width(h: &Head) -> Result<usize, String> {
    match h.get("IP")? {
        1 => Ok(2),
        2 => Ok(3),
        3 => Ok(6),
        ip => Err(format!("IP = {ip}; IGES 5.3 allows 1, 2 or 3")),
    }
}

/// The declaration: IP, N, then ZT when `IP = 1`, then `N` tuples of the width IP says.
pub(super) const SCHEMA: Schema = Schema {
    entity: 106,
    name: "Copious Data",
    fields: &[
        Field::one("IP", Type::Integer),
        Field::one("N", Type::Integer),
        Field::times(
            "ZT",
            Type::Real,
            Count::Formula {
                formula: "1 if IP = 1 else 0",
                of: |h| width(h).map(|w| usize::from(w == 2)),
            },
        ),
        Field::times(
            "data",
            Type::Real,
            Count::Formula {
                formula: "N x (2, 3 or 6 by IP)",
                of: |h| {
                    let w = width(h)?;
                    h.count("N")?
                        .checked_mul(w)
                        .ok_or_else(|| "106 parameter count overflows".to_owned())
                },
            },
        ),
    ],
};

/// Entity 106, Copious Data: the points (with `z = ZT` for `IP = 1`) and, for `IP = 3`, the
/// vectors.
#[derive(Debug, Clone, PartialEq)]
pub struct CopiousData106 {
    /// IP: 1 pairs, 2 triples, 3 sextuples.
    pub ip: i64,
    /// The points (definition space).
    pub points: Vec<[f64; 3]>,
    /// The vectors of `IP = 3` (empty otherwise).
    pub vectors: Vec<[f64; 3]>,
    /// The form number (DE field 15).
    pub form: i64,
}

impl Entity for CopiousData106 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, entry: &DirectoryEntry) -> Self {
        let ip = v.int("IP");
        let zt = v.reals("ZT").first().copied().unwrap_or(0.0);
        let data = v.reals("data");
        let (points, vectors) = match ip {
            1 => (
                data.chunks_exact(2).map(|c| [c[0], c[1], zt]).collect(),
                Vec::new(),
            ),
            2 => (
                data.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
                Vec::new(),
            ),
            _ => data
                .chunks_exact(6)
                .map(|c| ([c[0], c[1], c[2]], [c[3], c[4], c[5]]))
                .unzip(),
        };
        CopiousData106 {
            ip,
            points,
            vectors,
            form: entry.form,
        }
    }
}
