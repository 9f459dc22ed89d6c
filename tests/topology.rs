//! The topology layer's checked constructors on a cube built by hand (vertices, line edges,
//! plane faces with exact pcurves): closure of loops, vertex/edge/pcurve agreement, closed
//! shells by the oriented-edge condition (cross-checked with Euler's V - E + F = 2),
//! solids, and assemblies flattened without recursion.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::HashMap;

use nurbsx::nurbs::conic::line_segment;
use nurbsx::nurbs::sweep::{self, Frame};
use nurbsx::nurbs::transform::{Affine, apply};
use nurbsx::nurbs::{NurbsCurve, Point3};
use nurbsx::topology::{
    Assembly, Coedge, EdgeId, FaceId, Instance, Loop, Model, Part, TopologyError, VertexId,
};

const A: f64 = 3.5;

fn unit(k: usize) -> Point3 {
    let mut e = [0.0; 3];
    e[k % 3] = 1.0;
    e
}

fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

struct Cube {
    model: Model,
    faces: Vec<FaceId>,
    vertices: Vec<VertexId>,
}

/// Corner `bits` (x = bit 0, y = bit 1, z = bit 2) of the cube [0, A]^3.
fn corner(bits: usize) -> Point3 {
    std::array::from_fn(|k| if bits >> k & 1 == 1 { A } else { 0.0 })
}

fn bits_of(p: Point3) -> usize {
    (0..3).map(|k| usize::from(p[k] > 0.5 * A) << k).sum()
}

/// The cube with outward faces: face (k, s) has normal (2s - 1) e_k, frame x, y with
/// x cross y = that normal, and its loop runs counter-clockwise about it. `shift` moves the
/// pcurves of the first face off their edges.
fn cube(shift: f64) -> Result<Cube, TopologyError> {
    let mut model = Model::new();
    let vertices: Vec<VertexId> = (0..8)
        .map(|b| model.add_vertex(corner(b), 1e-9).unwrap())
        .collect();
    let mut edges: HashMap<(usize, usize), EdgeId> = HashMap::new();
    let mut faces = Vec::new();
    for k in 0..3 {
        for s in 0..2 {
            let (x, y) = if s == 1 {
                (unit(k + 1), unit(k + 2))
            } else {
                (unit(k + 2), unit(k + 1))
            };
            let mut origin = [0.0; 3];
            origin[k] = s as f64 * A;
            let frame = Frame {
                origin,
                x,
                y,
                z: if s == 1 {
                    unit(k)
                } else {
                    [-unit(k)[0], -unit(k)[1], -unit(k)[2]]
                },
            };
            let surface = sweep::plane(&frame, (0.0, A), (0.0, A)).unwrap();
            let uv = [[0.0, 0.0], [A, 0.0], [A, A], [0.0, A]];
            let at = |q: [f64; 2]| -> Point3 {
                std::array::from_fn(|c| origin[c] + q[0] * x[c] + q[1] * y[c])
            };
            let mut coedges = Vec::new();
            for i in 0..4 {
                let (pa, pb) = (uv[i], uv[(i + 1) % 4]);
                let (ba, bb) = (bits_of(at(pa)), bits_of(at(pb)));
                let key = (ba.min(bb), ba.max(bb));
                let edge = *edges.entry(key).or_insert_with(|| {
                    let c = line_segment(corner(key.0), corner(key.1), 0.0, 1.0).unwrap();
                    model
                        .add_edge(c, (0.0, 1.0), vertices[key.0], vertices[key.1], 1e-9)
                        .unwrap()
                });
                let forward = ba == key.0;
                // The pcurve runs like the edge's curve: from the edge's start to its end.
                let (from, to) = if forward { (pa, pb) } else { (pb, pa) };
                let off = if faces.is_empty() { shift } else { 0.0 };
                let pcurve = NurbsCurve::with_dimension(
                    1,
                    vec![0.0, 0.0, 1.0, 1.0],
                    vec![[from[0] + off, from[1], 0.0], [to[0] + off, to[1], 0.0]],
                    None,
                    2,
                )
                .unwrap();
                coedges.push(Coedge {
                    edge,
                    forward,
                    pcurve: Some(pcurve),
                    pcurve_deviation: None,
                });
            }
            let lp = Loop {
                coedges,
                outer: true,
            };
            faces.push(model.add_face(surface, vec![lp], true)?);
        }
    }
    Ok(Cube {
        model,
        faces,
        vertices,
    })
}

