//! The service under hostile clients, over real loopback sockets (127.0.0.1 only): slow
//! uploads, connections that never finish their headers, SIGTERM during both, timed-out
//! computations, made-up methods and request ids. Every test bounds its request count and
//! its time and stops by itself.
//!
//! Timing bounds are stated where they are used; they are generous for a loaded 2-core
//! machine running a debug build, and each is still far below what the failure it guards
//! against would take.

// Test helpers outside #[test] functions fail loudly on purpose.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::net::SocketAddr;
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

use nurbsx::service::{self, ServeConfig};

fn config() -> ServeConfig {
    ServeConfig {
        max_concurrency: 2,
        ..ServeConfig::default()
    }
}

/// A server on 127.0.0.1 (free port) and the sender that starts its shutdown.
struct Server {
    addr: SocketAddr,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    task: tokio::task::JoinHandle<std::io::Result<()>>,
}

async fn start(config: ServeConfig) -> Server {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let task = tokio::spawn(service::serve_on(listener, config, async move {
        let _ = stopped.await;
    }));
    Server {
        addr,
        stop: Some(stop),
        task,
    }
}

/// The unit circle as 4 rational quadratic arcs.
fn circle() -> Value {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    json!({
        "degree": 2,
        "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
        "control_points": [[1,0,0],[1,1,0],[0,1,0],[-1,1,0],[-1,0,0],[-1,-1,0],[0,-1,0],[1,-1,0],[1,0,0]],
        "weights": [1, w, 1, w, 1, w, 1, w, 1]
    })
}

/// One request on its own connection (`Connection: close`): status, body, time taken.
async fn request(
    addr: SocketAddr,
    method: &str,
    path: &str,
    body: &str,
) -> (u16, String, Duration) {
    let (status, _head, body, took) = request_with_head(addr, method, path, body).await;
    (status, body, took)
}

/// [`request`], also giving the reply's head (status line and header fields).
async fn request_with_head(
    addr: SocketAddr,
    method: &str,
    path: &str,
    body: &str,
) -> (u16, String, String, Duration) {
    request_typed(addr, method, path, "application/json", body).await
}

/// [`request_with_head`] with a body of type `content_type`.
async fn request_typed(
    addr: SocketAddr,
    method: &str,
    path: &str,
    content_type: &str,
    body: &str,
) -> (u16, String, String, Duration) {
    let start = Instant::now();
    let mut s = TcpStream::connect(addr).await.unwrap();
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Type: {content_type}\r\n\
         Content-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).await.unwrap();
    s.write_all(body.as_bytes()).await.unwrap();
    let mut reply = Vec::new();
    tokio::time::timeout(Duration::from_secs(30), s.read_to_end(&mut reply))
        .await
        .expect("a reply within 30 s")
        .unwrap();
    let text = String::from_utf8_lossy(&reply).into_owned();
    let status = text
        .get(9..12)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no status line in {text:?}"));
    let (head, body) = text.split_once("\r\n\r\n").unwrap_or((&text, ""));
    let body = if head
        .to_ascii_lowercase()
        .contains("transfer-encoding: chunked")
    {
        dechunk(body)
    } else {
        body.to_owned()
    };
    (status, head.to_owned(), body, start.elapsed())
}

/// The content of a complete chunked HTTP/1.1 body (RFC 9112 section 7.1); panics on a
/// body cut off before its last chunk.
fn dechunk(mut body: &str) -> String {
    let mut out = String::new();
    loop {
        let (size, rest) = body.split_once("\r\n").expect("a chunk size line");
        let size = usize::from_str_radix(size.trim(), 16).expect("a hexadecimal chunk size");
        if size == 0 {
            return out;
        }
        out.push_str(&rest[..size]);
        body = rest[size..]
            .strip_prefix("\r\n")
            .expect("CRLF after a chunk");
    }
}

/// The head of a keep-alive JSON POST to `path` announcing `len` body bytes.
fn post_head(path: &str, len: usize) -> String {
    format!(
        "POST {path} HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
         Content-Length: {len}\r\n\r\n"
    )
}

fn evaluate_body() -> String {
    json!({ "geometry": circle(), "params": [[0.1], [0.6]] }).to_string()
}

/// A `name value` sample of the metrics text.
fn sample(metrics: &str, name: &str) -> f64 {
    metrics
        .lines()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(' ')?.parse().ok())
        .unwrap_or_else(|| panic!("no {name} in\n{metrics}"))
}

async fn metrics(addr: SocketAddr) -> String {
    let (status, body, _) = request(addr, "GET", "/metrics", "").await;
    assert_eq!(status, 200);
    body
}

