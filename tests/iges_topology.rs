//! IGES faces, shells and solids (issue 20, IGES half):
//! - the FreeCAD samples of both export modes (144 faces and 186 B-rep) read into the
//!   topology with FreeCAD's own face, shell and solid counts (its committed readings), every
//!   loop closed, Euler-Poincare on every solid;
//! - IGES -> IGES in both modes re-imported by FreeCAD: the same number of faces, total area
//!   within 1e-6 relative, solids valid with the volume within 1e-6 (skipped with a message
//!   when `freecadcmd` is missing, fatal with `NURBSX_REQUIRE_FREECAD=1`);
//! - read -> write -> read gives bit-identical surface and edge poles;
//! - located diagnostics on broken topology, the rest of the file still read.
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../parsers/tests/iges_support/mod.rs"]
mod iges_util;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use iges_util::{Builder, De};
use nurbsx::exchange::{self, Document, ExportOptions, ImportOptions, Severity};
use nurbsx::topology::Model;

/// The IGES samples with faces: FreeCAD's faces mode (144) and B-rep mode (186).
fn samples() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad");
    let mut out = Vec::new();
    for dir in [root.clone(), root.join("analytic"), root.join("parts")] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "igs") {
                let fe = &reading(&p)["file_entities"];
                if fe.get("144").is_some() || fe.get("186").is_some() {
                    out.push(p);
                }
            }
        }
    }
    out.sort();
    assert!(out.len() >= 20, "{} samples", out.len());
    out
}

/// FreeCAD's committed reading of a sample (`<file>.json`).
fn reading(path: &Path) -> serde_json::Value {
    let json = PathBuf::from(format!("{}.json", path.display()));
    serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
}

fn read_text(text: &str) -> Document {
    exchange::iges::read(text, &ImportOptions::default()).unwrap()
}

fn fe_has(reading: &serde_json::Value, entity: &str) -> bool {
    reading["file_entities"].get(entity).is_some()
}

fn name(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

/// Genus of a closed shell by Euler-Poincare, `V - E + F - (L - F) = 2 (1 - G)` over the
/// vertices, edges, faces and loops it uses; `None` when that is not a whole number >= 0.
fn genus(m: &Model, shell: usize) -> Option<i64> {
    let (mut v, mut e, mut l) = (BTreeSet::new(), BTreeSet::new(), 0i64);
    let faces = &m.shells[shell].faces;
    for &(f, _) in faces {
        for lp in &m.faces[f.0].loops {
            l += 1;
            for c in &lp.coedges {
                e.insert(c.edge);
                let edge = &m.edges[c.edge.0];
                v.insert(edge.start);
                v.insert(edge.end);
            }
        }
    }
    let f = faces.len() as i64;
    let chi = v.len() as i64 - e.len() as i64 + f - (l - f);
    (chi % 2 == 0 && chi <= 2).then(|| 1 - chi / 2)
}

/// Every sample: FreeCAD's face, shell and solid counts; loops closed through shared
/// vertices (every coedge ends where the next starts); the solids' shells closed with the
/// genus of the part (1 for the box with a through hole and the torus, 0 otherwise).
#[test]
fn samples_read_with_freecads_counts() {
    for p in samples() {
        let doc = read_text(&std::fs::read_to_string(&p).unwrap());
        let m = &doc.topology.model;
        let own = reading(&p);
        let file = name(&p);
        assert_eq!(
            m.faces.len() as u64,
            own["counts"]["faces"].as_u64().unwrap(),
            "{file}"
        );
        // FreeCAD reads a faces-mode (144) file as loose faces; nurbsx sews them (a lone
        // face to itself where its boundary runs twice along its seam), so its shells and
        // solids are those of FreeCAD's reading of the same part's STEP file.
        let step = p.with_extension("step");
        let sewn = fe_has(&own, "144")
            && !fe_has(&own, "186")
            && step.exists()
            && doc.diagnostics.iter().any(|d| d.code == "topology.sewn");
        let reference = if sewn { reading(&step) } else { own };
        let c = &reference["counts"];
        assert_eq!(
            m.shells.len() as u64,
            c["shells"].as_u64().unwrap(),
            "{file}"
        );
        assert_eq!(
            m.solids.len() as u64,
            c["solids"].as_u64().unwrap(),
            "{file}"
        );
        let errors: Vec<String> = doc
            .diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .map(ToString::to_string)
            .collect();
        assert!(errors.is_empty(), "{file}: {errors:?}");
        // The origins are index-aligned and name the entity holding the geometry.
        let o = &doc.topology.origins;
        assert_eq!(o.faces.len(), m.faces.len(), "{file}");
        assert_eq!(o.edges.len(), m.edges.len(), "{file}");
        assert_eq!(o.vertices.len(), m.vertices.len(), "{file}");
        for origin in o.faces.iter().chain(&o.edges) {
            let id = origin.entity.as_deref().unwrap();
            assert!(doc.entities.iter().any(|e| e.id == id), "{file}: {id}");
        }
        for f in &m.faces {
            for l in &f.loops {
                let n = l.coedges.len();
                for i in 0..n {
                    let (_, end) = m.coedge_ends(&l.coedges[i]).unwrap();
                    let (next, _) = m.coedge_ends(&l.coedges[(i + 1) % n]).unwrap();
                    assert_eq!(end, next, "{file}");
                }
            }
        }
        // The genus of the solids: the parts state their total in `<part>.source.json`
        // (the part made in memory; null for a part without solids).
        let stem = file.trim_end_matches(".igs").trim_end_matches("_brep");
        let source = p.with_file_name(format!("{stem}.source.json"));
        let part = p.parent().is_some_and(|d| d.ends_with("parts"));
        let mut total = 0;
        for s in &m.solids {
            assert!(m.shells[s.outer.0].closed, "{file}");
            let g = genus(m, s.outer.0).unwrap();
            if !part {
                let want = i64::from(
                    file.starts_with("filleted_box_with_hole") || file.starts_with("torus"),
                );
                assert_eq!(g, want, "{file}");
            }
            total += g;
        }
        if part {
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&source).unwrap()).unwrap();
            assert_eq!(v["genus"].as_i64().unwrap_or(0), total, "{file}");
        }
        // No trim or topology is reported ignored any more.
        assert!(
            !doc.diagnostics
                .iter()
                .any(|d| d.code == "trim_ignored" || d.code == "topology_ignored"),
            "{file}"
        );
    }
}

/// `geometry_only`: no topology, one visible warning naming what was left out, and the
/// old per-entity notes.
#[test]
fn geometry_only_says_what_it_leaves_out() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("samples/freecad/analytic/filleted_box_with_hole_brep.igs");
    let options = ImportOptions {
        geometry_only: true,
        ..ImportOptions::default()
    };
    let doc = exchange::iges::read(&std::fs::read_to_string(p).unwrap(), &options).unwrap();
    assert!(doc.topology.is_empty());
    let w: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.code == "topology.not_read")
        .collect();
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].severity, Severity::Warning);
    assert!(w[0].message.contains("1 solids (186)"), "{}", w[0].message);
    assert!(w[0].message.contains("27 faces (510)"), "{}", w[0].message);
}