#[test]
fn a_cube_is_a_closed_shell_and_a_solid() {
    let mut c = cube(0.0).unwrap();
    let m = &c.model;
    // Euler: V - E + F = 2 for a closed genus-0 shell, counted independently of the check.
    assert_eq!(
        m.vertices.len() as i64 - m.edges.len() as i64 + m.faces.len() as i64,
        2
    );
    // Every exact pcurve agrees with its edge to rounding.
    for f in &m.faces {
        for cd in &f.loops[0].coedges {
            assert!(cd.pcurve_deviation.unwrap() <= 1e-15 * A);
        }
        // Outward: the surface normal at the middle points away from the centre.
        let n = f.surface.normal(0.5 * A, 0.5 * A).unwrap();
        let p = f.surface.point_at(0.5 * A, 0.5 * A).unwrap();
        let out = [p[0] - 0.5 * A, p[1] - 0.5 * A, p[2] - 0.5 * A];
        assert!(dot(n, out) > 0.0);
    }
    let all: Vec<_> = c.faces.iter().map(|&f| (f, true)).collect();
    let shell = c.model.add_shell(all, true).unwrap();
    assert!(c.model.shells[shell.0].closed);
    let solid = c.model.add_solid(shell, vec![]).unwrap();
    // Measured over the trimmed regions: each face A^2 with its centre as centroid, the
    // volume A^3 (closed forms).
    for f in &c.model.faces {
        let m = c.model.measure_face(f).unwrap();
        assert!((m.area - A * A).abs() <= 1e-12 * A * A, "{}", m.area);
        let mid = f.surface.point_at(0.5 * A, 0.5 * A).unwrap();
        assert!(dist(m.centroid, mid) <= 1e-12 * A, "{:?}", m.centroid);
    }
    let v = c.model.solid_volume(solid).unwrap();
    assert!((v - A * A * A).abs() <= 1e-12 * A * A * A, "{v}");
}