/// Polls `/metrics` until `name` has `value`, at most `within`; the time it took.
async fn wait_for(addr: SocketAddr, name: &str, value: f64, within: Duration) -> Duration {
    let start = Instant::now();
    loop {
        let m = metrics(addr).await;
        if sample(&m, name) == value {
            return start.elapsed();
        }
        assert!(
            start.elapsed() < within,
            "{name} did not reach {value} within {within:?}:\n{m}"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Asserts that no computing slot is busy within 1 s from now.
async fn slot_freed_within_a_second(addr: SocketAddr) {
    let freed = wait_for(
        addr,
        "nurbsx_compute_slots_busy",
        0.0,
        Duration::from_secs(1),
    )
    .await;
    assert!(freed < Duration::from_secs(1), "{freed:?}");
}

/// Median of a few evaluate round trips.
async fn evaluate_latency(addr: SocketAddr) -> Duration {
    let mut times = Vec::new();
    for _ in 0..7 {
        let (status, body, t) = request(addr, "POST", "/v1/evaluate", &evaluate_body()).await;
        assert_eq!(status, 200, "{body}");
        times.push(t);
    }
    times.sort();
    times[times.len() / 2]
}

/// A client that sends a request head announcing `len` body bytes, then one byte per
/// second until `stop` is set or the server closes.
fn slow_upload(addr: SocketAddr, len: usize) -> tokio::task::JoinHandle<()> {
    tokio::spawn(async move {
        let Ok(mut s) = TcpStream::connect(addr).await else {
            return;
        };
        let head = format!(
            "POST /v1/evaluate HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\n\
             Content-Length: {len}\r\n\r\n"
        );
        if s.write_all(head.as_bytes()).await.is_err() {
            return;
        }
        for _ in 0..len {
            if s.write_all(b" ").await.is_err() {
                return;
            }
            tokio::time::sleep(Duration::from_secs(1)).await;
        }
    })
}

/// 50 clients uploading at 1 byte/s hold 50 upload places, no queue place: a normal
/// request is answered 200 and its median latency grows by less than 100 ms (the issue's
/// bound; before, twelve such clients made every request 503 for a minute).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn slow_uploads_do_not_delay_a_normal_request() {
    let server = start(ServeConfig {
        // 1 byte/s passes: the slow clients stay for the whole test.
        min_upload_rate: 1,
        ..config()
    })
    .await;
    let addr = server.addr;
    let before = evaluate_latency(addr).await;
    let slow: Vec<_> = (0..50).map(|_| slow_upload(addr, 1000)).collect();
    wait_for(
        addr,
        "nurbsx_uploads_receiving",
        50.0,
        Duration::from_secs(10),
    )
    .await;
    let m = metrics(addr).await;
    assert_eq!(sample(&m, "nurbsx_requests_admitted"), 0.0, "{m}");
    let during = evaluate_latency(addr).await;
    assert!(
        during < before + Duration::from_millis(100),
        "median latency {before:?} without and {during:?} with 50 slow uploads"
    );
    // Still uploading: nothing above depended on them giving up.
    assert_eq!(
        sample(&metrics(addr).await, "nurbsx_uploads_receiving"),
        50.0
    );
    for c in slow {
        c.abort();
    }
    drop(server);
}

/// A body slower than the minimum rate gets 408 once the grace (5 s) is over, and frees
/// its upload place.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_body_below_the_minimum_rate_gets_408() {
    let server = start(ServeConfig {
        min_upload_rate: 1000,
        ..config()
    })
    .await;
    let addr = server.addr;
    let start = Instant::now();
    let mut s = TcpStream::connect(addr).await.unwrap();
    s.write_all(
        format!(
            "POST /v1/evaluate HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\n\
             Content-Length: 100000\r\n\r\n{{"
        )
        .as_bytes(),
    )
    .await
    .unwrap();
    let mut reply = Vec::new();
    tokio::time::timeout(Duration::from_secs(20), s.read_to_end(&mut reply))
        .await
        .expect("the server answers and closes")
        .unwrap();
    let text = String::from_utf8_lossy(&reply);
    assert!(text.starts_with("HTTP/1.1 408"), "{text}");
    assert!(text.contains("request.upload_too_slow"), "{text}");
    // Grace 5 s, plus 1 byte at 1000 bytes/s: not before 5 s; well before the 60 s time
    // limit (20 s allows for a loaded machine).
    let took = start.elapsed();
    assert!(
        took >= Duration::from_secs(5) && took < Duration::from_secs(20),
        "{took:?}"
    );
    assert_eq!(
        sample(&metrics(addr).await, "nurbsx_uploads_receiving"),
        0.0
    );
}

/// The upload bounds: one body more than `max_uploads` is refused at once with 503, and
/// the bytes bound refuses the body that would pass it; a declared length over the body
/// limit is 413 before anything is read.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn upload_count_and_bytes_are_bounded() {
    let server = start(ServeConfig {
        max_uploads: 3,
        max_upload_bytes: 5000,
        max_body_bytes: 4000,
        min_upload_rate: 1,
        ..config()
    })
    .await;
    let addr = server.addr;
    let slow: Vec<_> = (0..3).map(|_| slow_upload(addr, 100)).collect();
    wait_for(
        addr,
        "nurbsx_uploads_receiving",
        3.0,
        Duration::from_secs(10),
    )
    .await;
    let (status, body, took) = request(addr, "POST", "/v1/evaluate", &evaluate_body()).await;
    assert_eq!(status, 503, "{body}");
    assert!(body.contains("request bodies are being received"), "{body}");
    assert!(
        took < Duration::from_secs(2),
        "refused at once, took {took:?}"
    );
    for c in slow {
        c.abort();
    }
    wait_for(
        addr,
        "nurbsx_uploads_receiving",
        0.0,
        Duration::from_secs(10),
    )
    .await;
    // Bytes: two bodies of 3000 bytes cannot be held together under 5000.
    let holder = tokio::spawn(async move {
        let mut s = TcpStream::connect(addr).await.unwrap();
        s.write_all(
            format!(
                "POST /v1/evaluate HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 3500\r\n\r\n{}",
                " ".repeat(3000)
            )
            .as_bytes(),
        )
        .await
        .unwrap();
        tokio::time::sleep(Duration::from_secs(30)).await;
    });
    wait_for(addr, "nurbsx_upload_bytes", 3000.0, Duration::from_secs(10)).await;
    let padded = format!("{}{}", evaluate_body(), " ".repeat(3000));
    let (status, body, _) = request(addr, "POST", "/v1/evaluate", &padded).await;
    assert_eq!(status, 503, "{body}");
    assert!(
        body.contains("bodies being received hold more than"),
        "{body}"
    );
    holder.abort();
    let (status, body, _) = request(addr, "POST", "/v1/evaluate", &" ".repeat(4001)).await;
    assert_eq!(status, 413, "{body}");
    assert!(body.contains("limit.body_bytes"), "{body}");
}

/// Opens `n` connections; odd ones send half a request head, even ones nothing.
async fn half_open(addr: SocketAddr, n: usize) -> Vec<TcpStream> {
    let mut out = Vec::new();
    for k in 0..n {
        let mut s = TcpStream::connect(addr).await.unwrap();
        if k % 2 == 1 {
            s.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
                .await
                .unwrap();
        }
        out.push(s);
    }
    out
}

/// Whether the server closed the connection (end of stream or reset) within `within`.
async fn closed_within(s: &mut TcpStream, within: Duration) -> bool {
    let mut buf = [0u8; 512];
    loop {
        match tokio::time::timeout(within, s.read(&mut buf)).await {
            Err(_) => return false,
            Ok(Ok(0) | Err(_)) => return true,
            // A 408 reply, if hyper sends one, then the end.
            Ok(Ok(_)) => {}
        }
    }
}

/// 200 connections that never complete a request head are closed by the header timeout
/// (1 s here: all closed between 0.9 s and 6 s after opening), and 200 more do not hold
/// up shutdown: with a 30 s header timeout, shutdown with a 1 s drain still returns within
/// drain + 1 s.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn silent_connections_are_closed_and_do_not_block_shutdown() {
    let server = start(ServeConfig {
        header_timeout: Duration::from_secs(1),
        ..config()
    })
    .await;
    let opened = Instant::now();
    let mut conns = half_open(server.addr, 200).await;
    for s in &mut conns {
        assert!(closed_within(s, Duration::from_secs(6)).await);
    }
    let took = opened.elapsed();
    assert!(
        took >= Duration::from_millis(900) && took < Duration::from_secs(6),
        "{took:?}"
    );
    wait_for(
        server.addr,
        "nurbsx_http_connections_open",
        1.0, // the scrape's own
        Duration::from_secs(5),
    )
    .await;

    let mut server = start(ServeConfig {
        header_timeout: Duration::from_secs(30),
        drain: Duration::from_secs(1),
        ..config()
    })
    .await;
    let mut conns = half_open(server.addr, 200).await;
    wait_for(
        server.addr,
        "nurbsx_http_connections_open",
        201.0,
        Duration::from_secs(10),
    )
    .await;
    let asked = Instant::now();
    server.stop.take().unwrap().send(()).unwrap();
    tokio::time::timeout(Duration::from_secs(2), &mut server.task)
        .await
        .expect("shutdown within drain + 1 s")
        .unwrap()
        .unwrap();
    let took = asked.elapsed();
    assert!(
        took >= Duration::from_secs(1),
        "the drain lasts 1 s: {took:?}"
    );
    for s in &mut conns {
        assert!(closed_within(s, Duration::from_secs(1)).await);
    }
}

/// A curve tessellation that needs millions of points (a priori estimate above 2 M, far
/// more than a debug build computes in a second) times out after 300 ms; its computing
/// slot is free again within 1 s of the 503.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_timed_out_tessellation_frees_its_slot_within_a_second() {
    let parabola = json!({
        "degree": 2, "knots": [0, 0, 0, 1, 1, 1],
        "control_points": [[0, 0, 0], [1, 2, 0], [3, 2, 1]]
    });
    let tolerance = 1e-14;
    let curve: nurbsx::nurbs::NurbsCurve = serde_json::from_value(parabola.clone()).unwrap();
    let estimate = curve.tessellation_estimate(tolerance);
    assert!(
        (2e6..2e7).contains(&estimate),
        "the request must be long yet within the 20 M vertex limit: {estimate}"
    );
    let server = start(ServeConfig {
        request_timeout: Duration::from_millis(300),
        max_reply_bytes: usize::MAX,
        ..config()
    })
    .await;
    let body = json!({ "geometry": parabola, "tolerance": tolerance }).to_string();
    let (status, reply, _) = request(server.addr, "POST", "/v1/tessellate", &body).await;
    assert_eq!(status, 503, "{reply}");
    assert!(reply.contains("\"timeout\""), "{reply}");
    slot_freed_within_a_second(server.addr).await;
}

