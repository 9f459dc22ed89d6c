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
                    let p = exact_pcurve(s, None, &e.curve, e.range, e.tolerance);
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
    ("loft_bspline.step", QUADRATURE),
    ("loft_bspline.igs", QUADRATURE),
    ("loft_bspline_brep.igs", QUADRATURE),
    ("sweep_circle_bspline.step", QUADRATURE),
    ("sweep_circle_bspline.igs", QUADRATURE),
    ("sweep_circle_bspline_brep.igs", QUADRATURE),
    ("revolve_bspline_270.step", REVOLVE),
    ("revolve_bspline_270.igs", REVOLVE),
    ("revolve_bspline_270_brep.igs", REVOLVE),
];

/// The radial hole's intersection curves have projected pcurves (1e-6 bound): the volume is
/// 1.06e-6 from FreeCAD's.
const HOLE: &str = "projected pcurves of the radial hole: volume 1.06e-6 from FreeCAD's";
/// FreeCAD's figures are off: the area and volume of this part are checked against exact
/// rational arithmetic in [`extrude_bspline_against_exact_rationals`].
const FREECAD_OFF: &str = "FreeCAD's area/volume off by 2e-4 (ours agree with exact rationals)";
/// FreeCAD's (Open CASCADE's) integration of B-spline faces is off by 2e-8 to 4e-3: every
/// face's area and flux, and the volume, of these parts agree with a direct quadrature in
/// [`bspline_parts_against_direct_quadrature`].
const QUADRATURE: &str = "FreeCAD's B-spline figures off (ours agree with direct quadrature)";
/// FreeCAD's area of the revolution is 1e-5 off (its IGES 1.3e-5); ours agree with exact
/// rationals and Pappus in [`revolve_bspline_against_exact_rationals`].
const REVOLVE: &str = "FreeCAD's area off by 1e-5 (ours agree with exact rationals)";

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
                    exact &=
                        exact_pcurve(&face.surface, None, &e.curve, e.range, e.tolerance).is_some();
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
            // IGES 144 faces carry no orientation: sewing turns each closed shell outward,
            // so its volume is positive like every other's.
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

