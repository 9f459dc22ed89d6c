//! Meshes of whole parts (`Model::mesh`, `nurbsx tessellate`), checked against figures
//! that do not come from the mesher:
//! - each face's mesh area against the exact trimmed area (`Model::measure_face`, Green's
//!   theorem along the pcurves) and each part's total against FreeCAD's reading (the sample
//!   JSONs), within the bound the chord tolerance allows (below);
//! - triangle centroids and edge midpoints against the surface (`invert_surface`);
//! - closed shells watertight (every mesh edge used once in each direction), their signed
//!   volume against FreeCAD's solid volume;
//! - the hole of a plate against its exact circle; a broken loop gives a reported skip.
//!
//! The area bound: a flat triangle whose points are within `d` of a surface with principal
//! curvatures `k1, k2` differs in area from the surface over it by at most about
//! `(|k1| + |k2|) d` relatively (on a cylinder of radius `r`, chords of sagitta `d` lose
//! `d / (3 r)`), and the boundary chords cut off at most `d` times the boundary length; so
//! `|A_mesh - A| <= A max(|k1| + |k2|) d + P d`, with `d` the tolerance plus the edges'
//! tolerance (edge points lie that far from the surface).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nurbsx::exchange::{self, Document, ImportOptions};
use nurbsx::nurbs::project::invert_surface;
use nurbsx::nurbs::tessellate::{Budget, Mesh};
use nurbsx::nurbs::vector::{cross, dist, dot, norm, sub};
use nurbsx::nurbs::{NurbsCurve, NurbsSurface, Point3};
use nurbsx::topology::{Coedge, FaceId, Loop, Model, PartMesh};
use serde_json::Value;

fn parts() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts")
}

fn read(path: &Path) -> Document {
    exchange::read(&std::fs::read(path).unwrap(), &ImportOptions::default()).unwrap()
}

fn reading(file: &str) -> Value {
    let text = std::fs::read_to_string(parts().join(format!("{file}.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn budget() -> Budget<'static> {
    Budget {
        max_points: 4_000_000,
        stop: &|| false,
    }
}

fn mesh(m: &Model, tolerance: f64) -> PartMesh {
    m.mesh(None, tolerance, &budget()).unwrap()
}

fn area(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.vertices[i]);
            0.5 * norm(cross(sub(b, a), sub(c, a)))
        })
        .sum()
}

/// Largest `|k1| + |k2|` on a 9 x 9 sample of the surface's domain.
fn curvature(s: &NurbsSurface) -> f64 {
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut k: f64 = 0.0;
    for i in 0..9 {
        for j in 0..9 {
            let u = u0 + (u1 - u0) * (i as f64 + 0.5) / 9.0;
            let v = v0 + (v1 - v0) * (j as f64 + 0.5) / 9.0;
            if let Ok(c) = s.curvature(u, v) {
                k = k.max(c.k1.abs() + c.k2.abs());
            }
        }
    }
    k
}

/// The edges' tolerance and boundary length of a face (from the edge polylines).
fn boundary(m: &Model, pm: &PartMesh, face: usize) -> (f64, f64) {
    let (mut tol, mut length): (f64, f64) = (0.0, 0.0);
    for l in &m.faces[face].loops {
        for c in &l.coedges {
            tol = tol.max(m.edges[c.edge.0].tolerance);
            if let Some(Some(line)) = pm.edges.get(c.edge.0) {
                length += line
                    .points
                    .windows(2)
                    .map(|w| dist(w[0], w[1]))
                    .sum::<f64>();
            }
        }
    }
    (tol, length)
}

/// Largest distance from the surface of the centroids and edge midpoints of (at most 150
/// of) the mesh's triangles.
fn farthest(s: &NurbsSurface, mesh: &Mesh, bound: f64) -> f64 {
    let step = (mesh.triangles.len() / 150).max(1);
    let mut worst: f64 = 0.0;
    for t in mesh.triangles.iter().step_by(step) {
        let [a, b, c] = t.map(|i| mesh.vertices[i]);
        let guess = {
            let [p, q, r] = t.map(|i| mesh.params[i]);
            ((p[0] + q[0] + r[0]) / 3.0, (p[1] + q[1] + r[1]) / 3.0)
        };
        let mid = |x: Point3, y: Point3| std::array::from_fn(|k| 0.5 * (x[k] + y[k]));
        let centroid: Point3 = std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
        for p in [centroid, mid(a, b), mid(b, c), mid(c, a)] {
            // Newton from the corners' mean parameters, and from a global start where that
            // lands farther than the bound (a local minimum across a seam).
            let mut d = invert_surface(s, p, Some(guess)).unwrap().distance;
            // On a closed surface the mean of corners across the seam is on the far side:
            // each corner is a start too.
            for i in *t {
                if d > bound {
                    let [u, v] = mesh.params[i];
                    d = d.min(invert_surface(s, p, Some((u, v))).unwrap().distance);
                }
            }
            if d > bound {
                d = d.min(invert_surface(s, p, None).unwrap().distance);
            }
            worst = worst.max(d);
        }
    }
    worst
}