fn poles(doc: &Document) -> Vec<Vec<[f64; 3]>> {
    let m = &doc.topology.model;
    let mut out = Vec::new();
    for f in &m.faces {
        out.push(f.surface.control_points().as_slice().to_vec());
        for l in &f.loops {
            for c in &l.coedges {
                out.push(m.edges[c.edge.0].curve.control_points().to_vec());
            }
        }
    }
    out
}

/// Read -> write -> read: the faces' surfaces and the edges' curves come back with
/// bit-identical poles, in the same order, in both modes (144 for the 144 samples, 186 for
/// the B-rep ones); the topology counts are kept.
#[test]
fn read_write_read_is_bit_identical() {
    for p in samples() {
        let doc = read_text(&std::fs::read_to_string(&p).unwrap());
        let brep = !doc.topology.model.solids.is_empty();
        let options = ExportOptions {
            iges_brep: brep,
            timestamp: Some("2026-01-01T00:00:00".into()),
            ..ExportOptions::default()
        };
        let text = exchange::iges::write(&doc, &options).unwrap();
        let back = read_text(&text);
        let file = name(&p);
        let (a, b) = (&doc.topology.model, &back.topology.model);
        assert_eq!(a.faces.len(), b.faces.len(), "{file}");
        assert_eq!(a.edges.len(), b.edges.len(), "{file}");
        assert_eq!(a.vertices.len(), b.vertices.len(), "{file}");
        assert_eq!(a.shells.len(), b.shells.len(), "{file}");
        assert_eq!(a.solids.len(), b.solids.len(), "{file}");
        let (pa, pb) = (poles(&doc), poles(&back));
        assert_eq!(pa.len(), pb.len(), "{file}");
        for (x, y) in pa.iter().zip(&pb) {
            assert_eq!(x.len(), y.len(), "{file}");
            for (p, q) in x.iter().zip(y) {
                assert_eq!(p.map(f64::to_bits), q.map(f64::to_bits), "{file}");
            }
        }
    }
}

/// `freecadcmd` on PATH, or `None` (then the FreeCAD check is skipped with a message unless
/// `NURBSX_REQUIRE_FREECAD=1`).
fn freecadcmd() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    let found = std::env::split_paths(&path)
        .flat_map(|dir| ["freecadcmd", "FreeCADCmd"].map(|n| dir.join(n)))
        .find(|c| c.is_file());
    if found.is_none() {
        assert_ne!(
            std::env::var("NURBSX_REQUIRE_FREECAD").as_deref(),
            Ok("1"),
            "FreeCAD required but freecadcmd is not on PATH"
        );
        eprintln!("SKIPPED the FreeCAD re-import: freecadcmd not on PATH");
    }
    found
}

/// FreeCAD's reading of each file (scripts/freecad/reimport_faces.py).
fn freecad_readings(exe: &Path, files: &[PathBuf]) -> Vec<serde_json::Value> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let joined = std::env::join_paths(files).unwrap();
    let out = Command::new(exe)
        .arg(root.join("scripts/freecad/reimport_faces.py"))
        .env("NURBSX_FILES", joined)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let v: Vec<serde_json::Value> = stdout
        .lines()
        .filter_map(|l| l.strip_prefix("reimport_faces: "))
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(v.len(), files.len(), "{stdout}");
    v
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

/// Samples with faces on B-spline geometry (a B-spline surface, or a swept B-spline
/// directrix or profile), where Open CASCADE's `Face.Area` (its fixed Gauss rule, README)
/// is not a 1e-6 reference: FreeCAD's two readings of `extrude_bspline` (144 and 186)
/// differ by 2e-5 between themselves, and nurbsx's own meshes of that part at 1e-3 and
/// 2e-4 chord extrapolate to its measure within 3e-7 while FreeCAD is 2.3e-4 off. They
/// are held to 5e-4.
const FREECAD_AREA_ROUGH: [&str; 8] = [
    "extrusion_ellipse.igs",
    "ruled_surface.igs",
    "extrude_bspline.igs",
    "extrude_bspline_brep.igs",
    "loft_bspline.igs",
    "loft_bspline_brep.igs",
    "revolve_bspline_270.igs",
    "revolve_bspline_270_brep.igs",
];

