//! [`Topology`] -> IGES 5.3 entities, for [`super::write()`].
//!
//! - Faces (the default, and the faces no shell holds): a 144 Trimmed Surface (IGES 5.3
//!   section 4.34) over the face's 128, `N1 = 1` with the outer loop as PTO and the holes as
//!   PTI (`N1 = 0` and no loop for a face bounded by its surface's domain). Each loop is a
//!   142 Curve on a Parametric Surface (section 4.32) whose model-space curve C(t) is a 102
//!   Composite Curve (section 4.4) of one 126 per coedge, in the loop's direction and on the
//!   edge's parameter range (`V(0), V(1)`); when every coedge has a pcurve and the pcurves
//!   chain in the surface's (u, v) within 1e-9 of its domain's size, B(t) is a 102 of the 2-D
//!   126 pcurves (z = 0, use flag 05) and PREF = 1 (parameter space preferred), otherwise
//!   BPTR = 0 and PREF = 2 (model space). Loops that wind around a closed surface without a
//!   seam edge, and loops that skip a collapsed side, are first made into boundaries that
//!   close in (u, v): joined by the seam, with the collapsed side as a curve of zero length
//!   (`closed_in_parameter_space`).
//! - With `iges_brep`: every solid as a 186 Manifold Solid B-Rep Object, every shell as a
//!   514 Shell (form 1 closed, 2 open; a shell no solid holds is written alone), every face
//!   of a shell as a 510 Face with its 508 Loops (form 1), the edges in one 504 Edge List
//!   and the vertices in one 502 Vertex List (each written once however many loops use it),
//!   each coedge with its orientation flag and its 2-D pcurve when it has one (IGES 5.3
//!   types 186, 502-514); a vertex loop is a 508 of one vertex use (TYPE = 1). A face's
//!   orientation in its shell is the 514 OF flag (the shell's orientation combined with
//!   the face's `same_sense`); the loops of a face with `same_sense` false run the other
//!   way round, as in a 144.
//! - Free edges (in no face) as independent 126s on their range.
//! - The faces of a shell of several faces, written as 144s, are listed by a 402 form 7
//!   group (IGES 5.3 section 4.83), as Open CASCADE writes a shell: a reader that sews
//!   sews each group on its own.
//!
//! Every entity another one names is written physically dependent (DE status digits 3-4 =
//! 01), so a reader takes the 144s, 402s and 186s as the roots; a 144 a group lists is
//! logically dependent (02).

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap, HashSet};

use nurbsx_parsers::iges::records::{
    BrepSolid186, CompositeCurve102, CurveOnSurface142, Edge as Edge504, EdgeList504, Face510,
    Group402, Loop508, LoopEdge, Shell514, TrimmedSurface144, VertexList502,
};

use super::write::Items;
use crate::exchange::{Cancel, Document, Entity, Meta, ParameterRange};
use crate::nurbs::{Geometry, NurbsCurve, NurbsSurface, Point3, bounding_box_diagonal};
use crate::topology::{Coedge, EdgeId, Face, FaceId, Loop, Model, VertexId};

/// Relative distance (of the surface's parameter domain) within which consecutive pcurves
/// of a loop must meet for the loop to be written in parameter space too.
const PCURVE_CHAIN_TOL: f64 = 1e-9;

