//! The `/v1` handlers: extract, run the pipeline on a computing slot, render. No
//! conversion logic lives here; every step is a `crate::pipeline` call the CLI makes too.

use std::sync::Arc;

use axum::Json;
use axum::extract::State;
use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Response};
use serde::Serialize;

use super::AppState;
use super::api::{
    ConvertQuery, ElevateRequest, EvaluateRequest, Input, KnotEndsRequest, TessellateRequest,
    ValidateQuery,
};
use super::error::ApiError;
use super::extract::{ApiJson, ApiQuery, FileBody};
use super::openapi::{
    ConvertJsonReply, EvalReportDoc, FileErrors, GeometryReply, InfoReportDoc, ValidationReportDoc,
};
use crate::exchange::{ExportOptions, Format};
use crate::pipeline::{self, ConvertReport, ConvertRequest, EvalRequest, Loaded, Operation};

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

/// `{"report": ..., "file": "..."}`: the conversion with `Accept: application/json`.
#[derive(Serialize)]
struct ConvertJson {
    report: ConvertReport,
    file: String,
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
            ..ExportOptions::default()
        },
        clamp: query.clamp.map(Into::into).unwrap_or_default(),
        verify: query.verify()?,
    };
    let mut settings = state.settings.clone();
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
        return Ok(Json(ConvertJson {
            report: output.report,
            file: output.text,
        })
        .into_response());
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
    responses((status = 200, description = "One result per parameter", body = EvalReportDoc), FileErrors)
)]
pub async fn evaluate(
    State(state): State<Arc<AppState>>,
    ApiJson(req): ApiJson<EvaluateRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let mut request = EvalRequest {
        entity: req.entity,
        params: Vec::new(),
        derivatives: req.derivatives,
        normals: req.normals,
        curvature: req.curvature,
    };
    let params = req.params;
    let mut settings = state.settings.clone();
    let report = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            let loaded = pipeline::load(&input.bytes, input.hint, &settings)?;
            // Limits first, while the parameters are still flat.
            pipeline::check_evaluation(&loaded.document, &request, params.len(), &settings)?;
            request.params = params.into_vecs();
            Ok(pipeline::evaluate(&loaded.document, &request, &settings)?)
        })
        .await?;
    Ok(Json(report).into_response())
}

/// Loads, applies `op`, and renders in the input's form: model JSON in gives
/// `{"geometry": ...}` out; a file in gives a file in the same format out.
async fn operate(
    state: Arc<AppState>,
    input: Input,
    op: Operation,
    entity: Option<String>,
) -> Result<Response, ApiError> {
    let mut settings = state.settings.clone();
    let json_array = input.json_array;
    let rendered = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            let Loaded { kind, mut document } =
                pipeline::load(&input.bytes, input.hint, &settings)?;
            pipeline::apply(&mut document, op, entity.as_deref(), &settings)?;
            pipeline::check_file_reply(&document, &settings)?;
            match kind.format() {
                Some(format) => {
                    let text = pipeline::write(&document, format, &ExportOptions::default())?;
                    Ok(Ok((
                        format,
                        text,
                        document.entities.len(),
                        document.diagnostics.len(),
                    )))
                }
                None => Ok(Err(document)),
            }
        })
        .await?;
    match rendered {
        Ok((format, text, entities, diagnostics)) => {
            Ok(file_reply(format, text, entities, diagnostics))
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
            Ok(Json(serde_json::json!({ "geometry": geometry })).into_response())
        }
    }
}

/// Elevates the degree of curves and surfaces, exactly (the shape is unchanged).
#[utoipa::path(
    post,
    path = "/v1/degree-elevate",
    tag = "geometry",
    request_body = ElevateRequest,
    responses(
        (status = 200, description = "Model JSON in: model JSON out; a file in: a file in the same format out",
            content(
                (GeometryReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn degree_elevate(
    State(state): State<Arc<AppState>>,
    ApiJson(req): ApiJson<ElevateRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let op = Operation::Elevate {
        by: req.by,
        direction: req.direction.into(),
    };
    operate(state, input, op, req.entity).await
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
                (GeometryReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn clamp(
    State(state): State<Arc<AppState>>,
    ApiJson(req): ApiJson<KnotEndsRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let op = Operation::Clamp {
        direction: req.direction.into(),
    };
    operate(state, input, op, req.entity).await
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
                (GeometryReply = "application/json"),
                (String = "model/step"),
                (String = "model/iges")
            )),
        FileErrors
    )
)]
pub async fn unclamp(
    State(state): State<Arc<AppState>>,
    ApiJson(req): ApiJson<KnotEndsRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, req.format)?;
    let op = Operation::Unclamp {
        direction: req.direction.into(),
    };
    operate(state, input, op, req.entity).await
}

/// Tessellates curves (polylines) and surfaces (triangles) under a chord tolerance.
#[utoipa::path(
    post,
    path = "/v1/tessellate",
    tag = "geometry",
    request_body = TessellateRequest,
    responses(
        (status = 200, description = "OBJ text or SVG",
            content((String = "text/plain"), (String = "image/svg+xml"))),
        FileErrors
    )
)]
pub async fn tessellate(
    State(state): State<Arc<AppState>>,
    ApiJson(req): ApiJson<TessellateRequest>,
) -> Result<Response, ApiError> {
    let input = Input::from_fields(req.geometry, req.file, None)?;
    let format = req.format;
    let mut settings = state.settings.clone();
    let text = state
        .gate
        .run(move |cancel| {
            settings.cancel = cancel;
            let loaded = pipeline::load(&input.bytes, input.hint, &settings)?;
            Ok(pipeline::tessellate(
                &loaded.document,
                req.entity.as_deref(),
                req.tolerance,
                format.into(),
                &settings,
            )?)
        })
        .await?;
    let media = match format {
        super::api::MeshFormatName::Obj => "text/plain; charset=utf-8",
        super::api::MeshFormatName::Svg => "image/svg+xml",
    };
    Ok(([(header::CONTENT_TYPE, media)], text).into_response())
}
