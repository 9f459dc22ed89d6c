//! STEP boundary representation -> [`Topology`]: the ISO 10303-42 clause 5 topology
//! (vertex_point, edge_curve, oriented_edge, edge_loop / poly_loop / vertex_loop,
//! face_bound / face_outer_bound, advanced_face / face_surface, open_shell / closed_shell /
//! oriented_closed_shell) and the clause 6 solids (manifold_solid_brep, brep_with_voids)
//! over the exact NURBS geometry [`super::geometry`] converted.
//!
//! - Vertices are the VERTEX_POINTs, edges the converted EDGE_CURVEs: an edge's curve is
//!   the one in [`Document::entities`](crate::exchange::Document) (bounded by its vertices);
//!   it runs from `edge_start` to `edge_end` when `same_sense`, else the other way, so the
//!   model's edge starts at `edge_end` then and the oriented edges using it are flipped.
//! - A face_bound with `orientation = .F.` is its loop reversed (ISO 10303-42 face_bound).
//!   A face_outer_bound is the outer loop; a face with a single bound has it as its outer
//!   loop. A vertex_loop (a degenerate bound, a cone's apex) adds no edge: its vertex is
//!   kept on the face ([`crate::topology::Face::vertex_loops`]).
//! - Tolerance of vertices and edges: 1e-7 of the part's size (the diagonal of the box of
//!   all its vertices), at least 1e-9 in the file's unit.
//! - Every refused item is a located diagnostic (`topology.*`) and is skipped; a
//!   CLOSED_SHELL that is not closed is kept as an open shell.

/// The id-keyed maps of the topology build: foldhash's `quality` hasher (ids far apart do
/// not share buckets; see `geometry::Items`), about a tenth of SipHash's cost per lookup.
type HashMap<K, V> = std::collections::HashMap<K, V, foldhash::quality::RandomState>;

use nurbsx_parsers::step::geometry::GeometryRecord as R;

use super::geometry::{Converter, EdgeOut, Items};
use crate::exchange::{Diagnostic, Entity, Label, Location, Origin, Source, Topology};
use crate::nurbs::sweep::QuadricMap;
use crate::nurbs::vector::dist;
use crate::nurbs::{
    Geometry, NurbsCurve, NurbsSurface, Point3, bounding_box_diagonal, conic::line_segment,
};
use crate::topology::{
    Coedge, EdgeId, FaceId, Loop, RefusedFace, ShellId, TopologyError, VertexId, edge_pcurve,
    moved_seams, same_trace, seam_side, seam_splits,
};

/// Relative tolerance of the topology (of the part's size).
const RELATIVE_TOLERANCE: f64 = 1e-7;

/// The largest file uncertainty taken as the topology's tolerance (of the part's size).
const MAX_UNCERTAINTY: f64 = 1e-3;

/// The stable diagnostic code of a refused piece of topology.
pub(super) fn code(e: &TopologyError) -> &'static str {
    match e {
        TopologyError::Missing { .. } => "topology.missing",
        TopologyError::BadVertex { .. } => "topology.vertex_invalid",
        TopologyError::EdgeRange { .. } => "topology.edge_range",
        TopologyError::EdgeMissesVertex { .. } => "topology.edge_vertex",
        TopologyError::LoopOpen { .. } => "topology.loop_open",
        TopologyError::PcurveDeviates { .. } => "topology.pcurve_deviates",
        TopologyError::ShellNotClosed { .. } => "topology.shell_open",
        TopologyError::SolidShellOpen { .. } => "topology.solid_shell_open",
        TopologyError::AssemblyCycle { .. }
        | TopologyError::AssemblyTooLarge { .. }
        | TopologyError::PlacementInvalid { .. } => "topology.assembly",
    }
}

/// How many topological items of each kind a file holds (for `geometry_only`).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub(super) struct Counts {
    pub faces: usize,
    pub edges: usize,
    pub shells: usize,
    pub solids: usize,
}

/// Counts the faces, edges, shells and solids of the decoded items.
pub(super) fn count(conv: &Converter<'_, '_, '_>) -> Counts {
    let mut c = Counts::default();
    for item in conv.items.values() {
        match item.record {
            R::FaceSurface { .. } => c.faces += 1,
            R::EdgeCurve { .. } => c.edges += 1,
            R::Shell { .. } => c.shells += 1,
            R::ManifoldSolidBrep { .. } => c.solids += 1,
            _ => {}
        }
    }
    c
}

/// Whether the topology ([`build`]) reads items of this kind once the curves and surfaces
/// are converted: everything but the curves, surfaces, placements, directions and vectors,
/// whose NURBS are the entities now (the few placements the product structure reads as
/// frames are kept by the reader, `assembly::frame_items`). Any kind not listed stays.
pub(super) fn reads(record: &R<'_>) -> bool {
    !(super::geometry::stands_alone(record)
        || matches!(
            record,
            R::Direction { .. }
                | R::Vector { .. }
                | R::Axis1Placement { .. }
                | R::Axis2Placement2d { .. }
                | R::Axis2Placement3d { .. }
                | R::CompositeCurveSegment { .. }
                | R::Pcurve { .. }
                | R::DefinitionalRepresentation { .. }
        ))
}

