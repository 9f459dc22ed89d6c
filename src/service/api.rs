//! The request bodies and query strings of the `/v1` endpoints, and how they turn into
//! pipeline inputs. Geometry travels as an opaque JSON value and is judged by the pipeline
//! (`pipeline::load`), so invalid geometry is a 422 from the same checks the CLI runs.

use serde::Deserialize;
use serde_json::value::RawValue;
use utoipa::{IntoParams, ToSchema};

use super::error::ApiError;
use crate::exchange::{LengthUnit, StepSchema};
use crate::pipeline::{ClampPolicy, Direction, InputKind, MeshFormat, Operation};

/// The relative tolerance `verify=true` uses: 1e-9 of the entity's control-box size, far
/// below any modelling tolerance and far above `f64` round-off of the written digits.
pub const DEFAULT_VERIFY_TOLERANCE: f64 = 1e-9;

/// An exchange file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum FileFormat {
    /// STEP (ISO 10303-21).
    Step,
    /// IGES 5.3.
    Iges,
}

impl FileFormat {
    /// The pipeline's input kind.
    pub fn kind(self) -> InputKind {
        match self {
            FileFormat::Step => InputKind::Step,
            FileFormat::Iges => InputKind::Iges,
        }
    }

    /// The exchange format.
    pub fn format(self) -> crate::exchange::Format {
        match self {
            FileFormat::Step => crate::exchange::Format::Step,
            FileFormat::Iges => crate::exchange::Format::Iges,
        }
    }
}

/// A surface direction for an operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum DirectionName {
    /// Along u.
    U,
    /// Along v.
    V,
    /// Both directions (curves: the only one).
    #[default]
    Both,
}

impl From<DirectionName> for Direction {
    fn from(d: DirectionName) -> Self {
        match d {
            DirectionName::U => Direction::U,
            DirectionName::V => Direction::V,
            DirectionName::Both => Direction::Both,
        }
    }
}

/// Where the geometry of a JSON request comes from: model JSON or a file's text.
pub struct Input {
    /// The bytes for `pipeline::load`.
    pub bytes: Vec<u8>,
    /// The kind declared (`Json` for `geometry`, the `format` field for `file`).
    pub hint: Option<InputKind>,
    /// Whether the model JSON was an array (the reply keeps the shape).
    pub json_array: bool,
}

impl Input {
    /// Exactly one of `geometry` and `file` must be given; `format` only with `file`.
    pub fn from_fields(
        geometry: Option<Box<RawValue>>,
        file: Option<String>,
        format: Option<FileFormat>,
    ) -> Result<Self, ApiError> {
        match (geometry, file) {
            (Some(g), None) => {
                if format.is_some() {
                    return Err(ApiError::bad_request(
                        "request.input",
                        "\"format\" names the format of \"file\"; model JSON in \"geometry\" needs none",
                    ));
                }
                // The text as sent: no value tree is built for it here (the pipeline
                // parses it once, into geometry).
                let text = g.get();
                let json_array = text.trim_start().starts_with('[');
                Ok(Input {
                    bytes: String::from(Box::<str>::from(g)).into_bytes(),
                    hint: Some(InputKind::Json),
                    json_array,
                })
            }
            (None, Some(text)) => Ok(Input {
                bytes: text.into_bytes(),
                hint: format.map(FileFormat::kind),
                json_array: false,
            }),
            (Some(_), Some(_)) => Err(ApiError::bad_request(
                "request.input",
                "give either \"geometry\" (model JSON) or \"file\" (STEP/IGES text), not both",
            )),
            (None, None) => Err(ApiError::bad_request(
                "request.input",
                "missing input: give \"geometry\" (model JSON) or \"file\" (STEP/IGES text)",
            )),
        }
    }
}