/// Writes the document's topology into `items`; returns the ids of the entities it
/// wrote as face surfaces or edge curves (the writer leaves them out of the free
/// entities). Polls `cancel` before each face and edge (a record's plan evaluates its
/// geometry) and returns early once it has fired (`exchange::write` then answers
/// `cancelled`).
pub(super) fn write<'d>(
    document: &'d Document,
    brep: bool,
    cancel: &Cancel,
    items: &mut Items<'d>,
) -> HashSet<&'d str> {
    let topology = &document.topology;
    let model = &topology.model;
    let entities: HashMap<&str, &Entity> = document
        .entities
        .iter()
        .map(|e| (e.id.as_str(), e))
        .collect();
    let mut named: HashSet<&'d str> = HashSet::new();
    for o in topology.origins.faces.iter().chain(&topology.origins.edges) {
        if let Some(id) = o.entity.as_deref() {
            named.insert(id);
        }
    }
    let meta_of = |origin: Option<&crate::exchange::Origin>| -> Meta {
        origin
            .and_then(|o| o.entity.as_deref())
            .and_then(|id| entities.get(id))
            .map(|e| e.meta.clone())
            .unwrap_or_default()
    };
    let face_meta = |f: FaceId| meta_of(topology.origins.faces.get(f.0));
    let edge_meta = |e: EdgeId| meta_of(topology.origins.edges.get(e.0));
    // A surface several faces share (they name one entity and each carries its geometry
    // bit for bit, as CATIA writes split faces) is written once, as read: its 128 is the
    // surface of each of their 510s or 144s.
    let shared_label = |f: FaceId| -> Option<&'d str> {
        let label = topology.origins.faces.get(f.0)?.entity.as_deref()?;
        let face = model.faces.get(f.0)?;
        matches!(&entities.get(label)?.geometry, Geometry::Surface(x) if *x == face.surface)
            .then_some(label)
    };
    let mut shared: HashMap<&'d str, i64> = HashMap::new();
    let mut surface_de = |f: FaceId, items: &mut Items<'d>| -> i64 {
        let label = shared_label(f);
        if let Some(&de) = label.and_then(|l| shared.get(l)) {
            return de;
        }
        let face = &model.faces[f.0];
        let de = items.surface(Cow::Borrowed(&face.surface), &face_meta(f), 1);
        if let Some(l) = label {
            shared.insert(l, de);
        }
        de
    };
    let mut in_brep: HashSet<FaceId> = HashSet::new();
    if brep {
        let mut w = Brep {
            edges: BTreeMap::new(),
            vertices: BTreeMap::new(),
        };
        // Faces of shells, with their edges and vertices numbered in order of use.
        for shell in &model.shells {
            for &(f, _) in &shell.faces {
                in_brep.insert(f);
            }
        }
        let mut faces: Vec<FaceId> = in_brep.iter().copied().collect();
        faces.sort();
        for &f in &faces {
            if cancel.is_set() {
                return named;
            }
            for &v in &model.faces[f.0].vertex_loops {
                let n = w.vertices.len();
                w.vertices.entry(v).or_insert(n);
            }
            for c in model.faces[f.0].loops.iter().flat_map(|l| &l.coedges) {
                let next = w.edges.len();
                if let std::collections::btree_map::Entry::Vacant(slot) = w.edges.entry(c.edge) {
                    slot.insert(next);
                    let e = &model.edges[c.edge.0];
                    for v in [e.start, e.end] {
                        let n = w.vertices.len();
                        w.vertices.entry(v).or_insert(n);
                    }
                }
            }
        }
        // 502: the vertices in index order.
        let mut points = vec![[0.0; 3]; w.vertices.len()];
        for (v, &i) in &w.vertices {
            points[i] = model.vertices[v.0].point;
        }
        let factor = items.factor();
        let points = points
            .into_iter()
            .map(|p| factor.map_or(p, |f| [p[0] * f, p[1] * f, p[2] * f]))
            .collect();
        let vertex_list = items.record(502, 1, 1, 0, VertexList502 { points });
        // The edge curves, then the 504.
        let mut order: Vec<(EdgeId, usize)> = w.edges.iter().map(|(&e, &i)| (e, i)).collect();
        order.sort_by_key(|&(_, i)| i);
        let mut list = Vec::with_capacity(order.len());
        for &(e, _) in &order {
            if cancel.is_set() {
                return named;
            }
            let edge = &model.edges[e.0];
            let mut meta = edge_meta(e);
            meta.parameter_range = Some(Box::new(ParameterRange {
                u: edge.range,
                v: None,
            }));
            let curve = items.curve(Cow::Borrowed(&edge.curve), &meta, 1);
            list.push(Edge504 {
                curve,
                start: (vertex_list, w.vertex_index(edge.start)),
                end: (vertex_list, w.vertex_index(edge.end)),
            });
        }
        let edge_list = items.record(504, 1, 1, 0, EdgeList504 { edges: list });
        let mut face_de: BTreeMap<FaceId, i64> = BTreeMap::new();
        for &f in &faces {
            if cancel.is_set() {
                return named;
            }
            let face = &model.faces[f.0];
            let surface = surface_de(f, items);
            let mut loops = Vec::with_capacity(face.loops.len());
            // The outer loop first (510 OF = 1).
            let mut ordered: Vec<_> = face.loops.iter().collect();
            ordered.sort_by_key(|l| !l.outer);
            for l in &ordered {
                let mut uses = Vec::with_capacity(l.coedges.len());
                for (c, forward) in written_coedges(face, l) {
                    let pcurve = c.pcurve.as_ref().map(|p| {
                        let mut meta = Meta::default();
                        let range = model.edges[c.edge.0].range;
                        meta.parameter_range = Some(Box::new(ParameterRange { u: range, v: None }));
                        items.curve(Cow::Borrowed(p), &meta, 1)
                    });
                    uses.push(LoopEdge {
                        kind: 0,
                        edge: edge_list,
                        index: w.edge_index(c.edge),
                        orientation: i64::from(forward),
                        parameter_curves: pcurve.map(|p| (0, p)).into_iter().collect(),
                    });
                }
                loops.push(items.record(508, 1, 1, 0, Loop508 { edges: uses }));
            }
            // A vertex loop: a 508 of one vertex use (TYPE = 1) naming the 502 vertex.
            for &v in &face.vertex_loops {
                let vertex = LoopEdge {
                    kind: 1,
                    edge: vertex_list,
                    index: w.vertex_index(v),
                    orientation: 1,
                    parameter_curves: Vec::new(),
                };
                let edges = vec![vertex];
                loops.push(items.record(508, 1, 1, 0, Loop508 { edges }));
            }
            let outer_first = i64::from(ordered.first().is_some_and(|l| l.outer));
            let de = items.record(
                510,
                1,
                1,
                0,
                Face510 {
                    surface,
                    outer_first,
                    loops,
                },
            );
            face_de.insert(f, de);
        }
        let mut shell_de = Vec::with_capacity(model.shells.len());
        let in_solid: HashSet<usize> = model
            .solids
            .iter()
            .flat_map(|s| std::iter::once(s.outer.0).chain(s.voids.iter().map(|v| v.0)))
            .collect();
        for (i, shell) in model.shells.iter().enumerate() {
            let faces = shell
                .faces
                .iter()
                .filter_map(|&(f, orientation)| {
                    let same = model.faces[f.0].same_sense;
                    face_de
                        .get(&f)
                        .map(|&de| (de, i64::from(orientation == same)))
                })
                .collect();
            let form = if shell.closed { 1 } else { 2 };
            let subordinate = u8::from(in_solid.contains(&i));
            shell_de.push(items.record(514, form, subordinate, 0, Shell514 { faces, form }));
        }
        for solid in &model.solids {
            let shell = (shell_de[solid.outer.0], 1);
            let voids = solid.voids.iter().map(|v| (shell_de[v.0], 1)).collect();
            items.record(186, 0, 0, 0, BrepSolid186 { shell, voids });
        }
    }
    // Faces as 144 (all of them, or those no shell holds in B-rep mode). The faces of a
    // shell of several faces are listed by a 402 form 7 group (IGES 5.3 section 4.83), as
    // Open CASCADE writes a shell: a reader that sews (nurbsx does) sews each group on its
    // own, so that solids which touch stay apart; the 144s it lists are logically
    // dependent (DE status digits 3-4 = 02, section 2.2.4.4.9.2).
    let mut grouped: HashSet<FaceId> = HashSet::new();
    if !brep {
        for shell in model.shells.iter().filter(|s| s.faces.len() > 1) {
            grouped.extend(shell.faces.iter().map(|&(f, _)| f));
        }
    }
    let mut face_de: HashMap<FaceId, i64> = HashMap::new();
    for (i, face) in model.faces.iter().enumerate() {
        let f = FaceId(i);
        if cancel.is_set() {
            return named;
        }
        if in_brep.contains(&f) {
            continue;
        }
        let surface = surface_de(f, items);
        let subordinate = if grouped.contains(&f) { 2 } else { 0 };
        let de = trimmed_face(model, face, surface, subordinate, &edge_meta, items);
        face_de.insert(f, de);
    }
    // Free edges (in no face: the curves of a STEP GEOMETRIC_SET placed by an assembly) as
    // independent 126s on their range, with their entity's metadata.
    let mut in_face = vec![false; model.edges.len()];
    for c in model
        .faces
        .iter()
        .flat_map(|f| &f.loops)
        .flat_map(|l| &l.coedges)
    {
        if let Some(x) = in_face.get_mut(c.edge.0) {
            *x = true;
        }
    }
    for (k, edge) in model.edges.iter().enumerate() {
        if in_face[k] {
            continue;
        }
        if cancel.is_set() {
            return named;
        }
        let mut meta = edge_meta(EdgeId(k));
        meta.parameter_range = (edge.range != edge.curve.domain()).then(|| {
            Box::new(ParameterRange {
                u: edge.range,
                v: None,
            })
        });
        items.curve(Cow::Borrowed(&edge.curve), &meta, 0);
    }
    for shell in model.shells.iter().filter(|s| s.faces.len() > 1) {
        let members: Vec<i64> = shell
            .faces
            .iter()
            .filter_map(|(f, _)| face_de.get(f).copied())
            .collect();
        if members.len() > 1 {
            items.record(402, 7, 0, 0, Group402 { members, form: 7 });
        }
    }
    named
}