fn dist(a: Point3, b: Point3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A closed cylinder: the lateral face (a full turn with its seam edge used twice, pcurves
/// exact iso-lines) and two disks (planes trimmed by the circles, pcurves by projection).
/// Area 2 pi r h + 2 pi r^2, volume pi r^2 h, lateral centroid on the axis at mid-height:
/// the closed forms, through the seam and the trimmed planes.
#[test]
fn a_cylinder_solid_measures_as_the_closed_forms() {
    use nurbsx::nurbs::conic::{ConicKind, conic_arc};
    use nurbsx::nurbs::project::pcurve_by_projection;
    use std::f64::consts::PI;
    let (r, h) = (1.3, 2.1);
    let o = [0.4, -0.2, 0.7];
    let z = Frame {
        origin: o,
        x: [1.0, 0.0, 0.0],
        y: [0.0, 1.0, 0.0],
        z: [0.0, 0.0, 1.0],
    };
    let (lateral, _) = sweep::cylinder(&z, r, (0.0, 2.0 * PI), (0.0, h)).unwrap();
    let ((u0, u1), _) = lateral.domain();
    let mut m = Model::new();
    let at = |k: f64| [o[0] + r, o[1], o[2] + k];
    let (vb, vt) = (
        m.add_vertex(at(0.0), 1e-9).unwrap(),
        m.add_vertex(at(h), 1e-9).unwrap(),
    );
    let circle = |k: f64| {
        conic_arc(
            ConicKind::Elliptic,
            [o[0], o[1], o[2] + k],
            [r, 0.0, 0.0],
            [0.0, r, 0.0],
            0.0,
            2.0 * PI,
        )
        .unwrap()
        .0
    };
    let (cb, ct) = (circle(0.0), circle(h));
    let dom = cb.domain();
    let eb = m.add_edge(cb.clone(), dom, vb, vb, 1e-9).unwrap();
    let et = m.add_edge(ct.clone(), dom, vt, vt, 1e-9).unwrap();
    let seam_curve = line_segment(at(0.0), at(h), 0.0, h).unwrap();
    let es = m.add_edge(seam_curve, (0.0, h), vb, vt, 1e-9).unwrap();
    let line2 = |a: [f64; 2], b: [f64; 2], t: (f64, f64)| {
        NurbsCurve::with_dimension(
            1,
            vec![t.0, t.0, t.1, t.1],
            vec![[a[0], a[1], 0.0], [b[0], b[1], 0.0]],
            None,
            2,
        )
        .unwrap()
    };
    let co = |edge, forward, pcurve| Coedge {
        edge,
        forward,
        pcurve: Some(pcurve),
        pcurve_deviation: None,
    };
    // The circles share the cylinder's angle map (both A7.1 over [0, 2 pi]): their
    // pcurves are the iso-lines v = 0 and v = h with u = t; the add_face check proves it.
    let lateral_loop = Loop {
        coedges: vec![
            co(eb, true, line2([dom.0, 0.0], [dom.1, 0.0], dom)),
            co(es, true, line2([u1, 0.0], [u1, h], (0.0, h))),
            co(et, false, line2([dom.0, h], [dom.1, h], dom)),
            co(es, false, line2([u0, 0.0], [u0, h], (0.0, h))),
        ],
        outer: true,
    };
    let fl = m.add_face(lateral, vec![lateral_loop], true).unwrap();
    let mut disk = |k: f64, up: bool, edge, curve: &NurbsCurve| {
        let frame = Frame {
            origin: [o[0], o[1], o[2] + k],
            x: if up { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] },
            y: if up { [0.0, 1.0, 0.0] } else { [1.0, 0.0, 0.0] },
            z: [0.0, 0.0, if up { 1.0 } else { -1.0 }],
        };
        let s = sweep::plane(&frame, (-2.0, 2.0), (-2.0, 2.0)).unwrap();
        let (pc, dev) = pcurve_by_projection(&s, curve, dom, 1e-9).unwrap();
        assert!(dev <= 1e-9);
        let l = Loop {
            coedges: vec![co(edge, up, pc)],
            outer: true,
        };
        m.add_face(s, vec![l], true).unwrap()
    };
    let fb = disk(0.0, false, eb, &cb);
    let ft = disk(h, true, et, &ct);
    let shell = m
        .add_shell(vec![(fl, true), (fb, true), (ft, true)], true)
        .unwrap();
    let solid = m.add_solid(shell, vec![]).unwrap();
    let lat = m.measure_face(&m.faces[fl.0]).unwrap();
    assert!(
        (lat.area - 2.0 * PI * r * h).abs() <= 1e-10 * lat.area,
        "{}",
        lat.area
    );
    let axis_mid = [o[0], o[1], o[2] + 0.5 * h];
    assert!(dist(lat.centroid, axis_mid) <= 1e-10, "{:?}", lat.centroid);
    for f in [fb, ft] {
        let d = m.measure_face(&m.faces[f.0]).unwrap();
        assert!((d.area - PI * r * r).abs() <= 1e-8 * d.area, "{}", d.area);
    }
    let v = m.solid_volume(solid).unwrap();
    assert!(
        (v - PI * r * r * h).abs() <= 1e-8 * v,
        "{v} vs {}",
        PI * r * r * h
    );
}

/// A square plate with a round hole: area 16 - pi r^2 whichever way the hole's loop runs,
/// centroid at the centre (symmetric), and an unknown region (no pcurve) is refused.
#[test]
fn a_plate_with_a_hole() {
    use nurbsx::nurbs::conic::{ConicKind, conic_arc};
    use nurbsx::nurbs::project::pcurve_by_projection;
    use std::f64::consts::PI;
    let z = Frame {
        origin: [0.0; 3],
        x: [1.0, 0.0, 0.0],
        y: [0.0, 1.0, 0.0],
        z: [0.0, 0.0, 1.0],
    };
    let plane = sweep::plane(&z, (-1.0, 5.0), (-1.0, 5.0)).unwrap();
    let mut m = Model::new();
    let corners = [
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [4.0, 4.0, 0.0],
        [0.0, 4.0, 0.0],
    ];
    let vs: Vec<VertexId> = corners
        .iter()
        .map(|&p| m.add_vertex(p, 1e-9).unwrap())
        .collect();
    let mut outer = Vec::new();
    for i in 0..4 {
        let (a, b) = (corners[i], corners[(i + 1) % 4]);
        let c = line_segment(a, b, 0.0, 1.0).unwrap();
        let (pc, _) = pcurve_by_projection(&plane, &c, (0.0, 1.0), 1e-10).unwrap();
        let e = m
            .add_edge(c, (0.0, 1.0), vs[i], vs[(i + 1) % 4], 1e-9)
            .unwrap();
        outer.push(Coedge {
            edge: e,
            forward: true,
            pcurve: Some(pc),
            pcurve_deviation: None,
        });
    }
    let r = 1.0;
    let (hole, _) = conic_arc(
        ConicKind::Elliptic,
        [2.0, 2.0, 0.0],
        [r, 0.0, 0.0],
        [0.0, r, 0.0],
        0.0,
        2.0 * PI,
    )
    .unwrap();
    let vh = m.add_vertex([3.0, 2.0, 0.0], 1e-9).unwrap();
    let dom = hole.domain();
    let (pc, _) = pcurve_by_projection(&plane, &hole, dom, 1e-9).unwrap();
    let eh = m.add_edge(hole, dom, vh, vh, 1e-9).unwrap();
    for forward in [false, true] {
        let loops = vec![
            Loop {
                coedges: outer.clone(),
                outer: true,
            },
            Loop {
                coedges: vec![Coedge {
                    edge: eh,
                    forward,
                    pcurve: Some(pc.clone()),
                    pcurve_deviation: None,
                }],
                outer: false,
            },
        ];
        let f = m.add_face(plane.clone(), loops, true).unwrap();
        let got = m.measure_face(&m.faces[f.0]).unwrap();
        let want = 16.0 - PI * r * r;
        assert!(
            (got.area - want).abs() <= 1e-9 * want,
            "{} vs {want}",
            got.area
        );
        assert!(
            dist(got.centroid, [2.0, 2.0, 0.0]) <= 1e-9,
            "{:?}",
            got.centroid
        );
    }
    let mut bare = m.faces[0].clone();
    bare.loops[1].coedges[0].pcurve = None;
    assert!(m.measure_face(&bare).is_err());

    // Splitting the hole's edge (used by both faces, once each way) keeps every face whole:
    // two coedges in the order each loop runs, pcurves cut at the same parameter and still
    // on the 3-D curve, the loops closed through the new vertex, the same area.
    let (edges, vertices) = (m.edges.len(), m.vertices.len());
    assert!(m.split_edge(eh, dom.1 + 1.0).is_err());
    assert!(m.split_edge(eh, dom.0).is_err());
    assert_eq!((m.edges.len(), m.vertices.len()), (edges, vertices));
    let t = dom.0 + 0.37 * (dom.1 - dom.0);
    let (mid, second) = m.split_edge(eh, t).unwrap();
    assert_eq!((m.edges.len(), m.vertices.len()), (edges + 1, vertices + 1));
    assert!(
        dist(
            m.vertices[mid.0].point,
            m.edges[eh.0].curve.point_at(t).unwrap()
        ) == 0.0
    );
    assert_eq!(m.edges[eh.0].range, (dom.0, t));
    assert_eq!(m.edges[second.0].range, (t, dom.1));
    for face in m.faces.clone() {
        let hole = &face.loops[1].coedges;
        assert_eq!(hole.len(), 2);
        let ends: Vec<_> = hole.iter().map(|c| m.coedge_ends(c).unwrap()).collect();
        assert_eq!(ends[0].1, ends[1].0);
        assert_eq!(ends[1].1, ends[0].0);
        for c in hole {
            let e = &m.edges[c.edge.0];
            let p = c.pcurve.as_ref().unwrap();
            for k in 0..=10 {
                let s = e.range.0 + (e.range.1 - e.range.0) * k as f64 / 10.0;
                let [u, v, _] = p.point_at(s).unwrap();
                let on = face.surface.point_at(u, v).unwrap();
                assert!(dist(on, e.curve.point_at(s).unwrap()) <= 1e-9);
            }
        }
        let again = m
            .add_face(face.surface.clone(), face.loops.clone(), true)
            .unwrap();
        let got = m.measure_face(&m.faces[again.0]).unwrap();
        let want = 16.0 - PI * r * r;
        assert!(
            (got.area - want).abs() <= 1e-9 * want,
            "{} vs {want}",
            got.area
        );
    }
}

#[test]
fn open_or_misoriented_shells_are_named() {
    let mut c = cube(0.0).unwrap();
    let five: Vec<_> = c.faces[..5].iter().map(|&f| (f, true)).collect();
    match c.model.add_shell(five.clone(), true) {
        Err(TopologyError::ShellNotClosed { count, .. }) => assert_eq!(count, 4),
        other => panic!("{other:?}"),
    }
    let open = c.model.add_shell(five, false).unwrap();
    assert!(!c.model.shells[open.0].closed);
    assert!(matches!(
        c.model.add_solid(open, vec![]),
        Err(TopologyError::SolidShellOpen { .. })
    ));
    let mut flipped: Vec<_> = c.faces.iter().map(|&f| (f, true)).collect();
    flipped[2].1 = false;
    match c.model.add_shell(flipped, true) {
        Err(TopologyError::ShellNotClosed { count, .. }) => assert_eq!(count, 4),
        other => panic!("{other:?}"),
    }
}

#[test]
fn loops_edges_and_pcurves_are_checked() {
    // A pcurve 0.01 off its edge is refused with the deviation found.
    match cube(0.01) {
        Err(TopologyError::PcurveDeviates { deviation, .. }) => {
            assert!((deviation - 0.01).abs() < 1e-12, "{deviation}")
        }
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("the shifted pcurve must be refused"),
    }
    let mut c = cube(0.0).unwrap();
    // A deviation measured where the pcurve was made is compared with the edge's tolerance
    // (not sampled again): above it, the face is refused with that deviation; within it,
    // the face is added and keeps it.
    let f0 = c.model.faces[c.faces[0].0].clone();
    let tolerance = c.model.edges[f0.loops[0].coedges[0].edge.0].tolerance;
    for (given, accepted) in [(2.0 * tolerance, false), (0.5 * tolerance, true)] {
        let mut loops = f0.loops.clone();
        loops[0].coedges[0].pcurve_deviation = Some(given);
        match c.model.add_face(f0.surface.clone(), loops, f0.same_sense) {
            Ok(f) if accepted => assert_eq!(
                c.model.faces[f.0].loops[0].coedges[0].pcurve_deviation,
                Some(given)
            ),
            Err(TopologyError::PcurveDeviates { deviation, .. }) if !accepted => {
                assert_eq!(deviation, given)
            }
            other => panic!("{given}: {other:?}"),
        }
    }
    // A loop whose edges do not chain: two opposite edges of the bottom face.
    let f0 = &c.model.faces[c.faces[0].0];
    let (a, b) = (
        f0.loops[0].coedges[0].clone(),
        f0.loops[0].coedges[2].clone(),
    );
    let surface = f0.surface.clone();
    let bad = Loop {
        coedges: vec![a, b],
        outer: true,
    };
    assert!(matches!(
        c.model.add_face(surface.clone(), vec![bad], true),
        Err(TopologyError::LoopOpen { coedge: 0, .. })
    ));
    assert!(matches!(
        c.model.add_face(
            surface,
            vec![Loop {
                coedges: vec![],
                outer: true
            }],
            true
        ),
        Err(TopologyError::LoopOpen { .. })
    ));
    // An edge whose curve misses its end vertex by 1e-3.
    let v = c.model.add_vertex([A, 1e-3, 0.0], 1e-9).unwrap();
    let curve = line_segment([0.0; 3], [A, 0.0, 0.0], 0.0, 1.0).unwrap();
    match c
        .model
        .add_edge(curve.clone(), (0.0, 1.0), c.vertices[0], v, 1e-7)
    {
        Err(TopologyError::EdgeMissesVertex { distance, end, .. }) => {
            assert_eq!(end, "end");
            assert!((distance - 1e-3).abs() < 1e-12);
        }
        other => panic!("{other:?}"),
    }
    // A range outside the curve's domain, and a missing vertex.
    assert!(matches!(
        c.model.add_edge(
            curve.clone(),
            (0.0, 1.5),
            c.vertices[0],
            c.vertices[1],
            1e-7
        ),
        Err(TopologyError::EdgeRange { .. })
    ));
    assert!(matches!(
        c.model
            .add_edge(curve, (0.0, 1.0), c.vertices[0], VertexId(99), 1e-7),
        Err(TopologyError::Missing { what: "vertex", .. })
    ));
}

fn translate(t: Point3) -> Affine {
    [
        [1.0, 0.0, 0.0, t[0]],
        [0.0, 1.0, 0.0, t[1]],
        [0.0, 0.0, 1.0, t[2]],
    ]
}

fn rot_z(t: f64) -> Affine {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0, 0.0], [s, c, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]
}