/// `POST /v1/evaluate`: points (and, once integrated, derivatives, normals, curvature) of
/// one curve or surface.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct EvaluateRequest {
    /// Model JSON: a curve or surface object, an array of them, or `{"geometry": ...}`.
    #[schema(value_type = Option<crate::service::openapi::GeometryInputDoc>)]
    pub geometry: Option<Box<RawValue>>,
    /// A STEP or IGES file's text (instead of `geometry`).
    pub file: Option<String>,
    /// The format of `file` (sniffed when absent).
    pub format: Option<FileFormat>,
    /// Entity id (`#17`, `D5`, or the index for model JSON); default: the first entity.
    pub entity: Option<String>,
    /// `[[u], ...]` for a curve, `[[u, v], ...]` for a surface.
    #[schema(value_type = Vec<Vec<f64>>)]
    pub params: ParamList,
    /// Highest derivative order (0: points only).
    #[serde(default)]
    pub derivatives: usize,
    /// Surface unit normals.
    #[serde(default)]
    pub normals: bool,
    /// Curvature (curves: curvature, torsion; surfaces: Gaussian, mean, principal).
    #[serde(default)]
    pub curvature: bool,
}

/// Evaluation parameters as they arrive: `[[u], ...]` or `[[u, v], ...]`, kept flat (8
/// bytes per number instead of a vector per point, 56 bytes and more) from parsing to the
/// evaluation, which reads them in place ([`crate::pipeline::evaluate_each`]).
/// All tuples have the same length (else the request is malformed).
#[derive(Debug, Default)]
pub struct ParamList {
    /// The numbers, tuple after tuple.
    values: Vec<f64>,
    /// The length of every tuple (0 when there are none).
    arity: usize,
}

impl ParamList {
    /// How many tuples.
    pub fn len(&self) -> usize {
        self.values.len().checked_div(self.arity).unwrap_or(0)
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The tuples in order, each a slice of the flat list.
    pub fn tuples(&self) -> std::slice::ChunksExact<'_, f64> {
        // With no tuples (arity 0) the list is empty, and so are its chunks of 1.
        self.values.chunks_exact(self.arity.max(1))
    }
}

impl<'de> Deserialize<'de> for ParamList {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Tuples;
        /// One tuple appended to the flat list; its length.
        struct Tuple<'a>(&'a mut Vec<f64>);
        impl<'de> serde::de::DeserializeSeed<'de> for Tuple<'_> {
            type Value = usize;
            fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<usize, D::Error> {
                d.deserialize_seq(self)
            }
        }
        impl<'de> serde::de::Visitor<'de> for Tuple<'_> {
            type Value = usize;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a parameter tuple [u] or [u, v]")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<usize, A::Error> {
                let mut n = 0;
                while let Some(x) = seq.next_element::<f64>()? {
                    self.0.push(x);
                    n += 1;
                }
                Ok(n)
            }
        }
        impl<'de> serde::de::Visitor<'de> for Tuples {
            type Value = ParamList;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a list of parameter tuples [[u], ...] or [[u, v], ...]")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<ParamList, A::Error> {
                let mut list = ParamList::default();
                let mut first = true;
                while let Some(n) = seq.next_element_seed(Tuple(&mut list.values))? {
                    if first {
                        list.arity = n;
                        first = false;
                    } else if n != list.arity {
                        return Err(serde::de::Error::custom(format!(
                            "parameter tuples of different lengths ({} and {n}): give [u] for \
                             every point of a curve, [u, v] for every point of a surface",
                            list.arity
                        )));
                    }
                }
                if !first && list.arity == 0 {
                    return Err(serde::de::Error::custom(
                        "empty parameter tuple []: give [u] or [u, v]",
                    ));
                }
                Ok(list)
            }
        }
        d.deserialize_seq(Tuples)
    }
}

/// `POST /v1/degree-elevate`.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ElevateRequest {
    /// Model JSON (the reply is model JSON).
    #[schema(value_type = Option<crate::service::openapi::GeometryInputDoc>)]
    pub geometry: Option<Box<RawValue>>,
    /// A STEP or IGES file's text (the reply is a file in the same format, or with
    /// `Accept: application/json` the report and the file).
    pub file: Option<String>,
    /// The format of `file` (sniffed when absent).
    pub format: Option<FileFormat>,
    /// Elevate only this entity (default: all).
    pub entity: Option<String>,
    /// How many degrees to add (NURBS Book A5.9/A5.10).
    pub by: usize,
    /// Surface direction(s); default `both`.
    #[serde(default)]
    pub direction: DirectionName,
}

