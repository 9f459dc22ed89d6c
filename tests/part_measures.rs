//! The pcurves of whole parts (`topology::edge_pcurve`): every sample part of
//! `samples/freecad/parts` (STEP, IGES 144 faces, IGES 186 B-rep) read with a pcurve on
//! every coedge, every face measured exactly (Green's theorem along the pcurves), the total
//! area and each solid's volume against FreeCAD's readings (the sample JSONs, an independent
//! kernel); and each exact pcurve evaluated on its surface against the 3-D edge curve at
//! dense samples (an evaluation, not the construction).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use nurbsx::exchange::{self, Document, ImportOptions};
use nurbsx::nurbs::vector::{cross, dist, dot, norm, sub};
use nurbsx::topology::{PcurveMethod, exact_pcurve};
use serde_json::Value;

fn parts() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/freecad/parts")
}

/// The document of a part file, read once per test run (both tests walk every file).
fn read(name: &str) -> &'static Document {
    static READ: OnceLock<Mutex<BTreeMap<String, &'static Document>>> = OnceLock::new();
    let cache = READ.get_or_init(Default::default);
    if let Some(doc) = cache.lock().unwrap().get(name) {
        return doc;
    }
    let bytes = std::fs::read(parts().join(name)).unwrap();
    let doc: &'static Document = Box::leak(Box::new(
        exchange::read(&bytes, &ImportOptions::default()).unwrap(),
    ));
    cache.lock().unwrap().insert(name.to_owned(), doc);
    doc
}

