//! Bodies being received: a bound on how many arrive at once and on the bytes they hold,
//! and a minimum upload rate per body. A request takes a queue place ([`super::gate`]) only
//! once its whole body is here, so slow uploads cost memory within these bounds, never
//! computing capacity.
//!
//! Policy (README "HTTP service"):
//! - at most `max_uploads` bodies are received at once; one more is refused with 503
//!   `overloaded` before a byte of it is read;
//! - the bodies being received hold at most `max_upload_bytes` together (counted as the
//!   bytes arrive); the body whose bytes would pass it is refused with 503 `overloaded`;
//! - a body declaring more than `max_body_bytes` is refused with 413 before it is read,
//!   one sending more is refused when it passes the limit;
//! - a body must arrive at `min_upload_rate` bytes per second on average after a grace of
//!   [`UPLOAD_GRACE`]: by `start + UPLOAD_GRACE + received / min_upload_rate` the next bytes
//!   must have come, otherwise the reply is 408 `request.upload_too_slow`.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use axum::body::{Body, Bytes};
use axum::http::{HeaderMap, StatusCode, header};
use http_body_util::BodyExt;

use super::error::ApiError;

/// How long a body may take before the minimum upload rate applies.
pub const UPLOAD_GRACE: Duration = Duration::from_secs(5);

/// The bounds on bodies being received, and the counts in use.
#[derive(Debug)]
pub struct Uploads {
    receiving: AtomicUsize,
    bytes: AtomicUsize,
    max_uploads: usize,
    max_upload_bytes: usize,
    max_body_bytes: usize,
    min_rate: u64,
}

/// One body being received: its place and the bytes it holds, given back on drop.
#[derive(Debug)]
struct Place<'u> {
    uploads: &'u Uploads,
    held: usize,
}

impl Drop for Place<'_> {
    fn drop(&mut self) {
        self.uploads.receiving.fetch_sub(1, Ordering::AcqRel);
        self.uploads.bytes.fetch_sub(self.held, Ordering::AcqRel);
    }
}

impl Place<'_> {
    /// Counts `n` more bytes held, or refuses when all bodies together would pass the bound.
    fn hold(&mut self, n: usize) -> Result<(), ApiError> {
        let before = self.uploads.bytes.fetch_add(n, Ordering::AcqRel);
        self.held += n;
        if before.saturating_add(n) > self.uploads.max_upload_bytes {
            return Err(ApiError::overloaded(format!(
                "the bodies being received hold more than the server's {} bytes; retry shortly",
                self.uploads.max_upload_bytes
            )));
        }
        Ok(())
    }
}

impl Uploads {
    /// Bounds: bodies at once, their bytes together, one body's bytes, the minimum rate in
    /// bytes per second (0 is taken as 1).
    pub fn new(
        max_uploads: usize,
        max_upload_bytes: usize,
        max_body_bytes: usize,
        min_rate: u64,
    ) -> Self {
        Uploads {
            receiving: AtomicUsize::new(0),
            bytes: AtomicUsize::new(0),
            max_uploads,
            max_upload_bytes,
            max_body_bytes,
            min_rate: min_rate.max(1),
        }
    }

    /// Bodies being received now.
    pub fn receiving(&self) -> usize {
        self.receiving.load(Ordering::Acquire)
    }

    /// Bytes the bodies being received hold now.
    pub fn bytes(&self) -> usize {
        self.bytes.load(Ordering::Acquire)
    }

    /// Receives a whole body within the bounds (see the module notes).
    pub async fn receive(&self, headers: &HeaderMap, body: Body) -> Result<Bytes, ApiError> {
        let declared = headers
            .get(header::CONTENT_LENGTH)
            .and_then(|v| v.to_str().ok())
            .and_then(|v| v.parse::<u64>().ok());
        if declared.is_some_and(|n| n > self.max_body_bytes as u64) {
            return Err(self.too_large());
        }
        let before = self.receiving.fetch_add(1, Ordering::AcqRel);
        let mut place = Place {
            uploads: self,
            held: 0,
        };
        if before >= self.max_uploads {
            return Err(ApiError::overloaded(format!(
                "{} request bodies are being received, the server's limit; retry shortly",
                self.max_uploads
            )));
        }
        let start = tokio::time::Instant::now();
        // Never reserve what a client only declares: grow with what arrives.
        let mut data = Vec::with_capacity(
            usize::try_from(declared.unwrap_or(0))
                .unwrap_or(0)
                .min(64 << 10),
        );
        let mut body = body;
        loop {
            let due = start
                + UPLOAD_GRACE
                + Duration::from_secs_f64(data.len() as f64 / self.min_rate as f64);
            let frame = match tokio::time::timeout_at(due, body.frame()).await {
                Err(_late) => {
                    return Err(ApiError::new(
                        StatusCode::REQUEST_TIMEOUT,
                        "request.upload_too_slow",
                        format!(
                            "the body arrived slower than the server's minimum of {} bytes/s \
                             ({} bytes in {} ms)",
                            self.min_rate,
                            data.len(),
                            start.elapsed().as_millis()
                        ),
                    ));
                }
                Ok(None) => break,
                Ok(Some(Err(e))) => {
                    return Err(ApiError::bad_request(
                        "request.body",
                        format!("the request body could not be read: {e}"),
                    ));
                }
                Ok(Some(Ok(frame))) => frame,
            };
            let Ok(chunk) = frame.into_data() else {
                continue; // trailers carry nothing this service reads
            };
            if data.len().saturating_add(chunk.len()) > self.max_body_bytes {
                return Err(self.too_large());
            }
            place.hold(chunk.len())?;
            data.extend_from_slice(&chunk);
        }
        Ok(Bytes::from(data))
    }

    fn too_large(&self) -> ApiError {
        ApiError::new(
            StatusCode::PAYLOAD_TOO_LARGE,
            "limit.body_bytes",
            format!(
                "request body too large: the limit is {} bytes",
                self.max_body_bytes
            ),
        )
    }
}
