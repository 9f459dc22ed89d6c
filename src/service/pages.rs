//! The operational endpoints: liveness, readiness, metrics, the OpenAPI document and the
//! landing page. None of them takes a computing slot.

use std::sync::{Arc, OnceLock};

use axum::Json;
use axum::extract::State;
use axum::http::{StatusCode, header};
use axum::response::{Html, IntoResponse, Response};
use utoipa::OpenApi;

use super::AppState;
use super::openapi::{ApiDoc, Health, Limits};

/// Liveness: the process answers.
#[utoipa::path(get, path = "/healthz", tag = "operations",
    responses((status = 200, description = "Alive", body = Health)))]
pub async fn healthz() -> Json<Health> {
    Json(Health {
        status: "ok".to_owned(),
    })
}

/// Readiness: 200 when not shutting down and a request would be admitted now; 503 from
/// the moment SIGTERM arrives (the listener keeps serving during the drain).
#[utoipa::path(get, path = "/readyz", tag = "operations",
    responses(
        (status = 200, description = "Ready", body = Health),
        (status = 503, description = "Shutting down or saturated", body = Health)
    ))]
pub async fn readyz(State(state): State<Arc<AppState>>) -> Response {
    if state.gate.ready() {
        return Json(Health {
            status: "ready".to_owned(),
        })
        .into_response();
    }
    let status = if state.gate.shutting_down() {
        "shutting down"
    } else {
        "saturated"
    };
    (
        StatusCode::SERVICE_UNAVAILABLE,
        Json(Health {
            status: status.to_owned(),
        }),
    )
        .into_response()
}

/// The request limits of this server.
#[utoipa::path(get, path = "/limits", tag = "operations",
    responses((status = 200, description = "Body, reply and time limits", body = Limits)))]
pub async fn limits(State(state): State<Arc<AppState>>) -> Json<Limits> {
    Json(Limits {
        max_body_bytes: state.max_body_bytes,
        max_reply_bytes: state.settings.max_reply_bytes,
        request_timeout_ms: u64::try_from(state.request_timeout.as_millis()).unwrap_or(u64::MAX),
    })
}

/// Prometheus metrics (text format 0.0.4).
#[utoipa::path(get, path = "/metrics", tag = "operations",
    responses((status = 200, description = "Prometheus text exposition format 0.0.4",
        content_type = "text/plain; version=0.0.4", body = String)))]
pub async fn metrics(State(state): State<Arc<AppState>>) -> Response {
    let text = state.metrics.render(&state.gauges());
    (
        [(
            header::CONTENT_TYPE,
            "text/plain; version=0.0.4; charset=utf-8",
        )],
        text,
    )
        .into_response()
}

/// The OpenAPI document as JSON, built once.
pub fn openapi_text() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| {
        ApiDoc::openapi().to_pretty_json().unwrap_or_else(|e| {
            tracing::error!(error = %e, "serialising the OpenAPI document failed");
            "{}".to_owned()
        })
    })
}

/// This API's OpenAPI 3.1 description.
#[utoipa::path(get, path = "/openapi.json", tag = "operations",
    responses((status = 200, description = "OpenAPI 3.1 document", content_type = "application/json", body = Object)))]
pub async fn openapi_json() -> Response {
    ([(header::CONTENT_TYPE, "application/json")], openapi_text()).into_response()
}

/// The web page (drop a file, see the part, check it, convert it) when it was built into
/// the binary ([`super::assets`]); otherwise the API list with how to build the page.
#[utoipa::path(get, path = "/", tag = "operations",
    responses((status = 200, description = "The web page, or without it the API list",
        content_type = "text/html", body = String)))]
pub async fn landing() -> Response {
    if let Some(page) = super::assets::reply("index.html") {
        return page;
    }
    static PAGE: OnceLock<String> = OnceLock::new();
    Html(
        PAGE.get_or_init(|| LANDING.replacen("<!-- web page -->", NO_WEB_PAGE, 1))
            .as_str(),
    )
    .into_response()
}

/// An HTML page listing the endpoints with curl examples.
#[utoipa::path(get, path = "/api", tag = "operations",
    responses((status = 200, description = "HTML list of the endpoints", content_type = "text/html", body = String)))]
pub async fn api_list() -> Html<&'static str> {
    Html(LANDING)
}

/// What `GET /` says when the web page was not built into the binary.
const NO_WEB_PAGE: &str = r#"<p><strong>The web page is not built into this binary.</strong>
Build it with Node.js 20 and npm, then rebuild nurbsx, which embeds <code>web/dist</code>:</p>
<pre>cd web &amp;&amp; npm ci &amp;&amp; npm run build &amp;&amp; cd .. &amp;&amp; cargo build --release</pre>
"#;