/// The numbering of the B-rep lists (from 0; written from 1).
struct Brep {
    edges: BTreeMap<EdgeId, usize>,
    vertices: BTreeMap<VertexId, usize>,
}

impl Brep {
    fn vertex_index(&self, v: VertexId) -> i64 {
        self.vertices
            .get(&v)
            .map_or(0, |&i| i64::try_from(i + 1).unwrap_or(i64::MAX))
    }

    fn edge_index(&self, e: EdgeId) -> i64 {
        self.edges
            .get(&e)
            .map_or(0, |&i| i64::try_from(i + 1).unwrap_or(i64::MAX))
    }
}

/// A loop's coedges as IGES writes them, each with its direction along its edge. A 144 has
/// no orientation of its own (its side is its surface's normal, with the region on the left
/// of its boundaries seen from there, IGES 5.3 section 4.34), and neither has a 510 (its
/// shell's OF flag turns it over as a whole, section 4.147, which the writer sets from
/// `same_sense`). So a face on the other side of its surface (`same_sense` false) has its
/// loops run the other way round: a reader orients it as the surface does and does not
/// take the loops for the face's side.
fn written_coedges<'d>(face: &Face, l: &'d Loop) -> Vec<(&'d Coedge, bool)> {
    if face.same_sense {
        l.coedges.iter().map(|c| (c, c.forward)).collect()
    } else {
        l.coedges.iter().rev().map(|c| (c, !c.forward)).collect()
    }
}

