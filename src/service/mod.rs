//! # The HTTP service: `nurbsx serve`
//!
//! An axum router over the same [`crate::pipeline`] the CLI uses; this module only routes,
//! extracts, runs pipeline calls on a bounded pool of blocking threads, and renders.
//!
//! - `POST /v1/convert`, `/v1/validate`, `/v1/info` take a file as the body;
//!   `POST /v1/evaluate`, `/v1/degree-elevate`, `/v1/clamp`, `/v1/unclamp`, `/v1/tessellate`
//!   take JSON with `geometry` (model JSON) or `file` (STEP/IGES text).
//! - `GET /healthz`, `/readyz`, `/metrics` (Prometheus), `/openapi.json`, `/` (HTML).
//! - Errors are `{"error":{"code","message","location"}}`: 400 malformed request, 413 too
//!   large, 415 unknown format or Content-Type, 422 unreadable or invalid geometry, 503
//!   overloaded / shutting down / over the time limit, 500 only for a bug (logged).
//! - Work policy: see [`gate`]. Time limit: [`ServeConfig::request_timeout`] covers the whole
//!   request (body upload included); past it the reply is 503 `timeout`.

pub mod api;
pub mod error;
pub mod extract;
pub mod gate;
pub mod metrics;
pub mod openapi;
pub mod pages;
pub mod routes;

use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use axum::Router;
use axum::extract::{DefaultBodyLimit, MatchedPath, Request, State};
use axum::http::{HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use tower::ServiceBuilder;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::request_id::{
    MakeRequestId, PropagateRequestIdLayer, RequestId, SetRequestIdLayer,
};
use tower_http::trace::{DefaultOnFailure, TraceLayer};

use crate::pipeline::Settings;
use error::ApiError;
use gate::Gate;
use metrics::Metrics;

/// Service configuration; the CLI fills it from flags and environment variables.
#[derive(Debug, Clone)]
pub struct ServeConfig {
    /// Address to listen on (default 127.0.0.1:8080).
    pub addr: SocketAddr,
    /// Largest request body in bytes (default 64 MiB).
    pub max_body_bytes: usize,
    /// Per-request time limit (default 60 s).
    pub request_timeout: Duration,
    /// Most requests doing CPU work at once (default: the number of cores).
    pub max_concurrency: usize,
    /// Pipeline limits and policies.
    pub settings: Settings,
}

impl Default for ServeConfig {
    fn default() -> Self {
        ServeConfig {
            addr: SocketAddr::from(([127, 0, 0, 1], 8080)),
            max_body_bytes: 64 << 20,
            request_timeout: Duration::from_secs(60),
            max_concurrency: std::thread::available_parallelism().map_or(2, |n| n.get()),
            settings: Settings::default(),
        }
    }
}

/// What every handler shares.
#[derive(Debug)]
pub struct AppState {
    /// Pipeline limits and policies.
    pub settings: Settings,
    /// Admission and computing slots.
    pub gate: Gate,
    /// Counters and histograms.
    pub metrics: Metrics,
    /// The configured number of computing slots.
    pub max_concurrency: usize,
    /// The per-request time limit.
    pub request_timeout: Duration,
}

/// Builds the router (for in-process tests: drive it with `tower::ServiceExt::oneshot`).
pub fn app(config: ServeConfig) -> Router {
    build(config).0
}

/// The router and its shared state (the state lets [`serve_on`] flag shutdown).
fn build(config: ServeConfig) -> (Router, Arc<AppState>) {
    let state = Arc::new(AppState {
        settings: config.settings,
        gate: Gate::new(config.max_concurrency),
        metrics: Metrics::default(),
        max_concurrency: config.max_concurrency,
        request_timeout: config.request_timeout,
    });
    let work = Router::new()
        .route("/v1/convert", post(routes::convert))
        .route("/v1/validate", post(routes::validate))
        .route("/v1/info", post(routes::info))
        .route("/v1/evaluate", post(routes::evaluate))
        .route("/v1/degree-elevate", post(routes::degree_elevate))
        .route("/v1/clamp", post(routes::clamp))
        .route("/v1/unclamp", post(routes::unclamp))
        .route("/v1/tessellate", post(routes::tessellate))
        // Admission runs before the body is read, so refused bodies are never buffered.
        .route_layer(middleware::from_fn_with_state(state.clone(), admit));
    let router = Router::new()
        .route("/", get(pages::landing))
        .route("/healthz", get(pages::healthz))
        .route("/readyz", get(pages::readyz))
        .route("/metrics", get(pages::metrics))
        .route("/openapi.json", get(pages::openapi_json))
        .merge(work)
        .fallback(not_found)
        .method_not_allowed_fallback(method_not_allowed)
        .layer(DefaultBodyLimit::max(config.max_body_bytes))
        .layer(middleware::from_fn_with_state(state.clone(), time_limit))
        .layer(middleware::from_fn_with_state(state.clone(), record))
        .layer(
            ServiceBuilder::new()
                .layer(SetRequestIdLayer::x_request_id(MakeId::default()))
                .layer(
                    TraceLayer::new_for_http()
                        .make_span_with(span_for)
                        // 503s are load shedding, not faults; 500s are logged as errors
                        // where they are made.
                        .on_failure(DefaultOnFailure::new().level(tracing::Level::WARN)),
                )
                .layer(PropagateRequestIdLayer::x_request_id())
                .layer(CatchPanicLayer::custom(panic_reply)),
        )
        .with_state(state.clone());
    (router, state)
}

/// The tracing span of a request: method, path and request id.
fn span_for(req: &Request) -> tracing::Span {
    let id = req
        .headers()
        .get("x-request-id")
        .and_then(|v| v.to_str().ok())
        .unwrap_or("-");
    tracing::info_span!("request", method = %req.method(), path = %req.uri().path(), request_id = %id)
}

/// Request ids for requests that come without `x-request-id`: the process start time in
/// hex and a counter, unique per process and sortable.
#[derive(Debug, Clone, Default)]
struct MakeId {
    next: Arc<AtomicU64>,
}

impl MakeRequestId for MakeId {
    fn make_request_id<B>(&mut self, _request: &axum::http::Request<B>) -> Option<RequestId> {
        static START: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
        let start = START.get_or_init(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs())
        });
        let n = self.next.fetch_add(1, Ordering::Relaxed);
        HeaderValue::from_str(&format!("{start:x}-{n:08x}"))
            .ok()
            .map(RequestId::new)
    }
}

