//! # The HTTP service: `nurbsx serve`
//!
//! An axum router over the same [`crate::pipeline`] the CLI uses; this module only routes,
//! extracts, runs pipeline calls on a bounded pool of blocking threads, and renders.
//!
//! - `POST /v1/convert`, `/v1/validate`, `/v1/info` take a file as the body;
//!   `POST /v1/evaluate`, `/v1/degree-elevate`, `/v1/clamp`, `/v1/unclamp`, `/v1/insert-knot`,
//!   `/v1/refine`, `/v1/reduce`, `/v1/remove-knots`, `/v1/decompose`, `/v1/split`, `/v1/join`,
//!   `/v1/reverse`, `/v1/reparameterize`, `/v1/transform`, `/v1/iso`, `/v1/periodic`,
//!   `/v1/derivative-curve`, `/v1/make`, `/v1/fit`, `/v1/measure`, `/v1/compare`, `/v1/tessellate`
//!   take JSON with `geometry` (model JSON) or `file` (STEP/IGES text).
//! - `GET /healthz`, `/readyz`, `/metrics` (Prometheus), `/openapi.json`, `/limits`, `/api` (the
//!   endpoint list), `/` (the web page, [`assets`]) and the page's files.
//! - Errors are `{"error":{"code","message","location"}}`: 400 malformed request, 408 body
//!   too slow, 413 too large (body or reply), 415 unknown format or Content-Type, 422
//!   unreadable or invalid geometry, 503 overloaded / shutting down / over the time limit,
//!   500 only for a bug (logged).
//! - Bodies: see [`upload`]; work: see [`gate`]. Time limit: [`ServeConfig::request_timeout`]
//!   covers the whole request (body upload included); past it the reply is 503 `timeout`
//!   and the computation stops at its next poll.
//! - Connections ([`serve_on`]): HTTP/1.1 and HTTP/2 over cleartext with prior knowledge
//!   (h2c, RFC 9113 section 3.3), told apart by the connection preface; timeouts in
//!   [`connection`]: a request head within [`ServeConfig::header_timeout`], silence between
//!   requests up to [`ServeConfig::idle_timeout`]; on shutdown, see [`serve_on`].
//! - Large replies (`/v1/evaluate` results, `/v1/tessellate` OBJ and STL) are streamed in
//!   chunks ([`reply`]): memory is bounded by the chunk queue, not by the reply's size.

pub mod api;
pub mod assets;
pub mod connection;
pub mod error;
pub mod extract;
pub mod gate;
pub mod metrics;
pub mod openapi;
pub mod pages;
pub mod reply;
pub mod routes;
pub mod upload;

use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use axum::Router;
use axum::body::Body;
use axum::extract::{DefaultBodyLimit, MatchedPath, Request, State};
use axum::http::{HeaderValue, StatusCode, header};
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
use metrics::{Gauge, Metrics};
use upload::Uploads;

/// Service configuration; the CLI fills it from flags and environment variables.
#[derive(Debug, Clone)]
pub struct ServeConfig {
    /// Address to listen on (default 127.0.0.1:8080).
    pub addr: SocketAddr,
    /// Largest request body in bytes (default 64 MiB).
    pub max_body_bytes: usize,
    /// Largest reply an operation may build, estimated before the work (default 64 MiB):
    /// over it the reply is 413 `limit.reply_bytes`.
    pub max_reply_bytes: usize,
    /// Per-request time limit (default 60 s).
    pub request_timeout: Duration,
    /// Most requests doing CPU work at once (default: the number of cores).
    pub max_concurrency: usize,
    /// Most request bodies being received at once (default 256).
    pub max_uploads: usize,
    /// Most bytes the bodies being received hold together (default 256 MiB).
    pub max_upload_bytes: usize,
    /// Slowest average upload accepted after [`upload::UPLOAD_GRACE`], bytes per second
    /// (default 16 KiB/s).
    pub min_upload_rate: u64,
    /// Time a connection has to deliver a complete request head, from opening or from the
    /// first byte of a later request (default 10 s).
    pub header_timeout: Duration,
    /// How long a connection may stay silent between requests before it is closed
    /// (default 60 s; HTTP/1.1 keep-alive and HTTP/2 alike).
    pub idle_timeout: Duration,
    /// How long a streamed reply waits for the client to take its next chunk (default
    /// 30 s); past it the work stops and the reply is cut off.
    pub write_timeout: Duration,
    /// How long the server keeps serving after SIGTERM with `/readyz` at 503 (default 5 s).
    pub drain: Duration,
    /// Pipeline limits and policies.
    pub settings: Settings,
}

