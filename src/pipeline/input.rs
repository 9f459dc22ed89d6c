//! Loading input: format detection (extension, then content) and reading into a
//! [`Document`], including the model-JSON form.

use std::path::Path;

use crate::exchange::{self, Document, Entity, Format, ImportOptions, LengthUnit, Meta, Source};
use crate::nurbs::Geometry;

use super::{ErrorKind, PipelineError};

/// Limits and policies that apply to every request.
#[derive(Debug, Clone)]
pub struct Settings {
    /// How files are read (parser limits, units, trimming).
    pub import: ImportOptions,
    /// Most evaluation parameters in one request (default 10 million).
    pub max_eval_points: usize,
    /// Largest degree elevation in one request (default 20).
    pub max_elevate_by: usize,
    /// Largest degree any operation may produce (default 25, as Open CASCADE reads).
    pub max_degree: usize,
    /// Most tessellation output vertices (default 20 million), checked before the work
    /// from an estimate and during it.
    pub max_mesh_vertices: usize,
    /// Largest reply (evaluation results, mesh text, written file) an operation may build,
    /// estimated before the work and checked after it (default: no limit; the HTTP service
    /// sets one).
    pub max_reply_bytes: usize,
    /// The stop signal long operations poll (default: never).
    pub cancel: super::Cancel,
    /// Every violation of the standard that the reader read anyway is an error, as
    /// `validate` reports it (`convert --strict`, `info --strict`), not a warning.
    pub strict: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            import: ImportOptions::default(),
            max_eval_points: 10_000_000,
            max_elevate_by: 20,
            max_degree: 25,
            max_mesh_vertices: 20_000_000,
            max_reply_bytes: usize::MAX,
            cancel: super::Cancel::default(),
            strict: false,
        }
    }
}

/// What kind of input a request carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// STEP Part 21.
    Step,
    /// IGES 5.3.
    Iges,
    /// nurbsx model JSON: one geometry object, an array of them, or `{"geometry": ...}`.
    Json,
}

impl InputKind {
    /// From a file extension (`.step`, `.stp`, `.p21`, `.igs`, `.iges`, `.json`).
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "step" | "stp" | "p21" => Some(InputKind::Step),
            "igs" | "iges" => Some(InputKind::Iges),
            "json" => Some(InputKind::Json),
            _ => None,
        }
    }

    /// From the content: STEP and IGES signatures, or a JSON object/array.
    pub fn sniff(bytes: &[u8]) -> Option<Self> {
        match Format::sniff(bytes) {
            Some(Format::Step) => Some(InputKind::Step),
            Some(Format::Iges) => Some(InputKind::Iges),
            None => {
                let first = bytes.iter().find(|b| !b.is_ascii_whitespace())?;
                matches!(first, b'{' | b'[').then_some(InputKind::Json)
            }
        }
    }

    /// The exchange format, if this is one.
    pub fn format(self) -> Option<Format> {
        match self {
            InputKind::Step => Some(Format::Step),
            InputKind::Iges => Some(Format::Iges),
            InputKind::Json => None,
        }
    }

    /// Lower-case name: `step`, `iges`, `json`.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Step => "step",
            InputKind::Iges => "iges",
            InputKind::Json => "json",
        }
    }
}

/// A loaded input: its kind and its document.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// What the input was.
    pub kind: InputKind,
    /// The entities and diagnostics. For JSON input `document.format` is a placeholder
    /// (STEP); `kind` is authoritative.
    pub document: Document,
}