#[test]
fn assemblies_compose_placements_and_refuse_cycles() {
    let c = cube(0.0).unwrap();
    let mut m = c.model;
    let all: Vec<_> = c.faces.iter().map(|&f| (f, true)).collect();
    let shell = m.add_shell(all, true).unwrap();
    let solid = m.add_solid(shell, vec![]).unwrap();
    let inst = |placement, part| Instance {
        name: None,
        placement,
        part,
    };
    let sub = m.add_assembly(Assembly {
        name: "pair".into(),
        instances: vec![
            inst(translate([10.0, 0.0, 0.0]), Part::Solid(solid)),
            inst(translate([0.0, 0.0, 5.0]), Part::Solid(solid)),
        ],
    });
    let top = m.add_assembly(Assembly {
        name: "top".into(),
        instances: vec![
            inst(rot_z(std::f64::consts::FRAC_PI_2), Part::Assembly(sub)),
            inst(translate([-1.0, -2.0, -3.0]), Part::Face(c.faces[0])),
        ],
    });
    let leaves = m.flatten(top, 8, 100).unwrap();
    assert_eq!(leaves.len(), 3);
    assert_eq!(leaves[0].path, vec![0, 0]);
    assert_eq!(leaves[1].path, vec![0, 1]);
    assert_eq!(leaves[2].path, vec![1]);
    // Independent: apply the placements one after the other to a point.
    let p = [1.0, 2.0, 3.0];
    let want = [
        apply(
            &rot_z(std::f64::consts::FRAC_PI_2),
            apply(&translate([10.0, 0.0, 0.0]), p),
        ),
        apply(
            &rot_z(std::f64::consts::FRAC_PI_2),
            apply(&translate([0.0, 0.0, 5.0]), p),
        ),
        apply(&translate([-1.0, -2.0, -3.0]), p),
    ];
    for (leaf, w) in leaves.iter().zip(want) {
        let got = apply(&leaf.placement, p);
        assert!(
            (0..3).all(|k| (got[k] - w[k]).abs() < 1e-13),
            "{got:?} vs {w:?}"
        );
    }
    // A cycle through two assemblies.
    let a = m.add_assembly(Assembly {
        name: "a".into(),
        instances: vec![],
    });
    let b = m.add_assembly(Assembly {
        name: "b".into(),
        instances: vec![inst(translate([0.0; 3]), Part::Assembly(a))],
    });
    m.assemblies[a.0]
        .instances
        .push(inst(translate([0.0; 3]), Part::Assembly(b)));
    assert!(matches!(
        m.flatten(a, 8, 100),
        Err(TopologyError::AssemblyCycle { .. })
    ));
    // A shared sub-assembly doubling at each of 30 levels stops at the instance limit,
    // quickly, instead of expanding 2^30 leaves.
    let mut level = m.add_assembly(Assembly {
        name: "leaf".into(),
        instances: vec![inst(translate([0.0; 3]), Part::Solid(solid))],
    });
    for _ in 0..30 {
        level = m.add_assembly(Assembly {
            name: "twice".into(),
            instances: vec![
                inst(translate([1.0, 0.0, 0.0]), Part::Assembly(level)),
                inst(translate([0.0, 1.0, 0.0]), Part::Assembly(level)),
            ],
        });
    }
    assert!(matches!(
        m.flatten(level, 64, 10_000),
        Err(TopologyError::AssemblyTooLarge {
            what: "instances",
            ..
        })
    ));
    assert!(matches!(
        m.flatten(level, 8, 10_000),
        Err(TopologyError::AssemblyTooLarge { what: "levels", .. })
    ));
}