/// The case: tolerance 1e-300 on a 3-point parabola is refused before the work,
/// with the one documented limit named, instead of burning a slot for 18 s.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_hopeless_tessellation_is_refused_before_the_work() {
    let server = start(config()).await;
    let body = json!({
        "geometry": {"degree": 2, "knots": [0, 0, 0, 1, 1, 1],
                     "control_points": [[0, 0, 0], [1, 2, 0], [3, 2, 1]]},
        "tolerance": 1e-300
    })
    .to_string();
    let (status, reply, took) = request(server.addr, "POST", "/v1/tessellate", &body).await;
    assert_eq!(status, 413, "{reply}");
    assert!(reply.contains("limit.mesh_vertices"), "{reply}");
    assert!(reply.contains("20000000 vertices"), "{reply}");
    assert!(took < Duration::from_secs(2), "{took:?}");
}

/// 1,000 requests with made-up methods (and paths) leave /metrics under 30 KB: unknown
/// methods count as `other`, unknown paths as `unmatched`.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn made_up_methods_do_not_grow_the_metrics() {
    let app = service::app(config());
    use tower::ServiceExt;
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        // xorshift64: a fixed, reproducible sequence.
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for _ in 0..1000 {
        let method = format!("M{:X}", next() % 1_000_000_000);
        let path = format!("/x{}", next() % 1_000_000);
        let req = axum::http::Request::builder()
            .method(method.as_str())
            .uri(path)
            .body(axum::body::Body::empty())
            .unwrap();
        let status = app.clone().oneshot(req).await.unwrap().status();
        assert!(status.is_client_error(), "{status}");
    }
    let req = axum::http::Request::builder()
        .uri("/metrics")
        .body(axum::body::Body::empty())
        .unwrap();
    let reply = app.oneshot(req).await.unwrap();
    let text = axum::body::to_bytes(reply.into_body(), 1 << 20)
        .await
        .unwrap();
    let text = String::from_utf8(text.to_vec()).unwrap();
    assert!(text.len() < 30_000, "{} bytes:\n{text}", text.len());
    assert!(text.contains("method=\"other\""), "{text}");
    assert!(!text.contains("method=\"M"), "{text}");
}

/// Request ids: a short id of safe characters is echoed; a 200 KB one, or one with
/// characters outside the set, is replaced by a generated id.
#[tokio::test]
async fn request_ids_are_bounded() {
    use tower::ServiceExt;
    let app = service::app(config());
    let id_for = |id: &str| {
        axum::http::Request::builder()
            .uri("/healthz")
            .header("x-request-id", id)
            .body(axum::body::Body::empty())
            .unwrap()
    };
    let ok = "7f3a-01:trace/span_2.x";
    let reply = app.clone().oneshot(id_for(ok)).await.unwrap();
    assert_eq!(reply.headers()["x-request-id"], ok);
    for bad in [
        "a".repeat(200_000),
        "a".repeat(65),
        "semi;colon".into(),
        "sp ace".into(),
    ] {
        let reply = app.clone().oneshot(id_for(&bad)).await.unwrap();
        let echoed = reply.headers()["x-request-id"].to_str().unwrap();
        assert_ne!(echoed, bad);
        assert!(
            service::request_id_acceptable(echoed.as_bytes()),
            "{echoed}"
        );
    }
}

/// Sends `body` to `path` on servers with no reply limit, a limit one byte below the real
/// reply (expects 413 `limit.reply_bytes` naming `what`) and three times the real reply
/// (expects 200).
async fn estimate_bounds_the_reply(path: &str, body: &str, what: &str) {
    let with_limit = |max_reply_bytes| {
        start(ServeConfig {
            max_reply_bytes,
            ..config()
        })
    };
    let open = with_limit(usize::MAX).await;
    let (status, reply, _) = request(open.addr, "POST", path, body).await;
    assert_eq!(status, 200, "{reply}");
    let real = reply.len();
    let tight = with_limit(real - 1).await;
    let (status, reply, _) = request(tight.addr, "POST", path, body).await;
    assert_eq!(status, 413, "{reply}");
    assert!(
        reply.contains("limit.reply_bytes") && reply.contains(what),
        "{reply}"
    );
    let loose = with_limit(3 * real).await;
    let (status, reply, _) = request(loose.addr, "POST", path, body).await;
    assert_eq!(status, 200, "{reply}");
}

/// The reply estimate bounds the real reply from above and not by much: a limit one byte
/// below a real evaluation reply refuses it (413 `limit.reply_bytes`), a limit of three
/// times the real size accepts it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_reply_estimate_bounds_the_reply() {
    let surface = json!({
        "degree_u": 2, "degree_v": 2,
        "knots_u": [0, 0, 0, 1, 1, 1], "knots_v": [0, 0, 0, 1, 1, 1],
        "control_points": [[[0,0,0],[0,1,0.3],[0,2,0]], [[1,0,0.2],[1,1,1.1],[1,2,0.1]],
                           [[2,0,0],[2,1,-0.4],[2,2,0.5]]]
    });
    let params: Vec<[f64; 2]> = (0..200)
        .map(|k| [f64::from(k) / 199.0, f64::from(199 - k) / 199.0 * 0.7])
        .collect();
    for (derivatives, normals, curvature) in [(0, false, false), (2, true, true)] {
        let body = json!({ "geometry": surface, "params": params,
                           "derivatives": derivatives, "normals": normals,
                           "curvature": curvature })
        .to_string();
        estimate_bounds_the_reply("/v1/evaluate", &body, "evaluation reply").await;
    }
}

