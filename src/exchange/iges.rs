//! IGES records <-> NURBS model (being written).

use super::{Diagnostic, Document, ExportOptions, ImportOptions, Location};

/// Reads every B-spline curve and surface of a IGES file.
pub fn read(_text: &str, _options: &ImportOptions) -> Result<Document, Diagnostic> {
    Err(Diagnostic::error(
        "unsupported",
        "IGES reading is being written",
        Location::default(),
    ))
}

/// Writes a document as a IGES file.
pub fn write(_document: &Document, _options: &ExportOptions) -> Result<String, Diagnostic> {
    Err(Diagnostic::error(
        "unsupported",
        "IGES writing is being written",
        Location::default(),
    ))
}
