//! The machine-readable reports the pipeline returns (serialised as JSON by the CLI with
//! `--json` and by the HTTP service).

use serde::Serialize;

use crate::exchange::{Diagnostic, PlacedInstance, Severity, Shape, Source};
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
    /// Every curve and surface, as exact NURBS (face surfaces and edge curves included).
    pub entities: Vec<EntityInfo>,
    /// The boundary representation: solids, shells, faces with their areas, edges.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub structure: Option<StructureInfo>,
    /// What the reader noticed.
    pub diagnostics: Vec<Diagnostic>,
}

/// The boundary representation of a file, in an [`InfoReport`].
#[derive(Debug, Clone, Serialize)]
pub struct StructureInfo {
    /// Solids.
    pub solids: Vec<SolidInfo>,
    /// Shells.
    pub shells: Vec<ShellInfo>,
    /// Faces.
    pub faces: Vec<FaceInfo>,
    /// Number of edges.
    pub edges: usize,
    /// Number of vertices.
    pub vertices: usize,
    /// Assemblies (product structure kept as instances).
    pub assemblies: usize,
    /// The assembly instances whose placements were applied, depth first: name path,
    /// placing entity, product, placement in the parent and in root coordinates (3x4 rows
    /// `[r r r t]`), and the ids of the solids/shells/faces/edges each placed.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub instances: Vec<PlacedInstance>,
    /// Total area of the faces that could be measured (trimmed regions).
    pub area: f64,
    /// Their area-weighted centroid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub centroid: Option<Point3>,
    /// Faces whose area could not be measured (each says why).
    pub unmeasured_faces: usize,
}

/// One solid of a [`StructureInfo`].
#[derive(Debug, Clone, Serialize)]
pub struct SolidInfo {
    /// Id in the file.
    pub id: String,
    /// Its name, when the file gives one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Shells: the outer one and the voids.
    pub shells: usize,
    /// Their ids (in `StructureInfo::shells`), the outer one first.
    pub shell_ids: Vec<String>,
    /// Faces of all its shells.
    pub faces: usize,
    /// Enclosed volume (negative: the shells point inwards), when every face measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume: Option<f64>,
}

/// One shell of a [`StructureInfo`].
#[derive(Debug, Clone, Serialize)]
pub struct ShellInfo {
    /// Id in the file.
    pub id: String,
    /// Whether every edge is used twice in opposite directions.
    pub closed: bool,
    /// Number of faces.
    pub faces: usize,
    /// Their ids (in `StructureInfo::faces`).
    pub face_ids: Vec<String>,
}

/// One face of a [`StructureInfo`].
#[derive(Debug, Clone, Serialize)]
pub struct FaceInfo {
    /// Id in the file.
    pub id: String,
    /// Id of the entity holding its surface (in `entities`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface: Option<String>,
    /// What the surface was in the file (plane, cylinder ...), when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<Shape>,
    /// Number of loops (outer and holes).
    pub loops: usize,
    /// Number of edge uses over all loops.
    pub edges: usize,
    /// Whether the face normal is the surface normal.
    pub same_sense: bool,
    /// Area of the trimmed face.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub area: Option<f64>,
    /// Why the area is missing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub area_error: Option<String>,
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
    /// What it is in the part: `face` (the surface of a face), `edge` (the curve of an
    /// edge), `pcurve` (a parameter-space curve of a face boundary) or `free` (geometry no
    /// face or edge uses: free curves and surfaces, and all of a file without faces).
    pub role: &'static str,
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
    /// With verification of a file without faces: the largest deviation per entity after
    /// re-reading the output (empty for a file with faces: see `verify_part`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verify: Option<Vec<EntityDeviation>>,
    /// With verification of a file with faces: what a CAD system sees of the part, before
    /// and after (faces, trimmed area, solids, volume).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verify_part: Option<PartDeviation>,
}

/// The part as a CAD system sees it, input against re-read output (output unit).
#[derive(Debug, Clone, Serialize)]
pub struct PartDeviation {
    /// Faces in the input.
    pub faces_in: usize,
    /// Faces read back.
    pub faces_out: usize,
    /// Total trimmed area of the input.
    pub area_in: f64,
    /// Total trimmed area read back.
    pub area_out: f64,
    /// `|area_out - area_in| / area_in`.
    pub area_relative: f64,
    /// Solids in the input.
    pub solids_in: usize,
    /// Solids read back.
    pub solids_out: usize,
    /// Total volume of the input's solids.
    pub volume_in: f64,
    /// Total volume read back.
    pub volume_out: f64,
    /// `|volume_out - volume_in| / |volume_in|` (0 without solids).
    pub volume_relative: f64,
    /// Distance between the area-weighted centroids relative to the part's size.
    pub centroid_relative: f64,
    /// Faces of either side whose area could not be measured.
    pub unmeasured_faces: usize,
    /// Whether areas, volumes and centroids were compared (every face measurable on
    /// both sides); else only the counts.
    pub measured: bool,
    /// Same counts, and every relative figure within the tolerance.
    pub ok: bool,
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
