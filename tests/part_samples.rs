//! The whole-part sample corpus (`samples/freecad/parts/`) is self-consistent.
//!
//! These checks are about FreeCAD's data, not about nurbsx (no nurbsx code is used):
//! - every JSON parses and carries the schema string `nurbsx-freecad-parts/1`; every part of
//!   `index.json` has its source reading and its three files (STEP, IGES faces mode, IGES
//!   B-rep mode), each with its reading;
//! - each reading agrees with the file it describes, counted here from the file text: the
//!   entity counts (STEP instance keywords, ISO 10303-21 clause 10; IGES Directory Entry types,
//!   IGES 5.3 section 2.2.5), the declared unit (STEP `CONVERSION_BASED_UNIT` / `SI_UNIT`;
//!   IGES Global parameter 14, section 2.2.4.3.14) against the export unit, 144 without 186
//!   in faces mode, one 186 per solid in B-rep mode, the assembly's
//!   `NEXT_ASSEMBLY_USAGE_OCCURRENCE`s;
//! - each reading is internally consistent (counts against lists, totals against the faces
//!   and solids they sum);
//! - the readings of a part agree with its in-memory source: face count, total area (1e-6
//!   relative), area-weighted face centroid (1e-6 of the size), free-edge length; for the
//!   STEP and B-rep readings solid count, volume (1e-6 relative), validity, closed shells;
//!   FreeCAD's faces-mode IGES area errors are checked as recorded (README: FreeCAD's own
//!   errors);
//! - Euler–Poincaré for every reading made of closed shells:
//!   V − E + F − (L − F) = 2(S − G) with degenerated edges removed, L the loops (wires per
//!   face), S the shells, gives the genus stated by hand for the part.
//!
//! The checks return their findings as text, and `mutated_readings_are_caught` shows that
//! each kind of corruption of a reading is found.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

const SCHEMA: &str = "nurbsx-freecad-parts/1";
/// Areas, volumes, centroids and lengths of a re-import against the source.
const REL_TOL: f64 = 1e-6;
/// FreeCAD's faces-mode IGES files whose re-imported area is known to be off by more than
/// REL_TOL (README: FreeCAD's own errors): the face areas over the parameter-space boundary
/// of faces bounded by B-spline edges. Recorded values: 2.0e-5, 4.3e-6, 3.4e-6.
const FREECAD_IGES_AREA_ERRORS: [&str; 3] = [
    "extrude_bspline.igs",
    "loft_bspline.igs",
    "revolve_bspline_270.igs",
];
/// Upper bound for those known errors (area relative, centroid per size).
const FREECAD_IGES_ERROR_BOUND: f64 = 1e-4;
/// The issue asks for at least this many parts.
const MIN_PARTS: usize = 15;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts")
}

fn load(name: &str) -> Value {
    let path = dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{name}: not JSON: {e}"))
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number in {v}"))
}

fn count(r: &Value, key: &str) -> i64 {
    r["counts"][key]
        .as_i64()
        .unwrap_or_else(|| panic!("counts.{key} missing"))
}

fn v3(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("a 3-vector");
    assert_eq!(a.len(), 3, "{v}");
    [
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    ]
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn rel(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        (a - b).abs()
    } else {
        ((a - b) / b).abs()
    }
}

fn parts() -> Vec<Value> {
    let index = load("index.json");
    index["parts"]
        .as_array()
        .expect("index.json: parts")
        .clone()
}

