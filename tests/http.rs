//! The HTTP service driven in-process (`tower::ServiceExt::oneshot` on `service::app`) for
//! every endpoint and error status, plus one request over a real loopback socket.
//!
//! Geometry answers are checked against independent computations (the Bernstein form of a
//! rational quadratic arc, bilinear interpolation, central differences), never against
//! captured output.

// Test helpers outside #[test] functions fail loudly on purpose.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::pin::Pin;
use std::task::{Context, Poll};
use std::time::Duration;

use axum::Router;
use axum::body::{Body, Bytes, HttpBody};
use axum::http::{HeaderMap, Method, Request, StatusCode, header};
use http_body_util::BodyExt;
use serde_json::{Value, json};
use tower::ServiceExt;

use nurbsx::service::{self, ServeConfig};

const W: f64 = std::f64::consts::FRAC_1_SQRT_2;

fn config() -> ServeConfig {
    ServeConfig {
        max_concurrency: 2,
        ..ServeConfig::default()
    }
}

fn app() -> Router {
    service::app(config())
}

/// The unit circle as 4 rational quadratic arcs (9 poles, weights 1, √2/2, ...).
fn circle() -> Value {
    json!({
        "degree": 2,
        "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
        "control_points": [[1,0,0],[1,1,0],[0,1,0],[-1,1,0],[-1,0,0],[-1,-1,0],[0,-1,0],[1,-1,0],[1,0,0]],
        "weights": [1, W, 1, W, 1, W, 1, W, 1]
    })
}

/// The circle point at `u` by the Bernstein form of the arc holding `u`, independent of
/// the knot-vector evaluation the service uses.
fn circle_bernstein(u: f64) -> [f64; 2] {
    let p = [
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [-1.0, 1.0],
        [-1.0, 0.0],
        [-1.0, -1.0],
        [0.0, -1.0],
        [1.0, -1.0],
        [1.0, 0.0],
    ];
    let k = ((u * 4.0).floor() as usize).min(3);
    let t = u * 4.0 - k as f64;
    let (a, b, c) = (p[2 * k], p[2 * k + 1], p[2 * k + 2]);
    let (b0, b1, b2) = ((1.0 - t).powi(2), 2.0 * t * (1.0 - t) * W, t * t);
    let d = b0 + b1 + b2;
    [
        (b0 * a[0] + b1 * b[0] + b2 * c[0]) / d,
        (b0 * a[1] + b1 * b[1] + b2 * c[1]) / d,
    ]
}

/// A bilinear patch: S(u, v) = (2u, 3v, 1 + u v) on [0,1]².
fn bilinear() -> Value {
    json!({
        "degree_u": 1, "degree_v": 1,
        "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
        "control_points": [[[0,0,1],[0,3,1]], [[2,0,1],[2,3,2]]]
    })
}

async fn send(app: Router, req: Request<Body>) -> (StatusCode, HeaderMap, Bytes) {
    let response = app.oneshot(req).await.expect("router is infallible");
    let status = response.status();
    let headers = response.headers().clone();
    let body = response
        .into_body()
        .collect()
        .await
        .expect("body reads")
        .to_bytes();
    (status, headers, body)
}

fn post_json(path: &str, body: &Value) -> Request<Body> {
    Request::builder()
        .method(Method::POST)
        .uri(path)
        .header(header::CONTENT_TYPE, "application/json")
        .body(Body::from(body.to_string()))
        .unwrap()
}

fn post_raw(path: &str, content_type: Option<&str>, body: impl Into<Body>) -> Request<Body> {
    let mut b = Request::builder().method(Method::POST).uri(path);
    if let Some(ct) = content_type {
        b = b.header(header::CONTENT_TYPE, ct);
    }
    b.body(body.into()).unwrap()
}

fn get(path: &str) -> Request<Body> {
    Request::builder().uri(path).body(Body::empty()).unwrap()
}

fn json_of(body: &Bytes) -> Value {
    serde_json::from_slice(body)
        .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(body)))
}

/// Asserts a JSON error reply with this status and code; returns the error object.
async fn expect_error(app: Router, req: Request<Body>, status: StatusCode, code: &str) -> Value {
    let (got, headers, body) = send(app, req).await;
    let v = json_of(&body);
    assert_eq!(got, status, "{v}");
    assert_eq!(
        headers.get(header::CONTENT_TYPE).unwrap(),
        "application/json",
        "{v}"
    );
    let e = &v["error"];
    assert_eq!(e["code"], code, "{v}");
    assert!(e["message"].as_str().is_some_and(|m| !m.is_empty()), "{v}");
    assert!(e.get("location").is_some(), "{v}");
    e.clone()
}

async fn openapi() -> Value {
    let (status, _, body) = send(app(), get("/openapi.json")).await;
    assert_eq!(status, StatusCode::OK);
    json_of(&body)
}