/// The real binary under SIGTERM with slow uploads, half-sent heads and a request in
/// flight (its body half sent): `/readyz` turns 503 at once (within 500 ms) and stays 503
/// while the listener still answers; the in-flight request, completed during the drain, is
/// answered 200 with the right point; the process exits cleanly within drain (2 s) + 1 s
/// of the signal, and not before the drain is over.
#[cfg(unix)]
#[test]
fn sigterm_drains_then_exits_within_the_drain_plus_one_second() {
    use std::io::{BufRead, BufReader, Read, Write};
    use std::process::{Command, Stdio};
    let drain = Duration::from_secs(2);
    let mut child = Command::new(env!("CARGO_BIN_EXE_nurbsx"))
        .args([
            "serve",
            "--addr",
            "127.0.0.1:0",
            "--drain",
            "2s",
            "--concurrency",
            "2",
        ])
        .env("RUST_LOG", "info")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (addr_tx, addr_rx) = std::sync::mpsc::channel::<String>();
    let log = std::thread::spawn(move || {
        let mut lines = Vec::new();
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if line.contains("nurbsx service listening") {
                let addr = line
                    .split_whitespace()
                    .find_map(|w| w.strip_prefix("addr="))
                    .unwrap_or_default()
                    .to_owned();
                let _ = addr_tx.send(addr);
            }
            lines.push(line);
        }
        lines
    });
    let addr: SocketAddr = addr_rx
        .recv_timeout(Duration::from_secs(30))
        .expect("the startup line names the address")
        .parse()
        .unwrap();
    let get = |path: &str| -> String {
        let mut s = std::net::TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        write!(
            s,
            "GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
        )
        .unwrap();
        let mut reply = String::new();
        s.read_to_string(&mut reply).unwrap();
        reply
    };
    // Hostile clients: slow uploads and half-sent heads.
    let mut hostile = Vec::new();
    for k in 0..10 {
        let mut s = std::net::TcpStream::connect(addr).unwrap();
        if k % 2 == 0 {
            write!(
                s,
                "POST /v1/evaluate HTTP/1.1\r\nHost: x\r\nContent-Length: 1000\r\n\r\n{{"
            )
            .unwrap();
        } else {
            write!(s, "GET /healthz HTTP/1.1\r\nHost:").unwrap();
        }
        hostile.push(s);
    }
    // The request in flight: head and half its body.
    let body = json!({ "geometry": circle(), "params": [[0.125]] }).to_string();
    let (first, second) = body.split_at(body.len() / 2);
    let mut in_flight = std::net::TcpStream::connect(addr).unwrap();
    in_flight
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    write!(
        in_flight,
        "POST /v1/evaluate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\n\r\n{first}",
        body.len()
    )
    .unwrap();
    let deadline = Instant::now() + Duration::from_secs(20);
    while !get("/metrics").contains("\nnurbsx_uploads_receiving 6\n") {
        assert!(Instant::now() < deadline, "{}", get("/metrics"));
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(get("/readyz").starts_with("HTTP/1.1 200"));

    let signalled = Instant::now();
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    loop {
        let reply = get("/readyz");
        if reply.starts_with("HTTP/1.1 503") {
            assert!(reply.contains("shutting down"), "{reply}");
            break;
        }
        assert!(
            signalled.elapsed() < Duration::from_millis(500),
            "/readyz still {reply}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    // Halfway through the drain the listener still answers, and says it is draining.
    std::thread::sleep(Duration::from_millis(700));
    let reply = get("/readyz");
    assert!(reply.starts_with("HTTP/1.1 503"), "{reply}");
    assert!(get("/healthz").starts_with("HTTP/1.1 200"));
    in_flight.write_all(second.as_bytes()).unwrap();
    let mut reply = String::new();
    in_flight.read_to_string(&mut reply).unwrap();
    assert!(reply.starts_with("HTTP/1.1 200"), "{reply}");
    assert!(
        reply.to_ascii_lowercase().contains("connection: close"),
        "{reply}"
    );
    let v: Value = serde_json::from_str(&reply[reply.find("\r\n\r\n").unwrap() + 4..]).unwrap();
    // The circle at u = 1/8: the middle of the first arc, (√2/2, √2/2).
    let p = &v["results"][0]["point"];
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert!((p[0].as_f64().unwrap() - h).abs() < 1e-12, "{v}");
    assert!((p[1].as_f64().unwrap() - h).abs() < 1e-12, "{v}");

    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if signalled.elapsed() > drain + Duration::from_secs(1) {
            child.kill().unwrap();
            panic!("still running {:?} after SIGTERM", signalled.elapsed());
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let took = signalled.elapsed();
    assert!(status.success(), "{status:?}");
    assert!(took >= drain, "exited before the drain was over: {took:?}");
    drop(hostile);
    let lines = log.join().unwrap();
    assert!(
        lines
            .iter()
            .any(|l| l.contains("version=") && l.contains("max_body_bytes=")),
        "{lines:?}"
    );
}

/// Admission by predicted wait, and `Retry-After` from the queue's drain time: after
/// computations of 400 ms on 1 slot, a request is refused once the requests ahead would
/// keep it waiting more than 2 s (5 ahead: 6 admitted; sleeps that overshoot on a loaded
/// machine make it 4 or 5), and `Retry-After` is about admitted × 0.4 s = 2.4 s, rounded
/// up (2 to 4 s), not a fixed 1.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn admission_and_retry_after_follow_the_measured_pace() {
    use nurbsx::service::gate::{Gate, QUEUE_FACTOR};
    let gate = Gate::new(1);
    assert_eq!(gate.retry_after_s(), 1, "no measurement yet");
    for _ in 0..3 {
        gate.run(|_| {
            std::thread::sleep(Duration::from_millis(400));
            Ok(())
        })
        .await
        .unwrap();
    }
    let mut held = Vec::new();
    let refused = loop {
        match gate.admit(0) {
            Ok(a) => held.push(a),
            Err(e) => break e,
        }
        assert!(held.len() <= QUEUE_FACTOR + 1);
    };
    assert!((4..=6).contains(&held.len()), "{} admitted", held.len());
    assert_eq!(refused.code, "overloaded");
    assert!(
        refused.message.contains("at the measured pace"),
        "{}",
        refused.message
    );
    assert!(
        (2..=4).contains(&refused.retry_after_s),
        "{}",
        refused.retry_after_s
    );
    use axum::response::IntoResponse;
    let reply = refused.clone().into_response();
    assert_eq!(
        reply.headers()["retry-after"],
        refused.retry_after_s.to_string().as_str()
    );
    drop(held);
    // The byte budget: bodies of the admitted requests together.
    let gate = Gate::with_byte_budget(2, 1000);
    let first = gate.admit(600).unwrap();
    let e = gate.admit(600).unwrap_err();
    assert!(e.message.contains("bodies would pass"), "{}", e.message);
    drop(first);
    assert!(gate.admit(600).is_ok());
}

/// A client that goes away while its computation runs frees the slot within 1 s.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_gone_client_frees_its_slot() {
    let server = start(ServeConfig {
        max_reply_bytes: usize::MAX,
        ..config()
    })
    .await;
    let body = json!({
        "geometry": {"degree": 2, "knots": [0, 0, 0, 1, 1, 1],
                     "control_points": [[0, 0, 0], [1, 2, 0], [3, 2, 1]]},
        "tolerance": 1e-14
    })
    .to_string();
    let mut s = TcpStream::connect(server.addr).await.unwrap();
    let head = post_head("/v1/tessellate", body.len());
    s.write_all(format!("{head}{body}").as_bytes())
        .await
        .unwrap();
    wait_for(
        server.addr,
        "nurbsx_compute_slots_busy",
        1.0,
        Duration::from_secs(10),
    )
    .await;
    drop(s);
    slot_freed_within_a_second(server.addr).await;
}

/// Parameter tuples of mixed or zero length are a malformed request (400), found while the
/// body is parsed.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn parameter_tuples_must_share_one_length() {
    let server = start(config()).await;
    for params in [json!([[0.1], [0.2, 0.3]]), json!([[]])] {
        let body = json!({ "geometry": circle(), "params": params }).to_string();
        let (status, reply, _) = request(server.addr, "POST", "/v1/evaluate", &body).await;
        assert_eq!(status, 400, "{reply}");
        assert!(reply.contains("parameter tuple"), "{reply}");
    }
    let body = json!({ "geometry": circle(), "params": [] }).to_string();
    let (status, reply, _) = request(server.addr, "POST", "/v1/evaluate", &body).await;
    assert_eq!(status, 200, "{reply}");
    assert!(reply.contains("\"results\":[]"), "{reply}");
}

/// A mesh much finer than its a-priori estimate (the mesher refines a cylinder's straight
/// direction too): with room the request is 200 and its reply stays under the limit; with a
/// limit one byte below that reply's real size it is 413 `limit.reply_bytes`, not written
/// out.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_mesh_finer_than_estimated_stops_at_the_reply_limit() {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let ring = [
        [2.0, 0.0],
        [2.0, 2.0],
        [0.0, 2.0],
        [-2.0, 2.0],
        [-2.0, 0.0],
        [-2.0, -2.0],
        [0.0, -2.0],
        [2.0, -2.0],
        [2.0, 0.0],
    ];
    let cylinder = json!({
        "degree_u": 2, "degree_v": 1,
        "knots_u": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
        "knots_v": [0, 0, 1, 1],
        "control_points": ring.iter().map(|p| json!([[p[0], p[1], 0], [p[0], p[1], 1]])).collect::<Vec<_>>(),
        "weights": ring.iter().enumerate().map(|(i, _)| {
            let wi = if i % 2 == 1 { w } else { 1.0 };
            json!([wi, wi])
        }).collect::<Vec<_>>()
    });
    let body = json!({ "geometry": cylinder, "tolerance": 1e-3 }).to_string();
    let roomy = start(ServeConfig {
        max_reply_bytes: 2_000_000,
        ..config()
    })
    .await;
    let (status, reply, _) = request(roomy.addr, "POST", "/v1/tessellate", &body).await;
    assert_eq!(status, 200);
    let vertices = reply.lines().filter(|l| l.starts_with("v ")).count();
    assert!(
        vertices > 662 && reply.len() < 2_000_000,
        "{vertices} {}",
        reply.len()
    );
    // One byte below the mesh's real size: refused, whatever the estimate allowed.
    let tight = start(ServeConfig {
        max_reply_bytes: reply.len() - 1,
        ..config()
    })
    .await;
    let (status, refused, _) = request(tight.addr, "POST", "/v1/tessellate", &body).await;
    assert_eq!(status, 413, "{refused}");
    assert!(refused.contains("limit.reply_bytes"), "{refused}");
}