/// `POST /v1/clamp` and `POST /v1/unclamp`.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct KnotEndsRequest {
    /// Model JSON (the reply is model JSON).
    #[schema(value_type = Option<crate::service::openapi::GeometryInputDoc>)]
    pub geometry: Option<Box<RawValue>>,
    /// A STEP or IGES file's text (the reply is a file in the same format, or with
    /// `Accept: application/json` the report and the file).
    pub file: Option<String>,
    /// The format of `file` (sniffed when absent).
    pub format: Option<FileFormat>,
    /// Only this entity (default: all).
    pub entity: Option<String>,
    /// Surface direction(s); default `both`.
    #[serde(default)]
    pub direction: DirectionName,
}

/// A tessellation output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum MeshFormatName {
    /// Wavefront OBJ (polylines and triangles), `text/plain`.
    #[default]
    Obj,
    /// SVG of curves projected on XY, `image/svg+xml`.
    Svg,
    /// Binary glTF 2.0, `model/gltf-binary`: one node per face or curve, named by its id
    /// in the file (`#40`, `D45`); surfaces as indexed triangles, curves as line strips.
    Glb,
    /// Binary STL (triangles only), `model/stl`.
    Stl,
}

impl From<MeshFormatName> for MeshFormat {
    fn from(m: MeshFormatName) -> Self {
        match m {
            MeshFormatName::Obj => MeshFormat::Obj,
            MeshFormatName::Svg => MeshFormat::Svg,
            MeshFormatName::Glb => MeshFormat::Glb,
            MeshFormatName::Stl => MeshFormat::Stl,
        }
    }
}

/// `POST /v1/tessellate`.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TessellateRequest {
    /// Model JSON.
    #[schema(value_type = Option<crate::service::openapi::GeometryInputDoc>)]
    pub geometry: Option<Box<RawValue>>,
    /// A STEP or IGES file's text (format sniffed).
    pub file: Option<String>,
    /// Only this entity (default: all).
    pub entity: Option<String>,
    /// Chord tolerance, in the geometry's unit.
    pub tolerance: f64,
    /// Output format; default `obj`.
    #[serde(default)]
    pub format: MeshFormatName,
}

/// A STEP application protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum SchemaName {
    /// AP203 CONFIG_CONTROL_DESIGN.
    Ap203,
    /// AP214 AUTOMOTIVE_DESIGN (the default).
    Ap214,
    /// AP242 managed model-based 3D engineering.
    Ap242,
}

impl From<SchemaName> for StepSchema {
    fn from(s: SchemaName) -> Self {
        match s {
            SchemaName::Ap203 => StepSchema::Ap203,
            SchemaName::Ap214 => StepSchema::Ap214,
            SchemaName::Ap242 => StepSchema::Ap242,
        }
    }
}

/// What to do with knot-vector ends while converting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum ClampName {
    /// Keep the knots exactly as read.
    #[default]
    Keep,
    /// Clamp every entity.
    Clamp,
    /// Unclamp every entity.
    Unclamp,
}

impl From<ClampName> for ClampPolicy {
    fn from(c: ClampName) -> Self {
        match c {
            ClampName::Keep => ClampPolicy::Keep,
            ClampName::Clamp => ClampPolicy::Clamp,
            ClampName::Unclamp => ClampPolicy::Unclamp,
        }
    }
}

/// The query string of `POST /v1/convert`.
#[derive(Debug, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct ConvertQuery {
    /// Output format (required for model JSON input; default: the input's format).
    pub to: Option<FileFormat>,
    /// STEP schema to write (default ap214).
    pub schema: Option<SchemaName>,
    /// Unit to write in: mm, cm, m, km, um, in, ft, mi, mil, uin (default: the input's).
    pub units: Option<String>,
    /// Knot-end policy (default keep).
    pub clamp: Option<ClampName>,
    /// `true` (relative tolerance 1e-9) or a relative tolerance: re-read the output and
    /// compare every entity by sampling; a deviation above it is a 422.
    pub verify: Option<String>,
    /// `true`: read the curves and surfaces only, without faces, edges, shells, solids and
    /// assembly placements (a warning says how many were left out).
    pub geometry_only: Option<bool>,
    /// `true`: IGES output writes solids and shells as 186 manifold solid B-rep objects
    /// instead of 144 trimmed surfaces.
    pub iges_brep: Option<bool>,
    /// `true`: STEP output of an assembly writes every instance's parts placed in root
    /// coordinates as one product, instead of the product structure (the default).
    pub flatten_assemblies: Option<bool>,
    /// IGES input: the tolerance within which boundary curve ends are joined into loops
    /// and trimmed faces (144) are sewn into shells and solids (a positive length in the
    /// file's unit; default: the file's resolution or 1e-7 of the model's size, whichever
    /// is larger).
    pub sew_tolerance: Option<f64>,
}