/// The cube's six faces each with its own four vertices and edges (as an IGES file of 144
/// trimmed surfaces gives them). Face 0's edges run the other way round; face 1's edges are
/// parameterised non-uniformly (a degree-2 line whose speed varies), so sewing must
/// re-project its pcurves. Face 3 is described from the other side (`same_sense = false`,
/// loop reversed: the same face). `inward`: every face described from the other side, a
/// shell whose faces all point inwards. `skip` leaves faces out.
fn loose_cube(skip: &[usize], inward: bool) -> (Model, Vec<FaceId>) {
    let mut model = Model::new();
    let mut faces = Vec::new();
    let mut index = 0;
    for k in 0..3 {
        for s in 0..2 {
            let this = index;
            index += 1;
            if skip.contains(&this) {
                continue;
            }
            let (x, y) = if s == 1 {
                (unit(k + 1), unit(k + 2))
            } else {
                (unit(k + 2), unit(k + 1))
            };
            let mut origin = [0.0; 3];
            origin[k] = s as f64 * A;
            let z = if s == 1 {
                unit(k)
            } else {
                [-unit(k)[0], -unit(k)[1], -unit(k)[2]]
            };
            let frame = Frame { origin, x, y, z };
            let surface = sweep::plane(&frame, (0.0, A), (0.0, A)).unwrap();
            let uv = [[0.0, 0.0], [A, 0.0], [A, A], [0.0, A]];
            let at = |q: [f64; 2]| -> Point3 {
                std::array::from_fn(|c| origin[c] + q[0] * x[c] + q[1] * y[c])
            };
            let vs: Vec<VertexId> = uv
                .iter()
                .map(|&q| model.add_vertex(at(q), 1e-9).unwrap())
                .collect();
            let mut coedges = Vec::new();
            for i in 0..4 {
                let (a, b) = (i, (i + 1) % 4);
                // Face 0: each edge from b to a, used backwards.
                let (from, to, forward) = if this == 0 {
                    (b, a, false)
                } else {
                    (a, b, true)
                };
                let (pa, pb) = (uv[from], uv[to]);
                let curve = if this == 1 {
                    let (p0, p2) = (at(pa), at(pb));
                    // Middle pole off the midpoint: same segment, varying speed.
                    let p1: Point3 = std::array::from_fn(|c| p0[c] + 0.3 * (p2[c] - p0[c]));
                    NurbsCurve::new(2, vec![0., 0., 0., 2., 2., 2.], vec![p0, p1, p2], None)
                        .unwrap()
                } else {
                    line_segment(at(pa), at(pb), 0.0, 1.0).unwrap()
                };
                let range = curve.domain();
                let pcurve = if this == 1 {
                    let q = |p: [f64; 2]| [p[0], p[1], 0.0];
                    let m: [f64; 2] = std::array::from_fn(|c| pa[c] + 0.3 * (pb[c] - pa[c]));
                    NurbsCurve::with_dimension(
                        2,
                        vec![0., 0., 0., 2., 2., 2.],
                        vec![q(pa), q(m), q(pb)],
                        None,
                        2,
                    )
                    .unwrap()
                } else {
                    NurbsCurve::with_dimension(
                        1,
                        vec![0.0, 0.0, 1.0, 1.0],
                        vec![[pa[0], pa[1], 0.0], [pb[0], pb[1], 0.0]],
                        None,
                        2,
                    )
                    .unwrap()
                };
                let edge = model
                    .add_edge(curve, range, vs[from], vs[to], 1e-9)
                    .unwrap();
                coedges.push(Coedge {
                    edge,
                    forward,
                    pcurve: Some(pcurve),
                    pcurve_deviation: None,
                });
            }
            // Described from the other side: the normal (same_sense) and the loop flipped
            // together, as ISO 10303-42 ties the loop's direction to the face normal.
            let flipped = (this == 3) != inward;
            let same_sense = !flipped;
            if flipped {
                coedges.reverse();
                for c in &mut coedges {
                    c.forward = !c.forward;
                }
            }
            let lp = Loop {
                coedges,
                outer: true,
            };
            faces.push(model.add_face(surface, vec![lp], same_sense).unwrap());
        }
    }
    (model, faces)
}