/// `(EDGE_CURVE, 2-D curve)` instance pairs of the EDGE_CURVEs `edges` (ascending), in
/// their order: the 2-D curves of each edge's PCURVEs (ISO 10303-42 surface_curve ->
/// pcurve -> definitional_representation), in the order the file lists them. Read before
/// the surface curves, pcurves and their representations are freed ([`reads`]): the
/// topology needs nothing else of them (it recomputes the pcurves on its NURBS surfaces),
/// and a pair is a fraction of their items.
pub(super) fn edge_pcurve_curves(items: &Items<'_>, edges: &[u64]) -> Vec<(u64, u64)> {
    let mut out = Vec::new();
    for &edge in edges {
        let Some(R::EdgeCurve { edge_geometry, .. }) = items.get(&edge).map(|i| &i.record) else {
            continue;
        };
        let Some(R::SurfaceCurve {
            associated_geometry,
            ..
        }) = items.get(edge_geometry).map(|i| &i.record)
        else {
            continue;
        };
        for g in associated_geometry {
            let Some(R::Pcurve {
                reference_to_curve, ..
            }) = items.get(g).map(|i| &i.record)
            else {
                continue;
            };
            if let Some(R::DefinitionalRepresentation { items: curves, .. }) =
                items.get(reference_to_curve).map(|i| &i.record)
            {
                out.extend(curves.iter().map(|&c| (edge, c)));
            }
        }
    }
    // Held through the B-spline pass and the topology (the read's peak): without the
    // growth's spare room.
    out.shrink_to_fit();
    out
}

/// The builder's state: the model under construction and the map from file ids to it.
struct Build<'c, 'm, 's, 'a> {
    conv: &'c Converter<'m, 's, 'a>,
    /// The quadric face surfaces' closed-form parameter maps, by surface instance id.
    quadric_maps: &'c HashMap<u64, QuadricMap>,
    topology: Topology,
    diagnostics: Vec<Diagnostic>,
    tolerance: f64,
    vertices: HashMap<u64, VertexId>,
    /// EDGE_CURVE id -> (edge, whether the model's edge runs as the file's).
    edges: HashMap<u64, (EdgeId, bool)>,
    /// POLY_LOOP sides by their ordered point pair, shared between faces.
    poly_edges: HashMap<(u64, u64), EdgeId>,
    faces: HashMap<u64, FaceId>,
    shells: HashMap<u64, ShellId>,
    /// Coedges whose pcurve could not be computed.
    missing_pcurves: usize,
    /// Edges split at a face's seam ([`seam_splits`]): (first half, second half).
    splits: Vec<(EdgeId, EdgeId)>,
    /// (instance of a PCURVE's 2-D curve, the EDGE_CURVE using it).
    pcurve_entities: Vec<(u64, u64)>,
    /// The EDGE_CURVE of each model edge, by edge index (`None` for a POLY_LOOP side).
    edge_instances: Vec<Option<u64>>,
    /// The faces added with their surface's seam moved.
    moved_faces: Vec<FaceId>,
    /// [`edge_pcurve_curves`] of the file.
    edge_pcurves: &'c [(u64, u64)],
}

/// What [`build`] made.
pub(super) struct Built {
    /// The topology.
    pub topology: Topology,
    /// What was refused or left out.
    pub diagnostics: Vec<Diagnostic>,
    /// (curve instance, EDGE_CURVE instance): the 2-D curves of the file's PCURVEs of edges
    /// in the topology, to be marked as used by those edges.
    pub pcurve_entities: Vec<(u64, u64)>,
    /// The EDGE_CURVEs in the topology whose every coedge carries a pcurve (ascending; see
    /// [`Build::edges_with_pcurves`]).
    pub edges_with_pcurves: Vec<u64>,
    /// The faces whose surface has its seam moved (for
    /// [`Document::adopt_moved_surfaces`](crate::exchange::Document::adopt_moved_surfaces)).
    pub moved_faces: Vec<FaceId>,
}

