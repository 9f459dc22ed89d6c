//! The analytic STEP samples made by FreeCAD (`samples/freecad/analytic/*.step`, README
//! there): nurbsx's exact NURBS of every edge curve and face surface equals FreeCAD's own
//! evaluation of the analytic entity, at FreeCAD's parameters mapped through the documented
//! parameter map (README, "Parameterisation"):
//! - lines, planes, axial directions, extrusion directions, B-splines: identity (OCCT writes
//!   every VECTOR with magnitude 1 mm in the file's unit, so the ISO parameter is FreeCAD's
//!   arc length);
//! - circles, ellipses, hyperbolas and angular surface directions: the ISO angle is
//!   FreeCAD's (plus a whole number of turns), and the NURBS parameter is its image under
//!   the exact `ArcMap` of `nurbs::conic` on the entity's domain (u = t at the domain ends);
//! - parabolas: FreeCAD `V + t^2/(4f) X + t Y`, ISO `V + f (s^2 X + 2 s Y)`: s = t / (2f);
//! - cones: FreeCAD's v runs along the generatrix, ISO 10303-42's along the axis: v' = v cos a.
//!
//! Points within 1e-12 of the model size; first and second derivatives (chain rule through
//! the map: `C_t = C_u u'`, `C_tt = C_uu u'^2 + C_u u''`, with `u'' = u' tan((t - m)/2)` on
//! an elliptic segment of middle m, `-u' tanh((t - m)/2)` on a hyperbolic one, from the
//! rational form's half-angle relation `tan((t - m)/2) = tan(a/2)(2s - 1)`) within 1e-9
//! relative to the largest derivative of that order on the item.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};

use nurbsx::exchange::{self, Document, ImportOptions, LengthUnit, Severity, Shape};
use nurbsx::nurbs::conic::{ArcMap, ConicKind, conic_arc};
use nurbsx::nurbs::{Geometry, NurbsCurve, NurbsSurface, Point3};
use serde_json::Value;

const POINT_TOL: f64 = 1e-12;
const DERIV_TOL: f64 = 1e-9;
const TAU: f64 = std::f64::consts::TAU;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/analytic")
}

fn v3(v: &Value) -> Point3 {
    let a = v.as_array().unwrap();
    [
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    ]
}

fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn norm(a: Point3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn mul(a: Point3, s: f64) -> Point3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// How one direction's FreeCAD parameter becomes the NURBS parameter.
#[derive(Debug, Clone, Copy)]
enum Map {
    /// `u = k t`.
    Linear(f64),
    /// The conic map on the entity's domain (after shifting `t` by whole turns).
    Arc(ConicKind),
}

/// `(u, du/dt, d2u/dt2)` for FreeCAD parameter `t` on domain `(a, b)`; `None` when `t`
/// is not in the domain (within 1e-9 of its length).
fn map(m: Map, t: f64, (a, b): (f64, f64)) -> Option<(f64, f64, f64)> {
    let slack = 1e-9 * (b - a).abs().max(1.0);
    match m {
        Map::Linear(k) => {
            let u = k * t;
            (u >= a - slack && u <= b + slack).then_some((u.clamp(a, b), k, 0.0))
        }
        Map::Arc(kind) => {
            let mut t = t;
            if kind == ConicKind::Elliptic {
                while t < a - slack {
                    t += TAU;
                }
                while t > b + slack {
                    t -= TAU;
                }
            }
            if t < a - slack || t > b + slack {
                return None;
            }
            let t = t.clamp(a, b);
            // (A domain no conic can have, e.g. a line's 10 > 2 pi, is no match.)
            let am: ArcMap = conic_arc(kind, [0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], a, b)
                .ok()?
                .1;
            let u = am.to_nurbs(t);
            let d1 = am.derivative(t);
            // The segment holding t: its middle parameter.
            let n = am.segments();
            let mut i = 0;
            while i + 1 < n && t >= am.knot(i + 1) {
                i += 1;
            }
            let mid = 0.5 * (am.knot(i) + am.knot(i + 1));
            let d2 = match kind {
                ConicKind::Elliptic => d1 * (0.5 * (t - mid)).tan(),
                ConicKind::Hyperbolic => -d1 * (0.5 * (t - mid)).tanh(),
            };
            Some((u, d1, d2))
        }
    }
}

/// The worst (point, d1, d2) deviations of a curve against FreeCAD's samples, or `None`
/// when a sample is outside its domain.
fn curve_error(c: &NurbsCurve, m: Map, samples: &[Value]) -> Option<(f64, f64, f64)> {
    let dom = c.domain();
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    let mut rows = Vec::new();
    for s in samples {
        let t = s["t"].as_f64().unwrap();
        let (u, du, ddu) = map(m, t, dom)?;
        let d = c.derivatives(u, 2).ok()?;
        let c1 = mul(d[1], du);
        let c2 = add(mul(d[2], du * du), mul(d[1], ddu));
        let (p, f1, f2) = (v3(&s["point"]), v3(&s["d1"]), v3(&s["d2"]));
        s1 = s1.max(norm(f1));
        s2 = s2.max(norm(f2));
        rows.push((norm(sub(d[0], p)), norm(sub(c1, f1)), norm(sub(c2, f2))));
    }
    for (p, a, b) in rows {
        worst.0 = worst.0.max(p);
        worst.1 = worst.1.max(a / s1.max(1e-300));
        worst.2 = worst.2.max(if s2 > 0.0 { b / s2 } else { b });
    }
    Some(worst)
}

fn curve_maps(curve: &Value) -> Vec<Map> {
    match curve["type"].as_str().unwrap() {
        "Part.Line" | "Part.BSplineCurve" | "Part.BezierCurve" => vec![Map::Linear(1.0)],
        "Part.Circle" | "Part.Ellipse" => vec![Map::Arc(ConicKind::Elliptic)],
        "Part.Hyperbola" => vec![Map::Arc(ConicKind::Hyperbolic)],
        "Part.Parabola" => vec![Map::Linear(1.0 / (2.0 * curve["focal"].as_f64().unwrap()))],
        other => panic!("no map for {other}"),
    }
}

/// (u map, v map) for a FreeCAD surface.
fn surface_maps(surface: &Value) -> (Map, Map) {
    let arc = Map::Arc(ConicKind::Elliptic);
    match surface["type"].as_str().unwrap() {
        "Part.Plane" | "Part.BSplineSurface" => (Map::Linear(1.0), Map::Linear(1.0)),
        "Part.Cylinder" => (arc, Map::Linear(1.0)),
        "Part.Cone" => (
            arc,
            Map::Linear(surface["semi_angle"].as_f64().unwrap().cos()),
        ),
        "Part.Sphere" | "Part.Toroid" => (arc, arc),
        "Part.SurfaceOfRevolution" => (arc, curve_maps(&surface["basis_curve"])[0]),
        "Part.SurfaceOfExtrusion" => (curve_maps(&surface["basis_curve"])[0], Map::Linear(1.0)),
        other => panic!("no map for {other}"),
    }
}

/// The worst (point, first partials, second partials) deviations of a surface.
fn surface_error(s: &NurbsSurface, (mu, mv): (Map, Map), samples: &[Value]) -> Option<[f64; 3]> {
    let (du_dom, dv_dom) = s.domain();
    let mut rows = Vec::new();
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    for x in samples {
        let (u, u1, u2) = map(mu, x["u"].as_f64().unwrap(), du_dom)?;
        let (v, v1, v2) = map(mv, x["v"].as_f64().unwrap(), dv_dom)?;
        let d = s.derivatives(u, v, 2).ok()?;
        let su = mul(d[1][0], u1);
        let sv = mul(d[0][1], v1);
        let suu = add(mul(d[2][0], u1 * u1), mul(d[1][0], u2));
        let svv = add(mul(d[0][2], v1 * v1), mul(d[0][1], v2));
        let suv = mul(d[1][1], u1 * v1);
        let f = |k: &str| v3(&x[k]);
        for k in ["su", "sv"] {
            s1 = s1.max(norm(f(k)));
        }
        for k in ["suu", "suv", "svv"] {
            s2 = s2.max(norm(f(k)));
        }
        rows.push((
            norm(sub(d[0][0], f("point"))),
            norm(sub(su, f("su"))).max(norm(sub(sv, f("sv")))),
            norm(sub(suu, f("suu")))
                .max(norm(sub(suv, f("suv"))))
                .max(norm(sub(svv, f("svv")))),
        ));
    }
    let mut w = [0.0f64; 3];
    for (p, a, b) in rows {
        w[0] = w[0].max(p);
        w[1] = w[1].max(a / s1.max(1e-300));
        w[2] = w[2].max(if s2 > 0.0 { b / s2 } else { b });
    }
    Some(w)
}

fn read(path: &Path) -> Document {
    let options = ImportOptions {
        target_units: Some(LengthUnit::Mm),
        ..ImportOptions::default()
    };
    exchange::read(&std::fs::read(path).unwrap(), &options).unwrap()
}

fn model_size(reading: &Value) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut take = |p: Point3| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    };
    for e in reading["edges"].as_array().unwrap() {
        for s in e["samples"].as_array().into_iter().flatten() {
            take(v3(&s["point"]));
        }
    }
    for f in reading["faces"].as_array().unwrap() {
        for s in f["samples"].as_array().unwrap() {
            take(v3(&s["point"]));
        }
    }
    norm(sub(hi, lo))
}

