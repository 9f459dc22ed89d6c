//! Explicit resource limits for untrusted input.
//!
//! A converter that accepts uploads must bound the work and memory any single file can
//! cause. Every limit here is checked *before* the allocation or recursion it guards, and
//! exceeding one yields a located error, never a panic or an abort. The defaults suit a
//! service on a 2-core, 24 GiB machine; the CLI and the HTTP service can override each.

/// Resource limits applied by the STEP and IGES parsers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Limits {
    /// Largest input accepted, in bytes (default 2 GiB).
    pub max_input_bytes: usize,
    /// Most entity instances (STEP) or directory entries (IGES) in one file (default 50 million).
    pub max_entities: usize,
    /// Deepest nesting of parenthesised lists in a STEP parameter list (default 64, at most
    /// [`Limits::MAX_NESTING_DEPTH`]: the grammar recurses once per level, and a larger value
    /// is read as that ceiling). Real files nest at most 3 or 4 deep (a surface's weights
    /// are a list of lists).
    pub max_nesting_depth: usize,
    /// Most parameters in one instance or one IGES parameter record, counting list elements
    /// at every depth (default 50 million).
    pub max_params_per_entity: usize,
    /// Highest B-spline degree a typed record accepts (default 25, as Open CASCADE).
    pub max_degree: usize,
    /// Most control points in one curve, or in one surface (both directions multiplied)
    /// (default 25 million).
    pub max_poles: usize,
}

impl Limits {
    /// The ceiling of [`Limits::max_nesting_depth`]: 128 levels of the list rule fit in half
    /// of a 2 MiB thread stack (the default of rayon's and tokio's blocking threads), even
    /// in a debug build (tested).
    pub const MAX_NESTING_DEPTH: usize = 128;
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_input_bytes: 2 << 30,
            max_entities: 50_000_000,
            max_nesting_depth: 64,
            max_params_per_entity: 50_000_000,
            max_degree: 25,
            max_poles: 25_000_000,
        }
    }
}
