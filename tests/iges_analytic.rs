//! The IGES analytic entities against FreeCAD's own evaluation and against independent
//! computations.
//!
//! FreeCAD part: `samples/freecad/analytic/` (see its README: FreeCAD 0.20.2 / OCCT 7.6.3
//! writes each case and re-reads it; the JSON holds FreeCAD's points and first and second
//! derivatives at FreeCAD's parameters). nurbsx's NURBS must give the same point, within
//! 1e-12 of the model size, and the same derivatives, within 1e-9 relative, at FreeCAD's
//! parameter mapped through the documented parameter map (README "Parameterisation"):
//! an affine change (orientation, origin, arc length <-> `[0, 1]` for lines, axial <->
//! slant distance for cones), then for circles, conics and rotations the rational arc's
//! map, computed here from its defining relation `tan((t - m)/2) = tan((b - a)/4)(2s - 1)`
//! on each segment `[a, b]` of the knot vector (`tanh` for hyperbolic arcs), independently
//! of the library's `ArcMap`. Derivatives follow by the chain rule.
//!
//! Hand-made part: entities FreeCAD does not write (112, 114, general-position 104, 118,
//! unbounded surfaces without a use, inexact entities) with their expected geometry
//! computed from the entity's definition (power series, the implicit conic equation,
//! the bilinear ruled patch), never from nurbsx's output.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
#![allow(clippy::cast_precision_loss)]

#[path = "../parsers/tests/iges_support/mod.rs"]
mod iges_util;

use iges_util::{Builder, De};
use nurbsx::exchange::{self, Document, ImportOptions, Severity};
use nurbsx::nurbs::{Geometry, NurbsCurve, NurbsSurface, Point3};
use serde_json::Value;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/samples/freecad/analytic/");

/// The document, FreeCAD's JSON, and the largest departure from orthonormality of the
/// file's 124 rotation matrices (`max |R R^T - I|`).
///
/// IGES 5.3 section 4.21 defines `x' = R x + T`, which nurbsx applies as written. Open
/// CASCADE writes `R` with 9 significant digits, so a rotation is orthonormal only to about
/// 1e-9, and Open CASCADE's reader makes it orthonormal again (each entity type its own way:
/// rows or columns). Geometry that passes through such a matrix can therefore agree with
/// FreeCAD only to that defect times the model size, which the tolerances below add to the
/// 1e-12 (points) and 1e-9 (derivatives) of the exact comparison; files without a rotation
/// have defect 0 and are compared at 1e-12 / 1e-9.
fn load(name: &str) -> (Document, Value, f64) {
    let text = std::fs::read_to_string(format!("{DIR}{name}")).unwrap();
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{DIR}{name}.json")).unwrap())
            .unwrap();
    let doc = exchange::iges::read(&text, &ImportOptions::default()).unwrap();
    assert!(!doc.has_errors(), "{name}: {:#?}", doc.diagnostics);
    let file = nurbsx_parsers::iges::parse(&text).unwrap();
    let mut defect = 0.0f64;
    for e in file
        .entries
        .iter()
        .flatten()
        .filter(|e| e.entity_type == 124)
    {
        let t = file
            .decode::<nurbsx_parsers::iges::records::Transform124>(e)
            .record
            .unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| t.rows[i][k] * t.rows[j][k]).sum();
                let id = if i == j { 1.0 } else { 0.0 };
                defect = defect.max((d - id).abs());
            }
        }
    }
    (doc, json, defect)
}