/// Checks a closed shell's meshes: every undirected edge used exactly twice, once in each
/// direction (vertices identified by their exact coordinates across faces); returns the
/// signed volume (divergence theorem over the outward triangles).
fn watertight_volume(m: &Model, pm: &PartMesh, shell: usize, what: &str) -> f64 {
    let mut ids: HashMap<[u64; 3], usize> = HashMap::new();
    let mut directed: HashMap<(usize, usize), i32> = HashMap::new();
    let mut volume = 0.0;
    for &(f, orientation) in &m.shells[shell].faces {
        let mesh = pm.faces[f.0].as_ref().unwrap();
        let n = ids.len();
        let local: Vec<usize> = mesh
            .vertices
            .iter()
            .map(|p| {
                let n = ids.len();
                *ids.entry(p.map(f64::to_bits)).or_insert(n)
            })
            .collect();
        let _ = n;
        for t in &mesh.triangles {
            let mut t = *t;
            if !orientation {
                t.swap(1, 2);
            }
            let [a, b, c] = t.map(|i| mesh.vertices[i]);
            volume += dot(a, cross(b, c)) / 6.0;
            for k in 0..3 {
                let (x, y) = (local[t[k]], local[t[(k + 1) % 3]]);
                *directed.entry((x, y)).or_default() += 1;
            }
        }
    }
    for (&(x, y), &count) in &directed {
        let back = directed.get(&(y, x)).copied().unwrap_or(0);
        assert!(
            count == 1 && back == 1,
            "{what}: shell {shell}: mesh edge {x}-{y} used {count} times, reversed {back} times"
        );
    }
    volume
}

/// Faces the mesher may leave out (and reports) today, over all 51 sample files: loops that
/// wind around a closed surface across its seam in ways the boundary walk does not resolve
/// yet (a torus, spheres and cones cut by their seam in IGES files).
const MAX_SKIPPED: usize = 12;

