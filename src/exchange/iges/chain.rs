//! 124 Transformation Matrix chains (IGES 5.3 section 4.21; spec.md b.3): an entity's DE
//! field 7 points at a 124, whose own field 7 may point at another 124, and so on. The maps
//! apply innermost first: `x' = T_k(... T_2(T_1(x)))`. Walking is iterative, bounded by
//! `Limits::max_nesting_depth`, with cycle detection.

use nurbsx_parsers::iges::records::Transform124;
use nurbsx_parsers::iges::{IgesFile, ParseError};

/// Why a chain could not be resolved.
#[derive(Debug, Clone)]
pub enum ChainError {
    /// The chain comes back to an entry already visited.
    Cycle(usize),
    /// A pointer names no directory entry.
    BadPointer(i64),
    /// A pointer names an entity that is not a 124.
    NotTransform {
        /// DE pointer.
        de: usize,
        /// Its type.
        entity_type: i64,
    },
    /// A 124 in the chain could not be read.
    Parse(ParseError),
    /// The chain is longer than the nesting limit (real files chain a few matrices; a
    /// longer chain is treated as hostile, since every entity using it would pay for it).
    TooDeep(usize),
}

impl std::fmt::Display for ChainError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ChainError::Cycle(de) => write!(f, "the 124 transformation chain loops back to D{de}"),
            ChainError::BadPointer(p) => {
                write!(
                    f,
                    "transformation matrix pointer {p} names no directory entry"
                )
            }
            ChainError::NotTransform { de, entity_type } => write!(
                f,
                "transformation matrix pointer names D{de}, a type {entity_type} entity, not a 124"
            ),
            ChainError::Parse(e) => write!(f, "transformation matrix unreadable: {e}"),
            ChainError::TooDeep(n) => {
                write!(
                    f,
                    "the 124 transformation chain is longer than the limit of {n}"
                )
            }
        }
    }
}

/// The 124 maps to apply, innermost first, with their DE pointers.
pub fn resolve(
    file: &IgesFile<'_>,
    first: i64,
    max_depth: usize,
) -> Result<Vec<(usize, Transform124)>, ChainError> {
    let mut out: Vec<(usize, Transform124)> = Vec::new();
    let mut next = first;
    while next != 0 {
        if out.len() >= max_depth {
            return Err(ChainError::TooDeep(max_depth));
        }
        let entry = file.entry(next).ok_or(ChainError::BadPointer(next))?;
        if out.iter().any(|(de, _)| *de == entry.pointer) {
            return Err(ChainError::Cycle(entry.pointer));
        }
        if entry.entity_type != 124 {
            return Err(ChainError::NotTransform {
                de: entry.pointer,
                entity_type: entry.entity_type,
            });
        }
        let t = file
            .decode::<Transform124>(entry)
            .record
            .map_err(ChainError::Parse)?;
        out.push((entry.pointer, t));
        // The visited check above bounds the loop by the number of entries.
        next = entry.transform;
    }
    Ok(out)
}