/// Six loose faces sew into the cube: 8 vertices, 12 edges (each used once each way), one
/// closed shell, one solid of volume A^3 (outward, also when every loop came inside out),
/// whatever the edges' directions and parameterisations were; Euler V - E + F = 2.
#[test]
fn loose_faces_sew_into_a_solid() {
    for inward in [false, true] {
        sew_the_cube(inward);
    }
}

fn sew_the_cube(inward: bool) {
    let (mut m, faces) = loose_cube(&[], inward);
    assert_eq!((m.vertices.len(), m.edges.len()), (24, 24));
    let sewing = m.sew(std::slice::from_ref(&faces), 1e-7).unwrap();
    assert_eq!(sewing.merged_edges, 12);
    assert_eq!(sewing.lost_pcurves, 0);
    assert_eq!((m.vertices.len(), m.edges.len()), (8, 12));
    assert_eq!(
        m.vertices.len() as i64 - m.edges.len() as i64 + m.faces.len() as i64,
        2
    );
    assert!(sewing.open_edges.is_empty(), "{:?}", sewing.open_edges);
    assert_eq!(sewing.solids.len(), 1);
    assert!(m.shells[sewing.shells[0].0].closed);
    let v = m.solid_volume(sewing.solids[0]).unwrap();
    assert!((v - A * A * A).abs() <= 1e-12 * A * A * A, "{v}");
    // Every carried or re-projected pcurve still lies on its edge.
    for f in &m.faces {
        for c in &f.loops[0].coedges {
            assert!(
                c.pcurve_deviation.unwrap() <= 1e-7,
                "{:?}",
                c.pcurve_deviation
            );
        }
    }
}