/// Builds the topology of the decoded items over the converted edges (moved into the
/// model's edges, each curve without a copy) and the document's
/// entities (face surfaces by id). The tolerance is [`RELATIVE_TOLERANCE`] of the
/// vertices' box (of the edges' curves when the vertices span nothing), or the file's
/// length `uncertainty` (model unit) when that is larger.
pub(super) fn build(
    conv: &Converter<'_, '_, '_>,
    edges: Vec<(u64, EdgeOut)>,
    quadric_maps: &HashMap<u64, QuadricMap>,
    entities: &[Entity],
    uncertainty: f64,
    edge_pcurves: &[(u64, u64)],
) -> Built {
    let mut b = Build {
        edge_pcurves,
        conv,
        quadric_maps,
        topology: Topology::default(),
        diagnostics: Vec::new(),
        tolerance: 0.0,
        vertices: HashMap::default(),
        edges: HashMap::default(),
        poly_edges: HashMap::default(),
        faces: HashMap::default(),
        shells: HashMap::default(),
        missing_pcurves: 0,
        splits: Vec::new(),
        pcurve_entities: Vec::new(),
        edge_instances: Vec::new(),
        moved_faces: Vec::new(),
    };
    // The items of each kind the model is built from, in one walk of the items (each walk
    // reads all of them: on a large file, several were a visible part of the read).
    let mut kinds = Kinds::default();
    for (id, item) in conv.items.iter() {
        match item.record {
            R::VertexPoint { vertex_geometry } => kinds.vertices.push((id, vertex_geometry)),
            R::FaceSurface { .. } => kinds.faces.push(id),
            R::Shell { .. } => kinds.shells.push(id),
            R::OrientedClosedShell { .. } => kinds.oriented_shells.push(id),
            R::ManifoldSolidBrep { .. } => kinds.solids.push(id),
            _ => {}
        }
    }
    // Vertices first: their box gives the tolerance.
    let mut points: Vec<(u64, Point3)> = Vec::with_capacity(kinds.vertices.len());
    // Each list is freed once walked (the read's peak of memory comes at the end).
    for (id, vertex_geometry) in std::mem::take(&mut kinds.vertices) {
        match conv.point(vertex_geometry, id) {
            Ok(p) => points.push((id, p)),
            Err(d) => b.diagnostics.push(d),
        }
    }
    let diagonal = {
        let all: Vec<Point3> = points.iter().map(|(_, p)| *p).collect();
        bounding_box_diagonal(&all)
    };
    // A part whose vertices span nothing (one vertex: a torus's seams, a sphere's) has the
    // size of its edges' curves.
    let diagonal = if diagonal > 0.0 {
        diagonal
    } else {
        let poles: Vec<Point3> = edges
            .iter()
            .flat_map(|(_, e)| e.curve.control_points().iter().copied())
            .collect();
        bounding_box_diagonal(&poles)
    };
    b.tolerance = (diagonal * RELATIVE_TOLERANCE).max(1e-9);
    // Without two distinct vertices there is nothing for a tolerance to join.
    if uncertainty > b.tolerance && diagonal > 0.0 {
        // A declared uncertainty above a thousandth of the part would merge its features.
        if uncertainty <= MAX_UNCERTAINTY * diagonal {
            b.tolerance = uncertainty;
        } else {
            b.diagnostics.push(Diagnostic::warning(
                "step.uncertainty_ignored",
                format!(
                    "the file's length uncertainty {uncertainty:e} is more than {MAX_UNCERTAINTY:e} of the part's size {diagonal:e}; the topology is read within {:e} instead",
                    b.tolerance
                ),
                Location::default(),
            ));
        }
    }
    // The model's lists and their origins at the size the file gives them (grown by
    // doubling, up to half of each would be unused room at the read's peak of memory).
    let faces = kinds.faces.len();
    let (model, origins) = (&mut b.topology.model, &mut b.topology.origins);
    model.vertices.reserve_exact(points.len());
    origins.vertices.reserve_exact(points.len());
    model.edges.reserve_exact(edges.len());
    origins.edges.reserve_exact(edges.len());
    model.faces.reserve_exact(faces);
    origins.faces.reserve_exact(faces);
    for (id, p) in points {
        match b.topology.model.add_vertex(p, b.tolerance) {
            Ok(v) => {
                b.vertices.insert(id, v);
                b.topology.origins.vertices.push(b.origin(id, None));
            }
            Err(e) => b.refuse(id, &e),
        }
    }
    // In item order; each curve moves into the model.
    for (id, out) in edges {
        b.edge(id, out);
    }
    // The surfaces by the instance their label names (`#N`; the first of several with one
    // label): a face finds its surface by number, without making and hashing the label.
    let mut surfaces: HashMap<u64, &Entity> = HashMap::default();
    for e in entities {
        if let (Geometry::Surface(_), Some(id)) = (&e.geometry, super::instance_of(&e.id)) {
            surfaces.entry(id).or_insert(e);
        }
    }
    for id in std::mem::take(&mut kinds.faces) {
        b.face(id, &surfaces);
    }
    for &id in &kinds.shells {
        b.shell(id);
    }
    for &id in &kinds.oriented_shells {
        b.oriented_shell(id);
    }
    for &id in &kinds.solids {
        b.solid(id);
    }
    if b.missing_pcurves > 0 {
        b.diagnostics.push(Diagnostic::warning(
            "pcurve.not_computed",
            format!(
                "{} coedge(s) have no parameter-space curve: no exact one applies and their 3-D curve could not be projected onto the face's surface within the edge tolerance {:e} (the 3-D edges are exact)",
                b.missing_pcurves, b.tolerance
            ),
            Location::default(),
        )
        .not_carried());
    }
    Built {
        edges_with_pcurves: b.edges_with_pcurves(),
        topology: b.topology,
        diagnostics: b.diagnostics,
        pcurve_entities: b.pcurve_entities,
        moved_faces: b.moved_faces,
    }
}