/// Checks `value` against an OpenAPI schema structurally: every object key is a declared
/// property, every required property is present, arrays and `oneOf` recurse. This is what
/// keeps the documentation mirrors honest about the real reply types.
fn conforms(value: &Value, schema: &Value, doc: &Value, path: &str) -> Result<(), String> {
    if let Some(r) = schema.get("$ref").and_then(Value::as_str) {
        let name = r.trim_start_matches("#/components/schemas/");
        let target = &doc["components"]["schemas"][name];
        assert!(!target.is_null(), "dangling $ref {r}");
        return conforms(value, target, doc, path);
    }
    for key in ["oneOf", "anyOf"] {
        if let Some(options) = schema.get(key).and_then(Value::as_array) {
            if value.is_null() && options.iter().any(|o| o["type"] == "null") {
                return Ok(());
            }
            let errors: Vec<String> = options
                .iter()
                .filter(|o| o["type"] != "null")
                .filter_map(|o| conforms(value, o, doc, path).err())
                .collect();
            return if errors.len() < options.iter().filter(|o| o["type"] != "null").count() {
                Ok(())
            } else {
                Err(format!("{path}: matches no {key} branch: {errors:?}"))
            };
        }
    }
    match value {
        Value::Object(map) => {
            if let Some(props) = schema.get("properties").and_then(Value::as_object) {
                for (k, v) in map {
                    let s = props
                        .get(k)
                        .ok_or_else(|| format!("{path}: key {k:?} is not in the schema"))?;
                    conforms(v, s, doc, &format!("{path}.{k}"))?;
                }
                for r in schema["required"].as_array().into_iter().flatten() {
                    let r = r.as_str().unwrap();
                    if !map.contains_key(r) {
                        return Err(format!("{path}: required {r:?} missing"));
                    }
                }
            }
            Ok(())
        }
        Value::Array(items) => {
            if let Some(s) = schema.get("items") {
                for (i, v) in items.iter().enumerate() {
                    conforms(v, s, doc, &format!("{path}[{i}]"))?;
                }
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

fn schema_ref(name: &str) -> Value {
    json!({ "$ref": format!("#/components/schemas/{name}") })
}

// ---------------------------------------------------------------------------------------
// /v1/evaluate on model JSON (works now)

#[tokio::test]
async fn evaluate_circle_matches_the_bernstein_form_and_the_schema() {
    let params: Vec<f64> = (0..=40).map(|i| f64::from(i) / 40.0).collect();
    let body = json!({
        "geometry": circle(),
        "params": params.iter().map(|u| [u]).collect::<Vec<_>>()
    });
    let (status, headers, bytes) = send(app(), post_json("/v1/evaluate", &body)).await;
    let v = json_of(&bytes);
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(headers[header::CONTENT_TYPE], "application/json");
    assert_eq!(v["entity"], "0");
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), params.len());
    for (r, &u) in results.iter().zip(&params) {
        assert_eq!(r["at"], json!([u]));
        let p: Vec<f64> = serde_json::from_value(r["point"].clone()).unwrap();
        assert_eq!(p.len(), 3, "a 3-D curve gives 3 coordinates");
        let want = circle_bernstein(u);
        assert!(
            (p[0] - want[0]).abs() < 1e-12 && (p[1] - want[1]).abs() < 1e-12 && p[2] == 0.0,
            "u = {u}: {p:?} vs {want:?}"
        );
        assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12, "on the unit circle");
    }
    let doc = openapi().await;
    conforms(&v, &schema_ref("EvalReport"), &doc, "$").unwrap();
}

#[tokio::test]
async fn evaluate_surface_matches_bilinear_interpolation() {
    let at = [[0.0, 0.0], [0.25, 0.5], [1.0, 1.0], [0.8, 0.1]];
    let body = json!({ "geometry": bilinear(), "params": at });
    let (status, _, bytes) = send(app(), post_json("/v1/evaluate", &body)).await;
    let v = json_of(&bytes);
    assert_eq!(status, StatusCode::OK, "{v}");
    for (r, [u, v_]) in v["results"].as_array().unwrap().iter().zip(at) {
        let p: Vec<f64> = serde_json::from_value(r["point"].clone()).unwrap();
        let want = [2.0 * u, 3.0 * v_, 1.0 + u * v_];
        for k in 0..3 {
            assert!((p[k] - want[k]).abs() < 1e-14, "{p:?} vs {want:?}");
        }
    }
}

#[tokio::test]
async fn evaluate_selects_an_entity_of_an_array() {
    let body = json!({
        "geometry": [circle(), bilinear()],
        "entity": "1",
        "params": [[0.5, 0.5]]
    });
    let (status, _, bytes) = send(app(), post_json("/v1/evaluate", &body)).await;
    let v = json_of(&bytes);
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(v["entity"], "1");
    assert_eq!(v["results"][0]["point"], json!([1.0, 1.5, 1.25]));
}

// ---------------------------------------------------------------------------------------
// Error statuses

#[tokio::test]
async fn malformed_requests_are_400_json() {
    let cases: Vec<(Request<Body>, &str)> = vec![
        (
            post_raw("/v1/evaluate", Some("application/json"), "{\"geometry\": "),
            "request.json_syntax",
        ),
        (
            post_json("/v1/evaluate", &json!({ "geometry": circle() })),
            "request.invalid",
        ),
        (
            post_json(
                "/v1/evaluate",
                &json!({ "geometry": circle(), "params": [[0.5]], "derivative": 1 }),
            ),
            "request.invalid",
        ),
        (
            post_json("/v1/evaluate", &json!({ "params": [[0.5]] })),
            "request.input",
        ),
        (
            post_json(
                "/v1/evaluate",
                &json!({ "geometry": circle(), "file": "x", "params": [[0.5]] }),
            ),
            "request.input",
        ),
        (
            post_json(
                "/v1/evaluate",
                &json!({ "geometry": circle(), "params": [[1.5]] }),
            ),
            "evaluate.domain",
        ),
        (
            post_json(
                "/v1/evaluate",
                &json!({ "geometry": circle(), "params": [[0.5, 0.5]] }),
            ),
            "evaluate.arity",
        ),
        (
            post_json(
                "/v1/evaluate",
                &json!({ "geometry": circle(), "entity": "7", "params": [[0.5]] }),
            ),
            "entity.not_found",
        ),
        (
            post_raw(
                "/v1/convert?to=dxf",
                Some("application/json"),
                circle().to_string(),
            ),
            "request.query",
        ),
        (
            post_raw(
                "/v1/convert?to=step&units=parsec",
                Some("application/json"),
                circle().to_string(),
            ),
            "request.units",
        ),
        (
            post_raw(
                "/v1/convert?to=step&verify=-1",
                Some("application/json"),
                circle().to_string(),
            ),
            "request.verify",
        ),
        (
            post_raw(
                "/v1/convert",
                Some("application/json"),
                circle().to_string(),
            ),
            "convert.no_target",
        ),
        (post_raw("/v1/info", None, ""), "request.empty"),
        (
            post_json(
                "/v1/evaluate",
                &json!({ "geometry": circle(), "format": "step", "params": [[0.5]] }),
            ),
            "request.input",
        ),
        (
            post_json(
                "/v1/degree-elevate",
                &json!({ "geometry": circle(), "by": 1, "direction": "w" }),
            ),
            "request.invalid",
        ),
    ];
    for (req, code) in cases {
        let what = format!("{} {}", req.method(), req.uri());
        let e = expect_error(app(), req, StatusCode::BAD_REQUEST, code).await;
        assert!(!e.to_string().is_empty(), "{what}");
    }
}

#[tokio::test]
async fn invalid_geometry_is_422_with_its_location() {
    // 3 poles of degree 2 need 6 knots, not 5.
    let bad =
        json!({ "degree": 2, "knots": [0, 0, 0, 1, 1], "control_points": [[0,0],[1,1],[2,0]] });
    let e = expect_error(
        app(),
        post_json(
            "/v1/evaluate",
            &json!({ "geometry": bad, "params": [[0.5]] }),
        ),
        StatusCode::UNPROCESSABLE_ENTITY,
        "geometry.invalid",
    )
    .await;
    assert_eq!(e["location"]["entity"], "0", "{e}");
    assert!(e["message"].as_str().unwrap().contains("knot"), "{e}");
    // Zero weight: refused by the checked constructor.
    let mut zero = circle();
    zero["weights"][1] = json!(0.0);
    expect_error(
        app(),
        post_raw("/v1/info", Some("application/json"), zero.to_string()),
        StatusCode::UNPROCESSABLE_ENTITY,
        "geometry.invalid",
    )
    .await;
    // A body declared STEP that is not STEP.
    expect_error(
        app(),
        post_raw("/v1/info", Some("model/step"), "hello"),
        StatusCode::UNPROCESSABLE_ENTITY,
        "format.mismatch",
    )
    .await;
    // Broken JSON sent as a file to /v1/info: the pipeline's JSON syntax error, located.
    let e = expect_error(
        app(),
        post_raw("/v1/info", Some("application/json"), "{\n \"degree\": ,"),
        StatusCode::UNPROCESSABLE_ENTITY,
        "json.syntax",
    )
    .await;
    assert_eq!(e["location"]["line"], 2, "{e}");
}

#[tokio::test]
async fn unknown_formats_and_content_types_are_415() {
    expect_error(
        app(),
        post_raw("/v1/info", Some("application/octet-stream"), "hello, world"),
        StatusCode::UNSUPPORTED_MEDIA_TYPE,
        "format.unknown",
    )
    .await;
    // Content that is recognisably something else is named by what it is.
    let e = expect_error(
        app(),
        post_raw(
            "/v1/info",
            Some("application/octet-stream"),
            "%PDF-1.7\n1 0 obj\n",
        ),
        StatusCode::UNSUPPORTED_MEDIA_TYPE,
        "format.other",
    )
    .await;
    assert!(e.to_string().contains("PDF document"), "{e}");
    expect_error(
        app(),
        post_raw("/v1/convert?to=step", Some("image/png"), "\u{89}PNG"),
        StatusCode::UNSUPPORTED_MEDIA_TYPE,
        "request.content_type",
    )
    .await;
    // A JSON endpoint without a JSON Content-Type.
    expect_error(
        app(),
        post_raw(
            "/v1/evaluate",
            Some("text/plain"),
            json!({ "geometry": circle(), "params": [[0]] }).to_string(),
        ),
        StatusCode::UNSUPPORTED_MEDIA_TYPE,
        "request.content_type",
    )
    .await;
}

#[tokio::test]
async fn bodies_and_work_over_the_limits_are_413() {
    let small = service::app(ServeConfig {
        max_body_bytes: 1024,
        ..config()
    });
    let big = json!({ "geometry": circle(), "params": vec![[0.5]; 400] });
    assert!(big.to_string().len() > 1024);
    expect_error(
        small.clone(),
        post_json("/v1/evaluate", &big),
        StatusCode::PAYLOAD_TOO_LARGE,
        "limit.body_bytes",
    )
    .await;
    expect_error(
        small,
        post_raw("/v1/validate", None, vec![b'x'; 4096]),
        StatusCode::PAYLOAD_TOO_LARGE,
        "limit.body_bytes",
    )
    .await;
    // A pipeline limit: evaluation points.
    let mut cfg = config();
    cfg.settings.max_eval_points = 10;
    expect_error(
        service::app(cfg),
        post_json(
            "/v1/evaluate",
            &json!({ "geometry": circle(), "params": vec![[0.5]; 11] }),
        ),
        StatusCode::PAYLOAD_TOO_LARGE,
        "limit.eval_points",
    )
    .await;
}

#[tokio::test]
async fn no_computing_slot_is_503_and_not_ready() {
    let closed = service::app(ServeConfig {
        max_concurrency: 0,
        ..config()
    });
    let (status, headers, body) = send(
        closed.clone(),
        post_json(
            "/v1/evaluate",
            &json!({ "geometry": circle(), "params": [[0]] }),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE);
    assert_eq!(headers[header::RETRY_AFTER], "1"); // nothing measured yet
    assert_eq!(json_of(&body)["error"]["code"], "overloaded");
    let (status, _, body) = send(closed.clone(), get("/readyz")).await;
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE);
    assert_eq!(json_of(&body)["status"], "saturated");
    // Liveness does not depend on capacity.
    assert_eq!(send(closed, get("/healthz")).await.0, StatusCode::OK);
}

#[tokio::test]
async fn a_full_queue_refuses_and_a_busy_slot_times_out_the_wait() {
    use nurbsx::service::gate::{Gate, QUEUE_FACTOR, QUEUE_WAIT};
    use std::sync::Arc;
    let gate = Arc::new(Gate::new(1));
    // Admission: 1 computing + QUEUE_FACTOR waiting, then refused.
    let held: Vec<_> = (0..=QUEUE_FACTOR).map(|_| gate.admit(0).unwrap()).collect();
    let refused = gate.admit(0).unwrap_err();
    assert_eq!(refused.status, StatusCode::SERVICE_UNAVAILABLE);
    assert!(!gate.ready());
    drop(held);
    assert!(gate.ready());
    let closing = Gate::new(1);
    closing.begin_shutdown();
    assert!(!closing.ready() && closing.shutting_down());
    // A slot held by blocked work: the next request waits QUEUE_WAIT, then 503.
    let (release, wait) = std::sync::mpsc::channel::<()>();
    let g = gate.clone();
    let first = tokio::spawn(async move {
        g.run(move |_| {
            let _ = wait.recv();
            Ok(1)
        })
        .await
    });
    while gate.busy() == 0 {
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
    let start = std::time::Instant::now();
    let second = gate.run(|_| Ok(2)).await.unwrap_err();
    assert!(start.elapsed() >= QUEUE_WAIT);
    assert_eq!(second.status, StatusCode::SERVICE_UNAVAILABLE);
    assert_eq!(second.code, "overloaded");
    release.send(()).unwrap();
    assert_eq!(first.await.unwrap().unwrap(), 1);
    // The slot is free again.
    assert_eq!(gate.run(|_| Ok(3)).await.unwrap(), 3);
}

#[tokio::test]
async fn a_panic_in_work_is_a_generic_500() {
    let gate = nurbsx::service::gate::Gate::new(1);
    let e = gate
        .run(|_| -> Result<(), _> { panic!("secret detail") })
        .await
        .unwrap_err();
    assert_eq!(e.status, StatusCode::INTERNAL_SERVER_ERROR);
    assert_eq!(e.code, "internal");
    assert!(!e.message.contains("secret"));
    // The slot came back.
    assert_eq!(gate.run(|_| Ok(5)).await.unwrap(), 5);
}

/// A request body that never delivers a byte.
struct Stalled;

impl HttpBody for Stalled {
    type Data = Bytes;
    type Error = std::io::Error;
    fn poll_frame(
        self: Pin<&mut Self>,
        _cx: &mut Context<'_>,
    ) -> Poll<Option<Result<http_body::Frame<Bytes>, std::io::Error>>> {
        Poll::Pending
    }
}

#[tokio::test]
async fn a_request_over_the_time_limit_is_503_timeout() {
    let quick = service::app(ServeConfig {
        request_timeout: Duration::from_millis(100),
        ..config()
    });
    let req = Request::builder()
        .method(Method::POST)
        .uri("/v1/validate")
        .header(header::CONTENT_TYPE, "model/step")
        .body(Body::new(Stalled))
        .unwrap();
    expect_error(quick, req, StatusCode::SERVICE_UNAVAILABLE, "timeout").await;
}

#[tokio::test]
async fn unknown_routes_and_methods_are_json_errors() {
    expect_error(
        app(),
        get("/v2/nothing"),
        StatusCode::NOT_FOUND,
        "not_found",
    )
    .await;
    expect_error(
        app(),
        get("/v1/evaluate"),
        StatusCode::METHOD_NOT_ALLOWED,
        "method_not_allowed",
    )
    .await;
}

// ---------------------------------------------------------------------------------------
// /v1/info and /v1/validate on model JSON (works now)

#[tokio::test]
async fn info_describes_model_json() {
    let (status, _, bytes) = send(
        app(),
        post_raw(
            "/v1/info",
            Some("application/json"),
            json!([circle(), bilinear()]).to_string(),
        ),
    )
    .await;
    let v = json_of(&bytes);
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(v["format"], "json");
    let e = v["entities"].as_array().unwrap();
    assert_eq!(e.len(), 2);
    assert_eq!(e[0]["kind"], "curve");
    assert_eq!(e[0]["degree"], json!([2]));
    assert_eq!(e[0]["poles"], json!([9]));
    assert_eq!(e[0]["rational"], true);
    assert_eq!(e[0]["domain"], json!([[0.0, 1.0]]));
    assert_eq!(e[1]["kind"], "surface");
    assert_eq!(e[1]["poles"], json!([2, 2]));
    assert_eq!(e[1]["rational"], false);
    // The exact geometry comes back unchanged (poles and weights bit for bit).
    let got: Vec<f64> = serde_json::from_value(e[0]["geometry"]["weights"].clone()).unwrap();
    let sent: Vec<f64> = serde_json::from_value(circle()["weights"].clone()).unwrap();
    assert_eq!(got, sent);
    let doc = openapi().await;
    conforms(&v, &schema_ref("InfoReport"), &doc, "$").unwrap();
}

#[tokio::test]
async fn content_type_parameters_do_not_change_the_format() {
    for ct in [
        "application/json; charset=utf-8",
        "Application/JSON",
        "text/plain",
    ] {
        let (status, _, body) =
            send(app(), post_raw("/v1/info", Some(ct), circle().to_string())).await;
        assert_eq!(
            status,
            StatusCode::OK,
            "{ct}: {}",
            String::from_utf8_lossy(&body)
        );
        assert_eq!(json_of(&body)["format"], "json", "{ct}");
    }
}

#[tokio::test]
async fn validate_reports_instead_of_failing() {
    let (status, _, bytes) = send(
        app(),
        post_raw("/v1/validate?strict=true", None, circle().to_string()),
    )
    .await;
    let v = json_of(&bytes);
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(v["valid"], true);
    assert_eq!(v["entities"], 1);
    let doc = openapi().await;
    conforms(&v, &schema_ref("ValidationReport"), &doc, "$").unwrap();
    let (status, _, bytes) = send(app(), post_raw("/v1/validate", None, "garbage")).await;
    let v = json_of(&bytes);
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(v["valid"], false);
    assert_eq!(v["errors"], 1);
    assert_eq!(v["diagnostics"][0]["code"], "format.unknown");
    conforms(&v, &schema_ref("ValidationReport"), &doc, "$").unwrap();
}

// ---------------------------------------------------------------------------------------
// Operations endpoints

#[tokio::test]
async fn health_readiness_and_landing_page() {
    let (status, _, body) = send(app(), get("/healthz")).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(json_of(&body)["status"], "ok");
    let (status, _, body) = send(app(), get("/readyz")).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(json_of(&body)["status"], "ready");
    // The endpoint list is at /api; / is the web page when it was built into the binary
    // (checked against web/dist in tests/web_page.rs), else the same list.
    let pages: &[&str] = if service::assets::embedded() {
        &["/api"]
    } else {
        &["/api", "/"]
    };
    for page in pages {
        let (status, headers, body) = send(app(), get(page)).await;
        assert_eq!(status, StatusCode::OK);
        assert!(
            headers[header::CONTENT_TYPE]
                .to_str()
                .unwrap()
                .starts_with("text/html")
        );
        let html = String::from_utf8(body.to_vec()).unwrap();
        for path in ROUTES.iter().filter(|(_, p)| p.starts_with("/v1")) {
            assert!(html.contains(path.1), "{page} lacks {}", path.1);
        }
    }
}

/// Every route the router serves, with its method.
const ROUTES: [(&str, &str); 32] = [
    ("post", "/v1/convert"),
    ("post", "/v1/validate"),
    ("post", "/v1/info"),
    ("post", "/v1/evaluate"),
    ("post", "/v1/degree-elevate"),
    ("post", "/v1/clamp"),
    ("post", "/v1/unclamp"),
    ("post", "/v1/insert-knot"),
    ("post", "/v1/refine"),
    ("post", "/v1/reduce"),
    ("post", "/v1/remove-knots"),
    ("post", "/v1/decompose"),
    ("post", "/v1/split"),
    ("post", "/v1/join"),
    ("post", "/v1/reverse"),
    ("post", "/v1/reparameterize"),
    ("post", "/v1/transform"),
    ("post", "/v1/iso"),
    ("post", "/v1/periodic"),
    ("post", "/v1/derivative-curve"),
    ("post", "/v1/make"),
    ("post", "/v1/fit"),
    ("post", "/v1/measure"),
    ("post", "/v1/compare"),
    ("post", "/v1/tessellate"),
    ("get", "/healthz"),
    ("get", "/readyz"),
    ("get", "/metrics"),
    ("get", "/openapi.json"),
    ("get", "/limits"),
    ("get", "/api"),
    ("get", "/"),
];

#[tokio::test]
async fn openapi_documents_every_route_and_error() {
    let doc = openapi().await;
    assert!(doc["openapi"].as_str().unwrap().starts_with("3."));
    let paths = doc["paths"].as_object().unwrap();
    assert_eq!(paths.len(), ROUTES.len(), "{:?}", paths.keys());
    for (method, path) in ROUTES {
        let op = &doc["paths"][path][method];
        assert!(op.is_object(), "{method} {path} is not documented");
        // And the router really serves it (not 404/405).
        let req = Request::builder()
            .method(method.to_uppercase().as_str())
            .uri(path)
            .header(header::CONTENT_TYPE, "application/json")
            .body(Body::from("{}"))
            .unwrap();
        let (status, _, _) = send(app(), req).await;
        assert!(
            status != StatusCode::NOT_FOUND && status != StatusCode::METHOD_NOT_ALLOWED,
            "{method} {path}: {status}"
        );
        if path.starts_with("/v1") {
            assert!(op["requestBody"].is_object(), "{path} has no request body");
            for code in ["200", "400", "408", "413", "415", "422", "503"] {
                assert!(op["responses"][code].is_object(), "{path} lacks {code}");
            }
            let err = &op["responses"]["422"]["content"]["application/json"]["schema"];
            assert_eq!(err["$ref"], "#/components/schemas/ErrorBody", "{path}");
        }
    }
    for s in [
        "ErrorBody",
        "EvaluateRequest",
        "ElevateRequest",
        "InsertKnotRequest",
        "RefineRequest",
        "ReduceRequest",
        "RemoveKnotsRequest",
        "DecomposeRequest",
        "SplitRequest",
        "JoinRequest",
        "ReverseRequest",
        "ReparameterizeRequest",
        "TransformRequest",
        "IsoRequest",
        "PeriodicRequest",
        "DerivativeCurveRequest",
        "OpNote",
        "MakeRequest",
        "FitRequest",
        "TessellateRequest",
        "Geometry",
        "EvalReport",
        "InfoReport",
        "ValidationReport",
        "ConvertReport",
    ] {
        assert!(doc["components"]["schemas"][s].is_object(), "schema {s}");
    }
    // Error replies conform to the error schema.
    let (_, _, body) = send(app(), get("/nope")).await;
    conforms(&json_of(&body), &schema_ref("ErrorBody"), &doc, "$").unwrap();
}

#[tokio::test]
async fn metrics_count_requests_by_route_and_status() {
    let app = app();
    let ok = json!({ "geometry": circle(), "params": [[0.1]] });
    let bad = json!({ "geometry": circle(), "params": [[2.0]] });
    for body in [&ok, &ok, &bad] {
        send(app.clone(), post_json("/v1/evaluate", body)).await;
    }
    let (status, headers, body) = send(app.clone(), get("/metrics")).await;
    assert_eq!(status, StatusCode::OK);
    assert!(
        headers[header::CONTENT_TYPE]
            .to_str()
            .unwrap()
            .starts_with("text/plain; version=0.0.4")
    );
    let text = String::from_utf8(body.to_vec()).unwrap();
    let line = |prefix: &str| {
        text.lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no {prefix} in\n{text}"))
            .to_owned()
    };
    assert!(
        line("nurbsx_http_requests_total{route=\"/v1/evaluate\",method=\"POST\",status=\"200\"}")
            .ends_with(" 2")
    );
    assert!(
        line("nurbsx_http_requests_total{route=\"/v1/evaluate\",method=\"POST\",status=\"400\"}")
            .ends_with(" 1")
    );
    assert!(
        line("nurbsx_http_request_duration_seconds_count{route=\"/v1/evaluate\"}").ends_with(" 3")
    );
    assert!(
        line("nurbsx_http_request_duration_seconds_bucket{route=\"/v1/evaluate\",le=\"+Inf\"}")
            .ends_with(" 3")
    );
    // The scrape itself is in flight while it renders.
    assert_eq!(
        line("nurbsx_http_requests_in_flight "),
        "nurbsx_http_requests_in_flight 1"
    );
    assert_eq!(
        line("nurbsx_entities_converted_total "),
        "nurbsx_entities_converted_total 0"
    );
    // Every sample line is `name{labels} value` or `name value` with a numeric value.
    for l in text.lines().filter(|l| !l.starts_with('#')) {
        let value = l.rsplit(' ').next().unwrap();
        assert!(value.parse::<f64>().is_ok(), "bad sample line {l:?}");
    }
}

#[tokio::test]
async fn request_ids_are_echoed_or_generated() {
    let mut req = get("/healthz");
    req.headers_mut()
        .insert("x-request-id", "abc-123".parse().unwrap());
    let (_, headers, _) = send(app(), req).await;
    assert_eq!(headers["x-request-id"], "abc-123");
    let (_, h1, _) = send(app(), get("/healthz")).await;
    let (_, h2, _) = send(app(), get("/healthz")).await;
    let (a, b) = (&h1["x-request-id"], &h2["x-request-id"]);
    assert!(!a.is_empty() && !b.is_empty());
    // Different router instances restart the counter only if the process restarts; within
    // one router ids differ.
    let one = app();
    let (_, h3, _) = send(one.clone(), get("/healthz")).await;
    let (_, h4, _) = send(one, get("/healthz")).await;
    assert_ne!(h3["x-request-id"], h4["x-request-id"]);
}

// ---------------------------------------------------------------------------------------
// A real socket

/// A GET over a plain socket; the whole reply as text.
fn raw_get(addr: std::net::SocketAddr, path: &str) -> String {
    use std::io::{Read, Write};
    let mut stream = std::net::TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut reply = String::new();
    stream.read_to_string(&mut reply).unwrap();
    reply
}

#[tokio::test]
async fn serves_over_loopback_and_shuts_down_gracefully() {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let server = tokio::spawn(service::serve_on(listener, config(), async move {
        let _ = stopped.await;
    }));
    let body = json!({ "geometry": circle(), "params": [[0.125]] }).to_string();
    let head = format!(
        "POST /v1/evaluate HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\nX-Request-Id: loop-1\r\nConnection: close\r\n\r\n",
        body.len()
    );
    // A plain blocking socket, as any client would use, off the test's async threads. The
    // request is sent in two parts with the shutdown signal in between: a graceful
    // shutdown lets it finish.
    let (half_sent, wait_half) = std::sync::mpsc::channel::<()>();
    let (go_on, wait_go) = std::sync::mpsc::channel::<()>();
    let client = tokio::task::spawn_blocking(move || {
        use std::io::{Read, Write};
        let mut stream = std::net::TcpStream::connect(addr).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(10)))
            .unwrap();
        let (first, second) = body.split_at(body.len() / 2);
        stream.write_all(head.as_bytes()).unwrap();
        stream.write_all(first.as_bytes()).unwrap();
        stream.flush().unwrap();
        half_sent.send(()).unwrap();
        wait_go.recv().unwrap();
        stream.write_all(second.as_bytes()).unwrap();
        let mut reply = String::new();
        stream.read_to_string(&mut reply).unwrap();
        reply
    });
    tokio::task::spawn_blocking(move || wait_half.recv().unwrap())
        .await
        .unwrap();
    // Wait until the server is handling the request (the metrics scrape itself is one
    // request in flight, ours the other), then ask it to stop while the body is incomplete.
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    loop {
        let metrics = tokio::task::spawn_blocking(move || raw_get(addr, "/metrics"))
            .await
            .unwrap();
        if metrics.contains("\nnurbsx_http_requests_in_flight 2\n") {
            break;
        }
        assert!(std::time::Instant::now() < deadline, "{metrics}");
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    stop.send(()).unwrap();
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert!(
        !server.is_finished(),
        "the server waits for the request in flight"
    );
    go_on.send(()).unwrap();
    let reply = client.await.unwrap();
    assert!(reply.starts_with("HTTP/1.1 200 OK\r\n"), "{reply}");
    assert!(
        reply
            .to_ascii_lowercase()
            .contains("x-request-id: loop-1\r\n"),
        "{reply}"
    );
    let json_text = &reply[reply.find("\r\n\r\n").unwrap() + 4..];
    let v: Value = serde_json::from_str(json_text).unwrap();
    let p = &v["results"][0]["point"];
    let want = circle_bernstein(0.125);
    assert!((p[0].as_f64().unwrap() - want[0]).abs() < 1e-12, "{v}");
    assert!((p[1].as_f64().unwrap() - want[1]).abs() < 1e-12, "{v}");
    tokio::time::timeout(Duration::from_secs(10), server)
        .await
        .expect("graceful shutdown completes")
        .unwrap()
        .unwrap();
    assert!(
        tokio::net::TcpStream::connect(addr).await.is_err(),
        "listener closed"
    );
}

// ---------------------------------------------------------------------------------------
// Files and operations: enabled once the STEP/IGES layers and the operations are merged.

/// A hand-written STEP file with one parabolic arc: P(u) = (1-u)² P0 + 2u(1-u) P1 + u² P2.
const STEP_ARC: &str = "ISO-10303-21;
HEADER;
FILE_DESCRIPTION(('nurbsx http test'),'2;1');
FILE_NAME('arc.step','2024-01-01T00:00:00',(''),(''),'','','');
FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));
ENDSEC;
DATA;
#1=CARTESIAN_POINT('',(0.,0.,0.));
#2=CARTESIAN_POINT('',(1.,2.,0.));
#3=CARTESIAN_POINT('',(3.,2.,1.));
#4=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);
ENDSEC;
END-ISO-10303-21;
";

