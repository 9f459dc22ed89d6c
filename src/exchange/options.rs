//! Import and export policies.

use nurbsx_parsers::Limits;

use super::LengthUnit;

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
        }
    }
}