// ----------------------------------------------------------------------------- file text
/// Entity type -> count, counted from the file text.
/// STEP (ISO 10303-21 clause 10.2): `#n = KEYWORD(` simple instances by keyword, complex
/// instances `#n = ( ... )` together under "(complex)". IGES (5.3 section 2.2.5): the entity
/// type number in columns 1-8 of the first Directory Entry record of each entity.
fn text_entities(name: &str, text: &str) -> BTreeMap<String, i64> {
    let mut out = BTreeMap::new();
    if name.ends_with(".step") {
        let data = text.split_once("DATA;").map(|(_, d)| d).unwrap_or("");
        for stmt in data.split(';') {
            let s = stmt.trim_start();
            let Some(rest) = s.strip_prefix('#') else {
                continue;
            };
            let Some((_, rhs)) = rest.split_once('=') else {
                continue;
            };
            let rhs = rhs.trim_start();
            let key = if rhs.starts_with('(') {
                "(complex)".to_string()
            } else {
                rhs.chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect()
            };
            *out.entry(key).or_insert(0) += 1;
        }
    } else {
        for line in text.lines() {
            if line.len() >= 80 && &line[72..73] == "D" {
                let seq: i64 = line[73..80].trim().parse().unwrap();
                if seq % 2 == 1 {
                    let ty = line[0..8].trim().to_string();
                    *out.entry(ty).or_insert(0) += 1;
                }
            }
        }
    }
    out
}

/// IGES Global section parameters (IGES 5.3 section 2.2.4: default delimiters `,` and `;`,
/// strings as Hollerith `nH...`).
fn iges_global(text: &str) -> Vec<String> {
    let g: String = text
        .lines()
        .filter(|l| l.len() >= 73 && &l[72..73] == "G")
        .map(|l| &l[..72])
        .collect();
    let b = g.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i > start && i < b.len() && b[i] == b'H' {
            let n: usize = g[start..i].parse().unwrap();
            out.push(g[i + 1..i + 1 + n].to_string());
            i += 1 + n;
        } else {
            i = start;
            while i < b.len() && b[i] != b',' && b[i] != b';' {
                i += 1;
            }
            out.push(g[start..i].trim().to_string());
        }
        if i >= b.len() || b[i] == b';' {
            break;
        }
        i += 1;
    }
    out
}

/// The length unit declared by the file text: "MM", "INCH" or "M".
fn text_unit(name: &str, text: &str) -> String {
    if name.ends_with(".step") {
        let flat: String = text.chars().filter(|c| !c.is_whitespace()).collect();
        if flat.contains("CONVERSION_BASED_UNIT('INCH'") {
            "INCH".into()
        } else if flat.contains("SI_UNIT(.MILLI.,.METRE.)") {
            "MM".into()
        } else if flat.contains("SI_UNIT($,.METRE.)") {
            "M".into()
        } else {
            "unknown".into()
        }
    } else {
        // Global parameter 14 is the units flag: 1 inch, 2 mm, 6 m.
        match iges_global(text).get(13).map(String::as_str) {
            Some("1") => "INCH".into(),
            Some("2") => "MM".into(),
            Some("6") => "M".into(),
            other => format!("unknown {other:?}"),
        }
    }
}

/// The reading's `file_entities` against the file text.
fn check_file(name: &str, r: &Value, text: &str) -> Vec<String> {
    let mut bad = Vec::new();
    let counted = text_entities(name, text);
    let mut recorded: BTreeMap<String, i64> = BTreeMap::new();
    for (k, v) in r["file_entities"].as_object().expect("file_entities") {
        let key = if k.starts_with('(') {
            "(complex)".to_string()
        } else {
            k.clone()
        };
        *recorded.entry(key).or_insert(0) += v.as_i64().unwrap();
    }
    if counted != recorded {
        bad.push(format!(
            "{name}: file_entities {recorded:?} but the file holds {counted:?}"
        ));
    }
    let unit = text_unit(name, text);
    if r["unit"]["name"] != unit.as_str() || r["export"]["unit"] != unit.as_str() {
        bad.push(format!(
            "{name}: file declares {unit}, reading {}, export {}",
            r["unit"]["name"], r["export"]["unit"]
        ));
    }
    let n = |k: &str| counted.get(k).copied().unwrap_or(0);
    let faces = count(r, "faces");
    let solids = count(r, "solids");
    if name.ends_with("_brep.igs") {
        if solids > 0 && n("186") != solids {
            bad.push(format!("{name}: {} IGES 186 for {solids} solids", n("186")));
        }
        if faces > 0 && n("510") == 0 {
            bad.push(format!("{name}: B-rep mode without 510 faces"));
        }
        if n("144") != 0 {
            bad.push(format!("{name}: 144 in a B-rep mode file"));
        }
    } else if name.ends_with(".igs") && faces > 0 && (n("144") == 0 || n("186") + n("510") > 0) {
        bad.push(format!("{name}: faces mode must hold 144 and no 186/510"));
    }
    bad
}

