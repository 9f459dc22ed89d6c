//! What the web page needs from the service: its files (embedded from `web/dist` when it
//! was built), `GET /limits`, binary glTF from `/v1/tessellate` with nodes named by id, and
//! the structure's shell and solid membership. The page itself is tested in a browser by
//! `web/tests/e2e.mjs` (run by CI).

// Test helpers outside #[test] functions fail loudly on purpose.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::time::Duration;

use axum::Router;
use axum::body::{Body, Bytes};
use axum::http::{HeaderMap, Method, Request, StatusCode, header};
use http_body_util::BodyExt;
use serde_json::{Value, json};
use tower::ServiceExt;

use nurbsx::service::{self, ServeConfig, assets};

fn app() -> Router {
    service::app(ServeConfig {
        max_concurrency: 2,
        ..ServeConfig::default()
    })
}

async fn send(app: Router, req: Request<Body>) -> (StatusCode, HeaderMap, Bytes) {
    let response = app.oneshot(req).await.expect("router is infallible");
    let status = response.status();
    let headers = response.headers().clone();
    let body = response.into_body().collect().await.unwrap().to_bytes();
    (status, headers, body)
}

fn get(path: &str) -> Request<Body> {
    Request::builder().uri(path).body(Body::empty()).unwrap()
}

fn post(path: &str, content_type: &str, body: impl Into<Body>) -> Request<Body> {
    Request::builder()
        .method(Method::POST)
        .uri(path)
        .header(header::CONTENT_TYPE, content_type)
        .body(body.into())
        .unwrap()
}

fn json_of(body: &Bytes) -> Value {
    serde_json::from_slice(body)
        .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(body)))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn part(name: &str) -> String {
    std::fs::read_to_string(root().join("samples/freecad/parts").join(name)).unwrap()
}

/// Every file under `dir`, relative, with `/` separators.
fn files_under(base: &Path, dir: &Path, out: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files_under(base, &path, out);
        } else {
            let rel = path.strip_prefix(base).unwrap();
            out.insert(
                rel.components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect::<Vec<_>>()
                    .join("/"),
            );
        }
    }
}

/// The embedded page is `web/dist` byte for byte, each file with its media type and cache
/// policy, and `index.html` names only files that are served; without a build, `/` says how
/// to make one and no page file is served.
#[tokio::test]
async fn web_page_files_are_served_as_built() {
    let dist = root().join("web/dist");
    if assets::embedded() {
        let mut on_disk = BTreeSet::new();
        files_under(&dist, &dist, &mut on_disk);
        let embedded: BTreeSet<String> = assets::FILES.iter().map(|(p, _)| p.to_string()).collect();
        assert_eq!(
            embedded, on_disk,
            "the binary embeds another web/dist than the one on disk"
        );
        for rel in &on_disk {
            let url = if rel == "index.html" {
                "/".to_owned()
            } else {
                format!("/{rel}")
            };
            let (status, headers, body) = send(app(), get(&url)).await;
            assert_eq!(status, StatusCode::OK, "{url}");
            assert_eq!(
                body.as_ref(),
                std::fs::read(dist.join(rel)).unwrap(),
                "{url}"
            );
            let ty = headers[header::CONTENT_TYPE].to_str().unwrap();
            let want = match rel.rsplit('.').next().unwrap() {
                "html" => "text/html",
                "js" => "text/javascript",
                "css" => "text/css",
                "svg" => "image/svg+xml",
                "png" => "image/png",
                _ => "",
            };
            assert!(ty.starts_with(want), "{url}: {ty}");
            let cache = headers[header::CACHE_CONTROL].to_str().unwrap();
            if rel.starts_with("assets/") {
                assert_eq!(cache, "public, max-age=31536000, immutable", "{url}");
            } else {
                assert_eq!(cache, "no-cache", "{url}");
            }
        }
        // Every /assets/... the page names is served.
        let (_, _, index) = send(app(), get("/")).await;
        let html = String::from_utf8(index.to_vec()).unwrap();
        let named: Vec<&str> = html
            .split('"')
            .filter(|s| s.starts_with("/assets/"))
            .collect();
        assert!(
            named.len() >= 2,
            "index.html names no script or style: {html}"
        );
        for url in named {
            let (status, _, _) = send(app(), get(url)).await;
            assert_eq!(status, StatusCode::OK, "{url} named by index.html");
        }
    } else {
        // Status, media type and the endpoint list: tests/http.rs.
        let (_, _, body) = send(app(), get("/")).await;
        let html = String::from_utf8(body.to_vec()).unwrap();
        assert!(
            html.contains("npm ci") && html.contains("npm run build"),
            "{html}"
        );
        let (status, _, body) = send(app(), get("/assets/index.js")).await;
        assert_eq!(status, StatusCode::NOT_FOUND);
        assert_eq!(json_of(&body)["error"]["code"], "not_found");
    }
    // Page files answer GET only; unknown paths stay JSON 404s.
    let (status, _, body) = send(app(), post("/index.html", "text/plain", "x")).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert_eq!(json_of(&body)["error"]["code"], "not_found");
    let (status, _, body) = send(app(), get("/no/such/file.js")).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert_eq!(json_of(&body)["error"]["code"], "not_found");
}