/// Every FreeCAD IGES sample with faces (144 or 186) measures, face by face summed and in
/// mm, the area FreeCAD gives its faces (the sample JSON's `faces[].area`, Open CASCADE's
/// integration over its own analytic surfaces: an independent kernel) within 1e-6. The
/// whole sphere (`sphere.igs`, a 120 cut along one meridian; `sphere_brep.igs`, a 196) and
/// the whole torus have loops of seam coedges only: they measured 0 or could not be
/// measured while those seam pcurves lay on one side of the domain.
#[test]
fn face_areas_match_freecads() {
    let mut bad = Vec::new();
    for p in samples() {
        let doc = read_text(&std::fs::read_to_string(&p).unwrap());
        let m = &doc.topology.model;
        let mm2 = doc.units.to_mm() * doc.units.to_mm();
        let got: f64 = m
            .faces
            .iter()
            .map(|f| m.measure_face(f).map_or(f64::NAN, |x| x.area * mm2))
            .sum();
        let want: f64 = reading(&p)["faces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["area"].as_f64().unwrap())
            .sum();
        let file = name(&p);
        let bound = if FREECAD_AREA_ROUGH.contains(&file.as_str()) {
            5e-4
        } else {
            1e-6
        };
        let within = rel(got, want) <= bound;
        if !within {
            bad.push(format!("{file}: {got} vs FreeCAD {want} (bound {bound})"));
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

/// IGES -> IGES in 144 mode and in 186 mode, re-imported by FreeCAD: the number of faces
/// FreeCAD finds in the source, valid shapes, and for the 186 output of a solid part the
/// source's number of solids; the total area within 1e-6 relative of the source's where
/// Open CASCADE's area integration is accurate on the output (every face on a single knot
/// span: `single_span` of scripts/freecad/reimport_faces.py). On exact rational B-spline
/// faces whose parameterisation is C0 at a knot (the NURBS form of a cylinder, cone, torus)
/// Face.Area integrates across the joint and is off by up to 1e-3; the table shows it.
#[test]
fn freecad_reimports_both_modes() {
    let Some(exe) = freecadcmd() else { return };
    let work = std::env::temp_dir().join(format!("nurbsx-iges-topology-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    let mut files = Vec::new();
    let list = samples();
    for p in &list {
        let doc = read_text(&std::fs::read_to_string(p).unwrap());
        files.push(p.clone());
        for brep in [false, true] {
            let options = ExportOptions {
                iges_brep: brep,
                ..ExportOptions::default()
            };
            let out = work.join(format!(
                "{}.{}.igs",
                name(p),
                if brep { "186" } else { "144" }
            ));
            std::fs::write(&out, exchange::iges::write(&doc, &options).unwrap()).unwrap();
            files.push(out);
        }
    }
    let r = freecad_readings(&exe, &files);
    println!(
        "{:<32} {:>5} {:>4} {:>4} {:>16} {:>8} {:>8} {:>8} {:>8} {:>8} {:>7}",
        "sample",
        "faces",
        "144",
        "186",
        "area (FreeCAD)",
        "144 rel",
        "144 kind",
        "186 rel",
        "186 kind",
        "vol 186",
        "solids"
    );
    let mut failures = Vec::new();
    let mut measured = 0;
    for (k, p) in list.iter().enumerate() {
        let (src, f144, f186) = (&r[3 * k], &r[3 * k + 1], &r[3 * k + 2]);
        let file = name(p);
        let num = |v: &serde_json::Value, key: &str| v[key].as_f64().unwrap_or(f64::NAN);
        let area = num(src, "area");
        let vol = num(src, "volume");
        let vrel = if vol > 0.0 {
            rel(vol, num(f186, "volume"))
        } else {
            0.0
        };
        let show = |v: &serde_json::Value| {
            if v["single_span"] == true {
                "one span"
            } else {
                "  spans "
            }
        };
        println!(
            "{file:<32} {:>5} {:>4} {:>4} {area:>16.9} {:>8.1e} {} {:>8.1e} {} {vrel:>8.1e} {:>3}/{}",
            src["faces"],
            f144["faces"],
            f186["faces"],
            rel(area, num(f144, "area")),
            show(f144),
            rel(area, num(f186, "area")),
            show(f186),
            f186["solids"],
            src["solids"]
        );
        let mut bad = Vec::new();
        for (mode, out) in [("144", f144), ("186", f186)] {
            if out["faces"] != src["faces"] {
                bad.push(format!(
                    "{file} {mode}: faces {} vs {}",
                    out["faces"], src["faces"]
                ));
            }
            if out["valid"] != true {
                bad.push(format!("{file} {mode}: not valid"));
            }
            if out["single_span"] == true && src["single_span"] == true {
                measured += 1;
                let a = num(out, "area");
                let within = rel(area, a) <= 1e-6;
                if !within {
                    bad.push(format!("{file} {mode}: area {a} vs {area}"));
                }
            }
        }
        if src["solids"].as_u64().unwrap_or(0) > 0 && f186["solids"] != src["solids"] {
            bad.push(format!(
                "{file} 186: solids {} vs {}",
                f186["solids"], src["solids"]
            ));
        }
        failures.extend(bad);
    }
    let _ = std::fs::remove_dir_all(&work);
    assert!(failures.is_empty(), "{failures:#?}");
    assert!(measured >= 6, "only {measured} outputs measured");
}

const GLOBAL: &str = ",,4Htest,8Hfile.igs,,,,,,,,,1.,2,2HMM,,,,1.E-7,,,,11,0,;";

/// A degree-1 126 from `a` to `b` (z = 0).
fn line(a: [f64; 2], b: [f64; 2]) -> String {
    format!(
        "126,1,1,1,0,1,0,0.,0.,1.,1.,1.,1.,{:?},{:?},0.,{:?},{:?},0.,0.,1.,0.,0.,1.;",
        a[0], a[1], b[0], b[1]
    )
}

fn ty(ty: i64) -> De<'static> {
    De {
        ty,
        ..De::default()
    }
}

/// Broken topology gives located errors (section D, the offending entity's sequence number
/// and line) with stable codes; the good face of the same file is still read, with its
/// pcurves exact from the file's parameter-space curves.
#[test]
fn broken_topology_is_located() {
    let mut b = Builder::new(GLOBAL);
    // The unit square as a bilinear 128: (u, v) = (x, y).
    let s = b.entity(
        ty(128),
        "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;",
    );
    let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    // A good face: model-space and parameter-space squares.
    let mut model = Vec::new();
    let mut param = Vec::new();
    for i in 0..4 {
        model.push(b.entity(De::default(), &line(corners[i], corners[(i + 1) % 4])));
        param.push(b.entity(
            De {
                status: "00010500",
                ..De::default()
            },
            &line(corners[i], corners[(i + 1) % 4]),
        ));
    }
    let list = |v: &[usize]| {
        v.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(",")
    };
    let cm = b.entity(ty(102), &format!("102,4,{};", list(&model)));
    let cp = b.entity(ty(102), &format!("102,4,{};", list(&param)));
    let good142 = b.entity(ty(142), &format!("142,0,{s},{cp},{cm},1;"));
    let good = b.entity(ty(144), &format!("144,{s},1,0,{good142};"));
    // A 142 whose CPTR names no directory entry.
    let missing142 = b.entity(ty(142), &format!("142,0,{s},0,999,2;"));
    let missing = b.entity(ty(144), &format!("144,{s},1,0,{missing142};"));
    // A 144 whose PTO is the surface, not a 142.
    let not142 = b.entity(ty(144), &format!("144,{s},1,0,{s};"));
    // A B-rep face whose 508 loop runs (0,0) -> (1,0) -> (1,1) and stops.
    let l1 = b.entity(De::default(), &line([0.0, 0.0], [1.0, 0.0]));
    let l2 = b.entity(De::default(), &line([1.0, 0.0], [1.0, 1.0]));
    let v = b.entity(ty(502), "502,3,0.,0.,0.,1.,0.,0.,1.,1.,0.;");
    let e = b.entity(
        ty(504),
        &format!("504,2,{l1},{v},1,{v},2,{l2},{v},2,{v},3;"),
    );
    let lp = b.entity(ty(508), &format!("508,2,0,{e},1,1,0,0,{e},2,1,0;"));
    let f = b.entity(ty(510), &format!("510,{s},1,1,{lp};"));
    b.entity(
        De {
            ty: 514,
            form: 2,
            ..De::default()
        },
        &format!("514,1,{f},1;"),
    );
    let text = b.build();
    let doc = read_text(&text);
    let find = |code: &str, de: usize| {
        doc.diagnostics
            .iter()
            .find(|d| d.code == code && d.location.entity.as_deref() == Some(&format!("D{de}")))
            .unwrap_or_else(|| panic!("no {code} at D{de}: {:#?}", doc.diagnostics))
    };
    let d = find("pointer.invalid", missing142);
    assert_eq!(d.severity, Severity::Error);
    assert_eq!(
        (d.location.section, d.location.sequence),
        (Some('D'), Some(missing142))
    );
    assert!(d.location.line.is_some());
    assert!(d.message.contains("CPTR = 999"), "{}", d.message);
    let d = find("topology.wrong_entity", not142);
    assert!(d.message.contains("PTO"), "{}", d.message);
    let d = find("topology.loop_open", lp);
    assert!(d.message.contains(&format!("face D{f}")), "{}", d.message);
    // The good face is read, the three broken ones are not.
    let m = &doc.topology.model;
    assert_eq!(m.faces.len(), 1);
    assert_eq!(doc.topology.origins.faces[0].id, format!("D{good}"));
    let _ = missing;
    let l = &m.faces[0].loops[0];
    assert_eq!(l.coedges.len(), 4);
    assert!(m.vertices.len() >= 4);
    // Exact pcurves: the file's 2-D lines, found on the surface within rounding.
    for c in &l.coedges {
        let p = c.pcurve.as_ref().expect("pcurve");
        assert_eq!(p.dimension(), 2);
        assert!(c.pcurve_deviation.unwrap() <= 1e-15);
    }
    // The open shell holds no face (its only face was refused).
    assert_eq!(m.shells.len(), 1);
    assert!(m.shells[0].faces.is_empty());
}

/// STEP parts whose solid cannot be measured yet: a coedge without pcurve. The curve
/// crosses the seam of its closed surface (an intersection curve around a cylinder, a tube
/// circle of the elbow's torus starting half-way round), where neither the isocurve pcurve
/// nor the projection applies (one pcurve would have to continue past the seam).
const UNMEASURED_STEP_PARTS: &[&str] = &[
    "boss_radial_hole.step",
    "pipe_elbow.step",
    "extrude_bspline.step",
];

/// Every part of `samples/freecad/parts` read from STEP, written as IGES 144 faces and read
/// back (sewn) has the same solids with the same volume (1e-9 relative): a face on the
/// other side of its surface (`same_sense` false) must reach the IGES faces with its loops
/// turned, or the sewn solid takes its flux with the wrong sign (the filleted box: 1.5 %).
#[test]
fn step_parts_through_iges_144_keep_their_volume() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts");
    let mut checked = 0;
    let mut flipped = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "step") {
            continue;
        }
        let src = exchange::read(&std::fs::read(&p).unwrap(), &ImportOptions::default()).unwrap();
        let m = &src.topology.model;
        if m.solids.is_empty() {
            continue;
        }
        flipped += m.faces.iter().filter(|f| !f.same_sense).count();
        let volume = |m: &Model| -> Result<f64, nurbsx::topology::MeasureError> {
            (0..m.solids.len())
                .map(|k| m.solid_volume(nurbsx::topology::SolidId(k)))
                .sum()
        };
        let file = name(&p);
        // A face some of whose coedges have no pcurve cannot be measured (reported by the
        // reader as pcurve.not_computed); only the parts listed as such are skipped, visibly.
        let want = match volume(m) {
            Ok(v) => v,
            Err(e) if UNMEASURED_STEP_PARTS.contains(&file.as_str()) => {
                eprintln!("{file}: not measurable ({e}), skipped");
                continue;
            }
            Err(e) => panic!("{file}: not measurable: {e}"),
        };
        let text =
            exchange::write(&src, exchange::Format::Iges, &ExportOptions::default()).unwrap();
        let back = read_text(&text);
        assert_eq!(back.topology.model.solids.len(), m.solids.len(), "{file}");
        let got = volume(&back.topology.model).unwrap();
        assert!(
            (got - want).abs() <= 1e-9 * want.abs(),
            "{file}: {got} vs {want}"
        );
        checked += 1;
    }
    assert!(checked >= 6, "{checked} parts with solids measured");
    assert!(flipped > 0, "no face with same_sense false among the parts");
}

/// A face on a closed surface without a seam edge (Solid Edge: cylinders between two full
/// circles, pierced by holes; cones up to their apex) has loops that do not close in the
/// surface's parameter space, which a 144 boundary must. Written as IGES 144 faces, each
/// such face gets one outer boundary joined by the seam (and the collapsed side of an apex):
/// read back, the part is one closed solid again with the STEP reading's area and volume
/// (1e-6 relative: the seam lines join pcurves that end up to 5e-5 mm off the seam), and
/// FreeCAD re-imports 21 valid faces with its area within 2e-3 (Open CASCADE's fixed Gauss
/// rule is off by up to 1.7e-3 on exact rational B-spline faces, README; 1.2e-3 here, as on
/// nurbsx's STEP output of the part, whose mesh has the area within 1e-5; a mesh of this
/// IGES output at a 0.002 mm chord agrees within 1e-5 too, but takes FreeCAD 13 minutes). Before, the winding loops were written as separate
/// boundaries in model space only: nurbsx skipped a face and left the shell open, FreeCAD
/// made 48 faces, 27 of them invalid slivers of zero area.
#[test]
fn faces_without_a_seam_edge_close_in_iges_144() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/public/solidedge_sylinterin_tappi.stp");
    let src = exchange::read(&std::fs::read(&path).unwrap(), &ImportOptions::default()).unwrap();
    let m = &src.topology.model;
    let want = m.totals();
    assert_eq!((m.solids.len(), m.faces.len(), want.unmeasured), (1, 21, 0));
    let text = exchange::write(&src, exchange::Format::Iges, &ExportOptions::default()).unwrap();
    let back = read_text(&text);
    let warnings: Vec<_> = back
        .diagnostics
        .iter()
        .filter(|d| d.severity >= Severity::Warning)
        .map(|d| d.code.clone())
        .collect();
    assert!(warnings.is_empty(), "{warnings:?}");
    let b = &back.topology.model;
    let got = b.totals();
    assert_eq!((b.solids.len(), b.faces.len(), got.unmeasured), (1, 21, 0));
    let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
    assert!(
        rel(got.area, want.area) <= 1e-6,
        "area {} vs {}",
        got.area,
        want.area
    );
    let (v, w) = (
        got.volumes[0].clone().unwrap(),
        want.volumes[0].clone().unwrap(),
    );
    assert!(rel(v, w) <= 1e-6, "volume {v} vs {w}");
    let Some(exe) = freecadcmd() else { return };
    let work = std::env::temp_dir().join(format!("nurbsx-seamless-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    let out = work.join("part.igs");
    std::fs::write(&out, &text).unwrap();
    let script = work.join("check.py");
    std::fs::write(
        &script,
        format!(
            "import Part\ns = Part.Shape()\ns.read({:?})\nprint('FACES', len(s.Faces), sum(1 for f in s.Faces if f.isValid() and f.Area > 1e-6), s.Area)\n",
            out.display().to_string()
        ),
    )
    .unwrap();
    let run = Command::new(exe).arg(&script).output().unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("FACES"))
        .unwrap_or_else(|| panic!("no answer from FreeCAD: {stdout}"));
    let f: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!((f[0], f[1]), (21.0, 21.0), "{line}");
    assert!(rel(f[2], want.area) <= 2e-3, "{line} vs {}", want.area);
    let _ = std::fs::remove_dir_all(&work);
}

/// IGES 143 Bounded Surfaces with 141 Boundaries (`samples/iges143/make.py` rewrites the
/// 144/142 faces of four FreeCAD parts as 143/141, nothing else changed): the same faces,
/// total area and sewn solid volumes as the 144 originals (1e-12 relative), and FreeCAD's
/// own area and volume of the part (its reading of the STEP file) within 1e-6; no warning.
#[test]
fn bounded_surfaces_read_as_faces() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples");
    let measure = |doc: &Document| {
        let m = &doc.topology.model;
        let area: f64 = m
            .faces
            .iter()
            .map(|f| m.measure_face(f).unwrap().area)
            .sum();
        let volumes: Vec<f64> = (0..m.solids.len())
            .map(|k| m.solid_volume(nurbsx::topology::SolidId(k)).unwrap())
            .collect();
        (m.faces.len(), area, volumes)
    };
    let mut checked = 0;
    for part in [
        "box_fillet_chamfer_hole",
        "flange",
        "sphere_cap",
        "trimmed_face",
    ] {
        let original = root.join(format!("freecad/parts/{part}.igs"));
        let bounded = root.join(format!("iges143/{part}_143.igs"));
        let text = std::fs::read_to_string(&bounded).unwrap();
        let types: Vec<&str> = text
            .lines()
            .filter(|l| l.as_bytes().get(72) == Some(&b'D'))
            .map(|l| l[..8].trim())
            .collect();
        assert!(types.contains(&"143") && !types.contains(&"144"), "{part}");
        let doc = read_text(&text);
        // Nothing but the warning that the file's 402 group (the solid's entities, as Open
        // CASCADE groups them) is not carried, which is true.
        let loud: Vec<_> = doc
            .diagnostics
            .iter()
            .filter(|d| {
                d.severity != Severity::Info
                    && !(d.code == "entities_skipped" && d.message.ends_with(": 1 x 402"))
            })
            .collect();
        assert!(loud.is_empty(), "{part}: {loud:#?}");
        let (faces, area, volumes) = measure(&doc);
        let (faces0, area0, volumes0) =
            measure(&read_text(&std::fs::read_to_string(&original).unwrap()));
        assert_eq!(faces, faces0, "{part}");
        assert!(faces > 0, "{part}");
        assert!(rel(area, area0) <= 1e-12, "{part}: area {area} vs {area0}");
        assert_eq!(volumes.len(), volumes0.len(), "{part}");
        for (v, w) in volumes.iter().zip(&volumes0) {
            assert!(rel(*v, *w) <= 1e-12, "{part}: volume {v} vs {w}");
        }
        let freecad = reading(&root.join(format!("freecad/parts/{part}.step")));
        let want = freecad["totals"]["area"].as_f64().unwrap();
        assert!(
            rel(area, want) <= 1e-6,
            "{part}: area {area} vs FreeCAD's {want}"
        );
        let solids = freecad["solids"].as_array().unwrap();
        assert_eq!(volumes.len(), solids.len(), "{part}");
        for (v, s) in volumes.iter().zip(solids) {
            let w = s["volume"].as_f64().unwrap();
            assert!(rel(*v, w) <= 1e-6, "{part}: volume {v} vs FreeCAD's {w}");
        }
        checked += 1;
    }
    assert_eq!(checked, 4);
}

/// A 141 Boundary's SENSE = 2 reverses its curve: the unit square on a bilinear 128 with a
/// square hole [¼, ¾]², the outer boundary with two of its four sides written backwards
/// (SENSE = 2), the hole's clockwise loop of four sides all written counter-clockwise
/// (SENSE = 2). One face whose loops close, reversed coedges marked so, area 1 - ¼.
#[test]
fn boundary_sense_reverses_its_curves() {
    let mut b = Builder::new(GLOBAL);
    let s = b.entity(
        ty(128),
        "128,1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,0.,1.,0.,1.,1.,0.,0.,1.,0.,1.;",
    );
    let outer = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let mut sides = Vec::new();
    for i in 0..4 {
        let (a, c) = (outer[i], outer[(i + 1) % 4]);
        // Sides 1 and 3 written from their end to their start.
        let (written, sense) = if i % 2 == 1 {
            (line(c, a), 2)
        } else {
            (line(a, c), 1)
        };
        sides.push((b.entity(De::default(), &written), sense));
    }
    // The hole, clockwise: (¼,¼) -> (¼,¾) -> (¾,¾) -> (¾,¼).
    let hole = [[0.25, 0.25], [0.25, 0.75], [0.75, 0.75], [0.75, 0.25]];
    let mut inner = Vec::new();
    for i in 0..4 {
        let (a, c) = (hole[i], hole[(i + 1) % 4]);
        inner.push((b.entity(De::default(), &line(c, a)), 2));
    }
    let boundary = |curves: &[(usize, i32)]| {
        let list: Vec<String> = curves.iter().map(|(c, s)| format!("{c},{s},0")).collect();
        format!("141,0,1,{s},{},{};", curves.len(), list.join(","))
    };
    let outer141 = b.entity(ty(141), &boundary(&sides));
    let inner141 = b.entity(ty(141), &boundary(&inner));
    let face = b.entity(ty(143), &format!("143,0,{s},2,{outer141},{inner141};"));
    let doc = read_text(&b.build());
    let loud: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.severity != Severity::Info)
        .collect();
    assert!(loud.is_empty(), "{loud:#?}");
    let m = &doc.topology.model;
    assert_eq!(m.faces.len(), 1);
    assert_eq!(doc.topology.origins.faces[0].id, format!("D{face}"));
    let f = &m.faces[0];
    assert_eq!(f.loops.len(), 2);
    let forward: Vec<Vec<bool>> = f
        .loops
        .iter()
        .map(|l| l.coedges.iter().map(|c| c.forward).collect())
        .collect();
    assert_eq!(
        forward,
        vec![vec![true, false, true, false], vec![false; 4]]
    );
    let area = m.measure_face(f).unwrap().area;
    assert!((area - 0.75).abs() <= 1e-15, "{area}");
}