// ----------------------------------------------------------------------------- readings
/// Counts against lists, totals against what they sum.
fn check_internal(name: &str, r: &Value) -> Vec<String> {
    let mut bad = Vec::new();
    let faces = r["faces"].as_array().expect("faces");
    let solids = r["solids"].as_array().expect("solids");
    let shells = r["shells"].as_array().expect("shells");
    let free = r["free_edges"].as_array().expect("free_edges");
    for (key, len) in [
        ("faces", faces.len()),
        ("solids", solids.len()),
        ("shells", shells.len()),
        ("free_edges", free.len()),
    ] {
        if count(r, key) != len as i64 {
            bad.push(format!("{name}: counts.{key} {} != {len}", count(r, key)));
        }
    }
    let closed = shells.iter().filter(|s| s["closed"] == true).count() as i64;
    let wires: i64 = faces.iter().map(|f| f["wires"].as_i64().unwrap()).sum();
    if count(r, "closed_shells") != closed || count(r, "face_wires") != wires {
        bad.push(format!(
            "{name}: closed_shells / face_wires disagree with the lists"
        ));
    }
    let t = &r["totals"];
    let area: f64 = faces.iter().map(|f| num(f, "area")).sum();
    if rel(num(t, "area"), area) > 1e-12 {
        bad.push(format!("{name}: totals.area {} != sum {area}", t["area"]));
    }
    if !faces.is_empty() && area > 0.0 {
        let mut c = [0.0; 3];
        for f in faces {
            let p = v3(&f["center_of_mass"]);
            for k in 0..3 {
                c[k] += num(f, "area") * p[k] / area;
            }
        }
        let size = num(r, "size");
        if dist(c, v3(&t["face_centroid"])) > 1e-12 * size {
            bad.push(format!(
                "{name}: totals.face_centroid is not the area-weighted mean"
            ));
        }
    }
    if solids.is_empty() {
        if !t["volume"].is_null() {
            bad.push(format!("{name}: a volume without solids"));
        }
    } else {
        let vol: f64 = solids.iter().map(|s| num(s, "volume")).sum();
        if rel(num(t, "volume"), vol) > 1e-12 {
            bad.push(format!(
                "{name}: totals.volume {} != sum {vol}",
                t["volume"]
            ));
        }
    }
    let length: f64 = free.iter().map(|e| num(e, "length")).sum();
    if rel(num(t, "free_edge_length"), length) > 1e-12 {
        bad.push(format!(
            "{name}: totals.free_edge_length != sum of free edges"
        ));
    }
    bad
}

/// Euler–Poincaré (V − E + F − (L − F) = 2(S − G)) for a reading made of closed shells: the
/// genus it gives must be the hand-stated one.
fn check_euler(name: &str, r: &Value, genus: i64) -> Vec<String> {
    let shells = count(r, "shells");
    if shells == 0 || count(r, "closed_shells") != shells || count(r, "free_edges") != 0 {
        return vec![];
    }
    let v = count(r, "vertices");
    let e = count(r, "edges") - count(r, "degenerated_edges");
    let f = count(r, "faces");
    let l = count(r, "face_wires");
    let twice = 2 * shells - (v - e + f - (l - f));
    if twice != 2 * genus {
        return vec![format!(
            "{name}: V={v} E={e} F={f} L={l} S={shells} gives genus {}, stated {genus}",
            twice as f64 / 2.0
        )];
    }
    vec![]
}