fn p3(v: &Value) -> Point3 {
    let a = v.as_array().unwrap();
    [0, 1, 2].map(|k| a[k].as_f64().unwrap())
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: Point3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn lin(a: Point3, s: f64, b: Point3, t: f64) -> Point3 {
    [0, 1, 2].map(|k| a[k] * s + b[k] * t)
}

/// Relative difference of two vectors (scaled by the larger norm, at least `floor`).
fn rel(a: Point3, b: Point3, floor: f64) -> f64 {
    norm(sub(a, b)) / norm(a).max(norm(b)).max(floor)
}

/// One parameter's map from FreeCAD's parameter to nurbsx's: `t = sigma x + delta`, then
/// (for arcs) the rational arc's map `u(t)` on the knot segments, with wrap-around by
/// `period` into the domain. Returns `(u, du/dx, d2u/dx2)`.
#[derive(Clone, Debug)]
struct Map {
    sigma: f64,
    delta: f64,
    /// Segment ends of a rational arc (distinct knots), `None` for an affine map.
    arc: Option<Vec<f64>>,
    hyperbolic: bool,
    period: f64,
}

impl Map {
    fn affine(sigma: f64, delta: f64) -> Map {
        Map {
            sigma,
            delta,
            arc: None,
            hyperbolic: false,
            period: 0.0,
        }
    }

    fn apply(&self, x: f64) -> (f64, f64, f64) {
        let mut t = self.sigma * x + self.delta;
        let Some(ends) = &self.arc else {
            return (t, self.sigma, 0.0);
        };
        let (lo, hi) = (ends[0], ends[ends.len() - 1]);
        if self.period > 0.0 {
            while t < lo - 1e-12 {
                t += self.period;
            }
            while t > hi + 1e-12 {
                t -= self.period;
            }
        }
        let t = t.clamp(lo, hi);
        // At a knot, the segment that starts there: the span A2.1 evaluates (the map's
        // and the NURBS's second derivatives both jump at a knot; their product does not).
        let i = ends
            .windows(2)
            .position(|w| t < w[1])
            .unwrap_or(ends.len() - 2);
        let (a, b) = (ends[i], ends[i + 1]);
        let m = 0.5 * (a + b);
        // tan((t - m)/2) = tan((b - a)/4)(2s - 1), u = a + s (b - a).
        let (h, tq, dh, ddh) = if self.hyperbolic {
            let h = (0.5 * (t - m)).tanh();
            (h, (0.25 * (b - a)).tanh(), 1.0 - h * h, -h * (1.0 - h * h))
        } else {
            let h = (0.5 * (t - m)).tan();
            (h, (0.25 * (b - a)).tan(), 1.0 + h * h, h * (1.0 + h * h))
        };
        let k = (b - a) / (4.0 * tq);
        let u = a + 0.5 * (1.0 + h / tq) * (b - a);
        (u, k * dh * self.sigma, k * ddh * self.sigma * self.sigma)
    }
}

/// The distinct knots of a knot vector inside `[lo, hi]`.
fn segment_ends(knots: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = Vec::new();
    for &k in knots {
        if v.last() != Some(&k) {
            v.push(k);
        }
    }
    v
}

/// The largest point error (absolute) and derivative errors (relative) of `c` against
/// FreeCAD's samples of one edge under `map`.
fn curve_errors(c: &NurbsCurve, samples: &[Value], map: &Map, size: f64) -> (f64, f64) {
    let (mut ep, mut ed) = (0.0f64, 0.0f64);
    for s in samples {
        let (u, du, ddu) = map.apply(f(&s["t"]));
        let (d0, d1) = c.domain();
        if !(d0 - 1e-12..=d1 + 1e-12).contains(&u) {
            return (f64::INFINITY, f64::INFINITY);
        }
        let d = c.derivatives(u.clamp(d0, d1), 2).unwrap();
        ep = ep.max(norm(sub(d[0], p3(&s["point"]))));
        let d1e = lin(d[1], du, [0.0; 3], 0.0);
        let d2e = lin(d[2], du * du, d[1], ddu);
        ed = ed.max(rel(d1e, p3(&s["d1"]), size * 1e-3));
        ed = ed.max(rel(d2e, p3(&s["d2"]), size * 1e-3));
    }
    (ep, ed)
}

fn curves(doc: &Document) -> Vec<(&str, &NurbsCurve)> {
    doc.entities
        .iter()
        .filter_map(|e| match &e.geometry {
            Geometry::Curve(c) => Some((&*e.source.entity, c)),
            Geometry::Surface(_) => None,
        })
        .collect()
}

fn size_of(json: &Value) -> f64 {
    let mut m = 1.0f64;
    for e in json["edges"].as_array().unwrap() {
        for s in e["samples"].as_array().unwrap() {
            m = m.max(norm(p3(&s["point"])));
        }
    }
    for fa in json["faces"].as_array().unwrap() {
        for s in fa["samples"].as_array().unwrap() {
            m = m.max(norm(p3(&s["point"])));
        }
    }
    m
}

/// The best (point error, derivative error) of an item is within 1e-12 of the model size and
/// 1e-9 relative, widened by the file's 124 defect (see [`load`]); printed for the record.
fn agrees(what: &str, best: (f64, f64), size: f64, defect: f64) {
    assert!(
        best.0 <= (1e-12 + 10.0 * defect) * size && best.1 <= 1e-9 + 10.0 * defect,
        "{what}: point error {:e} (size {size}, 124 defect {defect:e}), derivative error {:e}",
        best.0,
        best.1
    );
    eprintln!(
        "{what}: point error {:.1e} x size, derivative error {:.1e} (124 defect {defect:.1e})",
        best.0 / size,
        best.1
    );
}

/// The candidate maps of a curve edge of FreeCAD type `ty` onto `c`.
fn curve_maps(ty: &str, c: &NurbsCurve, edge: &Value) -> Vec<Map> {
    let ends = segment_ends(c.knots());
    let mut out = Vec::new();
    match ty {
        "Part.Line" => {
            // 110: u in [0, 1] from P1 to P2; FreeCAD's t is the arc length from P1.
            let (a, b) = (c.point_at(0.0).unwrap(), c.point_at(1.0).unwrap());
            let len = norm(sub(b, a));
            let origin = p3(&edge["curve"]["location"]);
            let dir = p3(&edge["curve"]["direction"]);
            // FreeCAD's t of P1.
            let t1 = (0..3).map(|k| (a[k] - origin[k]) * dir[k]).sum::<f64>();
            for sigma in [1.0, -1.0] {
                out.push(Map::affine(sigma / len, -sigma * t1 / len));
            }
        }
        "Part.Parabola" => {
            for sigma in [1.0, -1.0] {
                out.push(Map::affine(sigma, 0.0));
            }
        }
        "Part.Circle" | "Part.Ellipse" | "Part.Hyperbola" => {
            let hyperbolic = ty == "Part.Hyperbola";
            for sigma in [1.0, -1.0] {
                let deltas: Vec<f64> = if hyperbolic {
                    vec![0.0]
                } else {
                    (-4..=4)
                        .map(|k| f64::from(k) * std::f64::consts::FRAC_PI_2)
                        .collect()
                };
                for delta in deltas {
                    out.push(Map {
                        sigma,
                        delta,
                        arc: Some(ends.clone()),
                        hyperbolic,
                        period: if hyperbolic {
                            0.0
                        } else {
                            std::f64::consts::TAU
                        },
                    });
                }
            }
        }
        _ => {}
    }
    out
}

/// Every FreeCAD edge of the listed curve types matches one nurbsx curve of `entity` type
/// under one of its candidate maps.
fn check_curves(name: &str, entity: &str) -> usize {
    let (doc, json, defect) = load(name);
    let size = size_of(&json);
    let mine = curves(&doc);
    let mut checked = 0;
    for edge in json["edges"].as_array().unwrap() {
        let ty = edge["curve"]["type"].as_str().unwrap_or("");
        let samples = edge["samples"].as_array().unwrap();
        let mut best = (f64::INFINITY, f64::INFINITY);
        for &(_, c) in mine.iter().filter(|(e, _)| *e == entity) {
            for m in curve_maps(ty, c, edge) {
                let e = curve_errors(c, samples, &m, size);
                if e.0 < best.0 {
                    best = e;
                }
            }
        }
        agrees(
            &format!("{name}: {ty} edge {}", edge["index"]),
            best,
            size,
            defect,
        );
        checked += 1;
    }
    checked
}

#[test]
fn circles_conics_and_lines_match_freecad() {
    for (name, entity) in [
        ("circle_arc_tilted.igs", "100"),
        ("circle_full.igs", "100"),
        ("ellipse_arc.igs", "104"),
        ("hyperbola_arc.igs", "104"),
        ("parabola_arc.igs", "104"),
        ("line_segment.igs", "110"),
    ] {
        assert_eq!(check_curves(name, entity), 1, "{name}");
    }
}

/// The largest point error (absolute) and derivative error (relative) of `s` against
/// FreeCAD's samples of one face under the maps `mu`, `mv`.
fn surface_errors(
    s: &NurbsSurface,
    samples: &[Value],
    mu: &Map,
    mv: &Map,
    size: f64,
) -> (f64, f64) {
    let ((u0, u1), (v0, v1)) = s.domain();
    let (mut ep, mut ed) = (0.0f64, 0.0f64);
    for x in samples {
        let (u, du, ddu) = mu.apply(f(&x["u"]));
        let (v, dv, ddv) = mv.apply(f(&x["v"]));
        let eps = 1e-9 * (u1 - u0).abs().max(v1 - v0).max(1.0);
        if !(u0 - eps..=u1 + eps).contains(&u) || !(v0 - eps..=v1 + eps).contains(&v) {
            return (f64::INFINITY, f64::INFINITY);
        }
        let d = s.derivatives(u.clamp(u0, u1), v.clamp(v0, v1), 2).unwrap();
        ep = ep.max(norm(sub(d[0][0], p3(&x["point"]))));
        // Relative to the larger vector, or to the model size where a derivative vanishes
        // (the u derivatives at a cone's apex or a sphere's poles).
        let floor = size;
        let want = [
            (lin(d[1][0], du, [0.0; 3], 0.0), "su"),
            (lin(d[0][1], dv, [0.0; 3], 0.0), "sv"),
            (lin(d[2][0], du * du, d[1][0], ddu), "suu"),
            (lin(d[1][1], du * dv, [0.0; 3], 0.0), "suv"),
            (lin(d[0][2], dv * dv, d[0][1], ddv), "svv"),
        ];
        for (mine, key) in want {
            ed = ed.max(rel(mine, p3(&x[key]), floor));
        }
    }
    (ep, ed)
}

/// Angle maps `t = sigma x + delta`: both orientations, origins a multiple of a quarter
/// turn apart, or at either end of nurbsx's range (Open CASCADE starts a surface of
/// revolution's angle at its start angle).
fn angle_maps(ends: &[f64], period: f64) -> Vec<Map> {
    let mut out = Vec::new();
    let (lo, hi) = (ends[0], ends[ends.len() - 1]);
    for sigma in [1.0, -1.0] {
        for base in [0.0, lo, hi] {
            for k in -4..=4 {
                out.push(Map {
                    sigma,
                    delta: base + f64::from(k) * std::f64::consts::FRAC_PI_2,
                    arc: Some(ends.to_vec()),
                    hyperbolic: false,
                    period,
                });
            }
        }
    }
    out
}

/// Candidate maps of a FreeCAD profile (generatrix / directrix) parameter onto nurbsx's.
fn profile_maps(curve: &Value, ends: &[f64]) -> Vec<Map> {
    match curve["type"].as_str().unwrap_or("") {
        "Part.LineSegment" => {
            // 110: nurbsx's [0, 1] from P1 to P2; Open CASCADE's t is the arc length from P1.
            let (a, b) = (f(&curve["first_parameter"]), f(&curve["last_parameter"]));
            vec![Map::affine(1.0 / (b - a), -a / (b - a))]
        }
        "Part.ArcOfCircle" | "Part.Circle" => angle_maps(ends, std::f64::consts::TAU),
        _ => vec![Map::affine(1.0, 0.0)],
    }
}

/// Every FreeCAD face of the given types matches a nurbsx surface of `entity` type; planes
/// are checked for lying in nurbsx's plane (their frames are chosen independently).
fn check_faces(name: &str, entity: &str, types: &[&str]) -> usize {
    let (doc, json, defect) = load(name);
    let size = size_of(&json);
    let mine: Vec<&NurbsSurface> = doc
        .entities
        .iter()
        .filter(|e| e.source.entity == entity)
        .filter_map(|e| match &e.geometry {
            Geometry::Surface(s) => Some(s),
            Geometry::Curve(_) => None,
        })
        .collect();
    let mut checked = 0;
    for face in json["faces"].as_array().unwrap() {
        let surf = &face["surface"];
        let ty = surf["type"].as_str().unwrap_or("");
        if !types.contains(&ty) {
            continue;
        }
        let samples = face["samples"].as_array().unwrap();
        let mut best = (f64::INFINITY, f64::INFINITY);
        for s in &mine {
            let eu = segment_ends(s.knots_u());
            let ev = segment_ends(s.knots_v());
            let tau = std::f64::consts::TAU;
            let (mus, mvs): (Vec<Map>, Vec<Map>) = match ty {
                "Part.Cylinder" => (angle_maps(&eu, tau), vec![Map::affine(1.0, 0.0)]),
                "Part.Cone" => {
                    // Open CASCADE's v runs along the generatrix; ISO 10303-42's (nurbsx's)
                    // along the axis: v' = v cos(semi-angle).
                    let c = f(&surf["semi_angle"]).cos();
                    (angle_maps(&eu, tau), vec![Map::affine(c, 0.0)])
                }
                "Part.Sphere" => (angle_maps(&eu, tau), angle_maps(&ev, 0.0)),
                "Part.Toroid" => (angle_maps(&eu, tau), angle_maps(&ev, tau)),
                "Part.SurfaceOfRevolution" => (
                    angle_maps(&eu, tau),
                    profile_maps(&surf["basis_curve"], &ev),
                ),
                "Part.SurfaceOfExtrusion" => {
                    // nurbsx's v in [0, 1] along L - C(start); FreeCAD's v is a length.
                    let r = face["range"].as_array().unwrap();
                    let len = f(&r[3]) - f(&r[2]);
                    (
                        vec![Map::affine(1.0, 0.0)],
                        vec![Map::affine(1.0 / len, 0.0)],
                    )
                }
                "Part.Plane" => {
                    // Distance of every sample from nurbsx's plane, and FreeCAD's tangents
                    // in it.
                    let ((u0, _), (v0, _)) = s.domain();
                    let d = s.derivatives(u0, v0, 1).unwrap();
                    let n = {
                        let (a, b) = (d[1][0], d[0][1]);
                        let c = [
                            a[1] * b[2] - a[2] * b[1],
                            a[2] * b[0] - a[0] * b[2],
                            a[0] * b[1] - a[1] * b[0],
                        ];
                        lin(c, 1.0 / norm(c), [0.0; 3], 0.0)
                    };
                    let dot = |a: Point3, b: Point3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                    let mut e = (0.0f64, 0.0f64);
                    for x in samples {
                        e.0 = e.0.max(dot(sub(p3(&x["point"]), d[0][0]), n).abs());
                        for key in ["su", "sv"] {
                            e.1 = e.1.max(dot(p3(&x[key]), n).abs() / norm(p3(&x[key])));
                        }
                    }
                    if e.0 < best.0 {
                        best = e;
                    }
                    continue;
                }
                _ => continue,
            };
            for mu in &mus {
                for mv in &mvs {
                    let e = surface_errors(s, samples, mu, mv, size);
                    if e.0 < best.0 || (e.0 == best.0 && e.1 < best.1) {
                        best = e;
                    }
                }
            }
        }
        agrees(
            &format!("{name}: {ty} face {}", face["index"]),
            best,
            size,
            defect,
        );
        checked += 1;
    }
    checked
}

#[test]
fn quadrics_revolutions_extrusions_and_planes_match_freecad() {
    let cases: [(&str, &str, &[&str], usize); 12] = [
        ("cylinder_full_brep.igs", "192", &["Part.Cylinder"], 1),
        ("cylinder_full_brep.igs", "190", &["Part.Plane"], 2),
        ("cone_brep.igs", "194", &["Part.Cone"], 1),
        ("cone_frustum_brep.igs", "194", &["Part.Cone"], 1),
        ("sphere_brep.igs", "196", &["Part.Sphere"], 1),
        ("torus_brep.igs", "198", &["Part.Toroid"], 1),
        (
            "revolution_bspline.igs",
            "120",
            &["Part.SurfaceOfRevolution"],
            1,
        ),
        ("cylinder_full.igs", "120", &["Part.SurfaceOfRevolution"], 1),
        ("cylinder_full.igs", "108", &["Part.Plane"], 2),
        ("sphere.igs", "120", &["Part.SurfaceOfRevolution"], 1),
        ("torus.igs", "120", &["Part.SurfaceOfRevolution"], 1),
        (
            "extrusion_ellipse.igs",
            "122",
            &["Part.SurfaceOfExtrusion"],
            1,
        ),
    ];
    for (name, entity, types, n) in cases {
        assert_eq!(check_faces(name, entity, types), n, "{name}");
    }
}

/// The part of the issue: a box with fillets and a hole (planes, cylinders, spheres) in both
/// IGES modes converts without errors, with one surface per FreeCAD face.
#[test]
fn filleted_box_with_hole_converts() {
    for (name, faces) in [
        ("filleted_box_with_hole.igs", 27),
        ("filleted_box_with_hole_brep.igs", 27),
    ] {
        let (doc, json, _) = load(name);
        assert_eq!(json["faces"].as_array().unwrap().len(), faces);
        let surfaces = doc
            .entities
            .iter()
            .filter(|e| matches!(e.geometry, Geometry::Surface(_)))
            .count();
        assert_eq!(surfaces, faces, "{name}");
        // No warning but the one for coedges whose pcurve projection did not converge
        // (pcurve.not_computed, a warning since it keeps the face from being measured; an
        // info before it was one code for STEP and IGES): at most one coedge here; and, in
        // the B-rep file, the one that says its 402 associativity (Open CASCADE's group of
        // the solid's entities) is not carried, which is true (its 116 points and 123
        // directions are carried in the surfaces that use them, so they are not named).
        assert!(
            !doc.diagnostics
                .iter()
                .any(|d| d.severity == Severity::Warning
                    && !(d.code == "pcurve.not_computed" && d.message.starts_with("1 of "))
                    && !(d.code == "entities_skipped" && d.message.ends_with(": 1 x 402"))),
            "{name}: {:#?}",
            doc.diagnostics
        );
    }
}

// ---------------------------------------------------------------------------------------
// Hand-made entities: expected geometry from the entity's own definition.

const GLOBAL: &str = ",,4Htest,8Hfile.igs,6Hnurbsx,3H0.1,32,38,6,308,15,,1.,2,2HMM,1,0.01,15H20260101.120000,1.E-7,100.,,,11,0,15H20260101.120000,;";

fn de(ty: i64, form: i64) -> De<'static> {
    De {
        ty,
        form,
        ..De::default()
    }
}