/// The arc of [`STEP_ARC`] by its Bernstein form.
fn arc_bernstein(u: f64) -> [f64; 3] {
    // P0 is the origin, so its Bernstein term adds nothing.
    let (b1, b2) = (2.0 * u * (1.0 - u), u * u);
    [b1 + 3.0 * b2, 2.0 * b1 + 2.0 * b2, b2]
}

fn close(a: &Value, want: &[f64], tol: f64) -> bool {
    let a: Vec<f64> = serde_json::from_value(a.clone()).unwrap();
    a.len() == want.len() && a.iter().zip(want).all(|(x, y)| (x - y).abs() <= tol)
}

/// POSTs and expects 200; returns headers and body.
async fn ok(app: Router, req: Request<Body>) -> (HeaderMap, Bytes) {
    let (status, headers, body) = send(app, req).await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    (headers, body)
}

#[tokio::test]
async fn info_validate_and_evaluate_read_a_step_file() {
    let (_, body) = ok(app(), post_raw("/v1/info", Some("model/step"), STEP_ARC)).await;
    let v = json_of(&body);
    assert_eq!(v["format"], "step");
    assert_eq!(v["entities"][0]["id"], "#4");
    assert_eq!(v["entities"][0]["degree"], json!([2]));
    let (_, body) = ok(app(), post_raw("/v1/validate", None, STEP_ARC)).await;
    let v = json_of(&body);
    assert_eq!(v["valid"], true, "{v}");
    assert_eq!(v["entities"], 1);
    let params = [0.0, 0.3, 0.5, 1.0];
    let req = json!({
        "file": STEP_ARC, "format": "step", "entity": "#4",
        "params": params.iter().map(|u| [u]).collect::<Vec<_>>()
    });
    let (_, body) = ok(app(), post_json("/v1/evaluate", &req)).await;
    let v = json_of(&body);
    assert_eq!(v["entity"], "#4");
    for (r, u) in v["results"].as_array().unwrap().iter().zip(params) {
        assert!(close(&r["point"], &arc_bernstein(u), 1e-14), "{r}");
    }
}

