//! The machine-readable reports the pipeline returns (serialised as JSON by the CLI with
//! `--json` and by the HTTP service).

use serde::Serialize;

use crate::exchange::{Diagnostic, Severity, Source};
use crate::nurbs::{Geometry, Point3};

/// `nurbsx info --json` / `POST /v1/info`.
#[derive(Debug, Clone, Serialize)]
pub struct InfoReport {
    /// `step`, `iges` or `json`.
    pub format: String,
    /// STEP FILE_SCHEMA / IGES version.
    pub schema: Option<String>,
    /// The length unit the coordinates are in.
    pub units: UnitsInfo,
    /// Every B-spline entity.
    pub entities: Vec<EntityInfo>,
    /// What the reader noticed.
    pub diagnostics: Vec<Diagnostic>,
}

/// A length unit by name and factor.
#[derive(Debug, Clone, Serialize)]
pub struct UnitsInfo {
    /// `mm`, `in`, ...
    pub name: String,
    /// Millimetres per unit.
    pub to_mm: f64,
}

/// One entity in an [`InfoReport`].
#[derive(Debug, Clone, Serialize)]
pub struct EntityInfo {
    /// `#17` (STEP) or `D5` (IGES).
    pub id: String,
    /// `curve` or `surface`.
    pub kind: &'static str,
    /// 2 or 3.
    pub dimension: usize,
    /// `[p]` for curves, `[p, q]` for surfaces.
    pub degree: Vec<usize>,
    /// `[n]` poles for curves, `[nu, nv]` for surfaces.
    pub poles: Vec<usize>,
    /// Whether weights are present.
    pub rational: bool,
    /// The knot layout per direction (`clamped`, `unclamped`, `uniform`, `quasi-uniform`,
    /// `piecewise-bezier`, `periodic`).
    pub layout: Vec<String>,
    /// The valid domain per direction.
    pub domain: Vec<(f64, f64)>,
    /// The exact geometry (model JSON).
    pub geometry: Geometry,
    /// The source entity and line.
    pub source: Source,
}

/// `nurbsx validate` / `POST /v1/validate` for one file.
#[derive(Debug, Clone, Serialize)]
pub struct ValidationReport {
    /// Whether the file passed (no errors; with `strict`, no warnings either).
    pub valid: bool,
    /// Entities read.
    pub entities: usize,
    /// Counts by severity.
    pub errors: usize,
    /// Warnings.
    pub warnings: usize,
    /// Everything found.
    pub diagnostics: Vec<Diagnostic>,
}

impl ValidationReport {
    /// Builds the report from diagnostics; `strict` makes warnings fail too.
    pub fn new(entities: usize, diagnostics: Vec<Diagnostic>, strict: bool) -> Self {
        let errors = diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count();
        let warnings = diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Warning)
            .count();
        ValidationReport {
            valid: errors == 0 && (!strict || warnings == 0),
            entities,
            errors,
            warnings,
            diagnostics,
        }
    }
}

/// `nurbsx convert --report` / the service's conversion report.
#[derive(Debug, Clone, Serialize)]
pub struct ConvertReport {
    /// Input format name.
    pub input_format: String,
    /// Output format name.
    pub output_format: String,
    /// Entities read.
    pub entities_in: usize,
    /// Entities written.
    pub entities_out: usize,
    /// Unit written.
    pub units: UnitsInfo,
    /// Reader and writer diagnostics.
    pub diagnostics: Vec<Diagnostic>,
    /// With verification: the largest deviation per entity after re-reading the output.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verify: Option<Vec<EntityDeviation>>,
}

/// The sampled deviation of one entity between input and re-read output.
#[derive(Debug, Clone, Serialize)]
pub struct EntityDeviation {
    /// Entity id in the input.
    pub input_id: String,
    /// Entity id in the output.
    pub output_id: String,
    /// Largest distance found, in the output unit.
    pub max_deviation: f64,
    /// That distance relative to the entity's size (control-polygon bounding box).
    pub relative: f64,
    /// Whether it is within the tolerance.
    pub ok: bool,
}

/// `nurbsx evaluate --json` / `POST /v1/evaluate`.
#[derive(Debug, Clone, Serialize)]
pub struct EvalReport {
    /// The entity evaluated.
    pub entity: String,
    /// One result per parameter.
    pub results: Vec<EvalResult>,
}

/// Evaluation at one parameter.
#[derive(Debug, Clone, Serialize)]
pub struct EvalResult {
    /// `[u]` or `[u, v]`.
    pub at: Vec<f64>,
    /// The point (2 or 3 coordinates, as the geometry's dimension).
    pub point: Vec<f64>,
    /// Curves: `derivatives[k-1]` is the k-th derivative. Surfaces: an object keyed
    /// `"u"`, `"v"`, `"uu"`, `"uv"`, `"vv"`, ...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub derivatives: Option<serde_json::Value>,
    /// Surface unit normal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal: Option<Point3>,
    /// Curves: curvature, torsion, osculating circle; surfaces: Gaussian, mean, principal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curvature: Option<serde_json::Value>,
}