/// `GET /limits` tells the configured limits, and the body limit it tells is the one a
/// request meets.
#[tokio::test]
async fn limits_tell_the_limits_requests_meet() {
    let config = ServeConfig {
        max_concurrency: 1,
        max_body_bytes: 12_345,
        max_reply_bytes: 99_999,
        request_timeout: Duration::from_secs(7),
        ..ServeConfig::default()
    };
    let (status, _, body) = send(service::app(config.clone()), get("/limits")).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(
        json_of(&body),
        json!({"max_body_bytes": 12_345, "max_reply_bytes": 99_999, "request_timeout_ms": 7000})
    );
    let over = vec![b' '; 12_346];
    let (status, _, body) = send(service::app(config), post("/v1/info", "model/step", over)).await;
    assert_eq!(status, StatusCode::PAYLOAD_TOO_LARGE);
    assert_eq!(json_of(&body)["error"]["code"], "limit.body_bytes");
}

/// The little-endian u32 at `at`.
fn u32_at(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize
}

/// A binary glTF 2.0 (Khronos glTF 2.0 specification, section 4.4 "GLB File Format"):
/// the JSON chunk and the binary chunk.
fn glb_chunks(b: &[u8]) -> (Value, &[u8]) {
    assert_eq!(&b[0..4], b"glTF");
    assert_eq!(u32_at(b, 4), 2, "version");
    assert_eq!(u32_at(b, 8), b.len(), "length");
    let json_len = u32_at(b, 12);
    assert_eq!(&b[16..20], b"JSON");
    let doc: Value = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
    let rest = &b[20 + json_len..];
    if rest.is_empty() {
        return (doc, rest);
    }
    let bin_len = u32_at(rest, 0);
    assert_eq!(&rest[4..8], b"BIN\0");
    (doc, &rest[8..8 + bin_len])
}