impl ConvertQuery {
    /// The sewing tolerance, checked (absent: the reader's default).
    pub fn sew_tolerance(&self) -> Result<Option<f64>, ApiError> {
        match self.sew_tolerance {
            Some(t) if !(t.is_finite() && t > 0.0) => Err(ApiError::bad_request(
                "request.sew_tolerance",
                format!("sew_tolerance must be a positive length, got {t}"),
            )),
            t => Ok(t),
        }
    }

    /// The output unit, parsed.
    pub fn units(&self) -> Result<Option<LengthUnit>, ApiError> {
        self.units
            .as_deref()
            .map(|name| {
                LengthUnit::parse_name(name).ok_or_else(|| {
                    ApiError::bad_request(
                        "request.units",
                        format!(
                            "unknown unit {name:?}: use mm, cm, m, km, um, in, ft, mi, mil or uin"
                        ),
                    )
                })
            })
            .transpose()
    }

    /// The verification tolerance, parsed (`false` and absent: no verification).
    pub fn verify(&self) -> Result<Option<f64>, ApiError> {
        match self.verify.as_deref() {
            None | Some("false") => Ok(None),
            Some("true") | Some("") => Ok(Some(DEFAULT_VERIFY_TOLERANCE)),
            Some(text) => match text.parse::<f64>() {
                Ok(t) if t.is_finite() && t > 0.0 => Ok(Some(t)),
                _ => Err(ApiError::bad_request(
                    "request.verify",
                    format!("verify must be true, false or a positive tolerance, got {text:?}"),
                )),
            },
        }
    }
}

/// The query string of `POST /v1/validate`.
#[derive(Debug, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct ValidateQuery {
    /// Warnings fail validation too.
    #[serde(default)]
    pub strict: bool,
}

/// A request of a geometric operation: its input, the entity it names, and the operation.
pub trait OperationRequest {
    /// Splits the request; a malformed combination of fields is a 400.
    fn parts(self) -> Result<(Input, Option<String>, Operation), ApiError>;
}