/// Reads input bytes. The content decides the format when it is recognisable; `hint`
/// (from a file extension or a Content-Type) is used when the content is ambiguous, and a
/// hint that contradicts the content is refused rather than trusted.
pub fn load(
    bytes: &[u8],
    hint: Option<InputKind>,
    settings: &Settings,
) -> Result<Loaded, PipelineError> {
    if bytes.len() > settings.import.limits.max_input_bytes {
        return Err(PipelineError::new(
            ErrorKind::Limit,
            "limit.input_bytes",
            format!(
                "input is {} bytes, above the limit of {} bytes",
                bytes.len(),
                settings.import.limits.max_input_bytes
            ),
            Default::default(),
        ));
    }
    let kind = match (InputKind::sniff(bytes), hint) {
        (Some(found), _) => found,
        (None, Some(InputKind::Json)) => InputKind::Json,
        (None, Some(h)) => {
            // Plain text declared STEP or IGES is a mismatch; content that is recognisably
            // something else (empty, UTF-16, a PDF ...) gets that more precise code.
            let not = exchange::describe_content(bytes);
            let code = if not.code == "format.unknown" {
                "format.mismatch"
            } else {
                not.code
            };
            return Err(PipelineError::new(
                ErrorKind::Invalid,
                code,
                format!(
                    "declared {} (by its name or content type), but {}",
                    h.name(),
                    not.what
                ),
                crate::exchange::Location::at_line(1),
            ));
        }
        (None, None) => {
            let not = exchange::describe_content(bytes);
            return Err(PipelineError::new(
                ErrorKind::UnknownFormat,
                not.code,
                format!("{} (nor model JSON)", not.what),
                crate::exchange::Location::at_line(1),
            ));
        }
    };
    let mut document = match kind {
        InputKind::Json => load_json(bytes, &settings.cancel)?,
        InputKind::Step | InputKind::Iges => {
            let import = exchange::ImportOptions {
                cancel: settings.cancel.clone(),
                ..settings.import.clone()
            };
            exchange::read(bytes, &import).map_err(|d| {
                if settings.cancel.is_set() {
                    super::cancelled()
                } else {
                    PipelineError::from_exchange(d)
                }
            })?
        }
    };
    if settings.strict {
        document.diagnostics = std::mem::take(&mut document.diagnostics)
            .into_iter()
            .map(crate::exchange::Diagnostic::for_conformance)
            .collect();
    }
    Ok(Loaded { kind, document })
}

/// The input of the JSON parser: `bytes`, read in pieces of [`JSON_POLL`] bytes, failing
/// once the stop signal has fired (the parse then ends with an I/O error).
struct PolledBytes<'a> {
    rest: &'a [u8],
    cancel: &'a super::Cancel,
}

/// Bytes the JSON parser reads between two polls of the stop signal: a few milliseconds of
/// parsing at most in a debug build.
const JSON_POLL: usize = 16 * 1024;

impl std::io::Read for PolledBytes<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.cancel.is_set() {
            return Err(std::io::Error::other("stopped"));
        }
        self.rest.read(buf)
    }
}

/// Parses model JSON: a geometry object, an array of them, or `{"geometry": ...}`. The
/// parse polls `cancel` every [`JSON_POLL`] bytes of input, and once more at its end (the
/// text is tokenised as it is read; building and checking the geometry from the tokens
/// is not polled).
fn load_json(bytes: &[u8], cancel: &super::Cancel) -> Result<Document, PipelineError> {
    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum Shape {
        Wrapped { geometry: Geometry },
        Many(Vec<Geometry>),
        One(Geometry),
    }
    let input = std::io::BufReader::with_capacity(
        JSON_POLL,
        PolledBytes {
            rest: bytes,
            cancel,
        },
    );
    let shape: Shape = serde_json::from_reader(input).map_err(|e| {
        if e.is_io() {
            return super::cancelled();
        }
        // Re-parse as a plain value to tell syntax errors from invalid geometry.
        let location = crate::exchange::Location {
            line: Some(e.line()),
            column: Some(e.column()),
            ..Default::default()
        };
        match serde_json::from_slice::<serde_json::Value>(bytes) {
            Err(e) => {
                PipelineError::new(ErrorKind::Invalid, "json.syntax", e.to_string(), location)
            }
            Ok(value) => invalid_geometry(&value),
        }
    })?;
    cancel.check()?;
    let geometries = match shape {
        Shape::Wrapped { geometry } | Shape::One(geometry) => vec![geometry],
        Shape::Many(list) => list,
    };
    let mut doc = Document::new(Format::Step, LengthUnit::Mm);
    doc.schema = Some("nurbsx model JSON".into());
    doc.entities = geometries
        .into_iter()
        .enumerate()
        .map(|(i, geometry)| Entity {
            id: compact_str::ToCompactString::to_compact_string(&i),
            geometry,
            source: Source {
                entity: "json".into(),
                line: None,
            },
            meta: Meta::default(),
        })
        .collect();
    Ok(doc)
}

/// The checked constructors' message for the first geometry object that fails.
fn invalid_geometry(value: &serde_json::Value) -> PipelineError {
    let items: Vec<&serde_json::Value> = match value {
        serde_json::Value::Array(a) => a.iter().collect(),
        serde_json::Value::Object(o) => vec![o.get("geometry").unwrap_or(value)],
        other => vec![other],
    };
    for (i, item) in items.iter().enumerate() {
        if let Err(e) = serde_json::from_value::<Geometry>((*item).clone()) {
            return PipelineError::new(
                ErrorKind::Invalid,
                "geometry.invalid",
                format!("geometry {i}: {e}"),
                crate::exchange::Location::at_entity(i.to_string()),
            );
        }
    }
    PipelineError::new(
        ErrorKind::Invalid,
        "json.shape",
        "expected a geometry object, an array of them, or {\"geometry\": ...}",
        Default::default(),
    )
}