/// The entity types declared in session 18 (IGES 5.3 sections 4.136 Rectangular Array
/// Subfigure Instance, 4.142 Solid Instance, 4.140 Network Subfigure Instance) have their pointers checked by `validate`'s conformance read: a pointer
/// to no directory entry and a pointer to an entity of a type the standard's table does
/// not list are located errors, a well-formed instance is not.
#[test]
fn pointers_of_arrays_instances_and_templates_are_checked() {
    let mut b = Builder::new(GLOBAL);
    let curve = b.entity(De::default(), &line([0.0, 0.0], [1.0, 0.0]));
    // 412: base entity, scale, corner, NC, NR, DX, DY, AX, LC, DO-DON'T.
    let good412 = b.entity(
        ty(412),
        &format!("412,{curve},1.,0.,0.,0.,2,3,1.,1.,0.,0,0;"),
    );
    let missing412 = b.entity(ty(412), "412,999,1.,0.,0.,0.,2,3,1.,1.,0.,0,0;");
    // 430: the solid it places; a 126 curve is not one of the table's types.
    let wrong430 = b.entity(ty(430), &format!("430,{curve};"));
    // 420 naming the curve as its definition (a 320 or a 416 is required).
    let wrong420 = b.entity(
        ty(420),
        &format!("420,{curve},0.,0.,0.,1.,1.,1.,0,4HR101,0,0;"),
    );
    let text = b.build();
    // The conformance check (`validate`) reads every entity's pointers.
    let options = ImportOptions {
        conformance: true,
        ..ImportOptions::default()
    };
    let doc = exchange::iges::read(&text, &options).unwrap();
    let at = |de: usize| {
        doc.diagnostics
            .iter()
            .filter(|d| {
                d.code == "pointer.invalid"
                    && d.location.entity.as_deref() == Some(&format!("D{de}"))
            })
            .collect::<Vec<_>>()
    };
    assert!(at(good412).is_empty(), "{:#?}", at(good412));
    for de in [missing412, wrong430, wrong420] {
        let found = at(de);
        assert_eq!(found.len(), 1, "D{de}: {:#?}", doc.diagnostics);
        assert_eq!(found[0].severity, Severity::Error);
        assert_eq!(
            (found[0].location.section, found[0].location.sequence),
            (Some('D'), Some(de))
        );
    }
    assert!(
        at(missing412)[0].message.contains("999"),
        "{}",
        at(missing412)[0].message
    );
}

