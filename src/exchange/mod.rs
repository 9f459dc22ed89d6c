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

pub use diagnostic::{Diagnostic, Location, Severity};
pub use document::{Document, Entity, Meta, ParameterRange, Shape, Source};
pub use options::{ExportOptions, ImportOptions, StepSchema};
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
        Diagnostic::error(
            "format.unknown",
            "neither a STEP file (ISO-10303-21;) nor an IGES file (S/G in column 73)",
            Location::at_line(1),
        )
    })?;
    let text = text_of(bytes)?;
    match format {
        Format::Step => step::read(text, options),
        Format::Iges => iges::read(text, options),
    }
}

/// Writes a document in the given format.
pub fn write(
    document: &Document,
    format: Format,
    options: &ExportOptions,
) -> Result<String, Diagnostic> {
    match format {
        Format::Step => step::write(document, options),
        Format::Iges => iges::write(document, options),
    }
}

/// Checks that input bytes are UTF-8 text, naming the line and column of the first bad byte.
pub fn text_of(bytes: &[u8]) -> Result<&str, Diagnostic> {
    std::str::from_utf8(bytes).map_err(|e| {
        let good = &bytes[..e.valid_up_to()];
        let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
        let column = good.len() - good.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1) + 1;
        Diagnostic::error(
            "encoding.not_utf8",
            format!(
                "byte {} is not valid UTF-8/ASCII text (NUL bytes, UTF-16 and binary data are refused)",
                e.valid_up_to()
            ),
            Location {
                line: Some(line),
                column: Some(column),
                ..Location::default()
            },
        )
    })
}
