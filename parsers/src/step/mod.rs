//! # ISO 10303-21 (STEP Part 21) exchange structures
//!
//! - `grammar` (private): the Part 21 rules as nom parsers, each named after its
//!   production; [`scan`], [`Scanned::decode`] and [`parse`] run them.
//! - [`scan`]: one pass over the file: header decoded, every entity instance located
//!   (`#id`, keyword, body slice) with `memchr`, an `#id` index; parameters decoded lazily
//!   with [`Scanned::decode`]. This is what a reader that needs a few entity types uses.
//! - [`parse`]: scan + decode everything into an [`Exchange`] (the borrowed syntax tree),
//!   with references checked.
//! - [`schema`]: typed records for the ISO 10303-42 B-spline entities, `CARTESIAN_POINT`,
//!   the unit entities and the representation context, read by attribute *name* from the
//!   EXPRESS definitions (so simple and complex instances, in any partial order, read the
//!   same).
//!   Its decoders of raw instances, [`Scanned::bspline`] and [`Scanned::cartesian_point`],
//!   read the shapes Open CASCADE, FreeCAD and nurbsx write straight from the body text in
//!   one pass (a private fast path inside each) and everything else through the grammar.
//! - [`geometry`]: typed records of the other ISO 10303-42 entities a B-rep's geometry is
//!   made of (placements, lines, conics, polylines, trimmed and composite curves, surface
//!   curves and pcurves, elementary and swept surfaces, rectangular trimmed surfaces) and of
//!   the topology that bounds them (vertex points, edge curves, loops, faces), through the
//!   same attribute tables; [`Scanned::geometry_item`] decodes one.
//! - [`product`]: typed records of the product and representation structure that places
//!   parts in an assembly (next_assembly_usage_occurrence, the representation relationships
//!   with their transformations, mapped items); [`Scanned::product_item`] decodes one.
//! - [`upper_case_keywords`]: a copy of a file with lower-case keywords (not conforming,
//!   clause 6.4) upper-cased, each located, for a reader that reads them anyway.
//! - [`writer`]: Part 21 text from a tree; [`Builder`] creates instances with fresh ids.
//!
//! Errors: [`ParseError`] (syntax/structure: line, column, `#id`), [`SchemaError`] (a
//! record's attribute: `#id`, entity, attribute index and name, expected vs found).

mod ast;
mod bspline_text;
mod error;
pub mod geometry;
mod geometry_text;
mod grammar;
mod instance_text;
mod keyword_case;
mod keyword_run;
pub mod product;
mod scan;
pub mod schema;
mod specials;
mod string;
#[cfg(test)]
mod test_files;
pub mod writer;

pub use ast::{Body, DataSection, Exchange, Instance, Parameter, Record, schema_names};
pub use error::{LineIndex, ParseError, ParseErrorKind, SchemaError};
pub use keyword_case::upper_case_keywords;
pub use scan::{
    Parsed, RawInstance, Scanned, SectionInfo, for_each_reference, parse, scan, scan_parallel,
};
pub use string::{StepString, StringError, encode_string};
pub use writer::{Builder, write_exchange};