/// Degree elevation's output is estimated before the work from the A5.9 pole count: a
/// limit one byte below the real reply refuses it (413 `limit.reply_bytes`, the elevated
/// file named), three times the real size accepts it (full-precision coordinates; round
/// numbers print shorter than the 25 bytes the estimate counts); model JSON and STEP.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_elevation_estimate_bounds_the_reply() {
    let n = 12;
    let knots: Vec<f64> = [0.0; 3]
        .into_iter()
        .chain((1..n - 2).map(|k| f64::from(k) / f64::from(n - 2)))
        .chain([1.0; 3])
        .collect();
    let net: Vec<Vec<[f64; 3]>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    // Full-precision coordinates, as real models have.
                    let (x, y) = (f64::from(i) / 7.0, f64::from(j) / 3.0);
                    [x, y, (x * 1.3).sin() * (y * 0.7).cos()]
                })
                .collect()
        })
        .collect();
    let surface = json!({ "degree_u": 2, "degree_v": 2, "knots_u": knots, "knots_v": knots,
                          "control_points": net });
    let step = {
        let open = start(ServeConfig {
            max_reply_bytes: usize::MAX,
            ..config()
        })
        .await;
        let (status, reply, _) = request(
            open.addr,
            "POST",
            "/v1/convert?to=step",
            &surface.to_string(),
        )
        .await;
        assert_eq!(status, 200, "{reply}");
        reply
    };
    for body in [
        json!({ "geometry": surface, "by": 2 }),
        json!({ "file": step, "by": 2, "direction": "u" }),
    ] {
        estimate_bounds_the_reply("/v1/degree-elevate", &body.to_string(), "elevated file").await;
    }
}

/// Every new option comes from its environment variable too (a flag wins), as the startup
/// line shows; zero is refused with exit 2.
#[cfg(unix)]
#[test]
fn options_come_from_flags_and_environment_variables() {
    use std::io::{BufRead, BufReader};
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_nurbsx"))
        .args(["serve", "--addr", "127.0.0.1:0", "--max-uploads", "7"])
        .env("RUST_LOG", "info")
        .env("NURBSX_MAX_UPLOADS", "9")
        .env("NURBSX_MAX_REPLY_BYTES", "1MiB")
        .env("NURBSX_MAX_UPLOAD_BYTES", "2MiB")
        .env("NURBSX_MIN_UPLOAD_RATE", "3KiB")
        .env("NURBSX_HEADER_TIMEOUT", "4s")
        .env("NURBSX_IDLE_TIMEOUT", "5s")
        .env("NURBSX_WRITE_TIMEOUT", "6s")
        .env("NURBSX_DRAIN", "0s")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let line = BufReader::new(stderr)
        .lines()
        .map_while(Result::ok)
        .find(|l| l.contains("nurbsx service listening"));
    let _ = child.kill();
    let _ = child.wait();
    let line = line.expect("a startup line") + " ";
    for field in [
        "max_uploads=7 ",
        "max_reply_bytes=1048576 ",
        "max_upload_bytes=2097152 ",
        "min_upload_rate=3072 ",
        "header_timeout_ms=4000 ",
        "idle_timeout_ms=5000 ",
        "write_timeout_ms=6000 ",
        "drain_ms=0 ",
    ] {
        assert!(line.contains(field), "{field} in {line}");
    }
    for (name, value) in [
        ("NURBSX_HEADER_TIMEOUT", "0s"),
        ("NURBSX_IDLE_TIMEOUT", "0s"),
        ("NURBSX_WRITE_TIMEOUT", "0s"),
        ("NURBSX_MIN_UPLOAD_RATE", "0"),
        ("NURBSX_MAX_UPLOADS", "0"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_nurbsx"))
            .args(["serve", "--addr", "127.0.0.1:0"])
            .env(name, value)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{name}={value}: {out:?}");
    }
}

/// A model-JSON surface: an `n` x `n` net of degree `p` both ways on uniform knots.
fn surface(n: usize, p: usize) -> Value {
    let spans = n - p;
    let mut knots = vec![0.0; p];
    knots.extend((0..=spans).map(|k| k as f64 / spans as f64));
    knots.extend(vec![1.0; p]);
    let net: Vec<Vec<[f64; 3]>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let (x, y) = (i as f64, j as f64);
                    [x, y, (0.3 * x).sin() * (0.2 * y).cos()]
                })
                .collect()
        })
        .collect();
    json!({ "degree_u": p, "degree_v": p, "knots_u": knots, "knots_v": knots,
            "control_points": net })
}

/// The streamed evaluation reply is, byte for byte, the JSON of the report the pipeline
/// builds whole (what the CLI prints), so values, digits and field order are the same: for
/// a reply smaller than one chunk (sent whole, with Content-Length) and for replies of many
/// chunks (sent chunked), on a curve and a surface, with derivatives, normals and
/// curvature.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_streamed_evaluation_is_the_whole_report_byte_for_byte() {
    use nurbsx::pipeline::{EvalRequest, InputKind, Settings};
    let server = start(ServeConfig {
        max_reply_bytes: usize::MAX,
        ..config()
    })
    .await;
    let curve_params: Vec<Vec<f64>> = (0..20_000).map(|k| vec![f64::from(k) / 19_999.0]).collect();
    let grid: Vec<Vec<f64>> = (0..3_600)
        .map(|k| vec![f64::from(k / 60) / 59.0, f64::from(k % 60) / 59.0])
        .collect();
    let cases = [
        (circle(), vec![vec![0.1], vec![0.6]], 0, false, false),
        (circle(), curve_params, 2, true, true),
        (surface(8, 3), grid, 2, true, true),
    ];
    for (geometry, params, derivatives, normals, curvature) in cases {
        let body = json!({ "geometry": geometry, "params": params, "derivatives": derivatives,
                           "normals": normals, "curvature": curvature })
        .to_string();
        let (status, head, reply, _) =
            request_with_head(server.addr, "POST", "/v1/evaluate", &body).await;
        assert_eq!(status, 200, "{reply}");
        let settings = Settings::default();
        let loaded = nurbsx::pipeline::load(
            geometry.to_string().as_bytes(),
            Some(InputKind::Json),
            &settings,
        )
        .unwrap();
        let request = EvalRequest {
            entity: None,
            params,
            derivatives,
            normals,
            curvature,
        };
        let whole = nurbsx::pipeline::evaluate(&loaded.document, &request, &settings).unwrap();
        let expected = serde_json::to_string(&whole).unwrap();
        assert!(
            reply == expected,
            "the streamed reply differs from the report"
        );
        let chunked = head
            .to_ascii_lowercase()
            .contains("transfer-encoding: chunked");
        assert_eq!(
            chunked,
            expected.len() > nurbsx::service::reply::CHUNK_BYTES,
            "{} bytes: {head}",
            expected.len()
        );
    }
}