/// Gauss-Legendre nodes and weights on `[0, 1]`, by Newton's method on the Legendre
/// polynomial `P_n` (three-term recurrence): the test's own rule, independent of the
/// library's.
fn gauss_01(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as f64;
                (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / dp;
            x -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        out.push((0.5 * (1.0 - x), 1.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// The distinct knots of `knots` inside `(a, b)`, with `a` and `b`: the polynomial pieces.
fn pieces(knots: &[f64], (a, b): (f64, f64)) -> Vec<f64> {
    let mut out = vec![a];
    for &k in knots {
        if k > a && k < b && k > *out.last().unwrap() {
            out.push(k);
        }
    }
    out.push(b);
    out
}

/// Each polynomial piece cut in `CUTS` cells, a `RULE`-point rule in each.
const CUTS: usize = 8;
const RULE: usize = 24;

/// `f(S, S_u × S_v)` summed over the surface's whole domain with weights: each knot span
/// cut in `CUTS` × `CUTS` cells, the tensor `RULE`-point rule in each.
fn over_domain(s: &nurbsx::nurbs::NurbsSurface, mut f: impl FnMut([f64; 3], [f64; 3], f64)) {
    let g = gauss_01(RULE);
    let (du, dv) = s.domain();
    let cells = |b: Vec<f64>| -> Vec<(f64, f64)> {
        b.windows(2)
            .flat_map(|w| {
                let h = (w[1] - w[0]) / CUTS as f64;
                (0..CUTS).map(move |c| (w[0] + c as f64 * h, h))
            })
            .collect()
    };
    let (us, vs) = (
        cells(pieces(s.knots_u(), du)),
        cells(pieces(s.knots_v(), dv)),
    );
    for &(u0, hu) in &us {
        for &(v0, hv) in &vs {
            for &(x, wx) in &g {
                for &(y, wy) in &g {
                    let d = s.derivatives(u0 + x * hu, v0 + y * hv, 1).unwrap();
                    f(d[0][0], cross(d[1][0], d[0][1]), wx * wy * hu * hv);
                }
            }
        }
    }
}

/// `(area, flux)` of a face over its surface's whole domain, `∫∫ |S_u × S_v|` and
/// `∫∫ S · (S_u × S_v)` ([`over_domain`]): a direct quadrature of the surface, not the
/// boundary integral of `topology::measure`.
fn whole_domain(s: &nurbsx::nurbs::NurbsSurface) -> (f64, f64) {
    let (mut area, mut flux) = (0.0, 0.0);
    over_domain(s, |p, c, w| {
        area += w * norm(c);
        flux += w * dot(p, c);
    });
    (area, flux)
}

/// `(area, flux)` of a planar face from its boundary alone: the vector area
/// `½ ∮ p × dp` of its loops (each coedge walked its way, every knot span of its curve
/// cut and integrated by the rule), measured along the plane's normal `S_u × S_v`; the
/// flux is the plane's offset `S(0,0) · n` times the area.
fn planar(m: &nurbsx::topology::Model, face: &nurbsx::topology::Face) -> (f64, f64) {
    let g = gauss_01(RULE);
    let s = &face.surface;
    let ((u0, _), (v0, _)) = s.domain();
    let d = s.derivatives(u0, v0, 1).unwrap();
    let n = cross(d[1][0], d[0][1]);
    let n = n.map(|x| x / norm(n));
    let mut vector = [0.0; 3];
    for l in &face.loops {
        for c in &l.coedges {
            let e = &m.edges[c.edge.0];
            let sign = if c.forward { 0.5 } else { -0.5 };
            let b = pieces(e.curve.knots(), e.range);
            for w in b.windows(2) {
                let h = (w[1] - w[0]) / CUTS as f64;
                for k in 0..CUTS {
                    for &(x, wx) in &g {
                        let t = w[0] + (k as f64 + x) * h;
                        let d = e.curve.derivatives(t, 1).unwrap();
                        let pxd = cross(d[0], d[1]);
                        for i in 0..3 {
                            vector[i] += sign * wx * h * pxd[i];
                        }
                    }
                }
            }
        }
    }
    let area = dot(vector, n).abs();
    (area, dot(d[0][0], n) * area)
}

/// `∫∫ ½ (x, y, 0) · (S_u × S_v)` over a surface's whole domain ([`over_domain`]): the flux of a field of divergence 1 that has none through horizontal
/// planes, so over the side faces of a solid closed by horizontal caps it is ± its volume
/// whatever the faces' orientation flags say.
fn horizontal_flux(s: &nurbsx::nurbs::NurbsSurface) -> f64 {
    let mut flux = 0.0;
    over_domain(s, |p, c, w| flux += w * 0.5 * (p[0] * c[0] + p[1] * c[1]));
    flux
}

/// The B-spline parts whose area or volume FreeCAD gives apart from ours ([`FREECAD_OFF`]):
/// each face measured a second way, independent of the pcurves and of the Green's theorem
/// boundary integral: a plane from its 3-D boundary curves ([`planar`]), any other face
/// over its surface's whole domain ([`whole_domain`]; these parts' curved faces are whole
/// surfaces, so the two must agree). Area and flux of every face within 1e-10 of the
/// part's figures. The volume, within 1e-10: the loft's (closed by two horizontal caps) as
/// the side faces' [`horizontal_flux`], which needs no orientation; the others' as a third
/// of the faces' fluxes, each signed by the face's orientation: among every choice of
/// signs the one nearest FreeCAD's volume, and clearly nearer than any other (FreeCAD's
/// figure settles the orientation, the quadrature the value). The revolution's volume is
/// also checked in [`revolve_bspline_against_exact_rationals`], which alone checks
/// `revolve_bspline_270_brep.igs`: its cylinder is a 270° trim of a whole one.
#[test]
fn bspline_parts_against_direct_quadrature() {
    let mut checked = 0;
    for (part, name) in files() {
        let parts = [
            "loft_bspline",
            "sweep_circle_bspline",
            "revolve_bspline_270",
        ];
        if !parts.contains(&part.as_str()) || name == "revolve_bspline_270_brep.igs" {
            continue;
        }
        let doc = read(&name);
        let m = &doc.topology.model;
        let mm = doc.units.to_mm();
        let (mut total, mut direct_total) = (0.0, 0.0);
        let mut scale_flux = 0.0f64;
        let mut rows = Vec::new();
        for (f, face) in m.faces.iter().enumerate() {
            let ours = m.measure_face(face).unwrap();
            let g = face.surface.control_points();
            let p = *g.get(0, 0);
            let n0 = cross(sub(*g.get(1, 0), p), sub(*g.get(0, 1), p));
            let flat =
                g.as_slice().iter().all(|q| {
                    dot(sub(*q, p), n0).abs() <= 1e-12 * norm(n0) * (1.0 + norm(sub(*q, p)))
                }) && face.surface.degree_u() == 1
                    && face.surface.degree_v() == 1;
            let (area, flux) = if flat {
                planar(m, face)
            } else {
                whole_domain(&face.surface)
            };
            total += ours.area;
            direct_total += area;
            scale_flux = scale_flux.max(flux.abs());
            rows.push((f, flat, ours.area, area, ours.flux, flux));
        }
        let json = reading(&name);
        let freecad = json["totals"]["area"].as_f64().unwrap() / (mm * mm);
        eprintln!(
            "{name}: area {total} (direct {direct_total}, FreeCAD {freecad}: {:e} relative)",
            (freecad - direct_total) / direct_total
        );
        let fluxes: Vec<f64> = rows.iter().map(|r| r.5).collect();
        for (f, flat, a, da, x, dx) in rows {
            assert!(
                (a - da).abs() <= 1e-10 * direct_total,
                "{name} face {f} (plane: {flat}): area {a} vs direct {da}"
            );
            assert!(
                (x - dx).abs() <= 1e-10 * scale_flux,
                "{name} face {f} (plane: {flat}): flux {x} vs direct {dx}"
            );
        }
        let step = reading(&format!("{part}.step"));
        let want = step["solids"][0]["volume"].as_f64().unwrap() / (mm * mm * mm);
        assert_eq!(m.solids.len(), 1, "{name}");
        let v = m.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
        if part == "loft_bspline" {
            let sides: Vec<f64> = m
                .faces
                .iter()
                .filter(|f| f.surface.degree_u() > 1 || f.surface.degree_v() > 1)
                .map(|f| horizontal_flux(&f.surface))
                .collect();
            assert_eq!(sides.len(), 3, "{name}");
            assert!(
                sides.iter().all(|x| x.signum() == sides[0].signum()),
                "{sides:?}"
            );
            let direct = sides.iter().sum::<f64>().abs();
            assert!(
                (v - direct).abs() <= 1e-10 * direct,
                "{name}: volume {v} vs direct {direct}"
            );
            eprintln!(
                "{name}: volume {v} (direct {direct}, FreeCAD {want}: {:e} relative)",
                (want - direct) / direct
            );
            checked += 1;
            continue;
        }
        // Every signed sum of the direct fluxes, nearest FreeCAD's volume first.
        let mut sums: Vec<f64> = (0..1u32 << fluxes.len())
            .map(|signs| {
                let signed = fluxes
                    .iter()
                    .enumerate()
                    .map(|(i, x)| if signs >> i & 1 == 1 { -x } else { *x });
                signed.sum::<f64>() / 3.0
            })
            .collect();
        sums.sort_by(|a, b| (a - want).abs().total_cmp(&(b - want).abs()));
        let nearest = sums[0];
        let other = sums
            .iter()
            .find(|v| (*v - nearest).abs() > 1e-9 * want)
            .unwrap();
        assert!(
            (other - want).abs() > 100.0 * (nearest - want).abs(),
            "{name}: FreeCAD's volume {want} does not settle the orientation ({nearest}, {other})"
        );
        assert!(
            (v - nearest).abs() <= 1e-10 * nearest,
            "{name}: volume {v} vs direct {nearest}"
        );
        eprintln!(
            "{name}: volume {v} (direct {nearest}, FreeCAD {want}: {:e} relative)",
            (want - nearest) / nearest
        );
        checked += 1;
    }
    assert_eq!(checked, 8);
}

/// `revolve_bspline_270.step`: the region between the cubic B-spline `#34` (poles (r, z) =
/// (10, 0), (16, 6), (9, 14), (15, 22), (10, 30), knots 0⁴ ½ 1⁴ in the XZ plane), the line
/// r = 4 and the planes z = 0 and z = 30, revolved 270° about z. In exact rationals from the
/// profile's two Bezier spans (knot ½ inserted twice, Boehm): the profile's area
/// `∫ r dz - 4·30 = 10089/40` (each end face), and `∫∫ r dA = ½ ∫ r² dz - 16·30/2 =
/// 133077/64`, so by Pappus the volume is `(3π/2) · 133077/64`. The area adds the revolved
/// profile `(3π/2) ∫ r |p'| dt` (composite Simpson, 20 000 intervals a span), the two
/// annular caps `(3π/4)(10² - 4²)` and the cylinder `(3π/2)·4·30`. All three files of the
/// part must give these within 1e-10 (sewn IGES volumes by size); FreeCAD gives the area
/// 1.0e-5 and the volume 9.5e-7 off.
#[test]
fn revolve_bspline_against_exact_rationals() {
    use num_rational::BigRational as Q;
    use num_traits::ToPrimitive;
    let q = |n: i64, d: i64| Q::new(n.into(), d.into());
    let poles: Vec<[Q; 2]> = [(10, 0), (16, 6), (9, 14), (15, 22), (10, 30)]
        .iter()
        .map(|&(r, z)| [q(r, 1), q(z, 1)])
        .collect();
    // Insert ½ twice into 0 0 0 0 ½ 1 1 1 1 (NURBS Book A5.1): the 7 Bezier poles.
    let mut knots: Vec<Q> = [0, 0, 0, 0, 1, 2, 2, 2, 2]
        .iter()
        .map(|&k| q(k, 2))
        .collect();
    let mut p = poles;
    for _ in 0..2 {
        let u = q(1, 2);
        let k = (0..knots.len() - 1)
            .rfind(|&i| knots[i] <= u && u < knots[i + 1])
            .unwrap();
        let mut next = Vec::with_capacity(p.len() + 1);
        for i in 0..=p.len() {
            if i + 3 <= k {
                next.push(p[i].clone());
            } else if i > k {
                next.push(p[i - 1].clone());
            } else {
                let a = (u.clone() - knots[i].clone()) / (knots[i + 3].clone() - knots[i].clone());
                next.push([0, 1].map(|j| {
                    (q(1, 1) - a.clone()) * p[i - 1][j].clone() + a.clone() * p[i][j].clone()
                }));
            }
        }
        p = next;
        knots.insert(k + 1, u);
    }
    assert_eq!(p.len(), 7);
    // Power basis of a cubic Bezier span: coefficient d of axis j.
    const M: [[i64; 4]; 4] = [[1, 0, 0, 0], [-3, 3, 0, 0], [3, -6, 3, 0], [-1, 3, -3, 1]];
    let (mut profile, mut moment) = (q(0, 1), q(0, 1));
    let mut lateral = 0.0;
    for span in [&p[0..4], &p[3..7]] {
        let coef = |j: usize| -> Vec<Q> {
            (0..4)
                .map(|d| (0..4).fold(q(0, 1), |s, k| s + q(M[d][k], 1) * span[k][j].clone()))
                .collect()
        };
        let (r, z) = (coef(0), coef(1));
        // ∫_0^1 t^a t^b t^(c-1) c dt = c / (a + b + c).
        for (c, z_c) in z.iter().enumerate().skip(1) {
            let zc = z_c.clone() * q(c as i64, 1);
            for (a, r_a) in r.iter().enumerate() {
                profile += r_a.clone() * zc.clone() / q((a + c) as i64, 1);
                for (b, r_b) in r.iter().enumerate() {
                    moment += r_a.clone() * r_b.clone() * zc.clone() / q(2 * (a + b + c) as i64, 1);
                }
            }
        }
        let f = |t: f64| {
            let at = |c: &[Q], d: usize| -> f64 {
                (d..4)
                    .map(|i| {
                        let k = (i - d + 1..=i).product::<usize>() as f64;
                        k * c[i].to_f64().unwrap() * t.powi((i - d) as i32)
                    })
                    .sum()
            };
            at(&r, 0) * at(&r, 1).hypot(at(&z, 1))
        };
        let n = 20_000;
        let h = 1.0 / n as f64;
        let mut sum = f(0.0) + f(1.0);
        for j in 1..n {
            sum += if j % 2 == 1 { 4.0 } else { 2.0 } * f(j as f64 * h);
        }
        lateral += sum * h / 3.0;
    }
    profile -= q(4 * 30, 1);
    moment -= q(16 * 30, 2);
    assert_eq!(profile, q(10089, 40));
    assert_eq!(moment, q(133077, 64));
    let theta = 1.5 * std::f64::consts::PI;
    let volume = theta * moment.to_f64().unwrap();
    let area = theta * lateral
        + 2.0 * (theta / 2.0) * (100.0 - 16.0)
        + theta * 4.0 * 30.0
        + 2.0 * profile.to_f64().unwrap();
    for name in [
        "revolve_bspline_270.step",
        "revolve_bspline_270.igs",
        "revolve_bspline_270_brep.igs",
    ] {
        let m = &read(name).topology.model;
        let measured: f64 = m
            .faces
            .iter()
            .map(|f| m.measure_face(f).unwrap().area)
            .sum();
        assert!(
            (measured - area).abs() <= 1e-10 * area,
            "{name}: area {measured} vs {area}"
        );
        assert_eq!(m.solids.len(), 1, "{name}");
        let v = m.solid_volume(nurbsx::topology::SolidId(0)).unwrap();
        assert!(
            (v - volume).abs() <= 1e-10 * volume,
            "{name}: volume {v} vs {volume}"
        );
    }
}
