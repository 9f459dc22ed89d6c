//! The `/v1` handlers: extract, run the pipeline on a computing slot, render. No
//! conversion logic lives here; every step is a `crate::pipeline` call the CLI makes too.

use std::sync::Arc;

use std::io::Write as _;

use axum::extract::State;
use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Response};
use axum::{Extension, Json};
use serde::Serialize;

use super::api::{
    ConvertQuery, DecomposeRequest, DerivativeCurveRequest, ElevateRequest, EvaluateRequest, Input,
    InsertKnotRequest, IsoRequest, JoinRequest, KnotEndsRequest, OperationRequest, PeriodicRequest,
    ReduceRequest, RefineRequest, RemoveKnotsRequest, ReparameterizeRequest, ReverseRequest,
    SplitRequest, TessellateRequest, TransformRequest, ValidateQuery,
};
use super::error::ApiError;
use super::extract::{ApiJson, ApiQuery, FileBody};
use super::openapi::{
    ConvertJsonReply, EvalReportDoc, FileErrors, InfoReportDoc, OperationJsonReply,
    ValidationReportDoc,
};
use super::{AppState, Deadline};
use crate::exchange::{ExportOptions, Format};
use crate::pipeline::{
    self, ConvertReport, ConvertRequest, EvalRequest, InputKind, Loaded, OpNote, Operation,
};

/// The media type of a written file.
fn media_type(format: Format) -> &'static str {
    match format {
        Format::Step => "model/step",
        Format::Iges => "model/iges",
    }
}

/// Whether the client asked for JSON (`Accept: application/json`).
fn wants_json(headers: &HeaderMap) -> bool {
    headers
        .get_all(header::ACCEPT)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .any(|v| v.to_ascii_lowercase().contains("application/json"))
}

/// A file reply: the text with its media type and count headers.
fn file_reply(format: Format, text: String, entities: usize, diagnostics: usize) -> Response {
    let mut response = ([(header::CONTENT_TYPE, media_type(format))], text).into_response();
    let headers = response.headers_mut();
    headers.insert("x-nurbsx-entities", HeaderValue::from(entities));
    headers.insert("x-nurbsx-diagnostics", HeaderValue::from(diagnostics));
    response
}

/// `{"report": ..., "file": "..."}`: a written file with `Accept: application/json` (a
/// conversion, an operation on a file, a built shape written as a file), with what the
/// endpoint's model-JSON reply carries besides the geometry: an operation's `notes`, a
/// fit's `fit`.
#[derive(Serialize)]
struct FileJson {
    report: ConvertReport,
    file: String,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    notes: Vec<OpNote>,
    #[serde(skip_serializing_if = "Option::is_none")]
    fit: Option<pipeline::construct::FitReport>,
}

impl FileJson {
    /// The reply of `report` and `file` alone.
    fn new(report: ConvertReport, file: String) -> Self {
        FileJson {
            report,
            file,
            notes: Vec::new(),
            fit: None,
        }
    }
}

/// Converts a STEP, IGES or model-JSON file to STEP or IGES.
#[utoipa::path(
    post,
    path = "/v1/convert",
    tag = "exchange",
    params(ConvertQuery),
    request_body(
        description = "The file: model/step, model/iges, application/json (model JSON) or \
                       application/octet-stream (the content decides)",
        content(
            (String = "model/step"),
            (String = "model/iges"),
            (super::openapi::GeometryInputDoc = "application/json"),
            (String = "application/octet-stream")
        )
    ),
    responses(
        (status = 200, description = "The converted file (headers X-Nurbsx-Entities and \
                                      X-Nurbsx-Diagnostics); with Accept: application/json, \
                                      the report and the file text",
            content(
                (String = "model/step"),
                (String = "model/iges"),
                (ConvertJsonReply = "application/json")
            )),
        FileErrors
    )
)]
pub async fn convert(
    State(state): State<Arc<AppState>>,
    ApiQuery(query): ApiQuery<ConvertQuery>,
    headers: HeaderMap,
    body: FileBody,
) -> Result<Response, ApiError> {
    let request = ConvertRequest {
        to: query.to.map(|f| f.format()),
        export: ExportOptions {
            schema: query.schema.map(Into::into).unwrap_or_default(),
            units: query.units()?,
            iges_brep: query.iges_brep.unwrap_or(false),
            flatten_assemblies: query.flatten_assemblies.unwrap_or(false),
            ..ExportOptions::default()
        },
        clamp: query.clamp.map(Into::into).unwrap_or_default(),
        verify: query.verify()?,
    };
    let mut settings = state.settings.clone();
    settings.import.geometry_only = query.geometry_only.unwrap_or(false);
    settings.import.sew_tolerance = query.sew_tolerance()?;
    let output = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            pipeline::convert(&body.bytes, body.hint, &request, &settings).map_err(ApiError::from)
        })
        .await?;
    state
        .metrics
        .add_entities_converted(output.report.entities_out);
    if wants_json(&headers) {
        return Ok(Json(FileJson::new(output.report, output.text)).into_response());
    }
    Ok(file_reply(
        output.format,
        output.text,
        output.report.entities_out,
        output.report.diagnostics.len(),
    ))
}