/// Reads one HTTP/1.1 reply with a `Content-Length` from a keep-alive connection: its
/// status.
async fn read_reply(s: &mut TcpStream) -> u16 {
    let mut data = Vec::new();
    let mut buf = [0u8; 4096];
    let (head_end, length) = loop {
        let n = tokio::time::timeout(Duration::from_secs(10), s.read(&mut buf))
            .await
            .expect("a reply within 10 s")
            .unwrap();
        assert!(n > 0, "closed before the reply");
        data.extend_from_slice(&buf[..n]);
        if let Some(i) = data.windows(4).position(|w| w == b"\r\n\r\n") {
            let head = String::from_utf8_lossy(&data[..i]).to_ascii_lowercase();
            let length: usize = head
                .lines()
                .find_map(|l| l.strip_prefix("content-length:"))
                .and_then(|v| v.trim().parse().ok())
                .unwrap_or_else(|| panic!("no content-length in {head}"));
            break (i + 4, length);
        }
    };
    while data.len() < head_end + length {
        let n = s.read(&mut buf).await.unwrap();
        assert!(n > 0, "closed inside the reply");
        data.extend_from_slice(&buf[..n]);
    }
    String::from_utf8_lossy(&data[9..12]).parse().unwrap()
}

/// The idle timeout (1.5 s here) and the header timeout (300 ms) are separate: a keep-alive
/// connection silent for 1 s between requests is still served, then closed about 1.5 s
/// after its last reply (not before 1.4 s, and within 2.5 s); a request head begun after a
/// pause must still be complete within the header timeout; and a connection whose request
/// is in flight (its body arriving over 2.5 s) is not closed as idle, and is kept alive
/// after its reply.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn idle_connections_close_after_the_idle_timeout_and_busy_ones_do_not() {
    let server = start(ServeConfig {
        header_timeout: Duration::from_millis(300),
        idle_timeout: Duration::from_millis(1500),
        ..config()
    })
    .await;
    let get = b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n";
    let mut idle = TcpStream::connect(server.addr).await.unwrap();
    idle.write_all(get).await.unwrap();
    assert_eq!(read_reply(&mut idle).await, 200);
    tokio::time::sleep(Duration::from_secs(1)).await;
    idle.write_all(get).await.unwrap();
    assert_eq!(read_reply(&mut idle).await, 200);
    let since = Instant::now();
    assert!(closed_within(&mut idle, Duration::from_secs(3)).await);
    let took = since.elapsed();
    assert!(
        took >= Duration::from_millis(1400) && took < Duration::from_millis(2500),
        "closed {took:?} after the last reply"
    );

    let mut slow_head = TcpStream::connect(server.addr).await.unwrap();
    slow_head.write_all(get).await.unwrap();
    assert_eq!(read_reply(&mut slow_head).await, 200);
    tokio::time::sleep(Duration::from_millis(200)).await;
    slow_head
        .write_all(b"GET /healthz HTTP/1.1\r\n")
        .await
        .unwrap();
    let since = Instant::now();
    assert!(closed_within(&mut slow_head, Duration::from_secs(3)).await);
    let took = since.elapsed();
    assert!(
        took >= Duration::from_millis(250) && took < Duration::from_millis(1000),
        "a half-sent head was closed after {took:?}"
    );

    let body = evaluate_body();
    let (first, second) = body.split_at(body.len() / 2);
    let mut busy = TcpStream::connect(server.addr).await.unwrap();
    let head = post_head("/v1/evaluate", body.len());
    busy.write_all(format!("{head}{first}").as_bytes())
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_millis(2500)).await;
    busy.write_all(second.as_bytes()).await.unwrap();
    assert_eq!(read_reply(&mut busy).await, 200);
    busy.write_all(get).await.unwrap();
    assert_eq!(read_reply(&mut busy).await, 200);
}

/// An HTTP/2 client with prior knowledge (h2c) is served on the same port: two requests at
/// once on one connection, each answered 200 over HTTP/2 with the right values. On
/// shutdown with that connection open, `/readyz` over it turns 503 during the drain, the
/// server ends the connection, and `serve_on` returns within drain (1 s) + 1 s.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn http2_prior_knowledge_is_served_and_drained() {
    use http_body_util::{BodyExt, Full};
    use hyper::body::Bytes;
    use hyper_util::rt::{TokioExecutor, TokioIo};
    let mut server = start(ServeConfig {
        drain: Duration::from_secs(1),
        ..config()
    })
    .await;
    let addr = server.addr;
    let stream = TcpStream::connect(addr).await.unwrap();
    let (sender, connection) =
        hyper::client::conn::http2::handshake(TokioExecutor::new(), TokioIo::new(stream))
            .await
            .unwrap();
    let mut connection = tokio::spawn(connection);
    let call = |method: &str, path: &str, body: String| {
        let mut sender = sender.clone();
        let request = hyper::Request::builder()
            .method(method)
            .uri(format!("http://{addr}{path}"))
            .header("content-type", "application/json")
            .body(Full::new(Bytes::from(body)))
            .unwrap();
        async move {
            let reply = sender.send_request(request).await.unwrap();
            assert_eq!(reply.version(), hyper::Version::HTTP_2);
            let status = reply.status().as_u16();
            let body = reply.into_body().collect().await.unwrap().to_bytes();
            (status, String::from_utf8_lossy(&body).into_owned())
        }
    };
    let a = json!({ "geometry": circle(), "params": [[0.125]] }).to_string();
    let b = json!({ "geometry": circle(), "params": [[0.375]] }).to_string();
    let (ra, rb) = tokio::join!(
        call("POST", "/v1/evaluate", a),
        call("POST", "/v1/evaluate", b)
    );
    let h = std::f64::consts::FRAC_1_SQRT_2;
    for ((status, body), x) in [(ra, h), (rb, -h)] {
        assert_eq!(status, 200, "{body}");
        let v: Value = serde_json::from_str(&body).unwrap();
        let p = &v["results"][0]["point"];
        assert!((p[0].as_f64().unwrap() - x).abs() < 1e-12, "{v}");
        assert!((p[1].as_f64().unwrap() - h).abs() < 1e-12, "{v}");
    }
    let (status, _) = call("GET", "/readyz", String::new()).await;
    assert_eq!(status, 200);

    let asked = Instant::now();
    server.stop.take().unwrap().send(()).unwrap();
    tokio::time::sleep(Duration::from_millis(200)).await;
    let (status, body) = call("GET", "/readyz", String::new()).await;
    assert_eq!(status, 503, "{body}");
    tokio::time::timeout(Duration::from_secs(2), &mut server.task)
        .await
        .expect("shutdown within drain + 1 s")
        .unwrap()
        .unwrap();
    assert!(
        asked.elapsed() >= Duration::from_secs(1),
        "{:?}",
        asked.elapsed()
    );
    tokio::time::timeout(Duration::from_secs(1), &mut connection)
        .await
        .expect("the server ended the HTTP/2 connection")
        .unwrap()
        .ok();
}

/// A STEP file of `n` B-spline curves on the same three points: little text per curve, so
/// that reading is mostly the curves' decoding, little the syntax scan.
fn many_curves_step(n: usize) -> String {
    let mut text = String::from(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n\
         FILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n\
         #1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=CARTESIAN_POINT('',(0.5,1.,0.));\n\
         #3=CARTESIAN_POINT('',(1.,0.,1.));\n",
    );
    for k in 0..n {
        text.push_str(&format!(
            "#{}=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);\n",
            k + 4
        ));
    }
    text.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    text
}

/// Sends `body` (JSON) to `path` on a server with the time limit `limit`, checks that the
/// work started (a slot busy), that the reply is 503 `timeout`, and that the slot is free
/// within 1 s of it.
async fn times_out_and_frees_its_slot(path: &str, body: String, limit: Duration) {
    typed_times_out_and_frees_its_slot(path, "application/json", body, limit).await;
}