/// `/v1/tessellate` as binary glTF: every node is named by an id `/v1/info` gives (an
/// entity or a face), every face of the part has a mesh named by it or by its surface,
/// and every triangle index points at a vertex of its mesh.
#[tokio::test]
async fn tessellate_glb_nodes_are_named_by_ids() {
    let step = part("box_fillet_chamfer_hole.step");
    let (status, _, body) = send(app(), post("/v1/info", "model/step", step.clone())).await;
    assert_eq!(status, StatusCode::OK);
    let info = json_of(&body);
    let mut known: BTreeSet<String> = BTreeSet::new();
    for e in info["entities"].as_array().unwrap() {
        known.insert(e["id"].as_str().unwrap().to_owned());
    }
    let faces = info["structure"]["faces"].as_array().unwrap();
    for f in faces {
        known.insert(f["id"].as_str().unwrap().to_owned());
    }
    let req = json!({"file": step, "tolerance": 0.05, "format": "glb"});
    let (status, headers, body) = send(
        app(),
        post("/v1/tessellate", "application/json", req.to_string()),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    assert_eq!(headers[header::CONTENT_TYPE], "model/gltf-binary");
    // What is left out is said: the 2-D parameter-space curves /v1/info lists.
    let left: Value = serde_json::from_str(headers["x-nurbsx-left-out"].to_str().unwrap()).unwrap();
    let flat: Vec<&Value> = info["entities"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["dimension"] == 2)
        .collect();
    let said = left
        .as_array()
        .unwrap()
        .iter()
        .any(|d| d["code"] == "pcurve_not_written");
    assert_eq!(said, !flat.is_empty(), "{left}");
    let (doc, bin) = glb_chunks(&body);
    let names: Vec<&str> = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    for n in &names {
        assert!(known.contains(*n), "node {n} names nothing /v1/info knows");
    }
    for e in &flat {
        let id = e["id"].as_str().unwrap();
        assert!(
            !names.contains(&id),
            "2-D curve {id} drawn although said left out"
        );
    }
    let meshed: BTreeSet<&str> = doc["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["primitives"][0]["mode"] == 4)
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    for f in faces {
        let (id, surface) = (f["id"].as_str().unwrap(), f["surface"].as_str().unwrap());
        assert!(
            meshed.contains(id) || meshed.contains(surface),
            "face {id} (surface {surface}) has no mesh"
        );
    }
    let accessors = doc["accessors"].as_array().unwrap();
    let views = doc["bufferViews"].as_array().unwrap();
    for m in doc["meshes"].as_array().unwrap() {
        let prim = &m["primitives"][0];
        let Some(ix) = prim["indices"].as_u64() else {
            continue;
        };
        let vertices = accessors[prim["attributes"]["POSITION"].as_u64().unwrap() as usize]["count"]
            .as_u64()
            .unwrap() as usize;
        let acc = &accessors[ix as usize];
        let view = &views[acc["bufferView"].as_u64().unwrap() as usize];
        let start = view["byteOffset"].as_u64().unwrap() as usize;
        let count = acc["count"].as_u64().unwrap() as usize;
        assert!(count > 0 && count % 3 == 0, "{}", m["name"]);
        for k in 0..count {
            assert!(u32_at(bin, start + 4 * k) < vertices, "{}", m["name"]);
        }
    }
    // STL of the same part: 80-byte header, triangle count, 50 bytes per triangle.
    let req =
        json!({"file": part("box_fillet_chamfer_hole.step"), "tolerance": 0.05, "format": "stl"});
    let (status, headers, body) = send(
        app(),
        post("/v1/tessellate", "application/json", req.to_string()),
    )
    .await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(headers[header::CONTENT_TYPE], "model/stl");
    assert!(u32_at(&body, 80) > 0);
    assert_eq!(body.len(), 84 + 50 * u32_at(&body, 80));
}

/// Shells list their faces and solids their shells: FreeCAD's reading of the same parts
/// (the `.step.json` beside each sample) gives the counts per shell and solid.
#[tokio::test]
async fn structure_lists_shell_faces_and_solid_shells() {
    for name in ["box_fillet_chamfer_hole.step", "several_solids.step"] {
        let reference: Value = serde_json::from_str(
            &std::fs::read_to_string(
                root()
                    .join("samples/freecad/parts")
                    .join(format!("{name}.json")),
            )
            .unwrap(),
        )
        .unwrap();
        let (status, _, body) = send(app(), post("/v1/info", "model/step", part(name))).await;
        assert_eq!(status, StatusCode::OK);
        let s = &json_of(&body)["structure"];
        let faces: BTreeSet<&str> = s["faces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["id"].as_str().unwrap())
            .collect();
        let mut seen: HashMap<&str, usize> = HashMap::new();
        let mut per_shell: Vec<usize> = Vec::new();
        for sh in s["shells"].as_array().unwrap() {
            let ids = sh["face_ids"].as_array().unwrap();
            assert_eq!(ids.len() as u64, sh["faces"].as_u64().unwrap(), "{name}");
            per_shell.push(ids.len());
            for id in ids {
                let id = id.as_str().unwrap();
                assert!(faces.contains(id), "{name}: shell face {id} is no face");
                *seen.entry(id).or_default() += 1;
            }
        }
        assert!(
            seen.values().all(|&n| n == 1),
            "{name}: a face in two shells"
        );
        let mut want: Vec<usize> = reference["shells"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x["faces"].as_u64().unwrap() as usize)
            .collect();
        want.sort_unstable();
        per_shell.sort_unstable();
        assert_eq!(per_shell, want, "{name}: faces per shell against FreeCAD");
        let shells: BTreeSet<&str> = s["shells"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x["id"].as_str().unwrap())
            .collect();
        let solids = s["solids"].as_array().unwrap();
        assert_eq!(
            solids.len(),
            reference["solids"].as_array().unwrap().len(),
            "{name}"
        );
        for so in solids {
            let ids = so["shell_ids"].as_array().unwrap();
            assert_eq!(ids.len() as u64, so["shells"].as_u64().unwrap(), "{name}");
            assert!(
                ids.iter().all(|i| shells.contains(i.as_str().unwrap())),
                "{name}"
            );
        }
    }
}