/// The ids of the items [`build`] makes the model from, by kind, in item order.
#[derive(Default)]
struct Kinds {
    /// VERTEX_POINTs with their point.
    vertices: Vec<(u64, u64)>,
    faces: Vec<u64>,
    shells: Vec<u64>,
    oriented_shells: Vec<u64>,
    solids: Vec<u64>,
}

impl Build<'_, '_, '_, '_> {
    fn origin(&self, id: u64, entity: Option<Label>) -> Origin {
        let found = self.conv.provenance(id);
        Origin {
            id: super::instance_label(id),
            source: Source {
                entity: found.entity,
                line: found.line,
            },
            name: found.name,
            entity,
        }
    }

    fn refuse(&mut self, id: u64, e: &TopologyError) {
        let d = self
            .conv
            .error(id, code(e), format!("{}; skipped", describe(e)));
        self.diagnostics.push(d);
    }

    fn missing(&mut self, id: u64, what: &str, refs: &[u64]) {
        let list: Vec<Label> = refs.iter().map(|&r| super::instance_label(r)).collect();
        let d = self.conv.error(
            id,
            "topology.missing",
            format!(
                "{what} {} could not be read (see the diagnostics there)",
                list.join(", ")
            ),
        );
        self.diagnostics.push(d);
    }

    /// An EDGE_CURVE (ISO 10303-42 5.4, edge_curve).
    fn edge(&mut self, id: u64, out: EdgeOut) {
        let Some(&R::EdgeCurve {
            edge_start,
            edge_end,
            same_sense,
            ..
        }) = self.conv.items.get(&id).map(|i| &i.record)
        else {
            return;
        };
        let (Some(&vs), Some(&ve)) = (self.vertices.get(&edge_start), self.vertices.get(&edge_end))
        else {
            self.missing(id, "the vertices of the edge: of", &[edge_start, edge_end]);
            return;
        };
        let (start, end) = if same_sense { (vs, ve) } else { (ve, vs) };
        let range = out.range.unwrap_or_else(|| out.curve.domain());
        match self
            .topology
            .model
            .add_edge(out.curve, range, start, end, self.tolerance)
        {
            Ok(e) => {
                self.edges.insert(id, (e, same_sense));
                let o = self.origin(id, Some(out.entity));
                self.topology.origins.edges.push(o);
                self.edge_instances.push(Some(id));
                self.note_pcurves(id);
            }
            Err(e) => self.refuse(id, &e),
        }
    }

    /// The 2-D curves of the edge's PCURVEs ([`edge_pcurve_curves`]): the model recomputes
    /// them on its NURBS surfaces, so the entities are marked as used by the edge.
    fn note_pcurves(&mut self, edge: u64) {
        let pairs = self.edge_pcurves;
        let start = pairs.partition_point(|&(e, _)| e < edge);
        for &(_, curve) in pairs[start..].iter().take_while(|&&(e, _)| e == edge) {
            self.pcurve_entities.push((curve, edge));
        }
    }

    /// The EDGE_CURVEs of the model (ascending) used by at least one coedge and whose every
    /// coedge, on every face and on both halves of an edge split at a seam, carries a pcurve:
    /// the model holds their parameter-space curves, computed on its NURBS surfaces, so the
    /// 2-D curves of their PCURVEs in the file are not needed (the reader converts the
    /// others).
    fn edges_with_pcurves(&self) -> Vec<u64> {
        let model = &self.topology.model;
        // Per model edge: bit 0 for a coedge with a pcurve, bit 1 for one without.
        let mut seen = vec![0u8; model.edges.len()];
        for c in model
            .faces
            .iter()
            .flat_map(|f| &f.loops)
            .flat_map(|l| &l.coedges)
        {
            if let Some(s) = seen.get_mut(c.edge.0) {
                *s |= if c.pcurve.is_some() { 1 } else { 2 };
            }
        }
        let mut by_instance: Vec<(u64, u8)> = self
            .edge_instances
            .iter()
            .zip(&seen)
            .filter_map(|(i, &s)| Some(((*i)?, s)))
            .collect();
        by_instance.sort_unstable_by_key(|&(i, _)| i);
        by_instance
            .chunk_by(|a, b| a.0 == b.0)
            .filter(|run| run.iter().fold(0, |all, &(_, s)| all | s) == 1)
            .filter_map(|run| run.first().map(|&(i, _)| i))
            .collect()
    }