fn read(text: &str, options: &ImportOptions) -> Document {
    exchange::iges::read(text, options).unwrap()
}

fn entity<'d>(doc: &'d Document, id: &str) -> &'d exchange::Entity {
    doc.entities
        .iter()
        .find(|e| e.id == id)
        .unwrap_or_else(|| panic!("no {id}: {:#?}", doc.diagnostics))
}

fn curve_of<'d>(doc: &'d Document, id: &str) -> &'d NurbsCurve {
    match &entity(doc, id).geometry {
        Geometry::Curve(c) => c,
        Geometry::Surface(_) => panic!("{id} is a surface"),
    }
}

fn surface_of<'d>(doc: &'d Document, id: &str) -> &'d NurbsSurface {
    match &entity(doc, id).geometry {
        Geometry::Surface(s) => s,
        Geometry::Curve(_) => panic!("{id} is a curve"),
    }
}

fn diag<'d>(doc: &'d Document, code: &str, id: &str) -> &'d exchange::Diagnostic {
    doc.diagnostics
        .iter()
        .find(|d| d.code == code && d.location.entity.as_deref() == Some(id))
        .unwrap_or_else(|| panic!("no {code} on {id}: {:#?}", doc.diagnostics))
}

/// `sum c[k] s^k` and its first two derivatives.
fn poly(c: &[f64], s: f64) -> (f64, f64, f64) {
    let mut v = (0.0, 0.0, 0.0);
    for (k, &a) in c.iter().enumerate() {
        let k = k as i32;
        v.0 += a * s.powi(k);
        if k >= 1 {
            v.1 += f64::from(k) * a * s.powi(k - 1);
        }
        if k >= 2 {
            v.2 += f64::from(k * (k - 1)) * a * s.powi(k - 2);
        }
    }
    v
}