/// [`times_out_and_frees_its_slot`] with a body of type `content_type`.
async fn typed_times_out_and_frees_its_slot(
    path: &str,
    content_type: &'static str,
    body: String,
    limit: Duration,
) {
    let server = start(ServeConfig {
        request_timeout: limit,
        max_reply_bytes: usize::MAX,
        ..config()
    })
    .await;
    let addr = server.addr;
    let path = path.to_owned();
    let call =
        tokio::spawn(async move { request_typed(addr, "POST", &path, content_type, &body).await });
    wait_for(
        addr,
        "nurbsx_compute_slots_busy",
        1.0,
        Duration::from_secs(10),
    )
    .await;
    let (status, _, reply, _) = call.await.unwrap();
    assert_eq!(status, 503, "{reply}");
    assert!(reply.contains("\"timeout\""), "{reply}");
    slot_freed_within_a_second(addr).await;
}

/// Reading a large STEP file (480,000 curves, 45 MB: in a debug build the 10 MB of 120,000
/// curves took 0.7 s of syntax scan then 3.4 s of decoding on a loaded host, and under 1 s
/// on a fast one; both polled) stops when its request times out at 0.5 s: the slot is free
/// within 1 s of the 503. The work is sized so that a debug build would need about 90 MB/s
/// to finish before the limit.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_timed_out_read_frees_its_slot_within_a_second() {
    let limit = Duration::from_millis(500);
    let step = many_curves_step(480_000);
    let body = json!({ "file": step, "params": [[0.5]] }).to_string();
    times_out_and_frees_its_slot("/v1/evaluate", body, limit).await;
}

/// A STEP file of `n` tiny statements that no reader decodes (`#k=X();`): reading it is
/// almost all syntax scan.
fn tiny_statements_step(n: usize) -> String {
    let mut text = String::from(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n\
         FILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n",
    );
    for k in 1..=n {
        text.push_str(&format!("#{k}=X();\n"));
    }
    text.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    text
}

/// The syntax scan of a large STEP body (4.5 million tiny statements, 60 MB, in the body
/// limit: seconds of scan in a debug build, under 2 s on a fast host, before any decoding)
/// stops when its request times out at 0.3 s, because it polls the stop signal: the slot
/// is free within 1 s of the 503. A debug build would need 200 MB/s to finish first.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_timed_out_syntax_scan_frees_its_slot_within_a_second() {
    let body = tiny_statements_step(4_500_000);
    assert!(body.len() < 64 << 20, "{} bytes", body.len());
    times_out_and_frees_its_slot("/v1/info", body, Duration::from_millis(300)).await;
}

/// The STEP and IGES writers poll the stop signal before each curve and surface: writing
/// 120,000 curves (about 2 s for STEP, 4 s for IGES in a debug build) stopped 300 ms in
/// ends with `cancelled` within 0.5 s of the signal.
#[test]
fn a_stopped_write_ends_within_half_a_second() {
    use nurbsx::exchange::{self, Cancel, ExportOptions, Format, ImportOptions};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    let doc = exchange::read(
        many_curves_step(120_000).as_bytes(),
        &ImportOptions::default(),
    )
    .unwrap();
    assert_eq!(doc.entities.len(), 120_000);
    for format in [Format::Step, Format::Iges] {
        let fired = Arc::new(AtomicBool::new(false));
        let flag = fired.clone();
        let options = ExportOptions {
            cancel: Cancel::new(move || flag.load(Ordering::Relaxed)),
            ..ExportOptions::default()
        };
        let timer = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(300));
            fired.store(true, Ordering::Relaxed);
            Instant::now()
        });
        let result = exchange::write(&doc, format, &options);
        let ended = Instant::now();
        let fired_at = timer.join().unwrap();
        let err = result.expect_err("stopped");
        assert_eq!(err.code, "cancelled", "{format:?}: {err}");
        let late = ended.saturating_duration_since(fired_at);
        assert!(late < Duration::from_millis(500), "{format:?}: {late:?}");
    }
}

/// Elevating one surface (a 64 x 64 net of degree 5 by 20 both ways: 1.5 million poles
/// out, about 2.3 s of elevation in a debug build on a slow host, a third of that on a fast
/// one; polled once per Bezier strip) stops when its request times out at 0.3 s: the slot
/// is free within 1 s of the 503.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_timed_out_elevation_frees_its_slot_within_a_second() {
    let body = json!({ "geometry": surface(64, 5), "by": 20 }).to_string();
    let limit = Duration::from_millis(300);
    times_out_and_frees_its_slot("/v1/degree-elevate", body, limit).await;
}

/// A request of `n` evaluations of the unit circle at `(k + 0.5) / n`.
fn many_evaluations(n: u32) -> String {
    let params: Vec<[f64; 1]> = (0..n)
        .map(|k| [(f64::from(k) + 0.5) / f64::from(n)])
        .collect();
    json!({ "geometry": circle(), "params": params }).to_string()
}

/// [`many_evaluations`] asking for three derivatives and the curvature and torsion of each
/// point: several times the work and the reply per point for the same body, so that the
/// computation, not the upload and parse, takes the time.
fn many_full_evaluations(n: u32) -> String {
    let params: Vec<[f64; 1]> = (0..n)
        .map(|k| [(f64::from(k) + 0.5) / f64::from(n)])
        .collect();
    json!({ "geometry": circle(), "params": params, "derivatives": 3, "curvature": true })
        .to_string()
}

/// Sends `body` (from [`many_evaluations`]) to `/v1/evaluate`, reads `keep` bytes of the
/// reply, and returns the connection.
async fn start_reading(addr: SocketAddr, body: &str, keep: usize) -> TcpStream {
    let mut s = TcpStream::connect(addr).await.unwrap();
    let head = post_head("/v1/evaluate", body.len());
    s.write_all(format!("{head}{body}").as_bytes())
        .await
        .unwrap();
    let mut got = vec![0u8; keep];
    tokio::time::timeout(Duration::from_secs(20), s.read_exact(&mut got))
        .await
        .expect("the reply starts within 20 s")
        .unwrap();
    assert!(
        got.starts_with(b"HTTP/1.1 200"),
        "{}",
        String::from_utf8_lossy(&got)
    );
    s
}

/// A streamed reply does not hold its computing slot for a client that will not take it:
/// one that stops reading frees the slot within the write timeout (500 ms) + 1 s of the
/// moment its buffers are full, one that closes its connection within 1 s, and one whose
/// request passes the time limit (2 s) while its reply streams gets a cut-off reply (no
/// last chunk) and frees the slot within 1 s of the limit. The whole evaluation (400,000
/// points with three derivatives, curvature and torsion: over 100 MB of reply) takes
/// several times the 2 s in a debug build; 400,000 points alone took under 2 s on a fast
/// host, while the upload and parse of the body must fit in the limit under load.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_streamed_reply_frees_its_slot_when_the_client_stops_taking_it() {
    let server = start(ServeConfig {
        max_reply_bytes: usize::MAX,
        write_timeout: Duration::from_millis(500),
        ..config()
    })
    .await;
    let addr = server.addr;
    let body = many_full_evaluations(400_000);
    // Stops reading: the socket buffers and the chunk queue fill, then the write timeout.
    let stalled = start_reading(addr, &body, 4096).await;
    let since = Instant::now();
    wait_for(
        addr,
        "nurbsx_compute_slots_busy",
        0.0,
        Duration::from_secs(5),
    )
    .await;
    let took = since.elapsed();
    assert!(took < Duration::from_millis(3500), "{took:?}");
    drop(stalled);

    // Goes away: the queue closes.
    let gone = start_reading(addr, &body, 4096).await;
    drop(gone);
    slot_freed_within_a_second(addr).await;

    // Reads everything, but the time limit passes while the reply streams.
    let limit = Duration::from_secs(2);
    let server = start(ServeConfig {
        max_reply_bytes: usize::MAX,
        request_timeout: limit,
        ..config()
    })
    .await;
    let started = Instant::now();
    let mut reader = start_reading(server.addr, &body, 12).await;
    let mut rest = Vec::new();
    tokio::time::timeout(Duration::from_secs(30), reader.read_to_end(&mut rest))
        .await
        .expect("the reply ends")
        .ok();
    let ended = started.elapsed();
    assert!(
        ended < limit + Duration::from_secs(1),
        "the reply is cut at the time limit: {ended:?}"
    );
    assert!(
        !rest.ends_with(b"\r\n0\r\n\r\n"),
        "a cut reply has no last chunk"
    );
    slot_freed_within_a_second(server.addr).await;
}