/// Declares the request of a geometric operation: the input fields every operation takes
/// (`geometry` or `file` with `format`, and `entity`), then its own.
macro_rules! operation_request {
    ($(#[$m:meta])* $name:ident { $($(#[$fm:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$m])*
        #[derive(Debug, Deserialize, ToSchema)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            /// Model JSON (the reply is model JSON).
            #[schema(value_type = Option<crate::service::openapi::GeometryInputDoc>)]
            pub geometry: Option<Box<RawValue>>,
            /// A STEP or IGES file's text (the reply is a file in the same format, or with
            /// `Accept: application/json` the report and the file).
            pub file: Option<String>,
            /// The format of `file` (sniffed when absent).
            pub format: Option<FileFormat>,
            /// Only this entity (default: all).
            pub entity: Option<String>,
            $($(#[$fm])* pub $field: $ty,)*
        }
    };
}

fn one() -> usize {
    1
}

fn default_tolerance() -> f64 {
    1e-9
}

operation_request!(
    /// `POST /v1/insert-knot`.
    InsertKnotRequest {
        /// The parameter value of the new knot (A5.1).
        at: f64,
        /// How many times to insert it (default 1).
        #[serde(default = "one")]
        times: usize,
        /// Surface direction: `u` or `v` (required for surfaces).
        #[serde(default)]
        direction: DirectionName,
    }
);

operation_request!(
    /// `POST /v1/refine`.
    RefineRequest {
        /// The knots to insert (A5.4; a value given twice is inserted twice). Give `knots`
        /// or `halve`.
        #[serde(default)]
        knots: Option<Vec<f64>>,
        /// Interval halving (seed 003): insert the midpoint of every non-degenerate knot
        /// span of the domain; surfaces may use `direction: both`.
        #[serde(default)]
        halve: bool,
        /// Surface direction: `u` or `v` (required for surfaces).
        #[serde(default)]
        direction: DirectionName,
    }
);

operation_request!(
    /// `POST /v1/reduce`.
    ReduceRequest {
        /// Largest accepted deviation bound (model units) of the reduction by one degree
        /// (A5.11).
        tolerance: f64,
        /// Surface direction(s); default `both`.
        #[serde(default)]
        direction: DirectionName,
    }
);

operation_request!(
    /// `POST /v1/remove-knots`.
    RemoveKnotsRequest {
        /// Largest accepted change of the shape (model units; A5.8).
        tolerance: f64,
    }
);

operation_request!(
    /// `POST /v1/decompose`: Bezier segments or patches (A5.6/A5.7).
    DecomposeRequest {}
);

operation_request!(
    /// `POST /v1/split`.
    SplitRequest {
        /// The parameter, strictly inside the domain.
        at: f64,
        /// Surface direction: `u` or `v` (required for surfaces).
        #[serde(default)]
        direction: DirectionName,
    }
);

operation_request!(
    /// `POST /v1/join`: all curves, in order, into one (`entity` is refused).
    JoinRequest {
        /// Largest accepted gap between an end and the next start (default 1e-9).
        #[serde(default = "default_tolerance")]
        tolerance: f64,
    }
);

operation_request!(
    /// `POST /v1/reverse`.
    ReverseRequest {
        /// Surface direction(s); default `both`.
        #[serde(default)]
        direction: DirectionName,
    }
);

operation_request!(
    /// `POST /v1/reparameterize`.
    ReparameterizeRequest {
        /// The new domain `[a, b]`, `a < b`.
        to: [f64; 2],
        /// Surface direction(s); default `both`.
        #[serde(default)]
        direction: DirectionName,
    }
);

/// A rotation about an axis through the origin.
#[derive(Debug, Clone, Copy, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct Rotation {
    /// The axis (need not be unit length).
    pub axis: [f64; 3],
    /// The angle in degrees, right-handed about the axis.
    pub degrees: f64,
}

operation_request!(
    /// `POST /v1/transform`: either `matrix`, or any of `scale`, `rotate`, `translate`
    /// (applied in that order).
    TransformRequest {
        /// The rows of `[R | T]` (`x' = R x + T`, the IGES 124 layout).
        matrix: Option<[[f64; 4]; 3]>,
        /// Uniform scale about the origin.
        scale: Option<f64>,
        /// Rotation about an axis through the origin.
        rotate: Option<Rotation>,
        /// Translation.
        translate: Option<[f64; 3]>,
    }
);

operation_request!(
    /// `POST /v1/iso`: exactly one of `u` and `v`.
    IsoRequest {
        /// The curve at u = this value (running along v).
        u: Option<f64>,
        /// The curve at v = this value (running along u).
        v: Option<f64>,
    }
);

operation_request!(
    /// `POST /v1/periodic`.
    PeriodicRequest {
        /// Largest accepted difference of the wrapped poles (default 1e-9).
        #[serde(default = "default_tolerance")]
        tolerance: f64,
        /// Surface direction(s); default `both`.
        #[serde(default)]
        direction: DirectionName,
    }
);

operation_request!(
    /// `POST /v1/derivative-curve`.
    DerivativeCurveRequest {
        /// The derivative order k, 1 <= k < degree (default 1).
        #[serde(default = "one")]
        order: usize,
    }
);

impl OperationRequest for ElevateRequest {
    fn parts(self) -> Result<(Input, Option<String>, Operation), ApiError> {
        let op = Operation::Elevate {
            by: self.by,
            direction: self.direction.into(),
        };
        Ok((
            Input::from_fields(self.geometry, self.file, self.format)?,
            self.entity,
            op,
        ))
    }
}

/// `impl OperationRequest` for a request whose operation is built from its own fields
/// alone: `$op` is a closure from the request to the operation.
macro_rules! plain_operation {
    ($name:ident, $op:expr) => {
        impl OperationRequest for $name {
            fn parts(self) -> Result<(Input, Option<String>, Operation), ApiError> {
                let make: fn(&$name) -> Result<Operation, ApiError> = $op;
                let op = make(&self)?;
                Ok((
                    Input::from_fields(self.geometry, self.file, self.format)?,
                    self.entity,
                    op,
                ))
            }
        }
    };
}

plain_operation!(InsertKnotRequest, |r| Ok(Operation::InsertKnot {
    u: r.at,
    times: r.times,
    direction: r.direction.into(),
}));
plain_operation!(RefineRequest, |r| match (&r.knots, r.halve) {
    (Some(knots), false) => Ok(Operation::Refine {
        knots: knots.clone(),
        direction: r.direction.into(),
    }),
    (None, true) => Ok(Operation::Halve {
        direction: r.direction.into(),
    }),
    _ => Err(ApiError::bad_request(
        "refine.arguments",
        "give either `knots` or `halve: true` (exactly one)",
    )),
});
plain_operation!(ReduceRequest, |r| Ok(Operation::Reduce {
    tolerance: r.tolerance,
    direction: r.direction.into(),
}));
plain_operation!(RemoveKnotsRequest, |r| Ok(Operation::RemoveKnots {
    tolerance: r.tolerance,
}));
plain_operation!(DecomposeRequest, |_| Ok(Operation::Decompose));
plain_operation!(SplitRequest, |r| Ok(Operation::Split {
    at: r.at,
    direction: r.direction.into(),
}));
plain_operation!(JoinRequest, |r| Ok(Operation::Join {
    tolerance: r.tolerance,
}));
plain_operation!(ReverseRequest, |r| Ok(Operation::Reverse {
    direction: r.direction.into(),
}));
plain_operation!(ReparameterizeRequest, |r| Ok(Operation::Reparameterize {
    start: r.to[0],
    end: r.to[1],
    direction: r.direction.into(),
}));
plain_operation!(TransformRequest, |r| {
    let matrix = match (r.matrix, r.scale, r.rotate, r.translate) {
        (Some(m), None, None, None) => m,
        (Some(_), ..) => {
            return Err(ApiError::bad_request(
                "transform.arguments",
                "give `matrix` or `scale`/`rotate`/`translate`, not both",
            ));
        }
        (None, None, None, None) => {
            return Err(ApiError::bad_request(
                "transform.arguments",
                "give `matrix`, or at least one of `scale`, `rotate`, `translate`",
            ));
        }
        (None, scale, rotate, translate) => {
            crate::pipeline::affine(scale, rotate.map(|r| (r.axis, r.degrees)), translate)?
        }
    };
    Ok(Operation::Transform { matrix })
});
plain_operation!(IsoRequest, |r| match (r.u, r.v) {
    (Some(at), None) => Ok(Operation::Iso {
        at,
        direction: Direction::U,
    }),
    (None, Some(at)) => Ok(Operation::Iso {
        at,
        direction: Direction::V,
    }),
    _ => Err(ApiError::bad_request(
        "iso.arguments",
        "give exactly one of `u` and `v`"
    )),
});
plain_operation!(PeriodicRequest, |r| Ok(Operation::Periodic {
    tolerance: r.tolerance,
    direction: r.direction.into(),
}));
plain_operation!(DerivativeCurveRequest, |r| Ok(Operation::DerivativeCurve {
    order: r.order,
}));

/// `POST /v1/make`: what to build (`shape`) and its numbers. Lengths in millimetres,
/// angles in degrees; `axis` is the normal of circles and ellipses.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct MakeRequest {
    /// `circle`, `arc`, `ellipse`, `line`, `cylinder`, `cone`, `sphere`, `torus`, `revolve`,
    /// `extrude`, `ruled` or `coons`.
    pub shape: MakeName,
    /// The reply: model JSON (default) or a STEP/IGES file.
    pub format: Option<FileFormat>,
    /// Centre, or base centre of cylinders and cones (default the origin).
    pub centre: Option<[f64; 3]>,
    /// Normal or axis (default `[0, 0, 1]`).
    pub axis: Option<[f64; 3]>,
    /// Direction of angle 0 (default: perpendicular to the axis).
    pub reference: Option<[f64; 3]>,
    /// Radius (circle, arc, cylinder, cone, sphere).
    pub radius: Option<f64>,
    /// Arc start angle (default 0).
    pub start: Option<f64>,
    /// Arc end angle (default 360).
    pub end: Option<f64>,
    /// Major semi-axis (ellipse) or major radius (torus).
    pub major: Option<f64>,
    /// Minor semi-axis (ellipse) or tube radius (torus).
    pub minor: Option<f64>,
    /// Line start.
    pub p0: Option<[f64; 3]>,
    /// Line end.
    pub p1: Option<[f64; 3]>,
    /// Height of cylinders and cones.
    pub height: Option<f64>,
    /// Semi-angle of cones.
    pub semi_angle: Option<f64>,
    /// Sweep of cylinders and cones, or revolution angle (default 360).
    pub sweep: Option<f64>,
    /// A point of the revolution axis (default the origin).
    pub axis_point: Option<[f64; 3]>,
    /// Extrusion vector.
    pub direction: Option<[f64; 3]>,
    /// Largest accepted corner gap of `coons` boundaries (default 1e-9).
    pub tolerance: Option<f64>,
    /// The curves of `revolve`, `extrude` (one), `ruled` (two) and `coons` (four: S(u,0),
    /// S(u,1), S(0,v), S(1,v)), in model JSON.
    #[schema(value_type = Option<Vec<crate::service::openapi::CurveDoc>>)]
    pub curves: Option<Vec<crate::nurbs::NurbsCurve>>,
}

