//! A request's stop signal. Long operations (evaluation batches, tessellation, operations
//! over many entities, conversion stages) poll it at bounded intervals and stop with the
//! error [`Cancel::check`] gives, so work whose result nobody waits for frees its thread.

use std::sync::Arc;

use super::{ErrorKind, PipelineError};

/// The stop test of one request; the default never fires (the CLI).
#[derive(Clone, Default)]
pub struct Cancel(Option<Arc<dyn Fn() -> bool + Send + Sync>>);

impl Cancel {
    /// A signal that fires when `stop` returns true.
    pub fn new(stop: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        Cancel(Some(Arc::new(stop)))
    }

    /// Whether the work should stop now.
    pub fn is_set(&self) -> bool {
        self.0.as_ref().is_some_and(|stop| stop())
    }

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

impl std::fmt::Debug for Cancel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() {
            "Cancel(armed)"
        } else {
            "Cancel(never)"
        })
    }
}