impl Default for ServeConfig {
    fn default() -> Self {
        ServeConfig {
            addr: SocketAddr::from(([127, 0, 0, 1], 8080)),
            max_body_bytes: 64 << 20,
            max_reply_bytes: 64 << 20,
            request_timeout: Duration::from_secs(60),
            max_concurrency: std::thread::available_parallelism().map_or(2, |n| n.get()),
            max_uploads: 256,
            max_upload_bytes: 256 << 20,
            min_upload_rate: 16 << 10,
            header_timeout: Duration::from_secs(10),
            idle_timeout: Duration::from_secs(60),
            write_timeout: Duration::from_secs(30),
            drain: Duration::from_secs(5),
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
    /// Bodies being received.
    pub uploads: Uploads,
    /// Counters and histograms.
    pub metrics: Metrics,
    /// Open connections (served by [`serve_on`]).
    pub connections: AtomicUsize,
    /// The configured number of computing slots.
    pub max_concurrency: usize,
    /// The per-request time limit.
    pub request_timeout: Duration,
    /// The largest request body.
    pub max_body_bytes: usize,
    /// How long a streamed reply waits for the client ([`ServeConfig::write_timeout`]).
    pub write_timeout: Duration,
}

impl AppState {
    /// The service's gauges for `/metrics`.
    pub fn gauges(&self) -> Vec<Gauge> {
        vec![
            Gauge::new(
                "nurbsx_compute_slots_busy",
                "Computing slots in use.",
                self.gate.busy() as f64,
            ),
            Gauge::new(
                "nurbsx_requests_admitted",
                "Requests computing or queued for a slot.",
                self.gate.admitted() as f64,
            ),
            Gauge::new(
                "nurbsx_uploads_receiving",
                "Request bodies being received.",
                self.uploads.receiving() as f64,
            ),
            Gauge::new(
                "nurbsx_upload_bytes",
                "Bytes held by request bodies being received.",
                self.uploads.bytes() as f64,
            ),
            Gauge::new(
                "nurbsx_http_connections_open",
                "Open client connections.",
                self.connections.load(Ordering::Acquire) as f64,
            ),
        ]
    }
}

/// Builds the router (for in-process tests: drive it with `tower::ServiceExt::oneshot`).
pub fn app(config: ServeConfig) -> Router {
    build(&config).0
}

/// The router and its shared state (the state lets [`serve_on`] flag shutdown).
fn build(config: &ServeConfig) -> (Router, Arc<AppState>) {
    let mut settings = config.settings.clone();
    settings.max_reply_bytes = config.max_reply_bytes;
    let state = Arc::new(AppState {
        settings,
        gate: Gate::with_byte_budget(
            config.max_concurrency,
            config
                .max_concurrency
                .saturating_mul(5)
                .saturating_mul(config.max_body_bytes),
        ),
        uploads: Uploads::new(
            config.max_uploads,
            config.max_upload_bytes,
            config.max_body_bytes,
            config.min_upload_rate,
        ),
        metrics: Metrics::default(),
        connections: AtomicUsize::new(0),
        max_concurrency: config.max_concurrency,
        request_timeout: config.request_timeout,
        max_body_bytes: config.max_body_bytes,
        write_timeout: config.write_timeout,
    });
    let work = Router::new()
        .route("/v1/convert", post(routes::convert))
        .route("/v1/validate", post(routes::validate))
        .route("/v1/info", post(routes::info))
        .route("/v1/evaluate", post(routes::evaluate))
        .route("/v1/degree-elevate", post(routes::degree_elevate))
        .route("/v1/clamp", post(routes::clamp))
        .route("/v1/unclamp", post(routes::unclamp))
        .route("/v1/insert-knot", post(routes::insert_knot))
        .route("/v1/refine", post(routes::refine))
        .route("/v1/reduce", post(routes::reduce))
        .route("/v1/remove-knots", post(routes::remove_knots))
        .route("/v1/decompose", post(routes::decompose))
        .route("/v1/split", post(routes::split))
        .route("/v1/join", post(routes::join))
        .route("/v1/reverse", post(routes::reverse))
        .route("/v1/reparameterize", post(routes::reparameterize))
        .route("/v1/transform", post(routes::transform))
        .route("/v1/iso", post(routes::iso))
        .route("/v1/periodic", post(routes::periodic))
        .route("/v1/derivative-curve", post(routes::derivative_curve))
        .route("/v1/make", post(routes::make))
        .route("/v1/fit", post(routes::fit))
        // measure
        .route("/v1/measure", post(routes::measure))
        .route("/v1/compare", post(routes::compare))
        .route("/v1/tessellate", post(routes::tessellate))
        // The body is received within the upload bounds first; admission follows.
        .route_layer(middleware::from_fn_with_state(
            state.clone(),
            receive_then_admit,
        ));
    let router = Router::new()
        .route("/", get(pages::landing))
        .route("/api", get(pages::api_list))
        .route("/limits", get(pages::limits))
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
                .layer(middleware::from_fn(screen_request_id))
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

/// Longest client request id kept; longer ones are replaced by a generated id.
pub const MAX_REQUEST_ID_LEN: usize = 64;

/// Whether a client's `x-request-id` is kept: 1 to [`MAX_REQUEST_ID_LEN`] characters of
/// `A-Z a-z 0-9 - _ . : /` (enough for UUIDs, trace ids and most gateway ids; nothing that
/// could break a log line or a header).
pub fn request_id_acceptable(id: &[u8]) -> bool {
    (1..=MAX_REQUEST_ID_LEN).contains(&id.len())
        && id
            .iter()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.' | b':' | b'/'))
}

/// Request ids: the client's when acceptable ([`request_id_acceptable`]), otherwise the
/// process start time in hex and a counter, unique per process and sortable.
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

/// Drops a client request id that [`request_id_acceptable`] refuses, so that
/// [`SetRequestIdLayer`] generates one in its place.
async fn screen_request_id(mut req: Request, next: Next) -> Response {
    let refused = req
        .headers()
        .get_all("x-request-id")
        .iter()
        .any(|v| !request_id_acceptable(v.as_bytes()))
        || req.headers().get_all("x-request-id").iter().count() > 1;
    if refused {
        req.headers_mut().remove("x-request-id");
    }
    next.run(req).await
}

/// Receives the body of a `/v1` request within the upload bounds ([`upload`]), then takes
/// its admission ([`gate`]); the handler reads the body from memory.
async fn receive_then_admit(
    State(state): State<Arc<AppState>>,
    req: Request,
    next: Next,
) -> Response {
    let (parts, body) = req.into_parts();
    let bytes = match state.uploads.receive(&parts.headers, body).await {
        Ok(bytes) => bytes,
        Err(e) => return close_after(e.into_response()),
    };
    match state.gate.admit(bytes.len()) {
        Ok(_admission) => {
            next.run(Request::from_parts(parts, Body::from(bytes)))
                .await
        }
        Err(e) => e.into_response(),
    }
}

/// When a request's time limit ends (a request extension): a streamed reply's work stops
/// then too ([`gate::Gate::stream`]).
#[derive(Debug, Clone, Copy)]
pub struct Deadline(pub Instant);

/// The whole-request time limit: until the reply's head here, and for a streamed reply's
/// work through [`Deadline`].
async fn time_limit(State(state): State<Arc<AppState>>, mut req: Request, next: Next) -> Response {
    let now = Instant::now();
    // (A limit too large for the clock means none: about 34 years.)
    let deadline = now
        .checked_add(state.request_timeout)
        .unwrap_or(now + Duration::from_secs(1 << 30));
    req.extensions_mut().insert(Deadline(deadline));
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

/// Marks a reply as the connection's last: sent before the request body was read (so a
/// keep-alive client reconnects instead of writing the rest of its body into a closed
/// socket), or while the server drains.
fn close_after(mut response: Response) -> Response {
    response
        .headers_mut()
        .insert(header::CONNECTION, HeaderValue::from_static("close"));
    response
}

/// Request counts, latency and the in-flight gauge, by matched route; refusals (408, 413,
/// 503) logged at WARN with the request id, method and path; during the drain every reply
/// closes its connection.
async fn record(State(state): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    let route = req
        .extensions()
        .get::<MatchedPath>()
        .map_or_else(|| "unmatched".to_owned(), |p| p.as_str().to_owned());
    let method = req.method().clone();
    let path = req.uri().path().to_owned();
    let id = req
        .headers()
        .get("x-request-id")
        .and_then(|v| v.to_str().ok())
        .unwrap_or("-")
        .to_owned();
    let start = Instant::now();
    state.metrics.start();
    let mut response = next.run(req).await;
    let status = response.status();
    state
        .metrics
        .finish(&route, method.as_str(), status.as_u16(), start.elapsed());
    if matches!(
        status,
        StatusCode::REQUEST_TIMEOUT
            | StatusCode::PAYLOAD_TOO_LARGE
            | StatusCode::SERVICE_UNAVAILABLE
    ) {
        tracing::warn!(
            request_id = %id,
            method = %metrics::method_label(method.as_str()),
            path = %path.chars().take(200).collect::<String>(),
            status = status.as_u16(),
            "request refused"
        );
    }
    if state.gate.shutting_down() {
        response = close_after(response);
    }
    response
}

/// A panic on the async side (a bug: handlers only extract and render) becomes the same
/// generic JSON 500 as a panic in pipeline work; the payload goes to the log only.
fn panic_reply(payload: Box<dyn std::any::Any + Send + 'static>) -> Response {
    let what = error::panic_text(payload.as_ref());
    tracing::error!(panic = %what, "request handler panicked");
    ApiError::internal().into_response()
}

/// The web page's files ([`assets`]) for GET and HEAD; otherwise a JSON 404.
async fn not_found(method: axum::http::Method, uri: axum::http::Uri) -> Response {
    if method == axum::http::Method::GET || method == axum::http::Method::HEAD {
        if let Some(file) = assets::reply(uri.path().trim_start_matches('/')) {
            return file;
        }
    }
    ApiError::new(
        StatusCode::NOT_FOUND,
        "not_found",
        "no such endpoint; GET /api lists them and /openapi.json describes them",
    )
    .into_response()
}

async fn method_not_allowed() -> ApiError {
    ApiError::new(
        StatusCode::METHOD_NOT_ALLOWED,
        "method_not_allowed",
        "this endpoint does not take that method; see /openapi.json",
    )
}

/// One open connection in [`AppState::connections`], counted until dropped (also when
/// its task is aborted at the end of a shutdown).
struct OpenConnection(Arc<AppState>);

impl OpenConnection {
    fn count(state: Arc<AppState>) -> Self {
        state.connections.fetch_add(1, Ordering::AcqRel);
        OpenConnection(state)
    }
}

impl Drop for OpenConnection {
    fn drop(&mut self) {
        self.0.connections.fetch_sub(1, Ordering::AcqRel);
    }
}

/// After the drain, how long connections get to send the replies of stopped work before
/// they are dropped.
pub const CLOSE_GRACE: Duration = Duration::from_millis(300);

/// Serves on a bound listener until `shutdown` completes, then drains:
///
/// 1. at once `/readyz` answers 503, and every reply from then on closes its connection
///    (`Connection: close`), so keep-alive clients reconnect through their load balancer;
/// 2. the listener keeps accepting and serving for [`ServeConfig::drain`], so a load
///    balancer that still sends requests gets answers while it notices the 503;
/// 3. then the listener closes, idle connections are closed, computations still running
///    are stopped (their requests get 503 `cancelled`), and after [`CLOSE_GRACE`] every
///    connection still open (slow uploads, half-sent heads, slow readers) is dropped.
///
/// So `serve_on` returns within `drain + CLOSE_GRACE` of `shutdown`, whatever the clients
/// do.
pub async fn serve_on(
    listener: tokio::net::TcpListener,
    config: ServeConfig,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    use hyper_util::rt::{TokioExecutor, TokioIo, TokioTimer};
    use tower::ServiceExt as _;

    let (router, state) = build(&config);
    let local = listener.local_addr()?;
    tracing::info!(
        addr = %local,
        version = env!("CARGO_PKG_VERSION"),
        protocols = "http/1.1, h2c (prior knowledge)",
        compute_slots = config.max_concurrency,
        queue = config.max_concurrency.saturating_mul(gate::QUEUE_FACTOR),
        max_body_bytes = config.max_body_bytes,
        max_reply_bytes = config.max_reply_bytes,
        max_uploads = config.max_uploads,
        max_upload_bytes = config.max_upload_bytes,
        min_upload_rate = config.min_upload_rate,
        request_timeout_ms = config.request_timeout.as_millis() as u64,
        header_timeout_ms = config.header_timeout.as_millis() as u64,
        idle_timeout_ms = config.idle_timeout.as_millis() as u64,
        write_timeout_ms = config.write_timeout.as_millis() as u64,
        drain_ms = config.drain.as_millis() as u64,
        "nurbsx service listening"
    );
    // HTTP/1.1, or HTTP/2 when the connection opens with its preface. The header and idle
    // timeouts are the connection task's ([`connection::Activity`]), the same for both.
    let mut http = hyper_util::server::conn::auto::Builder::new(TokioExecutor::new());
    http.http1()
        .timer(TokioTimer::new())
        .header_read_timeout(None)
        .keep_alive(true);
    http.http2().timer(TokioTimer::new());
    let http = Arc::new(http);
    let (header_timeout, idle_timeout) = (config.header_timeout, config.idle_timeout);
    // How often a connection task looks at its silence deadline.
    let tick = (header_timeout.min(idle_timeout) / 4)
        .clamp(Duration::from_millis(20), Duration::from_secs(1));
    // Set at the end of the drain: every connection finishes its exchange and closes.
    let (closing_tx, closing_rx) = tokio::sync::watch::channel(false);
    let mut connections = tokio::task::JoinSet::new();
    let mut listener = Some(listener);
    let mut drain_end: Option<tokio::time::Instant> = None;
    let shutdown = std::pin::pin!(shutdown);
    let mut shutdown = Some(shutdown);
    loop {
        let accept = async {
            match &listener {
                Some(l) => l.accept().await,
                None => std::future::pending().await,
            }
        };
        let drained = async {
            match drain_end {
                Some(t) => tokio::time::sleep_until(t).await,
                None => std::future::pending().await,
            }
        };
        let signalled = async {
            match shutdown.as_mut() {
                Some(s) => s.as_mut().await,
                None => std::future::pending().await,
            }
        };
        tokio::select! {
            () = signalled => {
                shutdown = None;
                state.gate.begin_shutdown();
                drain_end = Some(tokio::time::Instant::now() + config.drain);
                tracing::info!(drain_ms = config.drain.as_millis() as u64,
                    "shutting down: /readyz is 503, serving until the drain ends");
            }
            () = drained => break,
            accepted = accept => match accepted {
                Ok((stream, _peer)) => {
                    let activity = connection::Activity::new();
                    let service = {
                        let activity = activity.clone();
                        let router = router.clone();
                        hyper::service::service_fn(move |req: Request<hyper::body::Incoming>| {
                            let http2 = req.version() == axum::http::Version::HTTP_2;
                            let in_flight = activity.begin(http2);
                            let call = router.clone().oneshot(req.map(Body::new));
                            async move {
                                let (mut parts, body) = match call.await {
                                    Ok(response) => response.into_parts(),
                                    Err(never) => match never {},
                                };
                                if http2 {
                                    // Connection-specific fields are not HTTP/2's (RFC 9113
                                    // section 8.2.2); GOAWAY ends the connection instead.
                                    parts.headers.remove(header::CONNECTION);
                                }
                                Ok::<_, std::convert::Infallible>(Response::from_parts(
                                    parts,
                                    connection::GuardedBody::new(body, in_flight),
                                ))
                            }
                        })
                    };
                    let mut closing = closing_rx.clone();
                    let open = OpenConnection::count(state.clone());
                    let http = http.clone();
                    connections.spawn(async move {
                        let _open = open;
                        let io = TokioIo::new(connection::Tracked::new(stream, activity.clone()));
                        let conn = http.serve_connection(io, service);
                        let mut conn = std::pin::pin!(conn);
                        let mut told = false;
                        // Set when the connection is closed for silence: it is dropped if
                        // it has not ended by then.
                        let mut give_up: Option<tokio::time::Instant> = None;
                        loop {
                            let now = tokio::time::Instant::now();
                            let wake = give_up.unwrap_or(now + tick).min(now + tick);
                            tokio::select! {
                                result = conn.as_mut() => {
                                    if let Err(e) = result {
                                        tracing::debug!(error = %e, "connection ended with an error");
                                    }
                                    break;
                                }
                                changed = closing.changed(), if !told => {
                                    told = changed.is_err() || *closing.borrow();
                                    if told && give_up.is_none() {
                                        // Idle: closed now; mid-exchange: after its reply.
                                        conn.as_mut().graceful_shutdown();
                                    }
                                }
                                () = tokio::time::sleep_until(wake) => {
                                    let now = tokio::time::Instant::now();
                                    if give_up.is_some_and(|t| now >= t) {
                                        tracing::debug!("dropping a silent connection");
                                        break;
                                    }
                                    let silent = activity
                                        .deadline(header_timeout, idle_timeout)
                                        .is_some_and(|d| now >= d);
                                    if silent && give_up.is_none() && !told {
                                        conn.as_mut().graceful_shutdown();
                                        give_up = Some(now + CLOSE_GRACE);
                                    }
                                }
                            }
                        }
                    });
                }
                Err(e) => {
                    // Out of descriptors or a connection reset before accept: go on.
                    tracing::warn!(error = %e, "accept failed");
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
            },
            Some(_) = connections.join_next(), if !connections.is_empty() => {}
        }
        // Do not keep finished connection tasks around while serving.
        while connections.try_join_next().is_some() {}
    }
    drop(listener.take());
    state.gate.stop_all();
    let _ = closing_tx.send(true);
    let left = connections.len();
    tracing::info!(
        connections = left,
        "drain over: listener closed, stopping work"
    );
    let closed = tokio::time::timeout(CLOSE_GRACE, async {
        while connections.join_next().await.is_some() {}
    })
    .await;
    if closed.is_err() {
        tracing::info!(
            connections = connections.len(),
            "dropping connections still open"
        );
        connections.shutdown().await;
    }
    Ok(())
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
    // Every connection is closed by now and every computation told to stop; one in a step
    // that does not poll (parsing a file) may still run on a blocking thread. Exit anyway.
    runtime.shutdown_timeout(SHUTDOWN_GRACE);
    result
}

/// How long `serve` waits, after the connections are closed, for computations that have
/// not yet seen their stop signal before exiting.
pub const SHUTDOWN_GRACE: Duration = Duration::from_millis(300);