/// Validates a file: parse and geometry diagnostics.
#[utoipa::path(
    post,
    path = "/v1/validate",
    tag = "exchange",
    params(ValidateQuery),
    request_body(
        description = "The file (as for /v1/convert)",
        content((String = "model/step"), (String = "model/iges"), (String = "application/octet-stream"))
    ),
    responses(
        (status = 200, description = "The report (valid or not: `valid` says)", body = ValidationReportDoc),
        FileErrors
    )
)]
pub async fn validate(
    State(state): State<Arc<AppState>>,
    ApiQuery(query): ApiQuery<ValidateQuery>,
    body: FileBody,
) -> Result<Response, ApiError> {
    let mut settings = state.settings.clone();
    let report = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            Ok(pipeline::validate(
                &body.bytes,
                body.hint,
                query.strict,
                &settings,
            ))
        })
        .await?;
    Ok(Json(report).into_response())
}

/// Describes a file: format, schema, units, every entity with its exact geometry.
#[utoipa::path(
    post,
    path = "/v1/info",
    tag = "exchange",
    request_body(
        description = "The file (as for /v1/convert)",
        content((String = "model/step"), (String = "model/iges"), (String = "application/octet-stream"))
    ),
    responses((status = 200, description = "The file's content", body = InfoReportDoc), FileErrors)
)]
pub async fn info(
    State(state): State<Arc<AppState>>,
    body: FileBody,
) -> Result<Response, ApiError> {
    let mut settings = state.settings.clone();
    let report = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            let loaded = pipeline::load(&body.bytes, body.hint, &settings)?;
            // The report holds every entity's geometry: about a written file's size.
            pipeline::check_file_reply(&loaded.document, &settings)?;
            Ok(pipeline::info(&loaded))
        })
        .await?;
    Ok(Json(report).into_response())
}

/// Evaluates one curve or surface at parameters.
#[utoipa::path(
    post,
    path = "/v1/evaluate",
    tag = "geometry",
    request_body = EvaluateRequest,
    responses(
        (status = 200, description = "One result per parameter. A reply over 64 KiB is \
                                      streamed (chunked) once its first 64 KiB are ready; an \
                                      error after that cuts the transfer off (no last chunk)",
            body = EvalReportDoc),
        FileErrors
    )
)]
pub async fn evaluate(
    State(state): State<Arc<AppState>>,
    Extension(Deadline(deadline)): Extension<Deadline>,
    ApiJson(req): ApiJson<EvaluateRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let request = EvalRequest {
        entity: req.entity,
        params: Vec::new(),
        derivatives: req.derivatives,
        normals: req.normals,
        curvature: req.curvature,
    };
    let params = req.params;
    let mut settings = state.settings.clone();
    let ((), body) = state
        .gate
        .stream(deadline, state.write_timeout, move |cancel, out| {
            settings.cancel = cancel;
            let loaded = pipeline::load(&input.bytes, input.hint, &settings)?;
            let document = &loaded.document;
            let entity = pipeline::check_evaluation(document, &request, params.len(), &settings)?;
            out.head(());
            // The JSON of `EvalReport` ({"entity": ..., "results": [...]}, as serde writes
            // it), result by result.
            let written = |e: std::io::Error| {
                tracing::debug!(error = %e, "an evaluation reply was not taken");
                pipeline::cancelled()
            };
            out.write_all(b"{\"entity\":").map_err(written)?;
            serde_json::to_writer(&mut *out, &entity.id).map_err(|e| written(e.into()))?;
            out.write_all(b",\"results\":[").map_err(written)?;
            let mut first = true;
            pipeline::evaluate_each(document, &request, params.tuples(), &settings, |r| {
                if !first {
                    out.write_all(b",").map_err(written)?;
                }
                first = false;
                serde_json::to_writer(&mut *out, &r).map_err(|e| written(e.into()))
            })?;
            out.write_all(b"]}").map_err(written)?;
            Ok(())
        })
        .await?;
    Ok(([(header::CONTENT_TYPE, "application/json")], body).into_response())
}