/// A face as a 144 with its 142 boundaries (module documentation), over the 128 `surface`.
fn trimmed_face<'d>(
    model: &'d Model,
    face: &'d Face,
    surface: i64,
    subordinate: u8,
    edge_meta: &dyn Fn(EdgeId) -> Meta,
    items: &mut Items<'d>,
) -> i64 {
    let mut ordered: Vec<_> = face.loops.iter().collect();
    ordered.sort_by_key(|l| !l.outer);
    let loops: Vec<Boundary<'d>> = ordered
        .iter()
        .map(|l| {
            let coedges = written_coedges(face, l);
            let segments = coedges
                .iter()
                .map(|&(c, forward)| {
                    let edge = &model.edges[c.edge.0];
                    let (d0, d1) = c.pcurve.as_ref().map_or((0.0, 0.0), |p| p.domain());
                    Segment {
                        model: along(&edge.curve, edge.range, forward),
                        meta: edge_meta(c.edge),
                        parameter: c
                            .pcurve
                            .as_ref()
                            .filter(|_| edge.range.0 >= d0 && edge.range.1 <= d1)
                            .map(|p| along(p, edge.range, forward)),
                    }
                })
                .collect();
            Boundary {
                outer: l.outer,
                segments,
            }
        })
        .collect();
    let tolerance = face
        .loops
        .iter()
        .flat_map(|l| &l.coedges)
        .map(|c| model.edges[c.edge.0].tolerance)
        .fold(0.0, f64::max);
    let loops = closed_in_parameter_space(&face.surface, tolerance, loops);
    let mut boundaries = Vec::with_capacity(loops.len());
    for l in &loops {
        // Model space: one 126 per segment, in the loop's direction.
        let mut model_pieces = Vec::with_capacity(l.segments.len());
        for seg in &l.segments {
            let mut m = seg.meta.clone();
            m.parameter_range = Some(Box::new(ParameterRange {
                u: seg.model.1,
                v: None,
            }));
            model_pieces.push(items.curve(seg.model.0.clone(), &m, 1));
        }
        let model_curve = items.record(
            102,
            0,
            1,
            0,
            CompositeCurve102 {
                members: model_pieces,
            },
        );
        let parameter_curve = parameter_loop(&face.surface, &l.segments).map(|pieces| {
            let members = pieces
                .into_iter()
                .map(|(curve, range)| {
                    let m = Meta {
                        parameter_range: Some(Box::new(ParameterRange { u: range, v: None })),
                        ..Meta::default()
                    };
                    items.curve(curve, &m, 1)
                })
                .collect();
            items.record(102, 0, 1, 5, CompositeCurve102 { members })
        });
        boundaries.push(items.record(
            142,
            0,
            1,
            5,
            CurveOnSurface142 {
                creation: 0,
                surface,
                parameter_curve: parameter_curve.unwrap_or(0),
                model_curve,
                preferred: if parameter_curve.is_some() { 1 } else { 2 },
            },
        ));
    }
    let outer = loops.first().is_some_and(|l| l.outer);
    let (outer_given, outer_ptr, inner) = if outer {
        (1, boundaries[0], boundaries[1..].to_vec())
    } else {
        (0, 0, boundaries)
    };
    items.record(
        144,
        0,
        subordinate,
        0,
        TrimmedSurface144 {
            surface,
            outer_given,
            outer: outer_ptr,
            inner,
        },
    )
}

/// One piece of a 144 boundary: its model-space curve on its range with the metadata of
/// the edge it comes from, and its pcurve on its range when it has one.
struct Segment<'d> {
    model: Piece<'d>,
    meta: Meta,
    parameter: Option<Piece<'d>>,
}

/// A 144 boundary (outer or hole) as a chain of segments.
struct Boundary<'d> {
    outer: bool,
    segments: Vec<Segment<'d>>,
}

