//! The pipeline's error: a located diagnostic plus the class of failure, which decides the
//! CLI exit code and the HTTP status.

use crate::exchange::{Diagnostic, Location};

/// What kind of failure a [`PipelineError`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// The request itself is malformed (bad option, unknown entity id, bad parameter list).
    /// CLI exit 2, HTTP 400.
    Usage,
    /// The input is not a format nurbsx reads. CLI exit 1, HTTP 415.
    UnknownFormat,
    /// The input is unreadable or its geometry invalid. CLI exit 1, HTTP 422.
    Invalid,
    /// A configured limit was exceeded (size, counts, degree, points). CLI exit 1, HTTP 413.
    Limit,
    /// The operation cannot be done on this geometry within tolerance (reduction refused,
    /// verification failed). CLI exit 1, HTTP 422.
    Geometry,
}

/// A failure of a pipeline step, with the diagnostic that explains it.
#[derive(Debug, Clone, PartialEq)]
pub struct PipelineError {
    /// The class of failure.
    pub kind: ErrorKind,
    /// Code, message and location.
    pub diagnostic: Diagnostic,
}

impl PipelineError {
    /// A usage error with a stable code.
    pub fn usage(code: &str, message: impl Into<String>) -> Self {
        PipelineError {
            kind: ErrorKind::Usage,
            diagnostic: Diagnostic::error(code, message, Location::default()),
        }
    }

    /// An error of the given kind.
    pub fn new(
        kind: ErrorKind,
        code: &str,
        message: impl Into<String>,
        location: Location,
    ) -> Self {
        PipelineError {
            kind,
            diagnostic: Diagnostic::error(code, message, location),
        }
    }

    /// Wraps an exchange-layer diagnostic, classifying it by its code.
    pub fn from_exchange(d: Diagnostic) -> Self {
        let kind = if crate::exchange::NOT_EXCHANGE_CODES.contains(&d.code.as_ref()) {
            ErrorKind::UnknownFormat
        } else if d.code.starts_with("limit") {
            ErrorKind::Limit
        } else {
            ErrorKind::Invalid
        };
        PipelineError {
            kind,
            diagnostic: d,
        }
    }

    /// The stable code.
    pub fn code(&self) -> &str {
        &self.diagnostic.code
    }
}

impl std::fmt::Display for PipelineError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.diagnostic.fmt(f)
    }
}

impl std::error::Error for PipelineError {}

impl From<crate::nurbs::GeometryError> for PipelineError {
    fn from(e: crate::nurbs::GeometryError) -> Self {
        if matches!(e, crate::nurbs::GeometryError::Stopped) {
            return super::cancelled();
        }
        PipelineError::new(
            ErrorKind::Geometry,
            "geometry",
            e.to_string(),
            Location::default(),
        )
    }
}