#[tokio::test]
async fn convert_json_to_step_to_iges_keeps_the_geometry_exactly() {
    let app = app();
    let (headers, step) = ok(
        app.clone(),
        post_raw(
            "/v1/convert?to=step&schema=ap242",
            Some("application/json"),
            circle().to_string(),
        ),
    )
    .await;
    assert_eq!(headers[header::CONTENT_TYPE], "model/step");
    assert_eq!(headers["x-nurbsx-entities"], "1");
    assert!(headers.contains_key("x-nurbsx-diagnostics"));
    assert!(step.starts_with(b"ISO-10303-21;"));
    // STEP -> IGES with verification, JSON reply.
    let mut req = post_raw("/v1/convert?to=iges&verify=true", Some("model/step"), step);
    req.headers_mut()
        .insert(header::ACCEPT, "application/json".parse().unwrap());
    let (headers, body) = ok(app.clone(), req).await;
    assert_eq!(headers[header::CONTENT_TYPE], "application/json");
    let v = json_of(&body);
    conforms(&v, &schema_ref("ConvertJsonReply"), &openapi().await, "$").unwrap();
    assert_eq!(v["report"]["input_format"], "step");
    assert_eq!(v["report"]["output_format"], "iges");
    assert_eq!(v["report"]["entities_out"], 1);
    assert!(
        v["report"]["verify"]
            .as_array()
            .unwrap()
            .iter()
            .all(|d| d["ok"] == true)
    );
    let iges = v["file"].as_str().unwrap().to_owned();
    // The IGES text describes the same circle, bit for bit.
    let (_, body) = ok(app.clone(), post_raw("/v1/info", None, iges)).await;
    let info = json_of(&body);
    assert_eq!(info["format"], "iges");
    let g = &info["entities"][0]["geometry"];
    for key in ["knots", "weights", "control_points"] {
        let got: Value = g[key].clone();
        let want: Value = circle()[key].clone();
        let f = |v: &Value| -> Vec<f64> {
            let mut out = Vec::new();
            let mut stack = vec![v.clone()];
            while let Some(x) = stack.pop() {
                match x {
                    Value::Array(a) => stack.extend(a.into_iter().rev()),
                    n => out.push(n.as_f64().unwrap()),
                }
            }
            out
        };
        assert_eq!(f(&got), f(&want), "{key}");
    }
    // Metrics counted the converted entities (one per conversion).
    let (_, body) = ok(app, get("/metrics")).await;
    let text = String::from_utf8(body.to_vec()).unwrap();
    assert!(
        text.contains("nurbsx_entities_converted_total 2\n"),
        "{text}"
    );
}

#[tokio::test]
async fn convert_to_inches_scales_the_poles() {
    let (_, iges) = ok(
        app(),
        post_raw("/v1/convert?to=iges&units=in", Some("model/step"), STEP_ARC),
    )
    .await;
    let (_, body) = ok(app(), post_raw("/v1/info", Some("model/iges"), iges)).await;
    let v = json_of(&body);
    assert_eq!(v["units"]["name"], "in");
    let p = &v["entities"][0]["geometry"]["control_points"][1];
    assert!(close(p, &[1.0 / 25.4, 2.0 / 25.4, 0.0], 1e-15), "{p}");
}