/// The face's loops as boundaries that close in the surface's parameter space, which a 144
/// needs (IGES 5.3 section 4.34: each boundary a closed curve in the domain; Open CASCADE
/// otherwise cuts the face into pieces and zero-area slivers). ISO 10303-42 and the
/// topology model do not need it: a face on a surface closed in u (or v) may have no seam
/// edge, with one loop winding around each end of a band (two full circles bounding a
/// cylinder), or one winding loop and a collapsed side (a cone up to its apex, a sphere cap
/// up to its pole), and a face's loops may skip a collapsed side (a side of zero length is
/// no edge). Points are compared in model space, within the edges' tolerance: a pcurve
/// projected from another system's curve may end a little off the seam. So:
/// - a gap between consecutive pcurves whose ends both lie on a collapsed side of the
///   domain is filled by a segment along it (its model-space curve a single point);
/// - a loop with one gap left whose ends are the same point and lie a period apart winds
///   around the surface;
/// - two loops winding in the same direction become one outer boundary around the band
///   between them, counter-clockwise (each loop turned round if it ran the other way: the
///   band is the only region two winding loops bound), joined by the seam twice: the lower
///   loop, the seam from its end to the upper loop's start, the upper loop, the seam back;
/// - one winding loop becomes the outer boundary around to the collapsed side on its left
///   (or to the only collapsed side, the loop turned round if needed): loop, seam, the
///   collapsed side, seam.
///
/// The seam segments are the surface's iso-curve on the seam in model space, and in
/// parameter space the line between the loop ends they join. Loops that do not close this
/// way keep their gaps and are written in model space only (PREF = 2).
fn closed_in_parameter_space<'d>(
    surface: &NurbsSurface,
    tolerance: f64,
    loops: Vec<Boundary<'d>>,
) -> Vec<Boundary<'d>> {
    if loops.iter().all(|l| chains(surface, &l.segments)) {
        return loops;
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    let size = bounding_box_diagonal(surface.control_points().as_slice());
    let tol3 = tolerance.max(1e-9 * size);
    let tol2 = PCURVE_CHAIN_TOL * (u1 - u0).abs().max((v1 - v0).abs()).max(1.0);
    let period = [u1 - u0, v1 - v0];
    let closed = [surface.is_closed_u(tol3), surface.is_closed_v(tol3)];
    let at = |p: [f64; 2]| surface.point_at_unchecked(p[0].clamp(u0, u1), p[1].clamp(v0, v1));
    let near = |a: Point3, b: Point3| (0..3).all(|k| (a[k] - b[k]).abs() <= tol3);
    // The point of a side of the domain (`k` the coordinate fixed on it, at `value`) when
    // the side is collapsed to it.
    let collapsed = |k: usize, value: f64| -> Option<Point3> {
        let row = if k == 1 {
            surface.iso_v(value).ok()?
        } else {
            surface.iso_u(value).ok()?
        };
        let poles = row.control_points();
        let first = *poles.first()?;
        poles.iter().all(|&p| near(p, first)).then_some(first)
    };
    let sides: Vec<(usize, f64, Point3)> = [(1, v0), (1, v1), (0, u0), (0, u1)]
        .into_iter()
        .filter_map(|(k, value)| Some((k, value, collapsed(k, value)?)))
        .collect();
    let mut closed_loops: Vec<Boundary<'d>> = Vec::with_capacity(loops.len());
    // Winding loops: rotated to start after their gap, with the closed direction.
    let mut winding: Vec<(Boundary<'d>, usize)> = Vec::new();
    let mut open: Vec<Boundary<'d>> = Vec::new();
    for mut l in loops {
        let ends: Option<Vec<([f64; 2], [f64; 2])>> = l
            .segments
            .iter()
            .map(|s| {
                let (c, (a, b)) = s.parameter.as_ref()?;
                let p = c.point_at_unchecked(*a);
                let q = c.point_at_unchecked(*b);
                Some(([p[0], p[1]], [q[0], q[1]]))
            })
            .collect();
        let Some(ends) = ends.filter(|e| !e.is_empty()) else {
            open.push(l);
            continue;
        };
        let n = ends.len();
        // Fill the gaps along collapsed sides: fills[i] goes after segment i.
        let mut gaps: Vec<usize> = Vec::new();
        let mut fills: Vec<Option<Segment<'d>>> = (0..n).map(|_| None).collect();
        for i in 0..n {
            let (e, s) = (ends[i].1, ends[(i + 1) % n].0);
            if (e[0] - s[0]).abs().max((e[1] - s[1]).abs()) <= tol2 {
                continue;
            }
            let side = sides.iter().find(|&&(k, value, point)| {
                (e[k] - value).abs() <= 0.5 * period[k]
                    && (s[k] - value).abs() <= 0.5 * period[k]
                    && near(at(e), point)
                    && near(at(s), point)
            });
            match side.and_then(|&(k, _, point)| collapsed_segment(e, s, point, 1 - k)) {
                Some(seg) => fills[i] = Some(seg),
                None => gaps.push(i),
            }
        }
        // Which gap is left: none (closed), or one a period long in a closed direction
        // between two ends that are the same point (winding).
        let wind = match gaps.as_slice() {
            [] => None,
            &[i] => {
                let (e, s) = (ends[i].1, ends[(i + 1) % n].0);
                let found = (0..2).find(|&d| {
                    closed[d] && (e[d] - s[d]).abs() > 0.5 * period[d] && near(at(e), at(s))
                });
                match found {
                    Some(d) => Some((i, d)),
                    None => {
                        open.push(l);
                        continue;
                    }
                }
            }
            _ => {
                open.push(l);
                continue;
            }
        };
        // The segments with the fills, starting after the winding loop's gap.
        let first = wind.map_or(0, |(i, _)| (i + 1) % n);
        let mut old: Vec<Option<Segment<'d>>> = l.segments.into_iter().map(Some).collect();
        let mut segments = Vec::with_capacity(n + 2);
        for k in 0..n {
            let j = (first + k) % n;
            segments.extend(old[j].take());
            segments.extend(fills[j].take());
        }
        l.segments = segments;
        match wind {
            None => closed_loops.push(l),
            Some((_, d)) => winding.push((l, d)),
        }
    }
    let joined = join_winding(surface, &sides, &mut winding, &at, &near);
    let mut out = Vec::with_capacity(closed_loops.len() + winding.len() + open.len() + 1);
    match joined {
        Some(j) => {
            out.push(j);
            for l in &mut closed_loops {
                l.outer = false;
            }
        }
        None => open.extend(winding.into_iter().map(|(l, _)| l)),
    }
    out.extend(closed_loops);
    out.extend(open);
    out.sort_by_key(|l| !l.outer);
    out
}

/// The first and last parameter-space points of a boundary.
fn boundary_ends(l: &Boundary<'_>) -> Option<([f64; 2], [f64; 2])> {
    let (c, (a, _)) = l.segments.first()?.parameter.as_ref()?;
    let (d, (_, b)) = l.segments.last()?.parameter.as_ref()?;
    let (p, q) = (c.point_at_unchecked(*a), d.point_at_unchecked(*b));
    Some(([p[0], p[1]], [q[0], q[1]]))
}

/// The boundary traversed the other way (segments in reverse order, each reversed).
fn turned<'d>(l: &mut Boundary<'d>) {
    let old = std::mem::take(&mut l.segments);
    l.segments = old
        .into_iter()
        .rev()
        .map(|s| {
            let (m, r) = s.model;
            Segment {
                model: reversed_piece(m, r),
                meta: s.meta,
                parameter: s.parameter.map(|(c, r)| reversed_piece(c, r)),
            }
        })
        .collect();
}