/// Loads, applies `op`, and renders in the input's form: model JSON in gives
/// `{"geometry": ..., "notes": [...]}` out (`notes` when the operation reports something,
/// such as a reduction's deviation bound); a file in gives a file in the same format out,
/// with the largest reported bound in `X-Nurbsx-Error-Bound`, or, with `json`
/// (`Accept: application/json`), `{"report": ..., "file": "...", "notes": [...]}` as
/// `/v1/convert` replies.
async fn operate(
    state: Arc<AppState>,
    input: Input,
    op: Operation,
    entity: Option<String>,
    json: bool,
) -> Result<Response, ApiError> {
    let mut settings = state.settings.clone();
    let json_array = input.json_array;
    let (rendered, notes) = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            let Loaded { kind, mut document } =
                pipeline::load(&input.bytes, input.hint, &settings)?;
            let entities_in = document.entities.len();
            let notes = pipeline::apply(&mut document, op, entity.as_deref(), &settings)?;
            pipeline::check_file_reply(&document, &settings)?;
            match kind.format() {
                Some(format) => {
                    let export = ExportOptions {
                        cancel: settings.cancel.clone(),
                        ..ExportOptions::default()
                    };
                    // What the output cannot hold is dropped and reported (counted in
                    // `x-nurbsx-diagnostics`), as the CLI's modify commands do, with what
                    // the writer says.
                    pipeline::drop_unwritable(&mut document, format);
                    let (text, written) = pipeline::write(&document, format, &export)?;
                    document.diagnostics.extend(written);
                    let units = document.units;
                    let report = pipeline::file_report(kind, format, entities_in, &document, units);
                    Ok((Ok((format, text, report)), notes))
                }
                None => Ok((Err(document), notes)),
            }
        })
        .await?;
    match rendered {
        Ok((_, text, report)) if json => Ok(Json(FileJson {
            notes,
            ..FileJson::new(report, text)
        })
        .into_response()),
        Ok((format, text, report)) => {
            let mut response =
                file_reply(format, text, report.entities_out, report.diagnostics.len());
            let bound = notes
                .iter()
                .filter_map(|n| n.error_bound)
                .fold(None, |m: Option<f64>, b| Some(m.map_or(b, |m| m.max(b))));
            if let Some(bound) = bound {
                if let Ok(value) = HeaderValue::from_str(&format!("{bound:e}")) {
                    response.headers_mut().insert("x-nurbsx-error-bound", value);
                }
            }
            Ok(response)
        }
        Err(document) => {
            let geometries: Vec<_> = document.entities.into_iter().map(|e| e.geometry).collect();
            let geometry = match (json_array, geometries.as_slice()) {
                (false, [one]) => serde_json::to_value(one),
                _ => serde_json::to_value(&geometries),
            }
            .map_err(|e| {
                tracing::error!(error = %e, "serialising geometry failed");
                ApiError::internal()
            })?;
            let mut reply = serde_json::json!({ "geometry": geometry });
            if !notes.is_empty() {
                reply["notes"] = serde_json::to_value(&notes).map_err(|e| {
                    tracing::error!(error = %e, "serialising notes failed");
                    ApiError::internal()
                })?;
            }
            Ok(Json(reply).into_response())
        }
    }
}

/// Runs the operation of a request (see [`OperationRequest`]); `headers` say whether a
/// file reply is wanted as JSON.
async fn run_operation(
    state: Arc<AppState>,
    headers: &HeaderMap,
    request: impl OperationRequest,
) -> Result<Response, ApiError> {
    let (input, entity, op) = request.parts()?;
    operate(state, input, op, entity, wants_json(headers)).await
}