/// The shapes of `POST /v1/make`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum MakeName {
    /// A full circle.
    Circle,
    /// A circular arc.
    Arc,
    /// An ellipse or elliptic arc.
    Ellipse,
    /// A line segment.
    Line,
    /// A cylinder.
    Cylinder,
    /// A cone.
    Cone,
    /// A sphere.
    Sphere,
    /// A torus.
    Torus,
    /// A revolved curve.
    Revolve,
    /// An extruded curve.
    Extrude,
    /// A ruled surface.
    Ruled,
    /// A bilinearly blended Coons patch.
    Coons,
}

impl MakeRequest {
    /// The shape to build (a missing number or curve is a 400 `make.arguments`).
    pub fn shape(self) -> Result<crate::pipeline::construct::MakeShape, ApiError> {
        use crate::pipeline::construct::{MakeKind, MakeSpec, shape};
        let kind = match self.shape {
            MakeName::Circle => MakeKind::Circle,
            MakeName::Arc => MakeKind::Arc,
            MakeName::Ellipse => MakeKind::Ellipse,
            MakeName::Line => MakeKind::Line,
            MakeName::Cylinder => MakeKind::Cylinder,
            MakeName::Cone => MakeKind::Cone,
            MakeName::Sphere => MakeKind::Sphere,
            MakeName::Torus => MakeKind::Torus,
            MakeName::Revolve => MakeKind::Revolve,
            MakeName::Extrude => MakeKind::Extrude,
            MakeName::Ruled => MakeKind::Ruled,
            MakeName::Coons => MakeKind::Coons,
        };
        let spec = MakeSpec {
            centre: self.centre,
            axis: self.axis,
            reference: self.reference,
            radius: self.radius,
            start: self.start,
            end: self.end,
            major: self.major,
            minor: self.minor,
            p0: self.p0,
            p1: self.p1,
            height: self.height,
            semi_angle: self.semi_angle,
            sweep: self.sweep,
            axis_point: self.axis_point,
            direction: self.direction,
            tolerance: self.tolerance,
            curves: self.curves.unwrap_or_default(),
        };
        Ok(shape(kind, spec)?)
    }
}