/// Two loose cubes side by side, the second at x = A: they touch along a whole face, and
/// each of that face's four edges is a boundary of four faces, two of each cube. Sewn as two
/// groups (as the 402 groups of an IGES file give them), each cube closes on its own: two
/// solids of volume A^3, 8 vertices and 12 edges each, nothing shared between them, no
/// open edge.
#[test]
fn touching_cubes_sewn_as_two_groups_stay_two_solids() {
    let (mut m, a) = loose_cube(&[], false);
    let (other, b) = loose_cube(&[], false);
    let shift: Affine = [
        [1.0, 0.0, 0.0, A],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    let (nv, ne, nf) = (m.vertices.len(), m.edges.len(), m.faces.len());
    for mut v in other.vertices {
        v.point[0] += A;
        m.vertices.push(v);
    }
    for mut e in other.edges {
        e.curve = e.curve.transform(&shift).unwrap();
        e.start.0 += nv;
        e.end.0 += nv;
        m.edges.push(e);
    }
    for mut f in other.faces {
        f.surface = f.surface.transform(&shift).unwrap();
        for c in f.loops.iter_mut().flat_map(|l| &mut l.coedges) {
            c.edge.0 += ne;
        }
        m.faces.push(f);
    }
    let b: Vec<FaceId> = b.iter().map(|f| FaceId(f.0 + nf)).collect();
    let sewing = m.sew(&[a.clone(), b.clone()], 1e-7).unwrap();
    assert_eq!(sewing.merged_edges, 24);
    assert!(sewing.open_edges.is_empty(), "{:?}", sewing.open_edges);
    assert_eq!((m.vertices.len(), m.edges.len()), (16, 24));
    assert_eq!(sewing.solids.len(), 2);
    for (solid, group) in sewing.solids.iter().zip([&a, &b]) {
        let v = m.solid_volume(*solid).unwrap();
        assert!((v - A * A * A).abs() <= 1e-12 * A * A * A, "{v}");
        let shell = &m.shells[m.solids[solid.0].outer.0];
        assert!(shell.closed);
        let mut faces: Vec<FaceId> = shell.faces.iter().map(|(f, _)| *f).collect();
        faces.sort();
        let mut want = group.clone();
        want.sort();
        assert_eq!(faces, want);
    }
    // No edge or vertex is used by both cubes.
    let used = |group: &[FaceId]| {
        let mut vertices = std::collections::BTreeSet::new();
        for f in group {
            for c in m.faces[f.0].loops.iter().flat_map(|l| &l.coedges) {
                let e = &m.edges[c.edge.0];
                vertices.insert((c.edge.0, e.start.0, e.end.0));
            }
        }
        vertices
    };
    let (ua, ub) = (used(&a), used(&b));
    for (e, s, t) in &ua {
        assert!(
            !ub.iter()
                .any(|(f, u, w)| f == e || [u, w].contains(&s) || [u, w].contains(&t)),
            "edge {e} or its vertices shared"
        );
    }
}

/// Five faces (the top left off) sew into one open shell whose four rim edges are reported;
/// no solid.
#[test]
fn an_open_box_stays_an_open_shell() {
    let (mut m, faces) = loose_cube(&[5], false);
    let sewing = m.sew(std::slice::from_ref(&faces), 1e-7).unwrap();
    assert_eq!(sewing.solids.len(), 0);
    assert_eq!(sewing.shells.len(), 1);
    assert!(!m.shells[sewing.shells[0].0].closed);
    assert_eq!(sewing.open_edges.len(), 4, "{:?}", sewing.open_edges);
    for e in &sewing.open_edges {
        let edge = &m.edges[e.0];
        let (a, b) = (m.vertices[edge.start.0].point, m.vertices[edge.end.0].point);
        assert!(
            a[2] == A && b[2] == A,
            "rim edges lie on the missing top face"
        );
    }
}

/// The cube with its top face lifted by 1e-4 (a thousand times the sewing tolerance): the
/// top face's four edges and the side faces' four top edges stay open, and each top edge
/// pairs with the side edge under it at the lift: a near miss (`Sewing::gaps`). The open
/// box's rim, the border of a surface model, has no partner: no gap.
#[test]
fn open_edges_that_nearly_meet_are_told_from_a_border() {
    let delta = 1e-4;
    let (mut m, faces) = loose_cube(&[], false);
    let lift: Affine = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, delta],
    ];
    let top = faces[5];
    m.faces[top.0].surface = m.faces[top.0].surface.transform(&lift).unwrap();
    let edges: Vec<usize> = m.faces[top.0].loops[0]
        .coedges
        .iter()
        .map(|c| c.edge.0)
        .collect();
    for e in edges {
        m.edges[e].curve = m.edges[e].curve.transform(&lift).unwrap();
        for v in [m.edges[e].start.0, m.edges[e].end.0] {
            m.vertices[v].point[2] = A + delta;
        }
    }
    let sewing = m.sew(std::slice::from_ref(&faces), 1e-7).unwrap();
    assert!(sewing.solids.is_empty());
    assert_eq!(sewing.open_edges.len(), 8, "{:?}", sewing.open_edges);
    assert!(sewing.gaps_complete);
    assert_eq!(sewing.gaps.len(), 4, "{:?}", sewing.gaps);
    for &(a, b, d) in &sewing.gaps {
        assert!((d - delta).abs() <= 1e-12, "{d}");
        let z = |e: EdgeId| m.vertices[m.edges[e.0].start.0].point[2];
        let mut zs = [z(a), z(b)];
        zs.sort_by(f64::total_cmp);
        assert_eq!(zs, [A, A + delta]);
    }

    let (mut m, faces) = loose_cube(&[5], false);
    let sewing = m.sew(std::slice::from_ref(&faces), 1e-7).unwrap();
    assert_eq!(sewing.open_edges.len(), 4);
    assert!(sewing.gaps_complete);
    assert!(sewing.gaps.is_empty(), "{:?}", sewing.gaps);
}