fn reversed_piece<'d>(c: Cow<'d, NurbsCurve>, r: (f64, f64)) -> Piece<'d> {
    let (rc, rr) = along(&c, r, false);
    (Cow::Owned(rc.into_owned()), rr)
}

/// Joins the winding loops of [`closed_in_parameter_space`] into one outer boundary.
fn join_winding<'d>(
    surface: &NurbsSurface,
    sides: &[(usize, f64, Point3)],
    winding: &mut [(Boundary<'d>, usize)],
    at: &dyn Fn([f64; 2]) -> Point3,
    near: &dyn Fn(Point3, Point3) -> bool,
) -> Option<Boundary<'d>> {
    let ((u0, u1), (v0, v1)) = surface.domain();
    match winding {
        [(a, da), (b, db)] if da == db => {
            let d = *da;
            let k = 1 - d;
            let (sa, _) = boundary_ends(a)?;
            let (sb, _) = boundary_ends(b)?;
            // Counter-clockwise around the band: for u closed the loop at the lower v runs
            // +u; for v closed the loop at the larger u runs +v.
            let (low, high) = if sa[k] <= sb[k] { (a, b) } else { (b, a) };
            let (first, second) = if d == 0 { (low, high) } else { (high, low) };
            let runs_forward =
                |l: &Boundary<'_>| boundary_ends(l).is_some_and(|(s, e)| e[d] > s[d]);
            if !runs_forward(first) {
                turned(first);
            }
            if runs_forward(second) {
                turned(second);
            }
            let (s1, e1) = boundary_ends(first)?;
            let (s2, e2) = boundary_ends(second)?;
            let up = seam_segment(surface, d, e1, s2, at, near)?;
            let down = seam_segment(surface, d, e2, s1, at, near)?;
            let mut segments = std::mem::take(&mut first.segments);
            segments.push(up);
            segments.append(&mut second.segments);
            segments.push(down);
            Some(Boundary {
                outer: true,
                segments,
            })
        }
        [(a, d)] => {
            let d = *d;
            let k = 1 - d;
            let (s, e) = boundary_ends(a)?;
            // The collapsed side the region reaches: the one on the loop's left (for u
            // closed and the loop running +u, v = v1; for v closed and +v, u = u0), or the
            // only collapsed side of that coordinate.
            let forward = e[d] > s[d];
            let left = match (d, forward) {
                (0, true) => v1,
                (0, false) => v0,
                (_, true) => u0,
                (_, false) => u1,
            };
            let candidates: Vec<&(usize, f64, Point3)> =
                sides.iter().filter(|x| x.0 == k).collect();
            let &&(_, value, point) = match candidates.as_slice() {
                [one] => one,
                _ => candidates.iter().find(|x| x.1 == left)?,
            };
            let lower = value == v0 || value == u0;
            // Counter-clockwise: for u closed a side above (v1) needs the loop to run +u;
            // for v closed a side on the left (u0) needs +v.
            let wanted = if d == 0 { !lower } else { lower };
            if forward != wanted {
                turned(a);
            }
            let (s, e) = boundary_ends(a)?;
            let corner = |p: [f64; 2]| {
                let mut q = p;
                q[k] = value;
                q
            };
            let (ce, cs) = (corner(e), corner(s));
            let up = seam_segment(surface, d, e, ce, at, near)?;
            let side = collapsed_segment(ce, cs, point, d)?;
            let down = seam_segment(surface, d, cs, s, at, near)?;
            let mut segments = std::mem::take(&mut a.segments);
            segments.extend([up, side, down]);
            Some(Boundary {
                outer: true,
                segments,
            })
        }
        _ => None,
    }
}