/// The curves and surfaces of a document, by dimension: (3-D curves, 2-D curves, surfaces).
fn kinds(doc: &Document) -> (usize, usize, usize) {
    let (mut c3, mut c2, mut s) = (0, 0, 0);
    for e in &doc.entities {
        match &e.geometry {
            nurbsx::nurbs::Geometry::Curve(c) if c.dimension() == 2 => c2 += 1,
            nurbsx::nurbs::Geometry::Curve(_) => c3 += 1,
            nurbsx::nurbs::Geometry::Surface(_) => s += 1,
        }
    }
    (c3, c2, s)
}

/// FreeCAD's 144 export of the filleted box gives each face its own boundary curves (two
/// per edge) and, in parameter space, B(t) curves; nurbsx sews the faces into the solid.
/// The boundary curves of the edges sewing merged into their twins, and the parameter-space
/// curves the coedges carry, are not loose geometry: the part reads as FreeCAD's STEP export
/// of the same box does (its 26 faces' surfaces and 48 edges' curves, nothing else), its
/// STEP output holds no loose curve set and no 2-D representation, and IGES -> IGES keeps
/// it so. `validate` (the conformance reading) still reads every curve of the file: the
/// file's 192 126 entities and 26 128s, counted from its Directory Entry section.
#[test]
fn sewn_faces_carry_their_boundary_and_parameter_curves() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad");
    let igs = std::fs::read_to_string(root.join("brep_filleted_box_nurbs.igs")).unwrap();
    let step = std::fs::read(root.join("brep_filleted_box_nurbs.step")).unwrap();
    let doc = read_text(&igs);
    let twin = exchange::read(&step, &ImportOptions::default()).unwrap();
    assert_eq!(kinds(&twin), (48, 0, 26), "the STEP export of the same box");
    assert_eq!(kinds(&doc), kinds(&twin));
    let m = &doc.topology.model;
    assert_eq!((m.solids.len(), m.faces.len(), m.edges.len()), (1, 26, 48));
    let options = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".into()),
        ..ExportOptions::default()
    };
    let text = exchange::step::write(&doc, &options).unwrap();
    assert!(
        !text.contains("GEOMETRIC_CURVE_SET"),
        "loose curves written"
    );
    assert!(!text.contains("'2D curves'"), "loose 2-D curves written");
    let back = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    assert_eq!(kinds(&back), (48, 0, 26));
    let again = read_text(&exchange::iges::write(&doc, &options).unwrap());
    assert_eq!(kinds(&again), (48, 0, 26));
    assert_eq!(again.topology.model.solids.len(), 1);
    // Every curve and surface of the file, by the types of its Directory Entries (the odd
    // lines of the D section; the type in columns 1-8).
    let types: Vec<i64> = igs
        .lines()
        .filter(|l| l.len() >= 80 && &l[72..73] == "D")
        .step_by(2)
        .map(|l| l[0..8].trim().parse().unwrap())
        .collect();
    let count = |t: i64| types.iter().filter(|&&x| x == t).count();
    assert_eq!((count(126), count(128)), (192, 26));
    let conformance = ImportOptions {
        conformance: true,
        ..ImportOptions::default()
    };
    let all = exchange::iges::read(&igs, &conformance).unwrap();
    let (c3, c2, s) = kinds(&all);
    assert_eq!((c3 + c2, s), (count(126), count(128)));
}

