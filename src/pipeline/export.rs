//! Writing a document as STEP, IGES or nurbsx model JSON (the modify commands keep the
//! input's form, and model JSON has no exchange writer of its own).

use crate::exchange::{Document, ExportOptions};
use crate::nurbs::Geometry;

use super::{ErrorKind, InputKind, PipelineError, write};

/// Writes the document's geometries as model JSON (`crate::nurbs` JSON form): a single
/// object when the document holds one entity, else an array, so that the output loads back
/// with [`load`](super::load) exactly as written (`f64` values print in shortest
/// round-trip form).
pub fn write_model_json(doc: &Document) -> Result<String, PipelineError> {
    let result = match doc.entities.as_slice() {
        [one] => serde_json::to_string_pretty(&one.geometry),
        many => serde_json::to_string_pretty(
            &many.iter().map(|e| &e.geometry).collect::<Vec<&Geometry>>(),
        ),
    };
    result
        .map(|mut text| {
            text.push('\n');
            text
        })
        .map_err(|e| {
            PipelineError::new(
                ErrorKind::Geometry,
                "json.write",
                format!("cannot write model JSON: {e}"),
                Default::default(),
            )
        })
}

/// Writes the document as STEP, IGES ([`write`]) or model JSON ([`write_model_json`]).
pub fn write_as(
    doc: &Document,
    kind: InputKind,
    options: &ExportOptions,
) -> Result<String, PipelineError> {
    match kind.format() {
        Some(format) => write(doc, format, options),
        None => write_model_json(doc),
    }
}