/// `POST /v1/fit`: a curve through points or a surface through a grid (A9.1, A9.4), or
/// with `poles` the least-squares fit (section 9.4.1, A9.7).
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FitRequest {
    /// The points `[[x, y], ...]` or `[[x, y, z], ...]` (at most 2000), or a grid: rows of
    /// points `[[[x, y, z], ...], ...]`, row `i` at the `i`-th u, every row as long (at most
    /// 2000 per direction, 250000 in all).
    #[schema(value_type = Vec<Vec<f64>>)]
    pub points: Box<RawValue>,
    /// Degree (along u for a grid; default 3).
    #[serde(default = "three")]
    pub degree: usize,
    /// Degree along v for a grid (default: `degree`).
    pub degree_v: Option<usize>,
    /// Least squares with this many poles (along u for a grid); absent: interpolation.
    pub poles: Option<usize>,
    /// Poles along v of a least-squares grid fit (default: `poles`).
    pub poles_v: Option<usize>,
    /// Parameter method (default `chord`).
    #[serde(default)]
    pub params: ParamsName,
    /// The reply: model JSON (default) or a STEP/IGES file.
    pub format: Option<FileFormat>,
}

fn three() -> usize {
    3
}

/// The parameter methods of `POST /v1/fit` (eqs. 2-125 .. 2-127).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum ParamsName {
    /// Equally spaced.
    Uniform,
    /// Proportional to the chord lengths.
    #[default]
    Chord,
    /// Proportional to the square roots of the chord lengths.
    Centripetal,
}