/// A face closed on itself (a sphere, a torus) is a whole solid in a 144 file: its
/// boundary runs twice along its seam, once per side. The lone face is sewn to itself,
/// and reads as the solid its STEP export is (FreeCAD's committed reading of the STEP
/// twin); so does a sphere written by nurbsx as 144 faces from FreeCAD's B-rep (186) file.
/// A lone face with nothing of its own to share (a plane rectangle) stays a loose face.
#[test]
fn a_face_closed_on_itself_is_sewn_into_its_solid() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/analytic");
    for case in ["sphere", "torus"] {
        let doc = read_text(&std::fs::read_to_string(root.join(format!("{case}.igs"))).unwrap());
        let twin = reading(&root.join(format!("{case}.step")));
        let m = &doc.topology.model;
        assert_eq!(m.faces.len(), 1, "{case}");
        assert_eq!(
            (m.shells.len() as u64, m.solids.len() as u64),
            (
                twin["counts"]["shells"].as_u64().unwrap(),
                twin["counts"]["solids"].as_u64().unwrap()
            ),
            "{case}"
        );
        assert_eq!(m.solids.len(), 1, "{case}");
        assert!(m.shells[0].closed, "{case}");
    }
    let brep = read_text(&std::fs::read_to_string(root.join("sphere_brep.igs")).unwrap());
    assert_eq!(brep.topology.model.solids.len(), 1);
    let options = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".into()),
        ..ExportOptions::default()
    };
    let faces = read_text(&exchange::iges::write(&brep, &options).unwrap());
    let m = &faces.topology.model;
    assert_eq!((m.solids.len(), m.faces.len(), m.edges.len()), (1, 1, 1));
    let plane = read_text(&std::fs::read_to_string(root.join("plane_rectangle.igs")).unwrap());
    let m = &plane.topology.model;
    assert_eq!((m.faces.len(), m.shells.len()), (1, 0));
}