/// 112: the NURBS equals the power series evaluated directly, with its first and second
/// derivatives, at the IGES parameter itself (identity map), on both segments.
#[test]
fn parametric_spline_curve_112_is_its_power_series() {
    let t = [0.0, 1.5, 4.0];
    let seg: [[[f64; 4]; 3]; 2] = [
        [
            [1.0, 2.0, -0.5, 0.25],
            [0.0, 1.0, 0.5, -0.125],
            [3.0, 0.0, 0.0, 0.0],
        ],
        [
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [3.0, 0.5, 0.0, 0.0],
        ],
    ];
    // The second segment starts where the first ends (C0 at least): fill its constants and
    // first derivatives from the first segment at s = 1.5, then add its own curvature.
    let mut seg = seg;
    let first = seg[0];
    for (axis, row) in seg[1].iter_mut().take(2).enumerate() {
        let (v, d, _) = poly(&first[axis], 1.5);
        *row = [v, d, 0.3 * (axis as f64 + 1.0), -0.05];
    }
    let end: Vec<f64> = (0..3).map(|a| poly(&seg[1][a], 2.5).0).collect();
    let coeffs: Vec<String> = seg
        .iter()
        .flatten()
        .flatten()
        .map(|x| format!("{x:e}"))
        .collect();
    let params = format!(
        "112,3,1,3,2,{},{},{},{},{:e},0.,0.,0.,{:e},0.,0.,0.,{:e},0.,0.,0.;",
        t[0],
        t[1],
        t[2],
        coeffs.join(","),
        end[0],
        end[1],
        end[2]
    )
    .replace("112,3,1,3,2,0,1.5,4,", "112,3,1,3,2,0.,1.5,4.,");
    let mut b = Builder::new(GLOBAL);
    b.entity(de(112, 0), &params);
    let doc = read(&b.build(), &ImportOptions::default());
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let c = curve_of(&doc, "D1");
    assert_eq!(c.domain(), (0.0, 4.0));
    for k in 0..=40 {
        let u = 4.0 * f64::from(k) / 40.0;
        let i = usize::from(u >= 1.5);
        let s = u - t[i];
        let d = c.derivatives(u, 2).unwrap();
        for axis in 0..3 {
            let (v, d1, d2) = poly(&seg[i][axis], s);
            assert!(
                (d[0][axis] - v).abs() <= 1e-13 * 10.0,
                "u={u} axis {axis}: {} vs {v}",
                d[0][axis]
            );
            assert!(
                (d[1][axis] - d1).abs() <= 1e-12 * 10.0,
                "u={u}: d1 {} vs {d1}",
                d[1][axis]
            );
            if k % 10 != 6 {
                // (u = 1.5 is the break point: the second derivative may jump there)
                assert!(
                    (d[2][axis] - d2).abs() <= 1e-11 * 10.0,
                    "u={u}: d2 {} vs {d2}",
                    d[2][axis]
                );
            }
        }
    }
    assert!(!doc.diagnostics.iter().any(|d| d.code == "spline_terminate"));
}