const LANDING: &str = r#"<!doctype html>
<html lang="en">
<head><meta charset="utf-8"><title>nurbsx</title>
<style>body{font-family:system-ui,sans-serif;max-width:60rem;margin:2rem auto;padding:0 1rem;line-height:1.45}
code,pre{font-family:ui-monospace,monospace}pre{background:#f4f4f4;padding:.6rem;overflow-x:auto}
td{padding:.2rem .6rem;vertical-align:top}</style></head>
<body>
<h1>nurbsx</h1>
<p><a href="/">The web page</a>. Exact NURBS exchange between IGES 5.3 (entities 126/128) and STEP (ISO 10303-21/42).
The full description is <a href="/openapi.json">/openapi.json</a> (OpenAPI 3.1).
Errors are JSON: <code>{"error":{"code","message","location"}}</code>.</p>
<!-- web page -->
<table>
<tr><td><code>POST /v1/convert?to=step|iges</code></td><td>convert a file (body = the file); options <code>schema=ap203|ap214|ap242</code>, <code>units=mm|in|...</code>, <code>clamp=keep|clamp|unclamp</code>, <code>verify=true|TOL</code>; <code>Accept: application/json</code> for report + file</td></tr>
<tr><td><code>POST /v1/validate[?strict=true]</code></td><td>diagnostics of a file</td></tr>
<tr><td><code>POST /v1/info</code></td><td>format, units, every entity with its exact geometry</td></tr>
<tr><td><code>POST /v1/evaluate</code></td><td>points (derivatives, normals, curvature) of a curve or surface</td></tr>
<tr><td><code>POST /v1/degree-elevate</code></td><td>exact degree elevation; on a file, as every operation, <code>Accept: application/json</code> for report + file</td></tr>
<tr><td><code>POST /v1/clamp</code>, <code>/v1/unclamp</code></td><td>knot-end conversion, shape unchanged</td></tr>
<tr><td><code>POST /v1/insert-knot</code>, <code>/v1/refine</code></td><td>knot insertion and refinement, shape unchanged</td></tr>
<tr><td><code>POST /v1/reduce</code>, <code>/v1/remove-knots</code></td><td>degree reduction and knot removal within a tolerance (the bound is reported)</td></tr>
<tr><td><code>POST /v1/decompose</code>, <code>/v1/split</code>, <code>/v1/join</code></td><td>Bezier pieces, split at a parameter, join curves</td></tr>
<tr><td><code>POST /v1/reverse</code>, <code>/v1/reparameterize</code>, <code>/v1/transform</code></td><td>direction, domain, affine map</td></tr>
<tr><td><code>POST /v1/iso</code>, <code>/v1/periodic</code>, <code>/v1/derivative-curve</code></td><td>iso-curves, periodic form, derivative curves (A3.3)</td></tr>
<tr><td><code>POST /v1/make</code></td><td>exact circles, arcs, ellipses, lines, cylinders, cones, spheres, tori, revolutions, extrusions, ruled surfaces</td></tr>
<tr><td><code>POST /v1/fit</code></td><td>a curve or surface fitted to points or a grid: interpolation (A9.1, A9.4) or least squares (A9.7), with the residual</td></tr>
<tr><td><code>POST /v1/measure</code></td><td>curve lengths, surface areas (to a tolerance) and closest points</td></tr>
<tr><td><code>POST /v1/compare</code></td><td>the Hausdorff distance between the geometry of two inputs (<code>first</code>, <code>second</code>), independent of the parameterisation</td></tr>
<tr><td><code>POST /v1/tessellate</code></td><td>OBJ, SVG, binary glTF (one node per face or curve, named by its id) or STL under a chord tolerance</td></tr>
<tr><td><code>GET /healthz</code>, <code>/readyz</code>, <code>/metrics</code>, <code>/limits</code></td><td>liveness, readiness, Prometheus metrics, request limits</td></tr>
</table>
<h2>Examples</h2>
<pre>curl -s --data-binary @part.igs -H 'Content-Type: model/iges' \
  'http://127.0.0.1:8080/v1/convert?to=step&amp;schema=ap242&amp;verify=true' -o part.step

curl -s --data-binary @part.step -H 'Content-Type: model/step' http://127.0.0.1:8080/v1/validate

curl -s http://127.0.0.1:8080/v1/evaluate -H 'Content-Type: application/json' -d '{
  "geometry": {"degree": 2, "knots": [0,0,0,1,1,1],
               "control_points": [[1,0],[1,1],[0,1]], "weights": [1,0.7071067811865476,1]},
  "params": [[0], [0.5], [1]]}'

curl -s http://127.0.0.1:8080/v1/degree-elevate -H 'Content-Type: application/json' -d '{
  "geometry": {"degree": 1, "knots": [0,0,1,1], "control_points": [[0,0,0],[1,2,3]]},
  "by": 2}'</pre>
</body>
</html>
"#;