/// A face whose boundary quadrature would take more surface evaluations than a face may
/// spend (a closed zig-zag pcurve of 200 000 spans, 600 evaluations each at least) ends as
/// `Unconverged` once the budget is spent, not after the whole walk: the work of one face is
/// bounded whatever its input (FACE_EVALUATIONS, checked before each evaluation).
#[test]
fn a_face_past_its_evaluation_budget_ends_unconverged() {
    use nurbsx::topology::{FACE_EVALUATIONS, MeasureError};
    let z = Frame {
        origin: [0.0; 3],
        x: [1.0, 0.0, 0.0],
        y: [0.0, 1.0, 0.0],
        z: [0.0, 0.0, 1.0],
    };
    let plane = sweep::plane(&z, (0.0, 1.0), (0.0, 1.0)).unwrap();
    let n = 200_000usize;
    // Out along v = 0.25 + 0.5 (k mod 2) and back at the same u: a closed polyline.
    let mut pts: Vec<Point3> = (0..=n)
        .map(|k| {
            let u = 0.1 + 0.8 * k as f64 / n as f64;
            [u, 0.25 + 0.5 * (k % 2) as f64, 0.0]
        })
        .collect();
    pts.push(pts[0]);
    let m_pts = pts.len();
    let mut knots = vec![0.0];
    knots.extend((0..m_pts).map(|k| k as f64));
    knots.push((m_pts - 1) as f64);
    let range = (0.0, (m_pts - 1) as f64);
    let pc =
        nurbsx::nurbs::NurbsCurve::with_dimension(1, knots.clone(), pts.clone(), None, 2).unwrap();
    let curve = nurbsx::nurbs::NurbsCurve::new(1, knots, pts.clone(), None).unwrap();
    let mut m = Model::new();
    let v = m
        .add_vertex(plane.point_at(pts[0][0], pts[0][1]).unwrap(), 1e-9)
        .unwrap();
    let e = m.add_edge(curve, range, v, v, 1e-9).unwrap();
    let loops = vec![Loop {
        coedges: vec![Coedge {
            edge: e,
            forward: true,
            pcurve: Some(pc),
            pcurve_deviation: None,
        }],
        outer: true,
    }];
    let f = m.add_face(plane, loops, true).unwrap();
    match m.measure_face(&m.faces[f.0]) {
        Err(MeasureError::Unconverged { evaluations }) => {
            assert!(evaluations <= FACE_EVALUATIONS, "{evaluations}")
        }
        other => panic!("expected Unconverged, got {other:?}"),
    }
}

/// A solid with a void written as IGES 144 faces, which hold no solid: a reader that sews
/// them (nurbsx does) makes each closed shell a solid, the void's too, so the writer says
/// so (`topology.voids_not_written`); the B-rep mode writes the void and says nothing.
#[test]
fn iges_faces_mode_warns_of_voids() {
    use nurbsx::exchange::{self, Document, ExportOptions, Format, LengthUnit};
    let mut outer = cube(0.0).unwrap();
    let inner = cube(0.0).unwrap();
    let all: Vec<_> = outer.faces.iter().map(|&f| (f, true)).collect();
    let shell = outer.model.add_shell(all, true).unwrap();
    // The void: a second cube's faces, reversed (ISO 10303-42 brep_with_voids: the void
    // shells face inwards), appended to the model.
    let (nv, ne, nf) = (
        outer.model.vertices.len(),
        outer.model.edges.len(),
        outer.model.faces.len(),
    );
    outer.model.vertices.extend(inner.model.vertices);
    for mut e in inner.model.edges {
        e.start.0 += nv;
        e.end.0 += nv;
        outer.model.edges.push(e);
    }
    for mut f in inner.model.faces {
        for c in f.loops.iter_mut().flat_map(|l| &mut l.coedges) {
            c.edge.0 += ne;
        }
        outer.model.faces.push(f);
    }
    let void: Vec<_> = (0..6).map(|k| (FaceId(nf + k), false)).collect();
    let void = outer.model.add_shell(void, true).unwrap();
    outer.model.add_solid(shell, vec![void]).unwrap();
    let mut doc = Document::new(Format::Step, LengthUnit::Mm);
    doc.topology.model = outer.model;
    let (_, warnings) =
        exchange::write_reporting(&doc, Format::Iges, &ExportOptions::default()).unwrap();
    let w: Vec<_> = warnings
        .iter()
        .filter(|d| d.code == "topology.voids_not_written")
        .collect();
    assert_eq!(w.len(), 1, "{warnings:?}");
    assert!(
        w[0].message.starts_with("1 solid(s) with voids"),
        "{}",
        w[0].message
    );
    let brep = ExportOptions {
        iges_brep: true,
        ..ExportOptions::default()
    };
    let (_, warnings) = exchange::write_reporting(&doc, Format::Iges, &brep).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
}