/// A reading against the part's source reading.
fn check_against_source(name: &str, r: &Value, src: &Value) -> Vec<String> {
    let mut bad = Vec::new();
    if count(r, "faces") != count(src, "faces") {
        bad.push(format!(
            "{name}: {} faces, source {}",
            count(r, "faces"),
            count(src, "faces")
        ));
    }
    let (t, s) = (&r["totals"], &src["totals"]);
    let known = FREECAD_IGES_AREA_ERRORS.contains(&name);
    let area_err = rel(num(t, "area"), num(s, "area"));
    let centroid_err = if s["face_centroid"].is_null() {
        if !t["face_centroid"].is_null() {
            bad.push(format!("{name}: a face centroid without source faces"));
        }
        0.0
    } else {
        dist(v3(&t["face_centroid"]), v3(&s["face_centroid"])) / num(src, "size")
    };
    if known {
        // FreeCAD's own error, recorded in the README: it must still be there and bounded.
        if !(area_err > REL_TOL && area_err < FREECAD_IGES_ERROR_BOUND) {
            bad.push(format!(
                "{name}: recorded FreeCAD area error, now {area_err:.2e} (README says > 1e-6)"
            ));
        }
        if centroid_err >= FREECAD_IGES_ERROR_BOUND {
            bad.push(format!(
                "{name}: centroid off by {centroid_err:.2e} of the size"
            ));
        }
    } else {
        if area_err > REL_TOL {
            bad.push(format!("{name}: area off by {area_err:.2e}"));
        }
        if centroid_err > REL_TOL {
            bad.push(format!(
                "{name}: face centroid off by {centroid_err:.2e} of the size"
            ));
        }
    }
    let fel = rel(num(t, "free_edge_length"), num(s, "free_edge_length"));
    if fel > REL_TOL || count(r, "free_edges") != count(src, "free_edges") {
        bad.push(format!(
            "{name}: free edges {} (length off by {fel:.2e}), source {}",
            count(r, "free_edges"),
            count(src, "free_edges")
        ));
    }
    // Solids survive STEP and IGES B-rep mode; faces mode (144) has none (README).
    let faces_mode = name.ends_with(".igs") && !name.ends_with("_brep.igs");
    let want_solids = if faces_mode { 0 } else { count(src, "solids") };
    if count(r, "solids") != want_solids {
        bad.push(format!(
            "{name}: {} solids, expected {want_solids}",
            count(r, "solids")
        ));
    } else if want_solids > 0 {
        let dv = rel(num(t, "volume"), num(s, "volume"));
        if dv > REL_TOL {
            bad.push(format!("{name}: volume off by {dv:.2e}"));
        }
        for solid in r["solids"].as_array().unwrap() {
            if solid["valid"] != true {
                bad.push(format!("{name}: solid {} not valid", solid["index"]));
            }
        }
        if count(r, "closed_shells") != count(r, "shells") {
            bad.push(format!("{name}: a solid part with open shells"));
        }
    }
    if t["valid"] != true {
        bad.push(format!("{name}: FreeCAD reports the shape invalid"));
    }
    bad
}

/// Every check of one reading (file name `name`, `None` for the source).
fn check_reading(part: &Value, name: &str, r: &Value, src: &Value) -> Vec<String> {
    let mut bad = Vec::new();
    if r["schema"] != SCHEMA {
        bad.push(format!("{name}: schema {}", r["schema"]));
    }
    if r["part"] != part["part"] || r["genus"] != part["genus"] {
        bad.push(format!("{name}: part / genus differ from index.json"));
    }
    bad.extend(check_internal(name, r));
    if let Some(g) = part["genus"].as_i64() {
        bad.extend(check_euler(name, r, g));
    }
    if !std::ptr::eq(r, src) {
        bad.extend(check_against_source(name, r, src));
    }
    bad
}

