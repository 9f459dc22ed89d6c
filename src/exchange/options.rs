//! Import and export policies, and the stop signal long work polls.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use nurbsx_parsers::{Limits, Stop};

use super::{Diagnostic, LengthUnit, Location};

/// A request's stop signal; the default never fires (the CLI). Long work (the readers'
/// loops here, the pipeline's operations) polls it at bounded intervals and stops once it
/// has fired; it stays fired.
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

    /// For a reader: `Err` (code `cancelled`) once the signal has fired.
    pub(crate) fn stop_read(&self) -> Result<(), Diagnostic> {
        self.stop("reading")
    }

    /// For a writer: `Err` (code `cancelled`) once the signal has fired. The writers poll it
    /// before each curve and surface and skip (STEP) or end (IGES) the rest once it has;
    /// `exchange::write` then answers this error instead of the partial text.
    pub(crate) fn stop_write(&self) -> Result<(), Diagnostic> {
        self.stop("writing")
    }

    fn stop(&self, what: &str) -> Result<(), Diagnostic> {
        if self.is_set() {
            return Err(Diagnostic::error(
                "cancelled",
                format!("{what} was stopped: its request timed out or the server is shutting down"),
                Location::default(),
            ));
        }
        Ok(())
    }

    /// The signal as the parsers' syntax scans poll it.
    pub(crate) fn scan_stop(&self) -> Stop<'_> {
        match &self.0 {
            Some(stop) => Stop::new(&**stop),
            None => Stop::NEVER,
        }
    }

    /// For a reader's parallel loop: whether to skip item `index` because the signal has
    /// fired. Polls it at every [`READ_POLL`]th index (each thread takes a run of
    /// consecutive items, so it polls at least every [`READ_POLL`] of its items) and keeps
    /// the answer in `stopped`, shared by the loop's threads; the caller calls
    /// [`Cancel::stop_read`] after the loop.
    pub(crate) fn skip(&self, index: usize, stopped: &AtomicBool) -> bool {
        if index % READ_POLL == 0 && self.is_set() {
            stopped.store(true, Ordering::Relaxed);
        }
        stopped.load(Ordering::Relaxed)
    }
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

/// Instances (STEP) or entries (IGES) a reader handles between two polls of the stop
/// signal: a poll costs far less than one instance's decoding.
pub const READ_POLL: usize = 4096;

/// How to read a file.
#[derive(Debug, Clone, Default)]
pub struct ImportOptions {
    /// Resource limits for the parsers (bytes, entities, nesting, degree, poles).
    pub limits: Limits,
    /// Convert coordinates to this unit (`None`: keep the file's unit). Either way the
    /// document reports its unit and a diagnostic says what was applied.
    pub target_units: Option<LengthUnit>,
    /// IGES: trim curves and surfaces to their declared parameter range `V(0)..V(1)` /
    /// `U(0)..V(1)` (by knot insertion, exact). Off by default: the range is kept in
    /// [`Meta::parameter_range`](super::Meta::parameter_range).
    pub trim_to_parameter_range: bool,
    /// Read the curves and surfaces only, as loose geometry: no faces, loops, edges,
    /// shells, solids or assembly placements ([`Document::topology`](super::Document)
    /// stays empty, and a warning says what was left out).
    pub geometry_only: bool,
    /// IGES: how close boundary curve ends must be to join into loops, and the boundaries of
    /// trimmed faces (144) to be sewn into shared edges (`None`: the file's resolution,
    /// Global parameter 19, or 1e-7 of the model's size, whichever is larger).
    pub sew_tolerance: Option<f64>,
    /// Also check what reading does not need (the conformance check `validate` runs):
    /// STEP: every instance of the file decoded, its attribute count checked where the
    /// schema tables know the entity, its references resolved and free of cycles, not only
    /// the instances the geometry uses.
    pub conformance: bool,
    /// The stop signal the read loops poll (every [`READ_POLL`] items and between stages);
    /// a stopped read is `Err` with code `cancelled`. The pipeline sets it from its own.
    pub cancel: Cancel,
}

/// The STEP application protocol to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StepSchema {
    /// AP203 `CONFIG_CONTROL_DESIGN`.
    Ap203,
    /// AP214 `AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }` (the default, as Open CASCADE).
    #[default]
    Ap214,
    /// AP242 `AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF { 1 0 10303 442 1 1 4 }`.
    Ap242,
}

/// How to write a file.
#[derive(Debug, Clone)]
pub struct ExportOptions {
    /// STEP schema.
    pub schema: StepSchema,
    /// Unit to write in (`None`: the document's unit). Coordinates are scaled exactly once
    /// and the file declares the unit its numbers are in.
    pub units: Option<LengthUnit>,
    /// STEP: write BEZIER_/UNIFORM_/QUASI_UNIFORM_ subtypes where the knots are exactly
    /// those the subtype implies (Open CASCADE never writes them; off by default).
    pub use_implicit_knot_subtypes: bool,
    /// Time stamp written in STEP FILE_NAME and IGES Global parameters 18/25
    /// (ISO 8601 `YYYY-MM-DDTHH:MM:SS`). `None`: the current UTC time.
    pub timestamp: Option<String>,
    /// File name written in the header.
    pub file_name: String,
    /// IGES: write solids and shells as 186 manifold solid B-rep objects with
    /// 502/504/508/510/514 (as Open CASCADE's B-rep mode) instead of 144 trimmed surfaces
    /// with 142 boundaries (the default, which every IGES reader understands).
    pub iges_brep: bool,
    /// STEP: write an assembly's placed parts in root coordinates, each instance's copy
    /// on its own (one product), instead of its product structure (each part once, placed
    /// by next_assembly_usage_occurrence; the default).
    pub flatten_assemblies: bool,
    /// The stop signal the writers poll (before each curve and surface); a stopped write
    /// is `Err` with code `cancelled`. The pipeline sets it from its own.
    pub cancel: Cancel,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            schema: StepSchema::Ap214,
            units: None,
            use_implicit_knot_subtypes: false,
            timestamp: None,
            file_name: "nurbsx-output".to_owned(),
            iges_brep: false,
            flatten_assemblies: false,
            cancel: Cancel::default(),
        }
    }
}