/// A torus's B-rep has one vertex, where its two seam edges meet: the part's size (and so
/// the tolerance its edges are checked within) comes from the edges' curves, not from the
/// vertices' box (a point). FreeCAD's 186 file of the torus, written as STEP, reads back
/// as the solid FreeCAD reads from it (before: its seam edge was checked within 1e-9 and
/// refused at 5.7e-9, and the face, shell and solid with it).
#[test]
fn a_part_with_one_vertex_keeps_its_solid_through_step() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/analytic/torus_brep.igs");
    let doc = read_text(&std::fs::read_to_string(&p).unwrap());
    let c = &reading(&p)["counts"];
    let m = &doc.topology.model;
    assert_eq!(m.vertices.len(), 1);
    assert_eq!(m.solids.len() as u64, c["solids"].as_u64().unwrap());
    let options = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".into()),
        ..ExportOptions::default()
    };
    let text = exchange::step::write(&doc, &options).unwrap();
    let back = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    let errors: Vec<_> = back
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    let b = &back.topology.model;
    assert_eq!(
        (b.solids.len(), b.faces.len(), b.edges.len()),
        (m.solids.len(), m.faces.len(), m.edges.len())
    );
    // The reader moved the torus's seam to the vertex (FreeCAD's torus has its v seam on
    // the inner equator, `v = -pi`): the document lists the surface the face carries, and
    // the STEP file's surface is that one, bit for bit.
    let surfaces = |d: &Document| -> Vec<String> {
        d.entities
            .iter()
            .filter(|e| matches!(e.geometry, nurbsx::nurbs::Geometry::Surface(_)))
            .map(|e| format!("{:?}", e.geometry))
            .collect()
    };
    assert_eq!(surfaces(&doc).len(), 1);
    assert_eq!(surfaces(&back), surfaces(&doc));
}

/// Every surface a face names (once, outside any assembly instance) is listed as the face
/// carries it, bit for bit: where a reader moved a seam, the entity moved with it.
#[test]
fn faces_carry_the_surfaces_the_document_lists() {
    let mut moved = 0;
    for p in samples() {
        let doc = read_text(&std::fs::read_to_string(&p).unwrap());
        let t = &doc.topology;
        if !t.instances.is_empty() {
            continue;
        }
        for (face, o) in t.model.faces.iter().zip(&t.origins.faces) {
            let Some(label) = &o.entity else { continue };
            let named = t
                .origins
                .faces
                .iter()
                .filter(|x| x.entity.as_ref() == Some(label));
            if named.count() != 1 {
                continue;
            }
            let e = doc.entities.iter().find(|e| e.id == *label).unwrap();
            assert_eq!(
                format!("{:?}", e.geometry),
                format!(
                    "{:?}",
                    nurbsx::nurbs::Geometry::Surface(face.surface.clone())
                ),
                "{}: face {} and its surface {label}",
                p.display(),
                o.id
            );
            moved += usize::from(e.id == "D7" && p.ends_with("torus_brep.igs"));
        }
    }
    // The torus's face is among them (its seam moved: see the test above).
    assert_eq!(moved, 1);
}

/// Two faces on one cylinder (a hand-written file, `tests/data/step/shared_cylinder_seam.step`):
/// the first runs across the cylinder's seam, so the reader moves the seam for it (exactly:
/// the same cylinder with other poles and knots), the second does not. The document lists
/// every surface a face carries, bit for bit, under the face's own entity: the cylinder as
/// read for the second face, and the moved one under a label of its own for the first,
/// which keeps the source entity and kind. Written as STEP (a surface per face) and read
/// again, the same surfaces are listed.
#[test]
fn a_surface_two_faces_share_is_listed_as_each_face_carries_it() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/step/shared_cylinder_seam.step");
    let doc = exchange::read(&std::fs::read(&p).unwrap(), &ImportOptions::default()).unwrap();
    let t = &doc.topology;
    assert_eq!(t.model.faces.len(), 2);
    let debug = |g: &nurbsx::nurbs::Geometry| format!("{g:?}");
    // Each face's entity holds the surface the face carries.
    let mut labels = Vec::new();
    for (face, o) in t.model.faces.iter().zip(&t.origins.faces) {
        let label = o.entity.clone().unwrap();
        let e = doc.entities.iter().find(|e| e.id == label).unwrap();
        assert_eq!(
            debug(&e.geometry),
            debug(&nurbsx::nurbs::Geometry::Surface(face.surface.clone())),
            "face {} and {label}",
            o.id
        );
        assert_eq!(e.source.entity, "CYLINDRICAL_SURFACE");
        assert_eq!(e.meta.shape, Some(nurbsx::exchange::Shape::Cylinder));
        labels.push(label);
    }
    // The two faces carry different surfaces (one seam moved), so two entities.
    assert_ne!(
        debug(&nurbsx::nurbs::Geometry::Surface(
            t.model.faces[0].surface.clone()
        )),
        debug(&nurbsx::nurbs::Geometry::Surface(
            t.model.faces[1].surface.clone()
        ))
    );
    assert_ne!(labels[0], labels[1]);
    let surfaces = |d: &Document| -> BTreeSet<String> {
        d.entities
            .iter()
            .filter(|e| matches!(e.geometry, nurbsx::nurbs::Geometry::Surface(_)))
            .map(|e| debug(&e.geometry))
            .collect()
    };
    assert_eq!(surfaces(&doc).len(), 2);
    let options = ExportOptions {
        timestamp: Some("2026-01-01T00:00:00".into()),
        ..ExportOptions::default()
    };
    let text = exchange::step::write(&doc, &options).unwrap();
    let back = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
    assert_eq!(back.topology.model.faces.len(), 2);
    assert_eq!(surfaces(&back), surfaces(&doc));
}