/// Declares the handler of one geometric operation: its OpenAPI description and the call
/// of [`run_operation`].
macro_rules! operation_route {
    ($(#[$doc:meta])* $name:ident, $path:literal, $request:ty) => {
        $(#[$doc])*
        #[utoipa::path(
            post,
            path = $path,
            tag = "geometry",
            request_body = $request,
            responses(
                (status = 200, description = "Model JSON in: model JSON out (with `notes` \
                                              when the operation reports); a file in: a \
                                              file in the same format out (headers \
                                              X-Nurbsx-Entities and X-Nurbsx-Diagnostics), \
                                              or with Accept: application/json the report \
                                              (every diagnostic), the file text and the \
                                              `notes`",
                    content(
                        (OperationJsonReply = "application/json"),
                        (String = "model/step"),
                        (String = "model/iges")
                    )),
                FileErrors
            )
        )]
        pub async fn $name(
            State(state): State<Arc<AppState>>,
            headers: HeaderMap,
            ApiJson(req): ApiJson<$request>,
        ) -> Result<Response, ApiError> {
            run_operation(state, &headers, req).await
        }
    };
}

operation_route!(
    /// Inserts a knot `times` times (NURBS Book A5.1/A5.3; shape unchanged).
    insert_knot, "/v1/insert-knot", InsertKnotRequest
);
operation_route!(
    /// Inserts several knots at once (knot refinement, A5.4; shape unchanged).
    refine, "/v1/refine", RefineRequest
);
operation_route!(
    /// Lowers the degree by one (A5.11) within a deviation bound; the bound reached is in
    /// `notes` (model JSON) or `X-Nurbsx-Error-Bound` (files).
    reduce, "/v1/reduce", ReduceRequest
);
operation_route!(
    /// Removes every interior knot that can go within the tolerance (A5.8); the count is
    /// in `notes`.
    remove_knots, "/v1/remove-knots", RemoveKnotsRequest
);
operation_route!(
    /// Bezier segments (curves) or patches (surfaces), exactly (A5.6/A5.7); the reply
    /// holds every piece (patches in u-major order).
    decompose, "/v1/decompose", DecomposeRequest
);
operation_route!(
    /// Splits at a parameter into two pieces, exactly.
    split, "/v1/split", SplitRequest
);
operation_route!(
    /// Joins all curves, in order, into one.
    join, "/v1/join", JoinRequest
);
operation_route!(
    /// Reverses the parameter direction (shape unchanged).
    reverse, "/v1/reverse", ReverseRequest
);
operation_route!(
    /// Maps the domain affinely onto `to` (shape unchanged).
    reparameterize, "/v1/reparameterize", ReparameterizeRequest
);
operation_route!(
    /// Applies an affine map to the control points (exact).
    transform, "/v1/transform", TransformRequest
);
operation_route!(
    /// The isoparametric curve of a surface (exact).
    iso, "/v1/iso", IsoRequest
);
operation_route!(
    /// The periodic form (wrapped poles) of closed curves and surfaces.
    periodic, "/v1/periodic", PeriodicRequest
);
operation_route!(
    /// The k-th derivative of a polynomial curve as a B-spline curve (A3.3).
    derivative_curve, "/v1/derivative-curve", DerivativeCurveRequest
);