/// 114: the NURBS equals the bicubic power series of each patch, evaluated directly.
#[test]
fn parametric_spline_surface_114_is_its_power_series() {
    // M = 2 patches in u (break points 0, 1, 3), N = 1 in v (0, 2). Patch 1 is a general
    // bicubic; patch 2 has its own coefficients (a jump at u = 1 is allowed, and the
    // shared boundary is taken from patch 1, so patch 2 is made to continue it in value).
    let tu = [0.0, 1.0, 3.0];
    let tv = [0.0, 2.0];
    let mut p1 = [[0.0f64; 16]; 3];
    for (axis, c) in p1.iter_mut().enumerate() {
        for (k, x) in c.iter_mut().enumerate() {
            *x = ((k * 7 + axis * 3) % 11) as f64 / 10.0 - 0.4;
        }
    }
    // Patch 2 at s = 0 must equal patch 1 at s = 1 for every t: its t-polynomial
    // coefficients (a = 0) are patch 1's summed over a; the rest is its own.
    let mut p2 = [[0.0f64; 16]; 3];
    for axis in 0..3 {
        for bt in 0..4 {
            p2[axis][4 * bt] = (0..4).map(|a| p1[axis][4 * bt + a]).sum();
            for a in 1..4 {
                p2[axis][4 * bt + a] = 0.1 * (a + bt + axis) as f64;
            }
        }
    }
    let eval = |c: &[f64; 16], s: f64, t: f64| -> f64 {
        (0..16)
            .map(|k| c[k] * s.powi((k % 4) as i32) * t.powi((k / 4) as i32))
            .sum()
    };
    let mut values = vec![format!("114,3,1,2,1,0.,1.,3.,0.,2.")];
    for p in [p1, p2] {
        for axis in p {
            values.extend(axis.iter().map(|x| format!("{x:e}")));
        }
        values.extend(std::iter::repeat_n("0.".to_owned(), 48)); // the arbitrary patch (i, N+1)
    }
    values.extend(std::iter::repeat_n("0.".to_owned(), 96)); // the arbitrary row M + 1
    let params = values.join(",") + ";";
    let mut b = Builder::new(GLOBAL);
    b.entity(de(114, 0), &params);
    let doc = read(&b.build(), &ImportOptions::default());
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let s = surface_of(&doc, "D1");
    assert_eq!(s.domain(), ((0.0, 3.0), (0.0, 2.0)));
    for i in 0..=12 {
        for j in 0..=6 {
            let (u, v) = (3.0 * f64::from(i) / 12.0, 2.0 * f64::from(j) / 6.0);
            let (patch, su) = if u < 1.0 {
                (&p1, u - tu[0])
            } else {
                (&p2, u - tu[1])
            };
            let p = s.point_at(u, v).unwrap();
            for axis in 0..3 {
                let want = eval(&patch[axis], su, v - tv[0]);
                assert!(
                    (p[axis] - want).abs() <= 1e-12 * 10.0,
                    "({u}, {v}) axis {axis}: {} vs {want}",
                    p[axis]
                );
            }
        }
    }
}

/// 104 in general position (rotated, translated): every point of the NURBS satisfies the
/// file's implicit equation, the ends are the file's points, and a form number that
/// contradicts the coefficients is reported.
#[test]
fn conic_104_in_general_position_satisfies_its_equation() {
    // Ellipse (x'/3)^2 + (y'/2)^2 = 1 rotated by 0.4 rad about (1, -2).
    let (a2, b2, th, cx, cy) = (9.0f64, 4.0f64, 0.4f64, 1.0f64, -2.0f64);
    let (c, s) = (th.cos(), th.sin());
    // x' = c (x - cx) + s (y - cy), y' = -s (x - cx) + c (y - cy).
    let qa = c * c / a2 + s * s / b2;
    let qb = 2.0 * c * s * (1.0 / a2 - 1.0 / b2);
    let qc = s * s / a2 + c * c / b2;
    let qd = -2.0 * qa * cx - qb * cy;
    let qe = -2.0 * qc * cy - qb * cx;
    let qf = qa * cx * cx + qb * cx * cy + qc * cy * cy - 1.0;
    let at = |t: f64| {
        let (xp, yp) = (3.0 * t.cos(), 2.0 * t.sin());
        (cx + c * xp - s * yp, cy + s * xp + c * yp)
    };
    let (p0, p1) = (at(0.3), at(2.5));
    let coeff = [qa, qb, qc, qd, qe, qf];
    let body = |form_pts: (f64, f64, f64, f64)| {
        let v: Vec<String> = coeff.iter().map(|x| format!("{x:e}")).collect();
        format!(
            "104,{},0.5,{:e},{:e},{:e},{:e};",
            v.join(","),
            form_pts.0,
            form_pts.1,
            form_pts.2,
            form_pts.3
        )
    };
    let mut b = Builder::new(GLOBAL);
    b.entity(de(104, 1), &body((p0.0, p0.1, p1.0, p1.1)));
    b.entity(de(104, 2), &body((p0.0, p0.1, p1.0, p1.1))); // wrong form: 2 = hyperbola
    b.entity(de(104, 0), &body((p0.0, p0.1, p1.0, p1.1))); // form 0: no type named
    let doc = read(&b.build(), &ImportOptions::default());
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    // Form 0 declares no type, so it disagrees with nothing; the coefficients give it.
    assert!(
        !doc.diagnostics
            .iter()
            .any(|d| d.code == "form_mismatch" && d.location.entity.as_deref() == Some("D5")),
        "{:#?}",
        doc.diagnostics
    );
    assert_eq!(
        entity(&doc, "D5").meta.shape,
        Some(exchange::Shape::EllipticArc)
    );
    for id in ["D1", "D3", "D5"] {
        let curve = curve_of(&doc, id);
        let (d0, d1) = curve.domain();
        for k in 0..=50 {
            let u = d0 + (d1 - d0) * f64::from(k) / 50.0;
            let p = curve.point_at(u).unwrap();
            let (x, y) = (p[0], p[1]);
            let implicit = qa * x * x + qb * x * y + qc * y * y + qd * x + qe * y + qf;
            assert!(implicit.abs() <= 1e-13, "{id} u={u}: {implicit:e}");
            assert_eq!(p[2], 0.5);
        }
        let (s0, s1) = (curve.point_at(d0).unwrap(), curve.point_at(d1).unwrap());
        assert!(
            (s0[0] - p0.0).abs() < 1e-13 && (s0[1] - p0.1).abs() < 1e-13,
            "{s0:?}"
        );
        assert!(
            (s1[0] - p1.0).abs() < 1e-13 && (s1[1] - p1.1).abs() < 1e-13,
            "{s1:?}"
        );
        // Counterclockwise from the start: the NURBS passes the conic's point at t = 1.4.
        let mid = at(1.4);
        let hit = (0..=2000).any(|k| {
            let p = curve
                .point_at(d0 + (d1 - d0) * f64::from(k) / 2000.0)
                .unwrap();
            (p[0] - mid.0).hypot(p[1] - mid.1) < 1e-2
        });
        assert!(
            hit,
            "{id}: the arc does not run counterclockwise from the start"
        );
    }
    assert!(
        diag(&doc, "form_mismatch", "D3")
            .message
            .contains("ellipse")
    );
    assert_eq!(
        entity(&doc, "D1").meta.shape,
        Some(exchange::Shape::EllipticArc)
    );
}