/// Every part sample (STEP, IGES 144 faces, IGES 186 B-rep): per-face area and distance,
/// total area against FreeCAD, closed shells watertight with FreeCAD's volume. An
/// optimised build (`cargo test --release`) checks all 51 files at a chord tolerance of
/// 4e-3 of the part's size; the plain test command's debug build, some fifteen times
/// slower, checks the 17 STEP files at 1e-2 of the size (the bounds follow the tolerance).
#[test]
fn parts_match_exact_measures_and_freecad() {
    let (relative, only_step) = if cfg!(debug_assertions) {
        (1e-2, true)
    } else {
        (4e-3, false)
    };
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(parts().join("index.json")).unwrap())
            .unwrap();
    let (mut checked, mut skipped) = (0, 0);
    for part in index["parts"].as_array().unwrap() {
        for file in part["files"].as_array().unwrap() {
            let name = file["file"].as_str().unwrap();
            if only_step && !name.ends_with(".step") {
                continue;
            }
            let json = reading(name);
            let doc = read(&parts().join(name));
            // FreeCAD's readings are in millimetres; the model is in the file's unit (the
            // inch part), so FreeCAD's figures are brought to it.
            let mm = doc.units.to_mm();
            let size = json["size"].as_f64().unwrap() / mm;
            let tolerance = relative * size;
            let m = &doc.topology.model;
            let pm = mesh(m, tolerance);
            for (f, why) in &pm.skipped {
                eprintln!("{name}: face {} left out: {why}", f.0);
            }
            skipped += pm.skipped.len();
            let mut total = 0.0;
            let mut bound_total = 0.0;
            let mut allowance: f64 = 0.0;
            for (f, face) in m.faces.iter().enumerate() {
                let Some(fm) = &pm.faces[f] else { continue };
                let (edge_tol, perimeter) = boundary(m, &pm, f);
                let d = tolerance + edge_tol;
                allowance = allowance.max(edge_tol);
                // Distance: the tolerance plus the edges' tolerance (boundary corners are
                // edge points, that far from the surface at most) plus 1e-9 of the size.
                let far = farthest(&face.surface, fm, d + 1e-9 * size);
                assert!(
                    far <= d + 1e-9 * size,
                    "{name} face {f}: a triangle is {far:e} from the surface (tolerance {d:e})"
                );
                let a = area(fm);
                let bound = a * curvature(&face.surface) * d + perimeter * d;
                if let Ok(exact) = m.measure_face(face) {
                    assert!(
                        (a - exact.area).abs() <= bound,
                        "{name} face {f}: mesh area {a} vs exact {} (bound {bound:e})",
                        exact.area
                    );
                }
                total += a;
                bound_total += bound;
            }
            // The assembly's product structure (parts placed several times) is not read
            // into the topology yet (tests/step_topology.rs KNOWN_GAPS): FreeCAD's totals
            // count every placed instance, so only its faces are checked.
            if pm.skipped.is_empty() && !name.starts_with("assembly_links") {
                let freecad = json["totals"]["area"].as_f64().unwrap() / (mm * mm);
                assert!(
                    (total - freecad).abs() <= bound_total,
                    "{name}: mesh area {total} vs FreeCAD's {freecad} (bound {bound_total:e})"
                );
                // FreeCAD's solid volumes (from its STEP reading: it makes no solids of
                // IGES 144 faces), in increasing order, against the meshes'.
                let step = reading(&format!("{}.step", part["part"].as_str().unwrap()));
                let mut want: Vec<f64> = step["solids"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x["volume"].as_f64().unwrap() / (mm * mm * mm))
                    .collect();
                let mut got: Vec<(f64, f64)> = Vec::new();
                for solid in &m.solids {
                    let mut volume = 0.0;
                    let mut shell_area = 0.0;
                    for shell in std::iter::once(&solid.outer).chain(&solid.voids) {
                        volume += watertight_volume(m, &pm, shell.0, name);
                        for (f, _) in &m.shells[shell.0].faces {
                            shell_area += area(pm.faces[f.0].as_ref().unwrap());
                        }
                    }
                    // The mesh lies within the tolerance (plus the edge allowance) of the
                    // surface everywhere, so the enclosed volumes differ by at most that
                    // times the area.
                    got.push((volume, shell_area * (tolerance + allowance)));
                }
                if !got.is_empty() {
                    want.sort_by(f64::total_cmp);
                    got.sort_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
                    assert_eq!(got.len(), want.len(), "{name}: solids");
                    // IGES 144 faces carry no orientation: nurbsx sews them and orients the
                    // shell, and the revolved part comes out inside-out (reported); there the
                    // size is compared. STEP and IGES 186 files orient their faces.
                    let sewn = !name.ends_with(".step") && !name.ends_with("_brep.igs");
                    for ((volume, bound), freecad) in got.iter().zip(&want) {
                        let volume = if sewn { volume.abs() } else { *volume };
                        assert!(
                            (volume - freecad).abs() <= *bound,
                            "{name}: mesh volume {volume} vs FreeCAD's {freecad} (bound {bound:e})"
                        );
                    }
                }
            }
            checked += 1;
        }
    }
    assert!(
        checked >= if only_step { 17 } else { 51 },
        "only {checked} sample files checked"
    );
    assert!(skipped <= MAX_SKIPPED, "{skipped} faces left out");
}

