//! The service's error: one JSON shape, `{"error":{"code","message","location"}}`, for
//! pipeline failures, malformed requests (including axum's own extractor rejections) and
//! operational refusals (overload, timeout), each with a fitting HTTP status.

use axum::Json;
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::Serialize;
use utoipa::ToSchema;

use crate::exchange::Location;
use crate::pipeline::{ErrorKind, PipelineError};

/// An error reply: the status and the body's code, message and location.
#[derive(Debug, Clone)]
pub struct ApiError {
    /// The HTTP status.
    pub status: StatusCode,
    /// Stable machine-readable code (`json.syntax`, `limit.body_bytes`, `overloaded`, ...).
    pub code: String,
    /// Human-readable explanation.
    pub message: String,
    /// Where in the input, when the failure comes from the input.
    pub location: Option<Location>,
    /// For a 503: the `Retry-After` seconds (1 unless the refusal knows better).
    pub retry_after_s: u64,
}

/// The JSON body of every error reply.
#[derive(Debug, Serialize, ToSchema)]
pub struct ErrorBody {
    /// The error.
    pub error: ErrorDetail,
}

/// Code, message and location of an error.
#[derive(Debug, Serialize, ToSchema)]
pub struct ErrorDetail {
    /// Stable code, e.g. `geometry.invalid`, `format.unknown`, `limit.body_bytes`,
    /// `request.json_syntax`, `overloaded`, `timeout`.
    pub code: String,
    /// What went wrong, naming the offending value.
    pub message: String,
    /// Where in the input (line, column, entity; IGES section and sequence), or null.
    #[schema(value_type = Option<crate::service::openapi::LocationDoc>)]
    pub location: Option<Location>,
}

impl ApiError {
    /// An error with a status and code and no location.
    pub fn new(status: StatusCode, code: &str, message: impl Into<String>) -> Self {
        ApiError {
            status,
            code: code.to_owned(),
            message: message.into(),
            location: None,
            retry_after_s: 1,
        }
    }

    /// 400: the request is malformed.
    pub fn bad_request(code: &str, message: impl Into<String>) -> Self {
        ApiError::new(StatusCode::BAD_REQUEST, code, message)
    }

    /// 503: no capacity now (the `Retry-After` header says when to try again).
    pub fn overloaded(message: impl Into<String>) -> Self {
        ApiError::new(StatusCode::SERVICE_UNAVAILABLE, "overloaded", message)
    }

    /// 500 with a generic message; the cause is logged, never sent.
    pub fn internal() -> Self {
        ApiError::new(
            StatusCode::INTERNAL_SERVER_ERROR,
            "internal",
            "internal error; the request id identifies it in the server log",
        )
    }

    /// Maps an axum extractor rejection (its status and text) to a JSON error: 413 for a
    /// body over the limit, 415 for a missing or wrong content type, 400 with `code` for
    /// the rest (JSON of the wrong shape is a malformed request here: geometry travels as an
    /// opaque value and is judged by the pipeline, which answers 422).
    pub fn from_rejection(status: StatusCode, code: &str, text: String) -> Self {
        match status {
            StatusCode::PAYLOAD_TOO_LARGE => ApiError::new(
                status,
                "limit.body_bytes",
                format!("request body too large: {text}"),
            ),
            StatusCode::UNSUPPORTED_MEDIA_TYPE => {
                ApiError::new(status, "request.content_type", text)
            }
            _ => ApiError::bad_request(code, text),
        }
    }
}

/// The text of a panic's payload (a bug, for the log only).
pub fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "non-string panic payload".to_owned())
}

/// The HTTP status for a pipeline failure class (see [`ErrorKind`]).
pub fn status_of(kind: ErrorKind) -> StatusCode {
    match kind {
        ErrorKind::Usage => StatusCode::BAD_REQUEST,
        ErrorKind::UnknownFormat => StatusCode::UNSUPPORTED_MEDIA_TYPE,
        ErrorKind::Invalid | ErrorKind::Geometry => StatusCode::UNPROCESSABLE_ENTITY,
        ErrorKind::Limit => StatusCode::PAYLOAD_TOO_LARGE,
    }
}

impl From<PipelineError> for ApiError {
    fn from(e: PipelineError) -> Self {
        // Stopped work: its request is gone (time limit) or the drain ended; either way the
        // server, not the input, is the cause.
        let status = if e.code() == crate::pipeline::cancelled().code() {
            StatusCode::SERVICE_UNAVAILABLE
        } else {
            status_of(e.kind)
        };
        ApiError {
            status,
            code: e.diagnostic.code,
            message: e.diagnostic.message,
            location: Some(e.diagnostic.location),
            retry_after_s: 1,
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        if self.status.is_server_error() && self.status != StatusCode::SERVICE_UNAVAILABLE {
            tracing::error!(code = %self.code, "{}", self.message);
        } else {
            tracing::debug!(status = %self.status, code = %self.code, "{}", self.message);
        }
        let retry = (self.status == StatusCode::SERVICE_UNAVAILABLE).then_some(self.retry_after_s);
        let body = ErrorBody {
            error: ErrorDetail {
                code: self.code,
                message: self.message,
                location: self.location,
            },
        };
        let mut response = (self.status, Json(body)).into_response();
        if let Some(seconds) = retry {
            response
                .headers_mut()
                .insert(header::RETRY_AFTER, HeaderValue::from(seconds.max(1)));
        }
        response
    }
}