/// 118 form 1 with two lines is the bilinear patch `(1 - v) L1(u) + v L2(u)` (L2 reversed
/// when DIRFLG = 1); form 0 over B-spline rails and a line paired with an arc are refused
/// with a located error.
#[test]
fn ruled_surface_118() {
    let mut b = Builder::new(GLOBAL);
    let l1 = b.entity(de(110, 0), "110,0.,0.,0.,4.,0.,0.;"); // D1
    let l2 = b.entity(de(110, 0), "110,0.,3.,1.,6.,3.,1.;"); // D3
    let r1 = b.entity(de(118, 1), &format!("118,{l1},{l2},0,0;")); // D5
    let r2 = b.entity(de(118, 1), &format!("118,{l1},{l2},1,0;")); // D7
    let arc = b.entity(de(100, 0), "100,0.,0.,0.,1.,0.,0.,1.;"); // D9
    let r3 = b.entity(de(118, 1), &format!("118,{l1},{arc},0,0;")); // D11
    let bs = b.entity(
        de(126, 0),
        "126,1,1,0,0,1,0,0.,0.,1.,1.,1.,1.,0.,0.,0.,1.,1.,0.,0.,1.;",
    ); // D13
    let r4 = b.entity(de(118, 0), &format!("118,{bs},{l2},0,0;")); // D15
    let r5 = b.entity(de(118, 0), &format!("118,{l1},{l2},0,0;")); // D17: lines, form 0
    let doc = read(&b.build(), &ImportOptions::default());
    let line = |a: Point3, b: Point3, t: f64| lin(a, 1.0 - t, b, t);
    let (a1, b1, a2, b2) = (
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [0.0, 3.0, 1.0],
        [6.0, 3.0, 1.0],
    );
    for (id, reversed) in [(r1, false), (r2, true), (r5, false)] {
        let s = surface_of(&doc, &format!("D{id}"));
        for i in 0..=4 {
            for j in 0..=4 {
                let (u, v) = (f64::from(i) / 4.0, f64::from(j) / 4.0);
                let q1 = line(a1, b1, u);
                let q2 = if reversed {
                    line(a2, b2, 1.0 - u)
                } else {
                    line(a2, b2, u)
                };
                let want = lin(q1, 1.0 - v, q2, v);
                assert!(
                    norm(sub(s.point_at(u, v).unwrap(), want)) < 1e-14,
                    "D{id} ({u}, {v})"
                );
            }
        }
    }
    assert_eq!(
        diag(&doc, "ruled.parameterisation", &format!("D{r3}")).severity,
        Severity::Error
    );
    assert_eq!(
        diag(&doc, "ruled.arc_length", &format!("D{r4}")).severity,
        Severity::Error
    );
}

/// Unbounded and inexact entities are never silent: one located diagnostic each.
#[test]
fn unbounded_and_inexact_entities_are_reported() {
    let mut b = Builder::new(GLOBAL);
    let p = b.entity(de(116, 0), "116,0.,0.,0.;"); // D1
    let z = b.entity(de(123, 0), "123,0.,0.,1.;"); // D3
    let cyl = b.entity(de(192, 0), &format!("192,{p},{z},2.;")); // D5: no use
    let ray = b.entity(de(110, 1), "110,0.,0.,0.,1.,0.,0.;"); // D7
    let flash = b.entity(de(125, 0), "125,0.,0.,1.,1.,0.,0,0;"); // D9
    let offset = b.entity(de(130, 0), "130,7,1,0,0,0,1.,0.,0.,0.,0.,0.,0.,1.,0.,1.;"); // D11
    let points = b.entity(de(106, 1), "106,1,2,0.,1.,2.,3.,4.;"); // D13
    let doc = read(&b.build(), &ImportOptions::default());
    assert!(doc.entities.is_empty(), "{:#?}", doc.entities);
    for (code, id) in [
        ("unbounded.not_represented", cyl),
        ("unbounded.not_represented", ray),
        ("no_exact_form", flash),
        ("no_exact_form", offset),
        ("points.not_represented", points),
    ] {
        assert_eq!(
            diag(&doc, code, &format!("D{id}")).severity,
            Severity::Warning
        );
    }
}