    /// The coedges of an EDGE_LOOP, as the file lists them.
    fn edge_loop(&mut self, face: u64, edge_list: &[u64]) -> Option<Vec<Coedge>> {
        let mut out = Vec::with_capacity(edge_list.len());
        for &oe in edge_list {
            let Some(R::OrientedEdge {
                edge_element,
                orientation,
            }) = self.conv.items.get(&oe).map(|i| &i.record)
            else {
                self.missing(face, "the oriented edge", &[oe]);
                return None;
            };
            let Some(&(edge, same)) = self.edges.get(edge_element) else {
                self.missing(face, "the edge", &[*edge_element]);
                return None;
            };
            out.push(Coedge {
                edge,
                forward: *orientation == same,
                pcurve: None,
                pcurve_deviation: None,
            });
        }
        // Edges split for an earlier face, in the order they were split.
        if !self.splits.is_empty() {
            let mut l = [Loop {
                coedges: out,
                outer: false,
            }];
            for &(edge, second) in &self.splits {
                let _ = self.topology.model.split_coedges(&mut l, edge, second);
            }
            let [Loop { coedges, .. }] = l;
            out = coedges;
        }
        Some(out)
    }

    /// The sides of a POLY_LOOP as line edges between its points (shared by the faces that
    /// use the same pair of points).
    fn poly_loop(&mut self, face: u64, polygon: &[u64]) -> Option<Vec<Coedge>> {
        if polygon.len() < 3 {
            let d = self.conv.error(
                face,
                "topology.loop_open",
                format!("a POLY_LOOP of {} points bounds nothing", polygon.len()),
            );
            self.diagnostics.push(d);
            return None;
        }
        let mut out = Vec::with_capacity(polygon.len());
        for i in 0..polygon.len() {
            let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
            let key = (a.min(b), a.max(b));
            let edge = match self.poly_edges.get(&key) {
                Some(&e) => e,
                None => {
                    let mut ends = [VertexId(0); 2];
                    for (k, p) in [key.0, key.1].into_iter().enumerate() {
                        ends[k] = match self.vertices.get(&p) {
                            Some(&v) => v,
                            None => {
                                let point = match self.conv.point(p, face) {
                                    Ok(q) => q,
                                    Err(d) => {
                                        self.diagnostics.push(d);
                                        return None;
                                    }
                                };
                                match self.topology.model.add_vertex(point, self.tolerance) {
                                    Ok(v) => {
                                        self.vertices.insert(p, v);
                                        let o = self.origin(p, None);
                                        self.topology.origins.vertices.push(o);
                                        v
                                    }
                                    Err(e) => {
                                        self.refuse(face, &e);
                                        return None;
                                    }
                                }
                            }
                        };
                    }
                    let m = &self.topology.model;
                    let (p, q) = (m.vertices[ends[0].0].point, m.vertices[ends[1].0].point);
                    let length = dist(p, q);
                    let curve = match line_segment(p, q, 0.0, length) {
                        Ok(c) => c,
                        Err(e) => {
                            let d = self.conv.error(
                                face,
                                "topology.edge_range",
                                format!("POLY_LOOP side #{a} - #{b}: {e}"),
                            );
                            self.diagnostics.push(d);
                            return None;
                        }
                    };
                    match self.topology.model.add_edge(
                        curve,
                        (0.0, length),
                        ends[0],
                        ends[1],
                        self.tolerance,
                    ) {
                        Ok(e) => {
                            self.poly_edges.insert(key, e);
                            let mut o = self.origin(face, None);
                            o.id = compact_str::format_compact!("#{}-#{}", key.0, key.1);
                            self.topology.origins.edges.push(o);
                            self.edge_instances.push(None);
                            e
                        }
                        Err(e) => {
                            self.refuse(face, &e);
                            return None;
                        }
                    }
                }
            };
            out.push(Coedge {
                edge,
                forward: a < b,
                pcurve: None,
                pcurve_deviation: None,
            });
        }
        Some(out)
    }

