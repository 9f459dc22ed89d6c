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

/// Writes the document as STEP, IGES ([`write()`]) or model JSON ([`write_model_json`]).
pub fn write_as(
    doc: &Document,
    kind: InputKind,
    options: &ExportOptions,
) -> Result<String, PipelineError> {
    match kind.format() {
        Some(format) => {
            // 2-D curves have no place in IGES model space (see `drop_unwritable`).
            let mut doc = doc.clone();
            super::drop_unwritable(&mut doc, format);
            write(&doc, format, options)
        }
        None => write_model_json(doc),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::{Settings, load};

    const CURVE: &str = r#"{"degree":2,"knots":[0,0,0,1,1,1],"control_points":[[1,0],[1,1],[0,1]],"weights":[1,0.7071067811865476,1]}"#;
    const SURFACE: &str = r#"{"degree_u":1,"degree_v":1,"knots_u":[0,0,1,1],"knots_v":[0,0,1,1],"control_points":[[[0,0,0],[0,1,0.1]],[[1,0,0.3],[1,1,0]]]}"#;

    #[test]
    fn model_json_reloads_to_the_same_geometries() {
        let settings = Settings::default();
        for input in [CURVE.to_owned(), format!("[{CURVE},{SURFACE}]")] {
            let doc = load(input.as_bytes(), Some(InputKind::Json), &settings)
                .unwrap()
                .document;
            let text = write_as(&doc, InputKind::Json, &ExportOptions::default()).unwrap();
            // One entity: a single object; several: an array.
            assert_eq!(text.starts_with('['), doc.entities.len() > 1, "{text}");
            let again = load(text.as_bytes(), None, &settings).unwrap().document;
            let geometries = |d: &Document| {
                d.entities
                    .iter()
                    .map(|e| e.geometry.clone())
                    .collect::<Vec<_>>()
            };
            assert_eq!(geometries(&doc), geometries(&again));
        }
    }
}
