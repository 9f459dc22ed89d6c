//! [`Topology`] -> IGES 5.3 entities, for [`super::write()`].
//!
//! - Faces (the default, and the faces no shell holds): a 144 Trimmed Surface (IGES 5.3
//!   section 4.34) over the face's 128, `N1 = 1` with the outer loop as PTO and the holes as
//!   PTI (`N1 = 0` and no loop for a face bounded by its surface's domain). Each loop is a
//!   142 Curve on a Parametric Surface (section 4.22) whose model-space curve C(t) is a 102
//!   Composite Curve (section 4.4) of one 126 per coedge, in the loop's direction and on the
//!   edge's parameter range (`V(0), V(1)`); when every coedge has a pcurve and the pcurves
//!   chain in the surface's (u, v) within 1e-9 of its domain's size, B(t) is a 102 of the 2-D
//!   126 pcurves (z = 0, use flag 05) and PREF = 1 (parameter space preferred), otherwise
//!   BPTR = 0 and PREF = 2 (model space).
//! - With `iges_brep`: every solid as a 186 Manifold Solid B-Rep Object, every shell as a
//!   514 Shell (form 1 closed, 2 open; a shell no solid holds is written alone), every face
//!   of a shell as a 510 Face with its 508 Loops (form 1), the edges in one 504 Edge List
//!   and the vertices in one 502 Vertex List (each written once however many loops use it),
//!   each coedge with its orientation flag and its 2-D pcurve when it has one (IGES 5.3
//!   types 186, 502-514). A face's orientation in its shell is the 514 OF flag (the shell's
//!   orientation combined with the face's `same_sense`); the loops of a face with
//!   `same_sense` false run the other way round, as in a 144.
//!
//! Every entity another one names is written physically dependent (DE status digits 3-4 =
//! 01), so a reader takes the 144s and 186s as the roots.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap, HashSet};

use nurbsx_parsers::iges::records::{
    BrepSolid186, CompositeCurve102, CurveOnSurface142, Edge as Edge504, EdgeList504, Face510,
    Loop508, LoopEdge, Shell514, TrimmedSurface144, VertexList502,
};

use super::write::Items;
use crate::exchange::{Cancel, Document, Entity, Meta, ParameterRange};
use crate::nurbs::NurbsCurve;
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
            meta.parameter_range = Some(ParameterRange {
                u: edge.range,
                v: None,
            });
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
            let surface = items.surface(Cow::Borrowed(&face.surface), &face_meta(f), 1);
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
                        meta.parameter_range = Some(ParameterRange { u: range, v: None });
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
    // Faces as 144 (all of them, or those no shell holds in B-rep mode).
    for (i, face) in model.faces.iter().enumerate() {
        let f = FaceId(i);
        if cancel.is_set() {
            return named;
        }
        if in_brep.contains(&f) {
            continue;
        }
        trimmed_face(model, face, &face_meta(f), &edge_meta, items);
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
/// shell's OF flag turns it over as a whole, section 4.151, which the writer sets from
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

/// A face as a 144 with its 142 boundaries (module documentation).
fn trimmed_face<'d>(
    model: &'d Model,
    face: &'d Face,
    meta: &Meta,
    edge_meta: &dyn Fn(EdgeId) -> Meta,
    items: &mut Items<'d>,
) {
    let surface = items.surface(Cow::Borrowed(&face.surface), meta, 1);
    let mut ordered: Vec<_> = face.loops.iter().collect();
    ordered.sort_by_key(|l| !l.outer);
    let mut boundaries = Vec::with_capacity(ordered.len());
    for l in &ordered {
        let coedges = written_coedges(face, l);
        // Model space: one 126 per coedge, in the loop's direction.
        let mut model_pieces = Vec::with_capacity(coedges.len());
        for &(c, forward) in &coedges {
            let edge = &model.edges[c.edge.0];
            let (curve, range) = along(&edge.curve, edge.range, forward);
            let mut m = edge_meta(c.edge);
            m.parameter_range = Some(ParameterRange { u: range, v: None });
            model_pieces.push(items.curve(curve, &m, 1));
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
        let parameter_curve = parameter_loop(model, face, &coedges).map(|pieces| {
            let members = pieces
                .into_iter()
                .map(|(curve, range)| {
                    let m = Meta {
                        parameter_range: Some(ParameterRange { u: range, v: None }),
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
    let outer = ordered.first().is_some_and(|l| l.outer);
    let (outer_given, outer_ptr, inner) = if outer {
        (1, boundaries[0], boundaries[1..].to_vec())
    } else {
        (0, 0, boundaries)
    };
    items.record(
        144,
        0,
        0,
        0,
        TrimmedSurface144 {
            surface,
            outer_given,
            outer: outer_ptr,
            inner,
        },
    );
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
    let (a, b) = curve.domain();
    match curve.reverse() {
        Ok(r) => (Cow::Owned(r), (a + b - range.1, a + b - range.0)),
        Err(_) => (Cow::Borrowed(curve), range),
    }
}

/// The loop's pcurves in the loop's direction when every coedge has one and they chain in
/// the surface's parameter space (module documentation); `None` otherwise.
fn parameter_loop<'d>(
    model: &'d Model,
    face: &Face,
    coedges: &[(&'d Coedge, bool)],
) -> Option<Vec<Piece<'d>>> {
    let ((u0, u1), (v0, v1)) = face.surface.domain();
    let tol = PCURVE_CHAIN_TOL * (u1 - u0).abs().max((v1 - v0).abs()).max(1.0);
    let mut pieces = Vec::with_capacity(coedges.len());
    for &(c, forward) in coedges {
        let p = c.pcurve.as_ref()?;
        let edge = &model.edges[c.edge.0];
        let (d0, d1) = p.domain();
        if edge.range.0 < d0 || edge.range.1 > d1 {
            return None;
        }
        pieces.push(along(p, edge.range, forward));
    }
    let n = pieces.len();
    for i in 0..n {
        let (a, ra) = &pieces[i];
        let (b, rb) = &pieces[(i + 1) % n];
        let end = a.point_at_unchecked(ra.1);
        let start = b.point_at_unchecked(rb.0);
        if (end[0] - start[0]).abs().max((end[1] - start[1]).abs()) > tol {
            return None;
        }
    }
    Some(pieces)
}