    /// An ADVANCED_FACE or FACE_SURFACE (ISO 10303-42 5.4, face_surface).
    fn face(&mut self, id: u64, surfaces: &HashMap<u64, &Entity>) {
        let Some(&R::FaceSurface {
            ref bounds,
            face_geometry,
            same_sense,
        }) = self.conv.items.get(&id).map(|i| &i.record)
        else {
            return;
        };
        let Some(entity) = surfaces.get(&face_geometry) else {
            self.missing(id, "the face's surface", &[face_geometry]);
            return;
        };
        let Geometry::Surface(surface) = &entity.geometry else {
            return;
        };
        let mut loops = Vec::with_capacity(bounds.len());
        let mut vertex_loops = Vec::new();
        for &fb in bounds {
            let Some(item) = self.conv.items.get(&fb) else {
                self.missing(id, "the face bound", &[fb]);
                return;
            };
            let R::FaceBound { bound, orientation } = item.record else {
                self.missing(id, "the face bound", &[fb]);
                return;
            };
            let outer = item.entity == "FACE_OUTER_BOUND";
            let coedges = match self.conv.items.get(&bound).map(|i| &i.record) {
                Some(R::EdgeLoop { edge_list }) => self.edge_loop(id, edge_list),
                Some(R::PolyLoop { polygon }) => self.poly_loop(id, polygon),
                Some(R::VertexLoop { loop_vertex }) => {
                    // A degenerate bound (a cone's apex, a sphere's pole): kept on the face.
                    match self.vertices.get(loop_vertex) {
                        Some(&v) => vertex_loops.push(v),
                        None => {
                            self.missing(id, "the loop's vertex", &[*loop_vertex]);
                            return;
                        }
                    }
                    continue;
                }
                _ => {
                    self.missing(id, "the loop", &[bound]);
                    return;
                }
            };
            let Some(mut coedges) = coedges else { return };
            if !orientation {
                coedges.reverse();
                for c in &mut coedges {
                    c.forward = !c.forward;
                }
            }
            loops.push(Loop { coedges, outer });
        }
        if loops.len() == 1 {
            loops[0].outer = true;
        }
        let map = self.quadric_maps.get(&face_geometry);
        let mut missing = self.pcurves(surface, map, &mut loops, same_sense);
        // Edges across the surface's seam: the face's own seam may lie elsewhere
        // (`moved_seams`); the first surface with the seam moved to a vertex of the face on
        // which every pcurve is found replaces it (the same surface, exactly).
        let mut moved: Option<NurbsSurface> = None;
        if missing > 0 {
            let m = &self.topology.model;
            for candidate in moved_seams(surface, m, &loops, self.tolerance) {
                let mut trial = loops.clone();
                if self.pcurves(&candidate, None, &mut trial, same_sense) == 0 {
                    loops = trial;
                    missing = 0;
                    moved = Some(candidate);
                    break;
                }
            }
        }
        // Loops that wind around the surface and loops that do not (a pipe between two
        // full circles, pierced by holes, without a seam edge): the seam goes between the
        // holes and the winding edges are split where it crosses them (`seam_splits`).
        if missing > 0 && moved.is_none() {
            let m = &self.topology.model;
            if let Some(plan) = seam_splits(surface, m, &loops, self.tolerance) {
                // The pcurves are found again below, on the halves.
                for c in loops.iter_mut().flat_map(|l| &mut l.coedges) {
                    c.pcurve = None;
                    c.pcurve_deviation = None;
                }
                for &(edge, t) in &plan.splits {
                    self.split_edge(id, edge, t, &mut loops);
                }
                let mut trial = loops.clone();
                if self.pcurves(&plan.surface, None, &mut trial, same_sense) == 0 {
                    loops = trial;
                    missing = 0;
                    moved = Some(plan.surface);
                } else if !plan.splits.is_empty() {
                    // The split loops, on the surface as it was.
                    missing = self.pcurves(surface, map, &mut loops, same_sense);
                }
            }
        }
        self.missing_pcurves += missing;
        let surface = moved.as_ref().unwrap_or(surface);
        // Bounds that do not say which one is outer (all plain face_bounds, as Open CASCADE
        // writes them): the one that contains the others is (ISO 10303-42 face_bound).
        if loops.len() > 1 && !loops.iter().any(|l| l.outer) {
            if let Some(k) = self.topology.model.outer_loop(&loops) {
                loops[k].outer = true;
            }
        }
        match self
            .topology
            .model
            .try_add_face(surface.clone(), loops, same_sense)
        {
            Ok(f) => self.face_added(id, f, entity.id.clone(), moved.is_some(), vertex_loops),
            Err(RefusedFace {
                error: e @ TopologyError::PcurveDeviates { .. },
                mut loops,
            }) => {
                // A pcurve the check refuses is left out (said here), the face kept.
                let d = self.conv.error(
                    id,
                    code(&e),
                    format!("{}; the face is kept without its pcurves", describe(&e)),
                );
                self.diagnostics.push(d);
                for l in &mut loops {
                    for c in &mut l.coedges {
                        c.pcurve = None;
                        c.pcurve_deviation = None;
                    }
                }
                match self
                    .topology
                    .model
                    .add_face(surface.clone(), loops, same_sense)
                {
                    Ok(f) => {
                        self.face_added(id, f, entity.id.clone(), moved.is_some(), vertex_loops);
                    }
                    Err(e) => self.refuse(id, &e),
                }
            }
            Err(r) => self.refuse(id, &r.error),
        }
    }