/// Straight edges are their two vertices, seams included: the extrusion's seam (a line
/// used twice by the lateral face) is one chord on both sides, and the shell stays
/// watertight with FreeCAD's volume at coarse and fine tolerances.
#[test]
fn straight_seams_are_one_chord_and_the_shell_stays_closed() {
    let name = "extrude_bspline.step";
    let json = reading(name);
    let size = json["size"].as_f64().unwrap();
    let freecad = reading(name)["solids"][0]["volume"].as_f64().unwrap();
    let doc = read(&parts().join(name));
    let m = &doc.topology.model;
    let seams: Vec<usize> = (0..m.edges.len())
        .filter(|&e| {
            m.faces.iter().any(|f| {
                f.loops
                    .iter()
                    .flat_map(|l| &l.coedges)
                    .filter(|c| c.edge.0 == e)
                    .count()
                    == 2
            })
        })
        .collect();
    assert!(!seams.is_empty(), "the lateral face has a seam");
    for relative in [1e-2, 1e-3] {
        let tolerance = relative * size;
        let pm = mesh(m, tolerance);
        assert!(pm.skipped.is_empty(), "{:?}", pm.skipped);
        for &e in &seams {
            let c = &m.edges[e].curve;
            let straight = c.degree() == 1 && c.num_poles() == 2;
            assert!(straight, "seam {e} is a line");
            assert_eq!(pm.edges[e].as_ref().unwrap().points.len(), 2, "seam {e}");
        }
        let volume = watertight_volume(m, &pm, m.solids[0].outer.0, name);
        let shell_area: f64 = m.shells[m.solids[0].outer.0]
            .faces
            .iter()
            .map(|(f, _)| area(pm.faces[f.0].as_ref().unwrap()))
            .sum();
        let allowance = m.edges.iter().map(|e| e.tolerance).fold(0.0, f64::max);
        assert!(
            (volume - freecad).abs() <= shell_area * (tolerance + allowance),
            "at {tolerance}: mesh volume {volume} vs FreeCAD's {freecad}"
        );
    }
}

