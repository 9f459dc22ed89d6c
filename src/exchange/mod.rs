//! # Format records <-> NURBS model
//!
//! The exchange layer turns the typed records of [`nurbsx_parsers`] into the exact NURBS
//! model of [`crate::nurbs`] and back, with every decision a CAD engineer needs to know
//! about reported as a [`Diagnostic`] rather than made silently: flags that disagree with
//! the data, units applied, trims not applied, entities that could not be read.
//!
//! - [`Document`]: what a file holds, in one form for both formats: the entities
//!   (geometry + provenance + metadata), the file's length unit, and the diagnostics.
//! - [`step`] and [`iges`]: `read(text, &ImportOptions) -> Result<Document, Diagnostic>` and
//!   `write(&Document, &ExportOptions) -> Result<String, Diagnostic>`.
//! - [`read`]: sniffs the format and dispatches.
//!
//! Per-entity problems never abort a file: the entity is skipped with an error diagnostic
//! and the others load. Only a file that cannot be read at all gives `Err`.

mod assembly;
mod diagnostic;
mod document;
pub mod iges;
mod options;
pub mod step;
#[cfg(test)]
pub(crate) mod test_documents;
#[cfg(test)]
pub(crate) mod test_files;
mod units;

pub use diagnostic::{Diagnostic, Location, Severity, Standing};
pub use document::{
    Document, Entity, Label, Meta, Origin, Origins, ParameterRange, PlacedInstance,
    ProductStructure, Shape, Source, Topology,
};
/// What content that is neither STEP nor IGES is (empty, UTF-16, a PDF ...): code and words.
pub use nurbsx_parsers::signature::{
    CODES as NOT_EXCHANGE_CODES, NotExchange, describe as describe_content,
};
pub use options::{Cancel, ExportOptions, ImportOptions, READ_POLL, StepSchema};
pub use units::LengthUnit;

pub use nurbsx_parsers::Format;

/// Reads a STEP or IGES file, choosing the reader from the content ([`Format::sniff`]).
///
/// The bytes must be ASCII/UTF-8 text; anything else is a located error.
pub fn read(bytes: &[u8], options: &ImportOptions) -> Result<Document, Diagnostic> {
    if bytes.len() > options.limits.max_input_bytes {
        return Err(Diagnostic::error(
            "limit.input_bytes",
            format!(
                "input is {} bytes, above the limit of {} bytes",
                bytes.len(),
                options.limits.max_input_bytes
            ),
            Location::default(),
        ));
    }
    let format = Format::sniff(bytes).ok_or_else(|| {
        let not = describe_content(bytes);
        Diagnostic::error(not.code, not.what, Location::at_line(1))
    })?;
    let (text, encoding) = text_of(bytes);
    let mut document = match format {
        Format::Step => step::read(&text, options),
        Format::Iges => iges::read(&text, options),
    }?;
    if !encoding.is_empty() {
        document.diagnostics.splice(0..0, encoding);
    }
    if options.conformance {
        let turned = solids_inside_out(&document.topology);
        document.diagnostics.extend(turned);
    }
    Ok(document)
}

/// The conformance check of the solids' orientation: a solid's outer shell faces away from
/// the solid and a void's shell into the void (ISO 10303-42 manifold_solid_brep and
/// brep_with_voids: the shell normals point away from the solid's material; IGES 5.3 186
/// with its shells' orientation flags). Each shell whose enclosed volume has the wrong sign
/// is a violation read as it is (the solid is still the region its shells bound).
/// Shells with a face that cannot be measured are not judged. The faces are measured once,
/// within the model's budget of evaluations ([`crate::topology::Model::totals`]).
fn solids_inside_out(topology: &Topology) -> Vec<Diagnostic> {
    let m = &topology.model;
    let mut out = Vec::new();
    if m.solids.is_empty() {
        return out;
    }
    let totals = m.totals();
    for (k, solid) in m.solids.iter().enumerate() {
        let shells =
            std::iter::once((solid.outer, true)).chain(solid.voids.iter().map(|&v| (v, false)));
        for (shell, outer) in shells {
            let volume = match m.shell_volume(shell, &totals.faces) {
                Ok(v) => v,
                Err(e) => {
                    // Not judged, but said: the face that could not be measured.
                    let origin = topology.origins.solids.get(k);
                    let (face, why) = match &e {
                        crate::topology::MeasureError::InFace { face, source } => {
                            (topology.origins.faces.get(*face), source.to_string())
                        }
                        _ => (None, e.to_string()),
                    };
                    out.push(
                        Diagnostic::warning(
                            "topology.unmeasured",
                            format!(
                                "solid {}: its orientation is not checked, a face could not be \
                             measured ({}{why})",
                                origin.map_or_else(|| (k + 1).to_string(), |o| o.id.to_string()),
                                face.map_or_else(String::new, |f| format!("face {}: ", f.id)),
                            ),
                            Location {
                                line: face.and_then(|o| o.source.line),
                                entity: face.map(|o| o.id.to_string()),
                                ..Location::default()
                            },
                        )
                        // A check nurbsx could not make, not a finding against the file.
                        .not_carried(),
                    );
                    continue;
                }
            };
            if (volume < 0.0) != outer {
                continue;
            }
            let origin = topology.origins.solids.get(k);
            let location = Location {
                line: origin.and_then(|o| o.source.line),
                entity: origin.map(|o| o.id.to_string()),
                ..Location::default()
            };
            let what = if outer {
                "its outer shell faces into the solid"
            } else {
                "a void's shell faces out of the void"
            };
            out.push(Diagnostic::nonconforming(
                "topology.inside_out",
                format!(
                    "solid {}: {what} (the shell encloses {volume:e} along its faces' normals); \
                     the shell normals must point away from the solid's material",
                    origin.map_or_else(|| (k + 1).to_string(), |o| o.id.to_string())
                ),
                location,
            ));
        }
    }
    out
}