    /// Splits `edge` at `t` for the face `face` ([`seam_splits`]): in the model (faces
    /// already built included), in the face's `loops`, and in every loop built later.
    fn split_edge(&mut self, face: u64, edge: EdgeId, t: f64, loops: &mut [Loop]) {
        let model = &mut self.topology.model;
        match model.split_edge(edge, t) {
            Ok((vertex, second)) => {
                // Without pcurves (cleared by the caller) the coedges always split.
                let _ = model.split_coedges(loops, edge, second);
                let origins = &mut self.topology.origins;
                let o = origins.edges.get(edge.0).cloned().unwrap_or_default();
                origins.vertices.push(o.clone());
                origins.edges.push(o.clone());
                let instance = self.edge_instances.get(edge.0).copied().flatten();
                self.edge_instances.push(instance);
                let d = Diagnostic::info(
                    "topology.edge_split_at_seam",
                    format!(
                        "edge {} is split in two at the seam of face #{face}'s NURBS surface (new vertex {}): the face has no seam edge, its loops need the seam where this edge runs, and a pcurve must stay inside the surface's domain; the geometry is unchanged",
                        o.id, vertex.0
                    ),
                    self.conv.location(face),
                );
                self.diagnostics.push(d);
                self.splits.push((edge, second));
            }
            Err(e) => self.refuse(face, &e),
        }
    }

    /// `moved`: the face carries its surface with the seam moved; `vertex_loops`: the
    /// vertices of its vertex_loop bounds.
    fn face_added(
        &mut self,
        id: u64,
        f: FaceId,
        entity: Label,
        moved: bool,
        vertex_loops: Vec<VertexId>,
    ) {
        if let Some(face) = self.topology.model.faces.get_mut(f.0) {
            face.vertex_loops = vertex_loops;
        }
        self.faces.insert(id, f);
        if moved {
            self.moved_faces.push(f);
        }
        let o = self.origin(id, Some(entity));
        self.topology.origins.faces.push(o);
    }

    /// The pcurve of every coedge on the face's NURBS surface ([`edge_pcurve`]: exact on
    /// planes and along isocurves, else projected within the edge tolerance; the file's
    /// PCURVEs are in the analytic surface's parameters, not the NURBS ones). A seam edge (used
    /// twice by the face) gets both sides of the seam: the coedge that runs with the face
    /// interior on its left in `(u, v)` (counter-clockwise outer loops for `same_sense`,
    /// clockwise otherwise) takes the side that puts the interior there; so does an edge
    /// used once that runs along the seam line of a surface closed across it ([`seam_side`]). Coedges whose
    /// projection fails keep `None`; returns how many (the caller counts them in one
    /// warning of the file).
    fn pcurves(
        &self,
        surface: &NurbsSurface,
        map: Option<&QuadricMap>,
        loops: &mut [Loop],
        same_sense: bool,
    ) -> usize {
        let mut missing = 0;
        // The face's edges, each with how many of its coedges use it, sorted: a coedge's
        // edge is found by binary search (a face has a few, and two hash tables per face
        // were a visible part of a large read).
        let mut all: Vec<EdgeId> = loops
            .iter()
            .flat_map(|l| l.coedges.iter().map(|c| c.edge))
            .collect();
        all.sort_unstable();
        let uses: Vec<(EdgeId, usize)> = all
            .chunk_by(|a, b| a == b)
            .filter_map(|run| run.first().map(|&e| (e, run.len())))
            .collect();
        // The pcurve of each edge (or why none), found once per edge of the face.
        let mut cache: Vec<Option<Option<(NurbsCurve, f64)>>> = vec![None; uses.len()];
        let size = bounding_box_diagonal(surface.control_points().as_slice());
        let closed = [
            surface.is_closed_u(1e-9 * size),
            surface.is_closed_v(1e-9 * size),
        ];
        for l in loops.iter_mut() {
            for c in &mut l.coedges {
                let edge = &self.topology.model.edges[c.edge.0];
                let find = || {
                    edge_pcurve(surface, map, &edge.curve, edge.range, edge.tolerance)
                        .ok()
                        .filter(|p| p.deviation <= edge.tolerance)
                        .map(|p| (p.curve, p.deviation))
                };
                // Every coedge's edge is in `uses` (made from these loops).
                let k = uses.binary_search_by_key(&c.edge, |(e, _)| *e).ok();
                let p = match k.and_then(|k| cache.get_mut(k)) {
                    Some(slot) => slot.get_or_insert_with(find).clone(),
                    None => find(),
                };
                // The deviation measured with the pcurve is kept (the face check then
                // compares it with the tolerance instead of sampling again), unless the
                // pcurve moves to the other side of a seam that is not the same curve
                // (`same_trace`), where it is measured anew.
                (c.pcurve, c.pcurve_deviation) = match p {
                    Some((p, deviation)) => {
                        let twice = k.and_then(|k| uses.get(k)).is_some_and(|(_, n)| *n == 2);
                        let seam = [closed[0] || twice, closed[1] || twice];
                        match seam_side(surface, &p, c.forward == same_sense, seam) {
                            Some(moved) => {
                                let same = same_trace(surface, &p, &moved);
                                (Some(moved), same.then_some(deviation))
                            }
                            None => (Some(p), Some(deviation)),
                        }
                    }
                    None => (None, None),
                };
                if c.pcurve.is_none() {
                    missing += 1;
                }
            }
        }
        missing
    }