/// Elevates the degree of curves and surfaces, exactly (the shape is unchanged).
#[utoipa::path(
    post,
    path = "/v1/degree-elevate",
    tag = "geometry",
    request_body = ElevateRequest,
    responses(
        (status = 200, description = "Model JSON in: model JSON out; a file in: a file in the \
                                      same format out (headers X-Nurbsx-Entities and \
                                      X-Nurbsx-Diagnostics), or with Accept: application/json \
                                      the report (every diagnostic) and the file text",
            content(
                (OperationJsonReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn degree_elevate(
    State(state): State<Arc<AppState>>,
    headers: HeaderMap,
    ApiJson(req): ApiJson<ElevateRequest>,
) -> Result<Response, ApiError> {
    run_operation(state, &headers, req).await
}

/// Clamps the knot-vector ends (knot insertion at the domain ends; shape unchanged).
#[utoipa::path(
    post,
    path = "/v1/clamp",
    tag = "geometry",
    request_body = KnotEndsRequest,
    responses(
        (status = 200, description = "As for /v1/degree-elevate",
            content(
                (OperationJsonReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn clamp(
    State(state): State<Arc<AppState>>,
    headers: HeaderMap,
    ApiJson(req): ApiJson<KnotEndsRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let op = Operation::Clamp {
        direction: req.direction.into(),
    };
    operate(state, input, op, req.entity, wants_json(&headers)).await
}

/// Unclamps the knot-vector ends (NURBS Book A12.1; shape unchanged).
#[utoipa::path(
    post,
    path = "/v1/unclamp",
    tag = "geometry",
    request_body = KnotEndsRequest,
    responses(
        (status = 200, description = "As for /v1/degree-elevate",
            content(
                (OperationJsonReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn unclamp(
    State(state): State<Arc<AppState>>,
    headers: HeaderMap,
    ApiJson(req): ApiJson<KnotEndsRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let op = Operation::Unclamp {
        direction: req.direction.into(),
    };
    operate(state, input, op, req.entity, wants_json(&headers)).await
}

/// Tessellates curves (polylines) and surfaces (triangles) under a chord tolerance; the
/// faces of a part are meshed trimmed by their boundaries and its edges drawn as lines.
/// `X-Nurbsx-Diagnostics` counts what the output leaves out (entities not drawn, faces that
/// could not be meshed) and `X-Nurbsx-Left-Out` lists them as JSON diagnostics.
#[utoipa::path(
    post,
    path = "/v1/tessellate",
    tag = "geometry",
    request_body = TessellateRequest,
    responses(
        (status = 200, description = "OBJ text, SVG, binary glTF 2.0 (one node per face or \
                                      curve, named by its id in the file) or binary STL; \
                                      header X-Nurbsx-Left-Out: a JSON array of diagnostics \
                                      saying what the output leaves out (`[]`: nothing). A \
                                      reply over 64 KiB is streamed (chunked); an error after \
                                      its start cuts the transfer off",
            content(
                (String = "text/plain"),
                (String = "image/svg+xml"),
                (Vec<u8> = "model/gltf-binary"),
                (Vec<u8> = "model/stl")
            )),
        FileErrors
    )
)]
pub async fn tessellate(
    State(state): State<Arc<AppState>>,
    Extension(Deadline(deadline)): Extension<Deadline>,
    ApiJson(req): ApiJson<TessellateRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, None)?;
    let format = req.format;
    let mut settings = state.settings.clone();
    let (left_out, body) = state
        .gate
        .stream(deadline, state.write_timeout, move |cancel, out| {
            settings.cancel = cancel;
            let loaded = pipeline::load(&input.bytes, input.hint, &settings)?;
            let plan =
                pipeline::mesh::plan(&loaded.document, req.entity.as_deref(), format.into())?;
            let mesh = pipeline::tessellate(
                &loaded.document,
                req.entity.as_deref(),
                req.tolerance,
                format.into(),
                &settings,
            )?;
            // What the mesh leaves out: the plan's (entities not drawn) and the meshing's
            // (faces that could not be meshed), for the reply's headers.
            let mut left_out = plan.left_out;
            left_out.extend(mesh.mesh.diagnostics.iter().cloned());
            out.head(left_out);
            mesh.write(out, &settings)?;
            Ok(())
        })
        .await?;
    let media = match format {
        super::api::MeshFormatName::Obj => "text/plain; charset=utf-8",
        super::api::MeshFormatName::Svg => "image/svg+xml",
        super::api::MeshFormatName::Glb => "model/gltf-binary",
        super::api::MeshFormatName::Stl => "model/stl",
    };
    // Counted in X-Nurbsx-Diagnostics and given as JSON in X-Nurbsx-Left-Out (non-ASCII
    // escaped: header values are visible ASCII, RFC 9110 section 5.5).
    let mut response = ([(header::CONTENT_TYPE, media)], body).into_response();
    response
        .headers_mut()
        .insert("x-nurbsx-diagnostics", HeaderValue::from(left_out.len()));
    let json = serde_json::to_string(&left_out).unwrap_or_else(|_| "[]".to_owned());
    let ascii: String = json
        .encode_utf16()
        .map(|u| match char::from_u32(u32::from(u)) {
            Some(c) if c.is_ascii() && !c.is_ascii_control() => c.to_string(),
            _ => format!("\\u{u:04x}"),
        })
        .collect();
    match HeaderValue::from_str(&ascii) {
        Ok(v) => {
            response.headers_mut().insert("x-nurbsx-left-out", v);
        }
        Err(e) => tracing::error!(error = %e, "the left-out header could not be built"),
    }
    Ok(response)
}

/// Builds an exact curve or surface (A7.1 arcs, A8.1 revolution, ISO 10303-42 quadrics).
#[utoipa::path(
    post,
    path = "/v1/make",
    tag = "geometry",
    request_body = super::api::MakeRequest,
    responses(
        (status = 200, description = "Model JSON `{\"geometry\": ...}` (default), or a STEP/IGES \
                                      file with `format` (with Accept: application/json, the \
                                      report and the file text)",
            content(
                (OperationJsonReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn make(
    State(state): State<Arc<AppState>>,
    headers: HeaderMap,
    ApiJson(req): ApiJson<super::api::MakeRequest>,
) -> Result<Response, ApiError> {
    let format = req.format;
    let shape = req.shape()?;
    built(state, format, wants_json(&headers), move || {
        pipeline::construct::make(&shape).map(|d| (d, None))
    })
    .await
}

/// Fits a curve to points or a surface to a grid: interpolation (A9.1, A9.4) or, with
/// `poles`, least squares (section 9.4.1, A9.7). The reply carries the residual.
#[utoipa::path(
    post,
    path = "/v1/fit",
    tag = "geometry",
    request_body = super::api::FitRequest,
    responses(
        (status = 200, description = "Model JSON `{\"geometry\": ..., \"fit\": ...}` \
                                      (default), or a STEP/IGES file with `format` and the \
                                      residual in `X-Nurbsx-Residual-Max` and \
                                      `X-Nurbsx-Residual-Rms` (with Accept: \
                                      application/json, the report, the file text and `fit`)",
            content(
                (super::openapi::FitJsonReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn fit(
    State(state): State<Arc<AppState>>,
    headers: HeaderMap,
    ApiJson(req): ApiJson<super::api::FitRequest>,
) -> Result<Response, ApiError> {
    let format = req.format;
    let spec = pipeline::construct::FitSpec {
        degree: req.degree,
        degree_v: req.degree_v,
        poles: req.poles,
        poles_v: req.poles_v,
        method: req.params.into(),
    };
    let points = req.points;
    built(state, format, wants_json(&headers), move || {
        let (data, dimension) = pipeline::construct::read_fit_data(points.get())?;
        let (document, report) = pipeline::construct::fit(&data, dimension, spec)?;
        Ok((document, Some(report)))
    })
    .await
}

// --- measure ---

/// Measures curves and surfaces: lengths and areas to a tolerance (adaptive Gauss-Kronrod)
/// and, with `closest`, each entity's closest point (NURBS Book section 6.1).
#[utoipa::path(
    post,
    path = "/v1/measure",
    tag = "geometry",
    request_body = super::api::MeasureRequest,
    responses(
        (status = 200, description = "One result per entity", body = super::openapi::MeasureReportDoc),
        FileErrors
    )
)]
pub async fn measure(
    State(state): State<Arc<AppState>>,
    ApiJson(req): ApiJson<super::api::MeasureRequest>,
) -> Result<Response, ApiError> {
    let closest = req.point()?;
    let request = pipeline::measure::MeasureRequest {
        entity: req.entity,
        closest,
        tolerance: req.tolerance,
    };
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let mut settings = state.settings.clone();
    let report = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            let loaded = pipeline::load(&input.bytes, input.hint, &settings)?;
            Ok(pipeline::measure::measure(
                &loaded.document,
                &request,
                &settings,
            )?)
        })
        .await?;
    Ok(Json(report).into_response())
}

/// The Hausdorff distance between the geometry of two inputs (curves against curves,
/// surfaces against surfaces, independent of the parameterisation; the second input is
/// read in the first one's unit): the reply is what `nurbsx compare --json` prints.
#[utoipa::path(
    post,
    path = "/v1/compare",
    tag = "geometry",
    request_body = super::api::CompareRequest,
    responses(
        (status = 200, description = "The comparison", body = super::openapi::CompareSummaryDoc),
        FileErrors
    )
)]
pub async fn compare(
    State(state): State<Arc<AppState>>,
    ApiJson(req): ApiJson<super::api::CompareRequest>,
) -> Result<Response, ApiError> {
    let (first, second, tolerance) = req.parts()?;
    let mut settings = state.settings.clone();
    let summary = state
        .gate
        .run(move |cancel| {
            use pipeline::measure::{compare_summary, settings_for_second};
            settings.cancel = cancel;
            let a = pipeline::load(&first.bytes, first.hint, &settings)?;
            let b = pipeline::load(
                &second.bytes,
                second.hint,
                &settings_for_second(&settings, &a.document),
            )?;
            let diagnostics = a
                .document
                .diagnostics
                .iter()
                .chain(&b.document.diagnostics)
                .cloned()
                .collect();
            Ok(compare_summary(
                &a.document,
                &b.document,
                tolerance,
                diagnostics,
                &settings,
            )?)
        })
        .await?;
    Ok(Json(summary).into_response())
}

// --- end of measure ---

/// Runs `build` on a computing slot and replies with the document: model JSON
/// `{"geometry": ...}` (with `fit` when the build reports a fit), or a file in `format`
/// (a fit's residual in `X-Nurbsx-Residual-Max` / `-Rms`), with `json`
/// (`Accept: application/json`) as `{"report": ..., "file": "...", "fit": ...}`.
async fn built(
    state: Arc<AppState>,
    format: Option<super::api::FileFormat>,
    json: bool,
    build: impl FnOnce() -> Result<
        (
            crate::exchange::Document,
            Option<pipeline::construct::FitReport>,
        ),
        pipeline::PipelineError,
    > + Send
    + 'static,
) -> Result<Response, ApiError> {
    let mut settings = state.settings.clone();
    let (document, report, text, entities_in) = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            let (mut document, report) = build()?;
            pipeline::check_file_reply(&document, &settings)?;
            let entities_in = document.entities.len();
            let text = match format {
                Some(f) => {
                    let format = f.kind().format().unwrap_or(Format::Step);
                    // What the output cannot hold is dropped and reported, as the CLI's
                    // make and fit commands do.
                    pipeline::drop_unwritable(&mut document, format);
                    let (text, written) = pipeline::write(
                        &document,
                        format,
                        &ExportOptions {
                            cancel: settings.cancel.clone(),
                            ..ExportOptions::default()
                        },
                    )?;
                    document.diagnostics.extend(written);
                    Some(text)
                }
                None => None,
            };
            Ok((document, report, text, entities_in))
        })
        .await?;
    match (format, text) {
        (Some(f), Some(text)) if json => {
            let format = f.kind().format().unwrap_or(Format::Step);
            let file_report = pipeline::file_report(
                InputKind::Json,
                format,
                entities_in,
                &document,
                document.units,
            );
            Ok(Json(FileJson {
                fit: report,
                ..FileJson::new(file_report, text)
            })
            .into_response())
        }
        (Some(f), Some(text)) => {
            let mut response = file_reply(
                f.kind().format().unwrap_or(Format::Step),
                text,
                document.entities.len(),
                document.diagnostics.len(),
            );
            if let Some(r) = &report {
                for (name, value) in [
                    ("x-nurbsx-residual-max", r.residual_max),
                    ("x-nurbsx-residual-rms", r.residual_rms),
                ] {
                    if let Ok(v) = HeaderValue::from_str(&format!("{value:e}")) {
                        response.headers_mut().insert(name, v);
                    }
                }
            }
            Ok(response)
        }
        _ => {
            let geometry = document
                .entities
                .first()
                .map(|e| serde_json::to_value(&e.geometry))
                .transpose()
                .map_err(|e| {
                    tracing::error!(error = %e, "serialising geometry failed");
                    ApiError::internal()
                })?;
            let mut reply = serde_json::json!({ "geometry": geometry });
            if let Some(r) = &report {
                reply["fit"] = serde_json::to_value(r).map_err(|e| {
                    tracing::error!(error = %e, "serialising the fit report failed");
                    ApiError::internal()
                })?;
            }
            Ok(Json(reply).into_response())
        }
    }
}
