//! End-to-end tests of the `nurbsx` binary: outputs and exit codes.
//!
//! Tests that need the STEP/IGES readers and writers or the geometric operations (being
//! them with `cargo test --test cli -- --include-ignored` once merged.

// Helpers outside #[test] functions panic on purpose: a failed helper is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};

use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_nurbsx");

/// A file of the test data folder.
fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/cli")
        .join(name)
}

/// A fresh, empty temporary folder unique to this process and call, removed with its
/// contents when the test is done with it (also when the test fails).
fn temp_dir(tag: &str) -> TempDir {
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "nurbsx-cli-{}-{}-{}",
        tag,
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// A folder of [`temp_dir`], read as its path.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for TempDir {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

fn nurbsx<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    Command::new(BIN)
        .args(args)
        .env_remove("RUST_LOG")
        .output()
        .unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}

/// Asserts the exit code and that nothing panicked.
#[track_caller]
fn assert_exit(o: &Output, expected: i32) {
    assert_eq!(
        code(o),
        expected,
        "exit code\nstdout:\n{}\nstderr:\n{}",
        stdout(o),
        stderr(o)
    );
    assert!(!stderr(o).contains("panicked"), "{}", stderr(o));
}

fn json(o: &Output) -> Value {
    serde_json::from_slice(&o.stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON ({e}):\n{}", stdout(o)))
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

const W: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// The unit circle of `circle.json` by an independent method: the rational quadratic
/// Bernstein form of the quarter arc that contains `u` (poles P0, P1, P2, weights 1, W, 1).
fn circle_by_bernstein(u: f64) -> [f64; 2] {
    let poles = [
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
    let (p0, p1, p2) = (poles[2 * k], poles[2 * k + 1], poles[2 * k + 2]);
    let b = [(1.0 - t) * (1.0 - t), 2.0 * t * (1.0 - t) * W, t * t];
    let den = b[0] + b[1] + b[2];
    [
        (b[0] * p0[0] + b[1] * p1[0] + b[2] * p2[0]) / den,
        (b[0] * p0[1] + b[1] * p1[1] + b[2] * p2[1]) / den,
    ]
}

// ---------------------------------------------------------------------------------------
// Help and usage

#[test]
fn every_help_teaches_an_example_and_the_exit_codes() {
    let commands = [
        "convert",
        "info",
        "validate",
        "evaluate",
        "elevate",
        "clamp",
        "unclamp",
        "insert-knot",
        "tessellate",
        "serve",
        "fit",
        "measure",
        "compare",
    ];
    let top = nurbsx(["--help"]);
    assert_exit(&top, 0);
    for c in commands {
        assert!(stdout(&top).contains(c), "top-level help lists {c}");
        let o = nurbsx([c, "--help"]);
        assert_exit(&o, 0);
        let text = stdout(&o);
        assert!(
            text.contains("Examples:"),
            "{c} --help has examples:\n{text}"
        );
        assert!(
            text.contains(&format!("  nurbsx {c} ")) || text.contains(&format!("nurbsx {c}\n")),
            "{c} --help shows a `nurbsx {c}` example:\n{text}"
        );
        assert!(text.contains("Exit codes:"), "{c} --help: exit codes");
        assert!(text.contains("  2  usage"), "{c} --help: code 2 explained");
    }
}

#[test]
fn bad_flags_and_values_exit_2() {
    for args in [
        vec!["info", "--bogus", "x.json"],
        vec!["frobnicate"],
        vec!["convert", "a.igs", "-o", "b.step", "--units", "parsec"],
        vec!["convert", "a.igs", "-o", "b.step", "--clamp", "--unclamp"],
        vec!["convert", "a.igs", "-o", "b.step", "--verify", "-1"],
        vec!["evaluate", "c.json", "--at", "1,2,3"],
        vec!["evaluate", "c.json", "--at", "nan"],
        vec!["tessellate", "c.json", "-o", "c.obj", "--tolerance", "0"],
        vec!["serve", "--max-body", "12XB"],
        vec!["serve", "--timeout", "soon"],
        vec!["serve", "--timeout", "0s"],
        vec!["serve", "--max-body", "0"],
        vec![],
    ] {
        let o = nurbsx(&args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains("error"), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn serve_reads_its_settings_from_the_environment() {
    let o = Command::new(BIN)
        .args(["serve"])
        .env("NURBSX_ADDR", "not-an-address")
        .output()
        .unwrap();
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("not-an-address"), "{}", stderr(&o));
    let o = Command::new(BIN)
        .args(["serve"])
        .env("NURBSX_CONCURRENCY", "0")
        .output()
        .unwrap();
    assert_exit(&o, 2);
}

// ---------------------------------------------------------------------------------------
// Errors and exit codes

#[test]
fn a_missing_file_exits_2_with_one_error_line() {
    let dir = temp_dir("missing");
    let missing = dir.join("nope.step");
    let m = missing.to_str().unwrap();
    for args in [
        vec!["info", m],
        vec!["validate", m],
        vec!["evaluate", m, "--at", "0.5"],
        vec!["convert", m, "-o", "x.igs"],
        vec!["clamp", m, "-o", "x.step"],
    ] {
        let o = nurbsx(&args);
        assert_exit(&o, 2);
        let err = stderr(&o);
        assert!(
            err.lines()
                .any(|l| l.starts_with("error: cannot read") && l.contains("nope.step")),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn an_unknown_format_exits_1_with_a_located_error() {
    let dir = temp_dir("unknown");
    let f = dir.join("notes.dat");
    std::fs::write(&f, "hello, this is not CAD data\n").unwrap();
    let o = nurbsx(["info", f.to_str().unwrap()]);
    assert_exit(&o, 1);
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(
        err.starts_with(&format!("{}:1: error[format.unknown]:", f.display())),
        "{err}"
    );
    let o = nurbsx(["validate", f.to_str().unwrap()]);
    assert_exit(&o, 1);
    // The finding on stderr, the verdict on stdout.
    assert!(
        stderr(&o).contains("error[format.unknown]"),
        "{}",
        stderr(&o)
    );
    assert!(stdout(&o).contains(": INVALID ("), "{}", stdout(&o));
    // An extension that contradicts the content is refused, not trusted.
    let g = dir.join("fake.step");
    std::fs::write(&g, "hello\n").unwrap();
    let o = nurbsx(["info", g.to_str().unwrap()]);
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains("error[format.mismatch]"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn limits_from_global_flags_are_enforced() {
    let c = data("circle.json");
    let o = nurbsx(["info", c.to_str().unwrap(), "--max-input-bytes", "10"]);
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains("error[limit.input_bytes]"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn convert_refuses_ambiguous_plans_with_exit_2() {
    let c = data("circle.json");
    let c = c.to_str().unwrap();
    let dir = temp_dir("plans");
    // No -o and no --out-dir.
    assert_exit(&nurbsx(["convert", c]), 2);
    // JSON is not a convert target.
    let o = nurbsx(["convert", c, "-o", dir.join("x.json").to_str().unwrap()]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("info --json"), "{}", stderr(&o));
    // Unknown output extension without --to.
    assert_exit(
        &nurbsx(["convert", c, "-o", dir.join("x.xyz").to_str().unwrap()]),
        2,
    );
    // Two inputs without --out-dir.
    assert_exit(&nurbsx(["convert", c, c, "-o", "x.step"]), 2);
    // Model JSON without a target format: the pipeline's usage error.
    let o = nurbsx(["convert", c, "-o", "-"]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("convert.no_target"), "{}", stderr(&o));
}

#[test]
fn a_closed_stdout_ends_quietly() {
    let dir = temp_dir("pipe");
    let params = dir.join("params.txt");
    let mut text = String::new();
    for i in 0..=40_000 {
        text.push_str(&format!("{}\n", f64::from(i) / 40_000.0));
    }
    std::fs::write(&params, text).unwrap();
    let mut child = Command::new(BIN)
        .args(["evaluate", data("circle.json").to_str().unwrap()])
        .args(["--params", params.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = child.stdout.take().unwrap();
    let mut first = [0u8; 16];
    out.read_exact(&mut first).unwrap();
    drop(out);
    let o = child.wait_with_output().unwrap();
    assert_exit(&o, 0);
    assert_eq!(stderr(&o), "", "no message for a closed pipe");
}

// ---------------------------------------------------------------------------------------
// evaluate

#[test]
fn evaluate_puts_circle_points_at_radius_1_where_the_bernstein_form_does() {
    let dir = temp_dir("eval");
    let params = dir.join("params.txt");
    // Comments, blank lines, and both separators are accepted.
    let mut text = String::from("# u\n\n");
    let us: Vec<f64> = (0..=64).map(|i| f64::from(i) / 64.0).collect();
    for u in &us[1..] {
        text.push_str(&format!("{u}\n"));
    }
    std::fs::write(&params, text).unwrap();
    let o = nurbsx([
        "evaluate",
        data("circle.json").to_str().unwrap(),
        "--at",
        "0",
        "--params",
        params.to_str().unwrap(),
        "--json",
    ]);
    assert_exit(&o, 0);
    let report = json(&o);
    assert_eq!(report["entity"], "0");
    let results = report["results"].as_array().unwrap();
    assert_eq!(results.len(), us.len());
    for (r, &u) in results.iter().zip(&us) {
        assert_eq!(floats(&r["at"]), vec![u]);
        let p = floats(&r["point"]);
        assert_eq!(p.len(), 2, "a 2-D curve gives 2 coordinates");
        let radius = (p[0] * p[0] + p[1] * p[1]).sqrt();
        assert!((radius - 1.0).abs() < 1e-14, "u = {u}: radius {radius}");
        let e = circle_by_bernstein(u);
        assert!(
            (p[0] - e[0]).abs() < 1e-14 && (p[1] - e[1]).abs() < 1e-14,
            "u = {u}: {p:?} vs Bernstein {e:?}"
        );
    }
    // At the double knots the curve passes through the weight-1 poles exactly.
    for (r, expected) in [(0, [1.0, 0.0]), (16, [0.0, 1.0]), (32, [-1.0, 0.0])] {
        let p = floats(&results[r]["point"]);
        assert!((p[0] - expected[0]).abs() < 1e-15 && (p[1] - expected[1]).abs() < 1e-15);
    }
}

#[test]
fn evaluate_prints_a_table_and_reads_json_parameter_files() {
    let dir = temp_dir("eval-table");
    let params = dir.join("p.json");
    std::fs::write(&params, "[[0.125], [0.625]]").unwrap();
    let o = nurbsx([
        "evaluate",
        data("circle.json").to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
    ]);
    assert_exit(&o, 0);
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "entity 0");
    assert_eq!(
        lines[1].split_whitespace().collect::<Vec<_>>(),
        ["u", "x", "y"]
    );
    assert_eq!(lines.len(), 4);
    for (line, u) in lines[2..].iter().zip([0.125, 0.625]) {
        let cells: Vec<f64> = line
            .split_whitespace()
            .map(|c| c.parse().unwrap())
            .collect();
        let e = circle_by_bernstein(u);
        assert_eq!(cells[0], u);
        assert!((cells[1] - e[0]).abs() < 1e-14 && (cells[2] - e[1]).abs() < 1e-14);
    }
}

#[test]
fn evaluate_selects_surface_entities_and_checks_arity_and_domain() {
    let two = data("two.json");
    let two = two.to_str().unwrap();
    // The surface of two.json is a quarter cylinder of radius 2 along z = 3u.
    let o = nurbsx([
        "evaluate", two, "--entity", "1", "--at", "0.5,0.25", "--at", "1 0.75", "--json",
    ]);
    assert_exit(&o, 0);
    let r = json(&o);
    assert_eq!(r["entity"], "1");
    for (res, u) in r["results"].as_array().unwrap().iter().zip([0.5, 1.0]) {
        let p = floats(&res["point"]);
        assert!(
            ((p[0] * p[0] + p[1] * p[1]).sqrt() - 2.0).abs() < 1e-14,
            "{p:?}"
        );
        assert!((p[2] - 3.0 * u).abs() < 1e-14, "{p:?}");
    }
    // A curve parameter on a surface, an unknown entity, a parameter outside the domain:
    // usage errors naming the file.
    for args in [
        vec!["evaluate", two, "--entity", "1", "--at", "0.5"],
        vec!["evaluate", two, "--entity", "9", "--at", "0.5"],
        vec!["evaluate", two, "--at=-0.5"],
        vec!["evaluate", two],
    ] {
        let o = nurbsx(&args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains("error"), "{args:?}: {}", stderr(&o));
    }
    let o = nurbsx(["evaluate", two, "--entity", "9", "--at", "0.5"]);
    assert!(
        stderr(&o).starts_with(&format!("{two}: error[entity.not_found]: no entity 9")),
        "{}",
        stderr(&o)
    );
}

#[test]
fn evaluate_reads_standard_input() {
    let mut child = Command::new(BIN)
        .args(["evaluate", "-", "--at", "0.25", "--json"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(&std::fs::read(data("circle.json")).unwrap())
        .unwrap();
    let o = child.wait_with_output().unwrap();
    assert_exit(&o, 0);
    let p = floats(&json(&o)["results"][0]["point"]);
    assert!(p[0].abs() < 1e-15 && (p[1] - 1.0).abs() < 1e-15, "{p:?}");
}

// ---------------------------------------------------------------------------------------
// info

#[test]
fn info_json_has_the_documented_shape() {
    let o = nurbsx(["info", data("two.json").to_str().unwrap(), "--json"]);
    assert_exit(&o, 0);
    let r = json(&o);
    assert_eq!(r["format"], "json");
    assert!(r["schema"].is_string());
    assert_eq!(r["units"]["name"], "mm");
    assert_eq!(r["units"]["to_mm"], 1.0);
    assert!(r["diagnostics"].as_array().unwrap().is_empty());
    let e = r["entities"].as_array().unwrap();
    assert_eq!(e.len(), 2);
    assert_eq!(e[0]["id"], "0");
    assert_eq!(e[0]["kind"], "curve");
    assert_eq!(e[1]["kind"], "surface");
    assert_eq!(e[1]["degree"], serde_json::json!([1, 2]));
    assert_eq!(e[1]["poles"], serde_json::json!([2, 3]));
    // A single clamped span in each direction: the classifier reports the most specific
    // layout, "piecewise Bezier" (src/nurbs/layout.rs documents the precedence).
    assert_eq!(
        e[1]["layout"],
        serde_json::json!(["piecewise Bezier", "piecewise Bezier"])
    );
    assert_eq!(e[1]["rational"], true);
    assert_eq!(floats(&e[0]["domain"][0]), vec![0.0, 1.0]);
    assert_eq!(e[0]["source"]["entity"], "json");
    assert!(e[0]["source"].get("line").is_some());
    // The geometry is the model JSON of the input, exactly.
    let input: Value =
        serde_json::from_str(&std::fs::read_to_string(data("two.json")).unwrap()).unwrap();
    for (i, key) in [(0, "knots"), (1, "knots_v")] {
        assert_eq!(floats(&e[i]["geometry"][key]), floats(&input[i][key]));
    }
    assert_eq!(
        floats(&e[0]["geometry"]["weights"]),
        floats(&input[0]["weights"])
    );
}

#[test]
fn info_text_lists_every_entity() {
    let o = nurbsx(["info", data("two.json").to_str().unwrap()]);
    assert_exit(&o, 0);
    let text = stdout(&o);
    assert!(text.contains("format:   json"), "{text}");
    assert!(
        text.contains("entities: 2 (1 curves, 1 surfaces)"),
        "{text}"
    );
    let row = text
        .lines()
        .find(|l| l.starts_with("1 "))
        .expect("a row for entity 1");
    let cells: Vec<&str> = row.split_whitespace().collect();
    assert_eq!(
        &cells[..6],
        ["1", "surface", "3D", "1x2", "2x3", "piecewise"]
    );
    assert!(row.contains("piecewise Bezier/piecewise Bezier"), "{row}");
}

// ---------------------------------------------------------------------------------------
// validate

#[test]
fn validate_reports_bad_geometry_with_exit_1_and_a_file_line() {
    let bad = data("bad_knots.json");
    let good = data("circle.json");
    let o = nurbsx(["validate", bad.to_str().unwrap(), good.to_str().unwrap()]);
    assert_exit(&o, 1);
    let err = stderr(&o);
    let prefix = format!("{}: error[geometry.invalid]: ", bad.display());
    assert!(
        err.lines()
            .any(|l| l.starts_with(&prefix) && l.contains("knot[4]")),
        "{err}"
    );
    let text = stdout(&o);
    assert!(
        !text.contains("error["),
        "diagnostics are not on stdout: {text}"
    );
    assert!(text.contains(&format!("{}: INVALID", bad.display())));
    assert!(text.contains(&format!("{}: valid (1 entities", good.display())));
    let o = nurbsx(["validate", good.to_str().unwrap()]);
    assert_exit(&o, 0);
}

/// Conforming content nurbsx does not carry: an unbounded LINE in a GEOMETRIC_SET of the
/// Pin's shape (legal ISO 10303-42: a line is unbounded by definition; nothing bounds this
/// one). `info` and `convert` warn (it is missing from the output); `validate --strict`
/// passes, with the finding as a note, since it says nothing against the file.
#[test]
fn content_not_carried_warns_when_reading_and_is_a_note_of_validate() {
    let dir = temp_dir("not-carried");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts/assembly_links.step"),
    )
    .unwrap()
    .replace(
        "ENDSEC;\nEND-ISO",
        "#9001 = CARTESIAN_POINT('',(0.,0.,0.));\n\
         #9002 = DIRECTION('',(1.,0.,0.));\n\
         #9003 = VECTOR('',#9002,1.);\n\
         #9004 = LINE('',#9001,#9003);\n\
         #9005 = GEOMETRIC_SET('',(#9004));\n\
         #9006 = SHAPE_REPRESENTATION('',(#9005),#577);\n\
         #9007 = SHAPE_REPRESENTATION_RELATIONSHIP('','',#9006,#478);\n\
         ENDSEC;\nEND-ISO",
    );
    assert!(text.contains("#9004 = LINE"));
    let input = dir.join("line.step");
    std::fs::write(&input, text).unwrap();
    let path = input.to_str().unwrap();
    let o = nurbsx(["info", path]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains("warning[geometry.unbounded]: LINE #9004"),
        "{}",
        stderr(&o)
    );
    let o = nurbsx([
        "validate",
        "--strict",
        "--min-severity",
        "info",
        "--json",
        path,
    ]);
    assert_exit(&o, 0);
    let r = json(&o);
    assert_eq!(r[0]["valid"], true, "{r}");
    let notes: Vec<&Value> = r[0]["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["code"] == "geometry.unbounded")
        .collect();
    assert_eq!(notes.len(), 1, "{r}");
    assert_eq!(notes[0]["severity"], "info");
    assert_eq!(notes[0]["location"]["entity"], "#9004");
}

/// Colours (STYLED_ITEM) are not carried: `info` says so by default, with the count and the
/// first instance; `validate` only notes it. The file's 2-D LINE pcurves are replaced by the
/// pcurves computed on the faces' NURBS surfaces in a whole-part reading (no warning), and
/// are named as left out by `--geometry-only`, which keeps no face.
#[test]
fn colours_and_geometry_only_pcurves_are_said_to_be_left_out() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/public/freecad_cube.step");
    let text = std::fs::read_to_string(&path).unwrap();
    let styled = text.matches("STYLED_ITEM(").count();
    assert!(styled > 0 && text.contains("PCURVE"));
    let path = path.to_str().unwrap();
    let o = nurbsx(["info", path]);
    assert_exit(&o, 0);
    let err = stderr(&o);
    assert!(
        err.contains("warning[presentation.not_carried]")
            && err.contains(&format!("{styled} x STYLED_ITEM")),
        "{err}"
    );
    assert!(!err.contains("pcurve.not_converted"), "{err}");
    let dir = temp_dir("colours");
    let out = dir.join("cube.igs");
    let o = nurbsx([
        "convert",
        "--geometry-only",
        path,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        stderr(&o).contains("warning[pcurve.not_converted]"),
        "{}",
        stderr(&o)
    );
    let o = nurbsx([
        "validate",
        "--strict",
        "--json",
        "--min-severity",
        "info",
        path,
    ]);
    assert_exit(&o, 0);
    let r = json(&o);
    let note = r[0]["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["code"] == "presentation.not_carried")
        .cloned()
        .unwrap_or_default();
    assert_eq!(note["severity"], "info", "{r}");
}

#[test]
fn validate_json_lists_one_report_per_file() {
    let bad = data("bad_knots.json");
    let good = data("two.json");
    let o = nurbsx([
        "validate",
        "--json",
        bad.to_str().unwrap(),
        good.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    let r = json(&o);
    let files = r.as_array().unwrap();
    assert_eq!(files.len(), 2);
    assert_eq!(files[0]["valid"], false);
    assert_eq!(files[0]["errors"], 1);
    assert_eq!(files[0]["diagnostics"][0]["code"], "geometry.invalid");
    assert_eq!(files[0]["diagnostics"][0]["severity"], "error");
    assert_eq!(files[1]["valid"], true);
    assert_eq!(files[1]["entities"], 2);
}

/// Checks XML well-formedness enough for these reports: balanced, properly nested tags,
/// quoted attributes, no raw `<` or unknown entity in text. Returns the start tags in order
/// with their attribute text.
fn check_xml(xml: &str) -> Vec<(String, String)> {
    let mut stack: Vec<String> = Vec::new();
    let mut tags = Vec::new();
    let mut rest = xml
        .strip_prefix("<?xml version=\"1.0\" encoding=\"UTF-8\"?>")
        .unwrap();
    let check_text = |t: &str| {
        let mut s = t;
        while let Some(i) = s.find('&') {
            s = &s[i..];
            assert!(
                ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
                    .iter()
                    .any(|e| s.starts_with(e)),
                "bad entity in {t:?}"
            );
            s = &s[1..];
        }
        assert!(!t.contains('>'), "raw > in text {t:?}");
    };
    while let Some(open) = rest.find('<') {
        check_text(&rest[..open]);
        let close = rest[open..].find('>').unwrap() + open;
        let tag = &rest[open + 1..close];
        assert!(!tag.contains('<'), "raw < in tag {tag:?}");
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name), "nesting at </{name}>");
        } else {
            let self_closing = tag.ends_with('/');
            let body = tag.trim_end_matches('/');
            let (name, attrs) = body.split_once(' ').unwrap_or((body, ""));
            assert_eq!(attrs.matches('"').count() % 2, 0, "quotes in {tag:?}");
            check_text(&attrs.replace('"', ""));
            tags.push((name.to_owned(), attrs.to_owned()));
            if !self_closing {
                stack.push(name.to_owned());
            }
        }
        rest = &rest[close + 1..];
    }
    check_text(rest);
    assert!(stack.is_empty(), "unclosed {stack:?}");
    tags
}

#[test]
fn validate_junit_is_well_formed_and_escaped() {
    let dir = temp_dir("junit");
    // A file name that needs escaping, holding invalid geometry.
    let bad = dir.join("bad & <odd> \"name\".json");
    std::fs::copy(data("bad_knots.json"), &bad).unwrap();
    let good = data("circle.json");
    let o = nurbsx([
        "validate",
        "--format",
        "junit",
        bad.to_str().unwrap(),
        good.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    let xml = stdout(&o);
    let tags = check_xml(&xml);
    let names: Vec<&str> = tags.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["testsuites", "testsuite", "testcase", "failure", "testcase"]
    );
    assert!(
        tags[0]
            .1
            .contains("tests=\"2\" failures=\"1\" errors=\"0\"")
    );
    assert!(
        tags[2]
            .1
            .contains("bad &amp; &lt;odd&gt; &quot;name&quot;.json")
    );
    assert!(xml.contains("error[geometry.invalid]"));
}

#[test]
fn validate_sarif_is_sarif_2_1_0_with_located_results() {
    let dir = temp_dir("sarif");
    let syntax = dir.join("syntax error.json");
    std::fs::write(&syntax, "{\"degree\": 2,\n  \"knots\": [0, 0, x]}\n").unwrap();
    let bad = data("bad_knots.json");
    let o = nurbsx([
        "validate",
        "--format",
        "sarif",
        syntax.to_str().unwrap(),
        bad.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    let s = json(&o);
    assert_eq!(s["version"], "2.1.0");
    assert!(s["$schema"].as_str().unwrap().contains("sarif-2.1.0"));
    let run = &s["runs"][0];
    assert_eq!(run["tool"]["driver"]["name"], "nurbsx");
    let results = run["results"].as_array().unwrap();
    assert_eq!(results.len(), 2);
    let first = &results[0];
    assert_eq!(first["ruleId"], "json.syntax");
    assert_eq!(first["level"], "error");
    assert!(first["message"]["text"].as_str().unwrap().len() > 5);
    let loc = &first["locations"][0]["physicalLocation"];
    assert!(
        loc["artifactLocation"]["uri"]
            .as_str()
            .unwrap()
            .ends_with("syntax%20error.json")
    );
    // The `x` is on line 2, column 19.
    assert_eq!(loc["region"]["startLine"], 2);
    assert_eq!(loc["region"]["startColumn"], 19);
    let second = &results[1];
    assert_eq!(second["ruleId"], "geometry.invalid");
    assert!(
        second["locations"][0]["physicalLocation"]
            .get("region")
            .is_none()
    );
    assert_eq!(second["locations"][0]["logicalLocations"][0]["name"], "0");
    let rules: Vec<&str> = run["tool"]["driver"]["rules"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["id"].as_str().unwrap())
        .collect();
    assert_eq!(rules, ["json.syntax", "geometry.invalid"]);
}

#[test]
fn validate_with_a_missing_file_reports_it_and_exits_2() {
    let dir = temp_dir("validate-missing");
    let missing = dir.join("gone.igs");
    let o = nurbsx([
        "validate",
        "--format",
        "junit",
        data("circle.json").to_str().unwrap(),
        missing.to_str().unwrap(),
    ]);
    assert_exit(&o, 2);
    let tags = check_xml(&stdout(&o));
    assert!(tags.iter().any(|(n, _)| n == "error"));
    // Inside the document, once; not repeated on stderr.
    assert_eq!(
        stdout(&o).matches("cannot read").count(),
        2,
        "message and text of <error>"
    );
    assert!(stdout(&o).contains("gone.igs"));
    assert_eq!(stderr(&o), "");
    // In text form the error is on stderr, once, and there is no verdict for the file.
    let o = nurbsx(["validate", missing.to_str().unwrap()]);
    assert_exit(&o, 2);
    assert_eq!(stderr(&o).matches("gone.igs").count(), 1, "{}", stderr(&o));
    assert_eq!(stdout(&o), "");
}

// ---------------------------------------------------------------------------------------
// batch

fn read_report(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn batch_reports_each_file_and_exits_1_when_one_fails() {
    let dir = temp_dir("batch");
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("sub")).unwrap();
    std::fs::write(input.join("sub/broken.STP"), "this is not STEP\n").unwrap();
    std::fs::write(input.join("notes.txt"), "ignored\n").unwrap();
    let out = dir.join("out");
    let report = dir.join("report.jsonl");
    let o = nurbsx([
        "convert",
        input.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--to",
        "iges",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    let lines = read_report(&report);
    assert_eq!(lines.len(), 1, "only exchange files are picked: {lines:?}");
    let line = &lines[0];
    assert!(line["file"].as_str().unwrap().ends_with("sub/broken.STP"));
    assert_eq!(line["ok"], false);
    assert_eq!(line["output"], Value::Null);
    assert_eq!(line["error_code"], "format.mismatch");
    assert_eq!(line["diagnostics"]["errors"], 1);
    assert!(
        line["error"]
            .as_str()
            .unwrap()
            .contains("error[format.mismatch]")
    );
    assert!(!out.join("sub/broken.igs").exists());
    let err = stderr(&o);
    assert!(err.contains("converted 0 of 1 files"), "{err}");
    assert!(err.contains("1 failed"), "{err}");
}

#[test]
fn batch_of_folders_without_exchange_files_is_a_usage_error() {
    let dir = temp_dir("batch-empty");
    std::fs::write(dir.join("a.txt"), "x").unwrap();
    let o = nurbsx([
        "convert",
        dir.to_str().unwrap(),
        "--out-dir",
        dir.join("out").to_str().unwrap(),
    ]);
    assert_exit(&o, 2);
    // A missing input is an I/O error before any work.
    let o = nurbsx([
        "convert",
        dir.join("missing").to_str().unwrap(),
        "--out-dir",
        dir.join("out").to_str().unwrap(),
    ]);
    assert_exit(&o, 2);
}

#[test]
fn batch_counts_files_given_explicitly_and_json_without_a_target_fails() {
    let dir = temp_dir("batch-json");
    let report = dir.join("r.jsonl");
    let o = nurbsx([
        "convert",
        data("circle.json").to_str().unwrap(),
        "--out-dir",
        dir.join("out").to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    let lines = read_report(&report);
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0]["error_code"], "convert.no_target");
    assert_eq!(lines[0]["input_format"], "json");
}

// ---------------------------------------------------------------------------------------
// Pending exchange integration (STEP/IGES readers and writers, geometric operations)

/// Evaluates entity `entity` of `file` at curve parameters and returns the points.
fn eval_points(file: &Path, entity: Option<&str>, params: &[f64]) -> Vec<Vec<f64>> {
    let mut args = vec!["evaluate".to_owned(), file.to_str().unwrap().to_owned()];
    if let Some(e) = entity {
        args.extend(["--entity".to_owned(), e.to_owned()]);
    }
    for p in params {
        args.push(format!("--at={p}"));
    }
    args.push("--json".into());
    let o = nurbsx(&args);
    assert_exit(&o, 0);
    json(&o)["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| floats(&r["point"]))
        .collect()
}

/// The FreeCAD files write the circle's period 2π rounded to 12 significant digits.
#[allow(clippy::approx_constant)]
const TWO_PI: f64 = 6.28318530718;

/// The FreeCAD IGES files write it with 10 significant digits.
#[allow(clippy::approx_constant)]
const IGES_PERIOD: f64 = 6.283185307;

#[test]
fn info_names_step_and_iges_entities_with_their_source() {
    let o = nurbsx([
        "info",
        data("curve_circle_nurbs.step").to_str().unwrap(),
        "--json",
    ]);
    assert_exit(&o, 0);
    let r = json(&o);
    assert_eq!(r["format"], "step");
    assert!(r["schema"].as_str().unwrap().contains("AUTOMOTIVE_DESIGN"));
    assert_eq!(r["units"]["name"], "mm");
    // The file's B-spline #17 is the basis of TRIMMED_CURVE #16 (trimmed at its own domain
    // ends): the entity is the trimmed curve.
    let e = &r["entities"][0];
    assert_eq!(r["entities"].as_array().unwrap().len(), 1);
    assert_eq!(e["id"], "#16");
    assert_eq!(e["source"]["entity"], "TRIMMED_CURVE");
    assert_eq!(e["degree"], serde_json::json!([3]));
    assert_eq!(e["poles"], serde_json::json!([7]));
    assert_eq!(e["rational"], true);
    assert_eq!(floats(&e["domain"][0]), vec![0.0, TWO_PI]);
    assert_eq!(e["source"]["line"], 28);
    let o = nurbsx(["info", data("curve_circle_nurbs.igs").to_str().unwrap()]);
    assert_exit(&o, 0);
    assert!(
        stdout(&o).lines().any(|l| l.starts_with("D1 ")),
        "{}",
        stdout(&o)
    );
}

#[test]
fn evaluate_step_and_iges_circles_at_radius_7_5() {
    // The IGES file writes the period with 10 digits (6.283185307): stay inside both domains.
    let params: Vec<f64> = (0..=12)
        .map(|i| IGES_PERIOD * f64::from(i) / 12.0)
        .collect();
    for file in ["curve_circle_nurbs.step", "curve_circle_nurbs.igs"] {
        for p in eval_points(&data(file), None, &params) {
            let r = ((p[0] - 1.0).powi(2) + (p[1] - 2.0).powi(2)).sqrt();
            assert!((r - 7.5).abs() < 1e-8, "{file}: {p:?}");
            assert!((p[2] - 3.0).abs() < 1e-12);
        }
    }
    // The cylinder surface r = 5 around z.
    let o = nurbsx([
        "evaluate",
        data("surf_cylinder_nurbs.step").to_str().unwrap(),
        "--entity",
        "#34",
        "--at",
        "1,6",
        "--json",
    ]);
    assert_exit(&o, 0);
    let p = floats(&json(&o)["results"][0]["point"]);
    assert!(
        ((p[0] * p[0] + p[1] * p[1]).sqrt() - 5.0).abs() < 1e-9,
        "{p:?}"
    );
}

#[test]
fn convert_step_to_iges_verifies_and_keeps_the_geometry() {
    let dir = temp_dir("convert");
    let out = dir.join("circle.igs");
    let report = dir.join("report.json");
    let step = data("curve_circle_nurbs.step");
    let o = nurbsx([
        "convert",
        step.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--verify",
        "--report",
        report.to_str().unwrap(),
        "--timestamp",
        "2026-01-01T00:00:00",
    ]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o)
            .contains("read 1 curves and surfaces, wrote 1 as IGES; verified 1 written entities"),
        "{}",
        stderr(&o)
    );
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["ok"], true);
    assert_eq!(r["output_format"], "iges");
    assert!(r["max_relative_deviation"].as_f64().unwrap() <= 1e-9);
    let params: Vec<f64> = (0..=16).map(|i| TWO_PI * f64::from(i) / 16.0).collect();
    let a = eval_points(&step, None, &params);
    let b = eval_points(&out, None, &params);
    for (p, q) in a.iter().zip(&b) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-9, "{p:?} vs {q:?}");
        }
    }
    // Units: inches scale coordinates by 1/25.4.
    let inch = dir.join("circle-in.step");
    let o = nurbsx([
        "convert",
        out.to_str().unwrap(),
        "-o",
        inch.to_str().unwrap(),
        "--units",
        "in",
        "--verify",
    ]);
    assert_exit(&o, 0);
    let c = eval_points(&inch, None, &params);
    for (p, q) in a.iter().zip(&c) {
        assert!((p[0] / 25.4 - q[0]).abs() < 1e-9, "{p:?} vs {q:?}");
    }
    // Model JSON in, STEP out.
    let step_out = dir.join("two.step");
    let o = nurbsx([
        "convert",
        data("two.json").to_str().unwrap(),
        "-o",
        step_out.to_str().unwrap(),
        "--verify",
    ]);
    assert_exit(&o, 0);
    let o = nurbsx(["info", step_out.to_str().unwrap(), "--json"]);
    assert_eq!(json(&o)["entities"].as_array().unwrap().len(), 2);
}

#[test]
fn batch_converts_good_files_and_reports_the_bad_one() {
    let dir = temp_dir("batch-full");
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("nested")).unwrap();
    std::fs::copy(data("curve_circle_nurbs.step"), input.join("circle.step")).unwrap();
    std::fs::copy(
        data("surf_cylinder_nurbs.igs"),
        input.join("nested/cylinder.igs"),
    )
    .unwrap();
    std::fs::write(input.join("broken.step"), "ISO-10303-21;\nHEADER;\n").unwrap();
    let out = dir.join("out");
    let report = dir.join("r.jsonl");
    let o = nurbsx([
        "convert",
        input.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--to",
        "step",
        "--verify",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    let lines = read_report(&report);
    assert_eq!(lines.len(), 3);
    let ok: Vec<&Value> = lines.iter().filter(|l| l["ok"] == true).collect();
    assert_eq!(ok.len(), 2);
    assert!(out.join("nested/cylinder.step").exists());
    assert!(out.join("circle.step").exists());
    assert_exit(
        &nurbsx(["validate", out.join("circle.step").to_str().unwrap()]),
        0,
    );
    std::fs::remove_file(input.join("broken.step")).unwrap();
    let o = nurbsx([
        "convert",
        input.to_str().unwrap(),
        "--out-dir",
        dir.join("out2").to_str().unwrap(),
        "--to",
        "iges",
    ]);
    assert_exit(&o, 0);
}

#[test]
fn shape_preserving_operations_keep_the_circle() {
    let dir = temp_dir("ops");
    let circle = data("circle.json");
    let params: Vec<f64> = (0..=32).map(|i| f64::from(i) / 32.0).collect();
    let before = eval_points(&circle, None, &params);
    for (cmd, extra) in [
        ("elevate", vec!["--by", "2"]),
        ("clamp", vec![]),
        ("unclamp", vec![]),
        ("insert-knot", vec!["--at", "0.3", "--times", "2"]),
    ] {
        let out = dir.join(format!("{cmd}.json"));
        let mut args = vec![cmd, circle.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend(extra);
        let o = nurbsx(&args);
        assert_exit(&o, 0);
        // The output is model JSON (input form kept); its domain may be reparametrised only
        // by unclamping, which keeps the domain too.
        let after = eval_points(&out, None, &params);
        for (p, q) in before.iter().zip(&after) {
            assert!(
                (p[0] - q[0]).abs() < 1e-12 && (p[1] - q[1]).abs() < 1e-12,
                "{cmd}"
            );
        }
    }
    let o = nurbsx(["info", dir.join("elevate.json").to_str().unwrap(), "--json"]);
    assert_eq!(json(&o)["entities"][0]["degree"], serde_json::json!([4]));
}

#[test]
fn refine_halve_writes_knot_intervals_and_keeps_the_circle() {
    let dir = temp_dir("halve");
    let circle = data("circle.json");
    let out = dir.join("halved.json");
    let o = nurbsx([
        "refine",
        circle.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--halve",
        "--knot-intervals",
    ]);
    assert_exit(&o, 0);
    // Knots [0,0,0,.125,.25,.25,.375,.5,.5,.625,.75,.75,.875,1,1,1] in knot-interval form:
    // the differences without the outermost ones (zero: clamped), origin 0.
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let h = 0.125;
    assert_eq!(
        v["knot_intervals"],
        serde_json::json!([0.0, h, h, 0.0, h, h, 0.0, h, h, 0.0, h, h, 0.0])
    );
    assert_eq!(v["knot_origin"], serde_json::json!(0.0));
    assert!(v.get("knots").is_none(), "{v}");
    let params: Vec<f64> = (0..=32).map(|i| f64::from(i) / 32.0).collect();
    for (p, q) in eval_points(&circle, None, &params)
        .iter()
        .zip(&eval_points(&out, None, &params))
    {
        assert!((p[0] - q[0]).abs() < 1e-12 && (p[1] - q[1]).abs() < 1e-12);
    }
    // --halve and --knots exclude each other; knot intervals are a model JSON form.
    let o = nurbsx([
        "refine",
        circle.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--halve",
        "--knots",
        "0.5",
    ]);
    assert_exit(&o, 2);
    let step = dir.join("halved.step");
    let o = nurbsx([
        "refine",
        circle.to_str().unwrap(),
        "-o",
        step.to_str().unwrap(),
        "--halve",
        "--knot-intervals",
    ]);
    assert_exit(&o, 2);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--knot-intervals"));
}

#[test]
fn tessellate_puts_obj_vertices_on_the_circle() {
    let dir = temp_dir("tess");
    let out = dir.join("circle.obj");
    let o = tessellate_to(&data("circle.json"), &out, "1e-3");
    assert_exit(&o, 0);
    let text = std::fs::read_to_string(&out).unwrap();
    let vertices: Vec<Vec<f64>> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split_whitespace().map(|c| c.parse().unwrap()).collect())
        .collect();
    // Chord error of a unit circle with n segments is 1 - cos(pi/n) <= 1e-3 needs n >= 71.
    assert!(vertices.len() >= 71, "{} vertices", vertices.len());
    for v in &vertices {
        assert!(((v[0] * v[0] + v[1] * v[1]).sqrt() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn evaluate_derivatives_and_curvature_of_the_circle() {
    let o = nurbsx([
        "evaluate",
        data("circle.json").to_str().unwrap(),
        "--at",
        "0.1",
        "--at",
        "0.6",
        "--derivatives",
        "1",
        "--curvature",
        "--json",
    ]);
    assert_exit(&o, 0);
    for r in json(&o)["results"].as_array().unwrap() {
        let p = floats(&r["point"]);
        let d1 = floats(&r["derivatives"][0]);
        // The tangent of a circle is perpendicular to the radius.
        let dot = p[0] * d1[0] + p[1] * d1[1];
        assert!(dot.abs() < 1e-12, "{p:?} {d1:?}");
        let k = match &r["curvature"] {
            Value::Number(n) => n.as_f64().unwrap(),
            other => other["curvature"].as_f64().unwrap(),
        };
        assert!((k - 1.0).abs() < 1e-10, "curvature {k}");
    }
}

#[test]
fn a_failed_single_conversion_still_writes_its_report() {
    let dir = temp_dir("single-report");
    let fake = dir.join("fake.igs");
    std::fs::write(&fake, "not IGES at all\n").unwrap();
    let report = dir.join("r.json");
    let out = dir.join("out.step");
    let o = nurbsx([
        "convert",
        fake.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    assert!(!out.exists(), "nothing written on failure");
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["ok"], false);
    assert_eq!(r["error_code"], "format.mismatch");
    assert_eq!(r["input_format"], "iges");
    assert_eq!(
        stderr(&o).trim_end(),
        r["error"].as_str().unwrap(),
        "the same one-line error on stderr and in the report"
    );
}

#[test]
fn logs_go_to_stderr_as_json_lines_on_request() {
    let dir = temp_dir("logs");
    let o = Command::new(BIN)
        .args(["-v", "--log-format", "json", "clamp"])
        .arg(data("circle.json"))
        .arg("-o")
        .arg(dir.join("c.json"))
        .env_remove("RUST_LOG")
        .output()
        .unwrap();
    let err = stderr(&o);
    let line = err
        .lines()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("a JSON log line in {err}"));
    let v: Value = serde_json::from_str(line).unwrap();
    assert_eq!(v["level"], "INFO");
    assert_eq!(v["fields"]["message"], "modify");
    // Without -v the info line is not shown.
    let o = nurbsx([
        "clamp",
        data("circle.json").to_str().unwrap(),
        "-o",
        dir.join("d.json").to_str().unwrap(),
    ]);
    assert!(!stderr(&o).contains("INFO"), "{}", stderr(&o));
}

#[test]
fn validate_searches_folders_for_exchange_files() {
    let dir = temp_dir("validate-folder");
    std::fs::create_dir_all(dir.join("deep/er")).unwrap();
    std::fs::write(dir.join("deep/er/broken.igs"), "junk\n").unwrap();
    std::fs::write(dir.join("readme.txt"), "not checked\n").unwrap();
    let o = nurbsx(["validate", "--json", dir.to_str().unwrap()]);
    assert_exit(&o, 1);
    let r = json(&o);
    let files = r.as_array().unwrap();
    assert_eq!(files.len(), 1);
    assert!(
        files[0]["file"]
            .as_str()
            .unwrap()
            .ends_with("deep/er/broken.igs")
    );
    assert_eq!(files[0]["valid"], false);
}

#[test]
fn the_freecad_samples_validate() {
    let o = nurbsx(["validate", data("").to_str().unwrap()]);
    assert_exit(&o, 0);
    assert_eq!(stdout(&o).matches(": valid (").count(), 4, "{}", stdout(&o));
}

#[test]
fn to_overrides_a_contradicting_extension_with_a_warning() {
    let dir = temp_dir("to-ext");
    let o = nurbsx([
        "convert",
        data("circle.json").to_str().unwrap(),
        "-o",
        dir.join("x.igs").to_str().unwrap(),
        "--to",
        "step",
    ]);
    assert!(
        stderr(&o).contains("x.igs: warning[format.extension]: writing STEP as --to asks"),
        "{}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("panicked"));
}

// ---------------------------------------------------------------------------------------
// Conventions: help, completions, man pages, colour

const COMMANDS: [&str; 13] = [
    "convert",
    "info",
    "validate",
    "evaluate",
    "elevate",
    "clamp",
    "unclamp",
    "insert-knot",
    "tessellate",
    "serve",
    "help",
    "completions",
    "man",
];

const LIMIT_FLAGS: [(&str, &str); 9] = [
    ("--max-degree", "NURBSX_MAX_DEGREE"),
    ("--max-input-bytes", "NURBSX_MAX_INPUT_BYTES"),
    ("--max-entities", "NURBSX_MAX_ENTITIES"),
    ("--max-nesting-depth", "NURBSX_MAX_NESTING_DEPTH"),
    ("--max-params", "NURBSX_MAX_PARAMS"),
    ("--max-poles", "NURBSX_MAX_POLES"),
    ("--max-eval-points", "NURBSX_MAX_EVAL_POINTS"),
    ("--max-elevate-by", "NURBSX_MAX_ELEVATE_BY"),
    ("--max-mesh-vertices", "NURBSX_MAX_MESH_VERTICES"),
];

#[test]
fn help_works_like_cargos_and_lists_the_limits_once() {
    // `help --help` and `help help` are help, not errors.
    for args in [vec!["help", "--help"], vec!["help", "help"], vec!["help"]] {
        let o = nurbsx(&args);
        assert_exit(&o, 0);
        assert!(
            stdout(&o).contains("Usage: nurbsx"),
            "{args:?}: {}",
            stdout(&o)
        );
    }
    // `help CMD` is the command's full help.
    for c in COMMANDS {
        let o = nurbsx(["help", c]);
        assert_exit(&o, 0);
        assert!(
            stdout(&o).contains(&format!("Usage: nurbsx {c}")),
            "help {c}: {}",
            stdout(&o)
        );
        // The limits are not repeated in every command's help.
        let o = nurbsx([c, "--help"]);
        assert!(
            !stdout(&o).contains("--max-poles"),
            "{c} --help:\n{}",
            stdout(&o)
        );
        assert!(stdout(&o).lines().count() < 150, "{c} --help is short");
    }
    // They are on one page, each with its environment variable.
    let o = nurbsx(["help", "limits"]);
    assert_exit(&o, 0);
    for (flag, env) in LIMIT_FLAGS {
        assert!(
            stdout(&o).contains(flag) && stdout(&o).contains(env),
            "{flag}"
        );
    }
    let top = stdout(&nurbsx(["--help"]));
    assert!(top.contains("nurbsx help limits"), "{top}");
    let o = nurbsx(["help", "exit-codes"]);
    assert_exit(&o, 0);
    for code in [
        "limit.*",
        "evaluate.domain",
        "insert_knot.domain",
        "format.unknown",
    ] {
        assert!(stdout(&o).contains(code), "{code}");
    }
    let o = nurbsx(["help", "output"]);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains("--min-severity"));
    let o = nurbsx(["help", "frobnicate"]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("frobnicate"), "{}", stderr(&o));
}

#[test]
fn completions_parse_for_every_shell() {
    let o = nurbsx(["completions", "bash"]);
    assert_exit(&o, 0);
    let dir = temp_dir("completions");
    let script = dir.join("nurbsx.bash");
    std::fs::write(&script, &o.stdout).unwrap();
    let check = Command::new("bash")
        .arg("-n")
        .arg(&script)
        .output()
        .unwrap();
    assert!(check.status.success(), "bash -n: {}", stderr(&check));
    // Sourcing it defines the completion function.
    let sourced = Command::new("bash")
        .arg("-c")
        .arg(format!("source {} && complete -p nurbsx", script.display()))
        .output()
        .unwrap();
    assert!(stdout(&sourced).contains("nurbsx"), "{}", stderr(&sourced));
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"] {
        let o = nurbsx(["completions", shell]);
        assert_exit(&o, 0);
        let text = stdout(&o);
        for c in ["convert", "validate", "insert-knot", "tessellate"] {
            assert!(text.contains(c), "{shell} completions name {c}");
        }
        assert!(text.contains("min-severity"), "{shell}: global options");
    }
    // zsh and fish parse their own scripts where they are installed.
    for (shell, flag) in [("zsh", "-n"), ("fish", "--no-execute")] {
        let o = nurbsx(["completions", shell]);
        let file = dir.join(format!("nurbsx.{shell}"));
        std::fs::write(&file, &o.stdout).unwrap();
        if let Ok(check) = Command::new(shell).arg(flag).arg(&file).output() {
            assert!(check.status.success(), "{shell}: {}", stderr(&check));
        }
    }
    assert_exit(&nurbsx(["completions", "tcsh"]), 2);
}

/// Renders roff with groff (as `man -l` does) and returns the text with its warnings.
fn render_roff(roff: &[u8]) -> Option<(String, String)> {
    let mut child = Command::new("groff")
        .args(["-man", "-Tutf8", "-ww", "-z"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .ok()?;
    child.stdin.take().unwrap().write_all(roff).unwrap();
    let checked = child.wait_with_output().unwrap();
    let mut child = Command::new("groff")
        .args(["-man", "-Tutf8"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .ok()?;
    child.stdin.take().unwrap().write_all(roff).unwrap();
    let rendered = child.wait_with_output().unwrap();
    // Undo the terminal overstrike (bold `N\bN`, underline `_\bx`).
    let mut text = String::new();
    for c in stdout(&rendered).chars() {
        if c == '\u{8}' {
            text.pop();
        } else {
            text.push(c);
        }
    }
    Some((text, stderr(&checked)))
}

#[test]
fn man_pages_render() {
    let mut pages = vec![("nurbsx".to_owned(), nurbsx(["man"]))];
    for c in ["convert", "validate", "insert-knot"] {
        pages.push((format!("nurbsx-{c}"), nurbsx(["man", c])));
    }
    for (name, o) in &pages {
        assert_exit(o, 0);
        let roff = stdout(o);
        assert!(roff.contains(&format!(".TH {name} 1")), "{roff}");
        assert!(roff.contains(".SH NAME") && roff.contains(".SH SYNOPSIS"));
        if let Some((text, warnings)) = render_roff(&o.stdout) {
            assert_eq!(warnings, "", "groff warnings for {name}");
            assert!(text.contains("NAME") && text.contains("SYNOPSIS"), "{text}");
            // groff hyphenates and escapes: compare without them.
            let plain = text.replace(['\u{2010}', '\u{2212}'], "-");
            assert!(plain.contains(name.as_str()), "{plain}");
        }
    }
    // The program's page lists the limits (hidden from the options) and the exit status.
    let o = nurbsx(["man"]);
    if let Some((text, _)) = render_roff(&o.stdout) {
        let plain = text.replace(['\u{2010}', '\u{2212}'], "-");
        for (flag, env) in LIMIT_FLAGS {
            assert!(
                plain.contains(flag) && plain.contains(env),
                "{flag}: {plain}"
            );
        }
        assert!(plain.contains("EXIT STATUS") && plain.contains("insert_knot.domain"));
    }
    let dir = temp_dir("man");
    let o = nurbsx(["man", "--out-dir", dir.to_str().unwrap()]);
    assert_exit(&o, 0);
    assert!(dir.join("nurbsx.1").is_file());
    for c in COMMANDS {
        assert!(dir.join(format!("nurbsx-{c}.1")).is_file(), "{c}");
    }
    assert_exit(&nurbsx(["man", "frobnicate"]), 2);
}

/// `nurbsx` with extra environment variables.
fn nurbsx_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(BIN);
    c.args(args).env_remove("RUST_LOG").env_remove("NO_COLOR");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

#[test]
fn colour_follows_the_flag_and_no_color() {
    let bad = data("bad_knots.json");
    let bad = bad.to_str().unwrap();
    let esc = "\u{1b}[";
    let o = nurbsx_env(&["--color", "always", "validate", bad], &[]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains(esc), "{:?}", stderr(&o));
    assert!(stderr(&o).contains("error[geometry.invalid]"));
    // The flag after the command works too, `=` or not.
    let o = nurbsx_env(&["validate", bad, "--color=always"], &[]);
    assert!(stderr(&o).contains(esc));
    for (args, env) in [
        (vec!["--color", "never", "validate", bad], vec![]),
        // Not a terminal: auto means plain.
        (vec!["validate", bad], vec![]),
        (
            vec!["--color", "auto", "validate", bad],
            vec![("NO_COLOR", "1")],
        ),
    ] {
        let o = nurbsx_env(&args, &env);
        assert_exit(&o, 1);
        assert!(!stderr(&o).contains(esc), "{args:?}: {:?}", stderr(&o));
        assert!(stderr(&o).contains("error[geometry.invalid]"));
    }
    // Help and usage errors follow the flag.
    let o = nurbsx_env(&["--color", "always", "--help"], &[]);
    assert!(stdout(&o).contains(esc));
    let o = nurbsx_env(&["--color", "never", "--help"], &[]);
    assert!(!stdout(&o).contains(esc));
    let o = nurbsx_env(&["--color", "always", "help", "convert"], &[]);
    assert!(stdout(&o).contains(esc));
    let o = nurbsx_env(&["--color", "always", "info", "--bogus"], &[]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains(esc), "{:?}", stderr(&o));
    let o = nurbsx_env(&["info", "--bogus"], &[]);
    assert!(!stderr(&o).contains(esc));
}

// ---------------------------------------------------------------------------------------
// One output policy: results on stdout, diagnostics on stderr (or in the JSON document),
// filtered by -q / --min-severity, JSON with --log-format json, each once

/// A STEP circle in a file named `.igs`: every command reads it (by its content) with one
/// `format.extension` warning.
fn misnamed_circle(dir: &Path) -> PathBuf {
    let f = dir.join("circle.igs");
    std::fs::copy(data("curve_circle_nurbs.step"), &f).unwrap();
    f
}

/// Every command that reads a file, with arguments that succeed on the circle.
fn every_reading_command(input: &str, dir: &Path) -> Vec<Vec<String>> {
    let out = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let cmds: Vec<Vec<&str>> = vec![
        vec!["info", input],
        vec!["validate", input],
        vec!["evaluate", input, "--at", "1"],
        vec!["elevate", input, "--by", "1", "-o"],
        vec!["clamp", input, "-o"],
        vec!["unclamp", input, "-o"],
        vec!["insert-knot", input, "--at", "1", "-o"],
        vec!["tessellate", input, "--tolerance", "0.1", "-o"],
        vec!["convert", input, "-o"],
    ];
    cmds.into_iter()
        .map(|c| {
            let mut v: Vec<String> = c.iter().map(|s| (*s).to_owned()).collect();
            if v.last().map(String::as_str) == Some("-o") {
                let ext = if v[0] == "tessellate" { "obj" } else { "step" };
                v.push(out(&format!("{}.{ext}", v[0])));
            }
            v
        })
        .collect()
}

#[test]
fn every_command_puts_diagnostics_on_stderr_once_and_filters_them() {
    let dir = temp_dir("policy");
    let input = misnamed_circle(&dir);
    let input = input.to_str().unwrap();
    for args in every_reading_command(input, &dir) {
        let c = &args[0];
        let o = nurbsx(&args);
        assert_exit(&o, 0);
        let (out, err) = (stdout(&o), stderr(&o));
        assert_eq!(
            err.matches("warning[format.extension]").count(),
            1,
            "{c}: the warning once on stderr:\n{err}"
        );
        assert!(
            err.contains(&format!("{input}: warning[format.extension]: the extension says IGES but the content is STEP")),
            "{c}: {err}"
        );
        assert!(
            !out.contains("warning["),
            "{c}: no diagnostics on stdout:\n{out}"
        );
        // -q and --min-severity error hide warnings; -qq hides the summaries too.
        for quiet in [vec!["-q"], vec!["--min-severity", "error"]] {
            let mut a = quiet.clone();
            a.extend(args.iter().map(String::as_str));
            let o = nurbsx(&a);
            assert_exit(&o, 0);
            assert!(
                !stderr(&o).contains("warning"),
                "{c} {quiet:?}: {}",
                stderr(&o)
            );
        }
        let mut a = vec!["-qq"];
        a.extend(args.iter().map(String::as_str));
        let o = nurbsx(&a);
        assert_exit(&o, 0);
        assert_eq!(stderr(&o), "", "{c} -qq");
        // -v / --min-severity info show the info notes too (the unit of the file).
        let mut a = vec!["--min-severity", "info"];
        a.extend(args.iter().map(String::as_str));
        let o = nurbsx(&a);
        assert!(stderr(&o).contains("info[units]"), "{c}: {}", stderr(&o));
        // JSON logs: every stderr line is a JSON object; the warning is one of them.
        let mut a = vec!["--log-format", "json"];
        a.extend(args.iter().map(String::as_str));
        let o = nurbsx(&a);
        assert_exit(&o, 0);
        let lines: Vec<Value> = stderr(&o)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{c}: not JSON ({e}): {l}")))
            .collect();
        let warnings: Vec<&Value> = lines
            .iter()
            .filter(|v| v["code"] == "format.extension")
            .collect();
        assert_eq!(warnings.len(), 1, "{c}: {lines:?}");
        assert_eq!(warnings[0]["severity"], "warning");
        assert_eq!(warnings[0]["file"], input);
    }
}

#[test]
fn json_documents_carry_the_diagnostics_instead_of_stderr() {
    let dir = temp_dir("policy-json");
    let input = misnamed_circle(&dir);
    let input = input.to_str().unwrap();
    for args in [
        vec!["info", input, "--json"],
        vec!["evaluate", input, "--at", "1", "--json"],
        vec!["validate", input, "--format", "json"],
    ] {
        let o = nurbsx(&args);
        assert_exit(&o, 0);
        assert_eq!(stderr(&o), "", "{args:?}");
        let doc = json(&o);
        let diagnostics = if args[0] == "validate" {
            doc[0]["diagnostics"].clone()
        } else {
            doc["diagnostics"].clone()
        };
        let codes: Vec<&str> = diagnostics
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d["code"].as_str().unwrap())
            .collect();
        assert!(codes.contains(&"format.extension"), "{args:?}: {codes:?}");
        // The default filter leaves out info notes; -v brings them in.
        assert!(!codes.contains(&"units"), "{args:?}: {codes:?}");
        let mut a = vec!["-v"];
        a.extend(&args);
        let doc = json(&nurbsx(&a));
        assert!(doc.to_string().contains("\"units\""), "{args:?} -v");
    }
    let o = nurbsx(["validate", input, "--format", "sarif"]);
    assert_eq!(stderr(&o), "");
    assert!(stdout(&o).contains("format.extension"));
}

#[test]
fn validate_on_the_samples_is_quiet_by_default() {
    let samples = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad");
    let o = nurbsx(["validate", samples.to_str().unwrap()]);
    assert_exit(&o, 0);
    let files = stdout(&o).lines().count();
    // 108 B-spline samples in samples/freecad/, 60 analytic ones in its analytic/ folder and
    // 54 whole-part files (18 parts x STEP, IGES 144, IGES 186) in parts/ (the folder walk
    // descends into them).
    assert_eq!(files, 108 + 60 + 54, "one verdict per sample");
    // Info notes only with -v.
    assert!(!stderr(&o).contains(": info["), "{}", stderr(&o));
    let o = nurbsx(["-v", "validate", samples.to_str().unwrap()]);
    assert!(stderr(&o).contains(": info["));
    let o = nurbsx(["-q", "validate", samples.to_str().unwrap()]);
    assert_eq!(stderr(&o), "");
}

// ---------------------------------------------------------------------------------------
// One exit-code policy

/// The code in the last `error[code]` of stderr.
fn error_code(o: &Output) -> String {
    let err = stderr(o);
    let line = err
        .lines()
        .rev()
        .find(|l| l.contains("error["))
        .unwrap_or_else(|| panic!("no error line: {err}"));
    let start = line.find("error[").unwrap() + 6;
    line[start..start + line[start..].find(']').unwrap()].to_owned()
}

#[test]
fn a_limit_of_zero_is_refused_by_every_command() {
    let circle = data("circle.json");
    let c = circle.to_str().unwrap();
    let dir = temp_dir("zero");
    for args in every_reading_command(c, &dir) {
        for zero in [
            ["--max-degree", "0"],
            ["--max-input-bytes", "0"],
            ["--max-poles", "0"],
        ] {
            let mut a: Vec<&str> = zero.to_vec();
            a.extend(args.iter().map(String::as_str));
            let o = nurbsx(&a);
            assert_exit(&o, 2);
            assert!(
                stderr(&o).contains("must be at least 1"),
                "{a:?}: {}",
                stderr(&o)
            );
        }
        let o = Command::new(BIN)
            .args(&args)
            .env("NURBSX_MAX_DEGREE", "0")
            .output()
            .unwrap();
        assert_exit(&o, 2);
    }
}

#[test]
fn a_limit_error_is_a_limit_error_in_every_command() {
    // The circle has degree 3: with --max-degree 2 its only entity is refused.
    let dir = temp_dir("limit-all");
    let step = data("curve_circle_nurbs.step");
    for args in every_reading_command(step.to_str().unwrap(), &dir) {
        let mut a = vec!["--max-degree", "2"];
        a.extend(args.iter().map(String::as_str));
        let o = nurbsx(&a);
        assert_exit(&o, 1);
        assert_eq!(error_code(&o), "limit.degree", "{a:?}");
        assert_eq!(
            stderr(&o).matches("error[limit.degree]").count(),
            1,
            "{a:?}: once: {}",
            stderr(&o)
        );
    }
    // The input-size limit too.
    for args in every_reading_command(step.to_str().unwrap(), &dir) {
        let mut a = vec!["--max-input-bytes", "100"];
        a.extend(args.iter().map(String::as_str));
        let o = nurbsx(&a);
        assert_exit(&o, 1);
        assert_eq!(error_code(&o), "limit.input_bytes", "{a:?}");
    }
}

#[test]
fn domain_errors_are_usage_errors_in_the_users_terms() {
    let dir = temp_dir("domain");
    let c = data("circle.json");
    let c = c.to_str().unwrap();
    let out = dir.join("k.json");
    let out = out.to_str().unwrap();
    let o = nurbsx(["evaluate", c, "--at", "100"]);
    assert_exit(&o, 2);
    assert_eq!(error_code(&o), "evaluate.domain");
    let o = nurbsx(["insert-knot", c, "-o", out, "--at", "100"]);
    assert_exit(&o, 2);
    assert_eq!(error_code(&o), "insert_knot.domain");
    assert!(
        stderr(&o).contains("knot 100 is outside the domain [0, 1]"),
        "{}",
        stderr(&o)
    );
    // Too often: named in terms of the command line, not of library functions.
    let o = nurbsx(["insert-knot", c, "-o", out, "--at", "0.5", "--times", "5"]);
    assert_exit(&o, 2);
    assert_eq!(error_code(&o), "insert_knot.multiplicity");
    assert!(!stderr(&o).contains("clamp_start"), "{}", stderr(&o));
    let o = nurbsx(["insert-knot", c, "-o", out, "--at", "0"]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("already clamped"), "{}", stderr(&o));
    assert!(!out_exists(out));
    // --direction offers only what it accepts.
    let help = stdout(&nurbsx(["insert-knot", "--help"]));
    let line = help.lines().find(|l| l.contains("--direction")).unwrap();
    assert!(!help.contains("both"), "{line}\n{help}");
    assert_exit(
        &nurbsx([
            "insert-knot",
            c,
            "-o",
            out,
            "--at",
            "0.5",
            "--direction",
            "both",
        ]),
        2,
    );
}

fn out_exists(p: &str) -> bool {
    Path::new(p).exists()
}

#[test]
fn evaluate_snaps_parameters_within_a_few_ulps_of_the_domain_ends() {
    let c = data("circle.json");
    let c = c.to_str().unwrap();
    // 1 + 1 ulp and -1e-17 (what a + (b - a) * t computes for t = 1 or 0 in bad cases).
    let above = f64::from_bits(1.0f64.to_bits() + 1);
    let o = nurbsx([
        "evaluate",
        c,
        "--json",
        "--at",
        &format!("{above:e}"),
        "--at",
        "-1e-17",
    ]);
    assert_exit(&o, 0);
    let r = json(&o);
    let p1 = floats(&r["results"][0]["point"]);
    let p0 = floats(&r["results"][1]["point"]);
    // The ends of the unit circle, by the independent Bernstein form.
    for (p, u) in [(p1, 1.0f64), (p0, 0.0)] {
        let q = circle_by_bernstein(u.min(0.999_999_999_999_999_9));
        assert!(
            (p[0] - q[0]).abs() < 1e-12 && (p[1] - q[1]).abs() < 1e-12,
            "{p:?} {q:?}"
        );
    }
    // Further out is still refused.
    let o = nurbsx(["evaluate", c, "--at", "1.000000001"]);
    assert_exit(&o, 2);
    assert_eq!(error_code(&o), "evaluate.domain");
}

#[test]
fn convert_verify_before_the_input_is_a_flag_not_a_tolerance() {
    let dir = temp_dir("verify-flag");
    let out = dir.join("c.igs");
    let step = data("curve_circle_nurbs.step");
    let o = nurbsx([
        "convert",
        "--verify",
        step.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains("verified 1 written entities"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("(tolerance 1e-9)"));
    let o = nurbsx([
        "convert",
        step.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--verify=1e-12",
    ]);
    assert_exit(&o, 0);
    assert!(stderr(&o).contains("(tolerance 1e-12)"), "{}", stderr(&o));
}

#[test]
fn files_without_b_splines_are_a_warning_in_convert_and_validate_alike() {
    let dir = temp_dir("no-bspline");
    let f = dir.join("points.step");
    std::fs::write(
        &f,
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\n\
         FILE_NAME('x','2000-01-01T00:00:00',('x'),('x'),'x','x','x');\n\
         FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n\
         #1 = CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n",
    )
    .unwrap();
    let f = f.to_str().unwrap();
    let out = dir.join("points.igs");
    let o = nurbsx(["convert", f, "-o", out.to_str().unwrap()]);
    assert_exit(&o, 0);
    assert!(!out.exists(), "nothing written");
    let convert_line = stderr(&o)
        .lines()
        .find(|l| l.contains("warning[no_bspline]"))
        .unwrap_or_else(|| panic!("{}", stderr(&o)))
        .to_owned();
    let o = nurbsx(["validate", f]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains(&convert_line),
        "same message:\n{}",
        stderr(&o)
    );
    assert!(stdout(&o).contains("valid (0 entities"));
    // In a batch it is not a failure either.
    let good = dir.join("good.step");
    std::fs::copy(data("curve_circle_nurbs.step"), &good).unwrap();
    let o = nurbsx([
        "convert",
        f,
        good.to_str().unwrap(),
        "--out-dir",
        dir.join("out").to_str().unwrap(),
        "--to",
        "iges",
    ]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains("converted 1 of 2 files")
            && stderr(&o).contains("1 without B-spline entities"),
        "{}",
        stderr(&o)
    );
}

// ---------------------------------------------------------------------------------------
// Batch collisions, content against extension, SARIF, nothing dropped in silence

#[test]
fn batch_name_collisions_are_errors_unless_a_policy_is_given() {
    let dir = temp_dir("collide");
    let a = dir.join("x.igs");
    let b = dir.join("x.step");
    std::fs::copy(data("curve_circle_nurbs.igs"), &a).unwrap();
    std::fs::copy(data("curve_circle_nurbs.step"), &b).unwrap();
    let out = dir.join("out");
    let run = |policy: Option<&str>| {
        let mut args = vec![
            "convert".to_owned(),
            a.to_str().unwrap().to_owned(),
            b.to_str().unwrap().to_owned(),
            "--out-dir".to_owned(),
            out.to_str().unwrap().to_owned(),
            "--to".to_owned(),
            "step".to_owned(),
        ];
        if let Some(p) = policy {
            args.push("--on-collision".to_owned());
            args.push(p.to_owned());
        }
        nurbsx(&args)
    };
    let o = run(None);
    assert_exit(&o, 2);
    assert!(
        stderr(&o).contains("x.igs")
            && stderr(&o).contains("x.step")
            && stderr(&o).contains("--on-collision"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "nothing converted");
    let o = run(Some("rename"));
    assert_exit(&o, 0);
    assert!(out.join("x.step").is_file() && out.join("x-2.step").is_file());
    assert!(
        stderr(&o).contains("warning[batch.collision]"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&out).unwrap();
    let o = run(Some("overwrite"));
    assert_exit(&o, 0);
    assert!(out.join("x.step").is_file() && !out.join("x-2.step").exists());
    assert!(
        stderr(&o).contains("warning[batch.collision]"),
        "{}",
        stderr(&o)
    );
    assert!(
        stderr(&o).contains("converted 1 of 1 files"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn batch_warns_when_content_contradicts_the_extension() {
    let dir = temp_dir("batch-ext");
    let f = misnamed_circle(&dir);
    let o = nurbsx([
        "convert",
        f.to_str().unwrap(),
        "--out-dir",
        dir.join("out").to_str().unwrap(),
        "--to",
        "iges",
    ]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o)
            .contains("warning[format.extension]: the extension says IGES but the content is STEP"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn sarif_names_the_tool_honestly_and_describes_its_rules() {
    let o = nurbsx([
        "validate",
        "--format",
        "sarif",
        data("bad_knots.json").to_str().unwrap(),
    ]);
    let doc = json(&o);
    let driver = &doc["runs"][0]["tool"]["driver"];
    // informationUri is Cargo.toml's `repository` when one is set (none while the project
    // has no public home), never a made-up home page.
    let repo = env!("CARGO_PKG_REPOSITORY");
    match driver.get("informationUri") {
        Some(uri) => {
            assert_eq!(uri, repo);
            assert!(!repo.contains(".invalid") && !repo.contains("example."));
        }
        None => assert!(repo.contains(".invalid") || repo.contains("example.") || repo.is_empty()),
    }
    assert!(!doc.to_string().contains("example.invalid"));
    let rules = driver["rules"].as_array().unwrap();
    assert!(!rules.is_empty());
    for r in rules {
        let text = r["shortDescription"]["text"].as_str().unwrap();
        assert!(!text.starts_with("nurbsx diagnostic"), "{text}");
        assert!(text.ends_with('.') && text.len() > 20, "a sentence: {text}");
    }
    let geometry = rules
        .iter()
        .find(|r| r["id"] == "geometry.invalid")
        .unwrap();
    assert!(
        geometry["shortDescription"]["text"]
            .as_str()
            .unwrap()
            .contains("B-spline curve or surface is invalid")
    );
}

#[test]
fn modify_commands_say_what_they_leave_out() {
    // The filleted box: 26 faces over 26 surfaces, 48 3-D edge curves, and 96 coedges whose
    // pcurves the reader computes on the faces' NURBS surfaces (the file's own 96 PCURVE
    // curves are not separate entities then). `convert` carries the faces, pcurves included
    // (IGES 144 with 142 boundaries); the operations work on loose curves and surfaces, so
    // they say that the faces, edges and pcurves are not carried.
    let dir = temp_dir("left-out");
    let step =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/brep_filleted_box_nurbs.step");
    let step = step.to_str().unwrap();
    let out = dir.join("faces.igs");
    let o = nurbsx(["convert", step, "-o", out.to_str().unwrap()]);
    assert_exit(&o, 0);
    assert!(!stderr(&o).contains("pcurve_not_written"), "{}", stderr(&o));
    let info = json(&nurbsx(["info", out.to_str().unwrap(), "--json"]));
    assert_eq!(info["structure"]["faces"].as_array().unwrap().len(), 26);
    assert_eq!(info["structure"]["solids"].as_array().unwrap().len(), 1);
    for args in [
        vec!["elevate", step, "--by", "1"],
        vec!["clamp", step],
        vec!["unclamp", step],
    ] {
        let out = dir.join(format!("{}.igs", args[0]));
        let mut a = args.clone();
        a.extend(["-o", out.to_str().unwrap()]);
        let o = nurbsx(&a);
        assert_exit(&o, 0);
        let err = stderr(&o);
        assert!(
            err.contains("warning[topology.dropped]")
                && err.contains("26 face(s), 48 edge(s), 96 coedge pcurve(s))"),
            "{args:?}: {err}"
        );
        assert!(!err.contains("pcurve_not_written"), "{args:?}: {err}");
        assert!(
            err.contains("read 74 curves and surfaces, wrote 74 as IGES"),
            "{args:?}: {err}"
        );
        // The file holds what the summary says: 26 surfaces and 48 curves.
        let info = json(&nurbsx(["info", out.to_str().unwrap(), "--json"]));
        let entities = info["entities"].as_array().unwrap();
        assert_eq!(entities.len(), 74);
        assert_eq!(
            entities.iter().filter(|e| e["kind"] == "surface").count(),
            26
        );
        assert!(entities.iter().all(|e| e["dimension"] == 3));
    }
    let out = dir.join("box.step");
    let o = nurbsx(["clamp", step, "-o", out.to_str().unwrap()]);
    assert_exit(&o, 0);
    assert!(stderr(&o).contains("warning[topology.dropped]"));
    assert!(stderr(&o).contains("wrote 74 as STEP"), "{}", stderr(&o));
    // Read as geometry only, the file's 96 PCURVE curves are loose 2-D curves: IGES has no
    // place for them outside a trimmed surface (said, and counted as left out); STEP keeps
    // them, with nothing to say.
    let geometry_only = |ext: &str| {
        let out = dir.join(format!("geometry.{ext}"));
        let o = nurbsx([
            "convert",
            step,
            "--geometry-only",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_exit(&o, 0);
        stderr(&o)
    };
    let err = geometry_only("igs");
    assert!(
        err.contains("warning[pcurve_not_written]: 96 2-D parameter-space curve(s) not written"),
        "{err}"
    );
    assert!(
        err.contains("read 170 curves and surfaces, wrote 74 as IGES, left out 96"),
        "{err}"
    );
    let err = geometry_only("step");
    assert!(!err.contains("pcurve_not_written"));
    assert!(err.contains("wrote 170 as STEP"), "{err}");
}

// ---------------------------------------------------------------------------------------
// Meshes and pictures

/// `nurbsx tessellate IN -o OUT --tolerance TOL`.
fn tessellate_to(input: &Path, out: &Path, tolerance: &str) -> Output {
    nurbsx([
        "tessellate".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--tolerance".as_ref(),
        std::ffi::OsStr::new(tolerance),
    ])
}

/// The triangles of a binary STL, read by the format's definition (80-byte header, count,
/// 50 bytes per triangle: normal, three vertices, attribute).
fn read_stl(bytes: &[u8]) -> Vec<[[f32; 3]; 3]> {
    let count = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(bytes.len(), 84 + 50 * count, "STL size");
    (0..count)
        .map(|i| {
            let t = &bytes[84 + 50 * i..];
            let f = |k: usize| f32::from_le_bytes(t[4 * k..4 * k + 4].try_into().unwrap());
            [[f(3), f(4), f(5)], [f(6), f(7), f(8)], [f(9), f(10), f(11)]]
        })
        .collect()
}

/// Checks a triangle soup is a closed surface: every edge (by its end points) belongs to
/// exactly two triangles, in opposite directions (consistent orientation), and no triangle
/// has zero area.
#[track_caller]
fn assert_watertight(triangles: &[[[f32; 3]; 3]]) {
    use std::collections::HashMap;
    assert!(!triangles.is_empty());
    let key = |p: [f32; 3]| p.map(f32::to_bits);
    let mut edges: HashMap<([u32; 3], [u32; 3]), usize> = HashMap::new();
    for t in triangles {
        let (a, b, c) = (t[0], t[1], t[2]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        assert!(n.iter().any(|&x| x != 0.0), "zero-area triangle {t:?}");
        for (p, q) in [(a, b), (b, c), (c, a)] {
            *edges.entry((key(p), key(q))).or_default() += 1;
        }
    }
    for (&(p, q), &n) in &edges {
        assert_eq!(n, 1, "directed edge used {n} times");
        assert_eq!(
            edges.get(&(q, p)),
            Some(&1),
            "edge {p:?}-{q:?} has no opposite"
        );
    }
}

#[test]
fn meshes_of_closed_samples_are_watertight_in_stl_and_gltf() {
    let dir = temp_dir("watertight");
    let samples = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad");
    for name in ["surf_sphere_nurbs", "surf_torus_nurbs"] {
        let input = samples.join(format!("{name}.step"));
        let stl = dir.join(format!("{name}.stl"));
        let o = tessellate_to(&input, &stl, "0.05");
        assert_exit(&o, 0);
        let triangles = read_stl(&std::fs::read(&stl).unwrap());
        assert_watertight(&triangles);
        // glTF 2.0 binary: header, JSON chunk, BIN chunk; the indexed mesh is the same.
        let glb = dir.join(format!("{name}.glb"));
        let o = tessellate_to(&input, &glb, "0.05");
        assert_exit(&o, 0);
        let bytes = std::fs::read(&glb).unwrap();
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        assert_eq!(&bytes[0..4], b"glTF");
        assert_eq!(word(4), 2, "glTF version");
        assert_eq!(word(8), bytes.len());
        let json_len = word(12);
        assert_eq!(&bytes[16..20], b"JSON");
        assert_eq!(json_len % 4, 0);
        let doc: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        let bin_at = 20 + json_len;
        assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
        let bin = &bytes[bin_at + 8..bin_at + 8 + word(bin_at)];
        assert_eq!(doc["asset"]["version"], "2.0");
        assert_eq!(
            doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize,
            bin.len()
        );
        let prim = &doc["meshes"][0]["primitives"][0];
        assert_eq!(prim["mode"], 4);
        let accessor = |i: &Value| &doc["accessors"][i.as_u64().unwrap() as usize];
        let view_of = |a: &Value| {
            let v = &doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
            let off = v["byteOffset"].as_u64().unwrap() as usize;
            &bin[off..off + v["byteLength"].as_u64().unwrap() as usize]
        };
        let pos = accessor(&prim["attributes"]["POSITION"]);
        let idx = accessor(&prim["indices"]);
        assert_eq!(pos["componentType"], 5126);
        assert_eq!(idx["componentType"], 5125);
        let f32s: Vec<f32> = view_of(pos)
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let points: Vec<[f32; 3]> = f32s.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        assert_eq!(points.len() as u64, pos["count"].as_u64().unwrap());
        for k in 0..3 {
            let lo = points.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min);
            let hi = points
                .iter()
                .map(|p| p[k])
                .fold(f32::NEG_INFINITY, f32::max);
            assert_eq!(pos["min"][k].as_f64().unwrap() as f32, lo);
            assert_eq!(pos["max"][k].as_f64().unwrap() as f32, hi);
        }
        let indices: Vec<usize> = view_of(idx)
            .chunks(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()) as usize)
            .collect();
        // Welded: no two vertices at the same place.
        let distinct: std::collections::HashSet<[u32; 3]> =
            points.iter().map(|p| p.map(f32::to_bits)).collect();
        assert_eq!(distinct.len(), points.len(), "{name}: vertices welded");
        let from_gltf: Vec<[[f32; 3]; 3]> = indices
            .chunks(3)
            .map(|t| [points[t[0]], points[t[1]], points[t[2]]])
            .collect();
        assert_watertight(&from_gltf);
        assert_eq!(from_gltf.len(), triangles.len());
    }
}

#[test]
fn three_d_outputs_leave_out_parameter_space_curves_with_a_warning() {
    let dir = temp_dir("mesh-pcurves");
    let step =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/brep_filleted_box_nurbs.step");
    // Read as geometry only, the box's 96 PCURVE curves are loose 2-D curves: a 3-D output
    // cannot draw them and says so.
    let loose = dir.join("loose.step");
    let o = nurbsx([
        "convert".as_ref(),
        step.as_os_str(),
        "--geometry-only".as_ref(),
        "-o".as_ref(),
        loose.as_os_str(),
    ]);
    assert_exit(&o, 0);
    for ext in ["obj", "glb", "svg"] {
        let o = tessellate_to(&loose, &dir.join(format!("loose.{ext}")), "0.1");
        assert_exit(&o, 0);
        assert!(
            stderr(&o).contains("warning[pcurve_not_written]: 96 curve(s) not drawn"),
            "{ext}: {}",
            stderr(&o)
        );
    }
    // The part itself: its faces are trimmed by their coedges' pcurves, so no curve is
    // left out.
    for ext in ["obj", "glb", "svg"] {
        let out = dir.join(format!("box.{ext}"));
        let o = tessellate_to(&step, &out, "0.1");
        assert_exit(&o, 0);
        assert!(
            !stderr(&o).contains("pcurve_not_written"),
            "{ext}: {}",
            stderr(&o)
        );
        assert!(
            // The part is drawn as its faces (trimmed) and edges: the 26 B-spline
            // surfaces and 48 curves, named by face and edge ids.
            stderr(&o).contains(
                "drew 74 item(s): 26 trimmed face(s), 48 edge(s), 0 free curve(s) and surface(s)"
            ),
            "{}",
            stderr(&o)
        );
    }
    let obj = std::fs::read_to_string(dir.join("box.obj")).unwrap();
    assert_eq!(obj.lines().filter(|l| l.starts_with("o ")).count(), 74);
    // #37 is the first pcurve of the box.
    assert!(!obj.lines().any(|l| l == "o #37"));
    // STL holds no curves: the 48 edges are named as left out.
    let o = tessellate_to(&step, &dir.join("box.stl"), "0.1");
    assert!(
        stderr(&o).contains("warning[curve_not_written]: 48 curve(s) not drawn"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn svg_and_png_pictures_have_a_frame_a_scale_and_labels() {
    let dir = temp_dir("pictures");
    let step =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/brep_filleted_box_nurbs.step");
    let svg = dir.join("box.svg");
    let o = tessellate_to(&step, &svg, "0.1");
    assert_exit(&o, 0);
    let text = std::fs::read_to_string(&svg).unwrap();
    let tags = check_xml(&text);
    assert_eq!(tags[0].0, "svg");
    assert!(text.contains("isometric view"));
    // One label per entity seen, a caption counting the entities hidden behind faces (the
    // box's back faces and edges), and a scale bar in the file's unit.
    let labels = tags.iter().filter(|(n, _)| n == "text").count();
    let hidden: usize = text
        .split(" hidden entities not labelled</text>")
        .next()
        .and_then(|h| h.rsplit('>').next())
        .and_then(|n| n.parse().ok())
        .expect("a caption counting the hidden entities");
    assert!(hidden > 0 && hidden < 74, "{hidden} hidden");
    assert_eq!(
        labels,
        (74 - hidden) + 3,
        "a label per visible entity, the caption, the title and the scale"
    );
    assert!(text.contains(" mm</text>"), "scale bar in mm");
    // One palette colour per entity (26 surfaces cycle through all 10 of Tableau 10):
    // shading scales a colour, so each fill points in the direction of its palette entry.
    let palette: [[f64; 3]; 10] = [
        [31.0, 119.0, 180.0],
        [255.0, 127.0, 14.0],
        [44.0, 160.0, 44.0],
        [214.0, 39.0, 40.0],
        [148.0, 103.0, 189.0],
        [140.0, 86.0, 75.0],
        [227.0, 119.0, 194.0],
        [127.0, 127.0, 127.0],
        [188.0, 189.0, 34.0],
        [23.0, 190.0, 207.0],
    ];
    let mut used = std::collections::BTreeSet::new();
    for fill in text.split("<polygon").skip(1).map(polygon_fill) {
        let (best, c) = palette
            .iter()
            .enumerate()
            .map(|(i, q)| (i, cosine(fill, *q)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        assert!(
            c > 0.999,
            "fill {fill:?} is a shade of a palette colour ({c})"
        );
        used.insert(best);
    }
    assert_eq!(used.len(), 10, "{used:?}");
    // A plane curve set: top view, inside the frame (no clipping), 2 px lines in pixel
    // coordinates (no scaled viewBox).
    let set = dir.join("set.json");
    let circle = std::fs::read_to_string(data("circle.json")).unwrap();
    std::fs::write(
        &set,
        format!(
            "[{circle}, {{\"degree\": 1, \"knots\": [0, 0, 1, 1], \"control_points\": [[-1, -1], [3, 1]]}}]"
        ),
    )
    .unwrap();
    let curves = dir.join("set.svg");
    let o = tessellate_to(&set, &curves, "0.001");
    assert_exit(&o, 0);
    let text = std::fs::read_to_string(&curves).unwrap();
    assert!(text.contains("top view (XY)"), "{text}");
    let (width, height) = (svg_attr(&text, "width"), svg_attr(&text, "height"));
    assert!(text.contains(&format!("viewBox=\"0 0 {width} {height}\"")));
    let segments: Vec<[f64; 4]> = text
        .split("<line ")
        .skip(1)
        .map(|l| ["x1", "y1", "x2", "y2"].map(|n| svg_attr(l, n)))
        .collect();
    assert!(
        segments.len() > 70,
        "the circle within 1e-3 needs 71 segments or more"
    );
    for [x1, y1, x2, y2] in &segments {
        for (x, y) in [(x1, y1), (x2, y2)] {
            assert!(
                *x >= 24.0 && *x <= width - 24.0 && *y >= 24.0 && *y <= height - 24.0,
                "{x},{y}"
            );
        }
    }
    // The line from (-1, -1) to (3, 1) spans the width: x from the left margin to the right
    // one, and it rises to the right (y up in the model, down in SVG).
    let xs: Vec<f64> = segments.iter().flat_map(|s| [s[0], s[2]]).collect();
    let left = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let right = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        (left - 48.0).abs() < 1e-6 && (right - (width - 48.0)).abs() < 1e-6,
        "{left} {right}"
    );
    assert!(text.contains("stroke-width=\"2\""));
    // PNG: the same picture rasterised.
    let png = dir.join("box.png");
    let o = tessellate_to(&step, &png, "0.1");
    assert_exit(&o, 0);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let pixmap = resvg::tiny_skia::Pixmap::decode_png(&bytes).unwrap();
    assert_eq!(pixmap.width(), 800);
    let coloured = pixmap
        .pixels()
        .iter()
        .filter(|p| {
            let (r, g, b) = (p.red(), p.green(), p.blue());
            r.max(g).max(b) - r.min(g).min(b) > 40
        })
        .count();
    let share = coloured as f64 / f64::from(pixmap.width() * pixmap.height());
    assert!(share > 0.1, "the shaded part covers {share} of the picture");
}

/// The Khronos glTF validator (npm package `gltf-validator`) on the .glb of a closed surface
/// and of the filleted box (meshes and line strips): no error, warning or info. Needs Node
/// and the package: `npm install --prefix DIR gltf-validator`, then
/// `NURBSX_GLTF_VALIDATOR=DIR/node_modules cargo test --test cli -- --ignored gltf`.
#[test]
#[ignore = "needs Node.js and the npm package gltf-validator (NURBSX_GLTF_VALIDATOR)"]
fn gltf_output_passes_the_khronos_validator() {
    let modules = std::env::var("NURBSX_GLTF_VALIDATOR")
        .expect("NURBSX_GLTF_VALIDATOR=<node_modules folder holding gltf-validator>");
    let dir = temp_dir("gltf-validator");
    let script = dir.join("validate.js");
    std::fs::write(
        &script,
        "const v = require('gltf-validator');\n\
         const data = new Uint8Array(require('fs').readFileSync(process.argv[2]));\n\
         v.validateBytes(data).then(r => {\n\
           console.log(JSON.stringify(r.issues));\n\
           process.exit(r.issues.numErrors + r.issues.numWarnings + r.issues.numInfos === 0 ? 0 : 1);\n\
         }).catch(e => { console.error(e); process.exit(2); });\n",
    )
    .unwrap();
    let samples = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad");
    for name in ["surf_torus_nurbs", "brep_filleted_box_nurbs"] {
        let glb = dir.join(format!("{name}.glb"));
        let o = tessellate_to(&samples.join(format!("{name}.step")), &glb, "0.05");
        assert_exit(&o, 0);
        let checked = Command::new("node")
            .arg(&script)
            .arg(&glb)
            .env("NODE_PATH", &modules)
            .output()
            .unwrap();
        assert!(
            checked.status.success(),
            "{name}: {}{}",
            stdout(&checked),
            stderr(&checked)
        );
    }
}

#[test]
fn evaluate_text_is_aligned_columns_without_inline_json() {
    let o = nurbsx([
        "evaluate",
        data("circle.json").to_str().unwrap(),
        "--at",
        "0.125",
        "--at",
        "1e-17",
        "--derivatives",
        "2",
        "--curvature",
    ]);
    assert_exit(&o, 0);
    let text = stdout(&o);
    assert!(!text.contains(['{', '[', '"']), "no JSON:\n{text}");
    // Small numbers in exponent form, not 0.00000000000000001.
    assert!(text.lines().any(|l| l.starts_with("1e-17 ")), "{text}");
    assert!(!text.contains("0.0000000000"), "{text}");
    // The labelled lines: every number parses, and the columns end at the same place.
    // (The header of the table is right-aligned too: it starts with blanks and a `u`.)
    let extra: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("    ") && !l.trim_start().starts_with("u "))
        .collect();
    assert!(extra.iter().any(|l| l.trim_start().starts_with("d2 ")));
    let ends: std::collections::BTreeSet<usize> = extra
        .iter()
        .filter(|l| l.split_whitespace().count() == 3)
        .map(|l| l.len())
        .collect();
    assert_eq!(
        ends.len(),
        1,
        "two-value lines end in the same column:\n{text}"
    );
    for l in &extra {
        for cell in l.split_whitespace().skip(1) {
            assert!(cell.parse::<f64>().is_ok(), "{cell} in {l}");
        }
    }
    // The numbers are the JSON output's, exactly.
    let j = json(&nurbsx([
        "evaluate",
        data("circle.json").to_str().unwrap(),
        "--at",
        "0.125",
        "--derivatives",
        "2",
        "--json",
    ]));
    let d2 = floats(&j["results"][0]["derivatives"][1]);
    let line = extra
        .iter()
        .find(|l| l.trim_start().starts_with("d2 "))
        .unwrap();
    let cells: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(cells, d2);
}

/// Runs a command line on a pseudo-terminal (util-linux `script`), as a user at a terminal
/// would, and returns what the terminal showed.
fn on_terminal(command: &str, env: &[(&str, &str)]) -> String {
    let mut c = Command::new("script");
    c.args(["-qec", command, "/dev/null"])
        .env_remove("NO_COLOR")
        .env("TERM", "xterm-256color");
    for (k, v) in env {
        c.env(k, v);
    }
    let o = c
        .output()
        .expect("util-linux `script` runs the command on a terminal");
    stdout(&o)
}

#[test]
fn colour_is_on_by_default_on_a_terminal_only() {
    let bad = data("bad_knots.json");
    let command = format!("{BIN} validate {}", bad.display());
    let esc = "\u{1b}[";
    let shown = on_terminal(&command, &[]);
    assert!(shown.contains(esc), "coloured on a terminal: {shown:?}");
    assert!(shown.contains("error[geometry.invalid]"));
    let shown = on_terminal(&command, &[("NO_COLOR", "1")]);
    assert!(!shown.contains(esc), "NO_COLOR: {shown:?}");
    let shown = on_terminal(&format!("{command} --color never"), &[]);
    assert!(!shown.contains(esc), "--color never: {shown:?}");
    let shown = on_terminal(&format!("{BIN} help convert"), &[]);
    assert!(shown.contains(esc), "coloured help: {shown:?}");
}

/// A `w` x `w` square at height `z` with its corner at (`x`, `x`), made by `nurbsx make`
/// (a line extruded), as model JSON.
fn square(dir: &Path, name: &str, x: f64, z: f64, w: f64) -> Value {
    let line = dir.join(format!("{name}-line.json"));
    let surface = dir.join(format!("{name}.json"));
    let o = nurbsx([
        "make",
        "line",
        "--p0",
        &format!("{x},{x},{z}"),
        "--p1",
        &format!("{},{x},{z}", x + w),
        "-o",
        line.to_str().unwrap(),
    ]);
    assert_exit(&o, 0);
    let o = nurbsx([
        "make",
        "extrude",
        line.to_str().unwrap(),
        "--direction",
        &format!("0,{w},0"),
        "-o",
        surface.to_str().unwrap(),
    ]);
    assert_exit(&o, 0);
    serde_json::from_str(&std::fs::read_to_string(&surface).unwrap()).unwrap()
}

/// The number in attribute `name` of the first element in `s` that has one.
fn svg_attr(s: &str, name: &str) -> f64 {
    s.split(&format!("{name}=\""))
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

/// The labels of an SVG picture: (text, anchor x, anchor y) of the text elements that are
/// not the title, the scale or a caption.
fn picture_labels(svg: &str) -> Vec<(String, f64, f64)> {
    svg.split("<text")
        .skip(1)
        .filter(|t| t.contains("paint-order"))
        .map(|t| {
            let body = t.split('>').nth(1).unwrap().split('<').next().unwrap();
            (body.to_string(), svg_attr(t, "x"), svg_attr(t, "y"))
        })
        .collect()
}

/// The `fill="rgb(r,g,b)"` of an SVG polygon element's text.
fn polygon_fill(p: &str) -> [f64; 3] {
    let rgb = p
        .split("fill=\"rgb(")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap();
    let c: Vec<f64> = rgb.split(',').map(|v| v.parse().unwrap()).collect();
    [c[0], c[1], c[2]]
}

/// The cosine of the angle between two colours as vectors: a shade of a colour (the colour
/// scaled) has cosine 1 with it.
fn cosine(a: [f64; 3], b: [f64; 3]) -> f64 {
    let n = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    (0..3).map(|k| a[k] * b[k]).sum::<f64>() / (n(a) * n(b))
}

/// The fill of the last-drawn polygon (painter's order: the one seen) that covers (x, y).
fn fill_seen_at(svg: &str, x: f64, y: f64) -> Option<[f64; 3]> {
    let mut seen = None;
    for p in svg.split("<polygon").skip(1) {
        let corners: Vec<(f64, f64)> = p
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .split_whitespace()
            .map(|xy| {
                let (a, b) = xy.split_once(',').unwrap();
                (a.parse().unwrap(), b.parse().unwrap())
            })
            .collect();
        let side = |a: (f64, f64), b: (f64, f64)| (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0);
        let s: Vec<f64> = (0..3)
            .map(|k| side(corners[k], corners[(k + 1) % 3]))
            .collect();
        if s.iter().all(|&v| v >= 0.0) || s.iter().all(|&v| v <= 0.0) {
            seen = Some(polygon_fill(p));
        }
    }
    seen
}

#[test]
fn pictures_label_only_what_is_seen() {
    let dir = temp_dir("hidden-labels");
    let small = square(&dir, "small", 0.0, 0.0, 1.0);
    // Seen along -(1, 1, 1), the big square one unit above covers the small one entirely:
    // a point (x, y, 0) projects where (x + 1, y + 1, 1) does.
    let over = square(&dir, "over", -5.0, 1.0, 10.0);
    let under = square(&dir, "under", -5.0, -1.0, 10.0);
    let picture = |name: &str, pair: [&Value; 2]| {
        let set = dir.join(format!("{name}.json"));
        std::fs::write(&set, serde_json::to_string(&pair).unwrap()).unwrap();
        let svg = dir.join(format!("{name}.svg"));
        let o = tessellate_to(&set, &svg, "0.01");
        assert_exit(&o, 0);
        std::fs::read_to_string(&svg).unwrap()
    };
    // Entity 0 (blue, the first palette colour) hidden under entity 1 (orange).
    let text = picture("covered", [&small, &over]);
    assert!(text.contains("isometric view"), "{text}");
    let labels = picture_labels(&text);
    let names: Vec<&str> = labels.iter().map(|l| l.0.as_str()).collect();
    assert_eq!(names, ["1"], "only the front square is labelled");
    assert!(
        text.contains(">1 hidden entity not labelled</text>"),
        "{text}"
    );
    // The small square in front of the big one: both seen, each label on its own colour
    // (the big square's label not over the small one), and no caption.
    let text = picture("in_front", [&small, &under]);
    let labels = picture_labels(&text);
    assert_eq!(labels.len(), 2, "{labels:?}");
    assert!(!text.contains("hidden entit"));
    let orange = [255.0, 127.0, 14.0];
    let blue = [31.0, 119.0, 180.0];
    for (name, x, y) in &labels {
        // The label's text starts 3 px right of and 3 px above its point.
        let fill = fill_seen_at(&text, x - 3.0, y + 3.0).unwrap();
        let want = if name == "0" { blue } else { orange };
        assert!(cosine(fill, want) > 0.999, "label {name} sits on {fill:?}");
    }
}

#[test]
fn the_picture_of_a_sphere_has_its_silhouette_on_the_projected_circle() {
    // Orthographic: a sphere projects to a disc whatever the view. The picture maps the
    // disc's diameter to the 704 px between the margins, so the silhouette is a circle of
    // radius 352 px around the middle of the drawing.
    let dir = temp_dir("silhouette");
    let svg = dir.join("sphere.svg");
    let sphere =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/surf_sphere_nurbs.step");
    let o = tessellate_to(&sphere, &svg, "0.01");
    assert_exit(&o, 0);
    let text = std::fs::read_to_string(&svg).unwrap();
    let height = svg_attr(&text, "height");
    let (cx, cy) = (400.0, height / 2.0);
    let outline: Vec<&str> = text
        .split("<line ")
        .skip(1)
        .filter(|l| l.contains("stroke=\"#303030\""))
        .collect();
    assert!(outline.len() > 40, "{} outline segments", outline.len());
    for l in &outline {
        for (x, y) in [
            (svg_attr(l, "x1"), svg_attr(l, "y1")),
            (svg_attr(l, "x2"), svg_attr(l, "y2")),
        ] {
            let r = ((x - cx).powi(2) + (y - cy).powi(2)).sqrt();
            assert!(
                r > 0.97 * 352.0 && r < 352.5,
                "silhouette point at radius {r}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// The geometric operations on the command line

/// Evaluates `file` (model JSON) at `u` with `nurbsx evaluate --json`.
fn point_of(file: &Path, u: f64) -> Vec<f64> {
    let o = nurbsx([
        "evaluate".as_ref(),
        file.as_os_str(),
        "--at".as_ref(),
        format!("{u}").as_ref(),
        "--json".as_ref(),
    ]);
    assert_exit(&o, 0);
    floats(&json(&o)["results"][0]["point"])
}

#[test]
fn reduce_prints_the_bound_and_gives_back_the_circle() {
    let dir = temp_dir("reduce");
    let (up, down) = (dir.join("up.json"), dir.join("down.json"));
    let circle = data("circle.json");
    assert_exit(
        &nurbsx([
            "elevate".as_ref(),
            circle.as_os_str(),
            "-o".as_ref(),
            up.as_os_str(),
            "--by".as_ref(),
            "1".as_ref(),
        ]),
        0,
    );
    let o = nurbsx([
        "reduce".as_ref(),
        up.as_os_str(),
        "-o".as_ref(),
        down.as_os_str(),
        "--tolerance".as_ref(),
        "1e-9".as_ref(),
    ]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains("degree 3 -> 2, deviation at most"),
        "{}",
        stderr(&o)
    );
    for u in [0.1, 0.37, 0.8] {
        let p = point_of(&down, u);
        let want = circle_by_bernstein(u);
        assert!((p[0] - want[0]).abs() < 1e-12 && (p[1] - want[1]).abs() < 1e-12);
    }
    // The circle is no quadratic polynomial... nor a reducible one: refused, exit 1.
    let o = nurbsx([
        "reduce".as_ref(),
        circle.as_os_str(),
        "-o".as_ref(),
        down.as_os_str(),
        "--tolerance".as_ref(),
        "1e-6".as_ref(),
    ]);
    assert_exit(&o, 1);
}

#[test]
fn transform_split_reverse_and_join_move_the_circle_as_asked() {
    let dir = temp_dir("ops");
    let circle = data("circle.json");
    let moved = dir.join("moved.json");
    let o = nurbsx([
        "transform".as_ref(),
        circle.as_os_str(),
        "-o".as_ref(),
        moved.as_os_str(),
        "--scale".as_ref(),
        "2".as_ref(),
        "--rotate".as_ref(),
        "0,0,1,180".as_ref(),
        "--translate".as_ref(),
        "1,0,0".as_ref(),
    ]);
    assert_exit(&o, 0);
    for u in [0.0, 0.3, 0.55] {
        let p = point_of(&moved, u);
        let q = circle_by_bernstein(u);
        // Scale 2, half turn about z, then x + 1: (x, y) -> (1 - 2x, -2y).
        assert!((p[0] - (1.0 - 2.0 * q[0])).abs() < 1e-12, "{p:?}");
        assert!((p[1] + 2.0 * q[1]).abs() < 1e-12, "{p:?}");
    }
    let halves = dir.join("halves.json");
    let o = nurbsx([
        "split".as_ref(),
        circle.as_os_str(),
        "-o".as_ref(),
        halves.as_os_str(),
        "--at".as_ref(),
        "0.4".as_ref(),
    ]);
    assert_exit(&o, 0);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&halves).unwrap()).unwrap();
    assert_eq!(v.as_array().map(Vec::len), Some(2), "{v}");
    let joined = dir.join("joined.json");
    assert_exit(
        &nurbsx([
            "join".as_ref(),
            halves.as_os_str(),
            "-o".as_ref(),
            joined.as_os_str(),
        ]),
        0,
    );
    let reversed = dir.join("reversed.json");
    assert_exit(
        &nurbsx([
            "reverse".as_ref(),
            joined.as_os_str(),
            "-o".as_ref(),
            reversed.as_os_str(),
        ]),
        0,
    );
    for u in [0.1, 0.4, 0.9] {
        let p = point_of(&reversed, u);
        let want = circle_by_bernstein(1.0 - u);
        assert!((p[0] - want[0]).abs() < 1e-12 && (p[1] - want[1]).abs() < 1e-12);
    }
    // One curve cannot be joined (usage, exit 2); --matrix needs 12 numbers.
    let one = nurbsx([
        "join".as_ref(),
        circle.as_os_str(),
        "-o".as_ref(),
        joined.as_os_str(),
    ]);
    assert_exit(&one, 2);
    let bad = nurbsx([
        "transform".as_ref(),
        circle.as_os_str(),
        "-o".as_ref(),
        moved.as_os_str(),
        "--matrix".as_ref(),
        "1,0,0".as_ref(),
    ]);
    assert_exit(&bad, 2);
}

#[test]
fn reparameterize_maps_the_domain() {
    let dir = temp_dir("reparam");
    let out = dir.join("r.json");
    let circle = data("circle.json");
    let o = nurbsx([
        "reparameterize".as_ref(),
        circle.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--to".as_ref(),
        "-1,3".as_ref(),
    ]);
    assert_exit(&o, 0);
    for s in [-1.0, 0.2, 2.5] {
        let p = point_of(&out, s);
        let want = circle_by_bernstein((s + 1.0) / 4.0);
        assert!((p[0] - want[0]).abs() < 1e-12 && (p[1] - want[1]).abs() < 1e-12);
    }
}

#[test]
fn make_writes_a_circle_on_its_radius_and_refuses_missing_numbers() {
    let dir = temp_dir("make");
    let out = dir.join("c.json");
    let o = nurbsx([
        "make".as_ref(),
        "circle".as_ref(),
        "--radius".as_ref(),
        "3".as_ref(),
        "--axis".as_ref(),
        "0,1,0".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_exit(&o, 0);
    // Angle parameter: a full turn on [0, 2 pi], in the plane y = 0.
    for k in 0..16 {
        let t = std::f64::consts::TAU * f64::from(k) / 16.0;
        let p = point_of(&out, t);
        assert!((p[0].hypot(p[2]) - 3.0).abs() <= 3e-15, "{p:?}");
        assert!(p[1].abs() <= 1e-15, "{p:?}");
    }
    let step = dir.join("s.step");
    let o = nurbsx([
        "make".as_ref(),
        "cone".as_ref(),
        "--radius".as_ref(),
        "2".as_ref(),
        "--semi-angle".as_ref(),
        "30".as_ref(),
        "--height".as_ref(),
        "4".as_ref(),
        "-o".as_ref(),
        step.as_os_str(),
    ]);
    assert_exit(&o, 0);
    assert!(
        std::fs::read_to_string(&step)
            .unwrap()
            .contains("B_SPLINE_SURFACE")
    );
    let o = nurbsx([
        "make".as_ref(),
        "sphere".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("`radius`"), "{}", stderr(&o));
}

#[test]
fn fit_passes_through_the_points_of_a_text_file() {
    let dir = temp_dir("fit");
    let points = dir.join("p.csv");
    // A helix sampled at 30 points.
    let q: Vec<[f64; 3]> = (0..30)
        .map(|k| {
            let t = f64::from(k) * 0.4;
            [t.cos(), t.sin(), 0.1 * t]
        })
        .collect();
    let text: String = q
        .iter()
        .map(|p| format!("{},{},{}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(&points, format!("# x,y,z\n{text}")).unwrap();
    let out = dir.join("c.json");
    let o = nurbsx([
        "fit".as_ref(),
        points.as_os_str(),
        "--degree".as_ref(),
        "4".as_ref(),
        "--params".as_ref(),
        "uniform".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_exit(&o, 0);
    // Uniform parameters: point k at k / 29.
    for (k, p) in q.iter().enumerate() {
        let got = point_of(&out, k as f64 / 29.0);
        assert!(
            (0..3).all(|i| (got[i] - p[i]).abs() < 1e-12 * 4.0),
            "{k}: {got:?} vs {p:?}"
        );
    }
    std::fs::write(&points, "0,0\n1,x\n").unwrap();
    assert_exit(
        &nurbsx([
            "fit".as_ref(),
            points.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ]),
        2,
    );
}

/// A fit of 2-D points is a 2-D curve, which IGES model space cannot hold: the output
/// warns and is refused (no empty file, exit 2); STEP and model JSON hold it.
#[test]
fn fit_says_what_the_output_format_cannot_hold() {
    let dir = temp_dir("fit-2d");
    let points = dir.join("p.csv");
    std::fs::write(&points, "0,0\n1,1\n2,0\n3,1\n").unwrap();
    let iges = dir.join("c.igs");
    let o = nurbsx([
        "fit".as_ref(),
        points.as_os_str(),
        "-o".as_ref(),
        iges.as_os_str(),
    ]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("pcurve_not_written"), "{}", stderr(&o));
    assert!(stderr(&o).contains("--to step"), "{}", stderr(&o));
    assert!(!iges.exists(), "an empty IGES file was written");
    for name in ["c.step", "c.json"] {
        let out = dir.join(name);
        let o = nurbsx([
            "fit".as_ref(),
            points.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ]);
        assert_exit(&o, 0);
        assert!(!stderr(&o).contains("warning"), "{name}: {}", stderr(&o));
        // Interpolation: the curve starts at the first point and ends at the last.
        let (start, end) = (point_of(&out, 0.0), point_of(&out, 1.0));
        assert!(
            start[0].abs() < 1e-12 && start[1].abs() < 1e-12,
            "{name}: {start:?}"
        );
        assert!(
            (end[0] - 3.0).abs() < 1e-12 && (end[1] - 1.0).abs() < 1e-12,
            "{name}: {end:?}"
        );
    }
}

/// A part sample of `samples/freecad/parts`.
fn part(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("samples/freecad/parts")
        .join(name)
}

/// `nurbsx info --json FILE`'s structure object.
fn structure_of(file: &Path) -> Value {
    let o = nurbsx(["info".as_ref(), "--json".as_ref(), file.as_os_str()]);
    assert_exit(&o, 0);
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    v["structure"].clone()
}

/// The IGES entity types of a file's directory entries (IGES 5.3 section 2.2.4: columns
/// 1-8 of every odd D line).
fn iges_entity_types(text: &str) -> Vec<u32> {
    text.lines()
        .filter(|l| l.len() >= 80 && l.as_bytes()[72] == b'D')
        .filter(|l| l[73..80].trim().parse::<u32>().is_ok_and(|n| n % 2 == 1))
        .map(|l| l[..8].trim().parse().unwrap())
        .collect()
}

/// `--iges-brep` writes the solid as a 186 manifold solid B-rep object (with its 514 shell
/// and 510 faces) and no 144; without it the faces are 144 trimmed surfaces and no 186.
/// Both read back as the same solid: one closed shell, 19 faces, the volume FreeCAD
/// measured on the part it made (`box_fillet_chamfer_hole.source.json`: 22008.27328) within
/// 1e-6 relative.
#[test]
fn iges_brep_writes_a_manifold_solid_and_faces_mode_trimmed_surfaces() {
    let dir = temp_dir("iges-brep");
    let source = part("box_fillet_chamfer_hole.step");
    let truth: Value = serde_json::from_str(
        &std::fs::read_to_string(part("box_fillet_chamfer_hole.source.json")).unwrap(),
    )
    .unwrap();
    let volume = truth["totals"]["volume"].as_f64().unwrap();
    for brep in [false, true] {
        let out = dir.join(format!("box-{brep}.igs"));
        let mut args = vec![
            "convert".as_ref(),
            source.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ];
        if brep {
            args.push("--iges-brep".as_ref());
        }
        assert_exit(&nurbsx(args), 0);
        let types = iges_entity_types(&std::fs::read_to_string(&out).unwrap());
        let count = |t: u32| types.iter().filter(|&&x| x == t).count();
        if brep {
            assert_eq!(
                (count(186), count(514), count(510)),
                (1, 1, 19),
                "{types:?}"
            );
            assert_eq!(count(144), 0);
        } else {
            assert_eq!((count(186), count(144)), (0, 19), "{types:?}");
        }
        let s = structure_of(&out);
        assert_eq!(s["solids"].as_array().unwrap().len(), 1, "{brep}: {s}");
        assert_eq!(s["faces"].as_array().unwrap().len(), 19);
        let got = s["solids"][0]["volume"].as_f64().unwrap();
        assert!(
            ((got - volume) / volume).abs() < 1e-6,
            "{brep}: {got} vs {volume}"
        );
    }
}

/// `--geometry-only` keeps the surfaces and curves, leaves faces, shells and solids out,
/// and says so on stderr (a warning, shown by default); the written STEP has no face.
#[test]
fn geometry_only_leaves_the_topology_out_and_says_so() {
    let dir = temp_dir("geometry-only");
    let out = dir.join("box.step");
    let source = part("box_fillet_chamfer_hole.step");
    let o = nurbsx([
        "convert".as_ref(),
        source.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--geometry-only".as_ref(),
    ]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains("warning[topology.not_read]"),
        "{}",
        stderr(&o)
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(!text.contains("ADVANCED_FACE") && !text.contains("MANIFOLD_SOLID_BREP"));
    assert!(text.contains("B_SPLINE_SURFACE"));
    let s = structure_of(&out);
    assert_eq!(s["faces"].as_array().map_or(0, Vec::len), 0, "{s}");
    // Without the flag the same input gives the solid.
    let whole = dir.join("whole.step");
    assert_exit(
        &nurbsx([
            "convert".as_ref(),
            source.as_os_str(),
            "-o".as_ref(),
            whole.as_os_str(),
        ]),
        0,
    );
    assert_eq!(structure_of(&whole)["solids"].as_array().unwrap().len(), 1);
}

/// The extruded B-spline part's IGES 144 file with one seam line moved by 1e-5 in y (the
/// side face's boundary then leaves a 1e-5 gap at two corners).
fn gapped_extrusion() -> String {
    let text = std::fs::read_to_string(part("extrude_bspline.igs")).unwrap();
    let line = "110,8.,7.166666667,15.,8.,7.166666667,0.;";
    assert!(text.contains(line), "the sample changed: update this test");
    text.replace(line, "110,8.,7.166676667,15.,8.,7.166676667,0.;")
}

/// `--sew-tolerance`: a 1e-5 gap is more than the file's default tolerance (1e-7 of the
/// part's size), so the side face is refused (`topology.loop_open`) and no solid comes out;
/// with `--sew-tolerance 1e-4` the loop closes, the three faces are sewn and the STEP
/// output holds one solid of three faces, as FreeCAD's source part.
#[test]
fn sew_tolerance_closes_gaps_the_default_leaves_open() {
    let dir = temp_dir("sew-tolerance");
    let input = dir.join("gap.igs");
    std::fs::write(&input, gapped_extrusion()).unwrap();
    let out = dir.join("gap.step");
    let run = |extra: &[&str]| {
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "convert".as_ref(),
            input.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ];
        args.extend(extra.iter().map(std::ffi::OsStr::new));
        nurbsx(args)
    };
    // An entity read with an error diagnostic: exit code 1, after writing the rest.
    let o = run(&[]);
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains("error[topology.loop_open]"),
        "{}",
        stderr(&o)
    );
    let s = structure_of(&out);
    assert_eq!(s["solids"].as_array().map_or(0, Vec::len), 0, "{s}");

    let o = run(&["--sew-tolerance", "1e-4"]);
    assert_exit(&o, 0);
    assert!(!stderr(&o).contains("loop_open"), "{}", stderr(&o));
    let s = structure_of(&out);
    assert_eq!(s["solids"].as_array().unwrap().len(), 1, "{s}");
    assert_eq!(s["faces"].as_array().unwrap().len(), 3);
    assert_eq!(s["shells"][0]["closed"], true);
    // The STEP output declares the tolerance the faces were sewn within (so the re-read
    // above joins them again).
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.0001)"));
    // Not a positive length: a usage error.
    assert_exit(&run(&["--sew-tolerance", "0"]), 2);
}

/// `validate --format sarif` against the OASIS SARIF 2.1.0 JSON schema (`sarif-2.1.0.json`
/// as Microsoft's SARIF multitool ships it in the npm package
/// `@microsoft/sarif-multitool-linux`), checked by the JSON-schema validator `ajv` (draft
/// 07, with `ajv-formats` for the uri and date-time formats): a valid file, a batch of
/// broken ones with located results of every kind (STEP line/column, IGES section and
/// sequence, model JSON), and a missing file. Needs Node and the packages:
/// `npm install --prefix DIR @microsoft/sarif-multitool-linux ajv ajv-formats`, then
/// `NURBSX_SARIF_SCHEMA=DIR/node_modules cargo test --test cli -- --ignored sarif_schema`.
#[test]
#[ignore = "needs Node.js and the npm packages of NURBSX_SARIF_SCHEMA"]
fn sarif_schema_accepts_validate_output() {
    let modules = std::env::var("NURBSX_SARIF_SCHEMA")
        .expect("NURBSX_SARIF_SCHEMA=<node_modules folder holding the schema and ajv>");
    let schema = Path::new(&modules).join("@microsoft/sarif-multitool-linux/sarif-2.1.0.json");
    assert!(schema.is_file(), "{} is missing", schema.display());
    let dir = temp_dir("sarif-schema");
    let script = dir.join("check.js");
    std::fs::write(
        &script,
        "const Ajv = require('ajv');\n\
         const addFormats = require('ajv-formats');\n\
         const fs = require('fs');\n\
         const schema = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));\n\
         delete schema['$schema'];\n\
         const ajv = new Ajv({ strict: false, allErrors: true });\n\
         addFormats(ajv);\n\
         const check = ajv.compile(schema);\n\
         const doc = JSON.parse(fs.readFileSync(process.argv[3], 'utf8'));\n\
         if (!check(doc)) { console.log(JSON.stringify(check.errors, null, 1)); process.exit(1); }\n\
         console.log('valid');\n",
    )
    .unwrap();
    let bad = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs");
    let mut broken: Vec<PathBuf> = std::fs::read_dir(&bad)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("step" | "igs" | "json")
            )
        })
        .collect();
    broken.sort();
    assert!(broken.len() > 20, "{} broken inputs", broken.len());
    let valid = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts/flange.step");
    let cases: Vec<(&str, Vec<PathBuf>, i32)> = vec![
        ("valid", vec![valid], 0),
        ("broken", broken, 1),
        ("missing", vec![dir.join("nosuch.step")], 2),
    ];
    for (name, files, code_expected) in cases {
        let mut args = vec!["validate".into(), "--format".into(), "sarif".into()];
        args.extend(files.iter().map(|p| p.clone().into_os_string()));
        let o = nurbsx(args);
        assert_eq!(code(&o), code_expected, "{name}: {}", stderr(&o));
        let sarif = dir.join(format!("{name}.sarif"));
        std::fs::write(&sarif, &o.stdout).unwrap();
        let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
        let results = doc["runs"][0]["results"].as_array().map_or(0, Vec::len);
        if name != "valid" {
            assert!(results > 0, "{name}: no result");
        }
        let checked = Command::new("node")
            .arg(&script)
            .arg(&schema)
            .arg(&sarif)
            .env("NODE_PATH", &modules)
            .output()
            .unwrap();
        assert!(
            checked.status.success(),
            "{name} ({results} results) does not conform to SARIF 2.1.0: {}{}",
            stdout(&checked),
            stderr(&checked)
        );
    }
}

/// `convert --strict` and `info --strict`: a violation the reader reads anyway (a byte that
/// is neither ASCII nor UTF-8 in a STEP string, ISO 10303-21 section 6.4.3) is a warning
/// and exit 0 without the flag, an error and exit 1 with it, as `validate` reports it; the
/// output is written either way.
#[test]
fn strict_makes_violations_errors_in_convert_and_info() {
    let dir = temp_dir("strict");
    let source = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/curve_circle_nurbs.step"),
    )
    .unwrap();
    let at = source
        .windows(9)
        .position(|w| w == b"PRODUCT('")
        .expect("a PRODUCT name")
        + 9;
    // "零件" (part) in GBK: legacy Chinese encoding, not UTF-8.
    let mut bytes = source[..at].to_vec();
    bytes.extend_from_slice(&[0xC1, 0xE3, 0xBC, 0xFE]);
    bytes.extend_from_slice(&source[at..]);
    let input = dir.join("gbk.step");
    std::fs::write(&input, bytes).unwrap();
    let out = dir.join("gbk.igs");
    for strict in [false, true] {
        let _ = std::fs::remove_file(&out);
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "convert".as_ref(),
            input.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ];
        let mut info: Vec<&std::ffi::OsStr> = vec!["info".as_ref(), input.as_os_str()];
        if strict {
            args.push("--strict".as_ref());
            info.push("--strict".as_ref());
        }
        let level = if strict { "error" } else { "warning" };
        for o in [nurbsx(args), nurbsx(info)] {
            assert_exit(&o, i32::from(strict));
            assert!(
                stderr(&o).contains(&format!("{level}[encoding.not_utf8]")),
                "{strict}: {}",
                stderr(&o)
            );
        }
        assert!(out.is_file(), "{strict}: the output is written");
    }
}

// ---------------------------------------------------------------------------------------
// fit (least squares, grids), measure, compare

fn curve_file(path: &Path) -> nurbsx::nurbs::NurbsCurve {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn fit_least_squares_and_grids_report_the_residual() {
    let dir = temp_dir("fit-ls");
    let points = dir.join("p.json");
    let q: Vec<[f64; 3]> = (0..50)
        .map(|k| {
            let t = f64::from(k) * 0.2;
            [t.cos(), t.sin(), 0.1 * t + 0.01 * (7.0 * t).sin()]
        })
        .collect();
    std::fs::write(&points, serde_json::to_string(&q).unwrap()).unwrap();
    let out = dir.join("c.json");
    let o = nurbsx([
        "fit".as_ref(),
        points.as_os_str(),
        "--poles".as_ref(),
        "9".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_exit(&o, 0);
    let c = curve_file(&out);
    assert_eq!(c.num_poles(), 9);
    // The ends are interpolated, bit for bit (numbers are read back exactly).
    assert_eq!(c.control_points()[0], q[0]);
    assert_eq!(c.control_points()[8], q[49]);
    // The summary names the method and the residual, which is the library's figure.
    let fit =
        nurbsx::nurbs::fit::approximate(&q, 3, 9, nurbsx::nurbs::fit::ParamMethod::ChordLength, 3)
            .unwrap();
    let text = stderr(&o);
    assert!(text.contains("least-squares of 50 points"), "{text}");
    let max: f64 = text
        .split("residual max ")
        .nth(1)
        .and_then(|rest| rest.split(',').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        (max - fit.residual.max).abs() <= 1e-12 * fit.residual.max,
        "{text}"
    );
    // A pole count outside degree + 1 .. points - 1 is a usage error.
    for n in ["3", "50"] {
        let o = nurbsx([
            "fit".as_ref(),
            points.as_os_str(),
            "--poles".as_ref(),
            n.as_ref(),
            "-o".as_ref(),
            out.as_os_str(),
        ]);
        assert!(
            code(&o) != 0 && !stderr(&o).contains("panicked"),
            "{}",
            stderr(&o)
        );
    }
    // A grid: interpolation through every point (the corners are poles), then least squares.
    let grid: Vec<Vec<[f64; 3]>> = (0..7)
        .map(|i| {
            (0..5)
                .map(|j| {
                    let (x, y) = (f64::from(i), f64::from(j) * 1.5);
                    [x, y, (0.5 * x).sin() * (0.3 * y).cos()]
                })
                .collect()
        })
        .collect();
    let gpath = dir.join("grid.json");
    std::fs::write(&gpath, serde_json::to_string(&grid).unwrap()).unwrap();
    let sout = dir.join("s.json");
    let o = nurbsx([
        "fit".as_ref(),
        gpath.as_os_str(),
        "--degree-v".as_ref(),
        "2".as_ref(),
        "-o".as_ref(),
        sout.as_os_str(),
    ]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains("interpolation of 7 x 5 points"),
        "{}",
        stderr(&o)
    );
    let s: nurbsx::nurbs::NurbsSurface =
        serde_json::from_str(&std::fs::read_to_string(&sout).unwrap()).unwrap();
    assert_eq!((s.degree_u(), s.degree_v()), (3, 2));
    assert_eq!((s.control_points().nu(), s.control_points().nv()), (7, 5));
    let o = nurbsx([
        "fit".as_ref(),
        gpath.as_os_str(),
        "--poles".as_ref(),
        "5".as_ref(),
        "--poles-v".as_ref(),
        "4".as_ref(),
        "--degree-v".as_ref(),
        "2".as_ref(),
        "-o".as_ref(),
        sout.as_os_str(),
    ]);
    assert_exit(&o, 0);
    let s: nurbsx::nurbs::NurbsSurface =
        serde_json::from_str(&std::fs::read_to_string(&sout).unwrap()).unwrap();
    assert_eq!((s.control_points().nu(), s.control_points().nv()), (5, 4));
    assert_eq!(*s.control_points().get(4, 3), grid[6][4]);
    // A ragged grid is a usage error.
    std::fs::write(&gpath, "[[[0,0,0],[1,0,0]],[[0,1,0]]]").unwrap();
    let o = nurbsx([
        "fit".as_ref(),
        gpath.as_os_str(),
        "-o".as_ref(),
        sout.as_os_str(),
    ]);
    assert_exit(&o, 2);
}

#[test]
fn measure_the_circle_length_and_closest_point() {
    let circle = data("circle.json");
    let o = nurbsx([
        "measure".as_ref(),
        circle.as_os_str(),
        "--tolerance".as_ref(),
        "1e-10".as_ref(),
        "--closest".as_ref(),
        "3,4".as_ref(),
        "--json".as_ref(),
    ]);
    assert_exit(&o, 0);
    let v = json(&o);
    let e = &v["entities"][0];
    assert_eq!(e["kind"], "curve");
    let length = e["length"]["value"].as_f64().unwrap();
    assert!((length - 2.0 * std::f64::consts::PI).abs() < 1e-10, "{v}");
    assert_eq!(e["length"]["converged"], true);
    // The closest point to (3, 4) on the unit circle is (0.6, 0.8), at distance 4.
    let d = e["closest"]["distance"].as_f64().unwrap();
    assert!((d - 4.0).abs() < 1e-12, "{v}");
    let p = floats(&e["closest"]["point"]);
    assert!(
        (p[0] - 0.6).abs() < 1e-9 && (p[1] - 0.8).abs() < 1e-9,
        "{p:?}"
    );
    assert_eq!(v["nearest"], "0");
    // An unreachable tolerance: exit 1 with a warning naming the estimate.
    let o = nurbsx([
        "measure".as_ref(),
        circle.as_os_str(),
        "--tolerance".as_ref(),
        "1e-300".as_ref(),
    ]);
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains("measure.not_converged"),
        "{}",
        stderr(&o)
    );
    assert!(stdout(&o).contains("NOT converged"), "{}", stdout(&o));
    let o = nurbsx([
        "measure".as_ref(),
        circle.as_os_str(),
        "--closest".as_ref(),
        "1,2,3,4".as_ref(),
    ]);
    assert_exit(&o, 2);
}

#[test]
fn compare_ignores_the_parameterisation_and_sees_a_move() {
    let dir = temp_dir("compare");
    let circle = data("circle.json");
    let (reversed, elevated, moved) = (
        dir.join("rev.json"),
        dir.join("up.step"),
        dir.join("moved.json"),
    );
    assert_exit(
        &nurbsx([
            "reverse".as_ref(),
            circle.as_os_str(),
            "-o".as_ref(),
            reversed.as_os_str(),
        ]),
        0,
    );
    assert_exit(
        &nurbsx([
            "elevate".as_ref(),
            reversed.as_os_str(),
            "--by".as_ref(),
            "2".as_ref(),
            "-o".as_ref(),
            elevated.as_os_str(),
        ]),
        0,
    );
    assert_exit(
        &nurbsx([
            "transform".as_ref(),
            circle.as_os_str(),
            "--translate".as_ref(),
            "0.3,0.4,0".as_ref(),
            "-o".as_ref(),
            moved.as_os_str(),
        ]),
        0,
    );
    for other in [&reversed, &elevated] {
        let o = nurbsx([
            "compare".as_ref(),
            circle.as_os_str(),
            other.as_os_str(),
            "--tolerance".as_ref(),
            "1e-9".as_ref(),
            "--json".as_ref(),
        ]);
        assert_exit(&o, 0);
        let v = json(&o);
        assert!(v["distance"].as_f64().unwrap() < 1e-9, "{v}");
        assert_eq!(v["within_tolerance"], true);
    }
    let o = nurbsx([
        "compare".as_ref(),
        circle.as_os_str(),
        moved.as_os_str(),
        "--tolerance".as_ref(),
        "1e-3".as_ref(),
        "--json".as_ref(),
    ]);
    assert_exit(&o, 1);
    let v = json(&o);
    assert!((v["distance"].as_f64().unwrap() - 0.5).abs() < 1e-9, "{v}");
    assert_eq!(v["within_tolerance"], false);
    // Without --tolerance: a report and exit 0.
    let o = nurbsx(["compare".as_ref(), circle.as_os_str(), moved.as_os_str()]);
    assert_exit(&o, 0);
    let text = stdout(&o);
    let number: f64 = text
        .strip_prefix("Hausdorff distance ")
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{text}"));
    assert!((number - 0.5).abs() < 1e-9, "{text}");
}