#[tokio::test]
async fn degree_elevation_keeps_the_shape_for_json_and_files() {
    let (_, body) = ok(
        app(),
        post_json(
            "/v1/degree-elevate",
            &json!({ "geometry": circle(), "by": 1 }),
        ),
    )
    .await;
    let v = json_of(&body);
    assert_eq!(v["geometry"]["degree"], 3);
    let params: Vec<f64> = (0..=32).map(|i| f64::from(i) / 32.0).collect();
    let req = json!({
        "geometry": v["geometry"],
        "params": params.iter().map(|u| [u]).collect::<Vec<_>>()
    });
    let (_, body) = ok(app(), post_json("/v1/evaluate", &req)).await;
    for (r, &u) in json_of(&body)["results"]
        .as_array()
        .unwrap()
        .iter()
        .zip(&params)
    {
        let want = circle_bernstein(u);
        assert!(
            close(&r["point"], &[want[0], want[1], 0.0], 1e-12),
            "u={u}: {r}"
        );
    }
    // A file in gives a file in the same format out.
    let (headers, step) = ok(
        app(),
        post_json(
            "/v1/degree-elevate",
            &json!({ "file": STEP_ARC, "by": 2, "entity": "#4" }),
        ),
    )
    .await;
    assert_eq!(headers[header::CONTENT_TYPE], "model/step");
    let (_, body) = ok(app(), post_raw("/v1/info", Some("model/step"), step)).await;
    assert_eq!(json_of(&body)["entities"][0]["degree"], json!([4]));
    // Too much elevation is a limit (the pipeline's Settings::max_elevate_by).
    let (status, _, body) = send(
        app(),
        post_json(
            "/v1/degree-elevate",
            &json!({ "geometry": circle(), "by": 1000 }),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::PAYLOAD_TOO_LARGE);
    let code = json_of(&body)["error"]["code"].clone();
    assert!(code.as_str().unwrap().starts_with("limit"), "{code}");
}

#[tokio::test]
async fn unclamp_then_clamp_keeps_the_shape() {
    let (_, body) = ok(
        app(),
        post_json("/v1/unclamp", &json!({ "geometry": circle() })),
    )
    .await;
    let unclamped = json_of(&body)["geometry"].clone();
    let knots: Vec<f64> = serde_json::from_value(unclamped["knots"].clone()).unwrap();
    assert!(knots[0] < knots[2], "unclamped: {knots:?}");
    let (_, body) = ok(
        app(),
        post_json(
            "/v1/clamp",
            &json!({ "geometry": unclamped, "direction": "both" }),
        ),
    )
    .await;
    let clamped = json_of(&body)["geometry"].clone();
    let knots: Vec<f64> = serde_json::from_value(clamped["knots"].clone()).unwrap();
    assert!(knots[0] == knots[2], "clamped: {knots:?}");
    for g in [&unclamped, &clamped] {
        let req = json!({ "geometry": g, "params": [[0.1], [0.6], [0.95]] });
        let (_, body) = ok(app(), post_json("/v1/evaluate", &req)).await;
        for (r, u) in json_of(&body)["results"]
            .as_array()
            .unwrap()
            .iter()
            .zip([0.1, 0.6, 0.95])
        {
            let want = circle_bernstein(u);
            assert!(close(&r["point"], &[want[0], want[1], 0.0], 1e-12), "{r}");
        }
    }
}

#[tokio::test]
async fn tessellation_stays_within_the_chord_tolerance() {
    let tol = 1e-3;
    let (headers, body) = ok(
        app(),
        post_json(
            "/v1/tessellate",
            &json!({ "geometry": circle(), "tolerance": tol, "format": "obj" }),
        ),
    )
    .await;
    assert!(
        headers[header::CONTENT_TYPE]
            .to_str()
            .unwrap()
            .starts_with("text/plain")
    );
    let text = String::from_utf8(body.to_vec()).unwrap();
    let v: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    assert!(v.len() >= 8, "{text}");
    for w in v.windows(2) {
        // Vertices on the circle; chord midpoints within the tolerance of it.
        assert!((w[0][0].hypot(w[0][1]) - 1.0).abs() < 1e-12);
        let mid = [(w[0][0] + w[1][0]) / 2.0, (w[0][1] + w[1][1]) / 2.0];
        assert!(1.0 - mid[0].hypot(mid[1]) <= tol * (1.0 + 1e-9), "{w:?}");
    }
    let (headers, body) = ok(
        app(),
        post_json(
            "/v1/tessellate",
            &json!({ "geometry": circle(), "tolerance": tol, "format": "svg" }),
        ),
    )
    .await;
    assert_eq!(headers[header::CONTENT_TYPE], "image/svg+xml");
    assert!(String::from_utf8_lossy(&body).contains("<svg"));
}

#[tokio::test]
async fn first_derivatives_match_central_differences() {
    let params = [0.1, 0.4, 0.7];
    let req = json!({
        "geometry": circle(), "derivatives": 1,
        "params": params.iter().map(|u| [u]).collect::<Vec<_>>()
    });
    let (_, body) = ok(app(), post_json("/v1/evaluate", &req)).await;
    let v = json_of(&body);
    let h = 1e-6;
    for (r, u) in v["results"].as_array().unwrap().iter().zip(params) {
        let (a, b) = (circle_bernstein(u + h), circle_bernstein(u - h));
        let fd = [(a[0] - b[0]) / (2.0 * h), (a[1] - b[1]) / (2.0 * h), 0.0];
        let d1 = &r["derivatives"][0];
        assert!(
            close(d1, &fd, 1e-6 * (1.0 + fd[0].hypot(fd[1]))),
            "{d1} vs {fd:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// The geometric operations: each reply is checked against the schema and its geometry,
// evaluated here (A2.2 on the returned knots and poles), against the circle's Bernstein
// form at the parameter the operation maps to, or against hand-computed values.

/// POSTs an operation on model JSON; checks 200 and the `GeometryReply` schema.
async fn operation(path: &str, body: &Value) -> Value {
    let (_, bytes) = ok(app(), post_json(path, body)).await;
    let v = json_of(&bytes);
    let doc = openapi().await;
    conforms(&v, &schema_ref("GeometryReply"), &doc, "$").unwrap_or_else(|e| panic!("{path}: {e}"));
    v
}

fn curve_of(v: &Value) -> nurbsx::nurbs::NurbsCurve {
    serde_json::from_value(v.clone()).unwrap_or_else(|e| panic!("not a curve ({e}): {v}"))
}

/// Asserts `got(s)` equals the circle at `map(s)` for 33 parameters of `got`'s domain.
fn same_as_circle(got: &nurbsx::nurbs::NurbsCurve, map: impl Fn(f64) -> f64, tol: f64, what: &str) {
    let (a, b) = got.domain();
    for i in 0..=32 {
        let s = a + (b - a) * f64::from(i) / 32.0;
        let p = got.point_at(s).unwrap();
        let want = circle_bernstein(map(s));
        assert!(
            (p[0] - want[0]).abs() <= tol && (p[1] - want[1]).abs() <= tol && p[2].abs() <= tol,
            "{what}: s = {s}: {p:?} vs {want:?}"
        );
    }
}

#[tokio::test]
async fn shape_preserving_operations_keep_the_circle() {
    let v = operation(
        "/v1/insert-knot",
        &json!({ "geometry": circle(), "at": 0.3, "times": 2 }),
    )
    .await;
    let c = curve_of(&v["geometry"]);
    assert_eq!(c.num_poles(), 11);
    same_as_circle(&c, |s| s, 1e-12, "insert-knot");

    let v = operation(
        "/v1/refine",
        &json!({ "geometry": circle(), "knots": [0.6, 0.1, 0.6] }),
    )
    .await;
    let refined = curve_of(&v["geometry"]);
    assert_eq!(refined.num_poles(), 12);
    same_as_circle(&refined, |s| s, 1e-12, "refine");

    // Interval halving (seed 003): the circle given in knot-interval form (its knots
    // [0,0,0,.25,.25,.5,.5,.75,.75,1,1,1]); each quarter gets its midpoint.
    let mut given = circle();
    let map = given.as_object_mut().unwrap();
    map.remove("knots");
    map.insert(
        "knot_intervals".into(),
        json!([0, 0.25, 0, 0.25, 0, 0.25, 0, 0.25, 0]),
    );
    let h = operation("/v1/refine", &json!({ "geometry": given, "halve": true })).await;
    let halved = curve_of(&h["geometry"]);
    assert_eq!(
        halved.knots(),
        [
            0.0, 0.0, 0.0, 0.125, 0.25, 0.25, 0.375, 0.5, 0.5, 0.625, 0.75, 0.75, 0.875, 1.0, 1.0,
            1.0
        ]
    );
    same_as_circle(&halved, |s| s, 1e-12, "refine halve");
    let (status, _, bytes) = send(
        app(),
        post_json(
            "/v1/refine",
            &json!({ "geometry": circle(), "halve": true, "knots": [0.5] }),
        ),
    )
    .await;
    assert_eq!(
        status,
        StatusCode::BAD_REQUEST,
        "{}",
        String::from_utf8_lossy(&bytes)
    );

    // Knot removal takes the refined circle back to its 9 poles (the removed knots were
    // inserted, so they go within rounding).
    let v = operation(
        "/v1/remove-knots",
        &json!({ "geometry": v["geometry"], "tolerance": 1e-9 }),
    )
    .await;
    let lean = curve_of(&v["geometry"]);
    assert_eq!(lean.num_poles(), 9, "{v}");
    same_as_circle(&lean, |s| s, 1e-9, "remove-knots");
    assert!(
        v["notes"][0]["message"]
            .as_str()
            .unwrap()
            .contains("removed 3"),
        "{v}"
    );

    let v = operation("/v1/reverse", &json!({ "geometry": circle() })).await;
    same_as_circle(&curve_of(&v["geometry"]), |s| 1.0 - s, 1e-12, "reverse");

    let v = operation(
        "/v1/reparameterize",
        &json!({ "geometry": circle(), "to": [2.0, 6.0] }),
    )
    .await;
    let c = curve_of(&v["geometry"]);
    assert_eq!(c.domain(), (2.0, 6.0));
    same_as_circle(&c, |s| (s - 2.0) / 4.0, 1e-12, "reparameterize");

    // Bezier decomposition: 4 quarter arcs, piece k on [k/4, (k+1)/4].
    let v = operation("/v1/decompose", &json!({ "geometry": circle() })).await;
    let pieces = v["geometry"].as_array().unwrap();
    assert_eq!(pieces.len(), 4);
    for (k, piece) in pieces.iter().enumerate() {
        let c = curve_of(piece);
        assert_eq!(c.num_poles(), 3);
        assert_eq!(c.domain(), (k as f64 / 4.0, (k + 1) as f64 / 4.0));
        same_as_circle(&c, |s| s, 1e-12, "decompose");
    }

    // Split at 0.3, then join the pieces back.
    let v = operation("/v1/split", &json!({ "geometry": circle(), "at": 0.3 })).await;
    let halves = v["geometry"].as_array().unwrap().clone();
    assert_eq!(halves.len(), 2);
    assert_eq!(curve_of(&halves[0]).domain(), (0.0, 0.3));
    assert_eq!(curve_of(&halves[1]).domain(), (0.3, 1.0));
    for h in &halves {
        same_as_circle(&curve_of(h), |s| s, 1e-12, "split");
    }
    let v = operation("/v1/join", &json!({ "geometry": halves })).await;
    let joined = &v["geometry"].as_array().unwrap()[0];
    same_as_circle(&curve_of(joined), |s| s, 1e-12, "join");
    assert!(
        v["notes"][0]["message"]
            .as_str()
            .unwrap()
            .contains("joined 2 curves"),
        "{v}"
    );
}

#[tokio::test]
async fn reduction_reports_its_bound_for_json_and_files() {
    let v = operation(
        "/v1/degree-elevate",
        &json!({ "geometry": circle(), "by": 1 }),
    )
    .await;
    let v = operation(
        "/v1/reduce",
        &json!({ "geometry": v["geometry"], "tolerance": 1e-9 }),
    )
    .await;
    let c = curve_of(&v["geometry"]);
    assert_eq!(c.degree(), 2);
    same_as_circle(&c, |s| s, 1e-12, "reduce");
    let bound = v["notes"][0]["error_bound"].as_f64().unwrap();
    assert!((0.0..=1e-9).contains(&bound), "{v}");
    // The bound is refused above the tolerance: the circle itself is not a parabola.
    expect_error(
        app(),
        post_json(
            "/v1/reduce",
            &json!({ "geometry": circle(), "tolerance": 1e-6 }),
        ),
        StatusCode::UNPROCESSABLE_ENTITY,
        "geometry",
    )
    .await;
    // A file: elevated, then reduced; the bound comes in a header.
    let (_, step) = ok(
        app(),
        post_json("/v1/degree-elevate", &json!({ "file": STEP_ARC, "by": 1 })),
    )
    .await;
    let (headers, step) = ok(
        app(),
        post_json(
            "/v1/reduce",
            &json!({ "file": String::from_utf8(step.to_vec()).unwrap(), "tolerance": 1e-9 }),
        ),
    )
    .await;
    assert_eq!(headers[header::CONTENT_TYPE], "model/step");
    let bound: f64 = headers["x-nurbsx-error-bound"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!((0.0..=1e-9).contains(&bound));
    let (_, body) = ok(app(), post_raw("/v1/info", Some("model/step"), step)).await;
    assert_eq!(json_of(&body)["entities"][0]["degree"], json!([2]));
}

#[tokio::test]
async fn transform_iso_periodic_and_derivative_curves() {
    // Rotation by 90 degrees about z, then translation: (x, y, z) -> (-y + 1, x + 2, z + 3).
    let v = operation(
        "/v1/transform",
        &json!({ "geometry": circle(), "rotate": { "axis": [0, 0, 2], "degrees": 90 },
                 "translate": [1, 2, 3] }),
    )
    .await;
    let c = curve_of(&v["geometry"]);
    for i in 0..=16 {
        let u = f64::from(i) / 16.0;
        let p = c.point_at(u).unwrap();
        let q = circle_bernstein(u);
        let want = [1.0 - q[1], 2.0 + q[0], 3.0];
        assert!(
            (0..3).all(|k| (p[k] - want[k]).abs() < 1e-12),
            "{p:?} vs {want:?}"
        );
    }
    let m = operation(
        "/v1/transform",
        &json!({ "geometry": circle(), "matrix": [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3]] }),
    )
    .await;
    let cm = curve_of(&m["geometry"]);
    for i in 0..=16 {
        let u = f64::from(i) / 16.0;
        let (p, q) = (c.point_at(u).unwrap(), cm.point_at(u).unwrap());
        assert!((0..3).all(|k| (p[k] - q[k]).abs() < 1e-12));
    }
    expect_error(
        app(),
        post_json("/v1/transform", &json!({ "geometry": circle() })),
        StatusCode::BAD_REQUEST,
        "transform.arguments",
    )
    .await;

    // The iso-curve u = 1/4 of S(u, v) = (2u, 3v, 1 + u v) is v -> (1/2, 3v, 1 + v/4).
    let v = operation("/v1/iso", &json!({ "geometry": bilinear(), "u": 0.25 })).await;
    let iso = curve_of(&v["geometry"]);
    for i in 0..=8 {
        let t = f64::from(i) / 8.0;
        let p = iso.point_at(t).unwrap();
        let want = [0.5, 3.0 * t, 1.0 + t / 4.0];
        assert!(
            (0..3).all(|k| (p[k] - want[k]).abs() < 1e-14),
            "{p:?} vs {want:?}"
        );
    }

    // Seed 000 section 2-19: the quadratic on {0,0,0,1/2,1,1,1} has the derivative curve of
    // degree 1 on {0,0,1/2,1,1} with Q = 4 (P1 - P0), 2 (P2 - P1), 4 (P3 - P2).
    let quad = json!({ "degree": 2, "knots": [0, 0, 0, 0.5, 1, 1, 1],
                       "control_points": [[0, 0, 0], [1, 2, 0], [3, 2, 0], [4, 0, 0]] });
    let v = operation("/v1/derivative-curve", &json!({ "geometry": quad })).await;
    assert_eq!(v["geometry"]["degree"], 1);
    assert!(close(
        &v["geometry"]["knots"],
        &[0.0, 0.0, 0.5, 1.0, 1.0],
        0.0
    ));
    let q: Vec<Vec<f64>> = serde_json::from_value(v["geometry"]["control_points"].clone()).unwrap();
    assert_eq!(
        q,
        vec![
            vec![4.0, 8.0, 0.0],
            vec![4.0, 0.0, 0.0],
            vec![4.0, -8.0, 0.0]
        ]
    );
    expect_error(
        app(),
        post_json("/v1/derivative-curve", &json!({ "geometry": circle() })),
        StatusCode::UNPROCESSABLE_ENTITY,
        "geometry",
    )
    .await;

    // A uniform periodic cubic (poles wrapped: P7..P9 = P0..P2), clamped, comes back to
    // a periodic form with the same points.
    let ring: Vec<[f64; 3]> = (0..7)
        .map(|i| {
            let a = f64::from(i) * std::f64::consts::TAU / 7.0;
            [a.cos() * (2.0 + f64::from(i % 2)), a.sin(), 0.0]
        })
        .collect();
    let mut poles = ring.clone();
    poles.extend_from_slice(&ring[..3]);
    let knots: Vec<f64> = (0..14).map(f64::from).collect();
    let periodic = json!({ "degree": 3, "knots": knots, "control_points": poles });
    let original = curve_of(&periodic);
    let v = operation("/v1/clamp", &json!({ "geometry": periodic })).await;
    let v = operation(
        "/v1/periodic",
        &json!({ "geometry": v["geometry"], "tolerance": 1e-9 }),
    )
    .await;
    let back = curve_of(&v["geometry"]);
    let k = back.knots();
    assert!(
        k[0] < k[1] && k[k.len() - 2] < k[k.len() - 1],
        "unclamped: {k:?}"
    );
    assert_eq!(back.domain(), original.domain());
    for i in 0..=40 {
        let u = 3.0 + 7.0 * f64::from(i) / 40.0;
        let (p, q) = (back.point_at(u).unwrap(), original.point_at(u).unwrap());
        assert!(
            (0..3).all(|k| (p[k] - q[k]).abs() < 1e-12),
            "u = {u}: {p:?} vs {q:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// /v1/make: exact constructions, checked against the analytic shapes

fn surface_of(v: &Value) -> nurbsx::nurbs::NurbsSurface {
    serde_json::from_value(v.clone()).unwrap_or_else(|e| panic!("not a surface ({e}): {v}"))
}

#[tokio::test]
async fn make_builds_circles_arcs_and_quadrics_on_their_analytic_shapes() {
    // Seed 000 section 2-23: the full circle is four 90-degree arcs, nine poles, knots
    // {0,0,0,1/4,1/4,...} (here in angle: multiples of pi/2), weights 1, sqrt(2)/2, ...
    let v = operation(
        "/v1/make",
        &json!({ "shape": "circle", "centre": [1, 2, 3], "radius": 2 }),
    )
    .await;
    let c = curve_of(&v["geometry"]);
    assert_eq!(c.num_poles(), 9);
    let w = c.weights().unwrap();
    for (i, wi) in w.iter().enumerate() {
        let want = if i % 2 == 0 { 1.0 } else { W };
        assert!((wi - want).abs() <= 1e-16, "w{i} = {wi}");
    }
    let (a, b) = c.domain();
    for i in 0..=400 {
        let p = c.point_at(a + (b - a) * f64::from(i) / 400.0).unwrap();
        let r = (p[0] - 1.0).hypot(p[1] - 2.0);
        assert!((r - 2.0).abs() <= 2.0 * 1e-15, "radius {r}");
        assert!((p[2] - 3.0).abs() <= 3.0 * 1e-15, "z {}", p[2]);
    }

    // Seed 000 section 2-23: the 240-degree arc of the unit circle from 150 degrees (through
    // 270) to 30 degrees is, in the seed, U = {0,0,0,1/2,1,1,1}, w = {1,1/4,1/4,1},
    // Q = {(a,1/2),(2a,-1),(-2a,-1),(-a,1/2)}, a = cos 30 (run from 30 degrees backwards).
    // make builds the same point set with the fewest segments of A7.1 (3 x 80 degrees).
    let a3 = 3f64.sqrt() / 2.0;
    let seed = nurbsx::nurbs::NurbsCurve::new(
        2,
        vec![0., 0., 0., 0.5, 1., 1., 1.],
        vec![
            [a3, 0.5, 0.],
            [2. * a3, -1., 0.],
            [-2. * a3, -1., 0.],
            [-a3, 0.5, 0.],
        ],
        Some(vec![1., 0.25, 0.25, 1.]),
    )
    .unwrap();
    let v = operation(
        "/v1/make",
        &json!({ "shape": "arc", "radius": 1, "start": 150, "end": 390 }),
    )
    .await;
    let arc = curve_of(&v["geometry"]);
    assert_eq!(arc.num_poles(), 7);
    let (a, b) = arc.domain();
    let (s0, s1) = (seed.point_at(0.0).unwrap(), seed.point_at(1.0).unwrap());
    let (m0, m1) = (arc.point_at(a).unwrap(), arc.point_at(b).unwrap());
    for k in 0..3 {
        assert!((m0[k] - s1[k]).abs() < 1e-15 && (m1[k] - s0[k]).abs() < 1e-15);
    }
    let in_arc = |p: [f64; 3]| {
        let deg = p[1].atan2(p[0]).to_degrees().rem_euclid(360.0);
        (p[0].hypot(p[1]) - 1.0).abs() <= 1e-15 && (deg >= 150.0 - 1e-9 || deg <= 30.0 + 1e-9)
    };
    for i in 0..=200 {
        let t = f64::from(i) / 200.0;
        assert!(in_arc(seed.point_at(t).unwrap()), "seed t = {t}");
        assert!(
            in_arc(arc.point_at((a + (b - a) * t).min(b)).unwrap()),
            "make t = {t}"
        );
    }

    // A cylinder of radius 5 and height 20 about the x axis, and a sphere of radius 3.
    let v = operation(
        "/v1/make",
        &json!({ "shape": "cylinder", "axis": [1, 0, 0], "radius": 5, "height": 20 }),
    )
    .await;
    let s = surface_of(&v["geometry"]);
    let ((u0, u1), (v0, v1)) = s.domain();
    for i in 0..=20 {
        for j in 0..=4 {
            let (u, w) = (
                u0 + (u1 - u0) * f64::from(i) / 20.0,
                v0 + (v1 - v0) * f64::from(j) / 4.0,
            );
            let p = s.point_at(u, w).unwrap();
            assert!((p[1].hypot(p[2]) - 5.0).abs() < 1e-14, "{p:?}");
            assert!(p[0] > -1e-12 && p[0] < 20.0 + 1e-12);
        }
    }
    let v = operation("/v1/make", &json!({ "shape": "sphere", "radius": 3 })).await;
    let s = surface_of(&v["geometry"]);
    let ((u0, u1), (v0, v1)) = s.domain();
    for i in 0..=12 {
        for j in 0..=12 {
            let p = s
                .point_at(
                    u0 + (u1 - u0) * f64::from(i) / 12.0,
                    v0 + (v1 - v0) * f64::from(j) / 12.0,
                )
                .unwrap();
            let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            assert!((r - 3.0).abs() < 1e-14, "{p:?}");
        }
    }
    // As a STEP file; missing numbers are a 400.
    let (headers, _) = ok(
        app(),
        post_json(
            "/v1/make",
            &json!({ "shape": "torus", "major": 5, "minor": 1, "format": "step" }),
        ),
    )
    .await;
    assert_eq!(headers[header::CONTENT_TYPE], "model/step");
    expect_error(
        app(),
        post_json("/v1/make", &json!({ "shape": "circle" })),
        StatusCode::BAD_REQUEST,
        "make.arguments",
    )
    .await;
    expect_error(
        app(),
        post_json(
            "/v1/make",
            &json!({ "shape": "torus", "major": 1, "minor": 2 }),
        ),
        StatusCode::BAD_REQUEST,
        "make.arguments",
    )
    .await;
    // The Coons patch of the four edges of S(u, v) = (2u, 3v, 1 + u v) is that patch.
    let line = |a: [f64; 3], b: [f64; 3]| json!({ "degree": 1, "knots": [0, 0, 1, 1], "control_points": [a, b] });
    let v = operation(
        "/v1/make",
        &json!({ "shape": "coons", "curves": [
            line([0., 0., 1.], [2., 0., 1.]),
            line([0., 3., 1.], [2., 3., 2.]),
            line([0., 0., 1.], [0., 3., 1.]),
            line([2., 0., 1.], [2., 3., 2.]),
        ] }),
    )
    .await;
    let s = surface_of(&v["geometry"]);
    for i in 0..=8 {
        for j in 0..=8 {
            let (u, w) = (f64::from(i) / 8.0, f64::from(j) / 8.0);
            let p = s.point_at(u, w).unwrap();
            let want = [2.0 * u, 3.0 * w, 1.0 + u * w];
            assert!(
                (0..3).all(|k| (p[k] - want[k]).abs() < 1e-14),
                "{p:?} vs {want:?}"
            );
        }
    }
    // The entity names its shape.
    let doc = nurbsx::pipeline::construct::make(&nurbsx::pipeline::construct::MakeShape::Line {
        from: [0.0; 3],
        to: [1.0, 2.0, 3.0],
    })
    .unwrap();
    assert_eq!(
        doc.entities[0].meta.shape,
        Some(nurbsx::exchange::Shape::Line)
    );
}

#[tokio::test]
async fn fit_interpolates_the_points_of_example_9_1() {
    // NURBS Book example 9.1: chord-length parameters 0, 5/17, 9/17, 14/17, 1 and the
    // cubic knots {0,0,0,0,28/51,1,1,1,1}; the curve passes through every point.
    let q = [
        [0.0, 0.0],
        [3.0, 4.0],
        [-1.0, 4.0],
        [-4.0, 0.0],
        [-4.0, -3.0],
    ];
    let v = fit_reply(&json!({ "points": q, "degree": 3 })).await;
    let c = curve_of(&v["geometry"]);
    assert_eq!(c.dimension(), 2);
    let want = [0., 0., 0., 0., 28.0 / 51.0, 1., 1., 1., 1.];
    assert!(
        c.knots()
            .iter()
            .zip(want)
            .all(|(a, b)| (a - b).abs() < 1e-15)
    );
    for (t, p) in [0.0, 5.0 / 17.0, 9.0 / 17.0, 14.0 / 17.0, 1.0]
        .iter()
        .zip(q)
    {
        let got = c.point_at(*t).unwrap();
        assert!(
            (got[0] - p[0]).abs() < 1e-12 && (got[1] - p[1]).abs() < 1e-12,
            "{got:?}"
        );
    }
    let (headers, _) = ok(
        app(),
        post_json(
            "/v1/fit",
            &json!({ "points": q, "params": "centripetal", "format": "iges" }),
        ),
    )
    .await;
    assert_eq!(headers[header::CONTENT_TYPE], "model/iges");
    expect_error(
        app(),
        post_json(
            "/v1/fit",
            &json!({ "points": [[0, 0], [0, 0], [1, 1], [2, 0]] }),
        ),
        StatusCode::UNPROCESSABLE_ENTITY,
        "geometry",
    )
    .await;
}

/// A part sample of `samples/freecad/parts`.
fn part_sample(name: &str) -> String {
    std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("samples/freecad/parts")
            .join(name),
    )
    .unwrap()
}

/// `POST /v1/convert` with the JSON reply: the report and the file text.
async fn convert_json(query: &str, content_type: &str, body: String) -> (Value, String) {
    let mut req = post_raw(&format!("/v1/convert?{query}"), Some(content_type), body);
    req.headers_mut()
        .insert(header::ACCEPT, "application/json".parse().unwrap());
    let (_, body) = ok(app(), req).await;
    let v = json_of(&body);
    conforms(&v, &schema_ref("ConvertJsonReply"), &openapi().await, "$").unwrap();
    let file = v["file"].as_str().unwrap().to_owned();
    (v["report"].clone(), file)
}

/// The `structure` of `/v1/info` on a file text.
async fn structure(file: String) -> Value {
    let (_, body) = ok(app(), post_raw("/v1/info", None, file)).await;
    json_of(&body)["structure"].clone()
}

/// The query options of whole-part conversion, as the CLI's flags: `iges_brep` writes a
/// 186 solid (no 144), `geometry_only` leaves faces and solids out with a visible warning,
/// and `sew_tolerance` closes a 1e-5 gap in an IGES 144 part that the default tolerance
/// leaves open (a non-positive value is a 400).
#[tokio::test]
async fn convert_query_options_of_whole_parts() {
    let step = part_sample("box_fillet_chamfer_hole.step");
    // iges_brep: one 186 (columns 1-8 of a D line), no 144; read back as one solid.
    for brep in [false, true] {
        let (_, iges) = convert_json(
            &format!("to=iges&iges_brep={brep}"),
            "model/step",
            step.clone(),
        )
        .await;
        let count = |t: &str| {
            iges.lines()
                .filter(|l| l.len() >= 80 && &l[72..73] == "D" && l[..8].trim() == t)
                .count()
        };
        if brep {
            assert_eq!((count("186"), count("144")), (2, 0));
        } else {
            assert_eq!((count("186"), count("144")), (0, 38));
        }
        let s = structure(iges).await;
        assert_eq!(s["solids"].as_array().unwrap().len(), 1, "{brep}: {s}");
    }
    // geometry_only: the surfaces without faces, and the warning that says so.
    let (report, out) = convert_json("to=step&geometry_only=true", "model/step", step).await;
    assert!(!out.contains("ADVANCED_FACE") && out.contains("B_SPLINE_SURFACE"));
    assert!(
        report["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .any(|d| d["code"] == "topology.not_read" && d["severity"] == "warning"),
        "{report}"
    );
    // sew_tolerance on an IGES 144 part with a 1e-5 gap (one seam line moved in y).
    let line = "110,8.,7.166666667,15.,8.,7.166666667,0.;";
    let text = part_sample("extrude_bspline.igs");
    assert!(text.contains(line), "the sample changed: update this test");
    let gapped = text.replace(line, "110,8.,7.166676667,15.,8.,7.166676667,0.;");
    for (query, solids) in [("to=step", 0), ("to=step&sew_tolerance=1e-4", 1)] {
        let (_, out) = convert_json(query, "model/iges", gapped.clone()).await;
        let s = structure(out).await;
        assert_eq!(
            s["solids"].as_array().map_or(0, Vec::len),
            solids,
            "{query}: {s}"
        );
    }
    for bad in ["0", "-1e-3"] {
        expect_error(
            app(),
            post_raw(
                &format!("/v1/convert?to=step&sew_tolerance={bad}"),
                Some("model/iges"),
                gapped.clone(),
            ),
            StatusCode::BAD_REQUEST,
            "request.sew_tolerance",
        )
        .await;
    }
}

/// `flatten_assemblies`, as `--flatten-assemblies`: an assembly's STEP output keeps its
/// product structure by default (the bracket's solid once, three usages) and is written as
/// placed copies in one product on request (an info says so); both read back as the same
/// three placed solids.
#[tokio::test]
async fn convert_flatten_assemblies_option() {
    let step = part_sample("assembly_links.step");
    for (query, solids, usages) in [("to=step", 2, 3), ("to=step&flatten_assemblies=true", 3, 0)] {
        let (report, out) = convert_json(query, "model/step", step.clone()).await;
        let count = |k: &str| out.matches(&format!("= {k}(")).count();
        assert_eq!(
            (
                count("MANIFOLD_SOLID_BREP"),
                count("NEXT_ASSEMBLY_USAGE_OCCURRENCE")
            ),
            (solids, usages),
            "{query}"
        );
        let flattened: Vec<&Value> = report["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|d| d["code"] == "assembly.flattened")
            .collect();
        assert_eq!(flattened.len(), usize::from(usages == 0), "{report}");
        let s = structure(out).await;
        assert_eq!(s["solids"].as_array().unwrap().len(), 3, "{query}: {s}");
    }
}

/// `/v1/info` says what each entity is in the part: the surfaces of faces (`face`), the
/// curves of edges (`edge`), parameter-space curves (`pcurve`), and the rest `free` (the
/// free edges sample: all of them; model JSON: all of it). Checked against the structure
/// the same reply describes, and against the schema.
#[tokio::test]
async fn info_gives_each_entity_its_role_in_the_part() {
    let doc = openapi().await;
    let info = |text: String| async move {
        let (_, body) = ok(app(), post_raw("/v1/info", None, text)).await;
        json_of(&body)
    };
    let v = info(part_sample("box_fillet_chamfer_hole.step")).await;
    conforms(&v, &schema_ref("InfoReport"), &doc, "$").unwrap();
    let role = |id: &str| {
        v["entities"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["id"] == id)
            .map(|e| e["role"].as_str().unwrap().to_owned())
    };
    let faces = v["structure"]["faces"].as_array().unwrap();
    for f in faces {
        assert_eq!(
            role(f["surface"].as_str().unwrap()).as_deref(),
            Some("face")
        );
    }
    let count = |r: &str| {
        v["entities"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["role"] == r)
            .count()
    };
    assert_eq!(count("face"), faces.len());
    assert_eq!(count("free"), 0, "a closed box has no free geometry");
    assert!(count("edge") >= v["structure"]["edges"].as_u64().unwrap() as usize);
    for e in v["entities"].as_array().unwrap() {
        if e["role"] == "pcurve" {
            assert_eq!(e["dimension"], 2);
        }
    }
    let v = info(part_sample("free_edges.step")).await;
    let roles: Vec<&str> = v["entities"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["role"].as_str().unwrap())
        .collect();
    assert!(
        !roles.is_empty() && roles.iter().all(|r| *r == "free"),
        "{roles:?}"
    );
    let v = info(circle().to_string()).await;
    assert_eq!(v["entities"][0]["role"], "free");
}

// ---------------------------------------------------------------------------------------
// /v1/fit with poles and grids, /v1/measure

async fn fit_reply(body: &Value) -> Value {
    let (_, bytes) = ok(app(), post_json("/v1/fit", body)).await;
    let v = json_of(&bytes);
    conforms(&v, &schema_ref("FitReply"), &openapi().await, "$").unwrap_or_else(|e| panic!("{e}"));
    v
}

#[tokio::test]
async fn fit_least_squares_and_grids_with_the_residual() {
    let q: Vec<[f64; 3]> = (0..40)
        .map(|k| {
            let t = f64::from(k) * 0.25;
            [t, t.sin(), 0.2 * (3.0 * t).cos()]
        })
        .collect();
    let v =
        fit_reply(&json!({ "points": q, "degree": 3, "poles": 10, "params": "centripetal" })).await;
    let c = curve_of(&v["geometry"]);
    assert_eq!(c.num_poles(), 10);
    let want =
        nurbsx::nurbs::fit::approximate(&q, 3, 10, nurbsx::nurbs::fit::ParamMethod::Centripetal, 3)
            .unwrap();
    assert_eq!(v["fit"]["method"], "least_squares");
    assert_eq!(v["fit"]["points"], json!([40]));
    assert_eq!(v["fit"]["poles"], json!([10]));
    // The same computation on the same numbers (read back exactly): the same bits.
    let near = |got: &Value, want: f64| got.as_f64().unwrap().to_bits() == want.to_bits();
    assert!(near(&v["fit"]["residual_max"], want.residual.max), "{v}");
    assert!(near(&v["fit"]["residual_rms"], want.residual.rms), "{v}");
    // Interpolation reports a residual at round-off.
    let v = fit_reply(&json!({ "points": q })).await;
    assert_eq!(v["fit"]["method"], "interpolation");
    assert!(v["fit"]["residual_max"].as_f64().unwrap() < 1e-12 * 10.0);
    // A grid: the surface passes through every point.
    let grid: Vec<Vec<[f64; 3]>> = (0..6)
        .map(|i| {
            (0..8)
                .map(|j| {
                    let (x, y) = (f64::from(i), 0.5 * f64::from(j));
                    [x, y, (x * y).sin()]
                })
                .collect()
        })
        .collect();
    let v = fit_reply(&json!({ "points": grid, "degree": 2, "degree_v": 3 })).await;
    let s = surface_of(&v["geometry"]);
    assert_eq!((s.degree_u(), s.degree_v()), (2, 3));
    assert_eq!(v["fit"]["points"], json!([6, 8]));
    assert!(v["fit"]["residual_max"].as_f64().unwrap() < 1e-12 * 6.0);
    let v = fit_reply(&json!({ "points": grid, "poles": 4, "poles_v": 5 })).await;
    assert_eq!(v["fit"]["poles"], json!([4, 5]));
    // As a file, the residual travels in headers.
    let (headers, _) = ok(
        app(),
        post_json(
            "/v1/fit",
            &json!({ "points": q, "poles": 10, "params": "centripetal", "format": "step" }),
        ),
    )
    .await;
    let max: f64 = headers["x-nurbsx-residual-max"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!((max - want.residual.max).abs() <= 1e-12 * want.residual.max);
    // Pole counts out of range and v options on points are refused.
    expect_error(
        app(),
        post_json("/v1/fit", &json!({ "points": q, "poles": 40 })),
        StatusCode::UNPROCESSABLE_ENTITY,
        "geometry",
    )
    .await;
    expect_error(
        app(),
        post_json("/v1/fit", &json!({ "points": q, "degree_v": 2 })),
        StatusCode::BAD_REQUEST,
        "fit.arguments",
    )
    .await;
}

#[tokio::test]
async fn compare_gives_the_hausdorff_distance_as_the_cli_prints_it() {
    // The unit circle against the same circle scaled by 1.001 about its centre: every
    // point of one is 0.001 from the other (concentric circles), in both directions.
    let mut bigger = circle();
    for p in bigger["control_points"].as_array_mut().unwrap() {
        for x in p.as_array_mut().unwrap() {
            *x = json!(x.as_f64().unwrap() * 1.001);
        }
    }
    let body = json!({
        "first": { "geometry": circle() },
        "second": { "geometry": bigger },
        "tolerance": 1e-4
    });
    let (_, bytes) = ok(app(), post_json("/v1/compare", &body)).await;
    let v = json_of(&bytes);
    conforms(&v, &schema_ref("CompareSummary"), &openapi().await, "$").unwrap();
    assert!((v["distance"].as_f64().unwrap() - 1e-3).abs() < 1e-9, "{v}");
    assert_eq!(v["within_tolerance"], false);
    assert_eq!(v["curves"], json!([1, 1]));
    // The same circle reparameterised (halved knots) is at distance 0: the comparison
    // does not depend on the parameterisation.
    let mut halved = circle();
    halved["knots"] = json!([0, 0, 0, 0.5, 0.5, 1, 1, 1.5, 1.5, 2, 2, 2]);
    let body = json!({
        "first": { "geometry": circle() },
        "second": { "geometry": halved },
        "tolerance": 1e-12
    });
    let (_, bytes) = ok(app(), post_json("/v1/compare", &body)).await;
    let v = json_of(&bytes);
    assert!(v["distance"].as_f64().unwrap() <= 1e-12, "{v}");
    assert_eq!(v["within_tolerance"], true);
    // A curve against a surface only: nothing to compare (a usage error, as in the CLI);
    // a missing input and a negative tolerance are refused.
    for body in [
        json!({ "first": { "geometry": circle() }, "second": { "geometry": bilinear() } }),
        json!({ "first": { "geometry": circle() } }),
        json!({ "first": { "geometry": circle() }, "second": { "geometry": circle() },
                "tolerance": -1 }),
    ] {
        let (status, _, bytes) = send(app(), post_json("/v1/compare", &body)).await;
        assert!(
            status.is_client_error(),
            "{status}: {}",
            String::from_utf8_lossy(&bytes)
        );
    }
}

#[tokio::test]
async fn measure_lengths_areas_and_closest_points() {
    // The unit circle: length 2 pi, closest point to (3, 4) at distance 4.
    let body = json!({ "geometry": circle(), "closest": [3.0, 4.0], "tolerance": 1e-11 });
    let (_, bytes) = ok(app(), post_json("/v1/measure", &body)).await;
    let v = json_of(&bytes);
    conforms(&v, &schema_ref("MeasureReport"), &openapi().await, "$").unwrap();
    let e = &v["entities"][0];
    assert!(
        (e["length"]["value"].as_f64().unwrap() - 2.0 * std::f64::consts::PI).abs() < 1e-11,
        "{v}"
    );
    assert!(
        (e["closest"]["distance"].as_f64().unwrap() - 4.0).abs() < 1e-12,
        "{v}"
    );
    assert_eq!(v["converged"], true);
    // The bilinear patch S(u, v) = (2u, 3v, 1 + u v): area by an independent rule
    // (|S_u x S_v| = sqrt(9 v^2 + 4 u^2 + 36), Simpson on a 400 x 400 grid, error ~1e-11).
    let body = json!({ "geometry": [circle(), bilinear()], "entity": "1", "tolerance": 1e-10 });
    let (_, bytes) = ok(app(), post_json("/v1/measure", &body)).await;
    let v = json_of(&bytes);
    conforms(&v, &schema_ref("MeasureReport"), &openapi().await, "$").unwrap();
    let n = 400;
    let f = |u: f64, w: f64| (9.0 * w * w + 4.0 * u * u + 36.0).sqrt();
    let simpson = |k: usize| {
        if k == 0 || k == n {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        }
    };
    let mut area = 0.0;
    for i in 0..=n {
        for j in 0..=n {
            area += simpson(i) * simpson(j) * f(i as f64 / n as f64, j as f64 / n as f64);
        }
    }
    area /= (3.0 * n as f64) * (3.0 * n as f64);
    let got = v["entities"][0]["area"]["value"].as_f64().unwrap();
    assert!((got - area).abs() < 1e-9, "{got} vs {area}");
    assert_eq!(v["entities"].as_array().unwrap().len(), 1);
    expect_error(
        app(),
        post_json(
            "/v1/measure",
            &json!({ "geometry": circle(), "closest": [1.0] }),
        ),
        StatusCode::BAD_REQUEST,
        "measure.point",
    )
    .await;
    expect_error(
        app(),
        post_json(
            "/v1/measure",
            &json!({ "geometry": circle(), "tolerance": -1.0 }),
        ),
        StatusCode::BAD_REQUEST,
        "measure.tolerance",
    )
    .await;
}

/// [`STEP_ARC`] with a second curve labelled `.CIRCULAR_ARC.` that is a polynomial
/// parabola (the STEP writer writes it `.UNSPECIFIED.`, `step.form_unspecified`).
fn labelled_parabola() -> String {
    STEP_ARC.replacen(
        "(0.,1.),.UNSPECIFIED.);",
        "(0.,1.),.UNSPECIFIED.);\n#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.CIRCULAR_ARC.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
        1,
    )
}

/// A file modified over HTTP is written as the CLI writes it: what the output cannot carry
/// is reported (and counted in `x-nurbsx-diagnostics`). Here the arc is labelled
/// `.CIRCULAR_ARC.` but is a polynomial parabola, so the STEP writer writes
/// `.UNSPECIFIED.` and says so (`step.form_unspecified`, one more diagnostic than the
/// reading has); the written file carries no circle label.
#[tokio::test]
async fn modified_files_report_what_the_writer_changes() {
    let labelled = labelled_parabola();
    let (_, body) = ok(
        app(),
        post_raw("/v1/info", Some("model/step"), labelled.clone()),
    )
    .await;
    let read = json_of(&body)["diagnostics"].as_array().unwrap().len();
    let (headers, step) = ok(
        app(),
        post_json(
            "/v1/degree-elevate",
            &json!({ "file": labelled, "by": 1, "entity": "#4" }),
        ),
    )
    .await;
    let written: usize = headers["x-nurbsx-diagnostics"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(written, read + 1, "{}", String::from_utf8_lossy(&step));
    assert!(!String::from_utf8_lossy(&step).contains(".CIRCULAR_ARC."));
}

/// `request` asking for a JSON reply (`Accept: application/json`).
fn accepting_json(mut request: Request<Body>) -> Request<Body> {
    request
        .headers_mut()
        .insert(header::ACCEPT, "application/json".parse().unwrap());
    request
}

/// A written file with its time stamps' digits masked (STEP FILE_NAME
/// `YYYY-MM-DDTHH:MM:SS`, ISO 10303-21 clause 8.2.2; IGES Global parameters 18 and 25
/// `YYYYMMDD.HHMMSS`), so that two writings of one document in different seconds compare
/// equal; every other byte is kept.
fn without_time_stamps(file: &str) -> String {
    const STEP: &[u8] = b"dddd-dd-ddTdd:dd:dd";
    const IGES: &[u8] = b"dddddddd.dddddd";
    let fits = |window: &[u8], pattern: &[u8]| {
        window.len() == pattern.len()
            && window.iter().zip(pattern).all(|(c, p)| match p {
                b'd' => c.is_ascii_digit(),
                p => c == p,
            })
    };
    let mut bytes = file.as_bytes().to_vec();
    let mut i = 0;
    while i < bytes.len() {
        let len = [STEP, IGES]
            .into_iter()
            .find(|p| fits(&bytes[i..bytes.len().min(i + p.len())], p))
            .map(<[u8]>::len);
        match len {
            Some(n) => {
                for c in &mut bytes[i..i + n] {
                    if c.is_ascii_digit() {
                        *c = b'#';
                    }
                }
                i += n;
            }
            None => i += 1,
        }
    }
    String::from_utf8(bytes).unwrap()
}

/// The codes of a JSON array of diagnostics, sorted.
fn codes(diagnostics: &Value) -> Vec<String> {
    let mut codes: Vec<String> = diagnostics
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap().to_owned())
        .collect();
    codes.sort();
    codes
}

/// An operation on a file with `Accept: application/json` replies as `/v1/convert` does:
/// the report holds every diagnostic that `X-Nurbsx-Diagnostics` counts in the file reply,
/// whole (code, severity, message, location): the reader's and the writer's (the arc
/// labelled `.CIRCULAR_ARC.` is a parabola, written `.UNSPECIFIED.` with
/// `step.form_unspecified`, as in `modified_files_report_what_the_writer_changes`), and
/// the file is the one the plain reply carries.
#[tokio::test]
async fn operations_on_files_answer_json_with_every_diagnostic() {
    let doc = openapi().await;
    let labelled = labelled_parabola();
    let (_, body) = ok(
        app(),
        post_raw("/v1/info", Some("model/step"), labelled.clone()),
    )
    .await;
    let mut want = codes(&json_of(&body)["diagnostics"]);
    want.push("step.form_unspecified".to_owned());
    want.sort();
    let request = json!({ "file": labelled, "by": 1, "entity": "#5" });
    let (headers, plain) = ok(app(), post_json("/v1/degree-elevate", &request)).await;
    assert_eq!(headers[header::CONTENT_TYPE], "model/step");
    let count = |name: &str| -> usize { headers[name].to_str().unwrap().parse().unwrap() };
    let (json_headers, body) = ok(
        app(),
        accepting_json(post_json("/v1/degree-elevate", &request)),
    )
    .await;
    assert_eq!(json_headers[header::CONTENT_TYPE], "application/json");
    let v = json_of(&body);
    conforms(&v, &schema_ref("ConvertJsonReply"), &doc, "$").unwrap_or_else(|e| panic!("{e}"));
    conforms(&v, &schema_ref("OperationJsonReply"), &doc, "$").unwrap_or_else(|e| panic!("{e}"));
    let report = &v["report"];
    assert_eq!(
        report["diagnostics"].as_array().unwrap().len(),
        count("x-nurbsx-diagnostics"),
        "{report}"
    );
    assert_eq!(codes(&report["diagnostics"]), want, "{report}");
    let form = report["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["code"] == "step.form_unspecified")
        .unwrap();
    assert_eq!(form["severity"], "warning", "{form}");
    assert_eq!(form["location"]["entity"], "#5", "{form}");
    assert!(form["message"].as_str().is_some_and(|m| !m.is_empty()));
    assert_eq!(
        (
            &report["input_format"],
            &report["output_format"],
            &report["entities_in"],
            &report["entities_out"]
        ),
        (
            &json!("step"),
            &json!("step"),
            &json!(2),
            &json!(count("x-nurbsx-entities"))
        ),
        "{report}"
    );
    // Elevation reports no notes.
    assert!(v.get("notes").is_none(), "{v}");
    let file = v["file"].as_str().unwrap();
    assert!(file.starts_with("ISO-10303-21;") && !file.contains(".CIRCULAR_ARC."));
    assert_eq!(
        without_time_stamps(file),
        without_time_stamps(std::str::from_utf8(&plain).unwrap())
    );
    // Model JSON in keeps its model-JSON reply, whatever the Accept header says.
    let (_, body) = ok(
        app(),
        accepting_json(post_json(
            "/v1/degree-elevate",
            &json!({ "geometry": circle(), "by": 1 }),
        )),
    )
    .await;
    let v = json_of(&body);
    assert!(v["geometry"].is_object() && v.get("file").is_none(), "{v}");
}

/// The JSON reply of an operation on a file carries the operation's notes, as its
/// model-JSON reply does: a reduction's bound is the one `X-Nurbsx-Error-Bound` gives in
/// the file reply, and the file is the same.
#[tokio::test]
async fn file_json_replies_carry_the_notes_the_headers_give() {
    let (_, elevated) = ok(
        app(),
        post_json("/v1/degree-elevate", &json!({ "file": STEP_ARC, "by": 1 })),
    )
    .await;
    let request =
        json!({ "file": String::from_utf8(elevated.to_vec()).unwrap(), "tolerance": 1e-9 });
    let (headers, plain) = ok(app(), post_json("/v1/reduce", &request)).await;
    let bound: f64 = headers["x-nurbsx-error-bound"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap();
    let (_, body) = ok(app(), accepting_json(post_json("/v1/reduce", &request))).await;
    let v = json_of(&body);
    conforms(&v, &schema_ref("OperationJsonReply"), &openapi().await, "$")
        .unwrap_or_else(|e| panic!("{e}"));
    let notes = v["notes"].as_array().unwrap();
    assert_eq!(notes.len(), 1, "{v}");
    assert!(notes[0]["entity"].is_string(), "{v}");
    assert_eq!(notes[0]["error_bound"].as_f64(), Some(bound), "{v}");
    assert_eq!(
        without_time_stamps(v["file"].as_str().unwrap()),
        without_time_stamps(std::str::from_utf8(&plain).unwrap())
    );
}

/// `/v1/make` and `/v1/fit` with `format` and `Accept: application/json` reply with the
/// report and the file (the plain reply's), and a fit with its report, as its model-JSON
/// reply gives it.
#[tokio::test]
async fn built_files_answer_json_too() {
    let doc = openapi().await;
    let q = [
        [0.0, 0.0, 0.0],
        [3.0, 4.0, 1.0],
        [-1.0, 4.0, 0.0],
        [-4.0, 0.0, 2.0],
    ];
    let model = fit_reply(&json!({ "points": q, "degree": 3 })).await;
    let request = json!({ "points": q, "degree": 3, "format": "iges" });
    let (headers, plain) = ok(app(), post_json("/v1/fit", &request)).await;
    let (_, body) = ok(app(), accepting_json(post_json("/v1/fit", &request))).await;
    let v = json_of(&body);
    conforms(&v, &schema_ref("FitJsonReply"), &doc, "$").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(v["fit"], model["fit"], "{v}");
    let report = &v["report"];
    assert_eq!(
        (&report["input_format"], &report["output_format"]),
        (&json!("json"), &json!("iges")),
        "{report}"
    );
    assert_eq!(
        report["diagnostics"].as_array().unwrap().len(),
        headers["x-nurbsx-diagnostics"]
            .to_str()
            .unwrap()
            .parse::<usize>()
            .unwrap()
    );
    assert_eq!(
        without_time_stamps(v["file"].as_str().unwrap()),
        without_time_stamps(std::str::from_utf8(&plain).unwrap())
    );
    let request = json!({ "shape": "circle", "radius": 2.0, "format": "step" });
    let (_, plain) = ok(app(), post_json("/v1/make", &request)).await;
    let (_, body) = ok(app(), accepting_json(post_json("/v1/make", &request))).await;
    let v = json_of(&body);
    conforms(&v, &schema_ref("OperationJsonReply"), &doc, "$").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(v["report"]["entities_out"], 1, "{v}");
    assert_eq!(
        without_time_stamps(v["file"].as_str().unwrap()),
        without_time_stamps(std::str::from_utf8(&plain).unwrap())
    );
}

/// A file built over HTTP is written as the CLI's make and fit commands write it: what the
/// output cannot hold is dropped and said. A 2-D fitted curve has no place in IGES model
/// space (`pcurve_not_written`), so the IGES reply holds no curve and its report says
/// why, with the built entity counted in and none out; STEP holds it.
#[tokio::test]
async fn built_files_drop_and_report_what_the_output_cannot_hold() {
    let q = [[0.0, 0.0], [3.0, 4.0], [-1.0, 4.0], [-4.0, 0.0]];
    let request = json!({ "points": q, "degree": 3, "format": "iges" });
    let (status, _, body) = send(app(), accepting_json(post_json("/v1/fit", &request))).await;
    let v = json_of(&body);
    assert_eq!(status, StatusCode::OK, "{v}");
    let report = &v["report"];
    assert_eq!(
        (&report["entities_in"], &report["entities_out"]),
        (&json!(1), &json!(0)),
        "{report}"
    );
    assert!(
        codes(&report["diagnostics"]).contains(&"pcurve_not_written".to_owned()),
        "{report}"
    );
    assert!(!v["file"].as_str().unwrap().contains("126,"), "{v}");
    let request = json!({ "points": q, "degree": 3, "format": "step" });
    let (_, body) = ok(app(), accepting_json(post_json("/v1/fit", &request))).await;
    let v = json_of(&body);
    assert_eq!(v["report"]["entities_out"], 1, "{v}");
    assert!(
        v["file"]
            .as_str()
            .unwrap()
            .contains("B_SPLINE_CURVE_WITH_KNOTS"),
        "{v}"
    );
}