impl From<ParamsName> for crate::nurbs::fit::ParamMethod {
    fn from(p: ParamsName) -> Self {
        match p {
            ParamsName::Uniform => Self::Uniform,
            ParamsName::Chord => Self::ChordLength,
            ParamsName::Centripetal => Self::Centripetal,
        }
    }
}

// --- measure ---

/// `POST /v1/measure`: lengths, areas and closest points.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct MeasureRequest {
    /// Model JSON.
    #[schema(value_type = Option<crate::service::openapi::GeometryInputDoc>)]
    pub geometry: Option<Box<RawValue>>,
    /// A STEP or IGES file's text.
    pub file: Option<String>,
    /// The format of `file` (sniffed when absent).
    pub format: Option<FileFormat>,
    /// Only this entity (default: all).
    pub entity: Option<String>,
    /// A point `[x, y, z]` (or `[x, y]`): each entity's closest point to it is found.
    pub closest: Option<Vec<f64>>,
    /// Largest error estimate of a length (model units) or area (model units squared);
    /// default 1e-9.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

impl MeasureRequest {
    /// The point of `closest`, checked.
    pub fn point(&self) -> Result<Option<crate::nurbs::Point3>, ApiError> {
        match self.closest.as_deref() {
            None => Ok(None),
            Some(&[x, y]) => Ok(Some([x, y, 0.0])),
            Some(&[x, y, z]) => Ok(Some([x, y, z])),
            Some(other) => Err(ApiError::bad_request(
                "measure.point",
                format!("closest takes 2 or 3 numbers, got {}", other.len()),
            )),
        }
    }
}

/// One input of `POST /v1/compare`: model JSON or a STEP/IGES file's text.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CompareInput {
    /// Model JSON.
    #[schema(value_type = Option<crate::service::openapi::GeometryInputDoc>)]
    pub geometry: Option<Box<RawValue>>,
    /// A STEP or IGES file's text.
    pub file: Option<String>,
    /// The format of `file` (sniffed when absent).
    pub format: Option<FileFormat>,
}

/// `POST /v1/compare`: the Hausdorff distance between the geometry of two inputs, as
/// `nurbsx compare --json` prints it.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CompareRequest {
    /// The first input; distances are in its length unit.
    pub first: CompareInput,
    /// The second input, read in the first one's length unit.
    pub second: CompareInput,
    /// A tolerance (model units of `first`): the reply says whether the distance is
    /// within it.
    pub tolerance: Option<f64>,
}

impl CompareRequest {
    /// The two inputs and the checked tolerance.
    pub fn parts(self) -> Result<(Input, Input, Option<f64>), ApiError> {
        if let Some(t) = self.tolerance.filter(|t| !(t.is_finite() && *t >= 0.0)) {
            return Err(ApiError::bad_request(
                "compare.tolerance",
                format!("tolerance {t} must be a finite number >= 0"),
            ));
        }
        let input = |i: CompareInput| Input::from_fields(i.geometry, i.file, i.format);
        Ok((input(self.first)?, input(self.second)?, self.tolerance))
    }
}

// --- end of measure ---