/// The peak resident memory (VmHWM) of a process, in bytes.
#[cfg(target_os = "linux")]
fn peak_rss(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or_else(|| panic!("no VmHWM in {status}"));
    kb * 1024
}

/// The documented bound (README "HTTP service", peak RSS table) on the server's peak
/// memory while it streams 1 million evaluations.
const STREAMED_EVALUATION_RSS_BOUND: u64 = 64 << 20;

/// The real server streams 1,000,000 evaluations (a 13 MB request, a 73 MB reply) with a
/// peak resident memory under [`STREAMED_EVALUATION_RSS_BOUND`], less than the reply
/// itself (built whole, the reply alone would pass it); every result is there, in order,
/// on the circle.
#[cfg(target_os = "linux")]
#[test]
fn a_large_evaluation_streams_in_bounded_memory() {
    use std::io::{BufRead, BufReader, Read, Write};
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_nurbsx"))
        .args(["serve", "--addr", "127.0.0.1:0", "--concurrency", "1"])
        .args(["--max-reply-bytes", "1GiB"])
        .env("RUST_LOG", "info")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (addr_tx, addr_rx) = std::sync::mpsc::channel::<String>();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if line.contains("nurbsx service listening") {
                let addr = line
                    .split_whitespace()
                    .find_map(|w| w.strip_prefix("addr="))
                    .unwrap_or_default()
                    .to_owned();
                let _ = addr_tx.send(addr);
            }
        }
    });
    let addr: SocketAddr = addr_rx
        .recv_timeout(Duration::from_secs(30))
        .expect("the startup line names the address")
        .parse()
        .unwrap();
    let n = 1_000_000;
    let body = many_evaluations(n);
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
    write!(
        s,
        "POST /v1/evaluate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    )
    .unwrap();
    s.write_all(body.as_bytes()).unwrap();
    drop(body);
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let peak = peak_rss(child.id());
    let _ = child.kill();
    let _ = child.wait();
    let text = String::from_utf8(raw).unwrap();
    let (head, chunked) = text.split_once("\r\n\r\n").unwrap();
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    let reply = dechunk(chunked);
    let v: Value = serde_json::from_str(&reply).unwrap();
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), n as usize);
    for (k, r) in results.iter().enumerate().step_by(997) {
        let u = (k as f64 + 0.5) / f64::from(n);
        assert_eq!(r["at"][0].as_f64().unwrap(), u);
        let (x, y) = (
            r["point"][0].as_f64().unwrap(),
            r["point"][1].as_f64().unwrap(),
        );
        assert!((x.hypot(y) - 1.0).abs() < 1e-12, "{r}");
    }
    eprintln!(
        "streamed {} reply bytes; server peak RSS {} MiB",
        reply.len(),
        peak >> 20
    );
    assert!(
        peak < STREAMED_EVALUATION_RSS_BOUND && peak < reply.len() as u64,
        "peak RSS {peak} bytes for a reply of {} bytes",
        reply.len()
    );
}

/// Converting stops when its request times out at 1 s, whatever stage it is in, and its
/// slot is free within 1 s of the 503: a large STEP file (120,000 curves, 10 MB: reading,
/// then writing as IGES, several seconds in a debug build), the same with lower-case
/// keywords (read again after a pass that upper-cases them), and 16 MB of model JSON (a
/// 700 x 700 surface: seconds of JSON parsing in a debug build, then the STEP writer).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_timed_out_conversion_frees_its_slot_within_a_second() {
    let limit = Duration::from_secs(1);
    let step = many_curves_step(120_000);
    let lower = step.replace("B_SPLINE_CURVE_WITH_KNOTS", "b_spline_curve_with_knots");
    typed_times_out_and_frees_its_slot("/v1/convert?to=iges", "model/step", step, limit).await;
    typed_times_out_and_frees_its_slot("/v1/convert?to=iges", "model/step", lower, limit).await;
    let json = surface(700, 3).to_string();
    times_out_and_frees_its_slot("/v1/convert?to=step", json, limit).await;
}

/// The quadric patch of the peak-memory measurement (README "HTTP service").
fn quadric_patch() -> Value {
    json!({
        "degree_u": 2, "degree_v": 2,
        "knots_u": [0, 0, 0, 1, 1, 1], "knots_v": [0, 0, 0, 1, 1, 1],
        "control_points": [[[0, 0, 0], [0, 1, 0.3], [0, 2, 0]], [[1, 0, 0.2], [1, 1, 1.1], [1, 2, 0.1]],
                           [[2, 0, 0], [2, 1, -0.4], [2, 2, 0.5]]]
    })
}

/// The number of vertices of a binary glTF reply (the POSITION accessors' counts of its
/// JSON chunk, which is ASCII).
fn glb_vertices(reply: &str) -> u64 {
    let json = reply.find('{').map(|k| &reply[k..]).unwrap();
    let doc: Value = serde_json::Deserializer::from_str(json)
        .into_iter::<Value>()
        .next()
        .unwrap()
        .unwrap();
    let accessors = doc["accessors"].as_array().unwrap();
    doc["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            let k = m["primitives"][0]["attributes"]["POSITION"]
                .as_u64()
                .unwrap();
            accessors[k as usize]["count"].as_u64().unwrap()
        })
        .sum()
}

/// Binary glTF is the densest mesh reply (about 36 bytes a vertex), so the reply limit
/// alone let a mesh grow until its working memory (160 bytes a vertex) passed the
/// documented peak. The tessellation's working-memory budget, 3 times the reply limit,
/// caps it: with a 1 MB reply limit (budget 3 MB, 18,750 vertices), the patch at tolerance
/// 1e-4 (a glTF file of about 0.8 MB, within the reply limit) is refused with 413
/// `limit.mesh_memory`, and at 1e-3 it is drawn with fewer vertices than the cap.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_memory_budget_caps_a_gltf_mesh() {
    let server = start(ServeConfig {
        max_reply_bytes: 1_000_000,
        ..config()
    })
    .await;
    let cap = 3 * 1_000_000 / 160;
    let ask = |tolerance: f64| {
        json!({ "geometry": quadric_patch(), "tolerance": tolerance, "format": "glb" }).to_string()
    };
    let (status, reply, _) = request(server.addr, "POST", "/v1/tessellate", &ask(1e-3)).await;
    assert_eq!(status, 200, "{reply}");
    let vertices = glb_vertices(&reply);
    assert!(vertices > 1000 && vertices <= cap, "{vertices}");
    let (status, reply, _) = request(server.addr, "POST", "/v1/tessellate", &ask(1e-4)).await;
    assert_eq!(status, 413, "{reply}");
    assert!(reply.contains("limit.mesh_memory"), "{reply}");
    assert!(
        reply.contains(&format!("more than {cap} vertices")),
        "{reply}"
    );
}