/// Admission to the `/v1` routes (see [`gate`]).
async fn admit(State(state): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    match state.gate.admit() {
        Ok(_admission) => next.run(req).await,
        Err(e) => close_after(e.into_response()),
    }
}

/// The whole-request time limit.
async fn time_limit(State(state): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    match tokio::time::timeout(state.request_timeout, next.run(req)).await {
        Ok(response) => response,
        Err(_elapsed) => close_after(
            ApiError::new(
                StatusCode::SERVICE_UNAVAILABLE,
                "timeout",
                format!(
                    "the request took longer than the server's limit of {} ms",
                    state.request_timeout.as_millis()
                ),
            )
            .into_response(),
        ),
    }
}

/// Marks a reply sent before the request body was read as the connection's last, so a
/// keep-alive client reconnects instead of writing the rest of its body into a closed
/// socket.
fn close_after(mut response: Response) -> Response {
    response.headers_mut().insert(
        axum::http::header::CONNECTION,
        HeaderValue::from_static("close"),
    );
    response
}

/// Request counts, latency and the in-flight gauge, by matched route.
async fn record(State(state): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    let route = req
        .extensions()
        .get::<MatchedPath>()
        .map_or_else(|| "unmatched".to_owned(), |p| p.as_str().to_owned());
    let method = req.method().as_str().to_owned();
    let start = Instant::now();
    state.metrics.start();
    let response = next.run(req).await;
    state
        .metrics
        .finish(&route, &method, response.status().as_u16(), start.elapsed());
    response
}

/// A panic on the async side (a bug: handlers only extract and render) becomes the same
/// generic JSON 500 as a panic in pipeline work; the payload goes to the log only.
fn panic_reply(payload: Box<dyn std::any::Any + Send + 'static>) -> Response {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "non-string panic payload".to_owned());
    tracing::error!(panic = %what, "request handler panicked");
    ApiError::internal().into_response()
}

async fn not_found() -> ApiError {
    ApiError::new(
        StatusCode::NOT_FOUND,
        "not_found",
        "no such endpoint; GET / lists them and /openapi.json describes them",
    )
}

async fn method_not_allowed() -> ApiError {
    ApiError::new(
        StatusCode::METHOD_NOT_ALLOWED,
        "method_not_allowed",
        "this endpoint does not take that method; see /openapi.json",
    )
}

/// Serves on a bound listener until `shutdown` completes, then finishes the requests in
/// flight (graceful shutdown). `/readyz` answers 503 from the moment `shutdown` fires.
pub async fn serve_on(
    listener: tokio::net::TcpListener,
    config: ServeConfig,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let (router, state) = build(config);
    let local = listener.local_addr()?;
    tracing::info!(addr = %local, "nurbsx service listening");
    axum::serve(listener, router)
        .with_graceful_shutdown(async move {
            shutdown.await;
            state.gate.begin_shutdown();
            tracing::info!("shutting down: finishing requests in flight");
        })
        .await
}

/// Completes on Ctrl-C or SIGTERM.
async fn shutdown_signal() {
    let ctrl_c = async {
        if let Err(e) = tokio::signal::ctrl_c().await {
            tracing::error!(error = %e, "cannot listen for Ctrl-C");
            std::future::pending::<()>().await;
        }
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(e) => {
                tracing::error!(error = %e, "cannot listen for SIGTERM");
                std::future::pending::<()>().await;
            }
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        () = ctrl_c => {},
        () = term => {},
    }
}

/// Runs the service until SIGTERM or Ctrl-C (builds its own multi-thread runtime; call it
/// from synchronous code).
pub fn serve(config: ServeConfig) -> std::io::Result<()> {
    // The CLI may have installed a subscriber already; then this one is not needed.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info")),
        )
        .try_init();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .thread_name("nurbsx-http")
        .build()?;
    let result = runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(config.addr).await?;
        serve_on(listener, config, shutdown_signal()).await
    });
    // Every request has been answered by now; a computation that outlived its request
    // (time limit) may still run on a blocking thread. Give it a moment, then exit anyway.
    runtime.shutdown_timeout(SHUTDOWN_GRACE);
    result
}

/// How long `serve` waits, after the last reply, for computations that outlived their
/// requests before exiting.
pub const SHUTDOWN_GRACE: Duration = Duration::from_secs(10);