fn step_samples() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "step"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_analytic_step_sample_matches_freecad() {
    let files = step_samples();
    assert!(
        files.len() >= 20,
        "expected the analytic samples, found {}",
        files.len()
    );
    let mut failures = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let reading: Value = serde_json::from_slice(
            &std::fs::read(path.with_file_name(format!("{name}.json"))).unwrap(),
        )
        .unwrap();
        let doc = read(path);
        for d in &doc.diagnostics {
            if d.severity == Severity::Error {
                failures.push(format!("{name}: {d}"));
            }
        }
        let size = model_size(&reading);
        let curves: Vec<&NurbsCurve> = doc
            .entities
            .iter()
            .filter_map(|e| match &e.geometry {
                Geometry::Curve(c) if c.dimension() == 3 => Some(c),
                _ => None,
            })
            .collect();
        let surfaces: Vec<&NurbsSurface> = doc
            .entities
            .iter()
            .filter_map(|e| match &e.geometry {
                Geometry::Surface(s) => Some(s),
                _ => None,
            })
            .collect();
        // Every curve bounded by nurbsx (a trim or an edge's vertices) ends where one of
        // FreeCAD's edges ends: the bounds were applied exactly, not only the shape.
        let ends: Vec<Point3> = reading["edges"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|e| e["vertices"].as_array().unwrap().iter().map(v3))
            .collect();
        for e in &doc.entities {
            let Geometry::Curve(c) = &e.geometry else {
                continue;
            };
            if c.dimension() != 3 || e.source.entity.starts_with("B_SPLINE") {
                continue;
            }
            let (a, b) = c.domain();
            for p in [c.point_at(a).unwrap(), c.point_at(b).unwrap()] {
                let d = ends
                    .iter()
                    .map(|q| norm(sub(p, *q)))
                    .fold(f64::INFINITY, f64::min);
                if d > 1e-9 * size {
                    failures.push(format!(
                        "{name}: {} ({}) ends {d:e} away from every FreeCAD vertex",
                        e.id, e.source.entity
                    ));
                }
            }
        }
        let mut worst = [0.0f64; 3];
        for e in reading["edges"].as_array().unwrap() {
            if e["degenerated"].as_bool() == Some(true) {
                continue;
            }
            let samples = e["samples"].as_array().unwrap();
            let maps = curve_maps(&e["curve"]);
            // Geometric matching: the nurbsx curve closest to FreeCAD's samples.
            let mut best = curves
                .iter()
                .flat_map(|c| maps.iter().filter_map(|&m| curve_error(c, m, samples)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if best.is_none() {
                // A face bounded by a VERTEX_LOOP (the sphere) has no edge curve in the
                // file; FreeCAD makes a seam edge. It is the u = u0 isoparametric curve of
                // the surface (u0 the start of the angular range), in v.
                let isos: Vec<NurbsCurve> = surfaces
                    .iter()
                    .filter_map(|s| s.iso_u(s.domain().0.0).ok())
                    .collect();
                best = isos
                    .iter()
                    .flat_map(|c| maps.iter().filter_map(|&m| curve_error(c, m, samples)))
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                if best.is_some() {
                    println!(
                        "{name}: edge {} (no edge curve in the file) matched as the surface's seam",
                        e["index"]
                    );
                }
            }
            match best {
                Some((p, d1, d2))
                    if p <= POINT_TOL * size && d1 <= DERIV_TOL && d2 <= DERIV_TOL =>
                {
                    worst = [worst[0].max(p / size), worst[1].max(d1), worst[2].max(d2)];
                }
                other => failures.push(format!(
                    "{name}: edge {} ({}) best match {other:?} (size {size})",
                    e["index"], e["curve"]["type"]
                )),
            }
        }
        for f in reading["faces"].as_array().unwrap() {
            let samples = f["samples"].as_array().unwrap();
            let maps = surface_maps(&f["surface"]);
            let best = surfaces
                .iter()
                .filter_map(|s| surface_error(s, maps, samples))
                .min_by(|a, b| a[0].total_cmp(&b[0]));
            match best {
                Some([p, d1, d2])
                    if p <= POINT_TOL * size && d1 <= DERIV_TOL && d2 <= DERIV_TOL =>
                {
                    worst = [worst[0].max(p / size), worst[1].max(d1), worst[2].max(d2)];
                }
                other => failures.push(format!(
                    "{name}: face {} ({}) best match {other:?} (size {size})",
                    f["index"], f["surface"]["type"]
                )),
            }
        }
        println!(
            "{name}: {} entities; worst point/size {:.1e}, d1 {:.1e}, d2 {:.1e}",
            doc.entities.len(),
            worst[0],
            worst[1],
            worst[2]
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The filleted box with a hole (planes, cylinders, spheres): every face becomes a surface
/// of its analytic kind, nothing is empty.
#[test]
fn filleted_box_with_hole_converts() {
    let doc = read(&dir().join("filleted_box_with_hole.step"));
    let reading: Value = serde_json::from_slice(
        &std::fs::read(dir().join("filleted_box_with_hole.step.json")).unwrap(),
    )
    .unwrap();
    let faces = reading["faces"].as_array().unwrap().len();
    let surfaces: Vec<Option<Shape>> = doc
        .entities
        .iter()
        .filter(|e| matches!(e.geometry, Geometry::Surface(_)))
        .map(|e| e.meta.shape)
        .collect();
    assert_eq!(surfaces.len(), faces, "one surface per face");
    for kind in [Shape::Plane, Shape::Cylinder, Shape::Sphere] {
        assert!(surfaces.contains(&Some(kind)), "{kind:?} missing");
    }
    assert!(!doc.has_errors(), "{:?}", doc.diagnostics);
}

/// The TRIMMED_CURVE over a periodic B-spline (FreeCAD's edge over [1, 4] only) comes out
/// on exactly [1, 4], and equals the periodic curve there.
#[test]
fn periodic_trimmed_edge_is_exactly_its_range() {
    let doc = read(&dir().join("periodic_trimmed_edge.step"));
    let curves: Vec<&NurbsCurve> = doc
        .entities
        .iter()
        .filter_map(|e| match &e.geometry {
            Geometry::Curve(c) => Some(c),
            _ => None,
        })
        .collect();
    assert_eq!(
        curves.len(),
        1,
        "the trimmed curve only, not its basis as well"
    );
    assert_eq!(curves[0].domain(), (1.0, 4.0));
    assert_eq!(doc.entities[0].source.entity, "TRIMMED_CURVE");
}

/// The STEP writer labels a curve or surface with its kind only when the geometry agrees:
/// each kind built exactly (nurbs::conic / nurbs::sweep) is written with its form, and the
/// same geometry with one pole moved by 1e-6 of its size is written `.UNSPECIFIED.` with a
/// warning.
#[test]
fn writer_forms_follow_a_check_of_the_geometry() {
    use nurbsx::exchange::{Entity, ExportOptions, Meta, Source};
    use nurbsx::nurbs::conic::parabola_arc;
    use nurbsx::nurbs::sweep::{self, Frame};
    let f = Frame {
        origin: [1.0, 2.0, 3.0],
        x: [0.0, 1.0, 0.0],
        y: [0.0, 0.0, 1.0],
        z: [1.0, 0.0, 0.0],
    };
    let circle = conic_arc(
        ConicKind::Elliptic,
        [1.0, 2.0, 3.0],
        [0.0, 4.0, 0.0],
        [0.0, 0.0, 4.0],
        0.3,
        5.0,
    )
    .unwrap()
    .0;
    let ellipse = conic_arc(
        ConicKind::Elliptic,
        [0.0; 3],
        [5.0, 0.0, 0.0],
        [0.0, 2.0, 1.0],
        -1.0,
        2.0,
    )
    .unwrap()
    .0;
    let hyperbola = conic_arc(
        ConicKind::Hyperbolic,
        [0.0; 3],
        [3.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        -1.0,
        1.5,
    )
    .unwrap()
    .0;
    let parabola = parabola_arc([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], -2.0, 3.0).unwrap();
    // A line with a pole in the middle (a 2-pole line moved is still a line).
    let line = nurbsx::nurbs::conic::polyline(
        &[[0.0, 0.0, 0.0], [0.5, 1.0, 1.5], [1.0, 2.0, 3.0]],
        &[0.0, 0.5, 1.0],
    )
    .unwrap();
    let cases: Vec<(Shape, Geometry, &str)> = vec![
        (
            Shape::CircularArc,
            Geometry::Curve(circle.clone()),
            "CIRCULAR_ARC",
        ),
        (Shape::EllipticArc, Geometry::Curve(ellipse), "ELLIPTIC_ARC"),
        (
            Shape::HyperbolicArc,
            Geometry::Curve(hyperbola),
            "HYPERBOLIC_ARC",
        ),
        (
            Shape::ParabolicArc,
            Geometry::Curve(parabola),
            "PARABOLIC_ARC",
        ),
        (Shape::Line, Geometry::Curve(line), "POLYLINE_FORM"),
        (
            Shape::Plane,
            Geometry::Surface(sweep::plane(&f, (0.0, 2.0), (-1.0, 1.0)).unwrap()),
            "PLANE_SURF",
        ),
        (
            Shape::Cylinder,
            Geometry::Surface(sweep::cylinder(&f, 2.0, (0.5, 4.0), (0.0, 3.0)).unwrap().0),
            "CYLINDRICAL_SURF",
        ),
        (
            Shape::Cone,
            Geometry::Surface(
                sweep::cone(&f, 2.0, 0.3, (0.0, TAU), (-1.0, 3.0))
                    .unwrap()
                    .0,
            ),
            "CONICAL_SURF",
        ),
        (
            Shape::Sphere,
            Geometry::Surface(
                sweep::sphere(
                    &f,
                    2.0,
                    (0.0, TAU),
                    (-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2),
                )
                .unwrap()
                .0,
            ),
            "SPHERICAL_SURF",
        ),
        (
            Shape::Torus,
            Geometry::Surface(
                sweep::torus(&f, 5.0, 1.0, (0.0, 3.0), (0.0, TAU))
                    .unwrap()
                    .0,
            ),
            "TOROIDAL_SURF",
        ),
        (
            Shape::Revolution,
            Geometry::Surface(
                sweep::revolve(&circle, [0.0; 3], [0.0, 0.0, 1.0], 0.0, 2.0)
                    .unwrap()
                    .0,
            ),
            "SURF_OF_REVOLUTION",
        ),
        (
            Shape::Extrusion,
            Geometry::Surface(sweep::extrude(&circle, [1.0, 1.0, 0.0], 0.0, 2.0).unwrap()),
            "SURF_OF_LINEAR_EXTRUSION",
        ),
    ];
    let entity = |shape: Shape, g: Geometry| Entity {
        id: "#1".into(),
        geometry: g,
        source: Source::default(),
        meta: Meta {
            shape: Some(shape),
            ..Meta::default()
        },
    };
    for (shape, g, form) in cases {
        let mut doc = Document::new(nurbsx::exchange::Format::Step, LengthUnit::Mm);
        doc.entities.push(entity(shape, g.clone()));
        let text = exchange::step::write(&doc, &ExportOptions::default()).unwrap();
        assert!(text.contains(&format!(".{form}.")), "{shape:?}: {text}");
        assert!(exchange::step::form_warnings(&doc).is_empty());
        // One pole moved by 1e-6 of the size: no longer that kind. (Any planar polynomial
        // quadratic is a parabola: the parabola gets a middle weight 1 + 1e-6 instead.)
        let moved = match g {
            Geometry::Curve(c) if shape == Shape::ParabolicArc => {
                let (p, k, pts, _, dim) = c.into_parts();
                let w = vec![1.0, 1.0 + 1e-6, 1.0];
                Geometry::Curve(NurbsCurve::with_dimension(p, k, pts, Some(w), dim).unwrap())
            }
            Geometry::Curve(c) => {
                let size = nurbsx::nurbs::bounding_box_diagonal(c.control_points());
                let (p, k, mut pts, w, dim) = c.into_parts();
                let i = pts.len() / 2;
                pts[i][2] += 1e-6 * size;
                pts[i][0] += 1e-6 * size;
                Geometry::Curve(NurbsCurve::with_dimension(p, k, pts, w, dim).unwrap())
            }
            Geometry::Surface(s) => {
                let size = nurbsx::nurbs::bounding_box_diagonal(s.control_points().as_slice());
                let (pu, pv, ku, kv, net, w, dim) = s.into_parts();
                let mut flat = net.as_slice().to_vec();
                let i = flat.len() / 2 + 1;
                flat[i][0] += 1e-6 * size;
                flat[i][1] += 1e-6 * size;
                flat[i][2] += 1e-6 * size;
                let net = nurbsx::nurbs::Grid::from_u_major(net.nu(), net.nv(), flat).unwrap();
                Geometry::Surface(
                    NurbsSurface::with_dimension(pu, pv, ku, kv, net, w, dim).unwrap(),
                )
            }
        };
        doc.entities[0] = entity(shape, moved);
        let text = exchange::step::write(&doc, &ExportOptions::default()).unwrap();
        assert!(!text.contains(&format!(".{form}.")), "{shape:?}");
        let w = exchange::step::form_warnings(&doc);
        assert_eq!(w.len(), 1, "{shape:?}");
        assert_eq!(w[0].code, "step.form_unspecified");
    }
}

/// A STEP file around `data` with a millimetre length unit and, when `degrees`, a DEGREE
/// plane-angle unit (ISO 10303-41 conversion_based_unit), else RADIAN.
fn step_text(data: &str, degrees: bool) -> String {
    let angle = if degrees {
        "#902=( CONVERSION_BASED_UNIT('DEGREE',#903) NAMED_UNIT(#905) PLANE_ANGLE_UNIT() );\n\
         #903=PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925199433),#904);\n\
         #904=( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );\n\
         #905=DIMENSIONAL_EXPONENTS(0.,0.,0.,0.,0.,0.,0.);\n"
    } else {
        "#902=( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );\n"
    };
    format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nFILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n{data}\n\
         #900=( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#901,#902)) REPRESENTATION_CONTEXT('','') );\n\
         #901=( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n{angle}ENDSEC;\nEND-ISO-10303-21;\n"
    )
}

fn read_text(text: &str) -> Document {
    exchange::read(text.as_bytes(), &ImportOptions::default()).unwrap()
}

fn only_curve(doc: &Document) -> &NurbsCurve {
    let cs: Vec<&NurbsCurve> = doc
        .entities
        .iter()
        .filter_map(|e| match &e.geometry {
            Geometry::Curve(c) => Some(c),
            _ => None,
        })
        .collect();
    assert_eq!(cs.len(), 1, "{:?}", doc.diagnostics);
    cs[0]
}

fn close(a: Point3, b: Point3, tol: f64) -> bool {
    norm(sub(a, b)) <= tol
}

/// Circle of radius 2 about (1, 0, 0) in the xy plane: `C + 2 (cos t, sin t, 0)`.
const CIRCLE: &str = "#1=CARTESIAN_POINT('',(1.,0.,0.));\n#2=DIRECTION('',(0.,0.,1.));\n#3=DIRECTION('',(1.,0.,0.));\n#4=AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5=CIRCLE('',#4,2.);\n";

fn on_circle(t: f64) -> Point3 {
    [1.0 + 2.0 * t.cos(), 2.0 * t.sin(), 0.0]
}

#[test]
fn circle_trimmed_in_degrees_is_exactly_its_arc() {
    let doc = read_text(&step_text(
        &format!(
            "{CIRCLE}#6=TRIMMED_CURVE('',#5,(PARAMETER_VALUE(30.)),(PARAMETER_VALUE(300.)),.T.,.PARAMETER.);"
        ),
        true,
    ));
    let c = only_curve(&doc);
    let (a, b) = c.domain();
    assert!(
        (a - 30f64.to_radians()).abs() < 1e-15 && (b - 300f64.to_radians()).abs() < 1e-14,
        "{a} {b}"
    );
    let m = conic_arc(
        ConicKind::Elliptic,
        [0.0; 3],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        a,
        b,
    )
    .unwrap()
    .1;
    for k in 0..=20 {
        let t = a + (b - a) * k as f64 / 20.0;
        assert!(
            close(c.point_at(m.to_nurbs(t)).unwrap(), on_circle(t), 1e-14),
            "t = {t}"
        );
    }
    assert_eq!(doc.entities[0].meta.shape, Some(Shape::CircularArc));
}

/// sense_agreement .F.: the arc from trim_1 backwards to trim_2, i.e. 300 -> 390 degrees
/// traversed from 30 down to -60.
#[test]
fn sense_agreement_false_runs_backwards_over_the_seam() {
    let doc = read_text(&step_text(
        &format!(
            "{CIRCLE}#6=TRIMMED_CURVE('',#5,(PARAMETER_VALUE(30.)),(PARAMETER_VALUE(300.)),.F.,.PARAMETER.);"
        ),
        true,
    ));
    let c = only_curve(&doc);
    let (a, b) = c.domain();
    assert!((b - a - 90f64.to_radians()).abs() < 1e-14);
    assert!(close(
        c.point_at(a).unwrap(),
        on_circle(30f64.to_radians()),
        1e-14
    ));
    assert!(close(
        c.point_at(b).unwrap(),
        on_circle(-60f64.to_radians()),
        1e-14
    ));
    // u' = a + b - u: the middle of the domain is the middle of the arc (one symmetric
    // 90-degree segment), at -15 degrees.
    assert!(close(
        c.point_at(0.5 * (a + b)).unwrap(),
        on_circle(-15f64.to_radians()),
        1e-14
    ));
}

/// A line trimmed by points only (master CARTESIAN): the exact inverse `t = (P - pnt).dir /
/// |dir|^2` with a vector of magnitude 2.
#[test]
fn line_trimmed_by_points_uses_the_exact_inverse() {
    let doc = read_text(&step_text(
        "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(1.,0.,0.));\n#3=VECTOR('',#2,2.);\n#4=LINE('',#1,#3);\n#5=CARTESIAN_POINT('',(2.,0.,0.));\n#7=CARTESIAN_POINT('',(6.,0.,0.));\n#6=TRIMMED_CURVE('',#4,(#5),(#7),.T.,.CARTESIAN.);",
        false,
    ));
    let c = only_curve(&doc);
    assert_eq!(c.domain(), (1.0, 3.0));
    assert_eq!(c.point_at(1.0).unwrap(), [2.0, 0.0, 0.0]);
    assert_eq!(c.point_at(3.0).unwrap(), [6.0, 0.0, 0.0]);
    assert_eq!(c.point_at(2.0).unwrap(), [4.0, 0.0, 0.0]);
}

/// A composite of a line segment and a quarter circle: one NURBS on [0, 2 + pi/2] (the
/// segments' parameter lengths), continuous, through both pieces' points.
#[test]
fn composite_curve_joins_its_segments_in_sequence() {
    let doc = read_text(&step_text(
        &format!(
            "{CIRCLE}#10=CARTESIAN_POINT('',(3.,-2.,0.));\n#11=DIRECTION('',(0.,1.,0.));\n#12=VECTOR('',#11,1.);\n#13=LINE('',#10,#12);\n\
         #14=TRIMMED_CURVE('',#13,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(2.)),.T.,.PARAMETER.);\n\
         #15=TRIMMED_CURVE('',#5,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(1.5707963267948966)),.T.,.PARAMETER.);\n\
         #16=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#14);\n#17=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#15);\n\
         #18=COMPOSITE_CURVE('',(#16,#17),.F.);"
        ),
        false,
    ));
    let c = only_curve(&doc);
    let (a, b) = c.domain();
    assert_eq!(a, 0.0);
    assert!((b - (2.0 + std::f64::consts::FRAC_PI_2)).abs() < 1e-15);
    assert!(close(c.point_at(0.0).unwrap(), [3.0, -2.0, 0.0], 1e-15));
    assert!(close(c.point_at(1.0).unwrap(), [3.0, -1.0, 0.0], 1e-15));
    assert!(close(c.point_at(2.0).unwrap(), on_circle(0.0), 1e-15));
    assert!(close(
        c.point_at(b).unwrap(),
        on_circle(std::f64::consts::FRAC_PI_2),
        1e-14
    ));
    assert_eq!(doc.entities[0].source.entity, "COMPOSITE_CURVE");
}

/// A rectangular trim of a cylinder in degrees: u 0..90 degrees, v 0..5.
#[test]
fn rectangular_trimmed_cylinder_in_degrees() {
    let doc = read_text(&step_text(
        "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(0.,0.,1.));\n#3=DIRECTION('',(1.,0.,0.));\n#4=AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5=CYLINDRICAL_SURFACE('',#4,3.);\n#6=RECTANGULAR_TRIMMED_SURFACE('',#5,0.,90.,0.,5.,.T.,.T.);",
        true,
    ));
    let s: Vec<&NurbsSurface> = doc
        .entities
        .iter()
        .filter_map(|e| match &e.geometry {
            Geometry::Surface(s) => Some(s),
            _ => None,
        })
        .collect();
    assert_eq!(s.len(), 1, "{:?}", doc.diagnostics);
    let ((u0, u1), (v0, v1)) = s[0].domain();
    assert_eq!((u0, v0, v1), (0.0, 0.0, 5.0));
    assert!((u1 - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert!(close(
        s[0].point_at(u1, 5.0).unwrap(),
        [0.0, 3.0, 5.0],
        1e-14
    ));
    assert_eq!(doc.entities[0].meta.shape, Some(Shape::Cylinder));
}

/// An unbounded line nothing uses: one warning naming it, no entity, no invented extent.
/// An offset curve: one error naming it.
#[test]
fn unbounded_and_unrepresentable_geometry_is_reported_per_entity() {
    let doc = read_text(&step_text(
        &format!(
            "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(1.,0.,0.));\n#3=VECTOR('',#2,1.);\n#4=LINE('',#1,#3);\n{}\
         #20=OFFSET_CURVE_3D('',#5,1.,.F.,#2);",
            CIRCLE
                .replace("#1=", "#21=")
                .replace("(#1,", "(#21,")
                .replace("#4=AXIS", "#24=AXIS")
                .replace("#5=CIRCLE('',#4", "#5=CIRCLE('',#24")
        ),
        false,
    ));
    assert!(doc.entities.iter().all(|e| e.source.entity != "LINE"));
    let unbounded: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.code == "geometry.unbounded")
        .collect();
    assert_eq!(unbounded.len(), 1, "{:?}", doc.diagnostics);
    assert_eq!(unbounded[0].severity, Severity::Warning);
    assert_eq!(unbounded[0].location.entity.as_deref(), Some("#4"));
    let offset: Vec<_> = doc
        .diagnostics
        .iter()
        .filter(|d| d.code == "geometry.unsupported")
        .collect();
    assert_eq!(offset.len(), 1, "{:?}", doc.diagnostics);
    assert_eq!(offset[0].location.entity.as_deref(), Some("#20"));
}

/// An edge over an unbounded line with same_sense .F.: the segment between the vertices
/// in the line's own direction (from the end vertex to the start vertex).
#[test]
fn edge_over_a_line_is_bounded_by_its_vertices() {
    let doc = read_text(&step_text(
        "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(0.,1.,0.));\n#3=VECTOR('',#2,1.);\n#4=LINE('',#1,#3);\n\
         #5=CARTESIAN_POINT('',(0.,7.,0.));\n#6=CARTESIAN_POINT('',(0.,-2.,0.));\n#7=VERTEX_POINT('',#5);\n#8=VERTEX_POINT('',#6);\n\
         #9=EDGE_CURVE('',#7,#8,#4,.F.);",
        false,
    ));
    let c = only_curve(&doc);
    assert_eq!(c.domain(), (-2.0, 7.0));
    assert_eq!(doc.entities[0].meta.used_by, vec!["#9".to_owned()]);
}

/// A trimmed curve whose basis is itself (a reference cycle): a located error, no hang.
#[test]
fn self_referencing_trim_is_refused() {
    let doc = read_text(&step_text(
        "#6=TRIMMED_CURVE('',#6,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(1.)),.T.,.PARAMETER.);",
        false,
    ));
    assert!(doc.entities.is_empty());
    assert!(doc.has_errors());
}