/// A 2-D line from `p` to `q`, parameterised by the coordinate `k` that changes along it
/// (the other is equal at both ends), on the range it runs over, traversed from `p`.
fn parameter_line(p: [f64; 2], q: [f64; 2], k: usize) -> Option<Piece<'static>> {
    let (lo, hi) = if p[k] < q[k] { (p, q) } else { (q, p) };
    if hi[k].partial_cmp(&lo[k]) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let line = NurbsCurve::with_dimension(
        1,
        vec![lo[k], lo[k], hi[k], hi[k]],
        vec![[lo[0], lo[1], 0.0], [hi[0], hi[1], 0.0]],
        None,
        2,
    )
    .ok()?;
    let (c, range) = along(&line, (lo[k], hi[k]), p[k] < q[k]);
    Some((Cow::Owned(c.into_owned()), range))
}

/// The segment along a collapsed side of the domain from `p` to `q` (both on it, `k` the
/// coordinate that changes along it): in parameter space the line between them, in model
/// space the side's single point as a curve of zero length (as Open CASCADE writes a
/// degenerate edge), on the same range.
fn collapsed_segment<'d>(p: [f64; 2], q: [f64; 2], point: Point3, k: usize) -> Option<Segment<'d>> {
    let parameter = parameter_line(p, q, k)?;
    let (a, b) = parameter.1;
    let model = NurbsCurve::new(1, vec![a, a, b, b], vec![point, point], None).ok()?;
    Some(Segment {
        model: (Cow::Owned(model), (a, b)),
        meta: Meta::default(),
        parameter: Some(parameter),
    })
}

/// The seam of a surface closed in direction `d` (0: u) from `p` to `q`, both within the
/// tolerance of it in model space: in model space the surface's iso-curve on the seam
/// (exact, NURBS Book section 5.4 knot insertion to full multiplicity; the one at the
/// domain's start, so that the seam's two uses are the same curve), in parameter space the
/// line from `p` to `q`, both parameterised by the coordinate along the seam.
fn seam_segment<'d>(
    surface: &NurbsSurface,
    d: usize,
    p: [f64; 2],
    q: [f64; 2],
    at: &dyn Fn([f64; 2]) -> Point3,
    near: &dyn Fn(Point3, Point3) -> bool,
) -> Option<Segment<'d>> {
    let k = 1 - d;
    let ((u0, _), (v0, _)) = surface.domain();
    let on_seam = |x: [f64; 2]| {
        let mut y = x;
        y[d] = if d == 0 { u0 } else { v0 };
        near(at(x), at(y))
    };
    if !(on_seam(p) && on_seam(q)) {
        return None;
    }
    let parameter = parameter_line(p, q, k)?;
    let iso = if d == 0 {
        surface.iso_u(u0).ok()?
    } else {
        surface.iso_v(v0).ok()?
    };
    let (model, range) = along(&iso, (p[k].min(q[k]), p[k].max(q[k])), p[k] < q[k]);
    Some(Segment {
        model: (Cow::Owned(model.into_owned()), range),
        meta: Meta::default(),
        parameter: Some(parameter),
    })
}

/// A curve to write with the parameter range it is written on.
type Piece<'d> = (Cow<'d, NurbsCurve>, (f64, f64));