/// A cylinder used by a 144 whose boundaries are two full circles: bounded to the full turn
/// and exactly the axial range of the circles; the NURBS is the cylinder
/// `O + r (cos t x + sin t y) + h z` (points on radius 2 about the z axis).
#[test]
fn cylinder_192_is_bounded_by_its_use() {
    let mut b = Builder::new(GLOBAL);
    let p = b.entity(de(116, 0), "116,0.,0.,0.;"); // D1
    let z = b.entity(de(123, 0), "123,0.,0.,1.;"); // D3
    let x = b.entity(de(123, 0), "123,1.,0.,0.;"); // D5
    let cyl = b.entity(de(192, 1), &format!("192,{p},{z},2.,{x};")); // D7
    let c0 = b.entity(de(100, 0), "100,-1.,0.,0.,2.,0.,2.,0.;"); // D9: z = -1
    let c1 = b.entity(de(100, 0), "100,4.,0.,0.,2.,0.,2.,0.;"); // D11: z = 4
    let k0 = b.entity(de(142, 0), &format!("142,0,{cyl},0,{c0},2;")); // D13
    let k1 = b.entity(de(142, 0), &format!("142,0,{cyl},0,{c1},2;")); // D15
    b.entity(de(144, 0), &format!("144,{cyl},1,1,{k0},{k1};"));
    let doc = read(&b.build(), &ImportOptions::default());
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let s = surface_of(&doc, &format!("D{cyl}"));
    let ((u0, u1), (v0, v1)) = s.domain();
    assert_eq!((u0, u1), (0.0, std::f64::consts::TAU));
    assert_eq!((v0, v1), (-1.0, 4.0));
    for i in 0..=16 {
        for j in 0..=4 {
            let (u, v) = (
                u0 + (u1 - u0) * f64::from(i) / 16.0,
                v0 + (v1 - v0) * f64::from(j) / 4.0,
            );
            let q = s.point_at(u, v).unwrap();
            assert!(
                (q[0].hypot(q[1]) - 2.0).abs() < 1e-14 && (q[2] - v).abs() < 1e-14,
                "{q:?}"
            );
        }
    }
    // At the knots (multiples of a quarter turn) the NURBS parameter is the angle.
    let q = s.point_at(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
    assert!(norm(sub(q, [0.0, 2.0, 0.0])) < 1e-15, "{q:?}");
    assert_eq!(
        entity(&doc, &format!("D{cyl}")).meta.shape,
        Some(exchange::Shape::Cylinder)
    );
}

/// A 102 of a line and an arc that join is one curve; its constituents are not emitted on
/// their own. One that does not join, or that bounds a face, gives its pieces, each once.
#[test]
fn composite_102_joins_or_gives_its_pieces_once() {
    let mut b = Builder::new(GLOBAL);
    let l = b.entity(de(110, 0), "110,0.,0.,0.,2.,0.,0.;"); // D1
    let a = b.entity(de(100, 0), "100,0.,2.,1.,2.,0.,3.,1.;"); // D3: quarter arc from (2, 0)
    let joined = b.entity(de(102, 0), &format!("102,2,{l},{a};")); // D5
    let l2 = b.entity(de(110, 0), "110,10.,0.,0.,12.,0.,0.;"); // D7
    let l3 = b.entity(de(110, 0), "110,20.,0.,0.,22.,0.,0.;"); // D9
    let apart = b.entity(de(102, 0), &format!("102,2,{l2},{l3};")); // D11
    // A 102 that bounds a face (the C(t) of a 142) keeps its constituents: they are the
    // boundary's edges.
    let e1 = b.entity(de(110, 0), "110,0.,5.,0.,2.,5.,0.;"); // D13
    let e2 = b.entity(de(110, 0), "110,2.,5.,0.,2.,7.,0.;"); // D15
    let chain = b.entity(de(102, 0), &format!("102,2,{e1},{e2};")); // D17
    b.entity(de(142, 0), &format!("142,0,0,0,{chain},2;")); // D19
    let doc = read(&b.build(), &ImportOptions::default());
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let ids: Vec<&str> = doc.entities.iter().map(|e| e.id.as_str()).collect();
    assert_eq!(
        ids,
        vec![
            format!("D{joined}"),
            format!("D{l2}"),
            format!("D{l3}"),
            format!("D{e1}"),
            format!("D{e2}")
        ]
    );
    assert!(doc.diagnostics.iter().any(|d| d.code == "composite_edges"));
    let c = curve_of(&doc, &format!("D{joined}"));
    let (d0, d1) = c.domain();
    assert_eq!(c.point_at(d0).unwrap(), [0.0, 0.0, 0.0]);
    let end = c.point_at(d1).unwrap();
    assert!(norm(sub(end, [3.0, 1.0, 0.0])) < 1e-15, "{end:?}");
    // The line's piece keeps its parameter [0, 1]; the arc continues after it.
    assert_eq!(c.point_at(0.5).unwrap(), [1.0, 0.0, 0.0]);
    assert!(
        entity(&doc, &format!("D{l2}"))
            .meta
            .used_by
            .contains(&compact_str::format_compact!("D{apart}"))
    );
    assert!(doc.diagnostics.iter().any(|d| d.code == "composite_pieces"));
}

/// Cox-de Boor evaluation of a rational B-spline from the file's data (independent of the
/// library): `sum N_i,p(u) w_i P_i / sum N_i,p(u) w_i`.
fn de_boor(p: usize, knots: &[f64], poles: &[Point3], weights: &[f64], u: f64) -> Point3 {
    let n = poles.len();
    let basis = |i: usize, u: f64| -> f64 {
        // N_{i,0} with the last span closed at the domain end.
        let mut nk: Vec<f64> = (0..=p)
            .map(|j| {
                let (a, b) = (knots[i + j], knots[i + j + 1]);
                let last = u == knots[n] && b == knots[n] && a < b;
                f64::from(u8::from((a <= u && u < b) || last))
            })
            .collect();
        for k in 1..=p {
            for j in 0..=p - k {
                let (a, b) = (knots[i + j], knots[i + j + k]);
                let (c, d) = (knots[i + j + 1], knots[i + j + k + 1]);
                let left = if b > a {
                    (u - a) / (b - a) * nk[j]
                } else {
                    0.0
                };
                let right = if d > c {
                    (d - u) / (d - c) * nk[j + 1]
                } else {
                    0.0
                };
                nk[j] = left + right;
            }
        }
        nk[0]
    };
    let mut num = [0.0; 3];
    let mut den = 0.0;
    for i in 0..n {
        let b = basis(i, u) * weights[i];
        den += b;
        for k in 0..3 {
            num[k] += b * poles[i][k];
        }
    }
    num.map(|x| x / den)
}

/// `--trim-to-range`: a 126 with V(0), V(1) inside its domain comes out on exactly
/// `[V(0), V(1)]` and equals the untrimmed B-spline (evaluated independently) there; a 128
/// likewise on `U(0)..U(1) x V(0)..V(1)`.
#[test]
fn trim_to_range_is_exact() {
    // Cubic rational curve, 6 poles, knots 0 0 0 0 1 2 3 3 3 3; V = [0.4, 2.7].
    let knots = [0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0];
    let poles: [Point3; 6] = [
        [0.0, 0.0, 0.0],
        [1.0, 2.0, 0.5],
        [3.0, 2.5, -1.0],
        [4.0, -1.0, 0.0],
        [6.0, 0.5, 2.0],
        [7.0, 3.0, 1.0],
    ];
    let weights = [1.0, 0.8, 1.5, 1.0, 0.6, 1.0];
    let mut params = vec!["126,5,3,0,0,0,0".to_owned()];
    params.extend(knots.iter().map(|k| format!("{k:?}")));
    params.extend(weights.iter().map(|w| format!("{w:?}")));
    params.extend(poles.iter().flatten().map(|x| format!("{x:?}")));
    params.extend(["0.4", "2.7", "0.", "0.", "0."].map(str::to_owned));
    let curve_params = params.join(",") + ";";
    let surface_params = "128,2,1,2,1,0,0,1,0,0,0.,0.,0.,1.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,1.,2.,0.,0.,0.,1.,0.,1.,1.,1.,2.,1.,0.,0.25,0.75,0.2,0.9;";
    let mut b = Builder::new(GLOBAL);
    b.entity(de(126, 0), &curve_params);
    b.entity(de(128, 0), surface_params);
    let text = b.build();
    let trim = ImportOptions {
        trim_to_parameter_range: true,
        ..ImportOptions::default()
    };
    let doc = read(&text, &trim);
    let whole = read(&text, &ImportOptions::default());
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let c = curve_of(&doc, "D1");
    assert_eq!(c.domain(), (0.4, 2.7));
    assert_eq!(curve_of(&whole, "D1").domain(), (0.0, 3.0));
    for k in 0..=46 {
        let u = 0.4 + 2.3 * f64::from(k) / 46.0;
        let want = de_boor(3, &knots, &poles, &weights, u);
        assert!(norm(sub(c.point_at(u).unwrap(), want)) < 1e-13, "u={u}");
    }
    let s = surface_of(&doc, "D3");
    assert_eq!(s.domain(), ((0.25, 0.75), (0.2, 0.9)));
    let sw = surface_of(&whole, "D3");
    for i in 0..=5 {
        for j in 0..=7 {
            let (u, v) = (
                (0.25 + 0.1 * f64::from(i)).min(0.75),
                (0.2 + 0.1 * f64::from(j)).min(0.9),
            );
            let d = norm(sub(s.point_at(u, v).unwrap(), sw.point_at(u, v).unwrap()));
            assert!(d < 1e-14, "({u}, {v}): {d:e}");
        }
    }
    assert!(
        doc.diagnostics
            .iter()
            .filter(|d| d.code == "trimmed_to_range")
            .count()
            == 2
    );
}

/// The forms written for each kind (IGES 5.3 sections 4.23, 4.24), read back from the
/// written Directory Entries; a kind whose geometry fails its check is written as form 0
/// with a warning.
#[test]
fn writer_labels_each_kind_with_its_checked_form() {
    let cases: [(&str, &str, i64); 14] = [
        ("line_segment.igs", "110", 1),
        ("circle_full.igs", "100", 2),
        ("circle_arc_tilted.igs", "100", 2),
        ("ellipse_arc.igs", "104", 3),
        ("parabola_arc.igs", "104", 4),
        ("hyperbola_arc.igs", "104", 5),
        ("cylinder_full_brep.igs", "190", 1),
        ("cylinder_full_brep.igs", "192", 2),
        ("cone_brep.igs", "194", 3),
        ("sphere_brep.igs", "196", 4),
        ("torus_brep.igs", "198", 5),
        ("revolution_bspline.igs", "120", 6),
        ("extrusion_ellipse.igs", "122", 7),
        ("cylinder_full.igs", "108", 1),
    ];
    for (name, entity, form) in cases {
        let (doc, _, _) = load(name);
        let mut one = doc.clone();
        one.entities.retain(|e| e.source.entity == entity);
        // The entities of one kind alone, as free geometry (a document with topology
        // writes its faces first).
        one.topology = exchange::Topology::default();
        assert!(!one.entities.is_empty(), "{name}");
        assert!(exchange::iges::form_warnings(&one).is_empty(), "{name}");
        let text = exchange::iges::write(&one, &exchange::ExportOptions::default()).unwrap();
        let file = nurbsx_parsers::iges::parse(&text).unwrap();
        for e in file.entries.iter().flatten() {
            assert_eq!(e.form, form, "{name}: {entity}");
        }
    }
    // A ruled surface of two lines (form 8), and a plane labelled as a cylinder (form 0 and
    // a warning).
    let mut b = Builder::new(GLOBAL);
    b.entity(de(110, 0), "110,0.,0.,0.,4.,0.,0.;");
    b.entity(de(110, 0), "110,0.,3.,1.,6.,3.,1.;");
    b.entity(de(118, 1), "118,1,3,0,0;");
    let mut doc = read(&b.build(), &ImportOptions::default());
    doc.entities.retain(|e| e.source.entity == "118");
    doc.entities.push(doc.entities[0].clone());
    doc.entities[1].id = "fake".into();
    doc.entities[1].meta.shape = Some(exchange::Shape::Cylinder);
    let warnings = exchange::iges::form_warnings(&doc);
    assert_eq!(warnings.len(), 1);
    assert_eq!(warnings[0].location.entity.as_deref(), Some("fake"));
    let text = exchange::iges::write(&doc, &exchange::ExportOptions::default()).unwrap();
    let file = nurbsx_parsers::iges::parse(&text).unwrap();
    let forms: Vec<i64> = file.entries.iter().flatten().map(|e| e.form).collect();
    assert_eq!(forms, vec![8, 0]);
}

/// A 120's axis and generatrix that are physically dependent (status 01) and used by
/// nothing else are part of the surface: not emitted as curves, one info each; an
/// independent generatrix is still a curve of its own.
#[test]
fn construction_curves_of_a_revolution_are_part_of_it() {
    let dependent = |ty| De {
        ty,
        status: "00010000",
        ..De::default()
    };
    let mut b = Builder::new(GLOBAL);
    let axis = b.entity(dependent(110), "110,0.,0.,0.,0.,0.,1.;"); // D1
    let profile = b.entity(dependent(110), "110,2.,0.,0.,2.,0.,3.;"); // D3
    let rev = b.entity(de(120, 0), &format!("120,{axis},{profile},0.,3.;")); // D5
    let free = b.entity(de(110, 0), "110,5.,0.,0.,5.,0.,3.;"); // D7
    b.entity(de(120, 0), &format!("120,{axis},{free},0.,1.;")); // D9
    let doc = read(&b.build(), &ImportOptions::default());
    assert!(!doc.has_errors(), "{:#?}", doc.diagnostics);
    let ids: Vec<&str> = doc.entities.iter().map(|e| e.id.as_str()).collect();
    assert_eq!(
        ids,
        vec![format!("D{rev}"), format!("D{free}"), "D9".to_owned()]
    );
    for id in [axis, profile] {
        assert_eq!(
            diag(&doc, "construction_curve", &format!("D{id}")).severity,
            Severity::Info
        );
    }
    // The revolution itself: radius 2 about z, heights 0..3, angle 0..3 rad.
    let s = surface_of(&doc, &format!("D{rev}"));
    let ((u0, u1), (v0, v1)) = s.domain();
    assert_eq!((u0, u1, v0, v1), (0.0, 3.0, 0.0, 1.0));
    let q = s.point_at(3.0, 0.5).unwrap();
    let want = [2.0 * 3.0f64.cos(), 2.0 * 3.0f64.sin(), 1.5];
    assert!(norm(sub(q, want)) < 1e-14, "{q:?}");
}
