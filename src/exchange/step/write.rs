//! Document -> STEP file (filled in below).

use crate::exchange::{Diagnostic, Document, ExportOptions, Location};

/// Writes a document as a STEP file.
pub fn write(_document: &Document, _options: &ExportOptions) -> Result<String, Diagnostic> {
    Err(Diagnostic::error(
        "unsupported",
        "STEP writing is being written",
        Location::default(),
    ))
}