    /// An OPEN_SHELL or CLOSED_SHELL (ISO 10303-42 5.4); a CLOSED_SHELL that is not
    /// closed is reported and kept as an open shell.
    fn shell(&mut self, id: u64) {
        let Some(&R::Shell {
            ref cfs_faces,
            closed,
        }) = self.conv.items.get(&id).map(|i| &i.record)
        else {
            return;
        };
        let mut faces = Vec::with_capacity(cfs_faces.len());
        let mut absent = Vec::new();
        for f in cfs_faces {
            // A face, or an ORIENTED_FACE reversing one (ISO 10303-42 oriented_face).
            let (face, same) = match self.conv.items.get(f).map(|i| &i.record) {
                Some(R::OrientedFace {
                    face_element,
                    orientation,
                }) => (*face_element, *orientation),
                _ => (*f, true),
            };
            match self.faces.get(&face) {
                Some(&x) => faces.push((x, same)),
                None => absent.push(*f),
            }
        }
        if !absent.is_empty() {
            self.missing(id, "the shell's face(s)", &absent);
        }
        if faces.is_empty() {
            return;
        }
        let shell = match self.topology.model.add_shell(faces.clone(), closed) {
            Ok(s) => Some(s),
            Err(e @ TopologyError::ShellNotClosed { .. }) => {
                let d = self.conv.error(
                    id,
                    code(&e),
                    format!("{}; kept as an open shell", describe(&e)),
                );
                self.diagnostics.push(d);
                self.topology.model.add_shell(faces, false).ok()
            }
            Err(e) => {
                self.refuse(id, &e);
                None
            }
        };
        if let Some(s) = shell {
            self.shells.insert(id, s);
            let o = self.origin(id, None);
            self.topology.origins.shells.push(o);
        }
    }

    /// An ORIENTED_CLOSED_SHELL: the faces of its closed shell, each reversed when
    /// `orientation = .F.`.
    fn oriented_shell(&mut self, id: u64) {
        let Some(&R::OrientedClosedShell {
            closed_shell_element,
            orientation,
        }) = self.conv.items.get(&id).map(|i| &i.record)
        else {
            return;
        };
        let Some(base) = self.shells.get(&closed_shell_element).copied() else {
            self.missing(id, "the closed shell", &[closed_shell_element]);
            return;
        };
        let faces: Vec<(FaceId, bool)> = self.topology.model.shells[base.0]
            .faces
            .iter()
            .map(|&(f, o)| (f, o == orientation))
            .collect();
        match self.topology.model.add_shell(faces, true) {
            Ok(s) => {
                self.shells.insert(id, s);
                let o = self.origin(id, None);
                self.topology.origins.shells.push(o);
            }
            Err(e) => self.refuse(id, &e),
        }
    }

    /// A MANIFOLD_SOLID_BREP or BREP_WITH_VOIDS (ISO 10303-42 clause 6).
    fn solid(&mut self, id: u64) {
        let Some(&R::ManifoldSolidBrep { outer, ref voids }) =
            self.conv.items.get(&id).map(|i| &i.record)
        else {
            return;
        };
        let mut shells = Vec::with_capacity(1 + voids.len());
        for s in std::iter::once(&outer).chain(voids) {
            match self.shells.get(s) {
                Some(&x) => shells.push(x),
                None => {
                    self.missing(id, "the solid's shell", &[*s]);
                    return;
                }
            }
        }
        let outer = shells.remove(0);
        match self.topology.model.add_solid(outer, shells) {
            Ok(_) => {
                let o = self.origin(id, None);
                self.topology.origins.solids.push(o);
            }
            Err(e) => self.refuse(id, &e),
        }
    }
}

/// The error's message with the model's indices left out where the file ids say more.
fn describe(e: &TopologyError) -> String {
    match e {
        TopologyError::LoopOpen { index, coedge, .. } => format!(
            "loop {} of the face does not close: oriented edge {} does not end where the next one starts",
            index + 1,
            coedge + 1
        ),
        TopologyError::ShellNotClosed { count, .. } => format!(
            "the shell is declared closed but {count} of its edges are not used exactly twice in opposite directions"
        ),
        other => other.to_string(),
    }
}
