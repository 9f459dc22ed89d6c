//! The caller's stop signal, polled by the syntax scans.
//!
//! A service gives each request a time limit; the scans that split a file into statements
//! (STEP) or records (IGES) run before any decoding, so they poll the signal too, every
//! [`SCAN_POLL`] statements or lines, and end with a `Stopped` error once it has fired.

/// A stop signal: a function that returns true once the work should stop (it stays true).
/// [`Stop::NEVER`] never fires. Shared by the scan's threads, hence `Sync`.
#[derive(Clone, Copy, Default)]
pub struct Stop<'a>(Option<&'a (dyn Fn() -> bool + Sync)>);

impl<'a> Stop<'a> {
    /// The signal that never fires.
    pub const NEVER: Stop<'static> = Stop(None);

    /// A signal that fires when `stop` returns true.
    pub fn new(stop: &'a (dyn Fn() -> bool + Sync)) -> Self {
        Stop(Some(stop))
    }

    /// Whether the work should stop now.
    #[inline]
    pub fn is_set(&self) -> bool {
        self.0.is_some_and(|stop| stop())
    }

    /// Whether the work should stop after item `count` (polls at every [`SCAN_POLL`]th).
    #[inline]
    pub fn at(&self, count: usize) -> bool {
        count % SCAN_POLL == 0 && self.is_set()
    }
}

impl std::fmt::Debug for Stop<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() {
            "Stop(armed)"
        } else {
            "Stop(never)"
        })
    }
}

/// Statements (STEP) or lines (IGES) scanned between two polls of the signal: a poll is an
/// atomic load or two, a statement's scan tens of nanoseconds at least.
pub const SCAN_POLL: usize = 4096;
