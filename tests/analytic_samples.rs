//! The analytic sample corpus (`samples/freecad/analytic/`) is self-consistent.
//!
//! These checks are about FreeCAD's data, not about nurbsx: every reading JSON parses and
//! carries the schema string `nurbsx-freecad-analytic/1`, every exported file has its reading,
//! and FreeCAD's samples agree with the closed-form parameterisation documented in
//! `samples/freecad/analytic/README.md`, evaluated here independently from the JSON's defining
//! data (centre, axes, radii, semi-angle, focal distance):
//! - lines, circles, ellipses, hyperbolas, parabolas (ISO 10303-42 clause 4.4 conic forms):
//!   point, first and second derivative; a circle's points lie at its radius;
//! - planes, cylinders, cones (v along the generatrix), spheres, tori: point, the five partials
//!   and the normal su × sv / |su × sv|;
//! - surfaces of revolution and extrusion over an analytic profile: the same, through the
//!   rotation (ISO 10303-42 surface_of_revolution) or translation of the profile; over a
//!   B-spline profile: the invariants (distance to the axis and height along it do not depend
//!   on u; P(u, v) − P(u, v0) = (v − v0)·D);
//! - edge lengths of analytic curves (exact for lines and circles, Simpson quadrature of |d1|
//!   otherwise) and areas of quadric faces over their parameter rectangle;
//! - the end samples of every edge are vertices of the edge;
//! - the declared unit of the unit cases, and the re-imported vertices (in mm) are those of
//!   the in-memory source.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use serde_json::Value;

mod common;
use common::{cross, dot, norm, sub};

const SCHEMA: &str = "nurbsx-freecad-analytic/1";
/// Points and derivatives: FreeCAD and the formula here differ only by rounding.
const EVAL_TOL: f64 = 1e-11;
/// Lengths and areas: OCCT integrates numerically (BRepGProp).
const MEASURE_TOL: f64 = 1e-9;

type V3 = [f64; 3];

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/analytic")
}