/// Writes a document in the given format (what the writer says about it is left out: see
/// [`write_reporting`]).
pub fn write(
    document: &Document,
    format: Format,
    options: &ExportOptions,
) -> Result<String, Diagnostic> {
    write_reporting(document, format, options).map(|(text, _)| text)
}

/// Writes a document in the given format, and returns with the text what the writer says
/// about it: for STEP, how it wrote the document's assembly
/// ([`step::write_reporting`]); IGES says nothing here.
pub fn write_reporting(
    document: &Document,
    format: Format,
    options: &ExportOptions,
) -> Result<(String, Vec<Diagnostic>), Diagnostic> {
    let written = match format {
        Format::Step => step::write_reporting(document, options),
        Format::Iges => iges::write(document, options)
            .map(|text| (text, iges::write_warnings(document, options.iges_brep))),
    };
    // A stopped writer's text is partial, or its error stands for the stop.
    options.cancel.stop_write()?;
    written
}

/// Most byte-level encoding diagnostics reported one by one; the rest are counted.
const MAX_ENCODING_DIAGNOSTICS: usize = 20;

/// The input as text. ISO 10303-21 clause 5 and IGES 5.3 section 1.4 make both formats
/// 7/8-bit text whose strings carry other characters only through escapes (Part 21
/// `\X\`, `\X2\`) or Hollerith bytes; raw bytes that are not UTF-8 (a SolidWorks name in
/// GBK, a Latin-1 label) violate that, but they never decide geometry. Each such byte is
/// read as `?` (one byte for one, so every later line, column and Hollerith count stays
/// right), and each line holding some gets a non-conforming diagnostic at its first one:
/// `validate` fails, `convert` and `info` warn and read the geometry.
pub fn text_of(bytes: &[u8]) -> (std::borrow::Cow<'_, str>, Vec<Diagnostic>) {
    if let Ok(text) = std::str::from_utf8(bytes) {
        return (std::borrow::Cow::Borrowed(text), Vec::new());
    }
    let mut text = String::with_capacity(bytes.len());
    let mut diagnostics = Vec::new();
    let (mut line, mut line_start, mut reported_line, mut masked) = (1, 0, 0, 0usize);
    for chunk in bytes.utf8_chunks() {
        let valid = chunk.valid();
        for (i, b) in valid.bytes().enumerate() {
            if b == b'\n' {
                line += 1;
                line_start = text.len() + i + 1;
            }
        }
        text.push_str(valid);
        let bad = chunk.invalid();
        if bad.is_empty() {
            continue;
        }
        masked += bad.len();
        if reported_line != line {
            reported_line = line;
            if diagnostics.len() < MAX_ENCODING_DIAGNOSTICS {
                diagnostics.push(Diagnostic::nonconforming(
                    "encoding.not_utf8",
                    format!(
                        "byte 0x{:02X} at offset {} is not ASCII or UTF-8 (a name in a legacy encoding?); read as '?'",
                        bad[0],
                        text.len()
                    ),
                    Location {
                        line: Some(line),
                        column: Some(text.len() - line_start + 1),
                        ..Location::default()
                    },
                ));
            }
        }
        text.extend(std::iter::repeat_n('?', bad.len()));
    }
    if diagnostics.len() == MAX_ENCODING_DIAGNOSTICS {
        diagnostics.push(Diagnostic::nonconforming(
            "encoding.not_utf8",
            format!(
                "{masked} bytes in all are not ASCII or UTF-8; only the first {MAX_ENCODING_DIAGNOSTICS} lines holding them are listed"
            ),
            Location::default(),
        ));
    }
    (std::borrow::Cow::Owned(text), diagnostics)
}
