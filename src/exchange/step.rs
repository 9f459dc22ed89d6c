//! STEP records <-> NURBS model (being written).

use super::{Diagnostic, Document, ExportOptions, ImportOptions, Location};

/// Reads every B-spline curve and surface of a STEP file.
pub fn read(_text: &str, _options: &ImportOptions) -> Result<Document, Diagnostic> {
    Err(Diagnostic::error(
        "unsupported",
        "STEP reading is being written",
        Location::default(),
    ))
}

/// Writes a document as a STEP file.
pub fn write(_document: &Document, _options: &ExportOptions) -> Result<String, Diagnostic> {
    Err(Diagnostic::error(
        "unsupported",
        "STEP writing is being written",
        Location::default(),
    ))
}