/// The plate's through hole: no triangle of the top or bottom face has its centroid inside
/// the hole's exact circle (FreeCAD's cylinder face of radius 5 gives the axis).
#[test]
fn hole_is_empty() {
    let name = "box_fillet_chamfer_hole.step";
    let json = reading(name);
    let height = 20.0;
    let radius = 5.0;
    let hole = json["faces"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| {
            f["surface_type"] == "Cylinder"
                && (f["area"].as_f64().unwrap() - 2.0 * std::f64::consts::PI * radius * height)
                    .abs()
                    < 1e-6
        })
        .expect("the hole's cylinder face");
    let axis = &hole["center_of_mass"];
    let (cx, cy) = (axis[0].as_f64().unwrap(), axis[1].as_f64().unwrap());
    let doc = read(&parts().join(name));
    let tolerance = 0.02;
    let pm = mesh(&doc.topology.model, tolerance);
    let mut flat_faces = 0;
    for fm in pm.faces.iter().flatten() {
        let z0 = fm.vertices[0][2];
        if !fm.vertices.iter().all(|p| (p[2] - z0).abs() < 1e-9) {
            continue;
        }
        flat_faces += 1;
        for t in &fm.triangles {
            let [a, b, c] = t.map(|i| fm.vertices[i]);
            let (x, y) = ((a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0);
            assert!(
                (x - cx).hypot(y - cy) >= radius - tolerance,
                "a triangle centroid ({x}, {y}, {z0}) lies in the hole"
            );
        }
    }
    assert!(flat_faces >= 2, "top and bottom faces expected");
}

/// The lone trimmed face: FreeCAD's area 721.478 within the bound, from STEP and IGES.
#[test]
fn lone_trimmed_face_area() {
    for name in ["trimmed_face.step", "trimmed_face.igs"] {
        let freecad = reading(name)["totals"]["area"].as_f64().unwrap();
        assert!((freecad - 721.478).abs() < 1e-3);
        let doc = read(&parts().join(name));
        let m = &doc.topology.model;
        let tolerance = 0.01;
        let pm = mesh(m, tolerance);
        assert!(pm.skipped.is_empty(), "{name}: {:?}", pm.skipped);
        let fm = pm.faces[0].as_ref().unwrap();
        let (edge_tol, perimeter) = boundary(m, &pm, 0);
        let d = tolerance + edge_tol;
        let a = area(fm);
        let bound = a * curvature(&m.faces[0].surface) * d + perimeter * d;
        assert!(
            (a - freecad).abs() <= bound,
            "{name}: mesh area {a} vs FreeCAD's {freecad} (bound {bound:e})"
        );
        // Far from the untrimmed surface's area: the trim is honoured.
        let untrimmed = m
            .measure_face(&nurbsx::topology::Face {
                surface: m.faces[0].surface.clone(),
                loops: Vec::new(),
                same_sense: true,
                vertex_loops: Vec::new(),
            })
            .unwrap()
            .area;
        assert!(untrimmed > 1.5 * a, "{untrimmed} vs {a}");
    }
}

/// Halving the tolerance about halves the area error (chords of sagitta `d` lose an area
/// proportional to `d`).
#[test]
fn area_error_converges_with_the_tolerance() {
    let name = "steinmetz.step";
    let exact = reading(name)["totals"]["area"].as_f64().unwrap();
    let doc = read(&parts().join(name));
    let m = &doc.topology.model;
    let error = |tolerance: f64| {
        let pm = mesh(m, tolerance);
        assert!(pm.skipped.is_empty());
        let total: f64 = pm.faces.iter().flatten().map(area).sum();
        (total - exact).abs()
    };
    let (coarse, fine) = (error(0.1), error(0.05));
    assert!(coarse > 0.0);
    assert!(
        fine <= 0.7 * coarse && fine >= 0.2 * coarse,
        "error {coarse:e} at 0.1, {fine:e} at 0.05"
    );
}

fn line(a: Point3, b: Point3) -> NurbsCurve {
    NurbsCurve::new(1, vec![0.0, 0.0, 1.0, 1.0], vec![a, b], None).unwrap()
}

/// A bow-tie loop on a plane (its boundary crosses itself; every constructor check passes:
/// the loop closes through its vertices, the pcurves agree with the edges) is left out with
/// the reason, and the other face of the model is meshed.
#[test]
fn crossing_loop_is_reported_not_fatal() {
    let plane = NurbsSurface::new(
        1,
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        nurbsx::nurbs::Grid::from_u_major(
            2,
            2,
            vec![
                [0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
            ],
        )
        .unwrap(),
        None,
    )
    .unwrap();
    let mut m = Model::new();
    // The two crossing sides meet at (0.588.., 0.588..), no sample point of either.
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.7, 0.0],
    ];
    let vs: Vec<_> = corners
        .iter()
        .map(|&p| m.add_vertex(p, 1e-9).unwrap())
        .collect();
    let mut coedges = Vec::new();
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        let e = m
            .add_edge(line(a, b), (0.0, 1.0), vs[k], vs[(k + 1) % 4], 1e-9)
            .unwrap();
        coedges.push(Coedge {
            edge: e,
            forward: true,
            pcurve: Some(
                NurbsCurve::with_dimension(
                    1,
                    vec![0.0, 0.0, 1.0, 1.0],
                    vec![[a[0], a[1], 0.0], [b[0], b[1], 0.0]],
                    None,
                    2,
                )
                .unwrap(),
            ),
            pcurve_deviation: None,
        });
    }
    let bowtie = m
        .add_face(
            plane.clone(),
            vec![Loop {
                coedges,
                outer: true,
            }],
            true,
        )
        .unwrap();
    let whole = m.add_face(plane, Vec::new(), true).unwrap();
    let pm = mesh(&m, 1e-3);
    assert_eq!(pm.skipped.len(), 1);
    assert_eq!(pm.skipped[0].0, bowtie);
    assert!(pm.skipped[0].1.to_string().contains("crosses"));
    assert!(pm.faces[bowtie.0].is_none());
    let w = pm.faces[whole.0].as_ref().unwrap();
    assert!((area(w) - 1.0).abs() < 1e-12);
    let _ = FaceId(0);
}

/// `nurbsx tessellate part.step -o x.glb`: one mesh node per face, named by the face's id.
#[test]
fn cli_glb_has_one_node_per_face() {
    let name = "box_fillet_chamfer_hole.step";
    let input = parts().join(name);
    let out = std::env::temp_dir().join(format!("nurbsx-topology-mesh-{}.glb", std::process::id()));
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_nurbsx"))
        .args(["tessellate", "--tolerance", "0.05"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let glb = std::fs::read(&out).unwrap();
    let _ = std::fs::remove_file(&out);
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json: Value = serde_json::from_slice(&glb[20..20 + len]).unwrap();
    let doc = read(&input);
    let face_ids: Vec<&str> = doc
        .topology
        .origins
        .faces
        .iter()
        .map(|o| o.id.as_str())
        .collect();
    let meshes = json["meshes"].as_array().unwrap();
    let triangle_nodes: Vec<&str> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| meshes[n["mesh"].as_u64().unwrap() as usize]["primitives"][0]["mode"] == 4)
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(face_ids.len(), 19);
    assert_eq!(triangle_nodes, face_ids);
}