/// A curve on `range` traversed forward, or reversed (`C(a + b - u)`, NURBS Book section
/// 6.1 reversal by mirrored knots) with the range mirrored.
fn along(
    curve: &NurbsCurve,
    range: (f64, f64),
    forward: bool,
) -> (Cow<'_, NurbsCurve>, (f64, f64)) {
    if forward {
        return (Cow::Borrowed(curve), range);
    }
    match curve.reverse() {
        Ok(r) => (
            Cow::Owned(r),
            (
                curve.reversed_parameter(range.1),
                curve.reversed_parameter(range.0),
            ),
        ),
        Err(_) => (Cow::Borrowed(curve), range),
    }
}

/// The boundary's pcurves when every segment has one and they chain in the surface's
/// parameter space (module documentation); `None` otherwise.
fn parameter_loop<'d>(surface: &NurbsSurface, segments: &[Segment<'d>]) -> Option<Vec<Piece<'d>>> {
    chains(surface, segments).then(|| {
        segments
            .iter()
            .filter_map(|s| s.parameter.clone())
            .collect()
    })
}

/// Whether every segment has a pcurve and each ends where the next starts, within
/// [`PCURVE_CHAIN_TOL`] of the surface's domain.
fn chains(surface: &NurbsSurface, segments: &[Segment<'_>]) -> bool {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let tol = PCURVE_CHAIN_TOL * (u1 - u0).abs().max((v1 - v0).abs()).max(1.0);
    let n = segments.len();
    (0..n).all(|i| {
        let (Some((a, ra)), Some((b, rb))) =
            (&segments[i].parameter, &segments[(i + 1) % n].parameter)
        else {
            return false;
        };
        let end = a.point_at_unchecked(ra.1);
        let start = b.point_at_unchecked(rb.0);
        (end[0] - start[0]).abs().max((end[1] - start[1]).abs()) <= tol
    })
}

/// What [`write`] leaves out of the file it writes for `document` in the mode `brep`: the
/// vertex loops ([`Face::vertex_loops`]: a cone's apex, a sphere's pole) of the faces it
/// writes as 144s, which a 144 cannot hold (its boundaries are curves, IGES 5.3 section
/// 4.34; the B-rep mode writes a face of a shell with a 508 vertex use instead), and, in
/// the faces mode, which solids have voids: 144 faces hold no solid, and a reader that
/// sews makes each closed shell a solid of its own, the void one too.
pub(crate) fn write_warnings(document: &Document, brep: bool) -> Vec<crate::exchange::Diagnostic> {
    let model = &document.topology.model;
    let mut out = Vec::new();
    let with_voids: Vec<usize> = (0..model.solids.len())
        .filter(|&k| !brep && !model.solids[k].voids.is_empty())
        .collect();
    if let Some(&first) = with_voids.first() {
        out.push(not_written(
            "topology.voids_not_written",
            format!(
                "{} solid(s) with voids written as 144 trimmed faces, which hold no solid: a reader that sews them (nurbsx does) makes each closed shell a solid, the void's too; --iges-brep writes them as 186 solids with their voids",
                with_voids.len()
            ),
            &document.topology.origins.solids,
            first,
        ));
    }
    let mut in_shell = vec![false; model.faces.len()];
    if brep {
        for &(f, _) in model.shells.iter().flat_map(|s| &s.faces) {
            if let Some(x) = in_shell.get_mut(f.0) {
                *x = true;
            }
        }
    }
    let faces: Vec<usize> = (0..model.faces.len())
        .filter(|&k| !in_shell[k] && !model.faces[k].vertex_loops.is_empty())
        .collect();
    let Some(&first) = faces.first() else {
        return out;
    };
    let loops: usize = faces
        .iter()
        .map(|&k| model.faces[k].vertex_loops.len())
        .sum();
    out.push(not_written(
        "topology.vertex_loop_not_written",
        format!(
            "{loops} vertex loop(s) of {} face(s) (the degenerate bound at a cone's apex or a sphere's pole) are not written: a 144 trimmed surface is bounded by curves only; each face is written with its other boundaries (a sphere with none: its surface's whole domain), which bound the same region, and --iges-brep writes the vertex loops of faces in shells (508 vertex uses)",
            faces.len()
        ),
        &document.topology.origins.faces,
        first,
    ));
    out
}

/// A warning that something the model carries is not written, located at item `k` of
/// `origins` (its id).
fn not_written(
    code: &'static str,
    message: String,
    origins: &[crate::exchange::Origin],
    k: usize,
) -> crate::exchange::Diagnostic {
    let location = origins
        .get(k)
        .map(|o| crate::exchange::Location::at_entity(o.id.clone()))
        .unwrap_or_default();
    crate::exchange::Diagnostic::warning(code, message, location).not_carried()
}
