//! A request's stop signal ([`Cancel`], defined with the import options so the readers can
//! poll it too). Long operations (evaluation batches, tessellation, elevation, operations
//! over many entities, reading, conversion stages) poll it at bounded intervals and stop
//! with the error [`Cancel::check`] gives, so work whose result nobody waits for frees its
//! thread.

pub use crate::exchange::Cancel;

use super::{ErrorKind, PipelineError};

impl Cancel {
    /// `Err` with code `cancelled` once the signal has fired.
    pub fn check(&self) -> Result<(), PipelineError> {
        if self.is_set() {
            return Err(cancelled());
        }
        Ok(())
    }
}

/// The error of stopped work (code `cancelled`, kind [`ErrorKind::Limit`]: the request ran
/// out of its time budget).
pub fn cancelled() -> PipelineError {
    PipelineError::new(
        ErrorKind::Limit,
        "cancelled",
        "the work was stopped: its request timed out or the server is shutting down",
        Default::default(),
    )
}
