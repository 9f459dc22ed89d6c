//! Request extractors whose rejections are [`ApiError`]s, so a malformed request gets the
//! same JSON error shape as a pipeline failure (never axum's plain-text rejection).

use axum::Json;
use axum::body::Bytes;
use axum::extract::rejection::JsonRejection;
use axum::extract::{FromRequest, FromRequestParts, Query, Request};
use axum::http::{HeaderMap, header, request::Parts};
use serde::de::DeserializeOwned;

use super::error::ApiError;
use crate::pipeline::InputKind;

/// A JSON body; rejections become JSON errors (400, 413, 415).
#[derive(Debug)]
pub struct ApiJson<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequest<S> for ApiJson<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, ApiError> {
        match Json::<T>::from_request(req, state).await {
            Ok(Json(value)) => Ok(ApiJson(value)),
            Err(rejection) => {
                let code = match &rejection {
                    JsonRejection::JsonSyntaxError(_) => "request.json_syntax",
                    _ => "request.invalid",
                };
                Err(ApiError::from_rejection(
                    rejection.status(),
                    code,
                    rejection.body_text(),
                ))
            }
        }
    }
}

/// A query string; a bad one is a 400 JSON error.
#[derive(Debug)]
pub struct ApiQuery<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequestParts<S> for ApiQuery<T> {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, state: &S) -> Result<Self, ApiError> {
        match Query::<T>::from_request_parts(parts, state).await {
            Ok(Query(value)) => Ok(ApiQuery(value)),
            Err(rejection) => Err(ApiError::from_rejection(
                rejection.status(),
                "request.query",
                rejection.body_text(),
            )),
        }
    }
}

/// A file upload: the raw body and the format its Content-Type declares (`None`: sniff).
#[derive(Debug)]
pub struct FileBody {
    /// The bytes, exactly as sent.
    pub bytes: Bytes,
    /// From the Content-Type: `model/step`, `model/iges`, `application/json`; `None` for
    /// `application/octet-stream`, `text/plain`, `application/x-www-form-urlencoded`
    /// (curl's default) or no Content-Type (the content decides).
    pub hint: Option<InputKind>,
}

/// The input kind a Content-Type declares: `Ok(None)` means "sniff the content"; an
/// unsupported media type is a 415 error.
pub fn kind_of_content_type(headers: &HeaderMap) -> Result<Option<InputKind>, ApiError> {
    let Some(value) = headers.get(header::CONTENT_TYPE) else {
        return Ok(None);
    };
    let text = value.to_str().unwrap_or("");
    // Parameters such as `; charset=utf-8` do not change the format.
    let essence = text
        .split(';')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_lowercase();
    match essence.as_str() {
        "model/step" | "application/step" | "application/p21" => Ok(Some(InputKind::Step)),
        "model/iges" | "application/iges" => Ok(Some(InputKind::Iges)),
        "application/json" => Ok(Some(InputKind::Json)),
        // curl's `--data-binary` sends application/x-www-form-urlencoded unless told
        // otherwise; no form can carry a CAD file, so the content decides, as for bytes.
        "application/octet-stream" | "text/plain" | "application/x-www-form-urlencoded" | "" => {
            Ok(None)
        }
        _ => Err(ApiError::new(
            axum::http::StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "request.content_type",
            format!(
                "unsupported Content-Type {text:?}: send model/step, model/iges, \
                 application/json (model JSON) or application/octet-stream (sniffed)"
            ),
        )),
    }
}

impl<S: Send + Sync> FromRequest<S> for FileBody {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, ApiError> {
        let hint = kind_of_content_type(req.headers())?;
        let bytes = Bytes::from_request(req, state).await.map_err(|rejection| {
            ApiError::from_rejection(rejection.status(), "request.body", rejection.body_text())
        })?;
        if bytes.is_empty() {
            return Err(ApiError::bad_request(
                "request.empty",
                "the request body is empty: send the file as the body",
            ));
        }
        Ok(FileBody { bytes, hint })
    }
}
