//! STEP boundary representation: read into `Document.topology`, checked against FreeCAD's
//! own reading of the same files (the sample JSONs: faces, edges without the degenerate
//! ones Open CASCADE adds at poles, vertices, shells, solids), against Euler-Poincare, and
//! written back.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};

use nurbsx::exchange::{self, Document, ExportOptions, Format, ImportOptions, Severity};
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read_path(path: &Path) -> Document {
    exchange::read(&std::fs::read(path).unwrap(), &ImportOptions::default()).unwrap()
}

/// FreeCAD's counts of a sample: (faces, edges without degenerate ones, vertices when
/// known, shells, solids).
fn freecad_counts(json: &Value) -> (usize, usize, Option<usize>, usize, usize) {
    let c = &json["counts"];
    let n = |k: &str| c[k].as_u64().unwrap_or(0) as usize;
    let degenerate = c["degenerated_edges"]
        .as_u64()
        .or_else(|| c["curve_types"]["None"].as_u64())
        .or_else(|| c["other_curves"]["None"].as_u64())
        .unwrap_or(0) as usize;
    (
        n("faces"),
        n("edges") - degenerate,
        c["vertices"].as_u64().map(|v| v as usize),
        n("shells"),
        n("solids"),
    )
}

fn ours(doc: &Document) -> (usize, usize, usize, usize, usize) {
    let m = &doc.topology.model;
    (
        m.faces.len(),
        m.edges.len(),
        m.vertices.len(),
        m.shells.len(),
        m.solids.len(),
    )
}

/// Every STEP sample with a face, with FreeCAD's reading.
fn samples() -> Vec<(PathBuf, Value)> {
    let mut out = Vec::new();
    let mut dirs = vec![
        root().join("samples/freecad"),
        root().join("samples/freecad/analytic"),
    ];
    dirs.push(
        std::env::var_os("NURBSX_PARTS_DIR")
            .map_or_else(|| root().join("samples/freecad/parts"), PathBuf::from),
    );
    for dir in dirs {
        let Ok(list) = std::fs::read_dir(&dir) else {
            eprintln!(
                "step_topology: {} not found, its samples are not checked",
                dir.display()
            );
            continue;
        };
        let mut files: Vec<PathBuf> = list
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "step"))
            .collect();
        files.sort();
        for p in files {
            let json = PathBuf::from(format!("{}.json", p.display()));
            let Ok(text) = std::fs::read_to_string(&json) else {
                continue;
            };
            let v: Value = serde_json::from_str(&text).unwrap();
            if v["counts"]["faces"].as_u64().unwrap_or(0) > 0 {
                out.push((p, v));
            }
        }
    }
    out
}

/// Samples whose topology nurbsx does not read in full yet, with the reason; for these the
/// tests check that the reader says so with an error diagnostic (never silently).
const KNOWN_GAPS: &[(&str, &str)] = &[];

/// Samples where Open CASCADE's reading adds edges the file does not have (ShapeFix splits
/// or completes the boundary of a single B-spline face): compared with the file's own
/// EDGE_CURVE count instead.
const OCCT_ADDS_EDGES: &[&str] = &[
    "schema_ap203.step",
    "schema_ap242.step",
    "units_inch.step",
    "units_metre.step",
    "surf_sphere_nurbs.step",
    // A sphere bounded by a vertex loop: Open CASCADE adds the seam edge.
    "sphere.step",
];

fn name(path: &Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

/// `directory/file`, for names that occur in two sample directories.
fn qualified(path: &Path) -> String {
    let dir = path
        .parent()
        .unwrap()
        .file_name()
        .unwrap()
        .to_string_lossy();
    format!("{dir}/{}", name(path))
}

fn gap(path: &Path) -> Option<&'static str> {
    let n = name(path);
    KNOWN_GAPS
        .iter()
        .find(|(f, _)| *f == n)
        .map(|(_, why)| *why)
}

/// EDGE_CURVE instances in the file's text (an independent count).
fn edge_curves_in(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .matches("EDGE_CURVE(")
        .count()
}