fn reading(file: &str) -> Value {
    let text = std::fs::read_to_string(parts().join(format!("{file}.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Every sample file with its part name.
fn files() -> Vec<(String, String)> {
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(parts().join("index.json")).unwrap())
            .unwrap();
    let mut out = Vec::new();
    for part in index["parts"].as_array().unwrap() {
        for file in part["files"].as_array().unwrap() {
            out.push((
                part["part"].as_str().unwrap().to_owned(),
                file["file"].as_str().unwrap().to_owned(),
            ));
        }
    }
    out
}

/// Samples along an edge for the independent check.
const DENSE: usize = 200;

/// Every exact pcurve (planes: the affine map; isocurves) against its 3-D curve at
/// `DENSE + 1` parameters of the edge's range: `|S(pcurve(t)) - C(t)| <= 1e-12` of the part's
/// size, plus on a plane the curve's own distance from the plane (computed here from the
/// plane's poles: the affine map projects orthogonally, and an IGES edge written with fewer
/// digits than its plane lies up to 5e-10 off it); the pcurves the reader stored on the
/// coedges within the edge tolerance. Both exact kinds occur among the parts.
#[test]
fn exact_pcurves_lie_on_their_edges() {
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for (_, name) in files() {
        let doc = read(&name);
        let mm = doc.units.to_mm();
        let size = reading(&name)["size"].as_f64().unwrap() / mm;
        let m = &doc.topology.model;
        for (f, face) in m.faces.iter().enumerate() {
            let s = &face.surface;
            for l in &face.loops {
                for c in &l.coedges {
                    let e = &m.edges[c.edge.0];
                    let (a, b) = e.range;
                    let at = |t: f64| (a + (b - a) * t).min(b);
                    let p = exact_pcurve(s, &e.curve, e.range, e.tolerance);
                    let kind = match p.as_ref().map(|p| p.method) {
                        Some(PcurveMethod::Affine) => "affine",
                        Some(PcurveMethod::Iso) => "iso",
                        _ => "projected",
                    };
                    *counts.entry(kind).or_default() += 1;
                    // The plane's unit normal, for the affine pcurves.
                    let g = s.control_points();
                    let (p00, p10, p01) = (*g.get(0, 0), *g.get(1, 0), *g.get(0, 1));
                    let n = cross(sub(p10, p00), sub(p01, p00));
                    let n = n.map(|x| x / norm(n));
                    // Coedges left without one are reported (`pcurve.not_computed`) and
                    // listed in KNOWN by the test below.
                    let stored = c.pcurve.as_ref();
                    for k in 0..=DENSE {
                        let t = at(k as f64 / DENSE as f64);
                        let want = e.curve.point_at_unchecked(t);
                        if let Some(p) = &p {
                            let [u, v, _] = p.curve.point_at_unchecked(t);
                            let ((u0, u1), (v0, v1)) = s.domain();
                            let on = s.point_at(u.clamp(u0, u1), v.clamp(v0, v1)).unwrap();
                            let off = if p.method == PcurveMethod::Affine {
                                dot(sub(want, p00), n).abs()
                            } else {
                                0.0
                            };
                            let d = dist(on, want);
                            assert!(
                                d <= 1e-12 * size + off,
                                "{name} face {f}: {kind} pcurve {d:e} from its edge at t = {t} \
                                 ({off:e} off the plane)"
                            );
                        }
                        if let Some(stored) = stored {
                            let (sa, sb) = stored.domain();
                            let [u, v, _] = stored.point_at_unchecked(t.clamp(sa, sb));
                            let ((u0, u1), (v0, v1)) = s.domain();
                            let on = s.point_at(u.clamp(u0, u1), v.clamp(v0, v1)).unwrap();
                            let d = dist(on, want);
                            assert!(
                                d <= e.tolerance,
                                "{name} face {f}: stored pcurve {d:e} from its edge at t = {t}"
                            );
                        }
                    }
                }
            }
        }
    }
    eprintln!("pcurves by method over all parts: {counts:?}");
    assert!(counts.get("affine").copied().unwrap_or(0) > 0, "{counts:?}");
    assert!(counts.get("iso").copied().unwrap_or(0) > 0, "{counts:?}");
}

/// Files that do not meet [`every_part_is_measured_against_freecad`] yet, and why (printed
/// with their figures when the test runs).
const KNOWN: &[(&str, &str)] = &[
    ("boss_radial_hole.step", HOLE),
    ("boss_radial_hole.igs", HOLE),
    ("boss_radial_hole_brep.igs", HOLE),
    ("extrude_bspline.step", FREECAD_OFF),
    ("extrude_bspline.igs", FREECAD_OFF),
    ("extrude_bspline_brep.igs", FREECAD_OFF),
    ("loft_bspline.step", FREECAD),
    ("loft_bspline.igs", FREECAD),
    ("loft_bspline_brep.igs", FREECAD),
    ("sweep_circle_bspline.step", FREECAD),
    ("sweep_circle_bspline.igs", FREECAD),
    ("sweep_circle_bspline_brep.igs", FREECAD),
    ("revolve_bspline_270.step", FREECAD),
    ("revolve_bspline_270.igs", FREECAD),
    ("revolve_bspline_270_brep.igs", BREP_SENSE),
];

/// The radial hole's intersection curves have projected pcurves (1e-6 bound): the volume is
/// 1.06e-6 from FreeCAD's.
const HOLE: &str = "projected pcurves of the radial hole: volume 1.06e-6 from FreeCAD's";
/// The 186 B-rep of the 270-degree revolution: its volume is 11306.6 against 9798.6; the
/// faces' senses against their bounds are not resolved for this file.
const BREP_SENSE: &str = "186 B-rep of the revolution: volume 11306.6, faces' senses not resolved";
/// FreeCAD's figures are off: the area and volume of this part are checked against exact
/// rational arithmetic in [`extrude_bspline_against_exact_rationals`].
const FREECAD_OFF: &str = "FreeCAD's area/volume off by 2e-4 (ours agree with exact rationals)";
/// Faces of B-spline surfaces whose area or volume FreeCAD (Open CASCADE's integration)
/// reports 5e-7 to 4e-3 apart from the Green's theorem figure; not resolved which is off.
const FREECAD: &str = "B-spline faces: FreeCAD's area/volume differ by more than 1e-6";

/// Every part file: no coedge without a pcurve (`pcurve.not_computed`), every face
/// measured, the total area against FreeCAD's within 1e-9 relative where every pcurve of the
/// file is exact (1e-6 where some is projected within the edge tolerance), each solid's
/// volume likewise. The assembly's product structure is not read into the topology
/// (tests/step_topology.rs KNOWN_GAPS), so FreeCAD's totals, which count every placed
/// instance, are not compared there.
#[test]
fn every_part_is_measured_against_freecad() {
    let mut checked = 0;
    let mut failures: Vec<(String, String)> = Vec::new();
    for (part, name) in files() {
        let doc = read(&name);
        let missing: Vec<&str> = doc
            .diagnostics
            .iter()
            .filter(|d| d.code == "pcurve.not_computed")
            .map(|d| d.message.as_str())
            .collect();
        if !missing.is_empty() {
            failures.push((name.clone(), format!("{missing:?}")));
            continue;
        }
        let mm = doc.units.to_mm();
        let m = &doc.topology.model;
        let json = reading(&name);
        let mut exact = true;
        let mut area = 0.0;
        for (f, face) in m.faces.iter().enumerate() {
            match m.measure_face(face) {
                Ok(measured) => area += measured.area,
                Err(e) => failures.push((name.clone(), format!("face {f}: {e}"))),
            }
            for l in &face.loops {
                for c in &l.coedges {
                    let e = &m.edges[c.edge.0];
                    exact &= exact_pcurve(&face.surface, &e.curve, e.range, e.tolerance).is_some();
                }
            }
        }
        if part == "assembly_links" {
            continue;
        }
        let rel = if exact { 1e-9 } else { 1e-6 };
        let freecad = json["totals"]["area"].as_f64().unwrap() / (mm * mm);
        if (area - freecad).abs() > rel * freecad {
            failures.push((
                name.clone(),
                format!(
                    "area {area} vs FreeCAD's {freecad} ({:e} relative, exact pcurves: {exact})",
                    (area - freecad) / freecad
                ),
            ));
        }
        // FreeCAD's solids come from its STEP reading (it makes none of IGES 144 faces).
        let step = reading(&format!("{part}.step"));
        let mut want: Vec<f64> = step["solids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x["volume"].as_f64().unwrap() / (mm * mm * mm))
            .collect();
        let mut got: Vec<f64> = Vec::new();
        for k in 0..m.solids.len() {
            match m.solid_volume(nurbsx::topology::SolidId(k)) {
                Ok(v) => got.push(v),
                Err(e) => failures.push((name.clone(), format!("solid {k}: {e}"))),
            }
        }
        if !got.is_empty() {
            // IGES 144 faces carry no orientation; sewn shells are compared by size.
            let sewn = !name.ends_with(".step") && !name.ends_with("_brep.igs");
            if sewn {
                got.iter_mut().for_each(|v| *v = v.abs());
            }
            want.sort_by(f64::total_cmp);
            got.sort_by(f64::total_cmp);
            if got.len() != want.len() {
                let n = format!("{} solids, FreeCAD {}", got.len(), want.len());
                failures.push((name.clone(), n));
            }
            for (v, w) in got.iter().zip(&want) {
                if (v - w).abs() > rel * w.abs() {
                    failures.push((
                        name.clone(),
                        format!("volume {v} vs FreeCAD's {w} ({:e} relative)", (v - w) / w),
                    ));
                }
            }
        }
        checked += 1;
    }
    let mut unexpected = Vec::new();
    for (file, what) in &failures {
        match KNOWN.iter().find(|k| k.0 == file) {
            Some((_, why)) => eprintln!("{file}: {what} (known: {why})"),
            None => unexpected.push(format!("{file}: {what}")),
        }
    }
    for (file, why) in KNOWN {
        if !failures.iter().any(|f| f.0 == *file) {
            unexpected.push(format!(
                "{file}: listed in KNOWN ({why}) but passes: unlist it"
            ));
        }
    }
    assert!(unexpected.is_empty(), "{}", unexpected.join("\n"));
    assert!(checked >= 31, "only {checked} files compared");
}

/// `extrude_bspline.step`: a closed periodic uniform cubic B-spline profile (the poles of
/// its `#33`, knots -3..11 step 1) extruded by 15 along z. Its enclosed area is a polynomial
/// integral, `A = ∮ x dy` over the 8 spans in the power basis of the uniform cubic B-spline
/// (each span `P(t) = [1 t t² t³] M [P_i .. P_i+3]`, `M` with entries in sixths), computed
/// here in exact rationals: `A = 7843/24`. Its perimeter `L` by composite Simpson on each span
/// (20 000 intervals, error far below 1e-12). The solid's volume must be `15 A` and its area
/// `15 L + 2 A` within 1e-12 relative; FreeCAD's own figures are 4e-4 and 2e-4 off.
#[test]
fn extrude_bspline_against_exact_rationals() {
    use num_rational::BigRational as Q;
    use num_traits::ToPrimitive;
    const P: [(i64, i64); 11] = [
        (12, 0),
        (9, 9),
        (0, 7),
        (-10, 10),
        (-12, 0),
        (-6, -8),
        (0, -12),
        (9, -7),
        (12, 0),
        (9, 9),
        (0, 7),
    ];
    // Rows: pole k of the span; columns: the coefficient of t^d, times 6.
    const M: [[i64; 4]; 4] = [[1, -3, 3, -1], [4, 0, -6, 3], [1, 3, 3, -3], [0, 0, 0, 1]];
    let q = |n: i64, d: i64| Q::new(n.into(), d.into());
    let mut area = q(0, 1);
    let mut perimeter = 0.0;
    for i in 0..8 {
        let coef = |axis: usize, d: usize| -> Q {
            (0..4)
                .map(|k| q(M[k][d] * if axis == 0 { P[i + k].0 } else { P[i + k].1 }, 6))
                .fold(q(0, 1), |a, b| a + b)
        };
        // ∫_0^1 x(t) y'(t) dt = Σ_d Σ_e x_d e y_e / (d + e).
        for d in 0..4 {
            for e in 1..4 {
                area += coef(0, d) * coef(1, e) * q(e as i64, (d + e) as i64);
            }
        }
        let speed = |t: f64| {
            let (mut dx, mut dy) = (0.0, 0.0);
            for e in 1..4 {
                let w = e as f64 * t.powi(e as i32 - 1);
                dx += w * coef(0, e).to_f64().unwrap();
                dy += w * coef(1, e).to_f64().unwrap();
            }
            dx.hypot(dy)
        };
        let n = 20_000;
        let h = 1.0 / n as f64;
        let mut sum = speed(0.0) + speed(1.0);
        for j in 1..n {
            sum += if j % 2 == 1 { 4.0 } else { 2.0 } * speed(j as f64 * h);
        }
        perimeter += sum * h / 3.0;
    }
    assert_eq!(area, q(7843, 24));
    let a = area.to_f64().unwrap();
    let doc = read("extrude_bspline.step");
    let m = &doc.topology.model;
    let mut measured = 0.0;
    for face in &m.faces {
        measured += m.measure_face(face).unwrap().area;
    }
    let want = 15.0 * perimeter + 2.0 * a;
    assert!(
        (measured - want).abs() <= 1e-12 * want,
        "area {measured} vs {want}"
    );
    assert_eq!(m.solids.len(), 1);
    let volume = m.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
    assert!(
        (volume - 15.0 * a).abs() <= 1e-12 * 15.0 * a,
        "volume {volume} vs {}",
        15.0 * a
    );
}