fn check_part(part: &Value) -> Vec<String> {
    let pname = part["part"].as_str().expect("part name");
    let src = load(&format!("{pname}.source.json"));
    let mut bad = check_reading(part, &format!("{pname}.source.json"), &src, &src);
    if src["format"] != "in-memory" || !src["file"].is_null() {
        bad.push(format!("{pname}.source.json: not an in-memory reading"));
    }
    let files = part["files"].as_array().expect("files");
    let names: Vec<&str> = files.iter().map(|f| f["file"].as_str().unwrap()).collect();
    let want = [
        format!("{pname}.step"),
        format!("{pname}.igs"),
        format!("{pname}_brep.igs"),
    ];
    if names != want {
        bad.push(format!("{pname}: files {names:?}, expected {want:?}"));
        return bad;
    }
    for name in names {
        let r = load(&format!("{name}.json"));
        let text = std::fs::read_to_string(dir().join(name)).expect("the file");
        if r["file"] != name {
            bad.push(format!("{name}.json: file {}", r["file"]));
        }
        let (fmt, brep) = if name.ends_with(".step") {
            ("step", 0)
        } else {
            ("iges", i64::from(name.ends_with("_brep.igs")))
        };
        if r["format"] != fmt
            || r["export"]["iges_brep_mode"] != brep
            || r["export"]["step_schema"] != "AP214IS"
        {
            bad.push(format!("{name}.json: format / export options"));
        }
        if fmt == "step" && !text.contains("AUTOMOTIVE_DESIGN") {
            bad.push(format!("{name}: not AP214 (no AUTOMOTIVE_DESIGN schema)"));
        }
        bad.extend(check_file(name, &r, &text));
        bad.extend(check_reading(part, name, &r, &src));
    }
    bad
}

// ----------------------------------------------------------------------------- tests
#[test]
fn corpus_is_self_consistent() {
    let parts = parts();
    assert!(parts.len() >= MIN_PARTS, "{} parts", parts.len());
    assert_eq!(load("index.json")["schema"], SCHEMA);
    let mut bad = Vec::new();
    for p in &parts {
        bad.extend(check_part(p));
    }
    assert!(
        bad.is_empty(),
        "{} problems:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn every_json_is_listed_and_parses() {
    let mut listed = vec![
        "index.json".to_string(),
        "freecad_roundtrip.json".to_string(),
    ];
    for p in parts() {
        let name = p["part"].as_str().unwrap();
        listed.push(format!("{name}.source.json"));
        for f in p["files"].as_array().unwrap() {
            listed.push(format!("{}.json", f["file"].as_str().unwrap()));
        }
    }
    listed.sort();
    let mut found: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".json"))
        .collect();
    found.sort();
    assert_eq!(found, listed);
    for name in &found {
        assert_eq!(load(name)["schema"], SCHEMA, "{name}");
    }
}

/// The issue's list of what the parts must show, from the readings and files themselves.
#[test]
fn parts_cover_the_issue() {
    let src = |p: &str| load(&format!("{p}.source.json"));
    let mut surfaces = BTreeMap::new();
    for p in parts() {
        let r = src(p["part"].as_str().unwrap());
        for (k, v) in r["surface_types"].as_object().unwrap() {
            *surfaces.entry(k.clone()).or_insert(0) += v.as_i64().unwrap();
        }
    }
    for kind in [
        "Plane",
        "Cylinder",
        "Cone",
        "Sphere",
        "Toroid",
        "BSplineSurface",
        "SurfaceOfRevolution",
        "SurfaceOfExtrusion",
    ] {
        assert!(surfaces.contains_key(kind), "no {kind} face: {surfaces:?}");
    }
    let free = src("free_edges");
    for kind in ["Line", "Circle", "Ellipse", "BSplineCurve"] {
        assert!(
            free["curve_types"][kind].as_i64().unwrap_or(0) > 0,
            "free {kind}"
        );
    }
    let lone = src("trimmed_face");
    assert_eq!(count(&lone, "faces"), 1);
    assert_eq!(lone["faces"][0]["wires"], 2, "the lone face has a hole");
    assert_eq!(count(&src("several_solids"), "solids"), 3);
    let asm = load("assembly_links.step.json");
    assert_eq!(asm["file_entities"]["NEXT_ASSEMBLY_USAGE_OCCURRENCE"], 3);
    assert_eq!(asm["file_entities"]["ITEM_DEFINED_TRANSFORMATION"], 3);
    // the bracket's shape is written once and placed twice
    assert_eq!(asm["file_entities"]["MANIFOLD_SOLID_BREP"], 2);
    assert_eq!(count(&asm, "solids"), 3);
    assert_eq!(load("inch_plate.step.json")["unit"]["name"], "INCH");
}

