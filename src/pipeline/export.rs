//! Writing a document as STEP, IGES or nurbsx model JSON (the modify commands keep the
//! input's form, and model JSON has no exchange writer of its own).

use crate::exchange::{Diagnostic, Document, ExportOptions};
use crate::nurbs::serde_form::KnotIntervalForm;

use super::{ErrorKind, InputKind, PipelineError, write};

/// How model JSON writes a curve's knots.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum KnotForm {
    /// `knots`: the knot vector.
    #[default]
    Vector,
    /// `knot_intervals` (seed 003, [`KnotIntervalForm`]); surfaces keep knot vectors.
    Intervals,
}

/// Writes the document's geometries as model JSON (`crate::nurbs` JSON form): a single
/// object when the document holds one entity, else an array, so that the output loads back
/// with [`load`](super::load) exactly as written (`f64` values print in shortest
/// round-trip form; knot intervals sum back to the same knots, see
/// [`crate::nurbs::knot_intervals`]).
pub fn write_model_json(doc: &Document, knots: KnotForm) -> Result<String, PipelineError> {
    let form = |g| match knots {
        KnotForm::Vector => serde_json::to_value(g),
        KnotForm::Intervals => serde_json::to_value(KnotIntervalForm(g)),
    };
    let result = match doc.entities.as_slice() {
        [one] => form(&one.geometry),
        many => many
            .iter()
            .map(|e| form(&e.geometry))
            .collect::<Result<Vec<_>, _>>()
            .map(serde_json::Value::Array),
    }
    .and_then(|v| serde_json::to_string_pretty(&v));
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

/// Writes the document as STEP, IGES ([`write()`]) or model JSON ([`write_model_json`],
/// curves' knots in the form `knots` says). Returns the text and what the writer says
/// about it ([`write()`]; nothing for model JSON). What the format cannot hold must have
/// been dropped and reported first ([`super::drop_unwritable`] on the caller's document,
/// whose diagnostics the user sees).
pub fn write_as(
    doc: &Document,
    kind: InputKind,
    options: &ExportOptions,
    knots: KnotForm,
) -> Result<(String, Vec<Diagnostic>), PipelineError> {
    match kind.format() {
        Some(format) => write(doc, format, options),
        None => write_model_json(doc, knots).map(|text| (text, Vec::new())),
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
            for form in [KnotForm::Vector, KnotForm::Intervals] {
                let (text, _) =
                    write_as(&doc, InputKind::Json, &ExportOptions::default(), form).unwrap();
                // One entity: a single object; several: an array.
                assert_eq!(text.starts_with('['), doc.entities.len() > 1, "{text}");
                assert_eq!(text.contains("knot_intervals"), form == KnotForm::Intervals);
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
}