fn readings() -> Vec<(String, Value)> {
    let mut out: Vec<(String, Value)> = std::fs::read_dir(dir())
        .expect("samples/freecad/analytic exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("json"))
        .filter(|p| p.file_name().unwrap() != "index.json")
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read_to_string(&p).unwrap();
            let v: Value =
                serde_json::from_str(&text).unwrap_or_else(|e| panic!("{name}: not JSON: {e}"));
            (name, v)
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn v3(v: &Value) -> V3 {
    let a = v.as_array().expect("a 3-vector");
    assert_eq!(a.len(), 3);
    [
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    ]
}

fn f(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number in {v}"))
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}
fn lin(terms: &[(f64, V3)]) -> V3 {
    terms
        .iter()
        .fold([0.0; 3], |acc, &(s, v)| add(acc, mul(s, v)))
}

/// Point, first and second derivative of an analytic curve at t (README: curves table);
/// `None` for types without a closed form here (B-splines).
fn curve_eval(c: &Value, t: f64) -> Option<[V3; 3]> {
    let frame = || (v3(&c["center"]), v3(&c["x_axis"]), v3(&c["y_axis"]));
    let ty = c["type"].as_str().unwrap();
    if ty == "Part.LineSegment" || ty.starts_with("Part.ArcOf") {
        return curve_eval(&c["basis_curve"], t);
    }
    Some(match ty {
        "Part.Line" => {
            let (p, d) = (v3(&c["location"]), v3(&c["direction"]));
            [add(p, mul(t, d)), d, [0.0; 3]]
        }
        "Part.Circle" | "Part.Ellipse" | "Part.Hyperbola" => {
            let (o, x, y) = frame();
            let (a, b) = if c["type"] == "Part.Circle" {
                (f(c, "radius"), f(c, "radius"))
            } else {
                (f(c, "major_radius"), f(c, "minor_radius"))
            };
            if c["type"] == "Part.Hyperbola" {
                let (ch, sh) = (t.cosh(), t.sinh());
                [
                    add(o, lin(&[(a * ch, x), (b * sh, y)])),
                    lin(&[(a * sh, x), (b * ch, y)]),
                    lin(&[(a * ch, x), (b * sh, y)]),
                ]
            } else {
                let (co, si) = (t.cos(), t.sin());
                [
                    add(o, lin(&[(a * co, x), (b * si, y)])),
                    lin(&[(-a * si, x), (b * co, y)]),
                    lin(&[(-a * co, x), (-b * si, y)]),
                ]
            }
        }
        "Part.Parabola" => {
            let (v, x, y) = (v3(&c["vertex"]), v3(&c["x_axis"]), v3(&c["y_axis"]));
            let fo = f(c, "focal");
            [
                add(v, lin(&[(t * t / (4.0 * fo), x), (t, y)])),
                lin(&[(t / (2.0 * fo), x), (1.0, y)]),
                mul(1.0 / (2.0 * fo), x),
            ]
        }
        _ => return None,
    })
}

/// Rotation of w by the angle u about the unit axis a (ISO 10303-42 surface_of_revolution).
fn rotate(w: V3, a: V3, u: f64) -> V3 {
    let along = mul(dot(w, a), a);
    lin(&[
        (1.0, along),
        (u.cos(), sub(w, along)),
        (u.sin(), cross(a, w)),
    ])
}

/// [point, su, sv, suu, suv, svv] of a surface at (u, v) (README: surfaces table).
fn surface_eval(s: &Value, u: f64, v: f64) -> Option<[V3; 6]> {
    let ty = s["type"].as_str().unwrap();
    if ty == "Part.SurfaceOfRevolution" {
        let (l, a) = (v3(&s["location"]), v3(&s["direction"]));
        let [c, c1, c2] = curve_eval(&s["basis_curve"], v)?;
        let w = sub(c, l);
        // d/du of rot(w, u): rotation by u + pi/2 minus the axial part.
        let rot1 = |w: V3| sub(rotate(w, a, u + PI / 2.0), mul(dot(w, a), a));
        // d²/du² of rot(w, u): minus the radial part of the rotated vector.
        let radial = sub(rotate(w, a, u), mul(dot(w, a), a));
        return Some([
            add(l, rotate(w, a, u)),
            rot1(w),
            rotate(c1, a, u),
            mul(-1.0, radial),
            rot1(c1),
            rotate(c2, a, u),
        ]);
    }
    if ty == "Part.SurfaceOfExtrusion" {
        let d = v3(&s["direction"]);
        let [c, c1, c2] = curve_eval(&s["basis_curve"], u)?;
        return Some([add(c, mul(v, d)), c1, d, c2, [0.0; 3], [0.0; 3]]);
    }
    let (o, x, y, z) = match ty {
        "Part.Plane" | "Part.Cylinder" | "Part.Cone" | "Part.Sphere" | "Part.Toroid" => (
            v3(&s["location"]),
            v3(&s["x_axis"]),
            v3(&s["y_axis"]),
            v3(&s["axis"]),
        ),
        _ => return None,
    };
    let ring = lin(&[(u.cos(), x), (u.sin(), y)]);
    let ring1 = lin(&[(-u.sin(), x), (u.cos(), y)]);
    let zero = [0.0; 3];
    Some(match ty {
        "Part.Plane" => [add(o, lin(&[(u, x), (v, y)])), x, y, zero, zero, zero],
        "Part.Cylinder" => {
            let r = f(s, "radius");
            [
                add(o, lin(&[(r, ring), (v, z)])),
                mul(r, ring1),
                z,
                mul(-r, ring),
                zero,
                zero,
            ]
        }
        "Part.Cone" => {
            let (r, al) = (f(s, "radius"), f(s, "semi_angle"));
            let rho = r + v * al.sin();
            [
                add(o, lin(&[(rho, ring), (v * al.cos(), z)])),
                mul(rho, ring1),
                lin(&[(al.sin(), ring), (al.cos(), z)]),
                mul(-rho, ring),
                mul(al.sin(), ring1),
                zero,
            ]
        }
        "Part.Sphere" => {
            let r = f(s, "radius");
            let (cv, sv) = (v.cos(), v.sin());
            [
                add(o, lin(&[(r * cv, ring), (r * sv, z)])),
                mul(r * cv, ring1),
                lin(&[(-r * sv, ring), (r * cv, z)]),
                mul(-r * cv, ring),
                mul(-r * sv, ring1),
                lin(&[(-r * cv, ring), (-r * sv, z)]),
            ]
        }
        _ => {
            let (big, small) = (f(s, "major_radius"), f(s, "minor_radius"));
            let (cv, sv) = (v.cos(), v.sin());
            let rho = big + small * cv;
            [
                add(o, lin(&[(rho, ring), (small * sv, z)])),
                mul(rho, ring1),
                lin(&[(-small * sv, ring), (small * cv, z)]),
                mul(-rho, ring),
                mul(-small * sv, ring1),
                lin(&[(-small * cv, ring), (-small * sv, z)]),
            ]
        }
    })
}

/// 1 + the largest coordinate magnitude of all sample points: the model size.
fn model_size(r: &Value) -> f64 {
    let mut m: f64 = 0.0;
    for e in r["edges"].as_array().unwrap() {
        for s in e["samples"].as_array().unwrap() {
            m = v3(&s["point"]).iter().fold(m, |m, c| m.max(c.abs()));
        }
    }
    for fa in r["faces"].as_array().unwrap() {
        for s in fa["samples"].as_array().unwrap() {
            m = v3(&s["point"]).iter().fold(m, |m, c| m.max(c.abs()));
        }
    }
    1.0 + m
}

fn close(name: &str, what: &str, got: V3, want: V3, scale: f64) {
    let err = norm(sub(got, want));
    assert!(
        err <= EVAL_TOL * scale,
        "{name}: {what}: FreeCAD {got:?}, formula {want:?}, |diff| {err:e} > {EVAL_TOL:e} x {scale:e}"
    );
}

/// The largest norm of `key` over an item's samples (the scale of that derivative).
fn scale_of(samples: &[Value], key: &str, size: f64) -> f64 {
    samples
        .iter()
        .filter(|s| !s[key].is_null())
        .map(|s| norm(v3(&s[key])))
        .fold(size, f64::max)
}

fn simpson(n: usize, a: f64, b: f64, g: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / n as f64;
    let mut sum = g(a) + g(b);
    for i in 1..n {
        sum += g(a + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

struct Tally {
    checked: BTreeMap<String, usize>,
}

impl Tally {
    fn add(&mut self, what: &str) {
        *self.checked.entry(what.to_string()).or_default() += 1;
    }
}

fn check_edges(name: &str, r: &Value, size: f64, tally: &mut Tally) {
    for e in r["edges"].as_array().unwrap() {
        let samples = e["samples"].as_array().unwrap();
        if e["degenerated"].as_bool().unwrap() {
            assert!(
                e["curve"].is_null() && samples.is_empty(),
                "{name}: degenerated edge"
            );
            continue;
        }
        assert_eq!(samples.len(), 7, "{name}: 7 samples per edge");
        let c = &e["curve"];
        let ty = c["type"].as_str().unwrap();
        let range = e["range"].as_array().unwrap();
        let (t0, t1) = (range[0].as_f64().unwrap(), range[1].as_f64().unwrap());
        assert_eq!(
            f(&samples[0], "t"),
            t0,
            "{name}: first sample at range start"
        );
        assert_eq!(f(&samples[6], "t"), t1, "{name}: last sample at range end");
        // The edge's ends are its vertices (OCCT's vertex tolerance is 1e-7).
        let verts: Vec<V3> = e["vertices"].as_array().unwrap().iter().map(v3).collect();
        for s in [&samples[0], &samples[6]] {
            let p = v3(&s["point"]);
            let d = verts
                .iter()
                .map(|q| norm(sub(p, *q)))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d <= 1e-6 * size,
                "{name}: edge end {p:?} is {d:e} from every vertex"
            );
        }
        tally.add("edge ends at vertices");
        let s1 = scale_of(samples, "d1", size);
        let s2 = scale_of(samples, "d2", size);
        let mut analytic = false;
        for s in samples {
            let t = f(s, "t");
            let Some([p, d1, d2]) = curve_eval(c, t) else {
                break;
            };
            analytic = true;
            close(
                name,
                &format!("{ty} point at t={t}"),
                v3(&s["point"]),
                p,
                size,
            );
            close(name, &format!("{ty} d1 at t={t}"), v3(&s["d1"]), d1, s1);
            close(name, &format!("{ty} d2 at t={t}"), v3(&s["d2"]), d2, s2);
            if ty == "Part.Circle" {
                let rr = f(c, "radius");
                let w = sub(v3(&s["point"]), v3(&c["center"]));
                let off = dot(w, v3(&c["axis"]));
                let err = (norm(w) - rr).abs();
                assert!(
                    err <= 1e-12 * rr,
                    "{name}: circle point {err:e} off its radius"
                );
                assert!(
                    off.abs() <= 1e-12 * rr,
                    "{name}: circle point {off:e} off its plane"
                );
                tally.add("circle points at radius");
            }
        }
        if analytic {
            tally.add(ty);
            let length = f(e, "length");
            let want = match ty {
                "Part.Line" => (t1 - t0).abs(),
                "Part.Circle" => f(c, "radius") * (t1 - t0).abs(),
                _ => simpson(4000, t0, t1, |t| norm(curve_eval(c, t).unwrap()[1])),
            };
            let err = (length - want).abs();
            assert!(
                err <= MEASURE_TOL * want,
                "{name}: {ty} edge length {length}, formula {want}, rel {:e}",
                err / want
            );
            tally.add("edge lengths");
        }
    }
}

fn check_faces(name: &str, r: &Value, size: f64, tally: &mut Tally) {
    let n_edges = r["edges"].as_array().unwrap().len();
    for fa in r["faces"].as_array().unwrap() {
        for i in fa["edge_indices"].as_array().unwrap() {
            assert!(
                (i.as_u64().unwrap() as usize) < n_edges,
                "{name}: edge index in range"
            );
        }
        let s = &fa["surface"];
        let ty = s["type"].as_str().unwrap();
        let samples = fa["samples"].as_array().unwrap();
        assert_eq!(samples.len(), 25, "{name}: 5x5 samples per face");
        let keys = ["point", "su", "sv", "suu", "suv", "svv"];
        let scales: Vec<f64> = keys.iter().map(|k| scale_of(samples, k, size)).collect();
        let mut analytic = false;
        for sm in samples {
            let (u, v) = (f(sm, "u"), f(sm, "v"));
            let Some(want) = surface_eval(s, u, v) else {
                break;
            };
            analytic = true;
            for (k, key) in keys.iter().enumerate() {
                let scale = if k == 0 { size } else { scales[k] };
                close(
                    name,
                    &format!("{ty} {key} at ({u}, {v})"),
                    v3(&sm[*key]),
                    want[k],
                    scale,
                );
            }
            let n = cross(want[1], want[2]);
            if norm(n) > 1e-6 * scales[1] * scales[2] {
                let got = v3(&sm["normal"]);
                close(
                    name,
                    &format!("{ty} normal at ({u}, {v})"),
                    got,
                    mul(1.0 / norm(n), n),
                    1.0,
                );
            }
        }
        if analytic {
            tally.add(ty);
        } else if ty == "Part.SurfaceOfRevolution" || ty == "Part.SurfaceOfExtrusion" {
            check_sweep_invariants(name, s, samples, size);
            tally.add(&format!("{ty} (B-spline profile, invariants)"));
        }
        if let Some(want) = quadric_area(s, fa) {
            let area = f(fa, "area");
            let err = (area - want).abs();
            assert!(
                err <= MEASURE_TOL * want,
                "{name}: {ty} face area {area}, formula over its range {want}, rel {:e}",
                err / want
            );
            tally.add("quadric face areas");
        }
    }
}

/// Area of a quadric face over its whole parameter rectangle (every quadric face of this
/// corpus is bounded by iso-parametric curves, possibly degenerate at a pole or apex).
fn quadric_area(s: &Value, fa: &Value) -> Option<f64> {
    let r = fa["range"].as_array().unwrap();
    let [u0, u1, v0, v1] = [0, 1, 2, 3].map(|i| r[i].as_f64().unwrap());
    let du = u1 - u0;
    Some(match s["type"].as_str().unwrap() {
        "Part.Cylinder" => f(s, "radius") * du * (v1 - v0),
        "Part.Cone" => {
            let (rr, sa) = (f(s, "radius"), f(s, "semi_angle").sin());
            (du * ((rr * v1 + sa * v1 * v1 / 2.0) - (rr * v0 + sa * v0 * v0 / 2.0))).abs()
        }
        "Part.Sphere" => f(s, "radius").powi(2) * du * (v1.sin() - v0.sin()),
        "Part.Toroid" => {
            let (big, small) = (f(s, "major_radius"), f(s, "minor_radius"));
            small * du * (big * (v1 - v0) + small * (v1.sin() - v0.sin()))
        }
        _ => return None,
    })
}

/// Revolution: distance to the axis and height along it do not depend on u.
/// Extrusion: P(u, v) − P(u, v0) = (v − v0)·D and su does not depend on v.
fn check_sweep_invariants(name: &str, s: &Value, samples: &[Value], size: f64) {
    let d = v3(&s["direction"]);
    // samples: u outer (5), v inner (5)
    for j in 0..5 {
        for i in 0..5 {
            let sm = &samples[i * 5 + j];
            let p = v3(&sm["point"]);
            if s["type"] == "Part.SurfaceOfRevolution" {
                let l = v3(&s["location"]);
                let p0 = v3(&samples[j]["point"]);
                let (w, w0) = (sub(p, l), sub(p0, l));
                let (h, h0) = (dot(w, d), dot(w0, d));
                let (rho, rho0) = (norm(cross(w, d)), norm(cross(w0, d)));
                assert!(
                    (h - h0).abs() <= EVAL_TOL * size,
                    "{name}: revolution height varies"
                );
                assert!(
                    (rho - rho0).abs() <= EVAL_TOL * size,
                    "{name}: revolution radius varies"
                );
            } else {
                let base = &samples[i * 5];
                let dv = f(sm, "v") - f(base, "v");
                close(
                    name,
                    "extrusion point",
                    p,
                    add(v3(&base["point"]), mul(dv, d)),
                    size,
                );
                close(name, "extrusion su", v3(&sm["su"]), v3(&base["su"]), size);
            }
        }
    }
}

#[test]
fn analytic_samples_are_self_consistent() {
    let all = readings();
    assert!(all.len() >= 80, "corpus present ({} readings)", all.len());
    let mut tally = Tally {
        checked: BTreeMap::new(),
    };
    let mut sources: BTreeMap<String, Vec<V3>> = BTreeMap::new();
    for (name, r) in &all {
        assert_eq!(r["schema"], SCHEMA, "{name}: schema");
        let edges = r["edges"].as_array().expect("edges");
        let faces = r["faces"].as_array().expect("faces");
        let counts = &r["counts"];
        assert_eq!(
            counts["edges"].as_u64().unwrap() as usize,
            edges.len(),
            "{name}: edges"
        );
        assert_eq!(
            counts["faces"].as_u64().unwrap() as usize,
            faces.len(),
            "{name}: faces"
        );
        let per_type: u64 = counts["curve_types"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert_eq!(per_type as usize, edges.len(), "{name}: curve_types add up");
        if r["format"] == "in-memory" {
            assert!(
                r["file"].is_null() && r["declared_unit"].is_null(),
                "{name}"
            );
            let verts = edges
                .iter()
                .flat_map(|e| e["vertices"].as_array().unwrap().iter().map(v3));
            sources.insert(r["case"].as_str().unwrap().to_string(), verts.collect());
        } else {
            let file = r["file"].as_str().unwrap();
            assert_eq!(
                format!("{file}.json"),
                *name,
                "{name}: reading of its own file"
            );
            assert!(dir().join(file).exists(), "{name}: {file} is committed");
            let unit = &r["declared_unit"];
            let want = r["export"]["unit"].as_str().unwrap();
            assert_eq!(unit["name"], want, "{name}: declared unit");
            let mm = [("MM", 1.0), ("INCH", 25.4), ("M", 1000.0)];
            let factor = mm.iter().find(|(n, _)| *n == want).unwrap().1;
            assert_eq!(f(unit, "mm_per_unit"), factor, "{name}: unit factor");
            assert!(
                !r["file_entities"].as_object().unwrap().is_empty(),
                "{name}: entities"
            );
        }
        let size = model_size(r);
        check_edges(name, r, size, &mut tally);
        check_faces(name, r, size, &mut tally);
    }
    // Re-imported vertices (OCCT converts inch and metre files to mm) are the source's.
    for (name, r) in &all {
        if r["format"] == "in-memory" {
            continue;
        }
        let src = &sources[r["case"].as_str().unwrap()];
        let size = model_size(r);
        for e in r["edges"].as_array().unwrap() {
            for q in e["vertices"].as_array().unwrap().iter().map(v3) {
                let d = src
                    .iter()
                    .map(|p| norm(sub(*p, q)))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    d <= 1e-7 * size,
                    "{name}: vertex {q:?} is {d:e} from every source vertex"
                );
            }
        }
        tally.add("re-imported vertices at source vertices (files)");
    }
    // Every exported file has its reading, every case its source.
    for entry in std::fs::read_dir(dir()).unwrap() {
        let p = entry.unwrap().path();
        let fname = p.file_name().unwrap().to_string_lossy().into_owned();
        if fname.ends_with(".step") || fname.ends_with(".igs") {
            assert!(
                dir().join(format!("{fname}.json")).exists(),
                "{fname} has no reading"
            );
        }
    }
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("index.json")).unwrap()).unwrap();
    assert_eq!(index["schema"], SCHEMA);
    for c in index["cases"].as_array().unwrap() {
        let case = c["case"].as_str().unwrap();
        assert!(sources.contains_key(case), "{case}: source.json");
    }
    println!("checked: {:#?}", tally.checked);
    for what in [
        "Part.Line",
        "Part.Circle",
        "Part.Ellipse",
        "Part.Hyperbola",
        "Part.Parabola",
        "Part.Plane",
        "Part.Cylinder",
        "Part.Cone",
        "Part.Sphere",
        "Part.Toroid",
        "Part.SurfaceOfRevolution",
        "Part.SurfaceOfExtrusion",
        "Part.SurfaceOfRevolution (B-spline profile, invariants)",
        "circle points at radius",
        "edge lengths",
        "quadric face areas",
    ] {
        assert!(
            tally.checked.contains_key(what),
            "nothing checked for {what}"
        );
    }
}