/// FreeCAD's own conversions: one row per direction for every part, consistent with the
/// part's source reading.
#[test]
fn roundtrip_table_is_complete() {
    let rt = load("freecad_roundtrip.json");
    for p in parts() {
        let name = p["part"].as_str().unwrap();
        let src = load(&format!("{name}.source.json"));
        let rows = rt["parts"][name]
            .as_array()
            .unwrap_or_else(|| panic!("{name}"));
        let to: Vec<&str> = rows.iter().map(|r| r["to"].as_str().unwrap()).collect();
        assert_eq!(to, ["iges (144)", "iges (186)", "step", "step"], "{name}");
        for row in rows {
            assert_eq!(row["faces"][0], src["counts"]["faces"], "{name}");
            assert_eq!(row["solids"][0], src["counts"]["solids"], "{name}");
            assert!(row["area_rel_error"].as_f64().is_some(), "{name}");
        }
    }
}

/// An edit of a reading.
type Mutation = Box<dyn Fn(&mut Value)>;

/// Each kind of corruption of a reading is reported (the checks above can fail).
#[test]
fn mutated_readings_are_caught() {
    let part = parts().into_iter().find(|p| p["part"] == "flange").unwrap();
    let src = load("flange.source.json");
    let good = load("flange.step.json");
    assert!(check_reading(&part, "flange.step", &good, &src).is_empty());
    let text = std::fs::read_to_string(dir().join("flange.step")).unwrap();
    assert!(check_file("flange.step", &good, &text).is_empty());
    let mutations: Vec<(&str, Mutation)> = vec![
        (
            "area",
            Box::new(|r| {
                let a = num(&r["totals"], "area");
                r["totals"]["area"] = (a * (1.0 + 2e-6)).into();
                r["faces"][0]["area"] = (num(&r["faces"][0], "area") + a * 2e-6).into();
            }),
        ),
        (
            "volume",
            Box::new(|r| {
                let v = num(&r["totals"], "volume") * (1.0 + 2e-6);
                r["totals"]["volume"] = v.into();
                r["solids"][0]["volume"] = v.into();
            }),
        ),
        (
            "vertex count (Euler)",
            Box::new(|r| {
                r["counts"]["vertices"] = (count(r, "vertices") + 2).into();
            }),
        ),
        (
            "face count",
            Box::new(|r| {
                let f = r["faces"].as_array_mut().unwrap().pop().unwrap();
                r["counts"]["faces"] = (count(r, "faces") - 1).into();
                r["counts"]["face_wires"] =
                    (count(r, "face_wires") - f["wires"].as_i64().unwrap()).into();
                let a = num(&r["totals"], "area") - num(&f, "area");
                r["totals"]["area"] = a.into();
            }),
        ),
        (
            "centroid",
            Box::new(|r| {
                r["totals"]["face_centroid"][0] =
                    (r["totals"]["face_centroid"][0].as_f64().unwrap() + 1e-3).into();
            }),
        ),
        (
            "open shell",
            Box::new(|r| {
                r["shells"][0]["closed"] = false.into();
                r["counts"]["closed_shells"] = 0.into();
            }),
        ),
        (
            "schema",
            Box::new(|r| r["schema"] = "nurbsx-freecad-parts/0".into()),
        ),
    ];
    for (what, mutate) in &mutations {
        let mut r = good.clone();
        mutate(&mut r);
        assert!(
            !check_reading(&part, "flange.step", &r, &src).is_empty(),
            "mutation not caught: {what}"
        );
    }
    let mut r = good.clone();
    r["file_entities"]["ADVANCED_FACE"] = 11.into();
    assert!(
        !check_file("flange.step", &r, &text).is_empty(),
        "entity count"
    );
    let mut r = good.clone();
    r["unit"]["name"] = "INCH".into();
    assert!(!check_file("flange.step", &r, &text).is_empty(), "unit");
    // a known FreeCAD error that disappeared (or a part added to the list without one)
    let ext = load("extrude_bspline.source.json");
    assert!(!check_against_source("extrude_bspline.igs", &ext, &ext).is_empty());
}