/// Solids that touch without being fused (`samples/freecad/parts/touching_solids`: a box
/// with a second box against one face and a third on top of it, sharing that whole face, and
/// a cylinder standing on the third). In an IGES 144 file their faces meet along edges that
/// four faces use; sewn all together they made one solid and an open shell. Open CASCADE
/// writes each shell's faces in a 402 group (IGES 5.3 section 4.81), and nurbsx sews each
/// group on its own: FreeCAD's file reads as the four solids of FreeCAD's source shape, each
/// with its volume (1e-9 relative); nurbsx's own 144 output of the STEP file lists each
/// solid's faces in a 402 form 7 group (section 4.83) and reads back the same way.
#[test]
fn touching_solids_stay_apart_through_iges_144() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts");
    let source: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("touching_solids.source.json")).unwrap(),
    )
    .unwrap();
    let mut want: Vec<f64> = source["solids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["volume"].as_f64().unwrap())
        .collect();
    want.sort_by(f64::total_cmp);
    assert_eq!(want.len(), 4);
    let volumes = |doc: &Document| -> Vec<f64> {
        let m = &doc.topology.model;
        let mut v: Vec<f64> = (0..m.solids.len())
            .map(|k| m.solid_volume(nurbsx::topology::SolidId(k)).unwrap())
            .collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let same = |got: &[f64], what: &str| {
        assert_eq!(got.len(), want.len(), "{what}: {got:?}");
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-9 * w, "{what}: {got:?} vs {want:?}");
        }
    };
    let freecad = read_text(&std::fs::read_to_string(dir.join("touching_solids.igs")).unwrap());
    assert_eq!(freecad.topology.model.shells.len(), 4);
    same(&volumes(&freecad), "FreeCAD's IGES 144");
    // The groups are read: not reported as skipped (the one group of groups, FreeCAD's
    // compound, is).
    let skipped = freecad
        .diagnostics
        .iter()
        .find(|d| d.code == "entities_skipped")
        .unwrap();
    assert!(skipped.message.contains("1 x 402"), "{}", skipped.message);

    let step = exchange::read(
        &std::fs::read(dir.join("touching_solids.step")).unwrap(),
        &ImportOptions::default(),
    )
    .unwrap();
    same(&volumes(&step), "STEP");
    let text = exchange::write(&step, exchange::Format::Iges, &ExportOptions::default()).unwrap();
    let file = nurbsx_parsers::iges::parse(&text).unwrap();
    let groups: Vec<Vec<i64>> = file
        .entries
        .iter()
        .flatten()
        .filter(|e| e.entity_type == 402)
        .map(|e| {
            assert_eq!(e.form, 7);
            file.decode::<nurbsx_parsers::iges::records::Group402>(e)
                .record
                .unwrap()
                .members
        })
        .collect();
    let mut sizes: Vec<usize> = groups.iter().map(Vec::len).collect();
    sizes.sort_unstable();
    assert_eq!(sizes, [3, 6, 6, 6]);
    for g in &groups {
        for &m in g {
            let member = file.entry(m).unwrap();
            assert_eq!(member.entity_type, 144);
            assert_eq!(member.status.subordinate, 2);
        }
    }
    let back = read_text(&text);
    same(&volumes(&back), "nurbsx's IGES 144");
    assert!(
        !back
            .diagnostics
            .iter()
            .any(|d| d.code == "entities_skipped")
    );
}

/// A face bounded by its surface's own domain (a 144 with `N1 = 0`: Open CASCADE writes so a
/// face that is its whole surface, FreeCAD's `Part.Face(surface)` in
/// `tests/data/iges/freecad_arc_surface.igs`) gets that boundary as its outer loop: an edge
/// over the iso-curve at each end of the domain, its pcurve the side of the domain, the
/// curves listed as `D<face>:u0` .. `:v1`. Before, the face had no loop: nurbsx's STEP
/// output wrote an ADVANCED_FACE without a bound (ISO 10303-42 face.bounds is SET [1:?]),
/// and such a face shared no edge with a neighbour to sew. The area stays the untrimmed
/// surface's, 20.082356846872056 by an independent 40-point Gauss-Legendre rule per knot
/// span over FreeCAD's own surface derivatives (FreeCAD's Face.Area says 20.2268: its fixed
/// rule's error on this rational surface). STEP and both IGES modes read back with the same
/// four edges. A sphere written bounded by its domain comes back with its seam edge (the
/// poles give no edge) and closes into its solid, of volume 4/3 pi r^3.
#[test]
fn a_face_bounded_by_its_domain_gets_that_boundary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = read_text(
        &std::fs::read_to_string(root.join("tests/data/iges/freecad_arc_surface.igs")).unwrap(),
    );
    let m = &doc.topology.model;
    assert_eq!(m.faces.len(), 1);
    let face = &m.faces[0];
    assert_eq!(face.loops.len(), 1);
    assert_eq!((m.edges.len(), m.vertices.len()), (4, 4));
    let ((u0, u1), (v0, v1)) = face.surface.domain();
    let corners = [[u0, v0], [u1, v0], [u1, v1], [u0, v1]];
    // Counter-clockwise in (u, v) from (u0, v0): each coedge's pcurve runs along one side.
    for (k, c) in face.loops[0].coedges.iter().enumerate() {
        let p = c.pcurve.as_ref().unwrap();
        let (a, b) = p.domain();
        let (s, e) = if c.forward { (a, b) } else { (b, a) };
        let (ps, pe) = (p.point_at(s).unwrap(), p.point_at(e).unwrap());
        assert_eq!([ps[0], ps[1]], corners[k], "coedge {k}");
        assert_eq!([pe[0], pe[1]], corners[(k + 1) % 4], "coedge {k}");
        // The edge's curve runs on the surface along that side.
        let edge = &m.edges[c.edge.0];
        for i in 0..=8 {
            let t = a + (b - a) * f64::from(i) / 8.0;
            let q = p.point_at(t).unwrap();
            let on = face.surface.point_at(q[0], q[1]).unwrap();
            let at = edge.curve.point_at(t).unwrap();
            assert!(
                (0..3).all(|j| (on[j] - at[j]).abs() <= 1e-12),
                "{on:?} {at:?}"
            );
        }
    }
    let ids: Vec<&str> = doc.entities.iter().map(|e| e.id.as_str()).collect();
    for side in ["D3:v0", "D3:u1", "D3:v1", "D3:u0"] {
        assert!(ids.contains(&side), "{ids:?}");
    }
    let area = m.measure_face(face).unwrap().area;
    let independent = 20.082356846872056;
    assert!((area - independent).abs() <= 1e-12 * independent, "{area}");
    let step = exchange::write(&doc, exchange::Format::Step, &ExportOptions::default()).unwrap();
    assert!(!step.contains("ADVANCED_FACE('',()"));
    for (format, iges_brep) in [
        (exchange::Format::Step, false),
        (exchange::Format::Iges, false),
        (exchange::Format::Iges, true),
    ] {
        let options = ExportOptions {
            iges_brep,
            ..ExportOptions::default()
        };
        let text = exchange::write(&doc, format, &options).unwrap();
        let back = exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap();
        let b = &back.topology.model;
        assert_eq!(
            (b.faces.len(), b.edges.len(), b.vertices.len()),
            (1, 4, 4),
            "{format:?} {iges_brep}"
        );
        let a = b.measure_face(&b.faces[0]).unwrap().area;
        assert!((a - independent).abs() <= 1e-12 * independent, "{a}");
    }

    // A sphere bounded only by a vertex loop is written as a 144 bounded by its domain.
    let sphere = exchange::read(
        &std::fs::read(root.join("samples/freecad/analytic/sphere.step")).unwrap(),
        &ImportOptions::default(),
    )
    .unwrap();
    let text = exchange::write(&sphere, exchange::Format::Iges, &ExportOptions::default()).unwrap();
    let back = read_text(&text);
    let b = &back.topology.model;
    assert_eq!((b.edges.len(), b.vertices.len()), (1, 2));
    assert_eq!(b.faces[0].loops[0].coedges.len(), 2);
    assert_eq!(b.solids.len(), 1);
    let r: f64 = 10.0;
    let want = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let v = b.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
    assert!((v - want).abs() <= 1e-9 * want, "{v} vs {want}");
}