#[test]
fn counts_equal_freecads() {
    let mut failures = Vec::new();
    for (path, json) in samples() {
        let doc = read_path(&path);
        let (f, e, v, sh, so) = freecad_counts(&json);
        let got = ours(&doc);
        let errors: Vec<String> = doc
            .diagnostics
            .iter()
            .filter(|d| {
                d.severity == Severity::Error
                    || (d.severity == Severity::Warning && d.code.starts_with("assembly."))
            })
            .map(|d| format!("{} {:?}: {}", d.code, d.location.entity, d.message))
            .collect();
        println!(
            "{:<40} faces {}/{f} edges {}/{e} vertices {}/{v:?} shells {}/{sh} solids {}/{so} errors {}",
            path.file_name().unwrap().to_string_lossy(),
            got.0,
            got.1,
            got.2,
            got.3,
            got.4,
            errors.len()
        );
        for e in errors.iter().take(3) {
            println!("    {e}");
        }
        if let Some(why) = gap(&path) {
            assert!(
                !errors.is_empty(),
                "{}: {why}, but no diagnostic says so",
                path.display()
            );
            continue;
        }
        let e = if OCCT_ADDS_EDGES.contains(&name(&path).as_str()) {
            edge_curves_in(&path)
        } else {
            e
        };
        if (got.0, got.1, got.3, got.4) != (f, e, sh, so) || v.is_some_and(|v| v != got.2) {
            failures.push(path.display().to_string());
        }
        // Euler-Poincare for a closed solid's boundary: V - E + F - (L - F) = 2 (S - G),
        // with L the loops (so L - F the inner loops); the genus G from the sample when
        // given, else 0. Edge-less faces (a VERTEX_LOOP sphere) are outside the formula.
        let m = &doc.topology.model;
        if m.solids.len() == 1 && m.shells.len() == 1 && m.faces.iter().all(|f| !f.loops.is_empty())
        {
            let loops: usize = m.faces.iter().map(|f| f.loops.len()).sum();
            // Genus: the parts' JSON gives it; of the analytic samples, the box with a
            // through hole and the torus have one handle (their descriptions), the rest none.
            let genus = json["genus"]
                .as_i64()
                .unwrap_or(match name(&path).as_str() {
                    "filleted_box_with_hole.step" | "torus.step" => 1,
                    _ => 0,
                });
            let lhs = got.2 as i64 - got.1 as i64 + got.0 as i64 - (loops as i64 - got.0 as i64);
            // OCCT's own edge count (with its seams) is what the genus of the sample was
            // read with; a file without seam edges differs by them, so check only files
            // where every closed face has its seam (all of FreeCAD's here).
            if lhs != 2 * (1 - genus) {
                failures.push(format!(
                    "{}: V - E + F - inner loops = {lhs}, 2 (S - G) = {}",
                    path.display(),
                    2 * (1 - genus)
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `freecadcmd` on PATH.
fn find_freecadcmd() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| ["freecadcmd", "FreeCADCmd"].map(|name| dir.join(name)))
        .find(|candidate| candidate.is_file())
}

/// FreeCAD's readings (scripts/freecad/reimport_faces.py) of `files`, by path.
fn freecad_readings(
    freecadcmd: &Path,
    files: &[PathBuf],
) -> std::collections::HashMap<String, Value> {
    let list = std::env::join_paths(files).unwrap();
    let out = std::process::Command::new(freecadcmd)
        .arg(root().join("scripts/freecad/reimport_faces.py"))
        .env("NURBSX_FILES", list)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mut map = std::collections::HashMap::new();
    for line in stdout.lines() {
        if let Some(json) = line.strip_prefix("reimport_faces: ") {
            let v: Value = serde_json::from_str(json).unwrap();
            map.insert(v["file"].as_str().unwrap().to_owned(), v);
        }
    }
    assert_eq!(
        map.len(),
        files.len(),
        "FreeCAD read {} of {} files:\n{stdout}",
        map.len(),
        files.len()
    );
    map
}

/// Samples whose re-import area or volume differs from the source's beyond FreeCAD's
/// measuring error. (The single rational B-spline faces with a degenerate side or closed in
/// both directions once listed here agree since the pcurves are computed exactly.)
const AREA_GAPS: &[&str] = &[
    // Rational faces of analytic sources whose difference is above FreeCAD's measuring
    // error on Open CASCADE's own NURBS form of the shape (a 90-degree cylinder converts to
    // one span there) though of the order of that error on other forms: not yet separated
    // from a real difference.
    "analytic/cylinder_partial.step",
    "analytic/units_inch.step",
    "analytic/units_metre.step",
    // A whole sphere written as a face without bounds: area within FreeCAD's measuring
    // error, volume 9e-3 off (its error on Open CASCADE's own NURBS sphere: 4e-4).
    "analytic/sphere.step",
];

/// STEP -> nurbsx -> STEP, re-imported by FreeCAD: the same number of faces, shells and
/// solids, valid solids, and total area and volume within 1e-6 relative of FreeCAD's
/// reading of the source file, plus twice FreeCAD's own measuring error on NURBS geometry
/// (its reading of the source converted to NURBS by Open CASCADE, against the source: zero
/// for B-spline sources, up to 2e-2 for analytic ones, since Open CASCADE integrates
/// rational faces with a fixed Gauss rule).
#[test]
fn freecad_reimports_the_written_parts() {
    let Some(freecadcmd) = find_freecadcmd() else {
        if std::env::var("NURBSX_REQUIRE_FREECAD").as_deref() == Ok("1") {
            panic!("FreeCAD required (NURBSX_REQUIRE_FREECAD=1) but freecadcmd is not on PATH");
        }
        eprintln!("SKIPPED step_topology FreeCAD re-import: freecadcmd not on PATH");
        return;
    };
    let work = std::env::temp_dir().join(format!("nurbsx-step-topology-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    let mut pairs = Vec::new();
    for (path, _) in samples() {
        if gap(&path).is_some() {
            continue;
        }
        let doc = read_path(&path);
        let text = exchange::write(&doc, Format::Step, &ExportOptions::default()).unwrap();
        let parent = path
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy();
        let out = work.join(format!("{parent}_{}", name(&path)));
        std::fs::write(&out, text).unwrap();
        pairs.push((path, out));
    }
    let files: Vec<PathBuf> = pairs
        .iter()
        .flat_map(|(a, b)| [a.clone(), b.clone()])
        .collect();
    let readings = freecad_readings(&freecadcmd, &files);
    let mut failures = Vec::new();
    println!(
        "{:<34} {:>6} {:>6} {:>16} {:>10} {:>10} {:>16} {:>10} {:>10}",
        "sample",
        "faces",
        "solids",
        "area (source)",
        "rel. diff",
        "FC error",
        "volume (source)",
        "rel. diff",
        "FC error"
    );
    for (src, out) in &pairs {
        let a = &readings[&src.display().to_string()];
        let b = &readings[&out.display().to_string()];
        if b.get("error").is_some() {
            failures.push(format!(
                "{}: FreeCAD cannot read the output: {}",
                name(src),
                b["error"]
            ));
            continue;
        }
        let f = |v: &Value, k: &str| v[k].as_f64().unwrap();
        let rel = |x: f64, y: f64| {
            if x == y {
                0.0
            } else {
                (x - y).abs() / x.abs().max(y.abs())
            }
        };
        let darea = rel(f(a, "area"), f(b, "area"));
        let dvol = rel(f(a, "volume"), f(b, "volume"));
        // FreeCAD integrates rational B-spline faces with a fixed Gauss rule: its reading
        // of the source converted to NURBS by Open CASCADE itself differs from its reading
        // of the analytic source by this much, which bounds what it can tell apart.
        let measuring = |k: &str, nk: &str| rel(f(a, k), f(a, nk));
        let (earea, evol) = (
            measuring("area", "nurbs_area"),
            measuring("volume", "nurbs_volume"),
        );
        println!(
            "{:<34} {:>3}/{:<3} {:>2}/{:<3} {:>16.9} {:>10.1e} {:>10.1e} {:>16.9} {:>10.1e} {:>10.1e}",
            name(src),
            b["faces"],
            a["faces"],
            b["solids"],
            a["solids"],
            f(a, "area"),
            darea,
            earea,
            f(a, "volume"),
            dvol,
            evol
        );
        if a["faces"] != b["faces"]
            || a["solids"] != b["solids"]
            || a["shells"] != b["shells"]
            || b["solids_valid"] != Value::Bool(true)
        {
            failures.push(format!("{}: source {a} output {b}", name(src)));
        }
        let known = AREA_GAPS.contains(&qualified(src).as_str());
        let off = darea > 1e-6 + 2.0 * earea || dvol > 1e-6 + 2.0 * evol;
        if off && !known {
            failures.push(format!(
                "{}: area/volume off: source {a} output {b}",
                name(src)
            ));
        }
        if known && !off {
            failures.push(format!(
                "{}: listed in AREA_GAPS but now agrees: unlist it",
                name(src)
            ));
        }
    }
    // The outputs stay for a look only when something failed.
    if failures.is_empty() {
        let _ = std::fs::remove_dir_all(&work);
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Read, write, read, write, read: the second and third readings hold bit-identical
/// geometry (the poles, knots and weights of every face surface and edge curve) and the
/// same topology.
#[test]
fn step_step_step_is_bit_identical() {
    for (path, _) in samples() {
        if gap(&path).is_some() {
            continue;
        }
        let once = read_path(&path);
        let write = |d: &Document| {
            let text = exchange::write(d, Format::Step, &ExportOptions::default()).unwrap();
            exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap()
        };
        let twice = write(&once);
        let thrice = write(&twice);
        let (a, b) = (&twice.topology.model, &thrice.topology.model);
        assert_eq!(ours(&twice), ours(&once), "{}", path.display());
        assert_eq!(ours(&thrice), ours(&twice), "{}", path.display());
        for (x, y) in a.faces.iter().zip(&b.faces) {
            assert_eq!(x.surface, y.surface, "{}", path.display());
            assert_eq!(x.same_sense, y.same_sense, "{}", path.display());
        }
        for (x, y) in a.edges.iter().zip(&b.edges) {
            assert_eq!(x.curve, y.curve, "{}", path.display());
        }
        // The first write keeps the source's geometry too (up to the order of entities).
        for (x, y) in once.topology.model.edges.iter().zip(&a.edges) {
            assert_eq!(
                x.curve.control_points(),
                y.curve.control_points(),
                "{}",
                path.display()
            );
        }
    }
}

fn cylinder_partial() -> String {
    std::fs::read_to_string(root().join("samples/freecad/analytic/cylinder_partial.step")).unwrap()
}

/// A face loop with an oriented edge left out: a located `topology.loop_open` error on that
/// face; the face is skipped, the closed shell then misses it (located
/// `topology.shell_open`, kept open) and the solid is refused (`topology.solid_shell_open`);
/// the other faces are read.
#[test]
fn damaged_loop_is_located() {
    let text = cylinder_partial();
    // The first EDGE_LOOP of the file, with its first oriented edge removed.
    let start = text.find("EDGE_LOOP('',(").unwrap() + "EDGE_LOOP('',(".len();
    let comma = start + text[start..].find(',').unwrap();
    let damaged = format!("{}{}", &text[..start], &text[comma + 1..]);
    let loop_line = text[..start].lines().count();
    let doc = exchange::read(damaged.as_bytes(), &ImportOptions::default()).unwrap();
    let d = doc
        .diagnostics
        .iter()
        .find(|d| d.code == "topology.loop_open")
        .expect("topology.loop_open");
    assert_eq!(d.severity, Severity::Error);
    // Located at the face that uses the loop, a few lines above the loop.
    let line = d.location.line.unwrap();
    assert!(
        line < loop_line && line + 3 >= loop_line,
        "{line} vs loop at {loop_line}"
    );
    assert!(d.location.entity.as_deref().unwrap().starts_with('#'));
    assert!(
        doc.diagnostics
            .iter()
            .any(|d| d.code == "topology.shell_open")
    );
    assert!(
        doc.diagnostics
            .iter()
            .any(|d| d.code == "topology.solid_shell_open")
    );
    assert_eq!(doc.topology.model.faces.len(), 4);
    assert_eq!(doc.topology.model.solids.len(), 0);
    assert!(!doc.topology.model.shells[0].closed);
}

/// A CLOSED_SHELL with a face missing from its list: located at the shell, kept as an open
/// shell, and the solid on it is refused with its own located error.
#[test]
fn closed_shell_with_a_missing_face_is_located() {
    let text = cylinder_partial();
    let at = text.find("CLOSED_SHELL('',(").unwrap() + "CLOSED_SHELL('',(".len();
    let comma = at + text[at..].find(',').unwrap();
    let damaged = format!("{}{}", &text[..at], &text[comma + 1..]);
    let shell_line = text[..at].lines().count();
    let doc = exchange::read(damaged.as_bytes(), &ImportOptions::default()).unwrap();
    let d = doc
        .diagnostics
        .iter()
        .find(|d| d.code == "topology.shell_open")
        .expect("topology.shell_open");
    assert_eq!(d.severity, Severity::Error);
    assert_eq!(d.location.line, Some(shell_line));
    assert!(d.message.contains("kept as an open shell"), "{}", d.message);
    let s = doc
        .diagnostics
        .iter()
        .find(|d| d.code == "topology.solid_shell_open")
        .expect("solid refused");
    assert!(s.location.line.unwrap() < shell_line);
    let m = &doc.topology.model;
    assert_eq!((m.faces.len(), m.shells.len(), m.solids.len()), (5, 1, 0));
    assert_eq!(m.shells[0].faces.len(), 4);
    assert!(!m.shells[0].closed);
}

/// `geometry_only`: no topology, one visible warning with the counts, the same entities.
#[test]
fn geometry_only_says_what_it_left_out() {
    let text = cylinder_partial();
    let full = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    let options = ImportOptions {
        geometry_only: true,
        ..ImportOptions::default()
    };
    let doc = exchange::read(text.as_bytes(), &options).unwrap();
    assert!(doc.topology.is_empty());
    assert_eq!(doc.entities, full.entities);
    let w: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.code == "topology.not_read")
        .collect();
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].severity, Severity::Warning);
    assert!(
        w[0].message
            .contains("5 face(s), 9 edge(s), 1 shell(s) and 1 solid(s)"),
        "{}",
        w[0].message
    );
}

/// The written text with one face of the closed shell turned over: its ADVANCED_FACE's
/// `same_sense` and every bound's orientation flipped (the face's other side), and, when
/// `wrap`, named in the shell through `ORIENTED_FACE(.F.)` so the shell holds the same
/// oriented face as before (ISO 10303-42 oriented_face).
fn with_face_turned_over(text: &str, wrap: bool) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let shell = lines
        .iter()
        .position(|l| l.contains("= CLOSED_SHELL("))
        .unwrap();
    let face = lines[shell]
        .split("',(")
        .nth(1)
        .unwrap()
        .split([',', ')'])
        .next()
        .unwrap()
        .to_string();
    let head = format!("{face} = ADVANCED_FACE(");
    let at = lines.iter().position(|l| l.starts_with(&head)).unwrap();
    let bounds: Vec<String> = lines[at]
        .split("',(")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let flip = |l: &str| {
        let (body, last) = l.rsplit_once(',').unwrap();
        let turned = if last.starts_with(".T.") {
            ".F.);"
        } else {
            ".T.);"
        };
        format!("{body},{turned}")
    };
    let next_id = 1 + text
        .lines()
        .filter_map(|l| l.strip_prefix('#')?.split(' ').next()?.parse::<u64>().ok())
        .max()
        .unwrap();
    let mut out = Vec::with_capacity(lines.len() + 1);
    for (i, l) in lines.iter().enumerate() {
        let id = l.split(' ').next().unwrap_or("");
        if i == at || bounds.iter().any(|b| b == id) {
            out.push(flip(l));
        } else if i == shell && wrap {
            out.push(format!("#{next_id} = ORIENTED_FACE('',*,{face},.F.);"));
            out.push(l.replacen(&format!("',({face},"), &format!("',(#{next_id},"), 1));
        } else {
            out.push(l.to_string());
        }
    }
    out.join("\n")
}

/// ORIENTED_FACE in a closed shell (ISO 10303-42 oriented_face) is read as the face it
/// reverses: the solid still closes, with the same volume; the same face turned over
/// without it leaves the shell open (so the check can fail).
#[test]
fn oriented_face_in_a_closed_shell_is_read() {
    let src = read_path(&root().join("samples/freecad/parts/loft_bspline.step"));
    let volume = src
        .topology
        .model
        .solid_volume(nurbsx::topology::SolidId(0))
        .unwrap();
    let text = exchange::write(&src, Format::Step, &ExportOptions::default()).unwrap();
    let wrapped = with_face_turned_over(&text, true);
    assert!(wrapped.contains("ORIENTED_FACE"));
    let doc = exchange::read(wrapped.as_bytes(), &ImportOptions::default()).unwrap();
    let m = &doc.topology.model;
    assert_eq!(m.solids.len(), 1, "{:?}", doc.diagnostics);
    let v = m.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
    assert!((v - volume).abs() <= 1e-9 * volume, "{v} vs {volume}");
    let bare = with_face_turned_over(&text, false);
    let doc = exchange::read(bare.as_bytes(), &ImportOptions::default()).unwrap();
    assert_eq!(doc.topology.model.solids.len(), 0);
    assert!(
        doc.diagnostics
            .iter()
            .any(|d| d.code == "topology.shell_open")
    );
}

/// A face a shell uses reversed (IGES 514 orientation flag 0) is written as an
/// ADVANCED_FACE turned over, not through ORIENTED_FACE (which Open CASCADE drops from a
/// closed shell): FreeCAD's B-rep-mode loft has such faces; the STEP re-reads as the same
/// closed solid.
#[test]
fn faces_used_reversed_are_written_turned_over() {
    let path = root().join("samples/freecad/parts/loft_bspline_brep.igs");
    let src = read_path(&path);
    let m = &src.topology.model;
    assert!(
        m.shells
            .iter()
            .any(|s| s.faces.iter().any(|&(_, same)| !same)),
        "the sample no longer has a face used reversed"
    );
    let volume = m.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
    let text = exchange::write(&src, Format::Step, &ExportOptions::default()).unwrap();
    assert!(!text.contains("ORIENTED_FACE"));
    let doc = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    assert_eq!(ours(&doc), ours(&src));
    let v = doc
        .topology
        .model
        .solid_volume(nurbsx::topology::SolidId(0))
        .unwrap();
    assert!((v - volume).abs() <= 1e-9 * volume, "{v} vs {volume}");
}

/// Open CASCADE writes every bound of a face as a plain FACE_BOUND; the bound that
/// contains the others is the outer one (ISO 10303-42 face_bound), and the IGES 144
/// written from it names it as its outer boundary (N1 = 1, PTO): FreeCAD's lone trimmed
/// face with a hole keeps its hole through STEP -> IGES.
#[test]
fn outer_bound_is_found_when_not_declared() {
    let path = root().join("samples/freecad/parts/trimmed_face.step");
    assert!(
        !std::fs::read_to_string(&path)
            .unwrap()
            .contains("FACE_OUTER_BOUND")
    );
    let doc = read_path(&path);
    let face = &doc.topology.model.faces[0];
    let outer: Vec<usize> = face
        .loops
        .iter()
        .filter(|l| l.outer)
        .map(|l| l.coedges.len())
        .collect();
    // The rectangle (4 edges) bounds the hole (2 edges).
    assert_eq!(outer, vec![4]);
    let iges = exchange::write(&doc, Format::Iges, &ExportOptions::default()).unwrap();
    let back = exchange::read(iges.as_bytes(), &ImportOptions::default()).unwrap();
    let f = &back.topology.model.faces[0];
    assert_eq!(f.loops.len(), 2);
    assert_eq!(
        f.loops
            .iter()
            .filter(|l| l.outer)
            .map(|l| l.coedges.len())
            .collect::<Vec<_>>(),
        vec![4]
    );
    let freecad: Value =
        serde_json::from_str(&std::fs::read_to_string(path.with_extension("step.json")).unwrap())
            .unwrap();
    let want = freecad["faces"][0]["area"].as_f64().unwrap();
    let area = back.topology.model.measure_face(f).unwrap().area;
    assert!((area - want).abs() <= 1e-6 * want, "{area} vs {want}");
}

/// The file's length uncertainty (ISO 10303-43 `global_uncertainty_assigned_context`) is
/// the tolerance of its topology when it is larger than nurbsx's own (1e-7 of the part):
/// the filleted box with one vertex moved 1e-5 off its edges is refused under the file's
/// 1e-7 and read as the whole solid under a declared 1e-4; an absurd uncertainty (1e3 on
/// a 40 mm part) is ignored with a warning. And nurbsx writes the model's tolerance as the
/// uncertainty, so what it joined is joined again on re-reading.
#[test]
fn the_files_uncertainty_is_the_topology_tolerance() {
    let text =
        std::fs::read_to_string(root().join("samples/freecad/parts/box_fillet_chamfer_hole.step"))
            .unwrap();
    let vertex = "#23 = CARTESIAN_POINT('',(-1.110223024625E-16,4.,1.5));";
    let uncertainty = "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07)";
    assert!(
        text.contains(vertex) && text.contains(uncertainty),
        "sample changed"
    );
    let moved = text.replace(vertex, "#23 = CARTESIAN_POINT('',(1.E-05,4.,1.5));");
    let read = |t: &str| exchange::read(t.as_bytes(), &ImportOptions::default()).unwrap();
    let errors = |d: &Document| {
        d.diagnostics
            .iter()
            .filter(|x| x.severity == Severity::Error)
            .count()
    };
    let declared = |d: &Document| d.topology.model.solids.len();

    let strict = read(&moved);
    assert!(errors(&strict) > 0);
    assert_eq!(declared(&strict), 0);

    let loose = read(&moved.replace(
        uncertainty,
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-04)",
    ));
    assert_eq!(errors(&loose), 0, "{:?}", loose.diagnostics);
    assert_eq!(declared(&loose), 1);
    assert_eq!(loose.topology.model.faces.len(), 19);

    let absurd = read(&moved.replace(
        uncertainty,
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E+03)",
    ));
    assert!(
        absurd
            .diagnostics
            .iter()
            .any(|d| d.code == "step.uncertainty_ignored" && d.severity == Severity::Warning),
        "{:?}",
        absurd.diagnostics
    );
    assert_eq!(declared(&absurd), 0);

    // Written back: the uncertainty is the model's tolerance, and the re-read is whole.
    let out = exchange::write(&loose, Format::Step, &ExportOptions::default()).unwrap();
    assert!(out.contains("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.0001)"));
    let again = read(&out);
    assert_eq!(errors(&again), 0, "{:?}", again.diagnostics);
    assert_eq!(declared(&again), 1);
}

/// The conformance check of orientation: a MANIFOLD_SOLID_BREP whose outer shell is an
/// ORIENTED_CLOSED_SHELL turned over (every face normal into the solid) is a located
/// `topology.inside_out` violation (an error in `validate`, nothing in plain reading); the
/// file as FreeCAD wrote it has none.
#[test]
fn inside_out_solid_is_a_violation() {
    let path = root().join("samples/freecad/parts/box_fillet_chamfer_hole.step");
    let text = std::fs::read_to_string(path).unwrap();
    let conformance = ImportOptions {
        conformance: true,
        ..ImportOptions::default()
    };
    let doc = exchange::read(text.as_bytes(), &conformance).unwrap();
    assert!(
        !doc.diagnostics
            .iter()
            .any(|d| d.code == "topology.inside_out"),
        "{:?}",
        doc.diagnostics
    );
    let turned = text.replace(
        "#15 = MANIFOLD_SOLID_BREP('',#16);",
        "#15 = MANIFOLD_SOLID_BREP('',#9000);\n#9000 = ORIENTED_CLOSED_SHELL('',*,#16,.F.);",
    );
    assert_ne!(turned, text);
    let doc = exchange::read(turned.as_bytes(), &conformance).unwrap();
    let found: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.code == "topology.inside_out")
        .collect();
    assert_eq!(found.len(), 1, "{:?}", doc.diagnostics);
    assert_eq!(found[0].location.entity.as_deref(), Some("#15"));
    assert_eq!(found[0].clone().for_conformance().severity, Severity::Error);
    assert_eq!(doc.topology.model.solids.len(), 1);
    let v = doc
        .topology
        .model
        .solid_volume(nurbsx::topology::SolidId(0))
        .unwrap();
    assert!(v < 0.0, "{v}");
    let plain = exchange::read(turned.as_bytes(), &ImportOptions::default()).unwrap();
    assert!(
        !plain
            .diagnostics
            .iter()
            .any(|d| d.code == "topology.inside_out")
    );
}

/// A sphere split into lunes by meridians, one of them on the NURBS sphere's seam
/// (`samples/public/catia_head_front.stp`, CATIA V5: a hemispherical shell of radii
/// R = 2.36220472441 and r = 2.32283464567 in, cut by the plane of its axis into two
/// lunes per sphere). A meridian on the seam used once by a face goes on the side the
/// face's orientation asks for (ISO 10303-42 face_bound: the interior on the left about the
/// face normal), so each lune measures a quarter sphere, pi R^2 (not three quarters, to
/// 1e-9), and the solid the shell volume 2/3 pi (R^3 - r^3) with its faces outward, within
/// 1e-6 as the part tests bound projected pcurves: the file's meridians and its plane's
/// circles are degree-5 B-splines that only approximate great circles (its planar annulus
/// is 2e-7 larger than pi (R^2 - r^2)), and the flux of the plane face, 9.84 in off the
/// origin, amplifies that.
#[test]
fn a_lune_bounded_by_the_seam_meridian_is_not_its_complement() {
    let doc = read_path(&root().join("samples/public/catia_head_front.stp"));
    let m = &doc.topology.model;
    let (big, small) = (2.36220472441f64, 2.32283464567f64);
    let pi = std::f64::consts::PI;
    let mut quarters = 0;
    for face in &m.faces {
        let area = m.measure_face(face).unwrap().area;
        for r in [big, small] {
            if (area - pi * r * r).abs() <= 1e-9 * area {
                quarters += 1;
            }
        }
        assert!(area < 2.0 * pi * big * big, "a face of {area} in2");
    }
    assert_eq!(
        quarters, 4,
        "each of the four sphere faces is a quarter sphere"
    );
    assert_eq!(m.solids.len(), 1);
    let v = m.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
    let want = 2.0 / 3.0 * pi * (big.powi(3) - small.powi(3));
    assert!((v - want).abs() <= 1e-6 * want, "{v} vs {want}");
}

/// A cylinder whose face seam lies on a vertex a few ulps off the NURBS cylinder's knot at
/// pi (`samples/public/autodesk_atf_obstructed_hole.step`, Autodesk Translation Framework:
/// vertex x = 2.449e-15 where the pole has -2.449e-15): the seam moved to that vertex is
/// moved to the knot, so every coedge gets its pcurve and the solid has FreeCAD's volume
/// (Open CASCADE `BRepGProp`, 377886.16715 mm3, within 1e-6 as the part tests bound
/// projected pcurves).
#[test]
fn a_seam_moved_to_a_vertex_an_ulp_off_a_knot_keeps_every_pcurve() {
    let doc = read_path(&root().join("samples/public/autodesk_atf_obstructed_hole.step"));
    assert!(
        doc.diagnostics
            .iter()
            .all(|d| d.code != "pcurve.not_computed"),
        "{:?}",
        doc.diagnostics
    );
    let m = &doc.topology.model;
    assert_eq!(m.solids.len(), 1);
    let v = m.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
    let want = 377886.16715;
    assert!((v - want).abs() <= 1e-6 * want, "{v} vs {want}");
}

/// Every instance of a STEP text by id: its keyword and the instances it references, in
/// order, found in the text itself (one instance per `;`), apart from the reader.
fn instances_of(text: &str) -> std::collections::HashMap<u64, (String, Vec<u64>)> {
    let data = &text[text.find("DATA;").unwrap()..];
    let mut body = std::collections::HashMap::new();
    for statement in data.split(';') {
        let Some((head, rest)) = statement.split_once('=') else {
            continue;
        };
        let Ok(id) = head.trim().trim_start_matches('#').parse::<u64>() else {
            continue;
        };
        let keyword: String = rest
            .trim()
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        let refs = rest
            .split('#')
            .skip(1)
            .filter_map(|s| {
                let digits: String = s.chars().take_while(char::is_ascii_digit).collect();
                digits.parse().ok()
            })
            .collect();
        body.insert(id, (keyword, refs));
    }
    body
}

/// The file's PCURVEs of each EDGE_CURVE, as the text says (ISO 10303-42 edge_curve ->
/// surface_curve or seam_curve -> pcurve -> definitional_representation): (edge, the
/// pcurve's surface, the 2-D curve), in text order of the edges' lists.
fn edge_pcurves_in(
    body: &std::collections::HashMap<u64, (String, Vec<u64>)>,
) -> Vec<(u64, u64, u64)> {
    let mut out = Vec::new();
    let mut edges: Vec<u64> = body
        .iter()
        .filter(|(_, (k, _))| k == "EDGE_CURVE")
        .map(|(&id, _)| id)
        .collect();
    edges.sort_unstable();
    for edge in edges {
        let refs = &body[&edge].1;
        let Some((k, curve_refs)) = body.get(&refs[2]) else {
            continue;
        };
        if k != "SURFACE_CURVE" && k != "SEAM_CURVE" {
            continue;
        }
        for pcurve in &curve_refs[1..] {
            let (k, p) = &body[pcurve];
            assert_eq!(k, "PCURVE");
            let (k, items) = &body[&p[1]];
            assert_eq!(k, "DEFINITIONAL_REPRESENTATION");
            for &c in &items[..items.len() - 1] {
                out.push((edge, p[0], c));
            }
        }
    }
    out
}

/// `#N` -> N.
fn instance(label: &str) -> u64 {
    label.trim_start_matches('#').parse().unwrap()
}

/// A whole-part read carries every coedge's pcurve, computed on the face's NURBS surface;
/// the file's own PCURVE curves are then no entities of their own. On a part of B-spline
/// faces the two are in the same parameters: each coedge's pcurve runs where the file's
/// PCURVE curve on that face's surface runs (compared on the surface, at the edge's
/// parameters, within the edge's tolerance). The file's curves are read as entities with
/// `geometry_only` (ISO 10303-42 surface_curve -> pcurve -> definitional_representation
/// followed in the text itself).
#[test]
fn coedge_pcurves_run_where_the_files_pcurves_do() {
    let path = root().join("samples/freecad/brep_filleted_box_nurbs.step");
    let text = std::fs::read_to_string(&path).unwrap();
    let body = instances_of(&text);
    let pairs = edge_pcurves_in(&body);
    assert!(pairs.len() >= 96, "{} pcurves", pairs.len());
    let doc = read_path(&path);
    let loose = exchange::read(
        text.as_bytes(),
        &ImportOptions {
            geometry_only: true,
            ..ImportOptions::default()
        },
    )
    .unwrap();
    let file_curve = |id: u64| {
        loose
            .entities
            .iter()
            .find(|e| e.id == format!("#{id}"))
            .and_then(|e| match &e.geometry {
                nurbsx::nurbs::Geometry::Curve(c) if c.dimension() == 2 => Some(c.clone()),
                _ => None,
            })
            .unwrap_or_else(|| panic!("#{id} is a 2-D curve read as geometry only"))
    };
    for &(_, _, c) in &pairs {
        assert!(
            !doc.entities.iter().any(|e| e.id == format!("#{c}")),
            "#{c} is a coedge's pcurve, not an entity"
        );
    }
    let (m, o) = (&doc.topology.model, &doc.topology.origins);
    let mut compared = 0;
    for (f, face) in m.faces.iter().enumerate() {
        // ADVANCED_FACE(name, bounds, face_geometry, same_sense): the surface is its last
        // reference.
        let surface = *body[&instance(&o.faces[f].id)].1.last().unwrap();
        for c in face.loops.iter().flat_map(|l| &l.coedges) {
            let edge = &m.edges[c.edge.0];
            let id = instance(&o.edges[c.edge.0].id);
            let files: Vec<u64> = pairs
                .iter()
                .filter(|&&(e, s, _)| e == id && s == surface)
                .map(|&(_, _, c)| c)
                .collect();
            assert_eq!(files.len(), 1, "edge #{id} on #{surface}");
            let theirs = file_curve(files[0]);
            let ours = c
                .pcurve
                .as_ref()
                .expect("every coedge of the box has a pcurve");
            let (a, b) = edge.range;
            for k in 0..=16 {
                let t = a + (b - a) * k as f64 / 16.0;
                let (p, q) = (ours.point_at(t).unwrap(), theirs.point_at(t).unwrap());
                // The file's values may be a rounding outside the domain.
                let ((u0, u1), (v0, v1)) = face.surface.domain();
                let on = |p: nurbsx::nurbs::Point3| {
                    face.surface
                        .point_at(p[0].clamp(u0, u1), p[1].clamp(v0, v1))
                        .unwrap()
                };
                let d = nurbsx::nurbs::distance(on(p), on(q));
                assert!(
                    d <= edge.tolerance,
                    "edge #{id} on #{surface} at {t}: {d:e}"
                );
            }
            compared += 1;
        }
    }
    assert_eq!(compared, 96);
}

/// The file's PCURVE curves of an edge the topology does not carry with pcurves are
/// entities: those of an edge refused (a vertex missing), free; those of an edge all of
/// whose faces are refused (their surfaces missing, or an edge of theirs), used by the edge.
/// No other PCURVE curve is.
#[test]
fn pcurves_of_edges_without_coedge_pcurves_are_entities() {
    let path = root().join("samples/freecad/brep_filleted_box_nurbs.step");
    let mut text = std::fs::read_to_string(&path).unwrap();
    let body = instances_of(&text);
    let pairs = edge_pcurves_in(&body);
    // The faces using each edge, through their loops' oriented edges.
    let faces_of = |edge: u64| -> Vec<u64> {
        let mut out: Vec<u64> = body
            .iter()
            .filter(|(_, (k, _))| k == "ADVANCED_FACE")
            .filter(|(_, (_, refs))| {
                refs[..refs.len() - 1].iter().any(|bound| {
                    body[&body[bound].1[0]]
                        .1
                        .iter()
                        .any(|oe| body[oe].1[0] == edge)
                })
            })
            .map(|(&id, _)| id)
            .collect();
        out.sort_unstable();
        out
    };
    let mut edges: Vec<u64> = pairs.iter().map(|&(e, _, _)| e).collect();
    edges.dedup();
    let refused = edges[0];
    let near: Vec<u64> = faces_of(refused);
    // An edge away from the refused edge's faces.
    let unused = *edges
        .iter()
        .find(|&&e| faces_of(e).iter().all(|f| !near.contains(f)))
        .unwrap();
    let replace = |text: &mut String, id: u64, from: &str, to: &str| {
        let head = format!("#{id} = ");
        let at = text.find(&head).unwrap();
        let end = at + text[at..].find(';').unwrap();
        let statement = text[at..end].replacen(from, to, 1);
        assert_ne!(statement, text[at..end]);
        text.replace_range(at..end, &statement);
    };
    let (keyword, refs) = &body[&refused];
    assert_eq!(keyword, "EDGE_CURVE");
    replace(&mut text, refused, &format!("#{},", refs[0]), "#999999,");
    for f in faces_of(unused) {
        let surface = *body[&f].1.last().unwrap();
        replace(&mut text, f, &format!("#{surface},"), "#999998,");
    }
    let doc = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    let mut found: Vec<(u64, Vec<String>)> = doc
        .entities
        .iter()
        .filter(|e| pairs.iter().any(|&(_, _, c)| e.id == format!("#{c}")))
        .map(|e| {
            let users = e.meta.used_by.iter().map(|u| u.to_string()).collect();
            (instance(&e.id), users)
        })
        .collect();
    found.sort();
    // Refused: the faces of the refused edge and of the edge whose surfaces are missing.
    // An edge all of whose faces are refused has no coedge left.
    let refused_faces: Vec<u64> = near.iter().chain(&faces_of(unused)).copied().collect();
    let mut expected: Vec<(u64, Vec<String>)> = pairs
        .iter()
        .filter_map(|&(e, _, c)| {
            if e == refused {
                Some((c, Vec::new()))
            } else if faces_of(e).iter().all(|f| refused_faces.contains(f)) {
                Some((c, vec![format!("#{e}")]))
            } else {
                None
            }
        })
        .collect();
    expected.sort();
    assert!(expected.len() >= 4, "{expected:?}");
    assert!(
        expected
            .iter()
            .any(|(_, users)| users == &[format!("#{unused}")])
    );
    assert_eq!(found, expected);
    let d = &doc.diagnostics;
    assert!(d.iter().any(|d| d.code == "topology.missing"), "{d:?}");
}

/// Every topological item's origin, and every entity, names its instance as the file does: for `#N`, the line
/// where `#N =` starts, the keyword written there (simple instances) and the name string
/// when it is not empty, found here by reading the text line by line (an oracle apart from
/// the reader's index and line table). The origins are read after the model is built, in
/// instance order, and copied to the halves of edges split at a seam: these are checked
/// the same way. The samples' items have empty names: a copy of each with every face,
/// edge, vertex and shell named checks the names.
#[test]
fn origins_name_their_instance_line_keyword_and_name() {
    let (mut checked, mut named) = (0, 0);
    for (path, _) in samples() {
        let text = std::fs::read_to_string(&path).unwrap();
        let label = path.display().to_string();
        checked += check_origins(&label, &text).0;
        let mut renamed = text.clone();
        for keyword in [
            "ADVANCED_FACE",
            "EDGE_CURVE",
            "VERTEX_POINT",
            "CLOSED_SHELL",
            "OPEN_SHELL",
            "PLANE",
            "CYLINDRICAL_SURFACE",
            "CIRCLE",
            "LINE",
            "B_SPLINE_CURVE_WITH_KNOTS",
            "B_SPLINE_SURFACE_WITH_KNOTS",
        ] {
            let mut k = 0;
            let pattern = format!("{keyword}(''");
            while let Some(p) = renamed.find(&pattern) {
                k += 1;
                renamed.replace_range(p..p + pattern.len(), &format!("{keyword}('{keyword} {k}'"));
            }
        }
        named += check_origins(&format!("{label} (named)"), &renamed).1;
    }
    assert!(checked > 500, "only {checked} origins checked");
    assert!(named > 500, "only {named} names checked");
    eprintln!("{checked} origins and entities checked, {named} names");
}

/// Checks the origins of the document read from `text` against the text (see above):
/// (origins checked, names checked).
fn check_origins(label: &str, text: &str) -> (usize, usize) {
    // id -> (line, the text from where the statement starts)
    let mut at: std::collections::HashMap<u64, (usize, &str)> = Default::default();
    let mut offset = 0;
    for (k, line) in text.split('\n').enumerate() {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix('#') {
            let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
            if let Ok(id) = digits.parse::<u64>() {
                if rest[digits.len()..].trim_start().starts_with('=') {
                    at.entry(id).or_insert((k + 1, &text[offset..]));
                }
            }
        }
        offset += line.len() + 1;
    }
    let doc = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    let o = &doc.topology.origins;
    // (label, line, entity type, name) of every origin and every entity.
    let origins = o
        .vertices
        .iter()
        .chain(&o.edges)
        .chain(&o.faces)
        .chain(&o.shells)
        .chain(&o.solids)
        .map(|x| (&x.id, x.source.line, &x.source.entity, &x.name));
    let entities = doc
        .entities
        .iter()
        .map(|e| (&e.id, e.source.line, &e.source.entity, &e.meta.name));
    let (mut checked, mut named) = (0, 0);
    for (id_label, found_line, entity, found_name) in origins.chain(entities) {
        let Some(id) = id_label
            .strip_prefix('#')
            .and_then(|d| d.parse::<u64>().ok())
        else {
            continue;
        };
        let &(line, statement) = at
            .get(&id)
            .unwrap_or_else(|| panic!("{label}: {id_label} is no instance"));
        assert_eq!(found_line, Some(line), "{label}: line of {id_label}");
        let body = statement.split_once('=').unwrap().1.trim_start();
        if !body.starts_with('(') {
            let keyword = body.split('(').next().unwrap().trim();
            assert_eq!(entity, keyword, "{label}: {id_label}");
            let first = body[keyword.len()..].trim_start().trim_start_matches('(');
            if let Some(quoted) = first.trim_start().strip_prefix('\'') {
                let name = quoted.split('\'').next().unwrap();
                if quoted.starts_with("''") {
                    // An empty name, or one starting with an escaped quote: not checked.
                } else if name.is_empty() {
                    assert_eq!(found_name, &None, "{label}: {id_label}");
                } else if !name.contains('\\') {
                    assert_eq!(found_name.as_deref(), Some(name), "{label}: {id_label}");
                    named += 1;
                }
            }
        }
        checked += 1;
    }
    (checked, named)
}

/// A surface several faces share (CATIA V5 splits faces on one surface: 16 faces on 9
/// surfaces here) is written once, as read, to STEP and to IGES (144 and 186), so that
/// read -> write -> read lists the same entities; every face still names a surface whose geometry is its own, bit for bit. An
/// edge between two faces on the shared surface is a SURFACE_CURVE with a pcurve for each
/// face; SEAM_CURVE stays for an edge one face uses twice (the cylinder sample's seam).
#[test]
fn a_surface_faces_share_is_written_once() {
    let path = root().join("samples/public/catia_sg1-c5-214.stp");
    let once = read_path(&path);
    let faces = once.topology.model.faces.len();
    let surfaces = |d: &Document| {
        d.entities
            .iter()
            .filter(|e| matches!(e.geometry, nurbsx::nurbs::Geometry::Surface(_)))
            .count()
    };
    assert!(
        surfaces(&once) < faces,
        "{} surfaces, {faces} faces",
        surfaces(&once)
    );
    let text = exchange::write(&once, Format::Step, &ExportOptions::default()).unwrap();
    let body = instances_of(&text);
    let faces_text = body.values().filter(|(k, _)| k == "ADVANCED_FACE").count();
    assert_eq!(faces_text, faces);
    // Every ADVANCED_FACE's surface, distinct ones counted.
    let face_surfaces: std::collections::BTreeSet<u64> = body
        .values()
        .filter(|(k, _)| k == "ADVANCED_FACE")
        .filter_map(|(_, refs)| refs.last().copied())
        .collect();
    assert_eq!(face_surfaces.len(), surfaces(&once));
    let twice = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    assert_eq!(twice.entities.len(), once.entities.len());
    assert_eq!(surfaces(&twice), surfaces(&once));
    for (x, y) in once
        .topology
        .model
        .faces
        .iter()
        .zip(&twice.topology.model.faces)
    {
        assert_eq!(x.surface, y.surface);
    }
    for t in [&once.topology, &twice.topology] {
        for (face, o) in t.model.faces.iter().zip(&t.origins.faces) {
            let label = o.entity.as_ref().unwrap();
            let e = [&once, &twice]
                .iter()
                .flat_map(|d| &d.entities)
                .find(|e| e.id == *label && matches!(&e.geometry, nurbsx::nurbs::Geometry::Surface(s) if *s == face.surface));
            assert!(e.is_some(), "face {} names {label}", o.id);
        }
    }
    // Edges between two faces on one surface are surface curves; no seam is invented.
    assert_eq!(text.matches("SEAM_CURVE").count(), 0);
    // IGES, as 144s and as a 186 B-rep: one 128 per shared surface, the same listing back.
    for iges_brep in [false, true] {
        let options = ExportOptions {
            iges_brep,
            ..ExportOptions::default()
        };
        let text = exchange::write(&once, Format::Iges, &options).unwrap();
        let surfaces_128 = text
            .lines()
            .filter(|l| l.len() == 80 && &l[72..73] == "D")
            .step_by(2)
            .filter(|l| l[..8].trim() == "128")
            .count();
        assert_eq!(surfaces_128, surfaces(&once), "iges_brep {iges_brep}");
        let back = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
        assert_eq!(
            back.entities.len(),
            once.entities.len(),
            "iges_brep {iges_brep}"
        );
        assert_eq!(back.topology.model.faces.len(), faces);
    }
    // A real seam stays one.
    let cylinder = read_path(&root().join("samples/freecad/analytic/cylinder_full.step"));
    let text = exchange::write(&cylinder, Format::Step, &ExportOptions::default()).unwrap();
    assert_eq!(text.matches("SEAM_CURVE").count(), 1);
}

/// Edges that share one curve, as read, are written over that curve once, each EDGE_CURVE
/// bounded by its own vertices (ISO 10303-42 edge_curve). Solid Edge writes cylinders
/// between two full circles without a seam edge; nurbsx's reader splits such circles where
/// the NURBS surface's seam crosses them (`topology.edge_split_at_seam`), and both halves
/// keep the circle the document lists. Written once per half, read -> write -> read listed
/// 52 entities for the file's 43; now the same 43, with the same edges and vertices.
#[test]
fn edges_sharing_a_curve_are_written_over_it_once() {
    let once = read_path(&root().join("samples/public/solidedge_sylinterin_tappi.stp"));
    let m = &once.topology.model;
    let o = &once.topology.origins;
    // Pairs of edges naming one entity and carrying its curve bit for bit.
    let mut by_label: std::collections::HashMap<&str, Vec<usize>> =
        std::collections::HashMap::new();
    for (k, origin) in o.edges.iter().enumerate() {
        by_label
            .entry(origin.entity.as_deref().unwrap())
            .or_default()
            .push(k);
    }
    // How many edges fewer the curves are: a curve three edges share saves two.
    let shared: usize = by_label
        .values()
        .filter(|ks| ks.iter().all(|&k| m.edges[k].curve == m.edges[ks[0]].curve))
        .map(|ks| ks.len() - 1)
        .sum();
    assert!(
        shared > 0,
        "no curve is shared by edges of the split sample"
    );
    let text = exchange::write(&once, Format::Step, &ExportOptions::default()).unwrap();
    let body = instances_of(&text);
    let edge_curves: Vec<u64> = body
        .values()
        .filter(|(k, _)| k == "EDGE_CURVE")
        .filter_map(|(_, refs)| refs.get(2).copied())
        .collect();
    assert_eq!(edge_curves.len(), m.edges.len());
    // The curves (or the SURFACE_CURVEs over them) the EDGE_CURVEs name: the 3-D curves.
    let curve_3d = |id: u64| match body.get(&id) {
        Some((k, refs)) if k == "SURFACE_CURVE" || k == "SEAM_CURVE" => refs[0],
        _ => id,
    };
    let distinct: std::collections::BTreeSet<u64> =
        edge_curves.iter().map(|&c| curve_3d(c)).collect();
    assert_eq!(distinct.len(), edge_curves.len() - shared);
    let twice = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    assert_eq!(twice.entities.len(), once.entities.len());
    let t = &twice.topology.model;
    assert_eq!(
        (
            t.faces.len(),
            t.edges.len(),
            t.vertices.len(),
            t.solids.len()
        ),
        (
            m.faces.len(),
            m.edges.len(),
            m.vertices.len(),
            m.solids.len()
        )
    );
}

/// Free edges (the curves of a GEOMETRIC_CURVE_SET in a product that an assembly places:
/// `ug_io1-tu-203.stp` has six full circles beside its solid) are written to IGES as
/// independent 126s, in both modes. Before, IGES had no place for an edge in no face and
/// dropped them without a word, while the summary said every entity was written; read back,
/// the file listed 101 entities for 107. Now each circle comes back as a curve bit for bit
/// the edge's.
#[test]
fn free_edges_are_written_to_iges() {
    let once = read_path(&root().join("samples/public/ug_io1-tu-203.stp"));
    let m = &once.topology.model;
    let mut in_face = vec![false; m.edges.len()];
    for c in m
        .faces
        .iter()
        .flat_map(|f| &f.loops)
        .flat_map(|l| &l.coedges)
    {
        in_face[c.edge.0] = true;
    }
    let free: Vec<&nurbsx::nurbs::NurbsCurve> = m
        .edges
        .iter()
        .zip(&in_face)
        .filter(|(_, f)| !**f)
        .map(|(e, _)| &e.curve)
        .collect();
    assert_eq!(free.len(), 6);
    for iges_brep in [false, true] {
        let options = ExportOptions {
            iges_brep,
            ..ExportOptions::default()
        };
        let text = exchange::write(&once, Format::Iges, &options).unwrap();
        let back = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
        assert_eq!(
            back.entities.len(),
            once.entities.len(),
            "iges_brep {iges_brep}"
        );
        for c in &free {
            assert!(
                back.entities
                    .iter()
                    .any(|e| matches!(&e.geometry, nurbsx::nurbs::Geometry::Curve(x) if x == *c)),
                "iges_brep {iges_brep}: a free circle did not come back"
            );
        }
    }
}

/// A VERTEX_LOOP bound (ISO 10303-42 vertex_loop: a sphere's pole, a cone's apex) is kept on
/// its face and written back: to STEP as a FACE_BOUND of a VERTEX_LOOP naming the vertex
/// (before, the face was written with no bound at all, which the schema's `bounds SET
/// [1:?]` forbids, beside a VERTEX_POINT nothing used), to IGES B-rep as a 508 loop of one
/// vertex use (TYPE = 1). Both read back with the vertex loop at the same point. A 144
/// cannot hold it: the IGES faces mode says so in a warning.
#[test]
fn vertex_loops_are_kept_and_written() {
    for (file, loops) in [
        ("samples/freecad/analytic/sphere.step", 1),
        ("samples/public/solidedge_sylinterin_tappi.stp", 2),
    ] {
        let once = read_path(&root().join(file));
        let points = |d: &Document| -> Vec<[f64; 3]> {
            let m = &d.topology.model;
            let mut p: Vec<[f64; 3]> = m
                .faces
                .iter()
                .flat_map(|f| &f.vertex_loops)
                .map(|v| m.vertices[v.0].point)
                .collect();
            p.sort_by(|a, b| a.partial_cmp(b).unwrap());
            p
        };
        let want = points(&once);
        assert_eq!(want.len(), loops, "{file}");
        // The file's own VERTEX_LOOP vertices.
        let text = std::fs::read_to_string(root().join(file)).unwrap();
        assert_eq!(text.matches("VERTEX_LOOP").count(), loops, "{file}");

        let step = exchange::write(&once, Format::Step, &ExportOptions::default()).unwrap();
        let body = instances_of(&step);
        let vertex_loops: Vec<u64> = body
            .iter()
            .filter(|(_, (k, _))| k == "VERTEX_LOOP")
            .map(|(id, _)| *id)
            .collect();
        assert_eq!(vertex_loops.len(), loops, "{file}");
        for vl in &vertex_loops {
            let (kind, refs) = &body[&refs_to(&body, *vl, "FACE_BOUND")];
            assert_eq!(kind, "FACE_BOUND");
            assert_eq!(refs[0], *vl);
            let vertex = body[vl].1[0];
            assert_eq!(body[&vertex].0, "VERTEX_POINT", "{file}");
        }
        for (kind, refs) in body.values() {
            if kind == "ADVANCED_FACE" {
                assert!(refs.len() >= 2, "{file}: a face without bounds");
            }
        }
        let back = exchange::read(step.as_bytes(), &ImportOptions::default()).unwrap();
        assert_eq!(points(&back), want, "{file}: STEP");

        let brep = ExportOptions {
            iges_brep: true,
            ..ExportOptions::default()
        };
        let (iges, warnings) = exchange::write_reporting(&once, Format::Iges, &brep).unwrap();
        assert!(warnings.is_empty(), "{file}: {warnings:?}");
        let back = exchange::read(iges.as_bytes(), &ImportOptions::default()).unwrap();
        assert_eq!(points(&back), want, "{file}: IGES B-rep");

        let (_, warnings) =
            exchange::write_reporting(&once, Format::Iges, &ExportOptions::default()).unwrap();
        let w: Vec<_> = warnings
            .iter()
            .filter(|d| d.code == "topology.vertex_loop_not_written")
            .collect();
        assert_eq!(w.len(), 1, "{file}");
        assert!(
            w[0].message.starts_with(&format!("{loops} vertex loop(s)")),
            "{}",
            w[0].message
        );
    }
}

/// The instance among `body` of keyword `kind` whose first reference is `to`.
fn refs_to(body: &std::collections::HashMap<u64, (String, Vec<u64>)>, to: u64, kind: &str) -> u64 {
    *body
        .iter()
        .find(|(_, (k, refs))| k == kind && refs.first() == Some(&to))
        .unwrap()
        .0
}
